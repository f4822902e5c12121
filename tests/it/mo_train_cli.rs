//! `mo-train` as a process: Ctrl-C / SIGTERM save a checkpoint at a step boundary and exit 130,
//! and resuming from it ends where the uninterrupted run ends; the augmentation flags and the
//! recorded skeleton names.
use crate::common;

use common::{bin, ok, run, s, tempdir};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// One folder per creature (directories are not searched recursively: both are named).
fn data(dir: &Path) -> Vec<PathBuf> {
    ["biped", "quadruped"]
        .iter()
        .map(|n| {
            let folder = dir.join("data").join(n);
            std::fs::create_dir_all(&folder).unwrap();
            let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(format!("{n}.bvh"));
            std::fs::copy(from, folder.join(format!("{n}_walk.bvh"))).unwrap();
            folder
        })
        .collect()
}

fn train_args<'a>(data: &'a [PathBuf], out: &'a Path, steps: &'a str) -> Vec<&'a str> {
    preset_args(data, out, steps, "tiny")
}

fn preset_args<'a>(data: &'a [PathBuf], out: &'a Path, steps: &'a str, preset: &'a str) -> Vec<&'a str> {
    let mut args: Vec<&str> = data.iter().map(|d| s(d)).collect();
    args.extend(["--out", s(out), "--preset", preset, "--steps", steps, "--batch", "2", "--crop", "12", "--checkpoint-minutes", "1000"]);
    args
}

/// A new run given `option value` exits 2 with one line naming the option, before writing any
/// checkpoint.
fn refused_new_run(dir: &Path, data: &[PathBuf], option: &str, value: &str) {
    let other = dir.join("other");
    let mut args = train_args(data, &other, "1");
    args.extend([option, value]);
    common::check_failure("mo-train", &format!("{option} {value}"), &run("mo-train", &args, None), option);
    assert!(!other.join("checkpoint.json").exists());
}

fn info(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("checkpoint.json")).unwrap()).unwrap()
}

#[cfg(unix)]
#[test]
fn a_signal_saves_a_checkpoint_that_resumes_the_same_run() {
    let dir = tempdir("train-signal");
    let data = data(&dir);
    for signal in ["-INT", "-TERM"] {
        let out = dir.join(format!("run{signal}"));
        let child = bin("mo-train").args(train_args(&data, &out, "100000")).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
        // Let it take a few steps (the log has a line per step), then interrupt it.
        let started = Instant::now();
        let log = out.join("log.jsonl");
        while std::fs::read_to_string(&log).map_or(0, |t| t.lines().count()) < 3 {
            assert!(started.elapsed() < Duration::from_secs(120), "mo-train took no steps in 2 minutes");
            std::thread::sleep(Duration::from_millis(20));
        }
        let killed = std::process::Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap();
        assert!(killed.success());
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(130), "{signal}: {stderr}");
        let step = info(&out)["step"].as_u64().unwrap();
        assert!(step >= 3 && stderr.contains(&format!("interrupted at step {step}, checkpoint saved; --resume to continue")), "{stderr}");
        assert_eq!(std::fs::read_to_string(&log).unwrap().lines().count() as u64, step, "the checkpoint holds every logged step");
        let leftovers: Vec<_> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
        if signal == "-INT" {
            // Two more steps after the interruption equal a straight run of as many steps.
            let total = (step + 2).to_string();
            let mut resume = train_args(&data, &out, &total);
            resume.push("--resume");
            ok(&run("mo-train", &resume, None), "resume");
            let straight = dir.join("straight");
            ok(&run("mo-train", &train_args(&data, &straight, &total), None), "straight");
            assert_eq!(
                std::fs::read(straight.join("model.safetensors")).unwrap(),
                std::fs::read(out.join("model.safetensors")).unwrap(),
                "interrupted + resumed = straight"
            );
            assert_eq!(std::fs::read(straight.join("optimizer.safetensors")).unwrap(), std::fs::read(out.join("optimizer.safetensors")).unwrap());
        }
    }
}

