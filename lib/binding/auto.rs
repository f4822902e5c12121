//! Automatic bone binding (`mo-retarget --bind auto`): Motion2Motion's appendix A, made
//! sturdier with what the skeleton model knows.
//!
//! The paper traces, for every joint, the path of L joints up towards the root and compares
//! the unit bone directions of source and target paths by cosine similarity; the most similar
//! paths give the bound bones. Bone directions alone confuse limbs that point the same way
//! (a monkey's arms and legs both hang down; left and right legs are parallel), so the score
//! here adds, each with a small weight:
//!
//! * where the joint sits in the body: its rest position relative to the root, divided by the
//!   skeleton's size, in a frame where both creatures face +z (the AnyTop rig's natural rest
//!   pose), so a knee is near a knee whatever the creature's size;
//! * its side: left never binds to right; a centre joint binding to a side costs;
//! * feet bind to feet;
//! * names: words shared by the normalised names (`Bip01_L_Calf` and `LeftLeg` share nothing,
//!   `mixamorig:LeftLeg` and `LeftLeg` everything), as a tie-breaker, never alone: CMU's
//!   `LeftShoulder` is the upper arm, Xia's is the collar bone.
//!
//! Only joints that have children and are not the root are candidates: binding a joint binds
//! its local rotation, which moves its child bones (a leaf's rotation moves nothing), and the
//! root carries the whole body's placement. Pairs are taken greedily by score, each joint at
//! most once, until the binding rate 2|M| / (J_s + J_t) reaches the requested rate (the
//! paper's default 6.1%), with at least `min_pairs`.

use super::{Binding, Pair, FORMAT};
use crate::skeleton::names::{self, Side};
use crate::skeleton::{roles, Skeleton};
use glam::DVec3;

/// How the automatic binder chooses.
#[derive(Clone, Debug)]
pub struct AutoOptions {
    /// Target binding rate 2|M| / (J_source + J_target) (Motion2Motion's appendix B: 6.1%).
    pub rate: f64,
    /// Never fewer pairs than this (when there are enough candidates).
    pub min_pairs: usize,
    /// Path length L of the chain comparison (joints, the joint itself included).
    pub chain: usize,
    /// Use joint names as a tie-breaker.
    pub names: bool,
}

impl Default for AutoOptions {
    fn default() -> Self {
        AutoOptions { rate: 0.061, min_pairs: 4, chain: 3, names: true }
    }
}

/// One skeleton as the binder sees it.
pub struct Body<'a> {
    pub skeleton: &'a Skeleton,
    /// Rest-pose world positions, facing +z, y up (e.g. `AnyTopRig::rest_positions`).
    pub rest: &'a [DVec3],
}

