//! Procedural example creatures: the project's own test and demo data.
//!
//! The corpora people animate (Truebones, Mixamo, Bandai Namco) cannot be shipped with the
//! project, yet every tool needs skeletons of very different shapes to be exercised on: two,
//! four, eight and two dozen legs, no legs at all, wings, fins, tails. So we build them: each
//! creature is a hand-laid rest pose plus a periodic gait computed analytically (foot targets
//! on the ground, two-bone IK per leg, travelling waves along bodies), written through the same
//! `Motion::to_bvh` + `bvh::write_string` path as every other tool, so the files also exercise
//! our writer's channel layouts, Euler orders and naming styles.
//!
//! Everything is deterministic for a seed: a tiny splitmix64 generator perturbs stride, speed
//! and phases a little, so different seeds give different but equally plausible clips.
//!
//! Layout: this module holds the API and the shared machinery (PRNG, skeleton builder, per-frame
//! pose solver, IK, gait timing); the creatures live in `legged` (biped, quadruped, dragon),
//! `arthropod` (spider, centipede, crab), `undulating` (snake, fish) and `bird`.
//!
//! The training zoo (`training_clip`, `write_training_zoo`) reuses those bodies with other
//! proportions and joint counts and gives each family several actions (walk, run, idle, turn,
//! walk-stop-walk, ...): `training` holds its API, `route` the ground track and foot planning
//! that let bodies stop and curve, and `legged_actions`, `arthropod_actions` and `body_actions`
//! the families' actions. `rig` gives training variants from `RIG_VARIANTS` on the naming,
//! axis, unit and root conventions of real files, and jaws, ears and fingers.

mod arthropod;
mod arthropod_actions;
mod bird;
mod body_actions;
mod legged;
mod legged_actions;
mod rig;
mod route;
mod training;
mod undulating;

pub(crate) use crate::motion::ik::{aim, two_bone_knee};
pub(crate) use rig::human_name;
pub use rig::{rig, Naming, Rig, UpAxis, RIG_VARIANTS};
pub use training::{actions, proportions, training_clip, write_training_zoo, Action, Proportions, TrainingClip, CLIP_FRAMES};

#[cfg(test)]
mod rig_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod training_tests;

use crate::bvh::{self, Bvh, Channel};
use crate::motion::Motion;
use crate::rng::SplitMix64;
use crate::skeleton::{Joint, Skeleton};
use glam::{DQuat, DVec3};
use std::f64::consts::TAU;
use std::io;
use std::path::{Path, PathBuf};

/// Seconds per frame of every generated clip.
pub const FRAME_TIME: f64 = 1.0 / 30.0;

/// The seed `write_zoo` users get when they do not choose one.
pub const DEFAULT_SEED: u64 = 1;

type Generator = fn(&mut SplitMix64) -> (Skeleton, Motion);

/// Every creature, in the order the zoo writes them. Names are also the file stems.
const CREATURES: &[(&str, Generator)] = &[
    ("biped", legged::biped),
    ("quadruped", legged::quadruped),
    ("spider", arthropod::spider),
    ("centipede", arthropod::centipede),
    ("snake", undulating::snake),
    ("bird", bird::bird),
    ("fish", undulating::fish),
    ("crab", arthropod::crab),
    ("dragon", legged::dragon),
];

const NAMES: &[&str] = &["biped", "quadruped", "spider", "centipede", "snake", "bird", "fish", "crab", "dragon"];

/// Names of all creatures `creature` can build.
pub fn creature_names() -> &'static [&'static str] {
    NAMES
}

/// The skeleton and motion of creature `name` for `seed`, or `None` for an unknown name.
pub fn creature(name: &str, seed: u64) -> Option<(Skeleton, Motion)> {
    let (_, generate) = CREATURES.iter().find(|(n, _)| *n == name)?;
    // Mixing the name in keeps creatures independent: adding one never changes another's clip.
    let mut rng = SplitMix64::new(seed ^ fnv1a(name));
    Some(generate(&mut rng))
}

/// The creature as a BVH, values rounded so the files stay small (see `round_values`).
pub fn creature_bvh(name: &str, seed: u64) -> Option<Bvh> {
    let (skeleton, motion) = creature(name, seed)?;
    let mut bvh = motion.to_bvh(&skeleton);
    round_values(&mut bvh);
    Some(bvh)
}

/// Write every creature as `<dir>/<name>.bvh` (creating `dir`); returns the paths written.
pub fn write_zoo(dir: &Path, seed: u64) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for name in creature_names() {
        let bvh = creature_bvh(name, seed).expect("every listed creature exists");
        let path = dir.join(format!("{name}.bvh"));
        std::fs::write(&path, bvh::write_string(&bvh))?;
        written.push(path);
    }
    Ok(written)
}

