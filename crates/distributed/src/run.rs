//! A run on the ranks: the PETSc backend of [`problem::run`]. It partitions and assembles the
//! system in parallel, configures the Krylov solvers, solves by one Krylov solve or by the
//! active-set iteration, and gathers the solution on rank 0; the run around it (set-up,
//! contact boundary, checks, recovery, report) is the default backend's.

use crate::contact::{active_set, ActiveSetError, ActiveSetParams, ContactRows};
use crate::layout::Layout;
use crate::system::{assemble, System};
use fe_assembly::{Discretization, Dof};
use petsc::{Index, IndexSet, Ksp, Matrix, Petsc, PetscError, Vector};
use problem::backend::Fields as Free;
use problem::backend::{
    At, Backend, Contact, ContactBoundary, ContactSolve, Figures, InstantOf, InstantSolution, Posed, Primed, Setup,
    Unsupported,
};
use problem::{ContactLaw, Event, PetscReport, ProblemError, Reporter, Scene, Solution};
use std::time::Instant;

/// Steps of the active-set iteration at most.
pub const MAX_ACTIVE_SET_STEPS: usize = 60;

/// What can stop a run of the PETSc backend.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DistributedError {
    /// The scene, its mesh or its data (as the default backend reports them).
    #[error(transparent)]
    Problem(#[from] ProblemError),
    /// PETSc or MPI.
    #[error(transparent)]
    Petsc(#[from] PetscError),
    /// The contact iteration did not converge.
    #[error("contact: {0}")]
    Contact(ActiveSetError),
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

/// The backend's choices, as options of PETSc's database (the scene's `solver.petsc_options`
/// come after them and win). With potentials: FGMRES outside (the preconditioner is not a
/// fixed linear map when its blocks are multigrid cycles), the upper-triangular Schur
/// factorisation of the potentials, `selfp` (`B + G diag(A)⁻¹ Gᵀ`) for the Schur complement,
/// one GAMG cycle (smoothed aggregation with the rigid-body modes) for the elastic block and
/// one BoomerAMG cycle (hypre) for the Schur block, where PETSc has hypre, else GAMG. Without
/// potentials: CG with GAMG. Chosen by measurement on `paper-3d` (docs/performance.md): the
/// full factorisation with GAMG on both blocks took 2.6 times as long.
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
/// The default backend's errors for the scene and its data; PETSc's (a Krylov solve that did
/// not converge among them) as [`DistributedError::Petsc`].
pub fn solve(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    petsc: &Petsc,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DistributedError> {
    problem::run(&mut DistributedMemory { petsc }, scene, mesh, limits, reporter)
}

/// The backend named for its role: the ranks of an MPI run, each its own memory
/// (`solver.backend = "petsc"`, after the library that runs it), on the ranks of `petsc`.
pub struct DistributedMemory<'p> {
    /// PETSc, initialised on the ranks of the run.
    pub petsc: &'p Petsc,
}

/// The dofs laid out over the ranks, and the system assembled on them.
pub struct Assembled<'p> {
    layout: Layout,
    system: System<'p>,
}

/// The assembled system with its Krylov solvers configured, and what the solves measured.
pub struct Prepared<'p> {
    layout: Layout,
    system: System<'p>,
    fields: Fields,
    /// The options in force.
    options: String,
    /// Wall time of the preconditioners' set-up, s.
    t_pc: f64,
    /// Krylov iterations, and the last solve's reason.
    krylov: usize,
    reason: String,
    /// The instant's contact boundary ([`Backend::prime`]).
    boundary: Option<ContactBoundary>,
    /// The last contact solve's solution, until its fields are taken.
    x: Option<Vector<'p>>,
}

impl<'p> Backend for DistributedMemory<'p> {
    const NAME: &'static str = "petsc";
    type Assembled = Assembled<'p>;
    type System = Prepared<'p>;
    type Error = DistributedError;
    const HELD_TO_TOLERANCE: bool = false;

    fn supports(&self, scene: &Scene) -> Result<(), Unsupported> {
        crate::supports(scene)
    }

    fn estimate(&self, scene: &Scene) -> Option<(f64, String)> {
        per_rank_estimate(scene, self.petsc.size())
    }

