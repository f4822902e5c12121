//! `mo-train`: train AnyTop's denoiser on folders of BVH clips, with checkpoints that resume.

use crate::cli::bounds;
use crate::cli::load::{expand_inputs, load_motions, LoadOptions};
use crate::cli::{CommonOpts, Exit};
use crate::diffusion::data::{Augmentation, FallbackStats, LossUnits, TrainSet};
use crate::diffusion::rest_norm::{RestNorm, RestToken, RestTokens};
use crate::diffusion::start::init_dir;
use crate::diffusion::trainer::{refuse_existing, train_loop, AnyTopOptions, AnyTopStart, AnyTopTrainer, LoopOptions, StopFlag, TrainError, Trainer};
use crate::diffusion::unseen;
use crate::embed::NameTable;
use crate::nn::{DenoiserConfig, Preset};
use crate::sata::trainer::{SataOptions, SataResume, SataTrainer};
use crate::sata::SataConfig;
use crate::skeleton::topology;
use anyhow::{bail, Context};
use candle_core::Device;
use std::path::PathBuf;
use std::time::{Duration, Instant};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-train examples/data --out model --preset tiny --steps 3 --batch 2 --crop 16
    mo-train examples/data --out model --preset tiny --steps 5 --batch 2 --crop 16 --resume
    mo-train examples/data --out model2 --preset tiny --steps 3 --batch 2 --crop 16 --augment 0
    mo-train examples/data/dragon.bvh --init builtin --minutes 0.1 --out my_dragon";

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
/// --fallback-stats variants (or all) normalises the variants (or everything) as mo-sample
/// normalises a skeleton the model never saw, its rest pose as the mean: a model trained only on
/// its skeletons' own statistics leaves unseen skeletons standing
/// (models/zoo-compact/MODEL_CARD.md).
///
/// Checkpoints go to --out (model.safetensors, optimizer.safetensors, checkpoint.json) every
/// --checkpoint-minutes and at the end; --resume continues from the one there, exactly as the
/// run would have gone on. Ctrl-C (or SIGTERM) stops at the end of the current step, saves a
/// checkpoint and exits with code 130; a second Ctrl-C quits at once (the last checkpoint
/// stays whole). A JSON-lines log (step, loss, steps/s) is appended to OUT/log.jsonl. On a
/// terminal a progress bar shows loss, steps/s and ETA; otherwise a line every 50 steps.
/// The same data, flags and --seed give the same run.
///
/// Fine-tuning (--init builtin or --init DIR): the run starts from that model's weights,
/// size and noise schedule instead of random weights, with a fresh optimiser and the new
/// clips' own statistics; it defaults to --lr 1e-3, --batch 4, --crop 20 and --augment 0
/// (every draw is of your skeletons): many small steps (five minutes on one clip buy
/// 1,900-9,800 of the built-in model's on two quiet cores, fewer the more joints;
/// models/zoo-compact/MODEL_CARD.md, "Fine-tuning"). With --minutes it trains for a wall-time
/// budget rather than a step count. The result is an ordinary model directory for mo-sample,
/// mo-dift and mo-segment --model. It gets the starting model's unseen-skeleton denoiser
/// (OUT/unseen, the built-in's for --init builtin), so mo-sample --model OUT samples the
/// skeletons it was not tuned on as the starting model does.
///
/// --resume continues with the checkpoint's --lr, --batch, --crop and --augment unless they
/// are given, so a fine-tune resumes as a fine-tune; given ones are recorded in the
/// checkpoint, and the next --resume goes on with them.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-train", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH files or directories of them.
    #[arg(value_name = "DATA", required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// Model directory to write (and to resume from).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Model size: tiny (width 32, 2 layers), compact (width 64, 2 layers; for sata the same as
    /// small), small (width 64, 4 layers) or paper (width 128, 4 layers, 4 heads).
    #[arg(long, value_enum, default_value_t = Preset::Small)]
    pub preset: Preset,
    /// Training steps in total (a resumed run counts the steps already done) [default: 10000,
    /// or no limit with --minutes].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=bounds::MAX_TRAIN_STEPS))]
    pub steps: Option<u64>,
    /// Train for this much wall time (this invocation's), then save and stop; with --steps,
    /// whichever comes first. The progress bar then shows the time left.
    #[arg(long, value_name = "M", value_parser = bounds::positive(bounds::MAX_CHECKPOINT_MINUTES))]
    pub minutes: Option<f64>,
    /// anytop: start from a trained model instead of random weights: 'builtin' (the model
    /// inside the binaries) or a model directory written by mo-train (use ./builtin for a
    /// directory of that name). A new run only: with --resume the checkpoint in --out goes on.
    #[arg(long, value_name = "builtin|DIR")]
    pub init: Option<PathBuf>,
    /// Crops per step [default: 16; with --init 4].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub batch: Option<u64>,
    /// Crop length in frames (default 40 for anytop, with --init 20; for sata the preset's
    /// window, 32 for small, which then is also the model's inference window).
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
    /// Learning rate [default: 1e-4; with --init 1e-3].
    // Finite and positive, no upper bound: a rate that blows a model up is stopped by the
    // training loop's non-finite loss check (and tests use one for that).
    #[arg(long, value_name = "LR", value_parser = bounds::positive(f64::MAX))]
    pub lr: Option<f64>,
    /// Weight of the geodesic rotation loss (the angle, in radians, between predicted and true
    /// joint rotations) next to the MSE; the reference trains with 1.
    #[arg(long, value_name = "W", default_value_t = 1.0, value_parser = bounds::non_negative(bounds::MAX_WEIGHT))]
    pub lambda_geo: f64,
    /// Weight of a velocity loss next to the MSE: the squared error of the prediction's
    /// frame-to-frame changes against the motion's (normalised units; MDM's, not in AnyTop's
    /// reference). 0 = off. Not kept in the checkpoint: give it again with --resume.
    #[arg(long, value_name = "W", default_value_t = 0.0, value_parser = bounds::non_negative(bounds::MAX_WEIGHT))]
    pub lambda_vel: f64,
    /// Weight of a foot-slide loss next to the MSE: where a clip's foot is planted (its contact
    /// channel), how far the prediction's positions and root move that joint from frame to
    /// frame against how far the clip's joint moves, in the clip's velocity spreads, counted by
    /// the signal's share of the noised input. 0 = off. On a 1-creature proxy it did not pay:
    /// at 2 the feet slid 9-17% less and the creature moved 7-20% less, at 10 it stood
    /// (models/zoo-compact/MODEL_CARD.md). Not kept in the checkpoint: give it again with
    /// --resume.
    #[arg(long, value_name = "W", default_value_t = 0.0, value_parser = bounds::non_negative(bounds::MAX_WEIGHT))]
    pub lambda_foot: f64,
    /// Chance that a training draw uses an augmented skeleton (joints removed or added), as a
    /// number in [0, 1] or a fraction like 2/3 [default: 2/3; with --init 0].
    #[arg(long, value_name = "P", value_parser = parse_probability)]
    pub augment: Option<f64>,
    /// Augmented variants prepared per skeleton (alternately removing and adding joints).
    #[arg(long, value_name = "N", default_value_t = Augmentation::DEFAULT_VARIANTS as u64, value_parser = clap::value_parser!(u64).range(0..=64))]
    pub augment_variants: u64,
    /// anytop: what training normalises as sampling normalises a skeleton the model never saw
    /// (the rest pose as the mean, the skeletons' average spreads) instead of by its own clips'
    /// statistics, so that the model learns the condition it gets zero-shot. A model trained
    /// with `all` can go in another model's unseen/ folder, where mo-sample takes it for every
    /// skeleton that model was not trained on (the built-in model is such a pair) [default: none;
    /// with --resume the checkpoint's]
    #[arg(long, value_name = "WHAT", value_enum)]
    pub fallback_stats: Option<FallbackStats>,
    /// anytop: the units of the error of what --fallback-stats normalises: `own` measures it in
    /// the skeleton's own clips' spreads, so a creature that moves little next to the average
    /// spread weighs as much as one that moves a lot (measured on the zoo: no better than
    /// `normalised`) [default: normalised; with --resume the checkpoint's]
    #[arg(long, value_name = "UNITS", value_enum)]
    pub loss_units: Option<LossUnits>,
    /// anytop: what the rest-pose token is normalised by: `skeleton` (its skeleton's statistics,
    /// as the motion: all zeros under the fallback, so the model never learns where a creature's
    /// legs point) or `global` (statistics pooled over the training skeletons' rest poses, kept
    /// in the checkpoint, the same for every skeleton) [default: skeleton; with --resume the
    /// checkpoint's; with --init the model's]
    #[arg(long, value_name = "HOW", value_enum)]
    pub rest_token: Option<RestToken>,
    /// anytop: decay of the moving average of the weights that the saved model holds and
    /// mo-sample samples with (the raw weights are kept beside it for --resume). 0 = save the
    /// raw weights. An average over about 1/(1 - decay) steps.
    #[arg(long, value_name = "DECAY", default_value_t = 0.999, value_parser = parse_decay)]
    pub ema: f64,
    /// anytop: divide the cosine noise schedule's signal-to-noise ratio by S² at every step, so
    /// the slow, whole-crop directions of motion are drowned in noise early enough for sampling
    /// to choose a motion over many steps instead of settling on the mean pose in the first.
    /// 1 = AnyTop's schedule [default: 10 for a new run (3-skeleton proxy: samples' motion
    /// energy 0.2 of the clips' at 1, 0.4-0.6 at 10); a resumed run keeps its checkpoint's,
    /// unless this is given: then the model goes on learning under the new schedule].
    #[arg(long, value_name = "S", value_parser = bounds::positive(crate::diffusion::checkpoint::MAX_NOISE_SHIFT))]
    pub noise_shift: Option<f64>,
    /// anytop: how the loss weighs the diffusion steps: `x0` (every step's x0 error alike,
    /// AnyTop's), `v` (× 1 + SNR, the error of a v-prediction: the nearly clean steps count
    /// more) or `min-snr[:G]` (× min(SNR, G), G = 5 by default: the noisy steps count by the
    /// signal they carry) [default: v for a new run (3-skeleton proxy: samples' motion energy
    /// 0.47-0.74 of the clips' against 0.34-0.61 with x0); a resumed run or a fine-tune keeps
    /// its model's, unless this is given].
    #[arg(long, value_name = "W")]
    pub loss_weighting: Option<crate::diffusion::train::Weighting>,
    /// anytop: start each training crop's temporal positions at a random offset from 0 to N,
    /// so the model sees the positions of samples up to N + --crop frames long; without it
    /// (0) a longer sample's motion fades past the crop length [default: 1000 for a new run; a
    /// fine-tune or a resumed run keeps its model's, unless this is given].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(0..=1_000_000))]
    pub position_jitter: Option<u64>,
    /// anytop: taper the noise shift: the schedule's early (nearly clean) steps are shifted
    /// hardly at all and its last steps in full, so the model also learns to denoise finely;
    /// under the whole shift the cleanest step keeps noise of a quarter of the signal's scale.
    /// An experiment: on a 1-skeleton proxy its samples were worse [default: false for a new
    /// run; a fine-tune or a resumed run keeps its model's, unless this is given: then the
    /// model goes on learning under the new schedule].
    #[arg(long, value_name = "BOOL")]
    pub shift_taper: Option<bool>,
    /// anytop: draw a still clip (one whose mean frame-to-frame change is under 0.15 of its
    /// skeleton's most moving clip's, such as an idle) W times as often as a moving clip of the
    /// same skeleton; 0 leaves them out. On one zoo quadruped's five clips, the standing idle
    /// drawn as often as the others, or a quarter as often, left the samples' fore legs leading
    /// at random; left out, they led as the clips'. On three zoo skeletons trained together,
    /// leaving the idles out did not: the fore legs led at random as often, and the samples no
    /// longer covered the idles (models/zoo-small-next/MODEL_CARD.md, "Which fore leg leads" and
    /// "Which clips the samples cover") [default: 1 for a new run; a fine-tune or a resumed run
    /// keeps its model's, unless this is given].
    #[arg(long, value_name = "W", value_parser = bounds::non_negative(1.0))]
    pub still_weight: Option<f64>,
    /// Save a checkpoint at least this often.
    #[arg(long, value_name = "MIN", default_value_t = 5.0, value_parser = bounds::positive(bounds::MAX_CHECKPOINT_MINUTES))]
    pub checkpoint_minutes: f64,
    /// Continue from the checkpoint in --out.
    #[arg(long)]
    pub resume: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// A moving-average decay: a number in [0, 1) (1 would never move).
