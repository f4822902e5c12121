//! Neural networks on candle (CPU): AnyTop's denoiser and what it is built from.
//!
//! * [`config`]: `DenoiserConfig` with the `paper`, `small` and `tiny` presets;
//! * [`layers`]: linear, layer norm, softmax and attention from basic differentiable ops
//!   (candle-nn's fused CPU kernels pass no gradients);
//! * [`init`]: a `VarBuilder` that initialises new parameters from our seeded SplitMix64
//!   (candle's CPU RNG cannot be seeded), so the same seed gives the same model bytes;
//! * [`batch`]: `Batch`, the tensors one forward pass needs, and `batch_from` which pads clips
//!   of different skeletons and lengths into one batch;
//! * [`anytop`]: the `Denoiser` (anytop.md §2, paper §3.2).

pub mod anytop;
pub mod batch;
pub mod config;
pub mod init;
pub mod layers;

#[cfg(test)]
mod tests;

pub use anytop::Denoiser;
pub use batch::{batch_from, Batch, BatchItem};
pub use config::DenoiserConfig;
pub use init::seeded_var_builder;

#[derive(Debug, thiserror::Error)]
pub enum NnError {
    #[error("denoiser config: {field}: {problem}")]
    Config { field: &'static str, problem: String },
    #[error("batch item {item}: {what}: expected {expected}, got {got}")]
    BatchItem { item: usize, what: &'static str, expected: String, got: String },
    #[error("batch: {what}: expected {expected}, got {got:?}")]
    Shape { what: &'static str, expected: String, got: Vec<usize> },
    #[error("activations of layer {requested} requested, the model has {layers} layers")]
    Layer { requested: usize, layers: usize },
    #[error("candle: {0}")]
    Candle(#[from] candle_core::Error),
}
