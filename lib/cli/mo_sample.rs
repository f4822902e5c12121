//! `mo-sample`: generate motion for any skeleton with a trained denoiser, or from a few example
//! clips of it without a model (`--examples`, in `mo_sample_examples`).

use crate::cli::load::read_skeleton;
use crate::cli::{output, CommonOpts};
use crate::diffusion::checkpoint;
use crate::diffusion::condition::{SkeletonCondition, StatsSource};
use crate::diffusion::edit;
use crate::diffusion::keep::Reference;
use crate::diffusion::sample::{sample, FootLock, PostProcess, SampleOptions, DEFAULT_BLEND_SECONDS, DEFAULT_SMOOTH_HZ};
use crate::diffusion::unseen;
use crate::diffusion::Sampler;
use crate::motion::write::MotionFormat;
use crate::repr::anytop::{AnyTopRig, IkOptions, Placement};
use crate::repr::Features;
use anyhow::{bail, Context};
use candle_core::Device;
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    skel-info examples/data/quadruped.bvh | mo-sample -n 4 > out.npy
    mo-sample examples/data/dragon.bvh -n 2 --seconds 2 --bvh 'dragon_{i}.bvh'
    mo-sample examples/data/quadruped.bvh -n 2 --seconds 4 --lock-feet --bvh 'walk_{i}.bvh'
    skel-info examples/data/dragon.bvh | mo-sample --model model -n 2 --frames 30 --steps 5 > d.npy
    mo-sample examples/data/spider.bvh --model model --frames 30 --steps 5 --bvh 'spider_{i}.bvh'
    mo-sample examples/data/quadruped.bvh --model model --frames 40 --steps 5 --bvh q.bvh
    mo-sample --reference q.bvh --model model --steps 5 --keep-frames 0-9,30-38 --report > ib.npy
    mo-sample --reference q.bvh --model model --steps 5 --keep-joints '*Thigh/' --bvh legs.bvh
    mo-sample --examples examples/data/dragon.bvh -n 2 --frames 200 --bvh 'gen_{i}.bvh'
    mo-sample examples/data/crab.bvh --examples examples/data/crab.bvh --seconds 10 > crab.npy
    mo-sample --examples gen_0.bvh --reference gen_1.bvh --keep-frames 0-29,170-199 > ib.npy
    mo-sample examples/data/dragon.bvh --model my_dragon -n 2 --frames 60 --bvh 'my_dragon_{i}.bvh'";

/// Frames per sample (`--frames`, `--seconds`): the denoiser attends over all frames at once.
pub const MAX_SAMPLE_FRAMES: u64 = 10_000;

/// `--seconds S` as frames at `fps`, at most `MAX_SAMPLE_FRAMES` (both ways of sampling).
pub fn sample_frames(seconds: f64, fps: f64) -> anyhow::Result<usize> {
    match crate::cli::bounds::frames_for_seconds(seconds, fps).map_err(anyhow::Error::msg)? {
        n if n as u64 > MAX_SAMPLE_FRAMES => bail!("--seconds {seconds} is {n} frames at {fps:.3} fps, more than the {MAX_SAMPLE_FRAMES} a sample may have"),
        n => Ok(n),
    }
}

