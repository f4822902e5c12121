//! Topology descriptors against brute-force references written independently here:
//!
//! * relations R straight from AnyTop's definition (docs/reference/anytop.md §2.4): for row i and
//!   column j the first matching rule wins: 0 self, 2 child (parent(j) = i), 1 parent
//!   (j = parent(i)), 3 sibling (parent(j) = parent(i)), 4 none; then the diagonal entry of every
//!   joint without children becomes 5;
//! * distances D from ancestor lists: hops(i, j) = depth(i) + depth(j) - 2 depth(lca(i, j)),
//!   capped at d_max;
//! * kinematic chains checked by their properties, not by re-deriving them.
//!
//! On every corpus file (skipped without ../shared/data), every synthetic creature in
//! examples/data, and programmatic skeletons of up to 143 joints (AnyTop's largest).
use crate::common;

use common::topology::{reference_distances, reference_relations};

use glam::DVec3;
use menagerie::bvh::{self, Channel};
use menagerie::document::{MotionInfo, SkeletonDocument};
use menagerie::motion::Motion;
use menagerie::skeleton::topology::{self, distances, end_effectors, kinematic_chains, relations};
use menagerie::skeleton::{Joint, Skeleton};
use std::path::Path;

const DMAXES: [usize; 4] = [1, 2, 5, 8];

/// First differing cell of two matrices, for a readable failure.
fn first_difference(a: &[Vec<u8>], b: &[Vec<u8>]) -> Option<(usize, usize, u8, u8)> {
    assert_eq!(a.len(), b.len(), "matrix sizes differ");
    for (i, (ra, rb)) in a.iter().zip(b).enumerate() {
        assert_eq!(ra.len(), rb.len(), "row {i} lengths differ");
        if let Some(j) = (0..ra.len()).find(|&j| ra[j] != rb[j]) {
            return Some((i, j, ra[j], rb[j]));
        }
    }
    None
}

/// R and D for every d_max, end effectors and chains of one skeleton.
fn check_skeleton(name: &str, skeleton: &Skeleton) {
    skeleton.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    let parents = skeleton.parents();
    let n = parents.len();

    let r = relations(skeleton);
    if let Some((i, j, got, want)) = first_difference(&r, &reference_relations(&parents)) {
        panic!("{name}: relations R[{i}][{j}] = {got}, reference {want} (parents {:?}, {:?})", parents[i], parents[j]);
    }
    for dmax in DMAXES {
        let d = distances(skeleton, dmax);
        if let Some((i, j, got, want)) = first_difference(&d, &reference_distances(&parents, dmax)) {
            panic!("{name}: distances (dmax {dmax}) D[{i}][{j}] = {got}, reference {want}");
        }
    }

    let mut has_child = vec![false; n];
    for p in parents.iter().flatten() {
        has_child[*p] = true;
    }
    let leaves: Vec<usize> = (0..n).filter(|&j| !has_child[j]).collect();
    assert_eq!(end_effectors(skeleton), leaves, "{name}: end effectors");

    check_chains(name, skeleton, &has_child);
}

fn check_chains(name: &str, skeleton: &Skeleton, has_child: &[bool]) {
    let parents = skeleton.parents();
    let n = parents.len();
    let chains = kinematic_chains(skeleton);
    assert!(!chains.is_empty(), "{name}: no chains");
    let mut seen_after_first = vec![0usize; n];
    for (c, chain) in chains.iter().enumerate() {
        assert!(chain.len() >= 2 || n == 1, "{name}: chain {c} {chain:?} has no bone");
        for w in chain.windows(2) {
            assert_eq!(parents[w[1]], Some(w[0]), "{name}: chain {c} {chain:?}: {} -> {} is not parent -> child", w[0], w[1]);
        }
        let last = *chain.last().unwrap();
        assert!(!has_child[last], "{name}: chain {c} {chain:?} ends at joint {last}, which has children");
        for &j in &chain[1..] {
            seen_after_first[j] += 1;
        }
        // A chain starts at the root or at a branching joint (module doc).
        let first = chain[0];
        let branching = parents.iter().filter(|p| **p == Some(first)).count() >= 2;
        assert!(first == 0 || branching, "{name}: chain {c} {chain:?} starts at joint {first}, neither root nor a branch");
    }
    for j in 0..n {
        let want = usize::from(parents[j].is_some());
        assert_eq!(seen_after_first[j], want, "{name}: joint {j} appears {} times as a non-first chain element (want {want})", seen_after_first[j]);
    }
    assert!(chains.iter().any(|c| c[0] == 0), "{name}: no chain starts at the root");
}

