//! The outer unknowns of a contact solve, found around any backend's solve at given data: an
//! indenter's depth under force control and a floating conducting tip's potential
//! ([`contact::solve_force_controlled`], [`contact::solve_floating`]: one bracketed scalar
//! search), their failures a [`ProblemError::NoSolution`] keyed by what was sought.

use crate::boundary::ContactBoundary;
use crate::scene::{Control, Obstacle, Scene};
use crate::ProblemError;
use contact::{ContactPoints, ContactSolution, PointValues};

/// A force-controlled indenter (`contact.indenter.force`): the force it presses with, and its
/// own points among the boundary's (`None` where the boundary is its zone alone; the other
/// zones rest on foundations, their gaps as they are).
pub struct ForceControl {
    /// The force, in the scene's units (a path scales it by its load factor).
    pub force: f64,
    /// Whether each point of the boundary is the indenter's.
    pub driven: Option<Vec<bool>>,
}

impl ForceControl {
    /// The scene's force-controlled indenter on `boundary`, if it has one.
    pub fn of(scene: &Scene, boundary: &ContactBoundary) -> Option<ForceControl> {
        let (k, c) = scene.indenter_contact()?;
        let Obstacle::Indenter {
            control: Control::Force(force),
            ..
        } = c.model()?.obstacle
        else {
            return None;
        };
        let driven = (boundary.groups.len() > 1).then(|| boundary.group_of.iter().map(|&g| g == k).collect());
        Some(ForceControl { force, driven })
    }

    /// The search's failure as the caller's error: a contact solve's own, or no solution keyed
    /// `contact.indenter.force` where no depth carries the force.
    pub fn failed<E: From<ProblemError>>(e: contact::ForceError<E>) -> E {
        e.into_solve().unwrap_or_else(|why| {
            ProblemError::NoSolution {
                sought: "contact.indenter.force",
                why,
            }
            .into()
        })
    }
}

/// Force control (`contact.indenter.force`): [`contact::solve_force_controlled`] around the
/// contact solve `solve`, the indenter's points of `control` driven to carry `force`; where
/// no depth carries the force, no solution keyed `contact.indenter.force`.
pub(crate) fn force_controlled<E: From<ProblemError>>(
    points: &mut ContactPoints,
    control: &ForceControl,
    force: f64,
    start: Option<PointValues>,
    solve: impl FnMut(&ContactPoints, Option<PointValues>) -> Result<ContactSolution, E>,
) -> Result<ContactSolution, E> {
    contact::solve_force_controlled(points, control.driven.as_deref(), force, start, solve)
        .map_err(ForceControl::failed)
}

/// A floating conducting tip (`contact.charge`): [`contact::solve_floating`] around the
/// contact solve `newton`; where no potential carries the charge, no solution keyed
/// `contact.charge`.
pub(crate) fn floating_tip(
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
