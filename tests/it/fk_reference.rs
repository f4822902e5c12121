//! Forward kinematics against an independent implementation: `../shared/tools/bvhfk.py`, a
//! numpy BVH reader + FK written outside this project (it agrees with Blender's importer to
//! ~3e-6 of height). Position channels replace the joint's OFFSET in both.
//!
//! * `handmade_fixture_matches_our_fk` always runs: a small BVH written by hand below (8 joints,
//!   Euler orders ZXY, XYZ and YZX, 6 channels on two joints, a 4-channel joint with a lone
//!   Yposition, two End Sites, 3 frames of large angles)
//!   and bvhfk's positions for it, computed once and kept in `tests/fixtures/fk_handmade.json`.
//! * The other tests run bvhfk through `tests/tools/fk_dump.py` and need python3 with numpy
//!   (`python3 -m pip install numpy`) and the `../shared` folder; they print a SKIP line and
//!   pass when either is missing. `MENAGERIE_PYTHON` picks another interpreter.
//! * `MENAGERIE_REGEN_FIXTURES=1` rewrites the handmade fixture from bvhfk (only needed if the
//!   handmade BVH below is changed).
use crate::common;

use menagerie::bvh;
use menagerie::bvh::Channel;
use menagerie::motion::{Motion, WorldPose};
use menagerie::skeleton::Skeleton;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Worst allowed |ours - bvhfk| / height on the corpus.
const CORPUS_TOLERANCE: f64 = 1e-4;
/// Worst allowed |ours - fixture| / height on the handmade file.
const FIXTURE_TOLERANCE: f64 = 1e-9;

const FIXTURE: &str = "tests/fixtures/fk_handmade.json";

