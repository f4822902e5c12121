//! The 32 boolean geometric ("manual") features of Müller et al., as AIST++/Bailando and
//! Motion2Motion's `utils/features/manual_new.py` compute them (`docs/reference/motion2motion.md`
//! §3.7): per frame, 32 relations between body parts (a hand in front of the body, a knee
//! bent, a foot raised, a joint moving fast ...), averaged over frames into "fraction of frames
//! true". FID over these vectors is Motion2Motion's FID_g.
//!
//! The reference hard-wires SMPL joint order; we find the 18 SMPL roles the features use by
//! name and structure on any human-like skeleton ([`human_roles`]). Deviations (also in
//! `docs/metrics.md`): thresholds come from the clip's own humerus length, shoulder
//! width and hip width (the reference uses SMPL constants in metres), velocities use the clip's
//! frame rate (the reference uses a fixed 1/120 s), and a degenerate direction makes a relation
//! false instead of NaN.

use super::physics::{check_clip, joint_name};
use super::{MetricError, WorldClip};
use crate::skeleton::names::{self, Side};
use glam::DVec3;

/// Joints of the 18 SMPL roles the 32 features use (indices into the clip's joints).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct HumanRoles {
    /// Pelvis: where the two legs branch.
    pub root: usize,
    /// First spine joint above the pelvis (SMPL `spine1`).
    pub belly: usize,
    /// Where the two arms branch (SMPL `spine3`).
    pub chest: usize,
    pub neck: usize,
    pub left_hip: usize,
    pub right_hip: usize,
    pub left_knee: usize,
    pub right_knee: usize,
    pub left_ankle: usize,
    pub right_ankle: usize,
    pub left_toes: usize,
    pub right_toes: usize,
    /// The upper-arm joint (whose child is the elbow), not a clavicle.
    pub left_shoulder: usize,
    pub right_shoulder: usize,
    pub left_elbow: usize,
    pub right_elbow: usize,
    pub left_wrist: usize,
    pub right_wrist: usize,
}

/// Normalised names (side word removed) that mark a knee / an elbow. The hip and shoulder are
/// their parents, so `LeftUpLeg`/`Left Thigh`/`UpperLeg_L` and Mixamo's `LeftArm` (whose parent
/// `LeftShoulder` is a clavicle) need no list.
const KNEE: &[&str] = &["Knee", "Leg", "Calf", "Shin", "Lower Leg", "Low Leg", "Lo Leg", "Leg Lower", "Lowerleg"];
const ELBOW: &[&str] = &["Elbow", "Fore Arm", "Forearm", "Lower Arm", "Low Arm", "Lo Arm", "Arm Lower", "Lowerarm"];
const ANKLE: &[&str] = &["Foot", "Ankle"];
const WRIST: &[&str] = &["Hand", "Wrist"];

/// How far below a knee / elbow the ankle / wrist name may hang (twist or roll joints between).
const SEARCH_DEPTH: usize = 2;

