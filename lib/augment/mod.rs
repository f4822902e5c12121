//! Skeletal augmentation (AnyTop §3.3, appendix C): new skeletons from old ones, with the
//! motion carried over exactly, so a model trained on a few species sees many topologies.
//!
//! * `remove`: cut chains that end in end effectors (never feet, the root or a branching
//!   joint); the parent of a cut chain becomes an end effector.
//! * `subdivide`: split bones at their midpoint with an identity-rotation joint.
//! * `edit`: the structural edits both produce, applied the same way to a `Skeleton`, a
//!   `Motion` and a BVH's channel matrix.
//!
//! Every surviving joint keeps its exact world position in every frame: removal only drops
//! leaf-ended subtrees, and a split re-expresses one bone as two with no rotation between them.
//! Topology descriptors (R, D, chains, end effectors, feet, names) are not patched but rebuilt
//! from the new skeleton (`document::SkeletonDocument::build`), so they are right by
//! construction. All randomness comes from one seeded `SplitMix64`.

pub mod edit;
pub mod remove;
pub mod source;
pub mod subdivide;

pub use edit::{Edit, EditError};
pub use remove::{choose_removal, removable_chains, remove_chains, target_count, RemovalChoice, RemoveAmount};
pub use subdivide::{choose_splits, mid_name, splittable_bones, subdivide, Added};

use crate::bvh::Bvh;
use crate::motion::Motion;
use crate::rng::SplitMix64;
use crate::skeleton::{topology, Skeleton};
use std::fmt::Write as _;

/// What to do to a skeleton: remove first (counted against the original joints), then add.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// `None`: no removal.
    pub remove: Option<RemoveAmount>,
    /// Joints to insert by bone subdivision.
    pub add: usize,
    /// Never remove feet (`roles::feet`). Off only for bodies that lie on the ground.
    pub keep_feet: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options { remove: Some(RemoveAmount::Random), add: 0, keep_feet: true }
    }
}

/// What a removal did, by name.
#[derive(Clone, Debug, PartialEq)]
pub struct RemovalReport {
    pub target: usize,
    /// Joints of all removable chains: the most any removal could take.
    pub removable: usize,
    pub removed: Vec<String>,
    /// Joints that lost all their children and are end effectors now.
    pub new_end_effectors: Vec<String>,
}

/// The edits chosen for one skeleton, the skeleton they produce, and what they did.
#[derive(Clone, Debug)]
pub struct Plan {
    /// In order; each applies to the result of the previous one.
    pub edits: Vec<Edit>,
    pub skeleton: Skeleton,
    pub joints_before: usize,
    pub removal: Option<RemovalReport>,
    pub added: Vec<Added>,
}

/// Choose the edits `options` ask for on `skeleton`.
pub fn plan(skeleton: &Skeleton, options: &Options, rng: &mut SplitMix64) -> Plan {
    let mut edits = Vec::new();
    let mut current = skeleton.clone();
    let mut removal = None;
    if let Some(amount) = options.remove {
        let target = target_count(skeleton.len(), amount, rng);
        let choice = choose_removal(skeleton, target, options.keep_feet, rng);
        let removed: Vec<String> = choice.joints.iter().map(|&j| skeleton.joints[j].name.clone()).collect();
        let mut new_end_effectors = Vec::new();
        if !choice.joints.is_empty() {
            let edit = Edit::remove(skeleton, &choice.joints).expect("removable chains end in leaves and spare the root");
            current = edit.apply_skeleton(skeleton);
            let was_leaf = topology::end_effectors(skeleton);
            new_end_effectors = topology::end_effectors(&current)
                .into_iter()
                .map(|j| current.joints[j].name.clone())
                .filter(|name| skeleton.index_of(name).is_some_and(|old| was_leaf.binary_search(&old).is_err()))
                .collect();
            edits.push(edit);
        }
        removal = Some(RemovalReport { target: choice.target, removable: choice.removable, removed, new_end_effectors });
    }
    let (splits, result, added) = choose_splits(&current, options.add, rng);
    edits.extend(splits);
    Plan { edits, skeleton: result, joints_before: skeleton.len(), removal, added }
}

