//! A model's second denoiser, for the skeletons it was not trained on (`DIR/unseen/`).
//!
//! Why two: a denoiser trained on each skeleton's own statistics (upstream's way) moves its
//! trained skeletons like their clips but stands every other skeleton still under the fallback
//! statistics (the rest pose as the mean), which it never trained on; one trained under the
//! fallback (`mo-train --fallback-stats all`) moves skeletons it never saw but damps the ones it
//! trained on. Measured on the built-in pair (models/zoo-compact/MODEL_CARD.md, energy ratio to
//! the clips): the held-out dragon 0.42 against 0.90, the LAFAN1 walk 0.34 against 1.33; the
//! bundled spider 0.91 against 0.33. No single recipe measured so far does both, so a model
//! directory may hold, in `unseen/`, a model trained under the fallback, and sampling takes it
//! for every skeleton the main model has no statistics of. Everything else (DIFT features,
//! which measure their statistics on the caller's motion; fine-tuning; the out-of-distribution
//! score) uses the main model.

use super::checkpoint::{self, CheckpointError, CheckpointInfo, FrozenDenoiser};
use super::data::FallbackStats;
use candle_core::Device;
use std::path::Path;

/// The folder inside a model directory that holds its denoiser for unseen skeletons.
pub const UNSEEN_DIR: &str = "unseen";

/// The built-in model's denoiser for unseen skeletons (models/zoo-compact/unseen).
const BUILTIN_INFO: &[u8] = include_bytes!("../../models/zoo-compact/unseen/checkpoint.json");
const BUILTIN_WEIGHTS: &[u8] = include_bytes!("../../models/zoo-compact/unseen/model.safetensors");

/// How messages name the built-in model's unseen-skeleton denoiser.
pub const BUILTIN_NAME: &str = "the built-in default model's unseen-skeleton denoiser";

/// How messages name the unseen-skeleton denoiser of the model at `dir` (the built-in's when
/// `None`).
pub fn label(dir: Option<&Path>) -> String {
    dir.map_or_else(|| BUILTIN_NAME.to_string(), |d| format!("model {}", d.join(UNSEEN_DIR).display()))
}

/// The denoiser for skeletons the model at `dir` (the built-in one when `None`) was not trained
/// on: `dir/unseen` when it exists (`None` when it does not), checked to have trained under the
/// fallback statistics it will sample with.
pub fn frozen_or_default(dir: Option<&Path>, device: &Device) -> Result<Option<FrozenDenoiser>, CheckpointError> {
    match dir {
        Some(d) => read(d)?.map(|(info, weights)| checked(&info, &weights, dir, device)).transpose(),
        None => checked(BUILTIN_INFO, BUILTIN_WEIGHTS, None, device).map(Some),
    }
}

/// The bytes of `dir/unseen`'s `checkpoint.json` and weights, when the folder exists.
fn read(dir: &Path) -> Result<Option<(Vec<u8>, Vec<u8>)>, CheckpointError> {
    let unseen = dir.join(UNSEEN_DIR);
    if !unseen.is_dir() {
        return Ok(None);
    }
    checkpoint::read_dir_files(&unseen).map(Some)
}

/// The denoiser from its files' bytes, refused (naming it, `label(dir)`) unless it can serve
/// skeletons its model was not trained on.
fn checked(info: &[u8], weights: &[u8], dir: Option<&Path>, device: &Device) -> Result<FrozenDenoiser, CheckpointError> {
    let loaded = checkpoint::frozen_bytes(info, weights, device).map_err(CheckpointError::of(label(dir)))?;
    check(&loaded.info).map_err(|why| CheckpointError::of(label(dir))(CheckpointError::Invalid(why)))?;
    Ok(loaded)
}

/// The unseen-skeleton denoiser a fine-tune takes from the model it starts from, read and
/// checked before any training, so that a denoiser sampling would refuse stops the run before it
/// writes anything. Why a fine-tune takes it: a model tuned on one creature then samples every
/// other skeleton as its starting model did, instead of with a main denoiser that never trained
/// under the fallback statistics (it stands them still).
pub struct Carried {
    info: Vec<u8>,
    weights: Vec<u8>,
}