/// The role joints of a human-like skeleton, from normalised names and sides
/// (`skeleton::names`): knees and elbows by name, hips and shoulders as their parents, ankles,
/// toes and wrists as named descendants (else the first child), the pelvis and chest where the
/// legs and arms branch, the belly as the first joint above the pelvis towards the chest, the
/// neck by name (else the parent of the head). Sides come from names, inherited by unnamed
/// descendants. `Err` says which role is missing.
pub fn human_roles(clip: &WorldClip) -> Result<HumanRoles, String> {
    let n = clip.joints;
    if clip.parents.len() != n || clip.names.len() != n {
        return Err(format!("the clip has {n} joints but {} parents and {} names", clip.parents.len(), clip.names.len()));
    }
    if let Some(j) = (0..n).find(|&j| clip.parents[j].is_some_and(|p| p >= j)) {
        return Err(format!("joint {j} does not come after its parent"));
    }
    let normalised: Vec<String> = clip.names.iter().map(|s| names::normalise(s)).collect();
    let mut sides = vec![Side::Centre; n];
    for j in 0..n {
        sides[j] = names::side_from_name(&normalised[j]).unwrap_or_else(|| clip.parents[j].map_or(Side::Centre, |p| sides[p]));
    }
    // The name without its side word: "Left Fore Arm" -> "Fore Arm".
    let part: Vec<&str> = normalised.iter().map(|s| s.strip_prefix("Left ").or_else(|| s.strip_prefix("Right ")).unwrap_or(s.as_str())).collect();
    let children = {
        let mut c = vec![Vec::new(); n];
        for (j, p) in clip.parents.iter().enumerate() {
            if let Some(p) = p {
                c[*p].push(j);
            }
        }
        c
    };
    let side_word = |s: Side| if s == Side::Left { "left" } else { "right" };
    let named = |s: Side, words: &[&str], role: &str| -> Result<usize, String> {
        (0..n).find(|&j| sides[j] == s && words.contains(&part[j])).ok_or_else(|| {
            format!("no {} {role}: no joint on that side is named like {}", side_word(s), words.iter().map(|w| format!("'{w}'")).collect::<Vec<_>>().join(", "))
        })
    };
    // A descendant within SEARCH_DEPTH named by `test`, else the first child.
    let below = |from: usize, test: &dyn Fn(&str) -> bool, role: &str, s: Side| -> Result<usize, String> {
        let mut level = vec![from];
        for _ in 0..SEARCH_DEPTH {
            level = level.iter().flat_map(|&j| children[j].iter().copied()).collect();
            if let Some(&j) = level.iter().find(|&&j| test(part[j])) {
                return Ok(j);
            }
        }
        children[from].first().copied().ok_or_else(|| format!("no {} {role}: joint '{}' has no child joint", side_word(s), clip.names[from]))
    };
    let parent = |j: usize, role: &str, s: Side| -> Result<usize, String> {
        clip.parents[j].ok_or_else(|| format!("no {} {role}: '{}' is the root", side_word(s), clip.names[j]))
    };
    let mut limbs = Vec::new();
    for s in [Side::Left, Side::Right] {
        let knee = named(s, KNEE, "knee")?;
        let hip = parent(knee, "hip", s)?;
        let ankle = below(knee, &|p| ANKLE.contains(&p), "ankle", s)?;
        let toes = below(ankle, &|p| p.starts_with("Toe"), "toes", s)?;
        let elbow = named(s, ELBOW, "elbow")?;
        let shoulder = parent(elbow, "shoulder", s)?;
        let wrist = below(elbow, &|p| WRIST.contains(&p), "wrist", s)?;
        limbs.push([hip, knee, ankle, toes, shoulder, elbow, wrist]);
    }
    let [lh, lk, la, lt, ls, le, lw] = limbs[0];
    let [rh, rk, ra, rt, rs, re, rw] = limbs[1];
    let ancestors = |mut j: usize| {
        let mut out = vec![j];
        while let Some(p) = clip.parents[j] {
            out.push(p);
            j = p;
        }
        out
    };
    let lca = |a: usize, b: usize| {
        let up = ancestors(b);
        ancestors(a).into_iter().find(|j| up.contains(j))
    };
    let root = lca(lh, rh).ok_or("no pelvis: the two hips are in different trees")?;
    let chest = lca(ls, rs).ok_or("no chest: the two shoulders are in different trees")?;
    // Path chest -> root; the belly is the joint on it just above the root.
    let path = ancestors(chest);
    let at = path
        .iter()
        .position(|&j| j == root)
        .ok_or_else(|| format!("no spine: the arms branch at '{}', which is not above the pelvis '{}'", clip.names[chest], clip.names[root]))?;
    if at == 0 {
        return Err(format!("no spine: the arms and legs branch at the same joint '{}'", clip.names[root]));
    }
    let belly = path[at - 1];
    let neck = (0..n)
        .find(|&j| sides[j] == Side::Centre && part[j] == "Neck")
        .or_else(|| (0..n).find(|&j| sides[j] == Side::Centre && part[j] == "Head").and_then(|h| clip.parents[h]))
        .ok_or("no neck: no centre joint is named 'Neck', nor 'Head' with a parent")?;
    Ok(HumanRoles {
        root,
        belly,
        chest,
        neck,
        left_hip: lh,
        right_hip: rh,
        left_knee: lk,
        right_knee: rk,
        left_ankle: la,
        right_ankle: ra,
        left_toes: lt,
        right_toes: rt,
        left_shoulder: ls,
        right_shoulder: rs,
        left_elbow: le,
        right_elbow: re,
        left_wrist: lw,
        right_wrist: rw,
    })
}

