//! Edits of time: a new frame rate, a cut, clips joined one after another, a clip made to loop.
//!
//! Joining is where clips go wrong: the second clip starts wherever it was recorded, facing
//! wherever it faced, and its first pose is not the first's last. So each next clip is turned
//! about the vertical and moved over the ground until its first frame stands where the previous
//! clip's last frame stands (the two are one instant: the first replaces the last), and the
//! pose difference at the seam is spread over a window on both sides. The spreading is done on
//! the pose without the root's heading and ground position (local rotations, the root's
//! rotation relative to its heading, translations but the root's horizontal ones), so a
//! turning or walking clip keeps its path. A loop is a clip joined onto itself.

use super::{check, horizontal, turn, EditError};
use crate::genmm::heading::{heading_axis, yaw};
use crate::motion::Motion;
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};
use std::str::FromStr;

/// A new frame rate: frames at the new frame times over the same duration (the last new frame
/// at or before the clip's end), rotations slerped and translations interpolated. Ratios that
/// are whole numbers either way (30 -> 60, 60 -> 30) sample the old frames exactly, so
/// 30 -> 60 -> 30 gives the original back bit for bit.
pub fn resample(motion: &Motion, fps: f64) -> Result<Motion, EditError> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(EditError::Invalid(format!("the frame rate must be positive, found {fps}")));
    }
    if motion.frames == 0 || !(motion.frame_time.is_finite() && motion.frame_time > 0.0) {
        return Err(EditError::Range("the clip has no frames or no frame time to resample".to_string()));
    }
    let step = whole_ratio((1.0 / fps) / motion.frame_time);
    let last = (motion.frames - 1) as f64;
    let count = (last / step + 1e-9).floor() as usize + 1;
    let at: Vec<f64> = (0..count).map(|k| k as f64 * step).collect();
    let mut out = motion.interpolate(&at);
    out.frame_time = 1.0 / fps;
    Ok(out)
}

/// `r`, or the whole number or whole fraction (1/n) it is within rounding of.
fn whole_ratio(r: f64) -> f64 {
    if (r - r.round()).abs() < 1e-9 * r.max(1.0) && r.round() >= 1.0 {
        r.round()
    } else if r < 1.0 && (1.0 / r - (1.0 / r).round()).abs() < 1e-9 / r {
        1.0 / (1.0 / r).round()
    } else {
        r
    }
}

/// A range `A:B` of frames or seconds, either end open (`:B`, `A:`); both ends are included,
/// as in Blender's frame range, so `0:N` and `N:M` share frame N and join back with `concat`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    pub start: Option<f64>,
    pub end: Option<f64>,
}

impl FromStr for Span {
    type Err = String;
    fn from_str(s: &str) -> Result<Span, String> {
        let (a, b) = s.split_once(':').ok_or_else(|| format!("expected A:B (either end may be left out), found '{s}'"))?;
        let end = |x: &str| -> Result<Option<f64>, String> {
            let x = x.trim();
            if x.is_empty() {
                return Ok(None);
            }
            match x.parse::<f64>() {
                Ok(v) if v.is_finite() && v >= 0.0 => Ok(Some(v)),
                _ => Err(format!("expected a non-negative number, found '{x}' in '{s}'")),
            }
        };
        Ok(Span { start: end(a)?, end: end(b)? })
    }
}

