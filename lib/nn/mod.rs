//! Neural networks on candle (CPU): AnyTop's denoiser and what it is built from.
//!
//! * [`config`]: `DenoiserConfig` with the `paper`, `small` and `tiny` presets;
//! * [`layers`]: linear, layer norm, feed-forward and embeddings; [`fused`]: attention and layer
//!   norm kernels with their own backward, [`gelu`] likewise
//!   (candle-nn's fused CPU kernels pass no gradients);
//! * [`init`]: a `VarBuilder` that initialises new parameters from our seeded SplitMix64
//!   (candle's CPU RNG cannot be seeded), so the same seed gives the same model bytes;
//! * [`batch`]: `Batch`, the tensors one forward pass needs, and `batch_from` which pads clips
//!   of different skeletons and lengths into one batch;
//! * [`anytop`]: the `Denoiser` (docs/reference/anytop.md §2, paper §3.2).

pub mod anytop;
pub mod batch;
pub mod config;
pub mod fused;
pub mod gelu;
pub mod init;
pub mod layers;

#[cfg(test)]
mod tests;

pub use anytop::Denoiser;
pub use batch::{batch_from, Batch, BatchItem};
pub use config::{DenoiserConfig, Preset};
pub use init::seeded_var_builder;

/// Tells glibc's allocator to keep freed memory instead of returning it to the OS.
///
/// Every candle op allocates its output; in a training or sampling loop the same large sizes
/// are freed and allocated again each step. glibc serves blocks above its mmap threshold with
/// fresh mappings (page faults and kernel zeroing on every touch) and trims the heap top after
/// frees; measured here that was a sixth of the time of a training step (perf: page faults,
/// `clear_page`, memset). Raising both thresholds keeps the pages mapped and reused.
/// Call once, early, from a binary that runs the model; elsewhere it is a no-op.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes allocator tuning parameters; it is called before the
    // model allocates anything and has no memory-safety preconditions.
    unsafe {
        // 32 MiB is glibc's largest allowed mmap threshold on 64-bit (larger values are refused).
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        libc::mallopt(libc::M_TOP_PAD, 256 << 20);
    }
}

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
