//! Motion2Motion retargeting: transfer a motion to a skeleton of another topology from a few
//! example clips of the target and a sparse binding (the paper: docs/reference/README.md).
//!
//! The algorithm is the paper's (and the reference code's, docs/reference/motion2motion.md §3):
//! per pyramid level, coarse to fine, the bound channels of the synthesis are set from the
//! source ("projection"), then `steps` times every patch of the synthesis is replaced by its
//! nearest example patch (bound channels weigh `alpha`, the others `1 - alpha`) and the chosen
//! patches are averaged. Unbound channels start as noise.
//!
//! What we do differently, and why (§4 of the reference notes lists what fails users there):
//! * Any output length: frames past the source's end are synthesised from the examples alone.
//! * Clips shorter than a patch: the patch shrinks to the longest example (and the output) and
//!   the report says so; pyramid levels shorter than a patch are dropped instead of crashing
//!   when the target is much longer than the source; short example clips only leave the levels
//!   where they are shorter than a patch.
//! * Every example clip joins the patch database ("test-time scaling").
//! * Key-frame mode: the source constrains only its key frames; between them the bound
//!   channels start from the source interpolated (better than noise) and are then free.
//! * Bound rotations can be rest-aligned or root-relative world copies (`BoundRotation`), and
//!   the root trajectory can come from the source scaled to the target's size (`RootMotion`).
//! * Determinism: a seed gives the same bytes whatever the thread count (each frame's noise has
//!   its own stream derived from the seed, every parallel reduction has a fixed order).
//!
//! Frame rates are the caller's business: `resample` brings the source to the examples' rate.

pub mod clips;
mod describe;
mod features;
pub mod settings;
#[cfg(test)]
mod tests;

pub use settings::{BoundRotation, Repr, RootMotion, Settings};

use crate::binding::JointMap;
use crate::motion::Motion;
use crate::patch::channels::{self, Channels};
use crate::patch::{nn, pyramid};
use crate::repr::m2m;
use crate::rng::{stream_seed, PolarGaussian};
use crate::skeleton::Skeleton;
use glam::DQuat;
use rayon::prelude::*;
use std::time::{Duration, Instant};

