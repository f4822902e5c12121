//! One joint-correspondence engine for everything that matches joints across two skeletons:
//! `mo-dift --joints` (and its `--as-binding`) and `mo-retarget --bind auto` (issue 24).
//!
//! Each source of evidence alone makes mistakes a person reading the rigs would not: DIFT
//! features swap left and right on real rigs, bone directions confuse arms with legs, names
//! lie sometimes (CMU's `LeftShoulder` is Xia's `LeftArm`). So every pair of joints gets one
//! score that adds up:
//!
//! * names (`names`): the same side, words and ordinals score 1, shared words less;
//! * topology: the same place in two identical trees (subtree sizes from the root down) also
//!   scores 1, so where two rigs share a tree but not their names, the tree wins;
//! * rest-pose geometry: where the joint sits relative to the root (facing +z, divided by the
//!   skeleton's size), the directions of its bone chain, its position along its limb;
//! * optional extra similarity (DIFT features), with a small weight.
//!
//! and two hard rules: never left with right (when both skeletons have sides), never a front
//! limb with a hind limb (when both limbs' pairs are known). Joints are then assigned one to
//! one, maximising the total score (the Hungarian method, `pathfinding::kuhn_munkres`); a joint
//! may stay unmatched when every partner scores below `UNMATCHED`. Each pair carries its
//! margin over the best alternative for either joint, and a confidence from it.

pub mod describe;
pub mod names;

use crate::skeleton::names::Side;
use crate::skeleton::Skeleton;
use describe::{describe, Described, Limb, Roles};
use glam::DVec3;

/// One skeleton: its joints and rest positions facing +z, y up (`AnyTopRig::rest_positions`).
pub struct Body<'a> {
    pub skeleton: &'a Skeleton,
    pub rest: &'a [DVec3],
}

/// Which evidence to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Evidence {
    /// Joint names (and sides and limb pairs from them).
    pub names: bool,
    /// Rest pose and topology (and sides and limb pairs from them when names are off or silent).
    pub geometry: bool,
}

impl Evidence {
    pub const ALL: Evidence = Evidence { names: true, geometry: true };
    pub const NAMES: Evidence = Evidence { names: true, geometry: false };
    pub const GEOMETRY: Evidence = Evidence { names: false, geometry: true };
}

