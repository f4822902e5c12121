//! `mo-encode --repr m2m` end to end, through the real binary: encode -> decode reproduces every
//! joint's world position (1e-4 of the skeleton's size) on the examples and on every corpus
//! file whose bones do not translate, and the decoded BVH re-encodes to the same features;
//! batches stack or fail clearly; output does not depend on --threads; bad input exits 2 with
//! one line and leaves no file behind.
use crate::common;

use common::{check_failure, load, ok, s, tempdir};

use menagerie::bvh;
use menagerie::io::npy;
use menagerie::motion::Motion;
use menagerie::repr::{m2m, Features};
use menagerie::skeleton::Skeleton;
use std::path::{Path, PathBuf};

/// Largest world-position difference between two motions on one skeleton.
fn max_position_error(skeleton: &Skeleton, a: &Motion, b: &Motion) -> f64 {
    assert_eq!((a.frames, a.joints), (b.frames, b.joints));
    let (pa, pb) = (a.forward_kinematics(skeleton), b.forward_kinematics(skeleton));
    pa.positions.iter().zip(&pb.positions).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max)
}

fn features_of(array: npy::NpyArray) -> Features {
    let [frames, joints, dims] = array.shape[..] else { panic!("rank {:?}", array.shape) };
    Features { frames, joints, dims, data: array.data }
}

/// Result of one file's round trip through the binary.
struct RoundTrip {
    /// Max world-position error / the skeleton's rest extent.
    position_error: f64,
    /// Max |features(decoded BVH) - features(original)|.
    reencode_error: f32,
    /// What m2m cannot carry on this file (animated bone translations).
    lost: Option<m2m::BoneTranslationChange>,
    frames: usize,
}

/// Encode `path` with the binary, decode onto `skeleton_arg` (the BVH itself or a document),
/// and compare world positions and re-encoded features.
fn round_trip(path: &Path, dir: &Path, skeleton_arg: Option<&Path>) -> RoundTrip {
    // Unique names: corpus folders may share file names, and two workers share the directory.
    static SERIAL: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let serial = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let stem = format!("{serial}-{}", path.file_stem().unwrap().to_string_lossy().replace(' ', "_"));
    let npy_path = dir.join(format!("{stem}.npy"));
    let back_path = dir.join(format!("{stem}.back.bvh"));
    ok(&common::run("mo-encode", &["--repr", "m2m", s(path), "-o", s(&npy_path), "-q"], None), &format!("encode {}", path.display()));
    let skeleton_arg = skeleton_arg.unwrap_or(path);
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(skeleton_arg), s(&npy_path), "-o", s(&back_path)], None);
    ok(&out, &format!("decode {}", path.display()));

    let (skeleton, original) = load(path);
    let features = features_of(npy::from_bytes(&std::fs::read(&npy_path).unwrap(), "enc").unwrap());
    assert_eq!(features.shape(), [original.frames, skeleton.len(), m2m::DIMS], "{}", path.display());
    let (back_skeleton, decoded) = load(&back_path);
    assert_eq!(back_skeleton.joints, skeleton.joints, "{}: decoded hierarchy differs", path.display());
    assert_eq!(decoded.frame_time, original.frame_time, "{}", path.display());
    let size = skeleton.rest_extent().max(1e-12);
    let position_error = max_position_error(&skeleton, &original, &decoded) / size;
    let again = m2m::encode(&decoded);
    let reencode_error = features.data.iter().zip(&again.data).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
    let lost = m2m::max_bone_translation_change(&original, &skeleton, 1e-5 * size);
    let _ = std::fs::remove_file(&npy_path);
    let _ = std::fs::remove_file(&back_path);
    RoundTrip { position_error, reencode_error, lost, frames: original.frames }
}

