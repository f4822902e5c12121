//! What one forward pass needs, and how to pad clips of different skeletons into it.
//!
//! Layout (T = F + 1 tokens per joint: the rest-pose row P_S is token 0, "enrichment"):
//!
//! | field | shape | dtype |
//! |---|---|---|
//! | `x` | `[B, T, J, dims]` | f32: P_S at t = 0, then the (noised, normalised) motion |
//! | `timesteps` | `[B]` | u32 or f32 diffusion step |
//! | `names` | `[B, J, name_dim]` | f32 joint-name embeddings |
//! | `relations` | `[B, J, J]` | u32, R (0..=5) |
//! | `distances` | `[B, J, J]` | u32, D (the model caps it at `dmax`) |
//! | `joint_mask` | `[B, J]` | f32, 1 real joint, 0 padding |
//! | `frame_mask` | `[B, T]` | f32, 1 real token (always at t = 0), 0 padding |
//! | `positions` | `[B, T]` | f32 temporal position: 0 for P_S, `k + 1 + start` for frame k |
//!
//! Padding joints must come after the real joints of a clip (they do with `batch_from`); the
//! root is joint 0.

use super::NnError;
use crate::repr::Features;
use candle_core::{Device, Tensor};

#[derive(Clone, Debug)]
pub struct Batch {
    pub x: Tensor,
    pub timesteps: Tensor,
    pub names: Tensor,
    pub relations: Tensor,
    pub distances: Tensor,
    pub joint_mask: Tensor,
    pub frame_mask: Tensor,
    /// Per-sample positions (the reference shares sample 0's crop start across the batch,
    /// docs/reference/anytop.md §9.2; we do not).
    pub positions: Tensor,
}

/// One clip of a batch, borrowed from the representation and skeleton document.
#[derive(Clone, Copy, Debug)]
pub struct BatchItem<'a> {
    /// Normalised motion, `[F, J, dims]`.
    pub features: &'a Features,
    /// Normalised rest-pose row P_S, `J * dims` values (joint-major).
    pub rest_row: &'a [f32],
    /// Relations R, J x J.
    pub relations: &'a [Vec<u8>],
    /// Distances D, J x J.
    pub distances: &'a [Vec<u8>],
    /// Joint-name embeddings, J rows of `name_dim`.
    pub names: &'a [Vec<f32>],
    /// Index of the clip's first frame in its source motion (the crop start), for the
    /// temporal positions; 0 when generating.
    pub start: u32,
}

impl Batch {
    /// `(B, T, J, dims)` of `x`.
    pub fn dims(&self) -> Result<(usize, usize, usize, usize), NnError> {
        Ok(self.x.dims4()?)
    }
}

fn item_error(item: usize, what: &'static str, expected: impl ToString, got: impl ToString) -> NnError {
    NnError::BatchItem { item, what, expected: expected.to_string(), got: got.to_string() }
}

fn check_square(item: usize, what: &'static str, m: &[Vec<u8>], joints: usize) -> Result<(), NnError> {
    if m.len() != joints {
        return Err(item_error(item, what, format!("{joints} rows"), m.len()));
    }
    if let Some((i, row)) = m.iter().enumerate().find(|(_, r)| r.len() != joints) {
        return Err(item_error(item, what, format!("row {i} with {joints} entries"), row.len()));
    }
    Ok(())
}

