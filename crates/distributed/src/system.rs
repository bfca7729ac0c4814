//! The coupled system on the ranks: each rank's cells assembled into a parallel matrix, the
//! loads into a parallel vector, prescribed unknowns eliminated.
//!
//! ```text
//! [[A, Gᵀ], [-G, B]] [u; φ] = [b_u; -b_φ]
//! ```
//!
//! is docs/theory.md's `K [u; φ] = [b_u; b_φ]`, `K = [[A, Gᵀ], [G, -B]]`, with the potential's rows
//! negated: the same solution, and a Schur complement of the potentials, `B + G A⁻¹ Gᵀ`, that
//! is positive definite, as algebraic multigrid wants. The element matrices are those of
//! `fe_assembly::kernels` (one column at a time), the loads those of
//! [`fe_assembly::Discretization::rhs`] (with the prescribed values already lifted).

use crate::layout::Layout;
use fe_assembly::kernels::{coupling_column, dielectric_column, elasticity_column, MAX_NODES};
use fe_assembly::{Discretization, Dof};
use petsc::{Index, Matrix, Petsc, PetscError, Vector};

/// The assembled system of this rank's rows.
pub struct System<'p> {
    /// The matrix, prescribed rows and columns eliminated.
    pub matrix: Matrix<'p>,
    /// The right-hand side (prescribed rows: the diagonal times the value).
    pub rhs: Vector<'p>,
    /// The norm of the loads (`|(b_u, b_φ)|` over the free unknowns), the scale of the
    /// equilibrium residual.
    pub load_norm: f64,
    /// The mean diagonal entries of `A` and of `B`: the diagonal of an eliminated row of each
    /// field, and the stiffness scale of the contact iteration.
    pub diagonal: [f64; 2],
}

impl<'p> System<'p> {
    /// The right-hand side of other loads on the same matrix: `b_u`, `b_phi` over the free
    /// unknowns (prescribed values already lifted), the prescribed rows the diagonal times
    /// `disc`'s values (a load path's instant: its parts summed, its prescribed values
    /// scaled); `charges` those on the floating terminals ([`assemble`]). Collective.
    pub fn set_loads(
        &mut self,
        petsc: &'p Petsc,
        disc: &Discretization<'_>,
        layout: &Layout,
        (b_u, b_phi, charges): (&[f64], &[f64], &[f64]),
    ) -> Result<(), PetscError> {
        let rows = Rows::of(petsc, disc, layout, (b_u, b_phi, charges), self.diagonal)?;
        (self.rhs, self.load_norm) = (rows.rhs, rows.load_norm);
        Ok(())
    }

    /// `K x - b`: the forces that balance the loads at `x` (at a contact point, the contact
    /// force on the body; elsewhere the equilibrium residual). Collective.
    pub fn reactions(&self, x: &Vector<'p>) -> Result<Vector<'p>, PetscError> {
        let mut r = self.rhs.duplicate()?;
        self.matrix.mult(x, &mut r)?;
        r.axpy(-1.0, &self.rhs)?;
        Ok(r)
    }
}

/// Assembles this rank's cells and rows. `b_u`, `b_phi` are the loads over the free unknowns
/// (as `Discretization::rhs` gives them, on a piece: its nodes' own), `charges` the charge put
/// on each floating terminal of the layout (given once for the whole run, not in `b_phi`).
/// Collective.
pub fn assemble<'p>(
    petsc: &'p Petsc,
    disc: &Discretization<'_>,
    layout: &Layout,
    (b_u, b_phi, charges): (&[f64], &[f64], &[f64]),
) -> Result<System<'p>, PetscError> {
    let rank = petsc.rank();
    let mut matrix = preallocated(petsc, disc, layout)?;
    let mut diagonal = [0.0, 0.0]; // sums of A's and B's diagonal entries over this rank's cells
    let mut counts = [0.0, 0.0];
    let mesh = disc.mesh;
    for c in (0..mesh.n_cells()).filter(|&c| layout.cell_rank[c] == rank) {
        let (rows, ke) = element(disc, layout, c);
        let ne = rows.len();
        let nu = layout.dim * mesh.cell(c).len();
        for i in 0..ne {
            let which = usize::from(i >= nu);
            diagonal[which] += ke[i * ne + i];
            counts[which] += 1.0;
        }
        matrix.add_values(&rows, &rows, &ke)?;
    }
    matrix.assemble()?;
    // the mean diagonal entries of A and B: the scale of an eliminated row's diagonal, so that
    // elimination leaves the conditioning as it was
    let sums = petsc.sum(&[diagonal[0], diagonal[1], counts[0], counts[1]])?;
    let scale = [
        if sums[2] > 0.0 { sums[0] / sums[2] } else { 1.0 },
        if sums[3] > 0.0 { sums[1] / sums[3] } else { 1.0 },
    ];
    let rows = Rows::of(petsc, disc, layout, (b_u, b_phi, charges), scale)?;
    eliminate(petsc, &mut matrix, layout, [&rows.fixed_u, &rows.fixed_phi], scale)?;
    let (rhs, load_norm) = (rows.rhs, rows.load_norm);
    Ok(System {
        matrix,
        rhs,
        load_norm,
        diagonal: scale,
    })
}

