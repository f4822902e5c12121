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
        eprintln!("SKIP {test}: ../shared/data is absent (corpus tests need it)");
        None
    }
}

/// Every BVH file of the corpus, sorted.
pub fn corpus_bvh_files(data: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![data.join("bvh")];
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
    assert!(!out.is_empty(), "no BVH files under {}", data.display());
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
