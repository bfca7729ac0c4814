//! A P1 simplex mesh raised to order 2: a node at the midpoint of every edge, each cell the
//! six-node triangle or ten-node tetrahedron with its corners (straight-sided cells), each
//! facet of a group its corners and its edges' midpoints. Regions keep their cells.

use crate::{FacetGroup, Mesh, MeshError};
use std::collections::HashMap;

impl Mesh {
    /// The same mesh with a node at the midpoint of every edge: P1 triangles become six-node
    /// triangles ([`crate::CellKind::Tri6`]) and tetrahedra ten-node ones
    /// ([`crate::CellKind::Tet10`]), straight-sided; the nodes of `self` keep their indices
    /// and the edges' nodes follow, numbered as the cells first meet them. A quadratic mesh is
    /// returned as it is.
    ///
    /// # Errors
    /// [`MeshError::Parts`] for a mesh of quadrilaterals (no quadratic simplex has their
    /// corners); [`MeshError::BadBoundaryFacet`] for a group's facet with an edge no cell has.
    ///
    /// # Example
    /// ```
    /// use mesh::{rectangle_tri, CellKind};
    /// let m = rectangle_tri([0.0, 0.0], [2.0, 1.0], 2, 1).quadratic().unwrap();
    /// assert_eq!(m.kind, CellKind::Tri6);
    /// // 6 corners, and 9 edges: 3 x 2 + 2 x 1 + 4 diagonals... of the 4 triangles
    /// assert_eq!(m.n_nodes(), 6 + 9);
    /// assert_eq!(m.boundary("bottom").unwrap().facet(0).len(), 3);
    /// m.check().unwrap();
    /// ```
    pub fn quadratic(&self) -> Result<Mesh, MeshError> {
        if self.kind.order() == 2 {
            return Ok(self.clone());
        }
        let kind = self.kind.quadratic().ok_or_else(|| MeshError::Parts {
            message: format!(
                "a mesh of {} cells has no second-order form: use triangles",
                self.kind.name()
            ),
        })?;
        let corners = self.kind.n_corners();
        let mut points = self.points.clone();
        let mut edge_node: HashMap<(usize, usize), usize> = HashMap::with_capacity(self.n_cells() * 2);
        let mut cells = Vec::with_capacity(self.n_cells() * kind.n_nodes());
        for cell in self.iter_cells() {
            cells.extend_from_slice(&cell[..corners]);
            for &[a, b] in kind.midside_edges() {
                let (i, j) = (cell[a], cell[b]);
                let node = *edge_node.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    let (p, q) = (points[i], points[j]);
                    points.push([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])]);
                    points.len() - 1
                });
                cells.push(node);
            }
        }
        let facet_edges: &[[usize; 2]] = if self.dim == 2 {
            &[[0, 1]]
        } else {
            &[[0, 1], [1, 2], [2, 0]]
        };
        let mut boundaries = std::collections::BTreeMap::new();
        for (name, group) in &self.boundaries {
            let mut facets = Vec::with_capacity(group.n_facets() * kind.facet_n_nodes());
            for (f, facet) in group.iter().enumerate() {
                facets.extend_from_slice(facet);
                for &[a, b] in facet_edges {
                    let (i, j) = (facet[a], facet[b]);
                    let node = edge_node
                        .get(&(i.min(j), i.max(j)))
                        .ok_or_else(|| MeshError::BadBoundaryFacet {
                            group: name.clone(),
                            facet: f,
                            nodes: facet.to_vec(),
                            problem: "is not a facet of any cell",
                        })?;
                    facets.push(*node);
                }
            }
            boundaries.insert(
                name.clone(),
                FacetGroup {
                    nodes_per_facet: kind.facet_n_nodes(),
                    facets,
                },
            );
        }
        Ok(Mesh {
            dim: self.dim,
            kind,
            points,
            cells,
            boundaries,
            regions: self.regions.clone(),
            reoriented_cells: self.reoriented_cells,
            other_groups: self.other_groups.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::parts::tests::parts_of as parts;
    use crate::{box_tet, rectangle_tri, CellKind};

    #[test]
    fn a_quadratic_rectangle_has_a_node_on_every_edge() {
        let (nx, ny) = (4, 3);
        let m = rectangle_tri([0.0, 0.0], [2.0, 1.0], nx, ny).quadratic().unwrap();
        // (2nx + 1)(2ny + 1) nodes: the grid of half the spacing
        assert_eq!(m.n_nodes(), (2 * nx + 1) * (2 * ny + 1));
        assert_eq!(m.kind, CellKind::Tri6);
        let report = m.check().unwrap();
        assert!((report.total_measure - 2.0).abs() < 1e-14);
        for (name, n) in [("bottom", nx), ("left", ny)] {
            let g = m.boundary(name).unwrap();
            assert_eq!((g.n_facets(), g.nodes().len()), (n, 2 * n + 1));
        }
    }

    #[test]
    fn a_quadratic_box_is_conforming_and_its_edge_nodes_are_midpoints() {
        let (nx, ny, nz) = (2, 3, 2);
        let m = box_tet([0.0; 3], [1.0, 2.0, 3.0], nx, ny, nz).quadratic().unwrap();
        assert_eq!(m.n_nodes(), (2 * nx + 1) * (2 * ny + 1) * (2 * nz + 1));
        let report = m.check().unwrap();
        assert!((report.total_measure - 6.0).abs() < 1e-13);
        // each face group: the grid of half the spacing on its face
        let top = m.boundary("top").unwrap();
        assert_eq!(top.nodes().len(), (2 * nx + 1) * (2 * ny + 1));
        assert_eq!(top.facet(0).len(), 6);
    }

    #[test]
    fn edge_nodes_not_shared_by_the_cells_of_an_edge_are_named() {
        // two cells on a diagonal, each with its own copy of the diagonal's midpoint
        let m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 1, 1).quadratic().unwrap();
        let mut split = m.clone();
        let (c0, c1) = (split.cell(0).to_vec(), split.cell(1).to_vec());
        let shared = c0[3..].iter().copied().find(|v| c1[3..].contains(v)).unwrap();
        split.points.push(split.points[shared]);
        let copy = split.n_nodes() - 1;
        let slot = 6 + c1[3..].iter().position(|&v| v == shared).unwrap() + 3;
        split.cells[slot] = copy;
        match crate::Mesh::from_parts(parts(&split)) {
            Err(crate::MeshError::NonConformingEdge { node, other: 0, .. }) => assert_eq!(node, copy),
            other => panic!("{other:?}"),
        }
        // a hanging node: the midpoint of one cell's edge is a corner of the cell below it
        let points = [
            [0.0, 0.0],
            [2.0, 0.0],
            [0.0, 2.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [1.0, -1.0],
            [0.5, -0.5],
            [1.0, -0.5],
            [0.5, 0.0],
        ];
        let hanging = crate::parts::MeshParts {
            dim: 2,
            points: points.iter().map(|p| [p[0], p[1], 0.0]).collect(),
            cells: vec![0, 1, 2, 3, 4, 5, 0, 6, 3, 7, 8, 9],
            nodes_per_cell: 6,
            boundaries: Default::default(),
            regions: Default::default(),
        };
        let e = crate::Mesh::from_parts(hanging).unwrap_err();
        assert!(matches!(e, crate::MeshError::NonConformingEdge { node: 3, .. }), "{e}");
        assert!(e.to_string().contains("corner of another cell"), "{e}");
    }

    #[test]
    fn a_curved_cell_is_counted_and_a_facet_with_foreign_edge_nodes_named() {
        let m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 1, 1).quadratic().unwrap();
        crate::Mesh::from_parts(parts(&m)).unwrap();
        let mut bent = m.clone();
        let mid = bent.cells[3];
        bent.points[mid][1] += 0.1;
        let bent = crate::Mesh::from_parts(parts(&bent)).unwrap();
        assert_eq!(bent.curved_cells().iter().filter(|&&c| c).count(), 1);
        let mut foreign = m.clone();
        let g = foreign.boundaries.get_mut("bottom").unwrap();
        g.facets[2] = m.cells[4]; // the midpoint of another edge
        let e = crate::Mesh::from_parts(parts(&foreign)).unwrap_err().to_string();
        assert!(e.contains("edge nodes"), "{e}");
    }
}
