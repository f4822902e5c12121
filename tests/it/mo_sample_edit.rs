//! `mo-sample` editing (AnyTop §5) end to end with a tiny model trained for two steps:
//! in-betweening and body-part editing keep the reference's values (in physical units), the
//! generated part depends on the seed and only on it, `--report` gives seam jumps, and bad
//! ranges, unknown joints and a reference of another skeleton exit 2 without output.
use crate::common;

use common::{check_failure, ok, run, s, tempdir};
use menagerie::io::npy;
use menagerie::repr::Features;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

/// The reference's features as mo-sample encodes them (the rig of the skeleton's own BVH).
fn reference_features(path: &Path) -> Features {
    let arg = menagerie::cli::load::read_skeleton(path).unwrap();
    let section = arg.record().unwrap();
    section.rig.encode(&arg.skeleton, arg.motion.as_ref().unwrap()).unwrap().features
}

/// Samples of an NPY batch `[n, frames, joints, 13]`.
fn samples(bytes: &[u8]) -> Vec<Features> {
    let array = npy::from_bytes(bytes, "out").unwrap();
    let [n, frames, joints, dims] = array.shape[..] else { panic!("shape {:?}", array.shape) };
    let per = frames * joints * dims;
    (0..n).map(|i| Features { frames, joints, dims, data: array.data[i * per..(i + 1) * per].to_vec() }).collect()
}

fn train(dir: &Path) -> PathBuf {
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    std::fs::copy(example("quadruped.bvh"), data.join("quadruped.bvh")).unwrap();
    let model = dir.join("model");
    let args = [s(&data), "--out", s(&model), "--preset", "tiny", "--steps", "2", "--batch", "2", "--crop", "12", "-q"];
    ok(&run("mo-train", &args, None), "train");
    model
}

#[test]
fn edits_keep_the_reference_and_generate_the_rest() {
    let dir = tempdir("edit");
    let model = train(&dir);
    let quad = example("quadruped.bvh");
    let reference = reference_features(&quad);
    let j = reference.joints;
    let base = |seed: &'static str| vec![s(&quad), "--model", s(&model), "--reference", s(&quad), "-n", "2", "--frames", "20", "--steps", "4", "--seed", seed];

    // In-betweening: frames 0-4 and 15-19 are the reference's, 5-14 generated.
    let inbetween = |seed| {
        let mut a = base(seed);
        a.extend(["--keep-frames", "0-4,15-19", "--report"]);
        run("mo-sample", &a, None)
    };
    let a = inbetween("3");
    ok(&a, "in-betweening");
    assert_eq!(a.stdout, inbetween("3").stdout, "same seed, same bytes");
    let other = samples(&inbetween("4").stdout);
    let got = samples(&a.stdout);
    assert_eq!(got.len(), 2);
    for (sample, other) in got.iter().zip(&other) {
        assert_eq!((sample.frames, sample.joints), (20, j));
        assert!(sample.data.iter().all(|v| v.is_finite()));
        for f in (0..5).chain(15..20) {
            for jj in 0..j {
                for (x, y) in sample.at(f, jj).iter().zip(reference.at(f, jj)) {
                    assert!((x - y).abs() <= 1e-4, "kept frame {f} joint {jj}: {x} vs {y}");
                }
            }
        }
        let generated = |x: &Features| x.data[5 * j * 13..15 * j * 13].to_vec();
        assert_ne!(generated(sample), generated(other), "another seed, another middle");
    }
    // Held feet leave kept frames as they are too.
    let mut held = base("3");
    held.extend(["--keep-frames", "0-4,15-19", "--lock-feet"]);
    let held = run("mo-sample", &held, None);
    ok(&held, "in-betweening with held feet");
    for (sample, plain) in samples(&held.stdout).iter().zip(&got) {
        assert_eq!(sample.data[..5 * j * 13], plain.data[..5 * j * 13], "kept frames, held feet or not");
        assert_eq!(sample.data[15 * j * 13..], plain.data[15 * j * 13..], "kept frames, held feet or not");
        assert_ne!(sample.data[5 * j * 13..15 * j * 13], plain.data[5 * j * 13..15 * j * 13], "holding the feet changed the middle");
    }

    // The report: one JSON line with the two seams of each sample and the reference's spread.
    let report: serde_json::Value = serde_json::from_str(String::from_utf8_lossy(&a.stderr).trim()).unwrap();
    let seams = report["samples"][0]["seams"].as_array().unwrap();
    let frames: Vec<u64> = seams.iter().map(|s| s["frame"].as_u64().unwrap()).collect();
    assert_eq!(frames, vec![5, 15]);
    assert!(seams.iter().all(|s| s["jump"].as_f64().unwrap() >= 0.0));
    let p95 = report["reference_jumps"]["p95"].as_f64().unwrap();
    assert!(p95 > 0.0 && p95 <= report["reference_jumps"]["max"].as_f64().unwrap());

    // The default smoothing and blend: against the raw model output (--smooth 0) the same
    // samples keep the kept frames and meet them far more gently (a 2-step model's raw frames
    // are noise).
    let mut raw_args = base("3");
    raw_args.extend(["--keep-frames", "0-4,15-19", "--report", "--smooth", "0"]);
    let raw = run("mo-sample", &raw_args, None);
    ok(&raw, "raw in-betweening");
    let raw_report: serde_json::Value = serde_json::from_str(String::from_utf8_lossy(&raw.stderr).trim()).unwrap();
    let seam_sum = |r: &serde_json::Value| -> f64 {
        r["samples"].as_array().unwrap().iter().flat_map(|x| x["seams"].as_array().unwrap().iter().map(|s| s["jump"].as_f64().unwrap())).sum()
    };
    let (smoothed, unsmoothed) = (seam_sum(&report), seam_sum(&raw_report));
    assert!(smoothed < 0.5 * unsmoothed, "seam jumps: {smoothed} smoothed vs {unsmoothed} raw");
    for (sample, raw) in got.iter().zip(samples(&raw.stdout)) {
        assert_eq!(sample.data[..5 * j * 13], raw.data[..5 * j * 13], "kept frames are the same either way");
        assert_ne!(sample.data[5 * j * 13..15 * j * 13], raw.data[5 * j * 13..15 * j * 13], "the middle is smoothed");
    }

    // Body-part editing with DDIM: the legs (thighs and below) are the reference's in every frame,
    // also when the feet are held (--lock-feet moves legs, but never kept ones).
    for extra in [&[][..], &["--lock-feet"][..]] {
        let mut args = base("3");
        args.extend(["--sampler", "ddim", "--keep-joints", "*Thigh/"]);
        args.extend(extra);
        let b = run("mo-sample", &args, None);
        ok(&b, "body part");
        let legs: Vec<usize> = (0..j)
            .filter(|&jj| {
                let names = ["Bip01_L_Thigh", "Bip01_L_Calf", "Bip01_L_Foot", "Bip01_L_Toe0", "Bip01_R_Thigh", "Bip01_R_Calf", "Bip01_R_Foot", "Bip01_R_Toe0"];
                let arg = menagerie::cli::load::read_skeleton(&quad).unwrap();
                names.contains(&arg.skeleton.joints[jj].name.as_str())
            })
            .collect();
        assert_eq!(legs.len(), 8);
        for sample in samples(&b.stdout) {
            for f in 0..20 {
                for jj in 0..j {
                    let same = sample.at(f, jj).iter().zip(reference.at(f, jj)).all(|(x, y)| (x - y).abs() <= 1e-4);
                    assert_eq!(same, legs.contains(&jj), "{extra:?} frame {f} joint {jj}: kept exactly when a leg joint");
                }
            }
        }
    }

    // Without --frames the output has the reference's length; BVH output works.
    let out = dir.join("legs_{i}.bvh");
    // SKELETON defaults to the reference.
    let args = ["--model", s(&model), "--reference", s(&quad), "--steps", "2", "--keep-joints", "Bip01_Spine/", "--bvh", s(&out)];
    ok(&run("mo-sample", &args, None), "bvh");
    let (_, motion) = common::load(&dir.join("legs_{i}.bvh".replace("{i}", "0")));
    assert_eq!(motion.frames, reference.frames);
}

