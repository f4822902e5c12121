//! Tests of the zoo. The clips are test data for everything else, so these check the
//! properties other tests will lean on: byte-stable output per seed, a clean round trip through
//! our own parser, the anatomy promised by the names (joint counts, legs, sides, mirror
//! symmetry, findable feet), and feet that actually plant instead of skating.

use super::*;
use crate::skeleton::names::{self, Side};
use crate::skeleton::{roles, Stats};

fn text(name: &str, seed: u64) -> String {
    bvh::write_string(&creature_bvh(name, seed).expect("known creature"))
}

/// (creature, joints, legs found by the foot rule; 0 = no named feet)
const ANATOMY: &[(&str, usize, usize)] = &[
    ("biped", 22, 2),
    ("quadruped", 26, 4),
    ("spider", 36, 8),
    ("centipede", 88, 24),
    ("snake", 25, 0),
    ("bird", 24, 2),
    ("fish", 14, 0),
    ("crab", 43, 8),
    ("dragon", 38, 4),
];

#[test]
fn every_creature_is_listed_and_unknown_names_are_none() {
    let listed: Vec<&str> = ANATOMY.iter().map(|a| a.0).collect();
    assert_eq!(creature_names(), listed.as_slice());
    assert!(CREATURES.iter().map(|c| c.0).eq(NAMES.iter().copied()), "generator table and name list disagree");
    for required in ["biped", "quadruped", "spider", "centipede", "snake", "bird", "fish"] {
        assert!(creature_names().contains(&required), "{required}");
    }
    assert!(creature("unicorn", 1).is_none());
}

#[test]
fn same_seed_gives_identical_bytes_and_other_seeds_differ() {
    for name in creature_names() {
        let a = text(name, 7);
        assert_eq!(a, text(name, 7), "{name}: not deterministic");
        assert_ne!(a, text(name, 8), "{name}: seed has no effect");
    }
}

