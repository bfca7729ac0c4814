//! What the run's instants keep on the default backend's one factorisation, and each
//! instant's steps on it: the contact problem condensed once (mechanical, or with the electric
//! rows of electrical contact) or one full solve per first-order step; a path's parts of the
//! right-hand side, solved once, whose sums are its instants' loads; the fields of an instant
//! under the contact forces found, refined, the law judged on them.

use super::condensed::{
    condense_reported, fields_at_points, in_frame, law_residual, note_condensed, refine, rhs, rhs_with_contact,
    Operator, Refining, PATH_REFINE_TOL, REFINE_TOL,
};
use super::{Factored, LinearSolver, SharedMemory};
use crate::backend::{At, Contact, ContactSolve, Fields, InstantOf, InstantSolution, Posed, Primed};
use crate::boundary::{ContactBoundary, FullSolve};
use crate::outer::floating_tip;
use crate::progress::{Event, Reporter};
use crate::scene::ZoneElectric;
use crate::ProblemError;
use contact::{
    ContactOperator, ContactPoints, ContactSolution, DenseContactProblem, ElectricContactProblem, NewtonParams,
    PointValues, ProblemClass, Schedule,
};
use linalg::{CondensedLoads, CoupledSolver};
use std::time::Instant;

/// What the instants keep from one to the next.
#[derive(Default)]
pub(super) enum Kept {
    /// Nothing: no contact (each instant one solve with the factors).
    #[default]
    Nothing,
    /// The contact problem condensed onto the contact dofs.
    Condensed(Condensed),
    /// The contact problem with electrical contact condensed onto the points' displacements
    /// and free potentials.
    Electric(Electric),
    /// One full primal solve per first-order step (a strategy without the condensation).
    Full(Box<Full>),
}

/// The condensed compliance, the first instant's loads part, and a path's parts.
pub(super) struct Condensed {
    dense: DenseContactProblem,
    /// The loads' part of the condensation (the first instant's), while `dense.u0` is its
    /// own: the fields of that instant finish its solve.
    loads: Option<CondensedLoads>,
    /// `u⁰` of the condensation.
    first: PointValues,
    /// `x_q`'s displacement part, per part of a path's right-hand side, in their order
    /// (empty for one instant).
    parts: Vec<Vec<f64>>,
}

/// The condensed problem with electrical contact, its loads part and `u⁰`, `φ⁰`, and a path's
/// parts.
pub(super) struct Electric {
    problem: ElectricContactProblem,
    loads: Option<CondensedLoads>,
    first: (PointValues, Vec<f64>),
    /// Per part of a path's right-hand side, its solution's displacements and its potentials
    /// at the electric points (empty for one instant).
    parts: Vec<(Vec<f64>, Vec<f64>)>,
}

/// An instant of a strategy without the condensation: its loads, boundary, and the fields of
/// its last solve.
pub(super) struct Full {
    b_u: Vec<f64>,
    b_phi: Vec<f64>,
    boundary: Option<ContactBoundary>,
    x: Option<Fields>,
}

