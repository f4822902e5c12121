//! `mo-metrics` end to end, with answers known in advance: a motion against itself scores
//! perfectly in every subcommand, physics runs on every creature and every corpus file without
//! a non-finite number, and bad input exits 2 with one line.
use crate::common;

use common::{check_failure, example_bvh_files, ok, run, s, shared_data, tempdir};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

fn json(out: &std::process::Output, what: &str) -> Value {
    ok(out, what);
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{what}: not JSON: {e}"))
}

fn num(v: &Value, path: &str) -> f64 {
    let mut cur = v;
    for part in path.split('.') {
        cur = match part.parse::<usize>() {
            Ok(i) => &cur[i],
            Err(_) => &cur[part],
        };
    }
    cur.as_f64().unwrap_or_else(|| panic!("{path} is not a number in {v}"))
}

/// Every number in the report is finite (JSON cannot hold NaN, but a null in its place would
/// be a silent NaN).
fn no_nulls(v: &Value, at: &str) {
    match v {
        Value::Null => panic!("null at {at}"),
        Value::Object(m) => m.iter().for_each(|(k, x)| no_nulls(x, &format!("{at}.{k}"))),
        Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| no_nulls(x, &format!("{at}[{i}]"))),
        _ => {}
    }
}

#[test]
fn a_motion_against_itself_is_perfect() {
    let dragon = example("dragon.bvh");
    let v = json(&run("mo-metrics", &["reconstruction", "--reference", s(&dragon), "--result", s(&dragon)], None), "reconstruction");
    for key in ["jr", "rt.value", "jp.value", "gp.value", "retargeting_error"] {
        assert_eq!(num(&v, &format!("report.{key}")), 0.0, "{key} of a motion against itself");
    }
    no_nulls(&v, "reconstruction");

    let biped = example("biped.bvh");
    let v = json(&run("mo-metrics", &["transfer", "--source", s(&biped), "--result", s(&biped)], None), "transfer");
    let freq = num(&v, "results.0.frequency_alignment.value");
    assert!((freq - 1.0).abs() < 1e-9, "frequency alignment of a motion with itself: {freq}");
    let contact = num(&v, "results.0.contact_consistency.value");
    assert!((contact - 1.0).abs() < 1e-9, "contact consistency of a motion with itself: {contact}");
    let motion = num(&v, "results.0.motion_ratio.value");
    assert!((motion - 1.0).abs() < 1e-9, "motion ratio of a motion with itself: {motion}");

    let quad = example("quadruped.bvh");
    let v =
        json(&run("mo-metrics", &["generation", "--gt", s(&quad), "--gen", s(&quad), s(&quad), "--window", "10", "--min-segment", "15"], None), "generation");
    assert_eq!(num(&v, "report.coverage.mean"), 100.0, "the ground truth covers itself");
    assert!(num(&v, "report.local_diversity.mean").abs() < 1e-9, "a sample that is a ground-truth clip has zero local diversity");
    assert!(num(&v, "report.inter_diversity.mean").abs() < 1e-9, "identical samples have zero inter diversity");
}

#[test]
fn physics_scores_every_creature_with_units_and_a_table() {
    let files = example_bvh_files();
    let mut args = vec!["physics"];
    args.extend(files.iter().map(|p| s(p)));
    let v = json(&run("mo-metrics", &args, None), "physics");
    assert_eq!(v["files"].as_array().unwrap().len(), files.len());
    assert!(v["files"][0]["units"]["jitter"].is_string(), "units are named");
    no_nulls(&v, "physics");
    let table = run("mo-metrics", &["physics", s(&example("spider.bvh")), "--format", "table"], None);
    ok(&table, "table");
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.contains("jitter") && text.contains("per second"), "table rows carry units: {text}");
}

#[test]
fn physics_runs_on_the_whole_corpus() {
    let Some(data) = shared_data("physics_runs_on_the_whole_corpus") else { return };
    let dir = data.join("bvh");
    // Directories are expanded by the tool itself; one run per family keeps memory modest.
    let mut total = 0;
    for family in std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.is_dir()) {
        let files = common::corpus_bvh_files_in(&family);
        if files.is_empty() {
            continue;
        }
        let mut args = vec!["physics".to_string()];
        args.extend(files.iter().map(|p| p.display().to_string()));
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let v = json(&run("mo-metrics", &refs, None), &family.display().to_string());
        no_nulls(&v, &family.display().to_string());
        total += v["files"].as_array().unwrap().len();
    }
    assert!(total > 40, "scored {total} corpus files");
}

