//! AnyTop's motion representation: 13 features per joint per frame, exact and invertible.
//!
//! AnyTop (docs/reference/anytop.md §1, paper §3.1) represents a clip of any skeleton as a
//! `[frames, joints, 13]` tensor: every joint is a token. Everything a model learns or a metric
//! measures sees motion through this module, so encoding follows the reference closely, and
//! decoding is exact: `decode(encode(m))` puts every joint back where it was.
//!
//! # The rig: per-skeleton quantities (`AnyTopRig`, §1.3)
//!
//! AnyTop processes a rest clip once per skeleton (a `*tpos*` file, else the first clip; the
//! caller picks it, see `RestSource`) and reuses what it finds for every clip:
//!
//! * `scale_factor` = 0.2092142857… (the mean SMPL bone length) / mean length of the non-root
//!   BVH OFFSETs (End Site OFFSETs included, as the reference loader turns non-zero End Sites
//!   into joints);
//! * the rest frame (frame 0 of the rest clip) turned to face +Z, centred, scaled and grounded:
//!   its local rotations T_j and its bone vectors, the *natural rest pose* (`rest_offsets`,
//!   scaled units; identity rotations with these offsets reproduce the rest frame);
//! * `root_origin_xz` (the rest root's x, z after the facing turn, BVH units) and
//!   `ground_height` (lowest y of any joint or End Site over all frames of the rest clip,
//!   scaled units);
//! * the facing rule and the foot joints (below).
//!
//! # Alignment of a clip (§1.4)
//!
//! p ↦ s·(q·p − (ox, 0, oz)) − (0, g, 0): q turns *this clip's* frame 0 to face +Z, (ox, oz) is
//! the rig's origin, s the scale factor, g the ground height. Features are root-relative and
//! velocity-based, so the origin does not change them; `Placement` records q and the clip's
//! start so decoding can put the clip back where it was.
//!
//! # Facing
//!
//! AnyTop takes a per-species table of face joints [r_hip, l_hip, r_shoulder, l_shoulder]:
//! across = (p[r_hip] − p[l_hip]) + (p[r_shoulder] − p[l_shoulder]), forward = y × across.
//! We find them from the skeleton (`Facing::FaceJoints`, see `rig.rs`): hips where the rear
//! (or only) pair of legs leaves the body, shoulders where the front pair of limbs does (one
//! pair: both). A creature without left/right limbs (snake) faces along its body instead:
//! `Facing::BodyAxis`, forward = horizontal part of p[front] − p[back] (AnyTop used two body
//! joints as "hips" plus an extra −90° turn for the Anaconda). Options override either.
//!
//! # Re-expression against the natural rest pose (§1.5)
//!
//! With D the clip's local rotations (the root's turned by q), T the rest's, C_j the rest's
//! world rotations: N_0 = D_0·T_0⁻¹, N_j = C_p·D_j·T_j⁻¹·C_p⁻¹ (p the parent). Then new world
//! rotation = old world rotation · C_j⁻¹, and rotations mean the same thing on every skeleton:
//! identity is the natural rest pose.
//!
//! # Features (§1.6), frame t = 0 .. F−2 (the last frame only provides velocities)
//!
//! | dims  | joint j ≥ 1                                  | root                                |
//! |-------|----------------------------------------------|-------------------------------------|
//! | 0..3  | r_t·(G_tj − (x, 0, z) of the root): y absolute | (0, root height, 0)               |
//! | 3..9  | 6D of N_parent(j) (the bone parent→j)        | 6D of the facing r_t (a pure yaw)   |
//! | 9..12 | r_{t+1}·(G_{t+1,j} − G_tj)                   | the same: root displacement         |
//! | 12    | contact: foot joint, ‖ΔG‖² ≤ 0.002 and abs(y_{t+1}) ≤ 0.3 | 0 unless the root is a foot |
//!
//! G are aligned world positions, r_t the yaw turning frame t's facing to +Z, 6D = the first
//! two matrix columns. A joint with several children has its rotation in each child's slot.
//! Leaf joints' own rotations are not represented: they move nothing but End Sites, and
//! decoding gives a leaf its rest rotation. `rest_features` is the rest-pose row P_S (§1.7).
//!
//! # Decoding (§1.10)
//!
//! Root height from dim 1, root x/z by summing displacements turned back by r_t, joints by
//! turning RIC positions back. Then either
//! * `decode` (from the rotations): N from the child slots (averaged over children), mapped
//!   back to the original skeleton's local rotations: D_0 = q⁻¹·N_0·T_0, D_j = C_p⁻¹·N_j·C_p·T_j;
//!   exact for encoded data; or
//! * `decode_ik` (from the positions): rotations fitted to the RIC positions with the natural
//!   rest offsets (for generated features, where positions and rotations disagree).
//!
//! Joints with BVH position channels take their bone translation from the RIC positions in both
//! ways, so files that animate bone lengths (Bandai Namco's moving `Hips` under a static
//! `joint_Root`, the Elephant's clavicles) come back exactly. One refinement keeps float32 out
//! of the way: a joint whose RIC positions agree with its rest translation to float32 precision
//! in every frame of the clip takes the rest translation (exact, f64) instead. Without it,
//! a body far from its root (Bandai's static root) re-encodes with its facing off by the
//! rounding of its face joints' positions, amplified by the distance (on a Bandai Namco walk,
//! 1.1e-5 instead of 5e-7).
//! Output is a `Motion` on the original skeleton, ready for `Motion::to_bvh`, at the
//! skeleton's frame time. Generated features carry no placement: `AnyTopRig::rest_placement`
//! puts them where the rest pose stands, facing its way.
//!
//! # Statistics (§1.8)
//!
//! `AnyTopStats`: per-joint mean; std grouped as the reference does since `f2e3465`.
//!
//! # Deviations from the reference (documented on purpose)
//!
//! * Joints are the BVH's ROOT/JOINT entries: End Sites are not tokens and a redundant root is
//!   not merged (§1.2), so J differs from the reference's for some rigs. A static dummy root
//!   (Bandai Namco) stays the root: its features are constant and the body's motion is carried
//!   by the RIC positions of the joint below it.
//! * The rest frame is used as it is: no IK rebuild with the BVH OFFSETs (§1.3 step 3). The
//!   reference's rebuild only approximates the rest pose (150 iterations, threshold 0.01);
//!   ours is exact, including bone translations.
//! * RIC positions and velocities come from the clip's true joint positions (position channels
//!   included); the reference rebuilt clips with fixed offsets, which loses animated bone
//!   translations.
//! * Face joints and (by default) feet are found automatically (`roles::feet`), not from
//!   per-species tables; snakes get `Facing::BodyAxis`. Species hacks are not ported (Dragon's
//!   ground height forced to 0, Anaconda's extra −90° turn): options cover such cases.
//! * Clips are not sliced into 200-frame chunks (§1.4): we keep whole clips at their native
//!   frame rate (§9.7); slicing and cropping are training-data concerns.
//! * A degenerate facing (face joints coinciding, or `across` vertical) keeps the previous
//!   frame's facing (+Z at frame 0) instead of producing NaN.
//! * Decoding projects the root 6D onto a pure yaw (the encoder only writes yaws), and
//!   `decode_ik` fits each joint's rotation to its children by a damped Gauss-Newton
//!   least-squares solve, in index order, starting from the minimal swing out of the natural
//!   rest pose; it stops when converged (see `ik.rs`). The reference instead repeats whole
//!   passes of averaged per-child rotations (log-mean) up to 150 times.
//! * Statistics do not drift (§9.5) and normalisation uses the same epsilon both ways:
//!   x̂ = (x − mean)/(std + ε), x = x̂·(std + ε) + mean, ε = 1e-6.

