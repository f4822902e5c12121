//! Denoiser checkpoints: a directory with `model.safetensors` (readable parameter names),
//! `optimizer.safetensors` (AdamW moments), and `checkpoint.json` (config, step, seed, the
//! training settings, and per-skeleton normalisation statistics so that sampling a trained
//! skeleton uses its own). Files are written beside their final names and renamed, so an
//! interrupted save never leaves a partial file.

use super::data::{offsets_agree, rest_record};
use super::ema::{Ema, RAW_PREFIX};
use super::train::{named_vars, AdamW};
use crate::document::AnyTopSection;
use crate::motion::Motion;
use crate::nn::{seeded_var_builder, Denoiser, DenoiserConfig, NnError};
use crate::repr::anytop::{AnyTopError, AnyTopStats};
use crate::skeleton::Skeleton;
use candle_core::Device;
use candle_nn::VarMap;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const FORMAT: &str = "menagerie.denoiser";
pub const VERSION: u32 = 1;

/// What can go wrong reading or writing a model directory (`sata::checkpoint` and
/// `sata::rigs` use it too). Messages name the file; `Model` says which model.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("{what}")]
    Io { what: String, source: std::io::Error },
    #[error("{what}")]
    Tensor { what: String, source: candle_core::Error },
    #[error("{what}")]
    Json { what: String, source: serde_json::Error },
    /// Readable, but not a model this version uses.
    #[error("{0}")]
    Invalid(String),
    #[error("model.safetensors does not match checkpoint.json's config")]
    Mismatch(#[source] NnError),
    #[error(transparent)]
    Config(#[from] NnError),
    /// An error about one model: `model DIR`, `the built-in default model`.
    #[error("{model}")]
    Model { model: String, source: Box<CheckpointError> },
}

impl CheckpointError {
    pub(crate) fn io(what: String) -> impl FnOnce(std::io::Error) -> CheckpointError {
        move |source| CheckpointError::Io { what, source }
    }

    pub(crate) fn tensor(what: String) -> impl FnOnce(candle_core::Error) -> CheckpointError {
        move |source| CheckpointError::Tensor { what, source }
    }

    pub(crate) fn json(what: String) -> impl FnOnce(serde_json::Error) -> CheckpointError {
        move |source| CheckpointError::Json { what, source }
    }

    /// This error, said to be about `model`.
    pub(crate) fn of(model: String) -> impl FnOnce(CheckpointError) -> CheckpointError {
        move |e| CheckpointError::Model { model, source: Box::new(e) }
    }
}

/// One trained skeleton: how to recognise it and its statistics.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TrainedSkeleton {
    pub name: String,
    pub joints: Vec<String>,
    pub parents: Vec<Option<usize>>,
    pub stats: AnyTopStats,
    pub clips: usize,
    /// Rest offsets (BVH units), to tell proportion variants of one rig apart; empty in
    /// checkpoints written before they were recorded.
    #[serde(default)]
    pub offsets: Vec<[f64; 3]>,
    /// The frames training built its AnyTop record from; absent in checkpoints written before
    /// they were recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest: Option<TrainedRest>,
}

/// The frames training built a skeleton's AnyTop record (rig and rest-pose row P_S) from: its
/// rest clip's first two. The record depends on which clip that is, and the model learnt under
/// this one; a sampler given the skeleton in any other file builds the same record from these
/// frames. (zoo-tiny, step 104,440, sampled from `walk_0.bvh`'s own record instead of
/// `idle_0.bvh`'s, the one training used, moved 0.53-0.86 times as much: models/zoo-tiny/MODEL_CARD.md.)
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TrainedRest {
    /// The clip's file name (it also says whether the frames are a T-pose file's).
    pub file: String,
    pub frame_time: f64,
    /// Local rotations (x, y, z, w) and translations of every joint, frame 0's then frame 1's.
    pub rotations: Vec<[f64; 4]>,
    pub translations: Vec<[f64; 3]>,
}

impl TrainedRest {
    /// The record of `motion`'s first two frames, from the clip named `clip`.
    pub fn new(clip: &str, motion: &Motion) -> TrainedRest {
        let first = motion.first_frames(2);
        TrainedRest {
            file: Path::new(clip).file_name().map_or_else(|| clip.to_string(), |f| f.to_string_lossy().into_owned()),
            frame_time: first.frame_time,
            rotations: first.rotations.iter().map(|q| q.to_array()).collect(),
            translations: first.translations.iter().map(|t| t.to_array()).collect(),
        }
    }

