//! Fused CPU kernels with their own backward pass: multi-head attention and layer norm.
//!
//! Why: built from candle's basic ops, one attention layer is some twenty passes over the
//! J x J and T x T logit tensors (bias add, max, subtract, exp, sum, divide, their backward
//! passes, permutes to and from the head layout), each into a freshly allocated tensor. On our
//! CPUs that made the model run at 3-10% of matmul peak (benches/nn.rs). Here one loop per
//! (group, head) computes the probabilities in a small scratch buffer, recomputes them in the
//! backward pass instead of storing them, and reads queries, keys and values straight from the
//! `[rows, 3 * width]` output of the fused q/k/v projection, so no head split, merge or
//! transpose is ever materialised.
//!
//! (candle-nn's fused softmax / layer norm / sdpa have no CPU backward, see `layers`; these do,
//! and `tests` checks them against the composition of basic ops, values and gradients.)

use candle_core::{CpuStorage, CustomOp1, CustomOp2, CustomOp3, Layout, Result, Shape, Tensor};
use std::sync::Arc;

/// Which token rows form one attention problem ("group"), and where each token's row is in the
/// `[rows, ...]` token matrix: token `i` of group `g` is row
/// `(g / inner) * outer_stride + (g % inner) * inner_stride + i * pos_stride`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Groups {
    pub groups: usize,
    pub len: usize,
    pub inner: usize,
    pub outer_stride: usize,
    pub inner_stride: usize,
    pub pos_stride: usize,
    /// Groups per batch sample, to find a group's sample for the key masks.
    pub per_sample: usize,
}

impl Groups {
    /// Tokens `[B, T, J]` (row-major), attention over the J joints of each frame.
    pub fn joints(b: usize, t: usize, j: usize) -> Groups {
        Groups { groups: b * t, len: j, inner: 1, outer_stride: j, inner_stride: 0, pos_stride: 1, per_sample: t }
    }

    /// Tokens `[B, T, J]` (row-major), attention over the T tokens of each joint.
    pub fn frames(b: usize, t: usize, j: usize) -> Groups {
        Groups { groups: b * j, len: t, inner: j, outer_stride: t * j, inner_stride: 1, pos_stride: j, per_sample: j }
    }

    fn rows(&self) -> usize {
        self.groups * self.len
    }

    #[inline(always)]
    fn row(&self, g: usize, i: usize) -> usize {
        (g / self.inner) * self.outer_stride + (g % self.inner) * self.inner_stride + i * self.pos_stride
    }
}

/// Which keys a query may attend, and the additive bias of the skeletal attention.
#[derive(Clone, Debug)]
pub enum Keys {
    /// Skeletal attention: key joint k is visible when real (`key_ok[b * J + k]`); the logit of
    /// (i, k) gets `c[row(i), h, a] + c[row(i), h, b]` for the two type ids
    /// `types[(b * J + i) * J + k] = [a, b]` (distance type, relation type); `NO_TYPE` adds nothing.
    Topology { types: Arc<Vec<[u16; 2]>>, key_ok: Arc<Vec<bool>>, type_count: usize },
    /// Windowed temporal attention: key k is visible from query i when the token is real
    /// (`frame_ok[b * T + k]`) and `k == 0` (the rest-pose token, §2.5) or `|i - k| <= half`.
    /// The reference's window is [i-15, i+16], one wider on the right; we keep it symmetric.
    Window { half: usize, frame_ok: Arc<Vec<bool>> },
}

/// A type id that contributes no bias (an unknown relation).
pub const NO_TYPE: u16 = u16::MAX;

/// The attention problem: shapes, heads, scale and masks.
#[derive(Debug)]
struct Attention {
    groups: Groups,
    heads: usize,
    head_dim: usize,
    scale: f32,
    keys: Keys,
    /// When the result takes part in a backward pass, the forward keeps every (group, head)
    /// probability block here (`groups x heads x len x len`) so the backward need not
    /// recompute them: the exponentials were a third of its time. Sampling keeps nothing.
    saved: Option<std::sync::Mutex<Vec<f32>>>,
}

