//! Orthographic cameras fitted to a whole track, so any creature fills its frame.
//!
//! A camera maps world points to pixels: `x = cx + scale * (p . right - shift[frame])`,
//! `y = cy - scale * (p . up - lift[frame])` (y up on screen). The scale is one number for the whole track,
//! taken from its extent over all frames and all points (end sites included), so a 20 cm mouse
//! and a 2 m human both fill the picture and size changes within a track stay visible.
//!
//! The ground is the lowest height any point reaches in the track, except that when that
//! lowest point stays just above 0 (by at most 10% of the track's height: foot joints sit a
//! little above the floor they stand on) the ground is 0, the floor the data was made on.
//! Level views (auto, side, front, an angle without pitch) see the ground as a line and stand
//! it on the bottom margin. The top view and pitched angles draw no ground line (a plane seen
//! at a slant is not a line), and there `Follow` re-centres vertically too, since travel in
//! depth moves the body up and down the screen.

use super::{RenderError, Track, View};
use glam::Vec3;

/// How the camera follows the motion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Framing {
    /// Each frame is re-centred horizontally on the body (its root), with one scale for the
    /// whole track: good for looking at the pose of a walk or run.
    #[default]
    Follow,
    /// One camera over all frames: shows the travel.
    Fixed,
}

/// Reject view angles that are not numbers.
pub fn check_view(view: View) -> Result<(), RenderError> {
    if let View::Angle { yaw, pitch } = view {
        if !yaw.is_finite() || !pitch.is_finite() {
            return Err(RenderError::Invalid(format!("view angle yaw {yaw}, pitch {pitch}: angles must be finite numbers of degrees")));
        }
    }
    Ok(())
}

/// A fitted orthographic camera for one track.
#[derive(Clone, Debug)]
pub struct Camera {
    /// World direction drawn to the right of the screen.
    pub right: Vec3,
    /// World direction drawn up the screen.
    pub up: Vec3,
    /// Pixels per world unit.
    pub scale: f32,
    cx: f32,
    cy: f32,
    /// Per-frame horizontal re-centring (`Follow`); empty for `Fixed`.
    shift: Vec<f32>,
    /// Per-frame vertical re-centring (`Follow` in views that are not level); else empty.
    lift: Vec<f32>,
    /// World ground height; `None` in views that are not level.
    ground: Option<f32>,
}

fn root_index(track: &Track) -> usize {
    track.parents.iter().position(Option::is_none).unwrap_or(0)
}

/// Principal axis (unit, xz) and its variance of a set of horizontal vectors given as sums.
fn principal(sxx: f64, sxz: f64, szz: f64) -> ((f32, f32), f64) {
    let angle = 0.5 * (2.0 * sxz).atan2(sxx - szz);
    let (s, c) = angle.sin_cos();
    let var = c * c * sxx + 2.0 * s * c * sxz + s * s * szz;
    ((c as f32, s as f32), var)
}

