//! A run, read as the method (as deal.II's step-41 reads): set up, discretise, assemble,
//! factor (or prepare the Krylov solvers), solve the contact problem (or the one linear
//! system) at each instant, check, recover the fields, report. The run (`crate::run`, its loop
//! over the instants in the `path` module) calls the steps in order on any backend and builds
//! the report once; here are the steps it shares between its instants: the set-up, the
//! checks, the recovery and the report.

use crate::backend::{Backend, Figures, Limits, Loads, Posed};
use crate::boundary::ContactBoundary;
use crate::exact::contact_errors;
use crate::plan::Plan;
use crate::progress::{Event, Reporter};
use crate::report::{
    rule_in_words, ContactReport, DofsReport, Iterations, Memory, MeshReport, Residuals, RunReport, SceneReport,
    SolverReport, Timings,
};
use crate::scene::{ContactLaw, Rule, Scene, Valid};
use crate::setup::{setup, Setup};
pub use crate::solution::{ContactResult, Solution};
use crate::ProblemError;
use contact::{ContactSolution, PointValues};
use fe_assembly::{CellFields, Discretization};

/// The start of a run on `backend`: its memory estimate (bytes, and what it counts) checked
/// against `limits` before the memory is taken, then the [`Setup`], its plan and what the
/// mesh's checks noted reported.
pub(crate) fn begin<B: Backend>(
    backend: &B,
    scene: Valid<'_>,
    mesh: Option<mesh::Mesh>,
    limits: &Limits,
    reporter: &mut dyn Reporter,
) -> Result<Setup, ProblemError> {
    check_memory(limits, backend.estimate(&scene))?;
    let setup = setup(scene, mesh)?;
    // a mesh read or handed over is known only now: the backend's estimate on it, before
    // anything is built on it
    check_memory(
        limits,
        backend.estimate_on_mesh(&scene, &setup.mesh, setup.plan.electric),
    )?;
    reporter.event(&Event::Planned(&setup.plan));
    reporter.event(&Event::Units(&setup.units));
    if !setup.notes.is_empty() {
        reporter.event(&Event::MeshNotes(setup.notes.clone()));
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

/// [`ProblemError::Interrupted`] after the step `after` where the run's interrupt has fired.
pub(crate) fn stop_if_interrupted(limits: &Limits, after: &'static str) -> Result<(), ProblemError> {
    match limits.interrupt.check() {
        Some(why) => Err(ProblemError::Interrupted { after, why }),
        None => Ok(()),
    }
}

/// The discrete problem: the loads on the free dofs, checked finite (what holds the body is
/// judged with the contact boundary, [`Bed::needed`]).
pub(crate) fn pose<'a>(
    scene: Valid<'a>,
    setup: &'a Setup,
    disc: &'a Discretization<'a>,
) -> Result<Posed<'a>, ProblemError> {
    let (b_u, b_phi) = disc.rhs(&setup.loads)?;
    ProblemError::check_finite(&b_u, "the mechanical load vector", &scene)?;
    ProblemError::check_finite(&b_phi, "the electric load vector", &scene)?;
    Ok(Posed {
        scene,
        setup,
        disc,
        loads: Loads {
            b_u,
            b_phi,
            factors: None,
        },
        bed: None,
    })
}

/// The contact boundary, where the plan has contact; its nodes that the Dirichlet conditions
/// hold reported.
pub(crate) fn contact_boundary(
    posed: &Posed<'_>,
    reporter: &mut dyn Reporter,
) -> Result<Option<ContactBoundary>, ProblemError> {
    let specs = posed.scene.zones();
    if specs.is_empty() || posed.plan().contact_law == ContactLaw::None {
        return Ok(None);
    }
    let boundary = ContactBoundary::of_groups(posed.disc, &specs)?;
    boundary.report_held(&boundary.groups.join(", "), posed.plan().friction, reporter);
    Ok(Some(boundary))
}

