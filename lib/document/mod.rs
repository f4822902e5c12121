//! The skeleton document: the JSON that `skel-info` prints and every skeleton-aware tool reads.
//!
//! It carries everything a tool needs without the original BVH: the hierarchy (names,
//! parents, offsets, channel layout, End Sites, frame time: enough to write a BVH back), the
//! readable names and roles, AnyTop's topology descriptors and rest-pose measurements. The
//! schema is `docs/skeleton.schema.json`; bump `FORMAT_VERSION` on any incompatible change.
//! Later versions add optional fields (feature statistics, the rest-pose feature row);
//! readers ignore fields they do not know.

pub mod of_file;
mod text;

use crate::bvh::Bvh;
use crate::bvh::Channel;
use crate::motion::Motion;
use crate::repr::anytop::{AnyTopError, AnyTopRig, AnyTopStats, RestSource, RigOptions, FEATURE_DIMS};
use crate::skeleton::names::{self, Side};
use crate::skeleton::roles::{self, FootRule};
use crate::skeleton::{topology, Joint, Skeleton, Stats};
use glam::DVec3;
use serde::{Deserialize, Serialize};

pub const FORMAT: &str = "menagerie.skeleton";
pub const FORMAT_VERSION: u32 = 1;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SkeletonDocument {
    pub format: String,
    pub version: u32,
    /// Where the skeleton came from (a path, `<stdin>`, or a generator name).
    pub source: String,
    pub frame_time: f64,
    pub joint_count: usize,
    pub joints: Vec<JointEntry>,
    pub topology: Topology,
    pub rest_pose: RestPose,
    /// Present when the BVH had frames.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionInfo>,
    /// AnyTop's per-skeleton record (docs/reference/anytop.md §1.7): what `mo-encode` needs to turn
    /// motion into features and back on this skeleton.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anytop: Option<AnyTopSection>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AnyTopSection {
    /// Natural rest pose, scale, ground, facing rule and feet.
    pub rig: AnyTopRig,
    /// P_S: the 13 features of every joint in the natural rest pose, J x 13.
    pub rest_row: Vec<Vec<f32>>,
    /// Normalisation statistics (AnyTop's grouping) of the motion the document came from;
    /// absent when it had fewer than two frames.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stats: Option<AnyTopStats>,
}

impl AnyTopSection {
    /// Rig and P_S from `rest` (its frame 0 is the rest pose, frame 1 gives P_S its velocity),
    /// without statistics.
    pub fn new(skeleton: &Skeleton, rest: &Motion, options: &RigOptions) -> Result<AnyTopSection, AnyTopError> {
        let rig = AnyTopRig::new(skeleton, rest, options)?;
        let row = rig.rest_features(skeleton, rest)?;
        let rest_row = (0..row.joints).map(|j| row.at(0, j).to_vec()).collect();
        Ok(AnyTopSection { rig, rest_row, stats: None })
    }

    /// Whether the record fits `skeleton`: the rig, one rest-row entry of 13 finite numbers per
    /// joint, and the statistics.
    pub fn check(&self, skeleton: &Skeleton) -> Result<(), AnyTopError> {
        self.rig.check(skeleton)?;
        let n = skeleton.len();
        if self.rest_row.len() != n {
            return Err(AnyTopError::JointCount { what: "the rest-pose row (rest_row)", got: self.rest_row.len(), expected: n });
        }
        if let Some(j) = self.rest_row.iter().position(|r| r.len() != FEATURE_DIMS || r.iter().any(|v| !v.is_finite())) {
            return Err(AnyTopError::BadRig(format!("rest_row entry {j} is not {FEATURE_DIMS} finite numbers")));
        }
        if let Some(stats) = &self.stats {
            stats.check(n)?;
        }
        Ok(())
    }

    /// The record of a lone clip: the rig on its own first two frames (AnyTop's rule without a
    /// T-pose file, the rig `mo-encode` builds for a single input), no statistics.
    pub fn of_clip(skeleton: &Skeleton, motion: &Motion, file: &str) -> Result<AnyTopSection, AnyTopError> {
        let options = RigOptions { rest_source: RestSource::FirstClip { file: file.to_string() }, ..RigOptions::default() };
        AnyTopSection::new(skeleton, &motion.first_frames(2), &options)
    }

