//! Training actions of the many-legged walkers: spider, crab, centipede.
//!
//! Bodies and leg solving are `arthropod`'s; feet come from a `Plan` so walks can stop and
//! curve. Run is a fast walk: shorter stance (duty below one half, so fewer feet are down at a
//! time), longer and quicker strides, the same phase pattern. Idle keeps every foot planted
//! and moves what arthropods move when they wait: a spider taps with its front legs and pulses
//! its abdomen, a crab picks at the ground with its claws and waves its eyes, a centipede
//! sweeps its antennae and turns its head.

use super::arthropod::{centipede_body, crab_body, place_jointed_leg, spider_body, CentipedeBody, CrabBody, SpiderBody};
use super::route::FootSpec;
use super::training::{Action, Job, Plan, TrainingClip};
use super::*;

fn scaled(gait: Gait, r: f64) -> Gait {
    Gait { period: gait.period * r.sqrt(), stride: gait.stride * r, lift: gait.lift * r, ..gait }
}

pub(super) fn spider(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let SpiderBody { skel, body_y, abdomen, fangs, legs } = spider_body(&job.shape);
    let r = job.shape.size * job.shape.limbs;
    let fast = job.action == Action::Run;
    let gait = if fast {
        Gait { period: rng.vary(0.4, 0.06), duty: rng.vary(0.45, 0.03), stride: rng.vary(0.15, 0.15), lift: rng.vary(0.04, 0.1) }
    } else {
        Gait { period: rng.vary(0.6, 0.06), duty: rng.vary(0.55, 0.03), stride: rng.vary(0.11, 0.15), lift: rng.vary(0.035, 0.1) }
    };
    let gait = scaled(gait, r);
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    // Alternating tetrapod groups, hind legs of a group leading a little.
    let feet: Vec<_> = legs
        .iter()
        .map(|&(ref leg, left, i)| {
            let group = if (i % 2 == 0) == left { 0.0 } else { 0.5 };
            let touchdown = group - 0.04 * i as f64 + rng.range(-0.02, 0.02);
            plan.foot(job, FootSpec { home: leg.home, lag: 0.0, touchdown })
        })
        .collect();
    let bob = 0.004 * r;
    let sway = rng.vary(3.0, 0.2);
    let tap_period = rng.range(1.6, 2.4);
    let breath = rng.range(1.2, 1.8);
    let motion = animate(&skel, job.frames, |p, t| {
        let frame = plan.route.at_time(t);
        let (a, c) = (plan.activity(t), plan.cycles(t));
        let rest = 1.0 - a;
        let y = body_y - bob * a + bob * a * cwave(2.0 * c) - 0.006 * r * rest;
        p.root(frame.apply(v3(0.0, y, 0.0)), frame.rot() * ry(sway * 0.3 * a * wave(c)) * rx(-2.0 - 2.0 * rest));
        let pulse = rest * wave(t / breath);
        p.local(abdomen, ry(sway * a * wave(c - 0.2)) * rx(3.0 * a * wave(2.0 * c) + 4.0 * pulse));
        for &f in &fangs {
            p.local(f, rx(10.0 * a * wave(2.0 * c).max(0.0) + 12.0 * rest * wave(t / 0.9).max(0.0)));
        }
        for (k, (leg, left, i)) in legs.iter().enumerate() {
            let mut f = feet[k].at(t);
            // Waiting, the front legs tap in turn: up and down on the spot.
            if *i == 0 && job.action == Action::Idle {
                let phase = t / tap_period + if *left { 0.0 } else { 0.5 };
                f.at.y += rest * 0.035 * r * wave(phase).max(0.0).powi(2);
            }
            place_jointed_leg(p, leg, f.at, ry(f.yaw.to_degrees()));
        }
    });
    let boundaries = plan.boundaries(&feet.iter().collect::<Vec<_>>());
    TrainingClip { skeleton: skel, motion, boundaries }
}

