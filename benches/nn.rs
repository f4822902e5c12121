//! Denoiser speed on CPU: `cargo bench --bench nn`.
//!
//! 1. Raw candle f32 matmul throughput (n x n), the peak the model FLOP utilisation is measured
//!    against, and at the shapes the compact preset's training step multiplies (thin: an inner
//!    or outer dimension of 64-192). Cargo.toml enables gemm's `x86-v4` feature for this.
//! 2. For the `tiny`, `small` and `paper` presets: forward, and forward + backward (one training
//!    step without the optimiser), on a batch of 8 random skeletons with 25..60 joints (padded
//!    to 60) and 40 frames (41 tokens with P_S). GFLOP/s counts the matmul FLOPs of the model
//!    (backward = 2x forward), so `fwd+bwd GFLOP/s / matmul peak` is the FLOP utilisation.
//!
//! Set `NN_BENCH_PRESETS=tiny,small` to skip presets; medians of `RUNS` runs (fewer for slow ones).
//!
//! Measured here (2 shared cores), before the fused kernels (`lib/nn/fused.rs`): the time went
//! to element-wise passes over the J x J and T x T attention maps and to fresh allocations
//! (page faults, memset). glibc returning large blocks to the OS cost a lot; `mo-train` and
//! `mo-sample` call `nn::keep_freed_memory` (mallopt), and so does this bench unless
//! NN_BENCH_GLIBC_DEFAULTS is set. Current numbers: BENCHMARKS.md.

mod common;
use common::{denoiser_forward_flops, median, ms, time_runs};

use candle_core::{DType, Device, Tensor};
use candle_nn::VarMap;
use glam::DVec3;
use menagerie::nn::{batch_from, seeded_var_builder, BatchItem, Denoiser, DenoiserConfig};
use menagerie::repr::Features;
use menagerie::rng::SplitMix64;
use menagerie::skeleton::{topology, Joint, Skeleton};
use std::hint::black_box;
use std::time::{Duration, Instant};

fn matmul_gflops(n: usize) -> f64 {
    shaped_gflops(n, n, n, false)
}

/// GFLOP/s of an (m x k) by (k x n) f32 matmul; `a_transposed`: a is the transpose of a
/// contiguous (k x m) tensor, as in a linear layer's weight gradient dW = dYᵀ X.
fn shaped_gflops(m: usize, k: usize, n: usize, a_transposed: bool) -> f64 {
    let dev = Device::Cpu;
    let a = if a_transposed { Tensor::ones((k, m), DType::F32, &dev).unwrap().t().unwrap() } else { Tensor::ones((m, k), DType::F32, &dev).unwrap() };
    let b = Tensor::ones((k, n), DType::F32, &dev).unwrap();
    let _ = a.matmul(&b).unwrap();
    let t = median(&time_runs(|| {
        black_box(a.matmul(&b).unwrap());
    }));
    2.0 * (m * k * n) as f64 / t.as_secs_f64() / 1e9
}

struct Clip {
    features: Features,
    rest: Vec<f32>,
    relations: Vec<Vec<u8>>,
    distances: Vec<Vec<u8>>,
    names: Vec<Vec<f32>>,
}

/// A random tree of `joints` joints (each joint's parent is an earlier joint) with random features.
fn clip(joints: usize, frames: usize, name_dim: usize, rng: &mut SplitMix64) -> Clip {
    let joints_v: Vec<Joint> = (0..joints)
        .map(|j| Joint {
            name: format!("j{j}"),
            parent: if j == 0 { None } else { Some((rng.unit() * j as f64) as usize) },
            offset: DVec3::ZERO,
            channels: vec![],
            end_sites: vec![],
        })
        .collect();
    let skeleton = Skeleton { joints: joints_v, frame_time: 1.0 / 30.0 };
    let mut features = Features::zeros(frames, joints, 13);
    features.data.iter_mut().for_each(|v| *v = rng.range(-1.0, 1.0) as f32);
    Clip {
        features,
        rest: (0..joints * 13).map(|_| rng.range(-1.0, 1.0) as f32).collect(),
        relations: topology::relations(&skeleton),
        distances: topology::distances(&skeleton, topology::DEFAULT_DMAX),
        names: (0..joints).map(|_| (0..name_dim).map(|_| rng.range(-0.1, 0.1) as f32).collect()).collect(),
    }
}