fn parse_decay(text: &str) -> Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number"))?;
    if (0.0..1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("expected a decay in [0, 1), found {text}"))
    }
}

/// A probability: a decimal in [0, 1] or a fraction `a/b`.
fn parse_probability(text: &str) -> Result<f64, String> {
    let value = match text.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) =
                (a.trim().parse().map_err(|_| format!("'{text}' is not a fraction"))?, b.trim().parse().map_err(|_| format!("'{text}' is not a fraction"))?);
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

/// Exit code after an interruption (128 + SIGINT, what shells report for Ctrl-C).
pub const INTERRUPTED_EXIT: u8 = 130;

/// Set by Ctrl-C / SIGTERM; the loop stops at the next step boundary.
static STOP: StopFlag = StopFlag::new();

/// The first signal asks the loop to stop at the next step boundary; a second one quits at
/// once unless a checkpoint is being written (`StopFlag::catch_interrupts`).
fn catch_interrupts() -> anyhow::Result<()> {
    let twice = || {
        eprintln!("\nmo-train: interrupted twice, quitting without saving (the last checkpoint is whole)");
        crate::io::output::remove_temps_and_exit(INTERRUPTED_EXIT as i32);
    };
    STOP.catch_interrupts(twice).map_err(|e| anyhow::anyhow!("cannot catch Ctrl-C: {e}"))
}

