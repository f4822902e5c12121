//! Limbless movers: the snake and the fish.
//!
//! Both propel themselves with a wave travelling backwards along the body, which is the case
//! that skeleton tools built for legs get wrong (no feet, a root in the middle of a long chain,
//! motion almost all in yaw). The snake's wave must not slip on the ground, so its body follows
//! one serpenoid path: every joint sits on the curve its head traced. A fish pushes against
//! water and may slip, so its wave is the classic carangiform one — segment k yaws by
//! A_k sin(2π(f t − k/λ)) with amplitude growing towards the tail — applied directly as local
//! rotations.

use super::*;

/// A planar curve sampled by arc length: heading θ(s) = α cos(2π s / Λ) (the serpenoid curve,
/// the shape real snakes take in lateral undulation), integrated once into positions.
struct Serpenoid {
    start: f64,
    step: f64,
    points: Vec<DVec3>,
}

impl Serpenoid {
    fn new(amplitude_deg: f64, wavelength: f64, start: f64, end: f64) -> Serpenoid {
        let step = 0.001;
        let n = ((end - start) / step).ceil() as usize + 2;
        // Cosine, so the lateral offset is a sine about x = 0 and the snake travels along +z.
        let heading = |s: f64| amplitude_deg.to_radians() * cwave(s / wavelength);
        let mut points = Vec::with_capacity(n);
        let mut at = DVec3::ZERO;
        for i in 0..n {
            points.push(at);
            // Midpoint heading: second-order accurate, plenty at a millimetre step.
            let h = heading(start + (i as f64 + 0.5) * step);
            at += v3(h.sin(), 0.0, h.cos()) * step;
        }
        // Re-anchor so that arc length 0 is at the origin.
        let origin = Serpenoid { start, step, points: points.clone() }.at(0.0);
        Serpenoid { start, step, points: points.into_iter().map(|p| p - origin).collect() }
    }

    fn at(&self, s: f64) -> DVec3 {
        let x = ((s - self.start) / self.step).clamp(0.0, (self.points.len() - 2) as f64);
        let i = x.floor() as usize;
        self.points[i].lerp(self.points[i + 1], x - i as f64)
    }
}

/// The snake's joints: the jaw, and the body chain from the neck to the tail tip.
pub(super) struct SnakeBody {
    pub skel: Skeleton,
    pub radius: f64,
    pub jaw: usize,
    pub neck: usize,
    pub body: Vec<usize>,
}

/// The snake with `shape.body_joints` spine and `shape.tail_joints` tail joints, scaled by
/// `shape` (`tail` stretches the vertebrae, `neck` the head and neck).
pub(super) fn snake_body(shape: &Proportions) -> SnakeBody {
    let layout = Layout { root_order: "YZX", joint_order: "YZX", all_positions: false };
    let (k, n, tl) = (shape.size, shape.size * shape.neck, shape.size * shape.tail);
    let radius = 0.03 * k;
    let mut b = Builder::new("jtHead", v3(0.0, radius, 0.0), layout);
    let jaw = b.add("jtJaw", 0, v3(0.0, -0.01 * k, 0.02 * k));
    b.end(jaw, v3(0.0, 0.0, 0.05 * n));
    let neck = b.add("jtNeck", 0, v3(0.0, 0.0, -0.06 * n));
    let spine_names: Vec<String> = (1..=shape.body_joints).map(|i| format!("jtSpine{i:02}")).collect();
    let mut body = vec![neck];
    body.extend(b.chain(&spine_names, neck, v3(0.0, 0.0, -0.07 * tl), v3(0.0, 0.0, -0.07 * tl)));
    let tail_names: Vec<String> = (1..=shape.tail_joints).map(|i| format!("jtTail{i:02}")).collect();
    let last = *body.last().expect("the neck is there");
    body.extend(b.chain(&tail_names, last, v3(0.0, 0.0, -0.06 * tl), v3(0.0, 0.0, -0.055 * tl)));
    b.end(*body.last().expect("the neck is there"), v3(0.0, 0.0, -0.05 * tl));
    SnakeBody { skel: b.build(), radius, jaw, neck, body }
}

