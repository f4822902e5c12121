//! Topology descriptors, exactly as AnyTop defines them (docs/reference/anytop.md §2.4, paper
//! §3.1), plus kinematic chains and end effectors.
//!
//! * Relations R (J x J), first matching rule wins: 0 self, 2 child (j's parent is i),
//!   1 parent (i's parent is j), 3 sibling (same parent), 4 no relation; then the diagonal of
//!   every end effector (a joint without child joints) becomes 5.
//! * Distances D: tree hop distance, capped at d_max (AnyTop uses 5).
//! * Chains: walk from the root; at a branching joint the chain continues into the child with
//!   the highest index (AnyTop's default "main child" policy) and every other child starts a
//!   new chain that begins with the branching joint, so chains share their branch point.

use super::Skeleton;

pub const RELATION_SELF: u8 = 0;
pub const RELATION_PARENT: u8 = 1;
pub const RELATION_CHILD: u8 = 2;
pub const RELATION_SIBLING: u8 = 3;
pub const RELATION_NONE: u8 = 4;
pub const RELATION_END_EFFECTOR: u8 = 5;

/// AnyTop's d_max.
pub const DEFAULT_DMAX: usize = 5;

/// Relations matrix R, row-major J x J.
pub fn relations(skeleton: &Skeleton) -> Vec<Vec<u8>> {
    let parents = skeleton.parents();
    let children = skeleton.children();
    let n = parents.len();
    let mut r = vec![vec![RELATION_NONE; n]; n];
    for i in 0..n {
        for j in 0..n {
            r[i][j] = if i == j {
                if children[i].is_empty() {
                    RELATION_END_EFFECTOR
                } else {
                    RELATION_SELF
                }
            } else if parents[j] == Some(i) {
                RELATION_CHILD
            } else if parents[i] == Some(j) {
                RELATION_PARENT
            } else if parents[i].is_some() && parents[i] == parents[j] {
                RELATION_SIBLING
            } else {
                RELATION_NONE
            };
        }
    }
    r
}

/// Graph (hop) distances D, capped at `dmax`, row-major J x J. One breadth-first search per
/// joint over the tree: O(J^2), a few microseconds for AnyTop's largest (143-joint) skeleton.
pub fn distances(skeleton: &Skeleton, dmax: usize) -> Vec<Vec<u8>> {
    let n = skeleton.len();
    let parents = skeleton.parents();
    let children = skeleton.children();
    let cap = dmax.min(u8::MAX as usize) as u8;
    let mut d = vec![vec![cap; n]; n];
    let mut queue = Vec::with_capacity(n);
    let mut seen = vec![usize::MAX; n];
    for s in 0..n {
        queue.clear();
        queue.push((s, 0usize));
        seen[s] = s;
        let mut head = 0;
        while head < queue.len() {
            let (u, du) = queue[head];
            head += 1;
            d[s][u] = du.min(cap as usize) as u8;
            if du >= cap as usize {
                continue; // everything further is capped anyway
            }
            for v in children[u].iter().copied().chain(parents[u]) {
                if seen[v] != s {
                    seen[v] = s;
                    queue.push((v, du + 1));
                }
            }
        }
    }
    d
}

/// Joints without child joints.
pub fn end_effectors(skeleton: &Skeleton) -> Vec<usize> {
    skeleton.children().iter().enumerate().filter(|(_, c)| c.is_empty()).map(|(j, _)| j).collect()
}

/// Kinematic chains (see the module doc). Every joint appears in exactly one chain as a
/// non-first element, except the root, which starts the first chain.
pub fn kinematic_chains(skeleton: &Skeleton) -> Vec<Vec<usize>> {
    let children = skeleton.children();
    let mut chains = Vec::new();
    if skeleton.is_empty() {
        return chains;
    }
    // Each pending start is (chain so far): the root alone, or [branch point, first child].
    let mut pending: Vec<Vec<usize>> = vec![vec![0]];
    while let Some(mut chain) = pending.pop() {
        let mut at = *chain.last().unwrap_or(&0);
        loop {
            let kids = &children[at];
            let Some(&main) = kids.iter().max() else { break };
            for &k in kids.iter().rev() {
                if k != main {
                    pending.push(vec![at, k]);
                }
            }
            chain.push(main);
            at = main;
        }
        chains.push(chain);
    }
    // Deterministic, readable order: by the index of the first joint after the branch point.
    chains.sort_by_key(|c| (c.get(1).copied().unwrap_or(0), c[0]));
    chains
}
