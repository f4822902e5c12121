//! AnyTop's diffusion process as numbers: the cosine noise schedule (T = 100), the forward
//! (noising) coefficients, and the per-step coefficients of the samplers — ancestral DDPM on
//! all steps, as the reference samples (`docs/reference/anytop.md` §3.1–3.2), and the fast ones: a
//! respaced DDPM and DDIM on a subset of steps.
//!
//! Everything here is plain f64 scalars so that it can be tested exactly and shared by the
//! trainer (which only needs ᾱ_t) and every sampler. The model predicts x0 (START_X), so each
//! sampler step is: x̂0 from the model, then x_{t'} from (x̂0, x_t) with the coefficients of
//! the step [`Step`].

/// ᾱ(s) of the cosine schedule, s in [0, 1] (Nichol & Dhariwal; offset 0.008).
fn cosine_alpha_bar(s: f64) -> f64 {
    let x = (s + 0.008) / 1.008 * std::f64::consts::FRAC_PI_2;
    x.cos().powi(2)
}

/// The signal-to-noise ratio ᾱ / (1 − ᾱ) of a step with ᾱ = `alpha_bar` (infinite at ᾱ = 1).
pub fn signal_to_noise(alpha_bar: f64) -> f64 {
    alpha_bar / (1.0 - alpha_bar)
}

/// The noise schedule of T steps: β_t and ᾱ_t for t = 0..T-1.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    pub betas: Vec<f64>,
    /// ᾱ_t = Π_{i ≤ t} (1 − β_i).
    pub alpha_bars: Vec<f64>,
}

impl Schedule {
    /// The cosine schedule of `steps` steps (AnyTop: 100): β_i = min(1 − ᾱ((i+1)/T)/ᾱ(i/T), 0.999).
    pub fn cosine(steps: usize) -> Schedule {
        let t = steps.max(1) as f64;
        let betas: Vec<f64> = (0..steps.max(1)).map(|i| (1.0 - cosine_alpha_bar((i + 1) as f64 / t) / cosine_alpha_bar(i as f64 / t)).min(0.999)).collect();
        Schedule::from_betas(betas)
    }

    /// The cosine schedule with its signal-to-noise ratio divided by `shift`² at every step
    /// (log-SNR moved down by 2·ln `shift`; 1 = the plain cosine schedule). Why: a motion crop's
    /// features are strongly correlated over frames and joints, so along its slow directions
    /// (the pose held over a crop, a gait's phase) the variance is hundreds of times a single
    /// feature's. At the cosine schedule's late steps those directions still show through the
    /// noise, so the whole choice of *which* motion falls into the first sampling step, where
    /// the model can only predict the mean pose: samples stand still. Shifting the schedule
    /// (as for high-resolution images, Hoogeboom et al. 2023) spreads that choice over many steps.
    pub fn cosine_shifted(steps: usize, shift: f64) -> Schedule {
        Schedule::cosine_moved(steps, shift, false)
    }

    /// `cosine_shifted` with the shift tapered: the log-SNR moves down by 2·ln `shift` ×
    /// (t + 1) / T at step t, so the last steps are shifted in full and the first nearly not.
    /// Why: under the full shift 10 even step 0 keeps noise of 0.24 times the signal's scale
    /// (0.025 unshifted), so the model never learns to denoise finer than that, and its
    /// final x0 is a posterior mean that smooths the motion: a probe of a 3-skeleton proxy
    /// (`examples/denoise_probe.rs`) kept 0.81 of a crop's smoothed motion at step 2. Tapered,
    /// step 0 keeps 0.026 and steps 40 and above are at 0.89 or more.
    ///
    /// Measured, it fixes the fine denoising but not the samples: a 1-skeleton proxy
    /// (quadruped_v0, tiny, 8,000 steps) then keeps 0.99 of the smoothed motion at step 2
    /// (0.89 untapered), yet its samples are worse (calibrated coverage 21% against 42%,
    /// alternation 0.53 against 0.73, skating 0.56 against 0.22 /s). So it is not the default.
    pub fn cosine_tapered(steps: usize, shift: f64) -> Schedule {
        Schedule::cosine_moved(steps, shift, true)
    }

    fn cosine_moved(steps: usize, shift: f64, tapered: bool) -> Schedule {
        let plain = Schedule::cosine(steps);
        if shift == 1.0 {
            return plain;
        }
        let full = 2.0 * shift.ln();
        let count = plain.alpha_bars.len() as f64;
        let shifted: Vec<f64> = plain
            .alpha_bars
            .iter()
            .enumerate()
            .map(|(t, &ab)| {
                let offset = if tapered { full * (t + 1) as f64 / count } else { full };
                let log_snr = signal_to_noise(ab).ln() - offset;
                1.0 / (1.0 + (-log_snr).exp())
            })
            .collect();
        let mut betas = Vec::with_capacity(shifted.len());
        let mut previous = 1.0;
        for &ab in &shifted {
            betas.push((1.0 - ab / previous).clamp(0.0, 0.999));
            previous = ab;
        }
        Schedule::from_betas(betas)
    }

