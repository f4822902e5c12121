//! `mo-train`: train AnyTop's denoiser on folders of BVH clips, with checkpoints that resume.

use crate::cli::bounds;
use crate::cli::load::{expand_inputs, load_motions, LoadOptions};
use crate::cli::CommonOpts;
use crate::diffusion::checkpoint::{self, CheckpointInfo, TrainedSkeleton};
use crate::diffusion::data::{Augmentation, RawClip, TrainSet};
use crate::diffusion::train::{named_vars, train_step, AdamW};
use crate::diffusion::Schedule;
use crate::embed::NameTable;
use crate::nn::{seeded_var_builder, Denoiser, DenoiserConfig};
use crate::sata::{self, checkpoint::SataInfo, train::{FeatureScale, LossWeights}, SataConfig, SataModel};
use crate::skeleton::topology;
use crate::synth::SplitMix64;
use anyhow::{bail, Context};
use candle_core::Device;
use candle_nn::VarMap;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-train examples/data --out model --preset tiny --steps 3 --batch 2 --crop 16
    mo-train examples/data --out model --preset tiny --steps 5 --batch 2 --crop 16 --resume
    mo-train examples/data --out model2 --preset tiny --steps 3 --batch 2 --crop 16 --augment 0";

/// Train the diffusion model (AnyTop's denoiser) on BVH clips of any skeletons.
///
/// DATA are BVH files or directories of them. Clips are grouped by skeleton: same joint names
/// and parents and the same proportions (rest offsets within 0.1% of the body's size), so
/// proportion variants of one rig train as separate skeletons. A group is named after its
/// folder when it is the folder's only skeleton, else after its clips' common file-name stem.
/// Each skeleton gets its AnyTop rig (rest pose from a T-pose file if one is named so, else its
/// first clip), its own normalisation statistics, topology (R, D) and joint-name embeddings.
///
/// Training draws --batch crops of --crop frames per step, every skeleton equally often,
/// noises them at a random step of the cosine schedule (T = 100) and teaches the model to
/// predict the clean motion, with AdamW. The loss is the masked MSE of the normalised features
/// plus --lambda-geo x the geodesic angle (radians, arccos((tr(R'^T R) - 1) / 2), clamped as
/// the reference) between predicted and true joint rotations.
///
/// Skeletal augmentation (AnyTop appendix C): before training, --augment-variants edited
/// copies of every skeleton are prepared, alternately with 10-30% of the joints removed (whole
/// end-effector chains, never feet) and with one bone subdivided, each with its own rest pose,
/// statistics, topology and names. Each clip (or, when a skeleton has fewer clips than
/// variants, a piece of one) is re-encoded for one variant only, so feature memory at most
/// about doubles. A draw then uses one of the variants with probability --augment (default 2/3:
/// the reference picks none / remove / add uniformly). --augment 0 turns it off.
///
/// Checkpoints go to --out (model.safetensors, optimizer.safetensors, checkpoint.json) every
/// --checkpoint-minutes and at the end; --resume continues from the one there, exactly as the
/// run would have gone on. Ctrl-C (or SIGTERM) stops at the end of the current step, saves a
/// checkpoint and exits with code 130; a second Ctrl-C quits at once (the last checkpoint
/// stays whole). A JSON-lines log (step, loss, steps/s) is appended to OUT/log.jsonl. On a
/// terminal a progress bar shows loss, steps/s and ETA; otherwise a line every 50 steps.
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
    #[arg(long, value_name = "N", default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=bounds::MAX_TRAIN_STEPS))]
    pub steps: u64,
    /// Crops per step.
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub batch: u64,
    /// Crop length in frames (default 40 for anytop; for sata the preset's window, 32 for
    /// small, which then is also the model's inference window).
    #[arg(long, value_name = "FRAMES", value_parser = clap::value_parser!(u64).range(2..=1000))]
    pub crop: Option<u64>,
    /// What to train: anytop (the diffusion model behind mo-sample, mo-dift and mo-segment) or
    /// sata (the topology-agnostic autoencoder behind mo-encode --latent and mo-retarget
    /// --method latent).
    #[arg(long, value_enum, default_value_t = Arch::Anytop)]
    pub arch: Arch,
    /// sata: weight of the KL term that keeps the latent near a unit Gaussian.
    #[arg(long, value_name = "W", default_value_t = 1e-4, value_parser = bounds::non_negative(bounds::MAX_WEIGHT))]
    pub lambda_kl: f64,
    /// sata: weight of the cross-skeleton latent cycle (a motion's latent decoded onto another
    /// training skeleton and encoded again should come back). Default 0 for a new run (tried
    /// at 1 for 1,100 steps: transfers moved less, models/zoo-sata/MODEL_CARD.md); a resumed
    /// run keeps its checkpoint's unless this is given.
    #[arg(long, value_name = "W", value_parser = bounds::non_negative(bounds::MAX_WEIGHT))]
    pub lambda_cycle: Option<f64>,
    /// Learning rate.
    #[arg(long, value_name = "LR", default_value_t = 1e-4, value_parser = bounds::positive(1.0))]
    pub lr: f64,
    /// Weight of the geodesic rotation loss (the angle, in radians, between predicted and true
    /// joint rotations) next to the MSE; the reference trains with 1.
    #[arg(long, value_name = "W", default_value_t = 1.0, value_parser = bounds::non_negative(bounds::MAX_WEIGHT))]
    pub lambda_geo: f64,
    /// Chance that a training draw uses an augmented skeleton (joints removed or added), as a
    /// number in [0, 1] or a fraction like 2/3.
    #[arg(long, value_name = "P", default_value = "2/3", value_parser = parse_probability)]
    pub augment: f64,
    /// Augmented variants prepared per skeleton (alternately removing and adding joints).
    #[arg(long, value_name = "N", default_value_t = Augmentation::DEFAULT_VARIANTS as u64, value_parser = clap::value_parser!(u64).range(0..=64))]
    pub augment_variants: u64,
    /// Save a checkpoint at least this often.
    #[arg(long, value_name = "MIN", default_value_t = 5.0, value_parser = bounds::positive(bounds::MAX_CHECKPOINT_MINUTES))]
    pub checkpoint_minutes: f64,
    /// Continue from the checkpoint in --out.
    #[arg(long)]
    pub resume: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// A probability: a decimal in [0, 1] or a fraction `a/b`.
