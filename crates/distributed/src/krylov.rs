//! The Krylov route of a run without contact (and of the active sets where MUMPS would not
//! fit): the parallel matrix of [`crate::system`], PETSc's Krylov solver on it with the
//! backend's options (a field split of the potentials' Schur complement, algebraic multigrid),
//! and the map between the free unknowns `[u; φ]` and the layout's rows, so that the run's
//! instants ([`problem::Instants`]) solve on it as on a factorisation.

use crate::free::{copy_into, joined, split};
use crate::layout::Layout;
use crate::system::System;
use fe_assembly::{Discretization, Dof};
use petsc::{Index, IndexSet, Ksp, Matrix, Petsc, PetscError, Vector};
use problem::backend::{Fields, Setup};
use problem::{Event, Factorization, ProblemError, Reporter, Scene};
use std::time::Instant;

/// The backend's choices for the Krylov route, as options of PETSc's database (the scene's
/// `solver.petsc_options` come after them and win). With potentials: FGMRES outside (the
/// preconditioner is not a fixed linear map when its blocks are multigrid cycles), the
/// upper-triangular Schur factorisation of the potentials, `selfp` (`B + G diag(A)⁻¹ Gᵀ`) for
/// the Schur complement, one GAMG cycle (smoothed aggregation with the rigid-body modes) for
/// the elastic block and one BoomerAMG cycle (hypre) for the Schur block, where PETSc has
/// hypre, else GAMG. Without potentials: CG with GAMG. Chosen by measurement on `paper-3d`
/// (docs/performance.md): the full factorisation with GAMG on both blocks took 2.6 times as
/// long.
pub const COUPLED_OPTIONS: &str = "-ksp_type fgmres -ksp_gmres_restart 200 -ksp_rtol 1e-10 -ksp_max_it 5000 \
-pc_type fieldsplit -pc_fieldsplit_type schur -pc_fieldsplit_schur_fact_type upper \
-pc_fieldsplit_schur_precondition selfp -fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type gamg \
-fieldsplit_phi_ksp_type preonly -fieldsplit_phi_pc_type hypre";

/// See [`COUPLED_OPTIONS`].
pub const ELASTIC_OPTIONS: &str = "-ksp_type cg -ksp_rtol 1e-10 -ksp_max_it 5000 -pc_type gamg";

/// The Krylov route: the parallel matrix, its solver (set up once, at the first solve), and the
/// map between the free unknowns and the layout's rows.
pub(crate) struct Krylov<'p> {
    pub(crate) petsc: &'p Petsc,
    pub(crate) system: System<'p>,
    pub(crate) fields: KrylovFields,
    ksp: Option<Ksp<'p>>,
    /// Each global row's free unknown in `[u; φ]` (the potentials' rows negated), or `None`
    /// for a prescribed one.
    free_of_row: Vec<Option<usize>>,
    /// This rank's rows.
    owned: std::ops::Range<usize>,
    n_u: usize,
    /// Wall time of the preconditioner's set-up, s; Krylov iterations and the last reason.
    pub(crate) t_pc: f64,
    pub(crate) iterations: usize,
    pub(crate) reason: String,
}

impl<'p> Krylov<'p> {
    /// The route on the assembled `system`.
    pub(crate) fn new(
        petsc: &'p Petsc,
        disc: &Discretization<'_>,
        layout: &Layout,
        system: System<'p>,
        fields: KrylovFields,
    ) -> Self {
        let d = &disc.dofs;
        let mut free_of_row = vec![None; layout.n_global()];
        for v in 0..layout.first.len() {
            let f = layout.first[v];
            for k in 0..layout.dim {
                if let Dof::Free(j) = d.u[v * layout.dim + k] {
                    free_of_row[f + k] = Some(j);
                }
            }
            if let Dof::Free(j) = d.phi[v] {
                free_of_row[f + layout.dim] = Some(d.n_u + j);
            }
        }
        Krylov {
            petsc,
            system,
            fields,
            ksp: None,
            free_of_row,
            owned: layout.owned(petsc.rank()),
            n_u: d.n_u,
            t_pc: 0.0,
            iterations: 0,
            reason: String::new(),
        }
    }

