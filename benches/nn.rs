//! Denoiser speed: `cargo bench --bench nn`.
//!
//! Raw candle f32 matmul throughput first (the machine's peak for model FLOP utilisation).

mod common;
use common::{median, time_runs};

use candle_core::{Device, Tensor};
use std::hint::black_box;

fn matmul_gflops(n: usize) -> f64 {
    let dev = Device::Cpu;
    let a = Tensor::ones((n, n), candle_core::DType::F32, &dev).unwrap();
    let b = Tensor::ones((n, n), candle_core::DType::F32, &dev).unwrap();
    let _ = a.matmul(&b).unwrap();
    let t = median(&time_runs(|| {
        black_box(a.matmul(&b).unwrap());
    }));
    2.0 * (n as f64).powi(3) / t.as_secs_f64() / 1e9
}

fn main() {
    println!("| matmul n x n (f32, candle CPU) | GFLOP/s |");
    println!("|---|---|");
    for n in [256, 512, 1024] {
        println!("| {n} | {:.1} |", matmul_gflops(n));
    }
}
