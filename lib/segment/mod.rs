//! Temporal segmentation of a motion: per-frame feature vectors -> PCA -> temporal context ->
//! k-means -> smoothing -> contiguous segments (issue 8, `mo-segment`).
//!
//! The pipeline only sees `&[Vec<f64>]`, one feature vector per frame, so any feature provider
//! plugs in: the motion's own AnyTop features (`raw_frame_features`, the baseline) or a
//! denoiser's activations averaged over joints (DIFT). Steps, each a public function:
//!
//! 1. `pca`: centre, project on the top `pca_dims` components (the features of a many-joint
//!    skeleton have hundreds of correlated dimensions).
//! 2. `context`: each frame becomes the mean and standard deviation of its projections over a
//!    window of neighbouring frames. Per-frame poses of a walk sweep through a gait cycle, so
//!    k-means on single frames clusters *phases* (left foot forward, right foot forward) rather
//!    than actions; statistics over about a cycle describe the action (a walk varies, a stand
//!    does not) — measured in `benches/segment.rs`.
//! 3. `standardise` (optional, off by default): z-score every dimension. Measured on the
//!    boundary benchmark it changes nothing on the synthetic clips and doubles the spurious
//!    boundaries on the real ones (it inflates components that barely vary), so it stays off.
//! 4. `kmeans`: k-means++ and Lloyd, several seeded restarts, labels by first appearance.
//! 5. `smooth`: runs shorter than `min_segment` frames are merged into a neighbour.
//! 6. `refine`: each boundary moves to the best single-frame change point within half a window
//!    (the window statistics of step 2 place it only to about half a window).
//! 7. `segments`: the contiguous runs, `end` exclusive (what `mo-render --frame-labels` reads).
//!
//! Defaults (`SegmentOptions::default`, `mo-segment`'s flags) are the best of
//! `cargo bench --bench segment` on walk-stop-walk clips and concatenated real clips: a
//! one-second window (30 frames at 30 fps), 8 components, runs of at least 10 frames, refined.
//!
//! Everything is sequential f64 arithmetic in a fixed order: same input and seed, same labels.

pub mod input;
mod kmeans;
mod pca;
pub mod report;

pub use kmeans::{kmeans, KMeans, MAX_ITERATIONS};
pub use pca::{pca, Pca};

use crate::repr::anytop::{DIMS_ROTATION, FEATURE_DIMS};
use crate::repr::Features;
use serde::Serialize;

/// What can be wrong with the input of a segmentation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SegmentError {
    #[error("no frames to segment")]
    Empty,
    #[error("the frame features have no dimensions")]
    NoDims,
    #[error("frame {frame} has {got} feature values but frame 0 has {expected}")]
    Ragged { frame: usize, got: usize, expected: usize },
    #[error("non-finite feature value at frame {frame}, dimension {dim}")]
    NonFinite { frame: usize, dim: usize },
    #[error("PCA needs at least one component (pca dims 0 means: no PCA)")]
    ZeroDims,
    #[error("k must be at least 1")]
    ZeroK,
    #[error("{k} clusters need at least {k} frames, the clip has {frames}")]
    TooFewFrames { k: usize, frames: usize },
}

/// Non-empty, rectangular, finite; returns the dimension.
pub(crate) fn check_frames(frames: &[Vec<f64>]) -> Result<usize, SegmentError> {
    let first = frames.first().ok_or(SegmentError::Empty)?;
    let d = first.len();
    if d == 0 {
        return Err(SegmentError::NoDims);
    }
    for (frame, f) in frames.iter().enumerate() {
        if f.len() != d {
            return Err(SegmentError::Ragged { frame, got: f.len(), expected: d });
        }
        if let Some(dim) = f.iter().position(|v| !v.is_finite()) {
            return Err(SegmentError::NonFinite { frame, dim });
        }
    }
    Ok(d)
}

/// One contiguous run of a label: frames `start..end` (end exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Segment {
    pub start: usize,
    pub end: usize,
    pub label: usize,
}

