//! Topology checks and the outward normals of boundary facets.
//!
//! A conforming mesh has every facet on one cell (the boundary) or two (the interior); no two
//! cells with the same nodes; facet groups made of facets of the cells, each listed once (a
//! facet listed twice, as two physical groups of one name on one curve give, would count its
//! load or contact twice). A group may hold interior facets (a material interface, an internal
//! electrode): they are counted, and refused only where a boundary is needed (a traction, a
//! contact face, an outward normal). Nodes at the same coordinates (a crack, or a mesh glued
//! from parts that were not merged) are allowed and counted.

use crate::{CellKind, Mesh, MeshError};
use rayon::prelude::*;

/// A facet (or a cell) as its sorted corners (unused slots `usize::MAX`), so equal facets
/// compare equal: the corners are the first nodes of a quadratic facet, its midpoints follow.
pub(crate) type Key = [usize; 4];

/// The key of the entity whose corners are `corners` (at most 4).
pub(crate) fn key(corners: &[usize]) -> Key {
    let mut k = [usize::MAX; 4];
    k[..corners.len()].copy_from_slice(corners);
    k[..corners.len()].sort_unstable();
    k
}

impl CellKind {
    /// The local nodes of each facet of a cell (edges in 2D, faces of a tetrahedron): its
    /// corners, then, in a quadratic cell, the midpoints of its edges in the facet's order
    /// (a face `(a, b, c)`: the midpoints of `a-b`, `b-c`, `c-a`).
    pub fn facets(self) -> &'static [&'static [usize]] {
        match self {
            CellKind::Tri3 => &[&[0, 1], &[1, 2], &[2, 0]],
            CellKind::Quad4 => &[&[0, 1], &[1, 2], &[2, 3], &[3, 0]],
            CellKind::Tet4 => &[&[1, 2, 3], &[0, 2, 3], &[0, 1, 3], &[0, 1, 2]],
            CellKind::Tri6 => &[&[0, 1, 3], &[1, 2, 4], &[2, 0, 5]],
            CellKind::Tet10 => &[
                &[1, 2, 3, 5, 9, 8],
                &[0, 2, 3, 6, 9, 7],
                &[0, 1, 3, 4, 8, 7],
                &[0, 1, 2, 4, 5, 6],
            ],
        }
    }

    /// Corner nodes per facet (the first of a facet's nodes).
    pub fn facet_corners(self) -> usize {
        self.dim()
    }
}

impl Mesh {
    /// Every facet of every cell with its cell, sorted by facet.
    pub(crate) fn cell_facets(&self) -> Vec<(Key, usize)> {
        let local = self.kind.facets();
        let corners = self.kind.facet_corners();
        let mut all = Vec::with_capacity(self.n_cells() * local.len());
        let mut buf = [0usize; 3];
        for (c, cell) in self.iter_cells().enumerate() {
            for f in local {
                for (q, &l) in f.iter().take(corners).enumerate() {
                    buf[q] = cell[l];
                }
                all.push((key(&buf[..corners]), c));
            }
        }
        all.par_sort_unstable();
        all
    }

    /// The parts of the mesh that hold together as solids: cells joined through a shared facet
    /// (an edge in 2D, a face in 3D), not through a lone node or edge (a hinge, about which
    /// two parts turn freely). Returns each cell's part (numbered by their first cells) and
    /// the number of parts.
    pub fn solid_parts(&self) -> (Vec<usize>, usize) {
        let mut cells = UnionFind::new(self.n_cells());
        // a facet's other cell is among the cells of its first node (no sort of every facet)
        let (offsets, node_cells) = self.node_cells();
        let k = self.kind.n_nodes();
        for (c, cell) in self.iter_cells().enumerate() {
            for f in self.kind.facets() {
                let first = cell[f[0]];
                for &c2 in &node_cells[offsets[first]..offsets[first + 1]] {
                    let other = &self.cells[c2 * k..(c2 + 1) * k];
                    if c2 > c && f.iter().all(|&l| other.contains(&cell[l])) {
                        cells.join(c, c2);
                    }
                }
            }
        }
        let mut number = vec![usize::MAX; self.n_cells()];
        let mut n = 0;
        let part = (0..self.n_cells())
            .map(|c| {
                let r = cells.root(c);
                if number[r] == usize::MAX {
                    number[r] = n;
                    n += 1;
                }
                number[r]
            })
            .collect();
        (part, n)
    }

