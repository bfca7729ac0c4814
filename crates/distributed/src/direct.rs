//! The PETSc backend's direct route: `K` factored by MUMPS on the ranks, and the run's instants
//! ([`problem::Instants`]) on that factorisation, as the default backend's on its own.
//!
//! The matrix is docs/theory.md's `K = [[A, Gᵀ], [G, -B]]` over the free unknowns `[u; φ]`
//! (symmetric and indefinite: MUMPS' `L D Lᵀ`; `L Lᵀ` without potentials), each rank giving
//! the entries of its own cells (one triangle), MUMPS summing what two ranks give. A floating
//! terminal's potential is one unknown of the tied numbering, so its rows are summed there too.
//! Where the run has contact, the contact dofs are MUMPS' Schur unknowns: the Schur complement
//! `S` comes back whole on rank 0, `(K⁻¹)_cc = S⁻¹` is broadcast, and the contact solvers of
//! the default backend run on it unchanged on every rank (every law, path, indenter and
//! terminal reaches this backend without being written again). A solve is MUMPS' two halves
//! around `S⁻¹`: the loads condensed onto the contact dofs, the dense solve, the expansion.
//! The right-hand sides and solutions are whole on every rank (the mesh is, too).

use crate::free::{copy_into, joined, split};
use crate::layout::Layout;
use fe_assembly::kernels::{coupling_column, dielectric_column, elasticity_column, MAX_NODES};
use fe_assembly::{Discretization, Dof};
use linalg::{CondenseRoute, Condensed, CondensedLoads, CoupledSolver, Rhs};
use petsc::{Mumps, Petsc, PetscError, Symmetry};
use problem::backend::Fields;
use problem::{Factorization, ProblemError, Refinement};

/// `K` factored by MUMPS on the ranks, with `(K⁻¹)_cc` of its chosen dofs on every rank.
pub struct Direct<'p> {
    petsc: &'p Petsc,
    mumps: Mumps<'p>,
    /// Free displacements (the potentials follow them).
    n_u: usize,
    /// The chosen dofs (the contact dofs, MUMPS' Schur unknowns), in their order.
    chosen: Vec<usize>,
    /// `S⁻¹ = (K⁻¹)_cc`, row-major, on every rank.
    inverse: Vec<f64>,
    /// Wall time of the analysis and factorisation, s.
    pub seconds: f64,
}

/// Entries `(row, column, value)` of one triangle (`row >= column`) of a symmetric matrix.
#[derive(Default)]
struct Entries {
    rows: Vec<usize>,
    cols: Vec<usize>,
    values: Vec<f64>,
}

impl Entries {
    /// Adds `v` at `(i, j)` if it lies in the lower triangle (the upper one is its mirror).
    fn push(&mut self, i: usize, j: usize, v: f64) {
        if i >= j && v != 0.0 {
            self.rows.push(i);
            self.cols.push(j);
            self.values.push(v);
        }
    }
}

impl<'p> Direct<'p> {
    /// Factors `K` of `disc`, this rank's cells those `layout` gives it, with the entries
    /// `extra` (both triangles, in the free displacements' numbering: a compliant bed's
    /// springs) added once, and the Schur complement of `chosen` (empty: none), within the
    /// `memory` a rank may use (MUMPS' estimate checked after its analysis). Collective.
    ///
    /// # Errors
    /// MUMPS' (a singular `K` among them).
    pub fn new(
        petsc: &'p Petsc,
        disc: &Discretization<'_>,
        layout: &Layout,
        extra: &[(usize, usize, f64)],
        chosen: Vec<usize>,
        memory: Option<u64>,
    ) -> Result<Self, PetscError> {
        let t = std::time::Instant::now();
        let (n_u, n_phi) = (disc.dofs.n_u, disc.dofs.n_phi);
        let mut entries = Entries::default();
        let rank = petsc.rank();
        for c in (0..disc.mesh.n_cells()).filter(|&c| layout.cell_rank[c] == rank) {
            cell_entries(disc, c, &mut entries);
        }
        if rank == 0 {
            for &(i, j, v) in extra {
                entries.push(i, j, v);
            }
        }
        // K is quasi-definite: no pivoting, as the default backend's L D Lᵀ
        let symmetry = if n_phi == 0 {
            Symmetry::Definite
        } else {
            Symmetry::QuasiDefinite
        };
        let order = pivot_order(disc, &chosen);
        let mumps = Mumps::factor(
            petsc,
            n_u + n_phi,
            (&entries.rows, &entries.cols, entries.values),
            symmetry,
            &chosen,
            Some(&order),
            memory,
        )?;
        let k = chosen.len();
        let mut inverse = vec![0.0; k * k];
        if let Some(s) = mumps.schur_complement() {
            // a singular S leaves NaN in the inverse: every rank sees it after the broadcast
            inverse = linalg::symmetric_inverse(s, k).unwrap_or_else(|_| vec![f64::NAN; k * k]);
        }
        petsc.broadcast(&mut inverse)?;
        if inverse.iter().any(|v| !v.is_finite()) {
            return Err(PetscError::Argument(
                "the contact dofs' Schur complement is singular (is the body held without its contact?)".into(),
            ));
        }
        Ok(Direct {
            petsc,
            mumps,
            n_u,
            chosen,
            inverse,
            seconds: t.elapsed().as_secs_f64(),
        })
    }

