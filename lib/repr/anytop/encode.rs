//! Motion -> AnyTop features (docs/reference/anytop.md §1.4–1.6; the table is in the module doc).

use super::rig::Prepared;
use super::{
    heading_of, put3, put_6d, yaw_to_front, AnyTopError, AnyTopRig, Encoded, Placement, DIMS_POSITION, DIMS_ROTATION, DIMS_VELOCITY, DIM_CONTACT, FEATURE_DIMS,
    FOOT_CONTACT_HEIGHT, FOOT_CONTACT_SQUARED_DISPLACEMENT,
};
use crate::motion::Motion;
use crate::repr::Features;
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};

impl AnyTopRig {
    /// Encode a whole clip (no slicing, native frame rate): `[frames − 1, joints, 13]`, and
    /// where the clip stood. A clip of fewer than two frames gives zero feature frames.
    pub fn encode(&self, skeleton: &Skeleton, motion: &Motion) -> Result<Encoded, AnyTopError> {
        let prep = self.prepare(skeleton)?;
        let n = skeleton.len();
        if motion.joints != n {
            return Err(AnyTopError::JointCount { what: "the motion", got: motion.joints, expected: n });
        }
        let frames = motion.frames;
        if frames == 0 {
            return Ok(Encoded { features: Features::zeros(0, n, FEATURE_DIMS), placement: self.rest_placement() });
        }
        let world = motion.forward_kinematics(skeleton);

        // This clip's turn to +Z, from its frame 0.
        let heading = self.facing.forward(world.frame_positions(0)).map(heading_of).unwrap_or(0.0);
        let q = yaw_to_front(heading);
        let root0 = world.position(0, 0);
        let placement = Placement { heading, root_xz: [root0.x, root0.z] };

        let aligned: Vec<DVec3> = world.positions.iter().map(|&p| prep.align(q, p)).collect();
        let facing = per_frame_facing(self, &aligned, n, frames);

        let mut features = Features::zeros(frames.saturating_sub(1), n, FEATURE_DIMS);
        let mut local = vec![DQuat::IDENTITY; n];
        for t in 0..frames.saturating_sub(1) {
            reexpress(&prep, q, &motion.rotations[t * n..(t + 1) * n], &mut local);
            let now = &aligned[t * n..(t + 1) * n];
            let next = &aligned[(t + 1) * n..(t + 2) * n];
            let (r, r_next) = (facing[t], facing[t + 1]);
            let base = DVec3::new(now[0].x, 0.0, now[0].z);
            for j in 0..n {
                let out = features.at_mut(t, j);
                match prep.parents[j] {
                    None => {
                        out[DIMS_POSITION].copy_from_slice(&[0.0, now[0].y as f32, 0.0]);
                        put_6d(&mut out[DIMS_ROTATION], r);
                    }
                    Some(p) => {
                        put3(&mut out[DIMS_POSITION], r * (now[j] - base));
                        put_6d(&mut out[DIMS_ROTATION], local[p]);
                    }
                }
                let step = next[j] - now[j];
                put3(&mut out[DIMS_VELOCITY], r_next * step);
                if prep.is_foot[j] && step.length_squared() <= FOOT_CONTACT_SQUARED_DISPLACEMENT && next[j].y.abs() <= FOOT_CONTACT_HEIGHT {
                    out[DIM_CONTACT] = 1.0;
                }
            }
        }
        Ok(Encoded { features, placement })
    }
}

/// r_t for every frame: the yaw that turns frame t's facing to +Z; a degenerate frame keeps
/// the previous frame's (identity before the first).
fn per_frame_facing(rig: &AnyTopRig, aligned: &[DVec3], n: usize, frames: usize) -> Vec<DQuat> {
    let mut out = Vec::with_capacity(frames);
    let mut previous = DQuat::IDENTITY;
    for t in 0..frames {
        if let Some(f) = rig.facing.forward(&aligned[t * n..(t + 1) * n]) {
            previous = yaw_to_front(heading_of(f));
        }
        out.push(previous);
    }
    out
}

/// Local rotations re-expressed against the natural rest pose (§1.5):
/// N_0 = (q·D_0)·T_0⁻¹, N_j = C_p·D_j·T_j⁻¹·C_p⁻¹.
pub(super) fn reexpress(prep: &Prepared, q: DQuat, clip: &[DQuat], out: &mut [DQuat]) {
    for (j, (o, &d)) in out.iter_mut().zip(clip).enumerate() {
        *o = match prep.parents[j] {
            None => q * d * prep.right[0],
            Some(p) => prep.rest_world[p] * d * prep.right[j],
        };
    }
}
