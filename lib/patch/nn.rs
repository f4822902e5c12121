//! Patch nearest neighbours and blending: one matching-and-blending step of GenMM and
//! Motion2Motion.
//!
//! A patch is `patch` consecutive frames of channel vectors; its distance to an example patch
//! is the mean squared difference of the weighted values (docs/reference/motion2motion.md §3.4).
//! Instead of unfolding patches (`patch` times the data) and multiplying them, we use that a patch
//! dot product is a sum of frame dot products along a diagonal:
//!
//! `x_i . y_j = sum_k G(i + k, j + k)`, with `G = X Y^T` the frame-by-frame Gram matrix,
//!
//! so the expensive part is one `T_query x T_example x C` product per step (the reference's
//! unfolded GEMM costs `patch` = 11 times more), computed in row blocks with a 2x2 register
//! tile, rayon over the blocks. Every value is computed by the same code in the same order
//! whatever the thread count, so results are bit-identical for any number of threads.

use super::channels::Channels;
use rayon::prelude::*;

/// Query patches per parallel block. The Gram rows of a block overlap the next block's by
/// `patch - 1` frames, so larger blocks waste less; 128 keeps a block's Gram rows in L2.
const BLOCK: usize = 128;
/// Largest distance matrix kept in memory (entries); bigger ones are computed twice instead.
const MAX_STORED: usize = 1 << 23;
/// A patch is a candidate of a seeded draw when its normalised distance is at most this many
/// times the nearest one's.
const NEAR_TIE: f32 = 1.5;
/// Lane width of the dot-product kernel; rows are zero-padded to a multiple of it.
const LANES: usize = 8;

/// The example patches of one pyramid level: every window of every clip (never across clips).
pub(crate) struct Bank {
    /// Weighted match channels of each clip, rows padded to `stride`.
    weighted: Vec<Vec<f32>>,
    /// Unweighted match and payload channels of each clip (what gets blended).
    pub matched: Vec<Channels>,
    pub payload: Vec<Channels>,
    /// (clip, first frame) of every patch, clip by clip.
    patches: Vec<(usize, usize)>,
    /// Index of each clip's first patch in `patches`.
    first_patch: Vec<usize>,
    /// Squared norm of every weighted patch.
    norms: Vec<f32>,
    stride: usize,
    width: usize,
    patch: usize,
}

fn padded(width: usize) -> usize {
    width.div_ceil(LANES) * LANES
}

/// Weighted, zero-padded copy of `c` (frame-major, rows of `stride`), with each frame's norm.
fn weigh(c: &Channels, weights: &[f32], stride: usize) -> (Vec<f32>, Vec<f32>) {
    // Built by extending rather than zeroing first: this runs on the whole synthesis every step.
    let mut out = Vec::with_capacity(c.frames * stride);
    let mut norms = Vec::with_capacity(c.frames);
    for t in 0..c.frames {
        let start = out.len();
        out.extend(c.row(t).iter().zip(weights).map(|(&v, &w)| v * w));
        out.resize(start + stride, 0.0);
        norms.push(out[start..].iter().map(|d| d * d).sum());
    }
    (out, norms)
}

/// Sums of `patch` consecutive frame norms.
fn window_sums(norms: &[f32], patch: usize) -> Vec<f32> {
    if norms.len() < patch {
        return Vec::new();
    }
    (0..=norms.len() - patch).map(|i| norms[i..i + patch].iter().sum()).collect()
}

impl Bank {
    /// Patches of the clips that are at least `patch` frames long; `payload` may have width 0.
    pub fn new(matched: Vec<Channels>, payload: Vec<Channels>, weights: &[f32], patch: usize) -> Bank {
        let width = matched.first().map(|c| c.width).unwrap_or(0);
        let stride = padded(width);
        let mut bank = Bank {
            weighted: Vec::new(),
            matched: Vec::new(),
            payload: Vec::new(),
            patches: Vec::new(),
            first_patch: Vec::new(),
            norms: Vec::new(),
            stride,
            width,
            patch,
        };
        for (m, p) in matched.into_iter().zip(payload) {
            if m.frames < patch {
                continue;
            }
            let k = bank.matched.len();
            let (w, frame_norms) = weigh(&m, weights, stride);
            bank.first_patch.push(bank.patches.len());
            for (b, n) in window_sums(&frame_norms, patch).into_iter().enumerate() {
                bank.patches.push((k, b));
                bank.norms.push(n);
            }
            bank.weighted.push(w);
            bank.matched.push(m);
            bank.payload.push(p);
        }
        bank
    }

