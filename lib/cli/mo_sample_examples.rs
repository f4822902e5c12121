//! `mo-sample --examples CLIPS...`: example-based generation without a model (GenMM). This file
//! reads the clips (and the optional SKELETON and `--reference`), turns the options into
//! `genmm::Settings` and a `genmm::Keep`, runs `genmm::generate` (one seed per sample), and
//! writes BVH on the examples' skeleton or Motion2Motion features, all outputs or none.

use super::mo_sample::{sample_frames, Args};
use crate::cli::load::{is_dash, read_bvh_clip, read_example_clips, read_skeleton};
use crate::cli::output;
use crate::diffusion::keep::Kept;
use crate::genmm::{self, Keep, Settings};
use crate::motion::write::MotionFormat;
use crate::motion::Clip;
use crate::repr::m2m;
use anyhow::{bail, Context};
use std::time::Instant;

pub fn run(args: &Args) -> anyhow::Result<()> {
    let started = Instant::now();
    let count = args.samples as usize;
    let outputs = args.bvh.as_deref().map(|p| output::numbered(p, count)).transpose()?;
    let skeleton_path = args.skeleton.as_ref().or(args.skeleton_option.as_ref());
    let dashes = args.examples.iter().chain(skeleton_path).chain(args.reference.as_ref()).filter(|p| is_dash(p)).count();
    if dashes > 1 {
        bail!("stdin ('-') can be read only once");
    }
    if args.reference.is_some() && args.keep_frames.is_none() && args.keep_joints.is_none() {
        bail!("--reference needs --keep-frames RANGES or --keep-joints LIST (what to keep of it)");
    }
    let clips = read_example_clips(&args.examples, "mo-sample --examples", "example clips")?;
    let first = &clips[0];
    let skeleton = &first.skeleton;
    if let Some(path) = skeleton_path {
        let given = read_skeleton(path)?;
        if let Some(why) = given.skeleton.first_difference(skeleton) {
            bail!("{} is not the skeleton of the example clips ({}): {why}", given.name, first.name);
        }
    }
    let frame_time = first.motion.frame_time;
    let fps = if frame_time > 0.0 { 1.0 / frame_time } else { 30.0 };
    let reference = args.reference.as_deref().map(|path| read_reference(path, first)).transpose()?;
    let frames = match (args.seconds, args.frames, &reference) {
        (Some(s), _, _) => sample_frames(s, fps)?,
        (None, Some(n), _) => n as usize,
        (None, None, Some(r)) => r.motion.frames,
        (None, None, None) => clips.iter().map(|c| c.motion.frames).max().unwrap_or(1),
    };
    crate::budget::check_motion(&format!("{count} samples of {frames} frames"), count.saturating_mul(frames), skeleton.len())?;
    let keep = reference.as_ref().map(|r| keep(args, r, frames)).transpose()?;

    let motions: Vec<crate::motion::Motion> = clips.iter().map(|c| c.motion.clone()).collect();
    let settings = Settings { frames: Some(frames), ..Settings::default() };
    let seeds: Vec<u64> = (0..count as u64).map(|i| args.common.seed.wrapping_add(i)).collect();
    let generated_at = Instant::now();
    let generated = genmm::generate(&motions, skeleton, &settings, keep.as_ref(), &seeds).with_context(|| format!("generating from {}", first.name))?;
    let generation = generated_at.elapsed();

    if args.report {
        eprintln!("{}", genmm::clips::report(&clips, &generated, generation));
    }
    let say = args.common.say("mo-sample");
    say.info(format_args!("{count} x {frames} frames from {} example clip(s) in {:.3} s", clips.len(), generation.as_secs_f64()));
    if !args.common.quiet {
        for note in genmm::clips::notes(&generated) {
            say.note(note);
        }
    }

    match outputs {
        Some(paths) => {
            output::write_motions(skeleton, generated.iter().map(|g| &g.motion), &paths.into_iter().map(Some).collect::<Vec<_>>(), MotionFormat::Bvh)?
        }
        None => {
            let features: Vec<_> = generated.iter().map(|g| m2m::encode(&g.motion)).collect();
            output::write_npy(args.common.output.as_deref(), &features, true, "redirect stdout, or give -o FILE or --bvh PATTERN")?;
        }
    }
    say.info(format_args!("total {:.3} s", started.elapsed().as_secs_f64()));
    Ok(())
}

/// `--reference`: a clip of the examples' skeleton at their frame rate.
fn read_reference(path: &std::path::Path, first: &Clip) -> anyhow::Result<Clip> {
    let r = read_bvh_clip(path, "mo-sample --reference")?;
    genmm::clips::check_reference(first, &r)?;
    Ok(r)
}

/// What `--keep-frames` and `--keep-joints` keep (`diffusion::keep`).
fn keep<'a>(args: &Args, r: &'a Clip, frames: usize) -> anyhow::Result<Keep<'a>> {
    let why = format!("the output has {frames} frames, the reference {} has {}", r.name, r.motion.frames);
    let kept = Kept::resolve(args.keep_frames.as_deref(), args.keep_joints.as_deref(), &r.skeleton, frames, r.motion.frames, &why)?;
    Ok(Keep { reference: &r.motion, frames: kept.frames, joints: kept.joints })
}
