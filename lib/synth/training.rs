//! The training zoo: several actions per creature family, on many body proportions and joint
//! counts, for the default motion-diffusion model (issue 7, "The default model").
//!
//! `creature(name, seed)` keeps producing the one gait each example file shows; this module
//! adds `training_clip(name, variant, action, seed, frames)`. A *variant* is a body: variant 0
//! is the example creature's own proportions, every other variant scales size, limbs, neck and
//! tail independently and, for the families with repeated parts, changes how many there are
//! (centipede segments, snake and fish vertebrae, quadruped and dragon spine, neck and tail).
//! An *action* is what the body does: walking, running (trot, hop), idling, turning along a
//! curve, walking-stopping-walking, undulating slowly or fast. All actions share one recipe
//! (`route`): a ground track for the root, feet that land on it and stay planted, IK for legs.
//! Variants from `RIG_VARIANTS` on also take a `Rig` (see `rig`): naming style, extra anatomy
//! and wider neck and tail counts when the body is built, then axes, units and root OFFSET.

use super::route::{Clock, FootPlan, FootSpec, Route};
use super::*;

/// What a training clip shows the creature doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Action {
    /// The family's ordinary walk.
    Walk,
    /// Faster and in a different phase pattern: a run with a flight phase (biped), a trot
    /// (quadruped, dragon), a fast low-duty walk (arthropods).
    Run,
    /// Both feet together, with a flight phase (bird).
    Hop,
    /// Standing: breathing, weight shifts, looking around, pecking; the root almost still.
    Idle,
    /// Walking (or swimming, slithering) along a curve; the heading turns 60-120 degrees.
    Turn,
    /// Walk, come to a stop, stand about a second, walk again. `TrainingClip::boundaries` gives the
    /// frames where standing begins and ends.
    WalkStopWalk,
    /// Slow lateral undulation (snake) or cruising (fish).
    Undulate,
    /// Fast undulation: higher beat frequency and speed.
    UndulateFast,
}

impl Action {
    /// Lower-case name, used as the file stem of training clips.
    pub fn name(self) -> &'static str {
        match self {
            Action::Walk => "walk",
            Action::Run => "run",
            Action::Hop => "hop",
            Action::Idle => "idle",
            Action::Turn => "turn",
            Action::WalkStopWalk => "walk_stop_walk",
            Action::Undulate => "undulate",
            Action::UndulateFast => "undulate_fast",
        }
    }
}

const LEGGED: &[Action] = &[Action::Walk, Action::Run, Action::Idle, Action::Turn, Action::WalkStopWalk];
const BIRD: &[Action] = &[Action::Walk, Action::Hop, Action::Idle, Action::Turn, Action::WalkStopWalk];
const LIMBLESS: &[Action] = &[Action::Undulate, Action::UndulateFast, Action::Idle, Action::Turn];

/// The actions creature `name` can perform, in file order; empty for an unknown name.
pub fn actions(name: &str) -> &'static [Action] {
    match name {
        "biped" | "quadruped" | "dragon" | "spider" | "centipede" | "crab" => LEGGED,
        "bird" => BIRD,
        "snake" | "fish" => LIMBLESS,
        _ => &[],
    }
}

/// Body proportions of one variant. Factors multiply the example creature's dimensions; counts
/// are absolute. Families ignore what they do not have (a fish has no limbs to lengthen).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proportions {
    /// Overall scale (every length).
    pub size: f64,
    /// Leg and arm (and wing) bone lengths, on top of `size`.
    pub limbs: f64,
    /// Neck and head.
    pub neck: f64,
    /// Tail (and, for limbless bodies, spacing of the vertebrae).
    pub tail: f64,
    /// Repeated body joints: spine joints (quadruped, dragon), segments (centipede), vertebrae
    /// (snake: spine joints, fish: spine joints behind the first).
    pub body_joints: usize,
    /// Neck joints (dragon) — 0 where the neck is fixed.
    pub neck_joints: usize,
    /// Tail joints (quadruped, dragon, snake).
    pub tail_joints: usize,
}

/// (body, neck, tail) joint counts of the example creature, and the ranges variants draw from.
fn counts(name: &str) -> ([usize; 3], [(usize, usize); 3]) {
    match name {
        "quadruped" => ([3, 1, 4], [(2, 4), (1, 1), (2, 7)]),
        "dragon" => ([3, 3, 8], [(2, 4), (2, 5), (5, 12)]),
        "centipede" => ([12, 0, 0], [(7, 18), (0, 0), (0, 0)]),
        "snake" => ([16, 0, 6], [(11, 22), (0, 0), (4, 8)]),
        "fish" => ([5, 0, 0], [(4, 8), (0, 0), (0, 0)]),
        _ => ([0, 0, 0], [(0, 0), (0, 0), (0, 0)]),
    }
}

