//! A run on the ranks: the PETSc backend of [`problem::run`]. It partitions the cells among
//! the ranks and, on them, either factors `K` by MUMPS (any run with contact: [`Direct`], the
//! contact dofs' Schur complement for the instants' condensed route, the default backend's
//! contact solvers on it) or assembles a parallel matrix for Krylov solves with algebraic
//! multigrid (a run without contact: `Krylov`). Every rank holds the whole solution of each
//! instant (the mesh is whole on every rank too); rank 0 returns the run's solution.

use crate::active::ActiveSets;
use crate::direct::Direct;
use crate::error::DistributedError;
use crate::krylov::{configure, Krylov, KrylovFields};
use crate::layout::Layout;
use crate::system::{assemble, System};
use petsc::{Petsc, PetscError};
use problem::backend::{
    At, Backend, Contact, ContactBoundary, ContactSolve, Fields, Figures, InstantOf, InstantSolution, Posed, Primed,
    Unsupported,
};
use problem::{Bytes, Event, Factorization, Instants, PetscReport, ProblemError, Reporter, Scene, Solution, Step};

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

/// The unknowns of a 3D body from which a run with contact that the active sets hold takes
/// them rather than MUMPS' condensed route: measured on `paper-3d` on 2 ranks (one session,
/// run.json's totals; docs/performance.md), the active sets 1.96 / 7.5 / 18.3 s against MUMPS'
/// 1.80 / 12.3 / 61.7 s at 38,148 / 117,500 / 283,140 unknowns (n = 16, 24, 32): the crossover
/// near 50,000, the factorisation's cost growing as the square of the unknowns in 3D, the
/// Krylov solves' as their first power.
pub const ACTIVE_SETS_FROM: f64 = 5.0e4;

/// The share of the unknowns a contact zone (its points that can touch) must hold for a run
/// to take the active sets for speed: an indenter's small zone costs MUMPS' condensed route
/// little and the active sets several steps (a paraboloid in a 3D block of 139,392 unknowns,
/// `indent-sphere-3d` without its symmetry planes at n = 32, 2 ranks: 15.7 s on the active sets
/// in 6 steps, 13.3 s on MUMPS, 9.8 s on the default backend), where a face that touches everywhere (2.2 to
/// 4.4 % of `paper-3d`'s unknowns) costs MUMPS its Schur complement.
pub const ACTIVE_SETS_ZONE: f64 = 0.01;

/// How a run with contact solves it on the ranks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactRoute {
    /// The Krylov route's active sets where they hold the run and either MUMPS' factorisation
    /// would not fit the memory of a rank or the body is 3D with at least
    /// [`ACTIVE_SETS_FROM`] unknowns (where they are the faster); MUMPS' condensed route
    /// otherwise.
    #[default]
    Auto,
    /// MUMPS' condensed route (every law).
    Condensed,
    /// The Krylov route's active sets (the paper's base model, one zone or several; other scenes
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

impl<'p> DistributedMemory<'p> {
    /// Whether a run of `scene` factors `K` by MUMPS ([`crate::factors_directly`]), unless the
    /// factorisation's estimate per rank exceeds the memory each rank may use and the Krylov
    /// route's active sets hold the scene ([`crate::active_sets_hold`]).
    ///
    /// The size is told from `mesh` (with whether the body has potentials) once it is made or
    /// read, before from the scene (a generated mesh; a Gmsh file's size is not known then).
    fn direct_route(&self, scene: &Scene, mesh: Option<(&mesh::Mesh, bool)>) -> bool {
        let held = || crate::active_sets_hold_on(scene, mesh.map(|(m, _)| m)).is_ok();
        crate::factors_directly(scene)
            && match self.contact {
                ContactRoute::Auto => !(self.direct_too_large(scene, mesh) && held()),
                ContactRoute::Condensed => true,
                ContactRoute::ActiveSets => !held(),
            }
    }

