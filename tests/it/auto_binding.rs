//! Automatic binding on pairs whose correspondence is known: CMU vs Xia (same tree, different
//! names, and a name trap: CMU's LeftShoulder is Xia's LeftArm), Mixamo Joe vs Malcolm, a
//! skeleton vs its skel-aug variants, and Flamingo -> Monkey (legs to legs, left to left).
//! The issue asks for at least 90% correct pairs.
use crate::common;

use menagerie::binding::auto::{auto_bind, AutoOptions, Body, Choice};
use menagerie::correspond::Evidence;
use menagerie::document::AnyTopSection;
use menagerie::repr::anytop::RigOptions;
use menagerie::skeleton::Skeleton;
use std::path::Path;

/// The AnyTop rig's natural rest pose: both creatures face +z.
fn rest(path: &Path) -> (Skeleton, Vec<glam::DVec3>) {
    let (skeleton, motion) = common::load(path);
    let section = AnyTopSection::new(&skeleton, &motion.first_frames(2), &RigOptions::default()).unwrap();
    let rest = section.rig.rest_positions(&skeleton);
    (skeleton, rest)
}

fn bind(a: &Path, b: &Path, opts: &AutoOptions) -> (Skeleton, Skeleton, Vec<Choice>) {
    let (sa, ra) = rest(a);
    let (sb, rb) = rest(b);
    let pairs = auto_bind(&Body { skeleton: &sa, rest: &ra }, &Body { skeleton: &sb, rest: &rb }, opts).unwrap();
    (sa, sb, pairs)
}

fn report(what: &str, sa: &Skeleton, sb: &Skeleton, pairs: &[Choice], correct: impl Fn(&Choice) -> bool) -> usize {
    let good = pairs.iter().filter(|c| correct(c)).count();
    eprintln!("{what}: {good}/{} correct", pairs.len());
    for c in pairs {
        eprintln!("  {:>28} -> {:<28} {:.3} {}", sa.joints[c.source].name, sb.joints[c.target].name, c.score, if correct(c) { "" } else { "WRONG" });
    }
    good
}

fn at_least_90_percent(what: &str, good: usize, total: usize) {
    assert!(total > 0 && good * 10 >= total * 9, "{what}: {good} of {total} pairs correct");
}

#[test]
fn known_correspondences_are_found() {
    let Some(data) = common::shared_data("known_correspondences_are_found") else { return };
    let bvh = data.join("bvh");
    for rate in [Some(0.061), Some(0.2), None] {
        let opts = AutoOptions { rate, ..AutoOptions::default() };
        // CMU and Xia: the same 31-joint tree in the same file order.
        let (sa, sb, pairs) = bind(&bvh.join("cmu_bvh11/131_01.bvh"), &bvh.join("xia_dme/neutral_01_000.bvh"), &opts);
        assert_eq!(sa.parents(), sb.parents());
        let good = report(&format!("CMU -> Xia at {rate:?}"), &sa, &sb, &pairs, |c| c.source == c.target);
        at_least_90_percent("CMU -> Xia", good, pairs.len());
        // Joe and Malcolm: Mixamo names under different namespaces; Malcolm has eyes too.
        let (sa, sb, pairs) = bind(&bvh.join("ganimator/Joe/Walk-In-Circle.bvh"), &bvh.join("ganimator/Malcolm/Gangnam-Style.bvh"), &opts);
        // Same name once the namespace is gone (normalised names drop digits: Middle1 vs Middle2).
        let bare = |n: &str| n.rsplit(':').next().unwrap_or(n).to_string();
        let good = report(&format!("Joe -> Malcolm at {rate:?}"), &sa, &sb, &pairs, |c| bare(&sa.joints[c.source].name) == bare(&sb.joints[c.target].name));
        at_least_90_percent("Joe -> Malcolm", good, pairs.len());
    }
}

