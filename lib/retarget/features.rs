//! Motion2Motion's extra per-frame features and skeleton comparisons: the position and
//! velocity channels of `Repr::Position` / `Repr::Velocity` (the rotation channels every run
//! blends are `patch::channels`), the size ratio between two skeletons and bone alignment.

use super::settings::Repr;
use crate::motion::Motion;
use crate::patch::channels::{root_track, Channels};
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};

/// Height of the root above the lowest rest point: the leg length that sets stride size. A
/// lying creature (snake) has almost none, so its largest extent is used instead.
fn hip_height(skeleton: &Skeleton) -> f64 {
    let (lo, _) = skeleton.rest_bounds();
    let root = skeleton.joints.first().map(|j| j.offset.y).unwrap_or(0.0);
    let h = root - lo.y;
    let extent = skeleton.rest_extent();
    if h.is_finite() && h > 0.1 * extent {
        h
    } else {
        extent
    }
}

/// How much longer the target's strides are than the source's (ratio of hip heights).
pub(crate) fn size_ratio(source: &Skeleton, target: &Skeleton) -> f64 {
    let (s, t) = (hip_height(source), hip_height(target));
    if s.is_finite() && t.is_finite() && s > 0.0 && t > 0.0 {
        t / s
    } else {
        1.0
    }
}

/// Width of the position or velocity features.
pub(crate) fn point_width(joints: usize) -> usize {
    3 * joints + 3
}

/// Per-joint 3-vectors of a motion for the position or velocity features: positions relative
/// to the root (translation only), or world velocities per frame; times `scale`. Joint 0's slot
/// is unused (the root track sits at the end).
pub(crate) fn joint_points(motion: &Motion, skeleton: &Skeleton, repr: Repr, scale: f64) -> Vec<DVec3> {
    let world = motion.forward_kinematics(skeleton);
    let j = motion.joints;
    let mut out = vec![DVec3::ZERO; motion.frames * j];
    for f in 0..motion.frames {
        for k in 1..j {
            let v = match repr {
                Repr::Velocity => {
                    let (a, b) = if f > 0 {
                        (f - 1, f)
                    } else if motion.frames > 1 {
                        (0, 1)
                    } else {
                        (0, 0)
                    };
                    world.position(b, k) - world.position(a, k)
                }
                _ => world.position(f, k) - world.position(f, 0),
            };
            out[f * j + k] = v * scale;
        }
    }
    out
}

/// Position or velocity features of a motion (width `3J + 3`).
pub(crate) fn point_features(motion: &Motion, skeleton: &Skeleton, repr: Repr, scale: f64) -> Channels {
    let j = motion.joints;
    let points = joint_points(motion, skeleton, repr, scale);
    let root = root_track(motion, scale);
    let mut out = Channels::zeros(motion.frames, point_width(j));
    for f in 0..motion.frames {
        let row = out.row_mut(f);
        for k in 1..j {
            let p = points[f * j + k];
            row[3 * k..3 * k + 3].copy_from_slice(&[p.x as f32, p.y as f32, p.z as f32]);
        }
        row[3 * j..].copy_from_slice(&root[f]);
    }
    out
}

/// Rest direction of a joint's bone: towards its first child, else its first End Site.
pub(crate) fn bone_direction(skeleton: &Skeleton, joint: usize) -> Option<DVec3> {
    let child = skeleton.joints.iter().find(|c| c.parent == Some(joint)).map(|c| c.offset);
    let d = child.or_else(|| skeleton.joints[joint].end_sites.first().copied())?;
    d.try_normalize()
}

/// The rotation `A` with `A * target_dir = source_dir` (identity when either is unknown).
pub(crate) fn alignment(source: &Skeleton, s: usize, target: &Skeleton, t: usize) -> DQuat {
    match (bone_direction(source, s), bone_direction(target, t)) {
        (Some(ds), Some(dt)) => DQuat::from_rotation_arc(dt, ds),
        _ => DQuat::IDENTITY,
    }
}
