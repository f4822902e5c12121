use super::*;
use crate::motion::Motion;
use crate::skeleton::Skeleton;
use std::path::Path;

fn bundled(name: &str) -> (Skeleton, Motion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name);
    let parsed = crate::bvh::read_path(&path).unwrap();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    (skeleton, motion)
}

/// Largest joint position difference over all frames, in units of the skeleton's height.
fn max_position_error(a: (&Skeleton, &Motion), b: (&Skeleton, &Motion)) -> f64 {
    assert_eq!(a.1.frames, b.1.frames);
    let (pa, pb) = (a.1.forward_kinematics(a.0), b.1.forward_kinematics(b.0));
    let worst = pa.positions.iter().zip(&pb.positions).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max);
    worst / a.0.rest_height().max(1e-12)
}

#[test]
fn every_bundled_creature_survives_glb_and_gltf() {
    for name in ["biped.bvh", "quadruped.bvh", "spider.bvh", "snake.bvh", "bird.bvh", "fish.bvh", "crab.bvh", "dragon.bvh", "centipede.bvh"] {
        let (skeleton, motion) = bundled(name);
        for glb in [true, false] {
            let bytes = if glb { write_glb(&skeleton, &motion, name).unwrap() } else { write_gltf(&skeleton, &motion, name).unwrap() };
            let (s2, m2) = read(&bytes, name, None, &ReadOptions::default()).unwrap();
            assert_eq!(s2.joints.len(), skeleton.joints.len(), "{name}");
            for (x, y) in skeleton.joints.iter().zip(&s2.joints) {
                assert_eq!(x.name, y.name);
                assert_eq!(x.parent, y.parent);
                assert_eq!(x.end_sites.len(), y.end_sites.len(), "{name} {}", x.name);
                assert!(x.offset.distance(y.offset) <= 1e-6 * (1.0 + x.offset.length()), "{name} {}", x.name);
            }
            assert_eq!(s2.frame_time, skeleton.frame_time, "{name}: the frame time comes back as written");
            let err = max_position_error((&skeleton, &motion), (&s2, &m2));
            assert!(err < 1e-5, "{name}: {err}");
        }
    }
}

#[test]
fn writing_is_deterministic_and_rereading_our_file_gives_the_same_file() {
    let (skeleton, motion) = bundled("quadruped.bvh");
    let a = write_glb(&skeleton, &motion, "q").unwrap();
    assert_eq!(a, write_glb(&skeleton, &motion, "q").unwrap());
    let (s2, m2) = read(&a, "q.glb", None, &ReadOptions::default()).unwrap();
    let (s3, m3) = read(&write_glb(&s2, &m2, "q").unwrap(), "q2.glb", None, &ReadOptions::default()).unwrap();
    assert_eq!(s2, s3);
    assert!(max_position_error((&s2, &m2), (&s3, &m3)) < 1e-6);
}

#[test]
fn fps_resamples_and_animation_choice_is_checked() {
    let (skeleton, motion) = bundled("biped.bvh");
    let bytes = write_glb(&skeleton, &motion, "b").unwrap();
    let fps = 1.0 / skeleton.frame_time / 2.0;
    let (s, m) = read(&bytes, "b", None, &ReadOptions { fps: Some(fps), ..ReadOptions::default() }).unwrap();
    assert_eq!(m.frames, (motion.frames - 1) / 2 + 1);
    assert!((s.frame_time - 2.0 * skeleton.frame_time).abs() < 1e-12);
    let by_name = read(&bytes, "b", None, &ReadOptions { animation: AnimationChoice::parse("motion"), ..ReadOptions::default() }).unwrap();
    assert_eq!(by_name.1.frames, motion.frames);
    for bad in ["1", "walk"] {
        let e = read(&bytes, "b.glb", None, &ReadOptions { animation: AnimationChoice::parse(bad), ..ReadOptions::default() }).unwrap_err().to_string();
        assert!(e.starts_with("b.glb: no animation") && e.contains("'motion'"), "{e}");
    }
}

#[test]
fn malformed_files_are_errors_naming_the_file() {
    let (skeleton, motion) = bundled("snake.bvh");
    let good = write_glb(&skeleton, &motion, "s").unwrap();
    // Every truncation, and bytes flipped all over the file: an error or a motion, never a panic.
    for cut in (0..good.len()).step_by(97) {
        if let Err(e) = read(&good[..cut], "cut.glb", None, &ReadOptions::default()) {
            assert!(e.to_string().starts_with("cut.glb: "), "{e}");
        }
    }
    for at in (0..good.len()).step_by(31) {
        let mut bad = good.clone();
        bad[at] ^= 0x5a;
        let _ = read(&bad, "flip.glb", None, &ReadOptions::default());
    }
    let json = r#"{"asset":{"version":"2.0"},"nodes":[{"name":"a"}],"scenes":[{"nodes":[0]}]}"#;
    let e = read(json.as_bytes(), "walk.gltf", None, &ReadOptions::default()).unwrap_err().to_string();
    assert_eq!(e, "walk.gltf: no skin: expected a skinned armature (a skin whose joints are the skeleton)");
    let cycle = r#"{"asset":{"version":"2.0"},"nodes":[{"children":[1]},{"children":[0]}],"skins":[{"joints":[0,1]}]}"#;
    let e = read(cycle.as_bytes(), "c.gltf", None, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.starts_with("c.gltf: "), "{e}");
    let two_roots = r#"{"asset":{"version":"2.0"},"nodes":[{"name":"a"},{"name":"b"}],"skins":[{"joints":[0,1]}]}"#;
    let e = read(two_roots.as_bytes(), "r.gltf", None, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("2 root joints"), "{e}");
    let external = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"walk.bin","byteLength":4}],"nodes":[{"name":"a"}],"skins":[{"joints":[0]}]}"#;
    let e = read(external.as_bytes(), "<stdin>", None, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("cannot be found from stdin"), "{e}");
}

