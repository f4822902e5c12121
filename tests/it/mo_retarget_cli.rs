//! `mo-retarget` end to end: the Motion2Motion demo with the reference's binding and with
//! `--bind auto`, determinism and diverse samples, output lengths, frame-rate handling, and
//! every bad input the issue lists (one line, exit 2, no file).
use crate::common;

use common::{check_failure, load, ok, run, s, shared_data, tempdir};
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

/// The output keeps the target's joints, channel layouts and End Sites.
fn assert_on_target(out: &Path, target: &Path, frames: usize) {
    let (ts, _) = load(target);
    let (os, om) = load(out);
    assert_eq!(om.frames, frames, "{}", out.display());
    assert_eq!(os.joints.len(), ts.joints.len());
    for (a, b) in os.joints.iter().zip(&ts.joints) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.channels, b.channels, "channel order of {}", a.name);
        assert_eq!(a.end_sites.len(), b.end_sites.len(), "End Sites of {}", a.name);
    }
    assert!(om.rotations.iter().all(|q| q.is_finite()) && om.translations.iter().all(|t| t.is_finite()));
}

#[test]
fn demo_with_reference_and_auto_binding_both_directions() {
    let Some(data) = shared_data("demo_with_reference_and_auto_binding_both_directions") else { return };
    let dir = tempdir("demo");
    let flamingo = data.join("bvh/truebones_motion2motion/Flamingo/Flamingo_Walk.bvh");
    let monkey = data.join("bvh/truebones_motion2motion/Monkey/__Walk.bvh");
    let binding = data.join("bindings/flamingo_to_monkey.m2m.json");
    let out = dir.join("fm.bvh");
    ok(&run("mo-retarget", &[s(&flamingo), s(monkey.parent().unwrap()), "--bind", s(&binding), "-o", s(&out)], None), "reference binding");
    assert_on_target(&out, &monkey, 79);
    let auto = dir.join("fm_auto.bvh");
    ok(&run("mo-retarget", &[s(&flamingo), s(&monkey), "--bind", "auto", "-o", s(&auto)], None), "auto binding");
    assert_on_target(&auto, &monkey, 79);
    // The reverse direction: the monkey walk on the flamingo.
    let back = dir.join("mf.bvh");
    ok(&run("mo-retarget", &[s(&monkey), s(&flamingo), "--bind", "auto", "-o", s(&back)], None), "reverse");
    assert_on_target(&back, &flamingo, 61);
}

#[test]
fn same_seed_same_bytes_and_samples_differ() {
    let dir = tempdir("seeds");
    let (src, tgt) = (example("quadruped.bvh"), example("dragon.bvh"));
    let a = dir.join("a_{i}.bvh");
    let b = dir.join("b_{i}.bvh");
    ok(&run("mo-retarget", &[s(&src), s(&tgt), "--bind", "auto", "-n", "3", "--seed", "7", "-o", s(&a)], None), "a");
    ok(&run("mo-retarget", &[s(&src), s(&tgt), "--bind", "auto", "-n", "3", "--seed", "7", "--threads", "1", "-o", s(&b)], None), "b");
    let read = |p: &Path, i: usize| std::fs::read(p.to_string_lossy().replace("{i}", &i.to_string())).unwrap();
    for i in 0..3 {
        assert_eq!(read(&a, i), read(&b, i), "sample {i}: same seed, same bytes, any thread count");
    }
    assert_ne!(read(&a, 0), read(&a, 1), "samples differ");
    assert_ne!(read(&a, 1), read(&a, 2), "samples differ");
}

