//! Principal component analysis of per-frame feature vectors, on the repository's own symmetric
//! eigen solver (`linalg`): no linear-algebra dependency for one small decomposition.
//!
//! Of the two equivalent routes the cheaper one is taken: the `d × d` covariance when there are
//! at least as many frames as dimensions, else the `n × n` Gram matrix of the centred frames
//! (a 200-frame clip of a 65-joint skeleton has 845 raw dimensions; its Gram matrix is 200²).
//! Both give the same projections up to each component's sign, which is then fixed (see
//! `fix_signs`) so that the output does not depend on the route or on rounding.

use super::{check_frames, SegmentError};
use crate::linalg::symmetric_eigen;

/// Frames projected on the leading principal components.
#[derive(Clone, Debug, PartialEq)]
pub struct Pca {
    /// One row per frame, `dims` values each (component 0 first, the largest variance).
    pub projections: Vec<Vec<f64>>,
    /// Components kept: the requested count, clamped to the number of dimensions and frames.
    pub dims: usize,
    /// Fraction of the total variance the kept components explain, in [0, 1]; 1 when the
    /// frames do not vary at all (nothing is left unexplained).
    pub explained: f64,
}

/// Centre `frames` (one feature vector per frame, all the same length) and project them on
/// their top `dims` principal components. `dims` larger than the data's rank is clamped to the
/// number of dimensions and of frames; components beyond the rank project to zeros. Errors on
/// no frames, `dims == 0`, ragged rows or non-finite values.
pub fn pca(frames: &[Vec<f64>], dims: usize) -> Result<Pca, SegmentError> {
    let d = check_frames(frames)?;
    if dims == 0 {
        return Err(SegmentError::ZeroDims);
    }
    let n = frames.len();
    let keep = dims.min(d).min(n);
    let mean: Vec<f64> = (0..d).map(|j| frames.iter().map(|f| f[j]).sum::<f64>() / n as f64).collect();
    let centred: Vec<Vec<f64>> = frames.iter().map(|f| f.iter().zip(&mean).map(|(x, m)| x - m).collect()).collect();

    let (values, mut projections): (Vec<f64>, Vec<Vec<f64>>) = if d <= n {
        // Scatter matrix XᵀX (the 1/n of a covariance cancels in every ratio used here).
        let mut scatter = vec![0.0; d * d];
        for row in &centred {
            for i in 0..d {
                let xi = row[i];
                if xi == 0.0 {
                    continue;
                }
                let line = &mut scatter[i * d..(i + 1) * d];
                for (s, &xj) in line[i..].iter_mut().zip(&row[i..]) {
                    *s += xi * xj;
                }
            }
        }
        for i in 0..d {
            for j in 0..i {
                scatter[i * d + j] = scatter[j * d + i];
            }
        }
        let (values, vectors) = symmetric_eigen(&scatter, d);
        let projections = centred
            .iter()
            .map(|row| {
                (0..keep)
                    .map(|c| {
                        let k = d - 1 - c;
                        row.iter().zip(&vectors[k * d..(k + 1) * d]).map(|(x, v)| x * v).sum()
                    })
                    .collect()
            })
            .collect();
        (values, projections)
    } else {
        // Gram matrix XXᵀ: its eigenvalues are the scatter's non-zero ones, and frame i's
        // coordinate on component k is sqrt(λ_k) u_k[i].
        let mut gram = vec![0.0; n * n];
        for i in 0..n {
            for j in i..n {
                let g: f64 = centred[i].iter().zip(&centred[j]).map(|(a, b)| a * b).sum();
                gram[i * n + j] = g;
                gram[j * n + i] = g;
            }
        }
        let (values, vectors) = symmetric_eigen(&gram, n);
        let scale: Vec<f64> = (0..keep).map(|c| values[n - 1 - c].max(0.0).sqrt()).collect();
        let projections = (0..n).map(|i| (0..keep).map(|c| scale[c] * vectors[(n - 1 - c) * n + i]).collect()).collect();
        (values, projections)
    };
    fix_signs(&mut projections, keep);

    // Rounding can leave tiny negative eigenvalues; they carry no variance.
    let total: f64 = values.iter().map(|v| v.max(0.0)).sum();
    let top: f64 = values.iter().rev().take(keep).map(|v| v.max(0.0)).sum();
    let explained = if total > 0.0 { (top / total).clamp(0.0, 1.0) } else { 1.0 };
    Ok(Pca { projections, dims: keep, explained })
}

