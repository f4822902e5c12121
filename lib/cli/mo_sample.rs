//! `mo-sample`: generate motion for any skeleton with a trained denoiser.

use crate::cli::load::{is_dash, read_skeleton};
use crate::cli::CommonOpts;
use crate::diffusion::checkpoint;
use crate::diffusion::sample::{sample, Condition, SampleOptions};
use crate::diffusion::{Sampler, Schedule};
use crate::embed::NameTable;
use crate::io::{self, npy};
use crate::repr::anytop::{AnyTopStats, IkOptions, FEATURE_DIMS};
use crate::repr::Features;
use crate::skeleton::topology;
use crate::bvh;
use anyhow::{bail, Context};
use candle_core::Device;
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    skel-info examples/data/dragon.bvh | mo-sample --model model -n 2 --frames 30 --steps 5 > d.npy
    mo-sample examples/data/spider.bvh --model model --frames 30 --steps 5 --bvh 'spider_{i}.bvh'";

/// Generate motion for a skeleton with a trained diffusion model (AnyTop).
///
/// SKELETON is a skeleton document (skel-info's JSON, also on stdin) or a BVH file. The model
/// needs only the skeleton's topology, rest pose and joint names, so skeletons never seen in
/// training work too. Output: NPY [n, frames, joints, 13] AnyTop features in physical units on
/// stdout (or -o), or BVH files with --bvh PATTERN ('{i}' = sample index), posed by inverse
/// kinematics from the generated joint positions.
///
/// Normalisation: a skeleton the model was trained on uses its training statistics; else the
/// document's own statistics (skel-info of a BVH with motion); else the rest-pose row as mean and
/// the trained skeletons' average spreads (said on stderr).
///
/// Sampling: --steps 100 with --sampler ddpm is the reference's full ancestral loop; fewer steps
/// respace it (or use ddim) for speed. The same seed, model and input give the same output.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-sample", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// Skeleton document or BVH ('-' = stdin).
    #[arg(value_name = "SKELETON", default_value = "-")]
    pub skeleton: PathBuf,
    /// Model directory written by mo-train.
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
    /// Number of samples.
    #[arg(short = 'n', long = "samples", value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub samples: u64,
    /// Frames per sample.
    #[arg(long, value_name = "N", default_value_t = 120, value_parser = clap::value_parser!(u64).range(1..=10_000), conflicts_with = "seconds")]
    pub frames: u64,
    /// Length in seconds (at the skeleton's frame rate).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Diffusion steps to visit (1..=100).
    #[arg(long, value_name = "N", default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub steps: u64,
    /// Sampler.
    #[arg(long, value_enum, default_value_t = SamplerArg::Ddpm)]
    pub sampler: SamplerArg,
    /// Write BVH files instead of NPY ('{i}' becomes the sample index).
    #[arg(long, value_name = "PATTERN")]
    pub bvh: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerArg {
    Ddpm,
    Ddim,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads();
    crate::nn::keep_freed_memory();
    let Some(model_dir) = &args.model else {
        bail!("--model DIR is needed: no default model ships yet (train one with mo-train)");
    };
    let count = args.samples as usize;
    let outputs: Option<Vec<PathBuf>> = match &args.bvh {
        Some(p) => Some((0..count).map(|i| io::numbered_output(p, i, count).map_err(anyhow::Error::msg)).collect::<anyhow::Result<_>>()?),
        None => None,
    };
    let arg = read_skeleton(&args.skeleton)?;
    let skeleton = &arg.skeleton;
    let device = Device::Cpu;
    let loaded = checkpoint::load(model_dir, &device)?;
    let section = arg.record()?;
    let fps = if skeleton.frame_time > 0.0 { 1.0 / skeleton.frame_time } else { 30.0 };
    let frames = match args.seconds {
        Some(s) if s.is_finite() && s > 0.0 => ((s * fps).round() as usize).max(1),
        Some(s) => bail!("--seconds must be a positive number, found {s}"),
        None => args.frames as usize,
    };

    let stats = match checkpoint::find_trained(&loaded.info.skeletons, skeleton) {
        Some(t) => t.stats.clone(),
        None => match &section.stats {
            Some(s) => s.clone(),
            None => {
                if !args.common.quiet {
                    eprintln!("mo-sample: {}: not a trained skeleton and no statistics in it: normalising by its rest pose and the trained skeletons' spreads", arg.name);
                }
                fallback_stats(&section.rest_row, &loaded.info.skeletons.iter().map(|t| &t.stats).collect::<Vec<_>>())?
            }
        },
    };
    let mut rest = Features { frames: 1, joints: skeleton.len(), dims: FEATURE_DIMS, data: section.rest_row.concat() };
    stats.normalise(&mut rest).map_err(|e| anyhow::anyhow!("{}: {e}", arg.name))?;
    let names = NameTable::builtin().context("the built-in joint-name table")?.embed_skeleton(skeleton);
    let relations = topology::relations(skeleton);
    let distances = topology::distances(skeleton, loaded.info.dmax);
    let cond = Condition { rest_row: &rest.data, relations: &relations, distances: &distances, names: &names, stats: &stats };
    let sampler = match args.sampler {
        SamplerArg::Ddpm => Sampler::Ddpm,
        SamplerArg::Ddim => Sampler::Ddim,
    };
    let schedule = Schedule::cosine(loaded.info.schedule_steps);
    let opts = SampleOptions { samples: count, frames, steps: args.steps as usize, sampler, seed: args.common.seed };
    let started = std::time::Instant::now();
    let samples = sample(&loaded.model, &schedule, &cond, &opts, &device)?;
    if args.common.verbose {
        eprintln!("mo-sample: {count} x {frames} frames in {:.2} s", started.elapsed().as_secs_f64());
    }

    match outputs {
        Some(paths) => {
            let placement = section.rig.rest_placement();
            let mut texts = Vec::with_capacity(count);
            for (i, f) in samples.iter().enumerate() {
                let motion = section.rig.decode_ik(skeleton, f, &placement, &IkOptions::default()).map_err(|e| anyhow::anyhow!("sample {i}: {e}"))?;
                texts.push(bvh::write_string(&motion.to_bvh(skeleton)));
            }
            for (p, t) in paths.iter().zip(texts) {
                io::write_output(Some(p), t.as_bytes()).with_context(|| format!("cannot write {}", p.display()))?;
            }
        }
        None => {
            if args.common.output.as_deref().is_none_or(is_dash) && std::io::IsTerminal::is_terminal(&std::io::stdout()) {
                bail!("refusing to write NPY to a terminal: redirect stdout, or give -o FILE or --bvh PATTERN");
            }
            let shape = [count, frames, skeleton.len(), FEATURE_DIMS];
            let parts: Vec<&[f32]> = samples.iter().map(|f| f.data.as_slice()).collect();
            let mut bytes = Vec::new();
            npy::write_f32_parts(&mut bytes, &shape, &parts).context("building the NPY")?;
            io::write_output(args.common.output.as_deref(), &bytes).context("cannot write the samples")?;
        }
    }
    Ok(())
}

/// Statistics for a skeleton nobody measured: its rest-pose row as the mean, and the average
/// of the trained skeletons' (grouped) spreads — the root's from their roots, every other
/// joint's from their non-root joints.
fn fallback_stats(rest_row: &[Vec<f32>], trained: &[&AnyTopStats]) -> anyhow::Result<AnyTopStats> {
    if trained.is_empty() {
        bail!("the model records no trained skeleton statistics");
    }
    let d = FEATURE_DIMS;
    let mut root = vec![0f32; d];
    let mut joint = vec![0f32; d];
    for s in trained {
        for k in 0..d {
            root[k] += s.std[k] / trained.len() as f32;
            // Joint 1's spreads stand for every non-root joint (they share them, §1.8).
            joint[k] += s.std.get(d + k).copied().unwrap_or(s.std[k]) / trained.len() as f32;
        }
    }
    let mean: Vec<f32> = rest_row.concat();
    let std: Vec<f32> = (0..rest_row.len()).flat_map(|j| if j == 0 { root.clone() } else { joint.clone() }).collect();
    Ok(AnyTopStats { mean, std })
}
