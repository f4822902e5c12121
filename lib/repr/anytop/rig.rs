//! The per-skeleton quantities AnyTop computes from its rest ("T-pose") clip
//! (docs/reference/anytop.md §1.3–1.4), and the automatic choice of face joints that replaces
//! AnyTop's per-species table.
//!
//! Face joints, automatically. Left/right come from `roles::sides` (names, else geometry).
//! A *limb* is a chain that leaves the body: a left or right joint whose parent is a centre
//! joint. Left and right limbs are paired when they hang from the same joint and their names
//! agree once the side word is removed (else in index order). Head parts (eyes, ears, antennae,
//! chelicerae, ... by name) are not limbs, nor are pairs much shorter than the longest (reach
//! below 25% of the longest pair's). A pair is a *leg* pair when its chains hold a foot
//! (`roles::feet` or the override).
//! Pairs are ordered front to back along the body: the direction from the body's centroid to
//! its head (joints named head, neck, jaw, eye, ...; else away from the tail; else +Z, the BVH
//! convention) in the rest frame. Then hips = the rearmost leg pair (the rearmost pair when no
//! pair holds a foot) and shoulders = the frontmost other pair (the hips again when there is
//! only one pair). A pair whose two joints coincide (CMU's `LHipJoint` sits on the hips) is
//! replaced by the first joints down its chains that do not. Without any pair the creature
//! faces along its body: front and back are the ends of the skeleton's longest path (by bone
//! length), front being the end nearer the head (else away from the tail, else nearer the root).

use super::{heading_of, yaw_to_front, AnyTopError, Facing, Provenance, RestSource, RigOptions, HUMANML_MEAN_BONE_LENGTH};
use crate::motion::Motion;
use crate::repr::Features;
use crate::skeleton::names::{self, Side};
use crate::skeleton::{roles, Skeleton};
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Limb pairs shorter than this fraction of the longest pair are not limbs (Chicken wings
/// reach 0.28 of its legs; its upstream face joints use them).
const LIMB_REACH_FRACTION: f64 = 0.25;

/// Words of paired head parts that are never limbs, however long.
const FACE_PART_WORDS: &[&str] = &[
    "eye",
    "eyes",
    "eyebrow",
    "brow",
    "eyelid",
    "lid",
    "ear",
    "ears",
    "antenna",
    "antennae",
    "whisker",
    "beard",
    "lip",
    "mouth",
    "jaw",
    "mandible",
    "chelicera",
    "horn",
    "tusk",
    "cheek",
];

/// A joint with position channels is *free* when some rest frame moves it from its OFFSET by
/// more than this fraction of the OFFSET's length (a moving hips under a static dummy root).
const FREE_TRANSLATION_FRACTION: f64 = 0.5;

/// Words (of normalised names, lower case) that mark the head end of a body.
const HEAD_WORDS: &[&str] =
    &["head", "neck", "skull", "jaw", "mouth", "beak", "bill", "nose", "snout", "eye", "eyes", "antenna", "mandible", "chelicera", "cephalothorax", "lip"];

/// Everything AnyTop derives from a skeleton's rest clip; with the `Skeleton` it is enough to
/// encode clips and decode features back to BVH. Plain numbers, so it serialises into the
/// skeleton document. Units: "scaled" means BVH units times `scale_factor`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnyTopRig {
    /// Joints of the skeleton this rig belongs to.
    pub joint_count: usize,
    /// Which clip the rest pose came from.
    pub rest_source: RestSource,
    /// 0.2092142857142857 / mean length of the non-root BVH OFFSETs (End Sites included).
    pub scale_factor: f64,
    /// Lowest y of any joint or End Site over the rest clip, scaled units; subtracted from the
    /// root height of every clip.
    pub ground_height: f64,
    /// The rest root's x, z after turning the rest frame to face +Z, BVH units; subtracted
    /// from every clip's root (AnyTop's `root_pose_init_xz`).
    pub root_origin_xz: [f64; 2],
    /// Heading of the rest frame (radians about +y; forward = (sin, 0, cos)).
    pub rest_heading: f64,
    /// How facing is measured.
    pub facing: Facing,
    pub facing_source: Provenance,
    /// Joints that get contact labels, sorted.
    pub feet: Vec<usize>,
    pub feet_source: Provenance,
    /// Local rotations T_j of the processed rest frame as [x, y, z, w] (the root's includes the
    /// turn to +Z).
    pub rest_rotations: Vec<[f64; 4]>,
    /// The natural rest pose: bone vectors (child − parent, world axes, scaled units) of the
    /// processed rest frame; the root entry is the root's position (0, height, 0). Identity
    /// rotations with these offsets reproduce the processed rest frame.
    pub rest_offsets: Vec<[f64; 3]>,
    /// Joints with position channels that the rest clip moves far from their OFFSET; inverse
    /// kinematics does not aim their parent at them.
    pub free_translations: Vec<usize>,
}

