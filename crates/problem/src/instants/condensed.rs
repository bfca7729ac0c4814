//! The contact solve on what the instants keep: on the condensed compliance (semismooth Newton
//! or a first-order method), or one full primal solve per first-order step; the condensation;
//! the fields under the forces found, refined with the factors of `K`, and the law judged on
//! them.

use super::Factorization;
use crate::backend::{ContactSolve, Posed};
use crate::boundary::ContactBoundary;
use crate::progress::{Event, Reporter};
use crate::scene::{ContactSolver, Rule};
use crate::ProblemError;
use contact::{
    ContactError, ContactOperator, ContactPoints, ContactSolution, DenseContactProblem, NewtonParams, PointValues,
    ProblemClass, Schedule, StopRule, UzawaParams,
};
use linalg::CondenseRoute;
use std::time::Instant;

/// The contact problem as its solvers see it.
pub(super) enum Operator<'a> {
    /// The condensed compliance (Newton, or a first-order method).
    Condensed(&'a mut DenseContactProblem),
    /// One full primal solve per call (first-order methods).
    FullSolves(&'a mut dyn ContactOperator),
}

impl ContactSolve<'_> {
    /// Semismooth Newton's parameters for this solve: its tolerance and interrupt.
    pub(super) fn newton_params(&self) -> NewtonParams {
        NewtonParams {
            tol: self.tol,
            interrupt: self.interrupt,
            schedule: Schedule::of(ProblemClass::CondensedFe),
            ..Default::default()
        }
    }

    /// Runs the strategy's contact solver on `problem`, reporting each outer iteration.
    pub(super) fn run(
        &self,
        problem: Operator<'_>,
        points: &ContactPoints,
        start: Option<PointValues>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        self.run_with(problem, points, start, false, reporter)
    }

    /// [`ContactSolve::run`], where `refine_start` asks Newton to take steps from a warm start
    /// that already meets the tolerance ([`NewtonParams::refine_start`]): one depth of force
    /// control's search ([`crate::outer::force_controlled`]), whose force must be this depth's. Taken as it
    /// was, the start of the depth before carried its force: the search's residual stood still
    /// while the depth moved, and it ended on a force 3e-8 off (`hertz-sphere` n = 96 on a
    /// 20-step path, at t = 0.3).
    pub(super) fn run_with(
        &self,
        problem: Operator<'_>,
        points: &ContactPoints,
        start: Option<PointValues>,
        refine_start: bool,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        let tol = self.tol;
        let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
        let solved = match (self.plan.linear_strategy.contact_solver(), problem) {
            (ContactSolver::Newton, Operator::Condensed(dense)) => {
                let params = NewtonParams {
                    refine_start,
                    ..self.newton_params()
                };
                match points.weakens() {
                    // the branch from the stick start, whatever the warm start
                    true => {
                        let params = contact::WeakeningParams {
                            newton: params,
                            tol,
                            ..Default::default()
                        };
                        let cache = &mut self.cache.borrow_mut();
                        contact::solve_slip_weakening_cached(dense, points, &params, &mut progress, cache)
                    }
                    false => {
                        let cache = &mut self.cache.borrow_mut();
                        contact::solve_newton_cached(dense, points, &self.law, &params, start, &mut progress, cache)
                    }
                }
            }
            (ContactSolver::FirstOrder { accelerate }, problem) => {
                let op: &mut dyn ContactOperator = match problem {
                    Operator::Condensed(dense) => dense,
                    Operator::FullSolves(op) => op,
                };
                let params = UzawaParams {
                    rule: match self.plan.rule {
                        Rule::Paper => StopRule::Paper,
                        Rule::Tight => StopRule::Tight { tol },
                    },
                    report_every: 50,
                    accelerate,
                    interrupt: self.interrupt,
                    ..Default::default()
                };
                contact::solve_uzawa(op, points, &self.law, &params, start, &mut progress)
            }
            (ContactSolver::Newton, Operator::FullSolves(_)) => Err(ContactError::Input(
                contact::InputError::Unsupported("semismooth Newton needs the condensed compliance"),
            )),
        };
        solved.map_err(|e| ProblemError::contact(e, self.plan.linear_strategy, self.scene))
    }
}