fn f32_slice<'a>(s: &'a CpuStorage, l: &Layout, what: &str) -> Result<&'a [f32]> {
    let CpuStorage::F32(data) = s else {
        candle_core::bail!("{what}: fused kernels take f32 tensors");
    };
    match l.contiguous_offsets() {
        Some((start, end)) => Ok(&data[start..end]),
        None => candle_core::bail!("{what}: fused kernels take contiguous tensors"),
    }
}

fn values(t: &Tensor) -> Result<Vec<f32>> {
    t.flatten_all()?.to_vec1::<f32>()
}

impl Attention {
    fn width(&self) -> usize {
        self.heads * self.head_dim
    }

    fn check(&self, qkv: &[f32], c: Option<&[f32]>) -> Result<()> {
        let rows = self.groups.rows();
        if qkv.len() != rows * 3 * self.width() {
            candle_core::bail!("fused attention: q/k/v has {} values, expected {rows} x {}", qkv.len(), 3 * self.width());
        }
        if let (Keys::Topology { type_count, .. }, Some(c)) = (&self.keys, c) {
            if c.len() != rows * self.heads * type_count {
                candle_core::bail!("fused attention: bias coefficients have {} values, expected {rows} x {} x {type_count}", c.len(), self.heads);
            }
        }
        Ok(())
    }

    /// The keys query `i` can see at most: `lo..hi`, plus key 0 when `lo > 0` (the rest-pose
    /// token of the temporal window). Keys inside may still be masked (padding).
    #[inline(always)]
    fn span(&self, i: usize) -> (usize, usize) {
        let n = self.groups.len;
        match &self.keys {
            Keys::Topology { .. } => (0, n),
            Keys::Window { half, .. } => (i.saturating_sub(*half), (i + half + 1).min(n)),
        }
    }

    /// Gathers group `g`'s head `h` into `s`: queries (pre-scaled), keys, keys transposed and
    /// values, each `len x dh` (transposed: `dh x len`), so the loops below run over
    /// contiguous memory.
    #[inline(always)]
    fn gather(&self, qkv: &[f32], h: usize, s: &mut Scratch) {
        let (n, dh, w) = (self.groups.len, self.head_dim, self.width());
        for i in 0..n {
            let r = s.rows[i] * 3 * w + h * dh;
            for e in 0..dh {
                s.q[i * dh + e] = qkv[r + e] * self.scale;
                let k = qkv[r + w + e];
                s.k[i * dh + e] = k;
                s.kt[e * n + i] = k;
                let v = qkv[r + 2 * w + e];
                s.v[i * dh + e] = v;
                s.vt[e * n + i] = v;
            }
        }
    }

    /// Attention probabilities of the gathered group (`g`, head `h`) into `s.p` (`len x len`,
    /// row = query; invisible keys 0). A query without any visible key (never the case for our
    /// masks) gets a zero row.
    #[inline(always)]
    fn probabilities(&self, c: Option<&[f32]>, g: usize, h: usize, s: &mut Scratch) {
        let (n, dh) = (self.groups.len, self.head_dim);
        let sample = g / self.groups.per_sample;
        for i in 0..n {
            let (lo, hi) = self.span(i);
            let row = &mut s.p[i * n..(i + 1) * n];
            row.fill(0.0);
            // Logits q_i·k over the span: one axpy per head dimension (vectorises over keys).
            for e in 0..dh {
                let qe = s.q[i * dh + e];
                let kt = &s.kt[e * n..(e + 1) * n];
                row[lo..hi].iter_mut().zip(&kt[lo..hi]).for_each(|(o, k)| *o += qe * k);
                if lo > 0 {
                    row[0] += qe * kt[0];
                }
            }
            match &self.keys {
                Keys::Topology { types, key_ok, type_count } => {
                    let at = (s.rows[i] * self.heads + h) * type_count;
                    let keys_ok = &key_ok[sample * n..(sample + 1) * n];
                    let pair_types = &types[(sample * n + i) * n..(sample * n + i + 1) * n];
                    for ((v, &ok), &[a, b]) in row.iter_mut().zip(keys_ok).zip(pair_types) {
                        if !ok {
                            *v = f32::NEG_INFINITY;
                            continue;
                        }
                        if let Some(c) = c {
                            if a != NO_TYPE {
                                *v += c[at + a as usize];
                            }
                            if b != NO_TYPE {
                                *v += c[at + b as usize];
                            }
                        }
                    }
                }
                Keys::Window { frame_ok, .. } => {
                    let tokens_ok = &frame_ok[sample * n..(sample + 1) * n];
                    for k in (lo..hi).chain((lo > 0).then_some(0)) {
                        if !tokens_ok[k] {
                            row[k] = f32::NEG_INFINITY;
                        }
                    }
                }
            }
            // Only the span (and key 0) can be visible: everything else stays 0, which saves
            // the exponentials and value rows of the 90 keys outside a 31-frame window when
            // sampling 120 frames.
            let max = row[lo..hi].iter().fold(if lo > 0 { row[0] } else { f32::NEG_INFINITY }, |m, &v| m.max(v));
            if max == f32::NEG_INFINITY {
                row.fill(0.0);
                continue;
            }
            row[lo..hi].iter_mut().for_each(|v| *v = exp(*v - max));
            let mut sum = sum(&row[lo..hi]);
            if lo > 0 {
                row[0] = exp(row[0] - max);
                sum += row[0];
            }
            let inv = 1.0 / sum;
            row[lo..hi].iter_mut().for_each(|v| *v *= inv);
            if lo > 0 {
                row[0] *= inv;
            }
        }
    }