/// Quantities of a rig ready for computation.
pub(super) struct Prepared {
    pub parents: Vec<Option<usize>>,
    pub children: Vec<Vec<usize>>,
    /// C_j = C_parent · T_j.
    pub rest_world: Vec<DQuat>,
    /// For j ≥ 1: N_j = rest_world[p] · D_j · right[j] with right[j] = T_j⁻¹ · C_p⁻¹;
    /// for the root: N_0 = (q · D_0) · T_0⁻¹.
    pub right: Vec<DQuat>,
    pub has_position: Vec<bool>,
    pub is_foot: Vec<bool>,
    pub free: Vec<bool>,
    pub offsets: Vec<DVec3>,
    pub rest_offsets: Vec<DVec3>,
    /// Local translation of every joint in the rest frame, BVH units (C_p⁻¹·rest_offset / s;
    /// the OFFSET for joints without position channels).
    pub rest_translations: Vec<DVec3>,
    pub scale: f64,
    pub ground: f64,
    pub origin: DVec3,
}

impl Prepared {
    /// Aligned (scaled, turned, centred, grounded) position of a BVH-space point.
    pub fn align(&self, q: DQuat, p: DVec3) -> DVec3 {
        self.scale * (q * p - self.origin) - DVec3::new(0.0, self.ground, 0.0)
    }

    /// Inverse of `align`.
    pub fn unalign(&self, q_inv: DQuat, p: DVec3) -> DVec3 {
        q_inv * ((p + DVec3::new(0.0, self.ground, 0.0)) / self.scale + self.origin)
    }
}