    pub fn len(&self) -> usize {
        self.patches.len()
    }

    pub fn frames(&self) -> usize {
        self.matched.iter().map(|c| c.frames).sum()
    }
}

#[inline(always)]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut s = [0.0f32; LANES];
    for (x, y) in a.chunks_exact(LANES).zip(b.chunks_exact(LANES)) {
        for l in 0..LANES {
            s[l] += x[l] * y[l];
        }
    }
    hsum(&s)
}

#[inline(always)]
fn hsum(s: &[f32; LANES]) -> f32 {
    ((s[0] + s[4]) + (s[1] + s[5])) + ((s[2] + s[6]) + (s[3] + s[7]))
}

fn row(m: &[f32], i: usize, stride: usize) -> &[f32] {
    &m[i * stride..(i + 1) * stride]
}

/// `G = A B^T` for `rows` rows of `a` and `cols` rows of `b` (both of `stride` floats, a
/// multiple of `LANES`).
///
/// On x86-64 CPUs with AVX a hand-tiled AVX kernel runs instead (the baseline target has only
/// SSE, and the compiler does not tile this loop well). It performs exactly the same
/// multiplications and additions per output (8 lane sums, no FMA, the same final sum), so
/// both give the same bits and results do not depend on the CPU's features.
fn gram(a: &[f32], rows: usize, b: &[f32], cols: usize, stride: usize, out: &mut Vec<f32>) {
    out.clear();
    out.resize(rows * cols, 0.0);
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX, checked just above; that is gram_avx's only requirement.
            unsafe { gram_avx(a, rows, b, cols, stride, out) };
            return;
        }
    }
    for r in 0..rows {
        for c in 0..cols {
            out[r * cols + c] = dot(row(a, r, stride), row(b, c, stride));
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn gram_avx(a: &[f32], rows: usize, b: &[f32], cols: usize, stride: usize, out: &mut [f32]) {
    use std::arch::x86_64::*;
    // Loads of 8 floats at `k` from a row: k + 8 <= stride = the row's length.
    let load = |v: &[f32], k: usize| -> __m256 {
        debug_assert!(k + LANES <= v.len());
        // SAFETY: in bounds (see above); loadu has no alignment requirement.
        unsafe { _mm256_loadu_ps(v.as_ptr().add(k)) }
    };
    let sum = |v: __m256| -> f32 {
        let mut lanes = [0.0f32; LANES];
        // SAFETY: `lanes` holds exactly 8 floats.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), v) };
        hsum(&lanes)
    };
    // 4 query rows x 2 example rows: 8 accumulators, 2 example loads and 4 query loads per
    // 64 multiply-adds.
    let mut r = 0;
    while r + 4 <= rows {
        let q = [row(a, r, stride), row(a, r + 1, stride), row(a, r + 2, stride), row(a, r + 3, stride)];
        let mut c = 0;
        while c + 2 <= cols {
            let (e0, e1) = (row(b, c, stride), row(b, c + 1, stride));
            let mut acc = [_mm256_setzero_ps(); 8];
            let mut k = 0;
            while k + LANES <= stride {
                let (y0, y1) = (load(e0, k), load(e1, k));
                for i in 0..4 {
                    let x = load(q[i], k);
                    acc[2 * i] = _mm256_add_ps(acc[2 * i], _mm256_mul_ps(x, y0));
                    acc[2 * i + 1] = _mm256_add_ps(acc[2 * i + 1], _mm256_mul_ps(x, y1));
                }
                k += LANES;
            }
            for i in 0..4 {
                out[(r + i) * cols + c] = sum(acc[2 * i]);
                out[(r + i) * cols + c + 1] = sum(acc[2 * i + 1]);
            }
            c += 2;
        }
        for c in c..cols {
            for i in 0..4 {
                out[(r + i) * cols + c] = dot(q[i], row(b, c, stride));
            }
        }
        r += 4;
    }
    for r in r..rows {
        for c in 0..cols {
            out[r * cols + c] = dot(row(a, r, stride), row(b, c, stride));
        }
    }
}

/// What one step found.
pub(crate) struct StepResult {
    pub matched: Channels,
    pub payload: Channels,
    /// Mean (unnormalised) distance of the chosen patches.
    pub cost: f64,
}

/// Query side of a step: weighted state and its patch norms.
struct Query {
    weighted: Vec<f32>,
    norms: Vec<f32>,
    frames: usize,
}

/// Distances of query patches `i0..i1` to every bank patch into `out` (row-major, `bank.len()`
/// columns): mean squared difference of weighted values, clamped at 0 (the dot-product form
/// can dip below by rounding).
fn distances(q: &Query, bank: &Bank, i0: usize, i1: usize, out: &mut [f32], scratch: &mut Vec<f32>) {
    let (p, stride, ny) = (bank.patch, bank.stride, bank.len());
    let inv = 1.0 / (p as f32 * bank.width.max(1) as f32);
    let (a0, a1) = (i0, (i1 + p - 1).min(q.frames));
    let rows = a1 - a0;
    for (k, clip) in bank.weighted.iter().enumerate() {
        let frames = bank.matched[k].frames;
        gram(&q.weighted[a0 * stride..a1 * stride], rows, clip, frames, stride, scratch);
        let first = bank.first_patch[k];
        for i in i0..i1 {
            let r = i - a0;
            let dst = &mut out[(i - i0) * ny..(i - i0 + 1) * ny];
            for b in 0..=frames - p {
                let mut s = 0.0f32;
                for o in 0..p {
                    s += scratch[(r + o) * frames + b + o];
                }
                let d = q.norms[i] + bank.norms[first + b] - 2.0 * s;
                dst[first + b] = d.max(0.0) * inv;
            }
        }
    }
}

/// Seeded choice among the nearest example patches instead of the nearest one (the source of
/// diversity between seeds; see `Settings::sample_choices`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sampling {
    /// Each query patch picks uniformly among its `choices` nearest example patches.
    pub choices: usize,
    pub seed: u64,
}

/// One matching-and-blending step: every query patch of `state` picks its nearest example
/// patch (with GenMM's completeness normalisation when `completeness` is set), or one of its
/// few nearest when `sample` says so, and every frame becomes the average of the chosen
/// patches covering it.
pub(crate) fn step(state: &Channels, bank: &Bank, weights: &[f32], completeness: Option<f32>, sample: Option<Sampling>) -> StepResult {
    step_with_limit(state, bank, weights, completeness, sample, MAX_STORED)
}

/// `step`, keeping the distance matrix only when it has at most `max_stored` entries.
fn step_with_limit(state: &Channels, bank: &Bank, weights: &[f32], completeness: Option<f32>, sample: Option<Sampling>, max_stored: usize) -> StepResult {
    let p = bank.patch;
    let (weighted, frame_norms) = weigh(state, weights, bank.stride);
    let q = Query { weighted, norms: window_sums(&frame_norms, p), frames: state.frames };
    let nq = q.norms.len();
    let ny = bank.len();
    let blocks: Vec<(usize, usize)> = (0..nq).step_by(BLOCK).map(|i| (i, (i + BLOCK).min(nq))).collect();

    let nn: Vec<(usize, f32)> = if nq * ny <= max_stored {
        let mut d = vec![0.0f32; nq * ny];
        d.par_chunks_mut(BLOCK * ny).zip(&blocks).for_each_init(Vec::new, |scratch, (out, &(i0, i1))| distances(&q, bank, i0, i1, out, scratch));
        let norm = column_normalisers(completeness, ny, d.chunks(ny));
        d.par_chunks(ny).enumerate().map(|(i, row)| pick(row, &norm, i, sample)).collect()
    } else {
        // Too big to keep: one pass for the column minima, one for the nearest neighbours.
        let mins: Vec<Vec<f32>> = blocks
            .par_iter()
            .map_init(Vec::new, |scratch, &(i0, i1)| {
                let mut out = vec![0.0f32; (i1 - i0) * ny];
                distances(&q, bank, i0, i1, &mut out, scratch);
                column_mins(ny, out.chunks(ny))
            })
            .collect();
        let norm = column_normalisers(completeness, ny, mins.iter().map(|m| m.as_slice()));
        blocks
            .par_iter()
            .map_init(Vec::new, |scratch, &(i0, i1)| {
                let mut out = vec![0.0f32; (i1 - i0) * ny];
                distances(&q, bank, i0, i1, &mut out, scratch);
                out.chunks(ny).enumerate().map(|(r, row)| pick(row, &norm, i0 + r, sample)).collect::<Vec<_>>()
            })
            .flatten()
            .collect()
    };
    let cost = nn.iter().map(|&(_, d)| d as f64).sum::<f64>() / nq.max(1) as f64;
    let choice: Vec<(usize, usize)> = nn.iter().map(|&(j, _)| bank.patches[j]).collect();
    StepResult { matched: blend(&choice, &bank.matched, state.frames, p), payload: blend(&choice, &bank.payload, state.frames, p), cost }
}

fn column_mins<'a>(ny: usize, rows: impl Iterator<Item = &'a [f32]>) -> Vec<f32> {
    let mut mins = vec![f32::INFINITY; ny];
    for row in rows {
        for (m, &v) in mins.iter_mut().zip(row) {
            *m = m.min(v);
        }
    }
    mins
}

