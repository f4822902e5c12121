//! Rotations from and to BVH Euler channels.
//!
//! A BVH joint lists its rotation channels in the order they compose: `Zrotation Xrotation
//! Yrotation` means R = Rz * Rx * Ry (intrinsic rotations, applied to column vectors), angles in
//! degrees. Decomposition supports the six Tait-Bryan orders, which is every order real files
//! use; joints with one or two rotation channels are decomposed by treating the missing axes as
//! zero-angle (exact when the rotation came from such a joint).

use crate::bvh::Channel;
use glam::{DMat3, DQuat, DVec3};

/// Rotation about one axis (0 = x, 1 = y, 2 = z) by `degrees`.
pub fn axis_rotation(axis: usize, degrees: f64) -> DQuat {
    let a = degrees.to_radians();
    match axis {
        0 => DQuat::from_rotation_x(a),
        1 => DQuat::from_rotation_y(a),
        _ => DQuat::from_rotation_z(a),
    }
}

/// Compose rotation channel values (degrees), in channel order, into one rotation.
pub fn compose(axes: &[usize], degrees: &[f64]) -> DQuat {
    let mut q = DQuat::IDENTITY;
    for (&axis, &d) in axes.iter().zip(degrees) {
        q *= axis_rotation(axis, d);
    }
    q
}

/// Euler angles (degrees) for `q` in the given axis order, such that `compose(order, angles)`
/// gives back `q` (up to the usual double cover). `order` must hold distinct axes.
pub fn decompose(q: DQuat, order: &[usize]) -> Vec<f64> {
    match order.len() {
        0 => Vec::new(),
        1 => {
            let (axis, angle) = q.to_axis_angle();
            let a = if axis[order[0]] < 0.0 { -angle } else { angle };
            vec![wrap_degrees(a.to_degrees())]
        }
        2 => {
            let third = 3 - order[0] - order[1];
            let full = decompose_tait_bryan(q, [order[0], order[1], third]);
            vec![full[0], full[1]]
        }
        _ => decompose_tait_bryan(q, [order[0], order[1], order[2]]).to_vec(),
    }
}

fn wrap_degrees(a: f64) -> f64 {
    let w = (a + 180.0).rem_euclid(360.0) - 180.0;
    if w == -180.0 {
        180.0
    } else {
        w
    }
}

/// R = Ri(a) * Rj(b) * Rk(c) for distinct axes i, j, k.
fn decompose_tait_bryan(q: DQuat, [i, j, k]: [usize; 3]) -> [f64; 3] {
    let m = DMat3::from_quat(q.normalize());
    let at = |r: usize, c: usize| m.col(c)[r];
    // +1 for cyclic orders (xyz, yzx, zxy), -1 for the others.
    let s = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let sb = (s * at(i, k)).clamp(-1.0, 1.0);
    let b = sb.asin();
    let (a, c);
    if sb.abs() < 1.0 - 1e-12 {
        a = (-s * at(j, k)).atan2(at(k, k));
        c = (-s * at(i, j)).atan2(at(i, i));
    } else {
        // Gimbal lock: only a +/- c is determined; put it all in the first angle.
        c = 0.0;
        a = (s * at(k, j)).atan2(at(j, j));
    }
    [a.to_degrees(), b.to_degrees(), c.to_degrees()]
}

/// The mirror image of a rotation across the plane through the origin normal to `axis`
/// (0 = x, 1 = y, 2 = z): for a reflection M, the rotation M q M. Its axis is reflected and
/// its sense reversed, so the component along `axis` stays and the other two change sign.
pub fn reflect(q: DQuat, axis: usize) -> DQuat {
    let mut v = [-q.x, -q.y, -q.z];
    v[axis.min(2)] = -v[axis.min(2)];
    DQuat::from_xyzw(v[0], v[1], v[2], q.w)
}

/// Axes of the rotation channels of a joint, in channel order.
pub fn rotation_axes(channels: &[Channel]) -> Vec<usize> {
    channels.iter().filter(|c| c.is_rotation()).map(|c| c.axis()).collect()
}

/// 6D rotation representation (first two columns of the matrix), as AnyTop and
/// Motion2Motion use it.
pub fn to_6d(q: DQuat) -> [f64; 6] {
    let m = DMat3::from_quat(q);
    let (a, b) = (m.x_axis, m.y_axis);
    [a.x, a.y, a.z, b.x, b.y, b.z]
}

/// Inverse of `to_6d` by Gram-Schmidt, robust to non-orthonormal network outputs.
pub fn from_6d(v: [f64; 6]) -> DQuat {
    let a = DVec3::new(v[0], v[1], v[2]);
    let b = DVec3::new(v[3], v[4], v[5]);
    let x = a.try_normalize().unwrap_or(DVec3::X);
    let y = (b - x * x.dot(b)).try_normalize().unwrap_or_else(|| x.any_orthonormal_vector());
    let z = x.cross(y);
    DQuat::from_mat3(&DMat3::from_cols(x, y, z))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DQuat, b: DQuat) -> bool {
        a.dot(b).abs() > 1.0 - 1e-12
    }

    #[test]
    fn decompose_inverts_compose_for_every_order_including_gimbal_lock() {
        let orders = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        let angles = [[10.0, 20.0, 30.0], [-170.0, 89.0, 45.0], [0.0, 90.0, 0.0], [30.0, -90.0, 10.0], [120.0, 5.0, -135.0], [0.0, 0.0, 0.0]];
        for order in orders {
            for a in angles {
                let q = compose(&order, &a);
                let back = decompose(q, &order);
                assert!(close(compose(&order, &back), q), "order {order:?} angles {a:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn partial_channel_sets_round_trip() {
        let q = compose(&[2], &[33.0]);
        assert!((decompose(q, &[2])[0] - 33.0).abs() < 1e-9);
        let q = compose(&[1, 0], &[-20.0, 70.0]);
        let back = decompose(q, &[1, 0]);
        assert!((back[0] + 20.0).abs() < 1e-9 && (back[1] - 70.0).abs() < 1e-9, "{back:?}");
    }

    #[test]
    fn six_d_round_trip() {
        let q = compose(&[2, 0, 1], &[12.0, -50.0, 160.0]);
        assert!(close(from_6d(to_6d(q)), q));
    }
}
