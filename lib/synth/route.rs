//! Where a body goes and where its feet land, for clips whose speed and heading change.
//!
//! The original zoo gaits move at one constant speed along +z, so a foot's stance spot is a
//! closed formula. The training actions stop, start and curve, so they are built from two
//! pieces instead: a `Route` (the ground frame under the root: position, heading and arc length,
//! integrated from a speed profile and a curvature), and per foot a `FootPlan` (the list of
//! stances: when the foot lands, when it lifts, and the world spot it holds in between). A
//! stance spot is the foot's home under the body at the moment the body has passed half a
//! nominal stance beyond the landing, or where the body is at lift-off if it covers less ground
//! than that (a stop). So at constant speed the stance is centred on the hip exactly as in
//! `Gait::foot`, and when the body stops, the feet land under it and stay there.

use super::*;

/// The ground frame under the root at one instant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub pos: DVec3,
    /// Heading of the body (radians about +y; 0 = facing +z).
    pub yaw: f64,
}

impl Frame {
    pub fn rot(&self) -> DQuat {
        DQuat::from_rotation_y(self.yaw)
    }

    /// A body-frame point in the world.
    pub fn apply(&self, local: DVec3) -> DVec3 {
        self.pos + self.rot() * local
    }
}

/// The root's ground track, sampled finely enough that linear interpolation is exact to well
/// below a millimetre. Covers `[start, end]` seconds; times outside are clamped and arc lengths
/// outside extrapolate straight ahead (or behind), which is what bodies trailing the root (a
/// snake's tail) need before the clip starts.
pub(crate) struct Route {
    start: f64,
    dt: f64,
    s: Vec<f64>,
    frames: Vec<Frame>,
    /// Direction of travel relative to the heading (a crab walks sideways: +90°).
    travel: f64,
}

impl Route {
    /// Integrate `speed(t)` (m/s) and `curvature(t)` (radians of heading per metre travelled)
    /// over `[start, end]`, anchored so that at t = 0 the frame is at the origin with heading
    /// `yaw0`. Heading changes only while moving, so a stopped body never spins.
    pub fn new(start: f64, end: f64, yaw0: f64, travel: f64, speed: impl Fn(f64) -> f64, curvature: impl Fn(f64) -> f64) -> Route {
        let dt = FRAME_TIME / 8.0;
        let n = ((end - start) / dt).ceil().max(1.0) as usize + 1;
        let mut s = Vec::with_capacity(n);
        let mut frames = Vec::with_capacity(n);
        let (mut arc, mut pos, mut yaw) = (0.0, DVec3::ZERO, 0.0);
        for i in 0..n {
            s.push(arc);
            frames.push(Frame { pos, yaw });
            // Midpoint rule: second order, and exact for the piecewise-smooth profiles used.
            let t = start + (i as f64 + 0.5) * dt;
            let v = speed(t).max(0.0);
            let dyaw = v * curvature(t) * dt;
            let dir = yaw + dyaw / 2.0 + travel;
            pos += v3(dir.sin(), 0.0, dir.cos()) * (v * dt);
            yaw += dyaw;
            arc += v * dt;
        }
        let mut route = Route { start, dt, s, frames, travel };
        let origin = route.at_time(0.0);
        let s0 = route.s_at(0.0);
        let turn = DQuat::from_rotation_y(yaw0 - origin.yaw);
        for (f, a) in route.frames.iter_mut().zip(route.s.iter_mut()) {
            f.pos = turn * (f.pos - origin.pos);
            f.yaw += yaw0 - origin.yaw;
            *a -= s0;
        }
        route
    }

    fn index(&self, t: f64) -> (usize, f64) {
        let x = ((t - self.start) / self.dt).clamp(0.0, (self.s.len() - 1) as f64);
        let i = (x.floor() as usize).min(self.s.len().saturating_sub(2));
        (i, (x - i as f64).min(1.0))
    }

    fn lerp(&self, i: usize, u: f64) -> Frame {
        let (a, b) = (self.frames[i], self.frames[(i + 1).min(self.frames.len() - 1)]);
        Frame { pos: a.pos.lerp(b.pos, u), yaw: a.yaw + (b.yaw - a.yaw) * u }
    }

