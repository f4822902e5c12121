//! Motion2Motion on clips as the tools read them: the checks a source and its example clips
//! must pass, the source brought to the examples' frame rate, and the lines that describe a
//! transfer and its binding. `mo-retarget` calls these between reading files and writing them;
//! a library caller with `motion::Clip`s gets the same checks, resampling and report.

use super::resample;
use crate::binding::{Binding, JointMap};
use crate::budget::BudgetError;
use crate::motion::{Clip, Motion};

/// Why clips cannot be retargeted as given; every message names the clip.
#[derive(Debug, thiserror::Error)]
pub enum ClipsError {
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Budget(#[from] BudgetError),
}

/// A source and example clips at least two frames long (a patch needs a velocity).
pub fn check_lengths(source: &Clip, examples: &[Clip]) -> Result<(), ClipsError> {
    if source.motion.frames < 2 {
        return Err(ClipsError::Invalid(format!("{}: {} frame(s): a source motion needs at least two frames", source.name, source.motion.frames)));
    }
    if let Some(e) = examples.iter().find(|e| e.motion.frames < 2) {
        return Err(ClipsError::Invalid(format!("{}: {} frame(s): example clips need at least two frames", e.name, e.motion.frames)));
    }
    Ok(())
}

/// The source's motion at the examples' frame rate (`first` is an example clip), with the two
/// rates when it had to be resampled; at most `max_frames` frames.
pub fn at_rate_of(source: &Clip, first: &Clip, max_frames: usize) -> Result<(Motion, Option<(f64, f64)>), ClipsError> {
    let target_fps = 1.0 / first.motion.frame_time;
    let source_fps = 1.0 / source.motion.frame_time;
    if (source_fps - target_fps).abs() <= 1e-6 * target_fps {
        return Ok((source.motion.clone(), None));
    }
    let frames = (source.motion.frames - 1) as f64 * source.motion.frame_time * target_fps + 1.0;
    if !(frames <= max_frames as f64) {
        return Err(ClipsError::Invalid(format!(
            "{}: resampling {source_fps:.3} fps to the examples' {target_fps:.3} fps ({}: Frame Time {}) would give {frames:.0} frames, more than {}",
            source.name, first.name, first.motion.frame_time, max_frames
        )));
    }
    crate::budget::check_motion(&format!("{}: resampling", source.name), frames as usize, source.skeleton.len())?;
    Ok((resample(&source.motion, target_fps), Some((source_fps, target_fps))))
}

/// The report lines about a transfer's clips and binding: the source (`source_frames` at the
/// examples' rate) against the examples, the binding's size and rate, and each bound pair with
/// its score when it has one.
pub fn describe(source: &Clip, source_frames: usize, examples: &[Clip], map: &JointMap, binding: &Binding) -> Vec<String> {
    let first = &examples[0];
    let mut lines = vec![
        format!(
            "{} ({} frames, {} joints) -> {} ({} example clip(s), {} frames, {} joints)",
            source.name,
            source_frames,
            source.skeleton.len(),
            first.name,
            examples.len(),
            examples.iter().map(|e| e.motion.frames).sum::<usize>(),
            first.skeleton.len()
        ),
        format!("binding: {} pairs, rate {:.1}%", map.len(), 100.0 * Binding::rate(map.len(), source.skeleton.len(), first.skeleton.len())),
    ];
    for (p, &(s, t)) in binding.mapping.iter().zip(map) {
        let score = p.score.map(|x| format!(" (score {x:.3})")).unwrap_or_default();
        lines.push(format!("  {} -> {}{score}", source.skeleton.joints[s].name, first.skeleton.joints[t].name));
    }
    lines
}
