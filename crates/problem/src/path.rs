//! The run's quasi-static loop (deal.II step-18's shape: set up, then each instant in turn):
//! a scene with a load path (`[path]`) solves its instants in order, its loads, prescribed
//! displacements, potentials and gap scaled by their factors at each, friction on the slip
//! since the instant before (backward Euler of the quasi-static law: friction remembers); a
//! static scene is a path of one instant. One preparation of the system (one factorisation,
//! one condensation onto the contact dofs) serves every instant: the matrix does not change
//! along the path. The run knows no backend: each instant is posed
//! ([`Backend::prime`]), its contact problem solved ([`Backend::solve_posed`], around it the
//! outer unknowns: force control's depth, a compliant bed's springs), and, at the instants
//! that need them, its fields computed ([`Backend::instant_fields`]).
//!
//! A path's right-hand side at an instant is the sum of the parts of
//! [`Discretization::rhs_parts`] scaled by the instant's factors, and so is the loads'
//! displacement at the points: the backend solves the parts once. An instant whose fields are
//! not written has its row (forces, slips, counts, the charges through the terminals) from
//! the multipliers alone, the charges by their functionals
//! ([`Discretization::charge_functionals`]: `Σ_q f_q Q_q - Σ_i w_i λ_i · z_i`, `Q_q` the
//! charge of part `q`'s solution and `z` the response `K⁻¹ a` of the functional `a` at the
//! points, both computed once). The fields (a solve with `K`'s factors, refined, and the
//! recovery) are computed only at the instants whose files are written, and at the last.

use crate::backend::{
    At, Backend, Bed, Contact, ContactSolve, Figures, Framed, InstantOf, InstantSolution, Limits, Loads, Posed, Primed,
};
use crate::boundary::ContactBoundary;
use crate::progress::{Event, Reporter};
use crate::reach::{Beyond, Reach};
use crate::report::{Iterations, PathReport, RunReport, StepRow, Timings};
use crate::run::{
    begin, check_accurate, check_solved, closed_form, contact_boundary, contact_result, indenter_report, pose, recover,
    report, stop_if_interrupted, terminal_groups, ContactResult, Measured, Recovered,
};
use crate::scene::{Factors, PathSpec, Scene};
use crate::setup::Setup;
use crate::ProblemError;
use crate::Solution;
use contact::{ContactSolution, PointValues};
use fe_assembly::{CellFields, Discretization, RhsParts};
use std::cell::Cell;
use std::time::Instant;

/// One instant of a path, as its step hands it to the caller: the step's row, its contact
/// solution, and, at the instants whose fields are computed, its fields.
pub struct Step<'a> {
    /// The step's row (`path.csv`).
    pub row: &'a StepRow,
    /// The mesh.
    pub mesh: &'a mesh::Mesh,
    /// The contact solution of the step (its displacements the total ones).
    pub contact: &'a ContactResult,
    /// The fields, at the instants that have them ([`crate::solve_path`]).
    pub fields: Option<StepFields<'a>>,
}

/// What a path hands each instant to ([`run_steps`], [`crate::solve_path`]).
type Each<'a> = dyn FnMut(Step<'_>) -> Result<(), ProblemError> + 'a;

/// The fields of an instant of a path.
pub struct StepFields<'a> {
    /// Nodal displacements.
    pub u: &'a [[f64; 3]],
    /// Nodal potentials.
    pub phi: &'a [f64],
    /// Per-cell fields: the last instant's, and every written instant's where the path asks
    /// for them (`path.cell_fields`).
    pub fields: Option<&'a CellFields>,
}

/// A written instant's nodal fields, and its cells' where the path asks for them.
struct FrameFields {
    u: Vec<[f64; 3]>,
    phi: Vec<f64>,
    cells: Option<CellFields>,
}

/// What a path produced: the last instant's solution (its report with the path's section)
/// and every step's row.
pub struct PathSolution {
    /// The solution at the last instant; `report.path` holds the rows.
    pub last: Solution,
}

