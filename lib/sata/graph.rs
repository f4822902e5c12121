//! The static side of a skeleton as SATA's model sees it (paper §3.1): per joint the rest-pose
//! offset w.r.t. the root (X_g) and w.r.t. the parent (X_l) and the joint-name embedding (X_t);
//! per bone, in both directions, the structural edge features: depth and reverse depth of the
//! child joint.

use crate::repr::anytop::AnyTopRig;
use crate::skeleton::Skeleton;
use candle_core::{Device, Tensor};

/// Edge features per directed edge: child depth, child reverse depth (both / `DEPTH_SCALE`),
/// and the direction (1 parent -> child, -1 child -> parent).
pub const EDGE_DIMS: usize = 3;
/// Depths are divided by this so typical rigs (depth <= 20) give inputs of order one.
const DEPTH_SCALE: f32 = 10.0;

/// Tensors describing one skeleton, on the model's device.
#[derive(Clone, Debug)]
pub struct SkeletonGraph {
    pub joints: usize,
    /// `[J, 6]`: X_g (rest position minus the root's) then X_l (minus the parent's; zero for
    /// the root), in AnyTop's scaled units (natural rest pose, mean bone 0.209).
    pub statics: Tensor,
    /// `[J, name_dim]` joint-name embeddings.
    pub names: Tensor,
    /// `[E, J]` one-hot of each directed edge's source joint (gathers messages).
    pub gather: Tensor,
    /// `[J, E]` one-hot of each edge's destination (sums messages per joint).
    pub scatter: Tensor,
    /// `[E, EDGE_DIMS]`.
    pub edges: Tensor,
    /// `[J * 13]`: [`rest_row`], what the model's features are measured from.
    pub rest: Vec<f32>,
}

/// The AnyTop features of the natural rest pose standing still, `[J * 13]`: positions relative
/// to the root's ground point (y absolute), identity 6D, no velocity or contact. The model sees
/// and predicts features as offsets from it (`train::FeatureScale`), so a skeleton's size and
/// shape need not be learned, and the small motions around the pose are not drowned by it.
pub fn rest_row(skeleton: &Skeleton, rig: &AnyTopRig) -> Vec<f32> {
    let rest = rig.rest_positions(skeleton);
    let mut row = vec![0f32; rest.len() * 13];
    for (k, p) in rest.iter().enumerate() {
        let q = if k == 0 { glam::DVec3::new(0.0, p.y, 0.0) } else { glam::DVec3::new(p.x - rest[0].x, p.y, p.z - rest[0].z) };
        row[k * 13..k * 13 + 9].copy_from_slice(&[q.x as f32, q.y as f32, q.z as f32, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    }
    row
}

/// Bones from the root to each joint.
pub fn depths(parents: &[Option<usize>]) -> Vec<usize> {
    let mut out = vec![0; parents.len()];
    for j in 0..parents.len() {
        // Parents come before children in our skeletons; walk up anyway so any order works.
        let (mut d, mut p) = (0, parents[j]);
        while let Some(q) = p {
            d += 1;
            if d > parents.len() {
                break;
            }
            p = parents[q];
        }
        out[j] = d;
    }
    out
}

/// Bones from each joint down to its deepest leaf (0 for a leaf).
pub fn reverse_depths(parents: &[Option<usize>]) -> Vec<usize> {
    let depth = depths(parents);
    let mut out = vec![0usize; parents.len()];
    // Deepest joints first, so a child's value is final before its parent reads it.
    let mut order: Vec<usize> = (0..parents.len()).collect();
    order.sort_by_key(|&j| std::cmp::Reverse(depth[j]));
    for j in order {
        if let Some(p) = parents[j] {
            out[p] = out[p].max(out[j] + 1);
        }
    }
    out
}

impl SkeletonGraph {
    /// From a skeleton, its AnyTop rig (for the natural rest pose) and one name embedding per
    /// joint. Call with embeddings from `embed::NameTable::embed_skeleton`.
    pub fn new(skeleton: &Skeleton, rig: &AnyTopRig, names: &[Vec<f32>], device: &Device) -> candle_core::Result<SkeletonGraph> {
        let j = skeleton.len();
        if names.len() != j {
            candle_core::bail!("{} name embeddings for {j} joints", names.len());
        }
        let dim = names.first().map_or(0, Vec::len);
        if names.iter().any(|n| n.len() != dim) {
            candle_core::bail!("name embeddings of different sizes");
        }
        let rest = rig.rest_positions(skeleton);
        if rest.len() != j {
            candle_core::bail!("the rig has {} joints, the skeleton {j}", rest.len());
        }
        let parents = skeleton.parents();
        let mut statics = Vec::with_capacity(j * 6);
        for (k, p) in rest.iter().enumerate() {
            let g = *p - rest[0];
            let l = parents[k].map_or(glam::DVec3::ZERO, |q| *p - rest[q]);
            statics.extend([g.x, g.y, g.z, l.x, l.y, l.z].map(|v| v as f32));
        }
        let depth = depths(&parents);
        let reverse = reverse_depths(&parents);
        let bones: Vec<(usize, usize)> = parents.iter().enumerate().filter_map(|(c, p)| p.map(|p| (p, c))).collect();
        // Two directed edges per bone; an isolated root (one joint) gets a self-loop so the
        // message sum is over a non-empty set and shapes stay non-zero.
        let mut list: Vec<(usize, usize, [f32; EDGE_DIMS])> = Vec::with_capacity(bones.len() * 2);
        for &(p, c) in &bones {
            let f = |dir: f32| [depth[c] as f32 / DEPTH_SCALE, reverse[c] as f32 / DEPTH_SCALE, dir];
            list.push((p, c, f(1.0)));
            list.push((c, p, f(-1.0)));
        }
        if list.is_empty() {
            list.push((0, 0, [0.0, 0.0, 0.0]));
        }
        let e = list.len();
        let mut gather = vec![0f32; e * j];
        let mut scatter = vec![0f32; j * e];
        let mut edges = Vec::with_capacity(e * EDGE_DIMS);
        for (k, (src, dst, f)) in list.iter().enumerate() {
            gather[k * j + src] = 1.0;
            scatter[dst * e + k] = 1.0;
            edges.extend_from_slice(f);
        }
        let flat: Vec<f32> = names.iter().flatten().copied().collect();
        Ok(SkeletonGraph {
            joints: j,
            statics: Tensor::from_vec(statics, (j, 6), device)?,
            names: Tensor::from_vec(flat, (j, dim), device)?,
            gather: Tensor::from_vec(gather, (e, j), device)?,
            scatter: Tensor::from_vec(scatter, (j, e), device)?,
            edges: Tensor::from_vec(edges, (e, EDGE_DIMS), device)?,
            rest: rest_row(skeleton, rig),
        })
    }
}
