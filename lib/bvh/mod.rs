//! BVH text in and out.
//!
//! BVH is the format users bring and take home, and real files vary a lot: CRLF, tabs, exponents,
//! 0/3/6 channels per joint in any order, names with `:` and spaces, End Sites, one-frame files,
//! 100k-frame files. This module is our own parser and writer (the `bvh_anim` crate truncates
//! names at `:`, panics on malformed files and keeps f32), built around three promises:
//!
//! * values are kept as f64, and the writer prints the shortest text that reads back to the same
//!   f64, so read -> write -> read is exact and write -> read -> write is byte-identical;
//! * every error names the file and line and says what was expected; no input panics and no
//!   header can make us allocate more than the file could possibly hold;
//! * the frame section parses at hundreds of MB/s (see `number.rs` and BENCHMARKS.md).
//!
//! The data model here is the file's, not the skeleton's: joints in file order with their raw
//! channel lists and a flat row-major matrix of channel values. `skeleton::Skeleton` and
//! `motion::Motion` are built from it.

mod number;
mod parse;
mod write;

pub use number::parse_f64;
pub use parse::{parse, parse_bytes, read_path};
pub use write::{write, write_string};

use std::fmt;

/// One animation channel of a joint, as named in a BVH `CHANNELS` line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    Xposition,
    Yposition,
    Zposition,
    Xrotation,
    Yrotation,
    Zrotation,
}

impl Channel {
    pub const ALL: [Channel; 6] = [Channel::Xposition, Channel::Yposition, Channel::Zposition, Channel::Xrotation, Channel::Yrotation, Channel::Zrotation];

    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// Case-insensitive, because exporters disagree on `XROTATION` vs `Xrotation`.
    pub fn from_name(s: &str) -> Option<Channel> {
        Channel::ALL.into_iter().find(|c| c.name().eq_ignore_ascii_case(s))
    }

    pub fn is_rotation(self) -> bool {
        matches!(self, Channel::Xrotation | Channel::Yrotation | Channel::Zrotation)
    }

    /// 0, 1, 2 for x, y, z.
    pub fn axis(self) -> usize {
        match self {
            Channel::Xposition | Channel::Xrotation => 0,
            Channel::Yposition | Channel::Yrotation => 1,
            Channel::Zposition | Channel::Zrotation => 2,
        }
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A `ROOT` or `JOINT` entry, in file order (so parents always precede children).
#[derive(Clone, Debug, PartialEq)]
pub struct BvhJoint {
    pub name: String,
    pub parent: Option<usize>,
    pub offset: [f64; 3],
    pub channels: Vec<Channel>,
    /// Offsets of `End Site` blocks directly under this joint (almost always zero or one).
    pub end_sites: Vec<[f64; 3]>,
}

/// A parsed BVH file: hierarchy plus the frame matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    pub joints: Vec<BvhJoint>,
    pub frame_time: f64,
    pub frames: usize,
    /// `frames x channel_count` values, row-major, in file order.
    pub values: Vec<f64>,
}

impl Bvh {
    pub fn channel_count(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// The values of one frame.
    pub fn frame(&self, f: usize) -> &[f64] {
        let n = self.channel_count();
        &self.values[f * n..(f + 1) * n]
    }

    /// Index of the first channel of each joint within a frame row.
    pub fn channel_starts(&self) -> Vec<usize> {
        let mut starts = Vec::with_capacity(self.joints.len());
        let mut at = 0;
        for j in &self.joints {
            starts.push(at);
            at += j.channels.len();
        }
        starts
    }
}

/// A BVH error: where it happened and what was expected there.
#[derive(Debug, thiserror::Error)]
pub enum BvhError {
    #[error("{file}:{line}: {message}")]
    Syntax { file: String, line: usize, message: String },
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
}

impl BvhError {
    pub fn line(&self) -> Option<usize> {
        match self {
            BvhError::Syntax { line, .. } => Some(*line),
            BvhError::Io { .. } => None,
        }
    }
}
