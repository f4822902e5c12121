//! Motion metrics (physics, kinetic and geometric features, reconstruction, transfer) on real
//! files: our synthetic creatures for known answers, the shared corpus for "runs everywhere".
use crate::common;

use glam::{DQuat, DVec3};
use menagerie::bvh;
use menagerie::metrics::geometric::{self, GeometricOptions};
use menagerie::metrics::physics::{self, Maybe, PhysicsOptions};
use menagerie::metrics::reconstruction::{self, Rotations};
use menagerie::metrics::{kinetic, transfer, MetricError, WorldClip};
use menagerie::motion::Motion;
use menagerie::skeleton::Skeleton;
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

fn load(path: &Path) -> (Skeleton, Motion, WorldClip) {
    let parsed = bvh::read_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    let clip = WorldClip::from_motion(&skeleton, &motion);
    (skeleton, motion, clip)
}

fn example(name: &str) -> (Skeleton, Motion, WorldClip) {
    load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name))
}

/// Frames `start..start + len` of a clip.
fn window(clip: &WorldClip, start: usize, len: usize) -> WorldClip {
    let j = clip.joints;
    WorldClip { frames: len, positions: clip.positions[start * j..(start + len) * j].to_vec(), ..clip.clone() }
}

fn map_positions(clip: &WorldClip, f: impl Fn(DVec3) -> DVec3) -> WorldClip {
    WorldClip { positions: clip.positions.iter().map(|&p| f(p)).collect(), ..clip.clone() }
}

