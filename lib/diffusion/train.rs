//! Training the denoiser (AnyTop §3.3–3.4): x0 prediction, loss = masked MSE in normalised
//! space over real joints and frames, AdamW (lr 1e-4, no weight decay, as the reference), and
//! checkpoints that can resume exactly.
//!
//! The optimiser is ours rather than candle-nn's `AdamW` because a checkpoint must carry the
//! moment estimates (candle-nn keeps them private), and resuming must continue the same run.
//! Noise and timesteps come from our seeded SplitMix64, so the same seed and data give the
//! same run whatever the thread count.

use super::data::{Crop, TrainSet};
use super::schedule::Schedule;
use crate::nn::{batch_from, BatchItem, Denoiser};
use crate::synth::SplitMix64;
use candle_core::{DType, Device, Tensor, Var};
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
    /// (first moment, second moment) per parameter.
    moments: BTreeMap<String, (Tensor, Tensor)>,
}

impl AdamW {
    /// PyTorch's defaults with the reference's lr 1e-4 and weight decay 0.
    pub fn new(lr: f64) -> AdamW {
        AdamW { lr, beta1: 0.9, beta2: 0.999, eps: 1e-8, weight_decay: 0.0, step: 0, moments: BTreeMap::new() }
    }

    /// One update of every variable of `vars` from `grads`; variables without a gradient are
    /// left alone.
    pub fn update(&mut self, vars: &BTreeMap<String, Var>, grads: &candle_core::backprop::GradStore) -> candle_core::Result<()> {
        self.step += 1;
        let t = self.step as i32;
        let c1 = 1.0 - self.beta1.powi(t);
        let c2 = 1.0 - self.beta2.powi(t);
        for (name, var) in vars {
            let Some(g) = grads.get(var.as_tensor()) else { continue };
            let (m, v) = match self.moments.get(name) {
                Some((m, v)) => (m.clone(), v.clone()),
                None => (g.zeros_like()?, g.zeros_like()?),
            };
            let m = ((m * self.beta1)? + (g * (1.0 - self.beta1))?)?;
            let v = ((v * self.beta2)? + (g.sqr()? * (1.0 - self.beta2))?)?;
            let update = ((&m / c1)? / ((&v / c2)?.sqrt()? + self.eps)?)?;
            let mut next = var.as_tensor().clone();
            if self.weight_decay > 0.0 {
                next = (&next * (1.0 - self.lr * self.weight_decay))?;
            }
            next = (next - (update * self.lr)?)?;
            var.set(&next)?;
            self.moments.insert(name.clone(), (m, v));
        }
        Ok(())
    }

    /// Moments as named tensors (`m.<name>`, `v.<name>`) for a safetensors file.
    pub fn state(&self) -> BTreeMap<String, Tensor> {
        let mut out = BTreeMap::new();
        for (name, (m, v)) in &self.moments {
            out.insert(format!("m.{name}"), m.clone());
            out.insert(format!("v.{name}"), v.clone());
        }
        out
    }

    /// Restore moments saved by `state`.
    pub fn load_state(&mut self, tensors: &std::collections::HashMap<String, Tensor>, step: u64) {
        self.step = step;
        self.moments.clear();
        for (key, m) in tensors {
            if let Some(name) = key.strip_prefix("m.") {
                if let Some(v) = tensors.get(&format!("v.{name}")) {
                    self.moments.insert(name.to_string(), (m.clone(), v.clone()));
                }
            }
        }
    }
}

/// The variables of `varmap` by name, in name order.
pub fn named_vars(varmap: &VarMap) -> BTreeMap<String, Var> {
    let data = varmap.data().lock().expect("the VarMap lock is never poisoned: nothing panics while holding it");
    data.iter().map(|(k, v)| (k.clone(), v.clone())).collect()
}

/// Standard normal values from `rng` (Box–Muller), as f32.
pub fn gaussian(rng: &mut SplitMix64, n: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(n + 1);
    while out.len() < n {
        let u1 = rng.unit().max(f64::MIN_POSITIVE);
        let u2 = rng.unit();
        let r = (-2.0 * u1.ln()).sqrt();
        let a = std::f64::consts::TAU * u2;
        out.push((r * a.cos()) as f32);
        out.push((r * a.sin()) as f32);
    }
    out.truncate(n);
    out
}