    pub fn at_time(&self, t: f64) -> Frame {
        let (i, u) = self.index(t);
        self.lerp(i, u)
    }

    /// Arc length travelled since t = 0 (negative before).
    pub fn s_at(&self, t: f64) -> f64 {
        let (i, u) = self.index(t);
        let b = self.s[(i + 1).min(self.s.len() - 1)];
        self.s[i] + (b - self.s[i]) * u
    }

    /// Speed at `t` from the sampled arc length (m/s).
    pub fn speed(&self, t: f64) -> f64 {
        (self.s_at(t + self.dt) - self.s_at(t - self.dt)) / (2.0 * self.dt)
    }

    /// The frame where the body had travelled `s`; beyond the sampled track, straight on.
    pub fn at_arc(&self, s: f64) -> Frame {
        let last = self.s.len() - 1;
        let straight = |f: Frame, ds: f64| {
            let dir = f.yaw + self.travel;
            Frame { pos: f.pos + v3(dir.sin(), 0.0, dir.cos()) * ds, yaw: f.yaw }
        };
        if s <= self.s[0] {
            return straight(self.frames[0], s - self.s[0]);
        }
        if s >= self.s[last] {
            return straight(self.frames[last], s - self.s[last]);
        }
        // First sample at or beyond s; plateaus (standing still) give the same frame anyway.
        let j = self.s.partition_point(|&x| x < s).clamp(1, last);
        let (a, b) = (self.s[j - 1], self.s[j]);
        let u = if b > a { (s - a) / (b - a) } else { 1.0 };
        self.lerp(j - 1, u)
    }
}

/// The shared step clock: feet lift and land on a fixed rhythm, which stops for a `pause`
/// (real seconds, start and end) while the body stands. A swing under way when the pause
/// begins still finishes, so no foot freezes in the air.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Clock {
    pub period: f64,
    pub duty: f64,
    pub pause: Option<(f64, f64)>,
}

impl Clock {
    /// Real time of clock time `tau`.
    pub fn real(&self, tau: f64) -> f64 {
        match self.pause {
            Some((a, b)) if tau >= a => tau + (b - a),
            _ => tau,
        }
    }
}

/// One stance: the foot holds `at` (ground contact, y = 0) with heading `yaw` from `land` to
/// `lift` seconds.
#[derive(Clone, Copy, Debug)]
struct Plant {
    land: f64,
    lift: f64,
    at: DVec3,
    yaw: f64,
}

/// A foot at one instant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FootNow {
    /// Ground contact point in the world; `y` is the lift above the ground.
    pub at: DVec3,
    /// Heading the foot points in (radians about +y).
    pub yaw: f64,
    /// Progress through the swing, 0 in stance.
    pub swing: f64,
}

/// All stances of one foot over a clip.
pub(crate) struct FootPlan {
    plants: Vec<Plant>,
    lift: f64,
    stride: f64,
    /// Running swing: the foot leaves and meets the ground with vertical speed (push-off and
    /// strike), so both feet are clearly off the ground during the flight phase.
    sharp: bool,
}

/// What a foot is: its ground contact in the body frame (`home`, y ignored), how far behind
/// the root along the track its body part rides (`lag`: 0 for rigid bodies, the segment's
/// distance for a centipede), and when in the cycle it lands (`touchdown`, in cycles).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FootSpec {
    pub home: DVec3,
    pub lag: f64,
    pub touchdown: f64,
}

