//! Hostile input, odd outputs and huge numbers (issue 25): every tool keeps the contract of
//! README's Conventions. A failing case exits 2 with one line `tool: ...` that says what was
//! wrong, prints nothing on stdout, panics never, and leaves no output and no temporary file.
//! What `-o` names survives: a device stays a device (written in place), a symlink stays a
//! link (its target is written). Outputs of one run are written all or none.
//!
//! Device nodes are private ones made with mknod in a scratch directory (root only; skipped
//! with a printed reason otherwise). Nothing here ever names anything in /dev.
use crate::common;

use common::{run, s, tempdir};
use std::path::{Path, PathBuf};
use std::process::Output;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

/// One run that must fail as the conventions say.
struct Case {
    name: String,
    tool: &'static str,
    args: Vec<String>,
    stdin: Option<Vec<u8>>,
    /// Words the message must contain.
    expect: Vec<String>,
    /// Paths that must not exist afterwards.
    absent: Vec<PathBuf>,
}

fn case(name: &str, tool: &'static str, args: &[&str], expect: &[&str]) -> Case {
    Case {
        name: name.to_string(),
        tool,
        args: args.iter().map(|a| a.to_string()).collect(),
        stdin: None,
        expect: expect.iter().map(|e| e.to_string()).collect(),
        absent: Vec::new(),
    }
}

impl Case {
    fn absent(mut self, paths: &[&Path]) -> Case {
        self.absent.extend(paths.iter().map(|p| p.to_path_buf()));
        self
    }
    fn stdin(mut self, bytes: &[u8]) -> Case {
        self.stdin = Some(bytes.to_vec());
        self
    }
}

/// What is wrong with a run that should have failed cleanly (None when nothing).
fn judge(c: &Case, out: &Output) -> Option<String> {
    let err = String::from_utf8_lossy(&out.stderr);
    let mut wrong = Vec::new();
    if out.status.code() != Some(2) {
        wrong.push(format!("exit {:?}", out.status.code()));
    }
    if !(err.starts_with(&format!("{}: ", c.tool)) && err.trim_end().lines().count() == 1) {
        wrong.push("not one line".to_string());
    }
    if err.contains("panicked") {
        wrong.push("panic".to_string());
    }
    for e in &c.expect {
        if !err.contains(e.as_str()) {
            wrong.push(format!("no '{e}'"));
        }
    }
    if !out.stdout.is_empty() {
        wrong.push(format!("{} bytes on stdout", out.stdout.len()));
    }
    for p in &c.absent {
        if p.exists() {
            wrong.push(format!("{} was written", p.display()));
        }
        if let Some(dir) = p.parent() {
            if let Ok(rd) = std::fs::read_dir(dir) {
                let temps: Vec<String> =
                    rd.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.contains(".tmp")).collect();
                if !temps.is_empty() {
                    wrong.push(format!("temporary files left: {temps:?}"));
                }
            }
        }
    }
    if wrong.is_empty() {
        None
    } else {
        Some(format!("{} ({} {:?}): {}: {}", c.name, c.tool, c.args, wrong.join(", "), err.trim_end()))
    }
}

fn check_all(cases: Vec<Case>) {
    let mut failures = Vec::new();
    for c in &cases {
        let args: Vec<&str> = c.args.iter().map(String::as_str).collect();
        let out = run(c.tool, &args, c.stdin.as_deref());
        if let Some(f) = judge(c, &out) {
            failures.push(f);
        }
    }
    assert!(failures.is_empty(), "{} of {} cases failed:\n{}", failures.len(), cases.len(), failures.join("\n"));
}

const TOOLS: [&str; 11] =
    ["skel-info", "skel-aug", "mo-encode", "mo-retarget", "mo-metrics", "mo-render", "mo-train", "mo-sample", "mo-dift", "mo-segment", "mo-edit"];

