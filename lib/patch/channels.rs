//! Per-frame channel vectors: what patches are made of, built from motions and decoded back.
//!
//! The rotation features (what GenMM and Motion2Motion match and blend) are the reference's flat vector (`repr::m2m::reference_vector`): the
//! local 6D rotation of every joint, then the root's (dx, y, dz). Two changes from the
//! reference, both to keep patches comparable wherever they come from:
//! * root positions are multiplied by `scale` (the reference's `1 / ceil(max offset)` of the
//!   target, with the sign fixed), so centimetre and metre skeletons weigh the same;
//! * frame 0's dx/dz repeat frame 1's instead of holding an absolute position (the reference's
//!   `v[0] = p[1]` quirk can blend a start position into a mid-clip frame,
//!   docs/reference/motion2motion.md §4 "root handling"). The start position is kept aside and
//!   restored when decoding.

use crate::motion::Motion;
use crate::repr::m2m;
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};
use rayon::prelude::*;

/// A `[frames, width]` float32 array, frame-major: one channel vector per frame.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Channels {
    pub frames: usize,
    pub width: usize,
    pub data: Vec<f32>,
}

impl Channels {
    pub fn zeros(frames: usize, width: usize) -> Channels {
        Channels { frames, width, data: vec![0.0; frames * width] }
    }

    pub fn row(&self, t: usize) -> &[f32] {
        &self.data[t * self.width..(t + 1) * self.width]
    }

    pub fn row_mut(&mut self, t: usize) -> &mut [f32] {
        &mut self.data[t * self.width..(t + 1) * self.width]
    }

    /// Linear resampling in time to `frames` frames with half-pixel centres (torch's
    /// `interpolate(mode='linear', align_corners=False)`, what the reference uses between
    /// pyramid levels). Same length: a copy.
    pub fn resize(&self, frames: usize) -> Channels {
        if frames == self.frames || self.frames == 0 {
            let mut out = self.clone();
            if self.frames == 0 {
                out = Channels::zeros(frames, self.width);
            }
            return out;
        }
        let mut out = Channels::zeros(frames, self.width);
        let ratio = self.frames as f64 / frames as f64;
        let last = (self.frames - 1) as f64;
        for t in 0..frames {
            let x = ((t as f64 + 0.5) * ratio - 0.5).clamp(0.0, last);
            let a = x.floor() as usize;
            let b = (a + 1).min(self.frames - 1);
            let w = (x - a as f64) as f32;
            let (ra, rb) = (self.row(a), self.row(b));
            for ((o, &va), &vb) in out.row_mut(t).iter_mut().zip(ra).zip(rb) {
                *o = va + (vb - va) * w;
            }
        }
        out
    }
}

/// The scale applied to root positions (and joint positions): the reference's
/// `1 / ceil(max offset component)` of the target, on absolute values so a skeleton with only
/// negative offsets does not divide by zero.
pub(crate) fn feature_scale(target: &Skeleton) -> f64 {
    let max = target.joints.iter().map(|j| j.offset.abs().max_element()).fold(0.0f64, f64::max);
    let ceil = max.ceil();
    if ceil >= 1.0 && ceil.is_finite() {
        1.0 / ceil
    } else {
        1.0
    }
}

/// Width of the rotation features of a skeleton with `joints` joints.
pub(crate) fn rotation_width(joints: usize) -> usize {
    6 * joints + 3
}

/// Root (dx, y, dz) per frame, times `scale`; frame 0 repeats frame 1's velocity.
pub(crate) fn root_track(motion: &Motion, scale: f64) -> Vec<[f32; 3]> {
    let j = motion.joints;
    let root = |f: usize| motion.translations[f * j];
    let mut out = Vec::with_capacity(motion.frames);
    for f in 0..motion.frames {
        let p = root(f);
        let d = if f > 0 {
            p - root(f - 1)
        } else if motion.frames > 1 {
            root(1) - p
        } else {
            DVec3::ZERO
        };
        out.push([(d.x * scale) as f32, (p.y * scale) as f32, (d.z * scale) as f32]);
    }
    out
}

/// Root start position (x, z) of a motion.
pub(crate) fn root_start(motion: &Motion) -> (f64, f64) {
    motion.translations.first().map(|p| (p.x, p.z)).unwrap_or((0.0, 0.0))
}

/// Rotation features of a motion (width `6J + 3`).
pub(crate) fn rotation_features(motion: &Motion, scale: f64) -> Channels {
    let j = motion.joints;
    let mut out = Channels::zeros(motion.frames, rotation_width(j));
    let root = root_track(motion, scale);
    for (f, track) in root.iter().enumerate() {
        let row = out.row_mut(f);
        for k in 0..j {
            let six = m2m::rotation_to_6d(motion.rotations[f * j + k]);
            for (slot, v) in row[6 * k..6 * k + 6].iter_mut().zip(six) {
                *slot = v as f32;
            }
        }
        row[6 * j..].copy_from_slice(track);
    }
    out
}

