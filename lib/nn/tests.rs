//! Denoiser tests on tiny configs and small synthetic skeletons (each well under 2 s).

use super::*;
use crate::repr::Features;
use crate::rng::SplitMix64;
use candle_core::{Device, Tensor};
use candle_nn::VarMap;

/// A clip with its skeleton, owned, so tests can borrow `BatchItem`s from it.
struct Clip {
    features: Features,
    rest: Vec<f32>,
    relations: Vec<Vec<u8>>,
    distances: Vec<Vec<u8>>,
    names: Vec<Vec<f32>>,
}

impl Clip {
    fn item(&self) -> BatchItem<'_> {
        BatchItem { features: &self.features, rest_row: &self.rest, relations: &self.relations, distances: &self.distances, names: &self.names, start: 0 }
    }
}

/// R and D from a parents array (parents before children), following skeleton::topology's rules.
fn topology(parents: &[Option<usize>], dmax: u8) -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let n = parents.len();
    let ancestors = |mut i: usize| {
        let mut a = vec![i];
        while let Some(p) = parents[i] {
            a.push(p);
            i = p;
        }
        a
    };
    let mut r = vec![vec![4u8; n]; n];
    let mut d = vec![vec![0u8; n]; n];
    for i in 0..n {
        let leaf = !parents.contains(&Some(i));
        for j in 0..n {
            r[i][j] = if i == j {
                if leaf {
                    5
                } else {
                    0
                }
            } else if parents[j] == Some(i) {
                2
            } else if parents[i] == Some(j) {
                1
            } else if parents[i].is_some() && parents[i] == parents[j] {
                3
            } else {
                4
            };
            let (ai, aj) = (ancestors(i), ancestors(j));
            let (ci, cj) = ai.iter().enumerate().find_map(|(x, a)| aj.iter().position(|b| b == a).map(|y| (x, y))).unwrap_or((0, 0));
            d[i][j] = ((ci + cj) as u8).min(dmax);
        }
    }
    (r, d)
}

fn clip(parents: &[Option<usize>], frames: usize, name_dim: usize, seed: u64) -> Clip {
    let mut rng = SplitMix64::new(seed);
    let j = parents.len();
    let mut features = Features::zeros(frames, j, 13);
    features.data.iter_mut().for_each(|v| *v = rng.range(-1.0, 1.0) as f32);
    let rest = (0..j * 13).map(|_| rng.range(-1.0, 1.0) as f32).collect();
    let names = (0..j).map(|_| (0..name_dim).map(|_| rng.range(-0.2, 0.2) as f32).collect()).collect();
    let (relations, distances) = topology(parents, 5);
    Clip { features, rest, relations, distances, names }
}

/// A 6-joint creature: root, spine, head, two legs.
fn creature(frames: usize, seed: u64) -> Clip {
    clip(&[None, Some(0), Some(1), Some(0), Some(3), Some(0)], frames, DenoiserConfig::tiny().name_dim, seed)
}

/// A 3-joint chain.
fn worm(frames: usize, seed: u64) -> Clip {
    clip(&[None, Some(0), Some(1)], frames, DenoiserConfig::tiny().name_dim, seed)
}

fn model(cfg: &DenoiserConfig, seed: u64) -> (VarMap, Denoiser) {
    let vm = VarMap::new();
    let m = Denoiser::new(seeded_var_builder(&vm, seed, &Device::Cpu), cfg).unwrap();
    (vm, m)
}

fn values(t: &Tensor) -> Vec<f32> {
    t.flatten_all().unwrap().to_vec1::<f32>().unwrap()
}

