//! `mo-dift` end to end with the built-in model: features have the documented shape and the
//! same bytes for the same seed; a skeleton matched against its own `skel-aug` variant finds
//! most surviving joints; `--as-binding` writes a binding that `mo-retarget` accepts; frame
//! matching of a clip with itself is the identity, and against a time-warped copy recovers the
//! warp; bad inputs exit 2 without output.
use crate::common;

use common::{check_failure, ok, run, s, tempdir};
use menagerie::binding::Binding;
use menagerie::io::npy;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

fn json(bytes: &[u8]) -> serde_json::Value {
    serde_json::from_slice(bytes).expect("JSON output")
}

#[test]
fn features_have_one_token_per_frame_plus_the_rest_pose_and_repeat_by_seed() {
    let quad = example("quadruped.bvh");
    let a = run("mo-dift", &[s(&quad), "--draws", "2"], None);
    ok(&a, "features");
    let array = npy::from_bytes(&a.stdout, "dift").unwrap();
    let motion_frames = menagerie::bvh::read_path(&quad).unwrap().frames;
    // AnyTop features drop the last BVH frame; the rest-pose token comes first.
    assert_eq!(array.shape, vec![motion_frames, 26, 64]);
    assert!(array.data.iter().all(|v| v.is_finite()));
    assert_eq!(a.stdout, run("mo-dift", &[s(&quad), "--draws", "2"], None).stdout, "same seed, same bytes");
    assert_ne!(a.stdout, run("mo-dift", &[s(&quad), "--draws", "2", "--seed", "1"], None).stdout, "the noise depends on the seed");
}

#[test]
fn joints_of_a_skel_aug_variant_find_their_originals_and_bind() {
    let dir = tempdir("joints");
    let quad = example("quadruped.bvh");
    let variant = dir.join("variant.bvh");
    ok(&run("skel-aug", &[s(&quad), "--seed", "1", "--add", "2", "-o", s(&variant)], None), "skel-aug");
    let out = run("mo-dift", &["--joints", s(&quad), s(&variant)], None);
    ok(&out, "joints");
    let doc = json(&out.stdout);
    let matches = doc["matches"].as_array().unwrap();
    let surviving: Vec<_> = matches.iter().filter(|m| !m["target"].as_str().unwrap().ends_with("_mid")).collect();
    let right = surviving.iter().filter(|m| m["target"] == m["reference"]).count();
    assert!(right * 10 >= surviving.len() * 8, "{right} of {} surviving joints matched their originals", surviving.len());

    let binding_file = dir.join("bind.json");
    ok(&run("mo-dift", &["--joints", s(&quad), s(&variant), "--as-binding", "-o", s(&binding_file)], None), "binding");
    let text = std::fs::read_to_string(&binding_file).unwrap();
    let binding = Binding::from_json(&text, "bind.json").unwrap();
    assert!(binding.mapping.len() >= 2);
    let retargeted = dir.join("out.bvh");
    let args = [s(&quad), s(&variant), "--bind", s(&binding_file), "--seconds", "1", "-o", s(&retargeted), "-q"];
    ok(&run("mo-retarget", &args, None), "mo-retarget with the DIFT binding");
    assert!(std::fs::metadata(&retargeted).unwrap().len() > 0);
}

#[test]
fn as_binding_is_what_bind_auto_binds_and_dift_only_stays_available() {
    let dir = tempdir("engine");
    for (a, b) in [("biped.bvh", "quadruped.bvh"), ("spider.bvh", "centipede.bvh"), ("quadruped.bvh", "dragon.bvh")] {
        let (a, b) = (example(a), example(b));
        let from_dift = run("mo-dift", &["--joints", s(&a), s(&b), "--as-binding"], None);
        ok(&from_dift, "mo-dift --as-binding");
        let from_retarget = run("mo-retarget", &[s(&a), s(&b), "--bind", "auto", "--emit-binding"], None);
        ok(&from_retarget, "mo-retarget --emit-binding");
        let (x, y) = (
            Binding::from_json(&String::from_utf8_lossy(&from_dift.stdout), "d").unwrap(),
            Binding::from_json(&String::from_utf8_lossy(&from_retarget.stdout), "r").unwrap(),
        );
        assert_eq!(x.mapping, y.mapping, "{}: one engine, one answer", a.display());
        // Every pair keeps its side; more than the paper's 6.1% rate is bound.
        for p in &x.mapping {
            let side = |n: &str| {
                if n.contains("_l") || n.contains("_L") || n.contains("Left") {
                    'L'
                } else if n.contains("_r") || n.contains("_R") || n.contains("Right") {
                    'R'
                } else {
                    'C'
                }
            };
            assert!(!matches!((side(&p.source), side(&p.target)), ('L', 'R') | ('R', 'L')), "{} -> {}", p.source, p.target);
        }
        assert!(x.mapping.len() >= 4, "{} pairs", x.mapping.len());
        let limited = run("mo-retarget", &[s(&a), s(&b), "--bind", "auto", "--bind-rate", "0.061", "--emit-binding"], None);
        let limited = Binding::from_json(&String::from_utf8_lossy(&limited.stdout), "l").unwrap();
        assert!(limited.mapping.len() <= x.mapping.len() && limited.mapping[..] == x.mapping[..limited.mapping.len()]);
    }
    // The spider's legs keep their numbers: leg 3 goes to leg 3 of a copy.
    let spider = example("spider.bvh");
    let out = run("mo-dift", &["--joints", s(&spider), s(&spider)], None);
    ok(&out, "spider joints");
    let doc = json(&out.stdout);
    let rows = doc["matches"].as_array().unwrap();
    assert!(rows.iter().all(|m| m["target"] == m["reference"] && m["one_to_one"] == true));
    let dift = run("mo-dift", &["--joints", s(&spider), s(&spider), "--features", "dift-only", "--draws", "1", "-o", s(&dir.join("d.json"))], None);
    ok(&dift, "dift-only");
}