/// Pads `items` (possibly different skeletons and lengths) to the largest J and F and builds a
/// batch on `device`. Padded joints and frames are zero and masked out.
pub fn batch_from(items: &[BatchItem], timesteps: &[u32], device: &Device) -> Result<Batch, NnError> {
    let Some(first) = items.first() else {
        return Err(NnError::Shape { what: "batch items", expected: "at least one".into(), got: vec![0] });
    };
    if timesteps.len() != items.len() {
        return Err(NnError::Shape { what: "timesteps", expected: format!("{} (one per item)", items.len()), got: vec![timesteps.len()] });
    }
    let dims = first.features.dims;
    let name_dim = first.names.first().map_or(0, |r| r.len());
    for (i, it) in items.iter().enumerate() {
        let f = it.features;
        let j = f.joints;
        if f.dims != dims || dims == 0 {
            return Err(item_error(i, "feature dims", dims, f.dims));
        }
        if f.frames == 0 || j == 0 {
            return Err(item_error(i, "frames and joints", "at least 1 each", format!("{} frames, {j} joints", f.frames)));
        }
        if f.data.len() != f.frames * j * dims {
            return Err(item_error(i, "feature values", f.frames * j * dims, f.data.len()));
        }
        if let Some((fr, jt, d)) = f.first_non_finite() {
            return Err(item_error(i, "finite features", "finite values", format!("non-finite at frame {fr} joint {jt} dim {d}")));
        }
        if it.rest_row.len() != j * dims {
            return Err(item_error(i, "rest row P_S", j * dims, it.rest_row.len()));
        }
        if it.rest_row.iter().any(|v| !v.is_finite()) {
            return Err(item_error(i, "rest row P_S", "finite values", "non-finite"));
        }
        check_square(i, "relations R", it.relations, j)?;
        check_square(i, "distances D", it.distances, j)?;
        if let Some(v) = it.relations.iter().flatten().find(|&&v| v as usize >= super::config::RELATION_TYPES) {
            return Err(item_error(i, "relation type", "0..=5", v));
        }
        if it.names.len() != j {
            return Err(item_error(i, "name embeddings", format!("{j} rows"), it.names.len()));
        }
        if let Some(row) = it.names.iter().find(|r| r.len() != name_dim) {
            return Err(item_error(i, "name embedding size", name_dim, row.len()));
        }
        if it.names.iter().flatten().any(|v| !v.is_finite()) {
            return Err(item_error(i, "name embeddings", "finite values", "non-finite"));
        }
    }
    let b = items.len();
    let jm = items.iter().map(|it| it.features.joints).max().unwrap_or(1);
    let fm = items.iter().map(|it| it.features.frames).max().unwrap_or(1);
    let t = fm + 1;
    let mut x = vec![0f32; b * t * jm * dims];
    let mut names = vec![0f32; b * jm * name_dim];
    let mut rel = vec![0u32; b * jm * jm];
    let mut dist = vec![0u32; b * jm * jm];
    let mut jmask = vec![0f32; b * jm];
    let mut fmask = vec![0f32; b * t];
    let mut pos = vec![0f32; b * t];
    for (s, it) in items.iter().enumerate() {
        let f = it.features;
        let j = f.joints;
        let at = |tok: usize, joint: usize| ((s * t + tok) * jm + joint) * dims;
        for joint in 0..j {
            x[at(0, joint)..at(0, joint) + dims].copy_from_slice(&it.rest_row[joint * dims..(joint + 1) * dims]);
            for fr in 0..f.frames {
                x[at(fr + 1, joint)..at(fr + 1, joint) + dims].copy_from_slice(f.at(fr, joint));
            }
            names[(s * jm + joint) * name_dim..(s * jm + joint + 1) * name_dim].copy_from_slice(&it.names[joint]);
            for k in 0..j {
                rel[(s * jm + joint) * jm + k] = it.relations[joint][k] as u32;
                dist[(s * jm + joint) * jm + k] = it.distances[joint][k] as u32;
            }
            jmask[s * jm + joint] = 1.0;
        }
        for tok in 0..=f.frames {
            fmask[s * t + tok] = 1.0;
        }
        // Token 0 (P_S) sits at position 0; frame k at k + 1 + start, also for padded frames
        // (masked anyway), so positions stay increasing.
        for tok in 1..t {
            pos[s * t + tok] = (tok as u64 + it.start as u64) as f32;
        }
    }
    Ok(Batch {
        x: Tensor::from_vec(x, (b, t, jm, dims), device)?,
        timesteps: Tensor::from_vec(timesteps.to_vec(), b, device)?,
        names: Tensor::from_vec(names, (b, jm, name_dim), device)?,
        relations: Tensor::from_vec(rel, (b, jm, jm), device)?,
        distances: Tensor::from_vec(dist, (b, jm, jm), device)?,
        joint_mask: Tensor::from_vec(jmask, (b, jm), device)?,
        frame_mask: Tensor::from_vec(fmask, (b, t), device)?,
        positions: Tensor::from_vec(pos, (b, t), device)?,
    })
}
