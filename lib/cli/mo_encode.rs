//! `mo-encode`: BVH motion -> feature tensors (NPY), and back (`--decode`).
//!
//! Everything learned or measured downstream sees motion through these tensors, so the tool is
//! the one place where representations meet files. Two representations:
//!
//! * `anytop` (the default, `repr::anytop`): 13 dims per joint, F frames -> F-1 feature frames.
//!   It needs a *rig*: per-skeleton quantities computed once from a rest pose (scale, ground,
//!   natural rest pose, face joints, feet). Encoding and decoding must use the same rig, so it
//!   travels in the skeleton document's AnyTop record (`--emit-skeleton`, or `skel-info`), and
//!   one rule (`record_of`) turns a `--skeleton` into a record in both directions: the
//!   document's own record when it has one, else one built from a rest pose exactly as
//!   `skel-info` builds it (a BVH given as `--skeleton` stands for its `skel-info` document).
//!   Without `--skeleton`, encoding builds the rig from the inputs (`--rest-pose`, else a
//!   `*tpos*` input, else the first input: AnyTop's rule).
//! * `m2m` (`repr::m2m`): 9 dims per joint, a function of the clip alone.
//!
//! Encoding runs across clips in parallel (rayon), each clip sequentially, and statistics are
//! summed in argument order, so the output is byte-identical whatever `--threads` says. Every
//! input is checked and every output built before anything is written; files are written
//! atomically, and a failed write removes the outputs of the call already written, so an
//! error never leaves a partial output.

use crate::cli::load::{is_dash, read_skeleton, split_samples, FeatureDecoder};
use crate::input::SkeletonFile;
pub use crate::cli::load::{load_skeleton, DecodeFrom, MotionFormat};
use crate::cli::CommonOpts;
use crate::document::{AnyTopSection, MotionInfo, SkeletonDocument};
use crate::io;
use crate::io::npy;
use crate::motion::Motion;
use crate::repr::anytop::{self, RigOptions, AnyTopRig, AnyTopStats, Facing, Placement, Provenance, RestSource};
use crate::repr::{m2m, Features};
use crate::skeleton::{lookup, topology, Skeleton};
use anyhow::{anyhow, bail, Context};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-encode examples/data/spider.bvh --emit-skeleton s.json --placement p.json -o spider.npy
    mo-encode --decode --skeleton s.json --placement p.json spider.npy -o spider.bvh
    mo-encode --decode --skeleton s.json --from positions spider.npy -o spider_ik.bvh
    mo-encode examples/data/quadruped.bvh --normalise --emit-skeleton q.json -o quadruped.npy
    mo-encode --decode --normalised --skeleton q.json quadruped.npy -o quadruped.bvh
    mo-encode examples/data/crab.bvh examples/data/crab.bvh --stats stats.json -o crabs.npy
    mo-encode --decode --skeleton examples/data/crab.bvh crabs.npy -o crab_{i}.bvh
    mo-encode examples/data/biped.bvh --face-joints RightUpLeg,LeftUpLeg,RightArm,LeftArm > b.npy
    skel-info examples/data/snake.bvh | mo-encode --skeleton - examples/data/snake.bvh > snake.npy
    mo-encode --repr m2m examples/data/bird.bvh examples/data/bird.bvh -o birds.npy
    mo-encode --repr m2m --decode --skeleton examples/data/bird.bvh birds.npy -o bird_{i}.bvh
    cat examples/data/fish.bvh | mo-encode - --threads 1 > fish.npy
    mo-encode --latent examples/data/quadruped.bvh -o z.npy
    mo-encode --decode-latent --skeleton examples/data/dragon.bvh z.npy -o dragon_from_dog.bvh";

