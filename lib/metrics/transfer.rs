//! Motion transfer metrics of Motion2Motion (paper §4.2):
//! frequency alignment, contact consistency, diversity and throughput. The paper gives one
//! sentence per metric and the reference code computes none of them, so the exact recipes are
//! ours; `docs/metrics.md` states each choice.

use super::physics::{self, check_clip, Maybe, Measure, PhysicsOptions};
use super::{MetricError, WorldClip};
use glam::DVec3;

/// Frequency alignment: mean over joint pairs of the cosine similarity of the power spectral
/// densities of the source and result joint velocities (0..1, 1 = same spectrum shape).
#[derive(Clone, Debug, serde::Serialize)]
pub struct FrequencyAlignment {
    pub value: f64,
    /// One similarity per pair, in the order given.
    pub per_pair: Vec<f64>,
    /// Frequency bins compared (0 Hz excluded).
    pub bins: usize,
    /// Bin spacing and highest bin, Hz.
    pub resolution_hz: f64,
    pub max_hz: f64,
}

/// Contact consistency: agreement of the foot contact patterns of source and result through
/// the bound pairs that reach feet (0..1, fraction of frames on which both agree).
#[derive(Clone, Debug, serde::Serialize)]
pub struct ContactConsistency {
    pub value: f64,
    /// The pairs that counted (source joint, result joint), and their agreement.
    pub pairs: Vec<(usize, usize)>,
    pub per_pair: Vec<f64>,
    /// Result frames compared.
    pub frames: usize,
}

fn check_pairs(source: &WorldClip, result: &WorldClip, pairs: &[(usize, usize)], what: &str) -> Result<(), MetricError> {
    if pairs.is_empty() {
        return Err(MetricError::TooLittle(format!("{what} needs at least one (source joint, result joint) pair")));
    }
    if let Some(&(s, r)) = pairs.iter().find(|&&(s, r)| s >= source.joints || r >= result.joints) {
        return Err(MetricError::Mismatch(format!(
            "{what}: pair ({s}, {r}) is outside the skeletons ({} source joints, {} result joints)",
            source.joints, result.joints
        )));
    }
    Ok(())
}

/// Velocities of joint `j` (one per frame step, clip units per second), minus their mean:
/// the mean velocity is the 0 Hz bin (steady locomotion), which says nothing about timing.
fn velocities(clip: &WorldClip, j: usize) -> Vec<DVec3> {
    let v: Vec<DVec3> = (1..clip.frames).map(|f| (clip.at(f, j) - clip.at(f - 1, j)) * clip.fps).collect();
    let mean = v.iter().copied().sum::<DVec3>() / v.len() as f64;
    v.into_iter().map(|x| x - mean).collect()
}

/// Power spectral density of a vector signal at the given frequencies (Hz): Hann-windowed
/// periodogram, |X(f)|² summed over x, y, z (so it does not depend on the axes' orientation),
/// evaluated at arbitrary frequencies (so clips of different lengths and frame rates land on
/// the same bins) by Goertzel's recurrence: one multiply-add per sample and axis, and |X(f)|²
/// exactly for any f, not only the DFT's own bins.
fn psd(signal: &[DVec3], fps: f64, freqs: &[f64]) -> Vec<f64> {
    let n = signal.len();
    let window = |i: usize| if n > 1 { 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64).cos() } else { 1.0 };
    let power: f64 = (0..n).map(|i| window(i) * window(i)).sum::<f64>().max(1e-300);
    let windowed: Vec<DVec3> = signal.iter().enumerate().map(|(i, x)| *x * window(i)).collect();
    freqs
        .iter()
        .map(|&hz| {
            let coeff = 2.0 * (2.0 * std::f64::consts::PI * hz / fps).cos();
            let (mut s1, mut s2) = (DVec3::ZERO, DVec3::ZERO);
            for x in &windowed {
                let s0 = *x + coeff * s1 - s2;
                s2 = s1;
                s1 = s0;
            }
            // |s1 - e^{-iω} s2|² per axis.
            let magnitude = s1 * s1 + s2 * s2 - coeff * s1 * s2;
            magnitude.element_sum().max(0.0) / (power * fps)
        })
        .collect()
}

