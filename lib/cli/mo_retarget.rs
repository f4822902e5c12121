//! `mo-retarget`: cross-topology motion transfer (Motion2Motion). This file reads the source
//! and the target's example clips, resolves or computes the binding, matches frame rates,
//! calls `retarget::retarget_samples`, and writes BVH (or NPY) on the target skeleton. All
//! outputs are built in memory first, so a failure never leaves some files written.

use crate::cli::bounds;
use crate::cli::load::{is_dash, read_bvh_clip, read_example_clips, read_skeleton};
use crate::cli::output::{self, OutFormat};
use crate::cli::CommonOpts;
use crate::io;
use crate::motion::write::motion_file;
use crate::motion::Clip;
use crate::motion::Motion;
use crate::repr::m2m;
use crate::retarget::{self, BoundRotation, Repr, RootMotion, Settings};
use anyhow::{bail, Context};
use std::path::PathBuf;
use std::time::Instant;

const EXAMPLES: &str = "\
EXAMPLES:
    mo-retarget examples/data/biped.bvh examples/data/quadruped.bvh --bind auto -o quad.bvh
    mo-retarget examples/data/biped.bvh examples/data/quadruped.bvh --bind auto --emit-binding
    mo-retarget examples/data/quadruped.bvh examples/data/dragon.bvh --bind auto -n 3 -o 'd_{i}.bvh'
    mo-retarget examples/data/biped.bvh examples/data/biped.bvh --bind auto --seconds 2 -o b.bvh
    cat examples/data/spider.bvh | mo-retarget - examples/data/crab.bvh --bind auto --format npy
    mo-retarget --method latent examples/data/biped.bvh --to examples/data/quadruped.bvh -o q.bvh
    mo-retarget examples/data/quadruped.bvh examples/data/dragon.bvh --bind auto -o dragon.glb";

