//! Removal: drop a fraction of the joints by cutting chains that end in end effectors, so one
//! clip teaches a model many related topologies (AnyTop §3.3, appendix C).
//!
//! A *removable chain* is an end effector and its ancestors up to, not including, the first
//! joint that has several children, is a foot or is the root. Such chains never overlap (each
//! member has at most one child), and cutting any of them, or the leaf end of one, leaves one
//! tree whose surviving joints keep all their ancestors, hence their exact world positions.
//!
//! Where this deliberately differs from the upstream code (docs/reference/anytop.md §4):
//! * the rate is a fraction of *all* joints, reached by whole chains (plus at most one partial
//!   chain, cut from its leaf end), as the paper describes; upstream removes
//!   floor(rate x #end effectors) single leaves, which barely changes a skeleton with few leaves;
//! * feet are found from the skeleton (`roles::feet`), not from one clip's contact labels, so
//!   every clip of a skeleton protects the same joints;
//! * nothing shared is mutated: the topology is rebuilt from the new skeleton (upstream writes
//!   the end-effector mark into a shared relation array, which leaks into later samples).

use super::below;
use super::edit::Edit;
use crate::motion::Motion;
use crate::rng::SplitMix64;
use crate::skeleton::{roles, Skeleton};

/// How many joints to remove.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RemoveAmount {
    /// This fraction of the joints (rounded, at least one), in (0, 1).
    Rate(f64),
    /// A count drawn uniformly between 10% and 30% of the joints (rounded inwards, at least one).
    Random,
}

/// The number of joints to remove from a skeleton of `joints` joints.
pub fn target_count(joints: usize, amount: RemoveAmount, rng: &mut SplitMix64) -> usize {
    match amount {
        RemoveAmount::Rate(rate) => ((rate * joints as f64).round() as usize).max(1),
        RemoveAmount::Random => {
            let lo = joints.div_ceil(10).max(1);
            let hi = (3 * joints / 10).max(lo);
            lo + below(rng, hi - lo + 1)
        }
    }
}

/// Every removable chain, leaf first (see the module doc), in order of their end effectors'
/// indices. With `keep_feet` false, feet do not stop a chain (AnyTop does this for snakes,
/// whose whole body touches the ground).
pub fn removable_chains(skeleton: &Skeleton, keep_feet: bool) -> Vec<Vec<usize>> {
    let n = skeleton.len();
    let children = skeleton.children();
    let mut foot = vec![false; n];
    if keep_feet {
        for j in roles::feet(skeleton).0 {
            foot[j] = true;
        }
    }
    let mut chains = Vec::new();
    for leaf in (0..n).filter(|&j| children[j].is_empty()) {
        let mut chain = Vec::new();
        let mut at = leaf;
        while let Some(p) = skeleton.joints[at].parent {
            if children[at].len() > 1 || foot[at] {
                break;
            }
            chain.push(at);
            at = p;
        }
        if !chain.is_empty() {
            chains.push(chain);
        }
    }
    chains
}

/// Which joints a removal takes, and how that compares with what was asked.
#[derive(Clone, Debug, PartialEq)]
pub struct RemovalChoice {
    /// Removed joints (indices of the skeleton before the edit), sorted.
    pub joints: Vec<usize>,
    /// How many were asked for.
    pub target: usize,
    /// How many the skeleton could give at most (the joints of all removable chains).
    pub removable: usize,
}

/// Choose `target` joints to remove: removable chains in a random order, each taken whole
/// when it fits in what is still needed; then, if still short, the leaf end of the first
/// chain that did not fit. So the count is exactly `target` whenever the skeleton has that
/// many removable joints, and all of them otherwise.
pub fn choose_removal(skeleton: &Skeleton, target: usize, keep_feet: bool, rng: &mut SplitMix64) -> RemovalChoice {
    let chains = removable_chains(skeleton, keep_feet);
    let removable = chains.iter().map(Vec::len).sum();
    let mut order: Vec<usize> = (0..chains.len()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, below(rng, i + 1));
    }
    let mut need = target;
    let mut taken = vec![0usize; chains.len()];
    for &c in &order {
        if chains[c].len() <= need {
            taken[c] = chains[c].len();
            need -= chains[c].len();
        }
    }
    if need > 0 {
        // Chains not taken are longer than what is still needed: cut the first one short.
        if let Some(&c) = order.iter().find(|&&c| taken[c] == 0) {
            taken[c] = need;
        }
    }
    let mut joints: Vec<usize> = chains.iter().zip(&taken).flat_map(|(chain, &k)| chain[..k].iter().copied()).collect();
    joints.sort_unstable();
    RemovalChoice { joints, target, removable }
}

