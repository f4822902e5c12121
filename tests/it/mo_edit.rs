//! `mo-edit` end to end, through the binary and the files it writes, one known answer per
//! subcommand:
//!
//! * resample 30 -> 60 -> 30 gives the clip back; mirror twice gives the input back (1e-9 of
//!   the size through two BVH files), and once puts each joint at its partner's reflected place;
//! * trim keeps B - A + 1 frames; a clip trimmed at 0:N and N: and concatenated is the clip;
//! * a loop's seam step lies within the clip's own frame-to-frame range;
//! * axis y-up -> z-up is (x, y, z) -> (x, -z, y), and z-up -> y-up -> z-up is the identity;
//! * rest --frame N leaves every world position where it was (1e-9 of the size);
//! * scale, in-place, root, rename do what they say; a glTF goes through an edit and back;
//! * foot-lock lowers `mo-metrics physics` foot skating of a retargeted clip, and moves no
//!   joint outside the locked legs;
//! * bad input: one line, exit 2, nothing written.

use crate::common::{self, check_failure, ok, run, s, tempdir};
use glam::DVec3;
use menagerie::motion::Motion;
use menagerie::skeleton::Skeleton;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

/// Run `mo-edit` and require success; its stdout.
fn edit(args: &[&str], stdin: Option<&[u8]>) -> Vec<u8> {
    let out = run("mo-edit", args, stdin);
    ok(&out, &format!("mo-edit {args:?}"));
    out.stdout
}

fn parse(bytes: &[u8]) -> (Skeleton, Motion) {
    let parsed = menagerie::bvh::parse_bytes(bytes, "stdout").unwrap_or_else(|e| panic!("{e}"));
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    (skeleton, motion)
}

fn positions(clip: &(Skeleton, Motion)) -> Vec<DVec3> {
    clip.1.forward_kinematics(&clip.0).positions
}

/// Largest distance between corresponding world positions, as a fraction of `a`'s size.
fn worst(a: &(Skeleton, Motion), b: &(Skeleton, Motion)) -> f64 {
    let (pa, pb) = (positions(a), positions(b));
    assert_eq!(pa.len(), pb.len(), "frame or joint counts differ");
    pa.iter().zip(&pb).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max) / a.0.rest_extent()
}

#[test]
fn resample_there_and_back_gives_the_clip() {
    let biped = example("biped.bvh");
    let original = common::load(&biped);
    let up = edit(&["resample", s(&biped), "--fps", "60"], None);
    let fast = parse(&up);
    assert_eq!(fast.1.frames, 2 * original.1.frames - 1);
    assert!((fast.1.frame_time - 1.0 / 60.0).abs() < 1e-15);
    let back = parse(&edit(&["resample", "-", "--fps", "30"], Some(&up)));
    assert_eq!(back.1.frames, original.1.frames);
    let e = worst(&original, &back);
    assert!(e < 1e-9, "30 -> 60 -> 30 moved a joint by {e} of the size");
    let out = run("mo-edit", &["resample", s(&biped)], None);
    check_failure("mo-edit", "resample without --fps", &out, "--fps");
}

#[test]
fn mirror_twice_is_the_identity_and_once_reflects() {
    for name in ["biped.bvh", "spider.bvh", "crab.bvh"] {
        let path = example(name);
        let plain = edit(&["convert", s(&path)], None);
        let once = edit(&["mirror", s(&path)], None);
        let twice = edit(&["mirror", "-"], Some(&once));
        // Exact in the library (its unit test); through two BVH files, Euler angles round.
        let e = worst(&parse(&plain), &parse(&twice));
        assert!(e < 1e-9, "{name}: mirror twice moved a joint by {e} of the size");
        // Once: every joint stands where its partner stood, reflected across x = 0.
        let (a, b) = (parse(&plain), parse(&once));
        let (partner, lateral) = menagerie::edit::space::partners(&a.0).unwrap();
        let (pa, pb) = (a.1.forward_kinematics(&a.0), b.1.forward_kinematics(&b.0));
        let mut err = 0.0f64;
        for f in 0..a.1.frames {
            for j in 0..a.0.len() {
                let mut want = pa.position(f, partner[j]);
                want[lateral] = -want[lateral];
                err = err.max(pb.position(f, j).distance(want));
            }
        }
        assert!(err < 1e-6 * a.0.rest_extent(), "{name}: reflection off by {err}");
    }
    let out = run("mo-edit", &["mirror", s(&example("snake.bvh"))], None);
    check_failure("mo-edit", "mirror without sides", &out, "snake.bvh: no joint has a side");
}

