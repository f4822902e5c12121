//! Tests of `metrics::generation` (kept beside it to keep the module short).

use super::*;

#[test]
fn tiling_follows_its_definition() {
    // Source 4 frames × target 5 frames; cost = |a − b| (a diagonal match at offset 1).
    let m: Vec<f64> = (0..4).flat_map(|a| (0..5).map(move |b| (a as f64 - b as f64 + 1.0).abs())).collect();
    assert_eq!(tiling_cost(&m, 5, 4, 0, 5, 2), 0.0);
    // Pieces longer than the target cannot exist.
    assert!(tiling_cost(&m, 5, 4, 0, 1, 2).is_infinite());
    // A 2-frame target forces two pieces of 2: rows 0-1 match it at cost 0 + 0, rows 2-3
    // at 1 + 1; a 3-frame piece does not fit, a 1-frame piece is too short.
    let m = [0.0, 5.0, 5.0, 0.0, 1.0, 9.0, 9.0, 1.0];
    assert_eq!(tiling_cost(&m, 2, 4, 0, 2, 2), 2.0);
    assert!(tiling_cost(&m, 2, 3, 0, 2, 2).is_infinite());
    assert_eq!(tiling_cost(&m, 2, 3, 0, 2, 1), 1.0);
}

/// A clip whose frame t is `f(t)` (a list of points).
fn clip(frames: usize, f: impl Fn(usize) -> Vec<[f64; 3]>) -> PointClip {
    let values: Vec<f64> = (0..frames).flat_map(|t| f(t).into_iter().flatten()).collect();
    let dims = values.len() / frames.max(1);
    PointClip::new(frames, dims, values).unwrap()
}

fn wave(frames: usize, phase: f64, speed: f64) -> PointClip {
    clip(frames, |t| {
        let x = t as f64 * speed + phase;
        vec![[x.sin(), 1.0, 0.0], [0.5 * x.cos(), 0.5, (2.0 * x).sin()], [0.0, 0.3 * x.sin(), 1.0]]
    })
}

/// Two points sliding along x by `v` per frame, frames `from..from + frames`, lifted by `lift`.
fn slide(from: usize, frames: usize, v: f64, lift: f64) -> PointClip {
    clip(frames, |t| {
        let x = (from + t) as f64 * v;
        vec![[x, lift, 0.0], [x, 1.0 + lift, 0.0]]
    })
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12
}

#[test]
fn identical_sets_are_fully_covered_and_at_distance_zero() {
    let set = vec![wave(60, 0.0, 0.2), wave(60, 1.0, 0.3), wave(60, 2.0, 0.15)];
    let r = generation_metrics(&set, &set, &GenerationOptions::default()).unwrap();
    assert_eq!(r.coverage, MeanStd { mean: 100.0, std: 0.0 });
    assert!(near(r.local_diversity.mean, 0.0) && near(r.global_diversity.mean, 0.0), "{r:?}");
    assert!(r.inter_diversity.mean > 0.1, "different clips are apart: {r:?}");
    assert_eq!((r.generated, r.gt, r.gt_dropped, r.coverage_subset), (3, 3, 0, 3));
    // 180 GT frames / 60 + 1 = 4 samples wanted, 3 available; and 180 < 2 × 180.
    assert_eq!(r.warnings.len(), 2, "{:?}", r.warnings);
}

#[test]
fn a_constant_pose_has_no_diversity() {
    let still = || clip(50, |_| vec![[0.1, 0.2, 0.3], [1.0, 0.0, -1.0]]);
    let r = generation_metrics(&[still(), still(), still()], &[still(), still()], &GenerationOptions::default()).unwrap();
    for (name, m) in [
        ("local", r.local_diversity),
        ("global", r.global_diversity),
        ("inter", r.inter_diversity),
        ("intra", r.intra_diversity),
        ("gt intra", r.gt_intra_diversity),
        ("diff", r.intra_diversity_diff),
    ] {
        assert_eq!(m, MeanStd::default(), "{name}");
    }
    assert_eq!(r.coverage.mean, 100.0);
}

