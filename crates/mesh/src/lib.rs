//! Meshes for piezocontact: nodes, cells, named boundary facet groups and named cell regions.
//!
//! # Glossary
//! - `dim`: the spatial dimension, 2 (plane strain, x-y) or 3.
//! - node: a point; stored as `[x, y, z]` with `z = 0` in 2D. Indices are `usize`, 0-based.
//! - cell: a P1 triangle ([`CellKind::Tri3`]), a Q1 quadrilateral ([`CellKind::Quad4`]) or a
//!   P1 tetrahedron ([`CellKind::Tet4`]); node order is counter-clockwise (2D) or positively
//!   oriented (3D, `det[p1-p0, p2-p0, p3-p0] > 0`), checked by [`Mesh::check`].
//! - facet: an entity of dimension `dim - 1` (a segment in 2D, a triangle in 3D), on the
//!   boundary (one cell holds it) or inside (two cells do).
//! - boundary group: a named list of facets, on the boundary or inside (an interface) (`left`, `right`, `bottom`, `top`, and in 3D also
//!   `front` (y = y0) and `back` (y = y1) for the generators; Gmsh physical groups of dimension
//!   `dim - 1` for files).
//! - region: a named list of cells (`body` for the generators; Gmsh physical groups of
//!   dimension `dim` for files). Materials are attached to regions.
//!
//! Lengths carry the unit of the scene; the mesh itself is unit-free.
//!
//! # Example
//! ```
//! use mesh::{rectangle_tri, CellKind};
//! let m = rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2);
//! assert_eq!(m.kind, CellKind::Tri3);
//! assert_eq!(m.n_nodes(), 5 * 3);
//! assert_eq!(m.n_cells(), 2 * 4 * 2);
//! assert_eq!(m.boundary("bottom").unwrap().n_facets(), 4);
//! m.check().unwrap();
//! ```

mod generate;
mod gmsh;
mod ordering;
mod parts;
mod pieces;
mod quadratic;
mod quality;
mod seams;
mod topology;

pub use generate::{box_tet, rectangle_quad, rectangle_tri, round_quarter_section};
pub use gmsh::{parts_of, read_msh, read_msh_bytes, read_msh_part, MshPart};
pub use ordering::nested_dissection;
pub use parts::MeshParts;
pub use pieces::{Blocks, MeshPiece};
pub use quality::{straight_sided, QualityReport};

use rayon::prelude::*;
use std::collections::BTreeMap;

/// The kind of every cell of a mesh (meshes hold one kind).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellKind {
    /// Three-node triangle (P1), 2D.
    Tri3,
    /// Four-node quadrilateral (Q1), 2D, counter-clockwise.
    Quad4,
    /// Four-node tetrahedron (P1), 3D.
    Tet4,
    /// Six-node triangle (P2), 2D: the corners counter-clockwise, then the midpoints of the
    /// edges 0-1, 1-2, 2-0 (VTK's and Gmsh's order).
    Tri6,
    /// Ten-node tetrahedron (P2), 3D: the corners positively oriented, then the midpoints of
    /// the edges 0-1, 1-2, 2-0, 0-3, 1-3, 2-3 (VTK's order; Gmsh's swaps the last two).
    Tet10,
}

