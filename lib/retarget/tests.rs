//! Retargeting on the project's synthetic creatures (small clips so debug builds stay fast).

use super::*;
use crate::skeleton::Skeleton;
use crate::synth::creature;

fn biped(frames: usize, seed: u64) -> (Skeleton, Motion) {
    let (s, m) = creature("biped", seed).unwrap();
    let m = m.first_frames(frames);
    (s, m)
}

fn quadruped(frames: usize, seed: u64) -> (Skeleton, Motion) {
    let (s, m) = creature("quadruped", seed).unwrap();
    (s.clone(), m.first_frames(frames))
}

/// Biped legs -> quadruped hind legs.
fn leg_map(src: &Skeleton, tgt: &Skeleton) -> JointMap {
    let pairs = [
        ("mixamorig:LeftUpLeg", "Bip01_L_Thigh"),
        ("mixamorig:LeftLeg", "Bip01_L_Calf"),
        ("mixamorig:LeftFoot", "Bip01_L_Foot"),
        ("mixamorig:RightUpLeg", "Bip01_R_Thigh"),
        ("mixamorig:RightLeg", "Bip01_R_Calf"),
        ("mixamorig:RightFoot", "Bip01_R_Foot"),
    ];
    pairs.iter().map(|(s, t)| (src.index_of(s).unwrap(), tgt.index_of(t).unwrap())).collect()
}

fn angle(a: DQuat, b: DQuat) -> f64 {
    2.0 * a.dot(b).abs().min(1.0).acos()
}

fn max_position_error(a: &Motion, b: &Motion, skeleton: &Skeleton) -> f64 {
    let (pa, pb) = (a.forward_kinematics(skeleton), b.forward_kinematics(skeleton));
    pa.positions.iter().zip(&pb.positions).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max)
}

fn finite(m: &Motion) -> bool {
    m.rotations.iter().all(|q| q.is_finite() && q.is_normalized()) && m.translations.iter().all(|t| t.is_finite())
}

#[test]
fn identity_retarget_reproduces_the_source() {
    let (s, m) = biped(40, 1);
    let map: JointMap = (0..s.len()).map(|j| (j, j)).collect();
    let r = retarget(&m, &s, std::slice::from_ref(&m), &s, &map, &Settings::default()).unwrap();
    assert_eq!(r.motion.frames, 40);
    assert_eq!(r.report.bound, s.len());
    assert_eq!(r.report.bound_channels, 6 * s.len());
    let err = max_position_error(&r.motion, &m, &s);
    assert!(err < 0.02 * s.rest_height(), "max joint error {err}");
    // Every query patch found itself: the match cost of the finest level is ~0.
    assert!(r.report.levels.last().unwrap().mean_match_cost < 1e-6, "{:?}", r.report.levels);
}

#[test]
fn copied_bound_channels_follow_the_source_and_others_come_from_the_examples() {
    let (ss, sm) = biped(36, 1);
    let (ts, tm) = quadruped(30, 2);
    let map = leg_map(&ss, &ts);
    let settings = Settings { copy_bound: true, seed: 5, ..Settings::default() };
    let r = retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &settings).unwrap();
    assert_eq!((r.motion.frames, r.motion.joints), (36, ts.len()));
    assert!(finite(&r.motion));
    for f in 0..36 {
        for &(s, t) in &map {
            let a = angle(r.motion.rotations[f * ts.len() + t], sm.rotations[f * ss.len() + s]);
            assert!(a < 1e-3, "frame {f} joint {t}: {a} rad");
        }
    }
    // An unbound joint (the tail) takes rotations seen in the examples, not the rest pose.
    let tail = ts.index_of("BN_Tail_02").unwrap();
    let seen = |q: DQuat| (0..tm.frames).map(|f| angle(q, tm.rotations[f * ts.len() + tail])).fold(f64::INFINITY, f64::min);
    let worst = (0..36).map(|f| seen(r.motion.rotations[f * ts.len() + tail])).fold(0.0, f64::max);
    assert!(worst < 0.2, "tail strays {worst} rad from every example pose");
    assert!(r.report.timings.total >= r.report.timings.synthesis);
}

