//! `mo-edit`: the everyday edits of a clip, one subcommand each, composable in pipes. This file
//! only reads, calls `edit` and writes; the edits themselves live in `lib/edit`.

use crate::cli::load::{is_dash, read_bvh_clip, read_example_clips};
use crate::cli::mo_metrics::Contact;
use crate::cli::output::OutFormat;
use crate::cli::{bounds, CommonOpts};
use crate::edit::space::{Axes, SignedAxis, Units};
use crate::edit::time::Span;
use crate::edit::{self, EditError};
use crate::io;
use crate::motion::write::{motion_bytes, MotionFormat};
use crate::motion::Clip;
use crate::motion::Motion;
use crate::repr::Features;
use crate::skeleton::Skeleton;
use anyhow::{anyhow, bail, Context};
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-edit convert examples/data/biped.bvh -o biped.glb
    mo-edit resample biped.glb --fps 60 -o biped60.gltf
    mo-edit trim examples/data/biped.bvh --seconds 0.5:2.5 | mo-edit loop --blend 0.2 -o loop.bvh
    mo-edit concat examples/data/quadruped.bvh examples/data/quadruped.bvh --blend 0.2 -o quad2.bvh
    mo-edit mirror examples/data/crab.bvh | mo-edit in-place --keep-heading -o crab.glb
    mo-edit axis examples/data/dragon.bvh --from y-up --to z-up | mo-edit axis --from z-up --to y-up
    mo-edit scale examples/data/bird.bvh --to-units cm --from-units m -o bird_cm.bvh
    mo-edit rest examples/data/spider.bvh --frame 10 | mo-edit rename --normalise
    mo-edit in-place examples/data/biped.bvh | mo-edit root --path examples/data/biped.bvh -o b.bvh
    mo-edit foot-lock examples/data/quadruped.bvh -v -o quad_locked.bvh
    mo-edit convert examples/data/fish.bvh --format npy > fish.npy";

