//! Training actions of the bird, the snake and the fish.
//!
//! The bird walks like the example one (legs from a `Plan`, the head held still in the world
//! and thrust forward once a step), hops with both feet together and a flight phase, and
//! idles by looking around and pecking at the ground. The snake's body lies on one curve — the
//! route with a sine laid across it — and slides along it without slipping, so turning and
//! speed changes come for free; idling, it lies still and sways its raised head. The fish
//! beats a carangiform wave whose frequency and amplitude set its speed; turning bends the body
//! into the turn; idling, it hovers, sculling with its fins.

use super::bird::{bird_body, BirdBody};
use super::route::FootSpec;
use super::training::{Action, Job, Plan, TrainingClip};
use super::undulating::{fish_body, snake_body, FishBody, SnakeBody};
use super::*;

pub(super) fn bird(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let shape = job.shape;
    let body = bird_body(&shape);
    let BirdBody { skel, spine, chest, neck1, neck2, head, wings, legs, tail: [tail1, tail2], hip_drop, shin, tarsus, ankle_y } = body;
    let r = shape.size * shape.limbs;
    let hop = job.action == Action::Hop;
    let gait = if hop {
        Gait { period: rng.vary(0.42, 0.06), duty: rng.vary(0.42, 0.03), stride: rng.vary(0.2, 0.15), lift: rng.vary(0.06, 0.1) }
    } else {
        Gait { period: rng.vary(0.5, 0.06), duty: rng.vary(0.6, 0.03), stride: rng.vary(0.13, 0.15), lift: rng.vary(0.03, 0.1) }
    };
    let gait = Gait { period: gait.period * r.sqrt(), stride: gait.stride * r, lift: gait.lift * r, ..gait };
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    let touchdown = if hop { [0.0, rng.range(0.0, 0.02)] } else { [0.0, 0.5 + rng.range(-0.02, 0.02)] };
    let feet: Vec<_> = legs.iter().zip(touchdown).map(|(&(_, x), td)| plan.foot(job, FootSpec { home: v3(x, 0.0, 0.0), lag: 0.0, touchdown: td })).collect();
    let leg_len = shin.length() + tarsus.length();
    let bob = 0.004 * r;
    let strike_y = ankle_y + stand_height(leg_len, gait.half_reach(), 0.93) + hip_drop;
    // Walking bobs twice a cycle, highest at mid-stance; hopping once, lowest at mid-stance
    // (the legs absorb the landing) and highest in flight.
    let hop_amp = 0.025 * r;
    let walk_y = if hop { strike_y + hop_amp * (TAU * gait.duty).cos() } else { strike_y - bob };
    let stand_y = ankle_y + stand_height(leg_len, 0.5 * gait.half_reach(), 0.93) + hip_drop - bob;
    let flap = rng.vary(if hop { 55.0 } else { 45.0 }, 0.12);
    let waddle = rng.vary(5.0, 0.2);
    let neck_leg = Leg { upper: neck1, lower: neck2, tip: Some(head), rest_pole: DVec3::NEG_Z };
    let rest_pos = skel.rest_positions();
    let head_rest = rest_pos[head] - rest_pos[0];
    let hold = 0.55;
    // Idle: look around for a while, then bend down and peck a few times.
    let idle_period = rng.range(2.6, 3.6);
    let look = rng.range(40.0, 70.0);
    let motion = animate(&skel, job.frames, |p, t| {
        let frame = plan.route.at_time(t);
        let (a, c) = (plan.activity(t), plan.cycles(t));
        let rest = 1.0 - a;
        let u = (t / idle_period).rem_euclid(1.0);
        let bend = rest * smoothstep((u - 0.55) / 0.1) * (1.0 - smoothstep((u - 0.9) / 0.08));
        let pecks = bend * wave(3.0 * (u - 0.65)).max(0.0);
        let cycle_y = if hop { -cwave(c - gait.duty / 2.0) } else { cwave(2.0 * (c - gait.duty / 2.0)) };
        let bob_amp = if hop { hop_amp } else { bob };
        let y = a * (walk_y + bob_amp * cycle_y) + rest * (stand_y - 0.01 * r * bend);
        let x = if hop { 0.0 } else { 0.004 * r * a * wave(c - touchdown[0] - 0.25) };
        let sway = if hop { 0.0 } else { waddle * a * wave(c - 0.25) };
        p.root(frame.apply(v3(x, y, 0.0)), frame.rot() * rz(sway) * rx(6.0 + 30.0 * bend));
        p.local(spine, rx(-3.0 + 8.0 * bend));
        p.local(chest, rx(-3.0 + 8.0 * bend));
        // Walking head bob: the head holds still on the track for `hold` of a step, then
        // thrusts to catch up (see `bird::bird`); the track position is taken at a time that
        // steps, so stops and curves are followed.
        let step = gait.period / 2.0;
        let (n, phi) = ((c * 2.0).floor(), c * 2.0 - (c * 2.0).floor());
        let g = if hop || phi < hold {
            0.0
        } else {
            let v = (phi - hold) / (1.0 - hold);
            v - wave(v) / TAU
        };
        let held = plan.clock.real(step * (n + g + hold / 2.0));
        let head_frame = if hop { frame } else { plan.route.at_arc(plan.route.s_at(held)) };
        let mut target = head_frame.apply(v3(x, 0.0, head_rest.z));
        target.y = y + head_rest.y - 0.022 * r;
        // Pecking: the head goes down towards the ground in front of the feet (as far as the
        // neck reaches; the body tips forward to help).
        let ground = frame.apply(v3(0.0, 0.01 * r, head_rest.z + 0.06 * r));
        let target = target.lerp(ground, 0.5 * bend + 0.5 * pecks);
        let glance = rest * (1.0 - bend) * look * wave(t / idle_period * 2.0 + 0.1).powi(3);
        let head_rot = frame.rot() * ry(glance) * rx(45.0 * bend);
        p.leg(&neck_leg, target, frame.rot() * DVec3::NEG_Z, head_rot);
        for (i, w) in wings.iter().enumerate() {
            // Flapping as the example bird does while walking, a full beat per hop, folded
            // and ruffled while standing.
            let beat = if hop { c } else { 2.0 * c };
            // Hopping needs the wings for balance; walking birds keep them mostly folded
            // with a small flick per step.
            let (f, fold) = if hop { (flap * a, 0.3 + 0.7 * rest) } else { (0.2 * flap * a, 0.8 + 0.2 * rest) };
            // Folded, the wing lies in a Z against the body (arm back, forearm forward, hand
            // back), with a ruffle now and then.
            let q = [
                rz(10.0 + f * wave(beat) + 3.0 * rest * wave(t / 1.7)) * ry(-8.0 * a * cwave(beat) + 80.0 * fold),
                rz(-0.25 * f * wave(beat - 0.12)) * ry(12.0 * a * (1.0 - cwave(beat)) / 2.0 - 160.0 * fold),
                rz(-0.2 * f * wave(beat - 0.22)) * ry(150.0 * fold),
            ];
            for (k, &j) in w.iter().enumerate() {
                p.local(j, if i == 0 { q[k] } else { mirror(q[k]) });
            }
        }
        p.local(tail1, rx(8.0 + 4.0 * a * wave(2.0 * c) - 10.0 * bend));
        p.local(tail2, rx(4.0 * a * wave(2.0 * c - 0.2) + 3.0 * rest * wave(t / 1.3)));
        for (k, &(leg, _)) in legs.iter().enumerate() {
            let f = feet[k].at(t);
            let turn = ry(f.yaw.to_degrees());
            let lift = f.at.y;
            let target = f.at + v3(0.0, ankle_y, 0.0);
            p.leg(&leg, target, turn * DVec3::NEG_Z, turn * rx(15.0 * (lift / gait.lift).min(1.0)));
        }
    });
    let boundaries = plan.boundaries(&feet.iter().collect::<Vec<_>>());
    TrainingClip { skeleton: skel, motion, boundaries }
}