/// Transfer a motion to a different skeleton from a few example clips of it (Motion2Motion).
///
/// SOURCE is a BVH or glTF (path or '-'); TARGETS are example clips of the target skeleton (BVH or glTF files
/// or directories of them; all must share one skeleton). No training: the result is stitched
/// from patches of the examples, chosen coarse-to-fine so that the bound joints follow the
/// source and everything else moves like the examples do.
///
/// Binding: --bind FILE reads pairs source joint -> target joint (our JSON or the reference's
/// {\"mapping\": [{\"source\", \"target\"}]}); names match exactly, by case, without namespace
/// or by normalised name, never by substring. --bind auto binds every confident pair of the
/// joint correspondence that `mo-dift --joints` prints (names with their sides and ordinals,
/// front and hind limbs, topology and rest pose, one to one): the same side, the same limb
/// pair, joints that move a bone, no toes, inside a limb the same place along both limbs with
/// bones pointing the same way, no one-bone limb with a jointed one, and each matched limb tied
/// at its first joint and its end (foot, hand or tip; a bird's and a mammal's ankles where
/// their legs differ below the knee); --bind-rate R keeps at most that rate (the paper's 0.061
/// gives its sparse binding); --emit-binding prints it as JSON to inspect, edit and reuse
/// instead of retargeting.
///
/// Frame rates: the source is resampled to the examples' rate when they differ (said on
/// stderr). Output length: the source's, or --frames / --seconds. --key-frames makes the
/// source count only at those frames; the rest is synthesised.
///
/// Output: BVH on the target skeleton with its channel orders and End Sites (default), or
/// --format npy (Motion2Motion features [frames, joints, 9], or [n, frames, joints, 9] for -n).
/// -n K writes K diverse samples (seeds --seed .. --seed+K-1) to -o PATTERN with '{i}'.
/// --report prints timing, the binding, pyramid levels and per-level match cost on stderr.
///
/// --method latent (SATA, zero-shot): the source is encoded by the latent model (--model, or
/// the built-in one trained on the synthetic zoo) into one vector per frame and decoded onto
/// the target skeleton (--to, a BVH or skeleton document, or the first of TARGETS), conditioned
/// only on its rest pose, topology and joint names (a skeleton the model was trained on keeps
/// its training rig and rest pose, from the model's rigs.json). No example clips and no
/// binding; the output has the source's frame time and one frame fewer than the source.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-retarget", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// The motion to transfer: a BVH file ('-' = stdin).
    #[arg(value_name = "SOURCE")]
    pub source: PathBuf,
    /// Example clips of the target skeleton: BVH files or directories (with --method latent,
    /// only the first is read, for its skeleton; or give --to).
    #[arg(value_name = "TARGETS", required_unless_present = "to", num_args = 0..)]
    pub targets: Vec<PathBuf>,
    /// m2m: binding JSON file, or 'auto' (required).
    #[arg(long, value_name = "FILE|auto")]
    pub bind: Option<String>,
    /// How to transfer: m2m (Motion2Motion, from example clips and a sparse binding) or latent
    /// (zero-shot through the SATA latent model: no examples, no binding).
    #[arg(long, value_enum, default_value_t = Method::M2m)]
    pub method: Method,
    /// latent: the target skeleton, a BVH or a skeleton document (instead of TARGETS).
    #[arg(long, value_name = "PATH")]
    pub to: Option<PathBuf>,
    /// latent: the model directory from 'mo-train --arch sata' [default: the built-in one].
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
    /// Limit of --bind auto: at most this binding rate, 2 x pairs / (source joints + target
    /// joints) (the paper: 0.061) [default: every confident pair].
    #[arg(long, value_name = "R", value_parser = bounds::positive(1.0))]
    pub bind_rate: Option<f64>,
    /// Print the binding (JSON) and stop.
    #[arg(long)]
    pub emit_binding: bool,
    /// Number of diverse samples.
    #[arg(short = 'n', long = "samples", value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub samples: u64,
    /// Output length in frames [default: the source's, after resampling].
    #[arg(long, value_name = "N", conflicts_with = "seconds", value_parser = bounds::count(1, bounds::MAX_FRAMES))]
    pub frames: Option<usize>,
    /// Output length in seconds.
    #[arg(long, value_name = "S", value_parser = bounds::positive(bounds::MAX_SECONDS))]
    pub seconds: Option<f64>,
    /// Key-frame mode: the source counts only at these frames (comma-separated, source frames).
    #[arg(long, value_name = "F,F,...", value_delimiter = ',')]
    pub key_frames: Option<Vec<usize>>,
    /// Output format on stdout: BVH, glTF (glb: binary, gltf: JSON) or Motion2Motion features (npy). An -o file named .glb or .gltf is written as glTF.
    #[arg(long, value_enum, default_value_t = OutFormat::Bvh)]
    pub format: OutFormat,
    /// Patch length in frames (paper: 11).
    #[arg(long, value_name = "FRAMES", value_parser = bounds::count(1, bounds::MAX_PATCH))]
    pub patch: Option<usize>,
    /// Weight of the bound (source) channels in matching, 0..1 (paper: 0.85).
    #[arg(long, value_name = "A")]
    pub alpha: Option<f64>,
    /// Match-and-blend iterations per pyramid level (paper: 3).
    #[arg(long, value_name = "L", value_parser = bounds::count(1, bounds::MAX_RETARGET_STEPS))]
    pub steps: Option<usize>,
    /// Scale between pyramid levels (paper: 0.75).
    #[arg(long, value_name = "S")]
    pub pyramid: Option<f64>,
    /// Matching features (paper table 4).
    #[arg(long, value_enum)]
    pub repr: Option<Repr>,
    /// How bound joints take the source's rotation.
    #[arg(long, value_enum)]
    pub bound_rotation: Option<BoundRotation>,
    /// Where the root trajectory comes from.
    #[arg(long, value_enum)]
    pub root_motion: Option<RootMotion>,
    /// After synthesis, overwrite the bound channels with the source's (the paper's "directly
    /// copy", the reference's copy mode): bound joints follow the source exactly.
    #[arg(long)]
    pub copy_bound: bool,
    /// Print timing, binding, pyramid levels and per-level match cost on stderr.
    #[arg(long)]
    pub report: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    M2m,
    Latent,
}