    /// Whether MUMPS' factorisation, estimated as the default backend's run shared among the
    /// ranks, exceeds the memory of a rank.
    fn direct_too_large(&self, scene: &Scene, mesh: Option<(&mesh::Mesh, bool)>) -> bool {
        match (
            self.limits.memory_bytes,
            direct_estimate(scene, mesh, self.petsc.size()),
        ) {
            (Some(limit), Some((bytes, _))) => bytes > limit as f64,
            _ => false,
        }
    }

    /// Why a run that MUMPS would factor takes the Krylov route's active sets for speed, in
    /// words, where it does: a run on its own (the route not asked for) of a 3D body of at least
    /// [`ACTIVE_SETS_FROM`] unknowns whose contact zone (the points that can touch) holds at
    /// least [`ACTIVE_SETS_ZONE`] of them, and whose contact they hold in one pass (not force
    /// control's or slip weakening's many: [`crate::repeats_contact_solves`]).
    fn active_sets_for_speed(&self, posed: &Posed<'_>, boundary: Option<&ContactBoundary>) -> Option<String> {
        let unknowns = posed.disc.dofs.n_u + posed.disc.dofs.n_phi;
        let zone = boundary?.condensed_dofs().len();
        let faster = self.contact == ContactRoute::Auto
            && posed.setup.mesh.dim == 3
            && unknowns as f64 >= ACTIVE_SETS_FROM
            && zone as f64 >= ACTIVE_SETS_ZONE * unknowns as f64
            && crate::factors_directly(&posed.scene)
            && !crate::repeats_contact_solves(&posed.scene)
            && crate::active_sets_hold_on(&posed.scene, Some(&posed.setup.mesh)).is_ok();
        faster.then(|| {
            format!(
                "a 3D body of {unknowns:.3e} unknowns, at least {ACTIVE_SETS_FROM:.1e}, with a contact zone of {zone} of them, at least {:.0} %, where the active sets' Krylov solves are faster than MUMPS' factorisation (docs/performance.md)",
                100.0 * ACTIVE_SETS_ZONE
            )
        })
    }

    /// Whether the Krylov route's active sets hold the run of `posed` and their estimate fits
    /// a rank's memory in `limits`.
    fn active_sets_fit(&self, posed: &Posed<'_>, limits: problem::Limits) -> bool {
        let estimate = per_rank_estimate(&posed.scene, Some(on_mesh(posed)), self.petsc.size());
        crate::active_sets_hold_on(&posed.scene, Some(&posed.setup.mesh)).is_ok()
            && match (limits.memory_bytes, estimate) {
                (Some(limit), Some((bytes, _))) => bytes <= limit as f64,
                _ => true,
            }
    }

    /// Why a run with contact that MUMPS would factor takes the active sets, in words.
    fn why_active_sets(&self, posed: &Posed<'_>) -> String {
        let estimate = direct_estimate(&posed.scene, Some(on_mesh(posed)), self.petsc.size());
        match (self.contact, self.limits.memory_bytes, estimate) {
            (ContactRoute::Auto, Some(limit), Some((bytes, what))) => format!(
                "MUMPS' factorisation would need about {} a rank ({what}), more than the {} a rank may use",
                Bytes(bytes),
                Bytes(limit as f64)
            ),
            _ => "asked for".to_string(),
        }
    }