/// Written for this test. Rotation orders: Root ZXY, Spine XYZ, Neck YZX (with positions),
/// Head ZXY, ArmL YZX, HandL ZXY after a lone Yposition, Tail XYZ, TailTip YZX.
const HANDMADE_BVH: &str = "HIERARCHY
ROOT Root
{
  OFFSET 1.5 90.25 -3.75
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0.5 12.0 -1.25
    CHANNELS 3 Xrotation Yrotation Zrotation
    JOINT Neck
    {
      OFFSET 0.0 20.0 2.5
      CHANNELS 6 Xposition Yposition Zposition Yrotation Zrotation Xrotation
      JOINT Head
      {
        OFFSET 0.25 9.5 1.0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0.0 11.0 3.0
        }
      }
    }
    JOINT ArmL
    {
      OFFSET 8.0 17.5 -0.5
      CHANNELS 3 Yrotation Zrotation Xrotation
      JOINT HandL
      {
        OFFSET 24.0 -1.5 0.75
        CHANNELS 4 Yposition Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 7.5 0.0 -2.0
        }
      }
    }
  }
  JOINT Tail
  {
    OFFSET -0.75 -4.0 -10.0
    CHANNELS 3 Xrotation Yrotation Zrotation
    JOINT TailTip
    {
      OFFSET 0.0 -2.5 -15.5
      CHANNELS 3 Yrotation Zrotation Xrotation
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 0 0 0 0 0 0 0 0 0 20 2.5 0 0 0 0 0 0 0 0 0 -1.5 0 0 0 0 0 0 0 0 0
12.5 88.0 -7.25 35.0 -20.5 110.0 15.0 -40.0 65.0 1.25 19.0 3.5 -75.0 30.0 45.0 100.0 -60.5 170.0 -95.0 25.0 130.0 -2.75 -30.0 88.5 -150.0 10.0 -45.0 60.0 120.0 -80.0 33.3
-31.75 95.5 14.0 -178.5 89.5 -45.25 -120.0 179.0 -5.5 -0.5 21.25 1.0 160.0 -89.0 12.0 -33.0 91.0 -135.75 48.5 -170.0 -12.25 -0.25 75.0 -91.0 5.5 -135.0 70.0 -17.5 -66.6 99.9 -179.9
";

/// What `fk_dump.py` prints for one file.
#[derive(Debug, Deserialize)]
struct RefFile {
    path: String,
    #[serde(default)]
    error: Option<String>,
    #[serde(default)]
    names: Vec<String>,
    #[serde(default)]
    frames: usize,
    #[serde(default)]
    height: Option<f64>,
    #[serde(default)]
    sampled: Vec<usize>,
    #[serde(default)]
    positions: Vec<Vec<[f64; 3]>>,
}

#[derive(Debug, Deserialize)]
struct RefDump {
    files: Vec<RefFile>,
}

/// The committed fixture: the handmade BVH and bvhfk's world positions for all its frames.
#[derive(Debug, Serialize, Deserialize)]
struct Fixture {
    about: String,
    bvh: String,
    names: Vec<String>,
    height: f64,
    positions: Vec<Vec<[f64; 3]>>,
}

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The interpreter and bvhfk's folder, or `None` after printing why the test is skipped.
fn reference_python(test: &str) -> Option<(String, PathBuf)> {
    let tools = manifest().join("../shared/tools");
    if !tools.join("bvhfk.py").is_file() {
        common::skip(test, "../shared/tools/bvhfk.py is absent");
        return None;
    }
    let python = std::env::var("MENAGERIE_PYTHON").unwrap_or_else(|_| "python3".to_string());
    match Command::new(&python).args(["-c", "import numpy"]).output() {
        Ok(out) if out.status.success() => Some((python, tools)),
        Ok(_) => {
            common::skip(test, &format!("{python} has no numpy (python3 -m pip install numpy)"));
            None
        }
        Err(e) => {
            common::skip(test, &format!("cannot run {python}: {e}"));
            None
        }
    }
}

/// Run `fk_dump.py` on `files` in one Python process.
fn fk_dump(python: &str, tools: &Path, frames: &str, files: &[PathBuf]) -> Vec<RefFile> {
    let script = manifest().join("tests/tools/fk_dump.py");
    let out = Command::new(python).arg(&script).arg("--bvhfk").arg(tools).args(["--frames", frames]).args(files).output().expect("run fk_dump.py");
    assert!(out.status.success(), "fk_dump.py failed ({}): {}", out.status, String::from_utf8_lossy(&out.stderr));
    let dump: RefDump = serde_json::from_slice(&out.stdout).expect("fk_dump.py output is JSON");
    assert_eq!(dump.files.len(), files.len(), "fk_dump.py answered for every file");
    dump.files
}

fn our_fk(text: &[u8], name: &str) -> (Skeleton, WorldPose) {
    let parsed = bvh::parse_bytes(text, name).unwrap_or_else(|e| panic!("{e}"));
    let skeleton = Skeleton::from_bvh(&parsed);
    let world = Motion::from_bvh(&parsed, &skeleton).forward_kinematics(&skeleton);
    (skeleton, world)
}

/// Largest |ours - reference| / height over the given frames, with where it happened.
fn worst_error(
    name: &str,
    skeleton: &Skeleton,
    ours: &WorldPose,
    names: &[String],
    frames: &[usize],
    positions: &[Vec<[f64; 3]>],
    height: f64,
) -> (f64, usize, usize) {
    let our_names: Vec<&str> = skeleton.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(our_names, names, "{name}: joint names / order differ from bvhfk");
    assert_eq!(frames.len(), positions.len(), "{name}");
    assert!(height > 0.0 && height.is_finite(), "{name}: height {height}");
    let mut worst = (0.0f64, 0, 0);
    for (&f, reference) in frames.iter().zip(positions) {
        assert!(f < ours.frames, "{name}: frame {f} of {}", ours.frames);
        assert_eq!(reference.len(), ours.joints, "{name}: frame {f} joint count");
        for (j, r) in reference.iter().enumerate() {
            let p = ours.position(f, j);
            let err = ((p.x - r[0]).powi(2) + (p.y - r[1]).powi(2) + (p.z - r[2]).powi(2)).sqrt() / height;
            assert!(err.is_finite(), "{name}: frame {f} joint {j} '{}': non-finite error", names[j]);
            if err > worst.0 {
                worst = (err, f, j);
            }
        }
    }
    worst
}

fn read_fixture() -> Fixture {
    let path = manifest().join(FIXTURE);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn handmade_bvh_is_what_it_claims() {
    let parsed = bvh::parse(HANDMADE_BVH, "handmade").unwrap();
    assert_eq!(parsed.joints.len(), 8);
    assert_eq!(parsed.frames, 3);
    let rot_order = |j: usize| -> String { parsed.joints[j].channels.iter().filter(|c| c.is_rotation()).map(|c| ["X", "Y", "Z"][c.axis()]).collect() };
    let orders: Vec<String> = (0..8).map(rot_order).collect();
    for wanted in ["ZXY", "XYZ", "YZX"] {
        assert!(orders.iter().any(|o| o == wanted), "handmade BVH lacks order {wanted}: {orders:?}");
    }
    assert!(parsed.joints.iter().filter(|j| j.channels.len() == 6).count() >= 2);
    assert!(parsed.joints[5].channels.contains(&Channel::Yposition) && parsed.joints[5].channels.len() == 4);
    assert_eq!(parsed.joints.iter().map(|j| j.end_sites.len()).sum::<usize>(), 2);
    // Non-trivial angles: some beyond +-90 degrees on every rotating frame after the first.
    for f in 1..3 {
        assert!(parsed.frame(f).iter().any(|v| v.abs() > 90.0));
    }
}

#[test]
fn handmade_fixture_matches_our_fk() {
    let fixture = read_fixture();
    assert_eq!(fixture.bvh, HANDMADE_BVH, "{FIXTURE} was computed for a different BVH; rerun with MENAGERIE_REGEN_FIXTURES=1 (needs numpy)");
    let (skeleton, ours) = our_fk(HANDMADE_BVH.as_bytes(), "handmade");
    assert_eq!(fixture.positions.len(), ours.frames);
    let frames: Vec<usize> = (0..ours.frames).collect();
    let (err, f, j) = worst_error("handmade", &skeleton, &ours, &fixture.names, &frames, &fixture.positions, fixture.height);
    println!("handmade fixture: worst FK error {err:.3e} of height (frame {f}, joint {j})");
    assert!(err <= FIXTURE_TOLERANCE, "handmade: FK error {err:e} of height at frame {f} joint {j}");
    // The fixture really exercises rotations: frames 1 and 2 are far from frame 0.
    for f in 1..3 {
        let moved = (0..ours.joints).map(|j| (ours.position(f, j) - ours.position(0, j)).length()).fold(0.0, f64::max);
        assert!(moved > 0.1 * fixture.height, "frame {f} barely moves");
    }
}

/// The committed fixture is what bvhfk computes for the handmade BVH (keeps it honest), and
/// the way to regenerate it.
#[test]
fn handmade_fixture_is_what_bvhfk_computes() {
    let Some((python, tools)) = reference_python("handmade_fixture_is_what_bvhfk_computes") else { return };
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fk_handmade_{}.bvh", std::process::id()));
    std::fs::write(&tmp, HANDMADE_BVH).unwrap();
    let mut dump = fk_dump(&python, &tools, "all", std::slice::from_ref(&tmp));
    let _ = std::fs::remove_file(&tmp);
    let r = dump.pop().unwrap();
    assert!(r.error.is_none(), "bvhfk on the handmade BVH: {:?}", r.error);
    let fresh = Fixture {
        about: "bvhfk.py (../shared/tools) world positions for the handmade BVH in tests/it/fk_reference.rs, \
                every frame, joints in file order; height = bvhfk's height() (largest extent of frame 0)"
            .to_string(),
        bvh: HANDMADE_BVH.to_string(),
        names: r.names,
        height: r.height.expect("height"),
        positions: r.positions,
    };
    assert_eq!(fresh.positions.len(), 3);
    if std::env::var_os("MENAGERIE_REGEN_FIXTURES").is_some() {
        let path = manifest().join(FIXTURE);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, serde_json::to_string_pretty(&fresh).unwrap() + "\n").unwrap();
        println!("wrote {}", path.display());
    }
    let kept = read_fixture();
    assert_eq!(kept.bvh, fresh.bvh);
    assert_eq!(kept.names, fresh.names);
    assert!((kept.height - fresh.height).abs() <= 1e-12 * fresh.height);
    for (a, b) in kept.positions.iter().flatten().zip(fresh.positions.iter().flatten()) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= 1e-12 * fresh.height, "fixture {a:?} vs bvhfk {b:?}");
        }
    }
}

