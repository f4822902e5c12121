//! The fused kernels against the same computation written with candle's basic ops (the way
//! the model computed it before): values and gradients.

use super::*;
use crate::nn::layers::softmax;
use crate::rng::SplitMix64;
use candle_core::{Device, Var, D};

fn values(t: &Tensor) -> Result<Vec<f32>> {
    t.flatten_all()?.to_vec1::<f32>()
}

fn random(rng: &mut SplitMix64, n: usize) -> Vec<f32> {
    (0..n).map(|_| rng.range(-1.5, 1.5) as f32).collect()
}

fn max_diff(a: &Tensor, b: &Tensor) -> f32 {
    let (a, b) = (values(a).unwrap(), values(b).unwrap());
    assert_eq!(a.len(), b.len());
    a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

/// `sum(y * r)` for a fixed random `r`, so every output element carries a distinct gradient.
fn weighted_sum(y: &Tensor, seed: u64) -> Tensor {
    let mut rng = SplitMix64::new(seed);
    let r = Tensor::from_vec(random(&mut rng, y.elem_count()), y.shape(), y.device()).unwrap();
    (y * r).unwrap().sum_all().unwrap()
}

const MASKED: f64 = -1e9;

#[test]
fn skeletal_attention_matches_basic_ops() {
    let dev = Device::Cpu;
    let (b, t, j, h, dh, nt) = (2, 3, 5, 2, 4, 4);
    let w = h * dh;
    let rows = b * t * j;
    let mut rng = SplitMix64::new(3);
    let qkv = Var::from_vec(random(&mut rng, rows * 3 * w), (rows, 3 * w), &dev).unwrap();
    let c = Var::from_vec(random(&mut rng, rows * h * nt), (rows, h * nt), &dev).unwrap();
    // Sample 1 has 3 real joints; type ids: distance (0..2) and relation (2..4), one unknown.
    let key_ok: Vec<bool> = (0..b * j).map(|i| i < j || i % j < 3).collect();
    let types: Vec<[u16; 2]> = (0..b * j * j).map(|i| [(i % 2) as u16, if i % 7 == 0 { NO_TYPE } else { 2 + (i % 3 % 2) as u16 }]).collect();
    let keys = Keys::Topology { types: Arc::new(types.clone()), key_ok: Arc::new(key_ok.clone()), type_count: nt };
    let fused = attention(qkv.as_tensor(), Some(c.as_tensor()), Groups::joints(b, t, j), h, keys).unwrap();

    // Reference: heads split, bias through a one-hot, additive key mask, softmax, merge.
    let split =
        |part: usize| qkv.as_tensor().narrow(1, part * w, w).unwrap().reshape((b * t, j, h, dh)).unwrap().transpose(1, 2).unwrap().contiguous().unwrap();
    let (q, k, v) = (split(0), split(1), split(2));
    let mut onehot = vec![0f32; b * j * nt * j];
    for s in 0..b {
        for i in 0..j {
            for kk in 0..j {
                for ty in types[(s * j + i) * j + kk] {
                    if ty != NO_TYPE {
                        onehot[((s * j + i) * nt + ty as usize) * j + kk] += 1.0;
                    }
                }
            }
        }
    }
    let onehot = Tensor::from_vec(onehot, (b, 1, 1, j, nt, j), &dev).unwrap();
    let cc = c.as_tensor().reshape((b, t, j, h, nt)).unwrap().permute((0, 1, 3, 2, 4)).unwrap().unsqueeze(5).unwrap();
    let bias = cc.broadcast_mul(&onehot).unwrap().sum(4).unwrap(); // [B, T, H, J, J]
    let mask: Vec<f32> = key_ok.iter().map(|&ok| if ok { 0.0 } else { MASKED as f32 }).collect();
    let mask = Tensor::from_vec(mask, (b, 1, 1, 1, j), &dev).unwrap();
    let logits = (q.matmul(&k.t().unwrap()).unwrap() * (1.0 / (dh as f64).sqrt())).unwrap().reshape((b, t, h, j, j)).unwrap();
    let logits = (logits + bias).unwrap().broadcast_add(&mask).unwrap();
    let p = softmax(&logits).unwrap().reshape((b * t, h, j, j)).unwrap();
    let reference = p.matmul(&v).unwrap().transpose(1, 2).unwrap().contiguous().unwrap().reshape((rows, w)).unwrap();

    assert!(max_diff(&fused, &reference) < 1e-5, "forward differs by {}", max_diff(&fused, &reference));
    let gf = weighted_sum(&fused, 9).backward().unwrap();
    let gr = weighted_sum(&reference, 9).backward().unwrap();
    for (name, var) in [("q/k/v", &qkv), ("bias coefficients", &c)] {
        let (a, r) = (gf.get(var.as_tensor()).unwrap(), gr.get(var.as_tensor()).unwrap());
        let scale = values(r).unwrap().iter().fold(0f32, |m, v| m.max(v.abs()));
        assert!(scale > 1e-3, "{name}: the reference gradient is not trivially zero");
        assert!(max_diff(a, r) < 1e-4 * scale.max(1.0), "{name} gradient differs by {}", max_diff(a, r));
    }
}

#[test]
fn temporal_attention_matches_basic_ops() {
    // 9 frames: one query block; 70 frames: three, the later ones without the rest-pose key
    // in their key range.
    for (t, half) in [(9, 2), (70, 3)] {
        temporal_attention_case(t, half);
    }
}

fn temporal_attention_case(t: usize, half: usize) {
    let dev = Device::Cpu;
    let (b, j, h, dh) = (2, 3, 2, 3);
    let w = h * dh;
    let rows = b * t * j;
    let mut rng = SplitMix64::new(4);
    let qkv = Var::from_vec(random(&mut rng, rows * 3 * w), (rows, 3 * w), &dev).unwrap();
    // Sample 1 has t - 3 real tokens.
    let frame_ok: Vec<bool> = (0..b * t).map(|i| i < t || i % t < t - 3).collect();
    let keys = Keys::Window { half, frame_ok: Arc::new(frame_ok.clone()) };
    let fused = attention(qkv.as_tensor(), None, Groups::frames(b, t, j), h, keys).unwrap();

    let split = |part: usize| {
        qkv.as_tensor().narrow(1, part * w, w).unwrap().reshape((b, t, j, h, dh)).unwrap().permute((0, 2, 3, 1, 4)).unwrap().contiguous().unwrap()
    };
    let (q, k, v) = (split(0), split(1), split(2)); // [B, J, H, T, dh]
    let mut mask = vec![0f32; b * t * t];
    for s in 0..b {
        for i in 0..t {
            for kk in 0..t {
                if !(frame_ok[s * t + kk] && (kk == 0 || i.abs_diff(kk) <= half)) {
                    mask[(s * t + i) * t + kk] = MASKED as f32;
                }
            }
        }
    }
    let mask = Tensor::from_vec(mask, (b, 1, 1, t, t), &dev).unwrap();
    let four = |x: &Tensor| x.reshape((b * j, h, t, dh)).unwrap();
    let (q, k, v) = (four(&q), four(&k), four(&v));
    let logits = (q.matmul(&k.t().unwrap()).unwrap() * (1.0 / (dh as f64).sqrt())).unwrap().reshape((b, j, h, t, t)).unwrap();
    let p = softmax(&logits.broadcast_add(&mask).unwrap()).unwrap().reshape((b * j, h, t, t)).unwrap();
    let reference =
        p.matmul(&v).unwrap().reshape((b, j, h, t, dh)).unwrap().permute((0, 3, 1, 2, 4)).unwrap().contiguous().unwrap().reshape((rows, w)).unwrap();

    assert!(max_diff(&fused, &reference) < 1e-5, "forward differs by {}", max_diff(&fused, &reference));
    let gf = weighted_sum(&fused, 2).backward().unwrap();
    let gr = weighted_sum(&reference, 2).backward().unwrap();
    let (a, r) = (gf.get(qkv.as_tensor()).unwrap(), gr.get(qkv.as_tensor()).unwrap());
    assert!(max_diff(a, r) < 1e-4, "q/k/v gradient differs by {}", max_diff(a, r));
}

#[test]
fn layer_norm_matches_basic_ops() {
    // 8: whole vectors of eight; 13: a remainder (the sums run in eight lanes).
    for width in [8, 13] {
        layer_norm_case(width);
    }
}

fn layer_norm_case(width: usize) {
    let dev = Device::Cpu;
    let mut rng = SplitMix64::new(5);
    let x = Var::from_vec(random(&mut rng, 6 * width), (2, 3, width), &dev).unwrap();
    let wt = Var::from_vec(random(&mut rng, width), width, &dev).unwrap();
    let bs = Var::from_vec(random(&mut rng, width), width, &dev).unwrap();
    let fused = layer_norm(x.as_tensor(), wt.as_tensor(), bs.as_tensor(), 1e-5).unwrap();
    let xt = x.as_tensor();
    let centred = xt.broadcast_sub(&xt.mean_keepdim(D::Minus1).unwrap()).unwrap();
    let var = centred.sqr().unwrap().mean_keepdim(D::Minus1).unwrap();
    let reference =
        centred.broadcast_div(&(var + 1e-5).unwrap().sqrt().unwrap()).unwrap().broadcast_mul(wt.as_tensor()).unwrap().broadcast_add(bs.as_tensor()).unwrap();
    assert_eq!(fused.dims(), &[2, 3, width]);
    assert!(max_diff(&fused, &reference) < 1e-5);
    let gf = weighted_sum(&fused, 1).backward().unwrap();
    let gr = weighted_sum(&reference, 1).backward().unwrap();
    for var in [&x, &wt, &bs] {
        let (a, r) = (gf.get(var.as_tensor()).unwrap(), gr.get(var.as_tensor()).unwrap());
        assert!(max_diff(a, r) < 1e-4, "gradient differs by {}", max_diff(a, r));
    }
}

#[test]
fn mismatched_inputs_are_errors_not_panics() {
    let dev = Device::Cpu;
    let qkv = Tensor::zeros((10, 12), candle_core::DType::F32, &dev).unwrap();
    let keys = Keys::Window { half: 1, frame_ok: Arc::new(vec![true; 10]) };
    assert!(attention(&qkv, None, Groups::frames(1, 4, 2), 2, keys.clone()).is_err(), "8 rows expected, 10 given");
    let topo = Keys::Topology { types: Arc::new(vec![[0, 1]; 25]), key_ok: Arc::new(vec![true; 5]), type_count: 2 };
    assert!(attention(&qkv, None, Groups::joints(1, 2, 5), 2, topo).is_err(), "topology keys without coefficients");
}

#[test]
fn broadcast_add_matches_basic_ops() {
    let dev = Device::Cpu;
    let mut rng = SplitMix64::new(6);
    let x = Var::from_vec(random(&mut rng, 2 * 3 * 4 * 5), (2, 3, 4, 5), &dev).unwrap();
    let v = Var::from_vec(random(&mut rng, 2 * 4 * 5), (2, 4, 5), &dev).unwrap();
    let fused = add_broadcast(x.as_tensor(), v.as_tensor(), 2).unwrap();
    let reference = x.as_tensor().broadcast_add(&v.as_tensor().unsqueeze(1).unwrap()).unwrap();
    assert_eq!(fused.dims(), &[2, 3, 4, 5]);
    assert!(max_diff(&fused, &reference) < 1e-6);
    let gf = weighted_sum(&fused, 3).backward().unwrap();
    let gr = weighted_sum(&reference, 3).backward().unwrap();
    for var in [&x, &v] {
        let (a, r) = (gf.get(var.as_tensor()).unwrap(), gr.get(var.as_tensor()).unwrap());
        assert!(max_diff(a, r) < 1e-5, "gradient differs by {}", max_diff(a, r));
    }
    assert!(add_broadcast(x.as_tensor(), v.as_tensor(), 3).is_err(), "40 values do not split into 3 groups");
}

#[test]
fn fast_exp_is_accurate_and_exactly_zero_for_masked_keys() {
    let mut worst = 0f32;
    let mut x = -87.0f32;
    while x <= 0.0 {
        let (a, b) = (super::exp(x), x.exp());
        worst = worst.max(((a - b) / b).abs());
        x += 0.0137;
    }
    assert!(worst < 1e-6, "relative error {worst}");
    assert_eq!(super::exp(0.0), 1.0);
    assert_eq!(super::exp(f32::NEG_INFINITY), 0.0);
    assert_eq!(super::exp(-1e9), 0.0);
    // Outside the softmax's range the exponent is clamped before its (unchecked) conversion:
    // still accurate up to f32's largest power of two, infinite beyond it.
    for x in [0.5f32, 10.0, 60.0, 88.0] {
        assert!(((super::exp(x) - x.exp()) / x.exp()).abs() < 1e-6, "e^{x}");
    }
    assert_eq!(super::exp(200.0), f32::INFINITY);
}

#[test]
fn linear_matches_basic_ops() {
    let dev = Device::Cpu;
    let mut rng = SplitMix64::new(8);
    for (dims, inputs, outputs) in [(vec![2, 3, 5], 5, 7), (vec![70, 16], 16, 48), (vec![1, 4], 4, 1)] {
        let n: usize = dims.iter().product();
        let x = Var::from_vec(random(&mut rng, n), dims.as_slice(), &dev).unwrap();
        let w = Var::from_vec(random(&mut rng, outputs * inputs), (outputs, inputs), &dev).unwrap();
        let b = Var::from_vec(random(&mut rng, outputs), outputs, &dev).unwrap();
        let fused = linear(x.as_tensor(), w.as_tensor(), b.as_tensor(), None).unwrap();
        let rows = n / inputs;
        let mut out_dims = dims.clone();
        *out_dims.last_mut().unwrap() = outputs;
        let reference = x
            .as_tensor()
            .reshape((rows, inputs))
            .unwrap()
            .matmul(&w.as_tensor().t().unwrap())
            .unwrap()
            .broadcast_add(b.as_tensor())
            .unwrap()
            .reshape(out_dims.as_slice())
            .unwrap();
        assert_eq!(fused.dims(), out_dims.as_slice());
        assert_eq!(values(&fused).unwrap(), values(&reference).unwrap(), "the forward is candle's matmul and bias add, to the bit");
        let gf = weighted_sum(&fused, 4).backward().unwrap();
        let gr = weighted_sum(&reference, 4).backward().unwrap();
        for (name, var) in [("x", &x), ("weight", &w), ("bias", &b)] {
            let (a, r) = (gf.get(var.as_tensor()).unwrap(), gr.get(var.as_tensor()).unwrap());
            assert!(max_diff(a, r) < 1e-5, "{name} gradient differs by {}", max_diff(a, r));
        }
        // Another shape for the same values.
        let flat = linear(x.as_tensor(), w.as_tensor(), b.as_tensor(), Some((rows * outputs,).into())).unwrap();
        assert_eq!(values(&flat).unwrap(), values(&fused).unwrap());
    }
    let x = Tensor::zeros((3, 4), candle_core::DType::F32, &dev).unwrap();
    let w = Tensor::zeros((2, 5), candle_core::DType::F32, &dev).unwrap();
    assert!(linear(&x, &w, &Tensor::zeros(2, candle_core::DType::F32, &dev).unwrap(), None).is_err(), "4 inputs against a weight for 5");
    let w = Tensor::zeros((2, 4), candle_core::DType::F32, &dev).unwrap();
    assert!(linear(&x, &w, &Tensor::zeros(2, candle_core::DType::F32, &dev).unwrap(), Some((7,).into())).is_err(), "6 values do not make 7");
}

#[test]
fn topology_coefficients_match_the_projection_matrix() {
    let dev = Device::Cpu;
    let (rows, heads, dh, types) = (13, 3, 4, 5);
    let w = heads * dh;
    let mut rng = SplitMix64::new(10);
    let qkv = Var::from_vec(random(&mut rng, rows * 3 * w), (rows, 3 * w), &dev).unwrap();
    let eq = Var::from_vec(random(&mut rng, types * w), (types, w), &dev).unwrap();
    let ek = Var::from_vec(random(&mut rng, types * w), (types, w), &dev).unwrap();
    let fused = topology_coefficients(qkv.as_tensor(), eq.as_tensor(), ek.as_tensor(), heads).unwrap();
    // How the model computed it before: one [3w, heads * types] matrix, each head's block on
    // its own rows, the value rows zero.
    let mut block = vec![0f32; w * heads * types];
    for row in 0..w {
        for ty in 0..types {
            block[row * heads * types + (row / dh) * types + ty] = 1.0;
        }
    }
    let block = Tensor::from_vec(block, (w, heads * types), &dev).unwrap();
    let per_head = |t: &Tensor| t.t().unwrap().repeat((1, heads)).unwrap().mul(&block).unwrap();
    let projection =
        Tensor::cat(&[per_head(eq.as_tensor()), per_head(ek.as_tensor()), Tensor::zeros((w, heads * types), candle_core::DType::F32, &dev).unwrap()], 0)
            .unwrap();
    let reference = (qkv.as_tensor().matmul(&projection).unwrap() * (1.0 / (dh as f64).sqrt())).unwrap();
    assert_eq!(fused.dims(), &[rows, heads * types]);
    assert!(max_diff(&fused, &reference) < 1e-5, "forward differs by {}", max_diff(&fused, &reference));
    let gf = weighted_sum(&fused, 11).backward().unwrap();
    let gr = weighted_sum(&reference, 11).backward().unwrap();
    for (name, var) in [("q/k/v", &qkv), ("query table", &eq), ("key table", &ek)] {
        let (a, r) = (gf.get(var.as_tensor()).unwrap(), gr.get(var.as_tensor()).unwrap());
        assert!(max_diff(a, r) < 1e-5, "{name} gradient differs by {}", max_diff(a, r));
    }
    assert!(topology_coefficients(qkv.as_tensor(), eq.as_tensor(), ek.as_tensor(), 5).is_err(), "12 is no multiple of 5 heads");
}