/// The writer prints the shortest exact text of each f64, so raw solver output costs ~19 bytes
/// a value; a thousandth of a degree and a hundredth of a millimetre are far below anything
/// visible and cut the files to a third.
fn round_values(bvh: &mut Bvh) {
    let mut kinds = Vec::new();
    for j in &bvh.joints {
        kinds.extend(j.channels.iter().map(|c| c.is_rotation()));
    }
    if kinds.is_empty() {
        return;
    }
    for (k, v) in bvh.values.iter_mut().enumerate() {
        let scale = if kinds[k % kinds.len()] { 1e3 } else { 1e5 };
        // `+ 0.0` turns -0 into 0 so the text never shows "-0".
        *v = (*v * scale).round() / scale + 0.0;
    }
}

fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

// ---------------------------------------------------------------------------------------------
// Skeleton building

/// Channel layouts: which joints get position channels and which Euler order they use. Real
/// files differ in exactly these ways, so the zoo varies them across creatures.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    pub root_order: &'static str,
    pub joint_order: &'static str,
    /// Six channels on every joint (Truebones style) instead of only on the root.
    pub all_positions: bool,
}

fn rotation_channels(order: &str) -> Vec<Channel> {
    order
        .chars()
        .map(|c| match c {
            'X' => Channel::Xrotation,
            'Y' => Channel::Yrotation,
            _ => Channel::Zrotation,
        })
        .collect()
}

fn with_positions(order: &str) -> Vec<Channel> {
    let mut c = vec![Channel::Xposition, Channel::Yposition, Channel::Zposition];
    c.extend(rotation_channels(order));
    c
}

/// Builds a skeleton joint by joint. Joints must be added in depth-first pre-order (each whole
/// subtree before its next sibling), because the BVH writer prints the hierarchy depth-first
/// while `Motion::to_bvh` emits frame values in joint order; `build` checks it.
pub(crate) struct Builder {
    joints: Vec<Joint>,
    layout: Layout,
}

/// Offsets are rounded to 0.1 mm so the hierarchy text stays short and mirrored pairs are
/// exact negatives of each other.
fn round_offset(v: DVec3) -> DVec3 {
    (v * 1e4).round() / 1e4 + DVec3::ZERO
}

impl Builder {
    pub fn new(root: &str, at: DVec3, layout: Layout) -> Builder {
        let joint =
            Joint { name: root.to_string(), parent: None, offset: round_offset(at), channels: with_positions(layout.root_order), end_sites: Vec::new() };
        Builder { joints: vec![joint], layout }
    }

    pub fn add(&mut self, name: &str, parent: usize, offset: DVec3) -> usize {
        let channels = if self.layout.all_positions { with_positions(self.layout.joint_order) } else { rotation_channels(self.layout.joint_order) };
        self.joints.push(Joint { name: name.to_string(), parent: Some(parent), offset: round_offset(offset), channels, end_sites: Vec::new() });
        self.joints.len() - 1
    }

    /// A straight chain of joints, each `step` from the previous; returns their indices.
    pub fn chain(&mut self, names: &[String], parent: usize, first: DVec3, step: DVec3) -> Vec<usize> {
        let mut out = Vec::with_capacity(names.len());
        let mut p = parent;
        for (k, n) in names.iter().enumerate() {
            p = self.add(n, p, if k == 0 { first } else { step });
            out.push(p);
        }
        out
    }

    pub fn end(&mut self, joint: usize, offset: DVec3) {
        self.joints[joint].end_sites.push(round_offset(offset));
    }

    pub fn build(self) -> Skeleton {
        // Depth-first pre-order: every parent is on the path from the root to the previous joint.
        let mut path: Vec<usize> = vec![0];
        for (j, joint) in self.joints.iter().enumerate().skip(1) {
            let p = joint.parent.expect("only the first joint is a root");
            while path.last().is_some_and(|&top| top != p) {
                path.pop();
            }
            assert!(!path.is_empty(), "joint {} '{}' added out of depth-first order", j, joint.name);
            path.push(j);
        }
        let skeleton = Skeleton { joints: self.joints, frame_time: FRAME_TIME };
        skeleton.validate().expect("builder keeps parents first");
        skeleton
    }
}

// ---------------------------------------------------------------------------------------------
// Posing

/// One frame being posed: world transforms are filled in joint order, so a joint's parent is
/// always final when the joint is set. Joints left alone keep their rest (identity) rotation.
/// Creatures mix the two ways of setting a joint: local angles for spines and tails, world
/// rotations for IK legs and stabilised heads.
pub(crate) struct Pose<'a> {
    skel: &'a Skeleton,
    pos: Vec<DVec3>,
    rot: Vec<DQuat>,
    local: Vec<DQuat>,
    root_t: DVec3,
    done: Vec<bool>,
}

