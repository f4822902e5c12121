//! Vertebrates on knees: the biped, the quadruped and the dragon.
//!
//! They share one recipe, which is why they share a module: the gait places each ankle on the
//! ground (fixed in stance, a cycloid arc in swing), the pelvis height is chosen so no leg has
//! to over-extend at the ends of its stance, two-bone IK bends each knee towards a pole, and
//! the spine, arms, neck and tail are driven by phase-locked sines so the body follows the legs.
//! The quadruped and the dragon are one parametrised body plan with different names, sizes,
//! gait (walk vs trot) and extras (wings), because naming style and proportions are exactly
//! what the zoo wants to vary while keeping the motion code in one place.

use super::*;

/// The biped's joints, as the gaits need them.
pub(super) struct BipedBody {
    pub skel: Skeleton,
    pub spine: [usize; 3],
    pub neck: usize,
    pub head: usize,
    /// (arm, forearm, hand) left then right.
    pub arms: Vec<(usize, usize, usize)>,
    /// Rest rotation of each arm below the T-pose (left, right), `None` in a T-pose: world
    /// rotations meant for a T-pose arm are multiplied by its inverse.
    pub arm_rest: Option<[DQuat; 2]>,
    /// (IK chain, toe, hip x) left then right.
    pub legs: Vec<(Leg, usize, f64)>,
}

/// The Mixamo-named human body scaled by `shape` (all factors 1 give the example biped), named
/// and given fingers as `rig` says.
pub(super) fn biped_body(shape: &Proportions, rig: &Rig) -> BipedBody {
    use super::rig::HumanPart as H;
    let layout = Layout { root_order: "ZXY", joint_order: "ZXY", all_positions: false };
    let m = |part: H, left: Option<bool>| human_name(rig.naming, part, left);
    let k = shape.size;
    let (arm_k, leg_k, neck_k) = (k * shape.limbs, k * shape.limbs, k * shape.neck);
    // Pelvis height follows the legs: hip drop and ankle scale with the body, the legs (0.84)
    // with the limbs.
    let mut b = Builder::new(&m(H::Hips, None), v3(0.0, 0.98 * k + 0.84 * (leg_k - k), 0.0), layout);
    let spine = b.add(&m(H::Spine(0), None), 0, v3(0.0, 0.1 * k, 0.0));
    let spine1 = b.add(&m(H::Spine(1), None), spine, v3(0.0, 0.12 * k, 0.0));
    let spine2 = b.add(&m(H::Spine(2), None), spine1, v3(0.0, 0.13 * k, 0.0));
    let neck = b.add(&m(H::Neck, None), spine2, v3(0.0, 0.14 * k, 0.01 * k));
    let head = b.add(&m(H::Head, None), neck, v3(0.0, 0.09 * neck_k, 0.01 * neck_k));
    b.end(head, v3(0.0, 0.18 * k, 0.0));
    let mut arms = Vec::new();
    let drop = rig.arm_drop_degrees as f64;
    let arm_rest = (drop > 0.0).then(|| [rz(-drop), rz(drop)]);
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let side = Some(left);
        // In an A-pose everything from the upper arm out hangs `drop` degrees lower; the
        // clavicle stays level. (Only then rotated, so T-pose offsets keep their exact bits.)
        let hang = |v: DVec3| match arm_rest {
            Some(r) => r[usize::from(!left)] * v,
            None => v,
        };
        let sh = b.add(&m(H::Shoulder, side), spine2, v3(0.06 * s * k, 0.1 * k, 0.0));
        let arm = b.add(&m(H::Arm, side), sh, v3(0.12 * s * k, 0.0, 0.0));
        let fore = b.add(&m(H::ForeArm, side), arm, hang(v3(0.27 * s * arm_k, 0.0, 0.0)));
        let hand = b.add(&m(H::Hand, side), fore, hang(v3(0.25 * s * arm_k, 0.0, 0.0)));
        if rig.fingers == 0 {
            b.end(hand, hang(v3(0.18 * s * k, 0.0, 0.0)));
        }
        // Fingers fan out from the palm along the hand's axis; the thumb sits forward and lower.
        // Five fingers are thumb..pinky, three are thumb, index and middle.
        for f in 0..rig.fingers {
            let (base, step) = if f == 0 {
                (v3(0.03 * s * k, -0.01 * k, 0.03 * k), v3(0.03 * s * arm_k, 0.0, 0.015 * arm_k))
            } else {
                let z = 0.022 * k - 0.012 * k * (f - 1) as f64;
                (v3(0.09 * s * k, 0.0, z), v3(0.028 * s * arm_k, 0.0, 0.0))
            };
            let (base, step) = (hang(base), hang(step));
            let names: Vec<String> = (0..3).map(|i| m(H::Finger(f, i), side)).collect();
            let joints = b.chain(&names, hand, base, step);
            b.end(joints[2], step * 0.8);
        }
        arms.push((arm, fore, hand));
    }
    let mut legs = Vec::new();
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let side = Some(left);
        let up = b.add(&m(H::UpLeg, side), 0, v3(0.09 * s * k, -0.06 * k, 0.0));
        let knee = b.add(&m(H::Leg, side), up, v3(0.0, -0.43 * leg_k, 0.0));
        let foot = b.add(&m(H::Foot, side), knee, v3(0.0, -0.41 * leg_k, 0.0));
        let toe = b.add(&m(H::Toe, side), foot, v3(0.0, -0.06 * k, 0.12 * k));
        b.end(toe, v3(0.0, -0.02 * k, 0.06 * k));
        legs.push((Leg { upper: up, lower: knee, tip: Some(foot), rest_pole: DVec3::Z }, toe, 0.09 * s * k));
    }
    BipedBody { skel: b.build(), spine: [spine, spine1, spine2], neck, head, arms, arm_rest, legs }
}