/// Remove about `rate` of the joints of `skeleton` (feet kept) and the matching columns of
/// `motion`. Returns the new skeleton and motion and the names of the removed joints.
pub fn remove_chains(skeleton: &Skeleton, motion: &Motion, rate: f64, rng: &mut SplitMix64) -> (Skeleton, Motion, Vec<String>) {
    let target = target_count(skeleton.len(), RemoveAmount::Rate(rate), rng);
    let choice = choose_removal(skeleton, target, true, rng);
    let names = choice.joints.iter().map(|&j| skeleton.joints[j].name.clone()).collect();
    // The choice only holds whole leaf-ended chains and leaf ends of chains: always valid.
    let edit = Edit::remove(skeleton, &choice.joints).expect("removable chains end in leaves and spare the root");
    (edit.apply_skeleton(skeleton), edit.apply_motion(skeleton, motion), names)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh;

    /// Hips with two legs ending in feet, a spine that branches into a neck/head and two arms
    /// of three joints each, and a one-joint tail.
    fn creature() -> Skeleton {
        let mut t = String::from("HIERARCHY\nROOT Hips\n{\nOFFSET 0 1 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n");
        let joint = |name: &str, off: &str| format!("JOINT {name}\n{{\nOFFSET {off}\nCHANNELS 3 Zrotation Xrotation Yrotation\n");
        for side in ["L", "R"] {
            t += &(joint(&format!("{side}Leg"), "0.1 -0.5 0") + &joint(&format!("{side}Foot"), "0 -0.5 0") + "}\n}\n");
        }
        t += &joint("Spine", "0 0.3 0");
        t += &(joint("Neck", "0 0.2 0") + &joint("Head", "0 0.1 0") + "}\n}\n");
        for side in ["L", "R"] {
            t += &(joint(&format!("{side}Arm"), "0.2 0 0")
                + &joint(&format!("{side}Fore"), "0.2 0 0")
                + &joint(&format!("{side}Hand"), "0.1 0 0")
                + "}\n}\n}\n");
        }
        t += "}\n";
        t += &(joint("Tail", "0 0 -0.3") + "}\n");
        t += "}\nMOTION\nFrames: 0\nFrame Time: 0.1\n";
        Skeleton::from_bvh(&bvh::parse(&t, "creature").unwrap())
    }

    fn names(s: &Skeleton, idx: &[usize]) -> Vec<String> {
        idx.iter().map(|&j| s.joints[j].name.clone()).collect()
    }

    #[test]
    fn chains_stop_at_branches_feet_and_the_root() {
        let s = creature();
        let chains: Vec<Vec<String>> = removable_chains(&s, true).iter().map(|c| names(&s, c)).collect();
        assert_eq!(chains, [vec!["Head", "Neck"], vec!["LHand", "LFore", "LArm"], vec!["RHand", "RFore", "RArm"], vec!["Tail"]]);
        // Without foot protection the legs become removable too.
        assert_eq!(removable_chains(&s, false).len(), 6);
    }

    #[test]
    fn choice_hits_the_target_exactly_and_spares_feet() {
        let s = creature();
        for seed in 0..50 {
            let mut rng = SplitMix64::new(seed);
            for target in 1..=9 {
                let c = choose_removal(&s, target, true, &mut rng);
                assert_eq!(c.joints.len(), target, "seed {seed}");
                assert_eq!(c.removable, 9);
                let removed = names(&s, &c.joints);
                assert!(!removed.iter().any(|n| n.contains("Foot") || n == "Hips" || n == "Spine"), "{removed:?}");
                Edit::remove(&s, &c.joints).unwrap();
            }
            let c = choose_removal(&s, 12, true, &mut rng);
            assert_eq!(c.joints.len(), 9, "all removable joints when the target is out of reach");
        }
    }

    #[test]
    fn random_counts_stay_within_ten_to_thirty_percent() {
        let mut rng = SplitMix64::new(7);
        for joints in 4..200 {
            for _ in 0..20 {
                let k = target_count(joints, RemoveAmount::Random, &mut rng);
                let f = k as f64 / joints as f64;
                assert!(k >= 1 && (0.1..=0.3).contains(&f), "{joints}: {k}");
            }
        }
        assert_eq!(target_count(22, RemoveAmount::Rate(0.2), &mut rng), 4);
        assert_eq!(target_count(3, RemoveAmount::Rate(0.01), &mut rng), 1);
    }
}
