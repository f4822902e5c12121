//! SATA's encoder and decoder (paper §3.2–3.3, sizes §4.1.1), on candle's basic ops and our
//! fused attention (which has a CPU backward; candle-nn's fused kernels do not).
//!
//! Every batch holds clips of one skeleton (batches are bucketed by skeleton), so no joint is
//! padding and the graph tensors are shared by the whole batch: the paper's "padding-free".
//!
//! * Semantic-spatial modulation: z_s = φ_s(sinusoids of [X_g; X_l]), z_t = φ_t(X_t),
//!   c = Φ([z_s; z_t]), [γ, β] = Ψ(c), x̂ = LN(z_m)(1 + γ) + β, out = z_m + σ(W_g c) ⊙ x̂.
//! * Block (pre-norm): x = LN(h); h += GINE(x) + SpatialAttention(x), GINE's messages
//!   ReLU(x_src + MLP_edge(e)) summed at each joint and passed through a two-layer MLP;
//!   h += MLP(LN(h)); then per joint over the window's frames h += TemporalAttention(LN(h) +
//!   sinusoidal position); h += FF(LN(h)).
//! * Encoder: motion input (root and other joints through their own linears, as AnyTop's) ->
//!   modulation by the source skeleton -> blocks -> max + mean over joints -> LN -> mean and
//!   log-variance of the per-frame latent.
//! * Decoder: latent -> linear -> broadcast to every joint of the target -> modulation by the
//!   target skeleton -> blocks -> LN -> 13 features per joint (root and joints own heads).
//!
//! Features in and out are offsets from the skeleton's rest pose standing still, divided by
//! one global scale per feature group (`train::FeatureScale`). Our choice, measured: with raw
//! features a 400-step model put every creature's hips at the zoo's mean height (0.55 where a
//! biped's are at 1.0), and a 900-step model with rest-relative outputs but raw inputs still
//! did no better than each clip's mean pose: the motion is a small ripple on top of the pose.

use super::graph::{SkeletonGraph, EDGE_DIMS};
use super::{SataConfig, FEATURE_DIMS, INPUT_DIMS};
use crate::nn::anytop::{project_qkv, PerJointType};
use crate::nn::fused::{self, Groups, Keys};
use crate::nn::gelu::gelu;
use crate::nn::layers::{sinusoid, FeedForward, LayerNorm, Linear};
use crate::nn::NnError;
use candle_core::{DType, Tensor, D};
use candle_nn::VarBuilder;
use std::sync::Arc;

fn sigmoid(x: &Tensor) -> candle_core::Result<Tensor> {
    (x.neg()?.exp()? + 1.0)?.recip()
}

/// `[J, 6]` coordinates -> `[J, 6 * 2 * frequencies]`: sin and cos of 2^k π x, k < frequencies.
fn spatial_encoding(statics: &Tensor, frequencies: usize) -> candle_core::Result<Tensor> {
    let freqs: Vec<f32> = (0..frequencies).map(|k| std::f32::consts::PI * (1u32 << k.min(20)) as f32).collect();
    let freqs = Tensor::from_vec(freqs, frequencies, statics.device())?;
    let j = statics.dim(0)?;
    let phi = statics.unsqueeze(2)?.broadcast_mul(&freqs.reshape((1, 1, frequencies))?)?;
    Tensor::cat(&[phi.sin()?, phi.cos()?], 2)?.reshape((j, 6 * 2 * frequencies))
}

#[derive(Clone, Debug)]
struct Modulation {
    spatial: Linear,
    text: Linear,
    cond_a: Linear,
    cond_b: Linear,
    film: Linear,
    gate: Linear,
    norm: LayerNorm,
    frequencies: usize,
    width: usize,
}

