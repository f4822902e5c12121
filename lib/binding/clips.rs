//! The automatic binding and the joint scores of two clips, each measured on its rig's natural
//! rest pose (facing +z), so that two creatures compare in one frame.
//!
//! `mo-retarget --bind auto` and `mo-dift --joints` both start from clips as read from files;
//! doing it here once means the two tools give the same answer for the same pair.

use super::auto::{self, AutoError, AutoOptions, Body, Choice};
use crate::correspond::{self, CorrespondError, Evidence, Scores};
use crate::document::AnyTopSection;
use crate::motion::Clip;
use crate::repr::anytop::{AnyTopError, RigOptions};
use glam::DVec3;

/// Why two clips could not be compared.
#[derive(Debug, thiserror::Error)]
pub enum ClipBindError {
    #[error("{name}: cannot find its rest pose and facing")]
    Rest {
        name: String,
        #[source]
        source: AnyTopError,
    },
    #[error(transparent)]
    Correspond(#[from] CorrespondError),
    #[error(transparent)]
    Auto(#[from] AutoError),
    #[error(transparent)]
    Binding(#[from] super::BindingError),
}

/// The AnyTop rig's natural rest pose of a clip's skeleton: faces +z.
pub fn facing_rest(clip: &Clip) -> Result<Vec<DVec3>, ClipBindError> {
    let section = AnyTopSection::new(&clip.skeleton, &clip.motion.first_frames(2), &RigOptions::default())
        .map_err(|source| ClipBindError::Rest { name: clip.name.clone(), source })?;
    Ok(section.rig.rest_positions(&clip.skeleton))
}

/// The binding `mo-retarget --bind` names: `auto` (`bind_auto`, at most `rate`) or a binding
/// file; as joint pairs, and as the document `--emit-binding` writes.
pub fn binding_for(bind: &str, source: &Clip, target: &Clip, rate: Option<f64>) -> Result<(super::JointMap, super::Binding), ClipBindError> {
    if bind != "auto" {
        return Ok(super::Binding::read_resolved(std::path::Path::new(bind), source, target)?);
    }
    let choices = bind_auto(source, target, rate)?;
    let binding = auto::to_binding(&choices, &source.skeleton, &source.name, &target.skeleton, &target.name);
    Ok((choices.iter().map(|c| (c.source, c.target)).collect(), binding))
}

/// Every pair's score (all evidence), source joints in rows.
pub fn joint_scores(source: &Clip, target: &Clip) -> Result<Scores, ClipBindError> {
    let (ra, rb) = (facing_rest(source)?, facing_rest(target)?);
    Ok(correspond::scores(&Body { skeleton: &source.skeleton, rest: &ra }, &Body { skeleton: &target.skeleton, rest: &rb }, Evidence::ALL, None)?)
}

/// The automatic binding of `source` to `target`, at most `rate` (`None`: every confident pair).
pub fn bind_auto(source: &Clip, target: &Clip, rate: Option<f64>) -> Result<Vec<Choice>, ClipBindError> {
    let scores = joint_scores(source, target)?;
    Ok(auto::choose(&scores, &source.skeleton, &target.skeleton, &AutoOptions { rate, ..AutoOptions::default() })?)
}
