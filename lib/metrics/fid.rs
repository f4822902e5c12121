//! Fréchet distance between two sets of feature vectors (the "FID" of motion papers).
//!
//! FID = ‖μ₁ − μ₂‖² + tr(Σ₁ + Σ₂ − 2 (Σ₁^½ Σ₂ Σ₁^½)^½), the Fréchet distance between two
//! Gaussians fitted to the real (1) and generated (2) sets. The textbook code computes the last
//! term as `sqrtm(Σ₁ Σ₂)` in complex arithmetic and keeps the real part; Σ₁Σ₂ has the same
//! eigenvalues as the symmetric Σ₁^½ Σ₂ Σ₁^½, so we take the square roots of those instead:
//! real, stable, and defined for singular covariances. Eigenvalues within rounding of zero
//! (tiny negatives included) count as zero, and the result is clamped at 0.
//!
//! Motion2Motion scores transfers with the FID of kinetic features; the recipe it inherits
//! (Bailando's `calc_metrics`, see docs/reference/motion2motion.md §3.7) first normalises both sets
//! by the **real** set's per-dimension mean and population std. [`FidOptions::normalise`]
//! does that (default on). Definitions and deviations: `docs/metrics.md`.

use super::MetricError;
use crate::linalg::{covariance, eigen_tolerance, matmul, sqrtm_psd, symmetric_eigenvalues, trace};

/// A real-set dimension whose std is at most this fraction of max(1, |mean|) is constant:
/// normalisation centres it but does not divide by its (zero) spread.
pub const CONSTANT_DIM_TOLERANCE: f64 = 1e-9;

#[derive(Clone, Debug, serde::Serialize)]
pub struct FidOptions {
    /// Normalise both sets by the real set's per-dimension mean and population std first
    /// (Motion2Motion / Bailando). Constant dimensions are centred only.
    pub normalise: bool,
}

