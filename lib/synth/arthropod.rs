//! Many-legged walkers: spider, centipede and crab.
//!
//! These are the skeletons that break human-centric assumptions (more than two of everything,
//! legs whose middle joint sits above the body, a root that is a head segment), so they get
//! their own module. Their legs use the same ground-target recipe as the vertebrates — feet
//! fixed in stance, IK for the chain — but the knee pole points up, and the coxa first turns
//! the leg plane towards the foot, as an arthropod's basal joint does. Gaits differ only in
//! phase patterns: alternating tetrapod for spider and crab, a metachronal wave for the
//! centipede.

use super::*;

/// An arachnid-style leg: coxa (turns the leg plane), femur up, tibia down, foot to the ground.
pub(super) struct JointedLeg {
    pub coxa: usize,
    pub ik: Leg,
    /// Horizontal rest direction of the leg plane.
    pub dir: DVec3,
    /// The foot's End Site offset (where it touches the ground).
    pub end: DVec3,
    /// Rest ground contact relative to the root's ground projection.
    pub home: DVec3,
}

/// Leg dimensions along the leg plane: (out, up) of each bone.
struct LegDims {
    attach: f64,
    coxa: f64,
    femur: (f64, f64),
    tibia: (f64, f64),
    end: (f64, f64),
}

impl LegDims {
    /// Body height that puts the foot ends on the ground.
    fn body_height(&self) -> f64 {
        -(self.femur.1 + self.tibia.1 + self.end.1)
    }
}

/// Add one leg pointing at `angle` degrees from forward (+z) towards the creature's side.
fn jointed_leg(b: &mut Builder, parent: usize, names: [String; 4], left: bool, angle: f64, d: &LegDims) -> JointedLeg {
    let s = if left { 1.0 } else { -1.0 };
    let a = angle.to_radians();
    let dir = v3(s * a.sin(), 0.0, a.cos());
    let along = |out: f64, up: f64| dir * out + DVec3::Y * up;
    let coxa = b.add(&names[0], parent, along(d.attach, 0.0));
    let femur = b.add(&names[1], coxa, along(d.coxa, 0.0));
    let tibia = b.add(&names[2], femur, along(d.femur.0, d.femur.1));
    let foot = b.add(&names[3], tibia, along(d.tibia.0, d.tibia.1));
    b.end(foot, along(d.end.0, d.end.1));
    let reach = d.attach + d.coxa + d.femur.0 + d.tibia.0 + d.end.0;
    JointedLeg { coxa, ik: Leg { upper: femur, lower: tibia, tip: Some(foot), rest_pole: DVec3::Y }, dir, end: along(d.end.0, d.end.1), home: dir * reach }
}

/// Pose a jointed leg so its foot end touches `contact` (world) with the foot held at the
/// world rotation `foot`. Keeping the foot's rotation fixed (rather than turning it with the
/// leg) keeps the foot joint itself still during stance, which is what contact detectors
/// measure; the coxa then aims the leg plane at the foot joint.
pub(super) fn place_jointed_leg(p: &mut Pose, leg: &JointedLeg, contact: DVec3, foot: DQuat) {
    let target = contact - foot * leg.end;
    let pivot = p.pos(leg.coxa);
    let mut h = target - pivot;
    h.y = 0.0;
    p.world(leg.coxa, aim(leg.dir, DVec3::Y, h, DVec3::Y));
    p.leg(&leg.ik, target, DVec3::Y, foot);
}

/// The spider's joints: body parts and (leg, left, index) per leg.
pub(super) struct SpiderBody {
    pub skel: Skeleton,
    pub body_y: f64,
    pub abdomen: usize,
    pub fangs: [usize; 2],
    pub legs: Vec<(JointedLeg, bool, usize)>,
}

/// The spider scaled by `shape` (size everything, limbs the legs).
pub(super) fn spider_body(shape: &Proportions) -> SpiderBody {
    let layout = Layout { root_order: "ZYX", joint_order: "ZYX", all_positions: true };
    let (k, l) = (shape.size, shape.size * shape.limbs);
    let dims = LegDims { attach: 0.04 * k, coxa: 0.025 * l, femur: (0.08 * l, 0.08 * l), tibia: (0.08 * l, -0.12 * l), end: (0.015 * l, -0.04 * l) };
    let body_y = dims.body_height();
    let mut b = Builder::new("cephalothorax", v3(0.0, body_y, 0.0), layout);
    let abdomen = b.add("abdomen", 0, v3(0.0, 0.015 * k, -0.045 * k));
    b.end(abdomen, v3(0.0, 0.01 * k, -0.1 * k * shape.tail));
    let fang_l = b.add("chelicera_l", 0, v3(0.01 * k, -0.005 * k, 0.035 * k));
    b.end(fang_l, v3(0.0, -0.02 * k, 0.01 * k));
    let fang_r = b.add("chelicera_r", 0, v3(-0.01 * k, -0.005 * k, 0.035 * k));
    b.end(fang_r, v3(0.0, -0.02 * k, 0.01 * k));
    let angles = [35.0, 70.0, 110.0, 148.0];
    let mut legs = Vec::new();
    for left in [true, false] {
        for (i, &angle) in angles.iter().enumerate() {
            let s = if left { 'l' } else { 'r' };
            let names = ["coxa", "femur", "tibia", "foot"].map(|part| format!("leg_{s}{}_{part}", i + 1));
            legs.push((jointed_leg(&mut b, 0, names, left, angle, &dims), left, i));
        }
    }
    SpiderBody { skel: b.build(), body_y, abdomen, fangs: [fang_l, fang_r], legs }
}

