//! Motion: per-frame local joint rotations and translations, and forward kinematics.
//!
//! Every joint carries a per-frame local translation, not only the root: files with six
//! channels on every joint (Truebones, Bandai Namco, LAFAN1-resolved) animate bone lengths,
//! and following Blender's importer a joint's position channels *replace* its OFFSET (missing
//! components are zero). Joints without position channels translate by their OFFSET.

pub mod clip;
pub mod contact;
pub mod ik;
pub mod rotation;
pub mod write;

pub use clip::{Clip, ClipError};

use crate::bvh::Bvh;
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    pub frames: usize,
    pub joints: usize,
    pub frame_time: f64,
    /// Local rotation of joint j at frame f at `[f * joints + j]`.
    pub rotations: Vec<DQuat>,
    /// Local translation (relative to the parent, in the parent's frame) at `[f * joints + j]`.
    pub translations: Vec<DVec3>,
}

/// World-space joint positions and rotations for every frame.
#[derive(Clone, Debug)]
pub struct WorldPose {
    pub frames: usize,
    pub joints: usize,
    pub positions: Vec<DVec3>,
    pub rotations: Vec<DQuat>,
}

impl WorldPose {
    pub fn position(&self, frame: usize, joint: usize) -> DVec3 {
        self.positions[frame * self.joints + joint]
    }
    pub fn frame_positions(&self, frame: usize) -> &[DVec3] {
        &self.positions[frame * self.joints..(frame + 1) * self.joints]
    }
}

impl Motion {
    /// The first (frame, joint) whose rotation or translation holds a NaN or an infinity.
    pub fn first_non_finite(&self) -> Option<(usize, usize)> {
        let bad = |k: usize| !(self.rotations[k].is_finite() && self.translations[k].is_finite());
        let k = (0..self.rotations.len().min(self.translations.len())).find(|&k| bad(k))?;
        Some((k / self.joints.max(1), k % self.joints.max(1)))
    }

    /// Build the motion of a parsed BVH (`skeleton` must come from the same file).
    pub fn from_bvh(bvh: &Bvh, skeleton: &Skeleton) -> Motion {
        Motion::from_bvh_frames(bvh, skeleton, 0..bvh.frames)
    }

    /// Build the motion of some frames of a parsed BVH (the range is clamped to the file).
    pub fn from_bvh_frames(bvh: &Bvh, skeleton: &Skeleton, frames: std::ops::Range<usize>) -> Motion {
        let frames = frames.start.min(bvh.frames)..frames.end.min(bvh.frames);
        let nj = skeleton.joints.len();
        let nc = bvh.channel_count();
        let mut rotations = Vec::with_capacity(frames.len() * nj);
        let mut translations = Vec::with_capacity(frames.len() * nj);
        for f in frames.clone() {
            let row = &bvh.values[f * nc..(f + 1) * nc];
            let mut at = 0;
            for joint in &skeleton.joints {
                let mut q = DQuat::IDENTITY;
                let mut pos = DVec3::ZERO;
                let mut has_pos = false;
                for (c, &v) in joint.channels.iter().zip(&row[at..]) {
                    if c.is_rotation() {
                        q *= rotation::axis_rotation(c.axis(), v);
                    } else {
                        pos[c.axis()] = v;
                        has_pos = true;
                    }
                }
                at += joint.channels.len();
                rotations.push(q);
                translations.push(if has_pos { pos } else { joint.offset });
            }
        }
        Motion { frames: frames.len(), joints: nj, frame_time: bvh.frame_time, rotations, translations }
    }

    /// The first `n` frames (all of them when there are fewer).
    pub fn first_frames(&self, n: usize) -> Motion {
        self.frame_range(0, n)
    }

    /// Frames `start..end` as their own motion (clamped to the frames there are).
    pub fn frame_range(&self, start: usize, end: usize) -> Motion {
        let end = end.min(self.frames);
        let start = start.min(end);
        let j = self.joints;
        Motion {
            frames: end - start,
            joints: j,
            frame_time: self.frame_time,
            rotations: self.rotations[start * j..end * j].to_vec(),
            translations: self.translations[start * j..end * j].to_vec(),
        }
    }

    /// Frames at fractional source positions `at` (frame units, clamped to the motion):
    /// rotations slerped, translations interpolated linearly; same frame time. Resampling and
    /// time warps are this with different positions.
    pub fn interpolate(&self, at: &[f64]) -> Motion {
        let j = self.joints;
        let mut out = Motion {
            frames: at.len(),
            joints: j,
            frame_time: self.frame_time,
            rotations: Vec::with_capacity(at.len() * j),
            translations: Vec::with_capacity(at.len() * j),
        };
        if self.frames == 0 {
            out.frames = 0;
            return out;
        }
        let last = self.frames - 1;
        for &x in at {
            let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, last as f64) };
            let a = (x.floor() as usize).min(last);
            let b = (a + 1).min(last);
            let w = x - a as f64;
            for k in 0..j {
                let (ra, rb) = (self.rotations[a * j + k], self.rotations[b * j + k]);
                out.rotations.push(if w == 0.0 { ra } else { ra.slerp(rb, w).normalize() });
                out.translations.push(self.translations[a * j + k].lerp(self.translations[b * j + k], w));
            }
        }
        out
    }

    /// The skeleton's rest pose as a one-frame motion (identity rotations, OFFSET translations).
    pub fn rest(skeleton: &Skeleton) -> Motion {
        Motion {
            frames: 1,
            joints: skeleton.joints.len(),
            frame_time: skeleton.frame_time,
            rotations: vec![DQuat::IDENTITY; skeleton.joints.len()],
            translations: skeleton.joints.iter().map(|j| j.offset).collect(),
        }
    }

    /// Forward kinematics: world positions and rotations of every joint at every frame.
    pub fn forward_kinematics(&self, skeleton: &Skeleton) -> WorldPose {
        let nj = self.joints;
        let mut positions = Vec::with_capacity(self.frames * nj);
        let mut world_rot = Vec::with_capacity(self.frames * nj);
        for f in 0..self.frames {
            let base = f * nj;
            for (j, joint) in skeleton.joints.iter().enumerate() {
                let lr = self.rotations[base + j];
                let lt = self.translations[base + j];
                match joint.parent {
                    None => {
                        positions.push(lt);
                        world_rot.push(lr);
                    }
                    Some(p) => {
                        let pr: DQuat = world_rot[base + p];
                        positions.push(positions[base + p] + pr * lt);
                        world_rot.push(pr * lr);
                    }
                }
            }
        }
        WorldPose { frames: self.frames, joints: nj, positions, rotations: world_rot }
    }

    /// The BVH channel values that reproduce this motion on `skeleton` (for writing BVH).
    pub fn to_bvh(&self, skeleton: &Skeleton) -> Bvh {
        let mut bvh = skeleton.to_bvh_hierarchy();
        bvh.frames = self.frames;
        bvh.frame_time = self.frame_time;
        let orders: Vec<Vec<usize>> = skeleton.joints.iter().map(|j| rotation::rotation_axes(&j.channels)).collect();
        let mut values = Vec::with_capacity(self.frames * bvh.channel_count());
        for f in 0..self.frames {
            for (j, joint) in skeleton.joints.iter().enumerate() {
                let angles = rotation::decompose(self.rotations[f * self.joints + j], &orders[j]);
                let t = self.translations[f * self.joints + j];
                let mut next_angle = angles.iter();
                for c in &joint.channels {
                    values.push(if c.is_rotation() { *next_angle.next().unwrap_or(&0.0) } else { t[c.axis()] });
                }
            }
        }
        bvh.values = values;
        bvh
    }
}