/// Mixamo-named human walking: alternating legs, counter-swinging arms, a level head.
pub(super) fn biped(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let body = biped_body(&training::proportions("biped", 0).expect("biped exists"), &Rig::NATIVE);
    let BipedBody { skel, spine: [spine, spine1, spine2], neck, head, arms, legs, .. } = body;

    let (frames, period) = frames_for(rng.vary(1.1, 0.06), 3);
    let gait = Gait { period, duty: rng.vary(0.6, 0.03), stride: rng.vary(1.05, 0.08), lift: rng.vary(0.07, 0.1) };
    let touchdown = [0.0, 0.5 + rng.range(-0.02, 0.02)];
    let (ankle_y, hip_drop) = (0.08, 0.06);
    // The ball of the foot (toe base) is what stays planted: the heel rises about it late in
    // stance, which lets the trailing leg stay long, so the leading leg at heel strike is the
    // one that limits the pelvis height. 0.975 leaves room for the pelvis yaw and lean.
    let ball = skel.joints[legs[0].1].offset;
    let heel_rise = rng.vary(22.0, 0.1);
    let strike_y = ankle_y + stand_height(0.84, gait.half_reach(), 0.975) + hip_drop;
    // The pelvis vaults over the standing leg: highest at mid-stance, where the leg is
    // vertical and may be almost straight, lowest at double support (0.81 = the bob wave's
    // value at touchdown, just before its minimum).
    let mid_y = ankle_y + 0.84 * 0.97 + hip_drop;
    let bob = (mid_y - strike_y) / 1.81;
    let root_y = mid_y - bob;
    let yaw_amp = rng.vary(5.0, 0.2);
    let arm_amp = rng.vary(18.0, 0.15);
    let lean = rng.vary(4.0, 0.25);
    let motion = animate(&skel, frames, |p, t| {
        let c = t / gait.period;
        // Highest at mid-stance of either foot, when the standing leg is vertical.
        let y = root_y + bob * cwave(2.0 * (c - gait.duty / 2.0));
        // The hip of the swinging leg leads: left hip forward (negative yaw) at left touchdown.
        let yaw = -yaw_amp * cwave(c);
        p.root(v3(0.0, y, gait.speed() * t), ry(yaw) * rx(lean));
        // Shoulders counter-rotate against the pelvis and the spine takes back the lean.
        for j in [spine, spine1, spine2] {
            p.local(j, ry(-0.55 * yaw) * rx(-lean / 3.0));
        }
        // The head stays level and looks ahead, with a small nod per step.
        p.world(neck, rx(-3.0));
        p.world(head, rx(2.0 * wave(2.0 * c)));
        for (k, &(arm, fore, hand)) in arms.iter().enumerate() {
            // Arms swing against the leg of their side: back when that leg lands.
            let swing = arm_amp * cwave(c - touchdown[k]);
            let bend = 12.0 + 8.0 * (1.0 - cwave(c - touchdown[k])) / 2.0;
            let (upper, lower) = (rx(swing) * rz(-80.0), rx(swing - bend) * rz(-80.0));
            let (upper, lower) = if k == 0 { (upper, lower) } else { (mirror(upper), mirror(lower)) };
            p.world(arm, upper);
            p.world(fore, lower);
            p.world(hand, lower);
        }
        for (k, &(leg, toe, x)) in legs.iter().enumerate() {
            let f = gait.foot(t, touchdown[k]);
            // Foot pitch (positive = heel up): heel rise in the second half of stance, then
            // back to flat through swing with the toes pulled up to clear the ground.
            let (pitch, toe_follow) = if f.swing == 0.0 {
                let phi = gait.phase(t, touchdown[k]) / gait.duty;
                (heel_rise * smoothstep((phi - 0.6) / 0.4), 0.0)
            } else {
                let u = f.swing;
                let lift_toes = 12.0 * (std::f64::consts::PI * u).sin().powi(2);
                (heel_rise * (1.0 - smoothstep(u / 0.5)) - lift_toes, smoothstep(u / 0.3))
            };
            let ball_at = v3(x, ankle_y + ball.y + f.lift, ball.z + f.forward);
            let foot_rot = rx(pitch);
            p.leg(&leg, ball_at - foot_rot * ball, DVec3::Z, foot_rot);
            // The toes stay flat on the ground until the foot leaves it.
            p.world(toe, rx(pitch * toe_follow));
        }
    });
    (skel, motion)
}

