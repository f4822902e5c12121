//! A small RGB canvas with the few primitives our pictures need: anti-aliased thick lines
//! (capsules), filled discs, rectangles, tints and bitmap text.
//!
//! Coverage is computed from the exact distance to the shape (1 inside, fading to 0 over one
//! pixel at the edge), which gives clean lines at any angle without supersampling. Everything
//! is clipped to the canvas, so any finite coordinates are safe; work is bounded by the canvas
//! size, never by how far outside a shape lies.

use super::{font, RenderError};

/// An RGB colour.
pub type Rgb = [u8; 3];

/// Largest picture side we draw, and the largest pixel count (a sheet of a very long motion
/// with a small `every` would otherwise ask for gigabytes).
pub const MAX_SIDE: u64 = 16384;
pub const MAX_PIXELS: u64 = 100_000_000;

/// Refuse pictures that are empty or beyond [`MAX_SIDE`] / [`MAX_PIXELS`] (`what` names the picture).
pub fn check_size(width: u64, height: u64, what: &str) -> Result<(), RenderError> {
    if width == 0 || height == 0 {
        return Err(RenderError::Invalid(format!("{what}: a {width} x {height} picture has no pixels")));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width * height > MAX_PIXELS {
        return Err(RenderError::TooLarge(format!(
            "{what} would be {width} x {height} pixels; the limit is {MAX_SIDE} a side and {} Mpx \
             (draw fewer frames: a larger --every, fewer columns or rows, smaller cells)",
            MAX_PIXELS / 1_000_000
        )));
    }
    Ok(())
}

/// Row-major RGB pixels, 3 bytes each, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Canvas {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}

/// `c` over `under` with opacity `alpha` in 0..=256.
#[inline]
fn mix(under: u8, c: u8, alpha: u32) -> u8 {
    ((c as u32 * alpha + under as u32 * (256 - alpha) + 128) >> 8) as u8
}

/// `c` over `under` with opacity `alpha` in 0.0..=1.0 (for building colours, not per pixel).
pub fn blend(under: Rgb, c: Rgb, alpha: f32) -> Rgb {
    let a = (alpha.clamp(0.0, 1.0) * 256.0).round() as u32;
    [mix(under[0], c[0], a), mix(under[1], c[1], a), mix(under[2], c[2], a)]
}

impl Canvas {
    /// A canvas filled with `background`. Callers check the size first ([`check_size`]).
    pub fn new(width: u32, height: u32, background: Rgb) -> Canvas {
        let mut pixels = Vec::with_capacity(width as usize * height as usize * 3);
        for _ in 0..width as usize * height as usize {
            pixels.extend_from_slice(&background);
        }
        Canvas { width, height, pixels }
    }

    /// The colour at (x, y); black outside the canvas.
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        if x >= self.width || y >= self.height {
            return [0, 0, 0];
        }
        let i = (y as usize * self.width as usize + x as usize) * 3;
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    /// Paint (x, y) with `c` at opacity `alpha` (0..=256); ignores points outside the canvas.
    #[inline]
    pub fn blend_pixel(&mut self, x: i32, y: i32, c: Rgb, alpha: u32) {
        if x < 0 || y < 0 || x as u32 >= self.width || y as u32 >= self.height || alpha == 0 {
            return;
        }
        let i = (y as usize * self.width as usize + x as usize) * 3;
        let px = &mut self.pixels[i..i + 3];
        if alpha >= 256 {
            px.copy_from_slice(&c);
        } else {
            for k in 0..3 {
                px[k] = mix(px[k], c[k], alpha);
            }
        }
    }

    /// Clip a rectangle to the canvas: (x0, y0, x1, y1) exclusive, or None when nothing is left.
    fn clip(&self, x: i64, y: i64, w: i64, h: i64) -> Option<(usize, usize, usize, usize)> {
        let x0 = x.max(0);
        let y0 = y.max(0);
        let x1 = (x + w).min(self.width as i64);
        let y1 = (y + h).min(self.height as i64);
        (x0 < x1 && y0 < y1).then_some((x0 as usize, y0 as usize, x1 as usize, y1 as usize))
    }

    /// Fill a rectangle with `c` at opacity `alpha` (0..=256; 256 paints over).
    pub fn fill_rect(&mut self, x: i32, y: i32, w: i32, h: i32, c: Rgb, alpha: u32) {
        let Some((x0, y0, x1, y1)) = self.clip(x as i64, y as i64, w as i64, h as i64) else { return };
        let stride = self.width as usize * 3;
        for row in y0..y1 {
            let line = &mut self.pixels[row * stride + x0 * 3..row * stride + x1 * 3];
            for px in line.chunks_exact_mut(3) {
                if alpha >= 256 {
                    px.copy_from_slice(&c);
                } else {
                    for k in 0..3 {
                        px[k] = mix(px[k], c[k], alpha);
                    }
                }
            }
        }
    }

    /// A one-pixel outline of a rectangle.
    pub fn outline_rect(&mut self, x: i32, y: i32, w: i32, h: i32, c: Rgb) {
        self.fill_rect(x, y, w, 1, c, 256);
        self.fill_rect(x, y + h - 1, w, 1, c, 256);
        self.fill_rect(x, y, 1, h, c, 256);
        self.fill_rect(x + w - 1, y, 1, h, c, 256);
    }

    /// Copy `src` with its top-left corner at (x, y), clipped.
    pub fn blit(&mut self, src: &Canvas, x: i32, y: i32) {
        let Some((x0, y0, x1, y1)) = self.clip(x as i64, y as i64, src.width as i64, src.height as i64) else { return };
        let (stride, src_stride) = (self.width as usize * 3, src.width as usize * 3);
        for row in y0..y1 {
            let sy = (row as i64 - y as i64) as usize;
            let sx = (x0 as i64 - x as i64) as usize;
            let from = &src.pixels[sy * src_stride + sx * 3..sy * src_stride + (sx + x1 - x0) * 3];
            self.pixels[row * stride + x0 * 3..row * stride + x1 * 3].copy_from_slice(from);
        }
    }

    /// An anti-aliased line `width` pixels thick with round ends, from `a` to `b` (pixel
    /// coordinates; pixel (i, j) covers [i, i+1) x [j, j+1)).
    pub fn line(&mut self, a: (f32, f32), b: (f32, f32), width: f32, c: Rgb) {
        let r = (width * 0.5).max(0.5);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        if len2.is_nan() || len2 <= 1e-6 {
            self.disc(a, r, c);
            return;
        }
        let reach = r + 1.0;
        let Some((x0, y0, x1, y1)) = self.bounds(a.0.min(b.0) - reach, a.1.min(b.1) - reach, a.0.max(b.0) + reach, a.1.max(b.1) + reach) else {
            return;
        };
        let len = len2.sqrt();
        let outer2 = (r + 0.5) * (r + 0.5);
        let inner2 = if r > 0.5 { (r - 0.5) * (r - 0.5) } else { 0.0 };
        for y in y0..y1 {
            let py = y as f32 + 0.5;
            // Only the pixels of this row within `reach` of the infinite line can be covered:
            // |(p - a) x d| <= reach * |d| is an interval in x (the whole row for a flat line).
            let (mut lo, mut hi) = (x0, x1);
            if dy.abs() > 1e-3 {
                let base = (py - a.1) * dx;
                let e1 = a.0 + (base - reach * len) / dy;
                let e2 = a.0 + (base + reach * len) / dy;
                lo = lo.max((e1.min(e2) - 0.5).floor().max(x0 as f32) as i32);
                hi = hi.min((e1.max(e2) + 0.5).ceil().min(x1 as f32) as i32);
            }
            for x in lo..hi {
                let px = x as f32 + 0.5;
                let t = (((px - a.0) * dx + (py - a.1) * dy) / len2).clamp(0.0, 1.0);
                let (ex, ey) = (px - a.0 - t * dx, py - a.1 - t * dy);
                let d2 = ex * ex + ey * ey;
                // Square roots only on the one-pixel edge band.
                if d2 >= outer2 {
                    continue;
                }
                let alpha = if d2 <= inner2 { 256 } else { ((r + 0.5 - d2.sqrt()).clamp(0.0, 1.0) * 256.0) as u32 };
                self.blend_pixel(x, y, c, alpha);
            }
        }
    }

    /// An anti-aliased filled disc.
    pub fn disc(&mut self, centre: (f32, f32), radius: f32, c: Rgb) {
        let reach = radius + 1.0;
        let Some((x0, y0, x1, y1)) = self.bounds(centre.0 - reach, centre.1 - reach, centre.0 + reach, centre.1 + reach) else { return };
        for y in y0..y1 {
            let ey = y as f32 + 0.5 - centre.1;
            for x in x0..x1 {
                let ex = x as f32 + 0.5 - centre.0;
                let cover = radius + 0.5 - (ex * ex + ey * ey).sqrt();
                if cover > 0.0 {
                    self.blend_pixel(x, y, c, (cover.min(1.0) * 256.0) as u32);
                }
            }
        }
    }

    /// A filled square of side `side` centred on `centre` (anti-aliased edges).
    pub fn square(&mut self, centre: (f32, f32), side: f32, c: Rgb) {
        let h = side * 0.5;
        let Some((x0, y0, x1, y1)) = self.bounds(centre.0 - h - 1.0, centre.1 - h - 1.0, centre.0 + h + 1.0, centre.1 + h + 1.0) else { return };
        for y in y0..y1 {
            let cy = (h + 0.5 - (y as f32 + 0.5 - centre.1).abs()).clamp(0.0, 1.0);
            for x in x0..x1 {
                let cx = (h + 0.5 - (x as f32 + 0.5 - centre.0).abs()).clamp(0.0, 1.0);
                self.blend_pixel(x, y, c, (cx * cy * 256.0) as u32);
            }
        }
    }

    /// Pixel bounds [x0, x1) x [y0, y1) of a float box, clipped; None when off the canvas or
    /// not finite.
    fn bounds(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> Option<(i32, i32, i32, i32)> {
        if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite()) {
            return None;
        }
        let bx0 = x0.floor().max(0.0);
        let by0 = y0.floor().max(0.0);
        let bx1 = x1.ceil().min(self.width as f32);
        let by1 = y1.ceil().min(self.height as f32);
        (bx0 < bx1 && by0 < by1).then_some((bx0 as i32, by0 as i32, bx1 as i32, by1 as i32))
    }

    /// Write `text` with its top-left corner at (x, y) at integer `scale`; returns the x after it.
    pub fn text(&mut self, x: i32, y: i32, text: &str, c: Rgb, scale: u32) -> i32 {
        let s = scale.max(1) as i32;
        let mut pen = x;
        for ch in text.chars() {
            if pen >= self.width as i32 {
                break;
            }
            let g = font::glyph(ch);
            for (row, bits) in g.iter().enumerate() {
                if *bits == 0 {
                    continue;
                }
                for col in 0..font::GLYPH_WIDTH as i32 {
                    if bits & (1 << (font::GLYPH_WIDTH as i32 - 1 - col)) != 0 {
                        self.fill_rect(pen + col * s, y + row as i32 * s, s, s, c, 256);
                    }
                }
            }
            pen += font::ADVANCE as i32 * s;
        }
        pen
    }

    /// PNG bytes (8-bit RGB).
    pub fn to_png(&self) -> Result<Vec<u8>, RenderError> {
        let mut out = Vec::new();
        let fail = |e: png::EncodingError| RenderError::Invalid(format!("PNG encoding failed: {e}"));
        {
            let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            // Flat colours compress well even with the fastest settings; the picture is for
            // looking at, not for archiving.
            encoder.set_compression(png::Compression::Fast);
            let mut writer = encoder.write_header().map_err(fail)?;
            writer.write_image_data(&self.pixels).map_err(fail)?;
            writer.finish().map_err(fail)?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: Rgb = [255, 255, 255];
    const BLACK: Rgb = [0, 0, 0];

    #[test]
    fn lines_cover_their_path_and_stay_clipped() {
        let mut c = Canvas::new(40, 30, WHITE);
        c.line((5.0, 5.0), (35.0, 25.0), 2.0, BLACK);
        assert_eq!(c.get(20, 15), BLACK, "the middle of the line is inked");
        assert_eq!(c.get(35, 5), WHITE, "far from the line stays blank");
        let edge = c.get(20, 17);
        assert!(edge[0] > 0, "anti-aliased edge or blank beside the line: {edge:?}");
        // Far outside and huge coordinates: no panic, nothing drawn on-canvas from off-canvas shapes.
        let mut d = Canvas::new(10, 10, WHITE);
        d.line((-1e9, -1e9), (-1e8, 5e8), 3.0, BLACK);
        d.disc((1e12, 3.0), 2.0, BLACK);
        d.line((f32::NAN, 0.0), (3.0, 3.0), 1.0, BLACK);
        assert!(d.pixels.iter().all(|&v| v == 255));
        // A vertical line crossing the whole canvas.
        d.line((5.5, -100.0), (5.5, 100.0), 1.0, BLACK);
        assert_eq!(d.get(5, 9), BLACK);
    }

    #[test]
    fn discs_rects_text_and_blit() {
        let mut c = Canvas::new(30, 20, WHITE);
        c.disc((10.0, 10.0), 3.0, [200, 0, 0]);
        assert_eq!(c.get(10, 10), [200, 0, 0]);
        assert_eq!(c.get(16, 10), WHITE);
        c.fill_rect(0, 0, 4, 4, BLACK, 128);
        assert_eq!(c.get(1, 1), [128, 128, 128]);
        let end = c.text(12, 2, "Hi", BLACK, 1);
        assert_eq!(end, 24);
        assert_eq!(c.get(12, 2), BLACK, "top-left pixel of H");
        let mut big = Canvas::new(40, 40, [9, 9, 9]);
        big.blit(&c, 35, -5);
        assert_eq!(big.get(35, 0), c.get(0, 5));
        assert_eq!(big.get(0, 39), [9, 9, 9]);
        let png = c.to_png().unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }

    #[test]
    fn size_limits() {
        assert!(check_size(16384, 100, "x").is_ok());
        assert!(matches!(check_size(16385, 100, "x"), Err(RenderError::TooLarge(_))));
        assert!(matches!(check_size(12000, 12000, "x"), Err(RenderError::TooLarge(_))));
        assert!(matches!(check_size(0, 10, "x"), Err(RenderError::Invalid(_))));
    }
}