impl<'a> Pose<'a> {
    pub fn new(skel: &'a Skeleton) -> Pose<'a> {
        let n = skel.len();
        Pose {
            skel,
            pos: vec![DVec3::ZERO; n],
            rot: vec![DQuat::IDENTITY; n],
            local: vec![DQuat::IDENTITY; n],
            root_t: skel.joints[0].offset,
            done: vec![false; n],
        }
    }

    pub fn root(&mut self, at: DVec3, q: DQuat) {
        assert!(!self.done[0], "root set twice");
        self.root_t = at;
        self.pos[0] = at;
        self.rot[0] = q;
        self.local[0] = q;
        self.done[0] = true;
    }

    fn ensure(&mut self, j: usize) {
        if self.done[j] {
            return;
        }
        match self.skel.joints[j].parent {
            None => self.root(self.root_t, DQuat::IDENTITY),
            Some(_) => self.local(j, DQuat::IDENTITY),
        }
    }

    fn place(&mut self, j: usize, local: DQuat, world: DQuat) {
        assert!(!self.done[j], "joint {} set twice", self.skel.joints[j].name);
        let p = self.skel.joints[j].parent.expect("use root() for the root");
        self.ensure(p);
        self.pos[j] = self.pos[p] + self.rot[p] * self.skel.joints[j].offset;
        self.rot[j] = world;
        self.local[j] = local;
        self.done[j] = true;
    }

    /// Set joint `j`'s rotation relative to its parent.
    pub fn local(&mut self, j: usize, q: DQuat) {
        let p = self.skel.joints[j].parent.expect("use root() for the root");
        self.ensure(p);
        let world = self.rot[p] * q;
        self.place(j, q, world);
    }

    /// Set joint `j`'s rotation in the world.
    pub fn world(&mut self, j: usize, q: DQuat) {
        let p = self.skel.joints[j].parent.expect("use root() for the root");
        self.ensure(p);
        let local = self.rot[p].inverse() * q;
        self.place(j, local, q);
    }

    /// World position of joint `j`. It depends only on the parents, so asking for it does not
    /// fix the joint's own rotation (parents not yet posed get their rest rotation).
    pub fn pos(&mut self, j: usize) -> DVec3 {
        if self.done[j] {
            return self.pos[j];
        }
        let p = self.skel.joints[j].parent.expect("the root is posed first");
        self.ensure(p);
        self.pos[p] + self.rot[p] * self.skel.joints[j].offset
    }

    /// Pose a two-bone leg `upper -> lower -> tip` so that `tip` lands on `target`, the middle
    /// joint bending towards `pole` (world), and give `tip` the world rotation `tip_rot`.
    /// `rest_pole` is the bend direction the rest pose was built with; together with the
    /// pole it fixes the twist of both bones, so a knee stays a hinge instead of spinning.
    /// Without a tip joint the lower bone ends at the lower joint's End Site.
    pub fn leg(&mut self, leg: &Leg, target: DVec3, pole: DVec3, tip_rot: DQuat) {
        let o1 = self.skel.joints[leg.lower].offset;
        let o2 = match leg.tip {
            Some(t) => self.skel.joints[t].offset,
            None => self.skel.joints[leg.lower].end_sites[0],
        };
        let hip = self.pos(leg.upper);
        let knee = two_bone_knee(hip, target, o1.length(), o2.length(), pole);
        // Rest rotations are identity, so rest offsets are also rest world directions.
        let w1 = aim(o1, leg.rest_pole, knee - hip, pole);
        self.world(leg.upper, w1);
        let knee = self.pos(leg.lower);
        let w2 = aim(o2, leg.rest_pole, target - knee, pole);
        self.world(leg.lower, w2);
        if let Some(t) = leg.tip {
            self.world(t, tip_rot);
        }
    }

    /// Write this frame's local rotations and the root translation into `motion`.
    fn finish(mut self, motion: &mut Motion, frame: usize) {
        for j in 0..self.skel.len() {
            self.ensure(j);
        }
        let base = frame * motion.joints;
        motion.rotations[base..base + motion.joints].copy_from_slice(&self.local);
        motion.translations[base] = self.root_t;
    }
}

/// The joints of a two-bone limb and the direction its middle joint bends in the rest pose.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Leg {
    pub upper: usize,
    pub lower: usize,
    pub tip: Option<usize>,
    pub rest_pole: DVec3,
}

