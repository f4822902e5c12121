//! The training loop both models share (`mo-train`): one seeded data stream per step, a
//! JSON-lines log, checkpoints at an interval and at the end, and a stop flag that a signal
//! handler sets. It prints nothing: the caller sees each step through a callback. The
//! denoiser's trainer is here too; the SATA autoencoder's is `sata::trainer`.
//!
//! A run that is stopped and resumed is bit-identical to one that was not: the data stream of
//! step k depends only on the seed and k (`step_rng`), and a checkpoint carries the optimiser.

use super::checkpoint::{self, CheckpointInfo, TrainedRest, TrainedSkeleton};
use super::data::{FallbackStats, LossUnits, TrainSet};
use super::ema::Ema;
use super::rest_norm::RestToken;
use super::train::{named_vars, train_step, AdamW, LossTerms, Weighting};
use super::Schedule;
use crate::nn::{seeded_var_builder, Denoiser, DenoiserConfig, NnError};
use crate::rng::SplitMix64;
use candle_core::{Device, Var};
use candle_nn::VarMap;
use serde::ser::{Serialize, SerializeMap, Serializer};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Why training stopped before its last step.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    #[error("cannot create {}", .0.display())]
    CreateDir(PathBuf, #[source] std::io::Error),
    #[error("cannot open the training log")]
    OpenLog(#[source] std::io::Error),
    #[error("cannot write the training log")]
    WriteLog(#[source] std::io::Error),
    /// A new run would overwrite the checkpoint of another.
    #[error("{} already holds a checkpoint", .0.display())]
    CheckpointExists(PathBuf),
    /// The stop flag was set; the checkpoint of `step` was saved first.
    #[error("interrupted at step {step}, checkpoint saved")]
    Interrupted { step: u64 },
    /// The loss of `step` was NaN or infinite. Nothing of that step was saved or logged:
    /// the last checkpoint (`kept`, none when the run saved none yet) is the last good model.
    #[error("the loss of step {step} is not finite ({losses}): training stopped, {}", match kept { Some(s) => format!("the checkpoint of step {s} is kept"), None => "no checkpoint was saved".to_string() })]
    NonFinite { step: u64, losses: String, kept: Option<u64> },
    #[error(transparent)]
    Checkpoint(#[from] checkpoint::CheckpointError),
    #[error(transparent)]
    Nn(#[from] NnError),
    /// From another model's training step (`sata::SataError`).
    #[error(transparent)]
    Model(Box<dyn std::error::Error + Send + Sync>),
}

/// The data stream of step k depends only on the seed and k, so a resumed run draws what the
/// uninterrupted one would have.
pub fn step_rng(seed: u64, k: u64) -> SplitMix64 {
    SplitMix64::new(seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// What one step measured: the loss trained on, and its named parts for the log.
#[derive(Clone, Debug, Default)]
pub struct StepLosses {
    pub total: f64,
    pub parts: Vec<(&'static str, f64)>,
}

impl StepLosses {
    fn describe(&self) -> String {
        std::iter::once(("loss", self.total)).chain(self.parts.iter().copied()).map(|(n, v)| format!("{n} {v}")).collect::<Vec<_>>().join(", ")
    }
}

/// What the training loop drives, for either architecture.
pub trait Trainer {
    /// Step `k` (0-based). A non-finite loss must leave the model as it was (no update), so
    /// the loop can stop with the last good model.
    fn step(&mut self, k: u64) -> Result<StepLosses, TrainError>;
    /// Save a checkpoint saying `steps` steps are done.
    fn save(&mut self, steps: u64) -> Result<(), TrainError>;
}

/// A stop request a signal handler can make, and whether a checkpoint is being written (so a
/// second signal can wait for it rather than leave a save half done).
#[derive(Debug, Default)]
pub struct StopFlag {
    stop: AtomicBool,
    saving: AtomicBool,
}

impl StopFlag {
    pub const fn new() -> StopFlag {
        StopFlag { stop: AtomicBool::new(false), saving: AtomicBool::new(false) }
    }

    /// Ask the loop to stop at the next step boundary; true if that was already asked.
    pub fn request(&self) -> bool {
        self.stop.swap(true, Ordering::SeqCst)
    }

    pub fn requested(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    pub fn reset(&self) {
        self.stop.store(false, Ordering::SeqCst);
    }

    /// True while the loop writes a checkpoint.
    pub fn saving(&self) -> bool {
        self.saving.load(Ordering::SeqCst)
    }

    /// Make Ctrl-C and SIGTERM ask this flag to stop the loop at the next step boundary, and
    /// reset it. The handler is installed once per process (for the first flag; later calls
    /// only reset theirs and return the first installation's result); a second signal calls
    /// `twice` unless a checkpoint is being written (then the save finishes and the loop stops).
    pub fn catch_interrupts(&'static self, twice: fn()) -> Result<(), String> {
        static INSTALLED: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
        let installed = INSTALLED.get_or_init(|| {
            let handler = move || {
                if self.request() && !self.saving() {
                    twice();
                }
            };
            ctrlc::set_handler(handler).map_err(|e| e.to_string())
        });
        self.reset();
        installed.clone()
    }

    fn guard<T>(&self, save: impl FnOnce() -> T) -> T {
        self.saving.store(true, Ordering::SeqCst);
        let result = save();
        self.saving.store(false, Ordering::SeqCst);
        result
    }
}

/// How long to train and where the log and checkpoints go.
#[derive(Clone, Debug)]
pub struct LoopOptions {
    /// The model directory: `log.jsonl` is appended to there.
    pub out: PathBuf,
    /// Steps in total, counting those a resumed run has done.
    pub steps: u64,
    /// Save a checkpoint at least this often.
    pub checkpoint_every: Duration,
    /// Wall time this run may take (`mo-train --minutes`): the loop stops after the step that
    /// reaches it, and saves. None = until `steps`.
    pub budget: Option<Duration>,
}

/// One finished step, for a progress display.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Steps done (1-based: the step just finished).
    pub step: u64,
    pub steps: u64,
    pub loss: f64,
    /// Steps per second since this run started.
    pub rate: f64,
    /// Seconds until the run ends: by `steps` at the current rate, or by the time budget.
    pub eta_seconds: f64,
    /// The time budget's share used, in [0, 1] (None without a budget).
    pub budget_used: Option<f64>,
}

/// One line of `log.jsonl`: step, loss, its parts, speed, elapsed seconds. Written by
/// serde_json so the file stays JSON whatever the numbers are.
struct LogLine<'a> {
    step: u64,
    losses: &'a StepLosses,
    rate: f64,
    elapsed: f64,
}

impl Serialize for LogLine<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(4 + self.losses.parts.len()))?;
        map.serialize_entry("step", &self.step)?;
        map.serialize_entry("loss", &self.losses.total)?;
        for (name, value) in &self.losses.parts {
            map.serialize_entry(name, value)?;
        }
        // The precision the log always had: speed and time are not worth 17 digits.
        map.serialize_entry("steps_per_second", &((self.rate * 1e4).round() / 1e4))?;
        map.serialize_entry("elapsed", &((self.elapsed * 1e2).round() / 1e2))?;
        map.end()
    }
}

/// Steps from `first` to `opts.steps` (or until the time budget is spent) with the log,
/// periodic checkpoints and the stop flag; `progress` is called after every step. Returns the
/// steps done, all saved.
pub fn train_loop(opts: &LoopOptions, first: u64, trainer: &mut impl Trainer, stop: &StopFlag, mut progress: impl FnMut(&Progress)) -> Result<u64, TrainError> {
    std::fs::create_dir_all(&opts.out).map_err(|e| TrainError::CreateDir(opts.out.clone(), e))?;
    let mut log = std::fs::OpenOptions::new().create(true).append(true).open(opts.out.join("log.jsonl")).map_err(TrainError::OpenLog)?;
    let started = Instant::now();
    let mut last_save = Instant::now();
    let mut saved = (first > 0).then_some(first);
    let mut step = first;
    while step < opts.steps {
        if stop.requested() {
            stop.guard(|| trainer.save(step))?;
            return Err(TrainError::Interrupted { step });
        }
        let losses = trainer.step(step)?;
        step += 1;
        if !losses.total.is_finite() {
            return Err(TrainError::NonFinite { step, losses: losses.describe(), kept: saved });
        }
        let done = step - first;
        let elapsed = started.elapsed().as_secs_f64();
        let rate = done as f64 / elapsed.max(1e-9);
        let mut eta_seconds = (opts.steps - step) as f64 / rate.max(1e-9);
        let budget_used = opts.budget.map(|b| (elapsed / b.as_secs_f64().max(1e-9)).min(1.0));
        if let Some(b) = opts.budget {
            eta_seconds = eta_seconds.min((b.as_secs_f64() - elapsed).max(0.0));
        }
        let line = LogLine { step, losses: &losses, rate, elapsed };
        let mut text = serde_json::to_vec(&line).map_err(|e| TrainError::WriteLog(e.into()))?;
        text.push(b'\n');
        log.write_all(&text).map_err(TrainError::WriteLog)?;
        progress(&Progress { step, steps: opts.steps, loss: losses.total, rate, eta_seconds, budget_used });
        if budget_used.is_some_and(|u| u >= 1.0) {
            break;
        }
        if last_save.elapsed() >= opts.checkpoint_every {
            stop.guard(|| trainer.save(step))?;
            saved = Some(step);
            last_save = Instant::now();
        }
    }
    stop.guard(|| trainer.save(step))?;
    Ok(step)
}

/// Refuse to start a new run in a directory that holds another run's checkpoint.
pub fn refuse_existing(dir: &Path) -> Result<(), TrainError> {
    if dir.join("checkpoint.json").exists() {
        return Err(TrainError::CheckpointExists(dir.to_path_buf()));
    }
    Ok(())
}

/// How to train the denoiser.
#[derive(Clone, Debug)]
pub struct AnyTopOptions {
    /// The model for a new run (a resumed one keeps its checkpoint's).
    pub config: DenoiserConfig,
    pub seed: u64,
    pub lr: f64,
    pub batch: usize,
    pub crop: usize,
    /// Weight of the geodesic rotation loss next to the MSE.
    pub lambda_geo: f64,
    /// Weight of the velocity loss (frame-to-frame changes) next to the MSE.
    pub lambda_vel: f64,
    /// Weight of the foot-slide loss (`train::foot_slide_error`) next to the MSE.
    pub lambda_foot: f64,
    /// How diffusion steps weigh in the loss: none = `DEFAULT_WEIGHTING` for a new run, the
    /// checkpoint's for a resumed one or a fine-tune.
    pub weighting: Option<Weighting>,
    pub augment: f64,
    pub augment_variants: usize,
    /// What is normalised by the fallback statistics (`data::FallbackStats`).
    pub fallback_stats: FallbackStats,
    /// The units of a fallback-normalised draw's error (`data::LossUnits`).
    pub loss_units: LossUnits,
    /// What the rest tokens are normalised by (`rest_norm::RestToken`).
    pub rest_token: RestToken,
    /// Decay of the weights' moving average that checkpoints hold for sampling (`ema.rs`);
    /// 0 = none.
    pub ema: f64,
    /// The noise schedule's shift (`Schedule::cosine_shifted`): none = `DEFAULT_NOISE_SHIFT` for
    /// a new run, the checkpoint's for a resumed one; given, a resumed run continues under the
    /// new schedule.
    pub noise_shift: Option<f64>,
    /// The largest random offset of a training crop's temporal positions
    /// (`data::Crop::position`): none = `DEFAULT_POSITION_JITTER` for a new run, the model's
    /// for a fine-tune or a resumed run.
    pub position_jitter: Option<usize>,
    /// Whether the noise shift is tapered (`Schedule::cosine_tapered`): none =
    /// `DEFAULT_SHIFT_TAPER` for a new run, the model's for a fine-tune or a resumed run; given,
    /// a resumed run continues under the new schedule.
    pub shift_taper: Option<bool>,
    /// How often a still clip is drawn against a moving one of its skeleton
    /// (`data::still_clips`): none = 1 (alike) for a new run, the model's for a fine-tune or a
    /// resumed run.
    pub still_weight: Option<f64>,
}

/// Whether a new run tapers its noise shift: no, the taper made a 1-skeleton proxy's samples
/// worse (`Schedule::cosine_tapered`).
pub const DEFAULT_SHIFT_TAPER: bool = false;

/// The position jitter of a new run or fine-tune. Without one (0) the model sees positions
/// 1..=crop only, and a sample longer than the crops loses its motion past them: a 1-skeleton
/// proxy (quadruped_v0, tiny, 8,000 steps, crop 40) gave 160-frame samples whose joint speed fell
/// from 0.25 over frames 0-40 (the walk clip's 0.29) to 0.13 and 0.11 over the next 40s.
/// 1,000 covers a 30 fps half minute with the crop. `models/zoo-tiny`, resumed with it at step
/// 78,121, had its feet alternate more on every zoo skeleton 20,000 steps later (0.53-0.63
/// against 0.37-0.51) and its quadruped's calibrated coverage rose from 3% to 27%, while its
/// energy fell (its card, "Positions past the crop").
pub const DEFAULT_POSITION_JITTER: usize = 1000;

/// The noise shift of a new run. Measured on a 3-skeleton proxy (quadruped, biped, spider of
/// the zoo, tiny preset, 4,000 steps; models/zoo-small/MODEL_CARD.md): samples' motion energy
/// 0.21-0.24 of the clips' with AnyTop's schedule (1), 0.38-0.61 at 10 with crop-relative
/// positions. 20 and 40 were not better on a 1-skeleton proxy.
pub const DEFAULT_NOISE_SHIFT: f64 = 10.0;

/// The loss weighting of a new run. Measured on the 3-skeleton proxy (quadruped, biped, spider
/// of the zoo, tiny preset, 4,000 steps, two training seeds; models/zoo-small/MODEL_CARD.md):
/// `v` gave samples 0.47-0.74 of the clips' motion energy against 0.34-0.61 with `x0` (higher
/// on all six pairs, poses as near the clips', jerk still inside the clips' range);
/// `min-snr` starved the noisy steps and gave jitter (jerk 4-6x the clips').
pub const DEFAULT_WEIGHTING: Weighting = Weighting::V;

/// Where a denoiser run starts.
pub enum AnyTopStart {
    /// New weights from the seed, with `AnyTopOptions::config`.
    New,
    /// A fine-tune (`mo-train --init`): another model's weights, config and noise schedule,
    /// with a fresh optimiser, step 0, and the run's own skeletons and statistics.
    Init(AnyTopInit),
    /// The checkpoint in the output directory, continued exactly.
    Resume(AnyTopResume),
}

impl AnyTopStart {
    /// The topology distance limit the training set must be built with: the starting
    /// model's, or the default for new weights.
    /// A fine-tune's model's pooled rest statistics (`Some(None)`: it normalises rest tokens by
    /// each skeleton's); `None` for other starts.
    pub fn init_rest_norm(&self) -> Option<Option<crate::diffusion::rest_norm::RestNorm>> {
        match self {
            AnyTopStart::Init(i) => Some(i.loaded.info.rest_norm),
            _ => None,
        }
    }

    pub fn dmax(&self) -> usize {
        match self {
            AnyTopStart::New => crate::skeleton::topology::DEFAULT_DMAX,
            AnyTopStart::Init(i) => i.loaded.info.dmax,
            AnyTopStart::Resume(r) => r.loaded.info.dmax,
        }
    }
}

/// A model whose weights start a new run.
pub struct AnyTopInit {
    loaded: checkpoint::LoadedDenoiser,
    /// How the checkpoint names it: "the built-in default model (step N)", "model DIR (step N)".
    source: String,
}

impl AnyTopInit {
    /// The model embedded in the binaries.
    pub fn builtin(device: &Device) -> Result<AnyTopInit, TrainError> {
        let loaded = checkpoint::load_default(device)?;
        let source = format!("{} (step {})", checkpoint::BUILTIN_NAME, loaded.info.step);
        Ok(AnyTopInit { loaded, source })
    }

    /// The model in `dir` (its averaged weights, the ones samplers use).
    pub fn load(dir: &Path, device: &Device) -> Result<AnyTopInit, TrainError> {
        let loaded = checkpoint::load(dir, device)?;
        let source = format!("model {} (step {})", dir.display(), loaded.info.step);
        Ok(AnyTopInit { loaded, source })
    }

    pub fn info(&self) -> &CheckpointInfo {
        &self.loaded.info
    }

    pub fn source(&self) -> &str {
        &self.source
    }
}

/// A denoiser checkpoint to continue, with its optimiser state.
pub struct AnyTopResume {
    loaded: checkpoint::LoadedDenoiser,
    opt: AdamW,
    /// The raw weights of an averaged checkpoint (its `model.safetensors` holds the average).
    raw: std::collections::HashMap<String, candle_core::Tensor>,
}

impl AnyTopResume {
    /// The checkpoint in `dir`; the optimiser continues with learning rate `lr`.
    pub fn load(dir: &Path, lr: f64, device: &Device) -> Result<AnyTopResume, TrainError> {
        let loaded = checkpoint::load(dir, device)?;
        let opt = checkpoint::load_optimizer(dir, loaded.info.step, device, lr)?;
        let raw = checkpoint::load_raw_weights(dir, device)?;
        Ok(AnyTopResume { loaded, opt, raw })
    }

    /// The training data must be rebuilt (augmented variants included) from the seed and
    /// distance limit the run started with.
    pub fn info(&self) -> &CheckpointInfo {
        &self.loaded.info
    }

    /// Whether `opts` draw other data than the checkpoint's run did (then the resumed run is
    /// not the one it would have been).
    pub fn differs(&self, opts: &AnyTopOptions) -> bool {
        let i = &self.loaded.info;
        i.batch != opts.batch
            || i.crop != opts.crop
            || i.seed != opts.seed
            || i.augment != opts.augment
            || i.augment_variants != opts.augment_variants
            || i.fallback_stats != opts.fallback_stats
            || i.loss_units != opts.loss_units
            || i.rest_norm.is_some() != (opts.rest_token == RestToken::Global)
            || opts.position_jitter.is_some_and(|j| j != i.position_jitter)
            || opts.still_weight.is_some_and(|w| w != i.still_weight)
    }

    /// The loss weighting the checkpoint was trained with, when `opts` asks for another.
    pub fn weighting_changes(&self, opts: &AnyTopOptions) -> Option<(Weighting, Weighting)> {
        opts.weighting.filter(|&w| w != self.loaded.info.weighting).map(|w| (self.loaded.info.weighting, w))
    }

    /// The checkpoint's shift taper and the one `opts` asks for, when they differ.
    pub fn taper_changes(&self, opts: &AnyTopOptions) -> Option<(bool, bool)> {
        opts.shift_taper.filter(|&t| t != self.loaded.info.shift_taper).map(|t| (self.loaded.info.shift_taper, t))
    }

    /// The noise shift the checkpoint was trained with, when `opts` asks for another.
    pub fn shift_changes(&self, opts: &AnyTopOptions) -> Option<(f64, f64)> {
        opts.noise_shift.filter(|&s| s != self.loaded.info.noise_shift).map(|s| (self.loaded.info.noise_shift, s))
    }
}

/// The denoiser's training state.
pub struct AnyTopTrainer {
    out: PathBuf,
    info: CheckpointInfo,
    varmap: VarMap,
    model: Denoiser,
    vars: BTreeMap<String, Var>,
    opt: AdamW,
    set: TrainSet,
    schedule: Schedule,
    batch: usize,
    crop: usize,
    lambda_geo: f64,
    lambda_vel: f64,
    lambda_foot: f64,
    ema: Option<Ema>,
    device: Device,
}

impl AnyTopTrainer {
    /// A run from `start` on `set`, saving to `out` (which must not hold a checkpoint unless
    /// the run resumes it). The set must be built with the dmax of `AnyTopStart::dmax`, and a
    /// resumed run's with its checkpoint's seed.
    pub fn new(out: &Path, opts: &AnyTopOptions, start: AnyTopStart, mut set: TrainSet, device: &Device) -> Result<AnyTopTrainer, TrainError> {
        let fresh = |config: &DenoiserConfig, base: Option<&CheckpointInfo>| CheckpointInfo {
            format: checkpoint::FORMAT.into(),
            version: checkpoint::VERSION,
            config: config.clone(),
            step: 0,
            seed: opts.seed,
            schedule_steps: base.map_or(100, |b| b.schedule_steps),
            lr: opts.lr,
            batch: opts.batch,
            crop: opts.crop,
            dmax: base.map_or(crate::skeleton::topology::DEFAULT_DMAX, |b| b.dmax),
            augment: 0.0,
            augment_variants: 0,
            fallback_stats: FallbackStats::None,
            loss_units: LossUnits::Normalised,
            rest_norm: None,
            ema: 0.0,
            noise_shift: base.map_or(DEFAULT_NOISE_SHIFT, |b| b.noise_shift),
            position_jitter: base.map_or(DEFAULT_POSITION_JITTER, |b| b.position_jitter),
            still_weight: base.map_or(1.0, |b| b.still_weight),
            shift_taper: base.map_or(DEFAULT_SHIFT_TAPER, |b| b.shift_taper),
            weighting: base.map_or(DEFAULT_WEIGHTING, |b| b.weighting),
            init: None,
            skeletons: Vec::new(),
        };
        let (varmap, model, opt, mut info, raw) = match start {
            AnyTopStart::Resume(r) => (r.loaded.varmap, r.loaded.model, r.opt, r.loaded.info, r.raw),
            AnyTopStart::New => {
                refuse_existing(out)?;
                let varmap = VarMap::new();
                let model = Denoiser::new(seeded_var_builder(&varmap, opts.seed, device), &opts.config)?;
                (varmap, model, AdamW::new(opts.lr), fresh(&opts.config, None), Default::default())
            }
            AnyTopStart::Init(i) => {
                refuse_existing(out)?;
                let mut info = fresh(&i.loaded.info.config, Some(&i.loaded.info));
                info.init = Some(i.source);
                (i.loaded.varmap, i.loaded.model, AdamW::new(opts.lr), info, Default::default())
            }
        };
        if let Some(shift) = opts.noise_shift {
            info.noise_shift = shift;
        }
        if let Some(taper) = opts.shift_taper {
            info.shift_taper = taper;
        }
        if let Some(jitter) = opts.position_jitter {
            info.position_jitter = jitter;
        }
        if let Some(weight) = opts.still_weight {
            info.still_weight = weight;
        }
        if let Some(weighting) = opts.weighting {
            info.weighting = weighting;
        }
        let schedule = info.schedule();
        // The checkpoint describes the run that wrote it last (as SATA's does): a resumed run
        // with another --lr, --batch or --crop records them, so the next --resume goes on
        // with them.
        info.lr = opts.lr;
        info.batch = opts.batch;
        info.crop = opts.crop;
        info.augment = opts.augment;
        info.augment_variants = opts.augment_variants;
        info.fallback_stats = opts.fallback_stats;
        info.loss_units = opts.loss_units;
        info.rest_norm = set.rest_norm;
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
                rest: Some(TrainedRest::new(&s.rest.0, &s.rest.1)),
            })
            .collect();
        let vars = named_vars(&varmap);
        // The loaded weights are the average (or the raw weights of a checkpoint without one):
        // the average continues from them, training from the raw weights kept beside them.
        let ema = if opts.ema > 0.0 { Some(Ema::new(opts.ema, &vars).map_err(NnError::from)?) } else { None };
        for (name, var) in &vars {
            if let Some(w) = raw.get(name) {
                if w.dims() != var.dims() {
                    return Err(checkpoint::CheckpointError::Invalid(format!(
                        "optimizer.safetensors: raw weight {name} is {:?}, the model's is {:?}",
                        w.dims(),
                        var.dims()
                    ))
                    .into());
                }
                var.set(w).map_err(NnError::from)?;
            }
        }
        info.ema = opts.ema;
        set.position_jitter = info.position_jitter;
        set.still_weight = info.still_weight;
        Ok(AnyTopTrainer {
            out: out.to_path_buf(),
            info,
            varmap,
            model,
            vars,
            opt,
            set,
            schedule,
            batch: opts.batch,
            crop: opts.crop,
            lambda_geo: opts.lambda_geo,
            lambda_vel: opts.lambda_vel,
            lambda_foot: opts.lambda_foot,
            ema,
            device: device.clone(),
        })
    }

    /// Steps done before this run (0 for a new one).
    pub fn first_step(&self) -> u64 {
        self.info.step
    }
}

impl Trainer for AnyTopTrainer {
    fn step(&mut self, k: u64) -> Result<StepLosses, TrainError> {
        let mut rng = step_rng(self.info.seed, k);
        let stats = train_step(
            &self.model,
            &self.vars,
            &mut self.opt,
            &self.set,
            &self.schedule,
            &mut rng,
            self.batch,
            self.crop,
            LossTerms { geo: self.lambda_geo, vel: self.lambda_vel, foot: self.lambda_foot, weighting: self.info.weighting },
            &self.device,
        )?;
        if stats.loss.is_finite() {
            if let Some(ema) = self.ema.as_mut() {
                ema.update(&self.vars, k).map_err(NnError::from)?;
            }
        }
        Ok(StepLosses { total: stats.loss, parts: Vec::new() })
    }

    fn save(&mut self, steps: u64) -> Result<(), TrainError> {
        self.info.step = steps;
        Ok(checkpoint::save_averaged(&self.out, &self.info, &self.varmap, &self.opt, self.ema.as_ref())?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Losses from a list; counts saves.
    struct Scripted {
        losses: Vec<f64>,
        saves: Vec<u64>,
    }

    impl Trainer for Scripted {
        fn step(&mut self, k: u64) -> Result<StepLosses, TrainError> {
            Ok(StepLosses { total: self.losses[k as usize], parts: vec![("part", self.losses[k as usize] / 2.0)] })
        }

        fn save(&mut self, steps: u64) -> Result<(), TrainError> {
            self.saves.push(steps);
            Ok(())
        }
    }

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("menagerie-trainer-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_non_finite_loss_stops_without_saving_or_logging_it() {
        for bad in [f64::NAN, f64::INFINITY] {
            let out = dir("nan");
            let opts = LoopOptions { out: out.clone(), steps: 5, checkpoint_every: Duration::ZERO, budget: None };
            let mut t = Scripted { losses: vec![1.0, 0.5, bad, 0.25, 0.1], saves: Vec::new() };
            let mut seen = Vec::new();
            let err = train_loop(&opts, 0, &mut t, &StopFlag::new(), |p| seen.push(p.step)).unwrap_err();
            assert!(matches!(err, TrainError::NonFinite { step: 3, kept: Some(2), .. }), "{err}");
            assert_eq!((t.saves.as_slice(), seen.as_slice()), (&[1, 2][..], &[1, 2][..]), "the bad step is neither saved nor reported");
            let log = std::fs::read_to_string(out.join("log.jsonl")).unwrap();
            let lines: Vec<serde_json::Value> = log.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
            assert_eq!(lines.len(), 2);
            assert_eq!((lines[1]["step"].as_u64(), lines[1]["loss"].as_f64(), lines[1]["part"].as_f64()), (Some(2), Some(0.5), Some(0.25)));
            let _ = std::fs::remove_dir_all(&out);
        }
    }

    #[test]
    fn a_spent_time_budget_ends_the_run_with_a_save() {
        let out = dir("budget");
        let opts = LoopOptions { out: out.clone(), steps: 1000, checkpoint_every: Duration::from_secs(3600), budget: Some(Duration::ZERO) };
        let mut t = Scripted { losses: vec![1.0; 1000], saves: Vec::new() };
        let mut used = Vec::new();
        let done = train_loop(&opts, 4, &mut t, &StopFlag::new(), |p| used.push(p.budget_used)).unwrap();
        assert_eq!((done, t.saves.as_slice(), used.as_slice()), (5, &[5][..], &[Some(1.0)][..]), "one step, then saved and stopped");
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn a_stop_request_saves_at_the_step_boundary() {
        let out = dir("stop");
        let opts = LoopOptions { out: out.clone(), steps: 5, checkpoint_every: Duration::from_secs(3600), budget: None };
        let mut t = Scripted { losses: vec![1.0; 5], saves: Vec::new() };
        let stop = StopFlag::new();
        let err = train_loop(&opts, 1, &mut t, &stop, |p| {
            if p.step == 3 {
                stop.request();
            }
        })
        .unwrap_err();
        assert!(matches!(err, TrainError::Interrupted { step: 3 }), "{err}");
        assert_eq!(t.saves, [3]);
        assert!(!stop.saving());
        let _ = std::fs::remove_dir_all(&out);
    }
}
