//! Dense symmetric linear algebra for the metrics' FID and the segmenter's PCA:
//! eigen-decomposition, covariance and the square root of a positive semi-definite matrix, all
//! in f64.
//!
//! The Fréchet distance needs the trace of a matrix square root. The usual recipe
//! (`scipy.linalg.sqrtm(S1 @ S2)`, then the real part) goes through a complex Schur form of a
//! non-symmetric product; everything here stays symmetric instead, so eigenvalues are real by
//! construction and no complex arithmetic is needed. The decomposition is the classic one:
//! Householder reduction to tridiagonal form, then implicit QL iterations with Wilkinson-style
//! shifts, O(n³), which is plenty for feature sizes up to a few hundred.
//!
//! Matrices are square, row-major `Vec<f64>` of length `n * n`. Inputs are expected finite
//! (the metrics check that before calling); the functions never panic on any slice, but a
//! slice shorter than `n * n` is treated as if padded with zeros.

use rayon::prelude::*;

/// QL sweeps allowed per eigenvalue before giving up on it (textbook cases need 2–3; the cap
/// only guarantees termination on pathological input).
const MAX_QL_ITERATIONS: usize = 64;

/// Eigenvalues (ascending) and eigenvectors of the symmetric `n × n` matrix `a` (row-major).
///
/// Eigenvectors come back **column-major**: eigenvector `k` (unit length, for eigenvalue
/// `k`) is the contiguous slice `vectors[k * n..(k + 1) * n]`. Only the symmetric part
/// `(a + aᵀ) / 2` is used, so rounding asymmetry in the input does no harm.
pub fn symmetric_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let (values, vectors) = decompose(a, n, true);
    (values, vectors)
}

/// Eigenvalues (ascending) of the symmetric `n × n` matrix `a`, without the eigenvectors
/// (about half the work of [`symmetric_eigen`]).
pub fn symmetric_eigenvalues(a: &[f64], n: usize) -> Vec<f64> {
    decompose(a, n, false).0
}

fn decompose(a: &[f64], n: usize, want_vectors: bool) -> (Vec<f64>, Vec<f64>) {
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let at = |i: usize, j: usize| a.get(i * n + j).copied().unwrap_or(0.0);
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            m[i * n + j] = 0.5 * (at(i, j) + at(j, i));
        }
    }
    let (mut d, mut e, mut zt) = tridiagonalise(m, n, want_vectors);
    implicit_ql(&mut d, &mut e, &mut zt, n);

    // Sort ascending (stable on ties, so output is deterministic); `zt` already holds one
    // eigenvector per row.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| d[x].total_cmp(&d[y]));
    let values = order.iter().map(|&k| d[k]).collect();
    let mut vectors = Vec::new();
    if want_vectors {
        vectors.reserve(n * n);
        for &k in &order {
            vectors.extend_from_slice(&zt[k * n..(k + 1) * n]);
        }
    }
    (values, vectors)
}