/// A curve sampled by its own arc length.
struct Curve {
    sigma: Vec<f64>,
    points: Vec<DVec3>,
}

impl Curve {
    fn at(&self, sigma: f64) -> DVec3 {
        let last = self.sigma.len() - 1;
        let j = self.sigma.partition_point(|&x| x < sigma).clamp(1, last);
        let (a, b) = (self.sigma[j - 1], self.sigma[j]);
        let u = if b > a { ((sigma - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
        self.points[j - 1].lerp(self.points[j], u)
    }
}

pub(super) fn snake(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let shape = job.shape;
    let SnakeBody { skel, radius, jaw, neck, body } = snake_body(&shape);
    let k = shape.size;
    let rest = skel.rest_positions();
    let arc: Vec<f64> = rest.iter().map(|p| p.z - rest[0].z).collect();
    let last = *body.last().expect("the neck is there");
    let tail_end = arc[last] + skel.joints[last].end_sites.first().map_or(0.0, |e| e.z);
    let fast = job.action == Action::UndulateFast;
    let wavelength = rng.vary(if fast { 0.6 } else { 0.75 }, 0.08) * k * shape.tail;
    let speed = rng.vary(if fast { 0.9 } else { 0.45 }, 0.1) * k.sqrt();
    let period = wavelength / speed;
    let gait = Gait { period, duty: 0.5, stride: wavelength, lift: 0.0 };
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    // Lateral amplitude of a serpenoid with heading swing `amplitude`, to first order.
    let amplitude = rng.vary(if fast { 32.0 } else { 38.0 }, 0.1).to_radians();
    let width = wavelength * amplitude / TAU;
    // The body's curve: the route with a sine across it, sampled from behind the tail at t = 0
    // to beyond the head at the end.
    let (from, to) = (tail_end - 0.2 * k, plan.route.s_at(job.duration()) + 0.2 * k);
    let step = 0.002 * k;
    let count = ((to - from) / step).ceil() as usize + 2;
    let mut points = Vec::with_capacity(count);
    for i in 0..count {
        let u = from + i as f64 * step;
        points.push(plan.route.at_arc(u).apply(v3(width * wave(u / wavelength), 0.0, 0.0)));
    }
    let mut sigma = vec![0.0];
    for w in points.windows(2) {
        sigma.push(sigma.last().copied().unwrap_or(0.0) + w[0].distance(w[1]));
    }
    let curve = Curve { sigma, points };
    // Arc length on the curve of route parameter u.
    let sigma_of = |u: f64| {
        let x = ((u - from) / step).clamp(0.0, (count - 1) as f64);
        let i = (x.floor() as usize).min(count - 2);
        curve.sigma[i] + (curve.sigma[i + 1] - curve.sigma[i]) * (x - i as f64)
    };
    let head_lift = rng.vary(0.04, 0.2) * k;
    let idle_lift = rng.vary(0.05, 0.2) * k;
    let look = rng.range(20.0, 35.0);
    let motion = animate(&skel, job.frames, |p, t| {
        let rest_w = 1.0 - plan.activity(t);
        let lift = head_lift + rest_w * idle_lift;
        // The head and neck ride above the curve, the body lies on it.
        let height = |a: f64| radius + lift * smoothstep((a + 0.2 * k) / (0.14 * k));
        let s0 = sigma_of(plan.route.s_at(t));
        let at = |a: f64| curve.at(s0 + a) + DVec3::Y * height(a);
        let flat = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
        let forward = aim(DVec3::NEG_Z, DVec3::Y, flat(at(arc[neck]) - at(0.0)), DVec3::Y);
        // Idling, the raised head sways and looks about, the tongue (jaw) flicks.
        let sway = rest_w * look * wave(t / 3.1) * cwave(t / 7.3);
        p.root(at(0.0) + forward * v3(0.01 * k * rest_w * wave(t / 3.1), 0.0, 0.0), forward * ry(sway));
        p.local(jaw, rx(6.0 * wave(2.0 * t / period * (1.0 - rest_w) + rest_w * t / 0.7).max(0.0)));
        for (i, &j) in body.iter().enumerate() {
            let next = if i + 1 < body.len() { arc[body[i + 1]] } else { tail_end };
            p.world(j, aim(DVec3::NEG_Z, DVec3::Y, at(next) - at(arc[j]), DVec3::Y));
        }
    });
    TrainingClip { skeleton: skel, motion, boundaries: Vec::new() }
}

pub(super) fn fish(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let shape = job.shape;
    let depth = 0.5 * shape.size.max(1.0);
    let FishBody { skel, head, jaw, fins, pelvic, dorsal, spine, length } = fish_body(&shape, depth);
    let fast = job.action == Action::UndulateFast;
    let idle = job.action == Action::Idle;
    let beat = rng.vary(
        if fast {
            0.25
        } else if idle {
            1.4
        } else {
            0.4
        },
        0.08,
    ) * shape.size.sqrt();
    let speed = rng.vary(if fast { 2.0 } else { 0.9 }, 0.1) * length;
    let amplitude = rng.vary(
        if fast {
            18.0
        } else if idle {
            4.0
        } else {
            14.0
        },
        0.1,
    );
    let gait = Gait { period: beat, duty: 0.5, stride: speed * beat, lift: 0.0 };
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    let lambda = rng.vary(5.5, 0.08) * spine.len() as f64 / 6.0;
    // Turning bends the body into the turn: a share of the heading rate per joint.
    let turn_rate = {
        let t = job.duration();
        (plan.route.at_time(t).yaw - plan.route.at_time(0.0).yaw) / t
    };
    let bend = (turn_rate.to_degrees() * 0.12).clamp(-6.0, 6.0);
    let drift = rng.range(0.0, 1.0);
    let motion = animate(&skel, job.frames, |p, t| {
        let frame = plan.route.at_time(t);
        let c = t / beat;
        let sway = 0.006 * shape.size * wave(c + 0.25);
        // Hovering, the fish drifts a little up and down and side to side, and no further.
        let hover = if idle { v3(0.01 * wave(t / 4.3 + drift), 0.01 * wave(t / 3.7), 0.01 * wave(t / 5.1)) } else { DVec3::ZERO };
        let at = frame.apply(v3(sway, depth + 0.004 * wave(0.5 * c), 0.0) + hover);
        let idle_yaw = if idle { 8.0 * wave(t / 6.0 + drift) } else { 0.0 };
        p.root(at, frame.rot() * ry(idle_yaw - 0.35 * amplitude * wave(c) - 2.0 * bend) * rz(1.5 * wave(c)));
        p.local(head, ry(0.15 * amplitude * wave(c)));
        p.local(jaw, rx(3.0 + 3.0 * wave(if idle { t / 1.1 } else { 0.5 * c })));
        let n = spine.len() as f64;
        for (k, &j) in spine.iter().enumerate() {
            let x = (k + 1) as f64 / n;
            let a = amplitude * (0.25 + 0.75 * x * x) * 6.0 / n;
            p.local(j, ry(a * wave(c - (k + 1) as f64 / lambda) + bend));
        }
        // Pectoral fins: small steering strokes when cruising, wide sculling when hovering.
        let scull = if idle { 35.0 } else { 20.0 };
        for (i, &f) in fins.iter().enumerate() {
            let fin_c = if idle { t / 0.9 } else { c };
            let q = rz(scull * wave(fin_c)) * ry(10.0 * cwave(fin_c));
            p.local(f, if i == 0 { q } else { mirror(q) });
        }
        for (i, &f) in pelvic.iter().enumerate() {
            let q = rz(8.0 * wave(c - 0.3));
            p.local(f, if i == 0 { q } else { mirror(q) });
        }
        p.local(dorsal, rz(5.0 * wave(c - 0.4)));
    });
    TrainingClip { skeleton: skel, motion, boundaries: Vec::new() }
}
