//! Training throughput of the denoiser: `cargo bench --bench train_step`.
//!
//! Times what `mo-train` does per step (`AnyTopTrainer::step`: the data draw, forward, loss,
//! backward and AdamW) on the bundled creatures (`examples/data`, as `mo-train --augment 0`),
//! at each thread count in its own rayon pool. The thread counts take turns step by step
//! (1, 2, 1, 2, ...) so that other work on the machine hits them alike, and each runs its own
//! trainer from the same seed, so every thread count trains the same steps. Reports the median
//! and spread of s/step, the median CPU seconds per step (all threads; less sensitive to other
//! work on the machine than the wall clock), tokens/s (tokens = joints x (frames + P_S) of the batch's crops) and
//! GFLOP/s of the model's matmul FLOPs (forward x 3 for forward + backward) next to the f32
//! matmul peak, and whether the thread counts trained the same losses bit for bit.
//!
//! Environment: `TRAIN_BENCH_DATA` (comma-separated BVH files or folders, default
//! examples/data; e.g. the zoo), `TRAIN_BENCH_PRESET` (small), `TRAIN_BENCH_BATCH` (16),
//! `TRAIN_BENCH_CROP` (40), `TRAIN_BENCH_STEPS` (timed steps per thread count, 10; two warm-up
//! steps before), `TRAIN_BENCH_THREADS` (1,2). Current numbers: BENCHMARKS.md.

mod common;
use common::{denoiser_forward_flops, median};

use candle_core::{DType, Device, Tensor};
use menagerie::cli::load::{expand_inputs, load_motions, LoadOptions};
use menagerie::diffusion::data::{Augmentation, TrainSet};
use menagerie::diffusion::trainer::{step_rng, AnyTopOptions, AnyTopStart, AnyTopTrainer, Trainer};
use menagerie::embed::NameTable;
use menagerie::nn::DenoiserConfig;
use menagerie::skeleton::topology;
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|s| s.trim().parse().ok()).unwrap_or(default)
}

/// CPU seconds (user + system) of the whole process so far.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } != 0 {
        return f64::NAN;
    }
    let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    secs(usage.ru_utime) + secs(usage.ru_stime)
}

fn matmul_peak() -> f64 {
    let dev = Device::Cpu;
    let n = 1024;
    let a = Tensor::ones((n, n), DType::F32, &dev).expect("a matrix");
    let b = Tensor::ones((n, n), DType::F32, &dev).expect("a matrix");
    black_box(a.matmul(&b).expect("a matmul"));
    let runs: Vec<Duration> = (0..5)
        .map(|_| {
            let t = Instant::now();
            black_box(a.matmul(&b).expect("a matmul"));
            t.elapsed()
        })
        .collect();
    2.0 * (n as f64).powi(3) / median(&runs).as_secs_f64() / 1e9
}

/// Tokens and model matmul FLOPs (forward + backward) of step `k`: the crops its data stream
/// draws first, grouped by skeleton as the training step runs them.
fn step_work(set: &TrainSet, cfg: &DenoiserConfig, seed: u64, k: u64, batch: usize, crop: usize) -> (f64, f64) {
    let crops = set.sample(&mut step_rng(seed, k), batch, crop);
    let mut groups: BTreeMap<(usize, Option<usize>), (usize, usize, usize)> = BTreeMap::new();
    let mut tokens = 0.0;
    for c in &crops {
        let joints = set.data(c).skeleton.len();
        tokens += (joints * (c.frames + 1)) as f64;
        let g = groups.entry((c.skeleton, c.variant)).or_insert((0, 0, joints));
        g.0 += 1;
        g.1 = g.1.max(c.frames + 1);
    }
    let flops = groups.values().map(|&(b, t, j)| 3.0 * denoiser_forward_flops(cfg, b, t, j)).sum();
    (tokens, flops)
}