/// Solves `scene` on `backend`, within `limits`: validate, refuse what the backend does not
/// take, set up (the memory estimate checked first), discretise, assemble, build the contact
/// boundary, prepare (factor), then each instant of its path (a static scene is a path of one
/// instant) posed and solved, checked, recovered; the report built once.
/// `mesh` is the mesh of a `gmsh` scene, read by the caller. A backend on several processes
/// returns the solution on the one that gathers it, `None` on the others.
///
/// # Errors
/// The problem's errors ([`ProblemError`], naming the scene key, mesh item, material or
/// solver step at fault, and a path's step) and the backend's own.
pub fn run<B: Backend>(
    backend: &mut B,
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, B::Error> {
    walk(backend, scene, mesh, limits, reporter, false, &mut |_| Ok(()))
}

/// [`run`], each instant (one for a static scene) handed to `each` with its fields where they
/// were computed: for a backend outside this crate whose run writes a path's files as it goes
/// (as [`crate::solve_path`] does for the default one).
///
/// # Errors
/// As [`run`]; the error `each` returns.
pub fn run_steps<B: Backend>(
    backend: &mut B,
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<Option<Solution>, B::Error> {
    walk(backend, scene, mesh, limits, reporter, true, each)
}

/// The run of `scene` on `backend` ([`run`], [`crate::solve_path`]): validate, refuse
/// what the backend does not take, set up (the memory estimate checked first), discretise,
/// assemble, build the contact boundary, prepare (factor), then each instant (one for a
/// static scene) posed, solved, checked and, where asked, recovered; each instant with contact
/// handed to `each`; the report built once. A backend on several processes returns the
/// solution on the one that gathers it, `None` on the others.
///
/// # Errors
/// As [`crate::run`], naming the path's step where one happened; the error `each` returns.
pub(crate) fn walk<B: Backend>(
    backend: &mut B,
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
    with_fields: bool,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<Option<Solution>, B::Error> {
    let valid = scene.validate().map_err(ProblemError::from)?;
    backend.supports(&valid).map_err(ProblemError::from)?;
    let t_total = Instant::now();
    let setup = begin(backend, valid, mesh, &limits, reporter)?;
    let t_setup = t_total.elapsed().as_secs_f64();
    stop_if_interrupted(&limits, "set-up")?;
    let mut points = Points::ThatCanTouch;
    let walked = loop {
        let on = SetUp {
            valid,
            setup: &setup,
            limits,
            with_fields,
            times: (t_total, t_setup),
            points,
        };
        match walk_set_up(backend, on, reporter, each)? {
            Walked::Done(done) => break done,
            Walked::Beyond { points: beyond, of } => {
                reporter.event(&Event::BeyondReach { points: beyond, of });
                points = Points::All;
            }
        }
    };
    let Some(done) = walked else {
        // a process that does not hold the gathered fields
        return Ok(None);
    };
    let (report, result, recovered) = *done;
    Ok(Some(Solution {
        report,
        contact: result,
        mesh: setup.mesh,
        u: recovered.u,
        phi: recovered.phi,
        fields: recovered.fields,
    }))
}

/// Which contact points a run's contact problem holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Points {
    /// Those that can touch ([`Reach`]), where the backend, the run and its zones allow.
    ThatCanTouch,
    /// Every point of the contact groups: the second walk, after the first left out points
    /// that touch (its notes said once).
    All,
}

/// A run set up: its scene, set-up and limits, and how it is walked.
struct SetUp<'a> {
    valid: crate::Valid<'a>,
    setup: &'a Setup,
    limits: Limits,
    with_fields: bool,
    /// The run's start, and the seconds of its set-up.
    times: (Instant, f64),
    points: Points,
}

/// A walk of a set-up run: its report, contact result and fields (`None` on a process that
/// does not hold them); or points its contact problem left out that would touch.
enum Walked {
    Done(Option<Box<(RunReport, Option<ContactResult>, Recovered)>>),
    Beyond { points: usize, of: usize },
}

/// [`walk`] from the set-up on: discretise, assemble, build the contact boundary (narrowed to
/// the points that can touch where `on.points` asks and [`Reach`] finds them), prepare, then
/// each instant.
fn walk_set_up<B: Backend>(
    backend: &mut B,
    on: SetUp<'_>,
    reporter: &mut dyn Reporter,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<Walked, B::Error> {
    let SetUp {
        valid,
        setup,
        limits,
        with_fields,
        times: (t_total, t_setup),
        points,
    } = on;
    let scene: &Scene = valid.scene();
    let t = Instant::now();
    let mut disc = setup.discretize().map_err(ProblemError::from)?;
    let instants = scene.path.as_ref().map_or_else(|| vec![1.0], PathSpec::instants);
    let parts = match scene.path {
        Some(_) => Some(disc.rhs_parts(&setup.loads).map_err(ProblemError::from)?),
        None => None,
    };
    let mut walk = Walk {
        scene,
        valid,
        setup,
        spec: scene.path.as_ref(),
        parts: parts.as_ref(),
        prescribed: disc.dofs.prescribed(),
        base_dofs: disc.dofs.clone(),
        with_fields,
        every_fields: false,
        defer: false,
        terminals: Terminals::default(),
        first: Loads::default(),
        bed: None,
        held_to_tolerance: B::HELD_TO_TOLERANCE,
        of: instants.len() - 1,
        reach: None,
        beyond: Cell::new(None),
    };
    let mut posed = walk.first_posed(&disc, instants[0])?;
    let boundary = walk.boundary(&mut posed, &instants, points, reporter)?;
    let assembled = backend.assemble(&posed)?;
    let t_assembly = t.elapsed().as_secs_f64();
    reporter.event(&Event::assembled(setup, &disc.dofs, t_assembly));
    walk.plan_path(instants.len(), &disc, boundary.as_ref(), reporter);
    stop_if_interrupted(&limits, "assembly")?;
    let mut system = backend.prepare(&posed, assembled, boundary.as_ref(), limits, reporter)?;
    stop_if_interrupted(&limits, "factorisation")?;
    walk.defer = with_fields
        && walk.spec.is_some()
        && boundary.is_some()
        && !walk.every_fields
        && backend.defers_fields(&system);
    let how = boundary
        .as_ref()
        .map(|b| ContactSolve::new(&setup.plan, scene, b, limits.interrupt));
    let contact = boundary
        .as_ref()
        .zip(how.as_ref())
        .map(|(boundary, how)| Contact { boundary, how });
    let ordered = walk.ordered_parts();
    let solved = backend.begin(&mut system, &posed, contact, &ordered, reporter)?;
    let Posed { loads, bed, .. } = posed;
    (walk.first, walk.bed) = (loads, bed);
    if let (Some(b), false) = (&boundary, solved.is_empty()) {
        walk.terminals = Terminals::new(&walk, &disc, (&mut *backend, &mut system), b, &solved)?;
    }
    drop(solved);
    let t_steps = Instant::now();
    let n = boundary.as_ref().map_or(0, |b| b.points.len());
    let mut state = History::new(n, setup.plan.n_tangential(), instants.len());
    let prepared = Prepared {
        backend: &mut *backend,
        system,
        boundary: boundary.as_ref(),
        how: how.as_ref(),
    };
    let figures = walk.all_steps(prepared, &mut disc, &instants, &mut state, reporter, each)?;
    let steps_s = t_steps.elapsed().as_secs_f64();
    if let Some(beyond) = walk.agreed_beyond(backend)? {
        return Ok(beyond);
    }
    let Some(mut last) = state.last.take() else {
        // a process that does not hold the gathered fields
        return Ok(Walked::Done(None));
    };
    let Some((recovered, equilibrium, loads)) = last.fields.take() else {
        return Ok(Walked::Done(None));
    };
    let timings = (t_setup, t_assembly, steps_s, t_total);
    let last = (last, recovered, equilibrium, loads);
    Ok(Walked::Done(Some(Box::new(
        walk.finish(&disc, figures, state, last, timings),
    ))))
}

/// The backend with its prepared system, the contact boundary and its solve: what the
/// instants run on.
struct Prepared<'a, B: Backend> {
    backend: &'a mut B,
    system: B::System,
    boundary: Option<&'a ContactBoundary>,
    how: Option<&'a ContactSolve<'a>>,
}

/// What an instant's steps work on: the backend and its prepared system, the boundary at the
/// scene's own factors, the contact solve, friction's history.
struct On<'a, B: Backend> {
    backend: &'a mut B,
    base: Option<&'a ContactBoundary>,
    system: &'a mut B::System,
    how: Option<&'a ContactSolve<'a>>,
    state: &'a mut History,
}

/// What stays the same along the run: the scene, its set-up, the parts of a path's
/// right-hand side.
struct Walk<'a> {
    scene: &'a Scene,
    valid: crate::Valid<'a>,
    setup: &'a Setup,
    /// The path (`None`: a static scene, one instant at the scene's own data).
    spec: Option<&'a PathSpec>,
    /// A path's parts of the right-hand side.
    parts: Option<&'a RhsParts>,
    /// The dof map with the scene's prescribed values (scaled at each step).
    base_dofs: fe_assembly::DofMap,
    /// Its prescribed values, which each instant scales.
    prescribed: fe_assembly::Prescribed,
    /// Whether the fields of the output instants are computed ([`PathSpec::has_fields`]; the
    /// last instant's always are).
    with_fields: bool,
    /// Whether every instant's fields are computed: with electrical contact, whose flux the
    /// charges' functionals do not carry, the charges are the fields'.
    every_fields: bool,
    /// Whether the written instants before the last have their fields computed later, several
    /// together ([`Frames`]): their contact results and friction's history then come from the
    /// contact solve, as every other instant's (the path does not depend on which instants it
    /// writes), and their rows take what the fields measure when they come.
    defer: bool,
    /// The charges' functionals.
    terminals: Terminals,
    /// The loads of a static scene's instant.
    first: Loads,
    /// The springs that hold a body only its compliant bed holds.
    bed: Option<Bed>,
    /// Whether the backend is held to the tight rule's tolerances.
    held_to_tolerance: bool,
    /// The last instant's index.
    of: usize,
    /// Where the contact problem holds only the points that can touch: the whole boundary,
    /// which each instant's solution is widened to.
    reach: Option<Reach>,
    /// Points left out of the contact problem that the fields found touching: the walk is
    /// done again with every point.
    beyond: Cell<Option<Beyond>>,
}

/// An instant's collective steps done ([`Walk::solve_step`]): its factors and boundary, the
/// contact solve (where its fields were not computed), the fields where asked (`Some(None)`
/// on a process that does not hold them), its loads, the bed's springs, its seconds.
struct Stepped {
    k: usize,
    t: f64,
    f: Factors,
    /// A path's factors of the parts, in their order.
    factors: Option<Vec<f64>>,
    boundary: Option<ContactBoundary>,
    sol: Option<ContactSolution>,
    fields: Option<Option<InstantSolution>>,
    loads: Loads,
    springs: Springs,
    seconds: f64,
}

