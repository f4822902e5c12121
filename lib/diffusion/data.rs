//! Training data for the denoiser (docs/reference/anytop.md §1.7–1.9, §3.5): clips grouped by
//! skeleton, each skeleton with its rig, rest-pose row P_S, normalisation statistics, topology
//! (R, D) and joint name embeddings; clips encoded and normalised once; batches of random
//! 40-frame crops drawn by the balancing sampler (every skeleton equally likely, then a clip of
//! it uniformly).
//!
//! Grouping: clips whose joint names and parents are identical and whose rest offsets agree
//! within `OFFSET_TOLERANCE` (relative to the skeleton's size) share a skeleton. Proportions
//! matter: a long-legged variant of a creature has its own rest pose and statistics, as two
//! performers of the same rig do in motion-capture sets. A folder is not required, but a
//! group that is the only skeleton of its folder is named after the folder. The rest pose of
//! a skeleton is the first two frames of a clip whose file name says T-pose, else of its first
//! clip (AnyTop's rule, `anytop::names_tpose`).
//!
//! Skeletal augmentation (AnyTop §3.3, appendix C; docs/reference/anytop.md §4): upstream edits
//! every drawn sample on the fly, choosing uniformly among {none, remove joints, add a joint}.
//! Re-encoding clips on every draw would cost more than the training step, so we precompute
//! `Augmentation::variants` edited skeletons per skeleton at build time through `crate::augment`
//! (even variants remove 10–30 % of the joints, odd ones subdivide one bone, as upstream's two
//! edits), each prepared exactly like a real skeleton (own rig, P_S, statistics, R, D, names),
//! and the sampler draws one with probability `Augmentation::probability` (default 2/3, the
//! upstream odds). To bound memory, the clips of a skeleton are dealt round-robin over its
//! variants (each clip is re-encoded for one variant only), so augmentation at most about
//! doubles the feature memory.

use super::rest_norm::{RestNorm, RestTokens};
use crate::augment::{self, RemoveAmount};
use crate::document::AnyTopSection;
use crate::embed::NameTable;
use crate::motion::Motion;
use crate::repr::anytop::{self, AnyTopStats, RestSource, RigOptions};
use crate::repr::Features;
use crate::rng::SplitMix64;
use crate::skeleton::{topology, Skeleton};
use std::borrow::Cow;
use std::path::Path;
use std::sync::OnceLock;

/// Clips shorter than this (in feature frames) are left out, as the reference does.
pub const MIN_FRAMES: usize = 20;

/// Two clips have the same proportions when every non-root rest offset differs by at most this
/// fraction of the skeleton's rest extent. Re-exported rigs of one creature differ by ~1e-4
/// (float printing); different performers or proportion variants by 1e-2 and more.
pub const OFFSET_TOLERANCE: f64 = 1e-3;
use crate::motion::Clip;

/// Everything the model needs to know about one skeleton, and its clips.
pub struct SkeletonData {
    pub name: String,
    pub skeleton: Skeleton,
    pub section: AnyTopSection,
    pub stats: AnyTopStats,
    /// P_S, normalised: `[joints * 13]`.
    pub rest_row: Vec<f32>,
    /// The frames `section` (rig and P_S) was built from: the rest clip's first two, and that
    /// clip's name.
    pub rest: (String, Motion),
    pub relations: Vec<Vec<u8>>,
    pub distances: Vec<Vec<u8>>,
    /// One embedding per joint.
    pub names: Vec<Vec<f32>>,
    /// Normalised features `[frames, joints, 13]` of each clip.
    pub clips: Vec<Features>,
    pub clip_names: Vec<String>,
    /// Per joint and feature (`[joints * 13]`), what an error in `stats`' units weighs in the
    /// loss: `None` counts every value alike; with the fallback, (fallback spread / own spread)²,
    /// so the error is measured in the skeleton's own units (see `LOSS_WEIGHT_RANGE`).
    pub loss_weights: Option<Vec<f32>>,
    /// `still_clips`, worked out at the first draw that weighs them (`TrainSet::still_weight`):
    /// not in `prepare`, because the clips are normalised in place after it.
    still: OnceLock<Vec<bool>>,
}

/// Skeletal augmentation settings (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Augmentation {
    /// Chance that a draw uses an augmented variant of the drawn skeleton, in [0, 1].
    pub probability: f64,
    /// Augmented variants prepared per skeleton (0: none).
    pub variants: usize,
    /// Seeds the choice of edits, so the same seed gives the same variants.
    pub seed: u64,
    /// Which draws are normalised as an unseen skeleton (see `FallbackStats`).
    pub stats: FallbackStats,
    /// The units a fallback-normalised draw's error is measured in (see `LossUnits`).
    pub units: LossUnits,
    /// What the rest tokens are normalised by (`rest_norm::RestTokens`).
    pub rest: RestTokens,
}

/// Which skeletons training normalises as sampling normalises a skeleton the model never saw
/// (`condition::fallback_stats`: the rest pose as the mean, the skeletons' average spreads)
/// rather than by their own clips' statistics. Why: the built-in compact model (step 15,462)
/// sampled its own trained quadruped at 0.32 of the clips' motion energy under the fallback
/// against 0.98 under its statistics, and at 1.07 with its means but the fallback's spreads:
/// the rest pose as the mean (which makes the rest row P_S all zeros), a condition it never
/// trained on, is what stills a skeleton it never saw (models/zoo-compact/MODEL_CARD.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum FallbackStats {
    /// Every skeleton and variant by its own clips (upstream's way).
    #[default]
    None,
    /// The augmented variants (new topologies every one); the skeletons keep theirs, which
    /// sampling uses for them.
    Variants,
    /// Every skeleton and variant, so the model has one condition; the checkpoint then
    /// records the fallback as each skeleton's statistics, and sampling uses it for them too.
    All,
}

/// The units in which the loss measures the error of a draw normalised by the fallback
/// statistics. Why: the fallback's spreads are the zoo's average, and a creature that moves
/// little next to it (the spider's joints move 0.39 of the average spread, its velocities
/// 0.60) has a small signal in those units, so predicting its rest pose costs little. Under
/// `--fallback-stats all` the bundled spider's motion energy fell from 0.91 of its clips' to
/// 0.20 (models/zoo-compact/unseen/MODEL_CARD.md). Measuring the error in the skeleton's own
/// units (its clips' spreads) weighs it as upstream's per-skeleton normalisation does, while
/// the model still reads and writes the fallback's units it gets zero-shot. Measured, it is not
/// the fix: 5,762 steps from that run's step 21,234 left the spider at 0.31 (the `normalised`
/// run read 0.20-0.37 over its checkpoints), and no other skeleton moved beyond the readings'
/// noise (models/zoo-compact/unseen/MODEL_CARD.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum LossUnits {
    /// Every value alike, in the units it is normalised in.
    #[default]
    Normalised,
    /// A fallback-normalised value's squared error times (fallback spread / own spread)²,
    /// clamped to `LOSS_WEIGHT_RANGE`.
    Own,
}