/// A snake on the ground with its head raised, `jt`-prefixed names. The root is the head, as
/// in many snake rigs; a root in mid-body would also make the straight rest pose look
/// mirror-symmetric front to back to the geometric side rule.
pub(super) fn snake(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let SnakeBody { skel, radius, jaw, neck, body } = snake_body(&training::proportions("snake", 0).expect("snake exists"));

    // Arc length of every joint behind the head (the rest pose is straight along -z).
    let rest = skel.rest_positions();
    let arc: Vec<f64> = rest.iter().map(|p| p.z - rest[0].z).collect();
    let tail_end = arc[*body.last().unwrap()] - 0.05;

    let wavelength = rng.vary(0.75, 0.08);
    let (frames, period) = frames_for(wavelength / rng.vary(0.45, 0.1), 2);
    // No slip: the wave travels back along the body exactly as fast as the body moves forward.
    let speed = wavelength / period;
    let amplitude = rng.vary(38.0, 0.1);
    let travel = speed * frames as f64 * FRAME_TIME;
    let path = Serpenoid::new(amplitude, wavelength, tail_end - 0.1, travel + 0.1);
    let head_lift = rng.vary(0.04, 0.2);
    // The head and neck ride above the path, the body lies on it.
    let height = |a: f64| radius + head_lift * smoothstep((a + 0.2) / 0.14);
    let motion = animate(&skel, frames, |p, t| {
        let s0 = speed * t;
        let at = |a: f64| path.at(s0 + a) + DVec3::Y * height(a);
        let flat = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
        // The head stays level, looking along the path; it flicks its jaw twice per wave.
        p.root(at(0.0), aim(DVec3::NEG_Z, DVec3::Y, flat(at(arc[neck]) - at(0.0)), DVec3::Y));
        p.local(jaw, rx(6.0 * wave(2.0 * t / period).max(0.0)));
        // Each bone is aimed along the chord to where its child lies on the path.
        for (i, &j) in body.iter().enumerate() {
            let next = if i + 1 < body.len() { arc[body[i + 1]] } else { tail_end };
            p.world(j, aim(DVec3::NEG_Z, DVec3::Y, at(next) - at(arc[j]), DVec3::Y));
        }
    });
    (skel, motion)
}

/// The fish's joints: head, jaw, fins, and the spine chain ending in the tail fin.
pub(super) struct FishBody {
    pub skel: Skeleton,
    pub head: usize,
    pub jaw: usize,
    pub fins: Vec<usize>,
    pub pelvic: Vec<usize>,
    pub dorsal: usize,
    /// spine_02 .. tail_fin.
    pub spine: Vec<usize>,
    /// Nose to tail tip, for the swimming speed in body lengths.
    pub length: f64,
}