/// An eight-legged walker in alternating tetrapod gait (L1 R2 L3 R4 against R1 L2 R3 L4),
/// six channels on every joint as Truebones exports them, snake_case names.
pub(super) fn spider(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let body = spider_body(&training::proportions("spider", 0).expect("spider exists"));
    let SpiderBody { skel, body_y, abdomen, fangs: [fang_l, fang_r], legs } = body;

    let (frames, period) = frames_for(rng.vary(0.6, 0.06), 4);
    let gait = Gait { period, duty: rng.vary(0.55, 0.03), stride: rng.vary(0.11, 0.08), lift: rng.vary(0.035, 0.1) };
    // Tetrapod groups alternate; within a group the hind legs lead a little, as in real spiders.
    let touchdown: Vec<f64> = legs
        .iter()
        .map(|&(_, left, i)| {
            let group = if (i % 2 == 0) == left { 0.0 } else { 0.5 };
            group - 0.04 * i as f64 + rng.range(-0.02, 0.02)
        })
        .collect();
    let bob = 0.004;
    let sway = rng.vary(3.0, 0.2);
    let motion = animate(&skel, frames, |p, t| {
        let c = t / gait.period;
        p.root(v3(0.0, body_y - bob + bob * cwave(2.0 * c), gait.speed() * t), ry(sway * 0.3 * wave(c)) * rx(-2.0));
        p.local(abdomen, ry(sway * wave(c - 0.2)) * rx(3.0 * wave(2.0 * c)));
        p.local(fang_l, rx(10.0 * wave(2.0 * c).max(0.0)));
        p.local(fang_r, rx(10.0 * wave(2.0 * c).max(0.0)));
        for (k, (leg, _, _)) in legs.iter().enumerate() {
            let f = gait.foot(t, touchdown[k]);
            let contact = v3(leg.home.x, f.lift, leg.home.z + f.forward);
            place_jointed_leg(p, leg, contact, DQuat::IDENTITY);
        }
    });
    (skel, motion)
}

/// The crab's joints: eyes, claws (merus, carpus, finger) and (leg, left, index) per leg.
pub(super) struct CrabBody {
    pub skel: Skeleton,
    pub body_y: f64,
    pub eyes: Vec<usize>,
    pub claws: Vec<(usize, usize, usize)>,
    pub legs: Vec<(JointedLeg, bool, usize)>,
}

/// The crab scaled by `shape` (size everything, limbs the legs and claws).
pub(super) fn crab_body(shape: &Proportions) -> CrabBody {
    let layout = Layout { root_order: "YXZ", joint_order: "XZY", all_positions: false };
    let (k, l) = (shape.size, shape.size * shape.limbs);
    let dims = LegDims { attach: 0.07 * k, coxa: 0.02 * l, femur: (0.08 * l, 0.05 * l), tibia: (0.07 * l, -0.09 * l), end: (0.03 * l, -0.05 * l) };
    let body_y = dims.body_height();
    let mut b = Builder::new("Carapace", v3(0.0, body_y, 0.0), layout);
    let mut eyes = Vec::new();
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let eye = b.add(if left { "L_Eye" } else { "R_Eye" }, 0, v3(0.02 * s * k, 0.02 * k, 0.06 * k));
        b.end(eye, v3(0.0, 0.03 * k, 0.005 * k));
        eyes.push(eye);
    }
    let mut claws = Vec::new();
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let side = if left { "L" } else { "R" };
        let merus = b.add(&format!("{side}_Claw_Merus"), 0, v3(0.05 * s * k, 0.0, 0.05 * k));
        let carpus = b.add(&format!("{side}_Claw_Carpus"), merus, v3(0.05 * s * l, 0.01 * l, 0.04 * l));
        let hand = b.add(&format!("{side}_Claw_Hand"), carpus, v3(0.01 * s * l, 0.0, 0.05 * l));
        b.end(hand, v3(0.0, -0.005 * l, 0.06 * l));
        let finger = b.add(&format!("{side}_Claw_Finger"), carpus, v3(0.015 * s * l, 0.015 * l, 0.05 * l));
        b.end(finger, v3(-0.003 * s * l, -0.008 * l, 0.055 * l));
        claws.push((merus, carpus, finger));
    }
    let angles = [62.0, 82.0, 102.0, 124.0];
    let mut legs = Vec::new();
    for left in [true, false] {
        for (i, &angle) in angles.iter().enumerate() {
            let side = if left { "L" } else { "R" };
            let names = ["Coxa", "Merus", "Carpus", "Toe"].map(|part| format!("{side}_Leg{}_{part}", i + 1));
            legs.push((jointed_leg(&mut b, 0, names, left, angle, &dims), left, i));
        }
    }
    CrabBody { skel: b.build(), body_y, eyes, claws, legs }
}

