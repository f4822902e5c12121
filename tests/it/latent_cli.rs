//! The latent model (SATA) end to end: `mo-encode --latent` / `--decode-latent`, `mo-retarget
//! --method latent`, `mo-train --arch sata` with resume; bad inputs exit 2 without output.
use crate::common;

use common::{check_failure, ok, run, s, tempdir};
use menagerie::io::npy;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

fn frames(path: &Path) -> usize {
    menagerie::bvh::read_path(path).unwrap().frames
}

#[test]
fn latents_have_one_width_for_every_skeleton_and_repeat() {
    let mut widths = Vec::new();
    for name in ["quadruped.bvh", "crab.bvh", "snake.bvh"] {
        let clip = example(name);
        let out = run("mo-encode", &["--latent", s(&clip)], None);
        ok(&out, name);
        let z = npy::from_bytes(&out.stdout, name).unwrap();
        assert_eq!(z.shape[0], frames(&clip) - 1, "{name}: one latent per feature frame");
        assert!(z.data.iter().all(|v| v.is_finite()), "{name}");
        widths.push(z.shape[1]);
        assert_eq!(out.stdout, run("mo-encode", &["--latent", s(&clip)], None).stdout, "{name}: same input, same bytes");
    }
    assert!(widths.iter().all(|&w| w == widths[0]), "latent width depends on the skeleton: {widths:?}");
}

#[test]
fn decoding_onto_another_skeleton_gives_its_hierarchy_and_retarget_does_the_same() {
    let dir = tempdir("decode");
    let (quad, dragon) = (example("quadruped.bvh"), example("dragon.bvh"));
    let z = dir.join("z.npy");
    ok(&run("mo-encode", &["--latent", s(&quad), "-o", s(&z)], None), "encode");
    let out = dir.join("dragon.bvh");
    ok(&run("mo-encode", &["--decode-latent", "--skeleton", s(&dragon), s(&z), "-o", s(&out)], None), "decode");
    let parsed = menagerie::bvh::read_path(&out).unwrap();
    let (dragon_skeleton, _) = common::load(&dragon);
    let decoded = menagerie::skeleton::Skeleton::from_bvh(&parsed);
    assert_eq!(decoded.joints.iter().map(|j| &j.name).collect::<Vec<_>>(), dragon_skeleton.joints.iter().map(|j| &j.name).collect::<Vec<_>>());
    assert_eq!(parsed.frames, frames(&quad) - 1);
    // Latents on stdin (a pipe from --latent) decode the same.
    let piped = run("mo-encode", &["--decode-latent", "--skeleton", s(&dragon)], Some(&std::fs::read(&z).unwrap()));
    ok(&piped, "decode from stdin");
    assert_eq!(piped.stdout, std::fs::read(&out).unwrap());
    // The zero-shot path is the same two steps (both clips are at 30 fps).
    let retargeted = run("mo-retarget", &["--method", "latent", s(&quad), "--to", s(&dragon)], None);
    ok(&retargeted, "retarget");
    assert_eq!(retargeted.stdout, std::fs::read(&out).unwrap());
}

