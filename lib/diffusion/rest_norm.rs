//! How the rest token P_S (the skeleton's rest pose, AnyTop's conditioning frame 0) is
//! normalised.
//!
//! AnyTop normalises P_S with the skeleton's motion statistics, like the motion. A skeleton
//! nobody measured gets the fallback statistics, whose mean is its rest pose, so its P_S is all
//! zeros: the model is told nothing of where its legs point or how long they are, only its
//! topology and joint names. Under `--fallback-stats all` every skeleton trains that way, and
//! the bundled spider (eight legs whose names tell little apart) lost its gait
//! (models/zoo-compact/unseen/MODEL_CARD.md). `Global` normalises P_S by statistics pooled
//! over the trained skeletons' rest rows instead (the root's row apart from the other
//! joints'), the same for every skeleton, seen or not, so the rest token always carries the
//! skeleton's shape.

use crate::repr::anytop::{AnyTopStats, FEATURE_DIMS};

/// What P_S is normalised by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum RestToken {
    /// The skeleton's own (or fallback) statistics, as the motion (upstream's way).
    #[default]
    Skeleton,
    /// Statistics pooled over the trained skeletons' rest rows (`RestNorm`).
    Global,
}

/// How a training set's rest tokens are normalised: a `RestToken` with the statistics it uses.
// Made once per training run (and copied with `data::Augmentation`): its 208 bytes cost nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum RestTokens {
    /// By each skeleton's statistics.
    #[default]
    Skeleton,
    /// By statistics pooled over the set's skeletons.
    Pool,
    /// By these (a resumed or fine-tuned model's).
    Given(RestNorm),
}

impl RestTokens {
    /// `token`, with the statistics a model already has (`known`) when it has them.
    pub fn of(token: RestToken, known: Option<RestNorm>) -> RestTokens {
        match (token, known) {
            (RestToken::Skeleton, _) => RestTokens::Skeleton,
            (RestToken::Global, Some(norm)) => RestTokens::Given(norm),
            (RestToken::Global, None) => RestTokens::Pool,
        }
    }

    pub fn token(&self) -> RestToken {
        match self {
            RestTokens::Skeleton => RestToken::Skeleton,
            RestTokens::Pool | RestTokens::Given(_) => RestToken::Global,
        }
    }
}

/// Mean and spread of the rest rows of the trained skeletons: row 0 the roots', row 1 every
/// other joint's.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RestNorm {
    pub mean: [[f32; FEATURE_DIMS]; 2],
    pub std: [[f32; FEATURE_DIMS]; 2],
}

impl RestNorm {
    /// The least spread of a value. Rest rows hold identity rotations and near-zero velocities
    /// on every zoo skeleton (spread 0), and a real file's rest frames can differ a little: at
    /// 0.05 such a difference reads as a few units, not millions.
    pub const STD_FLOOR: f32 = 0.05;

    /// Pool `rows` (`[joints * 13]` each, unnormalised P_S); `None` without a non-root joint.
    pub fn pool<'a>(rows: impl IntoIterator<Item = &'a [f32]>) -> Option<RestNorm> {
        let d = FEATURE_DIMS;
        let (mut roots, mut others): (Vec<&[f32]>, Vec<&[f32]>) = (Vec::new(), Vec::new());
        for row in rows {
            for (j, joint) in row.chunks_exact(d).enumerate() {
                if j == 0 {
                    roots.push(joint);
                } else {
                    others.push(joint);
                }
            }
        }
        if roots.is_empty() || others.is_empty() {
            return None;
        }
        let moments = |set: &[&[f32]]| {
            let n = set.len() as f64;
            let (mut mean, mut std) = ([0f32; FEATURE_DIMS], [0f32; FEATURE_DIMS]);
            for k in 0..d {
                let m = set.iter().map(|v| v[k] as f64).sum::<f64>() / n;
                let var = set.iter().map(|v| (v[k] as f64 - m).powi(2)).sum::<f64>() / n;
                mean[k] = m as f32;
                std[k] = (var.sqrt() as f32).max(Self::STD_FLOOR);
            }
            (mean, std)
        };
        let (root_mean, root_std) = moments(&roots);
        let (mean, std) = moments(&others);
        Some(RestNorm { mean: [root_mean, mean], std: [root_std, std] })
    }

    /// As statistics of a skeleton of `joints` joints, for `AnyTopStats::normalise`.
    pub fn for_joints(&self, joints: usize) -> AnyTopStats {
        AnyTopStats {
            mean: AnyTopStats::grouped_rows(&self.mean[0], &self.mean[1], joints),
            std: AnyTopStats::grouped_rows(&self.std[0], &self.std[1], joints),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_keeps_roots_apart_and_floors_the_spread() {
        let d = FEATURE_DIMS;
        // Two skeletons: 2 and 3 joints; value k of joint j is j + k, the root's 10k.
        let row =
            |joints: usize| -> Vec<f32> { (0..joints).flat_map(|j| (0..d).map(move |k| if j == 0 { 10.0 * k as f32 } else { (j + k) as f32 })).collect() };
        let (a, b) = (row(2), row(3));
        let norm = RestNorm::pool([a.as_slice(), b.as_slice()]).unwrap();
        // Roots alike: mean 10k, no spread, so the floor.
        assert_eq!(norm.mean[0][3], 30.0);
        assert!(norm.std[0].iter().all(|&s| s == RestNorm::STD_FLOOR));
        // Others: joints 1, 1, 2 -> mean 4/3 + k, population std sqrt(2)/3.
        assert!((norm.mean[1][2] - (4.0 / 3.0 + 2.0)).abs() < 1e-6);
        assert!((norm.std[1][5] - 2f32.sqrt() / 3.0).abs() < 1e-6);
        let stats = norm.for_joints(4);
        assert_eq!((stats.mean.len(), stats.std.len()), (4 * d, 4 * d));
        assert_eq!((&stats.mean[..d], &stats.mean[3 * d..]), (&norm.mean[0][..], &norm.mean[1][..]));
        assert!(RestNorm::pool([&a[..d]]).is_none(), "a lone root has no other joints to pool");
    }
}
