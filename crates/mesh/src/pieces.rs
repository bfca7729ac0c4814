//! A generated mesh made in pieces, one per rank of a parallel run, so that no rank holds the
//! whole: the structured grid of [`rectangle_tri`](crate::rectangle_tri) or
//! [`box_tet`](crate::box_tet) cut into blocks of cells along its axes ([`Blocks`]), each
//! rank's piece its block's cells plus one layer of ghost cells around it ([`MeshPiece`]).
//!
//! The pieces are the whole mesh's, bit for bit: the same coordinates, the same cells with
//! their nodes in the same order, the same boundary facets, numbered locally with the map to
//! the whole mesh's numbers beside them. A node belongs to the lowest rank among its cells'.
//!
//! Why one layer of ghosts is enough: every cell that holds a node of a rank's own cells lies
//! in the layer of cells around its block, so a rank holds every cell, every boundary facet and
//! every node that its own nodes' rows of a finite-element matrix or load vector sum over.

use crate::generate::{lerp, signed_volume, triangle_normal};
use crate::{CellKind, FacetGroup, Mesh};
use std::collections::BTreeMap;

/// The structured grid of `n` cells per axis cut into `p` blocks per axis, one per rank;
/// rank `b₀ + p₀ (b₁ + p₁ b₂)` holds block `(b₀, b₁, b₂)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Blocks {
    /// Spatial dimension, 2 or 3 (in 2D the third axis has one cell and one block).
    pub dim: usize,
    /// Cells per axis (squares or cubes, before they are split into simplices).
    pub n: [usize; 3],
    /// Blocks per axis.
    pub p: [usize; 3],
}

/// The part of the whole mesh a rank holds: its own cells first (`0..own_cells`), then one
/// layer of ghost cells (the other ranks' cells that share a node with its own), and the nodes
/// of both, numbered locally.
#[derive(Clone, Debug)]
pub struct MeshPiece {
    /// The piece as a mesh: its own and ghost cells, their nodes, and the whole mesh's
    /// boundary facets that lie on its cells, under the whole mesh's group names (a group
    /// the piece does not reach is present and empty); region `body` holds every cell.
    pub mesh: Mesh,
    /// The rank's own cells: the first `own_cells` of `mesh`.
    pub own_cells: usize,
    /// The rank that owns each cell of the piece.
    pub cell_rank: Vec<usize>,
    /// Each cell's number in the whole mesh.
    pub global_cell: Vec<usize>,
    /// Each node's number in the whole mesh.
    pub global_node: Vec<usize>,
    /// The rank that owns each node: the lowest rank among the cells that hold it.
    pub node_rank: Vec<usize>,
    /// Nodes of the whole mesh.
    pub n_global_nodes: usize,
    /// Cells of the whole mesh.
    pub n_global_cells: usize,
}

impl Blocks {
    /// The blocks of a grid of `n` cells per axis (`n[2]` ignored in 2D) among `ranks`: of the
    /// ways to write `ranks` as a product of blocks per axis, none more than the axis' cells,
    /// the one whose cuts cross the fewest cell facets. `None` where there is no such way (more
    /// ranks than cells along the axes can hold).
    pub fn new(dim: usize, n: [usize; 3], ranks: usize) -> Option<Blocks> {
        let n = [n[0].max(1), n[1].max(1), if dim == 2 { 1 } else { n[2].max(1) }];
        let mut best: Option<(usize, [usize; 3])> = None;
        for p0 in (1..=ranks).filter(|p| ranks.is_multiple_of(*p)) {
            for p1 in (1..=ranks / p0).filter(|p| (ranks / p0).is_multiple_of(*p)) {
                let p = [p0, p1, ranks / (p0 * p1)];
                if (0..3).any(|k| p[k] > n[k]) {
                    continue;
                }
                // the facets each cut crosses: the cells across it
                let cut: usize = (0..3)
                    .map(|k| (p[k] - 1) * (0..3).filter(|&l| l != k).map(|l| n[l]).product::<usize>())
                    .sum();
                if best.is_none_or(|(c, _)| cut < c) {
                    best = Some((cut, p));
                }
            }
        }
        best.map(|(_, p)| Blocks { dim, n, p })
    }

    /// Ranks in all.
    pub fn ranks(&self) -> usize {
        self.p.iter().product()
    }

