//! Picture rendering time: `cargo bench --bench render`.
//!
//! Issue 6 asks that a 1000-frame, 86-joint motion renders to a contact sheet or a GIF in well
//! under a second. The motion is the Monkey walk of `../shared/data/bvh/truebones_motion2motion`
//! (86 joints) when the corpus is present, else the project's spider, repeated to 1000 frames.
//! The table gives the median of `RUNS` runs, one thread.
//!
//! With `RENDER_LOOK_DIR=/some/dir` it also writes a sheet and a GIF of every creature in
//! `examples/data` and of a few corpus files there, for looking at.

mod common;
use common::{median, ms, time_runs, RUNS};

use menagerie::bvh;
use menagerie::motion::Motion;
use menagerie::render::camera::Framing;
use menagerie::render::gif::{render_gif, GifOptions};
use menagerie::render::sheet::{render_sheet, SheetOptions};
use menagerie::render::{Legend, Track, View};
use menagerie::skeleton::Skeleton;
use std::hint::black_box;
use std::path::{Path, PathBuf};

fn load(path: &Path) -> Track {
    let bytes = std::fs::read(path).unwrap();
    let name = path.file_name().unwrap().to_string_lossy().to_string();
    let parsed = bvh::parse_bytes(&bytes, &name).unwrap();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    Track::from_motion(&name, &skeleton, &motion)
}

/// `track` played over and over until it has `frames` frames.
fn repeated(track: &Track, frames: usize) -> Track {
    let mut t = track.clone();
    t.positions = track.positions.iter().cycle().take(frames * track.points()).copied().collect();
    t.frames = frames;
    t
}

/// Composite GIF frame `k` to a PNG, to look at a GIF with a PNG viewer.
fn gif_frame_png(gif_bytes: &[u8], k: usize, out: &Path) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut d = options.read_info(std::io::Cursor::new(gif_bytes)).unwrap();
    let (w, h) = (d.width() as usize, d.height() as usize);
    let mut screen = vec![0u8; w * h * 3];
    let mut i = 0;
    while let Some(f) = d.read_next_frame().unwrap() {
        for y in 0..f.height as usize {
            for x in 0..f.width as usize {
                let p = &f.buffer[(y * f.width as usize + x) * 4..][..4];
                if p[3] != 0 {
                    let o = ((f.top as usize + y) * w + f.left as usize + x) * 3;
                    screen[o..o + 3].copy_from_slice(&p[..3]);
                }
            }
        }
        if i == k {
            break;
        }
        i += 1;
    }
    let canvas = menagerie::render::raster::Canvas { width: w as u32, height: h as u32, pixels: screen };
    std::fs::write(out, canvas.to_png().unwrap()).unwrap();
}

