//! Seeded randomness for everything random in the crate: one generator (splitmix64), seeds for
//! independent streams, and standard normal values. All of it is specified here, so outputs
//! never change because a dependency changed its generator, and none of it depends on the
//! thread count.
//!
//! Two ways to draw normal values are kept because each fixes the bytes of existing outputs:
//! `gaussian` (Box–Muller in f64, one `unit` pair per two values) feeds the diffusion model's
//! training and sampling noise, and `PolarGaussian` (Marsaglia's polar method in f32, one
//! 64-bit draw per attempt) the retargeting's initial noise. They give different streams from
//! the same generator, so merging them would change trained models and retargeted clips.

/// splitmix64: tiny, fast, good enough for jitter and noise.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform integer in `0..n` (0 when `n` is 0), by the multiply-shift method (bias below
    /// 2^-32 for any realistic `n`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() as u128 * n as u128) >> 64) as usize
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// `x` scaled by a random factor in [1 - frac, 1 + frac).
    pub fn vary(&mut self, x: f64, frac: f64) -> f64 {
        x * (1.0 + self.range(-frac, frac))
    }
}

/// The seed of one of many independent streams derived from a run's seed (splitmix64's
/// finaliser over the three numbers, so nearby seeds, streams and indices do not correlate).
pub fn stream_seed(seed: u64, stream: u64, index: u64) -> u64 {
    let mut rng = SplitMix64::new(seed ^ stream.wrapping_mul(0xd1b5_4a32_d192_ed03));
    let a = rng.next_u64();
    SplitMix64::new(a ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15)).next_u64()
}

/// `n` standard normal values from `rng` (Box–Muller in f64), as f32.
pub fn gaussian(rng: &mut SplitMix64, n: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(n + 1);
    while out.len() < n {
        let u1 = rng.unit().max(f64::MIN_POSITIVE);
        let u2 = rng.unit();
        let r = (-2.0 * u1.ln()).sqrt();
        let a = std::f64::consts::TAU * u2;
        out.push((r * a.cos()) as f32);
        out.push((r * a.sin()) as f32);
    }
    out.truncate(n);
    out
}

/// Standard normal values one at a time (Marsaglia's polar method: no trigonometry, both
/// outputs used), in f32 from one 64-bit draw per attempt: the retargeting's noise only needs
/// to be noise, and this is the hot loop of its initialisation on long clips.
pub struct PolarGaussian {
    rng: SplitMix64,
    spare: Option<f32>,
}

impl PolarGaussian {
    pub fn new(seed: u64) -> PolarGaussian {
        // Mix the seed so that seeds 0, 1, 2... start far apart in the splitmix sequence.
        PolarGaussian { rng: SplitMix64::new(seed ^ 0x6d6f_2d72_6574_6172), spare: None }
    }

    pub fn draw(&mut self) -> f32 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        const UNIT: f32 = 1.0 / (1u32 << 24) as f32;
        loop {
            let bits = self.rng.next_u64();
            let u = 2.0 * ((bits >> 40) as f32 * UNIT) - 1.0;
            let v = 2.0 * (((bits >> 16) & 0xff_ffff) as f32 * UNIT) - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let k = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(v * k);
                return u * k;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn moments(xs: &[f64]) -> (f64, f64) {
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        (mean, xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / xs.len() as f64)
    }

    #[test]
    fn polar_standard_normal_moments_and_determinism() {
        let mut g = PolarGaussian::new(3);
        let xs: Vec<f64> = (0..20_000).map(|_| g.draw() as f64).collect();
        let (mean, var) = moments(&xs);
        assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.05, "{mean} {var}");
        assert!(xs.iter().all(|x| x.is_finite()));
        let mut again = PolarGaussian::new(3);
        assert_eq!(again.draw() as f64, xs[0]);
        assert_ne!(PolarGaussian::new(4).draw() as f64, xs[0]);
    }

    #[test]
    fn box_muller_standard_normal_moments_and_determinism() {
        let xs: Vec<f64> = gaussian(&mut SplitMix64::new(3), 20_001).into_iter().map(f64::from).collect();
        let (mean, var) = moments(&xs);
        assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.05, "{mean} {var}");
        // Drawn in pairs: an odd count is the even one's prefix.
        assert_eq!(gaussian(&mut SplitMix64::new(3), 7).as_slice(), &gaussian(&mut SplitMix64::new(3), 8)[..7]);
    }

    /// The two are different streams (see the module doc): this is why both are kept.
    #[test]
    fn the_two_normal_generators_differ() {
        let mut polar = PolarGaussian::new(0);
        let polar: Vec<f32> = (0..4).map(|_| polar.draw()).collect();
        assert_ne!(polar, gaussian(&mut SplitMix64::new(0x6d6f_2d72_6574_6172), 4), "from the same generator state");
    }
}