/// Proportions of `variant` of creature `name` (`None` for an unknown name). Variant 0 is the
/// example creature itself; others draw size from 0.6-1.5 (log-uniform), limbs, neck and tail
/// from ±25 %, and joint counts from the family's range, all from the variant number alone.
pub fn proportions(name: &str, variant: u64) -> Option<Proportions> {
    if !creature_names().contains(&name) {
        return None;
    }
    let (base, mut ranges) = counts(name);
    if variant >= rig::RIG_VARIANTS {
        ranges = rig::wide_counts(name).unwrap_or(ranges);
    }
    if variant == 0 {
        let [body_joints, neck_joints, tail_joints] = base;
        return Some(Proportions { size: 1.0, limbs: 1.0, neck: 1.0, tail: 1.0, body_joints, neck_joints, tail_joints });
    }
    let mut rng = SplitMix64::new(fnv1a(name) ^ variant.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x0076_6172_6961_6e74);
    let size = rng.range(0.6f64.ln(), 1.5f64.ln()).exp();
    let limbs = rng.range(0.78, 1.25);
    let neck = rng.range(0.78, 1.25);
    let tail = rng.range(0.78, 1.25);
    let mut pick = |(lo, hi): (usize, usize)| lo + rng.below(hi - lo + 1);
    let [body_joints, neck_joints, tail_joints] = ranges.map(&mut pick);
    Some(Proportions { size, limbs, neck, tail, body_joints, neck_joints, tail_joints })
}

/// One training clip.
#[derive(Clone, Debug)]
pub struct TrainingClip {
    pub skeleton: Skeleton,
    pub motion: Motion,
    /// Frames where the action changes (walk -> stand -> walk); empty for single actions.
    pub boundaries: Vec<usize>,
}

/// Clip lengths accepted by `training_clip`; shorter requests are lengthened, longer shortened.
pub const CLIP_FRAMES: std::ops::RangeInclusive<usize> = 30..=3000;

/// `frames` frames of creature `name`, body `variant`, doing `action`, jittered by `seed`.
/// `None` for an unknown creature or an action it does not perform (see `actions`). Frame
/// counts outside `CLIP_FRAMES` are clamped into it.
pub fn training_clip(name: &str, variant: u64, action: Action, seed: u64, frames: usize) -> Option<TrainingClip> {
    let (mut clip, rig) = native_clip(name, variant, action, seed, frames)?;
    rig::apply(&rig, &mut clip);
    Some(clip)
}

/// `training_clip` before its axes, units and root are converted to the variant's rig (names
/// and anatomy are already the rig's): Y-up metres, root OFFSET at the hips.
pub(crate) fn native_clip(name: &str, variant: u64, action: Action, seed: u64, frames: usize) -> Option<(TrainingClip, Rig)> {
    if !actions(name).contains(&action) {
        return None;
    }
    let shape = proportions(name, variant)?;
    let frames = frames.clamp(*CLIP_FRAMES.start(), *CLIP_FRAMES.end());
    // Name, action and variant all mix in, so clips are independent of each other.
    let mut rng = SplitMix64::new(seed ^ fnv1a(name) ^ fnv1a(action.name()).rotate_left(17) ^ variant.rotate_left(40));
    let rig = rig::rig(name, variant)?;
    let job = Job { shape, action, frames, rig };
    let clip = match name {
        "biped" => legged_actions::biped(&job, &mut rng),
        "quadruped" => legged_actions::quadruped(&job, &mut rng),
        "dragon" => legged_actions::dragon(&job, &mut rng),
        "spider" => arthropod_actions::spider(&job, &mut rng),
        "crab" => arthropod_actions::crab(&job, &mut rng),
        "centipede" => arthropod_actions::centipede(&job, &mut rng),
        "bird" => body_actions::bird(&job, &mut rng),
        "snake" => body_actions::snake(&job, &mut rng),
        _ => body_actions::fish(&job, &mut rng),
    };
    let mut clip = clip;
    if rig.naming == Naming::Biped {
        rig::add_biped_centre(&mut clip);
    }
    Some((clip, rig))
}

