//! The placement file: where each encoded clip stood, which AnyTop's features leave out.
//!
//! `mo-encode --placement` writes it when encoding and reads it when decoding, so a decoded
//! clip goes back where it was; it is JSON so that people and scripts can read and edit it.

use super::Placement;

/// One clip's placement as written (the file name is for readers; decoding ignores it).
#[derive(serde::Serialize)]
struct Entry<'a> {
    file: &'a str,
    #[serde(flatten)]
    placement: &'a Placement,
}

/// A JSON list, one clip per line, named by `files`.
pub fn to_json<'a>(files: impl IntoIterator<Item = &'a str>, placements: &[Placement]) -> Result<String, serde_json::Error> {
    let lines =
        files.into_iter().zip(placements).map(|(file, placement)| serde_json::to_string(&Entry { file, placement })).collect::<Result<Vec<String>, _>>()?;
    Ok(format!("[\n  {}\n]\n", lines.join(",\n  ")))
}

/// What a placement file holds: a list (from `to_json`), or one placement.
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum PlacementFile {
    List(Vec<Placement>),
    One(Placement),
}

/// One placement per sample from the placement file at `path` (`-` = stdin): `from_json`.
pub fn read(path: &std::path::Path, samples: usize, npy_name: &str) -> Result<Vec<Placement>, String> {
    let name = crate::io::display_name(path);
    let bytes = crate::io::read_input(path).map_err(|e| format!("cannot read placements {name}: {e}"))?;
    from_json(&bytes, &name, samples, npy_name)
}

/// One placement per sample from the bytes of a placement file (`name`, for messages), which
/// must hold `samples` of them (the samples of `npy_name`).
pub fn from_json(bytes: &[u8], name: &str, samples: usize, npy_name: &str) -> Result<Vec<Placement>, String> {
    // JSON first, so a syntax error keeps its line and column (an untagged enum's error has none).
    let value: serde_json::Value = serde_json::from_slice(bytes).map_err(|e| format!("{name}: not a placement file (not JSON): {e}"))?;
    let placements = match serde_json::from_value::<PlacementFile>(value) {
        Ok(PlacementFile::List(list)) => list,
        Ok(PlacementFile::One(one)) => vec![one],
        Err(e) => return Err(format!("{name}: not a placement file (a JSON list of {{\"heading\", \"root_xz\"}} as mo-encode --placement writes): {e}")),
    };
    if let Some(i) = placements.iter().position(|p| !(p.heading.is_finite() && p.root_xz.iter().all(|v| v.is_finite()))) {
        return Err(format!("{name}: placement {i} holds a non-finite number"));
    }
    if placements.len() != samples {
        return Err(format!("{name} holds {} placement(s) but {npy_name} holds {samples} sample(s)", placements.len()));
    }
    Ok(placements)
}