/// The horizontal direction drawn to the right in the `Auto` view.
///
/// A track that travels (the root's horizontal path is long compared with the body) is seen
/// from the side of its principal direction of travel, oriented so it goes left to right.
/// Motion in place is seen from the side of the body: with two feet the line between them runs
/// across the body, so we look along it; otherwise (four legs, many legs, none) the body's
/// longest horizontal axis runs head to tail and is drawn left-right, oriented towards +z
/// (AnyTop's canonical facing) so the unknown facing at least has a fixed convention.
pub fn auto_direction(track: &Track) -> Vec3 {
    let n = track.points();
    let root = root_index(track);
    let frames = track.frames.max(1);
    let rootp = |f: usize| track.positions.get(f * n + root).copied().unwrap_or(Vec3::ZERO);
    // Root path spread.
    let (mut mx, mut mz) = (0.0f64, 0.0f64);
    for f in 0..track.frames {
        let p = rootp(f);
        mx += p.x as f64;
        mz += p.z as f64;
    }
    mx /= frames as f64;
    mz /= frames as f64;
    let (mut sxx, mut sxz, mut szz) = (0.0f64, 0.0f64, 0.0f64);
    for f in 0..track.frames {
        let p = rootp(f);
        let (x, z) = (p.x as f64 - mx, p.z as f64 - mz);
        sxx += x * x;
        sxz += x * z;
        szz += z * z;
    }
    let (axis, _) = principal(sxx, sxz, szz);
    let travel_along = |f: usize| rootp(f).x * axis.0 + rootp(f).z * axis.1;
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for f in 0..track.frames {
        let t = travel_along(f);
        lo = lo.min(t);
        hi = hi.max(t);
    }
    // Body size: the largest side of a frame's bounding box, over a few frames.
    let mut body = 0.0f32;
    for f in [0, track.frames / 2, track.frames.saturating_sub(1)] {
        if f < track.frames {
            let pts = track.frame(f);
            let (mut a, mut b) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for p in pts {
                a = a.min(*p);
                b = b.max(*p);
            }
            body = body.max((b - a).max_element());
        }
    }
    if track.frames >= 2 && hi - lo > 0.5 * body && hi - lo > 0.0 {
        let net = travel_along(track.frames - 1) - travel_along(0);
        let sign = if net < 0.0 { -1.0 } else { 1.0 };
        return Vec3::new(axis.0 * sign, 0.0, axis.1 * sign);
    }
    // In place.
    let (mut sxx, mut sxz, mut szz) = (0.0f64, 0.0f64, 0.0f64);
    let step = (track.frames / 64).max(1);
    let across = track.feet.len() == 2;
    for f in (0..track.frames).step_by(step) {
        let pts = track.frame(f);
        let mut add = |v: Vec3| {
            let (x, z) = (v.x as f64, v.z as f64);
            sxx += x * x;
            sxz += x * z;
            szz += z * z;
        };
        if across {
            let (a, b) = (track.feet[0], track.feet[1]);
            if a < n && b < n {
                add(pts[b] - pts[a]);
            }
        } else {
            let c = pts[root.min(n - 1)];
            for p in pts {
                add(*p - c);
            }
        }
    }
    let ((ax, az), var) = principal(sxx, sxz, szz);
    if var.is_nan() || var <= 0.0 {
        return Vec3::Z;
    }
    let (mut dx, mut dz) = if across { (-az, ax) } else { (ax, az) };
    if dz < -1e-6 || (dz.abs() <= 1e-6 && dx < 0.0) {
        dx = -dx;
        dz = -dz;
    }
    Vec3::new(dx, 0.0, dz).normalize_or(Vec3::Z)
}

/// Screen axes (right, up) in world space for `view`.
pub fn view_axes(track: &Track, view: View) -> (Vec3, Vec3) {
    match view {
        View::Auto => (auto_direction(track), Vec3::Y),
        View::Side => (Vec3::Z, Vec3::Y),
        View::Front => (Vec3::X, Vec3::Y),
        View::Top => (Vec3::X, Vec3::NEG_Z),
        View::Angle { yaw, pitch } => {
            let (yaw, pitch) = (yaw.to_radians(), pitch.to_radians());
            let (sy, cy) = if yaw.is_finite() { yaw.sin_cos() } else { (0.0, 1.0) };
            let (sp, cp) = if pitch.is_finite() { pitch.sin_cos() } else { (0.0, 1.0) };
            // Yaw 0 looks along +x (the side view); positive pitch tilts the gaze down.
            let forward = Vec3::new(cp * cy, -sp, -cp * sy);
            let right = Vec3::new(sy, 0.0, cy);
            (right, right.cross(forward).normalize_or(Vec3::Y))
        }
    }
}

/// The ground height of a track (see the module documentation).
pub fn ground_height(track: &Track) -> f32 {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for p in &track.positions {
        lo = lo.min(p.y);
        hi = hi.max(p.y);
    }
    if !lo.is_finite() {
        return 0.0;
    }
    if lo > 0.0 && lo <= 0.1 * (hi - lo) {
        0.0
    } else {
        lo
    }
}

