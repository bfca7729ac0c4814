//! What a run's instants keep on one factorisation of `K`, and each instant's steps on it,
//! for any backend whose factorisation condenses ([`Factorization`]): the contact problem
//! condensed once (mechanical, or with the electric rows of electrical contact) or one full
//! solve per first-order step; a path's parts of the right-hand side, solved once, whose sums
//! are its instants' loads; the fields of an instant under the contact forces found, refined,
//! the law judged on them. The contact solvers run on the condensed problem unchanged, so
//! every law of the `contact` crate reaches every backend that factors.

mod condensed;

use crate::backend::{At, Contact, ContactSolve, Fields, InstantOf, InstantSolution, Posed, Primed};
use crate::boundary::{ContactBoundary, FullSolve};
use crate::factorization::Factorization;
use crate::outer::floating_tip;
use crate::progress::{Event, Reporter};
use crate::scene::ZoneElectric;
use crate::ProblemError;
pub(crate) use condensed::rhs_with_contact;
use condensed::ScaledRhs;
use condensed::{
    condense_reported, fields_at_points, in_frame, law_residual, note_condensed, rhs, Operator, Refining,
    PATH_REFINE_TOL, REFINE_TOL, SUPERPOSED_REFINE_TOL,
};
use contact::{
    ContactOperator, ContactPoints, ContactSolution, DenseContactProblem, ElectricContactProblem, NewtonParams,
    PointValues, ProblemClass, Schedule,
};
use linalg::{CondenseRoute, CondensedLoads};
use std::time::Instant;

/// What the instants keep, and what their solves measured.
#[derive(Default)]
pub struct Instants {
    kept: Kept,
    /// How the contact compliance was formed, and in how long.
    pub condense: Option<(CondenseRoute, f64)>,
    /// Steps of iterative refinement of the last instant's fields.
    pub refinement: usize,
}

/// What the instants keep from one to the next.
#[derive(Default)]
enum Kept {
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
struct Condensed {
    dense: DenseContactProblem,
    /// The loads' part of the condensation (the first instant's), while `dense.u0` is its
    /// own: the fields of that instant finish its solve.
    loads: Option<CondensedLoads>,
    /// `u⁰` of the condensation.
    first: PointValues,
    /// `x_q`, per part of a path's right-hand side, in their order (empty for one instant):
    /// an instant's `u⁰` is their displacements at the points summed at its factors, a written
    /// instant's fields their sum and the solve of its contact forces alone
    /// ([`Instants::frames_superposed`]).
    parts: Vec<Fields>,
    /// The dofs of the condensation, in its order.
    dofs: Vec<usize>,
}

/// The condensed problem with electrical contact, its loads part and `u⁰`, `φ⁰`, and a path's
/// parts.
struct Electric {
    problem: ElectricContactProblem,
    loads: Option<CondensedLoads>,
    first: (PointValues, Vec<f64>),
    /// Per part of a path's right-hand side, its solution's displacements and its potentials
    /// at the electric points (empty for one instant).
    parts: Vec<(Vec<f64>, Vec<f64>)>,
}

/// An instant of a strategy without the condensation: its loads, boundary, and the fields of
/// its last solve.
struct Full {
    b_u: Vec<f64>,
    b_phi: Vec<f64>,
    boundary: Option<ContactBoundary>,
    x: Option<Fields>,
}

impl Instants {
    /// [`crate::backend::Backend::begin`]: the condensation (once, for the first instant's
    /// loads), and the parts' solutions (one solve each).
    ///
    /// # Errors
    /// The factorisation's; a path on a strategy without the condensation.
    pub fn begin(
        &mut self,
        f: &mut dyn Factorization,
        posed: &Posed<'_>,
        contact: Option<Contact<'_>>,
        parts: &[Fields],
        reporter: &mut dyn Reporter,
    ) -> Result<Vec<Fields>, ProblemError> {
        let Some(Contact { boundary, how }) = contact else {
            self.kept = Kept::Nothing;
            return Ok(vec![]);
        };
        let loads = &posed.loads;
        let nt = how.plan.n_tangential();
        if !how.plan.linear_strategy.is_condensed() {
            if !parts.is_empty() {
                return Err(not_direct());
            }
            self.kept = Kept::Full(Box::new(Full {
                b_u: vec![],
                b_phi: vec![],
                boundary: None,
                x: None,
            }));
            return Ok(vec![]);
        }
        if !f.condenses() {
            return Err(not_direct());
        }
        if let Some((electric, _)) = &boundary.electric {
            let t = Instant::now();
            let (problem, condensed) = boundary.condense_electric(electric, f, &loads.b_u, &loads.b_phi, nt)?;
            note_condensed(&mut self.condense, reporter, problem.order(), condensed.route, t);
            let first = (problem.u0.clone(), problem.phi0.clone());
            let solved = solve_parts(f, parts)?;
            // a part is a response to a load: the prescribed terms come with each instant
            let at_points = |(u, phi): &Fields| (u.clone(), boundary.free_potentials_at_points(phi, u.len()));
            self.kept = Kept::Electric(Electric {
                problem,
                loads: Some(condensed),
                first,
                parts: solved.iter().map(at_points).collect(),
            });
            return Ok(solved);
        }
        let (dense, condensed) = condense_reported(
            boundary,
            f,
            (&loads.b_u, &loads.b_phi),
            nt,
            &mut self.condense,
            reporter,
        )?;
        let solved = solve_parts(f, parts)?;
        self.kept = Kept::Condensed(Condensed {
            first: dense.u0.clone(),
            dense,
            dofs: condensed.dofs().to_vec(),
            loads: Some(condensed),
            parts: solved.clone(),
        });
        Ok(solved)
    }