/// Cosine similarity of two non-negative spectra; two silent joints agree (1), a silent and a
/// moving one do not (0).
fn cosine(a: &[f64], b: &[f64]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let (na, nb) = (a.iter().map(|x| x * x).sum::<f64>().sqrt(), b.iter().map(|x| x * x).sum::<f64>().sqrt());
    // An absolute floor: FK rounding on a still joint (velocities ~1e-13 units/s) gives
    // spectra many orders below it, any visible motion many orders above.
    let silent = |norm: f64| norm <= 1e-20;
    match (silent(na), silent(nb)) {
        (true, true) => 1.0,
        (true, false) | (false, true) => 0.0,
        _ => (dot / (na * nb)).clamp(0.0, 1.0),
    }
}

/// Frequency alignment over joint pairs (source joint, result joint). Velocities of each
/// joint's world position (mean removed), Hann-windowed periodograms evaluated on common bins:
/// spacing = the coarser of the two clips' native resolutions (fps / steps), up to the lower
/// Nyquist frequency, 0 Hz excluded. Needs 4 frames in each clip.
pub fn frequency_alignment(source: &WorldClip, result: &WorldClip, pairs: &[(usize, usize)]) -> Result<FrequencyAlignment, MetricError> {
    check_clip(source, 4, "frequency alignment (source)")?;
    check_clip(result, 4, "frequency alignment (result)")?;
    check_pairs(source, result, pairs, "frequency alignment")?;
    let steps = |c: &WorldClip| (c.frames - 1) as f64;
    let resolution = (source.fps / steps(source)).max(result.fps / steps(result));
    let max_hz = 0.5 * source.fps.min(result.fps);
    let bins = ((max_hz / resolution) + 1e-9).floor() as usize;
    if bins == 0 {
        return Err(MetricError::TooLittle("frequency alignment: the clips are too short to share a frequency bin".into()));
    }
    let freqs: Vec<f64> = (1..=bins).map(|k| k as f64 * resolution).collect();
    let per_pair: Vec<f64> =
        pairs.iter().map(|&(s, r)| cosine(&psd(&velocities(source, s), source.fps, &freqs), &psd(&velocities(result, r), result.fps, &freqs))).collect();
    Ok(FrequencyAlignment { value: per_pair.iter().sum::<f64>() / per_pair.len() as f64, per_pair, bins, resolution_hz: resolution, max_hz: freqs[bins - 1] })
}

/// Joints in the subtree of `j` (itself included).
fn subtree(clip: &WorldClip, j: usize) -> Vec<bool> {
    let mut inside = vec![false; clip.joints];
    inside[j] = true;
    // Parents precede children in every skeleton we build; a later pass catches any that don't.
    for _ in 0..2 {
        for k in 0..clip.joints {
            if let Some(p) = clip.parents[k] {
                if inside[p] {
                    inside[k] = true;
                }
            }
        }
    }
    inside
}

/// Contact consistency through a binding. A pair counts when both joints reach feet (the
/// joint is a foot or has feet below it) and neither is a root (a root reaches every foot,
/// which would make "some foot down" agree trivially). Per frame, a pair's contact is "some
/// foot below the joint is in contact" (`physics::contacts`); result frame f is compared with
/// source frame round(f x (source frames - 1) / (result frames - 1)), so clips of different
/// lengths compare at the same phase. `NotApplicable` when no pair reaches feet on both sides.
pub fn contact_consistency(
    source: &WorldClip,
    result: &WorldClip,
    pairs: &[(usize, usize)],
    opts: &PhysicsOptions,
) -> Result<Maybe<ContactConsistency>, MetricError> {
    check_clip(source, 2, "contact consistency (source)")?;
    check_clip(result, 2, "contact consistency (result)")?;
    check_pairs(source, result, pairs, "contact consistency")?;
    let (src_contacts, res_contacts) = (physics::contacts(source, opts), physics::contacts(result, opts));
    // Per frame: is some foot of the subtree of j in contact? `None` when the subtree has none.
    let signal = |clip: &WorldClip, rows: &[Vec<bool>], j: usize| -> Option<Vec<bool>> {
        clip.parents[j]?;
        let inside = subtree(clip, j);
        let feet: Vec<usize> = clip.feet.iter().enumerate().filter(|(_, &f)| inside[f]).map(|(i, _)| i).collect();
        (!feet.is_empty()).then(|| (0..clip.frames).map(|f| feet.iter().any(|&i| rows[i][f])).collect())
    };
    let map = |f: usize| -> usize {
        if result.frames == 1 {
            0
        } else {
            ((f as f64 * (source.frames - 1) as f64 / (result.frames - 1) as f64).round() as usize).min(source.frames - 1)
        }
    };
    let (mut counted, mut per_pair) = (Vec::new(), Vec::new());
    for &(s, r) in pairs {
        if let (Some(a), Some(b)) = (signal(source, &src_contacts, s), signal(result, &res_contacts, r)) {
            let agree = (0..result.frames).filter(|&f| a[map(f)] == b[f]).count();
            counted.push((s, r));
            per_pair.push(agree as f64 / result.frames as f64);
        }
    }
    if counted.is_empty() {
        return Ok(Maybe::NotApplicable(format!(
            "no bound pair reaches feet on both sides (source feet: {}, result feet: {}; roots do not count)",
            source.feet.len(),
            result.feet.len()
        )));
    }
    Ok(Maybe::Value(ContactConsistency { value: per_pair.iter().sum::<f64>() / per_pair.len() as f64, pairs: counted, per_pair, frames: result.frames }))
}