impl Camera {
    /// Fit a camera to all frames of `track` for a `width` x `height` picture, keeping `margin`
    /// pixels free on every side. Positions must be finite (see [`super::check`]).
    pub fn fit(track: &Track, view: View, framing: Framing, width: u32, height: u32, margin: u32) -> Camera {
        let (right, up) = view_axes(track, view);
        let n = track.points().max(1);
        let root = root_index(track);
        let level = (up - Vec3::Y).length() < 1e-4;
        let ground = level.then(|| ground_height(track));
        let follow = framing == Framing::Follow;
        let per_frame = |axis: Vec3| -> Vec<f32> { (0..track.frames).map(|f| track.positions.get(f * n + root).map_or(0.0, |p| p.dot(axis))).collect() };
        let shift = if follow { per_frame(right) } else { Vec::new() };
        let lift = if follow && !level { per_frame(up) } else { Vec::new() };
        let (mut xlo, mut xhi, mut ylo, mut yhi) = (f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY);
        for (i, p) in track.positions.iter().enumerate() {
            let x = p.dot(right) - shift.get(i / n).copied().unwrap_or(0.0);
            let y = p.dot(up) - lift.get(i / n).copied().unwrap_or(0.0);
            xlo = xlo.min(x);
            xhi = xhi.max(x);
            ylo = ylo.min(y);
            yhi = yhi.max(y);
        }
        // The ground must be visible too.
        if let Some(g) = ground {
            ylo = ylo.min(g);
            yhi = yhi.max(g);
        }
        if !(xlo <= xhi && ylo <= yhi) {
            (xlo, xhi, ylo, yhi) = (-1.0, 1.0, -1.0, 1.0);
        }
        let avail_w = (width as f32 - 2.0 * margin as f32).max(1.0);
        let avail_h = (height as f32 - 2.0 * margin as f32).max(1.0);
        // A single point (or a flat line) has no extent: give it one so the scale stays finite.
        let floor = 1e-6 * xhi.abs().max(xlo.abs()).max(yhi.abs()).max(ylo.abs()).max(1e-3);
        let (span_x, span_y) = ((xhi - xlo).max(floor), (yhi - ylo).max(floor));
        let scale = (avail_w / span_x).min(avail_h / span_y);
        let scale = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
        let cx = margin as f32 + avail_w * 0.5 - scale * (xlo + xhi) * 0.5;
        // Side-like views stand on the bottom margin; the top view is centred.
        let cy = if ground.is_some() { height as f32 - margin as f32 + scale * ylo } else { margin as f32 + avail_h * 0.5 + scale * (ylo + yhi) * 0.5 };
        Camera { right, up, scale, cx, cy, shift, lift, ground }
    }

    /// Pixel coordinates of world point `p` in frame `frame`.
    #[inline]
    pub fn project(&self, frame: usize, p: Vec3) -> (f32, f32) {
        let s = self.shift.get(frame).copied().unwrap_or(0.0);
        let l = self.lift.get(frame).copied().unwrap_or(0.0);
        (self.cx + self.scale * (p.dot(self.right) - s), self.cy - self.scale * (p.dot(self.up) - l))
    }

    /// Screen y of the ground line in `frame` (`root` is the root's position then; level
    /// views give the same line in every frame), or `None` in views that are not level.
    pub fn ground_line(&self, frame: usize, root: Vec3) -> Option<f32> {
        self.ground.map(|g| self.project(frame, Vec3::new(root.x, g, root.z)).1)
    }

    /// World ground height used by this camera (`None` in views that are not level).
    pub fn ground(&self) -> Option<f32> {
        self.ground
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stick creature of `size` walking `travel` along `dir` over 20 frames.
    fn walker(size: f32, dir: Vec3, travel: f32) -> Track {
        let rest = [Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.1, 0.0, 0.0), Vec3::new(-0.1, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.3)];
        let frames = 20;
        let mut positions = Vec::new();
        for f in 0..frames {
            let offset = dir * travel * f as f32 / (frames - 1) as f32;
            positions.extend(rest.iter().map(|p| *p * size + offset));
        }
        Track {
            title: "w".into(),
            names: (0..5).map(|i| format!("j{i}")).collect(),
            parents: vec![None, Some(0), Some(0), Some(0), Some(1)],
            end_site: vec![false, false, false, false, true],
            feet: vec![2, 3],
            fps: 30.0,
            frames,
            positions,
            point_labels: None,
            frame_labels: None,
        }
    }

    fn all_inside(t: &Track, cam: &Camera, w: u32, h: u32, margin: u32) {
        for f in 0..t.frames {
            for p in t.frame(f) {
                let (x, y) = cam.project(f, *p);
                let m = margin as f32 - 0.01;
                assert!(x >= m && x <= w as f32 - m && y >= m && y <= h as f32 - m, "frame {f}: {p} -> ({x}, {y})");
            }
        }
    }

