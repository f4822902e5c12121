//! Physical plausibility of one motion, without ground truth: foot skating, ground
//! penetration, floating and jitter, plus the foot contacts the transfer metrics compare.
//! Definitions, units and deviations: `docs/metrics.md`.
//!
//! Every threshold is a fraction of the skeleton's size (`WorldClip::scale`), so a mouse and a
//! dinosaur are judged alike; every distance is reported in clip units and divided by the
//! scale (`Measure::normalised`).

use super::{MetricError, WorldClip};
use glam::DVec3;
use serde::ser::SerializeMap;

/// Where the ground plane (y = height) is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Ground {
    /// y = 0, the BVH convention.
    Zero,
    /// y = this height, in clip units.
    Height(f64),
    /// From the motion: the 10th percentile over frames of the lowest foot (or, without feet,
    /// the lowest joint). Robust to a few glitch frames, and still on the ground for a clip
    /// that is airborne most of the time.
    Estimate,
}

impl std::str::FromStr for Ground {
    type Err = String;

    /// `zero`, `estimate` or a finite height (the tools' `--ground`).
    fn from_str(s: &str) -> Result<Ground, String> {
        match s {
            "zero" => Ok(Ground::Zero),
            "estimate" => Ok(Ground::Estimate),
            h => match h.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Ground::Height(v)),
                _ => Err(format!("expected zero, estimate or a height, found '{s}'")),
            },
        }
    }
}

/// Thresholds of contact, as fractions of `WorldClip::scale`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PhysicsOptions {
    /// A foot joint this close to the ground (fraction of the scale) is on it.
    pub contact_height: f64,
    /// ... and moving slower than this (fraction of the scale per second) is in contact.
    pub contact_speed: f64,
    pub ground: Ground,
}

impl PhysicsOptions {
    /// Options with both thresholds checked positive (named as the tools' flags name them).
    pub fn new(ground: Ground, contact_height: f64, contact_speed: f64) -> Result<PhysicsOptions, MetricError> {
        if !(contact_height.is_finite() && contact_height > 0.0) || !(contact_speed.is_finite() && contact_speed > 0.0) {
            return Err(MetricError::BadOption("--contact-height and --contact-speed must be positive numbers".to_string()));
        }
        Ok(PhysicsOptions { contact_height, contact_speed, ground })
    }
}

impl Default for PhysicsOptions {
    /// 5% of the size in height and 50% of the size per second: for a 1.7 m human, 8.5 cm and
    /// 0.85 m/s, the usual contact labels of HumanML3D-style pipelines (a few cm, under 1 m/s).
    fn default() -> Self {
        PhysicsOptions { contact_height: 0.05, contact_speed: 0.5, ground: Ground::Zero }
    }
}

/// A value, or why the metric does not apply to this motion (a skeleton without feet has no
/// foot skating). Serialised as the bare value, or `{"not_applicable": reason}`.
#[derive(Clone, Debug, PartialEq)]
pub enum Maybe<T> {
    Value(T),
    NotApplicable(String),
}

impl<T> Maybe<T> {
    pub fn value(&self) -> Option<&T> {
        match self {
            Maybe::Value(v) => Some(v),
            Maybe::NotApplicable(_) => None,
        }
    }

    pub fn map<U>(self, f: impl FnOnce(T) -> U) -> Maybe<U> {
        match self {
            Maybe::Value(v) => Maybe::Value(f(v)),
            Maybe::NotApplicable(r) => Maybe::NotApplicable(r),
        }
    }
}

impl<T: serde::Serialize> serde::Serialize for Maybe<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Maybe::Value(v) => v.serialize(s),
            Maybe::NotApplicable(reason) => {
                let mut m = s.serialize_map(Some(1))?;
                m.serialize_entry("not_applicable", reason)?;
                m.end()
            }
        }
    }
}

/// A distance-like value in clip units, and the same divided by a size (the skeleton's scale,
/// or the height a caller gave).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Measure {
    pub value: f64,
    pub normalised: f64,
}

