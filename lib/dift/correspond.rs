//! Correspondence from descriptors (AnyTop §4.1): cosine similarity between every target and
//! every reference descriptor, and the best reference for each target. Used for joints (DIFT
//! averaged over time) and frames (DIFT averaged over joints), and by the baselines.

use crate::binding::auto::{pair_count, Choice};
use crate::skeleton::Skeleton;
use serde::Serialize;

/// The best reference item for one target item.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Match {
    pub target: usize,
    pub reference: usize,
    /// Cosine similarity of the two descriptors.
    pub score: f64,
    /// Best score minus the second best: how clear the choice was (1 when there is one candidate).
    pub margin: f64,
}

/// Cosine similarity `[target][reference]`. A zero descriptor has similarity 0 with everything.
///
/// One matrix product of the unit rows (candle's GEMM, f32): frame descriptors of one skeleton
/// side by side are joints x width long, and two 2,000-frame clips made the plain loop the
/// slowest part of `mo-dift --frames` (4-5 s of 16).
pub fn cosine_matrix(target: &[Vec<f32>], reference: &[Vec<f32>]) -> Vec<Vec<f64>> {
    let width = target.first().or(reference.first()).map_or(0, Vec::len);
    let same_width = target.iter().chain(reference).all(|v| v.len() == width);
    if target.is_empty() || reference.is_empty() || width == 0 || !same_width {
        return cosine_loop(target, reference);
    }
    let unit = |rows: &[Vec<f32>]| -> Vec<f32> {
        rows.iter()
            .flat_map(|v| {
                let n = v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
                v.iter().map(move |&x| if n > 0.0 { (x as f64 / n) as f32 } else { 0.0 })
            })
            .collect()
    };
    let product = || -> candle_core::Result<Vec<Vec<f32>>> {
        let device = candle_core::Device::Cpu;
        let t = candle_core::Tensor::from_vec(unit(target), (target.len(), width), &device)?;
        let r = candle_core::Tensor::from_vec(unit(reference), (reference.len(), width), &device)?;
        t.matmul(&r.t()?)?.to_vec2::<f32>()
    };
    match product() {
        Ok(rows) => rows.into_iter().map(|row| row.into_iter().map(f64::from).collect()).collect(),
        Err(_) => cosine_loop(target, reference),
    }
}

/// `cosine_matrix` one pair at a time, in f64 (rows of unequal length compare over the
/// shorter).
fn cosine_loop(target: &[Vec<f32>], reference: &[Vec<f32>]) -> Vec<Vec<f64>> {
    let unit = |v: &Vec<f32>| -> Vec<f64> {
        let n = v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
        v.iter().map(|&x| if n > 0.0 { x as f64 / n } else { 0.0 }).collect()
    };
    let r: Vec<Vec<f64>> = reference.iter().map(unit).collect();
    target.iter().map(unit).map(|t| r.iter().map(|r| t.iter().zip(r).map(|(a, b)| a * b).sum()).collect()).collect()
}

/// For every target row, the best reference column (ties to the lower index). Empty rows give
/// no match.
pub fn best_matches(similarity: &[Vec<f64>]) -> Vec<Match> {
    similarity
        .iter()
        .enumerate()
        .filter(|(_, row)| !row.is_empty())
        .map(|(target, row)| {
            let mut best = 0;
            for (i, &s) in row.iter().enumerate() {
                if s > row[best] {
                    best = i;
                }
            }
            let second = row.iter().enumerate().filter(|&(i, _)| i != best).map(|(_, &s)| s).fold(f64::NEG_INFINITY, f64::max);
            let margin = if second.is_finite() { row[best] - second } else { 1.0 };
            Match { target, reference: best, score: row[best], margin }
        })
        .collect()
}

