//! Motion editing with the denoiser (AnyTop §5): in-betweening (keep some frames of a reference
//! motion, generate the rest) and body-part editing (keep some joints, generate the others),
//! both as one masked sampling loop (`sample::denoise`): the known part is imposed at every
//! step, on the model's input (the reference noised to that step) and on its x0 prediction.
//!
//! Also here: which frames and joints a person asked to keep (`--keep-frames 0-19,100-119`,
//! `--keep-joints '*Leg*,LeftUpLeg/'`), and the continuity measure for in-betweening — the jump
//! of joint velocities at each seam between kept and generated frames, next to the same
//! statistic over every frame boundary of real clips.

use super::sample::{denoise, Condition, Imposed, SampleOptions};
use super::schedule::Schedule;
use super::DiffusionError;
use crate::nn::Denoiser;
use crate::repr::anytop::{AnyTopError, AnyTopRig, Placement};
use crate::repr::Features;
use crate::skeleton::{lookup, Skeleton};
use candle_core::Device;
use glam::DVec3;
use std::ops::Range;

/// Why an edit cannot be set up: what was given and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EditError {
    #[error("frame range '{text}': {problem}")]
    BadRange { text: String, problem: String },
    #[error("frame range '{text}' goes past the last frame that can be kept ({last}; {why})")]
    RangePastEnd { text: String, last: usize, why: String },
    #[error("no joint matches '{pattern}' (closest: {})", closest.join(", "))]
    NoJoint { pattern: String, closest: Vec<String> },
    #[error(transparent)]
    Lookup(#[from] lookup::LookupError),
    #[error("an empty list of {0}")]
    EmptyList(&'static str),
    #[error("the reference motion is [{got_frames}, {got_joints}, {got_dims}] but the edit needs [{frames}, {joints}, 13] (or more frames)")]
    Shape { got_frames: usize, got_joints: usize, got_dims: usize, frames: usize, joints: usize },
    #[error("the keep-mask has {got} entries; {frames} frames x {joints} joints need {}", frames * joints)]
    Mask { got: usize, frames: usize, joints: usize },
    #[error("{0}")]
    Stats(String),
    /// An option's value that does not hold (the option names itself).
    #[error("{flag}")]
    Option {
        flag: &'static str,
        #[source]
        source: Box<EditError>,
    },
    #[error("--keep-frames/--keep-joints keep every frame and joint: nothing is left to generate")]
    KeepsAll,
    /// A reference clip that cannot be edited on the skeleton being sampled.
    #[error("{0}")]
    Reference(String),
}

/// Which (frame, joint) cells of the output are taken from the reference; all 13 features of a
/// kept cell are kept.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeepMask {
    pub frames: usize,
    pub joints: usize,
    /// `[frame * joints + joint]`.
    pub keep: Vec<bool>,
}

impl KeepMask {
    /// Nothing kept.
    pub fn new(frames: usize, joints: usize) -> KeepMask {
        KeepMask { frames, joints, keep: vec![false; frames * joints] }
    }

    /// Keep every joint of the frames in `ranges` (clipped to the mask).
    pub fn keep_frames(&mut self, ranges: &[Range<usize>]) {
        for r in ranges {
            for f in r.start.min(self.frames)..r.end.min(self.frames) {
                self.keep[f * self.joints..(f + 1) * self.joints].fill(true);
            }
        }
    }

    /// Keep `joints` in the frames `frames` (clipped to the mask).
    pub fn keep_joints(&mut self, joints: &[usize], frames: Range<usize>) {
        for f in frames.start.min(self.frames)..frames.end.min(self.frames) {
            for &j in joints.iter().filter(|&&j| j < self.joints) {
                self.keep[f * self.joints + j] = true;
            }
        }
    }

    pub fn count(&self) -> usize {
        self.keep.iter().filter(|&&k| k).count()
    }

    /// Per frame: are all its joints kept (the frames in-betweening fixed)?
    pub fn whole_frames(&self) -> Vec<bool> {
        (0..self.frames).map(|f| self.joints > 0 && self.keep[f * self.joints..(f + 1) * self.joints].iter().all(|&k| k)).collect()
    }
}