mod decode;
mod encode;
mod ik;
mod lock;
pub mod named;
pub mod placements;
mod plant;
mod rig;
mod stats;

pub use ik::IkOptions;
pub use lock::lock_feet;
pub use named::NamedOverrides;
pub use plant::plant_feet;
pub use rig::AnyTopRig;
pub use stats::AnyTopStats;

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Features per joint.
pub const FEATURE_DIMS: usize = 13;

/// Mean length of the 21 non-root bones of SMPL's offset table (§1.1): every skeleton is scaled
/// so that its mean bone has this length.
pub const HUMANML_MEAN_BONE_LENGTH: f64 = 0.2092142857142857;

/// A foot is in contact when its height (scaled units) is at most this (§1.1).
pub const FOOT_CONTACT_HEIGHT: f64 = 0.3;

/// ... and its squared per-frame displacement (scaled units²) is at most this (§1.1).
pub const FOOT_CONTACT_SQUARED_DISPLACEMENT: f64 = 0.002;

/// Added to the standard deviation when normalising and denormalising (§1.8).
pub const STD_EPSILON: f32 = 1e-6;

/// Feature dimension ranges.
pub const DIMS_POSITION: std::ops::Range<usize> = 0..3;
pub const DIMS_ROTATION: std::ops::Range<usize> = 3..9;
pub const DIMS_VELOCITY: std::ops::Range<usize> = 9..12;
pub const DIM_CONTACT: usize = 12;