impl AnyTopRig {
    /// Process a skeleton's rest clip: `rest`'s frame 0 is the rest pose; all its frames
    /// count for the ground height.
    pub fn new(skeleton: &Skeleton, rest: &Motion, options: &RigOptions) -> Result<AnyTopRig, AnyTopError> {
        skeleton.validate()?;
        let n = skeleton.len();
        if rest.joints != n {
            return Err(AnyTopError::JointCount { what: "the rest motion", got: rest.joints, expected: n });
        }
        if rest.frames == 0 {
            return Err(AnyTopError::EmptyRest);
        }
        let mean_bone = mean_offset_length(skeleton)?;
        let scale = HUMANML_MEAN_BONE_LENGTH / mean_bone;
        // f64 keeps about 16 digits: a bone measured from positions 1e9 bones out keeps ~7.
        for (j, t) in rest.translations.iter().take(n).enumerate() {
            let value = t.abs().max_element();
            if !(value <= 1e9 * mean_bone) {
                return Err(AnyTopError::RestOutOfRange { joint: j, name: skeleton.joints[j].name.clone(), value });
            }
        }

        let world = rest.forward_kinematics(skeleton);
        let p0 = world.frame_positions(0);

        let (feet, feet_source) = match &options.feet {
            Some(f) => {
                let mut f = f.clone();
                f.sort_unstable();
                f.dedup();
                (f, Provenance::Override)
            }
            None => (roles::feet(skeleton).0, Provenance::Automatic),
        };
        check_indices("the foot list", &feet, n)?;
        let (facing, facing_source) = match (options.face_joints, options.body_axis) {
            (Some(j), _) => (Facing::FaceJoints(j), Provenance::Override),
            (None, Some([front, back])) => (Facing::BodyAxis { front, back }, Provenance::Override),
            (None, None) => (automatic_facing(skeleton, p0, &feet), Provenance::Automatic),
        };
        check_indices("the facing rule", &facing.joints(), n)?;

        let rest_heading = facing.forward(p0).map(heading_of).unwrap_or(0.0);
        let q = yaw_to_front(rest_heading);
        let turned_root = q * p0[0];
        let root_origin_xz = [turned_root.x, turned_root.z];

        // Lowest joint or End Site over the whole rest clip (a yaw does not change heights).
        let mut lowest = f64::INFINITY;
        for f in 0..rest.frames {
            for (j, joint) in skeleton.joints.iter().enumerate() {
                let p = world.position(f, j);
                lowest = lowest.min(p.y);
                let r = world.rotations[f * n + j];
                for e in &joint.end_sites {
                    lowest = lowest.min((p + r * *e).y);
                }
            }
        }
        let ground_height = scale * lowest;

        let mut rest_rotations: Vec<[f64; 4]> = rest.rotations[..n].iter().map(|r| r.normalize().to_array()).collect();
        rest_rotations[0] = (q * DQuat::from_array(rest_rotations[0])).normalize().to_array();
        let rest_offsets = (0..n)
            .map(|j| match skeleton.joints[j].parent {
                None => [0.0, scale * p0[0].y - ground_height, 0.0],
                Some(p) => (scale * (q * (p0[j] - p0[p]))).to_array(),
            })
            .collect();

        let extent = skeleton.rest_extent().max(1e-12);
        let free_translations = (1..n)
            .filter(|&j| {
                let joint = &skeleton.joints[j];
                joint.channels.iter().any(|c| !c.is_rotation()) && {
                    let limit = FREE_TRANSLATION_FRACTION * joint.offset.length() + 1e-9 * extent;
                    (0..rest.frames).any(|f| rest.translations[f * n + j].distance(joint.offset) > limit)
                }
            })
            .collect();

        Ok(AnyTopRig {
            joint_count: n,
            rest_source: options.rest_source.clone(),
            scale_factor: scale,
            ground_height,
            root_origin_xz,
            rest_heading,
            facing,
            facing_source,
            feet,
            feet_source,
            rest_rotations,
            rest_offsets,
            free_translations,
        })
    }

    /// Check that the rig fits the skeleton and holds usable numbers (rigs come from files).
    pub fn check(&self, skeleton: &Skeleton) -> Result<(), AnyTopError> {
        skeleton.validate()?;
        let n = skeleton.len();
        if self.joint_count != n {
            return Err(AnyTopError::JointCount { what: "the AnyTop rig", got: self.joint_count, expected: n });
        }
        let bad = |what: &str| Err(AnyTopError::BadRig(what.to_string()));
        if self.rest_rotations.len() != n || self.rest_offsets.len() != n {
            return bad("rest rotations or offsets do not have one entry per joint");
        }
        if !(self.scale_factor.is_finite() && self.scale_factor > 0.0) {
            return bad("scale factor is not a positive number");
        }
        let numbers = [self.ground_height, self.root_origin_xz[0], self.root_origin_xz[1], self.rest_heading];
        if numbers.iter().chain(self.rest_offsets.iter().flatten()).any(|v| !v.is_finite()) {
            return bad("non-finite number");
        }
        if self.rest_rotations.iter().any(|r| {
            let q = DQuat::from_array(*r);
            !q.is_finite() || (q.length() - 1.0).abs() > 1e-6
        }) {
            return bad("a rest rotation is not a unit quaternion");
        }
        check_indices("the facing rule", &self.facing.joints(), n)?;
        check_indices("the foot list", &self.feet, n)?;
        check_indices("the free-translation list", &self.free_translations, n)?;
        Ok(())
    }

