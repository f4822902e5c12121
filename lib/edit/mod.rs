//! The everyday edits of a motion, one small file per family, behind `mo-edit`.
//!
//! Animators fix clips before they use them: the frame rate is wrong, the axes are Blender's,
//! the clip is too long, the feet slide. Each edit here takes a skeleton and its motion and
//! gives back a new pair (or an [`EditError`] saying what was expected), never a panic:
//!
//! * [`time`]: resample, trim, concatenate with aligned roots and blended seams, loop;
//! * [`space`]: axis conventions, scale and units, left/right mirror;
//! * [`root`]: remove the root's travel, or replace it with another clip's;
//! * [`rest`]: a new rest pose (OFFSETs) from a frame, the world motion unchanged;
//! * [`rename`]: joint names from a map, or normalised;
//! * [`foot_lock`]: pin feet during the contacts `metrics::physics` finds, by two-bone IK.
//!
//! Vertical is y and the heading is the turn about y, the BVH convention every other room
//! uses; z-up data is turned first (`space::axis`). An edit may leave a rotation or a
//! translation that a joint's BVH channels cannot hold (a joint with one rotation channel
//! after a new rest pose); [`fit_channels`] gives such joints the channels they need, so the
//! written file reproduces the edited motion.

pub mod foot_lock;
pub mod rename;
pub mod rest;
pub mod root;
pub mod space;
pub mod time;

use crate::bvh::Channel;
use crate::motion::{rotation, Motion};
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};

/// Why an edit cannot be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EditError {
    /// A frame or time range outside the clip, or an empty one.
    #[error("{0}")]
    Range(String),
    /// Clips or files that do not fit together (skeletons, frame rates, lengths).
    #[error("{0}")]
    Mismatch(String),
    /// The skeleton lacks what the edit needs (sides to mirror, feet to lock).
    #[error("{0}")]
    Skeleton(String),
    /// A value out of its domain (a zero scale, an axis given twice, a name map line).
    #[error("{0}")]
    Invalid(String),
}

/// How far apart two rotations or translations may be and still count as reproduced.
const CHANNEL_TOLERANCE: f64 = 1e-9;

/// Give every joint the channels its motion needs: rotation channels (all three, keeping the
/// existing ones first) where a rotation is not the identity or not about the joint's own
/// axes, position channels where a translation is not the OFFSET. Joints that already hold
/// their motion keep their channels exactly.
pub fn fit_channels(skeleton: &mut Skeleton, motion: &Motion) {
    let n = skeleton.len().min(motion.joints);
    for j in 0..n {
        let joint = &mut skeleton.joints[j];
        let axes = rotation::rotation_axes(&joint.channels);
        let has_position = joint.channels.iter().any(|c| !c.is_rotation());
        let mut need_rotation = false;
        let mut need_position = false;
        for f in 0..motion.frames {
            let q = motion.rotations[f * motion.joints + j];
            let t = motion.translations[f * motion.joints + j];
            if axes.len() < 3 && !same_rotation(rotation::compose(&axes, &rotation::decompose(q, &axes)), q) {
                need_rotation = true;
            }
            if !has_position && (t - joint.offset).length() > CHANNEL_TOLERANCE * (1.0 + joint.offset.length()) {
                need_position = true;
            }
        }
        if need_rotation {
            for axis in [2, 0, 1] {
                if !axes.contains(&axis) {
                    joint.channels.push([Channel::Xrotation, Channel::Yrotation, Channel::Zrotation][axis]);
                }
            }
        }
        if need_position {
            let mut channels = vec![Channel::Xposition, Channel::Yposition, Channel::Zposition];
            channels.append(&mut joint.channels);
            joint.channels = channels;
        }
    }
}

fn same_rotation(a: DQuat, b: DQuat) -> bool {
    a.dot(b).abs() > 1.0 - CHANNEL_TOLERANCE
}

/// Whether a joint's translation comes from the file's position channels (else it is the
/// OFFSET in every frame, and edits of the OFFSET carry over to it).
pub(crate) fn has_position_channels(skeleton: &Skeleton, j: usize) -> bool {
    skeleton.joints[j].channels.iter().any(|c| !c.is_rotation())
}

/// A motion needs a frame and the skeleton's joint count; every edit checks this first.
pub(crate) fn check(skeleton: &Skeleton, motion: &Motion) -> Result<(), EditError> {
    if skeleton.is_empty() || motion.joints != skeleton.len() {
        return Err(EditError::Mismatch(format!("the motion has {} joints but the skeleton {}", motion.joints, skeleton.len())));
    }
    if motion.frames == 0 {
        return Err(EditError::Range("the clip has no frames".to_string()));
    }
    if !(motion.frame_time.is_finite() && motion.frame_time > 0.0) {
        return Err(EditError::Invalid(format!("the frame time must be positive, found {}", motion.frame_time)));
    }
    Ok(())
}

/// The turn about the vertical (y) by `angle` radians.
pub(crate) fn turn(angle: f64) -> DQuat {
    DQuat::from_rotation_y(angle)
}

/// The horizontal part of a position.
pub(crate) fn horizontal(v: DVec3) -> DVec3 {
    DVec3::new(v.x, 0.0, v.z)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small synthetic walk with its skeleton, for the unit tests of every edit.
    pub(crate) fn creature() -> (Skeleton, Motion) {
        crate::synth::creature("quadruped", 0).expect("the quadruped builds")
    }

    #[test]
    fn channels_grow_only_where_needed() {
        let (mut s, mut m) = creature();
        let before = s.clone();
        fit_channels(&mut s, &m);
        assert_eq!(s, before);
        let j = s.len() - 1;
        s.joints[j].channels = vec![Channel::Zrotation];
        m.rotations[j] = DQuat::from_rotation_x(0.3);
        m.translations[j] += DVec3::X;
        fit_channels(&mut s, &m);
        assert_eq!(s.joints[j].channels.len(), 6);
        assert_eq!(s.joints[j].channels[3], Channel::Zrotation);
    }
}
