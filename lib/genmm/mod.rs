//! Example-based motion generation without training: generative motion matching (GenMM, Li et
//! al., SIGGRAPH 2023), the patch-based synthesis Motion2Motion is built on.
//!
//! Given a few clips of one skeleton, a new motion of any length is synthesised coarse to fine
//! over a pyramid in time (`patch::pyramid`, the same level lengths as `retarget`):
//!
//! 1. at the coarsest level the synthesis starts as a seeded random walk through the examples'
//!    coarse patches (`arrangement`): from a random patch it runs on in its clip for a patch,
//!    then jumps to a place whose predecessor looks like where it is (or runs on when there is
//!    none), cross-fading over a patch at each jump;
//! 2. at every level, `steps` times, each patch of the synthesis is replaced by its nearest
//!    example patch of that level (with GenMM's completeness normalisation, which favours
//!    example patches not used yet) and overlapping patches are averaged (`patch::nn::step`);
//! 3. the result is upsampled to the next level's length and refined again.
//!
//! Seeds differ only in the random walk; the matching is deterministic, so the same seed gives
//! the same bytes on any thread count. The channels are Motion2Motion's (`patch::channels`:
//! local 6D rotations and the root's dx, y, dz) with the root's heading taken out
//! (`heading`: the root's rotation relative to its heading, its velocity in the heading's
//! frame and the heading's turning rate), so the result decodes to a `Motion` on the examples'
//! skeleton through `patch::channels::decode`.
//!
//! Editing (`Keep`): kept frames and joints of a reference clip are imposed on the synthesis
//! at every level (the reference resampled to the level's length, blended in by the kept
//! share of each frame) and after every matching step, so the matched patches fit around them;
//! in the decoded motion the kept cells are the reference's exactly, and the root's heading and
//! horizontal drift between kept frames are spread over the generated stretch so the path meets
//! them without a jump.
//!
//! What differs from the GenMM paper's code, measured with `mo-metrics generation` on zoo and
//! corpus clips (docs/metrics.md, BENCHMARKS.md):
//! * the start is a random walk through example patches instead of the examples stretched in
//!   time plus wrapped noise: with noise of sigma 1 the matching settles on near-static motion
//!   for the corpus chicken, flamingo and monkey walks (energy ratio 0.3-0.5), with sigma 10
//!   (Motion2Motion's reference) the zoo walks cover less (47-75% calibrated coverage); random
//!   segments with arbitrary seams make the matching re-phase the gait at every seam (bursts of
//!   speed, energy ratio up to 1.3); jumps between similar places keep it nearer 1;
//! * the coarsest level is twice GenMM's (10 patches, not 5) of the median example, not the
//!   longest, and the walk runs on 4 patches before it looks for a jump (`Settings::default`):
//!   with GenMM's 5 the zoo's run and turn clips are rarely reached or are matched into the walk
//!   at the finer levels (energy ratio 0.6-0.7 on the zoo quadruped and biped). Measured on the
//!   longest, three dog_mann clips of 1531 (standing), 593 and 155 (running) frames at 60 fps
//!   were squeezed 14 times, the run to a single coarse patch, and the samples stood (energy
//!   ratio 0.13; 0.42 with the equal shares below, 0.70 with both);
//! * the walk gives every clip an equal share, however long it is (as the metrics weigh the
//!   clips, and as a user who brings a long idle and a short run expects to see both): it starts
//!   in a clip drawn uniformly, at a clip's end it jumps into another clip when it can, and
//!   jumps are drawn weighted by how far their clip is behind its share (`balanced`). Drawn
//!   uniformly, an idle clip (whose end looks most like its own middle) held the walk for the
//!   rest of the sample: energy 0.77 / 0.72 on the zoo quadruped and biped and 0.66 on a real
//!   chicken's three clips (walk, egg laying, idle pecking). Over 40 samples
//!   (`tools/eval_generation.py --model genmm=examples -n 40 --frames 200 --seed 100`; zoo
//!   quadruped / biped / dragon, chicken's three, the dog's three): with uniform jumps 0.79 /
//!   0.84 / 0.86 / 0.64 (dog not measured); with shares by length 0.89 / 0.90 / 0.99 / 0.93
//!   (dog 0.13 over 8 samples at seed 7); with equal shares 0.88 / 0.84 / 0.84 / 0.96 / 0.70,
//!   and 0.88 / 0.84 / 0.85 / 0.96 / 0.85 since jumps are drawn only among near-equals
//!   (`NEAR_BEST`);
//! * the root's heading is a turning rate, so a stretch that turned a little can follow one that
//!   did not without the body snapping round;
//! * the example pyramid follows the synthesis's time scale at every level (as in `retarget`),
//!   so an output longer than the examples has proportionally longer levels.

