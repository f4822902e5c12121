//! Addition: subdivide bones, so a model sees the same motion on skeletons with more joints.
//!
//! A real subdivision (what AnyTop §3.3 intends): the new joint hangs from the bone's parent,
//! the old joint hangs from the new one, the OFFSET is split in half, and the new joint keeps
//! identity rotation in every frame, so every original joint keeps its world position and
//! rotation exactly. The upstream code instead inserts a self-parented, disconnected joint
//! (docs/reference/anytop.md §4 and §9.10); we fix that rather than copy it.
//!
//! Bones are chosen uniformly among the non-degenerate bones of the skeleton *as it is at that
//! moment*, so with several additions a bone may be split again (its halves are bones too).

use super::below;
use super::edit::Edit;
use crate::motion::Motion;
use crate::rng::SplitMix64;
use crate::skeleton::Skeleton;

/// A bone shorter than this fraction of the skeleton's size is not split (a new joint on top
/// of an old one teaches nothing).
const MIN_BONE: f64 = 1e-9;

/// Joints whose bone (from their parent) may be split: every non-root joint with a rest OFFSET
/// that is not degenerate.
pub fn splittable_bones(skeleton: &Skeleton) -> Vec<usize> {
    let size = skeleton.rest_extent();
    let min = if size.is_finite() && size > 0.0 { MIN_BONE * size } else { 0.0 };
    (0..skeleton.len()).filter(|&j| skeleton.joints[j].parent.is_some() && skeleton.joints[j].offset.length() > min).collect()
}

/// A readable name for a joint inserted above `child`, unique in `skeleton`:
/// `<child>_mid`, then `<child>_mid2`, `<child>_mid3`, ...
pub fn mid_name(skeleton: &Skeleton, child: usize) -> String {
    let base = format!("{}_mid", skeleton.joints[child].name);
    let taken = |name: &str| skeleton.joints.iter().any(|j| j.name == name);
    if !taken(&base) {
        return base;
    }
    (2..).map(|k| format!("{base}{k}")).find(|n| !taken(n)).unwrap_or(base)
}

/// One bone split by `choose_splits`, in the words of the skeleton it was split in.
#[derive(Clone, Debug, PartialEq)]
pub struct Added {
    pub name: String,
    pub parent: String,
    pub child: String,
}

/// Choose and make `count` splits one after another on `skeleton`. Returns the edits (each
/// to be applied to the result of the previous one), the final skeleton and what was added;
/// fewer than `count` only when the skeleton has no bone to split.
pub fn choose_splits(skeleton: &Skeleton, count: usize, rng: &mut SplitMix64) -> (Vec<Edit>, Skeleton, Vec<Added>) {
    let mut current = skeleton.clone();
    let mut edits = Vec::with_capacity(count);
    let mut added = Vec::with_capacity(count);
    for _ in 0..count {
        let bones = splittable_bones(&current);
        if bones.is_empty() {
            break;
        }
        let child = bones[below(rng, bones.len())];
        let name = mid_name(&current, child);
        let edit = Edit::split(&current, child, &name).expect("a non-root joint and a fresh name");
        let parent = current.joints[child].parent.map(|p| current.joints[p].name.clone()).unwrap_or_default();
        added.push(Added { name, parent, child: current.joints[child].name.clone() });
        current = edit.apply_skeleton(&current);
        edits.push(edit);
    }
    (edits, current, added)
}

/// Insert `count` joints at the midpoints of random bones of `skeleton`, and the matching
/// identity-rotation columns into `motion`. Returns the new skeleton and motion and the names
/// of the new joints.
pub fn subdivide(skeleton: &Skeleton, motion: &Motion, count: usize, rng: &mut SplitMix64) -> (Skeleton, Motion, Vec<String>) {
    let (edits, result, added) = choose_splits(skeleton, count, rng);
    let mut at = skeleton.clone();
    let mut m = motion.clone();
    for e in &edits {
        m = e.apply_motion(&at, &m);
        at = e.apply_skeleton(&at);
    }
    (result, m, added.into_iter().map(|a| a.name).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh;

    const TEXT: &str = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation\nJOINT a\n{\nOFFSET 0 1 0\nCHANNELS 3 Yrotation Xrotation Zrotation\nJOINT z\n{\nOFFSET 0 0 0\nCHANNELS 3 Yrotation Xrotation Zrotation\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 10 20 30 40 50 60 1 2 3\n";

    #[test]
    fn names_are_unique_and_degenerate_bones_are_skipped() {
        let b = bvh::parse(TEXT, "t").unwrap();
        let s = Skeleton::from_bvh(&b);
        assert_eq!(splittable_bones(&s), vec![1]);
        let mut rng = SplitMix64::new(3);
        let (edits, t, added) = choose_splits(&s, 3, &mut rng);
        assert_eq!(edits.len(), 3);
        let names: Vec<&str> = t.joints.iter().map(|j| j.name.as_str()).collect();
        // Every split lands on a piece of the r -> a bone; names never collide.
        assert_eq!(t.len(), 6);
        let mut sorted = names.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 6, "{names:?}");
        assert_eq!(added[0], Added { name: "a_mid".into(), parent: "r".into(), child: "a".into() });
        // The rest pose and the motion's world positions are unchanged for r, a and z.
        let m = Motion::from_bvh(&b, &s);
        let (s2, m2, new_names) = subdivide(&s, &m, 3, &mut SplitMix64::new(3));
        assert_eq!(s2, t);
        assert_eq!(new_names.len(), 3);
        let before = m.forward_kinematics(&s).positions;
        let after = m2.forward_kinematics(&s2).positions;
        for (old, name) in ["r", "a", "z"].iter().enumerate() {
            let new = s2.index_of(name).unwrap();
            assert!(after[new].distance(before[old]) < 1e-12, "{name}");
        }
        // New joints use the split joint's Euler order.
        let mid = s2.index_of("a_mid").unwrap();
        assert_eq!(s2.joints[mid].channels, s.joints[1].channels);
    }
}
