//! A mesh from plain arrays (points, cells, named facet lists, named cell lists), as another
//! program hands it over: gmsh's or meshio's arrays from Python, or a mesh built in code.

use crate::{CellKind, FacetGroup, Mesh, MeshError};
use std::collections::BTreeMap;

/// The parts of a mesh as plain arrays, before they are checked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshParts {
    /// Spatial dimension, 2 or 3.
    pub dim: usize,
    /// Node coordinates (`z` must be 0 in 2D).
    pub points: Vec<[f64; 3]>,
    /// Flat cell connectivity, `nodes_per_cell` per cell.
    pub cells: Vec<usize>,
    /// Nodes per cell: 3 or 6 (P1 or P2 triangles) or 4 (quadrilaterals) in 2D, 4 or 10 (P1 or
    /// P2 tetrahedra) in 3D; a P2 cell's edge nodes in VTK's (and meshio's) order.
    pub nodes_per_cell: usize,
    /// Named boundary facet lists, flat: `dim` nodes per facet (segments in 2D, triangles in
    /// 3D), and in a P2 mesh its edges' midpoints after them (3 and 6 nodes).
    pub boundaries: BTreeMap<String, Vec<usize>>,
    /// Named cell lists (regions, to attach materials to).
    pub regions: BTreeMap<String, Vec<usize>>,
}

impl CellKind {
    /// The kind of a cell of `nodes` nodes in dimension `dim`, `None` where there is none.
    pub fn of(dim: usize, nodes: usize) -> Option<CellKind> {
        match (dim, nodes) {
            (2, 3) => Some(CellKind::Tri3),
            (2, 4) => Some(CellKind::Quad4),
            (3, 4) => Some(CellKind::Tet4),
            (2, 6) => Some(CellKind::Tri6),
            (3, 10) => Some(CellKind::Tet10),
            _ => None,
        }
    }
}

impl Mesh {
    /// The mesh of `parts`, checked as a file's mesh is ([`Mesh::check`]); where every cell is
    /// negatively oriented (a surface numbered clockwise), every cell is turned round and
    /// [`Mesh::reoriented_cells`] counts them, as the Gmsh reader does.
    ///
    /// # Errors
    /// [`MeshError::Parts`] for arrays of the wrong shape (a dimension other than 2 or 3, a
    /// cell size that is no cell kind of the dimension, a flat list that is not whole cells or
    /// facets, a 2D point off `z = 0`), and the errors of [`Mesh::check`].
    ///
    /// # Example
    /// ```
    /// use mesh::{Mesh, MeshParts};
    /// // the unit square as two triangles, its bottom edge named
    /// let parts = MeshParts {
    ///     dim: 2,
    ///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    ///     cells: vec![0, 1, 2, 0, 2, 3],
    ///     nodes_per_cell: 3,
    ///     boundaries: [("bottom".to_string(), vec![0, 1])].into(),
    ///     regions: [("body".to_string(), vec![0, 1])].into(),
    /// };
    /// let m = Mesh::from_parts(parts).unwrap();
    /// assert_eq!((m.n_nodes(), m.n_cells()), (4, 2));
    /// assert_eq!(m.boundary("bottom").unwrap().n_facets(), 1);
    /// ```
    pub fn from_parts(parts: MeshParts) -> Result<Mesh, MeshError> {
        let MeshParts {
            dim,
            points,
            mut cells,
            nodes_per_cell,
            boundaries,
            regions,
        } = parts;
        let bad = |message: String| MeshError::Parts { message };
        let kind = CellKind::of(dim, nodes_per_cell).ok_or_else(|| {
            bad(format!(
                "cells of {nodes_per_cell} nodes in dimension {dim}: the cells are triangles (3 or 6) or quadrilaterals (4) in 2D, tetrahedra (4 or 10) in 3D"
            ))
        })?;
        if cells.len() % nodes_per_cell != 0 {
            return Err(bad(format!(
                "the cell list has {} entries, not a whole number of {nodes_per_cell}-node cells",
                cells.len()
            )));
        }
        if dim == 2 {
            if let Some((i, p)) = points.iter().enumerate().find(|(_, p)| p[2] != 0.0) {
                return Err(bad(format!("a 2D mesh lies in z = 0; node {i} has z = {}", p[2])));
            }
        }
        let nodes_per_facet = kind.facet_n_nodes();
        let mut groups = BTreeMap::new();
        for (name, facets) in boundaries {
            if facets.len() % nodes_per_facet != 0 {
                return Err(bad(format!(
                    "boundary group `{name}` has {} entries, not a whole number of {nodes_per_facet}-node facets",
                    facets.len()
                )));
            }
            groups.insert(
                name,
                FacetGroup {
                    nodes_per_facet,
                    facets,
                },
            );
        }
        let regions = regions
            .into_iter()
            .map(|(name, mut list)| {
                list.sort_unstable();
                list.dedup();
                (name, list)
            })
            .collect();
        let n_cells = cells.len() / nodes_per_cell;
        let in_range = cells.iter().all(|&v| v < points.len());
        // turning round needs the cells' nodes; out-of-range ones are named by `check`
        let reoriented_cells = if in_range {
            crate::gmsh::orient_block(&points, &mut cells, kind, 0, n_cells)
        } else {
            0
        };
        let mesh = Mesh {
            dim,
            kind,
            points,
            cells,
            boundaries: groups,
            regions,
            reoriented_cells,
            other_groups: Default::default(),
        };
        mesh.check()?;
        Ok(mesh)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The arrays of `m`, as another program would hand them over.
    pub(crate) fn parts_of(m: &Mesh) -> MeshParts {
        MeshParts {
            dim: m.dim,
            points: m.points.clone(),
            cells: m.cells.clone(),
            nodes_per_cell: m.kind.n_nodes(),
            boundaries: m
                .boundaries
                .iter()
                .map(|(k, g)| (k.clone(), g.facets.clone()))
                .collect(),
            regions: m.regions.clone(),
        }
    }

    fn square(cells: Vec<usize>) -> MeshParts {
        MeshParts {
            dim: 2,
            points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            cells,
            nodes_per_cell: 3,
            boundaries: [("bottom".to_string(), vec![0, 1])].into(),
            regions: [("body".to_string(), vec![1, 0, 1])].into(),
        }
    }

    #[test]
    fn parts_give_the_generated_mesh() {
        let m = crate::rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2);
        assert_eq!(Mesh::from_parts(parts_of(&m)).unwrap(), m);
    }