impl Measure {
    /// `value` and `value / size` (`size` is checked positive by every caller).
    pub fn of(value: f64, size: f64) -> Measure {
        Measure { value, normalised: value / size }
    }
}

/// Units of the report's fields, so JSON readers need not guess.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PhysicsUnits {
    pub ground: &'static str,
    pub foot_skating: &'static str,
    pub ground_penetration: &'static str,
    pub floating: &'static str,
    pub jitter: &'static str,
    pub fractions: &'static str,
}

const UNITS: PhysicsUnits = PhysicsUnits {
    ground: "clip units (y of the ground plane)",
    foot_skating: "clip units per second; normalised: skeleton sizes per second",
    ground_penetration: "clip units; normalised: skeleton sizes",
    floating: "clip units; normalised: skeleton sizes",
    jitter: "clip units per second cubed (mean jerk); normalised: skeleton sizes per second cubed",
    fractions: "0..1",
};

/// Physical plausibility of one motion. Fractions are in 0..1.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PhysicsReport {
    pub frames: usize,
    pub fps: f64,
    /// The skeleton size every threshold and `normalised` value refers to.
    pub scale: f64,
    /// y of the ground plane used.
    pub ground: f64,
    /// Names of the foot joints (empty: no feet, so skating and floating do not apply).
    pub feet: Vec<String>,
    /// Foot-frames in contact (near the ground and slow).
    pub contact_fraction: Maybe<f64>,
    /// Mean horizontal speed of feet while near the ground (both ends of the frame step).
    pub foot_skating: Maybe<Measure>,
    /// Near-ground foot steps faster than the contact speed.
    pub skating_fraction: Maybe<f64>,
    /// Mean over frames of how far the lowest joint is below the ground (0 when above).
    pub ground_penetration: Measure,
    /// Frames with some joint below the ground.
    pub penetration_fraction: f64,
    /// Mean over frames of how far the lowest foot is above the contact band (0 when in it).
    pub floating: Maybe<Measure>,
    /// Frames with no foot within the contact band.
    pub floating_fraction: Maybe<f64>,
    /// Mean jerk magnitude (third difference x fps³) over joints and frames; needs 4 frames.
    pub jitter: Maybe<Measure>,
    pub units: PhysicsUnits,
}

/// Check what every metric relies on: enough frames, consistent sizes, a positive finite fps
/// and scale, finite positions. `what` names the metric in messages.
pub fn check_clip(clip: &WorldClip, min_frames: usize, what: &str) -> Result<(), MetricError> {
    if clip.joints == 0 {
        return Err(MetricError::TooLittle(format!("{what}: the clip has no joints")));
    }
    if clip.frames < min_frames {
        return Err(MetricError::TooLittle(format!("{what} needs at least {min_frames} frames, the clip has {}", clip.frames)));
    }
    let expected = clip.frames.checked_mul(clip.joints);
    if expected != Some(clip.positions.len()) {
        return Err(MetricError::Mismatch(format!(
            "{what}: the clip says {} frames x {} joints but holds {} positions",
            clip.frames,
            clip.joints,
            clip.positions.len()
        )));
    }
    if clip.parents.len() != clip.joints {
        return Err(MetricError::Mismatch(format!("{what}: {} parents for {} joints", clip.parents.len(), clip.joints)));
    }
    if let Some((j, p)) = clip.parents.iter().enumerate().find_map(|(j, p)| p.filter(|&p| p >= clip.joints).map(|p| (j, p))) {
        return Err(MetricError::Mismatch(format!("{what}: joint {j} has parent {p}, outside the {} joints", clip.joints)));
    }
    if let Some(&f) = clip.feet.iter().find(|&&f| f >= clip.joints) {
        return Err(MetricError::Mismatch(format!("{what}: foot joint {f} is outside the {} joints", clip.joints)));
    }
    if !clip.fps.is_finite() || clip.fps <= 0.0 {
        return Err(MetricError::NonFinite(format!("{what}: frames per second must be positive and finite, found {}", clip.fps)));
    }
    if !clip.scale.is_finite() || clip.scale <= 0.0 {
        return Err(MetricError::NonFinite(format!("{what}: the skeleton size (scale) must be positive and finite, found {}", clip.scale)));
    }
    if let Some((f, j)) = clip.first_non_finite() {
        let p = clip.at(f, j);
        return Err(MetricError::NonFinite(format!(
            "{what}: non-finite position ({}, {}, {}) at frame {f}, joint {j} '{}'",
            p.x,
            p.y,
            p.z,
            joint_name(clip, j)
        )));
    }
    Ok(())
}