#[test]
fn frames_of_a_clip_against_itself_match_one_to_one() {
    let quad = example("quadruped.bvh");
    let out = run("mo-dift", &["--frames", s(&quad), s(&quad), "--draws", "2"], None);
    ok(&out, "frames");
    let doc = json(&out.stdout);
    let matches = doc["matches"].as_array().unwrap();
    assert!(!matches.is_empty());
    let exact = matches.iter().filter(|m| m["target"] == m["reference"]).count();
    assert_eq!(exact, matches.len(), "identical clips, identical noise: every frame is its own best match");
}

#[test]
fn frames_recover_a_time_warp_in_order_where_frame_by_frame_cannot() {
    use menagerie::{bvh, motion::Motion, skeleton::Skeleton};
    let quad = example("quadruped.bvh");
    let parsed = bvh::read_path(&quad).unwrap();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    let (warped, truth) = menagerie::dift::eval::time_warp(&motion, 0.5);
    let dir = tempdir("warp");
    let warped_path = dir.join("warped.bvh");
    std::fs::write(&warped_path, bvh::write_string(&warped.to_bvh(&skeleton))).unwrap();
    let mean_error = |align: &str| -> (f64, bool) {
        let out = run("mo-dift", &["--frames", s(&quad), s(&warped_path), "--align", align], None);
        ok(&out, align);
        let doc = json(&out.stdout);
        assert_eq!(doc["settings"]["align"], align);
        assert_eq!(doc["settings"]["descriptors"], "joints side by side");
        let refs: Vec<f64> = doc["matches"].as_array().unwrap().iter().map(|m| m["reference"].as_f64().unwrap()).collect();
        assert_eq!(refs.len(), motion.frames - 1, "a match per feature frame");
        let error = refs.iter().zip(&truth).map(|(r, x)| (r - x).abs()).sum::<f64>() / refs.len() as f64;
        eprintln!("{align}: {error:.2} frames off");
        (error, refs.windows(2).all(|w| w[1] >= w[0]))
    };
    let (in_order, monotone) = mean_error("monotonic");
    let (nearest, _) = mean_error("nearest");
    assert!(monotone, "monotonic answers never go back");
    // The quadruped walks: frame by frame a pose matches other cycles (BENCHMARKS.md: 7.6
    // frames off on the synthetic gaits); in order, within a frame.
    assert!(in_order < 1.0 && in_order < nearest, "in order {in_order:.2} frames off, frame by frame {nearest:.2}");
}

#[test]
fn bad_inputs_exit_2_without_output() {
    let dir = tempdir("bad");
    let quad = example("quadruped.bvh");
    let out = dir.join("out.json");
    let one = run("mo-dift", &["--joints", s(&quad), "-o", s(&out)], None);
    check_failure("mo-dift", "one input", &one, "REF and TGT");
    let broken = dir.join("broken.bvh");
    std::fs::write(&broken, "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0\n").unwrap();
    let bad = run("mo-dift", &["--frames", s(&quad), s(&broken), "-o", s(&out)], None);
    check_failure("mo-dift", "broken BVH", &bad, "broken.bvh");
    let t = run("mo-dift", &[s(&quad), "--t", "100", "-o", s(&out)], None);
    check_failure("mo-dift", "step past T", &t, "diffusion step 100");
    assert!(!out.exists(), "no partial output");
}