#[test]
fn bad_latent_inputs_fail_cleanly() {
    let dir = tempdir("bad");
    let (quad, dragon) = (example("quadruped.bvh"), example("dragon.bvh"));
    let features = dir.join("features.npy");
    ok(&run("mo-encode", &[s(&quad), "-o", s(&features)], None), "anytop features");
    let out = dir.join("never.bvh");
    let r = run("mo-encode", &["--decode-latent", "--skeleton", s(&dragon), s(&features), "-o", s(&out)], None);
    check_failure("mo-encode", "3-D features as latents", &r, "expected latents [frames, dims]");
    assert!(!out.exists(), "no partial output");
    let narrow = dir.join("narrow.npy");
    std::fs::write(&narrow, npy::to_bytes(&[10, 7], &[0.0; 70]).unwrap()).unwrap();
    let r = run("mo-encode", &["--decode-latent", "--skeleton", s(&dragon), s(&narrow)], None);
    check_failure("mo-encode", "wrong latent width", &r, "latents have 7 values per frame");
    let denoiser = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/zoo-compact");
    let r = run("mo-encode", &["--latent", "--model", s(&denoiser), s(&quad)], None);
    check_failure("mo-encode", "a diffusion model as the latent model", &r, "expected 'menagerie.sata'");
    let r = run("mo-retarget", &["--method", "latent", s(&quad), "--to", s(&dragon), "--bind", "auto"], None);
    check_failure("mo-retarget", "m2m flag with the latent method", &r, "--bind belongs to --method m2m");
    let r = run("mo-retarget", &[s(&quad), s(&dragon)], None);
    check_failure("mo-retarget", "m2m without a binding", &r, "--bind is required");
}

#[test]
fn a_trained_latent_model_resumes_and_serves_the_tools() {
    let dir = tempdir("train");
    let model = dir.join("model");
    let data = example("");
    let train = |steps: &str, resume: bool| {
        let mut a = vec![s(&data), "--arch", "sata", "--out", s(&model), "--preset", "tiny", "--steps", steps, "--batch", "2", "-q"];
        if resume {
            a.push("--resume");
        }
        run("mo-train", &a, None)
    };
    ok(&train("2", false), "train");
    ok(&train("3", true), "resume");
    let info: serde_json::Value = serde_json::from_slice(&std::fs::read(model.join("checkpoint.json")).unwrap()).unwrap();
    assert_eq!(info["format"], "menagerie.sata");
    assert_eq!(info["step"], 3);
    assert_eq!(std::fs::read_to_string(model.join("log.jsonl")).unwrap().lines().count(), 3);
    let out = run("mo-encode", &["--latent", "--model", s(&model), s(&example("spider.bvh"))], None);
    ok(&out, "encode with the trained model");
    assert_eq!(npy::from_bytes(&out.stdout, "z").unwrap().shape[1], 16, "the tiny preset's latent");

    // The model keeps the rig of every skeleton it trained on, and reads and writes a trained
    // skeleton with it whatever clip of it is given: onto the spider from its clip and from the
    // same clip without its first frames (another first frame, so another rest pose of its
    // own), the transfer is the same. Without rigs.json each clip brings its own rig.
    let rigs: serde_json::Value = serde_json::from_slice(&std::fs::read(model.join("rigs.json")).unwrap()).unwrap();
    assert_eq!(rigs["rigs"].as_array().map(Vec::len), Some(9), "one rig per example skeleton");
    let shifted = dir.join("spider_later.bvh");
    std::fs::write(&shifted, drop_frames(&std::fs::read_to_string(example("spider.bvh")).unwrap(), 7)).unwrap();
    let onto = |target: &Path| {
        let out = run("mo-retarget", &["--method", "latent", "--model", s(&model), s(&example("quadruped.bvh")), "--to", s(target)], None);
        ok(&out, "latent transfer onto the spider");
        out.stdout
    };
    assert_eq!(onto(&example("spider.bvh")), onto(&shifted), "one rig for the trained spider");
    std::fs::remove_file(model.join("rigs.json")).unwrap();
    assert_ne!(onto(&example("spider.bvh")), onto(&shifted), "each clip's own first frame");
}

/// A BVH text without its first `n` frames.
fn drop_frames(text: &str, n: usize) -> String {
    let (head, motion) = text.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let frames: usize = lines.next().unwrap().trim_start_matches("Frames:").trim().parse().unwrap();
    let time = lines.next().unwrap();
    let rest: Vec<&str> = lines.skip(n).collect();
    assert_eq!(rest.len(), frames - n);
    format!("{head}MOTION\nFrames: {}\n{time}\n{}\n", frames - n, rest.join("\n"))
}
