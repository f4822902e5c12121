//! AnyTop's denoiser (paper §3.2, reference facts in docs/reference/anytop.md §2): predicts the
//! clean motion x0 from a noised motion, the diffusion step and the skeleton.
//!
//! 1. Enrichment: each joint token is projected to `width` by its own linear (root and other
//!    joints separately, the rest-pose token P_S at t = 0 separately from motion frames); the
//!    projected joint-name embedding is added to every token of that joint; a sinusoidal
//!    temporal position is added per token (0 for P_S, k + 1 + `BatchItem::start` for frame k;
//!    training and sampling both give start 0, the reference gives training crops their start).
//! 2. `layers` skeletal-temporal layers, post-norm as the reference:
//!    `x += W_t·temb` (per-layer linear of the sinusoidal step embedding — the reference has no
//!    other timestep MLP); `x = LN1(x + SkeletalAttn(x))` over the joints of each frame with the
//!    GRPE topology terms; `x = LN2(x + TemporalAttn(x))` over the tokens of each joint within
//!    the window; `x = LN3(x + FF(x))`. No final norm.
//! 3. Output: root and other joints projected back to `feature_dims` by their own linears.
//!
//! Skeletal attention logits for head h, query joint i, key joint j (docs/reference/anytop.md
//! §2.4):
//! `(q_i·k_j + q_i·EqD[D_ij] + k_i·EkD[D_ij] + q_i·EqR[R_ij] + k_i·EkR[R_ij]) / sqrt(head_dim)`.
//! The key-side terms use k at the *query's* joint i, as the reference (GRPE's indexing) does;
//! the paper's formula writes k_j. Because every bias term is then a function of (i, type), it
//! is computed once per token, head and type (`fused::topology_coefficients`) and looked up by
//! (D_ij, R_ij) in the attention kernel.
//!
//! Padding (fixes the reference's mask-ordering bug, §9.1): padded joints are masked as keys
//! of the skeletal attention (per sample), padded frames as keys of the temporal attention,
//! padded inputs are zeroed and padded outputs are zero. Real joints of a sample never see
//! padding nor other samples, so a padded batch gives each clip the output it gets alone.

use super::config::{DenoiserConfig, RELATION_TYPES};
use super::fused::{self, Groups, Keys};
use super::layers::{sinusoid, FeedForward, LayerNorm, Linear};
use super::{Batch, NnError};
use candle_core::{DType, Tensor, D};
use candle_nn::{Init, VarBuilder};
use std::sync::Arc;

/// The skeletal attention's topology tables, `[types, d]` each (see `Denoiser::topology_tables`).
struct Tables {
    query: Tensor,
    key: Tensor,
}

/// Per-forward masks shared by all layers.
struct Context {
    b: usize,
    t: usize,
    j: usize,
    /// Skeletal attention: per (sample, query, key) the distance and relation type ids, and
    /// which joints are real.
    skeletal: Keys,
    /// Temporal attention: the window and which tokens are real.
    temporal: Keys,
}

/// `[rows, 3d]` queries, keys and values from one matmul against the stacked weights; `x` is
/// any shape with `d` last (its rows are all but the last dimension).
pub(crate) fn project_qkv(query: &Linear, key: &Linear, value: &Linear, x: &Tensor) -> candle_core::Result<Tensor> {
    let w = Tensor::cat(&[query.weight(), key.weight(), value.weight()], 0)?; // [3d, d]
    let b = Tensor::cat(&[query.bias(), key.bias(), value.bias()], 0)?;
    let d = x.dim(D::Minus1)?;
    fused::linear(x, &w, &b, Some((x.elem_count() / d.max(1), w.dim(0)?).into()))
}

#[derive(Clone, Debug)]
struct SkeletalAttention {
    query: Linear,
    key: Linear,
    value: Linear,
    out: Linear,
    heads: usize,
}

impl SkeletalAttention {
    fn new(vb: VarBuilder, cfg: &DenoiserConfig) -> candle_core::Result<SkeletalAttention> {
        let d = cfg.width;
        Ok(SkeletalAttention {
            query: Linear::new(vb.pp("query"), d, d)?,
            key: Linear::new(vb.pp("key"), d, d)?,
            value: Linear::new(vb.pp("value"), d, d)?,
            out: Linear::new(vb.pp("out"), d, d)?,
            heads: cfg.heads,
        })
    }

