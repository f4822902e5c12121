//! Planting feet in generated features: the root's horizontal travel taken from the feet that
//! are on the ground, so that they stay where they are.
//!
//! A generated clip's root velocity and leg motion come out of the model separately, and when
//! they disagree the feet slide (the commonest artefact of generated motion). Decoding puts a
//! foot at `root(t) + r_t⁻¹·ric(t)` (`decode::recover`), so between frames t−1 and t a foot moves
//! by `Δroot + r_t⁻¹·ric(t) − r_{t−1}⁻¹·ric(t−1)`. Over a step where some feet are in contact
//! (the generated contact channel above one half at both frames), we choose the horizontal
//! Δroot that makes their mean horizontal motion zero — with one foot planted it stands still,
//! with several the body follows their average — and write it back as the root's velocity
//! feature (`r_t·Δroot`). Steps without a foot down keep the model's velocity. Height, facing
//! and the legs are untouched.

use super::{get3, get_6d, DIMS_POSITION, DIMS_ROTATION, DIMS_VELOCITY, DIM_CONTACT, FEATURE_DIMS};
use crate::repr::Features;
use glam::DVec3;

/// Contact channel value above which a foot counts as on the ground (the encoder writes 0 or 1).
const IN_CONTACT: f32 = 0.5;

/// Re-derive the root's horizontal velocity from the planted `feet` (see the module doc).
/// `fixed` cells (`[frame * joints + joint]`, e.g. an edit's kept frames) keep their values: a
/// step is changed only when the root's velocity cell at frame t−1 is not fixed. Returns how many
/// steps were changed. Features without the AnyTop layout, or no feet, change nothing.
pub fn plant_feet(features: &mut Features, feet: &[usize], fixed: Option<&[bool]>) -> usize {
    let (frames, joints) = (features.frames, features.joints);
    if features.dims != FEATURE_DIMS || joints == 0 || feet.is_empty() || feet.iter().any(|&j| j == 0 || j >= joints) {
        return 0;
    }
    let yaw_inv = |f: &Features, t: usize| super::decode::root_yaw(get_6d(&f.at(t, 0)[DIMS_ROTATION])).inverse();
    let mut changed = 0;
    for t in 1..frames {
        if fixed.is_some_and(|m| m.get((t - 1) * joints).copied().unwrap_or(false)) {
            continue;
        }
        let planted: Vec<usize> =
            feet.iter().copied().filter(|&j| features.at(t - 1, j)[DIM_CONTACT] > IN_CONTACT && features.at(t, j)[DIM_CONTACT] > IN_CONTACT).collect();
        if planted.is_empty() {
            continue;
        }
        let (now, before) = (yaw_inv(features, t), yaw_inv(features, t - 1));
        let mut drift = DVec3::ZERO;
        for &j in &planted {
            drift += now * get3(&features.at(t, j)[DIMS_POSITION]) - before * get3(&features.at(t - 1, j)[DIMS_POSITION]);
        }
        drift /= planted.len() as f64;
        // The root moves against the feet's drift; back into the root's velocity feature.
        let velocity = now.inverse() * DVec3::new(-drift.x, 0.0, -drift.z);
        let cell = &mut features.at_mut(t - 1, 0)[DIMS_VELOCITY];
        cell[0] = velocity.x as f32;
        cell[2] = velocity.z as f32;
        changed += 1;
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A root turned by `yaw` and moving by `step` (world) per frame, one foot whose RIC position
    /// is `foot(t)`, contact `down(t)`.
    fn clip(frames: usize, yaw: f64, step: DVec3, foot: impl Fn(usize) -> DVec3, down: impl Fn(usize) -> bool) -> Features {
        let mut f = Features::zeros(frames, 2, FEATURE_DIMS);
        let r = glam::DQuat::from_rotation_y(yaw);
        let m = glam::DMat3::from_quat(r);
        for t in 0..frames {
            let root = f.at_mut(t, 0);
            // 6D = the first two columns of the facing rotation.
            let (c0, c1) = (m.x_axis, m.y_axis);
            root[3..9].copy_from_slice(&[c0.x as f32, c0.y as f32, c0.z as f32, c1.x as f32, c1.y as f32, c1.z as f32]);
            let v = r * step;
            root[9] = v.x as f32;
            root[11] = v.z as f32;
            let p = foot(t);
            let j = f.at_mut(t, 1);
            j[0..3].copy_from_slice(&[p.x as f32, p.y as f32, p.z as f32]);
            j[DIM_CONTACT] = if down(t) { 1.0 } else { 0.0 };
        }
        f
    }

    /// World positions of joint 1 as decoding computes them.
    fn foot_world(f: &Features) -> Vec<DVec3> {
        let mut root = DVec3::ZERO;
        (0..f.frames)
            .map(|t| {
                let r_inv = super::super::decode::root_yaw(get_6d(&f.at(t, 0)[DIMS_ROTATION])).inverse();
                if t > 0 {
                    let v = get3(&f.at(t - 1, 0)[DIMS_VELOCITY]);
                    root += r_inv * DVec3::new(v.x, 0.0, v.z);
                }
                r_inv * get3(&f.at(t, 1)[DIMS_POSITION]) + root
            })
            .collect()
    }

    #[test]
    fn a_planted_foot_stops_sliding_and_a_lifted_one_keeps_the_models_motion() {
        // The body travels 0.05 per frame (turned 0.7 rad) while the foot stays put relative to
        // it: a slide of 0.05 per frame. Down on frames 0..10, lifted after.
        let mut f = clip(20, 0.7, DVec3::new(0.0, 0.0, 0.05), |_| DVec3::new(0.2, 0.0, 0.1), |t| t < 10);
        let before = foot_world(&f);
        assert!((before[9] - before[0]).length() > 0.4, "it slides before");
        let changed = plant_feet(&mut f, &[1], None);
        assert_eq!(changed, 9, "steps 1..=9 have the foot down at both ends");
        let after = foot_world(&f);
        for t in 1..10 {
            assert!((after[t] - after[0]).length() < 1e-5, "frame {t}: {:?} vs {:?}", after[t], after[0]);
        }
        // Lifted: the model's velocity is kept.
        for t in 11..20 {
            assert!(((after[t] - after[t - 1]) - (before[t] - before[t - 1])).length() < 1e-5);
        }
    }

    #[test]
    fn kept_cells_and_foreign_layouts_are_left_alone() {
        let f0 = clip(12, 0.3, DVec3::new(0.05, 0.0, 0.0), |t| DVec3::new(0.0, 0.0, 0.01 * t as f64), |_| true);
        let mut f = f0.clone();
        let fixed: Vec<bool> = (0..12 * 2).map(|k| k / 2 < 6).collect();
        let changed = plant_feet(&mut f, &[1], Some(&fixed));
        assert_eq!(changed, 5, "the velocities of frames 6..=10 (frames 0..=5 are kept)");
        assert_eq!(f.data[..6 * 2 * FEATURE_DIMS], f0.data[..6 * 2 * FEATURE_DIMS]);
        let mut other = Features::zeros(5, 2, 9);
        assert_eq!(plant_feet(&mut other, &[1], None), 0);
        assert_eq!(plant_feet(&mut f.clone(), &[0], None), 0, "the root is not a foot here");
        assert_eq!(plant_feet(&mut f.clone(), &[7], None), 0, "no such joint");
    }
}
