//! Sampling motion for a skeleton from a trained denoiser: start from Gaussian noise, and at
//! every visited step predict x0 and move to the next step with the sampler's coefficients
//! (`schedule::Step`). The rest-pose token stays the skeleton's P_S throughout.

use super::schedule::{Sampler, Schedule};
use super::DiffusionError;
use crate::nn::{batch_from, BatchItem, Denoiser};
use crate::repr::anytop::{lock_feet, plant_feet, AnyTopStats};
use crate::repr::smooth::{lambda_for_cutoff, smooth_features};
use crate::repr::Features;
use crate::rng::gaussian;
use crate::rng::SplitMix64;
use candle_core::Device;

/// What the model is told about the skeleton to animate (all normalised like training data).
pub struct Condition<'a> {
    pub rest_row: &'a [f32],
    pub relations: &'a [Vec<u8>],
    pub distances: &'a [Vec<u8>],
    pub names: &'a [Vec<f32>],
    pub stats: &'a AnyTopStats,
}

/// Planted feet held in place inside the sampler: at each of the last steps (`LOCK_BELOW_STEP`)
/// the predicted motion gets `plant_feet` (the root's travel from the feet that are down) and
/// `lock_feet` (each of those feet held where it landed, its leg bent to reach), and the
/// sampler goes on from there, so the remaining steps fit the rest of the body to the held feet.
///
/// Why inside and not after: the model's legs and root disagree, so its planted feet slide
/// (issue 22: 91% of the built-in's near-ground foot steps had the contact channel on and slid
/// at 0.32 sizes/s). Locking the finished sample holds them but bends the legs away from the
/// model's poses (the running dog's nearest pose 0.0137 -> 0.0158); locking inside the last
/// three DDIM steps gives the same skating with poses within 0.0005 of the model's own, at a
/// cost in motion (models/zoo-compact/MODEL_CARD.md, "Feet held inside the sampler"), so
/// `mo-sample` does it only when asked (`--lock-feet`).
#[derive(Clone, Debug)]
pub struct FootLock {
    pub feet: Vec<usize>,
    pub parents: Vec<Option<usize>>,
    /// A foot is held only this near the ground (scaled units).
    pub near_ground: f64,
    /// Frames a held foot takes to settle into its place and to leave it.
    pub ease: usize,
    /// Cells (`[frame * joints + joint]`) that stay as they are: an edit's kept part.
    pub fixed: Option<Vec<bool>>,
}

/// The sampler steps (of the schedule's 100) at and below which feet are held: DDIM's last
/// three at the default 10 steps (22, 11, 0). From noisier predictions the feet are not yet
/// where the motion will put them, and holding them there costs motion (the built-in model's
/// quadruped at seed 7: energy ratio 0.76 holding in three steps, 0.68 in five).
pub const LOCK_BELOW_STEP: usize = 22;

/// How long a held foot takes to settle into its place and to leave it.
pub const LOCK_EASE_SECONDS: f64 = 0.1;

/// How near the ground a foot must be to be held, as a fraction of the skeleton's size: the
/// contact band of `mo-metrics physics`, whose foot skating this brings down.
pub const LOCK_NEAR_GROUND: f64 = 0.05;

impl FootLock {
    /// `size` is the skeleton's rest extent in scaled units (`Skeleton::rest_extent` × the rig's
    /// scale factor).
    pub fn new(feet: Vec<usize>, parents: Vec<Option<usize>>, size: f64, fps: f64, fixed: Option<Vec<bool>>) -> FootLock {
        let ease = ((LOCK_EASE_SECONDS * fps).round() as usize).max(1);
        FootLock { feet, parents, near_ground: LOCK_NEAR_GROUND * size, ease, fixed }
    }

    /// Plant, then lock, one motion in physical units. Returns how many (foot, frame) pairs moved.
    pub fn apply(&self, f: &mut Features) -> usize {
        plant_feet(f, &self.feet, self.fixed.as_deref());
        lock_feet(f, &self.parents, &self.feet, self.near_ground, self.ease, self.fixed.as_deref())
    }
}

/// How to sample.
#[derive(Clone, Debug)]
pub struct SampleOptions {
    pub samples: usize,
    pub frames: usize,
    /// Visited diffusion steps (the schedule's length = the reference's full ancestral loop).
    pub steps: usize,
    pub sampler: Sampler,
    pub seed: u64,
    /// Hold planted feet in the last steps (`FootLock`); none: the model's motion as it is.
    pub lock: Option<FootLock>,
}

