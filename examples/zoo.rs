//! Writes the procedural example creatures (see `menagerie::synth`) as BVH files.
//!
//! usage: cargo run --release --example zoo [OUTPUT_DIR] [--seed N]
//!        cargo run --release --example zoo -- --training DIR [--variants N] [--clips N] [--seed N]
//!
//! The default directory is `examples/data` and the default seed `synth::DEFAULT_SEED`; the
//! same seed always writes byte-identical files. `--training` writes the training zoo instead
//! (`synth::write_training_zoo`: every action of every creature on variants 0..N, default 8,
//! N clips per action, default 1) into DIR/<creature>_v<k>/<action>_<n>.bvh. Variants from
//! `synth::RIG_VARIANTS` (8) on also come in the conventions of real files (Mixamo, LAFAN, CMU
//! and 3ds Max Biped names, Z-up, centimetres, root at the origin, jaws, ears and fingers), so
//! `--variants 16` adds eight such bodies per creature; 0..8 stay as they always were.

use menagerie::synth;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut dir: Option<PathBuf> = None;
    let mut seed = synth::DEFAULT_SEED;
    let mut training: Option<PathBuf> = None;
    let (mut variants, mut clips) = (8u64, 1u64);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if arg == "--training" {
            match args.next() {
                Some(d) => training = Some(PathBuf::from(d)),
                None => {
                    eprintln!("zoo: --training needs a directory");
                    return ExitCode::from(2);
                }
            }
            continue;
        }
        if arg == "--variants" || arg == "--clips" {
            match args.next().as_deref().map(str::parse::<u64>) {
                Some(Ok(n)) if arg == "--variants" => variants = n,
                Some(Ok(n)) => clips = n,
                _ => {
                    eprintln!("zoo: {arg} needs a non-negative integer");
                    return ExitCode::from(2);
                }
            }
            continue;
        }
        let value = if arg == "--seed" {
            args.next()
        } else if let Some(v) = arg.strip_prefix("--seed=") {
            Some(v.to_string())
        } else if arg == "-h" || arg == "--help" {
            let names = synth::creature_names().join(", ");
            println!("usage: zoo [OUTPUT_DIR] [--seed N]\nWrites {names} as BVH into OUTPUT_DIR (default examples/data).");
            println!("       zoo --training DIR [--variants N] [--clips N] [--seed N]\nWrites the training zoo: every action on variants 0..N (default 8), N clips each (default 1).");
            return ExitCode::SUCCESS;
        } else if arg.starts_with('-') && arg != "-" {
            eprintln!("zoo: unknown option '{arg}' (usage: zoo [OUTPUT_DIR] [--seed N])");
            return ExitCode::from(2);
        } else if dir.is_none() {
            dir = Some(PathBuf::from(arg));
            continue;
        } else {
            eprintln!("zoo: more than one output directory given");
            return ExitCode::from(2);
        };
        match value.as_deref().map(str::parse::<u64>) {
            Some(Ok(n)) => seed = n,
            _ => {
                eprintln!("zoo: --seed needs a non-negative integer");
                return ExitCode::from(2);
            }
        }
    }
    if let Some(dir) = training {
        return match synth::write_training_zoo(&dir, variants, clips as usize, seed) {
            Ok(paths) => {
                println!("{}: {} clips, action boundaries in boundaries.tsv", dir.display(), paths.len());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("zoo: cannot write {}: {e}", dir.display());
                ExitCode::from(2)
            }
        };
    }
    let dir = dir.unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/data"));
    match synth::write_zoo(&dir, seed) {
        Ok(paths) => {
            for path in paths {
                let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
                let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
                let (skeleton, motion) = synth::creature(name, seed).expect("written creatures exist");
                let kb = bytes as f64 / 1024.0;
                println!("{}: {} joints, {} frames, {kb:.1} KB", path.display(), skeleton.len(), motion.frames);
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("zoo: cannot write {}: {e}", dir.display());
            ExitCode::from(2)
        }
    }
}
