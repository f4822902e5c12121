//! Temporal smoothing of feature tracks: the Whittaker–Henderson smoother, with cells that must
//! not move and a blend into them.
//!
//! Every `(joint, dim)` track y over frames becomes the x minimising
//! `Σ_t w_t (x_t − y_t)² + λ Σ_t (x_{t+1} − 2x_t + x_{t−1})²`, optionally with some cells held
//! at their values. Why this one: it is a low-pass filter with a known response (with all
//! w = 1, `H(ω) = 1 / (1 + 16 λ sin⁴(ω/2))`, so λ follows from a cutoff in Hz), it needs no
//! padding at the clip's ends, and hard constraints are natural: the kept frames of an
//! in-betweening stay exact. Straight lines (constant velocity) pass unchanged.
//!
//! The blend (editing): generated frames rarely start where the kept ones end. A smoother
//! pinned at the kept frames absorbs that offset within the frame or two its cutoff allows — a
//! kink at the seam, however smooth the rest. So with a blend of B frames, smoothing is two
//! solves, in the spirit of inertialization in game animation:
//! 1. the generated frames alone are smoothed (kept frames weigh ~nothing), which also
//!    continues the generated motion smoothly into the kept stretches;
//! 2. the offset between kept and generated motion, known on the kept frames and 0 elsewhere,
//!    is smoothed with the kept frames pinned and λ for a half-response at a period of 2B:
//!    a correction that equals the offset on the kept frames and fades over about B frames.
//!
//! Generated frames are (1) + (2): the generated motion's own detail, shifted onto the kept
//! motion near the seams with matching velocity.
//!
//! The system per track is symmetric, positive definite and pentadiagonal: a banded LDLᵀ solves
//! it in O(frames).

use super::Features;

/// Weight of the kept frames in the first solve of a blend: small enough that they do not pull
/// the generated motion, large enough that a track with fewer than two generated frames still
/// has one solution.
const KEPT_WEIGHT: f64 = 1e-6;

/// λ whose response is one half at `cutoff_hz` for motion sampled at `fps`; `None` when the
/// cutoff is not a positive frequency below Nyquist (no smoothing would be asked for).
pub fn lambda_for_cutoff(cutoff_hz: f64, fps: f64) -> Option<f64> {
    if !(cutoff_hz > 0.0 && fps > 0.0 && cutoff_hz < fps / 2.0) {
        return None;
    }
    let s = (std::f64::consts::PI * cutoff_hz / fps).sin();
    Some(1.0 / (16.0 * s.powi(4)))
}

/// Smooth every `(joint, dim)` track of `features` over time with weight `lambda` (see the
/// module doc). `fixed`, if given, is per cell `[frame * joints + joint]`: those cells keep their
/// values exactly; the rest are smoothed and, with `blend` > 0 frames, blended into them over
/// about that many frames (0: pinned smoothing only). Clips of fewer than three frames have no
/// second differences and are left alone, as is everything when `lambda` is not positive.
pub fn smooth_features(features: &mut Features, lambda: f64, fixed: Option<&[bool]>, blend: usize) {
    let (frames, joints, dims) = (features.frames, features.joints, features.dims);
    if frames < 3 || !(lambda > 0.0) || !lambda.is_finite() {
        return;
    }
    // Half-response at a period of 2·blend frames (blend >= 2; shorter blends are the cutoff's).
    let blend_lambda = (blend >= 2).then(|| lambda_for_cutoff(1.0, 2.0 * blend as f64)).flatten();
    let none = vec![false; frames];
    let ones = vec![1.0f64; frames];
    let mut track = vec![0.0f64; frames];
    let mut offset = vec![0.0f64; frames];
    let mut pinned = vec![false; frames];
    let mut kept_light = vec![1.0f64; frames];
    let mut plain = Solver::new(frames);
    let mut generated = Solver::new(frames);
    let mut fade = Solver::new(frames);
    for j in 0..joints {
        for (t, p) in pinned.iter_mut().enumerate() {
            *p = fixed.is_some_and(|m| m.get(t * joints + j).copied().unwrap_or(false));
        }
        if pinned.iter().all(|&p| p) {
            continue;
        }
        let blended = match blend_lambda {
            Some(fade_lambda) if pinned.iter().any(|&p| p) => {
                for (w, &p) in kept_light.iter_mut().zip(&pinned) {
                    *w = if p { KEPT_WEIGHT } else { 1.0 };
                }
                generated.factor(lambda, &none, &kept_light);
                fade.factor(fade_lambda, &pinned, &ones);
                true
            }
            _ => {
                plain.factor(lambda, &pinned, &ones);
                false
            }
        };
        for d in 0..dims {
            let at = |t: usize| (t * joints + j) * dims + d;
            for (t, v) in track.iter_mut().enumerate() {
                *v = features.data[at(t)] as f64;
            }
            if blended {
                let kept = track.clone();
                generated.solve(&mut track);
                for t in 0..frames {
                    offset[t] = if pinned[t] { kept[t] - track[t] } else { 0.0 };
                }
                fade.solve(&mut offset);
                for (v, o) in track.iter_mut().zip(&offset) {
                    *v += o;
                }
            } else {
                plain.solve(&mut track);
            }
            for (t, v) in track.iter().enumerate() {
                if !pinned[t] {
                    features.data[at(t)] = *v as f32;
                }
            }
        }
    }
}