#[test]
fn flamingo_legs_bind_to_monkey_legs_left_to_left() {
    let Some(data) = common::shared_data("flamingo_legs_bind_to_monkey_legs_left_to_left") else { return };
    let bvh = data.join("bvh/truebones_motion2motion");
    let (sa, sb, pairs) = bind(&bvh.join("Flamingo/Flamingo_Walk.bvh"), &bvh.join("Monkey/__Walk.bvh"), &AutoOptions::default());
    let leg = |n: &str| ["Thigh", "Calf", "HorseLink", "Foot", "Toe"].iter().any(|w| n.contains(w));
    let side = |n: &str| {
        if n.contains("_L_") {
            'L'
        } else if n.contains("_R_") {
            'R'
        } else {
            'C'
        }
    };
    let good = report("Flamingo -> Monkey", &sa, &sb, &pairs, |c| {
        let (s, t) = (&sa.joints[c.source].name, &sb.joints[c.target].name);
        // A flamingo leg joint binds to a monkey leg joint of the same side.
        !leg(s) || (leg(t) && side(s) == side(t))
    });
    assert_eq!(good, pairs.len(), "every flamingo leg joint binds to a monkey leg joint of its side");
    let legs = pairs.iter().filter(|c| leg(&sa.joints[c.source].name)).count();
    assert!(legs >= 2, "the legs are bound: {legs} leg pairs");
}

#[test]
fn skel_aug_variants_bind_back_to_their_original() {
    use menagerie::augment::{self, Options, RemoveAmount};
    use menagerie::rng::SplitMix64;
    let Some(data) = common::shared_data("skel_aug_variants_bind_back_to_their_original") else { return };
    let bvh = data.join("bvh");
    // (correct, returned) with default options, and with geometry only (names ignored).
    let mut with_names = (0, 0);
    let mut geometry = (0, 0);
    for file in ["lafan1/walk4_subject1.bvh", "dog_mann/Dog", "truebones_motion2motion/Monkey/__Walk.bvh"] {
        let path = bvh.join(file);
        let path = if path.is_dir() { common::corpus_bvh_files_in(&path).remove(0) } else { path };
        let (skeleton, motion) = common::load(&path);
        let (sa, ra) = rest(&path);
        for seed in 0..3 {
            let options = Options { remove: Some(RemoveAmount::Random), add: 2, keep_feet: true };
            let plan = augment::plan(&skeleton, &options, &mut SplitMix64::new(seed));
            let variant = plan.apply_motion(&skeleton, &motion);
            let section = AnyTopSection::new(&plan.skeleton, &variant.first_frames(2), &RigOptions::default()).unwrap();
            let rb = section.rig.rest_positions(&plan.skeleton);
            for (names, total) in [(true, &mut with_names), (false, &mut geometry)] {
                let evidence = if names { Evidence::ALL } else { Evidence::GEOMETRY };
                let opts = AutoOptions { evidence, ..AutoOptions::default() };
                let pairs = auto_bind(&Body { skeleton: &sa, rest: &ra }, &Body { skeleton: &plan.skeleton, rest: &rb }, &opts).unwrap();
                let what = format!("{file} variant {seed}{}", if names { "" } else { ", geometry only" });
                total.0 += report(&what, &sa, &plan.skeleton, &pairs, |c| sa.joints[c.source].name == plan.skeleton.joints[c.target].name);
                total.1 += pairs.len();
            }
        }
    }
    eprintln!("skel-aug variants: {}/{} correct; geometry only {}/{}", with_names.0, with_names.1, geometry.0, geometry.1);
    at_least_90_percent("skel-aug variants", with_names.0, with_names.1);
    // Without names, subdivided bones (X_mid) and shortened chains are genuinely ambiguous;
    // this guards against regressions of the geometric part.
    assert!(geometry.0 * 10 >= geometry.1 * 8, "geometry only: {}/{}", geometry.0, geometry.1);
}

