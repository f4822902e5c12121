//! Foot locking: feet that should stand still while on the ground are pinned there.
//!
//! Retargeted and generated clips slide their feet (HumanIK calls the fix foot stabilisation).
//! Contacts are found by the very rule `mo-metrics physics` scores with
//! (`metrics::physics::contacts`: near the ground and slow), so what is locked is what the
//! metric calls a contact. During each contact the foot is held at its mean position over the
//! contact. Between two contacts the foot follows its own path plus an offset that eases from
//! the first pin's to the second's over the whole time between them, so the catch-up happens
//! mostly in the air (sliding it into a few frames near the ground would be skating again);
//! before the first contact and after the last, the offset eases in and out over `blend`
//! frames. The foot's parent and grandparent (knee and hip, whatever the
//! creature calls them) are turned by two-bone IK (`motion::ik`), bending in the plane they
//! already bend in; the foot keeps its world rotation. Nothing above the hip moves.

use super::{check, EditError};
use crate::metrics::physics::{self, PhysicsOptions};
use crate::metrics::WorldClip;
use crate::motion::contact::{self, Contact};
use crate::motion::{ik, Motion};
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};

/// What was locked and what it changed.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FootLockReport {
    /// Feet locked, by name, with their contact count and contact frames.
    pub feet: Vec<LockedFoot>,
    /// Feet of `roles::feet` that head their chain but have no hip and knee to turn (the
    /// foot hangs from the root or its parent), by name.
    pub skipped: Vec<String>,
    /// `mo-metrics physics` foot skating (skeleton sizes per second) before and after; `None`
    /// when the metric does not apply.
    pub skating_before: Option<f64>,
    pub skating_after: Option<f64>,
    /// Largest distance any joint of a locked leg moved, in skeleton sizes.
    pub legs_moved: f64,
    /// Largest distance any other joint moved, in skeleton sizes (0: nothing else moves).
    pub rest_moved: f64,
}

impl FootLockReport {
    /// The report for people, one line each: the skating and how far things moved, then
    /// each locked foot, then the feet not locked.
    pub fn lines(&self) -> Vec<String> {
        let show = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.4}"));
        let mut out = vec![format!(
            "skating {} -> {} sizes/s; legs moved at most {:.4} sizes, the rest {:.4}",
            show(self.skating_before),
            show(self.skating_after),
            self.legs_moved,
            self.rest_moved
        )];
        out.extend(self.feet.iter().map(|f| format!("{}: {} contacts, {} frames", f.name, f.contacts, f.contact_frames)));
        if !self.skipped.is_empty() {
            out.push(format!("not locked (no hip and knee above them): {}", self.skipped.join(", ")));
        }
        out
    }
}

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LockedFoot {
    pub name: String,
    pub contacts: usize,
    pub contact_frames: usize,
}

/// One leg: the foot, its parent and its grandparent.
struct Leg {
    foot: usize,
    knee: usize,
    hip: usize,
    /// Per frame, where the foot should be (`None`: where it is).
    targets: Vec<Option<DVec3>>,
}

