//! Locking planted feet in generated features: a foot stays where it landed for as long as the
//! model says it is down, and the leg above it bends to keep it there.
//!
//! `plant_feet` takes the root's travel from the feet that are down, which stops their *mean*
//! slide. A foot that moves against the others still slides: the legs come out of the model
//! separately, and four feet down rarely agree. Here each stretch of frames where a foot's
//! contact channel is above one half and the foot is near the ground (`mo-sample`: within 5% of
//! the skeleton's size, the contact band of `mo-metrics physics`) gets one target, the foot's mean horizontal position over
//! the stretch (its height is left alone), eased in and out over `ease` frames either side. The
//! limb above the foot (the chain of joints with one child each, up to the first joint that
//! branches, is a foot or is the root, which stays where it is) is bent by FABRIK to reach the
//! target with its bone lengths kept, starting from the model's pose so the knee bends the way
//! it did; everything below the foot moves with it, turned as the model had it. Feet are done in
//! joint order, so a toe is locked after the foot it hangs from, by turning only the toe's bone.
//!
//! Positions are rewritten (RIC, the frame's facing frame) and so are the velocities derived
//! from them. The rotation channels are left as the model made them: generated positions and
//! rotations already disagree, and `mo-sample` decodes from the positions (`decode_ik`).

use super::decode::root_yaw;
use super::{get3, get_6d, put3, DIMS_POSITION, DIMS_ROTATION, DIMS_VELOCITY, DIM_CONTACT, FEATURE_DIMS};
use crate::motion::contact::contacts;
use crate::repr::Features;
use glam::{DQuat, DVec3};

/// Contact channel value above which a foot counts as down (as `plant_feet`).
const IN_CONTACT: f32 = 0.5;
/// FABRIK passes at most; a leg reaching a few hundredths of its length converges in a handful.
const FABRIK_ITERATIONS: usize = 20;
/// FABRIK stops when the foot is this close to its target, as a fraction of the chain's length.
const FABRIK_TOLERANCE: f64 = 1e-5;

/// The limb a foot moves: joints from the fixed base (first) to the foot (last). The base is the
/// first joint up from the foot whose position nothing here may change: the root, a foot, a
/// joint with several children, or a joint hanging from one of those (a hip socket stays on the
/// pelvis; the thigh turns about it).
fn limb(parents: &[Option<usize>], children: &[Vec<usize>], is_foot: &[bool], foot: usize) -> Option<Vec<usize>> {
    let mut chain = vec![foot];
    let mut at = parents[foot]?;
    loop {
        chain.push(at);
        let Some(up) = parents[at] else { break };
        if is_foot[at] || children[at].len() != 1 || parents[up].is_none() || children[up].len() != 1 {
            break;
        }
        at = up;
    }
    chain.reverse();
    Some(chain)
}

/// Joints below `j` (not `j`), parents first.
fn below(children: &[Vec<usize>], j: usize) -> Vec<usize> {
    let mut out = Vec::new();
    let mut stack: Vec<usize> = children[j].iter().rev().copied().collect();
    while let Some(k) = stack.pop() {
        out.push(k);
        stack.extend(children[k].iter().rev());
    }
    out
}

/// FABRIK (Aristidou & Lasenby 2011): `points[0]` stays, the last point goes to `target` (or as
/// near as the chain reaches), each segment keeps its length.
fn fabrik(points: &mut [DVec3], target: DVec3) {
    let n = points.len();
    if n < 2 {
        return;
    }
    let lengths: Vec<f64> = points.windows(2).map(|w| w[0].distance(w[1])).collect();
    let total: f64 = lengths.iter().sum();
    let base = points[0];
    let toward = |from: DVec3, to: DVec3, length: f64| from + (to - from).normalize_or_zero() * length;
    if base.distance(target) >= total {
        for i in 1..n {
            points[i] = toward(points[i - 1], target, lengths[i - 1]);
        }
        return;
    }
    for _ in 0..FABRIK_ITERATIONS {
        if points[n - 1].distance(target) <= FABRIK_TOLERANCE * total {
            break;
        }
        points[n - 1] = target;
        for i in (0..n - 1).rev() {
            points[i] = toward(points[i + 1], points[i], lengths[i]);
        }
        points[0] = base;
        for i in 1..n {
            points[i] = toward(points[i - 1], points[i], lengths[i - 1]);
        }
    }
}

/// How much of a stretch's target frame `t` takes: 1 inside, easing to 0 over `ease` frames
/// outside (smoothstep, so the leg starts and stops moving gently).
fn weight(t: usize, (s, e): (usize, usize), ease: usize) -> f64 {
    let gap = if t < s { s - t } else { t.saturating_sub(e) };
    if gap == 0 {
        return 1.0;
    }
    if gap > ease {
        return 0.0;
    }
    let x = 1.0 - gap as f64 / (ease + 1) as f64;
    x * x * (3.0 - 2.0 * x)
}