#[test]
fn augmentation_flags_and_skeleton_names_are_recorded() {
    let dir = tempdir("train-augment");
    let data = data(&dir);
    let out = dir.join("model");
    let mut args = train_args(&data, &out, "1");
    args.extend(["--augment", "1/2", "--augment-variants", "2"]);
    let result = run("mo-train", &args, None);
    ok(&result, "augmented");
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(stderr.contains("2 skeletons (biped, quadruped)") && stderr.contains("4 augmented variants"), "{stderr}");
    let info = info(&out);
    assert_eq!((info["augment"].as_f64(), info["augment_variants"].as_u64()), (Some(0.5), Some(2)));
    let names: Vec<&str> = info["skeletons"].as_array().unwrap().iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["biped", "quadruped"], "one skeleton per folder: named after it");
    for bad in ["1.5", "-0.1", "2/0", "x"] {
        let flag = format!("--augment={bad}");
        let mut args = train_args(&data, &dir, "1");
        args.push(&flag);
        let out = run("mo-train", &args, None);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.code() == Some(2) && stderr.contains("'--augment <P>'"), "{bad}: {stderr}");
    }
}

/// --fallback-stats and --loss-units are recorded only when they are not the defaults (upstream's
/// way; old checkpoints read as those), a resume keeps them unless told otherwise, SATA refuses
/// them, and own units without a fallback (they would weigh nothing) are refused.
#[test]
fn fallback_stats_are_recorded_and_kept_by_resume() {
    let dir = tempdir("train-fallback-stats");
    let data = data(&dir);
    let (plain, fallback) = (dir.join("plain"), dir.join("fallback"));
    ok(&run("mo-train", &train_args(&data, &plain, "1"), None), "measured");
    assert!(info(&plain).get("fallback_stats").is_none(), "measured is the default and not written");
    assert!(info(&plain).get("loss_units").is_none(), "normalised is the default and not written");
    let mut args = train_args(&data, &fallback, "1");
    args.extend(["--fallback-stats", "variants", "--loss-units", "own"]);
    ok(&run("mo-train", &args, None), "fallback");
    assert_eq!((info(&fallback)["fallback_stats"].as_str(), info(&fallback)["loss_units"].as_str()), (Some("variants"), Some("own")));
    let mut args = train_args(&data, &fallback, "2");
    args.push("--resume");
    let resumed = run("mo-train", &args, None);
    ok(&resumed, "resume");
    assert!(!String::from_utf8_lossy(&resumed.stderr).contains("differ from the checkpoint"), "the same run goes on");
    let kept = info(&fallback);
    assert_eq!((kept["step"].as_u64(), kept["fallback_stats"].as_str(), kept["loss_units"].as_str()), (Some(2), Some("variants"), Some("own")));
    let sata = dir.join("sata");
    for flag in ["--fallback-stats", "--loss-units"] {
        let mut args = train_args(&data, &sata, "1");
        args.extend(["--arch", "sata", flag, if flag == "--loss-units" { "own" } else { "variants" }]);
        refused(&args, flag, &sata);
    }
    let alone = dir.join("alone");
    let mut args = train_args(&data, &alone, "1");
    args.extend(["--loss-units", "own"]);
    refused(&args, "--fallback-stats", &alone);
}

/// `mo-train ARGS` fails with exit 2, an error naming `needle`, and no `out`.
fn refused(args: &[&str], needle: &str, out: &Path) {
    let result = run("mo-train", args, None);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.code() == Some(2) && stderr.contains(needle) && !out.exists(), "{stderr}");
}

