//! AnyTop's generation metrics: coverage, local / global / inter / intra diversity and the
//! intra-diversity difference (paper §6.3, reference `eval/eval_truebones.py`,
//! docs/reference/anytop.md §6). They descend from GANimator's and SinMDM's single-motion metrics:
//! windows of a motion are matched to their nearest windows in another set, and a dynamic programme
//! tiles a generated motion with pieces of a ground-truth (GT) clip.
//!
//! Everything works on [`PointClip`]s: per-frame sets of 3-D points, compared by the mean
//! Euclidean distance of corresponding points (the reference's `pos_avg_l2`, "loc" mode). The
//! reference's points are the RIC positions of every non-root joint with the root height
//! subtracted, in AnyTop's scaled units (mean bone = 0.2092, the mean SMPL bone), so the
//! distances are comparable across skeletons and with the coverage threshold.
//!
//! Determinism: every random draw (window offsets, coverage subsets) comes from one SplitMix64
//! stream seeded by [`GenerationOptions::seed`], drawn in a fixed order before any parallel
//! work; parallel loops only fill per-item slots, and every reduction runs in item order. So
//! the same input and seed give bit-identical reports at any thread count.
//!
//! Definitions, units and deviations from the reference: `docs/metrics.md`.

use super::{MetricError, WorldClip};
use crate::repr::anytop::{Facing, HUMANML_MEAN_BONE_LENGTH};
use crate::rng::SplitMix64;
use glam::{DQuat, DVec3};
use rayon::prelude::*;

/// A motion as per-frame vectors of 3-D points (`dims = 3 × points`), row-major by frame.
#[derive(Clone, Debug)]
pub struct PointClip {
    frames: usize,
    dims: usize,
    values: Vec<f64>,
}

/// How [`PointClip::from_clip_with`] builds the reference's features from world positions.
#[derive(Clone, Debug, Default)]
pub struct PointFeatures {
    /// Facing rule; every frame is turned (about +y) so that it faces +Z, as AnyTop's RIC
    /// positions are. `None` keeps world axes: right for clips that do not turn, otherwise
    /// pass the skeleton's rule (`AnyTopRig::facing`).
    pub facing: Option<Facing>,
    /// Multiplier to AnyTop's scaled units (`AnyTopRig::scale_factor`). `None`: 0.2092… / the
    /// mean bone length (joint to parent) of the clip's frame 0.
    pub scale: Option<f64>,
}

impl PointClip {
    /// `frames × dims` values, row-major; `dims` must be a positive multiple of 3 (points).
    pub fn new(frames: usize, dims: usize, values: Vec<f64>) -> Result<PointClip, MetricError> {
        if dims == 0 || !dims.is_multiple_of(3) {
            return Err(MetricError::Mismatch(format!("point clip: {dims} values per frame is not a positive multiple of 3")));
        }
        if values.len() != frames * dims {
            return Err(MetricError::Mismatch(format!("point clip: {} values for {frames} frames of {dims} (expected {})", values.len(), frames * dims)));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(MetricError::NonFinite(format!("point clip: frame {} value {} is {}", i / dims, i % dims, values[i])));
        }
        Ok(PointClip { frames, dims, values })
    }

    /// The reference's features from AnyTop's 13-D features `[frames, joints, 13]` (physical,
    /// denormalised units, as `mo-sample` writes and the reference evaluates): dims 0..3 of
    /// every non-root joint, with the root's height (root dim 1) subtracted from y.
    pub fn from_anytop_features(frames: usize, joints: usize, features: &[f32]) -> Result<PointClip, MetricError> {
        const D: usize = crate::repr::anytop::FEATURE_DIMS;
        if features.len() != frames * joints * D {
            return Err(MetricError::Mismatch(format!(
                "AnyTop features: {} values for {frames} frames × {joints} joints × {D} (expected {})",
                features.len(),
                frames * joints * D
            )));
        }
        if joints < 2 {
            return Err(MetricError::TooLittle(format!("AnyTop features: {joints} joint(s); the metrics use the non-root joints")));
        }
        let mut values = Vec::with_capacity(frames * (joints - 1) * 3);
        for t in 0..frames {
            let row = &features[t * joints * D..(t + 1) * joints * D];
            let root_y = row[1] as f64;
            for j in 1..joints {
                let f = &row[j * D..j * D + 3];
                values.extend([f[0] as f64, f[1] as f64 - root_y, f[2] as f64]);
            }
        }
        PointClip::new(frames, (joints - 1) * 3, values)
    }

