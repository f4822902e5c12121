//! `mo-render`: pictures of motion. Loads BVH or NPY + skeleton through `cli::load` (the same
//! decoding every tool uses), poses them with our FK into `render::Track`s, and hands them to
//! the sheet, GIF and HTML renderers. Every picture is drawn in memory before any file is
//! written, so a bad input or option never leaves a partial or a stale-mixed set of outputs.

use crate::cli::load::{expand_inputs, is_dash, load_motions, DecodeFrom, LoadOptions};
use crate::cli::CommonOpts;
use crate::io;
use crate::render::camera::Framing;
use crate::render::gif::{render_gif, GifOptions};
use crate::render::html::{render_html, HtmlOptions};
use crate::render::labels::{self, FrameLabels, JointLabels};
use crate::render::sheet::{render_sheet, SheetOptions};
use crate::render::{Legend, Track, View};
use anyhow::bail;
use std::path::{Path, PathBuf};

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
    #[arg(long, value_enum, value_name = "FROM", default_value_t = DecodeFrom::Rotations)]
    pub from: DecodeFrom,
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
    #[arg(long, value_name = "X", default_value_t = 1.0)]
    pub speed: f64,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// The three kinds of picture.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Sheet,
    Gif,
    Html,
}

fn parse_range(s: &str) -> Result<(Option<usize>, Option<usize>), String> {
    let (a, b) = s.split_once(':').ok_or_else(|| format!("expected START:END, found '{s}'"))?;
    let num = |t: &str| -> Result<Option<usize>, String> {
        if t.trim().is_empty() {
            Ok(None)
        } else {
            t.trim().parse().map(Some).map_err(|_| format!("'{t}' is not a frame number"))
        }
    };
    let (start, end) = (num(a)?, num(b)?);
    if let (Some(s0), Some(e)) = (start, end) {
        if e <= s0 {
            return Err(format!("the range {s} is empty (END is exclusive)"));
        }
    }
    Ok((start, end))
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) =
        s.to_ascii_lowercase().split_once('x').map(|(a, b)| (a.to_string(), b.to_string())).ok_or_else(|| format!("expected WIDTHxHEIGHT, found '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("width '{w}' is not a whole number"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("height '{h}' is not a whole number"))?;
    if !(32..=4096).contains(&w) || !(32..=4096).contains(&h) {
        return Err(format!("sizes must be within 32..4096 pixels, found {w}x{h}"));
    }
    Ok((w, h))
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
        let by_extension = o.filter(|p| !is_dash(p)).and_then(|p| kind_of_extension(p));
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

fn kind_of_extension(p: &Path) -> Option<Kind> {
    match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "png" => Some(Kind::Sheet),
        "gif" => Some(Kind::Gif),
        "html" | "htm" => Some(Kind::Html),
        _ => None,
    }
}

fn read_text(path: &Path) -> anyhow::Result<String> {
    let (name, bytes) = io::read_named(path)?;
    String::from_utf8(bytes).map_err(|_| anyhow::anyhow!("{name}: not UTF-8 text"))
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if !(args.speed.is_finite() && args.speed > 0.0 && args.speed <= 100.0) {
        bail!("--speed must be within (0, 100], found {}", args.speed);
    }
    let outputs = outputs(args)?;
    let joint_labels = match &args.joint_labels {
        Some(p) => Some((JointLabels::from_json(&read_text(p)?, &io::display_name(p))?, io::display_name(p))),
        None => None,
    };
    let frame_labels = match &args.frame_labels {
        Some(p) => Some((FrameLabels::from_json(&read_text(p)?, &io::display_name(p))?, io::display_name(p))),
        None => None,
    };

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
    let mut pictures: Vec<(Vec<u8>, Option<PathBuf>, Kind)> = Vec::new();
    for (kind, path) in outputs {
        let bytes = draw(kind, &tracks, &legend, framing, args)?;
        pictures.push((bytes, path, kind));
    }
    // All pictures or none.
    io::write_all(&pictures.iter().map(|(b, p, _)| (p.as_deref(), b.as_slice())).collect::<Vec<_>>())?;
    for (bytes, path, kind) in &pictures {
        let target = path.as_ref().map_or("stdout".to_string(), |p| p.display().to_string());
        args.common.say("mo-render").info(format_args!("wrote {kind:?} ({} bytes, {} motion(s)) to {target}", bytes.len(), tracks.len()));
    }
    Ok(())
}

fn draw(kind: Kind, tracks: &[Track], legend: &Legend, framing: Framing, args: &Args) -> anyhow::Result<Vec<u8>> {
    Ok(match kind {
        Kind::Sheet => {
            let mut o = SheetOptions { view: args.view, framing, columns: args.columns as usize, max_rows: args.rows as usize, ..SheetOptions::default() };
            if let Some(k) = args.every {
                o.every = k as usize;
            }
            if let Some((w, h)) = args.size {
                o.cell_width = w;
                o.cell_height = h;
            }
            render_sheet(tracks, legend, &o)?
        }
        Kind::Gif => {
            let mut o = GifOptions { view: args.view, framing, ..GifOptions::default() };
            if let Some((w, h)) = args.size {
                o.panel_width = w;
                o.panel_height = h;
            }
            render_gif(tracks, legend, &o)?
        }
        Kind::Html => {
            let title = tracks.iter().map(|t| t.title.as_str()).collect::<Vec<_>>().join(" | ");
            let o = HtmlOptions { title, speed: args.speed, overlay: args.overlay, ..HtmlOptions::default() };
            render_html(tracks, legend, &o)?.into_bytes()
        }
    })
}
