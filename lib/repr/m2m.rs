//! Motion2Motion's motion representation: local 6D rotations of every joint plus the root's
//! position, with the root's horizontal position as per-frame velocities.
//!
//! `mo-retarget` matches and blends patches of these vectors, so they must be what the
//! reference feeds its patch search (docs/reference/motion2motion.md §3.1), and `mo-encode`
//! must turn them back into the same motion. The paper states D = 6J + 3 per frame; the
//! reference code lays the 6J rotation values (joints in file order) first, then the root
//! position (x, y, z), with x and z turned into frame-to-frame differences and y kept absolute.
//!
//! # Layout: `[frames, joints, 9]`
//!
//! We keep one row per skeleton joint (the pipeline contract's `[frames, joints, dims]`, so joint
//! counts check against the skeleton and per-joint tools work unchanged):
//!
//! | dims | joint 0 (root) | other joints |
//! |---|---|---|
//! | 0..6 | local rotation, 6D | local rotation, 6D |
//! | 6..9 | root position: dx, y, dz | 0 (unused) |
//!
//! * **6D** is the reference's convention: the first two *rows* of the local rotation matrix R
//!   (R maps the joint's frame to its parent's; column vectors), row-major:
//!   `[R00, R01, R02, R10, R11, R12]`. (`motion::rotation::to_6d`, AnyTop's convention, keeps
//!   the first two columns instead.) Decoding orthonormalises by Gram-Schmidt, so network or
//!   blended outputs that are not exactly rotations decode to the nearest sensible one.
//! * **Root position**, in the BVH's own units: `dx[t] = x[t] - x[t-1]`, `dz` likewise, `y[t]`
//!   absolute, and frame 0's `dx, dz` are the start position itself (as if `x[-1] = z[-1] = 0`).
//!   Decoding sums them, so a tensor alone puts the motion back where it was.
//!   The reference's flat vector is `[f[:, :, 0:6].reshape(F, 6J), f[:, 0, 6:9]]` in numpy terms.
//!
//! # Deviations from the reference, and why
//!
//! * Layout: 9 dims per joint (3(J-1) zero columns more than the reference's 6J + 3), see above.
//! * Frame 0: the reference stores `v[0] = p[1]` (an absolute position in a velocity channel, a
//!   GenMM quirk, §4 "root handling") and keeps `p[0]` outside the tensor; we store `p[0]`
//!   there, and every later frame is a true difference. Tools that want pure velocities should
//!   ignore frame 0's dx/dz.
//! * Rounding: the velocities are computed against the position the decoder will reconstruct
//!   from the already-rounded float32 values, so float32 rounding does not accumulate along a
//!   long clip (decoded positions stay within one float32 rounding step of the original).
//! * No rescaling (the reference multiplies offsets and root positions by the target's
//!   `1/ceil(max offset)`), no 120 -> 60 fps decimation and no detour through XYZ Euler angles:
//!   tensors are in physical units at the clip's frame rate (docs/ARCHITECTURE.md), and the
//!   rotation is taken from the file's own channel order, which gives the same matrix.
//!
//! # What it cannot carry
//!
//! Like the reference, only the root translates: every other joint's translation is its
//! skeleton OFFSET. Files that animate bone translations (six channels on every joint, where
//! the position channels replace the OFFSET) lose that motion, and files whose position channels
//! hold constants different from the OFFSET decode onto the OFFSET skeleton.
//! `max_bone_translation_change` measures how much is lost; `mo-encode` warns about it. A joint
//! without rotation channels keeps whatever rotation the features give it in the `Motion`, but
//! a BVH cannot write it (the identity, for encoded data).

use super::Features;
use crate::motion::{rotation, Motion};
use crate::skeleton::Skeleton;
use glam::{DMat3, DQuat, DVec3};

/// Feature dims per joint.
pub const DIMS: usize = 9;
/// Where the 6D rotation sits in a joint's row.
pub const ROTATION: std::ops::Range<usize> = 0..6;
/// Where the root position (dx, y, dz) sits in the root's row.
pub const ROOT_POSITION: std::ops::Range<usize> = 6..9;