/// For every target row, a reference column such that the columns never go back in time:
/// dynamic time warping on the cost 1 − similarity, from (0, 0) to (last, last) with steps
/// (1, 0), (0, 1), (1, 1). Where the path crosses a target row over several columns, the most
/// similar of them is that row's answer. `margin` is the answer's similarity minus the best
/// other in its row: negative where the ordering overruled the frame-by-frame best.
///
/// Frame by frame (`best_matches`, the paper's rule) a pose matches any moment that looks
/// alike: every cycle of a gait, the stand at either end of a clip. Two takes of one action —
/// a time-warped copy, a slower performance — share their order, and the ordering constraint
/// settles what the descriptors alone cannot (benches/dift.rs: time-warped clips).
pub fn monotonic_matches(similarity: &[Vec<f64>]) -> Vec<Match> {
    let rows = similarity.len();
    let cols = similarity.first().map_or(0, Vec::len);
    if rows == 0 || cols == 0 || similarity.iter().any(|r| r.len() != cols) {
        return best_matches(similarity);
    }
    // Accumulated cost, one row at a time; the step taken into each cell for the way back
    // (0 diagonal, 1 from the row above, 2 from the left), one byte per cell.
    let cost = |t: usize, r: usize| 1.0 - similarity[t][r];
    let mut step = vec![0u8; rows * cols];
    let mut prev = vec![f64::INFINITY; cols];
    let mut cur = vec![0.0; cols];
    for t in 0..rows {
        for r in 0..cols {
            let (best, from) = if t == 0 && r == 0 {
                (0.0, 0)
            } else {
                // Ties prefer the diagonal, then the row above: the path stays near k -> k
                // when the descriptors cannot tell.
                let diag = if t > 0 && r > 0 { prev[r - 1] } else { f64::INFINITY };
                let up = if t > 0 { prev[r] } else { f64::INFINITY };
                let left = if r > 0 { cur[r - 1] } else { f64::INFINITY };
                if diag <= up && diag <= left {
                    (diag, 0)
                } else if up <= left {
                    (up, 1)
                } else {
                    (left, 2)
                }
            };
            cur[r] = best + cost(t, r);
            step[t * cols + r] = from;
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    // Walk back, keeping per target row the most similar column the path crosses.
    let mut answer = vec![usize::MAX; rows];
    let (mut t, mut r) = (rows - 1, cols - 1);
    loop {
        if answer[t] == usize::MAX || similarity[t][r] > similarity[t][answer[t]] {
            answer[t] = r;
        }
        if t == 0 && r == 0 {
            break;
        }
        match step[t * cols + r] {
            0 => (t, r) = (t - 1, r - 1),
            1 => t -= 1,
            _ => r -= 1,
        }
    }
    answer
        .iter()
        .enumerate()
        .map(|(target, &reference)| {
            let row = &similarity[target];
            let other = row.iter().enumerate().filter(|&(i, _)| i != reference).map(|(_, &s)| s).fold(f64::NEG_INFINITY, f64::max);
            let margin = if other.is_finite() { row[reference] - other } else { 1.0 };
            Match { target, reference, score: row[reference], margin }
        })
        .collect()
}

/// A sparse binding (reference = source, target = target) from a joint similarity matrix
/// `[target][reference]`: only joints whose rotation moves a bone (not the root, not leaves,
/// as `binding::auto`), only mutual best matches among them (each is the other's first
/// choice: the confident pairs), highest similarity first, as many as Motion2Motion's binding
/// rate asks for (`auto::pair_count`).
pub fn binding_choices(similarity: &[Vec<f64>], reference: &Skeleton, target: &Skeleton, rate: f64, min_pairs: usize) -> Vec<Choice> {
    let candidates = |s: &Skeleton| -> Vec<usize> {
        let children = s.children();
        (1..s.len()).filter(|&j| !children[j].is_empty()).collect()
    };
    let (rc, tc) = (candidates(reference), candidates(target));
    let at = |t: usize, r: usize| similarity.get(t).and_then(|row| row.get(r)).copied().unwrap_or(f64::NEG_INFINITY);
    // First choice by score, ties to the lower index, so the result depends on nothing else.
    let first = |scores: &mut dyn Iterator<Item = (usize, f64)>| {
        scores.fold(None, |best: Option<(usize, f64)>, (i, s)| match best {
            Some((_, b)) if b >= s => best,
            _ => Some((i, s)),
        })
    };
    let mut pairs: Vec<Choice> = Vec::new();
    for &t in &tc {
        let Some((r, s)) = first(&mut rc.iter().map(|&r| (r, at(t, r)))) else { continue };
        let back = first(&mut tc.iter().map(|&t2| (t2, at(t2, r))));
        if back.map(|(t2, _)| t2) == Some(t) {
            pairs.push(Choice { source: r, target: t, score: s });
        }
    }
    pairs.sort_by(|a, b| b.score.total_cmp(&a.score).then(a.target.cmp(&b.target)));
    pairs.truncate(pair_count(rate, reference.len(), target.len(), min_pairs));
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn best_matches_pick_the_most_similar_direction() {
        let reference = vec![vec![1.0, 0.0], vec![0.0, 1.0], vec![-1.0, 0.0]];
        let target = vec![vec![0.1, 2.0], vec![3.0, 0.2], vec![0.0, 0.0]];
        let sim = cosine_matrix(&target, &reference);
        let m = best_matches(&sim);
        assert_eq!(m.iter().map(|m| m.reference).collect::<Vec<_>>(), vec![1, 0, 0]);
        assert!(m[0].score > 0.99 && m[0].margin > 0.9);
        // The zero descriptor is similar to nothing: a tie at 0, resolved to the first.
        assert_eq!((m[2].score, m[2].margin), (0.0, 0.0));
    }

    #[test]
    fn the_matrix_product_agrees_with_the_plain_loop() {
        let mut rng = crate::rng::SplitMix64::new(4);
        let mut rows = |n: usize| -> Vec<Vec<f32>> { (0..n).map(|_| (0..37).map(|_| rng.below(2001) as f32 / 1000.0 - 1.0).collect()).collect() };
        let (t, mut r) = (rows(23), rows(31));
        r[5] = vec![0.0; 37];
        let (fast, slow) = (cosine_matrix(&t, &r), cosine_loop(&t, &r));
        assert_eq!((fast.len(), fast[0].len()), (23, 31));
        for (a, b) in fast.iter().flatten().zip(slow.iter().flatten()) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
        assert!(fast.iter().all(|row| row[5] == 0.0), "a zero descriptor is similar to nothing");
    }

    #[test]
    fn monotonic_matches_follow_the_order_where_frames_look_alike() {
        // A periodic descriptor (a gait: frame k looks like frame k + 10) and a target that is
        // the reference played at half speed for its first half, then double speed.
        let desc = |x: f64| vec![(x * std::f64::consts::TAU / 10.0).cos() as f32, (x * std::f64::consts::TAU / 10.0).sin() as f32, 0.3];
        let reference: Vec<Vec<f32>> = (0..29).map(|k| desc(k as f64)).collect();
        let truth: Vec<usize> = (0..30).map(|k| if k < 20 { k / 2 } else { 10 + (k - 20) * 2 }).collect();
        let target: Vec<Vec<f32>> = truth.iter().map(|&x| desc(x as f64)).collect();
        let sim = cosine_matrix(&target, &reference);
        let nearest = best_matches(&sim);
        assert!(nearest.iter().zip(&truth).any(|(m, &x)| m.reference != x), "frame by frame picks the wrong cycle");
        let aligned = monotonic_matches(&sim);
        assert_eq!(aligned.len(), truth.len());
        assert!(aligned.windows(2).all(|w| w[1].reference >= w[0].reference));
        assert_eq!((aligned[0].reference, aligned[29].reference), (0, 28));
        let wrong = aligned.iter().zip(&truth).filter(|(m, &x)| m.reference.abs_diff(x) > 1).count();
        assert!(wrong <= 2, "{wrong} frames off: {:?}", aligned.iter().map(|m| m.reference).collect::<Vec<_>>());
        // A ragged matrix cannot be aligned; it falls back to frame by frame.
        assert_eq!(monotonic_matches(&[vec![0.5, 0.9], vec![0.1]]).len(), 2);
    }

    #[test]
    fn binding_keeps_only_mutual_best_pairs_of_moving_joints() {
        let (s, _) = crate::synth::creature("quadruped", 0).unwrap();
        let n = s.len();
        // Identity similarity, except target joint 5 prefers reference 6 which prefers target 6.
        let mut sim: Vec<Vec<f64>> = (0..n).map(|t| (0..n).map(|r| if t == r { 0.9 } else { 0.0 }).collect()).collect();
        sim[5][6] = 0.95;
        let pairs = binding_choices(&sim, &s, &s, 1.0, 1);
        let children = s.children();
        assert!(!pairs.is_empty());
        for p in &pairs {
            assert!(p.source != 0 && !children[p.source].is_empty());
            assert_eq!(p.source, p.target, "only mutual best pairs: {p:?}");
        }
        assert!(pairs.iter().all(|p| p.target != 5), "joint 5's first choice is not mutual");
        let few = binding_choices(&sim, &s, &s, 0.061, 2);
        assert_eq!(few.len(), pair_count(0.061, n, n, 2));
    }
}
