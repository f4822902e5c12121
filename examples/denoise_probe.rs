//! Diagnosis (issue 22): does the denoiser keep the motion it is shown? For clip crops of the
//! training data, noised to step t, compare the temporal variation of the predicted x0 with
//! the clean crop's, per t. A model that flattens time even at small t ignores its input's
//! motion; one that keeps it at small t but not at large t has not learnt to invent it.
//!
//!     cargo run --release --example denoise_probe -- MODEL_DIR DATA...
//!
//! Prints, per t: the ratio of the mean frame-to-frame change of joint positions (feature dims
//! 0..3, denormalised) predicted / clean, and the normalised MSE.

use candle_core::{Device, Tensor};
use menagerie::cli::load::{expand_inputs, load_motions, LoadOptions};
use menagerie::diffusion::checkpoint;
use menagerie::diffusion::data::{Augmentation, RawClip, TrainSet};
use menagerie::diffusion::Schedule;
use menagerie::embed::NameTable;
use menagerie::nn::{batch_from, BatchItem};
use menagerie::repr::Features;
use menagerie::rng::SplitMix64;

fn motion_of(f: &[f32], frames: usize, joints: usize, dims: usize, mean: &[f32], std: &[f32]) -> f64 {
    let mut total = 0.0;
    for t in 1..frames {
        for j in 1..joints {
            for k in 0..3 {
                let i = j * dims + k;
                let a = f[(t - 1) * joints * dims + i] * std[i] + mean[i];
                let b = f[t * joints * dims + i] * std[i] + mean[i];
                total += (a - b).abs() as f64;
            }
        }
    }
    total
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    anyhow::ensure!(args.len() >= 2, "usage: denoise_probe MODEL_DIR DATA...");
    let device = Device::Cpu;
    let loaded = checkpoint::load(std::path::Path::new(&args[0]), &device)?;
    let files = expand_inputs(&args[1..].iter().map(Into::into).collect::<Vec<_>>())?;
    let clips: Vec<RawClip> = load_motions(&files, &LoadOptions::default())?.into_iter().map(|l| RawClip { name: l.name, skeleton: l.skeleton, motion: l.motion }).collect();
    let names = NameTable::builtin()?;
    let (set, _) = TrainSet::build(clips, names, loaded.info.dmax, &Augmentation::none())?;
    let schedule = Schedule::cosine(loaded.info.schedule_steps);
    let mut rng = SplitMix64::new(5);
    let crops = set.sample(&mut rng, 24, 60);
    println!("| t | motion ratio (pred / clean) | normalised MSE |");
    println!("|---|---|---|");
    for t in [2usize, 10, 25, 50, 75, 90, 99] {
        let (mut ratio_num, mut ratio_den, mut mse, mut n) = (0.0, 0.0, 0.0, 0.0);
        for c in &crops {
            let s = set.data(c);
            let clean: Features = set.crop(c);
            let (a, b) = schedule.noise_coefficients(t);
            let noise = menagerie::rng::gaussian(&mut rng, clean.data.len());
            let noisy = Features { data: clean.data.iter().zip(&noise).map(|(x, e)| (a * *x as f64 + b * *e as f64) as f32).collect(), ..clean.clone() };
            let item = BatchItem { features: &noisy, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: c.start as u32 };
            let batch = batch_from(&[item], &[t as u32], &device)?;
            let pred = loaded.model.forward(&batch)?;
            let frames = clean.frames;
            let x0: Vec<f32> = pred.narrow(1, 1, frames)?.contiguous()?.flatten_all()?.to_vec1()?;
            let (j, d) = (clean.joints, clean.dims);
            ratio_num += motion_of(&x0, frames, j, d, &s.stats.mean, &s.stats.std);
            ratio_den += motion_of(&clean.data, frames, j, d, &s.stats.mean, &s.stats.std);
            mse += x0.iter().zip(&clean.data).map(|(p, q)| ((p - q) * (p - q)) as f64).sum::<f64>();
            n += x0.len() as f64;
            let _ = Tensor::zeros(1, candle_core::DType::F32, &device)?;
        }
        println!("| {t} | {:.3} | {:.4} |", ratio_num / ratio_den.max(1e-12), mse / n);
    }
    Ok(())
}
