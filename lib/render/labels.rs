//! Colour by data: per-joint and per-frame label files, attached to tracks with one legend.
//!
//! Per-joint labels (a body part, a correspondence...) are either an object from joint name to
//! label, `{"LeftFoot": "left leg", ...}`, or a list with one label per joint in skeleton
//! order; either may sit under a `"joints"` key. Names are found as everywhere else
//! (`skeleton::lookup`), so one file can colour a source and its retarget when they share
//! names; a name that fits no track at all is an error (a typo would otherwise colour nothing).
//!
//! Per-frame labels (a segmentation...) are a list with one label per frame, the same under a
//! `"labels"` key, or `{"segments": [{"start": 0, "end": 40, "label": "walk"}, ...]}` with `end`
//! exclusive (what `mo-segment` writes). Labels are strings or numbers; `null` leaves a joint or
//! frame unlabelled. The legend lists labels in order of first appearance: joints in skeleton order,
//! then frames.

use super::{Legend, RenderError, Track};
use crate::skeleton::{lookup, Skeleton};
use serde_json::Value;

/// Joint labels as read from a file.
#[derive(Clone, Debug, PartialEq)]
pub enum JointLabels {
    /// Joint name -> label.
    ByName(Vec<(String, Option<String>)>),
    /// One label per joint, in skeleton order.
    ByIndex(Vec<Option<String>>),
}

/// Frame labels as read from a file: one per frame, or segments that say which frames.
#[derive(Clone, Debug, PartialEq)]
pub enum FrameLabels {
    PerFrame(Vec<Option<String>>),
    /// (start, end exclusive, label).
    Segments(Vec<(usize, usize, Option<String>)>),
}

fn label_text(v: &Value, file: &str, at: &str) -> Result<Option<String>, RenderError> {
    match v {
        Value::Null => Ok(None),
        Value::String(s) => Ok(Some(s.clone())),
        Value::Number(n) => Ok(Some(format!("label {n}"))),
        Value::Bool(b) => Ok(Some(b.to_string())),
        other => Err(RenderError::Invalid(format!("{file}: {at}: a label must be a string, a number or null, found {other}"))),
    }
}

/// A label file's name for messages and its text (`-` = stdin).
fn read_text(path: &std::path::Path) -> Result<(String, String), RenderError> {
    let (name, bytes) = crate::io::read_named(path).map_err(|e| RenderError::Read(format!("{e}: {}", e.source)))?;
    let text = String::from_utf8(bytes).map_err(|_| RenderError::Read(format!("{name}: not UTF-8 text")))?;
    Ok((name, text))
}

impl JointLabels {
    /// Read a joint label file: the labels and the file's name.
    pub fn read(path: &std::path::Path) -> Result<(JointLabels, String), RenderError> {
        let (name, text) = read_text(path)?;
        Ok((JointLabels::from_json(&text, &name)?, name))
    }

    /// Parse a joint label file (`file` names it in errors).
    pub fn from_json(text: &str, file: &str) -> Result<JointLabels, RenderError> {
        let value: Value = serde_json::from_str(text).map_err(|e| RenderError::Invalid(format!("{file}: not JSON: {e}")))?;
        let value = match value {
            Value::Object(mut o) if o.len() == 1 && o.contains_key("joints") => o.remove("joints").expect("checked"),
            v => v,
        };
        match value {
            Value::Object(o) => {
                let pairs = o.iter().map(|(k, v)| Ok((k.clone(), label_text(v, file, &format!("joint '{k}'"))?))).collect::<Result<Vec<_>, RenderError>>()?;
                Ok(JointLabels::ByName(pairs))
            }
            Value::Array(a) => {
                let labels = a.iter().enumerate().map(|(i, v)| label_text(v, file, &format!("entry {i}"))).collect::<Result<Vec<_>, _>>()?;
                Ok(JointLabels::ByIndex(labels))
            }
            _ => Err(RenderError::Invalid(format!("{file}: joint labels must be an object {{\"JointName\": \"label\"}} or a list with one label per joint"))),
        }
    }
}

impl FrameLabels {
    /// Segments are frames of the motions drawn (`longest` frames at most): a segment that
    /// ends past them belongs to a label file of another motion (`file` names it).
    pub fn check_fits(&self, longest: usize, file: &str) -> Result<(), RenderError> {
        if let FrameLabels::Segments(segments) = self {
            if let Some((i, (_, end, _))) = segments.iter().enumerate().find(|(_, (_, end, _))| *end > longest) {
                return Err(RenderError::Invalid(format!("{file}: segment {i} ends at frame {end}, but the longest motion has {longest} frames")));
            }
        }
        Ok(())
    }