    #[test]
    fn tiny_and_huge_creatures_fill_the_frame_and_stay_inside() {
        for size in [0.2f32, 2.0, 180.0] {
            for framing in [Framing::Follow, Framing::Fixed] {
                let t = walker(size, Vec3::X, 3.0 * size);
                let cam = Camera::fit(&t, View::Auto, framing, 200, 150, 10);
                all_inside(&t, &cam, 200, 150, 10);
                // The body is 1 unit tall (times size) and must use a good part of the height.
                let (_, y0) = cam.project(0, Vec3::ZERO);
                let (_, y1) = cam.project(0, Vec3::Y * size);
                assert!((y0 - y1) > 40.0, "size {size} {framing:?}: only {} px tall", y0 - y1);
                // Ground at the bottom margin.
                let g = cam.ground_line(0, t.frame(0)[0]).unwrap();
                assert!((g - 140.0).abs() < 0.5, "ground at {g}");
            }
        }
    }

    #[test]
    fn auto_view_walks_left_to_right_whatever_the_direction() {
        for dir in [Vec3::X, Vec3::NEG_X, Vec3::Z, Vec3::new(-0.6, 0.0, 0.8)] {
            let t = walker(1.0, dir, 4.0);
            let cam = Camera::fit(&t, View::Auto, Framing::Fixed, 300, 100, 5);
            let (x0, _) = cam.project(0, t.frame(0)[0]);
            let (x1, _) = cam.project(19, t.frame(19)[0]);
            assert!(x1 > x0 + 100.0, "{dir}: {x0} -> {x1}");
        }
        // In place with two feet side by side along x: we look along x, so right is +-z.
        let t = walker(1.0, Vec3::X, 0.0);
        let d = auto_direction(&t);
        assert!(d.z.abs() > 0.99, "{d}");
    }

    #[test]
    fn named_views_follow_the_documented_axes() {
        let t = walker(1.0, Vec3::X, 0.0);
        assert_eq!(view_axes(&t, View::Side), (Vec3::Z, Vec3::Y));
        let (r, u) = view_axes(&t, View::Angle { yaw: 0.0, pitch: 0.0 });
        assert!((r - Vec3::Z).length() < 1e-6 && (u - Vec3::Y).length() < 1e-6);
        let (r, u) = view_axes(&t, View::Angle { yaw: 90.0, pitch: 30.0 });
        assert!((r - Vec3::X).length() < 1e-5 && u.y > 0.8 && u.z < 0.0, "{r} {u}");
        assert!(check_view(View::Angle { yaw: f32::NAN, pitch: 0.0 }).is_err());
        // Top view: no ground, centred; Follow re-centres on the root in both directions.
        let cam = Camera::fit(&t, View::Top, Framing::Fixed, 100, 100, 5);
        assert!(cam.ground().is_none());
        all_inside(&t, &cam, 100, 100, 5);
        let walk = walker(1.0, Vec3::Z, 10.0);
        let cam = Camera::fit(&walk, View::Top, Framing::Follow, 100, 100, 5);
        all_inside(&walk, &cam, 100, 100, 5);
        let (a, b) = (cam.project(0, walk.frame(0)[0]), cam.project(19, walk.frame(19)[0]));
        assert!((a.0 - b.0).abs() < 1e-3 && (a.1 - b.1).abs() < 1e-3, "{a:?} {b:?}");
        assert!(Camera::fit(&walk, View::Angle { yaw: 0.0, pitch: 30.0 }, Framing::Follow, 100, 100, 5).ground().is_none());
        assert!(Camera::fit(&walk, View::Angle { yaw: 40.0, pitch: 0.0 }, Framing::Follow, 100, 100, 5).ground().is_some());
    }

    #[test]
    fn follow_keeps_the_body_in_place_fixed_shows_travel() {
        let t = walker(1.0, Vec3::Z, 10.0);
        let follow = Camera::fit(&t, View::Side, Framing::Follow, 200, 200, 10);
        let fixed = Camera::fit(&t, View::Side, Framing::Fixed, 200, 200, 10);
        let root = |cam: &Camera, f: usize| cam.project(f, t.frame(f)[0]).0;
        assert!((root(&follow, 0) - root(&follow, 19)).abs() < 1e-3);
        assert!(root(&fixed, 19) - root(&fixed, 0) > 150.0);
        // One scale for the whole track in both.
        assert!(follow.scale > fixed.scale);
    }

    #[test]
    fn a_single_point_gets_a_finite_camera() {
        let mut t = walker(1.0, Vec3::X, 0.0);
        t.positions.iter_mut().for_each(|p| *p = Vec3::new(1.0, 2.0, 3.0));
        let cam = Camera::fit(&t, View::Auto, Framing::Fixed, 50, 50, 5);
        let (x, y) = cam.project(0, t.positions[0]);
        assert!(x.is_finite() && y.is_finite() && cam.scale.is_finite());
    }
}
