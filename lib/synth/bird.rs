//! The bird: two legs, two wings, a bobbing head.
//!
//! Birds are the skeleton that has both arms-as-wings and legs, so it tests that tools do not
//! map "the two upper limbs" to hands. It walks like a pigeon: legs step with the visible
//! joint (the ankle) pointing backwards, the head holds still in the world and then thrusts
//! forward once per step (a two-bone IK on the neck), and the wings flap twice per stride as
//! if about to take off. Names are CamelCase with a `Left`/`Right` prefix.

use super::*;

/// The bird's joints and leg dimensions.
pub(super) struct BirdBody {
    pub skel: Skeleton,
    pub spine: usize,
    pub chest: usize,
    pub neck1: usize,
    pub neck2: usize,
    pub head: usize,
    pub wings: Vec<[usize; 3]>,
    /// (IK chain, hip x) left then right.
    pub legs: Vec<(Leg, f64)>,
    pub tail: [usize; 2],
    pub hip_drop: f64,
    pub shin: DVec3,
    pub tarsus: DVec3,
    pub ankle_y: f64,
}

/// The bird scaled by `shape` (size everything; limbs the legs and wings; neck and tail theirs).
pub(super) fn bird_body(shape: &Proportions) -> BirdBody {
    let layout = Layout { root_order: "ZYX", joint_order: "ZYX", all_positions: false };
    let (k, l, n, tl) = (shape.size, shape.size * shape.limbs, shape.size * shape.neck, shape.size * shape.tail);
    let (hip_drop, shin, tarsus, ankle_y) = (0.02 * k, v3(0.0, -0.1 * l, -0.03 * l), v3(0.0, -0.1 * l, 0.03 * l), 0.02 * k);
    let pelvis_y = ankle_y - shin.y - tarsus.y + hip_drop;
    let mut b = Builder::new("Pelvis", v3(0.0, pelvis_y, 0.0), layout);
    let spine = b.add("Spine", 0, v3(0.0, 0.02 * k, 0.05 * k));
    let chest = b.add("Chest", spine, v3(0.0, 0.02 * k, 0.05 * k));
    let neck1 = b.add("Neck1", chest, v3(0.0, 0.05 * k, 0.03 * k));
    let neck2 = b.add("Neck2", neck1, v3(0.0, 0.05 * n, 0.01 * n));
    let head = b.add("Head", neck2, v3(0.0, 0.03 * n, 0.01 * n));
    b.end(head, v3(0.0, -0.005 * k, 0.05 * k));
    let mut wings = Vec::new();
    for left in [true, false] {
        let (s, side) = if left { (1.0, "Left") } else { (-1.0, "Right") };
        let w1 = b.add(&format!("{side}Wing1"), chest, v3(0.04 * s * k, 0.02 * k, -0.01 * k));
        let w2 = b.add(&format!("{side}Wing2"), w1, v3(0.09 * s * l, 0.0, 0.0));
        let w3 = b.add(&format!("{side}Wing3"), w2, v3(0.09 * s * l, 0.0, -0.01 * l));
        b.end(w3, v3(0.13 * s * l, 0.0, -0.03 * l));
        wings.push([w1, w2, w3]);
    }
    let mut legs = Vec::new();
    for left in [true, false] {
        let (s, side) = if left { (1.0, "Left") } else { (-1.0, "Right") };
        let thigh = b.add(&format!("{side}Thigh"), 0, v3(0.045 * s * k, -hip_drop, 0.0));
        let shin_j = b.add(&format!("{side}Shin"), thigh, shin);
        let foot = b.add(&format!("{side}Foot"), shin_j, tarsus);
        let toe = b.add(&format!("{side}Toe"), foot, v3(0.0, -0.015 * k, 0.04 * k));
        b.end(toe, v3(0.0, -0.005 * k, 0.035 * k));
        let hallux = b.add(&format!("{side}Hallux"), foot, v3(0.0, -0.015 * k, -0.02 * k));
        b.end(hallux, v3(0.0, -0.005 * k, -0.02 * k));
        legs.push((Leg { upper: thigh, lower: shin_j, tip: Some(foot), rest_pole: DVec3::NEG_Z }, 0.045 * s * k));
    }
    let tail1 = b.add("Tail1", 0, v3(0.0, 0.01 * k, -0.05 * k));
    let tail2 = b.add("Tail2", tail1, v3(0.0, 0.01 * tl, -0.05 * tl));
    b.end(tail2, v3(0.0, 0.0, -0.07 * tl));
    let skel = b.build();
    BirdBody { skel, spine, chest, neck1, neck2, head, wings, legs, tail: [tail1, tail2], hip_drop, shin, tarsus, ankle_y }
}