#[test]
fn pieces_of_a_motion_shifted_in_time_score_as_predicted() {
    // GT: one 100-frame slide at 0.5 per frame, so frames a and b are |a − b| / 2 apart.
    // Generated: its frames 10..50 and 30..70, optionally lifted by 0.2 off the GT.
    let v = 0.5;
    let gt = [slide(0, 100, v, 0.0)];
    for lift in [0.0, 0.2] {
        let gen = [slide(10, 40, v, lift), slide(30, 40, v, lift)];
        let r = generation_metrics(&gen, &gt, &GenerationOptions::default()).unwrap();
        // Every generated window exists in the GT (at distance `lift`), so both
        // nearest-neighbour diversities are exactly the lift.
        assert!(near(r.local_diversity.mean, lift) && near(r.global_diversity.mean, lift), "{r:?}");
        // The samples are 20 frames apart all along: 20 · 0.5 = 10, both ways round.
        assert!(near(r.inter_diversity.mean, 10.0) && near(r.inter_diversity.std, 0.0), "{r:?}");
        // GT windows starting at 10..=55 lie inside a sample (cost `lift` < 0.349); the
        // next best diagonal is a frame off (≥ 0.5), and windows straddling the two
        // samples jump ≥ 20 frames. Starts 0..85 are counted: 46 / 85.
        assert!(near(r.coverage.mean, 46.0 / 85.0 * 100.0) && near(r.coverage.std, 0.0), "{r:?}");
        // Window pairs of a slide are a whole number of frames apart (0..=24 here).
        let steps = r.intra_diversity.mean / v * gen.len() as f64;
        assert!((steps - steps.round()).abs() < 1e-9 && r.intra_diversity.mean <= 24.0 * v, "{r:?}");
        assert!(r.gt_intra_diversity.mean > 0.0 && r.gt_intra_diversity.mean <= 84.0 * v, "{r:?}");
    }
}

#[test]
fn coverage_counts_windows_straddling_consecutive_samples() {
    // GT frames 0..100; samples 0..40 and 40..80. Drawn in that order, the concatenation is
    // frames 0..80 and covers GT starts 0..=65 (66 windows); drawn the other way round,
    // starts 26..=39 are lost at the seam (52 windows). Of the 85 GT starts.
    let gt = [slide(0, 100, 0.5, 0.0)];
    let gen = [slide(0, 40, 0.5, 0.0), slide(40, 40, 0.5, 0.0)];
    let mut mixed = false;
    for seed in 0..8 {
        let r = generation_metrics(&gen, &gt, &GenerationOptions { seed, ..Default::default() }).unwrap();
        let in_order = (0..=10).find(|&a| near(r.coverage.mean, (a * 66 + (10 - a) * 52) as f64 / 850.0 * 100.0));
        let a = in_order.unwrap_or_else(|| panic!("coverage {} is no mix of 66/85 and 52/85", r.coverage.mean));
        mixed |= a > 0 && a < 10;
    }
    assert!(mixed, "both orders should be drawn at some seed");
}

#[test]
fn same_seed_same_report_at_any_thread_count() {
    let gen: Vec<PointClip> = (0..5).map(|i| wave(40, i as f64, 0.25)).collect();
    let gt: Vec<PointClip> = (0..3).map(|i| wave(70, 0.5 + i as f64, 0.2)).collect();
    let opts = GenerationOptions::default();
    let json = || serde_json::to_string(&generation_metrics(&gen, &gt, &opts).unwrap()).unwrap();
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(json);
    let three = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap().install(json);
    assert_eq!(one, three);
    let other = generation_metrics(&gen, &gt, &GenerationOptions { seed: 11, ..opts.clone() }).unwrap();
    assert_ne!(serde_json::to_string(&other).unwrap(), one, "the seed drives the random windows");
}

#[test]
fn bad_and_tiny_inputs_are_typed_errors() {
    let opts = GenerationOptions::default();
    let gt = [wave(60, 0.0, 0.2)];
    let too_little = |r: Result<GenerationReport, MetricError>| matches!(r, Err(MetricError::TooLittle(_)));
    assert!(too_little(generation_metrics(&[], &gt, &opts)));
    assert!(too_little(generation_metrics(&[wave(1, 0.0, 0.2)], &gt, &opts)), "one frame");
    assert!(too_little(generation_metrics(&[wave(15, 0.0, 0.2)], &gt, &opts)), "window-long sample");
    assert!(too_little(generation_metrics(&[wave(60, 0.0, 0.2)], &[wave(20, 0.0, 0.2)], &opts)), "short GT only");
    assert!(too_little(generation_metrics(&[wave(60, 0.0, 0.2)], &[], &opts)));
    // 20 frames cannot be cut into pieces of 30: global diversity has no value.
    match generation_metrics(&[wave(20, 0.0, 0.2)], &gt, &opts) {
        Err(MetricError::TooLittle(m)) => assert!(m.contains("sample 0"), "{m}"),
        other => panic!("{other:?}"),
    }
    let zero_reps = GenerationOptions { reps: 0, ..opts.clone() };
    assert!(matches!(generation_metrics(&gt, &gt, &zero_reps), Err(MetricError::Mismatch(_))));
    let two_points = slide(0, 60, 0.1, 0.0);
    assert!(matches!(generation_metrics(&[two_points], &gt, &opts), Err(MetricError::Mismatch(_))));
    assert!(matches!(PointClip::new(2, 3, vec![0.0, 1.0, 2.0, 3.0, f64::NAN, 5.0]), Err(MetricError::NonFinite(m)) if m.contains("frame 1 value 1")));
    assert!(matches!(PointClip::new(1, 2, vec![0.0, 1.0]), Err(MetricError::Mismatch(_))));
    assert!(matches!(PointClip::new(2, 3, vec![0.0; 3]), Err(MetricError::Mismatch(_))));
    // A single sample is its own neighbour: inter diversity 0, everything else defined.
    let r = generation_metrics(&[wave(60, 0.0, 0.2)], &gt, &opts).unwrap();
    assert_eq!(r.inter_diversity, MeanStd::default());
    assert_eq!(r.coverage.mean, 100.0);
}