    /// MUMPS' factorisation of `K` of `posed` on the ranks, with the Schur complement of the
    /// contact dofs of `boundary` where the plan condenses, within the memory of `limits`; and
    /// its description. Collective.
    fn factor(
        &self,
        posed: &Posed<'_>,
        layout: &Layout,
        boundary: Option<&ContactBoundary>,
        limits: problem::Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<(Direct<'p>, String), DistributedError> {
        let chosen = match boundary {
            Some(cb) if posed.plan().linear_strategy.is_condensed() => cb.condensed_dofs(),
            _ => vec![],
        };
        let springs = match (posed.bed, boundary) {
            (Some(bed), Some(cb)) => cb.normal_springs(bed.stiffness),
            _ => vec![],
        };
        // every rank holds the dense contact problem whole (its contact solve is each rank's
        // own): MUMPS has what it leaves
        let dense = match boundary {
            Some(cb) if !chosen.is_empty() => cb.dense_bytes(posed.plan().n_tangential()),
            _ => 0.0,
        };
        let memory = limits
            .memory_bytes
            .map(|m| (m as f64 - dense - problem::BASE_BYTES).max(0.0) as u64);
        let k = chosen.len();
        let direct = Direct::new(self.petsc, posed.disc, layout, &springs, chosen, memory)?;
        reporter.event(&Event::Factored {
            seconds: direct.seconds,
        });
        let options = format!(
            "MUMPS (L D Lᵀ on {} ranks, its own C interface; the default backend's nested dissection), the Schur complement of {k} contact dofs; {:.3e} flops, {:.3e} bytes of factors",
            self.petsc.size(),
            direct.factor_flops(),
            direct.factor_bytes()
        );
        Ok((direct, options))
    }
}

/// Whether MUMPS' factorisation of `scene` (its mesh `mesh` where it is read) would exceed
/// `memory_bytes` a rank by the estimate (the default backend's, shared among the `ranks`):
/// where a load path must then walk on pieces, which need no factorisation.
pub fn direct_exceeds(scene: &Scene, mesh: Option<&mesh::Mesh>, ranks: usize, memory_bytes: Option<u64>) -> bool {
    // (a mesh read: with potentials, the larger estimate)
    match (memory_bytes, direct_estimate(scene, mesh.map(|m| (m, true)), ranks)) {
        (Some(limit), Some((bytes, _))) => bytes > limit as f64,
        _ => false,
    }
}

/// The default backend's estimate of its run's peak (the factor, the dense compliance) shared
/// among `ranks`: MUMPS' factorisation on them; on `mesh` where it is known, the larger of the
/// scene's and the mesh's.
fn direct_estimate(scene: &Scene, mesh: Option<(&mesh::Mesh, bool)>, ranks: usize) -> Option<(f64, String)> {
    let shared = problem::SharedMemory;
    let on_mesh = mesh.and_then(|(mesh, electric)| shared.estimate_on_mesh(scene, mesh, electric));
    let (bytes, what) = [Backend::estimate(&shared, scene), on_mesh]
        .into_iter()
        .flatten()
        .max_by(|a, b| a.0.total_cmp(&b.0))?;
    Some((
        bytes / ranks.max(1) as f64,
        format!(
            "on each of {ranks} ranks, its share of MUMPS' factorisation: {what}{}",
            in_parts(scene, mesh.is_some(), ranks)
        ),
    ))
}

/// Where a run of `scene` reads its mesh whole on several ranks and a run on pieces would take
/// it, the way past one rank's memory that is not a coarser mesh: the mesh in parts.
fn in_parts(scene: &Scene, read: bool, ranks: usize) -> &'static str {
    match read && ranks > 1 && crate::pieces_support(scene).is_ok() {
        true => "; saved in one part per rank, the Gmsh mesh runs on pieces instead, no rank holding it whole nor a factorisation (README: \"a Gmsh mesh in parts\")",
        false => "",
    }
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
    /// The Krylov route's active sets, where its run has contact.
    active: Option<ActiveSets<'p>>,
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

    fn agree_beyond(&mut self, found: Option<usize>) -> Result<Option<usize>, DistributedError> {
        // rank 0 holds the fields; -1: no point left out touches
        let mut count = [found.map_or(-1.0, |n| n as f64)];
        self.petsc.broadcast(&mut count)?;
        Ok((count[0] >= 0.0).then_some(count[0] as usize))
    }

    fn supports(&self, scene: &Scene) -> Result<(), Unsupported> {
        crate::supports(scene)?;
        match self.contact {
            ContactRoute::ActiveSets if !scene.zones().is_empty() => crate::active_sets_hold(scene),
            _ => Ok(()),
        }
    }

    fn estimate(&self, scene: &Scene) -> Option<(f64, String)> {
        match self.direct_route(scene, None) {
            true => direct_estimate(scene, None, self.petsc.size()),
            false => per_rank_estimate(scene, None, self.petsc.size()),
        }
    }