impl ContactResult {
    /// The contact part of a solution whose fields were not computed: the displacement of
    /// the points the contact solve's own (all tangential components 0 where it has none).
    pub fn condensed(b: ContactBoundary, solution: ContactSolution) -> ContactResult {
        let n_t = b.points.n_tangential();
        let mut displacement = PointValues::zeros(b.points.len(), n_t);
        displacement.normal.clone_from(&solution.u.normal);
        if solution.u.n_tangential() == n_t {
            displacement.tangential.clone_from(&solution.u.tangential);
        }
        ContactResult {
            nodes: b.nodes,
            points: b.points,
            solution,
            displacement,
            groups: b.groups,
            group_of: b.group_of,
        }
    }
}

/// The contact part of the solution: the boundary, the contact solve, and the displacement of
/// the points in the free displacements `u`.
pub(crate) fn contact_result(b: ContactBoundary, solution: ContactSolution, u: &[f64]) -> ContactResult {
    let mut displacement = PointValues::zeros(b.points.len(), b.points.n_tangential());
    b.extract(u, &mut displacement);
    ContactResult {
        points: b.points,
        nodes: b.nodes,
        solution,
        displacement,
        groups: b.groups,
        group_of: b.group_of,
    }
}

/// Checks the solution, the multipliers and the equilibrium residual for numbers that
/// overflowed.
pub(crate) fn check_solved(
    scene: &Scene,
    (u, phi): (&[f64], &[f64]),
    contact: Option<&ContactSolution>,
    equilibrium: f64,
) -> Result<(), ProblemError> {
    ProblemError::check_finite(u, "the displacement", scene)?;
    ProblemError::check_finite(phi, "the potential", scene)?;
    if let Some(sol) = contact {
        ProblemError::check_finite(&sol.lambda.normal, "the contact pressure", scene)?;
        ProblemError::check_finite(&sol.lambda.tangential, "the tangential multiplier", scene)?;
    }
    ProblemError::check_finite(&[equilibrium], "the equilibrium residual", scene)
}

/// Under the tight rule, every reported residual meets its tolerance, or the run fails naming
/// what makes the system ill-conditioned: the equilibrium residual ([`EQUILIBRIUM_TOL`]) and
/// the complementarity residual of the final fields (`solver.tol`).
pub(crate) fn check_accurate(
    scene: &Scene,
    plan: &Plan,
    contact: Option<&ContactSolution>,
    equilibrium: f64,
) -> Result<(), ProblemError> {
    if plan.rule != Rule::Tight {
        return Ok(());
    }
    let tol = equilibrium_tol(plan);
    if !(equilibrium <= tol) {
        return Err(ProblemError::inaccurate(
            "equilibrium residual",
            equilibrium,
            tol,
            scene,
        ));
    }
    if let Some(sol) = contact {
        let c = sol.info.complementarity;
        if !(c <= plan.tol) {
            return Err(ProblemError::inaccurate(
                "complementarity residual of the final fields",
                c,
                plan.tol,
                scene,
            ));
        }
    }
    Ok(())
}

/// The equilibrium residual a run must reach (relative, as [`linalg::equilibrium_residual`]):
/// eight digits of the loads balanced. The direct solves reach 1e-13 to 1e-15 on the shipped
/// scenes; a solve above it is refined, and a run still above it under the tight rule fails,
/// naming the inputs that make the system ill-conditioned.
pub const EQUILIBRIUM_TOL: f64 = 1e-8;

/// The equilibrium residual the plan's run must reach: [`EQUILIBRIUM_TOL`], or the PCG's own
/// relative tolerance where a Schur-complement PCG is asked for a looser one (`solver.pcg_tol`:
/// the run meets what it was asked, and its residual is that tolerance's, not a sign of an
/// ill-conditioned system).
pub fn equilibrium_tol(plan: &Plan) -> f64 {
    if plan.linear_strategy.runs_pcg() {
        EQUILIBRIUM_TOL.max(plan.pcg_tol)
    } else {
        EQUILIBRIUM_TOL
    }
}

