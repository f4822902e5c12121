//! What the benchmarks share: repeated timing, medians, and finding BVH files.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Runs per measurement; tables report the median (robust on a noisy machine).
pub const RUNS: usize = 7;

pub fn time_runs(mut f: impl FnMut()) -> Vec<Duration> {
    (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed()
        })
        .collect()
}

pub fn median(t: &[Duration]) -> Duration {
    let mut t = t.to_vec();
    t.sort();
    t[t.len() / 2]
}

pub fn min(t: &[Duration]) -> Duration {
    *t.iter().min().unwrap()
}

pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Every `.bvh` file under `dir` (recursively), sorted; empty when `dir` is missing.
pub fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh")) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Matmul FLOPs of one forward pass (multiply-adds x 2), for tokens `b x t x j`.
pub fn denoiser_forward_flops(cfg: &menagerie::nn::DenoiserConfig, b: usize, t: usize, j: usize) -> f64 {
    let (d, h) = (cfg.width as f64, cfg.heads as f64);
    let (b, t, j) = (b as f64, t as f64, j as f64);
    let n = b * t * j;
    let types = (cfg.dmax + 1 + 6) as f64;
    let input = 2.0 * n * (cfg.feature_dims as f64 + cfg.name_dim as f64 / t) * d;
    let linears = 2.0 * n * d * d * 8.0 + 2.0 * n * d * cfg.ff as f64 * 2.0;
    let skeletal = 2.0 * b * t * j * j * d * 2.0 + 2.0 * n * d * types * 2.0 + 2.0 * b * j * t * h * types * j;
    let temporal = 2.0 * b * j * t * t * d * 2.0;
    let output = 2.0 * n * d * cfg.feature_dims as f64;
    input + cfg.layers as f64 * (linears + skeletal + temporal) + output
}
