//! A run, read as the method (as deal.II's step-41 reads): set up, assemble, factor, solve the
//! contact problem (or the one linear system), recover the fields, report. Each step is one
//! function; [`solve`] calls them in order and times them.

use crate::boundary::{ContactBoundary, FullSolve};
use crate::exact::contact_errors;
use crate::plan::Plan;
use crate::progress::{Event, Reporter};
use crate::report::{
    rule_in_words, ContactReport, DofsReport, Iterations, Memory, MeshReport, Residuals, RunReport, SceneReport,
    SolverReport, Timings,
};
use crate::scene::{Backend, ContactLaw, ContactSolver, Rule, Scene, SceneError};
use crate::setup::{setup, MeshNotes, Setup};
use crate::ProblemError;
use contact::{
    ContactError, ContactOperator, ContactPoints, ContactSolution, DenseContactProblem, Law, NewtonParams, PointValues,
    StopRule, UzawaParams,
};
use fe_assembly::{Blocks, CellFields, Discretization, Parallelism};
use linalg::{equilibrium_residual, CondenseRoute, CoupledSolver, DirectLdlt, Ordering, PcgParams, PcgStop, SchurPcg};
use std::time::Instant;

/// What a run produced: its report, the mesh, the nodal solution, the per-cell fields, and the
/// contact solution where the plan has contact.
pub struct Solution {
    /// What `run.json` holds.
    pub report: RunReport,
    /// The mesh (with the scene's regions and electrode group).
    pub mesh: mesh::Mesh,
    /// Nodal displacements (`z = 0` in 2D).
    pub u: Vec<[f64; 3]>,
    /// Nodal potentials (0 where a node has no electric unknown).
    pub phi: Vec<f64>,
    /// Per-cell stress, strain, electric displacement and field.
    pub fields: CellFields,
    /// The contact points and their solution.
    pub contact: Option<ContactResult>,
}

/// The contact solution on its points.
pub struct ContactResult {
    /// The contact points.
    pub points: ContactPoints,
    /// The mesh node of each point.
    pub nodes: Vec<usize>,
    /// Multipliers, displacements and status, as the contact solver returned them (without
    /// friction, the displacements have no tangential part).
    pub solution: ContactSolution,
    /// `u_n` and all `dim - 1` components of `u_t` of the final displacement, whatever the law
    /// (a frictionless body slides too).
    pub displacement: PointValues,
}

/// What a run may use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Limits {
    /// Bytes of memory the run may take (`None`: no check).
    pub memory_bytes: Option<u64>,
    /// What sets `memory_bytes`, in words (for the message of a run too large): the
    /// machine's available memory, an address-space limit, a memory cgroup.
    pub memory_limit: Option<&'static str>,
    /// A deadline or a cancel flag for the contact solve (a typed
    /// [`contact::ContactError::Interrupted`], with the best iterate, when it fires).
    pub interrupt: contact::Interrupt,
}

/// Solves `scene`. `mesh` is the mesh of a `gmsh` scene, read by the caller (generated meshes
/// are made here); `reporter` receives one event per step and per outer iteration.
///
/// # Errors
/// A [`ProblemError`] naming the scene key, mesh item, material or solver step at fault.
pub fn solve(scene: &Scene, mesh: Option<mesh::Mesh>, reporter: &mut dyn Reporter) -> Result<Solution, ProblemError> {
    solve_within(scene, mesh, Limits::default(), reporter)
}