impl SharedMemory {
    /// [`crate::backend::Backend::begin`]: the condensation (once, for the first instant's
    /// loads), and the parts' solutions (one solve each).
    pub(super) fn begin_instants(
        system: &mut Factored,
        posed: &Posed<'_>,
        contact: Option<Contact<'_>>,
        parts: &[Fields],
        reporter: &mut dyn Reporter,
    ) -> Result<Vec<Fields>, ProblemError> {
        let Some(Contact { boundary, how }) = contact else {
            system.kept = Kept::Nothing;
            return Ok(vec![]);
        };
        let loads = &posed.loads;
        let nt = how.plan.n_tangential();
        if !how.plan.linear_strategy.is_condensed() {
            if !parts.is_empty() {
                return Err(not_direct());
            }
            system.kept = Kept::Full(Box::new(Full {
                b_u: vec![],
                b_phi: vec![],
                boundary: None,
                x: None,
            }));
            return Ok(vec![]);
        }
        let LinearSolver::Direct(direct) = &mut system.solver else {
            return Err(not_direct());
        };
        if let Some((electric, _)) = &boundary.electric {
            let t = Instant::now();
            let (problem, condensed) = boundary.condense_electric(electric, direct, &loads.b_u, &loads.b_phi, nt)?;
            note_condensed(&mut system.condense, reporter, problem.order(), condensed.route, t);
            let first = (problem.u0.clone(), problem.phi0.clone());
            let solved = solve_parts(system, parts)?;
            let at_points = |(u, phi): &Fields| (u.clone(), at_electric_points(boundary, phi, u.len()));
            system.kept = Kept::Electric(Electric {
                problem,
                loads: Some(condensed),
                first,
                parts: solved.iter().map(at_points).collect(),
            });
            return Ok(solved);
        }
        let (dense, condensed) = condense_reported(
            boundary,
            direct,
            (&loads.b_u, &loads.b_phi),
            nt,
            &mut system.condense,
            reporter,
        )?;
        let solved = solve_parts(system, parts)?;
        system.kept = Kept::Condensed(Condensed {
            first: dense.u0.clone(),
            dense,
            loads: Some(condensed),
            parts: solved.iter().map(|(u, _)| u.clone()).collect(),
        });
        Ok(solved)
    }

    /// [`crate::backend::Backend::prime`]: `u⁰` of the instant: a path's parts summed at its
    /// factors, in its frame; the condensation's own for the first instant; the springs'
    /// forces added.
    pub(super) fn prime_instant(system: &mut Factored, primed: Primed<'_>) -> Result<(), ProblemError> {
        let Primed {
            posed,
            framed,
            factors,
            springs,
        } = primed;
        let pressed = springs.normal.iter().any(|&l| l != 0.0);
        match &mut system.kept {
            Kept::Nothing => Ok(()),
            Kept::Condensed(c) => {
                let nt = c.dense.nt;
                match factors {
                    Some(factors) => {
                        let x0 = superpose(c.parts.iter().map(|u| &u[..]), factors);
                        c.dense.u0 = in_frame(fields_at_points(framed.boundary, &x0, nt), Some(framed.shift));
                        c.loads = None;
                    }
                    None => c.dense.u0.clone_from(&c.first),
                }
                if pressed {
                    c.add_forces(springs)?;
                    c.loads = None;
                }
                Ok(())
            }
            Kept::Electric(e) => {
                // the instant's foundation potential (a path scales it with the voltage)
                if let Some((electric, _)) = &framed.boundary.electric {
                    e.problem.electric.potential = electric.potential;
                }
                let nt = e.problem.nt;
                let (u0, phi0) = match (factors, pressed) {
                    (None, false) => e.first.clone(),
                    (Some(factors), false) => {
                        let u = superpose(e.parts.iter().map(|(u, _)| &u[..]), factors);
                        let phi0 = superpose(e.parts.iter().map(|(_, phi)| &phi[..]), factors);
                        (
                            in_frame(fields_at_points(framed.boundary, &u, nt), Some(framed.shift)),
                            phi0,
                        )
                    }
                    (_, true) => {
                        // the springs' forces among the loads: `u⁰` and `φ⁰` of a solve with them
                        let mut b_u = posed.loads.b_u.clone();
                        framed.boundary.add_forces(springs, &mut b_u);
                        let (u, phi) = solve(system, &b_u, &posed.loads.b_phi)?;
                        let at = fields_at_points(framed.boundary, &u, nt);
                        (
                            in_frame(at, factors.map(|_| framed.shift)),
                            at_electric_points(framed.boundary, &phi, u.len()),
                        )
                    }
                };
                if let Kept::Electric(e) = &mut system.kept {
                    (e.problem.u0, e.problem.phi0) = (u0, phi0);
                    if factors.is_some() || pressed {
                        e.loads = None;
                    }
                }
                Ok(())
            }
            Kept::Full(f) => {
                f.b_u.clone_from(&posed.loads.b_u);
                framed.boundary.add_forces(springs, &mut f.b_u);
                f.b_phi.clone_from(&posed.loads.b_phi);
                f.boundary = Some(framed.boundary.clone());
                Ok(())
            }
        }
    }