/// A fine-tune's (`--init`) settings when none are given: many small steps. On one real clip
/// of a skeleton the built-in model never saw, a thousand steps brought a chicken's poses to
/// within 0.012 of its clip's, where 268 steps of batch 16 left them at 0.015; crops of 20
/// frames cost half of 40's per step and did as well per step (models/zoo-small/MODEL_CARD.md).
/// From the compact built-in, lr 3e-4 left the monkey's poses farther off than 1e-3 in the same
/// steps (models/zoo-compact/MODEL_CARD.md).
pub const INIT_LR: f64 = 1e-3;
pub const INIT_BATCH: u64 = 4;
pub const INIT_CROP: u64 = 20;

/// What a checkpoint says of the run that wrote it: `--resume`'s defaults. Both checkpoint
/// formats (denoiser and SATA) hold these; a SATA one has no crop (its window is its config).
#[derive(serde::Deserialize)]
struct Previous {
    lr: f64,
    batch: u64,
    crop: Option<u64>,
    augment: f64,
    #[serde(default)]
    fallback_stats: FallbackStats,
    #[serde(default)]
    loss_units: LossUnits,
    #[serde(default)]
    rest_norm: Option<RestNorm>,
}

impl Previous {
    /// `None` when there is no readable description: the resume itself then fails with the
    /// checkpoint's own error.
    fn read(out: &std::path::Path) -> Option<Previous> {
        serde_json::from_slice(&std::fs::read(out.join("checkpoint.json")).ok()?).ok()
    }
}