    pub(super) fn prepare(&self, skeleton: &Skeleton) -> Result<Prepared, AnyTopError> {
        self.check(skeleton)?;
        let n = skeleton.len();
        let parents = skeleton.parents();
        let rest_rot: Vec<DQuat> = self.rest_rotations.iter().map(|r| DQuat::from_array(*r).normalize()).collect();
        let mut rest_world = rest_rot.clone();
        let mut right = vec![DQuat::IDENTITY; n];
        right[0] = rest_rot[0].inverse();
        for j in 1..n {
            let p = parents[j].expect("validated: only joint 0 is a root");
            rest_world[j] = rest_world[p] * rest_rot[j];
            right[j] = rest_rot[j].inverse() * rest_world[p].inverse();
        }
        let rest_offsets: Vec<DVec3> = self.rest_offsets.iter().map(|o| DVec3::from_array(*o)).collect();
        let offsets: Vec<DVec3> = skeleton.joints.iter().map(|j| j.offset).collect();
        let has_position: Vec<bool> = skeleton.joints.iter().map(|j| j.channels.iter().any(|c| !c.is_rotation())).collect();
        let mut rest_translations = offsets.clone();
        for j in 1..n {
            let p = parents[j].expect("validated");
            let t = rest_world[p].inverse() * rest_offsets[j] / self.scale_factor;
            if has_position[j] {
                rest_translations[j] = t;
            } else if t.distance(offsets[j]) > 1e-6 * offsets[j].length() + 1e-7 * HUMANML_MEAN_BONE_LENGTH / self.scale_factor {
                return Err(AnyTopError::BadRig(format!(
                    "joint {j} '{}': the rig's rest bone does not match the skeleton's OFFSET (a rig of another skeleton?)",
                    skeleton.joints[j].name
                )));
            }
        }
        let mut is_foot = vec![false; n];
        for &f in &self.feet {
            is_foot[f] = true;
        }
        let mut free = vec![false; n];
        for &f in &self.free_translations {
            free[f] = true;
        }
        Ok(Prepared {
            children: skeleton.children(),
            parents,
            rest_world,
            right,
            has_position,
            is_foot,
            free,
            offsets,
            rest_offsets,
            rest_translations,
            scale: self.scale_factor,
            ground: self.ground_height,
            origin: DVec3::new(self.root_origin_xz[0], 0.0, self.root_origin_xz[1]),
        })
    }

    /// World positions of the natural rest pose (identity rotations with `rest_offsets`):
    /// scaled units, facing +Z, grounded.
    pub fn rest_positions(&self, skeleton: &Skeleton) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = Vec::with_capacity(self.rest_offsets.len());
        for (j, o) in self.rest_offsets.iter().enumerate() {
            let o = DVec3::from_array(*o);
            out.push(match skeleton.joints.get(j).and_then(|x| x.parent) {
                None => o,
                Some(p) => out[p] + o,
            });
        }
        out
    }

    /// The rest-pose feature row P_S (§1.7), `[1, joints, 13]`: the features of the processed
    /// rest frame, with identity 6D for every non-root joint (the rest pose relative to
    /// itself), the rest facing for the root, velocities from rest frames 0 -> 1 (zero for a
    /// one-frame rest clip). `rest` must be the clip the rig was built from.
    pub fn rest_features(&self, skeleton: &Skeleton, rest: &Motion) -> Result<Features, AnyTopError> {
        if rest.joints != skeleton.len() {
            return Err(AnyTopError::JointCount { what: "the rest motion", got: rest.joints, expected: skeleton.len() });
        }
        if rest.frames == 0 {
            return Err(AnyTopError::EmptyRest);
        }
        let n = rest.joints;
        let second = if rest.frames > 1 { 1 } else { 0 };
        let frames = |f: usize| f * n..(f + 1) * n;
        let two = Motion {
            frames: 2,
            joints: n,
            frame_time: rest.frame_time,
            rotations: [&rest.rotations[frames(0)], &rest.rotations[frames(second)]].concat(),
            translations: [&rest.translations[frames(0)], &rest.translations[frames(second)]].concat(),
        };
        let mut features = self.encode(skeleton, &two)?.features;
        for j in 1..n {
            features.at_mut(0, j)[super::DIMS_ROTATION].copy_from_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        }
        Ok(features)
    }

    /// The placement that puts a decoded clip where the rest pose stands, facing its way
    /// (for generated features, which carry no placement).
    pub fn rest_placement(&self) -> super::Placement {
        let root = yaw_to_front(self.rest_heading).inverse() * DVec3::new(self.root_origin_xz[0], 0.0, self.root_origin_xz[1]);
        super::Placement { heading: self.rest_heading, root_xz: [root.x, root.z] }
    }
}