/// Check one BVH file's skeleton; returns its parent list.
fn check_bvh_file(path: &Path) -> Vec<Option<usize>> {
    let name = path.display().to_string();
    let parsed = bvh::read_path(path).unwrap_or_else(|e| panic!("{e}"));
    let skeleton = Skeleton::from_bvh(&parsed);
    check_skeleton(&name, &skeleton);
    skeleton.parents()
}

#[test]
fn corpus_topology_matches_brute_force() {
    let Some(data) = common::shared_data("corpus_topology_matches_brute_force") else { return };
    let files = common::corpus_bvh_files(&data);
    let mut shapes = std::collections::BTreeSet::new();
    for path in &files {
        shapes.insert(check_bvh_file(path));
    }
    println!("topology vs brute force: {} corpus files ({} distinct parent lists), dmax {DMAXES:?}", files.len(), shapes.len());
}

#[test]
fn example_creatures_topology_matches_brute_force() {
    let files = common::example_bvh_files();
    for path in &files {
        check_bvh_file(path);
    }
    println!("topology vs brute force: {} synthetic skeletons in examples/data checked", files.len());
}

/// A joint-only skeleton from a parent list (3 rotation channels, 6 on the root, End Sites on
/// leaves), with names and offsets that look like a creature's.
fn skeleton_from_parents(parents: &[Option<usize>]) -> Skeleton {
    let n = parents.len();
    let mut has_child = vec![false; n];
    for p in parents.iter().flatten() {
        has_child[*p] = true;
    }
    let rot = [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];
    let joints = (0..n)
        .map(|j| {
            let (name, offset, channels) = match parents[j] {
                None => ("Hips".to_string(), DVec3::new(0.0, 50.0, 0.0), {
                    let mut c = vec![Channel::Xposition, Channel::Yposition, Channel::Zposition];
                    c.extend(rot);
                    c
                }),
                Some(p) => {
                    // Spread children around their parent so the rest pose is not degenerate.
                    let a = j as f64 * 2.399963; // golden angle
                    let side = if a.cos() >= 0.0 { "Left" } else { "Right" };
                    let offset = DVec3::new(3.0 * a.cos(), 2.0 + (j % 5) as f64, 3.0 * a.sin()) * (1.0 + (p % 3) as f64 * 0.25);
                    (format!("{side}Segment{j}"), offset, rot.to_vec())
                }
            };
            Joint { name, parent: parents[j], offset, channels, end_sites: if has_child[j] { Vec::new() } else { vec![DVec3::new(0.0, 1.5, 0.5)] } }
        })
        .collect();
    Skeleton { joints, frame_time: 1.0 / 30.0 }
}

/// A deterministic branching tree: each joint usually continues the previous one's chain and
/// sometimes branches off an earlier joint (a tiny linear congruential generator).
fn branching_parents(n: usize, seed: u64) -> Vec<Option<usize>> {
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 33) as usize
    };
    let mut parents = vec![None];
    for j in 1..n {
        parents.push(Some(if next() % 10 < 7 { j - 1 } else { next() % j }));
    }
    parents
}

/// A "creature" shape: spine, neck and head, 8 legs with toes, 2 arms with 5 three-joint
/// fingers, a long tail; 143 joints in all.
fn creature_parents() -> Vec<Option<usize>> {
    let mut parents: Vec<Option<usize>> = vec![None];
    let chain = |parents: &mut Vec<Option<usize>>, from: usize, len: usize| -> usize {
        let mut at = from;
        for _ in 0..len {
            parents.push(Some(at));
            at = parents.len() - 1;
        }
        at
    };
    let chest = chain(&mut parents, 0, 4); // 4 spine
    let _head = chain(&mut parents, chest, 4); // 3 neck + head
    for leg in 0..8 {
        let hip = if leg < 4 { 0 } else { chest };
        let ankle = chain(&mut parents, hip, 4);
        chain(&mut parents, ankle, 3); // toes
        chain(&mut parents, ankle, 2);
    }
    for _arm in 0..2 {
        let hand = chain(&mut parents, chest, 4);
        for _finger in 0..5 {
            chain(&mut parents, hand, 3);
        }
    }
    let have = parents.len();
    chain(&mut parents, 0, 143 - have); // tail
    parents
}