pub(super) fn crab(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let CrabBody { skel, body_y, eyes, claws, legs } = crab_body(&job.shape);
    let r = job.shape.size * job.shape.limbs;
    let fast = job.action == Action::Run;
    let gait = if fast {
        Gait { period: rng.vary(0.38, 0.06), duty: rng.vary(0.45, 0.03), stride: rng.vary(0.14, 0.15), lift: rng.vary(0.045, 0.1) }
    } else {
        Gait { period: rng.vary(0.55, 0.06), duty: rng.vary(0.55, 0.03), stride: rng.vary(0.1, 0.15), lift: rng.vary(0.04, 0.1) }
    };
    let gait = scaled(gait, r);
    // Facing -x and walking towards its left, as the example crab does.
    let plan = Plan::new(job, gait, -std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2, rng);
    let feet: Vec<_> = legs
        .iter()
        .map(|&(ref leg, left, i)| {
            let touchdown = (if (i % 2 == 0) == left { 0.0 } else { 0.5 }) + rng.range(-0.03, 0.03);
            plan.foot(job, FootSpec { home: leg.home, lag: 0.0, touchdown })
        })
        .collect();
    let wave_claw = rng.vary(12.0, 0.2);
    let pick = rng.range(1.1, 1.6);
    let motion = animate(&skel, job.frames, |p, t| {
        let frame = plan.route.at_time(t);
        let (a, c) = (plan.activity(t), plan.cycles(t));
        let rest = 1.0 - a;
        let y = body_y - 0.004 * r + 0.004 * r * (a * cwave(2.0 * c) + rest * 0.5 * wave(t / 2.3));
        p.root(frame.apply(v3(0.0, y, 0.0)), frame.rot() * rz(2.0 * a * wave(c)));
        for (i, &e) in eyes.iter().enumerate() {
            p.local(e, rx(8.0 * a * wave(c) + 15.0 * rest * wave(t / 1.7 + 0.3 * i as f64)));
        }
        for (k, &(merus, carpus, finger)) in claws.iter().enumerate() {
            // Walking: claws held up, waving out of step. Waiting: each claw in turn reaches
            // down and forward to pick at the ground, then lifts to the mouth.
            let reach = rest * wave(t / pick + 0.5 * k as f64).max(0.0);
            let q = [
                ry(-20.0) * rz(10.0 + wave_claw * a * wave(c + 0.5 * k as f64) - 25.0 * reach),
                ry(35.0 - 30.0 * reach) * rx(-15.0 + 35.0 * reach),
                rx(-12.0 * (0.5 + 0.5 * wave(2.0 * c * a + 2.0 * t / pick * rest))),
            ];
            let q = if k == 0 { q } else { q.map(mirror) };
            p.local(merus, q[0]);
            p.local(carpus, q[1]);
            p.local(finger, q[2]);
        }
        for (k, (leg, _, _)) in legs.iter().enumerate() {
            let f = feet[k].at(t);
            place_jointed_leg(p, leg, f.at, ry(f.yaw.to_degrees()));
        }
    });
    let boundaries = plan.boundaries(&feet.iter().collect::<Vec<_>>());
    TrainingClip { skeleton: skel, motion, boundaries }
}

pub(super) fn centipede(job: &Job, rng: &mut SplitMix64) -> TrainingClip {
    let CentipedeBody { skel, body_y, seg_len, head, antennae, segments, tail, legs, claw } = centipede_body(&job.shape);
    let r = job.shape.size * job.shape.limbs;
    let fast = job.action == Action::Run;
    let gait = if fast {
        Gait { period: rng.vary(0.28, 0.06), duty: rng.vary(0.45, 0.03), stride: rng.vary(0.07, 0.15), lift: rng.vary(0.018, 0.1) }
    } else {
        Gait { period: rng.vary(0.36, 0.06), duty: rng.vary(0.55, 0.03), stride: rng.vary(0.05, 0.15), lift: rng.vary(0.015, 0.1) }
    };
    let gait = scaled(gait, r);
    let plan = Plan::new(job, gait, 0.0, 0.0, rng);
    // Retrograde metachronal wave: each pair lands `lag` of a cycle after the pair in front.
    let wavelength = rng.vary(if fast { 5.0 } else { 7.0 }, 0.1);
    let lag = 1.0 / wavelength;
    let feet: Vec<_> = legs
        .iter()
        .map(|&(_, home, k, left)| {
            let touchdown = k as f64 * lag + if left { 0.0 } else { 0.5 } + rng.range(-0.015, 0.015);
            plan.foot(job, FootSpec { home, lag: seg_len * k as f64, touchdown })
        })
        .collect();
    let sway = rng.vary(0.006, 0.2) * job.shape.size;
    let n = segments.len();
    let look = rng.range(15.0, 30.0);
    let motion = animate(&skel, job.frames, |p, t| {
        let (a, c) = (plan.activity(t), plan.cycles(t));
        let rest = 1.0 - a;
        let s = plan.route.s_at(t);
        // Segment centres ride the track behind the head, with the body's lateral wave on top.
        let centre = |k: usize| {
            let side = sway * a * wave(c - k as f64 * lag) + 0.3 * sway * rest * wave(t / 3.0 - 0.05 * k as f64);
            plan.route.at_arc(s - seg_len * k as f64).apply(v3(side, body_y, 0.0))
        };
        let along = |k: usize| aim(DVec3::NEG_Z, DVec3::Y, centre(k + 1) - centre(k), DVec3::Y);
        p.root(centre(0), along(0));
        p.local(head, ry(rest * look * wave(t / 2.7)) * rx(-4.0 + 6.0 * rest * wave(t / 1.9).max(0.0)));
        for (i, &ant) in antennae.iter().enumerate() {
            let amp = 10.0 + 15.0 * rest;
            let q = ry(amp * wave(c * a + t / 1.3 * rest + 0.3 * i as f64)) * rx(-8.0 * wave(2.0 * c * a + t * rest));
            p.local(ant, if i == 0 { q } else { mirror(q) });
        }
        for (k, &seg) in segments.iter().enumerate().skip(1) {
            p.world(seg, along(k));
        }
        p.world(tail, along(n));
        for (i, (leg, _, _, _)) in legs.iter().enumerate() {
            let f = feet[i].at(t);
            let turn = ry(f.yaw.to_degrees());
            p.leg(leg, f.at - turn * claw, DVec3::Y, turn);
        }
    });
    let boundaries = plan.boundaries(&feet.iter().collect::<Vec<_>>());
    TrainingClip { skeleton: skel, motion, boundaries }
}
