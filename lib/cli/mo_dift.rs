//! `mo-dift`: diffusion features of a motion, and joint and frame correspondence from them.

use crate::cli::bounds;
use crate::cli::load::{expand_inputs, load_motions, LoadOptions};
use crate::cli::CommonOpts;
use crate::diffusion::checkpoint;
use crate::dift::report::{self, Align};
use crate::dift::{self, DiftFeatures, DiftOptions};
use crate::io;
use crate::motion::Clip;
use anyhow::{bail, Context};
use candle_core::Device;
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    mo-dift examples/data/quadruped.bvh > quadruped_dift.npy
    mo-dift --joints examples/data/quadruped.bvh examples/data/dragon.bvh > joints.json
    mo-dift --joints examples/data/biped.bvh examples/data/quadruped.bvh --as-binding > bind.json
    mo-dift --frames examples/data/quadruped.bvh examples/data/dragon.bvh --draws 8 > frames.json
    mo-dift --joints examples/data/spider.bvh examples/data/crab.bvh --t 5 --layer 1 -o sc.json";

/// Diffusion features (DIFT, AnyTop §4.1) of a motion, and correspondence from them.
///
/// The motion is noised to diffusion step --t, the denoiser runs once, and the activations
/// after --layer are read: [frames + 1, joints, width], token 0 being the rest pose. Several
/// noise draws (--draws) are averaged: one draw gives noisy descriptors. Joints of different
/// creatures that do the same job, and frames that do the same action, land close together.
///
/// With one INPUT: the features as NPY float32 [frames + 1, joints, width] (stdout or -o).
///
/// --joints REF TGT: joint correspondence, a REF joint for every TGT joint, as JSON. By default
/// (--features combined) the correspondence engine that `mo-retarget --bind auto` uses, and no
/// model runs: joint names with their sides and ordinals, front and hind limbs, topology and
/// rest pose, never left with right nor front limb with hind limb, assigned one to one
/// (one_to_one false: a TGT joint left over, given its best allowed REF joint); score is the
/// combined evidence, margin how far it beats the best alternative, confidence 0..1 from it.
/// --features dift-only: the paper's DIFT matching (features averaged over frames, each
/// skeleton's mean joint descriptor subtracted, cosine, the best REF joint for every TGT
/// joint; score cosine, margin best minus second best). --as-binding writes instead a binding
/// REF -> TGT that `mo-retarget REF.bvh TGT.bvh --bind bind.json` reads: combined, exactly
/// what --bind auto binds (every confident pair of joints that move a bone, same side, same
/// limb pair, no toes, the same place along matched limbs with bones pointing the same way,
/// and each matched limb tied at its first joint and its end: foot, hand, tip or ankle; at
/// most --bind-rate); dift-only, mutual best pairs of joints that move a bone,
/// most similar first, as many as --bind-rate asks for (default 0.061, the paper's rate).
///
/// --frames REF TGT: frame correspondence, a REF frame for every TGT frame, as JSON. Frame
/// descriptors are the joints' features side by side when REF and TGT share a skeleton (same
/// joint names and parents), else the mean over joints (the paper's, across creatures). With
/// --align monotonic (default) the answers never go back in time: dynamic time warping over
/// the whole of both clips, for two takes of one action (a slower performance, a time-warped
/// copy), where frame by frame a pose matches every cycle of a gait. --align nearest is the
/// paper's frame-by-frame best match, for clips that do not share an order. Each noise draw
/// places the clip at its own random temporal position, so that frames are not matched for
/// sharing a position embedding.
///
/// Defaults: joints t 2, layer 0; frames and plain features t 3, layer 1 (the paper's settings;
/// see BENCHMARKS.md for accuracy on our models at other settings). AnyTop features drop a BVH's
/// last frame, so frame k of the output is BVH frame k, and the last BVH frame has none.
/// Inputs are BVH files, or NPY AnyTop features with --skeleton. Every clip is normalised by its
/// own statistics, so two clips compare alike whether or not the model was trained on them.
/// The same seed, model and inputs give the same bytes.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-dift", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// One motion (features), or REF TGT with --joints / --frames (BVH, or NPY with --skeleton).
    #[arg(value_name = "INPUT", required = true, num_args = 1..=2)]
    pub inputs: Vec<PathBuf>,
    /// Joint correspondence between REF and TGT (JSON).
    #[arg(long, conflicts_with = "frames")]
    pub joints: bool,
    /// Frame correspondence between REF and TGT (JSON).
    #[arg(long)]
    pub frames: bool,
    /// With --frames: how frames are matched.
    #[arg(long, value_enum, value_name = "HOW", default_value_t = Align::Monotonic, requires = "frames")]
    pub align: Align,
    /// With --joints: write a sparse binding REF -> TGT for mo-retarget --bind.
    #[arg(long, requires = "joints")]
    pub as_binding: bool,
    /// With --as-binding: at most this binding rate, 2 x pairs / (REF joints + TGT joints)
    /// [default: combined, every confident pair; dift-only, 0.061].
    #[arg(long, value_name = "R", requires = "as_binding", value_parser = bounds::positive(1.0))]
    pub bind_rate: Option<f64>,
    /// With --joints: the evidence joints are matched by.
    #[arg(long, value_enum, value_name = "WHICH", default_value_t = Features::Combined, requires = "joints")]
    pub features: Features,
    /// Diffusion step the motion is noised to (0..T-1) [default: joints 2, otherwise 3].
    #[arg(long, value_name = "T", value_parser = bounds::count(0, bounds::MAX_DIFFUSION_T))]
    pub t: Option<usize>,
    /// Layer whose activations are read (0-based) [default: joints 0, otherwise 1].
    #[arg(long, value_name = "L", value_parser = bounds::count(0, bounds::MAX_LAYER))]
    pub layer: Option<usize>,
    /// Noise draws averaged.
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub draws: u64,
    /// Model directory written by mo-train [default: the built-in model].
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
    /// Skeleton (document or BVH) that NPY inputs are decoded on.
    #[arg(long, value_name = "FILE")]
    pub skeleton: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// What `--joints` matches joints by.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Features {
    /// The correspondence engine (names, sides, limbs, topology, rest pose); no model runs.
    Combined,
    /// DIFT features alone (AnyTop §4.1), for research.
    DiftOnly,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    let pairwise = args.joints || args.frames;
    let inputs = expand_inputs(&args.inputs)?;
    match (pairwise, inputs.len()) {
        (true, 2) | (false, 1) => {}
        (true, n) => bail!("--joints and --frames compare two motions, REF and TGT; {n} given"),
        (false, n) => bail!("features are written for one motion; {n} given (use --joints or --frames to compare two)"),
    }
    if args.joints && args.features == Features::Combined {
        return combined_joints(args, &inputs);
    }
    let device = Device::Cpu;
    let model = checkpoint::frozen_or_default(args.model.as_deref(), &device)?;
    let defaults = if args.joints { DiftOptions::SPATIAL } else { DiftOptions::TEMPORAL };
    let opts = DiftOptions {
        t: args.t.unwrap_or(defaults.t),
        layer: args.layer.unwrap_or(defaults.layer),
        draws: args.draws as usize,
        seed: args.common.seed,
        ..defaults
    };
    let motions = load_one_each(args, &inputs)?;
    let known = super::ood::Known::denoiser(args.model.as_deref(), &model.info)?;
    for m in &motions {
        known.warn("mo-dift", &m.name, &m.skeleton, args.common.quiet)?;
    }
    let features: Vec<DiftFeatures> = motions.iter().map(|m| dift::of_clip(&model, m, &opts, &device)).collect::<Result<_, _>>()?;
    let bytes = if !pairwise {
        let f = &features[0];
        io::refuse_terminal(args.common.output.as_deref(), "NPY", "redirect stdout or give -o FILE")?;
        f.to_npy().context("building the NPY")?
    } else {
        comparison(args, &motions, &features, &opts)?.into_bytes()
    };
    Ok(io::write_output(args.common.output.as_deref(), &bytes)?)
}