/// The everyday edits of a clip: convert, resample, trim, concat, loop, mirror, axis, scale,
/// in-place, root, rest, rename, foot-lock.
///
/// Each subcommand reads a BVH or glTF (.gltf, .glb) clip, a file or '-' for stdin, and writes
/// the edited clip as BVH, glTF, GLB or NPY (Motion2Motion features [frames, joints, 9]):
/// the format of -o's extension, else --format, else BVH on stdout. So edits chain in pipes,
/// and a clip goes to Blender and back: mo-edit axis in.glb --from y-up --to z-up -o out.glb.
///
/// Vertical is y, as in BVH and glTF (turn z-up data first with 'axis'). Frame ranges A:B
/// include both ends (Blender's frame range), so trimming 0:N and N: and concatenating the two
/// gives the clip back. Errors are one line naming the file, and nothing is written.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-edit", version, after_long_help = EXAMPLES)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
    /// Output format when -o has no telling extension or is stdout.
    #[arg(long, value_enum, value_name = "FORMAT", global = true)]
    pub format: Option<OutFormat>,
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Change the format only.
    Convert {
        #[arg(default_value = "-")]
        input: PathBuf,
    },
    /// New frame rate (the global --fps): rotations slerped, positions interpolated.
    Resample {
        #[arg(default_value = "-")]
        input: PathBuf,
    },
    /// Keep a range of frames (--frames A:B) or seconds (--seconds S:E), both ends included.
    Trim {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long, value_name = "A:B", conflicts_with = "seconds", required_unless_present = "seconds")]
        frames: Option<Span>,
        #[arg(long, value_name = "S:E")]
        seconds: Option<Span>,
    },
    /// Join clips of one skeleton and frame rate: each starts where and facing how the one
    /// before ends (its first frame replaces the previous last), the pose eased across seams.
    Concat {
        #[arg(required = true, num_args = 1..)]
        inputs: Vec<PathBuf>,
        /// Seconds of easing on each side of every seam.
        #[arg(long, value_name = "S", default_value_t = 0.0, value_parser = bounds::non_negative(60.0))]
        blend: f64,
    },
    /// Make the clip loop: its end eased into its start, its last frame dropped.
    Loop {
        #[arg(default_value = "-")]
        input: PathBuf,
        /// Seconds of easing on each side of the seam.
        #[arg(long, value_name = "S", default_value_t = 0.25, value_parser = bounds::non_negative(60.0))]
        blend: f64,
    },
    /// Swap left and right (skel-info's sides; partners by name, else by mirrored rest position).
    Mirror {
        #[arg(default_value = "-")]
        input: PathBuf,
    },
    /// Re-express rest pose and motion in another axis convention (forward: +z for y-up, -y for z-up).
    Axis {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long, value_name = "UP", allow_hyphen_values = true)]
        from: SignedAxis,
        #[arg(long, value_name = "UP", allow_hyphen_values = true)]
        to: SignedAxis,
        #[arg(long, value_name = "AXIS", allow_hyphen_values = true)]
        from_forward: Option<SignedAxis>,
        #[arg(long, value_name = "AXIS", allow_hyphen_values = true)]
        to_forward: Option<SignedAxis>,
    },
    /// Scale OFFSETs and root motion by --factor, or to --to-units (m, cm, mm, in).
    Scale {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long, value_name = "K", conflicts_with = "to_units", required_unless_present = "to_units", value_parser = bounds::positive(1e9))]
        factor: Option<f64>,
        #[arg(long, value_name = "UNIT")]
        to_units: Option<Units>,
        /// The clip's units [default: guessed: cm if it is 20 units or more across, else m].
        #[arg(long, value_name = "UNIT", requires = "to_units")]
        from_units: Option<Units>,
    },
    /// Remove the root's travel over the ground (and its turning, unless --keep-heading).
    InPlace {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long)]
        keep_heading: bool,
    },
    /// Replace the root's travel and turning with another clip's (--path, any skeleton).
    Root {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long, value_name = "FILE")]
        path: PathBuf,
    },
    /// Set the rest pose (OFFSETs) from --frame N, or from frame 0 of --t-pose FILE (same skeleton).
    Rest {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long, value_name = "N", conflicts_with = "t_pose", required_unless_present = "t_pose")]
        frame: Option<usize>,
        #[arg(long, value_name = "FILE")]
        t_pose: Option<PathBuf>,
    },
    /// Rename joints from --map (JSON {\"old\": \"new\"} or lines 'old new'), or --normalise them.
    Rename {
        #[arg(default_value = "-")]
        input: PathBuf,
        #[arg(long, value_name = "FILE", conflicts_with = "normalise", required_unless_present = "normalise")]
        map: Option<PathBuf>,
        #[arg(long)]
        normalise: bool,
    },
    /// Pin feet during contacts (mo-metrics physics' rule) by two-bone IK; -v reports skating.
    FootLock {
        #[arg(default_value = "-")]
        input: PathBuf,
        /// Seconds of easing into and out of each contact.
        #[arg(long, value_name = "S", default_value_t = 0.1, value_parser = bounds::non_negative(60.0))]
        blend: f64,
        #[command(flatten)]
        contact: Contact,
    },
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    let read = |p: &Path| read_bvh_clip(p, "mo-edit");
    let (name, skeleton, motion) = match &args.command {
        Command::Concat { inputs, blend } => {
            let clips = read_example_clips(inputs, "mo-edit", "clips to join")?;
            let motions: Vec<Motion> = clips.iter().map(|c| c.motion.clone()).collect();
            crate::budget::check_motion("the joined clip", motions.iter().map(|m| m.frames).sum(), clips[0].skeleton.len())?;
            let joined = edit::time::concat(&clips[0].skeleton, &motions, frames(*blend, &motions[0])).map_err(|e| named(&clips[0].name, e))?;
            (clips[0].name.clone(), clips[0].skeleton.clone(), joined)
        }
        Command::Convert { input } | Command::Resample { input } | Command::Mirror { input } => {
            let c = read(input)?;
            let motion = match &args.command {
                Command::Resample { .. } => resample(&c, args.common.fps)?,
                Command::Mirror { .. } => edit::space::mirror(&c.skeleton, &c.motion).map_err(|e| named(&c.name, e))?,
                _ => c.motion.clone(),
            };
            (c.name, c.skeleton, motion)
        }
        command => {
            let c = read(input_of(command))?;
            let (skeleton, motion) = edit_one(command, &c, args.common.verbose).map_err(|e| named(&c.name, e))?;
            (c.name, skeleton, motion)
        }
    };
    if args.common.verbose {
        eprintln!("mo-edit: {name}: {} frames at {:.3} fps, {} joints", motion.frames, 1.0 / motion.frame_time, skeleton.len());
    }
    write(args, skeleton, motion)
}

/// The input of a one-clip subcommand.
fn input_of(command: &Command) -> &Path {
    match command {
        Command::Convert { input } | Command::Resample { input } | Command::Mirror { input } => input,
        Command::Trim { input, .. } | Command::Loop { input, .. } | Command::Axis { input, .. } | Command::Scale { input, .. } => input,
        Command::InPlace { input, .. } | Command::Root { input, .. } | Command::Rest { input, .. } | Command::Rename { input, .. } => input,
        Command::FootLock { input, .. } => input,
        Command::Concat { .. } => Path::new("-"),
    }
}

fn named(name: &str, e: EditError) -> anyhow::Error {
    anyhow!("{name}: {e}")
}

/// Seconds as a whole number of frames of `motion`.
fn frames(seconds: f64, motion: &Motion) -> usize {
    (seconds / motion.frame_time).round() as usize
}

fn resample(c: &Clip, fps: Option<f64>) -> anyhow::Result<Motion> {
    let fps = fps.context("resample needs the new frame rate: --fps F")?;
    let out_frames = ((c.motion.frames.saturating_sub(1)) as f64 * c.motion.frame_time * fps).min(u64::MAX as f64) as usize + 1;
    crate::budget::check_motion(&format!("{}: the resampled clip", c.name), out_frames, c.skeleton.len())?;
    edit::time::resample(&c.motion, fps).map_err(|e| named(&c.name, e))
}

