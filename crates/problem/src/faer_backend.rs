//! The default backend: faer's sparse factorisations on one machine. A run without contact
//! is one solve with the factors, refined; a run with contact condenses `K` onto the contact
//! dofs (ordered last, so that the contact block comes off the one factorisation) and solves
//! the dense contact problem by semismooth Newton or a first-order method, or (the paper's
//! Uzawa) solves the primal problem once per first-order step.

use crate::backend::Unsupported;
use crate::backend::{Backend, ContactSolve, Figures, Finished, Limits, Posed, Solved};
use crate::boundary::{ContactBoundary, FullSolve};
use crate::progress::{Event, Reporter};
use crate::scene::{BackendChoice, ContactSolver, Rule, Scene, SceneError};
use crate::ProblemError;
use contact::{
    ContactError, ContactOperator, ContactPoints, ContactSolution, DenseContactProblem, NewtonParams, PointValues,
    StopRule, UzawaParams,
};
use fe_assembly::{Blocks, Parallelism};
use linalg::{CondenseRoute, CoupledSolver, DirectLdlt, Ordering, PcgParams, PcgStop, SchurPcg};
use std::time::Instant;

/// The default backend (`solver.backend = "faer"`): faer's sparse direct factorisations on
/// one machine.
#[derive(Clone, Copy, Debug, Default)]
pub struct Faer;

impl Backend for Faer {
    type Assembled = Blocks;
    type System = Factored;
    type Solution = Fields;
    type Error = ProblemError;
    const HELD_TO_TOLERANCE: bool = true;

    fn supports(&self, scene: &Scene) -> Result<(), Unsupported> {
        // the scene asks for another backend: solving it here would ignore that silently
        if scene.solver.backend != BackendChoice::Faer {
            return Err(Unsupported::new(
                "faer",
                "solver.backend",
                format!("solver.backend = \"{}\" asks for the distributed backend (the program built with the `petsc` feature, under mpirun; distributed::solve)", scene.solver.backend),
            )
            .advise("remove solver.backend, or set it to \"faer\""));
        }
        if scene.solver.petsc_options.is_some() {
            return Err(
                Unsupported::new("faer", "solver.petsc_options", "options for PETSc's database")
                    .advise("remove them, or set solver.backend = \"petsc\""),
            );
        }
        Ok(())
    }

    fn estimate(&self, scene: &Scene) -> Option<(f64, String)> {
        crate::estimate::before_mesh(scene)
    }

    /// Assembles `A`, `G`, `B` over the free dofs (on rayon's threads), checked finite.
    fn assemble(&mut self, posed: &Posed<'_>) -> Result<Blocks, ProblemError> {
        let blocks = posed.disc.assemble(Parallelism::Rayon);
        let scene = posed.scene.scene();
        ProblemError::check_finite(blocks.a.val(), "the stiffness matrix A", scene)?;
        ProblemError::check_finite(blocks.g.val(), "the coupling matrix G", scene)?;
        ProblemError::check_finite(blocks.b.val(), "the dielectric matrix B", scene)?;
        Ok(blocks)
    }