fn main() {
    // As mo-train and mo-sample run the model (NN_BENCH_GLIBC_DEFAULTS=1: glibc's defaults, which
    // add page faults and kernel zeroing to every step).
    let tuned = std::env::var_os("NN_BENCH_GLIBC_DEFAULTS").is_none();
    if tuned {
        menagerie::nn::keep_freed_memory();
    }
    println!("allocator: {}", if tuned { "freed memory kept (as mo-train)" } else { "glibc defaults" });
    println!();
    println!("| matmul n x n (f32, candle CPU, gemm x86-v4) | GFLOP/s |");
    println!("|---|---|");
    let mut peak: f64 = 0.0;
    for n in [256, 512, 1024] {
        let g = matmul_gflops(n);
        peak = peak.max(g);
        println!("| {n} | {g:.1} |");
    }
    println!();
    // The products a training step of the compact preset (width 64, feed-forward 128) makes, on
    // one sub-batch of a zoo quadruped (4 crops x 41 tokens x 26 joints = 4,264 rows): how near
    // they run to the square peak bounds what a faster matmul could give a step.
    let rows = 4 * 41 * 26;
    println!("| model-shaped matmul, {rows} rows | m x k x n | GFLOP/s |");
    println!("|---|---|---|");
    for (what, m, k, n, t) in [
        ("q, k, v projection", rows, 64, 192, false),
        ("attention output", rows, 64, 64, false),
        ("feed-forward up", rows, 64, 128, false),
        ("feed-forward down", rows, 128, 64, false),
        ("q, k, v input gradient", rows, 192, 64, false),
        ("q, k, v weight gradient", 192, rows, 64, true),
        ("feed-forward down weight gradient", 64, rows, 128, true),
    ] {
        println!("| {what} | {m} x {k} x {n} | {:.1} |", shaped_gflops(m, k, n, t));
    }
    println!();

    let presets: Vec<String> =
        std::env::var("NN_BENCH_PRESETS").unwrap_or_else(|_| "tiny,small,paper".to_string()).split(',').map(|s| s.trim().to_string()).collect();
    let dev = Device::Cpu;
    let frames = 40usize;
    println!("Batches: `8 x 25..60`: 8 skeletons with 25, 30, .. 60 joints (padded to 60); `4 x 25`: one 25-joint");
    println!("skeleton 4 times (an overfit run). {frames} frames + P_S. Threads: {}", rayon::current_num_threads());
    println!();
    println!("| preset | batch | params | forward ms | fwd+bwd ms | fwd+bwd GFLOP/s | of matmul peak |");
    println!("|---|---|---|---|---|---|---|");
    let mut cases: Vec<(String, usize, bool)> = Vec::new();
    for name in presets {
        if name == "tiny" {
            cases.push((name.clone(), 4, false));
        }
        cases.push((name, 8, true));
    }
    for (name, b, mixed) in cases {
        let cfg = match name.as_str() {
            "tiny" => DenoiserConfig::tiny(),
            "small" => DenoiserConfig::small(),
            "paper" => DenoiserConfig::paper(),
            other => {
                println!("unknown preset {other}, skipped");
                continue;
            }
        };
        let clips: Vec<Clip> = (0..b)
            .map(|i| {
                let mut rng = if mixed { SplitMix64::new(i as u64) } else { SplitMix64::new(0) };
                clip(if mixed { 25 + i * 5 } else { 25 }, frames, cfg.name_dim, &mut rng)
            })
            .collect();
        let items: Vec<BatchItem> = clips
            .iter()
            .map(|c| BatchItem { features: &c.features, rest_row: &c.rest, relations: &c.relations, distances: &c.distances, names: &c.names, start: 0 })
            .collect();
        let steps: Vec<u32> = (0..b as u32).map(|i| i * 12).collect();
        let batch = batch_from(&items, &steps, &dev).unwrap();
        let vm = VarMap::new();
        let model = Denoiser::new(seeded_var_builder(&vm, 0, &dev), &cfg).unwrap();
        let (_, t, j, _) = batch.dims().unwrap();
        let flops = denoiser_forward_flops(&cfg, b, t, j);
        // One warm-up, then fewer runs when a step takes seconds.
        let warm = Instant::now();
        black_box(model.forward(&batch).unwrap());
        let runs = if warm.elapsed() > Duration::from_secs(2) { 3 } else { common::RUNS };
        let timed = |f: &dyn Fn()| {
            let mut v: Vec<Duration> = (0..runs)
                .map(|_| {
                    let s = Instant::now();
                    f();
                    s.elapsed()
                })
                .collect();
            v.sort();
            v[v.len() / 2]
        };
        let fwd = timed(&|| {
            black_box(model.forward(&batch).unwrap());
        });
        let step = timed(&|| {
            let y = model.forward(&batch).unwrap();
            let loss = y.sqr().unwrap().mean_all().unwrap();
            black_box(loss.backward().unwrap());
        });
        let gflops = 3.0 * flops / step.as_secs_f64() / 1e9;
        println!(
            "| {name} | {} | {} | {:.1} | {:.1} | {:.1} | {:.0}% |",
            if mixed { format!("{b} x 25..60") } else { format!("{b} x 25") },
            cfg.parameter_count(),
            ms(fwd),
            ms(step),
            gflops,
            100.0 * gflops / peak
        );
    }
}
