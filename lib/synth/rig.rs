//! Rig conventions of training-zoo variants: how the files people bring differ from our own
//! example creatures in ways that have nothing to do with the animal.
//!
//! Real rigs name the same joint differently (3ds Max Biped `Bip01_L_Thigh`, Mixamo
//! `mixamorig:LeftUpLeg`, CMU and LAFAN `LeftUpLeg`), point a different axis up (3ds Max and
//! Blender exports are Z-up, with the Y-up-to-Z-up rotation baked into every OFFSET), measure in
//! centimetres instead of metres, and put the root's OFFSET at the world origin instead of at
//! hip height (the position channels then carry the whole height). They also carry anatomy our
//! examples leave out: jaws and ears, fingers, longer necks and tails.
//!
//! Variants below `RIG_VARIANTS` keep the native conventions, so the example files and the
//! training zoo the built-in model was trained on (variants 0-7) stay byte-identical; every
//! variant from `RIG_VARIANTS` on draws its conventions from its number alone.

use super::training::TrainingClip;
use super::*;

/// First training-zoo variant whose conventions are drawn instead of native.
pub const RIG_VARIANTS: u64 = 8;

/// Joint naming style.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Naming {
    /// The family's own style (Mixamo for the biped, Biped for the quadruped, Rigify for the
    /// dragon, and the arthropods', birds' and limbless bodies' styles).
    Native,
    /// `mixamorig:LeftUpLeg`.
    Mixamo,
    /// LAFAN1 style: bare Mixamo-like names, `LeftToe`.
    Lafan,
    /// CMU BVH conversions: `LowerBack`, `Spine`, `Spine1`, `LeftToeBase`.
    Cmu,
    /// 3ds Max Biped: `Bip01_L_Thigh`, `Bip01_L_HorseLink` on hind legs, `BN_Tail_01`.
    Biped,
}

/// Which world axis points up in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum UpAxis {
    Y,
    /// Z up, the creature facing -Y (3ds Max, Blender): the rest pose and every frame are
    /// rotated +90 degrees about X.
    Z,
}

/// Conventions and extra anatomy of one training variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Rig {
    pub naming: Naming,
    pub up: UpAxis,
    /// Lengths in centimetres (OFFSETs and positions times 100).
    pub centimetres: bool,
    /// The root's OFFSET is the world origin; otherwise it is the rest hip position.
    pub root_at_origin: bool,
    /// Jaw and two ears on four-legged heads.
    pub jaw_and_ears: bool,
    /// Fingers per hand (0, 3 or 5) on the biped, three joints each.
    pub fingers: usize,
    /// How far the biped's arms hang below horizontal in the rest pose, in degrees: 0 is a
    /// T-pose, 30-50 an A-pose (the natural stance many rigs are modelled in).
    pub arm_drop_degrees: u32,
}

impl Rig {
    /// What the example creatures and variants below `RIG_VARIANTS` use.
    pub const NATIVE: Rig =
        Rig { naming: Naming::Native, up: UpAxis::Y, centimetres: false, root_at_origin: false, jaw_and_ears: false, fingers: 0, arm_drop_degrees: 0 };
}