/// The nodal solution, the per-cell fields, the contact counts and forces, and the error
/// against the exact solution: what a run reports, whichever backend solved it.
pub(crate) struct Recovered {
    /// Nodal displacements.
    pub(crate) u: Vec<[f64; 3]>,
    /// Nodal potentials.
    pub(crate) phi: Vec<f64>,
    /// Per-cell stress, strain, electric displacement and field.
    pub(crate) fields: CellFields,
    /// The contact boundary's counts and resultant forces (zeros without contact).
    pub(crate) contact: ContactReport,
    /// The error against the scene's exact solution, where it has one.
    pub(crate) exact: Option<crate::exact::ExactReport>,
    /// The groups at a prescribed potential, with their charges.
    pub(crate) terminals: Vec<crate::report::TerminalReport>,
    /// A rigid indenter's figures.
    pub(crate) indenter: Option<crate::report::IndenterReport>,
}

/// Expands the free unknowns `(u, φ)` to the nodes, recovers stress and electric
/// displacement per cell, counts the contact solution (on its boundary), measures the error
/// against the scene's exact solution (an indenter's closed form at the instant's factors `f`:
/// a static run's are 1), and checks that every reported number (with the run's
/// `equilibrium` residual) is finite.
pub(crate) fn recover(
    scene: &Scene,
    (setup, disc): (&Setup, &Discretization<'_>),
    f: &crate::Factors,
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
        potential: scene
            .zones()
            .into_iter()
            .find(|c| c.electric_law().is_some())
            .and_then(|c| conductor_potential(c, b, sol)),
        ..ContactReport::of_groups(&b.points, sol, &b.groups, &b.group_of, b.revolution)
    });
    let indenter = contact.and_then(|(b, sol)| {
        indenter_figures(
            scene,
            setup.plan.electric,
            indented(scene, b, sol)?,
            &|i| phi[b.nodes[i]],
            f,
        )
    });
    let half_space = scene
        .exact
        .as_ref()
        .is_some_and(|x| x.kind == crate::scene::ExactKind::HalfSpace);
    let exact = match (&setup.exact, contact) {
        (Some(ex), _) => Some(ex.errors(disc, &u, &phi, setup.plan.electric)),
        // the half-space's closed form, reported with the indenter's figures
        (None, Some(_)) if half_space => {
            let h = indenter.as_ref().and_then(|i| i.half_space.clone()).ok_or_else(|| {
                let why = indenter.as_ref().and_then(|i| i.half_space_absent.clone());
                ProblemError::Setup(crate::SetupError::new(
                    "exact.kind",
                    format!(
                        "exact.kind `half-space`: the run's indenter has no closed form: {}",
                        why.unwrap_or_else(|| "it does not apply".into())
                    ),
                ))
            })?;
            Some(crate::exact::ExactReport::HalfSpace(Box::new(h)))
        }
        (None, Some((b, sol))) => contact_errors(scene, &b.points, sol, counts.normal_force, counts.tangential_force)?,
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
    let terminals = terminals(setup, disc, &u, &phi)?;
    Ok(Recovered {
        u,
        phi,
        fields,
        contact: counts,
        exact,
        terminals,
        indenter,
    })
}

/// The half-space's closed form beside an indenter's figures `r` (`r.half_space`, or why it is
/// absent), at the instant's factors `f` (a path scales a conducting tip's potential by the
/// voltage factor and an indenter's force by the load factor; a static run's are 1).
pub(crate) fn closed_form(scene: &Scene, electric: bool, r: &mut crate::report::IndenterReport, f: &crate::Factors) {
    let measured = crate::exact::Measured {
        depth: r.depth,
        force: r.force,
        contact_radius: r.contact_radius,
        potential: r.potential,
        charge: r.charge,
        tip_potential: r.tip_potential,
    };
    // outside its domain it is absent and why is said (not applying, it is not said)
    (r.half_space, r.half_space_absent) = match crate::exact::half_space(scene, electric, &measured, f) {
        Some(Ok(h)) => (Some(h), None),
        Some(Err(why)) => (None, Some(why)),
        None => (None, None),
    };
}

