//! Training the denoiser (AnyTop paper §3.3, docs/reference/anytop.md §3.3–3.4): x0 prediction,
//! loss = masked MSE in normalised space over real joints and frames plus λ_geo × the geodesic
//! rotation angle, AdamW (lr 1e-4, no weight decay, as the reference), and checkpoints that can
//! resume exactly.
//!
//! The optimiser is ours rather than candle-nn's `AdamW` because a checkpoint must carry the
//! moment estimates (candle-nn keeps them private), and resuming must continue the same run.
//! Noise and timesteps come from our seeded SplitMix64, so the same seed and data give the
//! same run whatever the thread count.

use super::data::{Crop, TrainSet};
use super::schedule::Schedule;
use crate::nn::{batch_from, BatchItem, Denoiser, NnError};
use crate::repr::anytop::{DIMS_ROTATION, DIMS_VELOCITY, DIM_CONTACT};
use crate::rng::{gaussian, SplitMix64};
use candle_core::backprop::GradStore;
use candle_core::cpu_backend::unary_map;
use candle_core::{CpuStorage, CustomOp1, DType, Device, Layout, Shape, Tensor, Var};
use candle_nn::VarMap;
use std::collections::BTreeMap;

/// AdamW with bias correction; state per parameter name.
pub struct AdamW {
    pub lr: f64,
    pub beta1: f64,
    pub beta2: f64,
    pub eps: f64,
    pub weight_decay: f64,
    pub step: u64,
    /// First and second moment estimates per parameter.
    moments: BTreeMap<String, Moments>,
}

/// The moment estimates of one parameter, as flat f32 values in the parameter's layout.
struct Moments {
    m: Vec<f32>,
    v: Vec<f32>,
    shape: Shape,
}

impl AdamW {
    /// PyTorch's defaults with the reference's lr 1e-4 and weight decay 0.
    pub fn new(lr: f64) -> AdamW {
        AdamW { lr, beta1: 0.9, beta2: 0.999, eps: 1e-8, weight_decay: 0.0, step: 0, moments: BTreeMap::new() }
    }

    /// One update of every variable of `vars` from `grads`; variables without a gradient are
    /// left alone.
    pub fn update(&mut self, vars: &BTreeMap<String, Var>, grads: &candle_core::backprop::GradStore) -> candle_core::Result<()> {
        self.update_sum(vars, std::slice::from_ref(grads))
    }

    /// One update from the sum of several gradients (a batch's groups, each with its own
    /// backward pass): a variable's gradient is `parts[0] + parts[1] + ...` in that order, so
    /// the update does not depend on which thread computed which part. Variables no part has
    /// a gradient for are left alone.
    ///
    /// One pass per parameter over its f32 values, in place: the same f32 arithmetic, value for
    /// value, as the candle tensor expressions this replaces (`m * β1 + g * (1 - β1)`, ...;
    /// the test `fused_adamw_matches_the_tensor_formula` keeps that), without their dozen
    /// temporary tensors per parameter.
    pub fn update_sum(&mut self, vars: &BTreeMap<String, Var>, parts: &[candle_core::backprop::GradStore]) -> candle_core::Result<()> {
        self.step += 1;
        let t = self.step as i32;
        let c1 = 1.0 - self.beta1.powi(t);
        let c2 = 1.0 - self.beta2.powi(t);
        let k = AdamWConstants {
            beta1: self.beta1 as f32,
            one_minus_beta1: (1.0 - self.beta1) as f32,
            beta2: self.beta2 as f32,
            one_minus_beta2: (1.0 - self.beta2) as f32,
            inv_c1: (1.0 / c1) as f32,
            inv_c2: (1.0 / c2) as f32,
            eps: self.eps as f32,
            lr: self.lr as f32,
            decay: (self.weight_decay > 0.0).then_some((1.0 - self.lr * self.weight_decay) as f32),
        };
        let mut sum: Vec<f32> = Vec::new();
        for (name, var) in vars {
            let grads: Vec<Tensor> = parts.iter().filter_map(|p| p.get(var.as_tensor())).map(Tensor::contiguous).collect::<candle_core::Result<_>>()?;
            let Some(first) = grads.first() else { continue };
            let n = var.as_tensor().elem_count();
            sum.clear();
            with_f32(first, "gradient", |g| {
                sum.extend_from_slice(g);
                Ok(())
            })?;
            for g in &grads[1..] {
                with_f32(g, "gradient", |g| {
                    sum.iter_mut().zip(g).for_each(|(a, b)| *a += b);
                    Ok(())
                })?;
            }
            if sum.len() != n {
                candle_core::bail!("AdamW: {name} has {n} values, its gradient {}", sum.len());
            }
            let moments =
                self.moments.entry(name.clone()).or_insert_with(|| Moments { m: vec![0.0; n], v: vec![0.0; n], shape: var.as_tensor().shape().clone() });
            if moments.m.len() != n || moments.v.len() != n {
                candle_core::bail!("AdamW: {name} has {n} values, its saved moments {}", moments.m.len());
            }
            let op = AdamWStep { k, grad: &sum, m: std::cell::RefCell::new(&mut moments.m), v: std::cell::RefCell::new(&mut moments.v) };
            var.as_tensor().inplace_op1(&op)?;
        }
        Ok(())
    }

    /// Moments as named tensors (`m.<name>`, `v.<name>`) for a safetensors file.
    pub fn state(&self) -> candle_core::Result<BTreeMap<String, Tensor>> {
        let mut out = BTreeMap::new();
        for (name, moments) in &self.moments {
            out.insert(format!("m.{name}"), Tensor::from_slice(&moments.m, moments.shape.clone(), &Device::Cpu)?);
            out.insert(format!("v.{name}"), Tensor::from_slice(&moments.v, moments.shape.clone(), &Device::Cpu)?);
        }
        Ok(out)
    }

    /// Restore moments saved by `state`.
    pub fn load_state(&mut self, tensors: &std::collections::HashMap<String, Tensor>, step: u64) -> candle_core::Result<()> {
        self.step = step;
        self.moments.clear();
        let values = |t: &Tensor| t.to_dtype(DType::F32)?.flatten_all()?.to_vec1::<f32>();
        for (key, m) in tensors {
            if let Some(name) = key.strip_prefix("m.") {
                if let Some(v) = tensors.get(&format!("v.{name}")) {
                    self.moments.insert(name.to_string(), Moments { m: values(m)?, v: values(v)?, shape: m.shape().clone() });
                }
            }
        }
        Ok(())
    }
}

/// AdamW's per-step constants, in f32 as candle's `tensor * f64` applies them.
#[derive(Clone, Copy, Debug)]
struct AdamWConstants {
    beta1: f32,
    one_minus_beta1: f32,
    beta2: f32,
    one_minus_beta2: f32,
    inv_c1: f32,
    inv_c2: f32,
    eps: f32,
    lr: f32,
    /// `1 - lr * weight_decay` when there is weight decay.
    decay: Option<f32>,
}

/// One parameter's AdamW update, written into the parameter in place.
struct AdamWStep<'a> {
    k: AdamWConstants,
    grad: &'a [f32],
    m: std::cell::RefCell<&'a mut Vec<f32>>,
    v: std::cell::RefCell<&'a mut Vec<f32>>,
}

impl candle_core::InplaceOp1 for AdamWStep<'_> {
    fn name(&self) -> &'static str {
        "adamw-step"
    }

    fn cpu_fwd(&self, storage: &mut CpuStorage, layout: &Layout) -> candle_core::Result<()> {
        let CpuStorage::F32(data) = storage else { candle_core::bail!("AdamW: parameters must be f32") };
        let Some((start, end)) = layout.contiguous_offsets() else { candle_core::bail!("AdamW: parameters must be contiguous") };
        let w = &mut data[start..end];
        let (mut m, mut v) = (self.m.borrow_mut(), self.v.borrow_mut());
        if w.len() != self.grad.len() || m.len() != w.len() || v.len() != w.len() {
            candle_core::bail!("AdamW: {} values, gradient {}, moments {}", w.len(), self.grad.len(), m.len());
        }
        let k = self.k;
        // Each line is one candle op of the tensor formula: `x * a` is `x * a + 0` (affine).
        for (((w, m), v), &g) in w.iter_mut().zip(m.iter_mut()).zip(v.iter_mut()).zip(self.grad) {
            *m = (*m * k.beta1 + 0.0) + (g * k.one_minus_beta1 + 0.0);
            *v = (*v * k.beta2 + 0.0) + ((g * g) * k.one_minus_beta2 + 0.0);
            let update = (*m * k.inv_c1 + 0.0) / ((*v * k.inv_c2 + 0.0).sqrt() * 1.0 + k.eps);
            if let Some(decay) = k.decay {
                *w = *w * decay + 0.0;
            }
            *w -= update * k.lr + 0.0;
        }
        Ok(())
    }
}

/// Runs `f` on the values of a contiguous CPU f32 tensor in place.
fn with_f32<R>(t: &Tensor, what: &str, f: impl FnOnce(&[f32]) -> candle_core::Result<R>) -> candle_core::Result<R> {
    let (storage, layout) = t.storage_and_layout();
    let candle_core::Storage::Cpu(CpuStorage::F32(data)) = &*storage else { candle_core::bail!("{what}: expected f32 values on the CPU") };
    let Some((start, end)) = layout.contiguous_offsets() else { candle_core::bail!("{what}: expected a contiguous tensor") };
    f(&data[start..end])
}

/// The variables of `varmap` by name, in name order.
pub fn named_vars(varmap: &VarMap) -> BTreeMap<String, Var> {
    let data = varmap.data().lock().expect("the VarMap lock is never poisoned: nothing panics while holding it");
    data.iter().map(|(k, v)| (k.clone(), v.clone())).collect()
}