/// Body parts of the four-legged plan, named by each style's `name` function.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Part {
    Pelvis,
    Spine(usize),
    Neck(usize),
    Head,
    Tail(usize),
    Thigh,
    Calf,
    Foot,
    Toe,
    UpperArm,
    Forearm,
    Forefoot,
    Foretoe,
    Wing(usize),
    Jaw,
    Ear,
}

struct QuadSpec {
    layout: Layout,
    /// Name of a part; `left` is `None` for centre parts.
    name: fn(Part, Option<bool>) -> String,
    scale: f64,
    /// Leg and wing bone lengths relative to `scale`.
    limbs: f64,
    /// Tail bone lengths relative to `scale`.
    tail_length: f64,
    spine: usize,
    neck: usize,
    neck_length: f64,
    tail: usize,
    wings: bool,
    /// A jaw and two ears on the head.
    jaw_and_ears: bool,
    /// Touchdown phases of left hind, left fore, right hind, right fore.
    touchdown: [f64; 4],
    gait: Gait,
    cycles: usize,
    tail_sway: f64,
    wing_flap: f64,
}

/// 3ds Max Biped style (`Bip01_L_Thigh`, `BN_Tail_01`).
fn bip01_name(part: Part, left: Option<bool>) -> String {
    let s = match left {
        Some(true) => "L_",
        Some(false) => "R_",
        None => "",
    };
    match part {
        Part::Pelvis => "Bip01_Pelvis".into(),
        Part::Spine(0) => "Bip01_Spine".into(),
        Part::Spine(i) => format!("Bip01_Spine{i}"),
        Part::Neck(0) => "Bip01_Neck".into(),
        Part::Neck(i) => format!("Bip01_Neck{i}"),
        Part::Head => "Bip01_Head".into(),
        Part::Tail(i) => format!("BN_Tail_{:02}", i + 1),
        Part::Thigh => format!("Bip01_{s}Thigh"),
        Part::Calf => format!("Bip01_{s}Calf"),
        Part::Foot => format!("Bip01_{s}Foot"),
        Part::Toe => format!("Bip01_{s}Toe0"),
        Part::UpperArm => format!("Bip01_{s}UpperArm"),
        Part::Forearm => format!("Bip01_{s}Forearm"),
        Part::Forefoot => format!("Bip01_{s}Forefoot"),
        Part::Foretoe => format!("Bip01_{s}Finger0"),
        Part::Wing(i) => format!("Bip01_{s}Wing{i}"),
        Part::Jaw => "BN_Jaw_01".into(),
        Part::Ear => format!("BN_Ear_{}01", s),
    }
}