/// Decode rotation features on `skeleton`: 6D rotations (`m2m`'s convention, in parallel over
/// frames), root velocities summed from `start`, other translations from the OFFSETs.
pub(crate) fn decode(rot: &Channels, skeleton: &Skeleton, scale: f64, start: (f64, f64), frame_time: f64) -> Result<Motion, m2m::M2mError> {
    let j = skeleton.len();
    if let Some(k) = rot.data.iter().position(|v| !v.is_finite()) {
        let (frame, c) = (k / rot.width, k % rot.width);
        let (joint, dim) = if c < 6 * j { (c / 6, c % 6) } else { (0, c - 6 * j + 6) };
        return Err(m2m::M2mError::NonFinite { frame, joint, name: skeleton.joints[joint].name.clone(), dim, value: rot.data[k] });
    }
    // Filled in place: collecting a parallel flat_map goes through per-thread pieces and
    // needs about twice the memory at the end, which set the peak on long outputs.
    let mut rotations = vec![DQuat::IDENTITY; rot.frames * j];
    rotations.par_chunks_mut(j.max(1)).enumerate().for_each(|(f, out)| {
        let row = rot.row(f);
        for (k, q) in out.iter_mut().enumerate() {
            *q = quat_from_6d(&row[6 * k..6 * k + 6]);
        }
    });
    let mut translations = Vec::with_capacity(rot.frames * j);
    let (mut x, mut z) = start;
    for f in 0..rot.frames {
        let r = &rot.row(f)[6 * j..6 * j + 3];
        if f > 0 {
            x += r[0] as f64 / scale;
            z += r[2] as f64 / scale;
        }
        translations.push(DVec3::new(x, r[1] as f64 / scale, z));
        translations.extend(skeleton.joints.iter().skip(1).map(|joint| joint.offset));
    }
    Ok(Motion { frames: rot.frames, joints: j, frame_time, rotations, translations })
}

/// `m2m::rotation_from_6d` without the detours (the hot loop of decoding long outputs): the
/// rows are orthonormalised by Gram-Schmidt and the matrix turned into a quaternion (Shepperd's
/// method, largest diagonal first). Degenerate rows fall back to `m2m`'s careful version.
pub(crate) fn quat_from_6d(v: &[f32]) -> DQuat {
    let a = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
    let b = DVec3::new(v[3] as f64, v[4] as f64, v[5] as f64);
    // Reciprocals and products instead of divisions: this loop is bound by the latency of
    // its chain of square roots and divisions.
    let la = a.length();
    let x = a * (1.0 / la);
    let b = b - x * x.dot(b);
    let lb = b.length();
    if !(la > 1e-12 && lb > 1e-12 && la.is_finite() && lb.is_finite()) {
        return m2m::rotation_from_6d(std::array::from_fn(|i| v[i] as f64));
    }
    let y = b * (1.0 / lb);
    let z = x.cross(y);
    // x, y, z are the rows of R.
    let (m00, m01, m02, m10, m11, m12, m20, m21, m22) = (x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z);
    let trace = m00 + m11 + m22;
    let q = if trace > 0.0 {
        let s = (trace + 1.0).sqrt() * 2.0;
        let r = 1.0 / s;
        DQuat::from_xyzw((m21 - m12) * r, (m02 - m20) * r, (m10 - m01) * r, 0.25 * s)
    } else if m00 > m11 && m00 > m22 {
        let s = (1.0 + m00 - m11 - m22).sqrt() * 2.0;
        let r = 1.0 / s;
        DQuat::from_xyzw(0.25 * s, (m01 + m10) * r, (m02 + m20) * r, (m21 - m12) * r)
    } else if m11 > m22 {
        let s = (1.0 + m11 - m00 - m22).sqrt() * 2.0;
        let r = 1.0 / s;
        DQuat::from_xyzw((m01 + m10) * r, 0.25 * s, (m12 + m21) * r, (m02 - m20) * r)
    } else {
        let s = (1.0 + m22 - m00 - m11).sqrt() * 2.0;
        let r = 1.0 / s;
        DQuat::from_xyzw((m02 + m20) * r, (m12 + m21) * r, 0.25 * s, (m10 - m01) * r)
    };
    // The matrix is orthonormal to rounding, so the quaternion is unit to rounding; one
    // multiply by the reciprocal length makes it exact enough for `is_normalized`.
    q * (1.0 / q.length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_6d_decoding_agrees_with_m2m() {
        let qs = [
            DQuat::IDENTITY,
            DQuat::from_rotation_x(3.1),
            DQuat::from_rotation_y(-2.9),
            DQuat::from_rotation_z(3.0),
            DQuat::from_euler(glam::EulerRot::ZXY, 0.3, -1.2, 2.2),
            DQuat::from_euler(glam::EulerRot::XYZ, 2.8, 0.1, -2.9),
        ];
        for q in qs {
            let six: Vec<f32> = m2m::rotation_to_6d(q).iter().map(|&v| v as f32 * 1.7).collect();
            let (fast, slow) = (quat_from_6d(&six), m2m::rotation_from_6d(std::array::from_fn(|i| six[i] as f64)));
            assert!(fast.dot(slow).abs() > 1.0 - 1e-9, "{q}: {fast} vs {slow}");
            assert!(fast.dot(q).abs() > 1.0 - 1e-6);
        }
        // Degenerate rows still give a rotation.
        assert!(quat_from_6d(&[0.0; 6]).is_normalized());
        assert!(quat_from_6d(&[1.0, 0.0, 0.0, 2.0, 0.0, 0.0]).is_normalized());
    }
}