#[test]
fn files_parse_back_to_the_same_skeleton_and_motion() {
    for &(name, joints, _) in ANATOMY {
        let (skel, motion) = creature(name, DEFAULT_SEED).unwrap();
        assert_eq!(skel.len(), joints, "{name}: joint count");
        let text = text(name, DEFAULT_SEED);
        assert!(text.len() < 300_000, "{name}: {} bytes", text.len());
        let parsed = bvh::parse(&text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let back = Skeleton::from_bvh(&parsed);
        assert_eq!(back, skel, "{name}: hierarchy changed in the round trip");
        assert!((60..=120).contains(&parsed.frames), "{name}: {} frames", parsed.frames);
        assert_eq!(parsed.frames, motion.frames);
        assert_eq!(parsed.frame_time, FRAME_TIME);
        // Rounding and Euler decomposition must not move any joint visibly.
        let a = motion.forward_kinematics(&skel);
        let b = Motion::from_bvh(&parsed, &back).forward_kinematics(&back);
        let worst = a.positions.iter().zip(&b.positions).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
        assert!(worst < 1e-4 * skel.rest_extent(), "{name}: FK differs by {worst} after the round trip");
    }
}

#[test]
fn channel_layouts_vary_and_end_sites_close_every_leaf() {
    let mut orders = std::collections::BTreeSet::new();
    let mut all_six = Vec::new();
    for name in creature_names() {
        let (skel, _) = creature(name, DEFAULT_SEED).unwrap();
        let children = skel.children();
        let root = &skel.joints[0].channels;
        assert_eq!(root.len(), 6, "{name}: root channels");
        assert!(root[..3].iter().all(|c| !c.is_rotation()), "{name}: root positions first");
        for (j, joint) in skel.joints.iter().enumerate() {
            assert!(joint.channels.len() == 3 || joint.channels.len() == 6, "{name}/{}", joint.name);
            let order: String = joint.channels.iter().filter(|c| c.is_rotation()).map(|c| &c.name()[..1]).collect();
            orders.insert(order);
            if children[j].is_empty() {
                assert_eq!(joint.end_sites.len(), 1, "{name}/{}: leaf without End Site", joint.name);
            }
        }
        if skel.joints.iter().all(|j| j.channels.len() == 6) {
            all_six.push(*name);
        }
    }
    assert!(orders.len() >= 4, "Euler orders used: {orders:?}");
    assert!(!all_six.is_empty(), "no creature has six channels on every joint");
}

#[test]
fn rest_poses_are_mirror_symmetric_with_named_sides() {
    for name in creature_names() {
        let (skel, _) = creature(name, DEFAULT_SEED).unwrap();
        let pos = skel.rest_positions();
        let normalised: Vec<String> = skel.joints.iter().map(|j| names::normalise(&j.name)).collect();
        let sides = roles::sides(&skel, &normalised);
        let tol = 1e-9;
        for (j, p) in pos.iter().enumerate() {
            let want = if p.x > tol {
                Side::Left
            } else if p.x < -tol {
                Side::Right
            } else {
                Side::Centre
            };
            assert_eq!(sides[j], want, "{name}/{}: side", skel.joints[j].name);
            if want == Side::Centre {
                continue;
            }
            let mirrored = DVec3::new(-p.x, p.y, p.z);
            let partner = pos.iter().position(|q| q.distance(mirrored) < tol);
            let partner = partner.unwrap_or_else(|| panic!("{name}/{}: no mirror partner", skel.joints[j].name));
            // Partners share a name once the side is dropped, and their End Sites mirror too.
            let strip = |s: &str| s.trim_start_matches("Left ").trim_start_matches("Right ").to_string();
            assert_eq!(strip(&normalised[j]), strip(&normalised[partner]), "{name}/{}", skel.joints[j].name);
            for (a, b) in skel.joints[j].end_sites.iter().zip(&skel.joints[partner].end_sites) {
                assert!((*a - DVec3::new(-b.x, b.y, b.z)).length() < tol, "{name}/{}: End Site", skel.joints[j].name);
            }
        }
    }
}

#[test]
fn feet_are_found_by_name_and_count_the_legs() {
    for &(name, _, legs) in ANATOMY {
        let (skel, _) = creature(name, DEFAULT_SEED).unwrap();
        let (feet, rule) = roles::feet(&skel);
        if legs == 0 {
            assert_eq!(rule, roles::FootRule::Geometry, "{name}: limbless creatures have no foot names");
            continue;
        }
        assert_eq!(rule, roles::FootRule::Names, "{name}");
        // One leg per foot subtree: feet whose parent is not a foot.
        let tops = feet.iter().filter(|&&j| skel.joints[j].parent.is_none_or(|p| !feet.contains(&p))).count();
        assert_eq!(tops, legs, "{name}: legs");
    }
    let (bird, _) = creature("bird", DEFAULT_SEED).unwrap();
    assert_eq!(bird.joints.iter().filter(|j| j.name.contains("Wing")).count(), 6);
}

/// Ground contact points of a creature: every End Site under a named foot, and the foot joint
/// it hangs from (contact detectors look at joints, which must be still too).
pub(super) fn contacts(skel: &Skeleton) -> Vec<(usize, DVec3)> {
    let (feet, _) = roles::feet(skel);
    let mut out = Vec::new();
    for &j in &feet {
        if let Some(e) = skel.joints[j].end_sites.first() {
            out.push((j, DVec3::ZERO));
            out.push((j, *e));
        }
    }
    out
}

/// Per contact: (fraction of frames near the ground, median horizontal speed in those frames,
/// fastest horizontal speed), all speeds relative to the root's mean speed.
pub(super) fn planting(skel: &Skeleton, motion: &Motion) -> Vec<(String, f64, f64, f64)> {
    let world = motion.forward_kinematics(skel);
    let n = motion.frames;
    let dt = motion.frame_time;
    let flat = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
    let root_speed = flat(world.position(n - 1, 0) - world.position(0, 0)).length() / ((n - 1) as f64 * dt);
    let near = 0.01 * skel.rest_height();
    contacts(skel)
        .into_iter()
        .map(|(j, end)| {
            let at = |f: usize| world.position(f, j) + world.rotations[f * world.joints + j] * end;
            let heights: Vec<f64> = (0..n).map(|f| at(f).y).collect();
            let ground = heights.iter().copied().fold(f64::INFINITY, f64::min);
            let speeds: Vec<(bool, f64)> =
                (1..n - 1).map(|f| (heights[f] - ground < near, flat(at(f + 1) - at(f - 1)).length() / (2.0 * dt) / root_speed)).collect();
            let stance: Vec<f64> = speeds.iter().filter(|s| s.0).map(|s| s.1).collect();
            let median = Stats::of(&stance).map_or(f64::INFINITY, |s| s.median);
            let fastest = speeds.iter().map(|s| s.1).fold(0.0, f64::max);
            (skel.joints[j].name.clone(), stance.len() as f64 / speeds.len() as f64, median, fastest)
        })
        .collect()
}

#[test]
fn feet_plant_during_stance_and_swing_in_between() {
    for &(name, _, legs) in ANATOMY {
        if legs == 0 {
            continue;
        }
        // Measured on the written file, rounding and all: that is what users get.
        let parsed = bvh::parse(&text(name, DEFAULT_SEED), name).unwrap();
        let skel = Skeleton::from_bvh(&parsed);
        let rows = planting(&skel, &Motion::from_bvh(&parsed, &skel));
        assert!(rows.len() >= legs, "{name}: {} contacts", rows.len());
        let worst = rows.iter().map(|r| r.2).fold(0.0, f64::max);
        for (joint, share, median, fastest) in &rows {
            // Each foot spends a real stance on the ground ...
            assert!(*share > 0.3, "{name}/{joint}: on the ground only {share:.2} of the time");
            // ... does not skate while there ...
            assert!(*median < 0.15, "{name}/{joint}: median stance speed {median:.3} of the root's");
            // ... and catches up with the body in swing (it is not simply dragged along).
            assert!(*fastest > 1.5, "{name}/{joint}: fastest {fastest:.2} of the root's");
        }
        let least = rows.iter().map(|r| r.1).fold(1.0, f64::min);
        let n = rows.len();
        eprintln!("{name}: {n} contact points, grounded >= {least:.2} of frames, stance speed <= {worst:.1e} x root");
    }
}

#[test]
fn the_planting_measure_catches_skating_feet() {
    // The same walk with the legs frozen in their rest pose: the feet now slide along with the
    // body, and the measure must say so.
    let (skel, mut motion) = creature("quadruped", DEFAULT_SEED).unwrap();
    for f in 0..motion.frames {
        for j in 1..motion.joints {
            motion.rotations[f * motion.joints + j] = DQuat::IDENTITY;
        }
    }
    for (joint, _, median, _) in planting(&skel, &motion) {
        assert!(median > 0.5, "{joint}: skating not detected ({median})");
    }
}

#[test]
fn nothing_goes_through_the_ground_and_bodies_move_forward() {
    for name in creature_names() {
        let (skel, motion) = creature(name, DEFAULT_SEED).unwrap();
        let world = motion.forward_kinematics(&skel);
        let h = skel.rest_height().max(0.05);
        let mut lowest = f64::INFINITY;
        for f in 0..motion.frames {
            for j in 0..skel.len() {
                lowest = lowest.min(world.position(f, j).y);
                for e in &skel.joints[j].end_sites {
                    lowest = lowest.min((world.position(f, j) + world.rotations[f * world.joints + j] * *e).y);
                }
            }
        }
        assert!(lowest > -0.01 * h, "{name}: reaches y = {lowest}");
        let travel = world.position(motion.frames - 1, 0) - world.position(0, 0);
        assert!(travel.z > 0.2 * skel.rest_extent(), "{name}: travels {travel}");
        assert!(travel.x.abs() < 0.2 * travel.z, "{name}: drifts sideways {travel}");
    }
}

#[test]
fn two_bone_ik_reaches_reachable_targets_and_bends_towards_the_pole() {
    let hip = DVec3::new(0.0, 1.0, 0.0);
    let target = DVec3::new(0.0, 0.2, 0.3);
    let knee = two_bone_knee(hip, target, 0.5, 0.45, DVec3::Z);
    assert!((knee.distance(hip) - 0.5).abs() < 1e-12);
    assert!((knee.distance(target) - 0.45).abs() < 1e-12);
    assert!(knee.z > (hip.z + target.z) / 2.0, "knee bends backwards: {knee}");
    // Out of reach: a straight limb pointing at the target, never NaN.
    let far = two_bone_knee(hip, DVec3::new(0.0, -5.0, 0.0), 0.5, 0.45, DVec3::Z);
    assert!(far.is_finite() && (far.y - 0.5).abs() < 1e-3);
}

#[test]
fn splitmix_matches_the_reference_sequence() {
    // First outputs of splitmix64 seeded with 1234567 (Vigna's reference implementation).
    let mut r = SplitMix64::new(1234567);
    assert_eq!(r.next_u64(), 6457827717110365317);
    assert_eq!(r.next_u64(), 3203168211198807973);
    let u = SplitMix64::new(0).unit();
    assert!((0.0..1.0).contains(&u));
}