    /// The block of `rank`.
    pub fn block(&self, rank: usize) -> [usize; 3] {
        [
            rank % self.p[0],
            (rank / self.p[0]) % self.p[1],
            rank / (self.p[0] * self.p[1]),
        ]
    }

    /// The rank of block `b`.
    pub fn rank(&self, b: [usize; 3]) -> usize {
        b[0] + self.p[0] * (b[1] + self.p[1] * b[2])
    }

    /// The cells of block `b` along `axis`: an even split (the first blocks one more).
    pub fn cells(&self, axis: usize, b: usize) -> std::ops::Range<usize> {
        let (q, r) = (self.n[axis] / self.p[axis], self.n[axis] % self.p[axis]);
        let start = b * q + b.min(r);
        start..start + q + usize::from(b < r)
    }

    /// The block along `axis` that holds cell `c`.
    pub fn block_of_cell(&self, axis: usize, c: usize) -> usize {
        let (q, r) = (self.n[axis] / self.p[axis], self.n[axis] % self.p[axis]);
        if c < r * (q + 1) {
            c / (q + 1)
        } else {
            r + (c - r * (q + 1)) / q
        }
    }

    /// The rank of the grid's cell (square or cube) at `c`.
    pub fn rank_of_cell(&self, c: [usize; 3]) -> usize {
        self.rank([0, 1, 2].map(|k| self.block_of_cell(k, c[k])))
    }

    /// The rank that owns the grid's node at `v`: the lowest among its cells' (the rank is
    /// increasing in each block index, so the lowest cell index along every axis).
    pub fn rank_of_node(&self, v: [usize; 3]) -> usize {
        self.rank_of_cell([0, 1, 2].map(|k| v[k].saturating_sub(1).min(self.n[k] - 1)))
    }

    /// The cells of `rank`'s piece along each axis: its block's, widened by one on each side
    /// where the grid goes on.
    fn with_ghosts(&self, rank: usize) -> ([std::ops::Range<usize>; 3], [std::ops::Range<usize>; 3]) {
        let b = self.block(rank);
        let own = [0, 1, 2].map(|k| self.cells(k, b[k]));
        let ghost = [0, 1, 2].map(|k| own[k].start.saturating_sub(1)..(own[k].end + 1).min(self.n[k]));
        (own, ghost)
    }

    /// `rank`'s piece of [`box_tet`](crate::box_tet)`(lo, hi, n)`.
    pub fn box_piece(&self, lo: [f64; 3], hi: [f64; 3], rank: usize) -> MeshPiece {
        let n = self.n;
        let (own, g) = self.with_ghosts(rank);
        let size = [0, 1, 2].map(|k| g[k].len() + 1);
        let local = |v: [usize; 3]| ((v[2] - g[2].start) * size[1] + v[1] - g[1].start) * size[0] + v[0] - g[0].start;
        let whole = |v: [usize; 3]| (v[2] * (n[1] + 1) + v[1]) * (n[0] + 1) + v[0];
        let mut piece = Nodes::new(self, size.iter().product());
        for k in g[2].start..=g[2].end {
            for j in g[1].start..=g[1].end {
                for i in g[0].start..=g[0].end {
                    let p = [
                        lerp(lo[0], hi[0], i, n[0]),
                        lerp(lo[1], hi[1], j, n[1]),
                        lerp(lo[2], hi[2], k, n[2]),
                    ];
                    piece.push(p, whole([i, j, k]), self.rank_of_node([i, j, k]));
                }
            }
        }
        const ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        let mut cells = Cells::default();
        // own cubes first, then the ghosts'
        for pass_own in [true, false] {
            for k in g[2].clone() {
                for j in g[1].clone() {
                    for i in g[0].clone() {
                        let inside = own[0].contains(&i) && own[1].contains(&j) && own[2].contains(&k);
                        if inside != pass_own {
                            continue;
                        }
                        let cube = (k * n[1] + j) * n[0] + i;
                        for (t, order) in ORDERS.iter().enumerate() {
                            let mut c = [i, j, k];
                            let mut tet = [local(c), 0, 0, local([i + 1, j + 1, k + 1])];
                            for (slot, &axis) in order[..2].iter().enumerate() {
                                c[axis] += 1;
                                tet[slot + 1] = local(c);
                            }
                            if signed_volume(&piece.points, &tet) < 0.0 {
                                tet.swap(2, 3);
                            }
                            cells.push(&tet, 6 * cube + t, self.rank_of_cell([i, j, k]));
                        }
                    }
                }
            }
        }
        let mut boundaries = BTreeMap::new();
        let names = [("left", "right"), ("front", "back"), ("bottom", "top")];
        for axis in 0..3 {
            let (a, b) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            for (side, name) in [(0usize, names[axis].0), (n[axis], names[axis].1)] {
                let outward = if side == 0 { -1.0 } else { 1.0 };
                let reached = if side == 0 {
                    g[axis].start == 0
                } else {
                    g[axis].end == n[axis]
                };
                let mut facets = vec![];
                for jb in g[b].clone().filter(|_| reached) {
                    for ia in g[a].clone() {
                        let node = |da: usize, db: usize| {
                            let mut c = [0usize; 3];
                            c[axis] = side;
                            c[a] = ia + da;
                            c[b] = jb + db;
                            local(c)
                        };
                        let (n00, n10, n11, n01) = (node(0, 0), node(1, 0), node(1, 1), node(0, 1));
                        for mut tri in [[n00, n10, n11], [n00, n11, n01]] {
                            if triangle_normal(&piece.points, &tri)[axis] * outward < 0.0 {
                                tri.swap(1, 2);
                            }
                            facets.extend_from_slice(&tri);
                        }
                    }
                }
                boundaries.insert(
                    name.to_string(),
                    FacetGroup {
                        nodes_per_facet: 3,
                        facets,
                    },
                );
            }
        }
        let own_cells = own.iter().map(|r| r.len()).product::<usize>() * 6;
        let n_global_cells = 6 * n.iter().product::<usize>();
        piece.finish(3, CellKind::Tet4, cells, boundaries, own_cells, n_global_cells)
    }

