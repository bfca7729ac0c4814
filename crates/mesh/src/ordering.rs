//! A fill-reducing node ordering by geometric nested dissection: split the nodes at the median
//! of each axis they extend along, keep the split with the fewest separator nodes (the nodes of
//! one half that touch the other), order the two halves recursively and the separator last. On meshes of planar or
//! solid bodies this gives the O(n log n) fill of nested dissection (George, 1973), less than
//! minimum degree on 2D grids. The two halves of a large part are ordered at the same time on
//! rayon's pool; the order does not depend on the number of threads.
//!
//! A quadratic mesh ([`Mesh::nested_dissection`]) is dissected on its corners (the graph of its
//! linear cells), each edge node then ordered with the first-ordered corner of its edge: a
//! separator is then a surface of cell faces with their edge nodes, one layer thick. Dissected
//! as its own nodes, a second-order mesh's separators are two layers thick (a cell couples
//! nodes two spacings apart), which tripled the factorisation's operations in 2D.

use crate::{CellKind, Mesh};
use rayon::join;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Parts smaller than this are ordered as they come (the factorisation's own supernodes and
/// their dense kernels handle small blocks best).
const LEAF: usize = 64;

/// Parts with at least this many nodes have their two halves ordered on two threads (below it,
/// a task costs more than it saves).
const PARALLEL: usize = 2048;

/// Marks of the nodes for the splits under way, one array per axis (a part's splits along its
/// axes run at the same time): each median split marks its left half with a tag of its own,
/// so that splits of disjoint parts on different threads never read each other's marks as
/// theirs (a node outside the part carries another split's tag, or none).
struct Marks {
    side: [Vec<AtomicU32>; 3],
    next: AtomicU32,
}

impl Marks {
    fn new(n: usize) -> Marks {
        Marks {
            side: std::array::from_fn(|_| (0..n).map(|_| AtomicU32::new(0)).collect()),
            next: AtomicU32::new(1),
        }
    }

    /// A tag no split has used.
    fn fresh(&self) -> u32 {
        self.next.fetch_add(1, Relaxed)
    }
}

/// The nested-dissection order of the nodes (`order[new] = old`), from node coordinates and the
/// node adjacency in compressed form (as [`crate::Mesh::node_graph`] returns it).
pub fn nested_dissection(points: &[[f64; 3]], graph: &(Vec<usize>, Vec<usize>)) -> Vec<usize> {
    let n = points.len();
    let marks = Marks::new(n);
    let order = dissect(points, graph, (0..n).collect(), &marks);
    debug_assert_eq!(order.len(), n);
    order
}

impl Mesh {
    /// The nested-dissection order of the mesh's nodes (`order[new] = old`): of its node graph
    /// in a linear mesh ([`nested_dissection`]); in a quadratic mesh, of its corners' graph,
    /// each edge node just before the first-ordered corner of its edge (so it lies in that
    /// corner's part or separator, and no edge node widens a separator), the nodes of no cell
    /// first.
    pub fn nested_dissection(&self) -> Vec<usize> {
        let linear_kind = match self.kind {
            CellKind::Tri6 => CellKind::Tri3,
            CellKind::Tet10 => CellKind::Tet4,
            _ => return nested_dissection(&self.points, &self.node_graph()),
        };
        let (n, corners) = (self.n_nodes(), self.kind.n_corners());
        // the corners, numbered in their order of first use
        let mut compact = vec![usize::MAX; n];
        let mut corner_nodes = vec![];
        for cell in self.iter_cells() {
            for &v in &cell[..corners] {
                if compact[v] == usize::MAX {
                    compact[v] = corner_nodes.len();
                    corner_nodes.push(v);
                }
            }
        }
        let linear = Mesh {
            dim: self.dim,
            kind: linear_kind,
            points: corner_nodes.iter().map(|&v| self.points[v]).collect(),
            cells: self
                .iter_cells()
                .flat_map(|c| c[..corners].iter().map(|&v| compact[v]))
                .collect(),
            boundaries: Default::default(),
            regions: Default::default(),
            reoriented_cells: 0,
            other_groups: Default::default(),
        };
        let corner_order = nested_dissection(&linear.points, &linear.node_graph());
        let mut position = vec![0; corner_nodes.len()];
        for (p, &c) in corner_order.iter().enumerate() {
            position[c] = p;
        }
        // each edge node's place: the first of its edge's corners in the corner order
        let mut place = vec![usize::MAX; n];
        for cell in self.iter_cells() {
            for (m, &[a, b]) in self.kind.midside_edges().iter().enumerate() {
                let first = position[compact[cell[a]]].min(position[compact[cell[b]]]);
                let v = cell[corners + m];
                place[v] = place[v].min(first);
            }
        }
        let mut order: Vec<usize> = (0..n)
            .filter(|&v| compact[v] == usize::MAX && place[v] == usize::MAX)
            .collect();
        let mut edge_nodes: Vec<(usize, usize)> = (0..n)
            .filter(|&v| compact[v] == usize::MAX && place[v] != usize::MAX)
            .map(|v| (place[v], v))
            .collect();
        edge_nodes.sort_unstable();
        let mut next = edge_nodes.iter().peekable();
        for (p, &c) in corner_order.iter().enumerate() {
            while let Some(&(_, v)) = next.next_if(|e| e.0 == p) {
                order.push(v);
            }
            order.push(corner_nodes[c]);
        }
        debug_assert_eq!(order.len(), n);
        order
    }
}

/// The order of `part`: its left half's, its right half's, then the separator.
fn dissect(points: &[[f64; 3]], graph: &(Vec<usize>, Vec<usize>), part: Vec<usize>, marks: &Marks) -> Vec<usize> {
    if part.len() <= LEAF {
        return part;
    }
    let (left, right, sep) = split(points, graph, &part, marks);
    if left.is_empty() || right.is_empty() {
        return part;
    }
    let (mut order, right) = if part.len() >= PARALLEL {
        join(
            || dissect(points, graph, left, marks),
            || dissect(points, graph, right, marks),
        )
    } else {
        (
            dissect(points, graph, left, marks),
            dissect(points, graph, right, marks),
        )
    };
    order.extend(right);
    order.extend(sep);
    order
}

fn split(
    points: &[[f64; 3]],
    graph: &(Vec<usize>, Vec<usize>),
    part: &[usize],
    marks: &Marks,
) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &v in part {
        for k in 0..3 {
            lo[k] = lo[k].min(points[v][k]);
            hi[k] = hi[k].max(points[v][k]);
        }
    }
    // the median split along each axis the part extends in, the smallest separator kept (the
    // first axis of those): on a graded mesh the longest axis in space may cut across the most
    // nodes. Large parts try their axes at the same time (each axis has its own marks).
    let axes: Vec<usize> = (0..3).filter(|&k| hi[k] > lo[k]).collect();
    let cut = |&axis: &usize| split_along(points, graph, part, marks, axis);
    let cuts: Vec<_> = if part.len() >= PARALLEL {
        axes.par_iter().map(cut).collect()
    } else {
        axes.iter().map(cut).collect()
    };
    let mut best: Option<(Vec<usize>, Vec<usize>, Vec<usize>)> = None;
    for cut in cuts {
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
    marks: &Marks,
    axis: usize,
) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let (off, nbr) = graph;
    let mut sorted: Vec<usize> = part.to_vec();
    let mid = sorted.len() / 2;
    sorted.select_nth_unstable_by(mid, |&a, &b| {
        points[a][axis].total_cmp(&points[b][axis]).then(a.cmp(&b))
    });
    let (left_half, right_half) = sorted.split_at(mid);
    let (tag, side) = (marks.fresh(), &marks.side[axis]);
    for &v in left_half {
        side[v].store(tag, Relaxed);
    }
    let mut left = left_half.to_vec();
    let mut right = Vec::with_capacity(right_half.len());
    let mut sep = vec![];
    for &v in right_half {
        if nbr[off[v]..off[v + 1]].iter().any(|&w| side[w].load(Relaxed) == tag) {
            sep.push(v);
        } else {
            right.push(v);
        }
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
            &Marks::new(m.n_nodes()),
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

    #[test]
    fn a_quadratic_mesh_is_dissected_by_one_layer_of_nodes() {
        // the P2 form of the mesh above: its top separator the 21 corners on x = 1 and the 20
        // midpoints of the edges between them, one layer, and still a separator
        let m = crate::rectangle_tri([0.0, 0.0], [2.0, 1.0], 40, 20)
            .quadratic()
            .unwrap();
        let g = m.node_graph();
        let order = m.nested_dissection();
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..m.n_nodes()).collect::<Vec<_>>());
        // the separator (ordered last): the corner column at the median and its edges' nodes,
        // within one corner spacing (0.05) of x = 1 (the median falls inside a column)
        let (_, sep) = order.split_at(order.len() - 41);
        let near = |o: &[usize], w: f64| o.iter().all(|&v| (m.points[v][0] - 1.0).abs() <= w + 1e-12);
        assert!(near(sep, 0.05), "{sep:?}");
        let in_sep = |v: usize| sep.contains(&v);
        let (off, nbr) = &g;
        for v in (0..m.n_nodes()).filter(|&v| !in_sep(v) && m.points[v][0] < 1.0) {
            for &w in &nbr[off[v]..off[v + 1]] {
                assert!(
                    in_sep(w) || m.points[w][0] <= 1.0 + 1e-12,
                    "edge {v}-{w} crosses the separator"
                );
            }
        }
        // the nodes' own median split takes two layers
        let all: Vec<usize> = (0..m.n_nodes()).collect();
        let (_, _, own) = split(&m.points, &g, &all, &Marks::new(m.n_nodes()));
        assert!(own.len() >= 2 * 40, "{}", own.len());
    }

    #[test]
    fn the_order_does_not_depend_on_the_threads() {
        // above PARALLEL nodes: halves and axes on different threads, marks shared
        for m in [
            crate::box_tet([0.0; 3], [2.0, 1.4, 1.0], 24, 16, 12),
            crate::rectangle_tri([0.0, 0.0], [3.0, 1.0], 150, 50),
        ] {
            let g = m.node_graph();
            let on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| (nested_dissection(&m.points, &g), m.node_graph()))
            };
            let (one, graph) = on(1);
            assert!(m.n_nodes() > 2 * PARALLEL);
            assert_eq!(graph, g);
            let mut seen = one.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..m.n_nodes()).collect::<Vec<_>>());
            for threads in [2, 3] {
                for _ in 0..3 {
                    assert_eq!(on(threads), (one.clone(), g.clone()), "{threads} threads");
                }
            }
        }
    }
}
