//! `mo-sample --examples` (GenMM, no model) end to end: the same seed gives the same bytes on
//! any thread count, other seeds other motions, any length, kept frames exact, a SKELETON or
//! reference of another skeleton and bad clips exit 2 with one line and no output, and a
//! known-answer quality check with `mo-metrics generation` on a synthetic zoo clip.
use crate::common;

use common::{check_failure, load, ok, run, s, tempdir};
use menagerie::io::npy;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

fn frames_of(bvh: &[u8]) -> usize {
    let text = String::from_utf8_lossy(bvh);
    let line = text.lines().find(|l| l.trim_start().starts_with("Frames:")).expect("a Frames line");
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

#[test]
fn same_seed_same_bytes_other_seeds_differ() {
    let dir = tempdir("seeds");
    let dragon = example("dragon.bvh");
    let gen = |seed: &str, threads: &str, tag: &str| {
        let pattern = dir.join(format!("{tag}_{{i}}.bvh"));
        let out = run("mo-sample", &["--examples", s(&dragon), "-n", "2", "--frames", "60", "--seed", seed, "--threads", threads, "--bvh", s(&pattern)], None);
        ok(&out, tag);
        (std::fs::read(dir.join(format!("{tag}_0.bvh"))).unwrap(), std::fs::read(dir.join(format!("{tag}_1.bvh"))).unwrap())
    };
    let (a0, a1) = gen("7", "2", "a");
    let (b0, b1) = gen("7", "1", "b");
    assert_eq!(a0, b0, "same seed, same bytes, whatever the threads");
    assert_eq!(a1, b1);
    assert_ne!(a0, a1, "the two samples of a run differ");
    let (c0, _) = gen("8", "2", "c");
    assert_eq!(c0, a1, "sample 1 of seed 7 is sample 0 of seed 8");
    let (d0, _) = gen("100", "2", "d");
    assert_ne!(d0, a0, "another seed, another motion");
    assert_eq!(frames_of(&a0), 60);

    // NPY: the same motion as Motion2Motion features, one batch.
    let npy_out = run("mo-sample", &["--examples", s(&dragon), "-n", "2", "--frames", "60", "--seed", "7"], None);
    ok(&npy_out, "npy");
    let array = npy::from_bytes(&npy_out.stdout, "out").unwrap();
    let (skeleton, _) = load(&dragon);
    assert_eq!(array.shape, vec![2, 60, skeleton.len(), 9]);
    assert_eq!(npy_out.stdout, run("mo-sample", &["--examples", s(&dragon), "-n", "2", "--frames", "60", "--seed", "7"], None).stdout);
}

#[test]
fn any_length_and_skeleton_from_the_examples() {
    let dir = tempdir("length");
    let crab = example("crab.bvh");
    let out = dir.join("c.bvh");
    // Shorter than a patch, longer than the clip (62 frames), and seconds at the clip's 30 fps.
    for (flag, value, frames) in [("--frames", "5", 5), ("--frames", "250", 250), ("--seconds", "2", 60)] {
        ok(&run("mo-sample", &[s(&crab), "--examples", s(&crab), flag, value, "--bvh", s(&out)], None), flag);
        let bytes = std::fs::read(&out).unwrap();
        assert_eq!(frames_of(&bytes), frames, "{flag} {value}");
        // The output is a BVH of the clip's skeleton.
        let (a, _) = load(&out);
        let (b, _) = load(&crab);
        assert_eq!(a.first_difference(&b), None);
    }
    // Default: the longest clip's length; a directory of clips works.
    let clips = dir.join("clips");
    std::fs::create_dir_all(&clips).unwrap();
    std::fs::copy(&crab, clips.join("a.bvh")).unwrap();
    ok(&run("mo-sample", &["--examples", s(&clips), "--bvh", s(&out)], None), "directory");
    assert_eq!(frames_of(&std::fs::read(&out).unwrap()), 62);
}

#[test]
fn bad_inputs_exit_2_with_one_line_and_no_output() {
    let dir = tempdir("bad");
    let (crab, biped) = (example("crab.bvh"), example("biped.bvh"));
    let out = dir.join("o.bvh");
    let o = s(&out);
    let npy_file = dir.join("f.npy");
    ok(&run("mo-sample", &["--examples", s(&crab), "--frames", "20", "-o", s(&npy_file)], None), "npy");
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let broken = dir.join("broken.bvh");
    std::fs::write(&broken, "HIERARCHY\nROOT a\n{\n").unwrap();
    let cases: Vec<(&str, Vec<&str>, &str)> = vec![
        ("SKELETON of another creature", vec![s(&biped), "--examples", s(&crab), "--bvh", o], "biped.bvh is not the skeleton of the example clips ("),
        ("--skeleton of another creature", vec!["--skeleton", s(&biped), "--examples", s(&crab), "--bvh", o], "biped.bvh is not the skeleton"),
        ("clips of two creatures", vec!["--examples", s(&crab), s(&biped), "--bvh", o], "must share one skeleton"),
        (
            "reference of another creature",
            vec!["--examples", s(&crab), "--reference", s(&biped), "--keep-frames", "0-3", "--bvh", o],
            "biped.bvh is not on the skeleton of the example clips",
        ),
        (
            "kept frame past the reference",
            vec!["--examples", s(&crab), "--reference", s(&crab), "--frames", "100", "--keep-frames", "60-70", "--bvh", o],
            "--keep-frames",
        ),
        ("NPY clip", vec!["--examples", s(&npy_file), "--bvh", o], "f.npy: mo-sample --examples reads BVH or glTF files"),
        ("directory without clips", vec!["--examples", s(&empty), "--bvh", o], "holds no .bvh"),
        ("broken BVH", vec!["--examples", s(&broken), "--bvh", o], "broken.bvh"),
        ("missing clip", vec!["--examples", "nowhere.bvh", "--bvh", o], "nowhere.bvh"),
        ("diffusion option", vec!["--examples", s(&crab), "--steps", "5", "--bvh", o], "--steps"),
        ("frames 0", vec!["--examples", s(&crab), "--frames", "0", "--bvh", o], "--frames"),
    ];
    for (what, args, expect) in cases {
        let r = run("mo-sample", &args, None);
        check_failure("mo-sample", what, &r, expect);
        assert!(!out.exists(), "{what}: wrote output");
    }
}

#[test]
fn kept_frames_and_joints_are_the_references() {
    let dir = tempdir("keep");
    let quad = example("quadruped.bvh");
    let out = dir.join("ib.bvh");
    let args = ["--examples", s(&quad), "--reference", s(&quad), "--keep-frames", "0-9,60-80", "--seed", "3", "--bvh", s(&out)];
    ok(&run("mo-sample", &args, None), "in-betweening");
    let (skeleton, got) = load(&out);
    let (_, want) = load(&quad);
    let j = skeleton.len();
    assert_eq!(got.frames, want.frames, "the reference's length by default");
    let close = |a: glam::DQuat, b: glam::DQuat| a.dot(b).abs() > 1.0 - 1e-9;
    for t in (0..10).chain(60..81) {
        for k in 0..j {
            assert!(close(got.rotations[t * j + k], want.rotations[t * j + k]), "frame {t} joint {k}");
        }
        assert!(got.translations[t * j].distance(want.translations[t * j]) < 1e-5, "frame {t} root");
    }
    // The generated frames are not the reference's.
    let moved = (15..55).any(|t| (0..j).any(|k| !close(got.rotations[t * j + k], want.rotations[t * j + k])));
    assert!(moved, "frames 10-59 are generated");

    // Body part: the thighs and below keep the reference's rotations at every frame.
    let args = ["--examples", s(&quad), "--reference", s(&quad), "--keep-joints", "*Thigh/", "--frames", "50", "--bvh", s(&out)];
    ok(&run("mo-sample", &args, None), "body part");
    let (_, got) = load(&out);
    let legs = menagerie::diffusion::edit::select_joints(&skeleton, "*Thigh/").unwrap();
    for t in 0..50 {
        for &k in &legs {
            assert!(close(got.rotations[t * j + k], want.rotations[t * j + k]), "frame {t} joint {k}");
        }
    }
}

/// Known answer: samples from one synthetic zoo clip (the bundled dragon: 88 frames of a walk in
/// place with flapping wings) move like it (energy), hold poses of it (nearest pose), cover its
/// windows, keep its footfall order and differ from each other. (A clip that repeats itself
/// exactly, like a fresh `synth::creature_bvh`, gives calibrated coverage a threshold of 0,
/// which nothing but a copy meets.)
#[test]
fn samples_of_a_zoo_walk_move_like_it() {
    let dir = tempdir("quality");
    let clip = example("dragon.bvh");
    let gen = dir.join("gen");
    std::fs::create_dir_all(&gen).unwrap();
    let pattern = gen.join("s_{i}.bvh");
    ok(&run("mo-sample", &["--examples", s(&clip), "-n", "4", "--frames", "120", "--seed", "1", "--bvh", s(&pattern)], None), "generate");
    let out = run("mo-metrics", &["generation", "--gt", s(&clip), "--gen", s(&gen)], None);
    ok(&out, "metrics");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let movement = &report["movement"]["samples"];
    let energy = movement["energy_ratio"].as_f64().unwrap();
    let nearest = movement["nearest_pose"].as_f64().unwrap();
    let coverage = movement["calibrated_coverage"].as_f64().unwrap();
    let inter = report["report"]["inter_diversity"]["mean"].as_f64().unwrap();
    eprintln!("energy ratio {energy:.3}, nearest pose {nearest:.4}, calibrated coverage {coverage:.1}%, inter diversity {inter:.4}");
    assert!((0.8..=1.2).contains(&energy), "energy ratio {energy}");
    assert!(nearest <= 0.01, "nearest pose {nearest}");
    assert!(coverage >= 90.0, "calibrated coverage {coverage}: {}", report["movement"]);
    assert!(inter > 0.0, "inter diversity {inter}");
    // Patches of the clip keep its footfall order: far nearer it than feet phased at random.
    let footfall = movement["footfall_error"].as_f64().unwrap();
    let chance = report["movement"]["footfall_chance"].as_f64().unwrap();
    assert!(footfall < chance / 4.0, "footfall error {footfall} against chance {chance}");
}
