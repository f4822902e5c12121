//! glTF in and out through the tools: BVH -> GLB -> BVH keeps every joint's world position (the
//! bundled creatures and the real corpus), tools read `.glb`/`.gltf` wherever they read BVH and
//! write it where the output path says so, and malformed glTF gets a one-line error, exit 2.

use crate::common::{self, check_failure, ok, run, s, tempdir};
use menagerie::cli::load::parse_motion;
use menagerie::motion::Motion;
use menagerie::skeleton::Skeleton;
use std::path::Path;

/// The worst joint position difference over all frames, in units of the skeleton's height.
fn max_error(a: (&Skeleton, &Motion), b: (&Skeleton, &Motion)) -> f64 {
    assert_eq!(a.1.frames, b.1.frames, "frame counts");
    assert_eq!(a.0.joints.len(), b.0.joints.len(), "joint counts");
    let (pa, pb) = (a.1.forward_kinematics(a.0), b.1.forward_kinematics(b.0));
    let worst = pa.positions.iter().zip(&pb.positions).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max);
    worst / a.0.rest_height().max(1e-12)
}

/// BVH file -> GLB bytes -> the BVH the loader makes of it -> BVH text -> parsed again.
fn bvh_glb_bvh(path: &Path) -> f64 {
    let (skeleton, motion) = common::load(path);
    let glb = menagerie::gltf::write_glb(&skeleton, &motion, "t.glb").unwrap();
    let back = parse_motion(&glb, "t.glb", Path::new("t.glb")).unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
    let text = menagerie::bvh::write_string(&back);
    let reparsed = menagerie::bvh::parse(&text, "back.bvh").unwrap();
    let s2 = Skeleton::from_bvh(&reparsed);
    let m2 = Motion::from_bvh(&reparsed, &s2);
    for (a, b) in skeleton.joints.iter().zip(&s2.joints) {
        assert_eq!((&a.name, a.parent), (&b.name, b.parent), "{}", path.display());
    }
    max_error((&skeleton, &motion), (&s2, &m2))
}

#[test]
fn bundled_creatures_survive_bvh_glb_bvh() {
    for path in common::example_bvh_files() {
        let err = bvh_glb_bvh(&path);
        eprintln!("{}: max joint error {err:.2e} of height", path.display());
        assert!(err < 1e-5, "{}: {err}", path.display());
    }
}

#[test]
fn corpus_survives_bvh_glb_bvh() {
    let Some(data) = common::shared_data("corpus_survives_bvh_glb_bvh") else { return };
    let mut worst = (0.0, String::new());
    for path in common::corpus_bvh_files(&data) {
        let err = bvh_glb_bvh(&path);
        assert!(err < 1e-5, "{}: {err}", path.display());
        if err > worst.0 {
            worst = (err, path.display().to_string());
        }
    }
    eprintln!("corpus BVH -> GLB -> BVH: worst joint error {:.2e} of height ({})", worst.0, worst.1);
}

