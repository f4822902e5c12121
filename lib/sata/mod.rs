//! SATA: a topology-agnostic motion autoencoder (ICML 2026 paper, docs/reference/README.md; no
//! public code).
//!
//! A clip of any skeleton is encoded into one latent vector per frame, and a latent sequence is
//! decoded onto any skeleton given only its rest pose, topology and joint names: zero-shot
//! retargeting without paired data or a hand-made binding.
//!
//! * [`graph`]: the static side of a skeleton (§3.1): per joint its rest offset w.r.t. the root
//!   and the parent, its name embedding; per bone the depth and reverse depth of the child.
//! * [`model`]: semantic-spatial modulation (§3.2), spatio-temporal interleaved blocks (graph
//!   message passing + spatial transformer, then per-joint temporal attention, §3.3), a
//!   symmetric encoder/decoder with a spatial max-pool and a VAE bottleneck.
//! * [`train`]: the losses of §3.4 and one training step on skeleton-bucketed batches.
//! * [`checkpoint`]: model directories (`mo-train --arch sata`) and the built-in model.
//! * [`infer`]: whole clips through 64-frame windows with 16-frame overlaps (appendix B).
//!
//! Dynamic features: where SATA stacks (6D rotation, parent-relative position, rotational and
//! linear velocity, root motion, contact), we feed AnyTop's 13 per-joint features
//! (`repr::anytop`: root-relative position, 6D rotation in the natural rest frame, linear
//! velocity, contact; the root token carries height, facing and root displacement) plus the
//! frame-to-frame change of the 6D rotation. They carry the same information, are exactly
//! invertible, and their rotations mean the same thing on every skeleton (identity is the
//! natural rest pose, positions are in body-size units), which is what lets one decoder put a
//! dog's latent on a human. Instead of per-skeleton normalisation (which would need statistics
//! of the target before decoding), one global scale per feature group is learned from the
//! training set and kept in the checkpoint ([`train::FeatureScale`]).

pub mod checkpoint;
pub mod clips;
pub mod graph;
pub mod infer;
pub mod model;
pub mod rigs;
pub mod train;
pub mod trainer;

pub use graph::SkeletonGraph;
pub use model::SataModel;

use crate::nn::NnError;
use crate::repr::anytop::AnyTopError;
use serde::{Deserialize, Serialize};

/// Hyper-parameters of the autoencoder; checkpoints carry it as JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SataConfig {
    /// Hidden width of every joint token (the paper's 256).
    pub width: usize,
    /// Spatio-temporal blocks in the encoder, and again in the decoder (the paper's 3).
    pub blocks: usize,
    /// Attention heads (spatial and temporal); must divide `width`.
    pub heads: usize,
    /// Inner width of the feed-forward layers (the paper's 512).
    pub ff: usize,
    /// Size of the per-frame latent (the paper's VAE: 128).
    pub latent: usize,
    /// Frequencies per coordinate of the sinusoidal spatial encoder.
    pub frequencies: usize,
    /// Joint-name embedding size (384: all-MiniLM-L6-v2, `embed`).
    pub name_dim: usize,
    /// Frames per window, in training crops and at inference (the paper's 64).
    pub window: usize,
    /// Frames shared by consecutive inference windows (the paper's 16).
    pub overlap: usize,
    pub ln_eps: f64,
    /// The latent is the encoder's output minus its output for the same skeleton standing
    /// still in its rest pose ([`model::SataModel::encode`]): what the body does, not which
    /// body it is. False in checkpoints written before it (their latents are absolute).
    #[serde(default)]
    pub relative_latent: bool,
    /// A direct linear read-out of the latent at every joint, its matrix made from the joint's
    /// condition (rest offsets and name; [`model::SataModel::decode`]). False in checkpoints
    /// written before it.
    #[serde(default)]
    pub direct_readout: bool,
}

/// AnyTop's 13 features per joint and frame.
/// What can go wrong training or running the latent model (its files: `checkpoint`'s
/// `CheckpointError`).
#[derive(Debug, thiserror::Error)]
pub enum SataError {
    #[error(transparent)]
    Nn(#[from] NnError),
    #[error(transparent)]
    Tensor(#[from] candle_core::Error),
    #[error(transparent)]
    Repr(#[from] AnyTopError),
    /// Input of the wrong shape or values.
    #[error("{0}")]
    Invalid(String),
}

pub const FEATURE_DIMS: usize = 13;
/// The model's motion input per joint: the 13 features and the change of the 6D rotation.
pub const INPUT_DIMS: usize = FEATURE_DIMS + 6;

impl SataConfig {
    /// This config with inference windows (and training crops) of `window` frames; the overlap
    /// shrinks, if needed, to under half a window, so windows still advance.
    pub fn with_window(mut self, window: usize) -> SataConfig {
        self.window = window;
        self.overlap = self.overlap.min(window.saturating_sub(1) / 2);
        self
    }

    /// The autoencoder of a preset size.
    pub fn preset(preset: crate::nn::Preset) -> SataConfig {
        match preset {
            crate::nn::Preset::Tiny => SataConfig::tiny(),
            // The latent model's small is already this size (width 64, 2 blocks).
            crate::nn::Preset::Compact | crate::nn::Preset::Small => SataConfig::small(),
            crate::nn::Preset::Paper => SataConfig::paper(),
        }
    }

    /// The paper's base model (§4.1.1): width 256, 3 + 3 blocks, 4 heads, ff 512, latent 128,
    /// windows of 64 frames overlapping by 16.
    pub fn paper() -> SataConfig {
        SataConfig {
            width: 256,
            blocks: 3,
            heads: 4,
            ff: 512,
            latent: 128,
            frequencies: 6,
            name_dim: 384,
            window: 64,
            overlap: 16,
            ln_eps: 1e-5,
            relative_latent: true,
            direct_readout: true,
        }
    }

    /// What trains on our CPUs in an hour or two: width 64, 2 + 2 blocks, 32-frame windows
    /// overlapping by 8 (the paper's appendix B measures 32/8 too).
    pub fn small() -> SataConfig {
        SataConfig { width: 64, blocks: 2, heads: 4, ff: 128, latent: 64, window: 32, overlap: 8, ..SataConfig::paper() }
    }

    /// For tests: one block each way, width 32.
    pub fn tiny() -> SataConfig {
        SataConfig { width: 32, blocks: 1, heads: 2, ff: 64, latent: 16, frequencies: 4, window: 16, overlap: 4, ..SataConfig::paper() }
    }

    pub fn validate(&self) -> Result<(), NnError> {
        let bad = |field: &'static str, problem: String| Err(NnError::Config { field, problem });
        if self.width < 2 || self.blocks == 0 || self.ff == 0 || self.latent == 0 || self.frequencies == 0 || self.name_dim == 0 {
            return bad("width/blocks/ff/latent/frequencies/name_dim", format!("all must be > 0 (width >= 2), got {self:?}"));
        }
        if self.heads == 0 || !self.width.is_multiple_of(self.heads) {
            return bad("heads", format!("must divide width {}, got {}", self.width, self.heads));
        }
        if self.window < 2 || self.overlap * 2 >= self.window {
            return bad("window/overlap", format!("need window >= 2 and overlap < window / 2, got {} / {}", self.window, self.overlap));
        }
        if !(self.ln_eps > 0.0 && self.ln_eps.is_finite()) {
            return bad("ln_eps", format!("must be positive and finite, got {}", self.ln_eps));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
