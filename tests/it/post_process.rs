//! `mo-sample`'s default post-process (smoothing at `--smooth`'s default cutoff, then planted
//! feet), alone and after `--lock-feet`'s hold (`FootLock`, which works on the predicted motion
//! inside the sampler), applied to real motion instead of samples: it must keep the motion
//! (issue 22: the clips' motion energy changes by less than 10%), so that what it removes from
//! samples is jitter and sliding, not movement.
use crate::common;

use menagerie::bvh;
use menagerie::diffusion::sample::DEFAULT_SMOOTH_HZ;
use menagerie::diffusion::sample::{FootLock, PostProcess};
use menagerie::metrics::movement::energy;
use menagerie::metrics::WorldClip;
use menagerie::motion::Motion;
use menagerie::repr::anytop::{AnyTopRig, IkOptions, RigOptions};
use menagerie::repr::smooth::lambda_for_cutoff;
use menagerie::skeleton::Skeleton;
use std::path::Path;

/// The energy ratio (5-frame average, as `mo-metrics generation`) of the clip after and before
/// the post-process (`lock`: after holding the feet as `--lock-feet` does), both decoded the way
/// `mo-sample --bvh` decodes (IK).
fn ratio(path: &Path, lock: bool) -> f64 {
    let b = bvh::read_path(path).unwrap_or_else(|e| panic!("{e}"));
    let skeleton = Skeleton::from_bvh(&b);
    let motion = Motion::from_bvh_frames(&b, &skeleton, 0..b.frames);
    let rig = AnyTopRig::new(&skeleton, &motion, &RigOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let enc = rig.encode(&skeleton, &motion).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let fps = 1.0 / motion.frame_time;
    let post = PostProcess { smooth: lambda_for_cutoff(DEFAULT_SMOOTH_HZ, fps), blend: 0, plant_feet: true };
    let mut processed = enc.features.clone();
    if lock {
        let hold = FootLock::new(rig.feet.clone(), skeleton.parents(), skeleton.rest_extent() * rig.scale_factor, fps, None);
        hold.apply(&mut processed);
    }
    post.apply(&mut processed, &rig.feet, None);
    let decode = |f| {
        let m = rig.decode_ik(&skeleton, f, &enc.placement, &IkOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        energy(&WorldClip::from_motion(&skeleton, &m), 5)
    };
    decode(&processed) / decode(&enc.features)
}

fn check(files: &[std::path::PathBuf]) {
    let mut bad = Vec::new();
    for f in files {
        for lock in [false, true] {
            let r = ratio(f, lock);
            let how = if lock { "held feet and the default post-process" } else { "the default post-process" };
            eprintln!("{}: energy after / before {how}: {r:.3}", f.display());
            if !(0.9..=1.1).contains(&r) {
                bad.push(format!("{} ({how}) {r:.3}", f.display()));
            }
        }
    }
    assert!(bad.is_empty(), "the default post-process changes these clips' motion energy by 10% or more: {bad:?}");
}

#[test]
fn the_default_post_process_keeps_the_bundled_creatures_motion() {
    check(&common::example_bvh_files());
}

#[test]
fn the_default_post_process_keeps_real_motion() {
    let Some(data) = common::shared_data("the_default_post_process_keeps_real_motion") else { return };
    // One clip of each real creature issue 22 names: dog, chicken, flamingo, monkey, crab, a human.
    let bvh = data.join("bvh");
    let files: Vec<_> = [
        "truebones_anytop/Chicken/Chicken_Walk.bvh",
        "truebones_motion2motion/Flamingo/Flamingo_Walk.bvh",
        "truebones_motion2motion/Monkey/__Walk.bvh",
        "ganimator/Crab/Crab-dance-long.bvh",
        "lafan1/walk4_subject1.bvh",
    ]
    .iter()
    .map(|f| bvh.join(f))
    .chain(common::corpus_bvh_files_in(&bvh.join("dog_mann")).into_iter().take(2))
    .collect();
    for f in &files {
        assert!(f.is_file(), "{} is missing from the corpus", f.display());
    }
    check(&files);
}
