//! Sampling motion for a skeleton from a trained denoiser: start from Gaussian noise, and at
//! every visited step predict x0 and move to the next step with the sampler's coefficients
//! (`schedule::Step`). The rest-pose token stays the skeleton's P_S throughout.

use super::schedule::{Sampler, Schedule};
use super::train::gaussian;
use crate::nn::{batch_from, BatchItem, Denoiser};
use crate::repr::anytop::AnyTopStats;
use crate::repr::Features;
use crate::synth::SplitMix64;
use candle_core::Device;

/// What the model is told about the skeleton to animate (all normalised like training data).
pub struct Condition<'a> {
    pub rest_row: &'a [f32],
    pub relations: &'a [Vec<u8>],
    pub distances: &'a [Vec<u8>],
    pub names: &'a [Vec<f32>],
    pub stats: &'a AnyTopStats,
}

/// How to sample.
#[derive(Clone, Debug)]
pub struct SampleOptions {
    pub samples: usize,
    pub frames: usize,
    /// Visited diffusion steps (the schedule's length = the reference's full ancestral loop).
    pub steps: usize,
    pub sampler: Sampler,
    pub seed: u64,
}

/// `samples` motions, denormalised AnyTop features `[frames, joints, 13]` each.
pub fn sample(model: &Denoiser, schedule: &Schedule, cond: &Condition, opts: &SampleOptions, device: &Device) -> anyhow::Result<Vec<Features>> {
    let joints = cond.names.len();
    let dims = model.config().feature_dims;
    let per = opts.frames * joints * dims;
    let mut rng = SplitMix64::new(opts.seed);
    let mut x: Vec<Features> =
        (0..opts.samples).map(|_| Features { frames: opts.frames, joints, dims, data: gaussian(&mut rng, per) }).collect();
    let timesteps = schedule.timesteps(opts.steps);
    for step in schedule.steps(&timesteps, opts.sampler) {
        let items: Vec<BatchItem> = x
            .iter()
            .map(|f| BatchItem { features: f, rest_row: cond.rest_row, relations: cond.relations, distances: cond.distances, names: cond.names, start: 0 })
            .collect();
        let batch = batch_from(&items, &vec![step.t as u32; items.len()], device)?;
        let predicted = model.forward(&batch)?;
        let t = opts.frames + 1;
        let x0: Vec<f32> = predicted.narrow(1, 1, t - 1)?.contiguous()?.flatten_all()?.to_vec1()?;
        for (i, f) in x.iter_mut().enumerate() {
            let noise = if step.sigma > 0.0 { gaussian(&mut rng, per) } else { Vec::new() };
            for k in 0..per {
                let z = noise.get(k).copied().unwrap_or(0.0) as f64;
                f.data[k] = (step.x0 * x0[i * per + k] as f64 + step.xt * f.data[k] as f64 + step.sigma * z) as f32;
            }
        }
    }
    for f in &mut x {
        cond.stats.denormalise(f).map_err(|e| anyhow::anyhow!("denormalising the samples: {e}"))?;
    }
    Ok(x)
}