/// Generate motion for a skeleton with a trained diffusion model (AnyTop), or from a few clips
/// of it with no model at all (--examples, GenMM).
///
/// Your own creature, three ways: the built-in model as it is (any skeleton, no clips; best on
/// creatures like its synthetic zoo); --examples with a clip or more of it (no training, new
/// motion made of the clips' own pieces); or a model fine-tuned on its clips in a few minutes
/// (`mo-train CLIPS --init builtin --minutes 5 --out DIR`, then --model DIR).
///
/// SKELETON is a skeleton document (skel-info's JSON, also on stdin) or a BVH file. The model
/// needs only the skeleton's topology, rest pose and joint names, so skeletons never seen in
/// training work too. Output: NPY [n, frames, joints, 13] AnyTop features in physical units on
/// stdout (or -o), or BVH files with --bvh PATTERN ('{i}' = sample index), posed by inverse
/// kinematics from the generated joint positions.
///
/// Normalisation: a skeleton the model was trained on uses its training statistics; any other
/// takes its rest-pose row as the mean and the trained skeletons' average spreads (-v says so),
/// also when its document carries statistics, so a file and its skel-info document give the
/// same samples (fine-tune on its clips to give a model its own). A trained skeleton (same names,
/// parents and proportions) also keeps the rest pose training took from its first clip, so any of
/// its files or documents gives the same samples (-v says so); another skeleton's rest pose is
/// the first frame of the file given. A model directory may hold a second denoiser in unseen/,
/// trained under that rest-pose normalisation (mo-train --fallback-stats all); it samples every
/// skeleton the main one was not trained on. The built-in model has one: its main denoiser
/// moves its own zoo like the clips but stands other skeletons still, its unseen one moves them
/// (held-out dragon: 0.90 of the clip's motion against 0.42).
///
/// Sampling: the default, 10 DDIM steps, keeps `mo-sample -n 4` of a 40-joint creature under
/// 10 s on two slow cores; --steps 100 --sampler ddpm is the reference's full ancestral loop
/// (fewer ddpm steps respace it). Quality against steps: models/zoo-small/MODEL_CARD.md. The
/// same seed, model and input give the same output.
///
/// Editing (AnyTop §5): --reference names a clip of the same skeleton; --keep-frames keeps
/// whole frames of it (in-betweening: '0-19,100-119' generates the frames between) and
/// --keep-joints keeps joints over all its frames (body-part editing: '*Thigh/' keeps the thighs
/// and all below them, generates the rest); both together keep the union. The kept part is
/// imposed at every diffusion step, and the output's kept values are the reference's exactly.
/// Only the joints named are kept: a kept leg whose root is generated moves with the generated
/// root (positions are root-relative), so add the root to keep the legs in place. The output has
/// the reference's length (its BVH frames minus one: AnyTop features drop the last frame)
/// unless --frames or --seconds says otherwise; frames past the reference's end are generated.
/// BVH output stands where the reference stood.
///
/// Smoothing: the model's raw frames jitter (mean jerk 6-370x the training clips' for the
/// built-in model), so the output is low-passed over time, --smooth HZ being where motion keeps
/// half its amplitude (a Whittaker smoother; slow motion passes, straight lines exactly). Kept
/// frames and joints stay exact; generated frames next to kept ones give way to them over
/// --blend seconds, so a transition continues the kept motion with its velocity instead of
/// jumping. --smooth 0 gives the model's raw output.
///
/// --report prints one JSON line on stderr: per sample, the velocity jump at every seam
/// between kept and generated frames (mean over joints of the largest change of a joint's
/// velocity at the boundary, BVH units per frame), next to the distribution of the same
/// number over every frame boundary of the reference clip (median, p95, max) and over the
/// boundaries inside the generated frames. A seam jump no larger than the reference's p95 is
/// as continuous as the clip itself.
///
/// Example-based generation (--examples CLIPS..., generative motion matching, GenMM, Li et al.
/// 2023): no model and no training. CLIPS are BVH files or directories of them, all of one
/// skeleton and frame rate; the output is new motion stitched from their patches, coarse to
/// fine over a pyramid in time: the coarsest level starts as a seeded random walk through the
/// clips' coarse patches (jumping between similar places), and every level replaces each patch
/// (11 frames) by its nearest clip patch and averages the overlaps; the root's turning is kept
/// as a rate, so stitched stretches turn smoothly. Two 200-frame samples take 0.04-0.44 s,
/// growing with the clips' length and joint count (benches/genmm_cli.sh). Any
/// length (default: the longest clip's; --frames, --seconds), -n samples with seeds --seed,
/// --seed+1, ... (the same seed gives the same bytes); BVH on the clips' skeleton with --bvh,
/// else NPY [n, frames, joints, 9] of Motion2Motion features (decode with mo-encode --repr m2m
/// --decode, or read with mo-metrics and mo-render). SKELETON, if given, must be the clips'
/// skeleton. Editing works as above: --reference (a clip of the same skeleton and frame rate)
/// with --keep-frames/--keep-joints; the kept part is imposed at every level and is the
/// reference's exactly in the output, whose default length is the reference's frame count.
/// --report prints the pyramid levels and match costs as one JSON line on stderr. --model,
/// --steps, --sampler, --smooth, --blend and --no-plant-feet belong to the diffusion model.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-sample", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// Skeleton document or BVH ('-' = stdin) [default: stdin; with --reference: the reference;
    /// with --examples: the clips' own].
    #[arg(value_name = "SKELETON")]
    pub skeleton: Option<PathBuf>,
    /// The same as SKELETON, as a named option.
    #[arg(long = "skeleton", value_name = "PATH", conflicts_with = "skeleton")]
    pub skeleton_option: Option<PathBuf>,
    /// Model directory written by mo-train, with an optional unseen/ model directory beside
    /// its files for skeletons it was not trained on [default: the built-in model, a compact
    /// denoiser pair trained on the synthetic zoo; see models/zoo-compact/MODEL_CARD.md].
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
    /// Number of samples.
    #[arg(short = 'n', long = "samples", value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub samples: u64,
    /// Frames per sample [default: 120; with --reference: the reference's length; with
    /// --examples: the longest clip's].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=MAX_SAMPLE_FRAMES), conflicts_with = "seconds")]
    pub frames: Option<u64>,
    /// Length in seconds (at the skeleton's frame rate).
    #[arg(long, value_name = "S", value_parser = crate::cli::bounds::positive(crate::cli::bounds::MAX_SECONDS))]
    pub seconds: Option<f64>,
    /// Diffusion steps to visit (1..=100).
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub steps: u64,
    /// Sampler.
    #[arg(long, value_enum, default_value_t = Sampler::Ddim)]
    pub sampler: Sampler,
    /// Write BVH files instead of NPY ('{i}' becomes the sample index); named .glb or .gltf: glTF.
    #[arg(long, value_name = "PATTERN")]
    pub bvh: Option<PathBuf>,
    /// A clip of the same skeleton (BVH) to keep parts of (needs --keep-frames or --keep-joints).
    #[arg(long, value_name = "REF.bvh")]
    pub reference: Option<PathBuf>,
    /// In-betweening: output frames taken from the reference, e.g. '0-19,100-119' (inclusive).
    #[arg(long, value_name = "RANGES", requires = "reference")]
    pub keep_frames: Option<String>,
    /// Body-part editing: joints taken from the reference: names or globs ('*Leg*'), 'Name/' for
    /// a joint and all its descendants, comma-separated.
    #[arg(long, value_name = "LIST", requires = "reference")]
    pub keep_joints: Option<String>,
    /// Print seam continuity as one JSON line on stderr (with --reference), or with --examples
    /// the synthesis levels and match costs.
    #[arg(long)]
    pub report: bool,
    /// Example-based generation, no model (GenMM): clips of the skeleton, BVH files or
    /// directories of them.
    #[arg(long, value_name = "CLIPS", num_args = 1.., conflicts_with_all = ["model", "steps", "sampler", "smooth", "blend", "no_plant_feet", "lock_feet"])]
    pub examples: Vec<PathBuf>,
    /// Low-pass the generated frames over time: the cutoff in Hz where motion keeps half its
    /// amplitude (kept frames and joints stay exact; 0 = the model's raw output).
    #[arg(long, value_name = "HZ", default_value_t = DEFAULT_SMOOTH_HZ)]
    pub smooth: f64,
    /// Editing with --smooth: generated frames next to kept ones give way to them over this
    /// many seconds, continuing the kept motion instead of jumping to the generated one.
    #[arg(long, value_name = "S", default_value_t = DEFAULT_BLEND_SECONDS)]
    pub blend: f64,
    /// Keep the model's root travel even where it makes planted feet slide (by default the
    /// root's horizontal motion follows the feet the model puts on the ground).
    #[arg(long)]
    pub no_plant_feet: bool,
    /// Hold planted feet in place: in the last sampling steps (the last three of DDIM's 10)
    /// each foot the model puts down near the ground is held where it landed, its leg bent to
    /// reach, and the remaining steps fit the body to it. Measured on the built-in model
    /// (models/zoo-compact/MODEL_CARD.md): the zoo quadruped's feet slide 0.39 -> 0.11 body
    /// sizes/s (its clips 0-0.12) with poses as near its clips, but it moves a fifth less and
    /// the spider 28% less; so it is not the default.
    #[arg(long)]
    pub lock_feet: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if !args.examples.is_empty() {
        return super::mo_sample_examples::run(args);
    }
    if args.report && args.reference.is_none() {
        bail!("--report needs --reference (seam continuity) or --examples (the synthesis levels)");
    }
    crate::nn::keep_freed_memory();
    let count = args.samples as usize;
    let outputs = args.bvh.as_deref().map(|p| output::numbered(p, count)).transpose()?;
    let dash = PathBuf::from("-");
    let arg = read_skeleton(args.skeleton.as_ref().or(args.skeleton_option.as_ref()).or(args.reference.as_ref()).unwrap_or(&dash))?;
    let skeleton = &arg.skeleton;
    let device = Device::Cpu;
    let loaded = checkpoint::frozen_or_default(args.model.as_deref(), &device)?;
    // A skeleton the model was trained on is conditioned and decoded on the record training
    // built (its rest clip's first frames), whichever of its files or documents is given.
    let section = match checkpoint::trained_record(&loaded.info.skeletons, skeleton) {
        Some((file, record)) => {
            args.common.say("mo-sample").info(format_args!("{}: a trained skeleton: its rest pose is the one training used (frame 0 of {file})", arg.name));
            record.with_context(|| format!("{}: the rest pose training used (frame 0 of {file})", arg.name))?
        }
        None => arg.record()?,
    };
    // A skeleton the model was not trained on is sampled by the model's unseen-skeleton
    // denoiser when it has one: trained under the normalisation such a skeleton gets below, it
    // moves skeletons the main one stands still (`diffusion::unseen`).
    let unseen = match checkpoint::find_trained(&loaded.info.skeletons, skeleton) {
        Some(_) => None,
        None => unseen::frozen_or_default(args.model.as_deref(), &device)?,
    };
    let denoiser = unseen.as_ref().unwrap_or(&loaded);
    // The warning judges the skeleton against the denoiser that samples it, by that one's limit.
    let known = match &unseen {
        Some(u) => super::ood::Known::unseen_denoiser(args.model.as_deref(), &u.info)?,
        None => super::ood::Known::denoiser(args.model.as_deref(), &loaded.info)?,
    };
    known.warn("mo-sample", &arg.name, skeleton, args.common.quiet)?;
    let fps = if skeleton.frame_time > 0.0 { 1.0 / skeleton.frame_time } else { 30.0 };
    let reference = match &args.reference {
        Some(path) => {
            if args.keep_frames.is_none() && args.keep_joints.is_none() {
                bail!("--reference needs --keep-frames RANGES or --keep-joints LIST (what to keep of it)");
            }
            Some(Reference::read(path, &crate::cli::load::gltf_options(), &arg.name, skeleton, &section.rig)?)
        }
        None => None,
    };
    let frames = match args.seconds {
        Some(s) => sample_frames(s, fps)?,
        None => match (args.frames, &reference) {
            (Some(n), _) => n as usize,
            (None, Some(r)) => r.features.frames,
            (None, None) => 120,
        },
    };
    // Every sample goes through the denoiser at once: a few activations of its width per
    // joint and frame.
    let tokens = count as u128 * frames as u128 * skeleton.len() as u128;
    crate::budget::check(&format!("{count} samples of {frames} frames on {} joints", skeleton.len()), tokens, denoiser.info.config.width * 4 * 4)?;
    let mask = reference.as_ref().map(|r| r.mask(args.keep_frames.as_deref(), args.keep_joints.as_deref(), skeleton, frames)).transpose()?;

    // A skeleton the model never saw is normalised by its rest pose and the trained skeletons'
    // spreads even when its document carries statistics of its own motion: with those, the
    // built-in model's poses were 2-12x farther from the clip's on six real skeletons
    // (models/zoo-compact/MODEL_CARD.md, "The pipe and the file"), and the file and the pipe
    // now sample alike.
    let condition = SkeletonCondition::new(&denoiser.info, skeleton, &section.rest_row).with_context(|| arg.name.clone())?;
    if condition.stats_source == StatsSource::Fallback {
        let by = if unseen.is_some() { ", with the model's unseen-skeleton denoiser" } else { "" };
        args.common
            .say("mo-sample")
            .info(format_args!("{}: not a trained skeleton: normalising by its rest pose and the trained skeletons' spreads{by}", arg.name));
    }
    let cond = condition.condition();
    let post = PostProcess::new(args.smooth, args.blend, !args.no_plant_feet, fps, crate::cli::bounds::MAX_SECONDS)?;
    let schedule = denoiser.info.schedule();
    let fixed = mask.as_ref().map(|m| m.keep.as_slice());
    let lock = args.lock_feet.then(|| {
        let size = skeleton.rest_extent() * section.rig.scale_factor;
        FootLock::new(section.rig.feet.clone(), skeleton.parents(), size, fps, fixed.map(<[bool]>::to_vec))
    });
    let opts = SampleOptions { samples: count, frames, steps: args.steps as usize, sampler: args.sampler, seed: args.common.seed, lock };
    let started = std::time::Instant::now();
    let mut samples = match (&reference, &mask) {
        (Some(r), Some(mask)) => edit::sample_edit(&denoiser.model, &schedule, &cond, &opts, &r.features.padded_to(frames), mask, &device)?,
        _ => sample(&denoiser.model, &schedule, &cond, &opts, &device)?,
    };
    for f in &mut samples {
        post.apply(f, &section.rig.feet, fixed);
    }
    if let (true, Some(r), Some(mask)) = (args.report, &reference, &mask) {
        let report =
            edit::seam_report(&section.rig, skeleton, (&r.name, &r.features, &r.placement), mask, &samples).map_err(|e| anyhow::anyhow!("--report: {e}"))?;
        eprintln!("{report}");
    }
    args.common.say("mo-sample").info(format_args!("{count} x {frames} frames in {:.2} s", started.elapsed().as_secs_f64()));

    // An edit stands where its reference stood, so kept frames land on the reference's.
    let placement = reference.as_ref().map_or_else(|| section.rig.rest_placement(), |r| r.placement);
    write_samples(args, outputs, &samples, &section.rig, skeleton, &placement)
}

/// The samples as BVH files (`--bvh PATTERN`, all or none) or one NPY batch.
fn write_samples(
    args: &Args,
    outputs: Option<Vec<PathBuf>>,
    samples: &[Features],
    rig: &AnyTopRig,
    skeleton: &crate::skeleton::Skeleton,
    placement: &Placement,
) -> anyhow::Result<()> {
    let Some(paths) = outputs else {
        return output::write_npy(args.common.output.as_deref(), samples, true, "redirect stdout, or give -o FILE or --bvh PATTERN");
    };
    let decode = |(i, f): (usize, &Features)| rig.decode_ik(skeleton, f, placement, &IkOptions::default()).map_err(|e| anyhow::anyhow!("sample {i}: {e}"));
    let motions = samples.iter().enumerate().map(decode).collect::<anyhow::Result<Vec<_>>>()?;
    output::write_motions(skeleton, &motions, &paths.into_iter().map(Some).collect::<Vec<_>>(), MotionFormat::Bvh)
}
