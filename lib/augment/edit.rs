//! Structural edits of a skeleton, replayable on everything that is laid out by joint.
//!
//! Augmentation decides *what* to change from the skeleton alone (which chains go, which bones
//! are split). The same decision must then reach three places: the `Skeleton`, a `Motion` (for
//! in-memory users such as training) and a BVH's raw channel matrix (for files: columns that
//! did not change keep their exact values, with no Euler -> quaternion -> Euler round trip).
//! One `Edit` value drives all three, so they cannot drift apart.
//!
//! Index order after an edit: parents before children and the original relative order kept
//! (removal drops indices; a split inserts the new joint right before the joint it splits).
//! For a skeleton read from BVH, index order is the file's depth-first order, and both edits
//! keep it that way, so the BVH writer's hierarchy and channel columns stay in step.

use crate::bvh::{Bvh, Channel};
use crate::motion::Motion;
use crate::skeleton::{Joint, Skeleton};
use glam::{DQuat, DVec3};

/// Why an edit cannot be made on a skeleton.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EditError {
    #[error("joint {0} does not exist")]
    NoSuchJoint(usize),
    #[error("the root cannot be removed or split")]
    Root,
    #[error("joint {joint} '{name}' is removed but its child {child} is not")]
    OrphanedChild { joint: usize, name: String, child: usize },
    #[error("a joint named '{0}' already exists")]
    DuplicateName(String),
}

/// One structural change. Build it with `Edit::remove` or `Edit::split` against the skeleton
/// it will be applied to; applying it to a different skeleton panics (a programming error).
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    Remove(Removal),
    Split(Split),
}

/// Drop a set of joints that is closed under descendants (whole subtrees, never the root).
#[derive(Clone, Debug, PartialEq)]
pub struct Removal {
    joints_before: usize,
    /// Removed joints, sorted, as indices of the skeleton before the edit.
    removed: Vec<usize>,
}

/// Insert a joint in the middle of the bone that ends at `child`.
#[derive(Clone, Debug, PartialEq)]
pub struct Split {
    joints_before: usize,
    /// The joint whose bone is split (index before the edit; the new joint takes this index
    /// and `child` moves to `child + 1`).
    child: usize,
    name: String,
    /// The new joint's OFFSET, and what is taken off the child's OFFSET and translations.
    offset: DVec3,
    channels: Vec<Channel>,
}

impl Removal {
    pub fn removed(&self) -> &[usize] {
        &self.removed
    }
}

impl Split {
    /// Index (before the edit) of the joint whose bone is split.
    pub fn child(&self) -> usize {
        self.child
    }
    pub fn name(&self) -> &str {
        &self.name
    }
    pub fn offset(&self) -> DVec3 {
        self.offset
    }
}