/// AnyTop's T-pose rule lives with the clip files it looks at.
pub use crate::motion::clip::names_tpose;

/// How a clip's facing direction is measured from joint positions.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Facing {
    /// AnyTop's face joints `[r_hip, l_hip, r_shoulder, l_shoulder]`:
    /// forward = y × ((p[r_hip] − p[l_hip]) + (p[r_shoulder] − p[l_shoulder])).
    FaceJoints([usize; 4]),
    /// Forward = horizontal part of p[front] − p[back] (creatures without left/right limbs).
    BodyAxis { front: usize, back: usize },
}

impl Facing {
    /// The joints the rule reads.
    pub fn joints(&self) -> Vec<usize> {
        match self {
            Facing::FaceJoints(j) => j.to_vec(),
            Facing::BodyAxis { front, back } => vec![*front, *back],
        }
    }

    /// Horizontal unit forward direction of a pose, or `None` when the rule is degenerate there.
    pub fn forward(&self, positions: &[DVec3]) -> Option<DVec3> {
        let f = match *self {
            Facing::FaceJoints([rh, lh, rs, ls]) => {
                let across = (positions[rh] - positions[lh]) + (positions[rs] - positions[ls]);
                let across = across.try_normalize()?;
                // y × across, written out so that the y component is exactly zero.
                DVec3::new(across.z, 0.0, -across.x)
            }
            Facing::BodyAxis { front, back } => {
                let d = positions[front] - positions[back];
                DVec3::new(d.x, 0.0, d.z)
            }
        };
        if f.length_squared() < 1e-24 {
            return None;
        }
        f.try_normalize()
    }
}

/// Heading (radians about +y) of a horizontal forward vector: forward = (sin h, 0, cos h).
pub(crate) fn heading_of(forward: DVec3) -> f64 {
    forward.x.atan2(forward.z)
}

/// The pure yaw that turns heading `h` to face +Z.
pub(crate) fn yaw_to_front(heading: f64) -> DQuat {
    DQuat::from_rotation_y(-heading)
}

/// Which clip provided the rest pose (what AnyTop calls the T-pose, §1.3.1).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum RestSource {
    /// A file named like a T-pose (`*tpos*`); AnyTop leaves it out of training.
    TPose { file: String },
    /// The first input clip (AnyTop's fallback when there is no T-pose file).
    FirstClip { file: String },
    /// Given explicitly (e.g. `--rest-pose FILE`).
    Explicit { file: String },
    /// The skeleton's OFFSETs with identity rotations (`Motion::rest`).
    Offsets,
    /// Not recorded by the caller.
    Unrecorded,
}

/// Whether a rig quantity was found automatically or given by the caller.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Provenance {
    Automatic,
    Override,
}