    /// Read a frame label file: the labels and the file's name.
    pub fn read(path: &std::path::Path) -> Result<(FrameLabels, String), RenderError> {
        let (name, text) = read_text(path)?;
        Ok((FrameLabels::from_json(&text, &name)?, name))
    }

    /// Parse a frame label file (`file` names it in errors).
    pub fn from_json(text: &str, file: &str) -> Result<FrameLabels, RenderError> {
        let value: Value = serde_json::from_str(text).map_err(|e| RenderError::Invalid(format!("{file}: not JSON: {e}")))?;
        let list = |a: &[Value]| a.iter().enumerate().map(|(i, v)| label_text(v, file, &format!("frame {i}"))).collect::<Result<Vec<_>, _>>();
        match &value {
            Value::Array(a) => return Ok(FrameLabels::PerFrame(list(a)?)),
            Value::Object(o) => {
                if let Some(Value::Array(a)) = o.get("labels") {
                    return Ok(FrameLabels::PerFrame(list(a)?));
                }
                if let Some(Value::Array(segments)) = o.get("segments") {
                    let mut out = Vec::with_capacity(segments.len());
                    for (i, s) in segments.iter().enumerate() {
                        let bound = |key: &str| {
                            s.get(key)
                                .and_then(Value::as_u64)
                                .map(|v| v as usize)
                                .ok_or_else(|| RenderError::Invalid(format!("{file}: segment {i}: '{key}' must be a frame number (a non-negative integer)")))
                        };
                        let (start, end) = (bound("start")?, bound("end")?);
                        if end < start {
                            return Err(RenderError::Invalid(format!("{file}: segment {i}: end {end} is before start {start}")));
                        }
                        let label = label_text(s.get("label").unwrap_or(&Value::Null), file, &format!("segment {i}"))?;
                        out.push((start, end, label));
                    }
                    return Ok(FrameLabels::Segments(out));
                }
            }
            _ => {}
        }
        Err(RenderError::Invalid(format!(
            "{file}: frame labels must be a list with one label per frame, {{\"labels\": [...]}} or {{\"segments\": [{{\"start\", \"end\", \"label\"}}]}}"
        )))
    }
}

/// Label indices in order of first appearance.
struct Names(Vec<String>);

impl Names {
    fn index(&mut self, label: &Option<String>) -> Option<usize> {
        let label = label.as_ref()?;
        Some(match self.0.iter().position(|l| l == label) {
            Some(i) => i,
            None => {
                self.0.push(label.clone());
                self.0.len() - 1
            }
        })
    }
}