    /// [`crate::backend::Backend::solve_posed`]: the strategy's contact solver on what the
    /// instants keep.
    pub(super) fn solve_kept(
        system: &mut Factored,
        how: &ContactSolve<'_>,
        At {
            points,
            start,
            refine_start,
        }: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        match &mut system.kept {
            Kept::Condensed(c) => {
                how.run_with(Operator::Condensed(&mut c.dense), points, start, refine_start, reporter)
            }
            Kept::Electric(e) => electric_solve(how, &mut e.problem, points, reporter),
            Kept::Full(f) => {
                let boundary = f.boundary.as_ref().ok_or_else(unprimed)?;
                let mut op = FullSolve {
                    boundary,
                    solver: system.solver.coupled(),
                    b_u: &f.b_u,
                    b_phi: &f.b_phi,
                    nt: how.plan.n_tangential(),
                    u: vec![0.0; f.b_u.len()],
                    phi: vec![0.0; f.b_phi.len()],
                };
                let sol = how.run(Operator::FullSolves(&mut op), points, start, reporter)?;
                f.x = Some((op.u, op.phi));
                Ok(sol)
            }
            Kept::Nothing => Err(unprimed()),
        }
    }

    /// [`crate::backend::Backend::instant_fields`].
    pub(super) fn fields_of(
        system: &mut Factored,
        posed: &Posed<'_>,
        contact: Option<InstantOf<'_>>,
        reporter: &mut dyn Reporter,
    ) -> Result<InstantSolution, ProblemError> {
        let Some(InstantOf { how, framed, sol }) = contact else {
            return super::solve_linear(system, posed);
        };
        let boundary = framed.boundary;
        match std::mem::take(&mut system.kept) {
            Kept::Condensed(mut c) => {
                let result = condensed_fields(system, &mut c, posed, InstantOf { how, framed, sol }, reporter);
                system.kept = Kept::Condensed(c);
                result
            }
            Kept::Electric(mut e) => {
                let result = electric_fields(system, &mut e, posed, InstantOf { how, framed, sol });
                system.kept = Kept::Electric(e);
                result
            }
            Kept::Full(mut f) => {
                let x = f.x.take().ok_or_else(unprimed)?;
                system.kept = Kept::Full(f);
                let b = rhs_with_contact(posed, Some((boundary, &sol)));
                let equilibrium = system.equilibrium_of(&x.0, &x.1, &b);
                Ok(InstantSolution {
                    x,
                    pcg_iters: sol.info.inner_iters,
                    contact: Some(sol),
                    equilibrium,
                })
            }
            Kept::Nothing => Err(unprimed()),
        }
    }

    /// [`crate::backend::Backend::own_scale`].
    pub(super) fn own_scale_of(system: &Factored, factors: &[f64]) -> f64 {
        match &system.kept {
            Kept::Condensed(c) if !c.parts.is_empty() => largest(&superpose(c.parts.iter().map(|u| &u[..]), factors)),
            Kept::Electric(e) if !e.parts.is_empty() => {
                largest(&superpose(e.parts.iter().map(|(u, _)| &u[..]), factors))
            }
            _ => 0.0,
        }
    }
}

/// The fields of a condensed contact solve: the condensation's solve finished for the
/// instant whose loads it carried, else one solve with the factors; refined, the law judged
/// on them (and the contact solve corrected where they miss it); with their equilibrium
/// residual.
fn condensed_fields(
    system: &mut Factored,
    c: &mut Condensed,
    posed: &Posed<'_>,
    InstantOf { how, framed, sol }: InstantOf<'_>,
    reporter: &mut dyn Reporter,
) -> Result<InstantSolution, ProblemError> {
    let boundary = framed.boundary;
    let loads = &posed.loads;
    let path = !c.parts.is_empty();
    let (mut u, mut phi) = match c.loads.take() {
        Some(condensed) => boundary.recover(direct(system)?, condensed, &sol.lambda, &loads.b_u, &loads.b_phi)?,
        None => {
            let (b_u, b_phi, _) = rhs_with_contact(posed, Some((boundary, &sol)));
            solve(system, &b_u, &b_phi)?
        }
    };
    let blocks = &system.blocks;
    let LinearSolver::Direct(direct) = &mut system.solver else {
        return Err(not_direct());
    };
    let mut on = Refining {
        direct,
        blocks,
        posed,
        boundary,
        refinement: 0,
        // a path's step: friction's frame, and refinement only where a direct solve missed
        shift: path.then_some(framed.shift),
        refine_tol: if path { PATH_REFINE_TOL } else { REFINE_TOL },
    };
    let sol = on.correct(how, &mut c.dense, sol, (&mut u, &mut phi), reporter)?;
    system.refinement = on.refinement;
    let b = rhs_with_contact(posed, Some((boundary, &sol)));
    let equilibrium = system.equilibrium_of(&u, &phi, &b);
    Ok(InstantSolution {
        x: (u, phi),
        contact: Some(sol),
        equilibrium,
        pcg_iters: 0,
    })
}