    /// `rank`'s piece of [`rectangle_tri`](crate::rectangle_tri)`(lo, hi, n[0], n[1])`.
    pub fn rectangle_piece(&self, lo: [f64; 2], hi: [f64; 2], rank: usize) -> MeshPiece {
        let n = self.n;
        let (own, g) = self.with_ghosts(rank);
        let width = g[0].len() + 1;
        let local = |i: usize, j: usize| (j - g[1].start) * width + i - g[0].start;
        let mut piece = Nodes::new(self, width * (g[1].len() + 1));
        for j in g[1].start..=g[1].end {
            for i in g[0].start..=g[0].end {
                let p = [lerp(lo[0], hi[0], i, n[0]), lerp(lo[1], hi[1], j, n[1]), 0.0];
                piece.push(p, j * (n[0] + 1) + i, self.rank_of_node([i, j, 0]));
            }
        }
        let mut cells = Cells::default();
        for pass_own in [true, false] {
            for j in g[1].clone() {
                for i in g[0].clone() {
                    if (own[0].contains(&i) && own[1].contains(&j)) != pass_own {
                        continue;
                    }
                    let (n00, n10, n11, n01) = (local(i, j), local(i + 1, j), local(i + 1, j + 1), local(i, j + 1));
                    let (square, rank) = (j * n[0] + i, self.rank_of_cell([i, j, 0]));
                    cells.push(&[n00, n10, n11], 2 * square, rank);
                    cells.push(&[n00, n11, n01], 2 * square + 1, rank);
                }
            }
        }
        let seg = |pairs: Vec<(usize, usize)>| FacetGroup {
            nodes_per_facet: 2,
            facets: pairs.into_iter().flat_map(|(a, b)| [a, b]).collect(),
        };
        let on = |reached: bool, r: std::ops::Range<usize>| r.filter(move |_| reached);
        let (x, y) = (g[0].clone(), g[1].clone());
        let mut boundaries = BTreeMap::new();
        let bottom = on(y.start == 0, x.clone()).map(|i| (local(i, 0), local(i + 1, 0)));
        boundaries.insert("bottom".into(), seg(bottom.collect()));
        let right = on(x.end == n[0], y.clone()).map(|j| (local(n[0], j), local(n[0], j + 1)));
        boundaries.insert("right".into(), seg(right.collect()));
        let top = on(y.end == n[1], x.clone())
            .rev()
            .map(|i| (local(i + 1, n[1]), local(i, n[1])));
        boundaries.insert("top".into(), seg(top.collect()));
        let left = on(x.start == 0, y).rev().map(|j| (local(0, j + 1), local(0, j)));
        boundaries.insert("left".into(), seg(left.collect()));
        let own_cells = 2 * own[0].len() * own[1].len();
        piece.finish(2, CellKind::Tri3, cells, boundaries, own_cells, 2 * n[0] * n[1])
    }
}

