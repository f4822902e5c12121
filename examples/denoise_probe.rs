//! Diagnosis (issue 22): does the denoiser keep the motion it is shown? For clip crops of the
//! training data, noised to step t, compare the temporal variation of the predicted x0 with
//! the clean crop's, per t. A model that flattens time even at small t ignores its input's
//! motion; one that keeps it at small t but not at large t has not learnt to invent it.
//!
//!     cargo run --release --example denoise_probe -- MODEL_DIR DATA...
//!
//! Prints, per t: the ratio of the mean frame-to-frame change of joint positions (feature dims
//! 0..3, denormalised) predicted / clean, the normalised MSE, and the mean square of the
//! prediction next to the clean crop's (a calibrated denoiser predicts the mean, near 0, from
//! pure noise). Then, at the cleanest steps, the MSE per feature group next to that of the
//! noisy input itself (does the model improve on what it is given?); how a DDIM-10 sample's
//! x0 prediction approaches the clips along the sampler; and how much of a clip noised to each
//! visited step the sampler keeps (SDEdit). The last two use the first crop's skeleton.

use candle_core::Device;
use menagerie::cli::load::{expand_inputs, load_motions, LoadOptions};
use menagerie::diffusion::checkpoint;
use menagerie::diffusion::data::{Augmentation, SkeletonData, TrainSet};
use menagerie::diffusion::Schedule;
use menagerie::embed::NameTable;
use menagerie::nn::{batch_from, BatchItem, Denoiser};
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

/// A clean crop noised as training noises it: `a·x + b·ε`.
fn noised(clean: &Features, noise: &[f32], (a, b): (f64, f64)) -> Features {
    Features { data: clean.data.iter().zip(noise).map(|(x, e)| (a * *x as f64 + b * *e as f64) as f32).collect(), ..clean.clone() }
}

/// The model's x0 prediction for `f` (one item of skeleton `s`) at step `t`, the rest token
/// dropped: `f.frames × joints × dims` values.
fn predict(model: &Denoiser, s: &SkeletonData, f: &Features, t: usize, device: &Device) -> anyhow::Result<Vec<f32>> {
    let item = BatchItem { features: f, rest_row: &s.rest_row, relations: &s.relations, distances: &s.distances, names: &s.names, start: 0 };
    Ok(model.forward(&batch_from(&[item], &[t as u32], device)?)?.narrow(1, 1, f.frames)?.contiguous()?.flatten_all()?.to_vec1()?)
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
    println!("| t | motion ratio, raw (pred / clean) | after a 5-frame average | normalised MSE | mean square, predicted / clean |");
    println!("|---|---|---|---|---|");
    for t in [2usize, 10, 25, 50, 75, 90, 99] {
        let (mut ratio_num, mut ratio_den, mut mse, mut n) = (0.0, 0.0, 0.0, 0.0);
        let (mut smooth_num, mut smooth_den) = (0.0, 0.0);
        let (mut power_predicted, mut power_clean) = (0.0, 0.0);
        for c in &crops {
            let s = set.data(c);
            let clean: Features = set.crop(c);
            let noise = menagerie::rng::gaussian(&mut rng, clean.data.len());
            let x0 = predict(&loaded.model, s, &noised(&clean, &noise, schedule.noise_coefficients(t)), t, &device)?;
            let frames = clean.frames;
            let (j, d) = (clean.joints, clean.dims);
            ratio_num += motion_of(&x0, frames, j, d, &s.stats.mean, &s.stats.std, 1);
            ratio_den += motion_of(&clean.data, frames, j, d, &s.stats.mean, &s.stats.std, 1);
            smooth_num += motion_of(&x0, frames, j, d, &s.stats.mean, &s.stats.std, 5);
            smooth_den += motion_of(&clean.data, frames, j, d, &s.stats.mean, &s.stats.std, 5);
            mse += x0.iter().zip(&clean.data).map(|(p, q)| ((p - q) * (p - q)) as f64).sum::<f64>();
            power_predicted += x0.iter().map(|p| (p * p) as f64).sum::<f64>();
            power_clean += clean.data.iter().map(|p| (p * p) as f64).sum::<f64>();
            n += x0.len() as f64;
        }
        println!(
            "| {t} | {:.3} | {:.3} | {:.4} | {:.4} / {:.4} |",
            ratio_num / ratio_den.max(1e-12),
            smooth_num / smooth_den.max(1e-12),
            mse / n,
            power_predicted / n,
            power_clean / n
        );
    }
    by_group(&loaded.model, &set, &schedule, &crops, &device)?;
    trajectory(&loaded.model, &set, &schedule, &crops[0], &device)?;
    sensitivity(&loaded.model, &set, &schedule, &crops, &device)?;
    Ok(())
}

