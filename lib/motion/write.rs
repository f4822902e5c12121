//! The other half of the motion room's file door: a skeleton and motion as the bytes of a
//! motion file, BVH or glTF, in the format an output's name asks for. `motion::clip` reads
//! every format a tool reads; this writes every format a tool writes, so the tools and library
//! callers name a `.glb` output and get the same file.

use super::Motion;
use crate::gltf::{self, GltfError};
use crate::io::output::OutputError;
use crate::skeleton::Skeleton;
use crate::{bvh, io};
use std::path::Path;

/// The motion file formats tools write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionFormat {
    Bvh,
    /// Binary glTF: skin, animation and a stick mesh in one file (Blender, three.js, game engines).
    Glb,
    /// glTF JSON with the binary data inlined.
    Gltf,
}

/// Why a motion file could not be built.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error(transparent)]
    Gltf(#[from] GltfError),
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// `-` means stdout.
fn is_dash(p: &Path) -> bool {
    p.as_os_str() == "-"
}

impl MotionFormat {
    /// What a path's extension asks for (`.glb`, `.gltf`; anything else is BVH).
    pub fn of_path(path: &Path) -> MotionFormat {
        match path.extension().and_then(|x| x.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("glb") => MotionFormat::Glb,
            Some("gltf") => MotionFormat::Gltf,
            _ => MotionFormat::Bvh,
        }
    }

    /// The format for an output: the path's extension, or `stdout` for stdout (`None` or `-`).
    pub fn for_output(path: Option<&Path>, stdout: MotionFormat) -> MotionFormat {
        match path {
            Some(p) if !is_dash(p) => MotionFormat::of_path(p),
            _ => stdout,
        }
    }
}

/// The bytes of a motion file in `format`; `name` is the output's, for messages.
pub fn motion_bytes(skeleton: &Skeleton, motion: &Motion, format: MotionFormat, name: &str) -> Result<Vec<u8>, GltfError> {
    Ok(match format {
        MotionFormat::Bvh => bvh::write_string(&motion.to_bvh(skeleton)).into_bytes(),
        MotionFormat::Glb => gltf::write_glb(skeleton, motion, name)?,
        MotionFormat::Gltf => gltf::write_gltf(skeleton, motion, name)?,
    })
}

/// A motion written to `path` (or stdout as `stdout` says), in the format the path asks for;
/// binary glTF is not written to a terminal.
pub fn motion_file(skeleton: &Skeleton, motion: &Motion, path: Option<&Path>, stdout: MotionFormat) -> Result<Vec<u8>, WriteError> {
    let name = path.filter(|p| !is_dash(p)).map_or_else(|| "<stdout>".to_string(), |p| p.display().to_string());
    let format = MotionFormat::for_output(path, stdout);
    if format == MotionFormat::Glb {
        io::refuse_terminal(path, "binary glTF", "give -o FILE.glb or redirect stdout")?;
    }
    Ok(motion_bytes(skeleton, motion, format, &name)?)
}