#[derive(Debug, thiserror::Error)]
pub enum RetargetError {
    #[error("no example clips of the target skeleton were given (at least one is needed)")]
    NoExamples,
    #[error("example clip {example} has {joints} joints but the target skeleton has {skeleton}: all examples must share the target skeleton")]
    ExampleSkeleton { example: usize, joints: usize, skeleton: usize },
    #[error("the source motion has {joints} joints but the source skeleton has {skeleton}")]
    SourceSkeleton { joints: usize, skeleton: usize },
    #[error("the {side} skeleton has no joints")]
    EmptySkeleton { side: &'static str },
    #[error("the {side} skeleton: {error}")]
    Skeleton { side: &'static str, error: crate::skeleton::SkeletonError },
    #[error("{what} has zero frames")]
    ZeroFrames { what: String },
    #[error("binding pair {pair}: {side} joint index {index} is out of range (the {side} skeleton has {joints} joints)")]
    MapIndex { pair: usize, side: &'static str, index: usize, joints: usize },
    #[error("binding pairs {first} and {second} both bind target joint {joint} '{name}'")]
    MapDuplicate { first: usize, second: usize, joint: usize, name: String },
    #[error("key frame {frame} is past the end of the source ({frames} frames)")]
    KeyFrame { frame: usize, frames: usize },
    #[error("{what}: non-finite value at frame {frame}, joint {joint}")]
    NonFinite { what: String, frame: usize, joint: usize },
    #[error("setting {what} = {value}: expected {expected}")]
    Setting { what: String, value: String, expected: String },
    #[error("decoding the result")]
    Decode(#[from] m2m::M2mError),
}

/// A retargeted motion and how it was made.
#[derive(Clone, Debug)]
pub struct Retargeted {
    /// The motion on the target skeleton, at the examples' frame rate.
    pub motion: Motion,
    pub report: Report,
}

#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Pyramid levels, coarse to fine.
    pub levels: Vec<LevelReport>,
    pub timings: Timings,
    /// Bound (joint pairs of the map).
    pub bound: usize,
    /// Channels per frame that are matched, and how many of them are bound.
    pub channels: usize,
    pub bound_channels: usize,
    /// Patch length used (the setting, or less when clips are shorter; see `notes`).
    pub patch: usize,
    pub example_clips: usize,
    pub example_frames: usize,
    /// Output frames, and how many of them the source constrains.
    pub frames: usize,
    pub known_frames: usize,
    /// Target size / source size (scales the root trajectory with `RootMotion::Source`).
    pub size_ratio: f64,
    pub seed: u64,
    /// Things the user should know (patch shrunk, levels dropped, frames past the source...).
    pub notes: Vec<String>,
}

#[derive(Clone, Debug, Default)]
pub struct LevelReport {
    /// Synthesised frames at this level.
    pub frames: usize,
    /// Example frames and patches in this level's database.
    pub example_frames: usize,
    pub example_patches: usize,
    /// Matching-and-blending steps run (0 when no example clip is a patch long here).
    pub steps: usize,
    /// Mean distance (weighted mean squared difference) of the chosen patches, last step.
    pub mean_match_cost: f64,
    /// The same for every step.
    pub step_costs: Vec<f64>,
}

#[derive(Clone, Debug, Default)]
pub struct Timings {
    /// Checks and feature extraction.
    pub prepare: Duration,
    /// Pyramid: resampling, projection, matching and blending.
    pub synthesis: Duration,
    /// Decoding the result into a motion.
    pub decode: Duration,
    pub total: Duration,
}

/// Retarget `source` (on `source_skeleton`) to `target_skeleton`, learning the target's style
/// from `examples` (motions on `target_skeleton`), with the bound joints of `map` as
/// (source joint, target joint) index pairs. The source and examples should share a frame
/// rate (see `resample`); the result has the examples' frame time.
pub fn retarget(
    source: &Motion,
    source_skeleton: &Skeleton,
    examples: &[Motion],
    target_skeleton: &Skeleton,
    map: &JointMap,
    settings: &Settings,
) -> Result<Retargeted, RetargetError> {
    let start = Instant::now();
    let plan = Plan::new(source, source_skeleton, examples, target_skeleton, map, settings)?;
    let prepare = start.elapsed();
    plan.run(settings.seed, start, prepare)
}

/// `retarget` once per seed (the `-n` diverse samples), in parallel. Each result is the one
/// `retarget` gives with that seed.
pub fn retarget_samples(
    source: &Motion,
    source_skeleton: &Skeleton,
    examples: &[Motion],
    target_skeleton: &Skeleton,
    map: &JointMap,
    settings: &Settings,
    seeds: &[u64],
) -> Result<Vec<Retargeted>, RetargetError> {
    let start = Instant::now();
    let plan = Plan::new(source, source_skeleton, examples, target_skeleton, map, settings)?;
    let prepare = start.elapsed();
    seeds.par_iter().map(|&seed| plan.run(seed, Instant::now(), prepare)).collect()
}

/// Most frames `resample` produces (a day at 1000 fps is far beyond any clip).
pub const RESAMPLE_MAX_FRAMES: usize = 100_000_000;

/// `motion` at `fps` frames per second over the same duration: rotations slerped, translations
/// interpolated linearly. A one-frame motion only changes its frame time; a motion without a
/// valid frame time, a non-positive `fps`, or a rate that would give more than
/// `RESAMPLE_MAX_FRAMES` frames returns the motion unchanged (callers compare frame times).
pub fn resample(motion: &Motion, fps: f64) -> Motion {
    if !(fps.is_finite() && fps > 0.0 && motion.frame_time.is_finite() && motion.frame_time > 0.0) {
        return motion.clone();
    }
    if motion.frames.saturating_sub(1) as f64 * motion.frame_time * fps >= RESAMPLE_MAX_FRAMES as f64 {
        return motion.clone();
    }
    let duration = motion.frames.saturating_sub(1) as f64 * motion.frame_time;
    let frames = if motion.frames == 0 { 0 } else { (duration * fps).round() as usize + 1 };
    let at: Vec<f64> = (0..frames).map(|t| t as f64 / fps / motion.frame_time).collect();
    Motion { frame_time: 1.0 / fps, ..motion.interpolate(&at) }
}

/// Everything a run needs that does not depend on the seed.
struct Plan<'a> {
    settings: &'a Settings,
    target: &'a Skeleton,
    /// Per example clip: matched channels and payload (rotation features when matching on
    /// points; width 0 when matching on rotations).
    clips: Vec<(Channels, Channels)>,
    /// Source values of the bound channels at full output length (matched, payload).
    source: (Channels, Channels),
    /// Bound channels (matched, payload), not counting `world` blocks.
    mask: (Vec<bool>, Vec<bool>),
    /// Channel weights for matching.
    weights: Vec<f32>,
    /// How much the source constrains each output frame (1 at known frames, 0 elsewhere).
    known: Vec<f32>,
    /// Target joints bound with `BoundRotation::World` (their source values are root-relative
    /// world rotations, turned into local ones against the synthesis at projection time).
    world: Vec<usize>,
    /// Joints whose rotation world projection needs (ancestors of `world` joints).
    world_needed: Vec<bool>,
    frames: usize,
    patch: usize,
    levels: Vec<usize>,
    scale: f64,
    root_start: (f64, f64),
    frame_time: f64,
    report: Report,
}

impl<'a> Plan<'a> {
    fn new(
        source: &Motion,
        source_skeleton: &Skeleton,
        examples: &[Motion],
        target: &'a Skeleton,
        map: &JointMap,
        settings: &'a Settings,
    ) -> Result<Plan<'a>, RetargetError> {
        settings.validate()?;
        check_inputs(source, source_skeleton, examples, target, map)?;
        let jt = target.len();
        let frames = settings.frames.unwrap_or(source.frames);
        let mut notes = Vec::new();

        // Which output frames the source constrains.
        let key: Vec<usize> = match &settings.key_frames {
            Some(k) => {
                if let Some(&frame) = k.iter().find(|&&f| f >= source.frames) {
                    return Err(RetargetError::KeyFrame { frame, frames: source.frames });
                }
                let mut k = k.clone();
                k.sort_unstable();
                k.dedup();
                k
            }
            None => (0..source.frames).collect(),
        };
        let key: Vec<usize> = key.into_iter().filter(|&f| f < frames).collect();
        if frames > source.frames {
            notes.push(format!(
                "output frames {}..{} are past the source's end ({} frames): synthesised from the examples alone",
                source.frames, frames, source.frames
            ));
        }
        if key.is_empty() {
            notes.push("no source frame falls inside the output: the result is unconditioned".to_string());
        }
        if map.is_empty() && settings.root_motion == RootMotion::Examples {
            notes.push("nothing is bound: the result is an unconditioned mix of the examples".to_string());
        }
        let mut known = vec![0.0f32; frames];
        for &f in &key {
            known[f] = 1.0;
        }

        let scale = channels::feature_scale(target);
        let ratio = features::size_ratio(source_skeleton, target);
        let points = settings.repr != Repr::Rotation;
        let clips: Vec<(Channels, Channels)> = examples
            .iter()
            .map(|e| {
                let rot = channels::rotation_features(e, scale);
                if points {
                    (features::point_features(e, target, settings.repr, scale), rot)
                } else {
                    (rot, Channels::zeros(e.frames, 0))
                }
            })
            .collect();
        let (mw, pw) = (clips[0].0.width, clips[0].1.width);

        // Source values of the bound channels, one row per source frame (then stretched to the
        // output's frames below).
        let mut src_m = Channels::zeros(source.frames, mw);
        let mut src_p = Channels::zeros(source.frames, pw);
        let (mut mask_m, mut mask_p) = (vec![false; mw], vec![false; pw]);
        let mut world = Vec::new();
        let source_world = (settings.bound_rotation == BoundRotation::World).then(|| source.forward_kinematics(source_skeleton));
        let js = source.joints;
        {
            // Rotation blocks go to the matched channels or to the payload.
            let (rot_c, rot_mask) = if points { (&mut src_p, &mut mask_p) } else { (&mut src_m, &mut mask_m) };
            for &(s, t) in map {
                let align = features::alignment(source_skeleton, s, target, t);
                let world_joint = source_world.is_some() && t != 0;
                if world_joint {
                    world.push(t);
                } else {
                    rot_mask[6 * t..6 * t + 6].iter_mut().for_each(|m| *m = true);
                }
                for f in 0..source.frames {
                    let local = source.rotations[f * js + s];
                    let q = match (&source_world, settings.bound_rotation) {
                        (Some(w), _) if world_joint => w.rotations[f * js].inverse() * w.rotations[f * js + s],
                        (_, BoundRotation::Aligned) => align.inverse() * local * align,
                        _ => local,
                    };
                    for (slot, v) in rot_c.row_mut(f)[6 * t..6 * t + 6].iter_mut().zip(m2m::rotation_to_6d(q)) {
                        *slot = v as f32;
                    }
                }
            }
        }
        if points {
            let p = features::joint_points(source, source_skeleton, settings.repr, scale * ratio);
            for &(s, t) in map.iter().filter(|&&(s, t)| s > 0 && t > 0) {
                mask_m[3 * t..3 * t + 3].iter_mut().for_each(|m| *m = true);
                for f in 0..source.frames {
                    let v = p[f * js + s];
                    src_m.row_mut(f)[3 * t..3 * t + 3].copy_from_slice(&[v.x as f32, v.y as f32, v.z as f32]);
                }
            }
        }
        if settings.root_motion == RootMotion::Source {
            let root = channels::rotation_features(&root_only(source), scale * ratio);
            for (c, mask) in [(&mut src_m, &mut mask_m), (&mut src_p, &mut mask_p)] {
                if c.width == 0 {
                    continue;
                }
                let at = c.width - 3;
                mask[at..].iter_mut().for_each(|m| *m = true);
                for f in 0..source.frames {
                    c.row_mut(f)[at..].copy_from_slice(&root.row(f)[6..9]);
                }
            }
        }
        let src_m = spread(&src_m, &key, frames);
        let src_p = spread(&src_p, &key, frames);

        let mut weights: Vec<f32> = mask_m.iter().map(|&b| if b { settings.alpha } else { 1.0 - settings.alpha }).collect();
        if !points {
            for &t in &world {
                weights[6 * t..6 * t + 6].iter_mut().for_each(|w| *w = settings.alpha);
            }
        }
        let mut world_needed = vec![false; jt];
        for &t in &world {
            let mut j = Some(t);
            while let Some(k) = j {
                world_needed[k] = true;
                j = target.joints[k].parent;
            }
        }

        let longest = examples.iter().map(|e| e.frames).max().unwrap_or(1);
        let patch = pyramid::fit_patch(settings.patch, frames, &examples.iter().map(|e| e.frames).collect::<Vec<_>>(), &mut notes);
        let levels = pyramid::output_levels(frames, longest, patch, settings.coarse_patches, settings.pyramid);
        let root_start = match settings.root_motion {
            RootMotion::Examples => channels::root_start(&examples[0]),
            RootMotion::Source => {
                let (x, z) = channels::root_start(source);
                (x * ratio, z * ratio)
            }
        };
        let report = Report {
            bound: map.len(),
            channels: mw,
            bound_channels: mask_m.iter().filter(|&&b| b).count() + if points { 0 } else { 6 * world.len() },
            patch,
            example_clips: examples.len(),
            example_frames: examples.iter().map(|e| e.frames).sum(),
            frames,
            known_frames: key.len(),
            size_ratio: ratio,
            notes,
            ..Report::default()
        };
        Ok(Plan {
            settings,
            target,
            clips,
            source: (src_m, src_p),
            mask: (mask_m, mask_p),
            weights,
            known,
            world,
            world_needed,
            frames,
            patch,
            levels,
            scale,
            root_start,
            frame_time: examples[0].frame_time,
            report,
        })
    }

    fn run(&self, seed: u64, start: Instant, prepare: Duration) -> Result<Retargeted, RetargetError> {
        let synthesis_start = Instant::now();
        let s = self.settings;
        let mut report = self.report.clone();
        report.seed = seed;
        let level_clips = |len: usize| -> (Vec<Channels>, Vec<Channels>) {
            let scale = len as f64 / self.frames as f64;
            self.clips
                .iter()
                .map(|(m, p)| {
                    let n = ((m.frames as f64 * scale).round() as usize).max(1);
                    (m.resize(n), p.resize(n))
                })
                .unzip()
        };

        // Initial synthesis: the examples' coarsest level, stretched to the first level's
        // length, plus wrapped noise (as the reference; with sigma 10 it is nearly uniform).
        let first = self.levels[0];
        let (cm, cp) = level_clips(first);
        let mut state_m = concat(&cm).resize(first);
        let mut state_p = concat(&cp).resize(first);
        // Bound channels are about to be overwritten by the source: they get no noise. Each
        // frame draws from its own stream (seeded by the seed and the frame), so frames can be
        // filled in parallel with the same values on any thread count.
        for (stream, (c, mask)) in [(&mut state_m, &self.mask.0), (&mut state_p, &self.mask.1)].into_iter().enumerate() {
            let free: Vec<usize> = (0..c.width).filter(|&k| !mask[k]).collect();
            if c.width == 0 {
                continue;
            }
            let stream = stream as u64;
            let sigma = s.noise_sigma as f32;
            c.data.par_chunks_mut(c.width).enumerate().for_each(|(t, row)| {
                let mut gauss = PolarGaussian::new(stream_seed(seed, stream, t as u64));
                for &k in &free {
                    let x = row[k] + sigma * gauss.draw();
                    // fmod(x, 1) as the reference. The integer cast truncates like fmod without
                    // a library call; |x| is far below i64's range (sigma is at most 1e6).
                    row[k] = x - (x as i64) as f32;
                }
            });
        }
        // Bound channels start from the source everywhere (interpolated between key frames).
        let ones = vec![1.0f32; first];
        self.project(&mut state_m, &mut state_p, first, &ones);

        for (l, &len) in self.levels.iter().enumerate() {
            if l > 0 {
                state_m = state_m.resize(len);
                state_p = state_p.resize(len);
            }
            self.project(&mut state_m, &mut state_p, len, &resize_weights(&self.known, len));
            let (cm, cp) = if len == self.frames {
                (self.clips.iter().map(|c| c.0.clone()).collect(), self.clips.iter().map(|c| c.1.clone()).collect())
            } else {
                level_clips(len)
            };
            let bank = nn::Bank::new(cm, cp, &self.weights, self.patch);
            let mut level = LevelReport { frames: len, example_frames: bank.frames(), example_patches: bank.len(), ..LevelReport::default() };
            if bank.len() > 0 && len >= self.patch {
                for k in 0..s.steps {
                    // Diversity: each level's first match draws among the few nearest patches
                    // (see `Settings::sample_choices`); the level's later steps are plain
                    // nearest neighbours, which pull the draw back into a coherent motion.
                    let sample = (k == 0).then_some(nn::Sampling { choices: s.sample_choices, seed });
                    let r = nn::step(&state_m, &bank, &self.weights, s.completeness, sample);
                    state_m = r.matched;
                    if state_p.width > 0 {
                        state_p = r.payload;
                    }
                    level.step_costs.push(r.cost);
                }
            } else {
                report.notes.push(format!("level of {len} frames: no example clip is a patch long here, matching skipped"));
            }
            level.steps = level.step_costs.len();
            level.mean_match_cost = level.step_costs.last().copied().unwrap_or(0.0);
            report.levels.push(level);
        }
        if s.copy_bound {
            self.project(&mut state_m, &mut state_p, self.frames, &self.known);
        }
        let synthesis = synthesis_start.elapsed();

        let decode_start = Instant::now();
        let rot = if state_p.width > 0 { &state_p } else { &state_m };
        let motion = channels::decode(rot, self.target, self.scale, self.root_start, self.frame_time)?;
        report.timings = Timings { prepare, synthesis, decode: decode_start.elapsed(), total: prepare + start.elapsed() };
        Ok(Retargeted { motion, report })
    }

    /// Set the bound channels of a `len`-frame synthesis from the source, frame t weighted by
    /// `known[t]` (1: the source's value, 0: keep the synthesis).
    fn project(&self, state_m: &mut Channels, state_p: &mut Channels, len: usize, known: &[f32]) {
        // Only resample the source when something reads it (it is as wide as the synthesis).
        let world = !self.world.is_empty();
        let needed = |mask: &[bool], rotations: bool| mask.iter().any(|&b| b) || (world && rotations);
        let points = state_p.width > 0;
        let src_m = source_at(&self.source.0, needed(&self.mask.0, !points), len);
        let src_p = source_at(&self.source.1, needed(&self.mask.1, points), len);
        for (state, src, mask) in [(&mut *state_m, &*src_m, &self.mask.0), (&mut *state_p, &*src_p, &self.mask.1)] {
            let bound: Vec<usize> = (0..mask.len()).filter(|&c| mask[c]).collect();
            if bound.is_empty() {
                continue;
            }
            for (t, &k) in known.iter().enumerate().take(len) {
                if k <= 0.0 {
                    continue;
                }
                let (row, srow) = (state.row_mut(t), src.row(t));
                for &c in &bound {
                    row[c] += k * (srow[c] - row[c]);
                }
            }
        }
        if !self.world.is_empty() {
            let (state, src) = if state_p.width > 0 { (state_p, &*src_p) } else { (state_m, &*src_m) };
            self.project_world(state, src, known);
        }
    }

    /// `BoundRotation::World`: the local rotation that gives each bound joint the source's
    /// root-relative orientation under the synthesis's own parent rotations.
    fn project_world(&self, state: &mut Channels, src: &Channels, known: &[f32]) {
        let width = state.width;
        let joints = self.target.joints.as_slice();
        state.data.par_chunks_mut(width).zip(known.par_iter()).enumerate().for_each(|(t, (row, &k))| {
            if k <= 0.0 {
                return;
            }
            let mut relative = vec![DQuat::IDENTITY; joints.len()];
            for j in 1..joints.len() {
                if !self.world_needed[j] {
                    continue;
                }
                let parent = joints[j].parent.map(|p| relative[p]).unwrap_or(DQuat::IDENTITY);
                let block = 6 * j..6 * j + 6;
                if self.world.contains(&j) {
                    let want = m2m::rotation_from_6d(std::array::from_fn(|i| src.row(t)[6 * j + i] as f64));
                    let six = m2m::rotation_to_6d(parent.inverse() * want);
                    for (slot, v) in row[block.clone()].iter_mut().zip(six) {
                        *slot += k * (v as f32 - *slot);
                    }
                }
                let local = m2m::rotation_from_6d(std::array::from_fn(|i| row[6 * j + i] as f64));
                relative[j] = parent * local;
            }
        });
    }
}

fn check_inputs(source: &Motion, source_skeleton: &Skeleton, examples: &[Motion], target: &Skeleton, map: &JointMap) -> Result<(), RetargetError> {
    if source_skeleton.is_empty() {
        return Err(RetargetError::EmptySkeleton { side: "source" });
    }
    if target.is_empty() {
        return Err(RetargetError::EmptySkeleton { side: "target" });
    }
    // Forward kinematics (position and velocity features, world rotations) needs parents
    // before children and one root.
    source_skeleton.validate().map_err(|error| RetargetError::Skeleton { side: "source", error })?;
    target.validate().map_err(|error| RetargetError::Skeleton { side: "target", error })?;
    if source.joints != source_skeleton.len()
        || source.rotations.len() != source.frames * source.joints
        || source.translations.len() != source.frames * source.joints
    {
        return Err(RetargetError::SourceSkeleton { joints: source.joints, skeleton: source_skeleton.len() });
    }
    if source.frames == 0 {
        return Err(RetargetError::ZeroFrames { what: "the source motion".into() });
    }
    if examples.is_empty() {
        return Err(RetargetError::NoExamples);
    }
    for (i, e) in examples.iter().enumerate() {
        if e.joints != target.len() || e.rotations.len() != e.frames * e.joints || e.translations.len() != e.frames * e.joints {
            return Err(RetargetError::ExampleSkeleton { example: i, joints: e.joints, skeleton: target.len() });
        }
        if e.frames == 0 {
            return Err(RetargetError::ZeroFrames { what: format!("example clip {i}") });
        }
    }
    for (what, m) in
        std::iter::once(("the source motion".to_string(), source)).chain(examples.iter().enumerate().map(|(i, e)| (format!("example clip {i}"), e)))
    {
        let bad = m.rotations.iter().zip(&m.translations).position(|(q, p)| !(q.is_finite() && p.is_finite()));
        if let Some(k) = bad {
            return Err(RetargetError::NonFinite { what, frame: k / m.joints, joint: k % m.joints });
        }
    }
    for (pair, &(s, t)) in map.iter().enumerate() {
        if s >= source_skeleton.len() {
            return Err(RetargetError::MapIndex { pair, side: "source", index: s, joints: source_skeleton.len() });
        }
        if t >= target.len() {
            return Err(RetargetError::MapIndex { pair, side: "target", index: t, joints: target.len() });
        }
        if let Some(first) = map[..pair].iter().position(|&(_, u)| u == t) {
            return Err(RetargetError::MapDuplicate { first, second: pair, joint: t, name: target.joints[t].name.clone() });
        }
    }
    Ok(())
}

/// The source channels at `len` frames when `needed` (else an empty stand-in). At the source's
/// own length they are borrowed: on long clips a copy is as big as the synthesis and would
/// raise the peak memory.
fn source_at(c: &Channels, needed: bool, len: usize) -> std::borrow::Cow<'_, Channels> {
    if !needed {
        std::borrow::Cow::Owned(Channels::zeros(0, c.width))
    } else if c.frames == len {
        std::borrow::Cow::Borrowed(c)
    } else {
        std::borrow::Cow::Owned(c.resize(len))
    }
}