impl CellKind {
    /// Nodes per cell.
    pub fn n_nodes(self) -> usize {
        match self {
            CellKind::Tri3 => 3,
            CellKind::Quad4 | CellKind::Tet4 => 4,
            CellKind::Tri6 => 6,
            CellKind::Tet10 => 10,
        }
    }
    /// Corner nodes per cell (the first of its nodes): what its shape is made of.
    pub fn n_corners(self) -> usize {
        match self {
            CellKind::Tri3 | CellKind::Tri6 => 3,
            CellKind::Quad4 | CellKind::Tet4 | CellKind::Tet10 => 4,
        }
    }
    /// Spatial dimension of the cell.
    pub fn dim(self) -> usize {
        match self {
            CellKind::Tri3 | CellKind::Quad4 | CellKind::Tri6 => 2,
            CellKind::Tet4 | CellKind::Tet10 => 3,
        }
    }
    /// The polynomial order of the cell's shape functions: 1 or 2.
    pub fn order(self) -> usize {
        match self {
            CellKind::Tri6 | CellKind::Tet10 => 2,
            _ => 1,
        }
    }
    /// Nodes per boundary facet of a mesh of this kind (its corners first, then its edges'
    /// midpoints in a quadratic mesh).
    pub fn facet_n_nodes(self) -> usize {
        match self {
            CellKind::Tri3 | CellKind::Quad4 => 2,
            CellKind::Tet4 | CellKind::Tri6 => 3,
            CellKind::Tet10 => 6,
        }
    }
    /// A short name, as in messages.
    pub fn name(self) -> &'static str {
        match self {
            CellKind::Tri3 => "triangle (P1)",
            CellKind::Quad4 => "quadrilateral (Q1)",
            CellKind::Tet4 => "tetrahedron (P1)",
            CellKind::Tri6 => "triangle (P2)",
            CellKind::Tet10 => "tetrahedron (P2)",
        }
    }
    /// The edges whose midpoints are the cell's nodes after its corners, in their order (its
    /// corners' local indices); none for a P1 cell.
    pub fn midside_edges(self) -> &'static [[usize; 2]] {
        match self {
            CellKind::Tri6 => &[[0, 1], [1, 2], [2, 0]],
            CellKind::Tet10 => &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
            _ => &[],
        }
    }
    /// A triangle (or a triangular face of a tetrahedron of the same order) as first-order
    /// triangles of its nodes' local indices, each counter-clockwise as it is: itself, or a
    /// six-node triangle's four of its corners and edge nodes (its quadratic fields drawn
    /// linear on each); none for the other kinds.
    pub fn linear_triangles(self) -> &'static [[usize; 3]] {
        match self {
            CellKind::Tri3 | CellKind::Tet4 => &[[0, 1, 2]],
            CellKind::Tri6 | CellKind::Tet10 => &[[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]],
            CellKind::Quad4 => &[],
        }
    }
    /// The simplex of order 2 with the same corners (a quadrilateral has none: `None`).
    pub fn quadratic(self) -> Option<CellKind> {
        match self {
            CellKind::Tri3 | CellKind::Tri6 => Some(CellKind::Tri6),
            CellKind::Tet4 | CellKind::Tet10 => Some(CellKind::Tet10),
            CellKind::Quad4 => None,
        }
    }
}

/// A named set of facets, each given by its `facet_n_nodes` node indices: on the boundary, or
/// inside the mesh (a material interface, an internal electrode; see
/// [`Mesh::interior_facets`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FacetGroup {
    /// Nodes per facet (2 in 2D, 3 in 3D).
    pub nodes_per_facet: usize,
    /// Flat node indices, `nodes_per_facet` per facet.
    pub facets: Vec<usize>,
}

impl FacetGroup {
    /// Number of facets.
    pub fn n_facets(&self) -> usize {
        self.facets.len().checked_div(self.nodes_per_facet).unwrap_or(0)
    }
    /// The node indices of facet `f`.
    pub fn facet(&self, f: usize) -> &[usize] {
        &self.facets[f * self.nodes_per_facet..(f + 1) * self.nodes_per_facet]
    }
    /// Iterator over the facets.
    pub fn iter(&self) -> impl Iterator<Item = &[usize]> + '_ {
        self.facets.chunks_exact(self.nodes_per_facet.max(1))
    }
    /// The distinct nodes of the group, sorted.
    pub fn nodes(&self) -> Vec<usize> {
        let mut v = self.facets.clone();
        v.sort_unstable();
        v.dedup();
        v
    }
}

/// A mesh of one cell kind with named boundary groups and regions.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Spatial dimension (2 or 3).
    pub dim: usize,
    /// The kind of every cell.
    pub kind: CellKind,
    /// Node coordinates, `z = 0` in 2D.
    pub points: Vec<[f64; 3]>,
    /// Flat cell connectivity, `kind.n_nodes()` per cell.
    pub cells: Vec<usize>,
    /// Named boundary facet groups.
    pub boundaries: BTreeMap<String, FacetGroup>,
    /// Named cell regions (lists of cell indices, sorted).
    pub regions: BTreeMap<String, Vec<usize>>,
    /// Cells the reader turned round (a 2D block written clockwise); 0 for a generated mesh.
    pub reoriented_cells: usize,
    /// A file's named groups that are neither regions nor boundary groups (points, or curves
    /// of a 3D mesh), with their dimension: unused, kept to name them where one is asked for
    /// as a boundary group or a region.
    pub other_groups: BTreeMap<String, usize>,
}

