//! The correspondence engine's side of the tools: `mo-retarget --bind auto` and `mo-dift
//! --joints` (with or without `--as-binding`) both call `bind_auto` / `joint_scores`, so the
//! two tools give the same answer for the same pair of skeletons.

use crate::binding::auto::{self, AutoOptions, Body, Choice};
use crate::correspond::{self, Evidence, Scores};
use crate::document::AnyTopSection;
use crate::motion::Motion;
use crate::repr::anytop::RigOptions;
use crate::skeleton::Skeleton;
use anyhow::Context;
use glam::DVec3;

/// The AnyTop rig's natural rest pose: faces +z, so two creatures compare in one frame.
pub fn facing_rest(skeleton: &Skeleton, motion: &Motion, name: &str) -> anyhow::Result<Vec<DVec3>> {
    let section = AnyTopSection::new(skeleton, &motion.first_frames(2), &RigOptions::default())
        .with_context(|| format!("{name}: cannot find its rest pose and facing"))?;
    Ok(section.rig.rest_positions(skeleton))
}

/// One skeleton with the motion it came with, as the engine needs it.
pub struct Side<'a> {
    pub name: &'a str,
    pub skeleton: &'a Skeleton,
    pub motion: &'a Motion,
}

/// Every pair's score (all evidence), source joints in rows.
pub fn joint_scores(source: &Side, target: &Side) -> anyhow::Result<Scores> {
    let (ra, rb) = (facing_rest(source.skeleton, source.motion, source.name)?, facing_rest(target.skeleton, target.motion, target.name)?);
    Ok(correspond::scores(&Body { skeleton: source.skeleton, rest: &ra }, &Body { skeleton: target.skeleton, rest: &rb }, Evidence::ALL, None)?)
}

/// The automatic binding of `source` to `target`, at most `rate` (`None`: every confident pair).
pub fn bind_auto(source: &Side, target: &Side, rate: Option<f64>) -> anyhow::Result<Vec<Choice>> {
    let scores = joint_scores(source, target)?;
    Ok(auto::choose(&scores, source.skeleton, target.skeleton, &AutoOptions { rate, ..AutoOptions::default() })?)
}
