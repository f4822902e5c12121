//! Pictures of motion: contact sheets (PNG), animations (GIF) and a self-contained HTML viewer.
//!
//! Everything here draws [`Track`]s: world-space point positions per frame, already posed by
//! our forward kinematics, with the bone structure to connect them. The renderers never see a
//! BVH or a feature tensor, so whatever `mo-render` can load (BVH, NPY + skeleton) draws the
//! same way, and the pictures show exactly the positions every other tool computes.
//!
//! Conventions: y is up; lengths are in the motion's own units (a 20 cm mouse and a 2 m human
//! both fill their frame because cameras are fitted to the points, never to a fixed size).

pub mod camera;
pub mod font;
pub mod gif;
pub mod html;
pub mod labels;
pub mod picture;
pub mod raster;
pub mod sheet;

use crate::motion::Clip;
use crate::motion::Motion;
use crate::skeleton::{roles, Skeleton};
use glam::{DVec3, Vec3};
use std::path::Path;

/// One motion, ready to draw.
#[derive(Clone, Debug)]
pub struct Track {
    /// Shown above the track (usually the file name).
    pub title: String,
    /// One entry per point: the skeleton's joints first (in skeleton order), then one point per
    /// End Site. Names of end sites are `"<joint> End"`.
    pub names: Vec<String>,
    /// Parent point of each point (`None` for roots); bones are drawn from parent to child.
    pub parents: Vec<Option<usize>>,
    /// Points that are End Sites: drawn as bone ends, without a joint dot.
    pub end_site: Vec<bool>,
    /// Foot joints (marked differently from other joints).
    pub feet: Vec<usize>,
    pub fps: f64,
    pub frames: usize,
    /// Position of point `p` at frame `f` at `[f * points + p]`.
    pub positions: Vec<Vec3>,
    /// Optional label (index into [`Legend::labels`]) of each point; colours joints and bones.
    pub point_labels: Option<Vec<Option<usize>>>,
    /// Optional label (index into [`Legend::labels`]) of each frame; tints frames.
    pub frame_labels: Option<Vec<Option<usize>>>,
}

impl Track {
    /// Pose `motion` on `skeleton` (our FK) and collect what the renderers need.
    pub fn from_motion(title: &str, skeleton: &Skeleton, motion: &Motion) -> Track {
        let pose = motion.forward_kinematics(skeleton);
        // End Site offsets are in their joint's frame.
        let ends: Vec<(usize, DVec3)> = skeleton.joints.iter().enumerate().flat_map(|(j, joint)| joint.end_sites.iter().map(move |&e| (j, e))).collect();
        let nj = skeleton.len();
        let points = nj + ends.len();
        let mut names: Vec<String> = skeleton.joints.iter().map(|j| j.name.clone()).collect();
        let mut parents: Vec<Option<usize>> = skeleton.joints.iter().map(|j| j.parent).collect();
        for &(j, _) in &ends {
            names.push(format!("{} End", skeleton.joints[j].name));
            parents.push(Some(j));
        }
        let mut end_site = vec![false; nj];
        end_site.resize(points, true);
        let mut positions = Vec::with_capacity(motion.frames * points);
        for f in 0..motion.frames {
            let base = f * nj;
            positions.extend(pose.positions[base..base + nj].iter().map(|p| p.as_vec3()));
            for &(j, offset) in &ends {
                let p: DVec3 = pose.positions[base + j] + pose.rotations[base + j] * offset;
                positions.push(p.as_vec3());
            }
        }
        let fps = if motion.frame_time > 0.0 { 1.0 / motion.frame_time } else { 30.0 };
        Track {
            title: title.to_string(),
            names,
            parents,
            end_site,
            feet: roles::feet(skeleton).0,
            fps,
            frames: motion.frames,
            positions,
            point_labels: None,
            frame_labels: None,
        }
    }

    /// Number of points (joints + end sites).
    pub fn points(&self) -> usize {
        self.parents.len()
    }

    /// The points of frame `f`.
    pub fn frame(&self, f: usize) -> &[Vec3] {
        let n = self.points();
        &self.positions[f * n..(f + 1) * n]
    }
}

