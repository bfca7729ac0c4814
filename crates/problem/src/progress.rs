//! What a run tells its caller while it works: one [`Event`] per step done and per outer
//! iteration of the contact solve, through the [`Reporter`] trait. Each event knows the line it
//! prints ([`Event::line`]); a terminal may also draw a progress bar from the contact events.

use crate::plan::Plan;
use linalg::CondenseRoute;
use std::fmt;

/// A step of a run, done; or an iteration of its contact solve.
#[derive(Clone, Debug, PartialEq)]
pub enum Event<'a> {
    /// The plan is made.
    Planned(&'a Plan),
    /// The units of the run's numbers (and, where the materials' stiffness is no solid's in
    /// them, a note saying so).
    Units(&'a crate::Units),
    /// The mesh's checks noted something without refusing the mesh.
    MeshNotes(crate::setup::MeshNotes),
    /// Dirichlet conditions hold some nodes or directions of the contact group.
    ContactHeld {
        /// The group.
        group: &'a str,
        /// Contact points with a tangent held (no multiplier there).
        tangents: usize,
        /// Nodes whose normal displacement is prescribed: no contact points.
        nodes: usize,
        /// Those of them held past the gap, inside the foundation.
        inside: usize,
    },
    /// The blocks and loads are assembled.
    Assembled {
        /// Mesh nodes.
        n_nodes: usize,
        /// Mesh cells.
        n_cells: usize,
        /// Their kind, in words (`mesh::CellKind::name`).
        kind: &'static str,
        /// Largest cell diameter.
        h: f64,
        /// The unit of `h` (the scene's length unit).
        length: &'a str,
        /// Free displacement unknowns.
        n_u: usize,
        /// Free potential unknowns.
        n_phi: usize,
        /// Wall time (s).
        seconds: f64,
    },
    /// The factorisation of `K` begins: `watch` follows it (a progress bar reads it from
    /// another thread; it has no line of its own).
    Factoring {
        /// The factorisation's progress.
        watch: FactorWatch,
    },
    /// A path's plan: its instants, the ones whose fields it writes (`step-NNNN.vtu`), and what
    /// one such file holds before compression.
    PathPlan {
        /// Instants.
        instants: usize,
        /// Instants written.
        written: usize,
        /// Bytes of one written instant's arrays before compression: the mesh's, the nodal
        /// fields' and the contact's, the cells' fields where the path asks for them.
        step_bytes: f64,
    },
    /// The linear solver is factored.
    Factored {
        /// Wall time (s).
        seconds: f64,
    },
    /// A static run's contact problem holds only the points that can touch: those whose
    /// indenter's profile lies within `depths` depths of its tip (`crate::reach`).
    Reach {
        /// The points it holds.
        kept: usize,
        /// The points of the contact groups.
        of: usize,
        /// How many depths above the tip.
        depths: f64,
    },
    /// Points the contact problem left out would touch: the run is done again with all `of`.
    BeyondReach {
        /// How many.
        points: usize,
        /// The points of the contact groups.
        of: usize,
    },
    /// The contact compliance is formed.
    Condensed {
        /// Its size, `m x m`.
        m: usize,
        /// How.
        route: CondenseRoute,
        /// Wall time (s).
        seconds: f64,
    },
    /// A step of the fixed point that takes out the springs holding a body only its compliant
    /// bed holds (the run's `Bed`): the change of the springs' forces, relative to the
    /// loads.
    BedStep {
        /// The step, from 1.
        step: usize,
        /// The change.
        change: f64,
        /// The change below which the fixed point has settled.
        settled: f64,
    },
    /// An outer iteration of the contact solve, with the tolerance it aims at.
    Contact {
        /// The solver's progress line.
        progress: &'a contact::Progress,
        /// The tolerance of the solve.
        tol: f64,
    },
    /// The solve is done: `u`, `φ` and (with contact) the multipliers.
    Solved {
        /// Wall time of the solve (contact included), s.
        seconds: f64,
        /// PCG iterations, summed.
        pcg_iters: usize,
        /// The equilibrium residual of the final pair.
        equilibrium: f64,
    },
    /// Slip weakening's fixed point on the coefficients was not contractive on its way (its
    /// largest secant ratio at or above 1): the static problem may have several solutions,
    /// and the one found is the branch from the stick start.
    NotContractive {
        /// The largest secant ratio of the map.
        contraction: f64,
    },
    /// A step of a load path is solved: its row.
    PathStepDone {
        /// The row (`path.csv`'s).
        row: &'a crate::report::StepRow,
        /// The last step.
        of: usize,
        /// The unit of its forces (run.json's `units.quantities.force`).
        force: &'a str,
    },
    /// A step of a load path begins.
    PathStep {
        /// The step (0 for the path's first instant).
        step: usize,
        /// The last step.
        of: usize,
        /// Its instant.
        t: f64,
    },
    /// The Krylov solves of the PETSc backend are done.
    Krylov {
        /// Iterations, summed over the solves.
        iterations: usize,
        /// PETSc's reason for the last solve's stop.
        reason: &'a str,
        /// Building the preconditioners, s.
        setup_seconds: f64,
    },
    /// The error against the scene's exact solution.
    Exact {
        /// Which solution.
        kind: crate::scene::ExactKind,
        /// What the error measures.
        what: &'a str,
        /// The error.
        error: f64,
    },
}

/// `bytes` in kB, MB or GB (powers of 1000), three figures.
fn in_bytes(bytes: f64) -> String {
    let (value, unit) = match bytes {
        b if b >= 1e9 => (b / 1e9, "GB"),
        b if b >= 1e6 => (b / 1e6, "MB"),
        b => (b / 1e3, "kB"),
    };
    format!("{value:.3} {unit}")
}

impl<'a> Event<'a> {
    /// A path's plan ([`Event::PathPlan`]) on `mesh`: each written instant's file holds the
    /// mesh (its points, each cell's nodes, offset and type), the nodal `u`, `φ` and the
    /// contact's status, pressure, traction (3 components), gap and, with electrical contact,
    /// flux; with `cells`, the stress and strain (`nv` components each) and `D`, `E`.
    pub fn path_plan(
        (instants, written): (usize, usize),
        mesh: &mesh::Mesh,
        nv: usize,
        (flux, cells): (bool, bool),
    ) -> Self {
        let (n, c) = (mesh.n_nodes() as f64, mesh.n_cells() as f64);
        // u, φ and the contact's point data; with the cell fields on P2 cells, the same four
        // fields at the nodes too
        let at_nodes = cells && mesh.kind.order() == 2;
        let per_node = 3.0
            + 4.0
            + 6.0
            + if flux { 1.0 } else { 0.0 }
            + if at_nodes { (2 * nv + 2 * mesh.dim) as f64 } else { 0.0 };
        let per_cell = (mesh.kind.n_nodes() + 1) as f64 * 8.0 + 1.0;
        let fields = if cells {
            (2 * nv + 2 * mesh.dim) as f64 * 8.0
        } else {
            0.0
        };
        Event::PathPlan {
            instants,
            written,
            step_bytes: 8.0 * per_node * n + (per_cell + fields) * c,
        }
    }

    /// The event that ends assembly: the mesh's (in its scene's length unit) and the dofs'
    /// sizes, and the time taken.
    pub fn assembled(setup: &'a crate::setup::Setup, dofs: &fe_assembly::DofMap, seconds: f64) -> Self {
        let (mesh, length) = (&setup.mesh, &setup.units.length);
        Event::Assembled {
            n_nodes: mesh.n_nodes(),
            n_cells: mesh.n_cells(),
            kind: mesh.kind.name(),
            h: mesh.h_max(),
            length,
            n_u: dofs.n_u,
            n_phi: dofs.n_phi,
            seconds,
        }
    }

    /// A path's step `row` of the steps to `of` solved, its forces in `units`.
    pub fn step_done(row: &'a crate::report::StepRow, of: usize, units: &'a crate::Units) -> Self {
        Event::PathStepDone {
            row,
            of,
            force: units.of_quantity("force"),
        }
    }

    /// The line the event prints, `None` for the first-order steps between the 500s (they
    /// report every 50 steps, for a progress bar).
    pub fn line(&self) -> Option<String> {
        match self {
            Event::Contact { progress: p, .. } if p.stage == contact::Stage::Uzawa && p.iter % 500 != 0 => None,
            Event::Factoring { .. } => None,
            _ => Some(self.to_string()),
        }
    }

    /// The fraction of the contact solve done, on a log scale from `first` (the first residual
    /// seen) down to the tolerance: for a progress bar.
    pub fn contact_fraction(&self, first: f64) -> Option<f64> {
        let Event::Contact { progress: p, tol } = self else {
            return None;
        };
        if !(p.residual > 0.0) {
            return None;
        }
        let r0 = first.max(tol * 10.0);
        Some(((r0 / p.residual).ln() / (r0 / tol).ln()).clamp(0.0, 1.0))
    }
}

impl Event<'_> {
    /// The line of an event of the contact solve: the points it holds, its compliance, its
    /// iterations.
    fn fmt_contact(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Event::Reach { kept, of, depths } => write!(
                f,
                "contact: {kept} of {of} points can touch (the indenter's profile within {depths} depths of its tip): the contact problem and its progress lines hold those, the rest are checked open after the solve"
            ),
            Event::BeyondReach { points, of } => write!(
                f,
                "contact: {points} points left out of the contact problem would touch: solving again with all {of}"
            ),
            Event::Condensed { m, route, seconds } => write!(
                f,
                "condensed the contact compliance ({m} x {m}, {route:?}) in {seconds:.3} s"
            ),
            Event::Contact { progress: p, .. } if p.stage == contact::Stage::Fallback => write!(
                f,
                "semismooth Newton and its proximal stage stalled after {} steps (best residual {:.3e}): the last stage (block Gauss-Seidel for Coulomb's law, the accelerated gradient otherwise) takes over from the best multipliers (run.json: iterations.newton_fallback)",
                p.iter, p.residual
            ),
            Event::Contact { progress: p, .. } => write!(
                f,
                "{:>11} {:>6}: residual {:.3e}, stick {}, slip {}, separated {}",
                p.stage.name(),
                p.iter,
                p.residual,
                p.counts.0,
                p.counts.1,
                p.counts.2
            ),
            _ => Ok(()),
        }
    }
}

