//! Reconstruction and retargeting errors against a ground truth on the same skeleton (SATA,
//! following SAME and SAN; SATA paper §4.1.3 and appendix D.2): JR, RT, JP,
//! FS, GP and the character-normalised retargeting error. Definitions and deviations:
//! `docs/metrics.md`.

use super::physics::{self, check_clip, Maybe, Measure, PhysicsOptions};
use super::{MetricError, WorldClip};
use crate::skeleton::Skeleton;
use glam::DQuat;

/// Local joint rotations of the reference and the result, `[frame * joints + joint]`, and the
/// joints whose rotation error counts (usually [`rotation_joints`]).
#[derive(Clone, Debug)]
pub struct Rotations<'a> {
    pub reference: &'a [DQuat],
    pub result: &'a [DQuat],
    pub counted: Vec<usize>,
}

/// Units of the report's fields.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ReconstructionUnits {
    pub jr: &'static str,
    pub rt: &'static str,
    pub jp: &'static str,
    pub fs: &'static str,
    pub gp: &'static str,
    pub retargeting_error: &'static str,
}

const UNITS: ReconstructionUnits = ReconstructionUnits {
    jr: "radians",
    rt: "clip units; normalised: divided by height",
    jp: "clip units; normalised: divided by height",
    fs: "clip units per second; normalised: skeleton sizes per second (see physics)",
    gp: "clip units; normalised: skeleton sizes (see physics)",
    retargeting_error: "1000 x mean squared joint distance / height² (dimensionless)",
};

#[derive(Clone, Debug, serde::Serialize)]
pub struct ReconstructionReport {
    pub frames: usize,
    pub joints: usize,
    /// The height errors are normalised by (the target character's, as SAN defines it).
    pub height: f64,
    /// Joint rotations: mean geodesic angle between reference and result local rotations
    /// over the counted joints and all frames.
    pub jr: Maybe<f64>,
    /// Joints that JR counted.
    pub jr_joints: usize,
    /// Root trajectory: mean distance between the reference and result root positions.
    pub rt: Measure,
    /// Joint positions: mean distance between reference and result world positions, over all
    /// joints and frames.
    pub jp: Measure,
    /// Foot skating of the result (`physics::physics`).
    pub fs: Maybe<Measure>,
    /// Ground penetration of the result.
    pub gp: Measure,
    /// The reference's own foot skating and penetration, the floor a result can reach.
    pub reference_fs: Maybe<Measure>,
    pub reference_gp: Measure,
    /// SAN's retargeting error: 1000 x mean over joints and frames of |p - p̂|² / height².
    pub retargeting_error: f64,
    pub units: ReconstructionUnits,
}

/// Joints whose local rotation is meaningful: those with a rotation channel that move
/// something (a child joint or an End Site). A leaf's rotation moves nothing, and a joint
/// without rotation channels never rotates, so counting them would dilute JR.
pub fn rotation_joints(skeleton: &Skeleton) -> Vec<usize> {
    let children = skeleton.children();
    skeleton
        .joints
        .iter()
        .enumerate()
        .filter(|(j, joint)| joint.channels.iter().any(|c| c.is_rotation()) && (!children[*j].is_empty() || !joint.end_sites.is_empty()))
        .map(|(j, _)| j)
        .collect()
}

/// Geodesic angle between two rotations, in [0, π] (q and -q are the same rotation). The
/// half-angle comes from atan2(|a - b|, |a + b|), exact for equal inputs and accurate for
/// small angles, where 2 acos(a . b) loses half the digits.
fn angle_between(a: DQuat, b: DQuat) -> f64 {
    let (a, mut b) = (a.normalize(), b.normalize());
    if a.dot(b) < 0.0 {
        b = -b;
    }
    4.0 * (a - b).length().atan2((a + b).length())
}