/// What can go wrong with a mesh: reading it, checking it, or asking it for a group.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// A boundary group was asked for that the mesh does not have.
    #[error("boundary group `{name}` is missing (the mesh has: {available}){elsewhere}")]
    MissingBoundary {
        /// The group asked for.
        name: String,
        /// The groups the mesh has, comma-separated.
        available: String,
        /// What a group of that name is where the mesh has one of another kind (`; `name` is a
        /// region ...`), or empty.
        elsewhere: String,
    },
    /// A region was asked for that the mesh does not have.
    #[error("region `{name}` is missing (the mesh has: {available}){elsewhere}")]
    MissingRegion {
        /// The region asked for.
        name: String,
        /// The regions the mesh has, comma-separated.
        available: String,
        /// What a group of that name is where the mesh has one of another kind, or empty.
        elsewhere: String,
    },
    /// A cell whose signed measure is zero (up to round-off) or has the wrong sign.
    #[error("cell {cell} is {what} (signed {measure_name} {measure:.3e}, nodes {nodes:?})")]
    BadCell {
        /// Cell index.
        cell: usize,
        /// `degenerate` or `inverted`.
        what: &'static str,
        /// `area` or `volume`.
        measure_name: &'static str,
        /// The signed measure.
        measure: f64,
        /// The cell's nodes.
        nodes: Vec<usize>,
    },
    /// A cell or facet that names a node that does not exist.
    #[error("{item} refers to node {node}, but the mesh has {n_nodes} nodes")]
    NodeOutOfRange {
        /// What refers to it (e.g. `cell 12`, `facet 3 of group top`).
        item: String,
        /// The bad index.
        node: usize,
        /// Number of nodes.
        n_nodes: usize,
    },
    /// A coordinate that is NaN or infinite.
    #[error("node {node} has a non-finite coordinate {coord:?}")]
    NonFiniteCoordinate {
        /// Node index.
        node: usize,
        /// Its coordinates.
        coord: [f64; 3],
    },
    /// A mesh without cells.
    #[error("the mesh has no cells")]
    Empty,
    /// A facet shared by more than two cells: cells overlap.
    #[error("facet {facet:?} is shared by {} cells ({cells:?}): the cells overlap", cells.len())]
    OverlappingCells {
        /// The facet's nodes.
        facet: Vec<usize>,
        /// The cells that hold it.
        cells: Vec<usize>,
    },
    /// Two cells with the same nodes.
    #[error("cells {first} and {second} have the same nodes")]
    DuplicateCell {
        /// The first.
        first: usize,
        /// The second.
        second: usize,
    },
    /// A facet of a boundary group that is not one boundary facet of the mesh, listed once.
    #[error("facet {facet} of boundary group `{group}` (nodes {nodes:?}) {problem}")]
    BadBoundaryFacet {
        /// The group.
        group: String,
        /// The facet's index in the group.
        facet: usize,
        /// Its nodes.
        nodes: Vec<usize>,
        /// What is wrong.
        problem: &'static str,
    },
    /// A second-order mesh whose cells do not share their edges' midpoint nodes: an edge
    /// with two midpoint nodes (edge nodes made per cell and not merged), or a node that is
    /// one cell's edge node and another's corner (a hanging node). Either splits the body
    /// along the edge, silently.
    #[error("edge {edge:?} of cell {cell} {problem} (node {node}, cell {other}): a quadratic mesh's cells must share each edge's midpoint node")]
    NonConformingEdge {
        /// The edge's corners.
        edge: [usize; 2],
        /// The cell whose edge it is.
        cell: usize,
        /// Its midpoint node in that cell.
        node: usize,
        /// What is wrong.
        problem: &'static str,
        /// The other cell that uses the node or the edge.
        other: usize,
    },
    /// A file could not be read.
    #[error("cannot read mesh file {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// Arrays handed over as a mesh ([`Mesh::from_parts`]) that do not have a mesh's shape.
    #[error("mesh arrays: {message}")]
    Parts {
        /// What is wrong.
        message: String,
    },
    /// A Gmsh file that does not parse, or holds what we cannot use.
    #[error("Gmsh file {path}: {message}")]
    Gmsh {
        /// The file (or `<bytes>`).
        path: String,
        /// What is wrong.
        message: String,
    },
}