/// Per example patch, what its distances are multiplied by: `1 / (completeness + its distance
/// to the closest query patch)`, or 1 without completeness.
fn column_normalisers<'a>(completeness: Option<f32>, ny: usize, rows: impl Iterator<Item = &'a [f32]>) -> Vec<f32> {
    match completeness {
        None => vec![1.0; ny],
        Some(c) => column_mins(ny, rows).into_iter().map(|m| 1.0 / (c + m)).collect(),
    }
}

/// The example patch query patch `query` takes: the nearest, or with `sample` one of the
/// `choices` nearest drawn from a stream of the seed and the query (so the draw does not depend
/// on how queries are split among threads).
fn pick(row: &[f32], norm: &[f32], query: usize, sample: Option<Sampling>) -> (usize, f32) {
    let Some(Sampling { choices, seed }) = sample.filter(|s| s.choices > 1) else {
        return nearest(row, norm);
    };
    // The few smallest normalised distances by insertion: `choices` is small (a handful).
    let mut best: Vec<(f32, usize)> = Vec::with_capacity(choices + 1);
    for (j, (&d, &n)) in row.iter().zip(norm).enumerate() {
        let v = d * n;
        if best.len() < choices || v < best[best.len() - 1].0 {
            let at = best.partition_point(|&(b, _)| b <= v);
            best.insert(at, (v, j));
            best.truncate(choices);
        }
    }
    // Only near ties are candidates: where one example patch fits far better than the rest
    // (e.g. the source itself is an example) it stays the choice.
    let limit = best.first().map(|b| b.0 * NEAR_TIE).unwrap_or(0.0);
    best.retain(|b| b.0 <= limit);
    if best.is_empty() {
        return nearest(row, norm);
    }
    let r = (crate::rng::stream_seed(seed, 7, query as u64) % best.len() as u64) as usize;
    let j = best[r].1;
    (j, row[j])
}

