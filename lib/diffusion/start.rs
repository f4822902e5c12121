//! How a denoiser run starts, chosen from what was asked: the checkpoint in the output
//! directory continued (`--resume`), another model fine-tuned (`--init`), or new weights; with
//! the notes a person should read first (settings that differ from the checkpoint's, the model
//! being fine-tuned). The choice is the library's so that any caller starts runs the same way.

use super::trainer::{AnyTopInit, AnyTopOptions, AnyTopResume, AnyTopStart, TrainError};
use candle_core::Device;
use std::path::Path;

/// What `--init` names the model inside the binaries by (a directory of that name is `./builtin`).
pub const BUILTIN_INIT: &str = "builtin";

/// The model directory an `--init` value names, or None for the built-in model.
pub fn init_dir(init: &Path) -> Option<&Path> {
    (init.as_os_str() != BUILTIN_INIT).then_some(init)
}

impl AnyTopStart {
    /// Resume the checkpoint in `out` when `resume` (its optimiser at learning rate `lr`), else
    /// fine-tune `init` (`builtin`, the model inside the binaries, or a model directory), else
    /// start new; with the notes to print, in order.
    pub fn choose(
        out: &Path,
        resume: bool,
        init: Option<&Path>,
        lr: f64,
        opts: &AnyTopOptions,
        device: &Device,
    ) -> Result<(AnyTopStart, Vec<String>), TrainError> {
        let mut notes = Vec::new();
        if resume {
            let resume = AnyTopResume::load(out, lr, device)?;
            if resume.differs(opts) {
                notes.push(
                    "note: --batch, --crop, --seed, --position-jitter, --augment*, --fallback-stats, --loss-units or --rest-token differ from the checkpoint's; the resumed run is not the one it would have been".to_string(),
                );
            }
            if let Some((old, new)) = resume.shift_changes(opts) {
                notes.push(format!("note: the checkpoint was trained with --noise-shift {old}; it goes on learning under {new}, and samplers will use {new}"));
            }
            if let Some((old, new)) = resume.taper_changes(opts) {
                notes.push(format!(
                    "note: the checkpoint was trained with --shift-taper {old}; it goes on learning under --shift-taper {new}, which samplers will use too"
                ));
            }
            if let Some((old, new)) = resume.weighting_changes(opts) {
                notes.push(format!("note: the checkpoint was trained with --loss-weighting {old}; it goes on learning under {new}"));
            }
            return Ok((AnyTopStart::Resume(resume), notes));
        }
        if let Some(init) = init {
            let init = match init_dir(init) {
                None => AnyTopInit::builtin(device)?,
                Some(dir) => AnyTopInit::load(dir, device)?,
            };
            notes.push(format!("fine-tuning {} (its size and noise schedule; --preset is not used)", init.source()));
            return Ok((AnyTopStart::Init(init), notes));
        }
        Ok((AnyTopStart::New, notes))
    }

    /// The seed the run's data comes from: a resumed run's own (its augmented variants are
    /// rebuilt exactly), else `opts.seed`.
    pub fn seed(&self, opts: &AnyTopOptions) -> u64 {
        match self {
            AnyTopStart::Resume(r) => r.info().seed,
            _ => opts.seed,
        }
    }
}
