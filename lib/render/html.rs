//! A self-contained HTML viewer: one file with inline CSS, JS and data that plays tracks in 3D.
//!
//! The page needs no network and no server (it works from `file://`): the viewer script
//! (`viewer.js`, plain canvas 2D with its own perspective projection) and style sheet are
//! embedded with `include_str!`, and the positions travel inside the page as base64 of one
//! zlib stream that the browser inflates with `DecompressionStream('deflate')`.
//!
//! Positions are quantised to 16-bit levels of 1/2000 of the creature's size (error at most
//! 0.025% of the body per coordinate; see `quantise`), stored relative to the parent point,
//! and predicted from the previous frame(s) of the same series, so what deflate sees is mostly
//! small residuals in two byte planes. Real 30 fps mocap takes about 1.4-2.1 bytes per point
//! and frame after base64 (faster motion costs more), so a 5000-frame, 115-point clip makes a
//! page of about 0.8-1.2 MB (`cargo test --test it render_html -- --ignored --nocapture` measures
//! it on the corpus).
//!
//! The page also carries a self test: opened with `#selftest` it draws two frames, counts the
//! drawn pixels of each and the pixels that differ, and writes the result (and any script
//! error) as JSON into `<pre id="selftest">`, which the browser test reads with
//! `chromium --dump-dom`.

use super::{palette, Legend, RenderError, Track};
use serde_json::{json, Value};

const TEMPLATE: &str = include_str!("viewer.html");
const CSS: &str = include_str!("viewer.css");
const JS: &str = include_str!("viewer.js");

/// Highest 16-bit level.
const LEVELS: f64 = 65535.0;
/// Levels per body size (see `quantise`).
const BODY_LEVELS: f64 = 2000.0;
/// Decoded positions per track that the page's self test checks its decoder against.
const PROBES: usize = 16;
/// Most points x frames in one page: about 20 MB of page and 200 MB of browser memory, far
/// beyond what plays well; longer material should be cut or subsampled first.
const MAX_POINT_FRAMES: usize = 10_000_000;

/// How the page plays.
#[derive(Clone, Debug, PartialEq)]
pub struct HtmlOptions {
    /// The page title (the browser tab's).
    pub title: String,
    /// Initial playback speed (1.0 = the motion's own frame rate).
    pub speed: f64,
    /// Draw all tracks in one scene on top of each other instead of side by side.
    pub overlay: bool,
    /// Start playing when the page opens.
    pub autoplay: bool,
    /// The camera follows the root of the (first) track instead of framing the whole path.
    pub follow: bool,
}

impl Default for HtmlOptions {
    fn default() -> Self {
        HtmlOptions { title: "motion".to_string(), speed: 1.0, overlay: false, autoplay: true, follow: false }
    }
}

/// The viewer page for `tracks`, coloured with `legend` (see [`super::labels`]).
pub fn render_html(tracks: &[Track], legend: &Legend, opts: &HtmlOptions) -> Result<String, RenderError> {
    let total = tracks.iter().fold(0usize, |sum, t| sum.saturating_add(t.frames.saturating_mul(t.points())));
    if total > MAX_POINT_FRAMES {
        return Err(RenderError::TooLarge(format!(
            "{total} points x frames would make a page too big to play ({MAX_POINT_FRAMES} at most): show fewer frames or tracks"
        )));
    }
    validate(tracks, legend)?;
    if !opts.speed.is_finite() || opts.speed <= 0.0 {
        return Err(RenderError::Invalid(format!("speed must be a positive number, got {}", opts.speed)));
    }
    let mut raw = Vec::new();
    let mut metas = Vec::with_capacity(tracks.len());
    for track in tracks {
        let encoded = encode_track(track);
        metas.push(track_meta(track, &encoded, raw.len()));
        raw.extend_from_slice(&encoded.bytes);
    }
    // Level 9: the page is written once and read many times; 3.5 MB compress in well under a second.
    let packed = miniz_oxide::deflate::compress_to_vec_zlib(&raw, 9);
    let legend_json: Vec<Value> = legend.labels.iter().enumerate().map(|(i, name)| json!({"name": name, "colour": hex(palette(i))})).collect();
    let meta = json!({
        "title": opts.title,
        "speed": opts.speed,
        "overlay": opts.overlay,
        "autoplay": opts.autoplay,
        "follow": opts.follow,
        "legend": legend_json,
        // Overlaid tracks without point labels are told apart by colour.
        "trackColours": (0..tracks.len()).map(|i| hex(palette(i))).collect::<Vec<_>>(),
        "dataBytes": raw.len(),
        "tracks": metas,
    });
    let meta = script_json(&meta.to_string());
    let data = base64(&packed);
    let title = escape_html(&opts.title);
    Ok(fill(TEMPLATE, &[("TITLE", &title), ("CSS", CSS), ("META", &meta), ("DATA", &data), ("JS", JS)]))
}

