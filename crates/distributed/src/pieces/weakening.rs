//! Slip-weakening friction on pieces: the contact crate's fixed point on the coefficients
//! (`contact::solve_slip_weakening`), each step Coulomb's law with the coefficients frozen, run
//! around the active sets, its coefficients spread over the ranks as their points are. The
//! steps are mixed by the contact crate's mixing (`contact::Anderson`, Anderson's type II),
//! its inner products summed over the ranks so that every rank takes the same mixing. The contact crate's Newton on the law itself, which needs the whole
//! compliance, is not used: a law whose mixed fixed point does not settle is told by name.

use crate::contact::ContactOutcome;
use crate::error::DistributedError;
use contact::{ContactPoints, PointValues};
use petsc::{Petsc, PetscError, Vector};
use problem::ProblemError;

/// Steps of the fixed point at most.
const MAX_STEPS: usize = 200;

/// Slip-weakening friction on the points `points`: from the coefficients at the slip before
/// this problem (the static ones in a static run; a path's earlier slip in
/// [`ContactPoints::slipped`]), each step `solve`
/// (Coulomb's law with the coefficients frozen, from the last step's multipliers and
/// solution), the next coefficients those at its slips, mixed and kept within each law's
/// range (each at the slip before plus this problem's, `u` less `shift`), until no
/// coefficient moves by more than `tol` of the largest static one between a
/// step's and its slips' (over the ranks). Returns the last step's outcome, whose coefficients
/// are then those of its slips to that tolerance, with the fixed point's steps and every
/// step's active-set steps counted. Collective.
///
/// # Errors
/// `solve`'s; [`ProblemError::NoSolution`] keyed `contact.friction_law` where the fixed point
/// does not settle in [`MAX_STEPS`] steps.
pub(super) fn weakened<'p>(
    petsc: &Petsc,
    (points, shift): (&ContactPoints, &PointValues),
    (mut start, mut warm): (Option<PointValues>, Option<Vector<'p>>),
    tol: f64,
    solve: &mut impl FnMut(
        &ContactPoints,
        Option<PointValues>,
        Option<Vector<'p>>,
    ) -> Result<ContactOutcome<'p>, DistributedError>,
) -> Result<ContactOutcome<'p>, DistributedError> {
    // the coefficients at the slip before this problem (a path's earlier instants; the static
    // ones in a static run), and the largest static coefficient, the change's scale
    let mut at = points.clone();
    at.friction = points.coefficients_at(&PointValues::zeros(points.len(), points.n_tangential()));
    let most = points
        .weakening
        .iter()
        .flatten()
        .fold(f64::MIN_POSITIVE, |m, w| m.max(w.static_coefficient));
    let scale = petsc.max(&[most])?[0];
    let mut mixing = contact::Anderson::new(contact::ANDERSON_DEPTH);
    let (mut change, mut steps) = (f64::INFINITY, 0);
    for k in 1..=MAX_STEPS {
        let mut out = solve(&at, start.take(), warm.take())?;
        steps += out.solution.info.newton_iters;
        let next = at.coefficients_at(&increments(&out.solution.u, shift));
        let own = next
            .iter()
            .zip(&at.friction)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        change = petsc.max(&[own])?[0];
        if change <= tol * scale {
            out.solution.info.fixed_point_iters = k;
            out.solution.info.newton_iters = steps;
            return Ok(out);
        }
        // (the mixing's inner products summed over the ranks: every rank mixes alike)
        at.friction = mixing.step_spread(&at.friction, &next, |products| {
            let sums = petsc.sum(products)?;
            products.copy_from_slice(&sums);
            Ok::<_, PetscError>(())
        })?;
        for (i, m) in at.friction.iter_mut().enumerate() {
            *m = match points.weakening_of(i) {
                Some(w) => m.clamp(w.dynamic_coefficient, w.static_coefficient),
                None => points.friction[i],
            };
        }
        start = Some(out.solution.lambda);
        warm = Some(out.x);
    }
    Err(ProblemError::NoSolution {
        sought: "contact.friction_law",
        why: format!(
            "the fixed point on the slip-weakening coefficients did not settle in {MAX_STEPS} steps (the last moved a coefficient by {change:.3e}); the default backend's Newton on the law itself may"
        ),
    }
    .into())
}

/// The tangential displacements `u` less friction's frame `shift` (a path's instant before;
/// zero in a static run): the slip of this problem, the coefficient's argument beside the
/// slip before it.
pub(super) fn increments(u: &PointValues, shift: &PointValues) -> PointValues {
    let mut slip = u.clone();
    for (v, s) in slip.tangential.iter_mut().zip(&shift.tangential) {
        *v -= s;
    }
    slip
}