    /// The frames as a motion of `joints` joints (None when they do not fit).
    fn motion(&self, joints: usize) -> Option<Motion> {
        let n = self.rotations.len();
        if joints == 0 || n != self.translations.len() || !n.is_multiple_of(joints) || !(1..=2).contains(&(n / joints)) {
            return None;
        }
        Some(Motion {
            frames: n / joints,
            joints,
            frame_time: self.frame_time,
            rotations: self.rotations.iter().map(|&q| DQuat::from_array(q)).collect(),
            translations: self.translations.iter().map(|&t| DVec3::from_array(t)).collect(),
        })
    }
}

impl TrainedSkeleton {
    /// Same joint names and parents (proportions aside).
    pub fn matches(&self, s: &Skeleton) -> bool {
        self.joints.len() == s.len() && s.joints.iter().zip(&self.joints).zip(&self.parents).all(|((j, n), p)| &j.name == n && &j.parent == p)
    }

    /// The largest difference between a non-root rest offset of `s` and the recorded one
    /// (0 when none are recorded); call only when `matches`.
    fn offset_gap(&self, s: &Skeleton) -> f64 {
        s.joints.iter().zip(&self.offsets).skip(1).map(|(j, o)| (j.offset - glam::DVec3::from_array(*o)).abs().max_element()).fold(0.0, f64::max)
    }
}

/// The AnyTop record training built for `s` (as `diffusion::data` builds it), when `s` is a
/// trained skeleton with the same proportions and the checkpoint recorded its rest frames;
/// with the file those frames came from.
pub fn trained_record(trained: &[TrainedSkeleton], s: &Skeleton) -> Option<(String, Result<AnyTopSection, AnyTopError>)> {
    let t = find_trained(trained, s)?;
    let rest = t.rest.as_ref()?;
    let offsets = t.offsets.iter().map(|&o| DVec3::from_array(o));
    if t.offsets.len() != s.len() || !offsets_agree(s.rest_extent(), s.joints.iter().map(|j| j.offset), offsets) {
        return None;
    }
    let motion = rest.motion(s.len())?;
    Some((rest.file.clone(), rest_record(s, &rest.file, &motion)))
}

/// The trained skeleton whose statistics suit `s`: among those with its joint names and
/// parents, the one with the nearest rest offsets (proportion variants of one rig are trained
/// as separate skeletons, `data::same_skeleton`).
pub fn find_trained<'a>(trained: &'a [TrainedSkeleton], s: &Skeleton) -> Option<&'a TrainedSkeleton> {
    trained.iter().filter(|t| t.matches(s)).min_by(|a, b| a.offset_gap(s).total_cmp(&b.offset_gap(s)))
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CheckpointInfo {
    pub format: String,
    pub version: u32,
    pub config: DenoiserConfig,
    pub step: u64,
    pub seed: u64,
    pub schedule_steps: usize,
    pub lr: f64,
    pub batch: usize,
    pub crop: usize,
    pub dmax: usize,
    /// Skeletal augmentation: the chance a draw uses an augmented skeleton, and how many
    /// variants each skeleton has (0 and 0 in checkpoints written before augmentation).
    #[serde(default)]
    pub augment: f64,
    #[serde(default)]
    pub augment_variants: usize,
    /// What training normalised by the fallback statistics (`data::FallbackStats`; none in
    /// checkpoints written before the choice).
    #[serde(default, skip_serializing_if = "is_no_fallback")]
    pub fallback_stats: crate::diffusion::data::FallbackStats,
    /// The units of a fallback-normalised draw's error (`data::LossUnits`; normalised in
    /// checkpoints written before the choice).
    #[serde(default, skip_serializing_if = "is_normalised_units")]
    pub loss_units: crate::diffusion::data::LossUnits,
    /// What the rest tokens were normalised by, when not each skeleton's statistics
    /// (`rest_norm`; absent in checkpoints written before the choice). Sampling normalises a
    /// skeleton's rest token by it too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest_norm: Option<crate::diffusion::rest_norm::RestNorm>,
    /// Decay of the weights' moving average that `model.safetensors` holds (`ema.rs`); 0 = the
    /// raw weights (and checkpoints written before the average existed).
    #[serde(default)]
    pub ema: f64,
    /// The noise schedule's shift (`Schedule::cosine_shifted`); 1 in checkpoints written
    /// before it existed.
    #[serde(default = "no_shift")]
    pub noise_shift: f64,
    /// The shift is tapered (`Schedule::cosine_tapered`) rather than whole; false in
    /// checkpoints written before the taper existed.
    #[serde(default)]
    pub shift_taper: bool,
    /// Training crops' temporal positions started at a random offset in `0..=position_jitter`
    /// (`data::Crop::position`); 0 in checkpoints written before it existed (every crop at 0).
    #[serde(default)]
    pub position_jitter: usize,
    /// How often still clips were drawn against moving ones (`data::still_clips`); 1 (alike) in
    /// checkpoints written before it existed.
    #[serde(default = "alike", skip_serializing_if = "is_alike")]
    pub still_weight: f64,
    /// How the diffusion steps weighed in the loss (`train::Weighting`); x0 in checkpoints
    /// written before it existed.
    #[serde(default = "plain_x0", skip_serializing_if = "is_plain_x0")]
    pub weighting: crate::diffusion::train::Weighting,
    /// The model a fine-tune started from (`mo-train --init`), as "the built-in default model
    /// (step N)" or "model DIR (step N)"; absent for a run from random weights.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub init: Option<String>,
    pub skeletons: Vec<TrainedSkeleton>,
}

