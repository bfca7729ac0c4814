//! A run on the ranks: the PETSc backend of [`problem::run`]. It partitions the cells among
//! the ranks and, on them, either factors `K` by MUMPS (any run with contact: [`Direct`], the
//! contact dofs' Schur complement for the instants' condensed route, the default backend's
//! contact solvers on it) or assembles a parallel matrix for Krylov solves with algebraic
//! multigrid (a run without contact: `Krylov`). Every rank holds the whole solution of each
//! instant (the mesh is whole on every rank too); rank 0 returns the run's solution.

use crate::direct::Direct;
use crate::layout::Layout;
use crate::system::{assemble, System};
use fe_assembly::{Discretization, Dof};
use petsc::{Index, IndexSet, Ksp, Matrix, Petsc, PetscError, Vector};
use problem::backend::{
    At, Backend, Contact, ContactBoundary, ContactSolve, Fields, Figures, InstantOf, InstantSolution, Posed, Primed,
    Setup, Unsupported,
};
use problem::{Event, Factorization, Instants, PetscReport, ProblemError, Reporter, Scene, Solution, Step};
use std::time::Instant;

/// What can stop a run of the PETSc backend.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DistributedError {
    /// The scene, its mesh or its data (as the default backend reports them).
    #[error(transparent)]
    Problem(#[from] ProblemError),
    /// PETSc, MPI or MUMPS.
    #[error(transparent)]
    Petsc(#[from] PetscError),
    /// The active sets (the Krylov route's contact) did not converge.
    #[error("contact: {0}")]
    Contact(crate::contact::ActiveSetError),
}

impl From<fe_assembly::AssemblyError> for DistributedError {
    fn from(e: fe_assembly::AssemblyError) -> Self {
        DistributedError::Problem(e.into())
    }
}

impl From<problem::SceneError> for DistributedError {
    fn from(e: problem::SceneError) -> Self {
        DistributedError::Problem(e.into())
    }
}

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

/// Solves `scene` on the ranks of `petsc`. Every rank calls it (it is collective); rank 0
/// returns the [`Solution`], as [`problem::solve`] gives it, the others `None`. `mesh` is the
/// mesh of a `gmsh` scene, read by the caller on every rank. `limits.memory_bytes` is the
/// memory each rank may take: a generated mesh whose estimate exceeds it is refused before
/// anything is built. Only rank 0 should pass a reporter that prints.
///
/// # Errors
/// The default backend's errors for the scene and its data; PETSc's and MUMPS' (a Krylov
/// solve that did not converge among them) as [`DistributedError::Petsc`].
pub fn solve(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    petsc: &Petsc,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DistributedError> {
    solve_path(scene, mesh, petsc, limits, reporter, &mut |_| Ok(()))
}

/// [`solve`], each instant of the scene's path (one for a static scene) handed to `each` on
/// every rank, with its fields where they were computed (as [`problem::solve_path`] hands them:
/// the driver writes a path's files from rank 0's).
///
/// # Errors
/// As [`solve`]; the error `each` returns.
pub fn solve_path(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    petsc: &Petsc,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<Option<Solution>, DistributedError> {
    let mut backend = DistributedMemory {
        petsc,
        limits,
        contact: ContactRoute::Auto,
    };
    solve_with(&mut backend, scene, mesh, reporter, each)
}

/// [`solve_path`] on `backend` (its limits, its contact route).
///
/// # Errors
/// As [`solve`]; the error `each` returns.
pub fn solve_with(
    backend: &mut DistributedMemory<'_>,
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    reporter: &mut dyn Reporter,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<Option<Solution>, DistributedError> {
    let (petsc, limits) = (backend.petsc, backend.limits);
    let solution = problem::run_steps(backend, scene, mesh, limits, reporter, each)?;
    Ok(solution.filter(|_| petsc.rank() == 0))
}

/// How a run with contact solves it on the ranks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactRoute {
    /// MUMPS' condensed route where its factorisation fits the memory of a rank, else the
    /// Krylov route's active sets where they hold the scene.
    #[default]
    Auto,
    /// MUMPS' condensed route (every law).
    Condensed,
    /// The Krylov route's active sets (the paper's base model on one zone; other scenes
    /// refused by key).
    ActiveSets,
}

/// The backend named for its role: the ranks of an MPI run, each its own memory
/// (`solver.backend = "petsc"`, after the library that runs it), on the ranks of `petsc`.
pub struct DistributedMemory<'p> {
    /// PETSc, initialised on the ranks of the run.
    pub petsc: &'p Petsc,
    /// What each rank may use (the route is chosen by it: MUMPS where its factorisation fits,
    /// else the Krylov route's active sets where they hold the scene).
    pub limits: problem::Limits,
    /// How a run with contact solves it.
    pub contact: ContactRoute,
}

impl DistributedMemory<'_> {
    /// Whether a run of `scene` factors `K` by MUMPS ([`crate::factors_directly`]), unless the
    /// factorisation's estimate per rank exceeds the memory each rank may use and the Krylov
    /// route's active sets hold the scene ([`crate::active_sets_hold`]).
    fn direct_route(&self, scene: &Scene) -> bool {
        let held = || crate::active_sets_hold(scene).is_ok();
        crate::factors_directly(scene)
            && match self.contact {
                ContactRoute::Auto => !(self.direct_too_large(scene) && held()),
                ContactRoute::Condensed => true,
                ContactRoute::ActiveSets => !held(),
            }
    }

    /// Whether MUMPS' factorisation, estimated as the default backend's run shared among the
    /// ranks, exceeds the memory of a rank.
    fn direct_too_large(&self, scene: &Scene) -> bool {
        match (self.limits.memory_bytes, direct_estimate(scene, self.petsc.size())) {
            (Some(limit), Some((bytes, _))) => bytes > limit as f64,
            _ => false,
        }
    }
}

/// The default backend's estimate of its run's peak (the factor, the dense compliance) shared
/// among `ranks`: MUMPS' factorisation on them.
fn direct_estimate(scene: &Scene, ranks: usize) -> Option<(f64, String)> {
    let (bytes, what) = Backend::estimate(&problem::SharedMemory, scene)?;
    Some((
        bytes / ranks.max(1) as f64,
        format!("on each of {ranks} ranks, its share of MUMPS' factorisation: {what}"),
    ))
}

/// The cells laid out over the ranks, and (the Krylov route) the system assembled on them.
pub struct Assembled<'p> {
    layout: Layout,
    system: Option<System<'p>>,
}