/// As [`solve`], within `limits`: a run whose memory estimate exceeds them stops with
/// [`ProblemError::TooLarge`] before the memory is taken (see [`crate::estimate`]).
///
/// # Errors
/// As [`solve`], and [`ProblemError::TooLarge`].
pub fn solve_within(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Solution, ProblemError> {
    scene.validate()?;
    if scene.solver.backend != Backend::Faer {
        // the scene asks for another backend: solving it here would ignore that silently
        return Err(SceneError::new(
            "solver.backend",
            format!(
                "solver.backend = \"{}\" is solved by the distributed backend (the program built with the `petsc` feature, under mpirun; distributed::solve); this is the default backend's solve: remove solver.backend, or set it to \"faer\"",
                scene.solver.backend
            ),
        )
        .into());
    }
    let t_total = Instant::now();
    let setup = begin(scene, mesh, crate::estimate::before_mesh(scene), &limits, reporter)?;
    let t_setup = t_total.elapsed().as_secs_f64();
    stop_if_interrupted(&limits, "set-up")?;
    let assembled = assemble(&setup, reporter)?;
    check_assembled(scene, &assembled)?;
    stop_if_interrupted(&limits, "assembly")?;
    let mut factored = factor(scene, &setup, &assembled, limits, reporter)?;
    stop_if_interrupted(&limits, "factorisation")?;
    let solved = match factored.boundary.take() {
        Some(boundary) => {
            let how = ContactSolve::new(&setup.plan, scene, boundary.points.len(), limits.interrupt);
            solve_contact(&how, &mut factored.solver, boundary, &assembled, reporter).map_err(|e| e.on_scene(scene))?
        }
        None => solve_linear(&mut factored.solver, &assembled).map_err(|e| e.on_scene(scene))?,
    };
    check_solved(scene, &solved)?;
    let equilibrium = equilibrium(&assembled, &solved);
    reporter.event(&Event::Solved {
        seconds: solved.seconds,
        pcg_iters: solved.pcg_iters,
        equilibrium,
    });
    ProblemError::check_finite(&[equilibrium], "the equilibrium residual", scene)?;
    check_accurate(scene, &setup.plan, &solved, equilibrium)?;
    let contact = solved.contact.as_ref().map(|(b, sol)| (b, sol));
    let recovered = recover(
        scene,
        &setup,
        &assembled.disc,
        (&solved.u, &solved.phi),
        contact,
        equilibrium,
        reporter,
    )?;
    let times = Timings {
        setup: t_setup,
        assembly: assembled.seconds,
        factorization: factored.seconds,
        condense: solved.condense.map_or(0.0, |c| c.1),
        contact: if solved.contact.is_some() { solved.seconds } else { 0.0 },
        solve: solved.seconds,
        total: t_total.elapsed().as_secs_f64(),
    };
    let report = report(
        scene,
        &setup,
        &assembled,
        &factored,
        &solved,
        &recovered,
        equilibrium,
        times,
    );
    drop(assembled);
    Ok(Solution {
        report,
        mesh: setup.mesh,
        u: recovered.u,
        phi: recovered.phi,
        fields: recovered.fields,
        contact: solved.contact.map(|(b, solution)| {
            let mut displacement = PointValues::zeros(b.points.len(), b.points.n_tangential());
            b.extract(&solved.u, &mut displacement);
            ContactResult {
                points: b.points,
                nodes: b.nodes,
                solution,
                displacement,
            }
        }),
    })
}

/// The start of a run on either backend: the memory `estimate` (bytes, and what it counts)
/// checked against `limits` before the memory is taken, then the [`Setup`], its plan and what
/// the mesh's checks noted reported.
///
/// # Errors
/// [`ProblemError::TooLarge`], and the set-up's errors.
pub fn begin(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    estimate: Option<(f64, String)>,
    limits: &Limits,
    reporter: &mut dyn Reporter,
) -> Result<Setup, ProblemError> {
    check_memory(limits, estimate)?;
    let setup = setup(scene, mesh)?;
    // a mesh read or handed over is known only now: the same model, before anything is built
    // on it
    check_memory(limits, crate::estimate::after_mesh(&setup.mesh, setup.plan.electric))?;
    reporter.event(&Event::Planned(&setup.plan));
    if setup.notes != MeshNotes::default() {
        reporter.event(&Event::MeshNotes(setup.notes));
    }
    Ok(setup)
}

/// [`ProblemError::TooLarge`] where the `estimate` (bytes, and what it counts) exceeds the
/// memory of `limits`.
fn check_memory(limits: &Limits, estimate: Option<(f64, String)>) -> Result<(), ProblemError> {
    if let (Some(available), Some((needed, what))) = (limits.memory_bytes, estimate) {
        if needed > available as f64 {
            return Err(ProblemError::TooLarge {
                what,
                needed: needed as u64,
                available,
                limit: limits.limit(),
            });
        }
    }
    Ok(())
}

impl Limits {
    /// What limits the memory, in words.
    fn limit(&self) -> &'static str {
        self.memory_limit.unwrap_or("the memory available")
    }
}