    /// This rank's rows of the free vector `v` (`[u; φ]`; prescribed rows 0), the potentials'
    /// negated where `rhs` (the parallel system's right-hand side is `[b_u; -b_φ]`).
    fn distributed(&self, v: &[f64], rhs: bool) -> Result<Vector<'p>, PetscError> {
        let local: Vec<f64> = self
            .owned
            .clone()
            .map(|r| match self.free_of_row[r] {
                Some(j) if rhs && j >= self.n_u => -v[j],
                Some(j) => v[j],
                None => 0.0,
            })
            .collect();
        Vector::from_local(self.petsc, &local)
    }

    /// A distributed vector in the free unknowns `[u; φ]`, whole on every rank (the
    /// potentials' rows negated back where `negate`).
    pub(crate) fn whole(&self, x: &Vector<'p>, negate: bool) -> Result<Vec<f64>, PetscError> {
        let n = self.free_of_row.len();
        let mut all = x.gather()?.unwrap_or_else(|| vec![0.0; n]);
        self.petsc.broadcast(&mut all)?;
        let mut out = vec![0.0; self.free_of_row.iter().flatten().count()];
        for (r, j) in self.free_of_row.iter().enumerate() {
            if let Some(j) = *j {
                out[j] = if negate && j >= self.n_u { -all[r] } else { all[r] };
            }
        }
        Ok(out)
    }

    /// `K⁻¹ b` by the Krylov solver from `start` (zero without), whole on every rank.
    fn solve_whole(&mut self, b: &[f64], start: Option<&[f64]>) -> Result<Vec<f64>, PetscError> {
        let rhs = self.distributed(b, true)?;
        let mut x = match start {
            Some(x0) => self.distributed(x0, false)?,
            None => rhs.duplicate()?,
        };
        if self.ksp.is_none() {
            let t = Instant::now();
            self.ksp = Some(self.fields.krylov(self.petsc, &mut self.system.matrix)?);
            self.t_pc += t.elapsed().as_secs_f64();
        }
        let ksp = self
            .ksp
            .as_mut()
            .ok_or_else(|| PetscError::Argument("no Krylov solver".into()))?;
        let info = ksp.solve(&rhs, &mut x)?;
        (self.iterations, self.reason) = (info.iterations, info.reason);
        self.whole(&x, false)
    }

    /// Reports the last Krylov solve's figures.
    pub(crate) fn report(&self, reporter: &mut dyn Reporter) {
        reporter.event(&Event::Krylov {
            iterations: self.iterations,
            reason: &self.reason,
            setup_seconds: self.t_pc,
        });
    }
}

/// A PETSc error among the problem's.
fn problem(e: PetscError) -> ProblemError {
    crate::error::solve_failed("the Krylov solve on the ranks", e)
}

impl Factorization for Krylov<'_> {
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64]) -> Result<(Fields, usize), ProblemError> {
        let x = self.solve_whole(&joined(b_u, b_phi), None).map_err(problem)?;
        Ok((split(x, self.n_u), 0))
    }

    fn condense(&mut self, _: &[f64], _: &[f64], _: &[usize]) -> Result<linalg::Condensed, ProblemError> {
        Err(ProblemError::NoSolution {
            sought: "the condensation on the ranks",
            why: "the Krylov route does not condense (a run with contact factors by MUMPS)".into(),
        })
    }

    fn solve_with_update(
        &mut self,
        _: linalg::CondensedLoads,
        _: &[f64],
        _: &[f64],
        _: &[f64],
    ) -> Result<Fields, ProblemError> {
        self.condense(&[], &[], &[]).map(|_| (vec![], vec![]))
    }

    /// None: the Krylov solver's tolerance is its accuracy.
    fn refine(
        &mut self,
        _: linalg::Rhs<'_>,
        _: &mut [f64],
        _: &mut [f64],
        _: f64,
    ) -> Result<problem::Refinement, ProblemError> {
        Ok(problem::Refinement::default())
    }

    fn equilibrium(&mut self, u: &[f64], phi: &[f64], rhs: linalg::Rhs<'_>) -> Result<f64, ProblemError> {
        let (x, b) = (joined(u, phi), joined(rhs.u, rhs.phi));
        let run = || -> Result<Vec<f64>, PetscError> {
            let xd = self.distributed(&x, false)?;
            let mut r = self.distributed(&b, true)?;
            let mut kx = r.duplicate()?;
            self.system.matrix.mult(&xd, &mut kx)?;
            // r = K x - b, the potentials' rows of both negated alike
            r.axpy(-1.0, &kx)?;
            self.whole(&r, true)
        };
        let r = run().map_err(problem)?;
        let (ru, rp) = r.split_at(self.n_u);
        Ok(linalg::relative_residual(ru, rp, rhs))
    }

    fn coupled(&mut self) -> Option<&mut dyn linalg::CoupledSolver> {
        Some(self)
    }

    fn condenses(&self) -> bool {
        false
    }
}