/// The charges through the terminals and their potentials at any step from its factors and
/// multipliers, each a linear functional of the solution: `Σ_q f_q Q_q - Σ_i w_i λ_i · z_i`.
#[derive(Default)]
struct Terminals {
    /// Per terminal, the charge through it.
    charges: Vec<Functional>,
    /// Per terminal, its potential (a prescribed one's is its parts' alone; a floating one's
    /// responds to the multipliers).
    potentials: Vec<Functional>,
}

/// A linear functional `a` of the solution along a path: its value on each part's solution
/// `Q_q` (the part's prescribed values lifted), and `z = K⁻¹ a` at the points where it responds
/// to the multipliers.
struct Functional {
    of_parts: Vec<f64>,
    at_points: Option<PointValues>,
}

impl Functional {
    /// The value at a step of `factors` (in the order of the parts) and multipliers.
    fn at(&self, factors: &[f64], lambda: &PointValues, weight: &[f64]) -> f64 {
        let loads: f64 = self.of_parts.iter().zip(factors).map(|(q, f)| q * f).sum();
        let Some(z) = &self.at_points else { return loads };
        let nt = lambda.n_tangential();
        let contact: f64 = (0..weight.len())
            .map(|i| {
                let t: f64 = (0..nt.min(z.n_tangential()))
                    .map(|k| lambda.tangential_of(i)[k] * z.tangential_of(i)[k])
                    .sum();
                weight[i] * (lambda.normal[i] * z.normal[i] + t)
            })
            .sum();
        loads - contact
    }
}

impl Terminals {
    /// The functionals of the setup's terminals: each part's charge and potential, from its
    /// solution's fields, and the response of each functional at the points (one solve each).
    fn new<B: Backend>(
        walk: &Walk<'_>,
        disc: &Discretization<'_>,
        (backend, system): (&mut B, &mut B::System),
        boundary: &ContactBoundary,
        solved: &[(Vec<f64>, Vec<f64>)],
    ) -> Result<Terminals, B::Error> {
        let setup = walk.setup;
        let groups = terminal_groups(setup);
        if groups.is_empty() {
            return Ok(Terminals::default());
        }
        let dim = setup.mesh.dim;
        let first_node = |g: &str| -> Result<Option<usize>, ProblemError> {
            let group = setup.mesh.boundary(g).map_err(fe_assembly::AssemblyError::from)?;
            Ok(group.nodes().first().copied())
        };
        let firsts: Vec<Option<usize>> = groups.iter().map(|g| first_node(g)).collect::<Result<_, _>>()?;
        let mut charges = vec![vec![]; groups.len()];
        let mut potentials = vec![vec![]; groups.len()];
        for (q, (u, phi)) in solved.iter().enumerate() {
            // the part's own prescribed values: part q's factor 1, every other 0
            let unit = |k: usize| if q == k + 1 { 1.0 } else { 0.0 };
            let dofs = walk
                .base_dofs
                .scaled([unit(0), unit(1), unit(2)], if q == dim + 1 { 1.0 } else { 0.0 });
            let (u, phi) = (dofs.expand_u(u), dofs.expand_phi(phi));
            let loads: &[fe_assembly::Load] = if q == 0 { &setup.loads } else { &[] };
            for (g, charge) in disc
                .charges(&u, &phi, &groups, loads)
                .map_err(ProblemError::from)?
                .into_iter()
                .enumerate()
            {
                charges[g].push(charge);
                potentials[g].push(firsts[g].map_or(0.0, |v| phi[v]));
            }
        }
        // the functionals whose responses the points need: every charge's, and a floating
        // terminal's potential (a free unknown: e_j's), solved together
        let dofs = &disc.dofs;
        let mut functionals = disc.charge_functionals(&groups).map_err(ProblemError::from)?;
        let n_charges = functionals.len();
        let floating: Vec<bool> = firsts
            .iter()
            .map(|first| match first.map(|v| dofs.phi[v]) {
                Some(fe_assembly::Dof::Free(j)) => {
                    let mut a_phi = vec![0.0; dofs.n_phi];
                    a_phi[j] = 1.0;
                    functionals.push((vec![0.0; dofs.n_u], a_phi));
                    true
                }
                _ => false,
            })
            .collect();
        let a: Vec<(&[f64], &[f64])> = functionals.iter().map(|(a_u, a_phi)| (&a_u[..], &a_phi[..])).collect();
        let points = &boundary.points;
        let mut responses = backend.respond(system, &a)?.into_iter().map(|(z, _)| {
            let mut out = PointValues::zeros(points.len(), points.n_tangential());
            boundary.extract_free(&z, &mut out);
            out
        });
        let mut out = Terminals::default();
        for of_parts in charges.into_iter().take(n_charges) {
            out.charges.push(Functional {
                of_parts,
                at_points: responses.next(),
            });
        }
        for (floats, of_parts) in floating.into_iter().zip(potentials) {
            let at_points = if floats { responses.next() } else { None };
            out.potentials.push(Functional { of_parts, at_points });
        }
        Ok(out)
    }

    /// The charges and the potentials at a step of `factors` (in the order of the parts) and
    /// multipliers.
    fn at(&self, factors: &[f64], lambda: &PointValues, weight: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let values = |of: &[Functional]| of.iter().map(|f| f.at(factors, lambda, weight)).collect();
        (values(&self.charges), values(&self.potentials))
    }
}

/// What a path carries from step to step: the tangential displacement of the points at the
/// step before (friction's frame), the multipliers (the warm start), the rows so far, and the
/// last instant.
struct History {
    /// The contact solves' iterations, summed over the steps.
    iterations: crate::report::Iterations,
    shift: PointValues,
    /// The slip each point accumulated in contact (slip-weakening friction's argument).
    slipped: Vec<f64>,
    start: Option<PointValues>,
    rows: Vec<StepRow>,
    last: Option<Done>,
}

impl History {
    fn new(n: usize, nt: usize, instants: usize) -> Self {
        History {
            iterations: Default::default(),
            shift: PointValues::zeros(n, nt),
            slipped: vec![0.0; n],
            start: None,
            rows: Vec::with_capacity(instants),
            last: None,
        }
    }

    /// The step is done: its tangential displacement `now` the next step's frame, the slip of
    /// its points in contact added to what they slipped, its multipliers the next start.
    fn advance(&mut self, now: &PointValues, sol: &ContactSolution, iterations: &Iterations) {
        self.iterations.add(iterations);
        let nt = self.shift.n_tangential();
        if nt > 0 {
            for i in 0..self.slipped.len() {
                if sol.status[i] != contact::Status::Separated {
                    let (a, b) = (now.tangential_of(i), self.shift.tangential_of(i));
                    self.slipped[i] += a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
                }
            }
            self.shift.tangential.clone_from(&now.tangential);
        }
        self.start = Some(sol.lambda.clone());
    }
}

/// The springs' multipliers of an instant of a body only its compliant bed holds (zeros
/// otherwise), the bed's fixed-point steps, and its last change (relative to the forces).
struct Springs {
    lambda: PointValues,
    steps: usize,
    change: f64,
}

impl Springs {
    /// No springs, at `n` points of `nt` tangential components.
    fn none(n: usize, nt: usize) -> Springs {
        Springs {
            lambda: PointValues::zeros(n, nt),
            steps: 0,
            change: 0.0,
        }
    }

    /// The multipliers that act on the springs' `K`: the contact's `lambda` and the springs'.
    fn applied(&self, lambda: &PointValues) -> PointValues {
        let mut out = lambda.clone();
        for (a, s) in out.normal.iter_mut().zip(&self.lambda.normal) {
            *a += s;
        }
        out
    }
}

/// An instant's data for its contact solves: the discrete problem with its loads (and a
/// path's factors of the parts), and its load factor (force control's force scales with it).
#[derive(Clone, Copy)]
struct InstantData<'a> {
    posed: &'a Posed<'a>,
    load: f64,
}

