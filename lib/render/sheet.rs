//! Contact sheets: a PNG grid of every k-th frame of one or several tracks.
//!
//! Each track gets a band of rows under a title line (title, fps, frame count, which frames).
//! Cell `i` of every band shows frame `i * every`, so when several motions are drawn (a source
//! and its retarget) the same frame numbers sit in the same column and compare frame by frame.
//! Bones are lines, joints dots, feet squares; end sites end bones without a dot. With point
//! labels, bones (coloured by their child point) and joints take the label's palette colour;
//! frame labels tint their cells; a legend then sits at the bottom.

use super::camera::{self, Camera, Framing};
use super::raster::{self, blend, Canvas, Rgb};
use super::{check, font, palette, Legend, RenderError, Track, View};

pub(super) const BACKGROUND: Rgb = [250, 250, 247];
pub(super) const INK: Rgb = [34, 34, 40];
pub(super) const MUTED: Rgb = [112, 112, 118];
pub(super) const BONE: Rgb = [72, 74, 88];
pub(super) const JOINT: Rgb = [28, 28, 34];
pub(super) const FOOT: Rgb = [214, 96, 24];
pub(super) const GROUND: Rgb = [168, 162, 150];
pub(super) const FAINT: Rgb = [214, 214, 208];
/// Opacity (of 256) of frame-label tints: light enough for the skeleton to stay readable.
pub(super) const TINT: u32 = 44;

/// Sizes of the skeleton's marks, in pixels.
#[derive(Clone, Copy, Debug)]
pub(super) struct Style {
    pub bone: f32,
    pub dot: f32,
    pub foot: f32,
}

impl Style {
    /// Marks that grow with the picture so small cells stay uncluttered.
    pub fn for_size(width: u32, height: u32) -> Style {
        let side = width.min(height) as f32;
        Style { bone: (side / 110.0).clamp(1.1, 4.0), dot: (side / 90.0).clamp(1.2, 4.5), foot: (side / 40.0).clamp(3.0, 9.0) }
    }
}

/// The cell tint for frame `f`, if it is labelled.
pub(super) fn frame_tint(track: &Track, f: usize) -> Option<Rgb> {
    track.frame_labels.as_ref().and_then(|l| l.get(f).copied().flatten()).map(palette)
}

/// Draw frame `f` of `track` with `cam`, offset by (ox, oy) pixels. `scratch` holds projected
/// points between calls (no allocation per frame).
pub(super) fn draw_pose(canvas: &mut Canvas, track: &Track, cam: &Camera, f: usize, (ox, oy): (f32, f32), style: Style, scratch: &mut Vec<(f32, f32)>) {
    scratch.clear();
    scratch.extend(track.frame(f).iter().map(|p| {
        let (x, y) = cam.project(f, *p);
        (x + ox, y + oy)
    }));
    let label = |p: usize| track.point_labels.as_ref().and_then(|l| l.get(p).copied().flatten());
    for (p, parent) in track.parents.iter().enumerate() {
        if let Some(q) = *parent {
            let colour = label(p).map_or(BONE, palette);
            canvas.line(scratch[q], scratch[p], style.bone, colour);
        }
    }
    for (p, &at) in scratch.iter().enumerate() {
        if !track.end_site[p] && !track.feet.contains(&p) {
            canvas.disc(at, style.dot, label(p).map_or(JOINT, palette));
        }
    }
    for &p in &track.feet {
        canvas.square(scratch[p], style.foot, label(p).map_or(FOOT, palette));
    }
}

/// The ground line across a cell at x0..x0+w, within y0..y0+h.
pub(super) fn draw_ground(canvas: &mut Canvas, track: &Track, cam: &Camera, f: usize, (x0, y0, w, h): (i32, i32, i32, i32), oy: f32) {
    let root = track.frame(f)[track.parents.iter().position(Option::is_none).unwrap_or(0)];
    if let Some(g) = cam.ground_line(f, root) {
        let gy = (g + oy).round() as i32;
        if gy >= y0 && gy < y0 + h {
            canvas.fill_rect(x0, gy, w, 1, GROUND, 256);
        }
    }
}

/// "30", "29.97".
pub(super) fn fps_text(fps: f64) -> String {
    if (fps - fps.round()).abs() < 0.005 {
        format!("{:.0}", fps)
    } else {
        format!("{:.2}", fps)
    }
}

/// Height in pixels of the legend at `width`, and where each entry goes (x, y relative).
pub(super) fn legend_layout(legend: &Legend, width: u32, pad: u32) -> (u32, Vec<(i32, i32)>) {
    if legend.labels.is_empty() {
        return (0, Vec::new());
    }
    let row = font::LINE_HEIGHT + 4;
    let (mut x, mut y) = (pad, pad / 2);
    let mut spots = Vec::with_capacity(legend.labels.len());
    for label in &legend.labels {
        let w = 14 + font::text_width(&font::fit(label, width.saturating_sub(2 * pad + 14), 1), 1) + 14;
        if x > pad && x + w > width.saturating_sub(pad) {
            x = pad;
            y += row;
        }
        spots.push((x as i32, y as i32));
        x += w;
    }
    (y + row + pad / 2, spots)
}