/// 3ds Max Biped set up as a quadruped: hind legs have the fourth link (`Bip01_L_HorseLink`)
/// between calf and foot, the front legs are arms, extra bones are `BN_` (`BN_Tail_01`).
fn horselink_name(part: Part, left: Option<bool>) -> String {
    let s = match left {
        Some(true) => "L_",
        Some(false) => "R_",
        None => "",
    };
    match part {
        Part::Foot => format!("Bip01_{s}HorseLink"),
        Part::Toe => format!("Bip01_{s}Foot"),
        Part::Wing(i) => format!("BN_Wing_{s}{:02}", i + 1),
        // Arms, spine, tail and the rest are named as on a Biped.
        other => bip01_name(other, left),
    }
}

/// Blender Rigify style (`DEF-thigh.L`, `DEF-tail.003`).
fn rigify_name(part: Part, left: Option<bool>) -> String {
    let s = match left {
        Some(true) => ".L",
        Some(false) => ".R",
        None => "",
    };
    match part {
        Part::Pelvis => "DEF-hips".into(),
        Part::Spine(i) => format!("DEF-spine.{:03}", i + 1),
        Part::Neck(i) => format!("DEF-neck.{:03}", i + 1),
        Part::Head => "DEF-head".into(),
        Part::Tail(i) => format!("DEF-tail.{:03}", i + 1),
        Part::Thigh => format!("DEF-thigh{s}"),
        Part::Calf => format!("DEF-shin{s}"),
        Part::Foot => format!("DEF-foot{s}"),
        Part::Toe => format!("DEF-toe{s}"),
        Part::UpperArm => format!("DEF-upper_arm{s}"),
        Part::Forearm => format!("DEF-forearm{s}"),
        Part::Forefoot => format!("DEF-forefoot{s}"),
        Part::Foretoe => format!("DEF-foretoe{s}"),
        Part::Wing(i) => format!("DEF-wing{s}.{:03}", i + 1),
        Part::Jaw => "DEF-jaw".into(),
        Part::Ear => format!("DEF-ear{s}"),
    }
}

/// A dog-sized walker in lateral-sequence walk (hind, fore, other hind, other fore).
pub(super) fn quadruped(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let mut touchdown = [0.0, 0.25, 0.5, 0.75];
    for t in &mut touchdown {
        *t += rng.range(-0.02, 0.02);
    }
    let period = rng.vary(0.9, 0.06);
    let spec = QuadSpec {
        layout: Layout { root_order: "XYZ", joint_order: "XYZ", all_positions: false },
        name: bip01_name,
        scale: 1.0,
        limbs: 1.0,
        tail_length: 1.0,
        spine: 3,
        neck: 1,
        neck_length: 0.14,
        tail: 4,
        wings: false,
        jaw_and_ears: false,
        touchdown,
        gait: Gait { period, duty: rng.vary(0.68, 0.03), stride: rng.vary(0.5, 0.08), lift: rng.vary(0.06, 0.1) },
        cycles: 3,
        tail_sway: rng.vary(12.0, 0.2),
        wing_flap: 0.0,
    };
    four_legged(&spec, rng)
}