fn parse_probability(text: &str) -> Result<f64, String> {
    let value = match text.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) = (a.trim().parse().map_err(|_| format!("'{text}' is not a fraction"))?, b.trim().parse().map_err(|_| format!("'{text}' is not a fraction"))?);
            a / b
        }
        None => text.trim().parse().map_err(|_| format!("'{text}' is not a number"))?,
    };
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("expected a probability in [0, 1], found {text}"))
    }
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arch {
    Anytop,
    Sata,
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

    fn sata(self) -> SataConfig {
        match self {
            Preset::Tiny => SataConfig::tiny(),
            Preset::Small => SataConfig::small(),
            Preset::Paper => SataConfig::paper(),
        }
    }
}

/// The training ended on Ctrl-C or SIGTERM, after saving a checkpoint.
#[derive(Debug, thiserror::Error)]
#[error("interrupted at step {step}, checkpoint saved; --resume to continue")]
pub struct Interrupted {
    pub step: u64,
}

/// Exit code after an interruption (128 + SIGINT, what shells report for Ctrl-C).
pub const INTERRUPTED_EXIT: u8 = 130;

/// `run`, then the exit code: 130 after Ctrl-C, else as `cli::finish`.
pub fn main(args: &Args) -> std::process::ExitCode {
    match run(args) {
        Err(e) if e.is::<Interrupted>() => {
            eprintln!("mo-train: {e}");
            std::process::ExitCode::from(INTERRUPTED_EXIT)
        }
        result => crate::cli::finish("mo-train", result),
    }
}

/// Set by Ctrl-C / SIGTERM; `SAVING` while a checkpoint is being written.
static STOP: AtomicBool = AtomicBool::new(false);
static SAVING: AtomicBool = AtomicBool::new(false);

/// Install the signal handler once per process: the first signal asks the loop to stop at
/// the next step boundary; a second one quits at once unless a checkpoint is being written
/// (then the save finishes and the loop stops).
fn catch_interrupts() -> anyhow::Result<()> {
    static INSTALLED: OnceLock<Result<(), String>> = OnceLock::new();
    let installed = INSTALLED.get_or_init(|| {
        ctrlc::set_handler(|| {
            if STOP.swap(true, Ordering::SeqCst) && !SAVING.load(Ordering::SeqCst) {
                eprintln!("\nmo-train: interrupted twice, quitting without saving (the last checkpoint is whole)");
                crate::io::output::remove_temps_and_exit(INTERRUPTED_EXIT as i32);
            }
        })
        .map_err(|e| e.to_string())
    });
    STOP.store(false, Ordering::SeqCst);
    installed.clone().map_err(|e| anyhow::anyhow!("cannot catch Ctrl-C: {e}"))
}

