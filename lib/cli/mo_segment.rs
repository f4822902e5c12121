//! `mo-segment`: split a motion into actions. This file reads the input (a BVH, encoded here
//! with AnyTop's rig, or an NPY of AnyTop features as `mo-encode` writes them, so the two are
//! interchangeable in a pipeline), turns it into one feature vector per frame
//! (`frame_features`: the place where feature providers plug in), runs `segment::segment`, and
//! writes JSON that `mo-render --frame-labels` reads.

use crate::cli::bounds;
use crate::cli::load::is_dash;
use crate::cli::CommonOpts;
use crate::diffusion::checkpoint;
use crate::dift::DiftOptions;
use crate::io;
use crate::segment::input::{dift_features, raw_features, segment_input, window_frames, Input};
use crate::segment::SegmentOptions;
use anyhow::bail;
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    mo-segment examples/data/biped.bvh
    mo-segment examples/data/quadruped.bvh --k 2 --min-segment 20 -o quadruped_segments.json
    mo-segment examples/data/dragon.bvh --pca-dims 4 --window 0.5 --seed 7 > dragon_segments.json
    cat examples/data/crab.bvh | mo-segment - --k 4 --quiet
    mo-encode examples/data/spider.bvh | mo-segment --skeleton examples/data/spider.bvh --k 2
    mo-segment examples/data/snake.bvh --features raw --window 0.5";

/// Split a motion into actions: per-frame labels and contiguous segments (JSON).
///
/// Each frame of the motion becomes a feature vector (--features): 'dift' (default) is the
/// trained denoiser's activations (AnyTop §5: the motion noised to step --t, the layer --layer
/// output averaged over joints and over --draws noise draws, as mo-dift computes them; the
/// built-in model unless --model); 'raw' is the motion's own AnyTop features, every joint's 13
/// values (root-relative position, 6D rotation, velocity, foot contact) except the root's
/// facing — a baseline that needs no model. The vectors are centred and projected on their top
/// --pca-dims principal components; each frame is then described by the mean and standard
/// deviation of its projections over --window seconds around it (single poses of a walk sweep
/// through the gait cycle; statistics over about a cycle describe the action); k-means
/// (k-means++ seeding, several restarts, --seed) groups the frames into --k clusters; runs
/// shorter than --min-segment frames are merged into their longer neighbour, and each boundary
/// moves, within half a window, to the frame where the single-frame projections change most
/// (window statistics place a change only to about half a window). Defaults are measured:
/// 'cargo bench --bench segment', BENCHMARKS.md.
///
/// Output: JSON with the file, its frame count and frame time, the options, the explained
/// variance of the kept components, one label per frame ('labels', numbered by first
/// appearance: frame 0 has label 0) and the contiguous 'segments' [{start, end, label}] with end
/// exclusive, in BVH frames. AnyTop features have one frame fewer than the BVH (a frame's
/// velocity needs the next one): the last frame takes the label before it. 'mo-render
/// --frame-labels FILE' tints frames by this output.
///
/// The input is a BVH file, or an NPY of AnyTop features as mo-encode writes them by default
/// ([frames, joints, 13], physical units), so 'mo-encode clip.bvh | mo-segment' gives the labels
/// 'mo-segment clip.bvh' does; '-' = stdin. An NPY counts as 30 fps unless --skeleton is a BVH.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-segment", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// Motion to segment: a BVH file or an NPY of AnyTop features ('-' = stdin).
    #[arg(value_name = "INPUT", default_value = "-")]
    pub input: PathBuf,
    /// Clusters (kinds of action) to find; segments with the same label are the same kind.
    #[arg(long, value_name = "K", default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=64))]
    pub k: u64,
    /// Principal components kept (0 = cluster the features as they are).
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = bounds::count(0, bounds::MAX_PCA_DIMS))]
    pub pca_dims: usize,
    /// Temporal context: mean and std of each component over this many seconds around a frame
    /// (0 = single frames).
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0, allow_negative_numbers = true)]
    pub window: f64,
    /// Shortest segment in frames; shorter runs are merged into their longer neighbour.
    #[arg(long, value_name = "FRAMES", default_value_t = 10, value_parser = bounds::count(0, bounds::MAX_MIN_SEGMENT))]
    pub min_segment: usize,
    /// What each frame is described by.
    #[arg(long, value_enum, value_name = "KIND", default_value_t = Features::Dift)]
    pub features: Features,
    /// With --features dift: model directory written by mo-train [default: the built-in model].
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
    /// With --features dift: diffusion step the motion is noised to.
    #[arg(long, value_name = "T", default_value_t = DiftOptions::TEMPORAL.t, value_parser = bounds::count(0, bounds::MAX_DIFFUSION_T))]
    pub t: usize,
    /// With --features dift: layer whose activations are read (0-based).
    #[arg(long, value_name = "L", default_value_t = DiftOptions::TEMPORAL.layer, value_parser = bounds::count(0, bounds::MAX_LAYER))]
    pub layer: usize,
    /// With --features dift: noise draws averaged.
    #[arg(long, value_name = "N", default_value_t = DiftOptions::TEMPORAL.draws as u64, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub draws: u64,
    /// K-means restarts from different seedings; the tightest clustering wins.
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub restarts: u64,
    /// The input's skeleton, a skeleton document (skel-info) or a BVH file: a BVH input is
    /// encoded with its AnyTop record (as 'mo-encode --skeleton' does), an NPY input is checked
    /// against it.
    #[arg(long, value_name = "PATH")]
    pub skeleton: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// Per-frame descriptions `mo-segment` can cluster.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Features {
    /// The motion's own AnyTop features without the root's facing (a baseline; no model needed).
    Raw,
    /// Diffusion features (AnyTop §5: the denoiser's activations, averaged over joints), as
    /// `mo-dift` computes them.
    Dift,
}