#[test]
fn tools_read_and_write_gltf() {
    let dir = tempdir("gltf-tools");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data");
    let quad = data.join("quadruped.bvh");
    let dragon = data.join("dragon.bvh");

    // BVH -> GLB and glTF with the no-op augmentation: the extension decides.
    let glb = dir.join("quad.glb");
    let gltf = dir.join("quad.gltf");
    for out in [&glb, &gltf] {
        ok(&run("skel-aug", &[s(&quad), "--no-remove", "-o", s(out)], None), "skel-aug -o glTF");
    }
    assert!(std::fs::read(&glb).unwrap().starts_with(b"glTF"));
    assert!(std::fs::read(&gltf).unwrap().starts_with(b"{"));

    // skel-info gives the same skeleton from BVH, GLB, glTF and glTF on stdin.
    let doc = |args: &[&str], stdin: Option<&[u8]>| {
        let out = run("skel-info", args, stdin);
        ok(&out, "skel-info");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (v["joints"].clone(), v["rest_pose"].clone())
    };
    let from_bvh = doc(&[s(&quad)], None);
    assert_eq!(from_bvh.0.as_array().map(Vec::len), doc(&[s(&glb)], None).0.as_array().map(Vec::len));
    let names = |j: &serde_json::Value| j.as_array().unwrap().iter().map(|x| x["name"].clone()).collect::<Vec<_>>();
    assert_eq!(names(&from_bvh.0), names(&doc(&[s(&gltf)], None).0));
    assert_eq!(names(&from_bvh.0), names(&doc(&["-"], Some(&std::fs::read(&glb).unwrap())).0));

    // Directories pick up .glb files; mo-render and mo-metrics read them.
    let clips = dir.join("clips");
    std::fs::create_dir_all(&clips).unwrap();
    std::fs::copy(&glb, clips.join("a.glb")).unwrap();
    ok(&run("mo-metrics", &["physics", s(&clips)], None), "mo-metrics physics on a folder of GLB");
    ok(&run("mo-render", &[s(&glb), "--sheet", s(&dir.join("sheet.png")), "--frames", "0:8"], None), "mo-render GLB");

    // mo-retarget: GLB source in, GLB out (file by extension, stdout by --format).
    let out = dir.join("quad_as_dragon.glb");
    ok(&run("mo-retarget", &[s(&glb), s(&dragon), "--bind", "auto", "--frames", "24", "-o", s(&out)], None), "mo-retarget -o x.glb");
    let (s1, m1) = menagerie::gltf::read(&std::fs::read(&out).unwrap(), "x", None, &Default::default()).unwrap();
    assert_eq!(s1.joints.len(), common::load(&dragon).0.joints.len());
    assert_eq!(m1.frames, 24);
    let piped = run("mo-retarget", &[s(&glb), s(&dragon), "--bind", "auto", "--frames", "24", "--format", "glb"], None);
    ok(&piped, "mo-retarget --format glb");
    assert_eq!(piped.stdout, std::fs::read(&out).unwrap(), "the same bytes on stdout and in the file");

    // mo-sample --examples writes GLB samples.
    let pattern = dir.join("gen_{i}.glb");
    ok(&run("mo-sample", &["--examples", s(&glb), "-n", "2", "--seconds", "1", "--bvh", s(&pattern)], None), "mo-sample --examples GLB");
    for i in 0..2 {
        let bytes = std::fs::read(dir.join(format!("gen_{i}.glb"))).unwrap();
        assert!(menagerie::gltf::read(&bytes, "g", None, &Default::default()).is_ok());
    }

    // mo-encode decodes to GLB.
    let npy = dir.join("quad.npy");
    let json = dir.join("quad.json");
    ok(&run("mo-encode", &[s(&glb), "--emit-skeleton", s(&json), "-o", s(&npy)], None), "mo-encode a GLB");
    ok(&run("mo-encode", &["--decode", "--skeleton", s(&json), s(&npy), "-o", s(&dir.join("back.glb"))], None), "mo-encode --decode -o GLB");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn animation_and_fps_options() {
    let dir = tempdir("gltf-options");
    let glb = dir.join("b.glb");
    let bvh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/biped.bvh");
    ok(&run("skel-aug", &[s(&bvh), "--no-remove", "-o", s(&glb)], None), "to GLB");
    let frames = |args: &[&str]| {
        let out = run("skel-info", args, None);
        ok(&out, "skel-info");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["motion"]["frames"].as_u64().unwrap()
    };
    let all = frames(&[s(&glb)]);
    assert_eq!(all, frames(&[s(&glb), "--animation", "motion"]));
    assert_eq!(all, frames(&[s(&glb), "--animation", "0"]));
    let fps = common::load(&bvh).1.frame_time.recip() / 2.0;
    assert_eq!(frames(&[s(&glb), "--fps", &fps.to_string()]), (all - 1) / 2 + 1);
    let out = run("skel-info", &[s(&glb), "--animation", "run"], None);
    check_failure("skel-info", "unknown animation", &out, "no animation named 'run' (it has 'motion')");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn malformed_gltf_is_one_line_exit_2() {
    let dir = tempdir("gltf-malformed");
    let bvh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/snake.bvh");
    let glb = dir.join("snake.glb");
    ok(&run("skel-aug", &[s(&bvh), "--no-remove", "-o", s(&glb)], None), "to GLB");
    let good = std::fs::read(&glb).unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let cases: Vec<(std::path::PathBuf, &str)> = vec![
        (write("cut.glb", &good[..good.len() / 2]), "cut.glb: "),
        (write("empty.glb", b""), "empty.glb: "),
        (write("text.gltf", b"{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"name\": \"a\"}]}"), "text.gltf: no skin: expected a skinned armature"),
        (write("bad.gltf", b"{\"asset\": {\"version\": \"2.0\"}, \"skins\": [{\"joints\": [7]}]}"), "bad.gltf: invalid glTF"),
        (write("broken.gltf", b"{\"asset\": "), "broken.gltf: not a readable glTF file"),
        (write("junk.glb", b"glTF\x02\x00\x00\x00\xff\xff\xff\xff"), "junk.glb: "),
    ];
    for (path, expect) in &cases {
        for tool in ["skel-info", "mo-metrics"] {
            let args: Vec<&str> = if tool == "mo-metrics" { vec!["physics", s(path)] } else { vec![s(path)] };
            check_failure(tool, &format!("{tool} {}", path.display()), &run(tool, &args, None), expect);
        }
    }
    // No partial output: a failed conversion leaves no file.
    let out = dir.join("never.glb");
    check_failure("mo-retarget", "bad source", &run("mo-retarget", &[s(&cases[0].0), s(&bvh), "--bind", "auto", "-o", s(&out)], None), "cut.glb: ");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A GLB written by Blender 3.4's own exporter (tools/blender_export_gltf.py on the first 12
/// frames of the bundled quadruped): rest rotations on every bone, translation and scale keys
/// on every bone, f32 noise. Its joints must land where the BVH's do.
#[test]
fn reads_a_blender_export() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(root.join("tests/fixtures/quadruped_blender34.glb")).unwrap();
    let parsed = parse_motion(&bytes, "blender.glb", Path::new("blender.glb")).unwrap();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    let (s0, m0) = common::load(&root.join("examples/data/quadruped.bvh"));
    let m0 = m0.first_frames(12);
    assert_eq!(motion.frames, 12);
    assert!((skeleton.frame_time - s0.frame_time).abs() < 1e-6);
    assert!(skeleton.joints.iter().all(|j| j.channels.len() == if j.parent.is_none() { 6 } else { 3 }), "rest-valued translation keys are not motion");
    let (p, p0) = (motion.forward_kinematics(&skeleton), m0.forward_kinematics(&s0));
    let mut worst: f64 = 0.0;
    for (j, joint) in skeleton.joints.iter().enumerate() {
        let k = s0.joints.iter().position(|x| x.name == joint.name).unwrap_or_else(|| panic!("joint {}", joint.name));
        for f in 0..12 {
            worst = worst.max(p.position(f, j).distance(p0.position(f, k)));
        }
    }
    assert_eq!(skeleton.joints.len(), s0.joints.len());
    let err = worst / s0.rest_height();
    assert!(err < 1e-5, "{err}");
}