impl Modulation {
    fn new(vb: VarBuilder, cfg: &SataConfig) -> candle_core::Result<Modulation> {
        let d = cfg.width;
        Ok(Modulation {
            spatial: Linear::new(vb.pp("spatial"), 12 * cfg.frequencies, d)?,
            text: Linear::new(vb.pp("text"), cfg.name_dim, d)?,
            cond_a: Linear::new(vb.pp("condition_a"), 2 * d, d)?,
            cond_b: Linear::new(vb.pp("condition_b"), d, d)?,
            film: Linear::new(vb.pp("film"), d, 2 * d)?,
            gate: Linear::new(vb.pp("gate"), d, d)?,
            norm: LayerNorm::new(vb.pp("norm"), d, cfg.ln_eps)?,
            frequencies: cfg.frequencies,
            width: d,
        })
    }

    /// The per-joint condition c, `[J, d]`.
    fn condition(&self, g: &SkeletonGraph) -> candle_core::Result<Tensor> {
        let zs = self.spatial.forward(&spatial_encoding(&g.statics, self.frequencies)?)?;
        let zt = self.text.forward(&g.names)?;
        self.cond_b.forward(&gelu(&self.cond_a.forward(&Tensor::cat(&[zs, zt], 1)?)?)?)
    }

    /// `z`: `[B, T, J, d]`, `c`: `[J, d]`.
    fn forward(&self, z: &Tensor, c: &Tensor) -> candle_core::Result<Tensor> {
        let d = self.width;
        let gb = self.film.forward(c)?;
        let (gamma, beta) = ((gb.narrow(1, 0, d)? + 1.0)?, gb.narrow(1, d, d)?);
        let gate = sigmoid(&self.gate.forward(c)?)?;
        let x = self.norm.forward(z)?.broadcast_mul(&gamma)?.broadcast_add(&beta)?;
        z + x.broadcast_mul(&gate)?
    }
}

#[derive(Clone, Debug)]
struct SelfAttention {
    query: Linear,
    key: Linear,
    value: Linear,
    out: Linear,
    heads: usize,
}

impl SelfAttention {
    fn new(vb: VarBuilder, cfg: &SataConfig) -> candle_core::Result<SelfAttention> {
        let d = cfg.width;
        let l = |name: &str| Linear::new(vb.pp(name), d, d);
        Ok(SelfAttention { query: l("query")?, key: l("key")?, value: l("value")?, out: l("out")?, heads: cfg.heads })
    }

    /// Full attention within each group of tokens of `x` (`[B, T, J, d]`, row-major).
    fn forward(&self, x: &Tensor, groups: Groups, keys: Keys) -> candle_core::Result<Tensor> {
        let dims = x.dims().to_vec();
        let d = dims[3];
        let qkv = project_qkv(&self.query, &self.key, &self.value, &x.reshape((dims[0] * dims[1] * dims[2], d))?)?;
        self.out.forward(&fused::attention(&qkv, None, groups, self.heads, keys)?)?.reshape(dims)
    }
}

/// Which groups attend and with which (all-visible) keys, for one batch shape.
struct Shape {
    b: usize,
    t: usize,
    j: usize,
    joints_ok: Keys,
    frames_ok: Keys,
}

impl Shape {
    fn new(b: usize, t: usize, j: usize) -> Shape {
        // A window wider than the group makes every token visible (no padding in our batches).
        Shape {
            b,
            t,
            j,
            joints_ok: Keys::Window { half: j, frame_ok: Arc::new(vec![true; b * j]) },
            frames_ok: Keys::Window { half: t, frame_ok: Arc::new(vec![true; b * t]) },
        }
    }
}

#[derive(Clone, Debug)]
struct Block {
    norm_spatial: LayerNorm,
    edge_a: Linear,
    edge_b: Linear,
    gine_a: Linear,
    gine_b: Linear,
    spatial: SelfAttention,
    norm_mix: LayerNorm,
    mix: FeedForward,
    norm_temporal: LayerNorm,
    temporal: SelfAttention,
    norm_ff: LayerNorm,
    ff: FeedForward,
}

