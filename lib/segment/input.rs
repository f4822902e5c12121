//! A motion to segment, as AnyTop features, and the frame features segmentation runs on.
//!
//! `mo-segment` and the segmentation bench share these steps (features from a clip or from an
//! NPY, raw or DIFT frame features, labels stretched back to every motion frame), so they live
//! here rather than in the tool.

use super::{SegmentError, SegmentOptions, Segmentation};
use crate::diffusion::checkpoint::FrozenDenoiser;
use crate::dift::{self, DiftError, DiftOptions};
use crate::document::AnyTopSection;
use crate::input::{InputError, SkeletonFile};
use crate::motion::{Clip, Motion};
use crate::repr::anytop::{RigError, FEATURE_DIMS};
use crate::repr::batch::split_samples;
use crate::repr::Features as ReprFeatures;
use crate::skeleton::Skeleton;

/// Why a motion could not be prepared or segmented; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum SegmentInputError {
    #[error(transparent)]
    Rig(#[from] RigError),
    // Boxed: a DIFT error is large, and every result here carries this type.
    #[error(transparent)]
    Dift(Box<DiftError>),
    /// DIFT extraction failed on the named motion.
    #[error("{name}")]
    Within {
        name: String,
        #[source]
        source: Box<DiftError>,
    },
    #[error("{name}: cannot segment")]
    Segment {
        name: String,
        #[source]
        source: SegmentError,
    },
    #[error("{0}")]
    Invalid(String),
    /// The skeleton file given with the motion.
    #[error(transparent)]
    Skeleton(#[from] InputError),
    #[error(transparent)]
    Read(#[from] crate::io::ReadError),
    #[error(transparent)]
    Clip(#[from] crate::motion::ClipError),
    #[error(transparent)]
    Npy(#[from] crate::io::npy::NpyError),
}

/// A motion to segment, as its AnyTop features: what every feature provider gets.
pub struct Input {
    /// File name for messages and the report.
    pub name: String,
    /// Motion frames the labels cover: the BVH's frames, or the features' frames + 1 for an
    /// NPY (AnyTop features of an F-frame clip have F − 1 frames).
    pub frames: usize,
    /// Seconds per frame: the BVH's (or the --skeleton BVH's); 1/30 (AnyTop's rate) otherwise.
    pub frame_time: f64,
    /// `[frames − 1, joints, 13]` AnyTop features in physical units (as `mo-encode` writes them
    /// without --normalise).
    pub anytop: ReprFeatures,
    /// The skeleton and the AnyTop record the features were made with, when known (a BVH
    /// input, or an NPY with --skeleton); a model-based provider needs them.
    pub skeleton: Option<(Skeleton, AnyTopSection)>,
}

impl Input {
    /// A motion with a rig built on its own first two frames: AnyTop's rule for a clip without
    /// a T-pose file, the rig `mo-encode` builds for a single input, so `mo-encode clip.bvh |
    /// mo-segment` and `mo-segment clip.bvh` see the same features.
    pub fn from_motion(name: String, skeleton: Skeleton, motion: Motion) -> Result<Input, SegmentInputError> {
        if motion.frames < 2 {
            return Err(SegmentInputError::Invalid(format!(
                "{name}: {} frame(s); segmenting needs at least 2 (AnyTop features need the next frame)",
                motion.frames
            )));
        }
        let section = AnyTopSection::of_clip(&skeleton, &motion, &name).map_err(|source| SegmentInputError::from(RigError { name: name.clone(), source }))?;
        Input::with_record(name, skeleton, motion, section)
    }

    /// A motion encoded with a given AnyTop record (a skeleton document's).
    pub fn with_record(name: String, skeleton: Skeleton, motion: Motion, section: AnyTopSection) -> Result<Input, SegmentInputError> {
        if motion.frames < 2 {
            return Err(SegmentInputError::Invalid(format!(
                "{name}: {} frame(s); segmenting needs at least 2 (AnyTop features need the next frame)",
                motion.frames
            )));
        }
        let encoded = section.rig.encode(&skeleton, &motion).map_err(|e| SegmentInputError::Invalid(format!("{name}: {e}")))?;
        let frame_time = usable_frame_time(motion.frame_time);
        Ok(Input { name, frames: motion.frames, frame_time, anytop: encoded.features, skeleton: Some((skeleton, section)) })
    }
}

impl Input {
    /// The input of `mo-segment` at `path` (`-` = stdin): a motion file (`from_clip`) or an NPY
    /// of AnyTop features (`from_npy`), with the skeleton file at `skeleton` if one is given.
    pub fn read(path: &std::path::Path, skeleton: Option<&std::path::Path>, gltf: &crate::gltf::ReadOptions) -> Result<Input, SegmentInputError> {
        let (name, bytes) = crate::io::read_named(path)?;
        let skeleton = skeleton.map(|p| SkeletonFile::read(p, gltf)).transpose()?;
        if !crate::io::npy::looks_like_npy(path, &bytes) {
            let clip = Clip::from_bytes(&bytes, &name, path, gltf)?;
            drop(bytes);
            return Input::from_clip(clip, skeleton);
        }
        let array = crate::io::npy::from_bytes(&bytes, &name)?;
        Input::from_npy(name, array, skeleton)
    }

    /// A motion file's clip, encoded with the rig of `skeleton` when one is given (so that the
    /// features are those `mo-encode --skeleton` makes with it), else with its own.
    pub fn from_clip(clip: Clip, skeleton: Option<SkeletonFile>) -> Result<Input, SegmentInputError> {
        let Clip { name, skeleton: own, motion } = clip;
        match skeleton {
            Some(file) => {
                if let Some(diff) = file.skeleton.first_difference(&own) {
                    return Err(SegmentInputError::Invalid(format!("{name} is not on the skeleton of {}: {diff}", file.name)));
                }
                let section = file.record()?;
                Input::with_record(name, own, motion, section)
            }
            None => Input::from_motion(name, own, motion),
        }
    }

    /// One motion's AnyTop features from an NPY (`[frames, joints, 13]`, as `mo-encode` writes
    /// them), on `skeleton` when one is given: its record, and its frame time when it is a
    /// motion file (else AnyTop's 1/30 s).
    pub fn from_npy(name: String, array: crate::io::npy::NpyArray, skeleton: Option<SkeletonFile>) -> Result<Input, SegmentInputError> {
        let (mut samples, batch) = split_samples(array, &name).map_err(SegmentInputError::Invalid)?;
        if batch {
            return Err(SegmentInputError::Invalid(format!(
                "{name}: a batch of {} samples; mo-segment takes one motion (a [frames, joints, 13] array)",
                samples.len()
            )));
        }
        let anytop = samples.remove(0);
        if anytop.dims != FEATURE_DIMS {
            return Err(SegmentInputError::Invalid(format!(
                "{name}: expected AnyTop features with {FEATURE_DIMS} values per joint (mo-encode's default), found {}",
                anytop.dims
            )));
        }
        if anytop.frames == 0 {
            return Err(SegmentInputError::Invalid(format!("{name}: the features have no frames")));
        }
        let (skeleton, frame_time) = match skeleton {
            Some(file) => {
                if anytop.joints != file.skeleton.len() {
                    return Err(SegmentInputError::Invalid(format!(
                        "{name}: the features have {} joints but the skeleton {} has {}",
                        anytop.joints,
                        file.name,
                        file.skeleton.len()
                    )));
                }
                let frame_time = file.motion.as_ref().map_or(1.0 / 30.0, |m| usable_frame_time(m.frame_time));
                let section = file.record()?;
                (Some((file.skeleton, section)), frame_time)
            }
            None => (None, 1.0 / 30.0),
        };
        Ok(Input { name, frames: anytop.frames + 1, frame_time, anytop, skeleton })
    }
}

/// A file's frame time, or AnyTop's 1/30 s when it has none that can be used.
pub fn usable_frame_time(t: f64) -> f64 {
    if t.is_finite() && t > 0.0 {
        t
    } else {
        1.0 / 30.0
    }
}

/// `--features raw`: `segment::raw_frame_features` of the clip's AnyTop features, one row per
/// BVH frame but the last.
pub fn raw_features(input: &Input) -> Vec<Vec<f64>> {
    super::raw_frame_features(&input.anytop)
}

/// `--features dift`: DIFT features averaged over joints, one row per AnyTop feature frame.
pub fn dift_features(model: &FrozenDenoiser, input: &Input, opts: &DiftOptions) -> Result<Vec<Vec<f64>>, SegmentInputError> {
    let Some((skeleton, section)) = &input.skeleton else {
        return Err(SegmentInputError::Invalid(format!(
            "{}: DIFT features need the skeleton: give --skeleton (a skeleton document or BVH) with an NPY input",
            input.name
        )));
    };
    let prepared =
        dift::prepare_encoded(&model.info, skeleton, &section.rest_row, input.anytop.clone(), &input.name).map_err(|e| SegmentInputError::Dift(Box::new(e)))?;
    let schedule = model.info.schedule();
    let f = dift::extract(&model.model, &schedule, &prepared.condition.condition(), &prepared.features, opts, &candle_core::Device::Cpu)
        .map_err(|source| SegmentInputError::Within { name: input.name.clone(), source: Box::new(source) })?;
    Ok(f.per_frame().into_iter().map(|row| row.into_iter().map(f64::from).collect()).collect())
}

/// `--window` seconds as frames at `frame_time` (0 = none).
pub fn window_frames(seconds: f64, frame_time: f64) -> usize {
    if seconds > 0.0 && frame_time > 0.0 {
        (seconds / frame_time).round() as usize
    } else {
        0
    }
}

/// Segment `features` of `input` and return the result in BVH frames (labels extended to every
/// frame of the motion, segments recomputed on them).
pub fn segment_input(input: &Input, features: &[Vec<f64>], options: &SegmentOptions, seed: u64) -> Result<Segmentation, SegmentInputError> {
    if features.is_empty() {
        return Err(SegmentInputError::Invalid(format!("{}: no feature frames to segment", input.name)));
    }
    let mut s = super::segment(features, options, seed).map_err(|source| SegmentInputError::Segment { name: input.name.clone(), source })?;
    s.labels = super::extend_labels(&s.labels, input.frames);
    s.segments = super::segments(&s.labels);
    Ok(s)
}