/// A horse-sized winged lizard in a trot (diagonal pairs together), flapping slowly.
pub(super) fn dragon(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let pair = rng.range(-0.02, 0.02);
    let period = rng.vary(1.0, 0.06);
    let spec = QuadSpec {
        layout: Layout { root_order: "ZXY", joint_order: "YZX", all_positions: false },
        name: rigify_name,
        scale: 2.4,
        limbs: 1.0,
        tail_length: 1.0,
        spine: 3,
        neck: 3,
        neck_length: 0.3,
        tail: 8,
        wings: true,
        jaw_and_ears: false,
        touchdown: [0.0, 0.5 + pair, 0.5, pair],
        gait: Gait { period, duty: rng.vary(0.55, 0.03), stride: rng.vary(1.3, 0.08), lift: rng.vary(0.16, 0.1) },
        cycles: 3,
        tail_sway: rng.vary(9.0, 0.2),
        wing_flap: rng.vary(30.0, 0.15),
    };
    four_legged(&spec, rng)
}

/// The four-legged body's joints and dimensions, as the gaits need them.
pub(super) struct QuadBody {
    pub skel: Skeleton,
    pub spine: Vec<usize>,
    pub neck: Vec<usize>,
    pub head: usize,
    /// Jaw and ears (left, right), when the spec asks for them.
    pub jaw: Option<usize>,
    pub ears: Vec<usize>,
    pub tail: Vec<usize>,
    /// Three joints per wing, left then right; empty without wings.
    pub wings: Vec<[usize; 3]>,
    /// (IK chain, home x, home z, knee pole), in the order LF, RF, LH, RH.
    pub legs: Vec<(Leg, f64, f64, DVec3)>,
    pub hip_drop: f64,
    /// One leg bone (thigh = calf).
    pub bone: f64,
    pub ankle_y: f64,
}