#[test]
fn limb_ends_bind_to_their_own_limb_ends() {
    let Some(data) = common::shared_data("limb_ends_bind_to_their_own_limb_ends") else { return };
    let bvh = data.join("bvh");
    let has =
        |sa: &Skeleton, sb: &Skeleton, pairs: &[Choice], s: &str, t: &str| pairs.iter().any(|c| sa.joints[c.source].name == s && sb.joints[c.target].name == t);
    // Human -> dog: hands, feet and head to the joints of the same name.
    let (sa, sb, pairs) = bind(&bvh.join("lafan1/walk4_subject1.bvh"), &bvh.join("dog_mann/Dog/D1_007_KAN01_001.bvh"), &AutoOptions::default());
    report("LAFAN1 -> Dog", &sa, &sb, &pairs, |c| sa.joints[c.source].name == sb.joints[c.target].name);
    for end in ["LeftFoot", "RightFoot", "LeftHand", "RightHand", "Head"] {
        assert!(has(&sa, &sb, &pairs, end, end), "LAFAN1 -> Dog: {end} is not bound to {end}");
    }
    // CMU -> Xia: CMU's ankle is Xia's foot (the same place in one tree); toes stay unbound.
    let (sa, sb, pairs) = bind(&bvh.join("cmu_bvh11/131_01.bvh"), &bvh.join("xia_dme/neutral_01_000.bvh"), &AutoOptions::default());
    assert!(has(&sa, &sb, &pairs, "LeftAnkle", "LeftFoot") && has(&sa, &sb, &pairs, "RightAnkle", "RightFoot"), "CMU -> Xia: ankles");
    assert!(!pairs.iter().any(|c| sb.joints[c.target].name.contains("ToeBase")), "CMU -> Xia: a toe is bound");
    // Dog -> crab: the hind feet to the tips of the crab's rearmost legs, the fore feet to the
    // claws' tips.
    let (sa, sb, pairs) = bind(&bvh.join("dog_mann/Dog/D1_007_KAN01_001.bvh"), &bvh.join("ganimator/Crab/Crab-dance-long.bvh"), &AutoOptions::default());
    report("Dog -> Crab", &sa, &sb, &pairs, |_| true);
    assert!(has(&sa, &sb, &pairs, "LeftFoot", "DEF_BN_Leg_L_15_end") && has(&sa, &sb, &pairs, "RightFoot", "DEF_BN_Leg_R_15_end"), "Dog -> Crab: hind feet");
    assert!(has(&sa, &sb, &pairs, "LeftHand", "DEF_BN_Arm_L_03_end") && has(&sa, &sb, &pairs, "RightHand", "DEF_BN_Arm_R_03_end"), "Dog -> Crab: fore feet");
    // Dog -> crab: the dog's upper foreleg is not the claw's last joint (one joint out of place
    // along a three-bone limb), whatever the word "Arm" says.
    assert!(!has(&sa, &sb, &pairs, "LeftArm", "DEF_BN_Arm_L_03") && !has(&sa, &sb, &pairs, "RightArm", "DEF_BN_Arm_R_03"), "Dog -> Crab: arm out of place");
    // LAFAN1 -> Dog: the dog sits in its first frame, its knees above its hips: a human knee
    // is not bound to them.
    let (sa, sb, pairs) = bind(&bvh.join("lafan1/walk4_subject1.bvh"), &bvh.join("dog_mann/Dog/D1_007_KAN01_001.bvh"), &AutoOptions::default());
    assert!(!has(&sa, &sb, &pairs, "LeftLeg", "LeftLeg") && !has(&sa, &sb, &pairs, "RightLeg", "RightLeg"), "LAFAN1 -> Dog: knees");
    // Flamingo and Chicken -> Monkey: a bird's Foot is the base of its toes, its ankle the
    // HorseLink; a monkey's Foot is its ankle. The ankles are bound, the bird's Foot is not;
    // the chicken's one-bone wings are not bound to the monkey's arms.
    let fm = data.join("bvh/truebones_motion2motion");
    for bird in [fm.join("Flamingo/Flamingo_Walk.bvh"), bvh.join("truebones_anytop/Chicken/Chicken_Walk.bvh")] {
        let (sa, sb, pairs) = bind(&bird, &fm.join("Monkey/__Walk.bvh"), &AutoOptions::default());
        report(&format!("{} -> Monkey", bird.display()), &sa, &sb, &pairs, |_| true);
        let bare = |n: &str| n.split("__").next().unwrap_or(n).to_string();
        for side in ["L", "R"] {
            let ankle = pairs.iter().any(|c| {
                bare(&sa.joints[c.source].name) == format!("Bip01_{side}_HorseLink") && bare(&sb.joints[c.target].name) == format!("Bip01_{side}_Foot")
            });
            assert!(ankle, "{}: {side} ankles not bound", bird.display());
        }
        assert!(!pairs.iter().any(|c| sa.joints[c.source].name.contains("_Foot")), "{}: the bird's Foot is bound", bird.display());
        assert!(!pairs.iter().any(|c| sa.joints[c.source].name.contains("Finger")), "{}: a wing finger is bound", bird.display());
    }
}