#[test]
fn a_motion_against_itself_identical_shifted_mirrored_scaled() {
    let (skeleton, motion, clip) = example("biped.bvh");
    assert!(clip.frames > 20 && !clip.feet.is_empty());
    let opts = PhysicsOptions::default();
    let height = skeleton.rest_height();
    let counted = reconstruction::rotation_joints(&skeleton);
    // Every joint of the biped has rotation channels and a child or an End Site.
    assert_eq!(counted.len(), skeleton.len());

    // Identical: every error is exactly zero.
    let rot = Rotations { reference: &motion.rotations, result: &motion.rotations, counted: counted.clone() };
    let same = reconstruction::reconstruction(&clip, &clip, Some(&rot), height, &opts).unwrap();
    assert_eq!(same.jr, Maybe::Value(0.0));
    assert_eq!((same.rt.value, same.jp.value, same.retargeting_error), (0.0, 0.0, 0.0));

    // Shifted by k frames: predicted from the positions directly.
    let k = 3;
    let n = clip.frames - k;
    let (a, b) = (window(&clip, 0, n), window(&clip, k, n));
    let root_error: f64 = (0..n).map(|f| clip.at(f, 0).distance(clip.at(f + k, 0))).sum::<f64>() / n as f64;
    let joint_errors: Vec<f64> = (0..n).flat_map(|f| (0..clip.joints).map(move |j| (f, j))).map(|(f, j)| clip.at(f, j).distance(clip.at(f + k, j))).collect();
    let jp = joint_errors.iter().sum::<f64>() / joint_errors.len() as f64;
    let mse = joint_errors.iter().map(|d| d * d).sum::<f64>() / joint_errors.len() as f64;
    let shifted = reconstruction::reconstruction(&a, &b, None, height, &opts).unwrap();
    assert!(root_error > 0.0 && jp > 0.0, "the example must move");
    assert!((shifted.rt.value - root_error).abs() < 1e-12 && (shifted.jp.value - jp).abs() < 1e-12);
    assert!((shifted.retargeting_error - 1000.0 * mse / (height * height)).abs() < 1e-9);
    assert!((shifted.jp.normalised - jp / height).abs() < 1e-12);

    // Mirrored in x: every joint is 2|x| away from its mirror image.
    let mirrored = map_positions(&clip, |p| DVec3::new(-p.x, p.y, p.z));
    let by_hand = clip.positions.iter().map(|p| 2.0 * p.x.abs()).sum::<f64>() / clip.positions.len() as f64;
    let r = reconstruction::reconstruction(&clip, &mirrored, None, height, &opts).unwrap();
    assert!((r.jp.value - by_hand).abs() < 1e-12, "{} vs {by_hand}", r.jp.value);
    // Mirroring keeps the physics of a y-up motion: same skating, penetration, jitter.
    let (p0, p1) = (physics::physics(&clip, &opts).unwrap(), physics::physics(&mirrored, &opts).unwrap());
    assert_eq!(p0.ground_penetration, p1.ground_penetration);
    let jitter = |p: &physics::PhysicsReport| *p.jitter.value().unwrap();
    assert!((jitter(&p0).value - jitter(&p1).value).abs() < 1e-9 * jitter(&p0).value.max(1.0));

    // Scaled by s about the origin: joints move (s - 1)|p|; kinetic energies scale by s²,
    // energy expenditure by s; normalised physics (with the scale scaled too) is unchanged.
    let s = 2.5;
    let scaled = WorldClip { scale: clip.scale * s, ..map_positions(&clip, |p| p * s) };
    let by_hand = clip.positions.iter().map(|p| (s - 1.0) * p.length()).sum::<f64>() / clip.positions.len() as f64;
    let r = reconstruction::reconstruction(&clip, &scaled, None, height, &opts).unwrap();
    assert!((r.jp.value - by_hand).abs() < 1e-12);
    let (k0, k1) = (kinetic::kinetic_features(&clip).unwrap(), kinetic::kinetic_features(&scaled).unwrap());
    for (i, (x, y)) in k0.iter().zip(&k1).enumerate() {
        let factor = if i % 3 == 2 { s } else { s * s };
        assert!((y - factor * x).abs() <= 1e-9 * y.abs().max(1.0), "kinetic dim {i}: {x} -> {y}");
    }
    let p2 = physics::physics(&scaled, &opts).unwrap();
    assert!((jitter(&p2).normalised - jitter(&p0).normalised).abs() < 1e-9 * jitter(&p0).normalised.max(1.0));
    // The geometric features are scale-free with measured body lengths.
    let roles = geometric::human_roles(&clip).unwrap();
    let (g0, g1) = (
        geometric::geometric_features(&clip, &roles, &GeometricOptions::default()).unwrap(),
        geometric::geometric_features(&scaled, &roles, &GeometricOptions::default()).unwrap(),
    );
    assert_eq!(g0, g1);
}

#[test]
fn a_constant_pose_has_no_jitter_energy_or_diversity() {
    let (_, _, clip) = example("quadruped.bvh");
    let frozen = WorldClip { positions: (0..clip.frames).flat_map(|_| clip.frame(0).to_vec()).collect(), ..clip.clone() };
    let p = physics::physics(&frozen, &PhysicsOptions::default()).unwrap();
    assert_eq!(p.jitter.value().unwrap().value, 0.0);
    assert_eq!(p.foot_skating.value().unwrap().value, 0.0);
    assert!(kinetic::kinetic_features(&frozen).unwrap().iter().all(|&x| x == 0.0));
    assert_eq!(transfer::diversity(&[frozen.clone(), frozen.clone(), frozen]).unwrap().value, 0.0);
    // A moving clip against itself: diversity 0 as well; against a shifted copy: positive.
    assert_eq!(transfer::diversity(&[clip.clone(), clip.clone()]).unwrap().value, 0.0);
    let moved = map_positions(&clip, |p| p + DVec3::new(0.0, 0.0, 0.25));
    assert!((transfer::diversity(&[clip, moved]).unwrap().value - 0.25).abs() < 1e-12);
}