impl Carried {
    /// The denoiser of the model at `init` (`None`: the built-in one), if it has one.
    pub fn from(init: Option<&Path>) -> Result<Option<Carried>, CheckpointError> {
        match init {
            None => Ok(Some(Carried { info: BUILTIN_INFO.to_vec(), weights: BUILTIN_WEIGHTS.to_vec() })),
            Some(dir) => {
                let Some((info, weights)) = read(dir)? else { return Ok(None) };
                // The same check sampling makes, on the bytes that will be written.
                checked(&info, &weights, init, &Device::Cpu)?;
                Ok(Some(Carried { info, weights }))
            }
        }
    }

    /// Writes it to `out/unseen` (only what sampling reads: `checkpoint.json` and the weights),
    /// through a temporary folder moved into place. Returns whether it was written; an existing
    /// `out/unseen` is left alone.
    pub fn write(&self, out: &Path) -> Result<bool, CheckpointError> {
        let target = out.join(UNSEEN_DIR);
        if target.exists() {
            return Ok(false);
        }
        let temporary = out.join(format!(".{UNSEEN_DIR}.partial"));
        let _ = std::fs::remove_dir_all(&temporary);
        std::fs::create_dir_all(&temporary).map_err(CheckpointError::io(format!("cannot create {}", temporary.display())))?;
        for (name, bytes) in [("checkpoint.json", &self.info), ("model.safetensors", &self.weights)] {
            let path = temporary.join(name);
            std::fs::write(&path, bytes).map_err(CheckpointError::io(format!("cannot write {}", path.display())))?;
        }
        std::fs::rename(&temporary, &target).map_err(CheckpointError::io(format!("cannot move {} into place", target.display())))?;
        Ok(true)
    }
}

/// Why `info` cannot serve skeletons a model was not trained on, if it cannot.
fn check(info: &CheckpointInfo) -> Result<(), String> {
    match info.fallback_stats {
        FallbackStats::All => Ok(()),
        other => {
            let name = clap::ValueEnum::to_possible_value(&other).map_or_else(String::new, |v| v.get_name().to_string());
            Err(format!("trained with --fallback-stats {name}; an unseen/ denoiser must be trained with --fallback-stats all, the statistics it samples with"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The built-in pair: the main model trained on own statistics, its unseen half under the
    /// fallback, on the same zoo (the same skeleton names), so the out-of-distribution score the
    /// main model gives holds for both.
    #[test]
    fn the_builtin_unseen_denoiser_trained_under_the_fallback_on_the_same_zoo() {
        let unseen = frozen_or_default(None, &Device::Cpu).unwrap().expect("the built-in model has an unseen/ denoiser");
        assert_eq!(unseen.info.fallback_stats, FallbackStats::All);
        let main: CheckpointInfo = serde_json::from_slice(checkpoint::BUILTIN_INFO).unwrap();
        assert_eq!(main.fallback_stats, FallbackStats::None);
        let names = |info: &CheckpointInfo| info.skeletons.iter().map(|s| s.name.clone()).collect::<std::collections::BTreeSet<_>>();
        assert_eq!(names(&unseen.info), names(&main));
    }

    #[test]
    fn a_denoiser_trained_on_own_statistics_is_refused_as_the_unseen_one() {
        let mut info: CheckpointInfo = serde_json::from_slice(checkpoint::BUILTIN_INFO).unwrap();
        let why = check(&info).unwrap_err();
        assert!(why.contains("--fallback-stats none") && why.contains("must be trained with --fallback-stats all"), "{why}");
        info.fallback_stats = FallbackStats::Variants;
        assert!(check(&info).unwrap_err().contains("--fallback-stats variants"));
        info.fallback_stats = FallbackStats::All;
        assert!(check(&info).is_ok());
    }
}