/// The one-clip edits that may change the skeleton.
fn edit_one(command: &Command, c: &Clip, verbose: bool) -> Result<(Skeleton, Motion), EditError> {
    let (s, m) = (&c.skeleton, &c.motion);
    let keep = |m: Motion| Ok((s.clone(), m));
    match command {
        Command::Trim { frames: f, seconds, .. } => {
            let (first, last) = edit::time::span_frames(m, seconds.or(*f).unwrap_or(Span { start: None, end: None }), seconds.is_some())?;
            keep(edit::time::trim(m, first, last)?)
        }
        Command::Loop { blend, .. } => keep(edit::time::make_loop(s, m, frames(*blend, m))?),
        Command::Axis { from, to, from_forward, to_forward, .. } => edit::space::axis(s, m, Axes::new(*from, *from_forward)?, Axes::new(*to, *to_forward)?),
        Command::Scale { factor, to_units, from_units, .. } => {
            let factor = match (factor, to_units) {
                (Some(k), _) => *k,
                (None, Some(to)) => from_units.unwrap_or_else(|| Units::guess(s)).metres() / to.metres(),
                (None, None) => 1.0,
            };
            edit::space::scale(s, m, factor)
        }
        Command::InPlace { keep_heading, .. } => keep(edit::root::in_place(s, m, *keep_heading)?),
        Command::Root { path, .. } => {
            let p = read_bvh_clip(path, "mo-edit").map_err(|e| EditError::Invalid(format!("{e:#}")))?;
            keep(edit::root::follow_path(s, m, &p.motion).map_err(|e| EditError::Mismatch(format!("{}: {e}", p.name)))?)
        }
        Command::Rest { frame: Some(n), .. } => edit::rest::from_frame(s, m, *n),
        Command::Rest { t_pose, .. } => {
            let path = t_pose.as_deref().unwrap_or(Path::new("-"));
            let p = read_bvh_clip(path, "mo-edit").map_err(|e| EditError::Invalid(format!("{e:#}")))?;
            if let Some(why) = s.first_difference(&p.skeleton) {
                return Err(EditError::Mismatch(format!("the T-pose {} has another skeleton ({why})", p.name)));
            }
            edit::rest::from_pose(s, m, &p.motion)
        }
        Command::Rename { normalise: true, .. } => Ok((edit::rename::normalise(s)?, m.clone())),
        Command::Rename { map, .. } => {
            let pairs = edit::rename::read_map(map.as_deref().unwrap_or(Path::new("-")))?;
            Ok((edit::rename::rename(s, &pairs)?, m.clone()))
        }
        Command::FootLock { blend, contact, .. } => {
            let options = contact.options().map_err(|e| EditError::Invalid(e.to_string()))?;
            let (out, report) = edit::foot_lock::foot_lock(s, m, &options, frames(*blend, m))?;
            if verbose {
                for line in report.lines() {
                    eprintln!("mo-edit: foot-lock: {line}");
                }
            }
            keep(out)
        }
        Command::Convert { .. } | Command::Resample { .. } | Command::Mirror { .. } | Command::Concat { .. } => keep(m.clone()),
    }
}

/// Write the edited clip in the format asked for, all or nothing.
fn write(args: &Args, mut skeleton: Skeleton, motion: Motion) -> anyhow::Result<()> {
    if let Some((f, j)) = motion.first_non_finite() {
        bail!("the edit gives a non-finite pose at frame {f}, joint {j} '{}'", skeleton.joints[j].name);
    }
    edit::fit_channels(&mut skeleton, &motion);
    let out = args.common.output.as_deref().filter(|p| !is_dash(p));
    let format = match (args.format, out) {
        (Some(f), _) => f,
        (None, Some(p)) if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("npy")) => OutFormat::Npy,
        (None, Some(p)) => match MotionFormat::of_path(p) {
            MotionFormat::Glb => OutFormat::Glb,
            MotionFormat::Gltf => OutFormat::Gltf,
            MotionFormat::Bvh => OutFormat::Bvh,
        },
        (None, None) => OutFormat::Bvh,
    };
    let name = out.map_or_else(|| "<stdout>".to_string(), |p| p.display().to_string());
    if matches!(format, OutFormat::Npy | OutFormat::Glb) {
        io::refuse_terminal(out, if format == OutFormat::Npy { "NPY" } else { "binary glTF" }, "give -o FILE or redirect stdout")?;
    }
    let bytes = match format {
        OutFormat::Npy => Features::batch_npy(&[crate::repr::m2m::encode(&motion)], false).context("building the NPY")?,
        format => motion_bytes(&skeleton, &motion, format.motion(), &name)?,
    };
    Ok(io::write_output(out, &bytes)?)
}
