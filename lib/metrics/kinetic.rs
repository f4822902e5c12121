//! Kinetic features of one clip (AIST++/Bailando, as Motion2Motion's `utils/features/kinetic.py`
//! computes them; `docs/reference/motion2motion.md` §3.7): for every joint, the mean horizontal and
//! vertical kinetic energy (per unit mass) and the mean energy expenditure. FID over these
//! vectors is Motion2Motion's FID_k.
//!
//! Deviations from the reference (also in `docs/metrics.md`): the frame time is the
//! clip's own (`1 / clip.fps`), not a hard-coded 1/60 s; values stay f64 (the reference casts
//! to f32); clips shorter than 3 frames are refused instead of giving zero energy expenditure.

use super::physics::check_clip;
use super::{MetricError, WorldClip};
use glam::DVec3;

/// Half-width of the smoothing window, in frames (the reference's `sliding_window = 2`).
const WINDOW: isize = 2;

/// `3 x joints` values, `[h_0, v_0, e_0, h_1, v_1, e_1, ...]` in joint order:
/// * `h_j`: mean over frames 1..T-1 of the squared horizontal (x, z) speed, the displacement
///   summed over the window of up to 5 one-frame steps around the frame before taking the
///   norm (clip units² / s²);
/// * `v_j`: the same for the vertical (y) speed (clip units² / s²);
/// * `e_j`: mean over frames 1..T-1 of the norm of the window-averaged acceleration (clip
///   units / s²); a frame whose window holds no second difference contributes 0.
///
/// Needs 3 frames (the first frame that has an acceleration) and finite input.
pub fn kinetic_features(clip: &WorldClip) -> Result<Vec<f64>, MetricError> {
    check_clip(clip, 3, "kinetic features")?;
    let dt = 1.0 / clip.fps;
    let t = clip.frames as isize;
    let mut out = Vec::with_capacity(3 * clip.joints);
    for j in 0..clip.joints {
        let p = |f: isize| clip.at(f as usize, j);
        let (mut h, mut v, mut e) = (0.0, 0.0, 0.0);
        for i in 1..t {
            let mut displacement = DVec3::ZERO;
            let mut n = 0usize;
            let mut acceleration = DVec3::ZERO;
            let mut m = 0usize;
            for o in -WINDOW..=WINDOW {
                let k = i + o;
                if k >= 1 && k < t {
                    displacement += p(k) - p(k - 1);
                    n += 1;
                }
                if k >= 1 && k + 1 < t {
                    acceleration += ((p(k + 1) - p(k)) - (p(k) - p(k - 1))) / (dt * dt);
                    m += 1;
                }
            }
            // n >= 1 always: o = 0 gives the step (i-1, i).
            let velocity = displacement / (n as f64 * dt);
            h += velocity.x * velocity.x + velocity.z * velocity.z;
            v += velocity.y * velocity.y;
            if m > 0 {
                e += (acceleration / m as f64).length();
            }
        }
        let steps = (t - 1) as f64;
        out.extend([h / steps, v / steps, e / steps]);
    }
    Ok(out)
}

/// Names of the `kinetic_features` dimensions, `<joint>/h`, `<joint>/v`, `<joint>/e`.
pub fn kinetic_feature_names(clip: &WorldClip) -> Vec<String> {
    (0..clip.joints)
        .flat_map(|j| {
            let name = super::physics::joint_name(clip, j);
            ["h", "v", "e"].map(|k| format!("{name}/{k}"))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::physics::tests::biped;

    #[test]
    fn constant_velocity_has_known_energy_and_no_expenditure() {
        // Both joints move (3, 4, 0) units per frame at 10 fps: horizontal speed 30, vertical 40.
        let clip = biped(7, 10.0, |f| DVec3::new(3.0, 4.0, 0.0) * f as f64);
        let k = kinetic_features(&clip).unwrap();
        assert_eq!(k.len(), 6);
        for j in 0..2 {
            assert!((k[3 * j] - 900.0).abs() < 1e-9, "{k:?}");
            assert!((k[3 * j + 1] - 1600.0).abs() < 1e-9);
            assert!(k[3 * j + 2].abs() < 1e-9);
        }
        assert_eq!(kinetic_feature_names(&clip)[4], "LeftFoot/v");
    }

    #[test]
    fn constant_acceleration_expends_energy_on_the_frames_that_have_it() {
        // x = f² / 2 per frame at 1 fps: second difference 1 everywhere. With T = 5 second
        // differences exist at k = 1..=3, and every frame's window (i-2..=i+2) holds one: e = 1.
        let clip = biped(5, 1.0, |f| DVec3::new((f * f) as f64 / 2.0, 0.0, 0.0));
        let k = kinetic_features(&clip).unwrap();
        assert!((k[2] - 1.0).abs() < 1e-12, "{k:?}");
        // Horizontal: window-averaged speeds by hand, displacements 0.5, 1.5, 2.5, 3.5.
        // i=1: steps 1..=3 -> (0.5+1.5+2.5)/3 = 1.5; i=2: steps 1..=4 -> 2; i=3: 1..=4 -> 2;
        // i=4: steps 2..=4 -> 2.5. Mean of squares = (2.25 + 4 + 4 + 6.25) / 4 = 4.125.
        assert!((k[0] - 4.125).abs() < 1e-12, "{k:?}");
    }

    #[test]
    fn short_or_non_finite_clips_are_refused() {
        for frames in [1, 2] {
            assert!(matches!(kinetic_features(&biped(frames, 30.0, |_| DVec3::ZERO)), Err(MetricError::TooLittle(_))));
        }
        let mut clip = biped(4, 30.0, |_| DVec3::ZERO);
        clip.positions[3].x = f64::INFINITY;
        assert!(matches!(kinetic_features(&clip), Err(MetricError::NonFinite(_))));
        assert!(kinetic_features(&biped(3, 30.0, |_| DVec3::ZERO)).unwrap().iter().all(|&x| x == 0.0));
    }
}
