//! `mo-train` and `mo-sample` end to end on the bundled creatures (tiny model, a few steps):
//! an interrupted-and-resumed run equals the straight run byte for byte, sampling is
//! deterministic, works for a skeleton never trained on, and bad input exits 2.
use crate::common;

use common::{check_failure, ok, run, s, tempdir};
use std::path::Path;

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(name)
}

#[test]
fn resume_equals_the_straight_run_and_samples_are_deterministic() {
    let dir = tempdir("train");
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    for n in ["biped.bvh", "quadruped.bvh"] {
        std::fs::copy(example(n), data.join(n)).unwrap();
    }
    let (straight, resumed) = (dir.join("straight"), dir.join("resumed"));
    let train = |out: &Path, steps: &str, extra: &[&str]| {
        let mut a = vec![s(&data), "--out", s(out), "--preset", "tiny", "--steps", steps, "--batch", "2", "--crop", "12", "-q"];
        a.extend(extra);
        run("mo-train", &a, None)
    };
    ok(&train(&straight, "4", &[]), "straight");
    ok(&train(&resumed, "2", &[]), "first half");
    check_failure("mo-train", "existing checkpoint", &train(&resumed, "4", &[]), "--resume");
    ok(&train(&resumed, "4", &["--resume"]), "second half");
    assert_eq!(
        std::fs::read(straight.join("model.safetensors")).unwrap(),
        std::fs::read(resumed.join("model.safetensors")).unwrap(),
        "a resumed run ends with the straight run's parameters"
    );
    let log = std::fs::read_to_string(straight.join("log.jsonl")).unwrap();
    assert_eq!(log.lines().count(), 4, "one log line per step");

    // A trained skeleton and one never seen (the crab), twice each.
    for skel in ["quadruped.bvh", "crab.bvh"] {
        let path = example(skel);
        let args = [s(&path), "--model", s(&straight), "-n", "2", "--frames", "16", "--steps", "4", "--seed", "3"];
        let a = run("mo-sample", &args, None);
        ok(&a, skel);
        let b = run("mo-sample", &args, None);
        assert_eq!(a.stdout, b.stdout, "{skel}: same seed, same bytes");
        let mut named = args.to_vec();
        named.insert(0, "--skeleton");
        assert_eq!(run("mo-sample", &named, None).stdout, a.stdout, "{skel}: --skeleton PATH = the positional SKELETON");
        let array = menagerie::io::npy::from_bytes(&a.stdout, skel).unwrap();
        let (skeleton, _) = common::load(&example(skel));
        assert_eq!(array.shape, vec![2, 16, skeleton.len(), 13]);
        assert!(array.data.iter().all(|v| v.is_finite()));
    }
    let bvh = dir.join("gen_{i}.bvh");
    ok(&run("mo-sample", &[s(&example("crab.bvh")), "--model", s(&straight), "-n", "2", "--frames", "16", "--steps", "4", "--bvh", s(&bvh)], None), "bvh");
    let (_, motion) = common::load(&dir.join("gen_1.bvh"));
    assert_eq!(motion.frames, 16);

    let out = run("mo-sample", &[s(&example("crab.bvh")), "--model", s(&dir.join("nowhere"))], None);
    check_failure("mo-sample", "missing model", &out, "checkpoint.json");
    // Without --model the built-in model samples: same seed, same bytes; another seed differs.
    let builtin = |seed: &str| run("mo-sample", &[s(&example("crab.bvh")), "-n", "2", "--frames", "12", "--steps", "2", "--seed", seed], None);
    let (a, b, c) = (builtin("3"), builtin("3"), builtin("4"));
    ok(&a, "built-in model");
    let array = menagerie::io::npy::from_bytes(&a.stdout, "built-in").unwrap();
    assert_eq!(array.shape[..2], [2, 12]);
    assert!(array.data.iter().all(|v| v.is_finite()));
    assert_eq!(a.stdout, b.stdout, "the built-in model is deterministic");
    assert_ne!(a.stdout, c.stdout, "another seed, other samples");
}

/// `text`, a BVH file, without its first `drop` frames.
fn without_first_frames(text: &str, drop: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("Frame Time:")).unwrap();
    let frames: usize = lines[at - 1].trim_start_matches("Frames:").trim().parse().unwrap();
    let mut out: Vec<String> = lines[..at - 1].iter().map(|l| l.to_string()).collect();
    out.push(format!("Frames: {}", frames - drop));
    out.push(lines[at].to_string());
    out.extend(lines[at + 1 + drop..].iter().map(|l| l.to_string()));
    out.join("\n") + "\n"
}