/// Encode BVH motion as feature tensors (NPY), or decode tensors back to BVH.
///
/// Encoding reads BVH files of one skeleton ('-' = stdin) and writes one little-endian float32
/// NPY: [frames, joints, dims] for one file, [files, frames, joints, dims] for several (they
/// must agree in frames). Values are physical (not normalised) unless --normalise says
/// otherwise; numpy loads them with numpy.load.
///
/// --repr anytop (the default; AnyTop, 13 dims per joint): a clip of F frames gives F-1 feature
/// frames (frame t's velocity needs frame t+1), so clips need at least two frames. The clip is
/// turned to face +Z at frame 0, scaled so that its mean bone is 0.2092 long, and grounded.
/// Then, per joint at frame t: dims 0-2 its position relative to the root's ground point in
/// frame t's facing frame (y absolute); 3-8 the 6D rotation of the bone from its parent
/// (relative to the natural rest pose); 9-11 its velocity to frame t+1 in frame t+1's facing
/// frame; 12 foot contact (0 or 1). The root's row holds (0, height, 0), its facing as a 6D
/// yaw and its displacement.
///
/// AnyTop needs a rig, measured once per skeleton on a rest pose: from --skeleton's AnyTop
/// record when it has one; else from frame 0 of --rest-pose, else of --skeleton when it is a
/// BVH (a skeleton document without motion: its OFFSET pose); without --skeleton, of the first
/// input whose file name contains 'tpos', else of the first input. Face joints and feet are
/// found automatically; --face-joints, --body-axis and --feet override them when the rig is
/// built. Decoding needs the same rig: --emit-skeleton saves it in a skeleton document, and
/// 'mo-encode --decode --skeleton that.json' uses it (the recommended pipeline); encode more
/// clips of the skeleton with '--skeleton that.json' too, so that they share the rig.
/// --placement saves where each clip stood, which the features leave out; --stats saves the
/// normalisation statistics (mean and grouped std over the given clips, AnyTop's grouping).
///
/// --repr m2m (Motion2Motion, 9 dims per joint): dims 0-5 are the joint's local rotation as 6D
/// (the first two rows of its rotation matrix); on the root (joint 0), dims 6-8 are its position
/// as dx, y, dz: x and z as per-frame differences, frame 0 holding the start position, y
/// absolute. Other joints' dims 6-8 are zero. Only the root translates: joints whose position
/// channels animate are decoded on their OFFSETs (a warning says so when encoding).
///
/// Decoding (--decode) reads one NPY file (default stdin) and writes BVH on the --skeleton's own
/// hierarchy, channel orders and frame time. --skeleton is a skeleton document (from
/// --emit-skeleton or skel-info) or a BVH file (recognised by content). AnyTop features decode
/// from their rotations (exact for encoded features) or, with --from positions, from their
/// positions by inverse kinematics (for generated features); without --placement a clip starts
/// where the rest pose stands, facing its way. A 4-D batch writes one BVH per sample: give -o
/// a pattern with {i}, replaced by the sample index.
///
/// Latents (--latent, --decode-latent; the SATA autoencoder, --model or the built-in one): a
/// clip of any skeleton becomes one vector per frame, [frames - 1, latent], whose size does not
/// depend on the skeleton; --decode-latent puts such a sequence on any --skeleton (a BVH, whose
/// first frame is taken as its rest pose, or a skeleton document), zero-shot: the decoded
/// motion starts where the target's rest pose stands, at its BVH's frame time (1/30 s for a
/// document). Long clips go through the model in overlapping windows. A skeleton the model was
/// trained on (its rigs.json) is read and written with its training rig, whatever clip of it is
/// given: the rest pose its rotations were learned against.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-encode", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH files to encode ('-' = stdin); with --decode or --decode-latent, one NPY file
    /// (default: stdin).
    #[arg(value_name = "INPUT", required_unless_present_any = ["decode", "decode_latent"])]
    pub inputs: Vec<PathBuf>,
    /// Feature representation.
    #[arg(long, value_enum, default_value_t = Repr::Anytop)]
    pub repr: Repr,
    /// Decode an NPY of features back to BVH on --skeleton.
    #[arg(long, requires = "skeleton")]
    pub decode: bool,
    /// The skeleton: a skeleton document (JSON) or a BVH file ('-' = stdin).
    ///
    /// Required with --decode (the skeleton to decode onto). When encoding with anytop, its
    /// AnyTop record (or, for a BVH or a document without one, the rig skel-info would build)
    /// gives the rig, and the inputs must have its joint names and parents.
    #[arg(long, value_name = "PATH")]
    pub skeleton: Option<PathBuf>,
    /// anytop: build the rig on frame 0 of this BVH (same skeleton).
    ///
    /// Instead of the first '*tpos*' input, the first input, or --skeleton's frame 0. Not with
    /// a --skeleton document that has an AnyTop record: its rig is fixed.
    #[arg(long, value_name = "BVH")]
    pub rest_pose: Option<PathBuf>,
    /// anytop: face joints, four joint names, instead of the automatic choice.
    ///
    /// Facing is forward = up x ((R_HIP - L_HIP) + (R_SHOULDER - L_SHOULDER)). Names match
    /// exactly, else ignoring case, else without a 'namespace:' prefix.
    #[arg(
        long,
        value_name = "R_HIP,L_HIP,R_SHOULDER,L_SHOULDER",
        value_delimiter = ',',
        conflicts_with_all = ["decode", "body_axis"]
    )]
    pub face_joints: Option<Vec<String>>,
    /// anytop: face along the body, from BACK to FRONT (two joint names).
    ///
    /// For creatures without left and right limbs (snakes, fish); instead of the automatic choice.
    #[arg(long, value_name = "FRONT,BACK", value_delimiter = ',', conflicts_with = "decode")]
    pub body_axis: Option<Vec<String>>,
    /// anytop: the joints that get foot-contact labels (joint names) instead of the automatic choice.
    #[arg(long, value_name = "NAME,...", value_delimiter = ',', conflicts_with = "decode")]
    pub feet: Option<Vec<String>>,
    /// anytop: fail when the skeleton has no foot joints, instead of writing all-zero contact
    /// features with a warning (for training data of walkers, where a missed foot is a bug).
    #[arg(long, conflicts_with = "decode")]
    pub require_contacts: bool,
    /// anytop: write normalised features, (x - mean) / (std + 1e-6).
    ///
    /// With the statistics of --skeleton's AnyTop record when it has them, else of the given
    /// clips. Decode them with --normalised and the document --emit-skeleton writes.
    #[arg(long, conflicts_with = "decode")]
    pub normalise: bool,
    /// anytop: write the normalisation statistics of the given clips (JSON: mean, std).
    #[arg(long, value_name = "PATH", conflicts_with = "decode")]
    pub stats: Option<PathBuf>,
    /// anytop: write the skeleton document with the rig used, for decoding.
    ///
    /// Its AnyTop record holds the exact rig the features were made with, the rest-pose row P_S
    /// and the statistics --normalise uses (of --skeleton's record, else of the given clips).
    #[arg(long, value_name = "PATH", conflicts_with = "decode")]
    pub emit_skeleton: Option<PathBuf>,
    /// anytop: where each clip stood (JSON): written when encoding, read when decoding.
    ///
    /// A list of {heading, root_xz} in input order (sample order when decoding a batch):
    /// decoding puts sample i back where clip i stood. Without it, decoded motion starts where
    /// the rest pose stands, facing its way.
    #[arg(long, value_name = "PATH")]
    pub placement: Option<PathBuf>,
    /// anytop decoding: from the rotations (default; exact for encoded features) or the positions.
    ///
    /// 'positions' fits the rotations to the features' joint positions by inverse kinematics,
    /// for generated features whose positions and rotations disagree.
    #[arg(long, value_enum, value_name = "FROM", requires = "decode")]
    pub from: Option<DecodeFrom>,
    /// anytop decoding: the NPY holds normalised features; undo it with --skeleton's statistics.
    #[arg(long, requires = "decode")]
    pub normalised: bool,
    /// Encode one BVH clip into per-frame latents of the latent model (SATA): NPY [frames - 1,
    /// latent], the same size for every skeleton.
    #[arg(long, conflicts_with_all = ["decode", "decode_latent", "repr"])]
    pub latent: bool,
    /// Decode latents (NPY [frames, latent] from --latent) onto --skeleton, any skeleton, as
    /// BVH.
    #[arg(long, requires = "skeleton", conflicts_with_all = ["decode", "repr"])]
    pub decode_latent: bool,
    /// The latent model: a directory from 'mo-train --arch sata' [default: the built-in one].
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// The feature representations `mo-encode` knows.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Repr {
    /// AnyTop: per joint position, 6D rotation, velocity and foot contact; 13 dims, F-1 frames.
    Anytop,
    /// Motion2Motion: local 6D rotation of every joint + root position (x/z as velocities); 9 dims.
    M2m,
}