/// The fish with `shape.body_joints` spine joints behind the root (at least 3), scaled by
/// `shape` (`tail` stretches the spine and tail fin, `limbs` the fins).
pub(super) fn fish_body(shape: &Proportions, depth: f64) -> FishBody {
    let layout = Layout { root_order: "XZY", joint_order: "XZY", all_positions: false };
    let (k, f, tl) = (shape.size, shape.size * shape.limbs, shape.size * shape.tail);
    let mut b = Builder::new("spine_01", v3(0.0, depth, 0.0), layout);
    let head = b.add("head", 0, v3(0.0, 0.0, 0.1 * k));
    let jaw = b.add("jaw", head, v3(0.0, -0.025 * k, 0.04 * k));
    b.end(jaw, v3(0.0, 0.0, 0.06 * k));
    let mut fins = Vec::new();
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let fin = b.add(if left { "fin_L" } else { "fin_R" }, 0, v3(0.04 * s * k, -0.03 * k, 0.03 * k));
        b.end(fin, v3(0.07 * s * f, -0.02 * f, -0.05 * f));
        fins.push(fin);
    }
    let spine2 = b.add("spine_02", 0, v3(0.0, 0.0, -0.1 * tl));
    let dorsal = b.add("dorsal_fin", spine2, v3(0.0, 0.06 * k, 0.0));
    b.end(dorsal, v3(0.0, 0.06 * f, -0.07 * f));
    let spine3 = b.add("spine_03", spine2, v3(0.0, 0.0, -0.1 * tl));
    let mut pelvic = Vec::new();
    for left in [true, false] {
        let s = if left { 1.0 } else { -1.0 };
        let fin = b.add(if left { "pelvic_fin_L" } else { "pelvic_fin_R" }, spine3, v3(0.02 * s * k, -0.05 * k, 0.0));
        b.end(fin, v3(0.02 * s * f, -0.04 * f, -0.05 * f));
        pelvic.push(fin);
    }
    // Behind spine_03 the vertebrae shorten from 0.09 to 0.08 as in the example fish (which
    // has three of them); more or fewer share the same length.
    let more = shape.body_joints.max(3) - 2;
    let rest: Vec<String> = (4..4 + more).map(|i| format!("spine_{i:02}")).collect();
    let mut spine = vec![spine2, spine3];
    let length_scale = 3.0 / more as f64;
    let (first, step) = (0.09 * tl * length_scale.sqrt(), 0.08 * tl * length_scale.sqrt());
    spine.extend(b.chain(&rest, spine3, v3(0.0, 0.0, -first), v3(0.0, 0.0, -step)));
    let tail = b.add("tail_fin", *spine.last().expect("spine_03 is there"), v3(0.0, 0.0, -0.07 * tl));
    b.end(tail, v3(0.0, 0.0, -0.1 * tl));
    spine.push(tail);
    let length = 0.16 * k + 0.2 * tl + first + step * (more - 1) as f64 + 0.17 * tl;
    FishBody { skel: b.build(), head, jaw, fins, pelvic, dorsal, spine, length }
}

/// A fish swimming in mid-water, snake_case names with `_L`/`_R` fins.
pub(super) fn fish(rng: &mut SplitMix64) -> (Skeleton, Motion) {
    let depth = 0.5;
    let FishBody { skel, head, jaw, fins, pelvic, dorsal, spine, .. } = fish_body(&training::proportions("fish", 0).expect("fish exists"), depth);

    let beat = rng.vary(0.4, 0.08);
    let (frames, period) = frames_for(beat, 8);
    let body_length = 0.1 + 0.06 + 0.1 + 0.1 + 0.09 + 0.08 + 0.08 + 0.07 + 0.1;
    let speed = rng.vary(0.9, 0.1) * body_length;
    let amplitude = rng.vary(14.0, 0.1);
    // About one body wave along the fish: λ in segments.
    let lambda = rng.vary(5.5, 0.08);
    let motion = animate(&skel, frames, |p, t| {
        let c = t / period;
        // The head recoils against the tail beat, and the body rolls a touch with it.
        let sway = 0.006 * wave(c + 0.25);
        p.root(v3(sway, depth + 0.004 * wave(0.5 * c), speed * t), ry(-0.35 * amplitude * wave(c)) * rz(1.5 * wave(c)));
        p.local(head, ry(0.15 * amplitude * wave(c)));
        p.local(jaw, rx(3.0 + 3.0 * wave(0.5 * c)));
        for (k, &j) in spine.iter().enumerate() {
            let x = (k + 1) as f64 / spine.len() as f64;
            let a = amplitude * (0.25 + 0.75 * x * x);
            p.local(j, ry(a * wave(c - (k + 1) as f64 / lambda)));
        }
        for (i, &f) in fins.iter().enumerate() {
            let q = rz(20.0 * wave(c)) * ry(10.0 * cwave(c));
            p.local(f, if i == 0 { q } else { mirror(q) });
        }
        for (i, &f) in pelvic.iter().enumerate() {
            let q = rz(8.0 * wave(c - 0.3));
            p.local(f, if i == 0 { q } else { mirror(q) });
        }
        p.local(dorsal, rz(5.0 * wave(c - 0.4)));
    });
    (skel, motion)
}
