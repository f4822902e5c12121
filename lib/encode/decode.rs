//! The way back: a batch of feature samples decoded on a skeleton as motion files. Every
//! sample is checked before any is decoded, then all are decoded in parallel (in sample order,
//! whatever the thread count) and each becomes the file its path asks for, so a caller writes
//! all or nothing with `io::write_all`.

use crate::motion::write::{motion_file, MotionFormat, WriteError};
use crate::repr::anytop::AnyTopStats;
use crate::repr::batch::FeatureDecoder;
use crate::repr::Features;
use crate::skeleton::Skeleton;
use rayon::prelude::*;
use std::path::PathBuf;

/// Why samples could not be decoded; every message names the sample.
#[derive(Debug, thiserror::Error)]
pub enum DecodeError {
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// The samples of one NPY (`name`; `batch` when it held several) on one skeleton (`skeleton_name`).
pub struct Samples<'a> {
    pub name: &'a str,
    pub batch: bool,
    pub features: &'a [Features],
    pub skeleton: &'a Skeleton,
    pub skeleton_name: &'a str,
}

impl Samples<'_> {
    /// How messages name sample `i`.
    fn label(&self, i: usize) -> String {
        if self.batch {
            format!("{}: sample {i}", self.name)
        } else {
            self.name.to_string()
        }
    }

    /// Every sample fits `decoder` and the skeleton.
    pub fn check(&self, decoder: &FeatureDecoder) -> Result<(), DecodeError> {
        for (i, f) in self.features.iter().enumerate() {
            decoder.check(f, self.skeleton).map_err(|(e, hint)| {
                DecodeError::Invalid(format!("{}: {e} ({} features, skeleton {}){hint}", self.label(i), decoder.repr_name(), self.skeleton_name))
            })?;
        }
        Ok(())
    }

    /// Sample `i` decoded and written as the motion file `paths[i]` asks for (BVH on stdout).
    pub fn decode_files(&self, decoder: &FeatureDecoder, paths: &[Option<PathBuf>]) -> Result<Vec<Vec<u8>>, DecodeError> {
        let files: Vec<Result<Vec<u8>, DecodeError>> = self
            .features
            .par_iter()
            .enumerate()
            .map(|(i, f)| {
                let motion = decoder.decode(i, f, self.skeleton).map_err(|e| DecodeError::Invalid(format!("{}: {e}", self.label(i))))?;
                Ok(motion_file(self.skeleton, &motion, paths[i].as_deref(), MotionFormat::Bvh)?)
            })
            .collect();
        files.into_iter().collect()
    }
}

/// The statistics that undo a normalisation: the record's (`stats`, of `skeleton_name`) when
/// the features are `normalised`, none otherwise.
pub fn normalisation(stats: Option<AnyTopStats>, normalised: bool, skeleton_name: &str) -> Result<Option<AnyTopStats>, DecodeError> {
    match (normalised, stats) {
        (false, _) => Ok(None),
        (true, Some(stats)) => Ok(Some(stats)),
        (true, None) => Err(DecodeError::Invalid(format!(
            "--normalised: {skeleton_name} has no AnyTop statistics to undo the normalisation with (give --skeleton the document mo-encode --emit-skeleton wrote for these features)"
        ))),
    }
}