/// The body lengths thresholds are multiples of (Müller's humerus length `hl`, shoulder
/// width `sw`, hip width `hw`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyLengths {
    /// Measured on the clip, averaged over frames: shoulder-elbow (both sides), shoulder-
    /// shoulder and hip-hip distances. Scales with the body, whatever the units.
    Measured,
    /// Given in clip units (the reference's `manual_new.py` uses hl 0.256838, sw 0.390848,
    /// hw 0.119247 metres for SMPL).
    Fixed { humerus: f64, shoulder_width: f64, hip_width: f64 },
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GeometricOptions {
    pub lengths: BodyLengths,
    /// Frame rate for the velocity relations; `None` uses the clip's. The reference uses 120
    /// whatever the data (so its velocities are twice the real ones on 60 fps AIST++).
    pub velocity_fps: Option<f64>,
}

impl Default for GeometricOptions {
    fn default() -> Self {
        GeometricOptions { lengths: BodyLengths::Measured, velocity_fps: None }
    }
}

/// The measured (or given) body lengths, in clip units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Lengths {
    pub humerus: f64,
    pub shoulder_width: f64,
    pub hip_width: f64,
}

/// A point of a relation: a role joint or one of the reference's pseudo-joints.
#[derive(Clone, Copy)]
enum Pt {
    Root,
    Belly,
    Chest,
    Neck,
    LHip,
    RHip,
    LKnee,
    RKnee,
    LAnkle,
    RAnkle,
    LToes,
    RToes,
    LShoulder,
    RShoulder,
    LElbow,
    RElbow,
    LWrist,
    RWrist,
    /// (0, 0, 0)
    Zero,
    /// (0, 1, 0)
    Up,
    /// (0, -1, 0)
    Down,
    /// (0, lowest y of the frame over all joints, 0)
    YMin,
}

/// A threshold as a multiple of a body length.
#[derive(Clone, Copy)]
enum Th {
    Hl(f64),
    Sw(f64),
    Hw(f64),
}

/// The reference's relations (`docs/reference/motion2motion.md` §3.7).
#[derive(Clone, Copy)]
enum Rel {
    /// Velocity of c relative to a, along a->b, above the threshold (d is ignored, as in the
    /// reference).
    Move(Pt, Pt, Pt, Th),
    /// Velocity of d relative to a, along the normal (c-a)x(b-a), above the threshold.
    NMove(Pt, Pt, Pt, Pt, Th),
    /// Distance of d from the plane through a with normal (c-a)x(b-a), above the threshold.
    Plane(Pt, Pt, Pt, Pt, Th),
    /// Distance of d from the plane through c with normal b-a, above the threshold.
    NPlane(Pt, Pt, Pt, Pt, Th),
    /// Angle between b-a and d-c strictly between the two bounds (degrees).
    Angle(Pt, Pt, Pt, Pt, f64, f64),
    /// Speed of a above the threshold.
    Fast(Pt, Th),
}

use Pt::*;
use Rel::*;

