//! A load path on pieces: each instant of the scene's `[path]` solved in turn on the same
//! matrix (it does not change along the path), its right-hand side the parts of the loads and
//! of the prescribed values' lifting summed at the instant's factors
//! ([`problem::step_loads`], the default backend's own sum), its prescribed values scaled in
//! the dof map, its gaps scaled ([`ContactBoundary::at_factors`]), and friction solved on the
//! slip since the instant before (the active sets' history, `ContactRows::with_history`: the
//! tangential displacements of the instant before at each rank's own points, and its
//! multipliers to start from). Each instant's row (`path.csv`) is made of sums and maxima over
//! the ranks' own points ([`problem::step_row`] on each rank's points, then reduced): nothing
//! is gathered. The instants the path writes hand each rank's piece of their fields to the
//! caller, which writes them as they come.

use super::{agree, nodal, History, OnPiece, PieceContact, Run, Solved};
use crate::error::DistributedError;
use crate::krylov::KrylovFields;
use crate::system::System;
use contact::PointValues;
use fe_assembly::{CellFields, Discretization};
use mesh::MeshPiece;
use petsc::Vector;
use problem::backend::ContactBoundary;
use problem::report::{PathReport, StepRow};
use problem::{ContactResult, Event, Factors, ProblemError, Reporter};
use std::time::Instant;

/// One instant of a path on pieces, as every rank hands it to the caller.
pub struct PieceStep<'a> {
    /// The instant's row, the same on every rank (from sums over the ranks).
    pub row: &'a StepRow,
    /// This rank's piece of the instant's fields, at the instants the path writes.
    pub frame: Option<PieceFrame<'a>>,
}

/// A rank's piece of an instant's fields.
pub struct PieceFrame<'a> {
    /// The piece's mesh (own and ghost cells).
    pub mesh: &'a mesh::Mesh,
    /// The piece's cells' and nodes' owners and numbers in the whole mesh (its own mesh is
    /// `mesh`).
    pub piece: &'a MeshPiece,
    /// The displacement at each node of the piece.
    pub u: &'a [[f64; 3]],
    /// The potential at each node of the piece.
    pub phi: &'a [f64],
    /// The cells' fields, where the path asks for them (`path.cell_fields`).
    pub cells: Option<&'a CellFields>,
    /// The contact at every node of the piece's own cells.
    pub contact: &'a ContactResult,
}

/// What a path on pieces hands each instant to.
pub type EachStep<'a> = dyn FnMut(PieceStep<'_>) -> Result<(), DistributedError> + 'a;

/// What the walk leaves: the last instant's solution vector, the Krylov solves' figures over
/// the path, the last instant's contact, and the path's section of the report.
pub(super) struct Walked<'p> {
    pub(super) x: Vector<'p>,
    pub(super) solved: Solved,
    pub(super) contact: PieceContact,
    pub(super) path: PathReport,
}