    /// `x`: `[B, T, J, d]`.
    fn forward(&self, x: &Tensor, ctx: &Context, tables: &Tables) -> candle_core::Result<Tensor> {
        let (b, t, j) = (ctx.b, ctx.t, ctx.j);
        let d = x.dim(D::Minus1)?;
        let qkv = project_qkv(&self.query, &self.key, &self.value, x)?;
        // c[row, h, type] = (q_i·Eq[type] + k_i·Ek[type]) / sqrt(dh): every topology term of
        // the logit (i, j) is c at the query's row for the pair's distance and relation type.
        let c = fused::topology_coefficients(&qkv, &tables.query, &tables.key, self.heads)?;
        let y = fused::attention(&qkv, Some(&c), Groups::joints(b, t, j), self.heads, ctx.skeletal.clone())?;
        self.out.forward_shaped(&y, (b, t, j, d))
    }
}

#[derive(Clone, Debug)]
struct TemporalAttention {
    query: Linear,
    key: Linear,
    value: Linear,
    out: Linear,
    heads: usize,
}

impl TemporalAttention {
    fn new(vb: VarBuilder, cfg: &DenoiserConfig) -> candle_core::Result<TemporalAttention> {
        let d = cfg.width;
        Ok(TemporalAttention {
            query: Linear::new(vb.pp("query"), d, d)?,
            key: Linear::new(vb.pp("key"), d, d)?,
            value: Linear::new(vb.pp("value"), d, d)?,
            out: Linear::new(vb.pp("out"), d, d)?,
            heads: cfg.heads,
        })
    }

    /// Tokens stay in `[B, T, J]` order: the kernel walks each joint's tokens with a stride.
    fn forward(&self, x: &Tensor, ctx: &Context) -> candle_core::Result<Tensor> {
        let (b, t, j) = (ctx.b, ctx.t, ctx.j);
        let d = x.dim(D::Minus1)?;
        let qkv = project_qkv(&self.query, &self.key, &self.value, x)?;
        let y = fused::attention(&qkv, None, Groups::frames(b, t, j), self.heads, ctx.temporal.clone())?;
        self.out.forward_shaped(&y, (b, t, j, d))
    }
}

#[derive(Clone, Debug)]
struct Layer {
    timestep: Linear,
    skeletal: SkeletalAttention,
    temporal: TemporalAttention,
    ff: FeedForward,
    norm1: LayerNorm,
    norm2: LayerNorm,
    norm3: LayerNorm,
}

impl Layer {
    fn new(vb: VarBuilder, cfg: &DenoiserConfig) -> candle_core::Result<Layer> {
        let d = cfg.width;
        Ok(Layer {
            timestep: Linear::new(vb.pp("timestep"), d, d)?,
            skeletal: SkeletalAttention::new(vb.pp("skeletal"), cfg)?,
            temporal: TemporalAttention::new(vb.pp("temporal"), cfg)?,
            ff: FeedForward::new(vb.pp("ff"), d, cfg.ff)?,
            norm1: LayerNorm::new(vb.pp("norm1"), d, cfg.ln_eps)?,
            norm2: LayerNorm::new(vb.pp("norm2"), d, cfg.ln_eps)?,
            norm3: LayerNorm::new(vb.pp("norm3"), d, cfg.ln_eps)?,
        })
    }

    /// `temb`: `[B, 1, 1, d]`.
    fn forward(&self, x: &Tensor, temb: &Tensor, ctx: &Context, tables: &Tables) -> candle_core::Result<Tensor> {
        let x = fused::add_broadcast(x, &self.timestep.forward(temb)?, x.dim(0)?)?;
        let x = self.norm1.forward(&(&x + self.skeletal.forward(&x, ctx, tables)?)?)?;
        let x = self.norm2.forward(&(&x + self.temporal.forward(&x, ctx)?)?)?;
        self.norm3.forward(&(&x + self.ff.forward(&x)?)?)
    }
}

/// Root (joint 0) and other joints through separate linears, as the reference (SATA's input
/// and output layers too).
#[derive(Clone, Debug)]
pub(crate) struct PerJointType {
    root: Linear,
    joint: Linear,
}

impl PerJointType {
    pub(crate) fn new(vb: VarBuilder, inputs: usize, outputs: usize) -> candle_core::Result<PerJointType> {
        Ok(PerJointType { root: Linear::new(vb.pp("root"), inputs, outputs)?, joint: Linear::new(vb.pp("joint"), inputs, outputs)? })
    }

    /// `x`: `[B, T, J, inputs]` -> `[B, T, J, outputs]`.
    pub(crate) fn forward(&self, x: &Tensor) -> candle_core::Result<Tensor> {
        let j = x.dim(2)?;
        let root = self.root.forward(&x.narrow(2, 0, 1)?)?;
        if j == 1 {
            return Ok(root);
        }
        let rest = self.joint.forward(&x.narrow(2, 1, j - 1)?)?;
        Tensor::cat(&[root, rest], 2)
    }
}

/// `x` where `mask` (broadcast to `x`) is non-zero, 0 elsewhere.
fn zero_where_masked(x: &Tensor, mask: &Tensor) -> candle_core::Result<Tensor> {
    let keep = mask.ne(0f32)?.broadcast_as(x.shape())?.contiguous()?;
    keep.where_cond(x, &x.zeros_like()?)
}

