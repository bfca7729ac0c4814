//! Quality checks: finite coordinates, node indices in range, no degenerate or inverted cell,
//! and the topology of `topology.rs`; nodes that no cell uses are counted.

use crate::generate::signed_volume;
use crate::{CellKind, Mesh, MeshError};

/// What [`Mesh::check`] measured on a mesh that passed.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityReport {
    /// Sum of the cells' areas (2D) or volumes (3D).
    pub total_measure: f64,
    /// The smallest cell measure.
    pub min_measure: f64,
    /// The longest edge over all cells.
    pub h_max: f64,
    /// The shortest edge over all cells.
    pub h_min: f64,
    /// The largest ratio of a cell's longest edge to its inscribed size
    /// (`h^dim / measure`, normalised to 1-ish for a right isoceles simplex).
    pub max_aspect: f64,
    /// Nodes that share their coordinates with another node (a crack, or parts not merged).
    pub coincident_nodes: usize,
    /// Nodes that no cell uses (the centre of a Gmsh circle arc, a point of the geometry off
    /// the body): they carry no unknown.
    pub unused_nodes: usize,
    /// Facets of boundary groups that lie inside the mesh (a material interface, an internal
    /// electrode), over all groups.
    pub interior_group_facets: usize,
    /// Boundary facets that lie on other boundary facets, and their total length (2D) or area
    /// (3D): a seam where parts of the mesh are not joined, so that the body is cut along it
    /// ([`Mesh::seam_facets`]).
    pub seam: (usize, f64),
}

/// A cell whose measure is below this fraction of `h^dim` (its longest edge to the power of
/// the dimension) is degenerate: round-off in coordinates of size `h` is about 1e-16 h.
const DEGENERATE_REL: f64 = 1e-12;

impl Mesh {
    /// Checks the mesh and measures it.
    ///
    /// Errors, in the order they are looked for: [`MeshError::Empty`],
    /// [`MeshError::NonFiniteCoordinate`], [`MeshError::NodeOutOfRange`] (cells, facets,
    /// region entries), [`MeshError::BadCell`] (degenerate: `|measure| <= 1e-12 h^dim`;
    /// inverted: negative measure, or for a quadrilateral a non-positive corner Jacobian; a
    /// curved second-order cell is measured by its corners, its map checked where it is
    /// assembled),
    /// then the topology: [`MeshError::OverlappingCells`],
    /// [`MeshError::DuplicateCell`], [`MeshError::BadBoundaryFacet`].
    pub fn check(&self) -> Result<QualityReport, MeshError> {
        if self.n_cells() == 0 {
            return Err(MeshError::Empty);
        }
        for (node, p) in self.points.iter().enumerate() {
            if p.iter().any(|x| !x.is_finite()) {
                return Err(MeshError::NonFiniteCoordinate { node, coord: *p });
            }
        }
        let n_nodes = self.n_nodes();
        let out_of_range = |item: String, node: usize| MeshError::NodeOutOfRange { item, node, n_nodes };
        for (c, cell) in self.iter_cells().enumerate() {
            if let Some(&v) = cell.iter().find(|&&v| v >= n_nodes) {
                return Err(out_of_range(format!("cell {c}"), v));
            }
        }
        for (name, g) in &self.boundaries {
            for (f, facet) in g.iter().enumerate() {
                if let Some(&v) = facet.iter().find(|&&v| v >= n_nodes) {
                    return Err(out_of_range(format!("facet {f} of boundary group `{name}`"), v));
                }
            }
        }
        let n_cells = self.n_cells();
        for (name, cells) in &self.regions {
            if let Some(&c) = cells.iter().find(|&&c| c >= n_cells) {
                return Err(MeshError::NodeOutOfRange {
                    item: format!("region `{name}` (cell index; the mesh has {n_cells} cells)"),
                    node: c,
                    n_nodes,
                });
            }
        }
        let mut report = QualityReport {
            total_measure: 0.0,
            min_measure: f64::INFINITY,
            h_max: 0.0,
            h_min: f64::INFINITY,
            max_aspect: 0.0,
            coincident_nodes: 0,
            unused_nodes: 0,
            interior_group_facets: 0,
            seam: (0, 0.0),
        };
        let measure_name = if self.dim == 2 { "area" } else { "volume" };
        let corners = self.kind.n_corners();
        for (c, cell) in self.iter_cells().enumerate() {
            let (mut lmin, mut lmax) = (f64::INFINITY, 0.0f64);
            for (a, &i) in cell[..corners].iter().enumerate() {
                for &j in &cell[a + 1..corners] {
                    let l = crate::dist(&self.points[i], &self.points[j]);
                    lmin = lmin.min(l);
                    lmax = lmax.max(l);
                }
            }
            let (measure, corners_ok) = self.cell_measure(cell);
            let scale = lmax.powi(self.dim as i32);
            let bad = |what| MeshError::BadCell {
                cell: c,
                what,
                measure_name,
                measure,
                nodes: cell.to_vec(),
            };
            if measure.abs() <= DEGENERATE_REL * scale || !measure.is_finite() {
                return Err(bad("degenerate"));
            }
            if measure < 0.0 || !corners_ok {
                return Err(bad("inverted"));
            }
            report.total_measure += measure;
            report.min_measure = report.min_measure.min(measure);
            report.h_max = report.h_max.max(lmax);
            report.h_min = report.h_min.min(lmin);
            let reference = match self.kind {
                CellKind::Tri3 | CellKind::Tri6 => 0.25, // right isoceles triangle: h^2 / 4 with h the hypotenuse
                CellKind::Quad4 => 0.5,                  // square: h^2 / 2 with h the diagonal
                CellKind::Tet4 | CellKind::Tet10 => 1.0 / 27.0, // cube-corner-ish scale, see Kuhn tetrahedra
            };
            report.max_aspect = report.max_aspect.max(reference * scale / measure);
        }
        report.unused_nodes = self.unused_nodes().len();
        // the cells' facets sorted once, for the topology's checks and the seams
        let facets = self.cell_facets();
        (report.coincident_nodes, report.interior_group_facets) = self.check_topology(&facets)?;
        report.seam = self.seams_of(&facets);
        Ok(report)
    }

