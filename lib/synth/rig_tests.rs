//! Tests of the rig conventions of training variants: native below `RIG_VARIANTS`, and from
//! there on the naming styles, axes, units, roots and extra anatomy real files have, each
//! actually present, each a pure re-expression of the same motion, and every file readable.

use super::training::native_clip;
use super::*;
use crate::skeleton::names;
use crate::skeleton::roles;
use std::collections::BTreeSet;

const FRAMES: usize = 60;

fn main_action(name: &str) -> Action {
    if actions(name).contains(&Action::Walk) {
        Action::Walk
    } else {
        Action::Undulate
    }
}

fn clip(name: &str, variant: u64) -> TrainingClip {
    training_clip(name, variant, main_action(name), 4, FRAMES).unwrap()
}

fn joint_names(c: &TrainingClip) -> BTreeSet<String> {
    c.skeleton.joints.iter().map(|j| j.name.clone()).collect()
}

/// The first rig variant of `name` whose rig satisfies `want`.
fn find(name: &str, want: impl Fn(&Rig) -> bool) -> u64 {
    (RIG_VARIANTS..RIG_VARIANTS + 64).find(|&v| want(&rig(name, v).unwrap())).unwrap_or_else(|| panic!("{name}: no such rig"))
}

#[test]
fn variants_below_the_rig_variants_are_native() {
    for name in creature_names() {
        for v in 0..RIG_VARIANTS {
            assert_eq!(rig(name, v), Some(Rig::NATIVE), "{name} v{v}");
        }
        let (c, r) = native_clip(name, 3, main_action(name), 4, FRAMES).unwrap();
        assert_eq!(r, Rig::NATIVE);
        let t = training_clip(name, 3, main_action(name), 4, FRAMES).unwrap();
        assert_eq!(c.skeleton, t.skeleton, "{name}: a native rig changed the skeleton");
        assert_eq!(c.motion.translations, t.motion.translations, "{name}");
    }
    assert!(rig("unicorn", 9).is_none());
}

