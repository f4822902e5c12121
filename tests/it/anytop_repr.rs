//! AnyTop representation: exact round trips on every frame of every corpus file and example
//! creature, the reference's invariants (docs/reference/anytop.md §1.6) on real clips, rig
//! serialisation, statistics. The worst errors are printed (run with `--nocapture`).
use crate::common;

use menagerie::bvh;
use menagerie::motion::Motion;
use menagerie::repr::anytop::{AnyTopRig, AnyTopStats, Facing, IkOptions, Placement, RestSource, RigOptions, DIM_CONTACT, FEATURE_DIMS};
use menagerie::repr::Features;
use menagerie::skeleton::Skeleton;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

struct Clip {
    name: String,
    skeleton: Skeleton,
    motion: Motion,
}

fn load(path: &Path, max_frames: usize) -> Clip {
    // `max_frames` keeps the small API tests fast; the corpus checks use whole clips.
    let name = path.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap_or(path).display().to_string();
    let b = bvh::read_path(path).unwrap_or_else(|e| panic!("{e}"));
    let skeleton = Skeleton::from_bvh(&b);
    let motion = Motion::from_bvh_frames(&b, &skeleton, 0..max_frames);
    Clip { name, skeleton, motion }
}

fn same_hierarchy(a: &Skeleton, b: &Skeleton) -> bool {
    a.len() == b.len()
        && a.joints.iter().zip(&b.joints).all(|(x, y)| x.name == y.name && x.parent == y.parent && x.offset == y.offset && x.channels == y.channels)
}

/// AnyTop's rest-clip rule within a folder: a `*tpos*` file of the same skeleton, else the
/// folder's first file of that skeleton.
fn rest_for(path: &Path, clip: &Clip) -> (Clip, RestSource) {
    let dir = path.parent().unwrap();
    let mut siblings: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh")))
        .collect();
    siblings.sort();
    let tpose = siblings.iter().find(|p| p.file_name().unwrap().to_string_lossy().to_lowercase().contains("tpos"));
    for (candidate, tpos) in tpose.into_iter().map(|p| (p, true)).chain(siblings.iter().map(|p| (p, false))) {
        let c = load(candidate, usize::MAX);
        if same_hierarchy(&c.skeleton, &clip.skeleton) {
            let file = candidate.display().to_string();
            return (c, if tpos { RestSource::TPose { file } } else { RestSource::FirstClip { file } });
        }
    }
    unreachable!("a file is its own rest candidate")
}

/// The creature's size for error tolerances: vertical extent of frame 0 (joints and End
/// Sites), or the rest extent for a flat creature (a snake lying on the ground).
fn size(clip: &Clip) -> f64 {
    let first = Motion { frames: 1, ..clip.motion.clone() };
    let first =
        Motion { rotations: first.rotations[..clip.skeleton.len()].to_vec(), translations: first.translations[..clip.skeleton.len()].to_vec(), ..first };
    let w = first.forward_kinematics(&clip.skeleton);
    let mut ys: Vec<f64> = w.positions.iter().map(|p| p.y).collect();
    for (j, joint) in clip.skeleton.joints.iter().enumerate() {
        for e in &joint.end_sites {
            ys.push((w.positions[j] + w.rotations[j] * *e).y);
        }
    }
    let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let extent = clip.skeleton.rest_extent();
    if hi - lo < 0.05 * extent {
        extent
    } else {
        hi - lo
    }
}

/// Worst joint distance between two motions' FK over the first `frames` frames, / `scale`.
fn worst_fk(skeleton: &Skeleton, a: &Motion, b: &Motion, frames: usize, scale: f64) -> f64 {
    let n = skeleton.len();
    let cut = |m: &Motion| Motion {
        frames,
        joints: n,
        frame_time: m.frame_time,
        rotations: m.rotations[..frames * n].to_vec(),
        translations: m.translations[..frames * n].to_vec(),
    };
    let (pa, pb) = (cut(a).forward_kinematics(skeleton), cut(b).forward_kinematics(skeleton));
    pa.positions.iter().zip(&pb.positions).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max) / scale
}

fn max_abs_diff(a: &Features, b: &Features) -> f64 {
    assert_eq!(a.shape(), b.shape());
    a.data.iter().zip(&b.data).map(|(x, y)| (x - y).abs() as f64).fold(0.0, f64::max)
}

