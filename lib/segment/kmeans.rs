//! K-means: k-means++ seeding, Lloyd iterations, several restarts keeping the lowest inertia.
//!
//! Everything runs sequentially in a fixed order from one `SplitMix64` stream, so the same
//! points, k and seed give the same labels on any machine and thread count. Clusters are
//! renumbered by first appearance (label 0 = the cluster of point 0), which makes the output
//! independent of the order the seeding happened to find them in, and readable for time series.

use super::{check_frames, SegmentError};
use crate::rng::SplitMix64;

/// Lloyd iterations per restart at most; real clips converge in tens.
pub const MAX_ITERATIONS: usize = 300;

/// A clustering.
#[derive(Clone, Debug, PartialEq)]
pub struct KMeans {
    /// Cluster of every point, numbered by first appearance: `labels[0] == 0`, and a label
    /// first appears only after all smaller ones. Fewer than k labels appear when the points
    /// have fewer than k distinct values (clusters that end up empty are dropped).
    pub labels: Vec<usize>,
    /// Centroid of every label, in label order.
    pub centroids: Vec<Vec<f64>>,
    /// Sum of squared distances of the points to their centroids.
    pub inertia: f64,
}

fn distance2(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Cluster `points` into `k` clusters. `restarts` runs (at least one) start from different
/// k-means++ seedings of one stream seeded by `seed`; the run with the lowest inertia wins (the
/// earliest on ties). Errors when k is 0 or larger than the number of points (no clamping: a
/// silent smaller k would change what the caller asked for), and on ragged or non-finite input.
pub fn kmeans(points: &[Vec<f64>], k: usize, seed: u64, restarts: usize) -> Result<KMeans, SegmentError> {
    check_frames(points)?;
    if k == 0 {
        return Err(SegmentError::ZeroK);
    }
    if k > points.len() {
        return Err(SegmentError::TooFewFrames { k, frames: points.len() });
    }
    let mut rng = SplitMix64::new(seed);
    let mut best: Option<(Vec<usize>, Vec<Vec<f64>>, f64)> = None;
    for _ in 0..restarts.max(1) {
        let centroids = seed_plus_plus(points, k, &mut rng);
        let (labels, centroids, inertia) = lloyd(points, centroids);
        if best.as_ref().is_none_or(|b| inertia < b.2) {
            best = Some((labels, centroids, inertia));
        }
    }
    let (labels, centroids, inertia) = best.expect("at least one restart ran");
    Ok(renumber(labels, centroids, inertia))
}

/// k-means++: the first centre uniformly, each next one with probability proportional to the
/// squared distance to the nearest centre so far (uniformly when every point sits on a centre).
fn seed_plus_plus(points: &[Vec<f64>], k: usize, rng: &mut SplitMix64) -> Vec<Vec<f64>> {
    let n = points.len();
    let mut centres = vec![points[rng.below(n)].clone()];
    let mut nearest: Vec<f64> = points.iter().map(|p| distance2(p, &centres[0])).collect();
    while centres.len() < k {
        let total: f64 = nearest.iter().sum();
        let pick = if total > 0.0 {
            let target = rng.unit() * total;
            let mut acc = 0.0;
            // Falls back to the last point with weight if rounding leaves `target` unreached.
            let mut chosen = nearest.iter().rposition(|&d| d > 0.0).unwrap_or(n - 1);
            for (i, &d) in nearest.iter().enumerate() {
                acc += d;
                if d > 0.0 && acc > target {
                    chosen = i;
                    break;
                }
            }
            chosen
        } else {
            rng.below(n)
        };
        let c = points[pick].clone();
        for (d, p) in nearest.iter_mut().zip(points) {
            *d = d.min(distance2(p, &c));
        }
        centres.push(c);
    }
    centres
}

/// Nearest centroid of `p` (the lowest index on ties) and the squared distance to it.
fn nearest(p: &[f64], centroids: &[Vec<f64>]) -> (usize, f64) {
    let mut best = (0, f64::INFINITY);
    for (c, centre) in centroids.iter().enumerate() {
        let d = distance2(p, centre);
        if d < best.1 {
            best = (c, d);
        }
    }
    best
}

/// Lloyd iterations until no point changes cluster (or `MAX_ITERATIONS`). An emptied cluster
/// keeps its centroid, so it can win points back later; it is dropped at the end if still empty.
fn lloyd(points: &[Vec<f64>], mut centroids: Vec<Vec<f64>>) -> (Vec<usize>, Vec<Vec<f64>>, f64) {
    let k = centroids.len();
    let dims = points[0].len();
    let mut labels: Vec<usize> = points.iter().map(|p| nearest(p, &centroids).0).collect();
    for _ in 0..MAX_ITERATIONS {
        let mut sums = vec![vec![0.0; dims]; k];
        let mut counts = vec![0usize; k];
        for (p, &l) in points.iter().zip(&labels) {
            counts[l] += 1;
            for (s, x) in sums[l].iter_mut().zip(p) {
                *s += x;
            }
        }
        for c in 0..k {
            if counts[c] > 0 {
                centroids[c] = sums[c].iter().map(|s| s / counts[c] as f64).collect();
            }
        }
        let next: Vec<usize> = points.iter().map(|p| nearest(p, &centroids).0).collect();
        if next == labels {
            break;
        }
        labels = next;
    }
    let inertia = points.iter().zip(&labels).map(|(p, &l)| distance2(p, &centroids[l])).sum();
    (labels, centroids, inertia)
}

/// Number clusters by first appearance and drop the ones no point uses.
fn renumber(labels: Vec<usize>, centroids: Vec<Vec<f64>>, inertia: f64) -> KMeans {
    let (labels, order) = first_appearance(&labels);
    let centroids = order.iter().map(|&c| centroids[c].clone()).collect();
    KMeans { labels, centroids, inertia }
}

/// `labels` renumbered by first appearance, and the old label of every new one.
pub(super) fn first_appearance(labels: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut order: Vec<usize> = Vec::new();
    let out = labels
        .iter()
        .map(|&l| match order.iter().position(|&o| o == l) {
            Some(i) => i,
            None => {
                order.push(l);
                order.len() - 1
            }
        })
        .collect();
    (out, order)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `counts[i]` points around `centres[i]`, in time order, with deterministic jitter.
    pub(crate) fn blobs(centres: &[[f64; 2]], counts: &[usize], spread: f64, seed: u64) -> Vec<Vec<f64>> {
        let mut rng = SplitMix64::new(seed);
        let mut out = Vec::new();
        for (c, &n) in centres.iter().zip(counts) {
            for _ in 0..n {
                out.push(vec![c[0] + rng.range(-spread, spread), c[1] + rng.range(-spread, spread)]);
            }
        }
        out
    }

    #[test]
    fn three_blobs_in_time_order_get_labels_0_1_2() {
        let points = blobs(&[[5.0, 5.0], [-5.0, 0.0], [0.0, -6.0]], &[20, 15, 25], 1.0, 3);
        let km = kmeans(&points, 3, 7, 4).unwrap();
        let want: Vec<usize> = [vec![0; 20], vec![1; 15], vec![2; 25]].concat();
        assert_eq!(km.labels, want);
        assert_eq!(km.centroids.len(), 3);
        assert!((km.centroids[1][0] + 5.0).abs() < 0.5, "{:?}", km.centroids);
        assert!(km.inertia > 0.0 && km.inertia < 60.0 * 2.0, "{}", km.inertia);
    }

    #[test]
    fn same_seed_same_result_and_restarts_never_hurt() {
        let points = blobs(&[[0.0, 0.0], [3.0, 0.0], [0.0, 3.0], [3.0, 3.0]], &[10, 10, 10, 10], 1.4, 11);
        let a = kmeans(&points, 4, 42, 3).unwrap();
        assert_eq!(a, kmeans(&points, 4, 42, 3).unwrap());
        // Five restarts include the single run of the same stream, so they can only do better.
        let one = kmeans(&points, 4, 42, 1).unwrap();
        let five = kmeans(&points, 4, 42, 5).unwrap();
        assert!(five.inertia <= one.inertia);
    }

    #[test]
    fn degenerate_inputs() {
        // Fewer distinct points than k: the empty clusters are dropped.
        let same = vec![vec![1.0, 1.0]; 6];
        let km = kmeans(&same, 3, 0, 2).unwrap();
        assert_eq!(km.labels, vec![0; 6]);
        assert_eq!(km.centroids.len(), 1);
        assert_eq!(km.inertia, 0.0);
        let one = kmeans(&[vec![2.0]], 1, 0, 1).unwrap();
        assert_eq!(one.labels, vec![0]);
        assert!(matches!(kmeans(&same, 7, 0, 1), Err(SegmentError::TooFewFrames { k: 7, frames: 6 })));
        assert!(matches!(kmeans(&same, 0, 0, 1), Err(SegmentError::ZeroK)));
        assert!(matches!(kmeans(&[], 1, 0, 1), Err(SegmentError::Empty)));
    }
}
