//! Training data for the denoiser (AnyTop §1.7–1.9, §3.5): clips grouped by skeleton, each
//! skeleton with its rig, rest-pose row P_S, normalisation statistics, topology (R, D) and joint
//! name embeddings; clips encoded and normalised once; batches of random 40-frame crops drawn
//! by the balancing sampler (every skeleton equally likely, then a clip of it uniformly).
//!
//! Grouping: clips whose joint names and parents are identical share a skeleton (one folder
//! per creature in the corpus, but a folder is not required). The rest pose of a skeleton is
//! the first two frames of a clip whose file name says T-pose, else of its first clip
//! (AnyTop's rule, `anytop::names_tpose`).

use crate::document::AnyTopSection;
use crate::embed::NameTable;
use crate::motion::Motion;
use crate::repr::anytop::{self, AnyTopOptions, AnyTopStats, RestSource};
use crate::repr::Features;
use crate::skeleton::{topology, Skeleton};
use crate::synth::SplitMix64;

/// Clips shorter than this (in feature frames) are left out, as the reference does.
pub const MIN_FRAMES: usize = 20;

/// One clip as read from a file.
pub struct RawClip {
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
}

/// Everything the model needs to know about one skeleton, and its clips.
pub struct SkeletonData {
    pub name: String,
    pub skeleton: Skeleton,
    pub section: AnyTopSection,
    pub stats: AnyTopStats,
    /// P_S, normalised: `[joints * 13]`.
    pub rest_row: Vec<f32>,
    pub relations: Vec<Vec<u8>>,
    pub distances: Vec<Vec<u8>>,
    /// One embedding per joint.
    pub names: Vec<Vec<f32>>,
    /// Normalised features `[frames, joints, 13]` of each clip.
    pub clips: Vec<Features>,
    pub clip_names: Vec<String>,
}

/// A training set: skeletons with their clips.
pub struct TrainSet {
    pub skeletons: Vec<SkeletonData>,
}

#[derive(Debug, thiserror::Error)]
pub enum DataError {
    #[error("no clips to train on")]
    Empty,
    #[error("{clip}: {why}")]
    Clip { clip: String, why: String },
    #[error("skeleton of {clip}: no clip has {min} or more frames", min = MIN_FRAMES + 1)]
    TooShort { clip: String },
}


impl TrainSet {
    /// Group `clips` by skeleton and prepare them. Clips too short to crop are dropped
    /// (returned by name, so the caller can say so).
    pub fn build(clips: Vec<RawClip>, names: &NameTable, dmax: usize) -> Result<(TrainSet, Vec<String>), DataError> {
        if clips.is_empty() {
            return Err(DataError::Empty);
        }
        let mut groups: Vec<Vec<RawClip>> = Vec::new();
        for c in clips {
            match groups.iter_mut().find(|g| g[0].skeleton.first_difference(&c.skeleton).is_none()) {
                Some(g) => g.push(c),
                None => groups.push(vec![c]),
            }
        }
        let mut skeletons = Vec::with_capacity(groups.len());
        let mut dropped = Vec::new();
        for group in groups {
            let rest_clip = group.iter().find(|c| anytop::names_tpose(&c.name)).unwrap_or(&group[0]);
            let source = if anytop::names_tpose(&rest_clip.name) {
                RestSource::TPose { file: rest_clip.name.clone() }
            } else {
                RestSource::FirstClip { file: rest_clip.name.clone() }
            };
            let skeleton = group[0].skeleton.clone();
            let options = AnyTopOptions { rest_source: source, ..AnyTopOptions::default() };
            let section = AnyTopSection::new(&skeleton, &rest_clip.motion.first_frames(2), &options)
                .map_err(|e| DataError::Clip { clip: rest_clip.name.clone(), why: e.to_string() })?;
            let mut features = Vec::new();
            let mut clip_names = Vec::new();
            for c in &group {
                if c.motion.frames < MIN_FRAMES + 1 {
                    dropped.push(c.name.clone());
                    continue;
                }
                let encoded = section.rig.encode(&skeleton, &c.motion).map_err(|e| DataError::Clip { clip: c.name.clone(), why: e.to_string() })?;
                features.push(encoded.features);
                clip_names.push(c.name.clone());
            }
            if features.is_empty() {
                return Err(DataError::TooShort { clip: group[0].name.clone() });
            }
            let stats = AnyTopStats::compute(features.iter()).map_err(|e| DataError::Clip { clip: group[0].name.clone(), why: e.to_string() })?;
            for f in &mut features {
                stats.normalise(f).map_err(|e| DataError::Clip { clip: group[0].name.clone(), why: e.to_string() })?;
            }
            let mut rest = Features { frames: 1, joints: skeleton.len(), dims: anytop::FEATURE_DIMS, data: section.rest_row.concat() };
            stats.normalise(&mut rest).map_err(|e| DataError::Clip { clip: group[0].name.clone(), why: e.to_string() })?;
            skeletons.push(SkeletonData {
                name: group[0].name.clone(),
                relations: topology::relations(&skeleton),
                distances: topology::distances(&skeleton, dmax),
                names: names.embed_skeleton(&skeleton),
                rest_row: rest.data,
                skeleton,
                section,
                stats,
                clips: features,
                clip_names,
            });
        }
        Ok((TrainSet { skeletons }, dropped))
    }

