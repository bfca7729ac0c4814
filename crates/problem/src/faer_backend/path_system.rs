//! What a load path keeps on the default backend's one factorisation: the condensed
//! compliance and the solutions of each part of the right-hand side, from which every step's
//! loads are a sum.

use super::condensed::{
    condense_reported, fields_at_points, in_frame, rhs_with_contact, Operator, Refining, PATH_REFINE_TOL,
};
use super::{Factored, Fields, LinearSolver};
use crate::backend::{ContactSolve, Posed};
use crate::boundary::ContactBoundary;
use crate::progress::Reporter;
use crate::scene::SceneError;
use crate::ProblemError;
use contact::{ContactPoints, ContactSolution, DenseContactProblem, PointValues};
use linalg::CoupledSolver;

/// What stays from step to step of a load path on one factorisation: the condensed compliance
/// and the solutions of `K x = b_q` for each part `q` of the right-hand side (the loads, each
/// displacement component's lifting, the potentials' lifting), whose sum with the step's
/// factors is the loads' solution of the step.
pub(crate) struct PathSystem {
    dense: DenseContactProblem,
    /// `x_q`'s displacement part, per part, in the order of the parts.
    parts: Vec<Vec<f64>>,
}

impl PathSystem {
    /// The condensation of `K` on the boundary's dofs (once) and the parts' solutions (one
    /// solve each), returned whole. `parts` are the right-hand side's parts in the order loads,
    /// x, y, z displacements (as many as the dimension), potentials.
    pub(crate) fn new(
        system: &mut Factored,
        boundary: &ContactBoundary,
        parts: &[(Vec<f64>, Vec<f64>)],
        nt: usize,
        reporter: &mut dyn Reporter,
    ) -> Result<(PathSystem, Vec<Fields>), ProblemError> {
        let LinearSolver::Direct(direct) = &mut system.solver else {
            return Err(not_direct());
        };
        let (b_u, b_phi) = &parts[0];
        let (dense, _) = condense_reported(boundary, direct, (b_u, b_phi), nt, &mut system.condense, reporter)?;
        let mut solved = Vec::with_capacity(parts.len());
        for (b_u, b_phi) in parts {
            solved.push(Self::solve(system, b_u, b_phi)?);
        }
        let parts = solved.iter().map(|(u, _)| u.clone()).collect();
        Ok((PathSystem { dense, parts }, solved))
    }

    /// `K⁻¹ [b_u; b_φ]` with the factors of `K`.
    pub(crate) fn solve(system: &mut Factored, b_u: &[f64], b_phi: &[f64]) -> Result<Fields, ProblemError> {
        let LinearSolver::Direct(direct) = &mut system.solver else {
            return Err(not_direct());
        };
        let (mut u, mut phi) = (vec![0.0; b_u.len()], vec![0.0; b_phi.len()]);
        direct.solve(b_u, b_phi, &mut u, &mut phi)?;
        Ok((u, phi))
    }

    /// The displacement of the boundary's dofs that a step's own data make, `Σ_q f_q x_q` at
    /// `factors` (no contact force).
    fn own_data(&self, factors: &[f64]) -> Vec<f64> {
        let mut x0 = vec![0.0; self.parts[0].len()];
        for (part, f) in self.parts.iter().zip(factors) {
            if *f != 0.0 {
                for (x, p) in x0.iter_mut().zip(part) {
                    *x += f * p;
                }
            }
        }
        x0
    }