/// Names of the labels that `Track::point_labels` / `frame_labels` index, in legend order.
/// Label `i` is drawn in [`palette`]`(i)`.
#[derive(Clone, Debug, Default)]
pub struct Legend {
    pub labels: Vec<String>,
}

/// Where the camera looks from. All views are orthographic and y-up on screen (except `Top`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// From the side of the motion's main horizontal direction (its principal axis of travel
    /// or, for motion in place, of the body), so walks go left to right.
    Auto,
    /// From -x looking along +x: +z is to the right.
    Side,
    /// From +z looking along -z: +x is to the right (the creature faces the viewer when it
    /// faces +z, AnyTop's canonical facing; its left side is on the viewer's right).
    Front,
    /// From above, +z down the screen.
    Top,
    /// Yaw (degrees, about +y, 0 = `Side`) and pitch (degrees, positive looks down).
    Angle { yaw: f32, pitch: f32 },
}

impl View {
    /// A view as `mo-render --view` spells it: auto, side, front, top or YAW,PITCH in degrees.
    pub fn parse(s: &str) -> Result<View, String> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(View::Auto),
            "side" => Ok(View::Side),
            "front" => Ok(View::Front),
            "top" => Ok(View::Top),
            other => {
                let (yaw, pitch) = other.split_once(',').ok_or_else(|| format!("expected auto, side, front, top or YAW,PITCH, found '{s}'"))?;
                let yaw: f32 = yaw.trim().parse().map_err(|_| format!("yaw '{yaw}' is not a number (degrees)"))?;
                let pitch: f32 = pitch.trim().parse().map_err(|_| format!("pitch '{pitch}' is not a number (degrees)"))?;
                if !yaw.is_finite() || !pitch.is_finite() || pitch.abs() > 90.0 {
                    return Err(format!("pitch must be within -90..90 degrees, found '{s}'"));
                }
                Ok(View::Angle { yaw, pitch })
            }
        }
    }
}

impl Track {
    /// Tracks of clips, each cut to frames `range` (START:END, either open), titled by file name;
    /// also the first drawn frame.
    pub fn from_clips(loaded: &[Clip], range: Option<(Option<usize>, Option<usize>)>) -> Result<(usize, Vec<Track>), String> {
        let start = range.and_then(|r| r.0).unwrap_or(0);
        let mut out = Vec::with_capacity(loaded.len());
        for l in loaded {
            let frames = l.motion.frames;
            if frames == 0 {
                return Err(format!("{}: the motion has no frames (nothing to draw)", l.name));
            }
            let end = range.and_then(|r| r.1).unwrap_or(frames).min(frames);
            if start >= end {
                return Err(format!("{}: --frames starts at frame {start} but the motion has {frames} frames (0..{})", l.name, frames - 1));
            }
            let motion = if start == 0 && end == frames { l.motion.clone() } else { l.motion.frame_range(start, end) };
            let title = Path::new(&l.name).file_name().map_or(l.name.clone(), |f| f.to_string_lossy().into_owned());
            out.push(Track::from_motion(&title, &l.skeleton, &motion));
        }
        Ok((start, out))
    }
}

/// A distinct, readable colour for label `i` (RGB), cycling after the table's end.
pub fn palette(i: usize) -> [u8; 3] {
    // Tableau-like qualitative colours, chosen to read on a light background.
    const COLOURS: [[u8; 3]; 10] = [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [214, 39, 40],
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [127, 127, 127],
        [188, 189, 34],
        [23, 190, 207],
    ];
    COLOURS[i % COLOURS.len()]
}

/// Why a picture cannot be drawn.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RenderError {
    /// Nothing to draw: no tracks, or a track without frames or points (names the track).
    #[error("{0}")]
    Empty(String),
    /// A NaN or infinite position (names the track, frame and point).
    #[error("{0}")]
    NonFinite(String),
    /// The requested picture would be unreasonably large (says how large and the limit).
    #[error("{0}")]
    TooLarge(String),
    /// Options that contradict each other or the input (a label index outside the legend...).
    #[error("{0}")]
    Invalid(String),
    /// A file that could not be read (names it and why).
    #[error("{0}")]
    Read(String),
}