/// Write `clips_per_action` clips of every action of every creature for variants
/// `0..variants` as `dir/<creature>_v<k>/<action>_<n>.bvh` (one folder per skeleton), plus
/// `dir/boundaries.tsv` listing each clip's action boundary frames. Clip lengths vary between
/// 150 and 300 frames. Returns the BVH paths written.
pub fn write_training_zoo(dir: &Path, variants: u64, clips_per_action: usize, seed: u64) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    let mut index = String::from("file\tframes\tboundaries\n");
    for name in creature_names() {
        for variant in 0..variants {
            let folder = dir.join(format!("{name}_v{variant}"));
            std::fs::create_dir_all(&folder)?;
            for &action in actions(name) {
                for n in 0..clips_per_action {
                    let clip_seed = seed.wrapping_add((n as u64).wrapping_mul(0x9e37_79b9));
                    let mut pick = SplitMix64::new(clip_seed ^ fnv1a(name) ^ variant ^ fnv1a(action.name()));
                    let frames = 150 + pick.below(151);
                    let clip = training_clip(name, variant, action, clip_seed, frames).expect("listed actions exist");
                    let mut bvh = clip.motion.to_bvh(&clip.skeleton);
                    round_values(&mut bvh);
                    let file = format!("{}_{n}.bvh", action.name());
                    let path = folder.join(&file);
                    std::fs::write(&path, bvh::write_string(&bvh))?;
                    let marks: Vec<String> = clip.boundaries.iter().map(|b| b.to_string()).collect();
                    index.push_str(&format!("{name}_v{variant}/{file}\t{frames}\t{}\n", marks.join(",")));
                    written.push(path);
                }
            }
        }
    }
    std::fs::write(dir.join("boundaries.tsv"), index)?;
    Ok(written)
}

// ---------------------------------------------------------------------------------------------
// Shared by the family modules

/// What to generate.
pub(crate) struct Job {
    pub shape: Proportions,
    pub action: Action,
    pub frames: usize,
    /// Naming, anatomy, axes and units (applied after posing, in the native frame).
    pub rig: Rig,
}

impl Job {
    pub fn duration(&self) -> f64 {
        self.frames as f64 * FRAME_TIME
    }

    pub fn moving(&self) -> bool {
        self.action != Action::Idle
    }
}

/// The root's track and the step clock of one clip, and the action boundaries they imply.
pub(crate) struct Plan {
    pub route: Route,
    pub clock: Clock,
    /// Nominal cruising speed (m/s); 0 for idle.
    pub speed: f64,
    /// Half the ground a foot's stance covers at cruising speed.
    pub reach: f64,
    pub lift: f64,
    /// (stand from, walk again at) in seconds, for walk-stop-walk.
    pub stop: Option<(f64, f64)>,
}

impl Plan {
    /// A plan for `job` with gait `gait` (period, duty, stride, lift), starting with heading
    /// `yaw0` and moving `travel` radians off the heading (crabs walk sideways).
    pub fn new(job: &Job, gait: Gait, yaw0: f64, travel: f64, rng: &mut SplitMix64) -> Plan {
        let t_end = job.duration();
        let speed = if job.moving() { gait.speed() } else { 0.0 };
        let stop = (job.action == Action::WalkStopWalk).then(|| {
            // The clock stops at `a`; the swings under way then land, and the body stands about
            // a second after that before walking on at `b`.
            let a = t_end * rng.range(0.33, 0.42);
            let land = (1.0 - gait.duty) * gait.period;
            (a, a + land + (0.25 * t_end).min(rng.range(1.0, 1.3)))
        });
        let ramp = stop.map_or(0.6, |_| (0.15 * t_end).min(0.6));
        // The heading turns 60-120 degrees over the clip, either way, on a constant curvature.
        let curvature = if job.action == Action::Turn && speed > 0.0 {
            let angle = rng.range(60.0f64, 120.0).to_radians() * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
            angle / (speed * t_end)
        } else {
            0.0
        };
        let pad = 3.0 * gait.period + 2.0;
        let profile = route::speed_profile(speed, stop, ramp);
        let route = Route::new(-pad, t_end + pad, yaw0, travel, profile, |_| curvature);
        let clock = Clock { period: gait.period, duty: gait.duty, pause: stop };
        Plan { route, clock, speed, reach: gait.half_reach(), lift: gait.lift, stop }
    }

    /// The stances of a foot.
    pub fn foot(&self, job: &Job, spec: FootSpec) -> FootPlan {
        FootPlan::new(&self.route, &self.clock, &spec, job.duration(), job.moving(), self.reach, self.lift)
    }

    /// Cycles of the step clock elapsed at `t` (frozen while standing).
    pub fn cycles(&self, t: f64) -> f64 {
        let tau = match self.stop {
            Some((a, b)) if t >= b => t - (b - a),
            Some((a, _)) if t >= a => a,
            _ => t,
        };
        tau / self.clock.period
    }

    /// How much the body is walking at `t`: speed over cruising speed, 0 when idle.
    pub fn activity(&self, t: f64) -> f64 {
        if self.speed > 0.0 {
            (self.route.speed(t) / self.speed).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Boundary frames for walk-stop-walk: from the first frame on which every foot is down
    /// and the body still, to the last frame before it moves again.
    pub fn boundaries(&self, feet: &[&FootPlan]) -> Vec<usize> {
        let Some((a, b)) = self.stop else { return Vec::new() };
        let planted = feet.iter().map(|f| f.landed_after(a)).fold(a, f64::max);
        let first = (planted / FRAME_TIME).ceil() as usize;
        let last = ((b / FRAME_TIME).floor() as usize).max(first);
        vec![first, last]
    }
}
