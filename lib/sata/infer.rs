//! Whole clips through the autoencoder: overlapping windows (paper appendix B: 64-frame
//! windows overlapping by 16, the overlapping frames cropped from the latter window), the
//! latent mean as the code (no sampling at inference), raw AnyTop features in and out.

use super::checkpoint::FrozenAutoencoder;
use super::graph::SkeletonGraph;
use super::{SataError, FEATURE_DIMS};
use crate::document::AnyTopSection;
use crate::embed::NameTable;
use crate::motion::Motion;
use crate::repr::Features;
use crate::skeleton::Skeleton;
use candle_core::{Device, Tensor};

/// Windows stacked into one forward pass at most (bounds memory on long clips).
const WINDOWS_PER_PASS: usize = 16;

/// A window over a sequence: it covers `[start, start + len)` and contributes the frames from
/// `start + keep_from` on (the earlier ones belong to the previous window).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    pub start: usize,
    pub len: usize,
    pub keep_from: usize,
}

/// Windows of `window` frames, each starting `window - overlap` after the previous; the last
/// one is moved back to end at the last frame, so every window is full length (a clip shorter
/// than a window is one window). Every frame is kept by exactly one window.
pub fn windows(frames: usize, window: usize, overlap: usize) -> Vec<Window> {
    if frames <= window {
        return vec![Window { start: 0, len: frames, keep_from: 0 }];
    }
    let stride = window.saturating_sub(overlap).max(1);
    let mut out = Vec::new();
    let mut kept_to = 0;
    let mut start = 0;
    loop {
        let start_here = start.min(frames - window);
        out.push(Window { start: start_here, len: window, keep_from: kept_to - start_here });
        kept_to = start_here + window;
        if kept_to >= frames {
            return out;
        }
        start += stride;
    }
}

/// Per-frame latents `[frames, dims]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Latents {
    pub frames: usize,
    pub dims: usize,
    pub data: Vec<f32>,
}

/// A skeleton ready for the model: its AnyTop record (rig) and graph tensors.
pub struct PreparedSkeleton {
    pub section: AnyTopSection,
    pub graph: SkeletonGraph,
}

impl PreparedSkeleton {
    pub fn new(skeleton: &Skeleton, section: AnyTopSection, names: &NameTable, device: &Device) -> Result<PreparedSkeleton, SataError> {
        let graph = SkeletonGraph::new(skeleton, &section.rig, &names.embed_skeleton(skeleton), device)?;
        Ok(PreparedSkeleton { section, graph })
    }
}

impl FrozenAutoencoder {
    /// Latent means of raw AnyTop features `[frames, J, 13]` of the skeleton `g`.
    pub fn encode_features(&self, features: &Features, g: &SkeletonGraph, device: &Device) -> Result<Latents, SataError> {
        if features.dims != FEATURE_DIMS || features.joints != g.joints {
            return Err(SataError::Invalid(format!(
                "features are [{}, {}, {}], the skeleton needs [frames, {}, {FEATURE_DIMS}]",
                features.frames, features.joints, features.dims, g.joints
            )));
        }
        if features.frames == 0 {
            return Err(SataError::Invalid("no frames to encode".into()));
        }
        let mut scaled = features.clone();
        self.info.scale.apply(&mut scaled, &g.rest);
        let per_frame = g.joints * FEATURE_DIMS;
        let l = self.info.config.latent;
        let mut out = vec![0f32; features.frames * l];
        let list = windows(features.frames, self.info.config.window, self.info.config.overlap);
        for group in list.chunks(WINDOWS_PER_PASS) {
            let len = group[0].len;
            let mut data = Vec::with_capacity(group.len() * len * per_frame);
            for w in group {
                data.extend_from_slice(&scaled.data[w.start * per_frame..(w.start + w.len) * per_frame]);
            }
            let x = Tensor::from_vec(data, (group.len(), len, g.joints, FEATURE_DIMS), device)?;
            let (mu, _) = self.model.encode(&x, g)?;
            let mu: Vec<f32> = mu.flatten_all()?.to_vec1()?;
            for (k, w) in group.iter().enumerate() {
                for f in w.keep_from..w.len {
                    let src = (k * len + f) * l;
                    out[(w.start + f) * l..(w.start + f + 1) * l].copy_from_slice(&mu[src..src + l]);
                }
            }
        }
        Ok(Latents { frames: features.frames, dims: l, data: out })
    }

