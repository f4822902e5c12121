//! GELU (erf form, as the reference's feed-forward) as one fused CPU op with its own backward.
//!
//! Why: candle's `gelu_erf` calls libm's scalar `erff` per element, and its backward is several
//! tensor passes (erf again, an exp, products); in a training step of the small preset that was
//! 12% of the CPU time (perf on `mo-train`). Here erf comes from Abramowitz & Stegun 7.1.26
//! (absolute error < 1.5e-7, below f32 rounding of the result for |x| > 0.5) built on the
//! vectorisable `exp` of the attention kernels, and the backward is one pass.

use super::fused::{exp, f32_slice};
use candle_core::{CpuStorage, CustomOp1, CustomOp2, Layout, Result, Shape, Tensor};

/// `(erf(x / sqrt 2), exp(-x^2 / 2))`: the second is the Gaussian factor of both erf's
/// approximation and GELU's derivative, computed once.
#[inline(always)]
fn erf_and_gauss(x: f32) -> (f32, f32) {
    const P: f32 = 0.327_591_1;
    const A: [f32; 5] = [0.254_829_6, -0.284_496_74, 1.421_413_7, -1.453_152_1, 1.061_405_4];
    let u = x.abs() * std::f32::consts::FRAC_1_SQRT_2;
    let t = 1.0 / (1.0 + P * u);
    let gauss = exp(-u * u);
    let poly = t * (A[0] + t * (A[1] + t * (A[2] + t * (A[3] + t * A[4]))));
    ((1.0 - poly * gauss).copysign(x), gauss)
}

#[inline(always)]
fn value(x: f32) -> f32 {
    0.5 * x * (1.0 + erf_and_gauss(x).0)
}

/// d GELU / dx = (1 + erf(x / sqrt 2)) / 2 + x exp(-x^2 / 2) / sqrt(2 pi).
#[inline(always)]
fn slope(x: f32) -> f32 {
    const INV_SQRT_2PI: f32 = 0.398_942_3;
    let (erf, gauss) = erf_and_gauss(x);
    0.5 * (1.0 + erf) + x * gauss * INV_SQRT_2PI
}

// The loops are plain `for` loops on purpose: a closure inside a `target_feature` function is
// compiled without the feature, and there `round` became a libm call per element (measured:
// the closure version was slower than candle's scalar erf).
#[inline(always)]
fn map_body(x: &[f32]) -> Vec<f32> {
    let mut y = vec![0f32; x.len()];
    for i in 0..x.len() {
        y[i] = value(x[i]);
    }
    y
}

#[inline(always)]
fn chain_body(x: &[f32], dy: &[f32]) -> Vec<f32> {
    let mut g = vec![0f32; x.len()];
    for i in 0..x.len().min(dy.len()) {
        g[i] = dy[i] * slope(x[i]);
    }
    g
}

fn map(x: &[f32]) -> Vec<f32> {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has AVX2 and FMA, the features `map_avx2` is compiled for.
        return unsafe { map_avx2(x) };
    }
    map_body(x)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn map_avx2(x: &[f32]) -> Vec<f32> {
    map_body(x)
}

fn chain(x: &[f32], dy: &[f32]) -> Vec<f32> {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
        // SAFETY: as in `map`.
        return unsafe { chain_avx2(x, dy) };
    }
    chain_body(x, dy)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn chain_avx2(x: &[f32], dy: &[f32]) -> Vec<f32> {
    chain_body(x, dy)
}

struct Gelu;

impl CustomOp1 for Gelu {
    fn name(&self) -> &'static str {
        "fused-gelu"
    }

    fn cpu_fwd(&self, s: &CpuStorage, l: &Layout) -> Result<(CpuStorage, Shape)> {
        Ok((CpuStorage::F32(map(f32_slice(s, l, "gelu input")?)), l.shape().clone()))
    }

    fn bwd(&self, x: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<Option<Tensor>> {
        Ok(Some(x.apply_op2_no_bwd(&grad.contiguous()?, &GeluBackward)?))
    }
}

/// `dy * GELU'(x)`; first-order only (nothing here needs the second derivative).
struct GeluBackward;

impl CustomOp2 for GeluBackward {
    fn name(&self) -> &'static str {
        "fused-gelu-backward"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout, s2: &CpuStorage, l2: &Layout) -> Result<(CpuStorage, Shape)> {
        let (x, dy) = (f32_slice(s1, l1, "gelu input")?, f32_slice(s2, l2, "gelu output gradient")?);
        if x.len() != dy.len() {
            candle_core::bail!("fused gelu: {} inputs but {} output gradients", x.len(), dy.len());
        }
        Ok((CpuStorage::F32(chain(x, dy)), l1.shape().clone()))
    }
}

/// `x/2 (1 + erf(x / sqrt 2))` element-wise on an f32 tensor, with gradient.
pub fn gelu(x: &Tensor) -> Result<Tensor> {
    x.contiguous()?.apply_op1(Gelu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Var};

    #[test]
    fn matches_candles_exact_erf_gelu_in_value_and_gradient() {
        let xs: Vec<f32> = (-4000..=4000).map(|i| i as f32 * 0.0025).chain([-30.0, 30.0, 1e-8, -1e-8]).collect();
        let x = Var::from_vec(xs.clone(), xs.len(), &Device::Cpu).unwrap();
        let (ours, exact) = (gelu(x.as_tensor()).unwrap(), x.as_tensor().gelu_erf().unwrap());
        let (a, b) = (ours.to_vec1::<f32>().unwrap(), exact.to_vec1::<f32>().unwrap());
        let worst = a.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0f32, f32::max);
        assert!(worst < 1e-6, "value differs by {worst}");
        // Weighted sums so every element's gradient is checked.
        let w = Tensor::from_vec((0..xs.len()).map(|i| 1.0 + (i % 7) as f32).collect::<Vec<_>>(), xs.len(), &Device::Cpu).unwrap();
        let ga = (ours * &w).unwrap().sum_all().unwrap().backward().unwrap();
        let gb = (exact * &w).unwrap().sum_all().unwrap().backward().unwrap();
        let (ga, gb) = (ga.get(x.as_tensor()).unwrap().to_vec1::<f32>().unwrap(), gb.get(x.as_tensor()).unwrap().to_vec1::<f32>().unwrap());
        let worst = ga.iter().zip(&gb).map(|(p, q)| (p - q).abs()).fold(0f32, f32::max);
        assert!(worst < 1e-5, "gradient differs by {worst}");
        assert!(gb.iter().any(|&g| g > 1.0), "the gradient check covers the slope's overshoot above 1");
    }

    #[test]
    fn strided_input_and_nan() {
        let x = Tensor::from_vec(vec![1f32, 2.0, 3.0, f32::NAN], (2, 2), &Device::Cpu).unwrap();
        let y = gelu(&x.t().unwrap()).unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
        let expect = [value(1.0), value(3.0), value(2.0)];
        assert_eq!(&y[..3], &expect);
        assert!(y[3].is_nan(), "NaN in, NaN out");
    }
}