fn is_no_fallback(v: &crate::diffusion::data::FallbackStats) -> bool {
    *v == crate::diffusion::data::FallbackStats::None
}

fn is_normalised_units(v: &crate::diffusion::data::LossUnits) -> bool {
    *v == crate::diffusion::data::LossUnits::Normalised
}

fn alike() -> f64 {
    1.0
}

fn is_alike(w: &f64) -> bool {
    *w == 1.0
}

fn no_shift() -> f64 {
    1.0
}

fn plain_x0() -> crate::diffusion::train::Weighting {
    crate::diffusion::train::Weighting::X0
}

fn is_plain_x0(w: &crate::diffusion::train::Weighting) -> bool {
    *w == crate::diffusion::train::Weighting::X0
}

impl CheckpointInfo {
    /// The training skeletons this checkpoint records, as the out-of-distribution score's
    /// reference (`ood`).
    pub fn ood_reference(&self) -> Result<crate::ood::Reference, crate::embed::EmbedError> {
        crate::ood::Reference::from_records(self.skeletons.iter().map(|t| (t.name.as_str(), t.joints.as_slice(), t.parents.as_slice(), t.offsets.as_slice())))
    }

    /// The noise schedule the model was trained with: sampling must use the same one.
    pub fn schedule(&self) -> crate::diffusion::Schedule {
        if self.shift_taper {
            crate::diffusion::Schedule::cosine_tapered(self.schedule_steps, self.noise_shift)
        } else {
            crate::diffusion::Schedule::cosine_shifted(self.schedule_steps, self.noise_shift)
        }
    }
}

/// Save model, optimiser and info to `dir` (created if needed). All three files are written
/// under temporary names first and only then renamed into place, info last, so an
/// interruption at any point leaves either the previous checkpoint's files or the new ones,
/// never a partial file (the renames themselves are atomic).
/// Any model's checkpoint (`sata::checkpoint` uses it too): `info` is its `checkpoint.json`.
pub fn save(dir: &Path, info: &impl Serialize, varmap: &VarMap, opt: &AdamW) -> Result<(), CheckpointError> {
    save_averaged(dir, info, varmap, opt, None)
}