#[derive(Clone, Debug)]
pub struct Denoiser {
    cfg: DenoiserConfig,
    motion_in: PerJointType,
    rest_in: PerJointType,
    names_in: Linear,
    distance_query: Tensor,
    distance_key: Tensor,
    relation_query: Tensor,
    relation_key: Tensor,
    layers: Vec<Layer>,
    out: PerJointType,
}

impl Denoiser {
    /// Builds (or loads, depending on `vb`'s backend) the parameters, named
    /// `input.{motion,rest}.{root,joint}`, `input.names`, `topology.{distance,relation}_{query,key}`,
    /// `layers.<l>.{timestep,skeletal.*,temporal.*,ff.{up,down},norm1..3}`, `output.{root,joint}`.
    /// Use [`super::seeded_var_builder`] for a reproducible fresh model.
    pub fn new(vb: VarBuilder, cfg: &DenoiserConfig) -> Result<Denoiser, NnError> {
        cfg.validate()?;
        let d = cfg.width;
        let input = vb.pp("input");
        let topo = vb.pp("topology");
        // PyTorch's nn.Embedding default, N(0, 1), as the reference's four tables.
        let table = |name: &str, rows: usize| topo.get_with_hints((rows, d), name, Init::Randn { mean: 0.0, stdev: 1.0 });
        Ok(Denoiser {
            cfg: cfg.clone(),
            motion_in: PerJointType::new(input.pp("motion"), cfg.feature_dims, d)?,
            rest_in: PerJointType::new(input.pp("rest"), cfg.feature_dims, d)?,
            names_in: Linear::new(input.pp("names"), cfg.name_dim, d)?,
            distance_query: table("distance_query", cfg.dmax + 1)?,
            distance_key: table("distance_key", cfg.dmax + 1)?,
            relation_query: table("relation_query", RELATION_TYPES)?,
            relation_key: table("relation_key", RELATION_TYPES)?,
            layers: (0..cfg.layers).map(|l| Layer::new(vb.pp("layers").pp(l), cfg)).collect::<candle_core::Result<_>>()?,
            out: PerJointType::new(vb.pp("output"), d, cfg.feature_dims)?,
        })
    }

    pub fn config(&self) -> &DenoiserConfig {
        &self.cfg
    }

    /// x0 prediction `[B, T, J, dims]`. Token 0 echoes the input rest-pose row P_S unchanged
    /// (it is conditioning, not predicted), so the output lines up with `batch.x`; padded
    /// joints and frames are 0.
    pub fn forward(&self, batch: &Batch) -> Result<Tensor, NnError> {
        Ok(self.forward_with_activations(batch, &[])?.0)
    }

    /// `forward` plus the activations after each layer in `keep_layers` (0-based, in the given
    /// order), each `[B, T, J, width]` including the P_S token — DIFT features.
    pub fn forward_with_activations(&self, batch: &Batch, keep_layers: &[usize]) -> Result<(Tensor, Vec<Tensor>), NnError> {
        if let Some(&l) = keep_layers.iter().find(|&&l| l >= self.cfg.layers) {
            return Err(NnError::Layer { requested: l, layers: self.cfg.layers });
        }
        let mut kept = vec![None; keep_layers.len()];
        let (h, x, token_mask) = self.run_layers(batch, self.cfg.layers, |l, h| {
            for (slot, _) in keep_layers.iter().enumerate().filter(|(_, &k)| k == l) {
                kept[slot] = Some(h.clone());
            }
        })?;
        let t = x.dim(1)?;
        let y = self.out.forward(&h.narrow(1, 1, t - 1)?)?;
        let y = Tensor::cat(&[x.narrow(1, 0, 1)?, y], 1)?.broadcast_mul(&token_mask)?;
        Ok((y, kept.into_iter().flatten().collect()))
    }

    /// The activations after layer `layer` alone, `[B, T, J, width]` with the P_S token, without
    /// running the later layers or the output head: DIFT features at a fraction of a forward.
    pub fn activations(&self, batch: &Batch, layer: usize) -> Result<Tensor, NnError> {
        if layer >= self.cfg.layers {
            return Err(NnError::Layer { requested: layer, layers: self.cfg.layers });
        }
        Ok(self.run_layers(batch, layer + 1, |_, _| {})?.0)
    }

