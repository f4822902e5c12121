//! Does a generated motion move like the clips? Metrics that tell a statue from a walk.
//!
//! AnyTop's coverage at its fixed threshold (0.349 in its scaled units) scores 100% for a
//! model that only stands on our zoo skeletons, so it cannot say whether a sample moves. These
//! measure what it misses, each per skeleton and always next to baselines built from the same
//! clips (`mo-metrics generation` reports them; definitions in docs/metrics.md):
//!
//! * motion energy: the mean speed of the joints relative to the root, in body sizes per
//!   second, after a 5-frame moving average so that jitter does not count; and its ratio to
//!   the clips' energy;
//! * nearest-pose distance: for each frame, the distance to the closest frame of the clips on
//!   pairwise joint distances over the body size (independent of where the creature stands
//!   and which way it faces); a tangled or crumpled pose is far from every real one;
//! * calibrated coverage: AnyTop's window coverage with thresholds read from the clips
//!   themselves: a clip window counts as covered when some window of the motions comes as
//!   close to it as the nearest window of the other clips does (never closer than the median
//!   of those distances is asked for). So the clips, each left out in turn, cover 100%, and a
//!   statue covers only windows that are themselves about still;
//! * foot contact: duty factor (the share of frames a foot is down) and the share of frames
//!   in which some feet are down and others up (0 for a statue and for a hopping bird, high
//!   for a walk);
//! * alternation: how much of the feet's horizontal motion (root-relative, in the creature's
//!   facing frame) is opposed rather than shared. A walk swings left against right, so about
//!   0.6-0.8; feet that all swing together score near 0, feet a quarter cycle apart 0.5.
//!   Mixed contact cannot see this: feet lifted together at odd times still give some up and
//!   some down.
//!
//! * footfall error: how far the feet's phases against each other lie from the nearest
//!   stretch of the clips (`footfall`), next to the level of feet phased at random.
//! * swing: whether feet are lifted while they move with the body's travel (+1, as in every
//!   walk) or against it (-1: the legs' cycle played backwards under a body that goes
//!   forwards, a moonwalk). A model that has not learnt which way time runs makes such legs,
//!   with every pose right.
//!
//! Every loop over frames or windows is bounded by caps on the reference frames and windows
//! (strided evenly), so a 15,000-frame capture scores in seconds; every result is the same at
//! any thread count (parallel loops fill per-item slots, reductions run in order).

use super::footfall::{self, Footfalls};
use super::generation::PointClip;
use super::physics::{contacts, Ground, PhysicsOptions};
use super::{MetricError, WorldClip};
use crate::rng::SplitMix64;
use glam::DVec3;
use rayon::prelude::*;

/// Settings of the movement metrics.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MovementOptions {
    /// Frames of the moving average before speeds are taken (jitter does not count): 5.
    pub smooth_frames: usize,
    /// Window length of the calibrated coverage, in frames (AnyTop's 15).
    pub window: usize,
    /// At most this many reference frames in the nearest-pose search (evenly strided).
    pub max_reference_frames: usize,
    /// At most this many windows on either side of a window search (evenly strided).
    pub max_windows: usize,
    /// Contact thresholds (fractions of the body size), as `mo-metrics physics`, with the
    /// ground estimated from the motion: a creature whose feet never reach y = 0 (the zoo's
    /// spider stands on its foot tips' end sites, above its foot joints) still steps.
    pub contact: PhysicsOptions,
}

impl Default for MovementOptions {
    fn default() -> Self {
        MovementOptions {
            smooth_frames: 5,
            window: 15,
            max_reference_frames: 4000,
            max_windows: 2000,
            contact: PhysicsOptions { ground: Ground::Estimate, ..PhysicsOptions::default() },
        }
    }
}

/// Movement of one set of motions (samples, or a baseline) against one skeleton's clips.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Movement {
    /// Mean motion energy over the motions, in body sizes per second.
    pub energy: f64,
    /// `energy` over the clips' mean energy.
    pub energy_ratio: f64,
    /// Smallest and largest ratio of one motion.
    pub energy_ratio_range: (f64, f64),
    /// Mean over all frames of the distance to the nearest clip frame (pairwise joint
    /// distances over the body size, mean absolute difference).
    pub nearest_pose: f64,
    /// Percent of the clips' windows that a window of these motions comes as close to as the
    /// other clips do (its calibrated threshold).
    pub calibrated_coverage: f64,
    /// The same per clip, in the clips' order: which of them the motions cover (`None` for a
    /// clip left out of the comparison, or with no window).
    pub calibrated_coverage_by_clip: Vec<Option<f64>>,
    /// Mean share of frames a foot is in contact, over feet and motions (`None`: no feet).
    pub duty_factor: Option<f64>,
    /// Share of frames with some feet down and some up, mean over motions (`None`: fewer
    /// than two feet).
    pub mixed_contact: Option<f64>,
    /// Share of the feet's horizontal motion that is opposed rather than shared (`alternation`),
    /// pooled over the motions by how long and how much their feet move (`None`: fewer than
    /// two feet, or no motion moves them).
    pub alternation: Option<f64>,
    /// Mean circular distance (cycles, 0-0.5) of the feet's relative phases to the nearest
    /// clip stretch's (`footfall`; `None`: no stretch of these motions or of the clips has two
    /// feet swinging).
    pub footfall_error: Option<f64>,
    /// From -1 to 1: whether lifted feet move with the root's travel or against it, pooled
    /// over the motions (`swing`; `None`: no feet, or the root does not travel).
    pub swing: Option<f64>,
}

