//! stub
use super::training::{Clip, Job};
use super::*;
pub(super) fn spider(job: &Job, rng: &mut SplitMix64) -> Clip { super::legged_actions::quadruped(job, rng) }
pub(super) fn crab(job: &Job, rng: &mut SplitMix64) -> Clip { super::legged_actions::quadruped(job, rng) }
pub(super) fn centipede(job: &Job, rng: &mut SplitMix64) -> Clip { super::legged_actions::quadruped(job, rng) }