/// The fields of a contact solve with electrical contact, under the forces and the flux
/// found, refined; the potentials reported the refined fields', the law judged on them.
fn electric_fields(
    system: &mut Factored,
    e: &mut Electric,
    posed: &Posed<'_>,
    InstantOf { how, framed, mut sol }: InstantOf<'_>,
) -> Result<InstantSolution, ProblemError> {
    let boundary = framed.boundary;
    let loads = &posed.loads;
    let b = rhs_with_contact(posed, Some((boundary, &sol)));
    let (mut u, mut phi) = match e.loads.take() {
        Some(condensed) => boundary.recover_electric(direct(system)?, condensed, &sol, &loads.b_u, &loads.b_phi)?,
        None => solve(system, &b.0, &b.1)?,
    };
    let blocks = &system.blocks;
    let LinearSolver::Direct(direct) = &mut system.solver else {
        return Err(not_direct());
    };
    // a path's step: friction's frame, and refinement only where a direct solve missed
    let path = !e.parts.is_empty();
    let refine_tol = if path { PATH_REFINE_TOL } else { REFINE_TOL };
    system.refinement = refine(direct, blocks, rhs(&b), &mut u, &mut phi, refine_tol)?.steps;
    // the potentials reported are the refined fields'
    if let Some(values) = &mut sol.electric {
        values.potential = at_electric_points(boundary, &phi, u.len());
    }
    sol.info.complementarity = law_residual(boundary, how, &sol, &e.problem.u0, &u, path.then_some(framed.shift));
    sol.info.residual = sol.info.residual.max(sol.info.complementarity);
    let equilibrium = system.equilibrium_of(&u, &phi, &b);
    Ok(InstantSolution {
        x: (u, phi),
        contact: Some(sol),
        equilibrium,
        pcg_iters: 0,
    })
}

/// Semismooth Newton on the displacement and electric rows; where the conducting zone
/// floats, around it the search for the potential that carries its charge.
fn electric_solve(
    how: &ContactSolve<'_>,
    problem: &mut ElectricContactProblem,
    points: &ContactPoints,
    reporter: &mut dyn Reporter,
) -> Result<ContactSolution, ProblemError> {
    let tol = how.tol;
    let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
    let params = NewtonParams {
        schedule: Schedule::of(ProblemClass::CoupledElectric),
        ..how.newton_params()
    };
    let mut newton = |problem: &ElectricContactProblem, points: &ContactPoints| {
        contact::solve_newton_electric(problem, points, &how.law, &params, &mut progress)
            .map_err(|e| ProblemError::contact(e, how.plan.linear_strategy, how.scene))
    };
    // the conducting zone's charge where it floats (one zone conducts: validated)
    let floating = how.scene.zones().into_iter().find_map(|c| match c.model()?.electric {
        ZoneElectric::Floating { charge, .. } => Some(charge),
        _ => None,
    });
    match floating {
        Some(charge) => floating_tip(problem, points, charge, &mut newton),
        None => newton(problem, points),
    }
}