/// A skeleton's clips, prepared once: world clips for energy, contact and poses, AnyTop point
/// clips for windows, and the calibrated threshold.
pub struct Reference<'a> {
    clips: &'a [WorldClip],
    points: &'a [PointClip],
    energy: f64,
    /// Pose descriptors of the (strided) reference frames, and which clip each came from.
    poses: Vec<(usize, Vec<f64>)>,
    /// The clip windows coverage is judged on, (clip, start), and each one's threshold: its
    /// distance to the nearest window of the other clips, at least `threshold`.
    targets: Vec<(usize, usize)>,
    thresholds: Vec<f64>,
    /// Windows with a window of another clip at a finite distance: those the other clips
    /// cover, since each threshold is at least that distance.
    covered_by_others: Vec<bool>,
    footfalls: Footfalls,
    /// The median of the clip windows' nearest-window distances, in the point clips' units:
    /// the smallest threshold asked for (zoo clips repeat one another exactly, and a sample
    /// need not be closer to them than the clips typically are to each other).
    pub threshold: f64,
    opts: MovementOptions,
}

/// Pairwise distances between all joints of one frame over `size`, upper triangle in order.
fn pose_descriptor(frame: &[DVec3], size: f64) -> Vec<f64> {
    let n = frame.len();
    let mut out = Vec::with_capacity(n * n.saturating_sub(1) / 2);
    for a in 0..n {
        for b in a + 1..n {
            out.push(frame[a].distance(frame[b]) / size);
        }
    }
    out
}

fn descriptor_distance(a: &[f64], b: &[f64]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum();
    sum / a.len().max(1) as f64
}

/// Mean speed of the joints relative to the root (joint 0, which counts as a still joint),
/// in sizes per second, after a `smooth`-frame moving average. 0 for clips too short to move.
pub fn energy(clip: &WorldClip, smooth: usize) -> f64 {
    let k = smooth.max(1);
    let (frames, joints) = (clip.frames, clip.joints);
    if frames < k + 1 || joints == 0 || !(clip.scale > 0.0) || !clip.fps.is_finite() {
        return 0.0;
    }
    let rel = |f: usize, j: usize| clip.at(f, j) - clip.at(f, 0);
    let averaged: Vec<DVec3> =
        (0..=frames - k).flat_map(|f| (0..joints).map(move |j| (f, j))).map(|(f, j)| (0..k).map(|t| rel(f + t, j)).sum::<DVec3>() / k as f64).collect();
    let steps = frames - k;
    let mut total = 0.0;
    for f in 0..steps {
        for j in 0..joints {
            total += averaged[(f + 1) * joints + j].distance(averaged[f * joints + j]);
        }
    }
    total / (steps * joints) as f64 / clip.scale * clip.fps
}

/// Foot-contact statistics of one clip: (duty factor, mixed-contact share), `None` where the
/// skeleton has no feet (or fewer than two, for the second).
pub fn contact_stats(clip: &WorldClip, opts: &PhysicsOptions) -> (Option<f64>, Option<f64>) {
    if clip.feet.is_empty() || clip.frames == 0 {
        return (None, None);
    }
    let rows = contacts(clip, opts);
    let down: usize = rows.iter().map(|r| r.iter().filter(|&&c| c).count()).sum();
    let duty = down as f64 / (rows.len() * clip.frames) as f64;
    if rows.len() < 2 {
        return (Some(duty), None);
    }
    let mixed = (0..clip.frames).filter(|&f| {
        let n = rows.iter().filter(|r| r[f]).count();
        n > 0 && n < rows.len()
    });
    (Some(duty), Some(mixed.count() as f64 / clip.frames as f64))
}

/// Share of the feet's horizontal motion that is opposed rather than shared. For a pair of feet
/// (a, b), with q the feet's horizontal (x, z) point-clip positions (root-relative, in the
/// facing frame for AnyTop features), D = the RMS over frames of (q_a - q_b) about its mean and
/// S = the same of (q_a + q_b). Each foot is paired with the foot it swings most against
/// (largest D / (D + S)): in a walk that is its mate on the other side, and the front-hind and
/// diagonal pairs, a quarter cycle apart, would only dilute the number. The result is ΣD /
/// Σ(D + S) over those pairs: 1 when every foot swings against a partner, 0 when all feet
/// swing together, 0.5 for feet a quarter cycle apart. `feet` are joint indices; the point
/// clip holds joints 1.. (the root is not a point). `None` with fewer than two feet inside the
/// clip or when the feet do not move.
pub fn alternation(points: &PointClip, feet: &[usize]) -> Option<f64> {
    alternation_parts(points, feet).map(|(opposed, total)| opposed / total)
}