/// The rig of `variant` of creature `name` (`None` for an unknown creature).
pub fn rig(name: &str, variant: u64) -> Option<Rig> {
    if !creature_names().contains(&name) {
        return None;
    }
    if variant < RIG_VARIANTS {
        return Some(Rig::NATIVE);
    }
    let mut rng = SplitMix64::new(fnv1a(name) ^ variant.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x0072_6967);
    // Namings are taken in turn (so every style appears within a few variants), the rest drawn.
    let styles: &[Naming] = match name {
        "biped" => &[Naming::Mixamo, Naming::Biped, Naming::Lafan, Naming::Cmu],
        "quadruped" => &[Naming::Biped, Naming::Native],
        "dragon" => &[Naming::Native, Naming::Biped],
        _ => &[Naming::Native],
    };
    let naming = styles[((variant - RIG_VARIANTS) % styles.len() as u64) as usize];
    let up = if rng.unit() < 0.4 { UpAxis::Z } else { UpAxis::Y };
    let centimetres = rng.unit() < 0.5;
    let root_at_origin = rng.unit() < 0.35;
    let jaw_and_ears = matches!(name, "quadruped" | "dragon") && rng.unit() < 0.75;
    let fingers = match (name, naming) {
        // LAFAN and CMU humans have no finger chains (CMU's stubs are left out too).
        ("biped", Naming::Mixamo | Naming::Biped) => [0, 3, 5, 5][rng.below(4)],
        _ => 0,
    };
    let arm_drop_degrees = if name == "biped" && rng.unit() < 0.5 { 30 + rng.below(21) as u32 } else { 0 };
    Some(Rig { naming, up, centimetres, root_at_origin, jaw_and_ears, fingers, arm_drop_degrees })
}

/// Joint-count ranges (body, neck, tail) that rig variants draw from where they differ from
/// the family's usual ones: longer necks and tails, so skeletons span about 20-80 joints.
pub(crate) fn wide_counts(name: &str) -> Option<[(usize, usize); 3]> {
    match name {
        // At most 1 + 6 + 4 + 4 (head, jaw, ears) + 16 + 16 + 1 (Bip01) = 48 joints.
        "quadruped" => Some([(2, 6), (1, 4), (2, 16)]),
        // At most 1 + 5 + 10 + 4 + 6 (wings) + 16 + 36 + 1 = 79 joints.
        "dragon" => Some([(2, 5), (2, 10), (5, 36)]),
        _ => None,
    }
}

/// Human joint names in each style. `side` is `Some(left)` for paired joints; `i` numbers
/// spine joints (0-2) and finger joints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum HumanPart {
    Hips,
    Spine(usize),
    Neck,
    Head,
    Shoulder,
    Arm,
    ForeArm,
    Hand,
    /// Finger `f` (0 = thumb), joint `i` (0-2).
    Finger(usize, usize),
    UpLeg,
    Leg,
    Foot,
    Toe,
}

pub(crate) fn human_name(naming: Naming, part: HumanPart, left: Option<bool>) -> String {
    use HumanPart::*;
    if naming == Naming::Biped {
        let s = match left {
            Some(true) => "L_",
            Some(false) => "R_",
            None => "",
        };
        let base = match part {
            Hips => "Pelvis".to_string(),
            Spine(0) => "Spine".to_string(),
            Spine(i) => format!("Spine{i}"),
            Neck => "Neck".into(),
            Head => "Head".into(),
            Shoulder => "Clavicle".into(),
            Arm => "UpperArm".into(),
            ForeArm => "Forearm".into(),
            Hand => "Hand".into(),
            Finger(f, 0) => format!("Finger{f}"),
            Finger(f, i) => format!("Finger{f}{i}"),
            UpLeg => "Thigh".into(),
            Leg => "Calf".into(),
            Foot => "Foot".into(),
            Toe => "Toe0".into(),
        };
        return format!("Bip01_{s}{base}");
    }
    let side = match left {
        Some(true) => "Left",
        Some(false) => "Right",
        None => "",
    };
    const FINGERS: [&str; 5] = ["Thumb", "Index", "Middle", "Ring", "Pinky"];
    let base = match part {
        Hips => "Hips".to_string(),
        Spine(i) if naming == Naming::Cmu => ["LowerBack", "Spine", "Spine1"][i.min(2)].to_string(),
        Spine(0) => "Spine".to_string(),
        Spine(i) => format!("Spine{i}"),
        Neck => "Neck".into(),
        Head => "Head".into(),
        Shoulder => "Shoulder".into(),
        Arm => "Arm".into(),
        ForeArm => "ForeArm".into(),
        Hand => "Hand".into(),
        Finger(f, i) => format!("Hand{}{}", FINGERS[f.min(4)], i + 1),
        UpLeg => "UpLeg".into(),
        Leg => "Leg".into(),
        Foot => "Foot".into(),
        Toe if naming == Naming::Lafan => "Toe".into(),
        Toe => "ToeBase".into(),
    };
    let name = format!("{side}{base}");
    match naming {
        Naming::Native | Naming::Mixamo => format!("mixamorig:{name}"),
        _ => name,
    }
}

