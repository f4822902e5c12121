//! The document `skel-info` prints for a motion file: the skeleton, a summary of its motion,
//! and the AnyTop record on a rest pose (another file's frame 0 when one is given). Here so
//! that a library caller describes a file exactly as the tool does.

use super::{AnyTopSection, MotionInfo, SkeletonDocument};
use crate::bvh::Bvh;
use crate::motion::Motion;
use crate::repr::anytop::AnyTopError;
use crate::skeleton::Skeleton;

/// A rest pose given as a file: its name, skeleton and first (up to two) frames.
pub struct RestPose {
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
}

/// Why a file cannot be described as asked.
#[derive(Debug, thiserror::Error)]
pub enum DescribeError {
    #[error("--rest-pose {name}: the file has no frames (the rest pose is its frame 0)")]
    NoRestFrames { name: String },
    #[error("--rest-pose {rest} has a different skeleton than {name}")]
    RestSkeleton { rest: String, name: String },
}

impl RestPose {
    /// The rest pose of a parsed motion file `name`: frame 0 (and 1); the file needs frames.
    pub fn of_bvh(parsed: &Bvh, name: &str) -> Result<RestPose, DescribeError> {
        if parsed.frames == 0 {
            return Err(DescribeError::NoRestFrames { name: name.to_string() });
        }
        let skeleton = Skeleton::from_bvh(parsed);
        let motion = Motion::from_bvh_frames(parsed, &skeleton, 0..2);
        Ok(RestPose { name: name.to_string(), skeleton, motion })
    }
}

impl SkeletonDocument {
    /// The document of a parsed motion file `name` with topology up to `dmax`, and (`anytop`)
    /// its AnyTop record on `rest` (which must be on the same skeleton) or AnyTop's rest pose of
    /// the file. A skeleton AnyTop cannot describe (a single joint, bones of zero length) is
    /// still a skeleton: its document has no record, and the reason is returned beside it.
    pub fn of_file(
        parsed: &Bvh,
        name: &str,
        dmax: usize,
        anytop: bool,
        rest: Option<&RestPose>,
    ) -> Result<(SkeletonDocument, Option<AnyTopError>), DescribeError> {
        let skeleton = Skeleton::from_bvh(parsed);
        let mut doc = SkeletonDocument::build(&skeleton, MotionInfo::of(parsed, &skeleton), name, dmax);
        if !anytop {
            return Ok((doc, None));
        }
        let motion = Motion::from_bvh(parsed, &skeleton);
        if let Some(r) = rest {
            let same = r.skeleton.joints.len() == skeleton.joints.len()
                && r.skeleton.joints.iter().zip(&skeleton.joints).all(|(a, b)| a.name == b.name && a.parent == b.parent);
            if !same {
                return Err(DescribeError::RestSkeleton { rest: r.name.clone(), name: name.to_string() });
            }
        }
        match AnyTopSection::of_file(&skeleton, &motion, name, rest.map(|r| (r.name.as_str(), &r.motion))) {
            Ok(section) => {
                doc.anytop = Some(section);
                Ok((doc, None))
            }
            Err(e) => Ok((doc, Some(e))),
        }
    }
}