    fn forward(&self, qkv: &[f32], c: Option<&[f32]>) -> Result<Vec<f32>> {
        self.check(qkv, c)?;
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `forward_avx2` is compiled for.
            return Ok(unsafe { self.forward_avx2(qkv, c) });
        }
        Ok(self.forward_body(qkv, c))
    }

    /// The same loops compiled for 8-wide vectors (the default target has 4-wide SSE only).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn forward_avx2(&self, qkv: &[f32], c: Option<&[f32]>) -> Vec<f32> {
        self.forward_body(qkv, c)
    }

    #[inline(always)]
    fn forward_body(&self, qkv: &[f32], c: Option<&[f32]>) -> Vec<f32> {
        let mut saved = self.saved.as_ref().map(|m| m.lock().unwrap_or_else(|e| e.into_inner()));
        if let Some(buf) = saved.as_mut() {
            buf.clear();
            buf.resize(self.groups.groups * self.heads * self.groups.len * self.groups.len, 0.0);
        }
        let (n, dh, w) = (self.groups.len, self.head_dim, self.width());
        let mut y = vec![0f32; self.groups.rows() * w];
        let mut s = Scratch::new(n, dh);
        for g in 0..self.groups.groups {
            s.fill_rows(&self.groups, g);
            for h in 0..self.heads {
                self.gather(qkv, h, &mut s);
                self.probabilities(c, g, h, &mut s);
                if let Some(buf) = saved.as_mut() {
                    buf[(g * self.heads + h) * n * n..(g * self.heads + h + 1) * n * n].copy_from_slice(&s.p);
                }
                for i in 0..n {
                    let yi = s.rows[i] * w + h * dh;
                    let out = &mut y[yi..yi + dh];
                    let (lo, hi) = self.span(i);
                    let prow = &s.p[i * n..(i + 1) * n];
                    // y_i[e] = sum_k P_ik v_k[e]: a dot product over the visible keys per head
                    // dimension, on the transposed values (long contiguous runs, not dh-long ones).
                    for (e, o) in out.iter_mut().enumerate() {
                        let vt = &s.vt[e * n..(e + 1) * n];
                        *o = dot(&prow[lo..hi], &vt[lo..hi]) + if lo > 0 { prow[0] * vt[0] } else { 0.0 };
                    }
                }
            }
        }
        y
    }

    /// Gradients of q/k/v (`[rows, 3w]`) and, for the topology bias, of `c`. The probabilities
    /// are recomputed rather than kept from the forward pass: cheaper than storing them.
    fn backward(&self, qkv: &[f32], c: Option<&[f32]>, dy: &[f32]) -> Result<(Vec<f32>, Option<Vec<f32>>)> {
        self.check(qkv, c)?;
        if dy.len() != self.groups.rows() * self.width() {
            candle_core::bail!("fused attention: output gradient has {} values, expected {}", dy.len(), self.groups.rows() * self.width());
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `backward_avx2` is compiled for.
            return Ok(unsafe { self.backward_avx2(qkv, c, dy) });
        }
        Ok(self.backward_body(qkv, c, dy))
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn backward_avx2(&self, qkv: &[f32], c: Option<&[f32]>, dy: &[f32]) -> (Vec<f32>, Option<Vec<f32>>) {
        self.backward_body(qkv, c, dy)
    }

    #[inline(always)]
    fn backward_body(&self, qkv: &[f32], c: Option<&[f32]>, dy: &[f32]) -> (Vec<f32>, Option<Vec<f32>>) {
        let saved = self.saved.as_ref().map(|m| m.lock().unwrap_or_else(|e| e.into_inner()));
        let (n, dh, w) = (self.groups.len, self.head_dim, self.width());
        let mut dqkv = vec![0f32; qkv.len()];
        let mut dc = c.map(|c| vec![0f32; c.len()]);
        let mut s = Scratch::new(n, dh);
        // Transposed gradients (`dh x len`) and dS (`len x len`) and its transpose, so that every
        // inner loop is an axpy over keys or queries on contiguous memory.
        let (mut dqt, mut dkt, mut dvt) = (vec![0f32; n * dh], vec![0f32; n * dh], vec![0f32; n * dh]);
        let (mut ds, mut dst) = (vec![0f32; n * n], vec![0f32; n * n]);
        let mut dyg = vec![0f32; n * dh];
        for g in 0..self.groups.groups {
            let sample = g / self.groups.per_sample;
            s.fill_rows(&self.groups, g);
            for h in 0..self.heads {
                self.gather(qkv, h, &mut s);
                match saved.as_ref().filter(|b| b.len() == self.groups.groups * self.heads * n * n) {
                    Some(buf) => s.p.copy_from_slice(&buf[(g * self.heads + h) * n * n..(g * self.heads + h + 1) * n * n]),
                    None => self.probabilities(c, g, h, &mut s),
                }
                for i in 0..n {
                    let r = s.rows[i] * w + h * dh;
                    dyg[i * dh..(i + 1) * dh].copy_from_slice(&dy[r..r + dh]);
                }
                dqt.fill(0.0);
                dkt.fill(0.0);
                dvt.fill(0.0);
                for i in 0..n {
                    let prow = &s.p[i * n..(i + 1) * n];
                    let dyi = &dyg[i * dh..(i + 1) * dh];
                    let dsrow = &mut ds[i * n..(i + 1) * n];
                    // dP_ik = dy_i · v_k, dS_ik = P_ik (dP_ik - sum_k P_ik dP_ik).
                    dsrow.fill(0.0);
                    for (e, &d) in dyi.iter().enumerate() {
                        dsrow.iter_mut().zip(&s.vt[e * n..(e + 1) * n]).for_each(|(o, v)| *o += d * v);
                        // dV^T[e] += dy_i[e] P_i
                        dvt[e * n..(e + 1) * n].iter_mut().zip(prow).for_each(|(o, p)| *o += d * p);
                    }
                    let dot_pd: f32 = prow.iter().zip(dsrow.iter()).map(|(p, d)| p * d).sum();
                    dsrow.iter_mut().zip(prow).for_each(|(d, p)| *d = p * (*d - dot_pd));
                    // With pre-scaled queries qs the logits are qs·k: dK^T[e] += qs_i[e] dS_i.
                    for e in 0..dh {
                        let q = s.q[i * dh + e];
                        dkt[e * n..(e + 1) * n].iter_mut().zip(dsrow.iter()).for_each(|(o, d)| *o += q * d);
                    }
                    if let (Some(dc), Keys::Topology { types, type_count, .. }) = (dc.as_mut(), &self.keys) {
                        let at = (s.rows[i] * self.heads + h) * type_count;
                        let pair_types = &types[(sample * n + i) * n..(sample * n + i + 1) * n];
                        for (&d, &[a, b]) in dsrow.iter().zip(pair_types) {
                            if a != NO_TYPE {
                                dc[at + a as usize] += d;
                            }
                            if b != NO_TYPE {
                                dc[at + b as usize] += d;
                            }
                        }
                    }
                }
                // dQs^T[e][i] = sum_k K[k][e] dS[i][k]: through dS^T, again axpys over queries.
                for i in 0..n {
                    for k in 0..n {
                        dst[k * n + i] = ds[i * n + k];
                    }
                }
                for k in 0..n {
                    let col = &dst[k * n..(k + 1) * n];
                    for e in 0..dh {
                        let kv = s.k[k * dh + e];
                        dqt[e * n..(e + 1) * n].iter_mut().zip(col).for_each(|(o, d)| *o += kv * d);
                    }
                }
                for i in 0..n {
                    let r = s.rows[i] * 3 * w + h * dh;
                    for e in 0..dh {
                        dqkv[r + e] += dqt[e * n + i] * self.scale;
                        dqkv[r + w + e] += dkt[e * n + i];
                        dqkv[r + 2 * w + e] += dvt[e * n + i];
                    }
                }
            }
        }
        (dqkv, dc)
    }
}

