//! Animation channels as keyframe tracks, and their value at any time.
//!
//! Our motion has one pose per frame on a fixed grid, while a glTF channel has keys at its own
//! times; this is where one becomes the other, with the interpolation the glTF specification
//! gives each sampler mode (Appendix C): LINEAR (slerp for rotations), STEP (the previous key),
//! CUBICSPLINE (cubic Hermite through the keys with their in and out tangents).

use glam::{DQuat, DVec3, DVec4};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    Linear,
    Step,
    CubicSpline,
}

/// One channel's keys. For CUBICSPLINE, `values` holds three entries per key (in-tangent, value,
/// out-tangent), else one. Times are strictly increasing (checked when read).
#[derive(Clone, Debug)]
pub struct Track {
    pub times: Vec<f64>,
    pub values: Vec<DVec4>,
    pub interpolation: Interpolation,
}

impl Track {
    /// The keyed value of key `k` (the middle entry of a CUBICSPLINE triple).
    fn key(&self, k: usize) -> DVec4 {
        match self.interpolation {
            Interpolation::CubicSpline => self.values[3 * k + 1],
            _ => self.values[k],
        }
    }

    /// Keys `a` and `b` around time `t` and the weight of `b` (clamped outside the keys; exactly
    /// key `a` with weight 0 when `t` is a key time, so sampling at key times is exact).
    fn locate(&self, t: f64) -> (usize, usize, f64) {
        let after = self.times.partition_point(|&x| x <= t);
        if after == 0 {
            return (0, 0, 0.0);
        }
        let a = after - 1;
        if after == self.times.len() {
            return (a, a, 0.0);
        }
        let span = self.times[after] - self.times[a];
        let w = if span > 0.0 { (t - self.times[a]) / span } else { 0.0 };
        (a, after, w)
    }

    /// The raw interpolated 4-vector at `t`: linear for LINEAR (callers slerp rotations
    /// themselves), previous key for STEP, Hermite for CUBICSPLINE.
    fn hermite_or_key(&self, a: usize, b: usize, w: f64) -> DVec4 {
        if w == 0.0 || a == b || self.interpolation == Interpolation::Step {
            return self.key(a);
        }
        match self.interpolation {
            Interpolation::CubicSpline => {
                let dt = self.times[b] - self.times[a];
                let (w2, w3) = (w * w, w * w * w);
                let out_a = self.values[3 * a + 2];
                let in_b = self.values[3 * b];
                self.key(a) * (2.0 * w3 - 3.0 * w2 + 1.0) + out_a * (dt * (w3 - 2.0 * w2 + w)) + self.key(b) * (-2.0 * w3 + 3.0 * w2) + in_b * (dt * (w3 - w2))
            }
            _ => self.key(a).lerp(self.key(b), w),
        }
    }

    pub fn vec3_at(&self, t: f64) -> DVec3 {
        let (a, b, w) = self.locate(t);
        self.hermite_or_key(a, b, w).truncate()
    }

    /// Rotation at `t`; keys are stored (x, y, z, w) as glTF has them.
    pub fn quat_at(&self, t: f64) -> DQuat {
        let (a, b, w) = self.locate(t);
        let q = |v: DVec4| DQuat::from_xyzw(v.x, v.y, v.z, v.w);
        let value = if self.interpolation == Interpolation::Linear && w > 0.0 && a != b {
            q(self.key(a)).slerp(q(self.key(b)), w)
        } else {
            q(self.hermite_or_key(a, b, w))
        };
        value.normalize()
    }

    /// Whether every keyed value (tangents aside) is within `tol` of `v`.
    pub fn all_keys_near(&self, v: DVec4, tol: f64) -> bool {
        (0..self.times.len()).all(|k| (self.key(k) - v).abs().max_element() <= tol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(interpolation: Interpolation, values: Vec<DVec4>) -> Track {
        Track { times: vec![0.0, 1.0], values, interpolation }
    }

    #[test]
    fn linear_step_and_clamping() {
        let t = track(Interpolation::Linear, vec![DVec4::ZERO, DVec4::new(2.0, 4.0, 6.0, 0.0)]);
        assert_eq!(t.vec3_at(0.25), DVec3::new(0.5, 1.0, 1.5));
        assert_eq!(t.vec3_at(-1.0), DVec3::ZERO);
        assert_eq!(t.vec3_at(5.0), DVec3::new(2.0, 4.0, 6.0));
        let s = track(Interpolation::Step, t.values.clone());
        assert_eq!(s.vec3_at(0.99), DVec3::ZERO);
        assert_eq!(s.vec3_at(1.0), DVec3::new(2.0, 4.0, 6.0));
    }

    #[test]
    fn cubic_spline_with_zero_tangents_passes_through_keys_and_eases() {
        let v = |x: f64| DVec4::new(x, 0.0, 0.0, 0.0);
        let t = track(Interpolation::CubicSpline, vec![v(9.0), v(0.0), v(0.0), v(0.0), v(1.0), v(9.0)]);
        assert_eq!(t.vec3_at(0.0).x, 0.0);
        assert_eq!(t.vec3_at(1.0).x, 1.0);
        assert!((t.vec3_at(0.5).x - 0.5).abs() < 1e-12);
        assert!(t.vec3_at(0.1).x < 0.1, "zero tangents ease in");
    }

    #[test]
    fn rotations_slerp_the_short_way() {
        let a = DQuat::from_rotation_y(0.0);
        let b = -DQuat::from_rotation_y(1.0);
        let v = |q: DQuat| DVec4::new(q.x, q.y, q.z, q.w);
        let t = track(Interpolation::Linear, vec![v(a), v(b)]);
        let mid = t.quat_at(0.5);
        assert!(mid.angle_between(DQuat::from_rotation_y(0.5)) < 1e-9, "{mid:?}");
    }
}
