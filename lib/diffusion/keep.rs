//! What a person asked to keep of a reference clip (`--keep-frames 0-19,100-119`,
//! `--keep-joints '*Leg*,LeftUpLeg/'`), resolved to output frames and joints and checked to
//! leave something to generate. Both editors take it: the denoiser's masked sampling
//! (`edit::KeepMask`) and example-based generation (`genmm::Keep`), so the two read the same
//! text the same way and refuse the same requests.

use super::edit::{parse_frame_ranges, select_joints, EditError, KeepMask};
use crate::motion::{Clip, ClipError};
use crate::repr::anytop::{AnyTopRig, Placement};
use crate::repr::Features;
use crate::skeleton::Skeleton;

/// Frames and joints to keep of a reference, per output frame and per joint.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Kept {
    /// Per output frame: the whole frame is the reference's.
    pub frames: Vec<bool>,
    /// Per joint: the joint is the reference's over the first `known` output frames.
    pub joints: Vec<bool>,
    /// Output frames the reference has.
    pub known: usize,
}

impl Kept {
    /// `frames` (ranges) and `joints` (names, globs, `Name/` for a subtree) of an output of
    /// `output_frames` frames on `skeleton`, whose reference has `reference_frames`; `why` says
    /// where the frame limit comes from, for the message.
    pub fn resolve(
        frames: Option<&str>,
        joints: Option<&str>,
        skeleton: &Skeleton,
        output_frames: usize,
        reference_frames: usize,
        why: &str,
    ) -> Result<Kept, EditError> {
        let known = output_frames.min(reference_frames);
        let mut kept = Kept { frames: vec![false; output_frames], joints: vec![false; skeleton.len()], known };
        if let Some(text) = frames {
            let flag = |e| EditError::Option { flag: "--keep-frames", source: Box::new(e) };
            for range in parse_frame_ranges(text, known, why).map_err(flag)? {
                kept.frames[range].iter_mut().for_each(|k| *k = true);
            }
        }
        if let Some(list) = joints {
            let flag = |e| EditError::Option { flag: "--keep-joints", source: Box::new(e) };
            for j in select_joints(skeleton, list).map_err(flag)? {
                kept.joints[j] = true;
            }
        }
        let every_frame = kept.frames.iter().all(|&k| k);
        let every_joint = known == output_frames && kept.joints.iter().all(|&k| k);
        if every_frame || every_joint {
            return Err(EditError::KeepsAll);
        }
        Ok(kept)
    }

    /// The cells of the denoiser's mask: kept frames whole, kept joints over the known frames.
    pub fn mask(&self) -> KeepMask {
        let mut mask = KeepMask::new(self.frames.len(), self.joints.len());
        let ranges: Vec<_> = self.frames.iter().enumerate().filter(|(_, &k)| k).map(|(f, _)| f..f + 1).collect();
        mask.keep_frames(&ranges);
        let joints: Vec<usize> = self.joints.iter().enumerate().filter(|(_, &k)| k).map(|(j, _)| j).collect();
        mask.keep_joints(&joints, 0..self.known);
        mask
    }
}

/// Why a reference clip could not be read (a bad skeleton's message names the file already;
/// other parse errors say it is the reference).
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error("cannot read the reference {name}")]
    Read {
        name: String,
        #[source]
        source: std::io::Error,
    },
    #[error("the reference {name}")]
    Parse {
        name: String,
        #[source]
        source: ClipError,
    },
    #[error(transparent)]
    Skeleton(ClipError),
    #[error(transparent)]
    Edit(#[from] EditError),
}

/// The reference clip of an edit, encoded on the sampled skeleton's rig.
pub struct Reference {
    pub name: String,
    /// Physical units, `[bvh frames − 1, joints, 13]`.
    pub features: Features,
    pub placement: Placement,
}

impl Reference {
    /// Read the reference clip at `path` (`-` = stdin; glTF as `gltf` says) and `encode` it.
    pub fn read(
        path: &std::path::Path,
        gltf: &crate::gltf::ReadOptions,
        skeleton_name: &str,
        skeleton: &Skeleton,
        rig: &AnyTopRig,
    ) -> Result<Reference, ReferenceError> {
        let (name, bytes) = crate::io::read_named(path).map_err(|e| ReferenceError::Read { name: e.name, source: e.source })?;
        let clip = Clip::from_bytes(&bytes, &name, path, gltf).map_err(|e| match e {
            e @ ClipError::Skeleton { .. } => ReferenceError::Skeleton(e),
            e => ReferenceError::Parse { name: name.clone(), source: e },
        })?;
        Ok(Reference::encode(clip, skeleton_name, skeleton, rig)?)
    }

    /// The cells `--keep-frames` and `--keep-joints` keep of this reference (`Kept`) in an
    /// output of `frames` frames on `skeleton`: frames must exist in both the output and the
    /// reference; joints are kept over every output frame the reference has.
    pub fn mask(&self, keep_frames: Option<&str>, keep_joints: Option<&str>, skeleton: &Skeleton, frames: usize) -> Result<KeepMask, EditError> {
        let why = format!("the output has {frames} frames, the reference {} has {} frames of features", self.name, self.features.frames);
        Ok(Kept::resolve(keep_frames, keep_joints, skeleton, frames, self.features.frames, &why)?.mask())
    }

    /// Encode `clip` with `rig`, the rig of `skeleton` (named `skeleton_name`), which the clip
    /// must be on; it needs two frames (AnyTop features drop the last).
    pub fn encode(clip: Clip, skeleton_name: &str, skeleton: &Skeleton, rig: &AnyTopRig) -> Result<Reference, EditError> {
        let name = clip.name;
        if let Some(diff) = skeleton.first_difference(&clip.skeleton) {
            return Err(EditError::Reference(format!("the reference {name} is not on the skeleton of {skeleton_name}: {diff}")));
        }
        let motion = clip.motion;
        if motion.frames < 2 {
            return Err(EditError::Reference(format!("the reference {name} has {} frame(s); AnyTop features need at least 2", motion.frames)));
        }
        let encoded = rig.encode(skeleton, &motion).map_err(|e| EditError::Reference(format!("the reference {name}: {e}")))?;
        Ok(Reference { name, features: encoded.features, placement: encoded.placement })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_frames_and_joints_make_the_mask_and_everything_is_refused() {
        let (skeleton, _) = crate::synth::creature("quadruped", 0).unwrap();
        let joints = skeleton.len();
        let kept = Kept::resolve(Some("0-1"), None, &skeleton, 4, 10, "").unwrap();
        assert_eq!(kept.frames, vec![true, true, false, false]);
        let mask = kept.mask();
        assert_eq!(mask.count(), 2 * joints);
        assert_eq!(mask.whole_frames(), vec![true, true, false, false]);
        // Joints are kept over the frames the reference has, and only those.
        let root = skeleton.joints[0].name.clone();
        let kept = Kept::resolve(None, Some(&root), &skeleton, 4, 2, "").unwrap();
        assert_eq!(kept.mask().count(), 2);
        assert!(matches!(Kept::resolve(Some("0-3"), None, &skeleton, 4, 10, ""), Err(EditError::KeepsAll)));
        let every = format!("{root}/");
        assert!(matches!(Kept::resolve(None, Some(&every), &skeleton, 4, 10, ""), Err(EditError::KeepsAll)));
        // A range past the reference names the option.
        let e = Kept::resolve(Some("0-5"), None, &skeleton, 8, 4, "why").unwrap_err();
        assert!(e.to_string().starts_with("--keep-frames"), "{e}");
    }
}