/// The system ready to be solved on the ranks (factored, or its Krylov solver configured),
/// with what the run's instants keep on it.
pub struct Prepared<'p> {
    route: Route<'p>,
    instants: Instants,
    layout: Layout,
    /// The options in force (the Krylov route), or the factorisation's description.
    options: String,
}

/// How `K` is solved on the ranks.
enum Route<'p> {
    /// MUMPS' factorisation (runs with contact).
    Direct(Box<Direct<'p>>),
    /// Krylov solves with algebraic multigrid (runs without contact; with contact, the active
    /// sets, where MUMPS would not fit).
    Krylov(Box<Krylov<'p>>),
}

impl<'p> Route<'p> {
    /// The Krylov route's active sets, where its run has contact.
    fn active(&mut self) -> Option<&mut crate::active::ActiveSets<'p>> {
        match self {
            Route::Krylov(k) => k.active.as_mut(),
            Route::Direct(_) => None,
        }
    }

    fn factorization(&mut self) -> &mut dyn Factorization {
        match self {
            Route::Direct(d) => &mut **d,
            Route::Krylov(k) => &mut **k,
        }
    }
}

impl<'p> Backend for DistributedMemory<'p> {
    const NAME: &'static str = "petsc";
    type Assembled = Assembled<'p>;
    type System = Prepared<'p>;
    type Error = DistributedError;
    const HELD_TO_TOLERANCE: bool = false;

