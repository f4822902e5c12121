//! Diffusion for any skeleton (AnyTop §3): the noise schedule and sampler coefficients.
//! The model itself is in `nn`; training and sampling loops build on both.

pub mod checkpoint;
pub mod condition;
pub mod data;
pub mod edit;
pub mod sample;
pub mod schedule;
pub mod train;
pub mod trainer;

pub use schedule::{Sampler, Schedule, Step};