#[test]
fn examples_round_trip_through_the_binary() {
    let dir = tempdir("examples");
    let files = common::example_bvh_files();
    assert!(files.len() >= 7, "examples/data should hold the synthetic zoo");
    for path in &files {
        let r = round_trip(path, &dir, None);
        assert!(r.lost.is_none(), "{}: example creatures do not animate bone translations", path.display());
        assert!(r.position_error < 1e-4, "{}: position error {:.3e} of the size", path.display(), r.position_error);
        assert!(r.reencode_error < 1e-5, "{}: re-encoded features differ by {:.3e}", path.display(), r.reencode_error);
    }
    // A skeleton document from skel-info decodes to the same file as the BVH itself.
    let spider = files.iter().find(|p| p.ends_with("spider.bvh")).expect("spider.bvh");
    let doc = common::run("skel-info", &[s(spider)], None);
    ok(&doc, "skel-info");
    let doc_path = dir.join("spider.json");
    std::fs::write(&doc_path, &doc.stdout).unwrap();
    let enc = common::run("mo-encode", &["--repr", "m2m", s(spider)], None);
    ok(&enc, "encode to stdout");
    let from_bvh = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(spider)], Some(&enc.stdout));
    let from_doc = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&doc_path), "-"], Some(&enc.stdout));
    ok(&from_bvh, "decode on BVH");
    ok(&from_doc, "decode on document");
    assert_eq!(from_bvh.stdout, from_doc.stdout);
    assert!(from_bvh.stdout.starts_with(b"HIERARCHY"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn corpus_round_trips_within_1e4_of_the_size() {
    let Some(data) = common::shared_data("corpus_round_trips_within_1e4_of_the_size") else { return };
    let dir = tempdir("corpus");
    let mut failures = Vec::new();
    let mut report = Vec::new();
    let (mut exact, mut lossy) = (0, 0);
    // Two workers (the machines have two cores); results are reported in file order.
    let files = common::corpus_bvh_files(&data);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(path) = files.get(i) else { break };
                let r = round_trip(path, &dir, None);
                results.lock().unwrap().push((i, r));
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|(i, _)| *i);
    for (i, r) in results {
        let rel = files[i].strip_prefix(&data).unwrap().display().to_string();
        if r.reencode_error >= 1e-5 {
            failures.push(format!("{rel}: re-encoded features differ by {:.3e}", r.reencode_error));
        }
        match &r.lost {
            None => {
                exact += 1;
                if r.position_error >= 1e-4 {
                    failures.push(format!("{rel}: position error {:.3e} of the size", r.position_error));
                }
                report.push(format!("  {rel}: {} frames, max error {:.2e} of the size", r.frames, r.position_error));
            }
            Some(c) => {
                lossy += 1;
                report.push(format!(
                    "  {rel}: {} frames, ANIMATED BONE TRANSLATIONS ({} joints, up to {:.4} units off OFFSET), max error {:.2e} of the size",
                    r.frames, c.joints, c.distance, r.position_error
                ));
            }
        }
    }
    eprintln!("m2m round trips ({exact} exact files, {lossy} with animated bone translations):\n{}", report.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn numpy_loads_the_encoded_tensor() {
    if !common_python() {
        common::skip("numpy_loads_the_encoded_tensor", "python3 with numpy is not available");
        return;
    }
    let dir = tempdir("numpy");
    let biped = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/biped.bvh");
    let one = dir.join("one.npy");
    let two = dir.join("two.npy");
    ok(&common::run("mo-encode", &["--repr", "m2m", s(&biped), "-o", s(&one)], None), "encode");
    ok(&common::run("mo-encode", &["--repr", "m2m", s(&biped), s(&biped), "-o", s(&two)], None), "encode batch");
    let (_, motion) = load(&biped);
    let f = m2m::encode(&motion);
    let script = format!(
        "import numpy as np\na = np.load('{}'); b = np.load('{}')\nprint(a.dtype.str, a.shape, b.dtype.str, b.shape, repr(float(a[3, 0, 7])), bool((b[0] == a).all() and (b[1] == a).all()))",
        s(&one),
        s(&two)
    );
    let out = std::process::Command::new("python3").arg("-c").arg(&script).output().unwrap();
    ok(&out, "python3");
    let text = String::from_utf8(out.stdout).unwrap();
    let want = format!("<f4 ({}, {}, 9) <f4 (2, {}, {}, 9) {} True", f.frames, f.joints, f.frames, f.joints, python_float(f.at(3, 0)[7]));
    assert_eq!(text.trim(), want);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Python's repr of a float32 value widened to float64.
fn python_float(v: f32) -> String {
    let s = format!("{:?}", v as f64);
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}

fn common_python() -> bool {
    std::process::Command::new("python3").args(["-c", "import numpy"]).output().is_ok_and(|o| o.status.success())
}

#[test]
fn batches_stack_equal_shapes_and_name_the_odd_file() {
    let dir = tempdir("batch");
    let ex = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data");
    let (bird, crab) = (ex.join("bird.bvh"), ex.join("crab.bvh"));
    let out = common::run("mo-encode", &["--repr", "m2m", s(&bird), s(&bird), s(&bird)], None);
    ok(&out, "batch");
    let a = npy::from_bytes(&out.stdout, "batch").unwrap();
    let (_, motion) = load(&bird);
    assert_eq!(a.shape, vec![3, motion.frames, motion.joints, m2m::DIMS]);
    let one = m2m::encode(&motion);
    for i in 0..3 {
        assert_eq!(&a.data[i * one.data.len()..(i + 1) * one.data.len()], &one.data[..]);
    }

    // The batch decodes to one file per sample, each the same BVH as a single decode.
    let batch_npy = dir.join("b.npy");
    std::fs::write(&batch_npy, &out.stdout).unwrap();
    let pattern = dir.join("bird_{i}.bvh");
    ok(&common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&bird), s(&batch_npy), "-o", s(&pattern)], None), "decode batch");
    let single = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&bird)], Some(&npy::to_bytes(&one.shape(), &one.data).unwrap()));
    ok(&single, "decode single");
    for i in 0..3 {
        assert_eq!(std::fs::read(dir.join(format!("bird_{i}.bvh"))).unwrap(), single.stdout, "sample {i}");
    }

    let target = dir.join("mixed.npy");
    let out = common::run("mo-encode", &["--repr", "m2m", s(&bird), s(&bird), s(&crab), "-o", s(&target)], None);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("bird.bvh") && err.contains("crab.bvh") && err.contains("cannot stack"), "{err}");
    assert!(!target.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn output_is_byte_identical_for_any_thread_count() {
    let dir = tempdir("threads");
    let files = common::example_bvh_files();
    let spider = files.iter().find(|p| p.ends_with("spider.bvh")).unwrap();
    let batch: Vec<&str> = vec![s(spider); 6];
    let run = |args: &[&str], threads: &str| {
        let mut a = vec!["--repr", "m2m"];
        a.extend_from_slice(args);
        a.extend(["--threads", threads]);
        let out = common::run("mo-encode", &a, None);
        ok(&out, "encode");
        out.stdout
    };
    for f in &files {
        assert_eq!(run(&[s(f)], "1"), run(&[s(f)], "2"), "{}", f.display());
    }
    let one = run(&batch, "1");
    assert_eq!(one, run(&batch, "2"));
    // Batch decode: every file identical whatever the thread count.
    let npy_path = dir.join("six.npy");
    std::fs::write(&npy_path, &one).unwrap();
    for threads in ["1", "2"] {
        let pattern = dir.join(format!("t{threads}_{{i}}.bvh"));
        ok(
            &common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(spider), s(&npy_path), "-o", s(&pattern), "--threads", threads], None),
            "decode",
        );
    }
    for i in 0..6 {
        let a = std::fs::read(dir.join(format!("t1_{i}.bvh"))).unwrap();
        let b = std::fs::read(dir.join(format!("t2_{i}.bvh"))).unwrap();
        assert_eq!(a, b, "sample {i}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A BVH written here, so the bad-input table needs no external data.
const TINY: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 1 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\tJOINT LeftLeg\n\t{\n\t\tOFFSET 0.1 -0.5 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 -0.5 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n0 1 0 0 0 0 10 0 0\n0.1 1 0 0 5 0 20 0 0\n";

/// Hand-made NPY with an arbitrary descr and payload.
fn raw_npy(descr: &str, shape: &str, payload: &[u8], fortran: bool) -> Vec<u8> {
    let dict = format!("{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}", if fortran { "True" } else { "False" });
    let mut h = dict.into_bytes();
    while (h.len() + 11) % 64 != 0 {
        h.push(b' ');
    }
    h.push(b'\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    out.extend_from_slice(&h);
    out.extend_from_slice(payload);
    out
}

#[test]
fn bad_input_exits_2_with_one_line_and_no_file() {
    let dir = tempdir("bad");
    let bvh_path = dir.join("tiny.bvh");
    std::fs::write(&bvh_path, TINY).unwrap();
    let good = common::run("mo-encode", &["--repr", "m2m", s(&bvh_path)], None);
    ok(&good, "encode tiny");
    let f = features_of(npy::from_bytes(&good.stdout, "tiny").unwrap());
    assert_eq!(f.shape(), [2, 2, 9]);
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let npy_of = |shape: &[usize], data: &[f32]| npy::to_bytes(shape, data).unwrap();

    let mut nan = f.clone();
    nan.at_mut(1, 1)[4] = f32::NAN;
    let f64_payload: Vec<u8> = f.data.iter().flat_map(|v| (*v as f64).to_le_bytes()).collect();
    let big_endian: Vec<u8> = f.data.iter().flat_map(|v| v.to_be_bytes()).collect();
    let int_payload = vec![0u8; 2 * 2 * 9 * 4];
    let cases: Vec<(&str, PathBuf, &str)> = vec![
        ("rank 2", write("rank2.npy", &npy_of(&[2, 18], &f.data)), "found shape [2, 18] (rank 2)"),
        ("rank 5", write("rank5.npy", &npy_of(&[1, 1, 2, 2, 9], &f.data)), "(rank 5)"),
        ("int dtype", write("int.npy", &raw_npy("<i4", "(2, 2, 9)", &int_payload, false)), "unsupported dtype '<i4'"),
        ("big-endian", write("be.npy", &raw_npy(">f4", "(2, 2, 9)", &big_endian, false)), "unsupported dtype '>f4'"),
        ("pickle", write("obj.npy", &raw_npy("|O", "(2, 2, 9)", &int_payload, false)), "unsupported dtype '|O'"),
        ("fortran", write("fortran.npy", &raw_npy("<f4", "(2, 2, 9)", &int_payload, true)), "fortran_order True"),
        ("truncated", write("short.npy", &good.stdout[..good.stdout.len() - 5]), "needs 144 data bytes but the input has 139"),
        ("NaN", write("nan.npy", &npy_of(&nan.shape(), &nan.data)), "non-finite value NaN at frame 1, joint 1 'LeftLeg', dim 4"),
        ("NaN in batch", write("nanb.npy", &npy_of(&[2, 2, 2, 9], &[f.data.clone(), nan.data.clone()].concat())), "sample 1: non-finite value NaN at frame 1"),
        ("joints", write("joints.npy", &npy_of(&[1, 3, 9], &[0.0; 27])), "the features have 3 joints but the skeleton has 2"),
        ("dims", write("dims.npy", &npy_of(&[2, 2, 13], &[0.0; 52])), "m2m features have 9 dims per joint, found 13"),
        ("not npy", bvh_path.clone(), "not an NPY file"),
    ];
    for (what, input, expect) in &cases {
        let target = dir.join(format!("out-{}.bvh", what.replace(' ', "_")));
        let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&bvh_path), s(input), "-o", s(&target)], None);
        check_failure("mo-encode", what, &out, expect);
        assert!(!target.exists(), "{what}: output written despite the error");
    }
    // f8 input is accepted and converted.
    let f8 = write("f8.npy", &raw_npy("<f8", "(2, 2, 9)", &f64_payload, false));
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&bvh_path), s(&f8)], None);
    ok(&out, "f8 decode");

    // A batch needs a numbered output.
    let batch = write("batch.npy", &npy_of(&[2, 2, 2, 9], &[f.data.clone(), f.data.clone()].concat()));
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&bvh_path), s(&batch)], None);
    check_failure("mo-encode", "batch to stdout", &out, "give -o a pattern");
    let target = dir.join("plain.bvh");
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&bvh_path), s(&batch), "-o", s(&target)], None);
    check_failure("mo-encode", "batch without {i}", &out, "numbered output path");
    assert!(!target.exists());

    // Skeletons that are neither documents nor BVH; documents that are broken.
    let junk = write("junk.txt", b"hello");
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&junk), s(&batch)], None);
    check_failure("mo-encode", "junk skeleton", &out, "not a skeleton");
    let broken = write("broken.json", b"{\"format\": \"menagerie.skeleton\"");
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&broken), s(&batch)], None);
    check_failure("mo-encode", "broken document", &out, "not a skeleton document");

    // Encoding errors: a broken BVH among good ones, a missing file; nothing written.
    let broken_bvh = write("broken.bvh", &TINY.as_bytes()[..TINY.len() - 12]);
    let target = dir.join("enc.npy");
    let out = common::run("mo-encode", &["--repr", "m2m", s(&bvh_path), s(&broken_bvh), "-o", s(&target)], None);
    check_failure("mo-encode", "broken BVH", &out, "broken.bvh:");
    assert!(!target.exists());
    let out = common::run("mo-encode", &["--repr", "m2m", "/nonexistent/x.bvh", "-o", s(&target)], None);
    check_failure("mo-encode", "missing file", &out, "/nonexistent/x.bvh");
    let out = common::run("mo-encode", &["--repr", "m2m", "-", "-"], Some(TINY.as_bytes()));
    check_failure("mo-encode", "stdin twice", &out, "only once");
    // Usage errors (clap) also exit 2.
    let out = common::run("mo-encode", &["--repr", "m2m", "--decode", s(&batch)], None);
    assert_eq!(out.status.code(), Some(2));
    let out = common::run("mo-encode", &["--repr", "nope", s(&bvh_path)], None);
    assert_eq!(out.status.code(), Some(2));

    let leftovers: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') || n.contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temp files left behind: {leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn stdin_in_and_out_and_closed_pipes() {
    use std::process::Stdio;
    let ex = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data");
    let fish = ex.join("fish.bvh");
    let text = std::fs::read(&fish).unwrap();
    let from_file = common::run("mo-encode", &["--repr", "m2m", s(&fish)], None);
    let from_stdin = common::run("mo-encode", &["--repr", "m2m", "-"], Some(&text));
    ok(&from_stdin, "stdin encode");
    assert_eq!(from_file.stdout, from_stdin.stdout);
    // Decode reads stdin when no input is given.
    let decoded = common::run("mo-encode", &["--repr", "m2m", "--decode", "--skeleton", s(&fish)], Some(&from_stdin.stdout));
    ok(&decoded, "stdin decode");
    let (skeleton, original) = load(&fish);
    let back = Motion::from_bvh(&bvh::parse_bytes(&decoded.stdout, "decoded").unwrap(), &skeleton);
    assert!(max_position_error(&skeleton, &original, &back) < 1e-4 * skeleton.rest_extent());

    // `| head -c 10`: a closed pipe is success, and quiet.
    let centipede = ex.join("centipede.bvh");
    let many: Vec<&str> = vec![s(&centipede); 40];
    let mut child = common::bin("mo-encode").args(["--repr", "m2m"]).args(&many).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 10];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(&first[..6], npy::MAGIC);
}
