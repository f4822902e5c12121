use super::*;
use crate::rng::SplitMix64;

/// Frames that sit around `centres[i]` for `counts[i]` frames, in time order, in `dims`
/// dimensions (centre values fill the first two, the rest is noise).
fn phases(centres: &[[f64; 2]], counts: &[usize], dims: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::new();
    for (c, &n) in centres.iter().zip(counts) {
        for _ in 0..n {
            let mut f: Vec<f64> = (0..dims).map(|_| rng.range(-0.3, 0.3)).collect();
            f[0] += c[0];
            f[1] += c[1];
            out.push(f);
        }
    }
    out
}

fn options(k: usize, pca_dims: usize, window: usize, min_segment: usize) -> SegmentOptions {
    SegmentOptions { k, pca_dims, window, min_segment, standardise: false, restarts: 4, refine: true }
}

#[test]
fn two_and_three_phases_are_found_at_their_boundaries() {
    let frames = phases(&[[0.0, 0.0], [4.0, 1.0]], &[40, 30], 6, 1);
    let s = segment(&frames, &options(2, 3, 0, 1), 5).unwrap();
    assert_eq!(s.segments, vec![Segment { start: 0, end: 40, label: 0 }, Segment { start: 40, end: 70, label: 1 }]);
    assert_eq!(s.pca_dims, 3);
    assert!(s.explained_variance > 0.5 && s.explained_variance <= 1.0);

    // Phase 3 returns to phase 1's place: a third segment with label 0 again.
    let frames = phases(&[[0.0, 0.0], [4.0, 1.0], [0.0, 0.0], [-3.0, 5.0]], &[30, 20, 25, 15], 5, 2);
    let s = segment(&frames, &options(3, 4, 0, 1), 9).unwrap();
    assert_eq!(boundaries(&s.labels), vec![30, 50, 75]);
    assert_eq!(s.labels[60], 0);
    assert_eq!(s.labels[80], 2);
    assert_eq!(s.clusters, 3);
}

#[test]
fn context_window_tells_a_varying_phase_from_a_still_one() {
    // A "walk" alternates between two poses every 3 frames, a "stand" sits between them: on
    // single frames k = 2 splits the walk by pose; with a window it splits walk from stand.
    let walk = |t: usize| if (t / 3).is_multiple_of(2) { vec![1.0, 0.0] } else { vec![-1.0, 0.0] };
    let mut frames: Vec<Vec<f64>> = (0..60).map(walk).collect();
    frames.extend((0..40).map(|_| vec![0.0, 0.0]));
    frames.extend((0..60).map(walk));
    let single = segment(&frames, &options(2, 0, 0, 1), 3).unwrap();
    assert!(boundaries(&single.labels).len() > 10, "single frames cluster poses: {:?}", single.segments);
    let windowed = segment(&frames, &options(2, 0, 12, 8), 3).unwrap();
    let b = boundaries(&windowed.labels);
    assert_eq!(b.len(), 2, "{:?}", windowed.segments);
    assert!(b[0].abs_diff(60) <= 6 && b[1].abs_diff(100) <= 6, "{b:?}");
}

#[test]
fn refine_moves_a_boundary_to_the_change_of_activity() {
    // Still for 50 frames, then alternating: the change is at 50; a boundary at 44 moves there.
    let points: Vec<Vec<f64>> = (0..100)
        .map(|t| {
            vec![if t < 50 {
                0.0
            } else if t % 2 == 0 {
                1.0
            } else {
                -1.0
            }]
        })
        .collect();
    let labels = [vec![0; 44], vec![1; 56]].concat();
    assert_eq!(boundaries(&refine(&points, &labels, 8)), vec![50]);
    // Out of sight (radius 3 looks at frames 38..50, all still): every split scores the same and
    // the boundary stays.
    assert_eq!(boundaries(&refine(&points, &labels, 3)), vec![44]);
    assert_eq!(refine(&points, &labels, 0), labels);
    assert_eq!(boundaries(&refine(&points, &labels, usize::MAX)), vec![50]);
    assert_eq!(context(&points, usize::MAX).len(), 100);
}

