//! What the PETSc backend solves, told from the scene alone (no PETSc needed: the program built
//! without the feature tells a user what the backend would refuse before they build it).
//!
//! Since its runs with contact factor `K` by MUMPS and run the default backend's contact
//! solvers on the contact dofs' Schur complement (the run's instants, `problem::Instants`), it
//! solves every scene the default backend solves: every law, path, indenter, terminal and
//! strategy. It refuses only a scene that asks for the default backend, and PETSc's options
//! where the run does not take them ([`direct`]).

use problem::backend::Unsupported;
use problem::{BackendChoice, Scene, Strategy};

const BACKEND: &str = "petsc";

/// Whether the PETSc backend solves `scene` (a valid scene): the first thing it lacks, by key.
///
/// # Errors
/// [`Unsupported`] naming the key (`solver.backend`, where the scene asks for the default
/// backend).
pub fn supports(scene: &Scene) -> Result<(), Unsupported> {
    if scene.solver.backend != BackendChoice::Petsc {
        return Err(Unsupported::new(
            BACKEND,
            "solver.backend",
            format!(
                "solver.backend = \"{}\" is the default backend's (problem::solve)",
                scene.solver.backend
            ),
        )
        .advise("set solver.backend = \"petsc\""));
    }
    if direct(scene) && scene.solver.petsc_options.is_some() {
        // options for the Krylov solvers, which this run does not use: not ignored silently
        return Err(Unsupported::new(
            BACKEND,
            "solver.petsc_options",
            "options for PETSc's Krylov solvers in a run that factors K by MUMPS (a run with contact, a floating terminal or a body of revolution), which takes none",
        )
        .advise("remove solver.petsc_options"));
    }
    Ok(())
}

/// Whether a run of `scene` factors `K` by MUMPS rather than solving by Krylov: a run with
/// contact (its condensed route; the paper's Uzawa with one Schur-complement solve per step
/// excepted, which solves by Krylov as the paper does), a floating terminal (one potential for
/// many nodes, which the Krylov route's node-by-node rows do not hold), a body of revolution
/// (whose rigid-body modes are not those the multigrid is given).
pub fn direct(scene: &Scene) -> bool {
    let contact = !scene.zones().is_empty() && scene.solver.strategy != Strategy::UzawaSchurPcg;
    let floating =
        scene.dirichlet.iter().any(|d| d.charge.is_some()) || scene.electrodes().iter().any(|e| e.charge.is_some());
    contact || floating || scene.mesh.axisymmetric
}