#[test]
fn armature_transforms_above_the_root_are_baked_in() {
    // An armature node scaled by 0.01 and turned 90 degrees about Y, over a two-joint chain.
    let json = r#"{"asset":{"version":"2.0"},
        "nodes":[{"name":"Armature","scale":[0.01,0.01,0.01],"rotation":[0,0.7071067811865476,0,0.7071067811865476],"translation":[1,2,3],"children":[1]},
                 {"name":"hip","translation":[0,100,0],"children":[2]},
                 {"name":"knee","translation":[100,0,0]}],
        "skins":[{"joints":[2,1]}]}"#;
    let (s, m) = read(json.as_bytes(), "a.gltf", None, &ReadOptions::default()).unwrap();
    assert_eq!(s.joints[0].name, "hip", "parents come first");
    let p = m.forward_kinematics(&s);
    assert!(p.position(0, 0).distance(glam::DVec3::new(1.0, 3.0, 3.0)) < 1e-6, "{:?}", p.position(0, 0));
    assert!(p.position(0, 1).distance(glam::DVec3::new(1.0, 3.0, 2.0)) < 1e-6, "{:?}", p.position(0, 1));
}

#[test]
fn step_rotations_and_cubic_joint_translations_from_a_data_uri() {
    use base64::Engine as _;
    // Root: STEP rotation keys at 0, 0.5, 1 s (identity, 90 degrees about z, identity).
    // Tip: CUBICSPLINE translation keys at 0 and 1 s from x = 1 to x = 3, zero tangents.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let mut floats: Vec<f32> = vec![0.0, 0.5, 1.0];
    floats.extend([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, s, s, 0.0, 0.0, 0.0, 1.0]);
    floats.extend([0.0, 1.0]);
    floats.extend([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    let uri = base64::engine::general_purpose::STANDARD.encode(&bytes);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":12}},{{"buffer":0,"byteOffset":12,"byteLength":48}},
                       {{"buffer":0,"byteOffset":60,"byteLength":8}},{{"buffer":0,"byteOffset":68,"byteLength":72}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"SCALAR","min":[0],"max":[1]}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC4"}},
                     {{"bufferView":2,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]}},
                     {{"bufferView":3,"componentType":5126,"count":6,"type":"VEC3"}}],
        "nodes":[{{"name":"root","translation":[0,1,0],"children":[1]}},{{"name":"tip","translation":[1,0,0]}}],
        "skins":[{{"joints":[0,1]}}],
        "animations":[{{"name":"a","samplers":[{{"input":0,"output":1,"interpolation":"STEP"}},{{"input":2,"output":3,"interpolation":"CUBICSPLINE"}}],
                        "channels":[{{"sampler":0,"target":{{"node":0,"path":"rotation"}}}},{{"sampler":1,"target":{{"node":1,"path":"translation"}}}}]}}]}}"#,
        len = bytes.len()
    );
    let (skeleton, motion) = read(json.as_bytes(), "t.gltf", None, &ReadOptions::default()).unwrap();
    assert_eq!((motion.frames, skeleton.frame_time), (3, 0.5));
    assert_eq!(skeleton.joints[1].channels.len(), 6, "a translating joint carries position channels");
    let p = motion.forward_kinematics(&skeleton);
    let close = |a: glam::DVec3, b: [f64; 3]| a.distance(glam::DVec3::from_array(b)) < 1e-6;
    assert!(close(p.position(0, 1), [1.0, 1.0, 0.0]), "{:?}", p.position(0, 1));
    assert!(close(p.position(1, 1), [0.0, 3.0, 0.0]), "{:?}", p.position(1, 1));
    assert!(close(p.position(2, 1), [3.0, 1.0, 0.0]), "{:?}", p.position(2, 1));
}

/// The stick body: one stick per bone and End Site, base ring on the parent and tip ring on the
/// child; a child that travels away from its offset (a root-at-origin file keying its hips in
/// world space) gets none, so viewers show no beam from the world origin to the creature.
#[test]
fn sticks_follow_both_ends_and_skip_travelling_children() {
    let (skeleton, mut motion) = bundled("quadruped.bvh");
    let rest = Motion::rest(&skeleton).forward_kinematics(&skeleton).positions;
    let bones = skeleton.joints.iter().filter(|j| j.parent.is_some()).count() + skeleton.joints.iter().map(|j| j.end_sites.len()).sum::<usize>();
    let all = mesh::sticks(&skeleton, &motion, &rest).unwrap();
    assert_eq!(all.positions.len(), 8 * bones);
    let child = 1;
    let parent = skeleton.joints[child].parent.unwrap();
    // The first stick is the one into joint 1: four base vertices on its parent, four tip ones on it.
    assert_eq!(&all.joints[..8], &[parent as u16; 4].iter().chain(&[child as u16; 4]).copied().collect::<Vec<_>>()[..]);
    for f in 0..motion.frames {
        motion.translations[f * motion.joints + child] = skeleton.joints[child].offset + glam::DVec3::X * f as f64;
    }
    let fewer = mesh::sticks(&skeleton, &motion, &rest).unwrap();
    assert_eq!(fewer.positions.len(), 8 * (bones - 1));
    assert!(!fewer.joints.chunks(8).any(|s| s[0] == parent as u16 && s[4] == child as u16));
}