/// Check tracks before drawing: something to draw, consistent lengths, finite positions and
/// label indices inside `legend`. Every renderer calls this first, so no picture is half drawn.
pub fn check(tracks: &[Track], legend: &Legend) -> Result<(), RenderError> {
    if tracks.is_empty() {
        return Err(RenderError::Empty("nothing to draw: no motion was given".into()));
    }
    for t in tracks {
        let title = &t.title;
        let n = t.points();
        if t.frames == 0 {
            return Err(RenderError::Empty(format!("{title}: the motion has no frames to draw")));
        }
        if n == 0 {
            return Err(RenderError::Empty(format!("{title}: the skeleton has no joints to draw")));
        }
        if t.names.len() != n || t.end_site.len() != n || t.positions.len() != t.frames * n {
            return Err(RenderError::Invalid(format!(
                "{title}: inconsistent track: {n} parents, {} names, {} end-site flags, {} positions for {} frames (expected {})",
                t.names.len(),
                t.end_site.len(),
                t.positions.len(),
                t.frames,
                t.frames * n
            )));
        }
        if let Some((p, parent)) = t.parents.iter().enumerate().find_map(|(p, q)| q.filter(|&q| q >= n || q == p).map(|q| (p, q))) {
            return Err(RenderError::Invalid(format!("{title}: point '{}' has parent {parent}, expected another point below {n}", t.names[p])));
        }
        if let Some(&foot) = t.feet.iter().find(|&&f| f >= n) {
            return Err(RenderError::Invalid(format!("{title}: foot {foot} is not a point (there are {n})")));
        }
        if !(t.fps.is_finite() && t.fps > 0.0) {
            return Err(RenderError::Invalid(format!("{title}: frame rate {} is not a positive number", t.fps)));
        }
        if let Some(i) = t.positions.iter().position(|p| !p.is_finite()) {
            let (f, p) = (i / n, i % n);
            return Err(RenderError::NonFinite(format!("{title}: frame {f}, point '{}': position {} is not finite", t.names[p], t.positions[i])));
        }
        let labels = legend.labels.len();
        for (what, list, expected) in [("point", &t.point_labels, n), ("frame", &t.frame_labels, t.frames)] {
            let Some(list) = list else { continue };
            if list.len() != expected {
                return Err(RenderError::Invalid(format!("{title}: {} {what} labels for {expected} {what}s", list.len())));
            }
            if let Some((k, l)) = list.iter().enumerate().find_map(|(k, l)| l.filter(|&l| l >= labels).map(|l| (k, l))) {
                return Err(RenderError::Invalid(format!("{title}: {what} {k} has label {l}, but the legend has {labels} labels")));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth;

    #[test]
    fn check_names_what_is_wrong() {
        let (skeleton, motion) = synth::creature("biped", 1).unwrap();
        let t = Track::from_motion("biped.bvh", &skeleton, &motion.first_frames(4));
        let legend = Legend { labels: vec!["a".into()] };
        assert_eq!(check(std::slice::from_ref(&t), &legend), Ok(()));
        assert!(matches!(check(&[], &legend), Err(RenderError::Empty(_))));
        let mut empty = t.clone();
        empty.frames = 0;
        empty.positions.clear();
        assert!(matches!(check(&[empty], &legend), Err(RenderError::Empty(m)) if m.contains("biped.bvh")));
        let mut bad = t.clone();
        let n = bad.points();
        bad.positions[2 * n + 3] = Vec3::new(f32::NAN, 0.0, 0.0);
        let e = check(&[bad], &legend).unwrap_err();
        assert!(matches!(&e, RenderError::NonFinite(m) if m.contains("frame 2") && m.contains(&t.names[3]) && m.contains("biped.bvh")), "{e}");
        let mut labelled = t.clone();
        labelled.frame_labels = Some(vec![Some(0), None, Some(1), None]);
        assert!(matches!(check(&[labelled], &legend), Err(RenderError::Invalid(m)) if m.contains("frame 2 has label 1")));
    }
}
