//! What the tools are given, read as skeletons and motions: motion files (BVH, glTF), skeleton
//! files (a skeleton document, or a BVH or glTF standing for the document `skel-info` prints),
//! NPY feature files decoded on such a skeleton, and directories of them.
//!
//! One door for every reader, so that a file means the same skeleton, rest pose and motion in
//! every tool, and an NPY decodes to the same joint positions (`repr::batch`). It sits on
//! floor 1b: it puts the data types of floor 1a and the skeleton document together.

use crate::bvh::{self, BvhError};
use crate::document::{AnyTopSection, DocumentError, MotionInfo, SkeletonDocument};
use crate::gltf::ReadOptions;
use crate::io::npy::{self, NpyArray, NpyError};
use crate::io::{self};
use crate::motion::clip::{self, Clip, ClipError};
use crate::motion::Motion;
use crate::repr::anytop::{self, AnyTopError, AnyTopStats, NamedOverrides, RestSource, RigError, RigOptions};
use crate::repr::batch::{split_samples, FeatureDecoder, PoseFrom};
use crate::repr::m2m;
use crate::skeleton::{topology, Skeleton, SkeletonError};
use std::path::{Path, PathBuf};

/// Why an input could not be read; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error(transparent)]
    Clip(#[from] ClipError),
    #[error(transparent)]
    Bvh(#[from] BvhError),
    #[error(transparent)]
    Npy(#[from] NpyError),
    /// A file or directory that cannot be read; the message says which and what for.
    #[error("{message}")]
    Io {
        message: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{name}")]
    Document {
        name: String,
        #[source]
        source: DocumentError,
    },
    #[error("{name}")]
    Skeleton {
        name: String,
        #[source]
        source: SkeletonError,
    },
    #[error("{name}: statistics of its motion")]
    Stats {
        name: String,
        #[source]
        source: AnyTopError,
    },
    #[error(transparent)]
    Rig(#[from] RigError),
    /// Input that is not what it should be, said in one sentence.
    #[error("{0}")]
    Invalid(String),
}

fn invalid(message: String) -> InputError {
    InputError::Invalid(message)
}

/// `-` means stdin/stdout.
pub fn is_dash(p: &Path) -> bool {
    p.as_os_str() == "-"
}

/// A skeleton file: a skeleton document, or a BVH or glTF file standing for the document
/// `skel-info` would print for it.
pub struct SkeletonFile {
    pub name: String,
    pub skeleton: Skeleton,
    pub document: SkeletonDocument,
    /// A motion file's motion (its rest frames and statistics); `None` for a document.
    pub motion: Option<Motion>,
    /// A motion file named like a T-pose.
    pub tpose: bool,
}

impl SkeletonFile {
    /// Read a skeleton file, recognised by content; `options` for a glTF one.
    pub fn read(path: &Path, options: &ReadOptions) -> Result<SkeletonFile, InputError> {
        let name = io::display_name(path);
        let bytes = io::read_input(path).map_err(|source| InputError::Io { message: format!("cannot read skeleton {name}"), source })?;
        let body = bytes.strip_prefix(b"\xEF\xBB\xBF".as_slice()).unwrap_or(&bytes).trim_ascii_start();
        let tpose = !is_dash(path) && anytop::names_tpose(&path.to_string_lossy());
        if clip::is_gltf(path, &bytes) {
            let parsed = clip::parse_motion(&bytes, &name, path, options)?;
            let skeleton = Skeleton::from_bvh(&parsed);
            let document = SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), &name, topology::DEFAULT_DMAX);
            let motion = Some(Motion::from_bvh(&parsed, &skeleton));
            Ok(SkeletonFile { tpose, name, skeleton, document, motion })
        } else if body.starts_with(b"{") {
            let text = std::str::from_utf8(body).map_err(|_| invalid(format!("{name}: skeleton document is not UTF-8")))?;
            let document = SkeletonDocument::from_json(text).map_err(|source| InputError::Document { name: name.clone(), source })?;
            let skeleton = document.skeleton().map_err(|source| InputError::Document { name: name.clone(), source })?;
            Ok(SkeletonFile { name, skeleton, document, motion: None, tpose: false })
        } else if body.len() >= 9 && body[..9].eq_ignore_ascii_case(b"HIERARCHY") {
            let parsed = bvh::parse_bytes(&bytes, &name)?;
            let skeleton = Skeleton::from_bvh(&parsed);
            skeleton.validate().map_err(|source| InputError::Skeleton { name: name.clone(), source })?;
            let document = SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), &name, topology::DEFAULT_DMAX);
            let motion = Some(Motion::from_bvh(&parsed, &skeleton));
            Ok(SkeletonFile { tpose, name, skeleton, document, motion })
        } else {
            let start: String = body.iter().take(12).flat_map(|&b| std::ascii::escape_default(b)).map(char::from).collect();
            Err(invalid(format!("{name}: not a skeleton: expected a skeleton document (JSON from skel-info), a BVH or a glTF file, found '{start}'")))
        }
    }

    /// The rest pose a rig is built on when nobody names one (AnyTop's rule, as `skel-info`
    /// applies it): frames 0-1 of the motion file, else the OFFSET pose of a document.
    pub fn own_rest(&self) -> (Motion, RestSource) {
        match &self.motion {
            Some(motion) if motion.frames > 0 => {
                let file = self.name.clone();
                (motion.first_frames(2), if self.tpose { RestSource::TPose { file } } else { RestSource::FirstClip { file } })
            }
            _ => (Motion::rest(&self.skeleton), RestSource::Offsets),
        }
    }

    /// The AnyTop record this skeleton stands for, without override flags: the document's own
    /// record, else one built on `own_rest` with the default options (no statistics).
    pub fn record(&self) -> Result<AnyTopSection, InputError> {
        if let Some(section) = &self.document.anytop {
            return Ok(section.clone());
        }
        let (rest, rest_source) = self.own_rest();
        let options = RigOptions { rest_source, ..RigOptions::default() };
        AnyTopSection::new(&self.skeleton, &rest, &options).map_err(|source| InputError::from(RigError { name: self.name.clone(), source }))
    }
}