    /// The reference's features from world positions, with the default [`PointFeatures`]
    /// (world axes, scale from the clip's own bones).
    pub fn from_clip(clip: &WorldClip) -> Result<PointClip, MetricError> {
        PointClip::from_clip_with(clip, &PointFeatures::default())
    }

    /// The reference's features from world positions: for every frame and every joint but
    /// joint 0 (the root), `s · r_t · (p_j − p_root)`, with r_t the yaw turning frame t to
    /// face +Z (identity without a facing rule; a degenerate frame keeps the previous yaw)
    /// and `s` the scale to AnyTop units. This equals the reference's RIC position with the
    /// root height subtracted.
    pub fn from_clip_with(clip: &WorldClip, features: &PointFeatures) -> Result<PointClip, MetricError> {
        if clip.positions.len() != clip.frames * clip.joints {
            return Err(MetricError::Mismatch(format!("clip: {} positions for {} frames × {} joints", clip.positions.len(), clip.frames, clip.joints)));
        }
        if let Some((f, j)) = clip.first_non_finite() {
            return Err(MetricError::NonFinite(format!("clip: frame {f} joint {j} has a non-finite position")));
        }
        if clip.joints < 2 {
            return Err(MetricError::TooLittle(format!("clip: {} joint(s); the metrics use the non-root joints", clip.joints)));
        }
        if let Some(facing) = &features.facing {
            if let Some(&bad) = facing.joints().iter().find(|&&j| j >= clip.joints) {
                return Err(MetricError::Mismatch(format!("facing joint {bad} is outside the clip's {} joints", clip.joints)));
            }
        }
        let scale = match features.scale {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => return Err(MetricError::Mismatch(format!("point features: scale {s} is not a positive number"))),
            None if clip.frames == 0 => 1.0,
            None => {
                let p = clip.frame(0);
                let bones: Vec<f64> =
                    (0..clip.joints).filter_map(|j| clip.parents.get(j).copied().flatten().filter(|&q| q < clip.joints).map(|q| p[j].distance(p[q]))).collect();
                let mean = bones.iter().sum::<f64>() / bones.len().max(1) as f64;
                if !(mean > 0.0 && mean.is_finite()) {
                    return Err(MetricError::TooLittle("clip: frame 0 has no bone of non-zero length to scale by (pass a scale)".to_string()));
                }
                HUMANML_MEAN_BONE_LENGTH / mean
            }
        };
        let points = clip.joints - 1;
        let mut values = Vec::with_capacity(clip.frames * points * 3);
        let mut yaw = DQuat::IDENTITY;
        for t in 0..clip.frames {
            let p = clip.frame(t);
            if let Some(forward) = features.facing.as_ref().and_then(|f| f.forward(p)) {
                yaw = DQuat::from_rotation_y(-forward.x.atan2(forward.z));
            }
            let root = p[0];
            for q in &p[1..] {
                let v: DVec3 = yaw * (*q - root) * scale;
                values.extend([v.x, v.y, v.z]);
            }
        }
        PointClip::new(clip.frames, points * 3, values)
    }

    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Values per frame (3 × points).
    pub fn dims(&self) -> usize {
        self.dims
    }

    pub fn points(&self) -> usize {
        self.dims / 3
    }

