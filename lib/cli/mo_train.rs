//! `mo-train`: train AnyTop's denoiser on folders of BVH clips, with checkpoints that resume.

use crate::cli::load::{expand_inputs, load_motions, LoadOptions};
use crate::cli::CommonOpts;
use crate::diffusion::checkpoint::{self, CheckpointInfo, TrainedSkeleton};
use crate::diffusion::data::{RawClip, TrainSet};
use crate::diffusion::train::{named_vars, train_step, AdamW};
use crate::diffusion::Schedule;
use crate::embed::NameTable;
use crate::nn::{seeded_var_builder, Denoiser, DenoiserConfig};
use crate::skeleton::topology;
use crate::synth::SplitMix64;
use anyhow::{bail, Context};
use candle_core::Device;
use candle_nn::VarMap;
use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-train examples/data --out model --preset tiny --steps 3 --batch 2 --crop 16
    mo-train examples/data --out model --preset tiny --steps 5 --batch 2 --crop 16 --resume";

/// Train the diffusion model (AnyTop's denoiser) on BVH clips of any skeletons.
///
/// DATA are BVH files or directories of them. Clips are grouped by skeleton (same joint names
/// and parents); each skeleton gets its AnyTop rig (rest pose from a T-pose file if one is
/// named so, else its first clip), its own normalisation statistics, topology (R, D) and
/// joint-name embeddings. Training draws --batch crops of --crop frames per step, every
/// skeleton equally often, noises them at a random step of the cosine schedule (T = 100) and
/// teaches the model to predict the clean motion (masked MSE plus --lambda-geo x a rotation
/// distance), with AdamW.
///
/// Checkpoints go to --out (model.safetensors, optimizer.safetensors, checkpoint.json) every
/// --checkpoint-minutes and at the end; --resume continues from the one there, exactly as the
/// run would have gone on. A JSON-lines log (step, loss, steps/s) is appended to OUT/log.jsonl.
/// The same data, flags and --seed give the same run.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-train", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH files or directories of them.
    #[arg(value_name = "DATA", required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// Model directory to write (and to resume from).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Model size: tiny, small or paper (width 128, 4 layers, 4 heads).
    #[arg(long, value_enum, default_value_t = Preset::Small)]
    pub preset: Preset,
    /// Training steps in total (a resumed run counts the steps already done).
    #[arg(long, value_name = "N", default_value_t = 10_000)]
    pub steps: u64,
    /// Crops per step.
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub batch: u64,
    /// Crop length in frames.
    #[arg(long, value_name = "FRAMES", default_value_t = 40, value_parser = clap::value_parser!(u64).range(2..=1000))]
    pub crop: u64,
    /// Learning rate.
    #[arg(long, value_name = "LR", default_value_t = 1e-4)]
    pub lr: f64,
    /// Weight of the rotation loss (1 - cos of the angle between predicted and true joint
    /// rotations) next to the MSE; the reference trains with 1.
    #[arg(long, value_name = "W", default_value_t = 1.0)]
    pub lambda_geo: f64,
    /// Save a checkpoint at least this often.
    #[arg(long, value_name = "MIN", default_value_t = 5.0)]
    pub checkpoint_minutes: f64,
    /// Continue from the checkpoint in --out.
    #[arg(long)]
    pub resume: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    Tiny,
    Small,
    Paper,
}

