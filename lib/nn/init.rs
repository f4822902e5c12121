//! Seeded parameter initialisation.
//!
//! candle's CPU backend draws `Init::Randn`/`Uniform` from a thread RNG and refuses
//! `Device::set_seed`, so a model built with `VarBuilder::from_varmap` differs run to run.
//! [`seeded_var_builder`] wraps a `VarMap` and creates each new parameter from SplitMix64
//! seeded by (seed, parameter name): the values depend on neither creation order nor threads.

use crate::rng::SplitMix64;
use candle_core::{DType, Device, Result, Shape, Tensor, Var};
use candle_nn::var_builder::SimpleBackend;
use candle_nn::{Init, VarBuilder, VarMap};

struct Seeded {
    varmap: VarMap,
    seed: u64,
}

/// FNV-1a of the name, so every parameter gets its own stream.
fn name_hash(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

fn values(shape: &Shape, init: Init, rng: &mut SplitMix64) -> Vec<f32> {
    let n = shape.elem_count();
    let normal = |rng: &mut SplitMix64| {
        // Box-Muller; 1 - unit() is in (0, 1], so the log is finite.
        let (u, v) = (1.0 - rng.unit(), rng.unit());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    match init {
        Init::Const(c) => vec![c as f32; n],
        Init::Uniform { lo, up } => (0..n).map(|_| rng.range(lo, up) as f32).collect(),
        Init::Randn { mean, stdev } => (0..n).map(|_| (mean + stdev * normal(rng)) as f32).collect(),
        Init::Kaiming { .. } => {
            // Not used by our layers; treat as PyTorch's default linear init over the fan-in.
            let fan_in: usize = shape.dims().iter().skip(1).product::<usize>().max(1);
            let bound = 1.0 / (fan_in as f64).sqrt();
            (0..n).map(|_| rng.range(-bound, bound) as f32).collect()
        }
    }
}

impl SimpleBackend for Seeded {
    fn get(&self, shape: Shape, name: &str, init: Init, dtype: DType, dev: &Device) -> Result<Tensor> {
        let mut data = self.varmap.data().lock().map_err(|_| candle_core::Error::Msg("varmap lock poisoned".into()))?;
        if let Some(var) = data.get(name) {
            if var.shape() != &shape {
                candle_core::bail!("parameter {name}: shape {:?} requested, {:?} stored", shape, var.shape());
            }
            return Ok(var.as_tensor().clone());
        }
        let mut rng = SplitMix64::new(self.seed ^ name_hash(name));
        let t = Tensor::from_vec(values(&shape, init, &mut rng), shape, dev)?.to_dtype(dtype)?;
        let var = Var::from_tensor(&t)?;
        let tensor = var.as_tensor().clone();
        data.insert(name.to_string(), var);
        Ok(tensor)
    }

    fn get_unchecked(&self, name: &str, _dtype: DType, _dev: &Device) -> Result<Tensor> {
        candle_core::bail!("parameter {name}: a seeded VarMap needs the shape to create it")
    }

    fn contains_tensor(&self, name: &str) -> bool {
        self.varmap.data().lock().map(|d| d.contains_key(name)).unwrap_or(false)
    }
}

/// A f32 `VarBuilder` over `varmap` that creates missing parameters deterministically from
/// `seed` (existing ones, e.g. loaded from a checkpoint, are returned unchanged).
pub fn seeded_var_builder(varmap: &VarMap, seed: u64, device: &Device) -> VarBuilder<'static> {
    VarBuilder::from_backend(Box::new(Seeded { varmap: varmap.clone(), seed }), DType::F32, device.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_values_other_seed_other_values() {
        let dev = Device::Cpu;
        let make = |seed| {
            let vm = VarMap::new();
            let vb = seeded_var_builder(&vm, seed, &dev);
            let a = vb.pp("a").get_with_hints((3, 4), "w", Init::Randn { mean: 0.0, stdev: 1.0 }).unwrap();
            a.flatten_all().unwrap().to_vec1::<f32>().unwrap()
        };
        assert_eq!(make(1), make(1));
        assert_ne!(make(1), make(2));
        let v = make(5);
        let mean = v.iter().sum::<f32>() / v.len() as f32;
        assert!(mean.abs() < 1.5 && v.iter().all(|x| x.is_finite()));
    }

    #[test]
    fn existing_parameters_are_reused_and_shape_checked() {
        let dev = Device::Cpu;
        let vm = VarMap::new();
        let vb = seeded_var_builder(&vm, 0, &dev);
        let a = vb.get_with_hints(4, "b", Init::Const(2.0)).unwrap();
        let b = vb.get_with_hints(4, "b", Init::Const(7.0)).unwrap();
        assert_eq!(a.to_vec1::<f32>().unwrap(), b.to_vec1::<f32>().unwrap());
        assert!(vb.get_with_hints(5, "b", Init::Const(0.0)).is_err());
    }
}