/// Check everything the page relies on, so the viewer never meets a broken track.
fn validate(tracks: &[Track], legend: &Legend) -> Result<(), RenderError> {
    if tracks.is_empty() {
        return Err(RenderError::Empty("no tracks to show".to_string()));
    }
    for t in tracks {
        let name = &t.title;
        let n = t.points();
        if t.frames == 0 {
            return Err(RenderError::Empty(format!("{name}: no frames to show")));
        }
        if n == 0 {
            return Err(RenderError::Empty(format!("{name}: no points to show")));
        }
        if t.names.len() != n || t.end_site.len() != n {
            return Err(RenderError::Invalid(format!(
                "{name}: {n} points but {} names and {} end-site flags (one each per point)",
                t.names.len(),
                t.end_site.len()
            )));
        }
        if t.positions.len() != t.frames * n {
            return Err(RenderError::Invalid(format!("{name}: {} positions, expected {} frames x {n} points = {}", t.positions.len(), t.frames, t.frames * n)));
        }
        if let Some((p, q)) = t.parents.iter().enumerate().find_map(|(p, q)| q.filter(|&q| q >= n).map(|q| (p, q))) {
            return Err(RenderError::Invalid(format!("{name}: point {p} has parent {q}, but there are only {n} points")));
        }
        if let Some(&foot) = t.feet.iter().find(|&&f| f >= n) {
            return Err(RenderError::Invalid(format!("{name}: foot {foot} is not a point (there are {n})")));
        }
        if !t.fps.is_finite() || t.fps <= 0.0 {
            return Err(RenderError::Invalid(format!("{name}: frame rate must be a positive number, got {}", t.fps)));
        }
        let labels = legend.labels.len();
        if let Some(pl) = &t.point_labels {
            if pl.len() != n {
                return Err(RenderError::Invalid(format!("{name}: {} point labels for {n} points", pl.len())));
            }
            if let Some((p, l)) = pl.iter().enumerate().find_map(|(p, l)| l.filter(|&l| l >= labels).map(|l| (p, l))) {
                return Err(RenderError::Invalid(format!("{name}: point {p} has label {l}, but the legend has {labels} labels")));
            }
        }
        if let Some(fl) = &t.frame_labels {
            if fl.len() != t.frames {
                return Err(RenderError::Invalid(format!("{name}: {} frame labels for {} frames", fl.len(), t.frames)));
            }
            if let Some((f, l)) = fl.iter().enumerate().find_map(|(f, l)| l.filter(|&l| l >= labels).map(|l| (f, l))) {
                return Err(RenderError::Invalid(format!("{name}: frame {f} has label {l}, but the legend has {labels} labels")));
            }
        }
        if let Some(i) = t.positions.iter().position(|p| !p.is_finite()) {
            let (f, p) = (i / n, i % n);
            return Err(RenderError::NonFinite(format!("{name}: frame {f}, point {p} ({}) is not finite: {}", t.names[p], t.positions[i])));
        }
    }
    Ok(())
}

/// One track's positions, ready for the page.
struct Encoded {
    q: Quantised,
    /// Prediction order: 1 = previous frame, 2 = linear extrapolation from the two previous.
    order: u8,
    /// Zigzagged residuals, series by series (point-major, then axis, then frame): all low
    /// bytes, then all high bytes (the high bytes are mostly 0 and compress to almost nothing).
    bytes: Vec<u8>,
}