    fn supports(&self, scene: &Scene) -> Result<(), Unsupported> {
        crate::supports(scene)?;
        match self.contact {
            ContactRoute::ActiveSets if !scene.zones().is_empty() => crate::active_sets_hold(scene),
            _ => Ok(()),
        }
    }

    fn estimate(&self, scene: &Scene) -> Option<(f64, String)> {
        match self.direct_route(scene) {
            true => direct_estimate(scene, self.petsc.size()),
            false => per_rank_estimate(scene, self.petsc.size()),
        }
    }

    fn assemble(&mut self, posed: &Posed<'_>) -> Result<Assembled<'p>, DistributedError> {
        let layout = Layout::new(self.petsc, &posed.setup.mesh, &posed.disc.dofs)?;
        let system = match self.direct_route(&posed.scene) {
            true => None,
            false => Some(assemble(
                self.petsc,
                posed.disc,
                &layout,
                &posed.loads.b_u,
                &posed.loads.b_phi,
            )?),
        };
        Ok(Assembled { layout, system })
    }

    fn prepare(
        &mut self,
        posed: &Posed<'_>,
        Assembled { layout, system }: Assembled<'p>,
        boundary: Option<&ContactBoundary>,
        _: problem::Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<Prepared<'p>, DistributedError> {
        let (route, options) = match system {
            None => {
                let chosen = match boundary {
                    Some(cb) if posed.plan().linear_strategy.is_condensed() => cb.condensed_dofs(),
                    _ => vec![],
                };
                let springs = match (posed.bed, boundary) {
                    (Some(bed), Some(cb)) => cb.normal_springs(bed.stiffness),
                    _ => vec![],
                };
                let k = chosen.len();
                let direct = Direct::new(self.petsc, posed.disc, &layout, &springs, chosen)?;
                reporter.event(&Event::Factored {
                    seconds: direct.seconds,
                });
                let options = format!(
                    "MUMPS (L D Lᵀ on {} ranks, its own C interface; the default backend's nested dissection), the Schur complement of {k} contact dofs; {:.3e} flops, {:.3e} bytes of factors",
                    self.petsc.size(),
                    direct.factor_flops(),
                    direct.factor_bytes()
                );
                (Route::Direct(Box::new(direct)), options)
            }
            Some(system) => {
                let contact = boundary.is_some();
                let options = configure(self.petsc, &posed.scene, &layout, contact.then_some(posed.plan().tol))?;
                let fields = KrylovFields::new(self.petsc, posed.setup, &layout);
                let mut krylov = Krylov::new(self.petsc, posed.disc, &layout, system, fields);
                krylov.active = contact.then(crate::active::ActiveSets::default);
                (Route::Krylov(Box::new(krylov)), options)
            }
        };
        Ok(Prepared {
            route,
            instants: Instants::default(),
            layout,
            options,
        })
    }

    fn begin(
        &mut self,
        s: &mut Prepared<'p>,
        posed: &Posed<'_>,
        contact: Option<Contact<'_>>,
        parts: &[Fields],
        reporter: &mut dyn Reporter,
    ) -> Result<Vec<Fields>, DistributedError> {
        if let Some(active) = s.route.active() {
            return active.begin(parts);
        }
        let f = s.route.factorization();
        Ok(s.instants.begin(f, posed, contact, parts, reporter)?)
    }

    fn respond(&mut self, s: &mut Prepared<'p>, a_u: &[f64], a_phi: &[f64]) -> Result<Fields, DistributedError> {
        Ok(Instants::respond(s.route.factorization(), a_u, a_phi)?)
    }

    fn prime(&mut self, s: &mut Prepared<'p>, primed: Primed<'_>) -> Result<(), DistributedError> {
        if let Some(active) = s.route.active() {
            return active.prime(primed);
        }
        Ok(s.instants.prime(s.route.factorization(), primed)?)
    }

    /// The default backend's contact solvers on the condensed problem, on every rank (each
    /// holds it whole, and they find the same solution); on the Krylov route, its active sets.
    fn solve_posed(
        &mut self,
        s: &mut Prepared<'p>,
        how: &ContactSolve<'_>,
        at: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<contact::ContactSolution, DistributedError> {
        if let Route::Krylov(k) = &mut s.route {
            if k.active.is_some() {
                return crate::active::solve(self.petsc, &s.layout, k, how, at, reporter);
            }
        }
        Ok(s.instants.solve(s.route.factorization(), how, at, reporter)?)
    }

    fn own_scale(&self, s: &Prepared<'p>, factors: &[f64]) -> f64 {
        s.instants.own_scale(factors)
    }

    /// The instant's fields, whole on every rank.
    fn instant_fields(
        &mut self,
        s: &mut Prepared<'p>,
        posed: &Posed<'_>,
        contact: Option<InstantOf<'_>>,
        reporter: &mut dyn Reporter,
    ) -> Result<Option<InstantSolution>, DistributedError> {
        if let (Route::Krylov(k), Some(of)) = (&mut s.route, contact.as_ref()) {
            if k.active.is_some() {
                return crate::active::fields(k, &s.layout, posed, of).map(Some);
            }
        }
        let x = s.instants.fields(s.route.factorization(), posed, contact, reporter)?;
        if let Route::Krylov(k) = &s.route {
            k.report(reporter);
        }
        Ok(Some(x))
    }

    /// The PETSc section of the report (collective).
    fn finish(&mut self, s: Prepared<'p>) -> Result<Figures, DistributedError> {
        let petsc = self.petsc;
        let cells_per_rank = per_rank(petsc, &s.layout)?;
        let unknowns_per_rank = (0..petsc.size()).map(|r| s.layout.owned(r).len()).collect();
        let (nonzeros, krylov, reason, setup, factor_bytes) = match &s.route {
            Route::Krylov(k) => {
                let (nonzeros, _) = k.system.matrix.local_info()?;
                let nonzeros = petsc.sum(&[nonzeros])?[0];
                (nonzeros, k.iterations, k.reason.clone(), k.t_pc, 0)
            }
            Route::Direct(d) => (
                0.0,
                0,
                "direct (MUMPS)".to_owned(),
                d.seconds,
                d.factor_bytes() as usize,
            ),
        };
        let report = PetscReport {
            ranks: petsc.size(),
            unknowns: s.layout.n_global(),
            nonzeros,
            krylov_iterations: krylov,
            reason,
            options: s.options,
            cells_per_rank,
            unknowns_per_rank,
            peak_bytes_per_rank: vec![],
            preconditioner_setup_s: setup,
        };
        Ok(Figures {
            factor_seconds: setup,
            condense: s.instants.condense,
            refinement_steps: s.instants.refinement,
            factor_bytes,
            petsc: Some(report),
            ..Figures::default()
        })
    }
}

/// The Krylov route: the parallel matrix, its solver (set up once, at the first solve), and the
/// map between the free unknowns and the layout's rows.
pub(crate) struct Krylov<'p> {
    pub(crate) petsc: &'p Petsc,
    pub(crate) system: System<'p>,
    pub(crate) fields: KrylovFields,
    ksp: Option<Ksp<'p>>,
    /// The active sets of a run with contact on this route.
    pub(crate) active: Option<crate::active::ActiveSets<'p>>,
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
    fn new(
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
            active: None,
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

    /// `K⁻¹ b` by the Krylov solver, whole on every rank.
    fn solve_whole(&mut self, b: &[f64]) -> Result<Vec<f64>, PetscError> {
        let rhs = self.distributed(b, true)?;
        let mut x = rhs.duplicate()?;
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
    ProblemError::NoSolution {
        sought: "the Krylov solve on the ranks",
        why: e.to_string(),
    }
}

impl Factorization for Krylov<'_> {
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64]) -> Result<(Fields, usize), ProblemError> {
        let b: Vec<f64> = b_u.iter().chain(b_phi).copied().collect();
        let mut x = self.solve_whole(&b).map_err(problem)?;
        let phi = x.split_off(self.n_u);
        Ok(((x, phi), 0))
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
    fn refine(&mut self, _: linalg::Rhs<'_>, _: &mut [f64], _: &mut [f64], _: f64) -> Result<usize, ProblemError> {
        Ok(0)
    }

    fn equilibrium(&mut self, u: &[f64], phi: &[f64], rhs: linalg::Rhs<'_>) -> Result<f64, ProblemError> {
        let x: Vec<f64> = u.iter().chain(phi).copied().collect();
        let b: Vec<f64> = rhs.u.iter().chain(rhs.phi).copied().collect();
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
        let b: Vec<f64> = b_u.iter().chain(b_phi).copied().collect();
        let x = self
            .solve_whole(&b)
            .map_err(|e| linalg::LinalgError::Solver(e.to_string()))?;
        u.copy_from_slice(&x[..self.n_u]);
        phi.copy_from_slice(&x[self.n_u..]);
        Ok(linalg::SolveInfo {
            pcg_iters: self.iterations,
        })
    }

    fn factor_bytes(&self) -> usize {
        0
    }
}

/// Puts the backend's options, then the scene's, into PETSc's database; returns them as one
/// string.
fn configure(petsc: &Petsc, scene: &Scene, layout: &Layout, contact_tol: Option<f64>) -> Result<String, PetscError> {
    let mut all = if layout.has_phi.iter().any(|&p| p) {
        let mut o = COUPLED_OPTIONS.to_owned();
        if !petsc.has_package("hypre")? {
            o = o.replace("-fieldsplit_phi_pc_type hypre", "-fieldsplit_phi_pc_type gamg");
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
/// potentials.
pub(crate) struct KrylovFields {
    dim: usize,
    u_rows: Vec<Index>,
    phi_rows: Vec<Index>,
    coords: Vec<f64>,
    coupled: bool,
}

impl KrylovFields {
    fn new(petsc: &Petsc, setup: &Setup, layout: &Layout) -> Self {
        let dim = layout.dim;
        let (mut u_rows, mut phi_rows, mut coords) = (vec![], vec![], vec![]);
        for v in layout.owned_nodes(petsc.rank()) {
            let f = layout.first[v];
            u_rows.extend((0..dim).map(|k| (f + k) as Index));
            coords.extend_from_slice(&setup.mesh.points[v][..dim]);
            if layout.has_phi[v] {
                phi_rows.push((f + dim) as Index);
            }
        }
        KrylovFields {
            dim,
            u_rows,
            phi_rows,
            coords,
            coupled: layout.has_phi.iter().any(|&p| p),
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

/// The cells each rank assembled.
fn per_rank(petsc: &Petsc, layout: &Layout) -> Result<Vec<usize>, PetscError> {
    let mine = layout.cell_rank.iter().filter(|&&r| r == petsc.rank()).count();
    Ok(petsc.all_gather(mine as u64)?.into_iter().map(|c| c as usize).collect())
}

/// Bytes per unknown on its rank in a run of the PETSc backend: the matrix, its copy for a
/// contact step, the field split's blocks and both multigrid hierarchies (measured on
/// `paper-3d` with Coulomb friction: 5.4 KB at n = 64 on 2 ranks; docs/performance.md).
const BYTES_PER_UNKNOWN: f64 = 5.0e3;
/// Bytes per cell that every rank holds in a run of the PETSc backend (the mesh, its geometry
/// and dof map are built whole on each rank: 100 MB for 393k cells measured, taken low).
const BYTES_PER_CELL: f64 = 200.0;

/// The estimate of each rank's peak memory in a run of the PETSc backend on `ranks` ranks, in
/// bytes, with what it counts; `None` for a Gmsh mesh.
fn per_rank_estimate(scene: &Scene, ranks: usize) -> Option<(f64, String)> {
    let (_, _, cells, unknowns) = problem::backend::generated_sizes(scene)?;
    let share = unknowns / ranks.max(1) as f64;
    let bytes = BYTES_PER_UNKNOWN * share + BYTES_PER_CELL * cells;
    Some((
        bytes,
        format!(
            "on each of {ranks} ranks: {share:.3e} of the {unknowns:.3e} unknowns, and the whole mesh of {cells:.3e} cells"
        ),
    ))
}