#[test]
fn a_creature_lifted_or_sunk_floats_or_penetrates_by_the_amount() {
    let (_, _, clip) = example("quadruped.bvh");
    let opts = PhysicsOptions::default();
    let base = physics::physics(&clip, &opts).unwrap();
    let lowest_foot: Vec<f64> = (0..clip.frames).map(|f| clip.feet.iter().map(|&j| clip.at(f, j).y).fold(f64::INFINITY, f64::min)).collect();
    let lowest: Vec<f64> = (0..clip.frames).map(|f| clip.frame(f).iter().map(|p| p.y).fold(f64::INFINITY, f64::min)).collect();
    // Lift by a full size: floating = mean(lowest foot + lift - band), nothing penetrates.
    let lift = clip.scale;
    let up = physics::physics(&map_positions(&clip, |p| p + DVec3::Y * lift), &opts).unwrap();
    let band = opts.contact_height * clip.scale;
    let want = lowest_foot.iter().map(|y| (y + lift - band).max(0.0)).sum::<f64>() / clip.frames as f64;
    assert!((up.floating.value().unwrap().value - want).abs() < 1e-9, "{:?} vs {want}", up.floating);
    assert_eq!(up.floating_fraction, Maybe::Value(1.0));
    assert_eq!(up.ground_penetration.value, 0.0);
    // Sink by a full size: penetration = mean(sink - lowest joint), no floating.
    let down = physics::physics(&map_positions(&clip, |p| p - DVec3::Y * lift), &opts).unwrap();
    let want = lowest.iter().map(|y| (lift - y).max(0.0)).sum::<f64>() / clip.frames as f64;
    assert!((down.ground_penetration.value - want).abs() < 1e-9);
    assert_eq!(down.floating.value().unwrap().value, 0.0);
    // Skating and jitter do not care about the height, only about horizontal motion.
    let (j0, j1) = (base.jitter.value().unwrap().value, down.jitter.value().unwrap().value);
    assert!((j0 - j1).abs() < 1e-9 * j0.max(1.0));
    // The estimated ground follows the lifted motion back to the original result.
    let est = PhysicsOptions { ground: physics::Ground::Estimate, ..opts };
    let (e0, e1) = (physics::physics(&clip, &est).unwrap(), physics::physics(&map_positions(&clip, |p| p + DVec3::Y * lift), &est).unwrap());
    assert!((e1.ground - e0.ground - lift).abs() < 1e-9);
    assert!((e1.floating.value().unwrap().value - e0.floating.value().unwrap().value).abs() < 1e-9);
}

#[test]
fn a_foot_dragged_along_the_ground_skates_at_the_drag_speed() {
    let (_, _, clip) = example("biped.bvh");
    // Flatten every foot onto the ground and drag it along x at a known speed.
    let speed = 0.4 * clip.scale;
    let mut dragged = clip.clone();
    for f in 0..clip.frames {
        for &j in &clip.feet {
            dragged.positions[f * clip.joints + j] = DVec3::new(speed * f as f64 / clip.fps, 0.0, 1.0);
        }
    }
    let p = physics::physics(&dragged, &PhysicsOptions::default()).unwrap();
    let s = p.foot_skating.value().unwrap();
    assert!((s.value - speed).abs() < 1e-9 && (s.normalised - 0.4).abs() < 1e-9, "{s:?}");
    // 0.4 sizes/s is below the 0.5 contact speed: every foot-frame is a contact.
    assert_eq!(p.contact_fraction, Maybe::Value(1.0));
    assert_eq!(p.skating_fraction, Maybe::Value(0.0));
}

#[test]
fn transfer_metrics_on_a_creature_and_itself() {
    let (_, _, clip) = example("quadruped.bvh");
    let pairs: Vec<(usize, usize)> = clip.feet.iter().map(|&f| (f, f)).collect();
    let fa = transfer::frequency_alignment(&clip, &clip, &pairs).unwrap();
    assert!(fa.per_pair.iter().all(|&x| (x - 1.0).abs() < 1e-9), "{fa:?}");
    let cc = transfer::contact_consistency(&clip, &clip, &pairs, &PhysicsOptions::default()).unwrap();
    assert_eq!(cc.value().unwrap().value, 1.0);
    let (_, _, fish) = example("fish.bvh");
    assert!(fish.feet.is_empty());
    let na = transfer::contact_consistency(&clip, &fish, &[(1, 1)], &PhysicsOptions::default()).unwrap();
    assert!(matches!(na, Maybe::NotApplicable(_)));
    let p = physics::physics(&fish, &PhysicsOptions::default()).unwrap();
    assert!(matches!(p.floating, Maybe::NotApplicable(_)));
}

