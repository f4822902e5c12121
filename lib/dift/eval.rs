//! Set-ups where the right correspondence is known, and the scores on them (issue 8's
//! acceptance; `benches/dift.rs` prints the tables):
//!
//! * joints: a skeleton against a copy with its joints in another file order and numbers for
//!   names, and against `skel-aug` variants and proportion variants that keep joint names;
//! * frames: a clip against a time-warped copy of itself, where the warp is the answer;
//! * the two baselines DIFT is compared with: joint names alone (their text embeddings) and
//!   rest-pose geometry alone (where each joint sits relative to the root).

use super::correspond::Match;
use crate::embed::NameTable;
use crate::motion::Motion;
use crate::rng::SplitMix64;
use crate::skeleton::{names, Joint, Skeleton};
use glam::DVec3;

/// `skeleton` and `motion` with the joints in another valid file order — every joint's children
/// visited in a shuffled order, depth first, so a BVH can hold it — and each joint named by its
/// new index. Returns the copy and, per new joint, its index in the original.
pub fn renamed_shuffled(skeleton: &Skeleton, motion: &Motion, rng: &mut SplitMix64) -> (Skeleton, Motion, Vec<usize>) {
    let children = skeleton.children();
    let mut order = Vec::with_capacity(skeleton.len());
    let mut stack: Vec<usize> = (0..skeleton.len()).filter(|&j| skeleton.joints[j].parent.is_none()).collect();
    stack.reverse();
    while let Some(j) = stack.pop() {
        order.push(j);
        let mut kids = children[j].clone();
        for i in (1..kids.len()).rev() {
            kids.swap(i, rng.below(i + 1));
        }
        stack.extend(kids.into_iter().rev());
    }
    let mut new_of = vec![0; skeleton.len()];
    for (new, &old) in order.iter().enumerate() {
        new_of[old] = new;
    }
    let joints = order
        .iter()
        .enumerate()
        .map(|(new, &old)| {
            let j = &skeleton.joints[old];
            Joint { name: new.to_string(), parent: j.parent.map(|p| new_of[p]), ..j.clone() }
        })
        .collect();
    let moved = Motion {
        rotations: reorder(&motion.rotations, motion.joints, &order),
        translations: reorder(&motion.translations, motion.joints, &order),
        ..motion.clone()
    };
    (Skeleton { joints, frame_time: skeleton.frame_time }, moved, order)
}

/// Per-frame joint values `[frame * joints + joint]` with the joints in `order` (old indices).
fn reorder<T: Copy>(values: &[T], joints: usize, order: &[usize]) -> Vec<T> {
    values.chunks_exact(joints.max(1)).flat_map(|frame| order.iter().map(move |&old| frame[old])).collect()
}

/// For every target joint, the reference joint of the same name (exact), if any.
pub fn truth_by_name(reference: &Skeleton, target: &Skeleton) -> Vec<Option<usize>> {
    target.joints.iter().map(|t| reference.joints.iter().position(|r| r.name == t.name)).collect()
}

/// Each joint's mirror image: the joint whose normalised name is its own with left and right
/// swapped (`LeftUpLeg` <-> `RightUpLeg`, `l_foot` <-> `r_foot`); `None` for centre joints.
pub fn mirrors(skeleton: &Skeleton) -> Vec<Option<usize>> {
    let normalised: Vec<String> = skeleton.joints.iter().map(|j| names::normalise(&j.name)).collect();
    let swap = |name: &str| -> Option<String> {
        let words: Vec<&str> = name.split(' ').collect();
        if !words.iter().any(|w| *w == "Left" || *w == "Right") {
            return None;
        }
        Some(
            words
                .iter()
                .map(|w| match *w {
                    "Left" => "Right",
                    "Right" => "Left",
                    w => w,
                })
                .collect::<Vec<_>>()
                .join(" "),
        )
    };
    normalised.iter().map(|n| swap(n).and_then(|m| normalised.iter().position(|o| *o == m))).collect()
}

