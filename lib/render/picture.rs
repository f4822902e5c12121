//! The three kinds of picture (contact sheet, GIF, HTML viewer) behind one call, with the
//! options that are spelled the same for all of them (`mo-render`'s flags), and the parsers of
//! the option values that only pictures have (frame ranges, cell sizes).

use super::camera::Framing;
use super::gif::{render_gif, GifOptions};
use super::html::{render_html, HtmlOptions};
use super::sheet::{render_sheet, SheetOptions};
use super::{Legend, RenderError, Track, View};
use std::path::Path;

/// The three kinds of picture.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    Sheet,
    Gif,
    Html,
}

/// How every picture of one run is drawn; `None` takes each kind's default.
#[derive(Clone, Copy, Debug)]
pub struct Look {
    pub view: View,
    pub framing: Framing,
    /// Sheet: every k-th frame.
    pub every: Option<usize>,
    /// Sheet: cells per row, and rows per track when `every` is not given.
    pub columns: usize,
    pub rows: usize,
    /// Size of a sheet cell or a GIF panel.
    pub size: Option<(u32, u32)>,
    /// HTML: initial playback speed, and all tracks in one scene.
    pub speed: f64,
    pub overlay: bool,
}

impl Picture {
    /// The kind a file name's extension says (.png, .gif, .html or .htm).
    pub fn of_path(p: &Path) -> Option<Picture> {
        match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "png" => Some(Picture::Sheet),
            "gif" => Some(Picture::Gif),
            "html" | "htm" => Some(Picture::Html),
            _ => None,
        }
    }

    /// `tracks` drawn as this kind of picture: PNG, GIF or HTML bytes.
    pub fn draw(self, tracks: &[Track], legend: &Legend, look: &Look) -> Result<Vec<u8>, RenderError> {
        Ok(match self {
            Picture::Sheet => {
                let mut o = SheetOptions { view: look.view, framing: look.framing, columns: look.columns, max_rows: look.rows, ..SheetOptions::default() };
                if let Some(k) = look.every {
                    o.every = k;
                }
                if let Some((w, h)) = look.size {
                    o.cell_width = w;
                    o.cell_height = h;
                }
                render_sheet(tracks, legend, &o)?
            }
            Picture::Gif => {
                let mut o = GifOptions { view: look.view, framing: look.framing, ..GifOptions::default() };
                if let Some((w, h)) = look.size {
                    o.panel_width = w;
                    o.panel_height = h;
                }
                render_gif(tracks, legend, &o)?
            }
            Picture::Html => {
                let title = tracks.iter().map(|t| t.title.as_str()).collect::<Vec<_>>().join(" | ");
                let o = HtmlOptions { title, speed: look.speed, overlay: look.overlay, ..HtmlOptions::default() };
                render_html(tracks, legend, &o)?.into_bytes()
            }
        })
    }
}

/// Frames `START:END`, END exclusive, either omitted ('100:', ':50').
pub fn parse_range(s: &str) -> Result<(Option<usize>, Option<usize>), String> {
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

/// A picture size `WIDTHxHEIGHT`, each within 32..4096 pixels.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) =
        s.to_ascii_lowercase().split_once('x').map(|(a, b)| (a.to_string(), b.to_string())).ok_or_else(|| format!("expected WIDTHxHEIGHT, found '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("width '{w}' is not a whole number"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("height '{h}' is not a whole number"))?;
    if !(32..=4096).contains(&w) || !(32..=4096).contains(&h) {
        return Err(format!("sizes must be within 32..4096 pixels, found {w}x{h}"));
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn option_values() {
        assert_eq!(parse_range("10:20"), Ok((Some(10), Some(20))));
        assert_eq!(parse_range("100:"), Ok((Some(100), None)));
        assert_eq!(parse_range(":50"), Ok((None, Some(50))));
        assert!(parse_range("5:5").unwrap_err().contains("is empty"));
        assert!(parse_range("5").is_err() && parse_range("a:3").is_err());
        assert_eq!(parse_size("160X120"), Ok((160, 120)));
        assert!(parse_size("16x16").unwrap_err().contains("32..4096"));
        assert!(parse_size("160").is_err() && parse_size("ax10").is_err());
        assert_eq!(Picture::of_path(Path::new("a/b.PNG")), Some(Picture::Sheet));
        assert_eq!(Picture::of_path(Path::new("v.htm")), Some(Picture::Html));
        assert_eq!(Picture::of_path(Path::new("walk.gif")), Some(Picture::Gif));
        assert_eq!(Picture::of_path(Path::new("out.bvh")), None);
    }
}