    fn estimate_on_mesh(&self, scene: &Scene, mesh: &mesh::Mesh, electric: bool) -> Option<(f64, String)> {
        let mesh = Some((mesh, electric));
        match self.direct_route(scene, mesh) {
            true => direct_estimate(scene, mesh, self.petsc.size()),
            false => per_rank_estimate(scene, mesh, self.petsc.size()),
        }
    }

    fn assemble(&mut self, posed: &Posed<'_>) -> Result<Assembled<'p>, DistributedError> {
        let layout = Layout::new(self.petsc, &posed.setup.mesh, &posed.disc.dofs)?;
        let system = match self.direct_route(&posed.scene, Some(on_mesh(posed))) {
            true => None,
            false => Some(assemble(
                self.petsc,
                posed.disc,
                &layout,
                (&posed.loads.b_u, &posed.loads.b_phi, &[]),
            )?),
        };
        Ok(Assembled { layout, system })
    }

    fn prepare(
        &mut self,
        posed: &Posed<'_>,
        Assembled { layout, system }: Assembled<'p>,
        boundary: Option<&ContactBoundary>,
        limits: problem::Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<Prepared<'p>, DistributedError> {
        let speed = match system {
            None => self.active_sets_for_speed(posed, boundary),
            Some(_) => None,
        };
        let mut why_krylov = None;
        let system = match (system, speed) {
            (Some(system), _) => system,
            (None, Some(why)) => {
                why_krylov = Some(why);
                assemble(
                    self.petsc,
                    posed.disc,
                    &layout,
                    (&posed.loads.b_u, &posed.loads.b_phi, &[]),
                )?
            }
            // options for the Krylov solvers in a run that MUMPS factors: not ignored silently
            (None, None) if posed.scene.solver.petsc_options.is_some() => {
                return Err(ProblemError::from(crate::supports::options_refused()).into())
            }
            (None, None) => match self.factor(posed, &layout, boundary, limits, reporter) {
                Ok((direct, options)) => {
                    return Ok(Prepared {
                        route: Route::Direct(Box::new(direct)),
                        active: None,
                        instants: Instants::default(),
                        layout,
                        options,
                    })
                }
                // MUMPS' own estimate, after its analysis, exceeds a rank's memory (the
                // estimate before the mesh is a lower one), or its allocation failed (what the
                // run took since its start is not in the limits): the Krylov route's active
                // sets where they hold the run
                Err(DistributedError::Petsc(
                    e @ (PetscError::MumpsTooLarge { .. } | PetscError::Mumps { info: -13, .. }),
                )) if self.contact == ContactRoute::Auto && self.active_sets_fit(posed, limits) => {
                    why_krylov = Some(e.to_string());
                    assemble(
                        self.petsc,
                        posed.disc,
                        &layout,
                        (&posed.loads.b_u, &posed.loads.b_phi, &[]),
                    )?
                }
                Err(e) => return Err(e),
            },
        };
        let contact = boundary.is_some();
        let mut options = configure(
            self.petsc,
            &posed.scene,
            &layout,
            contact.then_some(posed.plan().tol),
            false,
        )?;
        // the active sets where the run's contact would have factored by MUMPS; on the Krylov
        // route otherwise (the paper's Uzawa) the instants' full solves
        let active = (contact && crate::factors_directly(&posed.scene)).then(ActiveSets::default);
        if active.is_some() {
            // a route asked for by the library on a mesh whose order only its file told
            crate::active_sets_hold_on(&posed.scene, Some(&posed.setup.mesh)).map_err(ProblemError::from)?;
            let why = why_krylov.unwrap_or_else(|| self.why_active_sets(posed));
            options = format!("{why}: the Krylov route's active sets; {options}");
        }
        // (the paper's Uzawa on this route takes the same tolerance: its multipliers are
        // updated from the solves' displacements)
        let fields = KrylovFields::new(self.petsc, posed.setup, &layout);
        let krylov = Krylov::new(self.petsc, posed.disc, &layout, system, fields);
        Ok(Prepared {
            route: Route::Krylov(Box::new(krylov)),
            active,
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
        if let Some(active) = s.active.as_mut() {
            return active.begin(parts);
        }
        let f = s.route.factorization();
        Ok(s.instants.begin(f, posed, contact, parts, reporter)?)
    }

    fn respond(&mut self, s: &mut Prepared<'p>, a: &[(&[f64], &[f64])]) -> Result<Vec<Fields>, DistributedError> {
        Ok(Instants::respond(s.route.factorization(), a)?)
    }

    fn prime(&mut self, s: &mut Prepared<'p>, primed: Primed<'_>) -> Result<(), DistributedError> {
        if let Some(active) = s.active.as_mut() {
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
        if let (Route::Krylov(k), Some(active)) = (&mut s.route, s.active.as_mut()) {
            return crate::active::solve(active, &s.layout, k, how, at, reporter);
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
        if let (Route::Krylov(k), Some(active), Some(of)) = (&mut s.route, s.active.as_mut(), contact.as_ref()) {
            return crate::active::fields(active, k, &s.layout, posed, of).map(Some);
        }
        let x = s.instants.fields(s.route.factorization(), posed, contact, reporter)?;
        if let Route::Krylov(k) = &s.route {
            k.report(reporter);
        }
        Ok(Some(x))
    }

    /// The direct route's instants' fields come from their loads and multipliers alone; the
    /// active-set route's are its last Krylov solve's.
    fn defers_fields(&self, s: &Prepared<'p>) -> bool {
        !matches!((&s.route, &s.active), (Route::Krylov(_), Some(_)))
    }

    /// The instants' fields, whole on every rank, together ([`Self::defers_fields`]).
    fn frames_fields(
        &mut self,
        s: &mut Prepared<'p>,
        frames: Vec<(Posed<'_>, InstantOf<'_>)>,
        _: &mut dyn Reporter,
    ) -> Result<Vec<Option<InstantSolution>>, DistributedError> {
        let solved = problem::Instants::frames(s.route.factorization(), frames)?;
        Ok(solved.into_iter().map(Some).collect())
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
            pieces: None,
        };
        let factor_rate = match &s.route {
            Route::Direct(d) => Some(d.factor_rate()),
            Route::Krylov(_) => None,
        };
        Ok(Figures {
            factor_seconds: setup,
            factor_rate,
            condense: s.instants.condense,
            refinement_steps: s.instants.refinement,
            factor_bytes,
            petsc: Some(report),
            ..Figures::default()
        })
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
pub(crate) const BYTES_PER_UNKNOWN: f64 = 5.0e3;
/// Bytes per cell that every rank holds in a run of the PETSc backend (the mesh, its geometry
/// and dof map are built whole on each rank: 100 MB for 393k cells measured, taken low).
pub(crate) const BYTES_PER_CELL: f64 = 200.0;

/// The mesh of a posed run, and whether its body has potentials.
fn on_mesh<'a>(posed: &'a Posed<'_>) -> (&'a mesh::Mesh, bool) {
    (&posed.setup.mesh, posed.plan().electric)
}

/// The estimate of each rank's peak memory in a run of the Krylov route on `ranks` ranks, in
/// bytes, with what it counts: on `mesh` where it is known (with whether the body has
/// potentials), else on the scene's generated mesh (`None` for a Gmsh file not yet read).
fn per_rank_estimate(scene: &Scene, mesh: Option<(&mesh::Mesh, bool)>, ranks: usize) -> Option<(f64, String)> {
    let (cells, unknowns) = match mesh {
        Some((mesh, electric)) => (
            mesh.n_cells() as f64,
            (mesh.n_nodes() * (mesh.dim + usize::from(electric))) as f64,
        ),
        None => problem::backend::generated_sizes(scene).map(|(_, _, cells, unknowns)| (cells, unknowns))?,
    };
    let share = unknowns / ranks.max(1) as f64;
    let bytes = BYTES_PER_UNKNOWN * share + BYTES_PER_CELL * cells;
    Some((
        bytes,
        format!(
            "on each of {ranks} ranks: {share:.3e} of the {unknowns:.3e} unknowns, and the whole mesh of {cells:.3e} cells{}",
            in_parts(scene, mesh.is_some(), ranks)
        ),
    ))
}