fn first_frames(f: &Features, frames: usize) -> Features {
    let frames = frames.min(f.frames);
    Features { frames, joints: f.joints, dims: f.dims, data: f.data[..frames * f.joints * f.dims].to_vec() }
}

#[derive(Default, Clone)]
struct Worst {
    value: f64,
    file: String,
}

impl Worst {
    fn update(&mut self, value: f64, file: &str) {
        if value > self.value || self.file.is_empty() {
            *self = Worst { value, file: file.to_string() };
        }
    }
    fn merge(mut self, other: Worst) -> Worst {
        if other.value > self.value || self.file.is_empty() {
            self = other;
        }
        self
    }
}

#[derive(Default, Clone)]
struct Report {
    rotations: Worst,
    positions: Worst,
    reencode: Worst,
    ik: Worst,
    files: usize,
    short: Vec<String>,
    lines: Vec<String>,
}

fn face_description(rig: &AnyTopRig, skeleton: &Skeleton) -> String {
    let name = |j: usize| skeleton.joints[j].name.clone();
    match &rig.facing {
        Facing::FaceJoints(j) => {
            format!("face joints r_hip {} l_hip {} r_sh {} l_sh {}", name(j[0]), name(j[1]), name(j[2]), name(j[3]))
        }
        Facing::BodyAxis { front, back } => format!("body axis front {} back {}", name(*front), name(*back)),
    }
}

fn check_file(path: &Path) -> Report {
    let mut report = Report::default();
    let clip = load(path, usize::MAX);
    let (rest, source) = rest_for(path, &clip);
    let rig = AnyTopRig::new(&clip.skeleton, &rest.motion, &RigOptions { rest_source: source, ..Default::default() })
        .unwrap_or_else(|e| panic!("{}: {e}", clip.name));
    let skeleton = &clip.skeleton;
    report.files = 1;
    report.lines.push(format!(
        "{}: J={} {} feet={} scale={:.5} ground={:.4}",
        clip.name,
        skeleton.len(),
        face_description(&rig, skeleton),
        rig.feet.len(),
        rig.scale_factor,
        rig.ground_height
    ));
    if clip.motion.frames < 2 {
        let enc = rig.encode(skeleton, &clip.motion).unwrap();
        assert_eq!(enc.features.frames, 0);
        report.short.push(clip.name.clone());
        return report;
    }
    let scale = size(&clip);
    let enc = rig.encode(skeleton, &clip.motion).unwrap_or_else(|e| panic!("{}: {e}", clip.name));
    let frames = enc.features.frames;
    assert_eq!(enc.features.shape(), [clip.motion.frames - 1, skeleton.len(), FEATURE_DIMS]);
    assert!(enc.features.first_non_finite().is_none(), "{}: non-finite features", clip.name);

    // The features' positions are the clip's.
    let positions = rig.recover_positions(skeleton, &enc.features, &enc.placement).unwrap();
    let truth = clip.motion.forward_kinematics(skeleton);
    let pos_err = positions.iter().zip(&truth.positions).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max) / scale;
    report.positions.update(pos_err, &clip.name);

    // Decode from rotations.
    let decoded = rig.decode(skeleton, &enc.features, &enc.placement).unwrap();
    assert_eq!(decoded.frames, frames);
    let rot_err = worst_fk(skeleton, &clip.motion, &decoded, frames, scale);
    report.rotations.update(rot_err, &clip.name);

    // Through BVH text and back, then encode again.
    let text = bvh::write_string(&decoded.to_bvh(skeleton));
    let parsed = bvh::parse(&text, &clip.name).unwrap_or_else(|e| panic!("{e}"));
    let reread_skeleton = Skeleton::from_bvh(&parsed);
    assert!(same_hierarchy(&reread_skeleton, skeleton));
    let reread = Motion::from_bvh(&parsed, &reread_skeleton);
    let again = rig.encode(&reread_skeleton, &reread).unwrap();
    // The last decoded frame has no successor, so its velocities are not in `again`.
    let diff = max_abs_diff(&first_frames(&enc.features, frames - 1), &again.features);
    report.reencode.update(diff, &clip.name);

    // Decode from positions.
    let ik = rig.decode_ik(skeleton, &enc.features, &enc.placement, &IkOptions::default()).unwrap();
    let ik_err = worst_fk(skeleton, &clip.motion, &ik, frames, scale);
    report.ik.update(ik_err, &clip.name);
    report.lines.push(format!("    frames {frames}, size {scale:.3}: positions {pos_err:.2e}, rotations {rot_err:.2e}, re-encode {diff:.2e}, ik {ik_err:.2e}"));
    report
}

