//! A motion file read whole: its name, skeleton and motion, from BVH or glTF.
//!
//! Every tool and library caller that starts from a file wants the same three things, and the
//! same checks on them (a readable file, a valid skeleton), so they are read here once instead
//! of as "read bytes, parse, build the skeleton, build the motion" in each caller. glTF is read
//! as the BVH it stands for (`parse_motion`), so a glTF input behaves like its BVH everywhere.
//!
//! This sits on top of `bvh` and `gltf` although `gltf` builds on `Motion`: the file door of
//! the motion room, not its data type (docs/ARCHITECTURE.md lists the exception).

use super::Motion;
use crate::bvh::{self, Bvh, BvhError};
use crate::gltf::{self, GltfError, ReadOptions};
use crate::io::{self, npy};
use crate::skeleton::{Skeleton, SkeletonError};
use std::path::Path;

/// Why a motion file could not be read; each message names the file.
#[derive(Debug, thiserror::Error)]
pub enum ClipError {
    #[error("cannot read {name}")]
    Read {
        name: String,
        #[source]
        source: std::io::Error,
    },
    #[error(transparent)]
    Bvh(#[from] BvhError),
    #[error(transparent)]
    Gltf(#[from] GltfError),
    /// The file parsed, but its skeleton breaks a rule (`Skeleton::validate`).
    #[error("{name}")]
    Skeleton {
        name: String,
        #[source]
        source: SkeletonError,
    },
    /// An NPY given where a motion file belongs; `reader` says who refused it.
    #[error("{name}: {reader} reads BVH or glTF files (decode features first: mo-encode --decode)")]
    Features { name: String, reader: String },
}

/// One motion read from a file (or decoded from features), with the name messages use.
#[derive(Clone, Debug)]
pub struct Clip {
    /// The file's name as messages show it (`<stdin>` for `-`; `[i]` for the samples of a batch).
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
}

impl Clip {
    /// Read a BVH or glTF file (`-` = stdin) with glTF's default options.
    pub fn read(path: &Path) -> Result<Clip, ClipError> {
        Clip::read_with(path, &ReadOptions::default())
    }

    /// Read a BVH or glTF file; `options` choose a glTF's animation and sampling.
    pub fn read_with(path: &Path, options: &ReadOptions) -> Result<Clip, ClipError> {
        let name = io::display_name(path);
        let bytes = read_bytes(path, &name)?;
        Clip::from_bytes(&bytes, &name, path, options)
    }

    /// A clip from a file's bytes already read; `path` tells glTF from BVH and where a glTF's
    /// buffers lie.
    pub fn from_bytes(bytes: &[u8], name: &str, path: &Path, options: &ReadOptions) -> Result<Clip, ClipError> {
        let parsed = parse_motion(bytes, name, path, options)?;
        let skeleton = Skeleton::from_bvh(&parsed);
        skeleton.validate().map_err(|source| ClipError::Skeleton { name: name.to_string(), source })?;
        let motion = Motion::from_bvh(&parsed, &skeleton);
        Ok(Clip { name: name.to_string(), skeleton, motion })
    }

    /// `read_with`, refusing NPY feature files with a message naming `reader` (the tool).
    pub fn read_motion_file(path: &Path, options: &ReadOptions, reader: &str) -> Result<Clip, ClipError> {
        let name = io::display_name(path);
        let bytes = read_bytes(path, &name)?;
        if npy::looks_like_npy(path, &bytes) {
            return Err(ClipError::Features { name, reader: reader.to_string() });
        }
        Clip::from_bytes(&bytes, &name, path, options)
    }

    /// Whether the file's name says T-pose (AnyTop's rest clip, `*tpos*` in any case).
    pub fn names_tpose(&self) -> bool {
        names_tpose(&self.name)
    }
}

/// AnyTop's T-pose rule: a clip whose file name (not its directories) contains "tpos", in
/// any case, holds the rest pose.
pub fn names_tpose(path: &str) -> bool {
    let file = path.rsplit(['/', '\\']).next().unwrap_or(path);
    file.to_lowercase().contains("tpos")
}

/// Where a rig's rest pose comes from, by AnyTop's rule (`rest_pose`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RestChoice {
    /// Given explicitly (`--rest-pose FILE`).
    Explicit,
    /// A clip whose file name says T-pose.
    TPose,
    /// The first clip, when none says T-pose.
    FirstClip,
}

/// AnyTop's rest-pose rule over clips of one skeleton: the explicit clip when there is one,
/// else the first clip named like a T-pose, else the first clip. `None` when there are no
/// clips at all (the caller then falls back to the OFFSET pose, `Motion::rest`).
pub fn rest_pose<'a>(explicit: Option<&'a Clip>, clips: &'a [Clip]) -> Option<(&'a Clip, RestChoice)> {
    if let Some(clip) = explicit {
        return Some((clip, RestChoice::Explicit));
    }
    match clips.iter().find(|c| c.names_tpose()) {
        Some(t) => Some((t, RestChoice::TPose)),
        None => clips.first().map(|c| (c, RestChoice::FirstClip)),
    }
}

fn read_bytes(path: &Path, name: &str) -> Result<Vec<u8>, ClipError> {
    io::read_input(path).map_err(|source| ClipError::Read { name: name.to_string(), source })
}

/// Whether `bytes` from `path` are glTF: GLB's magic, a `.gltf`/`.glb` name, or JSON with the
/// `asset` object every glTF has (a glTF piped on stdin).
pub fn is_gltf(path: &Path, bytes: &[u8]) -> bool {
    #[derive(serde::Deserialize)]
    struct Probe {
        asset: Option<serde::de::IgnoredAny>,
    }
    gltf::looks_like_gltf(path, bytes)
        || (bytes.trim_ascii_start().starts_with(b"{") && serde_json::from_slice::<Probe>(bytes).is_ok_and(|p| p.asset.is_some()))
}

/// The skeleton and motion of a glTF file; its buffers are looked for beside `path`.
pub fn read_gltf(bytes: &[u8], name: &str, path: &Path, options: &ReadOptions) -> Result<(Skeleton, Motion), GltfError> {
    let base = if path.as_os_str() == "-" { None } else { Some(path.parent().unwrap_or(Path::new("."))) };
    gltf::read(bytes, name, base, options)
}

/// A motion file as BVH data: BVH parsed as it is, glTF (by name or content) as the BVH it
/// stands for (ZXY rotation channels, positions on the root and on joints that translate).
pub fn parse_motion(bytes: &[u8], name: &str, path: &Path, options: &ReadOptions) -> Result<Bvh, ClipError> {
    if is_gltf(path, bytes) {
        let (skeleton, motion) = read_gltf(bytes, name, path, options)?;
        Ok(motion.to_bvh(&skeleton))
    } else {
        Ok(bvh::parse_bytes(bytes, name)?)
    }
}
