//! Diffusion features (DIFT, AnyTop §4.1 after Tang et al. 2023): noise a clean motion to
//! diffusion step t, run the denoiser once, and read the activations after layer l —
//! `[frames + 1, joints, width]`, token 0 being the rest pose P_S. Joints of different creatures
//! that do the same job, and frames that do the same action, land close together.
//!
//! One noise draw gives noisy descriptors (the reference uses exactly one); we average the
//! activations over several draws, each from its own seeded stream, so the features are a
//! property of the motion more than of one ε.
//!
//! `correspond` turns features into joint and frame correspondences; `eval` has the
//! ground-truth set-ups (renamed and shuffled copies, time warps) the benchmarks score them on.

pub mod correspond;
pub mod eval;
pub mod report;

use crate::diffusion::checkpoint::CheckpointInfo;
use crate::diffusion::condition::{SkeletonCondition, StatsSource};
use crate::diffusion::sample::Condition;
use crate::diffusion::{DiffusionError, Schedule};
use crate::document::AnyTopSection;
use crate::motion::Motion;
use crate::nn::{batch_from, BatchItem, Denoiser, NnError};
use crate::repr::anytop::{AnyTopError, AnyTopStats, RigError};
use crate::repr::Features;
use crate::rng::gaussian;
use crate::rng::SplitMix64;
use crate::skeleton::Skeleton;
use candle_core::Device;

/// Where and how to read the features.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiftOptions {
    /// Diffusion step the motion is noised to (0 = least noise; the schedule has T steps).
    pub t: usize,
    /// Layer whose output is read (0-based).
    pub layer: usize,
    /// Noise draws averaged.
    pub draws: usize,
    pub seed: u64,
    /// Place each draw at its own random temporal position (for frame descriptors: see
    /// `extract`); joint descriptors, averaged over time, do better without.
    pub shift: bool,
}

