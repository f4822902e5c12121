//! `mo-render`: pictures of motion. Loads BVH or NPY + skeleton through `cli::load` (the same
//! decoding every tool uses), poses them with our FK into `render::Track`s, and hands them to
//! the sheet, GIF and HTML renderers. Every picture is drawn in memory before any file is
//! written, so a bad input or option never leaves a partial or a stale-mixed set of outputs.

use crate::cli::load::{expand_inputs, is_dash, load_motions, LoadOptions};
use crate::cli::CommonOpts;
use crate::io;
use crate::render::camera::Framing;
use crate::render::labels::{self, FrameLabels, JointLabels};
use crate::render::picture::{parse_range, parse_size, Look, Picture as Kind};
use crate::render::{Track, View};
use crate::repr::batch::PoseFrom;
use anyhow::bail;
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    mo-render examples/data/dragon.bvh --sheet dragon.png
    mo-render examples/data/quadruped.bvh examples/data/biped.bvh --gif walkers.gif --frames 0:60
    mo-render examples/data/spider.bvh --view top --every 4 --columns 6 -o spider.png
    mo-render examples/data/crab.bvh examples/data/fish.bvh --html zoo.html --sheet zoo.png
    mo-encode examples/data/bird.bvh | mo-render - --skeleton examples/data/bird.bvh -o bird.png
    mo-render examples/data/snake.bvh --view 30,20 --fixed-camera --format gif > snake.gif";

/// Draw motion: contact sheets (PNG), animations (GIF) and a 3D viewer (self-contained HTML).
///
/// Inputs are BVH files, NPY feature files decoded on --skeleton (AnyTop 13-D or Motion2Motion
/// 9-D features, as mo-encode writes them; a batch [n, frames, joints, dims] gives n motions),
/// or directories of them. Several motions are drawn side by side: in a sheet, one band of rows
/// per motion with the same frame numbers in the same columns, so a source and its retarget
/// compare frame by frame.
///
/// Outputs: --sheet PATH (PNG), --gif PATH, --html PATH, any combination; or -o PATH, whose
/// extension (.png, .gif, .html) says which; or --format with -o - / stdout. All pictures are
/// drawn before any file is written, and files are written atomically.
///
/// The camera is orthographic and y is up. --view auto looks from the side of the main direction
/// of travel so walks go left to right. The camera is fitted to each motion's points, so a mouse
/// and a dragon both fill their frames; by default it follows the body (the scale is fixed per
/// motion, so size changes stay visible); --fixed-camera shows travel over the whole clip.
///
/// Sheet: every k-th frame (--every; by default chosen so each motion fills at most --rows rows
/// of --columns cells), file name, fps and frame numbers written on it, feet marked, ground line.
/// GIF: played at the motion's frame rate (GIF timing has 1/100 s steps: above 50 fps frames
/// are skipped to keep real time), looping. HTML: one file with inline JavaScript, no network:
/// drag to orbit, wheel to zoom, space to play/pause, a frame slider, speed, a ground grid and
/// joint names on hover.
///
/// Colour by data: --joint-labels FILE colours joints and bones (a JSON object joint name ->
/// label, a list with one label per joint, or either under "joints"); --frame-labels FILE tints
/// frames (a list with one label per frame, {"labels": [...]}, or {"segments": [{"start",
/// "end", "label"}]} as mo-segment writes). Labels get a legend.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-render", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH files, NPY feature files (with --skeleton) or directories of them ('-' = stdin).
    #[arg(value_name = "INPUT", default_value = "-")]
    pub inputs: Vec<PathBuf>,
    /// Write a PNG contact sheet here.
    #[arg(long, value_name = "PATH")]
    pub sheet: Option<PathBuf>,
    /// Write an animated GIF here.
    #[arg(long, value_name = "PATH")]
    pub gif: Option<PathBuf>,
    /// Write a self-contained HTML viewer here.
    #[arg(long, value_name = "PATH")]
    pub html: Option<PathBuf>,
    /// What -o (or stdout) gets when its extension does not say [possible values: sheet, gif, html].
    #[arg(long, value_enum, value_name = "KIND")]
    pub format: Option<Kind>,
    /// Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file.
    #[arg(long, value_name = "PATH")]
    pub skeleton: Option<PathBuf>,
    /// AnyTop features: pose from their rotations (exact for encoded clips) or their positions
    /// (inverse kinematics, for generated clips).
    #[arg(long, value_enum, value_name = "FROM", default_value_t = PoseFrom::Rotations)]
    pub from: PoseFrom,
    /// Camera: auto, side, front, top, or YAW,PITCH in degrees (yaw about +y, 0 = side; pitch > 0
    /// looks down).
    #[arg(long, value_name = "VIEW", default_value = "auto", value_parser = View::parse)]
    pub view: View,
    /// Draw only frames START:END (END exclusive; either may be omitted: '100:', ':50').
    #[arg(long, value_name = "START:END", value_parser = parse_range)]
    pub frames: Option<(Option<usize>, Option<usize>)>,
    /// Sheet: draw every K-th frame [default: chosen so each motion fills at most --rows rows].
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u64).range(1..))]
    pub every: Option<u64>,
    /// Sheet: cells per row.
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=200))]
    pub columns: u64,
    /// Sheet: at most this many rows per motion when --every is not given.
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub rows: u64,
    /// Size of a sheet cell or a GIF panel in pixels, WIDTHxHEIGHT [default: 160x160 for sheets,
    /// 256x256 for GIFs].
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// One camera for the whole clip (shows travel) instead of following the body.
    #[arg(long)]
    pub fixed_camera: bool,
    /// JSON file of per-joint labels (colours joints and bones).
    #[arg(long, value_name = "FILE")]
    pub joint_labels: Option<PathBuf>,
    /// JSON file of per-frame labels (tints frames), e.g. mo-segment's output.
    #[arg(long, value_name = "FILE")]
    pub frame_labels: Option<PathBuf>,
    /// HTML: draw all motions in one scene instead of side by side.
    #[arg(long)]
    pub overlay: bool,
    /// HTML: initial playback speed.
    #[arg(long, value_name = "X", default_value_t = 1.0, value_parser = crate::cli::bounds::positive(100.0))]
    pub speed: f64,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// Where each picture goes (`None` = stdout).
