//! `mo-encode` with AnyTop's representation (the default), end to end through the real binary.
//!
//! * encode (`--emit-skeleton`, `--placement`) -> decode puts every joint back: within 1e-4 of
//!   the creature's height from the rotations, 1e-2 from the positions (`--from positions`),
//!   and the decoded BVH re-encodes with the emitted document to the same features (1e-5), on
//!   every example creature and every corpus clip (one-frame clips are refused);
//! * decoded frame t is clip frame t (F frames give F-1 feature frames: the last frame only
//!   provides velocities);
//! * numpy loads the tensors; `--stats` and `--normalise` round trip with `--normalised`;
//! * the rig follows skel-info's rules (the emitted document is skel-info's), the T-pose rule,
//!   `--rest-pose` and the override flags; a BVH as `--skeleton` stands for its document;
//! * batches keep each clip's placement; output does not depend on `--threads`;
//! * bad input exits 2 with one line and leaves no file behind.
//!
//! The worst errors are printed (run with `--nocapture`).
use crate::common;

use common::{check_failure, load, ok, s, tempdir};

use menagerie::bvh;
use menagerie::document::SkeletonDocument;
use menagerie::io::npy;
use menagerie::motion::Motion;
use menagerie::repr::anytop::{AnyTopStats, Facing, Placement, Provenance, RestSource, DIM_CONTACT, FEATURE_DIMS};
use menagerie::repr::Features;
use menagerie::skeleton::Skeleton;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::{AtomicUsize, Ordering};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

fn run(args: &[&str]) -> Output {
    common::run("mo-encode", args, None)
}

fn read_npy(path: &Path) -> npy::NpyArray {
    npy::from_bytes(&std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())), "test").unwrap()
}

fn read_features(path: &Path) -> Features {
    let array = read_npy(path);
    let [frames, joints, dims] = array.shape[..] else { panic!("{}: rank {:?}", path.display(), array.shape) };
    Features { frames, joints, dims, data: array.data }
}