/// Householder reduction: returns the diagonal `d`, the off-diagonal `e` (`e[i]` couples `i`
/// and `i + 1`, `e[n - 1] = 0`) and, when asked, Qᵀ (row-major; empty otherwise) with
/// `A = Q T Qᵀ`. Qᵀ rather than Q so that the QL rotations, which mix two columns of Q, touch
/// two contiguous rows.
fn tridiagonalise(mut a: Vec<f64>, n: usize, want_q: bool) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut q = vec![0.0; if want_q { n * n } else { 0 }];
    if want_q {
        for i in 0..n {
            q[i * n + i] = 1.0;
        }
    }
    let mut v = vec![0.0; n];
    let mut p = vec![0.0; n];
    let mut vq = vec![0.0; n];
    for k in 0..n.saturating_sub(2) {
        // Reflect x = a[k+1.., k] onto a multiple of the first unit vector.
        let lo = k + 1;
        let norm = (lo..n).map(|i| a[i * n + k] * a[i * n + k]).sum::<f64>().sqrt();
        if norm == 0.0 {
            continue;
        }
        let x0 = a[lo * n + k];
        let alpha = if x0 > 0.0 { -norm } else { norm };
        for i in lo..n {
            v[i] = a[i * n + k];
        }
        v[lo] -= alpha;
        let vv: f64 = (lo..n).map(|i| v[i] * v[i]).sum();
        if vv == 0.0 {
            continue;
        }
        let beta = 2.0 / vv;
        // Trailing block A ← H A H with H = I − β v vᵀ, done as A − v qᵀ − q vᵀ,
        // p = β A v, K = β vᵀp / 2, q = p − K v.
        for i in lo..n {
            p[i] = beta * (lo..n).map(|j| a[i * n + j] * v[j]).sum::<f64>();
        }
        let kk = 0.5 * beta * (lo..n).map(|i| v[i] * p[i]).sum::<f64>();
        for i in lo..n {
            p[i] -= kk * v[i];
        }
        for i in lo..n {
            for j in lo..n {
                a[i * n + j] -= v[i] * p[j] + p[i] * v[j];
            }
        }
        a[lo * n + k] = alpha;
        a[k * n + lo] = alpha;
        for i in lo + 1..n {
            a[i * n + k] = 0.0;
            a[k * n + i] = 0.0;
        }
        // Q ← Q H (H acts on indices lo..n), i.e. rows lo..n of Qᵀ: Qᵀ ← Qᵀ − β v (vᵀ Qᵀ).
        if want_q {
            vq.iter_mut().for_each(|x| *x = 0.0);
            for j in lo..n {
                for (x, qc) in vq.iter_mut().zip(&q[j * n..(j + 1) * n]) {
                    *x += v[j] * qc;
                }
            }
            for j in lo..n {
                let bv = beta * v[j];
                for (qc, x) in q[j * n..(j + 1) * n].iter_mut().zip(&vq) {
                    *qc -= bv * x;
                }
            }
        }
    }
    let d = (0..n).map(|i| a[i * n + i]).collect();
    let e = (0..n).map(|i| if i + 1 < n { a[(i + 1) * n + i] } else { 0.0 }).collect();
    (d, e, q)
}

/// Implicit QL on the tridiagonal (d, e); rotations are accumulated into the rows of `zt`
/// (eigenvector i ends up in row i), unless it is empty.
fn implicit_ql(d: &mut [f64], e: &mut [f64], zt: &mut [f64], n: usize) {
    for l in 0..n {
        let mut iterations = 0;
        loop {
            // The first negligible off-diagonal element at or after l splits the matrix.
            let mut m = l;
            while m + 1 < n {
                let dd = d[m].abs() + d[m + 1].abs();
                if e[m].abs() <= f64::EPSILON * dd {
                    break;
                }
                m += 1;
            }
            if m == l || iterations >= MAX_QL_ITERATIONS {
                break;
            }
            iterations += 1;
            // Shift from the leading 2×2 block's eigenvalue closer to d[l].
            let mut g = (d[l + 1] - d[l]) / (2.0 * e[l]);
            let mut r = g.hypot(1.0);
            g = d[m] - d[l] + e[l] / (g + if g >= 0.0 { r } else { -r });
            let (mut s, mut c, mut p) = (1.0f64, 1.0f64, 0.0f64);
            let mut deflated = false;
            let mut i = m;
            while i > l {
                i -= 1;
                let f = s * e[i];
                let b = c * e[i];
                r = f.hypot(g);
                e[i + 1] = r;
                if r == 0.0 {
                    // Underflow: the matrix split here; finish this sweep early.
                    d[i + 1] -= p;
                    e[m] = 0.0;
                    deflated = true;
                    break;
                }
                s = f / r;
                c = g / r;
                g = d[i + 1] - p;
                r = (d[i] - g) * s + 2.0 * c * b;
                p = s * r;
                d[i + 1] = g + p;
                g = c * r - b;
                if !zt.is_empty() {
                    let (head, tail) = zt.split_at_mut((i + 1) * n);
                    let row_i = &mut head[i * n..];
                    let row_i1 = &mut tail[..n];
                    for (zi, zi1) in row_i.iter_mut().zip(row_i1.iter_mut()) {
                        let (a, b) = (*zi, *zi1);
                        *zi1 = s * a + c * b;
                        *zi = c * a - s * b;
                    }
                }
            }
            if deflated {
                continue;
            }
            d[l] -= p;
            e[l] = g;
            e[m] = 0.0;
        }
    }
}