/// `save`, with `model.safetensors` holding the weights' moving average `ema` when there is
/// one, and the raw weights then kept in `optimizer.safetensors` for `--resume` (`ema.rs`).
pub fn save_averaged(dir: &Path, info: &impl Serialize, varmap: &VarMap, opt: &AdamW, ema: Option<&Ema>) -> Result<(), CheckpointError> {
    std::fs::create_dir_all(dir).map_err(CheckpointError::io(format!("cannot create {}", dir.display())))?;
    let tmp = |name: &str| dir.join(format!(".{name}.tmp"));
    let model = tmp("model.safetensors");
    let optimizer = tmp("optimizer.safetensors");
    let mut state: std::collections::HashMap<String, candle_core::Tensor> =
        opt.state().map_err(CheckpointError::tensor(format!("cannot write {}", optimizer.display())))?.into_iter().collect();
    match ema {
        None => varmap.save(&model).map_err(CheckpointError::tensor(format!("cannot write {}", model.display())))?,
        Some(ema) => {
            let weights: std::collections::HashMap<&str, candle_core::Tensor> = ema.weights().iter().map(|(k, t)| (k.as_str(), t.clone())).collect();
            candle_core::safetensors::save(&weights, &model).map_err(CheckpointError::tensor(format!("cannot write {}", model.display())))?;
            for (name, var) in named_vars(varmap) {
                state.insert(format!("{RAW_PREFIX}{name}"), var.as_tensor().clone());
            }
        }
    }
    candle_core::safetensors::save(&state, &optimizer).map_err(CheckpointError::tensor(format!("cannot write {}", optimizer.display())))?;
    let text = serde_json::to_string_pretty(info).map_err(CheckpointError::json("serialising the checkpoint info".into()))?;
    let json = tmp("checkpoint.json");
    std::fs::write(&json, text + "\n").map_err(CheckpointError::io(format!("cannot write {}", json.display())))?;
    // The info goes last: a checkpoint.json always describes complete tensor files.
    for name in ["model.safetensors", "optimizer.safetensors", "checkpoint.json"] {
        let from = tmp(name);
        std::fs::rename(&from, dir.join(name)).map_err(CheckpointError::io(format!("cannot move {} into place", from.display())))?;
    }
    Ok(())
}

/// A loaded checkpoint.
pub struct LoadedDenoiser {
    pub info: CheckpointInfo,
    pub varmap: VarMap,
    pub model: Denoiser,
}

/// Load `dir`'s info and model (the optimiser separately, with `load_optimizer`).
pub fn load(dir: &Path, device: &Device) -> Result<LoadedDenoiser, CheckpointError> {
    let (info, weights) = read_dir_files(dir)?;
    load_bytes(&info, &weights, device).map_err(CheckpointError::of(format!("model {}", dir.display())))
}

/// The bytes of `dir`'s `checkpoint.json` and `model.safetensors`.
pub fn read_dir_files(dir: &Path) -> Result<(Vec<u8>, Vec<u8>), CheckpointError> {
    let path = dir.join("checkpoint.json");
    let info =
        std::fs::read(&path).map_err(CheckpointError::io(format!("cannot read {} (is {} a model directory from mo-train?)", path.display(), dir.display())))?;
    let weights = dir.join("model.safetensors");
    let bytes = std::fs::read(&weights).map_err(CheckpointError::io(format!("cannot read {}", weights.display())))?;
    Ok((info, bytes))
}

/// Diffusion steps a checkpoint may declare (ours train with 100).
pub const MAX_SCHEDULE_STEPS: usize = 10_000;
/// The largest noise-schedule shift a checkpoint may carry (log-SNR moved by 2·ln 100 ≈ 9).
pub const MAX_NOISE_SHIFT: f64 = 100.0;

/// `checkpoint.json`'s description, checked to be ours and of this version.
fn parse_info(info_json: &[u8]) -> Result<CheckpointInfo, CheckpointError> {
    let info: CheckpointInfo = serde_json::from_slice(info_json).map_err(CheckpointError::json("checkpoint.json: not a checkpoint description".into()))?;
    if info.format != FORMAT || info.version != VERSION {
        return Err(CheckpointError::Invalid(format!("checkpoint.json: format {} version {}, expected {FORMAT} version {VERSION}", info.format, info.version)));
    }
    // The noise schedule is rebuilt from this count; 0 or 1 steps is no schedule at all.
    if !(info.noise_shift.is_finite() && (1.0..=MAX_NOISE_SHIFT).contains(&info.noise_shift)) {
        return Err(CheckpointError::Invalid(format!("checkpoint.json: noise_shift is {}, expected 1 to {MAX_NOISE_SHIFT}", info.noise_shift)));
    }
    if !(2..=MAX_SCHEDULE_STEPS).contains(&info.schedule_steps) {
        return Err(CheckpointError::Invalid(format!("checkpoint.json: schedule_steps is {}, expected 2 to {MAX_SCHEDULE_STEPS}", info.schedule_steps)));
    }
    Ok(info)
}

/// A checkpoint from the bytes of its `checkpoint.json` and `model.safetensors` (the embedded
/// default model has no directory).
pub fn load_bytes(info_json: &[u8], weights: &[u8], device: &Device) -> Result<LoadedDenoiser, CheckpointError> {
    let info = parse_info(info_json)?;
    let varmap = VarMap::new();
    // Build every parameter (the seed does not matter: all are overwritten), then fill them.
    let model = Denoiser::new(seeded_var_builder(&varmap, 0, device), &info.config)?;
    fill_vars(&varmap, weights, device)?;
    Ok(LoadedDenoiser { info, varmap, model })
}