/// `--joints` or `--frames` with DIFT: the matches of the target's joints or frames to the
/// reference's, as JSON (or, with `--as-binding`, a binding).
fn comparison(args: &Args, motions: &[Clip], features: &[DiftFeatures], opts: &DiftOptions) -> anyhow::Result<String> {
    let (reference, target) = (&motions[0], &motions[1]);
    let features = [&features[0], &features[1]];
    let model = args.model.as_ref().map_or_else(|| "built-in".to_string(), |p| p.display().to_string());
    let settings = report::settings(reference, target, opts, &model);
    Ok(match (args.joints, args.as_binding) {
        (true, true) => report::joint_binding(reference, target, features, args.bind_rate.unwrap_or(report::DIFT_BIND_RATE))?,
        (true, false) => report::joint_matches(reference, target, features, settings),
        (false, _) => report::frame_matches(reference, target, features, settings, args.align),
    })
}

/// `--joints` with the correspondence engine: no model, the same scores `--bind auto` uses.
fn combined_joints(args: &Args, inputs: &[PathBuf]) -> anyhow::Result<()> {
    let motions = load_one_each(args, inputs)?;
    let (reference, target) = (&motions[0], &motions[1]);
    let text = if args.as_binding { report::combined_binding(reference, target, args.bind_rate)? } else { report::combined_joint_matches(reference, target)? };
    Ok(io::write_output(args.common.output.as_deref(), text.as_bytes())?)
}

/// One motion per input file (an NPY batch holds several).
fn load_one_each(args: &Args, inputs: &[PathBuf]) -> anyhow::Result<Vec<Clip>> {
    let motions = load_motions(inputs, &LoadOptions { skeleton: args.skeleton.as_deref(), from: None })?;
    if motions.len() != inputs.len() {
        bail!("{} motions in {} files: give one motion per file (an NPY batch holds several)", motions.len(), inputs.len());
    }
    Ok(motions)
}