#[test]
fn trim_keeps_the_range_and_refuses_ranges_past_the_end() {
    let biped = example("biped.bvh");
    let n = common::load(&biped).1.frames;
    assert_eq!(parse(&edit(&["trim", s(&biped), "--frames", "10:40"], None)).1.frames, 31);
    assert_eq!(parse(&edit(&["trim", s(&biped), "--seconds", "0.5:1.5"], None)).1.frames, 31);
    assert_eq!(parse(&edit(&["trim", s(&biped), "--frames", "90:"], None)).1.frames, n - 90);
    let past = format!("0:{n}");
    let out = run("mo-edit", &["trim", s(&biped), "--frames", &past], None);
    check_failure("mo-edit", "trim past the end", &out, "past the end");
    let out = run("mo-edit", &["trim", s(&biped), "--frames", "20:10"], None);
    check_failure("mo-edit", "empty trim", &out, "empty");
}

#[test]
fn a_clip_cut_in_two_concatenates_back_to_itself() {
    let dir = tempdir("mo-edit-concat");
    for name in ["biped.bvh", "quadruped.bvh"] {
        let path = example(name);
        let original = common::load(&path);
        let (a, b) = (dir.join("a.bvh"), dir.join("b.bvh"));
        edit(&["trim", s(&path), "--frames", "0:40", "-o", s(&a)], None);
        edit(&["trim", s(&path), "--frames", "40:", "-o", s(&b)], None);
        for blend in ["0", "0.2"] {
            let joined = parse(&edit(&["concat", s(&a), s(&b), "--blend", blend], None));
            let e = worst(&original, &joined);
            assert!(e < 1e-9, "{name} --blend {blend}: joined clip off by {e} of the size");
        }
    }
    let out = run("mo-edit", &["concat", s(&example("biped.bvh")), s(&example("quadruped.bvh"))], None);
    check_failure("mo-edit", "concat of two skeletons", &out, "different skeletons");
}

/// Joint positions relative to the root's ground position and heading, per frame.
fn body_frame(clip: &(Skeleton, Motion)) -> Vec<Vec<DVec3>> {
    let pose = clip.1.forward_kinematics(&clip.0);
    (0..clip.1.frames)
        .map(|f| {
            let root = pose.position(f, 0);
            let forward = pose.rotations[f * pose.joints] * DVec3::Z;
            let heading = glam::DQuat::from_rotation_y(-forward.x.atan2(forward.z));
            pose.frame_positions(f).iter().map(|p| heading * (*p - DVec3::new(root.x, 0.0, root.z))).collect()
        })
        .collect()
}

fn step(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max)
}

#[test]
fn a_loop_seam_steps_like_the_clip_does() {
    for name in ["biped.bvh", "quadruped.bvh"] {
        let path = example(name);
        let original = common::load(&path);
        let body = body_frame(&original);
        let steps: Vec<f64> = body.windows(2).map(|w| step(&w[0], &w[1])).collect();
        let (lo, hi) = steps.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        let raw_seam = step(&body[body.len() - 1], &body[0]);
        let looped = parse(&edit(&["loop", s(&path), "--blend", "0.3"], None));
        assert_eq!(looped.1.frames, original.1.frames - 1);
        let lb = body_frame(&looped);
        let seam = step(&lb[lb.len() - 1], &lb[0]);
        eprintln!("{name}: loop seam step {seam:.5} (before {raw_seam:.5}); the clip's steps {lo:.5}..{hi:.5}");
        assert!(seam <= hi, "{name}: seam step {seam} beyond the clip's largest {hi}");
    }
}

#[test]
fn axis_there_and_back_is_the_identity() {
    let dragon = example("dragon.bvh");
    let original = common::load(&dragon);
    let z_up_bytes = edit(&["axis", s(&dragon), "--from", "y-up", "--to", "z-up"], None);
    let z_up = parse(&z_up_bytes);
    for (p, q) in positions(&original).iter().zip(positions(&z_up)) {
        assert!(q.distance(DVec3::new(p.x, -p.z, p.y)) < 1e-9 * original.0.rest_extent());
    }
    let y_up = edit(&["axis", "-", "--from", "z-up", "--to", "y-up"], Some(&z_up_bytes));
    // Spelled out: z-up facing -y is Blender's convention, the default for z-up.
    let again = parse(&edit(&["axis", "-", "--from", "y", "--to", "z-up", "--from-forward", "z", "--to-forward", "-y"], Some(&y_up)));
    let e = worst(&z_up, &again);
    assert!(e < 1e-9, "z-up -> y-up -> z-up moved a joint by {e} of the size");
    let out = run("mo-edit", &["axis", s(&dragon), "--from", "y-up", "--to", "z-up", "--to-forward", "z"], None);
    check_failure("mo-edit", "forward along up", &out, "forward axis");
}

#[test]
fn rest_from_a_frame_keeps_the_world_motion() {
    for name in ["biped.bvh", "spider.bvh", "bird.bvh"] {
        let path = example(name);
        let original = common::load(&path);
        let rested = parse(&edit(&["rest", s(&path), "--frame", "17"], None));
        let e = worst(&original, &rested);
        assert!(e < 1e-9, "{name}: rest --frame moved a joint by {e} of the size");
        assert_ne!(rested.0.joints[5].offset, original.0.joints[5].offset, "{name}: the rest pose did not change");
    }
    let out = run("mo-edit", &["rest", s(&example("biped.bvh")), "--frame", "100000"], None);
    check_failure("mo-edit", "rest past the end", &out, "past the end");
}