/// Overwrite every variable of `varmap` with the tensor of the same name in the safetensors
/// bytes `weights`; a missing or misshapen one is an error.
pub fn fill_vars(varmap: &VarMap, weights: &[u8], device: &Device) -> Result<(), CheckpointError> {
    let tensors =
        candle_core::safetensors::load_buffer(weights, device).map_err(CheckpointError::tensor("model.safetensors: not a safetensors file".into()))?;
    let vars = varmap.data().lock().map_err(|_| CheckpointError::Invalid("the parameter map is poisoned".into()))?;
    for (name, var) in vars.iter() {
        let Some(t) = tensors.get(name) else { return Err(CheckpointError::Invalid(format!("model.safetensors: parameter {name} is missing"))) };
        if t.dims() != var.dims() {
            return Err(CheckpointError::Invalid(format!("model.safetensors: parameter {name} is {:?}, the config needs {:?}", t.dims(), var.dims())));
        }
        var.set(t).map_err(CheckpointError::tensor(format!("model.safetensors: parameter {name}")))?;
    }
    Ok(())
}

/// A model for sampling only: its parameters are plain tensors, not training variables.
///
/// Why: candle records every op whose inputs include a variable, so a forward pass through a
/// trainable model keeps all its activations alive for a backward pass that sampling never
/// runs: 240 MB per 120-frame sample of a 38-joint creature, growing with every layer.
pub struct FrozenDenoiser {
    pub info: CheckpointInfo,
    pub model: Denoiser,
}

/// `FrozenDenoiser` from the bytes of `checkpoint.json` and `model.safetensors`.
pub fn frozen_bytes(info_json: &[u8], weights: &[u8], device: &Device) -> Result<FrozenDenoiser, CheckpointError> {
    let info = parse_info(info_json)?;
    let tensors =
        candle_core::safetensors::load_buffer(weights, device).map_err(CheckpointError::tensor("model.safetensors: not a safetensors file".into()))?;
    let vb = candle_nn::VarBuilder::from_tensors(tensors, candle_core::DType::F32, device);
    let model = Denoiser::new(vb, &info.config).map_err(CheckpointError::Mismatch)?;
    Ok(FrozenDenoiser { info, model })
}

/// `FrozenDenoiser` from a model directory written by mo-train.
pub fn frozen(dir: &Path, device: &Device) -> Result<FrozenDenoiser, CheckpointError> {
    let (info, weights) = read_dir_files(dir)?;
    frozen_bytes(&info, &weights, device).map_err(CheckpointError::of(format!("model {}", dir.display())))
}

/// The default model that ships inside the binaries: a `compact` denoiser trained on the
/// synthetic zoo (models/zoo-compact, see its MODEL_CARD.md).
pub fn frozen_default(device: &Device) -> Result<FrozenDenoiser, CheckpointError> {
    frozen_bytes(BUILTIN_INFO, BUILTIN_WEIGHTS, device).map_err(CheckpointError::of(BUILTIN_NAME.into()))
}

/// `--model DIR`'s model, or the built-in one.
pub fn frozen_or_default(dir: Option<&Path>, device: &Device) -> Result<FrozenDenoiser, CheckpointError> {
    match dir {
        Some(dir) => frozen(dir, device),
        None => frozen_default(device),
    }
}

/// The built-in model's `checkpoint.json` and `model.safetensors`, embedded in the binaries.
pub const BUILTIN_INFO: &[u8] = include_bytes!("../../models/zoo-compact/checkpoint.json");
pub const BUILTIN_WEIGHTS: &[u8] = include_bytes!("../../models/zoo-compact/model.safetensors");
/// How messages name the built-in model.
pub const BUILTIN_NAME: &str = "the built-in default model";

/// The built-in model as trainable variables (a fine-tune's start, `mo-train --init builtin`).
pub fn load_default(device: &Device) -> Result<LoadedDenoiser, CheckpointError> {
    load_bytes(BUILTIN_INFO, BUILTIN_WEIGHTS, device).map_err(CheckpointError::of(BUILTIN_NAME.into()))
}