pub mod clips;
pub(crate) mod heading;
#[cfg(test)]
mod tests;

use crate::motion::Motion;
use crate::patch::channels::{self, Channels};
use crate::patch::{nn, pyramid};
use crate::rng::{stream_seed, SplitMix64};
use crate::skeleton::Skeleton;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// The seed stream of the coarse arrangement.
const ARRANGEMENT_STREAM: u64 = 0x6e6d_6d01;

#[derive(Debug, thiserror::Error)]
pub enum GenmmError {
    #[error("no example clips were given (at least one is needed)")]
    NoExamples,
    #[error("the skeleton has no joints")]
    EmptySkeleton,
    #[error("the skeleton: {0}")]
    Skeleton(crate::skeleton::SkeletonError),
    #[error("{what} has {joints} joints but the skeleton has {skeleton}: all clips must share one skeleton")]
    JointCount { what: String, joints: usize, skeleton: usize },
    #[error("{what} has zero frames")]
    ZeroFrames { what: String },
    #[error("{what}: non-finite value at frame {frame}, joint {joint}")]
    NonFinite { what: String, frame: usize, joint: usize },
    #[error("setting {what} = {value}: expected {expected}")]
    Setting { what: String, value: String, expected: String },
    #[error("kept frame {frame} is past the end of the reference ({frames} frames)")]
    KeptFrame { frame: usize, frames: usize },
    #[error("the keep mask has {found} {what}, expected {expected}")]
    KeepShape { what: &'static str, found: usize, expected: usize },
    #[error("{0}")]
    Budget(#[from] crate::budget::BudgetError),
    /// A reference clip of an edit that does not fit the examples.
    #[error("{0}")]
    Reference(String),
    #[error("decoding the result")]
    Decode(#[from] crate::repr::m2m::M2mError),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Patch length in frames (GenMM: 11). Shrunk to the longest example / the output when
    /// those are shorter; the report says so.
    pub patch: usize,
    /// Matching-and-blending iterations per pyramid level (GenMM: 3).
    pub steps: usize,
    /// Length ratio between consecutive pyramid levels (GenMM: 0.75).
    pub pyramid: f64,
    /// The coarsest level holds about `coarse_patches * patch` frames of the median example
    /// (GenMM: '5x_patchsize' of the longest; we use 10 of the median, see `Default`).
    pub coarse_patches: f64,
    /// Completeness normalisation (GenMM's alpha, 0.01): each example patch's distances are
    /// divided by this plus its distance to its closest query patch. `None`: plain nearest
    /// neighbours.
    pub completeness: Option<f32>,
    /// The first match of every level picks among this many nearest example patches (near ties
    /// only, drawn from the seed); 1 = always the nearest, GenMM's behaviour.
    pub sample_choices: usize,
    /// How far the coarse random walk runs on in a clip before it looks for a jump, in patches
    /// (4, see `Default`; longer runs mean fewer, but more noticeable, seams).
    pub segment: usize,
    /// Output length in frames; `None` = the longest example's (with a reference: the caller
    /// decides).
    pub frames: Option<usize>,
}

/// `coarse_patches` and `segment` as measured with `tools/eval_generation.py` (200 frames, 40
/// seeds; zoo quadruped_v0 / biped_v0 / dragon_v7, corpus chicken / flamingo walks): GenMM's 5
/// with a segment of 1 gives energy ratios 0.67 / 0.59 / 0.86 / 1.23 / 1.21 against the clips,
/// 10 and 4 give 0.79 / 0.84 / 0.86 / 1.18 / 1.17 (calibrated coverage 100% for both). At 5 the
/// zoo clips are squeezed about 5x at the coarsest level and the walk places only ~27 patches:
/// a sample is one or two clips, the run is rarely among them and the turn is matched into the
/// walk at the finer levels. Fewer seams also mean less gait re-phasing on one short clip
/// (which speeds it up). Also measured, and not what slows the zoo motions down (energy within
/// 0.03 of plain averaging): overlapping votes weighted toward patch centres or by match
/// distance, the best patch's frames only, 5 steps a level, no completeness term.
impl Default for Settings {
    fn default() -> Settings {
        Settings { patch: 11, steps: 3, pyramid: 0.75, coarse_patches: 10.0, completeness: Some(0.01), sample_choices: 1, segment: 4, frames: None }
    }
}

impl Settings {
    fn validate(&self) -> Result<(), GenmmError> {
        let bad = |what: &str, value: String, expected: &str| Err(GenmmError::Setting { what: what.to_string(), value, expected: expected.to_string() });
        if self.patch == 0 {
            return bad("patch", "0".into(), "at least 1 frame");
        }
        if self.steps == 0 {
            return bad("steps", "0".into(), "at least 1 matching step per level");
        }
        if self.segment == 0 {
            return bad("segment", "0".into(), "at least 1 patch");
        }
        if self.sample_choices == 0 {
            return bad("sample_choices", "0".into(), "at least 1 candidate patch (1 = always the nearest)");
        }
        if !(self.pyramid > 0.0 && self.pyramid < 1.0) {
            return bad("pyramid", self.pyramid.to_string(), "a ratio in (0, 1)");
        }
        if !(self.coarse_patches.is_finite() && self.coarse_patches > 0.0) {
            return bad("coarse_patches", self.coarse_patches.to_string(), "a positive number");
        }
        if let Some(c) = self.completeness {
            if !(c.is_finite() && c > 0.0) {
                return bad("completeness", c.to_string(), "a positive number");
            }
        }
        if self.frames == Some(0) {
            return Err(GenmmError::ZeroFrames { what: "the requested output".into() });
        }
        Ok(())
    }
}

/// What an edit keeps of a reference clip (on the examples' skeleton and frame time).
#[derive(Clone, Debug)]
pub struct Keep<'a> {
    pub reference: &'a Motion,
    /// Per output frame: the whole frame is the reference's (only frames the reference has).
    pub frames: Vec<bool>,
    /// Per joint: the joint is the reference's over every output frame the reference has (the
    /// root's translation too when joint 0 is kept).
    pub joints: Vec<bool>,
}

/// A generated motion and how it was made.
#[derive(Clone, Debug)]
pub struct Generated {
    /// On the examples' skeleton, at the examples' frame time.
    pub motion: Motion,
    pub report: Report,
}

#[derive(Clone, Debug, Default)]
pub struct Report {
    pub seed: u64,
    /// Patch length used.
    pub patch: usize,
    pub frames: usize,
    /// Pyramid levels, coarse to fine.
    pub levels: Vec<LevelReport>,
    /// Matching, blending and decoding of this sample.
    pub synthesis: Duration,
    /// Things the user should know (patch shrunk, clips too short to use...).
    pub notes: Vec<String>,
}

#[derive(Clone, Debug, Default)]
pub struct LevelReport {
    pub frames: usize,
    pub example_patches: usize,
    /// Mean distance of the chosen patches after each step.
    pub step_costs: Vec<f64>,
}

/// Generate one motion per seed from `examples` (clips of `skeleton` sharing a frame time), in
/// parallel; each result depends only on its seed.
pub fn generate(examples: &[Motion], skeleton: &Skeleton, settings: &Settings, keep: Option<&Keep>, seeds: &[u64]) -> Result<Vec<Generated>, GenmmError> {
    let plan = Plan::new(examples, skeleton, settings, keep)?;
    seeds.par_iter().map(|&seed| plan.run(seed)).collect()
}

/// Everything a run needs that does not depend on the seed.
struct Plan<'a> {
    settings: &'a Settings,
    skeleton: &'a Skeleton,
    keep: Option<&'a Keep<'a>>,
    frames: usize,
    patch: usize,
    /// Every example's channels at full length.
    clips: Vec<Channels>,
    /// Per level, coarse to fine: its length and the example patches at its time scale.
    levels: Vec<(usize, nn::Bank)>,
    /// Per level with an edit: the reference's channels and the kept share of each cell.
    kept: Vec<Option<(Channels, Channels)>>,
    weights: Vec<f32>,
    scale: f64,
    root_start: (f64, f64),
    /// The root's local axis that tells its heading, and the heading at frame 0.
    axis: glam::DVec3,
    yaw_start: f64,
    frame_time: f64,
    notes: Vec<String>,
}

impl<'a> Plan<'a> {
    fn new(examples: &'a [Motion], skeleton: &'a Skeleton, settings: &'a Settings, keep: Option<&'a Keep<'a>>) -> Result<Plan<'a>, GenmmError> {
        settings.validate()?;
        check_inputs(examples, skeleton, keep)?;
        let longest = examples.iter().map(|e| e.frames).max().unwrap_or(1);
        let frames = settings.frames.unwrap_or(longest);
        let mut notes = Vec::new();
        let patch = pyramid::fit_patch(settings.patch, frames, &examples.iter().map(|e| e.frames).collect::<Vec<_>>(), &mut notes);
        // The pyramid's scale from the median clip that has a patch, not the longest: one long
        // clip beside short ones squeezed them to a patch or two at the coarsest level.
        let mut by_length: Vec<usize> = examples.iter().map(|e| e.frames).filter(|&f| f >= patch).collect();
        by_length.sort_unstable();
        let median = by_length.get(by_length.len() / 2).copied().unwrap_or(longest);
        let lengths = pyramid::output_levels(frames, median, patch, settings.coarse_patches, settings.pyramid);
        let scale = channels::feature_scale(skeleton);
        let width = channels::rotation_width(skeleton.len()) + 1;
        // The banks of every level are kept for all seeds: each holds its clips twice (weighted
        // and plain), rows padded to a multiple of 8 floats.
        let example_frames: usize = examples.iter().map(|e| e.frames).sum();
        let level_frames: u128 = lengths.iter().map(|&len| example_frames as u128 * len as u128 / frames as u128 + examples.len() as u128).sum();
        crate::budget::check("the examples' patch pyramid", level_frames, 2 * 4 * (width.div_ceil(8) * 8))?;
        if keep.is_some() {
            crate::budget::check("the kept part at every level", lengths.iter().map(|&l| l as u128).sum(), 2 * 4 * width)?;
        }
        let axis = heading::heading_axis(examples);
        let clips: Vec<Channels> = examples.par_iter().map(|e| heading::encode(e, scale, axis)).collect();
        // Every channel weighs the same, as in GenMM (weighting the root more was measured: no
        // gain).
        let weights = vec![1.0f32; width];
        let levels = lengths
            .iter()
            .map(|&len| {
                let level = at_level(&clips, len, frames);
                let payload = level.iter().map(|c| Channels::zeros(c.frames, 0)).collect();
                (len, nn::Bank::new(level, payload, &weights, patch))
            })
            .collect::<Vec<_>>();
        let kept = match keep {
            Some(k) => {
                let (reference, share) = kept_channels(k, skeleton, frames, scale, axis);
                lengths.iter().map(|&len| Some((reference.resize(len), share.resize(len)))).collect()
            }
            None => vec![None; lengths.len()],
        };
        let start = keep.map(|k| k.reference).unwrap_or(&examples[0]);
        let root_start = channels::root_start(start);
        let yaw_start = heading::yaw(start.rotations[0], axis);
        Ok(Plan {
            settings,
            skeleton,
            keep,
            frames,
            patch,
            clips,
            levels,
            kept,
            weights,
            scale,
            root_start,
            axis,
            yaw_start,
            frame_time: examples[0].frame_time,
            notes,
        })
    }

    fn run(&self, seed: u64) -> Result<Generated, GenmmError> {
        let start = Instant::now();
        let s = self.settings;
        let mut report = Report { seed, patch: self.patch, frames: self.frames, notes: self.notes.clone(), ..Report::default() };
        let (first, bank) = &self.levels[0];
        let mut state = if bank.len() > 0 {
            arrangement(&bank.matched, &self.weights, *first, self.patch, s.segment * self.patch, seed)
        } else {
            concat(&at_level(&self.clips, *first, self.frames)).resize(*first)
        };
        for (l, (len, bank)) in self.levels.iter().enumerate() {
            if l > 0 {
                state = state.resize(*len);
            }
            impose(&mut state, self.kept[l].as_ref());
            let mut level = LevelReport { frames: *len, example_patches: bank.len(), step_costs: Vec::new() };
            if bank.len() > 0 && *len >= self.patch {
                for k in 0..s.steps {
                    let sample = (k == 0 && s.sample_choices > 1).then_some(nn::Sampling { choices: s.sample_choices, seed });
                    let r = nn::step(&state, bank, &self.weights, s.completeness, sample);
                    state = r.matched;
                    impose(&mut state, self.kept[l].as_ref());
                    level.step_costs.push(r.cost);
                }
            } else {
                report.notes.push(format!("level of {len} frames: no example clip is a patch long here, matching skipped"));
            }
            report.levels.push(level);
        }
        let j = self.skeleton.len();
        let mut yaws = heading::yaws(&state, j, self.yaw_start);
        if let Some(k) = self.keep {
            meet_kept_headings(&mut yaws, k, self.axis);
        }
        let rotation = heading::to_rotation_channels(&state, j, &yaws);
        let mut motion = channels::decode(&rotation, self.skeleton, self.scale, self.root_start, self.frame_time)?;
        if let Some(k) = self.keep {
            restore_kept(&mut motion, k);
        }
        report.synthesis = start.elapsed();
        Ok(Generated { motion, report })
    }
}

/// The clips at the time scale of a level of `len` output frames (the output has `out`).
fn at_level(clips: &[Channels], len: usize, out: usize) -> Vec<Channels> {
    if len == out {
        clips.to_vec()
    } else {
        clips.iter().map(|c| c.resize(level_length(c.frames, len, out))).collect()
    }
}

/// Frames of a clip of `frames` frames at the time scale of a level of `len` output frames
/// (the output has `out` frames).
fn level_length(frames: usize, len: usize, out: usize) -> usize {
    ((frames as f64 * len as f64 / out as f64).round() as usize).max(1)
}

fn check_inputs(examples: &[Motion], skeleton: &Skeleton, keep: Option<&Keep>) -> Result<(), GenmmError> {
    if skeleton.is_empty() {
        return Err(GenmmError::EmptySkeleton);
    }
    skeleton.validate().map_err(GenmmError::Skeleton)?;
    if examples.is_empty() {
        return Err(GenmmError::NoExamples);
    }
    let named = examples.iter().enumerate().map(|(i, e)| (format!("example clip {i}"), e));
    for (what, m) in named.chain(keep.map(|k| ("the reference".to_string(), k.reference))) {
        if m.joints != skeleton.len() || m.rotations.len() != m.frames * m.joints || m.translations.len() != m.frames * m.joints {
            return Err(GenmmError::JointCount { what, joints: m.joints, skeleton: skeleton.len() });
        }
        if m.frames == 0 {
            return Err(GenmmError::ZeroFrames { what });
        }
        if let Some(k) = m.rotations.iter().zip(&m.translations).position(|(q, p)| !(q.is_finite() && p.is_finite())) {
            return Err(GenmmError::NonFinite { what, frame: k / m.joints, joint: k % m.joints });
        }
    }
    if let Some(k) = keep {
        if k.joints.len() != skeleton.len() {
            return Err(GenmmError::KeepShape { what: "joints", found: k.joints.len(), expected: skeleton.len() });
        }
        if let Some(frame) = k.frames.iter().enumerate().skip(k.reference.frames).find(|(_, &x)| x).map(|(f, _)| f) {
            return Err(GenmmError::KeptFrame { frame, frames: k.reference.frames });
        }
    }
    Ok(())
}

/// How many of the best transitions a segment's successor is drawn from.
const TRANSITION_CHOICES: usize = 4;

/// A jump is taken when it differs from the last patch placed by at most this many times what
/// running on one frame would.
const TRANSITION_FACTOR: f32 = 2.0;

/// A jump is drawn only among candidates within this factor of the best one's difference. At a
/// 200-frame sample's coarsest level (37 frames) a walk is one or two segments, so the balance
/// (`balanced`) always favoured leaving the clip it started in: at the end of a real dog's short
/// run (155 frames at 60 fps) it left for the idle or the walk (differences 84-86) although the
/// run's own start fitted best (55), and a run filled half its samples. Over 40 samples
/// (`tools/eval_generation.py --model genmm=examples -n 40 --frames 200 --seed 100`) the dog's
/// three clips went from energy ratio 0.70 to 0.85 (1.25: the same); the zoo quadruped, biped
/// and dragon and a chicken's three clips stayed within 0.02 (0.88 / 0.84 / 0.85 / 0.96).
const NEAR_BEST: f32 = 1.5;

/// The coarsest synthesis: a seeded random walk through the clips' patches. It starts at a
/// random patch and runs on in its clip for `segment` patches; then it jumps to a patch whose
/// predecessor looks like the last patch placed (drawn among the `TRANSITION_CHOICES` best that
/// are far from simply running on, see `transition`, and about as close as running on would
/// be), so the pose and its velocity carry over. Without such a jump it runs on, and at a
/// clip's end it takes one of the best jumps there are. Overlapping patches are averaged, so inside a
/// run the blend is the clip itself and a jump cross-fades over a patch between two similar
/// stretches. Without a usable clip: the clips one after the other, stretched to `len`.
fn arrangement(clips: &[Channels], weights: &[f32], len: usize, patch: usize, segment: usize, seed: u64) -> Channels {
    let starts: Vec<usize> = clips.iter().map(|c| (c.frames + 1).saturating_sub(patch)).collect();
    let total: usize = starts.iter().sum();
    if total == 0 || len < patch {
        return concat(clips).resize(len);
    }
    let mut rng = SplitMix64::new(stream_seed(seed, ARRANGEMENT_STREAM, 0));
    let queries = len - patch + 1;
    let mut choice: Vec<(usize, usize)> = Vec::with_capacity(queries);
    let mut placed = vec![0usize; clips.len()];
    while choice.len() < queries {
        let (k, b) = match choice.last() {
            Some(&last) => transition(clips, weights, &starts, &placed, last, patch, &mut rng).unwrap_or_else(|| random_patch(&starts, &mut rng)),
            None => random_patch(&starts, &mut rng),
        };
        // The segment runs on from that patch, up to `segment` patches or the clip's end.
        let run = segment.min(starts[k] - b).min(queries - choice.len());
        choice.extend((0..run).map(|o| (k, b + o)));
        placed[k] += run;
    }
    nn::blend(&choice, clips, len, patch)
}

/// A clip drawn uniformly among those with a patch, then a patch uniformly within it: its clip
/// and first frame. Each clip counts the same however long it is (see `balanced`).
fn random_patch(starts: &[usize], rng: &mut SplitMix64) -> (usize, usize) {
    let usable: Vec<usize> = (0..starts.len()).filter(|&k| starts[k] > 0).collect();
    let k = usable[rng.below(usable.len())];
    (k, rng.below(starts[k]))
}

/// Squared difference of the patches of `a` at frame `i` and of `b` at frame `j`.
fn patch_distance(a: &Channels, i: usize, b: &Channels, j: usize, patch: usize, weights: &[f32]) -> f32 {
    let w = a.width;
    let (x, y) = (&a.data[i * w..(i + patch) * w], &b.data[j * w..(j + patch) * w]);
    x.chunks_exact(w).zip(y.chunks_exact(w)).map(|(p, q)| p.iter().zip(q).zip(weights).map(|((u, v), c)| (c * (u - v)).powi(2)).sum::<f32>()).sum()
}

/// Where to go after patch `last` = (clip, first frame): the next patch of the clip, or a jump
/// to a patch (k, b) whose predecessor (k, b - 1) looks like `last` (see `arrangement`).
/// Candidates are the local minima of that difference (each the best within half a patch of
/// itself), so the choices are distinct places, not neighbouring frames of one. `None` when
/// nothing qualifies.
fn transition(
    clips: &[Channels],
    weights: &[f32],
    starts: &[usize],
    placed: &[usize],
    last: (usize, usize),
    patch: usize,
    rng: &mut SplitMix64,
) -> Option<(usize, usize)> {
    let (lk, lb) = last;
    let clip = &clips[lk];
    let runs_on = lb + 1 < starts[lk];
    // What running on one frame changes.
    let step = match (runs_on, lb > 0) {
        (true, _) => patch_distance(clip, lb, clip, lb + 1, patch, weights),
        (false, true) => patch_distance(clip, lb - 1, clip, lb, patch, weights),
        (false, false) => 0.0,
    };
    // A jump within the same clip goes at least a patch, and at least half the clip, away:
    // short loops (a third of the corpus flamingo's walk) make the matching rock back and forth
    // where they close, which looks like standing still for a second or two.
    let min_jump = patch.max(clip.frames / 2);
    let reach = (patch / 2).max(1);
    let mut minima: Vec<(f32, usize, usize)> = Vec::new();
    for (k, &n) in starts.iter().enumerate() {
        let cost: Vec<f32> =
            (0..n)
                .map(|b| {
                    if b == 0 || (k == lk && b.abs_diff(lb + 1) < min_jump) {
                        f32::INFINITY
                    } else {
                        patch_distance(clip, lb, &clips[k], b - 1, patch, weights)
                    }
                })
                .collect();
        for b in 1..n {
            let around = b.saturating_sub(reach)..(b + reach + 1).min(n);
            if cost[b].is_finite() && cost[around.clone()].iter().enumerate().all(|(o, &c)| c > cost[b] || (c == cost[b] && around.start + o >= b)) {
                minima.push((cost[b], k, b));
            }
        }
    }
    minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Only jumps about as good as the best one: the balance chooses among near-equals, never
    // against a clearly better place (see `NEAR_BEST`).
    let best = minima.first().map_or(0.0, |e| e.0);
    let good: Vec<&(f32, usize, usize)> =
        minima.iter().take(TRANSITION_CHOICES).filter(|e| e.0 <= TRANSITION_FACTOR * step && e.0 <= NEAR_BEST * best).collect();
    if !good.is_empty() {
        let e = good[balanced(&good, starts, placed, rng)];
        return Some((e.1, e.2));
    }
    if runs_on {
        return Some((lk, lb + 1));
    }
    // At a clip's end: one of the few best, as long as it is about as good as the best, in
    // another clip when there is one. A clip's end looks most like its own middle when the clip
    // hardly changes (an idle): looping back there kept the walk in the idle for the rest of
    // the sample, so the zoo's samples moved at 0.72-0.77 of their clips' energy.
    let elsewhere: Vec<(f32, usize, usize)> = minima.iter().copied().filter(|e| e.1 != lk).collect();
    let minima = if elsewhere.is_empty() { minima } else { elsewhere };
    let best = minima.first()?.0;
    let close: Vec<&(f32, usize, usize)> = minima.iter().take(TRANSITION_CHOICES).filter(|e| e.0 <= 2.0 * best).collect();
    let e = close[balanced(&close, starts, placed, rng)];
    Some((e.1, e.2))
}

/// One of the candidate jumps `(cost, clip, frame)`, drawn with each weighed by how far its
/// clip is behind its share: an equal share of the clips over its share of the walk so far. Drawn uniformly, the walk drifted toward clips whose poses resemble each
/// other's (an idle, a stop), where most good jumps lead, and the zoo's samples moved at
/// 0.72-0.77 of their clips' energy; with one clip every weight is equal.
fn balanced(candidates: &[&(f32, usize, usize)], starts: &[usize], placed: &[usize], rng: &mut SplitMix64) -> usize {
    let walked = placed.iter().sum::<usize>() as f64;
    let clips = starts.iter().filter(|&&n| n > 0).count().max(1) as f64;
    let weight: Vec<f64> = candidates
        .iter()
        .map(|e| {
            let share = 1.0 / clips;
            // Laplace-smoothed share of the walk, so an unvisited clip is not infinitely behind.
            let walked_share = (placed[e.1] as f64 + 1.0) / (walked + clips);
            share / walked_share
        })
        .collect();
    let mut r = rng.unit() * weight.iter().sum::<f64>();
    for (i, w) in weight.iter().enumerate() {
        if r < *w {
            return i;
        }
        r -= w;
    }
    candidates.len() - 1
}

/// Clips one after the other in time.
fn concat(clips: &[Channels]) -> Channels {
    let width = clips.first().map(|c| c.width).unwrap_or(0);
    let frames = clips.iter().map(|c| c.frames).sum();
    let mut data = Vec::with_capacity(frames * width);
    for c in clips {
        data.extend_from_slice(&c.data);
    }
    Channels { frames, width, data }
}

/// The reference's channels at the output's length (zero past its end) and the kept share of
/// every cell (1 kept, 0 generated).
fn kept_channels(k: &Keep, skeleton: &Skeleton, frames: usize, scale: f64, axis: glam::DVec3) -> (Channels, Channels) {
    let j = skeleton.len();
    let own = heading::encode(k.reference, scale, axis);
    let width = own.width;
    let mut reference = Channels::zeros(frames, width);
    let mut share = Channels::zeros(frames, width);
    for t in 0..frames.min(own.frames) {
        reference.row_mut(t).copy_from_slice(own.row(t));
        let row = share.row_mut(t);
        if k.frames.get(t).copied().unwrap_or(false) {
            row.iter_mut().for_each(|v| *v = 1.0);
            continue;
        }
        for (joint, _) in k.joints.iter().enumerate().filter(|(_, &kept)| kept) {
            row[6 * joint..6 * joint + 6].iter_mut().for_each(|v| *v = 1.0);
        }
        if k.joints.first().copied().unwrap_or(false) {
            row[6 * j..].iter_mut().for_each(|v| *v = 1.0);
        }
    }
    (reference, share)
}

/// Blend the kept part into the synthesis: each cell moves to the reference's value by its kept
/// share (exactly at shares of 1).
fn impose(state: &mut Channels, kept: Option<&(Channels, Channels)>) {
    let Some((reference, share)) = kept else { return };
    for ((x, &r), &w) in state.data.iter_mut().zip(&reference.data).zip(&share.data) {
        if w >= 1.0 {
            *x = r;
        } else if w > 0.0 {
            *x += w * (r - *x);
        }
    }
}

/// The frames whose root an edit keeps: kept frames, or every reference frame when the root
/// joint is kept.
fn root_anchors(k: &Keep, frames: usize) -> Vec<usize> {
    let known = frames.min(k.reference.frames);
    let root = k.joints.first().copied().unwrap_or(false);
    (0..known).filter(|&t| root || k.frames.get(t).copied().unwrap_or(false)).collect()
}

/// `values[t] += ` the offset at the anchors, linearly between them and held outside them.
fn spread_offsets<T: Copy + std::ops::Add<Output = T>>(values: &mut [T], anchors: &[(usize, T)], lerp: impl Fn(T, T, f64) -> T) {
    if anchors.is_empty() {
        return;
    }
    let mut next = 0;
    for (t, v) in values.iter_mut().enumerate() {
        while next < anchors.len() && anchors[next].0 < t {
            next += 1;
        }
        let shift = match (next.checked_sub(1).map(|i| anchors[i]), anchors.get(next).copied()) {
            (_, Some((b, d))) if b == t => d,
            (Some((a, da)), Some((b, db))) => lerp(da, db, (t - a) as f64 / (b - a) as f64),
            (Some((_, d)), None) | (None, Some((_, d))) => d,
            (None, None) => unreachable!("anchors is not empty"),
        };
        *v = *v + shift;
    }
}

/// Turn the generated headings so that they are the reference's where the root is kept, the
/// difference spread over the generated frames between (a turn made gradually, not a snap).
fn meet_kept_headings(yaws: &mut [f64], k: &Keep, axis: glam::DVec3) {
    let j = k.reference.joints;
    let mut anchors: Vec<(usize, f64)> = Vec::new();
    for t in root_anchors(k, yaws.len()) {
        let want = heading::yaw(k.reference.rotations[t * j], axis);
        let mut d = want - yaws[t];
        // The turn nearest to the previous anchor's, so no full circle is spread in between.
        let previous = anchors.last().map(|a| a.1).unwrap_or(0.0);
        d -= (2.0 * std::f64::consts::PI) * ((d - previous) / (2.0 * std::f64::consts::PI)).round();
        anchors.push((t, d));
    }
    spread_offsets(yaws, &anchors, |a, b, w| a + (b - a) * w);
}

/// Make the kept cells of a decoded motion the reference's exactly (rotations as given, not
/// through 6D and float32), and spread the root's horizontal drift over the generated frames so
/// the path meets every kept root position without a jump.
fn restore_kept(motion: &mut Motion, k: &Keep) {
    let (j, r) = (motion.joints, k.reference);
    let known = motion.frames.min(r.frames);
    let kept_frame = |t: usize| t < known && k.frames.get(t).copied().unwrap_or(false);
    let root_kept = |t: usize| kept_frame(t) || (t < known && k.joints.first().copied().unwrap_or(false));
    // Horizontal offset of the root at the frames whose root is kept, spread in between.
    let anchors: Vec<(usize, glam::DVec3)> = root_anchors(k, motion.frames)
        .into_iter()
        .map(|t| {
            let d = r.translations[t * j] - motion.translations[t * j];
            (t, glam::DVec3::new(d.x, 0.0, d.z))
        })
        .collect();
    let mut roots: Vec<glam::DVec3> = (0..motion.frames).map(|t| motion.translations[t * j]).collect();
    spread_offsets(&mut roots, &anchors, |a, b, w| a.lerp(b, w));
    for (t, p) in roots.into_iter().enumerate() {
        motion.translations[t * j] = p;
    }
    for t in 0..known {
        if kept_frame(t) {
            motion.rotations[t * j..(t + 1) * j].copy_from_slice(&r.rotations[t * j..(t + 1) * j]);
            motion.translations[t * j..(t + 1) * j].copy_from_slice(&r.translations[t * j..(t + 1) * j]);
            continue;
        }
        for (joint, _) in k.joints.iter().enumerate().filter(|(_, &kept)| kept) {
            motion.rotations[t * j + joint] = r.rotations[t * j + joint];
        }
        if root_kept(t) {
            motion.translations[t * j] = r.translations[t * j];
        }
    }
}
