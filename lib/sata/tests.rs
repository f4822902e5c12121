//! Model-level checks: shapes, topology independence of the latent's size, every parameter
//! trained, a tiny model learning to reconstruct one clip.

use super::graph::{depths, reverse_depths, SkeletonGraph};
use super::train::{cycle_loss, loss, FeatureScale, LossWeights};
use super::{SataConfig, SataModel};
use crate::diffusion::train::named_vars;
use crate::document::AnyTopSection;
use crate::embed::NameTable;
use crate::nn::seeded_var_builder;
use crate::repr::Features;
use crate::rng::SplitMix64;
use crate::synth;
use candle_core::{Device, Tensor};
use candle_nn::VarMap;

fn clip(name: &str) -> (crate::skeleton::Skeleton, SkeletonGraph, Features) {
    let (skeleton, motion) = synth::creature(name, 0).unwrap();
    let section = AnyTopSection::of_clip(&skeleton, &motion, name).unwrap();
    let names = NameTable::builtin().unwrap().embed_skeleton(&skeleton);
    let g = SkeletonGraph::new(&skeleton, &section.rig, &names, &Device::Cpu).unwrap();
    let features = section.rig.encode(&skeleton, &motion).unwrap().features;
    (skeleton, g, features)
}

fn tensor(f: &Features, frames: usize, scale: &FeatureScale, g: &SkeletonGraph) -> Tensor {
    let mut f = Features { frames, data: f.data[..frames * f.joints * f.dims].to_vec(), ..f.clone() };
    scale.apply(&mut f, &g.rest);
    Tensor::from_vec(f.data, (1, frames, f.joints, f.dims), &Device::Cpu).unwrap()
}

#[test]
fn depths_of_a_chain_with_a_branch() {
    let parents = [None, Some(0), Some(1), Some(1), Some(3)];
    assert_eq!(depths(&parents), vec![0, 1, 2, 2, 3]);
    assert_eq!(reverse_depths(&parents), vec![3, 2, 0, 1, 0]);
}

#[test]
fn latents_have_one_size_for_every_skeleton_and_decode_anywhere() {
    let varmap = VarMap::new();
    let model = SataModel::new(seeded_var_builder(&varmap, 3, &Device::Cpu), &SataConfig::tiny()).unwrap();
    let (_, dog, dog_f) = clip("quadruped");
    let (_, crab, crab_f) = clip("crab");
    assert_ne!(dog.joints, crab.joints);
    let scale = FeatureScale::measure([(&dog_f, dog.rest.as_slice()), (&crab_f, crab.rest.as_slice())]);
    let (mu_dog, _) = model.encode(&tensor(&dog_f, 12, &scale, &dog), &dog).unwrap();
    let (mu_crab, _) = model.encode(&tensor(&crab_f, 12, &scale, &crab), &crab).unwrap();
    assert_eq!(mu_dog.dims(), &[1, 12, 16]);
    assert_eq!(mu_crab.dims(), mu_dog.dims());
    let on_crab = model.decode(&mu_dog, &crab).unwrap();
    assert_eq!(on_crab.dims(), &[1, 12, crab.joints, 13]);
    let v: Vec<f32> = on_crab.flatten_all().unwrap().to_vec1().unwrap();
    assert!(v.iter().all(|x| x.is_finite()));
}

#[test]
fn every_parameter_gets_a_gradient() {
    let varmap = VarMap::new();
    let model = SataModel::new(seeded_var_builder(&varmap, 5, &Device::Cpu), &SataConfig::tiny()).unwrap();
    let (_, g, f) = clip("biped");
    let scale = FeatureScale::measure([(&f, g.rest.as_slice())]);
    let x = tensor(&f, 10, &scale, &g);
    let s = scale.tensor(g.joints, &Device::Cpu).unwrap();
    let (total, report) = loss(&model, &x, &g, &s, &LossWeights::default(), &mut SplitMix64::new(1)).unwrap();
    assert!(report.total.is_finite() && report.total > 0.0, "{report:?}");
    let grads = total.backward().unwrap();
    let vars = named_vars(&varmap);
    assert!(vars.len() > 50, "{} parameters", vars.len());
    for (name, var) in &vars {
        let g = grads.get(var.as_tensor()).unwrap_or_else(|| panic!("{name}: no gradient"));
        let norm = g.sqr().unwrap().sum_all().unwrap().to_scalar::<f32>().unwrap();
        assert!(norm > 0.0, "{name}: zero gradient");
    }
}

#[test]
fn a_tiny_model_learns_to_reconstruct_one_clip() {
    let varmap = VarMap::new();
    let model = SataModel::new(seeded_var_builder(&varmap, 7, &Device::Cpu), &SataConfig::tiny()).unwrap();
    let (_, g, f) = clip("quadruped");
    let scale = FeatureScale::measure([(&f, g.rest.as_slice())]);
    let x = tensor(&f, 16, &scale, &g);
    let s = scale.tensor(g.joints, &Device::Cpu).unwrap();
    let vars = named_vars(&varmap);
    let mut opt = crate::diffusion::train::AdamW::new(3e-3);
    let mut rng = SplitMix64::new(2);
    let weights = LossWeights::default();
    let first = loss(&model, &x, &g, &s, &weights, &mut rng).unwrap().1.reconstruction;
    let mut last = first;
    for _ in 0..60 {
        let (total, report) = loss(&model, &x, &g, &s, &weights, &mut rng).unwrap();
        opt.update(&vars, &total.backward().unwrap()).unwrap();
        last = report.reconstruction;
    }
    assert!(last < first * 0.5, "reconstruction MSE {first} -> {last}");
}