/// Parse `0-19,100-119` (inclusive ranges; a single `7` is one frame) into half-open ranges.
/// Every frame must be below `limit`; `why` says where the limit comes from (for the message).
pub fn parse_frame_ranges(text: &str, limit: usize, why: &str) -> Result<Vec<Range<usize>>, EditError> {
    let mut out = Vec::new();
    for part in text.split(',').map(str::trim) {
        if part.is_empty() {
            return Err(EditError::BadRange { text: text.to_string(), problem: "an empty range (stray comma?)".into() });
        }
        let bad = |problem: String| EditError::BadRange { text: part.to_string(), problem };
        let number = |s: &str| s.trim().parse::<usize>().map_err(|_| bad(format!("'{}' is not a frame number (expected FIRST-LAST, e.g. 0-19)", s.trim())));
        let (first, last) = match part.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None => {
                let f = number(part)?;
                (f, f)
            }
        };
        if last < first {
            return Err(bad(format!("ends ({last}) before it starts ({first})")));
        }
        if last >= limit {
            return Err(EditError::RangePastEnd { text: part.to_string(), last: limit.saturating_sub(1), why: why.to_string() });
        }
        out.push(first..last + 1);
    }
    Ok(out)
}

/// Joints named by a comma-separated list: names (resolved like everywhere else, exact then
/// looser: `skeleton::lookup`), glob patterns with `*` and `?` (ignoring case: `*leg*`), and
/// either with a trailing `/` for the joint and all its descendants (`LeftUpLeg/`). Sorted,
/// without repeats. A name or pattern that finds nothing is an error listing close names.
pub fn select_joints(skeleton: &Skeleton, list: &str) -> Result<Vec<usize>, EditError> {
    let children = skeleton.children();
    let mut chosen = vec![false; skeleton.len()];
    let mut any = false;
    for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        any = true;
        let (pattern, subtree) = match item.strip_suffix('/') {
            Some(p) => (p.trim(), true),
            None => (item, false),
        };
        let roots: Vec<usize> = if pattern.contains(['*', '?']) {
            let want: Vec<char> = pattern.to_lowercase().chars().collect();
            let hits: Vec<usize> = (0..skeleton.len()).filter(|&j| glob(&want, &skeleton.joints[j].name.to_lowercase().chars().collect::<Vec<_>>())).collect();
            if hits.is_empty() {
                let bare: String = pattern.chars().filter(|c| !matches!(c, '*' | '?')).collect();
                return Err(EditError::NoJoint { pattern: item.to_string(), closest: lookup::closest_names(skeleton, &bare, 5) });
            }
            hits
        } else {
            vec![lookup::find_joint(skeleton, pattern)?]
        };
        let mut stack = roots;
        while let Some(j) = stack.pop() {
            chosen[j] = true;
            if subtree {
                stack.extend(children[j].iter().copied());
            }
        }
    }
    if !any {
        return Err(EditError::EmptyList("joints"));
    }
    Ok((0..skeleton.len()).filter(|&j| chosen[j]).collect())
}

/// Shell-style match of the whole name: `*` any run of characters, `?` one character.
fn glob(pattern: &[char], name: &[char]) -> bool {
    // Iterative with one backtrack point (the last `*`): linear enough for joint names.
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        if p < pattern.len() && (pattern[p] == '?' || pattern[p] == name[n]) {
            p += 1;
            n += 1;
        } else if p < pattern.len() && pattern[p] == '*' {
            star = Some((p, n));
            p += 1;
        } else if let Some((sp, sn)) = star {
            p = sp + 1;
            n = sn + 1;
            star = Some((sp, sn + 1));
        } else {
            return false;
        }
    }
    pattern[p..].iter().all(|&c| c == '*')
}