fn check_rotations(r: &Rotations, frames: usize, joints: usize) -> Result<(), MetricError> {
    let want = frames * joints;
    for (what, q) in [("reference", r.reference), ("result", r.result)] {
        if q.len() != want {
            return Err(MetricError::Mismatch(format!("JR: the {what} has {} rotations, expected {frames} frames x {joints} joints = {want}", q.len())));
        }
        if let Some(i) = q.iter().position(|q| !q.is_finite() || q.length_squared() < 1e-24) {
            return Err(MetricError::NonFinite(format!(
                "JR: the {what} rotation at frame {}, joint {} is {:?} (not a rotation)",
                i / joints,
                i % joints,
                q[i]
            )));
        }
    }
    if let Some(&j) = r.counted.iter().find(|&&j| j >= joints) {
        return Err(MetricError::Mismatch(format!("JR: counted joint {j} is outside the {joints} joints")));
    }
    Ok(())
}

/// Compare a result with its reference, frame by frame and joint by joint. Both clips must
/// have the same joints, frames and frame rate (within 0.1%); `height` must be positive and
/// finite. One frame is a pose reconstruction: FS is then `NotApplicable`.
pub fn reconstruction(
    reference: &WorldClip,
    result: &WorldClip,
    rotations: Option<&Rotations>,
    height: f64,
    opts: &PhysicsOptions,
) -> Result<ReconstructionReport, MetricError> {
    check_clip(reference, 1, "reconstruction (reference)")?;
    check_clip(result, 1, "reconstruction (result)")?;
    if reference.joints != result.joints || reference.frames != result.frames {
        return Err(MetricError::Mismatch(format!(
            "reconstruction: the reference has {} joints x {} frames, the result {} joints x {} frames",
            reference.joints, reference.frames, result.joints, result.frames
        )));
    }
    if (reference.fps - result.fps).abs() > 1e-3 * reference.fps {
        return Err(MetricError::Mismatch(format!(
            "reconstruction: the reference runs at {} fps, the result at {} fps; resample one first",
            reference.fps, result.fps
        )));
    }
    if !height.is_finite() || height <= 0.0 {
        return Err(MetricError::NonFinite(format!("reconstruction: the height must be positive and finite, found {height}")));
    }
    let (frames, joints) = (reference.frames, reference.joints);
    let jr = match rotations {
        None => Maybe::NotApplicable("no rotations were given (positions only)".into()),
        Some(r) => {
            check_rotations(r, frames, joints)?;
            if r.counted.is_empty() {
                Maybe::NotApplicable("no joint has a meaningful rotation".into())
            } else {
                let mut sum = 0.0;
                for f in 0..frames {
                    for &j in &r.counted {
                        sum += angle_between(r.reference[f * joints + j], r.result[f * joints + j]);
                    }
                }
                Maybe::Value(sum / (frames * r.counted.len()) as f64)
            }
        }
    };
    // The root is the first joint without a parent (joint 0 in every BVH).
    let root = reference.parents.iter().position(Option::is_none).unwrap_or(0);
    let rt = (0..frames).map(|f| reference.at(f, root).distance(result.at(f, root))).sum::<f64>() / frames as f64;
    let (mut dist, mut squared) = (0.0, 0.0);
    for (a, b) in reference.positions.iter().zip(&result.positions) {
        let d = a.distance_squared(*b);
        squared += d;
        dist += d.sqrt();
    }
    let count = (frames * joints) as f64;
    let ours = physics::physics(result, opts)?;
    let theirs = physics::physics(reference, opts)?;
    Ok(ReconstructionReport {
        frames,
        joints,
        height,
        jr_joints: rotations.map_or(0, |r| r.counted.len()),
        jr,
        rt: Measure::of(rt, height),
        jp: Measure::of(dist / count, height),
        fs: ours.foot_skating,
        gp: ours.ground_penetration,
        reference_fs: theirs.foot_skating,
        reference_gp: theirs.ground_penetration,
        retargeting_error: 1000.0 * squared / count / (height * height),
        units: UNITS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::physics::tests::biped;
    use glam::DVec3;

    fn walk(frames: usize) -> WorldClip {
        biped(frames, 30.0, |f| DVec3::new(0.1 * f as f64, 0.0, 0.02 * (f as f64).sin()))
    }

    #[test]
    fn identical_motion_has_zero_errors() {
        let clip = walk(10);
        let q: Vec<DQuat> = (0..20).map(|i| DQuat::from_rotation_y(0.1 * i as f64)).collect();
        let rot = Rotations { reference: &q, result: &q, counted: vec![0, 1] };
        let r = reconstruction(&clip, &clip, Some(&rot), 1.7, &PhysicsOptions::default()).unwrap();
        assert_eq!(r.jr, Maybe::Value(0.0));
        assert_eq!((r.rt.value, r.jp.value, r.retargeting_error), (0.0, 0.0, 0.0));
        assert_eq!(r.fs, r.reference_fs);
    }

    #[test]
    fn shifted_scaled_and_rotated_by_hand() {
        // Result = reference moved by (0.3, 0.4, 0): every joint 0.5 off, squared 0.25.
        let a = walk(6);
        let mut b = a.clone();
        b.positions.iter_mut().for_each(|p| *p += DVec3::new(0.3, 0.4, 0.0));
        let r = reconstruction(&a, &b, None, 2.0, &PhysicsOptions::default()).unwrap();
        assert!((r.rt.value - 0.5).abs() < 1e-12 && (r.jp.value - 0.5).abs() < 1e-12);
        assert!((r.jp.normalised - 0.25).abs() < 1e-12);
        assert!((r.retargeting_error - 1000.0 * 0.25 / 4.0).abs() < 1e-9);
        assert!(matches!(r.jr, Maybe::NotApplicable(_)));
        // Rotations a quarter turn apart on every counted joint: JR = π/2 (and q vs -q is 0).
        let qa = vec![DQuat::IDENTITY; 12];
        let qb: Vec<DQuat> = (0..12).map(|i| if i % 2 == 0 { DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2) } else { -DQuat::IDENTITY }).collect();
        let rot = Rotations { reference: &qa, result: &qb, counted: vec![0, 1] };
        let r = reconstruction(&a, &a, Some(&rot), 1.0, &PhysicsOptions::default()).unwrap();
        assert!((r.jr.value().unwrap() - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    }

    #[test]
    fn mismatches_and_bad_input_are_errors() {
        let opts = PhysicsOptions::default();
        let e = reconstruction(&walk(6), &walk(7), None, 1.0, &opts).unwrap_err();
        assert!(matches!(&e, MetricError::Mismatch(m) if m.contains("6 frames") && m.contains("7 frames")), "{e}");
        assert!(matches!(reconstruction(&walk(6), &walk(6), None, 0.0, &opts), Err(MetricError::NonFinite(_))));
        assert!(matches!(reconstruction(&walk(0), &walk(0), None, 1.0, &opts), Err(MetricError::TooLittle(_))));
        let pose = reconstruction(&walk(1), &walk(1), None, 1.0, &opts).unwrap();
        assert!(pose.jp.value == 0.0 && matches!(pose.fs, Maybe::NotApplicable(_)));
        let mut nan = walk(6);
        nan.positions[0].x = f64::NAN;
        assert!(matches!(reconstruction(&walk(6), &nan, None, 1.0, &opts), Err(MetricError::NonFinite(_))));
        let short = vec![DQuat::IDENTITY; 3];
        let rot = Rotations { reference: &short, result: &short, counted: vec![0] };
        assert!(matches!(reconstruction(&walk(6), &walk(6), Some(&rot), 1.0, &opts), Err(MetricError::Mismatch(_))));
        let other_fps = WorldClip { fps: 60.0, ..walk(6) };
        assert!(matches!(reconstruction(&walk(6), &other_fps, None, 1.0, &opts), Err(MetricError::Mismatch(_))));
    }
}
