//! Skeleton: the joint tree of a BVH file and everything derived from it that does not depend
//! on motion — topology descriptors (AnyTop's relations and distances, chains, end effectors),
//! readable names, sides, feet, the rest pose and its measurements.
//!
//! Joints are the file's ROOT and JOINT entries in file order, so parents precede children and
//! joint indices match the frame columns. End Sites stay attached to their joint (they carry no
//! channels); they matter for drawing and height, not for the graph.

pub mod lookup;
pub mod names;
pub mod roles;
pub mod topology;

use crate::bvh::{Bvh, BvhJoint, Channel};
use crate::motion::Motion;
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    pub parent: Option<usize>,
    pub offset: DVec3,
    pub channels: Vec<Channel>,
    pub end_sites: Vec<DVec3>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    pub joints: Vec<Joint>,
    /// Seconds per frame of the motion this skeleton came with (BVH needs one to write a file).
    pub frame_time: f64,
}

/// Skeleton construction errors (a BVH that parsed but cannot be a skeleton).
#[derive(Debug, thiserror::Error)]
pub enum SkeletonError {
    #[error("joint {joint} '{name}': parent {parent} does not precede it")]
    ParentOrder { joint: usize, name: String, parent: usize },
    #[error("the skeleton has no joints")]
    Empty,
    #[error("the skeleton has {0} roots; exactly one is supported")]
    Roots(usize),
}

/// A chain of joints with these names, each one unit above its parent: the smallest skeleton
/// that name-lookup and binding tests need.
#[cfg(test)]
pub(crate) fn chain(names: &[&str]) -> Skeleton {
    let joints = names
        .iter()
        .enumerate()
        .map(|(i, n)| Joint { name: n.to_string(), parent: i.checked_sub(1), offset: DVec3::Y, channels: vec![], end_sites: vec![] })
        .collect();
    Skeleton { joints, frame_time: 1.0 / 30.0 }
}

impl Skeleton {
    pub fn from_bvh(bvh: &Bvh) -> Skeleton {
        let joints = bvh
            .joints
            .iter()
            .map(|j| Joint {
                name: j.name.clone(),
                parent: j.parent,
                offset: DVec3::from_array(j.offset),
                channels: j.channels.clone(),
                end_sites: j.end_sites.iter().map(|e| DVec3::from_array(*e)).collect(),
            })
            .collect();
        Skeleton { joints, frame_time: bvh.frame_time }
    }

    /// Check the invariants every algorithm relies on (one root, parents before children).
    /// Skeletons from our BVH parser always hold them; skeleton documents may not.
    pub fn validate(&self) -> Result<(), SkeletonError> {
        if self.joints.is_empty() {
            return Err(SkeletonError::Empty);
        }
        let roots = self.joints.iter().filter(|j| j.parent.is_none()).count();
        if roots != 1 || self.joints[0].parent.is_some() {
            return Err(SkeletonError::Roots(roots));
        }
        for (j, joint) in self.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                if p >= j {
                    return Err(SkeletonError::ParentOrder { joint: j, name: joint.name.clone(), parent: p });
                }
            }
        }
        Ok(())
    }

    /// The hierarchy as a BVH with no frames (write it with `bvh::write_string`).
    pub fn to_bvh_hierarchy(&self) -> Bvh {
        Bvh {
            joints: self
                .joints
                .iter()
                .map(|j| BvhJoint {
                    name: j.name.clone(),
                    parent: j.parent,
                    offset: j.offset.to_array(),
                    channels: j.channels.clone(),
                    end_sites: j.end_sites.iter().map(|e| e.to_array()).collect(),
                })
                .collect(),
            frame_time: self.frame_time,
            frames: 0,
            values: Vec::new(),
        }
    }

    /// Where `other` stops being the same skeleton as this one (same joint names and parents,
    /// in the same order), said for a message; `None` when they are the same.
    pub fn first_difference(&self, other: &Skeleton) -> Option<String> {
        match self.joints.iter().zip(&other.joints).position(|(x, y)| x.name != y.name || x.parent != y.parent) {
            Some(j) if self.joints[j].name == other.joints[j].name => Some(format!(
                "joint {j} '{}' hangs from joint {:?} in one and {:?} in the other",
                self.joints[j].name, self.joints[j].parent, other.joints[j].parent
            )),
            Some(j) => Some(format!("joint {j} is '{}' in one and '{}' in the other", self.joints[j].name, other.joints[j].name)),
            None if self.len() != other.len() => Some(format!("{} joints against {}", self.len(), other.len())),
            None => None,
        }
    }

    pub fn len(&self) -> usize {
        self.joints.len()
    }

    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    pub fn parents(&self) -> Vec<Option<usize>> {
        self.joints.iter().map(|j| j.parent).collect()
    }

    /// Children of every joint, in index order.
    pub fn children(&self) -> Vec<Vec<usize>> {
        let mut children = vec![Vec::new(); self.joints.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                children[p].push(j);
            }
        }
        children
    }

    /// Depth of every joint (root = 0).
    pub fn depths(&self) -> Vec<usize> {
        let mut depth = vec![0; self.joints.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                depth[j] = depth[p] + 1;
            }
        }
        depth
    }

    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// World positions of the rest pose (identity rotations, OFFSETs), root at its OFFSET.
    pub fn rest_positions(&self) -> Vec<DVec3> {
        Motion::rest(self).forward_kinematics(self).positions
    }

    /// World positions of the End Sites in the rest pose, with the joint each hangs from.
    pub fn rest_end_sites(&self) -> Vec<(usize, DVec3)> {
        let pos = self.rest_positions();
        let mut out = Vec::new();
        for (j, joint) in self.joints.iter().enumerate() {
            for e in &joint.end_sites {
                out.push((j, pos[j] + *e));
            }
        }
        out
    }

    /// Vertical (y) extent of the rest pose, End Sites included. This is "height" for a
    /// standing creature; for a lying one (a snake) it is small, so callers that need a scale
    /// should use `rest_extent`.
    pub fn rest_height(&self) -> f64 {
        let (lo, hi) = self.rest_bounds();
        hi.y - lo.y
    }

    /// Largest extent of the rest pose along any axis: a size that works for every creature.
    pub fn rest_extent(&self) -> f64 {
        let (lo, hi) = self.rest_bounds();
        (hi - lo).max_element()
    }

    /// Axis-aligned bounds of the rest pose, End Sites included.
    pub fn rest_bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in self.rest_positions().into_iter().chain(self.rest_end_sites().into_iter().map(|(_, p)| p)) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo, hi)
    }

    /// Lengths of all bones (non-root OFFSETs).
    pub fn bone_lengths(&self) -> Vec<f64> {
        self.joints.iter().filter(|j| j.parent.is_some()).map(|j| j.offset.length()).collect()
    }
}

/// Summary statistics of a list of numbers.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Stats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub median: f64,
}

impl Stats {
    pub fn of(values: &[f64]) -> Option<Stats> {
        if values.is_empty() {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) };
        Some(Stats { min: v[0], max: v[n - 1], mean: v.iter().sum::<f64>() / n as f64, median })
    }
}