/// `e^x` for `x <= 0` (softmax arguments after subtracting the row maximum), written so the
/// compiler vectorises a loop of it: libm's `expf` is a call per element, and was a tenth of
/// the attention time. Range reduction x = n ln2 + r (|r| <= ln2/2, ln2 split in two parts
/// for precision), a degree-6 Taylor polynomial for e^r (relative error < 2e-7 there), and
/// 2^n built in the exponent bits. Below -87 (including -inf, masked keys) the result is
/// exactly 0, as a masked key must contribute nothing.
#[inline(always)]
fn exp(x: f32) -> f32 {
    let xc = x.max(-87.0);
    let n = (xc * std::f32::consts::LOG2_E).round();
    let r = xc - n * 0.693_145_75 - n * 1.428_606_8e-6;
    let p = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    let scale = f32::from_bits(((n as i32 + 127) as u32) << 23);
    if x < -87.0 {
        0.0
    } else {
        p * scale
    }
}

/// Sum with eight independent partial sums (vectorisable, see `dot`).
#[inline(always)]
fn sum(a: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let chunks = a.chunks_exact(8);
    let tail: f32 = chunks.remainder().iter().sum();
    for x in chunks {
        for l in 0..8 {
            acc[l] += x[l];
        }
    }
    acc.iter().sum::<f32>() + tail
}