#[test]
fn without_copy_the_bound_legs_still_follow_the_source() {
    let (ss, sm) = biped(36, 1);
    let (ts, tm) = quadruped(30, 2);
    let map = leg_map(&ss, &ts);
    let r = retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &Settings::default()).unwrap();
    // Thigh angle over time correlates with the source's (same gait phase).
    let (s, t) = map[0];
    let track = |m: &Motion, j: usize, n: usize| -> Vec<f64> { (0..36).map(|f| angle(m.rotations[f * n + j], DQuat::IDENTITY)).collect() };
    let (a, b) = (track(&sm, s, ss.len()), track(&r.motion, t, ts.len()));
    let corr = correlation(&a, &b);
    assert!(corr > 0.3, "thigh correlation {corr}");
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma) * (x - ma)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb) * (y - mb)).sum();
    cov / (va * vb).sqrt().max(1e-12)
}

#[test]
fn a_seed_gives_the_same_bytes_on_any_thread_count() {
    let (ss, sm) = biped(30, 1);
    let (ts, tm) = quadruped(40, 2);
    let map = leg_map(&ss, &ts);
    // A low alpha: with the default 0.85 the bound channels decide nearly every match and the
    // noise barely matters, so two seeds can agree on a tiny example.
    let settings = Settings { seed: 9, alpha: 0.3, ..Settings::default() };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &settings).unwrap().motion)
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert_eq!(one, run(1));
    let other = retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &Settings { seed: 10, ..settings.clone() }).unwrap().motion;
    assert_ne!(one, other);
    // retarget_samples gives each seed's retarget result.
    let samples = retarget_samples(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &settings, &[9, 10]).unwrap();
    assert_eq!(samples[0].motion, one);
    assert_eq!(samples[1].motion, other);
    assert_eq!(samples[1].report.seed, 10);
}

#[test]
fn clips_shorter_than_a_patch_shrink_it() {
    let (ss, sm) = biped(4, 1);
    let (ts, tm) = quadruped(6, 2);
    let map = leg_map(&ss, &ts);
    let r = retarget(&sm, &ss, &[tm.clone(), tm.first_frames(2)], &ts, &map, &Settings::default()).unwrap();
    assert_eq!(r.motion.frames, 4);
    assert_eq!(r.report.patch, 4);
    assert!(r.report.notes.iter().any(|n| n.contains("patch shrunk from 11 to 4")), "{:?}", r.report.notes);
    assert!(r.report.notes.iter().any(|n| n.contains("example clip 1 (2 frames)")), "{:?}", r.report.notes);
    assert!(finite(&r.motion));
    // A one-frame source works too.
    let r = retarget(&sm.first_frames(1), &ss, &[tm], &ts, &map, &Settings::default()).unwrap();
    assert_eq!((r.motion.frames, r.report.patch), (1, 1));
    assert!(finite(&r.motion));
}

#[test]
fn a_target_much_longer_than_the_source_does_not_crash() {
    // The reference plans a coarse level below the patch size here and crashes.
    let (ss, sm) = biped(14, 1);
    let (ts, tm) = quadruped(81, 2);
    let map = leg_map(&ss, &ts);
    let r = retarget(&sm, &ss, &[tm.clone(), tm], &ts, &map, &Settings::default()).unwrap();
    assert_eq!(r.motion.frames, 14);
    assert!(r.report.levels.iter().all(|l| l.frames >= 11), "{:?}", r.report.levels);
    assert_eq!(r.report.example_clips, 2);
    assert!(r.report.levels.last().unwrap().example_patches == 2 * (81 - 10));
}

#[test]
fn any_output_length() {
    let (ss, sm) = biped(20, 1);
    let (ts, tm) = quadruped(30, 2);
    let map = leg_map(&ss, &ts);
    let r = retarget(&sm, &ss, &[tm], &ts, &map, &Settings { frames: Some(75), copy_bound: true, ..Settings::default() }).unwrap();
    assert_eq!(r.motion.frames, 75);
    assert_eq!(r.report.known_frames, 20);
    assert!(r.report.notes.iter().any(|n| n.contains("past the source's end")));
    assert!(finite(&r.motion));
    // The constrained part still copies the source.
    let (s, t) = map[1];
    assert!(angle(r.motion.rotations[10 * ts.len() + t], sm.rotations[10 * ss.len() + s]) < 1e-3);
}