    fn from_betas(betas: Vec<f64>) -> Schedule {
        let mut alpha_bars = Vec::with_capacity(betas.len());
        let mut acc = 1.0;
        for b in &betas {
            acc *= 1.0 - b;
            alpha_bars.push(acc);
        }
        Schedule { betas, alpha_bars }
    }

    pub fn len(&self) -> usize {
        self.betas.len()
    }

    pub fn is_empty(&self) -> bool {
        self.betas.is_empty()
    }

    /// Forward process at step t: x_t = a·x0 + b·ε with (a, b) = (√ᾱ_t, √(1 − ᾱ_t)).
    pub fn noise_coefficients(&self, t: usize) -> (f64, f64) {
        let ab = self.alpha_bars[t];
        (ab.sqrt(), (1.0 - ab).sqrt())
    }

    /// The steps a sampler visits, from noisiest to cleanest: all T for the reference's
    /// sampler, else `count` steps evenly spaced over 0..T-1 (always including T-1 and 0).
    pub fn timesteps(&self, count: usize) -> Vec<usize> {
        let t = self.len();
        let count = count.clamp(1, t);
        if count == t {
            return (0..t).rev().collect();
        }
        if count == 1 {
            return vec![t - 1];
        }
        let mut out: Vec<usize> = (0..count).map(|i| ((t - 1) as f64 * i as f64 / (count - 1) as f64).round() as usize).collect();
        out.dedup();
        out.reverse();
        out
    }

    /// The coefficients of every step of a sampler that visits `timesteps` (as from
    /// [`Schedule::timesteps`]).
    pub fn steps(&self, timesteps: &[usize], sampler: Sampler) -> Vec<Step> {
        timesteps
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                let ab = self.alpha_bars[t];
                // ᾱ of the step we land on; after the last step (t = 0 or the smallest visited
                // step) the result is x0 itself.
                let ab_prev = timesteps.get(i + 1).map_or(1.0, |&p| self.alpha_bars[p]);
                match sampler {
                    Sampler::Ddpm => {
                        // The respaced process has β = 1 − ᾱ_t / ᾱ_prev (the plain one when all
                        // steps are visited); its posterior q(x_prev | x_t, x0).
                        let beta = 1.0 - ab / ab_prev;
                        let alpha = 1.0 - beta;
                        let denom = 1.0 - ab;
                        let x0 = beta * ab_prev.sqrt() / denom;
                        let xt = (1.0 - ab_prev) * alpha.sqrt() / denom;
                        let variance = beta * (1.0 - ab_prev) / denom;
                        Step { t, x0, xt, sigma: variance.max(0.0).sqrt() }
                    }
                    Sampler::Ddim => {
                        // η = 0: x_prev = √ᾱ_prev·x̂0 + √(1 − ᾱ_prev)·ε̂, ε̂ = (x_t − √ᾱ_t·x̂0)/√(1 − ᾱ_t).
                        let k = ((1.0 - ab_prev) / (1.0 - ab)).sqrt();
                        Step { t, x0: ab_prev.sqrt() - k * ab.sqrt(), xt: k, sigma: 0.0 }
                    }
                }
            })
            .collect()
    }
}

/// How a sampler goes from x_t to the next, less noisy step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Sampler {
    /// Ancestral DDPM (the reference's, on all steps; respaced on fewer).
    Ddpm,
    /// Deterministic DDIM (η = 0).
    Ddim,
}