/// Frames `first..=last` of `span` in frames (`seconds` false) or seconds, checked against the
/// clip: an end past the last frame or a start after the end is an error, never a clamp.
pub fn span_frames(motion: &Motion, span: Span, seconds: bool) -> Result<(usize, usize), EditError> {
    let unit = if seconds { "s" } else { "" };
    let to_frame = |v: f64| if seconds { v / motion.frame_time } else { v };
    let last = motion.frames.saturating_sub(1);
    let first = span.start.map(to_frame).unwrap_or(0.0);
    let end = span.end.map(to_frame).unwrap_or(last as f64);
    let describe = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}{unit}"));
    let text = format!("{}:{}", describe(span.start), describe(span.end));
    let length =
        if seconds { format!("{:.4} s ({} frames)", last as f64 * motion.frame_time, motion.frames) } else { format!("{} frames (0:{last})", motion.frames) };
    if motion.frames == 0 {
        return Err(EditError::Range(format!("range {text}: the clip has no frames")));
    }
    // Seconds land on the nearest frame; frame numbers must be whole.
    let (first, end) = if seconds { (first.round(), end.round()) } else { (first, end) };
    if first.fract() != 0.0 || end.fract() != 0.0 {
        return Err(EditError::Range(format!("range {text}: frame numbers must be whole")));
    }
    if end > last as f64 {
        return Err(EditError::Range(format!("range {text} ends past the end: the clip has {length}")));
    }
    if first > end {
        return Err(EditError::Range(format!("range {text} is empty: it starts after it ends (the clip has {length})")));
    }
    Ok((first as usize, end as usize))
}

/// Frames `first..=last` (from `span_frames`).
pub fn trim(motion: &Motion, first: usize, last: usize) -> Result<Motion, EditError> {
    if first > last || last >= motion.frames {
        return Err(EditError::Range(format!("frames {first}:{last} are not within the clip's {} frames", motion.frames)));
    }
    Ok(motion.frame_range(first, last + 1))
}

/// The pose of a frame without the root's heading and ground position: what seams blend.
#[derive(Clone, Debug)]
struct LocalPose {
    /// Local rotations; the root's relative to its heading.
    rotations: Vec<DQuat>,
    /// Local translations; the root's horizontal part is zero.
    translations: Vec<DVec3>,
}

fn local_pose(m: &Motion, f: usize, axis: DVec3) -> LocalPose {
    let j = m.joints;
    let mut rotations = m.rotations[f * j..(f + 1) * j].to_vec();
    let mut translations = m.translations[f * j..(f + 1) * j].to_vec();
    rotations[0] = turn(-yaw(rotations[0], axis)) * rotations[0];
    translations[0] = DVec3::new(0.0, translations[0].y, 0.0);
    LocalPose { rotations, translations }
}

/// The pose halfway between two.
fn halfway(a: &LocalPose, b: &LocalPose) -> LocalPose {
    LocalPose {
        rotations: a.rotations.iter().zip(&b.rotations).map(|(x, y)| x.slerp(*y, 0.5).normalize()).collect(),
        translations: a.translations.iter().zip(&b.translations).map(|(x, y)| x.lerp(*y, 0.5)).collect(),
    }
}

/// Move frame `f` by `weight` of the difference `to - from` (both `LocalPose`s of one seam),
/// leaving the root's heading and ground position as they are.
fn shift_frame(m: &mut Motion, f: usize, from: &LocalPose, to: &LocalPose, weight: f64, axis: DVec3) {
    let j = m.joints;
    for k in 0..j {
        let delta = to.rotations[k] * from.rotations[k].inverse();
        let part = DQuat::IDENTITY.slerp(delta, weight).normalize();
        let q = &mut m.rotations[f * j + k];
        *q = if k == 0 {
            let heading = turn(yaw(*q, axis));
            (heading * part * heading.inverse() * *q).normalize()
        } else {
            (part * *q).normalize()
        };
        m.translations[f * j + k] += (to.translations[k] - from.translations[k]) * weight;
    }
}

/// Weight of the seam correction `k` frames away from the seam, over a window of `window`
/// frames: 1 at the seam, easing to 0 at the window's end.
fn seam_weight(k: usize, window: usize) -> f64 {
    if k >= window {
        0.0
    } else {
        0.5 * (1.0 + (std::f64::consts::PI * k as f64 / window as f64).cos())
    }
}