    /// Floating-point operations of the factorisation (all ranks).
    pub fn factor_flops(&self) -> f64 {
        self.mumps.factor_flops()
    }

    /// The numeric factorisation's operations and wall time, s (the analysis left out).
    pub fn factor_rate(&self) -> (f64, f64) {
        (self.mumps.factor_flops(), self.mumps.numeric_seconds())
    }

    /// Bytes of the factors (all ranks).
    pub fn factor_bytes(&self) -> f64 {
        self.mumps.factor_bytes()
    }

    /// `S⁻¹ y` (the chosen dofs' order).
    fn inverse_times(&self, y: &[f64]) -> Vec<f64> {
        let k = self.chosen.len();
        (0..k)
            .map(|i| self.inverse[i * k..(i + 1) * k].iter().zip(y).map(|(a, b)| a * b).sum())
            .collect()
    }

    /// `K⁻¹ b` for the whole `b` (the same on every rank), whole on every rank.
    fn solve_whole(&mut self, mut b: Vec<f64>) -> Result<Vec<f64>, PetscError> {
        if self.chosen.is_empty() {
            self.mumps.solve(&mut b)?;
        } else {
            let reduced = self.mumps.condense(&mut b)?;
            let x_c = if self.petsc.rank() == 0 {
                self.inverse_times(&reduced)
            } else {
                vec![]
            };
            self.mumps.expand(&mut b, &x_c)?;
        }
        self.petsc.broadcast(&mut b)?;
        Ok(b)
    }

    /// `b - K x` for the whole `x` and `b`, whole on every rank (each rank's entries, summed).
    fn minus_k_x_whole(&self, x: &[f64], b: &[f64]) -> Result<Vec<f64>, PetscError> {
        let mut y = vec![0.0; x.len()];
        // this rank's entries as MUMPS holds them (one triangle, 1-based)
        let (rows, cols, values) = self.mumps.entries();
        for ((&i, &j), &v) in rows.iter().zip(cols).zip(values) {
            let (i, j) = (i as usize - 1, j as usize - 1);
            y[i] += v * x[j];
            if i != j {
                y[j] += v * x[i];
            }
        }
        let kx = self.petsc.sum(&y)?;
        Ok(b.iter().zip(&kx).map(|(b, k)| b - k).collect())
    }
}

/// The default backend's pivot order (docs/performance.md: a geometric nested dissection of
/// the mesh's nodes, each node's unknowns together), `chosen` moved last: MUMPS' own choice
/// with a Schur complement is AMD, 35 times the flops on `paper-3d` at n = 16.
fn pivot_order(disc: &Discretization<'_>, chosen: &[usize]) -> Vec<usize> {
    let mesh = disc.mesh;
    let order = disc.dofs.expand_node_order(&mesh.nested_dissection());
    let mut last = vec![false; order.len()];
    for &c in chosen {
        last[c] = true;
    }
    let mut out: Vec<usize> = order.into_iter().filter(|&i| !last[i]).collect();
    out.extend_from_slice(chosen);
    out
}

/// A PETSc error among the problem's.
fn problem(e: PetscError) -> ProblemError {
    crate::error::solve_failed("the direct solve on the ranks (MUMPS)", e)
}

impl Factorization for Direct<'_> {
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64]) -> Result<(Fields, usize), ProblemError> {
        let x = self.solve_whole(joined(b_u, b_phi)).map_err(problem)?;
        Ok((split(x, self.n_u), 0))
    }

    fn condense(&mut self, b_u: &[f64], b_phi: &[f64], dofs: &[usize]) -> Result<Condensed, ProblemError> {
        if dofs != self.chosen {
            return Err(ProblemError::NoSolution {
                sought: "the condensation on the ranks",
                why: "the dofs asked for are not those factored as the Schur unknowns".into(),
            });
        }
        let mut b = joined(b_u, b_phi);
        let reduced = self.mumps.condense(&mut b).map_err(problem)?;
        let mut solution = vec![0.0; dofs.len()];
        if self.petsc.rank() == 0 {
            solution = self.inverse_times(&reduced);
        }
        self.petsc.broadcast(&mut solution).map_err(problem)?;
        Ok(Condensed {
            inverse: self.inverse.clone(),
            loads: CondensedLoads::formed(solution, CondenseRoute::SchurComplement, dofs.to_vec()),
        })
    }

    /// One whole solve with the loads and `d` at the condensation's dofs: MUMPS keeps the
    /// forward half of a condensation inside itself, for the expansion that follows it next
    /// (another solve in between is refused, its `INFOG(1) = -35`), so the loads' half cannot
    /// wait for the contact solve.
    fn solve_with_update(
        &mut self,
        loads: CondensedLoads,
        b_u: &[f64],
        b_phi: &[f64],
        d: &[f64],
    ) -> Result<Fields, ProblemError> {
        let mut b = joined(b_u, b_phi);
        for (&j, v) in loads.dofs().iter().zip(d) {
            b[j] += v;
        }
        let x = self.solve_whole(b).map_err(problem)?;
        Ok(split(x, self.n_u))
    }

    fn refine(&mut self, rhs: Rhs<'_>, u: &mut [f64], phi: &mut [f64], tol: f64) -> Result<Refinement, ProblemError> {
        let mut system = Refining { direct: self, rhs };
        Ok(linalg::refine_by(&mut system, u, phi, tol, 3).map_err(problem)?.into())
    }

    fn equilibrium(&mut self, u: &[f64], phi: &[f64], rhs: Rhs<'_>) -> Result<f64, ProblemError> {
        let r = self
            .minus_k_x_whole(&joined(u, phi), &joined(rhs.u, rhs.phi))
            .map_err(problem)?;
        let (ru, rp) = r.split_at(self.n_u);
        Ok(linalg::relative_residual(ru, rp, rhs))
    }

    fn coupled(&mut self) -> Option<&mut dyn CoupledSolver> {
        Some(self)
    }

    fn condenses(&self) -> bool {
        true
    }
}