#[test]
fn corpus_fk_matches_bvhfk() {
    let test = "corpus_fk_matches_bvhfk";
    let Some(data) = common::shared_data(test) else { return };
    let Some((python, tools)) = reference_python(test) else { return };
    let files = common::corpus_bvh_files(&data);
    let started = std::time::Instant::now();
    let refs = fk_dump(&python, &tools, "sample", &files);
    let mut worst = (0.0f64, String::new());
    let mut failures = Vec::new();
    for (path, r) in files.iter().zip(&refs) {
        let name = path.strip_prefix(&data).unwrap_or(path).display().to_string();
        assert!(r.error.is_none(), "bvhfk could not read {name}: {:?}", r.error);
        assert_eq!(Path::new(&r.path), path.as_path());
        let (skeleton, ours) = our_fk(&std::fs::read(path).unwrap(), &name);
        assert_eq!(ours.frames, r.frames, "{name}: frame count");
        let height = r.height.expect("height");
        let (err, f, j) = worst_error(&name, &skeleton, &ours, &r.names, &r.sampled, &r.positions, height);
        println!(
            "{name}: {} joints, frames {:?} of {}, worst {err:.2e} of height {height:.4} (frame {f}, joint '{}')",
            r.names.len(),
            r.sampled,
            r.frames,
            r.names[j]
        );
        if err > worst.0 || worst.1.is_empty() {
            worst = (err, name.clone());
        }
        if err > CORPUS_TOLERANCE {
            failures.push(format!("{name}: {err:e} at frame {f} joint {j} '{}'", r.names[j]));
        }
    }
    println!("corpus FK vs bvhfk: {} files, worst relative error {:.3e} ({}), {:.1} s", files.len(), worst.0, worst.1, started.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "FK disagrees with bvhfk beyond {CORPUS_TOLERANCE:e}:\n{}", failures.join("\n"));
}