/// [`ProblemError::Interrupted`] after the step `after` where the run's interrupt has fired.
fn stop_if_interrupted(limits: &Limits, after: &'static str) -> Result<(), ProblemError> {
    match limits.interrupt.check() {
        Some(why) => Err(ProblemError::Interrupted { after, why }),
        None => Ok(()),
    }
}

/// The assembled blocks and loads.
struct Assembled<'m> {
    disc: Discretization<'m>,
    blocks: Blocks,
    b_u: Vec<f64>,
    b_phi: Vec<f64>,
    seconds: f64,
}

/// Assembles `A`, `G`, `B` and the loads over the free dofs.
fn assemble<'m>(setup: &'m Setup, reporter: &mut dyn Reporter) -> Result<Assembled<'m>, ProblemError> {
    let t = Instant::now();
    let disc = Discretization::new(&setup.mesh, &setup.materials, &setup.constraints)?;
    disc.check_held().map_err(fe_assembly::AssemblyError::from)?;
    let blocks = disc.assemble(Parallelism::Rayon);
    let (b_u, b_phi) = disc.rhs(&setup.loads)?;
    let seconds = t.elapsed().as_secs_f64();
    reporter.event(&Event::assembled(&setup.mesh, &disc.dofs, seconds));
    Ok(Assembled {
        disc,
        blocks,
        b_u,
        b_phi,
        seconds,
    })
}

/// Checks the assembled blocks and loads for numbers that overflowed.
fn check_assembled(scene: &Scene, a: &Assembled<'_>) -> Result<(), ProblemError> {
    ProblemError::check_finite(&a.b_u, "the mechanical load vector", scene)?;
    ProblemError::check_finite(&a.b_phi, "the electric load vector", scene)?;
    ProblemError::check_finite(a.blocks.a.val(), "the stiffness matrix A", scene)?;
    ProblemError::check_finite(a.blocks.g.val(), "the coupling matrix G", scene)?;
    ProblemError::check_finite(a.blocks.b.val(), "the dielectric matrix B", scene)
}

/// Checks the solution for numbers that overflowed.
fn check_solved(scene: &Scene, s: &Solved) -> Result<(), ProblemError> {
    ProblemError::check_finite(&s.u, "the displacement", scene)?;
    ProblemError::check_finite(&s.phi, "the potential", scene)?;
    if let Some((_, sol)) = &s.contact {
        ProblemError::check_finite(&sol.lambda.normal, "the contact pressure", scene)?;
        ProblemError::check_finite(&sol.lambda.tangential, "the tangential multiplier", scene)?;
    }
    Ok(())
}

/// Under the tight rule, every reported residual meets its tolerance, or the run fails naming
/// what makes the system ill-conditioned: the equilibrium residual ([`EQUILIBRIUM_TOL`]) and
/// the complementarity residual of the final fields (`solver.tol`).
fn check_accurate(scene: &Scene, plan: &Plan, s: &Solved, equilibrium: f64) -> Result<(), ProblemError> {
    if plan.rule != Rule::Tight {
        return Ok(());
    }
    if !(equilibrium <= EQUILIBRIUM_TOL) {
        return Err(ProblemError::inaccurate(
            "equilibrium residual",
            equilibrium,
            EQUILIBRIUM_TOL,
            scene,
        ));
    }
    if let Some((_, sol)) = &s.contact {
        let c = sol.info.complementarity;
        if !(c <= scene.solver.tol) {
            return Err(ProblemError::inaccurate(
                "complementarity residual of the final fields",
                c,
                scene.solver.tol,
                scene,
            ));
        }
    }
    Ok(())
}

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

/// The factored solver, and the contact boundary (built with it: its dofs order the factor).
struct Factored {
    solver: LinearSolver,
    boundary: Option<ContactBoundary>,
    pcg_params: PcgParams,
    seconds: f64,
}