/// Lock the feet of `motion` (contacts by `options`, `blend` frames of easing on each side).
pub fn foot_lock(skeleton: &Skeleton, motion: &Motion, options: &PhysicsOptions, blend: usize) -> Result<(Motion, FootLockReport), EditError> {
    check(skeleton, motion)?;
    if motion.frames < 2 {
        return Err(EditError::Range("foot contacts need at least 2 frames (a speed), the clip has 1".to_string()));
    }
    let clip = WorldClip::from_motion(skeleton, motion);
    if clip.feet.is_empty() {
        return Err(EditError::Skeleton(
            "the skeleton has no feet (no joint is named like a foot or toe, nor lies on the ground in the rest pose)".to_string(),
        ));
    }
    let before = physics::physics(&clip, options).map_err(|e| EditError::Invalid(e.to_string()))?;
    let rows = physics::contacts(&clip, options);
    let is_foot = |j: usize| clip.feet.contains(&j);
    let mut legs: Vec<Leg> = Vec::new();
    let mut skipped = Vec::new();
    let mut used = vec![false; skeleton.len()];
    for (row, &foot) in rows.iter().zip(&clip.feet) {
        if skeleton.joints[foot].parent.is_some_and(is_foot) {
            continue; // a toe under a foot: it follows the foot.
        }
        let knee = skeleton.joints[foot].parent.filter(|&k| k != 0);
        let hip = knee.and_then(|k| skeleton.joints[k].parent).filter(|&h| h != 0);
        match (knee, hip) {
            (Some(knee), Some(hip)) if !used[knee] && !used[hip] && !used[foot] => {
                used[knee] = true;
                used[hip] = true;
                used[foot] = true;
                let track: Vec<DVec3> = (0..motion.frames).map(|f| clip.at(f, foot)).collect();
                legs.push(Leg { foot, knee, hip, targets: targets(row, &track, blend) });
            }
            _ => skipped.push(skeleton.joints[foot].name.clone()),
        }
    }

    let world = motion.forward_kinematics(skeleton);
    let mut out = motion.clone();
    let n = motion.joints;
    for leg in &legs {
        for f in 0..motion.frames {
            let Some(target) = leg.targets[f] else { continue };
            let at = |j: usize| world.positions[f * n + j];
            let rot = |j: usize| world.rotations[f * n + j];
            let (h, k, foot) = (at(leg.hip), at(leg.knee), at(leg.foot));
            let (l1, l2) = ((k - h).length(), (foot - k).length());
            if l1 < 1e-9 || l2 < 1e-9 {
                continue;
            }
            let axis = foot - h;
            let pole = (k - h) - axis * ((k - h).dot(axis) / axis.length_squared().max(1e-300));
            let knee = ik::two_bone_knee(h, target, l1, l2, pole);
            let turn_hip = arc(k - h, knee - h);
            let foot_now = h + turn_hip * (foot - h);
            let turn_knee = arc(foot_now - knee, target - knee);
            let hip_world = (turn_hip * rot(leg.hip)).normalize();
            let knee_world = (turn_knee * turn_hip * rot(leg.knee)).normalize();
            let above = skeleton.joints[leg.hip].parent.map_or(DQuat::IDENTITY, rot);
            out.rotations[f * n + leg.hip] = (above.inverse() * hip_world).normalize();
            out.rotations[f * n + leg.knee] = (hip_world.inverse() * knee_world).normalize();
            out.rotations[f * n + leg.foot] = (knee_world.inverse() * rot(leg.foot)).normalize();
        }
    }

    let after_clip = WorldClip::from_motion(skeleton, &out);
    let after = physics::physics(&after_clip, options).map_err(|e| EditError::Invalid(e.to_string()))?;
    let mut in_leg = vec![false; skeleton.len()];
    for leg in &legs {
        in_leg[leg.hip] = true;
    }
    for j in 0..skeleton.len() {
        if let Some(p) = skeleton.joints[j].parent {
            in_leg[j] |= in_leg[p];
        }
    }
    let (mut legs_moved, mut rest_moved) = (0.0f64, 0.0f64);
    for (i, (a, b)) in clip.positions.iter().zip(&after_clip.positions).enumerate() {
        let d = a.distance(*b) / clip.scale;
        if in_leg[i % n] {
            legs_moved = legs_moved.max(d);
        } else {
            rest_moved = rest_moved.max(d);
        }
    }
    let feet = legs
        .iter()
        .map(|leg| {
            let row = &rows[clip.feet.iter().position(|&x| x == leg.foot).unwrap_or(0)];
            let contacts = (0..row.len()).filter(|&f| row[f] && (f == 0 || !row[f - 1])).count();
            LockedFoot { name: skeleton.joints[leg.foot].name.clone(), contacts, contact_frames: row.iter().filter(|&&c| c).count() }
        })
        .collect();
    let skating = |r: &physics::PhysicsReport| r.foot_skating.value().map(|m| m.normalised);
    Ok((out, FootLockReport { feet, skipped, skating_before: skating(&before), skating_after: skating(&after), legs_moved, rest_moved }))
}