/// A contact solution on its points, as an indenter's figures read it.
#[derive(Clone, Copy)]
pub struct Indented<'a> {
    /// The contact points.
    pub points: &'a contact::ContactPoints,
    /// The scene's contact zone of each point (an index into its `[[contact]]` zones).
    pub group_of: &'a [usize],
    /// The solution on them.
    pub sol: &'a ContactSolution,
    /// A conducting tip's potential (`None` on an insulating one).
    pub potential: Option<f64>,
}

/// The solution `sol` on `b`'s points as an indenter's figures read it; `None` without
/// `contact.indenter`.
pub(crate) fn indented<'a>(scene: &Scene, b: &'a ContactBoundary, sol: &'a ContactSolution) -> Option<Indented<'a>> {
    Some(Indented {
        points: &b.points,
        group_of: &b.group_of,
        sol,
        potential: conductor_potential(scene.indenter_contact()?.1, b, sol),
    })
}

/// A rigid indenter's figures at the solution `at` (shape, depth, force, contact radius), with, where the body
/// has potentials, the surface's potential at the indenter's point nearest its axis
/// (`phi_at(i)`: the potential at point `i`), and the half-space's closed form beside them at
/// the instant's factors `f` (a static run's are [`crate::Factors::ONE`]); `None` without
/// `contact.indenter`. For a caller that holds the contact points without the mesh (the
/// points gathered from the ranks of a run on pieces), as the run reports them.
pub fn indenter_figures(
    scene: &Scene,
    electric: bool,
    at: Indented<'_>,
    phi_at: &dyn Fn(usize) -> f64,
    f: &crate::Factors,
) -> Option<crate::report::IndenterReport> {
    let mut r = indenter_report(scene, at)?;
    if electric {
        // the contact point nearest the indenter's axis
        let (k, c) = scene.indenter_contact()?;
        let ind = c.indenter.as_ref()?;
        let p = at.points;
        let nearest = (0..p.len()).filter(|&i| at.group_of[i] == k).min_by(|&i, &j| {
            let ri = ind.local(&p.position[i], &p.normal[i]).1;
            let rj = ind.local(&p.position[j], &p.normal[j]).1;
            ri.total_cmp(&rj)
        });
        r.tip_potential = nearest.map(phi_at);
    }
    closed_form(scene, electric, &mut r, f);
    Some(r)
}

/// A rigid indenter's figures at the solution `at` (the depth read off its points' gaps);
/// `None` without `contact.indenter`.
pub(crate) fn indenter_report(scene: &Scene, at: Indented<'_>) -> Option<crate::report::IndenterReport> {
    let (k, c) = scene.indenter_contact()?;
    let ind = c.indenter.as_ref()?;
    let (points, sol) = (at.points, at.sol);
    // the indenter's own points (the other groups rest on foundations)
    let mine: Vec<usize> = (0..points.len()).filter(|&i| at.group_of[i] == k).collect();
    let r = |i: usize| ind.local(&points.position[i], &points.normal[i]).1;
    let (mut radius, mut count, mut force) = (0.0f64, 0, 0.0);
    for &i in &mine {
        if sol.lambda.normal[i] > 0.0 {
            radius = radius.max(r(i));
            count += 1;
        }
        force += points.weight[i] * sol.lambda.normal[i];
    }
    // the zone's edge lies between its last point and the next one that carries nothing
    let next = (mine.iter())
        .filter(|&&i| !(sol.lambda.normal[i] > 0.0))
        .map(|&i| r(i))
        .filter(|&ri| ri > radius)
        .min_by(f64::total_cmp);
    let first = *mine.first()?;
    Some(crate::report::IndenterReport {
        shape: ind.shape.to_string(),
        depth: c.depth_at_point(&points.position[first], &points.normal[first], points.gap[first]),
        force,
        contact_radius: radius,
        contact_radius_next: next,
        points_in_contact: count,
        potential: at.potential,
        // the charge across its own zone, where it conducts (another zone may)
        charge: sol
            .electric
            .as_ref()
            .filter(|_| c.electric_law().is_some())
            .map(|e| e.charge(&points.weight)),
        tip_potential: None,
        half_space: None,
        half_space_absent: None,
    })
}

