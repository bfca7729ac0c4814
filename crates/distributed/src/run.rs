//! A run on the ranks: set up, partition, assemble, solve, gather and recover on rank 0.

use crate::layout::Layout;
use crate::system::{assemble, System};
use fe_assembly::{Discretization, Dof};
use petsc::{Index, IndexSet, Ksp, Petsc, PetscError};
use problem::report::{
    ContactReport, DofsReport, Iterations, Memory, MeshReport, Residuals, SceneReport, SolverReport, Timings,
};
use problem::setup::{setup, MeshNotes, Setup};
use problem::{Event, PetscReport, ProblemError, Reporter, RunReport, Scene, Solution};
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
/// fixed linear map when its blocks are multigrid cycles), the full Schur factorisation of the
/// potentials, `selfp` (`B + G diag(A)⁻¹ Gᵀ`) for the Schur complement, one GAMG cycle for
/// each block. Without: CG with GAMG.
pub const COUPLED_OPTIONS: &str = "-ksp_type fgmres -ksp_gmres_restart 200 -ksp_rtol 1e-10 -ksp_max_it 5000 \
-pc_type fieldsplit -pc_fieldsplit_type schur -pc_fieldsplit_schur_fact_type full \
-pc_fieldsplit_schur_precondition selfp -fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type gamg \
-fieldsplit_phi_ksp_type preonly -fieldsplit_phi_pc_type gamg";

/// See [`COUPLED_OPTIONS`].
pub const ELASTIC_OPTIONS: &str = "-ksp_type cg -ksp_rtol 1e-10 -ksp_max_it 5000 -pc_type gamg";

/// Solves `scene` on the ranks of `petsc`. Every rank calls it (it is collective); rank 0
/// returns the [`Solution`], as [`problem::solve`] gives it, the others `None`. `mesh` is the
/// mesh of a `gmsh` scene, read by the caller on every rank. Only rank 0 should pass a
/// reporter that prints.
///
/// # Errors
/// The default backend's errors for the scene and its data; PETSc's (a Krylov solve that did
/// not converge among them) as [`DistributedError::Petsc`].
pub fn solve(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    petsc: &Petsc,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DistributedError> {
    scene.validate()?;
    let t_total = Instant::now();
    let setup = setup(scene, mesh)?;
    let t_setup = t_total.elapsed().as_secs_f64();
    reporter.event(&Event::Planned(&setup.plan));
    if setup.notes != MeshNotes::default() {
        reporter.event(&Event::MeshNotes(setup.notes));
    }
    let t = Instant::now();
    let disc = Discretization::new(&setup.mesh, &setup.materials, &setup.constraints)?;
    let (b_u, b_phi) = disc.rhs(&setup.loads)?;
    ProblemError::check_finite(&b_u, "the mechanical load vector", scene)?;
    ProblemError::check_finite(&b_phi, "the electric load vector", scene)?;
    let layout = Layout::new(petsc, &setup.mesh, &disc.dofs)?;
    let system = assemble(petsc, &disc, &layout, &b_u, &b_phi)?;
    let t_assembly = t.elapsed().as_secs_f64();
    reporter.event(&Event::Assembled {
        n_nodes: setup.mesh.n_nodes(),
        n_cells: setup.mesh.n_cells(),
        h: setup.mesh.h_max(),
        n_u: disc.dofs.n_u,
        n_phi: disc.dofs.n_phi,
        seconds: t_assembly,
    });
    let options = configure(petsc, scene, &layout)?;
    let mut system = system;
    let (mut ksp, t_pc) = preconditioned(petsc, &setup, &layout, &mut system)?;
    reporter.event(&Event::Factored { seconds: t_pc });
    let t = Instant::now();
    let mut x = system.rhs.duplicate()?;
    let info = ksp.solve(&system.rhs, &mut x)?;
    let t_solve = t.elapsed().as_secs_f64();
    let equilibrium = residual(&system, &x)?;
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
    let u = disc.dofs.expand_u(&u_free);
    let phi = disc.dofs.expand_phi(&phi_free);
    let fields = disc.recover(&u, &phi);
    ProblemError::check_finite(&fields.stress, "the stress", scene)?;
    let exact = setup
        .exact
        .as_ref()
        .map(|ex| ex.errors(&disc, &u, &phi, setup.plan.electric));
    if let Some(e) = &exact {
        reporter.event(&Event::Exact {
            kind: e.kind(),
            what: e.error_name(),
            error: e.error(),
        });
    }
    let times = Timings {
        setup: t_setup,
        assembly: t_assembly,
        factorization: t_pc,
        condense: 0.0,
        contact: 0.0,
        solve: t_solve,
        total: t_total.elapsed().as_secs_f64(),
    };
    let petsc_report = PetscReport {
        ranks: petsc.size(),
        unknowns: layout.n_global(),
        nonzeros,
        krylov_iterations: info.iterations,
        reason: info.reason.clone(),
        options,
        cells_per_rank,
        unknowns_per_rank: (0..petsc.size()).map(|r| layout.owned(r).len()).collect(),
        peak_bytes_per_rank: vec![],
        preconditioner_setup_s: t_pc,
    };
    let report = report(scene, &setup, &disc, equilibrium, exact, times, petsc_report);
    Ok(Some(Solution {
        report,
        mesh: setup.mesh,
        u,
        phi,
        fields,
        contact: None,
    }))
}

/// Puts the backend's options, then the scene's, into PETSc's database; returns them as one
/// string.
fn configure(petsc: &Petsc, scene: &Scene, layout: &Layout) -> Result<String, PetscError> {
    let defaults = if layout.has_phi.iter().any(|&p| p) {
        COUPLED_OPTIONS
    } else {
        ELASTIC_OPTIONS
    };
    petsc.insert_options(defaults)?;
    let mut all = defaults.to_owned();
    if let Some(user) = &scene.solver.petsc_options {
        petsc.insert_options(user)?;
        all.push(' ');
        all.push_str(user);
    }
    Ok(all)
}

/// The Krylov solver for the system, configured from the options database, with the fields
/// (displacements with their rigid-body modes, potentials) named for a field split, and its
/// preconditioner built (timed).
fn preconditioned<'p>(
    petsc: &'p Petsc,
    setup: &Setup,
    layout: &Layout,
    system: &mut System<'p>,
) -> Result<(Ksp<'p>, f64), PetscError> {
    let t = Instant::now();
    let rank = petsc.rank();
    let dim = layout.dim;
    let (mut u_rows, mut phi_rows, mut coords) = (vec![], vec![], vec![]);
    for v in layout.owned_nodes(rank) {
        let f = layout.first[v];
        u_rows.extend((0..dim).map(|k| (f + k) as Index));
        coords.extend_from_slice(&setup.mesh.points[v][..dim]);
        if layout.has_phi[v] {
            phi_rows.push((f + dim) as Index);
        }
    }
    let coupled = layout.has_phi.iter().any(|&p| p);
    if !coupled {
        // the matrix's own near null space (its rows are the nodes' displacements, in order)
        system.matrix.set_rigid_body_modes(dim, &coords)?;
    }
    let mut ksp = Ksp::new(petsc, &system.matrix)?;
    if coupled {
        let mut is_u = IndexSet::new(petsc, &u_rows)?;
        is_u.set_block_size(dim)?;
        is_u.set_rigid_body_modes(dim, &coords)?;
        let is_phi = IndexSet::new(petsc, &phi_rows)?;
        ksp.set_types("fgmres", "fieldsplit")?;
        ksp.set_field("u", &is_u)?;
        ksp.set_field("phi", &is_phi)?;
    }
    ksp.set_from_options()?;
    ksp.set_up()?;
    Ok((ksp, t.elapsed().as_secs_f64()))
}