#[test]
fn one_frame_and_nan_inputs_are_errors_everywhere() {
    let (_, motion, clip) = example("biped.bvh");
    let one = window(&clip, 0, 1);
    let opts = PhysicsOptions::default();
    let roles = geometric::human_roles(&clip).unwrap();
    let mut nan = clip.clone();
    nan.positions[7].y = f64::NAN;
    for bad in [&one, &nan] {
        assert!(kinetic::kinetic_features(bad).is_err());
        assert!(geometric::geometric_features(bad, &roles, &GeometricOptions::default()).is_err());
        assert!(transfer::frequency_alignment(bad, &clip, &[(0, 0)]).is_err());
        assert!(transfer::contact_consistency(bad, &clip, &[(1, 1)], &opts).is_err());
    }
    for f in [physics::physics(&nan, &opts).map(|_| ()), reconstruction::reconstruction(&nan, &clip, None, 1.0, &opts).map(|_| ())] {
        assert!(matches!(f, Err(MetricError::NonFinite(_))));
    }
    // A single pose (a rest-pose file) is scored where that means something, and says why not
    // elsewhere, rather than failing the whole report.
    let p = physics::physics(&one, &opts).unwrap();
    assert!(matches!(p.foot_skating, Maybe::NotApplicable(_)) && matches!(p.jitter, Maybe::NotApplicable(_)));
    let r = reconstruction::reconstruction(&one, &one, None, 1.0, &opts).unwrap();
    assert!(r.jp.value == 0.0 && matches!(r.fs, Maybe::NotApplicable(_)));
    // One frame is a valid sample for diversity (a pose set); NaN is not.
    assert!(matches!(transfer::diversity(&[nan.clone(), clip.clone()]), Err(MetricError::NonFinite(_))));
    assert!(matches!(kinetic::kinetic_features(&one), Err(MetricError::TooLittle(_))));
    assert!(matches!(kinetic::kinetic_features(&nan), Err(MetricError::NonFinite(_))));
    // A NaN rotation is refused too.
    let mut rotations = motion.rotations.clone();
    rotations[3] = DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0);
    let rot = Rotations { reference: &motion.rotations, result: &rotations, counted: vec![0] };
    assert!(matches!(reconstruction::reconstruction(&clip, &clip, Some(&rot), 1.0, &opts), Err(MetricError::NonFinite(_))));
}

/// Frames of each corpus file the kinetic and geometric features look at.
const FEATURE_FRAMES: usize = 300;