/// `W + λ DᵀD` with the pinned rows and columns taken out (identity there), factored as LDLᵀ
/// with two sub-diagonals, plus the coupling of free cells to pinned ones for the right side.
struct Solver {
    /// The system's bands: `a0[i] = A[i][i]`, `a1[i] = A[i][i+1]`, `a2[i] = A[i][i+2]`, before
    /// pinning (pinned neighbours move to the right-hand side through them).
    a0: Vec<f64>,
    a1: Vec<f64>,
    a2: Vec<f64>,
    /// The factor: `l1[i] = L[i][i−1]`, `l2[i] = L[i][i−2]`, `d[i] = D[i]`.
    l1: Vec<f64>,
    l2: Vec<f64>,
    d: Vec<f64>,
    pinned: Vec<bool>,
    /// The data weights (the right side is `w·y`).
    w: Vec<f64>,
    rhs: Vec<f64>,
}

impl Solver {
    fn new(n: usize) -> Solver {
        Solver {
            a0: vec![0.0; n],
            a1: vec![0.0; n],
            a2: vec![0.0; n],
            l1: vec![0.0; n],
            l2: vec![0.0; n],
            d: vec![0.0; n],
            pinned: vec![false; n],
            w: vec![1.0; n],
            rhs: vec![0.0; n],
        }
    }

    fn factor(&mut self, lambda: f64, pinned: &[bool], weight: &[f64]) {
        let n = self.d.len();
        self.pinned.copy_from_slice(pinned);
        self.a0.copy_from_slice(weight);
        self.w.copy_from_slice(weight);
        self.a1.fill(0.0);
        self.a2.fill(0.0);
        // DᵀD as a sum over the second-difference rows (1, −2, 1) at frames r, r+1, r+2.
        const C: [f64; 3] = [1.0, -2.0, 1.0];
        for r in 0..n - 2 {
            for a in 0..3 {
                self.a0[r + a] += lambda * C[a] * C[a];
                if a < 2 {
                    self.a1[r + a] += lambda * C[a] * C[a + 1];
                }
            }
            self.a2[r] += lambda * C[0] * C[2];
        }
        // The pinned system: a pinned cell's row and column are the identity's.
        let band = |i: usize, k: usize, s: &Solver| -> f64 {
            if s.pinned[i] || s.pinned[k] {
                return if i == k { 1.0 } else { 0.0 };
            }
            match i.abs_diff(k) {
                0 => s.a0[i],
                1 => s.a1[i.min(k)],
                2 => s.a2[i.min(k)],
                _ => 0.0,
            }
        };
        for i in 0..n {
            let l2 = if i >= 2 { band(i, i - 2, self) / self.d[i - 2] } else { 0.0 };
            let l1 = if i >= 1 {
                let carried = if i >= 2 { l2 * self.d[i - 2] * self.l1[i - 1] } else { 0.0 };
                (band(i, i - 1, self) - carried) / self.d[i - 1]
            } else {
                0.0
            };
            let mut d = band(i, i, self) - l1 * l1 * if i >= 1 { self.d[i - 1] } else { 0.0 };
            if i >= 2 {
                d -= l2 * l2 * self.d[i - 2];
            }
            self.l1[i] = l1;
            self.l2[i] = l2;
            self.d[i] = d;
        }
    }