/// The 32 features in the reference's order.
const FEATURES: [Rel; 32] = [
    NMove(Neck, RHip, LHip, RWrist, Th::Hl(1.8)),
    NMove(Neck, LHip, RHip, LWrist, Th::Hl(1.8)),
    NPlane(Chest, Neck, Neck, RWrist, Th::Hl(0.2)),
    NPlane(Chest, Neck, Neck, LWrist, Th::Hl(0.2)),
    Move(Belly, Chest, Chest, Th::Hl(1.8)),
    Move(Belly, Chest, Chest, Th::Hl(1.8)),
    Angle(RElbow, RShoulder, RElbow, RWrist, 0.0, 110.0),
    Angle(LElbow, LShoulder, LElbow, LWrist, 0.0, 110.0),
    NPlane(LShoulder, RShoulder, LWrist, RWrist, Th::Sw(2.5)),
    Move(LWrist, RWrist, RWrist, Th::Hl(1.4)),
    Move(RWrist, Root, LWrist, Th::Hl(1.4)),
    Move(LWrist, Root, RWrist, Th::Hl(1.4)),
    Fast(RWrist, Th::Hl(2.5)),
    Fast(LWrist, Th::Hl(2.5)),
    Plane(Root, LHip, LToes, RAnkle, Th::Hl(0.38)),
    Plane(Root, RHip, RToes, LAnkle, Th::Hl(0.38)),
    NPlane(Zero, Up, YMin, RAnkle, Th::Hl(1.2)),
    NPlane(Zero, Up, YMin, LAnkle, Th::Hl(1.2)),
    NPlane(LHip, RHip, LAnkle, RAnkle, Th::Hw(2.1)),
    Angle(RKnee, RHip, RKnee, RAnkle, 0.0, 110.0),
    Angle(LKnee, LHip, LKnee, LAnkle, 0.0, 110.0),
    Fast(RAnkle, Th::Hl(2.5)),
    Fast(LAnkle, Th::Hl(2.5)),
    Angle(Neck, Root, RShoulder, RElbow, 25.0, 180.0),
    Angle(Neck, Root, LShoulder, LElbow, 25.0, 180.0),
    Angle(Neck, Root, RHip, RKnee, 50.0, 180.0),
    Angle(Neck, Root, LHip, LKnee, 50.0, 180.0),
    Plane(RAnkle, Neck, LAnkle, Root, Th::Hl(0.5)),
    Angle(Neck, Root, Zero, Up, 70.0, 110.0),
    NPlane(Zero, Down, YMin, RWrist, Th::Hl(-1.2)),
    NPlane(Zero, Down, YMin, LWrist, Th::Hl(-1.2)),
    Fast(Root, Th::Hl(2.3)),
];

/// Names of the 32 features, in order: the reference's relation and threshold (for tables and
/// JSON). `docs/metrics.md` says what each measures.
pub const FEATURE_NAMES: [&str; 32] = [
    "(1) nmove(neck,rhip,lhip,rwrist; 1.8hl)",
    "(2) nmove(neck,lhip,rhip,lwrist; 1.8hl)",
    "(3) nplane(chest,neck,neck,rwrist; 0.2hl)",
    "(4) nplane(chest,neck,neck,lwrist; 0.2hl)",
    "(5) move(belly,chest,chest,rwrist; 1.8hl)",
    "(6) move(belly,chest,chest,lwrist; 1.8hl)",
    "(7) angle(relbow,rshoulder,relbow,rwrist; 0-110)",
    "(8) angle(lelbow,lshoulder,lelbow,lwrist; 0-110)",
    "(9) nplane(lshoulder,rshoulder,lwrist,rwrist; 2.5sw)",
    "(10) move(lwrist,rwrist,rwrist,lwrist; 1.4hl)",
    "(11) move(rwrist,root,lwrist,root; 1.4hl)",
    "(12) move(lwrist,root,rwrist,root; 1.4hl)",
    "(13) fast(rwrist; 2.5hl)",
    "(14) fast(lwrist; 2.5hl)",
    "(15) plane(root,lhip,ltoes,rankle; 0.38hl)",
    "(16) plane(root,rhip,rtoes,lankle; 0.38hl)",
    "(17) nplane(zero,y_unit,y_min,rankle; 1.2hl)",
    "(18) nplane(zero,y_unit,y_min,lankle; 1.2hl)",
    "(19) nplane(lhip,rhip,lankle,rankle; 2.1hw)",
    "(20) angle(rknee,rhip,rknee,rankle; 0-110)",
    "(21) angle(lknee,lhip,lknee,lankle; 0-110)",
    "(22) fast(rankle; 2.5hl)",
    "(23) fast(lankle; 2.5hl)",
    "(24) angle(neck,root,rshoulder,relbow; 25-180)",
    "(25) angle(neck,root,lshoulder,lelbow; 25-180)",
    "(26) angle(neck,root,rhip,rknee; 50-180)",
    "(27) angle(neck,root,lhip,lknee; 50-180)",
    "(28) plane(rankle,neck,lankle,root; 0.5hl)",
    "(29) angle(neck,root,zero,y_unit; 70-110)",
    "(30) nplane(zero,minus_y_unit,y_min,rwrist; -1.2hl)",
    "(31) nplane(zero,minus_y_unit,y_min,lwrist; -1.2hl)",
    "(32) fast(root; 2.3hl)",
];

