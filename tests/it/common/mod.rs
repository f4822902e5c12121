//! Helpers shared by the integration tests: where the real corpus is, and running binaries.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

pub mod topology;

/// `../shared/data` next to the checkout, or `None` (with a printed note) when it is absent,
/// so a fresh clone without the licensed corpus still passes.
pub fn shared_data(test: &str) -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if dir.join("bvh").is_dir() {
        Some(dir)
    } else {
        skip(test, "../shared/data is absent (corpus tests need it)");
        None
    }
}

/// Say why `test` is skipped. Under `MENAGERIE_REQUIRE_ALL=1` (set by `.ci/run`) a skip is a
/// failure instead: CI must not go green with the corpus, numpy, scipy or Chromium missing.
pub fn skip(test: &str, why: &str) {
    if std::env::var_os("MENAGERIE_REQUIRE_ALL").is_some_and(|v| v == "1") {
        panic!("{test} cannot run ({why}) and MENAGERIE_REQUIRE_ALL=1 forbids skipping it");
    }
    eprintln!("SKIP {test}: {why}");
}

/// Every BVH file of the corpus, sorted.
pub fn corpus_bvh_files(data: &Path) -> Vec<PathBuf> {
    let out = corpus_bvh_files_in(&data.join("bvh"));
    assert!(!out.is_empty(), "no BVH files under {}", data.display());
    out
}

/// Every BVH file under `dir` (recursively), sorted; empty when there is none.
pub fn corpus_bvh_files_in(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh")) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The project's own synthetic creatures in examples/data.
pub fn example_bvh_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "bvh")).collect())
        .unwrap_or_default();
    out.sort();
    out
}

pub fn bin(name: &str) -> Command {
    let path = match name {
        "skel-info" => env!("CARGO_BIN_EXE_skel-info"),
        "skel-aug" => env!("CARGO_BIN_EXE_skel-aug"),
        "mo-encode" => env!("CARGO_BIN_EXE_mo-encode"),
        "mo-render" => env!("CARGO_BIN_EXE_mo-render"),
        "mo-metrics" => env!("CARGO_BIN_EXE_mo-metrics"),
        "mo-retarget" => env!("CARGO_BIN_EXE_mo-retarget"),
        "mo-train" => env!("CARGO_BIN_EXE_mo-train"),
        "mo-sample" => env!("CARGO_BIN_EXE_mo-sample"),
        "mo-dift" => env!("CARGO_BIN_EXE_mo-dift"),
        "mo-segment" => env!("CARGO_BIN_EXE_mo-segment"),
        "mo-edit" => env!("CARGO_BIN_EXE_mo-edit"),
        other => panic!("unknown binary {other}"),
    };
    let mut c = Command::new(path);
    c.stdin(Stdio::null());
    c
}

/// Run a binary with arguments and optional stdin bytes.
pub fn run(name: &str, args: &[&str], stdin: Option<&[u8]>) -> Output {
    let mut c = bin(name);
    c.args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    if stdin.is_some() {
        c.stdin(Stdio::piped());
    }
    let mut child = c.spawn().expect("spawn binary");
    if let Some(input) = stdin {
        use std::io::Write;
        let mut si = child.stdin.take().unwrap();
        let input = input.to_vec();
        std::thread::spawn(move || {
            let _ = si.write_all(&input);
        });
    }
    child.wait_with_output().expect("wait for binary")
}

/// A fresh scratch directory for one test (named after the test binary and `tag`).
pub fn tempdir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("menagerie-{}-{tag}-{}", env!("CARGO_CRATE_NAME"), std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The run succeeded (else fail with its stderr).
pub fn ok(out: &Output, what: &str) {
    assert!(out.status.success(), "{what}: exit {:?}: {}", out.status.code(), String::from_utf8_lossy(&out.stderr));
}

/// A failed run as the conventions require: exit 2, one line `tool: ...` containing
/// `expect`, nothing on stdout.
pub fn check_failure(tool: &str, what: &str, out: &Output, expect: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {err}");
    assert!(err.starts_with(&format!("{tool}: ")) && err.trim_end().lines().count() == 1, "{what}: not one line: {err}");
    assert!(err.contains(expect), "{what}: expected '{expect}' in: {err}");
    assert!(out.stdout.is_empty(), "{what}: printed on stdout");
}

/// Skeleton and motion of a BVH file.
pub fn load(path: &Path) -> (menagerie::skeleton::Skeleton, menagerie::motion::Motion) {
    let parsed = menagerie::bvh::read_path(path).unwrap_or_else(|e| panic!("{e}"));
    let skeleton = menagerie::skeleton::Skeleton::from_bvh(&parsed);
    let motion = menagerie::motion::Motion::from_bvh(&parsed, &skeleton);
    (skeleton, motion)
}

/// The skeleton document's JSON Schema, compiled.
pub fn schema_validator() -> jsonschema::Validator {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/skeleton.schema.json");
    let schema: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    jsonschema::validator_for(&schema).expect("schema compiles")
}