/// `boundary.condense` with `f` for the right-hand side `(b_u, b_φ)`, timed, reported
/// (`Event::Condensed`) and its route and seconds kept in `condense`.
pub(super) fn condense_reported(
    boundary: &ContactBoundary,
    f: &mut dyn Factorization,
    (b_u, b_phi): (&[f64], &[f64]),
    nt: usize,
    condense: &mut Option<(CondenseRoute, f64)>,
    reporter: &mut dyn Reporter,
) -> Result<(DenseContactProblem, linalg::CondensedLoads), ProblemError> {
    let t = Instant::now();
    let (dense, condensed) = boundary.condense(f, b_u, b_phi, nt)?;
    note_condensed(condense, reporter, dense.m(), condensed.route, t);
    Ok((dense, condensed))
}

/// The condensation formed in the time since `t` (of order `m`, by `route`): reported, and
/// kept for the report.
pub(super) fn note_condensed(
    condense: &mut Option<(linalg::CondenseRoute, f64)>,
    reporter: &mut dyn Reporter,
    m: usize,
    route: linalg::CondenseRoute,
    t: Instant,
) {
    let seconds = t.elapsed().as_secs_f64();
    reporter.event(&Event::Condensed { m, route, seconds });
    *condense = Some((route, seconds));
}

/// The fields of a condensed contact solve, refined with the factors of `K`.
pub(super) struct Refining<'a> {
    pub(super) f: &'a mut dyn Factorization,
    pub(super) posed: &'a Posed<'a>,
    pub(super) boundary: &'a ContactBoundary,
    /// Steps of iterative refinement of the last solve.
    pub(super) refinement: usize,
    /// A path's step: the tangential displacement of the points at the step before, which
    /// the friction law's slip is measured from (the contact problem's frame).
    pub(super) shift: Option<&'a PointValues>,
    /// The equilibrium residual above which the fields are refined ([`REFINE_TOL`] for one
    /// instant; a path's steps refine only what a direct solve did not reach,
    /// [`PATH_REFINE_TOL`]).
    pub(super) refine_tol: f64,
    /// The equilibrium residual of the fields as their last refinement measured it.
    pub(super) residual: Option<f64>,
}

/// The equilibrium residual a run's fields are refined to.
pub(super) const REFINE_TOL: f64 = 1e-14;

/// The equilibrium residual above which a path's step refines its fields: a direct solve
/// reaches 1e-13 to 1e-15 on the shipped scenes, and a refinement step costs a solve, the
/// step's own cost (measured on `paper-cycle`, n = 128: 1 to 3 refinement steps tripled it).
pub(super) const PATH_REFINE_TOL: f64 = 1e-12;

/// The equilibrium residual above which a written instant's fields summed from the path's
/// parts are refined ([`super::Instants::frames_superposed`]): the sum carries the parts'
/// round-off where the loads and the contact forces cancel (up to 4.5e-12 on the written
/// instants of `paper-cycle` at n = 256, against about 1e-12 for a solve of the whole
/// right-hand side), so that 1e-12 refined every one of them, at the price of the full solve
/// the sum saves. Still 1000 times below what a run must reach
/// ([`crate::EQUILIBRIUM_TOL`]).
pub(super) const SUPERPOSED_REFINE_TOL: f64 = 1e-11;

impl Refining<'_> {
    /// The fields are those of the last solve: refined, and the contact law judged on them
    /// (not on the condensed problem's own displacement); where the compliance lost digits to
    /// an ill-conditioned system, its defect at the points is corrected, at most
    /// [`MAX_CORRECTIONS`] times (each a warm contact solve and one solve with the factors).
    pub(super) fn correct(
        &mut self,
        how: &ContactSolve<'_>,
        dense: &mut DenseContactProblem,
        mut sol: ContactSolution,
        (u, phi): (&mut Vec<f64>, &mut Vec<f64>),
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        let (boundary, posed) = (self.boundary, self.posed);
        let u0 = dense.u0.clone();
        let mut corrections = 0;
        loop {
            let b = rhs_with_contact(posed, Some((boundary, &sol)));
            let refined = self.f.refine(rhs(&b), u, phi, self.refine_tol)?;
            (self.refinement, self.residual) = (self.refinement + refined.steps, refined.residual);
            sol.info.complementarity = law_residual(boundary, how, &sol, &u0, u, self.shift);
            if sol.info.complementarity <= how.tol || corrections == MAX_CORRECTIONS {
                break;
            }
            let actual = in_frame(fields_at_points(boundary, u, sol.lambda.n_tangential()), self.shift);
            for (d, (x, model)) in dense.u0.normal.iter_mut().chain(dense.u0.tangential.iter_mut()).zip(
                actual
                    .normal
                    .iter()
                    .chain(&actual.tangential)
                    .zip(sol.u.normal.iter().chain(&sol.u.tangential)),
            ) {
                *d += x - model;
            }
            let start = sol.lambda.clone();
            sol = how.run(Operator::Condensed(dense), &boundary.points, Some(start), reporter)?;
            let (b_full, b_phi, _) = rhs_with_contact(posed, Some((boundary, &sol)));
            (*u, *phi) = self.f.solve(&b_full, &b_phi)?.0;
            corrections += 1;
        }
        sol.info.residual = sol.info.residual.max(sol.info.complementarity);
        Ok(sol)
    }
}