/// ΣD and Σ(D + S) of `alternation`, each times the frames, so that several motions pool by
/// how long and how much their feet move (an idle clip's feet, which barely sway together,
/// then count for little); `None` where `alternation` is.
fn alternation_parts(points: &PointClip, feet: &[usize]) -> Option<(f64, f64)> {
    let idx: Vec<usize> = feet.iter().filter(|&&j| j >= 1 && j <= points.points()).map(|&j| j - 1).collect();
    let frames = points.frames();
    if idx.len() < 2 || frames < 2 {
        return None;
    }
    // Each foot's horizontal path about its own mean: the mean of q_a ± q_b is then removed
    // already, so D and S are plain RMS values of sums and differences.
    let centred: Vec<Vec<[f64; 2]>> = idx
        .iter()
        .map(|&p| {
            let path: Vec<[f64; 2]> = (0..frames).map(|f| [points.frame(f)[3 * p], points.frame(f)[3 * p + 2]]).collect();
            let mean = path.iter().fold([0.0, 0.0], |m, v| [m[0] + v[0] / frames as f64, m[1] + v[1] / frames as f64]);
            path.iter().map(|v| [v[0] - mean[0], v[1] - mean[1]]).collect()
        })
        .collect();
    let rms = |a: &[[f64; 2]], b: &[[f64; 2]], sign: f64| {
        let sq: f64 = a.iter().zip(b).map(|(p, q)| (p[0] + sign * q[0]).powi(2) + (p[1] + sign * q[1]).powi(2)).sum();
        (sq / frames as f64).sqrt()
    };
    // D and S of every pair, then each foot's most opposed partner.
    let mut pair = vec![vec![(0.0, 0.0); idx.len()]; idx.len()];
    for i in 0..idx.len() {
        for k in i + 1..idx.len() {
            let ds = (rms(&centred[i], &centred[k], -1.0), rms(&centred[i], &centred[k], 1.0));
            pair[i][k] = ds;
            pair[k][i] = ds;
        }
    }
    let (mut opposed, mut total) = (0.0, 0.0);
    for (i, row) in pair.iter().enumerate() {
        let share = |&(d, s): &(f64, f64)| if d + s > 0.0 { d / (d + s) } else { -1.0 };
        let best = row.iter().enumerate().filter(|&(k, _)| k != i).map(|(_, p)| p).max_by(|p, q| share(p).total_cmp(&share(q)));
        if let Some(&(d, s)) = best {
            opposed += d;
            total += d + s;
        }
    }
    // Below a millionth of a mean bone (0.209 in AnyTop units) the feet stand still.
    (total > 1e-6).then_some((opposed * frames as f64, total * frames as f64))
}

/// Whether a motion's feet are lifted while they move with the root's travel (+1) or against
/// it (-1). Over each step from one frame to the next in which the root travels horizontally
/// at least 5% of the body size per second, and each foot (not the root): h = the foot's height
/// above its lowest in the motion, v = its horizontal displacement relative to the root along
/// the root's direction of travel in that step. The result is Σ h·v / Σ h·|v|. A walk lifts a
/// foot to carry it forward and pushes back while it is down, so it scores near 1; its legs
/// played backwards under a root that goes forwards score near -1, and feet that swing
/// forwards and backwards alike while lifted near 0. `None` without feet, or when the root
/// does not travel (an idle clip) or no foot moves.
pub fn swing(clip: &WorldClip) -> Option<f64> {
    swing_parts(clip).map(|(with, all)| with / all)
}

/// Σ h·v and Σ h·|v| of `swing`, so that several motions pool by how far and how long their
/// feet swing; `None` where `swing` is.
fn swing_parts(clip: &WorldClip) -> Option<(f64, f64)> {
    let (frames, joints) = (clip.frames, clip.joints);
    let feet: Vec<usize> = clip.feet.iter().copied().filter(|&j| j > 0 && j < joints).collect();
    if feet.is_empty() || frames < 2 || !(clip.scale > 0.0) || !(clip.fps > 0.0) || clip.positions.len() < frames * joints {
        return None;
    }
    let min_step = 0.05 * clip.scale / clip.fps;
    let lowest: Vec<f64> = feet.iter().map(|&j| (0..frames).map(|f| clip.at(f, j).y).fold(f64::INFINITY, f64::min)).collect();
    let (mut with, mut all) = (0.0, 0.0);
    for f in 0..frames - 1 {
        let (r0, r1) = (clip.at(f, 0), clip.at(f + 1, 0));
        let travel = glam::DVec2::new(r1.x - r0.x, r1.z - r0.z);
        // `!(>=)` also skips a NaN step.
        if !(travel.length() >= min_step) {
            continue;
        }
        let along = travel.normalize();
        for (&j, low) in feet.iter().zip(&lowest) {
            let moved = (clip.at(f + 1, j) - r1) - (clip.at(f, j) - r0);
            let v = moved.x * along.x + moved.z * along.y;
            let h = 0.5 * (clip.at(f, j).y + clip.at(f + 1, j).y) - low;
            with += h * v;
            all += h * v.abs();
        }
    }
    (all.is_finite() && all > 1e-12 * clip.scale * clip.scale).then_some((with, all))
}

/// One clip's part of the clips' baseline: nearest pose against the other clips, duty factor,
/// mixed contact, alternation's parts.
type ClipParts = (f64, Option<f64>, Option<f64>, Option<(f64, f64)>);

/// Alternation (or swing) over several motions: their `alternation_parts` (`swing_parts`)
/// pooled, the first sums over the second.
fn pooled(parts: &[(f64, f64)]) -> Option<f64> {
    let (opposed, total) = parts.iter().fold((0.0, 0.0), |(o, t), p| (o + p.0, t + p.1));
    (!parts.is_empty()).then(|| opposed / total)
}

/// Every `stride`-th item so that at most `cap` remain (all when there are fewer).
fn stride_for(total: usize, cap: usize) -> usize {
    total.div_ceil(cap.max(1)).max(1)
}

/// Window starts (clip, start) of `clips` for windows of `w` frames, evenly strided to at most
/// `cap`.
fn windows(clips: &[PointClip], w: usize, cap: usize) -> Vec<(usize, usize)> {
    let all: Vec<(usize, usize)> = clips.iter().enumerate().flat_map(|(c, p)| (0..(p.frames() + 1).saturating_sub(w)).map(move |s| (c, s))).collect();
    let stride = stride_for(all.len(), cap);
    all.into_iter().step_by(stride).collect()
}