impl Augmentation {
    /// Upstream's odds: two of {none, remove, add} are augmentations.
    pub const DEFAULT_PROBABILITY: f64 = 2.0 / 3.0;
    pub const DEFAULT_VARIANTS: usize = 4;

    /// No augmentation.
    pub fn none() -> Augmentation {
        Augmentation { probability: 0.0, variants: 0, seed: 0, stats: FallbackStats::None, units: LossUnits::Normalised, rest: RestTokens::Skeleton }
    }

    /// The defaults with `seed`.
    pub fn with_seed(seed: u64) -> Augmentation {
        Augmentation { probability: Self::DEFAULT_PROBABILITY, variants: Self::DEFAULT_VARIANTS, seed, ..Self::none() }
    }
}

/// A training set: skeletons with their clips.
pub struct TrainSet {
    pub skeletons: Vec<SkeletonData>,
    /// Augmented variants of `skeletons[i]` at `augmented[i]` (empty when there are none).
    pub augmented: Vec<Vec<SkeletonData>>,
    /// Chance that a draw uses an augmented variant (when its skeleton has any).
    pub augment_probability: f64,
    /// Augmented variants that could not be prepared, with the reason.
    pub skipped_variants: Vec<String>,
    /// A crop's temporal positions start at a random offset in `0..=position_jitter` (0: every
    /// crop starts at 0), drawn apart from where the crop lies in its clip; see `Crop::position`.
    pub position_jitter: usize,
    /// How often a still clip is drawn against a moving one of its skeleton (`still_clips`):
    /// 1 draws every clip alike.
    pub still_weight: f64,
    /// What every rest token was normalised by, when not its skeleton's statistics.
    pub rest_norm: Option<RestNorm>,
}

#[derive(Debug, thiserror::Error)]
pub enum DataError {
    #[error("no clips to train on")]
    Empty,
    #[error("{clip}: {why}")]
    Clip { clip: String, why: String },
    #[error("skeleton of {clip}: no clip has {min} or more frames", min = MIN_FRAMES + 1)]
    TooShort { clip: String },
    #[error("augmentation probability must be in [0, 1], found {0}")]
    Probability(f64),
}

/// True when `a` and `b` are the same skeleton: same joint names and parents, and rest offsets
/// (root excluded: it places the body, it is not a proportion) within `OFFSET_TOLERANCE`.
pub fn same_skeleton(a: &Skeleton, b: &Skeleton) -> bool {
    if a.first_difference(b).is_some() {
        return false;
    }
    let size = a.rest_extent().max(b.rest_extent());
    offsets_agree(size, a.joints.iter().map(|j| j.offset), b.joints.iter().map(|j| j.offset))
}

/// Non-root rest offsets (joint 0 first in both) within `OFFSET_TOLERANCE` of `size`.
pub fn offsets_agree(size: f64, a: impl Iterator<Item = glam::DVec3>, b: impl Iterator<Item = glam::DVec3>) -> bool {
    let tolerance = if size.is_finite() && size > 0.0 { OFFSET_TOLERANCE * size } else { 0.0 };
    a.zip(b).skip(1).all(|(x, y)| (x - y).abs().max_element() <= tolerance)
}

/// The folder part of a clip name ("" when none).
fn folder_of(name: &str) -> String {
    Path::new(name).parent().map(|p| p.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The file stem of a clip name.
fn stem_of(name: &str) -> String {
    Path::new(name).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| name.to_string())
}

/// A readable name per group: the folder's name when the group is the only skeleton of its
/// folder, else the stem its clips' file names share (`biped_long_walk`, `biped_long_run` ->
/// `biped_long`) when no other group's files share it, else its first clip's stem; made
/// unique with `_2`, `_3`, ...
fn group_names(groups: &[Vec<Clip>]) -> Vec<String> {
    let folders: Vec<Vec<String>> = groups.iter().map(|g| g.iter().map(|c| folder_of(&c.name)).collect()).collect();
    let mut names = Vec::with_capacity(groups.len());
    for (i, group) in groups.iter().enumerate() {
        let folder = &folders[i][0];
        let only_here = folders[i].iter().all(|f| f == folder) && folders.iter().enumerate().all(|(k, fs)| k == i || !fs.contains(folder));
        let folder_name = Path::new(folder).file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let name = if only_here && !folder_name.is_empty() && folder_name != "." && folder_name != ".." {
            folder_name
        } else {
            let stems: Vec<String> = group.iter().map(|c| stem_of(&c.name)).collect();
            let mut prefix = stems[0].clone();
            for s in &stems[1..] {
                let common = prefix.chars().zip(s.chars()).take_while(|(a, b)| a == b).count();
                prefix = prefix.chars().take(common).collect();
            }
            let prefix = prefix.trim_end_matches(['_', '-', '.', ' ']).to_string();
            // A prefix that other groups' files share too (`dataset-1_...`) says nothing.
            let distinctive =
                prefix.chars().count() >= 2 && groups.iter().enumerate().all(|(k, g)| k == i || g.iter().all(|c| !stem_of(&c.name).starts_with(&prefix)));
            if distinctive {
                prefix
            } else {
                stems[0].clone()
            }
        };
        let mut unique = name.clone();
        let mut k = 2;
        while names.contains(&unique) {
            unique = format!("{name}_{k}");
            k += 1;
        }
        names.push(unique);
    }
    names
}

/// The AnyTop record (rig and P_S) of a skeleton whose rest pose is the first frames of the clip
/// `file` (a T-pose file by AnyTop's name rule); training builds it so, and sampling rebuilds a
/// trained skeleton's from the frames its checkpoint keeps (`checkpoint::trained_record`).
pub fn rest_record(skeleton: &Skeleton, file: &str, rest: &Motion) -> Result<AnyTopSection, anytop::AnyTopError> {
    let file = file.to_string();
    let rest_source = if anytop::names_tpose(&file) { RestSource::TPose { file } } else { RestSource::FirstClip { file } };
    AnyTopSection::new(skeleton, &rest.first_frames(2), &RigOptions { rest_source, ..RigOptions::default() })
}

/// What preparing a skeleton needs besides its clips.
#[derive(Clone, Copy)]
struct Preparation<'a> {
    names: &'a NameTable,
    dmax: usize,
}