/// Why features cannot be decoded on a skeleton.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum M2mError {
    #[error("the features have {features} joints but the skeleton has {skeleton}")]
    JointCount { features: usize, skeleton: usize },
    #[error("m2m features have {DIMS} dims per joint, found {0}")]
    Dims(usize),
    #[error("non-finite value {value} at frame {frame}, joint {joint} '{name}', dim {dim}")]
    NonFinite { frame: usize, joint: usize, name: String, dim: usize, value: f32 },
}

/// The 6D rotation of the reference: the first two rows of the rotation matrix, row-major.
pub fn rotation_to_6d(q: DQuat) -> [f64; 6] {
    // Rows of R are the columns of R^T, which is the matrix of the inverse rotation.
    rotation::to_6d(q.normalize().conjugate())
}

/// Inverse of `rotation_to_6d`, by Gram-Schmidt on the two rows (robust to inexact input).
pub fn rotation_from_6d(v: [f64; 6]) -> DQuat {
    rotation::from_6d(v).conjugate()
}

/// Encode a motion. The root is joint 0 (as in every `Skeleton` and `Motion` we build).
pub fn encode(motion: &Motion) -> Features {
    let (frames, joints) = (motion.frames, motion.joints);
    let mut features = Features::zeros(frames, joints, DIMS);
    // Reconstructed root x/z so far: exactly what `decode` will compute, in the same order.
    let (mut x, mut z) = (0.0f64, 0.0f64);
    for f in 0..frames {
        for j in 0..joints {
            let six = rotation_to_6d(motion.rotations[f * joints + j]);
            let row = features.at_mut(f, j);
            for (slot, v) in row[ROTATION].iter_mut().zip(six) {
                *slot = v as f32;
            }
        }
        if joints > 0 {
            let p = motion.translations[f * joints];
            let dx = (p.x - x) as f32;
            let dz = (p.z - z) as f32;
            x += dx as f64;
            z += dz as f64;
            features.at_mut(f, 0)[ROOT_POSITION].copy_from_slice(&[dx, p.y as f32, dz]);
        }
    }
    features
}

/// Check that `features` can be decoded on `skeleton` (shape and finiteness).
pub fn check(features: &Features, skeleton: &Skeleton) -> Result<(), M2mError> {
    if features.dims != DIMS {
        return Err(M2mError::Dims(features.dims));
    }
    if features.joints != skeleton.len() {
        return Err(M2mError::JointCount { features: features.joints, skeleton: skeleton.len() });
    }
    if let Some((frame, joint, dim)) = features.first_non_finite() {
        let value = features.at(frame, joint)[dim];
        return Err(M2mError::NonFinite { frame, joint, name: skeleton.joints[joint].name.clone(), dim, value });
    }
    Ok(())
}

/// Decode features on `skeleton`: rotations from the 6D values, root position from the summed
/// velocities, every other translation from the skeleton's OFFSETs, frame time from the
/// skeleton.
pub fn decode(features: &Features, skeleton: &Skeleton) -> Result<Motion, M2mError> {
    check(features, skeleton)?;
    let (frames, joints) = (features.frames, features.joints);
    let mut rotations = Vec::with_capacity(frames * joints);
    let mut translations = Vec::with_capacity(frames * joints);
    let (mut x, mut z) = (0.0f64, 0.0f64);
    for f in 0..frames {
        for (j, joint) in skeleton.joints.iter().enumerate() {
            let row = features.at(f, j);
            let six: [f64; 6] = std::array::from_fn(|k| row[k] as f64);
            rotations.push(rotation_from_6d(six));
            if j == 0 {
                x += row[ROOT_POSITION.start] as f64;
                z += row[ROOT_POSITION.start + 2] as f64;
                translations.push(DVec3::new(x, row[ROOT_POSITION.start + 1] as f64, z));
            } else {
                translations.push(joint.offset);
            }
        }
    }
    Ok(Motion { frames, joints, frame_time: skeleton.frame_time, rotations, translations })
}