/// A piece's nodes as they are made.
struct Nodes {
    points: Vec<[f64; 3]>,
    global: Vec<usize>,
    rank: Vec<usize>,
    n_global: usize,
}

impl Nodes {
    fn new(blocks: &Blocks, capacity: usize) -> Nodes {
        Nodes {
            points: Vec::with_capacity(capacity),
            global: Vec::with_capacity(capacity),
            rank: Vec::with_capacity(capacity),
            n_global: blocks.n.iter().take(blocks.dim).map(|&c| c + 1).product(),
        }
    }

    fn push(&mut self, p: [f64; 3], global: usize, rank: usize) {
        self.points.push(p);
        self.global.push(global);
        self.rank.push(rank);
    }

    fn finish(
        self,
        dim: usize,
        kind: CellKind,
        cells: Cells,
        boundaries: BTreeMap<String, FacetGroup>,
        own_cells: usize,
        n_global_cells: usize,
    ) -> MeshPiece {
        let n_cells = cells.global.len();
        let mut regions = BTreeMap::new();
        regions.insert("body".into(), (0..n_cells).collect());
        MeshPiece {
            mesh: Mesh {
                dim,
                kind,
                points: self.points,
                cells: cells.nodes,
                boundaries,
                regions,
                reoriented_cells: 0,
                other_groups: Default::default(),
            },
            own_cells,
            cell_rank: cells.rank,
            global_cell: cells.global,
            global_node: self.global,
            node_rank: self.rank,
            n_global_nodes: self.n_global,
            n_global_cells,
        }
    }
}

/// A piece's cells as they are made.
#[derive(Default)]
struct Cells {
    nodes: Vec<usize>,
    global: Vec<usize>,
    rank: Vec<usize>,
}

impl Cells {
    fn push(&mut self, nodes: &[usize], global: usize, rank: usize) {
        self.nodes.extend_from_slice(nodes);
        self.global.push(global);
        self.rank.push(rank);
    }
}

impl MeshPiece {
    /// The piece with its nodes numbered along a space-filling curve (the Z order of their
    /// coordinates on a grid of 2^21 steps per axis): neighbours in space get near numbers,
    /// which a mesh generator's numbering (the order a Delaunay kernel inserted the points in)
    /// does not give. A matrix or vector numbered by the nodes then reads memory nearly in
    /// order. The nodes' numbers in the whole mesh and their owners go with them; the cells,
    /// facets and regions are unchanged but for the node numbers they hold.
    pub fn in_space_order(self) -> MeshPiece {
        let order = space_order(&self.mesh.points);
        let mut new = vec![0; order.len()];
        for (i, &v) in order.iter().enumerate() {
            new[v] = i;
        }
        let MeshPiece {
            mut mesh,
            own_cells,
            cell_rank,
            global_cell,
            global_node,
            node_rank,
            n_global_nodes,
            n_global_cells,
        } = self;
        mesh.points = order.iter().map(|&v| mesh.points[v]).collect();
        for v in &mut mesh.cells {
            *v = new[*v];
        }
        for group in mesh.boundaries.values_mut() {
            for v in &mut group.facets {
                *v = new[*v];
            }
        }
        MeshPiece {
            mesh,
            own_cells,
            cell_rank,
            global_cell,
            global_node: order.iter().map(|&v| global_node[v]).collect(),
            node_rank: order.iter().map(|&v| node_rank[v]).collect(),
            n_global_nodes,
            n_global_cells,
        }
    }

    /// The one piece of a run on one rank: the whole of `mesh`, every cell and node its own
    /// and numbered as in `mesh`.
    pub fn whole(mesh: Mesh) -> MeshPiece {
        let (nodes, cells) = (mesh.n_nodes(), mesh.n_cells());
        MeshPiece {
            mesh,
            own_cells: cells,
            cell_rank: vec![0; cells],
            global_cell: (0..cells).collect(),
            global_node: (0..nodes).collect(),
            node_rank: vec![0; nodes],
            n_global_nodes: nodes,
            n_global_cells: cells,
        }
    }
}