/// The path's instants, each solved, reduced into its row and handed to `each` (collective:
/// every rank walks every instant, and a rank whose `each` fails stops them all). `disc`'s
/// prescribed values and `system`'s right-hand side are left at the last instant's.
pub(super) fn walk<'p>(
    on: &Run<'_, 'p>,
    disc: &mut Discretization<'_>,
    (system, fields): (&mut System<'p>, &KrylovFields),
    (limits, reporter): (problem::Limits, &mut dyn Reporter),
    each: &mut EachStep<'_>,
) -> Result<Walked<'p>, DistributedError> {
    let (petsc, scene) = (on.petsc, on.scene);
    let spec = scene.path.as_ref().ok_or_else(|| ProblemError::NoSolution {
        sought: "a path on pieces",
        why: "the scene has no [path]".into(),
    })?;
    let started = Instant::now();
    let instants = spec.instants();
    let parts = agree(
        petsc,
        disc.rhs_parts(&on.setup.loads).map_err(DistributedError::from),
        "assemble the parts of their loads",
    )?;
    let prescribed = disc.dofs.prescribed();
    let base = on.on(disc).boundary()?;
    let mut history = History::none(&base);
    // the slip each of this rank's points accumulated in contact (slip-weakening friction's
    // argument at the next instants), as the default backend's path adds it
    let mut slipped = vec![0.0; base.points.len()];
    let mut scale = OwnScale::default();
    let mut rows = Vec::with_capacity(instants.len());
    let mut solved = Solved {
        iterations: 0,
        reason: String::new(),
        options: String::new(),
        setup_seconds: 0.0,
    };
    let mut last = None;
    for (k, &t) in instants.iter().enumerate() {
        let f = spec.factors(t);
        disc.dofs.rescale(&prescribed, f.displacement, f.voltage);
        pose(on, disc, system, &parts, &f)?;
        let at = on.on(disc);
        let boundary = at_instant(&base, &f, &slipped);
        scale
            .check(petsc, &boundary, &history, system.load_norm, &on.setup.plan)
            .map_err(|e| e.at_step(k, t))?;
        let before = history.shift.clone();
        let (x, s, contact) = at
            .contact((system, fields), boundary, (history, f.load), limits, reporter)
            .map_err(|e| e.at_step(k, t))?;
        (solved.iterations, solved.setup_seconds) =
            (solved.iterations + s.iterations, solved.setup_seconds + s.setup_seconds);
        (solved.reason, solved.options) = (s.reason, s.options);
        let (u, phi) = nodal(&x, on.layout)?;
        let row = at.row((k, t, &f), &contact, &before, (&u, &phi))?;
        reporter.event(&Event::step_done(&row, instants.len() - 1, &on.setup.units));
        let written = spec.has_fields(k, instants.len());
        let frame_cells = (spec.cell_fields && written).then(|| disc.recover(&u, &phi));
        let frame = written.then(|| PieceFrame {
            mesh: disc.mesh,
            piece: on.piece,
            u: &u,
            phi: &phi,
            cells: frame_cells.as_ref(),
            contact: &contact.on_piece,
        });
        agree(
            petsc,
            each(PieceStep { row: &row, frame }),
            "hand on an instant of the path",
        )?;
        rows.push(row);
        scale.seen(petsc, &u, system.load_norm)?;
        add_slips(&mut slipped, &contact.solution, &before);
        history = History::after(&contact.solution, x);
        last = Some(contact);
    }
    let (Some(contact), Some(x)) = (last, history.x) else {
        return Err(ProblemError::NoSolution {
            sought: "a path on pieces",
            why: "the path has no instant".into(),
        }
        .into());
    };
    Ok(Walked {
        x,
        solved,
        contact,
        path: PathReport {
            instants: instants.len(),
            factorisations: 0,
            condensations: 0,
            steps_s: started.elapsed().as_secs_f64(),
            rows,
        },
    })
}

/// Sets `system`'s right-hand side to the instant of factors `f`: the parts of the loads
/// summed at `f` (`disc`'s prescribed values already scaled), the floating terminals' charges
/// scaled with the prescribed potentials, as the default backend's parts scale them.
/// Collective.
fn pose<'p>(
    on: &Run<'_, 'p>,
    disc: &Discretization<'_>,
    system: &mut System<'p>,
    parts: &fe_assembly::RhsParts,
    f: &problem::Factors,
) -> Result<(), DistributedError> {
    let loads = agree(
        on.petsc,
        problem::step_loads(parts, f, on.scene).map_err(DistributedError::from),
        "scale their loads",
    )?;
    let charges = on.floating.charges(f.voltage);
    system.set_loads(on.petsc, disc, on.layout, (&loads.b_u, &loads.b_phi, &charges))?;
    // (as the run's first loads: finite one by one, their squares may overflow)
    ProblemError::check_finite(&[system.load_norm], "the norm of the loads", on.scene)?;
    Ok(())
}