/// The largest distance between a non-root joint's local translation in `motion` and its
/// skeleton OFFSET, with the joint and frame where it occurs: what m2m drops. `None` when
/// every bone translation is its OFFSET (within `tolerance`).
pub fn max_bone_translation_change(motion: &Motion, skeleton: &Skeleton, tolerance: f64) -> Option<BoneTranslationChange> {
    let mut worst: Option<BoneTranslationChange> = None;
    let mut joints_changed = vec![false; motion.joints];
    for f in 0..motion.frames {
        for (j, joint) in skeleton.joints.iter().enumerate().skip(1).take(motion.joints.saturating_sub(1)) {
            let d = motion.translations[f * motion.joints + j].distance(joint.offset);
            if d > tolerance {
                joints_changed[j] = true;
                if worst.as_ref().is_none_or(|w| d > w.distance) {
                    worst = Some(BoneTranslationChange { joint: j, frame: f, distance: d, joints: 0 });
                }
            }
        }
    }
    worst.map(|w| BoneTranslationChange { joints: joints_changed.iter().filter(|&&c| c).count(), ..w })
}

/// See `max_bone_translation_change`.
#[derive(Clone, Debug, PartialEq)]
pub struct BoneTranslationChange {
    /// Joint and frame of the largest change.
    pub joint: usize,
    pub frame: usize,
    /// Largest distance between a local translation and its OFFSET (BVH units).
    pub distance: f64,
    /// How many joints differ from their OFFSET at some frame.
    pub joints: usize,
}

/// The reference's flat per-frame vector (6J rotation values, then root dx, y, dz) of frame
/// `f`: for comparing with the reference implementation's tensors.
pub fn reference_vector(features: &Features, f: usize) -> Vec<f32> {
    let mut v = Vec::with_capacity(features.joints * 6 + 3);
    for j in 0..features.joints {
        v.extend_from_slice(&features.at(f, j)[ROTATION]);
    }
    if features.joints > 0 {
        v.extend_from_slice(&features.at(f, 0)[ROOT_POSITION]);
    }
    v
}

/// Rotation matrix of a 6D value (rows), for tests and diagnostics.
pub fn matrix_from_6d(v: [f64; 6]) -> DMat3 {
    DMat3::from_quat(rotation_from_6d(v))
}