#[test]
fn key_frame_mode_constrains_only_the_key_frames() {
    let (ss, sm) = biped(40, 1);
    let (ts, tm) = quadruped(40, 2);
    let map = leg_map(&ss, &ts);
    let keys = vec![0, 13, 26, 39];
    let settings = Settings { key_frames: Some(keys.clone()), copy_bound: true, ..Settings::default() };
    let r = retarget(&sm, &ss, &[tm], &ts, &map, &settings).unwrap();
    assert_eq!((r.motion.frames, r.report.known_frames), (40, 4));
    let (s, t) = map[0];
    let a = |f: usize| angle(r.motion.rotations[f * ts.len() + t], sm.rotations[f * ss.len() + s]);
    for &k in &keys {
        assert!(a(k) < 1e-3, "key frame {k}: {}", a(k));
    }
    // Between key frames the leg is synthesised, so it does not copy the source exactly.
    assert!((1..13).any(|f| a(f) > 1e-3));
    assert!(finite(&r.motion));
}

#[test]
fn every_variant_runs_and_root_motion_follows_the_source() {
    let (ss, sm) = biped(30, 1);
    let (ts, tm) = quadruped(30, 2);
    let map = leg_map(&ss, &ts);
    for repr in [Repr::Rotation, Repr::Velocity, Repr::Position] {
        for bound_rotation in [BoundRotation::Local, BoundRotation::Aligned, BoundRotation::World] {
            let settings = Settings { repr, bound_rotation, root_motion: RootMotion::Source, copy_bound: true, ..Settings::default() };
            let r = retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &settings).unwrap();
            assert!(finite(&r.motion), "{repr:?} {bound_rotation:?}");
            // The root travels as far as the source's, scaled by the size ratio.
            let travel = |m: &Motion| (m.translations[(m.frames - 1) * m.joints] - m.translations[0]).length();
            let want = travel(&sm) * r.report.size_ratio;
            assert!((travel(&r.motion) - want).abs() < 0.02 * want.max(1e-3), "{repr:?} {bound_rotation:?}: {} vs {want}", travel(&r.motion));
        }
    }
    // World: a bound joint's orientation relative to the root matches the source's.
    let settings = Settings { bound_rotation: BoundRotation::World, copy_bound: true, ..Settings::default() };
    let r = retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &settings).unwrap();
    let (ws, wt) = (sm.forward_kinematics(&ss), r.motion.forward_kinematics(&ts));
    let (s, t) = map[2];
    for f in [0, 15, 29] {
        let a = ws.rotations[f * ss.len()].inverse() * ws.rotations[f * ss.len() + s];
        let b = wt.rotations[f * ts.len()].inverse() * wt.rotations[f * ts.len() + t];
        assert!(angle(a, b) < 1e-3, "frame {f}: {}", angle(a, b));
    }
}

