//! Edits of the root's travel: a clip played in place (the game-engine way, root motion taken
//! out), or moved along another clip's path.
//!
//! The travel is the root's ground position (x, z) and its heading (turn about y); its height
//! and everything below it are the pose and stay. The heading is measured on the root's local
//! axis that stays most horizontal (`genmm::heading`), so rigs facing +z, +x or lying along an
//! axis are all read the same way.

use super::{check, horizontal, turn, EditError};
use crate::genmm::heading::{heading_axis, yaw};
use crate::motion::Motion;
use crate::skeleton::Skeleton;

/// The root held over its first frame's ground position; its heading held at the first
/// frame's too, unless `keep_heading` (then the clip still turns, on the spot).
pub fn in_place(skeleton: &Skeleton, motion: &Motion, keep_heading: bool) -> Result<Motion, EditError> {
    check(skeleton, motion)?;
    let axis = heading_axis(std::slice::from_ref(motion));
    let j = motion.joints;
    let start = horizontal(motion.translations[0]);
    let start_yaw = yaw(motion.rotations[0], axis);
    let mut out = motion.clone();
    for f in 0..motion.frames {
        let t = &mut out.translations[f * j];
        *t = start + glam::DVec3::new(0.0, t.y, 0.0);
        if !keep_heading {
            let q = &mut out.rotations[f * j];
            *q = (turn(start_yaw - yaw(*q, axis)) * *q).normalize();
        }
    }
    Ok(out)
}

/// The root's travel replaced by `path`'s (another clip, any skeleton, sampled at this clip's
/// frame times): its ground position at every frame, and its change of heading since its first
/// frame added to this clip's first heading. The path must last as long as the clip.
pub fn follow_path(skeleton: &Skeleton, motion: &Motion, path: &Motion) -> Result<Motion, EditError> {
    check(skeleton, motion)?;
    if path.frames == 0 || path.joints == 0 || !(path.frame_time.is_finite() && path.frame_time > 0.0) {
        return Err(EditError::Range("the path has no frames".to_string()));
    }
    let (clip_length, path_length) = ((motion.frames - 1) as f64 * motion.frame_time, (path.frames - 1) as f64 * path.frame_time);
    if clip_length > path_length + 1e-9 * clip_length.max(1.0) {
        return Err(EditError::Range(format!("the path lasts {path_length:.4} s but the clip {clip_length:.4} s: give a path at least as long")));
    }
    let at: Vec<f64> = (0..motion.frames).map(|f| f as f64 * motion.frame_time / path.frame_time).collect();
    let root_only = Motion {
        frames: path.frames,
        joints: 1,
        frame_time: path.frame_time,
        rotations: (0..path.frames).map(|f| path.rotations[f * path.joints]).collect(),
        translations: (0..path.frames).map(|f| path.translations[f * path.joints]).collect(),
    };
    let sampled = root_only.interpolate(&at);
    let (axis, path_axis) = (heading_axis(std::slice::from_ref(motion)), heading_axis(std::slice::from_ref(&root_only)));
    let (clip_start, path_start) = (yaw(motion.rotations[0], axis), yaw(sampled.rotations[0], path_axis));
    let j = motion.joints;
    let mut out = motion.clone();
    for f in 0..motion.frames {
        let want = clip_start + yaw(sampled.rotations[f], path_axis) - path_start;
        let q = &mut out.rotations[f * j];
        *q = (turn(want - yaw(*q, axis)) * *q).normalize();
        let t = &mut out.translations[f * j];
        *t = horizontal(sampled.translations[f]) + glam::DVec3::new(0.0, t.y, 0.0);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::tests::creature;
    use super::*;

    #[test]
    fn in_place_keeps_the_root_over_its_start_and_the_pose() {
        let (s, m) = creature();
        let still = in_place(&s, &m, false).unwrap();
        let j = m.joints;
        let start = m.translations[0];
        for f in 0..m.frames {
            let t = still.translations[f * j];
            assert_eq!((t.x, t.y, t.z), (start.x, m.translations[f * j].y, start.z));
            assert_eq!(&still.rotations[f * j + 1..(f + 1) * j], &m.rotations[f * j + 1..(f + 1) * j]);
        }
        // Following its own path gives the clip back.
        let back = follow_path(&s, &still, &m).unwrap();
        for (a, b) in back.forward_kinematics(&s).positions.iter().zip(m.forward_kinematics(&s).positions) {
            assert!(a.distance(b) < 1e-9);
        }
        assert!(follow_path(&s, &m, &m.first_frames(3)).is_err());
    }
}