    /// The values of frame `f`.
    pub fn frame(&self, f: usize) -> &[f64] {
        &self.values[f * self.dims..(f + 1) * self.dims]
    }

    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

/// Mean Euclidean distance between corresponding points of two frames (`pos_avg_l2`).
fn frame_distance(a: &[f64], b: &[f64]) -> f64 {
    let points = a.len() / 3;
    let mut sum = 0.0;
    for (p, q) in a.chunks_exact(3).zip(b.chunks_exact(3)) {
        let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
        sum += (dx * dx + dy * dy + dz * dz).sqrt();
    }
    sum / points.max(1) as f64
}

/// A clip's frames in planar layout: per frame all x, then all y, then all z, so that
/// [`planar_distance`] runs over contiguous lanes.
fn planar(c: &PointClip) -> Vec<f64> {
    let points = c.points();
    let mut out = vec![0.0; c.values.len()];
    for (src, dst) in c.values.chunks_exact(c.dims).zip(out.chunks_exact_mut(c.dims)) {
        for (p, xyz) in src.chunks_exact(3).enumerate() {
            dst[p] = xyz[0];
            dst[points + p] = xyz[1];
            dst[2 * points + p] = xyz[2];
        }
    }
    out
}

/// [`frame_distance`] of two planar frames, summed in four interleaved lanes (a fixed order,
/// so results do not depend on the machine, and one the compiler can vectorise).
fn planar_distance(a: &[f64], b: &[f64], points: usize) -> f64 {
    let (ax, ayz) = a.split_at(points);
    let (ay, az) = ayz.split_at(points);
    let (bx, byz) = b.split_at(points);
    let (by, bz) = byz.split_at(points);
    let mut lanes = [0.0f64; 4];
    let whole = points / 4 * 4;
    for base in (0..whole).step_by(4) {
        for (l, lane) in lanes.iter_mut().enumerate() {
            let i = base + l;
            let (dx, dy, dz) = (ax[i] - bx[i], ay[i] - by[i], az[i] - bz[i]);
            *lane += (dx * dx + dy * dy + dz * dz).sqrt();
        }
    }
    for i in whole..points {
        let (dx, dy, dz) = (ax[i] - bx[i], ay[i] - by[i], az[i] - bz[i]);
        lanes[i - whole] += (dx * dx + dy * dy + dz * dz).sqrt();
    }
    ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) / points.max(1) as f64
}

/// Mean frame distance over the first `min(len)` frames (`avg_per_frame_dist`, loc norm).
fn average_frame_distance(a: &PointClip, a0: usize, b: &PointClip, b0: usize, len: usize) -> f64 {
    let total: f64 = (0..len).map(|t| frame_distance(a.frame(a0 + t), b.frame(b0 + t))).sum();
    total / len.max(1) as f64
}

/// The reference's protocol constants (`eval_truebones.py`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct GenerationOptions {
    /// Window length (frames) for coverage, local diversity and intra diversity: 15.
    pub window: usize,
    /// Coverage: a GT window is covered when its nearest generated window is closer than
    /// this (mean point distance, scaled units). The reference writes `radians(20)` (its
    /// rotation mode's 20°) and uses the same number in position mode: 0.3490658503988659.
    pub threshold: f64,
    /// Global diversity: shortest piece of the DP tiling: 30 frames.
    pub min_segment: usize,
    /// Coverage repetitions (random subsets of generated samples): 10.
    pub reps: usize,
    /// Random window pairs per GT clip for the GT intra diversity: 10.
    pub gt_pairs: usize,
    /// GT clips shorter than this are left out (the reference keeps clips of more than 20
    /// frames): 21.
    pub gt_min_frames: usize,
    /// Generated samples per coverage subset; `None`: GT frames / generated frames per sample
    /// + 1 (the reference's `n_gt_frames // 120 + 1`), at most the number of samples.
    pub coverage_subset: Option<usize>,
    /// Seed of every random draw (the reference evaluates with seed 10).
    pub seed: u64,
}

impl Default for GenerationOptions {
    fn default() -> Self {
        GenerationOptions {
            window: 15,
            threshold: 20f64.to_radians(),
            min_segment: 30,
            reps: 10,
            gt_pairs: 10,
            gt_min_frames: 21,
            coverage_subset: None,
            seed: 10,
        }
    }
}