/// What one training step measured.
#[derive(Clone, Copy, Debug)]
pub struct StepStats {
    pub loss: f64,
}

/// What a training step's loss is made of (see `training_loss`): the weights of the rotation
/// and velocity terms next to the MSE, and how the diffusion steps are weighed against each
/// other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LossTerms {
    pub geo: f64,
    pub vel: f64,
    /// Weight of the foot-slide term (`foot_slide_sum`).
    pub foot: f64,
    pub weighting: Weighting,
}

impl LossTerms {
    /// The reference's: MSE + 1 × rotation, every diffusion step alike.
    pub const REFERENCE: LossTerms = LossTerms { geo: 1.0, vel: 0.0, foot: 0.0, weighting: Weighting::X0 };
}

/// How much a crop's error counts, by the diffusion step it was noised to. The model predicts
/// x0 and its error is always measured on x0; the weighting says what that error stands for.
/// Weights are scaled to average 1 over the schedule's steps (drawn uniformly), so the loss
/// keeps its size next to the rotation and velocity terms.
///
/// Why it matters here: under the shifted schedule (`Schedule::cosine_shifted`, shift 10)
/// about half the steps have a signal-to-noise ratio below 0.01. There the best x0 is close to
/// the mean pose and its error is large and irreducible, so with equal weights those steps
/// dominate the loss and the gradient noise (issue 22: longer training made samples stiller).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Weighting {
    /// Every step's x0 error alike: AnyTop's loss.
    X0,
    /// The error of a v-prediction (Salimans & Ho 2022): x0 error × (1 + SNR). Leaves the
    /// noisy steps as they are and counts the nearly clean ones more.
    V,
    /// Min-SNR-γ (Hang et al. 2023) for x0: × min(SNR, γ). Counts the noisy steps by how much
    /// signal they carry and caps the clean ones at γ.
    MinSnr(f64),
}

impl Weighting {
    /// The unscaled weight at signal-to-noise ratio `snr`.
    fn raw(self, snr: f64) -> f64 {
        match self {
            Weighting::X0 => 1.0,
            Weighting::V => 1.0 + snr,
            Weighting::MinSnr(gamma) => snr.min(gamma),
        }
    }

    /// The weight of every step of `schedule`, averaging 1.
    pub fn weights(self, schedule: &Schedule) -> Vec<f64> {
        let raw: Vec<f64> = schedule.alpha_bars.iter().map(|&ab| self.raw(super::schedule::signal_to_noise(ab))).collect();
        let mean = raw.iter().sum::<f64>() / raw.len().max(1) as f64;
        raw.iter().map(|w| if mean > 0.0 { w / mean } else { 1.0 }).collect()
    }
}

impl std::fmt::Display for Weighting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Weighting::X0 => write!(f, "x0"),
            Weighting::V => write!(f, "v"),
            Weighting::MinSnr(gamma) => write!(f, "min-snr:{gamma}"),
        }
    }
}

impl std::str::FromStr for Weighting {
    type Err = String;

    /// `x0`, `v`, `min-snr` (γ = 5, the paper's) or `min-snr:G`.
    fn from_str(text: &str) -> Result<Weighting, String> {
        match text.trim() {
            "x0" => Ok(Weighting::X0),
            "v" => Ok(Weighting::V),
            "min-snr" => Ok(Weighting::MinSnr(5.0)),
            other => {
                let gamma = other.strip_prefix("min-snr:").ok_or_else(|| format!("'{text}' is not a weighting (expected x0, v, min-snr or min-snr:G)"))?;
                match gamma.parse::<f64>() {
                    Ok(g) if g.is_finite() && g > 0.0 && g <= 1e6 => Ok(Weighting::MinSnr(g)),
                    _ => Err(format!("'{gamma}' is not a min-snr cap (expected a number above 0 and at most 1e6)")),
                }
            }
        }
    }
}

/// The crops of one skeleton (or augmented variant) in a step, or a part of them (see
/// `MAX_SUB_BATCH`), in batch order, with their diffusion steps and the noise drawn for them:
/// one sub-batch of the model.
pub struct GroupDraw {
    pub crops: Vec<Crop>,
    pub steps: Vec<u32>,
    /// `(B, T, J, dims)` of the group's padded batch (T = the longest crop + the P_S token).
    pub shape: (usize, usize, usize, usize),
    /// Gaussian noise for the motion tokens, `B * T * J * dims` values (token 0 unused).
    noise: Vec<f32>,
}

/// What a training step draws from its data stream, all of it before any model work: the
/// crops, their diffusion steps, then the noise of each group in the order the groups first
/// appear in the batch (the order the stream always had). So the draws never depend on how
/// the groups are then spread over threads.
pub struct StepDraw {
    pub groups: Vec<GroupDraw>,
    /// Real motion tokens of the whole batch (frames 1.. of real joints): the rotation
    /// term's normaliser, and times `dims` the MSE's.
    pub tokens: f64,
    pub dims: usize,
    /// Values the velocity term covers (pairs of real consecutive motion frames, times joints
    /// and dims), or none when a group has fewer than 2 motion frames (then the term is off
    /// for the step, as it always was).
    pub velocity_values: Option<f64>,
}

/// The most crops one sub-batch of the model takes. A skeleton with more crops in a step is
/// split into near-equal sub-batches, so that a batch of one skeleton (fine-tuning, or the
/// paper's single-creature runs) still gives the threads separate work: one sub-batch's
/// backward pass is mostly small elementwise ops that run on one thread, which is why one
/// 16-crop group gained only 1.19x from a second core (issue 28). The split depends only on
/// the crops, never on the thread count, so the bytes stay the same at any `--threads`, and
/// the model gives a crop the same output in any sub-batch, so only the cost changes.
/// Why 4: its matmuls still have thousands of rows (4 crops x 41 frames x J joints), and a
/// paper-width sub-batch's largest activation (7k tokens x ff 1024 floats) stays under glibc's
/// 32 MiB mmap threshold (see `nn::keep_freed_memory`), so it can be reused rather than mapped
/// afresh each step. Measured quietly (BENCHMARKS.md, "Sub-batches") only against no split: 4
/// against 8 was compared under load only, and why one thread got faster as well is not
/// established.
///
/// A step of one skeleton alone (a fine-tune on one creature's clips) is cut in at least two
/// when it has two crops or more: at the fine-tune's batch of 4, one sub-batch of 4 left the
/// second core idle (a chicken fine-tune ran 3.2-3.5 steps/s on two threads, about what one
/// thread gives; BENCHMARKS.md, "A fine-tune's lone batch in two").
pub const MAX_SUB_BATCH: usize = 4;

/// `items` in order, cut into the fewest runs of at most `most` items, of near-equal length
/// (the first runs take the one extra item).
fn split_evenly(items: Vec<usize>, most: usize) -> Vec<Vec<usize>> {
    let runs = items.len().div_ceil(most.max(1)).max(1);
    let (base, extra) = (items.len() / runs, items.len() % runs);
    let mut rest = items.into_iter();
    (0..runs).map(|r| rest.by_ref().take(base + usize::from(r < extra)).collect()).filter(|run: &Vec<usize>| !run.is_empty()).collect()
}

/// Draw `batch` crops and timesteps, group the crops by skeleton (or variant), split large
/// groups into sub-batches (`MAX_SUB_BATCH`), and draw each sub-batch's noise (see
/// `StepDraw`).
pub fn draw_step(set: &TrainSet, schedule: &Schedule, rng: &mut SplitMix64, batch: usize, crop: usize) -> Result<StepDraw, NnError> {
    draw_split(set, schedule, rng, batch, crop, MAX_SUB_BATCH, true)
}

/// `draw_step` with sub-batches of at most `most` crops; `lone_in_two`: a step of one group
/// is cut in at least two.
fn draw_split(
    set: &TrainSet,
    schedule: &Schedule,
    rng: &mut SplitMix64,
    batch: usize,
    crop: usize,
    most: usize,
    lone_in_two: bool,
) -> Result<StepDraw, NnError> {
    let crops = set.sample(rng, batch, crop);
    let steps: Vec<u32> = (0..batch).map(|_| rng.below(schedule.len()) as u32).collect();
    let mut order: Vec<(usize, Option<usize>)> = Vec::new();
    for c in &crops {
        if !order.contains(&(c.skeleton, c.variant)) {
            order.push((c.skeleton, c.variant));
        }
    }
    if order.is_empty() {
        return Err(NnError::Shape { what: "training batch", expected: "at least one crop".into(), got: vec![0] });
    }
    let most = if lone_in_two && order.len() == 1 { most.min(crops.len().div_ceil(2)) } else { most };
    let (mut tokens, mut pairs, mut velocity) = (0usize, 0usize, true);
    let mut dims = 0;
    let mut groups = Vec::with_capacity(order.len());
    let parts = order.iter().flat_map(|&key| {
        let chosen: Vec<usize> = (0..crops.len()).filter(|&i| (crops[i].skeleton, crops[i].variant) == key).collect();
        split_evenly(chosen, most)
    });
    for chosen in parts {
        let part_crops: Vec<Crop> = chosen.iter().map(|&i| crops[i]).collect();
        let part_steps: Vec<u32> = chosen.iter().map(|&i| steps[i]).collect();
        let clip = |c: &Crop| &set.data(c).clips[c.clip];
        let b = part_crops.len();
        let t = part_crops.iter().map(|c| c.frames).max().unwrap_or(0) + 1;
        let j = part_crops.iter().map(|c| clip(c).joints).max().unwrap_or(0);
        dims = clip(&part_crops[0]).dims;
        for c in &part_crops {
            tokens += c.frames * clip(c).joints;
            pairs += c.frames.saturating_sub(1) * clip(c).joints;
        }
        velocity &= t > 2;
        let noise = gaussian(rng, b * t * j * dims);
        groups.push(GroupDraw { crops: part_crops, steps: part_steps, shape: (b, t, j, dims), noise });
    }
    Ok(StepDraw { groups, tokens: tokens as f64, dims, velocity_values: velocity.then_some((pairs * dims) as f64) })
}