/// Does the denoiser read its input across time? Per t: nudge the noisy input at one frame
/// (every joint and dim, +0.5 normalised units) and report the mean absolute change of the
/// predicted x0 at frame offsets 0, 1, 3, 8 and 15 from the nudged frame, next to how much two
/// different noise draws change the prediction (0 = the prediction ignores the noise, so every
/// sample from pure noise would be the same).
fn sensitivity(model: &Denoiser, set: &TrainSet, schedule: &Schedule, crops: &[menagerie::diffusion::data::Crop], device: &Device) -> anyhow::Result<()> {
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
            let ab = schedule.noise_coefficients(t);
            let width = clean.joints * clean.dims;
            let noise = menagerie::rng::gaussian(&mut rng, clean.data.len());
            let base = noised(&clean, &noise, ab);
            let p0 = predict(model, s, &base, t, device)?;
            let at = 10;
            let mut nudged = base.clone();
            nudged.data[at * width..(at + 1) * width].iter_mut().for_each(|v| *v += 0.5);
            let p1 = predict(model, s, &nudged, t, device)?;
            for (k, &o) in offsets.iter().enumerate() {
                let f = at + o;
                change[k] += (f * width..(f + 1) * width).map(|i| (p1[i] - p0[i]).abs() as f64).sum::<f64>() / width as f64;
            }
            let other = noised(&clean, &menagerie::rng::gaussian(&mut rng, clean.data.len()), ab);
            let p2 = predict(model, s, &other, t, device)?;
            draws += p0.iter().zip(&p2).map(|(x, y)| (x - y).abs() as f64).sum::<f64>() / p0.len() as f64;
            n += 1.0;
        }
        let row: Vec<String> = change.iter().map(|c| format!("{:.4}", c / n.max(1.0))).collect();
        println!("| {t} | {} | {:.4} |", row.join(" / "), draws / n.max(1.0));
    }
    Ok(())
}

/// Feature groups of AnyTop's 13 dims: a joint's position, rotation, velocity and contact, and
/// the root's row as one group.
const GROUPS: [&str; 5] = ["position", "rotation", "velocity", "contact", "root"];

fn group_of(joint: usize, dim: usize) -> usize {
    match (joint, dim) {
        (0, _) => 4,
        (_, 0..=2) => 0,
        (_, 3..=8) => 1,
        (_, 9..=11) => 2,
        _ => 3,
    }
}

/// At the cleanest steps, the model's normalised MSE per feature group next to the noisy
/// input's own (x_t / a, whose MSE is (b / a)²): a model that has learnt to denoise finely
/// beats its input there.
fn by_group(model: &Denoiser, set: &TrainSet, schedule: &Schedule, crops: &[menagerie::diffusion::data::Crop], device: &Device) -> anyhow::Result<()> {
    println!();
    println!("| t | the input x_t / a | {} |", GROUPS.join(" | "));
    println!("|---|---|{}", "---|".repeat(GROUPS.len()));
    let mut rng = SplitMix64::new(7);
    for t in [0usize, 2, 10] {
        let (a, b) = schedule.noise_coefficients(t);
        let (mut sum, mut count) = ([0.0f64; 5], [0.0f64; 5]);
        for c in crops {
            let s = set.data(c);
            let clean: Features = set.crop(c);
            let noise = menagerie::rng::gaussian(&mut rng, clean.data.len());
            let x0 = predict(model, s, &noised(&clean, &noise, (a, b)), t, device)?;
            for (i, (p, q)) in x0.iter().zip(&clean.data).enumerate() {
                let g = group_of((i / clean.dims) % clean.joints, i % clean.dims);
                sum[g] += ((p - q) * (p - q)) as f64;
                count[g] += 1.0;
            }
        }
        let cells: Vec<String> = sum.iter().zip(&count).map(|(s, n)| format!("{:.4}", s / n.max(1.0))).collect();
        println!("| {t} | {:.4} | {} |", (b / a).powi(2), cells.join(" | "));
    }
    Ok(())
}