/// The choices of a segmentation; `Default` holds the measured defaults of `mo-segment`.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentOptions {
    /// Clusters (actions) to find.
    pub k: usize,
    /// Principal components kept; 0 = no PCA (the features as they are).
    pub pca_dims: usize,
    /// Temporal context window in frames (mean and std over it); 0 or 1 = single frames.
    pub window: usize,
    /// Z-score every dimension before clustering.
    pub standardise: bool,
    /// Shortest run kept, in frames; shorter runs are merged into a neighbour (0 or 1 = none).
    pub min_segment: usize,
    /// K-means restarts (the lowest inertia wins).
    pub restarts: usize,
    /// Move every boundary to the best single-frame change point within half a window of it
    /// (see `refine`); without a window there is nothing to refine.
    pub refine: bool,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        SegmentOptions { k: 3, pca_dims: 8, window: 30, standardise: false, min_segment: 10, restarts: 8, refine: true }
    }
}

/// The result of `segment`.
#[derive(Clone, Debug, PartialEq)]
pub struct Segmentation {
    /// One label per input frame, numbered by first appearance (frame 0 has label 0).
    pub labels: Vec<usize>,
    /// Contiguous runs of `labels`.
    pub segments: Vec<Segment>,
    /// Components PCA kept (0 without PCA).
    pub pca_dims: usize,
    /// Fraction of the feature variance those components explain (1 without PCA).
    pub explained_variance: f64,
    /// Labels in use after smoothing (at most k).
    pub clusters: usize,
}

/// Segment a motion given one feature vector per frame (see the module doc for the steps).
/// Errors on empty, ragged or non-finite input and when k is 0 or exceeds the frame count.
pub fn segment(frames: &[Vec<f64>], options: &SegmentOptions, seed: u64) -> Result<Segmentation, SegmentError> {
    check_frames(frames)?;
    if options.k == 0 {
        return Err(SegmentError::ZeroK);
    }
    if options.k > frames.len() {
        return Err(SegmentError::TooFewFrames { k: options.k, frames: frames.len() });
    }
    let (mut points, pca_dims, explained_variance) = if options.pca_dims == 0 {
        (frames.to_vec(), 0, 1.0)
    } else {
        let p = pca(frames, options.pca_dims)?;
        (p.projections, p.dims, p.explained)
    };
    // A window longer than the clip is the whole clip.
    let window = options.window.min(frames.len());
    let single = (window > 1 && options.refine).then(|| points.clone());
    if window > 1 {
        points = context(&points, window);
    }
    if options.standardise {
        standardise(&mut points);
    }
    let clustered = kmeans(&points, options.k, seed, options.restarts)?;
    let mut labels = smooth(&clustered.labels, options.min_segment);
    if let Some(single) = single {
        labels = smooth(&refine(&single, &labels, window / 2), options.min_segment);
    }
    let clusters = labels.iter().max().map_or(0, |m| m + 1);
    Ok(Segmentation { segments: segments(&labels), labels, pca_dims, explained_variance, clusters })
}

/// Per frame, the mean and the standard deviation of every dimension over the `window` frames
/// centred on it (shifted inward at the clip's ends; the whole clip when it is shorter):
/// `2 × dims` values. `window` ≤ 1 returns the input.
pub fn context(frames: &[Vec<f64>], window: usize) -> Vec<Vec<f64>> {
    let n = frames.len();
    let Some(d) = frames.first().map(Vec::len) else { return Vec::new() };
    if window <= 1 {
        return frames.to_vec();
    }
    let before = (window - 1) / 2;
    // Prefix sums of x and x² make every window O(d).
    let mut sum = vec![vec![0.0; d]; n + 1];
    let mut sq = vec![vec![0.0; d]; n + 1];
    for (t, f) in frames.iter().enumerate() {
        for j in 0..d {
            sum[t + 1][j] = sum[t][j] + f[j];
            sq[t + 1][j] = sq[t][j] + f[j] * f[j];
        }
    }
    (0..n)
        .map(|t| {
            // Near the ends the window slides inward rather than shrinking, so every frame is
            // described over the same duration (a shrunken window sees less of a gait cycle and
            // would make the clip's ends look like a different action).
            let lo = t.saturating_sub(before).min(n.saturating_sub(window));
            let hi = lo.saturating_add(window).min(n);
            let m = (hi - lo) as f64;
            let mean: Vec<f64> = (0..d).map(|j| (sum[hi][j] - sum[lo][j]) / m).collect();
            // Cancellation can make the variance slightly negative; it is zero then.
            let std = (0..d).map(|j| ((sq[hi][j] - sq[lo][j]) / m - mean[j] * mean[j]).max(0.0).sqrt());
            mean.iter().copied().chain(std).collect()
        })
        .collect()
}

