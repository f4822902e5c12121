//! stub
use super::training::{Clip, Job};
use super::*;
pub(super) fn bird(job: &Job, rng: &mut SplitMix64) -> Clip { super::legged_actions::quadruped(job, rng) }
pub(super) fn snake(job: &Job, rng: &mut SplitMix64) -> Clip { super::legged_actions::quadruped(job, rng) }
pub(super) fn fish(job: &Job, rng: &mut SplitMix64) -> Clip { super::legged_actions::quadruped(job, rng) }