impl Repr {
    pub fn name(self) -> &'static str {
        match self {
            Repr::Anytop => "anytop",
            Repr::M2m => "m2m",
        }
    }

    /// Feature dims per joint.
    pub fn dims(self) -> usize {
        match self {
            Repr::Anytop => anytop::FEATURE_DIMS,
            Repr::M2m => m2m::DIMS,
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if args.latent || args.decode_latent {
        return latent(args);
    }
    if args.model.is_some() {
        bail!("--model belongs to --latent and --decode-latent");
    }
    refuse_anytop_flags(args)?;
    check_stdin(args)?;
    if args.decode {
        decode(args)
    } else {
        encode(args)
    }
}

/// `--latent` / `--decode-latent`: one clip to latents, or latents to a BVH on --skeleton.
fn latent(args: &Args) -> anyhow::Result<()> {
    let given = [
        (args.rest_pose.is_some(), "--rest-pose"),
        (args.face_joints.is_some(), "--face-joints"),
        (args.body_axis.is_some(), "--body-axis"),
        (args.feet.is_some(), "--feet"),
        (args.require_contacts, "--require-contacts"),
        (args.normalise, "--normalise"),
        (args.stats.is_some(), "--stats"),
        (args.emit_skeleton.is_some(), "--emit-skeleton"),
        (args.placement.is_some(), "--placement"),
        (args.latent && args.skeleton.is_some(), "--skeleton (with --latent: the clip carries its skeleton)"),
    ];
    if let Some((_, flag)) = given.iter().find(|(on, _)| *on) {
        bail!("{flag} does not apply to latents: the latent model builds each clip's rig itself");
    }
    let dash = args.inputs.iter().filter(|p| is_dash(p)).count() + usize::from(args.skeleton.as_deref().is_some_and(is_dash));
    if dash > 1 || (args.decode_latent && args.inputs.is_empty() && args.skeleton.as_deref().is_some_and(is_dash)) {
        bail!("stdin ('-') can be read only once");
    }
    let device = candle_core::Device::Cpu;
    let model = super::latent::load_model(args.model.as_deref(), &device)?;
    let bytes = if args.latent {
        let [input] = args.inputs.as_slice() else { bail!("--latent encodes one BVH clip, {} given", args.inputs.len()) };
        let clip = super::latent::read_source(input, &model, &device)?;
        super::ood::Known::latent(args.model.as_deref(), &model.rigs)?.warn("mo-encode", &clip.name, &clip.skeleton, args.common.quiet)?;
        let latents = super::latent::encode(&model, &clip, &device)?;
        io::refuse_terminal(args.common.output.as_deref(), "binary NPY", "redirect stdout or give -o FILE")?;
        super::latent::latents_npy(&latents)?
    } else {
        let input = match args.inputs.as_slice() {
            [] => PathBuf::from("-"),
            [one] => one.clone(),
            more => bail!("--decode-latent reads one NPY of latents, {} given", more.len()),
        };
        let latents = super::latent::read_latents(&input)?;
        let skeleton = args.skeleton.as_deref().context("--decode-latent needs --skeleton")?;
        let target = super::latent::read_target(skeleton, &model, &device)?;
        super::ood::Known::latent(args.model.as_deref(), &model.rigs)?.warn("mo-encode", &target.arg.name, &target.arg.skeleton, args.common.quiet)?;
        let frame_time = target.arg.motion.as_ref().map_or(1.0 / 30.0, |m| m.frame_time);
        super::latent::decode_file(&model, &latents, &target, frame_time, &device, args.common.output.as_deref(), MotionFormat::Bvh)?
    };
    Ok(io::write_output(args.common.output.as_deref(), &bytes)?)
}

/// AnyTop's flags mean nothing to m2m (clap cannot tie a flag to another flag's value).
fn refuse_anytop_flags(args: &Args) -> anyhow::Result<()> {
    if args.repr != Repr::M2m {
        return Ok(());
    }
    let given = [
        (!args.decode && args.skeleton.is_some(), "--skeleton (when encoding)"),
        (args.rest_pose.is_some(), "--rest-pose"),
        (args.face_joints.is_some(), "--face-joints"),
        (args.body_axis.is_some(), "--body-axis"),
        (args.feet.is_some(), "--feet"),
        (args.require_contacts, "--require-contacts"),
        (args.normalise, "--normalise"),
        (args.stats.is_some(), "--stats"),
        (args.emit_skeleton.is_some(), "--emit-skeleton"),
        (args.placement.is_some(), "--placement"),
        (args.from.is_some(), "--from"),
        (args.normalised, "--normalised"),
    ];
    match given.iter().find(|(on, _)| *on) {
        Some((_, flag)) => bail!("{flag} belongs to --repr anytop: m2m features need no rig, placement or statistics"),
        None => Ok(()),
    }
}

/// Everything that reads stdin, refused when more than one thing would.
fn check_stdin(args: &Args) -> anyhow::Result<()> {
    let mut readers: Vec<&str> = Vec::new();
    if args.decode {
        if args.inputs.is_empty() || args.inputs.iter().any(|p| is_dash(p)) {
            readers.push("the NPY");
        }
        if args.placement.as_deref().is_some_and(is_dash) {
            readers.push("--placement");
        }
    } else {
        readers.extend(args.inputs.iter().filter(|p| is_dash(p)).map(|_| "an input"));
    }
    if args.skeleton.as_deref().is_some_and(is_dash) {
        readers.push("--skeleton");
    }
    if args.rest_pose.as_deref().is_some_and(is_dash) {
        readers.push("--rest-pose");
    }
    if readers.len() > 1 {
        let all = if readers.len() == 2 { "both" } else { "all" };
        bail!("stdin ('-') can be read only once, but {} {all} read it", readers.join(" and "));
    }
    Ok(())
}

/// One parsed input clip.
struct Clip {
    name: String,
    /// Its file name says T-pose (contains 'tpos', any case): AnyTop's rest clip.
    tpose: bool,
    skeleton: Skeleton,
    motion: Motion,
    info: Option<MotionInfo>,
}

/// Parse a BVH clip (`frames`: only the first so many, for rest poses).
fn load_clip(path: &Path, frames: Option<usize>) -> anyhow::Result<Clip> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
    let parsed = crate::cli::load::parse_motion(&bytes, &name, path)?;
    drop(bytes);
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh_frames(&parsed, &skeleton, 0..frames.unwrap_or(usize::MAX));
    let info = MotionInfo::of(&parsed, &skeleton);
    Ok(Clip { tpose: !is_dash(path) && anytop::names_tpose(&path.to_string_lossy()), name, skeleton, motion, info })
}