/// Move each boundary of `labels` to the most likely change point of the single-frame `points`
/// within `radius` frames of it. Statistics over a window blur where an action changes (the
/// window straddles both sides for `window` frames), so clustering them finds a boundary only
/// to within about half a window; the single frames say where exactly. The score of a split at
/// s of the frames lo..hi around the boundary (up to two radii each side, never past the
/// neighbouring boundaries) is the Gaussian log-likelihood with a mean and a variance per side
/// and dimension, `Σ_d n₁ ln σ₁² + n₂ ln σ₂²` (lower is better), which sees a change of pose
/// (mean) and of activity (variance: a walk against a stand) alike. Variances are floored at
/// 1 % of the dimension's variance over the clip, so a side that stands still does not win by
/// an infinitely small variance. Ties keep the position closest to the old boundary.
pub fn refine(points: &[Vec<f64>], labels: &[usize], radius: usize) -> Vec<usize> {
    let n = points.len();
    let mut out = labels.to_vec();
    if radius == 0 || n != labels.len() || n < 4 {
        return out;
    }
    let d = points[0].len();
    let mut sum = vec![vec![0.0; d]; n + 1];
    let mut sq = vec![vec![0.0; d]; n + 1];
    for (t, f) in points.iter().enumerate() {
        for j in 0..d {
            sum[t + 1][j] = sum[t][j] + f[j];
            sq[t + 1][j] = sq[t][j] + f[j] * f[j];
        }
    }
    let var = |lo: usize, hi: usize, j: usize| {
        let m = (hi - lo) as f64;
        let mean = (sum[hi][j] - sum[lo][j]) / m;
        ((sq[hi][j] - sq[lo][j]) / m - mean * mean).max(0.0)
    };
    let floor: Vec<f64> = (0..d).map(|j| 0.01 * var(0, n, j) + 1e-12).collect();
    let cost = |lo: usize, s: usize, hi: usize| -> f64 {
        (0..d).map(|j| (s - lo) as f64 * (var(lo, s, j) + floor[j]).ln() + (hi - s) as f64 * (var(s, hi, j) + floor[j]).ln()).sum()
    };
    let marks = boundaries(labels);
    let mut previous = 0;
    for (i, &b) in marks.iter().enumerate() {
        let next = marks.get(i + 1).copied().unwrap_or(n);
        let lo = previous.max(b.saturating_sub(radius.saturating_mul(2)));
        let hi = next.min(b.saturating_add(radius.saturating_mul(2)));
        let first = (lo + 2).max(b.saturating_sub(radius));
        let last = hi.saturating_sub(2).min(b.saturating_add(radius));
        let mut best = (b, f64::INFINITY);
        for s in first..=last {
            let c = cost(lo, s, hi);
            if c < best.1 || (c == best.1 && s.abs_diff(b) < best.0.abs_diff(b)) {
                best = (s, c);
            }
        }
        let s = if best.1.is_finite() { best.0 } else { b };
        // Frames between the old and the new boundary change sides.
        let (left, right) = (labels[b - 1], labels[b]);
        for t in s.min(b)..s.max(b) {
            out[t] = if t < s { left } else { right };
        }
        previous = s;
    }
    out
}

/// Z-score every dimension in place; a dimension that does not vary becomes 0.
pub fn standardise(frames: &mut [Vec<f64>]) {
    let n = frames.len() as f64;
    let Some(d) = frames.first().map(Vec::len) else { return };
    for j in 0..d {
        let mean = frames.iter().map(|f| f[j]).sum::<f64>() / n;
        let var = frames.iter().map(|f| (f[j] - mean) * (f[j] - mean)).sum::<f64>() / n;
        let std = var.sqrt();
        for f in frames.iter_mut() {
            f[j] = if std > 1e-12 { (f[j] - mean) / std } else { 0.0 };
        }
    }
}