impl fmt::Display for Event<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Event::Planned(plan) => write!(f, "{plan}"),
            Event::Units(units) => match &units.note {
                Some(note) => write!(f, "{units}\nnote: {note}"),
                None => write!(f, "{units}"),
            },
            Event::MeshNotes(n) => write!(f, "note: {}", mesh_notes(n).join("; ")),
            Event::ContactHeld {
                group,
                tangents,
                nodes,
                inside,
            } => write!(
                f,
                "note: contact group `{group}`: {}",
                held_notes(*tangents, *nodes, *inside).join("; ")
            ),
            Event::Assembled {
                n_nodes,
                n_cells,
                kind,
                h,
                length,
                n_u,
                n_phi,
                seconds,
            } => write!(
                f,
                "mesh: {n_nodes} nodes, {n_cells} {kind} cells, h = {h:.4e} {length}; dofs: {n_u} u + {n_phi} phi; assembly {seconds:.3} s"
            ),
            Event::PathPlan {
                instants,
                written,
                step_bytes,
            } => write!(
                f,
                "path: {instants} instants, {written} written (step-NNNN.vtu): at most {} before compression, {} each (compressed: about a sixth to a half)",
                in_bytes(*step_bytes * *written as f64),
                in_bytes(*step_bytes)
            ),
            Event::Factoring { .. } => write!(f, "factorisation begins"),
            Event::Factored { seconds } => write!(f, "factorisation {seconds:.3} s"),
            Event::NotContractive { contraction } => write!(
                f,
                "note: the fixed point on the friction coefficients was not contractive on its way (largest ratio {contraction:.3}): the problem may have several solutions; this one is the branch from the stick start"
            ),
            Event::PathStepDone { row, of, force } => write!(
                f,
                "path step {}/{of}, t = {}: normal force {:.4e} {force}, tangential {:.4e} {force}; stick {}, slip {}, separated {}; {} iterations",
                row.step,
                instant(row.t),
                row.normal_force,
                row.tangential_force,
                row.n_stick,
                row.n_slip,
                row.n_separated,
                row.iterations
            ),
            Event::PathStep { step, of, t } => write!(f, "path step {step}/{of}: t = {}", instant(*t)),
            Event::BedStep { step, change, settled } => write!(
                f,
                "the bed's springs, step {step}: their forces changed by {change:.3e} of the loads (settled below {settled:.0e})"
            ),
            Event::Reach { .. } | Event::BeyondReach { .. } | Event::Condensed { .. } | Event::Contact { .. } => {
                self.fmt_contact(f)
            }
            Event::Solved {
                seconds,
                pcg_iters,
                equilibrium,
            } if *pcg_iters == 0 => write!(f, "solve {seconds:.3} s, equilibrium residual {equilibrium:.3e}"),
            Event::Solved {
                seconds,
                pcg_iters,
                equilibrium,
            } => write!(
                f,
                "solve {seconds:.3} s ({pcg_iters} PCG iterations), equilibrium residual {equilibrium:.3e}"
            ),
            Event::Krylov {
                iterations,
                reason,
                setup_seconds,
            } => write!(
                f,
                "Krylov: {iterations} iterations in all ({reason}), preconditioners built in {setup_seconds:.3} s"
            ),
            Event::Exact { kind, what, error } => write!(f, "exact ({kind}): {what} = {error:.4e}"),
        }
    }
}