    fn prepare(
        &mut self,
        posed: &Posed<'_>,
        blocks: Blocks,
        boundary: Option<&ContactBoundary>,
        limits: Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<Factored, ProblemError> {
        factor(posed, blocks, boundary, limits, reporter)
    }

    fn solve_linear(
        &mut self,
        posed: &Posed<'_>,
        system: &mut Factored,
        _: &mut dyn Reporter,
    ) -> Result<Solved<Self::Solution>, ProblemError> {
        solve_linear(system, posed).map_err(|e| e.on_scene(&posed.scene))
    }

    fn solve_contact(
        &mut self,
        posed: &Posed<'_>,
        system: &mut Factored,
        boundary: ContactBoundary,
        how: &ContactSolve<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<Solved<Self::Solution>, ProblemError> {
        solve_contact(how, system, boundary, posed, reporter).map_err(|e| e.on_scene(&posed.scene))
    }

    fn equilibrium(
        &mut self,
        posed: &Posed<'_>,
        system: &Factored,
        solved: &Solved<Self::Solution>,
    ) -> Result<f64, ProblemError> {
        let (b_full, b_phi, scale) = rhs_with_contact(posed, solved.contact.as_ref().map(|(b, sol)| (b, sol)));
        let (b, (u, phi)) = (&system.blocks, &solved.x);
        Ok(linalg::equilibrium_residual(
            &b.a, &b.g, &b.b, u, phi, &b_full, &b_phi, scale,
        ))
    }

    fn finish(
        &mut self,
        _: &Posed<'_>,
        system: Factored,
        (u, phi): Self::Solution,
    ) -> Result<Option<Finished>, ProblemError> {
        let figures = system.figures();
        Ok(Some(Finished { u, phi, figures }))
    }
}

/// The free unknowns `(u, φ)`.
pub(crate) type Fields = (Vec<f64>, Vec<f64>);

/// The linear solver the plan asks for, factored once.
#[allow(clippy::large_enum_variant)] // one per run, moved never
enum LinearSolver {
    /// One `L D Lᵀ` of `K`.
    Direct(DirectLdlt),
    /// The paper's Schur-complement PCG (Cholesky factors of `A` and `B`).
    SchurPcg(SchurPcg),
}

impl LinearSolver {
    fn coupled(&mut self) -> &mut dyn CoupledSolver {
        match self {
            LinearSolver::Direct(d) => d,
            LinearSolver::SchurPcg(p) => p,
        }
    }
}

/// The assembled blocks and the factored solver, with what the solves measured on it.
pub struct Factored {
    blocks: Blocks,
    solver: LinearSolver,
    pcg_params: PcgParams,
    /// Wall time of the factorisation.
    seconds: f64,
    /// Steps of iterative refinement of the last solve.
    refinement: usize,
    /// How the contact compliance was formed, and in how long (condensed strategies).
    condense: Option<(CondenseRoute, f64)>,
}

impl Factored {
    /// What the factorisation and the solves on it measured, for the report.
    pub(crate) fn figures(&self) -> Figures {
        let (smallest_pivot_ratio, factor_bytes) = match &self.solver {
            LinearSolver::Direct(d) => (Some(d.factor().pivot_ratio()), d.factor_bytes()),
            LinearSolver::SchurPcg(p) => (None, p.factor_bytes()),
        };
        Figures {
            factor_seconds: self.seconds,
            condense: self.condense,
            pcg_rel_tol: self.pcg_params.rel_tol,
            smallest_pivot_ratio,
            refinement_steps: self.refinement,
            factor_bytes,
            petsc: None,
        }
    }

    /// The equilibrium residual of `(u, φ)` against the right-hand sides (their size `scale`).
    pub(crate) fn equilibrium_of(&self, u: &[f64], phi: &[f64], b_u: &[f64], b_phi: &[f64], scale: f64) -> f64 {
        let b = &self.blocks;
        linalg::equilibrium_residual(&b.a, &b.g, &b.b, u, phi, b_u, b_phi, scale)
    }
}

/// Factors the linear solver: the Schur PCG's Cholesky factors, or the `L D Lᵀ` of `K` in
/// geometric nested dissection (measured no slower than AMD in 2D and 1.6x faster in 3D,
/// docs/performance.md), with the contact dofs of `boundary` last for the condensed
/// strategies, to read the contact block off the factor; its elimination tree on all of
/// rayon's threads ([`linalg::pool_par`]).
fn factor(
    posed: &Posed<'_>,
    blocks: Blocks,
    boundary: Option<&ContactBoundary>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Factored, ProblemError> {
    let t = Instant::now();
    let (scene, plan) = (posed.scene.scene(), posed.plan());
    let paper = plan.rule == Rule::Paper;
    let pcg_params = PcgParams {
        rel_tol: plan.pcg_tol,
        max_iters: 10_000,
        stop: if paper {
            PcgStop::PaperRz
        } else {
            PcgStop::RelativeResidual
        },
        ..Default::default()
    };
    // the Schur route's Cholesky factors with faer's sequential walk (its parallel dense kernels
    // lose on 2 cores); the L D Lᵀ of K walks its elimination tree on rayon's pool
    let par = faer::Par::Seq;
    let budget = factor_budget(posed, &blocks, boundary, limits)?;
    let too_large = |e: linalg::LinalgError| too_large(e, limits, scene);
    let solver = if plan.linear_strategy.runs_pcg() {
        let pcg = SchurPcg::new_within(blocks.a.clone(), blocks.g.clone(), &blocks.b, pcg_params, par, budget)
            .map_err(too_large)?;
        LinearSolver::SchurPcg(pcg)
    } else {
        let mesh = &posed.setup.mesh;
        let order = posed
            .disc
            .dofs
            .expand_node_order(&mesh::nested_dissection(&mesh.points, &mesh.node_graph()));
        let ordering = match (boundary, plan.linear_strategy.is_condensed()) {
            (Some(cb), true) => Ordering::GivenThenLast {
                order,
                last: cb.condensed_dofs(),
            },
            _ => Ordering::Given(order),
        };
        LinearSolver::Direct(
            DirectLdlt::new_within(&blocks.a, &blocks.g, &blocks.b, &ordering, linalg::pool_par(), budget)
                .map_err(too_large)?,
        )
    };
    let seconds = t.elapsed().as_secs_f64();
    reporter.event(&Event::Factored { seconds });
    Ok(Factored {
        blocks,
        solver,
        pcg_params,
        seconds,
        refinement: 0,
        condense: None,
    })
}

/// The bytes left for the factor within `limits`, once the assembled blocks and (condensed
/// strategies) the dense contact problem are counted; an error where those alone do not fit.
fn factor_budget(
    posed: &Posed<'_>,
    b: &Blocks,
    boundary: Option<&ContactBoundary>,
    limits: Limits,
) -> Result<Option<usize>, ProblemError> {
    let Some(available) = limits.memory_bytes else {
        return Ok(None);
    };
    let (plan, dofs) = (posed.plan(), &posed.disc.dofs);
    let nnz = b.a.val().len() + b.g.val().len() + b.b.val().len();
    let held = crate::estimate::assembled(nnz, posed.setup.mesh.n_nodes(), dofs.n_u + dofs.n_phi);
    let dense = match boundary {
        Some(cb) if plan.linear_strategy.is_condensed() => {
            let k = cb.condensed_dofs().len();
            let m = cb.points.len() * (1 + plan.n_tangential()) + (k - cb.dofs.len());
            crate::estimate::dense_contact(k, m)
        }
        _ => 0.0,
    };
    // the peak of a run is the assembled system and the factor together, times PEAK_RATIO, and
    // BASE_BYTES beside (the factorisation's workspace, the recovery; measured on paper and
    // paper-3d at several sizes): the factor's budget leaves that margin
    let available_f = ((available as f64) - crate::estimate::BASE_BYTES).max(0.0) / crate::estimate::PEAK_RATIO;
    if held + dense > available_f {
        return Err(ProblemError::TooLarge {
            what: format!(
                "the assembled system and the dense contact compliance of a condensed strategy ({:.1} GiB)",
                dense / crate::estimate::GIB
            ),
            needed: ((held + dense) * crate::estimate::PEAK_RATIO + crate::estimate::BASE_BYTES) as u64,
            available,
            limit: limits.limit(),
        });
    }
    Ok(Some((available_f - held - dense) as usize))
}

/// A linear-algebra error, made [`ProblemError::TooLarge`] where the factor did not fit, and
/// [`ProblemError::IllConditioned`] where it broke down on an ill-conditioned scene.
fn too_large(e: linalg::LinalgError, limits: Limits, scene: &Scene) -> ProblemError {
    let inner = match &e {
        linalg::LinalgError::In { source, .. } => source.as_ref(),
        other => other,
    };
    match (inner, limits.memory_bytes) {
        (linalg::LinalgError::TooLarge { needed, budget }, Some(available)) => ProblemError::TooLarge {
            what: format!(
                "a sparse factor of {:.1} GiB, counted by its symbolic analysis, beside the assembled system",
                *needed as f64 / crate::estimate::GIB
            ),
            // the rest of the run takes what the factor's budget left out
            needed: (*needed + (available as usize).saturating_sub(*budget)) as u64,
            available,
            limit: limits.limit(),
        },
        _ => ProblemError::linear(e, scene),
    }
}

/// The one linear solve of a run without contact, refined with the factors of `K`.
fn solve_linear(system: &mut Factored, posed: &Posed<'_>) -> Result<Solved<Fields>, ProblemError> {
    let t = Instant::now();
    let (dofs, loads) = (&posed.disc.dofs, &posed.loads);
    let (mut u, mut phi) = (vec![0.0; dofs.n_u], vec![0.0; dofs.n_phi]);
    let info = system
        .solver
        .coupled()
        .solve(&loads.b_u, &loads.b_phi, &mut u, &mut phi)?;
    if let LinearSolver::Direct(direct) = &mut system.solver {
        let (b, b_phi, scale) = rhs_with_contact(posed, None);
        system.refinement = refine(direct, &system.blocks, &b, &b_phi, scale, &mut u, &mut phi, REFINE_TOL)?.steps;
    }
    Ok(Solved {
        x: (u, phi),
        contact: None,
        pcg_iters: info.pcg_iters,
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// The contact problem as its solvers see it.
enum Operator<'a> {
    /// The condensed compliance (Newton, or a first-order method).
    Condensed(&'a mut DenseContactProblem),
    /// One full primal solve per call (first-order methods).
    FullSolves(&'a mut dyn ContactOperator),
}

impl ContactSolve<'_> {
    /// Semismooth Newton's parameters for this solve: its tolerance and interrupt.
    fn newton_params(&self) -> NewtonParams {
        NewtonParams {
            tol: self.tol,
            interrupt: self.interrupt,
            ..Default::default()
        }
    }

    /// Runs the strategy's contact solver on `problem`, reporting each outer iteration.
    fn run(
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
    /// control's search ([`force_controlled`]), whose force must be this depth's. Taken as it
    /// was, the start of the depth before carried its force: the search's residual stood still
    /// while the depth moved, and it ended on a force 3e-8 off (`hertz-sphere` n = 96 on a
    /// 20-step path, at t = 0.3).
    fn run_with(
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
                match &self.weakening {
                    // the branch from the stick start, whatever the warm start
                    Some(w) => {
                        let params = contact::WeakeningParams {
                            newton: params,
                            tol,
                            ..Default::default()
                        };
                        let cache = &mut self.cache.borrow_mut();
                        contact::solve_slip_weakening_cached(dense, points, w, &params, &mut progress, cache)
                    }
                    None => {
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
                contact::solve(op, points, &self.law, &params, start, &mut progress)
            }
            (ContactSolver::Newton, Operator::FullSolves(_)) => Err(ContactError::Input(
                contact::InputError::Unsupported("semismooth Newton needs the condensed compliance"),
            )),
        };
        solved.map_err(|e| ProblemError::contact(e, self.plan.linear_strategy, self.scene))
    }
}

/// Force control (`contact.indenter.force`): [`contact::solve_force_controlled`] around the
/// contact solve `solve`; where no depth carries the force, no solution keyed
/// `contact.indenter.force`.
pub(crate) fn force_controlled(
    points: &mut ContactPoints,
    force: f64,
    start: Option<PointValues>,
    solve: impl FnMut(&ContactPoints, Option<PointValues>) -> Result<ContactSolution, ProblemError>,
) -> Result<ContactSolution, ProblemError> {
    contact::solve_force_controlled(points, force, start, solve).map_err(|e| match e {
        contact::ForceError::Solve(e) => e,
        other => ProblemError::NoSolution {
            sought: "contact.indenter.force",
            why: other.to_string(),
        },
    })
}

/// A floating conducting tip (`contact.charge`): [`contact::solve_floating`] around the
/// contact solve `newton`; where no potential carries the charge, no solution keyed
/// `contact.charge`.
fn floating_tip(
    problem: &mut contact::ElectricContactProblem,
    points: &ContactPoints,
    charge: f64,
    newton: &mut impl FnMut(&contact::ElectricContactProblem, &ContactPoints) -> Result<ContactSolution, ProblemError>,
) -> Result<ContactSolution, ProblemError> {
    contact::solve_floating(problem, points, charge, newton).map_err(|e| match e {
        contact::FloatingError::Solve(e) => e,
        other => ProblemError::NoSolution {
            sought: "contact.charge",
            why: other.to_string(),
        },
    })
}

/// The force of a force-controlled indenter in `posed`'s scene.
fn indenter_force(posed: &Posed<'_>) -> Option<f64> {
    posed
        .scene
        .first_contact()
        .and_then(|c| c.indenter.as_ref())
        .and_then(|i| i.force)
}

/// The contact solve: on the condensed compliance (Newton, or a first-order method), or with
/// one full primal solve per first-order step; then `(u, φ)` under the contact forces found.
fn solve_contact(
    how: &ContactSolve<'_>,
    system: &mut Factored,
    mut boundary: ContactBoundary,
    posed: &Posed<'_>,
    reporter: &mut dyn Reporter,
) -> Result<Solved<Fields>, ProblemError> {
    let t = Instant::now();
    let nt = how.plan.n_tangential();
    let condensed = how.plan.linear_strategy.is_condensed();
    // electrical contact: its law, owned (force control lowers the boundary's gaps)
    let electric = boundary.electric.as_ref().map(|(e, _)| e.clone());
    let (sol, (u, phi)) = match (&mut system.solver, electric) {
        (LinearSolver::Direct(direct), Some(electric)) if condensed => {
            let (sol, fields, condense, refinement) =
                electric_contact(how, &electric, direct, &system.blocks, &mut boundary, posed, reporter)?;
            system.condense = Some(condense);
            system.refinement = refinement;
            (sol, fields)
        }
        (LinearSolver::Direct(direct), None) if condensed => {
            let t_condense = Instant::now();
            let loads = &posed.loads;
            let (mut dense, condensed) = boundary.condense(direct, &loads.b_u, &loads.b_phi, nt)?;
            let condense = (condensed.route, t_condense.elapsed().as_secs_f64());
            reporter.event(&Event::Condensed {
                m: dense.m(),
                route: condense.0,
                seconds: condense.1,
            });
            system.condense = Some(condense);
            let sol = match indenter_force(posed) {
                Some(force) => force_controlled(&mut boundary.points, force, None, |points, start| {
                    how.run_with(Operator::Condensed(&mut dense), points, start, true, reporter)
                })?,
                None => how.run(Operator::Condensed(&mut dense), &boundary.points, None, reporter)?,
            };
            let (mut u, mut phi) = boundary.recover(direct, condensed, &sol.lambda, &loads.b_u, &loads.b_phi)?;
            let mut on = Refining {
                direct,
                blocks: &system.blocks,
                posed,
                boundary: &boundary,
                refinement: 0,
                shift: None,
                refine_tol: REFINE_TOL,
            };
            let sol = on.correct(how, &mut dense, sol, (&mut u, &mut phi), reporter)?;
            system.refinement = on.refinement;
            (sol, (u, phi))
        }
        (other, _) => {
            let mut op = FullSolve {
                boundary: &boundary,
                solver: other.coupled(),
                b_u: &posed.loads.b_u,
                b_phi: &posed.loads.b_phi,
                nt,
                u: vec![0.0; posed.disc.dofs.n_u],
                phi: vec![0.0; posed.disc.dofs.n_phi],
            };
            let sol = how.run(Operator::FullSolves(&mut op), &boundary.points, None, reporter)?;
            (sol, (op.u, op.phi))
        }
    };
    Ok(Solved {
        x: (u, phi),
        pcg_iters: sol.info.inner_iters,
        contact: Some((boundary, sol)),
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// The contact solve with electrical contact: the condensation onto the points'
/// displacements and free potentials, semismooth Newton on all their rows, the fields under
/// the forces and the flux found, refined; the law judged on the refined fields. Returns the
/// solution, the fields, how the condensation was formed and in how long, and the refinement
/// steps.
#[allow(clippy::too_many_arguments)]
fn electric_contact(
    how: &ContactSolve<'_>,
    electric: &contact::ElectricContact,
    direct: &mut DirectLdlt,
    blocks: &Blocks,
    boundary: &mut ContactBoundary,
    posed: &Posed<'_>,
    reporter: &mut dyn Reporter,
) -> Result<(ContactSolution, Fields, (CondenseRoute, f64), usize), ProblemError> {
    let t = Instant::now();
    let loads = &posed.loads;
    let nt = how.plan.n_tangential();
    let (problem, condensed) = boundary.condense_electric(electric, direct, &loads.b_u, &loads.b_phi, nt)?;
    let condense = (condensed.route, t.elapsed().as_secs_f64());
    reporter.event(&Event::Condensed {
        m: problem.order(),
        route: condense.0,
        seconds: condense.1,
    });
    let tol = how.tol;
    let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
    let mut newton = |problem: &contact::ElectricContactProblem, points: &ContactPoints| {
        contact::solve_newton_electric(problem, points, &how.law, &how.newton_params(), &mut progress)
            .map_err(|e| ProblemError::contact(e, how.plan.linear_strategy, how.scene))
    };
    let mut problem = problem;
    let floating = posed.scene.first_contact().and_then(|c| c.charge);
    let mut solve = |points: &ContactPoints, _: Option<PointValues>| match floating {
        Some(charge) => floating_tip(&mut problem, points, charge, &mut newton),
        None => newton(&problem, points),
    };
    let mut sol = match indenter_force(posed) {
        Some(force) => force_controlled(&mut boundary.points, force, None, &mut solve)?,
        None => solve(&boundary.points, None)?,
    };
    let (mut u, mut phi) = boundary.recover_electric(direct, condensed, &sol, &loads.b_u, &loads.b_phi)?;
    let (b_u, b_phi, scale) = rhs_with_contact(posed, Some((boundary, &sol)));
    let refinement = refine(direct, blocks, &b_u, &b_phi, scale, &mut u, &mut phi, REFINE_TOL)?.steps;
    // the potentials reported are the refined fields'
    if let (Some(e), Some((_, dofs))) = (&mut sol.electric, &boundary.electric) {
        let n_u = loads.b_u.len();
        for (v, &d) in e.potential.iter_mut().zip(dofs) {
            *v = phi[d - n_u];
        }
    }
    sol.info.complementarity = law_residual(boundary, how, &sol, &problem.u0, &u, None);
    sol.info.residual = sol.info.residual.max(sol.info.complementarity);
    Ok((sol, (u, phi), condense, refinement))
}

/// The fields of a condensed contact solve, refined with the factors of `K`.
struct Refining<'a> {
    direct: &'a mut DirectLdlt,
    blocks: &'a Blocks,
    posed: &'a Posed<'a>,
    boundary: &'a ContactBoundary,
    /// Steps of iterative refinement of the last solve.
    refinement: usize,
    /// A path's step: the tangential displacement of the points at the step before, which
    /// the friction law's slip is measured from (the contact problem's frame).
    shift: Option<&'a PointValues>,
    /// The equilibrium residual above which the fields are refined ([`REFINE_TOL`] for one
    /// instant; a path's steps refine only what a direct solve did not reach,
    /// [`PATH_REFINE_TOL`]).
    refine_tol: f64,
}

/// The equilibrium residual a run's fields are refined to.
const REFINE_TOL: f64 = 1e-14;

/// The equilibrium residual above which a path's step refines its fields: a direct solve
/// reaches 1e-13 to 1e-15 on the shipped scenes, and a refinement step costs a solve, the
/// step's own cost (measured on `paper-cycle`, n = 128: 1 to 3 refinement steps tripled it).
const PATH_REFINE_TOL: f64 = 1e-12;

impl Refining<'_> {
    /// The fields are those of the last solve: refined, and the contact law judged on them
    /// (not on the condensed problem's own displacement); where the compliance lost digits to
    /// an ill-conditioned system, its defect at the points is corrected, at most
    /// [`MAX_CORRECTIONS`] times (each a warm contact solve and one solve with the factors).
    fn correct(
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
            let (b_full, b_phi, scale) = rhs_with_contact(posed, Some((boundary, &sol)));
            self.refinement += refine(
                self.direct,
                self.blocks,
                &b_full,
                &b_phi,
                scale,
                u,
                phi,
                self.refine_tol,
            )?
            .steps;
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
            self.direct.solve(&b_full, &b_phi, u, phi)?;
            corrections += 1;
        }
        sol.info.residual = sol.info.residual.max(sol.info.complementarity);
        Ok(sol)
    }
}

/// The right-hand sides with the contact forces of `contact` (and the electric flux, with
/// electrical contact), and the size of their parts (the loads, the contact forces: they may
/// cancel in the sum).
pub(crate) fn rhs_with_contact(
    posed: &Posed<'_>,
    contact: Option<(&ContactBoundary, &ContactSolution)>,
) -> (Vec<f64>, Vec<f64>, f64) {
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

/// Iterative refinement of the last solve (with `K`'s factors), to the equilibrium residual
/// `tol`: at most 3 corrections, each kept only where it lowers the residual.
#[allow(clippy::too_many_arguments)]
fn refine(
    direct: &mut DirectLdlt,
    b: &Blocks,
    b_u: &[f64],
    b_phi: &[f64],
    scale: f64,
    u: &mut [f64],
    phi: &mut [f64],
    tol: f64,
) -> Result<linalg::Refined, ProblemError> {
    let k = linalg::CoupledBlocks {
        a: &b.a,
        g: &b.g,
        b: &b.b,
    };
    Ok(linalg::refine(direct, k, b_u, b_phi, u, phi, scale, tol, 3)?)
}

/// Corrections of the condensed problem by its defect at the points, at most (each a warm
/// Newton solve and one solve with the factors): where the compliance is accurate to a
/// fraction, each gains that fraction's digits.
const MAX_CORRECTIONS: usize = 4;

/// The displacement of the points in the free vector `u`, in the contact problem's layout
/// (`nt` tangential components: none without friction).
fn fields_at_points(boundary: &ContactBoundary, u: &[f64], nt: usize) -> PointValues {
    let points = &boundary.points;
    let mut all = PointValues::zeros(points.len(), points.n_tangential());
    boundary.extract(u, &mut all);
    let tangential = if nt > 0 { all.tangential } else { vec![] };
    PointValues::from_parts(all.normal, tangential, nt).unwrap_or_else(|_| PointValues::zeros(points.len(), nt))
}

/// The points' displacement `at` in the frame of a path's step: its tangential part less
/// `shift` (the step before's), the slip increment the friction law reads.
fn in_frame(mut at: PointValues, shift: Option<&PointValues>) -> PointValues {
    if let Some(s) = shift {
        for (v, s) in at.tangential.iter_mut().zip(&s.tangential) {
            *v -= s;
        }
    }
    at
}

/// The complementarity residual of the law on the final fields: the multipliers of `sol` with
/// the displacement of the points in `u` (the last, refined solve), against the loads' `u0`.
fn law_residual(
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
        let t = Instant::now();
        let (b_u, b_phi) = &parts[0];
        let (dense, condensed) = boundary.condense(direct, b_u, b_phi, nt)?;
        let condense = (condensed.route, t.elapsed().as_secs_f64());
        reporter.event(&Event::Condensed {
            m: dense.m(),
            route: condense.0,
            seconds: condense.1,
        });
        system.condense = Some(condense);
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

    /// The contact problem of a step: the loads' displacement at the points for the step's
    /// `factors` (the parts summed), in the frame of the step before's tangential displacement
    /// `shift` (friction on the slip increment), warm-started from `start`. Its displacements
    /// are in that frame.
    pub(crate) fn contact(
        &mut self,
        how: &ContactSolve<'_>,
        boundary: &ContactBoundary,
        factors: &[f64],
        shift: &PointValues,
        start: Option<PointValues>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, ProblemError> {
        self.prime(boundary, factors, shift);
        how.run(Operator::Condensed(&mut self.dense), &boundary.points, start, reporter)
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
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn fields(
        &mut self,
        how: &ContactSolve<'_>,
        system: &mut Factored,
        boundary: &ContactBoundary,
        posed: &Posed<'_>,
        shift: &PointValues,
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

/// A path on a strategy without the `L D Lᵀ` of `K` (the scene's checks refuse it first).
fn not_direct() -> ProblemError {
    SceneError::new(
        "path",
        "a path carries friction's history on the condensed compliance of the L D Lᵀ of K: use a condensed strategy",
    )
    .into()
}
