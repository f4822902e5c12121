//! Animated GIFs: tracks side by side as panels, played at the motion's frame rate, looping.
//!
//! Timing: GIF delays are whole centiseconds and browsers slow down delays under 2 cs, so
//! motions above 50 fps are played with every `step`-th frame ([`frame_step`]): 60 fps plays
//! every 2nd frame, 120 fps every 3rd. Delays are rounded from the exact time of each shown
//! frame, so they alternate (3, 3, 4 cs for 30 shown frames per second) and the average rate is
//! exact. When tracks have different frame rates the fastest one sets the clock and each track
//! shows its frame at that time; shorter tracks hold their last frame.
//!
//! Colours come from one fixed palette (the label colours, greys, the skeleton's inks and
//! their anti-aliasing blends over the background and over the frame-label tints), so encoding
//! needs no colour search per picture and the same input always gives the same bytes. Each
//! frame after the first stores only the rectangle that changed, with unchanged pixels
//! transparent, which keeps files small and encoding fast.

use super::camera::{self, Camera, Framing};
use super::raster::{self, blend, Canvas, Rgb};
use super::sheet::{self, draw_ground, draw_pose, fps_text, frame_tint, Style, BACKGROUND, BONE, FAINT, FOOT, GROUND, INK, JOINT, MUTED, TINT};
use super::{check, font, palette, Legend, RenderError, Track, View};
use std::borrow::Cow;

/// What to draw in an animation.
#[derive(Clone, Debug, PartialEq)]
pub struct GifOptions {
    pub view: View,
    pub framing: Framing,
    /// Size of each track's panel.
    pub panel_width: u32,
    pub panel_height: u32,
}

impl Default for GifOptions {
    fn default() -> Self {
        GifOptions { view: View::Auto, framing: Framing::Follow, panel_width: 256, panel_height: 256 }
    }
}

/// For a motion at `fps`: show every `step`-th frame, each for about `delay` centiseconds.
/// Up to 50 fps every frame is shown; above, the smallest step that keeps delays at 2 cs or
/// more. (The exact delays alternate around `delay` so the average rate is exact; see the
/// module documentation.) A rate that is not a positive number is taken as 30 fps.
pub fn frame_step(fps: f64) -> (usize, u16) {
    let fps = if fps.is_finite() && fps > 0.0 { fps } else { 30.0 };
    let step = ((fps / 50.0 - 1e-9).ceil() as usize).max(1);
    let delay = (100.0 * step as f64 / fps).round().clamp(2.0, u16::MAX as f64) as u16;
    (step, delay)
}

/// Transparent index: "this pixel did not change".
const TRANSPARENT: u8 = 255;

/// The fixed palette (at most 255 colours; index 255 is transparent).
fn gif_palette() -> Vec<Rgb> {
    let mut colours: Vec<Rgb> = vec![BACKGROUND];
    let add = |c: Rgb, colours: &mut Vec<Rgb>| {
        if !colours.contains(&c) {
            colours.push(c);
        }
    };
    let mut inks = vec![INK, MUTED, BONE, JOINT, FOOT, GROUND, FAINT];
    inks.extend((0..10).map(palette));
    for &ink in &inks {
        for k in 1..=6 {
            add(blend(BACKGROUND, ink, k as f32 / 6.0), &mut colours);
        }
    }
    for i in 0..10 {
        let tint = sheet::tinted(palette(i));
        add(tint, &mut colours);
        for ink in [BONE, JOINT, INK, GROUND, FOOT, FAINT] {
            add(blend(tint, ink, 0.5), &mut colours);
        }
    }
    for g in 0..16u8 {
        add([g * 17, g * 17, g * 17], &mut colours);
    }
    colours.truncate(255);
    colours
}

/// Colour -> palette index through a table of 6 bits per channel, filled on first use of each
/// cell (a picture touches a few thousand cells; anti-aliased edges make many distinct colours,
/// so searching the palette per exact colour was the slowest part of encoding). Palette
/// colours are entered first so they map to themselves.
struct Quantiser {
    palette: Vec<Rgb>,
    table: Vec<u8>,
}

const UNSET: u8 = TRANSPARENT;