/// Prepare one skeleton from its clips: rig and P_S from `rest` (file name, motion), features
/// of every clip long enough (the others go to `dropped`), the clips' statistics, topology and
/// names. Clips and P_S are left unnormalised: `normalised` finishes the skeleton once it is
/// known which statistics it trains under. `None` when no clip is long enough.
fn prepare<'a>(
    name: String,
    skeleton: Skeleton,
    rest: (&str, &Motion),
    clips: impl Iterator<Item = (String, Cow<'a, Motion>)>,
    how: Preparation,
    dropped: &mut Vec<String>,
) -> Result<Option<SkeletonData>, DataError> {
    let (rest_name, rest_motion) = rest;
    let section = rest_record(&skeleton, rest_name, rest_motion).map_err(|e| DataError::Clip { clip: rest_name.to_string(), why: e.to_string() })?;
    let mut features = Vec::new();
    let mut clip_names = Vec::new();
    for (clip, motion) in clips {
        if motion.frames < MIN_FRAMES + 1 {
            dropped.push(clip);
            continue;
        }
        let encoded = section.rig.encode(&skeleton, &motion).map_err(|e| DataError::Clip { clip: clip.clone(), why: e.to_string() })?;
        features.push(encoded.features);
        clip_names.push(clip);
    }
    if features.is_empty() {
        return Ok(None);
    }
    let stats = AnyTopStats::compute(features.iter()).map_err(|e| DataError::Clip { clip: name.clone(), why: e.to_string() })?;
    Ok(Some(SkeletonData {
        relations: topology::relations(&skeleton),
        distances: topology::distances(&skeleton, how.dmax),
        names: how.names.embed_skeleton(&skeleton),
        rest_row: section.rest_row.concat(),
        rest: (rest_name.to_string(), rest_motion.first_frames(2)),
        name,
        skeleton,
        section,
        stats,
        clips: features,
        clip_names,
        loss_weights: None,
        still: OnceLock::new(),
    }))
}

/// Which frames of a skeleton's clips (lengths `frames`) variant `v` of `variants` carries,
/// as (clip, frame range): clips `v`, `v + variants`, ... whole when there are at least as
/// many clips as variants; otherwise one contiguous piece of clip `v mod n`, cut into as many
/// pieces as variants share it (but never shorter than a croppable clip). Either way each
/// frame goes to about one variant, so augmentation at most about doubles the memory.
fn deal(frames: &[usize], v: usize, variants: usize) -> Vec<(usize, std::ops::Range<usize>)> {
    let n = frames.len();
    if n >= variants {
        return (v..n).step_by(variants).map(|c| (c, 0..frames[c])).collect();
    }
    let clip = v % n;
    let sharing = (clip..variants).step_by(n).count().max(1);
    let piece = v / n;
    let len = frames[clip];
    // +1: motion frames, one more than feature frames.
    let size = len.div_ceil(sharing).max(MIN_FRAMES + 2).min(len);
    let start = (piece * len / sharing).min(len - size);
    vec![(clip, start..start + size)]
}

/// How `normalised` normalises a skeleton.
#[derive(Clone, Copy)]
struct Norms<'a> {
    /// The trained skeletons' statistics, when the skeleton is normalised by the fallback.
    fallback: Option<&'a [&'a AnyTopStats]>,
    /// The units of a fallback-normalised skeleton's error.
    units: LossUnits,
    /// What the rest token is normalised by, when not as the motion.
    rest: Option<&'a RestNorm>,
}

/// `data` as `prepare` left it, normalised by its clips' statistics, or with `how.fallback`
/// (the trained skeletons' statistics) by `condition::fallback_stats` of them, its error then
/// measured in `how.units`; its rest token by `how.rest` when given, else as the motion.
fn normalised(mut data: SkeletonData, how: Norms) -> Result<SkeletonData, DataError> {
    let fail = |e: &dyn std::fmt::Display| DataError::Clip { clip: data.name.clone(), why: e.to_string() };
    if let Some(trained) = how.fallback {
        let own = std::mem::replace(&mut data.stats, crate::diffusion::condition::fallback_stats(&data.section.rest_row, trained).map_err(|e| fail(&e))?);
        if how.units == LossUnits::Own {
            data.loss_weights = Some(own_unit_weights(&own, &data.stats));
        }
    }
    for f in &mut data.clips {
        data.stats.normalise(f).map_err(|e| fail(&e))?;
    }
    let mut rest = Features { frames: 1, joints: data.skeleton.len(), dims: anytop::FEATURE_DIMS, data: std::mem::take(&mut data.rest_row) };
    match how.rest {
        Some(norm) => norm.for_joints(data.skeleton.len()).normalise(&mut rest),
        None => data.stats.normalise(&mut rest),
    }
    .map_err(|e| fail(&e))?;
    data.rest_row = rest.data;
    Ok(data)
}

/// Clamp for `own_unit_weights`: a feature that never moves (a centipede's root height) has
/// no spread, and its weight would be unbounded.
pub const LOSS_WEIGHT_RANGE: (f32, f32) = (1.0 / 16.0, 16.0);

/// (used spread / own spread)² per value: an error in `used` units times this is the error in
/// `own` units squared.
fn own_unit_weights(own: &AnyTopStats, used: &AnyTopStats) -> Vec<f32> {
    let eps = anytop::STD_EPSILON;
    own.std.iter().zip(&used.std).map(|(o, u)| ((u + eps) / (o + eps)).powi(2).clamp(LOSS_WEIGHT_RANGE.0, LOSS_WEIGHT_RANGE.1)).collect()
}