impl Plan {
    /// The edited BVH: channel values copied column by column (see `Edit::apply_bvh`).
    pub fn apply_bvh(&self, bvh: &Bvh) -> Bvh {
        let mut out = bvh.clone();
        for e in &self.edits {
            out = e.apply_bvh(&out);
        }
        out
    }

    /// The edited motion; `skeleton` is the one the plan was made for.
    pub fn apply_motion(&self, skeleton: &Skeleton, motion: &Motion) -> Motion {
        let mut at = skeleton.clone();
        let mut m = motion.clone();
        for e in &self.edits {
            m = e.apply_motion(&at, &m);
            at = e.apply_skeleton(&at);
        }
        m
    }

    /// True when the plan changes nothing.
    pub fn is_empty(&self) -> bool {
        self.edits.is_empty()
    }
}

/// Uniform integer in `0..n` (`SplitMix64::below`).
pub(crate) fn below(rng: &mut SplitMix64, n: usize) -> usize {
    rng.below(n)
}

/// Variant `i`'s generator: independent streams for every (seed, variant), and variant 0 of
/// `-n K` is the same as a single run, whatever K.
pub fn variant_rng(seed: u64, i: usize) -> SplitMix64 {
    let a = SplitMix64::new(seed).next_u64();
    let b = SplitMix64::new(!(i as u64)).next_u64();
    SplitMix64::new(a ^ b)
}

impl Plan {
    /// Where the plan fell short of what was asked (`add` joints, feet kept or not), in words.
    pub fn shortfalls(&self, skeleton: &Skeleton, add: usize, keep_feet: bool) -> Vec<String> {
        let plan = self;
        let mut out = Vec::new();
        let n = plan.joints_before;
        if let Some(r) = &plan.removal {
            if r.removed.len() < r.target {
                let why = if keep_feet {
                    "chains ending in end effectors stop at feet, branching joints and the root"
                } else {
                    "chains stop at branching joints and the root"
                };
                let mut w = if r.removable == 0 {
                    format!("none of the {n} joints can be removed ({why})")
                } else {
                    format!(
                        "only {} of {n} joints ({:.1}%) can be removed ({why}); removing all of them, fewer than asked",
                        r.removable,
                        100.0 * r.removable as f64 / n as f64,
                    )
                };
                if keep_feet && r.removable * 10 < n && !crate::skeleton::roles::feet(skeleton).0.is_empty() {
                    w.push_str("; --allow-feet lets removal take feet (for bodies that lie on the ground)");
                }
                out.push(w);
            }
        }
        if plan.added.len() < add {
            out.push(format!("no bone long enough to split: added {} of {add} joints", plan.added.len()));
        }
        out
    }

    /// What the plan changed, for `skel-aug -v`: a line `input -> target: joints` and the
    /// removed and added joints, indented.
    pub fn describe(&self, input: &str, target: &str) -> String {
        let plan = self;
        let mut s = String::new();
        let _ = writeln!(s, "{input} -> {target}: {} -> {} joints", plan.joints_before, plan.skeleton.len());
        if let Some(r) = &plan.removal {
            let pct = 100.0 * r.removed.len() as f64 / plan.joints_before as f64;
            let list = if r.removed.is_empty() { "nothing".to_string() } else { r.removed.join(", ") };
            let _ = writeln!(s, "    removed {} ({pct:.1}%, asked {}): {list}", r.removed.len(), r.target);
            if !r.new_end_effectors.is_empty() {
                let _ = writeln!(s, "    new end effectors: {}", r.new_end_effectors.join(", "));
            }
        }
        for a in &plan.added {
            let _ = writeln!(s, "    added {} between {} and {}", a.name, a.parent, a.child);
        }
        s
    }
}

#[cfg(test)]
mod variant_tests {
    use std::collections::BTreeSet;

    #[test]
    fn variant_streams_differ_and_do_not_depend_on_the_count() {
        let a: Vec<u64> = (0..4).map(|i| super::variant_rng(5, i).next_u64()).collect();
        let unique: BTreeSet<u64> = a.iter().copied().collect();
        assert_eq!(unique.len(), 4);
        assert_ne!(super::variant_rng(5, 0).next_u64(), super::variant_rng(6, 0).next_u64());
    }
}