fn quad_body(spec: &QuadSpec) -> QuadBody {
    let k = spec.scale;
    let name = spec.name;
    let (lk, tk) = (k * spec.limbs, k * spec.tail_length);
    let (half_width, hip_drop, bone, ankle_y) = (0.09 * k, 0.07 * k, 0.21 * lk, 0.06 * k);
    let body = 0.58 * k;
    let pelvis_y = ankle_y + 2.0 * bone + hip_drop;
    let mut b = Builder::new(&name(Part::Pelvis, None), v3(0.0, pelvis_y, 0.0), spec.layout);
    let mut spine = Vec::new();
    let mut parent = 0;
    for i in 0..spec.spine {
        // The first segment rises a little so the back arches over the hips.
        let rise = if i == 0 { 0.02 * k } else { 0.0 };
        parent = b.add(&name(Part::Spine(i), None), parent, v3(0.0, rise, body / spec.spine as f64));
        spine.push(parent);
    }
    let chest = parent;
    let mut neck = Vec::new();
    for i in 0..spec.neck {
        let len = spec.neck_length * k / spec.neck as f64;
        let reach = 0.7 * len + if i == 0 { 0.03 * k } else { 0.0 };
        parent = b.add(&name(Part::Neck(i), None), parent, v3(0.0, 0.7 * len, reach));
        neck.push(parent);
    }
    let head = b.add(&name(Part::Head, None), parent, v3(0.0, 0.05 * k, 0.06 * k));
    b.end(head, v3(0.0, -0.02 * k, 0.16 * k));
    let (mut jaw, mut ears) = (None, Vec::new());
    if spec.jaw_and_ears {
        // The jaw hinges under the back of the skull and runs forward under the muzzle; the
        // ears stand on top of the skull, leaning out and back.
        let j = b.add(&name(Part::Jaw, None), head, v3(0.0, -0.03 * k, 0.02 * k));
        b.end(j, v3(0.0, -0.01 * k, 0.13 * k));
        jaw = Some(j);
        for left in [true, false] {
            let s = if left { 1.0 } else { -1.0 };
            let e = b.add(&name(Part::Ear, Some(left)), head, v3(0.035 * s * k, 0.04 * k, 0.0));
            b.end(e, v3(0.015 * s * k, 0.05 * k, -0.015 * k));
            ears.push(e);
        }
    }
    // Legs: each is (IK chain, home x, home z, pole). Elbows point back, knees forward.
    let mut legs: Vec<(Leg, f64, f64, DVec3)> = Vec::new();
    let mut add_leg = |b: &mut Builder, parent: usize, left: bool, front: bool| {
        let s = if left { 1.0 } else { -1.0 };
        let parts = if front { [Part::UpperArm, Part::Forearm, Part::Forefoot, Part::Foretoe] } else { [Part::Thigh, Part::Calf, Part::Foot, Part::Toe] };
        // Front shoulders sit lower on the chest than the hips on the pelvis; equal limbs
        // then reach the same ground.
        let drop = if front { hip_drop + 0.02 * k } else { hip_drop };
        let up = b.add(&name(parts[0], Some(left)), parent, v3(half_width * s, -drop, 0.0));
        let mid = b.add(&name(parts[1], Some(left)), up, v3(0.0, -bone, 0.0));
        let foot = b.add(&name(parts[2], Some(left)), mid, v3(0.0, -bone, 0.0));
        let toe = b.add(&name(parts[3], Some(left)), foot, v3(0.0, -0.04 * k, 0.04 * k));
        b.end(toe, v3(0.0, -0.02 * k, 0.03 * k));
        let pole = if front { DVec3::NEG_Z } else { DVec3::Z };
        let home_z = if front { body } else { 0.0 };
        legs.push((Leg { upper: up, lower: mid, tip: Some(foot), rest_pole: pole }, half_width * s, home_z, pole));
    };
    let mut wings = Vec::new();
    if spec.wings {
        for left in [true, false] {
            let s = if left { 1.0 } else { -1.0 };
            let w0 = b.add(&name(Part::Wing(0), Some(left)), chest, v3(0.07 * s * k, 0.05 * k, -0.05 * k));
            let w1 = b.add(&name(Part::Wing(1), Some(left)), w0, v3(0.35 * s * lk, 0.05 * lk, -0.05 * lk));
            let w2 = b.add(&name(Part::Wing(2), Some(left)), w1, v3(0.4 * s * lk, 0.0, -0.1 * lk));
            b.end(w2, v3(0.45 * s * lk, -0.05 * lk, -0.3 * lk));
            wings.push([w0, w1, w2]);
        }
    }
    add_leg(&mut b, chest, true, true);
    add_leg(&mut b, chest, false, true);
    add_leg(&mut b, 0, true, false);
    add_leg(&mut b, 0, false, false);
    let mut tail = Vec::new();
    parent = 0;
    // Tails of more than 12 joints (rig variants) are as long as a 12-joint one, finer cut.
    let tail_bone = if spec.tail > 12 { 0.1 * tk * 12.0 / spec.tail as f64 } else { 0.1 * tk };
    for i in 0..spec.tail {
        let off = if i == 0 { v3(0.0, 0.03 * k, -0.08 * k) } else { v3(0.0, 0.0, -tail_bone) };
        parent = b.add(&name(Part::Tail(i), None), parent, off);
        tail.push(parent);
    }
    b.end(parent, v3(0.0, 0.0, -tail_bone));
    QuadBody { skel: b.build(), spine, neck, head, jaw, ears, tail, wings, legs, hip_drop, bone, ankle_y }
}