/// Weight of an exact name, and of the same place in identical trees.
const NAME_WEIGHT: f64 = 1.0;
const SIGNATURE_WEIGHT: f64 = 1.0;
/// Weights of the geometric terms (each term is about -1..1).
const PLACE_WEIGHT: f64 = 0.35;
const CHAIN_WEIGHT: f64 = 0.2;
const ALONG_WEIGHT: f64 = 0.15;
/// A midline joint with a limb joint, a leaf with a joint that has children.
const CENTRE_WITH_SIDE: f64 = -0.3;
const LEAF_WITH_INNER: f64 = -0.15;
/// Weight of the extra similarity (cosine of DIFT features, -1..1).
pub const EXTRA_WEIGHT: f64 = 0.2;
/// Score of leaving a joint unmatched: a pair must score above this to be made.
pub const UNMATCHED: f64 = -0.25;
/// Larger skeletons than this (either) are assigned greedily: the Hungarian method is cubic.
const HUNGARIAN_LIMIT: usize = 600;
/// Bone chain length compared (joints, the joint included).
const CHAIN: usize = 3;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CorrespondError {
    #[error("{which} skeleton: {got} rest positions for {joints} joints")]
    RestSize { which: &'static str, got: usize, joints: usize },
    #[error("{which} skeleton has no joints")]
    Empty { which: &'static str },
    #[error("extra similarity is {rows} x {cols}, the skeletons have {source_joints} and {target_joints} joints")]
    ExtraSize { rows: usize, cols: usize, source_joints: usize, target_joints: usize },
}

/// Every pair's score, `None` where a hard rule forbids the pair.
pub struct Scores {
    pub source: Described,
    pub target: Described,
    /// `[source][target]`.
    pub score: Vec<Vec<Option<f64>>>,
}

/// A matched pair.
#[derive(Clone, Debug, PartialEq)]
pub struct Pair {
    pub source: usize,
    pub target: usize,
    pub score: f64,
    /// Score minus the best other pair either joint could have made (negative when the
    /// one-to-one assignment overruled a joint's own first choice).
    pub margin: f64,
    /// 0..1 from the margin: 0.5 at a tie, near 1 when the pair is clearly the best for both.
    pub confidence: f64,
}

/// Score every pair of `source` and `target` joints. `extra`, when given, is a similarity
/// `[source][target]` (e.g. DIFT cosine) added with `EXTRA_WEIGHT`.
pub fn scores(source: &Body, target: &Body, evidence: Evidence, extra: Option<&[Vec<f64>]>) -> Result<Scores, CorrespondError> {
    for (which, body) in [("source", source), ("target", target)] {
        if body.skeleton.is_empty() {
            return Err(CorrespondError::Empty { which });
        }
        if body.rest.len() != body.skeleton.len() {
            return Err(CorrespondError::RestSize { which, got: body.rest.len(), joints: body.skeleton.len() });
        }
    }
    let (ns, nt) = (source.skeleton.len(), target.skeleton.len());
    if let Some(x) = extra {
        if x.len() != ns || x.iter().any(|r| r.len() != nt) {
            return Err(CorrespondError::ExtraSize { rows: x.len(), cols: x.first().map_or(0, Vec::len), source_joints: ns, target_joints: nt });
        }
    }
    // Sides and limb pairs from names only when both skeletons name their sides.
    let named = |body: &Body| evidence.names && describe(body.skeleton, body.rest, true, Roles::Names).named_sides;
    let roles = if named(source) && named(target) { Roles::Names } else { Roles::Geometry };
    let a = describe(source.skeleton, source.rest, evidence.names, roles);
    let b = describe(target.skeleton, target.rest, evidence.names, roles);
    let score =
        (0..ns).map(|s| (0..nt).map(|t| pair_score(&a, s, &b, t, evidence).map(|v| v + extra.map_or(0.0, |x| EXTRA_WEIGHT * x[s][t]))).collect()).collect();
    Ok(Scores { source: a, target: b, score })
}

/// The joint and up to `len - 1` ancestors, stopping before the root.
fn path(d: &Described, j: usize, len: usize) -> Vec<usize> {
    let mut out = vec![j];
    let mut cur = j;
    while out.len() < len {
        match d.parents[cur] {
            Some(p) if d.parents[p].is_some() => {
                out.push(p);
                cur = p;
            }
            _ => break,
        }
    }
    out
}

fn pair_score(a: &Described, s: usize, b: &Described, t: usize, evidence: Evidence) -> Option<f64> {
    let (sa, sb) = (a.side[s], b.side[t]);
    if a.has_sides && b.has_sides && matches!((sa, sb), (Side::Left, Side::Right) | (Side::Right, Side::Left)) {
        return None;
    }
    let (la, lb) = (a.limb[s], b.limb[t]);
    if matches!((la, lb), (Limb::Front, Limb::Hind) | (Limb::Hind, Limb::Front)) {
        return None;
    }
    let mut score = 0.0;
    if (sa == Side::Centre) != (sb == Side::Centre) && a.has_sides && b.has_sides {
        score += CENTRE_WITH_SIDE;
    }
    if evidence.names {
        if let Some(n) = names::similarity(&a.keys[s], &b.keys[t]) {
            score += NAME_WEIGHT * n;
        }
    }
    if evidence.geometry {
        if a.signature[s] == b.signature[t] {
            score += SIGNATURE_WEIGHT;
        }
        let distance = (a.place[s] - b.place[t]).length();
        score += PLACE_WEIGHT * (1.0 - 2.0 * distance).max(-1.0);
        let (pa, pb) = (path(a, s, CHAIN), path(b, t, CHAIN));
        let len = pa.len().min(pb.len());
        score += CHAIN_WEIGHT * (0..len).map(|k| a.direction[pa[k]].dot(b.direction[pb[k]])).sum::<f64>() / len as f64;
        if (la == Limb::Centre) == (lb == Limb::Centre) {
            score += ALONG_WEIGHT * (1.0 - 2.0 * (a.along[s] - b.along[t]).abs());
        }
        if a.leaf[s] != b.leaf[t] {
            score += LEAF_WITH_INNER;
        }
    }
    Some(score)
}

/// One-to-one pairs maximising the total score, in source order. Pairs scoring at most
/// `UNMATCHED` are not made.
pub fn assign(scores: &Scores) -> Vec<Pair> {
    let ns = scores.score.len();
    let nt = scores.score.first().map_or(0, Vec::len);
    if ns == 0 || nt == 0 {
        return Vec::new();
    }
    let chosen: Vec<Option<usize>> = if ns.max(nt) <= HUNGARIAN_LIMIT { hungarian(&scores.score, nt) } else { greedy(&scores.score, nt) };
    let mut out = Vec::new();
    for (s, t) in chosen.into_iter().enumerate() {
        let Some(t) = t else { continue };
        let Some(score) = scores.score[s][t] else { continue };
        if score <= UNMATCHED {
            continue;
        }
        let row = scores.score[s].iter().enumerate().filter(|&(k, _)| k != t).filter_map(|(_, v)| *v);
        let col = scores.score.iter().enumerate().filter(|&(k, _)| k != s).filter_map(|(_, r)| r[t]);
        let other = row.chain(col).fold(UNMATCHED, f64::max);
        let margin = score - other;
        out.push(Pair { source: s, target: t, score, margin, confidence: (0.5 + margin).clamp(0.0, 1.0) });
    }
    out
}

/// Integer weights for the Hungarian method (it needs an ordered type): micro-units.
fn weight(v: f64) -> i64 {
    (v * 1e6).round() as i64
}

/// Kuhn-Munkres on `[source][target + source]`: the extra columns are "unmatched" at
/// `UNMATCHED`, so rows never outnumber columns and a poor pair can be declined.
fn hungarian(score: &[Vec<Option<f64>>], nt: usize) -> Vec<Option<usize>> {
    let ns = score.len();
    let cols = nt + ns;
    let forbidden = weight(-1e3);
    let mut values = Vec::with_capacity(ns * cols);
    for row in score {
        values.extend(row.iter().map(|v| v.map_or(forbidden, weight)));
        values.extend(std::iter::repeat_n(weight(UNMATCHED), ns));
    }
    let Ok(matrix) = pathfinding::matrix::Matrix::from_vec(ns, cols, values) else { return greedy(score, nt) };
    let (_, columns) = pathfinding::kuhn_munkres::kuhn_munkres(&matrix);
    columns.into_iter().map(|c| (c < nt).then_some(c)).collect()
}

/// Highest score first, each joint once (ties by index).
fn greedy(score: &[Vec<Option<f64>>], nt: usize) -> Vec<Option<usize>> {
    let mut all: Vec<(f64, usize, usize)> =
        score.iter().enumerate().flat_map(|(s, r)| r.iter().enumerate().filter_map(move |(t, v)| v.map(|v| (v, s, t)))).collect();
    all.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut out = vec![None; score.len()];
    let mut used = vec![false; nt];
    for (_, s, t) in all {
        if out[s].is_none() && !used[t] {
            out[s] = Some(t);
            used[t] = true;
        }
    }
    out
}

/// For every target joint, its source joint: the one-to-one pair when it has one, else the
/// best-scoring allowed source (`one_to_one` false), else none (every source forbidden).
pub fn per_target(scores: &Scores, pairs: &[Pair]) -> Vec<(usize, Option<(Pair, bool)>)> {
    let nt = scores.score.first().map_or(0, Vec::len);
    (0..nt)
        .map(|t| {
            if let Some(p) = pairs.iter().find(|p| p.target == t) {
                return (t, Some((p.clone(), true)));
            }
            let best = scores.score.iter().enumerate().filter_map(|(s, r)| r[t].map(|v| (s, v))).fold(None, |best: Option<(usize, f64)>, (s, v)| match best {
                Some((_, b)) if b >= v => best,
                _ => Some((s, v)),
            });
            (t, best.map(|(s, v)| (Pair { source: s, target: t, score: v, margin: 0.0, confidence: 0.0 }, false)))
        })
        .collect()
}

/// Pairs that may be bound: both joints move a bone (not the root; a leaf only with an End
/// Site, as a head or a hand tip has), the same side and the same limb pair (or
/// both on the midline). Highest score first.
pub fn compatible(scores: &Scores, pairs: &[Pair]) -> Vec<Pair> {
    let (a, b) = (&scores.source, &scores.target);
    let inner = |d: &Described, j: usize| d.parents[j].is_some() && d.moves[j];
    let mut out: Vec<Pair> = pairs
        .iter()
        .filter(|p| inner(a, p.source) && inner(b, p.target))
        .filter(|p| !(a.has_sides && b.has_sides) || a.side[p.source] == b.side[p.target])
        .filter(|p| a.limb[p.source] == b.limb[p.target])
        .cloned()
        .collect();
    sort_pairs(&mut out);
    out
}

fn sort_pairs(pairs: &mut [Pair]) {
    pairs.sort_by(|x, y| y.score.total_cmp(&x.score).then(x.source.cmp(&y.source)).then(x.target.cmp(&y.target)));
}

/// The compatible pairs worth binding, and each matched limb tied at both ends, as a person
/// binds by hand:
///
/// * limbs are matched first (`match_limbs`: per side and limb pair, in order along the body),
///   but never a limb of a single bone with one of three or more (`comparable_limbs`: a bird's
///   one-bone wing stub is no arm); a pair that joins two limbs that are not matched is dropped;
/// * a joint pair is bound when it is confident (neither joint had a better partner,
///   `margin` >= 0, and the evidence is positive overall), `end_ok`, and, inside a matched
///   limb, in the same place along both limbs (`chain_position` within `CHAIN_PLACE_TOLERANCE`:
///   a dog's upper foreleg is not a claw's last joint, whatever the names say) with its bones
///   pointing the same way in both rest poses (`BONE_AGREEMENT`: a knee bent forward is not
///   bound to one folded up under a sitting dog);
/// * every matched front or hind limb's first joint binds to the other's first joint, and its
///   end effector (the hand, foot or tip the limb ends in) to the other's, when `end_ok` and
///   neither joint is bound already; where two legs ending in toes differ in length above
///   their feet, their ankles instead (`ankles`).
///
/// Ends were once never bound (a rule from Flamingo -> Monkey alone); the hand bindings of
/// the corpus pairs tie exactly them, and without them the automatic binding's frequency
/// alignment fell short of a hand binding's (docs/retarget-results.md).
pub fn bindable(scores: &Scores, pairs: &[Pair]) -> Vec<Pair> {
    let (a, b) = (&scores.source, &scores.target);
    let limbs: Vec<(usize, usize)> = match_limbs(a, b).into_iter().filter(|&(x, y)| comparable_limbs(a, x, b, y)).collect();
    // Inside matched limbs: the same place along both, bones pointing the same way.
    let in_place = |p: &Pair| match (a.base[p.source], b.base[p.target]) {
        (Some(x), Some(y)) => {
            limbs.contains(&(x, y))
                && (chain_position(a, p.source, x) - chain_position(b, p.target, y)).abs() <= CHAIN_PLACE_TOLERANCE
                && a.direction[p.source].dot(b.direction[p.target]) >= BONE_AGREEMENT
        }
        _ => true,
    };
    let mut out: Vec<Pair> =
        compatible(scores, pairs).into_iter().filter(|p| p.margin >= 0.0 && p.score > 0.0 && in_place(p) && end_ok(a, p.source, b, p.target)).collect();
    for &(x, y) in &limbs {
        if !matches!(a.limb[x], Limb::Front | Limb::Hind) {
            continue;
        }
        let ends = (limb_end(a, x), limb_end(b, y));
        let ankles = ankles(a, x, ends.0, b, y, ends.1, &out);
        for (s, t) in [Some((x, y)), Some(ends), ankles].into_iter().flatten() {
            // The ankles are tied where the feet are not: their depths differ by design.
            let ok = if Some((s, t)) == ankles { !a.toe[s] && !b.toe[t] } else { end_ok(a, s, b, t) };
            if !(a.moves[s] && b.moves[t] && ok) || out.iter().any(|p| p.source == s || p.target == t) {
                continue;
            }
            if let Some(score) = scores.score[s][t] {
                out.push(Pair { source: s, target: t, score, margin: 0.0, confidence: 0.5 });
            }
        }
    }
    sort_pairs(&mut out);
    out
}

/// Whether joint `s` of `a` and `t` of `b` may be bound as far as limb ends go:
///
/// * never a toe (a foot joint below the top of its foot): its rotation is mostly its
///   contact with the ground, which the target's own clips know and another species' toe
///   does not;
/// * a foot with toes below it only where both limbs have as many joints above it: which joint
///   is the ankle is ambiguous otherwise (a bird's `Foot` is the base of its toes, its ankle is
///   the `HorseLink`; binding a flamingo's and a chicken's `Foot` to a monkey's lowered frequency
///   alignment from 0.95 to 0.87 and from 0.70 to 0.51; `ankles` ties such legs' ankles
///   instead);
/// * a leaf only on the midline (a head, a tail tip) or at the end of a front or hind limb (a
///   hand, a foot), not at the end of a limb of unknown kind (ears, eyelids, a beard).
fn end_ok(a: &Described, s: usize, b: &Described, t: usize) -> bool {
    if a.toe[s] || b.toe[t] {
        return false;
    }
    let toes_below = |d: &Described, j: usize| (0..d.parents.len()).any(|c| d.parents[c] == Some(j) && d.toe[c]);
    if toes_below(a, s) || toes_below(b, t) {
        match (a.base[s], b.base[t]) {
            (Some(x), Some(y)) if depth_below(a, s, x) == depth_below(b, t, y) => {}
            (None, None) => {}
            _ => return false,
        }
    }
    let leaf_ok = |d: &Described, j: usize| !d.leaf[j] || matches!(d.limb[j], Limb::Centre | Limb::Front | Limb::Hind);
    leaf_ok(a, s) && leaf_ok(b, t)
}

/// How far apart two joints of matched limbs may sit along them (`chain_position`, 0 at the
/// first joint, 1 at the end effector): under a third, so one joint out of place in a
/// three-bone limb is too far (a dog's `LeftArm` at 1/3 with a crab claw's `Arm_03` at 2/3),
/// while a quarter is not (CMU names no foot above its toe, so its leg ends at `LeftToe`, four
/// joints down, and its `LeftAnkle` at 3/4 pairs with Xia's `LeftFoot` at 1; a tolerance of 0.2
/// dropped them).
const CHAIN_PLACE_TOLERANCE: f64 = 0.3;

/// The least cosine between the bones (parent -> joint) of a bound limb pair in the two rest
/// poses: bones pointing into opposite half-spaces turn opposite ways when one's rotation
/// drives the other. (A human's knee below the hip against a sitting dog's knee above it:
/// binding them lowered LAFAN1 -> Dog's frequency alignment from 0.64 to 0.43.)
const BONE_AGREEMENT: f64 = 0.0;

/// The ankles of two legs that end in toes but differ in length above their feet: a bird's
/// leg has one more segment than a mammal's, the tarsometatarsus, below its ankle (the
/// `HorseLink`), so its `Foot` is the base of its toes while a monkey's `Foot` is its ankle.
/// Hip, knee and ankle come in the same order in both, so the ankles are the joints one step
/// further down each leg's main chain than the deepest pair already bound inside the limb (the
/// knees, or the limbs' first joints). `None` when the feet are at the same depth (they are
/// tied as ends), when either has no toes, or when the bound pair is already at a foot.
fn ankles(a: &Described, x: usize, ea: usize, b: &Described, y: usize, eb: usize, bound: &[Pair]) -> Option<(usize, usize)> {
    let toes_below = |d: &Described, j: usize| (0..d.parents.len()).any(|c| d.parents[c] == Some(j) && d.toe[c]);
    if !(toes_below(a, ea) && toes_below(b, eb)) || depth_below(a, ea, x) == depth_below(b, eb, y) {
        return None;
    }
    // On the main chain from the limb's first joint to its end.
    let on_chain = |d: &Described, j: usize, base: usize, end: usize| d.base[j] == Some(base) && ancestor_at(d, end, base, depth_below(d, j, base)) == j;
    let (s, t) = bound
        .iter()
        .filter(|p| on_chain(a, p.source, x, ea) && on_chain(b, p.target, y, eb))
        .map(|p| (p.source, p.target))
        .chain([(x, y)])
        .max_by_key(|&(s, t)| (depth_below(a, s, x) + depth_below(b, t, y), std::cmp::Reverse(s), std::cmp::Reverse(t)))?;
    if s == ea || t == eb {
        return None;
    }
    Some((ancestor_at(a, ea, x, depth_below(a, s, x) + 1), ancestor_at(b, eb, y, depth_below(b, t, y) + 1)))
}

/// The ancestor of `j` (or `j`) that is `depth` joints below `base`.
fn ancestor_at(d: &Described, j: usize, base: usize, depth: usize) -> usize {
    let mut cur = j;
    while depth_below(d, cur, base) > depth {
        match d.parents[cur] {
            Some(p) => cur = p,
            None => break,
        }
    }
    cur
}

/// Where `j` sits along the limb starting at `base`: 0 at `base`, 1 at its end effector
/// (`limb_end`), above 1 in the digits past it.
fn chain_position(d: &Described, j: usize, base: usize) -> f64 {
    depth_below(d, j, base) as f64 / depth_below(d, limb_end(d, base), base).max(1) as f64
}

/// Whether two limbs (by their first joints) may be tied: not a limb of a single bone with one
/// of three or more bones to its end effector. A bird's one-bone wing stub held against its
/// body does not carry what a monkey's arm does when it walks on it (binding them lowered
/// Chicken -> Monkey's frequency alignment by 0.04).
fn comparable_limbs(a: &Described, x: usize, b: &Described, y: usize) -> bool {
    let (na, nb) = (depth_below(a, limb_end(a, x), x), depth_below(b, limb_end(b, y), y));
    !(na.min(nb) == 1 && na.max(nb) >= 3)
}

/// Joints from `ancestor` down to `j`.
fn depth_below(d: &Described, mut j: usize, ancestor: usize) -> usize {
    let mut n = 0;
    while j != ancestor {
        match d.parents[j] {
            Some(p) => {
                j = p;
                n += 1;
            }
            None => break,
        }
    }
    n
}

/// Limbs of `a` and `b` (by their first joints) that correspond: the same side and the same
/// limb pair, matched in order along the body axis, front limbs from the front and hind limbs
/// from the back (a dog's hind legs with a crab's rearmost legs); limbs whose pair is unknown
/// only when both skeletons have as many of them. Limbs left over stay unmatched.
pub fn match_limbs(a: &Described, b: &Described) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for side in [Side::Left, Side::Right] {
        for class in [Limb::Front, Limb::Hind, Limb::Unknown] {
            let ordered = |d: &Described| {
                let mut v: Vec<usize> = (0..d.base.len()).filter(|&j| d.base[j] == Some(j) && d.side[j] == side && d.limb[j] == class).collect();
                // Front first; hind limbs back first.
                v.sort_by(|x, y| d.forward[*y].total_cmp(&d.forward[*x]).then(x.cmp(y)));
                if class == Limb::Hind {
                    v.reverse();
                }
                v
            };
            let (x, y) = (ordered(a), ordered(b));
            if class == Limb::Unknown && x.len() != y.len() {
                continue;
            }
            out.extend(x.into_iter().zip(y));
        }
    }
    out
}

/// The end effector of the limb starting at `base`: down its chain (children that move a bone
/// and are not toes) to a foot, to where the chain branches (a hand with its fingers) or to
/// its tip.
fn limb_end(d: &Described, base: usize) -> usize {
    let n = d.parents.len();
    let mut cur = base;
    loop {
        let next: Vec<usize> = (0..n).filter(|&c| d.parents[c] == Some(cur) && d.moves[c] && !d.toe[c]).collect();
        if d.foot[cur] || next.len() != 1 {
            return cur;
        }
        cur = next[0];
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::synth;

    /// A zoo creature and its rest positions (also for `binding::auto`'s tests).
    pub(crate) fn body_of(name: &str) -> (Skeleton, Vec<DVec3>) {
        let (skeleton, _) = synth::creature(name, 1).unwrap();
        let rest = skeleton.rest_positions();
        (skeleton, rest)
    }

    /// A skeleton from (name, parent, offset) rows, every leaf with an End Site, and its rest
    /// positions (facing +z, y up).
    fn rig(rows: &[(&str, Option<usize>, [f64; 3])]) -> (Skeleton, Vec<DVec3>) {
        use crate::skeleton::Joint;
        let joints = rows
            .iter()
            .enumerate()
            .map(|(j, (name, parent, offset))| Joint {
                name: name.to_string(),
                parent: *parent,
                offset: DVec3::from_array(*offset),
                channels: vec![],
                end_sites: if rows.iter().any(|r| r.1 == Some(j)) { vec![] } else { vec![DVec3::new(0.0, -0.2, 0.2)] },
            })
            .collect();
        let skeleton = Skeleton { joints, frame_time: 1.0 / 30.0 };
        let rest = skeleton.rest_positions();
        (skeleton, rest)
    }

    /// A body with a spine, a head and two legs (the left one mirrored to the right); `leg` is
    /// the left leg below the hip as (name, offset from the parent) down the chain, `toes` the
    /// toes under its last joint, `arm` the left front limb from the chest.
    fn creature(leg: &[(&str, [f64; 3])], toes: &[(&str, [f64; 3])], arm: &[(&str, [f64; 3])]) -> (Skeleton, Vec<DVec3>) {
        let mut rows: Vec<(String, Option<usize>, [f64; 3])> = vec![
            ("Hips".into(), None, [0.0, 10.0, 0.0]),
            ("Bip01_Spine".into(), Some(0), [0.0, 0.0, 2.0]),
            ("Bip01_Neck".into(), Some(1), [0.0, 1.0, 2.0]),
            ("Bip01_Head".into(), Some(2), [0.0, 1.0, 1.0]),
        ];
        for (side, sign) in [("L", 1.0), ("R", -1.0)] {
            let mirror = |o: [f64; 3]| [sign * o[0], o[1], o[2]];
            let mut parent = 0;
            for (k, (name, offset)) in leg.iter().enumerate() {
                let offset = if k == 0 { mirror([1.0, 0.0, 0.0]) } else { mirror(*offset) };
                rows.push((format!("Bip01_{side}_{name}"), Some(parent), offset));
                parent = rows.len() - 1;
            }
            let foot = parent;
            for (name, offset) in toes {
                rows.push((format!("Bip01_{side}_{name}"), Some(foot), mirror(*offset)));
            }
            parent = 1;
            for (name, offset) in arm {
                rows.push((format!("Bip01_{side}_{name}"), Some(parent), mirror(*offset)));
                parent = rows.len() - 1;
            }
        }
        let rows: Vec<(&str, Option<usize>, [f64; 3])> = rows.iter().map(|(n, p, o)| (n.as_str(), *p, *o)).collect();
        rig(&rows)
    }

    /// A bird: hip, knee, ankle (`HorseLink`), the long tarsometatarsus down to `Foot`, the base
    /// of its toes; a one-bone wing.
    fn bird() -> (Skeleton, Vec<DVec3>) {
        creature(
            &[("Thigh", [0.0; 3]), ("Calf", [0.0, -3.0, 1.0]), ("HorseLink", [0.0, -3.0, -1.0]), ("Foot", [0.0, -3.5, 0.5])],
            &[("Toe0", [0.0, -0.4, 1.0]), ("Toe1", [0.3, -0.4, 1.0])],
            &[("Finger_01", [1.5, 0.5, 0.0]), ("Finger_02", [0.0, 0.0, -3.0])],
        )
    }

    /// A monkey: hip, knee, `Foot` (its ankle) with its toes; a four-joint arm reaching down.
    fn mammal() -> (Skeleton, Vec<DVec3>) {
        creature(
            &[("Thigh", [0.0; 3]), ("Calf", [0.0, -4.5, 0.5]), ("Foot", [0.0, -4.5, -0.5])],
            &[("Toe0", [0.0, -0.8, 1.0]), ("Toe1", [0.3, -0.8, 1.0])],
            &[("Clavicle", [1.0, 0.0, 0.0]), ("UpperArm", [1.0, -0.5, 0.0]), ("Forearm", [0.0, -4.0, 0.3]), ("Hand", [0.0, -4.0, -0.3])],
        )
    }

    fn bound(a: &(Skeleton, Vec<DVec3>), b: &(Skeleton, Vec<DVec3>), edit: impl Fn(&mut Scores)) -> Vec<(String, String)> {
        let mut sc = scores(&Body { skeleton: &a.0, rest: &a.1 }, &Body { skeleton: &b.0, rest: &b.1 }, Evidence::ALL, None).unwrap();
        edit(&mut sc);
        bindable(&sc, &assign(&sc)).iter().map(|p| (a.0.joints[p.source].name.clone(), b.0.joints[p.target].name.clone())).collect()
    }

    fn has(pairs: &[(String, String)], s: &str, t: &str) -> bool {
        pairs.iter().any(|(x, y)| x == s && y == t)
    }

    #[test]
    fn a_birds_ankle_binds_to_a_mammals_ankle_and_its_wing_stays_out() {
        let (b, m) = (bird(), mammal());
        for (pairs, bird_first) in [(bound(&b, &m, |_| {}), true), (bound(&m, &b, |_| {}), false)] {
            let bird_of = |p: &(String, String)| if bird_first { p.0.clone() } else { p.1.clone() };
            let pair = |x: &str, y: &str| if bird_first { has(&pairs, x, y) } else { has(&pairs, y, x) };
            for side in ["L", "R"] {
                let j = |n: &str| format!("Bip01_{side}_{n}");
                assert!(pair(&j("Thigh"), &j("Thigh")) && pair(&j("Calf"), &j("Calf")), "{pairs:?}");
                // The HorseLink is the bird's ankle; its Foot (the base of its toes) is not.
                assert!(pair(&j("HorseLink"), &j("Foot")), "{side}: no ankle pair in {pairs:?}");
                assert!(!pairs.iter().any(|p| bird_of(p) == j("Foot")), "{side}: the bird's Foot is bound: {pairs:?}");
                // A one-bone wing is no arm.
                assert!(!pairs.iter().any(|p| bird_of(p).contains("Finger")), "{side}: the wing is bound: {pairs:?}");
            }
        }
        // Two mammals: the feet are the limbs' ends (no ankle rule), arms tied at both ends.
        let pairs = bound(&m, &m, |_| {});
        assert!(
            has(&pairs, "Bip01_L_Foot", "Bip01_L_Foot") && has(&pairs, "Bip01_L_Clavicle", "Bip01_L_Clavicle") && has(&pairs, "Bip01_L_Hand", "Bip01_L_Hand"),
            "{pairs:?}"
        );
    }

    #[test]
    fn limb_pairs_keep_their_place_along_the_limb() {
        let m = mammal();
        let idx = |n: &str| m.0.index_of(n).unwrap();
        let (upper, fore) = (idx("Bip01_L_UpperArm"), idx("Bip01_L_Forearm"));
        // Evidence (names, say) that swaps the upper arm and the forearm: each one joint out of
        // place in a three-bone arm.
        let swapped = bound(&m, &m, |sc| {
            sc.score[upper][fore] = Some(5.0);
            sc.score[fore][upper] = Some(5.0);
        });
        assert!(!has(&swapped, "Bip01_L_UpperArm", "Bip01_L_Forearm") && !has(&swapped, "Bip01_L_Forearm", "Bip01_L_UpperArm"), "{swapped:?}");
        assert!(has(&swapped, "Bip01_L_Clavicle", "Bip01_L_Clavicle") && has(&swapped, "Bip01_L_Hand", "Bip01_L_Hand"), "{swapped:?}");
        assert!(has(&bound(&m, &m, |_| {}), "Bip01_L_UpperArm", "Bip01_L_UpperArm"));
    }

    #[test]
    fn a_knee_bent_the_other_way_is_not_bound() {
        let m = mammal();
        // The same creature sitting: its left knee above the hip, the shin folded back down.
        let mut sitting = m.0.clone();
        let (calf, foot) = (sitting.index_of("Bip01_L_Calf").unwrap(), sitting.index_of("Bip01_L_Foot").unwrap());
        sitting.joints[calf].offset = DVec3::new(1.0, 3.0, 3.0);
        sitting.joints[foot].offset = DVec3::new(0.0, -7.0, 0.5);
        let rest = sitting.rest_positions();
        let pairs = bound(&m, &(sitting, rest), |_| {});
        assert!(!has(&pairs, "Bip01_L_Calf", "Bip01_L_Calf"), "{pairs:?}");
        assert!(has(&pairs, "Bip01_R_Calf", "Bip01_R_Calf") && has(&pairs, "Bip01_L_Thigh", "Bip01_L_Thigh"), "{pairs:?}");
    }

    #[test]
    fn a_skeleton_matches_itself_with_any_evidence() {
        for name in ["biped", "quadruped", "spider", "centipede"] {
            let (s, rest) = body_of(name);
            let body = Body { skeleton: &s, rest: &rest };
            for ev in [Evidence::ALL, Evidence::NAMES, Evidence::GEOMETRY] {
                let sc = scores(&body, &body, ev, None).unwrap();
                let pairs = assign(&sc);
                let right = pairs.iter().filter(|p| p.source == p.target).count();
                assert_eq!(right, s.len(), "{name} {ev:?}: {right} of {}", s.len());
            }
        }
    }

    #[test]
    fn spider_and_centipede_legs_keep_their_numbers_and_pairs() {
        for name in ["spider", "centipede"] {
            let (s, rest) = body_of(name);
            let d = describe(&s, &rest, true, Roles::Names);
            let legs: Vec<usize> = (0..s.len()).filter(|&j| d.side[j] == Side::Left && d.keys[j].words.contains(&"leg".to_string())).collect();
            let mut ordinals: Vec<u64> = legs.iter().flat_map(|&j| d.keys[j].ordinals.clone()).collect();
            ordinals.sort();
            ordinals.dedup();
            assert!(ordinals.len() >= 4, "{name}: ordinals {ordinals:?}");
            // The legs split into front and hind pairs by the rest pose.
            assert!(legs.iter().any(|&j| d.limb[j] == Limb::Front) && legs.iter().any(|&j| d.limb[j] == Limb::Hind), "{name}");
        }
    }

    #[test]
    fn never_left_with_right_nor_front_with_hind() {
        let (b, rb) = body_of("biped");
        let (q, rq) = body_of("quadruped");
        let sc = scores(&Body { skeleton: &b, rest: &rb }, &Body { skeleton: &q, rest: &rq }, Evidence::ALL, None).unwrap();
        for p in assign(&sc) {
            let (x, y) = (sc.source.side[p.source], sc.target.side[p.target]);
            assert!(!matches!((x, y), (Side::Left, Side::Right) | (Side::Right, Side::Left)), "{p:?}");
            let (x, y) = (sc.source.limb[p.source], sc.target.limb[p.target]);
            assert!(!matches!((x, y), (Limb::Front, Limb::Hind) | (Limb::Hind, Limb::Front)), "{p:?}");
        }
        let short = Body { skeleton: &b, rest: &rb[..2] };
        assert!(matches!(scores(&short, &short, Evidence::ALL, None), Err(CorrespondError::RestSize { .. })));
    }
}