/// An instant checked ([`Walk::checked`]): its contact solution, where computed its fields
/// recovered with their equilibrium residual and free displacements, its PCG iterations.
type Checked = (Option<ContactSolution>, Option<(Recovered, f64, Vec<f64>)>, usize);

/// A path's written instants whose fields wait to be computed together (before the last
/// instant, at most [`frames_at_once`] of them: one solve with as many right-hand sides reads
/// the factor once for all, where one each reads it once each), and every step completed since
/// the first of them, in order, for `each`.
#[derive(Default)]
struct Frames {
    waiting: Vec<Frame>,
    queue: Vec<Queued>,
}

/// A written instant's data for its fields: its step, factors and loads, its boundary and
/// contact solve (in its frame), the frame (the step before's tangential displacements), the
/// bed's last change, and its row's index.
struct Frame {
    k: usize,
    t: f64,
    f: Factors,
    loads: Loads,
    boundary: ContactBoundary,
    sol: ContactSolution,
    shift: PointValues,
    change: f64,
    row: usize,
}

/// A completed step waiting to be handed to `each`: its row's index and its contact result
/// (`None`: a written instant, whose result comes with its fields).
struct Queued {
    row: usize,
    result: Option<ContactResult>,
}

/// How many written instants' fields are computed together for a system of `n` unknowns:
/// up to 16, within about 128 MB of right-hand sides, solutions and loads (4 vectors each).
fn frames_at_once(n: usize) -> usize {
    const BYTES: usize = 128 << 20;
    (BYTES / (32 * n.max(1))).clamp(1, 16)
}

/// One instant completed: its contact result (with contact), its fields (the last
/// instant's, and where asked), its own iterations and PCG count, its seconds.
struct Done {
    result: Option<ContactResult>,
    fields: Option<(Recovered, f64, Loads)>,
    iterations: Iterations,
    pcg_iters: usize,
    seconds: f64,
}