impl HumanRoles {
    fn joint(&self, p: Pt) -> Option<usize> {
        Some(match p {
            Root => self.root,
            Belly => self.belly,
            Chest => self.chest,
            Neck => self.neck,
            LHip => self.left_hip,
            RHip => self.right_hip,
            LKnee => self.left_knee,
            RKnee => self.right_knee,
            LAnkle => self.left_ankle,
            RAnkle => self.right_ankle,
            LToes => self.left_toes,
            RToes => self.right_toes,
            LShoulder => self.left_shoulder,
            RShoulder => self.right_shoulder,
            LElbow => self.left_elbow,
            RElbow => self.right_elbow,
            LWrist => self.left_wrist,
            RWrist => self.right_wrist,
            Zero | Up | Down | YMin => return None,
        })
    }

    fn all(&self) -> [usize; 18] {
        [
            self.root,
            self.belly,
            self.chest,
            self.neck,
            self.left_hip,
            self.right_hip,
            self.left_knee,
            self.right_knee,
            self.left_ankle,
            self.right_ankle,
            self.left_toes,
            self.right_toes,
            self.left_shoulder,
            self.right_shoulder,
            self.left_elbow,
            self.right_elbow,
            self.left_wrist,
            self.right_wrist,
        ]
    }
}

/// The body lengths `opts` asks for (measured on the clip, or given).
pub fn body_lengths(clip: &WorldClip, roles: &HumanRoles, opts: &GeometricOptions) -> Lengths {
    match opts.lengths {
        BodyLengths::Fixed { humerus, shoulder_width, hip_width } => Lengths { humerus, shoulder_width, hip_width },
        BodyLengths::Measured => {
            let mean = |d: &dyn Fn(usize) -> f64| (0..clip.frames).map(d).sum::<f64>() / clip.frames.max(1) as f64;
            let dist = |f: usize, a: usize, b: usize| clip.at(f, a).distance(clip.at(f, b));
            Lengths {
                humerus: mean(&|f| 0.5 * (dist(f, roles.left_shoulder, roles.left_elbow) + dist(f, roles.right_shoulder, roles.right_elbow))),
                shoulder_width: mean(&|f| dist(f, roles.left_shoulder, roles.right_shoulder)),
                hip_width: mean(&|f| dist(f, roles.left_hip, roles.right_hip)),
            }
        }
    }
}

/// Unit vector or `None` for a degenerate one (the relation is then false).
fn unit(v: DVec3) -> Option<DVec3> {
    let l = v.length();
    (l > 1e-12 && l.is_finite()).then(|| v / l)
}