fn check_all(files: &[PathBuf], label: &str) {
    let report = files.par_iter().map(|p| check_file(p)).reduce(Report::default, |a, b| Report {
        rotations: a.rotations.merge(b.rotations),
        positions: a.positions.merge(b.positions),
        reencode: a.reencode.merge(b.reencode),
        ik: a.ik.merge(b.ik),
        files: a.files + b.files,
        short: [a.short, b.short].concat(),
        lines: [a.lines, b.lines].concat(),
    });
    for l in &report.lines {
        eprintln!("{l}");
    }
    eprintln!("{label}: {} files; fewer than two frames (zero feature frames): {:?}", report.files, report.short);
    eprintln!("{label}: worst recovered positions      {:.3e} of size ({})", report.positions.value, report.positions.file);
    eprintln!("{label}: worst decode from rotations    {:.3e} of size ({})", report.rotations.value, report.rotations.file);
    eprintln!("{label}: worst re-encode via BVH text   {:.3e} absolute ({})", report.reencode.value, report.reencode.file);
    eprintln!("{label}: worst decode from positions    {:.3e} of size ({})", report.ik.value, report.ik.file);
    assert!(report.positions.value < 1e-4, "recovered positions off by {:.3e} ({})", report.positions.value, report.positions.file);
    assert!(report.rotations.value < 1e-4, "decode from rotations off by {:.3e} ({})", report.rotations.value, report.rotations.file);
    assert!(report.reencode.value < 1e-5, "re-encoding differs by {:.3e} ({})", report.reencode.value, report.reencode.file);
    assert!(report.ik.value < 1e-2, "decode from positions off by {:.3e} ({})", report.ik.value, report.ik.file);
}

#[test]
fn example_creatures_round_trip_exactly() {
    let files = common::example_bvh_files();
    assert!(!files.is_empty(), "examples/data has no BVH files");
    check_all(&files, "examples");
}

#[test]
fn corpus_round_trips_exactly() {
    let Some(data) = common::shared_data("corpus_round_trips_exactly") else { return };
    check_all(&common::corpus_bvh_files(&data), "corpus");
}

/// docs/reference/anytop.md §1.6, as verified on the reference's processed arrays: root dims 0 and
/// 2 exactly zero, root 6D a pure yaw, contacts in {0, 1} and only on foot joints; plus frame 0
/// faces +Z. Mean velocity of all joints in the facing frame (dims 9..12): where the clip travels.
fn mean_velocity(f: &Features) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for t in 0..f.frames {
        for j in 0..f.joints {
            for (s, v) in sum.iter_mut().zip(&f.at(t, j)[9..12]) {
                *s += *v as f64;
            }
        }
    }
    sum.map(|s| s / (f.frames * f.joints).max(1) as f64)
}

/// A walking creature that travels goes forward: +Z in its facing frame. This catches a
/// facing rule whose left and right (or front and back) are swapped. In-place walks (the
/// Truebones ones) do not travel, and crabs walk sideways.
fn check_travels_forward(name: &str, f: &Features, assert_it: bool) {
    let v = mean_velocity(f);
    let travels = v[0].hypot(v[2]) > 0.005;
    eprintln!("{name}: mean velocity in the facing frame {v:.3?}{}", if travels { "" } else { " (in place)" });
    if assert_it && travels && !name.to_lowercase().contains("crab") {
        assert!(v[2] > 0.0 && v[2] > 2.0 * v[0].abs(), "{name}: does not travel forward (+Z): {v:?}");
    }
}