impl crate::setup::MeshNotes {
    /// Whether there is nothing to say: the notes a run prints are none (a seam of no facets
    /// still knows its dimension, so a field-by-field comparison with the default would not do).
    pub fn is_empty(&self) -> bool {
        mesh_notes(self).is_empty()
    }
}

/// An instant of a path as a line prints it: to 10 significant digits, so that the tail of a
/// sum of binary fractions (2.9000000000000004 for 29 steps of 0.1) does not show.
pub fn instant(t: f64) -> f64 {
    format!("{t:.9e}").parse().unwrap_or(t)
}

/// The notes on a mesh that is read but unusual.
pub(crate) fn mesh_notes(n: &crate::setup::MeshNotes) -> Vec<String> {
    let mut notes = vec![];
    if n.reoriented_cells > 0 {
        notes.push(format!(
            "the mesh reader turned {} cells round (a surface written clockwise)",
            n.reoriented_cells
        ));
    }
    if n.coincident_nodes > 0 {
        notes.push(format!(
            "{} nodes lie at the coordinates of another node (a crack, or parts not merged)",
            n.coincident_nodes
        ));
    }
    if n.seam.facets > 0 {
        notes.push(format!(
            "{} boundary facets lie on other boundary facets, the sides of a seam of {} {:.4e} where the mesh's parts are not joined: the body is cut along it (a crack); join them (Gmsh: fragment the parts, BooleanFragments or Coherence) unless the cut is meant",
            n.seam.facets,
            if n.seam.dim == 3 { "area" } else { "length" },
            n.seam.size()
        ));
    }
    if n.curved_cells > 0 {
        notes.push(format!(
            "{} curved cells (edge nodes off their edges' midpoints): mapped through their nodes",
            n.curved_cells
        ));
    }
    if n.unused_nodes > 0 {
        notes.push(format!(
            "{} nodes belong to no cell (the centre of an arc, a point off the body): they carry no unknown",
            n.unused_nodes
        ));
    }
    for r in &n.staircase_regions {
        let span = |axes: &[[f64; 2]]| {
            axes.iter()
                .map(|[lo, hi]| format!("[{lo}, {hi}]"))
                .collect::<Vec<_>>()
                .join(" x ")
        };
        notes.push(format!(
            "mesh.region `{}`: its cells (those whose centroids lie in the box) span {} of the box {}: the mesh has no cell faces on the box's sides, so the region's boundary is a staircase about them (a mesh with nodes on them, or [[mesh.layer]] for layers, follows the box)",
            r.name,
            span(&r.covered),
            span(&r.asked)
        ));
    }
    for e in &n.narrowed_electrodes {
        notes.push(format!(
            "the electrode `{}` covers x in [{}, {}] of the x_range [{}, {}] asked: its facets are those wholly inside the range, and the mesh has no node at its ends (run.json: terminals' covered_x)",
            e.name, e.covered[0], e.covered[1], e.asked[0], e.asked[1]
        ));
    }
    notes
}

