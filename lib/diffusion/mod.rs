//! Diffusion for any skeleton (AnyTop §3): the noise schedule and sampler coefficients.
//! The model itself is in `nn`; training and sampling loops build on both.

pub mod checkpoint;
pub mod condition;
pub mod data;
pub mod edit;
pub mod ema;
pub mod keep;
pub mod progress;
pub mod rest_norm;
pub mod sample;
pub mod schedule;
pub mod start;
pub mod train;
pub mod trainer;
pub mod unseen;

pub use schedule::{Sampler, Schedule, Step};

/// What can go wrong conditioning, sampling or editing with the denoiser (its files:
/// `checkpoint::CheckpointError`; training: `trainer::TrainError`).
#[derive(Debug, thiserror::Error)]
pub enum DiffusionError {
    #[error(transparent)]
    Nn(#[from] crate::nn::NnError),
    #[error(transparent)]
    Tensor(#[from] candle_core::Error),
    #[error(transparent)]
    Edit(#[from] edit::EditError),
    /// Normalising or denormalising with a skeleton's statistics; `what` says which.
    #[error("{what}")]
    Stats { what: &'static str, source: crate::repr::anytop::AnyTopError },
    #[error("the built-in joint-name table")]
    Names(#[source] crate::embed::EmbedError),
    #[error("{0}")]
    Invalid(String),
}
