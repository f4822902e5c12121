//! Two-bone inverse kinematics: where a knee goes so that a foot lands on a target, and the
//! rotation that aims a bone. The procedural creatures pose their legs with it and
//! `edit::foot_lock` pins feet with it, so both solve a leg the same way.

use glam::{DMat3, DQuat, DVec3};

/// Where the middle joint of a two-bone chain goes: the law of cosines in the plane of
/// `hip -> target` and `pole`. Out-of-reach targets are pulled in just short of a straight
/// limb, so the solve never produces NaN and knees never snap through.
pub fn two_bone_knee(hip: DVec3, target: DVec3, l1: f64, l2: f64, pole: DVec3) -> DVec3 {
    let to = target - hip;
    let dir = to.try_normalize().unwrap_or(DVec3::NEG_Y);
    let d = to.length().clamp((l1 - l2).abs() + 1e-6, (l1 + l2) * 0.9999);
    let a = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d);
    let h = (l1 * l1 - a * a).max(0.0).sqrt();
    let side = (pole - dir * dir.dot(pole)).try_normalize().unwrap_or_else(|| dir.any_orthonormal_vector());
    hip + dir * a + side * h
}

/// The rotation taking direction `from` to `to` while taking the reference `from_ref` to
/// `to_ref` as closely as possible (both references are made perpendicular first).
pub fn aim(from: DVec3, from_ref: DVec3, to: DVec3, to_ref: DVec3) -> DQuat {
    let frame = |x: DVec3, r: DVec3| {
        let x = x.normalize();
        let y = (r - x * x.dot(r)).try_normalize().unwrap_or_else(|| x.any_orthonormal_vector());
        DMat3::from_cols(x, y, x.cross(y))
    };
    DQuat::from_mat3(&(frame(to, to_ref) * frame(from, from_ref).transpose())).normalize()
}
