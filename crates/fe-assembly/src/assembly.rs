//! Global assembly of the blocks `A` (u-u), `G` (φ-u) and `B` (φ-φ) of docs/theory.md into sparse
//! patterns built from the mesh graph, and of the right-hand sides of the symmetric system
//!
//! ```text
//! K [u; φ] = [f; -q],   K = [[A, Gᵀ], [G, -B]]
//! ```
//!
//! Parallel assembly is node-owned: the columns of a node are contiguous (dofs are numbered
//! node by node), so each node's slice of the value array belongs to one task, which sums the
//! matching columns of the element matrices of the node's cells. No locks, no atomics, no
//! triplets. Serial assembly is the classic cell loop that scatters whole element matrices; both
//! give the same matrices (a test checks it).

use crate::kernels::{
    coupling_column, dielectric_column, elasticity_column, CellRule, LinearRule, QuadraticRule, SimplexGeometry,
};
use crate::InputError;
use crate::{AssemblyError, Constraint, Coordinates, Dof, DofMap, Material, Unheld};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use mesh::{CellKind, Mesh};
use rayon::prelude::*;

/// How to assemble: a visible choice, not a global setting.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Parallelism {
    /// One thread: a loop over cells scattering element matrices.
    Serial,
    /// Rayon's pool: node-owned columns, one task per chunk of nodes.
    #[default]
    Rayon,
}

/// The mesh with its materials and dofs: everything needed to assemble.
pub struct Discretization<'m> {
    /// The mesh.
    pub mesh: &'m Mesh,
    /// The materials, indexed by `cell_material`.
    pub materials: Vec<Material>,
    /// Material of each cell.
    pub cell_material: Vec<usize>,
    /// The dofs.
    pub dofs: DofMap,
    /// Geometry of each cell.
    pub geometry: Vec<SimplexGeometry>,
    /// Whether each cell's material is electric.
    pub cell_electric: Vec<bool>,
    /// Whether each cell is curved: a P2 cell with an edge node off its edge's midpoint,
    /// mapped through its nodes ([`crate::mapping`]; its `geometry` is its corners').
    pub curved: Vec<bool>,
    /// The body itself, or a body of revolution about the y axis meshed in its meridian plane
    /// (every integral carries `2π r`).
    pub coordinates: Coordinates,
}

/// The assembled blocks of the coupled system (free dofs only).
pub struct Blocks {
    /// Elasticity, `n_u x n_u`, SPD once enough displacements are prescribed.
    pub a: SparseColMat<usize, f64>,
    /// Coupling, `n_phi x n_u`: `G_{ψ,u} = ∫ (e ε(u)) · ∇ψ`.
    pub g: SparseColMat<usize, f64>,
    /// Dielectric, `n_phi x n_phi`, SPD once a potential is prescribed.
    pub b: SparseColMat<usize, f64>,
}