/// The training loss of one batch: draw `batch` crops and timesteps, noise the motion (never
/// the rest token), predict x0; loss = masked MSE (normalised space) + `terms.geo` × the
/// geodesic rotation distance of the 6D rotations (physical space), both over real joints and
/// frames, as the reference (§3.3, λ_geo = 1 in its training commands); plus `terms.vel` ×
/// the MSE of the frame-to-frame change of the prediction against the clean motion's (MDM's
/// velocity loss, in normalised space over pairs of real frames). The velocity term is ours:
/// the reference has none, and issue 22 measured that our undertrained model's x0 predictions
/// change more from frame to frame than the motion does (jitter) at mid noise levels.
///
/// The crops of each skeleton (or augmented variant) go through the model as their own
/// sub-batch: padding every crop to the batch's largest skeleton (88 joints for the centipede
/// next to 14 for the fish) would spend most of the attention work on padding. The model gives
/// a clip the same output alone or padded (nn tests), so this changes the cost, not the loss.
///
/// This is the whole batch's loss as one graph for one backward pass: the reference that
/// `step_gradients` (what training runs) is checked against.
#[allow(clippy::too_many_arguments)]
pub fn training_loss(
    model: &Denoiser,
    set: &TrainSet,
    schedule: &Schedule,
    rng: &mut SplitMix64,
    batch: usize,
    crop: usize,
    terms: LossTerms,
    device: &Device,
) -> Result<Tensor, NnError> {
    let draw = draw_step(set, schedule, rng, batch, crop)?;
    let mut total: Option<LossSums> = None;
    for group in &draw.groups {
        let part = loss_sums(model, set, group, terms, terms.vel != 0.0, schedule, device)?;
        total = Some(match total {
            None => part,
            Some(t) => LossSums {
                squared: (t.squared + part.squared)?,
                values: t.values + part.values,
                rotation: match (t.rotation, part.rotation) {
                    (Some(a), Some(b)) => Some((a + b)?),
                    _ => None,
                },
                tokens: t.tokens + part.tokens,
                velocity: match (t.velocity, part.velocity) {
                    (Some((a, n)), Some((b, m))) => Some(((a + b)?, n + m)),
                    _ => None,
                },
                foot: match (t.foot, part.foot) {
                    (Some(a), Some(b)) => Some((a + b)?),
                    _ => None,
                },
            },
        });
    }
    let Some(sums) = total else { return Err(NnError::Shape { what: "training batch", expected: "at least one crop".into(), got: vec![0] }) };
    let mut loss = (sums.squared / sums.values.max(1.0))?;
    if let Some(rotation) = sums.rotation.filter(|_| terms.geo != 0.0) {
        loss = (&loss + ((rotation / sums.tokens.max(1.0))? * terms.geo)?)?;
    }
    if let Some((velocity, values)) = sums.velocity.filter(|_| terms.vel != 0.0) {
        loss = (&loss + ((velocity / values.max(1.0))? * terms.vel)?)?;
    }
    if let Some(foot) = sums.foot {
        loss = (&loss + ((foot / sums.tokens.max(1.0))? * terms.foot)?)?;
    }
    Ok(loss)
}

/// The loss of a drawn step and its gradient, as one gradient store per group (in group
/// order; `AdamW::update_sum` adds them in that order).
///
/// The loss is a sum over groups: each group's squared errors, rotation distances and
/// velocity errors over the whole batch's normalisers, which the draw knows before any
/// forward pass. So each group's share is a loss of its own, with its own forward and
/// backward pass, and the groups run in parallel on the current rayon pool (spread by
/// estimated cost; a thread that runs out of groups helps with the others' matmuls). What a
/// group computes does not depend on which thread runs it, and the shares are added in group
/// order, so the loss and the gradients are the same bytes for any number of threads.
/// Returns the loss (the shares' sum, in f64) and the gradients.
pub fn step_gradients(
    model: &Denoiser,
    set: &TrainSet,
    schedule: &Schedule,
    draw: &StepDraw,
    terms: LossTerms,
    device: &Device,
) -> Result<(f64, Vec<GradStore>), NnError> {
    use rayon::prelude::*;
    let values = draw.tokens * draw.dims as f64;
    let velocity_values = draw.velocity_values.filter(|_| terms.vel != 0.0);
    let share = |group: &GroupDraw| -> Result<(f64, GradStore), NnError> {
        let sums = loss_sums(model, set, group, terms, velocity_values.is_some(), schedule, device)?;
        let mut loss = (sums.squared / values.max(1.0))?;
        if let Some(rotation) = sums.rotation {
            loss = (&loss + ((rotation / draw.tokens.max(1.0))? * terms.geo)?)?;
        }
        if let (Some((velocity, _)), Some(count)) = (sums.velocity, velocity_values) {
            loss = (&loss + ((velocity / count.max(1.0))? * terms.vel)?)?;
        }
        // Over the batch's tokens, as the rotation term: the draw knows them before any pass.
        if let Some(foot) = sums.foot {
            loss = (&loss + ((foot / draw.tokens.max(1.0))? * terms.foot)?)?;
        }
        let value = loss.to_scalar::<f32>()? as f64;
        Ok((value, loss.backward()?))
    };
    let cfg = model.config();
    let costs: Vec<f64> = draw.groups.iter().map(|g| group_cost(g.shape, cfg.width, cfg.ff, cfg.window)).collect();
    let lists = balance(&costs, rayon::current_num_threads());
    type Share = Result<(f64, GradStore), NnError>;
    let done: Vec<Vec<(usize, Share)>> = lists.into_par_iter().map(|list| list.into_iter().map(|g| (g, share(&draw.groups[g]))).collect()).collect();
    let mut slots: Vec<Option<Share>> = (0..draw.groups.len()).map(|_| None).collect();
    for (g, result) in done.into_iter().flatten() {
        slots[g] = Some(result);
    }
    let mut loss = 0.0;
    let mut grads = Vec::with_capacity(slots.len());
    for slot in slots {
        let Some(result) = slot else { return Err(NnError::Shape { what: "training groups", expected: "every group computed".into(), got: vec![] }) };
        let (value, g) = result?;
        loss += value;
        grads.push(g);
    }
    Ok((loss, grads))
}

/// A group's rough cost (multiply-adds of its forward pass), to spread groups over threads.
fn group_cost((b, t, j, _): (usize, usize, usize, usize), width: usize, ff: usize, window: usize) -> f64 {
    let tokens = (b * t * j) as f64;
    let d = width as f64;
    tokens * (8.0 * d * d + 2.0 * d * ff as f64 + 2.0 * d * (j + t.min(window + 1)) as f64)
}

/// Items (by cost) into at most `lists` lists, largest first onto the least loaded list
/// (ties: the lower index), so the lists take about equally long. Only the timing depends on
/// it, never the result.
fn balance(costs: &[f64], lists: usize) -> Vec<Vec<usize>> {
    let n = lists.clamp(1, costs.len().max(1));
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
    let mut out: Vec<(f64, Vec<usize>)> = vec![(0.0, Vec::new()); n];
    for i in order {
        let lightest = (0..n).min_by(|&a, &b| out[a].0.total_cmp(&out[b].0).then(a.cmp(&b))).unwrap_or(0);
        out[lightest].0 += costs[i];
        out[lightest].1.push(i);
    }
    out.into_iter().map(|(_, l)| l).filter(|l| !l.is_empty()).collect()
}

/// Unnormalised loss terms of one sub-batch: summed squared error and the number of values it
/// covers, summed rotation distance (when asked for) and the number of tokens.
struct LossSums {
    squared: Tensor,
    values: f64,
    rotation: Option<Tensor>,
    tokens: f64,
    /// Summed squared error of frame-to-frame changes and the number of values it covers.
    velocity: Option<(Tensor, f64)>,
    /// Summed foot-slide error (`foot_slide_sum`), when asked for.
    foot: Option<Tensor>,
}