/// Blend a seam: frames `before` (the seam frame first, then back in time) take the
/// difference from `left` to the halfway pose, frames `after` (the seam frame first, then on)
/// from `right`; both sides meet at the halfway pose.
fn blend_seam(m: &mut Motion, before: &[usize], after: &[usize], left: &LocalPose, right: &LocalPose, axis: DVec3) {
    let mid = halfway(left, right);
    for (k, &f) in before.iter().enumerate() {
        shift_frame(m, f, left, &mid, seam_weight(k, before.len()), axis);
    }
    for (k, &f) in after.iter().enumerate() {
        shift_frame(m, f, right, &mid, seam_weight(k, after.len()), axis);
    }
}

/// `b` turned about the vertical and moved over the ground so that its first frame has the
/// heading and ground position of `a`'s last frame.
fn align(a: &Motion, b: &Motion, axis: DVec3) -> Motion {
    let (ja, jb) = (a.joints, b.joints);
    let end = (a.frames - 1) * ja;
    let angle = yaw(a.rotations[end], axis) - yaw(b.rotations[0], axis);
    let r = turn(angle);
    let (from, to) = (horizontal(b.translations[0]), horizontal(a.translations[end]));
    let mut out = b.clone();
    for f in 0..b.frames {
        out.rotations[f * jb] = (r * b.rotations[f * jb]).normalize();
        out.translations[f * jb] = r * (b.translations[f * jb] - from) + to;
    }
    out
}

/// Clips of one skeleton and frame rate, one after another: each next clip's first frame is
/// laid on the previous clip's last (turned and moved to its heading and ground position) and
/// replaces it, and `blend` frames on each side of every seam ease the pose across. A clip cut
/// at a frame into `0:N` and `N:` comes back exactly.
pub fn concat(skeleton: &Skeleton, clips: &[Motion], blend: usize) -> Result<Motion, EditError> {
    let first = clips.first().ok_or_else(|| EditError::Range("no clips to join".to_string()))?;
    for (i, c) in clips.iter().enumerate() {
        check(skeleton, c).map_err(|e| EditError::Mismatch(format!("clip {i}: {e}")))?;
        if (c.frame_time - first.frame_time).abs() > 1e-6 * first.frame_time {
            return Err(EditError::Mismatch(format!(
                "clip {i} runs at {:.3} fps but clip 0 at {:.3} fps: resample first",
                1.0 / c.frame_time,
                1.0 / first.frame_time
            )));
        }
    }
    let axis = heading_axis(clips);
    let mut out = first.clone();
    for next in &clips[1..] {
        let b = align(&out, next, axis);
        let seam = out.frames - 1;
        let left = local_pose(&out, seam, axis);
        let right = local_pose(&b, 0, axis);
        let j = out.joints;
        out.rotations.truncate(seam * j);
        out.translations.truncate(seam * j);
        out.rotations.extend_from_slice(&b.rotations);
        out.translations.extend_from_slice(&b.translations);
        out.frames = seam + b.frames;
        if blend > 0 {
            // The seam frame is now the next clip's first; the left side is corrected from
            // the previous clip's last pose, which the seam frame replaced.
            let before: Vec<usize> = (0..=blend.min(seam)).map(|k| seam - k).filter(|&f| f < seam).collect();
            let after: Vec<usize> = (seam..(seam + blend + 1).min(out.frames)).collect();
            let mid = halfway(&left, &right);
            let window = blend + 1;
            for (k, &f) in before.iter().enumerate() {
                shift_frame(&mut out, f, &left, &mid, seam_weight(k + 1, window), axis);
            }
            for (k, &f) in after.iter().enumerate() {
                shift_frame(&mut out, f, &right, &mid, seam_weight(k, window), axis);
            }
        }
    }
    Ok(out)
}