#[inline]
fn cell(c: &[u8]) -> usize {
    ((c[0] as usize >> 2) << 12) | ((c[1] as usize >> 2) << 6) | (c[2] as usize >> 2)
}

impl Quantiser {
    fn new(palette: Vec<Rgb>) -> Quantiser {
        let mut table = vec![UNSET; 1 << 18];
        for (i, c) in palette.iter().enumerate().rev() {
            table[cell(c)] = i as u8;
        }
        Quantiser { palette, table }
    }

    #[inline]
    fn index(&mut self, c: &[u8]) -> u8 {
        let k = cell(c);
        let v = self.table[k];
        if v != UNSET {
            return v;
        }
        // Nearest palette colour to the cell's centre.
        let centre = [c[0] | 2, c[1] | 2, c[2] | 2];
        let mut best = (u32::MAX, 0u8);
        for (i, p) in self.palette.iter().enumerate() {
            let d = |a: u8, b: u8| (a as i32 - b as i32).pow(2) as u32;
            // Green weighs most, blue least, roughly as the eye does.
            let dist = 3 * d(centre[0], p[0]) + 4 * d(centre[1], p[1]) + 2 * d(centre[2], p[2]);
            if dist < best.0 {
                best = (dist, i as u8);
            }
        }
        self.table[k] = best.1;
        best.1
    }
}

/// GIF's LZW compression (variable-width codes, least significant bit first), written here
/// because the frames are mostly long runs of the transparent index, which we can skip over
/// (see `runs` below), and a small open-addressing table that stays in cache. Returns the
/// minimum code size byte followed by the codes, as [`gif::Encoder::write_lzw_pre_encoded_frame`]
/// expects. The table is reused between frames.
struct Lzw {
    /// (prefix code << 8 | byte) of each slot, `EMPTY` when free.
    keys: Vec<u32>,
    /// The code of the string in the same slot.
    codes: Vec<u16>,
}

const EMPTY: u32 = u32::MAX;
/// Slots: twice the 4096 codes, so probes stay short.
const SLOT_BITS: u32 = 13;

const MIN_CODE_SIZE: u8 = 8;

impl Lzw {
    fn new() -> Lzw {
        Lzw { keys: vec![EMPTY; 1 << SLOT_BITS], codes: vec![0; 1 << SLOT_BITS] }
    }

    fn reset(&mut self) {
        self.keys.fill(EMPTY);
    }

    /// The slot holding `key`, or the free slot where it would go.
    #[inline]
    fn slot(&self, key: u32) -> usize {
        let mask = (1usize << SLOT_BITS) - 1;
        let mut s = (key.wrapping_mul(0x9E37_79B1) >> (32 - SLOT_BITS)) as usize;
        loop {
            let k = self.keys[s];
            if k == key || k == EMPTY {
                return s;
            }
            s = (s + 1) & mask;
        }
    }

    fn encode(&mut self, data: &[u8]) -> Vec<u8> {
        let clear = 1u32 << MIN_CODE_SIZE;
        let end = clear + 1;
        let mut out = Vec::with_capacity(data.len() / 4 + 16);
        out.push(MIN_CODE_SIZE);
        let (mut acc, mut bits) = (0u64, 0u32);
        let mut emit = |code: u32, width: u32, out: &mut Vec<u8>| {
            acc |= (code as u64) << bits;
            bits += width;
            while bits >= 8 {
                out.push(acc as u8);
                acc >>= 8;
                bits -= 8;
            }
        };
        let mut width = MIN_CODE_SIZE as u32 + 1;
        let mut next = end + 1;
        emit(clear, width, &mut out);
        if let Some(&first) = data.first() {
            // Strings of nothing but the transparent index: `runs[k]` is the code of k + 1 of
            // them. Frames are mostly such runs, and the longest known run can be found
            // without walking the table byte by byte (same codes as the byte-wise walk).
            let mut runs: Vec<u16> = vec![TRANSPARENT as u16];
            let mut prefix = first as u32;
            let mut prefix_run = usize::from(first == TRANSPARENT);
            let mut i = 1;
            while i < data.len() {
                let b = data[i];
                if prefix_run > 0 && b == TRANSPARENT && prefix_run < runs.len() {
                    let ahead = data[i..].iter().take(runs.len() - prefix_run).take_while(|&&x| x == TRANSPARENT).count();
                    prefix_run += ahead;
                    prefix = runs[prefix_run - 1] as u32;
                    i += ahead;
                    continue;
                }
                let key = prefix << 8 | b as u32;
                let slot = self.slot(key);
                if self.keys[slot] == key {
                    prefix = self.codes[slot] as u32;
                    prefix_run = 0;
                    i += 1;
                    continue;
                }
                emit(prefix, width, &mut out);
                if next < 4096 {
                    self.keys[slot] = key;
                    self.codes[slot] = next as u16;
                    if prefix_run > 0 && b == TRANSPARENT {
                        runs.push(next as u16);
                    }
                    next += 1;
                    // The decoder adds this entry one code later, so it widens when `next`
                    // passes the width's range, not when it reaches it.
                    if next > (1 << width) && width < 12 {
                        width += 1;
                    }
                } else {
                    emit(clear, width, &mut out);
                    self.reset();
                    runs.truncate(1);
                    width = MIN_CODE_SIZE as u32 + 1;
                    next = end + 1;
                }
                prefix = b as u32;
                prefix_run = usize::from(b == TRANSPARENT);
                i += 1;
            }
            emit(prefix, width, &mut out);
        }
        emit(end, width, &mut out);
        if bits > 0 {
            out.push(acc as u8);
        }
        self.reset();
        out
    }
}