/// --rest-token global: the pooled rest statistics are recorded, a resume keeps them, a fine-tune
/// inherits them (and refuses to read rest tokens the other way), and the model samples.
#[test]
fn a_global_rest_token_is_recorded_kept_and_inherited() {
    let dir = tempdir("train-rest-token");
    let data = data(&dir);
    let run_dir = dir.join("global");
    let mut args = train_args(&data, &run_dir, "1");
    args.extend(["--fallback-stats", "all", "--rest-token", "global"]);
    ok(&run("mo-train", &args, None), "global");
    let norm = info(&run_dir)["rest_norm"].clone();
    assert_eq!((norm["mean"].as_array().map(Vec::len), norm["std"][1].as_array().map(Vec::len)), (Some(2), Some(13)), "{norm}");
    let mut args = train_args(&data, &run_dir, "2");
    args.push("--resume");
    let resumed = run("mo-train", &args, None);
    ok(&resumed, "resume");
    assert!(!String::from_utf8_lossy(&resumed.stderr).contains("differ from the checkpoint"), "the same run goes on");
    assert_eq!((info(&run_dir)["step"].as_u64(), &info(&run_dir)["rest_norm"]), (Some(2), &norm));
    let tuned = dir.join("tuned");
    let mut args = vec![s(&data[0]), "--init", s(&run_dir), "--out", s(&tuned), "--steps", "1", "--crop", "12"];
    ok(&run("mo-train", &args, None), "fine-tune");
    assert_eq!(info(&tuned)["rest_norm"], norm, "a fine-tune reads rest tokens as its model learned to");
    let refused = dir.join("refused");
    args[3] = s(&refused);
    args.extend(["--rest-token", "skeleton"]);
    let out = run("mo-train", &args, None);
    assert!(out.status.code() == Some(2) && !refused.exists(), "{}", String::from_utf8_lossy(&out.stderr));
    let walk = data[0].join("biped_walk.bvh");
    let sampled = run("mo-sample", &[s(&walk), "--model", s(&tuned), "-n", "1", "--frames", "8", "--steps", "2", "-q"], None);
    ok(&sampled, "sample");
    assert!(sampled.stdout.starts_with(b"\x93NUMPY"), "an NPY on stdout");
    let plain = dir.join("plain");
    ok(&run("mo-train", &train_args(&data, &plain, "1"), None), "plain");
    assert!(info(&plain).get("rest_norm").is_none(), "skeleton is the default and not written");
}

/// A learning rate that blows the model up: the first non-finite loss stops training with exit
/// 2, the checkpoint stays the last good one, and every log line is JSON.
#[test]
fn a_non_finite_loss_stops_and_keeps_the_last_checkpoint() {
    let dir = tempdir("train-nan");
    let data = data(&dir);
    for arch in ["anytop", "sata"] {
        let out = dir.join(arch);
        let mut args = train_args(&data, &out, "2");
        args.extend(["--arch", arch, "-q"]);
        ok(&run("mo-train", &args, None), arch);
        let model = std::fs::read(out.join("model.safetensors")).unwrap();
        let mut args = train_args(&data, &out, "20");
        args.extend(["--arch", arch, "--resume", "--lr", "1e30"]);
        let result = run("mo-train", &args, None);
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(2), "{arch}: {stderr}");
        assert!(stderr.contains("is not finite") && stderr.contains("the checkpoint of step 2 is kept"), "{arch}: {stderr}");
        assert_eq!(info(&out)["step"].as_u64(), Some(2), "{arch}");
        assert_eq!(std::fs::read(out.join("model.safetensors")).unwrap(), model, "{arch}: the model of step 2 stays");
        let log = std::fs::read_to_string(out.join("log.jsonl")).unwrap();
        for line in log.lines() {
            let value: serde_json::Value = serde_json::from_str(line).unwrap_or_else(|e| panic!("{arch}: {line}: {e}"));
            assert!(value["loss"].as_f64().is_some_and(f64::is_finite), "{arch}: {line}");
        }
    }
}