/// Mean and population standard deviation (numpy's `np.std`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct MeanStd {
    pub mean: f64,
    pub std: f64,
}

impl MeanStd {
    /// Of `values` in order; `{0, 0}` for none.
    pub fn of(values: &[f64]) -> MeanStd {
        if values.is_empty() {
            return MeanStd::default();
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
        MeanStd { mean, std: var.sqrt() }
    }
}

/// The metrics of one skeleton's generated samples against its GT clips.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GenerationReport {
    /// Percent of GT windows reproduced by generated windows; over coverage repetitions.
    pub coverage: MeanStd,
    /// Mean distance of generated windows to their nearest GT window; over samples.
    pub local_diversity: MeanStd,
    /// Mean per-frame cost of the best tiling of a sample by pieces of one GT clip (the best
    /// clip); over samples.
    pub global_diversity: MeanStd,
    /// Distance between consecutive samples (cyclic); over samples.
    pub inter_diversity: MeanStd,
    /// Distance between two random windows of a sample; over samples.
    pub intra_diversity: MeanStd,
    /// The same for GT clips (`gt_pairs` per clip); over all pairs.
    pub gt_intra_diversity: MeanStd,
    /// |intra diversity of a sample − mean GT intra diversity|; over samples.
    pub intra_diversity_diff: MeanStd,
    /// Generated samples and GT clips used, GT clips left out for being short.
    pub generated: usize,
    pub gt: usize,
    pub gt_dropped: usize,
    /// Samples per coverage subset.
    pub coverage_subset: usize,
    /// Where the input departs from the reference's protocol (the numbers are still defined).
    pub warnings: Vec<String>,
}

/// The paper's table row: per metric, the mean and std over skeletons of the per-skeleton
/// means.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct GenerationAggregate {
    pub skeletons: usize,
    pub coverage: MeanStd,
    pub local_diversity: MeanStd,
    pub global_diversity: MeanStd,
    pub inter_diversity: MeanStd,
    pub intra_diversity: MeanStd,
    pub gt_intra_diversity: MeanStd,
    pub intra_diversity_diff: MeanStd,
}

/// Mean ± std over skeletons of each metric's per-skeleton mean (the reference's FINAL row).
/// No reports give zeros.
pub fn aggregate(reports: &[GenerationReport]) -> GenerationAggregate {
    let over = |f: fn(&GenerationReport) -> MeanStd| MeanStd::of(&reports.iter().map(|r| f(r).mean).collect::<Vec<_>>());
    GenerationAggregate {
        skeletons: reports.len(),
        coverage: over(|r| r.coverage),
        local_diversity: over(|r| r.local_diversity),
        global_diversity: over(|r| r.global_diversity),
        inter_diversity: over(|r| r.inter_diversity),
        intra_diversity: over(|r| r.intra_diversity),
        gt_intra_diversity: over(|r| r.gt_intra_diversity),
        intra_diversity_diff: over(|r| r.intra_diversity_diff),
    }
}