/// The notes on contact points where Dirichlet conditions hold some directions.
fn held_notes(tangents: usize, nodes: usize, inside: usize) -> Vec<String> {
    let mut notes = vec![];
    match tangents {
        0 => {}
        1 => notes.push("1 contact point has a tangent held by a Dirichlet condition (no friction force there: the support takes it)".into()),
        _ => notes.push(format!(
            "{tangents} contact points have a tangent held by a Dirichlet condition (no friction force there: the support takes it)"
        )),
    }
    match nodes {
        0 => {}
        1 => notes.push("1 node has its normal displacement prescribed and is left to its support".into()),
        _ => notes.push(format!(
            "{nodes} nodes have their normal displacement prescribed and are left to their supports"
        )),
    }
    if inside > 0 {
        notes.push(format!(
            "{inside} of them held past the gap, inside the foundation (the Dirichlet condition wins)"
        ));
    }
    notes
}

/// A handle to a factorisation's progress ([`linalg::FactorProgress`]), shared with whoever
/// draws it; two handles are equal where they follow the same factorisation.
#[derive(Clone, Debug, Default)]
pub struct FactorWatch(pub std::sync::Arc<linalg::FactorProgress>);

impl PartialEq for FactorWatch {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Receives the events of a run.
pub trait Reporter {
    /// One event, in the order the run makes them.
    fn event(&mut self, event: &Event<'_>);
}

/// A reporter that drops every event.
pub struct Silent;

impl Reporter for Silent {
    fn event(&mut self, _: &Event<'_>) {}
}

/// A reporter that passes each event's line (where it has one) to a closure.
pub struct Lines<F: FnMut(&str)>(pub F);

impl<F: FnMut(&str)> Reporter for Lines<F> {
    fn event(&mut self, event: &Event<'_>) {
        if let Some(line) = event.line() {
            (self.0)(&line)
        }
    }
}