fn check_indices(what: &'static str, joints: &[usize], n: usize) -> Result<(), AnyTopError> {
    match joints.iter().find(|&&j| j >= n) {
        Some(&joint) => Err(AnyTopError::JointIndex { what, joint, joints: n }),
        None => Ok(()),
    }
}

/// Mean length of the non-root OFFSETs, non-zero End Site OFFSETs included (§1.3: the
/// reference loader turns non-zero End Sites into joints).
fn mean_offset_length(skeleton: &Skeleton) -> Result<f64, AnyTopError> {
    let mut sum = 0.0;
    let mut count = 0usize;
    for joint in &skeleton.joints {
        if joint.parent.is_some() {
            sum += joint.offset.length();
            count += 1;
        }
        for e in joint.end_sites.iter().filter(|e| **e != DVec3::ZERO) {
            sum += e.length();
            count += 1;
        }
    }
    let mean = if count == 0 { 0.0 } else { sum / count as f64 };
    if mean > 0.0 && mean.is_finite() {
        Ok(mean)
    } else {
        Err(AnyTopError::NoBones)
    }
}

/// The automatic facing rule (module doc).
pub(super) fn automatic_facing(skeleton: &Skeleton, p0: &[DVec3], feet: &[usize]) -> Facing {
    let n = skeleton.len();
    let normalised: Vec<String> = skeleton.joints.iter().map(|j| names::normalise(&j.name)).collect();
    let sides = roles::sides(skeleton, &normalised);
    let parents = skeleton.parents();
    let children = skeleton.children();
    let lateral = |j: usize| matches!(sides[j], Side::Left | Side::Right);

    // Reach of each joint's subtree: the longest chain of OFFSETs (End Sites included) below it.
    let mut reach = vec![0.0f64; n];
    for j in (0..n).rev() {
        let mut r = skeleton.joints[j].end_sites.iter().map(|e| e.length()).fold(0.0, f64::max);
        for &c in &children[j] {
            r = r.max(skeleton.joints[c].offset.length() + reach[c]);
        }
        reach[j] = r;
    }
    let mut holds_foot = vec![false; n];
    for &f in feet {
        holds_foot[f] = true;
    }
    for j in (1..n).rev() {
        if holds_foot[j] {
            if let Some(p) = parents[j] {
                holds_foot[p] = true;
            }
        }
    }

    // Limb roots and their left/right pairs.
    let limb_roots: Vec<usize> = (0..n).filter(|&j| lateral(j) && parents[j].is_none_or(|p| !lateral(p))).collect();
    let lefts: Vec<usize> = limb_roots.iter().copied().filter(|&j| sides[j] == Side::Left).collect();
    let rights: Vec<usize> = limb_roots.iter().copied().filter(|&j| sides[j] == Side::Right).collect();
    let keys: Vec<String> = skeleton.joints.iter().map(|j| names::mirror_key(&j.name)).collect();
    let mut used = vec![false; n];
    let mut pairs: Vec<(usize, usize)> = Vec::new(); // (right, left)
    let mut unpaired = Vec::new();
    for &l in &lefts {
        match rights.iter().copied().find(|&r| !used[r] && parents[r] == parents[l] && keys[r] == keys[l]) {
            Some(r) => {
                used[r] = true;
                pairs.push((r, l));
            }
            None => unpaired.push(l),
        }
    }
    for &l in &unpaired {
        if let Some(r) = rights.iter().copied().find(|&r| !used[r] && parents[r] == parents[l]) {
            used[r] = true;
            pairs.push((r, l));
        }
    }

    let face_part = |j: usize| normalised[j].to_lowercase().split(' ').any(|w| FACE_PART_WORDS.contains(&w));
    pairs.retain(|&(r, l)| !face_part(r) && !face_part(l));
    let head = body_front(skeleton, &normalised, &sides, p0);
    if pairs.is_empty() {
        return body_axis(skeleton, &parents, &children, p0, head);
    }

    let pair_reach = |&(r, l): &(usize, usize)| 0.5 * (reach[r] + reach[l]);
    let longest = pairs.iter().map(pair_reach).fold(0.0, f64::max);
    let centroid = p0.iter().copied().sum::<DVec3>() / n as f64;
    let axis = head.map(|(_, axis)| axis).unwrap_or(DVec3::Z);
    let frontness = |&(r, l): &(usize, usize)| ((p0[r] + p0[l]) * 0.5 - centroid).dot(axis);
    let by_front = |a: &(usize, usize), b: &(usize, usize)| frontness(a).total_cmp(&frontness(b));
    let limbs: Vec<(usize, usize)> = pairs.iter().copied().filter(|p| pair_reach(p) >= LIMB_REACH_FRACTION * longest).collect();
    let legs: Vec<(usize, usize)> = pairs.iter().copied().filter(|&(r, l)| holds_foot[r] || holds_foot[l]).collect();
    let hips = legs.iter().copied().min_by(by_front).or_else(|| limbs.iter().copied().min_by(by_front)).expect("the longest pair is a limb");
    let shoulders = limbs.iter().copied().filter(|&p| p != hips).max_by(by_front).unwrap_or(hips);

    let extent = skeleton.rest_extent().max(1e-12);
    let spread = |(mut r, mut l): (usize, usize)| {
        while p0[r].distance(p0[l]) < 1e-6 * extent && children[r].len() == 1 && children[l].len() == 1 {
            r = children[r][0];
            l = children[l][0];
        }
        (r, l)
    };
    let (rh, lh) = spread(hips);
    let (rs, ls) = spread(shoulders);
    Facing::FaceJoints([rh, lh, rs, ls])
}