/// Per-column mean and sample covariance (divisor `n − 1`, as `numpy.cov`) of equally long
/// rows; covariance is `dims × dims` row-major.
///
/// One row gives a zero covariance (not numpy's NaN): a single sample has no spread. No rows
/// give empty vectors. Rows are assumed equally long (callers check; a short row reads as
/// zeros). Each entry is summed over rows in row order, so the result does not depend on the
/// thread count.
pub fn covariance(rows: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let Some(first) = rows.first() else { return (Vec::new(), Vec::new()) };
    let dims = first.len();
    let n = rows.len();
    let value = |r: &Vec<f64>, j: usize| r.get(j).copied().unwrap_or(0.0);
    let mut mean = vec![0.0; dims];
    for r in rows {
        for (j, m) in mean.iter_mut().enumerate() {
            *m += value(r, j);
        }
    }
    for m in &mut mean {
        *m /= n as f64;
    }
    // Centred data by column, so each covariance entry is a contiguous dot product.
    let mut columns = vec![0.0; dims * n];
    for (i, r) in rows.iter().enumerate() {
        for j in 0..dims {
            columns[j * n + i] = value(r, j) - mean[j];
        }
    }
    let mut cov = vec![0.0; dims * dims];
    if n > 1 {
        let denom = (n - 1) as f64;
        cov.par_chunks_mut(dims.max(1)).enumerate().for_each(|(i, row)| {
            let ci = &columns[i * n..(i + 1) * n];
            for (j, out) in row.iter_mut().enumerate() {
                let cj = &columns[j * n..(j + 1) * n];
                *out = ci.iter().zip(cj).map(|(x, y)| x * y).sum::<f64>() / denom;
            }
        });
    }
    (mean, cov)
}

/// Eigenvalues at or below this fraction of the largest magnitude are rounding noise of a
/// singular matrix, and are taken as zero (their square roots would otherwise add ~1e-8 each).
pub fn eigen_tolerance(values: &[f64]) -> f64 {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    largest * values.len().max(1) as f64 * f64::EPSILON
}

/// The symmetric square root of a positive semi-definite `n × n` matrix: V diag(√λ⁺) Vᵀ,
/// with eigenvalues below [`eigen_tolerance`] (including tiny negative ones from rounding)
/// taken as zero.
pub fn sqrtm_psd(a: &[f64], n: usize) -> Vec<f64> {
    let (values, vectors) = symmetric_eigen(a, n);
    let tol = eigen_tolerance(&values);
    let roots: Vec<f64> = values.iter().map(|&v| if v > tol { v.sqrt() } else { 0.0 }).collect();
    let mut out = vec![0.0; n * n];
    for (k, &r) in roots.iter().enumerate() {
        if r == 0.0 {
            continue;
        }
        let vk = &vectors[k * n..(k + 1) * n];
        for i in 0..n {
            let s = r * vk[i];
            for j in 0..n {
                out[i * n + j] += s * vk[j];
            }
        }
    }
    out
}

/// `a · b` for `n × n` row-major matrices.
pub fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    out.par_chunks_mut(n.max(1)).enumerate().for_each(|(i, row)| {
        for k in 0..n {
            let aik = a.get(i * n + k).copied().unwrap_or(0.0);
            if aik == 0.0 {
                continue;
            }
            for (j, o) in row.iter_mut().enumerate() {
                *o += aik * b.get(k * n + j).copied().unwrap_or(0.0);
            }
        }
    });
    out
}

