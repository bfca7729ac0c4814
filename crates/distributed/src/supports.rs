//! What the PETSc backend solves, told from the scene alone (no PETSc needed: the program built
//! without the feature tells a user what the backend would refuse before they build it).
//!
//! Its contact iteration is a primal-dual active set on the full system, each step one Krylov
//! solve: it holds Signorini's conditions with Coulomb or Tresca friction on one insulating,
//! rigid, flat or indenting zone whose normal is a coordinate axis, at one instant, with a
//! given depth and prescribed potentials, on plane and 3D bodies. Every other law, condition
//! and process of the model family is the default backend's for now; each is refused here by
//! the key that asks for it.

use problem::backend::Unsupported;
use problem::{BackendChoice, ContactSpec, Rule, Scene, Strategy};

const BACKEND: &str = "petsc";

/// What to do instead of a feature the PETSc backend lacks.
const DEFAULT: &str = "use the default backend: remove solver.backend";

/// The backend lacks `feature`, asked for by `key`; the default backend has it.
fn lacks(key: &str, feature: impl Into<String>) -> Result<(), Unsupported> {
    Err(Unsupported::new(BACKEND, key, feature).advise(DEFAULT))
}

/// Whether the PETSc backend solves `scene` (a valid scene): the first thing it lacks, by key.
///
/// # Errors
/// [`Unsupported`] naming the key.
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
    let active = scene.zones();
    if active.len() > 1 {
        return lacks("contact", "several [[contact]] zones (its active sets hold one)");
    }
    if scene.mesh.axisymmetric {
        return lacks(
            "mesh.axisymmetric",
            "a body of revolution (it assembles plane and 3D bodies)",
        );
    }
    let floating = if scene.dirichlet.iter().any(|d| d.charge.is_some()) {
        Some("dirichlet.charge")
    } else if scene.electrodes().iter().any(|e| e.charge.is_some()) {
        Some("electrode.charge")
    } else {
        None
    };
    if let Some(key) = floating {
        return lacks(key, "a floating terminal (it takes prescribed potentials)");
    }
    for c in active {
        contact_zone(c)?;
    }
    if scene.solver.strategy != Strategy::NewtonCondensed {
        return Err(Unsupported::new(
            BACKEND,
            "solver.strategy",
            format!(
                "solver.strategy = \"{}\" (it runs its own contact solver: a primal-dual active set on the full system, Krylov solves)",
                scene.solver.strategy
            ),
        )
        .advise("remove solver.strategy"));
    }
    if scene.solver.rule != Rule::Tight {
        return Err(Unsupported::new(
            BACKEND,
            "solver.rule",
            "the paper's stopping rule (it stops on the complementarity residual; the paper's rule is Uzawa's)",
        )
        .advise("remove solver.rule"));
    }
    if scene.path.is_some() {
        return Err(path_unsupported());
    }
    Ok(())
}

/// A load path: the backend solves one instant (refused here before anything is built, and
/// again by the run's steps should one be asked a path's parts).
pub(crate) fn path_unsupported() -> Unsupported {
    Unsupported::new(
        BACKEND,
        "path",
        "a load path (it solves one instant; a path reuses one factorisation)",
    )
    .advise(DEFAULT)
}

/// What one contact zone asks for that the PETSc backend's active sets do not hold.
fn contact_zone(c: &ContactSpec) -> Result<(), Unsupported> {
    if c.indenter.as_ref().is_some_and(|i| i.force.is_some()) {
        return lacks(
            "contact.indenter.force",
            "force control (its active sets take a given depth)",
        );
    }
    if c.compliance.is_some() {
        return lacks(
            "contact.compliance",
            "a deformable foundation (its active sets hold Signorini's conditions)",
        );
    }
    if c.slip_weakening().is_some() {
        return lacks(
            "contact.friction_law",
            "slip-weakening friction (its active sets hold a constant coefficient)",
        );
    }
    if let Some(condition) = c.electric.filter(|_| c.electric_law().is_some()) {
        return lacks(
            "contact.electric",
            format!("contact.electric = \"{condition}\" (its active sets hold an insulating foundation)"),
        );
    }
    if c.normal.iter().filter(|&&x| x != 0.0).count() != 1 {
        return lacks(
            "contact.normal",
            format!(
                "contact.normal = {:?}, an oblique face (its contact iteration holds displacement components: a normal along a coordinate axis)",
                c.normal
            ),
        );
    }
    Ok(())
}