    /// The largest displacement of the boundary's dofs that the instant's own data make
    /// ([`PathSystem::own_data`]): the scale of the instant's answer.
    pub(crate) fn own_scale(&self, factors: &[f64]) -> f64 {
        self.own_data(factors).iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// The contact problem's `u⁰` at a step of `factors`, in the frame `shift`: the loads'
    /// displacement at the points, before any contact force.
    pub(crate) fn prime(&mut self, boundary: &ContactBoundary, factors: &[f64], shift: &PointValues) {
        let x0 = self.own_data(factors);
        let nt = self.dense.nt;
        self.dense.u0 = in_frame(fields_at_points(boundary, &x0, nt), Some(shift));
    }

    /// Tangential components per point of the condensed problem.
    pub(crate) fn n_tangential(&self) -> usize {
        self.dense.nt
    }

    /// Adds the displacement of the forces of the multipliers `lambda` to the primed step's
    /// `u⁰` (the springs that hold a body only its bed holds, which act as multipliers).
    ///
    /// # Errors
    /// The operator's (a dense one has none).
    pub(crate) fn add_forces(&mut self, lambda: &PointValues) -> Result<(), ProblemError> {
        if lambda.normal.iter().all(|&l| l == 0.0) {
            return Ok(());
        }
        let mut moved = PointValues::zeros(lambda.n_points(), self.dense.nt);
        let mut all = PointValues::zeros(lambda.n_points(), self.dense.nt);
        all.normal.clone_from(&lambda.normal);
        contact::ContactOperator::forces_alone(&mut self.dense, &all, &mut moved).map_err(|e| {
            ProblemError::NoSolution {
                sought: "contact.compliance",
                why: format!("the springs' forces on the condensed problem: {e}"),
            }
        })?;
        for (u, m) in self.dense.u0.normal.iter_mut().zip(&moved.normal) {
            *u += m;
        }
        for (u, m) in self.dense.u0.tangential.iter_mut().zip(&moved.tangential) {
            *u += m;
        }
        Ok(())
    }

    /// The contact solve of the primed step ([`PathSystem::prime`]).
    pub(crate) fn solve_primed(
        &mut self,
        how: &ContactSolve<'_>,
        points: &ContactPoints,
        start: Option<PointValues>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        how.run(Operator::Condensed(&mut self.dense), points, start, reporter)
    }

    /// The contact solve of the primed step ([`PathSystem::prime`]) at one depth of a force
    /// search: `points` with that depth's gaps, refined ([`ContactSolve::run_with`]).
    pub(crate) fn force_search_at(
        &mut self,
        how: &ContactSolve<'_>,
        points: &ContactPoints,
        start: Option<PointValues>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        how.run_with(Operator::Condensed(&mut self.dense), points, start, true, reporter)
    }

    /// The fields of a step under the loads of `posed` and the contact forces of `sol` (in
    /// the frame `shift`), refined, the law judged on them (and the contact solve corrected
    /// where they miss it).
    pub(crate) fn fields(
        &mut self,
        how: &ContactSolve<'_>,
        system: &mut Factored,
        Framed { boundary, shift }: Framed<'_>,
        posed: &Posed<'_>,
        sol: ContactSolution,
        reporter: &mut dyn Reporter,
    ) -> Result<(ContactSolution, Fields), ProblemError> {
        let (b_u, b_phi, _) = rhs_with_contact(posed, Some((boundary, &sol)));
        let (mut u, mut phi) = Self::solve(system, &b_u, &b_phi)?;
        let LinearSolver::Direct(direct) = &mut system.solver else {
            return Err(not_direct());
        };
        let mut on = Refining {
            direct,
            blocks: &system.blocks,
            posed,
            boundary,
            refinement: 0,
            shift: Some(shift),
            refine_tol: PATH_REFINE_TOL,
        };
        let sol = on.correct(how, &mut self.dense, sol, (&mut u, &mut phi), reporter)?;
        system.refinement = on.refinement;
        Ok((sol, (u, phi)))
    }
}

/// A step's contact boundary (its gaps and prescribed values at the step's factors) and the
/// frame its contact problem is posed in: the tangential displacements of the step before.
#[derive(Clone, Copy)]
pub(crate) struct Framed<'a> {
    pub(crate) boundary: &'a ContactBoundary,
    pub(crate) shift: &'a PointValues,
}

/// A path on a strategy without the `L D Lᵀ` of `K` (the scene's checks refuse it first).
fn not_direct() -> ProblemError {
    SceneError::new(
        "path",
        "a path carries friction's history on the condensed compliance of the L D Lᵀ of K: use a condensed strategy",
    )
    .into()
}
