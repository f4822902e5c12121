//! Footfall pattern: how far a motion's feet keep the clips' phases against each other.
//!
//! A model can learn each limb's stride and still put the limbs together wrongly: a quadruped
//! whose hind feet alternate as in the clips but whose fore feet swing at a phase of their own
//! (models/zoo-compact/MODEL_CARD.md, "Why samples do not find the clips' gaits"). Energy,
//! poses and alternation all look right on such a walk; calibrated coverage falls, without
//! saying why. This reads the pattern directly:
//!
//! * A motion is cut into segments of `SEGMENT` frames (hop `SEGMENT / 2`; a shorter motion is
//!   one segment if it has at least `SEGMENT / 2` frames), so that a clip that walks, stops
//!   and runs gives one pattern per stretch, not a blur of them.
//! * In each segment the feet's horizontal paths (root-relative, in the facing frame: the
//!   AnyTop point features) are Hann-windowed and their spectra taken. The stride frequency is
//!   the bin (1 cycle per segment or more) with the most power summed over feet and both axes.
//! * For each pair of feet that both swing at that frequency (amplitude at least `MIN_SWING`),
//!   the relative phase is the angle of their cross-spectrum summed over the two axes, in
//!   cycles. A pair where either foot barely swings has no phase.
//! * Two segments' distance is the mean over the pairs phased in both of the circular
//!   distance between their relative phases (0 to 0.5 cycles).
//! * A motion's footfall error is the mean over its phased segments of the distance to the
//!   nearest phased segment of the clips.
//!
//! The chance level (`Footfalls::chance`) is the same error for feet whose phases are drawn
//! at random: a model that learned each limb but not how they go together scores about that.

use super::generation::PointClip;
use crate::rng::SplitMix64;

/// Segment length in frames (3 s at AnyTop's 20 fps: one to six strides of the zoo's gaits).
pub const SEGMENT: usize = 60;
/// Smallest swing amplitude at the stride frequency, AnyTop units (a tenth of the mean SMPL
/// bone, 0.209), for a foot to have a phase.
pub const MIN_SWING: f64 = 0.02;
/// Random patterns drawn for the chance level.
const CHANCE_DRAWS: usize = 512;
/// At most this many segments per set of motions (evenly strided), which bounds the
/// comparisons as the window caps do; a 15,000-frame capture still gives one every 30 frames.
const MAX_SEGMENTS: usize = 500;

/// Relative phases (cycles, in [0, 1)) of every pair (i < k) of feet in one segment, in pair
/// order; `None` where either foot barely swings.
#[derive(Clone, Debug, PartialEq)]
pub struct Pattern {
    pairs: Vec<Option<f64>>,
}

/// Mean of `d`; `None` when it is empty.
pub(super) fn mean(d: &[f64]) -> Option<f64> {
    (!d.is_empty()).then(|| d.iter().sum::<f64>() / d.len() as f64)
}

/// Circular distance between two phases in cycles: 0 to 0.5.
fn circular(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(1.0);
    d.min(1.0 - d)
}

impl Pattern {
    /// Mean circular distance over the pairs phased in both; `None` when there are none.
    pub fn distance(&self, other: &Pattern) -> Option<f64> {
        mean(&self.pairs.iter().zip(&other.pairs).filter_map(|(a, b)| Some(circular((*a)?, (*b)?))).collect::<Vec<f64>>())
    }
}

