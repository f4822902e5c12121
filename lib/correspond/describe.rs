//! What the correspondence engine knows about each joint of one skeleton, computed once:
//! name key, side, limb pair (front/hind), position along its limb, rest-pose place and bone
//! directions, and a topology signature.
//!
//! Front and hind come from the names when the skeleton's names tell its limb pairs apart
//! (some limbs have arm/hand words and others leg/foot words); otherwise from the rest pose:
//! which end of the body axis the limb hangs from. The body axis is the main direction of the
//! centre joints, oriented up-or-forward (the rest pose faces +z), so a human's arms and a
//! dog's forelegs are both "front".

use super::names::{self as keys, LimbWord, NameKey};
use crate::skeleton::names::{self, Side};
use crate::skeleton::{roles, Skeleton};

use glam::DVec3;

/// Which limb pair a joint belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limb {
    /// On the body's midline (spine, neck, head, tail).
    Centre,
    Front,
    Hind,
    /// A sided joint whose limb pair neither names nor rest pose tell.
    Unknown,
}

/// One skeleton as the engine sees it.
pub struct Described {
    pub keys: Vec<NameKey>,
    pub side: Vec<Side>,
    pub limb: Vec<Limb>,
    /// Depth below the limb's first joint over the limb's depth (0 at the shoulder/hip, 1 at
    /// the tip); centre joints: depth over the skeleton's depth.
    pub along: Vec<f64>,
    /// Rest position relative to the root over the skeleton's size.
    pub place: Vec<DVec3>,
    /// Unit bone direction (parent -> joint); zero for the root.
    pub direction: Vec<DVec3>,
    /// Subtree sizes from the root down to the joint: equal for joints in the same place of
    /// two identical trees, whatever the file order.
    pub signature: Vec<Vec<usize>>,
    pub parents: Vec<Option<usize>>,
    pub leaf: Vec<bool>,
    /// Feet and toes (`roles::feet`: AnyTop's foot words and what hangs below them, else the
    /// lowest joints of the rest pose).
    pub foot: Vec<bool>,
    /// Toes and digits: feet below the top of their foot (a foot joint whose parent is a foot).
    pub toe: Vec<bool>,
    /// The joint moves a bone: it has a child joint or an End Site (BVH's mark of a bone's end;
    /// a head's End Site may sit at the joint itself, yet the head's rotation is animated).
    pub moves: Vec<bool>,
    /// The first joint of the joint's limb (`None` on the midline).
    pub base: Vec<Option<usize>>,
    /// Where each limb base sits along the body axis (larger is further front or up; 0 for
    /// joints that are not limb bases): orders limbs of one side and class front to back.
    pub forward: Vec<f64>,
    /// Some joint has a side.
    pub has_sides: bool,
    /// Sides (and limb pairs) come from the names; otherwise from the rest pose.
    pub named_sides: bool,
}

/// Where sides and limb pairs come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Roles {
    /// Names where they say, the rest pose otherwise (`roles::sides`, limb words).
    Names,
    /// The rest pose alone (`roles::sides` without names; front is up or forward). Two
    /// skeletons compare in this view when either one's names are silent: a named side and a
    /// geometric side need not agree on rigs whose rest pose is not the BVH convention.
    Geometry,
}

/// Describe `skeleton` with rest positions `rest` (facing +z, y up). `use_names` false leaves
/// the name keys blank; `roles` says where sides and limb pairs come from.
pub fn describe(skeleton: &Skeleton, rest: &[DVec3], use_names: bool, roles: Roles) -> Described {
    let n = skeleton.len();
    let parents = skeleton.parents();
    let children = skeleton.children();
    let keys: Vec<NameKey> = skeleton.joints.iter().map(|j| if use_names { keys::key(&j.name) } else { NameKey::default() }).collect();
    let root = rest.first().copied().unwrap_or(DVec3::ZERO);
    let (lo, hi) = rest.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = if n == 0 { 1.0 } else { (hi - lo).max_element().max(1e-9) };
    let place: Vec<DVec3> = rest.iter().map(|p| (*p - root) / size).collect();
    let normalised: Vec<String> = skeleton.joints.iter().map(|j| names::normalise(&j.name)).collect();
    let named_sides = normalised.iter().any(|s| names::side_from_name(s).is_some());
    let side = match roles {
        Roles::Names => roles::sides(skeleton, &normalised),
        Roles::Geometry => roles::sides(skeleton, &vec![String::new(); n]),
    };
    let has_sides = side.iter().any(|s| *s != Side::Centre);
    let direction = (0..n)
        .map(|j| match parents[j] {
            Some(p) => (rest[j] - rest[p]).try_normalize().unwrap_or(DVec3::ZERO),
            None => DVec3::ZERO,
        })
        .collect();
    let depth = skeleton.depths();
    // Subtree sizes (children follow parents in file order).
    let mut subtree = vec![1usize; n];
    for j in (0..n).rev() {
        if let Some(p) = parents[j] {
            subtree[p] += subtree[j];
        }
    }
    let mut signature: Vec<Vec<usize>> = vec![Vec::new(); n];
    for j in 0..n {
        let mut sig = parents[j].map(|p| signature[p].clone()).unwrap_or_default();
        sig.push(subtree[j]);
        signature[j] = sig;
    }
    // Limbs: a sided joint whose parent is not sided (or the root) starts a limb.
    let mut base = vec![usize::MAX; n];
    for j in 0..n {
        if side[j] == Side::Centre {
            continue;
        }
        base[j] = match parents[j] {
            Some(p) if side[p] != Side::Centre => base[p],
            _ => j,
        };
    }
    let mut limb_depth = vec![0usize; n];
    for j in 0..n {
        if base[j] != usize::MAX {
            let b = base[j];
            limb_depth[b] = limb_depth[b].max(depth[j] - depth[b]);
        }
    }
    let max_depth = depth.iter().copied().max().unwrap_or(0).max(1);
    let along =
        (0..n)
            .map(|j| {
                if base[j] == usize::MAX {
                    depth[j] as f64 / max_depth as f64
                } else {
                    (depth[j] - depth[base[j]]) as f64 / limb_depth[base[j]].max(1) as f64
                }
            })
            .collect();
    let bases: Vec<usize> = (0..n).filter(|&j| base[j] == j).collect();
    let limb_keys: &[NameKey] = if roles == Roles::Names { &keys } else { &[] };
    let axis = body_axis(&side, &place);
    let class_of_base = limb_classes(&bases, &base, limb_keys, &place, axis, n);
    let mut forward = vec![0.0; n];
    for &b in &bases {
        forward[b] = place[b].dot(axis.unwrap_or(DVec3::new(0.0, 1.0, 1.0).normalize()));
    }
    let limb = (0..n).map(|j| if base[j] == usize::MAX { Limb::Centre } else { class_of_base[base[j]] }).collect();
    let leaf = children.iter().map(Vec::is_empty).collect();
    let mut foot = vec![false; n];
    for f in roles::feet(skeleton).0 {
        foot[f] = true;
    }
    let toe = (0..n).map(|j| foot[j] && parents[j].is_some_and(|p| foot[p])).collect();
    let moves = (0..n).map(|j| !children[j].is_empty() || !skeleton.joints[j].end_sites.is_empty()).collect();
    let base = base.iter().map(|&b| (b != usize::MAX).then_some(b)).collect();
    Described { keys, side, limb, along, place, direction, signature, parents, leaf, foot, toe, moves, base, forward, has_sides, named_sides }
}

