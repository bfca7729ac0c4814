//! The quasi-static process along a load path (`[path]`): the scene's loads, prescribed
//! displacements, potentials and gap scaled by their factors at each instant, the contact
//! problem solved at each with the friction law on the slip since the instant before
//! (backward Euler of the quasi-static law: friction remembers), on one factorisation of `K`
//! and one condensation onto the contact dofs (the matrix does not change along the path).
//!
//! Each step's right-hand side is the sum of the parts of [`Discretization::rhs_parts`]
//! scaled by the step's factors, and so is the loads' displacement at the points: the parts
//! are solved once. A step is then its contact solve on the condensed compliance,
//! warm-started from the step before: its row (forces, slips, counts, the charges through the
//! terminals) comes from the multipliers alone, the charges by their functionals
//! ([`Discretization::charge_functionals`]: `Σ_q f_q Q_q - Σ_i w_i λ_i · z_i`, `Q_q` the
//! charge of part `q`'s solution and `z` the response `K⁻¹ a` of the functional `a` at the
//! points, both computed once). The fields (a solve with `K`'s factors, refined, and the
//! recovery) are computed only at the instants whose files are written, and at the last.

use crate::backend::{At, Bed, ContactSolve, Framed, InstantOf, Limits, Loads, PathBackend, Posed};
use crate::boundary::ContactBoundary;
use crate::progress::{Event, Reporter};
use crate::report::{PathReport, RunReport, StepRow, Timings};
use crate::run::{
    begin, check_accurate, check_solved, contact_result, indenter_report, recover, report, stop_if_interrupted,
    terminal_groups, ContactResult, Measured, Recovered,
};
use crate::scene::{Factors, PathSpec, Scene};
use crate::setup::Setup;
use crate::ProblemError;
use crate::SetupError;
use crate::Solution;
use contact::{ContactSolution, PointValues};
use fe_assembly::{CellFields, Discretization, RhsParts};
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

/// The fields of an instant of a path.
pub struct StepFields<'a> {
    /// Nodal displacements.
    pub u: &'a [[f64; 3]],
    /// Nodal potentials.
    pub phi: &'a [f64],
    /// Per-cell fields.
    pub fields: &'a CellFields,
}

/// What a path produced: the last instant's solution (its report with the path's section)
/// and every step's row.
pub struct PathSolution {
    /// The solution at the last instant; `report.path` holds the rows.
    pub last: Solution,
}