/// Draw the legend with its top edge at `top`.
pub(super) fn draw_legend(canvas: &mut Canvas, legend: &Legend, top: i32, pad: u32) {
    let (_, spots) = legend_layout(legend, canvas.width, pad);
    let max_w = canvas.width.saturating_sub(2 * pad + 14);
    for (i, (label, (x, y))) in legend.labels.iter().zip(spots).enumerate() {
        canvas.fill_rect(x, top + y, 10, 10, palette(i), 256);
        canvas.text(x + 14, top + y + 1, &font::fit(label, max_w, 1), INK, 1);
    }
}

/// What to draw on a contact sheet.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetOptions {
    pub view: View,
    pub framing: Framing,
    /// Draw every k-th frame; 0 chooses k so the longest track fits `columns * max_rows` cells.
    pub every: usize,
    /// Cells per row.
    pub columns: usize,
    /// Rows per track at most (longer tracks are cut, and their title says so).
    pub max_rows: usize,
    pub cell_width: u32,
    pub cell_height: u32,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions { view: View::Auto, framing: Framing::Follow, every: 0, columns: 10, max_rows: 3, cell_width: 160, cell_height: 160 }
    }
}

const PAD: u32 = 8;
const TITLE_HEIGHT: u32 = 18;
/// Room at the top of a cell for its frame number.
const NUMBER_HEIGHT: u32 = 12;

/// Draw `tracks` as a contact sheet; returns PNG bytes.
pub fn render_sheet(tracks: &[Track], legend: &Legend, opts: &SheetOptions) -> Result<Vec<u8>, RenderError> {
    check(tracks, legend)?;
    camera::check_view(opts.view)?;
    if opts.columns == 0 || opts.max_rows == 0 {
        return Err(RenderError::Invalid(format!("a sheet needs at least one column and one row (got {} columns, {} rows)", opts.columns, opts.max_rows)));
    }
    for (what, v) in [("cell width", opts.cell_width), ("cell height", opts.cell_height)] {
        if !(48..=4096).contains(&v) {
            return Err(RenderError::Invalid(format!("{what} {v} px: expected 48 to 4096")));
        }
    }
    let capacity = opts.columns.saturating_mul(opts.max_rows);
    let longest = tracks.iter().map(|t| t.frames).max().unwrap_or(1);
    let every = if opts.every == 0 { longest.div_ceil(capacity).max(1) } else { opts.every };
    let cells: Vec<usize> = tracks.iter().map(|t| t.frames.div_ceil(every).min(capacity)).collect();
    let columns = opts.columns.min(cells.iter().copied().max().unwrap_or(1)).max(1);
    let rows: Vec<usize> = cells.iter().map(|c| c.div_ceil(columns)).collect();
    let (cw, ch) = (opts.cell_width as u64, opts.cell_height as u64);
    let width = 2 * PAD as u64 + columns as u64 * cw;
    let bands: u64 = rows.iter().map(|&r| TITLE_HEIGHT as u64 + r as u64 * ch + PAD as u64).sum();
    let legend_height = if width <= raster::MAX_SIDE { legend_layout(legend, width as u32, PAD).0 as u64 } else { 0 };
    let height = PAD as u64 + bands + legend_height;
    raster::check_size(width, height, "the contact sheet")?;
    let mut canvas = Canvas::new(width as u32, height as u32, BACKGROUND);
    let style = Style::for_size(opts.cell_width, opts.cell_height - NUMBER_HEIGHT);
    let margin = (opts.cell_width.min(opts.cell_height) / 14).max(6);
    let mut scratch = Vec::new();
    let mut top = PAD as i32;
    for ((track, &n_cells), &n_rows) in tracks.iter().zip(&cells).zip(&rows) {
        let shown = if n_cells * every < track.frames { format!(", frames 0-{} shown", (n_cells - 1) * every) } else { String::new() };
        let each = if every == 1 { "every frame".to_string() } else { format!("every {every} frames") };
        let title = format!("{}   {} fps, {} frames, {each}{shown}", track.title, fps_text(track.fps), track.frames);
        canvas.text(PAD as i32, top + 4, &font::fit(&title, width as u32 - 2 * PAD, 1), INK, 1);
        top += TITLE_HEIGHT as i32;
        let cam = Camera::fit(track, opts.view, opts.framing, opts.cell_width, opts.cell_height - NUMBER_HEIGHT, margin);
        for i in 0..n_cells {
            let f = i * every;
            let x0 = PAD as i32 + (i % columns) as i32 * cw as i32;
            let y0 = top + (i / columns) as i32 * ch as i32;
            if let Some(tint) = frame_tint(track, f) {
                canvas.fill_rect(x0, y0, cw as i32, ch as i32, tint, TINT);
            }
            canvas.outline_rect(x0, y0, cw as i32, ch as i32, FAINT);
            let oy = (y0 + NUMBER_HEIGHT as i32) as f32;
            draw_ground(&mut canvas, track, &cam, f, (x0 + 1, y0 + 1, cw as i32 - 2, ch as i32 - 2), oy);
            draw_pose(&mut canvas, track, &cam, f, (x0 as f32, oy), style, &mut scratch);
            canvas.text(x0 + 4, y0 + 3, &f.to_string(), MUTED, 1);
        }
        top += (n_rows as u32 * opts.cell_height + PAD) as i32;
    }
    draw_legend(&mut canvas, legend, top, PAD);
    canvas.to_png()
}

