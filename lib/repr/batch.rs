//! Feature files back to motion: the samples of one NPY, and the decoder that poses them.
//!
//! `mo-encode --decode` and every tool that looks at features (`mo-render`, `mo-metrics`,
//! `input::read_motions`) go through this one decoder, so an NPY decodes to the same joint
//! positions everywhere, and a batch is checked whole before any of it is decoded. Errors are
//! sentences for the one-line message (the caller adds the file name and the skeleton's).

use super::anytop::{self, AnyTopRig, AnyTopStats, IkOptions, Placement};
use super::{m2m, Features};
use crate::io::npy::NpyArray;
use crate::motion::Motion;
use crate::skeleton::Skeleton;
use std::borrow::Cow;

/// Where AnyTop decoding takes the rotations from (also the tools' `--from`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PoseFrom {
    /// The features' 6D rotations: exact for encoded features.
    Rotations,
    /// The features' joint positions, by inverse kinematics: for generated features.
    Positions,
}

/// How the samples of one NPY go back to motion.
pub enum FeatureDecoder {
    M2m,
    AnyTop {
        rig: Box<AnyTopRig>,
        /// Undo `--normalise` first.
        stats: Option<AnyTopStats>,
        /// One per sample.
        placements: Vec<Placement>,
        from: PoseFrom,
    },
}

impl FeatureDecoder {
    /// Shape and value checks, so a batch is refused before anything is written; on failure,
    /// what is wrong and a hint (may be empty).
    pub fn check(&self, features: &Features, skeleton: &Skeleton) -> Result<(), (String, &'static str)> {
        match self {
            FeatureDecoder::M2m => m2m::check(features, skeleton).map_err(|e| {
                let hint = if features.dims == anytop::FEATURE_DIMS { ": AnyTop features? decode them without --repr m2m" } else { "" };
                (e.to_string(), hint)
            }),
            FeatureDecoder::AnyTop { .. } => check_anytop(features, skeleton),
        }
    }

    /// The representation's name, as `--repr` spells it.
    pub fn repr_name(&self) -> &'static str {
        match self {
            FeatureDecoder::M2m => "m2m",
            FeatureDecoder::AnyTop { .. } => "anytop",
        }
    }

    /// Decode sample `i`; a motion with a NaN or an infinity (a placement or features too large
    /// to pose) is an error, never a BVH that no reader takes.
    pub fn decode(&self, i: usize, features: &Features, skeleton: &Skeleton) -> Result<Motion, String> {
        let motion = self.decode_unchecked(i, features, skeleton)?;
        match motion.first_non_finite() {
            Some((frame, joint)) => Err(format!(
                "decoding gives a non-finite pose at frame {frame}, joint {joint} '{}' (the features or the placement hold numbers too large)",
                skeleton.joints.get(joint).map_or("?", |j| j.name.as_str())
            )),
            None => Ok(motion),
        }
    }

    fn decode_unchecked(&self, i: usize, features: &Features, skeleton: &Skeleton) -> Result<Motion, String> {
        match self {
            FeatureDecoder::M2m => m2m::decode(features, skeleton).map_err(|e| e.to_string()),
            FeatureDecoder::AnyTop { rig, stats, placements, from } => {
                let features = match stats {
                    Some(stats) => {
                        let mut f = features.clone();
                        stats.denormalise(&mut f).map_err(|e| format!("cannot undo the normalisation: {e}"))?;
                        Cow::Owned(f)
                    }
                    None => Cow::Borrowed(features),
                };
                let placement = &placements[i];
                match from {
                    PoseFrom::Rotations => rig.decode(skeleton, &features, placement),
                    PoseFrom::Positions => rig.decode_ik(skeleton, &features, placement, &IkOptions::default()),
                }
                .map_err(|e| e.to_string())
            }
        }
    }
}

/// AnyTop's shape and value checks, worded like m2m's.
fn check_anytop(features: &Features, skeleton: &Skeleton) -> Result<(), (String, &'static str)> {
    if features.dims != anytop::FEATURE_DIMS {
        let hint = if features.dims == m2m::DIMS { ": Motion2Motion features? decode them with --repr m2m" } else { "" };
        return Err((format!("AnyTop features have {} dims per joint, found {}", anytop::FEATURE_DIMS, features.dims), hint));
    }
    if features.joints != skeleton.len() {
        return Err((format!("the features have {} joints but the skeleton has {}", features.joints, skeleton.len()), ""));
    }
    if let Some((frame, joint, dim)) = features.first_non_finite() {
        let value = features.at(frame, joint)[dim];
        let name = &skeleton.joints[joint].name;
        return Err((format!("non-finite value {value} at frame {frame}, joint {joint} '{name}', dim {dim}"), ""));
    }
    Ok(())
}

/// Rank 3 -> one motion; rank 4 -> one per sample (`true`: the input was a batch).
pub fn split_samples(array: NpyArray, name: &str) -> Result<(Vec<Features>, bool), String> {
    match array.shape.as_slice() {
        shape if shape.len() >= 3 && shape[shape.len() - 3] == 0 => Err(format!("{name}: the features hold no frames (shape {shape:?})")),
        &[frames, joints, dims] => Ok((vec![Features { frames, joints, dims, data: array.data }], false)),
        &[n, frames, joints, dims] => {
            if n == 0 {
                return Err(format!("{name}: the batch holds no samples (shape {:?})", array.shape));
            }
            let per = frames * joints * dims;
            let samples = (0..n).map(|i| Features { frames, joints, dims, data: array.data[i * per..(i + 1) * per].to_vec() }).collect();
            Ok((samples, true))
        }
        shape => {
            Err(format!("{name}: expected a [frames, joints, dims] or [samples, frames, joints, dims] array, found shape {shape:?} (rank {})", shape.len()))
        }
    }
}

/// Features of clips (`names`, in the same order) that stack into one NPY batch: one shape
/// for all, else which two differ.
pub fn check_stackable(names: &[&str], features: &[Features]) -> Result<(), String> {
    let first = &features[0];
    for (name, f) in names.iter().zip(features).skip(1) {
        if f.shape() != first.shape() {
            return Err(format!(
                "cannot stack {} {:?} and {name} {:?}: a batch needs the same frames and joints (encode them separately, or cut the clips to one length)",
                names[0],
                first.shape(),
                f.shape()
            ));
        }
    }
    Ok(())
}

/// Every value finite, else where the first one is not: float32 features hold what a motion's
/// f64 numbers became, and 1e300 is inf there.
pub fn check_finite<'a>(names: &[&str], skeletons: impl IntoIterator<Item = &'a Skeleton>, features: &[Features]) -> Result<(), String> {
    for ((name, skeleton), f) in names.iter().zip(skeletons).zip(features) {
        if let Some((frame, joint, dim)) = f.first_non_finite() {
            let value = f.at(frame, joint)[dim];
            let joint_name = skeleton.joints.get(joint).map_or("?", |j| j.name.as_str());
            return Err(format!(
                "{name}: encodes to {value} at feature frame {frame}, joint {joint} '{joint_name}', dim {dim}: the motion holds numbers too large for float32 features"
            ));
        }
    }
    Ok(())
}