impl FootPlan {
    /// Stances over `[0, end]` seconds (with a cycle of margin each side). `stepping == false`
    /// plants the foot once under the body at t = 0 (idle). `reach` is half the ground a stance
    /// covers at nominal speed, `lift` the swing height at a full stride.
    pub fn new(route: &Route, clock: &Clock, foot: &FootSpec, end: f64, stepping: bool, reach: f64, lift: f64) -> FootPlan {
        let spot = |s: f64| {
            let f = route.at_arc(s - foot.lag);
            let mut at = f.apply(v3(foot.home.x, 0.0, foot.home.z));
            at.y = 0.0;
            (at, f.yaw)
        };
        let stride = 2.0 * reach / clock.duty.max(1e-6);
        if !stepping || clock.period.is_nan() || clock.period <= 0.0 {
            let (at, yaw) = spot(route.s_at(0.0));
            let plants = vec![Plant { land: f64::NEG_INFINITY, lift: f64::INFINITY, at, yaw }];
            return FootPlan { plants, lift, stride, sharp: false };
        }
        let p = clock.period;
        // Lift-offs in clock time are (n + touchdown + duty) periods; map each to real time.
        let first = ((-2.0 * p) / p - foot.touchdown - clock.duty).floor() as i64;
        let mut lifts = Vec::new();
        let mut n = first;
        loop {
            let tau = (n as f64 + foot.touchdown + clock.duty) * p;
            let t = clock.real(tau);
            lifts.push(t);
            if t > end + 2.0 * p || lifts.len() > 100_000 {
                break;
            }
            n += 1;
        }
        let swing = (1.0 - clock.duty) * p;
        let mut plants = Vec::with_capacity(lifts.len());
        for (k, &lift_t) in lifts.iter().enumerate() {
            let land = if k == 0 { lift_t - clock.duty * p } else { lifts[k - 1] + swing };
            let s = (route.s_at(land) + reach).min(route.s_at(lift_t));
            let (at, yaw) = spot(s);
            plants.push(Plant { land, lift: lift_t, at, yaw });
        }
        FootPlan { plants, lift, stride, sharp: false }
    }

    /// The same plan with a running swing (see `sharp`).
    pub fn sharp(self) -> FootPlan {
        FootPlan { sharp: true, ..self }
    }

    pub fn at(&self, t: f64) -> FootNow {
        let k = self.plants.partition_point(|p| p.lift <= t);
        if k == 0 || k >= self.plants.len() {
            let p = self.plants[k.min(self.plants.len() - 1)];
            return FootNow { at: p.at, yaw: p.yaw, swing: 0.0 };
        }
        let (a, b) = (self.plants[k - 1], self.plants[k]);
        if t >= b.land {
            return FootNow { at: b.at, yaw: b.yaw, swing: 0.0 };
        }
        let u = ((t - a.lift) / (b.land - a.lift)).clamp(0.0, 1.0);
        // Cycloid forward and cosine lift, as in `Gait::foot`: no skid at either end. Short
        // steps (starting, stopping) lift less, as animals shuffle them.
        let progress = u - (TAU * u).sin() / TAU;
        let step = a.at.distance(b.at);
        let lift = self.lift * (0.35 + 0.65 * (2.0 * step / self.stride).min(1.0));
        let mut at = a.at.lerp(b.at, progress);
        at.y = if self.sharp { lift * (std::f64::consts::PI * u).sin() } else { lift * 0.5 * (1.0 - (TAU * u).cos()) };
        FootNow { at, yaw: a.yaw + (b.yaw - a.yaw) * progress, swing: u.max(1e-9) }
    }

    /// Time by which the swing under way at `t` (if any) has landed.
    pub fn landed_after(&self, t: f64) -> f64 {
        self.plants.windows(2).filter(|w| w[0].lift < t && w[1].land > t).map(|w| w[1].land).fold(t, f64::max)
    }
}

/// A speed profile: cruise at `v`, with an optional stop (decelerate over `ramp` seconds to
/// stand still from `stop.0` to `stop.1`, then accelerate again). Smooth (C1) at every joint
/// so the feet never see a jerk.
pub(crate) fn speed_profile(v: f64, stop: Option<(f64, f64)>, ramp: f64) -> impl Fn(f64) -> f64 {
    move |t| match stop {
        None => v,
        Some((a, b)) => {
            if t < a {
                v * (1.0 - smoothstep((t - (a - ramp)) / ramp))
            } else if t < b {
                0.0
            } else {
                v * smoothstep((t - b) / ramp)
            }
        }
    }
}
