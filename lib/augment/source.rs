//! What `skel-aug` edits, recognised by content: a motion file (BVH, or glTF read as the BVH it
//! stands for), whose channels the edit carries over exactly, or a skeleton document, rebuilt
//! on the edited skeleton. Each variant becomes the bytes of its file: BVH, glTF when its name
//! asks for it, or the document's JSON. A library caller augmenting files gets what the tool
//! writes.

use super::Plan;
use crate::bvh::{self, Bvh};
use crate::document::{DocumentError, SkeletonDocument};
use crate::gltf::ReadOptions;
use crate::motion::clip::{self, ClipError};
use crate::motion::write::{self, MotionFormat, WriteError};
use crate::motion::Motion;
use crate::skeleton::Skeleton;
use std::path::Path;

/// Why a file could not be read as something to augment, or a variant not written.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    #[error(transparent)]
    Clip(#[from] ClipError),
    #[error("{name}: not UTF-8 text: {why}")]
    NotText { name: String, why: std::str::Utf8Error },
    #[error("{name}")]
    Document {
        name: String,
        #[source]
        source: DocumentError,
    },
    /// A document whose joints do not make a skeleton.
    #[error("{name}: {why}")]
    Skeleton { name: String, why: DocumentError },
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("serialising the skeleton document")]
    Json(#[source] serde_json::Error),
}

/// A file to augment.
pub enum Source {
    Bvh(Bvh),
    Document(Box<SkeletonDocument>),
}

/// A skeleton document starts with `{` (after a byte-order mark and white space); BVH never does.
pub fn looks_like_json(bytes: &[u8]) -> bool {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{')
}

impl Source {
    /// The file `bytes` (named `name`, read from `path`), recognised by content; glTF read
    /// with `options`.
    pub fn parse(bytes: &[u8], name: &str, path: &Path, options: &ReadOptions) -> Result<Source, SourceError> {
        if !clip::is_gltf(path, bytes) && looks_like_json(bytes) {
            let text = std::str::from_utf8(bytes).map_err(|why| SourceError::NotText { name: name.to_string(), why })?;
            let document = SkeletonDocument::from_json(text).map_err(|source| SourceError::Document { name: name.to_string(), source })?;
            return Ok(Source::Document(Box::new(document)));
        }
        Ok(Source::Bvh(clip::parse_motion(bytes, name, path, options)?))
    }

    /// The skeleton to plan the edit on.
    pub fn skeleton(&self, name: &str) -> Result<Skeleton, SourceError> {
        match self {
            Source::Bvh(b) => Ok(Skeleton::from_bvh(b)),
            Source::Document(d) => d.skeleton().map_err(|why| SourceError::Skeleton { name: name.to_string(), why }),
        }
    }

    /// Variant `i` of a run with `seed`, edited by `plan`, as the bytes of `out` (stdout when
    /// `None`): BVH (glTF for a `.glb`/`.gltf` name) for a motion file, the document's JSON
    /// (`pretty` or one line) for a document.
    pub fn variant(&self, plan: &Plan, i: usize, seed: u64, out: Option<&Path>, pretty: bool) -> Result<Vec<u8>, SourceError> {
        Ok(match self {
            Source::Bvh(b) => {
                let edited = plan.apply_bvh(b);
                let format = MotionFormat::for_output(out, MotionFormat::Bvh);
                if format == MotionFormat::Bvh {
                    bvh::write_string(&edited).into_bytes()
                } else {
                    let skeleton = Skeleton::from_bvh(&edited);
                    let motion = Motion::from_bvh(&edited, &skeleton);
                    write::motion_file(&skeleton, &motion, out, format)?
                }
            }
            Source::Document(d) => {
                let source = format!("{} (skel-aug --seed {seed} variant {i})", d.source);
                let motion = if plan.is_empty() { d.motion.clone() } else { None };
                let doc = SkeletonDocument::build(&plan.skeleton, motion, &source, d.topology.dmax);
                let mut json = if pretty { serde_json::to_string_pretty(&doc) } else { serde_json::to_string(&doc) }.map_err(SourceError::Json)?;
                json.push('\n');
                json.into_bytes()
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_is_recognised_by_its_first_character() {
        assert!(looks_like_json(b"  \n{\"format\": 1}"));
        assert!(looks_like_json(b"\xEF\xBB\xBF{}"));
        assert!(!looks_like_json(b"HIERARCHY\n"));
        assert!(!looks_like_json(b""));
    }
}