/// A light tint of `c` for backgrounds.
pub(super) fn tinted(c: Rgb) -> Rgb {
    blend(BACKGROUND, c, TINT as f32 / 256.0)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::synth;

    pub fn creature_track(name: &str, frames: usize) -> Track {
        let (skeleton, motion) = synth::creature(name, 1).unwrap();
        Track::from_motion(&format!("{name}.bvh"), &skeleton, &motion.first_frames(frames))
    }

    fn decode(png_bytes: &[u8]) -> (u32, u32, Vec<u8>) {
        let decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    #[test]
    fn sheet_decodes_to_the_expected_size_and_is_deterministic() {
        let a = creature_track("biped", 40);
        let b = creature_track("quadruped", 25);
        let opts = SheetOptions { every: 5, columns: 6, max_rows: 2, cell_width: 80, cell_height: 90, ..Default::default() };
        let bytes = render_sheet(&[a.clone(), b.clone()], &Legend::default(), &opts).unwrap();
        let (w, h, pixels) = decode(&bytes);
        // biped: 8 cells -> 6 columns x 2 rows; quadruped: 5 cells -> 1 row.
        assert_eq!(w, 2 * PAD + 6 * 80);
        assert_eq!(h, PAD + (TITLE_HEIGHT + 2 * 90 + PAD) + (TITLE_HEIGHT + 90 + PAD));
        assert!(pixels.chunks(3).any(|p| p == JOINT.as_slice()), "joints are drawn");
        assert!(pixels.chunks(3).any(|p| p == FOOT.as_slice()), "feet are drawn");
        assert_eq!(bytes, render_sheet(&[a, b], &Legend::default(), &opts).unwrap());
    }

    #[test]
    fn labels_colour_cells_and_add_a_legend() {
        let mut t = creature_track("spider", 20);
        t.frame_labels = Some((0..20).map(|f| Some(f / 10)).collect());
        t.point_labels = Some(vec![Some(1); t.points()]);
        let legend = Legend { labels: vec!["walk".into(), "turn".into()] };
        let opts = SheetOptions { every: 10, ..Default::default() };
        let (w, h, pixels) = decode(&render_sheet(&[t.clone()], &legend, &opts).unwrap());
        assert_eq!(w, 2 * PAD + 2 * 160);
        assert!(h > PAD + TITLE_HEIGHT + 160 + PAD, "legend adds height");
        let at = |x: u32, y: u32| &pixels[((y * w + x) * 3) as usize..((y * w + x) * 3 + 3) as usize];
        assert_eq!(at(PAD + 40, PAD + TITLE_HEIGHT + 3), tinted(palette(0)).as_slice(), "first cell tinted by label 0");
        assert_eq!(at(PAD + 160 + 40, PAD + TITLE_HEIGHT + 3), tinted(palette(1)).as_slice());
        assert!(pixels.chunks(3).any(|p| p == palette(1).as_slice()), "bones in the label colour");
    }

    #[test]
    fn bad_options_and_huge_sheets_are_refused() {
        let t = creature_track("snake", 30);
        let legend = Legend::default();
        let e = render_sheet(std::slice::from_ref(&t), &legend, &SheetOptions { columns: 0, ..Default::default() }).unwrap_err();
        assert!(matches!(e, RenderError::Invalid(_)));
        let e = render_sheet(std::slice::from_ref(&t), &legend, &SheetOptions { columns: 200, max_rows: 1, every: 1, cell_width: 100, ..Default::default() });
        assert!(e.is_ok(), "30 cells fit");
        let mut long = t.clone();
        long.frames = 3000;
        long.positions = t.positions.iter().cycle().take(3000 * t.points()).copied().collect();
        let e = render_sheet(&[long], &legend, &SheetOptions { columns: 200, max_rows: 100, every: 1, ..Default::default() }).unwrap_err();
        assert!(matches!(e, RenderError::TooLarge(_)), "{e}");
        let e = render_sheet(&[t], &legend, &SheetOptions { view: View::Angle { yaw: f32::INFINITY, pitch: 0.0 }, ..Default::default() });
        assert!(matches!(e, Err(RenderError::Invalid(_))));
    }
}