/// Motion ratio: how much the result moves next to its source, per bound pair the RMS speed of
/// the result joint over that of the source joint (mean velocity removed, as in frequency
/// alignment, and each divided by its skeleton's size, so a mouse and a dinosaur doing the
/// same motion score 1). Frequency alignment and contact consistency cannot tell a result
/// that barely moves from one that moves fully in the same rhythm; this can.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MotionRatio {
    /// Median over the pairs whose source joint moves.
    pub value: f64,
    /// One ratio per such pair (source joint, result joint).
    pub pairs: Vec<(usize, usize)>,
    pub per_pair: Vec<f64>,
}

/// [`MotionRatio`]; `NotApplicable` when no bound source joint moves. Needs 2 frames per clip.
pub fn motion_ratio(source: &WorldClip, result: &WorldClip, pairs: &[(usize, usize)]) -> Result<Maybe<MotionRatio>, MetricError> {
    check_clip(source, 2, "motion ratio (source)")?;
    check_clip(result, 2, "motion ratio (result)")?;
    check_pairs(source, result, pairs, "motion ratio")?;
    let speed = |clip: &WorldClip, j: usize| -> f64 {
        let v = velocities(clip, j);
        (v.iter().map(|x| x.length_squared()).sum::<f64>() / v.len() as f64).sqrt() / clip.scale.max(1e-12)
    };
    let (mut counted, mut per_pair) = (Vec::new(), Vec::new());
    for &(s, r) in pairs {
        let a = speed(source, s);
        // Relative floor: FK rounding on a still joint, not motion.
        if a > 1e-9 {
            counted.push((s, r));
            per_pair.push(speed(result, r) / a);
        }
    }
    if counted.is_empty() {
        return Ok(Maybe::NotApplicable("no bound source joint moves".into()));
    }
    let mut sorted = per_pair.clone();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let value = if n % 2 == 1 { sorted[n / 2] } else { 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]) };
    Ok(Maybe::Value(MotionRatio { value, pairs: counted, per_pair }))
}

/// Transfer diversity: mean over pairs of samples of the mean distance between corresponding
/// joints over all frames (clip units; normalised by the first sample's scale). Samples must
/// share joints and frame count; fewer than 2 samples is `TooLittle`.
pub fn diversity(samples: &[WorldClip]) -> Result<Measure, MetricError> {
    if samples.len() < 2 {
        return Err(MetricError::TooLittle(format!("diversity needs at least 2 samples, got {}", samples.len())));
    }
    for (i, c) in samples.iter().enumerate() {
        check_clip(c, 1, &format!("diversity (sample {i})"))?;
        if c.joints != samples[0].joints || c.frames != samples[0].frames {
            return Err(MetricError::Mismatch(format!(
                "diversity: sample {i} has {} joints x {} frames, sample 0 has {} joints x {} frames",
                c.joints, c.frames, samples[0].joints, samples[0].frames
            )));
        }
    }
    let (mut sum, mut pairs) = (0.0, 0usize);
    for a in 0..samples.len() {
        for b in a + 1..samples.len() {
            let d: f64 = samples[a].positions.iter().zip(&samples[b].positions).map(|(x, y)| x.distance(*y)).sum();
            sum += d / samples[a].positions.len() as f64;
            pairs += 1;
        }
    }
    Ok(Measure::of(sum / pairs as f64, samples[0].scale))
}

