//! Evaluation metrics of the three papers (AnyTop, Motion2Motion, SATA) and physical
//! plausibility scores for any motion. Definitions, sources and deviations: `docs/metrics.md`.
//!
//! Everything here works on world-space joint positions ([`WorldClip`]) or per-frame point sets,
//! never on files: `mo-metrics` loads BVH or NPY + skeleton, runs our FK, and hands clips over.
//! Every function returns a defined value or a [`MetricError`]; none panics or returns NaN on
//! finite input, and inputs are checked for non-finite values first.

pub mod checks;
pub mod fid;
pub mod footfall;
pub mod generation;
pub mod geometric;
pub mod kinetic;
pub mod movement;
pub mod physics;
pub mod reconstruction;
pub mod report;
pub mod transfer;

use glam::DVec3;

/// One motion as world positions (y up), with what metrics need to know about its skeleton.
#[derive(Clone, Debug)]
pub struct WorldClip {
    pub frames: usize,
    pub joints: usize,
    /// Frames per second.
    pub fps: f64,
    /// Position of joint `j` at frame `f` at `[f * joints + j]`.
    pub positions: Vec<DVec3>,
    /// Parent of each joint (`None` for roots).
    pub parents: Vec<Option<usize>>,
    /// Joint names (for role lookup and messages).
    pub names: Vec<String>,
    /// Foot joints (`skeleton::roles::feet`).
    pub feet: Vec<usize>,
    /// The skeleton's size in the clip's units (`Skeleton::rest_extent`): thresholds of
    /// contact, skating and penetration are fractions of it, so that a mouse and a dinosaur
    /// are judged alike.
    pub scale: f64,
}

impl WorldClip {
    /// The joints of frame `f`.
    pub fn frame(&self, f: usize) -> &[DVec3] {
        &self.positions[f * self.joints..(f + 1) * self.joints]
    }

    /// Position of joint `j` at frame `f`.
    pub fn at(&self, f: usize, j: usize) -> DVec3 {
        self.positions[f * self.joints + j]
    }

    /// A motion on its skeleton as a clip: our forward kinematics, feet by
    /// `skeleton::roles::feet`, scale `Skeleton::rest_extent`, fps `1 / frame_time` (a zero or
    /// negative frame time gives a non-finite or negative fps, which every metric refuses).
    /// `motion` must be on `skeleton` (as every loader in `cli::load` returns them).
    pub fn from_motion(skeleton: &crate::skeleton::Skeleton, motion: &crate::motion::Motion) -> WorldClip {
        let pose = motion.forward_kinematics(skeleton);
        WorldClip {
            frames: pose.frames,
            joints: pose.joints,
            fps: 1.0 / motion.frame_time,
            positions: pose.positions,
            parents: skeleton.parents(),
            names: skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            feet: crate::skeleton::roles::feet(skeleton).0,
            scale: skeleton.rest_extent(),
        }
    }

    /// The first non-finite coordinate, as (frame, joint).
    pub fn first_non_finite(&self) -> Option<(usize, usize)> {
        self.positions.iter().position(|p| !p.is_finite()).map(|i| (i / self.joints.max(1), i % self.joints.max(1)))
    }
}

/// Why a metric has no value.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MetricError {
    /// Too little data for the definition (e.g. a window longer than the clip, one clip for a
    /// covariance); the message says what was needed.
    #[error("{0}")]
    TooLittle(String),
    /// Inputs that cannot be compared (different joint counts, a binding outside a skeleton).
    #[error("{0}")]
    Mismatch(String),
    /// A NaN or infinity in the input, with where it is.
    #[error("{0}")]
    NonFinite(String),
    /// An option out of its range, named as the tools name it.
    #[error("{0}")]
    BadOption(String),
}
