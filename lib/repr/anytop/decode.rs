//! AnyTop features -> positions -> Motion on the original skeleton (docs/reference/anytop.md
//! §1.10).

use super::rig::Prepared;
use super::{get3, get_6d, yaw_to_front, AnyTopError, AnyTopRig, IkOptions, Placement, DIMS_POSITION, DIMS_ROTATION, DIMS_VELOCITY, FEATURE_DIMS};
use crate::motion::rotation::from_6d;
use crate::motion::Motion;
use crate::repr::Features;
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};

/// Positions recovered from features, in aligned space (scaled, clip turned to +Z at frame 0).
pub(super) struct Recovered {
    /// The turn from BVH space to aligned space (from the placement).
    pub q: DQuat,
    /// Aligned world position of every joint, `[frame * joints + joint]`.
    pub targets: Vec<DVec3>,
    /// How far each target may be off because features are float32 (see `RIC_PRECISION`).
    pub slack: Vec<f64>,
}

/// Relative precision of a float32 RIC position (a few units in the last place, plus the
/// float32 rotations it is turned by): a joint with position channels whose target is this
/// close to where its rest translation puts it takes the rest translation, which is exact,
/// instead of the rounded target. Without it, a body far from its root (Bandai Namco's static
/// `joint_Root`) would re-encode with its facing off by the rounding of its face joints.
const RIC_PRECISION: f64 = 1.5e-7;

impl AnyTopRig {
    /// World positions (BVH units and axes, `[frame * joints + joint]`) that the features'
    /// positions describe (§1.10 steps 2–3), put in place by `placement`.
    pub fn recover_positions(&self, skeleton: &Skeleton, features: &Features, placement: &Placement) -> Result<Vec<DVec3>, AnyTopError> {
        let prep = self.prepare(skeleton)?;
        let rec = recover(&prep, features, placement)?;
        let q_inv = rec.q.inverse();
        Ok(rec.targets.iter().map(|&p| prep.unalign(q_inv, p)).collect())
    }

    /// Decode from the rotations: exact for encoded data. Joints with position channels take
    /// their translation from the positions; leaves (whose rotation is not represented) get
    /// their rest rotation. Frame time: the skeleton's.
    pub fn decode(&self, skeleton: &Skeleton, features: &Features, placement: &Placement) -> Result<Motion, AnyTopError> {
        let prep = self.prepare(skeleton)?;
        let rec = recover(&prep, features, placement)?;
        let n = skeleton.len();
        let local: Vec<DQuat> = (0..features.frames * n).map(|k| slot_rotation(&prep, features, k / n, k % n)).collect();
        Ok(rebuild(&prep, skeleton, rec.q, &local, &rec))
    }

    /// Decode from the positions: rotations fitted to the features' positions with the natural
    /// rest pose by inverse kinematics (`ik.rs`), for generated features whose positions and
    /// rotations disagree. Joints with position channels land exactly on their positions.
    pub fn decode_ik(&self, skeleton: &Skeleton, features: &Features, placement: &Placement, options: &IkOptions) -> Result<Motion, AnyTopError> {
        let prep = self.prepare(skeleton)?;
        let rec = recover(&prep, features, placement)?;
        let n = skeleton.len();
        let mut local = vec![DQuat::IDENTITY; features.frames * n];
        let mut scratch = super::ik::Scratch::new(n);
        for (t, frame) in local.chunks_exact_mut(n.max(1)).enumerate() {
            super::ik::solve_frame(&prep, &rec.targets[t * n..(t + 1) * n], options, &mut scratch, frame);
        }
        Ok(rebuild(&prep, skeleton, rec.q, &local, &rec))
    }
}

/// A non-leaf joint's re-expressed rotation: the mean of the 6D in its children's slots.
fn slot_rotation(prep: &Prepared, features: &Features, t: usize, j: usize) -> DQuat {
    let kids = &prep.children[j];
    if kids.is_empty() {
        return DQuat::IDENTITY;
    }
    let mut sum = [0.0f64; 6];
    for &c in kids {
        for (s, v) in sum.iter_mut().zip(get_6d(&features.at(t, c)[DIMS_ROTATION])) {
            *s += v;
        }
    }
    let k = kids.len() as f64;
    from_6d(sum.map(|s| s / k))
}

/// The heading encoded in a root 6D, as the yaw it is (the encoder writes pure yaws; anything
/// else is projected onto one).
pub(super) fn root_yaw(v: [f64; 6]) -> DQuat {
    let a = DVec3::new(v[0], v[1], v[2]);
    let b = DVec3::new(v[3], v[4], v[5]);
    // R = R_y(θ) has third column (sin θ, 0, cos θ) and first column (cos θ, 0, −sin θ).
    if let Some(z) = a.cross(b).try_normalize().filter(|z| z.x.abs() + z.z.abs() > 1e-9) {
        return DQuat::from_rotation_y(z.x.atan2(z.z));
    }
    if a.x.abs() + a.z.abs() > 1e-12 {
        return DQuat::from_rotation_y((-a.z).atan2(a.x));
    }
    DQuat::IDENTITY
}

