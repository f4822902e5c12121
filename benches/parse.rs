//! BVH parse and write throughput: `cargo bench --bench parse`.
//!
//! Two inputs: the largest real file under `../shared/data/bvh` (skipped with a note when the
//! data is absent) and a ~50 MB synthetic file built here, so the number that matters (frame
//! parsing speed on one core) is measurable on any checkout. Each is parsed and written
//! `RUNS` times; the table reports the median (robust to a noisy machine) and the minimum
//! (closest to what the code can do). No benchmark framework, to keep dependencies at zero.
//! Results and history are in BENCHMARKS.md.

mod common;
use common::{median, min, ms, time_runs, RUNS};

use menagerie::bvh;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Size of the synthetic input; large enough that per-call overheads vanish and the frame
/// matrix (~37 MB of f64) is well beyond the caches, as with a long real capture.
const SYNTHETIC_BYTES: usize = 50_000_000;
const SYNTHETIC_JOINTS: usize = 60;

fn main() {
    let mut inputs: Vec<(String, Vec<u8>)> = Vec::new();
    let data_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bvh");
    match largest_bvh(&data_dir) {
        Some(path) => {
            let bytes = std::fs::read(&path).expect("reading the largest corpus file");
            let name = path.strip_prefix(&data_dir).unwrap_or(&path).display().to_string();
            inputs.push((name, bytes));
        }
        None => println!("note: no .bvh files under {}; skipping the real-file input", data_dir.display()),
    }
    inputs.push((format!("synthetic ({SYNTHETIC_JOINTS} joints)"), synthetic_bvh(SYNTHETIC_BYTES)));

    println!("{RUNS} runs each; MB = 10^6 bytes; MB/s from the median; write MB/s counts the bytes written");
    println!();
    println!("| input | bytes | frames | parse median ms | parse min ms | parse MB/s | write median ms | write MB/s |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for (name, bytes) in &inputs {
        let mut parsed = None;
        let parse_times = time_runs(|| {
            let b = bvh::parse_bytes(black_box(bytes), name).unwrap_or_else(|e| panic!("{e}"));
            // Keep the last result (for the write timing) without timing its drop on the next run.
            drop(parsed.replace(b));
        });
        let parsed = parsed.unwrap();
        let mut written_len = 0;
        let write_times = time_runs(|| {
            let s = bvh::write_string(black_box(&parsed));
            written_len = s.len();
        });
        let (pmed, pmin) = (median(&parse_times), min(&parse_times));
        let wmed = median(&write_times);
        println!(
            "| {name} | {} | {} | {:.1} | {:.1} | {:.0} | {:.1} | {:.0} |",
            bytes.len(),
            parsed.frames,
            ms(pmed),
            ms(pmin),
            mb_per_s(bytes.len(), pmed),
            ms(wmed),
            mb_per_s(written_len, wmed),
        );
    }
}

fn mb_per_s(bytes: usize, d: Duration) -> f64 {
    bytes as f64 / 1e6 / d.as_secs_f64()
}

/// The largest `.bvh` file under `dir` (searched recursively), if any.
fn largest_bvh(dir: &Path) -> Option<PathBuf> {
    common::bvh_files(dir).into_iter().max_by_key(|p| std::fs::metadata(p).map_or(0, |m| m.len()))
}

/// A deterministic BVH of about `target` bytes: a root with 6 channels and a chain-and-branches
/// hierarchy of 3-channel joints, frame values with six decimals like motion-capture exports
/// (`-171.350895`), mixed magnitudes and signs so the number parser sees realistic variety.
fn synthetic_bvh(target: usize) -> Vec<u8> {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(target + 4096);
    s.push_str("HIERARCHY\nROOT Hips\n{\n\tOFFSET 0.000000 0.000000 0.000000\n");
    s.push_str("\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n");
    // Five limbs of (JOINTS - 1) / 5 joints each, every limb a chain ending in an End Site.
    let per_limb = (SYNTHETIC_JOINTS - 1) / 5;
    let mut channels = 6;
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for limb in 0..5 {
        for depth in 0..per_limb {
            let pad = "\t".repeat(depth + 1);
            let _ = writeln!(s, "{pad}JOINT limb{limb}_joint{depth}\n{pad}{{");
            let _ = writeln!(s, "{pad}\tOFFSET {:.6} {:.6} {:.6}", rng.value(20.0), rng.value(20.0), rng.value(20.0));
            let _ = writeln!(s, "{pad}\tCHANNELS 3 Zrotation Xrotation Yrotation");
            channels += 3;
        }
        let pad = "\t".repeat(per_limb + 1);
        let _ = writeln!(s, "{pad}End Site\n{pad}{{\n{pad}\tOFFSET 0.000000 5.000000 0.000000\n{pad}}}");
        for depth in (0..per_limb).rev() {
            let _ = writeln!(s, "{}}}", "\t".repeat(depth + 1));
        }
    }
    s.push_str("}\n");

    // One row, then as many as fit: the header needs the count, so rows are built first.
    let mut rows = String::with_capacity(target);
    let mut frames = 0;
    while rows.len() < target.saturating_sub(s.len() + 64) {
        for c in 0..channels {
            if c > 0 {
                rows.push(' ');
            }
            // Root position in centimetres, rotations in degrees.
            let range = if c < 3 { 150.0 } else { 180.0 };
            let _ = write!(rows, "{:.6}", rng.value(range));
        }
        rows.push('\n');
        frames += 1;
    }
    let _ = write!(s, "MOTION\nFrames: {frames}\nFrame Time: 0.008333\n");
    s.push_str(&rows);
    s.into_bytes()
}

/// xorshift64*: tiny, deterministic, and good enough to vary digits and signs.
struct Rng(u64);

impl Rng {
    /// Uniform-ish in (-range, range).
    fn value(&mut self, range: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        (bits as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * range
    }
}