/// [`crate::solve_path`] on `backend`: the walk over the instants, written once for every
/// [`PathBackend`].
///
/// # Errors
/// As [`crate::solve_path`].
pub(crate) fn walk<B: PathBackend>(
    backend: &mut B,
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
    with_fields: bool,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<PathSolution, ProblemError> {
    let spec = scene.path.clone().unwrap_or_else(|| PathSpec {
        t: vec![0.0, 1.0],
        steps: Some(1),
        ..Default::default()
    });
    let instants = if scene.path.is_some() {
        spec.instants()
    } else {
        vec![1.0]
    };
    let valid = scene.validate()?;
    backend.supports(&valid)?;
    let Some(spec_contact) = scene.active_contact().cloned() else {
        return Err(SetupError::new("path", "a path carries friction's history: the scene has no contact").into());
    };
    let t_total = Instant::now();
    let setup = begin(valid, mesh, backend.estimate(&valid), &limits, reporter)?;
    let t_setup = t_total.elapsed().as_secs_f64();
    stop_if_interrupted(&limits, "set-up")?;
    let mut disc = setup.discretize()?;
    let parts = disc.rhs_parts(&setup.loads)?;
    let mut walk = Walk {
        scene,
        valid,
        setup: &setup,
        spec: &spec,
        contact: &spec_contact,
        parts: &parts,
        base_dofs: disc.dofs.clone(),
        with_fields,
        terminals: Terminals::default(),
    };
    let (mut system, boundary, t_assembly, bed) = walk.factor(backend, &disc, &instants, &limits, reporter)?;
    let how = ContactSolve::new(&setup.plan, scene, &boundary, limits.interrupt);
    let ordered: Vec<(Vec<f64>, Vec<f64>)> = std::iter::once(parts.loads.clone())
        .chain(parts.displacements.iter().cloned())
        .chain(std::iter::once(parts.potentials.clone()))
        .collect();
    let (mut path, solved) = backend.begin_path(&mut system, &boundary, &how, &ordered, reporter)?;
    walk.terminals = Terminals::new(&walk, &disc, (&mut *backend, &mut system), &boundary, &solved)?;
    drop(solved);
    let t_steps = Instant::now();
    let mut state = History::new(boundary.points.len(), setup.plan.n_tangential(), instants.len());
    let mut on = On {
        backend: &mut *backend,
        base: &boundary,
        disc: &mut disc,
        system: &mut system,
        path: &mut path,
        how: &how,
        state: &mut state,
        bed,
    };
    walk.all_steps(&instants, &mut on, reporter, each)?;
    let steps_s = t_steps.elapsed().as_secs_f64();
    let timings = (t_setup, t_assembly, steps_s, t_total);
    let figures = backend.figures(&system);
    let (report, done) = walk.finish(&disc, figures, state, timings);
    drop(disc);
    let (recovered, _, _) = done.fields.expect("the last instant has its fields");
    Ok(PathSolution {
        last: Solution {
            report,
            contact: Some(done.result),
            mesh: setup.mesh,
            u: recovered.u,
            phi: recovered.phi,
            fields: recovered.fields,
        },
    })
}

/// What a path's steps work on: the boundary at the scene's own factors, the discretisation
/// (its prescribed values scaled at each step), the factors of `K` and the path's condensed
/// system on them, the contact solve, and friction's history.
struct On<'a, 'd, B: PathBackend> {
    backend: &'a mut B,
    base: &'a ContactBoundary,
    disc: &'a mut Discretization<'d>,
    system: &'a mut B::System,
    path: &'a mut B::Path,
    how: &'a ContactSolve<'a>,
    state: &'a mut History,
    /// The springs that hold a body only its compliant bed holds.
    bed: Option<Bed>,
}

/// What stays the same along a path: the scene, its set-up, the parts of the right-hand side.
struct Walk<'a> {
    scene: &'a Scene,
    valid: crate::Valid<'a>,
    setup: &'a Setup,
    spec: &'a PathSpec,
    contact: &'a crate::ContactSpec,
    parts: &'a RhsParts,
    /// The dof map with the scene's prescribed values (scaled at each step).
    base_dofs: fe_assembly::DofMap,
    /// Whether the fields of the output instants are computed ([`PathSpec::has_fields`]; the
    /// last instant's always are).
    with_fields: bool,
    /// The charges' functionals.
    terminals: Terminals,
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
    fn new<B: PathBackend>(
        walk: &Walk<'_>,
        disc: &Discretization<'_>,
        (backend, system): (&mut B, &mut B::System),
        boundary: &ContactBoundary,
        solved: &[(Vec<f64>, Vec<f64>)],
    ) -> Result<Terminals, ProblemError> {
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
            for (g, charge) in disc.charges(&u, &phi, &groups, loads)?.into_iter().enumerate() {
                charges[g].push(charge);
                potentials[g].push(firsts[g].map_or(0.0, |v| phi[v]));
            }
        }
        let points = &boundary.points;
        let mut respond = |a_u: &[f64], a_phi: &[f64]| -> Result<PointValues, ProblemError> {
            let (z, _) = backend.respond(system, a_u, a_phi)?;
            let mut out = PointValues::zeros(points.len(), points.n_tangential());
            boundary.extract_free(&z, &mut out);
            Ok(out)
        };
        let mut out = Terminals::default();
        for ((a_u, a_phi), of_parts) in disc.charge_functionals(&groups)?.into_iter().zip(charges) {
            out.charges.push(Functional {
                of_parts,
                at_points: Some(respond(&a_u, &a_phi)?),
            });
        }
        let dofs = &disc.dofs;
        for (first, of_parts) in firsts.into_iter().zip(potentials) {
            // a floating terminal's potential is a free unknown: e_j's response
            let at_points = match first.map(|v| dofs.phi[v]) {
                Some(fe_assembly::Dof::Free(j)) => {
                    let mut a_phi = vec![0.0; dofs.n_phi];
                    a_phi[j] = 1.0;
                    Some(respond(&vec![0.0; dofs.n_u], &a_phi)?)
                }
                _ => None,
            };
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
    fn advance(&mut self, now: &PointValues, sol: &ContactSolution) {
        self.iterations.add(&crate::report::Iterations::of(Some(&sol.info), 0));
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

/// One instant solved: its row, its contact solution, and where computed its fields (with the
/// equilibrium residual and the step's loads).
/// An instant's fields: recovered, their equilibrium residual, the loads, the displacement.
type InstantFields = (Recovered, f64, Loads, Vec<f64>);

/// The springs' multipliers of an instant of a body only its compliant bed holds (zeros
/// otherwise), the bed's fixed-point steps, and its last change (relative to the forces).
struct Springs {
    lambda: PointValues,
    steps: usize,
    change: f64,
}

impl Springs {
    /// The multipliers that act on the springs' `K`: the contact's `lambda` and the springs'.
    fn applied(&self, lambda: &PointValues) -> PointValues {
        let mut out = lambda.clone();
        for (a, s) in out.normal.iter_mut().zip(&self.lambda.normal) {
            *a += s;
        }
        out
    }
}

struct Done {
    row: StepRow,
    result: ContactResult,
    fields: Option<(Recovered, f64, Loads)>,
}

impl Walk<'_> {
    /// Assembles and factors `K` with the boundary's dofs last (at the first instant's
    /// factors); the boundary, and the assembly's time.
    fn factor<B: PathBackend>(
        &self,
        backend: &mut B,
        disc: &Discretization<'_>,
        instants: &[f64],
        limits: &Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<(B::System, ContactBoundary, f64, Option<Bed>), ProblemError> {
        let t = Instant::now();
        let mut posed = Posed {
            scene: self.valid,
            setup: self.setup,
            disc,
            loads: step_loads(self.parts, &self.spec.factors(instants[0]), self.scene)?,
            bed: None,
        };
        let assembled = backend.assemble(&posed)?;
        let t_assembly = t.elapsed().as_secs_f64();
        reporter.event(&Event::assembled(&self.setup.mesh, &disc.dofs, t_assembly));
        let boundary = ContactBoundary::of_groups(disc, &self.scene.zones())?;
        boundary.report_held(&self.contact.group, reporter);
        posed.bed = self.bed(disc, instants, &boundary)?;
        let system = backend.prepare(&posed, assembled, Some(&boundary), *limits, reporter)?;
        stop_if_interrupted(limits, "factorisation")?;
        Ok((system, boundary, t_assembly, posed.bed))
    }

    /// The springs that hold a body only its compliant bed holds (`None` where the conditions
    /// hold it), sized by the loads of the path's strongest instant.
    fn bed(
        &self,
        disc: &Discretization<'_>,
        instants: &[f64],
        boundary: &ContactBoundary,
    ) -> Result<Option<Bed>, ProblemError> {
        let mut strongest = step_loads(self.parts, &self.spec.factors(instants[0]), self.scene)?;
        for &t in &instants[1..] {
            let loads = step_loads(self.parts, &self.spec.factors(t), self.scene)?;
            if linalg::norm(&loads.b_u) > linalg::norm(&strongest.b_u) {
                strongest = loads;
            }
        }
        let posed = Posed {
            scene: self.valid,
            setup: self.setup,
            disc,
            loads: strongest,
            bed: None,
        };
        Bed::needed(&posed, Some(boundary))
    }

    /// Every instant in order, each handed to `each` and its row kept; the last kept whole.
    fn all_steps<B: PathBackend>(
        &self,
        instants: &[f64],
        on: &mut On<'_, '_, B>,
        reporter: &mut dyn Reporter,
        each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
    ) -> Result<(), ProblemError> {
        let of = instants.len() - 1;
        for (k, &t) in instants.iter().enumerate() {
            reporter.event(&Event::PathStep { step: k, of, t });
            let at = |e: ProblemError| e.at_step(k, t);
            let fields = k == of || (self.with_fields && self.spec.has_fields(k, of + 1));
            let done = self.step(on, k, t, fields, reporter).map_err(at)?;
            reporter.event(&Event::PathStepDone { row: &done.row, of });
            each(Step {
                row: &done.row,
                mesh: &self.setup.mesh,
                contact: &done.result,
                fields: done.fields.as_ref().map(|(r, _, _)| StepFields {
                    u: &r.u,
                    phi: &r.phi,
                    fields: &r.fields,
                }),
            })?;
            on.state.rows.push(done.row.clone());
            if k == of {
                on.state.last = Some(done);
            }
        }
        Ok(())
    }

    /// The instant `t` (the path's `k`-th): its prescribed values, gap and loads scaled, the
    /// contact problem in the frame of the step before; where `with_fields`, the fields
    /// recovered and checked.
    fn step<B: PathBackend>(
        &self,
        on: &mut On<'_, '_, B>,
        k: usize,
        t: f64,
        with_fields: bool,
        reporter: &mut dyn Reporter,
    ) -> Result<Done, ProblemError> {
        let (scene, setup) = (self.scene, self.setup);
        let f = self.spec.factors(t);
        on.disc.dofs = self.base_dofs.scaled(f.displacement, f.voltage);
        let mut boundary = on.base.at_factors(f.gap, f.displacement);
        if on.base.points.weakens() {
            boundary.points.slipped.clone_from(&on.state.slipped);
        }
        let mut factors = vec![f.load];
        factors.extend_from_slice(&f.displacement[..setup.mesh.dim]);
        factors.push(f.voltage);
        let (sol, spring) = self.contact_at(on, &mut boundary, &factors, f.load, reporter)?;
        if let Some(contraction) = sol.info.contraction.filter(|c| *c >= 1.0) {
            reporter.event(&Event::NotContractive { contraction });
        }
        // the instant's own displacement scale: its loads' and prescribed values', and how far
        // its gaps press in
        let pressed = boundary.points.gap.iter().fold(0.0f64, |m, g| m.max(-g));
        check_history(
            &on.state.shift,
            on.backend.own_scale(on.path, &factors).max(pressed),
            &setup.plan,
        )?;
        let (mut sol, fields) = if with_fields {
            self.fields_at(on, &boundary, &f, (sol, &spring), reporter)?
        } else {
            check_solved(scene, (&[], &[]), Some(&sol), 0.0)?;
            check_accurate(scene, &setup.plan, Some(&sol), 0.0)?;
            (sol, None)
        };
        let state = &mut *on.state;
        // the multipliers and displacements of the step in the body's frame
        for (v, s) in sol.u.tangential.iter_mut().zip(&state.shift.tangential) {
            *v += s;
        }
        let now = match &fields {
            Some((_, _, _, u)) => {
                let mut now = PointValues::zeros(boundary.points.len(), boundary.points.n_tangential());
                boundary.extract(u, &mut now);
                now
            }
            None => sol.u.clone(),
        };
        let mut row = step_row(k, t, &f, &boundary, &sol, &now, &state.shift);
        if let Some(indenter) = indenter_report(scene, &boundary, &sol) {
            (row.depth, row.contact_radius) = (Some(indenter.depth), Some(indenter.contact_radius));
        }
        // the charges of the fields where they are computed, else of the functionals (equal to
        // the condensed solve's accuracy: tests/path.rs)
        (row.charges, row.potentials) = match &fields {
            Some((recovered, _, _, _)) => recovered.terminals.iter().map(|x| (x.charge, x.potential)).unzip(),
            None => self
                .terminals
                .at(&factors, &spring.applied(&sol.lambda), &boundary.points.weight),
        };
        row.equilibrium = fields.as_ref().map(|(_, e, _, _)| *e);
        state.advance(&now, &sol);
        state.iterations.bed += spring.steps;
        let result = match &fields {
            Some((_, _, _, u)) => contact_result(boundary, sol, u),
            None => ContactResult::condensed(boundary, sol),
        };
        Ok(Done {
            row,
            result,
            fields: fields.map(|(r, e, l, _)| (r, e, l)),
        })
    }

    /// The fields of an instant (factors `f`) under the contact forces of `sol`: refined, the
    /// law judged on them, checked and recovered; with the equilibrium residual, the loads and
    /// the displacement.
    fn fields_at<B: PathBackend>(
        &self,
        on: &mut On<'_, '_, B>,
        boundary: &ContactBoundary,
        f: &Factors,
        (sol, spring): (ContactSolution, &Springs),
        reporter: &mut dyn Reporter,
    ) -> Result<(ContactSolution, Option<InstantFields>), ProblemError> {
        let (scene, setup) = (self.scene, self.setup);
        let mut loads = step_loads(self.parts, f, scene)?;
        // the springs' forces of a body only its bed holds are loads of the springs' K
        boundary.add_forces(&spring.lambda, &mut loads.b_u);
        let posed = Posed {
            scene: self.valid,
            setup,
            disc: on.disc,
            loads,
            bed: None,
        };
        let framed = Framed {
            boundary,
            shift: &on.state.shift,
        };
        let instant = InstantOf {
            how: on.how,
            framed,
            posed: &posed,
        };
        let (sol, (u, phi), equilibrium) = on.backend.instant_fields(on.path, on.system, instant, sol, reporter)?;
        let equilibrium = equilibrium + spring.change;
        check_solved(scene, (&u, &phi), Some(&sol), equilibrium)?;
        check_accurate(scene, &setup.plan, Some(&sol), equilibrium)?;
        let pair = Some((boundary, &sol));
        let recovered = recover(scene, setup, on.disc, (&u, &phi), pair, equilibrium, reporter)?;
        Ok((sol, Some((recovered, equilibrium, posed.loads, u))))
    }

    /// The contact solve of an instant at `factors` (force control: the depth found for the
    /// indenter's force times the `load` factor, from the step before's multipliers); where
    /// only a compliant bed holds the body, the bed's fixed point around it (the springs'
    /// forces a multiplier of their own on the condensed problem, as in the run:
    /// `crate::bed`), with the springs' multipliers and steps.
    fn contact_at<B: PathBackend>(
        &self,
        on: &mut On<'_, '_, B>,
        boundary: &mut ContactBoundary,
        factors: &[f64],
        load: f64,
        reporter: &mut dyn Reporter,
    ) -> Result<(ContactSolution, Springs), ProblemError> {
        let (backend, path, how, state) = (&mut *on.backend, &mut *on.path, on.how, &mut *on.state);
        let control = crate::outer::ForceControl::of(self.scene, boundary);
        let base_gap = boundary.points.gap.clone();
        let n = boundary.points.len();
        let mut springs = Springs {
            lambda: PointValues::zeros(n, self.setup.plan.n_tangential()),
            steps: 0,
            change: 0.0,
        };
        let mut start = state.start.take();
        let mut last = f64::INFINITY;
        loop {
            let framed = Framed {
                boundary,
                shift: &state.shift,
            };
            backend.prime(path, framed, factors, &springs.lambda)?;
            boundary.points.gap.clone_from(&base_gap);
            let sol = match &control {
                Some(control) => {
                    let force = control.force * load;
                    crate::outer::force_controlled(&mut boundary.points, control, force, start, |points, warm| {
                        let at = At {
                            points,
                            start: warm,
                            refine_start: true,
                        };
                        backend.solve_posed(path, how, at, reporter)
                    })?
                }
                None => {
                    let at = At {
                        points: &boundary.points,
                        start,
                        refine_start: false,
                    };
                    backend.solve_posed(path, how, at, reporter)?
                }
            };
            let Some(bed) = on.bed else { return Ok((sol, springs)) };
            springs.steps += 1;
            let (next, change) = crate::bed::settle(boundary, bed, &sol, &springs.lambda, 0.0)?;
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
                return Err(crate::bed::unsettled(change));
            }
            last = change;
            springs.lambda = next;
            start = Some(sol.lambda);
        }
    }

    /// The report of the last instant with the path's section, and the last instant.
    fn finish(
        self,
        disc: &Discretization<'_>,
        figures: crate::backend::Figures,
        state: History,
        (t_setup, t_assembly, steps_s, t_total): (f64, f64, f64, Instant),
    ) -> (RunReport, Done) {
        let mut done = state.last.expect("a path has at least one instant");
        let timings_s = Timings {
            setup: t_setup,
            assembly: t_assembly,
            factorization: figures.factor_seconds,
            condense: figures.condense.map_or(0.0, |c| c.1),
            contact: steps_s,
            solve: steps_s,
            total: t_total.elapsed().as_secs_f64(),
        };
        let (recovered, equilibrium, loads) = done.fields.as_mut().expect("the last instant has its fields");
        let posed = Posed {
            scene: self.valid,
            setup: self.setup,
            disc,
            loads: std::mem::take(loads),
            bed: None,
        };
        let measured = Measured {
            info: Some(&done.result.solution.info),
            pcg_iters: 0,
            equilibrium: *equilibrium,
            timings_s,
            figures,
            bed_steps: 0,
        };
        let mut report: RunReport = report(&posed, measured, recovered);
        // the path's iterations are its steps' summed
        report.iterations = state.iterations;
        report.path = Some(PathReport {
            instants: state.rows.len(),
            factorisations: 1,
            condensations: 1,
            steps_s,
            rows: state.rows,
        });
        (report, done)
    }
}

/// One part of the right-hand side: its mechanical and electric entries.
type Part = (Vec<f64>, Vec<f64>);

/// The step's loads: the parts of the right-hand side scaled by its factors, checked finite.
fn step_loads(parts: &RhsParts, f: &Factors, scene: &Scene) -> Result<Loads, ProblemError> {
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
    Ok(Loads { b_u, b_phi })
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
/// and equilibrium residual are the caller's to fill.
fn step_row(
    step: usize,
    t: f64,
    f: &Factors,
    boundary: &ContactBoundary,
    sol: &ContactSolution,
    now: &PointValues,
    before: &PointValues,
) -> StepRow {
    let points = &boundary.points;
    let counts = crate::report::ContactReport::of_groups(points, sol, &boundary.groups, &boundary.group_of);
    let nt = sol.lambda.n_tangential();
    let mut max_slip = 0.0f64;
    let mut max_inc = 0.0f64;
    // the slips of the points in contact (a separated point moves freely)
    for i in (0..points.len()).filter(|&i| sol.status[i] != contact::Status::Separated) {
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
        charges: vec![],
        potentials: vec![],
        complementarity: sol.info.complementarity,
        equilibrium: None,
    }
}
