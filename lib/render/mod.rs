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
pub mod raster;
pub mod sheet;

use crate::motion::Motion;
use crate::skeleton::{roles, Skeleton};
use glam::{DVec3, Vec3};

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
        let ends: Vec<(usize, DVec3)> =
            skeleton.joints.iter().enumerate().flat_map(|(j, joint)| joint.end_sites.iter().map(move |&e| (j, e))).collect();
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
    /// From +z looking along -z: +x is to the left (the creature faces the viewer when it
    /// faces +z, AnyTop's canonical facing).
    Front,
    /// From above, +z down the screen.
    Top,
    /// Yaw (degrees, about +y, 0 = `Side`) and pitch (degrees, positive looks down).
    Angle { yaw: f32, pitch: f32 },
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
}
