//! Inverse kinematics for decoding from positions: rotations of the natural rest pose that put
//! every joint on its target.
//!
//! Like the reference (docs/reference/anytop.md §1.10 step 4) joints are visited in index order
//! (parents first) and each is rotated so that the directions to its children match the directions
//! from its current position to their targets. Where the reference takes one averaged (log-mean)
//! per-child rotation per visit and repeats whole passes up to 150 times, we solve each joint to
//! convergence: the rotation minimising Σ_c ‖N·â_c − û_c‖² over its children c (unit rest and
//! target directions, equal weights), by damped Gauss-Newton from the minimal swing that aims the
//! longest child, stopping when the update is below `tolerance`. A joint's solution depends only on
//! its ancestors', so one pass is the fixed point the reference's passes approach.
//!
//! * One child: the minimal swing out of the natural rest pose (no twist, as the rest pose).
//! * Children with collinear directions: the damping keeps the twist about their line at the
//!   swing's (the positions do not determine it).
//! * Children whose translation is free (`AnyTopRig::free_translations`) or that sit on their
//!   parent do not aim it; a joint with no aiming child keeps its rest rotation.
//! * Joints with position channels are placed on their targets (their translation absorbs any
//!   change of bone length); the others at parent + rotated rest offset.

use super::rig::Prepared;
use glam::{DMat3, DQuat, DVec3};

/// Stopping rule of the per-joint solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkOptions {
    /// Gauss-Newton iterations per joint at most.
    pub max_iterations: usize,
    /// Stop when the rotation update is smaller than this (radians).
    pub tolerance: f64,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions { max_iterations: 50, tolerance: 1e-10 }
    }
}

pub(super) struct Scratch {
    world: Vec<DQuat>,
    positions: Vec<DVec3>,
    rest_dirs: Vec<DVec3>,
    target_dirs: Vec<DVec3>,
}

impl Scratch {
    pub fn new(n: usize) -> Scratch {
        Scratch { world: vec![DQuat::IDENTITY; n], positions: vec![DVec3::ZERO; n], rest_dirs: Vec::new(), target_dirs: Vec::new() }
    }
}

/// Re-expressed local rotations (aligned space) of one frame that reach `targets`.
pub(super) fn solve_frame(prep: &Prepared, targets: &[DVec3], options: &IkOptions, s: &mut Scratch, local: &mut [DQuat]) {
    for j in 0..targets.len() {
        let parent_world = prep.parents[j].map_or(DQuat::IDENTITY, |p| s.world[p]);
        s.positions[j] = match prep.parents[j] {
            Some(p) if !prep.has_position[j] => s.positions[p] + parent_world * prep.rest_offsets[j],
            _ => targets[j],
        };
        s.rest_dirs.clear();
        s.target_dirs.clear();
        let to_parent = parent_world.inverse();
        let mut longest = (0.0, 0);
        for &c in &prep.children[j] {
            let rest = prep.rest_offsets[c];
            let aim = to_parent * (targets[c] - s.positions[j]);
            if prep.free[c] || rest.length() < 1e-9 {
                continue;
            }
            if let (Some(a), Some(u)) = (rest.try_normalize(), aim.try_normalize()) {
                if rest.length() > longest.0 {
                    longest = (rest.length(), s.rest_dirs.len());
                }
                s.rest_dirs.push(a);
                s.target_dirs.push(u);
            }
        }
        local[j] = fit(&s.rest_dirs, &s.target_dirs, longest.1, options);
        s.world[j] = parent_world * local[j];
    }
}

/// The rotation N minimising Σ ‖N·rest_i − target_i‖² (unit vectors), from the swing that
/// aims `start`.
fn fit(rest: &[DVec3], target: &[DVec3], start: usize, options: &IkOptions) -> DQuat {
    if rest.is_empty() {
        return DQuat::IDENTITY;
    }
    let mut n = DQuat::from_rotation_arc(rest[start], target[start]);
    if rest.len() == 1 {
        return n;
    }
    let damping = 1e-6 * rest.len() as f64;
    for _ in 0..options.max_iterations {
        // Linearise N ← exp(ω)·N: H ω = Σ v × u with H = Σ (I − v vᵀ), v = N·rest.
        let mut h = DMat3::from_diagonal(DVec3::splat(damping));
        let mut g = DVec3::ZERO;
        for (a, u) in rest.iter().zip(target) {
            let v = n * *a;
            h += DMat3::IDENTITY - DMat3::from_cols(v * v.x, v * v.y, v * v.z);
            g += v.cross(*u);
        }
        let mut w = h.inverse() * g;
        let step = w.length();
        if step > 1.0 {
            w /= step;
        }
        n = (DQuat::from_scaled_axis(w) * n).normalize();
        if step < options.tolerance {
            break;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_rotation_from_three_directions() {
        let truth = DQuat::from_euler(glam::EulerRot::ZXY, 0.7, -1.2, 2.5);
        let rest = [DVec3::X, DVec3::new(0.0, 1.0, 1.0).normalize(), DVec3::new(-1.0, 0.2, 0.3).normalize()];
        let target: Vec<DVec3> = rest.iter().map(|a| truth * *a).collect();
        let n = fit(&rest, &target, 0, &IkOptions::default());
        assert!(n.dot(truth).abs() > 1.0 - 1e-12, "{n:?} vs {truth:?}");
    }

    #[test]
    fn collinear_children_keep_the_swing() {
        let rest = [DVec3::Y, DVec3::Y];
        let target = [DVec3::X, DVec3::X];
        let n = fit(&rest, &target, 0, &IkOptions::default());
        assert!(n.dot(DQuat::from_rotation_arc(DVec3::Y, DVec3::X)).abs() > 1.0 - 1e-12);
    }
}
