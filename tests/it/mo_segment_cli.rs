//! `mo-segment` end to end: finds the boundaries of a synthetic walk-stop-walk clip, is
//! deterministic, reads `mo-encode`'s NPY like the BVH, feeds `mo-render --frame-labels`, and
//! fails cleanly on bad input.
use crate::common;

use common::{check_failure, ok, run, s, tempdir};
use menagerie::synth::{training_clip, Action};
use std::path::{Path, PathBuf};

/// A walk-stop-walk biped written as BVH, and its true boundaries (first standing frame, first
/// frame walking again).
fn walk_stop_walk(dir: &Path) -> (PathBuf, Vec<usize>) {
    let clip = training_clip("biped", 0, Action::WalkStopWalk, 0, 200).unwrap();
    let path = dir.join("wsw.bvh");
    std::fs::write(&path, menagerie::bvh::write_string(&clip.motion.to_bvh(&clip.skeleton))).unwrap();
    let [first, last] = clip.boundaries[..] else { panic!("walk-stop-walk has two boundaries: {:?}", clip.boundaries) };
    (path, vec![first, last + 1])
}

fn labels(json: &serde_json::Value) -> Vec<usize> {
    json["labels"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).collect()
}

#[test]
fn finds_walk_stop_walk_boundaries_deterministically() {
    let dir = tempdir("wsw");
    let (bvh, truth) = walk_stop_walk(&dir);
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    let mut by_kind = Vec::new();
    for kind in ["dift", "raw"] {
        ok(&run("mo-segment", &[s(&bvh), "--seed", "3", "--features", kind, "-o", s(&a)], None), "segment");
        ok(&run("mo-segment", &[s(&bvh), "--seed", "3", "--features", kind, "-o", s(&b), "--threads", "1"], None), "segment again");
        let bytes = std::fs::read(&a).unwrap();
        assert_eq!(bytes, std::fs::read(&b).unwrap(), "{kind}: same seed, different output");
        let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        assert_eq!(json["frames"], 200);
        assert_eq!(json["features"], kind);
        let labels = labels(&json);
        assert_eq!(labels.len(), 200, "one label per BVH frame");
        assert_eq!(labels[0], 0);
        let predicted = menagerie::segment::boundaries(&labels);
        let errors = menagerie::segment::boundary_errors(&predicted, &truth);
        for (t, e) in truth.iter().zip(&errors.errors) {
            assert!(e.is_some_and(|e| e <= 6), "{kind}: boundary {t}: nearest prediction {e:?} (predicted {predicted:?})");
        }
        by_kind.push(json);
    }
    let json = by_kind.pop().unwrap();
    let labels = labels(&json);
    // Segments cover the clip in order, end exclusive, and agree with the labels.
    let segments = json["segments"].as_array().unwrap();
    let mut next = 0;
    for seg in segments {
        let (start, end, label) = (seg["start"].as_u64().unwrap() as usize, seg["end"].as_u64().unwrap() as usize, seg["label"].as_u64().unwrap() as usize);
        assert_eq!(start, next);
        assert!(end > start && labels[start..end].iter().all(|&l| l == label));
        next = end;
    }
    assert_eq!(next, 200);

    // AnyTop features piped from mo-encode give the same labels (same rig, same features).
    let npy = run("mo-encode", &[s(&bvh)], None);
    ok(&npy, "encode");
    let piped = run("mo-segment", &["--seed", "3", "--features", "raw"], Some(&npy.stdout));
    ok(&piped, "segment the NPY");
    let piped: serde_json::Value = serde_json::from_slice(&piped.stdout).unwrap();
    assert_eq!(piped["frames"], 200);
    assert_eq!(piped["labels"], json["labels"]);

    // mo-render reads it as frame labels.
    let sheet = dir.join("sheet.png");
    ok(&run("mo-render", &[s(&bvh), "--frame-labels", s(&a), "--sheet", s(&sheet), "--every", "20"], None), "render");
    assert!(std::fs::metadata(&sheet).unwrap().len() > 1000);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = tempdir("bad");
    let out = dir.join("out.json");
    let text = dir.join("notes.bvh");
    std::fs::write(&text, "hello\n").unwrap();
    check_failure("mo-segment", "not a BVH", &run("mo-segment", &[s(&text), "-o", s(&out)], None), "notes.bvh");
    // DIFT needs the skeleton an NPY of features does not carry.
    let quad = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/quadruped.bvh");
    let npy = run("mo-encode", &[s(&quad)], None);
    ok(&npy, "encode");
    check_failure("mo-segment", "NPY without skeleton", &run("mo-segment", &["-o", s(&out)], Some(&npy.stdout)), "give --skeleton");
    // Three frames give two feature frames: too few for five clusters.
    let short = dir.join("short.bvh");
    let (skeleton, motion) = menagerie::synth::creature("crab", 0).unwrap();
    std::fs::write(&short, menagerie::bvh::write_string(&motion.first_frames(3).to_bvh(&skeleton))).unwrap();
    check_failure("mo-segment", "k > frames", &run("mo-segment", &[s(&short), "--k", "5", "-o", s(&out)], None), "5 clusters need at least 5 frames");
    check_failure("mo-segment", "bad window", &run("mo-segment", &[s(&short), "--window", "-1", "-o", s(&out)], None), "--window");
    let batch = dir.join("batch.npy");
    ok(&run("mo-encode", &[s(&short), s(&short), "-o", s(&batch)], None), "encode a batch");
    check_failure("mo-segment", "a batch", &run("mo-segment", &[s(&batch), "-o", s(&out)], None), "batch of 2 samples");
    assert!(!out.exists(), "an error left an output file");
    assert!(std::fs::read_dir(&dir).unwrap().all(|e| !e.unwrap().file_name().to_string_lossy().starts_with('.')), "temp file left");
    let _ = std::fs::remove_dir_all(&dir);
}