/// Top-1 joint accuracy over the target joints that have a true counterpart.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Accuracy {
    pub correct: usize,
    pub total: usize,
    /// Wrong answers that are the true joint's mirror image (left for right).
    pub left_right: usize,
}

impl Accuracy {
    pub fn rate(&self) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            self.correct as f64 / self.total as f64
        }
    }

    pub fn add(&mut self, other: Accuracy) {
        self.correct += other.correct;
        self.total += other.total;
        self.left_right += other.left_right;
    }
}

/// Score `matches` against `truth` (per target joint, the right reference joint) with the
/// reference's `mirror` table.
pub fn score_joints(matches: &[Match], truth: &[Option<usize>], mirror: &[Option<usize>]) -> Accuracy {
    let mut acc = Accuracy::default();
    for m in matches {
        let Some(Some(right)) = truth.get(m.target) else { continue };
        acc.total += 1;
        if m.reference == *right {
            acc.correct += 1;
        } else if mirror.get(*right).copied().flatten() == Some(m.reference) {
            acc.left_right += 1;
        }
    }
    acc
}

/// Names-only baseline descriptors: the joint names' text embeddings.
pub fn name_descriptors(skeleton: &Skeleton) -> Result<Vec<Vec<f32>>, crate::embed::EmbedError> {
    Ok(NameTable::builtin()?.embed_skeleton(skeleton))
}

/// Geometry-only baseline descriptors: rest position relative to the root, over the
/// skeleton's size, in a frame where the creature faces +z (`rest`, e.g.
/// `AnyTopRig::rest_positions`). Compare with `distance_similarity`.
pub fn geometry_descriptors(rest: &[DVec3]) -> Vec<Vec<f32>> {
    let root = rest.first().copied().unwrap_or(DVec3::ZERO);
    let (lo, hi) = rest.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = (hi - lo).max_element().max(1e-9);
    rest.iter().map(|p| ((*p - root) / size).to_array().iter().map(|&v| v as f32).collect()).collect()
}

/// Similarity as minus the Euclidean distance `[target][reference]` (for positions, where
/// the cosine would tie every joint along one ray from the root).
pub fn distance_similarity(target: &[Vec<f32>], reference: &[Vec<f32>]) -> Vec<Vec<f64>> {
    target.iter().map(|t| reference.iter().map(|r| -t.iter().zip(r).map(|(a, b)| (*a as f64 - *b as f64).powi(2)).sum::<f64>().sqrt()).collect()).collect()
}

/// A smooth time warp of a clip onto as many frames: new frame k shows source position
/// `x(u) = (L − 1)(u + a·sin(2πu)/(2π))` with u = k/(L − 1), which is monotone for |a| < 1
/// (slow where cos(2πu) < 0, fast elsewhere) and keeps both ends. Returns the warped motion
/// and, per new frame, the source position it shows — the right answer for frame matching.
pub fn time_warp(motion: &Motion, strength: f64) -> (Motion, Vec<f64>) {
    let a = strength.clamp(-0.95, 0.95);
    let n = motion.frames;
    let span = n.saturating_sub(1) as f64;
    let at: Vec<f64> = (0..n)
        .map(|k| {
            let u = if n > 1 { k as f64 / span } else { 0.0 };
            span * (u + a * (std::f64::consts::TAU * u).sin() / std::f64::consts::TAU)
        })
        .collect();
    (motion.interpolate(&at), at)
}

