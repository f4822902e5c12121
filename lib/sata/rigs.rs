//! The rigs a latent model was trained with (`rigs.json` beside `checkpoint.json`).
//!
//! A rig fixes the rest pose that rotations are measured from (AnyTop: a `*tpos*` clip, else
//! the skeleton's first clip). A lone clip given to `mo-encode --latent` or `mo-retarget
//! --method latent` would otherwise get a rig from its own first frame: for a skeleton the
//! model was trained on that is a different rest pose from the one it learned, and every
//! rotation it reads or writes is off by the difference (the corpus model decoded a flamingo
//! walk onto a chicken built from `Chicken_Walk.bvh`'s first frame as a chicken folded to the
//! ground; with its training rig, from `Chicken_TPOSE.bvh`, it stands and steps). So the model
//! keeps each trained skeleton's rig, and inference uses it whenever the skeleton matches.

use crate::diffusion::checkpoint::CheckpointError;
use crate::diffusion::data::{offsets_agree, TrainSet};
use crate::document::AnyTopSection;
use crate::skeleton::Skeleton;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const FILE: &str = "rigs.json";
pub const FORMAT: &str = "menagerie.sata.rigs";

/// One trained skeleton: how to recognise it and the rig it was trained with.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct KnownRig {
    pub name: String,
    pub joints: Vec<String>,
    pub parents: Vec<Option<usize>>,
    /// Rest offsets, BVH units (the root's is ignored: it places the body).
    pub offsets: Vec<[f64; 3]>,
    pub section: AnyTopSection,
}

impl KnownRig {
    /// `skeleton` and the rig it was trained with (normalisation statistics left out: the
    /// latent model has its own, `FeatureScale`).
    pub fn new(name: &str, skeleton: &Skeleton, section: &AnyTopSection) -> KnownRig {
        KnownRig {
            name: name.to_string(),
            joints: skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            parents: skeleton.joints.iter().map(|j| j.parent).collect(),
            offsets: skeleton.joints.iter().map(|j| j.offset.to_array()).collect(),
            section: AnyTopSection { stats: None, ..section.clone() },
        }
    }

    /// Same joint names and parents, and non-root offsets within the tolerance training groups
    /// clips by (`diffusion::data::same_skeleton`).
    pub fn matches(&self, s: &Skeleton) -> bool {
        if self.joints.len() != s.len() || self.offsets.len() != s.len() {
            return false;
        }
        let same_graph = s.joints.iter().zip(&self.joints).zip(&self.parents).all(|((j, n), p)| &j.name == n && &j.parent == p);
        same_graph && offsets_agree(s.rest_extent(), s.joints.iter().map(|j| j.offset), self.offsets.iter().map(|o| glam::DVec3::from_array(*o)))
    }
}

impl KnownRig {
    /// `s` with the recorded offsets: the skeleton the rig was built on. Clips whose offsets
    /// differ within the tolerance (other performers of one rig, re-exports) were trained as
    /// motions of the group's first skeleton, so inference reads and writes them the same way
    /// (the rig's own check is far stricter than the grouping).
    pub fn fit(&self, s: &Skeleton) -> Skeleton {
        let mut fitted = s.clone();
        for (j, o) in fitted.joints.iter_mut().zip(&self.offsets).skip(1) {
            j.offset = glam::DVec3::from_array(*o);
        }
        fitted
    }
}

#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct KnownRigs {
    pub format: String,
    pub rigs: Vec<KnownRig>,
}

impl KnownRigs {
    /// The skeletons these rigs were trained on, as the out-of-distribution score's reference
    /// (`ood`).
    pub fn ood_reference(&self) -> Result<crate::ood::Reference, crate::embed::EmbedError> {
        crate::ood::Reference::from_records(self.rigs.iter().map(|r| (r.name.as_str(), r.joints.as_slice(), r.parents.as_slice(), r.offsets.as_slice())))
    }

    /// The rigs of a training set's skeletons (not of its augmented variants: a variant met at
    /// inference is a new skeleton to the user too).
    pub fn of_set(set: &TrainSet) -> KnownRigs {
        KnownRigs::new(set.skeletons.iter().map(|sk| KnownRig::new(&sk.name, &sk.skeleton, &sk.section)).collect())
    }

    pub fn new(rigs: Vec<KnownRig>) -> KnownRigs {
        KnownRigs { format: FORMAT.into(), rigs }
    }