/// AnyTop encodes one skeleton per call: same joint names and parents.
fn check_same_skeleton(a_name: &str, a: &Skeleton, b_name: &str, b: &Skeleton) -> anyhow::Result<()> {
    if let Some(why) = a.first_difference(b) {
        bail!("{a_name} and {b_name} have different skeletons ({why}): AnyTop encodes one skeleton per call, so encode them separately");
    }
    Ok(())
}

fn encode(args: &Args) -> anyhow::Result<()> {
    let npy_target = args.common.output.as_deref();
    check_outputs(args)?;
    refuse_terminal(npy_target)?;
    // Clips in parallel, results in argument order; the first failing argument is reported.
    let results: Vec<anyhow::Result<Clip>> = args.inputs.par_iter().map(|p| load_clip(p, None)).collect();
    let clips = results.into_iter().collect::<anyhow::Result<Vec<Clip>>>()?;
    if clips.is_empty() {
        bail!("no BVH files to encode");
    }
    match args.repr {
        Repr::Anytop => encode_anytop(args, &clips),
        Repr::M2m => encode_m2m(args, &clips),
    }
}

/// At most one output on stdout, and no file named for two outputs.
fn check_outputs(args: &Args) -> anyhow::Result<()> {
    let outputs = [
        ("-o", args.common.output.clone().or_else(|| Some(PathBuf::from("-")))),
        ("--stats", args.stats.clone()),
        ("--emit-skeleton", args.emit_skeleton.clone()),
        ("--placement", args.placement.clone()),
    ];
    let given: Vec<(&str, PathBuf)> = outputs.into_iter().filter_map(|(flag, p)| Some((flag, p?))).collect();
    for (i, (flag, path)) in given.iter().enumerate() {
        if let Some((other, _)) = given[..i].iter().find(|(_, p)| p == path) {
            if is_dash(path) {
                bail!("{other} and {flag} both write to stdout: give one of them a file");
            }
            bail!("{other} and {flag} both write to {}", path.display());
        }
    }
    Ok(())
}

