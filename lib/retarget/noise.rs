//! Seeded Gaussian noise for the initial synthesis. The generator is the project's own
//! splitmix64 (`synth::SplitMix64`), so outputs never change because a dependency did; values
//! are drawn from streams derived from the seed and the frame (`stream_seed`), so they do not
//! depend on the thread count.

use crate::synth::SplitMix64;

/// The seed of one of many independent streams derived from a run's seed (splitmix64's
/// finaliser over the three numbers, so nearby seeds, streams and frames do not correlate).
pub(crate) fn stream_seed(seed: u64, stream: u64, index: u64) -> u64 {
    let mut rng = SplitMix64::new(seed ^ stream.wrapping_mul(0xd1b5_4a32_d192_ed03));
    let a = rng.next_u64();
    SplitMix64::new(a ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15)).next_u64()
}

pub(crate) struct Gaussian {
    rng: SplitMix64,
    spare: Option<f32>,
}

impl Gaussian {
    pub fn new(seed: u64) -> Gaussian {
        // Mix the seed so that seeds 0, 1, 2... start far apart in the splitmix sequence.
        Gaussian { rng: SplitMix64::new(seed ^ 0x6d6f_2d72_6574_6172), spare: None }
    }

    /// A standard normal value (Marsaglia's polar method: no trigonometry, both outputs used),
    /// in f32 from one 64-bit draw per attempt: the noise only needs to be noise, and this is
    /// the hot loop of the initialisation on long clips.
    pub fn next(&mut self) -> f32 {
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

    #[test]
    fn standard_normal_moments_and_determinism() {
        let mut g = Gaussian::new(3);
        let xs: Vec<f64> = (0..20_000).map(|_| g.next() as f64).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / xs.len() as f64;
        assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.05, "{mean} {var}");
        assert!(xs.iter().all(|x| x.is_finite()));
        let mut again = Gaussian::new(3);
        assert_eq!(again.next() as f64, xs[0]);
        assert_ne!(Gaussian::new(4).next() as f64, xs[0]);
    }
}