/// The clip made to loop: its end eased into its start over `blend` frames on each side, and
/// its last frame (now the same pose as the first, one cycle on) dropped, so that playing the
/// result over and over has no seam. The root's heading and ground position are left alone: a
/// walking loop walks on (concatenate it with itself to see).
pub fn make_loop(skeleton: &Skeleton, motion: &Motion, blend: usize) -> Result<Motion, EditError> {
    check(skeleton, motion)?;
    if motion.frames < 3 {
        return Err(EditError::Range(format!("a loop needs at least 3 frames, the clip has {}", motion.frames)));
    }
    let axis = heading_axis(std::slice::from_ref(motion));
    let n = motion.frames;
    let window = blend.clamp(1, (n - 1) / 2);
    let left = local_pose(motion, n - 1, axis);
    let right = local_pose(motion, 0, axis);
    let mut out = motion.clone();
    let before: Vec<usize> = (0..window).map(|k| n - 1 - k).collect();
    let after: Vec<usize> = (0..window).collect();
    blend_seam(&mut out, &before, &after, &left, &right, axis);
    Ok(out.frame_range(0, n - 1))
}

#[cfg(test)]
mod tests {
    use super::super::tests::creature;
    use super::*;

    fn max_difference(a: &Motion, b: &Motion, s: &Skeleton) -> f64 {
        let (pa, pb) = (a.forward_kinematics(s), b.forward_kinematics(s));
        pa.positions.iter().zip(&pb.positions).map(|(x, y)| x.distance(*y)).fold(0.0, f64::max)
    }

    #[test]
    fn resampling_there_and_back_is_exact_for_whole_ratios() {
        let (_, m) = creature();
        let up = resample(&m, 2.0 / m.frame_time).unwrap();
        assert_eq!(up.frames, 2 * m.frames - 1);
        let back = resample(&up, 1.0 / m.frame_time).unwrap();
        assert_eq!(back.rotations, m.rotations);
        assert_eq!(back.translations, m.translations);
        assert!(resample(&m, 0.0).is_err());
    }

    #[test]
    fn spans_are_inclusive_and_checked() {
        let (_, m) = creature();
        let n = m.frames;
        assert_eq!(span_frames(&m, "2:5".parse().unwrap(), false), Ok((2, 5)));
        assert_eq!(span_frames(&m, ":".parse().unwrap(), false), Ok((0, n - 1)));
        assert!(span_frames(&m, format!("0:{n}").parse().unwrap(), false).unwrap_err().to_string().contains("past the end"));
        assert!(span_frames(&m, "5:2".parse().unwrap(), false).is_err());
        assert!("5".parse::<Span>().is_err() && "a:3".parse::<Span>().is_err() && "-1:3".parse::<Span>().is_err());
        let secs = span_frames(&m, "0:0.5".parse().unwrap(), true).unwrap();
        assert_eq!(secs, (0, (0.5 / m.frame_time).round() as usize));
    }

    #[test]
    fn a_clip_cut_in_two_joins_back_exactly() {
        let (s, m) = creature();
        let cut = m.frames / 2;
        let a = trim(&m, 0, cut).unwrap();
        let b = trim(&m, cut, m.frames - 1).unwrap();
        for blend in [0, 5] {
            let joined = concat(&s, &[a.clone(), b.clone()], blend).unwrap();
            assert_eq!(joined.frames, m.frames);
            assert!(max_difference(&joined, &m, &s) < 1e-9, "blend {blend}");
        }
    }

    #[test]
    fn joined_clips_continue_where_the_previous_ends() {
        let (s, m) = creature();
        let joined = concat(&s, &[m.clone(), m.clone()], 4).unwrap();
        assert_eq!(joined.frames, 2 * m.frames - 1);
        let seam = m.frames - 1;
        let root = |f: usize| joined.translations[f * joined.joints];
        let step = (root(seam + 1) - root(seam)).length();
        let typical = (root(2) - root(1)).length();
        assert!(step < 3.0 * typical + 1e-9, "seam step {step} vs {typical}");
    }

    #[test]
    fn a_loop_drops_its_last_frame_and_needs_frames() {
        let (s, m) = creature();
        let l = make_loop(&s, &m, 6).unwrap();
        assert_eq!(l.frames, m.frames - 1);
        assert!(make_loop(&s, &m.first_frames(2), 1).is_err());
    }
}
