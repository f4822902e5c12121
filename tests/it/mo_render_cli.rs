//! `mo-render` end to end: every synthetic creature draws to a PNG sheet and a GIF of the
//! expected geometry, several motions stack, NPY + skeleton and GLB draw like the BVH they came
//! from, output is deterministic, and bad input exits 2 without leaving a file.
use crate::common;

use common::{check_failure, example_bvh_files, ok, run, s, tempdir};
use std::path::Path;

fn png_size(bytes: &[u8]) -> (u32, u32) {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let reader = decoder.read_info().expect("a PNG");
    let info = reader.info();
    (info.width, info.height)
}

/// RGB(A) pixels of a PNG, with its width.
fn png_pixels(bytes: &[u8]) -> (Vec<u8>, usize, usize) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size().expect("a PNG of known size")];
    let info = reader.next_frame(&mut buf).expect("PNG pixels");
    buf.truncate(info.buffer_size());
    (buf, info.width as usize, info.color_type.samples())
}

#[test]
fn a_glb_draws_like_the_bvh_it_came_from() {
    let dir = tempdir("render-glb");
    let bvh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/quadruped.bvh");
    let glb = dir.join("quadruped.glb");
    ok(&run("mo-edit", &["convert", s(&bvh), "-o", s(&glb)], None), "mo-edit convert -o GLB");
    let sheet = |input: &Path, name: &str| {
        let out = dir.join(name);
        ok(&run("mo-render", &[s(input), "--sheet", s(&out), "--frames", "0:8"], None), "mo-render");
        png_pixels(&std::fs::read(&out).unwrap())
    };
    let (a, width, samples) = sheet(&bvh, "from_bvh.png");
    let (b, width_b, _) = sheet(&glb, "from_glb.png");
    assert_eq!((a.len(), width), (b.len(), width_b), "the same sheet size");
    // The title line names the file (.bvh or .glb); below it the pictures match, but for a few
    // anti-aliased edge pixels that the GLB's float32 values move (5 of 220,000 when written).
    let title = 24 * width * samples;
    let pixels = (a.len() - title) / samples;
    let differ = a[title..].chunks(samples).zip(b[title..].chunks(samples)).filter(|(x, y)| x != y).count();
    assert!(differ <= pixels / 10_000, "{differ} of {pixels} pixels differ below the title");
    let background = &a[title..title + samples];
    assert!(a[title..].chunks(samples).filter(|p| *p != background).count() > 1000, "the sheet draws the creature");
    let _ = std::fs::remove_dir_all(&dir);
}

fn gif_frames(bytes: &[u8]) -> (u16, u16, usize) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut d = options.read_info(bytes).expect("a GIF");
    let (w, h) = (d.width(), d.height());
    let mut n = 0;
    while d.read_next_frame().expect("GIF frame").is_some() {
        n += 1;
    }
    (w, h, n)
}

#[test]
fn every_creature_draws_a_sheet_and_a_gif() {
    let dir = tempdir("creatures");
    let files = example_bvh_files();
    assert!(files.len() >= 8, "examples/data holds the synthetic zoo");
    for f in &files {
        let stem = f.file_stem().unwrap().to_string_lossy();
        let sheet = dir.join(format!("{stem}.png"));
        let anim = dir.join(format!("{stem}.gif"));
        let out = run("mo-render", &[s(f), "--sheet", s(&sheet), "--gif", s(&anim), "--frames", "0:40", "--size", "96x96"], None);
        ok(&out, &format!("mo-render {stem}"));
        let (w, h) = png_size(&std::fs::read(&sheet).unwrap());
        // 10 columns of 96 px cells; the height holds a title band and at least one row.
        assert!(w >= 960 && h >= 96, "{stem}: sheet {w}x{h}");
        let (gw, gh, n) = gif_frames(&std::fs::read(&anim).unwrap());
        assert!(gw >= 96 && gh >= 96, "{stem}: gif {gw}x{gh}");
        // 40 frames, fewer when the frame rate needs skipping (GIF delays are 1/100 s).
        assert!((10..=40).contains(&n), "{stem}: {n} GIF frames for 40 motion frames");
    }
}

