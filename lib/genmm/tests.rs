//! GenMM on the project's synthetic creatures (short clips so debug builds stay fast).

use super::*;
use crate::synth::creature;

fn quadruped(frames: usize) -> (Skeleton, Motion) {
    let (s, m) = creature("quadruped", 1).unwrap();
    (s, m.first_frames(frames))
}

fn finite(m: &Motion) -> bool {
    m.rotations.iter().all(|q| q.is_finite() && q.is_normalized()) && m.translations.iter().all(|t| t.is_finite())
}

fn settings(frames: usize) -> Settings {
    Settings { frames: Some(frames), ..Settings::default() }
}

#[test]
fn same_seed_same_motion_other_seed_another() {
    let (s, m) = quadruped(90);
    let a = generate(std::slice::from_ref(&m), &s, &settings(70), None, &[3, 4]).unwrap();
    let b = generate(std::slice::from_ref(&m), &s, &settings(70), None, &[3]).unwrap();
    assert_eq!(a[0].motion.rotations, b[0].motion.rotations);
    assert_eq!(a[0].motion.translations, b[0].motion.translations);
    assert_ne!(a[0].motion.rotations, a[1].motion.rotations);
    for g in &a {
        assert_eq!(g.motion.frames, 70);
        assert_eq!(g.motion.joints, s.len());
        assert!(finite(&g.motion));
        assert_eq!(g.motion.frame_time, m.frame_time);
        // The finest level's patches are example patches, closely matched.
        let last = g.report.levels.last().unwrap();
        assert_eq!(last.frames, 70);
        assert!(*last.step_costs.last().unwrap() < 0.01, "{:?}", g.report.levels);
    }
}

#[test]
fn any_length_from_shorter_than_a_patch_to_several_examples() {
    let (s, m) = quadruped(60);
    for frames in [1, 5, 11, 12, 61, 300] {
        let g = &generate(std::slice::from_ref(&m), &s, &settings(frames), None, &[1]).unwrap()[0];
        assert_eq!(g.motion.frames, frames);
        assert!(finite(&g.motion), "{frames}");
    }
    // The default length is the longest example's.
    let g = &generate(&[m.first_frames(40), m.clone()], &s, &Settings::default(), None, &[1]).unwrap()[0];
    assert_eq!(g.motion.frames, 60);
}

#[test]
fn the_arrangement_repeats_clip_frames_inside_segments() {
    let clip = Channels { frames: 40, width: 1, data: (0..40).map(|t| t as f32).collect() };
    let out = arrangement(std::slice::from_ref(&clip), &[1.0], 30, 5, 5, 9);
    // Inside a segment consecutive frames step by one clip frame; seams blend two segments.
    let steps = out.data.windows(2).filter(|w| (w[1] - w[0] - 1.0).abs() < 1e-5).count();
    assert!(steps >= 15, "{:?}", out.data);
    assert!(out.data.iter().all(|&v| (0.0..=39.0).contains(&v)));
    assert_ne!(out, arrangement(std::slice::from_ref(&clip), &[1.0], 30, 5, 5, 10));
}

#[test]
fn kept_frames_and_joints_are_the_references() {
    let (s, m) = quadruped(80);
    let reference = m.clone();
    let mut frames = vec![false; 80];
    for t in (0..10).chain(60..70) {
        frames[t] = true;
    }
    let joints = vec![false; s.len()];
    let keep = Keep { reference: &reference, frames: frames.clone(), joints };
    let g = &generate(std::slice::from_ref(&m), &s, &settings(80), Some(&keep), &[5]).unwrap()[0];
    let j = s.len();
    for t in (0..10).chain(60..70) {
        assert_eq!(g.motion.rotations[t * j..(t + 1) * j], reference.rotations[t * j..(t + 1) * j]);
        assert_eq!(g.motion.translations[t * j..(t + 1) * j], reference.translations[t * j..(t + 1) * j]);
    }
    // The root path meets the kept frames without a jump: the step into a kept frame is like
    // the steps around it.
    let step = |t: usize| (g.motion.translations[t * j] - g.motion.translations[(t - 1) * j]).length();
    let typical = (1..80).map(step).fold(0.0, f64::max);
    let clip_max = (1..80).map(|t| (reference.translations[t * j] - reference.translations[(t - 1) * j]).length()).fold(0.0, f64::max);
    assert!(typical < 3.0 * clip_max + 1e-9, "{typical} vs the clip's {clip_max}");

    // Kept joints over every frame.
    let legs: Vec<bool> = s.joints.iter().map(|x| x.name.contains("Thigh")).collect();
    assert!(legs.iter().any(|&x| x));
    let keep = Keep { reference: &reference, frames: vec![false; 80], joints: legs.clone() };
    let g = &generate(std::slice::from_ref(&m), &s, &settings(80), Some(&keep), &[5]).unwrap()[0];
    for t in 0..80 {
        for (k, _) in legs.iter().enumerate().filter(|(_, &x)| x) {
            assert_eq!(g.motion.rotations[t * j + k], reference.rotations[t * j + k]);
        }
    }
}

#[test]
fn bad_inputs_are_errors() {
    let (s, m) = quadruped(30);
    assert!(matches!(generate(&[], &s, &Settings::default(), None, &[1]), Err(GenmmError::NoExamples)));
    let (other, om) = creature("biped", 1).unwrap();
    assert!(matches!(generate(std::slice::from_ref(&om), &s, &Settings::default(), None, &[1]), Err(GenmmError::JointCount { .. })));
    let _ = other;
    let mut bad = m.clone();
    bad.rotations[5] = glam::DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0);
    assert!(matches!(generate(&[bad], &s, &Settings::default(), None, &[1]), Err(GenmmError::NonFinite { .. })));
    assert!(matches!(generate(std::slice::from_ref(&m), &s, &settings(0), None, &[1]), Err(GenmmError::ZeroFrames { .. })));
    let keep = Keep { reference: &m, frames: vec![true; 40], joints: vec![false; s.len()] };
    assert!(matches!(generate(std::slice::from_ref(&m), &s, &settings(40), Some(&keep), &[1]), Err(GenmmError::KeptFrame { frame: 30, .. })));
}

#[test]
fn a_short_lively_clip_loops_rather_than_leave_for_a_worse_fit() {
    // A short periodic "run" (30 frames) beside a long "idle": the run's own start fits its end
    // best; the idle fits too, but clearly worse. Samples that start in the run stay in it, so
    // the run fills 0.40 of all output frames (a clip is drawn uniformly to start; seams and
    // starts near the run's end take the rest). When the balance chose against the better fit,
    // it filled 0.16.
    let run = Channels { frames: 30, width: 1, data: (0..30).map(|t| (std::f32::consts::TAU * t as f32 / 8.0).sin()).collect() };
    let idle = Channels { frames: 200, width: 1, data: vec![0.0; 200] };
    let clips = [run, idle];
    let (mut lively, mut all) = (0usize, 0usize);
    for seed in 0..60 {
        let out = arrangement(&clips, &[1.0], 60, 5, 25, seed);
        lively += out.data.iter().filter(|v| v.abs() > 0.2).count();
        all += out.data.len();
    }
    // 6 of the run's 8 phases have |value| > 0.2.
    let share = lively as f64 / all as f64 / 0.75;
    assert!(share > 0.3, "the run fills {share:.2} of the output");
}
