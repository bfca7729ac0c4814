//! What the PETSc backend solves, told from the scene alone (no PETSc needed: the program built
//! without the feature tells a user what the backend would refuse before they build it).
//!
//! Since its runs with contact factor `K` by MUMPS and run the default backend's contact
//! solvers on the contact dofs' Schur complement (the run's instants, `problem::Instants`), it
//! solves every scene the default backend solves: every law, path, indenter, terminal and
//! strategy. It refuses only a scene that asks for the default backend, and PETSc's options
//! where the run does not take them ([`direct`]).
//!
//! Where MUMPS' factorisation would not fit the ranks' memory, or the body is 3D and large
//! enough that Krylov solves are the faster ([`crate::ACTIVE_SETS_FROM`] unknowns, a share
//! [`crate::ACTIVE_SETS_ZONE`] of them in the contact zone), a run whose
//! contact the Krylov route's active sets hold ([`active_sets_hold`]: the paper's base model, on
//! one zone or several) takes that route instead: Krylov solves on the whole system, no factorisation, no
//! dense compliance (`paper-3d` at n = 64, 2.2 million unknowns, on this machine).

use problem::backend::Unsupported;
use problem::{BackendChoice, ContactSpec, Rule, Scene, Strategy};

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
    // (a 3D run the active sets hold may take them, and their options, by speed: judged once
    // its route is chosen on the mesh; a plane one factors by MUMPS)
    let may_take_active_sets = active_sets_hold(scene).is_ok() && scene.mesh.dim() != Some(2);
    if direct(scene) && !may_take_active_sets && scene.solver.petsc_options.is_some() {
        // options for the Krylov solvers, which this run does not use: not ignored silently
        return Err(options_refused());
    }
    Ok(())
}

/// PETSc's options refused in a run that factors `K` by MUMPS (a run that the active sets
/// might take is judged once its route is chosen, on its mesh).
pub(crate) fn options_refused() -> Unsupported {
    Unsupported::new(
        BACKEND,
        "solver.petsc_options",
        "options for PETSc's Krylov solvers in a run that factors K by MUMPS (a run with contact, a floating terminal or a body of revolution, the Krylov route's active sets aside), which takes none",
    )
    .advise("remove solver.petsc_options")
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

/// Whether the Krylov route's active sets hold `scene`'s contact (`Err`: the first thing they
/// lack, by key): Signorini's conditions or normal compliance (a rigid or a deformable
/// foundation) with Coulomb or Tresca friction on insulating, flat or indenting zones (one or
/// several) whose normals are coordinate axes, at one instant,
/// at a given depth or force and prescribed potentials, on plane and 3D bodies, with Newton's
/// strategy and the tight rule. The route a run takes where MUMPS would not fit. (A node of
/// two zones whose conditions act on one component is told on the mesh:
/// [`crate::contact::shared_components`].)
///
/// # Errors
/// [`Unsupported`] naming the key.
pub fn active_sets_hold(scene: &Scene) -> Result<(), Unsupported> {
    active_sets_hold_on(scene, None)
}

/// [`active_sets_hold`] on the run's `mesh` where it is known (a Gmsh file's cells tell its
/// order only once read): linear cells only, a quadratic face's contact points being those
/// of a modified basis whose multipliers are not the nodes' reactions.
///
/// # Errors
/// [`Unsupported`] naming the key.
pub fn active_sets_hold_on(scene: &Scene, mesh: Option<&mesh::Mesh>) -> Result<(), Unsupported> {
    if scene.path.is_some() {
        return not_held("path", "a load path");
    }
    // (the whole mesh's rows are node by node; pieces tie a terminal's nodes to one row)
    if let Some(key) = scene.floating_key() {
        return not_held(key, "a floating terminal");
    }
    // (pieces run the fixed point on the coefficients around their active sets)
    if scene.zones().iter().any(|c| c.slip_weakening().is_some()) {
        return not_held("contact.friction_law", "slip-weakening friction");
    }
    active_sets_hold_at_instants(scene, mesh)
}

/// [`active_sets_hold_on`] at each instant of a load path, friction's history carried from
/// one to the next, floating terminals among the potentials (as a run on pieces walks a path
/// and ties a terminal's nodes; the whole mesh's route does neither).
///
/// # Errors
/// [`Unsupported`] naming the key.
pub(crate) fn active_sets_hold_at_instants(scene: &Scene, mesh: Option<&mesh::Mesh>) -> Result<(), Unsupported> {
    if scene.mesh.order.unwrap_or(1) > 1 || mesh.is_some_and(|m| m.kind.order() > 1) {
        return not_held("mesh.order", "quadratic elements (a modified basis' contact points)");
    }
    let zones = scene.zones();
    if scene.mesh.axisymmetric {
        return not_held("mesh.axisymmetric", "a body of revolution");
    }
    if scene.solver.strategy != Strategy::NewtonCondensed {
        return not_held("solver.strategy", "a strategy other than Newton's");
    }
    if scene.solver.rule != Rule::Tight {
        return not_held("solver.rule", "the paper's stopping rule");
    }
    zones.into_iter().try_for_each(zone_held)
}

/// Whether the active sets would solve `scene`'s contact many times over (force control's
/// search on the depth, slip weakening's fixed point on the coefficients): where MUMPS fits,
/// its condensed route, which factors once and solves each of those problems on the contact
/// dofs alone, is the faster, and the active sets are taken only where it does not fit.
pub fn repeats_contact_solves(scene: &Scene) -> bool {
    scene
        .zones()
        .iter()
        .any(|c| c.indenter.as_ref().is_some_and(|i| i.force.is_some()) || c.slip_weakening().is_some())
}

/// What one contact zone asks for that the active sets do not hold.
fn zone_held(c: &ContactSpec) -> Result<(), Unsupported> {
    if let Some(condition) = c.electric.filter(|_| c.electric_law().is_some()) {
        return not_held("contact.electric", &format!("contact.electric = \"{condition}\""));
    }
    if c.normal.iter().filter(|&&x| x != 0.0).count() != 1 {
        return not_held(
            "contact.normal",
            &format!("contact.normal = {:?}, an oblique face", c.normal),
        );
    }
    Ok(())
}

/// `feature`, asked for by `key`, which the active sets do not hold.
fn not_held(key: &str, feature: &str) -> Result<(), Unsupported> {
    Err(unheld(key, feature))
}

/// The refusal of the point at `at`, which [`crate::contact::shared_components`] found.
#[cfg(feature = "petsc")]
pub(crate) fn shared_refusal(at: [f64; 3]) -> Unsupported {
    unheld(
        "contact",
        &format!(
            "a node of two contact zones whose conditions act on one component of its displacement (the node at ({:.6e}, {:.6e}, {:.6e}): friction along the other zone's normal, or one normal)",
            at[0], at[1], at[2]
        ),
    )
    .advise("frictionless zones may meet at a node; else keep the zones apart, or give the ranks the memory for MUMPS' route")
}

/// The refusal of `feature`, asked for by `key`, which the active sets do not hold.
pub(crate) fn unheld(key: &str, feature: &str) -> Unsupported {
    Unsupported::new(BACKEND, key, format!("{feature}, which the active sets do not hold"))
}
