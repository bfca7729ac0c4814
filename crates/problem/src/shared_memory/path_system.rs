//! What a load path keeps on the default backend's one factorisation: the condensed
//! compliance and the solutions of each part of the right-hand side, from which every step's
//! loads are a sum ([`PathBackend`] for [`SharedMemory`]).

use super::condensed::{
    condense_reported, fields_at_points, in_frame, rhs_with_contact, Operator, Refining, PATH_REFINE_TOL,
};
use super::{Factored, LinearSolver, SharedMemory};
use crate::backend::Fields;
use crate::backend::{At, ContactSolve, Figures, Framed, InstantOf, PathBackend};
use crate::boundary::ContactBoundary;
use crate::progress::Reporter;
use crate::ProblemError;
use contact::{ContactSolution, DenseContactProblem, PointValues};
use linalg::CoupledSolver;

/// What stays from step to step of a load path on one factorisation: the condensed compliance
/// and the solutions of `K x = b_q` for each part `q` of the right-hand side (the loads, each
/// displacement component's lifting, the potentials' lifting), whose sum with the step's
/// factors is the loads' solution of the step.
pub struct PathSystem {
    dense: DenseContactProblem,
    /// `x_q`'s displacement part, per part, in the order of the parts.
    parts: Vec<Vec<f64>>,
}

impl PathBackend for SharedMemory {
    type Path = PathSystem;

    /// The condensation of `K` on the boundary's dofs (once) and the parts' solutions (one
    /// solve each), returned whole.
    fn begin_path(
        &mut self,
        system: &mut Factored,
        boundary: &ContactBoundary,
        how: &ContactSolve<'_>,
        parts: &[Fields],
        reporter: &mut dyn Reporter,
    ) -> Result<(PathSystem, Vec<Fields>), ProblemError> {
        let LinearSolver::Direct(direct) = &mut system.solver else {
            return Err(not_direct());
        };
        let (b_u, b_phi) = &parts[0];
        let nt = how.plan.n_tangential();
        let (dense, _) = condense_reported(boundary, direct, (b_u, b_phi), nt, &mut system.condense, reporter)?;
        let mut solved = Vec::with_capacity(parts.len());
        for (b_u, b_phi) in parts {
            solved.push(solve(system, b_u, b_phi)?);
        }
        let parts = solved.iter().map(|(u, _)| u.clone()).collect();
        Ok((PathSystem { dense, parts }, solved))
    }

    fn respond(&mut self, system: &mut Factored, a_u: &[f64], a_phi: &[f64]) -> Result<Fields, ProblemError> {
        solve(system, a_u, a_phi)
    }

    /// `u⁰` of the step: the loads' displacement at the points for the step's `factors` (the
    /// parts summed), in the frame `shift`, the springs' forces added (`-D W λ_s`).
    fn prime(
        &mut self,
        path: &mut PathSystem,
        Framed { boundary, shift }: Framed<'_>,
        factors: &[f64],
        springs: &PointValues,
    ) -> Result<(), ProblemError> {
        let x0 = path.own_data(factors);
        let nt = path.dense.nt;
        path.dense.u0 = in_frame(fields_at_points(boundary, &x0, nt), Some(shift));
        path.add_forces(springs)
    }

    fn solve_posed(
        &mut self,
        path: &mut PathSystem,
        how: &ContactSolve<'_>,
        At {
            points,
            start,
            refine_start,
        }: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        how.run_with(
            Operator::Condensed(&mut path.dense),
            points,
            start,
            refine_start,
            reporter,
        )
    }

    fn own_scale(&self, path: &PathSystem, factors: &[f64]) -> f64 {
        path.own_data(factors).iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// The fields: one solve with the factors, refined, the law judged on them (and the
    /// contact solve corrected where they miss it); the equilibrium residual of the refined
    /// fields.
    fn instant_fields(
        &mut self,
        path: &mut PathSystem,
        system: &mut Factored,
        InstantOf {
            how,
            framed: Framed { boundary, shift },
            posed,
        }: InstantOf<'_>,
        sol: ContactSolution,
        reporter: &mut dyn Reporter,
    ) -> Result<(ContactSolution, Fields, f64), ProblemError> {
        let (b_u, b_phi, _) = rhs_with_contact(posed, Some((boundary, &sol)));
        let (mut u, mut phi) = solve(system, &b_u, &b_phi)?;
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
        let sol = on.correct(how, &mut path.dense, sol, (&mut u, &mut phi), reporter)?;
        system.refinement = on.refinement;
        let b = rhs_with_contact(posed, Some((boundary, &sol)));
        let equilibrium = system.equilibrium_of(&u, &phi, &b);
        Ok((sol, (u, phi), equilibrium))
    }

    fn figures(&self, system: &Factored) -> Figures {
        system.figures()
    }
}

impl PathSystem {
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

    /// Adds the displacement of the forces of the multipliers `lambda` to the primed step's
    /// `u⁰` (the springs that hold a body only its bed holds, which act as multipliers).
    ///
    /// # Errors
    /// The operator's (a dense one has none).
    fn add_forces(&mut self, lambda: &PointValues) -> Result<(), ProblemError> {
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
}

/// `K⁻¹ [b_u; b_φ]` with the factors of `K`.
fn solve(system: &mut Factored, b_u: &[f64], b_phi: &[f64]) -> Result<Fields, ProblemError> {
    let LinearSolver::Direct(direct) = &mut system.solver else {
        return Err(not_direct());
    };
    let (mut u, mut phi) = (vec![0.0; b_u.len()], vec![0.0; b_phi.len()]);
    direct.solve(b_u, b_phi, &mut u, &mut phi)?;
    Ok((u, phi))
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
