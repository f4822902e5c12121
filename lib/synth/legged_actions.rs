//! Training actions of the vertebrates on knees: biped, quadruped, dragon.
//!
//! Same bodies and the same leg recipe as `legged` (ankles or balls of the feet fixed in
//! stance, pelvis high enough that no leg over-extends, IK to a pole), but feet come from a
//! `Plan` (route + step clock) so the body can stop, start and curve, and the upper body's
//! phase-locked swings fade with the walking activity, so a standing body stands.
//! Gait numbers scale with leg length by Froude similarity: stride ∝ leg, period ∝ √leg.

use super::legged::{biped_body, quad_training_body, BipedBody, QuadBody};
use super::route::FootSpec;
use super::training::{Action, Job, Plan, TrainingClip};
use super::*;

/// Stride and lift scale with `r` (leg length over the example's), the period with its root.
fn froude(gait: Gait, r: f64) -> Gait {
    Gait { period: gait.period * r.sqrt(), stride: gait.stride * r, lift: gait.lift * r, ..gait }
}

/// Idle motion shared by all: slow, incommensurate sines, so the loop never visibly repeats.
struct Idle {
    look_period: f64,
    look_phase: f64,
    look: f64,
    shift_period: f64,
    breath_period: f64,
}

impl Idle {
    fn new(rng: &mut SplitMix64) -> Idle {
        Idle {
            look_period: rng.range(3.5, 5.5),
            look_phase: rng.unit(),
            look: rng.range(25.0, 45.0),
            shift_period: rng.range(3.0, 4.5),
            breath_period: rng.range(2.8, 4.0),
        }
    }

    /// Head yaw in degrees: holds, then turns, as animals glance rather than sweep.
    fn look(&self, t: f64) -> f64 {
        let x = t / self.look_period + self.look_phase;
        let s = wave(x);
        self.look * s * s.abs().sqrt()
    }

    /// Side-to-side weight shift in [-1, 1].
    fn shift(&self, t: f64) -> f64 {
        wave(t / self.shift_period)
    }

    fn breath(&self, t: f64) -> f64 {
        wave(t / self.breath_period)
    }
}