/// Where the body's front is, from names: `(point, unit direction from the centroid)`.
fn body_front(skeleton: &Skeleton, normalised: &[String], sides: &[Side], p0: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let n = skeleton.len();
    let has_word = |j: usize, words: &[&str]| normalised[j].to_lowercase().split(' ').any(|w| words.contains(&w));
    let mean_of = |set: Vec<usize>| (!set.is_empty()).then(|| set.iter().map(|&j| p0[j]).sum::<DVec3>() / set.len() as f64);
    let centroid = p0.iter().copied().sum::<DVec3>() / n as f64;
    let centre_head: Vec<usize> = (0..n).filter(|&j| sides[j] == Side::Centre && has_word(j, HEAD_WORDS)).collect();
    let any_head: Vec<usize> = (0..n).filter(|&j| has_word(j, HEAD_WORDS)).collect();
    let head = mean_of(centre_head).or_else(|| mean_of(any_head));
    if let Some(h) = head {
        if let Some(d) = (h - centroid).try_normalize() {
            return Some((h, d));
        }
    }
    let tail = mean_of((0..n).filter(|&j| has_word(j, &["tail"])).collect());
    if let Some(t) = tail {
        if let Some(d) = (centroid - t).try_normalize() {
            return Some((centroid + (centroid - t), d));
        }
    }
    None
}