/// The saved model is the weights' moving average and the raw weights are kept beside the
/// optimiser's moments for --resume; `--ema 0` saves the raw weights and keeps no copy.
#[test]
fn the_saved_model_is_the_moving_average_of_the_weights() {
    let dir = tempdir("train-ema");
    let data = data(&dir);
    let load = |p: PathBuf| candle_core::safetensors::load(p, &candle_core::Device::Cpu).unwrap();
    let flat = |t: &candle_core::Tensor| t.flatten_all().unwrap().to_vec1::<f32>().unwrap();
    let averaged = dir.join("averaged");
    let mut args = train_args(&data, &averaged, "4");
    args.extend(["--ema", "0.5"]);
    ok(&run("mo-train", &args, None), "ema 0.5");
    assert_eq!(info(&averaged)["ema"].as_f64(), Some(0.5));
    let (model, state) = (load(averaged.join("model.safetensors")), load(averaged.join("optimizer.safetensors")));
    let mut differ = 0;
    for (name, w) in &model {
        let raw = state.get(&format!("w.{name}")).unwrap_or_else(|| panic!("no raw copy of {name}"));
        assert_eq!(raw.dims(), w.dims(), "{name}");
        differ += usize::from(flat(raw) != flat(w));
    }
    assert!(differ > model.len() / 2, "the average equals the raw weights for {} of {} parameters", model.len() - differ, model.len());
    let plain = dir.join("plain");
    let mut args = train_args(&data, &plain, "4");
    args.extend(["--ema", "0"]);
    ok(&run("mo-train", &args, None), "ema 0");
    assert!(load(plain.join("optimizer.safetensors")).keys().all(|k| !k.starts_with("w.")));
    // The raw weights of the averaged run are those of the plain run: the average never feeds
    // back into training.
    let (raw_plain, raw_avg) = (load(plain.join("model.safetensors")), state);
    for (name, w) in &raw_plain {
        assert_eq!(flat(w), flat(&raw_avg[&format!("w.{name}")]), "{name}");
    }
}

/// `--noise-shift` is recorded, a resumed run keeps it unless it is given again (then the
/// model goes on under the new schedule and says so), and a shift below 1 is refused.
#[test]
fn the_noise_shift_is_recorded_and_kept_on_resume() {
    let dir = tempdir("train-shift");
    let data = data(&dir);
    let out = dir.join("model");
    let mut args = train_args(&data, &out, "2");
    args.extend(["--noise-shift", "4"]);
    ok(&run("mo-train", &args, None), "shift 4");
    assert_eq!(info(&out)["noise_shift"].as_f64(), Some(4.0));
    let mut args = train_args(&data, &out, "3");
    args.push("--resume");
    ok(&run("mo-train", &args, None), "resume");
    assert_eq!(info(&out)["noise_shift"].as_f64(), Some(4.0));
    let mut args = train_args(&data, &out, "4");
    args.extend(["--resume", "--noise-shift", "8"]);
    let changed = run("mo-train", &args, None);
    ok(&changed, "resume with another shift");
    assert!(String::from_utf8_lossy(&changed.stderr).contains("--noise-shift 4"), "no note about the change");
    assert_eq!(info(&out)["noise_shift"].as_f64(), Some(8.0));
    assert_eq!(info(&out)["shift_taper"].as_bool(), Some(false));
    // The taper is recorded too, and kept by a resume that does not give it.
    let mut args = train_args(&data, &out, "5");
    args.extend(["--resume", "--shift-taper", "true"]);
    let tapered = run("mo-train", &args, None);
    ok(&tapered, "resume tapered");
    let said = String::from_utf8_lossy(&tapered.stderr);
    assert!(said.contains("trained with --shift-taper false; it goes on learning under --shift-taper true"), "{said}");
    let mut args = train_args(&data, &out, "6");
    args.push("--resume");
    let again = run("mo-train", &args, None);
    ok(&again, "resume again");
    assert!(!String::from_utf8_lossy(&again.stderr).contains("--shift-taper"), "{}", String::from_utf8_lossy(&again.stderr));
    assert_eq!((info(&out)["noise_shift"].as_f64(), info(&out)["shift_taper"].as_bool()), (Some(8.0), Some(true)));
    // The sampler reads the schedule from the checkpoint.
    let sample = run("mo-sample", &[s(&data[0].join("biped_walk.bvh")), "--model", s(&out), "--frames", "8", "--steps", "3"], None);
    ok(&sample, "sample");
    refused_new_run(&dir, &data, "--noise-shift", "0.5");
}