/// A motion of `frames` frames, each posed by `pose_at(pose, t)` with `t` in seconds.
/// Translations stay the OFFSETs except the root's, so joints with position channels write
/// their rest offsets (bones keep their lengths).
pub(crate) fn animate(skel: &Skeleton, frames: usize, mut pose_at: impl FnMut(&mut Pose, f64)) -> Motion {
    let n = skel.len();
    let mut motion = Motion {
        frames,
        joints: n,
        frame_time: FRAME_TIME,
        rotations: vec![DQuat::IDENTITY; frames * n],
        translations: (0..frames).flat_map(|_| skel.joints.iter().map(|j| j.offset)).collect(),
    };
    for f in 0..frames {
        let mut pose = Pose::new(skel);
        pose_at(&mut pose, f as f64 * FRAME_TIME);
        pose.finish(&mut motion, f);
    }
    motion
}

/// The mirror image of a rotation across the x = 0 plane: what the right side does when the
/// left side does `q`.
pub(crate) fn mirror(q: DQuat) -> DQuat {
    crate::motion::rotation::reflect(q, 0)
}

pub(crate) fn rx(deg: f64) -> DQuat {
    DQuat::from_rotation_x(deg.to_radians())
}
pub(crate) fn ry(deg: f64) -> DQuat {
    DQuat::from_rotation_y(deg.to_radians())
}
pub(crate) fn rz(deg: f64) -> DQuat {
    DQuat::from_rotation_z(deg.to_radians())
}

pub(crate) fn v3(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

// ---------------------------------------------------------------------------------------------
// Gait timing

/// A periodic stepping pattern shared by all legs of a creature. Each leg lands at its own
/// phase offset; during stance (the first `duty` of its cycle) its foot stays where it landed
/// while the body moves on at `speed()`, so the foot travels exactly one stride per cycle in
/// its swing. Feet therefore plant by construction, and IK makes the legs follow.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gait {
    pub period: f64,
    pub duty: f64,
    pub stride: f64,
    pub lift: f64,
}

/// Where a foot is relative to its home (its rest position carried along at body speed).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FootState {
    /// World forward position minus the home's position at t = 0.
    pub forward: f64,
    /// Height above the ground contact.
    pub lift: f64,
    /// Progress through swing, 0 in stance.
    pub swing: f64,
}

impl Gait {
    pub fn speed(&self) -> f64 {
        self.stride / self.period
    }

    /// Phase of the cycle (0 = touchdown) at time `t` for a leg that lands at `touchdown`.
    pub fn phase(&self, t: f64, touchdown: f64) -> f64 {
        (t / self.period - touchdown).rem_euclid(1.0)
    }

    /// The foot of a leg landing at `touchdown`, chosen so that it is right under its home at
    /// mid-stance: that centres the stance on the hip and keeps the IK reach symmetric.
    pub fn foot(&self, t: f64, touchdown: f64) -> FootState {
        let x = t / self.period - touchdown;
        let n = x.floor();
        let phi = x - n;
        let (progress, lift, swing) = if phi < self.duty {
            (0.0, 0.0, 0.0)
        } else {
            let u = (phi - self.duty) / (1.0 - self.duty);
            // Cycloid forward and cosine lift: zero velocity at lift-off and touchdown, so
            // feet neither skid nor stamp.
            (u - (TAU * u).sin() / TAU, self.lift * 0.5 * (1.0 - (TAU * u).cos()), u)
        };
        FootState { forward: self.stride * (n + progress + self.duty / 2.0 + touchdown), lift, swing }
    }

    /// Largest horizontal distance between a foot and its home during stance.
    pub fn half_reach(&self) -> f64 {
        self.stride * self.duty / 2.0
    }
}

/// Frames for `cycles` whole gait cycles of roughly `period` seconds, and the period adjusted
/// so the cycles fit the frames exactly (the clip then loops, up to the forward travel).
pub(crate) fn frames_for(period: f64, cycles: usize) -> (usize, f64) {
    let frames = (cycles as f64 * period / FRAME_TIME).round().max(1.0) as usize;
    (frames, frames as f64 * FRAME_TIME / cycles as f64)
}

/// Height of a hip above its ankle that keeps the leg at most `slack` of full extension when
/// the foot is `half_reach` ahead of or behind it.
pub(crate) fn stand_height(leg_length: f64, half_reach: f64, slack: f64) -> f64 {
    let l = leg_length * slack;
    (l * l - half_reach * half_reach).max(0.0).sqrt()
}

/// 0 below 0, 1 above 1, a smooth S between.
pub(crate) fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Smooth periodic helpers in cycles (1.0 = a full turn).
pub(crate) fn wave(x: f64) -> f64 {
    (TAU * x).sin()
}
pub(crate) fn cwave(x: f64) -> f64 {
    (TAU * x).cos()
}
