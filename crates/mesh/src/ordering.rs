//! A fill-reducing node ordering by geometric nested dissection: split the nodes at the median
//! of each axis they extend along, keep the split with the fewest separator nodes (the nodes of
//! one half that touch the other), order the two halves recursively and the separator last. On meshes of planar or
//! solid bodies this gives the O(n log n) fill of nested dissection (George, 1973), less than
//! minimum degree on 2D grids.

/// Parts smaller than this are ordered as they come (the factorisation's own supernodes and
/// their dense kernels handle small blocks best).
const LEAF: usize = 64;

/// The nested-dissection order of the nodes (`order[new] = old`), from node coordinates and the
/// node adjacency in compressed form (as [`crate::Mesh::node_graph`] returns it).
pub fn nested_dissection(points: &[[f64; 3]], graph: &(Vec<usize>, Vec<usize>)) -> Vec<usize> {
    let n = points.len();
    let mut order = Vec::with_capacity(n);
    let mut side = vec![0u8; n]; // scratch: 1 = left, 2 = right of the current split
    let mut stack: Vec<(Vec<usize>, bool)> = vec![((0..n).collect(), false)];
    let mut out_stack: Vec<Vec<usize>> = vec![];
    while let Some((part, done)) = stack.pop() {
        if done || part.len() <= LEAF {
            out_stack.push(part);
            continue;
        }
        let (left, right, sep) = split(points, graph, &part, &mut side);
        if left.is_empty() || right.is_empty() {
            out_stack.push(part);
            continue;
        }
        // LIFO: the left part is processed first, then the right, then the separator
        stack.push((sep, true));
        stack.push((right, false));
        stack.push((left, false));
    }
    // leaves come out as left subtree, right subtree, separator, recursively
    for leaf in out_stack {
        order.extend(leaf);
    }
    debug_assert_eq!(order.len(), n);
    order
}

fn split(
    points: &[[f64; 3]],
    graph: &(Vec<usize>, Vec<usize>),
    part: &[usize],
    side: &mut [u8],
) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &v in part {
        for k in 0..3 {
            lo[k] = lo[k].min(points[v][k]);
            hi[k] = hi[k].max(points[v][k]);
        }
    }
    // the median split along each axis the part extends in, the smallest separator kept: on
    // a graded mesh the longest axis in space may cut across the most nodes
    let mut best: Option<(Vec<usize>, Vec<usize>, Vec<usize>)> = None;
    for axis in (0..3).filter(|&k| hi[k] > lo[k]) {
        let cut = split_along(points, graph, part, side, axis);
        if best.as_ref().is_none_or(|b| cut.2.len() < b.2.len()) {
            best = Some(cut);
        }
    }
    best.unwrap_or_else(|| (part.to_vec(), vec![], vec![]))
}

/// The median split of `part` along `axis`: (left, right, separator), the separator the
/// right-half nodes with a left-half neighbour, each sorted.
fn split_along(
    points: &[[f64; 3]],
    graph: &(Vec<usize>, Vec<usize>),
    part: &[usize],
    side: &mut [u8],
    axis: usize,
) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let (off, nbr) = graph;
    let mut sorted: Vec<usize> = part.to_vec();
    let mid = sorted.len() / 2;
    sorted.select_nth_unstable_by(mid, |&a, &b| {
        points[a][axis].total_cmp(&points[b][axis]).then(a.cmp(&b))
    });
    let (left_half, right_half) = sorted.split_at(mid);
    for &v in left_half {
        side[v] = 1;
    }
    for &v in right_half {
        side[v] = 2;
    }
    let mut left = left_half.to_vec();
    let mut right = Vec::with_capacity(right_half.len());
    let mut sep = vec![];
    for &v in right_half {
        if nbr[off[v]..off[v + 1]].iter().any(|&w| side[w] == 1) {
            sep.push(v);
        } else {
            right.push(v);
        }
    }
    for &v in part {
        side[v] = 0;
    }
    left.sort_unstable();
    right.sort_unstable();
    sep.sort_unstable();
    (left, right, sep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_split_cuts_across_the_fewest_nodes_not_the_longest_side() {
        // 10 long in x with 5 node columns, 1 tall with 41 node rows (a graded mesh's
        // stretched cells): a cut across x would take a column of 41 nodes, across y a row of 5
        let m = crate::rectangle_tri([0.0, 0.0], [10.0, 1.0], 4, 40);
        let g = m.node_graph();
        let (left, right, sep) = split(
            &m.points,
            &g,
            &(0..m.n_nodes()).collect::<Vec<_>>(),
            &mut vec![0; m.n_nodes()],
        );
        // (the median falls inside a row: a row and a node of the next)
        assert!(sep.len() <= 6, "separator {sep:?}");
        assert_eq!(left.len() + right.len() + sep.len(), m.n_nodes());
        let ys: Vec<f64> = sep.iter().map(|&v| m.points[v][1]).collect();
        assert!(
            ys.iter().all(|&y| (y - ys[0]).abs() <= 1.0 / 40.0 + 1e-12),
            "across y: {ys:?}"
        );
    }

    #[test]
    fn is_a_permutation_and_separates() {
        let m = crate::rectangle_tri([0.0, 0.0], [2.0, 1.0], 40, 20);
        let g = m.node_graph();
        let order = nested_dissection(&m.points, &g);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..m.n_nodes()).collect::<Vec<_>>());
        // the top separator (ordered last) lies along x = 1 (the median of x), one cell wide,
        // and removing it leaves no edge between x < 1 and x > 1
        let (_, sep) = order.split_at(order.len() - 21);
        assert!(sep.iter().all(|&v| (m.points[v][0] - 1.0).abs() <= 0.05 + 1e-12));
        let in_sep = |v: usize| sep.contains(&v);
        let (off, nbr) = &g;
        for v in 0..m.n_nodes() {
            if in_sep(v) || m.points[v][0] >= 1.0 {
                continue;
            }
            for &w in &nbr[off[v]..off[v + 1]] {
                assert!(
                    in_sep(w) || m.points[w][0] <= 1.0 + 1e-12,
                    "edge {v}-{w} crosses the separator"
                );
            }
        }
    }
}
