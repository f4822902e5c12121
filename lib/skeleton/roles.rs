//! Body roles of joints that algorithms need without a per-species table: sides and feet.
//!
//! Names first, geometry when names say nothing. Geometry assumes the BVH convention that a
//! skeleton's rest pose is y-up; the lateral axis is whichever horizontal axis the skeleton is
//! mirror-symmetric about (x for most files, z for some Truebones rigs).

use super::names::{self, Side};
use super::Skeleton;
use glam::DVec3;

/// AnyTop's foot words (docs/reference/anytop.md §1.3.7): a joint whose lower-cased raw name
/// contains one of these is a foot candidate, and so are all of its descendants.
const FOOT_WORDS: &[&str] = &["toe", "foot", "phalanx", "hoof", "ashi"];

/// Fraction of the rest-pose height below which joints count as feet when no name says "foot".
const GEOMETRIC_FOOT_BAND: f64 = 0.1;

/// Lowest joint this far above y = 0 (as a fraction of the creature's size): not standing.
const GROUND_CLEARANCE: f64 = 0.25;

/// How feet were found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FootRule {
    /// AnyTop's name rule.
    Names,
    /// Joints in the lowest band of the rest pose.
    Geometry,
}

/// Foot joints (sorted) and the rule that found them.
pub fn feet(skeleton: &Skeleton) -> (Vec<usize>, FootRule) {
    let n = skeleton.len();
    let mut is_foot = vec![false; n];
    for (j, joint) in skeleton.joints.iter().enumerate() {
        let lower = joint.name.to_lowercase();
        let named = FOOT_WORDS.iter().any(|w| lower.contains(w));
        // Parents precede children, so one pass propagates to all descendants.
        let parent_is_foot = joint.parent.is_some_and(|p| is_foot[p]);
        is_foot[j] = named || parent_is_foot;
    }
    if is_foot.iter().any(|&f| f) {
        return ((0..n).filter(|&j| is_foot[j]).collect(), FootRule::Names);
    }
    // Joints only (End Sites would put the band below the foot joints they hang from).
    let pos = skeleton.rest_positions();
    let lo = pos.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let hi = pos.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
    let extent = skeleton.rest_extent().max(1e-12);
    // A creature whose lowest joint hovers well above the ground plane (a fish, a bird in
    // flight pose) has no feet to find.
    if lo > GROUND_CLEARANCE * extent {
        return (Vec::new(), FootRule::Geometry);
    }
    // For a flat creature (a snake) the band is measured against its length, so the whole
    // body that rests on the ground counts, as AnyTop treats snakes.
    let band = lo + GEOMETRIC_FOOT_BAND * (hi - lo).max(GEOMETRIC_FOOT_BAND * extent);
    let feet = (0..n).filter(|&j| pos[j].y <= band && (j != 0 || n == 1)).collect();
    (feet, FootRule::Geometry)
}

/// Left/right/centre for every joint: the name's side; else an ancestor's named side; else,
/// only when no joint names a side at all, the side of the symmetry plane the joint lies on;
/// else centre. Geometry is not mixed with names because many rigs' rest poses are not
/// upright (Bandai Namco and Truebones rigs lie along x), where an unnamed spine joint would
/// land on a "side".
pub fn sides(skeleton: &Skeleton, normalised: &[String]) -> Vec<Side> {
    let n = skeleton.len();
    let named: Vec<Option<Side>> = normalised.iter().map(|s| names::side_from_name(s)).collect();
    let geometric = if named.iter().any(Option::is_some) { vec![Side::Centre; n] } else { geometric_sides(skeleton, &skeleton.rest_positions()) };
    let mut out = vec![Side::Centre; n];
    for j in 0..n {
        out[j] = match named[j] {
            Some(s) => s,
            None => match skeleton.joints[j].parent.map(|p| out[p]) {
                Some(s @ (Side::Left | Side::Right)) if geometric[j] == Side::Centre || geometric[j] == s => s,
                _ => geometric[j],
            },
        };
    }
    out
}