    /// Enrichment and the first `layers` layers (calling `visit(l, h)` after each): the hidden
    /// state, the zero-padded input and the token mask `[B, T, J, 1]`.
    fn run_layers(&self, batch: &Batch, layers: usize, mut visit: impl FnMut(usize, &Tensor)) -> Result<(Tensor, Tensor, Tensor), NnError> {
        let (b, t, j) = self.check(batch)?;
        let ctx = self.context(batch, b, t, j)?;
        let token_mask = batch.frame_mask.reshape((b, t, 1, 1))?.broadcast_mul(&batch.joint_mask.reshape((b, 1, j, 1))?)?;
        // Replacing padded inputs by zeros (a select, not a product: NaN * 0 is NaN) keeps them
        // finite whatever the caller left there; a NaN or inf would survive multiplication by a
        // zero attention weight.
        let x = zero_where_masked(&batch.x, &token_mask)?;
        let rest = self.rest_in.forward(&x.narrow(1, 0, 1)?)?;
        let motion = self.motion_in.forward(&x.narrow(1, 1, t - 1)?)?;
        let names = zero_where_masked(&batch.names, &batch.joint_mask.unsqueeze(2)?)?;
        let h = Tensor::cat(&[rest, motion], 1)?;
        let mut h = fused::add_broadcast(&h, &self.names_in.forward(&names)?, b)?.broadcast_add(&sinusoid(&batch.positions, self.cfg.width)?.unsqueeze(2)?)?;
        let temb = sinusoid(&batch.timesteps.to_dtype(DType::F32)?, self.cfg.width)?.reshape((b, 1, 1, self.cfg.width))?;
        let tables = self.topology_tables()?;
        for (l, layer) in self.layers.iter().take(layers).enumerate() {
            h = layer.forward(&h, &temb, &ctx, &tables)?;
            visit(l, &h);
        }
        Ok((h, x, token_mask))
    }

    /// Shapes of every batch tensor against `x`'s `(B, T, J)`.
    fn check(&self, batch: &Batch) -> Result<(usize, usize, usize), NnError> {
        let shape = |what: &'static str, t: &Tensor, want: &[usize]| -> Result<(), NnError> {
            if t.dims() != want {
                return Err(NnError::Shape { what, expected: format!("{want:?}"), got: t.dims().to_vec() });
            }
            Ok(())
        };
        let dims = batch.x.dims();
        if dims.len() != 4 || dims[3] != self.cfg.feature_dims || dims[1] < 2 || dims[0] == 0 || dims[2] == 0 {
            return Err(NnError::Shape { what: "x", expected: format!("[B>0, T>=2, J>0, {}]", self.cfg.feature_dims), got: dims.to_vec() });
        }
        let (b, t, j) = (dims[0], dims[1], dims[2]);
        shape("timesteps", &batch.timesteps, &[b])?;
        shape("names", &batch.names, &[b, j, self.cfg.name_dim])?;
        shape("relations", &batch.relations, &[b, j, j])?;
        shape("distances", &batch.distances, &[b, j, j])?;
        shape("joint_mask", &batch.joint_mask, &[b, j])?;
        shape("frame_mask", &batch.frame_mask, &[b, t])?;
        shape("positions", &batch.positions, &[b, t])?;
        Ok((b, t, j))
    }

    fn context(&self, batch: &Batch, b: usize, t: usize, j: usize) -> Result<Context, NnError> {
        let dmax = self.cfg.dmax;
        let dist: Vec<u32> = batch.distances.to_dtype(DType::U32)?.flatten_all()?.to_vec1()?;
        let rel: Vec<u32> = batch.relations.to_dtype(DType::U32)?.flatten_all()?.to_vec1()?;
        // Distances beyond dmax share the dmax row; an unknown relation id (> 5) adds no bias.
        let types = dist
            .iter()
            .zip(&rel)
            .map(|(&d, &r)| [d.min(dmax as u32) as u16, if (r as usize) < RELATION_TYPES { (dmax + 1) as u16 + r as u16 } else { fused::NO_TYPE }])
            .collect();
        let real =
            |m: &Tensor| -> candle_core::Result<Vec<bool>> { Ok(m.to_dtype(DType::F32)?.flatten_all()?.to_vec1::<f32>()?.iter().map(|&v| v != 0.0).collect()) };
        let skeletal = Keys::Topology { types: Arc::new(types), key_ok: Arc::new(real(&batch.joint_mask)?), type_count: dmax + 1 + RELATION_TYPES };
        let temporal = Keys::Window { half: self.cfg.window / 2, frame_ok: Arc::new(real(&batch.frame_mask)?) };
        Ok(Context { b, t, j, skeletal, temporal })
    }

    /// The topology tables as `[types, d]` query and key tables (types: the `dmax + 1`
    /// distances, then the 6 relations), for `fused::topology_coefficients`.
    fn topology_tables(&self) -> candle_core::Result<Tables> {
        Ok(Tables { query: Tensor::cat(&[&self.distance_query, &self.relation_query], 0)?, key: Tensor::cat(&[&self.distance_key, &self.relation_key], 0)? })
    }
}