fn chain_clip(frames: usize, turn: f64) -> WorldClip {
    // Root at height 1 walking along +x; a 2-bone neck of length 1 and 2 leaning forward
    // (+x) and up; a body axis from joint 2 (front) to joint 0 (back); `turn` rotates the
    // whole clip about y.
    let q = DQuat::from_rotation_y(turn);
    let mut positions = Vec::new();
    for t in 0..frames {
        let root = DVec3::new(0.1 * t as f64, 1.0, 0.0);
        let j1 = root + DVec3::new(0.6, 0.8, 0.0);
        let j2 = j1 + DVec3::new(2.0, 0.0, 0.0);
        positions.extend([q * root, q * j1, q * j2]);
    }
    WorldClip {
        frames,
        joints: 3,
        fps: 30.0,
        positions,
        parents: vec![None, Some(0), Some(1)],
        names: vec!["root".into(), "neck".into(), "head".into()],
        feet: vec![],
        scale: 3.0,
    }
}

#[test]
fn clips_become_root_relative_points_in_anytop_units_facing_forward() {
    let s = HUMANML_MEAN_BONE_LENGTH / 1.5; // bones of 1 and 2
    let p = PointClip::from_clip(&chain_clip(2, 0.0)).unwrap();
    assert_eq!((p.frames(), p.points()), (2, 2));
    let want = [0.6 * s, 0.8 * s, 0.0, 2.6 * s, 0.8 * s, 0.0];
    for (a, b) in p.frame(1).iter().zip(want) {
        assert!((a - b).abs() < 1e-12, "{:?} vs {want:?}", p.frame(1));
    }
    // With a facing rule the features do not depend on which way the clip faces; the body
    // axis points along +x, so each frame is turned a quarter to face +z.
    let features = PointFeatures { facing: Some(Facing::BodyAxis { front: 2, back: 0 }), scale: None };
    let a = PointClip::from_clip_with(&chain_clip(3, 0.0), &features).unwrap();
    let b = PointClip::from_clip_with(&chain_clip(3, 1.1), &features).unwrap();
    for (x, y) in a.values().iter().zip(b.values()) {
        assert!((x - y).abs() < 1e-12);
    }
    assert!((a.frame(0)[5] - 2.6 * s).abs() < 1e-12 && a.frame(0)[3].abs() < 1e-12, "{:?}", a.frame(0));
    let turned = PointClip::from_clip(&chain_clip(3, 1.1)).unwrap();
    assert!(turned.values().iter().zip(a.values()).any(|(x, y)| (x - y).abs() > 0.1));
    // Bad inputs.
    let mut nan = chain_clip(2, 0.0);
    nan.positions[4].y = f64::NAN;
    assert!(matches!(PointClip::from_clip(&nan), Err(MetricError::NonFinite(m)) if m.contains("frame 1 joint 1")));
    let far = PointFeatures { facing: Some(Facing::BodyAxis { front: 7, back: 0 }), scale: None };
    assert!(matches!(PointClip::from_clip_with(&chain_clip(2, 0.0), &far), Err(MetricError::Mismatch(_))));
}

#[test]
fn anytop_features_give_heights_above_the_root() {
    let mut f = vec![0.0f32; 2 * 13];
    f[1] = 0.5;
    f[13..16].copy_from_slice(&[1.0, 2.0, 3.0]);
    let p = PointClip::from_anytop_features(1, 2, &f).unwrap();
    assert_eq!(p.frame(0), &[1.0, 1.5, 3.0]);
    assert!(matches!(PointClip::from_anytop_features(1, 2, &f[..20]), Err(MetricError::Mismatch(_))));
    assert!(matches!(PointClip::from_anytop_features(1, 1, &f[..13]), Err(MetricError::TooLittle(_))));
}

#[test]
fn aggregate_averages_skeleton_means() {
    let set = vec![wave(60, 0.0, 0.2), wave(60, 1.0, 0.3)];
    let a = generation_metrics(&set, &set, &GenerationOptions::default()).unwrap();
    let still = || clip(50, |_| vec![[0.0; 3]; 3]);
    let b = generation_metrics(&[still(), still()], &[still()], &GenerationOptions::default()).unwrap();
    let agg = aggregate(&[a.clone(), b]);
    assert_eq!(agg.skeletons, 2);
    assert!(near(agg.inter_diversity.mean, a.inter_diversity.mean / 2.0));
    assert!(near(agg.inter_diversity.std, a.inter_diversity.mean / 2.0));
    assert_eq!(agg.coverage, MeanStd { mean: 100.0, std: 0.0 });
    assert_eq!(aggregate(&[]).skeletons, 0);
}