/// AnyTop's generation metrics of `generated` samples against `gt` clips of one skeleton.
///
/// Errors: no samples or no GT clip long enough (`TooLittle`), clips with different point
/// counts (`Mismatch`), a sample not longer than the window, or one that no GT clip can tile
/// with pieces of at least `min_segment` frames (`TooLittle`, naming it).
pub fn generation_metrics(generated: &[PointClip], gt: &[PointClip], opts: &GenerationOptions) -> Result<GenerationReport, MetricError> {
    let w = opts.window;
    if w == 0 || opts.min_segment == 0 || opts.reps == 0 || opts.gt_pairs == 0 {
        return Err(MetricError::Mismatch(format!(
            "generation metrics: window ({w}), min_segment ({}), reps ({}) and gt_pairs ({}) must all be at least 1",
            opts.min_segment, opts.reps, opts.gt_pairs
        )));
    }
    if !opts.threshold.is_finite() {
        return Err(MetricError::NonFinite(format!("generation metrics: coverage threshold is {}", opts.threshold)));
    }
    let Some(first) = generated.first() else {
        return Err(MetricError::TooLittle("generation metrics: no generated samples".into()));
    };
    let dims = first.dims;
    for (what, set) in [("generated sample", generated), ("GT clip", gt)] {
        if let Some((i, c)) = set.iter().enumerate().find(|(_, c)| c.dims != dims) {
            return Err(MetricError::Mismatch(format!(
                "generation metrics: {what} {i} has {} points per frame, generated sample 0 has {}",
                c.points(),
                dims / 3
            )));
        }
    }
    if let Some((i, c)) = generated.iter().enumerate().find(|(_, c)| c.frames <= w) {
        return Err(MetricError::TooLittle(format!(
            "generation metrics: generated sample {i} has {} frames; windows of {w} need at least {}",
            c.frames,
            w + 1
        )));
    }
    let mut warnings = Vec::new();
    let kept: Vec<&PointClip> = gt.iter().filter(|c| c.frames >= opts.gt_min_frames && c.frames > w).collect();
    let gt_dropped = gt.len() - kept.len();
    if gt_dropped > 0 {
        warnings.push(format!("{gt_dropped} GT clip(s) left out for having fewer than {} frames", opts.gt_min_frames.max(w + 1)));
    }
    if kept.is_empty() {
        return Err(MetricError::TooLittle(format!(
            "generation metrics: no GT clip has at least {} frames (of {} given)",
            opts.gt_min_frames.max(w + 1),
            gt.len()
        )));
    }
    let gen_frames: usize = generated.iter().map(|c| c.frames).sum();
    let gt_frames: usize = kept.iter().map(|c| c.frames).sum();
    if generated.iter().any(|c| c.frames != first.frames) {
        warnings.push("generated samples differ in length (the reference requires 120 frames each)".into());
    }
    if gen_frames < 2 * gt_frames {
        warnings.push(format!("generated frames ({gen_frames}) are fewer than twice the GT frames ({gt_frames}); the reference asserts at least twice"));
    }
    let per_sample = (gen_frames / generated.len()).max(1);
    let wanted_subset = opts.coverage_subset.unwrap_or(gt_frames / per_sample + 1).max(1);
    let subset = wanted_subset.min(generated.len());
    if subset < wanted_subset {
        warnings.push(format!("coverage subsets hold all {subset} samples instead of {wanted_subset}"));
    }

    // Every random draw, in a fixed order: GT window pairs, sample window pairs, subsets.
    let mut rng = SplitMix64::new(opts.seed);
    let gt_offsets: Vec<Vec<(usize, usize)>> =
        kept.iter().map(|c| (0..opts.gt_pairs).map(|_| (rng.below(c.frames - w), rng.below(c.frames - w))).collect()).collect();
    let gen_offsets: Vec<(usize, usize)> = generated.iter().map(|c| (rng.below(c.frames - w), rng.below(c.frames - w))).collect();
    let subsets: Vec<Vec<usize>> = (0..opts.reps)
        .map(|_| {
            let mut idx: Vec<usize> = (0..generated.len()).collect();
            for i in 0..subset {
                let j = i + rng.below(idx.len() - i);
                idx.swap(i, j);
            }
            idx.truncate(subset);
            idx
        })
        .collect();

    // GT frames, concatenated (in the planar layout of `planar`), and where each clip starts.
    let points = dims / 3;
    let mut gt_starts = Vec::with_capacity(kept.len());
    let mut gt_all = Vec::with_capacity(gt_frames * dims);
    for c in &kept {
        gt_starts.push(gt_all.len() / dims);
        gt_all.extend(planar(c));
    }

    // cost[i][a * gt_frames + b]: distance of sample i's frame a to GT frame b. Shared by
    // local and global diversity and coverage.
    let cost: Vec<Vec<f64>> = generated
        .par_iter()
        .map(|c| {
            let frames = planar(c);
            let mut m = vec![0.0; c.frames * gt_frames];
            m.par_chunks_mut(gt_frames).enumerate().for_each(|(a, row)| {
                let fa = &frames[a * dims..(a + 1) * dims];
                for (out, fb) in row.iter_mut().zip(gt_all.chunks_exact(dims)) {
                    *out = planar_distance(fa, fb, points);
                }
            });
            m
        })
        .collect();

    // Window sums shared by local diversity and coverage: sums[i][k * gt_starts_all + g] =
    // Σ_{t<w} cost_i[k + t][g + t] for every window start k of sample i (0..=L − w) and g of
    // the GT concatenation (0..=T − w), summed in t order as GANimator's kernel does.
    let gt_starts_all = gt_frames - w + 1;
    let sums: Vec<Vec<f64>> = generated
        .par_iter()
        .enumerate()
        .map(|(i, c)| {
            let mut out = vec![0.0; (c.frames - w + 1) * gt_starts_all];
            out.par_chunks_mut(gt_starts_all).enumerate().for_each(|(k, acc)| {
                for t in 0..w {
                    let at = (k + t) * gt_frames + t;
                    for (a, v) in acc.iter_mut().zip(&cost[i][at..at + gt_starts_all]) {
                        *a += v;
                    }
                }
            });
            out
        })
        .collect();

    // Per sample: local diversity, global diversity (best GT clip), intra diversity.
    let per_sample: Vec<Result<(f64, f64), MetricError>> = generated
        .par_iter()
        .enumerate()
        .map(|(i, c)| {
            let m = &cost[i];
            // Starts 0..L − w (the reference leaves the last one out).
            let windows = sums[i].chunks_exact(gt_starts_all).take(c.frames - w);
            let local = windows.map(|row| row.iter().copied().fold(f64::INFINITY, f64::min)).sum::<f64>() / (c.frames - w) as f64 / w as f64;
            let mut best = f64::INFINITY;
            for (k, g) in kept.iter().enumerate() {
                best = best.min(tiling_cost(m, gt_frames, c.frames, gt_starts[k], g.frames, opts.min_segment));
            }
            if !best.is_finite() {
                return Err(MetricError::TooLittle(format!(
                    "global diversity: no GT clip tiles generated sample {i} ({} frames) with pieces of {} to the clip's length",
                    c.frames, opts.min_segment
                )));
            }
            Ok((local, best / c.frames as f64))
        })
        .collect();
    let mut local = Vec::with_capacity(generated.len());
    let mut global = Vec::with_capacity(generated.len());
    for r in per_sample {
        let (l, g) = r?;
        local.push(l);
        global.push(g);
    }

    let n = generated.len();
    let inter: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (&generated[i], &generated[(i + n - 1) % n]);
            average_frame_distance(a, 0, b, 0, a.frames.min(b.frames))
        })
        .collect();
    let intra: Vec<f64> = generated.iter().zip(&gen_offsets).map(|(c, &(a, b))| average_frame_distance(c, a, c, b, w)).collect();
    let gt_intra: Vec<f64> =
        kept.iter().zip(&gt_offsets).flat_map(|(c, pairs)| pairs.iter().map(move |&(a, b)| average_frame_distance(c, a, c, b, w))).collect();
    let gt_intra_stats = MeanStd::of(&gt_intra);
    let diff: Vec<f64> = intra.iter().map(|v| (v - gt_intra_stats.mean).abs()).collect();

    // Coverage: GT windows against the concatenated subset, per repetition. A target window
    // lies inside one sample (its sums are above; their minimum over the sample's starts is
    // taken once) or straddles two consecutive samples of the subset (summed here). A minimum
    // does not depend on the order it is taken in.
    let sample_minima: Vec<Vec<f64>> = sums
        .par_iter()
        .map(|s| {
            let mut least = vec![f64::INFINITY; gt_starts_all];
            for row in s.chunks_exact(gt_starts_all) {
                for (b, v) in least.iter_mut().zip(row) {
                    *b = b.min(*v);
                }
            }
            least
        })
        .collect();
    let coverages: Vec<f64> = subsets
        .iter()
        .map(|subset| {
            let mut best = vec![f64::INFINITY; gt_starts_all];
            for &s in subset {
                for (b, v) in best.iter_mut().zip(&sample_minima[s]) {
                    *b = b.min(*v);
                }
            }
            let straddling: Vec<Vec<f64>> = subset
                .windows(2)
                .flat_map(|pair| (1..w).map(move |j| (pair[0], pair[1], j)))
                .collect::<Vec<_>>()
                .par_iter()
                .map(|&(first, second, j)| {
                    // The last j frames of `first`, then the first w − j of `second`.
                    let lead = generated[first].frames - j;
                    let mut acc = vec![0.0; gt_starts_all];
                    for t in 0..w {
                        let at = if t < j { (lead + t) * gt_frames + t } else { (t - j) * gt_frames + t };
                        let m = if t < j { &cost[first] } else { &cost[second] };
                        for (a, v) in acc.iter_mut().zip(&m[at..at + gt_starts_all]) {
                            *a += v;
                        }
                    }
                    acc
                })
                .collect();
            for acc in &straddling {
                for (b, v) in best.iter_mut().zip(acc) {
                    *b = b.min(*v);
                }
            }
            let mut covered = 0usize;
            let mut total = 0usize;
            for (k, g) in kept.iter().enumerate() {
                // Starts 0..L − w, as the reference counts them (its last start is left out).
                let starts = &best[gt_starts[k]..gt_starts[k] + g.frames - w];
                covered += starts.iter().filter(|&&v| v / (w as f64) < opts.threshold).count();
                total += starts.len();
            }
            covered as f64 / total as f64 * 100.0
        })
        .collect();

    Ok(GenerationReport {
        coverage: MeanStd::of(&coverages),
        local_diversity: MeanStd::of(&local),
        global_diversity: MeanStd::of(&global),
        inter_diversity: MeanStd::of(&inter),
        intra_diversity: MeanStd::of(&intra),
        gt_intra_diversity: gt_intra_stats,
        intra_diversity_diff: MeanStd::of(&diff),
        generated: n,
        gt: kept.len(),
        gt_dropped,
        coverage_subset: subset,
        warnings,
    })
}

