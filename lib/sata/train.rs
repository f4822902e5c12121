//! Training SATA (paper §3.4): L = L_rec + λ_KL · KL, with L_rec after SAME: reconstruction of
//! the features (positions, 6D rotations, velocities, contacts), the geodesic rotation angle,
//! smoothness (frame-to-frame changes match), foot contact (feet that touch the ground in the
//! data do not slide in the output) and ground penetration (no joint below the floor).
//!
//! Batches are bucketed by skeleton: a step draws one skeleton as AnyTop's balancing sampler
//! does (every skeleton equally likely, an augmented variant with the set's probability), then
//! `batch` crops of its clips. Features come from `diffusion::data::TrainSet` (AnyTop's
//! representation, augmentation and grouping), de-normalised and divided by a global
//! [`FeatureScale`] instead of per-skeleton statistics (see the module doc of `sata`).

use super::graph::{rest_row, SkeletonGraph};
use super::{SataError, SataModel, FEATURE_DIMS};
use crate::diffusion::data::{Crop, TrainSet};
use crate::diffusion::train::{rotation_distance, AdamW};
use crate::repr::Features;
use crate::rng::{gaussian, SplitMix64};
use candle_core::{Device, Tensor, Var};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Feature groups of AnyTop's 13 dims: position, 6D rotation, velocity, contact.
const GROUPS: [(usize, usize); 4] = [(0, 3), (3, 9), (9, 12), (12, 13)];

/// How features become the model's numbers: `(x - rest) / scale`, with `rest` the skeleton's
/// [`graph::rest_row`] and one divisor per feature dim, for the root token and for the other
/// joints: the root-mean-square of the dim's group of `x - rest` over the training set
/// (contacts stay 0/1). Offsets from the rest pose make the motion, not the body, the signal;
/// dividing (no mean shift) keeps zero velocity at zero; the same numbers serve every skeleton.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureScale {
    pub root: Vec<f32>,
    pub joint: Vec<f32>,
}

impl FeatureScale {
    /// From raw (not normalised) AnyTop features of many skeletons, each with its rest row.
    pub fn measure<'a>(clips: impl IntoIterator<Item = (&'a Features, &'a [f32])>) -> FeatureScale {
        let mut sums = [[0f64; 4]; 2];
        let mut counts = [[0f64; 4]; 2];
        for (c, rest) in clips {
            let width = c.joints * FEATURE_DIMS;
            if rest.len() != width {
                continue;
            }
            for frame in c.data.chunks_exact(width) {
                for (k, (row, r)) in frame.chunks_exact(FEATURE_DIMS).zip(rest.chunks_exact(FEATURE_DIMS)).enumerate() {
                    let side = usize::from(k != 0);
                    for (g, &(a, b)) in GROUPS.iter().enumerate() {
                        sums[side][g] += (a..b).map(|d| ((row[d] - r[d]) as f64).powi(2)).sum::<f64>();
                        counts[side][g] += (b - a) as f64;
                    }
                }
            }
        }
        let expand = |side: usize| -> Vec<f32> {
            let mut out = vec![1f32; FEATURE_DIMS];
            for (g, &(a, b)) in GROUPS.iter().enumerate().take(3) {
                let rms = if counts[side][g] > 0.0 { (sums[side][g] / counts[side][g]).sqrt() } else { 1.0 };
                let rms = if rms.is_finite() && rms > 1e-6 { rms } else { 1.0 };
                out[a..b].iter_mut().for_each(|v| *v = rms as f32);
            }
            out
        };
        FeatureScale { root: expand(0), joint: expand(1) }
    }

    pub fn check(&self) -> Result<(), String> {
        for (what, v) in [("root", &self.root), ("joint", &self.joint)] {
            if v.len() != FEATURE_DIMS || v.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
                return Err(format!("feature scale ({what}): expected {FEATURE_DIMS} positive numbers, got {v:?}"));
            }
        }
        Ok(())
    }

    /// `[1, 1, J, 13]` divisors for a skeleton of `joints` joints.
    pub fn tensor(&self, joints: usize, device: &Device) -> candle_core::Result<Tensor> {
        let mut v = Vec::with_capacity(joints * FEATURE_DIMS);
        for j in 0..joints {
            v.extend_from_slice(if j == 0 { &self.root } else { &self.joint });
        }
        Tensor::from_vec(v, (1, 1, joints, FEATURE_DIMS), device)
    }

    /// Raw features -> the model's numbers, in place (`rest`: `[J * 13]`).
    pub fn apply(&self, f: &mut Features, rest: &[f32]) {
        let width = f.joints * FEATURE_DIMS;
        for frame in f.data.chunks_exact_mut(width.max(1)) {
            for (k, (row, r)) in frame.chunks_exact_mut(FEATURE_DIMS).zip(rest.chunks_exact(FEATURE_DIMS)).enumerate() {
                let s = if k == 0 { &self.root } else { &self.joint };
                row.iter_mut().zip(r).zip(s).for_each(|((v, r), s)| *v = (*v - r) / s);
            }
        }
    }

    /// The model's numbers -> raw features, in place.
    pub fn undo(&self, f: &mut Features, rest: &[f32]) {
        let width = f.joints * FEATURE_DIMS;
        for frame in f.data.chunks_exact_mut(width.max(1)) {
            for (k, (row, r)) in frame.chunks_exact_mut(FEATURE_DIMS).zip(rest.chunks_exact(FEATURE_DIMS)).enumerate() {
                let s = if k == 0 { &self.root } else { &self.joint };
                row.iter_mut().zip(r).zip(s).for_each(|((v, r), s)| *v = *v * s + r);
            }
        }
    }
}