#[test]
fn usage_errors_are_one_line() {
    let biped = example("biped.bvh");
    let b = s(&biped);
    let mut cases = Vec::new();
    for tool in TOOLS {
        let input: &[&str] = match tool {
            "mo-metrics" => &["physics", b],
            "mo-edit" => &["convert", b],
            _ => &[b],
        };
        cases.push(case("unknown flag", tool, &["--no-such-flag"], &["--no-such-flag", "(see --help)"]));
        cases.push(case("--threads 0", tool, &[input, &["--threads", "0"]].concat(), &["--threads", "(see --help)"]));
        cases.push(case("--threads huge", tool, &[input, &["--threads", "100000"]].concat(), &["--threads", "(see --help)"]));
    }
    cases.push(case("no input", "skel-info", &[], &["required", "(see --help)"]));
    cases.push(case("no --out", "mo-train", &[b], &["--out", "(see --help)"]));
    cases.push(case("no subcommand", "mo-metrics", &[], &["(see --help)"]));
    cases.push(case("bad enum", "skel-info", &[b, "--format", "xml"], &["xml", "(see --help)"]));
    check_all(cases);

    // --help and --version still print as clap prints them.
    let help = run("skel-info", &["--help"], None);
    assert_eq!(help.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&help.stdout).lines().count() > 10);
    let version = run("mo-sample", &["--version"], None);
    assert_eq!(version.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&version.stdout).starts_with("mo-sample "));
}