/// `|K x - b| / |loads|` over all unknowns (the prescribed rows hold exactly).
fn residual(system: &System<'_>, x: &petsc::Vector<'_>) -> Result<f64, PetscError> {
    let mut r = system.rhs.duplicate()?;
    system.matrix.mult(x, &mut r)?;
    r.axpy(-1.0, &system.rhs)?;
    let scale = if system.load_norm > 0.0 { system.load_norm } else { 1.0 };
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

/// The run's report, as the default backend writes it, with the PETSc section.
#[allow(clippy::too_many_arguments)]
fn report(
    scene: &Scene,
    setup: &Setup,
    disc: &Discretization<'_>,
    equilibrium: f64,
    exact: Option<problem::exact::ExactReport>,
    timings_s: Timings,
    petsc: PetscReport,
) -> RunReport {
    RunReport {
        scene: SceneReport {
            name: scene.name.clone(),
            source: scene.name.clone(),
            description: scene.description.clone(),
            settings: scene.clone(),
        },
        plan: setup.plan.clone(),
        mesh: MeshReport {
            n_nodes: setup.mesh.n_nodes(),
            n_cells: setup.mesh.n_cells(),
            h: setup.mesh.h_max(),
            cells_per_axis: scene.mesh.cells_per_axis(),
            reoriented_cells: setup.notes.reoriented_cells,
            coincident_nodes: setup.notes.coincident_nodes,
        },
        dofs: DofsReport {
            u: disc.dofs.n_u,
            phi: disc.dofs.n_phi,
        },
        contact: ContactReport::default(),
        exact,
        iterations: Iterations::of(None, 0),
        residuals: Residuals {
            equilibrium,
            complementarity: 0.0,
            converged_to_tolerance: true,
        },
        timings_s,
        memory: Memory::default(),
        solver: SolverReport {
            strategy: scene.solver.strategy,
            rule: problem::report::rule_in_words(setup.plan.rule).into(),
            tol: scene.solver.tol,
            pcg_rel_tol: 0.0,
            ..SolverReport::of(None)
        },
        petsc: Some(petsc),
    }
}