impl SkeletonFile {
    /// The AnyTop record this skeleton stands for, the same way when encoding and decoding:
    /// the document's own record (then no override may be given: it fixes the rig); else one
    /// built with the overrides as `skel-info` builds it, on frame 0 of `rest_pose` when given,
    /// else of the motion file, else (a document without motion) on the OFFSET pose. A built
    /// record's statistics come from the file's motion, computed only when `want_stats` (they
    /// cost encoding the whole file).
    pub fn record_with(&self, rest_pose: Option<&Clip>, overrides: &NamedOverrides, want_stats: bool) -> Result<AnyTopSection, InputError> {
        if let Some(section) = &self.document.anytop {
            let flag = if rest_pose.is_some() { Some("--rest-pose") } else { overrides.first_given() };
            if let Some(flag) = flag {
                return Err(invalid(format!(
                    "{flag}: the AnyTop record of {} fixes the rig (rest pose, facing, feet); to build another, give --skeleton a BVH or a document without one (skel-info --no-anytop)",
                    self.name
                )));
            }
            return Ok(section.clone());
        }
        let (rest, source) = match rest_pose {
            Some(clip) => {
                same_skeleton(&self.name, &self.skeleton, &clip.name, &clip.skeleton)?;
                (clip.motion.first_frames(2), RestSource::Explicit { file: clip.name.clone() })
            }
            None => self.own_rest(),
        };
        let options = overrides.resolve(&self.skeleton, &self.name, source).map_err(invalid)?;
        let rig_error = |source| InputError::from(RigError { name: self.name.clone(), source });
        let mut section = AnyTopSection::new(&self.skeleton, &rest, &options).map_err(rig_error)?;
        if let Some(motion) = self.motion.as_ref().filter(|m| want_stats && m.frames >= 2) {
            let stats_error = |source| InputError::Stats { name: self.name.clone(), source };
            let own = section.rig.encode(&self.skeleton, motion).map_err(stats_error)?;
            section.stats = Some(AnyTopStats::compute([&own.features]).map_err(stats_error)?);
        }
        Ok(section)
    }
}

/// AnyTop encodes one skeleton per call: the same joint names and parents.
pub fn same_skeleton(a_name: &str, a: &Skeleton, b_name: &str, b: &Skeleton) -> Result<(), InputError> {
    match a.first_difference(b) {
        Some(why) => {
            Err(invalid(format!("{a_name} and {b_name} have different skeletons ({why}): AnyTop encodes one skeleton per call, so encode them separately")))
        }
        None => Ok(()),
    }
}

/// How `read_motions` reads its inputs.
#[derive(Clone, Copy, Debug)]
pub struct ReadMotions<'a> {
    /// The skeleton NPY features are decoded on (a skeleton file); motion files ignore it.
    pub skeleton: Option<&'a Path>,
    /// AnyTop features: pose from the rotations or the positions.
    pub from: PoseFrom,
    /// glTF inputs: which animation, sampled how.
    pub gltf: &'a ReadOptions,
}

/// Files named by the command line: files as given, directories as the BVH, glTF (`.gltf`,
/// `.glb`) and NPY files directly inside them (sorted by name, so the order never depends on the file system).
pub fn expand_inputs(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, InputError> {
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|source| InputError::Io { message: format!("cannot list {}", input.display()), source })?;
            let mut files: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && p.extension().is_some_and(|x| ["bvh", "npy", "glb", "gltf"].iter().any(|e| x.eq_ignore_ascii_case(e))))
                .collect();
            if files.is_empty() {
                return Err(invalid(format!("{}: the directory holds no .bvh, .glb, .gltf or .npy files", input.display())));
            }
            files.sort();
            out.extend(files);
        } else {
            out.push(input.clone());
        }
    }
    if out.iter().filter(|p| is_dash(p)).count() > 1 {
        return Err(invalid("stdin ('-') can be read only once".to_string()));
    }
    Ok(out)
}

