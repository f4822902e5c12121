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
use menagerie::diffusion::data::{Augmentation, TrainSet};
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
    let clips = load_motions(&files, &LoadOptions::default())?;
    let names = NameTable::builtin()?;
    let (set, _) = TrainSet::build(clips, names, loaded.info.dmax, &Augmentation::none())?;
    let schedule = loaded.info.schedule();
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
            let item = BatchItem { features: &noisy, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: 0 };
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
    sensitivity(&loaded.model, &set, &schedule, &crops, &device)?;
    Ok(())
}

/// Does the denoiser read its input across time? Per t: nudge the noisy input at one frame
/// (every joint and dim, +0.5 normalised units) and report the mean absolute change of the
/// predicted x0 at frame offsets 0, 1, 3, 8 and 15 from the nudged frame, next to how much two
/// different noise draws change the prediction (0 = the prediction ignores the noise, so every
/// sample from pure noise would be the same).
fn sensitivity(
    model: &menagerie::nn::Denoiser,
    set: &TrainSet,
    schedule: &Schedule,
    crops: &[menagerie::diffusion::data::Crop],
    device: &Device,
) -> anyhow::Result<()> {
    let offsets = [0usize, 1, 3, 8, 15];
    println!();
    println!("| t | change of x0 at offset 0 / 1 / 3 / 8 / 15 after a nudge at one frame | change between two noise draws |");
    println!("|---|---|---|");
    let mut rng = SplitMix64::new(9);
    for t in [10usize, 50, 75, 90, 99] {
        let mut change = vec![0.0f64; offsets.len()];
        let (mut draws, mut n) = (0.0f64, 0.0f64);
        for c in crops.iter().take(8) {
            let s = set.data(c);
            let clean: Features = set.crop(c);
            if clean.frames < 40 {
                continue;
            }
            let (a, b) = schedule.noise_coefficients(t);
            let width = clean.joints * clean.dims;
            let noisy_with =
                |noise: &[f32]| Features { data: clean.data.iter().zip(noise).map(|(x, e)| (a * *x as f64 + b * *e as f64) as f32).collect(), ..clean.clone() };
            let predict = |f: &Features| -> anyhow::Result<Vec<f32>> {
                let item = BatchItem { features: f, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: 0 };
                let batch = batch_from(&[item], &[t as u32], device)?;
                Ok(model.forward(&batch)?.narrow(1, 1, f.frames)?.contiguous()?.flatten_all()?.to_vec1()?)
            };
            let noise = menagerie::rng::gaussian(&mut rng, clean.data.len());
            let base = noisy_with(&noise);
            let p0 = predict(&base)?;
            let at = 10;
            let mut nudged = base.clone();
            nudged.data[at * width..(at + 1) * width].iter_mut().for_each(|v| *v += 0.5);
            let p1 = predict(&nudged)?;
            for (k, &o) in offsets.iter().enumerate() {
                let f = at + o;
                change[k] += (f * width..(f + 1) * width).map(|i| (p1[i] - p0[i]).abs() as f64).sum::<f64>() / width as f64;
            }
            let other = noisy_with(&menagerie::rng::gaussian(&mut rng, clean.data.len()));
            let p2 = predict(&other)?;
            draws += p0.iter().zip(&p2).map(|(x, y)| (x - y).abs() as f64).sum::<f64>() / p0.len() as f64;
            n += 1.0;
        }
        let row: Vec<String> = change.iter().map(|c| format!("{:.4}", c / n.max(1.0))).collect();
        println!("| {t} | {} | {:.4} |", row.join(" / "), draws / n.max(1.0));
    }
    Ok(())
}
