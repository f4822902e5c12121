//! The creature's body in a glTF we write: one tapered four-sided stick per bone, so a viewer
//! that knows nothing of skeletons still shows the creature moving, like a wooden puppet. Every
//! vertex follows one joint with weight 1: the stick's base ring its parent joint, its tip ring
//! the child joint. A stick wholly on the parent would not reach a child whose translation is
//! animated (Bandai Namco and Truebones files key every joint's position): the headless-browser
//! check (tools/chromium_gltf_check.py) showed such a stick as a beam left at the rest pose.
//! A child that travels away from its rest offset (Bandai's hips, keyed in world coordinates
//! under a root at the origin) gets no stick at all: that is a displacement, not a bone, and
//! drawn it is a beam from the world origin to the creature.

use crate::motion::Motion;
use crate::skeleton::Skeleton;
use glam::DVec3;

/// Vertex positions (rest pose, world), the joint each vertex follows, and triangle indices.
pub struct Sticks {
    pub positions: Vec<[f32; 3]>,
    pub joints: Vec<u16>,
    pub indices: Vec<u32>,
}

/// Thickness at the joint end of a stick, as a fraction of its length; the far end is a quarter
/// of it, so the direction of each bone shows.
const BASE_RADIUS: f64 = 0.08;
const TIP_RADIUS: f64 = 0.02;

/// A child whose local translation strays further than this share of its rest offset's length
/// is travelling, not hanging from a bone.
const TRAVEL: f64 = 0.05;

/// Sticks from each joint to its children and End Sites (an End Site's tip follows its joint),
/// except to children that travel in `motion`; `None` when the skeleton has no bone to draw or
/// more joints than a 16-bit JOINTS_0 attribute can name.
pub fn sticks(skeleton: &Skeleton, motion: &Motion, rest: &[DVec3]) -> Option<Sticks> {
    if skeleton.joints.len() > usize::from(u16::MAX) {
        return None;
    }
    let mut out = Sticks { positions: Vec::new(), joints: Vec::new(), indices: Vec::new() };
    for (j, joint) in skeleton.joints.iter().enumerate() {
        if let Some(p) = joint.parent.filter(|_| !travels(motion, j, joint.offset)) {
            add_stick(&mut out, (rest[p], p as u16), (rest[j], j as u16));
        }
        for e in &joint.end_sites {
            add_stick(&mut out, (rest[j], j as u16), (rest[j] + *e, j as u16));
        }
    }
    (!out.indices.is_empty()).then_some(out)
}

fn travels(motion: &Motion, joint: usize, offset: DVec3) -> bool {
    let limit = TRAVEL * offset.length();
    (0..motion.frames).any(|f| motion.translations[f * motion.joints + joint].distance(offset) > limit)
}

fn add_stick(out: &mut Sticks, (head, head_joint): (DVec3, u16), (tail, tail_joint): (DVec3, u16)) {
    let along = tail - head;
    let length = along.length();
    let Some(dir) = along.try_normalize() else { return };
    if !(length > 0.0) || !length.is_finite() {
        return;
    }
    let u = dir.any_orthonormal_vector();
    let v = dir.cross(u);
    let first = out.positions.len() as u32;
    for (centre, radius, joint) in [(head, BASE_RADIUS * length, head_joint), (tail, TIP_RADIUS * length, tail_joint)] {
        for (a, b) in [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)] {
            let p = centre + (u * a + v * b) * radius;
            out.positions.push([p.x as f32, p.y as f32, p.z as f32]);
            out.joints.push(joint);
        }
    }
    // Base ring 0-3, tip ring 4-7: four sides of two triangles, and both end caps.
    for k in 0..4u32 {
        let n = (k + 1) % 4;
        out.indices.extend([first + k, first + n, first + 4 + n, first + k, first + 4 + n, first + 4 + k]);
    }
    out.indices.extend([first, first + 2, first + 1, first, first + 3, first + 2]);
    out.indices.extend([first + 4, first + 5, first + 6, first + 4, first + 6, first + 7]);
}