/// A right-hand side `(b_u, b_φ)` with the size of the parts it is made of (`linalg::Rhs`'s
/// `scale`), owned.
pub(crate) type ScaledRhs = (Vec<f64>, Vec<f64>, f64);

/// The right-hand sides with the contact forces of `contact` (and the electric flux, with
/// electrical contact), and the size of their parts (the loads, the contact forces: they may
/// cancel in the sum).
pub(crate) fn rhs_with_contact(posed: &Posed<'_>, contact: Option<(&ContactBoundary, &ContactSolution)>) -> ScaledRhs {
    let loads = &posed.loads;
    let (mut b_full, mut b_phi) = (loads.b_u.clone(), loads.b_phi.clone());
    let mut scale = linalg::norm(&loads.b_u).hypot(linalg::norm(&loads.b_phi));
    if let Some((cb, sol)) = contact {
        let forces = cb.forces(&sol.lambda);
        scale = scale.max(linalg::norm(&forces));
        for (&j, f) in cb.dofs.iter().zip(&forces) {
            b_full[j] += f;
        }
        let charges = cb.electric_charges(sol, loads.b_u.len());
        let charge_norm = charges.iter().map(|(_, q)| q * q).sum::<f64>().sqrt();
        scale = scale.max(charge_norm);
        for (j, q) in charges {
            b_phi[j] += q;
        }
    }
    (b_full, b_phi, scale)
}

/// The right-hand side `(b_u, b_φ)` of size `scale`, as linalg takes it.
pub(super) fn rhs<'a>((b_u, b_phi, scale): &'a ScaledRhs) -> linalg::Rhs<'a> {
    linalg::Rhs {
        u: b_u,
        phi: b_phi,
        scale: *scale,
    }
}

/// Corrections of the condensed problem by its defect at the points, at most (each a warm
/// Newton solve and one solve with the factors): where the compliance is accurate to a
/// fraction, each gains that fraction's digits.
const MAX_CORRECTIONS: usize = 4;

/// The displacement of the points in the free vector `u`, in the contact problem's layout
/// (`nt` tangential components: none without friction).
pub(super) fn fields_at_points(boundary: &ContactBoundary, u: &[f64], nt: usize) -> PointValues {
    let points = &boundary.points;
    let mut all = PointValues::zeros(points.len(), points.n_tangential());
    boundary.extract(u, &mut all);
    let tangential = if nt > 0 { all.tangential } else { vec![] };
    PointValues::from_parts(all.normal, tangential, nt).unwrap_or_else(|_| PointValues::zeros(points.len(), nt))
}

/// The points' displacement `at` in the frame of a path's step: its tangential part less
/// `shift` (the step before's), the slip increment the friction law reads.
pub(super) fn in_frame(mut at: PointValues, shift: Option<&PointValues>) -> PointValues {
    if let Some(s) = shift {
        for (v, s) in at.tangential.iter_mut().zip(&s.tangential) {
            *v -= s;
        }
    }
    at
}

/// The complementarity residual of the law on the final fields: the multipliers of `sol` with
/// the displacement of the points in `u` (the last, refined solve), against the loads' `u0`.
pub(super) fn law_residual(
    boundary: &ContactBoundary,
    how: &ContactSolve<'_>,
    sol: &ContactSolution,
    u0: &PointValues,
    u: &[f64],
    shift: Option<&PointValues>,
) -> f64 {
    let law = &how.law;
    let points = &how.points_at(&boundary.points, sol);
    let at = in_frame(fields_at_points(boundary, u, sol.lambda.n_tangential()), shift);
    let c = 1.0 / sol.info.mu_max;
    let reference = contact::multiplier_scale(points, u0, c);
    let radius = contact::slip_bound(points, law, &sol.lambda.normal);
    contact::complementarity_residual(points, &radius, &sol.lambda, &at, c, reference)
}
