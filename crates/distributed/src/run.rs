//! A run on the ranks: set up, partition, assemble, solve, gather and recover on rank 0.

use crate::contact::{active_set, ActiveSetError, ActiveSetParams, ContactRows, LinearSolve};
use crate::layout::Layout;
use crate::system::{assemble, System};
use fe_assembly::{Discretization, Dof};
use petsc::{Index, IndexSet, Ksp, Matrix, Petsc, PetscError};
use problem::boundary::ContactBoundary;
use problem::report::{
    ContactReport, DofsReport, Iterations, Memory, MeshReport, Residuals, SceneReport, SolverReport, Timings,
};
use problem::run::{begin, recover};
use problem::setup::Setup;
use problem::{ContactLaw, ContactResult, Event, PetscReport, ProblemError, Reporter, RunReport, Scene, Solution};

/// Steps of the active-set iteration at most.
pub const MAX_ACTIVE_SET_STEPS: usize = 60;
use std::time::Instant;

/// What can stop a run of the PETSc backend.
#[derive(Debug, thiserror::Error)]
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
/// anything is built ([`problem::estimate::petsc_per_rank`]). Only rank 0 should pass a
/// reporter that prints.
///
/// # Errors
/// The default backend's errors for the scene and its data; PETSc's (a Krylov solve that did
/// not converge among them) as [`DistributedError::Petsc`].
pub fn solve<'p>(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    petsc: &'p Petsc,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DistributedError> {
    scene.validate()?;
    let t_total = Instant::now();
    let estimate = problem::estimate::petsc_per_rank(scene, petsc.size());
    let setup = begin(scene, mesh, estimate, &limits, reporter)?;
    let t_setup = t_total.elapsed().as_secs_f64();
    let t = Instant::now();
    let disc = Discretization::new(&setup.mesh, &setup.materials, &setup.constraints)?;
    let (layout, mut system) = distribute(petsc, scene, &setup, &disc)?;
    let t_assembly = t.elapsed().as_secs_f64();
    reporter.event(&Event::assembled(&setup.mesh, &disc.dofs, t_assembly));
    let options = configure(petsc, scene, &setup, &layout)?;
    let fields = Fields::new(petsc, &setup, &layout);
    let t = Instant::now();
    let mut t_pc = 0.0;
    let mut solve_one = |m: &mut Matrix<'p>, b: &petsc::Vector<'p>, x: &mut petsc::Vector<'p>| {
        let t = Instant::now();
        let mut ksp = fields.krylov(petsc, m)?;
        t_pc += t.elapsed().as_secs_f64();
        let info = ksp.solve(b, x)?;
        Ok((info.iterations, info.reason))
    };
    let (x, contact, krylov, reason) = match &setup.plan.contact_law {
        ContactLaw::None => solve_linear(&mut system, &mut solve_one)?,
        _ => solve_contact(petsc, scene, &setup, &disc, &layout, &system, &mut solve_one, reporter)?,
    };
    let t_solve = t.elapsed().as_secs_f64() - t_pc;
    reporter.event(&Event::Krylov {
        iterations: krylov,
        reason: &reason,
        setup_seconds: t_pc,
    });
    let equilibrium = residual(&system, &x, contact.as_ref(), &layout, petsc)?;
    reporter.event(&Event::Solved {
        seconds: t_solve,
        pcg_iters: 0,
        equilibrium,
    });
    let (nonzeros, _) = system.matrix.local_info()?;
    let nonzeros = petsc.sum(&[nonzeros])?[0];
    let gathered = x.gather()?;
    let cells_per_rank = per_rank(petsc, &layout)?;
    let Some(x) = gathered else {
        return Ok(None);
    };
    let (u_free, phi_free) = unpermute(&disc, &layout, &x);
    ProblemError::check_finite(&u_free, "the displacement", scene)?;
    ProblemError::check_finite(&phi_free, "the potential", scene)?;
    let recovered = recover(
        scene,
        &setup,
        &disc,
        (&u_free, &phi_free),
        contact.as_ref().map(|(b, sol)| (b, sol)),
        equilibrium,
        reporter,
    )?;
    let times = Timings {
        setup: t_setup,
        assembly: t_assembly,
        factorization: t_pc,
        condense: 0.0,
        contact: if contact.is_some() { t_solve } else { 0.0 },
        solve: t_solve,
        total: t_total.elapsed().as_secs_f64(),
    };
    let petsc_report = petsc_report(
        petsc,
        &layout,
        (nonzeros, krylov, t_pc),
        reason,
        options,
        cells_per_rank,
    );
    let info = contact.as_ref().map(|(_, sol)| &sol.info);
    let report = Report {
        equilibrium,
        exact: recovered.exact,
        contact: recovered.contact,
        info,
        timings_s: times,
        petsc: petsc_report,
    }
    .run_report(scene, &setup, &disc);
    Ok(Some(Solution {
        report,
        mesh: setup.mesh,
        u: recovered.u,
        phi: recovered.phi,
        fields: recovered.fields,
        contact: contact.map(contact_result),
    }))
}

/// The dofs laid out over the ranks, and the system assembled on them (the loads checked
/// finite, the Dirichlet conditions checked to hold the body).
fn distribute<'p>(
    petsc: &'p Petsc,
    scene: &Scene,
    setup: &Setup,
    disc: &Discretization<'_>,
) -> Result<(Layout, System<'p>), DistributedError> {
    disc.check_held().map_err(fe_assembly::AssemblyError::from)?;
    let (b_u, b_phi) = disc.rhs(&setup.loads)?;
    ProblemError::check_finite(&b_u, "the mechanical load vector", scene)?;
    ProblemError::check_finite(&b_phi, "the electric load vector", scene)?;
    let layout = Layout::new(petsc, &setup.mesh, &disc.dofs)?;
    let system = assemble(petsc, disc, &layout, &b_u, &b_phi)?;
    Ok((layout, system))
}