/// What one training step measured.
#[derive(Clone, Copy, Debug)]
pub struct StepStats {
    pub loss: f64,
}

/// One training step: draw a batch of crops and timesteps, noise the motion (never the rest
/// token), predict x0; loss = masked MSE (normalised space) + `lambda_geo` × the rotation
/// distance of the 6D rotations (physical space), both over real joints and frames, as the
/// reference (§3.3, λ_geo = 1 in its training commands); backward, AdamW.
///
/// The crops of each skeleton go through the model as their own sub-batch: padding every crop
/// to the batch's largest skeleton (88 joints for the centipede next to 14 for the fish) would
/// spend most of the attention work on padding. The model gives a clip the same output alone
/// or padded (nn tests), so this changes the cost, not the loss.
pub fn train_step(
    model: &Denoiser,
    vars: &BTreeMap<String, Var>,
    opt: &mut AdamW,
    set: &TrainSet,
    schedule: &Schedule,
    rng: &mut SplitMix64,
    batch: usize,
    crop: usize,
    lambda_geo: f64,
    device: &Device,
) -> anyhow::Result<StepStats> {
    let crops = set.sample(rng, batch, crop);
    let steps: Vec<u32> = (0..batch).map(|_| rng.below(schedule.len()) as u32).collect();
    let mut order: Vec<usize> = Vec::new();
    for c in &crops {
        if !order.contains(&c.skeleton) {
            order.push(c.skeleton);
        }
    }
    let mut total: Option<LossSums> = None;
    for skeleton in order {
        let chosen: Vec<usize> = (0..crops.len()).filter(|&i| crops[i].skeleton == skeleton).collect();
        let part_crops: Vec<Crop> = chosen.iter().map(|&i| crops[i]).collect();
        let part_steps: Vec<u32> = chosen.iter().map(|&i| steps[i]).collect();
        let part = loss_sums(model, set, schedule, &part_crops, &part_steps, rng, device)?;
        total = Some(match total {
            None => part,
            Some(t) => LossSums { squared: (t.squared + part.squared)?, values: t.values + part.values, rotation: (t.rotation + part.rotation)?, tokens: t.tokens + part.tokens },
        });
    }
    let Some(sums) = total else { anyhow::bail!("an empty training batch") };
    let mse = (sums.squared / sums.values.max(1.0))?;
    let geo = (sums.rotation / sums.tokens.max(1.0))?;
    let loss = (&mse + (geo * lambda_geo)?)?;
    let grads = loss.backward()?;
    opt.update(vars, &grads)?;
    Ok(StepStats { loss: loss.to_scalar::<f32>()? as f64 })
}

/// Unnormalised loss terms of one sub-batch: summed squared error and the number of values it
/// covers, summed rotation distance and the number of tokens.
struct LossSums {
    squared: Tensor,
    values: f64,
    rotation: Tensor,
    tokens: f64,
}