/// Attach labels to every track (`skeletons[i]` is track i's skeleton) and return the legend.
/// `frames_file` / `joints_file` name the label files in errors. Track frames are counted from
/// the first drawn frame: `first_frame` is the motion frame track frame 0 shows.
pub fn apply(
    tracks: &mut [Track],
    skeletons: &[&Skeleton],
    joints: Option<(&JointLabels, &str)>,
    frames: Option<(&FrameLabels, &str)>,
    first_frame: usize,
) -> Result<Legend, RenderError> {
    let mut names = Names(Vec::new());
    if let Some((labels, file)) = joints {
        let mut used = Vec::new();
        for (track, skeleton) in tracks.iter_mut().zip(skeletons) {
            let nj = skeleton.len();
            let mut texts: Vec<Option<String>> = vec![None; nj];
            match labels {
                JointLabels::ByIndex(list) => {
                    if list.len() != nj {
                        return Err(RenderError::Invalid(format!(
                            "{file}: {} joint labels, but {} has {nj} joints (a list needs one label per joint, in skeleton order)",
                            list.len(),
                            track.title
                        )));
                    }
                    texts.clone_from(list);
                }
                JointLabels::ByName(pairs) => {
                    for (k, (name, label)) in pairs.iter().enumerate() {
                        if let Ok(j) = lookup::find_joint(skeleton, name) {
                            texts[j].clone_from(label);
                            used.push(k);
                        }
                    }
                }
            }
            // Legend order follows the skeleton, not the file (JSON objects carry no order).
            let per_joint: Vec<Option<usize>> = texts.iter().map(|l| names.index(l)).collect();
            // End sites take their joint's colour.
            let point_labels = (0..track.points()).map(|p| if p < nj { per_joint[p] } else { track.parents[p].and_then(|j| per_joint[j]) }).collect();
            track.point_labels = Some(point_labels);
        }
        if let JointLabels::ByName(pairs) = labels {
            if let Some((name, _)) = pairs.iter().enumerate().find(|(k, _)| !used.contains(k)).map(|(_, p)| p) {
                let closest = skeletons.first().map(|s| lookup::closest_names(s, name, 5).join(", ")).unwrap_or_default();
                return Err(RenderError::Invalid(format!("{file}: no drawn skeleton has a joint named '{name}' (closest: {closest})")));
            }
        }
    }
    if let Some((labels, file)) = frames {
        for track in tracks.iter_mut() {
            let per_frame: Vec<Option<usize>> = match labels {
                FrameLabels::PerFrame(list) => {
                    if list.len() < first_frame + track.frames {
                        return Err(RenderError::Invalid(format!(
                            "{file}: {} frame labels, but {} needs {} (one per frame)",
                            list.len(),
                            track.title,
                            first_frame + track.frames
                        )));
                    }
                    list[first_frame..first_frame + track.frames].iter().map(|l| names.index(l)).collect()
                }
                FrameLabels::Segments(segments) => {
                    let mut out = vec![None; track.frames];
                    for (start, end, label) in segments {
                        let index = names.index(label);
                        for f in (*start).max(first_frame)..(*end).min(first_frame + track.frames) {
                            out[f - first_frame] = index;
                        }
                    }
                    out
                }
            };
            track.frame_labels = Some(per_frame);
        }
    }
    Ok(Legend { labels: names.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth;

    fn track() -> (Skeleton, Track) {
        let (skeleton, motion) = synth::creature("biped", 1).unwrap();
        let t = Track::from_motion("biped", &skeleton, &motion.first_frames(10));
        (skeleton, t)
    }

    #[test]
    fn joint_labels_by_name_colour_end_sites_and_reject_typos() {
        let (skeleton, mut t) = track();
        let foot = skeleton.joints.iter().position(|j| j.name.contains("Foot")).unwrap();
        let text = format!(r#"{{"joints": {{"{}": "foot", "Hips": 3}}}}"#, skeleton.joints[foot].name);
        let labels = JointLabels::from_json(&text, "l.json").unwrap();
        let legend = apply(std::slice::from_mut(&mut t), &[&skeleton], Some((&labels, "l.json")), None, 0).unwrap();
        assert_eq!(legend.labels, vec!["label 3".to_string(), "foot".to_string()]);
        let pl = t.point_labels.as_ref().unwrap();
        assert_eq!(pl[foot], Some(1));
        assert_eq!(pl[0], Some(0));
        for p in skeleton.len()..t.points() {
            assert_eq!(pl[p], pl[t.parents[p].unwrap()], "end site {p} takes its joint's label");
        }
        let typo = JointLabels::from_json(r#"{"Hipz": "x"}"#, "l.json").unwrap();
        let e = apply(std::slice::from_mut(&mut t), &[&skeleton], Some((&typo, "l.json")), None, 0).unwrap_err();
        assert!(e.to_string().contains("no drawn skeleton has a joint named 'Hipz' (closest: mixamorig:Hips"), "{e}");
    }

    #[test]
    fn frame_labels_from_segments_and_lists() {
        let (skeleton, mut t) = track();
        let seg = FrameLabels::from_json(r#"{"segments": [{"start": 0, "end": 4, "label": "walk"}, {"start": 4, "end": 99, "label": "stop"}]}"#, "s").unwrap();
        let legend = apply(std::slice::from_mut(&mut t), &[&skeleton], None, Some((&seg, "s")), 2).unwrap();
        assert_eq!(legend.labels, vec!["walk", "stop"]);
        assert_eq!(t.frame_labels.as_ref().unwrap()[..4], [Some(0), Some(0), Some(1), Some(1)]);
        let short = FrameLabels::from_json("[0, 1, null]", "f").unwrap();
        let e = apply(std::slice::from_mut(&mut t), &[&skeleton], None, Some((&short, "f")), 0).unwrap_err();
        assert!(e.to_string().contains("3 frame labels, but biped needs 10"), "{e}");
        assert!(FrameLabels::from_json(r#"{"segments": [{"start": 5, "end": 2}]}"#, "f").is_err());
        assert!(FrameLabels::from_json(r#"{"frames": 1}"#, "f").is_err());
        assert!(JointLabels::from_json("[[1]]", "j").is_err());
    }
}