/// What can go wrong preparing a clip or extracting its features.
#[derive(Debug, thiserror::Error)]
pub enum DiftError {
    /// Bad options or a clip of the wrong size.
    #[error("{0}")]
    Invalid(String),
    /// Encoding or normalising a clip; `what` names it.
    #[error("{what}")]
    Repr { what: String, source: AnyTopError },
    #[error(transparent)]
    Rig(#[from] RigError),
    #[error("{file}")]
    Condition { file: String, source: DiffusionError },
    #[error(transparent)]
    Nn(#[from] NnError),
    #[error(transparent)]
    Tensor(#[from] candle_core::Error),
    #[error(transparent)]
    Names(#[from] crate::embed::EmbedError),
    /// Extraction failed on the named clip.
    #[error("{name}")]
    Clip {
        name: String,
        #[source]
        source: Box<DiftError>,
    },
}

impl DiftError {
    fn repr(file: &str) -> impl FnOnce(AnyTopError) -> DiftError + '_ {
        move |source| DiftError::Repr { what: file.to_string(), source }
    }
}

impl DiftOptions {
    /// The paper's joint-correspondence setting (§4.1: t = 2, l = 0).
    pub const SPATIAL: DiftOptions = DiftOptions { t: 2, layer: 0, draws: 4, seed: 0, shift: false };
    /// The paper's frame-correspondence and segmentation setting (§4.1, §5: t = 3, l = 1).
    pub const TEMPORAL: DiftOptions = DiftOptions { t: 3, layer: 1, draws: 4, seed: 0, shift: true };
}

/// Activations `[tokens, joints, width]` (tokens = frames + 1; token 0 is P_S).
#[derive(Clone, Debug, PartialEq)]
pub struct DiftFeatures {
    pub tokens: usize,
    pub joints: usize,
    pub width: usize,
    pub data: Vec<f32>,
}

impl DiftFeatures {
    /// The features as a little-endian float32 NPY `[tokens, joints, width]`.
    pub fn to_npy(&self) -> std::io::Result<Vec<u8>> {
        let mut bytes = Vec::new();
        crate::io::npy::write_f32_parts(&mut bytes, &[self.tokens, self.joints, self.width], &[self.data.as_slice()])?;
        Ok(bytes)
    }

    /// Motion frames (tokens minus the rest-pose token).
    pub fn frames(&self) -> usize {
        self.tokens.saturating_sub(1)
    }

    fn at(&self, token: usize, joint: usize) -> &[f32] {
        let i = (token * self.joints + joint) * self.width;
        &self.data[i..i + self.width]
    }

    /// One descriptor per joint: the mean over the motion frames (the P_S token is left out:
    /// it is the same for every motion of the skeleton, and the reference's off-by-one that
    /// counts it is not a choice worth copying).
    pub fn per_joint(&self) -> Vec<Vec<f32>> {
        let first = if self.tokens > 1 { 1 } else { 0 };
        let n = (self.tokens - first).max(1) as f32;
        (0..self.joints)
            .map(|j| {
                let mut v = vec![0f32; self.width];
                for t in first..self.tokens {
                    v.iter_mut().zip(self.at(t, j)).for_each(|(a, b)| *a += b);
                }
                v.iter_mut().for_each(|a| *a /= n);
                v
            })
            .collect()
    }

    /// One descriptor per motion frame: the mean over joints (frame k is token k + 1).
    pub fn per_frame(&self) -> Vec<Vec<f32>> {
        (1..self.tokens)
            .map(|t| {
                let mut v = vec![0f32; self.width];
                for j in 0..self.joints {
                    v.iter_mut().zip(self.at(t, j)).for_each(|(a, b)| *a += b);
                }
                v.iter_mut().for_each(|a| *a /= self.joints as f32);
                v
            })
            .collect()
    }

    /// One descriptor per motion frame: every joint's activations one after the other
    /// (`joints x width` long). Finer than `per_frame` — which pose, not only how much the body
    /// moves — but it compares only frames of one skeleton (same joints, same order).
    pub fn per_frame_joints(&self) -> Vec<Vec<f32>> {
        let per = self.joints * self.width;
        (1..self.tokens).map(|t| self.data[t * per..(t + 1) * per].to_vec()).collect()
    }
}

/// Frame descriptors of a reference and a target motion, comparable by cosine: each joint's
/// activations side by side when both are of one skeleton (`same_skeleton`), else the mean over
/// joints (AnyTop's, which works across creatures). Then centred on the mean frame of both
/// clips together (what every frame shares would dominate the cosine; one mean for both, so a
/// target that shows only part of the reference is not shifted against it). Measured on
/// time-warped corpus clips (benches/dift.rs): the joint mean leaves poses ambiguous that the
/// joints side by side tell apart.
pub fn frame_descriptors(reference: &DiftFeatures, target: &DiftFeatures, same_skeleton: bool) -> (Vec<Vec<f32>>, Vec<Vec<f32>>) {
    let (mut rows, split) = if same_skeleton && reference.joints == target.joints && reference.width == target.width {
        let r = reference.per_frame_joints();
        let n = r.len();
        (r.into_iter().chain(target.per_frame_joints()).collect::<Vec<_>>(), n)
    } else {
        let r = reference.per_frame();
        let n = r.len();
        (r.into_iter().chain(target.per_frame()).collect(), n)
    };
    rows = centred(rows);
    let target_rows = rows.split_off(split);
    (rows, target_rows)
}

/// Each row minus the mean row: removes what every joint (or frame) shares — the timestep
/// embedding, and averaged over time, the temporal positions — which otherwise dominates the
/// cosine (raw scores all sit near 0.98 with margins of 1e-3).
pub fn centred(mut rows: Vec<Vec<f32>>) -> Vec<Vec<f32>> {
    let Some(width) = rows.first().map(Vec::len) else { return rows };
    let mut mean = vec![0f64; width];
    for r in &rows {
        mean.iter_mut().zip(r).for_each(|(m, &v)| *m += v as f64);
    }
    let n = rows.len() as f64;
    for r in &mut rows {
        r.iter_mut().zip(&mean).for_each(|(v, m)| *v -= (m / n) as f32);
    }
    rows
}

/// A motion ready for the denoiser: its condition, and its AnyTop features normalised.
pub struct PreparedMotion {
    pub condition: SkeletonCondition,
    /// Normalised `[frames − 1, joints, 13]` (AnyTop features drop a BVH's last frame).
    pub features: Features,
}

/// Encode `motion` (of `skeleton`, read from `file`) for the model `info` describes: the rig's
/// rest pose is the clip's first frame (AnyTop's rule without a T-pose file, as `skel-info`),
/// and the clip is normalised by its own statistics — also for a skeleton the model was trained
/// on: two motions are compared, and normalising one by the training set's statistics and the
/// other by its own shifts all of its features alike, so a few reference joints become
/// everyone's best match (measured: a quadruped against its own skel-aug variant, 5 of 21
/// joints right with the training statistics for the original, 21 of 21 with each clip's own).
pub fn prepare(info: &CheckpointInfo, skeleton: &Skeleton, motion: &Motion, file: &str) -> Result<PreparedMotion, DiftError> {
    if motion.frames < 2 {
        return Err(DiftError::Invalid(format!("{file}: {} frame(s); DIFT features need a motion of at least 2 frames", motion.frames)));
    }
    let section = AnyTopSection::of_clip(skeleton, motion, file).map_err(|source| RigError { name: file.to_string(), source })?;
    let features = section.rig.encode(skeleton, motion).map_err(DiftError::repr(file))?.features;
    prepare_encoded(info, skeleton, &section.rest_row, features, file)
}

/// `prepare` for a motion already encoded (physical AnyTop features) with a rig whose P_S is
/// `rest_row`, e.g. an NPY from `mo-encode` and its skeleton document.
pub fn prepare_encoded(
    info: &CheckpointInfo,
    skeleton: &Skeleton,
    rest_row: &[Vec<f32>],
    mut features: Features,
    file: &str,
) -> Result<PreparedMotion, DiftError> {
    let measured = AnyTopStats::compute([&features]).map_err(DiftError::repr(file))?;
    let condition = SkeletonCondition::with_stats(info, skeleton, rest_row, measured, StatsSource::Measured)
        .map_err(|source| DiftError::Condition { file: file.to_string(), source })?;
    condition.stats.normalise(&mut features).map_err(DiftError::repr(file))?;
    Ok(PreparedMotion { condition, features })
}

/// DIFT features of a clip with `model` (`prepare`, then `extract`), what `mo-dift` writes.
pub fn of_clip(
    model: &crate::diffusion::checkpoint::FrozenDenoiser,
    clip: &crate::motion::Clip,
    opts: &DiftOptions,
    device: &Device,
) -> Result<DiftFeatures, DiftError> {
    let prepared = prepare(&model.info, &clip.skeleton, &clip.motion, &clip.name)?;
    let (schedule, condition) = (model.info.schedule(), prepared.condition.condition());
    extract(&model.model, &schedule, &condition, &prepared.features, opts, device).map_err(|e| DiftError::Clip { name: clip.name.clone(), source: Box::new(e) })
}

/// Draws place the clip at a temporal position below this (training crops start anywhere in
/// clips of a few hundred frames).
const MAX_START: usize = 256;

/// Tokens (frames x joints x draws) per forward pass: bounds memory on long clips.
const TOKENS_PER_PASS: usize = 48_000;

/// DIFT features of a normalised motion (`PreparedMotion::features`): the mean over `opts.draws`
/// noise draws of the activations after `opts.layer` at step `opts.t`. Deterministic for
/// `opts.seed`; draw k always takes the same noise whatever the batching.
pub fn extract(
    model: &Denoiser,
    schedule: &Schedule,
    cond: &Condition,
    motion: &Features,
    opts: &DiftOptions,
    device: &Device,
) -> Result<DiftFeatures, DiftError> {
    let cfg = model.config();
    if opts.t >= schedule.len() {
        return Err(DiftError::Invalid(format!("diffusion step {} is past the schedule's last ({})", opts.t, schedule.len().saturating_sub(1))));
    }
    if opts.layer >= cfg.layers {
        return Err(DiftError::Invalid(format!("layer {} does not exist: the model has layers 0..{}", opts.layer, cfg.layers.saturating_sub(1))));
    }
    if opts.draws == 0 {
        return Err(DiftError::Invalid("at least one noise draw is needed".into()));
    }
    if motion.joints != cond.names.len() || motion.dims != cfg.feature_dims || motion.frames == 0 {
        return Err(DiftError::Invalid(format!(
            "the motion is [{}, {}, {}] but the skeleton has {} joints and the model reads {} features per joint",
            motion.frames,
            motion.joints,
            motion.dims,
            cond.names.len(),
            cfg.feature_dims
        )));
    }
    let (a, b) = schedule.noise_coefficients(opts.t);
    let per = motion.data.len();
    let per_pass = (TOKENS_PER_PASS / ((motion.frames + 1) * motion.joints).max(1)).clamp(1, opts.draws);
    let mut rng = SplitMix64::new(opts.seed);
    let mut sum: Vec<f64> = Vec::new();
    let mut done = 0;
    while done < opts.draws {
        let n = per_pass.min(opts.draws - done);
        let noised: Vec<Features> = (0..n)
            .map(|_| {
                let eps = gaussian(&mut rng, per);
                let data = motion.data.iter().zip(&eps).map(|(&x, &e)| (a * x as f64 + b * e as f64) as f32).collect();
                Features { data, ..motion.clone() }
            })
            .collect();
        // With `shift`, each draw places the clip at its own temporal position (as a training
        // crop would be): with a fixed start, frame k of any two clips shares its position
        // embedding, and frame matching drifts to k -> k whatever the motion (benches/dift.rs:
        // mean frame error on time-warped corpus clips 8.5 -> 7.0 at t 3, layer 1).
        let starts: Vec<u32> = (0..n).map(|_| if opts.shift { rng.below(MAX_START) as u32 } else { 0 }).collect();
        let items: Vec<BatchItem> = noised
            .iter()
            .zip(&starts)
            .map(|(f, &start)| BatchItem {
                features: f,
                rest_row: cond.rest_row,
                relations: cond.relations,
                distances: cond.distances,
                names: cond.names,
                start,
            })
            .collect();
        let batch = batch_from(&items, &vec![opts.t as u32; n], device)?;
        let h: Vec<f32> = model.activations(&batch, opts.layer)?.flatten_all()?.to_vec1()?;
        let block = h.len() / n;
        if sum.is_empty() {
            sum = vec![0.0; block];
        }
        for draw in h.chunks_exact(block) {
            sum.iter_mut().zip(draw).for_each(|(s, &v)| *s += v as f64);
        }
        done += n;
    }
    let data = sum.iter().map(|&s| (s / opts.draws as f64) as f32).collect();
    Ok(DiftFeatures { tokens: motion.frames + 1, joints: motion.joints, width: cfg.width, data })
}