impl Block {
    fn new(vb: VarBuilder, cfg: &SataConfig) -> candle_core::Result<Block> {
        let d = cfg.width;
        let ln = |name: &str| LayerNorm::new(vb.pp(name), d, cfg.ln_eps);
        Ok(Block {
            norm_spatial: ln("norm_spatial")?,
            edge_a: Linear::new(vb.pp("edge_a"), EDGE_DIMS, d)?,
            edge_b: Linear::new(vb.pp("edge_b"), d, d)?,
            gine_a: Linear::new(vb.pp("gine_a"), d, d)?,
            gine_b: Linear::new(vb.pp("gine_b"), d, d)?,
            spatial: SelfAttention::new(vb.pp("spatial"), cfg)?,
            norm_mix: ln("norm_mix")?,
            mix: FeedForward::new(vb.pp("mix"), d, cfg.ff)?,
            norm_temporal: ln("norm_temporal")?,
            temporal: SelfAttention::new(vb.pp("temporal"), cfg)?,
            norm_ff: ln("norm_ff")?,
            ff: FeedForward::new(vb.pp("ff"), d, cfg.ff)?,
        })
    }

    /// GINE: messages ReLU(x_src + MLP(edge)) summed per destination joint, then an MLP.
    fn gine(&self, x: &Tensor, g: &SkeletonGraph, s: &Shape) -> candle_core::Result<Tensor> {
        let d = x.dim(3)?;
        let rows = x.reshape((s.b * s.t, s.j, d))?;
        let edge = self.edge_b.forward(&self.edge_a.forward(&g.edges)?.relu()?)?; // [E, d]
        let messages = g.gather.broadcast_matmul(&rows)?.broadcast_add(&edge)?.relu()?; // [BT, E, d]
        let summed = g.scatter.broadcast_matmul(&messages)?; // [BT, J, d]
        self.gine_b.forward(&gelu(&self.gine_a.forward(&(rows + summed)?)?)?)?.reshape((s.b, s.t, s.j, d))
    }

    fn forward(&self, h: &Tensor, g: &SkeletonGraph, s: &Shape, positions: &Tensor) -> candle_core::Result<Tensor> {
        let x = self.norm_spatial.forward(h)?;
        let spatial = (self.gine(&x, g, s)? + self.spatial.forward(&x, Groups::joints(s.b, s.t, s.j), s.joints_ok.clone())?)?;
        let h = (h + spatial)?;
        let h = (&h + self.mix.forward(&self.norm_mix.forward(&h)?)?)?;
        let x = self.norm_temporal.forward(&h)?.broadcast_add(positions)?;
        let h = (&h + self.temporal.forward(&x, Groups::frames(s.b, s.t, s.j), s.frames_ok.clone())?)?;
        &h + self.ff.forward(&self.norm_ff.forward(&h)?)?
    }
}

/// `[T, 1, d]` sinusoidal frame positions, broadcast over joints.
fn frame_positions(t: usize, d: usize, device: &candle_core::Device) -> candle_core::Result<Tensor> {
    let p = Tensor::arange(0u32, t as u32, device)?.to_dtype(DType::F32)?;
    sinusoid(&p, d)?.reshape((t, 1, d))
}

#[derive(Clone, Debug)]
pub struct SataModel {
    cfg: SataConfig,
    motion_in: PerJointType,
    enc_modulation: Modulation,
    enc_blocks: Vec<Block>,
    enc_norm: LayerNorm,
    to_latent: Linear,
    from_latent: Linear,
    dec_modulation: Modulation,
    dec_blocks: Vec<Block>,
    dec_norm: LayerNorm,
    motion_out: PerJointType,
    readout: Option<Linear>,
}