impl<'m> Discretization<'m> {
    /// Sets up the discretisation: `materials` pairs a region name with its material; every
    /// cell must lie in exactly one of these regions. P1 and P2 simplices are supported (not
    /// quadrilaterals).
    /// [`Coordinates::Axisymmetric`] makes the 2D mesh the meridian section of a body of
    /// revolution about the y axis (every node at `x >= 0`), each material made for it
    /// ([`Material::from_crystal_axisymmetric`]); the caller holds the radial displacement of
    /// the nodes on the axis (`u_r = 0` there).
    pub fn new(
        mesh: &'m Mesh,
        coordinates: Coordinates,
        materials: &[(String, Material)],
        constraints: &[Constraint],
    ) -> Result<Self, AssemblyError> {
        if !matches!(
            mesh.kind,
            CellKind::Tri3 | CellKind::Tet4 | CellKind::Tri6 | CellKind::Tet10
        ) {
            return Err(InputError::CellKind { kind: mesh.kind.name() }.into());
        }
        let axisymmetric = coordinates == Coordinates::Axisymmetric;
        if axisymmetric && mesh.dim != 2 {
            return Err(InputError::AxisymmetricDimension { dim: mesh.dim }.into());
        }
        let n_cells = mesh.n_cells();
        let cell_material = cell_materials(mesh, materials)?;
        if let Some((region, m)) = materials.iter().find(|(_, m)| m.coordinates() != coordinates) {
            return Err(InputError::MaterialCoordinates {
                region: region.clone(),
                material: m.coordinates(),
                body: coordinates,
            }
            .into());
        }
        if axisymmetric {
            if let Some(node) = mesh.points.iter().position(|x| !(x[0] >= 0.0)) {
                return Err(InputError::NegativeRadius {
                    node,
                    at: mesh.points[node][..2].to_vec(),
                }
                .into());
            }
        }
        let k = mesh.kind.n_nodes();
        let geometry: Vec<SimplexGeometry> = (0..n_cells)
            .into_par_iter()
            .map(|c| {
                let x: Vec<[f64; 3]> = mesh.cells[c * k..(c + 1) * k].iter().map(|&v| mesh.points[v]).collect();
                if axisymmetric {
                    SimplexGeometry::axisymmetric(&x)
                } else {
                    SimplexGeometry::new(mesh.dim, &x)
                }
            })
            .collect();
        if let Some(c) = geometry.iter().position(|g| !(g.measure > 0.0)) {
            return Err(AssemblyError::Mesh(mesh::MeshError::BadCell {
                cell: c,
                what: "degenerate or inverted",
                measure_name: "measure",
                measure: geometry[c].measure,
                nodes: mesh.cell(c).to_vec(),
            }));
        }
        let curved = mesh.curved_cells();
        if let Some((c, at)) = (0..n_cells)
            .filter(|&c| curved[c])
            .find_map(|c| folded(mesh, c).map(|at| (c, at)))
        {
            return Err(AssemblyError::Mesh(mesh::MeshError::BadCell {
                cell: c,
                what: "folded (a curved cell whose map turns inside out: its edge nodes too far off their edges)",
                measure_name: "Jacobian determinant (times dim!) at one of its nodes or points",
                measure: at,
                nodes: mesh.cell(c).to_vec(),
            }));
        }
        let cell_electric: Vec<bool> = cell_material.iter().map(|&m| materials[m].1.electric).collect();
        let mut has_phi = vec![false; mesh.n_nodes()];
        for (c, cell) in mesh.iter_cells().enumerate() {
            if cell_electric[c] {
                for &v in cell {
                    has_phi[v] = true;
                }
            }
        }
        let dofs = DofMap::new(mesh, &has_phi, constraints)?;
        Ok(Discretization {
            mesh,
            materials: materials.iter().map(|(_, m)| m.clone()).collect(),
            cell_material,
            dofs,
            geometry,
            cell_electric,
            curved,
            coordinates,
        })
    }

    /// Checks that the Dirichlet conditions hold every rigid motion and every potential of
    /// each connected part of the mesh ([`crate::held::check`]): `K` is invertible only then.
    pub fn check_held(&self) -> Result<(), Unheld> {
        crate::held::check(self.mesh, &self.dofs, &self.cell_electric, self.coordinates)
    }

    /// [`Discretization::check_held`], counting `supports` (a compliant bed's points along
    /// its normal) where the Dirichlet conditions alone leave a motion free
    /// ([`crate::held::check_with`]).
    pub fn check_held_with(&self, supports: &[crate::Support]) -> Result<crate::Held, Unheld> {
        crate::held::check_with(self.mesh, &self.dofs, &self.cell_electric, self.coordinates, supports)
    }

    /// The material of cell `c`.
    pub fn material(&self, c: usize) -> &Material {
        &self.materials[self.cell_material[c]]
    }