/// An eigenvector's sign is arbitrary; make each component's largest-magnitude coordinate
/// positive (the first one on ties), so both routes and any rounding give the same output.
fn fix_signs(projections: &mut [Vec<f64>], dims: usize) {
    for c in 0..dims {
        let mut best = 0.0f64;
        let mut sign = 1.0;
        for row in projections.iter() {
            if row[c].abs() > best {
                best = row[c].abs();
                sign = row[c].signum();
            }
        }
        if sign < 0.0 {
            for row in projections.iter_mut() {
                row[c] = -row[c];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: usize) -> Vec<Vec<f64>> {
        // Points along (1, 2, 0) with a little spread along (0, 0, 1).
        (0..n)
            .map(|i| {
                let t = i as f64 - (n as f64 - 1.0) / 2.0;
                vec![t, 2.0 * t, 0.1 * if i % 2 == 0 { 1.0 } else { -1.0 }]
            })
            .collect()
    }

    #[test]
    fn first_component_follows_the_main_direction() {
        let p = pca(&line(11), 1).unwrap();
        assert_eq!(p.dims, 1);
        assert!(p.explained > 0.99 && p.explained <= 1.0, "{}", p.explained);
        // Coordinates along the unit direction (1, 2, 0) / sqrt(5): t * sqrt(5), sign fixed.
        let want: Vec<f64> = (0..11).map(|i| (i as f64 - 5.0) * 5f64.sqrt()).collect();
        for (row, w) in p.projections.iter().zip(&want) {
            assert!((row[0].abs() - w.abs()).abs() < 1e-9, "{} vs {w}", row[0]);
        }
    }

    #[test]
    fn covariance_and_gram_routes_agree() {
        // 5 frames of 4 dims take the covariance route; the same frames with a zero and a
        // constant column appended (6 dims > 5 frames) take the Gram route and must agree.
        let frames: Vec<Vec<f64>> =
            vec![vec![1.0, 0.0, 2.0, 5.0], vec![0.0, 1.0, 1.0, 3.0], vec![3.0, 1.0, 0.0, 1.0], vec![2.0, 2.0, 2.0, 0.0], vec![0.5, 4.0, 1.0, 2.0]];
        let cov = pca(&frames, 3).unwrap();
        let wide: Vec<Vec<f64>> = frames.iter().map(|f| [f.as_slice(), &[0.0, 7.0]].concat()).collect();
        let gram = pca(&wide, 3).unwrap();
        assert!((cov.explained - gram.explained).abs() < 1e-9);
        for (a, b) in cov.projections.iter().zip(&gram.projections) {
            for (x, y) in a.iter().zip(b) {
                assert!((x - y).abs() < 1e-8, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn degenerate_inputs_do_not_panic_or_give_nan() {
        let one = pca(&[vec![1.0, 2.0, 3.0]], 8).unwrap();
        assert_eq!(one.dims, 1);
        assert_eq!(one.projections, vec![vec![0.0]]);
        assert_eq!(one.explained, 1.0);
        let constant = pca(&vec![vec![4.0, 4.0]; 10], 2).unwrap();
        assert!(constant.projections.iter().flatten().all(|v| *v == 0.0));
        assert_eq!(constant.explained, 1.0);
        let p = pca(&line(6), 50).unwrap();
        assert_eq!(p.dims, 3);
        assert!(p.projections.iter().flatten().all(|v| v.is_finite()));
        assert!(matches!(pca(&[], 2), Err(SegmentError::Empty)));
        assert!(matches!(pca(&line(3), 0), Err(SegmentError::ZeroDims)));
        assert!(matches!(pca(&[vec![1.0], vec![1.0, 2.0]], 1), Err(SegmentError::Ragged { frame: 1, .. })));
        assert!(matches!(pca(&[vec![f64::NAN]], 1), Err(SegmentError::NonFinite { frame: 0, dim: 0 })));
    }
}