/// A tiny model after two steps on `data` (a clip or a folder).
fn train_two_steps(data: &Path, model: &Path) {
    ok(&run("mo-train", &[s(data), "--out", s(model), "--preset", "tiny", "--steps", "2", "--batch", "2", "--crop", "12", "-q"], None), "train");
}

/// One short seeded sample of `skeleton` (a clip or a document) as BVH bytes, with mo-sample's
/// `-v` stderr.
fn sample_bvh(dir: &Path, model: &Path, skeleton: &Path, tag: &str) -> (Vec<u8>, String) {
    let bvh = dir.join(format!("{tag}.bvh"));
    let out = run("mo-sample", &[s(skeleton), "--model", s(model), "--frames", "12", "--steps", "3", "--seed", "5", "--bvh", s(&bvh), "-v"], None);
    ok(&out, tag);
    (std::fs::read(&bvh).unwrap(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A fine-tune carries the unseen-skeleton denoiser of the model it starts from: `--init builtin`
/// writes the built-in's (the bytes of models/zoo-compact/unseen), `--init DIR` copies DIR's,
/// and a skeleton the fine-tune did not train on is then sampled by it; a model without one
/// passes nothing on.
#[test]
fn a_fine_tune_carries_its_models_unseen_denoiser() {
    let dir = tempdir("carry-unseen");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tune = |init: &Path, data: &Path, out: &Path| {
        let args = [s(data), "--init", s(init), "--out", s(out), "--steps", "1", "--batch", "1", "--crop", "12"];
        let said = run("mo-train", &args, None);
        ok(&said, "fine-tune");
        String::from_utf8_lossy(&said.stderr).into_owned()
    };
    let from_builtin = dir.join("from-builtin");
    let said = tune(Path::new("builtin"), &example("quadruped.bvh"), &from_builtin);
    assert!(said.contains("carried the unseen-skeleton denoiser of the built-in model"), "{said}");
    for f in ["checkpoint.json", "model.safetensors"] {
        let carried = std::fs::read(from_builtin.join("unseen").join(f)).unwrap();
        assert!(carried == std::fs::read(root.join("models/zoo-compact/unseen").join(f)).unwrap(), "unseen/{f} is not the built-in's");
    }
    assert!(!from_builtin.join(".unseen.partial").exists(), "the temporary folder is left behind");
    // Resuming the fine-tune (--init kept on the command line) is a resume: nothing is carried
    // again, and the carried folder stays as it was. Equal bytes alone would also pass a fresh
    // copy, so a file only this test puts there must survive the resume.
    let marker = from_builtin.join("unseen/left-by-the-test");
    std::fs::write(&marker, b"x").unwrap();
    let resumed = run("mo-train", &[s(&example("quadruped.bvh")), "--init", "builtin", "--out", s(&from_builtin), "--steps", "2", "--resume"], None);
    ok(&resumed, "resumed fine-tune");
    assert!(!String::from_utf8_lossy(&resumed.stderr).contains("carried"), "{}", String::from_utf8_lossy(&resumed.stderr));
    assert!(
        std::fs::read(from_builtin.join("unseen/model.safetensors")).unwrap()
            == std::fs::read(root.join("models/zoo-compact/unseen/model.safetensors")).unwrap()
    );
    assert!(marker.exists(), "the resume replaced the carried unseen/ folder");
    std::fs::remove_file(&marker).unwrap();
    // A skeleton neither the built-in nor the tuned model trained on (an augmented crab) samples
    // from the tuned model as from the built-in: both through the built-in's unseen denoiser.
    let crab = dir.join("crab_aug.bvh");
    ok(&run("skel-aug", &[s(&example("crab.bvh")), "--add", "2", "--seed", "7", "-o", s(&crab)], None), "skel-aug");
    let (tuned, said) = sample_bvh(&dir, &from_builtin, &crab, "crab-tuned");
    assert!(said.contains("with the model's unseen-skeleton denoiser"), "{said}");
    let bvh = dir.join("crab-builtin.bvh");
    ok(&run("mo-sample", &[s(&crab), "--frames", "12", "--steps", "3", "--seed", "5", "--bvh", s(&bvh), "-q"], None), "builtin");
    assert!(tuned == std::fs::read(&bvh).unwrap(), "the tuned model samples an unseen skeleton unlike the built-in");

    // From a directory: its unseen/ goes on to the next fine-tune, byte for byte.
    let from_dir = dir.join("from-dir");
    tune(&from_builtin, &example("bird.bvh"), &from_dir);
    for f in ["checkpoint.json", "model.safetensors"] {
        assert!(std::fs::read(from_dir.join("unseen").join(f)).unwrap() == std::fs::read(from_builtin.join("unseen").join(f)).unwrap(), "unseen/{f}");
    }
    // A model without one: nothing is carried, and nothing said.
    let plain = dir.join("plain");
    train_two_steps(&example("quadruped.bvh"), &plain);
    let from_plain = dir.join("from-plain");
    let said = tune(&plain, &example("bird.bvh"), &from_plain);
    assert!(!from_plain.join("unseen").exists() && !said.contains("carried"), "{said}");
    // One whose unseen/ sampling would refuse stops the fine-tune before it writes anything.
    std::fs::create_dir_all(plain.join("unseen")).unwrap();
    for f in ["checkpoint.json", "model.safetensors"] {
        std::fs::copy(plain.join(f), plain.join("unseen").join(f)).unwrap();
    }
    let refused = dir.join("refused");
    let out = run("mo-train", &[s(&example("bird.bvh")), "--init", s(&plain), "--out", s(&refused), "--steps", "1"], None);
    check_failure("mo-train", "--init with a refused unseen/", &out, "--fallback-stats all");
    assert!(!refused.exists(), "no partial output");
}

/// A trained skeleton samples the same from any of its clips: the rest pose (rig and P_S) is
/// the one training built, from its rest clip's first frames, not the given file's. A
/// checkpoint without the recorded rest (written before it existed) falls back to the file's.
#[test]
fn a_trained_skeleton_samples_on_its_trained_rest_pose_from_any_clip() {
    let dir = tempdir("trained-rest");
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    let text = std::fs::read_to_string(example("quadruped.bvh")).unwrap();
    let (first, later) = (data.join("a_walk.bvh"), data.join("b_later.bvh"));
    std::fs::write(&first, &text).unwrap();
    std::fs::write(&later, without_first_frames(&text, 20)).unwrap();
    let model = dir.join("model");
    train_two_steps(&data, &model);
    let read = |p: &Path| -> serde_json::Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    let info = read(&model.join("checkpoint.json"));
    let rest = &info["skeletons"][0]["rest"];
    assert_eq!(rest["file"].as_str(), Some("a_walk.bvh"), "{rest}");
    let sample = |clip: &Path, tag: &str| sample_bvh(&dir, &model, clip, tag);
    let (from_first, _) = sample(&first, "first");
    let (from_later, said) = sample(&later, "later");
    assert!(said.contains("its rest pose is the one training used (frame 0 of a_walk.bvh)"), "{said}");
    assert_eq!(from_first, from_later, "the clip given changed the sample");
    // Without the recorded rest, the later clip's own first frame makes another sample.
    let path = model.join("checkpoint.json");
    let mut old = read(&path);
    old["skeletons"][0].as_object_mut().unwrap().remove("rest");
    std::fs::write(&path, serde_json::to_string(&old).unwrap()).unwrap();
    let (old_later, said) = sample(&later, "old-later");
    assert!(!said.contains("training used"), "{said}");
    assert_ne!(old_later, from_later);
}

#[test]
fn an_untrained_skeleton_samples_alike_from_its_file_and_its_document() {
    // The document carries statistics of the clip's motion; sampling ignores them for a
    // skeleton the model never saw, so `skel-info FILE | mo-sample` is `mo-sample FILE`.
    let dir = tempdir("file-document");
    let model = dir.join("model");
    train_two_steps(&example("quadruped.bvh"), &model);
    let dragon = example("dragon.bvh");
    let info = run("skel-info", &[s(&dragon)], None);
    ok(&info, "skel-info");
    let document: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert!(document["anytop"]["stats"].is_object(), "the document carries statistics");
    let doc_path = dir.join("dragon.json");
    std::fs::write(&doc_path, &info.stdout).unwrap();
    let sample = |skeleton: &Path, tag: &str| sample_bvh(&dir, &model, skeleton, tag);
    let (from_file, said) = sample(&dragon, "file");
    assert!(said.contains("not a trained skeleton: normalising by its rest pose"), "{said}");
    let (from_document, _) = sample(&doc_path, "document");
    assert_eq!(from_file, from_document, "the document's statistics changed the samples");
}

/// A model directory's unseen/ denoiser (trained under --fallback-stats all) samples every
/// skeleton the main one was not trained on, and only those; one trained on own statistics is
/// refused there.
#[test]
fn a_skeleton_the_model_never_saw_is_sampled_by_its_unseen_denoiser() {
    let dir = tempdir("unseen-denoiser");
    let model = dir.join("model");
    train_two_steps(&example("quadruped.bvh"), &model);
    let (crab, quadruped) = (example("crab.bvh"), example("quadruped.bvh"));
    let (crab_alone, said) = sample_bvh(&dir, &model, &crab, "crab-alone");
    assert!(!said.contains("unseen-skeleton denoiser"), "{said}");
    let (quadruped_alone, _) = sample_bvh(&dir, &model, &quadruped, "quadruped-alone");

    let unseen = model.join("unseen");
    let train = ["--out", s(&unseen), "--preset", "tiny", "--steps", "2", "--batch", "2", "--crop", "12", "-q", "--fallback-stats", "all"];
    ok(&run("mo-train", &[&[s(&quadruped)][..], &train].concat(), None), "train the unseen denoiser");
    let (crab_pair, said) = sample_bvh(&dir, &model, &crab, "crab-pair");
    assert!(said.contains("not a trained skeleton") && said.contains("with the model's unseen-skeleton denoiser"), "{said}");
    let (crab_unseen, _) = sample_bvh(&dir, &unseen, &crab, "crab-unseen");
    assert_eq!(crab_pair, crab_unseen, "the crab is sampled by unseen/ as by that model alone");
    assert_ne!(crab_pair, crab_alone, "unseen/ changed nothing");
    let (quadruped_pair, said) = sample_bvh(&dir, &model, &quadruped, "quadruped-pair");
    assert!(!said.contains("unseen-skeleton denoiser"), "{said}");
    assert_eq!(quadruped_pair, quadruped_alone, "a trained skeleton is sampled by the main denoiser");

    // A denoiser trained on own statistics in unseen/ is refused, naming it and the fix.
    for f in ["checkpoint.json", "model.safetensors"] {
        std::fs::copy(model.join(f), unseen.join(f)).unwrap();
    }
    let bvh = dir.join("refused.bvh");
    let out = run("mo-sample", &[s(&crab), "--model", s(&model), "--frames", "12", "--steps", "3", "--bvh", s(&bvh)], None);
    check_failure("mo-sample", "unseen/ trained on own statistics", &out, "--fallback-stats all");
    assert!(String::from_utf8_lossy(&out.stderr).contains("unseen"), "the message names the folder");
    assert!(!bvh.exists(), "no partial output");
}

/// `--lock-feet` with the built-in model on the bundled quadruped: the same seed gives the same
/// bytes, the samples differ from the default's, and their feet skate less (`mo-metrics
/// physics`, mean over the two samples); it belongs to the diffusion model, so `--examples`
/// refuses it.
#[test]
fn held_feet_skate_less_and_are_deterministic() {
    let dir = tempdir("lock-feet");
    let quadruped = example("quadruped.bvh");
    let sample = |tag: &str, extra: &[&str]| -> (Vec<u8>, f64) {
        let pattern = dir.join(format!("{tag}_{{i}}.bvh"));
        let mut args = vec![s(&quadruped), "-n", "2", "--frames", "60", "--seed", "3", "--bvh", s(&pattern), "-q"];
        args.extend(extra);
        ok(&run("mo-sample", &args, None), tag);
        let files: Vec<_> = (0..2).map(|i| dir.join(format!("{tag}_{i}.bvh"))).collect();
        let out = run("mo-metrics", &["physics", s(&files[0]), s(&files[1])], None);
        ok(&out, "physics");
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let skate: Vec<f64> = report["files"].as_array().unwrap().iter().map(|f| f["foot_skating"]["normalised"].as_f64().unwrap()).collect();
        let bytes = files.iter().flat_map(|f| std::fs::read(f).unwrap()).collect();
        (bytes, skate.iter().sum::<f64>() / skate.len() as f64)
    };
    let (plain, plain_skate) = sample("plain", &[]);
    let (held, held_skate) = sample("held", &["--lock-feet"]);
    let (again, _) = sample("again", &["--lock-feet"]);
    assert_eq!(held, again, "same seed, same bytes");
    assert_ne!(held, plain, "holding the feet changed nothing");
    assert!(held_skate < 0.75 * plain_skate, "feet skate {held_skate:.3} sizes/s held, {plain_skate:.3} not");
    let out = run("mo-sample", &["--examples", s(&quadruped), "--lock-feet"], None);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
}