/// A new run draws every clip alike and records nothing; a resumed run given --still-weight
/// records it (and says the draws differ), the next resume keeps it; a weight outside 0..=1 is
/// refused before any training.
#[test]
fn the_still_weight_is_recorded_and_kept_on_resume() {
    let dir = tempdir("train-still");
    let data = data(&dir);
    let out = dir.join("model");
    ok(&run("mo-train", &train_args(&data, &out, "2"), None), "new run");
    assert!(info(&out).get("still_weight").is_none(), "{}", info(&out));
    let mut args = train_args(&data, &out, "3");
    args.extend(["--resume", "--still-weight", "0.25"]);
    let changed = run("mo-train", &args, None);
    ok(&changed, "resume with a still weight");
    assert!(String::from_utf8_lossy(&changed.stderr).contains("differ from the checkpoint's"), "{}", String::from_utf8_lossy(&changed.stderr));
    assert_eq!(info(&out)["still_weight"].as_f64(), Some(0.25));
    let mut args = train_args(&data, &out, "4");
    args.push("--resume");
    ok(&run("mo-train", &args, None), "resume");
    assert_eq!(info(&out)["still_weight"].as_f64(), Some(0.25));
    refused_new_run(&dir, &data, "--still-weight", "2");
}

/// A new run records the default position jitter, a resumed run keeps its checkpoint's (0 for
/// checkpoints written before it existed) unless it is given again, and the jitter changes
/// what is learnt.
#[test]
fn the_position_jitter_is_recorded_and_kept_on_resume() {
    let dir = tempdir("train-jitter");
    let data = data(&dir);
    let out = dir.join("model");
    ok(&run("mo-train", &train_args(&data, &out, "2"), None), "new run");
    assert_eq!(info(&out)["position_jitter"].as_u64(), Some(1000));
    let mut args = train_args(&data, &out, "3");
    args.extend(["--resume", "--position-jitter", "0"]);
    let changed = run("mo-train", &args, None);
    ok(&changed, "resume without jitter");
    assert_eq!(info(&out)["position_jitter"].as_u64(), Some(0));
    // Another jitter draws other data, which the resume says.
    assert!(String::from_utf8_lossy(&changed.stderr).contains("differ from the checkpoint's"), "{}", String::from_utf8_lossy(&changed.stderr));
    let mut args = train_args(&data, &out, "4");
    args.extend(["--resume", "--position-jitter", "0"]);
    let same = run("mo-train", &args, None);
    ok(&same, "resume");
    assert!(!String::from_utf8_lossy(&same.stderr).contains("differ from the checkpoint's"), "{}", String::from_utf8_lossy(&same.stderr));
    assert_eq!(info(&out)["position_jitter"].as_u64(), Some(0));
    // An old checkpoint (no field) resumes without jitter.
    let path = out.join("checkpoint.json");
    let mut old: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    old.as_object_mut().unwrap().remove("position_jitter");
    std::fs::write(&path, serde_json::to_string(&old).unwrap()).unwrap();
    let mut args = train_args(&data, &out, "5");
    args.push("--resume");
    ok(&run("mo-train", &args, None), "resume an old checkpoint");
    assert_eq!(info(&out)["position_jitter"].as_u64(), Some(0));
    // Two new runs that differ only in the jitter learn different weights.
    let (a, b) = (dir.join("a"), dir.join("b"));
    ok(&run("mo-train", &train_args(&data, &a, "2"), None), "a");
    let mut args = train_args(&data, &b, "2");
    args.extend(["--position-jitter", "0"]);
    ok(&run("mo-train", &args, None), "b");
    let bytes = |d: &std::path::Path| std::fs::read(d.join("model.safetensors")).unwrap();
    assert_ne!(bytes(&a), bytes(&b));
}