fn loss_sums(model: &Denoiser, set: &TrainSet, schedule: &Schedule, crops: &[Crop], steps: &[u32], rng: &mut SplitMix64, device: &Device) -> anyhow::Result<LossSums> {
    let features: Vec<_> = crops.iter().map(|c| set.crop(c)).collect();
    let items: Vec<BatchItem> = crops
        .iter()
        .zip(&features)
        .map(|(c, f)| {
            let s = &set.skeletons[c.skeleton];
            BatchItem { features: f, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: c.start as u32 }
        })
        .collect();
    let clean = batch_from(&items, steps, device)?;
    let (b, t, j, d) = clean.dims()?;
    let noise = Tensor::from_vec(gaussian(rng, b * t * j * d), (b, t, j, d), device)?;
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
    let squared = (&predicted - &clean.x)?.sqr()?.broadcast_mul(&mask)?.sum_all()?;
    let tokens = mask.sum_all()?.to_scalar::<f32>()? as f64;
    // The rotation term needs the 6D values in physical units: undo each skeleton's
    // normalisation (padded joints get mean 0, std 1; they are masked anyway).
    let (mut mean, mut std) = (vec![0f32; b * j * 6], vec![1f32; b * j * 6]);
    for (i, c) in crops.iter().enumerate() {
        let stats = &set.skeletons[c.skeleton].stats;
        for jj in 0..set.skeletons[c.skeleton].skeleton.len() {
            for k in 0..6 {
                mean[(i * j + jj) * 6 + k] = stats.mean[jj * d + 3 + k];
                std[(i * j + jj) * 6 + k] = stats.std[jj * d + 3 + k] + crate::repr::anytop::STD_EPSILON;
            }
        }
    }
    let mean = Tensor::from_vec(mean, (b, 1, j, 6), device)?;
    let std = Tensor::from_vec(std, (b, 1, j, 6), device)?;
    let physical = |x: &Tensor| -> candle_core::Result<Tensor> { x.narrow(3, 3, 6)?.broadcast_mul(&std)?.broadcast_add(&mean) };
    let geo = rotation_distance(&physical(&predicted)?, &physical(&clean.x)?)?;
    let rotation = geo.unsqueeze(3)?.broadcast_mul(&mask)?.sum_all()?;
    Ok(LossSums { squared, values: tokens * d as f64, rotation, tokens })
}

/// 1 − cos θ of the rotation between two 6D rotations (first two matrix columns, `[..., 6]`),
/// per token: (3 − tr(R̂ᵀR)) / 2. The reference takes θ itself (arccos); candle has no arccos,
/// and 1 − cos θ is a smooth, monotone function of θ (≈ θ²/2 for small angles) with the same
/// minimiser, whose gradient does not blow up at θ = 0 as arccos's does.
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
    (trace * -0.5)? + 1.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::data::RawClip;
    use crate::embed::NameTable;
    use crate::nn::{seeded_var_builder, DenoiserConfig};
    use crate::skeleton::topology;

    fn set() -> TrainSet {
        let (skeleton, motion) = crate::synth::creature("quadruped", 0).unwrap();
        let clips = vec![RawClip { name: "q.bvh".into(), skeleton, motion }];
        TrainSet::build(clips, NameTable::builtin().unwrap(), topology::DEFAULT_DMAX).unwrap().0
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
                candle_core::safetensors::save(&opt.state().into_iter().collect(), dir.join("opt.safetensors")).unwrap();
                // A new process: fresh (differently seeded) parameters, then the checkpoint.
                varmap = VarMap::new();
                model = Denoiser::new(seeded_var_builder(&varmap, 99, &dev), &cfg).unwrap();
                varmap.load(dir.join("model.safetensors")).unwrap();
                vars = named_vars(&varmap);
                let state = candle_core::safetensors::load(dir.join("opt.safetensors"), &dev).unwrap();
                let step = opt.step;
                opt = AdamW::new(1e-3);
                opt.load_state(&state, step);
                let _ = std::fs::remove_dir_all(&dir);
            }
            losses.push(train_step(&model, &vars, &mut opt, set, &schedule, &mut rng, 2, 12, 1.0, &dev).unwrap().loss);
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

    #[test]
    fn rotation_distance_is_zero_for_equal_rotations_and_grows_with_angle() {
        let dev = Device::Cpu;
        // Identity (columns x, y) and rotations by 90 and 180 degrees about z; 6D are unnormalised.
        let r = |c1: [f32; 3], c2: [f32; 3]| Tensor::from_vec([c1, c2].concat(), (1, 6), &dev).unwrap();
        let id = r([2.0, 0.0, 0.0], [0.3, 1.0, 0.0]);
        let d = |a: &Tensor, b: &Tensor| rotation_distance(a, b).unwrap().to_vec1::<f32>().unwrap()[0];
        assert!(d(&id, &id).abs() < 1e-6);
        assert!((d(&id, &r([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0])) - 1.0).abs() < 1e-5, "90 degrees: 1 - cos = 1");
        assert!((d(&id, &r([-1.0, 0.0, 0.0], [0.0, -1.0, 0.0])) - 2.0).abs() < 1e-5, "180 degrees: 2");
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