/// Run a checkpoint save with `SAVING` set, so a second Ctrl-C waits for it.
fn save_guarded(save: impl FnOnce() -> anyhow::Result<()>) -> anyhow::Result<()> {
    SAVING.store(true, Ordering::SeqCst);
    let result = save();
    SAVING.store(false, Ordering::SeqCst);
    result
}

/// Seconds as `1h02m`, `3m05s` or `42s`.
fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "?".into();
    }
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m{:02}s", s / 60, s % 60),
        _ => format!("{}h{:02}m", s / 3600, (s % 3600) / 60),
    }
}

/// `[######..............]` for `done` of `total`, `width` cells inside the brackets.
fn bar(done: u64, total: u64, width: usize) -> String {
    let filled = if total == 0 { width } else { ((done.min(total) as u128 * width as u128) / total as u128) as usize };
    format!("[{}{}]", "#".repeat(filled), ".".repeat(width - filled))
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    crate::nn::keep_freed_memory();
    if !(args.lr.is_finite() && args.lr > 0.0) {
        bail!("--lr must be a positive number, found {}", args.lr);
    }
    // Before any work or message: --out must be (or become) a directory.
    if args.out.exists() && !args.out.is_dir() {
        bail!("--out {}: not a directory (the model directory to write)", args.out.display());
    }
    let say = |msg: String| {
        if !args.common.quiet {
            eprintln!("mo-train: {msg}");
        }
    };
    if args.arch == Arch::Sata {
        return run_sata(args);
    }
    let crop = args.crop.unwrap_or(40);
    let device = Device::Cpu;
    let schedule = Schedule::cosine(100);
    let dmax = topology::DEFAULT_DMAX;
    // The checkpoint first: a resumed run must rebuild the data (augmented variants included)
    // from the seed the run started with.
    let (varmap, model, opt, mut info) = if args.resume {
        let loaded = checkpoint::load(&args.out, &device)?;
        let opt = checkpoint::load_optimizer(&args.out, loaded.info.step, &device, args.lr)?;
        let i = &loaded.info;
        if i.batch as u64 != args.batch || i.crop as u64 != crop || i.seed != args.common.seed || i.augment != args.augment || i.augment_variants as u64 != args.augment_variants {
            say("note: --batch, --crop, --seed or --augment* differ from the checkpoint's; the resumed run is not the one it would have been".into());
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
            crop: crop as usize,
            dmax,
            augment: 0.0,
            augment_variants: 0,
            skeletons: Vec::new(),
        };
        (varmap, model, AdamW::new(args.lr), info)
    };
    info.augment = args.augment;
    info.augment_variants = args.augment_variants as usize;

    let set = training_set(args, info.seed, info.dmax)?;
    info.skeletons = set
        .skeletons
        .iter()
        .map(|s| TrainedSkeleton {
            name: s.name.clone(),
            joints: s.skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            parents: s.skeleton.parents(),
            stats: s.stats.clone(),
            clips: s.clips.len(),
            offsets: s.skeleton.joints.iter().map(|j| j.offset.to_array()).collect(),
        })
        .collect();
    let first = info.step;
    let vars = named_vars(&varmap);
    let mut trainer = AnyTopTrainer { args, info, varmap, model, vars, opt, set, schedule, crop: crop as usize, device };
    train_loop(args, first, &mut trainer)
}