    /// The parts of the mesh joined through any shared node by the cells `keep` selects (the
    /// parts a continuous scalar field, such as the potential, spans): each node's part
    /// (`None` for a node of no such cell), and each part's first cell and number of cells.
    pub fn node_parts(&self, keep: impl Fn(usize) -> bool) -> (Vec<Option<usize>>, Vec<(usize, usize)>) {
        let mut nodes = UnionFind::new(self.n_nodes());
        let mut used = vec![false; self.n_nodes()];
        for (_, cell) in self.iter_cells().enumerate().filter(|(c, _)| keep(*c)) {
            for w in cell.windows(2) {
                nodes.join(w[0], w[1]);
            }
            for &v in cell {
                used[v] = true;
            }
        }
        let mut part_of_root = vec![usize::MAX; self.n_nodes()];
        let mut found: Vec<(usize, usize)> = vec![];
        for (c, cell) in self.iter_cells().enumerate().filter(|(c, _)| keep(*c)) {
            let r = nodes.root(cell[0]);
            if part_of_root[r] == usize::MAX {
                part_of_root[r] = found.len();
                found.push((c, 0));
            }
            found[part_of_root[r]].1 += 1;
        }
        let part = (0..self.n_nodes())
            .map(|v| used[v].then(|| part_of_root[nodes.root(v)]))
            .collect();
        (part, found)
    }

