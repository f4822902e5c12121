//! Diagnosis (issue 22): does the denoiser keep the motion it is shown? For clip crops of the
//! training data, noised to step t, compare the temporal variation of the predicted x0 with
//! the clean crop's, per t. A model that flattens time even at small t ignores its input's
//! motion; one that keeps it at small t but not at large t has not learnt to invent it.
//!
//!     cargo run --release --example denoise_probe -- MODEL_DIR DATA...
//!
//! Prints, per t: the ratio of the mean frame-to-frame change of joint positions (feature dims
//! 0..3, denormalised) predicted / clean, and the normalised MSE.

use candle_core::Device;
use menagerie::cli::load::{expand_inputs, load_motions, LoadOptions};
use menagerie::diffusion::checkpoint;
use menagerie::diffusion::data::{Augmentation, RawClip, TrainSet};
use menagerie::diffusion::Schedule;
use menagerie::embed::NameTable;
use menagerie::nn::{batch_from, BatchItem};
use menagerie::repr::Features;
use menagerie::rng::SplitMix64;

/// Summed frame-to-frame change of the joints' positions (dims 0..3, denormalised), after a
/// `k`-frame moving average (k = 1: raw, jitter included; 5: jitter averaged away).
fn motion_of(f: &[f32], frames: usize, joints: usize, dims: usize, mean: &[f32], std: &[f32], k: usize) -> f64 {
    let value = |t: usize, i: usize| (f[t * joints * dims + i] * std[i] + mean[i]) as f64;
    let averaged = |t: usize, i: usize| (t..t + k).map(|u| value(u, i)).sum::<f64>() / k as f64;
    let mut total = 0.0;
    for t in 1..frames.saturating_sub(k - 1) {
        for j in 1..joints {
            for c in 0..3 {
                let i = j * dims + c;
                total += (averaged(t, i) - averaged(t - 1, i)).abs();
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
    let clips: Vec<RawClip> =
        load_motions(&files, &LoadOptions::default())?.into_iter().map(|l| RawClip { name: l.name, skeleton: l.skeleton, motion: l.motion }).collect();
    let names = NameTable::builtin()?;
    let (set, _) = TrainSet::build(clips, names, loaded.info.dmax, &Augmentation::none())?;
    let schedule = Schedule::cosine(loaded.info.schedule_steps);
    let mut rng = SplitMix64::new(5);
    let crops = set.sample(&mut rng, 24, 60);
    println!("| t | motion ratio, raw (pred / clean) | after a 5-frame average | normalised MSE |");
    println!("|---|---|---|---|");
    for t in [2usize, 10, 25, 50, 75, 90, 99] {
        let (mut ratio_num, mut ratio_den, mut mse, mut n) = (0.0, 0.0, 0.0, 0.0);
        let (mut smooth_num, mut smooth_den) = (0.0, 0.0);
        for c in &crops {
            let s = set.data(c);
            let clean: Features = set.crop(c);
            let (a, b) = schedule.noise_coefficients(t);
            let noise = menagerie::rng::gaussian(&mut rng, clean.data.len());
            let noisy = Features { data: clean.data.iter().zip(&noise).map(|(x, e)| (a * *x as f64 + b * *e as f64) as f32).collect(), ..clean.clone() };
            let item =
                BatchItem { features: &noisy, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: c.start as u32 };
            let batch = batch_from(&[item], &[t as u32], &device)?;
            let pred = loaded.model.forward(&batch)?;
            let frames = clean.frames;
            let x0: Vec<f32> = pred.narrow(1, 1, frames)?.contiguous()?.flatten_all()?.to_vec1()?;
            let (j, d) = (clean.joints, clean.dims);
            ratio_num += motion_of(&x0, frames, j, d, &s.stats.mean, &s.stats.std, 1);
            ratio_den += motion_of(&clean.data, frames, j, d, &s.stats.mean, &s.stats.std, 1);
            smooth_num += motion_of(&x0, frames, j, d, &s.stats.mean, &s.stats.std, 5);
            smooth_den += motion_of(&clean.data, frames, j, d, &s.stats.mean, &s.stats.std, 5);
            mse += x0.iter().zip(&clean.data).map(|(p, q)| ((p - q) * (p - q)) as f64).sum::<f64>();
            n += x0.len() as f64;
        }
        println!("| {t} | {:.3} | {:.3} | {:.4} |", ratio_num / ratio_den.max(1e-12), smooth_num / smooth_den.max(1e-12), mse / n);
    }
    Ok(())
}