/// Builds the contact boundary (where the plan has contact) and factors the linear solver:
/// the Schur PCG's Cholesky factors, or the `L D Lᵀ` of `K` in geometric nested dissection
/// (measured no slower than AMD in 2D and 1.6x faster in 3D, docs/performance.md), with the
/// contact dofs last for the condensed strategies, to read the contact block off the factor.
fn factor(
    scene: &Scene,
    setup: &Setup,
    a: &Assembled<'_>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Factored, ProblemError> {
    let t = Instant::now();
    let plan = &setup.plan;
    let paper = plan.rule == Rule::Paper;
    let pcg_params = PcgParams {
        rel_tol: scene.solver.pcg_tol.unwrap_or(if paper { 1e-2 } else { 1e-12 }),
        max_iters: 10_000,
        stop: if paper {
            PcgStop::PaperRz
        } else {
            PcgStop::RelativeResidual
        },
        ..Default::default()
    };
    let boundary = match scene.contact.as_ref().filter(|_| plan.contact_law != ContactLaw::None) {
        Some(spec) => Some(ContactBoundary::new(&setup.mesh, &a.disc.dofs, spec)?),
        None => None,
    };
    if let (Some(b), Some(spec)) = (&boundary, &scene.contact) {
        b.report_held(&spec.group, reporter);
    }
    let par = faer::Par::Seq;
    let budget = factor_budget(setup, a, boundary.as_ref(), limits)?;
    let too_large = |e: linalg::LinalgError| too_large(e, limits, scene);
    let (blocks, mesh) = (&a.blocks, &setup.mesh);
    let solver = if plan.linear_strategy.runs_pcg() {
        let pcg = SchurPcg::new_within(blocks.a.clone(), blocks.g.clone(), &blocks.b, pcg_params, par, budget)
            .map_err(too_large)?;
        LinearSolver::SchurPcg(pcg)
    } else {
        let order = a
            .disc
            .dofs
            .expand_node_order(&mesh::nested_dissection(&mesh.points, &mesh.node_graph()));
        let ordering = match (&boundary, plan.linear_strategy.is_condensed()) {
            (Some(cb), true) => Ordering::GivenThenLast {
                order,
                last: cb.dofs.clone(),
            },
            _ => Ordering::Given(order),
        };
        LinearSolver::Direct(
            DirectLdlt::new_within(&blocks.a, &blocks.g, &blocks.b, &ordering, par, budget).map_err(too_large)?,
        )
    };
    let seconds = t.elapsed().as_secs_f64();
    reporter.event(&Event::Factored { seconds });
    Ok(Factored {
        solver,
        boundary,
        pcg_params,
        seconds,
    })
}