/// The 32 feature values, each the fraction of frames 1..T-1 on which the relation holds
/// (velocities from frame f-1 to f). Needs 2 frames, finite input, roles inside the clip and
/// body lengths that are positive.
pub fn geometric_features(clip: &WorldClip, roles: &HumanRoles, opts: &GeometricOptions) -> Result<Vec<f64>, MetricError> {
    check_clip(clip, 2, "geometric features")?;
    if let Some(j) = roles.all().into_iter().find(|&j| j >= clip.joints) {
        return Err(MetricError::Mismatch(format!("geometric features: role joint {j} is outside the clip's {} joints", clip.joints)));
    }
    let fps = opts.velocity_fps.unwrap_or(clip.fps);
    if !fps.is_finite() || fps <= 0.0 {
        return Err(MetricError::NonFinite(format!("geometric features: velocity frame rate must be positive and finite, found {fps}")));
    }
    let lengths = body_lengths(clip, roles, opts);
    for (what, v) in [("humerus length", lengths.humerus), ("shoulder width", lengths.shoulder_width), ("hip width", lengths.hip_width)] {
        if !v.is_finite() || v <= 1e-9 * clip.scale {
            return Err(MetricError::Mismatch(format!(
                "geometric features: the {what} is {v} (shoulders {}/{}, elbows {}/{}, hips {}/{}): thresholds would be meaningless",
                joint_name(clip, roles.left_shoulder),
                joint_name(clip, roles.right_shoulder),
                joint_name(clip, roles.left_elbow),
                joint_name(clip, roles.right_elbow),
                joint_name(clip, roles.left_hip),
                joint_name(clip, roles.right_hip)
            )));
        }
    }
    let threshold = |t: Th| match t {
        Th::Hl(k) => k * lengths.humerus,
        Th::Sw(k) => k * lengths.shoulder_width,
        Th::Hw(k) => k * lengths.hip_width,
    };
    let mut counts = [0usize; 32];
    for f in 1..clip.frames {
        let y_min = |f: usize| clip.frame(f).iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        let at = |p: Pt, f: usize| match roles.joint(p) {
            Some(j) => clip.at(f, j),
            None => match p {
                Up => DVec3::Y,
                Down => DVec3::NEG_Y,
                YMin => DVec3::new(0.0, y_min(f), 0.0),
                _ => DVec3::ZERO,
            },
        };
        let now = |p: Pt| at(p, f);
        let relative_velocity = |p: Pt, base: Pt| ((now(p) - now(base)) - (at(p, f - 1) - at(base, f - 1))) * fps;
        for (k, rel) in FEATURES.iter().enumerate() {
            let holds = match *rel {
                Move(a, b, c, t) => unit(now(b) - now(a)).is_some_and(|d| relative_velocity(c, a).dot(d) > threshold(t)),
                NMove(a, b, c, d, t) => unit((now(c) - now(a)).cross(now(b) - now(a))).is_some_and(|n| relative_velocity(d, a).dot(n) > threshold(t)),
                Plane(a, b, c, d, t) => unit((now(c) - now(a)).cross(now(b) - now(a))).is_some_and(|n| (now(d) - now(a)).dot(n) > threshold(t)),
                NPlane(a, b, c, d, t) => unit(now(b) - now(a)).is_some_and(|n| (now(d) - now(c)).dot(n) > threshold(t)),
                Angle(a, b, c, d, lo, hi) => match (unit(now(b) - now(a)), unit(now(d) - now(c))) {
                    (Some(u), Some(v)) => {
                        let deg = u.dot(v).clamp(-1.0, 1.0).acos().to_degrees();
                        lo < deg && deg < hi
                    }
                    _ => false,
                },
                Fast(a, t) => (now(a) - at(a, f - 1)).length() * fps > threshold(t),
            };
            counts[k] += usize::from(holds);
        }
    }
    let steps = (clip.frames - 1) as f64;
    Ok(counts.iter().map(|&c| c as f64 / steps).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small human in the SMPL layout (y up, facing +z, left at +x), Mixamo-style names.
    /// Returns the clip (one frame per pose) and the expected roles by name.
    pub(crate) fn human(poses: &[Vec<DVec3>], fps: f64) -> WorldClip {
        let joints = skeleton_joints();
        let n = joints.len();
        let mut positions = Vec::new();
        for p in poses {
            assert_eq!(p.len(), n);
            positions.extend_from_slice(p);
        }
        WorldClip {
            frames: poses.len(),
            joints: n,
            fps,
            positions,
            parents: joints.iter().map(|j| j.1).collect(),
            names: joints.iter().map(|j| j.0.to_string()).collect(),
            feet: vec![],
            scale: 1.7,
        }
    }

    fn skeleton_joints() -> Vec<(&'static str, Option<usize>, DVec3)> {
        // name, parent, rest position (metres)
        vec![
            ("Hips", None, DVec3::new(0.0, 1.0, 0.0)),                 // 0
            ("LeftUpLeg", Some(0), DVec3::new(0.1, 0.95, 0.0)),        // 1
            ("LeftLeg", Some(1), DVec3::new(0.1, 0.5, 0.0)),           // 2
            ("LeftFoot", Some(2), DVec3::new(0.1, 0.08, 0.0)),         // 3
            ("LeftToeBase", Some(3), DVec3::new(0.1, 0.0, 0.12)),      // 4
            ("RightUpLeg", Some(0), DVec3::new(-0.1, 0.95, 0.0)),      // 5
            ("RightLeg", Some(5), DVec3::new(-0.1, 0.5, 0.0)),         // 6
            ("RightFoot", Some(6), DVec3::new(-0.1, 0.08, 0.0)),       // 7
            ("RightToeBase", Some(7), DVec3::new(-0.1, 0.0, 0.12)),    // 8
            ("Spine", Some(0), DVec3::new(0.0, 1.15, 0.0)),            // 9
            ("Spine1", Some(9), DVec3::new(0.0, 1.35, 0.0)),           // 10
            ("Neck", Some(10), DVec3::new(0.0, 1.5, 0.0)),             // 11
            ("Head", Some(11), DVec3::new(0.0, 1.65, 0.0)),            // 12
            ("LeftShoulder", Some(10), DVec3::new(0.08, 1.45, 0.0)),   // 13
            ("LeftArm", Some(13), DVec3::new(0.2, 1.45, 0.0)),         // 14
            ("LeftForeArm", Some(14), DVec3::new(0.45, 1.45, 0.0)),    // 15
            ("LeftHand", Some(15), DVec3::new(0.7, 1.45, 0.0)),        // 16
            ("RightShoulder", Some(10), DVec3::new(-0.08, 1.45, 0.0)), // 17
            ("RightArm", Some(17), DVec3::new(-0.2, 1.45, 0.0)),       // 18
            ("RightForeArm", Some(18), DVec3::new(-0.45, 1.45, 0.0)),  // 19
            ("RightHand", Some(19), DVec3::new(-0.7, 1.45, 0.0)),      // 20
        ]
    }

    pub(crate) fn rest_pose() -> Vec<DVec3> {
        skeleton_joints().iter().map(|j| j.2).collect()
    }

    #[test]
    fn roles_of_a_mixamo_style_human() {
        let clip = human(&[rest_pose()], 30.0);
        let r = human_roles(&clip).unwrap();
        let name = |j: usize| clip.names[j].as_str();
        assert_eq!([r.root, r.belly, r.chest, r.neck].map(name), ["Hips", "Spine", "Spine1", "Neck"]);
        assert_eq!([r.left_hip, r.left_knee, r.left_ankle, r.left_toes].map(name), ["LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase"]);
        assert_eq!([r.right_shoulder, r.right_elbow, r.right_wrist].map(name), ["RightArm", "RightForeArm", "RightHand"]);
    }

    #[test]
    fn roles_of_bip01_and_cmu_spellings() {
        let mut clip = human(&[rest_pose()], 30.0);
        let renames = [
            (1, "Bip01_L_Thigh"),
            (2, "Bip01_L_Calf"),
            (3, "Bip01_L_Foot"),
            (4, "Bip01_L_Toe0"),
            (14, "LeftShoulder"),
            (13, "LeftCollar"),
            (15, "LeftElbow"),
            (16, "LeftWrist"),
        ];
        for (j, s) in renames {
            clip.names[j] = s.into();
        }
        let r = human_roles(&clip).unwrap();
        assert_eq!((r.left_hip, r.left_knee, r.left_ankle, r.left_toes), (1, 2, 3, 4));
        assert_eq!((r.left_shoulder, r.left_elbow, r.left_wrist), (14, 15, 16));
    }

    #[test]
    fn a_missing_role_is_named() {
        let mut clip = human(&[rest_pose()], 30.0);
        clip.names[19] = "RightThing".into();
        let e = human_roles(&clip).unwrap_err();
        assert!(e.contains("no right elbow"), "{e}");
        let mut clip = human(&[rest_pose()], 30.0);
        clip.names[11] = "Collar".into();
        clip.names[12] = "Skull".into();
        assert!(human_roles(&clip).unwrap_err().contains("no neck"));
    }

    #[test]
    fn rest_pose_features_by_hand() {
        let clip = human(&[rest_pose(), rest_pose(), rest_pose()], 30.0);
        let roles = human_roles(&clip).unwrap();
        let g = geometric_features(&clip, &roles, &GeometricOptions::default()).unwrap();
        assert_eq!(g.len(), 32);
        // Standing still in a T-pose: nothing moves, arms straight (180°, not in (0, 110)),
        // legs straight, torso vertical (angle 180° from up: not horizontal).
        for k in [0, 1, 4, 5, 6, 7, 9, 10, 11, 12, 13, 19, 20, 21, 22, 28, 31] {
            assert_eq!(g[k], 0.0, "feature {k} ({})", FEATURE_NAMES[k]);
        }
        // Arms out sideways: 90° from the neck->root direction, so "raised" (> 25°); legs
        // hang along it (0°), not raised. Wrists 1.45 above the lowest joint, hl = 0.25:
        // far above 1.2 hl, so not low. Hands 1.4 apart vs 2.5 sw = 2.5 x 0.4 = 1.0:
        // nplane(ls, rs, lw, rw) = (rw - lw) . (rs - ls)/|..| = 1.4 > 1.0 -> true.
        assert_eq!((g[23], g[24], g[25], g[26]), (1.0, 1.0, 0.0, 0.0));
        assert_eq!((g[29], g[30]), (0.0, 0.0));
        assert_eq!(g[8], 1.0);
        // Ankles 0.08 above the lowest joint (the toes), far below 1.2 hl: not raised.
        assert_eq!((g[16], g[17]), (0.0, 0.0));
    }

    #[test]
    fn raising_a_foot_and_moving_fast_switch_features_on() {
        let still = rest_pose();
        let mut lifted = rest_pose();
        // Left ankle (3) and toes (4) up 0.5: above 1.2 hl = 0.3 over the lowest joint.
        lifted[3].y += 0.5;
        lifted[4].y += 0.5;
        let clip = human(&[still.clone(), still, lifted], 10.0);
        let roles = human_roles(&clip).unwrap();
        let g = geometric_features(&clip, &roles, &GeometricOptions::default()).unwrap();
        // Frame 2 only (of frames 1..=2): left foot raised; its 0.5 in 0.1 s = 5 units/s
        // beats 2.5 hl = 0.625 units/s: left foot fast.
        assert_eq!(g[17], 0.5);
        assert_eq!(g[22], 0.5);
        assert_eq!(g[16], 0.0);
        // With the reference's fixed 120 fps the same step is faster still; with a slow
        // 1 fps the ankle moves 0.5 units/s < 0.625: not fast.
        let slow = geometric_features(&clip, &roles, &GeometricOptions { velocity_fps: Some(1.0), ..Default::default() }).unwrap();
        assert_eq!(slow[22], 0.0);
    }

    #[test]
    fn measured_lengths_and_bad_input() {
        let clip = human(&[rest_pose(), rest_pose()], 30.0);
        let roles = human_roles(&clip).unwrap();
        let l = body_lengths(&clip, &roles, &GeometricOptions::default());
        assert!((l.humerus - 0.25).abs() < 1e-12 && (l.shoulder_width - 0.4).abs() < 1e-12 && (l.hip_width - 0.2).abs() < 1e-12);
        let one = human(&[rest_pose()], 30.0);
        assert!(matches!(geometric_features(&one, &roles, &GeometricOptions::default()), Err(MetricError::TooLittle(_))));
        let mut nan = clip.clone();
        nan.positions[30].z = f64::NAN;
        assert!(matches!(geometric_features(&nan, &roles, &GeometricOptions::default()), Err(MetricError::NonFinite(_))));
        let zero = GeometricOptions { lengths: BodyLengths::Fixed { humerus: 0.0, shoulder_width: 1.0, hip_width: 1.0 }, velocity_fps: None };
        assert!(matches!(geometric_features(&clip, &roles, &zero), Err(MetricError::Mismatch(_))));
    }
}