    /// The quadrature of cell `c` ([`crate::kernels::Rule::of`]; a curved cell's,
    /// [`Discretization::quadratic_rule`]).
    pub fn rule(&self, c: usize) -> crate::kernels::Rule<'_> {
        if self.curved[c] {
            return crate::kernels::Rule::Quadratic(Box::new(self.quadratic_rule(c)));
        }
        crate::kernels::Rule::of(self.mesh.dim, self.mesh.kind.order(), &self.geometry[c])
    }

    /// The assembly's quadrature of the P2 cell `c`: [`QuadraticRule::new`] on a straight-sided
    /// cell; on a curved one its map's ([`QuadraticRule::mapped`]) at the points of
    /// [`crate::kernels::curved_rule`].
    pub fn quadratic_rule(&self, c: usize) -> QuadraticRule {
        let dim = self.mesh.dim;
        if !self.curved[c] {
            return QuadraticRule::new(dim, &self.geometry[c]);
        }
        let (weights, points) = crate::kernels::curved_rule(dim);
        self.quadratic_rule_at(c, points, weights, true)
    }

    /// The P2 shape functions of cell `c` at `points` (barycentric) standing for `weights` of
    /// its measure: [`QuadraticRule::at`], or a curved cell's [`QuadraticRule::mapped`]; with
    /// `ring` false, without a body of revolution's `2π r` and hoop values (as a plane cell).
    pub fn quadratic_rule_at(&self, c: usize, points: &[[f64; 4]], weights: &[f64], ring: bool) -> QuadraticRule {
        let dim = self.mesh.dim;
        let axisymmetric = ring && self.coordinates == Coordinates::Axisymmetric;
        if self.curved[c] {
            let x: Vec<[f64; 3]> = self.mesh.cell(c).iter().map(|&v| self.mesh.points[v]).collect();
            return QuadraticRule::mapped(dim, &x, points, weights, axisymmetric);
        }
        let g = self.geometry[c];
        let g = if axisymmetric {
            g
        } else {
            SimplexGeometry { radii: None, ..g }
        };
        QuadraticRule::at(dim, &g, points, weights)
    }

    /// The point of cell `c` at the barycentric coordinates `l` and the measure a unit of
    /// reference weight stands for there (the cell's measure where it is straight; `|det J| /
    /// dim!` of a curved cell's map), without a body of revolution's `2π r`.
    pub(crate) fn cell_point(&self, c: usize, l: &[f64; 4]) -> ([f64; 3], f64) {
        let (mesh, dim) = (self.mesh, self.mesh.dim);
        let cell = mesh.cell(c);
        if !self.curved[c] {
            return (self.point_at(&cell[..=dim], l), self.geometry[c].measure);
        }
        let x: Vec<[f64; 3]> = cell.iter().map(|&v| mesh.points[v]).collect();
        let (at, jac) = crate::mapping::map_at(dim, &x, l);
        (at, crate::mapping::measure_at(dim, &jac))
    }

    /// The one-point rule at the centroid of cell `c` ([`crate::kernels::Rule::centroid`]).
    /// On a curved cell, its map's value there (the weight the map's measure there).
    pub fn centroid_rule(&self, c: usize) -> crate::kernels::Rule<'_> {
        let dim = self.mesh.dim;
        if self.curved[c] {
            let third = 1.0 / (dim + 1) as f64;
            let l = [third, third, third, if dim == 3 { third } else { 0.0 }];
            return crate::kernels::Rule::Quadratic(Box::new(self.quadratic_rule_at(c, &[l], &[1.0], true)));
        }
        crate::kernels::Rule::centroid(dim, self.mesh.kind.order(), &self.geometry[c])
    }

    /// Assembles `A`, `G` and `B`. A floating terminal's rows and columns are its nodes'
    /// summed (assembled on the untied map, [`DofMap::untied`], then folded).
    pub fn assemble(&self, par: Parallelism) -> Blocks {
        let mesh = self.mesh;
        let untied = self.dofs.untied();
        let d = untied.as_ref().map_or(&self.dofs, |(m, _)| m);
        let node_cells = mesh.node_cells();
        let graph_all = mesh.node_graph_from(&node_cells, |_| true);
        // the electric cells' graph is the whole graph when every cell is electric
        let graph_el_owned;
        let graph_el = if self.cell_electric.iter().all(|&e| e) {
            &graph_all
        } else {
            graph_el_owned = mesh.node_graph_from(&node_cells, |c| self.cell_electric[c]);
            &graph_el_owned
        };
        // the three patterns are independent: build them side by side
        let (a, (g, b)) = rayon::join(
            || Pattern::new(&graph_all, &ColDofs::U(d), &ColDofs::U(d)),
            || {
                rayon::join(
                    || Pattern::new(graph_el, &ColDofs::Phi(d), &ColDofs::U(d)),
                    || Pattern::new(graph_el, &ColDofs::Phi(d), &ColDofs::Phi(d)),
                )
            },
        );
        let (mut av, mut gv, mut bv) = (a.zeros(), g.zeros(), b.zeros());
        let (patterns, values) = ([&a, &g, &b], [&mut av[..], &mut gv[..], &mut bv[..]]);
        let dim = mesh.dim;
        match (par, mesh.kind.order()) {
            (Parallelism::Rayon, 2) => {
                self.assemble_node_owned::<{ crate::kernels::MAX_NODES }, _>(d, &node_cells, (patterns, values), |c| {
                    self.quadratic_rule(c)
                })
            }
            (Parallelism::Rayon, _) => self.assemble_node_owned::<4, _>(d, &node_cells, (patterns, values), |c| {
                LinearRule::new(dim, &self.geometry[c])
            }),
            (Parallelism::Serial, 2) => {
                self.assemble_cell_loop::<{ crate::kernels::MAX_NODES }, _>(d, (patterns, values), |c| {
                    self.quadratic_rule(c)
                })
            }
            (Parallelism::Serial, _) => {
                self.assemble_cell_loop::<4, _>(d, (patterns, values), |c| LinearRule::new(dim, &self.geometry[c]))
            }
        }
        let (g, b) = (g.into_matrix(gv), b.into_matrix(bv));
        let (g, b) = match &untied {
            Some((_, fold)) => {
                let (n, to) = (self.dofs.n_phi, |j: usize| fold[j]);
                (fold_rows(&g, n, &to), fold_cols(&fold_rows(&b, n, &to), n, &to))
            }
            None => (g, b),
        };
        Blocks {
            a: a.into_matrix(av),
            g,
            b,
        }
    }

    /// The blocks' values (`[A, G, B]` on their patterns), each node's columns filled by
    /// one task from the cells around it; `rule` gives a cell's quadrature (`N` at least its
    /// nodes).
    fn assemble_node_owned<'s, const N: usize, R: CellRule>(
        &'s self,
        d: &DofMap,
        node_cells: &(Vec<usize>, Vec<usize>),
        ([pa, pg, pb], [av, gv, bv]): ([&Pattern; 3], [&mut [f64]; 3]),
        rule: impl Fn(usize) -> R + Sync + 's,
    ) {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let (off, node_cells) = (&node_cells.0, &node_cells.1);
        // per node: its slice of each block's values (its columns are contiguous)
        let n_nodes = mesh.n_nodes();
        let a_slices = pa.split_by_node(av, n_nodes, |i| u_cols(d, i));
        let g_slices = pg.split_by_node(gv, n_nodes, |i| u_cols(d, i));
        let b_slices = pb.split_by_node(bv, n_nodes, |i| phi_cols(d, i));
        a_slices
            .into_par_iter()
            .zip(g_slices)
            .zip(b_slices)
            .enumerate()
            .with_min_len(256)
            .for_each(|(i, ((mut a_node, mut g_node), mut b_node))| {
                // the node's values written before they are added to: fresh pages read first
                // fault twice, the second time with an interrupt to every other core
                // (docs/performance.md, "The zero page")
                for values in [&mut a_node.1, &mut g_node.1, &mut b_node.1] {
                    values.fill(0.0);
                }
                let (ucols, nq) = free_components(d, i, dim);
                let ucols = &ucols[..nq];
                let (first_u, _) = u_cols(d, i);
                let a_rows = if nq > 0 { pa.rows_of(first_u) } else { &[][..] };
                let g_rows = if nq > 0 { pg.rows_of(first_u) } else { &[][..] };
                let phi_col = match d.phi[i] {
                    Dof::Free(j) => Some(j),
                    _ => None,
                };
                let b_rows = phi_col.map_or(&[][..], |j| pb.rows_of(j));
                let (la, lg) = (a_rows.len(), g_rows.len());
                for &c in &node_cells[off[i]..off[i + 1]] {
                    let cell = mesh.cell(c);
                    let a_loc = cell.iter().position(|&v| v == i).unwrap_or(0);
                    let (m, r) = (self.material(c), rule(c));
                    let electric = self.cell_electric[c];
                    let mut colv = [[[0.0; 3]; N]; 3];
                    let mut colg = [[0.0; N]; 3];
                    for &(k, q) in ucols {
                        colv[q] = elasticity_column(m, &r, a_loc, k);
                        if electric {
                            colg[q] = coupling_column(m, &r, a_loc, k);
                        }
                    }
                    let colb: Option<[f64; N]> = match (electric, phi_col) {
                        (true, Some(_)) => Some(dielectric_column(m, &r, a_loc)),
                        _ => None,
                    };
                    for (b, &vb) in cell.iter().enumerate() {
                        // u rows of node vb: contiguous in every column of node i
                        if nq > 0 {
                            let (first_row, count) = u_cols(d, vb);
                            if count > 0 {
                                let pos = position(a_rows, first_row);
                                let mut o = 0;
                                for l in 0..dim {
                                    if let Dof::Free(_) = d.u[vb * dim + l] {
                                        for &(_, q) in ucols {
                                            a_node.1[q * la + pos + o] += colv[q][b][l];
                                        }
                                        o += 1;
                                    }
                                }
                            }
                        }
                        if !electric {
                            continue;
                        }
                        if let Dof::Free(row) = d.phi[vb] {
                            if nq > 0 {
                                let pos = position(g_rows, row);
                                for &(_, q) in ucols {
                                    g_node.1[q * lg + pos] += colg[q][b];
                                }
                            }
                            if let Some(colb) = &colb {
                                let pos = position(b_rows, row);
                                b_node.1[pos] += colb[b];
                            }
                        }
                    }
                }
            });
    }

    /// The blocks' values (`[A, G, B]` on their patterns), cell after cell; `rule` gives a
    /// cell's quadrature (`N` at least its nodes).
    fn assemble_cell_loop<const N: usize, R: CellRule>(
        &self,
        d: &DofMap,
        ([pa, pg, pb], [av, gv, bv]): ([&Pattern; 3], [&mut [f64]; 3]),
        rule: impl Fn(usize) -> R,
    ) {
        let mesh = self.mesh;
        let dim = mesh.dim;
        for (c, cell) in mesh.iter_cells().enumerate() {
            let (m, r) = (self.material(c), rule(c));
            for (a, &va) in cell.iter().enumerate() {
                for k in 0..dim {
                    let Dof::Free(col) = d.u[va * dim + k] else {
                        continue;
                    };
                    let colv: [[f64; 3]; N] = elasticity_column(m, &r, a, k);
                    let colg: [f64; N] = coupling_column(m, &r, a, k);
                    for (b, &vb) in cell.iter().enumerate() {
                        for l in 0..dim {
                            if let Dof::Free(row) = d.u[vb * dim + l] {
                                av[pa.position(row, col)] += colv[b][l];
                            }
                        }
                        if self.cell_electric[c] {
                            if let Dof::Free(row) = d.phi[vb] {
                                gv[pg.position(row, col)] += colg[b];
                            }
                        }
                    }
                }
                if !self.cell_electric[c] {
                    continue;
                }
                let Dof::Free(col) = d.phi[va] else { continue };
                let colb: [f64; N] = dielectric_column(m, &r, a);
                for (b, &vb) in cell.iter().enumerate() {
                    if let Dof::Free(row) = d.phi[vb] {
                        bv[pb.position(row, col)] += colb[b];
                    }
                }
            }
        }
    }
}

