//! `skel-aug` end to end, on every corpus file (skipped without ../shared/data) and every
//! synthetic creature in examples/data:
//!
//! * removal and addition keep every surviving joint's world position within 1e-6 of the
//!   skeleton's size, checked on the BVH text as written and parsed back;
//! * removal takes 10-30% of the joints, or every removable joint when the skeleton has fewer
//!   (chains ending in end effectors stop at feet, branching joints and the root), and never a
//!   foot or the root;
//! * R and D of the result equal a brute-force recomputation (written independently here);
//! * through the binary: the same seed gives byte-identical output, variants differ, a
//!   skeleton document comes back as a document that passes the JSON Schema and describes the
//!   same skeleton as the BVH path; bad input exits 2 with one line and no file.
use crate::common;

use common::{schema_validator, tempdir};

use common::topology::{reference_distances, reference_relations};

use glam::DVec3;
use menagerie::augment::{self, Options, RemoveAmount};
use menagerie::bvh::{self, Bvh};
use menagerie::document::SkeletonDocument;
use menagerie::motion::Motion;
use menagerie::rng::SplitMix64;
use menagerie::skeleton::{roles, topology, Skeleton};
use std::path::Path;

/// World positions must agree within this fraction of the skeleton's size.
const TOLERANCE: f64 = 1e-6;
/// Frames checked per clip: evenly spaced, so long clips stay fast in the debug profile.
const MAX_FRAMES: usize = 240;
/// Seeds per file for the library checks.
const SEEDS: u64 = 3;

// ---------------------------------------------------------------------------------------------
// Brute-force topology (docs/reference/anytop.md §2.4), independent of lib/skeleton/topology.rs.

fn check_topology(name: &str, skeleton: &Skeleton) {
    skeleton.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    let doc = SkeletonDocument::build(skeleton, None, name, topology::DEFAULT_DMAX);
    let parents = skeleton.parents();
    assert_eq!(doc.topology.relations, reference_relations(&parents), "{name}: R");
    assert_eq!(doc.topology.distances, reference_distances(&parents, topology::DEFAULT_DMAX), "{name}: D");
    let leaves: Vec<usize> = (0..parents.len()).filter(|j| !parents.contains(&Some(*j))).collect();
    assert_eq!(doc.topology.end_effectors, leaves, "{name}: end effectors");
}

// ---------------------------------------------------------------------------------------------
// Helpers

/// Evenly spaced frames of a clip (all of them when there are few).
fn sample_frames(bvh: &Bvh, max: usize) -> Bvh {
    if bvh.frames <= max {
        return bvh.clone();
    }
    let nc = bvh.channel_count();
    let mut out = bvh.clone();
    out.values = Vec::with_capacity(max * nc);
    for k in 0..max {
        let f = k * (bvh.frames - 1) / (max - 1);
        out.values.extend_from_slice(bvh.frame(f));
    }
    out.frames = max;
    out
}

/// World positions of every frame, and the size used for the tolerance: the largest extent
/// of frame 0's joints (what bvhfk calls height), or the rest pose's when there is no frame.
fn pose(bvh: &Bvh) -> (Skeleton, Vec<DVec3>, f64) {
    let s = Skeleton::from_bvh(bvh);
    let positions = Motion::from_bvh(bvh, &s).forward_kinematics(&s).positions;
    let size = if bvh.frames > 0 {
        let first = &positions[..s.len()];
        let lo = first.iter().fold(DVec3::splat(f64::INFINITY), |a, p| a.min(*p));
        let hi = first.iter().fold(DVec3::splat(f64::NEG_INFINITY), |a, p| a.max(*p));
        (hi - lo).max_element()
    } else {
        s.rest_extent()
    };
    (s, positions, size.max(1e-12))
}