    /// [`crate::backend::Backend::prime`]: `u⁰` of the instant: a path's parts summed at its
    /// factors, in its frame; the condensation's own for the first instant; the springs'
    /// forces added.
    ///
    /// # Errors
    /// The factorisation's (a solve with the springs' forces, with electrical contact).
    pub fn prime(&mut self, f: &mut dyn Factorization, primed: Primed<'_>) -> Result<(), ProblemError> {
        let Primed {
            posed,
            framed,
            factors,
            springs,
        } = primed;
        let pressed = springs.normal.iter().any(|&l| l != 0.0);
        match &mut self.kept {
            Kept::Nothing => Ok(()),
            Kept::Condensed(c) => {
                let nt = c.dense.nt;
                match factors {
                    Some(factors) => {
                        // each part read at the points, then summed (the points' values are
                        // linear in the field: no sum over the whole field)
                        let at_points: Vec<PointValues> = c
                            .parts
                            .iter()
                            .map(|(u, _)| fields_at_points(framed.boundary, u, nt))
                            .collect();
                        let normal = superpose(at_points.iter().map(|p| &p.normal[..]), factors);
                        let tangential = superpose(at_points.iter().map(|p| &p.tangential[..]), factors);
                        let n = framed.boundary.points.len();
                        let x0 = PointValues::from_parts(normal, tangential, nt)
                            .unwrap_or_else(|_| PointValues::zeros(n, nt));
                        c.dense.u0 = in_frame(x0, Some(framed.shift));
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
                        let mut phi0 = superpose(e.parts.iter().map(|(_, phi)| &phi[..]), factors);
                        for (p, c) in phi0.iter_mut().zip(framed.boundary.prescribed_potentials()) {
                            *p += c;
                        }
                        (
                            in_frame(fields_at_points(framed.boundary, &u, nt), Some(framed.shift)),
                            phi0,
                        )
                    }
                    (_, true) => {
                        // the springs' forces among the loads: `u⁰` and `φ⁰` of a solve with them
                        let mut b_u = posed.loads.b_u.clone();
                        framed.boundary.add_forces(springs, &mut b_u);
                        let ((u, phi), _) = f.solve(&b_u, &posed.loads.b_phi)?;
                        let at = fields_at_points(framed.boundary, &u, nt);
                        (
                            in_frame(at, factors.map(|_| framed.shift)),
                            at_electric_points(framed.boundary, &phi, u.len()),
                        )
                    }
                };
                (e.problem.u0, e.problem.phi0) = (u0, phi0);
                if factors.is_some() || pressed {
                    e.loads = None;
                }
                Ok(())
            }
            Kept::Full(full) => {
                full.b_u.clone_from(&posed.loads.b_u);
                framed.boundary.add_forces(springs, &mut full.b_u);
                full.b_phi.clone_from(&posed.loads.b_phi);
                full.boundary = Some(framed.boundary.clone());
                Ok(())
            }
        }
    }