/// The augmented variants of one skeleton (group `index` of the set): variant `v` removes
/// joints (`v` even) or subdivides one bone (`v` odd) and carries the frames `deal` gives it.
/// Variants whose edit changes nothing, or whose clips are all too short, are left out; so are
/// variants that cannot be prepared (returned with the reason): an augmentation is never
/// worth failing a training run for. Each is normalised as `norms` says (the fallback, when given, always: a variant is a new topology).
fn variants_of(
    index: usize,
    base: &SkeletonData,
    group: &[Clip],
    rest: &Clip,
    aug: &Augmentation,
    how: Preparation,
    norms: Norms,
) -> (Vec<SkeletonData>, Vec<String>) {
    let (mut out, mut skipped) = (Vec::new(), Vec::new());
    for v in 0..aug.variants {
        // One stream per (seed, skeleton, variant): adding a skeleton or a variant leaves the
        // others' edits as they were.
        let mut rng = SplitMix64::new(aug.seed ^ 0xa076_1d64_78bd_642f ^ ((index as u64) << 20 | v as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let options = if v % 2 == 0 {
            augment::Options { remove: Some(RemoveAmount::Random), add: 0, keep_feet: true }
        } else {
            augment::Options { remove: None, add: 1, keep_feet: true }
        };
        let plan = augment::plan(&base.skeleton, &options, &mut rng);
        if plan.is_empty() {
            continue;
        }
        // Only croppable clips are dealt (a T-pose file would leave its variant without any).
        let usable: Vec<&Clip> = group.iter().filter(|c| c.motion.frames > MIN_FRAMES + 1).collect();
        if usable.is_empty() {
            continue;
        }
        let pieces = deal(&usable.iter().map(|c| c.motion.frames).collect::<Vec<_>>(), v, aug.variants);
        let tag = if v % 2 == 0 { format!("remove{}", plan.joints_before - plan.skeleton.len()) } else { "add1".to_string() };
        let rest_motion = plan.apply_motion(&base.skeleton, &rest.motion.first_frames(2));
        let clips = pieces.into_iter().map(|(c, range)| {
            let clip = usable[c];
            let motion = if range == (0..clip.motion.frames) {
                plan.apply_motion(&base.skeleton, &clip.motion)
            } else {
                plan.apply_motion(&base.skeleton, &clip.motion.frame_range(range.start, range.end))
            };
            (clip.name.clone(), Cow::Owned(motion))
        });
        let mut ignored = Vec::new();
        let name = format!("{}__{tag}_v{v}", base.name);
        let prepared = prepare(name.clone(), plan.skeleton.clone(), (&rest.name, &rest_motion), clips, how, &mut ignored);
        match prepared.and_then(|data| data.map(|data| normalised(data, norms)).transpose()) {
            Ok(Some(data)) => out.push(data),
            Ok(None) => {}
            Err(e) => skipped.push(format!("{name}: {e}")),
        }
    }
    (out, skipped)
}

impl TrainSet {
    /// Group `clips` by skeleton and prepare them, with augmented variants as `aug` says.
    /// Clips too short to crop are dropped (returned by name, so the caller can say so).
    pub fn build(clips: Vec<Clip>, names: &NameTable, dmax: usize, aug: &Augmentation) -> Result<(TrainSet, Vec<String>), DataError> {
        if clips.is_empty() {
            return Err(DataError::Empty);
        }
        if !(0.0..=1.0).contains(&aug.probability) {
            return Err(DataError::Probability(aug.probability));
        }
        let mut groups: Vec<Vec<Clip>> = Vec::new();
        for c in clips {
            match groups.iter_mut().find(|g| same_skeleton(&g[0].skeleton, &c.skeleton)) {
                Some(g) => g.push(c),
                None => groups.push(vec![c]),
            }
        }
        let group_names = group_names(&groups);
        let mut skeletons = Vec::with_capacity(groups.len());
        let mut augmented = Vec::with_capacity(groups.len());
        let mut dropped = Vec::new();
        let mut skipped_variants = Vec::new();
        let mut first_short = None;
        let mut prepared = Vec::with_capacity(groups.len());
        for (index, (group, name)) in groups.into_iter().zip(group_names).enumerate() {
            let rest = group.iter().position(|c| anytop::names_tpose(&c.name)).unwrap_or(0);
            let skeleton = group[0].skeleton.clone();
            let clips = group.iter().map(|c| (c.name.clone(), Cow::Borrowed(&c.motion)));
            // A skeleton with no croppable clip (a lone bind-pose file) is left out, its clips
            // reported as dropped; only a set with nothing left is an error.
            let Some(data) = prepare(name, skeleton, (&group[rest].name, &group[rest].motion), clips, Preparation { names, dmax }, &mut dropped)? else {
                first_short.get_or_insert_with(|| group[0].name.clone());
                continue;
            };
            prepared.push((index, group, rest, data));
        }
        // Normalising comes second: as unseen skeletons, skeletons and variants need every
        // skeleton's measured statistics (the fallback's spreads are their average, as at sampling).
        let trained: Vec<AnyTopStats> = prepared.iter().map(|(_, _, _, d)| d.stats.clone()).collect();
        let trained: Vec<&AnyTopStats> = trained.iter().collect();
        let fallback = (aug.stats != FallbackStats::None).then_some(&trained[..]);
        let rest_norm = match aug.rest {
            RestTokens::Skeleton => None,
            RestTokens::Given(norm) => Some(norm),
            RestTokens::Pool => Some(
                RestNorm::pool(prepared.iter().map(|(_, _, _, d)| d.rest_row.as_slice()))
                    .ok_or_else(|| DataError::Clip { clip: "--rest-token global".into(), why: "no skeleton has a joint besides its root".into() })?,
            ),
        };
        let norms = Norms { fallback, units: aug.units, rest: rest_norm.as_ref() };
        for (index, group, rest, data) in prepared {
            let data = normalised(data, Norms { fallback: fallback.filter(|_| aug.stats == FallbackStats::All), ..norms })?;
            // Variants nobody will draw are not worth their memory.
            let wanted = if aug.probability > 0.0 { *aug } else { Augmentation { variants: 0, ..*aug } };
            let (variants, skipped) = variants_of(index, &data, &group, &group[rest], &wanted, Preparation { names, dmax }, norms);
            augmented.push(variants);
            skipped_variants.extend(skipped);
            skeletons.push(data);
        }
        if skeletons.is_empty() {
            return Err(DataError::TooShort { clip: first_short.unwrap_or_default() });
        }
        Ok((
            TrainSet { skeletons, augmented, augment_probability: aug.probability, skipped_variants, position_jitter: 0, still_weight: 1.0, rest_norm },
            dropped,
        ))
    }

    /// The skeleton (original or augmented variant) a crop comes from.
    pub fn data(&self, crop: &Crop) -> &SkeletonData {
        match crop.variant {
            Some(v) => &self.augmented[crop.skeleton][v],
            None => &self.skeletons[crop.skeleton],
        }
    }

    /// Augmented variants in all.
    pub fn variant_count(&self) -> usize {
        self.augmented.iter().map(Vec::len).sum()
    }

    /// One line on what the set holds: its skeletons by name, clips, feature frames and
    /// augmented variants.
    pub fn summary(&self) -> String {
        format!(
            "{} skeletons ({}), {} clips, {} feature frames; {} augmented variants",
            self.skeletons.len(),
            self.skeletons.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", "),
            self.skeletons.iter().map(|s| s.clips.len()).sum::<usize>(),
            self.skeletons.iter().flat_map(|s| &s.clips).map(|c| c.frames).sum::<usize>(),
            self.variant_count()
        )
    }

    /// What a trainer says about the set: the clips `build` dropped, the `summary`, the
    /// variants left out and, when `verbose`, one line per augmented variant (name, joints, clips).
    pub fn report(&self, dropped: &[String], verbose: bool) -> Vec<String> {
        let mut lines: Vec<String> = dropped.iter().map(|d| format!("{d}: too short to crop, left out")).collect();
        lines.push(self.summary());
        lines.extend(self.skipped_variants.iter().map(|v| format!("augmented variant left out: {v}")));
        let variant = |v: &SkeletonData| format!("variant {}: {} joints, {} clips", v.name, v.skeleton.len(), v.clips.len());
        lines.extend(self.augmented.iter().flatten().filter(|_| verbose).map(variant));
        lines
    }

    /// Draw `batch` crops of at most `frames` feature frames: a skeleton uniformly (each gets
    /// 1/#skeletons, AnyTop's balancing sampler), with `augment_probability` one of its
    /// augmented variants (uniformly) instead, a clip of it uniformly, a crop start uniformly,
    /// and with `position_jitter` a position offset uniformly.
    pub fn sample(&self, rng: &mut SplitMix64, batch: usize, frames: usize) -> Vec<Crop> {
        (0..batch)
            .map(|_| {
                let s = rng.below(self.skeletons.len());
                let variants = &self.augmented[s];
                // No draw at all when augmentation is off, so such runs keep their old stream.
                let variant = if !variants.is_empty() && self.augment_probability > 0.0 && rng.unit() < self.augment_probability {
                    Some(rng.below(variants.len()))
                } else {
                    None
                };
                let sk = match variant {
                    Some(v) => &variants[v],
                    None => &self.skeletons[s],
                };
                let c = if self.still_weight == 1.0 {
                    rng.below(sk.clips.len())
                } else {
                    draw_weighted(rng, sk.still.get_or_init(|| still_clips(sk)), self.still_weight)
                };
                let clip = &sk.clips[c];
                let len = clip.frames.min(frames);
                let start = rng.below(clip.frames - len + 1);
                // No draw when the jitter is off, so such runs keep their old stream.
                let position = if self.position_jitter > 0 { rng.below(self.position_jitter + 1) } else { 0 };
                Crop { skeleton: s, variant, clip: c, start, frames: len, position }
            })
            .collect()
    }

    /// The features of a crop, `[frames, joints, 13]` (normalised).
    pub fn crop(&self, crop: &Crop) -> Features {
        let clip = &self.data(crop).clips[crop.clip];
        let width = clip.joints * clip.dims;
        Features { frames: crop.frames, joints: clip.joints, dims: clip.dims, data: clip.data[crop.start * width..(crop.start + crop.frames) * width].to_vec() }
    }
}

/// A clip is still when its mean absolute frame-to-frame change (normalised features) is under
/// this fraction of its skeleton's most moving clip's. In BVH channels the zoo quadruped's idle
/// changes 0.10 degrees per frame against its run's 2.22 (0.05 of it) and its walk-stop-walk
/// 0.71 (0.32); in features only the idle is still (`tests`).
pub const STILL_FRACTION: f64 = 0.15;

/// Which clips of `sk` are still (`STILL_FRACTION`).
pub fn still_clips(sk: &SkeletonData) -> Vec<bool> {
    let motion: Vec<f64> = sk
        .clips
        .iter()
        .map(|f| {
            let w = f.joints * f.dims;
            let n = f.data.len().saturating_sub(w).max(1);
            f.data.iter().zip(f.data.iter().skip(w)).map(|(a, b)| (b - a).abs() as f64).sum::<f64>() / n as f64
        })
        .collect();
    let most = motion.iter().copied().fold(0.0, f64::max);
    motion.iter().map(|&m| m < STILL_FRACTION * most).collect()
}

/// An index into `still`, a still entry weighing `weight` and a moving one 1; uniform when all
/// weigh alike (all still, or none).
fn draw_weighted(rng: &mut SplitMix64, still: &[bool], weight: f64) -> usize {
    let stills = still.iter().filter(|&&s| s).count();
    if stills == 0 || stills == still.len() {
        return rng.below(still.len());
    }
    let total = (still.len() - stills) as f64 + weight * stills as f64;
    let mut u = rng.unit() * total;
    for (i, &s) in still.iter().enumerate() {
        u -= if s { weight } else { 1.0 };
        if u < 0.0 {
            return i;
        }
    }
    // Rounding can leave u at a hair above 0: the last entry that weighs anything.
    still.iter().rposition(|&s| !s || weight > 0.0).unwrap_or(0)
}

/// Where a training crop comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub skeleton: usize,
    /// `Some(v)`: augmented variant `v` of the skeleton.
    pub variant: Option<usize>,
    pub clip: usize,
    pub start: usize,
    pub frames: usize,
    /// The temporal position offset the model sees for the crop's first frame
    /// (`BatchItem::start`). Independent of `start`: the position says nothing about the
    /// motion, so the model learns to ignore it, while it sees every position up to
    /// `position_jitter + frames`, the ones a longer sample uses.
    pub position: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth;

    fn zoo() -> Vec<Clip> {
        ["biped", "quadruped", "spider"]
            .iter()
            .flat_map(|n| {
                (0..2).map(move |seed| {
                    let (skeleton, motion) = synth::creature(n, seed).unwrap();
                    Clip { name: format!("{n}/{n}_{seed}.bvh"), skeleton, motion }
                })
            })
            .collect()
    }

    /// The same clip twice more: once with offsets nudged far below the tolerance, once with
    /// longer legs (every offset below the root x1.2).
    fn proportions() -> Vec<Clip> {
        let (skeleton, motion) = synth::creature("quadruped", 0).unwrap();
        let mut nudged = skeleton.clone();
        nudged.joints.iter_mut().skip(1).for_each(|j| j.offset *= 1.0 + 1e-6);
        let mut long = skeleton.clone();
        long.joints.iter_mut().skip(1).for_each(|j| j.offset *= 1.2);
        // Translations replace OFFSETs in a motion (`Motion` doc): scale them too.
        let mut long_motion = motion.clone();
        long_motion.translations.iter_mut().enumerate().filter(|(i, _)| i % long.len() != 0).for_each(|(_, t)| *t *= 1.2);
        vec![
            Clip { name: "zoo/quad_walk.bvh".into(), skeleton, motion: motion.clone() },
            Clip { name: "zoo/quad_run.bvh".into(), skeleton: nudged, motion: motion.clone() },
            Clip { name: "zoo/long_quad_walk.bvh".into(), skeleton: long, motion: long_motion },
        ]
    }

    #[test]
    fn clips_group_by_skeleton_and_normalise() {
        let names = NameTable::builtin().unwrap();
        // A skeleton whose only clip is too short is left out, not an error.
        let mut clips = zoo();
        let (skeleton, motion) = synth::creature("crab", 0).unwrap();
        clips.push(Clip { name: "crab/bind.bvh".into(), skeleton, motion: motion.first_frames(2) });
        let (set, dropped) = TrainSet::build(clips, names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        assert_eq!(dropped, ["crab/bind.bvh"]);
        assert!(set.skeletons.iter().all(|s| s.name != "crab"));
        let (skeleton, motion) = synth::creature("crab", 0).unwrap();
        let short = vec![Clip { name: "crab/bind.bvh".into(), skeleton, motion: motion.first_frames(2) }];
        assert!(matches!(TrainSet::build(short, names, topology::DEFAULT_DMAX, &Augmentation::none()), Err(DataError::TooShort { .. })));
        assert_eq!(set.skeletons.iter().map(|s| s.clips.len()).sum::<usize>(), 6);
        assert_eq!(set.variant_count(), 0);
        for s in &set.skeletons {
            let j = s.skeleton.len();
            assert_eq!(s.rest_row.len(), j * 13);
            assert_eq!((s.relations.len(), s.distances.len(), s.names.len()), (j, j, j));
            // Normalised features: the mean over all frames is ~0 per dimension.
            let frames: usize = s.clips.iter().map(|c| c.frames).sum();
            let mut sum = vec![0.0f64; j * 13];
            for c in &s.clips {
                for row in c.data.chunks_exact(j * 13) {
                    sum.iter_mut().zip(row).for_each(|(a, &x)| *a += x as f64);
                }
            }
            assert!(sum.iter().all(|x| (x / frames as f64).abs() < 1e-3), "{}", s.name);
        }
    }

    #[test]
    fn proportions_split_skeletons_and_groups_get_readable_names() {
        let names = NameTable::builtin().unwrap();
        let (set, _) = TrainSet::build(proportions(), names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        let got: Vec<(&str, usize)> = set.skeletons.iter().map(|s| (s.name.as_str(), s.clips.len())).collect();
        // Two skeletons share the folder, so they are named by what their file names share.
        assert_eq!(got, vec![("quad", 2), ("long_quad_walk", 1)]);
        assert_ne!(set.skeletons[0].rest_row, set.skeletons[1].rest_row, "each proportion has its own rest pose");
        // A prefix other groups' files share is no name: the first clip's stem instead.
        let mut clips = proportions();
        clips[2].name = "zoo/quad_long_walk.bvh".into();
        let (set, _) = TrainSet::build(clips, names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        assert_eq!(set.skeletons.iter().map(|s| s.name.as_str()).collect::<Vec<_>>(), ["quad_walk", "quad_long_walk"]);
        // One skeleton per folder: the folder names it.
        let (set, _) = TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        let folders: Vec<&str> = set.skeletons.iter().map(|s| s.name.as_str()).collect();
        if set.skeletons.len() == 3 {
            assert_eq!(folders, ["biped", "quadruped", "spider"]);
        } else {
            // Seeds vary proportions: several skeletons per folder, all names distinct.
            let mut unique = folders.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), folders.len(), "{folders:?}");
        }
    }

    #[test]
    fn frames_are_dealt_over_variants_once() {
        // Enough clips: whole clips, round-robin.
        assert_eq!(deal(&[30, 40, 50, 60, 70], 1, 4), vec![(1, 0..40)]);
        assert_eq!(deal(&[30, 40, 50, 60, 70], 0, 4), vec![(0, 0..30), (4, 0..70)]);
        // Two clips, four variants: each clip in two halves.
        let pieces: Vec<_> = (0..4).map(|v| deal(&[100, 60], v, 4)).collect();
        assert_eq!(pieces, vec![vec![(0, 0..50)], vec![(1, 0..30)], vec![(0, 50..100)], vec![(1, 30..60)]]);
        // A short clip: pieces overlap rather than get too short to crop.
        for v in 0..4 {
            let p = deal(&[30], v, 4);
            assert_eq!(p.len(), 1);
            assert!(p[0].1.len() == MIN_FRAMES + 2 && p[0].1.end <= 30, "{p:?}");
        }
    }

    #[test]
    fn augmented_variants_are_whole_skeletons_and_deterministic() {
        let names = NameTable::builtin().unwrap();
        let aug = Augmentation::with_seed(7);
        let build = || TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &aug).unwrap().0;
        let set = build();
        assert!(set.variant_count() >= set.skeletons.len(), "every zoo creature can lose and gain joints");
        let original_frames: usize = set.skeletons.iter().flat_map(|s| &s.clips).map(|c| c.frames * c.joints).sum();
        let variant_frames: usize = set.augmented.iter().flatten().flat_map(|s| &s.clips).map(|c| c.frames * c.joints).sum();
        assert!(variant_frames <= original_frames * 5 / 4, "clips are dealt over variants: {variant_frames} vs {original_frames}");
        for (base, variants) in set.skeletons.iter().zip(&set.augmented) {
            for v in variants {
                let j = v.skeleton.len();
                assert_ne!(j, base.skeleton.len(), "{}", v.name);
                assert!(v.name.starts_with(&base.name) && v.name.contains("__"), "{}", v.name);
                assert_eq!(v.rest_row.len(), j * 13);
                assert_eq!((v.relations.len(), v.distances.len(), v.names.len(), v.stats.mean.len()), (j, j, j, j * 13));
                assert!(v.clips.iter().all(|c| c.joints == j && c.data.iter().all(|x| x.is_finite())));
            }
        }
        let again = build();
        let shape = |s: &TrainSet| s.augmented.iter().flatten().map(|v| (v.name.clone(), v.skeleton.len(), v.clips[0].data.clone())).collect::<Vec<_>>();
        assert_eq!(shape(&set), shape(&again), "same seed, same variants");
        let other = TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &Augmentation::with_seed(8)).unwrap().0;
        assert_ne!(shape(&set), shape(&other), "the seed chooses the edits");
    }

    /// The zoo with the default augmentation (seed 7), normalised as `stats` says.
    fn zoo_set(stats: FallbackStats) -> TrainSet {
        zoo_set_in(stats, LossUnits::Normalised)
    }

    /// `zoo_set` with the loss measured in `units`.
    fn zoo_set_in(stats: FallbackStats, units: LossUnits) -> TrainSet {
        let aug = Augmentation { stats, units, ..Augmentation::with_seed(7) };
        TrainSet::build(zoo(), NameTable::builtin().unwrap(), topology::DEFAULT_DMAX, &aug).unwrap().0
    }

    #[test]
    fn a_global_rest_token_carries_every_skeletons_shape_under_the_fallback() {
        let aug = |rest| Augmentation { stats: FallbackStats::All, rest, ..Augmentation::with_seed(7) };
        let build = |a: &Augmentation| TrainSet::build(zoo(), NameTable::builtin().unwrap(), topology::DEFAULT_DMAX, a).unwrap().0;
        let zeros = build(&aug(RestTokens::Skeleton));
        assert!(zeros.rest_norm.is_none());
        assert!(zeros.skeletons.iter().all(|s| s.rest_row.iter().all(|&x| x == 0.0)), "the fallback's mean is the rest pose");
        let global = build(&aug(RestTokens::Pool));
        let norm = global.rest_norm.expect("pooled");
        let raw: Vec<Vec<f32>> = global.skeletons.iter().map(|s| s.section.rest_row.concat()).collect();
        assert_eq!(Some(norm), RestNorm::pool(raw.iter().map(|r| r.as_slice())), "pooled over the skeletons' rest rows");
        for s in global.skeletons.iter().chain(global.augmented.iter().flatten()) {
            let mut expected = Features { frames: 1, joints: s.skeleton.len(), dims: anytop::FEATURE_DIMS, data: s.section.rest_row.concat() };
            norm.for_joints(s.skeleton.len()).normalise(&mut expected).unwrap();
            assert_eq!(s.rest_row, expected.data, "{}", s.name);
        }
        for s in &global.skeletons {
            assert!(s.rest_row.iter().any(|&x| x.abs() > 0.5), "{}: a shape, not zeros", s.name);
        }
        // The motion is normalised as before; only the rest token changes.
        for (a, b) in global.skeletons.iter().zip(&zeros.skeletons) {
            assert_eq!((&a.stats, &a.clips[0].data), (&b.stats, &b.clips[0].data), "{}", a.name);
        }
        // Given statistics (a resumed model's) are used as they are, not pooled again.
        let mut other = norm;
        other.mean[1][0] += 1.0;
        let given = build(&aug(RestTokens::Given(other)));
        assert_eq!(given.rest_norm, Some(other));
        assert_ne!(given.skeletons[0].rest_row, global.skeletons[0].rest_row);
    }

    #[test]
    fn own_units_weigh_a_fallback_draws_error_by_its_own_spreads() {
        let measured = zoo_set(FallbackStats::None);
        let all = zoo_set_in(FallbackStats::All, LossUnits::Own);
        let (lo, hi) = LOSS_WEIGHT_RANGE;
        let mut clamped = 0;
        for (a, m) in all.skeletons.iter().zip(&measured.skeletons) {
            let w = a.loss_weights.as_ref().unwrap_or_else(|| panic!("{}: no weights", a.name));
            assert_eq!(w.len(), m.stats.std.len(), "{}", a.name);
            for (k, &wk) in w.iter().enumerate() {
                let ratio = (a.stats.std[k] + anytop::STD_EPSILON) / (m.stats.std[k] + anytop::STD_EPSILON);
                let expected = (ratio * ratio).clamp(lo, hi);
                assert!((wk - expected).abs() <= 1e-5 * expected, "{} value {k}: {wk} vs {expected}", a.name);
                clamped += usize::from(wk == hi || wk == lo);
            }
        }
        assert!(clamped < all.skeletons.iter().map(|s| s.stats.std.len()).sum::<usize>() / 4, "the clamp is for the odd feature: {clamped}");
        // A creature that moves less than the average spread weighs more, and one that moves more weighs less.
        let spreads = |s: &SkeletonData| s.loss_weights.as_ref().unwrap()[anytop::FEATURE_DIMS];
        assert!(all.skeletons.iter().any(|s| spreads(s) > 1.5) && all.skeletons.iter().any(|s| spreads(s) < 1.0));
        // The data are those of `all` in normalised units; only the weights are new.
        let plain = zoo_set(FallbackStats::All);
        for (a, p) in all.skeletons.iter().zip(&plain.skeletons) {
            assert_eq!((&a.clips[0].data, p.loss_weights.is_none()), (&p.clips[0].data, true), "{}", a.name);
        }
        // Under `variants`, the skeletons keep their own statistics and so need no weights.
        let variants = zoo_set_in(FallbackStats::Variants, LossUnits::Own);
        assert!(variants.skeletons.iter().all(|s| s.loss_weights.is_none()));
        assert!(variants.augmented.iter().flatten().all(|v| v.loss_weights.is_some()));
        assert!(zoo_set_in(FallbackStats::None, LossUnits::Own).augmented.iter().flatten().all(|v| v.loss_weights.is_none()));
    }

    #[test]
    fn fallback_variants_are_normalised_as_sampling_normalises_an_unseen_skeleton() {
        let (measured, set) = (zoo_set(FallbackStats::None), zoo_set(FallbackStats::Variants));
        let trained: Vec<&AnyTopStats> = set.skeletons.iter().map(|s| &s.stats).collect();
        // The skeletons themselves keep their measured statistics; only the variants change.
        for (a, b) in set.skeletons.iter().zip(&measured.skeletons) {
            assert_eq!((&a.stats.mean, &a.rest_row), (&b.stats.mean, &b.rest_row), "{}", a.name);
        }
        let mut variants = 0;
        for (v, m) in set.augmented.iter().flatten().zip(measured.augmented.iter().flatten()) {
            assert_eq!((&v.name, v.skeleton.len()), (&m.name, m.skeleton.len()), "the same edits");
            let expected = crate::diffusion::condition::fallback_stats(&v.section.rest_row, &trained).unwrap();
            assert_eq!((&v.stats.mean, &v.stats.std), (&expected.mean, &expected.std), "{}", v.name);
            assert!(v.rest_row.iter().all(|&x| x == 0.0), "{}: the rest pose is the mean, so P_S is zeros", v.name);
            assert_ne!(v.clips[0].data, m.clips[0].data, "{}: the same frames, normalised otherwise", v.name);
            variants += 1;
        }
        assert!(variants >= set.skeletons.len());
    }

    #[test]
    fn fallback_all_normalises_the_skeletons_too_with_the_measured_average_spreads() {
        let (measured, set) = (zoo_set(FallbackStats::None), zoo_set(FallbackStats::All));
        let trained: Vec<&AnyTopStats> = measured.skeletons.iter().map(|s| &s.stats).collect();
        assert_eq!(set.skeletons.len(), measured.skeletons.len());
        for (a, m) in set.skeletons.iter().zip(&measured.skeletons) {
            assert_eq!((&a.name, a.clips.len()), (&m.name, m.clips.len()));
            let expected = crate::diffusion::condition::fallback_stats(&a.section.rest_row, &trained).unwrap();
            assert_eq!((&a.stats.mean, &a.stats.std), (&expected.mean, &expected.std), "{}", a.name);
            assert!(a.rest_row.iter().all(|&x| x == 0.0), "{}", a.name);
            assert_ne!(a.clips[0].data, m.clips[0].data, "{}", a.name);
        }
        // The variants are those of `variants` (the same average spreads).
        let variants = zoo_set(FallbackStats::Variants);
        let stats = |s: &TrainSet| s.augmented.iter().flatten().map(|v| (v.stats.mean.clone(), v.stats.std.clone())).collect::<Vec<_>>();
        assert_eq!(stats(&set), stats(&variants));
    }

    #[test]
    fn the_sampler_draws_variants_with_the_asked_probability() {
        let names = NameTable::builtin().unwrap();
        let mut aug = Augmentation::with_seed(1);
        let (mut set, _) = TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &aug).unwrap();
        let share = |set: &TrainSet| {
            let crops = set.sample(&mut SplitMix64::new(4), 600, 40);
            for c in &crops {
                let clip = &set.data(c).clips[c.clip];
                assert!(c.frames <= 40 && c.start + c.frames <= clip.frames);
                assert_eq!(set.crop(c).joints, set.data(c).skeleton.len());
            }
            crops.iter().filter(|c| c.variant.is_some()).count() as f64 / crops.len() as f64
        };
        let p = share(&set);
        assert!((p - 2.0 / 3.0).abs() < 0.08, "{p}");
        set.augment_probability = 0.0;
        assert_eq!(share(&set), 0.0);
        let off = Augmentation { probability: 0.0, ..aug };
        assert_eq!(TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &off).unwrap().0.variant_count(), 0, "probability 0: no variants built");
        set.augment_probability = 1.0;
        assert_eq!(share(&set), 1.0);
        aug.probability = 1.5;
        assert!(matches!(TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &aug), Err(DataError::Probability(_))));
    }

    /// One zoo quadruped's five actions, as the zoo writes them (`synth::training_clip`).
    fn quadruped_actions() -> Vec<Clip> {
        use crate::synth::{training_clip, Action};
        [Action::Walk, Action::Run, Action::Idle, Action::Turn, Action::WalkStopWalk]
            .iter()
            .map(|&a| {
                let c = training_clip("quadruped", 0, a, 1, 160).unwrap();
                Clip { name: format!("quadruped/{}.bvh", a.name()), skeleton: c.skeleton, motion: c.motion }
            })
            .collect()
    }

    /// Of the zoo quadruped's actions only the idle is still; weight 1 draws the clips alike
    /// (and the same crops after other weights were used), 0 never draws the idle, 0.25 draws
    /// it about a quarter as often as each moving clip.
    #[test]
    fn the_still_weight_draws_the_idle_clip_less_often() {
        let names = NameTable::builtin().unwrap();
        let (mut set, _) = TrainSet::build(quadruped_actions(), names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        let sk = &set.skeletons[0];
        let idle = sk.clip_names.iter().position(|n| n.contains("idle")).unwrap();
        let still = still_clips(sk);
        assert_eq!(still.iter().filter(|&&s| s).count(), 1, "{still:?} for {:?}", sk.clip_names);
        assert!(still[idle]);
        let share = |set: &TrainSet| set.sample(&mut SplitMix64::new(9), 4000, 40).iter().filter(|c| c.clip == idle).count() as f64 / 4000.0;
        let alike = set.sample(&mut SplitMix64::new(9), 300, 40);
        assert!((share(&set) - 0.2).abs() < 0.03, "{}", share(&set));
        set.still_weight = 0.0;
        assert_eq!(share(&set), 0.0);
        set.still_weight = 0.25;
        // 0.25 / (4 + 0.25) of the draws.
        assert!((share(&set) - 0.25 / 4.25).abs() < 0.02, "{}", share(&set));
        set.still_weight = 1.0;
        assert_eq!(set.sample(&mut SplitMix64::new(9), 300, 40), alike);
    }

    /// All still or none: every clip alike, whatever the weight.
    #[test]
    fn a_weighted_draw_is_uniform_when_all_clips_weigh_alike() {
        let mut rng = SplitMix64::new(3);
        let mut counts = [0usize; 3];
        for _ in 0..3000 {
            counts[draw_weighted(&mut rng, &[true, true, true], 0.0)] += 1;
        }
        assert!(counts.iter().all(|&c| (800..1200).contains(&c)), "{counts:?}");
        let mut counts = [0usize; 3];
        for _ in 0..3000 {
            counts[draw_weighted(&mut rng, &[false, true, false], 0.0)] += 1;
        }
        assert_eq!(counts[1], 0, "{counts:?}");
        assert!(counts[0] > 1300 && counts[2] > 1300, "{counts:?}");
    }

    /// Off, every crop sits at position 0 and the draw stream is the one runs had before the
    /// jitter; on, positions spread over 0..=N apart from the crops, which stay the same.
    #[test]
    fn the_position_jitter_spreads_positions_and_leaves_the_crops() {
        let names = NameTable::builtin().unwrap();
        let (mut set, _) = TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        let off = set.sample(&mut SplitMix64::new(5), 400, 40);
        assert!(off.iter().all(|c| c.position == 0));
        set.position_jitter = 100;
        let on = set.sample(&mut SplitMix64::new(5), 400, 40);
        assert!(on.iter().all(|c| c.position <= 100));
        let distinct: std::collections::BTreeSet<usize> = on.iter().map(|c| c.position).collect();
        assert!(distinct.len() > 60 && distinct.iter().any(|&p| p > 90) && distinct.iter().any(|&p| p < 10), "{distinct:?}");
        // The first crop is drawn before any position, so it is the same with or without.
        assert_eq!((on[0].skeleton, on[0].clip, on[0].start), (off[0].skeleton, off[0].clip, off[0].start));
        assert_eq!(on, set.sample(&mut SplitMix64::new(5), 400, 40), "same seed, same positions");
    }

    #[test]
    fn sampling_is_balanced_deterministic_and_in_range() {
        let names = NameTable::builtin().unwrap();
        let (set, _) = TrainSet::build(zoo(), names, topology::DEFAULT_DMAX, &Augmentation::none()).unwrap();
        let a = set.sample(&mut SplitMix64::new(3), 300, 40);
        let b = set.sample(&mut SplitMix64::new(3), 300, 40);
        assert_eq!(a, b);
        let mut count = vec![0usize; set.skeletons.len()];
        for c in &a {
            count[c.skeleton] += 1;
            let clip = &set.skeletons[c.skeleton].clips[c.clip];
            assert!(c.frames <= 40 && c.start + c.frames <= clip.frames);
            assert_eq!(set.crop(c).frames, c.frames);
        }
        let expected = 300 / set.skeletons.len();
        assert!(count.iter().all(|&n| n.abs_diff(expected) < expected / 3), "{count:?}");
    }
}