impl Edit {
    /// Remove `joints` (any order, duplicates ignored). Every child of a removed joint must be
    /// removed too, and the root never is: what is left is still one tree.
    pub fn remove(skeleton: &Skeleton, joints: &[usize]) -> Result<Edit, EditError> {
        let n = skeleton.len();
        let mut gone = vec![false; n];
        for &j in joints {
            if j >= n {
                return Err(EditError::NoSuchJoint(j));
            }
            if skeleton.joints[j].parent.is_none() {
                return Err(EditError::Root);
            }
            gone[j] = true;
        }
        for (c, joint) in skeleton.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                if gone[p] && !gone[c] {
                    return Err(EditError::OrphanedChild { joint: p, name: skeleton.joints[p].name.clone(), child: c });
                }
            }
        }
        let removed = (0..n).filter(|&j| gone[j]).collect();
        Ok(Edit::Remove(Removal { joints_before: n, removed }))
    }

    /// Split the bone from `child`'s parent to `child` at its midpoint with a new joint called
    /// `name`. The new joint has identity rotation in every frame and rotation channels in the
    /// child's Euler order (else its parent's, else Z X Y); it takes half the child's OFFSET.
    ///
    /// When the child has some but not all position channels, its missing translation
    /// components are zero in every frame (they cannot be written), so the new joint's OFFSET
    /// is zero along those axes: the child's translations can only be shifted along axes it
    /// animates.
    pub fn split(skeleton: &Skeleton, child: usize, name: &str) -> Result<Edit, EditError> {
        let joint = skeleton.joints.get(child).ok_or(EditError::NoSuchJoint(child))?;
        let parent = joint.parent.ok_or(EditError::Root)?;
        if skeleton.joints.iter().any(|j| j.name == name) {
            return Err(EditError::DuplicateName(name.to_string()));
        }
        let mut offset = joint.offset * 0.5;
        let has_position = joint.channels.iter().any(|c| !c.is_rotation());
        if has_position {
            for axis in 0..3 {
                if !joint.channels.iter().any(|c| !c.is_rotation() && c.axis() == axis) {
                    offset[axis] = 0.0;
                }
            }
        }
        let channels = euler_order(&joint.channels)
            .or_else(|| euler_order(&skeleton.joints[parent].channels))
            .unwrap_or_else(|| vec![Channel::Zrotation, Channel::Xrotation, Channel::Yrotation]);
        Ok(Edit::Split(Split { joints_before: skeleton.len(), child, name: name.to_string(), offset, channels }))
    }

    fn check(&self, joints: usize) {
        let before = match self {
            Edit::Remove(r) => r.joints_before,
            Edit::Split(s) => s.joints_before,
        };
        assert_eq!(before, joints, "an Edit must be applied to the skeleton it was made for");
    }

    /// The edited skeleton.
    ///
    /// A joint that loses all its child joints to a removal becomes an end effector; when it
    /// has no End Site it gets one at its first removed child's OFFSET, so the last bone is
    /// still drawn (and Blender imports the same bone tail as before).
    pub fn apply_skeleton(&self, skeleton: &Skeleton) -> Skeleton {
        self.check(skeleton.len());
        match self {
            Edit::Remove(r) => {
                let n = skeleton.len();
                let gone = r.mask();
                let mut new_index = vec![usize::MAX; n];
                let mut joints: Vec<Joint> = Vec::with_capacity(n - r.removed.len());
                let mut kept_child = vec![false; n];
                let mut first_removed_child: Vec<Option<usize>> = vec![None; n];
                for (j, joint) in skeleton.joints.iter().enumerate() {
                    if let Some(p) = joint.parent {
                        if gone[j] {
                            first_removed_child[p] = first_removed_child[p].or(Some(j));
                        } else {
                            kept_child[p] = true;
                        }
                    }
                }
                for (j, joint) in skeleton.joints.iter().enumerate() {
                    if gone[j] {
                        continue;
                    }
                    new_index[j] = joints.len();
                    let mut kept = joint.clone();
                    kept.parent = joint.parent.map(|p| new_index[p]);
                    if let (false, Some(c), true) = (kept_child[j], first_removed_child[j], kept.end_sites.is_empty()) {
                        kept.end_sites.push(skeleton.joints[c].offset);
                    }
                    joints.push(kept);
                }
                Skeleton { joints, frame_time: skeleton.frame_time }
            }
            Edit::Split(s) => {
                let mut joints = Vec::with_capacity(skeleton.len() + 1);
                for (j, joint) in skeleton.joints.iter().enumerate() {
                    let shift = |p: usize| if p >= s.child { p + 1 } else { p };
                    if j == s.child {
                        joints.push(Joint {
                            name: s.name.clone(),
                            parent: joint.parent,
                            offset: s.offset,
                            channels: s.channels.clone(),
                            end_sites: Vec::new(),
                        });
                        let mut old = joint.clone();
                        old.parent = Some(s.child);
                        old.offset = joint.offset - s.offset;
                        joints.push(old);
                    } else {
                        let mut moved = joint.clone();
                        moved.parent = joint.parent.map(shift);
                        joints.push(moved);
                    }
                }
                Skeleton { joints, frame_time: skeleton.frame_time }
            }
        }
    }

    /// The edited motion (`skeleton` is the one before the edit). Surviving joints keep their
    /// local rotations; the new joint of a split has identity rotation and its OFFSET as
    /// translation, and the split child's translation loses that OFFSET, so every joint that
    /// existed before keeps its world position and rotation.
    pub fn apply_motion(&self, skeleton: &Skeleton, motion: &Motion) -> Motion {
        self.check(skeleton.len());
        assert_eq!(motion.joints, skeleton.len(), "motion and skeleton joint counts differ");
        let nj = motion.joints;
        let frames = motion.frames;
        match self {
            Edit::Remove(r) => {
                let gone = r.mask();
                let rotations = motion.rotations.iter().enumerate().filter(|(k, _)| !gone[k % nj]).map(|(_, q)| *q).collect();
                let translations = motion.translations.iter().enumerate().filter(|(k, _)| !gone[k % nj]).map(|(_, t)| *t).collect();
                Motion { frames, joints: nj - r.removed.len(), frame_time: motion.frame_time, rotations, translations }
            }
            Edit::Split(s) => {
                let mut rotations = Vec::with_capacity(frames * (nj + 1));
                let mut translations = Vec::with_capacity(frames * (nj + 1));
                for f in 0..frames {
                    let row = f * nj;
                    rotations.extend_from_slice(&motion.rotations[row..row + s.child]);
                    translations.extend_from_slice(&motion.translations[row..row + s.child]);
                    rotations.push(DQuat::IDENTITY);
                    translations.push(s.offset);
                    rotations.extend_from_slice(&motion.rotations[row + s.child..row + nj]);
                    translations.push(motion.translations[row + s.child] - s.offset);
                    translations.extend_from_slice(&motion.translations[row + s.child + 1..row + nj]);
                }
                Motion { frames, joints: nj + 1, frame_time: motion.frame_time, rotations, translations }
            }
        }
    }

    /// The edited BVH, channel values copied column by column: removed joints' columns are
    /// dropped; a split inserts the new joint's columns (zero angles) and shifts the split
    /// joint's position channels by the new joint's OFFSET. Everything else is bit-identical.
    pub fn apply_bvh(&self, bvh: &Bvh) -> Bvh {
        let skeleton = Skeleton::from_bvh(bvh);
        let edited = self.apply_skeleton(&skeleton);
        let nc = bvh.channel_count();
        let starts = bvh.channel_starts();
        // Each output column: a source column and what to subtract, or a constant.
        let mut columns: Vec<(Option<usize>, f64)> = Vec::new();
        match self {
            Edit::Remove(r) => {
                let gone = r.mask();
                for (j, joint) in skeleton.joints.iter().enumerate().filter(|(j, _)| !gone[*j]) {
                    columns.extend((0..joint.channels.len()).map(|k| (Some(starts[j] + k), 0.0)));
                }
            }
            Edit::Split(s) => {
                for (j, joint) in skeleton.joints.iter().enumerate() {
                    if j == s.child {
                        // The new joint's channels: rotations only, so constant zero angles.
                        columns.extend(s.channels.iter().map(|c| (None, if c.is_rotation() { 0.0 } else { s.offset[c.axis()] })));
                    }
                    for (k, c) in joint.channels.iter().enumerate() {
                        let shift = if j == s.child && !c.is_rotation() { s.offset[c.axis()] } else { 0.0 };
                        columns.push((Some(starts[j] + k), shift));
                    }
                }
            }
        }
        let mut values = Vec::with_capacity(bvh.frames * columns.len());
        for f in 0..bvh.frames {
            let row = &bvh.values[f * nc..(f + 1) * nc];
            values.extend(columns.iter().map(|&(src, v)| match src {
                Some(c) if v == 0.0 => row[c],
                Some(c) => row[c] - v,
                None => v,
            }));
        }
        let mut out = edited.to_bvh_hierarchy();
        out.frames = bvh.frames;
        out.frame_time = bvh.frame_time;
        out.values = values;
        out
    }
}

