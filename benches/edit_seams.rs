//! In-betweening continuity with a trained model: the velocity jump at the seams between kept
//! and generated frames (`diffusion::edit::seam_jump`), for the known motion imposed at every
//! step (ours) against two baselines — plain sampling with the reference's frames pasted in
//! afterwards, and the upstream's editing, which imposes zeros (the mean pose) instead of the
//! reference (docs/reference/anytop.md §5), pasted afterwards too. Next to: the same statistic
//! inside the generated frames and over the reference clip itself (the training data).
//!
//!     MENAGERIE_EDIT_MODEL=/tmp/edit_model cargo bench --bench edit_seams
//!
//! (a model from `mo-train examples/data --out /tmp/edit_model --preset tiny --steps 300 ...`;
//! optional MENAGERIE_EDIT_CLIP = a BVH of a trained skeleton, default examples/data/quadruped.bvh,
//! kept frames: the first and last quarter). Each method's samples are also shown through
//! `mo-sample`'s output smoother at a few `--smooth`/`--blend` settings (our method only).
//! MENAGERIE_EDIT_QUICK=1 runs only DDIM 20 and our method (~2 minutes instead of ~25).
use candle_core::Device;
use menagerie::cli::load::read_skeleton;
use menagerie::diffusion::condition::SkeletonCondition;
use menagerie::diffusion::edit::{boundary_jumps, jump_distribution, jump_distribution_of, sample_edit, seam_jump, KeepMask};
use menagerie::diffusion::sample::{sample, SampleOptions};
use menagerie::diffusion::{checkpoint, Sampler};
use menagerie::repr::smooth::{lambda_for_cutoff, smooth_features};
use menagerie::repr::Features;
use std::path::PathBuf;

fn main() {
    let Some(model_dir) = std::env::var_os("MENAGERIE_EDIT_MODEL").map(PathBuf::from) else {
        println!("SKIP edit_seams: set MENAGERIE_EDIT_MODEL to a mo-train model directory");
        return;
    };
    let clip = std::env::var_os("MENAGERIE_EDIT_CLIP")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/data/quadruped.bvh"));
    let device = Device::Cpu;
    let loaded = checkpoint::load(&model_dir, &device).expect("model");
    let arg = read_skeleton(&clip).expect("clip");
    let skeleton = &arg.skeleton;
    let section = arg.record().expect("rig");
    if !loaded.info.skeletons.iter().any(|t| t.matches(skeleton)) {
        println!("SKIP edit_seams: {} is not a skeleton the model was trained on", clip.display());
        return;
    }
    let encoded = section.rig.encode(skeleton, arg.motion.as_ref().unwrap()).expect("encode");
    let reference = encoded.features;
    let (frames, j) = (reference.frames, reference.joints);
    let condition = SkeletonCondition::new(&loaded.info, skeleton, &section.rest_row).expect("condition");
    let stats = &condition.stats;
    let cond = condition.condition();
    let schedule = loaded.info.schedule();

    let quarter = frames / 4;
    let mut mask = KeepMask::new(frames, j);
    mask.keep_frames(&[0..quarter, frames - quarter..frames]);
    let kept = mask.whole_frames();
    let positions = |f: &Features| section.rig.recover_positions(skeleton, f, &encoded.placement).unwrap();
    let data = jump_distribution([(positions(&reference).as_slice(), j)]).unwrap();
    let paste = |mut f: Features| {
        for (k, v) in f.data.iter_mut().enumerate() {
            if mask.keep[k / 13] {
                *v = reference.data[k];
            }
        }
        f
    };
    let zeros = Features { frames, joints: j, dims: 13, data: stats.mean.iter().copied().cycle().take(frames * j * 13).collect() };

    println!(
        "{} ({frames} frames, {j} joints), kept 0..{quarter} and {}..{frames}; model {} (step {})",
        clip.display(),
        frames - quarter,
        model_dir.display(),
        loaded.info.step
    );
    println!("reference clip: boundary jumps median {:.4}, p95 {:.4}, max {:.4} (BVH units/frame)", data.median, data.p95, data.max);
    println!();
    println!("| method | sampler | seams median | seams max | seams <= data p95 | inside generated median | inside p95 | seconds |");
    println!("|---|---|---|---|---|---|---|---|");
    let n = 8;
    // MENAGERIE_EDIT_QUICK=1: DDIM and our method only (the DDPM rows take ~20 minutes).
    let quick = std::env::var_os("MENAGERIE_EDIT_QUICK").is_some();
    let samplers: &[(Sampler, usize)] = if quick { &[(Sampler::Ddim, 20)] } else { &[(Sampler::Ddim, 20), (Sampler::Ddpm, 100)] };
    let fps = if skeleton.frame_time > 0.0 { 1.0 / skeleton.frame_time } else { 30.0 };
    for &(sampler, steps) in samplers {
        let opts = SampleOptions { samples: n, frames, steps, sampler, seed: 1, lock: None };
        let methods: &[&str] = if quick { &["imposed every step"] } else { &["imposed every step", "paste after sampling", "upstream (zeros), pasted"] };
        for &method in methods {
            let started = std::time::Instant::now();
            let out: Vec<Features> = match method {
                "imposed every step" => sample_edit(&loaded.model, &schedule, &cond, &opts, &reference, &mask, &device).unwrap(),
                "paste after sampling" => sample(&loaded.model, &schedule, &cond, &opts, &device).unwrap().into_iter().map(paste).collect(),
                _ => sample_edit(&loaded.model, &schedule, &cond, &opts, &zeros, &mask, &device).unwrap().into_iter().map(paste).collect(),
            };
            let seconds = started.elapsed().as_secs_f64();
            // The raw samples, then the same samples through mo-sample's --smooth (kept cells
            // pinned): the smoother's share of the result is visible row by row.
            for (hz, blend) in [(0.0, 0.0), (4.0, 0.0), (6.0, 0.5), (4.0, 0.5), (3.0, 0.5)] {
                if hz > 0.0 && method != "imposed every step" {
                    continue;
                }
                let mut out = out.clone();
                let label = if hz == 0.0 {
                    method.to_string()
                } else {
                    let lambda = lambda_for_cutoff(hz, fps).unwrap();
                    for f in &mut out {
                        smooth_features(f, lambda, Some(&mask.keep), (blend * fps).round() as usize);
                    }
                    format!("{method}, --smooth {hz} --blend {blend}")
                };
                let mut seams = Vec::new();
                let mut inside = Vec::new();
                for f in &out {
                    let p = positions(f);
                    seams.extend(seam_jump(&p, j, &kept).iter().map(|s| s.jump));
                    let jumps = boundary_jumps(&p, j);
                    inside.extend((1..frames).filter(|&b| !kept[b] && !kept[b - 1]).map(|b| jumps[b - 1]));
                }
                let within = seams.iter().filter(|&&s| s <= data.p95).count();
                let s = jump_distribution_of(seams.clone()).unwrap();
                let g = jump_distribution_of(inside).unwrap();
                println!(
                    "| {label} | {sampler:?} {steps} | {:.4} | {:.4} | {within}/{} | {:.4} | {:.4} | {seconds:.1} |",
                    s.median,
                    s.max,
                    seams.len(),
                    g.median,
                    g.p95
                );
            }
        }
    }
}