/// The PETSc section of the report: the layout, the matrix's `nonzeros`, the Krylov
/// iterations and the preconditioners' set-up time (`counts`), and the options in force.
fn petsc_report(
    petsc: &Petsc,
    layout: &Layout,
    (nonzeros, krylov, t_pc): (f64, usize, f64),
    reason: String,
    options: String,
    cells_per_rank: Vec<usize>,
) -> PetscReport {
    PetscReport {
        ranks: petsc.size(),
        unknowns: layout.n_global(),
        nonzeros,
        krylov_iterations: krylov,
        reason,
        options,
        cells_per_rank,
        unknowns_per_rank: (0..petsc.size()).map(|r| layout.owned(r).len()).collect(),
        peak_bytes_per_rank: vec![],
        preconditioner_setup_s: t_pc,
    }
}

/// The contact part of the solution, from the boundary and the contact solve.
fn contact_result((b, solution): (ContactBoundary, contact::ContactSolution)) -> ContactResult {
    let displacement = solution.u.clone();
    ContactResult {
        points: b.points,
        nodes: b.nodes,
        solution,
        displacement,
    }
}

/// A solve's vector, its contact boundary and solution (with contact), its Krylov iterations
/// and the last solve's reason.
type Solved<'p> = (
    petsc::Vector<'p>,
    Option<(ContactBoundary, contact::ContactSolution)>,
    usize,
    String,
);

/// The linear problem (no contact) on the PETSc backend: one Krylov solve.
fn solve_linear<'p>(
    system: &mut System<'p>,
    solve_one: &mut LinearSolve<'_, 'p>,
) -> Result<Solved<'p>, DistributedError> {
    let mut x = system.rhs.duplicate()?;
    let (its, reason) = solve_one(&mut system.matrix, &system.rhs, &mut x)?;
    Ok((x, None, its, reason))
}

/// The contact problem on the PETSc backend: the contact boundary (a held tangent refused by
/// name), then the active-set iteration over the distributed system.
#[allow(clippy::too_many_arguments)]
fn solve_contact<'p>(
    petsc: &'p Petsc,
    scene: &Scene,
    setup: &Setup,
    disc: &Discretization<'_>,
    layout: &Layout,
    system: &System<'p>,
    solve_one: &mut LinearSolve<'_, 'p>,
    reporter: &mut dyn Reporter,
) -> Result<Solved<'p>, DistributedError> {
    let spec = scene.contact.as_ref().ok_or_else(|| {
        ProblemError::from(problem::SceneError::new(
            "contact",
            "the plan has contact and the scene no [contact]",
        ))
    })?;
    let boundary = ContactBoundary::new(&setup.mesh, &disc.dofs, spec)?;
    boundary.report_held(&spec.group, reporter);
    if let Some(node) = boundary.first_held_tangent() {
        return Err(ProblemError::from(problem::SceneError::new(
            "contact.group",
            format!(
                "node {node} of contact group `{}` has a tangential component prescribed by a Dirichlet condition (a roller or symmetry plane through the contact face): the PETSc backend's active sets do not hold a tangent of a contact point; the default backend does",
                spec.group
            ),
        ))
        .into());
    }
    let law = setup.plan.law(scene, boundary.points.len());
    let rows = ContactRows::new(petsc, &boundary.points, &boundary.nodes, layout, system);
    let params = ActiveSetParams {
        tol: scene.solver.tol,
        max_steps: MAX_ACTIVE_SET_STEPS,
    };
    let tol = scene.solver.tol;
    let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
    let out =
        active_set(petsc, layout, system, &rows, &law, params, solve_one, &mut progress).map_err(|e| match e {
            ActiveSetError::Petsc(p) => DistributedError::Petsc(p),
            other => DistributedError::Contact(other),
        })?;
    Ok((out.x, Some((boundary, out.solution)), out.krylov_iterations, out.reason))
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
        let rtol = (1e-2 * scene.solver.tol).min(1e-10);
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

/// The parts of the run's report that the run measured.
struct Report<'a> {
    equilibrium: f64,
    exact: Option<problem::exact::ExactReport>,
    contact: ContactReport,
    info: Option<&'a contact::ContactInfo>,
    timings_s: Timings,
    petsc: PetscReport,
}

impl Report<'_> {
    /// The run's report, as the default backend writes it, with the PETSc section.
    fn run_report(self, scene: &Scene, setup: &Setup, disc: &Discretization<'_>) -> RunReport {
        RunReport {
            scene: SceneReport::of(scene),
            plan: setup.plan.clone(),
            mesh: MeshReport::of(scene, setup),
            dofs: DofsReport {
                u: disc.dofs.n_u,
                phi: disc.dofs.n_phi,
            },
            contact: self.contact,
            exact: self.exact,
            iterations: Iterations::of(self.info, 0),
            residuals: Residuals {
                equilibrium: self.equilibrium,
                complementarity: self.info.map_or(0.0, |i| i.complementarity),
                converged_to_tolerance: self.equilibrium <= problem::EQUILIBRIUM_TOL
                    && self.info.is_none_or(|i| i.complementarity <= scene.solver.tol),
            },
            timings_s: self.timings_s,
            memory: Memory::default(),
            solver: SolverReport {
                strategy: scene.solver.strategy,
                rule: problem::report::rule_in_words(setup.plan.rule).into(),
                tol: scene.solver.tol,
                pcg_rel_tol: 0.0,
                ..SolverReport::of(self.info)
            },
            petsc: Some(self.petsc),
        }
    }
}