impl Preset {
    fn config(self) -> DenoiserConfig {
        match self {
            Preset::Tiny => DenoiserConfig::tiny(),
            Preset::Small => DenoiserConfig::small(),
            Preset::Paper => DenoiserConfig::paper(),
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads();
    crate::nn::keep_freed_memory();
    if !(args.lr.is_finite() && args.lr > 0.0) {
        bail!("--lr must be a positive number, found {}", args.lr);
    }
    let files = expand_inputs(&args.data)?;
    let loaded = load_motions(&files, &LoadOptions::default())?;
    let clips: Vec<RawClip> = loaded.into_iter().map(|l| RawClip { name: l.name, skeleton: l.skeleton, motion: l.motion }).collect();
    let names = NameTable::builtin().context("the built-in joint-name table")?;
    let dmax = topology::DEFAULT_DMAX;
    let (set, dropped) = TrainSet::build(clips, names, dmax)?;
    let say = |msg: String| {
        if !args.common.quiet {
            eprintln!("mo-train: {msg}");
        }
    };
    for d in &dropped {
        say(format!("{d}: too short to crop, left out"));
    }
    say(format!(
        "{} skeletons, {} clips, {} feature frames",
        set.skeletons.len(),
        set.skeletons.iter().map(|s| s.clips.len()).sum::<usize>(),
        set.skeletons.iter().flat_map(|s| &s.clips).map(|c| c.frames).sum::<usize>()
    ));

    let device = Device::Cpu;
    let schedule = Schedule::cosine(100);
    let (varmap, model, mut opt, mut info) = if args.resume {
        let loaded = checkpoint::load(&args.out, &device)?;
        let opt = checkpoint::load_optimizer(&args.out, &loaded.info, &device, args.lr)?;
        if loaded.info.batch as u64 != args.batch || loaded.info.crop as u64 != args.crop || loaded.info.seed != args.common.seed {
            say("note: --batch, --crop or --seed differ from the checkpoint's; the resumed run is not the one it would have been".into());
        }
        (loaded.varmap, loaded.model, opt, loaded.info)
    } else {
        if args.out.join("checkpoint.json").exists() {
            bail!("{} already holds a checkpoint: --resume to continue it, or choose another --out", args.out.display());
        }
        let varmap = VarMap::new();
        let cfg = args.preset.config();
        let model = Denoiser::new(seeded_var_builder(&varmap, args.common.seed, &device), &cfg)?;
        let info = CheckpointInfo {
            format: checkpoint::FORMAT.into(),
            version: checkpoint::VERSION,
            config: cfg,
            step: 0,
            seed: args.common.seed,
            schedule_steps: schedule.len(),
            lr: args.lr,
            batch: args.batch as usize,
            crop: args.crop as usize,
            dmax,
            skeletons: Vec::new(),
        };
        (varmap, model, AdamW::new(args.lr), info)
    };
    info.skeletons = set
        .skeletons
        .iter()
        .map(|s| TrainedSkeleton {
            name: s.name.clone(),
            joints: s.skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            parents: s.skeleton.parents(),
            stats: s.stats.clone(),
            clips: s.clips.len(),
        })
        .collect();
    let vars = named_vars(&varmap);
    // The data stream of step k depends only on the seed and k, so a resumed run draws what
    // the uninterrupted one would have.
    let step_rng = |k: u64| SplitMix64::new(info.seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut log = std::fs::OpenOptions::new().create(true).append(true).open(args.out.join("log.jsonl")).context("cannot open the training log")?;
    let started = Instant::now();
    let mut last_save = Instant::now();
    let first = info.step;
    let every = Duration::from_secs_f64(args.checkpoint_minutes.max(0.0) * 60.0);
    let terminal = std::io::IsTerminal::is_terminal(&std::io::stderr());
    while info.step < args.steps {
        let mut rng = step_rng(info.step);
        let stats = train_step(&model, &vars, &mut opt, &set, &schedule, &mut rng, args.batch as usize, args.crop as usize, args.lambda_geo, &device)?;
        info.step += 1;
        let done = info.step - first;
        let rate = done as f64 / started.elapsed().as_secs_f64().max(1e-9);
        let eta = (args.steps - info.step) as f64 / rate.max(1e-9);
        writeln!(log, "{{\"step\":{},\"loss\":{},\"steps_per_second\":{:.4},\"elapsed\":{:.2}}}", info.step, stats.loss, rate, started.elapsed().as_secs_f64())
            .context("cannot write the training log")?;
        if !args.common.quiet && (terminal || info.step % 50 == 0 || info.step == args.steps) {
            let line = format!("step {}/{}  loss {:.4}  {:.2} steps/s  ETA {:.0} s", info.step, args.steps, stats.loss, rate, eta);
            if terminal { eprint!("\rmo-train: {line}   ") } else { eprintln!("mo-train: {line}") }
        }
        if last_save.elapsed() >= every {
            checkpoint::save(&args.out, &info, &varmap, &opt)?;
            last_save = Instant::now();
        }
    }
    if terminal && !args.common.quiet {
        eprintln!();
    }
    checkpoint::save(&args.out, &info, &varmap, &opt)?;
    say(format!("saved step {} to {}", info.step, args.out.display()));
    Ok(())
}
