//! Brute-force references for AnyTop's topology descriptors, written from the definition
//! (docs/reference/anytop.md §2.4) independently of lib/skeleton/topology.rs.

/// Joint j, its parent, its grandparent, ... up to a root.
pub fn ancestors(parents: &[Option<usize>], j: usize) -> Vec<usize> {
    let mut out = vec![j];
    let mut at = j;
    while let Some(p) = parents[at] {
        out.push(p);
        at = p;
        assert!(out.len() <= parents.len(), "cycle in the parent list at joint {j}");
    }
    out
}

pub fn reference_distances(parents: &[Option<usize>], dmax: usize) -> Vec<Vec<u8>> {
    let n = parents.len();
    let anc: Vec<Vec<usize>> = (0..n).map(|j| ancestors(parents, j)).collect();
    let mut d = vec![vec![0u8; n]; n];
    for i in 0..n {
        for j in 0..n {
            // Lowest common ancestor: the first of i's ancestors (i itself first) that is also
            // one of j's; the hops are the steps up from i plus the steps up from j.
            let hops = anc[i].iter().enumerate().find_map(|(up_i, a)| anc[j].iter().position(|b| b == a).map(|up_j| up_i + up_j)).unwrap_or(usize::MAX); // different roots: unreachable
            d[i][j] = hops.min(dmax) as u8;
        }
    }
    d
}

pub fn reference_relations(parents: &[Option<usize>]) -> Vec<Vec<u8>> {
    let n = parents.len();
    let mut has_child = vec![false; n];
    for p in parents.iter().flatten() {
        has_child[*p] = true;
    }
    let mut r = vec![vec![0u8; n]; n];
    for i in 0..n {
        for j in 0..n {
            r[i][j] = if i == j {
                0
            } else if parents[j] == Some(i) {
                2
            } else if parents[i] == Some(j) {
                1
            } else if parents[j] == parents[i] {
                3
            } else {
                4
            };
        }
    }
    for i in 0..n {
        if !has_child[i] {
            r[i][i] = 5;
        }
    }
    r
}