/// Raw features of every clip of every skeleton (and variant) in the set, with the rest row
/// of its skeleton.
pub fn raw_clips(set: &TrainSet) -> Vec<(Features, Vec<f32>)> {
    let all = set.skeletons.iter().chain(set.augmented.iter().flatten());
    all.flat_map(|sk| {
        let rest = rest_row(&sk.skeleton, &sk.section.rig);
        sk.clips.iter().map(move |c| {
            let mut f = c.clone();
            // Statistics were computed from these very clips: shapes match.
            let _ = sk.stats.denormalise(&mut f);
            (f, rest.clone())
        })
    })
    .collect()
}

/// Loss weights (λ of §3.4); the defaults weigh each term about equally at the start.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LossWeights {
    /// The root token's features again, on their own: in the plain MSE the root is one joint
    /// of 20-100, yet its velocity and facing, integrated over the clip, are the whole root
    /// trajectory (RT) and move every joint (JP).
    pub root: f64,
    pub geodesic: f64,
    pub smooth: f64,
    pub contact: f64,
    pub penetration: f64,
    pub kl: f64,
    /// Cross-skeleton latent cycle ([`cycle_loss`]); 0 in checkpoints written before it.
    #[serde(default)]
    pub cycle: f64,
}

impl Default for LossWeights {
    fn default() -> LossWeights {
        LossWeights { root: 1.0, geodesic: 1.0, smooth: 1.0, contact: 0.1, penetration: 1.0, kl: 1e-4, cycle: 0.0 }
    }
}

/// Loss terms of one step (means, before weighting).
#[derive(Clone, Copy, Debug, Default)]
pub struct SataLosses {
    pub total: f64,
    pub reconstruction: f64,
    pub root: f64,
    pub geodesic: f64,
    pub smooth: f64,
    pub contact: f64,
    pub penetration: f64,
    pub kl: f64,
    pub cycle: f64,
}

/// Crops of one skeleton (or variant) for a batch, all of one length: the balancing sampler's
/// draw for the first, then clips of the same skeleton.
pub fn draw_crops(set: &TrainSet, rng: &mut SplitMix64, batch: usize, frames: usize) -> Vec<Crop> {
    let Some(first) = set.sample(rng, 1, frames).pop() else { return Vec::new() };
    let sk = set.data(&first);
    let mut clips = vec![first.clip];
    clips.extend((1..batch).map(|_| rng.below(sk.clips.len())));
    let len = clips.iter().map(|&c| sk.clips[c].frames).min().unwrap_or(0).min(frames);
    clips.into_iter().map(|c| Crop { clip: c, start: rng.below(sk.clips[c].frames - len + 1), frames: len, ..first }).collect()
}