fn main() {
    menagerie::nn::keep_freed_memory();
    let data: Vec<PathBuf> = std::env::var("TRAIN_BENCH_DATA")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/examples/data").to_string())
        .split(',')
        .map(|s| PathBuf::from(s.trim()))
        .collect();
    let preset = std::env::var("TRAIN_BENCH_PRESET").unwrap_or_else(|_| "small".into());
    let config = match preset.as_str() {
        "tiny" => DenoiserConfig::tiny(),
        "small" => DenoiserConfig::small(),
        "paper" => DenoiserConfig::paper(),
        other => panic!("TRAIN_BENCH_PRESET: unknown preset {other}"),
    };
    let batch: usize = env_or("TRAIN_BENCH_BATCH", 16);
    let crop: usize = env_or("TRAIN_BENCH_CROP", 40);
    let steps: u64 = env_or("TRAIN_BENCH_STEPS", 10);
    let threads: Vec<usize> =
        std::env::var("TRAIN_BENCH_THREADS").unwrap_or_else(|_| "1,2".into()).split(',').filter_map(|s| s.trim().parse().ok()).filter(|&n| n > 0).collect();
    let seed = 1;

    // As `mo-train --augment 0` (which also prepares variants it never draws; none here).
    let build_set = || -> TrainSet {
        let files = expand_inputs(&data).expect("the training data");
        let loaded = load_motions(&files, &LoadOptions::default()).expect("readable BVH files");
        let clips = loaded;
        let names = NameTable::builtin().expect("the built-in name table");
        TrainSet::build(clips, names, topology::DEFAULT_DMAX, &Augmentation { seed, ..Augmentation::none() }).expect("a training set").0
    };
    let set = build_set();
    let joints: Vec<String> = set.skeletons.iter().map(|s| format!("{} {}", s.name, s.skeleton.len())).collect();
    println!(
        "data: {} ({} skeletons: {})",
        data.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "),
        set.skeletons.len(),
        joints.join(", ")
    );

    let opts = AnyTopOptions {
        config: config.clone(),
        seed,
        lr: 1e-4,
        batch,
        crop,
        lambda_geo: 1.0,
        lambda_vel: 0.0,
        lambda_foot: 0.0,
        ema: 0.999,
        noise_shift: None,
        position_jitter: None,
        shift_taper: None,
        still_weight: None,
        weighting: None,
        augment: 0.0,
        augment_variants: 0,
        fallback_stats: Default::default(),
        loss_units: Default::default(),
        rest_token: Default::default(),
    };
    let dev = Device::Cpu;
    let scratch = std::env::temp_dir().join(format!("menagerie-train-bench-{}", std::process::id()));
    let mut runs: Vec<(usize, rayon::ThreadPool, AnyTopTrainer, f64)> = threads
        .iter()
        .map(|&n| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().expect("a thread pool");
            let trainer = AnyTopTrainer::new(&scratch.join(n.to_string()), &opts, AnyTopStart::New, build_set(), &dev).expect("a trainer");
            let peak = pool.install(matmul_peak);
            (n, pool, trainer, peak)
        })
        .collect();
    println!("preset {preset}, batch {batch}, crop {crop}, {steps} timed steps per thread count after 2 warm-up steps, taking turns");

    let warm = 2;
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); runs.len()];
    let mut cpu: Vec<Vec<f64>> = vec![Vec::new(); runs.len()];
    let mut losses: Vec<Vec<u64>> = vec![Vec::new(); runs.len()];
    let (mut tokens, mut flops) = (0.0, 0.0);
    for k in 0..warm + steps {
        if k >= warm {
            let (t, f) = step_work(&set, &config, seed, k, batch, crop);
            tokens += t;
            flops += f;
        }
        for (i, (_, pool, trainer, _)) in runs.iter_mut().enumerate() {
            let (t, c) = (Instant::now(), cpu_seconds());
            let loss = pool.install(|| trainer.step(k)).expect("a training step");
            let (s, c) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
            losses[i].push(loss.total.to_bits());
            if k >= warm {
                times[i].push(s);
                cpu[i].push(c);
            }
        }
    }
    let (tokens, flops) = (tokens / steps as f64, flops / steps as f64);
    println!();
    println!("| threads | median s/step | min-max | CPU s/step | tokens/s | GFLOP/s | matmul peak GFLOP/s | of peak |");
    println!("|---|---|---|---|---|---|---|---|");
    for (i, (n, _, _, peak)) in runs.iter().enumerate() {
        let mut t = times[i].clone();
        t.sort_by(f64::total_cmp);
        let med = t[t.len() / 2];
        let mut c = cpu[i].clone();
        c.sort_by(f64::total_cmp);
        println!(
            "| {n} | {med:.3} | {:.3}-{:.3} | {:.3} | {:.0} | {:.1} | {peak:.1} | {:.0}% |",
            t[0],
            t[t.len() - 1],
            c[c.len() / 2],
            tokens / med,
            flops / med / 1e9,
            100.0 * flops / med / 1e9 / peak
        );
    }
    if runs.len() > 1 {
        let first = runs[0].0;
        let mut t0 = times[0].clone();
        t0.sort_by(f64::total_cmp);
        for (i, (n, _, _, _)) in runs.iter().enumerate().skip(1) {
            let mut t = times[i].clone();
            t.sort_by(f64::total_cmp);
            println!("speed-up of {n} threads over {first}: {:.2}x (medians)", t0[t0.len() / 2] / t[t.len() / 2]);
        }
        let same = losses.iter().all(|l| l == &losses[0]);
        println!("same losses bit for bit at every thread count: {}", if same { "yes" } else { "NO" });
    }
    println!("tokens per step {tokens:.0}, model matmul GFLOP per step {:.2}", flops / 1e9);
    let _ = std::fs::remove_dir_all(&scratch);
}