/// The pattern of frames `start..start + len` of `points` for `feet` (point indices, the root
/// excluded); `None` when fewer than two feet swing.
fn segment_pattern(points: &PointClip, feet: &[usize], start: usize, len: usize) -> Option<Pattern> {
    let n = len as f64;
    let hann: Vec<f64> = (0..len).map(|t| 0.5 - 0.5 * (std::f64::consts::TAU * (t as f64 + 0.5) / n).cos()).collect();
    let gain: f64 = hann.iter().sum();
    // Each foot's two horizontal axes about their means, windowed.
    let paths: Vec<[Vec<f64>; 2]> = feet
        .iter()
        .map(|&p| {
            let axis = |a: usize| {
                let raw: Vec<f64> = (start..start + len).map(|f| points.frame(f)[3 * p + a]).collect();
                let mean = raw.iter().sum::<f64>() / n;
                raw.iter().zip(&hann).map(|(v, w)| (v - mean) * w).collect::<Vec<f64>>()
            };
            [axis(0), axis(2)]
        })
        .collect();
    let spectrum = |x: &[f64], k: usize| -> (f64, f64) {
        let w = std::f64::consts::TAU * k as f64 / n;
        x.iter().enumerate().fold((0.0, 0.0), |(re, im), (t, v)| (re + v * (w * t as f64).cos(), im - v * (w * t as f64).sin()))
    };
    // Bins from one cycle per segment (a slow gait's stride) up to Nyquist.
    let bins: Vec<Vec<[(f64, f64); 2]>> = (1..=len / 2).map(|k| paths.iter().map(|[x, z]| [spectrum(x, k), spectrum(z, k)]).collect()).collect();
    let power = |b: &Vec<[(f64, f64); 2]>| b.iter().map(|ax| ax.iter().map(|(r, i)| r * r + i * i).sum::<f64>()).sum::<f64>();
    let best = bins.iter().max_by(|a, b| power(a).total_cmp(&power(b)))?;
    // Amplitude of a sinusoid from its windowed coefficient: 2 |X| / Σw.
    let swings: Vec<bool> = best.iter().map(|ax| ax.iter().map(|(r, i)| 2.0 * (r * r + i * i).sqrt() / gain).fold(0.0, f64::max) >= MIN_SWING).collect();
    if swings.iter().filter(|&&s| s).count() < 2 {
        return None;
    }
    let mut pairs = Vec::with_capacity(feet.len() * feet.len().saturating_sub(1) / 2);
    for i in 0..feet.len() {
        for k in i + 1..feet.len() {
            pairs.push((swings[i] && swings[k]).then(|| {
                // Σ over axes of X_i conj(X_k): its angle is φ_i − φ_k, weighted by amplitude.
                let (re, im) = best[i].iter().zip(&best[k]).fold((0.0, 0.0), |(re, im), ((ar, ai), (br, bi))| (re + ar * br + ai * bi, im + ai * br - ar * bi));
                (im.atan2(re) / std::f64::consts::TAU).rem_euclid(1.0)
            }));
        }
    }
    Some(Pattern { pairs })
}

/// Segment starts of a motion of `frames` frames: every `SEGMENT / 2`, each segment
/// `SEGMENT` long; one shorter segment for a motion of `SEGMENT / 2 .. SEGMENT` frames.
fn segments(frames: usize) -> Vec<(usize, usize)> {
    if frames < SEGMENT / 2 {
        Vec::new()
    } else if frames < SEGMENT {
        vec![(0, frames)]
    } else {
        (0..=frames - SEGMENT).step_by(SEGMENT / 2).map(|s| (s, SEGMENT)).collect()
    }
}

/// The patterns of every segment of `motions` (at most `MAX_SEGMENTS`, evenly strided), each
/// with the motion it came from; `points` are the feet's point indices (motions without all
/// of them are left out).
fn patterns(motions: &[PointClip], points: &[usize]) -> Vec<(usize, Pattern)> {
    if points.len() < 2 {
        return Vec::new();
    }
    let holds = |m: &PointClip| points.iter().all(|&p| p < m.points());
    let all: Vec<(usize, usize, usize)> =
        motions.iter().enumerate().filter(|(_, m)| holds(m)).flat_map(|(m, p)| segments(p.frames()).into_iter().map(move |(s, l)| (m, s, l))).collect();
    let stride = all.len().div_ceil(MAX_SEGMENTS).max(1);
    all.into_iter().step_by(stride).filter_map(|(m, s, l)| segment_pattern(&motions[m], points, s, l).map(|p| (m, p))).collect()
}

/// The clips' footfall patterns, to score motions of the same skeleton against.
pub struct Footfalls {
    /// The feet's point indices (joint − 1: the point clips hold joints 1..), those inside
    /// every clip.
    points: Vec<usize>,
    clips: Vec<(usize, Pattern)>,
}

impl Footfalls {
    /// `feet` are joint indices.
    pub fn new(clips: &[PointClip], feet: &[usize]) -> Footfalls {
        let points: Vec<usize> = feet.iter().filter(|&&j| j >= 1 && clips.iter().all(|m| j <= m.points())).map(|&j| j - 1).collect();
        let clips = patterns(clips, &points);
        Footfalls { points, clips }
    }

    /// Whether any clip segment has a footfall pattern (else every error is `None`).
    pub fn is_empty(&self) -> bool {
        self.clips.is_empty()
    }

    /// Distance of `p` to the nearest clip pattern, leaving out clip `skip`.
    fn nearest(&self, p: &Pattern, skip: Option<usize>) -> Option<f64> {
        self.clips.iter().filter(|(c, _)| Some(*c) != skip).filter_map(|(_, q)| p.distance(q)).min_by(f64::total_cmp)
    }

