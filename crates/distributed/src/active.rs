//! The Krylov route's contact, where MUMPS' factorisation would not fit the ranks' memory: the
//! primal-dual active set iteration on the whole system ([`crate::contact::active_set`]), each
//! step one Krylov solve, no factorisation and no dense compliance. It holds the paper's base
//! model, on one zone or several ([`crate::active_sets_hold`] chooses it); its steps here are the
//! backend's `begin`, `prime`, `solve_posed` and `instant_fields` on that route.

use crate::contact::{active_set, shared_components, ActiveSetParams, ContactRows};
use crate::error::DistributedError;
use crate::krylov::{Krylov, KrylovFields};
use crate::layout::Layout;
use crate::supports::shared_refusal;
use crate::system::System;
use petsc::{Index, Petsc, PetscError, Vector};
use problem::backend::{At, ContactBoundary, ContactSolve, Fields, InstantOf, InstantSolution, Posed, Primed};
use problem::{Event, ProblemError, Reporter};

/// Steps of the active-set iteration at most.
pub const MAX_ACTIVE_SET_STEPS: usize = 60;

/// The instant's boundary and the last contact solve's solution, until its fields are taken.
#[derive(Default)]
pub struct ActiveSets<'p> {
    boundary: Option<ContactBoundary>,
    x: Option<Vector<'p>>,
}

impl ActiveSets<'_> {
    /// Nothing is kept from instant to instant (the route is taken by one instant's runs).
    pub(crate) fn begin(&mut self, parts: &[Fields]) -> Result<Vec<Fields>, DistributedError> {
        match parts.is_empty() {
            true => Ok(vec![]),
            false => Err(path_refused()),
        }
    }

    /// The instant's boundary, kept for its active sets.
    pub(crate) fn prime(&mut self, primed: Primed<'_>) -> Result<(), DistributedError> {
        if primed.factors.is_some() {
            return Err(path_refused());
        }
        self.boundary = Some(primed.framed.boundary.clone());
        Ok(())
    }
}

/// The active-set iteration over the distributed system, each step one Krylov solve (a
/// tangent of a contact point held by a Dirichlet condition refused by name).
pub(crate) fn solve<'p>(
    active: &mut ActiveSets<'p>,
    layout: &Layout,
    k: &mut Krylov<'p>,
    how: &ContactSolve<'_>,
    at: At<'_>,
    reporter: &mut dyn Reporter,
) -> Result<contact::ContactSolution, DistributedError> {
    let petsc = k.petsc;
    let boundary = active.boundary.as_ref().ok_or_else(unprimed)?;
    // (every rank holds the whole boundary: the same verdict on each)
    if let Some(i) = shared_components(at.points, &boundary.nodes, &how.law) {
        return Err(ProblemError::from(shared_refusal(at.points.position[i])).into());
    }
    let rows = ContactRows::new(petsc, (at.points, &boundary.nodes, &how.law), true, layout, &k.system)?;
    let params = ActiveSetParams {
        tol: how.tol,
        max_steps: MAX_ACTIVE_SET_STEPS,
    };
    let tol = how.tol;
    let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
    let (fields, t_pc) = (&k.fields, &mut k.t_pc);
    let mut solve_one = |m: &mut petsc::Matrix<'p>, b: &Vector<'p>, x: &mut Vector<'p>, loose: Option<f64>| {
        step(petsc, fields, t_pc, (m, b, x), loose)
    };
    let out = active_set(
        petsc,
        layout,
        &k.system,
        (&rows, None),
        params,
        &mut solve_one,
        &mut progress,
    )?;
    (k.iterations, k.reason) = (out.krylov_iterations, out.reason);
    k.report(reporter);
    active.x = Some(out.x);
    // the run reports the whole boundary's solution on every rank
    Ok(rows.whole(petsc, &out.solution, &how.law, at.points)?)
}

