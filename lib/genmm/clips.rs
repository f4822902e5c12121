//! GenMM on clips as the tools read them: the check a reference clip of an edit must pass, the
//! notes of a batch of samples said once each, and the JSON report `mo-sample --examples
//! --report` prints. Here, beside the generator, so that a library caller gets the same.

use super::{Generated, GenmmError};
use crate::motion::Clip;
use serde_json::{json, Value};
use std::time::Duration;

/// A reference of an edit on the example clips' skeleton (`first` is one of them), at their
/// frame rate, with frames.
pub fn check_reference(first: &Clip, reference: &Clip) -> Result<(), GenmmError> {
    let r = reference;
    if let Some(why) = first.skeleton.first_difference(&r.skeleton) {
        return Err(GenmmError::Reference(format!("the reference {} is not on the skeleton of the example clips ({}): {why}", r.name, first.name)));
    }
    let (a, b) = (r.motion.frame_time, first.motion.frame_time);
    if (a - b).abs() > 1e-6 * b {
        return Err(GenmmError::Reference(format!(
            "the reference {} runs at {:.3} fps but the example clips ({}) at {:.3} fps: give a reference of their frame rate",
            r.name,
            1.0 / a,
            first.name,
            1.0 / b
        )));
    }
    if r.motion.frames == 0 {
        return Err(GenmmError::Reference(format!("the reference {} has no frames", r.name)));
    }
    Ok(())
}

/// The notes of all samples, each once, sorted.
pub fn notes(generated: &[Generated]) -> Vec<&String> {
    let mut notes: Vec<&String> = generated.iter().flat_map(|g| &g.report.notes).collect();
    notes.dedup();
    notes.sort();
    notes.dedup();
    notes
}

/// The report of a generation from `clips` that took `time`: per sample its seed, length,
/// patch, pyramid levels with their match costs, synthesis time and notes (one JSON line).
pub fn report(clips: &[Clip], generated: &[Generated], time: Duration) -> String {
    let samples: Vec<Value> = generated
        .iter()
        .map(|g| {
            let levels: Vec<Value> =
                g.report.levels.iter().map(|l| json!({ "frames": l.frames, "example_patches": l.example_patches, "match_costs": l.step_costs })).collect();
            json!({
                "seed": g.report.seed,
                "frames": g.report.frames,
                "patch": g.report.patch,
                "levels": levels,
                "synthesis_ms": g.report.synthesis.as_secs_f64() * 1e3,
                "notes": g.report.notes,
            })
        })
        .collect();
    json!({
        "report": "genmm",
        "examples": clips.iter().map(|c| &c.name).collect::<Vec<_>>(),
        "example_frames": clips.iter().map(|c| c.motion.frames).sum::<usize>(),
        "generation_ms": time.as_secs_f64() * 1e3,
        "samples": samples,
    })
    .to_string()
}