fn window_distance(a: &PointClip, a0: usize, b: &PointClip, b0: usize, w: usize) -> f64 {
    let points = a.points().max(1) as f64;
    let mut total = 0.0;
    for t in 0..w {
        let (fa, fb) = (a.frame(a0 + t), b.frame(b0 + t));
        let mut sum = 0.0;
        for (p, q) in fa.chunks_exact(3).zip(fb.chunks_exact(3)) {
            let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
            sum += (dx * dx + dy * dy + dz * dz).sqrt();
        }
        total += sum / points;
    }
    total / w.max(1) as f64
}

impl<'a> Reference<'a> {
    /// Prepare one skeleton's clips: `clips` in world space and `points` the same clips as
    /// AnyTop point clips (same order). Errors when no clip is long enough for a window, or
    /// the two lists differ.
    pub fn new(clips: &'a [WorldClip], points: &'a [PointClip], opts: &MovementOptions) -> Result<Reference<'a>, MetricError> {
        if clips.len() != points.len() || clips.is_empty() {
            return Err(MetricError::Mismatch(format!("movement: {} clips and {} point clips", clips.len(), points.len())));
        }
        if opts.window == 0 || opts.smooth_frames == 0 {
            return Err(MetricError::Mismatch(format!("movement: window ({}) and smoothing ({}) must be at least 1", opts.window, opts.smooth_frames)));
        }
        let w = opts.window;
        let targets = windows(points, w, opts.max_windows);
        if targets.is_empty() {
            return Err(MetricError::TooLittle(format!("movement: no clip has the {w} frames of a window")));
        }
        let energy = clips.iter().map(|c| energy(c, opts.smooth_frames)).sum::<f64>() / clips.len() as f64;
        let total: usize = clips.iter().map(|c| c.frames).sum();
        let stride = stride_for(total, opts.max_reference_frames);
        let mut poses = Vec::new();
        let mut k = 0usize;
        for (ci, c) in clips.iter().enumerate() {
            for f in 0..c.frames {
                if k.is_multiple_of(stride) {
                    poses.push((ci, pose_descriptor(c.frame(f), c.scale)));
                }
                k += 1;
            }
        }
        // Each clip window's nearest window in the other clips (leave-one-out). With one clip,
        // the nearest window of the same clip that does not overlap it in time (a walk repeats
        // itself a cycle later). Not the same clip where there are several: the zoo's clips
        // are exactly periodic, so a window's own clip a cycle later would match perfectly.
        let single = points.len() == 1;
        let nearest: Vec<f64> = targets
            .par_iter()
            .map(|&(c, s)| {
                targets
                    .iter()
                    .filter(|&&(d, t)| if single { t.abs_diff(s) >= w } else { d != c })
                    .map(|&(d, t)| window_distance(&points[c], s, &points[d], t, w))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let mut sorted: Vec<f64> = nearest.iter().copied().filter(|d| d.is_finite()).collect();
        if sorted.is_empty() {
            return Err(MetricError::TooLittle(format!(
                "movement: the clips hold no two windows of {w} frames that do not overlap, so no coverage threshold can be read from them"
            )));
        }
        sorted.sort_by(f64::total_cmp);
        let floor = sorted[(sorted.len() - 1) / 2];
        // A window nothing else resembles (infinite distance: a one-clip skeleton's window
        // with no other far enough away) is judged at the floor.
        let thresholds = nearest.iter().map(|&d| if d.is_finite() { d.max(floor) } else { floor }).collect();
        let covered_by_others = nearest.iter().map(|d| d.is_finite()).collect();
        let footfalls = Footfalls::new(points, &clips[0].feet);
        Ok(Reference { clips, points, energy, poses, targets, thresholds, covered_by_others, footfalls, threshold: floor, opts: opts.clone() })
    }

    /// The footfall error of feet phased at random against these clips (seeded), the level
    /// of a model that learned each leg's stride but not how the legs go together; `None`
    /// when the clips have no stretch with two feet swinging.
    pub fn footfall_chance(&self, seed: u64) -> Option<f64> {
        self.footfalls.chance(seed)
    }

    /// The clips' mean energy, sizes per second.
    pub fn energy(&self) -> f64 {
        self.energy
    }

    /// Mean over the frames of `clip` of the distance to the nearest reference frame, leaving
    /// out reference frames of clip `skip` (for leave-one-out baselines).
    fn nearest_pose(&self, clip: &WorldClip, skip: Option<usize>) -> f64 {
        let frames: Vec<Vec<f64>> = (0..clip.frames).map(|f| pose_descriptor(clip.frame(f), clip.scale)).collect();
        let best: Vec<f64> = frames
            .par_iter()
            .map(|d| self.poses.iter().filter(|(c, _)| Some(*c) != skip).map(|(_, r)| descriptor_distance(d, r)).fold(f64::INFINITY, f64::min))
            .collect();
        best.iter().sum::<f64>() / best.len().max(1) as f64
    }

    /// Percent of the clips' windows (except those of clip `skip`) that some window of
    /// `motions` comes within the window's threshold of.
    /// Also the same per clip (see `by_clip`).
    fn coverage(&self, motions: &[PointClip], skip: Option<usize>) -> (f64, Vec<Option<f64>>) {
        let w = self.opts.window;
        let candidates = windows(motions, w, self.opts.max_windows);
        let covered: Vec<bool> = (0..self.targets.len())
            .into_par_iter()
            .map(|i| {
                let (c, s) = self.targets[i];
                Some(c) != skip && candidates.iter().any(|&(d, t)| window_distance(&self.points[c], s, &motions[d], t, w) <= self.thresholds[i])
            })
            .collect();
        self.by_clip(&covered, skip)
    }

    /// Percent of the judged windows (all but clip `skip`'s) that `covered` marks, overall
    /// (0 when none is judged) and per clip.
    fn by_clip(&self, covered: &[bool], skip: Option<usize>) -> (f64, Vec<Option<f64>>) {
        let percent = |of: &dyn Fn(usize) -> bool| {
            let judged: Vec<usize> = (0..self.targets.len()).filter(|&i| of(self.targets[i].0) && Some(self.targets[i].0) != skip).collect();
            (!judged.is_empty()).then(|| 100.0 * judged.iter().filter(|&&i| covered[i]).count() as f64 / judged.len() as f64)
        };
        let per_clip = (0..self.points.len()).map(|c| percent(&|d| d == c)).collect();
        (percent(&|_| true).unwrap_or(0.0), per_clip)
    }

    /// Percent of the clip windows that the other clips cover: 100 by the thresholds'
    /// construction, less any window no other clip has a window for (a one-clip skeleton's
    /// window with none far enough away); the clips' own row of the report.
    fn coverage_leave_one_out(&self) -> (f64, Vec<Option<f64>>) {
        self.by_clip(&self.covered_by_others, None)
    }

    /// Score `motions` (world clips and the same as point clips, in one order) against the
    /// clips. `skip` leaves one clip out of every comparison (the clips' own baseline).
    pub fn score(&self, motions: &[WorldClip], points: &[PointClip], skip: Option<usize>) -> Result<Movement, MetricError> {
        if motions.is_empty() || motions.len() != points.len() {
            return Err(MetricError::Mismatch(format!("movement: {} motions and {} point clips", motions.len(), points.len())));
        }
        let reference = match skip {
            Some(s) => {
                let others: Vec<f64> = self.clips.iter().enumerate().filter(|&(i, _)| i != s).map(|(_, c)| energy(c, self.opts.smooth_frames)).collect();
                if others.is_empty() {
                    self.energy
                } else {
                    others.iter().sum::<f64>() / others.len() as f64
                }
            }
            None => self.energy,
        };
        let energies: Vec<f64> = motions.iter().map(|c| energy(c, self.opts.smooth_frames)).collect();
        let mean = energies.iter().sum::<f64>() / energies.len() as f64;
        let ratio = |e: f64| if reference > 0.0 { e / reference } else { 0.0 };
        let lo = energies.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = energies.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let frames: usize = motions.iter().map(|c| c.frames).sum();
        let pose_sum: f64 = motions.iter().map(|c| self.nearest_pose(c, skip) * c.frames as f64).sum();
        let stats: Vec<(Option<f64>, Option<f64>)> = motions.iter().map(|c| contact_stats(c, &self.opts.contact)).collect();
        let alternations: Vec<(f64, f64)> = motions.iter().zip(points).filter_map(|(c, p)| alternation_parts(p, &c.feet)).collect();
        let swings: Vec<(f64, f64)> = motions.iter().filter_map(swing_parts).collect();
        let coverage = self.coverage(points, skip);
        Ok(Movement {
            energy: mean,
            energy_ratio: ratio(mean),
            energy_ratio_range: (ratio(lo), ratio(hi)),
            nearest_pose: pose_sum / frames.max(1) as f64,
            calibrated_coverage: coverage.0,
            calibrated_coverage_by_clip: coverage.1,
            duty_factor: footfall::mean(&stats.iter().filter_map(|s| s.0).collect::<Vec<f64>>()),
            mixed_contact: footfall::mean(&stats.iter().filter_map(|s| s.1).collect::<Vec<f64>>()),
            alternation: pooled(&alternations),
            footfall_error: self.footfalls.error(points, skip),
            swing: pooled(&swings),
        })
    }

    /// The clips against themselves, each left out in turn and scored against the others
    /// (frame-weighted means); with one clip, that clip against itself with its overlapping
    /// windows and own frames allowed only where they differ (its nearest poses are its own,
    /// so `nearest_pose` is 0).
    pub fn clips_baseline(&self) -> Result<Movement, MetricError> {
        if self.clips.len() == 1 {
            return self.score(self.clips, self.points, None);
        }
        // Per clip, against the others: nearest pose and contact (coverage is the whole set's,
        // from the thresholds; energy is the clips' own).
        let parts: Vec<ClipParts> = self
            .clips
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let (duty, mixed) = contact_stats(c, &self.opts.contact);
                (self.nearest_pose(c, Some(i)), duty, mixed, alternation_parts(&self.points[i], &c.feet))
            })
            .collect();
        let weights: Vec<f64> = self.clips.iter().map(|c| c.frames as f64).collect();
        let total: f64 = weights.iter().sum();
        let avg_opt = |f: &dyn Fn(&ClipParts) -> Option<f64>| {
            let v: Vec<(f64, f64)> = parts.iter().zip(&weights).filter_map(|(m, w)| f(m).map(|x| (x, *w))).collect();
            if v.is_empty() {
                None
            } else {
                Some(v.iter().map(|(x, w)| x * w).sum::<f64>() / v.iter().map(|(_, w)| w).sum::<f64>())
            }
        };
        let energies: Vec<f64> = self.clips.iter().map(|c| energy(c, self.opts.smooth_frames)).collect();
        let ratio = |e: f64| if self.energy > 0.0 { e / self.energy } else { 0.0 };
        let coverage = self.coverage_leave_one_out();
        Ok(Movement {
            energy: self.energy,
            energy_ratio: 1.0,
            energy_ratio_range: (
                ratio(energies.iter().copied().fold(f64::INFINITY, f64::min)),
                ratio(energies.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
            ),
            nearest_pose: parts.iter().zip(&weights).map(|(p, w)| p.0 * w).sum::<f64>() / total,
            calibrated_coverage: coverage.0,
            calibrated_coverage_by_clip: coverage.1,
            duty_factor: avg_opt(&|p| p.1),
            mixed_contact: avg_opt(&|p| p.2),
            alternation: pooled(&parts.iter().filter_map(|p| p.3).collect::<Vec<_>>()),
            footfall_error: self.footfalls.leave_one_out(),
            swing: pooled(&self.clips.iter().filter_map(swing_parts).collect::<Vec<_>>()),
        })
    }