/// Example clips of one skeleton and one frame rate: motion files or directories of them (read
/// in parallel, kept in input order). `reader` names the tool in the message an NPY gets,
/// `what` names the clips in messages ("target clips").
pub fn read_example_clips(inputs: &[PathBuf], options: &ReadOptions, reader: &str, what: &str) -> Result<Vec<Clip>, InputError> {
    use rayon::prelude::*;
    let files = expand_inputs(inputs)?;
    let clips = files.par_iter().map(|p| Clip::read_motion_file(p, options, reader)).collect::<Result<Vec<Clip>, ClipError>>()?;
    let Some(first) = clips.first() else { return Err(invalid(format!("no {what} were given"))) };
    for c in &clips[1..] {
        if let Some(why) = first.skeleton.first_difference(&c.skeleton) {
            return Err(invalid(format!("{} and {} have different skeletons ({why}): all {what} must share one skeleton", first.name, c.name)));
        }
    }
    let ft = first.motion.frame_time;
    if let Some(c) = clips.iter().find(|c| (c.motion.frame_time - ft).abs() > 1e-6 * ft) {
        return Err(invalid(format!(
            "{} runs at {:.3} fps but {} at {:.3} fps: give {what} of one frame rate",
            c.name,
            1.0 / c.motion.frame_time,
            first.name,
            1.0 / ft
        )));
    }
    Ok(clips)
}

/// An error with its causes, as the one-line message prints it (`what: why: deeper why`).
fn full_message(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

/// Read motions from motion files and NPY feature files (recognised by content), in input
/// order. NPY inputs need `options.skeleton`; a batch `[n, frames, joints, dims]` gives n
/// motions. AnyTop features (13 dims) decode with the skeleton's AnyTop record and each clip at
/// the rest placement (features do not say where a clip stood); Motion2Motion features (9
/// dims) decode as `mo-encode --repr m2m --decode` does.
pub fn read_motions(inputs: &[PathBuf], options: &ReadMotions) -> Result<Vec<Clip>, InputError> {
    use rayon::prelude::*;
    let skeleton = std::sync::OnceLock::new();
    let read_one = |path: &PathBuf| -> Result<Vec<Clip>, InputError> {
        let name = io::display_name(path);
        let bytes = io::read_input(path).map_err(|source| InputError::Io { message: format!("cannot read {name}"), source })?;
        if npy::looks_like_npy(path, &bytes) {
            let path =
                options.skeleton.ok_or_else(|| invalid(format!("{name} is an NPY feature file: give --skeleton (a skeleton document or BVH) to decode it")))?;
            // Read once for all NPY inputs; the first failure is every caller's message.
            let file = skeleton.get_or_init(|| SkeletonFile::read(path, options.gltf).map_err(|e| full_message(&e)));
            let file = file.as_ref().map_err(|e| invalid(e.clone()))?;
            let array = npy::from_bytes(&bytes, &name)?;
            drop(bytes);
            decode_npy(array, &name, file, options.from)
        } else {
            Ok(vec![Clip::from_bytes(&bytes, &name, path, options.gltf)?])
        }
    };
    let read: Vec<Result<Vec<Clip>, InputError>> = inputs.par_iter().map(read_one).collect();
    let mut out = Vec::new();
    for clips in read {
        out.extend(clips?);
    }
    Ok(out)
}

/// The samples of one NPY as motions on `file`'s skeleton.
fn decode_npy(array: NpyArray, name: &str, file: &SkeletonFile, from: PoseFrom) -> Result<Vec<Clip>, InputError> {
    let (samples, batch) = split_samples(array, name).map_err(invalid)?;
    let dims = samples[0].dims;
    let decoder = if dims == m2m::DIMS {
        FeatureDecoder::M2m
    } else {
        let section = file.record()?;
        let placements = vec![section.rig.rest_placement(); samples.len()];
        FeatureDecoder::AnyTop { rig: Box::new(section.rig), stats: None, placements, from }
    };
    let label = |i: usize| if batch { format!("{name}[{i}]") } else { name.to_string() };
    let mut out = Vec::with_capacity(samples.len());
    for (i, f) in samples.iter().enumerate() {
        decoder
            .check(f, &file.skeleton)
            .map_err(|(e, hint)| invalid(format!("{}: {e} ({} features, skeleton {}){hint}", label(i), decoder.repr_name(), file.name)))?;
        let motion = decoder.decode(i, f, &file.skeleton).map_err(|e| invalid(format!("{}: {e}", label(i))))?;
        out.push(Clip { name: label(i), skeleton: file.skeleton.clone(), motion });
    }
    Ok(out)
}