    /// Overwrite `y` (the track, pinned cells holding their values) with the smoothed track.
    fn solve(&mut self, y: &mut [f64]) {
        let n = y.len();
        // Right side: free cells see their pinned neighbours through the unpinned bands.
        for i in 0..n {
            if self.pinned[i] {
                self.rhs[i] = y[i];
                continue;
            }
            self.rhs[i] = self.w[i] * y[i];
            for k in i.saturating_sub(2)..(i + 3).min(n) {
                if self.pinned[k] {
                    let a = match i.abs_diff(k) {
                        1 => self.a1[i.min(k)],
                        2 => self.a2[i.min(k)],
                        _ => 0.0,
                    };
                    self.rhs[i] -= a * y[k];
                }
            }
        }
        for i in 0..n {
            let mut z = self.rhs[i];
            if i >= 1 {
                z -= self.l1[i] * y[i - 1];
            }
            if i >= 2 {
                z -= self.l2[i] * y[i - 2];
            }
            y[i] = z;
        }
        for v in y.iter_mut().zip(&self.d) {
            *v.0 /= v.1;
        }
        for i in (0..n).rev() {
            let mut x = y[i];
            if i + 1 < n {
                x -= self.l1[i + 1] * y[i + 1];
            }
            if i + 2 < n {
                x -= self.l2[i + 2] * y[i + 2];
            }
            y[i] = x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same minimisation solved densely (Gaussian elimination with partial pivoting).
    fn dense(y: &[f64], lambda: f64, pinned: &[bool], weight: &[f64]) -> Vec<f64> {
        let n = y.len();
        let mut a = vec![vec![0.0; n + 1]; n];
        for (i, row) in a.iter_mut().enumerate() {
            row[i] = weight[i];
            row[n] = weight[i] * y[i];
        }
        for r in 0..n - 2 {
            let c = [1.0, -2.0, 1.0];
            for p in 0..3 {
                for q in 0..3 {
                    a[r + p][r + q] += lambda * c[p] * c[q];
                }
            }
        }
        for i in 0..n {
            if pinned[i] {
                a[i] = vec![0.0; n + 1];
                a[i][i] = 1.0;
                a[i][n] = y[i];
            }
        }
        for col in 0..n {
            let p = (col..n).max_by(|&x, &z| a[x][col].abs().total_cmp(&a[z][col].abs())).unwrap();
            a.swap(col, p);
            for r in 0..n {
                if r != col {
                    let f = a[r][col] / a[col][col];
                    for c in col..=n {
                        a[r][c] -= f * a[col][c];
                    }
                }
            }
        }
        (0..n).map(|i| a[i][n] / a[i][i]).collect()
    }

    fn track(features: &Features, j: usize, d: usize) -> Vec<f64> {
        (0..features.frames).map(|t| features.at(t, j)[d] as f64).collect()
    }

    fn wiggly(frames: usize, joints: usize, dims: usize) -> Features {
        let mut f = Features::zeros(frames, joints, dims);
        for (k, v) in f.data.iter_mut().enumerate() {
            // Deterministic, rough: a slow wave plus a frame-to-frame sawtooth.
            let t = (k / (joints * dims)) as f64;
            *v = ((t * 0.2 + k as f64 * 0.37).sin() + if (t as usize).is_multiple_of(2) { 0.3 } else { -0.3 }) as f32;
        }
        f
    }

    #[test]
    fn banded_solution_is_the_dense_minimiser_with_and_without_pinned_cells() {
        let frames = 23;
        let y: Vec<f64> = (0..frames).map(|t| (t as f64 * 0.9).sin() + if t % 2 == 0 { 0.3 } else { -0.3 }).collect();
        let free = vec![false; frames];
        let ends: Vec<bool> = (0..frames).map(|t| t < 4 || t >= 19 || t == 11).collect();
        let alternate: Vec<bool> = (0..frames).map(|t| t % 2 == 0).collect();
        let ones = vec![1.0; frames];
        let uneven: Vec<f64> = (0..frames).map(|t| if t < 6 { KEPT_WEIGHT } else { 0.2 + (t % 5) as f64 }).collect();
        for lambda in [0.3, 4.0, 250.0] {
            for (pins, weight) in [(&free, &ones), (&ends, &ones), (&alternate, &ones), (&free, &uneven), (&ends, &uneven)] {
                let mut solver = Solver::new(frames);
                solver.factor(lambda, pins, weight);
                let mut got = y.clone();
                solver.solve(&mut got);
                let want = dense(&y, lambda, pins, weight);
                for (t, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert!((g - w).abs() < 1e-6 * (1.0 + w.abs()), "lambda {lambda} frame {t}: {g} vs {w}");
                }
            }
        }
        // And smooth_features is that solve per track when nothing is blended.
        let (joints, dims) = (3, 2);
        let original = wiggly(frames, joints, dims);
        let mut f = original.clone();
        let fixed: Vec<bool> = (0..frames * joints).map(|k| k % joints == 1 && ends[k / joints]).collect();
        smooth_features(&mut f, 4.0, Some(&fixed), 0);
        for j in 0..joints {
            let pins: Vec<bool> = (0..frames).map(|t| fixed[t * joints + j]).collect();
            for d in 0..dims {
                let want = dense(&track(&original, j, d), 4.0, &pins, &ones);
                for (g, w) in track(&f, j, d).iter().zip(&want) {
                    assert!((g - w).abs() < 1e-5, "joint {j} dim {d}: {g} vs {w}");
                }
            }
        }
    }

    #[test]
    fn pinned_cells_stay_exact_and_lines_pass_unchanged() {
        let mut f = wiggly(40, 2, 3);
        let before = f.clone();
        let mut fixed = vec![false; 40 * 2];
        for t in (0..10).chain(30..40) {
            fixed[t * 2] = true;
            fixed[t * 2 + 1] = true;
        }
        smooth_features(&mut f, 10.0, Some(&fixed), 5);
        for (k, (a, b)) in f.data.iter().zip(&before.data).enumerate() {
            if fixed[k / 3] {
                assert_eq!(a.to_bits(), b.to_bits(), "pinned value {k} moved");
            }
        }
        assert_ne!(f, before, "the free frames were smoothed");

        let mut line = Features::zeros(50, 1, 1);
        for (t, v) in line.data.iter_mut().enumerate() {
            *v = 0.5 + 0.25 * t as f32;
        }
        let straight = line.clone();
        smooth_features(&mut line, 1e3, None, 0);
        for (a, b) in line.data.iter().zip(&straight.data) {
            assert!((a - b).abs() < 1e-3, "{a} vs {b}");
        }
    }

    #[test]
    fn the_cutoff_halves_a_wave_at_that_frequency_and_keeps_slow_ones() {
        let fps = 30.0;
        let lambda = lambda_for_cutoff(6.0, fps).unwrap();
        let amplitude = |hz: f64| {
            let mut f = Features::zeros(600, 1, 1);
            for (t, v) in f.data.iter_mut().enumerate() {
                *v = (2.0 * std::f64::consts::PI * hz * t as f64 / fps).sin() as f32;
            }
            let peak = |f: &Features| f.data[200..400].iter().fold(0.0f32, |m, v| m.max(v.abs())) as f64;
            let raw = peak(&f);
            smooth_features(&mut f, lambda, None, 0);
            // Away from the ends, where the steady-state response holds; against the sampled
            // wave's own peak (at 6 Hz and 30 fps the samples miss the crest).
            peak(&f) / raw
        };
        assert!((amplitude(6.0) - 0.5).abs() < 0.02, "{}", amplitude(6.0));
        assert!(amplitude(1.0) > 0.99, "{}", amplitude(1.0));
        // Everywhere the module doc's response.
        for hz in [2.0, 9.0, 12.0] {
            let s = (std::f64::consts::PI * hz / fps).sin();
            let want = 1.0 / (1.0 + 16.0 * lambda * s.powi(4));
            assert!((amplitude(hz) - want).abs() < 0.02, "{hz} Hz: {} vs {want}", amplitude(hz));
        }
        assert_eq!(lambda_for_cutoff(15.0, fps), None);
        assert_eq!(lambda_for_cutoff(0.0, fps), None);
    }

    #[test]
    fn short_clips_and_all_pinned_tracks_are_left_alone() {
        let mut two = wiggly(2, 2, 2);
        let before = two.clone();
        smooth_features(&mut two, 5.0, None, 0);
        assert_eq!(two, before);
        let mut f = wiggly(10, 1, 2);
        let before = f.clone();
        smooth_features(&mut f, 5.0, Some(&[true; 10]), 4);
        assert_eq!(f, before);
    }

    #[test]
    fn a_blend_spreads_an_offset_at_a_seam_instead_of_kinking() {
        // Kept: a track moving at constant velocity for 20 frames; generated: the same
        // velocity but 0.5 higher, as a generated stretch that starts in the wrong place.
        let frames = 60;
        let mut f = Features::zeros(frames, 1, 1);
        for (t, v) in f.data.iter_mut().enumerate() {
            *v = 0.01 * t as f32 + if t >= 20 { 0.5 } else { 0.0 };
        }
        let fixed: Vec<bool> = (0..frames).map(|t| t < 20).collect();
        let lambda = lambda_for_cutoff(6.0, 30.0).unwrap();
        let worst_acceleration = |blend: usize| {
            let mut g = f.clone();
            smooth_features(&mut g, lambda, Some(&fixed), blend);
            let x: Vec<f64> = g.data.iter().map(|&v| v as f64).collect();
            (1..frames - 1).map(|t| (x[t + 1] - 2.0 * x[t] + x[t - 1]).abs()).fold(0.0, f64::max)
        };
        let kink = worst_acceleration(0);
        let blended = worst_acceleration(15);
        assert!(kink > 0.1, "without a blend the offset lands in a couple of frames: {kink}");
        // Spread over ~15 frames, an offset of 0.5 needs accelerations of order 6 · 0.5 / 15².
        assert!(blended < 0.03 && blended < kink / 10.0, "with a 15-frame blend: {blended} (without: {kink})");
        // And past the blend the generated frames are back (up to the smoother's tail).
        let mut g = f.clone();
        smooth_features(&mut g, lambda, Some(&fixed), 15);
        assert!((g.data[50] - f.data[50]).abs() < 0.01, "{} vs {}", g.data[50], f.data[50]);
    }
}