    /// `count` static clips of `frames` frames holding the clips' mean pose (root-relative
    /// positions averaged over every frame, the root where the first clip starts), as world and
    /// point clips.
    pub fn mean_pose(&self, count: usize, frames: usize) -> (Vec<WorldClip>, Vec<PointClip>) {
        let first = &self.clips[0];
        let joints = first.joints;
        let mut sum = vec![DVec3::ZERO; joints];
        let mut n = 0usize;
        for c in self.clips {
            for f in 0..c.frames {
                let root = c.at(f, 0);
                for (j, s) in sum.iter_mut().enumerate() {
                    *s += c.at(f, j) - root;
                }
                n += 1;
            }
        }
        // The root where the first clip starts, at the clips' mean root height: the feet
        // then stand about where they do on average.
        let heights: Vec<f64> = self.clips.iter().flat_map(|c| (0..c.frames).map(move |f| c.at(f, 0).y)).collect();
        let root = DVec3::new(first.at(0, 0).x, heights.iter().sum::<f64>() / heights.len().max(1) as f64, first.at(0, 0).z);
        let pose: Vec<DVec3> = sum.iter().map(|s| root + *s / n.max(1) as f64).collect();
        let clip = WorldClip { frames, positions: (0..frames).flat_map(|_| pose.iter().copied()).collect(), ..first.clone() };
        let dims = self.points[0].dims();
        let mut mean = vec![0.0; dims];
        let mut m = 0usize;
        for p in self.points {
            for f in 0..p.frames() {
                for (a, v) in mean.iter_mut().zip(p.frame(f)) {
                    *a += v;
                }
                m += 1;
            }
        }
        mean.iter_mut().for_each(|v| *v /= m.max(1) as f64);
        let values: Vec<f64> = (0..frames).flat_map(|_| mean.iter().copied()).collect();
        let point = PointClip::new(frames, dims, values).expect("a mean of finite point frames has the clips' dims");
        (vec![clip; count], vec![point; count])
    }