impl Removal {
    fn mask(&self) -> Vec<bool> {
        let mut gone = vec![false; self.joints_before];
        for &j in &self.removed {
            gone[j] = true;
        }
        gone
    }
}

/// The rotation channels of a joint when they are a full Euler order (three distinct axes).
fn euler_order(channels: &[Channel]) -> Option<Vec<Channel>> {
    let rot: Vec<Channel> = channels.iter().copied().filter(|c| c.is_rotation()).collect();
    let distinct = rot.len() == 3 && rot[0] != rot[1] && rot[1] != rot[2] && rot[0] != rot[2];
    distinct.then_some(rot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh;

    /// Root with a three-joint arm (the middle one with partial position channels) and a leg.
    const TEXT: &str = "HIERARCHY\nROOT r\n{\nOFFSET 0 1 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\nJOINT a\n{\nOFFSET 1 0 0\nCHANNELS 3 Xrotation Yrotation Zrotation\nJOINT b\n{\nOFFSET 1 2 0\nCHANNELS 4 Xposition Zrotation Xrotation Yrotation\nJOINT c\n{\nOFFSET 0 -1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\nOFFSET 0 -0.5 0\n}\n}\n}\n}\nJOINT leg\n{\nOFFSET 0 -1 0\nCHANNELS 0\n}\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n0 1 0 0 0 0 10 20 30 1.5 40 5 6 7 8 9\n1 1 1 3 2 1 -10 20 -30 0.5 4 50 60 70 80 90\n";

    fn positions(bvh: &Bvh) -> Vec<DVec3> {
        let s = Skeleton::from_bvh(bvh);
        Motion::from_bvh(bvh, &s).forward_kinematics(&s).positions
    }

    #[test]
    fn removal_drops_subtrees_and_caps_the_new_leaf() {
        let b = bvh::parse(TEXT, "t").unwrap();
        let s = Skeleton::from_bvh(&b);
        assert_eq!(Edit::remove(&s, &[2]), Err(EditError::OrphanedChild { joint: 2, name: "b".into(), child: 3 }));
        assert_eq!(Edit::remove(&s, &[0]), Err(EditError::Root));
        let e = Edit::remove(&s, &[3, 2]).unwrap();
        let out = e.apply_bvh(&b);
        let t = Skeleton::from_bvh(&out);
        assert_eq!(t.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>(), ["r", "a", "leg"]);
        assert_eq!(t.joints[1].end_sites, vec![DVec3::new(1.0, 2.0, 0.0)]);
        assert_eq!(out.values, vec![0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 20.0, 30.0, 1.0, 1.0, 1.0, 3.0, 2.0, 1.0, -10.0, 20.0, -30.0]);
        let (before, after) = (positions(&b), positions(&out));
        for f in 0..2 {
            for (new, old) in [(0, 0), (1, 1), (2, 4)] {
                assert_eq!(after[f * 3 + new], before[f * 5 + old]);
            }
        }
        // The Motion path agrees with the BVH path.
        let m = e.apply_motion(&s, &Motion::from_bvh(&b, &s));
        assert_eq!(m, Motion::from_bvh(&out, &t));
    }

    #[test]
    fn split_keeps_world_positions_with_partial_position_channels() {
        let b = bvh::parse(TEXT, "t").unwrap();
        let s = Skeleton::from_bvh(&b);
        for child in 1..5 {
            let e = Edit::split(&s, child, "mid").unwrap();
            let out = e.apply_bvh(&b);
            let t = Skeleton::from_bvh(&out);
            t.validate().unwrap();
            assert_eq!(t.joints[child].name, "mid");
            assert_eq!(t.joints[child + 1].parent, Some(child));
            let (before, after) = (positions(&b), positions(&out));
            for f in 0..2 {
                for old in 0..5 {
                    let new = if old >= child { old + 1 } else { old };
                    let d = after[f * 6 + new].distance(before[f * 5 + old]);
                    assert!(d < 1e-12, "split {child}: joint {old} frame {f} moved by {d}");
                }
            }
            let m = e.apply_motion(&s, &Motion::from_bvh(&b, &s));
            let fk_a = m.forward_kinematics(&t).positions;
            assert!(fk_a.iter().zip(&after).all(|(a, b)| a.distance(*b) < 1e-12));
        }
        // b animates x only: the new joint's OFFSET is zero along y and z.
        let Edit::Split(sp) = Edit::split(&s, 2, "mid").unwrap() else { unreachable!() };
        assert_eq!(sp.offset(), DVec3::new(0.5, 0.0, 0.0));
        assert_eq!(sp.channels, vec![Channel::Zrotation, Channel::Xrotation, Channel::Yrotation]);
        // leg has no channels: it borrows the root's Euler order.
        let Edit::Split(sp) = Edit::split(&s, 4, "mid").unwrap() else { unreachable!() };
        assert_eq!(sp.channels, vec![Channel::Zrotation, Channel::Xrotation, Channel::Yrotation]);
        assert_eq!(Edit::split(&s, 0, "x"), Err(EditError::Root));
        assert_eq!(Edit::split(&s, 1, "c"), Err(EditError::DuplicateName("c".into())));
    }
}