/// One Krylov solve of the whole system (the paper's Uzawa: one Schur-complement solve per
/// step, here PETSc's field split with the potentials' Schur complement).
impl linalg::CoupledSolver for Krylov<'_> {
    fn solve(
        &mut self,
        b_u: &[f64],
        b_phi: &[f64],
        u: &mut [f64],
        phi: &mut [f64],
    ) -> Result<linalg::SolveInfo, linalg::LinalgError> {
        // the warm start `(u, φ)`: the paper's Uzawa hands each step the step before's solution
        let x = self
            .solve_whole(&joined(b_u, b_phi), Some(&joined(u, phi)))
            .map_err(|e| linalg::LinalgError::Solver(e.to_string()))?;
        copy_into(&x, u, phi);
        Ok(linalg::SolveInfo {
            pcg_iters: self.iterations,
        })
    }

    fn factor_bytes(&self) -> usize {
        0
    }
}

/// On a run on pieces, with potentials and hypre, the elastic block's preconditioner: one
/// BoomerAMG cycle in place of GAMG's. Measured on `paper-3d` n = 48 with contact (one session,
/// docs/performance.md): per rank 5565 / 2980 / 1627 MB on 1 / 2 / 4 ranks (0.535 and 0.292 of
/// one rank) against GAMG's 4583 / 3094 / 1677 MB (0.675 and 0.366), 158.5 / 95.7 / 119.0 s
/// against 191.7 / 92.9 / 125.4 s, and 53-55 Krylov iterations on every rank count where GAMG's
/// grew from 105 to 129: the memory a rank needs falls as `1/p`, and the iterations do not grow
/// with the ranks. (GAMG's parallel Galerkin products are what did not fall.) BoomerAMG is set
/// as its authors advise for 3D: HMIS coarsening, extended+i interpolation truncated to 4
/// entries a row, strength threshold 0.5. On one rank, against its defaults (one session):
/// a Gmsh box of 73,703 cells with contact 10.6 s against 17.3 s and 366 against 464 MB;
/// `indent-sphere-3d` n = 24 7.3 against 9.0 s, `paper-3d` n = 24 13.5 against 14.4 s, with
/// 5 to 7 % less memory.
pub const PIECES_ELASTIC_BLOCK: &str = "-fieldsplit_u_pc_type hypre -fieldsplit_u_pc_hypre_boomeramg_coarsen_type HMIS -fieldsplit_u_pc_hypre_boomeramg_interp_type ext+i -fieldsplit_u_pc_hypre_boomeramg_P_max 4 -fieldsplit_u_pc_hypre_boomeramg_strong_threshold 0.5";

