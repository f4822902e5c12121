//! Clips and skeletons made ready for the latent model, and latents to and from NPY data.
//!
//! `mo-encode --latent`, `--decode-latent` and `mo-retarget --method latent` do the same steps:
//! pick the rig a skeleton's motion is read with (the model's training rig when it knows the
//! skeleton, else the clip's or document's own), build the skeleton's graph, encode, decode.
//! They are written here once, so that a library caller gets exactly what the tools do.

use super::checkpoint::{self, FrozenAutoencoder};
use super::infer::{Latents, PreparedSkeleton};
use super::SataError;
use crate::diffusion::checkpoint::CheckpointError;
use crate::document::AnyTopSection;
use crate::embed::NameTable;
use crate::input::{InputError, SkeletonFile};
use crate::io::npy::{self, NpyArray, NpyError};
use crate::motion::{Clip, Motion};
use crate::repr::anytop::{AnyTopError, RigError};
use crate::skeleton::Skeleton;
use candle_core::Device;
use std::path::Path;

/// Why a clip, a skeleton or latents could not be used; messages name the file.
#[derive(Debug, thiserror::Error)]
pub enum LatentError {
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error(transparent)]
    Input(#[from] InputError),
    #[error(transparent)]
    Npy(#[from] NpyError),
    #[error(transparent)]
    Read(#[from] crate::io::ReadError),
    #[error(transparent)]
    Clip(#[from] crate::motion::ClipError),
    #[error(transparent)]
    Rig(#[from] RigError),
    #[error("{name}: cannot encode")]
    Encode {
        name: String,
        #[source]
        source: AnyTopError,
    },
    /// The model failed on the named clip or step.
    #[error("{what}")]
    Model {
        what: String,
        #[source]
        source: SataError,
    },
    #[error("the built-in joint-name table")]
    Names(#[source] crate::embed::EmbedError),
    #[error("{0}")]
    Invalid(String),
}

/// The model in `dir`, or the built-in latent model.
pub fn frozen_or_default(dir: Option<&Path>, device: &Device) -> Result<FrozenAutoencoder, CheckpointError> {
    match dir {
        Some(dir) => checkpoint::frozen(dir, device),
        None => checkpoint::frozen_default(device),
    }
}

/// The rig to read or write `skeleton`'s motion with, and the skeleton it fits: the model's
/// training rig when it knows the skeleton (`sata::rigs`: the rest pose its rotations are
/// measured from, on the offsets it trained with), else `own` (the clip's or document's).
fn rig_for(
    model: &FrozenAutoencoder,
    skeleton: &Skeleton,
    own: impl FnOnce() -> Result<AnyTopSection, LatentError>,
) -> Result<(AnyTopSection, Skeleton), LatentError> {
    match model.rigs.find(skeleton) {
        Some(known) => Ok((known.section.clone(), known.fit(skeleton))),
        None => Ok((own()?, skeleton.clone())),
    }
}

fn names() -> Result<&'static NameTable, LatentError> {
    NameTable::builtin().map_err(LatentError::Names)
}

/// A clip ready for encoding: skeleton, motion and its graph on its AnyTop record (the model's
/// rig for a trained skeleton, else one on the clip's first frames, as `mo-encode` builds for a
/// lone clip).
pub struct SourceClip {
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
    pub prepared: PreparedSkeleton,
}

impl SourceClip {
    /// A motion file read for encoding, glTF as `gltf` says (an NPY is refused: it holds
    /// features, not a clip).
    pub fn read(path: &Path, gltf: &crate::gltf::ReadOptions, model: &FrozenAutoencoder, device: &Device) -> Result<SourceClip, LatentError> {
        let (name, bytes) = crate::io::read_named(path)?;
        if bytes.starts_with(b"\x93NUMPY") {
            return Err(LatentError::Invalid(format!("{name}: expected a BVH clip to encode, found an NPY file (decode features first: mo-encode --decode)")));
        }
        SourceClip::new(Clip::from_bytes(&bytes, &name, path, gltf)?, model, device)
    }

    pub fn new(clip: Clip, model: &FrozenAutoencoder, device: &Device) -> Result<SourceClip, LatentError> {
        let Clip { name, skeleton, motion } = clip;
        if motion.frames < 2 {
            return Err(LatentError::Invalid(format!(
                "{name}: {} frame(s); a clip needs at least 2 frames to encode (velocities need a next frame)",
                motion.frames
            )));
        }
        let own = || AnyTopSection::of_clip(&skeleton, &motion, &name).map_err(|source| LatentError::from(RigError { name: name.clone(), source }));
        let (section, skeleton) = rig_for(model, &skeleton, own)?;
        let prepared = PreparedSkeleton::new(&skeleton, section, names()?, device).map_err(|source| LatentError::Model { what: name.clone(), source })?;
        Ok(SourceClip { name, skeleton, motion, prepared })
    }

    /// Per-frame latents (`[frames - 1, latent]`: AnyTop's features need a next frame).
    pub fn encode(&self, model: &FrozenAutoencoder, device: &Device) -> Result<Latents, LatentError> {
        let rig = &self.prepared.section.rig;
        let encoded = rig.encode(&self.skeleton, &self.motion).map_err(|source| LatentError::Encode { name: self.name.clone(), source })?;
        if let Some((f, j, d)) = encoded.features.first_non_finite() {
            return Err(LatentError::Invalid(format!("{}: non-finite feature at frame {f}, joint {j}, dim {d}", self.name)));
        }
        model.encode_features(&encoded.features, &self.prepared.graph, device).map_err(|source| LatentError::Model { what: self.name.clone(), source })
    }
}

/// The skeleton to decode onto (a skeleton file) with its rig (the model's for a trained
/// skeleton, else the document's or the motion file's first frame) and graph.
pub struct Target {
    pub file: SkeletonFile,
    /// `file`'s skeleton as the rig reads it (`rig_for`); the output keeps `file`'s offsets.
    pub fitted: Skeleton,
    pub prepared: PreparedSkeleton,
}

impl Target {
    pub fn new(file: SkeletonFile, model: &FrozenAutoencoder, device: &Device) -> Result<Target, LatentError> {
        let (section, fitted) = rig_for(model, &file.skeleton, || Ok(file.record()?))?;
        let prepared = PreparedSkeleton::new(&fitted, section, names()?, device).map_err(|source| LatentError::Model { what: file.name.clone(), source })?;
        Ok(Target { file, fitted, prepared })
    }

    /// Latents decoded onto this skeleton, `frame_time` seconds per frame.
    pub fn decode(&self, model: &FrozenAutoencoder, latents: &Latents, frame_time: f64, device: &Device) -> Result<Motion, LatentError> {
        model
            .decode_motion(latents, &self.fitted, &self.prepared, frame_time, device)
            .map_err(|source| LatentError::Model { what: format!("decoding onto {}", self.file.name), source })
    }
}

/// Latents `[frames, latent]` from an NPY array read from `name`.
pub fn latents_of(array: NpyArray, name: &str) -> Result<Latents, LatentError> {
    let shape = array.shape.clone();
    if shape.len() != 2 || shape[0] == 0 || shape[1] == 0 {
        return Err(LatentError::Invalid(format!("{name}: expected latents [frames, dims] (from mo-encode --latent), found shape {shape:?}")));
    }
    let data = array.data;
    if let Some(k) = data.iter().position(|v| !v.is_finite()) {
        return Err(LatentError::Invalid(format!("{name}: non-finite latent at frame {}, dim {}", k / shape[1], k % shape[1])));
    }
    Ok(Latents { frames: shape[0], dims: shape[1], data })
}

/// Latents `[frames, latent]` from an NPY file (`-` = stdin).
pub fn read_latents(path: &Path) -> Result<Latents, LatentError> {
    let (name, bytes) = crate::io::read_named(path)?;
    latents_of(npy::from_bytes(&bytes, &name)?, &name)
}

/// Latents as NPY bytes, `[frames, latent]` float32.
pub fn latents_npy(latents: &Latents) -> std::io::Result<Vec<u8>> {
    npy::to_bytes(&[latents.frames, latents.dims], &latents.data)
}