/// The data stream of step k depends only on the seed and k, so a resumed run draws what the
/// uninterrupted one would have.
fn step_rng(seed: u64, k: u64) -> SplitMix64 {
    SplitMix64::new(seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// What the training loop drives, for either architecture.
trait Trainer {
    /// Step `k` (0-based): the loss, and extra `"name":value` pairs for the JSON log.
    fn step(&mut self, k: u64) -> anyhow::Result<(f64, String)>;
    /// Save a checkpoint saying `steps` steps are done.
    fn save(&mut self, steps: u64) -> anyhow::Result<()>;
}

/// Steps from `first` to `--steps` with the log, progress, periodic checkpoints and Ctrl-C.
fn train_loop(args: &Args, first: u64, trainer: &mut impl Trainer) -> anyhow::Result<()> {
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut log = std::fs::OpenOptions::new().create(true).append(true).open(args.out.join("log.jsonl")).context("cannot open the training log")?;
    catch_interrupts()?;
    let started = Instant::now();
    let mut last_save = Instant::now();
    let mut last_draw: Option<Instant> = None;
    let every = Duration::from_secs_f64(args.checkpoint_minutes.max(0.0) * 60.0);
    let terminal = std::io::IsTerminal::is_terminal(&std::io::stderr()) && !args.common.quiet;
    let mut step = first;
    while step < args.steps {
        if STOP.load(Ordering::SeqCst) {
            if terminal {
                eprintln!();
            }
            save_guarded(|| trainer.save(step))?;
            return Err(Interrupted { step }.into());
        }
        let (loss, extra) = trainer.step(step)?;
        step += 1;
        let done = step - first;
        let rate = done as f64 / started.elapsed().as_secs_f64().max(1e-9);
        let eta = (args.steps - step) as f64 / rate.max(1e-9);
        writeln!(log, "{{\"step\":{step},\"loss\":{loss}{extra},\"steps_per_second\":{rate:.4},\"elapsed\":{:.2}}}", started.elapsed().as_secs_f64())
            .context("cannot write the training log")?;
        if terminal {
            // Redraw at most ten times a second: fast tiny models would flood the terminal.
            if last_draw.is_none_or(|t| t.elapsed() >= Duration::from_millis(100)) || step == args.steps {
                let width = args.steps.to_string().len();
                eprint!("\rmo-train: {} {step:>width$}/{}  loss {loss:.4}  {rate:.2} steps/s  ETA {}   ", bar(step, args.steps, 30), args.steps, duration(eta));
                last_draw = Some(Instant::now());
            }
        } else if !args.common.quiet && (step % 50 == 0 || step == args.steps) {
            eprintln!("mo-train: step {step}/{}  loss {loss:.4}  {rate:.2} steps/s  ETA {}", args.steps, duration(eta));
        }
        if last_save.elapsed() >= every {
            save_guarded(|| trainer.save(step))?;
            last_save = Instant::now();
        }
    }
    if terminal {
        eprintln!();
    }
    save_guarded(|| trainer.save(step))?;
    if !args.common.quiet {
        eprintln!("mo-train: saved step {step} to {}", args.out.display());
    }
    Ok(())
}

/// The denoiser's training state.
struct AnyTopTrainer<'a> {
    args: &'a Args,
    info: CheckpointInfo,
    varmap: VarMap,
    model: Denoiser,
    vars: std::collections::BTreeMap<String, candle_core::Var>,
    opt: AdamW,
    set: TrainSet,
    schedule: Schedule,
    crop: usize,
    device: Device,
}

impl Trainer for AnyTopTrainer<'_> {
    fn step(&mut self, k: u64) -> anyhow::Result<(f64, String)> {
        let mut rng = step_rng(self.info.seed, k);
        let stats = train_step(&self.model, &self.vars, &mut self.opt, &self.set, &self.schedule, &mut rng, self.args.batch as usize, self.crop, self.args.lambda_geo, &self.device)?;
        Ok((stats.loss, String::new()))
    }

    fn save(&mut self, steps: u64) -> anyhow::Result<()> {
        self.info.step = steps;
        checkpoint::save(&self.args.out, &self.info, &self.varmap, &self.opt)
    }
}

/// The clips of DATA grouped by skeleton, with augmented variants, as both architectures use.
fn training_set(args: &Args, seed: u64, dmax: usize) -> anyhow::Result<TrainSet> {
    let say = |msg: String| {
        if !args.common.quiet {
            eprintln!("mo-train: {msg}");
        }
    };
    let files = expand_inputs(&args.data)?;
    let loaded = load_motions(&files, &LoadOptions::default())?;
    let clips: Vec<RawClip> = loaded.into_iter().map(|l| RawClip { name: l.name, skeleton: l.skeleton, motion: l.motion }).collect();
    let names = NameTable::builtin().context("the built-in joint-name table")?;
    let augmentation = Augmentation { probability: args.augment, variants: args.augment_variants as usize, seed };
    let (set, dropped) = TrainSet::build(clips, names, dmax, &augmentation)?;
    for d in &dropped {
        say(format!("{d}: too short to crop, left out"));
    }
    say(format!(
        "{} skeletons ({}), {} clips, {} feature frames; {} augmented variants",
        set.skeletons.len(),
        set.skeletons.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", "),
        set.skeletons.iter().map(|s| s.clips.len()).sum::<usize>(),
        set.skeletons.iter().flat_map(|s| &s.clips).map(|c| c.frames).sum::<usize>(),
        set.variant_count()
    ));
    for v in &set.skipped_variants {
        say(format!("augmented variant left out: {v}"));
    }
    if args.common.verbose {
        for v in set.augmented.iter().flatten() {
            say(format!("variant {}: {} joints, {} clips", v.name, v.skeleton.len(), v.clips.len()));
        }
    }
    Ok(set)
}