fn encode_m2m(args: &Args, clips: &[Clip]) -> anyhow::Result<()> {
    let encoded: Vec<(Features, Option<String>)> = clips.par_iter().map(|c| (m2m::encode(&c.motion), m2m_loss_warning(&c.motion, &c.skeleton))).collect();
    let (features, warnings): (Vec<Features>, Vec<Option<String>>) = encoded.into_iter().unzip();
    check_stackable(clips, &features)?;
    let first = &clips[0];
    for (clip, (f, warning)) in clips.iter().zip(features.iter().zip(&warnings)) {
        if !args.common.quiet {
            if let Some(w) = warning {
                eprintln!("mo-encode: warning: {}: {w}", clip.name);
            }
            if first.skeleton.first_difference(&clip.skeleton).is_some() {
                eprintln!("mo-encode: warning: {} and {} have the same shape but different joint names or parents", first.name, clip.name);
            }
        }
        if args.common.verbose {
            let [n, j, d] = f.shape();
            eprintln!("mo-encode: {}: {} frames, {j} joints -> m2m features [{n}, {j}, {d}]", clip.name, clip.motion.frames);
        }
    }
    write_outputs(vec![(args.common.output.clone(), npy_bytes(clips, &features)?)])
}

/// What m2m loses on this clip, as a warning (None when nothing).
fn m2m_loss_warning(motion: &Motion, skeleton: &Skeleton) -> Option<String> {
    // Far below the 1e-4-of-size round-trip promise, far above text rounding.
    let tolerance = 1e-5 * skeleton.rest_extent().max(f64::MIN_POSITIVE);
    let c = m2m::max_bone_translation_change(motion, skeleton, tolerance)?;
    Some(format!(
        "{} joint(s) translate away from their OFFSET (up to {:.6} units: '{}' at frame {}); m2m carries only the root's translation, so decoding puts them on their OFFSETs",
        c.joints, c.distance, skeleton.joints[c.joint].name, c.frame
    ))
}

/// A batch stacks clips of one shape; else say which two differ.
fn check_stackable(clips: &[Clip], features: &[Features]) -> anyhow::Result<()> {
    let first = &features[0];
    for (clip, f) in clips.iter().zip(features).skip(1) {
        if f.shape() != first.shape() {
            bail!(
                "cannot stack {} {:?} and {} {:?}: a batch needs the same frames and joints (encode them separately, or cut the clips to one length)",
                clips[0].name,
                first.shape(),
                clip.name,
                f.shape()
            );
        }
    }
    Ok(())
}

/// One NPY of all clips: rank 3 for one, rank 4 for a batch.
fn npy_bytes(clips: &[Clip], features: &[Features]) -> anyhow::Result<Vec<u8>> {
    // float32 features hold what a motion's f64 numbers became: 1e300 is inf there.
    for (clip, f) in clips.iter().zip(features) {
        if let Some((frame, joint, dim)) = f.first_non_finite() {
            let value = f.at(frame, joint)[dim];
            let joint_name = clip.skeleton.joints.get(joint).map_or("?", |j| j.name.as_str());
            bail!("{}: encodes to {value} at feature frame {frame}, joint {joint} '{joint_name}', dim {dim}: the motion holds numbers too large for float32 features", clip.name);
        }
    }
    let mut shape = features[0].shape().to_vec();
    if features.len() > 1 {
        shape.insert(0, features.len());
    }
    let parts: Vec<&[f32]> = features.iter().map(|f| f.data.as_slice()).collect();
    let mut bytes = Vec::new();
    npy::write_f32_parts(&mut bytes, &shape, &parts).context("building the NPY")?;
    Ok(bytes)
}