/// `samples` motions, denormalised AnyTop features `[frames, joints, 13]` each.
pub fn sample(model: &Denoiser, schedule: &Schedule, cond: &Condition, opts: &SampleOptions, device: &Device) -> Result<Vec<Features>, DiffusionError> {
    let mut x = denoise(model, schedule, cond, opts, None, device)?;
    for f in &mut x {
        cond.stats.denormalise(f).map_err(|source| DiffusionError::Stats { what: "denormalising the samples", source })?;
    }
    Ok(x)
}

/// A known part of the motion, imposed at every step (`edit.rs`): normalised reference values
/// for the whole `[frames, joints, 13]` block, and which elements are known.
pub(super) struct Imposed<'a> {
    pub reference: &'a [f32],
    /// Per element of the block (all 13 features of a kept joint-frame are kept).
    pub known: &'a [bool],
    /// Seeds the noise the known part is diffused with, a stream apart from the sampler's own
    /// so that nothing known leaves the generated part's noise as plain sampling draws it.
    pub seed: u64,
}

/// The sampling loop, in normalised units. With a known part, the model's input x_t carries
/// the reference noised to step t (q_sample) at the known elements, and its x0 prediction is
/// overridden there by the reference (AnyTop paper §5; the upstream passes zeros as the reference,
/// docs/reference/anytop.md §5), so the generated part is denoised next to the motion it has to
/// join.
pub(super) fn denoise(
    model: &Denoiser,
    schedule: &Schedule,
    cond: &Condition,
    opts: &SampleOptions,
    imposed: Option<&Imposed>,
    device: &Device,
) -> Result<Vec<Features>, DiffusionError> {
    let joints = cond.names.len();
    let dims = model.config().feature_dims;
    let per = opts.frames * joints * dims;
    if let Some(k) = imposed {
        if k.reference.len() != per || k.known.len() != per {
            return Err(DiffusionError::Invalid(format!(
                "the known motion has {} values and {} flags; sampling {} frames x {joints} joints x {dims} needs {per}",
                k.reference.len(),
                k.known.len(),
                opts.frames
            )));
        }
    }
    let mut rng = SplitMix64::new(opts.seed);
    let mut known_rng = imposed.map(|k| SplitMix64::new(k.seed));
    let known_count = imposed.map_or(0, |k| k.known.iter().filter(|&&b| b).count());
    let mut x: Vec<Features> = (0..opts.samples).map(|_| Features { frames: opts.frames, joints, dims, data: gaussian(&mut rng, per) }).collect();
    let timesteps = schedule.timesteps(opts.steps);
    for step in schedule.steps(&timesteps, opts.sampler) {
        if let (Some(k), Some(krng)) = (imposed, known_rng.as_mut()) {
            let (a, b) = schedule.noise_coefficients(step.t);
            for f in x.iter_mut() {
                let eps = gaussian(krng, known_count);
                let mut e = eps.iter();
                for ((v, &r), _) in f.data.iter_mut().zip(k.reference).zip(k.known).filter(|(_, kn)| **kn) {
                    *v = (a * r as f64 + b * e.next().copied().unwrap_or(0.0) as f64) as f32;
                }
            }
        }
        let items: Vec<BatchItem> = x
            .iter()
            .map(|f| BatchItem { features: f, rest_row: cond.rest_row, relations: cond.relations, distances: cond.distances, names: cond.names, start: 0 })
            .collect();
        let batch = batch_from(&items, &vec![step.t as u32; items.len()], device)?;
        let predicted = model.forward(&batch)?;
        let t = opts.frames + 1;
        let mut x0: Vec<f32> = predicted.narrow(1, 1, t - 1)?.contiguous()?.flatten_all()?.to_vec1()?;
        if let Some(k) = imposed {
            for chunk in x0.chunks_exact_mut(per.max(1)) {
                for ((v, &r), _) in chunk.iter_mut().zip(k.reference).zip(k.known).filter(|(_, kn)| **kn) {
                    *v = r;
                }
            }
        }
        if let Some(lock) = opts.lock.as_ref().filter(|_| step.t <= LOCK_BELOW_STEP) {
            for chunk in x0.chunks_exact_mut(per.max(1)) {
                let mut f = Features { frames: opts.frames, joints, dims, data: chunk.to_vec() };
                cond.stats.denormalise(&mut f).map_err(|source| DiffusionError::Stats { what: "denormalising to hold the feet", source })?;
                lock.apply(&mut f);
                cond.stats.normalise(&mut f).map_err(|source| DiffusionError::Stats { what: "normalising the held feet", source })?;
                chunk.copy_from_slice(&f.data);
            }
        }
        for (i, f) in x.iter_mut().enumerate() {
            let noise = if step.sigma > 0.0 { gaussian(&mut rng, per) } else { Vec::new() };
            for k in 0..per {
                let z = noise.get(k).copied().unwrap_or(0.0) as f64;
                f.data[k] = (step.x0 * x0[i * per + k] as f64 + step.xt * f.data[k] as f64 + step.sigma * z) as f32;
            }
        }
    }
    // The last step lands on x̂0, which carries the reference; set it again so that no sampler
    // coefficient's rounding can leave a known value off.
    if let Some(k) = imposed {
        for f in x.iter_mut() {
            for ((v, &r), _) in f.data.iter_mut().zip(k.reference).zip(k.known).filter(|(_, kn)| **kn) {
                *v = r;
            }
        }
    }
    Ok(x)
}