    /// The record `skel-info` gives a motion file (`name`; its motion may have no frames): the
    /// rest pose is frame 0 of `rest` when given (a file of the same skeleton and its motion),
    /// else of the file itself (named like a T-pose or not: AnyTop's rule), else the OFFSET pose;
    /// statistics over the file's motion.
    pub fn of_file(skeleton: &Skeleton, motion: &Motion, name: &str, rest: Option<(&str, &Motion)>) -> Result<AnyTopSection, AnyTopError> {
        let (rest, source) = match rest {
            Some((file, rest)) => (rest.clone(), RestSource::Explicit { file: file.to_string() }),
            None if motion.frames > 0 => {
                let file = name.to_string();
                let source = if crate::motion::clip::names_tpose(&file) { RestSource::TPose { file } } else { RestSource::FirstClip { file } };
                (motion.first_frames(2), source)
            }
            None => (Motion::rest(skeleton), RestSource::Offsets),
        };
        AnyTopSection::build(skeleton, &rest, source, &[motion])
    }

    /// `new` with default options, plus statistics over `clips` (those with at least two frames).
    pub fn build(skeleton: &Skeleton, rest: &Motion, source: RestSource, clips: &[&Motion]) -> Result<AnyTopSection, AnyTopError> {
        let options = RigOptions { rest_source: source, ..RigOptions::default() };
        let mut section = AnyTopSection::new(skeleton, rest, &options)?;
        let mut features = Vec::new();
        for clip in clips.iter().filter(|m| m.frames >= 2) {
            features.push(section.rig.encode(skeleton, clip)?.features);
        }
        if !features.is_empty() {
            section.stats = Some(AnyTopStats::compute(features.iter())?);
        }
        Ok(section)
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct JointEntry {
    pub name: String,
    pub normalised: String,
    pub parent: Option<usize>,
    pub offset: [f64; 3],
    pub channels: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub end_sites: Vec<[f64; 3]>,
    pub side: Side,
    pub depth: usize,
    pub end_effector: bool,
    pub foot: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Topology {
    pub dmax: usize,
    /// AnyTop relation types, J x J: 0 self, 1 parent, 2 child, 3 sibling, 4 none, 5 end effector.
    pub relations: Vec<Vec<u8>>,
    /// Hop distances capped at dmax, J x J.
    pub distances: Vec<Vec<u8>>,
    pub chains: Vec<Vec<usize>>,
    pub end_effectors: Vec<usize>,
    pub feet: Vec<usize>,
    pub foot_rule: FootRule,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RestPose {
    /// World positions of the joints with identity rotations.
    pub positions: Vec<[f64; 3]>,
    pub bounds_min: [f64; 3],
    pub bounds_max: [f64; 3],
    /// Vertical extent (y), End Sites included.
    pub height: f64,
    /// Largest extent along any axis.
    pub extent: f64,
    pub bone_length: Option<Stats>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct MotionInfo {
    pub frames: usize,
    pub fps: f64,
    pub duration_s: f64,
    /// Vertical extent of frame 0's joint positions (BVH units).
    pub first_frame_height: f64,
}

impl MotionInfo {
    /// Summary of a BVH's motion, or `None` when it has no frames. Only frame 0 is converted
    /// and posed: building the whole motion for a summary cost more than the document itself.
    pub fn of(bvh: &Bvh, skeleton: &Skeleton) -> Option<MotionInfo> {
        if bvh.frames == 0 {
            return None;
        }
        let first = Motion::from_bvh_frames(bvh, skeleton, 0..1).forward_kinematics(skeleton);
        let (lo, hi) = first.positions.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.y), b.max(p.y)));
        Some(MotionInfo { frames: bvh.frames, fps: 1.0 / bvh.frame_time, duration_s: bvh.frames as f64 * bvh.frame_time, first_frame_height: hi - lo })
    }
}

/// Errors reading a document back.
#[derive(Debug, thiserror::Error)]
pub enum DocumentError {
    // The serde message is the source, so `{:#}` prints it once, after this.
    #[error("not a skeleton document")]
    Json(#[from] serde_json::Error),
    #[error("unsupported document: format '{format}' version {version} (expected '{FORMAT}' version {FORMAT_VERSION})")]
    Version { format: String, version: u32 },
    #[error("joint {joint} '{name}': {what}")]
    Joint { joint: usize, name: String, what: String },
    #[error("joint_count is {count} but the document lists {joints} joints")]
    JointCount { count: usize, joints: usize },
    // Transparent and source-less: `{:#}` would print the inner message twice otherwise.
    #[error(transparent)]
    Skeleton(#[from] crate::skeleton::SkeletonError),
    #[error("its AnyTop record does not fit the skeleton: {0}")]
    AnyTop(AnyTopError),
}

impl From<AnyTopError> for DocumentError {
    fn from(e: AnyTopError) -> DocumentError {
        DocumentError::AnyTop(e)
    }
}

impl SkeletonDocument {
    /// The document of a skeleton; `motion` (a summary, see `MotionInfo::of`) when the file had frames.
    pub fn build(skeleton: &Skeleton, motion: Option<MotionInfo>, source: &str, dmax: usize) -> SkeletonDocument {
        let normalised: Vec<String> = skeleton.joints.iter().map(|j| names::readable(&j.name)).collect();
        let sides = roles::sides(skeleton, &normalised);
        let (feet, foot_rule) = roles::feet(skeleton);
        let end_effectors = topology::end_effectors(skeleton);
        let depths = skeleton.depths();
        let rest = skeleton.rest_positions();
        let (lo, hi) = skeleton.rest_bounds();
        let joints = skeleton
            .joints
            .iter()
            .enumerate()
            .map(|(j, joint)| JointEntry {
                name: joint.name.clone(),
                normalised: normalised[j].clone(),
                parent: joint.parent,
                offset: joint.offset.to_array(),
                channels: joint.channels.iter().map(|c| c.name().to_string()).collect(),
                end_sites: joint.end_sites.iter().map(|e| e.to_array()).collect(),
                side: sides[j],
                depth: depths[j],
                end_effector: end_effectors.binary_search(&j).is_ok(),
                foot: feet.binary_search(&j).is_ok(),
            })
            .collect();
        SkeletonDocument {
            format: FORMAT.to_string(),
            version: FORMAT_VERSION,
            source: source.to_string(),
            frame_time: skeleton.frame_time,
            joint_count: skeleton.len(),
            joints,
            topology: Topology {
                dmax,
                relations: topology::relations(skeleton),
                distances: topology::distances(skeleton, dmax),
                chains: topology::kinematic_chains(skeleton),
                end_effectors,
                feet,
                foot_rule,
            },
            rest_pose: RestPose {
                positions: rest.iter().map(|p| p.to_array()).collect(),
                bounds_min: lo.to_array(),
                bounds_max: hi.to_array(),
                height: hi.y - lo.y,
                extent: (hi - lo).max_element(),
                bone_length: Stats::of(&skeleton.bone_lengths()),
            },
            motion,
            anytop: None,
        }
    }

    /// Parse a document and rebuild its skeleton, checking what the algorithms rely on.
    pub fn from_json(text: &str) -> Result<SkeletonDocument, DocumentError> {
        let doc: SkeletonDocument = serde_json::from_str(text)?;
        if doc.format != FORMAT || doc.version != FORMAT_VERSION {
            return Err(DocumentError::Version { format: doc.format, version: doc.version });
        }
        if doc.joint_count != doc.joints.len() {
            return Err(DocumentError::JointCount { count: doc.joint_count, joints: doc.joints.len() });
        }
        let skeleton = doc.skeleton()?;
        if let Some(section) = &doc.anytop {
            section.check(&skeleton)?;
        }
        Ok(doc)
    }

    /// The skeleton this document describes (enough to write the BVH hierarchy back).
    pub fn skeleton(&self) -> Result<Skeleton, DocumentError> {
        let mut joints = Vec::with_capacity(self.joints.len());
        for (j, e) in self.joints.iter().enumerate() {
            let bad = |what: String| DocumentError::Joint { joint: j, name: e.name.clone(), what };
            let mut channels = Vec::with_capacity(e.channels.len());
            for c in &e.channels {
                let channel = Channel::from_name(c).ok_or_else(|| bad(format!("unknown channel '{c}'")))?;
                if channels.contains(&channel) {
                    return Err(bad(format!("channel '{c}' is listed twice")));
                }
                channels.push(channel);
            }
            if e.offset.iter().chain(e.end_sites.iter().flatten()).any(|v| !v.is_finite()) {
                return Err(bad("non-finite offset".into()));
            }
            joints.push(Joint {
                name: e.name.clone(),
                parent: e.parent,
                offset: DVec3::from_array(e.offset),
                channels,
                end_sites: e.end_sites.iter().map(|v| DVec3::from_array(*v)).collect(),
            });
        }
        let skeleton = Skeleton { joints, frame_time: self.frame_time };
        skeleton.validate()?;
        Ok(skeleton)
    }
}
