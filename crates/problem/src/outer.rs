//! The outer unknowns of a contact solve, found around any backend's solve at given data: an
//! indenter's depth under force control and a floating conducting tip's potential
//! ([`contact::solve_force_controlled`], [`contact::solve_floating`]: one bracketed scalar
//! search), their failures a [`ProblemError::NoSolution`] keyed by what was sought.

use crate::ProblemError;
use contact::{ContactPoints, ContactSolution, PointValues};

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