/// Largest distance (relative to `size`) between a joint of `before` and the joint of the
/// same name in `after`, over all frames; joints of `before` missing in `after` are skipped.
fn worst_error(before: &(Skeleton, Vec<DVec3>, f64), after: &(Skeleton, Vec<DVec3>, f64)) -> f64 {
    let (s0, p0, size) = before;
    let (s1, p1, _) = after;
    let frames = p0.len() / s0.len();
    assert_eq!(p1.len() / s1.len(), frames, "frame count changed");
    let mut worst = 0.0f64;
    for (j, joint) in s0.joints.iter().enumerate() {
        let Some(k) = s1.index_of(&joint.name) else { continue };
        for f in 0..frames {
            worst = worst.max(p1[f * s1.len() + k].distance(p0[f * s0.len() + j]) / size);
        }
    }
    worst
}

/// Names of `s` in index order.
fn names(s: &Skeleton) -> Vec<&str> {
    s.joints.iter().map(|j| j.name.as_str()).collect()
}

/// What one file's checks measured.
#[derive(Default)]
struct Measured {
    worst_remove: f64,
    worst_add: f64,
    /// (file, joints, removable, min removed, max removed)
    removal: Vec<(String, usize, usize, usize, usize)>,
}

/// The library checks on one clip: removal and addition for a few seeds, each through BVH
/// text and back.
fn check_clip(name: &str, original: &Bvh, measured: &mut Measured) {
    let bvh = sample_frames(original, MAX_FRAMES);
    let before = pose(&bvh);
    let skeleton = &before.0;
    let n = skeleton.len();
    let unique: std::collections::BTreeSet<&str> = names(skeleton).into_iter().collect();
    assert_eq!(unique.len(), n, "{name}: joint names are not unique; the name-based checks need them");
    let feet = roles::feet(skeleton).0;
    let removable = augment::removable_chains(skeleton, true).iter().map(Vec::len).sum::<usize>();
    let (mut min_removed, mut max_removed) = (usize::MAX, 0);

    for seed in 0..SEEDS {
        // Removal with the default (random) rate.
        let mut rng = SplitMix64::new(seed);
        let plan = augment::plan(skeleton, &Options::default(), &mut rng);
        let text = bvh::write_string(&plan.apply_bvh(&bvh));
        let back = bvh::parse(&text, name).unwrap_or_else(|e| panic!("{name}: written BVH does not parse: {e}"));
        let after = pose(&back);
        assert_eq!(after.0, plan.skeleton, "{name}: written hierarchy differs from the plan's");
        let err = worst_error(&before, &after);
        assert!(err <= TOLERANCE, "{name} seed {seed}: removal moved a joint by {err:e} of the size");
        measured.worst_remove = measured.worst_remove.max(err);

        let removed = n - after.0.len();
        let report = plan.removal.as_ref().unwrap();
        assert_eq!(report.removed.len(), removed, "{name}");
        min_removed = min_removed.min(removed);
        max_removed = max_removed.max(removed);
        let fraction = removed as f64 / n as f64;
        if removable >= n.div_ceil(10) {
            assert!((0.1..=0.3).contains(&fraction), "{name} seed {seed}: removed {removed} of {n} ({fraction})");
        } else {
            assert_eq!(removed, removable, "{name} seed {seed}: a skeleton short of 10% loses every removable joint");
        }
        // Survivors keep their relative order; feet and the root survive, the root first.
        let kept: Vec<&str> = names(skeleton).into_iter().filter(|x| after.0.index_of(x).is_some()).collect();
        assert_eq!(kept, names(&after.0), "{name}: survivors changed order");
        assert_eq!(after.0.joints[0].name, skeleton.joints[0].name, "{name}: root");
        for &f in &feet {
            assert!(after.0.index_of(&skeleton.joints[f].name).is_some(), "{name}: foot {} removed", skeleton.joints[f].name);
        }
        // A joint that lost all its children is an end effector with an End Site.
        for (j, joint) in after.0.joints.iter().enumerate() {
            let was_leaf = skeleton.joints.iter().all(|c| c.parent != skeleton.index_of(&joint.name));
            let is_leaf = after.0.joints.iter().all(|c| c.parent != Some(j));
            if is_leaf && !was_leaf {
                assert!(!joint.end_sites.is_empty(), "{name}: new end effector {} has no End Site", joint.name);
            }
        }
        check_topology(name, &after.0);
        // The Motion path gives the same motion as the BVH path.
        let motion = plan.apply_motion(skeleton, &Motion::from_bvh(&bvh, skeleton));
        let fk = motion.forward_kinematics(&plan.skeleton).positions;
        let d = fk.iter().zip(&after.1).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max) / before.2;
        assert!(d <= TOLERANCE, "{name}: Motion and BVH paths differ by {d:e}");

        // Addition only: three joints, every original joint unmoved.
        let mut rng = SplitMix64::new(100 + seed);
        let options = Options { remove: None, add: 3, keep_feet: true };
        let plan = augment::plan(skeleton, &options, &mut rng);
        let back = bvh::parse(&bvh::write_string(&plan.apply_bvh(&bvh)), name).unwrap();
        let after = pose(&back);
        assert_eq!(after.0.len(), n + 3, "{name}");
        assert!(names(skeleton).iter().all(|x| after.0.index_of(x).is_some()), "{name}: addition lost a joint");
        let err = worst_error(&before, &after);
        assert!(err <= TOLERANCE, "{name} seed {seed}: addition moved a joint by {err:e} of the size");
        measured.worst_add = measured.worst_add.max(err);
        check_new_joints(name, &back, &after, &plan.added, before.2);
        check_topology(name, &after.0);

        // Both at once, with an explicit rate.
        let options = Options { remove: Some(RemoveAmount::Rate(0.3)), add: 2, keep_feet: true };
        let plan = augment::plan(skeleton, &options, &mut SplitMix64::new(200 + seed));
        let back = bvh::parse(&bvh::write_string(&plan.apply_bvh(&bvh)), name).unwrap();
        let after = pose(&back);
        let err = worst_error(&before, &after);
        assert!(err <= TOLERANCE, "{name}: remove + add moved a joint by {err:e}");
        assert_eq!(plan.added.len(), 2);
        check_topology(name, &after.0);
    }
    measured.removal.push((name.to_string(), n, removable, min_removed, max_removed));
}

