//! SATA model directories, the same layout as the denoiser's (`diffusion::checkpoint`):
//! `model.safetensors`, `optimizer.safetensors`, `checkpoint.json` (format `menagerie.sata`),
//! written atomically, resumable.

use super::rigs::KnownRigs;
use super::train::{FeatureScale, LossWeights};
use super::{SataConfig, SataModel};
use crate::diffusion::checkpoint::{fill_vars, read_dir_files, CheckpointError};
use crate::nn::seeded_var_builder;
use candle_core::Device;
use candle_nn::VarMap;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const FORMAT: &str = "menagerie.sata";
/// 2: features are offsets from the rest pose (`train::FeatureScale`); 1 scaled raw features.
pub const VERSION: u32 = 2;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SataInfo {
    pub format: String,
    pub version: u32,
    pub config: SataConfig,
    pub scale: FeatureScale,
    pub weights: LossWeights,
    pub step: u64,
    pub seed: u64,
    pub lr: f64,
    pub batch: usize,
    pub augment: f64,
    pub augment_variants: usize,
    /// Names of the trained skeletons (for the model card and `--verbose`).
    pub skeletons: Vec<String>,
}

/// `checkpoint.json`, checked to be a SATA checkpoint of this version. A denoiser directory
/// gets a message that says so.
pub fn parse_info(json: &[u8]) -> Result<SataInfo, CheckpointError> {
    let value: serde_json::Value = serde_json::from_slice(json).map_err(CheckpointError::json("checkpoint.json: not JSON".into()))?;
    let format = value.get("format").and_then(|f| f.as_str()).unwrap_or("");
    if format != FORMAT {
        return Err(CheckpointError::Invalid(format!("checkpoint.json: format '{format}', expected '{FORMAT}' (a latent model from `mo-train --arch sata`)")));
    }
    let info: SataInfo = serde_json::from_value(value).map_err(CheckpointError::json("checkpoint.json: not a SATA checkpoint description".into()))?;
    if info.version != VERSION {
        return Err(CheckpointError::Invalid(format!("checkpoint.json: version {}, expected {VERSION}", info.version)));
    }
    info.config.validate()?;
    info.scale.check().map_err(|e| CheckpointError::Invalid(format!("checkpoint.json: {e}")))?;
    Ok(info)
}

/// A checkpoint with trainable variables (for resuming).
pub struct LoadedAutoencoder {
    pub info: SataInfo,
    pub varmap: VarMap,
    pub model: SataModel,
}

pub fn load(dir: &Path, device: &Device) -> Result<LoadedAutoencoder, CheckpointError> {
    let (json, weights) = read_dir_files(dir)?;
    let info = parse_info(&json).map_err(CheckpointError::of(format!("model {}", dir.display())))?;
    let varmap = VarMap::new();
    let model = SataModel::new(seeded_var_builder(&varmap, 0, device), &info.config)?;
    fill_vars(&varmap, &weights, device).map_err(CheckpointError::of(format!("model {}", dir.display())))?;
    Ok(LoadedAutoencoder { info, varmap, model })
}

/// A model for inference only: plain tensors, so no op is recorded for a backward pass.
pub struct FrozenAutoencoder {
    pub info: SataInfo,
    pub model: SataModel,
    /// The rigs of the skeletons it was trained on (empty for models from before `rigs.json`).
    pub rigs: KnownRigs,
}

/// `rigs`: the contents of `rigs.json`, if the model has one.
pub fn frozen_bytes(json: &[u8], weights: &[u8], rigs: Option<&[u8]>, device: &Device) -> Result<FrozenAutoencoder, CheckpointError> {
    let info = parse_info(json)?;
    let tensors =
        candle_core::safetensors::load_buffer(weights, device).map_err(CheckpointError::tensor("model.safetensors: not a safetensors file".into()))?;
    let vb = candle_nn::VarBuilder::from_tensors(tensors, candle_core::DType::F32, device);
    let model = SataModel::new(vb, &info.config).map_err(CheckpointError::Mismatch)?;
    let rigs = rigs.map(KnownRigs::parse).transpose()?.unwrap_or_default();
    Ok(FrozenAutoencoder { info, model, rigs })
}

pub fn frozen(dir: &Path, device: &Device) -> Result<FrozenAutoencoder, CheckpointError> {
    let (json, weights) = read_dir_files(dir)?;
    let mut model = frozen_bytes(&json, &weights, None, device).map_err(CheckpointError::of(format!("model {}", dir.display())))?;
    model.rigs = KnownRigs::read(dir)?;
    Ok(model)
}

/// The latent model that ships inside the binaries (models/zoo-sata, see its MODEL_CARD.md).
pub fn frozen_default(device: &Device) -> Result<FrozenAutoencoder, CheckpointError> {
    const INFO: &[u8] = include_bytes!("../../models/zoo-sata/checkpoint.json");
    const WEIGHTS: &[u8] = include_bytes!("../../models/zoo-sata/model.safetensors");
    const RIGS: &[u8] = include_bytes!("../../models/zoo-sata/rigs.json");
    frozen_bytes(INFO, WEIGHTS, Some(RIGS), device).map_err(CheckpointError::of("the built-in latent model".into()))
}
