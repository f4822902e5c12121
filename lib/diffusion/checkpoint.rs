//! Denoiser checkpoints: a directory with `model.safetensors` (readable parameter names),
//! `optimizer.safetensors` (AdamW moments), and `checkpoint.json` (config, step, seed, the
//! training settings, and per-skeleton normalisation statistics so that sampling a trained
//! skeleton uses its own). Files are written beside their final names and renamed, so an
//! interrupted save leaves the previous checkpoint whole.

use super::train::AdamW;
use crate::nn::{seeded_var_builder, Denoiser, DenoiserConfig};
use crate::repr::anytop::AnyTopStats;
use crate::skeleton::Skeleton;
use anyhow::{bail, Context};
use candle_core::Device;
use candle_nn::VarMap;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const FORMAT: &str = "menagerie.denoiser";
pub const VERSION: u32 = 1;

/// One trained skeleton: how to recognise it and its statistics.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TrainedSkeleton {
    pub name: String,
    pub joints: Vec<String>,
    pub parents: Vec<Option<usize>>,
    pub stats: AnyTopStats,
    pub clips: usize,
}

impl TrainedSkeleton {
    pub fn matches(&self, s: &Skeleton) -> bool {
        self.joints.len() == s.len() && s.joints.iter().zip(&self.joints).zip(&self.parents).all(|((j, n), p)| &j.name == n && &j.parent == p)
    }
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
    pub skeletons: Vec<TrainedSkeleton>,
}

fn write_then_rename(dir: &Path, name: &str, write: impl FnOnce(&Path) -> anyhow::Result<()>) -> anyhow::Result<()> {
    let tmp = dir.join(format!(".{name}.tmp"));
    write(&tmp)?;
    std::fs::rename(&tmp, dir.join(name)).with_context(|| format!("cannot move {} into place", tmp.display()))
}

/// Save model, optimiser and info to `dir` (created if needed).
pub fn save(dir: &Path, info: &CheckpointInfo, varmap: &VarMap, opt: &AdamW) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_then_rename(dir, "model.safetensors", |p| varmap.save(p).with_context(|| format!("cannot write {}", p.display())))?;
    let state: std::collections::HashMap<String, candle_core::Tensor> = opt.state().into_iter().collect();
    write_then_rename(dir, "optimizer.safetensors", |p| candle_core::safetensors::save(&state, p).with_context(|| format!("cannot write {}", p.display())))?;
    // The info goes last: a checkpoint.json always describes complete tensor files.
    let text = serde_json::to_string_pretty(info).context("serialising the checkpoint info")?;
    write_then_rename(dir, "checkpoint.json", |p| std::fs::write(p, text + "\n").with_context(|| format!("cannot write {}", p.display())))
}

/// A loaded checkpoint.
pub struct Loaded {
    pub info: CheckpointInfo,
    pub varmap: VarMap,
    pub model: Denoiser,
}

/// Load `dir`'s info and model (the optimiser separately, with `load_optimizer`).
pub fn load(dir: &Path, device: &Device) -> anyhow::Result<Loaded> {
    let path = dir.join("checkpoint.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {} (is {} a model directory from mo-train?)", path.display(), dir.display()))?;
    let info: CheckpointInfo = serde_json::from_str(&text).with_context(|| format!("{}: not a checkpoint description", path.display()))?;
    if info.format != FORMAT || info.version != VERSION {
        bail!("{}: format {} version {}, expected {FORMAT} version {VERSION}", path.display(), info.format, info.version);
    }
    let varmap = VarMap::new();
    // Build every parameter (the seed does not matter: all are overwritten), then load.
    let model = Denoiser::new(seeded_var_builder(&varmap, 0, device), &info.config)?;
    let mut varmap = varmap;
    let weights = dir.join("model.safetensors");
    varmap.load(&weights).with_context(|| format!("cannot load {}", weights.display()))?;
    Ok(Loaded { info, varmap, model })
}

/// The optimiser state saved beside a checkpoint.
pub fn load_optimizer(dir: &Path, info: &CheckpointInfo, device: &Device, lr: f64) -> anyhow::Result<AdamW> {
    let path = dir.join("optimizer.safetensors");
    let tensors = candle_core::safetensors::load(&path, device).with_context(|| format!("cannot load {}", path.display()))?;
    let mut opt = AdamW::new(lr);
    opt.load_state(&tensors, info.step);
    Ok(opt)
}