    fn assemble(&mut self, posed: &Posed<'_>) -> Result<Assembled<'p>, DistributedError> {
        let layout = Layout::new(self.petsc, &posed.setup.mesh, &posed.disc.dofs)?;
        let system = assemble(self.petsc, posed.disc, &layout, &posed.loads.b_u, &posed.loads.b_phi)?;
        Ok(Assembled { layout, system })
    }

    fn prepare(
        &mut self,
        posed: &Posed<'_>,
        Assembled { layout, system }: Assembled<'p>,
        _: Option<&ContactBoundary>,
        _: problem::Limits,
        _: &mut dyn Reporter,
    ) -> Result<Prepared<'p>, DistributedError> {
        if posed.bed.is_some() {
            // a compliant bed is refused by supports(); a body only it holds is refused here too
            let feature = "a body that only its compliant bed holds (the springs that hold it in K)";
            return Err(ProblemError::from(Unsupported::new("petsc", "contact.compliance", feature)).into());
        }
        let options = configure(self.petsc, &posed.scene, posed.setup, &layout)?;
        let fields = Fields::new(self.petsc, posed.setup, &layout);
        Ok(Prepared {
            layout,
            system,
            fields,
            options,
            t_pc: 0.0,
            krylov: 0,
            reason: String::new(),
            boundary: None,
            x: None,
        })
    }

    /// Nothing is kept from instant to instant: each solve is on the whole system (a path's
    /// parts are refused, as `supports` refuses a path).
    fn begin(
        &mut self,
        _: &mut Prepared<'p>,
        _: &Posed<'_>,
        _: Option<Contact<'_>>,
        parts: &[Free],
        _: &mut dyn Reporter,
    ) -> Result<Vec<Free>, DistributedError> {
        match parts.is_empty() {
            true => Ok(vec![]),
            false => Err(ProblemError::from(crate::supports::path_unsupported()).into()),
        }
    }

    fn respond(&mut self, _: &mut Prepared<'p>, _: &[f64], _: &[f64]) -> Result<Free, DistributedError> {
        Err(ProblemError::from(crate::supports::path_unsupported()).into())
    }

    /// The instant's boundary, kept for its active sets (its loads are the assembled ones: a
    /// path's factors and a bed's springs are refused).
    fn prime(&mut self, s: &mut Prepared<'p>, primed: Primed<'_>) -> Result<(), DistributedError> {
        if primed.factors.is_some() {
            return Err(ProblemError::from(crate::supports::path_unsupported()).into());
        }
        s.boundary = Some(primed.framed.boundary.clone());
        Ok(())
    }