/// `--method latent`: encode the source with the latent model, decode onto the target skeleton.
fn run_latent(args: &Args) -> anyhow::Result<()> {
    let m2m_only = [
        (args.bind.is_some(), "--bind"),
        (args.emit_binding, "--emit-binding"),
        (args.samples != 1, "-n"),
        (args.frames.is_some() || args.seconds.is_some(), "--frames/--seconds"),
        (args.key_frames.is_some(), "--key-frames"),
        (args.format == OutFormat::Npy, "--format npy"),
        (args.patch.is_some() || args.alpha.is_some() || args.steps.is_some() || args.pyramid.is_some(), "--patch/--alpha/--steps/--pyramid"),
        (
            args.repr.is_some() || args.bound_rotation.is_some() || args.root_motion.is_some() || args.copy_bound,
            "--repr/--bound-rotation/--root-motion/--copy-bound",
        ),
    ];
    if let Some((_, flag)) = m2m_only.iter().find(|(on, _)| *on) {
        bail!("{flag} belongs to --method m2m; the latent method decodes one motion, as long as the source");
    }
    let target_path = match (&args.to, args.targets.first()) {
        (Some(to), _) => to.clone(),
        (None, Some(first)) => first.clone(),
        (None, None) => bail!("--method latent needs the target skeleton: --to PATH or a TARGETS clip"),
    };
    if is_dash(&args.source) && is_dash(&target_path) {
        bail!("stdin ('-') can be read only once");
    }
    let started = Instant::now();
    let device = candle_core::Device::Cpu;
    let model = crate::sata::clips::frozen_or_default(args.model.as_deref(), &device)?;
    let source = crate::sata::clips::SourceClip::read(&args.source, &crate::cli::load::gltf_options(), &model, &device)?;
    let target = crate::sata::clips::Target::new(read_skeleton(&target_path)?, &model, &device)?;
    let known = super::ood::Known::latent(args.model.as_deref(), &model.rigs)?;
    for (name, skeleton) in [(&source.name, &source.skeleton), (&target.file.name, &target.file.skeleton)] {
        known.warn("mo-retarget", name, skeleton, args.common.quiet)?;
    }
    let latents = source.encode(&model, &device)?;
    let motion = target.decode(&model, &latents, source.motion.frame_time, &device)?;
    let bytes = motion_file(&target.file.skeleton, &motion, args.common.output.as_deref(), args.format.motion())?;
    if args.report {
        eprintln!(
            "mo-retarget: latent: {} ({} joints) -> {} ({} joints), {} frames, latent {} per frame, {:.2} s",
            source.name,
            source.skeleton.len(),
            target.file.name,
            target.file.skeleton.len(),
            latents.frames,
            latents.dims,
            started.elapsed().as_secs_f64()
        );
    }
    Ok(io::write_output(args.common.output.as_deref(), &bytes)?)
}