/// Puts the backend's options, then the scene's, into PETSc's database; returns them as one
/// string. `pieces`: a run on pieces ([`PIECES_ELASTIC_BLOCK`]).
pub(crate) fn configure(
    petsc: &Petsc,
    scene: &Scene,
    layout: &Layout,
    contact_tol: Option<f64>,
    pieces: bool,
) -> Result<String, PetscError> {
    let mut all = if layout.coupled {
        let mut o = COUPLED_OPTIONS.to_owned();
        if !petsc.has_package("hypre")? {
            o = o.replace("-fieldsplit_phi_pc_type hypre", "-fieldsplit_phi_pc_type gamg");
        } else if pieces {
            o.push(' ');
            o.push_str(PIECES_ELASTIC_BLOCK);
        }
        o
    } else {
        ELASTIC_OPTIONS.to_owned()
    };
    if let Some(tol) = contact_tol {
        if all.starts_with(ELASTIC_OPTIONS) {
            // Coulomb's slip rows make the system unsymmetric: GMRES instead of CG
            all.push_str(" -ksp_type gmres -ksp_gmres_restart 200");
        }
        // the multipliers are reactions of the Krylov solution: its error bounds the
        // complementarity residual, which must reach solver.tol
        let rtol = (1e-2 * tol).min(1e-10);
        all.push_str(&format!(" -ksp_rtol {rtol:e}"));
    }
    petsc.insert_options(&all)?;
    if let Some(user) = &scene.solver.petsc_options {
        petsc.insert_options(user)?;
        all.push(' ');
        all.push_str(user);
    }
    Ok(all)
}

/// What the Krylov solver needs to know of the unknowns: this rank's rows of the
/// displacements (with their nodes' coordinates, for the rigid-body modes) and of the
/// potentials (the floating terminals' among them).
pub(crate) struct KrylovFields {
    dim: usize,
    u_rows: Vec<Index>,
    phi_rows: Vec<Index>,
    coords: Vec<f64>,
    coupled: bool,
}

impl KrylovFields {
    /// The fields of this rank's rows; coupled where the layout is (agreed over the ranks).
    pub(crate) fn new(petsc: &Petsc, setup: &Setup, layout: &Layout) -> Self {
        let dim = layout.dim;
        let (mut u_rows, mut phi_rows, mut coords) = (vec![], vec![], vec![]);
        for v in layout.owned_nodes(petsc.rank()) {
            let f = layout.first[v];
            u_rows.extend((0..dim).map(|k| (f + k) as Index));
            coords.extend_from_slice(&setup.mesh.points[v][..dim]);
            if layout.own_phi(v) {
                phi_rows.push((f + dim) as Index);
            }
        }
        // the floating terminals' potentials
        if petsc.rank() == layout.terminals_rank() {
            phi_rows.extend((0..layout.terminals).map(|t| Layout::index(layout.terminal_row(t))));
        }
        KrylovFields {
            dim,
            u_rows,
            phi_rows,
            coords,
            coupled: layout.coupled,
        }
    }

    /// The Krylov solver for `matrix`, configured from the options database, with the fields
    /// (displacements with their rigid-body modes, potentials) named for a field split, and
    /// its preconditioner built.
    pub(crate) fn krylov<'p>(&self, petsc: &'p Petsc, matrix: &mut Matrix<'p>) -> Result<Ksp<'p>, PetscError> {
        if !self.coupled {
            // the matrix's own near null space (its rows are the nodes' displacements, in order)
            matrix.set_rigid_body_modes(self.dim, &self.coords)?;
        }
        let mut ksp = Ksp::new(petsc, matrix)?;
        if self.coupled {
            let mut is_u = IndexSet::new(petsc, &self.u_rows)?;
            is_u.set_block_size(self.dim)?;
            is_u.set_rigid_body_modes(self.dim, &self.coords)?;
            let is_phi = IndexSet::new(petsc, &self.phi_rows)?;
            ksp.set_types("fgmres", "fieldsplit")?;
            ksp.set_field("u", &is_u)?;
            ksp.set_field("phi", &is_phi)?;
        }
        ksp.set_from_options()?;
        // the last step's solution is a good start for an iterative method; a direct solve
        // (`-ksp_type preonly -pc_type lu`, e.g. with MUMPS) takes none
        if ksp.kind()? != "preonly" {
            ksp.set_initial_guess_nonzero(true)?;
        }
        ksp.set_up()?;
        Ok(ksp)
    }
}