    /// The rig `s` was trained with, if the model knows it.
    pub fn find(&self, s: &Skeleton) -> Option<&KnownRig> {
        self.rigs.iter().find(|r| r.matches(s))
    }

    pub fn parse(json: &[u8]) -> Result<KnownRigs, CheckpointError> {
        let rigs: KnownRigs = serde_json::from_slice(json).map_err(CheckpointError::json("rigs.json: not a list of trained rigs".into()))?;
        if rigs.format != FORMAT {
            return Err(CheckpointError::Invalid(format!("rigs.json: format '{}', expected '{FORMAT}'", rigs.format)));
        }
        Ok(rigs)
    }

    /// `dir/rigs.json`; none (every clip gets its own rig) for models trained before it.
    pub fn read(dir: &Path) -> Result<KnownRigs, CheckpointError> {
        let path = dir.join(FILE);
        match std::fs::read(&path) {
            Ok(bytes) => KnownRigs::parse(&bytes).map_err(CheckpointError::of(format!("model {}", dir.display()))),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(KnownRigs::default()),
            Err(e) => Err(CheckpointError::io(format!("cannot read {}", path.display()))(e)),
        }
    }

    /// Write `dir/rigs.json` under a temporary name, then rename it into place.
    pub fn write(&self, dir: &Path) -> Result<(), CheckpointError> {
        std::fs::create_dir_all(dir).map_err(CheckpointError::io(format!("cannot create {}", dir.display())))?;
        let tmp = dir.join(format!(".{FILE}.tmp"));
        let text = serde_json::to_string(self).map_err(CheckpointError::json("serialising the trained rigs".into()))?;
        std::fs::write(&tmp, text + "\n").map_err(CheckpointError::io(format!("cannot write {}", tmp.display())))?;
        std::fs::rename(&tmp, dir.join(FILE)).map_err(CheckpointError::io(format!("cannot move {} into place", tmp.display())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::data::OFFSET_TOLERANCE;
    use crate::synth;

    fn known(name: &str) -> (Skeleton, KnownRigs) {
        let (skeleton, motion) = synth::creature(name, 0).unwrap();
        let section = AnyTopSection::of_clip(&skeleton, &motion, name).unwrap();
        let rigs = KnownRigs::new(vec![KnownRig::new(name, &skeleton, &section)]);
        (skeleton, rigs)
    }

    #[test]
    fn a_trained_skeleton_is_found_within_the_grouping_tolerance_and_fitted_to_its_offsets() {
        let (skeleton, rigs) = known("quadruped");
        assert_eq!(rigs.find(&skeleton).map(|r| r.name.as_str()), Some("quadruped"));
        let size = skeleton.rest_extent();
        let mut close = skeleton.clone();
        close.joints[3].offset.x += 0.2 * OFFSET_TOLERANCE * size;
        let found = rigs.find(&close).expect("a re-export of the same rig");
        let fitted = found.fit(&close);
        assert_eq!(fitted.joints[3].offset, skeleton.joints[3].offset, "read with the trained offsets");
        assert_eq!(fitted.joints[0].offset, close.joints[0].offset, "the root's offset is the clip's own");
        let mut far = skeleton.clone();
        far.joints[3].offset.x += 10.0 * OFFSET_TOLERANCE * size;
        assert!(rigs.find(&far).is_none(), "other proportions are another skeleton");
        let mut renamed = skeleton.clone();
        renamed.joints[2].name.push('x');
        assert!(rigs.find(&renamed).is_none());
        let (other, _) = known("spider");
        assert!(rigs.find(&other).is_none());
    }

    #[test]
    fn rigs_round_trip_through_the_model_directory_and_are_optional() {
        let (skeleton, rigs) = known("biped");
        let dir = std::env::temp_dir().join(format!("menagerie-rigs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(KnownRigs::read(&dir).unwrap(), KnownRigs::default(), "a model without rigs.json");
        rigs.write(&dir).unwrap();
        let back = KnownRigs::read(&dir).unwrap();
        assert_eq!(back, rigs);
        assert!(back.find(&skeleton).is_some());
        std::fs::write(dir.join(FILE), br#"{"format":"something.else","rigs":[]}"#).unwrap();
        let err = KnownRigs::read(&dir).unwrap_err();
        let why = std::error::Error::source(&err).map(|e| e.to_string()).unwrap_or_default();
        assert!(err.to_string().starts_with("model ") && why.contains("expected 'menagerie.sata.rigs'"), "{err}: {why}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