    /// Mean over the phased segments of `motions` of the distance to the nearest clip
    /// segment's pattern (clip `skip` left out); `None` when no segment of either is phased.
    pub fn error(&self, motions: &[PointClip], skip: Option<usize>) -> Option<f64> {
        mean(&patterns(motions, &self.points).iter().filter_map(|(_, p)| self.nearest(p, skip)).collect::<Vec<f64>>())
    }

    /// Each clip against the others: mean over the clips' phased segments of the distance to
    /// the nearest segment of another clip.
    pub fn leave_one_out(&self) -> Option<f64> {
        mean(&self.clips.iter().filter_map(|(c, p)| self.nearest(p, Some(*c))).collect::<Vec<f64>>())
    }

    /// The error of feet whose phases are drawn uniformly at random (seeded): the chance level.
    pub fn chance(&self, seed: u64) -> Option<f64> {
        let feet = self.points.len();
        if self.clips.is_empty() || feet < 2 {
            return None;
        }
        let mut rng = SplitMix64::new(seed);
        let mut sum = 0.0;
        for _ in 0..CHANCE_DRAWS {
            let phase: Vec<f64> = (0..feet).map(|_| rng.unit()).collect();
            let pairs = (0..feet).flat_map(|i| (i + 1..feet).map(move |k| (i, k))).map(|(i, k)| Some((phase[i] - phase[k]).rem_euclid(1.0))).collect();
            sum += self.nearest(&Pattern { pairs }, None)?;
        }
        Some(sum / CHANCE_DRAWS as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feet swinging forward and back (z) with the given phases (cycles), `period` frames a
    /// cycle, amplitude 0.1; the points are just the feet.
    fn walk(phases: &[f64], period: f64, frames: usize) -> PointClip {
        let mut values = Vec::new();
        for f in 0..frames {
            for (i, p) in phases.iter().enumerate() {
                let z = 0.1 * (std::f64::consts::TAU * (f as f64 / period - p)).cos();
                values.extend([i as f64 * 0.3, 0.0, z]);
            }
        }
        PointClip::new(frames, 3 * phases.len(), values).unwrap()
    }

    const FEET: [usize; 4] = [1, 2, 3, 4];

    #[test]
    fn a_walk_matches_itself_and_a_shifted_copy_but_not_another_gait() {
        let lateral = [0.0, 0.5, 0.25, 0.75];
        let reference = Footfalls::new(&[walk(&lateral, 20.0, 120)], &FEET);
        // The same gait, started at another moment and a little faster: the same pattern.
        let same = [0.3, 0.8, 0.55, 0.05];
        let e = reference.error(&[walk(&same, 18.0, 120)], None).unwrap();
        assert!(e < 0.02, "{e}");
        // A trot (diagonals together) differs by a quarter cycle on four of the six pairs.
        let trot = [0.0, 0.5, 0.5, 0.0];
        let e = reference.error(&[walk(&trot, 20.0, 120)], None).unwrap();
        assert!((e - 1.0 / 6.0).abs() < 0.02, "{e}");
        // Random phases sit between.
        let chance = reference.chance(1).unwrap();
        assert!((chance - 0.25).abs() < 0.03, "{chance}");
    }

    #[test]
    fn still_feet_have_no_pattern() {
        let still = walk(&[0.0, 0.5, 0.25, 0.75], 20.0, 120);
        let flat = PointClip::new(120, 12, (0..120).flat_map(|_| still.frame(0).to_vec()).collect()).unwrap();
        let reference = Footfalls::new(&[still], &FEET);
        assert_eq!(reference.error(&[flat.clone()], None), None);
        assert!(Footfalls::new(&[flat], &FEET).is_empty());
        // Too short for a segment.
        assert!(patterns(&[walk(&[0.0, 0.5], 20.0, 20)], &[0, 1]).is_empty());
    }

    #[test]
    fn leave_one_out_finds_a_gait_in_another_clip() {
        let lateral = [0.0, 0.5, 0.25, 0.75];
        let clips = [walk(&lateral, 20.0, 90), walk(&[0.1, 0.6, 0.35, 0.85], 24.0, 90), walk(&[0.0, 0.5, 0.5, 0.0], 20.0, 90)];
        let reference = Footfalls::new(&clips, &FEET);
        let loo = reference.leave_one_out().unwrap();
        // The two walks find each other (about 0); the trot finds a walk a sixth of a cycle off
        // on average; pooled over segments (2 per clip): about (0 + 0 + 1/6) / 3.
        assert!((loo - 1.0 / 18.0).abs() < 0.02, "{loo}");
    }
}