    /// Draw `batch` crops of at most `frames` feature frames: a skeleton uniformly (each gets
    /// 1/#skeletons, AnyTop's balancing sampler), a clip of it uniformly, a crop start uniformly.
    pub fn sample(&self, rng: &mut SplitMix64, batch: usize, frames: usize) -> Vec<Crop> {
        (0..batch)
            .map(|_| {
                let s = rng.below(self.skeletons.len());
                let sk = &self.skeletons[s];
                let c = rng.below(sk.clips.len());
                let clip = &sk.clips[c];
                let len = clip.frames.min(frames);
                let start = rng.below(clip.frames - len + 1);
                Crop { skeleton: s, clip: c, start, frames: len }
            })
            .collect()
    }

    /// The features of a crop, `[frames, joints, 13]` (normalised).
    pub fn crop(&self, crop: &Crop) -> Features {
        let clip = &self.skeletons[crop.skeleton].clips[crop.clip];
        let width = clip.joints * clip.dims;
        Features { frames: crop.frames, joints: clip.joints, dims: clip.dims, data: clip.data[crop.start * width..(crop.start + crop.frames) * width].to_vec() }
    }
}

/// Where a training crop comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub skeleton: usize,
    pub clip: usize,
    pub start: usize,
    pub frames: usize,
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth;

    fn zoo() -> Vec<RawClip> {
        ["biped", "quadruped", "spider"]
            .iter()
            .flat_map(|n| {
                (0..2).map(move |seed| {
                    let (skeleton, motion) = synth::creature(n, seed).unwrap();
                    RawClip { name: format!("{n}_{seed}.bvh"), skeleton, motion }
                })
            })
            .collect()
    }

    #[test]
    fn clips_group_by_skeleton_and_normalise() {
        let names = NameTable::builtin().unwrap();
        let clips = zoo();
        let (set, dropped) = TrainSet::build(clips, names, topology::DEFAULT_DMAX).unwrap();
        assert!(dropped.is_empty());
        // Seeds may change a creature's proportions but not its joints: two clips per skeleton.
        let per: Vec<usize> = set.skeletons.iter().map(|s| s.clips.len()).collect();
        assert_eq!(per.iter().sum::<usize>(), 6);
        for s in &set.skeletons {
            let j = s.skeleton.len();
            assert_eq!(s.rest_row.len(), j * 13);
            assert_eq!((s.relations.len(), s.distances.len(), s.names.len()), (j, j, j));
            // Normalised features: the mean over all frames is ~0 per dimension.
            let frames: usize = s.clips.iter().map(|c| c.frames).sum();
            let mut sum = vec![0.0f64; j * 13];
            for c in &s.clips {
                for row in c.data.chunks_exact(j * 13) {
                    sum.iter_mut().zip(row).for_each(|(a, &x)| *a += x as f64);
                }
            }
            assert!(sum.iter().all(|x| (x / frames as f64).abs() < 1e-3), "{}", s.name);
        }
    }

    #[test]
    fn sampling_is_balanced_deterministic_and_in_range() {
        let names = NameTable::builtin().unwrap();
        let (set, _) = TrainSet::build(zoo(), names, topology::DEFAULT_DMAX).unwrap();
        let a = set.sample(&mut SplitMix64::new(3), 300, 40);
        let b = set.sample(&mut SplitMix64::new(3), 300, 40);
        assert_eq!(a, b);
        let mut count = vec![0usize; set.skeletons.len()];
        for c in &a {
            count[c.skeleton] += 1;
            let clip = &set.skeletons[c.skeleton].clips[c.clip];
            assert!(c.frames <= 40 && c.start + c.frames <= clip.frames);
            assert_eq!(set.crop(c).frames, c.frames);
        }
        let expected = 300 / set.skeletons.len();
        assert!(count.iter().all(|&n| n.abs_diff(expected) < expected / 3), "{count:?}");
    }
}