/// This rank's rows of the right-hand side, and its prescribed rows.
struct Rows<'p> {
    rhs: Vector<'p>,
    load_norm: f64,
    fixed_u: Vec<Index>,
    fixed_phi: Vec<Index>,
}

impl<'p> Rows<'p> {
    /// The loads `b_u`, `b_phi` at this rank's free rows (the potential's negated), the
    /// prescribed rows `scale` (the field's diagonal) times their values; a floating terminal's
    /// row the sum of its nodes' `b_φ` over the ranks, less the charge put on it (docs/theory.md,
    /// "Floating terminals on pieces"). Collective.
    fn of(
        petsc: &'p Petsc,
        disc: &Discretization<'_>,
        layout: &Layout,
        (b_u, b_phi, charges): (&[f64], &[f64], &[f64]),
        scale: [f64; 2],
    ) -> Result<Self, PetscError> {
        let rank = petsc.rank();
        let owned = layout.owned(rank);
        let d = &disc.dofs;
        let (mut fixed_u, mut fixed_phi): (Vec<Index>, Vec<Index>) = (vec![], vec![]);
        let mut values = vec![0.0; owned.len()];
        let mut load_sq = 0.0;
        // each terminal's b_φ: its nodes' (free, untied) summed, the charge subtracted once
        let mut terminal = vec![0.0; layout.terminals];
        for v in layout.owned_nodes(rank) {
            let f = layout.first[v];
            for k in 0..layout.dim {
                values[f + k - owned.start] = match d.u[v * layout.dim + k] {
                    Dof::Free(j) => {
                        load_sq += b_u[j] * b_u[j];
                        b_u[j]
                    }
                    Dof::Fixed(x) => {
                        fixed_u.push(Layout::index(f + k));
                        scale[0] * x
                    }
                    Dof::Absent => 0.0,
                };
            }
            if let (Some(t), Dof::Free(j)) = (layout.tie[v], d.phi[v]) {
                terminal[t] += b_phi[j];
                continue;
            }
            if layout.has_phi[v] {
                let row = f + layout.dim;
                values[row - owned.start] = match d.phi[v] {
                    Dof::Free(j) => {
                        load_sq += b_phi[j] * b_phi[j];
                        -b_phi[j]
                    }
                    Dof::Fixed(x) => {
                        fixed_phi.push(Layout::index(row));
                        scale[1] * x
                    }
                    Dof::Absent => 0.0,
                };
            }
        }
        if layout.terminals > 0 {
            let sums = petsc.sum(&terminal)?;
            if rank == layout.terminals_rank() {
                for (t, (b, q)) in sums.iter().zip(charges).enumerate() {
                    // (the flux out of the body is -Q: Discretization::rhs's rule)
                    let b = b - q;
                    load_sq += b * b;
                    values[layout.terminal_row(t) - owned.start] = -b;
                }
            }
        }
        let rhs = Vector::from_local(petsc, &values)?;
        let load_norm = petsc.sum(&[load_sq])?[0].sqrt();
        Ok(Rows {
            rhs,
            load_norm,
            fixed_u,
            fixed_phi,
        })
    }
}

/// Zeroes the prescribed rows and columns (`fixed`: the displacements', the potentials'),
/// with the mean diagonal of their field on the diagonal (the right-hand side is set by the
/// caller: lifted already, and the value times that diagonal on the prescribed rows).
/// `MatZeroRowsColumns` takes one diagonal value, so the two fields' rows are eliminated in two
/// collective calls.
fn eliminate(
    petsc: &Petsc,
    matrix: &mut Matrix<'_>,
    layout: &Layout,
    fixed: [&[Index]; 2],
    scale: [f64; 2],
) -> Result<(), PetscError> {
    let x = Vector::mpi(petsc, layout.owned(petsc.rank()).len())?;
    let mut b = x.duplicate()?;
    matrix.zero_rows_columns(fixed[0], scale[0], &x, &mut b)?;
    matrix.zero_rows_columns(fixed[1], scale[1], &x, &mut b)
}