const PAD: u32 = 4;
/// Two lines of text above each panel's picture: title, then fps and frame counter.
const HEADER: u32 = 2 * font::LINE_HEIGHT + 4;

/// Draw `tracks` side by side as a looping animated GIF; returns the GIF bytes.
pub fn render_gif(tracks: &[Track], legend: &Legend, opts: &GifOptions) -> Result<Vec<u8>, RenderError> {
    check(tracks, legend)?;
    camera::check_view(opts.view)?;
    for (what, v) in [("panel width", opts.panel_width), ("panel height", opts.panel_height)] {
        if !(64..=4096).contains(&v) {
            return Err(RenderError::Invalid(format!("{what} {v} px: expected 64 to 4096")));
        }
    }
    let (pw, ph) = (opts.panel_width, opts.panel_height);
    let width = tracks.len() as u64 * pw as u64;
    let legend_height = if width <= raster::MAX_SIDE { sheet::legend_layout(legend, width as u32, PAD * 2).0 as u64 } else { 0 };
    let height = ph as u64 + legend_height;
    raster::check_size(width, height, "the animation")?;
    let (width, height) = (width as u32, height as u32);

    // Timeline: the fastest track sets the clock.
    let clock = tracks.iter().map(|t| t.fps).fold(0.0f64, f64::max);
    let (step, _) = frame_step(clock);
    let dt = step as f64 / clock;
    let shown = tracks.iter().map(|t| ((t.frames as f64 / t.fps / dt) - 1e-9).ceil().max(1.0) as usize).max().unwrap_or(1);
    let work = shown as u64 * width as u64 * height as u64;
    if work > 20_000_000_000 {
        return Err(RenderError::TooLarge(format!(
            "the animation would be {shown} frames of {width} x {height} pixels; the limit is 20 Gpx in all (cut the motion or use smaller panels)"
        )));
    }

    // What does not move: background, titles, separators, legend.
    let mut base = Canvas::new(width, height, BACKGROUND);
    let style = Style::for_size(pw, ph - HEADER);
    let margin = (pw.min(ph) / 16).max(6);
    let mut cameras = Vec::with_capacity(tracks.len());
    let mut counter_x = Vec::with_capacity(tracks.len());
    for (k, track) in tracks.iter().enumerate() {
        let x0 = (k as u32 * pw) as i32;
        base.text(x0 + PAD as i32, PAD as i32, &font::fit(&track.title, pw - 2 * PAD, 1), INK, 1);
        let end = base.text(x0 + PAD as i32, (PAD + font::LINE_HEIGHT) as i32, &format!("{} fps  ", fps_text(track.fps)), MUTED, 1);
        counter_x.push(end);
        if k > 0 {
            base.fill_rect(x0, 0, 1, ph as i32, FAINT, 256);
        }
        cameras.push(Camera::fit(track, opts.view, opts.framing, pw, ph - HEADER, margin));
    }
    if legend_height > 0 {
        base.fill_rect(0, ph as i32, width as i32, 1, FAINT, 256);
        sheet::draw_legend(&mut base, legend, ph as i32, PAD * 2);
    }

    let mut quantiser = Quantiser::new(gif_palette());
    let mut flat: Vec<u8> = quantiser.palette.iter().flatten().copied().collect();
    flat.resize(256 * 3, 0);
    let fail = |e: gif::EncodingError| RenderError::Invalid(format!("GIF encoding failed: {e}"));
    let mut encoder = gif::Encoder::new(Vec::new(), width as u16, height as u16, &flat).map_err(fail)?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(fail)?;

    let mut cur = base.clone();
    let mut prev = base.clone();
    let mut scratch = Vec::new();
    let mut pending: Option<gif::Frame<'static>> = None;
    let mut lzw = Lzw::new();
    let centis = |i: usize| (i as f64 * dt * 100.0).round() as u64;
    for i in 0..shown {
        cur.pixels.copy_from_slice(&base.pixels);
        let t = i as f64 * dt;
        for (k, (track, cam)) in tracks.iter().zip(&cameras).enumerate() {
            let f = ((t * track.fps + 1e-6).floor() as usize).min(track.frames - 1);
            let x0 = (k as u32 * pw) as i32;
            if let Some(tint) = frame_tint(track, f) {
                cur.fill_rect(x0 + 1, 0, pw as i32 - 1, ph as i32, tint, TINT);
            }
            let oy = HEADER as f32;
            draw_ground(&mut cur, track, cam, f, (x0 + 1, HEADER as i32, pw as i32 - 1, (ph - HEADER) as i32), oy);
            draw_pose(&mut cur, track, cam, f, (x0 as f32, oy), style, &mut scratch);
            cur.text(counter_x[k], (PAD + font::LINE_HEIGHT) as i32, &format!("frame {f}/{}", track.frames - 1), MUTED, 1);
        }
        let delay = (centis(i + 1) - centis(i)).clamp(2, u16::MAX as u64) as u16;
        let frame = if i == 0 {
            let buffer: Vec<u8> = cur.pixels.chunks_exact(3).map(|c| quantiser.index(c)).collect();
            Some(gif::Frame { width: width as u16, height: height as u16, buffer: Cow::Owned(buffer), delay, ..gif::Frame::default() })
        } else {
            changed_frame(&cur, &prev, &mut quantiser, delay)
        };
        match frame {
            Some(frame) => {
                if let Some(mut done) = pending.replace(frame) {
                    done.buffer = Cow::Owned(lzw.encode(&done.buffer));
                    encoder.write_lzw_pre_encoded_frame(&done).map_err(fail)?;
                }
            }
            // Nothing moved: show the previous frame longer.
            None => {
                if let Some(p) = pending.as_mut() {
                    p.delay = p.delay.saturating_add(delay);
                }
            }
        }
        std::mem::swap(&mut cur, &mut prev);
    }
    if let Some(mut done) = pending {
        done.buffer = Cow::Owned(lzw.encode(&done.buffer));
        encoder.write_lzw_pre_encoded_frame(&done).map_err(fail)?;
    }
    encoder.into_inner().map_err(fail)
}