/// One sampler step: x_next = x0·x̂0 + xt·x_t + sigma·z, z ~ N(0, I) (no noise on the last step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// The diffusion step the model is told.
    pub t: usize,
    pub x0: f64,
    pub xt: f64,
    pub sigma: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_schedule_matches_its_definition() {
        let s = Schedule::cosine(100);
        assert_eq!(s.len(), 100);
        // β_0 from the formula, and ᾱ decreasing to almost 0 with β capped at 0.999.
        let b0 = 1.0 - cosine_alpha_bar(0.01) / cosine_alpha_bar(0.0);
        assert!((s.betas[0] - b0).abs() < 1e-15);
        assert!(s.alpha_bars.windows(2).all(|w| w[1] < w[0]));
        assert_eq!(s.betas[99], 0.999);
        assert!(s.alpha_bars[99] < 1e-4 && s.alpha_bars[0] > 0.999);
        let (a, b) = s.noise_coefficients(50);
        assert!((a * a + b * b - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_shift_divides_every_steps_signal_to_noise_ratio() {
        let plain = Schedule::cosine(100);
        assert_eq!(Schedule::cosine_shifted(100, 1.0), plain);
        let shifted = Schedule::cosine_shifted(100, 4.0);
        assert_eq!(shifted.len(), 100);
        for t in 0..99 {
            let (p, s) = (plain.alpha_bars[t], shifted.alpha_bars[t]);
            assert!((signal_to_noise(s) * 16.0 / signal_to_noise(p) - 1.0).abs() < 1e-6, "t = {t}: {s} against {p}");
            assert!(shifted.alpha_bars[t + 1] < s, "ᾱ falls at t = {t}");
        }
    }

    /// Tapered, the ratio is divided by shift^(2(t+1)/T): nearly nothing at step 0, in full at
    /// the last step; the noise still rises step by step.
    #[test]
    fn a_tapered_shift_grows_from_nothing_to_the_full_shift() {
        let plain = Schedule::cosine(100);
        assert_eq!(Schedule::cosine_tapered(100, 1.0), plain);
        let tapered = Schedule::cosine_tapered(100, 10.0);
        // Not the last step, where β's clamp at 0.999 decides ᾱ (as in the whole shift's test).
        for t in 0..99 {
            let (p, s) = (plain.alpha_bars[t], tapered.alpha_bars[t]);
            let divided = 10f64.powf(2.0 * (t + 1) as f64 / 100.0);
            assert!((signal_to_noise(s) * divided / signal_to_noise(p) - 1.0).abs() < 1e-6, "t = {t}: {s} against {p}");
            assert!(tapered.alpha_bars[t + 1] < s, "ᾱ falls at t = {t}");
        }
        // Step 0's noise stays near the plain schedule's, far below the full shift's.
        let noise = |s: &Schedule| s.noise_coefficients(0).1;
        assert!(noise(&tapered) < 1.1 * noise(&plain) && noise(&Schedule::cosine_shifted(100, 10.0)) > 5.0 * noise(&tapered));
    }

    #[test]
    fn all_steps_ddpm_is_the_plain_posterior() {
        let s = Schedule::cosine(100);
        let ts = s.timesteps(100);
        assert_eq!(ts.first(), Some(&99));
        assert_eq!(ts.last(), Some(&0));
        let steps = s.steps(&ts, Sampler::Ddpm);
        // At step t (> 0) the respaced β equals the schedule's β_t.
        for st in &steps[..99] {
            let t = st.t;
            let (beta, ab, abp) = (s.betas[t], s.alpha_bars[t], s.alpha_bars[t - 1]);
            assert!((st.x0 - beta * abp.sqrt() / (1.0 - ab)).abs() < 1e-12, "t {t}");
            assert!((st.xt - (1.0 - abp) * (1.0 - beta).sqrt() / (1.0 - ab)).abs() < 1e-12, "t {t}");
        }
        // The last step lands on x0 exactly: coefficient 1 on x̂0, nothing else.
        let last = steps.last().unwrap();
        assert!((last.x0 - 1.0).abs() < 1e-12 && last.xt.abs() < 1e-12 && last.sigma.abs() < 1e-12);
    }

    #[test]
    fn a_perfect_denoiser_recovers_x0_with_any_sampler() {
        // With x̂0 = x0 exact and no noise, both samplers must end at x0 from any start.
        let s = Schedule::cosine(100);
        for (count, sampler) in [(100, Sampler::Ddpm), (10, Sampler::Ddpm), (10, Sampler::Ddim), (3, Sampler::Ddim)] {
            let ts = s.timesteps(count);
            assert!(ts.len() <= count && ts[0] == 99 && *ts.last().unwrap() == 0);
            let (x0, mut x) = (0.7, -2.0);
            for st in s.steps(&ts, sampler) {
                x = st.x0 * x0 + st.xt * x;
            }
            assert!((x - x0).abs() < 1e-9, "{count} {sampler:?}: {x}");
        }
        // DDIM keeps a consistent x_t: from x_t = √ᾱ x0 + √(1−ᾱ) ε it lands on the same ε's x_prev.
        let ts = s.timesteps(5);
        let steps = s.steps(&ts, Sampler::Ddim);
        let (x0, eps) = (0.3, 1.1);
        let (a, b) = s.noise_coefficients(ts[0]);
        let next = steps[0].x0 * x0 + steps[0].xt * (a * x0 + b * eps);
        let (a1, b1) = s.noise_coefficients(ts[1]);
        assert!((next - (a1 * x0 + b1 * eps)).abs() < 1e-12);
    }
}