    /// At least `count` crops of `frames` frames (or whole clips, when shorter) at seeded
    /// random places of the clips, as world and point clips. The crops take the clips in turn,
    /// at least two from each: a handful of crops drawn from clips at random can all land in
    /// the idle clip, and the baseline would then say that real motion barely moves.
    pub fn random_crops(&self, count: usize, frames: usize, seed: u64) -> (Vec<WorldClip>, Vec<PointClip>) {
        let mut rng = SplitMix64::new(seed);
        let count = count.max(2 * self.clips.len());
        let mut world = Vec::with_capacity(count);
        let mut points = Vec::with_capacity(count);
        for i in 0..count {
            let c = i % self.clips.len();
            let (clip, point) = (&self.clips[c], &self.points[c]);
            let len = frames.min(clip.frames).min(point.frames());
            let start = rng.below(clip.frames.min(point.frames()) - len + 1);
            let joints = clip.joints;
            world.push(WorldClip { frames: len, positions: clip.positions[start * joints..(start + len) * joints].to_vec(), ..clip.clone() });
            let dims = point.dims();
            points
                .push(PointClip::new(len, dims, point.values()[start * dims..(start + len) * dims].to_vec()).expect("a crop of a point clip is a point clip"));
        }
        (world, points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic quadruped's walk as world and point clips.
    fn walk() -> (WorldClip, PointClip) {
        let (skeleton, motion) = crate::synth::creature("quadruped", 3).unwrap();
        let clip = WorldClip::from_motion(&skeleton, &motion);
        let points = PointClip::from_clip(&clip).unwrap();
        (clip, points)
    }

    /// Every `k`-th frame at the same frame rate: the same motion played `k` times as fast.
    fn faster(clip: &WorldClip, k: usize) -> WorldClip {
        let frames: Vec<usize> = (0..clip.frames).step_by(k).collect();
        let positions = frames.iter().flat_map(|&f| clip.frame(f).iter().copied()).collect();
        WorldClip { frames: frames.len(), positions, ..clip.clone() }
    }

    #[test]
    fn a_clip_against_itself_is_perfect() {
        let (clip, points) = walk();
        let (clips, pts) = (vec![clip], vec![points]);
        let r = Reference::new(&clips, &pts, &MovementOptions::default()).unwrap();
        let m = r.score(&clips, &pts, None).unwrap();
        assert!((m.energy_ratio - 1.0).abs() < 1e-12, "{m:?}");
        assert_eq!(m.nearest_pose, 0.0);
        assert_eq!(m.calibrated_coverage, 100.0);
        assert!(r.energy() > 0.0);
        assert_eq!(r.clips_baseline().unwrap(), m);
    }

    #[test]
    fn coverage_by_clip_counts_each_clips_windows() {
        // The walk twice: every window has an exact twin in the other clip, so every
        // threshold is 0 and a window is covered only by itself.
        let (clip, points) = walk();
        let (clips, pts) = (vec![clip.clone(), clip.clone()], vec![points.clone(), points.clone()]);
        let r = Reference::new(&clips, &pts, &MovementOptions::default()).unwrap();
        assert_eq!(r.threshold, 0.0);
        // Its first 40 frames hold the windows starting at frames 0-25 of each copy.
        let head = PointClip::new(40, points.dims(), points.values()[..40 * points.dims()].to_vec()).unwrap();
        let head_world = WorldClip { frames: 40, positions: clip.positions[..40 * clip.positions.len() / clip.frames].to_vec(), ..clip.clone() };
        let share = 100.0 * 26.0 / (points.frames() - 14) as f64;
        let m = r.score(std::slice::from_ref(&head_world), std::slice::from_ref(&head), None).unwrap();
        assert!((m.calibrated_coverage - share).abs() < 1e-9, "{} against {share}", m.calibrated_coverage);
        assert_eq!(m.calibrated_coverage_by_clip, vec![Some(m.calibrated_coverage); 2]);
        // The clip left out has no share; a statue covers neither.
        let m = r.score(std::slice::from_ref(&head_world), std::slice::from_ref(&head), Some(1)).unwrap();
        assert_eq!(m.calibrated_coverage_by_clip, vec![Some(m.calibrated_coverage), None]);
        let (world, point) = r.mean_pose(2, 60);
        assert_eq!(r.score(&world, &point, None).unwrap().calibrated_coverage_by_clip, vec![Some(0.0); 2]);
        assert_eq!(r.clips_baseline().unwrap().calibrated_coverage_by_clip, vec![Some(100.0); 2]);
    }

    #[test]
    fn a_static_pose_covers_nothing_and_has_no_energy() {
        let (clip, points) = walk();
        let (clips, pts) = (vec![clip], vec![points]);
        let r = Reference::new(&clips, &pts, &MovementOptions::default()).unwrap();
        let (world, point) = r.mean_pose(4, 120);
        let m = r.score(&world, &point, None).unwrap();
        assert_eq!(m.energy, 0.0);
        assert_eq!(m.energy_ratio, 0.0);
        assert_eq!(m.calibrated_coverage, 0.0, "{m:?} threshold {}", r.threshold);
        // Standing on all fours: every foot down in every frame, never some up.
        assert_eq!(m.mixed_contact, Some(0.0));
        // The walk itself alternates its feet.
        let own = r.clips_baseline().unwrap();
        assert!(own.mixed_contact.unwrap() > 0.3, "{own:?}");
        // A statue's feet do not move, so they neither alternate nor swing together, and its
        // root does not travel.
        assert_eq!(m.alternation, None);
        assert_eq!(m.swing, None);
        assert!(own.alternation.unwrap() > 0.6, "{own:?}");
        // Pooled, a motion whose feet barely move counts for little: the walk next to a clip
        // whose two feet sway together by a ten-thousandth of a unit is still a walk.
        let (clip, points) = (&clips[0], &pts[0]);
        let walk_alt = alternation(points, &clip.feet).unwrap();
        let both = pooled(&[
            alternation_parts(points, &clip.feet).unwrap(),
            alternation_parts(&two_feet(points.frames(), |f| 1e-4 * f.sin(), |f| 1e-4 * f.sin()), &[1, 2]).unwrap(),
        ])
        .unwrap();
        assert!((both - walk_alt).abs() < 0.01, "{both} vs {walk_alt}");
    }

    /// Two feet (joints 1 and 2 under a root at 0) whose fore-aft positions are `a(f)` and
    /// `b(f)`, as a point clip.
    fn two_feet(frames: usize, a: impl Fn(f64) -> f64, b: impl Fn(f64) -> f64) -> PointClip {
        let values = (0..frames).flat_map(|f| [0.2, -1.0, a(f as f64), -0.2, -1.0, b(f as f64)]).collect();
        PointClip::new(frames, 6, values).unwrap()
    }

    #[test]
    fn alternation_tells_opposed_feet_from_feet_that_swing_together() {
        let phase = |f: f64| (std::f64::consts::TAU * f / 30.0).sin();
        let feet = [1, 2];
        // Left against right, as in a walk: all of the motion is opposed.
        let walk = two_feet(120, phase, |f| -phase(f));
        assert!((alternation(&walk, &feet).unwrap() - 1.0).abs() < 1e-12);
        // Both feet forward and back together, as the zoo-tiny quadruped's legs did.
        let together = two_feet(120, phase, phase);
        assert!(alternation(&together, &feet).unwrap() < 1e-12);
        // A quarter cycle apart: as much shared as opposed.
        let quarter = two_feet(120, phase, |f| phase(f + 7.5));
        assert!((alternation(&quarter, &feet).unwrap() - 0.5).abs() < 1e-9, "{:?}", alternation(&quarter, &feet));
        // Feet that stand still, one foot, or a foot outside the clip: nothing to measure.
        assert_eq!(alternation(&two_feet(120, |_| 0.3, |_| -0.1), &feet), None);
        assert_eq!(alternation(&walk, &[1]), None);
        assert_eq!(alternation(&walk, &[1, 9]), None);
        // Vertical motion (lifting the feet) does not count: only the horizontal swing.
        let lift = PointClip::new(60, 6, (0..60).flat_map(|f| [0.2, phase(f as f64), 0.0, -0.2, phase(f as f64), 0.0]).collect()).unwrap();
        assert_eq!(alternation(&lift, &feet), None);
    }

    /// The walk's legs played backwards under its root going forwards (a moonwalk): the walk
    /// played backwards whole, but with the root's horizontal travel of the walk played
    /// forwards, so every pose and every height is one of the walk's.
    fn moonwalk(clip: &WorldClip) -> WorldClip {
        let n = clip.frames;
        let positions = (0..n)
            .flat_map(|f| {
                let back = n - 1 - f;
                let (ahead, behind) = (clip.at(f, 0), clip.at(back, 0));
                let shift = DVec3::new(ahead.x - behind.x, 0.0, ahead.z - behind.z);
                (0..clip.joints).map(move |j| clip.at(back, j) + shift)
            })
            .collect();
        WorldClip { positions, ..clip.clone() }
    }

    #[test]
    fn swing_tells_a_walk_from_its_legs_played_backwards() {
        let (clip, _) = walk();
        let forward = swing(&clip).unwrap();
        assert!(forward > 0.8, "{forward}");
        let back = swing(&moonwalk(&clip)).unwrap();
        assert!(back < -0.8, "{back} (the walk: {forward})");
        // The whole walk played backwards is a walk backwards: its feet still swing with the
        // travel, by the same amount.
        let reversed = WorldClip { positions: (0..clip.frames).rev().flat_map(|f| clip.frame(f).to_vec()).collect(), ..clip.clone() };
        let backwards = swing(&reversed).unwrap();
        assert!((backwards - forward).abs() < 1e-9, "{backwards} vs {forward}");
        // The same legs on a root that stays where it is: no travel, no value.
        let in_place = WorldClip {
            positions: (0..clip.frames)
                .flat_map(|f| {
                    let r = clip.at(f, 0);
                    clip.frame(f).iter().map(move |p| *p - DVec3::new(r.x, 0.0, r.z)).collect::<Vec<_>>()
                })
                .collect(),
            ..clip.clone()
        };
        assert_eq!(swing(&in_place), None);
        // Through the scorer: the moonwalk has the walk's poses and the opposite swing.
        let points = vec![PointClip::from_clip(&clip).unwrap()];
        let clips = vec![clip];
        let r = Reference::new(&clips, &points, &MovementOptions::default()).unwrap();
        let moon = vec![moonwalk(&clips[0])];
        let m = r.score(&moon, &[PointClip::from_clip(&moon[0]).unwrap()], None).unwrap();
        assert!(m.nearest_pose < 1e-9, "{m:?}");
        assert!(m.swing.unwrap() < -0.8, "{m:?}");
        assert!(r.clips_baseline().unwrap().swing.unwrap() > 0.8);
    }

    /// A hip that stays put and a foot swinging under it at `hz`, 30 fps.
    fn pendulum(frames: usize, hz: f64) -> WorldClip {
        let positions = (0..frames)
            .flat_map(|f| {
                let x = 0.3 * (std::f64::consts::TAU * hz * f as f64 / 30.0).sin();
                [DVec3::Y, DVec3::new(x, 0.0, 0.0)]
            })
            .collect();
        WorldClip {
            frames,
            joints: 2,
            fps: 30.0,
            positions,
            parents: vec![None, Some(0)],
            names: vec!["Hips".into(), "LeftFoot".into()],
            feet: vec![1],
            scale: 1.0,
        }
    }

    #[test]
    fn a_sped_up_copy_has_twice_the_energy() {
        // A slow swing, which the 5-frame average leaves almost whole at both speeds.
        let slow = pendulum(480, 0.25);
        let fast = faster(&slow, 2);
        assert!((energy(&fast, 5) / energy(&slow, 5) - 2.0).abs() < 0.05, "{} vs {}", energy(&fast, 5), energy(&slow, 5));
        // The zoo walk through the whole scorer: its quick foot motion loses more to the
        // 5-frame average at double speed (motionq.py gives 1.57 on the same files), so the
        // ratio is under 2 but far above 1.
        let (clip, points) = walk();
        let fast = faster(&clip, 2);
        let fast_points = PointClip::from_clip(&fast).unwrap();
        let (clips, pts) = (vec![clip], vec![points]);
        let r = Reference::new(&clips, &pts, &MovementOptions::default()).unwrap();
        let m = r.score(std::slice::from_ref(&fast), std::slice::from_ref(&fast_points), None).unwrap();
        assert!(m.energy_ratio > 1.4 && m.energy_ratio < 2.1, "{m:?}");
        // Its poses are the clip's own.
        assert_eq!(m.nearest_pose, 0.0);
    }

    #[test]
    fn random_crops_are_seeded_pieces_of_the_clips() {
        let (clip, points) = walk();
        let (clips, pts) = (vec![clip], vec![points]);
        let r = Reference::new(&clips, &pts, &MovementOptions::default()).unwrap();
        let (a, pa) = r.random_crops(3, 60, 7);
        let (b, _) = r.random_crops(3, 60, 7);
        // At least two crops per clip.
        assert_eq!(a.len(), 3);
        assert_eq!(r.random_crops(1, 60, 7).0.len(), 2);
        assert_eq!(a.iter().map(|c| c.positions.clone()).collect::<Vec<_>>(), b.iter().map(|c| c.positions.clone()).collect::<Vec<_>>());
        let m = r.score(&a, &pa, None).unwrap();
        assert_eq!(m.nearest_pose, 0.0);
        assert!(m.energy_ratio > 0.5 && m.energy_ratio < 1.5, "{m:?}");
    }

    #[test]
    fn too_short_clips_are_an_error() {
        let (clip, _) = walk();
        let short = WorldClip { frames: 10, positions: clip.positions[..10 * clip.joints].to_vec(), ..clip };
        let points = PointClip::from_clip(&short).unwrap();
        assert!(matches!(Reference::new(&[short], &[points], &MovementOptions::default()), Err(MetricError::TooLittle(_))));
    }
}