/// The displacement an instant's own data make, told from the instants solved: the body's
/// largest displacement at the instant of the largest loads so far, in proportion to the
/// instant's loads (`K` is the same along the path), for the check that friction's history
/// does not drown an instant in round-off ([`problem::check_history_scales`], the default
/// backend's, which tells the scale from the parts' responses at the points instead). The
/// body's, not the points': where every point sticks from the first instant on, the points do
/// not move however the body deforms, and a scale of zero refused every instant after a slip.
#[derive(Default)]
struct OwnScale {
    /// The largest load norm so far, and the body's largest displacement then.
    peak: Option<(f64, f64)>,
}

impl OwnScale {
    /// Refuses (every rank alike) an instant that the history drowns: with friction, its own
    /// displacement (its loads' share of the peak's, or how far its gaps press in) at most
    /// `tol / ε` times smaller than the history's. Collective.
    fn check(
        &self,
        petsc: &petsc::Petsc,
        boundary: &ContactBoundary,
        history: &History<'_>,
        load_norm: f64,
        plan: &problem::Plan,
    ) -> Result<(), DistributedError> {
        if plan.n_tangential() == 0 {
            return Ok(());
        }
        let carried = history.shift.tangential.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let pressed = boundary.points.gap.iter().fold(0.0f64, |m, g| m.max(-g));
        let most = petsc.max(&[carried, pressed])?;
        let loaded = self
            .peak
            .map_or(0.0, |(load, u)| if load > 0.0 { u * load_norm / load } else { 0.0 });
        problem::check_history_scales(most[0], loaded.max(most[1]), plan).map_err(DistributedError::from)
    }

    /// Takes in the solved instant of `load_norm` (its displacements `u` at the piece's
    /// nodes): the peak where its loads are the largest. Collective.
    fn seen(&mut self, petsc: &petsc::Petsc, u: &[[f64; 3]], load_norm: f64) -> Result<(), DistributedError> {
        let own = u.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let u = petsc.max(&[own])?[0];
        if self.peak.is_none_or(|(load, _)| load_norm > load) {
            self.peak = Some((load_norm, u));
        }
        Ok(())
    }
}

/// This rank's points at an instant of factors `f`: the gaps scaled, and where friction
/// weakens, the slip each accumulated before it.
fn at_instant(base: &ContactBoundary, f: &Factors, slipped: &[f64]) -> ContactBoundary {
    let mut boundary = base.at_factors(f.gap, f.displacement, f.voltage);
    if boundary.points.weakens() {
        boundary.points.slipped = slipped.to_vec();
    }
    boundary
}

/// Adds to each of this rank's points that touch at the instant of `sol` the length of its
/// tangential increment from `before` (friction's frame at the instant before): the slip
/// accumulated in contact, slip-weakening friction's argument, as the default backend's path
/// adds it.
fn add_slips(slipped: &mut [f64], sol: &contact::ContactSolution, before: &PointValues) {
    for (i, s) in slipped.iter_mut().enumerate() {
        if sol.status[i] != contact::Status::Separated {
            let (now, then) = (sol.u.tangential_of(i), before.tangential_of(i));
            *s += now.iter().zip(then).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
        }
    }
}

impl<'p> History<'p> {
    /// What the instant after `sol` (its solution vector `x`, kept as the path's last) starts from: friction's frame
    /// where the points are now; their normal multipliers, the tangential ones zero: every point
    /// that presses is held where it is, and its reaction judges it (friction's elastic
    /// predictor; from the tangential multipliers too, a slipping point's `z_t` lies on the
    /// disc's edge, where the slip's spring across the direction is infinitely stiff).
    fn after(sol: &contact::ContactSolution, x: Vector<'p>) -> Self {
        let (n, nt) = (sol.lambda.normal.len(), sol.u.n_tangential());
        let mut shift = PointValues::zeros(n, nt);
        shift.tangential.clone_from(&sol.u.tangential);
        let mut pressed = PointValues::zeros(n, nt);
        pressed.normal.clone_from(&sol.lambda.normal);
        History {
            shift,
            lambda: Some(pressed),
            x: Some(x),
        }
    }
}

