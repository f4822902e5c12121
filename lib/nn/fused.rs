//! Fused CPU kernels with their own backward pass: multi-head attention and layer norm.
//!
//! Why: built from candle's basic ops, one attention layer is some twenty passes over the
//! J x J and T x T logit tensors (bias add, max, subtract, exp, sum, divide, their backward
//! passes, permutes to and from the head layout), each into a freshly allocated tensor. On our
//! CPUs that made the model run at 3-10% of matmul peak (benches/nn.rs). Here each (group,
//! head) is four small GEMMs (logits, output; three more in the backward) that read queries,
//! keys and values in place from the `[rows, 3 * width]` output of the fused q/k/v projection
//! through strides, so no head split, merge or transpose is ever materialised, and one pass
//! per row adds the bias and masks and takes the softmax. The probabilities are kept for the
//! backward pass when there is one.
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
    /// (`frame_ok[b * T + k]`) and `k == 0` (the rest-pose token, docs/reference/anytop.md §2.5) or
    /// `|i - k| <= half`. The reference's window is [i-15, i+16], one wider on the right; we keep
    /// it symmetric.
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

pub(super) fn f32_slice<'a>(s: &'a CpuStorage, l: &Layout, what: &str) -> Result<&'a [f32]> {
    let CpuStorage::F32(data) = s else {
        candle_core::bail!("{what}: fused kernels take f32 tensors");
    };
    match l.contiguous_offsets() {
        Some((start, end)) => Ok(&data[start..end]),
        None => candle_core::bail!("{what}: fused kernels take contiguous tensors"),
    }
}

