//! An exponential moving average (EMA) of the denoiser's weights: what `mo-sample` samples
//! with, while the optimiser keeps moving the raw weights.
//!
//! Why: with a learning rate as high as ours (3e-4) and batches of 16, the raw weights wander
//! from step to step around a better average, and a sampler calls the model 10-100 times with
//! one fixed set of weights, so their noise becomes a bias of the whole sample. Diffusion
//! models are usually sampled from such an average (DDPM, Ho et al. 2020: decay 0.9999).
//!
//! The checkpoint keeps both: `model.safetensors` holds the average (every reader of a model
//! gets it without knowing about it), and `optimizer.safetensors` holds the raw weights under
//! `w.<name>` beside the moments, so `--resume` continues the same run exactly. A checkpoint
//! written without an average has no `w.` entries; resuming it starts the average at its
//! weights.

use candle_core::{Tensor, Var};
use std::collections::BTreeMap;

/// Key prefix of the raw weights in `optimizer.safetensors`.
pub const RAW_PREFIX: &str = "w.";

/// The average of every parameter, by name.
pub struct Ema {
    decay: f64,
    weights: BTreeMap<String, Tensor>,
}

impl Ema {
    /// An average that starts at the variables' current values (copied: a `Var` is updated in
    /// place, so a shallow clone would follow it).
    pub fn new(decay: f64, vars: &BTreeMap<String, Var>) -> candle_core::Result<Ema> {
        let weights = vars.iter().map(|(k, v)| Ok((k.clone(), v.as_tensor().copy()?))).collect::<candle_core::Result<_>>()?;
        Ok(Ema { decay, weights })
    }

    pub fn decay(&self) -> f64 {
        self.decay
    }

    /// The decay used after `step` steps in all: it ramps up as (1 + step)/(10 + step), so the
    /// average of a young model is not dominated by its random start.
    pub fn decay_at(&self, step: u64) -> f64 {
        self.decay.min((1.0 + step as f64) / (10.0 + step as f64))
    }

    /// Move the average toward the variables' values after `step` steps in all.
    pub fn update(&mut self, vars: &BTreeMap<String, Var>, step: u64) -> candle_core::Result<()> {
        let d = self.decay_at(step);
        for (name, var) in vars {
            let w = var.as_tensor();
            let next = match self.weights.get(name) {
                Some(e) => ((e * d)? + (w * (1.0 - d))?)?,
                None => w.copy()?,
            };
            // Detached: arithmetic on a variable records its inputs for backprop, so without
            // this each average would hold the previous one and its two temporaries, a chain
            // as long as the run. It grew zoo-tiny's training process by about 0.6 MB a step
            // (12 GB after 20,000 steps) until the kernel's OOM killer stopped a second run
            // beside it.
            self.weights.insert(name.clone(), next.detach());
        }
        Ok(())
    }

    /// The averaged weights, by parameter name.
    pub fn weights(&self) -> &BTreeMap<String, Tensor> {
        &self.weights
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::Device;

    fn var(values: &[f32]) -> Var {
        Var::from_tensor(&Tensor::new(values, &Device::Cpu).unwrap()).unwrap()
    }

    fn values(t: &Tensor) -> Vec<f32> {
        t.to_vec1().unwrap()
    }

    #[test]
    fn the_average_starts_at_the_weights_and_does_not_follow_them_in_place() {
        let v = var(&[1.0, 2.0]);
        let vars = BTreeMap::from([("a".to_string(), v.clone())]);
        let ema = Ema::new(0.9, &vars).unwrap();
        v.set(&Tensor::new(&[5.0f32, 6.0], &Device::Cpu).unwrap()).unwrap();
        assert_eq!(values(&ema.weights()["a"]), vec![1.0, 2.0]);
    }

    #[test]
    fn the_average_keeps_no_history() {
        let v = var(&[1.0, 2.0]);
        let vars = BTreeMap::from([("a".to_string(), v.clone())]);
        let mut ema = Ema::new(0.9, &vars).unwrap();
        for step in 0..3 {
            ema.update(&vars, step).unwrap();
            // A tensor that tracks no op holds no reference to the averages before it.
            assert!(!ema.weights()["a"].track_op(), "step {step}: the average records its inputs");
        }
    }

    #[test]
    fn an_update_moves_by_one_minus_the_decay() {
        let v = var(&[0.0]);
        let vars = BTreeMap::from([("a".to_string(), v.clone())]);
        let mut ema = Ema::new(0.9, &vars).unwrap();
        v.set(&Tensor::new(&[10.0f32], &Device::Cpu).unwrap()).unwrap();
        // After many steps the decay is the configured 0.9: 0.9 * 0 + 0.1 * 10.
        ema.update(&vars, 1000).unwrap();
        assert!((values(&ema.weights()["a"])[0] - 1.0).abs() < 1e-6);
        // Early on the ramp wins: step 0 gives decay 0.1, so 0.1 * 1 + 0.9 * 10.
        assert!((ema.decay_at(0) - 0.1).abs() < 1e-12);
        ema.update(&vars, 0).unwrap();
        assert!((values(&ema.weights()["a"])[0] - 9.1).abs() < 1e-5);
    }
}