/// Lock the feet of `features` (see the module doc). `parents` is the skeleton's; a foot is held
/// only within `near_ground` (scaled units) of the ground; `fixed` cells
/// (`[frame * joints + joint]`, an edit's kept part) are not moved: a foot is not locked at a
/// frame where its limb has one. Returns how many (foot, frame) pairs were moved. Features
/// without the AnyTop layout, or a foot list that does not fit, change nothing.
pub fn lock_feet(features: &mut Features, parents: &[Option<usize>], feet: &[usize], near_ground: f64, ease: usize, fixed: Option<&[bool]>) -> usize {
    let (frames, joints) = (features.frames, features.joints);
    if features.dims != FEATURE_DIMS || joints == 0 || parents.len() != joints || feet.iter().any(|&j| j == 0 || j >= joints) {
        return 0;
    }
    if parents.iter().enumerate().any(|(j, p)| p.is_some_and(|p| p >= j)) {
        return 0; // not parents-first: not a skeleton this module can walk
    }
    let mut children = vec![Vec::new(); joints];
    for (j, p) in parents.iter().enumerate() {
        if let Some(p) = *p {
            children[p].push(j);
        }
    }
    let mut is_foot = vec![false; joints];
    feet.iter().for_each(|&f| is_foot[f] = true);

    // World positions as decoding recovers them (root x, z integrated from frame 0 at 0).
    let facing: Vec<DQuat> = (0..frames).map(|t| root_yaw(get_6d(&features.at(t, 0)[DIMS_ROTATION]))).collect();
    let mut root = vec![DVec3::ZERO; frames];
    for t in 1..frames {
        let v = get3(&features.at(t - 1, 0)[DIMS_VELOCITY]);
        root[t] = root[t - 1] + facing[t].inverse() * DVec3::new(v.x, 0.0, v.z);
        root[t].y = 0.0;
    }
    let mut world: Vec<DVec3> =
        (0..frames * joints).map(|k| facing[k / joints].inverse() * get3(&features.at(k / joints, k % joints)[DIMS_POSITION]) + root[k / joints]).collect();
    let original = world.clone();
    // Down means near the ground as well as the model's contact channel: the channel is
    // AnyTop's loose label (within 0.3 units of the ground and moving less than 0.045 a frame),
    // which on real clips also covers slow swings (a chicken's ankle drifts 0.4 units in one
    // labelled stretch); held still, those lose a sixth of the clip's motion. The ground is
    // where `mo-metrics` estimates it: the lowest foot's height, 10th percentile over frames.
    let mut lowest: Vec<f64> = (0..frames).map(|t| feet.iter().map(|&f| world[t * joints + f].y).fold(f64::INFINITY, f64::min)).collect();
    lowest.sort_by(f64::total_cmp);
    let ground = lowest.get(frames.saturating_sub(1) / 10).copied().unwrap_or(0.0);
    let mut moved = vec![false; frames * joints];
    let mut count = 0;

    let mut order: Vec<usize> = feet.to_vec();
    order.sort_unstable();
    order.dedup();
    for &foot in &order {
        let Some(chain) = limb(parents, &children, &is_foot, foot) else { continue };
        let hanging = below(&children, foot);
        // Each stretch's target: the foot's mean position over it (its height is not pulled),
        // taken after the feet above it were locked.
        let down = contacts(
            frames,
            |t| features.at(t, foot)[DIM_CONTACT] > IN_CONTACT && world[t * joints + foot].y <= ground + near_ground,
            |t| world[t * joints + foot],
        );
        for t in 0..frames {
            let pulls: Vec<(f64, DVec3)> = down.iter().map(|c| (weight(t, (c.first, c.last), ease), c.pin)).filter(|(w, _)| *w > 0.0).collect();
            if pulls.is_empty() || fixed.is_some_and(|m| chain[1..].iter().chain(&hanging).any(|&j| m.get(t * joints + j).copied().unwrap_or(true))) {
                continue;
            }
            let at = |j: usize| t * joints + j;
            let now = world[at(foot)];
            let total: f64 = pulls.iter().map(|(w, _)| w).sum();
            let mut pull = pulls.iter().fold(DVec3::ZERO, |acc, &(w, g)| acc + (g - now) * w) / total.max(1.0);
            pull.y = 0.0;
            if pull.length_squared() == 0.0 {
                continue;
            }
            let mut points: Vec<DVec3> = chain.iter().map(|&j| world[at(j)]).collect();
            fabrik(&mut points, now + pull);
            let shift = points[points.len() - 1] - now;
            for &j in &hanging {
                world[at(j)] += shift;
                moved[at(j)] = true;
            }
            for (&j, &p) in chain.iter().zip(&points).skip(1) {
                world[at(j)] = p;
                moved[at(j)] = true;
            }
            count += 1;
        }
    }

    // Back into the features: positions where moved, velocities next to anything moved.
    for t in 0..frames {
        for j in 1..joints {
            let k = t * joints + j;
            if moved[k] {
                put3(&mut features.at_mut(t, j)[DIMS_POSITION], facing[t] * (world[k] - root[t]));
            }
            let next_moved = t + 1 < frames && moved[k + joints];
            if !(moved[k] || next_moved) {
                continue;
            }
            let cell = &mut features.at_mut(t, j)[DIMS_VELOCITY];
            let velocity = if t + 1 < frames {
                facing[t + 1] * (world[k + joints] - world[k])
            } else {
                // The last frame's step goes to a frame the features do not hold: keep it,
                // less what this frame moved.
                get3(cell) - facing[t] * (world[k] - original[k])
            };
            put3(cell, velocity);
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A root walking along +z at `speed` per frame, facing `yaw`, with one leg: hip (joint 1,
    /// under the root), knee (2), foot (3), toe (4, also a foot). The leg swings back and forth
    /// relative to the body, so with the root's travel the foot slides while it is down.
    fn walker(frames: usize, yaw: f64, speed: f64, down: impl Fn(usize) -> bool) -> (Features, Vec<Option<usize>>) {
        let parents = vec![None, Some(0), Some(1), Some(2), Some(3)];
        let mut f = Features::zeros(frames, 5, FEATURE_DIMS);
        let r = DQuat::from_rotation_y(yaw);
        let m = glam::DMat3::from_quat(r);
        for t in 0..frames {
            let swing = 0.3 * (t as f64 * 0.4).sin();
            let pos = [
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.1, 0.9, 0.0),
                DVec3::new(0.1, 0.5, 0.25 + swing * 0.5),
                DVec3::new(0.1, 0.03, swing),
                DVec3::new(0.1, 0.0, swing + 0.15),
            ];
            for (j, p) in pos.iter().enumerate() {
                put3(&mut f.at_mut(t, j)[DIMS_POSITION], if j == 0 { *p } else { DVec3::new(p.x, p.y, p.z) });
            }
            let root = f.at_mut(t, 0);
            let (c0, c1) = (m.x_axis, m.y_axis);
            root[3..9].copy_from_slice(&[c0.x as f32, c0.y as f32, c0.z as f32, c1.x as f32, c1.y as f32, c1.z as f32]);
            put3(&mut root[DIMS_VELOCITY], DVec3::new(0.0, 0.0, speed));
            for j in [3, 4] {
                f.at_mut(t, j)[DIM_CONTACT] = if down(t) { 1.0 } else { 0.0 };
            }
        }
        (f, parents)
    }

    fn worlds(f: &Features) -> Vec<Vec<DVec3>> {
        let mut root = DVec3::ZERO;
        (0..f.frames)
            .map(|t| {
                let r_inv = root_yaw(get_6d(&f.at(t, 0)[DIMS_ROTATION])).inverse();
                if t > 0 {
                    let v = get3(&f.at(t - 1, 0)[DIMS_VELOCITY]);
                    root += r_inv * DVec3::new(v.x, 0.0, v.z);
                }
                (0..f.joints).map(|j| if j == 0 { root } else { r_inv * get3(&f.at(t, j)[DIMS_POSITION]) + root }).collect()
            })
            .collect()
    }

    #[test]
    fn a_locked_foot_stays_put_while_down_and_its_leg_keeps_its_bones() {
        let down = |t: usize| (4..14).contains(&t);
        let (mut f, parents) = walker(24, 0.6, 0.03, down);
        let before = worlds(&f);
        let slide = |w: &[Vec<DVec3>], j: usize| (5..14).map(|t| (w[t][j] - w[t - 1][j]).with_y(0.0).length()).sum::<f64>();
        assert!(slide(&before, 3) > 0.1, "the foot slides before: {}", slide(&before, 3));
        let moved = lock_feet(&mut f, &parents, &[3, 4], 0.05, 3, None);
        assert!(moved > 0);
        let after = worlds(&f);
        assert!(slide(&after, 3) < 1e-3, "the foot still slides {}", slide(&after, 3));
        assert!(slide(&after, 4) < 1e-3, "the toe slides {}", slide(&after, 4));
        for t in 0..24 {
            for (a, b) in [(1, 2), (2, 3), (3, 4)] {
                let (l0, l1) = (before[t][a].distance(before[t][b]), after[t][a].distance(after[t][b]));
                assert!((l0 - l1).abs() < 1e-5, "frame {t} bone {a}-{b}: {l0} -> {l1}");
            }
            // Heights are not touched for the foot; the root and hip never move.
            assert!((after[t][3].y - before[t][3].y).abs() < 1e-4, "frame {t}: {} -> {}", before[t][3].y, after[t][3].y);
            assert!(after[t][1].distance(before[t][1]) < 1e-6 && after[t][0].distance(before[t][0]) < 1e-9);
        }
        // Far from the stretch (more than the ease), the model's leg is kept.
        for t in 18..24 {
            assert!(after[t][3].distance(before[t][3]) < 1e-6, "frame {t}");
        }
        // Velocities follow the positions where they moved (frames 1..=16: the stretch and its
        // ease; the walker's own velocities are left at 0).
        for t in 0..=16 {
            let r = root_yaw(get_6d(&f.at(t + 1, 0)[DIMS_ROTATION]));
            let v = get3(&f.at(t, 3)[DIMS_VELOCITY]);
            assert!(v.distance(r * (after[t + 1][3] - after[t][3])) < 1e-5, "frame {t}");
        }
    }

    #[test]
    fn easing_moves_the_foot_gradually_and_nothing_moves_without_contact() {
        let (f0, parents) = walker(30, 0.0, 0.03, |t| (10..16).contains(&t));
        let mut f = f0.clone();
        lock_feet(&mut f, &parents, &[3], 0.05, 4, None);
        let (before, after) = (worlds(&f0), worlds(&f));
        let offset = |t: usize| after[t][3].distance(before[t][3]);
        assert!(offset(5) < 1e-9 && offset(20) < 1e-9, "outside the ease nothing moves");
        assert!(offset(6) > 0.0 && offset(19) > 0.0, "inside it the foot is pulled");
        let w: Vec<f64> = (5..=10).map(|t| weight(t, (10, 15), 4)).collect();
        assert!(w[0] == 0.0 && w.windows(2).all(|p| p[0] < p[1]) && w[5] == 1.0, "{w:?}");
        assert_eq!(weight(20, (10, 15), 4), 0.0);
        let (mut none, parents) = walker(30, 0.0, 0.03, |_| false);
        let copy = none.clone();
        assert_eq!(lock_feet(&mut none, &parents, &[3, 4], 0.05, 4, None), 0);
        assert_eq!(none.data, copy.data);
    }

    #[test]
    fn kept_cells_and_odd_inputs_are_left_alone() {
        let (f0, parents) = walker(20, 0.2, 0.03, |t| t < 12);
        let mut f = f0.clone();
        let fixed: Vec<bool> = (0..20 * 5).map(|k| k / 5 < 8).collect();
        lock_feet(&mut f, &parents, &[3], 0.05, 2, Some(&fixed));
        for t in 0..8 {
            for j in 0..5 {
                assert_eq!(f.at(t, j)[DIMS_POSITION], f0.at(t, j)[DIMS_POSITION], "kept frame {t} joint {j}");
            }
        }
        assert_ne!(f.data, f0.data, "the free frames are locked");
        let mut g = f0.clone();
        assert_eq!(lock_feet(&mut g, &parents, &[0], 0.05, 2, None), 0, "the root is not a foot");
        assert_eq!(lock_feet(&mut g, &parents, &[9], 0.05, 2, None), 0, "no such joint");
        assert_eq!(lock_feet(&mut g, &parents[..3], &[2], 0.05, 2, None), 0, "parents of another skeleton");
        let mut other = Features::zeros(5, 5, 9);
        assert_eq!(lock_feet(&mut other, &parents, &[3], 0.05, 2, None), 0);
        assert_eq!(g.data, f0.data);
    }

    #[test]
    fn fabrik_reaches_what_it_can_and_stretches_toward_the_rest() {
        let mut p = vec![DVec3::ZERO, DVec3::new(0.0, -1.0, 0.1), DVec3::new(0.0, -2.0, 0.0)];
        fabrik(&mut p, DVec3::new(0.3, -1.8, 0.2));
        assert!(p[2].distance(DVec3::new(0.3, -1.8, 0.2)) < 1e-4 && p[0] == DVec3::ZERO);
        assert!((p[0].distance(p[1]) - 1.01f64.sqrt()).abs() < 1e-9 && (p[1].distance(p[2]) - 1.01f64.sqrt()).abs() < 1e-9);
        let mut q = vec![DVec3::ZERO, DVec3::new(0.0, -1.0, 0.0), DVec3::new(0.0, -2.0, 0.0)];
        fabrik(&mut q, DVec3::new(0.0, -5.0, 0.0));
        assert!(q[2].distance(DVec3::new(0.0, -2.0, 0.0)) < 1e-12, "out of reach: straight toward it");
    }
}