/// Sample `opts.samples` motions of `opts.frames` frames that agree with `reference` (AnyTop
/// features in physical units, at least `opts.frames` frames of the skeleton `cond` describes)
/// wherever `mask` keeps a cell: the known part is imposed at every step (module doc), and the
/// output's kept cells are the reference's values exactly. Denormalised like `sample::sample`.
/// Deterministic for `opts.seed`, with any sampler and step count.
pub fn sample_edit(
    model: &Denoiser,
    schedule: &Schedule,
    cond: &Condition,
    opts: &SampleOptions,
    reference: &Features,
    mask: &KeepMask,
    device: &Device,
) -> Result<Vec<Features>, DiffusionError> {
    let joints = cond.names.len();
    let dims = reference.dims;
    if reference.joints != joints || dims != 13 || reference.frames < opts.frames || reference.data.len() != reference.frames * joints * dims {
        return Err(EditError::Shape { got_frames: reference.frames, got_joints: reference.joints, got_dims: dims, frames: opts.frames, joints }.into());
    }
    if mask.frames != opts.frames || mask.joints != joints || mask.keep.len() != opts.frames * joints {
        return Err(EditError::Mask { got: mask.keep.len(), frames: opts.frames, joints }.into());
    }
    let physical = Features { frames: opts.frames, joints, dims, data: reference.data[..opts.frames * joints * dims].to_vec() };
    let mut normalised = physical.clone();
    cond.stats.normalise(&mut normalised).map_err(|e| EditError::Stats(format!("normalising the reference: {e}")))?;
    let known: Vec<bool> = mask.keep.iter().flat_map(|&k| std::iter::repeat_n(k, dims)).collect();
    // A fixed offset from the seed: the known part's noise is its own stream (sample.rs).
    let imposed = Imposed { reference: &normalised.data, known: &known, seed: opts.seed ^ 0x6564_6974_6b6e_6f77 };
    let mut out = denoise(model, schedule, cond, opts, Some(&imposed), device)?;
    for f in &mut out {
        cond.stats.denormalise(f).map_err(|source| DiffusionError::Stats { what: "denormalising the samples", source })?;
        // Normalising and back rounds; the kept cells are the reference's own numbers.
        for ((v, &r), _) in f.data.iter_mut().zip(&physical.data).zip(&known).filter(|(_, k)| **k) {
            *v = r;
        }
    }
    Ok(out)
}

/// How much joint velocities change at each boundary between frames b−1 and b (b = 1..frames),
/// in position units per frame: per joint, the larger of |v_b − v_{b−1}| and |v_{b+1} − v_b|
/// with v_b = p_b − p_{b−1} (the velocity across the boundary against the one before and the
/// one after, whichever exist), averaged over joints. A seam that breaks the motion shows as a
/// large value at its boundary; `positions` are `[frame * joints + joint]`. Clips shorter than
/// three frames have no velocity change: empty.
pub fn boundary_jumps(positions: &[DVec3], joints: usize) -> Vec<f64> {
    let frames = positions.len().checked_div(joints).unwrap_or(0);
    if frames < 3 {
        return Vec::new();
    }
    let p = |f: usize, j: usize| positions[f * joints + j];
    let v = |b: usize, j: usize| p(b, j) - p(b - 1, j);
    (1..frames)
        .map(|b| {
            let total: f64 = (0..joints)
                .map(|j| {
                    let across = v(b, j);
                    let before = if b >= 2 { (across - v(b - 1, j)).length() } else { 0.0 };
                    let after = if b + 1 < frames { (v(b + 1, j) - across).length() } else { 0.0 };
                    before.max(after)
                })
                .sum();
            total / joints as f64
        })
        .collect()
}

/// One seam of an in-betweening: the boundary between frames `frame − 1` and `frame`, where
/// kept frames meet generated ones, and its `boundary_jumps` value.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Seam {
    pub frame: usize,
    pub jump: f64,
}

/// The velocity jump at every seam between kept (`whole_frames`) and generated frames.
pub fn seam_jump(positions: &[DVec3], joints: usize, kept_frames: &[bool]) -> Vec<Seam> {
    let jumps = boundary_jumps(positions, joints);
    (1..kept_frames.len()).filter(|&b| kept_frames[b] != kept_frames[b - 1]).filter_map(|b| jumps.get(b - 1).map(|&jump| Seam { frame: b, jump })).collect()
}

/// A distribution of `boundary_jumps` values (over every boundary of a set of clips): what a
/// seam's jump is compared with.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct JumpDistribution {
    pub boundaries: usize,
    pub median: f64,
    pub p95: f64,
    pub max: f64,
}

