//! The out-of-distribution warning the tools that run a learned model print (`crate::ood`): a
//! model's training skeletons as a reference, and one stderr line for a skeleton out of range.

use crate::diffusion::checkpoint::CheckpointInfo;
use crate::ood::{warning, Reference, Score, UNSEEN_LIMIT};
use crate::sata::rigs::KnownRigs;
use crate::skeleton::Skeleton;
use std::path::Path;

/// A model's training skeletons, profiled once per run, and how messages name the model.
pub struct Known {
    pub reference: Reference,
    pub model: String,
}

impl Known {
    /// The diffusion model's training skeletons (as its checkpoint records them); `dir` is the
    /// model's directory, none for the built-in one.
    pub fn denoiser(dir: Option<&Path>, info: &CheckpointInfo) -> anyhow::Result<Known> {
        let model = model_label(dir, crate::diffusion::checkpoint::BUILTIN_NAME);
        Ok(Known { reference: info.ood_reference()?, model })
    }

    /// The training skeletons of the unseen-skeleton denoiser of the model in `dir` (none: the
    /// built-in's), judged by `UNSEEN_LIMIT`: what `mo-sample` samples a skeleton the main
    /// denoiser was not trained on with.
    pub fn unseen_denoiser(dir: Option<&Path>, info: &CheckpointInfo) -> anyhow::Result<Known> {
        Ok(Known { reference: info.ood_reference()?.with_limit(UNSEEN_LIMIT), model: crate::diffusion::unseen::label(dir) })
    }

    /// The latent model's training skeletons (its `rigs.json`).
    pub fn latent(dir: Option<&Path>, rigs: &KnownRigs) -> anyhow::Result<Known> {
        let model = model_label(dir, "the built-in latent model");
        Ok(Known { reference: rigs.ood_reference()?, model })
    }

    /// `skeleton`'s score (None when the model records no skeletons).
    pub fn score(&self, label: &str, skeleton: &Skeleton) -> anyhow::Result<Option<Score>> {
        Ok(self.reference.score_skeleton(label, skeleton)?)
    }

    /// Print `tool`'s warning for `skeleton` (named `label`) on stderr when it is out of range,
    /// unless `quiet`.
    pub fn warn(&self, tool: &str, label: &str, skeleton: &Skeleton, quiet: bool) -> anyhow::Result<()> {
        if let Some(line) = self.score(label, skeleton)?.and_then(|s| warning(tool, label, &self.model, &s, advice(tool))) {
            if !quiet {
                eprintln!("{line}");
            }
        }
        Ok(())
    }
}

/// How warnings name a model: `model DIR` or the built-in one.
fn model_label(dir: Option<&Path>, builtin: &str) -> String {
    dir.map_or_else(|| builtin.to_string(), |d| format!("model {}", d.display()))
}

/// What to do instead, per tool.
fn advice(tool: &str) -> &'static str {
    match tool {
        "mo-sample" => "use --examples CLIPS (no model), or fine-tune on its clips: mo-train CLIPS --init builtin --minutes 5 --out DIR, then --model DIR",
        "mo-segment" => "use --features raw, or fine-tune on its clips: mo-train CLIPS --init builtin --minutes 5 --out DIR, then --model DIR",
        "mo-retarget" => {
            "use the default method (Motion2Motion, from example clips of the target), or train a latent model on both skeletons' clips: mo-train --arch sata"
        }
        "mo-encode" => "train a latent model on its clips: mo-train CLIPS --arch sata --out DIR, then --model DIR",
        _ => "fine-tune on its clips: mo-train CLIPS --init builtin --minutes 5 --out DIR, then --model DIR",
    }
}
