//! Temporal segmentation against known action boundaries: `cargo bench --bench segment`.
//!
//! Two families of clips:
//!
//! * `synthetic`: walk-stop-walk clips of every legged creature and the bird (`synth::training`,
//!   variants 0-2, two seeds each, 150-300 frames at 30 fps). True boundaries: the first
//!   standing frame and the first frame walking again (`Clip::boundaries` gives the first and
//!   *last* standing frame; the second boundary is one after it).
//! * `real`: two clips of one skeleton from `../shared/data/bvh` played one after the other (the
//!   second moved so that it starts where the first ended); the boundary is the first clip's
//!   frame count. Skipped with a printed reason when the corpus is absent. Nothing from it is
//!   stored; numbers are only printed.
//!
//! Frame indices are BVH frames throughout: feature row t describes BVH frame t (AnyTop features
//! have one row fewer than the clip; `segment::input::segment_input` gives the last frame the label
//! before it), so predicted and true boundaries count the same frames.
//!
//! Every row is one (feature provider, options) pair; a provider is a
//! `&dyn Fn(&Input) -> anyhow::Result<Vec<Vec<f64>>>`, so DIFT is one more entry in `providers`.
//! Columns per family: mean and median distance in frames from each true boundary to the nearest
//! predicted one, the share within 5 frames, missed boundaries (nothing predicted), spurious
//! predicted boundaries per clip, and the median time per clip (features + segmentation).

mod common;

use menagerie::diffusion::checkpoint;
use menagerie::dift::DiftOptions;
use menagerie::motion::Motion;
use menagerie::rng::SplitMix64;
use menagerie::segment::input::{dift_features, raw_features, segment_input, window_frames, Input, SegmentInputError};
use menagerie::segment::{boundaries, boundary_errors, SegmentOptions};
use menagerie::skeleton::Skeleton;
use menagerie::synth::creature_names;
use menagerie::synth::{actions, training_clip, Action};
use std::path::Path;
use std::time::{Duration, Instant};

type Provider<'a> = &'a dyn Fn(&Input) -> Result<Vec<Vec<f64>>, SegmentInputError>;

struct Case {
    input: Input,
    truth: Vec<usize>,
}

fn synthetic() -> Vec<Case> {
    let mut out = Vec::new();
    for name in creature_names() {
        if !actions(name).contains(&Action::WalkStopWalk) {
            continue;
        }
        for variant in 0..3u64 {
            for seed in 0..2u64 {
                let frames = 150 + SplitMix64::new(seed ^ variant.rotate_left(9) ^ name.len() as u64).below(151);
                let clip = training_clip(name, variant, Action::WalkStopWalk, seed, frames).expect("listed action");
                let truth = match clip.boundaries.as_slice() {
                    [first, last] => vec![*first, last + 1],
                    _ => continue,
                };
                let input = Input::from_motion(format!("{name}_v{variant}_s{seed}"), clip.skeleton, clip.motion).expect("synthetic clip");
                out.push(Case { input, truth });
            }
        }
    }
    out
}

/// Frames `range` of a corpus file (the whole file when the range runs past its end).
fn read(path: &Path, range: std::ops::Range<usize>) -> Option<(Skeleton, Motion)> {
    let bvh = menagerie::bvh::parse_bytes(&std::fs::read(path).ok()?, &path.display().to_string()).ok()?;
    let skeleton = Skeleton::from_bvh(&bvh);
    let motion = Motion::from_bvh(&bvh, &skeleton);
    let end = range.end.min(motion.frames);
    let start = range.start.min(end.saturating_sub(2));
    Some((skeleton, motion.frame_range(start, end)))
}

/// `b` after `a`, `b`'s root moved (x, z) to continue from `a`'s last frame.
fn concat(a: &Motion, b: &Motion) -> Motion {
    let n = a.joints;
    let last = a.translations[(a.frames - 1) * n];
    let first = b.translations[0];
    let shift = glam::DVec3::new(last.x - first.x, 0.0, last.z - first.z);
    let mut out = a.clone();
    out.frames += b.frames;
    out.rotations.extend_from_slice(&b.rotations);
    out.translations.extend(b.translations.iter().enumerate().map(|(i, &t)| if i % n == 0 { t + shift } else { t }));
    out
}