    #[test]
    fn clockwise_cells_are_turned_round_and_counted() {
        let m = Mesh::from_parts(square(vec![0, 2, 1, 0, 3, 2])).unwrap();
        assert_eq!(m.reoriented_cells, 2);
        assert_eq!(m.regions["body"], vec![0, 1]);
        // one of each: the inverted cell is named
        let e = Mesh::from_parts(square(vec![0, 1, 2, 0, 3, 2])).unwrap_err();
        assert!(
            matches!(
                e,
                MeshError::BadCell {
                    cell: 1,
                    what: "inverted",
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn arrays_of_the_wrong_shape_are_named() {
        let mut p = square(vec![0, 1, 2, 0, 2]);
        let e = Mesh::from_parts(p.clone()).unwrap_err().to_string();
        assert!(e.contains("not a whole number of 3-node cells"), "{e}");
        p.cells = vec![0, 1, 2, 0, 2, 3];
        p.nodes_per_cell = 5;
        let e = Mesh::from_parts(p.clone()).unwrap_err().to_string();
        assert!(e.contains("cells of 5 nodes in dimension 2"), "{e}");
        p.nodes_per_cell = 3;
        p.points[2][2] = 0.5;
        let e = Mesh::from_parts(p.clone()).unwrap_err().to_string();
        assert!(e.contains("node 2 has z = 0.5"), "{e}");
        p.points[2][2] = 0.0;
        p.boundaries.insert("top".into(), vec![2, 3, 0]);
        let e = Mesh::from_parts(p.clone()).unwrap_err().to_string();
        assert!(e.contains("`top` has 3 entries"), "{e}");
        p.boundaries.insert("top".into(), vec![2, 7]);
        let e = Mesh::from_parts(p.clone()).unwrap_err().to_string();
        assert!(e.contains("refers to node 7"), "{e}");
        p.boundaries.remove("top");
        p.regions.insert("pzt".into(), vec![5]);
        let e = Mesh::from_parts(p).unwrap_err().to_string();
        assert!(e.contains("region `pzt`"), "{e}");
    }
}
