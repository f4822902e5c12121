//! Reading motion for the tools that consume it, with this run's glTF options: the thin CLI
//! side of `motion::Clip` (motion files) and `input` (skeleton files, NPY features decoded on
//! a skeleton, directories), plus the motion formats tools write.
//!
//! A glTF file is read as the BVH it stands for, so every tool that reads BVH reads glTF
//! through this one door, and writes it through `motion_bytes`.

use crate::input::{self, ReadMotions, SkeletonFile};
use crate::motion::{clip, Clip};
use crate::repr::batch::PoseFrom;
use crate::{bvh, gltf};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

pub use crate::input::{expand_inputs, is_dash};
pub use crate::motion::write::MotionFormat;
pub use crate::repr::batch::{split_samples, FeatureDecoder};

/// The glTF input options of this run (`--animation`, `--fps`), set once from `CommonOpts`.
static GLTF_OPTIONS: Mutex<Option<gltf::ReadOptions>> = Mutex::new(None);

/// Set how glTF inputs are read for the rest of the process.
pub fn set_gltf_options(options: gltf::ReadOptions) {
    *GLTF_OPTIONS.lock().unwrap_or_else(|e| e.into_inner()) = Some(options);
}

/// How glTF inputs are read in this run.
pub fn gltf_options() -> gltf::ReadOptions {
    GLTF_OPTIONS.lock().unwrap_or_else(|e| e.into_inner()).clone().unwrap_or_default()
}

/// A motion file as BVH data (`motion::clip::parse_motion` with this run's glTF options).
pub fn parse_motion(bytes: &[u8], name: &str, path: &Path) -> anyhow::Result<bvh::Bvh> {
    Ok(clip::parse_motion(bytes, name, path, &gltf_options())?)
}

/// A clip from the bytes of a motion file already read (to look at them first).
pub fn clip_from_bytes(bytes: &[u8], name: &str, path: &Path) -> Result<Clip, clip::ClipError> {
    Clip::from_bytes(bytes, name, path, &gltf_options())
}

/// Read `--skeleton`, recognised by content.
pub fn read_skeleton(path: &Path) -> anyhow::Result<SkeletonFile> {
    Ok(SkeletonFile::read(path, &gltf_options())?)
}

/// How `load_motions` reads NPY inputs.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions<'a> {
    /// The skeleton NPY features are decoded on (document or BVH); BVH inputs ignore it.
    pub skeleton: Option<&'a Path>,
    /// AnyTop features: decode from rotations (default) or positions.
    pub from: Option<PoseFrom>,
}

/// Read motions from motion files and NPY feature files (`input::read_motions`).
pub fn load_motions(inputs: &[PathBuf], options: &LoadOptions) -> anyhow::Result<Vec<Clip>> {
    let gltf = gltf_options();
    let from = options.from.unwrap_or(PoseFrom::Rotations);
    Ok(input::read_motions(inputs, &ReadMotions { skeleton: options.skeleton, from, gltf: &gltf })?)
}

/// Read one motion clip; `tool` names the tool in the message an NPY file gets.
pub fn read_bvh_clip(path: &Path, tool: &str) -> anyhow::Result<Clip> {
    Ok(Clip::read_motion_file(path, &gltf_options(), tool)?)
}

/// Example clips of one skeleton and one frame rate (`input::read_example_clips`).
pub fn read_example_clips(inputs: &[PathBuf], tool: &str, what: &str) -> anyhow::Result<Vec<Clip>> {
    Ok(input::read_example_clips(inputs, &gltf_options(), tool, what)?)
}