/// 16-bit levels of every coordinate: `min + level * step` is the position the page shows.
struct Quantised {
    /// One series per point and axis, frames contiguous: level of point `p`, axis `a`, frame
    /// `f` at `[(p * 3 + a) * frames + f]`.
    levels: Vec<u16>,
    min: [f64; 3],
    /// Size of one level per axis (0 for a flat axis).
    step: [f64; 3],
}

/// The largest single-frame extent (bounding box diagonal): the creature's size, whatever
/// distance it travels.
fn body_size(track: &Track) -> f64 {
    (0..track.frames)
        .map(|f| {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in track.frame(f) {
                for a in 0..3 {
                    lo[a] = lo[a].min(f64::from(p[a]));
                    hi[a] = hi[a].max(f64::from(p[a]));
                }
            }
            (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt()
        })
        .fold(0.0, f64::max)
}

/// Quantise relative to the creature's size: a level is 1/2000 of the body, so a coordinate
/// is off by at most 0.025% of the body (a point by at most 0.043%), far below a pixel, while
/// finer levels would only add bits deflate cannot remove (the motion's own noise). Paths
/// longer than 32 bodies take coarser levels so 16 bits still span the bounding box.
fn quantise(track: &Track) -> Quantised {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &track.positions {
        for a in 0..3 {
            lo[a] = lo[a].min(f64::from(p[a]));
            hi[a] = hi[a].max(f64::from(p[a]));
        }
    }
    let body = body_size(track);
    let step: [f64; 3] = std::array::from_fn(|a| (body / BODY_LEVELS).max((hi[a] - lo[a]) / LEVELS));
    let (n, frames) = (track.points(), track.frames);
    let mut levels = vec![0u16; n * 3 * frames];
    for f in 0..frames {
        for (p, pos) in track.frame(f).iter().enumerate() {
            for a in 0..3 {
                // Validated finite, and the step spans the box, so the cast is exact.
                let level = if step[a] > 0.0 { ((f64::from(pos[a]) - lo[a]) / step[a]).round().clamp(0.0, LEVELS) } else { 0.0 };
                levels[(p * 3 + a) * frames + f] = level as u16;
            }
        }
    }
    Quantised { levels, min: lo, step }
}

/// The point a point's levels are stored relative to: its parent, when the page decodes that
/// first (a lower index; true of every track `Track::from_motion` builds). A child moves with
/// its parent, so the difference changes more slowly than either.
fn reference(track: &Track, p: usize) -> Option<usize> {
    track.parents[p].filter(|&q| q < p)
}

/// Residuals of one series under a prediction order, in wrapping 16-bit arithmetic (the
/// page undoes it with the same wrap), zigzagged so small residuals of either sign are small.
fn residuals(series: &[u16], order: u8, out: &mut Vec<u16>) {
    for (f, &q) in series.iter().enumerate() {
        let pred = match (f, order) {
            (0, _) => 0u16,
            (1, _) | (_, 1) => series[f - 1],
            _ => series[f - 1].wrapping_mul(2).wrapping_sub(series[f - 2]),
        };
        let e = q.wrapping_sub(pred) as i16;
        out.push(((e << 1) ^ (e >> 15)) as u16);
    }
}

/// Rough cost in bits of a residual stream, to pick the prediction order without compressing twice.
fn cost(residuals: &[u16]) -> u64 {
    residuals.iter().map(|&z| u64::from(16 - z.leading_zeros()) + 1).sum()
}

fn encode_track(track: &Track) -> Encoded {
    let q = quantise(track);
    let frames = track.frames;
    let series = |i: usize| &q.levels[i * frames..(i + 1) * frames];
    let relative: Vec<u16> = (0..track.points() * 3)
        .flat_map(|i| {
            let (p, a) = (i / 3, i % 3);
            let base = reference(track, p).map(|r| series(r * 3 + a));
            series(i).iter().enumerate().map(move |(f, &v)| base.map_or(v, |b| v.wrapping_sub(b[f])))
        })
        .collect();
    // Order 2 wins for smooth, densely sampled motion; order 1 for noisy or sparse motion.
    let mut best: Option<(u64, u8, Vec<u16>)> = None;
    for order in [1u8, 2] {
        let mut r = Vec::with_capacity(relative.len());
        for s in relative.chunks(frames) {
            residuals(s, order, &mut r);
        }
        let c = cost(&r);
        if best.as_ref().is_none_or(|(bc, _, _)| c < *bc) {
            best = Some((c, order, r));
        }
    }
    let (_, order, r) = best.expect("two orders tried");
    let mut bytes = Vec::with_capacity(2 * r.len());
    bytes.extend(r.iter().map(|z| (z & 0xff) as u8));
    bytes.extend(r.iter().map(|z| (z >> 8) as u8));
    Encoded { q, order, bytes }
}

/// Position of point `p` at frame `f` as the page decodes it.
fn dequantised(track: &Track, q: &Quantised, f: usize, p: usize) -> [f64; 3] {
    std::array::from_fn(|a| q.min[a] + f64::from(q.levels[(p * 3 + a) * track.frames + f]) * q.step[a])
}

fn track_meta(track: &Track, e: &Encoded, offset: usize) -> Value {
    let (n, frames) = (track.points(), track.frames);
    // A few decoded positions, spread over frames and points, that the page's self test
    // compares its own decoding with (the JS decoder is checked against this one).
    let probes: Vec<Value> = (0..PROBES)
        .map(|i| {
            let (f, p) = ((i * frames) / PROBES, (i * 7919 + n - 1) % n);
            json!([f, p, dequantised(track, &e.q, f, p)])
        })
        .collect();
    json!({
        "title": track.title,
        "names": track.names,
        "parents": track.parents,
        "reference": (0..n).map(|p| reference(track, p)).collect::<Vec<_>>(),
        "endSite": track.end_site,
        "feet": track.feet,
        "fps": track.fps,
        "frames": frames,
        "points": n,
        "min": e.q.min,
        "step": e.q.step,
        "order": e.order,
        "offset": offset,
        "pointLabels": track.point_labels,
        "frameLabels": track.frame_labels,
        "probes": probes,
    })
}

/// Positions as the page shows them, `[f * points + p]` (the quantisation error is measured on these).
pub fn decoded_positions(track: &Track) -> Vec<[f64; 3]> {
    let q = quantise(track);
    let n = track.points();
    (0..track.frames * n).map(|i| dequantised(track, &q, i / n, i % n)).collect()
}

fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// Text for HTML element content and attribute values.
fn escape_html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// JSON safe inside `<script type="application/json">`: `<`, `>` and `&` only occur inside JSON
/// strings, where their \u escapes mean the same, so no `</script>` or `<!--` can end the element.
fn script_json(json: &str) -> String {
    json.replace('<', "\\u003c").replace('>', "\\u003e").replace('&', "\\u0026")
}

/// Replace `{{KEY}}` markers in one pass, so inserted text is never scanned for markers.
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out = String::with_capacity(template.len() + values.iter().map(|(_, v)| v.len()).sum::<usize>());
    let mut rest = template;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        match after.find("}}").and_then(|end| values.iter().find(|(k, _)| *k == &after[..end]).map(|(_, v)| (end, v))) {
            Some((end, v)) => {
                out.push_str(v);
                rest = &after[end + 2..];
            }
            None => {
                out.push_str("{{");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Standard base64 with padding (the page decodes it with `atob`).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], chunk.get(1).copied().unwrap_or(0), chunk.get(2).copied().unwrap_or(0)];
        let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[((v >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;
    use glam::Vec3;

    /// A creature-like track: `points` points hanging off a root that walks a circle, each
    /// swinging at its own frequencies, plus mocap-like jitter (±0.5 mm on a 1.8 m body).
    fn synthetic(frames: usize, points: usize, seed: u64) -> Track {
        let mut rng = SplitMix64::new(seed);
        let parents: Vec<Option<usize>> = (0..points).map(|p| if p == 0 { None } else { Some((p - 1) / 3) }).collect();
        let swing: Vec<[f64; 6]> = (0..points).map(|_| std::array::from_fn(|i| if i < 3 { rng.range(0.02, 0.15) } else { rng.range(0.4, 1.6) })).collect();
        let rest: Vec<[f64; 3]> = (0..points).map(|_| [rng.range(-0.4, 0.4), rng.range(0.0, 1.8), rng.range(-0.3, 0.3)]).collect();
        let fps = 30.0;
        let mut positions = Vec::with_capacity(frames * points);
        for f in 0..frames {
            let t = f as f64 / fps;
            let (cx, cz) = (3.0 * (t * 0.4).cos(), 3.0 * (t * 0.4).sin());
            for p in 0..points {
                let v: [f64; 3] = std::array::from_fn(|a| {
                    let centre = [cx, 0.0, cz][a];
                    centre + rest[p][a] + swing[p][a] * (swing[p][a + 3] * std::f64::consts::TAU * t + p as f64).sin() + rng.range(-5e-4, 5e-4)
                });
                positions.push(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32));
            }
        }
        Track {
            title: format!("synthetic {points}"),
            names: (0..points).map(|p| format!("joint{p}")).collect(),
            parents,
            end_site: (0..points).map(|p| p > 0 && p + 5 >= points).collect(),
            feet: vec![1, 2],
            fps,
            frames,
            positions,
            point_labels: None,
            frame_labels: None,
        }
    }

    /// The page's own decoding, step by step as viewer.js does it.
    fn decode_page(page: &str) -> (Value, Vec<Vec<[f64; 3]>>) {
        let between = |from: &str| {
            let s = page.find(from).expect(from) + from.len();
            &page[s..s + page[s..].find("</script>").expect("closing script")]
        };
        let meta: Value = serde_json::from_str(between(r#"<script type="application/json" id="meta">"#)).unwrap();
        let text = between(r#"<script type="application/octet-stream" id="data">"#);
        let packed = unbase64(text);
        let bytes = miniz_oxide::inflate::decompress_to_vec_zlib(&packed).unwrap();
        assert_eq!(bytes.len() as u64, meta["dataBytes"].as_u64().unwrap());
        let mut out = Vec::new();
        for t in meta["tracks"].as_array().unwrap() {
            let u = |k: &str| t[k].as_u64().unwrap() as usize;
            let (frames, points, offset, order) = (u("frames"), u("points"), u("offset"), u("order"));
            let min: Vec<f64> = t["min"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let step: Vec<f64> = t["step"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let n = frames * points * 3;
            let mut levels = vec![0u16; n];
            let mut pos = vec![[0.0; 3]; frames * points];
            for k in 0..n {
                let (series, f) = (k / frames, k % frames);
                let (p, a) = (series / 3, series % 3);
                let z = u16::from(bytes[offset + k]) | (u16::from(bytes[offset + n + k]) << 8);
                let e = ((z >> 1) as i16) ^ -((z & 1) as i16);
                let prev = |d: usize| {
                    // Undo the reference to recover the stored (relative) series value.
                    let r = t["reference"][p].as_u64().map(|r| levels[(r as usize * 3 + a) * frames + f - d]).unwrap_or(0);
                    levels[k - d].wrapping_sub(r)
                };
                let pred = match f {
                    0 => 0,
                    1 => prev(1),
                    _ if order == 1 => prev(1),
                    _ => prev(1).wrapping_mul(2).wrapping_sub(prev(2)),
                };
                let v = pred.wrapping_add(e as u16);
                let r = t["reference"][p].as_u64().map(|r| levels[(r as usize * 3 + a) * frames + f]).unwrap_or(0);
                levels[k] = v.wrapping_add(r);
                pos[f * points + p][a] = min[a] + f64::from(levels[k]) * step[a];
            }
            out.push(pos);
        }
        (meta, out)
    }

    fn unbase64(text: &str) -> Vec<u8> {
        let value = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        };
        let mut out = Vec::new();
        for chunk in text.trim().as_bytes().chunks(4) {
            let digits: Vec<u8> = chunk.iter().filter(|&&c| c != b'=').map(|&c| value(c)).collect();
            let v = digits.iter().enumerate().fold(0u32, |v, (i, &d)| v | (u32::from(d) << (18 - 6 * i)));
            for i in 0..digits.len().saturating_sub(1) {
                out.push((v >> (16 - 8 * i)) as u8);
            }
        }
        out
    }

    #[test]
    fn positions_survive_the_page_within_the_error_bound() {
        let a = synthetic(120, 23, 1);
        let mut b = synthetic(7, 4, 2);
        // Nothing moves and the box is a point: zero-sized steps must decode to the point itself.
        b.positions.iter_mut().for_each(|p| *p = Vec3::new(1.0, 2.0, 3.0));
        let tracks = [a, b];
        let page = render_html(&tracks, &Legend::default(), &HtmlOptions::default()).unwrap();
        let (meta, decoded) = decode_page(&page);
        for (t, d) in tracks.iter().zip(&decoded) {
            let body = body_size(t);
            let mut worst: f64 = 0.0;
            for (p, q) in t.positions.iter().zip(d) {
                worst = worst.max((0..3).map(|a| (f64::from(p[a]) - q[a]).powi(2)).sum::<f64>().sqrt());
            }
            assert!(worst <= 0.0005 * body, "{}: error {worst} for body {body}", t.title);
            assert_eq!(d, &decoded_positions(t), "{}: the page decodes what decoded_positions says", t.title);
        }
        assert_eq!(meta["tracks"][1]["points"], 4);
        assert!(decoded[1].iter().all(|p| *p == [1.0, 2.0, 3.0]));
    }

    #[test]
    fn a_long_clip_makes_a_small_page() {
        // 5000 frames x 115 points: 1.7 M coordinates, 6.9 MB as f32.
        let track = synthetic(5000, 115, 7);
        let page = render_html(std::slice::from_ref(&track), &Legend::default(), &HtmlOptions::default()).unwrap();
        eprintln!("5000 x 115 synthetic: page {} bytes", page.len());
        assert!(page.len() < 1_500_000, "page is {} bytes", page.len());
        let body = body_size(&track);
        let worst = track
            .positions
            .iter()
            .zip(decoded_positions(&track))
            .map(|(p, q)| (0..3).map(|a| (f64::from(p[a]) - q[a]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        assert!(worst < 0.0005 * body, "error {worst} for body {body}");
    }

    #[test]
    fn hostile_names_stay_text() {
        let mut t = synthetic(5, 4, 3);
        t.title = "</script><script>alert(1)</script>".to_string();
        t.names[2] = "<!-- \"quoted\" & 'single' </SCRIPT >".to_string();
        t.point_labels = Some(vec![Some(0), None, Some(1), Some(0)]);
        let legend = Legend { labels: vec!["</style>".to_string(), "a\u{2028}b <b>".to_string()] };
        let opts = HtmlOptions { title: "</title><script>alert(2)</script>&".to_string(), ..HtmlOptions::default() };
        let page = render_html(std::slice::from_ref(&t), &legend, &opts).unwrap();
        let lower = page.to_ascii_lowercase();
        // Only the template's own four scripts, one title, one style and no comment opener.
        assert_eq!(lower.matches("<script").count(), 4, "{page}");
        assert_eq!(lower.matches("</script").count(), 4);
        assert_eq!(lower.matches("</title").count(), 1);
        assert_eq!(lower.matches("</style").count(), 1);
        assert!(!page.contains("<!--"));
        assert!(page.contains("<title>&lt;/title&gt;&lt;script&gt;alert(2)&lt;/script&gt;&amp;</title>"));
        let (meta, _) = decode_page(&page);
        assert_eq!(meta["tracks"][0]["title"], t.title);
        assert_eq!(meta["tracks"][0]["names"][2], t.names[2]);
        assert_eq!(meta["legend"][1]["name"], legend.labels[1]);
        assert_eq!(meta["legend"][0]["colour"], "#1f77b4");
        assert_eq!(meta["title"], opts.title);
    }

    #[test]
    fn bad_tracks_are_refused_with_names() {
        let legend = Legend::default();
        let opts = HtmlOptions::default();
        assert!(matches!(render_html(&[], &legend, &opts), Err(RenderError::Empty(_))));
        let mut empty = synthetic(3, 4, 4);
        empty.title = "walk.bvh".to_string();
        empty.frames = 0;
        empty.positions.clear();
        let e = render_html(&[synthetic(3, 4, 4), empty], &legend, &opts).unwrap_err();
        assert!(matches!(&e, RenderError::Empty(m) if m.contains("walk.bvh") && m.contains("no frames")), "{e}");
        let mut bad = synthetic(3, 4, 4);
        bad.positions[2 * 4 + 3].y = f32::NAN;
        let e = render_html(&[bad], &legend, &opts).unwrap_err();
        assert!(matches!(&e, RenderError::NonFinite(m) if m.contains("frame 2, point 3 (joint3)")), "{e}");
        let mut labelled = synthetic(3, 4, 4);
        labelled.frame_labels = Some(vec![None, Some(2), None]);
        let e = render_html(&[labelled], &Legend { labels: vec!["a".into(), "b".into()] }, &opts).unwrap_err();
        assert!(e.to_string().contains("frame 1 has label 2, but the legend has 2 labels"), "{e}");
        let mut short = synthetic(3, 4, 4);
        short.positions.pop();
        assert!(matches!(render_html(&[short], &legend, &opts), Err(RenderError::Invalid(_))));
        let mut huge = synthetic(1, 4, 4);
        huge.frames = MAX_POINT_FRAMES / 4 + 1;
        // Refused from the sizes alone, before looking at (here missing) positions.
        assert!(matches!(render_html(&[huge], &legend, &opts), Err(RenderError::TooLarge(_))));
        let e = render_html(&[synthetic(3, 4, 4)], &legend, &HtmlOptions { speed: f64::NAN, ..opts.clone() }).unwrap_err();
        assert!(e.to_string().contains("speed"), "{e}");
    }

    #[test]
    fn same_input_same_page() {
        let tracks = [synthetic(40, 9, 5), synthetic(30, 6, 6)];
        let opts = HtmlOptions { overlay: true, follow: true, autoplay: false, speed: 0.3, title: "t".into() };
        let a = render_html(&tracks, &Legend::default(), &opts).unwrap();
        let b = render_html(&tracks, &Legend::default(), &opts).unwrap();
        assert!(a == b, "two renders differ");
        assert!(a.contains(r#""overlay":true"#) && a.contains(r#""speed":0.3"#));
    }

    #[test]
    fn template_pieces() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar\xff"), "Zm9vYmFy/w==");
        assert_eq!(unbase64(&base64(&[0, 255, 7, 9, 128])), [0, 255, 7, 9, 128]);
        // Inserted text is not scanned again, and unknown markers stay as they are.
        assert_eq!(fill("a{{X}}b{{Y}}c{{", &[("X", "{{Y}}"), ("Y", "1")]), "a{{Y}}b1c{{");
        assert_eq!(fill("{{NOPE}}", &[]), "{{NOPE}}");
        assert_eq!(escape_html(r#"<a href="x">'&'"#), "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;");
        assert_eq!(script_json(r#"{"a":"</script><!--&"}"#), r#"{"a":"\u003c/script\u003e\u003c!--\u0026"}"#);
        // Our own files must not end their elements early.
        for (name, text) in [("viewer.js", JS), ("viewer.css", CSS)] {
            let lower = text.to_ascii_lowercase();
            assert!(!lower.contains("</script") && !lower.contains("</style") && !lower.contains("<!--"), "{name}");
        }
        for marker in ["{{TITLE}}", "{{CSS}}", "{{META}}", "{{DATA}}", "{{JS}}"] {
            assert_eq!(TEMPLATE.matches(marker).count(), 1, "{marker}");
        }
    }
}