fn look(root: &Path, dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let mut files: Vec<PathBuf> = common::bvh_files(&root.join("examples/data"));
    let corpus = root.join("../shared/data/bvh");
    for f in [
        "lafan1/walk1_subject1.bvh",
        "cmu_bvh11/131_01.bvh",
        "dog_mann/Dog/D1_001_KAN01_001.bvh",
        "truebones_motion2motion/Monkey/__Walk.bvh",
        "truebones_anytop/Chicken/Chicken_IdlePecking.bvh",
    ] {
        if corpus.join(f).is_file() {
            files.push(corpus.join(f));
        }
    }
    let legend = Legend::default();
    for f in files {
        let track = load(&f);
        let stem = f.file_stem().unwrap().to_string_lossy().to_string();
        let sheet = render_sheet(std::slice::from_ref(&track), &legend, &SheetOptions::default()).unwrap();
        std::fs::write(dir.join(format!("{stem}.png")), sheet).unwrap();
        let fixed = SheetOptions { framing: Framing::Fixed, ..Default::default() };
        std::fs::write(dir.join(format!("{stem}-fixed.png")), render_sheet(std::slice::from_ref(&track), &legend, &fixed).unwrap()).unwrap();
        let short = Track { frames: track.frames.min(240), positions: track.positions[..track.frames.min(240) * track.points()].to_vec(), ..track };
        let gif_bytes = render_gif(&[short], &legend, &GifOptions::default()).unwrap();
        gif_frame_png(&gif_bytes, 20, &dir.join(format!("{stem}-gif20.png")));
        std::fs::write(dir.join(format!("{stem}.gif")), gif_bytes).unwrap();
        println!("wrote {stem}.png, {stem}-fixed.png, {stem}.gif");
    }
    // Other views.
    let q = load(&root.join("examples/data/quadruped.bvh"));
    for (name, view) in [("top", View::Top), ("front", View::Front), ("angle", View::Angle { yaw: 30.0, pitch: 25.0 })] {
        let opts = SheetOptions { view, every: 10, columns: 5, max_rows: 1, ..Default::default() };
        std::fs::write(dir.join(format!("quadruped-{name}.png")), render_sheet(std::slice::from_ref(&q), &legend, &opts).unwrap()).unwrap();
    }
    // Two motions side by side with labels: tints, label colours, legend.
    let mut a = load(&root.join("examples/data/biped.bvh"));
    let mut b = load(&root.join("examples/data/quadruped.bvh"));
    for t in [&mut a, &mut b] {
        t.frame_labels = Some((0..t.frames).map(|f| if f % 40 < 20 { Some(0) } else { Some(1) }).collect());
        t.point_labels = Some((0..t.points()).map(|p| Some(2 + p % 3)).collect());
    }
    let labels = Legend { labels: ["walk", "turn", "spine", "left leg", "right leg"].map(String::from).to_vec() };
    let sheet = render_sheet(&[a.clone(), b.clone()], &labels, &SheetOptions { every: 8, ..Default::default() }).unwrap();
    std::fs::write(dir.join("pair.png"), sheet).unwrap();
    let gif_bytes = render_gif(&[a, b], &labels, &GifOptions::default()).unwrap();
    gif_frame_png(&gif_bytes, 30, &dir.join("pair-gif30.png"));
    std::fs::write(dir.join("pair.gif"), gif_bytes).unwrap();
}

/// CPU time of this thread in ns (Linux), so a busy machine does not inflate the numbers the
/// issue states in CPU time; `None` elsewhere.
fn thread_cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat").ok()?.split_whitespace().next()?.parse().ok()
}

/// Median wall time and median CPU time (ms) of `RUNS` runs of `f`.
fn measure(mut f: impl FnMut()) -> (f64, Option<f64>) {
    let mut cpu = Vec::new();
    let wall = time_runs(|| {
        let c0 = thread_cpu_ns();
        f();
        if let (Some(a), Some(b)) = (c0, thread_cpu_ns()) {
            cpu.push(b - a);
        }
    });
    cpu.sort();
    (ms(median(&wall)), cpu.get(cpu.len() / 2).map(|&ns| ns as f64 / 1e6))
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    if let Some(dir) = std::env::var_os("RENDER_LOOK_DIR") {
        look(root, Path::new(&dir));
    }
    let monkey = root.join("../shared/data/bvh/truebones_motion2motion/Monkey/__Walk.bvh");
    let (source, base) = if monkey.is_file() {
        ("Monkey __Walk (corpus)", load(&monkey))
    } else {
        println!("note: ../shared/data absent, using examples/data/spider.bvh");
        ("spider (examples)", load(&root.join("examples/data/spider.bvh")))
    };
    let track = repeated(&base, 1000);
    let tracks = [track];
    let legend = Legend::default();
    println!("render: {source}, {} frames, {} points; median of {RUNS} runs, one thread", tracks[0].frames, tracks[0].points());
    println!("| picture | framing | median wall ms | median CPU ms | bytes |");
    println!("|---|---|---:|---:|---:|");
    let cpu = |c: Option<f64>| c.map_or("-".to_string(), |c| format!("{c:.1}"));
    for framing in [Framing::Follow, Framing::Fixed] {
        let opts = SheetOptions { framing, view: View::Auto, ..Default::default() };
        let mut size = 0;
        let (wall, c) = measure(|| size = black_box(render_sheet(&tracks, &legend, &opts).unwrap()).len());
        println!("| sheet 10x3 cells 160 px | {framing:?} | {wall:.1} | {} | {size} |", cpu(c));
        let opts = GifOptions { framing, ..Default::default() };
        let (wall, c) = measure(|| size = black_box(render_gif(&tracks, &legend, &opts).unwrap()).len());
        println!("| GIF 256 px, 1000 frames | {framing:?} | {wall:.1} | {} | {size} |", cpu(c));
    }
}