#[test]
fn huge_numbers_are_refused() {
    let dir = tempdir("huge");
    let biped = example("biped.bvh");
    let quad = example("quadruped.bvh");
    let (b, q) = (s(&biped), s(&quad));
    let out = dir.join("out.bvh");
    let o = s(&out);
    let cases = vec![
        case("add u64::MAX", "skel-aug", &[b, "--add", "18446744073709551615", "-o", o], &["--add", "256"]),
        case("add a million", "skel-aug", &[b, "--add", "1000000", "-o", o], &["--add"]),
        case("variants huge", "skel-aug", &[b, "-n", "1000000000", "-o", o], &["--variants"]),
        case("frames 1e9", "mo-retarget", &[b, q, "--bind", "auto", "--frames", "1000000000", "-o", o], &["--frames"]),
        case("seconds 1e12", "mo-retarget", &[b, q, "--bind", "auto", "--seconds", "1e12", "-o", o], &["--seconds"]),
        case("seconds NaN", "mo-retarget", &[b, q, "--bind", "auto", "--seconds", "NaN", "-o", o], &["--seconds"]),
        case("steps 1e6", "mo-retarget", &[b, q, "--bind", "auto", "--steps", "1000000", "-o", o], &["--steps"]),
        case("patch huge", "mo-retarget", &[b, q, "--bind", "auto", "--patch", "99999999999", "-o", o], &["--patch"]),
        case("bind-rate 5", "mo-retarget", &[b, q, "--bind", "auto", "--bind-rate", "5", "-o", o], &["--bind-rate"]),
        case("seconds 1e12", "mo-sample", &[b, "--seconds", "1e12", "-o", o], &["--seconds"]),
        case("seconds past the frame limit", "mo-sample", &[b, "--seconds", "3600", "-o", o], &["--seconds", "10000"]),
        case("checkpoint NaN", "mo-train", &[b, "--out", o, "--checkpoint-minutes", "NaN"], &["--checkpoint-minutes"]),
        case("checkpoint inf", "mo-train", &[b, "--out", o, "--checkpoint-minutes", "inf"], &["--checkpoint-minutes"]),
        case("lr NaN", "mo-train", &[b, "--out", o, "--lr", "NaN"], &["--lr"]),
        case("steps u64::MAX", "mo-train", &[b, "--out", o, "--steps", "18446744073709551615"], &["--steps"]),
        case("pca dims huge", "mo-segment", &[b, "--pca-dims", "1000000000", "-o", o], &["--pca-dims"]),
        case("t huge", "mo-dift", &[b, "--t", "99999999999", "-o", o], &["--t"]),
        case("window huge", "mo-metrics", &["generation", "--gt", b, "--gen", b, "--window", "99999999999"], &["--window"]),
    ]
    .into_iter()
    .map(|c| c.absent(&[&out]))
    .collect();
    check_all(cases);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The malformed table's two-joint file with `value` as the root's Xposition in frame 0.
fn bvh_with_root_x(value: &str) -> String {
    format!(
        "HIERARCHY\nROOT Hips\n{{\n\tOFFSET 0 1 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\tJOINT Spine\n\t{{\n\t\tOFFSET 0 0.2 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{{\n\t\t\tOFFSET 0 0.3 0\n\t\t}}\n\t}}\n}}\nMOTION\nFrames: 3\nFrame Time: 0.0333333\n{value} 1 0 0 0 0 1 2 3\n0 1 0.1 0 0 0 4 5 6\n0 1 0.2 0 0 0 7 8 9\n"
    )
}

/// skel-info's document of `bvh`, as a JSON value.
fn document(bvh: &Path) -> serde_json::Value {
    let out = run("skel-info", &[s(bvh)], None);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn invalid_inputs_are_refused() {
    let dir = tempdir("invalid");
    let biped = example("biped.bvh");
    let b = s(&biped);
    let out = dir.join("out.npy");
    let o = s(&out);
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };

    let huge = write("huge.bvh", bvh_with_root_x("1e300").as_bytes());
    // A bundled quadruped with its first frame's root at x = 1e300: its bones cannot be
    // measured from that rest pose (the message used to blame a damaged rig).
    let quadruped = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/quadruped.bvh")).unwrap();
    let (head, frames) = quadruped.split_once("Frame Time:").unwrap();
    let (time, rows) = frames.split_once('\n').unwrap();
    let (first, rest) = rows.split_once('\n').unwrap();
    let first = std::iter::once("1e300").chain(first.split_whitespace().skip(1)).collect::<Vec<_>>().join(" ");
    let huge_rig = write("huge_rig.bvh", format!("{head}Frame Time:{time}\n{first}\n{rest}").as_bytes());
    let good = write("good.bvh", bvh_with_root_x("0").as_bytes());
    let no_frames = bvh_with_root_x("0");
    let no_frames = no_frames[..no_frames.find("Frames: 3").unwrap()].to_string() + "Frames: 0\nFrame Time: 0.0333333\n";
    let empty = write("empty.bvh", no_frames.as_bytes());

    // Skeleton documents broken in one place each.
    let doc = document(&biped);
    let edited = |name: &str, f: &dyn Fn(&mut serde_json::Value)| {
        let mut d = doc.clone();
        f(&mut d);
        write(name, serde_json::to_string(&d).unwrap().as_bytes())
    };
    let wrong_count = edited("count.json", &|d| d["joint_count"] = serde_json::json!(3));
    let dup_channels = edited("dup.json", &|d| d["joints"][1]["channels"] = serde_json::json!(vec!["Xrotation"; 9]));
    let short_row = edited("row.json", &|d| {
        let row = d["anytop"]["rest_row"].as_array_mut().unwrap();
        row.truncate(row.len() - 1);
    });
    let bad_parent = edited("parent.json", &|d| d["joints"][5]["parent"] = serde_json::json!(999));
    let syntax = write("syntax.json", b"{\n  \"format\": \"menagerie.skeleton\",\n  \"version\": 1,,\n}\n");

    // Features: [0, J, 13] and placements too large to pose.
    let joints = doc["joint_count"].as_u64().unwrap() as usize;
    let mut zero = Vec::new();
    menagerie::io::npy::write_f32(&mut zero, &[0, joints, 13], &[]).unwrap();
    let zero = write("zero.npy", &zero);
    let encoded = dir.join("biped.npy");
    assert!(run("mo-encode", &[b, "-o", s(&encoded)], None).status.success());
    let placement = write("placement.json", b"[{\"heading\": 1e308, \"root_xz\": [1.7e308, -1.7e308]}]");
    let placement_syntax = write("placement-syntax.json", b"[\n  {\"heading\": 0,, }\n]\n");
    let bvh_out = dir.join("decoded.bvh");

    // A model whose schedule has no steps.
    let model = dir.join("model");
    std::fs::create_dir_all(&model).unwrap();
    let zoo = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/zoo-compact");
    std::fs::copy(zoo.join("model.safetensors"), model.join("model.safetensors")).unwrap();
    let mut info: serde_json::Value = serde_json::from_slice(&std::fs::read(zoo.join("checkpoint.json")).unwrap()).unwrap();
    info["schedule_steps"] = serde_json::json!(0);
    std::fs::write(model.join("checkpoint.json"), serde_json::to_string(&info).unwrap()).unwrap();

    let far_labels = write("labels.json", br#"{"segments": [{"start": 0, "end": 1000000000, "label": "walk"}]}"#);
    let sheet = dir.join("sheet.png");

    let cases = vec![
        case("1e300 in a BVH", "mo-encode", &[s(&huge), "-q", "-o", o], &["huge.bvh", "too large"]).absent(&[&out]),
        case("1e300 as a rest-frame position of a real rig", "mo-encode", &[s(&huge_rig), "-q", "-o", o], &["huge_rig.bvh", "joint 0", "too large"])
            .absent(&[&out]),
        case("1e300 in a BVH, m2m", "mo-encode", &[s(&huge), "-q", "--repr", "m2m", "-o", o], &["huge.bvh", "too large"]).absent(&[&out]),
        case("placement too large", "mo-encode", &[s(&encoded), "--decode", "--skeleton", b, "--placement", s(&placement), "-o", s(&bvh_out)], &["non-finite"])
            .absent(&[&bvh_out]),
        case("joint_count", "mo-encode", &[s(&encoded), "--decode", "--skeleton", s(&wrong_count), "-o", s(&bvh_out)], &["count.json", "joint_count"])
            .absent(&[&bvh_out]),
        case("9 Xrotation channels", "mo-encode", &[s(&encoded), "--decode", "--skeleton", s(&dup_channels), "-o", s(&bvh_out)], &["dup.json", "twice"])
            .absent(&[&bvh_out]),
        case("truncated rest_row", "mo-encode", &[s(&encoded), "--decode", "--skeleton", s(&short_row), "-o", s(&bvh_out)], &["row.json", "rest_row"])
            .absent(&[&bvh_out]),
        case("truncated rest_row", "mo-sample", &[s(&short_row), "--frames", "4", "--steps", "1", "-o", o], &["row.json", "rest_row"]).absent(&[&out]),
        case("[0, J, 13]", "mo-encode", &[s(&zero), "--decode", "--skeleton", b, "-o", s(&bvh_out)], &["zero.npy", "no frames"]).absent(&[&bvh_out]),
        case("[0, J, 13]", "mo-render", &[s(&zero), "--skeleton", b, "--sheet", s(&sheet)], &["zero.npy", "no frames"]).absent(&[&sheet]),
        case("schedule_steps 0", "mo-sample", &[b, "--model", s(&model), "--frames", "4", "-o", o], &["schedule_steps"]).absent(&[&out]),
        case("schedule_steps 0", "mo-dift", &[b, "--model", s(&model), "-o", o], &["schedule_steps"]).absent(&[&out]),
        case("segment to 1e9", "mo-render", &[b, "--frame-labels", s(&far_labels), "--sheet", s(&sheet)], &["labels.json", "1000000000"]).absent(&[&sheet]),
        case("empty --rest-pose", "skel-info", &[s(&good), "--rest-pose", s(&empty), "-o", o], &["empty.bvh", "no frames"]).absent(&[&out]),
        // Messages.
        case("parent 999 said once", "mo-sample", &[s(&bad_parent), "-o", o], &["parent.json", "parent 999"]).absent(&[&out]),
        case("-n 256 x 10000 frames", "mo-sample", &[b, "-n", "256", "--frames", "10000", "-o", o], &["budget"]).absent(&[&out]),
        case(
            "placement JSON syntax: line and column",
            "mo-encode",
            &[s(&encoded), "--decode", "--skeleton", b, "--placement", s(&placement_syntax), "-o", s(&bvh_out)],
            &["placement-syntax.json", "line 2", "column"],
        )
        .absent(&[&bvh_out]),
        case(
            "JSON syntax: line and column",
            "mo-encode",
            &[s(&encoded), "--decode", "--skeleton", s(&syntax), "-o", s(&bvh_out)],
            &["syntax.json", "line 3", "column"],
        )
        .absent(&[&bvh_out]),
    ];
    check_all(cases);
    // A repeated message is the bug, whatever else it says.
    let err = String::from_utf8_lossy(&run("mo-sample", &[s(&bad_parent), "-o", o], None).stderr).to_string();
    assert_eq!(err.matches("parent 999").count(), 1, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn messages_name_what_is_wrong() {
    let dir = tempdir("messages");
    let biped = example("biped.bvh");
    let b = s(&biped);
    let garbage = dir.join("garbage.npy");
    std::fs::write(&garbage, b"this is not an array").unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, b"").unwrap();
    let nodir = dir.join("nodir");
    let cases = vec![
        case("-o nodir", "mo-sample", &[b, "--frames", "4", "--steps", "1", "-o", s(&nodir.join("x.npy"))], &["nodir/x.npy"]),
        case("-o nodir", "mo-segment", &[b, "--features", "raw", "-o", s(&nodir.join("x.json"))], &["nodir/x.json"]),
        case("-o nodir", "skel-info", &[b, "-o", s(&nodir.join("x.json"))], &["nodir/x.json"]),
        case("-o a directory", "skel-info", &[b, "-o", s(&dir)], &["is a directory"]),
        case("stdin twice", "mo-segment", &["-", "--skeleton", "-"], &["stdin", "once"]).stdin(&std::fs::read(&biped).unwrap()),
        case("garbage .npy", "mo-segment", &[s(&garbage), "--features", "raw"], &["garbage.npy", "NPY"]),
        case("garbage .npy", "mo-metrics", &["physics", s(&garbage), "--skeleton", b], &["garbage.npy", "NPY"]),
        case("--out is a file", "mo-train", &[b, "--out", s(&file), "--steps", "1"], &["a-file", "not a directory"]),
    ];
    check_all(cases);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn outputs_are_all_or_nothing() {
    let dir = tempdir("all-or-none");
    let biped = example("biped.bvh");
    let b = s(&biped);
    // The third output of each batch cannot be written: a directory stands in its place.
    let mut cases = Vec::new();
    for (tool, prefix, extra) in [
        ("skel-aug", "aug", vec!["-n", "3", "-o"]),
        ("mo-sample", "sample", vec!["-n", "3", "--frames", "4", "--steps", "1", "--bvh"]),
        ("mo-retarget", "retarget", vec![b, "--bind", "auto", "--frames", "12", "-n", "3", "-o"]),
    ] {
        std::fs::create_dir_all(dir.join(format!("{prefix}_2.bvh"))).unwrap();
        let pattern = dir.join(format!("{prefix}_{{i}}.bvh"));
        let mut args = vec![b];
        args.extend(extra);
        args.push(s(&pattern));
        let first = [dir.join(format!("{prefix}_0.bvh")), dir.join(format!("{prefix}_1.bvh"))];
        cases.push(case("third output unwritable", tool, &args, &[&format!("{prefix}_2.bvh")]).absent(&[&first[0], &first[1]]));
    }
    let sheet = dir.join("a.png");
    let gif = dir.join("nodir").join("b.gif");
    cases.push(case("--gif into nowhere", "mo-render", &[b, "--sheet", s(&sheet), "--gif", s(&gif)], &["nodir/b.gif"]).absent(&[&sheet]));
    let npy = dir.join("enc.npy");
    let stats = dir.join("nodir").join("stats.json");
    cases.push(case("--stats into nowhere", "mo-encode", &[b, "-o", s(&npy), "--stats", s(&stats)], &["nodir/stats.json"]).absent(&[&npy]));
    check_all(cases);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A cheap successful run of every tool that takes `-o`, writing to `out`.
fn writers(out: &Path, dir: &Path) -> Vec<(&'static str, Vec<String>)> {
    let b = example("biped.bvh").to_str().unwrap().to_string();
    let o = out.to_str().unwrap().to_string();
    let model_out = dir.join("m2m.npy");
    let v = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let _ = model_out;
    vec![
        ("skel-info", v(&[&b, "-o", &o])),
        ("skel-aug", v(&[&b, "-o", &o])),
        ("mo-encode", v(&[&b, "-o", &o])),
        ("mo-retarget", v(&[&b, &b, "--bind", "auto", "--frames", "12", "-o", &o])),
        ("mo-metrics", v(&["physics", &b, "-o", &o])),
        ("mo-render", v(&[&b, "--format", "html", "-o", &o])),
        ("mo-sample", v(&[&b, "--frames", "4", "--steps", "1", "-o", &o])),
        ("mo-dift", v(&[&b, "--draws", "1", "-o", &o])),
        ("mo-segment", v(&[&b, "--features", "raw", "-o", &o])),
        ("mo-edit", v(&["convert", &b, "-o", &o])),
    ]
}

#[cfg(unix)]
#[test]
fn a_symlink_given_to_o_stays_a_link() {
    let dir = tempdir("symlink");
    let link = dir.join("link");
    let target = dir.join("target");
    std::os::unix::fs::symlink("target", &link).unwrap();
    let mut failures = Vec::new();
    for (tool, args) in writers(&link, &dir) {
        let _ = std::fs::remove_file(&target);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run(tool, &args, None);
        let is_link = std::fs::symlink_metadata(&link).map(|m| m.file_type().is_symlink()).unwrap_or(false);
        let written = std::fs::metadata(&target).map(|m| m.len() > 0).unwrap_or(false);
        if !(out.status.success() && is_link && written) {
            failures.push(format!(
                "{tool}: exit {:?}, still a link: {is_link}, target written: {written}: {}",
                out.status.code(),
                String::from_utf8_lossy(&out.stderr).trim_end()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A private character device with the numbers of the kernel's null (1, 3) or full (1, 7)
/// device, or why it cannot be made.
#[cfg(target_os = "linux")]
fn private_device(dir: &Path, name: &str, minor: u32) -> Result<PathBuf, String> {
    let path = dir.join(name);
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a plain syscall on a NUL-terminated path.
    let made = unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, minor)) };
    if made != 0 {
        return Err(format!("mknod: {}", std::io::Error::last_os_error()));
    }
    // A file system mounted nodev refuses to open device nodes.
    std::fs::OpenOptions::new().write(true).open(&path).map_err(|e| format!("opening a private device node: {e}"))?;
    Ok(path)
}

#[cfg(target_os = "linux")]
fn is_char_device(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).map(|m| m.file_type().is_char_device()).unwrap_or(false)
}

#[cfg(target_os = "linux")]
#[test]
fn devices_given_to_o_are_written_in_place() {
    let dir = tempdir("devices");
    let (null, full) = match (private_device(&dir, "null", 3), private_device(&dir, "full", 7)) {
        (Ok(n), Ok(f)) => (n, f),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("SKIP devices_given_to_o_are_written_in_place: cannot make private device nodes ({e}; needs root and a file system without nodev)");
            let _ = std::fs::remove_dir_all(&dir);
            return;
        }
    };
    let mut failures = Vec::new();
    for (tool, args) in writers(&null, &dir) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run(tool, &args, None);
        if !(out.status.success() && is_char_device(&null)) {
            failures.push(format!(
                "{tool} -o null-device: exit {:?}, still a device: {}: {}",
                out.status.code(),
                is_char_device(&null),
                String::from_utf8_lossy(&out.stderr).trim_end()
            ));
        }
    }
    for (tool, args) in writers(&full, &dir) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run(tool, &args, None);
        let c = case("full device", tool, &args, &[s(&full), "No space left"]);
        if let Some(f) = judge(&c, &out) {
            failures.push(f);
        }
        if !is_char_device(&full) {
            failures.push(format!("{tool}: the full device was replaced"));
        }
    }
    let temps: Vec<String> =
        std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.contains(".tmp")).collect();
    assert!(temps.is_empty(), "temporary files left: {temps:?}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGTERM ends a run with 130 through the handler that removes temporary files (a run that
/// waits on stdin cannot have written anything; the removal itself is `io::output`'s unit test).
#[cfg(target_os = "linux")]
#[test]
fn sigterm_ends_a_run_through_the_cleanup_handler() {
    use std::process::Stdio;
    let dir = tempdir("signal");
    let out = dir.join("out.json");
    let mut child = common::bin("skel-info").args(["-", "-o", s(&out)]).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let stdin = child.stdin.take().unwrap();
    // Signal only once the handler is installed (the kernel lists SIGTERM as caught); the
    // process then blocks reading its stdin pipe, which stays open.
    let caught = || {
        let status = std::fs::read_to_string(format!("/proc/{}/status", child.id())).unwrap_or_default();
        let mask = status.lines().find_map(|l| l.strip_prefix("SigCgt:")).and_then(|m| u64::from_str_radix(m.trim(), 16).ok()).unwrap_or(0);
        mask & (1 << (libc::SIGTERM - 1)) != 0
    };
    for _ in 0..1000 {
        if caught() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(caught(), "skel-info never caught SIGTERM");
    // SAFETY: signalling our own child.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let status = child.wait().unwrap();
    drop(stdin);
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}