/// One feature vector per frame of `input` for `--features`, row t describing BVH frame t (rows
/// may stop short of the last frames; `segment_input` gives those the last row's label; all rows
/// the same length, finite). New feature kinds (DIFT) are one more `Features` variant and one
/// more arm here, reading their own flags (model, step, layer, draws, `args.common.seed`) from
/// `args` and the skeleton and rig from `input.skeleton`.
pub fn frame_features(args: &Args, input: &Input) -> anyhow::Result<Vec<Vec<f64>>> {
    match args.features {
        Features::Raw => Ok(raw_features(input)),
        Features::Dift => {
            let device = candle_core::Device::Cpu;
            let model = checkpoint::frozen_or_default(args.model.as_deref(), &device)?;
            let opts = DiftOptions { t: args.t, layer: args.layer, draws: args.draws as usize, seed: args.common.seed, ..DiftOptions::TEMPORAL };
            if let Some((skeleton, _)) = &input.skeleton {
                super::ood::Known::denoiser(args.model.as_deref(), &model.info)?.warn("mo-segment", &input.name, skeleton, args.common.quiet)?;
            }
            Ok(dift_features(&model, input, &opts)?)
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if !(args.window.is_finite() && args.window >= 0.0 && args.window <= bounds::MAX_SECONDS) {
        bail!("--window must be a number of seconds >= 0, found {}", args.window);
    }
    let input = load(args)?;
    let options = SegmentOptions {
        k: args.k as usize,
        pca_dims: args.pca_dims,
        window: window_frames(args.window, input.frame_time),
        min_segment: args.min_segment,
        restarts: args.restarts as usize,
        ..SegmentOptions::default()
    };
    let started = std::time::Instant::now();
    let features = frame_features(args, &input)?;
    let result = segment_input(&input, &features, &options, args.common.seed)?;
    if args.common.verbose {
        eprintln!(
            "mo-segment: {}: {} frames, {} segments, {} clusters in {:.3} s",
            input.name,
            input.frames,
            result.segments.len(),
            result.clusters,
            started.elapsed().as_secs_f64()
        );
    }
    let features_name = clap::ValueEnum::to_possible_value(&args.features).expect("no variant is skipped");
    let text = crate::segment::report::report(&input, features_name.get_name(), &options, args.common.seed, &result)?;
    Ok(io::write_output(args.common.output.as_deref(), text.as_bytes())?)
}

/// Read the input: a BVH (features on a rig from its own first frames), or an NPY of AnyTop
/// features taken as they are (checked against --skeleton when given).
fn load(args: &Args) -> anyhow::Result<Input> {
    if is_dash(&args.input) && args.skeleton.as_deref().is_some_and(is_dash) {
        bail!("stdin ('-') can be read only once, but the input and --skeleton both read it");
    }
    Ok(Input::read(&args.input, args.skeleton.as_deref(), &crate::cli::load::gltf_options())?)
}