fn real() -> Vec<Case> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bvh");
    if !dir.is_dir() {
        println!("SKIP real: {} is absent", dir.display());
        return Vec::new();
    }
    // (first file, its frames, second file, its frames): different actions of one skeleton.
    let pairs: &[(&str, std::ops::Range<usize>, &str, std::ops::Range<usize>)] = &[
        ("truebones_anytop/Chicken/Chicken_Walk.bvh", 0..90, "truebones_anytop/Chicken/Chicken_IdlePecking.bvh", 0..150),
        ("truebones_anytop/Chicken/Chicken_IdlePecking.bvh", 0..150, "truebones_anytop/Chicken/Chicken_EggLaying.bvh", 0..150),
        ("truebones_anytop/Chicken/Chicken_EggLaying.bvh", 0..150, "truebones_anytop/Chicken/Chicken_Walk.bvh", 0..90),
        ("bandai_namco/dataset-1/dataset-1_walk_normal_001.bvh", 0..195, "bandai_namco/dataset-1/dataset-1_kick_normal_001.bvh", 0..200),
        ("bandai_namco/dataset-2/dataset-2_walk_normal_001.bvh", 0..200, "bandai_namco/dataset-2/dataset-2_wave-both-hands_normal_001.bvh", 0..200),
        ("lafan1/walk4_subject1.bvh", 600..900, "lafan1/dance1_subject2.bvh", 600..900),
        ("lafan1/push1_subject2.bvh", 600..900, "lafan1/walk4_subject1.bvh", 1200..1500),
        ("lafan1/fallAndGetUp3_subject1.bvh", 300..600, "lafan1/dance1_subject2.bvh", 1500..1800),
        ("xia_dme/neutral_01_000.bvh", 0..327, "xia_dme/old_13_000.bvh", 0..189),
        ("dog_mann/Dog/D1_010_KAN01_002.bvh", 0..155, "dog_mann/Dog/D1_007_KAN01_001.bvh", 0..300),
    ];
    let mut out = Vec::new();
    for (fa, ra, fb, rb) in pairs {
        let (Some((sa, ma)), Some((sb, mb))) = (read(&dir.join(fa), ra.clone()), read(&dir.join(fb), rb.clone())) else {
            println!("SKIP {fa} + {fb}: missing or unreadable");
            continue;
        };
        if let Some(diff) = sa.first_difference(&sb) {
            println!("SKIP {fa} + {fb}: not one skeleton ({diff})");
            continue;
        }
        let short = |f: &str| Path::new(f).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let name = format!("{}+{}", short(fa), short(fb));
        let truth = vec![ma.frames];
        match Input::from_motion(name, sa, concat(&ma, &mb)) {
            Ok(input) => out.push(Case { input, truth }),
            Err(e) => println!("SKIP {fa} + {fb}: {e:#}"),
        }
    }
    out
}

/// Options with the window given in seconds (converted per clip).
#[derive(Clone)]
struct Config {
    label: String,
    options: SegmentOptions,
    window_seconds: f64,
}

fn config(label: &str, k: usize, pca_dims: usize, window_seconds: f64, min_segment: usize, standardise: bool, refine: bool) -> Config {
    let options = SegmentOptions { k, pca_dims, window: 0, min_segment, standardise, refine, ..SegmentOptions::default() };
    Config { label: label.to_string(), options, window_seconds }
}

struct Score {
    errors: Vec<usize>,
    missed: usize,
    spurious: usize,
    clips: usize,
    times: Vec<Duration>,
    failures: usize,
}

fn evaluate(cases: &[Case], provider: Provider, c: &Config, seed: u64, verbose: bool) -> Score {
    let mut s = Score { errors: Vec::new(), missed: 0, spurious: 0, clips: 0, times: Vec::new(), failures: 0 };
    for case in cases {
        let started = Instant::now();
        let options = SegmentOptions { window: window_frames(c.window_seconds, case.input.frame_time), ..c.options.clone() };
        let result = provider(&case.input).and_then(|f| segment_input(&case.input, &f, &options, seed));
        s.times.push(started.elapsed());
        let Ok(result) = result else {
            s.failures += 1;
            continue;
        };
        let predicted = boundaries(&result.labels);
        let e = boundary_errors(&predicted, &case.truth);
        if verbose {
            println!("    {:<40} truth {:?} predicted {:?}", case.input.name, case.truth, predicted);
        }
        s.clips += 1;
        s.spurious += e.spurious;
        for x in e.errors {
            match x {
                Some(d) => s.errors.push(d),
                None => s.missed += 1,
            }
        }
    }
    s
}

