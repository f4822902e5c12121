//! Pyramid level lengths (the reference's `_get_pyramid_lengths`, with its crash cases fixed).

/// numpy's `round`: half to even.
fn round_half_even(x: f64) -> f64 {
    let r = x.round();
    if (x - x.trunc()).abs() == 0.5 && r % 2.0 != 0.0 {
        r - x.signum()
    } else {
        r
    }
}

/// The reference's level lengths for a clip of `len` frames: start at `round(len * ratio)`,
/// grow by `1 / factor` (at least one frame a level) until `len` is reached, and end exactly at
/// `len`. `factor` is in (0, 1) (checked by `Settings::validate`).
pub(crate) fn lengths(len: usize, ratio: f64, factor: f64) -> Vec<usize> {
    let mut out = vec![round_half_even(len as f64 * ratio).max(1.0) as usize];
    while *out.last().unwrap_or(&len) < len {
        let last = *out.last().unwrap_or(&len);
        let mut next = round_half_even(last as f64 / factor) as usize;
        if next <= last {
            next = last + 1;
        }
        out.push(next);
    }
    if let Some(l) = out.last_mut() {
        *l = len;
    }
    out
}

/// The patch length both syntheses use: `requested`, no longer than the output (`frames`) or
/// the longest example clip, and at least 1. Notes when it had to shrink, and for every example
/// clip shorter than the patch (such a clip has no patch to match and is not used).
pub(crate) fn fit_patch(requested: usize, frames: usize, example_frames: &[usize], notes: &mut Vec<String>) -> usize {
    let longest = example_frames.iter().copied().max().unwrap_or(1);
    let patch = requested.min(frames).min(longest).max(1);
    if patch < requested {
        notes.push(format!("patch shrunk from {requested} to {patch} frames (the output or every example clip is shorter)"));
    }
    for (i, f) in example_frames.iter().enumerate().filter(|(_, &f)| f < patch) {
        notes.push(format!("example clip {i} ({f} frames) is shorter than a patch and is not used"));
    }
    patch
}

/// Output lengths of the levels for an output of `frames` frames, patch `patch`: the
/// reference's rule (the coarsest level of an example `example_frames` long holds about
/// `coarse_patches * patch` frames; the reference and `retarget` pass the longest example,
/// `genmm` the median), minus the coarse levels shorter than a patch. The reference keeps those
/// and crashes when the target is more than ~5x longer than the source.
pub(crate) fn output_levels(frames: usize, example_frames: usize, patch: usize, coarse_patches: f64, factor: f64) -> Vec<usize> {
    let ratio = (coarse_patches * patch as f64 / example_frames.max(1) as f64).min(1.0);
    let mut levels: Vec<usize> = lengths(frames, ratio, factor).into_iter().filter(|&l| l >= patch).collect();
    if levels.is_empty() {
        levels.push(frames);
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_demo_and_long_targets() {
        // Demo: 79-frame source, 61-frame target, patch 11: r = 55/61 -> [71, 79].
        assert_eq!(output_levels(79, 61, 11, 5.0, 0.75), vec![71, 79]);
        // 122-frame target: 4 levels (36, 48, 64, 79) as the reference documents.
        assert_eq!(output_levels(79, 122, 11, 5.0, 0.75), vec![36, 48, 64, 79]);
        // A 488-frame target: the reference plans a 9-frame level and crashes; we drop it.
        let l = output_levels(79, 488, 11, 5.0, 0.75);
        assert!(l[0] >= 11 && *l.last().unwrap() == 79, "{l:?}");
        assert_eq!(round_half_even(2.5), 2.0);
        assert_eq!(round_half_even(3.5), 4.0);
        assert_eq!(lengths(5, 2.0, 0.75), vec![5]);
    }
}
