//! Heading-free channels: the rotation channels of `patch::channels` with the root's turning
//! about the vertical taken out of its rotation and velocity, and kept as a turning rate.
//!
//! Stitching patches of a clip, the root's heading jumps wherever two stitched stretches faced
//! different ways (a slow sway over a whole clip becomes a snap at every stitch) and its world
//! velocity no longer agrees with where the body faces. Here a patch holds the root's rotation
//! relative to its heading, its horizontal velocity in the heading's frame and the heading's
//! change per frame, so a stitched motion turns as the clips turn and walks where it faces.
//!
//! Layout (`width = 6J + 4`): the root's 6D rotation relative to its heading, the other joints'
//! local 6D rotations, then the heading's change per frame (radians), and the root's velocity
//! along the heading's x, its height and its velocity along the heading's z (times `scale`).
//! Frame 0's rates repeat frame 1's, as in `patch::channels`.

use crate::motion::Motion;
use crate::patch::channels::{self, Channels};
use crate::repr::m2m;
use glam::{DQuat, DVec3};
use std::f64::consts::PI;

/// The root's local axis whose direction tells its heading: of x, y and z, the one that stays
/// most horizontal over the clips (a creature's forward or side axis, whatever its rig's
/// convention).
pub(crate) fn heading_axis(clips: &[Motion]) -> DVec3 {
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut score = [0.0f64; 3];
    for m in clips {
        for f in 0..m.frames {
            let q = m.rotations[f * m.joints];
            for (s, a) in score.iter_mut().zip(axes) {
                let d = q * a;
                *s += (d.x * d.x + d.z * d.z).sqrt();
            }
        }
    }
    // Ties (an identity rest) go to z, the forward axis of most rigs.
    let best = (0..3).rev().max_by(|&a, &b| score[a].total_cmp(&score[b])).unwrap_or(2);
    axes[best]
}

/// Heading angle of a root rotation: the angle about y of `axis`'s direction.
pub(crate) fn yaw(q: DQuat, axis: DVec3) -> f64 {
    let d = q * axis;
    d.x.atan2(d.z)
}

fn wrap(a: f64) -> f64 {
    let r = (a + PI).rem_euclid(2.0 * PI) - PI;
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

/// Heading-free channels of a motion.
pub(crate) fn encode(motion: &Motion, scale: f64, axis: DVec3) -> Channels {
    let mut c = channels::rotation_features(motion, scale);
    let j = motion.joints;
    let width = c.width + 1;
    let mut out = Channels::zeros(motion.frames, width);
    let yaws: Vec<f64> = (0..motion.frames).map(|f| yaw(motion.rotations[f * j], axis)).collect();
    for f in 0..motion.frames {
        let q = motion.rotations[f * j];
        let heading = DQuat::from_rotation_y(yaws[f]);
        let turn = match (f, motion.frames) {
            (0, n) if n > 1 => wrap(yaws[1] - yaws[0]),
            (0, _) => 0.0,
            _ => wrap(yaws[f] - yaws[f - 1]),
        };
        let row = c.row_mut(f);
        for (slot, v) in row[..6].iter_mut().zip(m2m::rotation_to_6d(heading.inverse() * q)) {
            *slot = v as f32;
        }
        let (dx, y, dz) = (row[6 * j] as f64, row[6 * j + 1], row[6 * j + 2] as f64);
        let local = heading.inverse() * DVec3::new(dx, 0.0, dz);
        let dst = out.row_mut(f);
        dst[..6 * j].copy_from_slice(&c.row(f)[..6 * j]);
        dst[6 * j..].copy_from_slice(&[turn as f32, local.x as f32, y, local.z as f32]);
    }
    out
}

/// The heading of every frame: `start` plus the turning rates summed (frame 0 is `start`).
pub(crate) fn yaws(c: &Channels, joints: usize, start: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(c.frames);
    let mut a = start;
    for f in 0..c.frames {
        if f > 0 {
            a += c.row(f)[6 * joints] as f64;
        }
        out.push(a);
    }
    out
}

/// Back to `patch::channels`' rotation channels (width `6J + 3`) with the headings `yaws`.
pub(crate) fn to_rotation_channels(c: &Channels, joints: usize, yaws: &[f64]) -> Channels {
    let j = joints;
    let mut out = Channels::zeros(c.frames, 6 * j + 3);
    for (f, &a) in yaws.iter().enumerate().take(c.frames) {
        let row = c.row(f);
        let heading = DQuat::from_rotation_y(a);
        let residual = channels::quat_from_6d(&row[..6]);
        let world = heading * DVec3::new(row[6 * j + 1] as f64, 0.0, row[6 * j + 3] as f64);
        let dst = out.row_mut(f);
        for (slot, v) in dst[..6].iter_mut().zip(m2m::rotation_to_6d(heading * residual)) {
            *slot = v as f32;
        }
        dst[6..6 * j].copy_from_slice(&row[6..6 * j]);
        dst[6 * j..].copy_from_slice(&[world.x as f32, row[6 * j + 2], world.z as f32]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::creature;

    #[test]
    fn round_trip_and_turn_invariance() {
        let (s, m) = creature("quadruped", 1).unwrap();
        let m = m.first_frames(40);
        let axis = heading_axis(std::slice::from_ref(&m));
        let scale = channels::feature_scale(&s);
        let c = encode(&m, scale, axis);
        assert_eq!(c.width, 6 * s.len() + 4);
        let back = to_rotation_channels(&c, s.len(), &yaws(&c, s.len(), yaw(m.rotations[0], axis)));
        let want = channels::rotation_features(&m, scale);
        for (a, b) in back.data.iter().zip(&want.data) {
            assert!((a - b).abs() < 1e-4, "{a} vs {b}");
        }
        // The same motion turned about y has the same channels, the first rate aside.
        let turn = DQuat::from_rotation_y(1.1);
        let mut turned = m.clone();
        for f in 0..m.frames {
            turned.rotations[f * m.joints] = turn * m.rotations[f * m.joints];
            turned.translations[f * m.joints] = turn * m.translations[f * m.joints];
        }
        let t = encode(&turned, scale, axis);
        for f in 1..m.frames {
            for (a, b) in t.row(f).iter().zip(c.row(f)) {
                assert!((a - b).abs() < 1e-4, "frame {f}: {a} vs {b}");
            }
        }
    }
}