/// `path`'s BVH text without its last `n` frames.
fn without_last_frames(path: &Path, n: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let (head, motion) = text.split_once("MOTION").unwrap();
    let lines: Vec<&str> = motion.lines().filter(|l| !l.trim().is_empty()).collect();
    let frames: usize = lines[0].trim_start_matches("Frames:").trim().parse().unwrap();
    format!("{head}MOTION\nFrames: {}\n{}\n{}\n", frames - n, lines[1], lines[2..2 + frames - n].join("\n"))
}

#[test]
fn a_decoded_round_trip_one_frame_short_is_compared_on_its_frames() {
    // Features and latents of an F-frame clip describe F - 1 frames (the last one only gives
    // velocities), so encode -> decode hands back one frame fewer.
    let dir = tempdir("short");
    let dragon = example("dragon.bvh");
    let short = dir.join("short.bvh");
    std::fs::write(&short, without_last_frames(&dragon, 1)).unwrap();
    let v = json(&run("mo-metrics", &["reconstruction", "--reference", s(&dragon), "--result", s(&short), "-q"], None), "one frame short");
    assert_eq!(num(&v, "report.jr"), 0.0, "the frames it has are the reference's");
    assert_eq!(num(&v, "report.jp.value"), 0.0);
    std::fs::write(&short, without_last_frames(&dragon, 2)).unwrap();
    let out = run("mo-metrics", &["reconstruction", "--reference", s(&dragon), "--result", s(&short)], None);
    check_failure("mo-metrics", "two frames short", &out, "frame by frame");
}

#[test]
fn bad_input_exits_2() {
    let dir = tempdir("bad");
    let crab = example("crab.bvh");
    let bird = example("bird.bvh");
    let out = run("mo-metrics", &["reconstruction", "--reference", s(&crab), "--result", s(&bird)], None);
    check_failure("mo-metrics", "different skeletons", &out, "joints");

    // NaN in a BVH frame.
    let text = std::fs::read_to_string(&crab).unwrap();
    let motion_at = text.find("Frame Time").unwrap();
    let line_end = motion_at + text[motion_at..].find('\n').unwrap() + 1;
    let mut frame: Vec<String> = text[line_end..].lines().next().unwrap().split_whitespace().map(String::from).collect();
    frame[1] = "nan".into();
    let nan = dir.join("nan.bvh");
    std::fs::write(&nan, format!("{}{}\n{}", &text[..line_end], frame.join(" "), &text[line_end..])).unwrap();
    let out = run("mo-metrics", &["physics", s(&nan)], None);
    assert_eq!(out.status.code(), Some(2), "NaN input: {}", String::from_utf8_lossy(&out.stderr));

    let out = run("mo-metrics", &["physics", s(&crab), "--contact-height", "-1"], None);
    check_failure("mo-metrics", "negative threshold", &out, "positive");
    let out = run("mo-metrics", &["generation", "--gt", s(&crab), "--gen", s(&bird)], None);
    check_failure("mo-metrics", "generation across skeletons", &out, "same skeleton");
}

#[test]
fn aggregate_is_the_mean_and_std_over_skeletons() {
    let dir = tempdir("aggregate");
    let report = |name: &str, coverage: f64| {
        let metrics = ["coverage", "local_diversity", "global_diversity", "inter_diversity", "intra_diversity", "gt_intra_diversity", "intra_diversity_diff"];
        let mut r = serde_json::Map::new();
        for (i, m) in metrics.iter().enumerate() {
            let mean = if i == 0 { coverage } else { i as f64 };
            r.insert(m.to_string(), serde_json::json!({"mean": mean, "std": 9.0}));
        }
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, serde_json::json!({"metric": "generation", "skeleton": name, "report": r}).to_string()).unwrap();
        path
    };
    let (a, b) = (report("dog", 80.0), report("crab", 100.0));
    let v = json(&run("mo-metrics", &["aggregate", s(&a), s(&b)], None), "aggregate");
    assert_eq!(num(&v, "final.coverage.mean"), 90.0);
    assert_eq!(num(&v, "final.coverage.std"), 10.0, "population std of 80 and 100");
    assert_eq!(num(&v, "final.inter_diversity.std"), 0.0);
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{"metric": "physics"}"#).unwrap();
    check_failure("mo-metrics", "not a generation report", &run("mo-metrics", &["aggregate", s(&bad)], None), "not a report of `mo-metrics generation`");
}