fn encode_anytop(args: &Args, clips: &[Clip]) -> anyhow::Result<()> {
    for clip in clips {
        if clip.motion.frames < 2 {
            bail!(
                "{}: {} frame(s): AnyTop features need at least two frames (frame t's velocity comes from frame t+1, so F frames give F-1 feature frames; a one-frame rest pose goes to --rest-pose)",
                clip.name,
                clip.motion.frames
            );
        }
    }
    let first = &clips[0];
    for clip in &clips[1..] {
        check_same_skeleton(&first.name, &first.skeleton, &clip.name, &clip.skeleton)?;
    }
    let rest_pose = args.rest_pose.as_deref().map(|p| load_clip(p, Some(2))).transpose()?;
    if let Some(rest) = &rest_pose {
        check_same_skeleton(&first.name, &first.skeleton, &rest.name, &rest.skeleton)?;
    }

    // The rig, the document that carries it, and the statistics --normalise uses.
    let (mut document, mut section, rig_name) = match args.skeleton.as_deref() {
        Some(path) => {
            let arg = read_skeleton(path)?;
            check_same_skeleton(&first.name, &first.skeleton, &arg.name, &arg.skeleton)?;
            let want_stats = args.normalise || args.emit_skeleton.is_some();
            let section = record_of(&arg, rest_pose.as_ref(), args, want_stats)?;
            (arg.document, section, arg.name)
        }
        None => {
            let (rest, source) = match &rest_pose {
                Some(r) => (r, RestSource::Explicit { file: r.name.clone() }),
                None => match clips.iter().find(|c| c.tpose) {
                    Some(t) => (t, RestSource::TPose { file: t.name.clone() }),
                    None => (first, RestSource::FirstClip { file: first.name.clone() }),
                },
            };
            let options = anytop_options(args, &rest.skeleton, &rest.name, source)?;
            let section = AnyTopSection::new(&rest.skeleton, &rest.motion.first_frames(2), &options)
                .with_context(|| format!("{}: cannot build an AnyTop rig", rest.name))?;
            // The document describes the encoded clips (their frame time), with the rig.
            let document = SkeletonDocument::build(&first.skeleton, first.info.clone(), &first.name, topology::DEFAULT_DMAX);
            (document, section, rest.name.clone())
        }
    };
    let rig = &section.rig;
    if rig.feet.is_empty() {
        // Contacts are part of every AnyTop token; without feet they are all zero, which is
        // right for a fish but surprising for a walker whose feet the names did not reveal.
        if args.require_contacts {
            bail!("{}: no foot joints found for contact features (name them with --feet)", first.name);
        }
        if !args.common.quiet {
            eprintln!("mo-encode: warning: {}: no foot joints found, so every contact feature is 0 (name them with --feet)", first.name);
        }
    }
    if args.common.verbose {
        eprintln!("mo-encode: rig: {}", describe_rig(rig, &first.skeleton));
    }

    let results: Vec<anyhow::Result<anytop::Encoded>> = clips
        .par_iter()
        .map(|c| rig.encode(&c.skeleton, &c.motion).with_context(|| format!("{}: cannot encode with the AnyTop rig of {rig_name}", c.name)))
        .collect();
    let encoded = results.into_iter().collect::<anyhow::Result<Vec<anytop::Encoded>>>()?;
    let (mut features, placements): (Vec<Features>, Vec<Placement>) = encoded.into_iter().map(|e| (e.features, e.placement)).unzip();
    check_stackable(clips, &features)?;
    if args.common.verbose {
        for (clip, f) in clips.iter().zip(&features) {
            let [n, j, d] = f.shape();
            eprintln!("mo-encode: {}: {} frames, {j} joints -> anytop features [{n}, {j}, {d}]", clip.name, clip.motion.frames);
        }
    }

    // Statistics: of the given clips for --stats; --normalise and the emitted document use the
    // record's when it has them (so that its --normalised decoding undoes this call's).
    let record_has_stats = section.stats.is_some();
    let need_clip_stats = args.stats.is_some() || (!record_has_stats && (args.normalise || args.emit_skeleton.is_some()));
    let clip_stats = if need_clip_stats { Some(AnyTopStats::compute(features.iter()).context("computing the statistics")?) } else { None };
    if !record_has_stats {
        section.stats = clip_stats.clone();
    }
    if args.normalise {
        let stats = section.stats.as_ref().expect("computed above when absent");
        let source = if record_has_stats { rig_name.clone() } else { "the given clips".to_string() };
        for f in &mut features {
            stats.normalise(f).with_context(|| format!("normalising with the statistics of {source}"))?;
        }
        if args.common.verbose {
            eprintln!("mo-encode: normalised with the statistics of {source}");
        }
    }

    let mut outputs = vec![(args.common.output.clone(), npy_bytes(clips, &features)?)];
    if let Some(path) = &args.stats {
        let stats = clip_stats.as_ref().expect("computed for --stats");
        outputs.push((Some(path.clone()), json_line(stats)?));
    }
    if let Some(path) = &args.placement {
        outputs.push((Some(path.clone()), placement_json(clips, &placements)?.into_bytes()));
    }
    if let Some(path) = &args.emit_skeleton {
        document.anytop = Some(section);
        outputs.push((Some(path.clone()), json_line(&document)?));
    }
    write_outputs(outputs)
}

fn json_line<T: serde::Serialize>(value: &T) -> anyhow::Result<Vec<u8>> {
    let mut out = serde_json::to_vec(value).context("serialising JSON")?;
    out.push(b'\n');
    Ok(out)
}

/// One clip's placement as written by `--placement` (the file name is for readers; decoding
/// ignores it).
#[derive(serde::Serialize)]
struct PlacementEntry<'a> {
    file: &'a str,
    #[serde(flatten)]
    placement: &'a Placement,
}

/// A JSON list, one clip per line.
fn placement_json(clips: &[Clip], placements: &[Placement]) -> anyhow::Result<String> {
    let lines = clips
        .iter()
        .zip(placements)
        .map(|(c, p)| serde_json::to_string(&PlacementEntry { file: &c.name, placement: p }))
        .collect::<Result<Vec<String>, _>>()
        .context("serialising placements")?;
    Ok(format!("[\n  {}\n]\n", lines.join(",\n  ")))
}

/// What `--placement` holds: a list (from `mo-encode`), or one placement.
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum PlacementFile {
    List(Vec<Placement>),
    One(Placement),
}