/// Index of the smallest normalised distance (first one on ties) and its raw distance.
fn nearest(row: &[f32], norm: &[f32]) -> (usize, f32) {
    let mut best = (0, f32::INFINITY, 0.0);
    for (j, (&d, &n)) in row.iter().zip(norm).enumerate() {
        let v = d * n;
        if v < best.1 {
            best = (j, v, d);
        }
    }
    (best.0, best.2)
}

/// Average of the chosen example patches over the frames they cover (`choice[i]` = clip and
/// first frame of the patch placed at frame i; `frames - p + 1` of them).
pub(crate) fn blend(choice: &[(usize, usize)], clips: &[Channels], frames: usize, p: usize) -> Channels {
    let width = clips.first().map(|c| c.width).unwrap_or(0);
    let mut out = Channels::zeros(frames, width);
    if width == 0 {
        return out;
    }
    out.data.par_chunks_mut(width).enumerate().for_each(|(t, row)| {
        let lo = t.saturating_sub(p - 1);
        let hi = t.min(choice.len().saturating_sub(1));
        // Where the chosen patches are coherent (patch i + 1 continues patch i) they all put
        // the same example frame here: add each distinct frame once, times its count.
        let mut sources: [(usize, usize, f32); 64] = [(0, 0, 0.0); 64];
        let (mut distinct, mut n) = (0usize, 0usize);
        for (i, &(k, b)) in choice.iter().enumerate().take(hi + 1).skip(lo) {
            let frame = (k, b + t - i);
            n += 1;
            if distinct > 0 && (sources[distinct - 1].0, sources[distinct - 1].1) == frame {
                sources[distinct - 1].2 += 1.0;
            } else if distinct < sources.len() {
                sources[distinct] = (frame.0, frame.1, 1.0);
                distinct += 1;
            } else {
                // More distinct frames than the buffer holds (patches over 64 frames): add
                // directly.
                for (o, &v) in row.iter_mut().zip(clips[frame.0].row(frame.1)) {
                    *o += v;
                }
            }
        }
        for &(k, f, count) in &sources[..distinct] {
            for (o, &v) in row.iter_mut().zip(clips[k].row(f)) {
                *o += count * v;
            }
        }
        if n > 0 {
            let inv = 1.0 / n as f32;
            row.iter_mut().for_each(|o| *o *= inv);
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channels(frames: usize, width: usize, f: impl Fn(usize, usize) -> f32) -> Channels {
        let mut c = Channels::zeros(frames, width);
        for t in 0..frames {
            for k in 0..width {
                c.row_mut(t)[k] = f(t, k);
            }
        }
        c
    }

    #[test]
    fn distances_match_the_direct_formula() {
        let (p, w) = (3, 11);
        let weights: Vec<f32> = (0..w).map(|k| if k % 3 == 0 { 0.85 } else { 0.15 }).collect();
        let ex = channels(9, w, |t, k| ((t * 7 + k * 3) as f32 * 0.37).sin());
        let st = channels(7, w, |t, k| ((t * 5 + k) as f32 * 0.23).cos());
        let bank = Bank::new(vec![ex.clone(), ex.resize(5)], vec![Channels::zeros(9, 0), Channels::zeros(5, 0)], &weights, p);
        assert_eq!(bank.len(), 7 + 3);
        let (weighted, fnorm) = weigh(&st, &weights, bank.stride);
        let q = Query { weighted, norms: window_sums(&fnorm, p), frames: 7 };
        let mut out = vec![0.0; 5 * bank.len()];
        distances(&q, &bank, 0, 5, &mut out, &mut Vec::new());
        for i in 0..5 {
            for (j, &(k, b)) in bank.patches.iter().enumerate() {
                let mut want = 0.0f32;
                for o in 0..p {
                    for c in 0..w {
                        let d = (st.row(i + o)[c] - bank.matched[k].row(b + o)[c]) * weights[c];
                        want += d * d;
                    }
                }
                want /= (p * w) as f32;
                assert!((out[i * bank.len() + j] - want).abs() < 1e-5, "{i} {j}");
            }
        }
    }

    #[test]
    fn the_fast_kernel_gives_the_scalar_bits() {
        // Sizes that exercise every remainder of the 4x2 tiling.
        let stride = 24;
        let a: Vec<f32> = (0..11 * stride).map(|i| ((i * 37 % 101) as f32 * 0.013).sin()).collect();
        let b: Vec<f32> = (0..7 * stride).map(|i| ((i * 53 % 97) as f32 * 0.029).cos()).collect();
        let mut g = Vec::new();
        gram(&a, 11, &b, 7, stride, &mut g);
        for r in 0..11 {
            for c in 0..7 {
                assert_eq!(g[r * 7 + c].to_bits(), dot(row(&a, r, stride), row(&b, c, stride)).to_bits(), "{r} {c}");
            }
        }
    }

    #[test]
    fn stored_and_recomputed_distances_agree() {
        let w = 13;
        let weights: Vec<f32> = (0..w).map(|k| if k < 4 { 0.85 } else { 0.15 }).collect();
        let clips: Vec<Channels> = (0..3).map(|c| channels(40 + 7 * c, w, |t, k| ((t * (3 + c) + k * 5) as f32 * 0.11).sin())).collect();
        let payload = clips.iter().map(|c| Channels::zeros(c.frames, 0)).collect();
        let bank = Bank::new(clips, payload, &weights, 5);
        let state = channels(300, w, |t, k| ((t * 7 + k) as f32 * 0.05).cos());
        let stored = step_with_limit(&state, &bank, &weights, Some(0.01), None, usize::MAX);
        let recomputed = step_with_limit(&state, &bank, &weights, Some(0.01), None, 0);
        assert_eq!(stored.matched, recomputed.matched);
        assert_eq!(stored.cost.to_bits(), recomputed.cost.to_bits());
    }

    #[test]
    fn a_state_equal_to_an_example_reproduces_it() {
        let w = 5;
        let ex = channels(20, w, |t, k| (t as f32 * 0.3 + k as f32).sin());
        let bank = Bank::new(vec![ex.clone()], vec![Channels::zeros(20, 0)], &[1.0; 5], 4);
        let r = step(&ex, &bank, &[1.0; 5], None, None);
        assert!(r.cost < 1e-6, "{}", r.cost);
        for (a, b) in r.matched.data.iter().zip(&ex.data) {
            assert!((a - b).abs() < 1e-6);
        }
    }
}