    /// Signed measure of a cell and, for quadrilaterals, whether every corner turns left.
    fn cell_measure(&self, cell: &[usize]) -> (f64, bool) {
        let p = |q: usize| self.points[cell[q]];
        match self.kind {
            CellKind::Tri3 | CellKind::Tri6 => {
                let (a, b, c) = (p(0), p(1), p(2));
                (
                    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])),
                    true,
                )
            }
            CellKind::Quad4 => {
                let mut area = 0.0;
                let mut convex = true;
                for q in 0..4 {
                    let (a, b, c) = (p(q), p((q + 1) % 4), p((q + 2) % 4));
                    area += 0.5 * (a[0] * b[1] - b[0] * a[1]);
                    let turn = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
                    convex &= turn > 0.0;
                }
                (area, convex)
            }
            CellKind::Tet4 | CellKind::Tet10 => (signed_volume(&self.points, cell), true),
        }
    }

    /// Which cells are curved: a second-order cell with an edge node off its edge's midpoint
    /// ([`straight_sided`]); none in a linear mesh.
    pub fn curved_cells(&self) -> Vec<bool> {
        let (corners, edges) = (self.kind.n_corners(), self.kind.midside_edges());
        let mut x = [[0.0; 3]; 10];
        self.iter_cells()
            .map(|cell| {
                for (xa, &v) in x.iter_mut().zip(cell) {
                    *xa = self.points[v];
                }
                !straight_sided(&x[..cell.len()], corners, edges)
            })
            .collect()
    }
}

/// Whether a second-order simplex whose nodes are at `x` (its `corners`, then the midpoints of
/// `edges`, by the corners' local indices) has each edge node at its edge's midpoint, to 1e-9
/// of its longest edge: a straight-sided simplex, whose map is its corners' (affine). True for
/// a first-order simplex (`x` its corners alone).
pub fn straight_sided(x: &[[f64; 3]], corners: usize, edges: &[[usize; 2]]) -> bool {
    if x.len() <= corners {
        return true;
    }
    let dist = |a: &[f64; 3], b: &[f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
    let h = edges.iter().map(|&[a, b]| dist(&x[a], &x[b])).fold(0.0f64, f64::max);
    edges.iter().enumerate().all(|(m, &[a, b])| {
        let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * (x[a][k] + x[b][k]));
        dist(&x[corners + m], &mid) <= 1e-9 * h
    })
}

#[cfg(test)]
mod tests {
    use crate::{box_tet, rectangle_tri, MeshError};

    #[test]
    fn inverted_and_degenerate_cells_are_named() {
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 2, 2);
        m.cells.swap(3, 4); // cell 1 reversed
        match m.check() {
            Err(MeshError::BadCell {
                cell: 1,
                what: "inverted",
                ..
            }) => {}
            other => panic!("{other:?}"),
        }
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 2, 2);
        let c0 = m.cell(0).to_vec();
        m.points[c0[2]] = [0.25, 0.0, 0.0]; // collapse onto the bottom edge
        assert!(matches!(m.check(), Err(MeshError::BadCell { what: "degenerate", .. })));
        let mut t = box_tet([0.0; 3], [1.0; 3], 1, 1, 1);
        t.cells.swap(0, 1);
        assert!(matches!(
            t.check(),
            Err(MeshError::BadCell {
                cell: 0,
                what: "inverted",
                ..
            })
        ));
    }

    #[test]
    fn unused_nodes_nan_and_missing_groups() {
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 1, 1);
        m.points.push([5.0, 5.0, 0.0]);
        assert_eq!(m.check().map(|r| r.unused_nodes), Ok(1));
        assert_eq!(m.unused_nodes(), vec![4]);
        let mut m = rectangle_tri([0.0, 0.0], [1.0, 1.0], 1, 1);
        m.points[2][1] = f64::NAN;
        assert!(matches!(m.check(), Err(MeshError::NonFiniteCoordinate { node: 2, .. })));
        let err = m.boundary("contact").unwrap_err();
        assert_eq!(
            err.to_string(),
            "boundary group `contact` is missing (the mesh has: bottom, left, right, top)"
        );
    }
}