impl Walk<'_> {
    /// Every instant in order: its collective steps, then (at the last, after the backend
    /// finished and freed its system) its completion; the last instant kept in `state`. Returns
    /// the backend's figures.
    fn all_steps<B: Backend>(
        &self,
        Prepared {
            backend,
            system,
            boundary,
            how,
        }: Prepared<'_, B>,
        disc: &mut Discretization<'_>,
        instants: &[f64],
        state: &mut History,
        reporter: &mut dyn Reporter,
        each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
    ) -> Result<Figures, B::Error> {
        let of = instants.len() - 1;
        let mut system = Some(system);
        let mut figures = Figures::default();
        let mut frames = Frames::default();
        let batch = frames_at_once(disc.dofs.n_u + disc.dofs.n_phi);
        for (k, &t) in instants.iter().enumerate() {
            let at = |e: B::Error| if self.spec.is_some() { B::at_step(e, k, t) } else { e };
            let Some(prepared) = system.as_mut() else { break };
            if k == of {
                // the written instants before the last (their recovery scales the dof map to
                // their own factors: before the last instant's is set)
                let on = (&mut *backend, &mut *prepared, how);
                self.flush_frames(&mut frames, on, disc, state, (reporter, &mut *each))?;
            }
            if self.spec.is_some() {
                reporter.event(&Event::PathStep { step: k, of, t });
            }
            let mut on = On {
                backend: &mut *backend,
                base: boundary,
                system: prepared,
                how,
                state: &mut *state,
            };
            let written = self.with_fields && self.spec.is_some_and(|s| s.has_fields(k, of + 1));
            let deferred = written && k != of && self.defer;
            let fields = k == of || (written && !deferred) || self.every_fields;
            let stepped = self.solve_step(&mut on, disc, k, t, fields, reporter).map_err(at)?;
            if k == of {
                // the system's memory freed before the last instant's recovery
                if let Some(prepared) = system.take() {
                    figures = backend.finish(prepared)?;
                }
            }
            let done = self.complete_step(state, disc, stepped, (reporter, &mut *each), (&mut frames, deferred));
            let done = done.map_err(|e| at(e.into()))?;
            if k == of {
                state.last = done;
            } else if frames.waiting.len() >= batch {
                if let Some(prepared) = system.as_mut() {
                    let on = (&mut *backend, prepared, how);
                    self.flush_frames(&mut frames, on, disc, state, (reporter, &mut *each))?;
                }
            }
        }
        Ok(figures)
    }

    /// The fields of the written instants that wait for them ([`Frames`]), computed together,
    /// checked and recovered, each handed to `each` with the steps queued after it, in order;
    /// the written instants' rows given their equilibrium residual.
    ///
    /// # Errors
    /// The backend's; a written instant's fields that fail the checks (named by its step).
    fn flush_frames<B: Backend>(
        &self,
        frames: &mut Frames,
        (backend, system, how): (&mut B, &mut B::System, Option<&ContactSolve<'_>>),
        disc: &mut Discretization<'_>,
        state: &mut History,
        (reporter, each): (&mut dyn Reporter, &mut Each<'_>),
    ) -> Result<(), B::Error> {
        let mut waiting = std::mem::take(&mut frames.waiting);
        let queue = std::mem::take(&mut frames.queue);
        let mut fields = vec![];
        if let (Some(how), false) = (how, waiting.is_empty()) {
            let loads: Vec<Loads> = waiting.iter_mut().map(|w| std::mem::take(&mut w.loads)).collect();
            let posed: Vec<_> = loads
                .into_iter()
                .zip(&waiting)
                .map(|(loads, w)| {
                    let posed = self.posed(disc, loads);
                    let framed = Framed {
                        boundary: &w.boundary,
                        shift: &w.shift,
                    };
                    let sol = w.sol.clone();
                    (posed, InstantOf { how, framed, sol })
                })
                .collect();
            let solved = backend.frames_fields(system, posed, reporter)?;
            for (w, x) in waiting.into_iter().zip(solved) {
                let (k, t) = (w.k, w.t);
                let done = self.frame_fields(w, x, disc, state);
                fields.push(done.map_err(|e| B::at_step(e.into(), k, t))?);
            }
        }
        self.hand_queued(queue, state, fields, each).map_err(Into::into)
    }

    /// A written instant's fields `x` (`None` on a process that does not hold them) checked
    /// and recovered at its factors, its row given what they measure (their equilibrium
    /// residual, the charges through the terminals and their potentials, as the fields of an
    /// instant computed at once give them); its contact result in the body's frame with them.
    fn frame_fields(
        &self,
        w: Frame,
        x: Option<InstantSolution>,
        disc: &mut Discretization<'_>,
        state: &mut History,
    ) -> Result<Option<(ContactResult, FrameFields)>, ProblemError> {
        let Some(x) = x else { return Ok(None) };
        let equilibrium = x.equilibrium + w.change;
        let (u, phi) = &x.x;
        check_solved(self.scene, (u, phi), x.contact.as_ref(), equilibrium)?;
        self.check_accurate(x.contact.as_ref(), equilibrium)?;
        disc.dofs.rescale(&self.prescribed, w.f.displacement, w.f.voltage);
        let (nodal_u, nodal_phi) = (disc.dofs.expand_u(u), disc.dofs.expand_phi(phi));
        let cells = match self.spec.is_some_and(|p| p.cell_fields) {
            true => {
                let cells = disc.recover(&nodal_u, &nodal_phi);
                ProblemError::check_finite(&cells.stress, "the stress", self.scene)?;
                Some(cells)
            }
            false => None,
        };
        let terminals = crate::run::terminals(self.setup, disc, &nodal_u, &nodal_phi)?;
        let recovered = FrameFields {
            u: nodal_u,
            phi: nodal_phi,
            cells,
        };
        let mut sol = x.contact.unwrap_or(w.sol);
        if let Some(row) = state.rows.get_mut(w.row) {
            // what the fields measure: their equilibrium, the charges through the terminals
            row.equilibrium = Some(equilibrium);
            (row.charges, row.potentials) = terminals.iter().map(|x| (x.charge, x.potential)).unzip();
        }
        // the multipliers and displacements of the step in the body's frame
        for (v, s) in sol.u.tangential.iter_mut().zip(&w.shift.tangential) {
            *v += s;
        }
        Ok(Some((contact_result(w.boundary, sol, u), recovered)))
    }

    /// The queued steps handed to `each` in order: a written one with its `fields` (in their
    /// order; none on a process that does not hold them), the others with none.
    fn hand_queued(
        &self,
        queue: Vec<Queued>,
        state: &History,
        fields: Vec<Option<(ContactResult, FrameFields)>>,
        each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
    ) -> Result<(), ProblemError> {
        let mut fields = fields.into_iter();
        let mesh = &self.setup.mesh;
        for q in queue {
            let Some(row) = state.rows.get(q.row) else { continue };
            match q.result {
                Some(contact) => each(Step {
                    row,
                    mesh,
                    contact: &contact,
                    fields: None,
                })?,
                None => {
                    let Some(Some((contact, r))) = fields.next() else {
                        continue;
                    };
                    each(Step {
                        row,
                        mesh,
                        contact: &contact,
                        fields: Some(StepFields {
                            u: &r.u,
                            phi: &r.phi,
                            fields: r.cells.as_ref(),
                        }),
                    })?;
                }
            }
        }
        Ok(())
    }

    /// The factors at `t` (a static scene's: every factor 1, the scene as written).
    fn factors(&self, t: f64) -> Factors {
        self.spec.map_or(Factors::ONE, |s| s.factors(t))
    }

    /// The discrete problem at the first instant `t0`: the scene's own loads, or a path's parts
    /// summed at its first factors.
    fn first_posed<'a>(&self, disc: &'a Discretization<'a>, t0: f64) -> Result<Posed<'a>, ProblemError>
    where
        Self: 'a,
    {
        match self.parts {
            Some(parts) => Ok(self.posed(disc, step_loads(parts, &self.factors(t0), self.scene)?)),
            None => pose(self.valid, self.setup, disc),
        }
    }

    /// The run's scene and set-up posed on `disc` under `loads` (no bed's springs).
    fn posed<'a>(&self, disc: &'a Discretization<'a>, loads: Loads) -> Posed<'a>
    where
        Self: 'a,
    {
        Posed {
            scene: self.valid,
            setup: self.setup,
            disc,
            loads,
            bed: None,
        }
    }

    /// An instant's loads at the factors `f` (with a path's factors of the parts in their
    /// order), its prescribed values scaled in `disc`'s dof map (a static scene's: its own
    /// loads).
    fn data_at(&self, f: &Factors, disc: &mut Discretization<'_>) -> Result<Loads, ProblemError> {
        let Some(parts) = self.parts else {
            return Ok(self.first.clone());
        };
        disc.dofs.rescale(&self.prescribed, f.displacement, f.voltage);
        step_loads(parts, f, self.scene)
    }

    /// A path's parts of the right-hand side in the backend's order: the loads, each
    /// displacement component's lifting, the potentials' lifting (none for a static scene).
    fn ordered_parts(&self) -> Vec<(Vec<f64>, Vec<f64>)> {
        let Some(parts) = self.parts else { return vec![] };
        std::iter::once(parts.loads.clone())
            .chain(parts.displacements.iter().cloned())
            .chain(std::iter::once(parts.potentials.clone()))
            .collect()
    }

    /// The springs that hold a body only its compliant bed holds (`None` where the conditions
    /// hold it), sized by the loads of `posed` (a path's: its strongest instant's).
    fn bed(
        &self,
        posed: &Posed<'_>,
        instants: &[f64],
        boundary: Option<&ContactBoundary>,
    ) -> Result<Option<Bed>, ProblemError> {
        let Some(parts) = self.parts else {
            return Bed::needed(posed, boundary);
        };
        let mut strongest = step_loads(parts, &self.factors(instants[0]), self.scene)?;
        for &t in &instants[1..] {
            let loads = step_loads(parts, &self.factors(t), self.scene)?;
            if linalg::norm(&loads.b_u) > linalg::norm(&strongest.b_u) {
                strongest = loads;
            }
        }
        let posed = self.posed(posed.disc, strongest);
        Bed::needed(&posed, boundary)
    }

    /// The instant `t` (the run's `k`-th) on every process: its prescribed values, gap and
    /// loads scaled, the contact problem in the frame of the instant before; where
    /// `with_fields`, its fields.
    fn solve_step<B: Backend>(
        &self,
        on: &mut On<'_, B>,
        disc: &mut Discretization<'_>,
        k: usize,
        t: f64,
        with_fields: bool,
        reporter: &mut dyn Reporter,
    ) -> Result<Stepped, B::Error> {
        let started = Instant::now();
        let f = self.factors(t);
        let loads = self.data_at(&f, disc)?;
        // (kept apart from the loads, which a deferred written instant takes with it)
        let factors = loads.factors.clone();
        let mut boundary = on.base.map(|b| match self.parts {
            Some(_) => b.at_factors(f.gap, f.displacement, f.voltage),
            None => b.clone(),
        });
        if let (Some(b), Some(_)) = (boundary.as_mut(), self.parts) {
            if b.points.weakens() {
                b.points.slipped.clone_from(&on.state.slipped);
            }
        }
        let mut posed = self.posed(disc, loads);
        let (mut sol, springs) = match (boundary.as_mut(), on.how) {
            (Some(b), Some(how)) => {
                let data = InstantData {
                    posed: &posed,
                    load: f.load,
                };
                let (sol, springs) = self.contact_at(on, how, b, data, reporter)?;
                (Some(sol), springs)
            }
            _ => (None, Springs::none(0, 0)),
        };
        if let Some(contraction) = sol.as_ref().and_then(|s| s.info.contraction).filter(|c| *c >= 1.0) {
            reporter.event(&Event::NotContractive { contraction });
        }
        if let (Some(b), Some(factors)) = (&boundary, &factors) {
            // the instant's own displacement scale: its loads' and prescribed values', and how
            // far its gaps press in
            let pressed = b.points.gap.iter().fold(0.0f64, |m, g| m.max(-g));
            let own = on.backend.own_scale(on.system, factors).max(pressed);
            check_history(&on.state.shift, own, &self.setup.plan)?;
        }
        if let (Some(b), Some(_)) = (&boundary, self.bed) {
            // the springs' forces of a body only its bed holds are loads of the springs' K
            b.add_forces(&springs.lambda, &mut posed.loads.b_u);
        }
        let fields = match (with_fields, &boundary, on.how, sol.take()) {
            (false, _, _, kept) => {
                sol = kept;
                None
            }
            (true, Some(b), Some(how), Some(found)) => {
                let framed = Framed {
                    boundary: b,
                    shift: &on.state.shift,
                };
                let instant = InstantOf {
                    how,
                    framed,
                    sol: found,
                };
                Some(on.backend.instant_fields(on.system, &posed, Some(instant), reporter)?)
            }
            (true, ..) => Some(on.backend.instant_fields(on.system, &posed, None, reporter)?),
        };
        let seconds = started.elapsed().as_secs_f64();
        if let (None, Some(Some(x))) = (self.spec, &fields) {
            reporter.event(&Event::Solved {
                seconds,
                pcg_iters: x.pcg_iters,
                equilibrium: x.equilibrium + springs.change,
            });
        }
        Ok(Stepped {
            k,
            t,
            f,
            factors,
            boundary,
            sol,
            fields,
            loads: posed.loads,
            springs,
            seconds,
        })
    }

    /// The contact solve of an instant (force control: the depth found for the indenter's
    /// force times the `load` factor, from the step before's multipliers); where only a
    /// compliant bed holds the body, the bed's fixed point around it (the springs' forces a
    /// multiplier of their own among the instant's loads: `crate::bed`), with the springs'
    /// multipliers and steps.
    fn contact_at<B: Backend>(
        &self,
        on: &mut On<'_, B>,
        how: &ContactSolve<'_>,
        boundary: &mut ContactBoundary,
        data: InstantData<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<(ContactSolution, Springs), B::Error> {
        let (backend, system, state) = (&mut *on.backend, &mut *on.system, &mut *on.state);
        let control = crate::outer::ForceControl::of(self.scene, boundary);
        let base_gap = boundary.points.gap.clone();
        let mut springs = Springs::none(boundary.points.len(), self.setup.plan.n_tangential());
        let scale = linalg::norm(&data.posed.loads.b_u);
        let mut start = state.start.take();
        let mut last = f64::INFINITY;
        loop {
            let primed = Primed {
                posed: data.posed,
                framed: Framed {
                    boundary,
                    shift: &state.shift,
                },
                factors: data.posed.loads.factors.as_deref(),
                springs: &springs.lambda,
            };
            backend.prime(system, primed)?;
            boundary.points.gap.clone_from(&base_gap);
            let sol = match &control {
                Some(control) => {
                    let force = control.force * data.load;
                    crate::outer::force_controlled(&mut boundary.points, control, force, start, |points, warm| {
                        let at = At {
                            points,
                            start: warm,
                            refine_start: true,
                        };
                        backend.solve_posed(system, how, at, reporter)
                    })?
                }
                None => {
                    let at = At {
                        points: &boundary.points,
                        start,
                        refine_start: false,
                    };
                    backend.solve_posed(system, how, at, reporter)?
                }
            };
            let Some(bed) = self.bed else { return Ok((sol, springs)) };
            springs.steps += 1;
            let (next, change) = crate::bed::settle(boundary, bed, &sol, &springs.lambda, scale)?;
            reporter.event(&Event::BedStep {
                step: springs.steps,
                change,
                settled: crate::bed::SETTLED,
            });
            if crate::bed::settled(change, last) {
                springs.change = change;
                return Ok((sol, springs));
            }
            if springs.steps == crate::bed::MAX_STEPS {
                return Err(crate::bed::unsettled(change).into());
            }
            last = change;
            springs.lambda = next;
            start = Some(sol.lambda);
        }
    }

    /// An instant completed on the process that holds its fields (`None` elsewhere): checked,
    /// recovered where its fields were computed, its row made (forces, slips, counts, charges)
    /// and handed to `each`, friction's history advanced.
    fn complete_step(
        &self,
        state: &mut History,
        disc: &Discretization<'_>,
        stepped: Stepped,
        (reporter, each): (&mut dyn Reporter, &mut Each<'_>),
        (frames, deferred): (&mut Frames, bool),
    ) -> Result<Option<Done>, ProblemError> {
        let Stepped {
            k,
            t,
            f,
            factors,
            boundary,
            sol,
            fields,
            mut loads,
            springs,
            seconds,
        } = stepped;
        let Some((boundary, fields)) = self.widened(boundary, fields, state) else {
            return Ok(None);
        };
        let Some((sol, fielded, pcg_iters)) =
            self.checked((boundary.as_ref(), &f), disc, (sol, fields), &springs, reporter)?
        else {
            return Ok(None);
        };
        let mut iterations = Iterations::of(sol.as_ref().map(|s| &s.info), pcg_iters);
        iterations.bed = springs.steps;
        let (Some(boundary), Some(mut sol)) = (boundary, sol) else {
            // no contact: the instant's fields alone
            return Ok(Some(Done {
                result: None,
                fields: fielded.map(|(r, e, _)| (r, e, loads)),
                iterations,
                pcg_iters,
                seconds,
            }));
        };
        // a written instant whose fields come later: what they are computed from
        let frame = deferred.then(|| Frame {
            k,
            t,
            f,
            loads: std::mem::take(&mut loads),
            boundary: boundary.clone(),
            sol: sol.clone(),
            shift: state.shift.clone(),
            change: springs.change,
            row: state.rows.len(),
        });
        if self.spec.is_some() {
            // the multipliers and displacements of the step in the body's frame
            for (v, s) in sol.u.tangential.iter_mut().zip(&state.shift.tangential) {
                *v += s;
            }
        }
        let now = match &fielded {
            Some((_, _, u)) => {
                let mut now = PointValues::zeros(boundary.points.len(), boundary.points.n_tangential());
                boundary.extract(u, &mut now);
                now
            }
            None => sol.u.clone(),
        };
        let mut row = step_row(k, t, &f, &boundary, &sol, &now, &state.shift);
        self.indenter_row(&mut row, (&boundary, &sol), &f);
        // the charges of the fields where they are computed, else of the functionals (equal to
        // the condensed solve's accuracy: tests/path.rs)
        (row.charges, row.potentials) = match (&fielded, &factors) {
            (Some((recovered, _, _)), _) => recovered.terminals.iter().map(|x| (x.charge, x.potential)).unzip(),
            (None, Some(factors)) => {
                let applied = springs.applied(&sol.lambda);
                self.terminals.at(factors, &applied, &boundary.points.weight)
            }
            (None, None) => (vec![], vec![]),
        };
        row.equilibrium = fielded.as_ref().map(|(_, e, _)| *e);
        state.advance(&now, &sol, &iterations);
        let result = match &fielded {
            Some((_, _, u)) => contact_result(boundary, sol, u),
            None => ContactResult::condensed(boundary, sol),
        };
        if self.spec.is_some() {
            reporter.event(&Event::step_done(&row, self.of, &self.setup.units));
        }
        let recovered = fielded.as_ref().map(|(r, _, _)| r);
        let result = self.hand_on((frames, frame), (&row, state.rows.len()), result, recovered, each)?;
        state.rows.push(row);
        Ok(Some(Done {
            result,
            fields: fielded.map(|(r, e, _)| (r, e, loads)),
            iterations,
            pcg_iters,
            seconds,
        }))
    }

    /// A completed step handed on: a written instant whose fields come later waits (its
    /// `frame`), and a step after one that waits is queued, each with its row's `index`;
    /// any other goes to `each` at once (with its fields where computed). The contact result
    /// is given back where it was handed on.
    fn hand_on(
        &self,
        (frames, frame): (&mut Frames, Option<Frame>),
        (row, index): (&StepRow, usize),
        result: ContactResult,
        fielded: Option<&Recovered>,
        each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
    ) -> Result<Option<ContactResult>, ProblemError> {
        if let Some(frame) = frame {
            // its row and result now, its fields with the next written instants'
            frames.waiting.push(frame);
            frames.queue.push(Queued {
                row: index,
                result: None,
            });
            return Ok(None);
        }
        if !frames.queue.is_empty() {
            // after a written instant that waits: handed on in order
            frames.queue.push(Queued {
                row: index,
                result: Some(result),
            });
            return Ok(None);
        }
        each(Step {
            row,
            mesh: &self.setup.mesh,
            contact: &result,
            fields: fielded.map(|r| StepFields {
                u: &r.u,
                phi: &r.phi,
                fields: Some(&r.fields),
            }),
        })?;
        Ok(Some(result))
    }

    /// An instant's contact solution and fields checked, the fields recovered where computed
    /// (with their equilibrium residual, the springs' last change added, and the free
    /// displacements), and its PCG iterations; `None` on a process that does not hold them.
    fn checked(
        &self,
        (boundary, f): (Option<&ContactBoundary>, &Factors),
        disc: &Discretization<'_>,
        (sol, fields): (Option<ContactSolution>, Option<Option<InstantSolution>>),
        springs: &Springs,
        reporter: &mut dyn Reporter,
    ) -> Result<Option<Checked>, ProblemError> {
        let (scene, setup) = (self.scene, self.setup);
        Ok(Some(match fields {
            Some(None) => return Ok(None),
            Some(Some(x)) => {
                let equilibrium = x.equilibrium + springs.change;
                let (u, phi) = &x.x;
                check_solved(scene, (u, phi), x.contact.as_ref(), equilibrium)?;
                self.check_accurate(x.contact.as_ref(), equilibrium)?;
                let pair = boundary.zip(x.contact.as_ref());
                let recovered = recover(scene, (setup, disc), f, (u, phi), pair, equilibrium, reporter)?;
                (x.contact, Some((recovered, equilibrium, x.x.0)), x.pcg_iters)
            }
            None => {
                check_solved(scene, (&[], &[]), sol.as_ref(), 0.0)?;
                self.check_accurate(sol.as_ref(), 0.0)?;
                (sol, None, 0)
            }
        }))
    }

    /// The contact boundary of the run (`None` without contact): whether every instant's
    /// fields are computed, and the bed where only it holds the body, follow from it; where
    /// `points` asks, narrowed to the points that can touch ([`Walk::narrowed`]). A second walk
    /// with every point ([`Points::All`]: the first left out some that touch) said its notes.
    fn boundary(
        &mut self,
        posed: &mut Posed<'_>,
        instants: &[f64],
        points: Points,
        reporter: &mut dyn Reporter,
    ) -> Result<Option<ContactBoundary>, ProblemError> {
        let boundary = match points {
            Points::ThatCanTouch => contact_boundary(posed, reporter)?,
            Points::All => contact_boundary(posed, &mut crate::Silent)?,
        };
        self.every_fields = boundary.as_ref().is_some_and(|b| b.electric.is_some());
        posed.bed = self.bed(posed, instants, boundary.as_ref())?;
        Ok(match boundary {
            Some(b) if points == Points::ThatCanTouch => Some(self.narrowed(b, posed, reporter)),
            b => b,
        })
    }

    /// A path's plan, where it writes its instants' fields: how many, and how large their files
    /// ([`Event::path_plan`]).
    fn plan_path(
        &self,
        instants: usize,
        disc: &Discretization<'_>,
        boundary: Option<&ContactBoundary>,
        reporter: &mut dyn Reporter,
    ) {
        if let (Some(spec), true, Some(b)) = (self.spec, self.with_fields, boundary) {
            let written = (0..instants).filter(|&k| spec.has_fields(k, instants)).count();
            let flux = b.electric.is_some();
            reporter.event(&Event::path_plan(
                (instants, written),
                &self.setup.mesh,
                disc.nv(),
                (flux, spec.cell_fields),
            ));
        }
    }

    /// Where the contact problem was narrowed: whether points left out would touch, as the
    /// process holding the fields found, agreed by every process ([`Backend::agree_beyond`]).
    fn agreed_beyond<B: Backend>(&self, backend: &mut B) -> Result<Option<Walked>, B::Error> {
        let Some(reach) = &self.reach else {
            return Ok(None);
        };
        let found = self.beyond.get().map(|b| b.points);
        Ok(backend.agree_beyond(found)?.map(|points| Walked::Beyond {
            points,
            of: reach.counts().1,
        }))
    }

    /// The boundary of a static run's contact problem narrowed to the points that can touch
    /// ([`Reach`]), where its plan condenses them and no bed needs the whole (the report says
    /// how many it holds); `whole` itself elsewhere, and for a path, whose instants' fields
    /// (which check the points left out) are not all computed.
    fn narrowed(&mut self, whole: ContactBoundary, posed: &Posed<'_>, reporter: &mut dyn Reporter) -> ContactBoundary {
        if self.spec.is_some() || posed.bed.is_some() || !posed.plan().linear_strategy.is_condensed() {
            return whole;
        }
        let Some((reach, part)) = Reach::of(&whole, &posed.scene.zones()) else {
            return whole;
        };
        let (kept, of) = reach.counts();
        reporter.event(&Event::Reach {
            kept,
            of,
            depths: crate::reach::REACH,
        });
        self.reach = Some(reach);
        part
    }

    /// An instant's boundary and fields on the whole boundary where the contact problem held
    /// only the points that can touch: its solution widened to every point ([`Reach::widen`]).
    /// Friction's history (its frame and slips, the static run's zeros) widened with it.
    /// `None` where a point left out would touch ([`Walk::beyond`] says how many).
    #[allow(clippy::type_complexity)]
    fn widened(
        &self,
        boundary: Option<ContactBoundary>,
        fields: Option<Option<InstantSolution>>,
        state: &mut History,
    ) -> Option<(Option<ContactBoundary>, Option<Option<InstantSolution>>)> {
        let Some(reach) = &self.reach else {
            return Some((boundary, fields));
        };
        let Some(Some(mut x)) = fields else {
            return Some((boundary, fields));
        };
        let Some(sol) = x.contact.take() else {
            return Some((boundary, Some(Some(x))));
        };
        match reach.widen(sol, &x.x.0) {
            Ok((whole, sol)) => {
                x.contact = Some(sol);
                (state.shift, state.slipped) = (reach.spread(&state.shift), reach.spread_each(&state.slipped));
                Some((Some(whole), Some(Some(x))))
            }
            Err(beyond) => {
                self.beyond.set(Some(beyond));
                None
            }
        }
    }

    /// An indenter's figures in the step's row: its depth, contact radius, a conducting tip's
    /// charge, and the half-space's closed form beside them at the step's factors `f`.
    fn indenter_row(&self, row: &mut StepRow, (boundary, sol): (&ContactBoundary, &ContactSolution), f: &Factors) {
        let at = crate::run::indented(self.scene, boundary, sol);
        if let Some(mut indenter) = at.and_then(|at| indenter_report(self.scene, at)) {
            (row.depth, row.contact_radius) = (Some(indenter.depth), Some(indenter.contact_radius));
            row.tip_charge = indenter.charge;
            closed_form(self.scene, self.setup.plan.electric, &mut indenter, f);
            row.half_space = indenter.half_space.map(|h| crate::report::HalfSpaceRow {
                depth: h.depth,
                force: h.force,
                contact_radius: h.contact_radius,
                charge: h.charge,
            });
        }
    }

    /// Under the tight rule, a backend held to its tolerances meets them
    /// ([`check_accurate`]); where only a compliant bed holds the body, its softness is named
    /// as the likely cause of an ill-conditioned system.
    fn check_accurate(&self, sol: Option<&ContactSolution>, equilibrium: f64) -> Result<(), ProblemError> {
        if !self.held_to_tolerance {
            return Ok(());
        }
        check_accurate(self.scene, &self.setup.plan, sol, equilibrium).map_err(|e| match (e, self.bed) {
            (ProblemError::IllConditioned { what, .. }, Some(bed)) => ProblemError::IllConditioned {
                what,
                factors: bed.conditioning_in_words(),
            },
            (e, _) => e,
        })
    }

    /// The report of the last instant (with a path's section), its contact result and
    /// recovered fields.
    fn finish(
        self,
        disc: &Discretization<'_>,
        figures: Figures,
        state: History,
        (done, recovered, equilibrium, loads): (Done, Recovered, f64, Loads),
        (t_setup, t_assembly, steps_s, t_total): (f64, f64, f64, Instant),
    ) -> (RunReport, Option<ContactResult>, Recovered) {
        let path = self.spec.is_some();
        let contact_s = match (path, &done.result) {
            (true, _) => steps_s,
            (false, Some(_)) => done.seconds,
            (false, None) => 0.0,
        };
        let timings_s = Timings {
            setup: t_setup,
            assembly: t_assembly,
            factorization: figures.factor_seconds,
            condense: figures.condense.map_or(0.0, |c| c.1),
            contact: contact_s,
            solve: if path { steps_s } else { done.seconds },
            output: 0.0,
            total: t_total.elapsed().as_secs_f64(),
        };
        let posed = self.posed(disc, loads);
        let measured = Measured {
            info: done.result.as_ref().map(|r| &r.solution.info),
            pcg_iters: done.pcg_iters,
            equilibrium,
            timings_s,
            figures,
            bed_steps: done.iterations.bed,
        };
        let mut report: RunReport = report(&posed, measured, &recovered);
        report.solver.condensed_points = self.reach.as_ref().map(|r| r.counts().0);
        if path {
            // the path's iterations are its steps' summed
            report.iterations = state.iterations;
            report.path = Some(PathReport {
                instants: state.rows.len(),
                factorisations: 1,
                condensations: 1,
                steps_s,
                rows: state.rows,
            });
        }
        (report, done.result, recovered)
    }
}

/// One part of the right-hand side: its mechanical and electric entries.
type Part = (Vec<f64>, Vec<f64>);

/// The step's loads: the parts of the right-hand side scaled by its factors, checked finite
/// (for a backend that walks a path on its own: a run on pieces).
///
/// # Errors
/// [`ProblemError::NotFinite`] where a scaled load is not finite.
pub fn step_loads(parts: &RhsParts, f: &Factors, scene: &Scene) -> Result<Loads, ProblemError> {
    let combine = |pick: fn(&Part) -> &Vec<f64>| {
        let mut out: Vec<f64> = pick(&parts.loads).iter().map(|v| f.load * v).collect();
        for (d, fk) in parts.displacements.iter().zip(f.displacement) {
            for (o, v) in out.iter_mut().zip(pick(d)) {
                *o += fk * v;
            }
        }
        for (o, v) in out.iter_mut().zip(pick(&parts.potentials)) {
            *o += f.voltage * v;
        }
        out
    };
    let b_u = combine(|p| &p.0);
    let b_phi = combine(|p| &p.1);
    ProblemError::check_finite(&b_u, "the mechanical load vector", scene)?;
    ProblemError::check_finite(&b_phi, "the electric load vector", scene)?;
    // (the parts' order: Walk::ordered_parts')
    let mut factors = vec![f.load];
    factors.extend(f.displacement.iter().take(parts.displacements.len()));
    factors.push(f.voltage);
    Ok(Loads {
        b_u,
        b_phi,
        factors: Some(factors),
    })
}

/// Whether an instant can be resolved at its own scale `own` (the displacement its
/// own data make): friction acts on the increment `u_t - shift`, so the step's slip, and the
/// multipliers it sets, are known to `ε |shift|` at best; where that is more than the
/// tolerance times the instant's own displacements (after an excursion: a load factor of 1e30
/// leaves tangential displacements of 1e12 behind, and a later instant at load 1 is round-off
/// in them) the instant cannot meet it, however well its solve converged on its own numbers.
/// An instant whose own data make nothing (zero load) has nothing to resolve. Under the tight
/// rule the path stops there with [`ProblemError::IllConditioned`].
fn check_history(shift: &PointValues, own: f64, plan: &crate::plan::Plan) -> Result<(), ProblemError> {
    let history = shift.tangential.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    check_history_scales(history, own, plan)
}

/// Whether an instant can be resolved beside friction's history, on its two scales:
/// `history` the largest tangential displacement the history carries, `own` the displacement
/// the instant's own data make (a path's own check; a backend that holds the points in pieces
/// reduces each scale over them). An instant whose own data make nothing has nothing to
/// resolve.
///
/// # Errors
/// [`ProblemError::IllConditioned`] under the tight rule where double precision resolves the
/// instant to more than the tolerance of itself.
pub fn check_history_scales(history: f64, own: f64, plan: &crate::plan::Plan) -> Result<(), ProblemError> {
    if plan.rule != crate::Rule::Tight || history == 0.0 || own == 0.0 {
        return Ok(());
    }
    let floor = f64::EPSILON * history / own;
    if floor <= plan.tol {
        return Ok(());
    }
    Err(ProblemError::IllConditioned {
        what: format!(
            "friction's history carries tangential displacements up to {history:.2e}, this instant's own data displace the contact face by {own:.2e}, so double precision resolves it to {floor:.1e} of itself at best, above solver.tol = {:e}",
            plan.tol
        ),
        factors: "an earlier instant's factors far larger than this one's (an excursion of the load, voltage or displacement along the path): scale the path's factors nearer each other, or start a new path after the excursion".into(),
    })
}

/// The row of a step: its forces (the multipliers weighted), slips and counts; its charges
/// and equilibrium residual are the caller's to fill. `boundary` and `sol` may be a rank's own
/// points (a run on pieces sums and takes the maxima of the ranks' rows).
#[must_use]
pub fn step_row(
    step: usize,
    t: f64,
    f: &Factors,
    boundary: &ContactBoundary,
    sol: &ContactSolution,
    now: &PointValues,
    before: &PointValues,
) -> StepRow {
    let points = &boundary.points;
    let counts =
        crate::report::ContactReport::of_groups(points, sol, &boundary.groups, &boundary.group_of, boundary.revolution);
    let nt = sol.lambda.n_tangential();
    let mut max_slip = 0.0f64;
    let mut max_inc = 0.0f64;
    // the slips of the points in contact (a separated point moves freely); without friction
    // the solution has no tangential components, and no slip is reported at any instant (the
    // points' tangential displacements, where an instant's fields give them, would make the
    // column depend on which instants were written)
    let frictional = nt > 0;
    for i in (0..points.len()).filter(|&i| frictional && sol.status[i] != contact::Status::Separated) {
        let u = now.tangential_of(i);
        max_slip = max_slip.max(u.iter().map(|v| v * v).sum::<f64>().sqrt());
        if nt > 0 {
            let b = before.tangential_of(i);
            let d: f64 = u.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
            max_inc = max_inc.max(d);
        }
    }
    StepRow {
        step,
        t,
        factors: [
            f.load,
            f.voltage,
            f.displacement[0],
            f.displacement[1],
            f.displacement[2],
            f.gap,
        ],
        normal_force: counts.normal_force,
        tangential_force: counts.tangential_force,
        tangential_resultant: counts.tangential_resultant,
        groups: counts.groups,
        max_slip,
        max_slip_increment: max_inc,
        n_stick: counts.n_stick,
        n_slip: counts.n_slip,
        n_separated: counts.n_separated,
        iterations: sol.info.newton_iters + sol.info.uzawa_iters,
        depth: None,
        contact_radius: None,
        tip_charge: None,
        half_space: None,
        charges: vec![],
        potentials: vec![],
        complementarity: sol.info.complementarity,
        equilibrium: None,
    }
}