/// A new run records its loss weighting (v by default), a resumed run keeps it unless it is
/// given again (then it says so), and the weighting changes what is learnt.
#[test]
fn the_loss_weighting_is_recorded_and_kept_on_resume() {
    let dir = tempdir("train-weighting");
    let data = data(&dir);
    let out = dir.join("model");
    ok(&run("mo-train", &train_args(&data, &out, "2"), None), "default");
    assert_eq!(info(&out)["weighting"].as_str(), Some("v"));
    let x0 = dir.join("x0");
    let mut args = train_args(&data, &x0, "2");
    args.extend(["--loss-weighting", "x0"]);
    ok(&run("mo-train", &args, None), "x0");
    // x0, the reference's, is what a checkpoint without the field means.
    assert!(info(&x0).get("weighting").is_none(), "{}", info(&x0));
    let read = |d: &std::path::Path| std::fs::read(d.join("model.safetensors")).unwrap();
    assert_ne!(read(&out), read(&x0), "the weighting made no difference");
    let mut args = train_args(&data, &out, "3");
    args.push("--resume");
    ok(&run("mo-train", &args, None), "resume");
    assert_eq!(info(&out)["weighting"].as_str(), Some("v"));
    let mut args = train_args(&data, &out, "4");
    args.extend(["--resume", "--loss-weighting", "min-snr:2"]);
    let changed = run("mo-train", &args, None);
    ok(&changed, "resume with another weighting");
    assert!(String::from_utf8_lossy(&changed.stderr).contains("--loss-weighting v"), "no note about the change");
    assert_eq!(info(&out)["weighting"]["min-snr"].as_f64(), Some(2.0));
    refused_new_run(&dir, &data, "--loss-weighting", "eps");
}

