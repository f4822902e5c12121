//! Training the denoiser (AnyTop §3.3–3.4): x0 prediction, loss = masked MSE in normalised
//! space over real joints and frames, AdamW (lr 1e-4, no weight decay, as the reference), and
//! checkpoints that can resume exactly.
//!
//! The optimiser is ours rather than candle-nn's `AdamW` because a checkpoint must carry the
//! moment estimates (candle-nn keeps them private), and resuming must continue the same run.
//! Noise and timesteps come from our seeded SplitMix64, so the same seed and data give the
//! same run whatever the thread count.

use super::data::TrainSet;
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
/// token), predict x0, masked MSE, backward, AdamW.
pub fn train_step(
    model: &Denoiser,
    vars: &BTreeMap<String, Var>,
    opt: &mut AdamW,
    set: &TrainSet,
    schedule: &Schedule,
    rng: &mut SplitMix64,
    batch: usize,
    crop: usize,
    device: &Device,
) -> anyhow::Result<StepStats> {
    let crops = set.sample(rng, batch, crop);
    let features: Vec<_> = crops.iter().map(|c| set.crop(c)).collect();
    let items: Vec<BatchItem> = crops
        .iter()
        .zip(&features)
        .map(|(c, f)| {
            let s = &set.skeletons[c.skeleton];
            BatchItem { features: f, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: c.start as u32 }
        })
        .collect();
    let steps: Vec<u32> = (0..batch).map(|_| rng.below(schedule.len()) as u32).collect();
    let clean = batch_from(&items, &steps, device)?;
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
    let err = ((predicted - &clean.x)?.sqr()?.broadcast_mul(&mask))?;
    let count = (mask.sum_all()?.to_scalar::<f32>()? as f64 * d as f64).max(1.0);
    let loss = (err.sum_all()? / count)?;
    let grads = loss.backward()?;
    opt.update(vars, &grads)?;
    Ok(StepStats { loss: loss.to_scalar::<f32>()? as f64 })
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
            losses.push(train_step(&model, &vars, &mut opt, set, &schedule, &mut rng, 2, 12, &dev).unwrap().loss);
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
