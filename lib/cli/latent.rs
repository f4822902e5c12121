//! The latent model's side of `mo-encode` (`--latent`, `--decode-latent`) and `mo-retarget
//! --method latent`: load the SATA model, encode a clip into per-frame latents, decode latents
//! onto a skeleton.

use crate::cli::load::{motion_file, read_skeleton, MotionFormat};
use crate::input::SkeletonFile;
use crate::document::AnyTopSection;
use crate::embed::NameTable;
use crate::io::{self, npy};
use crate::motion::{Clip, Motion};
use crate::sata::checkpoint::{self, FrozenAutoencoder};
use crate::sata::infer::{Latents, PreparedSkeleton};
use crate::skeleton::Skeleton;
use anyhow::{bail, Context};
use candle_core::Device;
use std::path::Path;

/// `--model DIR`, or the built-in latent model.
pub fn load_model(dir: Option<&Path>, device: &Device) -> anyhow::Result<FrozenAutoencoder> {
    Ok(match dir {
        Some(dir) => checkpoint::frozen(dir, device)?,
        None => checkpoint::frozen_default(device)?,
    })
}

/// The rig to read or write `skeleton`'s motion with, and the skeleton it fits: the model's
/// training rig when it knows the skeleton (`sata::rigs`: the rest pose its rotations are
/// measured from, on the offsets it trained with), else `own` (the clip's or document's).
fn rig_for(model: &FrozenAutoencoder, skeleton: &Skeleton, own: impl FnOnce() -> anyhow::Result<AnyTopSection>) -> anyhow::Result<(AnyTopSection, Skeleton)> {
    match model.rigs.find(skeleton) {
        Some(known) => Ok((known.section.clone(), known.fit(skeleton))),
        None => Ok((own()?, skeleton.clone())),
    }
}

/// A BVH clip read for encoding: skeleton, motion and its AnyTop record (the model's rig for
/// a trained skeleton, else one on the clip's first frames, as `mo-encode` builds for a lone
/// clip).
pub struct SourceClip {
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
    pub prepared: PreparedSkeleton,
}

pub fn read_source(path: &Path, model: &FrozenAutoencoder, device: &Device) -> anyhow::Result<SourceClip> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
    if bytes.starts_with(b"\x93NUMPY") {
        bail!("{name}: expected a BVH clip to encode, found an NPY file (decode features first: mo-encode --decode)");
    }
    let Clip { skeleton, motion, .. } = crate::cli::load::clip_from_bytes(&bytes, &name, path)?;
    if motion.frames < 2 {
        bail!("{name}: {} frame(s); a clip needs at least 2 frames to encode (velocities need a next frame)", motion.frames);
    }
    let (section, skeleton) =
        rig_for(model, &skeleton, || AnyTopSection::of_clip(&skeleton, &motion, &name).with_context(|| format!("{name}: cannot build an AnyTop rig")))?;
    let prepared = PreparedSkeleton::new(&skeleton, section, names()?, device).with_context(|| name.clone())?;
    Ok(SourceClip { name, skeleton, motion, prepared })
}

fn names() -> anyhow::Result<&'static NameTable> {
    NameTable::builtin().context("the built-in joint-name table")
}

/// Per-frame latents of a clip (`[frames - 1, latent]`: AnyTop's features need a next frame).
pub fn encode(model: &FrozenAutoencoder, clip: &SourceClip, device: &Device) -> anyhow::Result<Latents> {
    let encoded = clip.prepared.section.rig.encode(&clip.skeleton, &clip.motion).with_context(|| format!("{}: cannot encode", clip.name))?;
    if let Some((f, j, d)) = encoded.features.first_non_finite() {
        bail!("{}: non-finite feature at frame {f}, joint {j}, dim {d}", clip.name);
    }
    model.encode_features(&encoded.features, &clip.prepared.graph, device).with_context(|| clip.name.clone())
}

/// The skeleton to decode onto (`--skeleton`/`--to`: a document or a BVH) with its rig (the
/// model's for a trained skeleton, else the document's or the BVH's first frame) and graph.
pub struct Target {
    pub arg: SkeletonFile,
    /// `arg`'s skeleton as the rig reads it (`rig_for`); the output keeps `arg`'s offsets.
    pub fitted: Skeleton,
    pub prepared: PreparedSkeleton,
}

pub fn read_target(path: &Path, model: &FrozenAutoencoder, device: &Device) -> anyhow::Result<Target> {
    let arg = read_skeleton(path)?;
    let (section, fitted) = rig_for(model, &arg.skeleton, || Ok(arg.record()?))?;
    let prepared = PreparedSkeleton::new(&fitted, section, names()?, device).with_context(|| arg.name.clone())?;
    Ok(Target { arg, fitted, prepared })
}

/// Latents `[frames, latent]` from an NPY file.
pub fn read_latents(path: &Path) -> anyhow::Result<Latents> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
    let array = npy::from_bytes(&bytes, &name)?;
    let shape = array.shape.clone();
    if shape.len() != 2 || shape[0] == 0 || shape[1] == 0 {
        bail!("{name}: expected latents [frames, dims] (from mo-encode --latent), found shape {shape:?}");
    }
    let data = array.data;
    if let Some(k) = data.iter().position(|v| !v.is_finite()) {
        bail!("{name}: non-finite latent at frame {}, dim {}", k / shape[1], k % shape[1]);
    }
    Ok(Latents { frames: shape[0], dims: shape[1], data })
}

pub fn latents_npy(latents: &Latents) -> anyhow::Result<Vec<u8>> {
    npy::to_bytes(&[latents.frames, latents.dims], &latents.data).context("building the NPY")
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
    let motion =
        model.decode_motion(latents, &target.fitted, &target.prepared, frame_time, device).with_context(|| format!("decoding onto {}", target.arg.name))?;
    motion_file(&target.arg.skeleton, &motion, output, stdout)
}