/// The bytes left for the factor within `limits`, once the assembled blocks and (condensed
/// strategies) the dense contact problem are counted; an error where those alone do not fit.
fn factor_budget(
    setup: &Setup,
    a: &Assembled<'_>,
    boundary: Option<&ContactBoundary>,
    limits: Limits,
) -> Result<Option<usize>, ProblemError> {
    let Some(available) = limits.memory_bytes else {
        return Ok(None);
    };
    let b = &a.blocks;
    let nnz = b.a.val().len() + b.g.val().len() + b.b.val().len();
    let held = crate::estimate::assembled(nnz, setup.mesh.n_nodes(), a.disc.dofs.n_u + a.disc.dofs.n_phi);
    let dense = match boundary {
        Some(cb) if setup.plan.linear_strategy.is_condensed() => {
            let m = cb.points.len() * (1 + setup.plan.n_tangential());
            crate::estimate::dense_contact(cb.dofs.len(), m)
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

/// The solution `(u, φ)` with, where the plan has contact, the boundary and its solution.
struct Solved {
    u: Vec<f64>,
    phi: Vec<f64>,
    contact: Option<(ContactBoundary, ContactSolution)>,
    pcg_iters: usize,
    /// Steps of iterative refinement of the last solve.
    refinement: usize,
    /// How the contact compliance was formed, and in how long (condensed strategies).
    condense: Option<(CondenseRoute, f64)>,
    seconds: f64,
}

/// The one linear solve of a run without contact.
fn solve_linear(solver: &mut LinearSolver, a: &Assembled<'_>) -> Result<Solved, ProblemError> {
    let t = Instant::now();
    let (mut u, mut phi) = (vec![0.0; a.disc.dofs.n_u], vec![0.0; a.disc.dofs.n_phi]);
    let info = solver.coupled().solve(&a.b_u, &a.b_phi, &mut u, &mut phi)?;
    let refinement = match solver {
        LinearSolver::Direct(direct) => {
            let (b, scale) = rhs_with_contact(a, None);
            refine(direct, a, &b, scale, &mut u, &mut phi)?.steps
        }
        LinearSolver::SchurPcg(_) => 0,
    };
    Ok(Solved {
        u,
        phi,
        contact: None,
        pcg_iters: info.pcg_iters,
        refinement,
        condense: None,
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

/// How the plan's contact problem is solved: the law on its points, the solver, the tolerance.
struct ContactSolve<'p> {
    plan: &'p Plan,
    scene: &'p Scene,
    law: Law,
    tol: f64,
    interrupt: contact::Interrupt,
}

impl<'p> ContactSolve<'p> {
    /// The plan's contact law on `n` points: frictionless without tangential multipliers,
    /// Tresca with the scene's bound, else Coulomb.
    fn new(plan: &'p Plan, scene: &'p Scene, n: usize, interrupt: contact::Interrupt) -> Self {
        let law = plan.law(scene, n);
        // the first-order solvers meet Coulomb's law by the fixed point on S, Newton directly
        debug_assert_eq!(
            plan.fixed_point,
            law == Law::Coulomb && matches!(plan.linear_strategy.contact_solver(), ContactSolver::FirstOrder { .. })
        );
        ContactSolve {
            plan,
            scene,
            law,
            tol: scene.solver.tol,
            interrupt,
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
        let tol = self.tol;
        let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
        let solved = match (self.plan.linear_strategy.contact_solver(), problem) {
            (ContactSolver::Newton, Operator::Condensed(dense)) => {
                let params = NewtonParams {
                    tol,
                    interrupt: self.interrupt,
                    ..Default::default()
                };
                contact::solve_newton(dense, points, &self.law, &params, start, &mut progress)
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
                "semismooth Newton needs the condensed compliance".into(),
            )),
        };
        solved.map_err(|e| ProblemError::contact(e, self.plan.linear_strategy, self.scene))
    }
}

/// The contact solve: on the condensed compliance (Newton, or a first-order method), or with
/// one full primal solve per first-order step; then `(u, φ)` under the contact forces found.
fn solve_contact(
    how: &ContactSolve<'_>,
    solver: &mut LinearSolver,
    boundary: ContactBoundary,
    a: &Assembled<'_>,
    reporter: &mut dyn Reporter,
) -> Result<Solved, ProblemError> {
    let t = Instant::now();
    let plan = how.plan;
    let mut refinement = 0;
    let ((sol, (u, phi)), condense) = match solver {
        LinearSolver::Direct(direct) if plan.linear_strategy.is_condensed() => {
            let t_condense = Instant::now();
            let (mut dense, loads) = boundary.condense(direct, &a.b_u, &a.b_phi, plan.n_tangential())?;
            let condense = (loads.route, t_condense.elapsed().as_secs_f64());
            reporter.event(&Event::Condensed {
                m: dense.m(),
                route: condense.0,
                seconds: condense.1,
            });
            let mut sol = how.run(Operator::Condensed(&mut dense), &boundary.points, None, reporter)?;
            let u0 = dense.u0.clone();
            let (mut u, mut phi) = boundary.recover(direct, loads, &sol.lambda, &a.b_u, &a.b_phi)?;
            // the fields are those of the last solve: refined, and the contact law judged on
            // them (not on the condensed problem's own displacement); where the compliance lost
            // digits to an ill-conditioned system, its defect at the points is corrected
            let mut corrections = 0;
            loop {
                let (b_full, scale) = rhs_with_contact(a, Some((&boundary, &sol)));
                refinement += refine(direct, a, &b_full, scale, &mut u, &mut phi)?.steps;
                sol.info.complementarity = law_residual(&boundary, &sol, &how.law, &u0, &u);
                if sol.info.complementarity <= how.tol || corrections == MAX_CORRECTIONS {
                    break;
                }
                let actual = fields_at_points(&boundary, &u, sol.lambda.n_tangential());
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
                sol = how.run(Operator::Condensed(&mut dense), &boundary.points, Some(start), reporter)?;
                let (b_full, _) = rhs_with_contact(a, Some((&boundary, &sol)));
                direct.solve(&b_full, &a.b_phi, &mut u, &mut phi)?;
                corrections += 1;
            }
            sol.info.residual = sol.info.residual.max(sol.info.complementarity);
            drop(dense);
            ((sol, (u, phi)), Some(condense))
        }
        other => {
            let mut op = FullSolve {
                boundary: &boundary,
                solver: other.coupled(),
                b_u: &a.b_u,
                b_phi: &a.b_phi,
                nt: plan.n_tangential(),
                u: vec![0.0; a.disc.dofs.n_u],
                phi: vec![0.0; a.disc.dofs.n_phi],
            };
            let sol = how.run(Operator::FullSolves(&mut op), &boundary.points, None, reporter)?;
            ((sol, (op.u, op.phi)), None)
        }
    };
    Ok(Solved {
        u,
        phi,
        pcg_iters: sol.info.inner_iters,
        refinement,
        contact: Some((boundary, sol)),
        condense,
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// The equilibrium residual of the final pair, with the contact forces in the right-hand side,
/// relative to the larger of the loads and the contact forces (they may cancel in the sum: a
/// load pressing the contact face straight into the foundation).
fn equilibrium(a: &Assembled<'_>, s: &Solved) -> f64 {
    let (b_full, scale) = rhs_with_contact(a, s.contact.as_ref().map(|(b, sol)| (b, sol)));
    let b = &a.blocks;
    equilibrium_residual(&b.a, &b.g, &b.b, &s.u, &s.phi, &b_full, &a.b_phi, scale)
}

/// The mechanical right-hand side with the contact forces of `contact`, and the size of its
/// parts (the loads, the contact forces: they may cancel in the sum).
fn rhs_with_contact(a: &Assembled<'_>, contact: Option<(&ContactBoundary, &ContactSolution)>) -> (Vec<f64>, f64) {
    let mut b_full = a.b_u.clone();
    let mut scale = linalg::norm(&a.b_u).hypot(linalg::norm(&a.b_phi));
    if let Some((cb, sol)) = contact {
        let forces = cb.forces(&sol.lambda);
        scale = scale.max(linalg::norm(&forces));
        for (&j, f) in cb.dofs.iter().zip(&forces) {
            b_full[j] += f;
        }
    }
    (b_full, scale)
}

/// The equilibrium residual a run must reach (relative, as [`equilibrium_residual`]): eight
/// digits of the loads balanced. The direct solves reach 1e-13 to 1e-15 on the shipped scenes;
/// a solve above it is refined, and a run still above it under the tight rule fails, naming
/// the inputs that make the system ill-conditioned.
pub const EQUILIBRIUM_TOL: f64 = 1e-8;

/// Iterative refinement of the last solve (with `K`'s factors), towards round-off: at most 3
/// corrections, each kept only where it lowers the residual.
fn refine(
    direct: &mut DirectLdlt,
    a: &Assembled<'_>,
    b_u: &[f64],
    scale: f64,
    u: &mut [f64],
    phi: &mut [f64],
) -> Result<linalg::Refined, ProblemError> {
    let b = &a.blocks;
    let k = linalg::CoupledBlocks {
        a: &b.a,
        g: &b.g,
        b: &b.b,
    };
    Ok(linalg::refine(direct, k, b_u, &a.b_phi, u, phi, scale, 1e-14, 3)?)
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

/// The complementarity residual of the law on the final fields: the multipliers of `sol` with
/// the displacement of the points in `u` (the last, refined solve), against the loads' `u0`.
fn law_residual(boundary: &ContactBoundary, sol: &ContactSolution, law: &Law, u0: &PointValues, u: &[f64]) -> f64 {
    let points = &boundary.points;
    let at = fields_at_points(boundary, u, sol.lambda.n_tangential());
    let c = 1.0 / sol.info.mu_max;
    let mut free = u0.clone();
    for (v, g) in free.normal.iter_mut().zip(&points.gap) {
        *v -= g;
    }
    let reference = c * free.weighted_norm(&points.weight);
    let radius = contact::slip_bound(points, law, &sol.lambda.normal);
    contact::complementarity_residual(points, &radius, &sol.lambda, &at, c, reference)
}

/// The nodal solution, the per-cell fields, the contact counts and forces, and the error
/// against the exact solution: what a run reports, whichever backend solved it.
pub struct Recovered {
    /// Nodal displacements.
    pub u: Vec<[f64; 3]>,
    /// Nodal potentials.
    pub phi: Vec<f64>,
    /// Per-cell stress, strain, electric displacement and field.
    pub fields: CellFields,
    /// The contact boundary's counts and resultant forces (zeros without contact).
    pub contact: ContactReport,
    /// The error against the scene's exact solution, where it has one.
    pub exact: Option<crate::exact::ExactReport>,
}

/// Expands the free unknowns `(u, φ)` to the nodes, recovers stress and electric
/// displacement per cell, counts the contact solution (on its boundary), measures the error
/// against the scene's exact solution, and checks that every reported number (with the
/// run's `equilibrium` residual) is finite.
///
/// # Errors
/// [`ProblemError::NotFinite`], naming the extreme inputs, where the data overflow.
pub fn recover(
    scene: &Scene,
    setup: &Setup,
    disc: &Discretization<'_>,
    (u_free, phi_free): (&[f64], &[f64]),
    contact: Option<(&ContactBoundary, &ContactSolution)>,
    equilibrium: f64,
    reporter: &mut dyn Reporter,
) -> Result<Recovered, ProblemError> {
    let u = disc.dofs.expand_u(u_free);
    let phi = disc.dofs.expand_phi(phi_free);
    let fields = disc.recover(&u, &phi);
    let counts = contact.map_or_else(ContactReport::default, |(b, sol)| ContactReport {
        held_nodes: b.held_nodes,
        held_inside: b.held_inside,
        ..ContactReport::of(&b.points, sol)
    });
    let exact = match (&setup.exact, contact) {
        (Some(ex), _) => Some(ex.errors(disc, &u, &phi, setup.plan.electric)),
        (None, Some((b, sol))) => contact_errors(scene, &b.points, sol, counts.normal_force, counts.tangential_force),
        (None, None) => None,
    };
    if let Some(e) = &exact {
        reporter.event(&Event::Exact {
            kind: e.kind(),
            what: e.error_name(),
            error: e.error(),
        });
    }
    let reported = [
        equilibrium,
        counts.normal_force,
        counts.tangential_force,
        exact.as_ref().map_or(0.0, |e| e.error()),
    ];
    ProblemError::check_finite(&reported, "a reported number (residual, force or error)", scene)?;
    ProblemError::check_finite(&fields.stress, "the stress", scene)?;
    Ok(Recovered {
        u,
        phi,
        fields,
        contact: counts,
        exact,
    })
}

/// The typed report of the run.
#[allow(clippy::too_many_arguments)]
fn report(
    scene: &Scene,
    setup: &Setup,
    a: &Assembled<'_>,
    f: &Factored,
    s: &Solved,
    r: &Recovered,
    equilibrium: f64,
    timings_s: Timings,
) -> RunReport {
    let plan = &setup.plan;
    let info = s.contact.as_ref().map(|(_, sol)| &sol.info);
    let direct = match &f.solver {
        LinearSolver::Direct(d) => Some(d),
        LinearSolver::SchurPcg(_) => None,
    };
    let factor_bytes = match &f.solver {
        LinearSolver::Direct(d) => d.factor_bytes(),
        LinearSolver::SchurPcg(p) => p.factor_bytes(),
    };
    RunReport {
        scene: SceneReport::of(scene),
        plan: plan.clone(),
        mesh: MeshReport::of(scene, setup),
        dofs: DofsReport {
            u: a.disc.dofs.n_u,
            phi: a.disc.dofs.n_phi,
        },
        contact: r.contact.clone(),
        exact: r.exact.clone(),
        iterations: Iterations::of(info, s.pcg_iters),
        residuals: Residuals {
            equilibrium,
            complementarity: info.map_or(0.0, |i| i.complementarity),
            // under the tight rule a run reaches here only with every residual within its
            // tolerance (check_accurate)
            converged_to_tolerance: plan.rule == Rule::Tight
                && equilibrium <= EQUILIBRIUM_TOL
                && info.is_none_or(|i| i.complementarity <= scene.solver.tol),
        },
        timings_s,
        memory: Memory {
            peak_bytes: 0,
            factor_bytes,
        },
        solver: SolverReport {
            strategy: plan.linear_strategy,
            rule: rule_in_words(plan.rule).into(),
            tol: scene.solver.tol,
            pcg_rel_tol: f.pcg_params.rel_tol,
            condense_route: s.condense.map(|(route, _)| format!("{route:?}")),
            smallest_pivot_ratio: direct.map(|d| d.factor().pivot_ratio()),
            refinement_steps: s.refinement,
            ..SolverReport::of(info)
        },
        petsc: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{ContactSpec, DirichletSpec, LoadSpec, MaterialSpec, MeshSpec};
    use crate::Silent;
    use std::sync::atomic::AtomicBool;

    /// The paper's block at `n` cells along its height, with `mesh` as its mesh spec.
    fn block(mesh: MeshSpec) -> Scene {
        let clamped = |group: &str| DirichletSpec {
            group: group.into(),
            u: Some(vec![0.0, 0.0]),
            phi: Some(0.0),
            ..Default::default()
        };
        let mut contact = ContactSpec::new("bottom", ContactLaw::Coulomb, &[0.0, -1.0]);
        contact.friction = Some(0.6);
        Scene {
            name: "block".into(),
            description: String::new(),
            mesh,
            material: vec![MaterialSpec::crystal_6mm(
                "body",
                [121.0, 75.4, 75.2, 111.0, 21.1, 22.6],
                [-5.4, 15.8, 12.3],
                [8.11, 7.35],
                [0.0, 1.0, 0.0],
            )],
            dirichlet: vec![clamped("left"), clamped("right")],
            load: Some(LoadSpec {
                group: "top".into(),
                p: -2.0,
                direction: vec![0.0, 1.0],
            }),
            electrode: None,
            contact: Some(contact),
            solver: Default::default(),
            exact: None,
        }
    }

    #[test]
    fn a_given_mesh_gives_the_answer_of_the_same_generated_mesh() {
        let generated = solve(
            &block(MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 4)),
            None,
            &mut Silent,
        )
        .unwrap();
        let mesh = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4);
        let given = solve(&block(MeshSpec::given()), Some(mesh), &mut Silent).unwrap();
        assert_eq!(generated.u, given.u);
        assert_eq!(generated.phi, given.phi);
        // a given mesh that was not given is named, not taken for an empty one
        let e = solve(&block(MeshSpec::given()), None, &mut Silent)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("mesh.kind") && e.contains("none was given"), "{e}");
    }

    #[test]
    fn a_scene_for_another_backend_is_refused_not_solved_here() {
        let mut scene = block(MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 4));
        scene.solver.backend = Backend::Petsc;
        let e = solve(&scene, None, &mut Silent).err().unwrap().to_string();
        assert!(
            e.contains("solver.backend = \"petsc\" is solved by the distributed backend"),
            "{e}"
        );
    }

    #[test]
    fn a_cancelled_run_stops_between_steps_with_a_typed_error() {
        static CANCEL: AtomicBool = AtomicBool::new(true);
        let limits = Limits {
            interrupt: contact::Interrupt {
                deadline: None,
                cancel: Some(&CANCEL),
            },
            ..Default::default()
        };
        let scene = block(MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 4));
        let e = solve_within(&scene, None, limits, &mut Silent).err().unwrap();
        assert!(e.is_interrupted());
        assert!(
            matches!(
                e,
                ProblemError::Interrupted {
                    after: "set-up",
                    why: contact::Interruption::Cancelled
                }
            ),
            "{e}"
        );
    }
}