/// The potential of a conducting foundation or tip (`None` on an insulating one): prescribed
/// (the boundary's: a path's instant scales it by its voltage factor), or, floating with a
/// given charge, found: that of a point it presses.
fn conductor_potential(c: &crate::ContactSpec, b: &ContactBoundary, sol: &ContactSolution) -> Option<f64> {
    match (c.charge, sol.electric.as_ref()) {
        (Some(_), Some(e)) => e
            .points
            .iter()
            .zip(&e.potential)
            .filter(|&(&i, _)| sol.lambda.normal[i] > 0.0)
            .map(|(_, &v)| v)
            .next(),
        _ => c.electric_law().and(b.electric.as_ref().map(|(e, _)| e.potential)),
    }
}

/// The terminals: the groups where the potential is prescribed or floats (none without
/// electric unknowns), each once, in the order of the conditions.
pub fn terminal_groups(setup: &Setup) -> Vec<&str> {
    let mut groups: Vec<&str> = vec![];
    if !setup.plan.electric {
        return groups;
    }
    for c in setup
        .constraints
        .iter()
        .filter(|c| matches!(c.field, fe_assembly::Field::Potential | fe_assembly::Field::Floating))
    {
        if !groups.contains(&c.group.as_str()) {
            groups.push(&c.group);
        }
    }
    groups
}

/// The terminals (the groups where the potential is prescribed or floats), each with its
/// potential and the charge through it (none without electric unknowns).
pub(crate) fn terminals(
    setup: &Setup,
    disc: &Discretization<'_>,
    u: &[[f64; 3]],
    phi: &[f64],
) -> Result<Vec<crate::report::TerminalReport>, ProblemError> {
    let groups = terminal_groups(setup);
    if groups.is_empty() {
        return Ok(vec![]);
    }
    let charges = disc.charges(u, phi, &groups, &setup.loads)?;
    let mut out = vec![];
    for (group, charge) in groups.iter().zip(charges) {
        let facets = setup.mesh.boundary(group).map_err(fe_assembly::AssemblyError::from)?;
        let first = facets.nodes();
        let ranged = setup.ranged_electrodes.iter().any(|e| e == group);
        out.push(crate::report::TerminalReport {
            group: group.to_string(),
            potential: first.first().map_or(0.0, |&v| phi[v]),
            charge,
            floating: disc.dofs.floating.iter().any(|(g, _)| g == group),
            covered_x: ranged.then(|| crate::setup::x_extent(&setup.mesh, facets)),
        });
    }
    Ok(out)
}

/// What the run measured beside the recovered fields, for its report.
pub(crate) struct Measured<'a> {
    pub(crate) info: Option<&'a contact::ContactInfo>,
    pub(crate) pcg_iters: usize,
    pub(crate) equilibrium: f64,
    pub(crate) timings_s: Timings,
    pub(crate) figures: Figures,
    /// Steps of the bed's fixed point ([`crate::bed`]).
    pub(crate) bed_steps: usize,
}