fn check_invariants(path: &Path) -> (String, usize, usize) {
    let clip = load(path, usize::MAX);
    let rig = AnyTopRig::new(&clip.skeleton, &clip.motion, &RigOptions::default()).unwrap();
    let f = rig.encode(&clip.skeleton, &clip.motion).unwrap().features;
    let mut contacts = 0;
    for t in 0..f.frames {
        let root = f.at(t, 0);
        assert!(root[0] == 0.0 && root[2] == 0.0, "{}: root x/z at frame {t}: {root:?}", clip.name);
        assert!(root[4] == 0.0 && root[6..9] == [0.0, 1.0, 0.0], "{}: root 6D not a yaw at frame {t}: {root:?}", clip.name);
        let c0 = (root[3] as f64).hypot(root[5] as f64);
        assert!((c0 - 1.0).abs() < 1e-6, "{}: root 6D column 0 not unit: {root:?}", clip.name);
        for j in 0..f.joints {
            let c = f.at(t, j)[DIM_CONTACT];
            assert!(c == 0.0 || c == 1.0, "{}: contact {c}", clip.name);
            if c == 1.0 {
                assert!(rig.feet.contains(&j), "{}: contact on non-foot joint {j}", clip.name);
                contacts += 1;
            }
        }
    }
    if f.frames > 0 {
        let r0 = &f.at(0, 0)[3..9];
        let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let off = r0.iter().zip(identity).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(off < 1e-6, "{}: frame 0 does not face +Z: {r0:?}", clip.name);
    }
    check_travels_forward(&clip.name, &f, true);
    (clip.name, contacts, f.frames * rig.feet.len())
}

#[test]
fn reference_invariants_hold_on_real_clips() {
    let Some(data) = common::shared_data("reference_invariants_hold_on_real_clips") else { return };
    let results: Vec<(String, usize, usize)> = common::corpus_bvh_files(&data).par_iter().map(|p| check_invariants(p)).collect();
    let total: usize = results.iter().map(|r| r.1).sum();
    for (name, c, possible) in &results {
        eprintln!("{name}: {c} contacts of {possible} foot-frames");
    }
    assert!(total > 0, "no contact anywhere in the corpus");
    let walks: Vec<_> = results.iter().filter(|r| r.0.to_lowercase().contains("walk")).collect();
    assert!(walks.iter().all(|r| r.1 > 0), "a walking clip without contacts: {walks:?}");
}

#[test]
fn invariants_hold_on_example_creatures() {
    for p in common::example_bvh_files() {
        check_invariants(&p);
    }
}

#[test]
fn rig_json_round_trip_decodes_identically() {
    let path = common::example_bvh_files().into_iter().find(|p| p.ends_with("quadruped.bvh")).unwrap();
    let clip = load(&path, 60);
    let rig = AnyTopRig::new(&clip.skeleton, &clip.motion, &RigOptions::default()).unwrap();
    let json = serde_json::to_string_pretty(&rig).unwrap();
    let back: AnyTopRig = serde_json::from_str(&json).unwrap();
    assert_eq!(back, rig);
    let enc = rig.encode(&clip.skeleton, &clip.motion).unwrap();
    let placement: Placement = serde_json::from_str(&serde_json::to_string(&enc.placement).unwrap()).unwrap();
    assert_eq!(placement, enc.placement);
    let a = rig.decode(&clip.skeleton, &enc.features, &enc.placement).unwrap();
    let b = back.decode(&clip.skeleton, &enc.features, &placement).unwrap();
    assert_eq!(a, b);
    let (a, b) = (
        rig.decode_ik(&clip.skeleton, &enc.features, &enc.placement, &IkOptions::default()).unwrap(),
        back.decode_ik(&clip.skeleton, &enc.features, &placement, &IkOptions::default()).unwrap(),
    );
    assert_eq!(a, b);
    assert_eq!(back.encode(&clip.skeleton, &clip.motion).unwrap(), enc);
}

#[test]
fn a_damaged_rig_or_mismatched_input_is_an_error() {
    let path = common::example_bvh_files().into_iter().find(|p| p.ends_with("biped.bvh")).unwrap();
    let clip = load(&path, 10);
    let rig = AnyTopRig::new(&clip.skeleton, &clip.motion, &RigOptions::default()).unwrap();
    let enc = rig.encode(&clip.skeleton, &clip.motion).unwrap();
    let mut bad = rig.clone();
    bad.facing = Facing::FaceJoints([0, 1, 2, 999]);
    assert!(bad.encode(&clip.skeleton, &clip.motion).is_err());
    let mut bad = rig.clone();
    bad.scale_factor = f64::NAN;
    assert!(bad.decode(&clip.skeleton, &enc.features, &enc.placement).is_err());
    let mut wrong = enc.features.clone();
    wrong.data[5] = f32::NAN;
    assert!(rig.decode(&clip.skeleton, &wrong, &enc.placement).is_err());
    let narrow = Features::zeros(3, clip.skeleton.len(), 12);
    assert!(rig.decode(&clip.skeleton, &narrow, &enc.placement).is_err());
    let few = Features::zeros(3, clip.skeleton.len() - 1, FEATURE_DIMS);
    assert!(rig.decode_ik(&clip.skeleton, &few, &enc.placement, &IkOptions::default()).is_err());
    // A rig of the same hierarchy with other bone lengths (cm vs m) is caught.
    let mut bigger = clip.skeleton.clone();
    for j in &mut bigger.joints {
        j.offset *= 2.0;
    }
    assert!(rig.decode(&bigger, &enc.features, &enc.placement).is_err());
    let options = RigOptions { feet: Some(vec![clip.skeleton.len()]), ..Default::default() };
    assert!(AnyTopRig::new(&clip.skeleton, &clip.motion, &options).is_err());
}

