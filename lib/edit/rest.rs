//! A new rest pose: the OFFSETs of a chosen frame (or of a pose from another clip, a T-pose
//! say), with the motion re-expressed so that every joint's world position stays the same.
//!
//! Retargeting, IK and Blender's armature import read the rest pose as the bind pose; a clip
//! whose OFFSETs are a crouch or a tangle makes all of them worse. A BVH rest pose has every
//! joint unrotated, so the new rest pose is the chosen pose with each joint's world rotation
//! folded into the OFFSETs below it: with C_j = W_j(N)^-1 G (W world rotations at the chosen
//! pose, G its root heading), the new OFFSETs are C_parent^-1 OFFSET and the new local
//! rotations C_parent^-1 q C_j, which leaves every world position unchanged (to rounding).

use super::{check, EditError};
use crate::genmm::heading::{heading_axis, yaw};
use crate::motion::Motion;
use crate::skeleton::Skeleton;
use glam::DQuat;

/// The rest pose taken from frame `frame` of the clip itself.
pub fn from_frame(skeleton: &Skeleton, motion: &Motion, frame: usize) -> Result<(Skeleton, Motion), EditError> {
    check(skeleton, motion)?;
    if frame >= motion.frames {
        return Err(EditError::Range(format!("frame {frame} is past the end: the clip has {} frames (0..{})", motion.frames, motion.frames - 1)));
    }
    from_pose(skeleton, motion, &motion.frame_range(frame, frame + 1))
}

/// The rest pose taken from the first frame of `pose`, a motion of the same skeleton.
pub fn from_pose(skeleton: &Skeleton, motion: &Motion, pose: &Motion) -> Result<(Skeleton, Motion), EditError> {
    check(skeleton, motion)?;
    if pose.joints != skeleton.len() || pose.frames == 0 {
        return Err(EditError::Mismatch(format!("the pose has {} joints and {} frames; the skeleton has {} joints", pose.joints, pose.frames, skeleton.len())));
    }
    let n = skeleton.len();
    let world = pose.first_frames(1).forward_kinematics(skeleton).rotations;
    // The new rest pose faces as the old one did: the chosen pose's heading is taken out.
    let axis = heading_axis(std::slice::from_ref(pose));
    let heading = super::turn(yaw(pose.rotations[0], axis) - yaw(DQuat::IDENTITY, axis));
    let fold: Vec<DQuat> = world.iter().map(|w| (w.inverse() * heading).normalize()).collect();
    let parent_fold = |j: usize| skeleton.joints[j].parent.map_or(DQuat::IDENTITY, |p| fold[p]);

    let mut s = skeleton.clone();
    for (j, joint) in s.joints.iter_mut().enumerate() {
        if joint.parent.is_some() {
            joint.offset = parent_fold(j).inverse() * pose.translations[j];
        }
        for e in &mut joint.end_sites {
            *e = fold[j].inverse() * *e;
        }
    }
    let mut m = motion.clone();
    for f in 0..motion.frames {
        for j in 0..n {
            let k = f * n + j;
            let up = parent_fold(j).inverse();
            m.rotations[k] = (up * motion.rotations[k] * fold[j]).normalize();
            if skeleton.joints[j].parent.is_some() {
                m.translations[k] = up * motion.translations[k];
            }
        }
    }
    Ok((s, m))
}

#[cfg(test)]
mod tests {
    use super::super::tests::creature;
    use super::*;

    #[test]
    fn world_positions_stay_and_the_rest_pose_is_the_frame() {
        let (s, m) = creature();
        let n = m.frames / 3;
        let (s2, m2) = from_frame(&s, &m, n).unwrap();
        let (a, b) = (m.forward_kinematics(&s).positions, m2.forward_kinematics(&s2).positions);
        let worst = a.iter().zip(&b).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
        // The new rest pose has the frame's shape: the same distances between joints.
        let rest = s2.rest_positions();
        let frame = &a[n * s.len()..(n + 1) * s.len()];
        for j in 1..s.len() {
            let d = (rest[j] - rest[0]).length() - (frame[j] - frame[0]).length();
            assert!(d.abs() < 1e-9);
        }
        assert!(from_frame(&s, &m, m.frames).is_err());
    }
}