#[test]
fn bad_edits_exit_2_without_output() {
    let dir = tempdir("edit-bad");
    let model = train(&dir);
    let quad = example("quadruped.bvh");
    let out = dir.join("out.npy");
    let try_edit = |extra: &[&str]| {
        let mut a = vec![s(&quad), "--model", s(&model), "--steps", "2", "--frames", "20", "-o", s(&out)];
        a.extend(extra);
        run("mo-sample", &a, None)
    };
    let cases: [(&[&str], &str); 9] = [
        (&["--smooth", "1000"], "below half the frame rate"),
        (&["--smooth=-1"], "--smooth must be a cutoff in Hz"),
        (&["--blend=-0.5"], "--blend must be a duration"),
        (&["--reference", s(&quad), "--keep-frames", "0-4,18-25"], "past the last frame"),
        (&["--reference", s(&quad), "--keep-frames", "4-2"], "ends (2) before it starts (4)"),
        (&["--reference", s(&quad), "--keep-joints", "Bip01_L_Thihg"], "Bip01_L_Thigh"),
        (&["--reference", s(&quad), "--keep-joints", "*Wing*"], "no joint matches '*Wing*'"),
        (&["--reference", s(&quad)], "--keep-frames"),
        (&["--reference", s(&quad), "--keep-frames", "0-19"], "nothing is left to generate"),
    ];
    for (extra, expect) in cases {
        check_failure("mo-sample", &extra.join(" "), &try_edit(extra), expect);
        assert!(!out.exists(), "{extra:?}: wrote an output");
    }
    let crab = example("crab.bvh");
    let wrong = try_edit(&["--reference", s(&crab), "--keep-frames", "0-4"]);
    check_failure("mo-sample", "other skeleton", &wrong, "crab.bvh");
    assert!(String::from_utf8_lossy(&wrong.stderr).contains("quadruped.bvh"), "names both files");
    assert!(!out.exists());
}