/// A crab: four legs a side plus two claws, scuttling sideways to its left. The rest pose faces
/// +z like every creature; the clip turns it a quarter so that its sideways walk still advances
/// along +z.
pub(super) fn crab(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let CrabBody { skel, body_y, eyes, claws, legs } = crab_body(&training::proportions("crab", 0).expect("crab exists"));

    let (frames, period) = frames_for(rng.vary(0.55, 0.06), 4);
    let gait = Gait { period, duty: rng.vary(0.55, 0.03), stride: rng.vary(0.1, 0.08), lift: rng.vary(0.04, 0.1) };
    let touchdown: Vec<f64> = legs.iter().map(|&(_, left, i)| (if (i % 2 == 0) == left { 0.0 } else { 0.5 }) + rng.range(-0.03, 0.03)).collect();
    // Facing -x, the crab's left (+x in the rest pose) leads along +z.
    let heading = ry(-90.0);
    let wave_claw = rng.vary(12.0, 0.2);
    let motion = animate(&skel, frames, |p, t| {
        let c = t / gait.period;
        let y = body_y - 0.004 + 0.004 * cwave(2.0 * c);
        p.root(v3(0.0, y, gait.speed() * t), heading * rz(2.0 * wave(c)));
        for &e in &eyes {
            p.local(e, rx(8.0 * wave(c)));
        }
        for (k, &(merus, carpus, finger)) in claws.iter().enumerate() {
            // Claws held up and forward, waving out of step with each other and pinching.
            let q = [ry(-20.0) * rz(10.0 + wave_claw * wave(c + 0.5 * k as f64)), ry(35.0) * rx(-15.0), rx(-12.0 * (0.5 + 0.5 * wave(2.0 * c)))];
            let q = if k == 0 { q } else { q.map(mirror) };
            p.local(merus, q[0]);
            p.local(carpus, q[1]);
            p.local(finger, q[2]);
        }
        for (k, (leg, _, _)) in legs.iter().enumerate() {
            let f = gait.foot(t, touchdown[k]);
            let home = heading * leg.home;
            let contact = v3(home.x, f.lift, home.z + f.forward);
            place_jointed_leg(p, leg, contact, heading);
        }
    });
    (skel, motion)
}

/// The centipede's joints and dimensions.
pub(super) struct CentipedeBody {
    pub skel: Skeleton,
    pub body_y: f64,
    pub seg_len: f64,
    pub head: usize,
    pub antennae: Vec<usize>,
    /// Segment joints, head segment (the root) first.
    pub segments: Vec<usize>,
    pub tail: usize,
    /// (IK chain, home relative to its segment, segment index, left) per leg.
    pub legs: Vec<(Leg, DVec3, usize, bool)>,
    /// The foot's End Site (it stands on it).
    pub claw: DVec3,
}

