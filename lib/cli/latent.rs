//! The latent model's side of `mo-encode` (`--latent`, `--decode-latent`) and `mo-retarget
//! --method latent`: files in, files out, around `sata::clips`, which does the work.

use crate::cli::load::read_skeleton;
use crate::io::{self, npy};
use crate::motion::write::{motion_file, MotionFormat};
use crate::sata::checkpoint::FrozenAutoencoder;
use crate::sata::clips::{self, SourceClip, Target};
use crate::sata::infer::Latents;
use anyhow::{bail, Context};
use candle_core::Device;
use std::path::Path;

/// `--model DIR`, or the built-in latent model.
pub fn load_model(dir: Option<&Path>, device: &Device) -> anyhow::Result<FrozenAutoencoder> {
    Ok(clips::frozen_or_default(dir, device)?)
}

/// A motion file read for encoding (an NPY is refused: it holds features, not a clip).
pub fn read_source(path: &Path, model: &FrozenAutoencoder, device: &Device) -> anyhow::Result<SourceClip> {
    let (name, bytes) = io::read_named(path)?;
    if bytes.starts_with(b"\x93NUMPY") {
        bail!("{name}: expected a BVH clip to encode, found an NPY file (decode features first: mo-encode --decode)");
    }
    let clip = crate::cli::load::clip_from_bytes(&bytes, &name, path)?;
    Ok(SourceClip::new(clip, model, device)?)
}

/// Per-frame latents of a clip.
pub fn encode(model: &FrozenAutoencoder, clip: &SourceClip, device: &Device) -> anyhow::Result<Latents> {
    Ok(clip.encode(model, device)?)
}

/// The skeleton to decode onto (`--skeleton`/`--to`: a document or a motion file).
pub fn read_target(path: &Path, model: &FrozenAutoencoder, device: &Device) -> anyhow::Result<Target> {
    Ok(Target::new(read_skeleton(path)?, model, device)?)
}

/// Latents `[frames, latent]` from an NPY file.
pub fn read_latents(path: &Path) -> anyhow::Result<Latents> {
    let (name, bytes) = io::read_named(path)?;
    Ok(clips::latents_of(npy::from_bytes(&bytes, &name)?, &name)?)
}

pub fn latents_npy(latents: &Latents) -> anyhow::Result<Vec<u8>> {
    clips::latents_npy(latents).context("building the NPY")
}

/// Decode onto the target, `frame_time` seconds per frame, as the motion file `output` names
/// (BVH, or glTF by its extension; `stdout` says which on stdout).
pub fn decode_file(
    model: &FrozenAutoencoder,
    latents: &Latents,
    target: &Target,
    frame_time: f64,
    device: &Device,
    output: Option<&Path>,
    stdout: MotionFormat,
) -> anyhow::Result<Vec<u8>> {
    let motion = target.decode(model, latents, frame_time, device)?;
    Ok(motion_file(&target.file.skeleton, &motion, output, stdout)?)
}