/// Rotation-heavy case, every frame: Truebones Chicken (6 channels on every joint, Z X Y order,
/// so every joint's position channels replace its OFFSET) and the Truebones Monkey (86 joints).
#[test]
fn truebones_rotation_heavy_fk_matches_bvhfk() {
    let test = "truebones_rotation_heavy_fk_matches_bvhfk";
    let Some(data) = common::shared_data(test) else { return };
    let Some((python, tools)) = reference_python(test) else { return };
    let files: Vec<PathBuf> = [
        "bvh/truebones_anytop/Chicken/Chicken_EggLaying.bvh",
        "bvh/truebones_anytop/Chicken/Chicken_IdlePecking.bvh",
        "bvh/truebones_motion2motion/Monkey/__Walk.bvh",
    ]
    .iter()
    .map(|p| data.join(p))
    .collect();
    for f in &files {
        assert!(f.is_file(), "{} is missing from the corpus", f.display());
    }
    let refs = fk_dump(&python, &tools, "all", &files);
    for (i, (path, r)) in files.iter().zip(&refs).enumerate() {
        let name = path.strip_prefix(&data).unwrap().display().to_string();
        assert!(r.error.is_none(), "bvhfk could not read {name}: {:?}", r.error);
        let (skeleton, ours) = our_fk(&std::fs::read(path).unwrap(), &name);
        let zxy = [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];
        for joint in &skeleton.joints {
            let rot: Vec<Channel> = joint.channels.iter().copied().filter(|c| c.is_rotation()).collect();
            assert_eq!(rot, zxy, "{name}: joint '{}' is not Z X Y", joint.name);
            if i < 2 {
                assert_eq!(joint.channels.len(), 6, "{name}: joint '{}' lacks 6 channels", joint.name);
            }
        }
        assert_eq!(r.sampled.len(), ours.frames, "{name}: every frame compared");
        let height = r.height.unwrap();
        let (err, f, j) = worst_error(&name, &skeleton, &ours, &r.names, &r.sampled, &r.positions, height);
        println!("{name}: all {} frames, worst {err:.2e} of height (frame {f}, joint '{}')", ours.frames, r.names[j]);
        assert!(err <= CORPUS_TOLERANCE, "{name}: FK error {err:e} of height at frame {f} joint {j} '{}'", r.names[j]);
    }
}