    /// Raw AnyTop features `[frames, J, 13]` of skeleton `g` from latents.
    pub fn decode_latents(&self, latents: &Latents, g: &SkeletonGraph, device: &Device) -> Result<Features, SataError> {
        let l = self.info.config.latent;
        if latents.dims != l {
            return Err(SataError::Invalid(format!("latents have {} values per frame, the model's have {l}", latents.dims)));
        }
        if latents.frames == 0 || latents.data.len() != latents.frames * l {
            return Err(SataError::Invalid(format!("latents: expected {} x {l} values, got {}", latents.frames, latents.data.len())));
        }
        if let Some(k) = latents.data.iter().position(|v| !v.is_finite()) {
            return Err(SataError::Invalid(format!("latents: non-finite value at frame {}, dim {}", k / l, k % l)));
        }
        let per_frame = g.joints * FEATURE_DIMS;
        let mut out = Features::zeros(latents.frames, g.joints, FEATURE_DIMS);
        let list = windows(latents.frames, self.info.config.window, self.info.config.overlap);
        for group in list.chunks(WINDOWS_PER_PASS) {
            let len = group[0].len;
            let mut data = Vec::with_capacity(group.len() * len * l);
            for w in group {
                data.extend_from_slice(&latents.data[w.start * l..(w.start + w.len) * l]);
            }
            let z = Tensor::from_vec(data, (group.len(), len, l), device)?;
            let y: Vec<f32> = self.model.decode(&z, g)?.flatten_all()?.to_vec1()?;
            for (k, w) in group.iter().enumerate() {
                let from = (k * len + w.keep_from) * per_frame;
                let to = (k * len + w.len) * per_frame;
                out.data[(w.start + w.keep_from) * per_frame..(w.start + w.len) * per_frame].copy_from_slice(&y[from..to]);
            }
        }
        self.info.scale.undo(&mut out, &g.rest);
        Ok(out)
    }

    /// A motion of `target` that the latents describe, placed where the target's rest pose
    /// stands, with `frame_time`.
    pub fn decode_motion(
        &self,
        latents: &Latents,
        target: &Skeleton,
        prepared: &PreparedSkeleton,
        frame_time: f64,
        device: &Device,
    ) -> Result<Motion, SataError> {
        let features = self.decode_latents(latents, &prepared.graph, device)?;
        let rig = &prepared.section.rig;
        let mut motion = rig.decode(target, &features, &rig.rest_placement())?;
        motion.frame_time = frame_time;
        Ok(motion)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_keep_every_frame_once() {
        for (frames, window, overlap) in [(1, 16, 4), (16, 16, 4), (17, 16, 4), (100, 32, 8), (1000, 64, 16), (65, 64, 16)] {
            let list = windows(frames, window, overlap);
            let mut kept = vec![0; frames];
            for w in &list {
                assert!(w.start + w.len <= frames && w.keep_from <= w.len, "{frames}: {w:?}");
                assert_eq!(w.len, window.min(frames));
                for f in w.start + w.keep_from..w.start + w.len {
                    kept[f] += 1;
                }
            }
            assert!(kept.iter().all(|&k| k == 1), "{frames}/{window}/{overlap}: {list:?}");
        }
        // Consecutive windows share `overlap` frames except where the last is moved back.
        let list = windows(100, 32, 8);
        assert_eq!(list[1].start, 24);
        assert_eq!(list[1].keep_from, 8);
    }
}