#[test]
fn feature_scale_divides_by_group_rms_and_undoes_exactly() {
    let (_, g, f) = clip("spider");
    let scale = FeatureScale::measure([(&f, g.rest.as_slice())]);
    scale.check().unwrap();
    assert_eq!(scale.joint[12], 1.0, "contacts stay 0/1");
    assert!(scale.joint[0] == scale.joint[2] && scale.joint[3] == scale.joint[8], "one value per group");
    let mut h = f.clone();
    scale.apply(&mut h, &g.rest);
    // Every joint's position group has unit RMS after scaling.
    let rms = (h.data.chunks_exact(13).enumerate().filter(|(k, _)| k % h.joints != 0).map(|(_, r)| r[..3].iter().map(|v| v * v).sum::<f32>()).sum::<f32>()
        / ((h.frames * (h.joints - 1) * 3) as f32))
        .sqrt();
    assert!((rms - 1.0).abs() < 1e-3, "joint position RMS {rms}");
    // The rest pose itself is all zeros.
    let mut still = Features { frames: 1, data: g.rest.clone(), ..f.clone() };
    scale.apply(&mut still, &g.rest);
    assert!(still.data.iter().all(|&v| v == 0.0));
    scale.undo(&mut h, &g.rest);
    let worst = f.data.iter().zip(&h.data).map(|(a, b)| (a - b).abs()).fold(0f32, f32::max);
    assert!(worst < 1e-5, "apply + undo changed a value by {worst}");
    let bad = FeatureScale { root: vec![0.0; 13], joint: scale.joint.clone() };
    assert!(bad.check().is_err());
}

#[test]
fn the_latent_cycle_reaches_decoder_and_encoder_and_can_be_learned() {
    let varmap = VarMap::new();
    let model = SataModel::new(seeded_var_builder(&varmap, 11, &Device::Cpu), &SataConfig::tiny()).unwrap();
    let (_, dog, dog_f) = clip("quadruped");
    let (_, crab, crab_f) = clip("crab");
    let scale = FeatureScale::measure([(&dog_f, dog.rest.as_slice()), (&crab_f, crab.rest.as_slice())]);
    let x = tensor(&dog_f, 12, &scale, &dog);
    let s = scale.tensor(crab.joints, &Device::Cpu).unwrap();
    let vars = named_vars(&varmap);
    let cycle = |model: &SataModel| {
        let (mu, _) = model.encode(&x, &dog).unwrap();
        cycle_loss(model, &mu, &crab, &s).unwrap()
    };
    let c = cycle(&model);
    let first = c.to_scalar::<f32>().unwrap();
    assert!(first.is_finite() && first > 0.0, "cycle loss {first}");
    let grads = c.backward().unwrap();
    let moved = |prefix: &str| {
        vars.iter()
            .filter(|(n, _)| n.starts_with(prefix))
            .any(|(_, v)| grads.get(v.as_tensor()).is_some_and(|g| g.sqr().unwrap().sum_all().unwrap().to_scalar::<f32>().unwrap() > 0.0))
    };
    assert!(moved("decoder.output") && moved("decoder.modulation") && moved("encoder.input"), "the cycle must train both halves");
    let mut opt = crate::diffusion::train::AdamW::new(3e-3);
    for _ in 0..40 {
        opt.update(&vars, &cycle(&model).backward().unwrap()).unwrap();
    }
    let last = cycle(&model).to_scalar::<f32>().unwrap();
    assert!(last < first * 0.5, "cycle loss {first} -> {last}");
}

#[test]
fn a_relative_latent_is_zero_at_rest_and_old_configs_stay_absolute() {
    let (_, g, f) = clip("quadruped");
    let scale = FeatureScale::measure([(&f, g.rest.as_slice())]);
    let mut rest = Features::zeros(10, g.joints, 13);
    for frame in rest.data.chunks_exact_mut(g.joints * 13) {
        frame.copy_from_slice(&g.rest);
    }
    let still = tensor(&rest, 10, &scale, &g);
    let moving = tensor(&f, 10, &scale, &g);
    for relative in [true, false] {
        let varmap = VarMap::new();
        let cfg = SataConfig { relative_latent: relative, ..SataConfig::tiny() };
        let model = SataModel::new(seeded_var_builder(&varmap, 13, &Device::Cpu), &cfg).unwrap();
        let size = |t: &Tensor| t.abs().unwrap().max_all().unwrap().to_scalar::<f32>().unwrap();
        let (at_rest, _) = model.encode(&still, &g).unwrap();
        let (walking, _) = model.encode(&moving, &g).unwrap();
        assert!(size(&walking) > 1e-3, "relative {relative}: a moving clip's latent is {}", size(&walking));
        if relative {
            assert!(size(&at_rest) < 1e-6, "the rest pose standing still encodes to {}", size(&at_rest));
        } else {
            assert!(size(&at_rest) > 1e-3, "an absolute latent of the rest pose is {}", size(&at_rest));
        }
    }
    // Checkpoints written before the option decode as they were trained: absolute latents.
    let mut json = serde_json::to_value(SataConfig::small()).unwrap();
    json.as_object_mut().unwrap().remove("relative_latent");
    let old: SataConfig = serde_json::from_value(json).unwrap();
    assert!(!old.relative_latent);
}