    /// Checks the topology of the cells' `facets` (sorted, [`Mesh::cell_facets`]): every
    /// facet on one or two cells, no two cells with the same nodes, every facet of a group a
    /// facet of the cells, listed once. Returns the number of nodes that share their
    /// coordinates with another node, and of the groups' facets that lie inside the mesh.
    ///
    /// # Errors
    /// [`MeshError::OverlappingCells`], [`MeshError::DuplicateCell`],
    /// [`MeshError::BadBoundaryFacet`].
    pub(crate) fn check_topology(&self, facets: &[(Key, usize)]) -> Result<(usize, usize), MeshError> {
        // runs of one facet: its cells
        let mut i = 0;
        while i < facets.len() {
            let j = i + facets[i..].iter().take_while(|f| f.0 == facets[i].0).count();
            if j - i > 2 {
                return Err(MeshError::OverlappingCells {
                    facet: facets[i].0.iter().copied().filter(|&v| v != usize::MAX).collect(),
                    cells: facets[i..j].iter().map(|f| f.1).collect(),
                });
            }
            i = j;
        }
        let corners = self.kind.n_corners();
        let mut cells: Vec<(Key, usize)> = self
            .iter_cells()
            .enumerate()
            .map(|(c, n)| (key(&n[..corners]), c))
            .collect();
        cells.sort_unstable();
        if let Some(w) = cells.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(MeshError::DuplicateCell {
                first: w[0].1.min(w[1].1),
                second: w[0].1.max(w[1].1),
            });
        }
        self.check_edges()?;
        let mut interior = 0;
        let corners = self.kind.facet_corners();
        for (name, group) in &self.boundaries {
            let mut seen: Vec<(Key, usize)> = group.iter().enumerate().map(|(f, n)| (key(&n[..corners]), f)).collect();
            seen.sort_unstable();
            let bad = |facet: usize, problem: &'static str| MeshError::BadBoundaryFacet {
                group: name.clone(),
                facet,
                nodes: group.facet(facet).to_vec(),
                problem,
            };
            if let Some(w) = seen.windows(2).find(|w| w[0].0 == w[1].0) {
                return Err(bad(w[1].1.max(w[0].1), "is listed twice (two physical groups of one name, or one facet twice): its load or contact would count twice"));
            }
            for (k, f) in &seen {
                let at = facets.partition_point(|x| x.0 < *k);
                let on = facets[at..].iter().take_while(|x| x.0 == *k).count();
                match on {
                    0 => return Err(bad(*f, "is not a facet of any cell")),
                    1 => {}
                    _ => interior += 1,
                }
                if !self.same_edge_nodes(group.facet(*f), facets[at].1) {
                    return Err(bad(*f, "has edge nodes that are not its cell's (a second-order facet's midpoint nodes must be those of the cell that holds it)"));
                }
            }
        }
        Ok((self.coincident_nodes(), interior))
    }

    /// In a quadratic mesh: each edge has one midpoint node, whichever cell names it, and no
    /// midpoint node is a corner (a hanging node); nothing to check in a linear mesh.
    fn check_edges(&self) -> Result<(), MeshError> {
        let corners = self.kind.n_corners();
        let edges = self.kind.midside_edges();
        if edges.is_empty() {
            return Ok(());
        }
        // (edge, midpoint node, cell), sorted by edge
        let mut all: Vec<([usize; 2], usize, usize)> = Vec::with_capacity(self.n_cells() * edges.len());
        let mut corner_of = vec![usize::MAX; self.n_nodes()];
        for (c, cell) in self.iter_cells().enumerate() {
            for &v in &cell[..corners] {
                corner_of[v] = corner_of[v].min(c);
            }
            for (m, &[a, b]) in edges.iter().enumerate() {
                let (a, b) = (cell[a], cell[b]);
                all.push(([a.min(b), a.max(b)], cell[corners + m], c));
            }
        }
        all.par_sort_unstable();
        let bad = |(edge, node, cell): ([usize; 2], usize, usize), problem, other| MeshError::NonConformingEdge {
            edge,
            cell,
            node,
            problem,
            other,
        };
        if let Some(w) = all.windows(2).find(|w| w[0].0 == w[1].0 && w[0].1 != w[1].1) {
            return Err(bad(w[1], "has a second midpoint node", w[0].2));
        }
        if let Some(&e) = all.iter().find(|e| corner_of[e.1] != usize::MAX) {
            return Err(bad(e, "has as its midpoint a corner of another cell", corner_of[e.1]));
        }
        all.par_sort_unstable_by_key(|e| (e.1, e.0));
        if let Some(w) = all.windows(2).find(|w| w[0].1 == w[1].1 && w[0].0 != w[1].0) {
            return Err(bad(
                w[1],
                "has as its midpoint the midpoint node of another edge",
                w[0].2,
            ));
        }
        Ok(())
    }

    /// Whether `facet` (a facet of cell `c` by its corners) has the nodes of that facet of the
    /// cell, its edges' midpoints included (always, in a P1 mesh).
    fn same_edge_nodes(&self, facet: &[usize], c: usize) -> bool {
        if self.kind.order() == 1 {
            return true;
        }
        let cell = self.cell(c);
        let mut given = facet.to_vec();
        given.sort_unstable();
        self.kind.facets().iter().any(|f| {
            let mut nodes: Vec<usize> = f.iter().map(|&l| cell[l]).collect();
            nodes.sort_unstable();
            nodes == given
        })
    }

    /// The facets of group `group` that lie inside the mesh (shared by two cells), by their
    /// index in the group.
    ///
    /// # Errors
    /// [`MeshError::MissingBoundary`].
    pub fn interior_facets(&self, group: &str) -> Result<Vec<usize>, MeshError> {
        let g = self.boundary(group)?;
        let around = self.node_cells();
        Ok(g.iter()
            .enumerate()
            .filter(|(_, f)| self.cells_of_facet(&around, f).nth(1).is_some())
            .map(|(i, _)| i)
            .collect())
    }

    /// The cells that have `facet` (its nodes, in any order) as one of theirs, found among the
    /// cells around its first node (`around`: [`Mesh::node_cells`]); none for a facet whose
    /// nodes are not the mesh's.
    fn cells_of_facet<'a>(
        &'a self,
        (offsets, node_cells): &'a (Vec<usize>, Vec<usize>),
        facet: &'a [usize],
    ) -> impl Iterator<Item = usize> + 'a {
        let corners = self.kind.facet_corners();
        let k = key(&facet[..corners.min(facet.len())]);
        let near = match facet.first() {
            Some(&v) if v + 1 < offsets.len() => &node_cells[offsets[v]..offsets[v + 1]],
            _ => &[],
        };
        near.iter().copied().filter(move |&c| {
            let cell = self.cell(c);
            self.kind.facets().iter().any(|f| {
                let mut nodes = [0usize; 3];
                for (q, &l) in f.iter().take(corners).enumerate() {
                    nodes[q] = cell[l];
                }
                f.len() == facet.len() && key(&nodes[..corners]) == k
            })
        })
    }

    /// The nodes that no cell uses, sorted.
    pub fn unused_nodes(&self) -> Vec<usize> {
        let mut used = vec![false; self.n_nodes()];
        for &v in &self.cells {
            if let Some(u) = used.get_mut(v) {
                *u = true;
            }
        }
        (0..used.len()).filter(|&v| !used[v]).collect()
    }

    /// Nodes whose coordinates equal those of another node (each such node but the first).
    fn coincident_nodes(&self) -> usize {
        let mut order: Vec<[u64; 3]> = self
            .points
            .iter()
            .map(|p| p.map(|x| if x == 0.0 { 0.0f64.to_bits() } else { x.to_bits() }))
            .collect();
        order.sort_unstable();
        order.windows(2).filter(|w| w[0] == w[1]).count()
    }

    /// The unit outward normal of each facet of boundary group `group`: the facet's normal,
    /// turned away from the cell that holds it.
    ///
    /// # Errors
    /// [`MeshError::MissingBoundary`]; [`MeshError::BadBoundaryFacet`] for a facet that no cell
    /// holds, or that two cells hold (inside the mesh, it has no outward side).
    pub fn outward_normals(&self, group: &str) -> Result<Vec<[f64; 3]>, MeshError> {
        let g = self.boundary(group)?;
        let around = self.node_cells();
        // each facet's cells: its owner, and whether another shares it
        let owners: Vec<(Option<usize>, bool)> = g
            .iter()
            .map(|facet| {
                let mut cells = self.cells_of_facet(&around, facet);
                (cells.next(), cells.next().is_some())
            })
            .collect();
        if let Some(f) = owners.iter().position(|o| o.1) {
            return Err(MeshError::BadBoundaryFacet {
                group: group.into(),
                facet: f,
                nodes: g.facet(f).to_vec(),
                problem: "lies inside the mesh (two cells share it): it has no outward normal",
            });
        }
        let mut out = Vec::with_capacity(g.n_facets());
        for (f, facet) in g.iter().enumerate() {
            let owner = owners[f].0.ok_or_else(|| MeshError::BadBoundaryFacet {
                group: group.into(),
                facet: f,
                nodes: facet.to_vec(),
                problem: "is not a facet of any cell",
            })?;
            let p = |v: usize| self.points[v];
            let n = if self.dim == 2 {
                let (a, b) = (p(facet[0]), p(facet[1]));
                [b[1] - a[1], a[0] - b[0], 0.0]
            } else {
                crate::generate::triangle_normal(&self.points, facet)
            };
            // a node of the cell off the facet lies inside: the normal points away from it
            let inside = self
                .cell(owner)
                .iter()
                .copied()
                .find(|v| !facet.contains(v))
                .unwrap_or(facet[0]);
            let a = p(facet[0]);
            let towards: f64 = (0..3).map(|k| n[k] * (p(inside)[k] - a[k])).sum();
            let len = crate::scaled_norm(&n);
            let s = if towards > 0.0 { -1.0 / len } else { 1.0 / len };
            out.push(n.map(|x| x * s));
        }
        Ok(out)
    }
}

