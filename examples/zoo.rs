//! Writes the procedural example creatures (see `menagerie::synth`) as BVH files.
//!
//! usage: cargo run --release --example zoo [OUTPUT_DIR] [--seed N]
//!
//! The default directory is `examples/data` and the default seed `synth::DEFAULT_SEED`; the
//! same seed always writes byte-identical files.

use menagerie::synth;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut dir: Option<PathBuf> = None;
    let mut seed = synth::DEFAULT_SEED;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let value = if arg == "--seed" {
            args.next()
        } else if let Some(v) = arg.strip_prefix("--seed=") {
            Some(v.to_string())
        } else if arg == "-h" || arg == "--help" {
            let names = synth::creature_names().join(", ");
            println!("usage: zoo [OUTPUT_DIR] [--seed N]\nWrites {names} as BVH into OUTPUT_DIR (default examples/data).");
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