/// `mo-train --arch sata`: the autoencoder on the same data, bucketed by skeleton.
fn run_sata(args: &Args) -> anyhow::Result<()> {
    let device = Device::Cpu;
    let (varmap, model, opt, mut info, set) = if args.resume {
        let loaded = sata::checkpoint::load(&args.out, &device)?;
        let opt = checkpoint::load_optimizer(&args.out, loaded.info.step, &device, args.lr)?;
        let i = &loaded.info;
        if i.batch as u64 != args.batch || i.seed != args.common.seed || i.augment != args.augment || i.augment_variants as u64 != args.augment_variants {
            eprintln!("mo-train: note: --batch, --seed or --augment* differ from the checkpoint's; the resumed run is not the one it would have been");
        }
        let set = training_set(args, loaded.info.seed, topology::DEFAULT_DMAX)?;
        // The checkpoint records the settings its latest steps ran with (a curriculum changes
        // --augment or --lr between resumes; log.jsonl keeps the step-by-step history).
        let info = SataInfo { lr: args.lr, batch: args.batch as usize, augment: args.augment, augment_variants: args.augment_variants as usize, ..loaded.info };
        (loaded.varmap, loaded.model, opt, info, set)
    } else {
        if args.out.join("checkpoint.json").exists() {
            bail!("{} already holds a checkpoint: --resume to continue it, or choose another --out", args.out.display());
        }
        let mut cfg = args.preset.sata();
        if let Some(crop) = args.crop {
            cfg.window = crop as usize;
            cfg.overlap = cfg.overlap.min(cfg.window.saturating_sub(1) / 2);
        }
        cfg.validate()?;
        let set = training_set(args, args.common.seed, topology::DEFAULT_DMAX)?;
        // Measured once on the original data; a resumed run keeps the checkpoint's.
        let raw = sata::train::raw_clips(&set);
        let scale = FeatureScale::measure(raw.iter().map(|(f, rest)| (f, rest.as_slice())));
        let varmap = VarMap::new();
        let model = SataModel::new(seeded_var_builder(&varmap, args.common.seed, &device), &cfg)?;
        let info = SataInfo {
            format: sata::checkpoint::FORMAT.into(),
            version: sata::checkpoint::VERSION,
            config: cfg,
            scale,
            weights: LossWeights { kl: args.lambda_kl, cycle: args.lambda_cycle.unwrap_or(0.0), ..LossWeights::default() },
            step: 0,
            seed: args.common.seed,
            lr: args.lr,
            batch: args.batch as usize,
            augment: args.augment,
            augment_variants: args.augment_variants as usize,
            skeletons: Vec::new(),
        };
        (varmap, model, AdamW::new(args.lr), info, set)
    };
    info.skeletons = set.skeletons.iter().map(|s| s.name.clone()).collect();
    if let Some(w) = args.lambda_cycle {
        info.weights.cycle = w;
    }
    // Inference reads a trained skeleton's motion with the rig it was trained with.
    sata::rigs::KnownRigs::of_set(&set).write(&args.out)?;
    let first = info.step;
    let vars = named_vars(&varmap);
    let mut trainer = SataTrainer { args, info, varmap, model, vars, opt, set, device };
    train_loop(args, first, &mut trainer)
}

struct SataTrainer<'a> {
    args: &'a Args,
    info: SataInfo,
    varmap: VarMap,
    model: SataModel,
    vars: std::collections::BTreeMap<String, candle_core::Var>,
    opt: AdamW,
    set: TrainSet,
    device: Device,
}

impl Trainer for SataTrainer<'_> {
    fn step(&mut self, k: u64) -> anyhow::Result<(f64, String)> {
        let mut rng = step_rng(self.info.seed, k);
        let l = sata::train::train_step(&self.model, &self.vars, &mut self.opt, &self.set, &self.info.scale, &self.info.weights, &mut rng, self.args.batch as usize, &self.device)?;
        let extra = format!(
            ",\"reconstruction\":{},\"root\":{},\"geodesic\":{},\"smooth\":{},\"contact\":{},\"penetration\":{},\"kl\":{},\"cycle\":{}",
            l.reconstruction, l.root, l.geodesic, l.smooth, l.contact, l.penetration, l.kl, l.cycle
        );
        Ok((l.total, extra))
    }

    fn save(&mut self, steps: u64) -> anyhow::Result<()> {
        self.info.step = steps;
        checkpoint::save(&self.args.out, &self.info, &self.varmap, &self.opt)
    }
}