/// Index of the first byte where `a` and `b` differ (they do somewhere), 8 bytes at a time.
fn first_difference(a: &[u8], b: &[u8]) -> usize {
    let words = a.len() / 8;
    let word = |s: &[u8], i: usize| u64::from_ne_bytes(s[i * 8..i * 8 + 8].try_into().unwrap_or([0; 8]));
    let start = (0..words).find(|&i| word(a, i) != word(b, i)).map_or(words * 8, |i| i * 8);
    a[start..].iter().zip(&b[start..]).position(|(p, q)| p != q).map_or(0, |d| start + d)
}

/// Index of the last byte where `a` and `b` differ (they do somewhere).
fn last_difference(a: &[u8], b: &[u8]) -> usize {
    let n = a.len();
    let words = n / 8;
    let word = |s: &[u8], i: usize| u64::from_ne_bytes(s[n - i * 8 - 8..n - i * 8].try_into().unwrap_or([0; 8]));
    let end = (0..words).find(|&i| word(a, i) != word(b, i)).map_or(n - words * 8, |i| n - i * 8);
    a[..end].iter().zip(&b[..end]).rposition(|(p, q)| p != q).unwrap_or(0)
}

/// The rectangle where `cur` differs from `prev`, as palette indices with unchanged pixels
/// transparent; `None` when nothing changed.
fn changed_frame(cur: &Canvas, prev: &Canvas, quantiser: &mut Quantiser, delay: u16) -> Option<gif::Frame<'static>> {
    let stride = cur.width as usize * 3;
    let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0usize, usize::MAX, 0usize);
    for (y, (a, b)) in cur.pixels.chunks_exact(stride).zip(prev.pixels.chunks_exact(stride)).enumerate() {
        if a == b {
            continue;
        }
        let first = first_difference(a, b) / 3;
        let last = last_difference(a, b) / 3;
        x0 = x0.min(first);
        x1 = x1.max(last + 1);
        y0 = y0.min(y);
        y1 = y + 1;
    }
    if y0 == usize::MAX {
        return None;
    }
    let mut buffer = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        let a = &cur.pixels[y * stride + x0 * 3..y * stride + x1 * 3];
        let b = &prev.pixels[y * stride + x0 * 3..y * stride + x1 * 3];
        let mut k = 0;
        while k + 3 <= a.len() {
            // Skip unchanged stretches 8 bytes at a time; most of the rectangle did not move.
            if k + 24 <= a.len() && a[k..k + 24] == b[k..k + 24] {
                buffer.extend_from_slice(&[TRANSPARENT; 8]);
                k += 24;
                continue;
            }
            let same = a[k] == b[k] && a[k + 1] == b[k + 1] && a[k + 2] == b[k + 2];
            buffer.push(if same { TRANSPARENT } else { quantiser.index(&a[k..k + 3]) });
            k += 3;
        }
    }
    Some(gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0) as u16,
        height: (y1 - y0) as u16,
        buffer: Cow::Owned(buffer),
        transparent: Some(TRANSPARENT),
        dispose: gif::DisposalMethod::Keep,
        delay,
        ..gif::Frame::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sheet::tests::creature_track;

    /// (width, height, frames, total delay in cs, composited last frame as palette indices).
    fn decode(bytes: &[u8]) -> (u16, u16, usize, u32, Vec<u8>) {
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::Indexed);
        let mut d = options.read_info(std::io::Cursor::new(bytes)).unwrap();
        let (w, h) = (d.width(), d.height());
        let mut screen = vec![0u8; w as usize * h as usize];
        let (mut n, mut total) = (0, 0u32);
        while let Some(f) = d.read_next_frame().unwrap() {
            n += 1;
            total += f.delay as u32;
            for y in 0..f.height as usize {
                for x in 0..f.width as usize {
                    let v = f.buffer[y * f.width as usize + x];
                    if Some(v) != f.transparent {
                        screen[(f.top as usize + y) * w as usize + f.left as usize + x] = v;
                    }
                }
            }
        }
        (w, h, n, total, screen)
    }

    #[test]
    fn frame_steps_keep_delays_playable() {
        assert_eq!(frame_step(30.0), (1, 3));
        assert_eq!(frame_step(50.0), (1, 2));
        assert_eq!(frame_step(60.0), (2, 3));
        assert_eq!(frame_step(120.0), (3, 3));
        assert_eq!(frame_step(f64::NAN), (1, 3));
        assert_eq!(frame_step(10.0), (1, 10));
    }

    #[test]
    fn gif_has_the_expected_frames_timing_and_is_deterministic() {
        let a = creature_track("biped", 24);
        let mut b = creature_track("crab", 12);
        b.fps = 30.0;
        let mut a60 = a.clone();
        a60.fps = 60.0;
        let opts = GifOptions { panel_width: 96, panel_height: 110, ..Default::default() };
        let bytes = render_gif(&[a.clone(), b.clone()], &Legend::default(), &opts).unwrap();
        assert_eq!(&bytes[..6], b"GIF89a");
        let (w, h, n, total, _) = decode(&bytes);
        assert_eq!((w, h), (192, 110));
        assert_eq!(n, 24, "one frame per motion frame at 30 fps (the shorter track holds)");
        assert_eq!(total, 80, "24 frames at 30 fps last 0.8 s");
        assert_eq!(bytes, render_gif(&[a, b], &Legend::default(), &opts).unwrap());
        let (_, _, n, total, _) = decode(&render_gif(&[a60], &Legend::default(), &opts).unwrap());
        assert_eq!((n, total), (12, 40), "60 fps plays every 2nd frame at the right speed");
    }

    #[test]
    fn tints_legend_and_errors() {
        let mut t = creature_track("fish", 6);
        t.frame_labels = Some(vec![Some(0); 6]);
        let legend = Legend { labels: vec!["swim".into()] };
        let opts = GifOptions { panel_width: 128, panel_height: 128, ..Default::default() };
        let bytes = render_gif(&[t.clone()], &legend, &opts).unwrap();
        let (w, h, _, _, screen) = decode(&bytes);
        assert_eq!(w, 128);
        assert!(h > 128, "legend strip below the panel");
        let pal = gif_palette();
        let tint = pal.iter().position(|c| *c == sheet::tinted(palette(0))).unwrap() as u8;
        assert_eq!(screen[(HEADER as usize + 2) * 128 + 3], tint, "tinted panel");
        assert!(render_gif(&[t.clone()], &legend, &GifOptions { panel_width: 10, ..Default::default() }).is_err());
        let mut bad = t;
        bad.point_labels = Some(vec![Some(4); bad.points()]);
        assert!(matches!(render_gif(&[bad], &legend, &opts), Err(RenderError::Invalid(_))));
    }

    #[test]
    fn our_lzw_round_trips_through_the_gif_decoder() {
        // Runs, noise, and enough distinct strings to fill the code table several times.
        let mut data = vec![TRANSPARENT; 5000];
        let mut x = 12345u32;
        for _ in 0..60_000 {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            data.push((x >> 16) as u8);
        }
        data.extend(std::iter::repeat_n(7u8, 3000));
        for k in 0..3000usize {
            data.extend(std::iter::repeat_n(TRANSPARENT, k % 97));
            data.push((k % 5) as u8);
        }
        let (w, h) = (500u16, (data.len() / 500) as u16);
        data.truncate(w as usize * h as usize);
        let mut lzw = Lzw::new();
        let mut out = Vec::new();
        {
            let flat: Vec<u8> = (0..=255u8).flat_map(|v| [v, v, v]).collect();
            let mut e = gif::Encoder::new(&mut out, w, h, &flat).unwrap();
            for _ in 0..2 {
                let frame = gif::Frame { width: w, height: h, buffer: Cow::Owned(lzw.encode(&data)), ..gif::Frame::default() };
                e.write_lzw_pre_encoded_frame(&frame).unwrap();
            }
        }
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::Indexed);
        let mut d = options.read_info(std::io::Cursor::new(&out)).unwrap();
        for _ in 0..2 {
            let f = d.read_next_frame().unwrap().unwrap();
            assert!(f.buffer.as_ref() == data.as_slice(), "decoded pixels differ");
        }
        assert!(lzw.encode(&[]).len() >= 2);
    }

    #[test]
    fn differences_are_found_at_both_ends() {
        let a = vec![5u8; 61];
        for (i, j) in [(0, 0), (3, 40), (17, 60), (60, 60), (8, 9)] {
            let mut b = a.clone();
            b[i] = 1;
            b[j] = 2;
            assert_eq!((first_difference(&a, &b), last_difference(&a, &b)), (i, j));
        }
    }

    #[test]
    fn palette_fits_with_room_for_transparency() {
        let p = gif_palette();
        assert!(p.len() <= 255 && p.len() > 100, "{}", p.len());
        let mut q = Quantiser::new(p.clone());
        // Palette colours map to themselves unless another one shares their table cell.
        let exact = p.iter().enumerate().filter(|(i, c)| q.index(c.as_slice()) as usize == *i).count();
        assert!(exact + 10 >= p.len(), "only {exact} of {} palette colours map to themselves", p.len());
        for c in [BACKGROUND, BONE, FOOT, sheet::tinted(palette(0))] {
            assert_eq!(p[q.index(&c) as usize], c);
        }
    }
}