/// The distribution of velocity jumps over every frame boundary of `clips` (each: positions
/// `[frame * joints + joint]` and its joint count); `None` without any boundary.
pub fn jump_distribution<'a>(clips: impl IntoIterator<Item = (&'a [DVec3], usize)>) -> Option<JumpDistribution> {
    jump_distribution_of(clips.into_iter().flat_map(|(p, j)| boundary_jumps(p, j)).collect())
}

/// The distribution of some `boundary_jumps` values (non-finite ones ignored); `None` if none.
pub fn jump_distribution_of(values: Vec<f64>) -> Option<JumpDistribution> {
    let mut all: Vec<f64> = values.into_iter().filter(|v| v.is_finite()).collect();
    if all.is_empty() {
        return None;
    }
    all.sort_by(f64::total_cmp);
    let at = |q: f64| all[((all.len() - 1) as f64 * q).round() as usize];
    Some(JumpDistribution { boundaries: all.len(), median: at(0.5), p95: at(0.95), max: all[all.len() - 1] })
}

/// `mo-sample --report`: the seam jumps of each edited sample against the reference clip's own
/// jump distribution, and the jumps inside the generated stretch, as one JSON value.
/// `reference` is the clip's name, features and placement.
pub fn seam_report(
    rig: &AnyTopRig,
    skeleton: &Skeleton,
    reference: (&str, &Features, &Placement),
    mask: &KeepMask,
    samples: &[Features],
) -> Result<serde_json::Value, AnyTopError> {
    let (name, features, placement) = reference;
    let j = skeleton.len();
    let positions = |f: &Features| rig.recover_positions(skeleton, f, placement);
    let reference = positions(features)?;
    let distribution = jump_distribution([(reference.as_slice(), j)]);
    let kept = mask.whole_frames();
    let mut rows = Vec::with_capacity(samples.len());
    for f in samples {
        let p = positions(f)?;
        let seams = seam_jump(&p, j, &kept);
        let max = seams.iter().map(|s| s.jump).fold(0.0, f64::max);
        // The same number inside the generated stretch (boundaries between two generated
        // frames): a seam as smooth as the model's own motion matches it.
        let jumps = boundary_jumps(&p, j);
        let inside: Vec<f64> = (1..kept.len()).filter(|&b| !kept[b] && !kept[b - 1]).filter_map(|b| jumps.get(b - 1).copied()).collect();
        let generated = jump_distribution_of(inside);
        rows.push(serde_json::json!({ "seams": seams, "max_seam_jump": max, "generated_jumps": generated }));
    }
    let report = serde_json::json!({
        "report": "seam_jump",
        "units": "BVH units per frame",
        "reference": name,
        "kept_frames": kept.iter().filter(|&&k| k).count(),
        "kept_cells": mask.count(),
        "reference_jumps": distribution,
        "samples": rows,
    });
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::Sampler;
    use crate::embed::NameTable;
    use crate::nn::{seeded_var_builder, DenoiserConfig};
    use crate::repr::anytop::AnyTopStats;
    use crate::skeleton::topology;
    use candle_nn::VarMap;

    #[test]
    fn frame_ranges_parse_and_refuse_what_does_not_fit() {
        assert_eq!(parse_frame_ranges("0-19, 100-119", 120, "").unwrap(), vec![0..20, 100..120]);
        assert_eq!(parse_frame_ranges("7", 8, "").unwrap(), vec![7..8]);
        assert!(matches!(parse_frame_ranges("0-120", 120, "x"), Err(EditError::RangePastEnd { last: 119, .. })));
        for bad in ["", "0-", "a-3", "5-2", "1,,2", "-3"] {
            assert!(matches!(parse_frame_ranges(bad, 120, ""), Err(EditError::BadRange { .. })), "{bad}");
        }
    }

    fn chain(names: &[(&str, Option<usize>)]) -> Skeleton {
        let joints = names
            .iter()
            .map(|(n, p)| crate::skeleton::Joint { name: n.to_string(), parent: *p, offset: DVec3::Y, channels: vec![], end_sites: vec![] })
            .collect();
        Skeleton { joints, frame_time: 1.0 / 30.0 }
    }

    #[test]
    fn joints_by_name_glob_and_subtree() {
        let s = chain(&[
            ("Hips", None),
            ("LeftUpLeg", Some(0)),
            ("LeftLeg", Some(1)),
            ("LeftFoot", Some(2)),
            ("RightUpLeg", Some(0)),
            ("RightLeg", Some(4)),
            ("Spine", Some(0)),
        ]);
        assert_eq!(select_joints(&s, "Spine").unwrap(), vec![6]);
        assert_eq!(select_joints(&s, "*Leg*").unwrap(), vec![1, 2, 4, 5]);
        assert_eq!(select_joints(&s, "left*").unwrap(), vec![1, 2, 3], "case-insensitive");
        assert_eq!(select_joints(&s, "*leg").unwrap(), vec![1, 2, 4, 5], "whole name: not LeftFoot");
        assert_eq!(select_joints(&s, "LeftUpLeg/,Spine").unwrap(), vec![1, 2, 3, 6]);
        assert_eq!(select_joints(&s, "Right?pLeg/").unwrap(), vec![4, 5]);
        match select_joints(&s, "LeftUpLgs") {
            Err(EditError::Lookup(lookup::LookupError::Unknown { closest, .. })) => assert_eq!(closest[0], "LeftUpLeg"),
            other => panic!("{other:?}"),
        }
        assert!(matches!(select_joints(&s, "*Tail*"), Err(EditError::NoJoint { .. })));
        assert!(matches!(select_joints(&s, " , "), Err(EditError::EmptyList(_))));
    }

    #[test]
    fn seams_find_a_broken_velocity() {
        // One joint moving at constant speed, then teleporting by 5 at frame 6.
        let mut p: Vec<DVec3> = (0..10).map(|f| DVec3::new(f as f64, 0.0, 0.0)).collect();
        for q in &mut p[6..] {
            q.x += 5.0;
        }
        let jumps = boundary_jumps(&p, 1);
        assert_eq!(jumps.len(), 9);
        assert_eq!(jumps[5 - 1], 5.0, "boundary 5|6's neighbour sees the jump too");
        assert_eq!(jumps[6 - 1], 5.0);
        assert_eq!(jumps[2 - 1], 0.0);
        let kept: Vec<bool> = (0..10).map(|f| f < 3 || f >= 6).collect();
        let seams = seam_jump(&p, 1, &kept);
        assert_eq!(seams, vec![Seam { frame: 3, jump: 0.0 }, Seam { frame: 6, jump: 5.0 }]);
        let d = jump_distribution([(p.as_slice(), 1)]).unwrap();
        assert_eq!((d.boundaries, d.max, d.median), (9, 5.0, 0.0));
        assert!(jump_distribution([(&p[..2], 1)]).is_none());
    }

    struct Fixture {
        model: Denoiser,
        rest: Vec<f32>,
        relations: Vec<Vec<u8>>,
        distances: Vec<Vec<u8>>,
        names: Vec<Vec<f32>>,
        stats: AnyTopStats,
        reference: Features,
    }

    fn fixture() -> Fixture {
        let (skeleton, _) = crate::synth::creature("quadruped", 0).unwrap();
        let j = skeleton.len();
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 3, &Device::Cpu), &DenoiserConfig::tiny()).unwrap();
        let mut rng = crate::rng::SplitMix64::new(11);
        let frames = 10;
        let data: Vec<f32> = (0..frames * j * 13).map(|_| rng.range(-3.0, 3.0) as f32).collect();
        let stats = AnyTopStats { mean: (0..j * 13).map(|k| (k % 7) as f32 * 0.1).collect(), std: vec![2.0; j * 13] };
        Fixture {
            model,
            rest: vec![0.0; j * 13],
            relations: topology::relations(&skeleton),
            distances: topology::distances(&skeleton, topology::DEFAULT_DMAX),
            names: NameTable::builtin().unwrap().embed_skeleton(&skeleton),
            stats,
            reference: Features { frames, joints: j, dims: 13, data },
        }
    }

    #[test]
    fn kept_cells_are_the_reference_and_the_rest_is_generated() {
        let fx = fixture();
        let cond = Condition { rest_row: &fx.rest, relations: &fx.relations, distances: &fx.distances, names: &fx.names, stats: &fx.stats };
        let schedule = Schedule::cosine(100);
        let j = fx.reference.joints;
        let frames = 8;
        let mut mask = KeepMask::new(frames, j);
        mask.keep_frames(&[0..2, 6..8]);
        mask.keep_joints(&[1, 2], 0..frames);
        for (steps, sampler) in [(4, Sampler::Ddpm), (3, Sampler::Ddim)] {
            let opts = SampleOptions { samples: 2, frames, steps, sampler, seed: 5, lock: None };
            let a = sample_edit(&fx.model, &schedule, &cond, &opts, &fx.reference, &mask, &Device::Cpu).unwrap();
            let b = sample_edit(&fx.model, &schedule, &cond, &opts, &fx.reference, &mask, &Device::Cpu).unwrap();
            assert_eq!(a, b, "same seed, same samples");
            let c = sample_edit(&fx.model, &schedule, &cond, &SampleOptions { seed: 6, ..opts.clone() }, &fx.reference, &mask, &Device::Cpu).unwrap();
            for (s, other) in a.iter().zip(&c) {
                let mut generated_differs = false;
                for f in 0..frames {
                    for jj in 0..j {
                        let (got, want) = (s.at(f, jj), fx.reference.at(f, jj));
                        if mask.keep[f * j + jj] {
                            assert_eq!(got, want, "{sampler:?}: kept cell ({f}, {jj})");
                            assert_eq!(other.at(f, jj), want);
                        } else {
                            generated_differs |= got != other.at(f, jj);
                        }
                    }
                }
                assert!(generated_differs, "{sampler:?}: another seed, another generated part");
                assert!(s.data.iter().all(|v| v.is_finite()));
            }
        }
        // Nothing kept: exactly plain sampling (the known part's noise is a stream of its own).
        let opts = SampleOptions { samples: 1, frames, steps: 3, sampler: Sampler::Ddpm, seed: 9, lock: None };
        let plain = super::super::sample::sample(&fx.model, &schedule, &cond, &opts, &Device::Cpu).unwrap();
        let edit = sample_edit(&fx.model, &schedule, &cond, &opts, &fx.reference, &KeepMask::new(frames, j), &Device::Cpu).unwrap();
        assert_eq!(plain, edit);
    }

    #[test]
    fn the_known_part_reaches_the_generated_part() {
        // Two references that differ only in kept cells must give different generated cells:
        // the model sees the known motion (the upstream's zeros would make them equal).
        let fx = fixture();
        let cond = Condition { rest_row: &fx.rest, relations: &fx.relations, distances: &fx.distances, names: &fx.names, stats: &fx.stats };
        let schedule = Schedule::cosine(100);
        let j = fx.reference.joints;
        let frames = 8;
        let mut mask = KeepMask::new(frames, j);
        mask.keep_frames(&[0..4]);
        let mut other = fx.reference.clone();
        for v in &mut other.data[..4 * j * 13] {
            *v += 1.5;
        }
        let opts = SampleOptions { samples: 1, frames, steps: 3, sampler: Sampler::Ddim, seed: 2, lock: None };
        let a = sample_edit(&fx.model, &schedule, &cond, &opts, &fx.reference, &mask, &Device::Cpu).unwrap();
        let b = sample_edit(&fx.model, &schedule, &cond, &opts, &other, &mask, &Device::Cpu).unwrap();
        assert_ne!(a[0].data[4 * j * 13..], b[0].data[4 * j * 13..]);
        // Shape errors are errors, not panics.
        let short = Features { frames: 3, ..fx.reference.clone() };
        assert!(sample_edit(&fx.model, &schedule, &cond, &opts, &short, &mask, &Device::Cpu).is_err());
        assert!(sample_edit(&fx.model, &schedule, &cond, &opts, &fx.reference, &KeepMask::new(5, j), &Device::Cpu).is_err());
    }
}