/// Physics (and the features) on every corpus file: no error, nothing non-finite. Prints the
/// wall time of the physics pass (loading excluded) and which files have human roles.
#[test]
fn physics_on_every_corpus_file() {
    let Some(data) = common::shared_data("physics_on_every_corpus_file") else { return };
    let files = common::corpus_bvh_files(&data);
    let t0 = Instant::now();
    let clips: Vec<(String, WorldClip)> = files.par_iter().map(|p| (p.strip_prefix(&data).unwrap_or(p).display().to_string(), load(p).2)).collect();
    let loading = t0.elapsed();
    let frames: usize = clips.iter().map(|(_, c)| c.frames).sum();
    let t1 = Instant::now();
    let reports: Vec<_> = clips.par_iter().map(|(name, c)| (name, physics::physics(c, &PhysicsOptions::default()))).collect();
    let physics_time = t1.elapsed();
    for (name, r) in &reports {
        let r = r.as_ref().unwrap_or_else(|e| panic!("{name}: {e}"));
        let json = serde_json::to_string(r).unwrap();
        assert!(!json.contains("null") && !json.contains("NaN"), "{name}: {json}");
        let values = [r.ground_penetration.value, r.penetration_fraction, r.ground];
        assert!(values.iter().all(|v| v.is_finite()), "{name}: {r:?}");
    }
    let t2 = Instant::now();
    let human: Vec<_> = clips
        .par_iter()
        .map(|(name, c)| {
            if c.frames < 3 {
                // Rest-pose files: too short for an acceleration, and said so.
                assert!(matches!(kinetic::kinetic_features(c), Err(MetricError::TooLittle(_))), "{name}");
                return None;
            }
            let k = kinetic::kinetic_features(&window(c, 0, c.frames.min(FEATURE_FRAMES))).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(k.iter().all(|x| x.is_finite()), "{name}");
            let roles = match geometric::human_roles(c) {
                Ok(r) => r,
                Err(why) => {
                    eprintln!("no human roles in {name}: {why}");
                    return None;
                }
            };
            // The features on a prefix: they are per-frame averages, and the full corpus in an
            // unoptimised test build would take seconds.
            let c = &window(c, 0, c.frames.min(FEATURE_FRAMES));
            let g = geometric::geometric_features(c, &roles, &GeometricOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(g.iter().all(|x| (0.0..=1.0).contains(x)), "{name}");
            Some(name.clone())
        })
        .collect();
    let features_time = t2.elapsed();
    let with_roles = human.iter().flatten().count();
    eprintln!(
        "{} files, {frames} frames: loading+FK {:.2} s, physics {:.3} s, kinetic+geometric on {FEATURE_FRAMES}-frame prefixes {:.2} s ({} threads); human roles in {with_roles} files",
        files.len(),
        loading.as_secs_f64(),
        physics_time.as_secs_f64(),
        features_time.as_secs_f64(),
        rayon::current_num_threads()
    );
    // The corpus has human mocap (lafan1, cmu, xia ...): roles must be found in those.
    assert!(with_roles * 3 >= files.len(), "human roles found in only {with_roles} of {} files", files.len());
}

/// Frequency alignment and contact consistency of a long corpus clip against itself shifted
/// by half a second: timing printed, values in range.
#[test]
fn transfer_metrics_on_a_long_corpus_clip() {
    let Some(data) = common::shared_data("transfer_metrics_on_a_long_corpus_clip") else { return };
    let files = common::corpus_bvh_files(&data);
    let Some(path) = files.iter().find(|p| p.to_string_lossy().contains("lafan1/walk")) else { return };
    let (_, _, clip) = load(path);
    let n = clip.frames.min(1000);
    let k = (clip.fps * 0.5).round() as usize;
    if clip.frames < n + k {
        return;
    }
    let (a, b) = (window(&clip, 0, n), window(&clip, k, n));
    let pairs: Vec<(usize, usize)> = clip.feet.iter().map(|&f| (f, f)).collect();
    let t = Instant::now();
    let fa = transfer::frequency_alignment(&a, &b, &pairs).unwrap();
    let fa_time = t.elapsed();
    let cc = transfer::contact_consistency(&a, &b, &pairs, &PhysicsOptions::default()).unwrap();
    eprintln!(
        "{n} frames, {} foot pairs: frequency alignment {:.3} in {:.3} s ({} bins); contact consistency {:.3}",
        pairs.len(),
        fa.value,
        fa_time.as_secs_f64(),
        fa.bins,
        cc.value().map_or(f64::NAN, |c| c.value)
    );
    // The same walk half a second later has the same rhythm; its contacts are out of phase.
    assert!(fa.value > 0.8 && fa.value <= 1.0, "{fa:?}");
    assert!(cc.value().is_some_and(|c| (0.0..=1.0).contains(&c.value)));
}