/// New joints have identity rotation in every frame, no position channels, and sit at their
/// bone's midpoint in the rest pose (and in every frame when the split joint has no position
/// channels).
fn check_new_joints(name: &str, bvh: &Bvh, after: &(Skeleton, Vec<DVec3>, f64), added: &[augment::Added], size: f64) {
    let (s, positions, _) = after;
    let motion = Motion::from_bvh(bvh, s);
    let rest = s.rest_positions();
    for a in added {
        let m = s.index_of(&a.name).unwrap_or_else(|| panic!("{name}: new joint {} missing", a.name));
        let joint = &s.joints[m];
        assert!(joint.channels.iter().all(|c| c.is_rotation()), "{name}: {} has position channels", a.name);
        // The child may have been split again later, so find it by name.
        let c = s.index_of(&a.child).unwrap();
        let p = joint.parent.unwrap();
        let mid = 0.5 * (rest[p] + rest[c]);
        // Only exact when the child's rest bone was not re-split below the new joint.
        if s.joints[c].parent == Some(m) && s.joints[p].name == a.parent {
            assert!(rest[m].distance(mid) <= 1e-9 * size, "{name}: {} is not at its bone's rest midpoint", a.name);
        }
        for f in 0..motion.frames {
            let q = motion.rotations[f * s.len() + m];
            assert!(q.abs_diff_eq(glam::DQuat::IDENTITY, 1e-12) || q.abs_diff_eq(-glam::DQuat::IDENTITY, 1e-12), "{name}: {} rotates", a.name);
            if s.joints[c].parent == Some(m) && s.joints[c].channels.iter().all(|ch| ch.is_rotation()) && s.joints[p].name == a.parent {
                let mid = 0.5 * (positions[f * s.len() + p] + positions[f * s.len() + c]);
                assert!(positions[f * s.len() + m].distance(mid) <= TOLERANCE * size, "{name}: {} off its bone in frame {f}", a.name);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Binary helpers

fn ok(out: &std::process::Output, what: &str) -> Vec<u8> {
    assert!(out.status.success(), "{what}: {}", String::from_utf8_lossy(&out.stderr));
    out.stdout.clone()
}

/// The binary on one clip (given as BVH text on stdin): determinism, variants, and the JSON
/// path agreeing with the BVH path.
fn check_binary(name: &str, text: &[u8], validator: &jsonschema::Validator) {
    let a = ok(&common::run("skel-aug", &["--seed", "11", "--add", "2"], Some(text)), name);
    let b = ok(&common::run("skel-aug", &["--seed", "11", "--add", "2"], Some(text)), name);
    assert!(a == b, "{name}: the same seed gave different output");
    let out = bvh::parse_bytes(&a, name).unwrap_or_else(|e| panic!("{name}: output is not BVH: {e}"));

    // The skeleton document of the same clip gives the same skeleton, as a valid document.
    let original = bvh::parse_bytes(text, name).unwrap();
    let skeleton = Skeleton::from_bvh(&original);
    let doc = SkeletonDocument::build(&skeleton, None, name, 4);
    let json = serde_json::to_string(&doc).unwrap();
    let j = ok(&common::run("skel-aug", &["--seed", "11", "--add", "2"], Some(json.as_bytes())), name);
    let value: serde_json::Value = serde_json::from_slice(&j).unwrap_or_else(|e| panic!("{name}: output is not JSON: {e}"));
    let errors: Vec<String> = validator.iter_errors(&value).map(|e| format!("{} at {}", e, e.instance_path)).collect();
    assert!(errors.is_empty(), "{name}: schema errors: {errors:?}");
    let back = SkeletonDocument::from_json(std::str::from_utf8(&j).unwrap()).unwrap();
    assert_eq!(back.topology.dmax, 4, "{name}: dmax carried over");
    let from_json = back.skeleton().unwrap();
    assert_eq!(from_json, Skeleton::from_bvh(&out), "{name}: JSON and BVH paths chose different skeletons");
    let parents = from_json.parents();
    assert_eq!(back.topology.relations, reference_relations(&parents), "{name}: document R");
    assert_eq!(back.topology.distances, reference_distances(&parents, 4), "{name}: document D");
}

// ---------------------------------------------------------------------------------------------
// Tests

fn report(what: &str, files: usize, m: &Measured) {
    println!("{what}: {files} clips, worst position error {:.2e} (removal) / {:.2e} (addition) of the size", m.worst_remove, m.worst_add);
    for (file, n, removable, lo, hi) in &m.removal {
        let short = if *removable < n.div_ceil(10) { "  (cannot reach 10%: every removable joint taken)" } else { "" };
        println!(
            "  {file}: {n} joints, {removable} removable ({:.0}%), removed {lo}..{hi} ({:.1}%..{:.1}%){short}",
            100.0 * *removable as f64 / *n as f64,
            100.0 * *lo as f64 / *n as f64,
            100.0 * *hi as f64 / *n as f64
        );
    }
}

#[test]
fn corpus_augmentation_keeps_positions_and_topology() {
    let Some(data) = common::shared_data("corpus_augmentation_keeps_positions_and_topology") else { return };
    let files = common::corpus_bvh_files(&data);
    let validator = schema_validator();
    let mut m = Measured::default();
    for path in &files {
        let name = path.strip_prefix(&data).unwrap_or(path).display().to_string();
        let original = bvh::read_path(path).unwrap();
        check_clip(&name, &original, &mut m);
        // The binary sees a short excerpt (same skeleton, fewer frames) to keep this fast.
        let excerpt = bvh::write_string(&sample_frames(&original, 8));
        check_binary(&name, excerpt.as_bytes(), &validator);
    }
    report("corpus", files.len(), &m);
    assert!(m.worst_remove <= TOLERANCE && m.worst_add <= TOLERANCE);
}

#[test]
fn example_creatures_augmentation_keeps_positions_and_topology() {
    let files = common::example_bvh_files();
    assert!(files.len() >= 7, "examples/data should hold the synthetic zoo");
    let validator = schema_validator();
    let mut m = Measured::default();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let text = std::fs::read(path).unwrap();
        check_clip(&name, &bvh::parse_bytes(&text, &name).unwrap(), &mut m);
        check_binary(&name, &text, &validator);
    }
    report("examples", files.len(), &m);
}

#[test]
fn variants_are_numbered_reproducible_and_different() {
    let dir = tempdir("variants");
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/dragon.bvh");
    let pattern = dir.join("v_{i}.bvh");
    let args = [input.to_str().unwrap(), "-n", "4", "--add", "1", "--seed", "3", "-o", pattern.to_str().unwrap()];
    let out = common::run("skel-aug", &args, None);
    assert!(out.status.success() && out.stdout.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
    let variants: Vec<Vec<u8>> = (0..4).map(|i| std::fs::read(dir.join(format!("v_{i}.bvh"))).unwrap()).collect();
    let distinct: std::collections::BTreeSet<&Vec<u8>> = variants.iter().collect();
    assert!(distinct.len() >= 3, "variants should differ: {} distinct of 4", distinct.len());
    // Variant 0 is what a single run writes, whatever the count.
    let single = common::run("skel-aug", &[input.to_str().unwrap(), "--add", "1", "--seed", "3"], None);
    assert_eq!(ok(&single, "single"), variants[0]);
    // Another seed gives another skeleton.
    let other = common::run("skel-aug", &[input.to_str().unwrap(), "--add", "1", "--seed", "4"], None);
    assert_ne!(ok(&other, "other seed"), variants[0]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn verbose_names_what_changed_and_stdout_stays_bvh() {
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/biped.bvh");
    let out = common::run("skel-aug", &[input.to_str().unwrap(), "-v", "--remove-rate", "0.2", "--add", "1"], None);
    let stdout = ok(&out, "verbose");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("22 -> 19 joints") && err.contains("removed 4 (18.2%") && err.contains("added ") && err.contains("_mid between"), "{err}");
    let parsed = bvh::parse_bytes(&stdout, "stdout").unwrap();
    assert_eq!(parsed.joints.len(), 19);
    // Without -v: nothing on stderr.
    let out = common::run("skel-aug", &[input.to_str().unwrap()], None);
    assert!(out.status.success() && out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn skeletons_short_of_removable_joints_warn_and_feet_can_be_allowed() {
    let snake = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/snake.bvh");
    let snake = snake.to_str().unwrap();
    // The snake's whole body lies on the ground: every joint but the head is a foot.
    let out = common::run("skel-aug", &[snake], None);
    let stdout = ok(&out, "snake");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("warning") && err.contains("--allow-feet") && err.lines().count() == 1, "{err}");
    assert_eq!(bvh::parse_bytes(&stdout, "s").unwrap().joints.len(), 25);
    let out = common::run("skel-aug", &[snake, "-q"], None);
    assert!(out.status.success() && out.stderr.is_empty());
    // With --allow-feet the tail is shortened, the motion kept.
    let out = common::run("skel-aug", &[snake, "--allow-feet", "--remove-rate", "0.2"], None);
    let short = bvh::parse_bytes(&ok(&out, "snake --allow-feet"), "s").unwrap();
    assert_eq!(short.joints.len(), 20);
    let original = bvh::read_path(Path::new(snake)).unwrap();
    let err = worst_error(&pose(&original), &pose(&short));
    assert!(err <= TOLERANCE, "{err}");
}

const TINY: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 1 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\tJOINT Spine\n\t{\n\t\tOFFSET 0 0.2 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tJOINT Head\n\t\t{\n\t\t\tOFFSET 0 0.3 0\n\t\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 0 0.1 0\n\t\t\t}\n\t\t}\n\t}\n\tJOINT LeftFoot\n\t{\n\t\tOFFSET 0.1 -0.9 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t}\n\tJOINT RightFoot\n\t{\n\t\tOFFSET -0.1 -0.9 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n0 1 0 0 0 0 10 0 0 -10 0 0 0 0 0 0 0 0\n0 1 0.1 0 0 0 20 0 0 -20 0 0 0 0 0 0 0 0\n";

/// Run with a file output; require exit 2, one stderr line, and no file or temp file left.
fn fails_cleanly(args: &[&str], stdin: Option<&[u8]>, what: &str) -> String {
    let dir = tempdir(&format!("bad-{}", what.replace(' ', "-")));
    let target = dir.join("out.bvh");
    let mut full: Vec<&str> = args.to_vec();
    let t = target.to_str().unwrap().to_string();
    full.extend(["-o", &t]);
    let out = common::run("skel-aug", &full, stdin);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{what}: {err}");
    assert!(err.starts_with("skel-aug: ") && err.trim_end().lines().count() == 1, "{what}: {err:?}");
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "{what}: left files behind: {left:?}");
    assert!(out.stdout.is_empty(), "{what}: printed output");
    let _ = std::fs::remove_dir_all(&dir);
    err
}

#[test]
fn bad_input_exits_2_with_one_line_and_no_file() {
    let truncated = &TINY.as_bytes()[..TINY.len() - 30];
    let err = fails_cleanly(&["-"], Some(truncated), "truncated bvh");
    assert!(err.contains("<stdin>"), "{err}");
    fails_cleanly(&["-"], Some(b"HIERARCHY\nROOT a\n{\nOFFSET 0 0\n"), "bad offset");
    fails_cleanly(&["-"], Some(b""), "empty input");
    fails_cleanly(&["-"], Some(b"{\"format\": \"menagerie.skeleton\"}"), "incomplete document");
    fails_cleanly(&["-"], Some(b"{ not json"), "broken json");
    fails_cleanly(&["/nonexistent/input.bvh"], None, "missing file");
    for rate in ["0", "1", "1.5", "-0.2", "NaN", "inf"] {
        let err = fails_cleanly(&["-", "--remove-rate", rate], Some(TINY.as_bytes()), &format!("rate {rate}"));
        assert!(err.contains("--remove-rate"), "{err}");
    }
    // Several variants need '{i}' in the output path: checked before anything is written.
    let err = fails_cleanly(&["-", "-n", "2"], Some(TINY.as_bytes()), "two variants one path");
    assert!(err.contains("{i}"), "{err}");
    let out = common::run("skel-aug", &["-", "-n", "2"], Some(TINY.as_bytes()));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code() == Some(2) && out.stdout.is_empty() && err.contains("{i}") && err.trim_end().lines().count() == 1, "{err}");
    // Usage errors from clap also exit 2.
    for args in [&["--no-remove", "--remove-rate", "0.2"][..], &["-n", "0"], &["--add", "x"]] {
        let out = common::run("skel-aug", args, Some(TINY.as_bytes()));
        assert_eq!(out.status.code(), Some(2), "{args:?}");
    }
}

#[test]
fn tiny_skeleton_by_hand() {
    // Feet and the root are protected and Spine has one child: the only removable chain is
    // Head, Spine; a 20% rate (1 joint) cuts Head, and Spine becomes an end effector whose End
    // Site is where Head was.
    let out = common::run("skel-aug", &["-", "--remove-rate", "0.2", "--seed", "1"], Some(TINY.as_bytes()));
    let b = bvh::parse_bytes(&ok(&out, "tiny"), "tiny").unwrap();
    let s = Skeleton::from_bvh(&b);
    assert_eq!(names(&s), ["Hips", "Spine", "LeftFoot", "RightFoot"]);
    assert_eq!(s.joints[1].end_sites, vec![DVec3::new(0.0, 0.3, 0.0)]);
    assert_eq!(
        b.values,
        vec![
            0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.1, 0.0, 0.0, 0.0, 20.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
            0.0
        ]
    );
    // Splitting: the only bones are Spine, Head, LeftFoot, RightFoot; each split halves one.
    let out = common::run("skel-aug", &["-", "--no-remove", "--add", "1", "--seed", "2"], Some(TINY.as_bytes()));
    let b = bvh::parse_bytes(&ok(&out, "tiny add"), "tiny").unwrap();
    let s = Skeleton::from_bvh(&b);
    let m = s.joints.iter().position(|j| j.name.ends_with("_mid")).expect("a new joint");
    let child = &s.joints[m + 1];
    assert_eq!(child.parent, Some(m));
    assert_eq!(format!("{}_mid", child.name), s.joints[m].name);
    assert_eq!(s.joints[m].offset, child.offset);
    assert_eq!(s.joints[m].channels.len(), 3);
    assert_eq!(b.frame(0)[b.channel_starts()[m]..b.channel_starts()[m] + 3], [0.0, 0.0, 0.0]);
}