/// Frames produced per second of wall time.
pub fn throughput(frames: usize, seconds: f64) -> Result<f64, MetricError> {
    if !seconds.is_finite() || seconds <= 0.0 {
        return Err(MetricError::NonFinite(format!("throughput: the duration must be positive and finite, found {seconds} s")));
    }
    if frames == 0 {
        return Err(MetricError::TooLittle("throughput: no frames were produced".into()));
    }
    Ok(frames as f64 / seconds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::physics::tests::biped;

    fn sway(frames: usize, fps: f64, hz: f64, amplitude: f64) -> WorldClip {
        biped(frames, fps, move |f| DVec3::new(amplitude * (2.0 * std::f64::consts::PI * hz * f as f64 / fps).sin(), 0.0, 0.0))
    }

    #[test]
    fn same_rhythm_aligns_whatever_the_size_length_and_frame_rate() {
        let a = sway(120, 30.0, 1.5, 0.2);
        let same = frequency_alignment(&a, &a, &[(0, 0), (1, 1)]).unwrap();
        assert!((same.value - 1.0).abs() < 1e-12);
        // A bigger creature doing the same rhythm at 60 fps for a different duration.
        let b = sway(300, 60.0, 1.5, 3.0);
        let scaled = frequency_alignment(&a, &b, &[(1, 1)]).unwrap();
        assert!(scaled.value > 0.95, "{scaled:?}");
        assert!((scaled.max_hz - 15.0).abs() < 0.3 && scaled.bins > 10);
        // A different rhythm scores far lower.
        let c = sway(120, 30.0, 4.0, 0.2);
        let other = frequency_alignment(&a, &c, &[(1, 1)]).unwrap();
        assert!(other.value < 0.2, "{other:?}");
        // Silence against silence agrees, silence against motion does not.
        let still = sway(50, 30.0, 1.0, 0.0);
        assert_eq!(frequency_alignment(&still, &still, &[(1, 1)]).unwrap().value, 1.0);
        assert_eq!(frequency_alignment(&still, &a, &[(1, 1)]).unwrap().value, 0.0);
    }

    #[test]
    fn motion_ratio_tells_a_result_that_barely_moves() {
        let a = sway(120, 30.0, 1.5, 0.2);
        let Maybe::Value(same) = motion_ratio(&a, &a, &[(0, 0), (1, 1)]).unwrap() else { panic!("a moving source") };
        assert!((same.value - 1.0).abs() < 1e-12, "{same:?}");
        // The same rhythm at a tenth of the amplitude: frequency alignment cannot see it.
        let faint = sway(120, 30.0, 1.5, 0.02);
        assert!(frequency_alignment(&a, &faint, &[(1, 1)]).unwrap().value > 0.99);
        let Maybe::Value(r) = motion_ratio(&a, &faint, &[(1, 1)]).unwrap() else { panic!("a moving source") };
        assert!((r.value - 0.1).abs() < 1e-9, "{r:?}");
        let still = sway(50, 30.0, 1.0, 0.0);
        assert!(matches!(motion_ratio(&still, &a, &[(1, 1)]).unwrap(), Maybe::NotApplicable(_)));
        assert!(matches!(motion_ratio(&a, &a, &[(0, 9)]), Err(MetricError::Mismatch(_))));
    }

    #[test]
    fn psd_by_goertzel_matches_a_direct_dft() {
        let signal: Vec<DVec3> = (0..300).map(|i| DVec3::new((i as f64 * 0.37).sin(), (i as f64 * 1.1).cos(), (i % 7) as f64)).collect();
        let freqs = [0.1, 1.3, 7.7, 14.9];
        let fast = psd(&signal, 30.0, &freqs);
        let n = signal.len();
        let w = |i: usize| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64).cos();
        let power: f64 = (0..n).map(|i| w(i) * w(i)).sum();
        let direct: Vec<f64> = freqs
            .iter()
            .map(|&hz| {
                let (mut re, mut im) = (DVec3::ZERO, DVec3::ZERO);
                for (i, x) in signal.iter().enumerate() {
                    let a = -2.0 * std::f64::consts::PI * hz * i as f64 / 30.0;
                    re += *x * w(i) * a.cos();
                    im += *x * w(i) * a.sin();
                }
                (re.length_squared() + im.length_squared()) / (power * 30.0)
            })
            .collect();
        // Accurate relative to the spectrum's size (what the cosine similarity sees).
        let top = direct.iter().fold(0.0f64, |m, x| m.max(*x));
        for k in 0..freqs.len() {
            assert!((fast[k] - direct[k]).abs() <= 1e-10 * top, "{} Hz: {} vs {}", freqs[k], fast[k], direct[k]);
        }
    }

    #[test]
    fn frequency_alignment_refuses_bad_input() {
        let a = sway(20, 30.0, 1.0, 0.1);
        assert!(matches!(frequency_alignment(&a, &a, &[]), Err(MetricError::TooLittle(_))));
        assert!(matches!(frequency_alignment(&a, &a, &[(0, 5)]), Err(MetricError::Mismatch(_))));
        assert!(matches!(frequency_alignment(&sway(3, 30.0, 1.0, 0.1), &a, &[(0, 0)]), Err(MetricError::TooLittle(_))));
    }

    /// A foot that steps: on the ground for `down` frames, up 0.5 for `up` frames, repeating.
    fn stepper(frames: usize, down: usize, up: usize, phase: usize) -> WorldClip {
        biped(frames, 30.0, move |f| DVec3::new(0.0, if (f + phase) % (down + up) < down { 0.0 } else { 0.5 }, 0.0))
    }

    #[test]
    fn contact_consistency_by_hand() {
        let opts = PhysicsOptions::default();
        let a = stepper(40, 5, 5, 0);
        let same = contact_consistency(&a, &a, &[(1, 1)], &opts).unwrap();
        assert_eq!(same.value().unwrap().value, 1.0);
        // Half a cycle out of phase: contact exactly where the other is up, except the frames
        // where a foot has just landed (it moved 0.5 in one frame: too fast for contact).
        let b = stepper(40, 5, 5, 5);
        let r = contact_consistency(&a, &b, &[(1, 1)], &opts).unwrap();
        let v = r.value().unwrap().value;
        // Landing frames (f % 5 == 0, f > 0) are "not in contact" in both: they agree.
        let landings = (1..40).filter(|f| f % 5 == 0).count();
        assert!((v - landings as f64 / 40.0).abs() < 1e-12, "{v}");
        // Binding only the roots reaches no feet by the rule.
        assert!(matches!(contact_consistency(&a, &b, &[(0, 0)], &opts).unwrap(), Maybe::NotApplicable(_)));
        // A result twice as long at the same phase agrees fully... up to the landing frames
        // that the nearest-frame map shifts; at least most frames agree.
        let long = stepper(79, 10, 10, 0);
        assert!(contact_consistency(&a, &long, &[(1, 1)], &opts).unwrap().value().unwrap().value > 0.8);
    }

    #[test]
    fn diversity_and_throughput() {
        let a = sway(10, 30.0, 1.0, 0.0);
        assert_eq!(diversity(&[a.clone(), a.clone(), a.clone()]).unwrap().value, 0.0);
        let mut b = a.clone();
        b.positions.iter_mut().for_each(|p| p.z += 0.3);
        let mut c = a.clone();
        c.positions.iter_mut().for_each(|p| p.z -= 0.3);
        // Pairs: a-b 0.3, a-c 0.3, b-c 0.6 -> mean 0.4.
        let d = diversity(&[a.clone(), b, c]).unwrap();
        assert!((d.value - 0.4).abs() < 1e-12);
        assert!(matches!(diversity(std::slice::from_ref(&a)), Err(MetricError::TooLittle(_))));
        assert!(matches!(diversity(&[a.clone(), sway(11, 30.0, 1.0, 0.0)]), Err(MetricError::Mismatch(_))));
        assert_eq!(throughput(300, 1.5).unwrap(), 200.0);
        assert!(throughput(300, 0.0).is_err() && throughput(300, f64::NAN).is_err() && throughput(0, 1.0).is_err());
    }
}