/// A joint's name for messages (clips built by hand may have no names).
pub fn joint_name(clip: &WorldClip, j: usize) -> String {
    clip.names.get(j).cloned().unwrap_or_else(|| format!("joint {j}"))
}

fn check_options(opts: &PhysicsOptions) -> Result<(), MetricError> {
    let ok = |x: f64| x.is_finite() && x >= 0.0;
    if !ok(opts.contact_height) || !ok(opts.contact_speed) {
        return Err(MetricError::NonFinite(format!(
            "contact thresholds must be finite and non-negative, found height {} and speed {}",
            opts.contact_height, opts.contact_speed
        )));
    }
    if let Ground::Height(h) = opts.ground {
        if !h.is_finite() {
            return Err(MetricError::NonFinite(format!("the ground height must be finite, found {h}")));
        }
    }
    Ok(())
}

/// The y of the ground plane for this clip (the clip must have passed `check_clip`).
pub fn ground_height(clip: &WorldClip, ground: Ground) -> f64 {
    match ground {
        Ground::Zero => 0.0,
        Ground::Height(h) => h,
        Ground::Estimate => {
            let lowest: &dyn Fn(usize) -> f64 = if clip.feet.is_empty() {
                &|f| clip.frame(f).iter().map(|p| p.y).fold(f64::INFINITY, f64::min)
            } else {
                &|f| clip.feet.iter().map(|&j| clip.at(f, j).y).fold(f64::INFINITY, f64::min)
            };
            let mut per_frame: Vec<f64> = (0..clip.frames).map(lowest).collect();
            per_frame.sort_by(f64::total_cmp);
            per_frame.get((per_frame.len().saturating_sub(1)) / 10).copied().unwrap_or(0.0)
        }
    }
}

/// Foot contacts, one row per foot in `clip.feet` order, one flag per frame: the foot joint is
/// within `contact_height x scale` of the ground and moves slower than `contact_speed x scale`
/// per second (speed from the previous frame; frame 0 uses the next one). A clip that fails
/// `check_clip` (or a one-frame clip, for speed) gives all-false rows rather than a panic.
pub fn contacts(clip: &WorldClip, opts: &PhysicsOptions) -> Vec<Vec<bool>> {
    if check_clip(clip, 2, "contacts").is_err() || check_options(opts).is_err() {
        return vec![vec![false; clip.frames]; clip.feet.len()];
    }
    let ground = ground_height(clip, opts.ground);
    let band = opts.contact_height * clip.scale;
    let max_speed = opts.contact_speed * clip.scale;
    clip.feet
        .iter()
        .map(|&j| {
            (0..clip.frames)
                .map(|f| {
                    let (a, b) = if f == 0 { (0, 1) } else { (f - 1, f) };
                    let speed = clip.at(b, j).distance(clip.at(a, j)) * clip.fps;
                    clip.at(f, j).y - ground <= band && speed <= max_speed
                })
                .collect()
        })
        .collect()
}

fn horizontal(v: DVec3) -> f64 {
    (v.x * v.x + v.z * v.z).sqrt()
}