fn check_features(prep: &Prepared, features: &Features) -> Result<(), AnyTopError> {
    if features.dims != FEATURE_DIMS {
        return Err(AnyTopError::Dims(features.dims));
    }
    if features.joints != prep.parents.len() {
        return Err(AnyTopError::JointCount { what: "the features", got: features.joints, expected: prep.parents.len() });
    }
    if let Some((frame, joint, dim)) = features.first_non_finite() {
        return Err(AnyTopError::NonFinite { frame, joint, dim });
    }
    Ok(())
}

/// §1.10 steps 2–3: root height from dim 1, root x/z by summing displacements turned back by
/// each frame's facing (starting at the placement), joints by turning RIC positions back.
pub(super) fn recover(prep: &Prepared, features: &Features, placement: &Placement) -> Result<Recovered, AnyTopError> {
    check_features(prep, features)?;
    let n = features.joints;
    let q = yaw_to_front(placement.heading);
    let start = prep.align(q, DVec3::new(placement.root_xz[0], 0.0, placement.root_xz[1]));
    let mut root_xz = DVec3::new(start.x, 0.0, start.z);
    let mut targets = Vec::with_capacity(features.frames * n);
    let mut slack = Vec::with_capacity(features.frames * n);
    for t in 0..features.frames {
        let r_inv = root_yaw(get_6d(&features.at(t, 0)[DIMS_ROTATION])).inverse();
        if t > 0 {
            let v = get3(&features.at(t - 1, 0)[DIMS_VELOCITY]);
            root_xz += r_inv * DVec3::new(v.x, 0.0, v.z);
            root_xz.y = 0.0;
        }
        for j in 0..n {
            let ric = get3(&features.at(t, j)[DIMS_POSITION]);
            targets.push(if j == 0 { DVec3::new(root_xz.x, ric.y, root_xz.z) } else { r_inv * ric + root_xz });
            slack.push(RIC_PRECISION * (1.0 + ric.length()));
        }
    }
    Ok(Recovered { q, targets, slack })
}

/// The output Motion: re-expressed rotations N (aligned space, `[frame * joints + joint]`)
/// back to the skeleton's local rotations, D_0 = q⁻¹·N_0·T_0 and D_j = C_p⁻¹·N_j·C_j;
/// translations from the positions for joints with position channels, OFFSETs otherwise.
///
/// A joint with position channels whose targets agree with its rest translation to float32
/// precision in every frame takes the rest translation, which is exact (decided per joint for
/// the whole clip, so velocities stay smooth).
pub(super) fn rebuild(prep: &Prepared, skeleton: &Skeleton, q: DQuat, local: &[DQuat], rec: &Recovered) -> Motion {
    let n = prep.parents.len();
    let frames = local.len() / n.max(1);
    let q_inv = q.inverse();
    let at = |t: usize, j: usize| t * n + j;
    let mut rotations = vec![DQuat::IDENTITY; frames * n];
    let mut translations = vec![DVec3::ZERO; frames * n];
    let mut world = vec![DQuat::IDENTITY; frames * n];
    let mut positions = vec![DVec3::ZERO; frames * n];
    for j in 0..n {
        let Some(p) = prep.parents[j] else {
            for t in 0..frames {
                let k = at(t, 0);
                rotations[k] = (q_inv * local[k] * prep.rest_world[0]).normalize();
                world[k] = (local[k] * prep.rest_world[0]).normalize();
                positions[k] = rec.targets[k];
                translations[k] = if prep.has_position[0] { prep.unalign(q_inv, rec.targets[k]) } else { prep.offsets[0] };
            }
            continue;
        };
        let to_parent = prep.rest_world[p].inverse();
        for t in 0..frames {
            let k = at(t, j);
            rotations[k] = (to_parent * local[k] * prep.rest_world[j]).normalize();
            world[k] = world[at(t, p)] * rotations[k];
            positions[k] = positions[at(t, p)] + prep.scale * (world[at(t, p)] * prep.rest_translations[j]);
            translations[k] = prep.rest_translations[j];
        }
        let exact = |t: usize| positions[at(t, j)].distance(rec.targets[at(t, j)]) <= rec.slack[at(t, j)] + rec.slack[at(t, p)];
        if prep.has_position[j] && !(0..frames).all(exact) {
            for t in 0..frames {
                let (k, kp) = (at(t, j), at(t, p));
                positions[k] = rec.targets[k];
                translations[k] = world[kp].inverse() * (rec.targets[k] - positions[kp]) / prep.scale;
            }
        }
    }
    Motion { frames, joints: n, frame_time: skeleton.frame_time, rotations, translations }
}