/// Whether the sampler finds the clips: a DDIM-10 run from noise (4 seeds, 120 frames) and,
/// for each visited step, the same run started from a clip crop noised to that step
/// (SDEdit). Reported per step: the x0 prediction's distance to the clips (mean over its
/// 15-frame windows, stride 5, of the mean squared normalised joint position difference to the
/// nearest clip window) and its frame-to-frame motion over the clip's; for SDEdit the final
/// distance. A static mean pose (all zeros) and the crop itself are given for scale.
fn trajectory(model: &Denoiser, set: &TrainSet, schedule: &Schedule, crop: &menagerie::diffusion::data::Crop, device: &Device) -> anyhow::Result<()> {
    const FRAMES: usize = 120;
    const WINDOW: usize = 15;
    const SEEDS: u64 = 4;
    let s = set.data(crop);
    let clips: Vec<&Features> = s.clips.iter().filter(|c| c.frames >= WINDOW).collect();
    let Some(long) = s.clips.iter().find(|c| c.frames >= FRAMES) else {
        println!("\n(no clip of {FRAMES} frames: the sampler trajectory is not probed)");
        return Ok(());
    };
    let (j, d) = (long.joints, long.dims);
    let position = |x: &[f32], t: usize, joint: usize, c: usize| x[(t * j + joint) * d + c] as f64;
    let distance = |x: &[f32]| -> f64 {
        let windows: Vec<f64> = (0..=FRAMES - WINDOW)
            .step_by(5)
            .map(|a| {
                let mut best = f64::INFINITY;
                for clip in &clips {
                    for b in 0..=clip.frames - WINDOW {
                        let mut e = 0.0;
                        for f in 0..WINDOW {
                            for joint in 1..j {
                                for c in 0..3 {
                                    e += (position(x, a + f, joint, c) - position(&clip.data, b + f, joint, c)).powi(2);
                                }
                            }
                        }
                        best = best.min(e / (WINDOW * (j - 1) * 3) as f64);
                    }
                }
                best
            })
            .collect();
        windows.iter().sum::<f64>() / windows.len() as f64
    };
    let motion = |x: &[f32], frames: usize| -> f64 {
        let mut m = 0.0;
        for t in 1..frames {
            for joint in 1..j {
                for c in 0..3 {
                    m += (position(x, t, joint, c) - position(x, t - 1, joint, c)).abs();
                }
            }
        }
        m / ((frames - 1) * (j - 1) * 3) as f64
    };
    let clip_motion = motion(&long.data, long.frames);
    let reference = long.data[..FRAMES * j * d].to_vec();
    let steps = schedule.steps(&schedule.timesteps(10), menagerie::diffusion::schedule::Sampler::Ddim);
    // Runs DDIM from `x` at visited step `from`; returns each step's x0 prediction.
    let run = |mut x: Vec<f32>, from: usize| -> anyhow::Result<Vec<Vec<f32>>> {
        let mut out = Vec::new();
        for st in &steps[from..] {
            let x0 = predict(model, s, &Features { frames: FRAMES, joints: j, dims: d, data: x.clone() }, st.t, device)?;
            x = x0.iter().zip(&x).map(|(p, q)| (st.x0 * *p as f64 + st.xt * *q as f64) as f32).collect();
            out.push(x0);
        }
        Ok(out)
    };
    println!();
    println!(
        "Sampler (DDIM 10, {FRAMES} frames, {SEEDS} seeds): distance of x0 to the clips (a static mean pose: {:.4}; the clip: {:.4}) and its motion / the clip's",
        distance(&vec![0.0; FRAMES * j * d]),
        distance(&reference)
    );
    println!();
    println!("| step | from noise: distance | from noise: motion | from the clip noised to this step: final distance |");
    println!("|---|---|---|---|");
    let (mut far, mut moving) = (vec![0.0; steps.len()], vec![0.0; steps.len()]);
    let mut kept = vec![0.0; steps.len()];
    let clip = Features { frames: FRAMES, joints: j, dims: d, data: reference.clone() };
    for seed in 0..SEEDS {
        let noise = menagerie::rng::gaussian(&mut SplitMix64::new(100 + seed), FRAMES * j * d);
        for (i, x0) in run(noise.clone(), 0)?.iter().enumerate() {
            far[i] += distance(x0) / SEEDS as f64;
            moving[i] += motion(x0, FRAMES) / clip_motion.max(1e-12) / SEEDS as f64;
        }
        for (from, st) in steps.iter().enumerate() {
            let last = run(noised(&clip, &noise, schedule.noise_coefficients(st.t)).data, from)?.pop().unwrap_or_default();
            kept[from] += distance(&last) / SEEDS as f64;
        }
    }
    for (i, st) in steps.iter().enumerate() {
        println!("| {} | {:.4} | {:.3} | {:.4} |", st.t, far[i], moving[i], kept[i]);
    }
    Ok(())
}