/// One active-set step's linear solve: the Krylov solver of the step's matrix `m` (its
/// preconditioner's set-up time added to `t_pc`), to the relative tolerance `loose` where it is
/// looser than the options' (an inexact step), `x` the start and the solution; Krylov
/// iterations, PETSc's reason, and whether the tolerance was loosened.
pub(crate) fn step<'p>(
    petsc: &'p Petsc,
    fields: &KrylovFields,
    t_pc: &mut f64,
    (m, b, x): (&mut petsc::Matrix<'p>, &Vector<'p>, &mut Vector<'p>),
    loose: Option<f64>,
) -> Result<(usize, String, bool), PetscError> {
    let t = std::time::Instant::now();
    let mut ksp = fields.krylov(petsc, m)?;
    *t_pc += t.elapsed().as_secs_f64();
    // the start is the iterate before, whose residual may be many times the right-hand
    // side's norm (a path's instant unloaded to nothing from a loaded one): PETSc's test of
    // divergence against that norm would stop the solve before its first iteration
    ksp.set_divergence_tolerance(f64::MAX)?;
    let tight = ksp.relative_tolerance()?;
    let loosened = loose.filter(|&r| r > tight);
    if let Some(rtol) = loosened {
        ksp.set_relative_tolerance(rtol)?;
    }
    let info = ksp.solve(b, x)?;
    Ok((info.iterations, info.reason, loosened.is_some()))
}

/// The contact solve's solution, whole on every rank, with its equilibrium residual
/// (collective).
pub(crate) fn fields(
    active: &mut ActiveSets<'_>,
    k: &mut Krylov<'_>,
    layout: &Layout,
    posed: &Posed<'_>,
    InstantOf { framed, sol, .. }: &InstantOf<'_>,
) -> Result<InstantSolution, DistributedError> {
    let x = active.x.take().ok_or_else(unprimed)?;
    let equilibrium = residual(&k.system, &x, (framed.boundary, sol), layout, k.petsc)?;
    let mut free = k.whole(&x, false)?;
    let phi = free.split_off(posed.disc.dofs.n_u);
    Ok(InstantSolution {
        x: (free, phi),
        contact: Some(sol.clone()),
        equilibrium,
        pcg_iters: 0,
    })
}

/// `|K x - b - f_c| / max(|loads|, |f_c|)` over all unknowns, with `f_c` the contact forces of
/// the multipliers (the prescribed rows hold exactly), as the default backend measures it.
pub(crate) fn residual(
    system: &System<'_>,
    x: &Vector<'_>,
    (b, sol): (&ContactBoundary, &contact::ContactSolution),
    layout: &Layout,
    petsc: &Petsc,
) -> Result<f64, PetscError> {
    let mut r = system.reactions(x)?;
    // the points' forces, each added once, by the rank that owns its node
    let forces = b.point_forces(&sol.lambda);
    let scale = system.load_norm.max(forces.iter().map(|f| f * f).sum::<f64>().sqrt());
    let dim = layout.dim;
    let (mut idx, mut vals) = (vec![], vec![]);
    for (i, &node) in b.nodes.iter().enumerate() {
        if layout.node_rank[node] == petsc.rank() {
            for c in 0..dim {
                idx.push((layout.first[node] + c) as Index);
                vals.push(-forces[i * dim + c]);
            }
        }
    }
    r.add_values(&idx, &vals)?;
    r.assemble()?;
    let scale = if scale > 0.0 { scale } else { 1.0 };
    Ok(r.norm()? / scale)
}

/// A path on the active sets' route (chosen only for one instant: `active_sets_hold`).
fn path_refused() -> DistributedError {
    ProblemError::from(problem::backend::Unsupported::new(
        "petsc",
        "path",
        "a load path on the active sets' route (taken where MUMPS' factorisation would not fit the memory)",
    ))
    .into()
}

/// A step out of the run's order (a solve before the instant was posed).
fn unprimed() -> DistributedError {
    ProblemError::NoSolution {
        sought: "the contact solve",
        why: "the backend was asked for an instant it was not given (prime comes first)".into(),
    }
    .into()
}
