//! Training the SATA autoencoder in the shared loop (`diffusion::trainer`): a new run or the
//! continuation of a checkpoint, on the same bucketed data as the denoiser.

use super::checkpoint::{self, SataInfo};
use super::rigs::KnownRigs;
use super::train::{raw_clips, train_step, FeatureScale, LossWeights};
use super::{SataConfig, SataModel};
use crate::diffusion::checkpoint::{load_optimizer, save};
use crate::diffusion::data::TrainSet;
use crate::diffusion::train::{named_vars, AdamW};
use crate::diffusion::trainer::{refuse_existing, step_rng, StepLosses, TrainError, Trainer};
use crate::nn::seeded_var_builder;
use candle_core::{Device, Var};
use candle_nn::VarMap;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How to train the autoencoder.
#[derive(Clone, Debug)]
pub struct SataOptions {
    /// The model for a new run (a resumed one keeps its checkpoint's).
    pub config: SataConfig,
    pub seed: u64,
    pub lr: f64,
    pub batch: usize,
    pub augment: f64,
    pub augment_variants: usize,
    /// Weight of the KL term (new runs; a resumed run keeps its checkpoint's).
    pub lambda_kl: f64,
    /// Weight of the cross-skeleton cycle: a new run's default is 0, a resumed run keeps its
    /// checkpoint's unless this is given.
    pub lambda_cycle: Option<f64>,
}

/// A SATA checkpoint to continue, with its optimiser state.
pub struct SataResume {
    loaded: checkpoint::LoadedAutoencoder,
    opt: AdamW,
}

impl SataResume {
    /// The checkpoint in `dir`; the optimiser continues with learning rate `lr`.
    pub fn load(dir: &Path, lr: f64, device: &Device) -> Result<SataResume, TrainError> {
        let loaded = checkpoint::load(dir, device)?;
        let opt = load_optimizer(dir, loaded.info.step, device, lr)?;
        Ok(SataResume { loaded, opt })
    }

    /// The training data must be rebuilt from the seed the run started with.
    pub fn info(&self) -> &SataInfo {
        &self.loaded.info
    }

    /// Whether `opts` draw other data than the checkpoint's run did.
    pub fn differs(&self, opts: &SataOptions) -> bool {
        let i = &self.loaded.info;
        i.batch != opts.batch || i.seed != opts.seed || i.augment != opts.augment || i.augment_variants != opts.augment_variants
    }
}

/// The autoencoder's training state.
pub struct SataTrainer {
    out: PathBuf,
    info: SataInfo,
    varmap: VarMap,
    model: SataModel,
    vars: BTreeMap<String, Var>,
    opt: AdamW,
    set: TrainSet,
    device: Device,
}

impl SataTrainer {
    /// A new run (`resume` none; `out` must not hold a checkpoint) or the continuation of
    /// `resume`, on `set`, saving to `out`. Writes `out/rigs.json` at once: inference reads a
    /// trained skeleton's motion with the rig it was trained with.
    pub fn new(out: &Path, opts: &SataOptions, resume: Option<SataResume>, set: TrainSet, device: &Device) -> Result<SataTrainer, TrainError> {
        let (varmap, model, opt, mut info) = match resume {
            Some(r) => {
                // The checkpoint records the settings its latest steps ran with (a curriculum
                // changes --augment or --lr between resumes; log.jsonl keeps the history).
                let info = SataInfo { lr: opts.lr, batch: opts.batch, augment: opts.augment, augment_variants: opts.augment_variants, ..r.loaded.info };
                (r.loaded.varmap, r.loaded.model, r.opt, info)
            }
            None => {
                refuse_existing(out)?;
                opts.config.validate()?;
                // Measured once on the original data; a resumed run keeps the checkpoint's.
                let raw = raw_clips(&set);
                let scale = FeatureScale::measure(raw.iter().map(|(f, rest)| (f, rest.as_slice())));
                let varmap = VarMap::new();
                let model = SataModel::new(seeded_var_builder(&varmap, opts.seed, device), &opts.config)?;
                let info = SataInfo {
                    format: checkpoint::FORMAT.into(),
                    version: checkpoint::VERSION,
                    config: opts.config.clone(),
                    scale,
                    weights: LossWeights { kl: opts.lambda_kl, cycle: opts.lambda_cycle.unwrap_or(0.0), ..LossWeights::default() },
                    step: 0,
                    seed: opts.seed,
                    lr: opts.lr,
                    batch: opts.batch,
                    augment: opts.augment,
                    augment_variants: opts.augment_variants,
                    skeletons: Vec::new(),
                };
                (varmap, model, AdamW::new(opts.lr), info)
            }
        };
        info.skeletons = set.skeletons.iter().map(|s| s.name.clone()).collect();
        if let Some(w) = opts.lambda_cycle {
            info.weights.cycle = w;
        }
        KnownRigs::of_set(&set).write(out)?;
        let vars = named_vars(&varmap);
        Ok(SataTrainer { out: out.to_path_buf(), info, varmap, model, vars, opt, set, device: device.clone() })
    }

    /// Steps done before this run (0 for a new one).
    pub fn first_step(&self) -> u64 {
        self.info.step
    }
}

impl Trainer for SataTrainer {
    fn step(&mut self, k: u64) -> Result<StepLosses, TrainError> {
        let mut rng = step_rng(self.info.seed, k);
        let l = train_step(&self.model, &self.vars, &mut self.opt, &self.set, &self.info.scale, &self.info.weights, &mut rng, self.info.batch, &self.device)
            .map_err(|e| TrainError::Model(e.into()))?;
        let parts = vec![
            ("reconstruction", l.reconstruction),
            ("root", l.root),
            ("geodesic", l.geodesic),
            ("smooth", l.smooth),
            ("contact", l.contact),
            ("penetration", l.penetration),
            ("kl", l.kl),
            ("cycle", l.cycle),
        ];
        Ok(StepLosses { total: l.total, parts })
    }

    fn save(&mut self, steps: u64) -> Result<(), TrainError> {
        self.info.step = steps;
        Ok(save(&self.out, &self.info, &self.varmap, &self.opt)?)
    }
}
