//! What a trained denoiser needs to know about a skeleton, built once per skeleton for
//! sampling, editing and DIFT features alike: its normalised rest-pose row P_S, relations R,
//! distances D, joint-name embeddings, and the normalisation statistics — chosen in this order:
//! the statistics the model was trained with for that skeleton, else (sampling) a fallback built
//! from the rest pose and the trained skeletons' spreads, or (DIFT, which compares two motions)
//! statistics measured on the caller's motion.

use super::checkpoint::{find_trained, CheckpointInfo};
use super::sample::Condition;
use super::DiffusionError;
use crate::embed::NameTable;
use crate::repr::anytop::{AnyTopStats, FEATURE_DIMS};
use crate::repr::Features;
use crate::skeleton::{topology, Skeleton};

/// Where the normalisation statistics came from (tools say so when it is the fallback).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StatsSource {
    /// The model's own statistics for this skeleton (same names, parents, nearest proportions).
    Trained,
    /// Measured on the motion the caller gave.
    Measured,
    /// Rest pose as the mean, the trained skeletons' average spreads.
    Fallback,
}

/// Everything `sample::Condition` borrows, owned.
pub struct SkeletonCondition {
    pub rest_row: Vec<f32>,
    pub relations: Vec<Vec<u8>>,
    pub distances: Vec<Vec<u8>>,
    pub names: Vec<Vec<f32>>,
    pub stats: AnyTopStats,
    pub stats_source: StatsSource,
}

impl SkeletonCondition {
    /// The condition for `skeleton` under the model `info` describes, for sampling. `rest_row`
    /// is the skeleton's P_S in physical units (J rows of 13). A skeleton the model was not
    /// trained on gets the fallback, never statistics of a caller's motion: with those the
    /// built-in model's samples left the clips' poses (models/zoo-compact/MODEL_CARD.md).
    pub fn new(info: &CheckpointInfo, skeleton: &Skeleton, rest_row: &[Vec<f32>]) -> Result<SkeletonCondition, DiffusionError> {
        let (stats, stats_source) = match find_trained(&info.skeletons, skeleton) {
            Some(t) => (t.stats.clone(), StatsSource::Trained),
            None => (fallback_stats(rest_row, &info.skeletons.iter().map(|t| &t.stats).collect::<Vec<_>>())?, StatsSource::Fallback),
        };
        SkeletonCondition::with_stats(info, skeleton, rest_row, stats, stats_source)
    }

    /// The condition with the given statistics (e.g. always the caller's own, so that two
    /// motions compared with each other are normalised alike).
    pub fn with_stats(
        info: &CheckpointInfo,
        skeleton: &Skeleton,
        rest_row: &[Vec<f32>],
        stats: AnyTopStats,
        stats_source: StatsSource,
    ) -> Result<SkeletonCondition, DiffusionError> {
        let mut rest = Features { frames: 1, joints: skeleton.len(), dims: FEATURE_DIMS, data: rest_row.concat() };
        // As training normalised the rest tokens (`rest_norm`).
        match &info.rest_norm {
            Some(norm) => norm.for_joints(skeleton.len()).normalise(&mut rest),
            None => stats.normalise(&mut rest),
        }
        .map_err(|source| DiffusionError::Stats { what: "normalising the rest pose", source })?;
        let names = NameTable::builtin().map_err(DiffusionError::Names)?.embed_skeleton(skeleton);
        Ok(SkeletonCondition {
            rest_row: rest.data,
            relations: topology::relations(skeleton),
            distances: topology::distances(skeleton, info.dmax),
            names,
            stats,
            stats_source,
        })
    }

    pub fn condition(&self) -> Condition<'_> {
        Condition { rest_row: &self.rest_row, relations: &self.relations, distances: &self.distances, names: &self.names, stats: &self.stats }
    }
}

/// Statistics for a skeleton nobody measured: its rest-pose row as the mean, and the average
/// of the trained skeletons' (grouped) spreads — the root's from their roots, every other
/// joint's from their non-root joints.
pub fn fallback_stats(rest_row: &[Vec<f32>], trained: &[&AnyTopStats]) -> Result<AnyTopStats, DiffusionError> {
    if trained.is_empty() {
        return Err(DiffusionError::Invalid("the model records no trained skeleton statistics".into()));
    }
    let d = FEATURE_DIMS;
    let mut root = vec![0f32; d];
    let mut joint = vec![0f32; d];
    for s in trained {
        for k in 0..d {
            root[k] += s.std[k] / trained.len() as f32;
            // Joint 1's spreads stand for every non-root joint (they share them,
            // docs/reference/anytop.md §1.8).
            joint[k] += s.std.get(d + k).copied().unwrap_or(s.std[k]) / trained.len() as f32;
        }
    }
    let mean: Vec<f32> = rest_row.concat();
    let std = AnyTopStats::grouped_rows(&root, &joint, rest_row.len());
    Ok(AnyTopStats { mean, std })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::rest_norm::RestNorm;

    /// Sampling normalises the rest token as training did: by the checkpoint's pooled rest
    /// statistics when it has them, by the skeleton's statistics (all zeros under the fallback)
    /// when not.
    #[test]
    fn the_rest_token_is_normalised_as_the_checkpoint_says() {
        let mut info: CheckpointInfo = serde_json::from_slice(crate::diffusion::checkpoint::BUILTIN_INFO).unwrap();
        let (mut skeleton, _) = crate::synth::creature("spider", 3).unwrap();
        // Names no trained skeleton has: a skeleton the model never saw.
        skeleton.joints.iter_mut().enumerate().for_each(|(i, j)| j.name = format!("part{i}"));
        let rest_row: Vec<Vec<f32>> = (0..skeleton.len()).map(|j| (0..FEATURE_DIMS).map(|k| (j * FEATURE_DIMS + k) as f32 * 0.01).collect()).collect();
        let skeleton_way = SkeletonCondition::new(&info, &skeleton, &rest_row).unwrap();
        assert_eq!(skeleton_way.stats_source, StatsSource::Fallback);
        assert!(skeleton_way.rest_row.iter().all(|&x| x == 0.0), "the fallback's mean is the rest pose");
        let norm = RestNorm { mean: [[0.1; FEATURE_DIMS], [0.2; FEATURE_DIMS]], std: [[0.5; FEATURE_DIMS], [2.0; FEATURE_DIMS]] };
        info.rest_norm = Some(norm);
        let global = SkeletonCondition::new(&info, &skeleton, &rest_row).unwrap();
        let expected: Vec<f32> = rest_row
            .iter()
            .enumerate()
            .flat_map(|(j, row)| row.iter().map(move |&x| if j == 0 { (x - 0.1) / (0.5 + 1e-6) } else { (x - 0.2) / (2.0 + 1e-6) }))
            .collect();
        assert_eq!(global.rest_row.len(), expected.len());
        assert!(global.rest_row.iter().zip(&expected).all(|(a, b)| (a - b).abs() < 1e-5));
        // The motion's statistics are the same either way.
        assert_eq!(global.stats, skeleton_way.stats);
    }
}