/// Union-find with path halving; a root is the smallest member of its set.
struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n).collect())
    }

    fn root(&mut self, mut v: usize) -> usize {
        while self.0[v] != v {
            self.0[v] = self.0[self.0[v]];
            v = self.0[v];
        }
        v
    }

    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        self.0[ra.max(rb)] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use crate::{box_tet, rectangle_tri, MeshError};

    #[test]
    fn a_conforming_mesh_passes_and_its_normals_point_out() {
        let m = rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2);
        assert_eq!(m.check_topology(&m.cell_facets()), Ok((0, 0)));
        for (g, n) in [
            ("bottom", [0.0, -1.0]),
            ("top", [0.0, 1.0]),
            ("left", [-1.0, 0.0]),
            ("right", [1.0, 0.0]),
        ] {
            for v in m.outward_normals(g).unwrap() {
                assert!((v[0] - n[0]).abs() < 1e-14 && (v[1] - n[1]).abs() < 1e-14, "{g}: {v:?}");
            }
        }
        let b = box_tet([0.0; 3], [1.0, 2.0, 1.0], 2, 2, 2);
        assert_eq!(b.check_topology(&b.cell_facets()), Ok((0, 0)));
        for v in b.outward_normals("bottom").unwrap() {
            assert!((v[2] + 1.0).abs() < 1e-14, "{v:?}");
        }
    }

    /// A facet's cells are those with one of their own facets on its nodes: two across an
    /// interior edge of quads, none for a quad's diagonal (whose two nodes the quad holds).
    #[test]
    fn a_quads_diagonal_is_no_facet_of_it() {
        let m = crate::rectangle_quad([0.0, 0.0], [2.0, 1.0], 2, 1);
        let around = m.node_cells();
        let (a, b) = (m.cell(0).to_vec(), m.cell(1).to_vec());
        let shared: Vec<usize> = a.iter().copied().filter(|v| b.contains(v)).collect();
        assert_eq!(m.cells_of_facet(&around, &shared).count(), 2);
        let diagonal = [a[0], a[2]];
        assert_eq!(m.cells_of_facet(&around, &diagonal).count(), 0);
        assert_eq!(m.cells_of_facet(&around, &[a[0], a[1]]).collect::<Vec<_>>(), vec![0]);
        // nodes the mesh does not have
        assert_eq!(m.cells_of_facet(&around, &[m.n_nodes() + 5, 0]).count(), 0);
    }

    #[test]
    fn broken_topology_is_named() {
        // a cell listed twice
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 2, 2);
        let c0 = m.cell(0).to_vec();
        m.cells.extend_from_slice(&c0);
        assert!(matches!(
            m.check_topology(&m.cell_facets()),
            Err(MeshError::OverlappingCells { .. })
        ));
        // a boundary facet listed twice (two physical groups of one name)
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 2, 2);
        let g = m.boundaries.get_mut("bottom").unwrap();
        let first = g.facet(0).to_vec();
        g.facets.extend_from_slice(&first);
        let e = m.check_topology(&m.cell_facets()).unwrap_err().to_string();
        assert!(e.contains("listed twice"), "{e}");
        // an interior facet in a group (the diagonal of the first square): counted, and refused
        // where an outward normal is asked for
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 2, 2);
        let diag = {
            let c = m.cell(0);
            let f = m.cell(1);
            let shared: Vec<usize> = c.iter().copied().filter(|v| f.contains(v)).collect();
            shared
        };
        m.boundaries.get_mut("top").unwrap().facets.extend_from_slice(&diag);
        assert_eq!(m.check_topology(&m.cell_facets()), Ok((0, 1)));
        assert_eq!(m.interior_facets("top"), Ok(vec![2]));
        let e = m.outward_normals("top").unwrap_err().to_string();
        assert!(
            e.contains("lies inside the mesh") && e.contains("no outward normal"),
            "{e}"
        );
        // a crack: the diagonal of a square with its two nodes doubled is counted, not refused
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 1, 1);
        let (c0, c1) = (m.cell(0).to_vec(), m.cell(1).to_vec());
        let shared: Vec<usize> = c0.iter().copied().filter(|v| c1.contains(v)).collect();
        for (k, &v) in shared.iter().enumerate() {
            m.points.push(m.points[v]);
            let copy = m.points.len() - 1;
            for slot in &mut m.cells[3..6] {
                if *slot == v {
                    *slot = copy;
                }
            }
            assert!(k < 2);
        }
        m.boundaries.clear();
        assert_eq!(m.check_topology(&m.cell_facets()), Ok((2, 0)));
    }
}
