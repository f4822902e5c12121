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
        stats.normalise(&mut rest).map_err(|source| DiffusionError::Stats { what: "normalising the rest pose", source })?;
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
    let std: Vec<f32> = (0..rest_row.len()).flat_map(|j| if j == 0 { root.clone() } else { joint.clone() }).collect();
    Ok(AnyTopStats { mean, std })
}