    /// The active-set iteration over the distributed system, each step one Krylov solve (a
    /// tangent of a contact point held by a Dirichlet condition refused by name).
    fn solve_posed(
        &mut self,
        s: &mut Prepared<'p>,
        how: &ContactSolve<'_>,
        at: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<contact::ContactSolution, DistributedError> {
        let boundary = s.boundary.as_ref().ok_or_else(unprimed)?;
        refuse_held_tangent(how.scene, boundary)?;
        let rows = ContactRows::new(self.petsc, at.points, &boundary.nodes, &s.layout, &s.system);
        let params = ActiveSetParams {
            tol: how.tol,
            max_steps: MAX_ACTIVE_SET_STEPS,
        };
        let tol = how.tol;
        let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
        let mut solve_one = krylov_solve(self.petsc, &s.fields, &mut s.t_pc);
        let out = active_set(
            self.petsc,
            &s.layout,
            &s.system,
            &rows,
            &how.law,
            params,
            &mut solve_one,
            &mut progress,
        )
        .map_err(|e| match e {
            ActiveSetError::Petsc(p) => DistributedError::Petsc(p),
            other => DistributedError::Contact(other),
        })?;
        drop(solve_one);
        (s.krylov, s.reason) = (out.krylov_iterations, out.reason);
        s.report_krylov(reporter);
        s.x = Some(out.x);
        Ok(out.solution)
    }

    fn own_scale(&self, _: &Prepared<'p>, _: &[f64]) -> f64 {
        0.0
    }

    /// One Krylov solve without contact; with contact, the contact solve's solution. Its
    /// equilibrium residual (collective), then the solution gathered on rank 0.
    fn instant_fields(
        &mut self,
        s: &mut Prepared<'p>,
        posed: &Posed<'_>,
        contact: Option<InstantOf<'_>>,
        reporter: &mut dyn Reporter,
    ) -> Result<Option<InstantSolution>, DistributedError> {
        let (x, contact) = match contact {
            None => {
                let mut x = s.system.rhs.duplicate()?;
                (s.krylov, s.reason) =
                    krylov_solve(self.petsc, &s.fields, &mut s.t_pc)(&mut s.system.matrix, &s.system.rhs, &mut x)?;
                s.report_krylov(reporter);
                (x, None)
            }
            Some(InstantOf { framed, sol, .. }) => {
                let x = s.x.take().ok_or_else(unprimed)?;
                (x, Some((framed.boundary.clone(), sol)))
            }
        };
        let equilibrium = residual(&s.system, &x, contact.as_ref(), &s.layout, self.petsc)?;
        let Some(gathered) = x.gather()? else {
            return Ok(None);
        };
        Ok(Some(InstantSolution {
            x: unpermute(posed.disc, &s.layout, &gathered),
            contact: contact.map(|(_, sol)| sol),
            equilibrium,
            pcg_iters: 0,
        }))
    }

    /// The PETSc section of the report (collective).
    fn finish(&mut self, s: Prepared<'p>) -> Result<Figures, DistributedError> {
        let petsc = self.petsc;
        let (nonzeros, _) = s.system.matrix.local_info()?;
        let nonzeros = petsc.sum(&[nonzeros])?[0];
        let cells_per_rank = per_rank(petsc, &s.layout)?;
        let report = PetscReport {
            ranks: petsc.size(),
            unknowns: s.layout.n_global(),
            nonzeros,
            krylov_iterations: s.krylov,
            reason: s.reason,
            options: s.options,
            cells_per_rank,
            unknowns_per_rank: (0..petsc.size()).map(|r| s.layout.owned(r).len()).collect(),
            peak_bytes_per_rank: vec![],
            preconditioner_setup_s: s.t_pc,
        };
        Ok(Figures {
            factor_seconds: s.t_pc,
            petsc: Some(report),
            ..Figures::default()
        })
    }
}

/// A step out of the run's order (a solve before the instant was posed).
fn unprimed() -> DistributedError {
    ProblemError::NoSolution {
        sought: "the contact solve",
        why: "the backend was asked for an instant it was not given (prime comes first)".into(),
    }
    .into()
}

impl Prepared<'_> {
    /// Reports the last Krylov solve's figures.
    fn report_krylov(&self, reporter: &mut dyn Reporter) {
        reporter.event(&Event::Krylov {
            iterations: self.krylov,
            reason: &self.reason,
            setup_seconds: self.t_pc,
        });
    }
}