/// Re-express a clip in `rig`'s axis, unit and root conventions (naming and anatomy are the
/// body builders' business). World positions change by exactly the axis rotation and the unit
/// scale, so the motion is the same motion.
pub(crate) fn apply(rig: &Rig, clip: &mut TrainingClip) {
    let scale = if rig.centimetres { 100.0 } else { 1.0 };
    let turn = match rig.up {
        UpAxis::Y => DQuat::IDENTITY,
        UpAxis::Z => rx(90.0),
    };
    if scale == 1.0 && turn == DQuat::IDENTITY && !rig.root_at_origin {
        return;
    }
    // A rest rotation baked into the frame: offsets and translations turn with the world, and
    // every local rotation is conjugated (world rotations W become turn W turn^-1, and so do
    // the parent-relative ones).
    let inv = turn.inverse();
    // Offsets turn exactly (a quarter turn only swaps axes) and are rounded as the builder
    // rounds them, so the hierarchy text stays as short as the native one.
    let swap = |v: DVec3| match rig.up {
        UpAxis::Y => v * scale,
        UpAxis::Z => v3(v.x, -v.z, v.y) * scale,
    };
    let exact = |v: DVec3| round_offset(swap(v));
    for joint in &mut clip.skeleton.joints {
        joint.offset = exact(joint.offset);
        for e in &mut joint.end_sites {
            *e = exact(*e);
        }
    }
    if rig.root_at_origin {
        clip.skeleton.joints[0].offset = DVec3::ZERO;
    }
    for q in &mut clip.motion.rotations {
        *q = (turn * *q * inv).normalize();
    }
    for t in &mut clip.motion.translations {
        *t = swap(*t);
    }
    // Joints with position channels write their offsets; keep them equal to the new OFFSETs.
    // The root's translation is its world position and stays as turned and scaled.
    let n = clip.motion.joints;
    for f in 0..clip.motion.frames {
        for (j, joint) in clip.skeleton.joints.iter().enumerate().skip(1) {
            clip.motion.translations[f * n + j] = joint.offset;
        }
    }
}

/// 3ds Max Biped files put the body's centre node `Bip01` above `Bip01_Pelvis`: `Bip01` carries
/// the position and orientation, the pelvis hangs from it with a zero offset and rotation
/// channels only. A re-expression: every joint stays where it was.
pub(crate) fn add_biped_centre(clip: &mut TrainingClip) {
    let skel = &mut clip.skeleton;
    let mut centre = skel.joints[0].clone();
    centre.name = "Bip01".into();
    centre.end_sites.clear();
    let pelvis = &mut skel.joints[0];
    pelvis.parent = Some(0);
    pelvis.offset = DVec3::ZERO;
    pelvis.channels.retain(|c| c.is_rotation());
    for joint in skel.joints.iter_mut().skip(1) {
        joint.parent = joint.parent.map(|p| p + 1);
    }
    skel.joints.insert(0, centre);
    let m = &mut clip.motion;
    let n = m.joints;
    let mut rotations = Vec::with_capacity(m.frames * (n + 1));
    let mut translations = Vec::with_capacity(m.frames * (n + 1));
    for f in 0..m.frames {
        let (r, t) = (&m.rotations[f * n..(f + 1) * n], &m.translations[f * n..(f + 1) * n]);
        rotations.extend([r[0], DQuat::IDENTITY]);
        rotations.extend_from_slice(&r[1..]);
        translations.extend([t[0], DVec3::ZERO]);
        translations.extend_from_slice(&t[1..]);
    }
    m.rotations = rotations;
    m.translations = translations;
    m.joints = n + 1;
    debug_assert!(skel.validate().is_ok());
}
