//! glTF 2.0 in and out: the format animators' tools (Blender, game engines, web viewers) speak.
//!
//! Reading goes through the `gltf` crate, which parses and validates the file (indices, types);
//! this module resolves the buffers (GLB blob, `data:` URIs, files beside a `.gltf`), checks what
//! the crate leaves to us (accessor element types, counts, node cycles, finite numbers), and turns
//! a skin and one animation into our [`Skeleton`] and [`Motion`]:
//!
//! * the skin's joints become the joints, named after their nodes, ordered parent before child
//!   (the skin's order where it allows); the rest offsets are the nodes' translations;
//! * a joint's local rotation and translation per frame are its animated values, else the node's
//!   own; the transforms of the nodes above the root joint (an armature object) are baked into
//!   the root, so world positions are the file's;
//! * frames are the animation's keyframe times when they are evenly spaced (else a grid at the
//!   smallest key interval), or a given frame rate; LINEAR, STEP and CUBICSPLINE keys are
//!   interpolated as the glTF specification says (rotations by shortest-path slerp);
//! * leaf nodes under a joint that are not joints themselves become End Sites.
//!
//! Writing builds the file with `gltf-json`: one node per joint (rest translations, no rest
//! rotations), one per End Site, a skin with inverse bind matrices, one animation (rotations of
//! every joint, translations of the root and of every joint whose translation moves), and a
//! mesh of one tapered stick per bone skinned rigidly to it, so any viewer shows the creature.
//! Units and axes are whatever the motion has: nothing is converted (glTF says Y-up metres;
//! BVH files are usually Y-up, in centimetres or metres).

mod mesh;
mod read;
mod sample;
mod write;

pub use read::{looks_like_gltf, read};
pub use write::{write_glb, write_gltf};

/// Which animation of a file becomes the motion.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub enum AnimationChoice {
    /// The first one (a file without animations gives its rest pose as one frame).
    #[default]
    First,
    /// By position in the file's list, from 0.
    Index(usize),
    /// By name.
    Name(String),
}

impl AnimationChoice {
    /// `NAME|INDEX` as the command line gives it: all digits means an index.
    pub fn parse(s: &str) -> AnimationChoice {
        match s.parse::<usize>() {
            Ok(i) if !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) => AnimationChoice::Index(i),
            _ => AnimationChoice::Name(s.to_string()),
        }
    }
}

/// How a glTF file is read.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadOptions {
    pub animation: AnimationChoice,
    /// Sample at this frame rate instead of the keyframe times.
    pub fps: Option<f64>,
    /// More frames than this is an error (a file whose keys are microseconds apart).
    pub max_frames: usize,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions { animation: AnimationChoice::First, fps: None, max_frames: 1_000_000 }
    }
}

/// A glTF file that cannot be read or written; always names the file.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// The crate refused the bytes (not glTF, broken GLB, invalid JSON or indices).
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    /// Valid glTF, but not what we can animate, or inconsistent data.
    #[error("{file}: {message}")]
    Data { file: String, message: String },
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
}

#[cfg(test)]
mod tests;