/// One Krylov solve with the options in force, the preconditioner's set-up time added to
/// `t_pc`.
fn krylov_solve<'a, 'p: 'a>(
    petsc: &'p Petsc,
    fields: &'a Fields,
    t_pc: &'a mut f64,
) -> impl FnMut(&mut Matrix<'p>, &Vector<'p>, &mut Vector<'p>) -> Result<(usize, String), PetscError> + 'a {
    move |m, b, x| {
        let t = Instant::now();
        let mut ksp = fields.krylov(petsc, m)?;
        *t_pc += t.elapsed().as_secs_f64();
        let info = ksp.solve(b, x)?;
        Ok((info.iterations, info.reason))
    }
}

/// The active sets hold the normal and tangential components of a contact point as unknowns
/// of the system: a tangent prescribed by a Dirichlet condition is refused, naming its node.
fn refuse_held_tangent(scene: &Scene, boundary: &ContactBoundary) -> Result<(), ProblemError> {
    let (Some(node), Some(spec)) = (boundary.first_held_tangent(), scene.active_contact()) else {
        return Ok(());
    };
    // found once the mesh is read (the scene alone does not tell it): the backend's refusal
    Err(Unsupported::new(
        "petsc",
        "contact.group",
        format!(
            "node {node} of contact group `{}` has a tangential component prescribed by a Dirichlet condition (a roller or symmetry plane through the contact face), and its active sets do not hold a tangent of a contact point",
            spec.group
        ),
    )
    .advise("the default backend does: remove solver.backend")
    .into())
}

/// Puts the backend's options, then the scene's, into PETSc's database; returns them as one
/// string.
fn configure(petsc: &Petsc, scene: &Scene, setup: &Setup, layout: &Layout) -> Result<String, PetscError> {
    let mut all = if layout.has_phi.iter().any(|&p| p) {
        let mut o = COUPLED_OPTIONS.to_owned();
        if !petsc.has_package("hypre")? {
            o = o.replace("-fieldsplit_phi_pc_type hypre", "-fieldsplit_phi_pc_type gamg");
        }
        o
    } else {
        ELASTIC_OPTIONS.to_owned()
    };
    if setup.plan.contact_law == ContactLaw::Coulomb && setup.plan.friction && all.starts_with(ELASTIC_OPTIONS) {
        // Coulomb's slip rows make the system unsymmetric: GMRES instead of CG
        all.push_str(" -ksp_type gmres -ksp_gmres_restart 200");
    }
    if setup.plan.contact_law != ContactLaw::None {
        // the multipliers are reactions of the Krylov solution: its error bounds the
        // complementarity residual, which must reach solver.tol
        let rtol = (1e-2 * setup.plan.tol).min(1e-10);
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
struct Fields {
    dim: usize,
    u_rows: Vec<Index>,
    phi_rows: Vec<Index>,
    coords: Vec<f64>,
    coupled: bool,
}

impl Fields {
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
        Fields {
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
    fn krylov<'p>(&self, petsc: &'p Petsc, matrix: &mut Matrix<'p>) -> Result<Ksp<'p>, PetscError> {
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

/// `|K x - b - f_c| / max(|loads|, |f_c|)` over all unknowns, with `f_c` the contact forces
/// of the multipliers (the prescribed rows hold exactly), as the default backend measures it.
fn residual(
    system: &System<'_>,
    x: &petsc::Vector<'_>,
    contact: Option<&(ContactBoundary, contact::ContactSolution)>,
    layout: &Layout,
    petsc: &Petsc,
) -> Result<f64, PetscError> {
    let mut r = system.reactions(x)?;
    let mut scale = system.load_norm;
    if let Some((b, sol)) = contact {
        // the points' forces, each added once, by the rank that owns its node
        let forces = b.forces(&sol.lambda);
        scale = scale.max(forces.iter().map(|f| f * f).sum::<f64>().sqrt());
        let dim = layout.dim;
        let (mut idx, mut vals) = (vec![], vec![]);
        for (i, &node) in b.nodes.iter().enumerate() {
            if layout.node_rank[node] == petsc.rank() {
                for k in 0..dim {
                    idx.push((layout.first[node] + k) as Index);
                    vals.push(-forces[i * dim + k]);
                }
            }
        }
        r.add_values(&idx, &vals)?;
        r.assemble()?;
    }
    let scale = if scale > 0.0 { scale } else { 1.0 };
    Ok(r.norm()? / scale)
}

/// The cells each rank assembled.
fn per_rank(petsc: &Petsc, layout: &Layout) -> Result<Vec<usize>, PetscError> {
    let mine = layout.cell_rank.iter().filter(|&&r| r == petsc.rank()).count();
    Ok(petsc.all_gather(mine as u64)?.into_iter().map(|c| c as usize).collect())
}

/// The distributed solution (global order of the layout) as the free unknowns of the
/// discretisation, `(u, φ)`.
fn unpermute(disc: &Discretization<'_>, layout: &Layout, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let d = &disc.dofs;
    let (mut u, mut phi) = (vec![0.0; d.n_u], vec![0.0; d.n_phi]);
    for v in 0..layout.first.len() {
        let f = layout.first[v];
        for k in 0..layout.dim {
            if let Dof::Free(j) = d.u[v * layout.dim + k] {
                u[j] = x[f + k];
            }
        }
        if let Dof::Free(j) = d.phi[v] {
            phi[j] = x[f + layout.dim];
        }
    }
    (u, phi)
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
