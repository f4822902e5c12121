//! Clips of one skeleton encoded as one batch of feature tensors, with what travels beside them:
//! the AnyTop rig (a skeleton file's record, else AnyTop's rest-pose rule over the clips), the
//! placements the features leave out, the statistics and the normalisation they allow.
//!
//! `decode` is the way back: samples decoded on a skeleton as motion files.
//!
//! `mo-encode` reads files and writes them; everything between is here, so that a library
//! caller who encodes clips gets the rig, the features and the statistics the tool would write,
//! byte for byte. Clips are encoded in parallel (rayon), each sequentially, and collected in
//! order, so the result does not depend on the number of threads.

pub mod decode;

use crate::document::{AnyTopSection, MotionInfo, SkeletonDocument};
use crate::gltf::ReadOptions;
use crate::input::{self, InputError, SkeletonFile};
use crate::io;
use crate::motion::clip::{self, Clip, RestChoice};
use crate::motion::Motion;
use crate::repr::anytop::{AnyTopError, AnyTopStats, NamedOverrides, Placement, RestSource, RigError};
use crate::repr::{batch, m2m, Features};
use crate::skeleton::{topology, Skeleton};
use rayon::prelude::*;
use std::path::Path;

/// Why clips could not be encoded; every message names the clip or the rig.
#[derive(Debug, thiserror::Error)]
pub enum EncodeError {
    #[error(
        "{name}: {frames} frame(s): AnyTop features need at least two frames (frame t's velocity comes from frame t+1, so F frames give F-1 feature frames; a one-frame rest pose goes to --rest-pose)"
    )]
    TooShort { name: String, frames: usize },
    #[error(transparent)]
    Input(#[from] InputError),
    #[error(transparent)]
    Read(#[from] io::ReadError),
    #[error(transparent)]
    Clip(#[from] clip::ClipError),
    #[error(transparent)]
    Rig(#[from] RigError),
    #[error("{name}: cannot encode with the AnyTop rig of {rig}")]
    Encode {
        name: String,
        rig: String,
        #[source]
        source: AnyTopError,
    },
    #[error("computing the statistics")]
    Stats(#[source] AnyTopError),
    #[error("normalising with the statistics of {from}")]
    Normalise {
        from: String,
        #[source]
        source: AnyTopError,
    },
    /// Clips that cannot share one batch, bad rig overrides, non-finite features.
    #[error("{0}")]
    Invalid(String),
}

/// A motion file to encode, parsed but not validated (`frames`: only the first so many, for a
/// rest pose; glTF read with `options`), with the summary its skeleton document carries.
pub fn read_clip(path: &Path, frames: Option<usize>, options: &ReadOptions) -> Result<(Clip, Option<MotionInfo>), EncodeError> {
    let (name, bytes) = io::read_named(path)?;
    let parsed = clip::parse_motion(&bytes, &name, path, options)?;
    drop(bytes);
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh_frames(&parsed, &skeleton, 0..frames.unwrap_or(usize::MAX));
    let info = MotionInfo::of(&parsed, &skeleton);
    Ok((Clip { name, skeleton, motion }, info))
}

/// Every clip at least two frames long, as AnyTop features need.
pub fn check_frames(clips: &[Clip]) -> Result<(), EncodeError> {
    match clips.iter().find(|c| c.motion.frames < 2) {
        Some(clip) => Err(EncodeError::TooShort { name: clip.name.clone(), frames: clip.motion.frames }),
        None => Ok(()),
    }
}

/// Every clip on the first one's skeleton (AnyTop encodes one skeleton per batch).
pub fn same_skeleton(clips: &[Clip]) -> Result<(), EncodeError> {
    if let Some((first, rest)) = clips.split_first() {
        for clip in rest {
            input::same_skeleton(&first.name, &first.skeleton, &clip.name, &clip.skeleton)?;
        }
    }
    Ok(())
}

/// The names of clips, for batch messages.
fn names(clips: &[Clip]) -> Vec<&str> {
    clips.iter().map(|c| c.name.as_str()).collect()
}

/// The features of a batch are finite (a NaN in a BVH would poison every statistic downstream).
pub fn check_finite(clips: &[Clip], features: &[Features]) -> Result<(), EncodeError> {
    batch::check_finite(&names(clips), clips.iter().map(|c| &c.skeleton), features).map_err(EncodeError::Invalid)
}

/// Motion2Motion features of every clip, with the warning of a clip whose animated offsets the
/// representation drops; the features can be stacked into one batch.
pub fn m2m(clips: &[Clip]) -> Result<(Vec<Features>, Vec<Option<String>>), EncodeError> {
    let encoded: Vec<(Features, Option<String>)> = clips.par_iter().map(|c| (m2m::encode(&c.motion), m2m::loss_warning(&c.motion, &c.skeleton))).collect();
    let (features, warnings): (Vec<Features>, Vec<Option<String>>) = encoded.into_iter().unzip();
    batch::check_stackable(&names(clips), &features).map_err(EncodeError::Invalid)?;
    Ok((features, warnings))
}

/// The AnyTop rig of a batch, the skeleton document that carries it, and the name of the file
/// it was measured on.
pub struct Rig {
    pub document: SkeletonDocument,
    pub section: AnyTopSection,
    pub source: String,
}

impl Rig {
    /// `skeleton`'s record when a skeleton file is given (built on `rest_pose` or its own rest
    /// pose when it has none); else one built on AnyTop's rest pose of the clips (`rest_pose`,
    /// else a `*tpos*` clip, else the first), described by a document of the first clip
    /// (`first_info`: its frame time). `overrides` are the rig choices given by joint name.
    pub fn choose(
        clips: &[Clip],
        first_info: Option<MotionInfo>,
        rest_pose: Option<&Clip>,
        skeleton: Option<SkeletonFile>,
        overrides: &NamedOverrides,
        want_stats: bool,
    ) -> Result<Rig, EncodeError> {
        let first = clips.first().ok_or_else(|| EncodeError::Invalid("no clips to encode".into()))?;
        if let Some(file) = skeleton {
            input::same_skeleton(&first.name, &first.skeleton, &file.name, &file.skeleton)?;
            let section = file.record_with(rest_pose, overrides, want_stats)?;
            return Ok(Rig { document: file.document, section, source: file.name });
        }
        let (rest, choice) = clip::rest_pose(rest_pose, clips).ok_or_else(|| EncodeError::Invalid("no clips to encode".into()))?;
        let file = rest.name.clone();
        let source = match choice {
            RestChoice::Explicit => RestSource::Explicit { file },
            RestChoice::TPose => RestSource::TPose { file },
            RestChoice::FirstClip => RestSource::FirstClip { file },
        };
        let options = overrides.resolve(&rest.skeleton, &rest.name, source).map_err(EncodeError::Invalid)?;
        let section = AnyTopSection::new(&rest.skeleton, &rest.motion.first_frames(2), &options)
            .map_err(|source| EncodeError::from(RigError { name: rest.name.clone(), source }))?;
        // The document describes the encoded clips (their frame time), with the rig.
        let document = SkeletonDocument::build(&first.skeleton, first_info, &first.name, topology::DEFAULT_DMAX);
        Ok(Rig { document, section, source: rest.name.clone() })
    }

    /// AnyTop features and placement of every clip on this rig; the features can be stacked.
    pub fn encode(&self, clips: &[Clip]) -> Result<(Vec<Features>, Vec<Placement>), EncodeError> {
        let rig = &self.section.rig;
        let results: Vec<Result<crate::repr::anytop::Encoded, EncodeError>> = clips
            .par_iter()
            .map(|c| rig.encode(&c.skeleton, &c.motion).map_err(|source| EncodeError::Encode { name: c.name.clone(), rig: self.source.clone(), source }))
            .collect();
        let encoded = results.into_iter().collect::<Result<Vec<_>, _>>()?;
        let (features, placements): (Vec<Features>, Vec<Placement>) = encoded.into_iter().map(|e| (e.features, e.placement)).unzip();
        batch::check_stackable(&names(clips), &features).map_err(EncodeError::Invalid)?;
        Ok((features, placements))
    }

    /// The statistics a call asks for: the clips' own when `clip_stats` (`--stats`), or when
    /// `record_stats` (normalising or emitting the document) and the record has none, in which
    /// case the record takes them; with `normalise`, `features` are normalised by the record's
    /// statistics (so that decoding with its document undoes it).
    pub fn statistics(&mut self, features: &mut [Features], clip_stats: bool, record_stats: bool, normalise: bool) -> Result<Statistics, EncodeError> {
        let record_has_stats = self.section.stats.is_some();
        let need_clip_stats = clip_stats || (!record_has_stats && record_stats);
        let clips = if need_clip_stats { Some(AnyTopStats::compute(features.iter()).map_err(EncodeError::Stats)?) } else { None };
        if !record_has_stats {
            self.section.stats = clips.clone();
        }
        let mut normalised_with = None;
        if normalise {
            let stats = self.section.stats.as_ref().ok_or_else(|| EncodeError::Invalid("no statistics to normalise with".into()))?;
            let from = if record_has_stats { self.source.clone() } else { "the given clips".to_string() };
            for f in features.iter_mut() {
                stats.normalise(f).map_err(|source| EncodeError::Normalise { from: from.clone(), source })?;
            }
            normalised_with = Some(from);
        }
        Ok(Statistics { clips, normalised_with })
    }
}

/// What `Rig::statistics` computed and did.
pub struct Statistics {
    /// The clips' own statistics, when asked for or needed.
    pub clips: Option<AnyTopStats>,
    /// Where the statistics the features were normalised with came from, when they were.
    pub normalised_with: Option<String>,
}