fn read_document(path: &Path) -> SkeletonDocument {
    SkeletonDocument::from_json(&std::fs::read_to_string(path).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The creature's size for tolerances (as tests/it/anytop_repr.rs): the vertical extent of frame
/// 0 (joints and End Sites), or the rest extent for a flat creature (a snake on the ground).
fn size(skeleton: &Skeleton, motion: &Motion) -> f64 {
    let n = skeleton.len();
    let first = Motion {
        frames: 1,
        joints: n,
        frame_time: motion.frame_time,
        rotations: motion.rotations[..n].to_vec(),
        translations: motion.translations[..n].to_vec(),
    };
    let w = first.forward_kinematics(skeleton);
    let mut ys: Vec<f64> = w.positions.iter().map(|p| p.y).collect();
    for (j, joint) in skeleton.joints.iter().enumerate() {
        for e in &joint.end_sites {
            ys.push((w.positions[j] + w.rotations[j] * *e).y);
        }
    }
    let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let extent = skeleton.rest_extent();
    if hi - lo < 0.05 * extent {
        extent
    } else {
        hi - lo
    }
}

/// Worst world-position distance between decoded frame t and clip frame t + `shift`.
fn worst_position_error(skeleton: &Skeleton, clip: &Motion, decoded: &Motion, shift: usize) -> f64 {
    let n = skeleton.len();
    let (a, b) = (clip.forward_kinematics(skeleton), decoded.forward_kinematics(skeleton));
    (0..decoded.frames.min(clip.frames - shift) * n).map(|k| a.positions[k + shift * n].distance(b.positions[k])).fold(0.0, f64::max)
}

fn max_abs_diff(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

/// What one clip's trip through the binary measured (errors / the creature's size).
struct RoundTrip {
    label: String,
    frames: usize,
    joints: usize,
    rotations: f64,
    /// Decoded frame t against clip frame t + 1: the wrong correspondence, for contrast.
    shifted: f64,
    /// Max |features(decoded BVH) - features| (absolute); `None` when the decoded clip has one
    /// frame (nothing to re-encode).
    reencode: Option<f32>,
    ik: f64,
}

/// The recommended pipeline: encode with `--emit-skeleton` and `--placement`, decode with them
/// (from the rotations and from the positions), re-encode the decoded BVH with the document.
fn round_trip(path: &Path, dir: &Path, label: &str) -> RoundTrip {
    // Unique names: corpus folders may share file names, and two workers share the directory.
    static SERIAL: AtomicUsize = AtomicUsize::new(0);
    let serial = SERIAL.fetch_add(1, Ordering::Relaxed);
    let at = |what: &str| dir.join(format!("{serial}.{what}"));
    let (features_path, doc, place, back, ik_path, again_path) = (at("npy"), at("skel.json"), at("place.json"), at("back.bvh"), at("ik.bvh"), at("again.npy"));
    let enc = run(&[s(path), "--emit-skeleton", s(&doc), "--placement", s(&place), "-o", s(&features_path), "-q"]);
    ok(&enc, &format!("encode {label}"));
    let decode = |from: &str, out: &Path| {
        let result = run(&["--decode", "--skeleton", s(&doc), "--placement", s(&place), "--from", from, s(&features_path), "-o", s(out)]);
        ok(&result, &format!("decode {label} from {from}"));
    };
    decode("rotations", &back);
    decode("positions", &ik_path);

    let (skeleton, clip) = load(path);
    let features = read_features(&features_path);
    assert_eq!(features.shape(), [clip.frames - 1, skeleton.len(), FEATURE_DIMS], "{label}");
    let (back_skeleton, decoded) = load(&back);
    assert_eq!(back_skeleton.joints, skeleton.joints, "{label}: decoded hierarchy differs");
    assert_eq!(decoded.frame_time, clip.frame_time, "{label}: frame time");
    assert_eq!(decoded.frames, clip.frames - 1, "{label}: decoded frames");
    let scale = size(&skeleton, &clip);
    let rotations = worst_position_error(&skeleton, &clip, &decoded, 0) / scale;
    let shifted = worst_position_error(&skeleton, &clip, &decoded, 1) / scale;
    let (_, by_ik) = load(&ik_path);
    let ik = worst_position_error(&skeleton, &clip, &by_ik, 0) / scale;

    let reencode = (decoded.frames >= 2).then(|| {
        ok(&run(&["--skeleton", s(&doc), s(&back), "-o", s(&again_path), "-q"]), &format!("re-encode {label}"));
        let again = read_features(&again_path);
        // The decoded clip's last frame has no successor: one feature frame fewer.
        assert_eq!(again.shape(), [features.frames - 1, features.joints, FEATURE_DIMS], "{label}");
        max_abs_diff(&features.data[..again.data.len()], &again.data)
    });
    for p in [&features_path, &doc, &place, &back, &ik_path, &again_path] {
        let _ = std::fs::remove_file(p);
    }
    RoundTrip { label: label.to_string(), frames: clip.frames, joints: skeleton.len(), rotations, shifted, reencode, ik }
}

/// Print every trip and the worst of each measure (with its file), then hold them to the
/// acceptance bounds.
fn report_and_check(what: &str, trips: &[RoundTrip]) {
    for t in trips {
        eprintln!(
            "  {}: {} frames, {} joints: rotations {:.2e}, positions (IK) {:.2e}, re-encode {}, (frame t vs t+1: {:.2e})",
            t.label,
            t.frames,
            t.joints,
            t.rotations,
            t.ik,
            t.reencode.map_or("n/a (one decoded frame)".to_string(), |r| format!("{r:.2e}")),
            t.shifted
        );
    }
    let worst = |f: &dyn Fn(&RoundTrip) -> f64| trips.iter().map(|t| (f(t), t.label.as_str())).fold((0.0, ""), |a, b| if b.0 > a.0 { b } else { a });
    let (rot, rot_file) = worst(&|t| t.rotations);
    let (ik, ik_file) = worst(&|t| t.ik);
    let (re, re_file) = worst(&|t| t.reencode.map_or(0.0, f64::from));
    eprintln!("{what}: {} clips; worst decode from rotations {rot:.3e} of the height ({rot_file})", trips.len());
    eprintln!("{what}: worst decode from positions (IK) {ik:.3e} of the height ({ik_file})");
    eprintln!("{what}: worst re-encode of the decoded BVH {re:.3e} absolute ({re_file})");
    // Written so that NaN fails.
    let within = |x: f64, bound: f64| x < bound;
    let mut failures = Vec::new();
    for t in trips {
        if !within(t.rotations, 1e-4) {
            failures.push(format!("{}: decode from rotations off by {:.3e} of the height", t.label, t.rotations));
        }
        if !within(t.ik, 1e-2) {
            failures.push(format!("{}: decode from positions off by {:.3e} of the height", t.label, t.ik));
        }
        if t.reencode.is_some_and(|r| !within(r.into(), 1e-5)) {
            failures.push(format!("{}: re-encoded features differ by {:.3e}", t.label, t.reencode.unwrap()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `f` over `items` on two workers (the machines have two cores), results in item order.
fn on_two_workers<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                let r = f(item);
                results.lock().unwrap().push((i, r));
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|(i, _)| *i);
    results.into_iter().map(|(_, r)| r).collect()
}

#[test]
fn examples_round_trip_through_the_binary() {
    let dir = tempdir("examples");
    let files = common::example_bvh_files();
    assert!(files.len() >= 9, "examples/data should hold the synthetic zoo");
    let trips = on_two_workers(&files, |p| round_trip(p, &dir, &p.file_name().unwrap().to_string_lossy()));
    // Decoded frame t is clip frame t; frame t + 1 is visibly another pose.
    assert!(trips.iter().all(|t| t.shifted > 100.0 * t.rotations.max(1e-7)), "frames do not correspond one to one");
    report_and_check("examples", &trips);

    // The document --emit-skeleton writes for one clip is the one skel-info prints for it.
    for path in &files {
        let doc = dir.join("emitted.json");
        ok(&run(&[s(path), "--emit-skeleton", s(&doc), "-o", s(&dir.join("x.npy"))]), "emit");
        let info = common::run("skel-info", &[s(path)], None);
        ok(&info, "skel-info");
        assert!(std::fs::read(&doc).unwrap() == info.stdout, "{}: --emit-skeleton differs from skel-info", path.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A BVH file's frame count, read from its `Frames:` line (cheap: nothing parsed).
fn frame_count(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let line = text.lines().find_map(|l| l.trim().strip_prefix("Frames:")).unwrap_or_else(|| panic!("{}: no Frames line", path.display()));
    line.trim().parse().unwrap()
}

/// Every corpus clip (about 11 s in the debug profile on two cores); clips of one frame must
/// be refused with the two-frame rule.
#[test]
fn corpus_round_trips_through_the_binary() {
    let Some(data) = common::shared_data("corpus_round_trips_through_the_binary") else { return };
    let dir = tempdir("corpus");
    let label = |p: &Path| p.strip_prefix(&data).unwrap().display().to_string();
    let (clips, single): (Vec<PathBuf>, Vec<PathBuf>) = common::corpus_bvh_files(&data).into_iter().partition(|p| frame_count(p) >= 2);
    for path in &single {
        let target = dir.join("single.npy");
        let out = run(&[s(path), "-o", s(&target)]);
        check_failure("mo-encode", &label(path), &out, "AnyTop features need at least two frames");
        assert!(!target.exists());
        eprintln!("  {}: one frame, refused", label(path));
    }
    let trips = on_two_workers(&clips, |p| round_trip(p, &dir, &label(p)));
    report_and_check("corpus", &trips);
    let _ = std::fs::remove_dir_all(&dir);
}

fn python_numpy() -> bool {
    std::process::Command::new("python3").args(["-c", "import numpy"]).output().is_ok_and(|o| o.status.success())
}

#[test]
fn numpy_loads_anytop_tensors() {
    if !python_numpy() {
        common::skip("numpy_loads_anytop_tensors", "python3 with numpy is not available");
        return;
    }
    let dir = tempdir("numpy");
    let quadruped = example("quadruped.bvh");
    let (one, two) = (dir.join("one.npy"), dir.join("two.npy"));
    ok(&run(&[s(&quadruped), "-o", s(&one)]), "encode");
    ok(&run(&[s(&quadruped), s(&quadruped), "-o", s(&two)]), "encode batch");
    let (skeleton, motion) = load(&quadruped);
    let f = read_features(&one);
    let script = format!(
        "import numpy as np\na = np.load('{}'); b = np.load('{}')\nprint(a.dtype.str, a.shape, b.dtype.str, b.shape, repr(float(a[3, 0, 1])), bool((b[0] == a).all() and (b[1] == a).all()))",
        s(&one),
        s(&two)
    );
    let out = std::process::Command::new("python3").arg("-c").arg(&script).output().unwrap();
    ok(&out, "python3");
    let (frames, joints) = (motion.frames - 1, skeleton.len());
    let value = format!("{:?}", f.at(3, 0)[1] as f64);
    let want = format!("<f4 ({frames}, {joints}, 13) <f4 (2, {frames}, {joints}, 13) {value} True");
    assert_eq!(String::from_utf8(out.stdout).unwrap().trim(), want);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn statistics_and_normalisation_round_trip() {
    let dir = tempdir("stats");
    let quadruped = example("quadruped.bvh");
    let at = |name: &str| dir.join(name);
    ok(&run(&[s(&quadruped), "--stats", s(&at("stats.json")), "--emit-skeleton", s(&at("q.json")), "-o", s(&at("plain.npy"))]), "encode");
    ok(&run(&[s(&quadruped), "--normalise", "-o", s(&at("norm.npy"))]), "encode --normalise");

    // --stats holds the statistics of the given clips; the document carries the same.
    let plain = read_features(&at("plain.npy"));
    let stats: AnyTopStats = serde_json::from_slice(&std::fs::read(at("stats.json")).unwrap()).unwrap();
    assert_eq!(stats, AnyTopStats::compute([&plain]).unwrap());
    assert_eq!(read_document(&at("q.json")).anytop.unwrap().stats.as_ref(), Some(&stats));
    // --normalise is exactly (x - mean) / (std + eps) with them.
    let mut want = plain.clone();
    stats.normalise(&mut want).unwrap();
    let norm = read_features(&at("norm.npy"));
    assert_eq!(norm, want);
    // ... and a document's statistics are used when it has them.
    ok(&run(&["--skeleton", s(&at("q.json")), s(&quadruped), "--normalise", "-o", s(&at("norm2.npy"))]), "encode --skeleton --normalise");
    assert_eq!(std::fs::read(at("norm2.npy")).unwrap(), std::fs::read(at("norm.npy")).unwrap());

    // Decoding --normalised features equals decoding the plain ones.
    ok(&run(&["--decode", "--skeleton", s(&at("q.json")), s(&at("plain.npy")), "-o", s(&at("plain.bvh"))]), "decode");
    ok(&run(&["--decode", "--normalised", "--skeleton", s(&at("q.json")), s(&at("norm.npy")), "-o", s(&at("norm.bvh"))]), "decode --normalised");
    let (skeleton, clip) = load(&quadruped);
    let (_, a) = load(&at("plain.bvh"));
    let (_, b) = load(&at("norm.bvh"));
    let diff = worst_position_error(&skeleton, &a, &b, 0) / size(&skeleton, &clip);
    eprintln!("normalise -> decode --normalised vs plain decode: {diff:.3e} of the height");
    assert!(diff < 1e-5, "--normalised decoding differs by {diff:.3e} of the height");
    // A BVH given as --skeleton stands for its skel-info document: same rig, same statistics.
    ok(&run(&["--decode", "--normalised", "--skeleton", s(&quadruped), s(&at("norm.npy")), "-o", s(&at("bvh.bvh"))]), "decode on BVH");
    assert_eq!(std::fs::read(at("bvh.bvh")).unwrap(), std::fs::read(at("norm.bvh")).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `path`'s clip with the root moved by (dx, dz) (its x/z position channels), or cut to
/// `frames` frames, written to `out`.
fn edited_copy(path: &Path, out: &Path, dx: f64, dz: f64, frames: Option<usize>) {
    let mut b = bvh::read_path(path).unwrap();
    let n = b.channel_count();
    let root = b.joints[0].channels.clone();
    let x = root.iter().position(|c| c.name() == "Xposition").unwrap();
    let z = root.iter().position(|c| c.name() == "Zposition").unwrap();
    for row in b.values.chunks_exact_mut(n) {
        row[x] += dx;
        row[z] += dz;
    }
    if let Some(f) = frames {
        b.frames = f;
        b.values.truncate(f * n);
    }
    std::fs::write(out, bvh::write_string(&b)).unwrap();
}

#[test]
fn batches_keep_each_clips_placement() {
    let dir = tempdir("batch");
    let at = |name: &str| dir.join(name);
    let biped = example("biped.bvh");
    let moved = at("moved.bvh");
    edited_copy(&biped, &moved, 150.0, -80.0, None);
    let out = run(&[s(&biped), s(&moved), "--placement", s(&at("p.json")), "--emit-skeleton", s(&at("s.json")), "-o", s(&at("b.npy"))]);
    ok(&out, "encode batch");
    let (skeleton, clip) = load(&biped);
    let (_, moved_clip) = load(&moved);
    let batch = read_npy(&at("b.npy"));
    assert_eq!(batch.shape, vec![2, clip.frames - 1, skeleton.len(), FEATURE_DIMS]);
    // Features do not see where a clip stands; the placements do.
    let half = batch.data.len() / 2;
    assert!(max_abs_diff(&batch.data[..half], &batch.data[half..]) < 1e-5);
    let text = std::fs::read_to_string(at("p.json")).unwrap();
    let placements: Vec<Placement> = serde_json::from_str(&text).unwrap();
    assert_eq!(placements.len(), 2);
    assert!(text.contains("moved.bvh"), "{text}");
    assert!((placements[1].root_xz[0] - placements[0].root_xz[0] - 150.0).abs() < 1e-9);
    assert!((placements[1].root_xz[1] - placements[0].root_xz[1] + 80.0).abs() < 1e-9);

    // Each sample goes back where its clip stood; without placements, both start where the
    // rest pose (frame 0 of the first clip) stands.
    let scale = size(&skeleton, &clip);
    let placed = at("placed_{i}.bvh");
    ok(&run(&["--decode", "--skeleton", s(&at("s.json")), "--placement", s(&at("p.json")), s(&at("b.npy")), "-o", s(&placed)]), "decode");
    let unplaced = at("unplaced_{i}.bvh");
    ok(&run(&["--decode", "--skeleton", s(&at("s.json")), s(&at("b.npy")), "-o", s(&unplaced)]), "decode without placement");
    for (file, original) in [("placed_0.bvh", &clip), ("placed_1.bvh", &moved_clip), ("unplaced_0.bvh", &clip), ("unplaced_1.bvh", &clip)] {
        let (_, decoded) = load(&at(file));
        let e = worst_position_error(&skeleton, original, &decoded, 0) / scale;
        assert!(e < 1e-4, "{file}: off by {e:.3e} of the height");
    }

    // Different lengths do not stack; a placement list must match the samples.
    let short = at("short.bvh");
    edited_copy(&biped, &short, 0.0, 0.0, Some(clip.frames - 5));
    let out = run(&[s(&biped), s(&short), "-o", s(&at("no.npy"))]);
    check_failure("mo-encode", "different lengths", &out, "cannot stack");
    assert!(String::from_utf8_lossy(&out.stderr).contains("short.bvh"));
    std::fs::write(at("one.json"), serde_json::to_string(&placements[..1]).unwrap()).unwrap();
    let out = run(&["--decode", "--skeleton", s(&at("s.json")), "--placement", s(&at("one.json")), s(&at("b.npy")), "-o", s(&at("x_{i}.bvh"))]);
    check_failure("mo-encode", "placement count", &out, "holds 1 placement(s) but");
    assert!(!at("x_0.bvh").exists() && !at("no.npy").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn output_is_byte_identical_for_any_thread_count() {
    let dir = tempdir("threads");
    let spider = example("spider.bvh");
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let at = |what: &str| dir.join(format!("t{threads}.{what}"));
        let mut args = vec![s(&spider); 4];
        let (npy_path, stats, place, doc) = (at("npy"), at("stats.json"), at("place.json"), at("skel.json"));
        args.extend(["--stats", s(&stats), "--placement", s(&place), "--emit-skeleton", s(&doc), "--normalise"]);
        args.extend(["-o", s(&npy_path), "--threads", threads]);
        ok(&run(&args), "encode");
        for from in ["rotations", "positions"] {
            let pattern = at(&format!("{from}_{{i}}.bvh"));
            let args = ["--decode", "--normalised", "--skeleton", s(&doc), "--placement", s(&place), "--from", from];
            ok(&run(&[&args[..], &[s(&npy_path), "-o", s(&pattern), "--threads", threads]].concat()), "decode");
        }
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with(&format!("t{threads}.")))
            .collect();
        files.sort();
        outputs.push(files.iter().map(|p| (p.file_name().unwrap().to_string_lossy()[3..].to_string(), std::fs::read(p).unwrap())).collect::<Vec<_>>());
    }
    assert_eq!(outputs[0].len(), 4 + 8, "outputs: {:?}", outputs[0].iter().map(|o| &o.0).collect::<Vec<_>>());
    for (a, b) in outputs[0].iter().zip(&outputs[1]) {
        assert_eq!(a.0, b.0);
        assert!(a.1 == b.1, "{} differs between --threads 1 and 2", a.0);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_rig_follows_skel_info_and_the_overrides() {
    let dir = tempdir("rig");
    let at = |name: &str| dir.join(name);
    let biped = example("biped.bvh");
    let (skeleton, clip) = load(&biped);
    let index = |name: &str| skeleton.index_of(name).unwrap();

    // A clip named like a T-pose gives the rest pose (here: the biped played backwards, so
    // that its frame 0 differs from the first clip's).
    let mut reversed = bvh::read_path(&biped).unwrap();
    let n = reversed.channel_count();
    let rows: Vec<Vec<f64>> = reversed.values.chunks_exact(n).rev().map(<[f64]>::to_vec).collect();
    reversed.values = rows.concat();
    let tpose = at("Biped_TPose.bvh");
    std::fs::write(&tpose, bvh::write_string(&reversed)).unwrap();
    ok(&run(&[s(&biped), s(&tpose), "--emit-skeleton", s(&at("t.json")), "-o", s(&at("t.npy"))]), "T-pose rule");
    let rig = read_document(&at("t.json")).anytop.unwrap().rig;
    assert_eq!(rig.rest_source, RestSource::TPose { file: s(&tpose).to_string() });
    // The same rig as skel-info --rest-pose builds (which records the file as explicit).
    let info = common::run("skel-info", &["--rest-pose", s(&tpose), s(&biped)], None);
    ok(&info, "skel-info --rest-pose");
    let mut expected = SkeletonDocument::from_json(std::str::from_utf8(&info.stdout).unwrap()).unwrap().anytop.unwrap().rig;
    assert_eq!(expected.rest_source, RestSource::Explicit { file: s(&tpose).to_string() });
    expected.rest_source = rig.rest_source.clone();
    assert_eq!(rig, expected);
    // --rest-pose: the whole document is skel-info's.
    ok(&run(&["--rest-pose", s(&tpose), s(&biped), "--emit-skeleton", s(&at("r.json")), "-o", s(&at("r.npy"))]), "--rest-pose");
    let emitted: serde_json::Value = serde_json::from_slice(&std::fs::read(at("r.json")).unwrap()).unwrap();
    let printed: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(emitted, printed);

    // Overrides, recorded as such; the features follow them and still decode exactly.
    let args = [s(&biped), "--face-joints", "RightUpLeg,LEFTUPLEG,mixamorig:RightArm,LeftArm", "--feet", "LeftToeBase,RightToeBase"];
    ok(&run(&[&args[..], &["--emit-skeleton", s(&at("o.json")), "-o", s(&at("o.npy"))]].concat()), "overrides");
    let rig = read_document(&at("o.json")).anytop.unwrap().rig;
    let face = ["mixamorig:RightUpLeg", "mixamorig:LeftUpLeg", "mixamorig:RightArm", "mixamorig:LeftArm"].map(index);
    assert_eq!(rig.facing, Facing::FaceJoints(face));
    assert_eq!(rig.facing_source, Provenance::Override);
    let mut feet = vec![index("mixamorig:LeftToeBase"), index("mixamorig:RightToeBase")];
    feet.sort();
    assert_eq!((rig.feet.clone(), rig.feet_source), (feet.clone(), Provenance::Override));
    let f = read_features(&at("o.npy"));
    let f = &f;
    let contacts: Vec<usize> = (0..f.frames).flat_map(|t| (0..f.joints).filter(move |&j| f.at(t, j)[DIM_CONTACT] != 0.0)).collect();
    assert!(!contacts.is_empty() && contacts.iter().all(|j| feet.contains(j)), "contacts off the given feet");
    ok(&run(&["--decode", "--skeleton", s(&at("o.json")), s(&at("o.npy")), "-o", s(&at("o.bvh"))]), "decode overrides");
    let (_, decoded) = load(&at("o.bvh"));
    assert!(worst_position_error(&skeleton, &clip, &decoded, 0) < 1e-4 * size(&skeleton, &clip));
    // A body axis for the snake.
    let snake = example("snake.bvh");
    ok(&run(&[s(&snake), "--body-axis", "jtHead,jtTail06", "--emit-skeleton", s(&at("a.json")), "-o", s(&at("a.npy"))]), "--body-axis");
    let (snake_skeleton, _) = load(&snake);
    let rig = read_document(&at("a.json")).anytop.unwrap().rig;
    let (head, tail) = (snake_skeleton.index_of("jtHead").unwrap(), snake_skeleton.index_of("jtTail06").unwrap());
    assert_eq!((rig.facing, rig.facing_source), (Facing::BodyAxis { front: head, back: tail }, Provenance::Override));

    // A BVH as --skeleton stands for its skel-info document, when encoding as when decoding.
    let spider = example("spider.bvh");
    let doc = common::run("skel-info", &[s(&spider)], None);
    ok(&doc, "skel-info");
    std::fs::write(at("spider.json"), &doc.stdout).unwrap();
    ok(&run(&["--skeleton", s(&spider), s(&spider), "--emit-skeleton", s(&at("e.json")), "-o", s(&at("1.npy"))]), "on BVH");
    ok(&run(&["--skeleton", s(&at("spider.json")), s(&spider), "-o", s(&at("2.npy"))]), "on document");
    assert_eq!(std::fs::read(at("1.npy")).unwrap(), std::fs::read(at("2.npy")).unwrap());
    assert!(std::fs::read(at("e.json")).unwrap() == doc.stdout, "--skeleton BVH --emit-skeleton differs from skel-info");
    // A document without AnyTop record: the rig is built on its OFFSET pose, or on --rest-pose.
    let bare = common::run("skel-info", &["--no-anytop", s(&spider)], None);
    ok(&bare, "skel-info --no-anytop");
    std::fs::write(at("bare.json"), &bare.stdout).unwrap();
    for (extra, source) in [(vec![], RestSource::Offsets), (vec!["--rest-pose", s(&spider)], RestSource::Explicit { file: s(&spider).to_string() })] {
        let out = at("bare.out.json");
        ok(&run(&[&extra[..], &["--skeleton", s(&at("bare.json")), s(&spider), "--emit-skeleton", s(&out), "-o", s(&at("3.npy"))]].concat()), "bare document");
        assert_eq!(read_document(&out).anytop.unwrap().rig.rest_source, source);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Hand-made NPY with an arbitrary descr and payload.
fn raw_npy(descr: &str, shape: &str, payload: &[u8]) -> Vec<u8> {
    let mut h = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}").into_bytes();
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
    let at = |name: &str| dir.join(name);
    let biped = example("biped.bvh");
    let (skeleton, clip) = load(&biped);
    ok(&run(&[s(&biped), "--emit-skeleton", s(&at("s.json")), "--placement", s(&at("p.json")), "-o", s(&at("f.npy"))]), "encode");
    ok(&run(&["--repr", "m2m", s(&biped), "-o", s(&at("m2m.npy"))]), "encode m2m");
    let bare = common::run("skel-info", &["--no-anytop", s(&biped)], None);
    ok(&bare, "skel-info --no-anytop");
    std::fs::write(at("bare.json"), &bare.stdout).unwrap();
    let f = read_features(&at("f.npy"));
    let write = |name: &str, bytes: &[u8]| {
        let p = at(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let npy_of = |shape: &[usize], data: &[f32]| npy::to_bytes(shape, data).unwrap();
    let mut nan = f.clone();
    nan.at_mut(1, 2)[4] = f32::NAN;
    let wide = Features::zeros(f.frames, f.joints + 1, FEATURE_DIMS);
    let joint2 = &skeleton.joints[2].name;

    // Decoding: (what, NPY, extra flags, expected words).
    let doc = at("s.json");
    let nan_text = format!("non-finite value NaN at frame 1, joint 2 '{joint2}', dim 4");
    let decoding: Vec<(&str, PathBuf, Vec<&str>, String)> = vec![
        ("m2m features", at("m2m.npy"), vec![], "AnyTop features have 13 dims per joint, found 9".into()),
        ("m2m features (hint)", at("m2m.npy"), vec![], "decode them with --repr m2m".into()),
        ("NaN", write("nan.npy", &npy_of(&nan.shape(), &nan.data)), vec![], nan_text.clone()),
        (
            "NaN in a batch",
            write("nanb.npy", &npy_of(&[2, f.frames, f.joints, 13], &[f.data.clone(), nan.data.clone()].concat())),
            vec![],
            format!("sample 1: {nan_text}"),
        ),
        (
            "joint count",
            write("wide.npy", &npy_of(&wide.shape(), &wide.data)),
            vec![],
            format!("the features have {} joints but the skeleton has {}", f.joints + 1, f.joints),
        ),
        ("rank 2", write("rank2.npy", &npy_of(&[f.frames, f.joints * 13], &f.data)), vec![], "(rank 2)".into()),
        (
            "int dtype",
            write("int.npy", &raw_npy("<i4", &format!("({}, {}, 13)", f.frames, f.joints), &vec![0u8; f.data.len() * 4])),
            vec![],
            "unsupported dtype '<i4'".into(),
        ),
        ("--normalised without statistics", at("f.npy"), vec!["--normalised"], "has no AnyTop statistics".into()),
        ("placement file", at("f.npy"), vec!["--placement", s(&biped)], "not a placement file".into()),
    ];
    for (what, input, extra, expect) in &decoding {
        let target = at("out.bvh");
        let skeleton_doc = if what.contains("--normalised") { at("bare.json") } else { doc.clone() };
        let out = run(&[&["--decode", "--skeleton", s(&skeleton_doc)], &extra[..], &[s(input), "-o", s(&target)]].concat());
        check_failure("mo-encode", what, &out, expect);
        assert!(!target.exists(), "{what}: output written despite the error");
    }

    // Encoding: nothing of -o, --stats, --emit-skeleton, --placement is written.
    let mut one_frame = bvh::read_path(&biped).unwrap();
    one_frame.frames = 1;
    one_frame.values.truncate(one_frame.channel_count());
    let single = write("single.bvh", bvh::write_string(&one_frame).as_bytes());
    let crab = example("crab.bvh");
    let encoding: Vec<(&str, Vec<&str>, &str)> = vec![
        ("unknown --face-joints name", vec![s(&biped), "--face-joints", "RightHip,LeftUpLeg,RightArm,LeftArm"], "no joint named 'RightHip' (closest: "),
        ("close names", vec![s(&biped), "--face-joints", "RightHip,LeftUpLeg,RightArm,LeftArm"], "mixamorig:RightUpLeg"),
        ("three face joints", vec![s(&biped), "--face-joints", "RightUpLeg,LeftUpLeg,RightArm"], "takes four joint names"),
        ("unknown foot", vec![s(&biped), "--feet", "LeftPaw"], "--feet: "),
        ("one frame", vec![s(&single)], "AnyTop features need at least two frames"),
        ("one frame in a batch", vec![s(&biped), s(&single)], "single.bvh: 1 frame(s)"),
        ("two skeletons", vec![s(&biped), s(&crab)], "have different skeletons"),
        ("--skeleton of another creature", vec!["--skeleton", s(&crab), s(&biped)], "crab.bvh have different skeletons"),
        ("--rest-pose of another creature", vec!["--rest-pose", s(&crab), s(&biped)], "have different skeletons"),
        ("overrides against a record", vec!["--skeleton", s(&doc), "--feet", "LeftToeBase", s(&biped)], "fixes the rig"),
        ("anytop flags with m2m", vec!["--repr", "m2m", s(&biped)], "belongs to --repr anytop"),
    ];
    let outputs = [at("enc.npy"), at("enc.stats.json"), at("enc.skel.json"), at("enc.place.json")];
    let output_flags = ["-o", s(&outputs[0]), "--stats", s(&outputs[1]), "--emit-skeleton", s(&outputs[2]), "--placement", s(&outputs[3])];
    for (what, args, expect) in &encoding {
        let out = run(&[&args[..], &output_flags[..]].concat());
        check_failure("mo-encode", what, &out, expect);
        assert!(outputs.iter().all(|p| !p.exists()), "{what}: output written despite the error");
    }
    // A later output that cannot be written takes the earlier ones back.
    let out = run(&[s(&biped), "-o", s(&outputs[0]), "--stats", "/nonexistent/dir/stats.json"]);
    check_failure("mo-encode", "unwritable --stats", &out, "cannot write /nonexistent/dir/stats.json");
    assert!(!outputs[0].exists(), "the NPY stayed behind a failed --stats");
    // One clip, one skeleton: the good encode above still round trips (sanity of the fixtures).
    assert_eq!(f.shape(), [clip.frames - 1, skeleton.len(), FEATURE_DIMS]);

    let leftovers: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') || n.contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temp files left behind: {leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn require_contacts_fails_only_without_feet() {
    let dir = tempdir("contacts");
    let out = dir.join("fish.npy");
    let fish = run(&[s(&example("fish.bvh")), "--require-contacts", "-o", s(&out)]);
    assert_eq!(fish.status.code(), Some(2), "a fish has no feet");
    let err = String::from_utf8_lossy(&fish.stderr);
    assert!(err.contains("no foot joints") && err.trim_end().lines().count() == 1, "{err}");
    assert!(!out.exists(), "no partial file");
    // Without the flag the fish encodes, with a warning, and every contact is 0.
    let plain = run(&[s(&example("fish.bvh")), "-o", s(&out)]);
    ok(&plain, "fish without --require-contacts");
    assert!(String::from_utf8_lossy(&plain.stderr).contains("warning"));
    assert!(read_features(&out).data.chunks(13).all(|t| t[12] == 0.0));
    // A walker has feet, so the flag changes nothing.
    let walker = run(&[s(&example("quadruped.bvh")), "--require-contacts", "-o", s(&out)]);
    ok(&walker, "quadruped with --require-contacts");
    assert!(read_features(&out).data.chunks(13).any(|t| t[12] == 1.0));
}