/// The free u columns of node `i`: (component `k`, column offset `q` within the node), the
/// first `nq` of the array.
fn free_components(d: &DofMap, i: usize, dim: usize) -> ([(usize, usize); 3], usize) {
    let mut ucols = [(0usize, 0usize); 3];
    let mut nq = 0;
    for k in 0..dim {
        if let Dof::Free(_) = d.u[i * dim + k] {
            ucols[nq] = (k, nq);
            nq += 1;
        }
    }
    (ucols, nq)
}

/// Index of `row` in the sorted `rows` (present by construction of the pattern).
fn position(rows: &[usize], row: usize) -> usize {
    rows.binary_search(&row)
        .unwrap_or_else(|_| unreachable!("row {row} not in the pattern"))
}

/// The free column dofs of node `i` in the u field: `(first, count)`.
fn u_cols(d: &DofMap, i: usize) -> (usize, usize) {
    let mut first = None;
    let mut count = 0;
    for k in 0..d.dim {
        if let Dof::Free(j) = d.u[i * d.dim + k] {
            first.get_or_insert(j);
            count += 1;
        }
    }
    (first.unwrap_or(0), count)
}

fn phi_cols(d: &DofMap, i: usize) -> (usize, usize) {
    match d.phi[i] {
        Dof::Free(j) => (j, 1),
        _ => (0, 0),
    }
}