/// A chosen pair with its score (higher is surer; about 0..1).
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    pub source: usize,
    pub target: usize,
    pub score: f64,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AutoError {
    #[error("{which} skeleton: {got} rest positions for {joints} joints")]
    RestSize { which: &'static str, got: usize, joints: usize },
    #[error("{which} skeleton has no joint with children below the root, so there is no bone to bind")]
    NoCandidates { which: &'static str },
    #[error("binding rate must be within (0, 1], found {0}")]
    Rate(f64),
}

/// What the score needs of each joint, computed once per skeleton.
struct Prepared {
    candidates: Vec<usize>,
    /// Unit bone direction (parent -> joint) of every joint; zero for the root.
    direction: Vec<DVec3>,
    /// Rest position relative to the root, divided by the skeleton's size.
    place: Vec<DVec3>,
    side: Vec<Side>,
    foot: Vec<bool>,
    /// Words of the normalised name, without side words and digits.
    words: Vec<Vec<String>>,
    /// Words of the raw name (namespace and suffix gone), digits kept: `Middle1` vs `Middle2`.
    raw_words: Vec<Vec<String>>,
    parents: Vec<Option<usize>>,
}

fn prepare(body: &Body, which: &'static str) -> Result<Prepared, AutoError> {
    let s = body.skeleton;
    let n = s.len();
    if body.rest.len() != n {
        return Err(AutoError::RestSize { which, got: body.rest.len(), joints: n });
    }
    let parents = s.parents();
    let children = s.children();
    let root = body.rest.first().copied().unwrap_or(DVec3::ZERO);
    let (lo, hi) = body.rest.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = (hi - lo).max_element().max(1e-9);
    let direction = (0..n)
        .map(|j| match parents[j] {
            Some(p) => (body.rest[j] - body.rest[p]).try_normalize().unwrap_or(DVec3::ZERO),
            None => DVec3::ZERO,
        })
        .collect();
    let place = body.rest.iter().map(|p| (*p - root) / size).collect();
    let normalised: Vec<String> = s.joints.iter().map(|j| names::normalise(&j.name)).collect();
    let side = roles::sides(s, &normalised);
    let mut foot = vec![false; n];
    for f in roles::feet(s).0 {
        foot[f] = true;
    }
    let words = normalised
        .iter()
        .map(|name| {
            name.split(' ')
                .map(str::to_ascii_lowercase)
                .filter(|w| !w.is_empty() && w != "left" && w != "right" && !w.chars().all(|c| c.is_ascii_digit()))
                .collect()
        })
        .collect();
    let side_word = |w: &str| matches!(w, "l" | "r" | "left" | "right");
    let raw_words =
        s.joints.iter().map(|j| names::split_words(&j.name).into_iter().map(|w| w.to_ascii_lowercase()).filter(|w| !side_word(w)).collect()).collect();
    let candidates: Vec<usize> = (1..n).filter(|&j| !children[j].is_empty()).collect();
    if candidates.is_empty() {
        return Err(AutoError::NoCandidates { which });
    }
    Ok(Prepared { candidates, direction, place, side, foot, words, raw_words, parents })
}

impl Prepared {
    /// The joint and up to `len - 1` ancestors, stopping before the root.
    fn path(&self, j: usize, len: usize) -> Vec<usize> {
        let mut out = vec![j];
        let mut cur = j;
        while out.len() < len {
            match self.parents[cur] {
                Some(p) if self.parents[p].is_some() => {
                    out.push(p);
                    cur = p;
                }
                _ => break,
            }
        }
        out
    }
}

/// Score of binding source joint `s` to target joint `t`; `None` when the pair is ruled out
/// (left with right).
fn score(a: &Prepared, s: usize, b: &Prepared, t: usize, opts: &AutoOptions) -> Option<f64> {
    let side = match (a.side[s], b.side[t]) {
        (Side::Left, Side::Right) | (Side::Right, Side::Left) => return None,
        (x, y) if x == y => 0.0,
        _ => -0.3,
    };
    // Chain similarity: mean cosine of bone directions along the two upward paths, over the
    // length both have (the paper drops shorter paths; near the root we keep what exists).
    let (pa, pb) = (a.path(s, opts.chain), b.path(t, opts.chain));
    let len = pa.len().min(pb.len());
    let chain = (0..len).map(|k| a.direction[pa[k]].dot(b.direction[pb[k]])).sum::<f64>() / len as f64;
    // The bone that the joint's rotation drives: the direction to its first child would need a
    // choice among children; the joint's own place covers where it is instead.
    let distance = (a.place[s] - b.place[t]).length();
    let place = (1.0 - 2.0 * distance).max(-1.0);
    let foot = if a.foot[s] == b.foot[t] { 0.0 } else { -0.3 };
    let name = if opts.names { 0.5 * jaccard(&a.words[s], &b.words[t]) + 0.5 * jaccard(&a.raw_words[s], &b.raw_words[t]) } else { 0.0 };
    Some(0.45 * chain + 0.45 * place + 0.1 * name + side + foot)
}

fn jaccard(a: &[String], b: &[String]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    let shared = a.iter().filter(|w| b.contains(w)).count();
    shared as f64 / (a.len() + b.len() - shared) as f64
}

/// How many pairs `rate` asks for on skeletons of `js` and `jt` joints.
pub fn pair_count(rate: f64, js: usize, jt: usize, min_pairs: usize) -> usize {
    ((rate * (js + jt) as f64 / 2.0).round() as usize).max(min_pairs).max(1)
}

/// Bind `source` to `target`: pairs in order of decreasing score.
pub fn auto_bind(source: &Body, target: &Body, opts: &AutoOptions) -> Result<Vec<Choice>, AutoError> {
    if !(opts.rate.is_finite() && opts.rate > 0.0 && opts.rate <= 1.0) {
        return Err(AutoError::Rate(opts.rate));
    }
    let a = prepare(source, "source")?;
    let b = prepare(target, "target")?;
    let mut all: Vec<Choice> = Vec::with_capacity(a.candidates.len() * b.candidates.len());
    for &s in &a.candidates {
        for &t in &b.candidates {
            if let Some(score) = score(&a, s, &b, t, opts) {
                all.push(Choice { source: s, target: t, score });
            }
        }
    }
    // Highest score first; ties by index so the result never depends on anything else.
    all.sort_by(|x, y| y.score.total_cmp(&x.score).then(x.source.cmp(&y.source)).then(x.target.cmp(&y.target)));
    let want = pair_count(opts.rate, source.skeleton.len(), target.skeleton.len(), opts.min_pairs).min(a.candidates.len()).min(b.candidates.len());
    let mut used_s = vec![false; source.skeleton.len()];
    let mut used_t = vec![false; target.skeleton.len()];
    let mut out = Vec::with_capacity(want);
    for c in all {
        if out.len() == want {
            break;
        }
        if used_s[c.source] || used_t[c.target] {
            continue;
        }
        used_s[c.source] = true;
        used_t[c.target] = true;
        out.push(c);
    }
    Ok(out)
}

/// The choices as a binding file (names as the skeletons spell them, scores kept).
pub fn to_binding(choices: &[Choice], source: &Skeleton, source_name: &str, target: &Skeleton, target_name: &str) -> Binding {
    Binding {
        format: Some(FORMAT.to_string()),
        source_name: Some(source_name.to_string()),
        target_name: Some(target_name.to_string()),
        mapping: choices
            .iter()
            .map(|c| Pair {
                source: source.joints[c.source].name.clone(),
                target: target.joints[c.target].name.clone(),
                score: Some((c.score * 1000.0).round() / 1000.0),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth;

    fn body_of(name: &str) -> (Skeleton, Vec<DVec3>) {
        let (skeleton, _) = synth::creature(name, 1).unwrap();
        let rest = skeleton.rest_positions();
        (skeleton, rest)
    }

    #[test]
    fn a_skeleton_binds_to_itself_joint_for_joint() {
        for name in ["biped", "quadruped", "spider", "dragon"] {
            let (s, rest) = body_of(name);
            let body = Body { skeleton: &s, rest: &rest };
            let opts = AutoOptions { rate: 0.3, ..AutoOptions::default() };
            let pairs = auto_bind(&body, &body, &opts).unwrap();
            assert!(pairs.len() >= 4, "{name}: {} pairs", pairs.len());
            for c in &pairs {
                assert_eq!(c.source, c.target, "{name}: {} bound to {}", s.joints[c.source].name, s.joints[c.target].name);
            }
        }
    }

    #[test]
    fn geometry_alone_binds_a_renamed_copy_and_never_swaps_sides() {
        let (s, rest) = body_of("biped");
        let mut renamed = s.clone();
        for (i, j) in renamed.joints.iter_mut().enumerate() {
            // Numbers carry no side and no word: only geometry is left to bind by.
            j.name = format!("j{i}");
        }
        let opts = AutoOptions { rate: 0.3, names: false, ..AutoOptions::default() };
        let pairs = auto_bind(&Body { skeleton: &s, rest: &rest }, &Body { skeleton: &renamed, rest: &rest }, &opts).unwrap();
        let correct = pairs.iter().filter(|c| c.source == c.target).count();
        assert!(correct * 10 >= pairs.len() * 9, "{correct} of {} correct", pairs.len());
    }

    #[test]
    fn rate_controls_the_count_and_bad_input_is_an_error() {
        assert_eq!(pair_count(0.061, 41, 86, 4), 4);
        assert_eq!(pair_count(0.2, 41, 86, 4), 13);
        let (s, rest) = body_of("quadruped");
        let body = Body { skeleton: &s, rest: &rest };
        let few = auto_bind(&body, &body, &AutoOptions::default()).unwrap();
        let many = auto_bind(&body, &body, &AutoOptions { rate: 0.4, ..AutoOptions::default() }).unwrap();
        assert!(many.len() > few.len());
        assert_eq!(auto_bind(&body, &body, &AutoOptions { rate: 0.0, ..AutoOptions::default() }).unwrap_err(), AutoError::Rate(0.0));
        let short = Body { skeleton: &s, rest: &rest[..2] };
        assert!(matches!(auto_bind(&short, &body, &AutoOptions::default()), Err(AutoError::RestSize { .. })));
        let binding = to_binding(&few, &s, "a", &s, "b");
        let text = binding.to_json();
        let back = Binding::from_json(&text, "auto.json").unwrap();
        assert_eq!(back.resolve("auto.json", &s, "a", &s, "b").unwrap(), few.iter().map(|c| (c.source, c.target)).collect::<Vec<_>>());
    }
}