/// The global rows of cell `c`'s unknowns and its element matrix (row-major), in the order
/// `u(a, k)` for each node `a` and component `k`, then `φ_a` where the cell is electric.
pub fn element(disc: &Discretization<'_>, layout: &Layout, c: usize) -> (Vec<Index>, Vec<f64>) {
    let cell = disc.mesh.cell(c);
    let (dim, nl) = (layout.dim, cell.len());
    let electric = disc.cell_electric[c];
    let nu = nl * dim;
    let ne = nu + if electric { nl } else { 0 };
    let mut rows = Vec::with_capacity(ne);
    for &v in cell {
        rows.extend((0..dim).map(|k| Layout::index(layout.first[v] + k)));
    }
    if electric {
        // every node of an electric cell carries a potential (the dof map's rule): its own or
        // its floating terminal's
        let row = |v: usize| layout.phi_row(v).expect("an electric cell's node carries a potential");
        rows.extend(cell.iter().map(|&v| Layout::index(row(v))));
    }
    let (m, r) = (disc.material(c), disc.rule(c));
    let mut ke = vec![0.0; ne * ne];
    for a in 0..nl {
        for k in 0..dim {
            let col = a * dim + k;
            let colv: [[f64; 3]; MAX_NODES] = elasticity_column(m, &r, a, k);
            for b in 0..nl {
                for l in 0..dim {
                    ke[(b * dim + l) * ne + col] = colv[b][l];
                }
            }
            if electric {
                let colg: [f64; MAX_NODES] = coupling_column(m, &r, a, k);
                for b in 0..nl {
                    // -G in the potential's (negated) rows, Gᵀ in the displacement's
                    ke[(nu + b) * ne + col] = -colg[b];
                    ke[col * ne + nu + b] = colg[b];
                }
            }
        }
        if electric {
            let colb: [f64; MAX_NODES] = dielectric_column(m, &r, a);
            for b in 0..nl {
                ke[(nu + b) * ne + nu + a] = colb[b];
            }
        }
    }
    (rows, ke)
}

/// The matrix with each owned row's entries counted: a row of node `v` holds the unknowns of
/// every node that shares a cell with `v`, split into those of this rank and the others'; a
/// floating terminal's row those of every node next to its group (each rank counts the
/// neighbours of the group's nodes it owns, and the counts are summed: a bound, where two
/// ranks count one neighbour). Collective.
fn preallocated<'p>(petsc: &'p Petsc, disc: &Discretization<'_>, layout: &Layout) -> Result<Matrix<'p>, PetscError> {
    let rank = petsc.rank();
    let owned = layout.owned(rank);
    let (off, adj) = disc.mesh.node_graph();
    let mut d_nnz = vec![0 as Index; owned.len()];
    let mut o_nnz = vec![0 as Index; owned.len()];
    let terminals_rank = layout.terminals_rank();
    // each terminal's row: its neighbours' unknowns on the terminals' rank, and on the others
    let mut terminal = vec![0.0; 2 * layout.terminals];
    for v in layout.owned_nodes(rank) {
        let (mut d, mut o) = (0, 0);
        for &w in &adj[off[v]..off[v + 1]] {
            let n = layout.node_dofs(w).len() as Index;
            if layout.node_rank[w] == rank {
                d += n;
            } else {
                o += n;
            }
            // a tied neighbour's potential: its terminal's column
            if layout.tie[w].is_some() {
                if rank == terminals_rank {
                    d += 1;
                } else {
                    o += 1;
                }
            }
            if let Some(t) = layout.tie[v] {
                terminal[2 * t + usize::from(layout.node_rank[w] != terminals_rank)] += n as f64;
            }
        }
        for r in layout.node_dofs(v) {
            d_nnz[r - owned.start] = d;
            o_nnz[r - owned.start] = o;
        }
    }
    if layout.terminals > 0 {
        let terminal = petsc.sum(&terminal)?;
        if rank == terminals_rank {
            let (mine, others) = (owned.len(), layout.n_global() - owned.len());
            for t in 0..layout.terminals {
                // (and every terminal's column: two terminals may share a cell)
                let d = (terminal[2 * t] as usize + layout.terminals).min(mine);
                let o = (terminal[2 * t + 1] as usize).min(others);
                let r = layout.terminal_row(t) - owned.start;
                (d_nnz[r], o_nnz[r]) = (d as Index, o as Index);
            }
        }
    }
    // without potentials every node has `dim` unknowns: blocks for the multigrid
    let bs = if layout.coupled { 1 } else { layout.dim };
    Matrix::aij_blocked(petsc, owned.len(), layout.n_global(), bs, &d_nnz, &o_nnz)
}
