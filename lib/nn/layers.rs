//! Building blocks made only of basic differentiable tensor ops.
//!
//! Why not `candle_nn::{LayerNorm, ops::softmax_last_dim, ops::sdpa}`: their fused CPU kernels
//! are custom ops without a backward pass, so training through them silently leaves earlier
//! parameters without gradients. Everything here is matmuls, broadcasts, `exp`, sums and means,
//! which candle's autograd differentiates; `nn::anytop`'s gradient test checks every parameter.

use candle_core::{DType, Result, Tensor, D};
use candle_nn::{Init, VarBuilder};

/// `y = x W^T + b` over the last dimension, for inputs of any rank (flattened to one GEMM).
#[derive(Clone, Debug)]
pub struct Linear {
    weight: Tensor,
    bias: Tensor,
}

impl Linear {
    /// PyTorch's default init (uniform in ±1/sqrt(fan_in) for weight and bias), which the
    /// reference model was trained with.
    pub fn new(vb: VarBuilder, inputs: usize, outputs: usize) -> Result<Linear> {
        let bound = 1.0 / (inputs.max(1) as f64).sqrt();
        let init = Init::Uniform { lo: -bound, up: bound };
        let weight = vb.get_with_hints((outputs, inputs), "weight", init)?;
        let bias = vb.get_with_hints(outputs, "bias", init)?;
        Ok(Linear { weight, bias })
    }

    /// Weight and bias initialised to zero: a new path added to a trained model starts
    /// silent, so the model begins where it was.
    pub fn zeros(vb: VarBuilder, inputs: usize, outputs: usize) -> Result<Linear> {
        let weight = vb.get_with_hints((outputs, inputs), "weight", Init::Const(0.0))?;
        let bias = vb.get_with_hints(outputs, "bias", Init::Const(0.0))?;
        Ok(Linear { weight, bias })
    }

    pub fn weight(&self) -> &Tensor {
        &self.weight
    }

    pub fn bias(&self) -> &Tensor {
        &self.bias
    }

    pub fn forward(&self, x: &Tensor) -> Result<Tensor> {
        super::fused::linear(x, &self.weight, &self.bias, None)
    }

    /// `forward`, the result shaped `shape` (same values, no reshape node in the graph).
    pub fn forward_shaped(&self, x: &Tensor, shape: impl Into<candle_core::Shape>) -> Result<Tensor> {
        super::fused::linear(x, &self.weight, &self.bias, Some(shape.into()))
    }
}

/// Layer norm over the last dimension with learned scale and shift (eps 1e-5 as PyTorch).
#[derive(Clone, Debug)]
pub struct LayerNorm {
    weight: Tensor,
    bias: Tensor,
    eps: f64,
}

impl LayerNorm {
    pub fn new(vb: VarBuilder, width: usize, eps: f64) -> Result<LayerNorm> {
        let weight = vb.get_with_hints(width, "weight", Init::Const(1.0))?;
        let bias = vb.get_with_hints(width, "bias", Init::Const(0.0))?;
        Ok(LayerNorm { weight, bias, eps })
    }

    /// One fused pass forward and one backward (`fused::layer_norm`); the test below checks it
    /// against the textbook composition.
    pub fn forward(&self, x: &Tensor) -> Result<Tensor> {
        super::fused::layer_norm(x, &self.weight, &self.bias, self.eps)
    }
}

/// Softmax over the last dimension: `exp(x - max) / sum`. The max is detached: the result does
/// not depend on the shift, so no gradient has to flow through it.
pub fn softmax(x: &Tensor) -> Result<Tensor> {
    let max = x.max_keepdim(D::Minus1)?.detach();
    let e = x.broadcast_sub(&max)?.exp()?;
    let sum = e.sum_keepdim(D::Minus1)?;
    e.broadcast_div(&sum)
}

/// The feed-forward block: `Linear(d -> ff) -> GELU (erf form, as the reference) -> Linear(ff -> d)`.
#[derive(Clone, Debug)]
pub struct FeedForward {
    up: Linear,
    down: Linear,
}

impl FeedForward {
    pub fn new(vb: VarBuilder, width: usize, hidden: usize) -> Result<FeedForward> {
        Ok(FeedForward { up: Linear::new(vb.pp("up"), width, hidden)?, down: Linear::new(vb.pp("down"), hidden, width)? })
    }

    pub fn forward(&self, x: &Tensor) -> Result<Tensor> {
        self.down.forward(&super::gelu::gelu(&self.up.forward(x)?)?)
    }
}