/// `a · b` with eight independent partial sums, which the compiler keeps in one vector
/// register (a plain running sum has to stay in order and cannot be vectorised).
#[inline(always)]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f32 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += x[l] * y[l];
        }
    }
    acc.iter().sum::<f32>() + tail
}

/// Per-(group, head) buffers, reused across groups.
struct Scratch {
    q: Vec<f32>,
    k: Vec<f32>,
    kt: Vec<f32>,
    v: Vec<f32>,
    vt: Vec<f32>,
    p: Vec<f32>,
    /// Token row of each position of the current group.
    rows: Vec<usize>,
}

impl Scratch {
    fn new(n: usize, dh: usize) -> Scratch {
        Scratch { q: vec![0.0; n * dh], k: vec![0.0; n * dh], kt: vec![0.0; n * dh], v: vec![0.0; n * dh], vt: vec![0.0; n * dh], p: vec![0.0; n * n], rows: vec![0; n] }
    }

    fn fill_rows(&mut self, groups: &Groups, g: usize) {
        for (i, r) in self.rows.iter_mut().enumerate() {
            *r = groups.row(g, i);
        }
    }
}

fn output_shape(att: &Attention) -> Shape {
    Shape::from((att.groups.rows(), att.width()))
}

impl CustomOp1 for Attention {
    fn name(&self) -> &'static str {
        "fused-attention"
    }

    fn cpu_fwd(&self, s: &CpuStorage, l: &Layout) -> Result<(CpuStorage, Shape)> {
        let y = self.forward(f32_slice(s, l, "q/k/v")?, None)?;
        Ok((CpuStorage::F32(y), output_shape(self)))
    }

    fn bwd(&self, qkv: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<Option<Tensor>> {
        let (d, _) = self.backward(&values(qkv)?, None, &values(grad)?)?;
        Ok(Some(Tensor::from_vec(d, qkv.shape(), qkv.device())?))
    }
}