#[test]
fn same_seed_same_labels() {
    let frames = phases(&[[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]], &[25, 25, 25], 8, 4);
    let o = SegmentOptions::default();
    assert_eq!(segment(&frames, &o, 17).unwrap(), segment(&frames, &o, 17).unwrap());
}

#[test]
fn smoothing_removes_flickers_and_short_end_runs() {
    let mut labels = vec![0; 20];
    labels[7] = 1; // a one-frame flicker inside a run of 0
    labels.extend(vec![1; 15]);
    labels.extend(vec![2; 2]); // a short run at the end
    let s = smooth(&labels, 3);
    assert_eq!(s, [vec![0; 20], vec![1; 17]].concat());
    // The shortest run goes first, into its longer neighbour (0, not 2); then the short end run
    // joins its only neighbour.
    let labels = [vec![0; 10], vec![1; 2], vec![2; 4], vec![0; 3]].concat();
    assert_eq!(smooth(&labels, 4), [vec![0; 12], vec![1; 7]].concat());
    // min_segment 0 or 1 changes nothing; one run stays even when it is short.
    assert_eq!(smooth(&labels, 1), labels);
    assert_eq!(smooth(&[3, 3], 10), vec![0, 0]);
    assert_eq!(smooth(&[], 5), Vec::<usize>::new());
}

#[test]
fn segments_boundaries_and_their_errors() {
    let labels = [0, 0, 1, 1, 1, 0, 2];
    assert_eq!(
        segments(&labels),
        vec![
            Segment { start: 0, end: 2, label: 0 },
            Segment { start: 2, end: 5, label: 1 },
            Segment { start: 5, end: 6, label: 0 },
            Segment { start: 6, end: 7, label: 2 }
        ]
    );
    assert_eq!(boundaries(&labels), vec![2, 5, 6]);
    let e = boundary_errors(&[12, 48, 90], &[10, 50]);
    assert_eq!(e.errors, vec![Some(2), Some(2)]);
    assert_eq!(e.spurious, 1);
    let none = boundary_errors(&[], &[10]);
    assert_eq!(none.errors, vec![None]);
    assert_eq!(none.spurious, 0);
    assert_eq!(boundary_errors(&[5, 7], &[]).spurious, 2);
    assert_eq!(extend_labels(&[0, 1], 4), vec![0, 1, 1, 1]);
}

#[test]
fn degenerate_inputs_are_errors_or_trivial_answers() {
    assert_eq!(segment(&[], &SegmentOptions::default(), 0), Err(SegmentError::Empty));
    let one = segment(&[vec![1.0, 2.0]], &options(1, 8, 30, 10), 0).unwrap();
    assert_eq!(one.labels, vec![0]);
    assert_eq!(one.segments, vec![Segment { start: 0, end: 1, label: 0 }]);
    assert!(matches!(segment(&vec![vec![1.0]; 2], &options(3, 2, 0, 1), 0), Err(SegmentError::TooFewFrames { k: 3, frames: 2 })));
    let huge = SegmentOptions { window: usize::MAX, min_segment: usize::MAX, pca_dims: usize::MAX, ..SegmentOptions::default() };
    assert_eq!(segment(&phases(&[[0.0, 0.0]], &[12], 3, 1), &huge, 0).unwrap().labels, vec![0; 12]);
    let constant = segment(&vec![vec![0.5; 4]; 20], &SegmentOptions::default(), 0).unwrap();
    assert_eq!(constant.labels, vec![0; 20]);
    assert!(constant.explained_variance.is_finite());
    let mut nan = vec![vec![0.0; 3]; 5];
    nan[3][1] = f64::INFINITY;
    assert_eq!(segment(&nan, &SegmentOptions::default(), 0), Err(SegmentError::NonFinite { frame: 3, dim: 1 }));
}

#[test]
fn raw_features_drop_the_root_facing() {
    let mut f = Features::zeros(2, 3, FEATURE_DIMS);
    f.at_mut(1, 0)[4] = 9.0; // root facing: dropped
    f.at_mut(1, 1)[4] = 2.0; // a joint's rotation: kept
    let rows = raw_frame_features(&f);
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].len(), 3 * FEATURE_DIMS - 6);
    assert!(!rows[1].contains(&9.0));
    assert!(rows[1].contains(&2.0));
}