fn loss_sums(
    model: &Denoiser,
    set: &TrainSet,
    group: &GroupDraw,
    terms: LossTerms,
    velocity: bool,
    schedule: &Schedule,
    device: &Device,
) -> Result<LossSums, NnError> {
    let (crops, steps) = (&group.crops, &group.steps);
    let features: Vec<_> = crops.iter().map(|c| set.crop(c)).collect();
    let items: Vec<BatchItem> = crops
        .iter()
        .zip(&features)
        .map(|(c, f)| {
            let s = set.data(c);
            // Temporal positions count from the crop's random offset (`Crop::position`), not
            // from its start in the clip as the reference's do: with the start the model learns
            // what each clip does at each frame index, and from pure noise predicts the average
            // of all clips at that index, which stands still (issue 22: a 1-skeleton proxy's
            // samples moved with energy ratio 0.35 with the start added and 0.64 without, at
            // noise shift 10). Without any offset, a sample longer than the crops reaches
            // positions training never showed, and its motion fades after the crop length.
            let start = u32::try_from(c.position).unwrap_or(u32::MAX);
            BatchItem { features: f, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start }
        })
        .collect();
    let clean = batch_from(&items, steps, device)?;
    let (b, t, j, d) = clean.dims()?;
    if (b, t, j, d) != group.shape {
        return Err(NnError::Shape { what: "training group", expected: format!("{:?}", group.shape), got: vec![b, t, j, d] });
    }
    let noise = Tensor::from_slice(&group.noise, (b, t, j, d), device)?;
    let (a, s): (Vec<f32>, Vec<f32>) = steps.iter().map(|&k| schedule.noise_coefficients(k as usize)).map(|(a, s)| (a as f32, s as f32)).unzip();
    let a = Tensor::from_vec(a, (b, 1, 1, 1), device)?;
    let s = Tensor::from_vec(s, (b, 1, 1, 1), device)?;
    // Token 0 is the rest pose: conditioning, kept clean.
    let motion_token = Tensor::cat(&[Tensor::zeros((1, 1, 1, 1), DType::F32, device)?, Tensor::ones((1, t - 1, 1, 1), DType::F32, device)?], 1)?;
    let keep = (motion_token.broadcast_mul(&(a.clone() - 1.0)?)? + 1.0)?;
    let noisy = (clean.x.broadcast_mul(&keep)? + noise.broadcast_mul(&motion_token.broadcast_mul(&s)?)?)?;
    let mut input = clean.clone();
    input.x = noisy;
    let predicted = model.forward(&input)?;
    // Real motion tokens only: frames 1.. that exist, joints that exist.
    let mask = clean.frame_mask.reshape((b, t, 1, 1))?.broadcast_mul(&clean.joint_mask.reshape((b, 1, j, 1))?)?.broadcast_mul(&motion_token)?;
    let tokens = mask.sum_all()?.to_scalar::<f32>()? as f64;
    // The errors count by their crop's diffusion step; the normalisers stay plain counts.
    let step_weight = match terms.weighting {
        Weighting::X0 => None,
        weighting => {
            let all = weighting.weights(schedule);
            let w: Vec<f32> = steps.iter().map(|&k| all[k as usize] as f32).collect();
            Some(Tensor::from_vec(w, (b, 1, 1, 1), device)?)
        }
    };
    let weighed = |x: Tensor| -> candle_core::Result<Tensor> {
        match &step_weight {
            Some(w) => x.broadcast_mul(w),
            None => Ok(x),
        }
    };
    // Values weigh by the skeleton's own units when it trains under the fallback (padding: 1).
    let value_weights = if crops.iter().any(|c| set.data(c).loss_weights.is_some()) {
        let mut w = vec![1f32; b * j * d];
        for (i, c) in crops.iter().enumerate() {
            if let Some(lw) = &set.data(c).loss_weights {
                w[i * j * d..i * j * d + lw.len()].copy_from_slice(lw);
            }
        }
        Some(Tensor::from_vec(w, (b, 1, j, d), device)?)
    } else {
        None
    };
    let weighed_values = |x: Tensor| -> candle_core::Result<Tensor> {
        match &value_weights {
            Some(w) => weighed(x.broadcast_mul(w)?),
            None => weighed(x),
        }
    };
    let squared = weighed_values((&predicted - &clean.x)?.sqr()?.broadcast_mul(&mask)?)?.sum_all()?;
    let values = tokens * d as f64;
    // Frame-to-frame changes of motion frames 1..t-1 (token 0 is the rest pose, never a
    // neighbour); a pair counts where both frames are real.
    let velocity = if velocity && t > 2 {
        let change = |x: &Tensor| -> candle_core::Result<Tensor> { x.narrow(1, 2, t - 2)? - x.narrow(1, 1, t - 2)? };
        let pair_mask = (mask.narrow(1, 2, t - 2)? * mask.narrow(1, 1, t - 2)?)?;
        let sum = weighed_values((change(&predicted)? - change(&clean.x)?)?.sqr()?.broadcast_mul(&pair_mask)?)?.sum_all()?;
        let count = pair_mask.sum_all()?.to_scalar::<f32>()? as f64 * d as f64;
        Some((sum, count))
    } else {
        None
    };
    // The rotation and foot terms work in physical units: undo each skeleton's normalisation
    // (padded joints get mean 0, std 1; they are masked anyway). Built once for both.
    let with_foot = terms.foot != 0.0 && t > 2;
    let stats = if terms.geo != 0.0 || with_foot { Some(physical_stats(set, crops, j, d, device)?) } else { None };
    let foot = match &stats {
        Some((mean, std)) if with_foot => {
            let physical = |x: &Tensor| -> candle_core::Result<Tensor> { x.broadcast_mul(std)?.broadcast_add(mean) };
            let clean_physical = physical(&clean.x)?;
            let velocity_std = std.narrow(3, DIMS_VELOCITY.start, 3)?;
            let pair_mask = (mask.narrow(1, 2, t - 2)? * mask.narrow(1, 1, t - 2)?)?;
            let error = foot_slide_error(&physical(&predicted)?, &clean_physical, &velocity_std)?;
            // Only where the clip's own foot is planted (the contact channel, 0 or 1 in physical units).
            let contact = clean_physical.narrow(1, 1, t - 2)?.narrow(3, DIM_CONTACT, 1)?.ge(0.5)?.to_dtype(DType::F32)?;
            // Counted by the signal's share of the input (ᾱ): from a noisy input the model cannot
            // know which frames are planted, and the term then only teaches it to hold every joint
            // still (a 1-creature proxy: energy 0.78 -> 0.28 with the term at every step).
            let signal = a.sqr()?;
            Some(weighed(error.broadcast_mul(&contact)?.broadcast_mul(&pair_mask)?.broadcast_mul(&signal)?)?.sum_all()?)
        }
        _ => None,
    };
    let rotation = match &stats {
        Some((mean, std)) if terms.geo != 0.0 => {
            let (mean, std) = (mean.narrow(3, DIMS_ROTATION.start, 6)?, std.narrow(3, DIMS_ROTATION.start, 6)?);
            let physical = |x: &Tensor| -> candle_core::Result<Tensor> { x.narrow(3, DIMS_ROTATION.start, 6)?.broadcast_mul(&std)?.broadcast_add(&mean) };
            let geo = rotation_distance(&physical(&predicted)?, &physical(&clean.x)?)?;
            Some(weighed(geo.unsqueeze(3)?.broadcast_mul(&mask)?)?.sum_all()?)
        }
        _ => None,
    };
    Ok(LossSums { squared, values, rotation, tokens, velocity, foot })
}

/// Each crop's per-joint means and spreads (`STD_EPSILON` added), `(b, 1, j, d)`; padded
/// joints get mean 0, spread 1 (they are masked anyway).
fn physical_stats(set: &TrainSet, crops: &[Crop], j: usize, d: usize, device: &Device) -> candle_core::Result<(Tensor, Tensor)> {
    let b = crops.len();
    let (mut mean, mut std) = (vec![0f32; b * j * d], vec![1f32; b * j * d]);
    for (i, c) in crops.iter().enumerate() {
        let sk = set.data(c);
        let n = sk.skeleton.len() * d;
        mean[i * j * d..i * j * d + n].copy_from_slice(&sk.stats.mean[..n]);
        for (o, &v) in std[i * j * d..i * j * d + n].iter_mut().zip(&sk.stats.std[..n]) {
            *o = v + crate::repr::anytop::STD_EPSILON;
        }
    }
    Ok((Tensor::from_vec(mean, (b, 1, j, d), device)?, Tensor::from_vec(std, (b, 1, j, d), device)?))
}

/// Where each joint goes from frame k to k + 1 (k = 1 .. t − 2; token 0 is the rest pose) as
/// the prediction's positions and root imply it, against where the clip's joint goes
/// (its velocity channels), in the clip's velocity spreads, squared and summed over x, y, z:
/// `(b, t − 2, j, 1)`, in physical units in, nothing masked.
///
/// Why: the decoder places a joint by its RIC position turned back by the root's facing, on a
/// root moved by the root's velocity channels (`recover`). The model predicts those
/// separately, so a foot can be planted in the clip and slide in the sample when the legs and
/// the root disagree (issue 22: 91% of the sampled near-ground steps had the contact channel on
/// and still slid). The displacement in frame k + 1's facing is
/// `p[k+1] − R(θ[k+1] − θ[k]) p[k] + (v_root.x, 0, v_root.z)[k]`, which for the clip itself is
/// exactly its velocity channels; AnyTop's own foot term (off by default) compares only the
/// RIC positions, which move with the root.
pub fn foot_slide_error(predicted: &Tensor, clean: &Tensor, velocity_std: &Tensor) -> candle_core::Result<Tensor> {
    let t = predicted.dim(1)?;
    let dims = |x: &Tensor, start: usize, n: usize| x.narrow(3, start, n);
    // Facing as (cos θ, sin θ): the root's 6D holds R_y(θ)'s first column (cos θ, 0, −sin θ).
    let root = predicted.narrow(2, 0, 1)?;
    let (a, z) = (dims(&root, DIMS_ROTATION.start, 1)?, dims(&root, DIMS_ROTATION.start + 2, 1)?);
    let norm = (a.sqr()?.add(&z.sqr()?)? + 1e-8)?.sqrt()?;
    let (cos, sin) = (a.div(&norm)?, z.neg()?.div(&norm)?);
    let (c0, s0, c1, s1) = (cos.narrow(1, 1, t - 2)?, sin.narrow(1, 1, t - 2)?, cos.narrow(1, 2, t - 2)?, sin.narrow(1, 2, t - 2)?);
    // R(θ1 − θ0) acting on (x, z): x' = c x + s z, z' = −s x + c z.
    let c = ((&c1 * &c0)? + (&s1 * &s0)?)?;
    let s = ((&s1 * &c0)? - (&c1 * &s0)?)?;
    let p0 = predicted.narrow(1, 1, t - 2)?;
    let p1 = predicted.narrow(1, 2, t - 2)?;
    let (x0, y0, z0) = (dims(&p0, 0, 1)?, dims(&p0, 1, 1)?, dims(&p0, 2, 1)?);
    let root_velocity = root.narrow(1, 1, t - 2)?;
    let (vx, vz) = (dims(&root_velocity, DIMS_VELOCITY.start, 1)?, dims(&root_velocity, DIMS_VELOCITY.start + 2, 1)?);
    let turned_x = (c.broadcast_mul(&x0)? + s.broadcast_mul(&z0)?)?;
    let turned_z = (c.broadcast_mul(&z0)? - s.broadcast_mul(&x0)?)?;
    let moved = Tensor::cat(
        &[dims(&p1, 0, 1)?.sub(&turned_x)?.broadcast_add(&vx)?, (dims(&p1, 1, 1)? - y0)?, dims(&p1, 2, 1)?.sub(&turned_z)?.broadcast_add(&vz)?],
        3,
    )?;
    let target = dims(&clean.narrow(1, 1, t - 2)?, DIMS_VELOCITY.start, 3)?;
    (moved - target)?.broadcast_div(velocity_std)?.sqr()?.sum_keepdim(3)
}