pub(super) fn biped(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let shape = job.shape;
    let BipedBody { skel, spine, neck, head, arms, arm_rest, legs } = biped_body(&shape, &job.rig);
    let (k, r) = (shape.size, shape.size * shape.limbs);
    let leg_len = 0.84 * r;
    let run = job.action == Action::Run;
    let gait = if run {
        Gait { period: rng.vary(0.7, 0.05), duty: rng.vary(0.35, 0.03), stride: rng.vary(2.0, 0.15), lift: rng.vary(0.3, 0.1) }
    } else {
        Gait { period: rng.vary(1.1, 0.06), duty: rng.vary(0.6, 0.03), stride: rng.vary(1.05, 0.15), lift: rng.vary(0.07, 0.1) }
    };
    let gait = froude(gait, r);
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    let touchdown = [0.0, 0.5 + rng.range(-0.02, 0.02)];
    let ball = skel.joints[legs[0].1].offset;
    let feet: Vec<_> = legs
        .iter()
        .zip(touchdown)
        .map(|(&(_, _, x), td)| plan.foot(job, FootSpec { home: v3(x, 0.0, ball.z), lag: 0.0, touchdown: td }))
        .map(|f| if run { f.sharp() } else { f })
        .collect();
    let (ankle_y, hip_drop) = (0.08 * k, 0.06 * k);
    let heel_rise = rng.vary(if run { 30.0 } else { 22.0 }, 0.1);
    let strike_y = ankle_y + stand_height(leg_len, gait.half_reach(), 0.975) + hip_drop;
    let mid_y = ankle_y + leg_len * 0.97 + hip_drop;
    // Walking: highest at mid-stance (the pelvis vaults over the leg, see `legged::biped`).
    // Running: lowest at mid-stance (the leg is a spring) and highest in flight.
    let bob = if run { 0.035 * r } else { (mid_y - strike_y) / 1.81 };
    let walk_y = if run { strike_y + bob * (TAU * gait.duty).cos() } else { mid_y - bob };
    let stand_y = strike_y.min(mid_y - 0.015 * r);
    let yaw_amp = rng.vary(if run { 8.0 } else { 5.0 }, 0.2);
    let arm_amp = rng.vary(if run { 35.0 } else { 18.0 }, 0.15);
    let elbow = if run { 75.0 } else { 12.0 };
    let lean = rng.vary(if run { 9.0 } else { 4.0 }, 0.25);
    let idle = Idle::new(rng);
    let motion = animate(&skel, job.frames, |p, t| {
        let frame = plan.route.at_time(t);
        let a = plan.activity(t);
        let c = plan.cycles(t);
        let rest = 1.0 - a;
        let cycle_y = if run { -cwave(2.0 * (c - gait.duty / 2.0)) } else { cwave(2.0 * (c - gait.duty / 2.0)) };
        let y = a * (walk_y + bob * cycle_y) + rest * (stand_y + 0.004 * r * idle.breath(t));
        // Standing, the weight moves over one leg and back; the pelvis drops on the free side.
        // A pause inside a walk is too short for shifting the weight about.
        let shift = rest * idle.shift(t) * if job.action == Action::Idle { 1.0 } else { 0.15 };
        let yaw = -yaw_amp * a * cwave(c);
        let root = frame.rot() * ry(yaw) * rx(lean * a + 2.0 * rest) * rz(-3.0 * shift);
        p.root(frame.apply(v3(0.035 * k * shift, y, 0.0)), root);
        for &j in &spine {
            p.local(j, ry(-0.55 * yaw) * rx(-(lean * a) / 3.0 + 0.8 * rest * idle.breath(t)) * rz(shift));
        }
        let look = rest * idle.look(t);
        p.world(neck, frame.rot() * ry(0.4 * look) * rx(-3.0));
        p.world(head, frame.rot() * ry(look) * rx(2.0 * a * wave(2.0 * c) + 4.0 * rest * wave(t / 6.0)));
        for (side, &(arm, fore, hand)) in arms.iter().enumerate() {
            let swing = arm_amp * a * cwave(c - touchdown[side]);
            let bend = elbow * a + 8.0 * rest + 8.0 * a * (1.0 - cwave(c - touchdown[side])) / 2.0;
            let hang = -80.0 + 4.0 * rest * idle.breath(t);
            let (upper, lower) = (rx(swing) * rz(hang), rx(swing - bend) * rz(hang));
            let (upper, lower) = if side == 0 { (upper, lower) } else { (mirror(upper), mirror(lower)) };
            // The rotations are meant for a T-pose arm: an A-pose arm is first raised to it.
            let (upper, lower) = match arm_rest {
                Some(r) => (upper * r[side].inverse(), lower * r[side].inverse()),
                None => (upper, lower),
            };
            p.world(arm, frame.rot() * upper);
            p.world(fore, frame.rot() * lower);
            p.world(hand, frame.rot() * lower);
        }
        for (side, &(leg, toe, _)) in legs.iter().enumerate() {
            let f = feet[side].at(t);
            // Heel up once the body has passed over the planted ball (late stance), as in the
            // constant-speed walk but measured from the body, so a standing foot stays flat.
            let home = frame.apply(v3(legs[side].2, 0.0, ball.z));
            let behind = (home - f.at).dot(frame.rot() * DVec3::Z) / gait.half_reach();
            let (pitch, toe_follow) = if f.swing == 0.0 {
                (heel_rise * smoothstep((behind - 0.2) / 0.8), 0.0)
            } else {
                let u = f.swing;
                let lift_toes = 12.0 * (std::f64::consts::PI * u).sin().powi(2);
                (heel_rise * (1.0 - smoothstep(u / 0.5)) - lift_toes, smoothstep(u / 0.3))
            };
            let turn = ry(f.yaw.to_degrees());
            let foot_rot = turn * rx(pitch);
            let ball_at = f.at + v3(0.0, ankle_y + ball.y, 0.0);
            p.leg(&leg, ball_at - foot_rot * ball, turn * DVec3::Z, foot_rot);
            p.world(toe, turn * rx(pitch * toe_follow));
        }
    });
    let boundaries = plan.boundaries(&feet.iter().collect::<Vec<_>>());
    TrainingClip { skeleton: skel, motion, boundaries }
}