    /// [`crate::backend::Backend::solve_posed`]: the strategy's contact solver on what the
    /// instants keep.
    ///
    /// # Errors
    /// The contact solver's; a solve before the instants began.
    pub fn solve(
        &mut self,
        f: &mut dyn Factorization,
        how: &ContactSolve<'_>,
        At {
            points,
            start,
            refine_start,
        }: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        match &mut self.kept {
            Kept::Condensed(c) => {
                how.run_with(Operator::Condensed(&mut c.dense), points, start, refine_start, reporter)
            }
            Kept::Electric(e) => electric_solve(how, &mut e.problem, points, reporter),
            Kept::Full(full) => {
                let boundary = full.boundary.as_ref().ok_or_else(unprimed)?;
                let solver = f.coupled().ok_or_else(not_direct)?;
                let mut op = FullSolve {
                    boundary,
                    solver,
                    b_u: &full.b_u,
                    b_phi: &full.b_phi,
                    nt: how.plan.n_tangential(),
                    u: vec![0.0; full.b_u.len()],
                    phi: vec![0.0; full.b_phi.len()],
                };
                let sol = how.run(Operator::FullSolves(&mut op), points, start, reporter)?;
                full.x = Some((op.u, op.phi));
                Ok(sol)
            }
            Kept::Nothing => Err(unprimed()),
        }
    }