/// The settings whose defaults depend on other flags: given, else the resumed checkpoint's,
/// else a fine-tune's, else a new run's.
struct Resolved {
    /// `--init` without `--resume`: a new run from a model's weights (a resumed fine-tune is
    /// an ordinary resume).
    fine_tune: bool,
    lr: f64,
    augment: f64,
    fallback_stats: FallbackStats,
    loss_units: LossUnits,
    /// A resumed run keeps its pooled rest statistics.
    rest: RestTokens,
    steps: u64,
    batch: u64,
    /// `None`: the architecture's own (sata: the preset's window).
    crop: Option<u64>,
}

impl Resolved {
    fn of(args: &Args) -> Resolved {
        let fine_tune = args.init.is_some() && !args.resume;
        let previous = if args.resume { Previous::read(&args.out) } else { None };
        let pick = |given: Option<f64>, from: Option<f64>, init: f64, new: f64| given.or(from).unwrap_or(if fine_tune { init } else { new });
        Resolved {
            fine_tune,
            lr: pick(args.lr, previous.as_ref().map(|p| p.lr), INIT_LR, 1e-4),
            augment: pick(args.augment, previous.as_ref().map(|p| p.augment), 0.0, 2.0 / 3.0),
            fallback_stats: args.fallback_stats.or(previous.as_ref().map(|p| p.fallback_stats)).unwrap_or_default(),
            loss_units: args.loss_units.or(previous.as_ref().map(|p| p.loss_units)).unwrap_or_default(),
            rest: {
                let known = previous.as_ref().and_then(|p| p.rest_norm);
                let kept = if known.is_some() { RestToken::Global } else { RestToken::Skeleton };
                RestTokens::of(args.rest_token.unwrap_or(kept), known)
            },
            steps: args.steps.unwrap_or(if args.minutes.is_some() { bounds::MAX_TRAIN_STEPS } else { 10_000 }),
            batch: args.batch.or(previous.as_ref().map(|p| p.batch)).unwrap_or(if fine_tune { INIT_BATCH } else { 16 }),
            crop: args.crop.or(previous.as_ref().and_then(|p| p.crop)).or(fine_tune.then_some(INIT_CROP)),
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    crate::nn::keep_freed_memory();
    // --lr, --lambda-geo and --lambda-vel are checked by clap (`bounds::positive`, `non_negative`).
    let resolved = Resolved::of(args);
    if args.init.is_some() && args.arch != Arch::Anytop {
        bail!("--init fine-tunes the diffusion model (--arch anytop), not --arch sata");
    }
    if args.fallback_stats.is_some() && args.arch != Arch::Anytop {
        bail!("--fallback-stats is the diffusion model's (--arch anytop); --arch sata normalises every skeleton by its clips");
    }
    if args.rest_token.is_some() && args.arch != Arch::Anytop {
        bail!("--rest-token is the diffusion model's (--arch anytop)");
    }
    if args.loss_units.is_some() && args.arch != Arch::Anytop {
        bail!("--loss-units is the diffusion model's (--arch anytop); --arch sata normalises every skeleton by its clips");
    }
    if resolved.loss_units == LossUnits::Own && resolved.fallback_stats == FallbackStats::None {
        bail!("--loss-units own measures the error of what --fallback-stats normalises; give --fallback-stats variants or all");
    }
    // Before any work or message: --out must be (or become) a directory.
    if args.out.exists() && !args.out.is_dir() {
        bail!("--out {}: not a directory (the model directory to write)", args.out.display());
    }
    if let Some(shift) = args.noise_shift.filter(|&s| s < 1.0) {
        bail!("--noise-shift must be at least 1 (1 = AnyTop's schedule), found {shift}");
    }
    let device = Device::Cpu;
    let done = match args.arch {
        Arch::Anytop => train_anytop(args, &resolved, &device),
        Arch::Sata => train_sata(args, &resolved, &device),
    }?;
    say(args, &format!("saved step {done} to {}", args.out.display()));
    Ok(())
}

/// `--arch anytop`: a new, resumed or fine-tuned diffusion model; returns the steps done.
fn train_anytop(args: &Args, resolved: &Resolved, device: &Device) -> anyhow::Result<u64> {
    let opts = AnyTopOptions {
        config: DenoiserConfig::preset(args.preset),
        seed: args.common.seed,
        lr: resolved.lr,
        batch: resolved.batch as usize,
        crop: resolved.crop.unwrap_or(40) as usize,
        lambda_geo: args.lambda_geo,
        lambda_vel: args.lambda_vel,
        lambda_foot: args.lambda_foot,
        augment: resolved.augment,
        augment_variants: args.augment_variants as usize,
        fallback_stats: resolved.fallback_stats,
        loss_units: resolved.loss_units,
        rest_token: resolved.rest.token(),
        ema: args.ema,
        noise_shift: args.noise_shift,
        position_jitter: args.position_jitter.map(|n| n as usize),
        shift_taper: args.shift_taper,
        still_weight: args.still_weight,
        weighting: args.loss_weighting,
    };
    // Before any loading: a new run (fresh or fine-tune) never overwrites a checkpoint.
    refuse_to_overwrite(args)?;
    // A fine-tune samples other skeletons as the model it starts from did (`unseen::Carried`);
    // one sampling would refuse stops the run here, before any message or output.
    let init = args.init.as_deref().and_then(init_dir);
    let carried = if resolved.fine_tune { unseen::Carried::from(init)? } else { None };
    // The checkpoint first: a resumed run must rebuild the data (augmented variants
    // included) from the seed the run started with.
    let (start, notes) = AnyTopStart::choose(&args.out, args.resume, args.init.as_deref(), resolved.lr, &opts, device)?;
    notes.iter().for_each(|note| say(args, note));
    let seed = start.seed(&opts);
    // A fine-tune reads rest tokens as its model learned to.
    let rest = match start.init_rest_norm() {
        Some(norm) => {
            let rest = norm.map_or(RestTokens::Skeleton, RestTokens::Given);
            if args.rest_token.is_some_and(|t| t != rest.token()) {
                bail!("--rest-token: the model given to --init normalises rest tokens the other way ({:?}); a fine-tune keeps its model's", rest.token());
            }
            rest
        }
        None => resolved.rest,
    };
    let set = training_set(args, resolved, seed, start.dmax(), rest)?;
    let mut trainer = AnyTopTrainer::new(&args.out, &opts, start, set, device).map_err(explain)?;
    if let Some(carried) = carried {
        if carried.write(&args.out)? {
            say(
                args,
                &format!(
                    "carried the unseen-skeleton denoiser of {} into {}",
                    init.map_or("the built-in model".to_string(), |d| d.display().to_string()),
                    args.out.join(unseen::UNSEEN_DIR).display()
                ),
            );
        }
    }
    train(args, resolved, trainer.first_step(), &mut trainer)
}

/// `--arch sata`: a new or resumed latent autoencoder; returns the steps done.
fn train_sata(args: &Args, resolved: &Resolved, device: &Device) -> anyhow::Result<u64> {
    let config = match resolved.crop {
        Some(crop) => SataConfig::preset(args.preset).with_window(crop as usize),
        None => SataConfig::preset(args.preset),
    };
    let opts = SataOptions {
        config,
        seed: args.common.seed,
        lr: resolved.lr,
        batch: resolved.batch as usize,
        augment: resolved.augment,
        augment_variants: args.augment_variants as usize,
        lambda_kl: args.lambda_kl,
        lambda_cycle: args.lambda_cycle,
    };
    let resume = if args.resume { Some(SataResume::load(&args.out, resolved.lr, device)?) } else { None };
    if resume.as_ref().is_some_and(|r| r.differs(&opts)) {
        say(args, "note: --batch, --seed or --augment* differ from the checkpoint's; the resumed run is not the one it would have been");
    }
    refuse_to_overwrite(args)?;
    if resume.is_none() {
        opts.config.validate()?;
    }
    let seed = resume.as_ref().map_or(opts.seed, |r| r.info().seed);
    let set = training_set(args, resolved, seed, topology::DEFAULT_DMAX, RestTokens::Skeleton)?;
    let mut trainer = SataTrainer::new(&args.out, &opts, resume, set, device).map_err(explain)?;
    train(args, resolved, trainer.first_step(), &mut trainer)
}

fn say(args: &Args, msg: &str) {
    if !args.common.quiet {
        eprintln!("mo-train: {msg}");
    }
}

/// A new run never overwrites another's checkpoint (checked before the data is read).
fn refuse_to_overwrite(args: &Args) -> anyhow::Result<()> {
    if args.resume {
        return Ok(());
    }
    refuse_existing(&args.out).map_err(explain)
}

/// The library's error, with the flag that helps where there is one, and exit code 130 after
/// an interruption.
fn explain(e: TrainError) -> anyhow::Error {
    match e {
        TrainError::CheckpointExists(dir) => anyhow::anyhow!("{} already holds a checkpoint: --resume to continue it, or choose another --out", dir.display()),
        TrainError::Interrupted { .. } => Exit { code: INTERRUPTED_EXIT, message: format!("{e}; --resume to continue") }.into(),
        e => e.into(),
    }
}

/// The loop with a progress bar on a terminal (a line every 50 steps otherwise) and Ctrl-C;
/// returns the steps done.
fn train(args: &Args, resolved: &Resolved, first: u64, trainer: &mut impl Trainer) -> anyhow::Result<u64> {
    catch_interrupts()?;
    let opts = LoopOptions {
        out: args.out.clone(),
        steps: resolved.steps,
        checkpoint_every: Duration::from_secs_f64(args.checkpoint_minutes.max(0.0) * 60.0),
        budget: args.minutes.map(|m| Duration::from_secs_f64(m * 60.0)),
    };
    let terminal = std::io::IsTerminal::is_terminal(&std::io::stderr()) && !args.common.quiet;
    let mut last_draw: Option<Instant> = None;
    let result = train_loop(&opts, first, trainer, &STOP, |p| {
        if terminal {
            // Redraw at most ten times a second: fast tiny models would flood the terminal.
            if last_draw.is_none_or(|t| t.elapsed() >= Duration::from_millis(100)) || p.is_last() {
                eprint!("\rmo-train: {} {}   ", p.bar(30), p.status(args.steps.is_some()));
                last_draw = Some(Instant::now());
            }
        } else if !args.common.quiet && (p.step % 50 == 0 || p.is_last()) {
            eprintln!("mo-train: {}", p.status(args.steps.is_some()));
        }
    });
    if terminal {
        eprintln!();
    }
    result.map_err(explain)
}

/// The clips of DATA grouped by skeleton, with augmented variants, as both architectures use.
fn training_set(args: &Args, resolved: &Resolved, seed: u64, dmax: usize, rest: RestTokens) -> anyhow::Result<TrainSet> {
    let clips = load_motions(&expand_inputs(&args.data)?, &LoadOptions::default())?;
    let names = NameTable::builtin().context("the built-in joint-name table")?;
    let augmentation = Augmentation {
        probability: resolved.augment,
        variants: args.augment_variants as usize,
        seed,
        stats: resolved.fallback_stats,
        units: resolved.loss_units,
        rest,
    };
    let (set, dropped) = TrainSet::build(clips, names, dmax, &augmentation)?;
    set.report(&dropped, args.common.verbose).iter().for_each(|line| say(args, line));
    Ok(set)
}