fn settings(args: &Args, fps: f64, source_frames: usize) -> anyhow::Result<Settings> {
    // --patch, --steps and --frames are at least 1 (clap's `bounds::count`).
    let d = Settings::default();
    let (repr, bound_rotation, root_motion) =
        (args.repr.unwrap_or(d.repr), args.bound_rotation.unwrap_or(d.bound_rotation), args.root_motion.unwrap_or(d.root_motion));
    let (patch, steps) = (args.patch.unwrap_or(d.patch), args.steps.unwrap_or(d.steps));
    let mut s = Settings { seed: args.common.seed, copy_bound: args.copy_bound, patch, steps, repr, bound_rotation, root_motion, ..d };
    if let Some(a) = args.alpha {
        if !(0.0..=1.0).contains(&a) {
            bail!("--alpha must be within 0..1, found {a}");
        }
        s.alpha = a as f32;
    }
    if let Some(p) = args.pyramid {
        if !(p > 0.0 && p < 1.0) {
            bail!("--pyramid must be within (0, 1), found {p}");
        }
        s.pyramid = p;
    }
    s.frames = match (args.frames, args.seconds) {
        (Some(n), _) => Some(n),
        (None, Some(sec)) => Some(bounds::frames_for_seconds(sec, fps).map_err(anyhow::Error::msg)?),
        (None, None) => None,
    };
    if let Some(keys) = &args.key_frames {
        if keys.is_empty() {
            bail!("--key-frames needs at least one frame");
        }
        if let Some(&k) = keys.iter().find(|&&k| k >= source_frames) {
            bail!("--key-frames: frame {k} is past the source's last frame {}", source_frames.saturating_sub(1));
        }
        s.key_frames = Some(keys.clone());
    }
    Ok(s)
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if args.method == Method::Latent {
        return run_latent(args);
    }
    if args.to.is_some() || args.model.is_some() {
        bail!("--to and --model belong to --method latent; Motion2Motion reads TARGETS (example clips)");
    }
    if args.targets.is_empty() {
        bail!("Motion2Motion needs TARGETS: example clips of the target skeleton");
    }
    let Some(bind) = args.bind.as_deref() else { bail!("--bind is required with --method m2m: a binding JSON file, or 'auto'") };
    let started = Instant::now();
    let count = args.samples as usize;
    let outputs = output_paths(args, count)?;
    let (source, examples) = read_inputs(args)?;
    let first = &examples[0];
    let (map, binding) = crate::binding::clips::binding_for(bind, &source, first, args.bind_rate)?;
    if args.emit_binding {
        return Ok(io::write_output(outputs[0].as_deref(), binding.to_json().as_bytes())?);
    }
    let (source_motion, resampled) = retarget::clips::at_rate_of(&source, first, bounds::MAX_FRAMES)?;
    if let (Some((from, to)), false) = (resampled, args.common.quiet) {
        eprintln!("mo-retarget: {}: resampling {from:.3} fps to the examples' {to:.3} fps", source.name);
    }
    let settings = settings(args, 1.0 / first.motion.frame_time, source_motion.frames)?;
    let out_frames = settings.frames.unwrap_or(source_motion.frames);
    if out_frames > bounds::MAX_FRAMES {
        bail!("{}: {out_frames} output frames, more than {} (give --frames or --seconds)", source.name, bounds::MAX_FRAMES);
    }
    crate::budget::check_motion("the output", out_frames.saturating_mul(count), first.skeleton.len())?;
    let example_motions: Vec<Motion> = examples.iter().map(|e| e.motion.clone()).collect();
    let seeds: Vec<u64> = (0..count as u64).map(|i| args.common.seed.wrapping_add(i)).collect();
    let loaded = started.elapsed();
    let t0 = Instant::now();
    let results = retarget::retarget_samples(&source_motion, &source.skeleton, &example_motions, &first.skeleton, &map, &settings, &seeds)
        .with_context(|| format!("{} -> {}", source.name, first.name))?;
    let retargeted = t0.elapsed();

    // Everything to bytes first, then write all samples or none.
    let t1 = Instant::now();
    match args.format {
        OutFormat::Npy => {
            let features: Vec<_> = results.iter().map(|r| m2m::encode(&r.motion)).collect();
            output::write_npy(outputs[0].as_deref(), &features, false, "give -o FILE or redirect stdout")?;
        }
        _ => output::write_motions(&first.skeleton, results.iter().map(|r| &r.motion), &outputs, args.format.motion())?,
    }
    let written = t1.elapsed();

    if args.report && !args.common.quiet {
        let say = |line: &str| eprintln!("mo-retarget: {line}");
        retarget::clips::describe(&source, source_motion.frames, &examples, &map, &binding).iter().for_each(|line| say(line));
        for (i, r) in results.iter().enumerate() {
            r.report.describe(i, seeds[i]).iter().for_each(|line| say(line));
        }
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        let total = ms(started.elapsed());
        say(&format!("time: load {:.1} ms, retarget {:.1} ms, write {:.1} ms, total {total:.1} ms", ms(loaded), ms(retargeted), ms(written)));
    }
    Ok(())
}

/// Where the samples go: one numbered file each, one file (a binding, an NPY batch), or stdout.
fn output_paths(args: &Args, count: usize) -> anyhow::Result<Vec<Option<PathBuf>>> {
    if args.emit_binding || args.format == OutFormat::Npy {
        return Ok(vec![args.common.output.clone().filter(|p| !is_dash(p))]);
    }
    io::numbered_outputs(args.common.output.as_deref(), count, "samples", "(or --format npy for one batch)").map_err(anyhow::Error::msg)
}

/// The source and the target's example clips, each at least two frames long.
fn read_inputs(args: &Args) -> anyhow::Result<(Clip, Vec<Clip>)> {
    let source = read_bvh_clip(&args.source, "mo-retarget")?;
    retarget::clips::check_lengths(&source, &[])?;
    if args.targets.iter().any(|p| is_dash(p)) && is_dash(&args.source) {
        bail!("stdin ('-') can be read only once");
    }
    let examples = read_example_clips(&args.targets, "mo-retarget", "target clips")?;
    retarget::clips::check_lengths(&source, &examples)?;
    Ok((source, examples))
}