/// Sinusoidal embedding of positions (or diffusion steps) as the reference computes it
/// (docs/reference/anytop.md §2.2): half = width/2, phi_i = p / 10000^(i/(half-1)),
/// output `[cos phi, sin phi]` (cos block first). `positions` is f32 of any shape `S`; the
/// result is `S x width`. Odd widths get one trailing zero column.
pub fn sinusoid(positions: &Tensor, width: usize) -> Result<Tensor> {
    let half = width / 2;
    let device = positions.device();
    let denom = (half.max(2) - 1) as f64;
    let freqs: Vec<f32> = (0..half).map(|i| (10000f64.powf(-(i as f64) / denom)) as f32).collect();
    let freqs = Tensor::from_vec(freqs, half, device)?;
    let phi = positions.to_dtype(DType::F32)?.unsqueeze(D::Minus1)?.broadcast_mul(&freqs)?;
    let mut parts = vec![phi.cos()?, phi.sin()?];
    if width % 2 == 1 {
        let mut shape = phi.dims().to_vec();
        if let Some(last) = shape.last_mut() {
            *last = 1;
        }
        parts.push(Tensor::zeros(shape, DType::F32, device)?);
    }
    Tensor::cat(&parts, D::Minus1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Var};

    #[test]
    fn softmax_matches_closed_form_and_has_gradient() {
        let dev = Device::Cpu;
        let x = Var::from_vec(vec![1f32, 2.0, 3.0, -1.0, 0.0, 50.0], (2, 3), &dev).unwrap();
        let y = softmax(x.as_tensor()).unwrap();
        let rows = y.to_vec2::<f32>().unwrap();
        let e: Vec<f32> = [1f32, 2.0, 3.0].iter().map(|v| (v - 3.0).exp()).collect();
        let s: f32 = e.iter().sum();
        for (a, b) in rows[0].iter().zip(e.iter()) {
            assert!((a - b / s).abs() < 1e-6);
        }
        assert!((rows[1][2] - 1.0).abs() < 1e-6, "large logits must not overflow: {:?}", rows[1]);
        // Weighted sum so the gradient is not identically zero (sum of softmax is constant).
        let w = Tensor::new(&[[1f32, 0.0, 0.0], [0.0, 1.0, 0.0]], &dev).unwrap();
        let g = y.mul(&w).unwrap().sum_all().unwrap().backward().unwrap();
        let gx = g.get(x.as_tensor()).expect("softmax must pass a gradient");
        assert!(gx.sqr().unwrap().sum_all().unwrap().to_scalar::<f32>().unwrap() > 1e-8);
    }

    #[test]
    fn layer_norm_normalises_and_has_gradient() {
        let dev = Device::Cpu;
        let vm = candle_nn::VarMap::new();
        let vb = VarBuilder::from_varmap(&vm, DType::F32, &dev);
        let ln = LayerNorm::new(vb, 4, 1e-5).unwrap();
        let x = Var::from_vec(vec![1f32, 2.0, 3.0, 10.0], (1, 4), &dev).unwrap();
        let y = ln.forward(x.as_tensor()).unwrap();
        let v = y.to_vec2::<f32>().unwrap()[0].clone();
        let mean: f32 = v.iter().sum::<f32>() / 4.0;
        let var: f32 = v.iter().map(|a| (a - mean) * (a - mean)).sum::<f32>() / 4.0;
        assert!(mean.abs() < 1e-5 && (var - 1.0).abs() < 1e-3, "mean {mean} var {var}");
        let w = Tensor::new(&[[1f32, -2.0, 0.5, 3.0]], &dev).unwrap();
        let g = y.mul(&w).unwrap().sum_all().unwrap().backward().unwrap();
        for var in vm.all_vars() {
            let gv = g.get(var.as_tensor()).expect("layer norm parameters must get a gradient");
            assert!(gv.sqr().unwrap().sum_all().unwrap().to_scalar::<f32>().unwrap() > 1e-8);
        }
        assert!(g.get(x.as_tensor()).is_some());
    }

    #[test]
    fn sinusoid_is_cos_then_sin() {
        let p = Tensor::new(&[0f32, 3.0], &Device::Cpu).unwrap();
        let e = sinusoid(&p, 8).unwrap().to_vec2::<f32>().unwrap();
        assert_eq!(e[0], vec![1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        assert!((e[1][0] - 3f32.cos()).abs() < 1e-6 && (e[1][4] - 3f32.sin()).abs() < 1e-6);
        // Last frequency is 1/10000 because of the division by half-1.
        assert!((e[1][7] - (3e-4f32).sin()).abs() < 1e-7);
    }
}
