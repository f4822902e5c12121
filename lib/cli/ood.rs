//! The out-of-distribution warning the tools that run a learned model print (`crate::ood`): a
//! model's training skeletons as a reference, and one stderr line for a skeleton out of range.

use crate::diffusion::checkpoint::CheckpointInfo;
use crate::embed::NameTable;
use crate::ood::{warning, Profile, Reference, Score};
use crate::sata::rigs::KnownRigs;
use crate::skeleton::Skeleton;
use glam::DVec3;
use std::path::Path;

/// A model's training skeletons, profiled once per run, and how messages name the model.
pub struct Known {
    pub reference: Reference,
    pub model: String,
}

/// Name, joint names, parents and rest offsets of one recorded training skeleton.
type Recorded<'a> = (&'a str, &'a [String], &'a [Option<usize>], &'a [[f64; 3]]);

impl Known {
    fn new<'a>(model: String, recorded: impl Iterator<Item = Recorded<'a>>) -> anyhow::Result<Known> {
        let table = NameTable::builtin()?;
        let profiles = recorded
            .filter(|(_, joints, _, offsets)| offsets.len() == joints.len())
            .map(|(name, joints, parents, offsets)| {
                Profile::new(name, joints, parents, &offsets.iter().map(|o| DVec3::from_array(*o)).collect::<Vec<_>>(), table)
            })
            .collect();
        Ok(Known { reference: Reference { profiles }, model })
    }

    /// The diffusion model's training skeletons (as its checkpoint records them); `dir` is the
    /// model's directory, none for the built-in one.
    pub fn denoiser(dir: Option<&Path>, info: &CheckpointInfo) -> anyhow::Result<Known> {
        let model = model_label(dir, crate::diffusion::checkpoint::BUILTIN_NAME);
        Known::new(model, info.skeletons.iter().map(|t| (t.name.as_str(), t.joints.as_slice(), t.parents.as_slice(), t.offsets.as_slice())))
    }

    /// The latent model's training skeletons (its `rigs.json`).
    pub fn latent(dir: Option<&Path>, rigs: &KnownRigs) -> anyhow::Result<Known> {
        let model = model_label(dir, "the built-in latent model");
        Known::new(model, rigs.rigs.iter().map(|r| (r.name.as_str(), r.joints.as_slice(), r.parents.as_slice(), r.offsets.as_slice())))
    }

    /// `skeleton`'s score (None when the model records no skeletons).
    pub fn score(&self, label: &str, skeleton: &Skeleton) -> anyhow::Result<Option<Score>> {
        Ok(self.reference.score(&Profile::of_skeleton(label, skeleton, NameTable::builtin()?)))
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