/// Sides from geometry: pick the horizontal axis about which the rest pose is most
/// mirror-symmetric; joints clearly off that plane get a side by the sign of their coordinate,
/// following the BVH convention (a character faces +z, so its left is +x; a rig facing +x has
/// its left at -z).
fn geometric_sides(skeleton: &Skeleton, pos: &[DVec3]) -> Vec<Side> {
    let n = pos.len();
    let root = pos[0];
    let scale = skeleton.rest_extent().max(1e-12);
    let tol = 0.02 * scale;
    let parents = skeleton.parents();
    let depth = skeleton.depths();
    let child_count = {
        let mut c = vec![0usize; n];
        for p in parents.iter().flatten() {
            c[*p] += 1;
        }
        c
    };
    // Lowest common ancestor by walking up from the deeper joint.
    let lca = |mut a: usize, mut b: usize| -> usize {
        while a != b {
            if depth[a] >= depth[b] {
                a = parents[a].unwrap_or(a);
            } else {
                b = parents[b].unwrap_or(b);
            }
            if parents[a].is_none() && parents[b].is_none() {
                break;
            }
        }
        a
    };
    // Symmetry score of an axis: how many off-plane joints have a mirror partner that hangs
    // from a branching joint with a third branch (the body going on). That excludes the two
    // halves of a body whose root sits in its middle (a snake along z is "symmetric" front to
    // back), while left/right limbs always leave the body at a joint the spine continues from.
    let score = |axis: usize| -> usize {
        (0..n)
            .filter(|&j| (pos[j][axis] - root[axis]).abs() > tol)
            .filter(|&j| {
                let mut m = pos[j];
                m[axis] = 2.0 * root[axis] - m[axis];
                (0..n).any(|k| k != j && depth[k] == depth[j] && pos[k].distance(m) < tol && child_count[lca(j, k)] >= 3)
            })
            .count()
    };
    let (sx, sz) = (score(0), score(2));
    if sx == 0 && sz == 0 {
        return vec![Side::Centre; n];
    }
    let (axis, left_sign) = if sx >= sz { (0, 1.0) } else { (2, -1.0) };
    (0..n)
        .map(|j| {
            let d = pos[j][axis] - root[axis];
            if d.abs() <= tol {
                Side::Centre
            } else if d.signum() == left_sign {
                Side::Left
            } else {
                Side::Right
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh;

    fn skeleton(text: &str) -> Skeleton {
        Skeleton::from_bvh(&bvh::parse(text, "test").unwrap())
    }

    /// Root with two mirrored unnamed legs and a tail: sides come from geometry (+x = left).
    const UNNAMED: &str = "HIERARCHY\nROOT j0\n{\nOFFSET 0 1 0\nCHANNELS 0\nJOINT j1\n{\nOFFSET 0.3 -0.5 0\nCHANNELS 0\nJOINT j2\n{\nOFFSET 0 -0.5 0\nCHANNELS 0\n}\n}\nJOINT j3\n{\nOFFSET -0.3 -0.5 0\nCHANNELS 0\nJOINT j4\n{\nOFFSET 0 -0.5 0\nCHANNELS 0\n}\n}\nJOINT j5\n{\nOFFSET 0 0 -0.8\nCHANNELS 0\n}\n}\nMOTION\nFrames: 0\nFrame Time: 0.1\n";

    #[test]
    fn geometry_gives_sides_and_feet_when_names_are_silent() {
        let s = skeleton(UNNAMED);
        let norm: Vec<String> = s.joints.iter().map(|j| names::normalise(&j.name)).collect();
        let sides = sides(&s, &norm);
        assert_eq!(sides, vec![Side::Centre, Side::Left, Side::Left, Side::Right, Side::Right, Side::Centre]);
        let (f, rule) = feet(&s);
        assert_eq!(rule, FootRule::Geometry);
        assert_eq!(f, vec![2, 4]);
    }

    #[test]
    fn names_win_and_unnamed_joints_inherit_or_stay_centre() {
        let text = UNNAMED.replace("j1", "LeftLeg").replace("j2", "ankle").replace("j3", "Leg_R").replace("j4", "paw").replace("j5", "Tail_Foot");
        let s = skeleton(&text);
        let norm: Vec<String> = s.joints.iter().map(|j| names::normalise(&j.name)).collect();
        assert_eq!(sides(&s, &norm), vec![Side::Centre, Side::Left, Side::Left, Side::Right, Side::Right, Side::Centre]);
        // AnyTop's name rule: "foot" in the name, plus descendants.
        assert_eq!(feet(&s), (vec![5], FootRule::Names));
    }

    #[test]
    fn a_body_with_its_root_in_the_middle_is_not_left_and_right() {
        // A flat snake along z, root in the middle: front and back halves mirror each other
        // about z = 0 but are not sides; all of the body on the ground counts as contact.
        let mut text = String::from("HIERARCHY\nROOT mid\n{\nOFFSET 0 0 0\nCHANNELS 0\n");
        for (dir, tag) in [(1.0, "f"), (-1.0, "b")] {
            for k in 0..4 {
                text += &format!("JOINT {tag}{k}\n{{\nOFFSET 0 0 {}\nCHANNELS 0\n", dir * 0.1);
            }
            text += &"}\n".repeat(4);
        }
        text += "}\nMOTION\nFrames: 0\nFrame Time: 0.1\n";
        let s = skeleton(&text);
        let norm: Vec<String> = s.joints.iter().map(|j| names::normalise(&j.name)).collect();
        assert!(sides(&s, &norm).iter().all(|&x| x == Side::Centre));
        let (f, rule) = feet(&s);
        assert_eq!((f.len(), rule), (8, FootRule::Geometry));
    }

    #[test]
    fn a_hovering_creature_has_no_geometric_feet() {
        let text = UNNAMED.replace("OFFSET 0 1 0", "OFFSET 0 5 0");
        assert_eq!(feet(&skeleton(&text)), (Vec::new(), FootRule::Geometry));
    }
}