fn row(family: &str, provider: &str, c: &Config, s: &Score) {
    let mut e = s.errors.clone();
    e.sort_unstable();
    let mean = if e.is_empty() { f64::NAN } else { e.iter().sum::<usize>() as f64 / e.len() as f64 };
    let median = e.get(e.len() / 2).map_or(f64::NAN, |&m| m as f64);
    let total = e.len() + s.missed;
    let within = if total == 0 { 0.0 } else { 100.0 * e.iter().filter(|&&d| d <= 5).count() as f64 / total as f64 };
    let spurious = s.spurious as f64 / s.clips.max(1) as f64;
    let ms = common::ms(common::median(&s.times));
    println!(
        "{family:<10} {provider:<6} {:<34} {:>5} {:>8.1} {:>8.1} {:>7.0}% {:>6} {:>9.2} {:>8.1}{}",
        c.label,
        s.clips,
        mean,
        median,
        within,
        s.missed,
        spurious,
        ms,
        if s.failures > 0 { format!("  ({} failed)", s.failures) } else { String::new() }
    );
}

fn main() {
    let verbose = std::env::var_os("SEGMENT_VERBOSE").is_some();
    let families = [("synthetic", synthetic()), ("real", real())];
    let model = checkpoint::frozen_default(&candle_core::Device::Cpu).expect("the built-in model");
    let dift = |input: &Input| dift_features(&model, input, &DiftOptions::TEMPORAL);
    // DIFT runs the denoiser per clip: only the main window settings for it.
    let raw = |input: &Input| Ok(raw_features(input));
    let providers: Vec<(&str, Provider, &[usize])> = vec![("raw", &raw, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]), ("dift", &dift, &[0, 1, 4, 6])];
    let configs = vec![
        config("single frames k3 pca8 min10", 3, 8, 0.0, 10, false, true),
        config("window 0.5s k3 pca8 min10", 3, 8, 0.5, 10, false, true),
        config("window 0.5s k3 pca8 min10 norefine", 3, 8, 0.5, 10, false, false),
        config("window 1s k3 pca8 min10 norefine", 3, 8, 1.0, 10, false, false),
        config("window 1s k3 pca8 min10", 3, 8, 1.0, 10, false, true),
        config("window 2s k3 pca8 min10", 3, 8, 2.0, 10, false, true),
        config("window 1s k2 pca8 min10", 2, 8, 1.0, 10, false, true),
        config("window 0.5s k2 pca8 min10", 2, 8, 0.5, 10, false, true),
        config("window 1s k3 pca8 min10 std", 3, 8, 1.0, 10, true, true),
        config("window 1s k3 pca4 min10", 3, 4, 1.0, 10, false, true),
        config("window 1s k3 pca16 min10", 3, 16, 1.0, 10, false, true),
        config("window 1s k3 pca8 min5", 3, 8, 1.0, 5, false, true),
        config("window 1s k3 pca8 min20", 3, 8, 1.0, 20, false, true),
    ];
    println!("segmentation vs known boundaries (frames); seed 0; time = median per clip, features + segmentation");
    println!(
        "{:<10} {:<6} {:<34} {:>5} {:>8} {:>8} {:>8} {:>6} {:>9} {:>8}",
        "family", "feat", "options", "clips", "mean", "median", "<=5fr", "missed", "spur/clip", "ms/clip"
    );
    for (family, cases) in &families {
        if cases.is_empty() {
            continue;
        }
        for (pname, provider, chosen) in &providers {
            for c in chosen.iter().map(|&i| &configs[i]) {
                let s = evaluate(cases, *provider, c, 0, verbose);
                row(family, pname, c, &s);
            }
        }
    }
}