pub(super) fn bird(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let body = bird_body(&training::proportions("bird", 0).expect("bird exists"));
    let BirdBody { skel, spine, chest, neck1, neck2, head, wings, legs, tail: [tail1, tail2], hip_drop, shin, tarsus, ankle_y } = body;

    let (frames, period) = frames_for(rng.vary(0.5, 0.06), 5);
    let gait = Gait { period, duty: rng.vary(0.6, 0.03), stride: rng.vary(0.13, 0.08), lift: rng.vary(0.03, 0.1) };
    let touchdown = [0.0, 0.5 + rng.range(-0.02, 0.02)];
    let bob = 0.004;
    let leg_len = shin.length() + tarsus.length();
    let root_y = ankle_y + stand_height(leg_len, gait.half_reach(), 0.93) + hip_drop - bob;
    let flap = rng.vary(45.0, 0.12);
    let waddle = rng.vary(5.0, 0.2);
    // Neck: base at Neck1, head at the tip; its rest reach from Neck1 to Head.
    let neck_leg = Leg { upper: neck1, lower: neck2, tip: Some(head), rest_pole: DVec3::NEG_Z };
    let rest = skel.rest_positions();
    let head_rest = rest[head] - rest[0];
    let hold = 0.55;
    let motion = animate(&skel, frames, |p, t| {
        let c = t / gait.period;
        let y = root_y + bob * cwave(2.0 * (c - gait.duty / 2.0));
        let x = 0.004 * wave(c - touchdown[0] - 0.25);
        let z = gait.speed() * t;
        p.root(v3(x, y, z), rz(waddle * wave(c - 0.25)) * rx(6.0));
        p.local(spine, rx(-3.0));
        p.local(chest, rx(-3.0));
        // Head bob: twice per cycle the head stays put in the world for `hold` of a step,
        // then catches up with a smooth thrust, so its average speed matches the body's.
        let step = gait.period / 2.0;
        let u = t / step;
        let (n, phi) = (u.floor(), u - u.floor());
        let g = if phi < hold {
            0.0
        } else {
            let v = (phi - hold) / (1.0 - hold);
            v - wave(v) / std::f64::consts::TAU
        };
        // The rest neck is straight, so the head is held a little low and back: the neck
        // then stays bent and the IK never runs out of reach.
        let head_z = gait.speed() * step * (n + g + hold / 2.0) + head_rest.z;
        let head_y = root_y + head_rest.y - 0.022 + 0.003 * cwave(2.0 * c);
        p.leg(&neck_leg, v3(x, head_y, head_z), DVec3::NEG_Z, DQuat::IDENTITY);
        // Wings: two flaps per stride, the hand lagging the arm as real wing tips do.
        for (i, w) in wings.iter().enumerate() {
            let a = 2.0 * c;
            let q = [
                rz(10.0 + flap * wave(a)) * ry(-8.0 * cwave(a)),
                rz(-0.25 * flap * wave(a - 0.12)) * ry(12.0 * (1.0 - cwave(a)) / 2.0),
                rz(-0.2 * flap * wave(a - 0.22)),
            ];
            for (k, &j) in w.iter().enumerate() {
                p.local(j, if i == 0 { q[k] } else { mirror(q[k]) });
            }
        }
        p.local(tail1, rx(8.0 + 4.0 * wave(2.0 * c)));
        p.local(tail2, rx(4.0 * wave(2.0 * c - 0.2)));
        for (k, (leg, hx)) in legs.iter().enumerate() {
            let f = gait.foot(t, touchdown[k]);
            let target = v3(*hx, ankle_y + f.lift, f.forward);
            // Toes curl in swing, as a bird's do, never more than the lift lets them clear.
            let foot = rx(15.0 * f.lift / gait.lift);
            p.leg(leg, target, DVec3::NEG_Z, foot);
        }
    });
    (skel, motion)
}