    /// [`crate::backend::Backend::instant_fields`]: one solve without contact; with contact,
    /// the fields under the forces found.
    ///
    /// # Errors
    /// The factorisation's; a step out of the run's order.
    pub fn fields(
        &mut self,
        f: &mut dyn Factorization,
        posed: &Posed<'_>,
        contact: Option<InstantOf<'_>>,
        reporter: &mut dyn Reporter,
    ) -> Result<InstantSolution, ProblemError> {
        let Some(InstantOf { how, framed, sol }) = contact else {
            return self.linear(f, posed);
        };
        let boundary = framed.boundary;
        match std::mem::take(&mut self.kept) {
            Kept::Condensed(mut c) => {
                let result = self.condensed_fields(f, &mut c, posed, InstantOf { how, framed, sol }, reporter);
                self.kept = Kept::Condensed(c);
                result
            }
            Kept::Electric(mut e) => {
                let result = self.electric_fields(f, &mut e, posed, InstantOf { how, framed, sol });
                self.kept = Kept::Electric(e);
                result
            }
            Kept::Full(mut full) => {
                let x = full.x.take().ok_or_else(unprimed)?;
                self.kept = Kept::Full(full);
                let b = rhs_with_contact(posed, Some((boundary, &sol)));
                let equilibrium = measured(f, (&x.0, &x.1), &b, None)?;
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

    /// [`crate::backend::Backend::frames_fields`]: the fields of several instants, each under
    /// its loads and the forces (and, with electrical contact, the flux) of its contact solve,
    /// solved together ([`Factorization::solve_many`]), each refined where a direct solve
    /// missed (an equilibrium residual above 1e-12), with its equilibrium residual. Nothing the instants keep
    /// is read or changed: the path has gone on from these instants.
    ///
    /// # Errors
    /// The factorisation's.
    pub fn frames(
        f: &mut dyn Factorization,
        frames: Vec<(Posed<'_>, InstantOf<'_>)>,
    ) -> Result<Vec<InstantSolution>, ProblemError> {
        let b = frames_rhs(&frames);
        let columns: Vec<(&[f64], &[f64])> = b.iter().map(|(b_u, b_phi, _)| (&b_u[..], &b_phi[..])).collect();
        let solved = f.solve_many(&columns)?;
        Self::refined_frames(f, frames, (&b, PATH_REFINE_TOL), solved)
    }

    /// [`Instants::frames`], each written instant's solve made of the path's parts' solutions
    /// summed at its factors, `Σ_q f_q x_q`, and the solve of its contact forces alone at the
    /// condensation's dofs, `K⁻¹ Rᵀ W λ`, which a factor ordered with those dofs last solves
    /// by its backward sweep (the forward half is the trailing block's,
    /// [`Factorization::solve_trailing_many`]); then refined as [`Instants::frames`] refines
    /// them, against the whole right-hand side. Where an instant's loads are not the parts'
    /// sum (a bed's springs, electrical contact) or the factor cannot, as [`Instants::frames`].
    ///
    /// # Errors
    /// The factorisation's; a field that is not finite.
    pub fn frames_superposed(
        &self,
        f: &mut dyn Factorization,
        frames: Vec<(Posed<'_>, InstantOf<'_>)>,
    ) -> Result<Vec<InstantSolution>, ProblemError> {
        let Kept::Condensed(c) = &self.kept else {
            return Self::frames(f, frames);
        };
        match c.superposed(f, &frames)? {
            Some(solved) => {
                let b = frames_rhs(&frames);
                Self::refined_frames(f, frames, (&b, SUPERPOSED_REFINE_TOL), solved)
            }
            None => Self::frames(f, frames),
        }
    }

    /// The written instants' fields `solved` (of the right-hand sides `b`) refined together
    /// where their residual is above `tol`, checked and measured.
    fn refined_frames(
        f: &mut dyn Factorization,
        frames: Vec<(Posed<'_>, InstantOf<'_>)>,
        (b, tol): (&[ScaledRhs], f64),
        mut solved: Vec<Fields>,
    ) -> Result<Vec<InstantSolution>, ProblemError> {
        let measures: Vec<_> = b.iter().map(rhs).collect();
        let refined = f.refine_many(&measures, &mut solved, tol)?;
        let mut out = Vec::with_capacity(frames.len());
        for ((((_, of), (u, phi)), b), refined) in frames.into_iter().zip(solved).zip(b).zip(refined) {
            let mut sol = of.sol;
            if let Some(values) = &mut sol.electric {
                // the potentials reported are the refined fields'
                values.potential = at_electric_points(of.framed.boundary, &phi, u.len());
            }
            out.push(finished(f, (u, phi), sol, b, refined.residual)?);
        }
        Ok(out)
    }

    /// [`crate::backend::Backend::respond`]: `K⁻¹ [a_u; a_φ]` for each functional of `a`,
    /// solved together.
    ///
    /// # Errors
    /// The factorisation's.
    pub fn respond(f: &mut dyn Factorization, a: &[(&[f64], &[f64])]) -> Result<Vec<Fields>, ProblemError> {
        f.solve_many(a)
    }

    /// [`crate::backend::Backend::own_scale`].
    pub fn own_scale(&self, factors: &[f64]) -> f64 {
        match &self.kept {
            Kept::Condensed(c) if !c.parts.is_empty() => {
                largest(&superpose(c.parts.iter().map(|(u, _)| &u[..]), factors))
            }
            Kept::Electric(e) if !e.parts.is_empty() => {
                largest(&superpose(e.parts.iter().map(|(u, _)| &u[..]), factors))
            }
            _ => 0.0,
        }
    }

    /// The one linear solve of an instant without contact, refined.
    fn linear(&mut self, f: &mut dyn Factorization, posed: &Posed<'_>) -> Result<InstantSolution, ProblemError> {
        let loads = &posed.loads;
        let ((mut u, mut phi), pcg_iters) = f.solve(&loads.b_u, &loads.b_phi)?;
        let b = rhs_with_contact(posed, None);
        let refined = f.refine(rhs(&b), &mut u, &mut phi, REFINE_TOL)?;
        self.refinement = refined.steps;
        let equilibrium = measured(f, (&u, &phi), &b, refined.residual)?;
        Ok(InstantSolution {
            x: (u, phi),
            contact: None,
            equilibrium,
            pcg_iters,
        })
    }

    /// The fields of a condensed contact solve: the condensation's solve finished for the
    /// instant whose loads it carried, else one solve with the factors; refined, the law
    /// judged on them (and the contact solve corrected where they miss it); with their
    /// equilibrium residual.
    fn condensed_fields(
        &mut self,
        f: &mut dyn Factorization,
        c: &mut Condensed,
        posed: &Posed<'_>,
        InstantOf { how, framed, sol }: InstantOf<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<InstantSolution, ProblemError> {
        let boundary = framed.boundary;
        let loads = &posed.loads;
        let path = !c.parts.is_empty();
        let (mut u, mut phi) = match c.loads.take() {
            Some(condensed) => boundary.recover(f, condensed, &sol.lambda, &loads.b_u, &loads.b_phi)?,
            None => {
                let (b_u, b_phi, _) = rhs_with_contact(posed, Some((boundary, &sol)));
                f.solve(&b_u, &b_phi)?.0
            }
        };
        let mut on = Refining {
            f,
            posed,
            boundary,
            refinement: 0,
            // a path's step: friction's frame, and refinement only where a direct solve missed
            shift: path.then_some(framed.shift),
            refine_tol: if path { PATH_REFINE_TOL } else { REFINE_TOL },
            residual: None,
        };
        let sol = on.correct(how, &mut c.dense, sol, (&mut u, &mut phi), reporter)?;
        let (refinement, residual) = (on.refinement, on.residual);
        self.refinement = refinement;
        let b = rhs_with_contact(posed, Some((boundary, &sol)));
        finished(f, (u, phi), sol, &b, residual)
    }

    /// The fields of a contact solve with electrical contact, under the forces and the flux
    /// found, refined; the potentials reported the refined fields', the law judged on them.
    fn electric_fields(
        &mut self,
        f: &mut dyn Factorization,
        e: &mut Electric,
        posed: &Posed<'_>,
        InstantOf { how, framed, mut sol }: InstantOf<'_>,
    ) -> Result<InstantSolution, ProblemError> {
        let boundary = framed.boundary;
        let loads = &posed.loads;
        let b = rhs_with_contact(posed, Some((boundary, &sol)));
        let (mut u, mut phi) = match e.loads.take() {
            Some(condensed) => boundary.recover_electric(f, condensed, &sol, &loads.b_u, &loads.b_phi)?,
            None => f.solve(&b.0, &b.1)?.0,
        };
        // a path's step: friction's frame, and refinement only where a direct solve missed
        let path = !e.parts.is_empty();
        let refine_tol = if path { PATH_REFINE_TOL } else { REFINE_TOL };
        let refined = f.refine(rhs(&b), &mut u, &mut phi, refine_tol)?;
        self.refinement = refined.steps;
        // the potentials reported are the refined fields'
        if let Some(values) = &mut sol.electric {
            values.potential = at_electric_points(boundary, &phi, u.len());
        }
        sol.info.complementarity = law_residual(boundary, how, &sol, &e.problem.u0, &u, path.then_some(framed.shift));
        sol.info.residual = sol.info.residual.max(sol.info.complementarity);
        finished(f, (u, phi), sol, &b, refined.residual)
    }
}

/// The equilibrium residual of `(u, φ)` against `b`: `refined`, where the refinement of
/// these fields measured it (the same number), else one product with `K`.
fn measured(
    f: &mut dyn Factorization,
    (u, phi): (&[f64], &[f64]),
    b: &ScaledRhs,
    refined: Option<f64>,
) -> Result<f64, ProblemError> {
    match refined {
        Some(residual) => Ok(residual),
        None => f.equilibrium(u, phi, rhs(b)),
    }
}

/// The fields `x` of a contact solve `sol`, with their equilibrium residual against `b`
/// (`refined`: as the refinement of `x` measured it).
fn finished(
    f: &mut dyn Factorization,
    x: Fields,
    sol: ContactSolution,
    b: &ScaledRhs,
    refined: Option<f64>,
) -> Result<InstantSolution, ProblemError> {
    let equilibrium = measured(f, (&x.0, &x.1), b, refined)?;
    Ok(InstantSolution {
        x,
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
    /// The written instants' solves as [`Instants::frames_superposed`] makes them: the parts'
    /// solutions at each instant's factors plus the solve of its contact forces alone (all
    /// together); `None` where an instant's loads are not the parts' sum at known factors, it
    /// has a bed or electrical contact, a contact force falls outside the condensation's dofs,
    /// or the factorisation cannot solve them so.
    fn superposed(
        &self,
        f: &mut dyn Factorization,
        frames: &[(Posed<'_>, InstantOf<'_>)],
    ) -> Result<Option<Vec<Fields>>, ProblemError> {
        if self.parts.is_empty() || self.dofs.is_empty() {
            return Ok(None);
        }
        let at: std::collections::HashMap<usize, usize> = self.dofs.iter().enumerate().map(|(i, &d)| (d, i)).collect();
        let mut updates = Vec::with_capacity(frames.len());
        let mut factors = Vec::with_capacity(frames.len());
        for (posed, of) in frames {
            let boundary = of.framed.boundary;
            let Some(fs) = posed.loads.factors.as_ref().filter(|fs| fs.len() == self.parts.len()) else {
                return Ok(None);
            };
            if posed.bed.is_some() || boundary.electric.is_some() {
                return Ok(None);
            }
            let mut d = vec![0.0; self.dofs.len()];
            for (j, force) in boundary.dofs.iter().zip(boundary.forces(&of.sol.lambda)) {
                let Some(&i) = at.get(j) else {
                    return Ok(None);
                };
                d[i] += force;
            }
            updates.push(d);
            factors.push(fs);
        }
        let views: Vec<&[f64]> = updates.iter().map(|d| &d[..]).collect();
        let Some(mut solved) = f.solve_trailing_many(&self.dofs, &views)? else {
            return Ok(None);
        };
        for ((u, phi), fs) in solved.iter_mut().zip(factors) {
            for ((pu, pphi), &w) in self.parts.iter().zip(fs) {
                if w != 0.0 {
                    u.iter_mut().zip(pu).for_each(|(x, p)| *x += w * p);
                    phi.iter_mut().zip(pphi).for_each(|(x, p)| *x += w * p);
                }
            }
        }
        Ok(Some(solved))
    }

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

/// Each written instant's right-hand side with its contact forces ([`rhs_with_contact`]).
fn frames_rhs(frames: &[(Posed<'_>, InstantOf<'_>)]) -> Vec<ScaledRhs> {
    frames
        .iter()
        .map(|(posed, of)| rhs_with_contact(posed, Some((of.framed.boundary, &of.sol))))
        .collect()
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
    boundary.potentials_at_points(phi, n_u)
}

/// `K⁻¹ b_q` for each part `q` of a path's right-hand side, in their order, solved together.
fn solve_parts(f: &mut dyn Factorization, parts: &[Fields]) -> Result<Vec<Fields>, ProblemError> {
    let columns: Vec<(&[f64], &[f64])> = parts.iter().map(|(b_u, b_phi)| (&b_u[..], &b_phi[..])).collect();
    f.solve_many(&columns)
}

/// A path, or a condensed strategy, on a factorisation that does not condense (the scene's
/// checks refuse it first).
fn not_direct() -> ProblemError {
    let feature =
        "a path or a condensed contact solve on a strategy without the L D Lᵀ of K (it carries friction's history on the condensed compliance)";
    crate::backend::Unsupported::new("faer", "solver.strategy", feature)
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