/// Scaled features `[B, T, J, 13]` of same-skeleton crops (`rest`: their skeleton's rest row).
pub fn batch_tensor(set: &TrainSet, crops: &[Crop], scale: &FeatureScale, rest: &[f32], device: &Device) -> Result<Tensor, SataError> {
    let first = crops.first().ok_or_else(|| SataError::Invalid("empty batch".into()))?;
    let sk = set.data(first);
    let mut data = Vec::new();
    for c in crops {
        let mut f = set.crop(c);
        sk.stats.denormalise(&mut f)?;
        scale.apply(&mut f, rest);
        data.extend_from_slice(&f.data);
    }
    Ok(Tensor::from_vec(data, (crops.len(), first.frames, sk.skeleton.len(), FEATURE_DIMS), device)?)
}

/// The loss of reconstructing `x` (scaled, `[B, T, J, 13]`) through the model, with the VAE's
/// sampled latent (noise from `rng`); `scale` is `FeatureScale::tensor` for the skeleton.
pub fn loss(
    model: &SataModel,
    x: &Tensor,
    g: &SkeletonGraph,
    scale: &Tensor,
    weights: &LossWeights,
    rng: &mut SplitMix64,
) -> Result<(Tensor, SataLosses), SataError> {
    let (total, report, _) = loss_with_latent(model, x, g, scale, weights, rng)?;
    Ok((total, report))
}

/// [`loss`], also giving the latent mean `[B, T, latent]` (for [`cycle_loss`]).
fn loss_with_latent(
    model: &SataModel,
    x: &Tensor,
    g: &SkeletonGraph,
    scale: &Tensor,
    weights: &LossWeights,
    rng: &mut SplitMix64,
) -> Result<(Tensor, SataLosses, Tensor), SataError> {
    let (mu, logvar) = model.encode(x, g)?;
    let eps = Tensor::from_vec(gaussian(rng, mu.elem_count()), mu.shape(), mu.device())?;
    let z = (&mu + (logvar.clone() * 0.5)?.exp()?.mul(&eps)?)?;
    let y = model.decode(&z, g)?;
    let rest = Tensor::from_slice(&g.rest, (1, 1, g.joints, FEATURE_DIMS), x.device())?;
    let raw = |v: &Tensor| -> candle_core::Result<Tensor> { v.broadcast_mul(scale)?.broadcast_add(&rest) };
    let (_, t, j, _) = x.dims4()?;
    let rec = (&y - x)?.sqr()?.mean_all()?;
    let root = (y.narrow(2, 0, 1)? - x.narrow(2, 0, 1)?)?.sqr()?.mean_all()?;
    // Rotations compared as rotations, in their own units.
    let rot = |v: &Tensor| -> candle_core::Result<Tensor> { raw(v)?.narrow(3, 3, 6) };
    let geo = rotation_distance(&rot(&y)?, &rot(x)?)?.mean_all()?;
    let smooth = if t > 1 {
        let diff = |v: &Tensor| -> candle_core::Result<Tensor> { v.narrow(1, 1, t - 1)? - v.narrow(1, 0, t - 1)? };
        (diff(&y)? - diff(x)?)?.sqr()?.mean_all()?
    } else {
        rec.zeros_like()?
    };
    // Feet in contact in the data: the output's velocity there should be zero.
    let contact = x.narrow(3, 12, 1)?.broadcast_mul(&y.narrow(3, 9, 3)?.sqr()?)?.mean_all()?;
    // Heights of the non-root joints (dim 1 is absolute height) below the floor.
    let penetration = if j > 1 { raw(&y)?.narrow(2, 1, j - 1)?.narrow(3, 1, 1)?.neg()?.relu()?.mean_all()? } else { rec.zeros_like()? };
    let kl = ((mu.sqr()? + logvar.exp()?)? - 1.0)?.sub(&logvar)?.mean_all()?.affine(0.5, 0.0)?;
    let total = ((((((&rec + (&root * weights.root)?)? + (&geo * weights.geodesic)?)? + (&smooth * weights.smooth)?)? + (&contact * weights.contact)?)?
        + (&penetration * weights.penetration)?)?
        + (&kl * weights.kl)?)?;
    let v = |t: &Tensor| -> candle_core::Result<f64> { Ok(t.to_scalar::<f32>()? as f64) };
    let report = SataLosses {
        total: v(&total)?,
        reconstruction: v(&rec)?,
        root: v(&root)?,
        geodesic: v(&geo)?,
        smooth: v(&smooth)?,
        contact: v(&contact)?,
        penetration: v(&penetration)?,
        kl: v(&kl)?,
        cycle: 0.0,
    };
    Ok((total, report, mu))
}

