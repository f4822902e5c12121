//! What the tools write, written one way: the refusal to put binary on a terminal, feature
//! batches as one NPY, all-or-nothing writes of several files, numbered file patterns, and
//! messages on stderr that start with the tool's name.
//!
//! Each of these was once copied into every tool that needed it, and the copies drifted (one
//! tool wrote all-or-nothing, the others file by file); here there is one of each.

use crate::io;
use crate::motion::write::{motion_file, MotionFormat};
use crate::motion::Motion;
use crate::repr::Features;
use crate::skeleton::Skeleton;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// A motion output's format, for the tools whose `--format` offers BVH, glTF and Motion2Motion
/// features (`mo-retarget`, `mo-edit`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutFormat {
    Bvh,
    /// Binary glTF (skin, animation, a stick mesh).
    Glb,
    /// glTF JSON, data inlined.
    Gltf,
    /// Motion2Motion features [frames, joints, 9].
    Npy,
}

impl OutFormat {
    /// The motion file format (`npy` has none: BVH stands in).
    pub fn motion(self) -> crate::cli::load::MotionFormat {
        use crate::cli::load::MotionFormat;
        match self {
            OutFormat::Glb => MotionFormat::Glb,
            OutFormat::Gltf => MotionFormat::Gltf,
            OutFormat::Bvh | OutFormat::Npy => MotionFormat::Bvh,
        }
    }
}

/// Write every output or none: files atomically, stdout (`None` or `-`) last, since it cannot
/// be taken back; when a file cannot be written, the files of this call already written are
/// removed.
pub fn write_all(outputs: &[(Option<PathBuf>, Vec<u8>)]) -> anyhow::Result<()> {
    Ok(io::write_all(&outputs.iter().map(|(p, b)| (p.as_deref(), b.as_slice())).collect::<Vec<_>>())?)
}

/// Motions on `skeleton` written to `paths` (all or none; `None` = stdout), each file in the
/// format its extension asks for, else `stdout`'s (`motion::write::motion_file`).
pub fn write_motions<'a>(
    skeleton: &Skeleton,
    motions: impl IntoIterator<Item = &'a Motion>,
    paths: &[Option<PathBuf>],
    stdout: MotionFormat,
) -> anyhow::Result<()> {
    let file = |(m, p): (&Motion, &Option<PathBuf>)| Ok((p.clone(), motion_file(skeleton, m, p.as_deref(), stdout)?));
    write_all(&motions.into_iter().zip(paths).map(file).collect::<anyhow::Result<Vec<_>>>()?)
}

/// Feature tensors as one NPY (`Features::batch_npy`) on `output`, never on a terminal (`hint`
/// says what to do instead).
pub fn write_npy(output: Option<&Path>, features: &[Features], always_batch: bool, hint: &str) -> anyhow::Result<()> {
    io::refuse_terminal(output, "NPY", hint)?;
    Ok(io::write_output(output, &Features::batch_npy(features, always_batch).context("building the NPY")?)?)
}

/// `count` file names from a pattern with `{i}` (or one name for one file).
pub fn numbered(pattern: &Path, count: usize) -> anyhow::Result<Vec<PathBuf>> {
    (0..count).map(|i| io::numbered_output(pattern, i, count).map_err(anyhow::Error::msg)).collect()
}

/// Messages on stderr, each starting with the tool's name, as `-q` and `-v` allow.
#[derive(Clone, Copy, Debug)]
pub struct Say {
    pub tool: &'static str,
    pub quiet: bool,
    pub verbose: bool,
}

impl Say {
    /// Something the user should know about the result (not with `-q`).
    pub fn warn(&self, message: impl std::fmt::Display) {
        if !self.quiet {
            eprintln!("{}: warning: {message}", self.tool);
        }
    }

    /// A remark that is no warning (not with `-q`).
    pub fn note(&self, message: impl std::fmt::Display) {
        if !self.quiet {
            eprintln!("{}: note: {message}", self.tool);
        }
    }

    /// What is happening (only with `-v`).
    pub fn info(&self, message: impl std::fmt::Display) {
        if self.verbose {
            eprintln!("{}: {message}", self.tool);
        }
    }
}