/// Only the root's translations of a motion, as a one-joint motion.
fn root_only(m: &Motion) -> Motion {
    let j = m.joints;
    Motion {
        frames: m.frames,
        joints: 1,
        frame_time: m.frame_time,
        rotations: vec![DQuat::IDENTITY; m.frames],
        translations: (0..m.frames).map(|f| m.translations[f * j]).collect(),
    }
}

/// Source rows at the key frames, laid out on `frames` output frames: linear interpolation
/// between key frames, the nearest key frame's value before the first and after the last.
fn spread(src: &Channels, key: &[usize], frames: usize) -> Channels {
    let mut out = Channels::zeros(frames, src.width);
    if src.width == 0 || key.is_empty() {
        return out;
    }
    let mut next = 0;
    for t in 0..frames {
        while next < key.len() && key[next] < t {
            next += 1;
        }
        let dst = out.row_mut(t);
        match (next.checked_sub(1).map(|i| key[i]), key.get(next).copied()) {
            (_, Some(b)) if b == t => dst.copy_from_slice(src.row(b)),
            (Some(a), Some(b)) => {
                let w = (t - a) as f32 / (b - a) as f32;
                for ((d, x), y) in dst.iter_mut().zip(src.row(a)).zip(src.row(b)) {
                    *d = x + (y - x) * w;
                }
            }
            (Some(a), None) => dst.copy_from_slice(src.row(a)),
            (None, Some(b)) => dst.copy_from_slice(src.row(b)),
            (None, None) => {}
        }
    }
    out
}

/// Per-frame source weights at another length (linear, as the channels).
fn resize_weights(known: &[f32], len: usize) -> Vec<f32> {
    Channels { frames: known.len(), width: 1, data: known.to_vec() }.resize(len).data
}

/// Clips one after the other in time (the reference's initial motion).
fn concat(clips: &[Channels]) -> Channels {
    let width = clips.first().map(|c| c.width).unwrap_or(0);
    let frames = clips.iter().map(|c| c.frames).sum();
    let mut data = Vec::with_capacity(frames * width);
    for c in clips {
        data.extend_from_slice(&c.data);
    }
    Channels { frames, width, data }
}