/// One placement per sample, from a `--placement` file.
fn read_placements(path: &Path, samples: usize, npy_name: &str) -> anyhow::Result<Vec<Placement>> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read placements {name}"))?;
    // JSON first, so a syntax error keeps its line and column (an untagged enum's error has none).
    let value: serde_json::Value = serde_json::from_slice(&bytes).map_err(|e| anyhow!("{name}: not a placement file (not JSON): {e}"))?;
    let placements = match serde_json::from_value::<PlacementFile>(value) {
        Ok(PlacementFile::List(list)) => list,
        Ok(PlacementFile::One(one)) => vec![one],
        Err(e) => bail!("{name}: not a placement file (a JSON list of {{\"heading\", \"root_xz\"}} as mo-encode --placement writes): {e}"),
    };
    if let Some(i) = placements.iter().position(|p| !(p.heading.is_finite() && p.root_xz.iter().all(|v| v.is_finite()))) {
        bail!("{name}: placement {i} holds a non-finite number");
    }
    if placements.len() != samples {
        bail!("{name} holds {} placement(s) but {npy_name} holds {samples} sample(s)", placements.len());
    }
    Ok(placements)
}

/// Write every output or none: files atomically, stdout last (it cannot be taken back); when a
/// file cannot be written, the files of this call already written are removed.
fn write_outputs(outputs: Vec<(Option<PathBuf>, Vec<u8>)>) -> anyhow::Result<()> {
    Ok(io::write_all(&outputs.iter().map(|(p, b)| (p.as_deref(), b.as_slice())).collect::<Vec<_>>())?)
}

/// Binary on a terminal is never what anyone wants (and can upset it).
fn refuse_terminal(output: Option<&Path>) -> anyhow::Result<()> {
    Ok(io::refuse_terminal(output, "a binary NPY", "use -o FILE.npy or a pipe")?)
}

/// The AnyTop record `--skeleton` stands for, the same way when encoding and decoding: the
/// document's own record; else one built (with the override flags) as `skel-info` builds it,
/// on frame 0 of `rest_pose` when given, else of the BVH, else (a document without motion) on
/// the OFFSET pose. A built record's statistics come from the BVH's motion, computed only when
/// `want_stats` (they cost encoding the whole file).
fn record_of(arg: &SkeletonFile, rest_pose: Option<&Clip>, args: &Args, want_stats: bool) -> anyhow::Result<AnyTopSection> {
    if let Some(section) = &arg.document.anytop {
        let fixed = [
            (rest_pose.is_some(), "--rest-pose"),
            (args.face_joints.is_some(), "--face-joints"),
            (args.body_axis.is_some(), "--body-axis"),
            (args.feet.is_some(), "--feet"),
        ];
        if let Some((_, flag)) = fixed.iter().find(|(on, _)| *on) {
            bail!(
                "{flag}: the AnyTop record of {} fixes the rig (rest pose, facing, feet); to build another, give --skeleton a BVH or a document without one (skel-info --no-anytop)",
                arg.name
            );
        }
        return Ok(section.clone());
    }
    let (rest, source) = match rest_pose {
        Some(clip) => {
            check_same_skeleton(&arg.name, &arg.skeleton, &clip.name, &clip.skeleton)?;
            (clip.motion.first_frames(2), RestSource::Explicit { file: clip.name.clone() })
        }
        None => arg.own_rest(),
    };
    let options = anytop_options(args, &arg.skeleton, &arg.name, source)?;
    let mut section = AnyTopSection::new(&arg.skeleton, &rest, &options).with_context(|| format!("{}: cannot build an AnyTop rig", arg.name))?;
    if let Some(motion) = arg.motion.as_ref().filter(|m| want_stats && m.frames >= 2) {
        let own = section.rig.encode(&arg.skeleton, motion).with_context(|| format!("{}: statistics of its motion", arg.name))?;
        section.stats = Some(AnyTopStats::compute([&own.features]).with_context(|| format!("{}: statistics of its motion", arg.name))?);
    }
    Ok(section)
}

/// The override flags as rig options, joint names resolved on `skeleton` (from `file`).
fn anytop_options(args: &Args, skeleton: &Skeleton, file: &str, rest_source: RestSource) -> anyhow::Result<RigOptions> {
    let mut options = RigOptions { rest_source, ..RigOptions::default() };
    if let Some(names) = &args.face_joints {
        let j = joint_indices("--face-joints", names, skeleton, file)?;
        let Ok(four) = <[usize; 4]>::try_from(j) else { bail!("--face-joints takes four joint names, R_HIP,L_HIP,R_SHOULDER,L_SHOULDER; got {}", names.len()) };
        if four[0] == four[1] || four[2] == four[3] {
            bail!("--face-joints: the right and left joint of a pair must differ (R_HIP,L_HIP,R_SHOULDER,L_SHOULDER)");
        }
        options.face_joints = Some(four);
    }
    if let Some(names) = &args.body_axis {
        let j = joint_indices("--body-axis", names, skeleton, file)?;
        let Ok([front, back]) = <[usize; 2]>::try_from(j) else { bail!("--body-axis takes two joint names, FRONT,BACK; got {}", names.len()) };
        if front == back {
            bail!("--body-axis: FRONT and BACK must be different joints");
        }
        options.body_axis = Some([front, back]);
    }
    if let Some(names) = &args.feet {
        options.feet = Some(joint_indices("--feet", names, skeleton, file)?);
    }
    Ok(options)
}