/// Runs `f` on the values of a CPU f32 tensor in place. The backward passes used to copy
/// their inputs out first (`to_vec1`): 2-3% of a training step in `perf`.
fn with_values<R>(t: &Tensor, what: &str, f: impl FnOnce(&[f32]) -> Result<R>) -> Result<R> {
    let t = t.contiguous()?;
    let (storage, layout) = t.storage_and_layout();
    match &*storage {
        candle_core::Storage::Cpu(cpu) => f(f32_slice(cpu, layout, what)?),
        _ => candle_core::bail!("{what}: fused kernels run on the CPU"),
    }
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

    /// Query blocks `(i0, i1)` with the key range `klo..khi` their spans cover (key 0 comes on
    /// top when `klo > 0`). Skeletal attention is one block; the temporal window is cut into
    /// blocks so a 120-frame sample does not multiply 120 x 120 logits of which 31 per row count.
    fn blocks(&self) -> Vec<(usize, usize, usize, usize)> {
        let n = self.groups.len;
        match &self.keys {
            Keys::Topology { .. } => vec![(0, n, 0, n)],
            Keys::Window { half, .. } => (0..n)
                .step_by(QUERY_BLOCK)
                .map(|i0| {
                    let i1 = (i0 + QUERY_BLOCK).min(n);
                    (i0, i1, i0.saturating_sub(*half), (i1 + half).min(n))
                })
                .collect(),
        }
    }

    /// Where head `h` of group `g`'s queries, keys and values are in the `[rows, 3w]` q/k/v
    /// matrix (and its gradient), and its output in `[rows, w]`: `(q, k, v, out)`.
    fn views(&self, g: usize, h: usize) -> (Strided, Strided, Strided, Strided) {
        let (w, dh) = (self.width(), self.head_dim);
        let (base, ps) = (self.groups.row(g, 0), self.groups.pos_stride);
        let q = Strided { off: base * 3 * w + h * dh, rs: ps * 3 * w, cs: 1 };
        (q, Strided { off: q.off + w, ..q }, Strided { off: q.off + 2 * w, ..q }, Strided { off: base * w + h * dh, rs: ps * w, cs: 1 })
    }

    /// Attention probabilities of group `g`, head `h` into `p` (`len x len`, row = query):
    /// logits of each block as one small GEMM, then bias, masks and softmax per row. Columns a
    /// query cannot see are 0; columns outside its block's key range are not touched.
    #[inline(always)]
    fn probabilities(&self, qkv: &[f32], c: Option<&[f32]>, g: usize, h: usize, blocks: &[(usize, usize, usize, usize)], p: &mut [f32]) {
        let (n, dh) = (self.groups.len, self.head_dim);
        let sample = g / self.groups.per_sample;
        let (q, k, _, _) = self.views(g, h);
        let mut coefficients: Vec<f32> = Vec::new();
        for &(i0, i1, klo, khi) in blocks {
            let pm = Strided { off: i0 * n + klo, rs: n, cs: 1 };
            small_gemm(p, pm, qkv, q.at(i0, 0), qkv, k.at(klo, 0).t(), (i1 - i0, khi - klo, dh), self.scale, false);
            for i in i0..i1 {
                let row = &mut p[i * n..(i + 1) * n];
                if klo > 0 {
                    let (qi, k0) = (q.at(i, 0).off, k.off);
                    row[0] = self.scale * (0..dh).map(|e| qkv[qi + e] * qkv[k0 + e]).sum::<f32>();
                }
                let (lo, hi) = self.span(i);
                match &self.keys {
                    Keys::Topology { types, key_ok, type_count } => {
                        // This query's coefficients with a 0 appended for NO_TYPE, so the loop
                        // below has no branches but the key mask.
                        let at = (self.groups.row(g, i) * self.heads + h) * type_count;
                        coefficients.clear();
                        coefficients.extend_from_slice(c.map_or(&[][..], |c| &c[at..at + type_count]));
                        coefficients.resize(type_count + 1, 0.0);
                        let none = *type_count;
                        let keys_ok = &key_ok[sample * n..(sample + 1) * n];
                        let pair_types = &types[(sample * n + i) * n..(sample * n + i + 1) * n];
                        for ((v, &ok), &[a, b]) in row.iter_mut().zip(keys_ok).zip(pair_types) {
                            let (a, b) = ((a as usize).min(none), (b as usize).min(none));
                            let biased = *v + coefficients[a] + coefficients[b];
                            *v = if ok { biased } else { f32::NEG_INFINITY };
                        }
                    }
                    Keys::Window { frame_ok, .. } => {
                        let tokens_ok = &frame_ok[sample * n..(sample + 1) * n];
                        for k in (lo..hi).chain((lo > 0).then_some(0)) {
                            if !tokens_ok[k] {
                                row[k] = f32::NEG_INFINITY;
                            }
                        }
                        // Outside the window but inside the block's key range: invisible.
                        row[klo.max(1).min(lo)..lo].fill(0.0);
                        row[hi..khi].fill(0.0);
                    }
                }
                let max = max(&row[lo..hi]).max(if lo > 0 { row[0] } else { f32::NEG_INFINITY });
                if max == f32::NEG_INFINITY {
                    row[klo..khi].fill(0.0);
                    row[0] = 0.0;
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
        let (n, dh, w) = (self.groups.len, self.head_dim, self.width());
        if let Some(buf) = saved.as_mut() {
            buf.clear();
            buf.resize(self.groups.groups * self.heads * n * n, 0.0);
        }
        let mut y = vec![0f32; self.groups.rows() * w];
        let mut p = vec![0f32; n * n];
        let blocks = self.blocks();
        for g in 0..self.groups.groups {
            for h in 0..self.heads {
                self.probabilities(qkv, c, g, h, &blocks, &mut p);
                let (_, _, v, out) = self.views(g, h);
                // y = P V per block, plus the rest-pose key's share for blocks that miss it.
                for &(i0, i1, klo, khi) in &blocks {
                    let pm = Strided { off: i0 * n + klo, rs: n, cs: 1 };
                    small_gemm(&mut y, out.at(i0, 0), &p, pm, qkv, v.at(klo, 0), (i1 - i0, dh, khi - klo), 1.0, false);
                    if klo > 0 {
                        for i in i0..i1 {
                            let (p0, o) = (p[i * n], out.at(i, 0).off);
                            y[o..o + dh].iter_mut().zip(&qkv[v.off..v.off + dh]).for_each(|(y, v)| *y += p0 * v);
                        }
                    }
                }
                if let Some(buf) = saved.as_mut() {
                    buf[(g * self.heads + h) * n * n..(g * self.heads + h + 1) * n * n].copy_from_slice(&p);
                }
            }
        }
        y
    }

    /// Gradients of q/k/v (`[rows, 3w]`) and, for the topology bias, of `c`, from the
    /// probabilities the forward pass kept (recomputed when it kept none).
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
        let (n, dh) = (self.groups.len, self.head_dim);
        let mut dqkv = vec![0f32; qkv.len()];
        let mut dc = c.map(|c| vec![0f32; c.len()]);
        let (mut p, mut ds) = (vec![0f32; n * n], vec![0f32; n * n]);
        let blocks = self.blocks();
        for g in 0..self.groups.groups {
            let sample = g / self.groups.per_sample;
            for h in 0..self.heads {
                match saved.as_ref().filter(|b| b.len() == self.groups.groups * self.heads * n * n) {
                    Some(buf) => p.copy_from_slice(&buf[(g * self.heads + h) * n * n..(g * self.heads + h + 1) * n * n]),
                    None => self.probabilities(qkv, c, g, h, &blocks, &mut p),
                }
                let (q, k, v, out) = self.views(g, h);
                for &(i0, i1, klo, khi) in &blocks {
                    let (m, kn) = (i1 - i0, khi - klo);
                    let pm = Strided { off: i0 * n + klo, rs: n, cs: 1 };
                    // dP = dY V^T, then dS_ik = P_ik (dP_ik - sum_k P_ik dP_ik).
                    small_gemm(&mut ds, pm, dy, out.at(i0, 0), qkv, v.at(klo, 0).t(), (m, kn, dh), 1.0, false);
                    for i in i0..i1 {
                        let dyi = &dy[out.at(i, 0).off..out.at(i, 0).off + dh];
                        if klo > 0 {
                            ds[i * n] = dyi.iter().zip(&qkv[v.off..v.off + dh]).map(|(a, b)| a * b).sum();
                        }
                        let (prow, dsrow) = (&p[i * n + klo..i * n + khi], &mut ds[i * n + klo..i * n + khi]);
                        let mut dot_pd = dot(prow, dsrow);
                        if klo > 0 {
                            dot_pd += p[i * n] * ds[i * n];
                            ds[i * n] = p[i * n] * (ds[i * n] - dot_pd);
                        }
                        let dsrow = &mut ds[i * n + klo..i * n + khi];
                        dsrow.iter_mut().zip(prow).for_each(|(d, p)| *d = p * (*d - dot_pd));
                        if let (Some(dc), Keys::Topology { types, type_count, .. }) = (dc.as_mut(), &self.keys) {
                            let at = (self.groups.row(g, i) * self.heads + h) * type_count;
                            let pair_types = &types[(sample * n + i) * n..(sample * n + i + 1) * n];
                            for (&d, &[a, b]) in ds[i * n..(i + 1) * n].iter().zip(pair_types) {
                                if a != NO_TYPE {
                                    dc[at + a as usize] += d;
                                }
                                if b != NO_TYPE {
                                    dc[at + b as usize] += d;
                                }
                            }
                        }
                    }
                    // Logits are scale * q.k: dQ += scale dS K, dK += scale dS^T Q, dV += P^T dY.
                    small_gemm(&mut dqkv, q.at(i0, 0), &ds, pm, qkv, k.at(klo, 0), (m, dh, kn), self.scale, true);
                    small_gemm(&mut dqkv, k.at(klo, 0), &ds, pm.t(), qkv, q.at(i0, 0), (kn, dh, m), self.scale, true);
                    small_gemm(&mut dqkv, v.at(klo, 0), &p, pm.t(), dy, out.at(i0, 0), (kn, dh, m), 1.0, true);
                    if klo > 0 {
                        // The rest-pose key outside the block's range.
                        for i in i0..i1 {
                            let (d0, p0) = (ds[i * n] * self.scale, p[i * n]);
                            let (qi, di) = (q.at(i, 0).off, out.at(i, 0).off);
                            for e in 0..dh {
                                dqkv[qi + e] += d0 * qkv[k.off + e];
                                dqkv[k.off + e] += d0 * qkv[qi + e];
                                dqkv[v.off + e] += p0 * dy[di + e];
                            }
                        }
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
pub(super) fn exp(x: f32) -> f32 {
    let xc = x.max(-87.0);
    let n = (xc * std::f32::consts::LOG2_E).round();
    let r = xc - n * 0.693_145_75 - n * 1.428_606_8e-6;
    let p = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    // `n as i32` would saturate, and that check is done lane by lane in scalar code (it made
    // this function's loops scalar at their core). n is finite here (`xc` is never NaN) and at
    // most 128 after the `min`, so the unchecked conversion is exact and vectorises.
    // SAFETY: n is an integer-valued finite f32 in [-126, 128], representable as i32.
    let n = unsafe { n.min(128.0).to_int_unchecked::<i32>() };
    let scale = f32::from_bits(((n + 127) as u32) << 23);
    if x < -87.0 {
        0.0
    } else {
        p * scale
    }
}

/// Maximum with eight independent lanes (a running `f32::max` is a scalar chain; it was a
/// sixth of the forward attention time). NaN never wins, as with `f32::max`.
#[inline(always)]
fn max(a: &[f32]) -> f32 {
    let mut acc = [f32::NEG_INFINITY; 8];
    let chunks = a.chunks_exact(8);
    let tail = chunks.remainder().iter().fold(f32::NEG_INFINITY, |m, &v| m.max(v));
    for x in chunks {
        for l in 0..8 {
            acc[l] = if x[l] > acc[l] { x[l] } else { acc[l] };
        }
    }
    acc.iter().fold(tail, |m, &v| m.max(v))
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

/// Queries per block of the windowed temporal attention (see `Attention::blocks`).
const QUERY_BLOCK: usize = 32;

/// A matrix inside a slice: element (r, c) at `off + r * rs + c * cs`. Heads of the q/k/v
/// matrix are such views (row stride `3w` or `3wJ`), so no head is ever copied out.
#[derive(Clone, Copy, Debug)]
struct Strided {
    off: usize,
    rs: usize,
    cs: usize,
}

impl Strided {
    /// The view starting at element (r, c).
    fn at(self, r: usize, c: usize) -> Strided {
        Strided { off: self.off + r * self.rs + c * self.cs, ..self }
    }

    fn t(self) -> Strided {
        Strided { off: self.off, rs: self.cs, cs: self.rs }
    }

    fn fits(self, len: usize, rows: usize, cols: usize) -> bool {
        rows == 0 || cols == 0 || self.off + (rows - 1) * self.rs + (cols - 1) * self.cs < len
    }
}

/// `d = beta a b` (or `d += beta a b` when `accumulate`) for `a`: m x k, `b`: k x n views, with
/// the gemm crate's register-blocked kernels on this thread. Why not loops: our per-query
/// axpy loops ran at a fifth of gemm's speed on these 16-wide head dimensions (benches/nn.rs).
#[allow(clippy::too_many_arguments)]
fn small_gemm(d: &mut [f32], dm: Strided, a: &[f32], am: Strided, b: &[f32], bm: Strided, (m, n, k): (usize, usize, usize), beta: f32, accumulate: bool) {
    assert!(dm.fits(d.len(), m, n) && am.fits(a.len(), m, k) && bm.fits(b.len(), k, n), "small_gemm: a view overruns its buffer");
    if m == 0 || n == 0 || k == 0 {
        assert!(accumulate || k > 0 || m == 0 || n == 0, "small_gemm: empty inner dimension");
        return;
    }
    // SAFETY: every element the three views address is inside its slice (checked above), and
    // `d` is borrowed mutably, so it overlaps neither `a` nor `b`.
    unsafe {
        gemm::gemm(
            m,
            n,
            k,
            d.as_mut_ptr().add(dm.off),
            dm.cs as isize,
            dm.rs as isize,
            accumulate,
            a.as_ptr().add(am.off),
            am.cs as isize,
            am.rs as isize,
            b.as_ptr().add(bm.off),
            bm.cs as isize,
            bm.rs as isize,
            1.0,
            beta,
            false,
            false,
            false,
            gemm::Parallelism::None,
        )
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
        let (d, _) = with_values(qkv, "q/k/v", |q| with_values(grad, "output gradient", |g| self.backward(q, None, g)))?;
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
        let (d, dc) =
            with_values(qkv, "q/k/v", |q| with_values(c, "bias coefficients", |cv| with_values(grad, "output gradient", |g| self.backward(q, Some(cv), g))))?;
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
    /// Per row: the normalised values (into `xhat`) and 1/sigma. Sums with eight partial sums
    /// (see `sum`), and plain index loops: this is inlined into `target_feature` functions, where
    /// a closure would be compiled without the feature.
    #[inline(always)]
    fn normalise(&self, x: &[f32], xhat: &mut [f32]) -> f32 {
        let n = x.len() as f32;
        let mean = sum(x) / n;
        for e in 0..x.len() {
            xhat[e] = x[e] - mean;
        }
        let var = dot(xhat, xhat) / n;
        let rstd = 1.0 / (var + self.eps).sqrt();
        for v in xhat.iter_mut() {
            *v *= rstd;
        }
        rstd
    }

    #[inline(always)]
    fn forward_body(&self, x: &[f32], w: &[f32], b: &[f32]) -> Vec<f32> {
        let d = w.len();
        let mut y = vec![0f32; x.len()];
        for (xr, yr) in x.chunks_exact(d).zip(y.chunks_exact_mut(d)) {
            self.normalise(xr, yr);
            for e in 0..d {
                yr[e] = yr[e] * w[e] + b[e];
            }
        }
        y
    }

    /// The same loops compiled for 8-wide vectors.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn forward_avx2(&self, x: &[f32], w: &[f32], b: &[f32]) -> Vec<f32> {
        self.forward_body(x, w, b)
    }

    fn forward(&self, x: &[f32], w: &[f32], b: &[f32]) -> Vec<f32> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `forward_avx2` is compiled for.
            return unsafe { self.forward_avx2(x, w, b) };
        }
        self.forward_body(x, w, b)
    }

    /// `(dx, dw, db)` from the input, weight and output gradient.
    #[inline(always)]
    fn backward_body(&self, xv: &[f32], wv: &[f32], dy: &[f32]) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let d = wv.len();
        let n = d as f32;
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
            let mean_g = sum(&g) / n;
            let mean_gx = dot(&g, &xhat) / n;
            for e in 0..d {
                dxr[e] = rstd * (g[e] - mean_g - xhat[e] * mean_gx);
            }
        }
        (dx, dw, db)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn backward_avx2(&self, xv: &[f32], wv: &[f32], dy: &[f32]) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        self.backward_body(xv, wv, dy)
    }

    #[allow(clippy::type_complexity)]
    fn backward(&self, x: &Tensor, w: &Tensor, b: &Tensor, xv: &[f32], wv: &[f32], dy: &[f32]) -> Result<(Option<Tensor>, Option<Tensor>, Option<Tensor>)> {
        let d = wv.len();
        if d == 0 || !xv.len().is_multiple_of(d) || dy.len() != xv.len() {
            candle_core::bail!("layer norm backward: input of {} values, weight {d}, output gradient {}", xv.len(), dy.len());
        }
        #[cfg(target_arch = "x86_64")]
        let (dx, dw, db) = if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `backward_avx2` is compiled for.
            unsafe { self.backward_avx2(xv, wv, dy) }
        } else {
            self.backward_body(xv, wv, dy)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let (dx, dw, db) = self.backward_body(xv, wv, dy);
        Ok((
            Some(Tensor::from_vec(dx, x.shape(), x.device())?),
            Some(Tensor::from_vec(dw, w.shape(), w.device())?),
            Some(Tensor::from_vec(db, b.shape(), b.device())?),
        ))
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
        Ok((CpuStorage::F32(self.forward(x, w, b)), l1.shape().clone()))
    }

    fn bwd(&self, x: &Tensor, w: &Tensor, b: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<(Option<Tensor>, Option<Tensor>, Option<Tensor>)> {
        with_values(x, "layer norm input", |xv| {
            with_values(w, "layer norm weight", |wv| with_values(grad, "layer norm output gradient", |dy| self.backward(x, w, b, xv, wv, dy)))
        })
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
        let mut dv = vec![0f32; self.groups * self.width];
        with_values(grad, "output gradient", |gv| {
            for g in 0..self.groups {
                let out = &mut dv[g * self.width..(g + 1) * self.width];
                for r in gv[g * self.rows * self.width..(g + 1) * self.rows * self.width].chunks_exact(self.width) {
                    out.iter_mut().zip(r).for_each(|(a, b)| *a += b);
                }
            }
            Ok(())
        })?;
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

/// How many parts our GEMMs split into: `Rayon(n)` for a pool of n > 1 threads (the pool the
/// call runs in, or the global one), none for one thread. The result is the same bytes either
/// way; only the time differs. With one thread, `Rayon(n)` made every product a cross-thread
/// handoff: a caller outside the pool (`mo-train --threads 1` steps on the main thread) injects
/// each part into the pool, wakes its worker and sleeps until it is done. That wake-up and
/// sleep took about a third of a training step's CPU (`perf record` of `mo-train --preset tiny
/// --threads 1`, BENCHMARKS.md).
fn matmul_parallelism() -> gemm::Parallelism {
    match rayon::current_num_threads() {
        n if n > 1 => gemm::Parallelism::Rayon(n),
        _ => gemm::Parallelism::None,
    }
}

/// `a b` as a new contiguous row-major `m x n` buffer, for views `a` (m x k) and `b` (k x n),
/// with the gemm call candle's matmul makes (so the same bytes as `matmul`).
fn matmul_new(a: &[f32], am: Strided, b: &[f32], bm: Strided, (m, n, k): (usize, usize, usize)) -> Result<Vec<f32>> {
    if !am.fits(a.len(), m, k) || !bm.fits(b.len(), k, n) {
        candle_core::bail!("fused kernel: a {m} x {k} by {k} x {n} product does not fit its buffers");
    }
    let len = m.checked_mul(n).ok_or_else(|| candle_core::Error::Msg(format!("fused kernel: a {m} x {n} product is too large")))?;
    if len == 0 || k == 0 {
        return Ok(vec![0f32; len]);
    }
    let mut d: Vec<f32> = Vec::with_capacity(len);
    // SAFETY: the views fit their slices (checked above) and `d` has room for the m x n
    // destination, a fresh allocation that overlaps neither. With `read_dst` false gemm
    // (0.19, `gemm_basic_generic`) sets alpha to zero and writes every destination element
    // without reading it, so no zero fill is needed (it was 1-2% of a training step), and
    // after the call all `len` values are initialised.
    unsafe {
        gemm::gemm(
            m,
            n,
            k,
            d.as_mut_ptr(),
            1,
            n as isize,
            false,
            a.as_ptr().add(am.off),
            am.cs as isize,
            am.rs as isize,
            b.as_ptr().add(bm.off),
            bm.cs as isize,
            bm.rs as isize,
            0.0,
            1.0,
            false,
            false,
            false,
            matmul_parallelism(),
        );
        d.set_len(len);
    }
    Ok(d)
}

/// `y = x W^T + b` over the last dimension of `x` as one graph node. The forward is what
/// `x.matmul(W.t())` plus the bias gives, to the bit (the same gemm call, then the bias added to
/// each row); the backward gives `dx = dy W`, `dW = dy^T x` and `db` = the column sums of dy
/// in one go. Built from candle's ops a linear was four nodes (reshape, transpose, matmul,
/// bias add, reshape back), and candle's backward pass zero-fills and adds a fresh gradient
/// buffer for every input of every node: that was a tenth of a training step (perf).
#[derive(Clone, Debug)]
struct LinearOp {
    rows: usize,
    inputs: usize,
    outputs: usize,
    shape: Shape,
}

impl CustomOp3 for LinearOp {
    fn name(&self) -> &'static str {
        "fused-linear"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout, s2: &CpuStorage, l2: &Layout, s3: &CpuStorage, l3: &Layout) -> Result<(CpuStorage, Shape)> {
        let (x, w, b) = (f32_slice(s1, l1, "linear input")?, f32_slice(s2, l2, "linear weight")?, f32_slice(s3, l3, "linear bias")?);
        let (rows, i, o) = (self.rows, self.inputs, self.outputs);
        if x.len() != rows * i || w.len() != o * i || b.len() != o {
            candle_core::bail!("fused linear: input of {} values, weight {}, bias {}, for {rows} rows of {i} -> {o}", x.len(), w.len(), b.len());
        }
        let mut y = matmul_new(x, Strided { off: 0, rs: i, cs: 1 }, w, Strided { off: 0, rs: 1, cs: i }, (rows, o, i))?;
        for r in y.chunks_exact_mut(o.max(1)) {
            r.iter_mut().zip(b).for_each(|(a, b)| *a += b);
        }
        Ok((CpuStorage::F32(y), self.shape.clone()))
    }

    fn bwd(&self, x: &Tensor, w: &Tensor, b: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<(Option<Tensor>, Option<Tensor>, Option<Tensor>)> {
        let (rows, i, o) = (self.rows, self.inputs, self.outputs);
        let (dx, dw, db) = with_values(grad, "linear output gradient", |dy| {
            if dy.len() != rows * o {
                candle_core::bail!("fused linear: output gradient of {} values, expected {rows} x {o}", dy.len());
            }
            let dx =
                with_values(w, "linear weight", |wv| matmul_new(dy, Strided { off: 0, rs: o, cs: 1 }, wv, Strided { off: 0, rs: i, cs: 1 }, (rows, i, o)))?;
            let dw = with_values(x, "linear input", |xv| matmul_new(dy, Strided { off: 0, rs: 1, cs: o }, xv, Strided { off: 0, rs: i, cs: 1 }, (o, i, rows)))?;
            let mut db = vec![0f32; o];
            for r in dy.chunks_exact(o.max(1)) {
                db.iter_mut().zip(r).for_each(|(a, b)| *a += b);
            }
            Ok((dx, dw, db))
        })?;
        Ok((
            Some(Tensor::from_vec(dx, x.shape(), x.device())?),
            Some(Tensor::from_vec(dw, w.shape(), w.device())?),
            Some(Tensor::from_vec(db, b.shape(), b.device())?),
        ))
    }
}

/// `x W^T + b` over the last dimension of `x` (`weight`: `[outputs, inputs]`, `bias`:
/// `[outputs]`), shaped `shape` (which must hold `rows x outputs` values; `None`: `x`'s shape
/// with the last dimension `outputs`). One graph node; see `LinearOp`.
pub fn linear(x: &Tensor, weight: &Tensor, bias: &Tensor, shape: Option<Shape>) -> Result<Tensor> {
    let (outputs, inputs) = weight.dims2()?;
    let dims = x.dims();
    if dims.last() != Some(&inputs) || bias.elem_count() != outputs {
        candle_core::bail!("fused linear: input {dims:?}, weight [{outputs}, {inputs}], bias of {}", bias.elem_count());
    }
    let rows = x.elem_count() / inputs.max(1);
    let shape = match shape {
        Some(s) if s.elem_count() == rows * outputs => s,
        Some(s) => candle_core::bail!("fused linear: {rows} x {outputs} values do not make {s:?}"),
        None => {
            let mut d = dims.to_vec();
            if let Some(last) = d.last_mut() {
                *last = outputs;
            }
            Shape::from(d)
        }
    };
    let op = LinearOp { rows, inputs, outputs, shape };
    x.contiguous()?.apply_op3(&weight.contiguous()?, &bias.contiguous()?, op)
}

/// `d = beta a b` (`d += beta a b` when `accumulate`) for views `d` (m x n), `a` (m x k) and
/// `b` (k x n), with the parallelism of candle's matmul; an error, not a panic, when a view
/// overruns its buffer.
#[allow(clippy::too_many_arguments)]
fn strided_gemm(
    d: &mut [f32],
    dm: Strided,
    a: &[f32],
    am: Strided,
    b: &[f32],
    bm: Strided,
    (m, n, k): (usize, usize, usize),
    beta: f32,
    accumulate: bool,
) -> Result<()> {
    if !dm.fits(d.len(), m, n) || !am.fits(a.len(), m, k) || !bm.fits(b.len(), k, n) {
        candle_core::bail!("fused kernel: a {m} x {k} by {k} x {n} product does not fit its buffers");
    }
    if m == 0 || n == 0 || k == 0 {
        if !accumulate && k == 0 {
            candle_core::bail!("fused kernel: empty inner dimension");
        }
        return Ok(());
    }
    // SAFETY: every element the three views address is inside its slice (checked above), and
    // `d` is borrowed mutably, so it overlaps neither `a` nor `b`.
    unsafe {
        gemm::gemm(
            m,
            n,
            k,
            d.as_mut_ptr().add(dm.off),
            dm.cs as isize,
            dm.rs as isize,
            accumulate,
            a.as_ptr().add(am.off),
            am.cs as isize,
            am.rs as isize,
            b.as_ptr().add(bm.off),
            bm.cs as isize,
            bm.rs as isize,
            1.0,
            beta,
            false,
            false,
            false,
            matmul_parallelism(),
        )
    }
    Ok(())
}

/// The skeletal attention's topology coefficients (see `anytop`): for every token row, head h
/// and type t, `c[row, h, t] = (q_h . Eq[t]_h + k_h . Ek[t]_h) / sqrt(head_dim)`, where `_h` is
/// head h's slice of the width. As one `[3d, H * types]` matrix product this was mostly zeros
/// (the value rows, and the other heads' rows of each column): six times the multiply-adds
/// needed. Here it is two GEMMs per head over that head's slice only, and the same in the
/// backward pass.
#[derive(Clone, Copy, Debug)]
struct TopologyCoefficients {
    rows: usize,
    heads: usize,
    head_dim: usize,
    types: usize,
    scale: f32,
}

impl TopologyCoefficients {
    fn width(&self) -> usize {
        self.heads * self.head_dim
    }

    fn check(&self, qkv: usize, eq: usize, ek: usize) -> Result<()> {
        let w = self.width();
        if qkv != self.rows * 3 * w || eq != self.types * w || ek != self.types * w {
            candle_core::bail!(
                "topology coefficients: q/k/v of {qkv} values, tables of {eq} and {ek}, for {} rows of width {w} and {} types",
                self.rows,
                self.types
            );
        }
        Ok(())
    }

    /// Head h's queries (`part` 0) or keys (1): `rows x head_dim` inside the q/k/v matrix.
    fn tokens(&self, part: usize, h: usize) -> Strided {
        Strided { off: part * self.width() + h * self.head_dim, rs: 3 * self.width(), cs: 1 }
    }

    /// Head h's slice of a `[types, d]` table: `types x head_dim`.
    fn table(&self, h: usize) -> Strided {
        Strided { off: h * self.head_dim, rs: self.width(), cs: 1 }
    }

    /// Head h's coefficients: `rows x types` inside `[rows, heads * types]`.
    fn coefficients(&self, h: usize) -> Strided {
        Strided { off: h * self.types, rs: self.heads * self.types, cs: 1 }
    }
}

impl CustomOp3 for TopologyCoefficients {
    fn name(&self) -> &'static str {
        "fused-topology-coefficients"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout, s2: &CpuStorage, l2: &Layout, s3: &CpuStorage, l3: &Layout) -> Result<(CpuStorage, Shape)> {
        let (qkv, eq, ek) = (f32_slice(s1, l1, "q/k/v")?, f32_slice(s2, l2, "query table")?, f32_slice(s3, l3, "key table")?);
        self.check(qkv.len(), eq.len(), ek.len())?;
        let (rows, dh, ty) = (self.rows, self.head_dim, self.types);
        let mut c = vec![0f32; rows * self.heads * ty];
        for h in 0..self.heads {
            strided_gemm(&mut c, self.coefficients(h), qkv, self.tokens(0, h), eq, self.table(h).t(), (rows, ty, dh), self.scale, false)?;
            strided_gemm(&mut c, self.coefficients(h), qkv, self.tokens(1, h), ek, self.table(h).t(), (rows, ty, dh), self.scale, true)?;
        }
        Ok((CpuStorage::F32(c), Shape::from((rows, self.heads * ty))))
    }

    fn bwd(&self, qkv: &Tensor, eq: &Tensor, ek: &Tensor, _res: &Tensor, grad: &Tensor) -> Result<(Option<Tensor>, Option<Tensor>, Option<Tensor>)> {
        let (rows, dh, ty) = (self.rows, self.head_dim, self.types);
        let (dqkv, deq, dek) = with_values(grad, "topology coefficient gradient", |dc| {
            with_values(qkv, "q/k/v", |qv| {
                with_values(eq, "query table", |eqv| {
                    with_values(ek, "key table", |ekv| {
                        self.check(qv.len(), eqv.len(), ekv.len())?;
                        if dc.len() != rows * self.heads * ty {
                            candle_core::bail!("topology coefficients: gradient of {} values, expected {rows} x {}", dc.len(), self.heads * ty);
                        }
                        let mut dqkv = vec![0f32; qv.len()];
                        let (mut deq, mut dek) = (vec![0f32; eqv.len()], vec![0f32; ekv.len()]);
                        for h in 0..self.heads {
                            let dch = self.coefficients(h);
                            for (part, table, dtable) in [(0, eqv, &mut deq), (1, ekv, &mut dek)] {
                                // d tokens = scale dC E_h;  d E_h = scale dC^T tokens.
                                strided_gemm(&mut dqkv, self.tokens(part, h), dc, dch, table, self.table(h), (rows, dh, ty), self.scale, false)?;
                                strided_gemm(dtable, self.table(h), dc, dch.t(), qv, self.tokens(part, h), (ty, dh, rows), self.scale, false)?;
                            }
                        }
                        Ok((dqkv, deq, dek))
                    })
                })
            })
        })?;
        Ok((
            Some(Tensor::from_vec(dqkv, qkv.shape(), qkv.device())?),
            Some(Tensor::from_vec(deq, eq.shape(), eq.device())?),
            Some(Tensor::from_vec(dek, ek.shape(), ek.device())?),
        ))
    }
}

/// The skeletal attention's topology coefficients `[rows, heads * types]` from the q/k/v
/// matrix `[rows, 3d]` and the query and key tables `[types, d]`, scaled by
/// `1/sqrt(head_dim)`: see `TopologyCoefficients`.
pub fn topology_coefficients(qkv: &Tensor, query_table: &Tensor, key_table: &Tensor, heads: usize) -> Result<Tensor> {
    let (rows, w3) = qkv.dims2()?;
    let (types, w) = query_table.dims2()?;
    if heads == 0 || w % heads != 0 || w3 != 3 * w || key_table.dims() != query_table.dims() {
        candle_core::bail!("topology coefficients: q/k/v {rows} x {w3}, tables {:?} and {:?}, {heads} heads", query_table.dims(), key_table.dims());
    }
    let head_dim = w / heads;
    let op = TopologyCoefficients { rows, heads, head_dim, types, scale: 1.0 / (head_dim as f32).sqrt() };
    qkv.contiguous()?.apply_op3(&query_table.contiguous()?, &key_table.contiguous()?, op)
}

#[cfg(test)]
#[path = "fused_tests.rs"]
mod tests;