impl SataModel {
    /// Parameters `encoder.{input.{root,joint},modulation.*,blocks.<k>.*,norm,latent}` and
    /// `decoder.{latent,modulation.*,blocks.<k>.*,norm,output.{root,joint}}`.
    pub fn new(vb: VarBuilder, cfg: &SataConfig) -> Result<SataModel, NnError> {
        cfg.validate()?;
        let d = cfg.width;
        let enc = vb.pp("encoder");
        let dec = vb.pp("decoder");
        let blocks = |vb: VarBuilder| (0..cfg.blocks).map(|k| Block::new(vb.pp("blocks").pp(k), cfg)).collect::<candle_core::Result<Vec<_>>>();
        Ok(SataModel {
            cfg: cfg.clone(),
            motion_in: PerJointType::new(enc.pp("input"), INPUT_DIMS, d)?,
            enc_modulation: Modulation::new(enc.pp("modulation"), cfg)?,
            enc_blocks: blocks(enc.clone())?,
            enc_norm: LayerNorm::new(enc.pp("norm"), d, cfg.ln_eps)?,
            to_latent: Linear::new(enc.pp("latent"), d, 2 * cfg.latent)?,
            from_latent: Linear::new(dec.pp("latent"), cfg.latent, d)?,
            dec_modulation: Modulation::new(dec.pp("modulation"), cfg)?,
            dec_blocks: blocks(dec.clone())?,
            dec_norm: LayerNorm::new(dec.pp("norm"), d, cfg.ln_eps)?,
            motion_out: PerJointType::new(dec.pp("output"), d, FEATURE_DIMS)?,
            readout: if cfg.direct_readout { Some(Linear::zeros(dec.pp("readout"), d, cfg.latent * FEATURE_DIMS)?) } else { None },
        })
    }

    pub fn config(&self) -> &SataConfig {
        &self.cfg
    }

    /// Mean and log-variance of the latent, each `[B, T, latent]`, of scaled features
    /// `[B, T, J, 13]` (offsets from the rest pose, `train::FeatureScale`) of the skeleton `g`.
    ///
    /// With `relative_latent`, the mean is taken relative to the latent of the rest pose
    /// standing still (scaled features all zero) through the same encoder: measured on the
    /// absolute latents of a 6,798-step model, a linear read-out of the latent fitted on one
    /// skeleton's clips recovered 86-97% of their joint-rotation variance while the decoder
    /// recovered 0-20% (it put out about the clip's mean pose): most of an absolute latent says
    /// which creature (latents of different creatures 9-10 apart, a latent moving by 0.2-0.3 per
    /// dimension over time), and the decoder, which is told the body anyway, read little else.
    /// Relative to the rest latent, zero means "this body at rest" on every skeleton.
    pub fn encode(&self, features: &Tensor, g: &SkeletonGraph) -> Result<(Tensor, Tensor), NnError> {
        let (b, t, j, f) = features.dims4()?;
        if f != FEATURE_DIMS || j != g.joints || t == 0 || b == 0 {
            return Err(NnError::Shape { what: "features", expected: format!("[B>0, T>0, {}, {FEATURE_DIMS}]", g.joints), got: features.dims().to_vec() });
        }
        if !self.cfg.relative_latent {
            return self.encode_absolute(features, g);
        }
        // One pass for the batch and the still rest pose together.
        let still = Tensor::zeros((1, t, j, f), DType::F32, features.device())?;
        let (mu, logvar) = self.encode_absolute(&Tensor::cat(&[features, &still], 0)?, g)?;
        let mu = mu.narrow(0, 0, b)?.broadcast_sub(&mu.narrow(0, b, 1)?)?;
        Ok((mu, logvar.narrow(0, 0, b)?))
    }