/// Joint indices of names given on the command line (`skeleton::lookup::find_joint`).
fn joint_indices(flag: &str, names: &[String], skeleton: &Skeleton, file: &str) -> anyhow::Result<Vec<usize>> {
    if names.iter().all(|n| n.trim().is_empty()) {
        bail!("{flag} needs joint names, separated by commas");
    }
    names
        .iter()
        .map(|raw| match lookup::find_joint(skeleton, raw) {
            Ok(j) => Ok(j),
            Err(lookup::LookupError::Empty) => bail!("{flag}: an empty joint name in '{}'", names.join(",")),
            Err(e) => bail!("{flag}: {file}: {e}"),
        })
        .collect()
}

/// One line about a rig, for -v.
fn describe_rig(rig: &AnyTopRig, skeleton: &Skeleton) -> String {
    let name = |j: usize| skeleton.joints.get(j).map_or("?", |x| x.name.as_str());
    let how = |p: Provenance| if p == Provenance::Override { "given" } else { "automatic" };
    let rest = match &rig.rest_source {
        RestSource::TPose { file } => format!("rest pose frame 0 of {file} (T-pose)"),
        RestSource::FirstClip { file } | RestSource::Explicit { file } => format!("rest pose frame 0 of {file}"),
        RestSource::Offsets => "rest pose from the OFFSETs".to_string(),
        RestSource::Unrecorded => "rest pose not recorded".to_string(),
    };
    let facing = match &rig.facing {
        Facing::FaceJoints(f) => format!("face joints {}, {}, {}, {}", name(f[0]), name(f[1]), name(f[2]), name(f[3])),
        Facing::BodyAxis { front, back } => format!("body axis {} -> {}", name(*back), name(*front)),
    };
    format!("{rest}; {facing} ({}); {} foot joint(s) ({}); scale {:.6}", how(rig.facing_source), rig.feet.len(), how(rig.feet_source), rig.scale_factor)
}

fn decode(args: &Args) -> anyhow::Result<()> {
    let input = match args.inputs.as_slice() {
        [] => PathBuf::from("-"),
        [one] => one.clone(),
        many => bail!("--decode reads one NPY file, got {}", many.len()),
    };
    let skeleton_path = args.skeleton.as_deref().context("--decode needs --skeleton")?;
    let arg = read_skeleton(skeleton_path)?;
    let skeleton = &arg.skeleton;
    let name = io::display_name(&input);
    let bytes = io::read_input(&input).with_context(|| format!("cannot read {name}"))?;
    let array = npy::from_bytes(&bytes, &name)?;
    drop(bytes);
    let (samples, batch) = split_samples(array, &name).map_err(anyhow::Error::msg)?;

    let decoder = match args.repr {
        Repr::M2m => FeatureDecoder::M2m,
        Repr::Anytop => {
            let rest_pose = args.rest_pose.as_deref().map(|p| load_clip(p, Some(2))).transpose()?;
            let section = record_of(&arg, rest_pose.as_ref(), args, args.normalised)?;
            let stats = match (args.normalised, section.stats) {
                (false, _) => None,
                (true, Some(stats)) => Some(stats),
                (true, None) => bail!(
                    "--normalised: {} has no AnyTop statistics to undo the normalisation with (give --skeleton the document mo-encode --emit-skeleton wrote for these features)",
                    arg.name
                ),
            };
            let placements = match args.placement.as_deref() {
                Some(p) => read_placements(p, samples.len(), &name)?,
                None => vec![section.rig.rest_placement(); samples.len()],
            };
            if args.common.verbose {
                eprintln!("mo-encode: rig: {}", describe_rig(&section.rig, skeleton));
            }
            FeatureDecoder::AnyTop { rig: Box::new(section.rig), stats, placements, from: args.from.unwrap_or(DecodeFrom::Rotations).into() }
        }
    };

    // Check everything before writing anything.
    let label = |i: usize| if batch { format!("{name}: sample {i}") } else { name.clone() };
    for (i, f) in samples.iter().enumerate() {
        decoder.check(f, skeleton).map_err(|(e, hint)| anyhow!("{}: {e} ({} features, skeleton {}){hint}", label(i), decoder.repr_name(), arg.name))?;
    }
    let target = args.common.output.as_deref();
    let paths: Vec<Option<PathBuf>> = if target.is_none_or(is_dash) {
        if samples.len() > 1 {
            bail!("{name} holds a batch of {} samples: give -o a pattern such as 'out_{{i}}.bvh' to write one BVH per sample", samples.len());
        }
        vec![None]
    } else {
        let pattern = target.expect("checked above");
        (0..samples.len()).map(|i| io::numbered_output(pattern, i, samples.len()).map(Some).map_err(anyhow::Error::msg)).collect::<anyhow::Result<_>>()?
    };

    let texts: Vec<anyhow::Result<Vec<u8>>> = samples
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let motion = decoder.decode(i, f, skeleton).map_err(|e| anyhow!("{}: {e}", label(i)))?;
            crate::cli::load::motion_file(skeleton, &motion, paths[i].as_deref(), MotionFormat::Bvh)
        })
        .collect();
    let texts = texts.into_iter().collect::<anyhow::Result<Vec<Vec<u8>>>>()?;
    if args.common.verbose {
        eprintln!("mo-encode: {name}: {} sample(s) of {} frames decoded on {}", samples.len(), samples.first().map_or(0, |f| f.frames), arg.name);
    }
    write_outputs(paths.into_iter().zip(texts).collect())
}