impl Mesh {
    /// A mesh of nothing (no node, no cell) of dimension `dim`: a placeholder where a mesh
    /// was taken, or a solution with nothing to draw.
    pub fn empty(dim: usize) -> Mesh {
        Mesh {
            dim,
            kind: if dim == 2 { CellKind::Tri3 } else { CellKind::Tet4 },
            points: vec![],
            cells: vec![],
            boundaries: BTreeMap::new(),
            regions: BTreeMap::new(),
            reoriented_cells: 0,
            other_groups: Default::default(),
        }
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.points.len()
    }
    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.cells.len() / self.kind.n_nodes()
    }
    /// The node indices of cell `c`.
    pub fn cell(&self, c: usize) -> &[usize] {
        let k = self.kind.n_nodes();
        &self.cells[c * k..(c + 1) * k]
    }
    /// Iterator over the cells' node lists.
    pub fn iter_cells(&self) -> impl Iterator<Item = &[usize]> + '_ {
        self.cells.chunks_exact(self.kind.n_nodes())
    }
    /// The coordinates of node `i` (first `dim` entries meaningful).
    pub fn point(&self, i: usize) -> &[f64] {
        &self.points[i][..self.dim]
    }
    /// The boundary group `name`, or a [`MeshError::MissingBoundary`] that lists what exists.
    pub fn boundary(&self, name: &str) -> Result<&FacetGroup, MeshError> {
        self.boundaries.get(name).ok_or_else(|| MeshError::MissingBoundary {
            name: name.to_string(),
            available: join_keys(self.boundaries.keys()),
            elsewhere: self.group_elsewhere(name),
        })
    }

    /// What the mesh's group `name`, missing as the kind asked for, is instead: `"; `name` is a
    /// region ..."`, or empty where the mesh has no group of that name.
    fn group_elsewhere(&self, name: &str) -> String {
        let facets = if self.dim == 3 { "surfaces" } else { "curves" };
        if self.regions.contains_key(name) {
            format!(
                "; `{name}` is a region (a group of the body's {}D cells): a boundary group is one of {facets}",
                self.dim
            )
        } else if self.boundaries.contains_key(name) {
            format!(
                "; `{name}` is a boundary group (of {facets}): a region is a group of the body's {}D cells",
                self.dim
            )
        } else if let Some(d) = self.other_groups.get(name) {
            let what = ["points", "curves", "surfaces"].get(*d).copied().unwrap_or("entities");
            format!(
                "; the file's `{name}` is a group of {what} (dimension {d}), which a {}D mesh does not use: \
                 a boundary group is one of {facets}, a region one of {}D cells",
                self.dim, self.dim
            )
        } else {
            String::new()
        }
    }
    /// The region `name`, or a [`MeshError::MissingRegion`] that lists what exists.
    pub fn region(&self, name: &str) -> Result<&[usize], MeshError> {
        self.regions
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| MeshError::MissingRegion {
                name: name.to_string(),
                available: join_keys(self.regions.keys()),
                elsewhere: self.group_elsewhere(name),
            })
    }
    /// The facets of group `name` all of whose nodes satisfy `keep(x)` (for example the part
    /// of the top face under an electrode), as a new group.
    pub fn select_facets(&self, name: &str, keep: impl Fn(&[f64]) -> bool) -> Result<FacetGroup, MeshError> {
        let g = self.boundary(name)?;
        let mut out = FacetGroup {
            nodes_per_facet: g.nodes_per_facet,
            facets: vec![],
        };
        for f in g.iter() {
            if f.iter().all(|&v| keep(self.point(v))) {
                out.facets.extend_from_slice(f);
            }
        }
        Ok(out)
    }

    /// Axis-aligned bounding box `(min, max)`.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
    /// The largest cell diameter (longest edge), the `h` of convergence studies.
    pub fn h_max(&self) -> f64 {
        let mut h: f64 = 0.0;
        for c in self.iter_cells() {
            for (a, &i) in c.iter().enumerate() {
                for &j in &c[a + 1..] {
                    h = h.max(dist(&self.points[i], &self.points[j]));
                }
            }
        }
        h
    }
    /// The nodes-by-nodes adjacency (sorted, including the diagonal), in compressed form:
    /// `(offsets, neighbours)`, node `i`'s neighbours at `neighbours[offsets[i]..offsets[i+1]]`.
    /// Two nodes are neighbours when a cell holds both.
    pub fn node_graph(&self) -> (Vec<usize>, Vec<usize>) {
        self.node_graph_where(|_| true)
    }

    /// Cells of each node, in compressed form `(offsets, cells)` (as [`Mesh::node_graph`]).
    pub fn node_cells(&self) -> (Vec<usize>, Vec<usize>) {
        let n = self.n_nodes();
        let mut count = vec![0usize; n + 1];
        for &v in &self.cells {
            count[v + 1] += 1;
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut node_cells = vec![0usize; self.cells.len()];
        for (c, cell) in self.iter_cells().enumerate() {
            for &v in cell {
                node_cells[fill[v]] = c;
                fill[v] += 1;
            }
        }
        (count, node_cells)
    }

    /// As [`Mesh::node_graph`], counting only the cells `c` with `keep(c)`; a node in no kept
    /// cell is its own only neighbour.
    pub fn node_graph_where(&self, keep: impl Fn(usize) -> bool + Sync) -> (Vec<usize>, Vec<usize>) {
        self.node_graph_from(&self.node_cells(), keep)
    }

    /// As [`Mesh::node_graph_where`], from the cells of each node already computed by
    /// [`Mesh::node_cells`] (so that several graphs share one pass over the cells). Blocks of
    /// nodes are gathered on rayon's pool, then joined in order.
    pub fn node_graph_from(
        &self,
        node_cells: &(Vec<usize>, Vec<usize>),
        keep: impl Fn(usize) -> bool + Sync,
    ) -> (Vec<usize>, Vec<usize>) {
        /// Nodes gathered by one task.
        const BLOCK: usize = 4096;
        let n = self.n_nodes();
        let k = self.kind.n_nodes();
        let (count, node_cells) = (&node_cells.0, &node_cells.1);
        // each block: the neighbour count of each of its nodes, and the neighbours in order
        let blocks: Vec<(Vec<usize>, Vec<usize>)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let nodes = b * BLOCK..((b + 1) * BLOCK).min(n);
                let mut lens = Vec::with_capacity(nodes.len());
                let mut nbrs = Vec::with_capacity(nodes.len() * 8);
                let mut scratch = Vec::with_capacity(64);
                for i in nodes {
                    scratch.clear();
                    for &c in node_cells[count[i]..count[i + 1]].iter().filter(|&&c| keep(c)) {
                        scratch.extend_from_slice(&self.cells[c * k..(c + 1) * k]);
                    }
                    if scratch.is_empty() {
                        scratch.push(i);
                    }
                    scratch.sort_unstable();
                    scratch.dedup();
                    nbrs.extend_from_slice(&scratch);
                    lens.push(scratch.len());
                }
                (lens, nbrs)
            })
            .collect();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0);
        let mut nbrs = Vec::with_capacity(blocks.iter().map(|b| b.1.len()).sum());
        for (lens, block) in blocks {
            for len in lens {
                offsets.push(offsets[offsets.len() - 1] + len);
            }
            nbrs.extend_from_slice(&block);
        }
        (offsets, nbrs)
    }
}

fn join_keys<'a>(keys: impl Iterator<Item = &'a String>) -> String {
    let v: Vec<&str> = keys.map(String::as_str).collect();
    if v.is_empty() {
        "none".to_string()
    } else {
        v.join(", ")
    }
}

/// The Euclidean norm of `v`, scaled so that neither tiny nor huge entries underflow or
/// overflow in the squares.
pub fn scaled_norm(v: &[f64]) -> f64 {
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    scale * v.iter().map(|x| (x / scale) * (x / scale)).sum::<f64>().sqrt()
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}