impl CustomOp2 for Attention {
    fn name(&self) -> &'static str {
        "fused-attention-bias"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout, s2: &CpuStorage, l2: &Layout) -> Result<(CpuStorage, Shape)> {
        let y = self.forward(f32_slice(s1, l1, "q/k/v")?, Some(f32_slice(s2, l2, "bias coefficients")?))?;
        Ok((CpuStorage::F32(y), output_shape(self)))
    }

    fn bwd(&self, qkv: &Tensor, c: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<(Option<Tensor>, Option<Tensor>)> {
        let cv = values(c)?;
        let (d, dc) = self.backward(&values(qkv)?, Some(&cv), &values(grad)?)?;
        let dc = dc.map(|v| Tensor::from_vec(v, c.shape(), c.device())).transpose()?;
        Ok((Some(Tensor::from_vec(d, qkv.shape(), qkv.device())?), dc))
    }
}

/// Multi-head attention over the groups of `qkv` (`[rows, 3 * heads * head_dim]`: all queries,
/// then all keys, then all values, head-major inside each), scaled by `1/sqrt(head_dim)`.
/// `bias`: `[rows, heads * type_count]` coefficients for [`Keys::Topology`], `None` for
/// [`Keys::Window`]. Returns `[rows, heads * head_dim]` with the heads merged.
pub fn attention(qkv: &Tensor, bias: Option<&Tensor>, groups: Groups, heads: usize, keys: Keys) -> Result<Tensor> {
    let (rows, w3) = qkv.dims2()?;
    if rows != groups.rows() || w3 % (3 * heads.max(1)) != 0 {
        candle_core::bail!("fused attention: q/k/v is {rows} x {w3}, expected {} rows and a multiple of {}", groups.rows(), 3 * heads);
    }
    let head_dim = w3 / 3 / heads;
    let tracked = qkv.track_op() || bias.is_some_and(|b| b.track_op());
    let saved = tracked.then(|| std::sync::Mutex::new(Vec::new()));
    let att = Attention { groups, heads, head_dim, scale: 1.0 / (head_dim as f32).sqrt(), keys, saved };
    let qkv = qkv.contiguous()?;
    match (&att.keys, bias) {
        (Keys::Topology { .. }, Some(c)) => qkv.apply_op2(&c.contiguous()?, att),
        (Keys::Window { .. }, None) => qkv.apply_op1(att),
        _ => candle_core::bail!("fused attention: topology keys need bias coefficients, window keys take none"),
    }
}

/// Layer norm over the last dimension, `y = (x - mean) / sqrt(var + eps) * weight + bias`.
#[derive(Clone, Copy, Debug)]
struct LayerNormOp {
    eps: f32,
}

impl LayerNormOp {
    /// Per row: the normalised values (into `xhat`) and 1/sigma.
    fn normalise(&self, x: &[f32], xhat: &mut [f32]) -> f32 {
        let n = x.len() as f32;
        let mean = x.iter().sum::<f32>() / n;
        let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / n;
        let rstd = 1.0 / (var + self.eps).sqrt();
        xhat.iter_mut().zip(x).for_each(|(o, v)| *o = (v - mean) * rstd);
        rstd
    }
}

impl CustomOp3 for LayerNormOp {
    fn name(&self) -> &'static str {
        "fused-layer-norm"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout, s2: &CpuStorage, l2: &Layout, s3: &CpuStorage, l3: &Layout) -> Result<(CpuStorage, Shape)> {
        let (x, w, b) = (f32_slice(s1, l1, "layer norm input")?, f32_slice(s2, l2, "layer norm weight")?, f32_slice(s3, l3, "layer norm bias")?);
        let d = w.len();
        if d == 0 || b.len() != d || x.len() % d != 0 {
            candle_core::bail!("layer norm: input of {} values, weight {d}, bias {}", x.len(), b.len());
        }
        let mut y = vec![0f32; x.len()];
        for (xr, yr) in x.chunks_exact(d).zip(y.chunks_exact_mut(d)) {
            self.normalise(xr, yr);
            yr.iter_mut().zip(w.iter().zip(b)).for_each(|(v, (w, b))| *v = *v * w + b);
        }
        Ok((CpuStorage::F32(y), l1.shape().clone()))
    }

    fn bwd(&self, x: &Tensor, w: &Tensor, b: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<(Option<Tensor>, Option<Tensor>, Option<Tensor>)> {
        let (xv, wv, dy) = (values(x)?, values(w)?, values(grad)?);
        let d = wv.len();
        let mut dx = vec![0f32; xv.len()];
        let (mut dw, mut db) = (vec![0f32; d], vec![0f32; d]);
        let mut xhat = vec![0f32; d];
        let mut g = vec![0f32; d];
        for ((xr, dyr), dxr) in xv.chunks_exact(d).zip(dy.chunks_exact(d)).zip(dx.chunks_exact_mut(d)) {
            let rstd = self.normalise(xr, &mut xhat);
            for e in 0..d {
                dw[e] += dyr[e] * xhat[e];
                db[e] += dyr[e];
                g[e] = dyr[e] * wv[e];
            }
            // dx = rstd (g - mean(g) - xhat mean(g xhat))
            let n = d as f32;
            let mean_g = g.iter().sum::<f32>() / n;
            let mean_gx = g.iter().zip(&xhat).map(|(a, b)| a * b).sum::<f32>() / n;
            for e in 0..d {
                dxr[e] = rstd * (g[e] - mean_g - xhat[e] * mean_gx);
            }
        }
        Ok((
            Some(Tensor::from_vec(dx, x.shape(), x.device())?),
            Some(Tensor::from_vec(dw, w.shape(), w.device())?),
            Some(Tensor::from_vec(db, b.shape(), b.device())?),
        ))
    }
}