/// Facing along the body for a creature without left/right limbs.
fn body_axis(skeleton: &Skeleton, parents: &[Option<usize>], children: &[Vec<usize>], p0: &[DVec3], head: Option<(DVec3, DVec3)>) -> Facing {
    let n = skeleton.len();
    // Farthest joint from `start` along the tree, by bone length.
    let farthest = |start: usize| -> usize {
        let mut dist = vec![f64::NAN; n];
        dist[start] = 0.0;
        let mut stack = vec![start];
        while let Some(u) = stack.pop() {
            let nbrs = children[u].iter().copied().chain(parents[u]);
            for v in nbrs {
                if dist[v].is_nan() {
                    let bone = if parents[v] == Some(u) { skeleton.joints[v].offset } else { skeleton.joints[u].offset };
                    dist[v] = dist[u] + bone.length();
                    stack.push(v);
                }
            }
        }
        (0..n).max_by(|&a, &b| dist[a].total_cmp(&dist[b]).then(b.cmp(&a))).unwrap_or(0)
    };
    let a = farthest(0);
    let b = farthest(a);
    let depth = skeleton.depths();
    let (front, back) = match head {
        Some((h, _)) => {
            if p0[a].distance(h) <= p0[b].distance(h) {
                (a, b)
            } else {
                (b, a)
            }
        }
        None => {
            if depth[a] <= depth[b] {
                (a, b)
            } else {
                (b, a)
            }
        }
    };
    Facing::BodyAxis { front, back }
}

impl AnyTopRig {
    /// One line about the rig (`mo-encode -v`): where its rest pose came from, its facing, feet and scale.
    pub fn describe(&self, skeleton: &Skeleton) -> String {
        let rig = self;
        let name = |j: usize| skeleton.joints.get(j).map_or("?", |x| x.name.as_str());
        let how = |p: Provenance| if p == Provenance::Override { "given" } else { "automatic" };
        let rest = match &rig.rest_source {
            RestSource::TPose { file } => format!("rest pose frame 0 of {file} (T-pose)"),
            RestSource::FirstClip { file } | RestSource::Explicit { file } => format!("rest pose frame 0 of {file}"),
            RestSource::Offsets => "rest pose from the OFFSETs".to_string(),
            RestSource::Unrecorded => "rest pose not recorded".to_string(),
        };
        let facing = match &rig.facing {
            Facing::FaceJoints(f) => format!("face joints {}, {}, {}, {}", name(f[0]), name(f[1]), name(f[2]), name(f[3])),
            Facing::BodyAxis { front, back } => format!("body axis {} -> {}", name(*back), name(*front)),
        };
        format!("{rest}; {facing} ({}); {} foot joint(s) ({}); scale {:.6}", how(rig.facing_source), rig.feet.len(), how(rig.feet_source), rig.scale_factor)
    }
}

#[cfg(test)]
mod tests {
    use crate::skeleton::names::mirror_key;

    #[test]
    fn mirror_keys_agree_across_sides() {
        for (a, b) in [
            ("DEF_BN_Leg_L_11", "DEF_BN_Leg_R_11"),
            ("LeftUpLeg", "RightUpLeg"),
            ("LHipJoint", "RHipJoint"),
            ("Bip01_L_Thigh__UfG", "Bip01_R_Thigh__qPK"),
            ("leg_l1_coxa", "leg_r1_coxa"),
            ("mixamorig:LeftShoulder", "mixamorig:RightShoulder"),
            ("Shoulder_L", "Shoulder_R"),
        ] {
            assert_eq!(mirror_key(a), mirror_key(b), "{a} / {b}");
        }
        assert_ne!(mirror_key("DEF_BN_Leg_L_11"), mirror_key("DEF_BN_Leg_R_07"));
    }
}