/// One full solve with the factors (the strategies that solve the primal problem once per
/// first-order step).
impl CoupledSolver for Direct<'_> {
    fn solve(
        &mut self,
        b_u: &[f64],
        b_phi: &[f64],
        u: &mut [f64],
        phi: &mut [f64],
    ) -> Result<linalg::SolveInfo, linalg::LinalgError> {
        let x = self
            .solve_whole(joined(b_u, b_phi))
            .map_err(|e| linalg::LinalgError::Solver(e.to_string()))?;
        copy_into(&x, u, phi);
        Ok(linalg::SolveInfo { pcg_iters: 0 })
    }

    fn factor_bytes(&self) -> usize {
        self.mumps.factor_bytes() as usize
    }
}

/// The factorisation with the right-hand side it refines towards.
struct Refining<'a, 'p> {
    direct: &'a mut Direct<'p>,
    rhs: Rhs<'a>,
}

impl linalg::Refinable for Refining<'_, '_> {
    type Error = PetscError;

    fn residual(&mut self, u: &[f64], phi: &[f64]) -> Result<linalg::Residual, PetscError> {
        let r = self
            .direct
            .minus_k_x_whole(&joined(u, phi), &joined(self.rhs.u, self.rhs.phi))?;
        let (ru, rp) = split(r, self.direct.n_u);
        Ok(linalg::Residual::of(ru, rp, self.rhs))
    }

    fn correction(&mut self, r_u: &[f64], r_phi: &[f64]) -> Result<(Vec<f64>, Vec<f64>), PetscError> {
        let n_u = self.direct.n_u;
        Ok(split(self.direct.solve_whole(joined(r_u, r_phi))?, n_u))
    }
}

/// The lower triangle of cell `c`'s element matrix of `K = [[A, Gᵀ], [G, -B]]`, in the free
/// unknowns' numbering (`[u; φ]`, the prescribed ones left out: their values are lifted into
/// the loads).
fn cell_entries(disc: &Discretization<'_>, c: usize, out: &mut Entries) {
    let cell = disc.mesh.cell(c);
    let dim = disc.mesh.dim;
    let d = &disc.dofs;
    let free_u = |v: usize, k: usize| match d.u[v * dim + k] {
        Dof::Free(j) => Some(j),
        _ => None,
    };
    let free_phi = |v: usize| match d.phi[v] {
        Dof::Free(j) => Some(d.n_u + j),
        _ => None,
    };
    let electric = disc.cell_electric[c];
    let (m, r) = (disc.material(c), disc.rule(c));
    for (a, &va) in cell.iter().enumerate() {
        for k in 0..dim {
            let Some(col) = free_u(va, k) else {
                continue;
            };
            let colv: [[f64; 3]; MAX_NODES] = elasticity_column(m, &r, a, k);
            for (b, &vb) in cell.iter().enumerate() {
                for (l, &v) in colv[b].iter().enumerate().take(dim) {
                    if let Some(row) = free_u(vb, l) {
                        out.push(row, col, v);
                    }
                }
            }
            if electric {
                let colg: [f64; MAX_NODES] = coupling_column(m, &r, a, k);
                for (b, &vb) in cell.iter().enumerate() {
                    if let Some(row) = free_phi(vb) {
                        // G below the diagonal (the potentials come after the displacements)
                        out.push(row, col, colg[b]);
                    }
                }
            }
        }
        if !electric {
            continue;
        }
        let Some(col) = free_phi(va) else {
            continue;
        };
        let colb: [f64; MAX_NODES] = dielectric_column(m, &r, a);
        for (b, &vb) in cell.iter().enumerate() {
            if let Some(row) = free_phi(vb) {
                out.push(row, col, -colb[b]);
            }
        }
    }
}