/// Which field's free dofs index the rows or columns of a block.
enum ColDofs<'a> {
    U(&'a DofMap),
    Phi(&'a DofMap),
}

impl ColDofs<'_> {
    fn n(&self) -> usize {
        match self {
            ColDofs::U(d) => d.n_u,
            ColDofs::Phi(d) => d.n_phi,
        }
    }
    fn free_of(&self, node: usize, out: &mut Vec<usize>) {
        match self {
            ColDofs::U(d) => {
                for k in 0..d.dim {
                    if let Dof::Free(j) = d.u[node * d.dim + k] {
                        out.push(j);
                    }
                }
            }
            ColDofs::Phi(d) => {
                if let Dof::Free(j) = d.phi[node] {
                    out.push(j);
                }
            }
        }
    }
}

/// `m` with its row `i` moved to row `to(i)` (rows that meet summed), `nrows` rows.
fn fold_rows(m: &SparseColMat<usize, f64>, nrows: usize, to: &dyn Fn(usize) -> usize) -> SparseColMat<usize, f64> {
    let (mut col_ptr, mut row_idx, mut values) = (vec![0], vec![], vec![]);
    let mut entries: Vec<(usize, f64)> = vec![];
    for j in 0..m.ncols() {
        entries.clear();
        entries.extend(m.row_idx_of_col(j).zip(m.val_of_col(j)).map(|(i, &v)| (to(i), v)));
        push_merged(&mut entries, &mut row_idx, &mut values);
        col_ptr.push(row_idx.len());
    }
    let sym = SymbolicSparseColMat::new_checked(nrows, m.ncols(), col_ptr, None, row_idx);
    SparseColMat::new(sym, values)
}