pub(super) fn quadruped(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    four_legged(job, false, rng)
}

pub(super) fn dragon(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    four_legged(job, true, rng)
}

/// Walk: lateral sequence (LH, LF, RH, RF a quarter apart). Run: a trot (diagonal pairs), with
/// a shorter stance and longer stride. Idle: standing, looking around, tail swishing, wings
/// (dragon) half folded and stirring.
fn four_legged(job: &Job, dragon: bool, rng: &mut SplitMix64) -> TrainingClip {
    let shape = job.shape;
    let body = quad_training_body(dragon, &shape, &job.rig);
    let QuadBody { skel, spine, neck, head, jaw, ears, tail, wings, legs, hip_drop, bone, ankle_y } = body;
    let k = if dragon { 2.4 } else { 1.0 } * shape.size;
    let r = k * shape.limbs;
    let trot = job.action == Action::Run;
    let gait = if trot {
        Gait { period: rng.vary(0.55, 0.05), duty: rng.vary(0.45, 0.03), stride: rng.vary(0.9, 0.15), lift: rng.vary(0.08, 0.1) }
    } else {
        Gait { period: rng.vary(0.9, 0.06), duty: rng.vary(0.68, 0.03), stride: rng.vary(0.5, 0.15), lift: rng.vary(0.06, 0.1) }
    };
    // Dragons are bigger than their legs suggest: Froude-scale from the dog on leg length.
    let gait = froude(gait, r);
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    let jitter = |rng: &mut SplitMix64| rng.range(-0.02, 0.02);
    // In `legs` order: LF, RF, LH, RH.
    let touchdown =
        if trot { [0.5 + jitter(rng), jitter(rng), 0.0, 0.5 + jitter(rng)] } else { [0.25 + jitter(rng), 0.75 + jitter(rng), 0.0, 0.5 + jitter(rng)] };
    let feet: Vec<_> =
        legs.iter().zip(touchdown).map(|(&(_, x, z, _), td)| plan.foot(job, FootSpec { home: v3(x, 0.0, z), lag: 0.0, touchdown: td })).collect();
    let bob = if trot { 0.02 } else { 0.008 } * r;
    let hip_y = ankle_y + stand_height(2.0 * bone, gait.half_reach(), 0.95);
    let walk_y = hip_y + hip_drop - bob;
    let stand_y = ankle_y + stand_height(2.0 * bone, 0.5 * gait.half_reach(), 0.95) + hip_drop - bob;
    let roll_amp = rng.vary(1.5, 0.2);
    let yaw_amp = rng.vary(2.0, 0.2);
    let nod = rng.vary(if trot { 5.0 } else { 3.0 }, 0.2);
    let tail_sway = rng.vary(if dragon { 9.0 } else { 12.0 }, 0.2);
    let flap = rng.vary(30.0, 0.15);
    let idle = Idle::new(rng);
    let wag_period = rng.range(0.8, 1.6) * r.sqrt();
    let n_spine = spine.len() as f64;
    let motion = animate(&skel, job.frames, |p, t| {
        let frame = plan.route.at_time(t);
        let a = plan.activity(t);
        let rest = 1.0 - a;
        let c = plan.cycles(t);
        let lh = touchdown[2];
        let y = a * (walk_y + bob * cwave(2.0 * (c - lh - gait.duty / 2.0))) + rest * (stand_y + 0.003 * r * idle.breath(t));
        // A pause inside a walk is too short for shifting the weight about.
        let shift = rest * idle.shift(t) * if job.action == Action::Idle { 1.0 } else { 0.15 };
        let roll = roll_amp * a * wave(c - lh) + 1.5 * shift;
        let yaw = yaw_amp * a * wave(c - lh + 0.25);
        p.root(frame.apply(v3(0.01 * r * shift, y, 0.0)), frame.rot() * ry(yaw) * rz(roll));
        for &j in &spine {
            p.local(j, ry(-yaw / n_spine) * rz(-roll / n_spine) * rx(0.6 * rest * idle.breath(t) / n_spine));
        }
        // The neck turns with the look; the head adds the rest and stays level.
        let look = rest * idle.look(t);
        let n_neck = neck.len() as f64;
        for (i, &j) in neck.iter().enumerate() {
            p.local(j, ry(0.6 * look / n_neck) * rx(nod * a * wave(2.0 * c - 0.1 * i as f64) + 4.0 * rest / n_neck));
        }
        p.local(head, ry(0.4 * look) * rx(-3.0 * rest * wave(t / 5.0)));
        // The mouth pants while moving and opens now and then standing; the ears turn with
        // the look and flick on their own slow rhythm.
        if let Some(jaw) = jaw {
            let pant = 6.0 * a * (0.5 + 0.5 * wave(2.0 * c)) + 10.0 * rest * smoothstep(wave(t / 4.3 + 0.2));
            p.local(jaw, rx(2.0 + pant));
        }
        for (side, &e) in ears.iter().enumerate() {
            let flick = 15.0 * smoothstep(2.0 * wave(t / 2.7 + 0.37 * side as f64) - 1.0);
            let q = ry(0.3 * look) * rz(-flick) * rx(-5.0 * a);
            p.local(e, if side == 0 { q } else { mirror(q) });
        }
        // Walking, the tail lags the hips; standing, it swishes on its own slower rhythm.
        let n_tail = tail.len() as f64;
        // A degree of droop per joint, spread thinner on tails longer than 12 joints.
        let droop = if tail.len() > 12 { -12.0 / n_tail } else { -1.0 };
        for (i, &j) in tail.iter().enumerate() {
            let x = (i + 1) as f64;
            let sway = tail_sway * (0.6 + 0.4 * i as f64 / n_tail) * 4.0 / n_tail.max(1.0);
            let walk = a * wave(c - 0.12 * x * 4.0 / n_tail);
            let swish = rest * 0.7 * wave(t / wag_period - 0.12 * x * 4.0 / n_tail);
            p.local(j, ry(sway * (walk + swish)) * rx(if i == 0 { 8.0 } else { droop }));
        }
        for (side, w) in wings.iter().enumerate() {
            // Flapping while moving (for balance), folded and stirring while standing.
            let beat = if trot { 2.0 * c } else { c };
            let f = flap * a;
            // Folding is a Z: the arm swings back, the forearm forward along it, the hand back.
            let fold = rest;
            let q = [
                rz(15.0 + f * wave(beat) + 5.0 * rest * idle.breath(t)) * ry(70.0 * fold),
                rz(-0.35 * f * wave(beat - 0.1)) * ry(10.0 * a * (1.0 - cwave(beat)) / 2.0 - 150.0 * fold),
                rz(-0.3 * f * wave(beat - 0.2)) * ry(140.0 * fold),
            ];
            for (i, &j) in w.iter().enumerate() {
                p.local(j, if side == 0 { q[i] } else { mirror(q[i]) });
            }
        }
        for (i, (leg, _, _, pole)) in legs.iter().enumerate() {
            let f = feet[i].at(t);
            let turn = ry(f.yaw.to_degrees());
            let target = f.at + v3(0.0, ankle_y, 0.0);
            let paw = rx(-10.0 * (std::f64::consts::PI * f.swing).sin());
            p.leg(leg, target, turn * *pole, turn * paw);
        }
    });
    let boundaries = plan.boundaries(&feet.iter().collect::<Vec<_>>());
    TrainingClip { skeleton: skel, motion, boundaries }
}