/// The rotation turning direction `from` onto `to` by the shortest arc (identity for a zero
/// vector).
fn arc(from: DVec3, to: DVec3) -> DQuat {
    match (from.try_normalize(), to.try_normalize()) {
        (Some(a), Some(b)) => DQuat::from_rotation_arc(a, b),
        _ => DQuat::IDENTITY,
    }
}

/// Per frame, where the foot should be: each contact (a run of `true` in `row`) holds the
/// foot at its mean position over the contact; between contacts the foot's own path is
/// shifted by an offset easing from one contact's to the next's; `blend` frames before the
/// first and after the last contact ease the offset from and to nothing.
fn targets(row: &[bool], track: &[DVec3], blend: usize) -> Vec<Option<DVec3>> {
    let n = row.len().min(track.len());
    let contacts = contact::contacts(n, |t| row[t], |t| track[t]);
    let mut out = vec![None; n];
    let ease = |t: f64| 0.5 - 0.5 * (std::f64::consts::PI * t.clamp(0.0, 1.0)).cos();
    for (i, &Contact { first: start, last: end, pin }) in contacts.iter().enumerate() {
        for slot in out.iter_mut().take(end + 1).skip(start) {
            *slot = Some(pin);
        }
        let offset_out = pin - track[end];
        match contacts.get(i + 1) {
            Some(&Contact { first: next, pin: next_pin, .. }) => {
                let offset_in = next_pin - track[next];
                for g in end + 1..next {
                    let t = (g - end) as f64 / (next - end) as f64;
                    out[g] = Some(track[g] + offset_out.lerp(offset_in, ease(t)));
                }
            }
            None => {
                for g in end + 1..(end + 1 + blend).min(n) {
                    out[g] = Some(track[g] + offset_out * (1.0 - ease((g - end) as f64 / (blend + 1) as f64)));
                }
            }
        }
        if i == 0 {
            let offset_in = pin - track[start];
            for g in start.saturating_sub(blend)..start {
                out[g] = Some(track[g] + offset_in * (1.0 - ease((start - g) as f64 / (blend + 1) as f64)));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feet_hold_in_contacts_and_catch_up_between_them() {
        let track: Vec<DVec3> = (0..12).map(|f| DVec3::new(f as f64, 0.0, 0.0)).collect();
        let row = [false, false, true, true, true, false, false, false, true, true, false, false];
        let p = targets(&row, &track, 1);
        // Held at the mean of each contact.
        assert_eq!(p[2..5], [Some(DVec3::new(3.0, 0.0, 0.0)); 3]);
        assert_eq!(p[8..10], [Some(DVec3::new(8.5, 0.0, 0.0)); 2]);
        // One frame of easing before the first and after the last contact, nothing beyond.
        assert!((p[1].unwrap().x - 1.5).abs() < 1e-12 && (p[10].unwrap().x - 9.75).abs() < 1e-12, "{p:?}");
        assert_eq!((p[0], p[11]), (None, None));
        // Between contacts the offset eases from -1 (after the first) to +0.5 (before the second).
        let gap: Vec<f64> = (4..=8).map(|f| p[f].unwrap().x - track[f].x).collect();
        assert!(gap.windows(2).all(|w| w[1] >= w[0]), "{gap:?}");
    }

    #[test]
    fn a_sliding_creature_slides_less_and_nothing_else_moves() {
        // The synthetic quadruped, its feet dragged along: skating goes up, locking brings it down.
        let (s, mut m) = super::super::tests::creature();
        for f in 0..m.frames {
            m.translations[f * m.joints].x += 0.02 * s.rest_extent() * (f as f64 * 0.7).sin();
        }
        let (locked, report) = foot_lock(&s, &m, &PhysicsOptions::default(), 3).unwrap();
        assert_eq!(locked.frames, m.frames);
        assert!(!report.feet.is_empty(), "{report:?}");
        let (a, b) = (report.skating_before.unwrap(), report.skating_after.unwrap());
        assert!(b < a, "skating {a} -> {b}");
        assert_eq!(report.rest_moved, 0.0);
    }
}