fn outputs(args: &Args) -> anyhow::Result<Vec<(Kind, Option<PathBuf>)>> {
    let mut out: Vec<(Kind, Option<PathBuf>)> = Vec::new();
    for (kind, path) in [(Kind::Sheet, &args.sheet), (Kind::Gif, &args.gif), (Kind::Html, &args.html)] {
        if let Some(p) = path {
            out.push((kind, if is_dash(p) { None } else { Some(p.clone()) }));
        }
    }
    let o = args.common.output.as_ref();
    if o.is_some() || out.is_empty() {
        let by_extension = o.filter(|p| !is_dash(p)).and_then(|p| Kind::of_path(p));
        let kind = match (args.format, by_extension) {
            (Some(k), _) => k,
            (None, Some(k)) => k,
            (None, None) => match o {
                Some(p) if !is_dash(p) => bail!("{}: cannot tell the picture kind from the extension: use .png, .gif or .html, or --format", p.display()),
                _ if out.is_empty() => {
                    bail!("say what to draw: --sheet out.png, --gif out.gif, --html out.html, or -o with one of those extensions (--format for stdout)")
                }
                _ => bail!("-o - needs --format sheet|gif|html"),
            },
        };
        out.push((kind, o.filter(|p| !is_dash(p)).cloned()));
    }
    if out.iter().filter(|(_, p)| p.is_none()).count() > 1 {
        bail!("only one picture can go to stdout");
    }
    if let Some((kind, _)) = out.iter().find(|(_, p)| p.is_none()).filter(|(k, _)| *k != Kind::Html) {
        io::refuse_terminal(None, if *kind == Kind::Sheet { "a PNG" } else { "a GIF" }, "give a file (--sheet out.png, -o out.gif) or redirect stdout")?;
    }
    Ok(out)
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    let outputs = outputs(args)?;
    let joint_labels = args.joint_labels.as_deref().map(JointLabels::read).transpose()?;
    let frame_labels = args.frame_labels.as_deref().map(FrameLabels::read).transpose()?;

    let inputs = expand_inputs(&args.inputs)?;
    let options = LoadOptions { skeleton: args.skeleton.as_deref(), from: Some(args.from) };
    let loaded = load_motions(&inputs, &options)?;
    if loaded.is_empty() {
        bail!("no motion to draw");
    }
    if let Some((labels, file)) = &frame_labels {
        labels.check_fits(loaded.iter().map(|l| l.motion.frames).max().unwrap_or(0), file)?;
    }
    let (first_frame, mut tracks) = Track::from_clips(&loaded, args.frames).map_err(anyhow::Error::msg)?;
    let skeletons: Vec<_> = loaded.iter().map(|l| &l.skeleton).collect();
    let legend = labels::apply(
        &mut tracks,
        &skeletons,
        joint_labels.as_ref().map(|(l, f)| (l, f.as_str())),
        frame_labels.as_ref().map(|(l, f)| (l, f.as_str())),
        first_frame,
    )?;

    let framing = if args.fixed_camera { Framing::Fixed } else { Framing::Follow };
    let (every, columns, rows) = (args.every.map(|k| k as usize), args.columns as usize, args.rows as usize);
    let look = Look { view: args.view, framing, every, columns, rows, size: args.size, speed: args.speed, overlay: args.overlay };
    let mut pictures: Vec<(Vec<u8>, Option<PathBuf>, Kind)> = Vec::new();
    for (kind, path) in outputs {
        pictures.push((kind.draw(&tracks, &legend, &look)?, path, kind));
    }
    // All pictures or none.
    io::write_all(&pictures.iter().map(|(b, p, _)| (p.as_deref(), b.as_slice())).collect::<Vec<_>>())?;
    for (bytes, path, kind) in &pictures {
        let target = path.as_ref().map_or("stdout".to_string(), |p| p.display().to_string());
        args.common.say("mo-render").info(format_args!("wrote {kind:?} ({} bytes, {} motion(s)) to {target}", bytes.len(), tracks.len()));
    }
    Ok(())
}