/// Layer norm of `x` over its last dimension with learned `weight` and `bias` (`[d]` each).
pub fn layer_norm(x: &Tensor, weight: &Tensor, bias: &Tensor, eps: f64) -> Result<Tensor> {
    x.contiguous()?.apply_op3(&weight.contiguous()?, &bias.contiguous()?, LayerNormOp { eps: eps as f32 })
}

/// `x + v` where `x` is `[groups, rows, width]` and `v` is `[groups, width]`, broadcast over the
/// rows. candle's own broadcast add is fine forward, but its backward sums the gradient over a
/// middle dimension with a strided reduction that cost ~9% of a training step (perf); here it
/// is one pass of row additions.
#[derive(Clone, Copy, Debug)]
struct AddBroadcast {
    groups: usize,
    rows: usize,
    width: usize,
}

impl CustomOp2 for AddBroadcast {
    fn name(&self) -> &'static str {
        "fused-add-broadcast"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout, s2: &CpuStorage, l2: &Layout) -> Result<(CpuStorage, Shape)> {
        let (x, v) = (f32_slice(s1, l1, "broadcast add input")?, f32_slice(s2, l2, "broadcast add row")?);
        let mut y = x.to_vec();
        for g in 0..self.groups {
            let vg = &v[g * self.width..(g + 1) * self.width];
            for r in y[g * self.rows * self.width..(g + 1) * self.rows * self.width].chunks_exact_mut(self.width) {
                r.iter_mut().zip(vg).for_each(|(a, b)| *a += b);
            }
        }
        Ok((CpuStorage::F32(y), l1.shape().clone()))
    }

    fn bwd(&self, x: &Tensor, v: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<(Option<Tensor>, Option<Tensor>)> {
        let gv = values(grad)?;
        let mut dv = vec![0f32; self.groups * self.width];
        for g in 0..self.groups {
            let out = &mut dv[g * self.width..(g + 1) * self.width];
            for r in gv[g * self.rows * self.width..(g + 1) * self.rows * self.width].chunks_exact(self.width) {
                out.iter_mut().zip(r).for_each(|(a, b)| *a += b);
            }
        }
        Ok((Some(grad.reshape(x.shape())?), Some(Tensor::from_vec(dv, v.shape(), v.device())?)))
    }
}

/// `x + v`, with `x` of shape `[G, ..., W-block]` and `v` of `G * W` values: `x` is viewed as
/// `[G, rows, W]` (W = `v.elem_count() / G`) and `v` as `[G, W]`, added to every row.
pub fn add_broadcast(x: &Tensor, v: &Tensor, groups: usize) -> Result<Tensor> {
    let (n, m) = (x.elem_count(), v.elem_count());
    if groups == 0 || m % groups != 0 || n % m != 0 {
        candle_core::bail!("broadcast add: {n} values plus {m} in {groups} groups");
    }
    let width = m / groups;
    let op = AddBroadcast { groups, rows: n / m, width };
    x.contiguous()?.apply_op2(&v.contiguous()?, op)
}

#[cfg(test)]
#[path = "fused_tests.rs"]
mod tests;