fn max_abs_diff(a: &Tensor, b: &Tensor) -> f32 {
    values(a).iter().zip(values(b)).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

#[test]
fn shapes_and_activations() {
    let cfg = DenoiserConfig::tiny();
    let (_, m) = model(&cfg, 1);
    let (a, b) = (creature(6, 1), worm(4, 2));
    let batch = batch_from(&[a.item(), b.item()], &[10, 99], &Device::Cpu).unwrap();
    assert_eq!(batch.x.dims(), &[2, 7, 6, 13]);
    let (y, acts) = m.forward_with_activations(&batch, &[1, 0]).unwrap();
    assert_eq!(y.dims(), &[2, 7, 6, 13]);
    assert_eq!(acts.len(), 2);
    for act in &acts {
        assert_eq!(act.dims(), &[2, 7, 6, cfg.width]);
    }
    assert!(max_abs_diff(&acts[0], &acts[1]) > 1e-3, "layer 1 and layer 0 activations must differ");
    assert!(values(&y).iter().all(|v| v.is_finite()));
    // Token 0 echoes P_S; padding is zero.
    assert_eq!(values(&y.narrow(1, 0, 1).unwrap()), values(&batch.x.narrow(1, 0, 1).unwrap()));
    let padded_joint = y.narrow(0, 1, 1).unwrap().narrow(2, 3, 3).unwrap();
    assert!(values(&padded_joint).iter().all(|&v| v == 0.0));
    let padded_frames = y.narrow(0, 1, 1).unwrap().narrow(1, 5, 2).unwrap();
    assert!(values(&padded_frames).iter().all(|&v| v == 0.0));
    assert!(matches!(m.forward_with_activations(&batch, &[2]), Err(NnError::Layer { requested: 2, layers: 2 })));
}

#[test]
fn every_parameter_gets_a_gradient() {
    let cfg = DenoiserConfig::tiny();
    let (vm, m) = model(&cfg, 3);
    let (a, b) = (creature(5, 3), worm(3, 4));
    let batch = batch_from(&[a.item(), b.item()], &[5, 60], &Device::Cpu).unwrap();
    let y = m.forward(&batch).unwrap();
    let loss = y.sqr().unwrap().sum_all().unwrap();
    let grads = loss.backward().unwrap();
    let vars = vm.data().lock().unwrap();
    assert_eq!(vars.len(), 4 * 2 + 2 + 4 + cfg.layers * (2 + 8 * 2 + 4 + 6) + 4, "parameter tensors");
    let mut names: Vec<_> = vars.keys().cloned().collect();
    names.sort();
    for name in names {
        let g = grads.get(vars[&name].as_tensor()).unwrap_or_else(|| panic!("{name}: no gradient"));
        let norm = g.sqr().unwrap().sum_all().unwrap().to_scalar::<f32>().unwrap();
        assert!(norm > 0.0 && norm.is_finite(), "{name}: gradient norm {norm}");
    }
}

#[test]
fn padding_never_reaches_real_joints() {
    let cfg = DenoiserConfig::tiny();
    let (_, m) = model(&cfg, 5);
    let dev = Device::Cpu;
    let (big, small) = (creature(7, 5), worm(4, 6));
    // The small clip alone (no padding) ...
    let alone = m.forward(&batch_from(&[small.item()], &[42], &dev).unwrap()).unwrap();
    // ... and padded to 6 joints and 7 frames next to a bigger skeleton, in either order.
    for order in [[0usize, 1], [1, 0]] {
        let items = [big.item(), small.item()];
        let steps = [17u32, 42];
        let batch = batch_from(&[items[order[0]], items[order[1]]], &[steps[order[0]], steps[order[1]]], &dev).unwrap();
        let slot = order.iter().position(|&o| o == 1).unwrap();
        let mixed = m.forward(&batch).unwrap();
        let real = mixed.narrow(0, slot, 1).unwrap().narrow(1, 0, 5).unwrap().narrow(2, 0, 3).unwrap();
        let d = max_abs_diff(&real, &alone);
        assert!(d < 1e-5, "padded batch changes the small clip's output by {d}");

        // Garbage in every padded slot (x, names, R, D) changes nothing either.
        let mut x = values(&batch.x);
        let (t, j) = (8, 6);
        for tok in 0..t {
            for joint in 0..j {
                if tok > 4 || joint > 2 {
                    for k in 0..13 {
                        x[((slot * t + tok) * j + joint) * 13 + k] = if k == 3 { f32::NAN } else { 1e4 };
                    }
                }
            }
        }
        let mut names = values(&batch.names);
        for joint in 3..6 {
            for k in 0..cfg.name_dim {
                names[(slot * 6 + joint) * cfg.name_dim + k] = 50.0;
            }
        }
        let mut rel = batch.relations.flatten_all().unwrap().to_vec1::<u32>().unwrap();
        let mut dist = batch.distances.flatten_all().unwrap().to_vec1::<u32>().unwrap();
        for i in 0..6 {
            for k in 0..6 {
                if i > 2 || k > 2 {
                    rel[(slot * 6 + i) * 6 + k] = 3;
                    dist[(slot * 6 + i) * 6 + k] = 9;
                }
            }
        }
        let garbage = Batch {
            x: Tensor::from_vec(x, batch.x.dims(), &dev).unwrap(),
            names: Tensor::from_vec(names, batch.names.dims(), &dev).unwrap(),
            relations: Tensor::from_vec(rel, batch.relations.dims(), &dev).unwrap(),
            distances: Tensor::from_vec(dist, batch.distances.dims(), &dev).unwrap(),
            ..batch.clone()
        };
        let out = m.forward(&garbage).unwrap();
        assert!(values(&out).iter().all(|v| v.is_finite()), "garbage in padding must not leak NaN");
        assert!(max_abs_diff(&out, &mixed) < 1e-5, "garbage in padding changed the output");
    }
}

#[test]
fn same_seed_same_bytes_other_seed_other_output() {
    let cfg = DenoiserConfig::tiny();
    let (a, b) = (creature(6, 8), worm(5, 9));
    let batch = batch_from(&[a.item(), b.item()], &[3, 70], &Device::Cpu).unwrap();
    let run = |seed| values(&model(&cfg, seed).1.forward(&batch).unwrap());
    let (first, again, other) = (run(11), run(11), run(12));
    assert_eq!(first.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), again.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    assert_ne!(first, other);
}

#[test]
fn parameter_counts_match_the_config() {
    for cfg in [DenoiserConfig::tiny(), DenoiserConfig::small(), DenoiserConfig::paper()] {
        let (vm, _) = model(&cfg, 0);
        let total: usize = vm.all_vars().iter().map(|v| v.elem_count()).sum();
        assert_eq!(total, cfg.parameter_count(), "{cfg:?}");
    }
    assert_eq!(DenoiserConfig::paper().parameter_count(), 1_713_562);
}

#[test]
fn topology_and_timestep_change_the_output() {
    let cfg = DenoiserConfig::tiny();
    let (_, m) = model(&cfg, 13);
    let dev = Device::Cpu;
    let a = creature(5, 13);
    let base = m.forward(&batch_from(&[a.item()], &[30], &dev).unwrap()).unwrap();
    let other_t = m.forward(&batch_from(&[a.item()], &[31], &dev).unwrap()).unwrap();
    assert!(max_abs_diff(&base, &other_t) > 1e-4, "the timestep must matter");
    let mut b = creature(5, 13);
    b.relations[1][2] = 4;
    let other_r = m.forward(&batch_from(&[b.item()], &[30], &dev).unwrap()).unwrap();
    assert!(max_abs_diff(&base, &other_r) > 1e-4, "relations must matter");
    let mut c = creature(5, 13);
    c.distances[4][5] = 1;
    let other_d = m.forward(&batch_from(&[c.item()], &[30], &dev).unwrap()).unwrap();
    assert!(max_abs_diff(&base, &other_d) > 1e-4, "distances must matter");
    let mut shifted = a.item();
    shifted.start = 9;
    let other_pos = m.forward(&batch_from(&[shifted], &[30], &dev).unwrap()).unwrap();
    assert!(max_abs_diff(&base, &other_pos) > 1e-4, "the crop start must matter");
}

#[test]
fn temporal_window_limits_what_one_layer_sees() {
    let cfg = DenoiserConfig { layers: 1, window: 5, ..DenoiserConfig::tiny() };
    let (_, m) = model(&cfg, 21);
    let dev = Device::Cpu;
    let a = creature(30, 21);
    let base = m.forward(&batch_from(&[a.item()], &[50], &dev).unwrap()).unwrap();
    let mut b = creature(30, 21);
    b.features.at_mut(24, 1)[0] += 1.0; // token 25
    let moved = m.forward(&batch_from(&[b.item()], &[50], &dev).unwrap()).unwrap();
    let far = |y: &Tensor| y.narrow(1, 0, 23).unwrap();
    assert!(max_abs_diff(&far(&base), &far(&moved)) < 1e-6, "tokens more than W/2 away must not see the change");
    let near = |y: &Tensor| y.narrow(1, 23, 5).unwrap();
    assert!(max_abs_diff(&near(&base), &near(&moved)) > 1e-4, "tokens within the window must see it");
}

#[test]
fn bad_batches_are_typed_errors() {
    let dev = Device::Cpu;
    let a = creature(4, 1);
    let mut bad = creature(4, 1);
    bad.relations[2].pop();
    assert!(matches!(batch_from(&[a.item(), bad.item()], &[1, 2], &dev), Err(NnError::BatchItem { item: 1, what: "relations R", .. })));
    assert!(matches!(batch_from(&[a.item()], &[1, 2], &dev), Err(NnError::Shape { what: "timesteps", .. })));
    assert!(matches!(batch_from(&[], &[], &dev), Err(NnError::Shape { .. })));
    let mut nan = creature(4, 1);
    nan.features.data[7] = f32::NAN;
    assert!(matches!(batch_from(&[nan.item()], &[1], &dev), Err(NnError::BatchItem { what: "finite features", .. })));
    let mut short = creature(4, 1);
    short.names.pop();
    assert!(matches!(batch_from(&[short.item()], &[1], &dev), Err(NnError::BatchItem { what: "name embeddings", .. })));
    // A model refuses a batch whose shapes disagree with its config.
    let (_, m) = model(&DenoiserConfig::tiny(), 0);
    let mut batch = batch_from(&[a.item()], &[1], &dev).unwrap();
    batch.names = Tensor::zeros((1, 6, 7), candle_core::DType::F32, &dev).unwrap();
    assert!(matches!(m.forward(&batch), Err(NnError::Shape { what: "names", .. })));
}

#[test]
fn thread_count_does_not_change_the_bytes() {
    // candle reads RAYON_NUM_THREADS on every matmul to split the work; setting it here races
    // only with other tests' matmuls, which then also just run with another split — exactly
    // what must not matter.
    let cfg = DenoiserConfig::tiny();
    let (vm, m) = model(&cfg, 31);
    let weight = vm.data().lock().unwrap()["layers.0.skeletal.query.weight"].as_tensor().clone();
    let (a, b) = (creature(9, 31), worm(6, 32));
    let batch = batch_from(&[a.item(), b.item()], &[7, 77], &Device::Cpu).unwrap();
    let before = std::env::var("RAYON_NUM_THREADS").ok();
    let mut outs = Vec::new();
    for threads in ["1", "3"] {
        std::env::set_var("RAYON_NUM_THREADS", threads);
        let y = m.forward(&batch).unwrap();
        let g = y.sqr().unwrap().sum_all().unwrap().backward().unwrap();
        let gw = values(g.get(&weight).unwrap());
        outs.push((values(&y).iter().map(|v| v.to_bits()).collect::<Vec<_>>(), gw.iter().map(|v| v.to_bits()).collect::<Vec<_>>()));
    }
    match before {
        Some(v) => std::env::set_var("RAYON_NUM_THREADS", v),
        None => std::env::remove_var("RAYON_NUM_THREADS"),
    }
    assert!(outs[0] == outs[1], "1 and 3 threads give different bytes");
}