/// The points in Z order: sorted by the interleaved bits of their coordinates, each scaled
/// to 21 bits over the points' bounding box (ties by their index).
fn space_order(points: &[[f64; 3]]) -> Vec<usize> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in points {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    let steps = f64::from((1u32 << 21) - 1);
    let key = |x: &[f64; 3]| -> u64 {
        let mut key = 0u64;
        for k in 0..3 {
            let span = hi[k] - lo[k];
            let q = if span > 0.0 {
                ((x[k] - lo[k]) / span * steps) as u64
            } else {
                0
            };
            for bit in 0..21 {
                key |= ((q >> bit) & 1) << (3 * bit + k);
            }
        }
        key
    };
    let mut order: Vec<(u64, usize)> = points.iter().enumerate().map(|(v, x)| (key(x), v)).collect();
    order.sort_unstable();
    order.into_iter().map(|(_, v)| v).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{box_tet, rectangle_tri};
    use proptest::prelude::*;

    /// Every piece agrees with the whole mesh: its cells are the whole mesh's (same nodes, in
    /// the same order, at the same coordinates), its own cells over the ranks are each cell
    /// once, its facets are the whole mesh's facets on its cells, the owners are the lowest
    /// ranks of the cells, and the ghosts complete every own node's cells.
    fn agrees(whole: &Mesh, blocks: &Blocks, piece_of: impl Fn(usize) -> MeshPiece) {
        let ranks = blocks.ranks();
        let mut owner_of_cell = vec![usize::MAX; whole.n_cells()];
        let mut lowest = vec![usize::MAX; whole.n_nodes()];
        let pieces: Vec<MeshPiece> = (0..ranks).map(&piece_of).collect();
        for (r, p) in pieces.iter().enumerate() {
            assert_eq!(p.n_global_nodes, whole.n_nodes());
            assert_eq!(p.n_global_cells, whole.n_cells());
            for c in 0..p.mesh.n_cells() {
                let gc = p.global_cell[c];
                let mapped: Vec<usize> = p.mesh.cell(c).iter().map(|&v| p.global_node[v]).collect();
                assert_eq!(mapped, whole.cell(gc), "rank {r} cell {c}");
                assert_eq!(
                    c < p.own_cells,
                    p.cell_rank[c] == r,
                    "rank {r} cell {c}: own cells first"
                );
                if c < p.own_cells {
                    assert_eq!(owner_of_cell[gc], usize::MAX, "cell {gc} owned twice");
                    owner_of_cell[gc] = r;
                }
            }
            for (v, &gv) in p.global_node.iter().enumerate() {
                assert_eq!(p.mesh.points[v], whole.points[gv]);
            }
        }
        assert!(owner_of_cell.iter().all(|&r| r < ranks), "every cell owned");
        for (c, cell) in whole.iter_cells().enumerate() {
            for &v in cell {
                lowest[v] = lowest[v].min(owner_of_cell[c]);
            }
        }
        let (off, node_cells) = whole.node_cells();
        for (r, p) in pieces.iter().enumerate() {
            let held: std::collections::HashSet<usize> = p.global_cell.iter().copied().collect();
            for (v, &gv) in p.global_node.iter().enumerate() {
                assert_eq!(p.node_rank[v], lowest[gv], "the owner of node {gv}");
                if p.node_rank[v] == r {
                    for c in &node_cells[off[gv]..off[gv + 1]] {
                        assert!(held.contains(c), "rank {r} owns node {gv} but not its cell {c}");
                    }
                }
            }
            for (name, group) in &whole.boundaries {
                let mine = &p.mesh.boundaries[name];
                let set = |f: &[usize], map: &dyn Fn(usize) -> usize| {
                    f.chunks(group.nodes_per_facet)
                        .map(|x| x.iter().map(|&v| map(v)).collect::<Vec<_>>())
                        .collect::<Vec<_>>()
                };
                let local = set(&mine.facets, &|v| p.global_node[v]);
                let nodes: std::collections::HashSet<usize> = p.global_node.iter().copied().collect();
                // the whole group's facets whose nodes all lie in one of the piece's cells
                let expected: Vec<Vec<usize>> = set(&group.facets, &|v| v)
                    .into_iter()
                    .filter(|f| f.iter().all(|v| nodes.contains(v)))
                    .filter(|f| {
                        node_cells[off[f[0]]..off[f[0] + 1]]
                            .iter()
                            .any(|c| held.contains(c) && f.iter().all(|v| whole.cell(*c).contains(v)))
                    })
                    .collect();
                assert_eq!(local, expected, "rank {r}, group {name}");
            }
            p.mesh.check().expect("a piece is a valid mesh");
        }
    }

    #[test]
    fn the_blocks_cut_the_fewest_facets() {
        // a 96 x 48 x 48 box on 2 ranks: cut across the long axis
        assert_eq!(Blocks::new(3, [96, 48, 48], 2).unwrap().p, [2, 1, 1]);
        assert_eq!(Blocks::new(3, [8, 8, 8], 8).unwrap().p, [2, 2, 2]);
        assert_eq!(Blocks::new(2, [4, 64, 0], 4).unwrap().p, [1, 4, 1]);
        assert!(Blocks::new(2, [2, 2, 0], 5).is_none(), "5 ranks on 2 x 2 squares");
        let b = Blocks::new(3, [7, 5, 3], 6).unwrap();
        for r in 0..6 {
            assert_eq!(b.rank(b.block(r)), r);
        }
        for axis in 0..3 {
            let cells: Vec<usize> = (0..b.p[axis]).flat_map(|k| b.cells(axis, k)).collect();
            assert_eq!(cells, (0..b.n[axis]).collect::<Vec<_>>());
            for c in 0..b.n[axis] {
                assert!(b.cells(axis, b.block_of_cell(axis, c)).contains(&c));
            }
        }
    }

    #[test]
    fn a_piece_in_space_order_is_the_same_piece() {
        let blocks = Blocks::new(3, [5, 4, 3], 2).expect("blocks");
        let before = blocks.box_piece([0.0; 3], [1.0; 3], 1);
        let after = before.clone().in_space_order();
        let m = &after.mesh;
        // the same cells, facets and places, node by node in the whole mesh's numbers
        let globals = |p: &MeshPiece, nodes: &[usize]| nodes.iter().map(|&v| p.global_node[v]).collect::<Vec<_>>();
        for c in 0..m.n_cells() {
            assert_eq!(globals(&after, m.cell(c)), globals(&before, before.mesh.cell(c)));
        }
        for (name, g) in &m.boundaries {
            assert_eq!(
                globals(&after, &g.facets),
                globals(&before, &before.mesh.boundaries[name].facets)
            );
        }
        let place: BTreeMap<usize, ([f64; 3], usize)> = (0..before.mesh.n_nodes())
            .map(|v| (before.global_node[v], (before.mesh.points[v], before.node_rank[v])))
            .collect();
        for v in 0..m.n_nodes() {
            assert_eq!(place[&after.global_node[v]], (m.points[v], after.node_rank[v]));
        }
        // and neighbours in space are near in number: consecutive nodes a few cells apart
        let far = (1..m.n_nodes())
            .filter(|&v| {
                (0..3)
                    .map(|k| (m.points[v][k] - m.points[v - 1][k]).abs())
                    .fold(0.0, f64::max)
                    > 0.5
            })
            .count();
        assert!(
            far * 10 < m.n_nodes(),
            "{far} of {} jumps over half the box",
            m.n_nodes()
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        #[test]
        fn box_pieces_are_the_whole_box(nx in 1usize..6, ny in 1usize..5, nz in 1usize..5, ranks in 1usize..9) {
            let (lo, hi) = ([0.0, -1.0, 0.5], [2.0, 1.0, 1.25]);
            let whole = box_tet(lo, hi, nx, ny, nz);
            if let Some(blocks) = Blocks::new(3, [nx, ny, nz], ranks) {
                agrees(&whole, &blocks, |r| blocks.box_piece(lo, hi, r));
            }
        }

        #[test]
        fn rectangle_pieces_are_the_whole_rectangle(nx in 1usize..9, ny in 1usize..7, ranks in 1usize..9) {
            let (lo, hi) = ([0.0, -1.0], [2.0, 0.5]);
            let whole = rectangle_tri(lo, hi, nx, ny);
            if let Some(blocks) = Blocks::new(2, [nx, ny, 0], ranks) {
                agrees(&whole, &blocks, |r| blocks.rectangle_piece(lo, hi, r));
            }
        }
    }
}