impl OnPiece<'_, '_> {
    /// The instant's row, the same on every rank: each rank's row of its own points
    /// ([`problem::step_row`]) summed (forces, counts) and maximised (slips, an indenter's
    /// contact radius), the terminals' charges and potentials summed over the owned nodes, the
    /// equilibrium residual of the instant. Collective.
    fn row(
        &self,
        (k, t, f): (usize, f64, &Factors),
        contact: &PieceContact,
        before: &PointValues,
        (u, phi): (&[[f64; 3]], &[f64]),
    ) -> Result<StepRow, DistributedError> {
        let petsc = self.petsc;
        let (boundary, sol) = (&contact.boundary, &contact.solution);
        let mut row = problem::step_row(k, t, f, boundary, sol, &sol.u, before);
        let dim = row.tangential_resultant.len();
        // the indenter's depth (the same at each of its points) and contact radius
        let at = problem::Indented {
            points: &boundary.points,
            group_of: &boundary.group_of,
            sol,
            potential: None,
        };
        let indenter = problem::indenter_figures(self.scene, false, at, &|_| 0.0, f);
        let has_indenter = indenter.as_ref().map_or(0.0, |_| 1.0);
        let mut sums = vec![
            row.normal_force,
            row.n_stick as f64,
            row.n_slip as f64,
            row.n_separated as f64,
            has_indenter,
        ];
        sums.extend(&row.tangential_resultant);
        // several zones: each one's counts and forces, summed too
        let per_group = 5 + dim;
        for g in &row.groups {
            sums.extend([g.n_points, g.n_stick, g.n_slip, g.n_separated].map(|c| c as f64));
            sums.push(g.normal_force);
            sums.extend(&g.tangential_resultant);
        }
        let sums = petsc.sum(&sums)?;
        for (g, s) in row.groups.iter_mut().zip(sums[5 + dim..].chunks(per_group)) {
            (g.n_points, g.n_stick, g.n_slip, g.n_separated) =
                (s[0] as usize, s[1] as usize, s[2] as usize, s[3] as usize);
            g.normal_force = s[4];
            g.tangential_resultant = s[5..].to_vec();
            g.tangential_force = g.tangential_resultant.iter().map(|x| x * x).sum::<f64>().sqrt();
        }
        let depth = indenter.as_ref().map_or(f64::NEG_INFINITY, |i| i.depth);
        let radius = indenter.as_ref().map_or(f64::NEG_INFINITY, |i| i.contact_radius);
        let maxima = petsc.max(&[row.max_slip, row.max_slip_increment, depth, radius])?;
        row.normal_force = sums[0];
        (row.n_stick, row.n_slip, row.n_separated) = (sums[1] as usize, sums[2] as usize, sums[3] as usize);
        row.tangential_resultant = sums[5..5 + dim].to_vec();
        row.tangential_force = row.tangential_resultant.iter().map(|x| x * x).sum::<f64>().sqrt();
        // (without friction the plan has no tangential unknowns, and the default backend's
        // rows no slips: the same here, where the points carry their tangents regardless)
        if self.setup.plan.n_tangential() > 0 {
            (row.max_slip, row.max_slip_increment) = (maxima[0], maxima[1]);
        } else {
            (row.max_slip, row.max_slip_increment) = (0.0, 0.0);
        }
        if sums[4] > 0.0 {
            (row.depth, row.contact_radius) = (Some(maxima[2]), Some(maxima[3]));
        }
        (row.charges, row.potentials) = self
            .run
            .shares(self.disc)
            .terminals(u, phi)?
            .into_iter()
            .map(|t| (t.charge, t.potential))
            .unzip();
        row.equilibrium = Some(contact.equilibrium);
        Ok(row)
    }
}