/// The default `--smooth`: 7 Hz, the lowest whole cutoff at which the post-process keeps real
/// motion: on the bundled creatures and real clips (dog, chicken, flamingo, monkey, crab, a
/// LAFAN1 walk) it changes motion energy by at most 7% (the wing beats of the bird; 4 Hz took
/// 28% off them and 9% off the dog), `tests/it/post_process.rs`. What it leaves of the model's
/// jitter is the model's to fix (models/zoo-small/MODEL_CARD.md).
pub const DEFAULT_SMOOTH_HZ: f64 = 7.0;

/// The default `--blend`: half a second (15 frames at 30 fps), the order of a step.
pub const DEFAULT_BLEND_SECONDS: f64 = 0.5;

/// What is done to sampled features before they are decoded: the model's frame-to-frame jitter
/// smoothed away, and the root's travel taken from the planted feet so that they do not slide.
/// `Default` is the raw output.
#[derive(Clone, Copy, Debug, Default)]
pub struct PostProcess {
    /// The smoother's weight (`repr::smooth::lambda_for_cutoff` of a cutoff in Hz); none for
    /// no smoothing.
    pub smooth: Option<f64>,
    /// Frames over which generated motion gives way to fixed cells (editing; see
    /// `repr::smooth`).
    pub blend: usize,
    pub plant_feet: bool,
}

impl PostProcess {
    /// The post-process of motion at `fps` asked for in physical units: a smoothing cutoff in
    /// Hz (`smooth_hz`, 0 = none; below half the frame rate), and a blend of `blend_seconds`
    /// (at most `max_seconds`).
    pub fn new(smooth_hz: f64, blend_seconds: f64, plant_feet: bool, fps: f64, max_seconds: f64) -> Result<PostProcess, DiffusionError> {
        let smooth = match smooth_hz {
            0.0 => None,
            hz if !hz.is_finite() || hz < 0.0 => {
                return Err(DiffusionError::Invalid(format!("--smooth must be a cutoff in Hz (>= 0; 0 = no smoothing), found {hz}")));
            }
            hz => Some(lambda_for_cutoff(hz, fps).ok_or_else(|| {
                DiffusionError::Invalid(format!(
                    "--smooth {hz}: the cutoff must be below half the frame rate ({:.1} Hz at {fps:.1} fps); 0 = no smoothing",
                    fps / 2.0
                ))
            })?),
        };
        if !(blend_seconds.is_finite() && blend_seconds >= 0.0 && blend_seconds <= max_seconds) {
            return Err(DiffusionError::Invalid(format!("--blend must be a duration in seconds (>= 0), found {blend_seconds}")));
        }
        Ok(PostProcess { smooth, blend: (blend_seconds * fps).round() as usize, plant_feet })
    }

    /// Apply to one sample. `feet` are the rig's foot joints; `fixed` cells
    /// (`[frame * joints + joint]`, an edit's kept part) keep their values.
    pub fn apply(&self, f: &mut Features, feet: &[usize], fixed: Option<&[bool]>) {
        if let Some(lambda) = self.smooth {
            smooth_features(f, lambda, fixed, self.blend);
        }
        if self.plant_feet {
            plant_feet(f, feet, fixed);
            if let Some(lambda) = self.smooth {
                // Planting switches the root's velocity where feet land and lift: smooth the
                // root again (its cells only), so that no jump is left where the set changes.
                let joints = f.joints;
                let others: Vec<bool> = (0..f.frames * joints).map(|k| k % joints != 0 || fixed.is_some_and(|m| m[k])).collect();
                smooth_features(f, lambda, Some(&others), self.blend);
            }
        }
    }
}