#[test]
fn any_output_length_and_frame_rates() {
    let dir = tempdir("length");
    let (src, tgt) = (example("biped.bvh"), example("quadruped.bvh"));
    let (_, sm) = load(&src);
    // Much longer than the source and the example.
    let long = dir.join("long.bvh");
    let frames = (sm.frames * 3).to_string();
    ok(&run("mo-retarget", &[s(&src), s(&tgt), "--bind", "auto", "--frames", &frames, "-o", s(&long)], None), "long");
    assert_on_target(&long, &tgt, sm.frames * 3);
    // A source at another frame rate is resampled to the examples' rate, and says so.
    let text = std::fs::read_to_string(&src).unwrap();
    let ft = text.lines().find(|l| l.starts_with("Frame Time")).unwrap();
    let old: f64 = ft.split(':').nth(1).unwrap().trim().parse().unwrap();
    let half = dir.join("half.bvh");
    std::fs::write(&half, text.replace(ft, &format!("Frame Time: {}", old * 2.0))).unwrap();
    let out = dir.join("resampled.bvh");
    let r = run("mo-retarget", &[s(&half), s(&tgt), "--bind", "auto", "-o", s(&out)], None);
    ok(&r, "resampled");
    assert!(String::from_utf8_lossy(&r.stderr).contains("resampling"), "the resampling is said on stderr");
    let (_, om) = load(&out);
    let expected = 2 * (sm.frames - 1) + 1;
    assert!(om.frames.abs_diff(expected) <= 1, "{} frames at the examples' rate, expected about {expected}", om.frames);
}

#[test]
fn bad_input_is_one_line_and_no_file() {
    let dir = tempdir("bad");
    let (src, tgt) = (example("biped.bvh"), example("quadruped.bvh"));
    let out = dir.join("out.bvh");
    let args = |extra: &[&str]| -> Vec<String> { extra.iter().map(|x| x.to_string()).chain(["-o".into(), s(&out).into()]).collect() };
    let go = |a: Vec<String>| run("mo-retarget", &a.iter().map(String::as_str).collect::<Vec<_>>(), None);

    let binding = dir.join("b.json");
    std::fs::write(&binding, r#"{"mapping": [{"source": "LeftFooot", "target": "NoSuchJoint"}]}"#).unwrap();
    let r = go(args(&[s(&src), s(&tgt), "--bind", s(&binding)]));
    check_failure("mo-retarget", "unknown names", &r, "closest");

    let r = go(args(&[s(&src), s(&tgt), s(&example("crab.bvh")), "--bind", "auto"]));
    check_failure("mo-retarget", "mixed target skeletons", &r, "must share one skeleton");

    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let r = go(args(&[s(&src), s(&empty), "--bind", "auto"]));
    check_failure("mo-retarget", "empty target folder", &r, "holds no .bvh");

    let text = std::fs::read_to_string(&src).unwrap();
    let at = text.find("Frames:").unwrap();
    let ft = text[at..].find("Frame Time").unwrap() + at;
    let first_frame_end = ft + text[ft..].find('\n').unwrap() + 1;
    let second = first_frame_end + text[first_frame_end..].find('\n').unwrap() + 1;
    let one = dir.join("one.bvh");
    std::fs::write(&one, format!("{}Frames: 1\n{}", &text[..at], &text[ft..second])).unwrap();
    let r = go(args(&[s(&one), s(&tgt), "--bind", "auto"]));
    check_failure("mo-retarget", "1-frame source", &r, "at least two frames");

    // Example clips at two frame rates.
    let tt = std::fs::read_to_string(&tgt).unwrap();
    let line = tt.lines().find(|l| l.starts_with("Frame Time")).unwrap();
    let fast = dir.join("fast.bvh");
    std::fs::write(&fast, tt.replace(line, "Frame Time: 0.01")).unwrap();
    let r = go(args(&[s(&src), s(&tgt), s(&fast), "--bind", "auto"]));
    check_failure("mo-retarget", "mixed example frame rates", &r, "fps");

    let r = go(args(&[s(&src), s(&tgt), "--bind", "auto", "-n", "2"]));
    check_failure("mo-retarget", "two samples, one file", &r, "{i}");

    assert!(!out.exists(), "a failing run wrote {}", out.display());
}