#[test]
fn errors_are_typed_and_clear() {
    let (ss, sm) = biped(12, 1);
    let (ts, tm) = quadruped(12, 2);
    let map = leg_map(&ss, &ts);
    let d = Settings::default();
    let err = |r: Result<Retargeted, RetargetError>| r.unwrap_err().to_string();
    assert!(err(retarget(&sm, &ss, &[], &ts, &map, &d)).contains("no example clips"));
    assert!(err(retarget(&sm, &ss, &[tm.clone(), sm.clone()], &ts, &map, &d)).contains("example clip 1 has 22 joints but the target skeleton has"));
    assert!(err(retarget(&tm, &ss, &[tm.clone()], &ts, &map, &d)).contains("the source motion has"));
    assert!(err(retarget(&sm.first_frames(0), &ss, &[tm.clone()], &ts, &map, &d)).contains("the source motion has zero frames"));
    assert!(err(retarget(&sm, &ss, &[tm.first_frames(0)], &ts, &map, &d)).contains("example clip 0 has zero frames"));
    assert!(err(retarget(&sm, &ss, &[tm.clone()], &ts, &vec![(99, 0)], &d)).contains("pair 0: source joint index 99 is out of range"));
    assert!(err(retarget(&sm, &ss, &[tm.clone()], &ts, &vec![(0, 0), (1, 999)], &d)).contains("pair 1: target joint index 999"));
    assert!(err(retarget(&sm, &ss, &[tm.clone()], &ts, &vec![(1, 3), (2, 3)], &d)).contains("pairs 0 and 1 both bind target joint 3"));
    let keys = Settings { key_frames: Some(vec![0, 12]), ..d.clone() };
    assert!(err(retarget(&sm, &ss, &[tm.clone()], &ts, &map, &keys)).contains("key frame 12 is past the end of the source (12 frames)"));
    let mut bad = sm.clone();
    bad.translations[3 * ss.len() + 2].x = f64::NAN;
    assert!(err(retarget(&bad, &ss, &[tm.clone()], &ts, &map, &d)).contains("the source motion: non-finite value at frame 3, joint 2"));
    for (settings, want) in [
        (Settings { alpha: 1.5, ..d.clone() }, "alpha = 1.5"),
        (Settings { pyramid: 1.0, ..d.clone() }, "pyramid = 1"),
        (Settings { patch: 0, ..d.clone() }, "patch = 0"),
        (Settings { steps: 0, ..d.clone() }, "steps = 0"),
        (Settings { noise_sigma: f64::NAN, ..d.clone() }, "noise_sigma = NaN"),
        (Settings { completeness: Some(0.0), ..d.clone() }, "completeness = 0"),
        (Settings { frames: Some(0), ..d.clone() }, "the requested output has zero frames"),
        (Settings { key_frames: Some(vec![]), ..d.clone() }, "at least one key frame"),
    ] {
        assert!(err(retarget(&sm, &ss, &[tm.clone()], &ts, &map, &settings)).contains(want), "{want}");
    }
    let empty = Skeleton { joints: vec![], frame_time: 0.1 };
    assert!(err(retarget(&sm, &ss, &[tm.clone()], &empty, &map, &d)).contains("the target skeleton has no joints"));
    let mut tangled = ts.clone();
    tangled.joints[1].parent = Some(5);
    assert!(err(retarget(&sm, &ss, &[tm.clone()], &tangled, &map, &d)).contains("the target skeleton: joint 1"));
    // An empty binding is allowed (unconditioned synthesis) and says so.
    let r = retarget(&sm, &ss, &[tm.clone()], &ts, &vec![], &d).unwrap();
    assert!(r.report.notes.iter().any(|n| n.contains("nothing is bound")));
}

#[test]
fn resample_keeps_duration_and_endpoints() {
    let (_, m) = biped(31, 1);
    let r = resample(&m, 60.0);
    assert_eq!(r.frames, 61);
    assert!((r.frame_time - 1.0 / 60.0).abs() < 1e-12);
    let j = m.joints;
    for k in 0..j {
        assert!(angle(r.rotations[k], m.rotations[k]) < 1e-6);
        assert!(angle(r.rotations[60 * j + k], m.rotations[30 * j + k]) < 1e-6);
        assert!(angle(r.rotations[2 * j + k], m.rotations[j + k]) < 1e-6);
        assert!(r.translations[2 * j + k].distance(m.translations[j + k]) < 1e-6);
    }
    // Halfway frames lie between their neighbours.
    let mid = r.translations[j];
    assert!(mid.distance((m.translations[0] + m.translations[j]) * 0.5) < 1e-6);
    let same = resample(&m, 1.0 / m.frame_time);
    assert_eq!(same.frames, m.frames);
    assert_eq!(resample(&m, 0.0), m);
    assert_eq!(resample(&m, 1e300), m);
    assert_eq!(resample(&m.first_frames(1), 60.0).frames, 1);
}

#[test]
fn seeds_differ_at_the_default_alpha() {
    // With alpha 0.85 the bound channels decide the matches, so the initial noise alone gives
    // (nearly) the same motion for every seed; drawing among the nearest patches must not.
    let (ss, sm) = biped(30, 1);
    let (ts, tm) = quadruped(40, 2);
    let map = leg_map(&ss, &ts);
    let run = |settings: &Settings| retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, settings).unwrap().motion;
    let d = Settings::default();
    let a = run(&Settings { seed: 1, ..d.clone() });
    assert_eq!(a, run(&Settings { seed: 1, ..d.clone() }));
    let others: Vec<Motion> = (2..5).map(|seed| run(&Settings { seed, ..d.clone() })).collect();
    assert!(others.iter().all(|o| *o != a));
    assert!(others.iter().all(|o| o.rotations.iter().all(|q| q.is_finite())));
    assert!(matches!(retarget(&sm, &ss, std::slice::from_ref(&tm), &ts, &map, &Settings { sample_choices: 0, ..d }), Err(RetargetError::Setting { .. })));
}