/// `m` with its column `j` moved to column `to(j)` (columns that meet summed), `ncols`
/// columns.
fn fold_cols(m: &SparseColMat<usize, f64>, ncols: usize, to: &dyn Fn(usize) -> usize) -> SparseColMat<usize, f64> {
    let mut sources: Vec<Vec<usize>> = vec![vec![]; ncols];
    for j in 0..m.ncols() {
        sources[to(j)].push(j);
    }
    let (mut col_ptr, mut row_idx, mut values) = (vec![0], vec![], vec![]);
    let mut entries: Vec<(usize, f64)> = vec![];
    for from in &sources {
        entries.clear();
        for &j in from {
            entries.extend(m.row_idx_of_col(j).zip(m.val_of_col(j)).map(|(i, &v)| (i, v)));
        }
        push_merged(&mut entries, &mut row_idx, &mut values);
        col_ptr.push(row_idx.len());
    }
    let sym = SymbolicSparseColMat::new_checked(m.nrows(), ncols, col_ptr, None, row_idx);
    SparseColMat::new(sym, values)
}

/// One column's `(row, value)` entries, sorted by row with equal rows summed, appended.
fn push_merged(entries: &mut [(usize, f64)], row_idx: &mut Vec<usize>, values: &mut Vec<f64>) {
    entries.sort_unstable_by_key(|e| e.0);
    let start = row_idx.len();
    for &(i, v) in entries.iter() {
        if row_idx.len() > start && row_idx.last() == Some(&i) {
            *values.last_mut().expect("an entry was pushed") += v;
        } else {
            row_idx.push(i);
            values.push(v);
        }
    }
}