#[test]
fn scale_in_place_root_and_rename() {
    let biped = example("biped.bvh");
    let original = common::load(&biped);
    let big = parse(&edit(&["scale", s(&biped), "--to-units", "cm"], None));
    for (p, q) in positions(&original).iter().zip(positions(&big)) {
        assert!((*p * 100.0).distance(q) < 1e-9);
    }
    let still = parse(&edit(&["in-place", s(&biped)], None));
    let root: Vec<DVec3> = (0..still.1.frames).map(|f| still.1.translations[f * still.1.joints]).collect();
    assert!(root.iter().all(|t| (t.x, t.z) == (root[0].x, root[0].z)));
    // Walking the still clip along the original's own path gives the original back.
    let dir = tempdir("mo-edit-root");
    let still_path = dir.join("still.bvh");
    edit(&["in-place", s(&biped), "-o", s(&still_path)], None);
    let walked = parse(&edit(&["root", s(&still_path), "--path", s(&biped)], None));
    assert!(worst(&original, &walked) < 1e-9);
    let renamed = parse(&edit(&["rename", s(&biped), "--normalise"], None));
    assert_eq!(renamed.0.joints[0].name, "Hips");
    let map = dir.join("map.txt");
    std::fs::write(&map, "mixamorig:Hips Pelvis\nLeftFoot\tFoot L\n").unwrap();
    let mapped = parse(&edit(&["rename", s(&biped), "--map", s(&map)], None));
    assert_eq!(mapped.0.joints[0].name, "Pelvis");
    assert!(mapped.0.joints.iter().any(|j| j.name == "Foot L"));
    std::fs::write(&map, "NoSuchBone Pelvis\n").unwrap();
    let out = run("mo-edit", &["rename", s(&biped), "--map", s(&map)], None);
    check_failure("mo-edit", "rename of an unknown joint", &out, "NoSuchBone");
}

#[test]
fn gltf_in_edit_gltf_out_and_back() {
    // The "to Blender and back" round: BVH -> GLB, an edit in glTF, GLB -> BVH.
    let dir = tempdir("mo-edit-gltf");
    let biped = example("biped.bvh");
    let (glb, trimmed, bvh) = (dir.join("biped.glb"), dir.join("trimmed.glb"), dir.join("back.bvh"));
    edit(&["convert", s(&biped), "-o", s(&glb)], None);
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");
    edit(&["trim", s(&glb), "--frames", "10:50", "-o", s(&trimmed)], None);
    edit(&["convert", s(&trimmed), "-o", s(&bvh)], None);
    let want = parse(&edit(&["trim", s(&biped), "--frames", "10:50"], None));
    let e = worst(&want, &common::load(&bvh));
    assert!(e < 1e-5, "BVH -> GLB -> trim -> BVH off by {e} of the size");
    let npy = edit(&["convert", s(&biped), "--format", "npy"], None);
    assert_eq!(&npy[..6], b"\x93NUMPY");
    let out = run("mo-edit", &["convert", s(&dir.join("missing.glb"))], None);
    check_failure("mo-edit", "missing input", &out, "missing.glb");
}

#[test]
fn foot_lock_lowers_skating_of_a_retargeted_clip() {
    let dir = tempdir("mo-edit-foot-lock");
    let retargeted = dir.join("quadruped.bvh");
    let out = run("mo-retarget", &[s(&example("biped.bvh")), s(&example("quadruped.bvh")), "--bind", "auto", "-o", s(&retargeted)], None);
    ok(&out, "mo-retarget");
    let locked = dir.join("locked.bvh");
    let report = run("mo-edit", &["foot-lock", s(&retargeted), "-v", "-o", s(&locked)], None);
    ok(&report, "foot-lock");
    eprintln!("{}", String::from_utf8_lossy(&report.stderr));
    let skating = |p: &Path| -> f64 {
        let out = run("mo-metrics", &["physics", s(p)], None);
        ok(&out, "mo-metrics physics");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let clip = &v["files"][0];
        clip["foot_skating"]["normalised"].as_f64().unwrap_or_else(|| panic!("no skating in {v}"))
    };
    let (before, after) = (skating(&retargeted), skating(&locked));
    eprintln!("foot skating (sizes/s): {before:.4} -> {after:.4}");
    assert!(after < before, "foot-lock did not lower skating: {before} -> {after}");
    // The same input gives the same bytes.
    let again = edit(&["foot-lock", s(&retargeted)], None);
    assert!(again == std::fs::read(&locked).unwrap());
    let out = run("mo-edit", &["foot-lock", s(&example("fish.bvh"))], None);
    check_failure("mo-edit", "foot-lock without feet", &out, "no feet");
}