/// The centipede with `shape.body_joints` segments, scaled by `shape`.
pub(super) fn centipede_body(shape: &Proportions) -> CentipedeBody {
    let n_segments = shape.body_joints.max(2);
    let layout = Layout { root_order: "YXZ", joint_order: "YXZ", all_positions: false };
    let (k, l) = (shape.size, shape.size * shape.limbs);
    let seg_len = 0.05 * k;
    // Each leg: hip (`Leg`), knee (`Shin`) raised above the body, and a short foot standing
    // on the ground so the foot joint itself stays put in stance.
    let (attach, upper, lower, claw) = (0.012 * k, v3(0.05 * l, 0.025 * l, 0.0), v3(0.04 * l, -0.054 * l, 0.0), v3(0.0, -0.006 * l, 0.0));
    let body_y = -(upper.y + lower.y + claw.y);
    let mut b = Builder::new("Segment01", v3(0.0, body_y, 0.0), layout);
    let head = b.add("Head", 0, v3(0.0, 0.004 * k, 0.035 * k));
    let mut antennae = Vec::new();
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let a = b.add(if left { "Antenna_L" } else { "Antenna_R" }, head, v3(0.008 * s * k, 0.004 * k, 0.02 * k));
        let n = k * shape.neck;
        b.end(a, v3(0.04 * s * n, 0.015 * n, 0.07 * n));
        antennae.push(a);
    }
    let mut segments = vec![0];
    let mut legs = Vec::new();
    for k in 0..n_segments {
        if k > 0 {
            let seg = b.add(&format!("Segment{:02}", k + 1), segments[k - 1], v3(0.0, 0.0, -seg_len));
            segments.push(seg);
        }
        for left in [true, false] {
            let (s, side) = if left { (1.0, "L") } else { (-1.0, "R") };
            let leg = b.add(&format!("Leg{:02}_{side}", k + 1), segments[k], v3(attach * s, 0.0, 0.0));
            let shin = b.add(&format!("Shin{:02}_{side}", k + 1), leg, v3(upper.x * s, upper.y, 0.0));
            let foot = b.add(&format!("Foot{:02}_{side}", k + 1), shin, v3(lower.x * s, lower.y, 0.0));
            b.end(foot, claw);
            let home = v3((attach + upper.x + lower.x) * s, 0.0, 0.0);
            legs.push((Leg { upper: leg, lower: shin, tip: Some(foot), rest_pole: DVec3::Y }, home, k, left));
        }
    }
    let tail = b.add("Tail", segments[n_segments - 1], v3(0.0, 0.0, -seg_len));
    b.end(tail, v3(0.0, 0.005 * k, -0.03 * k * shape.tail));
    CentipedeBody { skel: b.build(), body_y, seg_len, head, antennae, segments, tail, legs, claw }
}

/// A centipede: a chain of segments from the head back, one leg pair each, legs stepping in a
/// metachronal wave (each pair lands a fixed fraction of a cycle after the pair in front, left
/// and right in antiphase) and the body undulating with the same wavelength.
pub(super) fn centipede(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    const SEGMENTS: usize = 12;
    let body = centipede_body(&training::proportions("centipede", 0).expect("centipede exists"));
    let CentipedeBody { skel, body_y, seg_len, head, antennae, segments, tail, claw, .. } = body;
    // Homes along the body, as the constant-speed gait below wants them.
    let legs: Vec<_> = body.legs.iter().map(|&(leg, home, k, left)| (leg, home - DVec3::Z * seg_len * k as f64, k, left)).collect();

    let (frames, period) = frames_for(rng.vary(0.36, 0.06), 8);
    let gait = Gait { period, duty: rng.vary(0.55, 0.03), stride: rng.vary(0.05, 0.08), lift: rng.vary(0.015, 0.1) };
    // Retrograde wave: each pair lands `lag` of a cycle after the pair in front of it.
    let wavelength = rng.vary(7.0, 0.1);
    let lag = 1.0 / wavelength;
    let touchdown: Vec<f64> = legs.iter().map(|&(_, _, k, left)| k as f64 * lag + if left { 0.0 } else { 0.5 } + rng.range(-0.015, 0.015)).collect();
    // The body's lateral wave is prescribed in the world (each segment aims at where the next
    // one should be), not as summed local angles, so its amplitude stays small at the tail
    // too and the legs keep their reach.
    let sway = rng.vary(0.006, 0.2);
    let motion = animate(&skel, frames, |p, t| {
        let c = t / gait.period;
        let centre = |k: usize| v3(sway * wave(c - k as f64 * lag), body_y, gait.speed() * t - seg_len * k as f64);
        let along = |k: usize| aim(DVec3::NEG_Z, DVec3::Y, centre(k + 1) - centre(k), DVec3::Y);
        p.root(centre(0), along(0));
        p.world(head, rx(-4.0));
        for (i, &a) in antennae.iter().enumerate() {
            let q = ry(10.0 * wave(c + 0.3 * i as f64)) * rx(-8.0 * wave(2.0 * c));
            p.local(a, if i == 0 { q } else { mirror(q) });
        }
        for (k, &seg) in segments.iter().enumerate().skip(1) {
            p.world(seg, along(k));
        }
        p.world(tail, along(SEGMENTS));
        for (i, (leg, home, _, _)) in legs.iter().enumerate() {
            let f = gait.foot(t, touchdown[i]);
            let contact = v3(home.x, f.lift, home.z + f.forward);
            p.leg(leg, contact - claw, DVec3::Y, DQuat::IDENTITY);
        }
    });
    (skel, motion)
}