/// One training step: `draw_step`, `step_gradients` (the groups in parallel on the current
/// rayon pool), AdamW; no update when the loss is not finite. Same bytes at any thread count.
#[allow(clippy::too_many_arguments)]
pub fn train_step(
    model: &Denoiser,
    vars: &BTreeMap<String, Var>,
    opt: &mut AdamW,
    set: &TrainSet,
    schedule: &Schedule,
    rng: &mut SplitMix64,
    batch: usize,
    crop: usize,
    terms: LossTerms,
    device: &Device,
) -> Result<StepStats, NnError> {
    let draw = draw_step(set, schedule, rng, batch, crop)?;
    let (value, grads) = step_gradients(model, set, schedule, &draw, terms, device)?;
    if !value.is_finite() {
        // No update from a NaN gradient: the caller stops with the model as it was.
        return Ok(StepStats { loss: value });
    }
    opt.update_sum(vars, &grads)?;
    Ok(StepStats { loss: value })
}

/// The cosine argument is clamped to [−1 + ε, 1 − ε] before arccos, as the reference does, so
/// the angle and its gradient stay finite at θ = 0 and θ = π.
pub const ARCCOS_EPSILON: f64 = 1e-6;

/// θ = arccos(clamp(x, −1 + ε, 1 − ε)) elementwise, with a backward: candle has no arccos.
/// The derivative is −1/√(1 − x²) inside the clamp and 0 outside it (the clamp's derivative,
/// as in the reference's PyTorch), at most ~707 in magnitude.
struct ClampedArccos;

/// The derivative of `ClampedArccos` at its input (a forward-only op: no second derivatives).
struct ClampedArccosDerivative;

fn clamped(x: f64) -> f64 {
    x.clamp(-1.0 + ARCCOS_EPSILON, 1.0 - ARCCOS_EPSILON)
}

fn derivative(x: f64) -> f64 {
    if x.abs() <= 1.0 - ARCCOS_EPSILON {
        -1.0 / (1.0 - x * x).sqrt()
    } else {
        0.0
    }
}

/// Apply `f` to every element of a float CPU tensor (f32 in f64 arithmetic, so the clamp
/// bounds are exact).
fn map_float(name: &'static str, storage: &CpuStorage, layout: &Layout, f: fn(f64) -> f64) -> candle_core::Result<(CpuStorage, Shape)> {
    let out = match storage {
        CpuStorage::F32(v) => CpuStorage::F32(unary_map(v, layout, |x| f(x as f64) as f32)),
        CpuStorage::F64(v) => CpuStorage::F64(unary_map(v, layout, f)),
        _ => candle_core::bail!("{name}: expected f32 or f64 values"),
    };
    Ok((out, layout.shape().clone()))
}

impl CustomOp1 for ClampedArccos {
    fn name(&self) -> &'static str {
        "clamped-arccos"
    }

    fn cpu_fwd(&self, storage: &CpuStorage, layout: &Layout) -> candle_core::Result<(CpuStorage, Shape)> {
        map_float(self.name(), storage, layout, |x| clamped(x).acos())
    }

    fn bwd(&self, arg: &Tensor, _res: &Tensor, grad_res: &Tensor) -> candle_core::Result<Option<Tensor>> {
        let slope = arg.apply_op1_no_bwd(&ClampedArccosDerivative)?;
        Ok(Some(grad_res.mul(&slope)?))
    }
}

impl CustomOp1 for ClampedArccosDerivative {
    fn name(&self) -> &'static str {
        "clamped-arccos-derivative"
    }

    fn cpu_fwd(&self, storage: &CpuStorage, layout: &Layout) -> candle_core::Result<(CpuStorage, Shape)> {
        map_float(self.name(), storage, layout, derivative)
    }
}

/// arccos(clamp(x, −1 + ε, 1 − ε)) of every element, differentiable (see `ClampedArccos`).
pub fn clamped_arccos(x: &Tensor) -> candle_core::Result<Tensor> {
    x.apply_op1(ClampedArccos)
}

