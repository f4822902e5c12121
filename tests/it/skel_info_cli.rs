//! `skel-info` end to end: documents for every corpus and example file pass the JSON Schema,
//! carry the right joint counts and give back the exact BVH hierarchy; stdin, several files,
//! text output, broken pipes and atomic output behave as docs/ARCHITECTURE.md promises.
use crate::common;

use common::{schema_validator, tempdir};

use menagerie::bvh;
use menagerie::document::SkeletonDocument;
use std::path::Path;

/// Check one BVH through the binary: schema, joint count, hierarchy round trip.
fn check_document(path: &Path, validator: &jsonschema::Validator) {
    let name = path.display().to_string();
    let out = common::run("skel-info", &[&name], None);
    assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let errors: Vec<String> = validator.iter_errors(&value).map(|e| format!("{} at {}", e, e.instance_path)).collect();
    assert!(errors.is_empty(), "{name}: schema errors: {errors:?}");

    let text = std::fs::read(path).unwrap();
    let entries = String::from_utf8_lossy(&text).lines().filter(|l| matches!(l.split_whitespace().next(), Some("ROOT") | Some("JOINT"))).count();
    let doc = SkeletonDocument::from_json(std::str::from_utf8(&out.stdout).unwrap()).unwrap();
    assert_eq!(doc.joint_count, entries, "{name}");
    assert_eq!(doc.joints.len(), entries, "{name}");
    let n = entries;
    assert!(doc.topology.relations.len() == n && doc.topology.relations.iter().all(|r| r.len() == n), "{name}: R shape");

    // The document alone writes the same hierarchy as the original file.
    let mut original = bvh::parse_bytes(&text, &name).unwrap();
    original.frames = 0;
    original.values.clear();
    let from_doc = doc.skeleton().unwrap().to_bvh_hierarchy();
    assert_eq!(bvh::write_string(&from_doc), bvh::write_string(&original), "{name}: hierarchy from document differs");
}

#[test]
fn corpus_documents_pass_the_schema_and_round_trip_the_hierarchy() {
    let Some(data) = common::shared_data("corpus_documents_pass_the_schema_and_round_trip_the_hierarchy") else { return };
    let validator = schema_validator();
    for path in common::corpus_bvh_files(&data) {
        check_document(&path, &validator);
    }
}

#[test]
fn example_documents_pass_the_schema() {
    let validator = schema_validator();
    let files = common::example_bvh_files();
    assert!(files.len() >= 7, "examples/data should hold the synthetic zoo (run `cargo run --example zoo`)");
    for path in files {
        check_document(&path, &validator);
    }
}

/// A small skeleton written here, so these tests need no external data.
const TINY: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 1 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\tJOINT LeftUpLeg\n\t{\n\t\tOFFSET 0.1 -0.1 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tJOINT LeftFoot\n\t\t{\n\t\t\tOFFSET 0 -0.8 0\n\t\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 0 -0.1 0.1\n\t\t\t}\n\t\t}\n\t}\n\tJOINT RightUpLeg\n\t{\n\t\tOFFSET -0.1 -0.1 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tJOINT RightFoot\n\t\t{\n\t\t\tOFFSET 0 -0.8 0\n\t\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 0 -0.1 0.1\n\t\t\t}\n\t\t}\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n0 1 0 0 0 0 10 0 0 -10 0 0 0 0 0 0 0 0\n0 1 0.1 0 0 0 20 0 0 -20 0 0 0 0 0 0 0 0\n";

#[test]
fn stdin_and_several_files_give_one_document_each() {
    let dir = tempdir("several");
    let a = dir.join("a.bvh");
    std::fs::write(&a, TINY).unwrap();
    let out = common::run("skel-info", &["-", a.to_str().unwrap()], Some(TINY.as_bytes()));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let docs: Vec<SkeletonDocument> = text.lines().map(|l| SkeletonDocument::from_json(l).unwrap()).collect();
    assert_eq!(docs.len(), 2);
    assert_eq!(docs[0].source, "<stdin>");
    assert_eq!(docs[0].joints, docs[1].joints);
    let d = &docs[0];
    assert_eq!(d.joints[1].normalised, "Left Up Leg");
    assert_eq!(d.topology.feet, vec![2, 4]);
    assert_eq!(d.topology.end_effectors, vec![2, 4]);
    assert_eq!(d.motion.as_ref().unwrap().frames, 2);
}

#[test]
fn text_format_shows_tree_sides_and_summary() {
    let out = common::run("skel-info", &["-", "--format", "text"], Some(TINY.as_bytes()));
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("└─RightUpLeg"), "{text}");
    assert!(text.contains("Left Foot") && text.contains(" L ") && text.contains(" R "), "{text}");
    assert!(text.contains("joints: 5") && text.contains("feet (Names): LeftFoot, RightFoot"), "{text}");
    assert!(text.contains("2 frames at 30.000 fps"), "{text}");
}

#[test]
fn output_file_is_written_only_on_success() {
    let dir = tempdir("atomic");
    let good = dir.join("good.bvh");
    std::fs::write(&good, TINY).unwrap();
    let bad = dir.join("bad.bvh");
    std::fs::write(&bad, &TINY[..TINY.len() - 20]).unwrap();
    let target = dir.join("out.json");
    let out = common::run("skel-info", &[good.to_str().unwrap(), bad.to_str().unwrap(), "-o", target.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(!target.exists(), "a failed run must not leave an output file");
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 2, "temp files left behind: {leftovers:?}");
    let out = common::run("skel-info", &[good.to_str().unwrap(), "-o", target.to_str().unwrap()], None);
    assert!(out.status.success() && out.stdout.is_empty());
    SkeletonDocument::from_json(&std::fs::read_to_string(&target).unwrap()).unwrap();
}

#[test]
fn closed_stdout_pipe_is_success() {
    use std::process::Stdio;
    // Many copies of the document so the pipe fills and closes while we still write.
    let dir = tempdir("pipe");
    let a = dir.join("a.bvh");
    std::fs::write(&a, TINY).unwrap();
    let args: Vec<String> = std::iter::repeat_n(a.to_str().unwrap().to_string(), 400).collect();
    let mut child = common::bin("skel-info").args(&args).arg("--pretty").stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 10];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty(), "broken pipe must be quiet: {}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn usage_errors_exit_2() {
    let out = common::run("skel-info", &[], None);
    assert_eq!(out.status.code(), Some(2));
    let out = common::run("skel-info", &["--dmax", "0", "x.bvh"], None);
    assert_eq!(out.status.code(), Some(2));
    let out = common::run("skel-info", &["-", "-"], Some(TINY.as_bytes()));
    assert_eq!(out.status.code(), Some(2));
    let out = common::run("skel-info", &["/nonexistent/file.bvh"], None);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("skel-info: ") && err.contains("/nonexistent/file.bvh") && err.trim_end().lines().count() == 1, "{err}");
}