fn four_legged(spec: &QuadSpec, rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let QuadBody { skel, spine, neck, tail, wings, legs, hip_drop, bone, ankle_y, .. } = quad_body(spec);
    let k = spec.scale;
    // Leg order in `legs` is LF, RF, LH, RH; the spec's touchdowns are LH, LF, RH, RF.
    let touchdown = [spec.touchdown[1], spec.touchdown[3], spec.touchdown[0], spec.touchdown[2]];

    let (frames, period) = frames_for(spec.gait.period, spec.cycles);
    let gait = Gait { period, ..spec.gait };
    let bob = 0.008 * k;
    let hip_y = ankle_y + stand_height(2.0 * bone, gait.half_reach(), 0.95);
    let root_y = hip_y + hip_drop - bob;
    let roll_amp = rng.vary(1.5, 0.2);
    let yaw_amp = rng.vary(2.0, 0.2);
    let nod = rng.vary(3.0, 0.2);
    let motion = animate(&skel, frames, |p, t| {
        let c = t / gait.period;
        // Bob twice per cycle; roll towards the side whose hind leg is in stance.
        let y = root_y + bob * cwave(2.0 * (c - touchdown[2] - gait.duty / 2.0));
        let roll = roll_amp * wave(c - touchdown[2]);
        let yaw = yaw_amp * wave(c - touchdown[2] + 0.25);
        p.root(v3(0.0, y, gait.speed() * t), ry(yaw) * rz(roll));
        for &j in &spine {
            p.local(j, ry(-yaw / spec.spine as f64) * rz(-roll / spec.spine as f64));
        }
        for (i, &j) in neck.iter().enumerate() {
            p.local(j, rx(nod * wave(2.0 * c - 0.1 * i as f64)));
        }
        // The tail lags the hips: a wave travelling back along it.
        for (i, &j) in tail.iter().enumerate() {
            let sway = spec.tail_sway * (0.6 + 0.4 * i as f64 / spec.tail as f64);
            p.local(j, ry(sway * wave(c - 0.12 * (i + 1) as f64)) * rx(if i == 0 { 8.0 } else { -1.0 }));
        }
        for (side, w) in wings.iter().enumerate() {
            // Downstroke fast and wide, tips trailing the shoulder.
            let flap = spec.wing_flap;
            let q = [rz(15.0 + flap * wave(c)), rz(-0.35 * flap * wave(c - 0.1)) * ry(10.0 * (1.0 - cwave(c)) / 2.0), rz(-0.3 * flap * wave(c - 0.2))];
            for (i, &j) in w.iter().enumerate() {
                p.local(j, if side == 0 { q[i] } else { mirror(q[i]) });
            }
        }
        for (i, (leg, x, z, pole)) in legs.iter().enumerate() {
            let f = gait.foot(t, touchdown[i]);
            let target = v3(*x, ankle_y + f.lift, z + f.forward);
            let paw = rx(-10.0 * (std::f64::consts::PI * f.swing).sin());
            p.leg(leg, target, *pole, paw);
        }
    });
    (skel, motion)
}

/// The quadruped's or (with `dragon`) the dragon's body scaled by `shape`, named and given a
/// jaw and ears as `rig` says, for training clips. Only the body fields of the spec matter
/// here; the gait ones are the training module's.
pub(super) fn quad_training_body(dragon: bool, shape: &Proportions, rig: &Rig) -> QuadBody {
    let gait = Gait { period: 1.0, duty: 0.5, stride: 1.0, lift: 0.1 };
    let spec = QuadSpec {
        layout: if dragon {
            Layout { root_order: "ZXY", joint_order: "YZX", all_positions: false }
        } else {
            Layout { root_order: "XYZ", joint_order: "XYZ", all_positions: false }
        },
        name: match (rig.naming, dragon) {
            (Naming::Biped, _) => horselink_name,
            (_, true) => rigify_name,
            (_, false) => bip01_name,
        },
        scale: if dragon { 2.4 } else { 1.0 } * shape.size,
        limbs: shape.limbs,
        tail_length: shape.tail,
        spine: shape.body_joints,
        neck: shape.neck_joints,
        neck_length: if dragon { 0.3 } else { 0.14 } * shape.neck,
        tail: shape.tail_joints,
        wings: dragon,
        jaw_and_ears: rig.jaw_and_ears,
        touchdown: [0.0; 4],
        gait,
        cycles: 1,
        tail_sway: 0.0,
        wing_flap: 0.0,
    };
    quad_body(&spec)
}
