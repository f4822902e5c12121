//! `mo-encode`: BVH motion -> feature tensors (NPY), and back (`--decode`).
//!
//! Everything learned or measured downstream sees motion through these tensors, so the tool is
//! the one place where representations meet files. Two representations:
//!
//! * `anytop` (the default, `repr::anytop`): 13 dims per joint, F frames -> F-1 feature frames.
//!   It needs a *rig*: per-skeleton quantities computed once from a rest pose (scale, ground,
//!   natural rest pose, face joints, feet). Encoding and decoding must use the same rig, so it
//!   travels in the skeleton document's AnyTop record (`--emit-skeleton`, or `skel-info`), and
//!   one rule (`input::SkeletonFile::record_with`) turns a `--skeleton` into a record in both directions: the
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

use crate::cli::load::{is_dash, read_skeleton, split_samples, FeatureDecoder, MotionFormat};
use crate::cli::{output, CommonOpts};
use crate::document::MotionInfo;
use crate::io::{self, npy};
use crate::motion::clip::Clip;
use crate::repr::batch::PoseFrom;

use crate::encode::{self, decode};
use crate::input;
use crate::motion::write;
use crate::repr::anytop::{placements, NamedOverrides};
use crate::repr::Features;
use crate::sata;
use anyhow::{bail, Context};
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
#[command(group = clap::ArgGroup::new("latents").args(["latent", "decode_latent"]))]
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
    pub from: Option<PoseFrom>,
    /// anytop decoding: the NPY holds normalised features; undo it with --skeleton's statistics.
    #[arg(long, requires = "decode")]
    pub normalised: bool,
    /// Encode one BVH clip into per-frame latents of the latent model (SATA): NPY [frames - 1,
    /// latent], the same size for every skeleton.
    #[arg(long, conflicts_with_all = ["decode", "repr", "skeleton"], conflicts_with_all = RIG_FLAGS)]
    pub latent: bool,
    /// Decode latents (NPY [frames, latent] from --latent) onto --skeleton, any skeleton, as
    /// BVH.
    #[arg(long, requires = "skeleton", conflicts_with_all = ["decode", "repr"], conflicts_with_all = RIG_FLAGS)]
    pub decode_latent: bool,
    /// The latent model: a directory from 'mo-train --arch sata' [default: the built-in one].
    #[arg(long, value_name = "DIR", requires = "latents")]
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