/// Cross-skeleton latent cycle, a step beyond the paper (which trains on same-skeleton
/// reconstruction only and gets cross-species transfer from data scale we do not have):
/// decode the latent `mu` of one skeleton's motion onto another skeleton `other`, encode that
/// again, and ask for the same latent, relative to how much the latent changes over time (not
/// to its size: most of a latent is the constant "which body, which pose", and a decoder that
/// only reproduced that scored a 3-5% error against the size while standing still; against
/// the change over time the same decoder scored 40-50). Without it our zoo
/// models decoded a dog's latent onto a biped as a standing pose: nothing in training asked the
/// decoder to put a foreign skeleton's motion into a body it was not recorded on. The target
/// is detached (the encoder is taught to read, not to make latents easy to cycle); the output
/// on `other` is also kept above the floor. `scale`: `FeatureScale::tensor` for `other`.
pub fn cycle_loss(model: &SataModel, mu: &Tensor, other: &SkeletonGraph, scale: &Tensor) -> Result<Tensor, SataError> {
    let target = mu.detach();
    let y = model.decode(&target, other)?;
    let (again, _) = model.encode(&y, other)?;
    let size = (target.broadcast_sub(&target.mean_keepdim(1)?)?.sqr()?.mean_all()?.to_scalar::<f32>()? as f64).max(1e-6);
    // log(1 + error / variance): at first the error is ~50 variances, and its plain gradient
    // threw a trained model's reconstruction from 0.4 back to 3 within 40 steps; the log
    // keeps the pull steady from far away and is the plain ratio near 0.
    let cycle = ((again - &target)?.sqr()?.mean_all()? / size)?.affine(1.0, 1.0)?.log()?;
    let j = other.joints;
    if j < 2 {
        return Ok(cycle);
    }
    let rest = Tensor::from_slice(&other.rest, (1, 1, j, FEATURE_DIMS), mu.device())?;
    let height = y.broadcast_mul(scale)?.broadcast_add(&rest)?.narrow(2, 1, j - 1)?.narrow(3, 1, 1)?;
    Ok((cycle + height.neg()?.relu()?.mean_all()?)?)
}

/// Crops of the cycle: at most this many of a batch go through the second decode + encode, so
/// the term costs about half a step, not a whole one.
const CYCLE_CROPS: usize = 4;

/// One training step: draw, loss, backward, AdamW; no update when the loss is not finite.
#[allow(clippy::too_many_arguments)]
pub fn train_step(
    model: &SataModel,
    vars: &BTreeMap<String, Var>,
    opt: &mut AdamW,
    set: &TrainSet,
    scale: &FeatureScale,
    weights: &LossWeights,
    rng: &mut SplitMix64,
    batch: usize,
    device: &Device,
) -> Result<SataLosses, SataError> {
    let crops = draw_crops(set, rng, batch, model.config().window);
    let first = crops.first().ok_or_else(|| SataError::Invalid("the training set gave no crop".into()))?;
    let sk = set.data(first);
    let g = SkeletonGraph::new(&sk.skeleton, &sk.section.rig, &sk.names, device)?;
    let x = batch_tensor(set, &crops, scale, &g.rest, device)?;
    let scale_t = scale.tensor(sk.skeleton.len(), device)?;
    let (mut total, mut report, mu) = loss_with_latent(model, &x, &g, &scale_t, weights, rng)?;
    if weights.cycle > 0.0 {
        // Another skeleton by the balancing sampler's draw; none when it is the same one (or
        // a variant of it: that pair the augmented reconstruction already covers).
        if let Some(draw) = set.sample(rng, 1, 1).pop() {
            let other = set.data(&draw);
            if draw.skeleton != first.skeleton {
                let go = SkeletonGraph::new(&other.skeleton, &other.section.rig, &other.names, device)?;
                let k = crops.len().min(CYCLE_CROPS);
                let c = cycle_loss(model, &mu.narrow(0, 0, k)?, &go, &scale.tensor(other.skeleton.len(), device)?)?;
                report.cycle = c.to_scalar::<f32>()? as f64;
                total = (total + (c * weights.cycle)?)?;
                report.total = total.to_scalar::<f32>()? as f64;
            }
        }
    }
    if !report.total.is_finite() {
        // No update from a NaN gradient: the caller stops with the model as it was.
        return Ok(report);
    }
    let grads = total.backward()?;
    opt.update(vars, &grads)?;
    Ok(report)
}