/// GANimator's `nn_dp`: the least total cost of cutting a `len`-frame source (rows of `m`)
/// into consecutive pieces of at least `min_segment` frames, each matched to an equally long
/// run of target columns `c0..c0 + width`; infinite when no such tiling exists.
fn tiling_cost(m: &[f64], cols: usize, len: usize, c0: usize, width: usize, min_segment: usize) -> f64 {
    // g[e]: cheapest tiling of frames [0, e). Pieces [l, l + s) only feed g[l + s] with
    // s ≥ min_segment, so g[l] is final when l is reached and the pieces starting there can be
    // pushed forward at once: no table of piece costs is kept. Each piece's cost comes from
    // running sums over its diagonals, grown one frame at a time.
    let mut g = vec![f64::INFINITY; len + 1];
    g[0] = 0.0;
    let mut acc = vec![0.0; width];
    for l in 0..len {
        let longest = (len - l).min(width);
        if longest < min_segment || !g[l].is_finite() {
            continue;
        }
        acc.iter_mut().for_each(|a| *a = 0.0);
        for s in 1..=longest {
            // Extend every diagonal starting at target offset k by frame l + s − 1.
            let t = s - 1;
            let offsets = width - s + 1;
            let row = &m[(l + t) * cols + c0 + t..(l + t) * cols + c0 + t + offsets];
            let mut least = f64::INFINITY;
            for (a, v) in acc[..offsets].iter_mut().zip(row) {
                *a += v;
                least = least.min(*a);
            }
            if s >= min_segment {
                let v = g[l] + least;
                if v < g[l + s] {
                    g[l + s] = v;
                }
            }
        }
    }
    g[len]
}

#[cfg(test)]
#[path = "generation_tests.rs"]
mod tests;