/// The typed report of the run, whichever backend solved it.
pub(crate) fn report(posed: &Posed<'_>, m: Measured<'_>, r: &Recovered) -> RunReport {
    let (scene, plan) = (posed.scene.scene(), posed.plan());
    let (info, equilibrium, figures) = (m.info, m.equilibrium, m.figures);
    RunReport {
        scene: SceneReport::of(scene),
        plan: plan.clone(),
        mesh: MeshReport::of(scene, posed.setup),
        dofs: DofsReport {
            u: posed.disc.dofs.n_u,
            phi: posed.disc.dofs.n_phi,
        },
        contact: r.contact.clone(),
        exact: r.exact.clone(),
        iterations: Iterations {
            bed: m.bed_steps,
            ..Iterations::of(info, m.pcg_iters)
        },
        residuals: Residuals {
            equilibrium,
            complementarity: info.map_or(0.0, |i| i.complementarity),
            // under the tight rule a run of a backend held to its tolerances reaches here only
            // with every residual within them (check_accurate)
            converged_to_tolerance: plan.rule == Rule::Tight
                && equilibrium <= equilibrium_tol(plan)
                && info.is_none_or(|i| i.complementarity <= plan.tol),
        },
        timings_s: m.timings_s,
        memory: Memory {
            peak_bytes: 0,
            factor_bytes: figures.factor_bytes,
        },
        path: None,
        terminals: r.terminals.clone(),
        indenter: r.indenter.clone(),
        units: posed.setup.units.clone(),
        solver: SolverReport {
            strategy: plan.linear_strategy,
            rule: rule_in_words(plan.rule).into(),
            tol: plan.tol,
            pcg_rel_tol: figures.pcg_rel_tol,
            condense_route: figures.condense.map(|(route, _)| format!("{route:?}")),
            smallest_pivot_ratio: figures.smallest_pivot_ratio,
            factor_flops: figures.factor_rate.map(|r| r.0),
            factor_gflops: figures.factor_rate.filter(|r| r.1 > 0.0).map(|r| r.0 / r.1 / 1e9),
            refinement_steps: figures.refinement_steps,
            ..SolverReport::of(info)
        },
        petsc: figures.petsc,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{BackendChoice, ContactSpec, DirichletSpec, LoadSpec, MaterialSpec, MeshSpec};
    use crate::{solve, solve_within, Silent};
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
            load: Some(
                LoadSpec {
                    group: "top".into(),
                    p: -2.0,
                    direction: vec![0.0, 1.0],
                }
                .into(),
            ),
            electrode: None,
            contact: Some(contact.into()),
            solver: Default::default(),
            exact: None,
            path: None,
            units: None,
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
    fn a_path_is_a_run_of_the_backend_as_its_walk_is() {
        let mut scene = block(MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 8));
        scene.path = Some(crate::PathSpec {
            t: vec![0.0, 1.0],
            steps: Some(3),
            load: Some(vec![0.0, 1.0]),
            ..Default::default()
        });
        let ran = crate::run(&mut crate::SharedMemory, &scene, None, Limits::default(), &mut Silent)
            .unwrap()
            .unwrap();
        let walked = crate::solve_path(&scene, None, Limits::default(), &mut Silent, false, &mut |_| Ok(())).unwrap();
        let rows = |s: &Solution| {
            s.report
                .path
                .as_ref()
                .map(|p| p.rows.iter().map(|r| r.normal_force).collect::<Vec<_>>())
        };
        assert_eq!(rows(&ran).map(|r| r.len()), Some(4));
        assert_eq!(rows(&ran), rows(&walked.last));
        assert_eq!(ran.u, walked.last.u);
    }

    #[test]
    fn a_scene_for_another_backend_is_refused_not_solved_here() {
        let mut scene = block(MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 4));
        scene.solver.backend = BackendChoice::Petsc;
        let e = solve(&scene, None, &mut Silent).err().unwrap();
        assert!(
            matches!(&e, ProblemError::Unsupported(u) if u.backend == "faer" && u.key == "solver.backend"),
            "{e}"
        );
        assert!(e.to_string().contains("asks for the distributed backend"), "{e}");
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