/// Choices for building a rig.
#[derive(Clone, Debug, PartialEq)]
pub struct RigOptions {
    /// `[r_hip, l_hip, r_shoulder, l_shoulder]` instead of the automatic choice.
    pub face_joints: Option<[usize; 4]>,
    /// `[front, back]` for a body-axis facing instead of the automatic choice (ignored when
    /// `face_joints` is given).
    pub body_axis: Option<[usize; 2]>,
    /// Foot joints for contacts instead of `roles::feet`.
    pub feet: Option<Vec<usize>>,
    /// Recorded in the rig (which clip the rest motion came from).
    pub rest_source: RestSource,
}

impl Default for RigOptions {
    fn default() -> Self {
        RigOptions { face_joints: None, body_axis: None, feet: None, rest_source: RestSource::Unrecorded }
    }
}

/// Where a clip stood in BVH space: decoding puts the root's frame-0 x/z here and turns the
/// clip to this heading. `encode` returns the clip's own placement; for generated features
/// `Placement::rest` puts the clip where the rest pose stands, facing its way.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// Radians about +y; the clip's frame-0 forward direction is (sin, 0, cos).
    pub heading: f64,
    /// The root's x and z at frame 0, BVH units.
    pub root_xz: [f64; 2],
}

/// A clip in AnyTop's representation.
#[derive(Clone, Debug, PartialEq)]
pub struct Encoded {
    /// `[frames − 1, joints, 13]`.
    pub features: crate::repr::Features,
    pub placement: Placement,
}

/// A named clip's skeleton that no AnyTop rig could be built for: the one message every
/// reader of clips gives (input, encode, segment, latent and metrics errors wrap it).
#[derive(Debug, thiserror::Error)]
#[error("{name}: cannot build an AnyTop rig")]
pub struct RigError {
    pub name: String,
    #[source]
    pub source: AnyTopError,
}

/// Errors of this module: inputs that do not fit together.
#[derive(Debug, thiserror::Error)]
pub enum AnyTopError {
    #[error("{what} has {got} joints but the skeleton has {expected}")]
    JointCount { what: &'static str, got: usize, expected: usize },
    #[error("features have {0} values per joint; AnyTop features have 13")]
    Dims(usize),
    #[error("the rest motion has no frames")]
    EmptyRest,
    /// A rest-frame position so far out that bones cannot be measured from it in f64.
    #[error("rest frame: joint {joint} '{name}' is placed at {value:e}: too large to measure bones from (more than 1e9 mean bone lengths out)")]
    RestOutOfRange { joint: usize, name: String, value: f64 },
    #[error("the skeleton has no bones (all OFFSETs are zero): no scale factor")]
    NoBones,
    #[error("{what} names joint {joint}, but the skeleton has {joints} joints")]
    JointIndex { what: &'static str, joint: usize, joints: usize },
    #[error("the rig is damaged: {0}")]
    BadRig(String),
    #[error("the statistics are damaged: {0}")]
    BadStats(String),
    #[error("non-finite feature at frame {frame}, joint {joint}, dim {dim}")]
    NonFinite { frame: usize, joint: usize, dim: usize },
    #[error("no frames to compute statistics from")]
    NoFrames,
    #[error(transparent)]
    Skeleton(#[from] crate::skeleton::SkeletonError),
}

/// Write a rotation's 6D (first two matrix columns) into `out[0..6]`.
pub(crate) fn put_6d(out: &mut [f32], q: DQuat) {
    for (o, v) in out.iter_mut().zip(crate::motion::rotation::to_6d(q)) {
        *o = v as f32;
    }
}

pub(crate) fn get_6d(v: &[f32]) -> [f64; 6] {
    [v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64, v[4] as f64, v[5] as f64]
}

pub(crate) fn put3(out: &mut [f32], v: DVec3) {
    out[0] = v.x as f32;
    out[1] = v.y as f32;
    out[2] = v.z as f32;
}

pub(crate) fn get3(v: &[f32]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}