/// What m2m loses on this clip, as a warning (None when nothing): joints whose position
/// channels move them off their OFFSET, which m2m does not carry.
pub fn loss_warning(motion: &Motion, skeleton: &Skeleton) -> Option<String> {
    // Far below the 1e-4-of-size round-trip promise, far above text rounding.
    let tolerance = 1e-5 * skeleton.rest_extent().max(f64::MIN_POSITIVE);
    let c = max_bone_translation_change(motion, skeleton, tolerance)?;
    Some(format!(
        "{} joint(s) translate away from their OFFSET (up to {:.6} units: '{}' at frame {}); m2m carries only the root's translation, so decoding puts them on their OFFSETs",
        c.joints, c.distance, skeleton.joints[c.joint].name, c.frame
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh;
    use crate::motion::rotation::compose;

    #[test]
    fn six_d_is_the_first_two_rows() {
        let q = compose(&[2, 0, 1], &[30.0, -40.0, 75.0]);
        let m = DMat3::from_quat(q);
        let six = rotation_to_6d(q);
        let rows = [m.row(0), m.row(1)];
        let want = [rows[0].x, rows[0].y, rows[0].z, rows[1].x, rows[1].y, rows[1].z];
        for k in 0..6 {
            assert!((six[k] - want[k]).abs() < 1e-12, "{six:?} vs {want:?}");
        }
        assert!(rotation_from_6d(six).dot(q).abs() > 1.0 - 1e-12);
        // A 90-degree turn about z: R00 = cos, R01 = -sin.
        let six = rotation_to_6d(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2));
        assert!((six[1] + 1.0).abs() < 1e-12 && six[0].abs() < 1e-12, "{six:?}");
        assert!((matrix_from_6d(six).row(0) - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12);
    }

    const TINY: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 1 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\tJOINT Leg\n\t{\n\t\tOFFSET 0.1 -0.5 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 -0.5 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 3\nFrame Time: 0.05\n5 1 -2 0 0 10 10 0 0\n5.5 1.1 -2 0 0 20 -10 0 0\n6.25 1.2 -1.5 45 0 30 0 0 5\n";

    #[test]
    fn layout_and_round_trip() {
        let parsed = bvh::parse(TINY, "tiny").unwrap();
        let skeleton = Skeleton::from_bvh(&parsed);
        let motion = Motion::from_bvh(&parsed, &skeleton);
        let f = encode(&motion);
        assert_eq!(f.shape(), [3, 2, DIMS]);
        assert_eq!(&f.at(0, 0)[ROOT_POSITION], &[5.0, 1.0, -2.0]);
        assert_eq!(&f.at(1, 0)[ROOT_POSITION], &[0.5, 1.1, 0.0]);
        assert_eq!(&f.at(2, 0)[ROOT_POSITION], &[0.75, 1.2, 0.5]);
        assert_eq!(&f.at(1, 1)[ROOT_POSITION], &[0.0, 0.0, 0.0]);
        assert_eq!(reference_vector(&f, 1).len(), 2 * 6 + 3);
        let back = decode(&f, &skeleton).unwrap();
        assert_eq!(back.frame_time, 0.05);
        let (a, b) = (motion.forward_kinematics(&skeleton), back.forward_kinematics(&skeleton));
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert!(p.distance(*q) < 1e-5, "{p} vs {q}");
        }
        assert_eq!(max_bone_translation_change(&motion, &skeleton, 1e-9), None);
    }

    #[test]
    fn float32_rounding_does_not_drift() {
        // A long clip far from the origin: naive f32 differences would accumulate error.
        let frames = 20_000;
        let skeleton = Skeleton::from_bvh(&bvh::parse(TINY, "tiny").unwrap());
        let motion = Motion {
            frames,
            joints: 2,
            frame_time: 0.01,
            rotations: vec![DQuat::IDENTITY; frames * 2],
            translations: (0..frames)
                .flat_map(|f| [DVec3::new(1234.5 + f as f64 * 0.0137, 90.0, -777.0 + (f as f64 * 0.01).sin()), DVec3::new(0.1, -0.5, 0.0)])
                .collect(),
        };
        let back = decode(&encode(&motion), &skeleton).unwrap();
        for f in 0..frames {
            let (p, q) = (motion.translations[f * 2], back.translations[f * 2]);
            assert!((p - q).abs().max_element() < 1e-3 * 2.0f64.powi(-10), "frame {f}: {p} vs {q}");
        }
    }

    #[test]
    fn decode_refuses_bad_features() {
        let skeleton = Skeleton::from_bvh(&bvh::parse(TINY, "tiny").unwrap());
        assert_eq!(decode(&Features::zeros(2, 2, 13), &skeleton).unwrap_err(), M2mError::Dims(13));
        assert_eq!(decode(&Features::zeros(2, 3, DIMS), &skeleton).unwrap_err(), M2mError::JointCount { features: 3, skeleton: 2 });
        let mut f = Features::zeros(2, 2, DIMS);
        f.at_mut(1, 1)[4] = f32::NAN;
        let e = decode(&f, &skeleton).unwrap_err().to_string();
        assert_eq!(e, "non-finite value NaN at frame 1, joint 1 'Leg', dim 4");
        // All-zero (degenerate) rotations still decode to rotations.
        let m = decode(&Features::zeros(2, 2, DIMS), &skeleton).unwrap();
        assert!(m.rotations.iter().all(|q| q.is_normalized()));
    }
}