#[test]
fn every_human_naming_style_appears_with_its_names() {
    let expect: &[(Naming, &[&str])] = &[
        (Naming::Mixamo, &["mixamorig:Hips", "mixamorig:LeftUpLeg", "mixamorig:LeftLeg", "mixamorig:RightToeBase", "mixamorig:Spine2"]),
        (Naming::Biped, &["Bip01_Pelvis", "Bip01_L_Thigh", "Bip01_L_Calf", "Bip01_R_Foot", "Bip01_Spine1", "Bip01_L_Clavicle", "Bip01_R_UpperArm"]),
        (
            Naming::Lafan,
            &["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToe", "Spine1", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"],
        ),
        (Naming::Cmu, &["Hips", "LowerBack", "Spine", "Spine1", "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase", "LeftForeArm"]),
    ];
    for &(naming, wanted) in expect {
        let v = find("biped", |r| r.naming == naming);
        let got = joint_names(&clip("biped", v));
        if naming == Naming::Biped {
            biped_centre_carries_the_pelvis("biped", v);
        }
        for w in wanted {
            assert!(got.contains(*w), "biped v{v} {naming:?}: no {w} in {got:?}");
        }
    }
    // Mixamo and Biped hands carry fingers on some variants, named in their style.
    let v = find("biped", |r| r.naming == Naming::Mixamo && r.fingers == 5);
    let got = joint_names(&clip("biped", v));
    assert!(got.contains("mixamorig:LeftHandThumb1") && got.contains("mixamorig:RightHandPinky3"), "{got:?}");
    let v = find("biped", |r| r.naming == Naming::Biped && r.fingers == 5);
    let got = joint_names(&clip("biped", v));
    assert!(got.contains("Bip01_L_Finger0") && got.contains("Bip01_R_Finger42"), "{got:?}");
}

#[test]
fn biped_style_quadrupeds_have_horse_links_and_bn_tails() {
    for name in ["quadruped", "dragon"] {
        let v = find(name, |r| r.naming == Naming::Biped);
        let got = joint_names(&clip(name, v));
        for w in ["Bip01_L_Thigh", "Bip01_L_Calf", "Bip01_L_HorseLink", "Bip01_R_HorseLink", "Bip01_Spine1", "BN_Tail_01", "Bip01_Head"] {
            assert!(got.contains(w), "{name} v{v}: no {w} in {got:?}");
        }
        biped_centre_carries_the_pelvis(name, v);
    }
}

#[test]
fn names_are_unique_and_keep_sides_and_feet() {
    for name in creature_names() {
        for v in RIG_VARIANTS..RIG_VARIANTS + 12 {
            let (c, _) = native_clip(name, v, main_action(name), 4, FRAMES).unwrap();
            let skel = &c.skeleton;
            assert_eq!(joint_names(&c).len(), skel.len(), "{name} v{v}: duplicate names");
            // The name's side agrees with the side of the body the joint is on (rest x).
            let normalised: Vec<String> = skel.joints.iter().map(|j| names::normalise(&j.name)).collect();
            let sides = roles::sides(skel, &normalised);
            let rest = skel.rest_positions();
            let x0 = rest[0].x;
            for (j, side) in sides.iter().enumerate() {
                let x = rest[j].x - x0;
                let ok = match side {
                    names::Side::Left => x > -1e-9,
                    names::Side::Right => x < 1e-9,
                    _ => true,
                };
                assert!(ok, "{name} v{v}: {} is {side:?} at x = {x}", skel.joints[j].name);
            }
            if ["biped", "quadruped", "dragon"].contains(name) {
                let (feet, rule) = roles::feet(skel);
                assert_eq!(rule, roles::FootRule::Names, "{name} v{v}");
                let left = feet.iter().filter(|&&j| sides[j] == names::Side::Left).count();
                let right = feet.iter().filter(|&&j| sides[j] == names::Side::Right).count();
                assert!(left > 0 && left == right, "{name} v{v}: feet {left} left, {right} right");
            }
        }
    }
}

#[test]
fn axes_units_and_root_re_express_the_same_motion() {
    for name in creature_names() {
        for v in RIG_VARIANTS..RIG_VARIANTS + 10 {
            let (native, r) = native_clip(name, v, main_action(name), 4, FRAMES).unwrap();
            let c = training_clip(name, v, main_action(name), 4, FRAMES).unwrap();
            let scale = if r.centimetres { 100.0 } else { 1.0 };
            let swap = |p: DVec3| match r.up {
                UpAxis::Y => p * scale,
                UpAxis::Z => v3(p.x, -p.z, p.y) * scale,
            };
            let a = native.motion.forward_kinematics(&native.skeleton);
            let b = c.motion.forward_kinematics(&c.skeleton);
            let extent = native.skeleton.rest_extent() * scale;
            let worst = a.positions.iter().zip(&b.positions).map(|(p, q)| swap(*p).distance(*q)).fold(0.0, f64::max);
            assert!(worst < 1e-6 * extent, "{name} v{v} {r:?}: positions differ by {worst}");
            if r.root_at_origin {
                assert_eq!(c.skeleton.joints[0].offset, DVec3::ZERO, "{name} v{v}");
            } else {
                assert!(swap(native.skeleton.joints[0].offset).distance(c.skeleton.joints[0].offset) < 1e-3 * extent, "{name} v{v}");
            }
        }
    }
}

#[test]
fn z_up_centimetre_and_origin_rigs_exist_and_look_like_it() {
    // Z-up: the standing human's rest pose is tall along z and flat in y; the hips stand at z.
    let v = find("biped", |r| r.up == UpAxis::Z);
    let c = clip("biped", v);
    let (lo, hi) = c.skeleton.rest_bounds();
    let size = hi - lo;
    assert!(size.z > 2.0 * size.y, "biped v{v} Z-up: rest size {size}");
    let world = c.motion.forward_kinematics(&c.skeleton);
    assert!(world.position(0, 0).z > 0.4 * size.z, "biped v{v}: hips at {}", world.position(0, 0));
    // A Y-up human stays tall along y.
    let v = find("biped", |r| r.up == UpAxis::Y);
    let (lo, hi) = clip("biped", v).skeleton.rest_bounds();
    assert!((hi - lo).y > 2.0 * (hi - lo).z, "biped v{v} Y-up: rest size {}", hi - lo);
    // Centimetres: a human is 150-250 units tall, against 1.5-2.5 in metres.
    let tall = |c: &TrainingClip| {
        let (lo, hi) = c.skeleton.rest_bounds();
        (hi - lo).max_element()
    };
    let v = find("biped", |r| r.centimetres);
    let h = tall(&clip("biped", v));
    assert!((90.0..=300.0).contains(&h), "biped v{v} cm: height {h}");
    let v = find("biped", |r| !r.centimetres);
    let h = tall(&clip("biped", v));
    assert!((0.9..=3.0).contains(&h), "biped v{v} m: height {h}");
    // Root at the origin: OFFSET zero, the frames carry the hip height.
    for name in ["biped", "quadruped"] {
        let v = find(name, |r| r.root_at_origin && r.up == UpAxis::Y);
        let c = clip(name, v);
        assert_eq!(c.skeleton.joints[0].offset, DVec3::ZERO);
        assert!(c.motion.translations[0].y > 0.1 * tall(&c), "{name} v{v}: root at {}", c.motion.translations[0]);
    }
}

#[test]
fn jaws_and_ears_move_on_quadrupeds() {
    for name in ["quadruped", "dragon"] {
        let v = find(name, |r| r.jaw_and_ears);
        let c = clip(name, v);
        let lower: Vec<String> = c.skeleton.joints.iter().map(|j| j.name.to_lowercase()).collect();
        let jaw = lower.iter().position(|n| n.contains("jaw")).unwrap_or_else(|| panic!("{name} v{v}: no jaw"));
        // "ear" alone would match UpperArm and Forearm.
        let ears: Vec<usize> = (0..lower.len()).filter(|&j| lower[j].contains("_ear_") || lower[j].contains("-ear.")).collect();
        assert_eq!(ears.len(), 2, "{name} v{v}: ears {ears:?}");
        let head = c.skeleton.joints[jaw].parent.unwrap();
        assert!(lower[head].contains("head"), "{name} v{v}: the jaw hangs from {}", lower[head]);
        let n = c.motion.joints;
        let turns = (0..c.motion.frames).map(|f| c.motion.rotations[f * n + jaw].angle_between(c.motion.rotations[jaw])).fold(0.0, f64::max);
        assert!(turns.to_degrees() > 2.0, "{name} v{v}: the jaw moves {:.2} degrees", turns.to_degrees());
        // Variants without the extra anatomy have none.
        let without = find(name, |r| !r.jaw_and_ears);
        assert!(!joint_names(&clip(name, without)).iter().any(|n| n.to_lowercase().contains("jaw")), "{name} v{without}");
    }
}

#[test]
fn joint_counts_span_twenty_to_eighty() {
    let mut all = Vec::new();
    for name in ["biped", "quadruped", "dragon"] {
        for v in RIG_VARIANTS..RIG_VARIANTS + 24 {
            let p = proportions(name, v).unwrap();
            // Only the skeleton's size matters here; a short idle clip is cheapest.
            let n = training_clip(name, v, Action::Idle, 1, 30).unwrap().skeleton.len();
            assert!((20..=80).contains(&n), "{name} v{v}: {n} joints ({p:?})");
            all.push(n);
        }
    }
    let (lo, hi) = (all.iter().min().unwrap(), all.iter().max().unwrap());
    assert!(*lo <= 26 && *hi >= 65, "joint counts only span {lo}..{hi}");
}

#[test]
fn rig_variants_are_deterministic_and_round_trip_through_the_reader() {
    for name in creature_names() {
        for v in [RIG_VARIANTS, RIG_VARIANTS + 1, RIG_VARIANTS + 2, RIG_VARIANTS + 5] {
            let text = |seed: u64| {
                let c = training_clip(name, v, main_action(name), seed, FRAMES).unwrap();
                let mut b = c.motion.to_bvh(&c.skeleton);
                round_values(&mut b);
                (c, bvh::write_string(&b))
            };
            let (c, a) = text(5);
            assert_eq!(a, text(5).1, "{name} v{v}: not deterministic");
            let parsed = bvh::parse(&a, name).unwrap_or_else(|e| panic!("{name} v{v}: {e}"));
            let back = Skeleton::from_bvh(&parsed);
            assert_eq!(back, c.skeleton, "{name} v{v}: hierarchy changed in the round trip");
            let x = c.motion.forward_kinematics(&c.skeleton);
            let y = Motion::from_bvh(&parsed, &back).forward_kinematics(&back);
            let worst = x.positions.iter().zip(&y.positions).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
            assert!(worst < 1e-4 * c.skeleton.rest_extent(), "{name} v{v}: FK differs by {worst} after the round trip");
        }
    }
}

#[test]
fn a_pose_arms_hang_at_rest_but_move_as_t_pose_arms_do() {
    use super::legged_actions;
    use super::training::Job;
    let v = find("biped", |r| r.arm_drop_degrees > 0);
    let shape = proportions("biped", v).unwrap();
    let a_pose = rig("biped", v).unwrap();
    let t_pose = Rig { arm_drop_degrees: 0, ..a_pose };
    let make = |rig: Rig| legged_actions::biped(&Job { shape, action: Action::Walk, frames: FRAMES, rig }, &mut SplitMix64::new(9));
    let (a, t) = (make(a_pose), make(t_pose));
    // At rest the hand hangs below the shoulder by the drop angle.
    let hand = a.skeleton.index_of(&human_name(a_pose.naming, super::rig::HumanPart::Hand, Some(true))).unwrap();
    let arm = a.skeleton.joints[a.skeleton.joints[hand].parent.unwrap()].parent.unwrap();
    let rest = a.skeleton.rest_positions();
    let d = rest[hand] - rest[arm];
    let angle = (-d.y).atan2(d.x).to_degrees();
    assert!((angle - a_pose.arm_drop_degrees as f64).abs() < 0.1, "biped v{v}: the arm hangs {angle:.2} degrees, not {}", a_pose.arm_drop_degrees);
    assert!(t.skeleton.rest_positions()[hand].y > rest[hand].y + 0.05, "the T-pose hand is not higher");
    // In motion every joint is where the T-pose body puts it.
    let (fa, ft) = (a.motion.forward_kinematics(&a.skeleton), t.motion.forward_kinematics(&t.skeleton));
    let worst = fa.positions.iter().zip(&ft.positions).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
    assert!(worst < 1e-3, "biped v{v}: A-pose motion differs by {worst}");
}

/// `Bip01` is the root, `Bip01_Pelvis` its only direct child at a zero offset, and the body
/// moves exactly as the same clip without the centre node.
fn biped_centre_carries_the_pelvis(name: &str, v: u64) {
    let (c, r) = native_clip(name, v, main_action(name), 4, FRAMES).unwrap();
    assert_eq!(r.naming, Naming::Biped);
    let skel = &c.skeleton;
    assert_eq!(skel.joints[0].name, "Bip01", "{name} v{v}");
    assert_eq!(skel.joints[1].name, "Bip01_Pelvis", "{name} v{v}");
    assert_eq!((skel.joints[1].parent, skel.joints[1].offset), (Some(0), DVec3::ZERO), "{name} v{v}");
    assert_eq!(skel.children()[0], vec![1], "{name} v{v}");
    assert_eq!(skel.joints[1].channels.len(), 3, "{name} v{v}: the pelvis has rotation channels only");
    // Dropping the centre again gives the body as built: the pelvis takes its motion back.
    let world = c.motion.forward_kinematics(skel);
    let root = (0..c.motion.frames).map(|f| world.position(f, 0).distance(world.position(f, 1))).fold(0.0, f64::max);
    assert!(root < 1e-12, "{name} v{v}: the pelvis is {root} from Bip01");
}

#[test]
fn long_necks_and_tails_stay_above_the_ground_in_every_action() {
    for name in ["quadruped", "dragon"] {
        for v in RIG_VARIANTS..RIG_VARIANTS + 16 {
            for &action in actions(name) {
                let (c, _) = native_clip(name, v, action, 2, FRAMES).unwrap();
                let world = c.motion.forward_kinematics(&c.skeleton);
                let lowest = world.positions.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
                let h = c.skeleton.rest_height();
                assert!(lowest > -0.01 * h, "{name} v{v} {action:?}: a joint reaches y = {lowest:.3} (height {h:.3})");
            }
        }
    }
}