impl Default for FidOptions {
    fn default() -> Self {
        FidOptions { normalise: true }
    }
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Fid {
    /// The Fréchet distance (≥ 0; in squared feature units, or squared real-set stds when
    /// normalised).
    pub value: f64,
    /// Vectors in the real and generated sets.
    pub real: usize,
    pub generated: usize,
    /// Length of every vector.
    pub dims: usize,
    /// Dimensions with no spread in the real set (not divided by their std when normalising).
    pub constant_dims: usize,
}

/// The Fréchet distance between `real` and `generated` feature vectors.
///
/// Errors: an empty set or zero-length vectors (`TooLittle`), vectors of different lengths
/// (`Mismatch`, naming the set and row), a NaN or infinity (`NonFinite`, naming set, row and
/// column). A set of one vector has zero covariance (numpy would give NaN), so the distance
/// is then that of the means plus the other set's spread.
pub fn fid(real: &[Vec<f64>], generated: &[Vec<f64>], opts: &FidOptions) -> Result<Fid, MetricError> {
    let dims = check_set("real", real, None)?;
    check_set("generated", generated, Some(dims))?;

    let (mut real_rows, mut gen_rows) = (real.to_vec(), generated.to_vec());
    let mut constant_dims = 0;
    let n = real.len() as f64;
    let mean: Vec<f64> = (0..dims).map(|j| real.iter().map(|r| r[j]).sum::<f64>() / n).collect();
    for j in 0..dims {
        let var = real.iter().map(|r| (r[j] - mean[j]).powi(2)).sum::<f64>() / n;
        let std = var.sqrt();
        let constant = std <= CONSTANT_DIM_TOLERANCE * mean[j].abs().max(1.0);
        constant_dims += usize::from(constant);
        if opts.normalise {
            let scale = if constant { 1.0 } else { 1.0 / std };
            for r in real_rows.iter_mut().chain(gen_rows.iter_mut()) {
                r[j] = (r[j] - mean[j]) * scale;
            }
        }
    }

    let (mu1, s1) = covariance(&real_rows);
    let (mu2, s2) = covariance(&gen_rows);
    let value = frechet_distance(&mu1, &s1, &mu2, &s2, dims);
    Ok(Fid { value, real: real.len(), generated: generated.len(), dims, constant_dims })
}

/// ‖μ₁ − μ₂‖² + tr Σ₁ + tr Σ₂ − 2 Σᵢ √λᵢ(Σ₁^½ Σ₂ Σ₁^½), clamped at 0. Inputs finite, `dims`
/// long means and `dims × dims` covariances.
pub fn frechet_distance(mu1: &[f64], s1: &[f64], mu2: &[f64], s2: &[f64], dims: usize) -> f64 {
    let mean_term: f64 = mu1.iter().zip(mu2).map(|(a, b)| (a - b) * (a - b)).sum();
    let root1 = sqrtm_psd(s1, dims);
    let mut m = matmul(&matmul(&root1, s2, dims), &root1, dims);
    // Symmetrise away the rounding of the two products.
    for i in 0..dims {
        for j in 0..i {
            let v = 0.5 * (m[i * dims + j] + m[j * dims + i]);
            m[i * dims + j] = v;
            m[j * dims + i] = v;
        }
    }
    let values = symmetric_eigenvalues(&m, dims);
    let tol = eigen_tolerance(&values);
    let cross: f64 = values.iter().map(|&v| if v > tol { v.sqrt() } else { 0.0 }).sum();
    let value = mean_term + trace(s1, dims) + trace(s2, dims) - 2.0 * cross;
    if value.is_finite() {
        value.max(0.0)
    } else {
        0.0
    }
}

/// Checks a set's shape and values; returns its vector length.
fn check_set(set: &str, rows: &[Vec<f64>], dims: Option<usize>) -> Result<usize, MetricError> {
    let Some(first) = rows.first() else {
        return Err(MetricError::TooLittle(format!("FID: the {set} set is empty (need at least one feature vector)")));
    };
    let want = dims.unwrap_or(first.len());
    if want == 0 {
        return Err(MetricError::TooLittle(format!("FID: the {set} set's feature vectors are empty")));
    }
    for (i, r) in rows.iter().enumerate() {
        if r.len() != want {
            return Err(MetricError::Mismatch(format!("FID: {set} row {i} has {} values, expected {want} (the length of real row 0)", r.len())));
        }
        if let Some(j) = r.iter().position(|v| !v.is_finite()) {
            return Err(MetricError::NonFinite(format!("FID: {set} row {i} column {j} is {}", r[j])));
        }
    }
    Ok(want)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn random_set(n: usize, dims: usize, shift: f64, seed: u64) -> Vec<Vec<f64>> {
        let mut rng = SplitMix64::new(seed);
        (0..n).map(|_| (0..dims).map(|j| rng.range(-1.0, 1.0) * (1.0 + j as f64) + shift).collect()).collect()
    }

    #[test]
    fn identical_sets_score_zero() {
        let a = random_set(50, 6, 0.0, 1);
        for normalise in [true, false] {
            let f = fid(&a, &a, &FidOptions { normalise }).unwrap();
            assert!(f.value.abs() < 1e-9, "{f:?}");
            assert_eq!((f.real, f.generated, f.dims, f.constant_dims), (50, 50, 6, 0));
        }
    }

    #[test]
    fn shifted_set_scores_the_squared_shift() {
        // Same covariance, means apart by 2 in each of 3 dims: FID = 3 · 2² (unnormalised).
        let a = random_set(40, 3, 0.0, 2);
        let b: Vec<Vec<f64>> = a.iter().map(|r| r.iter().map(|x| x + 2.0).collect()).collect();
        let f = fid(&a, &b, &FidOptions { normalise: false }).unwrap();
        assert!((f.value - 12.0).abs() < 1e-9, "{f:?}");
    }

    #[test]
    fn one_dimensional_gaussians_match_the_closed_form() {
        // 1-D: (μ1 − μ2)² + (σ1 − σ2)² with sample stds.
        let a = vec![vec![0.0], vec![2.0]];
        let b = vec![vec![1.0], vec![5.0]];
        let f = fid(&a, &b, &FidOptions { normalise: false }).unwrap();
        let (s1, s2) = (2.0f64.sqrt(), 8.0f64.sqrt());
        let want = (1.0 - 3.0f64).powi(2) + (s1 - s2).powi(2);
        assert!((f.value - want).abs() < 1e-12, "{} vs {want}", f.value);
    }

    #[test]
    fn tiny_singular_and_constant_inputs_have_defined_values() {
        let one = vec![vec![1.0, 2.0, 3.0]];
        let f = fid(&one, &one, &FidOptions::default()).unwrap();
        assert_eq!(f.value, 0.0);
        assert_eq!(f.constant_dims, 3);
        // A constant real dimension and a generated set that varies there: finite, positive.
        let real: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64, 5.0]).collect();
        let gen: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64, 5.0 + (i % 2) as f64]).collect();
        let f = fid(&real, &gen, &FidOptions::default()).unwrap();
        assert_eq!(f.constant_dims, 1);
        assert!(f.value.is_finite() && f.value > 0.0, "{f:?}");
        // Fewer samples than dims: singular covariances, still finite and ≥ 0.
        let a = random_set(3, 8, 0.0, 3);
        let b = random_set(4, 8, 0.5, 4);
        let f = fid(&a, &b, &FidOptions::default()).unwrap();
        assert!(f.value.is_finite() && f.value >= 0.0, "{f:?}");
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        let ok = vec![vec![1.0, 2.0]];
        assert!(matches!(fid(&[], &ok, &FidOptions::default()), Err(MetricError::TooLittle(_))));
        assert!(matches!(fid(&ok, &[], &FidOptions::default()), Err(MetricError::TooLittle(_))));
        assert!(matches!(fid(&[vec![]], &[vec![]], &FidOptions::default()), Err(MetricError::TooLittle(_))));
        let short = vec![vec![1.0]];
        assert!(matches!(fid(&ok, &short, &FidOptions::default()), Err(MetricError::Mismatch(_))));
        let nan = vec![vec![1.0, 2.0], vec![0.0, f64::NAN]];
        match fid(&ok, &nan, &FidOptions::default()) {
            Err(MetricError::NonFinite(m)) => assert!(m.contains("generated row 1 column 1"), "{m}"),
            other => panic!("{other:?}"),
        }
    }
}