#[test]
fn programmatic_skeletons_match_brute_force() {
    let mut shapes: Vec<(String, Vec<Option<usize>>)> = vec![
        ("single joint".into(), vec![None]),
        ("two joints".into(), vec![None, Some(0)]),
        ("chain of 143".into(), (0..143usize).map(|j| j.checked_sub(1)).collect()),
        ("star of 143".into(), (0..143).map(|j| if j == 0 { None } else { Some(0) }).collect()),
        ("creature of 143".into(), creature_parents()),
    ];
    for seed in 1..=8 {
        shapes.push((format!("branching tree of 143 (seed {seed})"), branching_parents(143, seed)));
    }
    for n in [3, 7, 20, 64] {
        shapes.push((format!("branching tree of {n}"), branching_parents(n, n as u64)));
    }
    for (name, parents) in &shapes {
        check_skeleton(name, &skeleton_from_parents(parents));
    }
    println!("topology vs brute force: {} programmatic skeletons checked", shapes.len());
}

/// The 143-joint skeleton's document builds, carries R/D equal to the brute force, and reads back.
#[test]
fn document_of_143_joints() {
    for (name, parents) in [("creature", creature_parents()), ("branching", branching_parents(143, 42))] {
        assert_eq!(parents.len(), 143);
        let skeleton = skeleton_from_parents(&parents);
        check_skeleton(name, &skeleton);
        let rest = Motion::rest(&skeleton).to_bvh(&skeleton);
        for m in [None, MotionInfo::of(&rest, &skeleton)] {
            let doc = SkeletonDocument::build(&skeleton, m.clone(), name, topology::DEFAULT_DMAX);
            assert_eq!(doc.joint_count, 143);
            assert_eq!(doc.joints.len(), 143);
            assert_eq!(doc.topology.dmax, 5);
            assert_eq!(doc.topology.relations, reference_relations(&parents), "{name}: document relations");
            assert_eq!(doc.topology.distances, reference_distances(&parents, 5), "{name}: document distances");
            assert_eq!(doc.topology.chains, kinematic_chains(&skeleton));
            assert_eq!(doc.motion.is_some(), m.is_some());
            let json = serde_json::to_string(&doc).unwrap();
            let back = SkeletonDocument::from_json(&json).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(back.skeleton().unwrap(), skeleton, "{name}: document -> skeleton");
            for (j, e) in doc.joints.iter().enumerate() {
                assert_eq!(e.parent, parents[j]);
                assert_eq!(e.end_effector, !parents.contains(&Some(j)), "{name}: joint {j} end_effector flag");
            }
        }
    }
}

/// The brute force itself on a hand-checked example, so a shared mistake cannot hide.
#[test]
fn brute_force_reference_on_a_hand_checked_tree() {
    //      0
    //     / \
    //    1   4
    //   / \    \
    //  2   3    5
    let parents = [None, Some(0), Some(1), Some(1), Some(0), Some(4)];
    let r = reference_relations(&parents);
    assert_eq!(
        r,
        vec![vec![0, 2, 4, 4, 2, 4], vec![1, 0, 2, 2, 3, 4], vec![4, 1, 5, 3, 4, 4], vec![4, 1, 3, 5, 4, 4], vec![1, 3, 4, 4, 0, 2], vec![4, 4, 4, 4, 1, 5],]
    );
    let d = reference_distances(&parents, 8);
    assert_eq!(
        d,
        vec![vec![0, 1, 2, 2, 1, 2], vec![1, 0, 1, 1, 2, 3], vec![2, 1, 0, 2, 3, 4], vec![2, 1, 2, 0, 3, 4], vec![1, 2, 3, 3, 0, 1], vec![2, 3, 4, 4, 1, 0],]
    );
    assert_eq!(reference_distances(&parents, 2)[2][5], 2);
    let skeleton = skeleton_from_parents(&parents);
    assert_eq!(relations(&skeleton), r);
    assert_eq!(distances(&skeleton, 8), d);
    assert_eq!(kinematic_chains(&skeleton), vec![vec![0, 1, 3], vec![1, 2], vec![0, 4, 5]]);
}