/// Merge runs shorter than `min_segment` frames into a neighbour until none is left (or one run
/// remains). The shortest short run goes first (the earliest on ties) and takes the label of its
/// *longer* neighbour (the earlier one on ties; a run at either end of the clip has one
/// neighbour): a flicker inside a long action joins that action, and merging shortest-first means
/// a short run is never absorbed into another run that is itself about to vanish. The result is
/// renumbered by first appearance, as `kmeans` numbers labels.
pub fn smooth(labels: &[usize], min_segment: usize) -> Vec<usize> {
    let mut runs: Vec<Segment> = segments(labels);
    loop {
        if runs.len() <= 1 {
            break;
        }
        let short = runs.iter().enumerate().filter(|(_, r)| r.end - r.start < min_segment).min_by_key(|(i, r)| (r.end - r.start, *i));
        let Some((i, _)) = short else { break };
        let len = |r: &Segment| r.end - r.start;
        let into = match (i.checked_sub(1), runs.get(i + 1)) {
            (Some(p), Some(next)) => {
                if len(next) > len(&runs[p]) {
                    i + 1
                } else {
                    p
                }
            }
            (Some(p), None) => p,
            (None, _) => i + 1,
        };
        runs[i].label = runs[into].label;
        // Coalesce neighbours that now share a label.
        let mut merged: Vec<Segment> = Vec::with_capacity(runs.len());
        for r in runs {
            match merged.last_mut() {
                Some(last) if last.label == r.label => last.end = r.end,
                _ => merged.push(r),
            }
        }
        runs = merged;
    }
    let flat: Vec<usize> = runs.iter().flat_map(|r| std::iter::repeat_n(r.label, r.end - r.start)).collect();
    kmeans::first_appearance(&flat).0
}

/// Contiguous runs of equal labels, `end` exclusive.
pub fn segments(labels: &[usize]) -> Vec<Segment> {
    let mut out: Vec<Segment> = Vec::new();
    for (t, &label) in labels.iter().enumerate() {
        match out.last_mut() {
            Some(last) if last.label == label => last.end = t + 1,
            _ => out.push(Segment { start: t, end: t + 1, label }),
        }
    }
    out
}

/// Boundary frames of a labelling: every t > 0 whose label differs from frame t−1's (the first
/// frame of each segment but the first).
pub fn boundaries(labels: &[usize]) -> Vec<usize> {
    (1..labels.len()).filter(|&t| labels[t] != labels[t - 1]).collect()
}

/// How well predicted boundaries match the true ones.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoundaryErrors {
    /// For every true boundary, in order, the distance in frames to the nearest predicted
    /// boundary; `None` when nothing was predicted.
    pub errors: Vec<Option<usize>>,
    /// Predicted boundaries that are no true boundary's nearest prediction.
    pub spurious: usize,
}

/// Score predicted boundary frames against true ones (both as `boundaries` gives them).
pub fn boundary_errors(predicted: &[usize], truth: &[usize]) -> BoundaryErrors {
    let mut matched = vec![false; predicted.len()];
    let errors = truth
        .iter()
        .map(|&b| {
            // Nearest prediction; the earlier on ties.
            let (i, d) = predicted.iter().enumerate().map(|(i, &p)| (i, p.abs_diff(b))).min_by_key(|&(i, d)| (d, i))?;
            matched[i] = true;
            Some(d)
        })
        .collect();
    BoundaryErrors { errors, spurious: matched.iter().filter(|m| !**m).count() }
}

/// The baseline features of `mo-segment --features raw`: per feature frame, every joint's 13
/// AnyTop values (root-relative positions, 6D rotations, velocities, foot contacts) except the
/// root's facing rotation (its 6D yaw: where the clip is heading, not what the body does, and
/// it drifts through a turn). AnyTop features of an F-frame clip have F−1 frames: frame t's
/// row describes BVH frame t (and the step to t+1); see `extend_labels` for the last frame.
pub fn raw_frame_features(features: &Features) -> Vec<Vec<f64>> {
    let dims = features.dims;
    (0..features.frames)
        .map(|t| {
            let mut row = Vec::with_capacity(features.joints * dims);
            for j in 0..features.joints {
                let v = features.at(t, j);
                if j == 0 && dims == FEATURE_DIMS {
                    row.extend(v.iter().enumerate().filter(|(d, _)| !DIMS_ROTATION.contains(d)).map(|(_, x)| *x as f64));
                } else {
                    row.extend(v.iter().map(|&x| x as f64));
                }
            }
            row
        })
        .collect()
}

/// Labels of feature frames as labels of `frames` motion frames: frames without a feature row
/// (the last BVH frame for AnyTop features) take the last row's label. Longer input is cut.
pub fn extend_labels(labels: &[usize], frames: usize) -> Vec<usize> {
    let last = labels.last().copied().unwrap_or(0);
    (0..frames).map(|t| labels.get(t).copied().unwrap_or(last)).collect()
}

#[cfg(test)]
mod tests;
