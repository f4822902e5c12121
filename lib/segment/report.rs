//! The JSON report of a segmentation, as `mo-segment` prints it and `mo-render --frame-labels`
//! reads it: one field a line, in a fixed order, so that a library caller writes the same file
//! as the tool.

use super::input::Input;
use super::{SegmentOptions, Segmentation};
use serde_json::to_string;

/// The JSON report: one key per line, values compact (a per-frame label list stays one line).
///
/// The report of `s` (a segmentation of `input` on `features` frame features, e.g. "dift", with
/// `options` and `seed`).
pub fn report(input: &Input, features: &str, options: &SegmentOptions, seed: u64, s: &Segmentation) -> Result<String, serde_json::Error> {
    let explained = (s.explained_variance * 1e6).round() / 1e6;
    let fields: Vec<(&str, String)> = vec![
        ("file", to_string(&input.name)?),
        ("frames", to_string(&input.frames)?),
        ("frame_time", to_string(&input.frame_time)?),
        ("features", to_string(features)?),
        ("k", to_string(&options.k)?),
        ("clusters", to_string(&s.clusters)?),
        ("pca_dims", to_string(&s.pca_dims)?),
        ("explained_variance", to_string(&explained)?),
        ("window_frames", to_string(&options.window)?),
        ("min_segment", to_string(&options.min_segment)?),
        ("seed", to_string(&seed)?),
        ("labels", to_string(&s.labels)?),
        ("segments", to_string(&s.segments)?),
    ];
    let mut out = String::from("{\n");
    for (i, (key, value)) in fields.iter().enumerate() {
        let comma = if i + 1 < fields.len() { "," } else { "" };
        out.push_str(&format!("  \"{key}\": {value}{comma}\n"));
    }
    out.push_str("}\n");
    Ok(out)
}
