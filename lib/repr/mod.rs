//! Feature encodings of a Motion: the tensors learned models and metrics see.
//!
//! Every encoding produces `Features`, a dense `[frames, joints, dims]` float32 tensor (the
//! layout of our NPY files), and can decode it back to a `Motion` on the same skeleton.
//! Encodings live in their own modules (`m2m`: Motion2Motion's local 6D rotations + root
//! motion; `anytop`: AnyTop's 13-D per-joint features).

pub mod anytop;
pub mod batch;
pub mod m2m;
pub mod smooth;
/// A `[frames, joints, dims]` float32 tensor, row-major (dims fastest).
#[derive(Clone, Debug, PartialEq)]
pub struct Features {
    pub frames: usize,
    pub joints: usize,
    pub dims: usize,
    pub data: Vec<f32>,
}

impl Features {
    /// Tensors of one shape as one NPY: `[frames, joints, dims]` for a single tensor unless
    /// `always_batch`, else `[count, frames, joints, dims]`.
    pub fn batch_npy(features: &[Features], always_batch: bool) -> std::io::Result<Vec<u8>> {
        let first = features.first().ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "no features to write"))?;
        let mut shape = first.shape().to_vec();
        if always_batch || features.len() > 1 {
            shape.insert(0, features.len());
        }
        let parts: Vec<&[f32]> = features.iter().map(|f| f.data.as_slice()).collect();
        let mut bytes = Vec::new();
        crate::io::npy::write_f32_parts(&mut bytes, &shape, &parts)?;
        Ok(bytes)
    }

    pub fn zeros(frames: usize, joints: usize, dims: usize) -> Features {
        Features { frames, joints, dims, data: vec![0.0; frames * joints * dims] }
    }

    pub fn shape(&self) -> [usize; 3] {
        [self.frames, self.joints, self.dims]
    }

    /// At least `frames` long: frames past the end are zeros (for an edit's reference, whose
    /// values past its end are generated and never read).
    pub fn padded_to(&self, frames: usize) -> Features {
        let mut padded = self.clone();
        if padded.frames < frames {
            padded.data.resize(frames * padded.joints * padded.dims, 0.0);
            padded.frames = frames;
        }
        padded
    }

    /// The feature vector of one joint at one frame.
    pub fn at(&self, frame: usize, joint: usize) -> &[f32] {
        let i = (frame * self.joints + joint) * self.dims;
        &self.data[i..i + self.dims]
    }

    pub fn at_mut(&mut self, frame: usize, joint: usize) -> &mut [f32] {
        let i = (frame * self.joints + joint) * self.dims;
        &mut self.data[i..i + self.dims]
    }

    /// Index of the first non-finite value, if any (features from files must be checked).
    pub fn first_non_finite(&self) -> Option<(usize, usize, usize)> {
        let k = self.data.iter().position(|v| !v.is_finite())?;
        let per_frame = self.joints * self.dims;
        Some((k / per_frame, (k % per_frame) / self.dims, k % self.dims))
    }
}
