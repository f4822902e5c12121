//! Upper bounds for every count, length, rate and size option, in one place.
//!
//! An option's bound is what a sane run could ask for with room to spare; past it a run would
//! take hours or more memory than a machine has, so clap refuses the value with one line
//! before any work starts. Integer options use `clap::value_parser!(u64).range(..)` or
//! `count` with these constants; real-valued ones use `positive` and `non_negative` (which also refuse NaN and
//! infinities, that `f64::from_str` accepts).

/// `--threads`.
pub const MAX_THREADS: usize = 256;
/// Frames a tool generates or synthesises (`--frames`, and `--seconds` times the frame rate):
/// an hour at 30 fps.
pub const MAX_FRAMES: usize = 108_000;
/// `skel-aug --add`: joints inserted (a skeleton rarely has more than a few hundred).
pub const MAX_ADD_JOINTS: usize = 256;
/// Variants or samples written by one run (`skel-aug -n`).
pub const MAX_VARIANTS: u64 = 1_000;
/// `mo-retarget --steps`: match-and-blend iterations per level (the paper uses 3).
pub const MAX_RETARGET_STEPS: usize = 100;
/// `mo-retarget --patch`: patch length in frames (the paper uses 11).
pub const MAX_PATCH: usize = 1_000;
/// `mo-train --steps`.
pub const MAX_TRAIN_STEPS: u64 = 100_000_000;
/// Durations in seconds (`--seconds`, `--blend`, `--window`): a day.
pub const MAX_SECONDS: f64 = 86_400.0;
/// `mo-train --checkpoint-minutes`: a week.
pub const MAX_CHECKPOINT_MINUTES: f64 = 7.0 * 24.0 * 60.0;
/// Loss weights.
pub const MAX_WEIGHT: f64 = 1e6;
/// Diffusion steps and layers asked of a model (`--t`, `--layer`): far above any schedule.
pub const MAX_DIFFUSION_T: usize = 10_000;
pub const MAX_LAYER: usize = 1_000;
/// `mo-segment --pca-dims` and `--min-segment`.
pub const MAX_PCA_DIMS: usize = 4_096;
pub const MAX_MIN_SEGMENT: usize = MAX_FRAMES;

/// A whole number in `lo..=hi`, for `usize` options.
pub fn count(lo: usize, hi: usize) -> impl Fn(&str) -> Result<usize, String> + Clone + Send + Sync + 'static {
    move |text| match text.trim().parse::<u128>() {
        Ok(v) if (lo as u128..=hi as u128).contains(&v) => Ok(v as usize),
        Ok(_) => Err(format!("expected a whole number from {lo} to {hi}, found {text}")),
        Err(_) => Err(format!("'{text}' is not a whole number")),
    }
}

fn number(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("'{text}' is not a finite number"))
    }
}

/// A number in `(0, max]`.
pub fn positive(max: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |text| {
        let v = number(text)?;
        match () {
            _ if v > 0.0 && v <= max => Ok(v),
            _ if max == f64::MAX => Err(format!("expected a number above 0, found {text}")),
            _ => Err(format!("expected a number above 0 and at most {max}, found {text}")),
        }
    }
}

/// A number in `[0, max]`.
pub fn non_negative(max: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |text| {
        let v = number(text)?;
        if (0.0..=max).contains(&v) {
            Ok(v)
        } else {
            Err(format!("expected a number from 0 to {max}, found {text}"))
        }
    }
}

/// Frames for `seconds` at `fps` when that is at most `MAX_FRAMES`; the error says what the
/// length came to.
pub fn frames_for_seconds(seconds: f64, fps: f64) -> Result<usize, String> {
    let frames = (seconds * fps).round();
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(format!("--seconds must be a positive number, found {seconds}"));
    }
    if !(frames <= MAX_FRAMES as f64) {
        return Err(format!("--seconds {seconds} is {frames} frames at {fps:.3} fps, more than the {MAX_FRAMES} a run may make"));
    }
    Ok((frames as usize).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers() {
        assert_eq!(count(1, 5)("5"), Ok(5));
        assert!(count(1, 5)("6").is_err());
        assert!(count(1, 5)("18446744073709551616").is_err());
        assert!(count(1, 5)("-1").is_err());
        assert_eq!(positive(10.0)("2.5"), Ok(2.5));
        assert!(positive(10.0)("0").is_err());
        assert!(positive(10.0)("NaN").is_err());
        assert!(positive(10.0)("inf").is_err());
        assert!(positive(10.0)("11").is_err());
        assert_eq!(non_negative(1.0)("0"), Ok(0.0));
        assert!(non_negative(1.0)("-0.1").is_err());
        assert_eq!(frames_for_seconds(2.0, 30.0), Ok(60));
        assert_eq!(frames_for_seconds(0.001, 30.0), Ok(1));
        assert!(frames_for_seconds(1e12, 30.0).is_err());
        assert!(frames_for_seconds(f64::NAN, 30.0).is_err());
    }
}
