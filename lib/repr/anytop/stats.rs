//! Per-skeleton normalisation statistics (docs/reference/anytop.md §1.8), with the reference's std
//! grouping.
//!
//! * mean: per joint and feature, over every frame of every clip;
//! * std: the population std per joint and feature, then grouped as the reference does since
//!   commit `f2e3465`: the root's positions (0..3), rotation (3..9) and velocity (9..12) each
//!   share the mean of their stds; all non-root joints share one value per group (the mean
//!   over those joints and dims); contact (12): non-zero stds are replaced by their common
//!   mean, zero stds by 1;
//! * normalise x̂ = (x − mean)/(std + ε), denormalise x = x̂·(std + ε) + mean, ε = 1e-6, all 13
//!   dims. Unlike the reference, std never drifts (§9.5) and both ways use the same ε.

use super::{AnyTopError, DIMS_POSITION, DIMS_ROTATION, DIMS_VELOCITY, DIM_CONTACT, FEATURE_DIMS, STD_EPSILON};
use crate::repr::Features;
use serde::{Deserialize, Serialize};

/// Mean and grouped std, `[joints * 13]` row-major (joint-major, feature fastest).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnyTopStats {
    pub mean: Vec<f32>,
    pub std: Vec<f32>,
}

impl AnyTopStats {
    /// Statistics over all frames of clips of one skeleton.
    pub fn compute<'a>(clips: impl IntoIterator<Item = &'a Features>) -> Result<AnyTopStats, AnyTopError> {
        let clips: Vec<&Features> = clips.into_iter().collect();
        let Some(first) = clips.first() else { return Err(AnyTopError::NoFrames) };
        let joints = first.joints;
        for c in &clips {
            if c.dims != FEATURE_DIMS {
                return Err(AnyTopError::Dims(c.dims));
            }
            if c.joints != joints {
                return Err(AnyTopError::JointCount { what: "a clip", got: c.joints, expected: joints });
            }
        }
        let width = joints * FEATURE_DIMS;
        let count: usize = clips.iter().map(|c| c.frames).sum();
        if count == 0 {
            return Err(AnyTopError::NoFrames);
        }
        let mut sum = vec![0.0f64; width];
        for c in &clips {
            for row in c.data.chunks_exact(width) {
                for (s, &x) in sum.iter_mut().zip(row) {
                    *s += x as f64;
                }
            }
        }
        let mean: Vec<f64> = sum.iter().map(|s| s / count as f64).collect();
        let mut var = vec![0.0f64; width];
        for c in &clips {
            for row in c.data.chunks_exact(width) {
                for ((v, &x), m) in var.iter_mut().zip(row).zip(&mean) {
                    *v += (x as f64 - m) * (x as f64 - m);
                }
            }
        }
        let mut std: Vec<f64> = var.iter().map(|v| (v / count as f64).sqrt()).collect();
        group_std(&mut std, joints);
        Ok(AnyTopStats { mean: mean.iter().map(|&m| m as f32).collect(), std: std.iter().map(|&s| s as f32).collect() })
    }

    pub fn joints(&self) -> usize {
        self.mean.len() / FEATURE_DIMS
    }

    /// Check shapes and numbers (statistics come from files).
    pub fn check(&self, joints: usize) -> Result<(), AnyTopError> {
        if self.mean.len() != self.std.len() || !self.mean.len().is_multiple_of(FEATURE_DIMS) {
            return Err(AnyTopError::BadStats("mean and std must both hold joints x 13 values".into()));
        }
        if self.joints() != joints {
            return Err(AnyTopError::JointCount { what: "the statistics", got: self.joints(), expected: joints });
        }
        if self.mean.iter().chain(&self.std).any(|v| !v.is_finite()) || self.std.iter().any(|&s| s < 0.0) {
            return Err(AnyTopError::BadStats("non-finite mean or negative std".into()));
        }
        Ok(())
    }

    /// `[joints * 13]` values from one row for the root and one that every other joint shares
    /// (the grouping of the spreads above).
    pub fn grouped_rows(root: &[f32], others: &[f32], joints: usize) -> Vec<f32> {
        (0..joints).flat_map(|j| if j == 0 { root } else { others }).copied().collect()
    }

    /// x̂ = (x − mean)/(std + ε), in place.
    pub fn normalise(&self, features: &mut Features) -> Result<(), AnyTopError> {
        self.apply(features, |x, m, s| (x - m) / (s + STD_EPSILON))
    }

    /// x = x̂·(std + ε) + mean, in place.
    pub fn denormalise(&self, features: &mut Features) -> Result<(), AnyTopError> {
        self.apply(features, |x, m, s| x * (s + STD_EPSILON) + m)
    }

    fn apply(&self, features: &mut Features, f: impl Fn(f32, f32, f32) -> f32) -> Result<(), AnyTopError> {
        if features.dims != FEATURE_DIMS {
            return Err(AnyTopError::Dims(features.dims));
        }
        self.check(features.joints)?;
        for row in features.data.chunks_exact_mut(self.mean.len()) {
            for ((x, &m), &s) in row.iter_mut().zip(&self.mean).zip(&self.std) {
                *x = f(*x, m, s);
            }
        }
        Ok(())
    }
}

/// The reference's grouping of per-element stds (module doc), in place.
fn group_std(std: &mut [f64], joints: usize) {
    let at = |j: usize, d: usize| j * FEATURE_DIMS + d;
    for range in [DIMS_POSITION, DIMS_ROTATION, DIMS_VELOCITY] {
        if joints == 0 {
            break;
        }
        let root = range.clone().map(|d| std[at(0, d)]).sum::<f64>() / range.len() as f64;
        for d in range.clone() {
            std[at(0, d)] = root;
        }
        if joints > 1 {
            let total: f64 = (1..joints).flat_map(|j| range.clone().map(move |d| (j, d))).map(|(j, d)| std[at(j, d)]).sum();
            let shared = total / ((joints - 1) * range.len()) as f64;
            for j in 1..joints {
                for d in range.clone() {
                    std[at(j, d)] = shared;
                }
            }
        }
    }
    let nonzero: Vec<f64> = (0..joints).map(|j| std[at(j, DIM_CONTACT)]).filter(|&s| s != 0.0).collect();
    let common = if nonzero.is_empty() { 1.0 } else { nonzero.iter().sum::<f64>() / nonzero.len() as f64 };
    for j in 0..joints {
        let s = &mut std[at(j, DIM_CONTACT)];
        *s = if *s == 0.0 { 1.0 } else { common };
    }
}