#[test]
fn two_motions_stack_and_output_is_deterministic() {
    let dir = tempdir("stack");
    let a = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/biped.bvh");
    let b = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/quadruped.bvh");
    let one = dir.join("one.png");
    let two = dir.join("two.png");
    let again = dir.join("again.png");
    ok(&run("mo-render", &[s(&a), "-o", s(&one), "--frames", "0:30"], None), "one");
    ok(&run("mo-render", &[s(&a), s(&b), "-o", s(&two), "--frames", "0:30"], None), "two");
    ok(&run("mo-render", &[s(&a), s(&b), "-o", s(&again), "--frames", "0:30", "--threads", "1"], None), "again");
    let (w1, h1) = png_size(&std::fs::read(&one).unwrap());
    let (w2, h2) = png_size(&std::fs::read(&two).unwrap());
    assert_eq!(w1, w2, "same columns");
    assert!(h2 > h1, "a second motion adds a band: {h1} -> {h2}");
    assert_eq!(std::fs::read(&two).unwrap(), std::fs::read(&again).unwrap(), "same input, same bytes");
}

#[test]
fn npy_with_skeleton_draws_like_the_bvh() {
    let dir = tempdir("npy");
    let bvh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/crab.bvh");
    let npy = dir.join("crab.npy");
    ok(&run("mo-encode", &[s(&bvh), "-o", s(&npy)], None), "encode");
    let html = dir.join("crab.html");
    ok(&run("mo-render", &[s(&npy), "--skeleton", s(&bvh), "--html", s(&html)], None), "render npy");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("<canvas") && !page.contains("http://") && !page.contains("https://"), "self-contained page");
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = tempdir("bad");
    let crab = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/crab.bvh");
    let bird = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/bird.bvh");
    let npy = dir.join("crab.npy");
    ok(&run("mo-encode", &[s(&crab), "-o", s(&npy)], None), "encode");
    let out_png = dir.join("out.png");
    let out_gif = dir.join("out.gif");

    // Features of one skeleton decoded on another.
    let out = run("mo-render", &[s(&npy), "--skeleton", s(&bird), "--sheet", s(&out_png), "--gif", s(&out_gif)], None);
    check_failure("mo-render", "mismatched skeleton", &out, "joints");

    // A motion without frames.
    let text = std::fs::read_to_string(&crab).unwrap();
    let motion_at = text.find("MOTION").unwrap();
    let empty = dir.join("empty.bvh");
    std::fs::write(&empty, format!("{}MOTION\nFrames: 0\nFrame Time: 0.033333\n", &text[..motion_at])).unwrap();
    let out = run("mo-render", &[s(&empty), "--sheet", s(&out_png)], None);
    check_failure("mo-render", "empty motion", &out, "no frames");

    // A frame range past the end; a second good input must not get drawn to a partial file.
    let out = run("mo-render", &[s(&crab), "--frames", "100000:", "--sheet", s(&out_png), "--gif", s(&out_gif)], None);
    check_failure("mo-render", "range past the end", &out, "--frames starts at frame 100000");

    // Unknown output kind, missing output.
    let out = run("mo-render", &[s(&crab), "-o", s(&dir.join("out.jpg"))], None);
    check_failure("mo-render", "unknown extension", &out, "cannot tell the picture kind");
    let out = run("mo-render", &[s(&crab)], None);
    check_failure("mo-render", "no output", &out, "say what to draw");

    // A label file naming a joint the skeleton lacks.
    let labels = dir.join("labels.json");
    std::fs::write(&labels, r#"{"NoSuchJoint": "x"}"#).unwrap();
    let out = run("mo-render", &[s(&crab), "--joint-labels", s(&labels), "--sheet", s(&out_png)], None);
    check_failure("mo-render", "unknown joint label", &out, "NoSuchJoint");

    for p in [&out_png, &out_gif] {
        assert!(!p.exists(), "{} was written by a failing run", p.display());
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).filter(|e| e.file_name().to_string_lossy().contains(".tmp")).collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn labels_colour_the_sheet() {
    let dir = tempdir("labels");
    let biped = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/biped.bvh");
    let plain = dir.join("plain.png");
    let coloured = dir.join("coloured.png");
    let labels = dir.join("segments.json");
    std::fs::write(&labels, r#"{"segments": [{"start": 0, "end": 10, "label": "walk"}, {"start": 10, "end": 20, "label": "turn"}]}"#).unwrap();
    ok(&run("mo-render", &[s(&biped), "--frames", "0:20", "--sheet", s(&plain)], None), "plain");
    ok(&run("mo-render", &[s(&biped), "--frames", "0:20", "--frame-labels", s(&labels), "--sheet", s(&coloured)], None), "labelled");
    let (a, b) = (std::fs::read(&plain).unwrap(), std::fs::read(&coloured).unwrap());
    assert_ne!(a, b, "frame labels change the picture");
    let (_, h_plain) = png_size(&a);
    let (_, h_col) = png_size(&b);
    assert!(h_col >= h_plain, "the legend never shrinks the sheet");
}
