//! The out-of-distribution warning the tools that run a learned model print (`crate::ood`): a
//! model's training skeletons as a reference, and one stderr line for a skeleton out of range.

use crate::diffusion::checkpoint::CheckpointInfo;
use crate::embed::NameTable;
use crate::ood::{warning, Profile, Reference, Score};
use crate::sata::rigs::KnownRigs;
use crate::skeleton::Skeleton;
use glam::DVec3;

/// The diffusion model's training skeletons (as its checkpoint records them).
pub fn denoiser_reference(info: &CheckpointInfo) -> anyhow::Result<Reference> {
    let table = NameTable::builtin()?;
    let profiles = info
        .skeletons
        .iter()
        .filter(|t| t.offsets.len() == t.joints.len())
        .map(|t| Profile::new(&t.name, &t.joints, &t.parents, &t.offsets.iter().map(|o| DVec3::from_array(*o)).collect::<Vec<_>>(), table))
        .collect();
    Ok(Reference { profiles })
}

/// The latent model's training skeletons (its `rigs.json`).
pub fn latent_reference(rigs: &KnownRigs) -> anyhow::Result<Reference> {
    let table = NameTable::builtin()?;
    let profiles = rigs
        .rigs
        .iter()
        .map(|r| Profile::new(&r.name, &r.joints, &r.parents, &r.offsets.iter().map(|o| DVec3::from_array(*o)).collect::<Vec<_>>(), table))
        .collect();
    Ok(Reference { profiles })
}

/// `skeleton`'s score against `reference`, with the warning (ending in `advice`) printed on
/// stderr when it is out of range (unless `quiet`). None when the model records no skeletons.
pub fn check(tool: &str, label: &str, model: &str, reference: &Reference, skeleton: &Skeleton, advice: &str, quiet: bool) -> anyhow::Result<Option<Score>> {
    let score = reference.score(&Profile::of_skeleton(label, skeleton, NameTable::builtin()?));
    if let Some(line) = score.as_ref().and_then(|s| warning(tool, label, model, s, advice)) {
        if !quiet {
            eprintln!("{line}");
        }
    }
    Ok(score)
}

/// How warnings name a model: `model DIR` or the built-in one.
pub fn model_label(dir: Option<&std::path::Path>, builtin: &str) -> String {
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

/// The warning for `skeleton` (named `label`) against a diffusion model (`dir`, or the
/// built-in one).
pub fn warn_denoiser(tool: &str, label: &str, dir: Option<&std::path::Path>, info: &CheckpointInfo, skeleton: &Skeleton, quiet: bool) -> anyhow::Result<()> {
    let model = model_label(dir, crate::diffusion::checkpoint::BUILTIN_NAME);
    check(tool, label, &model, &denoiser_reference(info)?, skeleton, advice(tool), quiet).map(drop)
}

/// The warning for `skeleton` (named `label`) against a latent model (`dir`, or the built-in
/// one).
pub fn warn_latent(tool: &str, label: &str, dir: Option<&std::path::Path>, rigs: &KnownRigs, skeleton: &Skeleton, quiet: bool) -> anyhow::Result<()> {
    let model = model_label(dir, "the built-in latent model");
    check(tool, label, &model, &latent_reference(rigs)?, skeleton, advice(tool), quiet).map(drop)
}