/// Score one motion; errors on non-finite input. A single frame (a rest pose) still has
/// penetration and floating; contacts and skating need 2 frames and jitter 4, and are
/// `NotApplicable` (with the reason) below that.
pub fn physics(clip: &WorldClip, opts: &PhysicsOptions) -> Result<PhysicsReport, MetricError> {
    check_clip(clip, 1, "physics")?;
    check_options(opts)?;
    let (frames, fps, scale) = (clip.frames, clip.fps, clip.scale);
    let ground = ground_height(clip, opts.ground);
    let band = opts.contact_height * scale;
    let max_speed = opts.contact_speed * scale;

    // Penetration: the lowest joint of each frame below the plane (any body part counts, so
    // it applies to creatures without feet too).
    let mut depth_sum = 0.0;
    let mut below = 0usize;
    for f in 0..frames {
        let lowest = clip.frame(f).iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        let depth = (ground - lowest).max(0.0);
        depth_sum += depth;
        below += usize::from(depth > 0.0);
    }
    let ground_penetration = Measure::of(depth_sum / frames as f64, scale);
    let penetration_fraction = below as f64 / frames as f64;

    // Jerk: third finite difference of every joint, built from one-frame steps so that a
    // constant pose gives exactly zero (constant velocity or acceleration: zero up to rounding).
    let jitter = if frames < 4 {
        Maybe::NotApplicable(format!("jerk needs 4 frames (a third difference), the clip has {frames}"))
    } else {
        let mut jerk_sum = 0.0;
        for f in 0..frames - 3 {
            for j in 0..clip.joints {
                let step = |k: usize| clip.at(f + k + 1, j) - clip.at(f + k, j);
                let (a, b, c) = (step(0), step(1), step(2));
                jerk_sum += ((c - b) - (b - a)).length();
            }
        }
        Maybe::Value(Measure::of(jerk_sum / ((frames - 3) * clip.joints) as f64 * fps * fps * fps, scale))
    };

    let (contact_fraction, foot_skating, skating_fraction, floating, floating_fraction) = if clip.feet.is_empty() {
        let why = "the skeleton has no feet (skeleton::roles::feet found none)".to_string();
        (
            Maybe::NotApplicable(why.clone()),
            Maybe::NotApplicable(why.clone()),
            Maybe::NotApplicable(why.clone()),
            Maybe::NotApplicable(why.clone()),
            Maybe::NotApplicable(why),
        )
    } else {
        let rows = contacts(clip, opts);
        let in_contact = rows.iter().flatten().filter(|&&c| c).count();
        let contact_fraction = in_contact as f64 / (frames * clip.feet.len()) as f64;
        // Skating: horizontal speed of a foot over steps where it is near the ground at both
        // ends; near-ground is by height only, since contact-by-speed would hide the sliding.
        let (mut speed_sum, mut steps, mut fast) = (0.0, 0usize, 0usize);
        for &j in &clip.feet {
            for f in 1..frames {
                let (a, b) = (clip.at(f - 1, j), clip.at(f, j));
                if a.y - ground <= band && b.y - ground <= band {
                    let speed = horizontal(b - a) * fps;
                    speed_sum += speed;
                    steps += 1;
                    fast += usize::from(speed > max_speed);
                }
            }
        }
        // A clip whose feet never come near the ground does not skate (floating reports it).
        let skating = if steps == 0 { 0.0 } else { speed_sum / steps as f64 };
        let skating_fraction = if steps == 0 { 0.0 } else { fast as f64 / steps as f64 };
        let (mut float_sum, mut airborne) = (0.0, 0usize);
        for f in 0..frames {
            let lowest = clip.feet.iter().map(|&j| clip.at(f, j).y).fold(f64::INFINITY, f64::min);
            let gap = (lowest - ground - band).max(0.0);
            float_sum += gap;
            airborne += usize::from(gap > 0.0);
        }
        let moving = |v: Maybe<f64>| {
            if frames < 2 {
                Maybe::NotApplicable("contacts and skating need 2 frames (a speed), the clip has 1".to_string())
            } else {
                v
            }
        };
        (
            moving(Maybe::Value(contact_fraction)),
            moving(Maybe::Value(skating)).map(|v| Measure::of(v, scale)),
            moving(Maybe::Value(skating_fraction)),
            Maybe::Value(Measure::of(float_sum / frames as f64, scale)),
            Maybe::Value(airborne as f64 / frames as f64),
        )
    };
    Ok(PhysicsReport {
        frames,
        fps,
        scale,
        ground,
        feet: clip.feet.iter().map(|&j| joint_name(clip, j)).collect(),
        contact_fraction,
        foot_skating,
        skating_fraction,
        ground_penetration,
        penetration_fraction,
        floating,
        floating_fraction,
        jitter,
        units: UNITS,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A two-joint clip: a hip above a foot, at `fps`, the foot at `foot(f)`, the hip 1 above.
    pub(crate) fn biped(frames: usize, fps: f64, foot: impl Fn(usize) -> DVec3) -> WorldClip {
        let mut positions = Vec::new();
        for f in 0..frames {
            positions.push(foot(f) + DVec3::Y);
            positions.push(foot(f));
        }
        WorldClip { frames, joints: 2, fps, positions, parents: vec![None, Some(0)], names: vec!["Hips".into(), "LeftFoot".into()], feet: vec![1], scale: 1.0 }
    }

    #[test]
    fn options_parse_and_check() {
        assert_eq!("zero".parse(), Ok(Ground::Zero));
        assert_eq!("estimate".parse(), Ok(Ground::Estimate));
        assert_eq!("-0.5".parse(), Ok(Ground::Height(-0.5)));
        assert!("inf".parse::<Ground>().unwrap_err().contains("expected zero, estimate or a height"));
        assert_eq!(PhysicsOptions::new(Ground::Zero, 0.05, 0.5), Ok(PhysicsOptions::default()));
        assert!(PhysicsOptions::new(Ground::Zero, -1.0, 0.5).unwrap_err().to_string().contains("must be positive numbers"));
        assert!(PhysicsOptions::new(Ground::Zero, 0.05, f64::NAN).is_err());
    }

    #[test]
    fn still_on_the_ground_scores_zero_everywhere() {
        let clip = biped(10, 30.0, |_| DVec3::ZERO);
        let r = physics(&clip, &PhysicsOptions::default()).unwrap();
        assert_eq!(r.ground_penetration.value, 0.0);
        assert_eq!(r.jitter.value().unwrap().value, 0.0);
        assert_eq!(r.foot_skating, Maybe::Value(Measure { value: 0.0, normalised: 0.0 }));
        assert_eq!(r.floating, Maybe::Value(Measure { value: 0.0, normalised: 0.0 }));
        assert_eq!(r.contact_fraction, Maybe::Value(1.0));
    }

    #[test]
    fn sliding_foot_skates_at_its_speed() {
        // 0.3 units per second along x, at ground level: skating 0.3, and faster than the
        // 0.5 x 0.5 = 0.25 contact speed on every step, so no contact.
        let clip = WorldClip { scale: 0.5, ..biped(31, 30.0, |f| DVec3::new(0.01 * f as f64, 0.0, 0.0)) };
        let r = physics(&clip, &PhysicsOptions::default()).unwrap();
        let s = r.foot_skating.value().unwrap();
        assert!((s.value - 0.3).abs() < 1e-12, "{s:?}");
        assert!((s.normalised - 0.6).abs() < 1e-12);
        assert_eq!(r.skating_fraction, Maybe::Value(1.0));
        assert_eq!(r.contact_fraction, Maybe::Value(0.0));
        // Constant velocity has no jerk.
        assert!(r.jitter.value().unwrap().value.abs() < 1e-9);
    }

    #[test]
    fn floating_and_sinking_are_measured_against_the_band() {
        let opts = PhysicsOptions::default();
        let up = physics(&biped(8, 30.0, |_| DVec3::new(0.0, 0.25, 0.0)), &opts).unwrap();
        assert!((up.floating.value().unwrap().value - 0.20).abs() < 1e-12);
        assert_eq!(up.floating_fraction, Maybe::Value(1.0));
        assert_eq!(up.ground_penetration.value, 0.0);
        let down = physics(&biped(8, 30.0, |_| DVec3::new(0.0, -0.1, 0.0)), &opts).unwrap();
        assert!((down.ground_penetration.value - 0.1).abs() < 1e-12);
        assert_eq!(down.penetration_fraction, 1.0);
        assert_eq!(down.floating.value().unwrap().value, 0.0);
        // A given ground plane moves both.
        let raised = physics(&biped(8, 30.0, |_| DVec3::ZERO), &PhysicsOptions { ground: Ground::Height(0.5), ..opts }).unwrap();
        assert!((raised.ground_penetration.value - 0.5).abs() < 1e-12);
        // The estimated ground follows the feet: the sinking clip stands on it.
        let est = physics(&biped(8, 30.0, |_| DVec3::new(0.0, -0.1, 0.0)), &PhysicsOptions { ground: Ground::Estimate, ..opts }).unwrap();
        assert!((est.ground + 0.1).abs() < 1e-12 && est.ground_penetration.value == 0.0);
    }

    #[test]
    fn jitter_is_the_mean_jerk() {
        // Foot and hip follow x = f³ / 6 at 10 fps: third difference 1 per frame³ -> 1000/s³.
        let clip = biped(6, 10.0, |f| DVec3::new((f * f * f) as f64 / 6.0, 0.0, 0.0));
        let r = physics(&clip, &PhysicsOptions::default()).unwrap();
        assert!((r.jitter.value().unwrap().value - 1000.0).abs() < 1e-9, "{:?}", r.jitter);
        let short = physics(&biped(3, 10.0, |_| DVec3::ZERO), &PhysicsOptions::default()).unwrap();
        assert!(matches!(short.jitter, Maybe::NotApplicable(_)));
    }

    #[test]
    fn no_feet_is_not_applicable_and_serialises_with_the_reason() {
        let clip = WorldClip { feet: vec![], ..biped(5, 30.0, |_| DVec3::ZERO) };
        let r = physics(&clip, &PhysicsOptions::default()).unwrap();
        assert!(matches!(r.foot_skating, Maybe::NotApplicable(_)));
        let json = serde_json::to_value(&r).unwrap();
        assert!(json["foot_skating"]["not_applicable"].as_str().unwrap().contains("no feet"));
        assert_eq!(json["jitter"]["value"], 0.0);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let opts = PhysicsOptions::default();
        assert!(matches!(physics(&biped(0, 30.0, |_| DVec3::ZERO), &opts), Err(MetricError::TooLittle(_))));
        // One frame: a pose can penetrate or float, but not skate or jitter.
        let one = physics(&biped(1, 30.0, |_| DVec3::new(0.0, -0.2, 0.0)), &opts).unwrap();
        assert!((one.ground_penetration.value - 0.2).abs() < 1e-12);
        assert!(matches!(one.foot_skating, Maybe::NotApplicable(_)) && matches!(one.jitter, Maybe::NotApplicable(_)));
        assert!(matches!(one.contact_fraction, Maybe::NotApplicable(_)));
        let mut nan = biped(6, 30.0, |_| DVec3::ZERO);
        nan.positions[5].y = f64::NAN;
        let e = physics(&nan, &opts).unwrap_err();
        assert!(matches!(&e, MetricError::NonFinite(m) if m.contains("frame 2, joint 1 'LeftFoot'")), "{e}");
        assert!(matches!(physics(&WorldClip { fps: 0.0, ..biped(6, 30.0, |_| DVec3::ZERO) }, &opts), Err(MetricError::NonFinite(_))));
        let short = WorldClip { frames: 7, ..biped(6, 30.0, |_| DVec3::ZERO) };
        assert!(matches!(physics(&short, &opts), Err(MetricError::Mismatch(_))));
        assert_eq!(contacts(&short, &opts), vec![vec![false; 7]]);
        assert!(physics(&biped(6, 30.0, |_| DVec3::ZERO), &PhysicsOptions { ground: Ground::Height(f64::NAN), ..opts }).is_err());
    }
}
