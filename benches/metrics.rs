//! Generation metrics and FID time: `cargo bench --bench metrics`.
//!
//! The reference protocol scores 20 generated samples of 120 frames per skeleton against that
//! skeleton's GT clips (docs/reference/anytop.md §6). Rows:
//!
//! * `generation`: `generation_metrics` on 20 samples × 120 frames against 10 GT clips of 100
//!   frames, built from the project's own creatures (`synth`), for several joint counts, on
//!   all cores and on one thread;
//! * `fid`: `fid` on 200 vs 200 random vectors of 72 and 300 dimensions.
//!
//! When `../shared/data` is present, a sanity block also scores a few real clips of one
//! creature against themselves (coverage 100 and zero nearest-neighbour distances expected);
//! those numbers are printed, never stored.

mod common;
use common::{median, ms, time_runs, RUNS};

use menagerie::metrics::fid::{fid, FidOptions};
use menagerie::metrics::generation::{generation_metrics, GenerationOptions, PointClip, PointFeatures};
use menagerie::metrics::WorldClip;
use menagerie::motion::Motion;
use menagerie::repr::anytop::{AnyTopRig, RigOptions};
use menagerie::rng::SplitMix64;
use menagerie::skeleton::{roles, Skeleton};
use menagerie::synth::creature;
use std::hint::black_box;
use std::path::Path;

fn to_clip(skeleton: &Skeleton, motion: &Motion) -> WorldClip {
    let world = motion.forward_kinematics(skeleton);
    WorldClip {
        frames: motion.frames,
        joints: motion.joints,
        fps: 1.0 / motion.frame_time.max(1e-9),
        positions: world.positions,
        parents: skeleton.parents(),
        names: skeleton.joints.iter().map(|j| j.name.clone()).collect(),
        feet: roles::feet(skeleton).0,
        scale: skeleton.rest_extent(),
    }
}

/// `frames` frames of `p` from `start`, wrapping around (synthetic gaits loop).
fn crop(p: &PointClip, start: usize, frames: usize) -> PointClip {
    let values: Vec<f64> = (0..frames).flat_map(|t| p.frame((start + t) % p.frames()).to_vec()).collect();
    PointClip::new(frames, p.dims(), values).unwrap()
}

fn point_clip(skeleton: &Skeleton, motion: &Motion) -> PointClip {
    let clip = to_clip(skeleton, motion);
    let features = match AnyTopRig::new(skeleton, &motion.first_frames(2), &RigOptions::default()) {
        Ok(rig) => PointFeatures { facing: Some(rig.facing.clone()), scale: Some(rig.scale_factor) },
        Err(_) => PointFeatures::default(),
    };
    PointClip::from_clip_with(&clip, &features).unwrap()
}

fn main() {
    println!("generation metrics: 20 samples x 120 frames vs 10 GT clips x 100 frames; median of {RUNS} runs, {} threads", rayon::current_num_threads());
    println!("{:<12} {:>7} {:>12} {:>14} {:>10} {:>10} {:>10}", "creature", "joints", "median ms", "1-thread ms", "coverage", "local", "global");
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    for name in ["biped", "quadruped", "spider", "centipede", "dragon"] {
        let Some((skeleton, motion)) = creature(name, 1) else { continue };
        let base = point_clip(&skeleton, &motion);
        // Generated: crops at random starts with a little per-sample wobble; GT: other crops.
        let mut rng = SplitMix64::new(5);
        let generated: Vec<PointClip> = (0..20)
            .map(|_| {
                let c = crop(&base, (rng.unit() * base.frames() as f64) as usize, 120);
                let wobble = rng.range(-0.05, 0.05);
                let v: Vec<f64> = c.values().iter().enumerate().map(|(i, x)| x + wobble * ((i % 7) as f64 - 3.0) / 3.0).collect();
                PointClip::new(120, c.dims(), v).unwrap()
            })
            .collect();
        let gt: Vec<PointClip> = (0..10).map(|k| crop(&base, k * 17, 100)).collect();
        let opts = GenerationOptions::default();
        let report = generation_metrics(&generated, &gt, &opts).unwrap();
        let times = time_runs(|| {
            black_box(generation_metrics(&generated, &gt, &opts).unwrap());
        });
        let one = single.install(|| {
            time_runs(|| {
                black_box(generation_metrics(&generated, &gt, &opts).unwrap());
            })
        });
        println!(
            "{:<12} {:>7} {:>12.1} {:>14.1} {:>10.1} {:>10.4} {:>10.4}",
            name,
            skeleton.len(),
            ms(median(&times)),
            ms(median(&one)),
            report.coverage.mean,
            report.local_diversity.mean,
            report.global_diversity.mean
        );
    }

    println!();
    println!("fid: 200 vs 200 vectors; median of {RUNS} runs");
    println!("{:<8} {:>12}", "dims", "median ms");
    for dims in [72, 300] {
        let mut rng = SplitMix64::new(dims as u64);
        let mut set = || -> Vec<Vec<f64>> { (0..200).map(|_| (0..dims).map(|_| rng.range(-1.0, 1.0)).collect()).collect() };
        let (a, b) = (set(), set());
        let times = time_runs(|| {
            black_box(fid(&a, &b, &FidOptions::default()).unwrap());
        });
        println!("{:<8} {:>12.1}", dims, ms(median(&times)));
    }

    corpus_sanity();
}

/// A few clips of one real creature against themselves: printed only.
fn corpus_sanity() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bvh/truebones_anytop");
    let mut files = common::bvh_files(&dir);
    files.retain(|p| !p.to_string_lossy().to_lowercase().contains("tpos"));
    let Some(first) = files.first().cloned() else {
        println!("\nnote: {} is absent; skipping the corpus sanity check", dir.display());
        return;
    };
    let folder = first.parent().unwrap().to_path_buf();
    let mut clips = Vec::new();
    let mut skeleton0: Option<Skeleton> = None;
    for path in files.iter().filter(|p| p.parent() == Some(folder.as_path())).take(4) {
        let Ok(parsed) = menagerie::bvh::read_path(path) else { continue };
        let skeleton = Skeleton::from_bvh(&parsed);
        let motion = Motion::from_bvh(&parsed, &skeleton);
        if skeleton0.as_ref().is_some_and(|s| s.len() != skeleton.len()) {
            continue;
        }
        clips.push(point_clip(&skeleton, &motion));
        skeleton0.get_or_insert(skeleton);
    }
    let usable: Vec<PointClip> = clips.into_iter().filter(|c| c.frames() > 30).collect();
    println!("\ncorpus sanity: {} clips of {} against themselves", usable.len(), folder.display());
    match generation_metrics(&usable, &usable, &GenerationOptions::default()) {
        Ok(r) => println!("{}", serde_json::to_string_pretty(&r).unwrap()),
        Err(e) => println!("error: {e}"),
    }
}