/// The geodesic angle θ (radians, in [0, π]) between two 6D rotations (first two matrix
/// columns, `[..., 6]`), per token: arccos((tr(R̂ᵀR) − 1) / 2), clamped as the reference's
/// geodesic loss. The 6D values are orthonormalised first (Gram–Schmidt, third column by cross
/// product), so unnormalised network outputs are fine.
pub fn rotation_distance(a: &Tensor, b: &Tensor) -> candle_core::Result<Tensor> {
    let frame = |x: &Tensor| -> candle_core::Result<[Tensor; 3]> {
        let last = x.rank() - 1;
        let norm = |v: &Tensor| -> candle_core::Result<Tensor> { v.broadcast_div(&(v.sqr()?.sum_keepdim(last)? + 1e-8)?.sqrt()?) };
        let c1 = norm(&x.narrow(last, 0, 3)?)?;
        let a2 = x.narrow(last, 3, 3)?;
        let c2 = norm(&(&a2 - c1.broadcast_mul(&(&c1 * &a2)?.sum_keepdim(last)?)?)?)?;
        let comp = |v: &Tensor, k: usize| v.narrow(last, k, 1);
        let (x1, y1, z1) = (comp(&c1, 0)?, comp(&c1, 1)?, comp(&c1, 2)?);
        let (x2, y2, z2) = (comp(&c2, 0)?, comp(&c2, 1)?, comp(&c2, 2)?);
        let c3 = Tensor::cat(&[((&y1 * &z2)? - (&z1 * &y2)?)?, ((&z1 * &x2)? - (&x1 * &z2)?)?, ((&x1 * &y2)? - (&y1 * &x2)?)?], last)?;
        Ok([c1, c2, c3])
    };
    let (fa, fb) = (frame(a)?, frame(b)?);
    let last = a.rank() - 1;
    let mut trace = (&fa[0] * &fb[0])?.sum(last)?;
    for k in 1..3 {
        trace = (trace + (&fa[k] * &fb[k])?.sum(last)?)?;
    }
    clamped_arccos(&((trace - 1.0)? * 0.5)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::data::Augmentation;
    use crate::embed::NameTable;
    use crate::motion::Clip;
    use crate::nn::{seeded_var_builder, DenoiserConfig};
    use crate::skeleton::topology;

    fn set() -> TrainSet {
        let (skeleton, motion) = crate::synth::creature("quadruped", 0).unwrap();
        let clips = vec![Clip { name: "q.bvh".into(), skeleton, motion }];
        // Augmented: the resume test then also covers variant draws.
        TrainSet::build(clips, NameTable::builtin().unwrap(), topology::DEFAULT_DMAX, &Augmentation::with_seed(2)).unwrap().0
    }

    /// Losses of `steps` steps from a fresh model, optionally saving and reloading model and
    /// optimiser after `resume_at` steps.
    fn run(set: &TrainSet, steps: usize, resume_at: Option<usize>) -> Vec<f64> {
        let dev = Device::Cpu;
        let cfg = DenoiserConfig::tiny();
        let schedule = Schedule::cosine(100);
        let mut varmap = VarMap::new();
        let mut model = Denoiser::new(seeded_var_builder(&varmap, 1, &dev), &cfg).unwrap();
        let mut vars = named_vars(&varmap);
        let mut opt = AdamW::new(1e-3);
        let mut rng = SplitMix64::new(5);
        let mut losses = Vec::new();
        for i in 0..steps {
            if resume_at == Some(i) {
                let dir = std::env::temp_dir().join(format!("menagerie-train-{}", std::process::id()));
                std::fs::create_dir_all(&dir).unwrap();
                varmap.save(dir.join("model.safetensors")).unwrap();
                candle_core::safetensors::save(&opt.state().unwrap().into_iter().collect(), dir.join("opt.safetensors")).unwrap();
                // A new process: fresh (differently seeded) parameters, then the checkpoint.
                varmap = VarMap::new();
                model = Denoiser::new(seeded_var_builder(&varmap, 99, &dev), &cfg).unwrap();
                varmap.load(dir.join("model.safetensors")).unwrap();
                vars = named_vars(&varmap);
                let state = candle_core::safetensors::load(dir.join("opt.safetensors"), &dev).unwrap();
                let step = opt.step;
                opt = AdamW::new(1e-3);
                opt.load_state(&state, step).unwrap();
                let _ = std::fs::remove_dir_all(&dir);
            }
            losses.push(train_step(&model, &vars, &mut opt, set, &schedule, &mut rng, 2, 12, LossTerms::REFERENCE, &dev).unwrap().loss);
        }
        losses
    }

    #[test]
    fn same_seed_same_run_and_resume_continues_it() {
        let set = set();
        let a = run(&set, 4, None);
        assert!(a.iter().all(|l| l.is_finite() && *l > 0.0), "{a:?}");
        assert_eq!(a, run(&set, 4, None), "same seed, same losses");
        assert_eq!(a, run(&set, 4, Some(2)), "a resumed run continues the same run");
    }

    /// Every parameter's values, by name.
    fn parameters(vars: &BTreeMap<String, Var>) -> BTreeMap<String, Vec<f32>> {
        vars.iter().map(|(n, v)| (n.clone(), v.as_tensor().flatten_all().unwrap().to_vec1::<f32>().unwrap())).collect()
    }

    #[test]
    fn one_and_two_threads_train_the_same_bytes() {
        let set = set();
        let dev = Device::Cpu;
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let varmap = VarMap::new();
                let model = Denoiser::new(seeded_var_builder(&varmap, 3, &dev), &DenoiserConfig::tiny()).unwrap();
                let vars = named_vars(&varmap);
                let mut opt = AdamW::new(1e-3);
                let schedule = Schedule::cosine(100);
                let losses: Vec<u64> = (0..2)
                    .map(|k| {
                        let mut rng = SplitMix64::new(40 + k);
                        train_step(
                            &model,
                            &vars,
                            &mut opt,
                            &set,
                            &schedule,
                            &mut rng,
                            6,
                            12,
                            LossTerms { geo: 1.0, vel: 0.5, foot: 1.0, weighting: Weighting::MinSnr(5.0) },
                            &dev,
                        )
                        .unwrap()
                        .loss
                        .to_bits()
                    })
                    .collect();
                (losses, parameters(&vars))
            })
        };
        // Several groups per step (the augmented variants), so the threads share the work.
        let draw = draw_step(&set, &Schedule::cosine(100), &mut SplitMix64::new(40), 6, 12).unwrap();
        assert!(draw.groups.len() > 1, "{} groups", draw.groups.len());
        let (one, two) = (run(1), run(2));
        assert_eq!(one.0, two.0, "losses");
        assert!(one.1 == two.1, "parameters differ between 1 and 2 threads");
        assert_eq!(one, run(2), "and again");
    }

    #[test]
    fn per_group_gradients_add_up_to_the_one_graph_gradient() {
        let set = set();
        let dev = Device::Cpu;
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 4, &dev), &DenoiserConfig::tiny()).unwrap();
        let vars = named_vars(&varmap);
        let schedule = Schedule::cosine(100);
        for (geo, vel, foot, weighting) in [(1.0, 0.0, 0.0, Weighting::X0), (1.0, 1.0, 2.0, Weighting::V), (0.0, 0.5, 1.0, Weighting::MinSnr(5.0))] {
            let terms = LossTerms { geo, vel, foot, weighting };
            let reference = training_loss(&model, &set, &schedule, &mut SplitMix64::new(9), 6, 12, terms, &dev).unwrap();
            let want = reference.backward().unwrap();
            let draw = draw_step(&set, &schedule, &mut SplitMix64::new(9), 6, 12).unwrap();
            assert!(draw.groups.len() > 1);
            let (loss, parts) = step_gradients(&model, &set, &schedule, &draw, terms, &dev).unwrap();
            let expected = reference.to_scalar::<f32>().unwrap() as f64;
            assert!((loss - expected).abs() < 1e-5 * expected.abs(), "loss {loss} against {expected}");
            for (name, var) in &vars {
                let w = want.get(var.as_tensor()).unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
                let mut sum = vec![0f32; w.len()];
                for p in &parts {
                    let g = p.get(var.as_tensor()).unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
                    sum.iter_mut().zip(&g).for_each(|(a, b)| *a += b);
                }
                let scale = w.iter().fold(0f32, |m, v| m.max(v.abs())).max(1e-12);
                let worst = w.iter().zip(&sum).fold(0f32, |m, (a, b)| m.max((a - b).abs()));
                assert!(worst <= 1e-4 * scale, "{name} (geo {geo}, vel {vel}): off by {worst}, largest {scale}");
            }
        }
    }

    #[test]
    fn split_evenly_makes_the_fewest_near_equal_runs() {
        let runs = |n: usize, most: usize| split_evenly((0..n).collect(), most).iter().map(Vec::len).collect::<Vec<_>>();
        assert_eq!(runs(16, 8), vec![8, 8]);
        assert_eq!(runs(17, 8), vec![6, 6, 5]);
        assert_eq!(runs(3, 8), vec![3]);
        assert!(runs(0, 8).is_empty());
        assert_eq!(split_evenly((0..5).collect(), 2), vec![vec![0, 1], vec![2, 3], vec![4]]);
    }

    /// Rows `from..to` of a group (crops, steps and their noise) as a group of its own.
    fn rows(group: &GroupDraw, from: usize, to: usize) -> GroupDraw {
        let (_, t, j, d) = group.shape;
        let per = t * j * d;
        GroupDraw {
            crops: group.crops[from..to].to_vec(),
            steps: group.steps[from..to].to_vec(),
            shape: (to - from, t, j, d),
            noise: group.noise[from * per..to * per].to_vec(),
        }
    }

    /// One synthetic quadruped clip, unaugmented, and AnyTop's schedule: a set whose every step
    /// is one skeleton's group.
    fn one_quadruped() -> (TrainSet, Schedule) {
        let (skeleton, motion) = crate::synth::creature("quadruped", 1).unwrap();
        let clips = vec![Clip { name: "q.bvh".into(), skeleton, motion }];
        let set = TrainSet::build(clips, NameTable::builtin().unwrap(), topology::DEFAULT_DMAX, &Augmentation::none()).unwrap().0;
        (set, Schedule::cosine(100))
    }

    #[test]
    fn a_lone_skeletons_small_batch_is_cut_in_two() {
        let (set, schedule) = one_quadruped();
        let sizes = |batch: usize| -> Vec<usize> {
            draw_step(&set, &schedule, &mut SplitMix64::new(3), batch, 12).unwrap().groups.iter().map(|g| g.crops.len()).collect()
        };
        // The fine-tune's batch of 4 gives both cores work; one crop stays one.
        assert_eq!(sizes(4), vec![2, 2]);
        assert_eq!(sizes(3), vec![2, 1]);
        assert_eq!(sizes(1), vec![1]);
        assert_eq!(sizes(16), vec![4, 4, 4, 4]);
    }

    /// A crop's position offset is what the model sees as its first frame's position: the
    /// same draw with the crops moved to another offset gives another loss. (Two runs that
    /// differ in `--position-jitter` differ anyway, through the extra draws in their stream.)
    #[test]
    fn a_crops_position_reaches_the_model() {
        let (set, schedule) = one_quadruped();
        let mut draw = draw_step(&set, &schedule, &mut SplitMix64::new(3), 2, 12).unwrap();
        let dev = Device::Cpu;
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 6, &dev), &DenoiserConfig::tiny()).unwrap();
        let terms = LossTerms { geo: 1.0, vel: 0.0, foot: 0.0, weighting: Weighting::V };
        let at_zero = step_gradients(&model, &set, &schedule, &draw, terms, &dev).unwrap().0;
        assert_eq!(step_gradients(&model, &set, &schedule, &draw, terms, &dev).unwrap().0, at_zero, "the loss of a draw is repeatable");
        draw.groups.iter_mut().flat_map(|g| g.crops.iter_mut()).for_each(|c| c.position = 300);
        let moved = step_gradients(&model, &set, &schedule, &draw, terms, &dev).unwrap().0;
        assert!((moved - at_zero).abs() > 1e-6 * at_zero.abs(), "loss {at_zero} at position 0, {moved} at 300");
    }

    #[test]
    fn splitting_a_skeletons_crops_into_sub_batches_changes_neither_loss_nor_gradient() {
        let (set, schedule) = one_quadruped();
        // One skeleton, more crops than a sub-batch takes: the step splits it.
        let batch = MAX_SUB_BATCH + 3;
        let draw = draw_step(&set, &schedule, &mut SplitMix64::new(3), batch, 12).unwrap();
        let sizes: Vec<usize> = draw.groups.iter().map(|g| g.crops.len()).collect();
        assert!(sizes.len() > 1 && sizes.iter().all(|&n| n <= MAX_SUB_BATCH) && sizes.iter().sum::<usize>() == batch, "{sizes:?}");
        // The same step as one group, and that group cut by hand into the same parts.
        let whole = draw_split(&set, &schedule, &mut SplitMix64::new(3), batch, 12, usize::MAX, false).unwrap();
        assert_eq!(whole.groups.len(), 1);
        let g = &whole.groups[0];
        assert_eq!(g.shape.1, 13, "every crop is full length, so the parts keep the group's shape");
        let mut from = 0;
        let groups = sizes
            .iter()
            .map(|&n| {
                from += n;
                rows(g, from - n, from)
            })
            .collect();
        let parts = StepDraw { groups, tokens: whole.tokens, dims: whole.dims, velocity_values: whole.velocity_values };
        let dev = Device::Cpu;
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 6, &dev), &DenoiserConfig::tiny()).unwrap();
        let terms = LossTerms { geo: 1.0, vel: 0.5, foot: 0.0, weighting: Weighting::V };
        let (a, ga) = step_gradients(&model, &set, &schedule, &whole, terms, &dev).unwrap();
        let (b, gb) = step_gradients(&model, &set, &schedule, &parts, terms, &dev).unwrap();
        // f32 sums in another order: rounding only.
        assert!((a - b).abs() < 1e-4 * a.abs(), "loss {a} whole, {b} split");
        for (name, var) in named_vars(&varmap) {
            let sum = |stores: &[GradStore]| {
                let mut out: Vec<f32> = Vec::new();
                for s in stores {
                    let g = s.get(var.as_tensor()).unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
                    out.resize(g.len(), 0.0);
                    out.iter_mut().zip(&g).for_each(|(o, v)| *o += v);
                }
                out
            };
            let (w, s) = (sum(&ga), sum(&gb));
            // The floor: a key bias's gradient is zero up to rounding (softmax ignores it).
            let scale = w.iter().fold(0f32, |m, v| m.max(v.abs())).max(1e-6);
            let worst = w.iter().zip(&s).fold(0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(worst <= 1e-4 * scale, "{name}: off by {worst}, largest {scale}");
        }
    }

    #[test]
    fn balance_spreads_costs_and_keeps_every_item() {
        let lists = balance(&[5.0, 1.0, 4.0, 2.0, 3.0], 2);
        assert_eq!(lists, vec![vec![0, 3, 1], vec![2, 4]]);
        assert_eq!(balance(&[1.0, 2.0], 8), vec![vec![1], vec![0]]);
        assert_eq!(balance(&[3.0], 1), vec![vec![0]]);
        assert!(balance(&[], 2).is_empty());
    }

    /// AdamW as candle tensor expressions (how it was written before the fused pass).
    fn tensor_adamw(opt: &AdamW, w: &Tensor, g: &Tensor, m: &Tensor, v: &Tensor) -> (Tensor, Tensor, Tensor) {
        let t = opt.step as i32;
        let c1 = 1.0 - opt.beta1.powi(t);
        let c2 = 1.0 - opt.beta2.powi(t);
        let m = ((m * opt.beta1).unwrap() + (g * (1.0 - opt.beta1)).unwrap()).unwrap();
        let v = ((v * opt.beta2).unwrap() + (g.sqr().unwrap() * (1.0 - opt.beta2)).unwrap()).unwrap();
        let update = ((&m / c1).unwrap() / ((&v / c2).unwrap().sqrt().unwrap() + opt.eps).unwrap()).unwrap();
        let mut next = w.clone();
        if opt.weight_decay > 0.0 {
            next = (&next * (1.0 - opt.lr * opt.weight_decay)).unwrap();
        }
        next = (next - (update * opt.lr).unwrap()).unwrap();
        (next, m, v)
    }

    #[test]
    fn fused_adamw_matches_the_tensor_formula() {
        let dev = Device::Cpu;
        let n = 37;
        for decay in [0.0, 0.01] {
            let mut rng = SplitMix64::new(7);
            let w0 = gaussian(&mut rng, n);
            let var = Var::from_vec(w0.clone(), n, &dev).unwrap();
            let vars: BTreeMap<String, Var> = [("w".to_string(), var.clone())].into();
            let mut opt = AdamW::new(3e-3);
            opt.weight_decay = decay;
            let zeros = Tensor::zeros(n, DType::F32, &dev).unwrap();
            let (mut w, mut m, mut v) = (Tensor::from_vec(w0, n, &dev).unwrap(), zeros.clone(), zeros);
            for _ in 0..5 {
                // Two gradient parts, as two groups' backward passes give: d(w . a)/dw = a exactly.
                let (a, b) = (Tensor::from_vec(gaussian(&mut rng, n), n, &dev).unwrap(), Tensor::from_vec(gaussian(&mut rng, n), n, &dev).unwrap());
                let parts: Vec<GradStore> = [&a, &b].iter().map(|g| (var.as_tensor() * *g).unwrap().sum_all().unwrap().backward().unwrap()).collect();
                opt.update_sum(&vars, &parts).unwrap();
                (w, m, v) = tensor_adamw(&opt, &w, &(&a + &b).unwrap(), &m, &v);
                let bits = |t: &Tensor| t.to_vec1::<f32>().unwrap().iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(var.as_tensor()), bits(&w), "parameters, decay {decay}, step {}", opt.step);
                let state = opt.state().unwrap();
                assert_eq!((bits(&state["m.w"]), bits(&state["v.w"])), (bits(&m), bits(&v)), "moments, step {}", opt.step);
            }
        }
    }

    /// The clip's own features move every joint exactly as its velocity channels say (the
    /// encoder's definition), on a creature that turns; a joint pushed off in one frame does not.
    #[test]
    fn foot_slide_error_is_zero_on_the_clip_itself() {
        use crate::document::AnyTopSection;
        use crate::repr::anytop::RigOptions;
        let dev = Device::Cpu;
        for name in ["quadruped", "snake", "biped"] {
            let (skeleton, mut motion) = crate::synth::creature(name, 0).unwrap();
            // Turn the whole creature about the vertical, faster and faster, so the facing changes.
            let n = motion.joints;
            for f in 0..motion.frames {
                let turn = glam::DQuat::from_rotation_y(0.0004 * (f * f) as f64);
                motion.rotations[f * n] = turn * motion.rotations[f * n];
                motion.translations[f * n] = turn * motion.translations[f * n];
            }
            let section = AnyTopSection::new(&skeleton, &motion.first_frames(2), &RigOptions::default()).unwrap();
            let f = section.rig.encode(&skeleton, &motion).unwrap().features;
            let (t, j, d) = (f.frames.min(60), f.joints, f.dims);
            let mut data = f.data[..t * j * d].to_vec();
            let x = Tensor::from_vec(data.clone(), (1, t, j, d), &dev).unwrap();
            let ones = Tensor::ones((1, 1, j, 3), DType::F32, &dev).unwrap();
            let e = foot_slide_error(&x, &x, &ones).unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
            // Some root turning is in the crop, so a wrong sign of the turn would show.
            let turn = (1..t).map(|k| (f.at(k, 0)[3] - f.at(k - 1, 0)[3]).abs()).fold(0f32, f32::max);
            assert!(turn > 1e-3, "{name}: the crop should turn (max change of cos {turn})");
            let worst = e.iter().cloned().fold(0f32, f32::max);
            assert!(worst < 1e-8, "{name}: the clip's own joints should move as their velocities say, worst {worst}");
            // Frame 10's last joint pushed 0.1 along x: pairs (9, 10) and (10, 11) are off.
            data[(10 * j + j - 1) * d] += 0.1;
            let pushed = Tensor::from_vec(data, (1, t, j, d), &dev).unwrap();
            let e = foot_slide_error(&pushed, &x, &ones).unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
            // Row k of the error is the pair (k + 1, k + 2).
            for (k, &v) in e.chunks(j).map(|r| &r[j - 1]).enumerate() {
                let expected = if k + 1 == 9 || k + 1 == 10 { 0.01 } else { 0.0 };
                assert!((v - expected).abs() < 2e-3, "{name}: pair {} of the pushed joint: {v}, expected about {expected}", k + 1);
            }
        }
    }

    #[test]
    fn rotation_distance_is_the_geodesic_angle() {
        let dev = Device::Cpu;
        // Identity (columns x, y) and rotations by 90 and 180 degrees about z; 6D are unnormalised.
        let r = |c1: [f32; 3], c2: [f32; 3]| Tensor::from_vec([c1, c2].concat(), (1, 6), &dev).unwrap();
        let id = r([2.0, 0.0, 0.0], [0.3, 1.0, 0.0]);
        let d = |a: &Tensor, b: &Tensor| rotation_distance(a, b).unwrap().to_vec1::<f32>().unwrap()[0] as f64;
        // Within the clamp: arccos(1 - 1e-6) = 1.4e-3 rad.
        let edge = (1.0 - ARCCOS_EPSILON).acos();
        assert!((d(&id, &id) - edge).abs() < 2e-4, "equal rotations: {}", d(&id, &id));
        assert!((d(&id, &r([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0])) - std::f64::consts::FRAC_PI_2).abs() < 1e-5, "90 degrees");
        assert!((d(&id, &r([-1.0, 0.0, 0.0], [0.0, -1.0, 0.0])) - (std::f64::consts::PI - edge)).abs() < 2e-4, "180 degrees");
        let c = (0.5f32).cos();
        let s = (0.5f32).sin();
        assert!((d(&id, &r([c, s, 0.0], [-s, c, 0.0])) - 0.5).abs() < 1e-4, "0.5 rad");
    }

    #[test]
    fn clamped_arccos_gradient_is_finite_and_matches_finite_differences() {
        let dev = Device::Cpu;
        let xs = [-0.9f64, -0.3, 0.0, 0.4, 0.95, 0.999];
        let x = Var::from_vec(xs.to_vec(), xs.len(), &dev).unwrap();
        let grads = clamped_arccos(x.as_tensor()).unwrap().sum_all().unwrap().backward().unwrap();
        let g = grads.get(x.as_tensor()).unwrap().to_vec1::<f64>().unwrap();
        for (&x0, &gx) in xs.iter().zip(&g) {
            let h = 1e-6;
            let numeric = ((x0 + h).acos() - (x0 - h).acos()) / (2.0 * h);
            assert!((gx - numeric).abs() < 1e-5 * numeric.abs().max(1.0), "x = {x0}: {gx} against {numeric}");
        }
        // At and beyond the clamp: the angle stays finite and the gradient is 0, never inf/NaN.
        let x = Var::from_vec(vec![1.0f32, -1.0, 1.5, -3.0], 4, &dev).unwrap();
        let theta = clamped_arccos(x.as_tensor()).unwrap();
        assert!(theta.to_vec1::<f32>().unwrap().iter().all(|t| t.is_finite() && (0.0..=std::f32::consts::PI).contains(t)));
        let g = theta.sum_all().unwrap().backward().unwrap().get(x.as_tensor()).unwrap().to_vec1::<f32>().unwrap();
        assert_eq!(g, vec![0.0; 4]);
        // Through the whole rotation distance, against a finite difference in one 6D input.
        let b = Tensor::from_vec(vec![1.0f64, 0.0, 0.0, 0.0, 1.0, 0.0], (1, 6), &dev).unwrap();
        let a0 = [0.8f64, 0.5, 0.1, -0.4, 0.9, 0.2];
        let a = Var::from_vec(a0.to_vec(), (1, 6), &dev).unwrap();
        let g = rotation_distance(a.as_tensor(), &b)
            .unwrap()
            .sum_all()
            .unwrap()
            .backward()
            .unwrap()
            .get(a.as_tensor())
            .unwrap()
            .flatten_all()
            .unwrap()
            .to_vec1::<f64>()
            .unwrap();
        let theta = |v: [f64; 6]| rotation_distance(&Tensor::from_vec(v.to_vec(), (1, 6), &dev).unwrap(), &b).unwrap().to_vec1::<f64>().unwrap()[0];
        for k in 0..6 {
            let (mut up, mut down) = (a0, a0);
            up[k] += 1e-6;
            down[k] -= 1e-6;
            let numeric = (theta(up) - theta(down)) / 2e-6;
            assert!(g[k].is_finite() && (g[k] - numeric).abs() < 1e-4, "component {k}: {} against {numeric}", g[k]);
        }
    }

    #[test]
    fn every_parameter_gets_a_finite_gradient_from_the_training_loss() {
        let dev = Device::Cpu;
        let set = set();
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 4, &dev), &DenoiserConfig::tiny()).unwrap();
        let loss = training_loss(
            &model,
            &set,
            &Schedule::cosine(100),
            &mut SplitMix64::new(9),
            3,
            12,
            LossTerms { geo: 1.0, vel: 1.0, foot: 0.0, weighting: Weighting::X0 },
            &dev,
        )
        .unwrap();
        let grads = loss.backward().unwrap();
        let vars = named_vars(&varmap);
        assert!(!vars.is_empty());
        for (name, var) in &vars {
            let g = grads.get(var.as_tensor()).unwrap_or_else(|| panic!("{name}: no gradient"));
            let norm = g.sqr().unwrap().sum_all().unwrap().to_scalar::<f32>().unwrap();
            assert!(norm > 0.0 && norm.is_finite(), "{name}: gradient norm {norm}");
        }
    }

    #[test]
    fn loss_weights_scale_each_values_error() {
        let dev = Device::Cpu;
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 4, &dev), &DenoiserConfig::tiny()).unwrap();
        let (mut set, schedule) = one_quadruped();
        let loss = |set: &TrainSet, geo: f64| {
            let terms = LossTerms { geo, vel: 0.5, foot: 0.0, weighting: Weighting::V };
            training_loss(&model, set, &schedule, &mut SplitMix64::new(9), 3, 12, terms, &dev).unwrap().to_scalar::<f32>().unwrap() as f64
        };
        let (plain, plain_geo) = (loss(&set, 0.0), loss(&set, 1.0));
        let n = set.skeletons[0].stats.std.len();
        set.skeletons[0].loss_weights = Some(vec![3.0; n]);
        // The MSE and velocity terms triple; the rotation term (radians) is left as it was.
        let (tripled, tripled_geo) = (loss(&set, 0.0), loss(&set, 1.0));
        assert!((tripled - 3.0 * plain).abs() <= 1e-4 * tripled, "{tripled} vs 3 x {plain}");
        assert!(((tripled_geo - tripled) - (plain_geo - plain)).abs() <= 1e-4 * plain_geo, "rotation term changed");
        // A weight on one value (joint 1's height) moves the loss up by that value's share only.
        let mut one = vec![1.0; n];
        one[crate::repr::anytop::FEATURE_DIMS + 1] = 2.0;
        set.skeletons[0].loss_weights = Some(one);
        let single = loss(&set, 0.0);
        assert!(single > plain && single < tripled, "{single}: plain {plain}, all tripled {tripled}");
    }

    /// The loss of one fixed draw from an untrained model with the terms `terms(w)` makes, at
    /// weights 0, 1 and 2 of the term under test.
    fn losses_at_weights(terms: impl Fn(f64) -> LossTerms) -> (f64, f64, f64) {
        let dev = Device::Cpu;
        let set = set();
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 4, &dev), &DenoiserConfig::tiny()).unwrap();
        let loss = |w: f64| {
            training_loss(&model, &set, &Schedule::cosine(100), &mut SplitMix64::new(9), 3, 12, terms(w), &dev).unwrap().to_scalar::<f32>().unwrap() as f64
        };
        (loss(0.0), loss(1.0), loss(2.0))
    }

    #[test]
    fn the_velocity_loss_adds_the_error_of_frame_to_frame_changes() {
        let (off, one, two) = losses_at_weights(|vel| LossTerms { geo: 1.0, vel, foot: 0.0, weighting: Weighting::X0 });
        // Same draws, so the term is linear in its weight; an untrained model's changes are off.
        assert!(one > off, "{one} vs {off}");
        assert!(((two - off) - 2.0 * (one - off)).abs() < 1e-4 * two.abs().max(1.0), "{off} {one} {two}");
    }

    #[test]
    fn the_foot_loss_adds_the_slide_of_planted_joints() {
        let (off, one, two) = losses_at_weights(|foot| LossTerms { geo: 1.0, vel: 0.0, foot, weighting: Weighting::V });
        // The quadruped's crops have planted feet, and an untrained model moves them.
        assert!(one > off, "{one} vs {off}");
        assert!(((two - off) - 2.0 * (one - off)).abs() < 1e-4 * two.abs().max(1.0), "{off} {one} {two}");
    }

    #[test]
    fn weightings_average_one_and_order_the_steps_as_their_formulas() {
        let schedule = Schedule::cosine_shifted(100, 10.0);
        for w in [Weighting::X0, Weighting::V, Weighting::MinSnr(5.0), Weighting::MinSnr(0.01)] {
            let weights = w.weights(&schedule);
            let mean = weights.iter().sum::<f64>() / weights.len() as f64;
            assert!((mean - 1.0).abs() < 1e-12, "{w}: mean {mean}");
            assert!(weights.iter().all(|x| x.is_finite() && *x >= 0.0), "{w}");
        }
        assert!(Weighting::X0.weights(&schedule).iter().all(|&x| x == 1.0));
        // Noise grows with the step: v counts the clean end more, min-SNR the noisy end less.
        let v = Weighting::V.weights(&schedule);
        let m = Weighting::MinSnr(5.0).weights(&schedule);
        assert!(v[0] > v[50] && v[50] >= v[99], "{} {} {}", v[0], v[50], v[99]);
        assert!(m[0] > 100.0 * m[60], "{} {}", m[0], m[60]);
        // A cap below every step's SNR weighs them all alike.
        let schedule = Schedule::cosine(100);
        let floor = schedule.alpha_bars.iter().map(|&ab| super::super::schedule::signal_to_noise(ab)).fold(f64::INFINITY, f64::min);
        assert!(Weighting::MinSnr(floor / 2.0).weights(&schedule).iter().all(|&x| (x - 1.0).abs() < 1e-12));
    }

    #[test]
    fn weightings_parse_and_print_back() {
        for text in ["x0", "v", "min-snr:5", "min-snr:0.5"] {
            let w: Weighting = text.parse().unwrap();
            assert_eq!(w.to_string(), text);
        }
        assert_eq!("min-snr".parse::<Weighting>().unwrap(), Weighting::MinSnr(5.0));
        for bad in ["", "eps", "min-snr:", "min-snr:-1", "min-snr:nan", "min-snr:inf", "min-snr:0"] {
            assert!(bad.parse::<Weighting>().is_err(), "{bad:?} parsed");
        }
    }

    #[test]
    fn a_weighting_scales_each_crops_error_by_its_steps_weight() {
        // One crop per draw: the weighted loss is the plain loss times that step's weight.
        let dev = Device::Cpu;
        let set = set();
        let varmap = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&varmap, 4, &dev), &DenoiserConfig::tiny()).unwrap();
        let schedule = Schedule::cosine_shifted(100, 10.0);
        for seed in [3, 9, 21] {
            let loss = |weighting| {
                let terms = LossTerms { geo: 1.0, vel: 0.5, foot: 0.0, weighting };
                training_loss(&model, &set, &schedule, &mut SplitMix64::new(seed), 1, 12, terms, &dev).unwrap().to_scalar::<f32>().unwrap() as f64
            };
            let step = draw_step(&set, &schedule, &mut SplitMix64::new(seed), 1, 12).unwrap().groups[0].steps[0] as usize;
            let w = Weighting::MinSnr(5.0).weights(&schedule)[step];
            let (plain, weighted) = (loss(Weighting::X0), loss(Weighting::MinSnr(5.0)));
            assert!((weighted - w * plain).abs() <= 1e-5 * weighted.abs().max(1e-3), "step {step}: {weighted} vs {w} x {plain}");
        }
    }

    #[test]
    fn adamw_moves_parameters_against_the_gradient() {
        let dev = Device::Cpu;
        let var = Var::from_vec(vec![1.0f32, -2.0], 2, &dev).unwrap();
        let vars: BTreeMap<String, Var> = [("w".to_string(), var.clone())].into();
        let mut opt = AdamW::new(0.1);
        for _ in 0..50 {
            let loss = var.as_tensor().sqr().unwrap().sum_all().unwrap();
            let grads = loss.backward().unwrap();
            opt.update(&vars, &grads).unwrap();
        }
        let w = var.as_tensor().to_vec1::<f32>().unwrap();
        assert!(w.iter().all(|x| x.abs() < 0.5), "minimising w² moves w towards 0: {w:?}");
    }
}