/// Front or hind for every limb base (indexed by joint): by names when the names tell the
/// limb pairs apart, else by the rest pose.
fn limb_classes(bases: &[usize], base: &[usize], keys: &[NameKey], place: &[DVec3], axis: Option<DVec3>, n: usize) -> Vec<Limb> {
    let mut out = vec![Limb::Unknown; n];
    // Votes of every joint's words in each limb.
    let mut votes = vec![(0usize, 0usize); n];
    for j in 0..keys.len().min(n) {
        if base[j] == usize::MAX {
            continue;
        }
        match keys::limb_word(&keys[j]) {
            Some(LimbWord::Front) => votes[base[j]].0 += 1,
            Some(LimbWord::Hind) => votes[base[j]].1 += 1,
            None => {}
        }
    }
    let named = |b: usize| match votes[b] {
        (f, h) if f > h => Some(Limb::Front),
        (f, h) if h > f => Some(Limb::Hind),
        _ => None,
    };
    let by_name: Vec<Option<Limb>> = bases.iter().map(|&b| named(b)).collect();
    let distinguishes = by_name.contains(&Some(Limb::Front)) && by_name.contains(&Some(Limb::Hind));
    if distinguishes {
        for (k, &b) in bases.iter().enumerate() {
            out[b] = by_name[k].unwrap_or(Limb::Unknown);
        }
        return out;
    }
    // Rest pose: which end of the body axis the limb hangs from.
    let Some(axis) = axis else { return out };
    let proj: Vec<f64> = bases.iter().map(|&b| place[b].dot(axis)).collect();
    let (lo, hi) = proj.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    if !(hi - lo > 0.05) {
        return out;
    }
    let mid = 0.5 * (lo + hi);
    for (k, &b) in bases.iter().enumerate() {
        out[b] = if proj[k] > mid { Limb::Front } else { Limb::Hind };
    }
    out
}

/// The body axis: the main direction of the centre joints, oriented up-or-forward (the rest
/// pose faces +z); `None` when the centre joints do not spread.
fn body_axis(side: &[Side], place: &[DVec3]) -> Option<DVec3> {
    let centre: Vec<DVec3> = (0..side.len()).filter(|&j| side[j] == Side::Centre).map(|j| place[j]).collect();
    let axis = main_direction(&centre)?;
    Some(if axis.dot(DVec3::new(0.0, 1.0, 1.0)) < 0.0 { -axis } else { axis })
}

/// The direction of largest spread of `points` (power iteration on the 3x3 covariance);
/// `None` for fewer than two distinct points.
fn main_direction(points: &[DVec3]) -> Option<DVec3> {
    if points.len() < 2 {
        return None;
    }
    let mean = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let mut cov = [[0.0f64; 3]; 3];
    for p in points {
        let d = (*p - mean).to_array();
        for r in 0..3 {
            for c in 0..3 {
                cov[r][c] += d[r] * d[c];
            }
        }
    }
    let mut v = DVec3::new(0.3, 0.9, 0.5);
    for _ in 0..50 {
        let a = v.to_array();
        let next = DVec3::new(
            cov[0][0] * a[0] + cov[0][1] * a[1] + cov[0][2] * a[2],
            cov[1][0] * a[0] + cov[1][1] * a[1] + cov[1][2] * a[2],
            cov[2][0] * a[0] + cov[2][1] * a[1] + cov[2][2] * a[2],
        );
        v = next.try_normalize()?;
    }
    Some(v)
}