impl Condensed {
    /// Adds the displacement of the forces of the multipliers `lambda` to the primed
    /// instant's `u⁰` (the springs that hold a body only its bed holds, which act as
    /// multipliers).
    ///
    /// # Errors
    /// The operator's (a dense one has none).
    fn add_forces(&mut self, lambda: &PointValues) -> Result<(), ProblemError> {
        let mut moved = PointValues::zeros(lambda.n_points(), self.dense.nt);
        let mut all = PointValues::zeros(lambda.n_points(), self.dense.nt);
        all.normal.clone_from(&lambda.normal);
        ContactOperator::forces_alone(&mut self.dense, &all, &mut moved).map_err(|e| ProblemError::NoSolution {
            sought: "contact.compliance",
            why: format!("the springs' forces on the condensed problem: {e}"),
        })?;
        for (u, m) in self.dense.u0.normal.iter_mut().zip(&moved.normal) {
            *u += m;
        }
        for (u, m) in self.dense.u0.tangential.iter_mut().zip(&moved.tangential) {
            *u += m;
        }
        Ok(())
    }
}

/// `Σ_q f_q x_q`: the parts `x_q` of a path's right-hand side's solution (all of one length)
/// summed at `factors`, in their order.
fn superpose<'a>(parts: impl Iterator<Item = &'a [f64]>, factors: &[f64]) -> Vec<f64> {
    let mut sum: Vec<f64> = vec![];
    for (part, f) in parts.zip(factors) {
        sum.resize(part.len(), 0.0);
        if *f != 0.0 {
            for (x, p) in sum.iter_mut().zip(part) {
                *x += f * p;
            }
        }
    }
    sum
}

/// The largest magnitude of `values`.
fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// The potentials at the boundary's electric points, from the free potentials `phi` (the free
/// unknowns laid out `[u; φ]`, `n_u` displacements first).
fn at_electric_points(boundary: &ContactBoundary, phi: &[f64], n_u: usize) -> Vec<f64> {
    let dofs = boundary.electric.as_ref().map_or(&[][..], |(_, d)| &d[..]);
    dofs.iter().map(|&d| phi[d - n_u]).collect()
}

/// `K⁻¹ b_q` for each part `q` of a path's right-hand side, in their order.
fn solve_parts(system: &mut Factored, parts: &[Fields]) -> Result<Vec<Fields>, ProblemError> {
    parts.iter().map(|(b_u, b_phi)| solve(system, b_u, b_phi)).collect()
}

/// `K⁻¹ [b_u; b_φ]` with the factors of `K`.
fn solve(system: &mut Factored, b_u: &[f64], b_phi: &[f64]) -> Result<Fields, ProblemError> {
    let (mut u, mut phi) = (vec![0.0; b_u.len()], vec![0.0; b_phi.len()]);
    direct(system)?.solve(b_u, b_phi, &mut u, &mut phi)?;
    Ok((u, phi))
}

/// [`SharedMemory`]'s `respond`: `K⁻¹ [a_u; a_φ]`.
pub(super) fn respond(system: &mut Factored, a_u: &[f64], a_phi: &[f64]) -> Result<Fields, ProblemError> {
    solve(system, a_u, a_phi)
}

/// The `L D Lᵀ` of `K`.
fn direct(system: &mut Factored) -> Result<&mut linalg::DirectLdlt, ProblemError> {
    match &mut system.solver {
        LinearSolver::Direct(direct) => Ok(direct),
        LinearSolver::SchurPcg(_) => Err(not_direct()),
    }
}

/// A path on a strategy without the `L D Lᵀ` of `K` (the scene's checks refuse it first).
fn not_direct() -> ProblemError {
    let feature =
        "a path on a strategy without the L D Lᵀ of K (it carries friction's history on the condensed compliance)";
    crate::backend::Unsupported::new(
        <SharedMemory as crate::backend::Backend>::NAME,
        "solver.strategy",
        feature,
    )
    .advise("use a condensed strategy")
    .into()
}

/// A step out of the run's order (a contact solve before the instants began or were posed):
/// a fault of the caller, said as such.
fn unprimed() -> ProblemError {
    ProblemError::NoSolution {
        sought: "the contact solve",
        why: "the backend was asked for an instant it was not given (begin and prime come first)".into(),
    }
}