/// The raw weights an averaged checkpoint keeps beside its optimiser state (`w.<name>`), by
/// parameter name; empty for a checkpoint written without an average.
pub fn load_raw_weights(dir: &Path, device: &Device) -> Result<std::collections::HashMap<String, candle_core::Tensor>, CheckpointError> {
    let path = dir.join("optimizer.safetensors");
    let tensors = candle_core::safetensors::load(&path, device).map_err(CheckpointError::tensor(format!("cannot load {}", path.display())))?;
    Ok(tensors.into_iter().filter_map(|(k, t)| k.strip_prefix(RAW_PREFIX).map(|n| (n.to_string(), t))).collect())
}

/// The optimiser state saved beside a checkpoint.
pub fn load_optimizer(dir: &Path, step: u64, device: &Device, lr: f64) -> Result<AdamW, CheckpointError> {
    let path = dir.join("optimizer.safetensors");
    let tensors = candle_core::safetensors::load(&path, device).map_err(CheckpointError::tensor(format!("cannot load {}", path.display())))?;
    let mut opt = AdamW::new(lr);
    opt.load_state(&tensors, step).map_err(CheckpointError::tensor(format!("cannot load {}", path.display())))?;
    Ok(opt)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repr::anytop::{RestSource, RigOptions};

    #[test]
    fn the_trained_record_is_rebuilt_exactly_for_the_same_proportions_only() {
        let (skeleton, motion) = crate::synth::creature("quadruped", 0).unwrap();
        let later = motion.frame_range(10, motion.frames);
        let built = |m: &Motion| {
            let options = RigOptions { rest_source: RestSource::FirstClip { file: "idle.bvh".into() }, ..RigOptions::default() };
            AnyTopSection::new(&skeleton, &m.first_frames(2), &options).unwrap()
        };
        let trained = TrainedSkeleton {
            name: "q".into(),
            joints: skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            parents: skeleton.parents(),
            stats: AnyTopStats { mean: vec![0.0; skeleton.len() * 13], std: vec![1.0; skeleton.len() * 13] },
            clips: 1,
            offsets: skeleton.joints.iter().map(|j| j.offset.to_array()).collect(),
            rest: Some(TrainedRest::new("zoo/q/idle.bvh", &motion)),
        };
        // Through JSON, as a checkpoint keeps it.
        let list: Vec<TrainedSkeleton> = serde_json::from_str(&serde_json::to_string(&[trained.clone()]).unwrap()).unwrap();
        let (file, record) = trained_record(&list, &skeleton).unwrap();
        let record = record.unwrap();
        assert_eq!(file, "idle.bvh");
        assert_eq!(record.rest_row, built(&motion).rest_row);
        assert_ne!(record.rest_row, built(&later).rest_row, "the frames chosen make no difference here");
        assert_eq!(serde_json::to_string(&record.rig).unwrap(), serde_json::to_string(&built(&motion).rig).unwrap());
        // Other proportions, or no recorded frames: no trained record.
        let mut longer = skeleton.clone();
        longer.joints.iter_mut().for_each(|j| j.offset *= 1.1);
        assert!(trained_record(&list, &longer).is_none());
        assert!(trained_record(&[TrainedSkeleton { rest: None, ..trained }], &skeleton).is_none());
    }

    #[test]
    fn find_trained_prefers_the_nearest_proportions() {
        let (skeleton, _) = crate::synth::creature("quadruped", 0).unwrap();
        let trained = |name: &str, scale: f64| TrainedSkeleton {
            name: name.into(),
            joints: skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            parents: skeleton.parents(),
            stats: AnyTopStats { mean: vec![0.0; skeleton.len() * 13], std: vec![1.0; skeleton.len() * 13] },
            clips: 1,
            offsets: skeleton.joints.iter().map(|j| (j.offset * scale).to_array()).collect(),
            rest: None,
        };
        let list = [trained("long", 1.3), trained("plain", 1.0), trained("short", 0.8)];
        assert_eq!(find_trained(&list, &skeleton).map(|t| t.name.as_str()), Some("plain"));
        let mut longer = skeleton.clone();
        longer.joints.iter_mut().for_each(|j| j.offset *= 1.25);
        assert_eq!(find_trained(&list, &longer).map(|t| t.name.as_str()), Some("long"));
        // Older checkpoints record no offsets: names and parents decide.
        let old = [TrainedSkeleton { offsets: Vec::new(), ..trained("old", 1.0) }];
        assert_eq!(find_trained(&old, &longer).map(|t| t.name.as_str()), Some("old"));
        let (crab, _) = crate::synth::creature("crab", 0).unwrap();
        assert!(find_trained(&list, &crab).is_none());
    }
}