    fn encode_absolute(&self, features: &Tensor, g: &SkeletonGraph) -> Result<(Tensor, Tensor), NnError> {
        let (b, t, j, _) = features.dims4()?;
        let s = Shape::new(b, t, j);
        let c = self.enc_modulation.condition(g)?;
        let mut h = self.enc_modulation.forward(&self.motion_in.forward(&motion_input(features)?)?, &c)?;
        let positions = frame_positions(t, self.cfg.width, features.device())?;
        for block in &self.enc_blocks {
            h = block.forward(&h, g, &s, &positions)?;
        }
        // Spatial pooling: whatever the joint count, one vector per frame. The paper max-pools;
        // we add the mean: a max passes gradient to one joint per channel, and early in
        // training the same few joints win every channel, so the others' motion never reaches
        // the latent (a 500-step model learned the root's motion and no joint's rotation).
        let pooled = self.enc_norm.forward(&(h.max(2)? + h.mean(2)?)?)?;
        let stats = self.to_latent.forward(&pooled)?;
        let l = self.cfg.latent;
        let logvar = stats.narrow(D::Minus1, l, l)?.clamp(-12f32, 8f32)?;
        Ok((stats.narrow(D::Minus1, 0, l)?, logvar))
    }

    /// Scaled features `[B, T, J, 13]` (offsets from the rest pose, `train::FeatureScale`) of
    /// skeleton `g` from latents `[B, T, latent]`.
    pub fn decode(&self, z: &Tensor, g: &SkeletonGraph) -> Result<Tensor, NnError> {
        let (b, t, l) = z.dims3()?;
        if l != self.cfg.latent || t == 0 || b == 0 {
            return Err(NnError::Shape { what: "latents", expected: format!("[B>0, T>0, {}]", self.cfg.latent), got: z.dims().to_vec() });
        }
        let (j, d) = (g.joints, self.cfg.width);
        let s = Shape::new(b, t, j);
        let c = self.dec_modulation.condition(g)?;
        let h = self.from_latent.forward(z)?.unsqueeze(2)?.broadcast_as((b, t, j, d))?.contiguous()?;
        let mut h = self.dec_modulation.forward(&h, &c)?;
        let positions = frame_positions(t, d, z.device())?;
        for block in &self.dec_blocks {
            h = block.forward(&h, g, &s, &positions)?;
        }
        let y = self.motion_out.forward(&self.dec_norm.forward(&h)?)?;
        let Some(readout) = &self.readout else { return Ok(y) };
        // Beside the blocks, each joint reads the latent through its own matrix, made from its
        // condition c (a hypernetwork): y_j += z A(c_j), A(c_j) of shape [latent, 13]. Why:
        // measured on a 6,798-step model, a linear map fitted per skeleton recovered 81-96% of
        // the rotation variance of held-out frames of walks and runs from the latent, while the
        // decoder's output varied 4-20x less than the data (it put out about the mean pose); a
        // per-joint linear path cannot average the motion away, and it is made from the joint's
        // rest offsets and name, so it exists for any skeleton. With the relative latent, on
        // three zoo creatures of different topologies (biped, bird, quadruped; 1,000 steps at
        // lr 1e-3 from scratch, same seed), the scaled-feature loss of steps 901-1,000 was 0.106
        // against 0.212 without both, and the quadruped's walk came out moving (rotation error
        // 0.08 of the clip's variance at step 1,500) where without them it was still about
        // its mean pose (0.90) at step 1,000.
        let a = readout.forward(&c)?.reshape((j, l, FEATURE_DIMS))?.transpose(0, 1)?.contiguous()?.reshape((l, j * FEATURE_DIMS))?;
        let direct = z.reshape((b * t, l))?.matmul(&a)?.reshape((b, t, j, FEATURE_DIMS))?;
        Ok((y + direct)?)
    }
}

/// The model's motion input: the 13 features and the change of the 6D rotation since the
/// previous frame (zero at the first), SATA's rotational velocity.
pub fn motion_input(x: &Tensor) -> candle_core::Result<Tensor> {
    let (b, t, j, _) = x.dims4()?;
    let rot = x.narrow(3, 3, 6)?;
    let first = Tensor::zeros((b, 1, j, 6), DType::F32, x.device())?;
    let delta = if t > 1 { Tensor::cat(&[first, (rot.narrow(1, 1, t - 1)? - rot.narrow(1, 0, t - 1)?)?], 1)? } else { first };
    Tensor::cat(&[x.clone(), delta], 3)
}