/// A compressed-column pattern with sorted rows.
struct Pattern {
    nrows: usize,
    ncols: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl Pattern {
    /// Rows of column (node i, dof) = the free row dofs of i's neighbours in `graph`.
    fn new(graph: &(Vec<usize>, Vec<usize>), rows: &ColDofs<'_>, cols: &ColDofs<'_>) -> Pattern {
        let (off, nbr) = graph;
        let n_nodes = off.len() - 1;
        let mut col_ptr = Vec::with_capacity(cols.n() + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        let (mut rbuf, mut cbuf) = (Vec::new(), Vec::new());
        for i in 0..n_nodes {
            cbuf.clear();
            cols.free_of(i, &mut cbuf);
            if cbuf.is_empty() {
                continue;
            }
            rbuf.clear();
            for &m in &nbr[off[i]..off[i + 1]] {
                rows.free_of(m, &mut rbuf);
            }
            for _ in &cbuf {
                row_idx.extend_from_slice(&rbuf);
                col_ptr.push(row_idx.len());
            }
        }
        debug_assert_eq!(col_ptr.len(), cols.n() + 1);
        Pattern {
            nrows: rows.n(),
            ncols: cols.n(),
            col_ptr,
            row_idx,
        }
    }

    /// The row indices of column `col`.
    fn rows_of(&self, col: usize) -> &[usize] {
        &self.row_idx[self.col_ptr[col]..self.col_ptr[col + 1]]
    }

    fn zeros(&self) -> Vec<f64> {
        vec![0.0; self.row_idx.len()]
    }

    /// Index into the values of entry `(row, col)`; the pattern holds it by construction.
    fn position(&self, row: usize, col: usize) -> usize {
        let (s, e) = (self.col_ptr[col], self.col_ptr[col + 1]);
        s + self.row_idx[s..e]
            .binary_search(&row)
            .unwrap_or_else(|_| unreachable!("({row}, {col}) not in pattern"))
    }

    /// Splits `values` into one slice per node, holding that node's columns `cols(i)`.
    /// Each slice is returned with the value index it starts at.
    fn split_by_node<'v>(
        &self,
        values: &'v mut [f64],
        n_nodes: usize,
        cols: impl Fn(usize) -> (usize, usize),
    ) -> Vec<(usize, &'v mut [f64])> {
        let mut out = Vec::with_capacity(n_nodes);
        let mut rest = values;
        let mut at = 0;
        for i in 0..n_nodes {
            let (first, count) = cols(i);
            let end = if count == 0 { at } else { self.col_ptr[first + count] };
            let (head, tail) = rest.split_at_mut(end - at);
            out.push((at, head));
            rest = tail;
            at = end;
        }
        out
    }

    fn into_matrix(self, values: Vec<f64>) -> SparseColMat<usize, f64> {
        let sym = SymbolicSparseColMat::new_checked(self.nrows, self.ncols, self.col_ptr, None, self.row_idx);
        SparseColMat::new(sym, values)
    }
}

/// The material of each cell: the index in `materials` of the one region holding it.
///
/// # Errors
/// A material of another dimension than the mesh's, a region the mesh lacks, a cell in two
/// materials' regions or in none ([`InputError`]).
pub fn cell_materials(mesh: &Mesh, materials: &[(String, Material)]) -> Result<Vec<usize>, AssemblyError> {
    let mut cell_material = vec![usize::MAX; mesh.n_cells()];
    for (mi, (region, m)) in materials.iter().enumerate() {
        if m.dim != mesh.dim {
            return Err(InputError::MaterialDimension {
                region: region.clone(),
                material: m.dim,
                mesh: mesh.dim,
            }
            .into());
        }
        for &c in mesh.region(region)? {
            if cell_material[c] != usize::MAX {
                return Err(InputError::TwoMaterials {
                    cell: c,
                    first: region.clone(),
                    second: materials[cell_material[c]].0.clone(),
                }
                .into());
            }
            cell_material[c] = mi;
        }
    }
    let bare: Vec<usize> = (0..mesh.n_cells())
        .filter(|&c| cell_material[c] == usize::MAX)
        .collect();
    if let Some(&c) = bare.first() {
        // the mesh's regions made of them alone (one that holds others too, as a generated
        // mesh's `body`, could not take a material of its own)
        let theirs = (mesh.regions.iter())
            .filter(|(_, cells)| !cells.is_empty() && cells.iter().all(|&k| cell_material.get(k) == Some(&usize::MAX)))
            .map(|(name, _)| name.clone())
            .collect();
        return Err(InputError::NoMaterial {
            cell: c,
            cells: bare.len(),
            theirs,
            regions: materials.iter().map(|(r, _)| r.clone()).collect(),
        }
        .into());
    }
    Ok(cell_material)
}

/// Where the map of the curved P2 cell `c` folds: its Jacobian determinant (times `dim!`, the
/// straight cell's measure scale) at the first of its nodes and rule points (the loads', the
/// assembly's) where it is not positive; `None` where it is positive at all of them.
fn folded(mesh: &Mesh, c: usize) -> Option<f64> {
    let dim = mesh.dim;
    let x: Vec<[f64; 3]> = mesh.cell(c).iter().map(|&v| mesh.points[v]).collect();
    let mut at = crate::kernels::simplex_nodes(dim);
    // every point a curved cell is integrated at: the loads' and norms' rule, the assembly's
    at.extend_from_slice(crate::kernels::simplex_rule(dim, 2).1);
    at.extend_from_slice(crate::kernels::curved_rule(dim).1);
    at.iter()
        .map(|l| crate::mapping::jacobian_det(dim, &crate::mapping::map_at(dim, &x, l).1))
        .find(|det| !(*det > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell no material's region holds is named with the mesh's regions it lies in (a Gmsh
    /// group whose name went missing is its tag: the message said only "regions given: body").
    #[test]
    fn cells_without_a_material_name_the_regions_they_lie_in() {
        let mut mesh = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2);
        let n = mesh.n_cells();
        mesh.regions.insert("body".into(), (0..n / 2).collect());
        mesh.regions.insert("6".into(), (n / 2..n).collect());
        let m = Material::from_crystal("iso", &crate::Crystal::isotropic(100.0, 0.3, 1.0), [0.0, 0.0, 1.0], 2).unwrap();
        let e = cell_materials(&mesh, &[("body".into(), m.clone())])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("{} cells lie in no region a material names", n - n / 2))
                && e.contains("the mesh's region `6`"),
            "{e}"
        );
        mesh.regions.remove("6");
        let e = cell_materials(&mesh, &[("body".into(), m.clone())])
            .unwrap_err()
            .to_string();
        assert!(e.contains("they lie in no region of their own"), "{e}");
        // a region that holds covered cells too (a generated mesh's `all`) is not offered
        mesh.regions.insert("all".into(), (0..n).collect());
        let e = cell_materials(&mesh, &[("body".into(), m)]).unwrap_err().to_string();
        assert!(
            e.contains("they lie in no region of their own") && !e.contains("`all`"),
            "{e}"
        );
    }
}