/// Mean |matched reference frame − true source position| over the target frames.
pub fn frame_error(matches: &[Match], truth: &[f64]) -> f64 {
    let errors: Vec<f64> = matches.iter().filter_map(|m| truth.get(m.target).map(|&x| (m.reference as f64 - x).abs())).collect();
    if errors.is_empty() {
        return 0.0;
    }
    errors.iter().sum::<f64>() / errors.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dift::correspond::{best_matches, cosine_matrix};

    fn quadruped() -> (Skeleton, Motion) {
        let (s, m) = crate::synth::creature("quadruped", 0).unwrap();
        (s, m)
    }

    #[test]
    fn the_shuffled_copy_is_the_same_body_in_another_order() {
        let (s, m) = quadruped();
        let (c, cm, order) = renamed_shuffled(&s, &m, &mut SplitMix64::new(3));
        c.validate().unwrap();
        assert_ne!(order, (0..s.len()).collect::<Vec<_>>(), "seed 3 should reorder something");
        let (a, b) = (m.forward_kinematics(&s), cm.forward_kinematics(&c));
        for f in [0, m.frames / 2, m.frames - 1] {
            for (new, &old) in order.iter().enumerate() {
                assert!((a.position(f, old) - b.position(f, new)).length() < 1e-9);
            }
        }
        assert!(c.joints.iter().enumerate().all(|(i, j)| j.name == i.to_string()));
    }

    #[test]
    fn mirrors_pair_left_and_right() {
        let (s, _) = quadruped();
        let mirror = mirrors(&s);
        let paired = mirror.iter().enumerate().filter(|(_, m)| m.is_some()).count();
        assert!(paired >= 8, "a quadruped has mirrored legs: {paired}");
        for (j, m) in mirror.iter().enumerate() {
            if let Some(m) = m {
                assert_eq!(mirror[*m], Some(j));
            }
        }
        assert_eq!(mirror[0], None, "the root is in the centre");
    }

    #[test]
    fn geometry_finds_every_joint_of_a_shuffled_copy_and_scores_count_mirrors() {
        let (s, m) = quadruped();
        let (c, _, order) = renamed_shuffled(&s, &m, &mut SplitMix64::new(5));
        let rest = |s: &Skeleton| s.rest_positions();
        let sim = distance_similarity(&geometry_descriptors(&rest(&c)), &geometry_descriptors(&rest(&s)));
        let truth: Vec<Option<usize>> = order.iter().map(|&o| Some(o)).collect();
        let acc = score_joints(&best_matches(&sim), &truth, &mirrors(&s));
        assert_eq!((acc.correct, acc.total), (s.len(), s.len()));
        // Answering every joint with its mirror counts as left/right confusions, not correct.
        let mirror = mirrors(&s);
        let flipped: Vec<Match> = (0..c.len()).map(|t| Match { target: t, reference: mirror[order[t]].unwrap_or(order[t]), score: 1.0, margin: 0.0 }).collect();
        let acc = score_joints(&flipped, &truth, &mirror);
        let sided = mirror.iter().filter(|m| m.is_some()).count();
        assert_eq!((acc.left_right, acc.correct), (sided, s.len() - sided));
        // Names against themselves: wrong only where normalised names coincide (the digits of
        // Spine1/Spine2 and Tail_01..04 are dropped), which is what a names-only matcher sees.
        let names = cosine_matrix(&name_descriptors(&s).unwrap(), &name_descriptors(&s).unwrap());
        let normalised: Vec<String> = s.joints.iter().map(|j| names::normalise(&j.name)).collect();
        for m in best_matches(&names) {
            assert_eq!(normalised[m.reference], normalised[m.target], "{m:?}");
        }
    }

    #[test]
    fn a_time_warp_keeps_the_ends_and_is_monotone() {
        let (_, m) = quadruped();
        let (w, at) = time_warp(&m, 0.5);
        assert_eq!(w.frames, m.frames);
        assert_eq!(at[0], 0.0);
        assert!((at[m.frames - 1] - (m.frames - 1) as f64).abs() < 1e-9);
        assert!(at.windows(2).all(|p| p[1] > p[0]));
        assert!(at.iter().enumerate().any(|(k, &x)| (x - k as f64).abs() > 3.0), "the warp moves frames");
        let exact = Match { target: 10, reference: at[10].round() as usize, score: 1.0, margin: 0.0 };
        assert!(frame_error(&[exact], &at) <= 0.5);
    }
}
