//! The latent model's side of `mo-encode` (`--latent`, `--decode-latent`) and `mo-retarget
//! --method latent`: files in, files out, around `sata::clips`, which does the work.

use crate::io::{self, npy};
use crate::sata::checkpoint::FrozenAutoencoder;
use crate::sata::clips::{self, SourceClip};
use crate::sata::infer::Latents;
use anyhow::bail;
use candle_core::Device;
use std::path::Path;

/// A motion file read for encoding (an NPY is refused: it holds features, not a clip).
pub fn read_source(path: &Path, model: &FrozenAutoencoder, device: &Device) -> anyhow::Result<SourceClip> {
    let (name, bytes) = io::read_named(path)?;
    if bytes.starts_with(b"\x93NUMPY") {
        bail!("{name}: expected a BVH clip to encode, found an NPY file (decode features first: mo-encode --decode)");
    }
    let clip = crate::cli::load::clip_from_bytes(&bytes, &name, path)?;
    Ok(SourceClip::new(clip, model, device)?)
}

/// Latents `[frames, latent]` from an NPY file.
pub fn read_latents(path: &Path) -> anyhow::Result<Latents> {
    let (name, bytes) = io::read_named(path)?;
    Ok(clips::latents_of(npy::from_bytes(&bytes, &name)?, &name)?)
}