/// Sum of the diagonal of an `n × n` row-major matrix.
pub fn trace(a: &[f64], n: usize) -> f64 {
    (0..n).map(|i| a.get(i * n + i).copied().unwrap_or(0.0)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_symmetric(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = crate::rng::SplitMix64::new(seed);
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let x = rng.range(-1.0, 1.0);
                a[i * n + j] = x;
                a[j * n + i] = x;
            }
        }
        a
    }

    /// ‖A v − λ v‖ and ‖VᵀV − I‖ for every pair.
    fn check(a: &[f64], n: usize, tol: f64) {
        let (values, vectors) = symmetric_eigen(a, n);
        assert_eq!(values.len(), n);
        for w in values.windows(2) {
            assert!(w[0] <= w[1], "ascending: {values:?}");
        }
        for k in 0..n {
            let v = &vectors[k * n..(k + 1) * n];
            for i in 0..n {
                let av: f64 = (0..n).map(|j| a[i * n + j] * v[j]).sum();
                assert!((av - values[k] * v[i]).abs() < tol, "residual at {k},{i}: {}", av - values[k] * v[i]);
            }
            for l in 0..n {
                let dot: f64 = (0..n).map(|i| v[i] * vectors[l * n + i]).sum();
                let want = if k == l { 1.0 } else { 0.0 };
                assert!((dot - want).abs() < tol, "orthonormality {k},{l}: {dot}");
            }
        }
    }

    #[test]
    fn eigen_decomposes_random_symmetric_matrices() {
        for (n, seed) in [(1, 1), (2, 2), (3, 3), (7, 4), (40, 5)] {
            check(&random_symmetric(n, seed), n, 1e-10);
        }
    }

    #[test]
    fn eigenvalues_alone_match_the_full_decomposition() {
        let a = random_symmetric(30, 9);
        let (full, _) = symmetric_eigen(&a, 30);
        let alone = symmetric_eigenvalues(&a, 30);
        for (x, y) in full.iter().zip(&alone) {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
        // Trace is preserved.
        let tr: f64 = alone.iter().sum();
        assert!((tr - trace(&a, 30)).abs() < 1e-10);
    }

    #[test]
    fn eigen_handles_diagonal_repeated_and_zero_matrices() {
        check(&[0.0; 16], 4, 1e-12);
        let mut diag = vec![0.0; 9];
        diag[0] = 3.0;
        diag[4] = 3.0;
        diag[8] = -1.0;
        let (values, _) = symmetric_eigen(&diag, 3);
        assert_eq!(values, vec![-1.0, 3.0, 3.0]);
        check(&diag, 3, 1e-12);
        // A 2×2 with known eigenvalues 1 and 3.
        let (values, _) = symmetric_eigen(&[2.0, 1.0, 1.0, 2.0], 2);
        assert!((values[0] - 1.0).abs() < 1e-14 && (values[1] - 3.0).abs() < 1e-14);
    }

    #[test]
    fn covariance_matches_hand_values_and_one_row_is_zero() {
        let rows = vec![vec![1.0, 2.0], vec![3.0, 2.0], vec![5.0, 8.0]];
        let (mean, cov) = covariance(&rows);
        assert_eq!(mean, vec![3.0, 4.0]);
        // centred x = (−2, 0, 2), y = (−2, −2, 4): var x = 8/2, var y = 24/2, cov = (4 + 0 + 8)/2
        assert_eq!(cov, vec![4.0, 6.0, 6.0, 12.0]);
        let (mean, cov) = covariance(&[vec![1.0, -2.0]]);
        assert_eq!(mean, vec![1.0, -2.0]);
        assert_eq!(cov, vec![0.0; 4]);
        assert_eq!(covariance(&[]), (vec![], vec![]));
    }

    #[test]
    fn sqrtm_squares_back_and_ignores_rounding_negatives() {
        // B Bᵀ is PSD of rank 2 in 4 dims.
        let b = [1.0, 0.0, 2.0, 1.0, 0.5, -1.0, 0.0, 3.0];
        let mut a = vec![0.0; 16];
        for i in 0..4 {
            for j in 0..4 {
                a[i * 4 + j] = b[i * 2] * b[j * 2] + b[i * 2 + 1] * b[j * 2 + 1];
            }
        }
        let r = sqrtm_psd(&a, 4);
        let rr = matmul(&r, &r, 4);
        for (x, y) in rr.iter().zip(&a) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
        assert!(r.iter().all(|x| x.is_finite()));
    }
}