/// P_S (§1.7): the processed rest frame with identity rotations for non-root joints, facing +Z.
#[test]
fn rest_row_is_the_processed_rest_frame() {
    for path in common::example_bvh_files() {
        let clip = load(&path, 5);
        let rig = AnyTopRig::new(&clip.skeleton, &clip.motion, &RigOptions::default()).unwrap();
        let row = rig.rest_features(&clip.skeleton, &clip.motion).unwrap();
        assert_eq!(row.shape(), [1, clip.skeleton.len(), FEATURE_DIMS]);
        let first = rig.encode(&clip.skeleton, &clip.motion).unwrap().features;
        let rest = rig.rest_positions(&clip.skeleton);
        for j in 0..row.joints {
            let r = row.at(0, j);
            if j > 0 {
                assert_eq!(&r[3..9], &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
                // Positions are the natural rest pose's (root-relative x/z, absolute y).
                let want = rest[j] - glam::DVec3::new(rest[0].x, 0.0, rest[0].z);
                let got = glam::DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64);
                assert!(got.distance(want) < 1e-5, "{}: joint {j}: {got} vs {want}", path.display());
            }
            // Everything but the rotations is frame 0 of the rest clip's features.
            for d in (0..3).chain(9..13) {
                assert_eq!(r[d], first.at(0, j)[d], "{}: joint {j} dim {d}", path.display());
            }
        }
        let one = Motion {
            frames: 1,
            rotations: clip.motion.rotations[..clip.skeleton.len()].to_vec(),
            translations: clip.motion.translations[..clip.skeleton.len()].to_vec(),
            ..clip.motion.clone()
        };
        let still = rig.rest_features(&clip.skeleton, &one).unwrap();
        assert!((0..still.joints).all(|j| still.at(0, j)[9..12] == [0.0, 0.0, 0.0]));
    }
}

/// §1.8 grouping on numbers small enough to check by hand.
#[test]
fn statistics_group_as_the_reference() {
    // Two joints, two one-frame clips; every feature of joint j in clip k is set explicitly.
    let mut a = Features::zeros(1, 2, FEATURE_DIMS);
    let mut b = Features::zeros(1, 2, FEATURE_DIMS);
    // Root: positions differ by (2, 4, 0) between clips -> stds (1, 2, 0) -> grouped 1.
    a.at_mut(0, 0)[0..3].copy_from_slice(&[0.0, 0.0, 5.0]);
    b.at_mut(0, 0)[0..3].copy_from_slice(&[2.0, 4.0, 5.0]);
    // Root rotation: one dim differs by 6 -> std 3 over 6 dims -> 0.5.
    b.at_mut(0, 0)[3] = 6.0;
    // Root velocity: constant -> 0.
    // Joint 1: positions stds (1, 0, 0), rotation stds all 0 but one of 2 -> 2/6, velocity 3 -> 1.
    b.at_mut(0, 1)[0] = 2.0;
    b.at_mut(0, 1)[8] = 4.0;
    b.at_mut(0, 1)[9..12].copy_from_slice(&[2.0, 2.0, 2.0]);
    // Contacts: root constant (std 0 -> 1), joint 1 alternates (std 0.5 -> 0.5).
    b.at_mut(0, 1)[12] = 1.0;
    let stats = AnyTopStats::compute([&a, &b]).unwrap();
    let want_std: [[f32; FEATURE_DIMS]; 2] = [
        [1.0, 1.0, 1.0, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.0, 0.0, 0.0, 1.0],
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0, 1.0, 1.0, 0.5],
    ];
    for (j, want) in want_std.iter().enumerate() {
        for (d, want) in want.iter().enumerate() {
            let got = stats.std[j * FEATURE_DIMS + d];
            assert!((got - want).abs() < 1e-6, "std[{j}][{d}] = {got}, want {want}");
        }
    }
    assert_eq!(stats.mean[0..3], [1.0, 2.0, 5.0]);
    assert_eq!(stats.mean[FEATURE_DIMS + 12], 0.5);
    // Normalise and back: the same epsilon both ways, so the round trip is exact up to f32.
    let mut x = b.clone();
    stats.normalise(&mut x).unwrap();
    assert!((x.at(0, 0)[0] - (2.0 - 1.0) / (1.0 + 1e-6)).abs() < 1e-6);
    assert!((x.at(0, 0)[9]).abs() < 1e-6, "a zero-std group maps its mean to 0");
    stats.denormalise(&mut x).unwrap();
    assert!(max_abs_diff(&x, &b) < 1e-5);
    let json = serde_json::to_string(&stats).unwrap();
    assert_eq!(serde_json::from_str::<AnyTopStats>(&json).unwrap(), stats);
    assert!(AnyTopStats::compute([&a, &Features::zeros(1, 3, FEATURE_DIMS)]).is_err());
    assert!(stats.normalise(&mut Features::zeros(1, 3, FEATURE_DIMS)).is_err());
}