/// `--init DIR` starts a new run from that model's weights, size, noise schedule and position
/// jitter, with the
/// fine-tune defaults (--lr 1e-3, --batch 4, --crop 20, --augment 0), kept by --resume, and a note of where it started; `--init
/// builtin` does the same from the model inside the binaries; `--minutes` ends a run on time
/// with a checkpoint; bad starts are one-line errors that write nothing.
#[test]
fn fine_tuning_starts_from_a_model_and_keeps_its_size_and_schedule() {
    let dir = tempdir("train-init");
    let data = data(&dir);
    let load = |p: PathBuf| candle_core::safetensors::load(p.join("model.safetensors"), &candle_core::Device::Cpu).unwrap();
    let flat = |t: &candle_core::Tensor| t.flatten_all().unwrap().to_vec1::<f32>().unwrap();
    let base = dir.join("base");
    let mut args = train_args(&data, &base, "3");
    args.extend(["--noise-shift", "4", "--position-jitter", "77"]);
    ok(&run("mo-train", &args, None), "base");

    // One step at a vanishing rate, no average: the weights are the base model's.
    let tuned = dir.join("tuned");
    let one = [s(&data[1]), "--init", s(&base), "--out", s(&tuned), "--steps", "1", "--batch", "2", "--crop", "12", "--checkpoint-minutes", "1000"];
    let mut args = one.to_vec();
    args.extend(["--lr", "1e-30", "--ema", "0"]);
    let out = run("mo-train", &args, None);
    ok(&out, "init from dir");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(&format!("fine-tuning model {} (step 3)", base.display())),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (b, t) = (info(&base), info(&tuned));
    assert_eq!((&t["config"], t["noise_shift"].as_f64(), t["step"].as_u64()), (&b["config"], Some(4.0), Some(1)));
    assert_eq!(t["position_jitter"].as_u64(), Some(77), "a fine-tune keeps its model's position jitter");
    assert_eq!(t["init"].as_str(), Some(format!("model {} (step 3)", base.display()).as_str()));
    assert_eq!(t["skeletons"].as_array().map(|a| a.len()), Some(1), "only the new clips' skeleton");
    let (bw, tw) = (load(base.clone()), load(tuned.clone()));
    assert_eq!(bw.len(), tw.len());
    for (name, w) in &bw {
        let gap = flat(w).iter().zip(flat(&tw[name])).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(gap < 1e-6, "{name} moved by {gap} at lr 1e-30: not started from the base weights");
    }
    // Without --init the same run starts from random weights.
    let scratch = dir.join("scratch");
    let args = [s(&data[1]), "--out", s(&scratch), "--steps", "1", "--batch", "2", "--crop", "12", "--preset", "tiny", "--lr", "1e-30", "--ema", "0"];
    ok(&run("mo-train", &args, None), "scratch");
    let sw = load(scratch.clone());
    assert!(bw.iter().any(|(n, w)| flat(w) != flat(&sw[n])), "a run from scratch equals the base model");

    // The fine-tune defaults, recorded; --resume goes on with them (no note of a difference),
    // not with a new run's (--batch 16, --crop 40, --lr 1e-4, --augment 2/3).
    let defaults = dir.join("defaults");
    let args = [s(&data[1]), "--out", s(&defaults), "--checkpoint-minutes", "1000"];
    ok(&run("mo-train", &[args.as_slice(), &["--init", s(&base), "--steps", "1"]].concat(), None), "init defaults");
    let d = info(&defaults);
    let settings = |d: &serde_json::Value| (d["lr"].as_f64(), d["augment"].as_f64(), d["batch"].as_u64(), d["crop"].as_u64());
    assert_eq!(settings(&d), (Some(1e-3), Some(0.0), Some(4), Some(20)));
    let resumed = run("mo-train", &[args.as_slice(), &["--steps", "2", "--resume"]].concat(), None);
    ok(&resumed, "resume a fine-tune");
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(!stderr.contains("differ from the checkpoint's"), "a resumed fine-tune changed its settings: {stderr}");
    assert_eq!((info(&defaults)["step"].as_u64(), settings(&info(&defaults))), (Some(2), settings(&d)));
    let changed = run("mo-train", &[args.as_slice(), &["--steps", "3", "--resume", "--batch", "8"]].concat(), None);
    ok(&changed, "resume with another batch");
    assert!(String::from_utf8_lossy(&changed.stderr).contains("differ from the checkpoint's"), "{}", String::from_utf8_lossy(&changed.stderr));
    assert_eq!(settings(&info(&defaults)), (Some(1e-3), Some(0.0), Some(8), Some(20)), "the checkpoint records the resumed run's batch");

    // The built-in model, for a wall-time budget: it stops on time, saves, and samples.
    let builtin = dir.join("builtin");
    let args = [s(&data[1]), "--init", "builtin", "--out", s(&builtin), "--minutes", "0.002", "--batch", "2", "--crop", "12"];
    let out = run("mo-train", &args, None);
    ok(&out, "init builtin");
    let bi = info(&builtin);
    assert!(bi["init"].as_str().is_some_and(|i| i.starts_with("the built-in default model (step ")), "{bi}");
    assert_eq!((bi["config"]["width"].as_u64(), bi["noise_shift"].as_f64()), (Some(64), Some(10.0)));
    let shipped: serde_json::Value =
        serde_json::from_slice(&std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("models/zoo-compact/checkpoint.json")).unwrap()).unwrap();
    assert_eq!(bi["position_jitter"], shipped["position_jitter"], "a fine-tune keeps the built-in model's position jitter");
    let steps = bi["step"].as_u64().unwrap();
    assert!((1..1000).contains(&steps), "a 0.12 s budget ran {steps} steps");
    let sample = run("mo-sample", &[s(&data[1].join("quadruped_walk.bvh")), "--model", s(&builtin), "--frames", "8", "--steps", "3"], None);
    ok(&sample, "sample the fine-tuned model");

    // Bad starts write nothing.
    let none = dir.join("none");
    let missing = dir.join("no-such-model");
    let args = [s(&data[1]), "--init", s(&missing), "--out", s(&none), "--steps", "1"];
    common::check_failure("mo-train", "missing init", &run("mo-train", &args, None), "no-such-model");
    let args = [s(&data[1]), "--init", "builtin", "--arch", "sata", "--out", s(&none), "--steps", "1"];
    common::check_failure("mo-train", "sata init", &run("mo-train", &args, None), "--arch sata");
    let args = [s(&data[1]), "--init", "builtin", "--out", s(&base), "--steps", "1"];
    common::check_failure("mo-train", "init over a checkpoint", &run("mo-train", &args, None), "already holds a checkpoint");
    assert!(!none.exists());
}

/// Each denoiser preset trains the size it names, recorded in the checkpoint.
#[test]
fn presets_train_the_sizes_they_name() {
    let dir = tempdir("train-presets");
    let data = data(&dir);
    for (preset, width, layers) in [("tiny", 32, 2), ("compact", 64, 2)] {
        let out = dir.join(preset);
        ok(&run("mo-train", &preset_args(&data, &out, "1", preset), None), preset);
        let config = &info(&out)["config"];
        assert_eq!((config["width"].as_u64(), config["layers"].as_u64()), (Some(width), Some(layers)), "{preset}: {config}");
    }
}