/// The flags that build or place an AnyTop rig, which latents do without (the latent model
/// builds each clip's rig itself).
const RIG_FLAGS: [&str; 9] = ["rest_pose", "face_joints", "body_axis", "feet", "require_contacts", "normalise", "stats", "emit_skeleton", "placement"];

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if args.latent || args.decode_latent {
        return latent(args);
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
    let dash = args.inputs.iter().filter(|p| is_dash(p)).count() + usize::from(args.skeleton.as_deref().is_some_and(is_dash));
    if dash > 1 || (args.decode_latent && args.inputs.is_empty() && args.skeleton.as_deref().is_some_and(is_dash)) {
        bail!("stdin ('-') can be read only once");
    }
    let device = candle_core::Device::Cpu;
    let model = sata::clips::frozen_or_default(args.model.as_deref(), &device)?;
    let bytes = if args.latent {
        let [input] = args.inputs.as_slice() else { bail!("--latent encodes one BVH clip, {} given", args.inputs.len()) };
        let clip = sata::clips::SourceClip::read(input, &crate::cli::load::gltf_options(), &model, &device)?;
        super::ood::Known::latent(args.model.as_deref(), &model.rigs)?.warn("mo-encode", &clip.name, &clip.skeleton, args.common.quiet)?;
        let latents = clip.encode(&model, &device)?;
        io::refuse_terminal(args.common.output.as_deref(), "binary NPY", "redirect stdout or give -o FILE")?;
        sata::clips::latents_npy(&latents).context("building the NPY")?
    } else {
        let input = match args.inputs.as_slice() {
            [] => PathBuf::from("-"),
            [one] => one.clone(),
            more => bail!("--decode-latent reads one NPY of latents, {} given", more.len()),
        };
        let latents = sata::clips::read_latents(&input)?;
        let skeleton = args.skeleton.as_deref().context("--decode-latent needs --skeleton")?;
        let target = sata::clips::Target::new(read_skeleton(skeleton)?, &model, &device)?;
        super::ood::Known::latent(args.model.as_deref(), &model.rigs)?.warn("mo-encode", &target.file.name, &target.file.skeleton, args.common.quiet)?;
        let frame_time = target.file.motion.as_ref().map_or(1.0 / 30.0, |m| m.frame_time);
        let motion = target.decode(&model, &latents, frame_time, &device)?;
        write::motion_file(&target.file.skeleton, &motion, args.common.output.as_deref(), MotionFormat::Bvh)?
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

/// `encode::read_clip` with this run's glTF options.
fn load_clip(path: &Path, frames: Option<usize>) -> anyhow::Result<(Clip, Option<MotionInfo>)> {
    Ok(encode::read_clip(path, frames, &crate::cli::load::gltf_options())?)
}

fn encode(args: &Args) -> anyhow::Result<()> {
    check_outputs(args)?;
    io::refuse_terminal(args.common.output.as_deref(), "a binary NPY", "use -o FILE.npy or a pipe")?;
    // Clips in parallel, results in argument order; the first failing argument is reported.
    let results: Vec<anyhow::Result<(Clip, Option<MotionInfo>)>> = args.inputs.par_iter().map(|p| load_clip(p, None)).collect();
    let (clips, infos): (Vec<Clip>, Vec<Option<MotionInfo>>) = results.into_iter().collect::<anyhow::Result<Vec<_>>>()?.into_iter().unzip();
    if clips.is_empty() {
        bail!("no BVH files to encode");
    }
    match args.repr {
        Repr::Anytop => encode_anytop(args, &clips, infos.into_iter().next().flatten()),
        Repr::M2m => encode_m2m(args, &clips),
    }
}

/// One NPY of the clips' features, checked finite first.
fn npy_bytes(clips: &[Clip], features: &[Features]) -> anyhow::Result<Vec<u8>> {
    encode::check_finite(clips, features)?;
    Features::batch_npy(features, false).context("building the NPY")
}

/// At most one output on stdout, and no file named for two outputs.
fn check_outputs(args: &Args) -> anyhow::Result<()> {
    let o = args.common.output.as_deref().unwrap_or(Path::new("-"));
    let given = [("--stats", &args.stats), ("--emit-skeleton", &args.emit_skeleton), ("--placement", &args.placement)];
    let outputs: Vec<(&str, &Path)> = [("-o", o)].into_iter().chain(given.iter().filter_map(|(flag, p)| Some((*flag, p.as_deref()?)))).collect();
    Ok(io::output::distinct(&outputs)?)
}

fn encode_m2m(args: &Args, clips: &[Clip]) -> anyhow::Result<()> {
    let say = args.common.say("mo-encode");
    let (features, warnings) = encode::m2m(clips)?;
    let first = &clips[0];
    for (clip, (f, warning)) in clips.iter().zip(features.iter().zip(&warnings)) {
        if let Some(w) = warning {
            say.warn(format_args!("{}: {w}", clip.name));
        }
        if first.skeleton.first_difference(&clip.skeleton).is_some() {
            say.warn(format_args!("{} and {} have the same shape but different joint names or parents", first.name, clip.name));
        }
        let [n, j, d] = f.shape();
        say.info(format_args!("{}: {} frames, {j} joints -> m2m features [{n}, {j}, {d}]", clip.name, clip.motion.frames));
    }
    output::write_all(&[(args.common.output.clone(), npy_bytes(clips, &features)?)])
}

fn encode_anytop(args: &Args, clips: &[Clip], first_info: Option<MotionInfo>) -> anyhow::Result<()> {
    let say = args.common.say("mo-encode");
    encode::check_frames(clips)?;
    let first = &clips[0];
    // Checked in this order: the clips, the rest pose, the skeleton file.
    encode::same_skeleton(clips)?;
    let rest_pose = args.rest_pose.as_deref().map(|p| load_clip(p, Some(2))).transpose()?.map(|(clip, _)| clip);
    if let Some(rest) = &rest_pose {
        input::same_skeleton(&first.name, &first.skeleton, &rest.name, &rest.skeleton)?;
    }
    let file = args.skeleton.as_deref().map(read_skeleton).transpose()?;
    let want_stats = args.normalise || args.emit_skeleton.is_some();
    let mut rig = encode::Rig::choose(clips, first_info, rest_pose.as_ref(), file, &overrides(args), want_stats)?;
    if rig.section.rig.feet.is_empty() {
        // Contacts are part of every AnyTop token; without feet they are all zero, which is
        // right for a fish but surprising for a walker whose feet the names did not reveal.
        if args.require_contacts {
            bail!("{}: no foot joints found for contact features (name them with --feet)", first.name);
        }
        say.warn(format_args!("{}: no foot joints found, so every contact feature is 0 (name them with --feet)", first.name));
    }
    say.info(format_args!("rig: {}", rig.section.rig.describe(&first.skeleton)));
    let (mut features, placements) = rig.encode(clips)?;
    for (clip, f) in clips.iter().zip(&features) {
        let [n, j, d] = f.shape();
        say.info(format_args!("{}: {} frames, {j} joints -> anytop features [{n}, {j}, {d}]", clip.name, clip.motion.frames));
    }
    let stats = rig.statistics(&mut features, args.stats.is_some(), want_stats, args.normalise)?;
    if let Some(from) = &stats.normalised_with {
        say.info(format_args!("normalised with the statistics of {from}"));
    }

    let mut outputs = vec![(args.common.output.clone(), npy_bytes(clips, &features)?)];
    if let Some(path) = &args.stats {
        let stats = stats.clips.as_ref().expect("computed for --stats");
        outputs.push((Some(path.clone()), json_line(stats)?));
    }
    if let Some(path) = &args.placement {
        let json = placements::to_json(clips.iter().map(|c| c.name.as_str()), &placements).context("serialising placements")?;
        outputs.push((Some(path.clone()), json.into_bytes()));
    }
    if let Some(path) = &args.emit_skeleton {
        rig.document.anytop = Some(rig.section);
        outputs.push((Some(path.clone()), json_line(&rig.document)?));
    }
    output::write_all(&outputs)
}

fn json_line<T: serde::Serialize>(value: &T) -> anyhow::Result<Vec<u8>> {
    let mut out = serde_json::to_vec(value).context("serialising JSON")?;
    out.push(b'\n');
    Ok(out)
}

/// The rig overrides given by joint name.
fn overrides(args: &Args) -> NamedOverrides {
    NamedOverrides { face_joints: args.face_joints.clone(), body_axis: args.body_axis.clone(), feet: args.feet.clone() }
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
    let (name, bytes) = io::read_named(&input)?;
    let array = npy::from_bytes(&bytes, &name)?;
    drop(bytes);
    let (samples, batch) = split_samples(array, &name).map_err(anyhow::Error::msg)?;

    let decoder = match args.repr {
        Repr::M2m => FeatureDecoder::M2m,
        Repr::Anytop => {
            let rest_pose = args.rest_pose.as_deref().map(|p| load_clip(p, Some(2))).transpose()?.map(|(clip, _)| clip);
            let section = arg.record_with(rest_pose.as_ref(), &overrides(args), args.normalised)?;
            let stats = decode::normalisation(section.stats, args.normalised, &arg.name)?;
            let placements = match args.placement.as_deref() {
                Some(p) => placements::read(p, samples.len(), &name).map_err(anyhow::Error::msg)?,
                None => vec![section.rig.rest_placement(); samples.len()],
            };
            args.common.say("mo-encode").info(format_args!("rig: {}", section.rig.describe(skeleton)));
            FeatureDecoder::AnyTop { rig: Box::new(section.rig), stats, placements, from: args.from.unwrap_or(PoseFrom::Rotations) }
        }
    };

    // Check everything before writing anything.
    let batch = decode::Samples { name: &name, batch, features: &samples, skeleton, skeleton_name: &arg.name };
    batch.check(&decoder)?;
    let target = args.common.output.as_deref();
    let paths: Vec<Option<PathBuf>> = if target.is_none_or(is_dash) {
        if samples.len() > 1 {
            bail!("{name} holds a batch of {} samples: give -o a pattern such as 'out_{{i}}.bvh' to write one BVH per sample", samples.len());
        }
        vec![None]
    } else {
        let pattern = target.expect("checked above");
        output::numbered(pattern, samples.len())?.into_iter().map(Some).collect()
    };

    let texts = batch.decode_files(&decoder, &paths)?;
    let frames = samples.first().map_or(0, |f| f.frames);
    args.common.say("mo-encode").info(format_args!("{name}: {} sample(s) of {frames} frames decoded on {}", samples.len(), arg.name));
    output::write_all(&paths.into_iter().zip(texts).collect::<Vec<_>>())
}