/// Features that no motion produced (noisy positions and rotations) still decode, both ways,
/// to finite motion; IK lands joints near the noisy targets.
#[test]
fn generated_like_features_decode_to_finite_motion() {
    let path = common::example_bvh_files().into_iter().find(|p| p.ends_with("spider.bvh")).unwrap();
    let clip = load(&path, 40);
    let rig = AnyTopRig::new(&clip.skeleton, &clip.motion, &RigOptions::default()).unwrap();
    let mut f = rig.encode(&clip.skeleton, &clip.motion).unwrap().features;
    let mut state = 12345u64;
    for v in f.data.iter_mut() {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        *v += ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.02;
    }
    let placement = rig.rest_placement();
    for m in [rig.decode(&clip.skeleton, &f, &placement).unwrap(), rig.decode_ik(&clip.skeleton, &f, &placement, &IkOptions::default()).unwrap()] {
        assert!(m.rotations.iter().all(|q| q.is_finite()) && m.translations.iter().all(|t| t.is_finite()));
        assert_eq!(m.frames, f.frames);
    }
}

/// Positions that disagree with the rotations and with rigid bones (noise on the RIC
/// positions only): IK lands each joint about as far from its target as the noise moved it.
#[test]
fn ik_follows_noisy_positions() {
    let path = common::example_bvh_files().into_iter().find(|p| p.ends_with("quadruped.bvh")).unwrap();
    let clip = load(&path, 40);
    let rig = AnyTopRig::new(&clip.skeleton, &clip.motion, &RigOptions::default()).unwrap();
    let enc = rig.encode(&clip.skeleton, &clip.motion).unwrap();
    let mut f = enc.features.clone();
    let amplitude = 0.01f32; // scaled units, i.e. 5% of the mean bone
    let mut state = 777u64;
    for t in 0..f.frames {
        for j in 1..f.joints {
            for v in &mut f.at_mut(t, j)[0..3] {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                *v += ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 2.0 * amplitude;
            }
        }
    }
    let targets = rig.recover_positions(&clip.skeleton, &f, &enc.placement).unwrap();
    let ik = rig.decode_ik(&clip.skeleton, &f, &enc.placement, &IkOptions::default()).unwrap();
    let got = ik.forward_kinematics(&clip.skeleton).positions;
    let noise = amplitude as f64 * 3f64.sqrt() / rig.scale_factor; // largest noise vector, BVH units
    let errors: Vec<f64> = got.iter().zip(&targets).map(|(a, b)| a.distance(*b) / noise).collect();
    let worst = errors.iter().copied().fold(0.0, f64::max);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    eprintln!("IK on noisy positions: mean {mean:.3}, worst {worst:.3} of the largest noise vector");
    assert!(mean < 1.0 && worst < 4.0, "IK strays from noisy targets: mean {mean}, worst {worst}");
}
