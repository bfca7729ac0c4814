//! A floating ideal conductor: the foundation (a tip) whose potential `ψ` is not given but
//! found, so that it carries a given charge `Q` (`-Σ w_i q_i`, [`ElectricValues::charge`]).
//! One more unknown with its equation, solved around any contact solve at a given `ψ`
//! ([`solve_floating`]).
//!
//! The charge of the ideal conductor jumps where a point enters contact, since the point
//! brings its potential condition with it: between two members of the contact zone no `ψ`
//! carries `Q`. There the answer is the mixture of the two members at the jump that carries
//! `Q`: the contact edge lies between the entering node and the zone, the node carrying that
//! fraction of its flux (docs/theory.md, "A floating conducting indenter"). Its defect, the
//! entering node's flux while it is not yet pressed, shrinks with the mesh as the jump does.

use crate::outer::{bracketed_root, Evaluation, Found, Search, SearchError};
use crate::{ContactPoints, ContactSolution, ElectricContactProblem, ElectricValues, PointValues};

/// Relative tolerance on the charge.
pub const CHARGE_TOL: f64 = 1e-10;

/// The contact solves the search may take.
const MAX_SOLVES: usize = 100;

/// Why the floating conductor's potential was not found.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FloatingError<E> {
    /// A contact solve at some `ψ` failed.
    #[error(transparent)]
    Solve(E),
    /// The conductor touches the body nowhere at the potential tried.
    #[error("the floating conductor touches the body nowhere, so it carries no charge, and its charge was given as {charge:e}")]
    Untouched {
        /// The charge asked for.
        charge: f64,
    },
    /// The zone's compliance does not let the charge follow the potential.
    #[error("the contact zone's compliance is singular: its charge does not follow its potential")]
    Singular,
    /// The search did not find the potential in 100 contact solves.
    #[error("the potential of the floating conductor carrying the charge {charge:e} was not found in {MAX_SOLVES} contact solves")]
    NotFound {
        /// The charge asked for.
        charge: f64,
    },
}

/// The potential `ψ` at which `solve`'s contact solution carries `charge`: the bracketed
/// search of [`crate::outer`] on `ψ` (`problem.electric.potential`), each evaluation a contact
/// solve, with the derivative of the contact zone as found (its normal rows at their gaps, its
/// electric rows at `ψ`: `dQ/dψ = 1ᵀ S⁻¹ e` from the compliance's block `S` on those rows),
/// exact while the zone does not change. The start is the `ψ` `problem` carries. Where the
/// bracket closes on a jump of the charge, the mixture of its two ends that carries `charge`
/// (the module's documentation). Leaves `problem`'s potential at the `ψ` found.
///
/// # Errors
/// [`FloatingError`]: a solve's own error, a zone that touches nowhere or whose compliance is
/// singular, or no potential found in 100 contact solves.
pub fn solve_floating<E>(
    problem: &mut ElectricContactProblem,
    points: &ContactPoints,
    charge: f64,
    mut solve: impl FnMut(&ElectricContactProblem, &ContactPoints) -> Result<ContactSolution, E>,
) -> Result<ContactSolution, FloatingError<E>> {
    let search = Search {
        start: problem.electric.potential,
        up_from: problem.electric.potential,
        first_step: 0.0,
        max_step: 0.0,
        closed: 1e-12,
        floor: f64::MIN_POSITIVE,
        max_evals: MAX_SOLVES,
    };
    // the tolerance's scale: the charge asked, or the largest charge met on the way
    let mut scale = charge.abs();
    let found = bracketed_root(&search, |psi| {
        problem.electric.potential = psi;
        let sol = solve(problem, points).map_err(FloatingError::Solve)?;
        let Some(e) = sol.electric.as_ref() else {
            return Err(FloatingError::Untouched { charge });
        };
        let q = e.charge(&points.weight);
        scale = scale.max(q.abs());
        let met = (q - charge).abs() <= CHARGE_TOL * scale.max(f64::MIN_POSITIVE);
        let slope = if met {
            None
        } else {
            Some(charge_slope(problem, &sol, e, charge)?)
        };
        Ok(Evaluation {
            residual: q - charge,
            slope,
            met,
            value: sol,
        })
    });
    match found {
        Ok(Found::Root { s, at }) => {
            problem.electric.potential = s;
            Ok(at.value)
        }
        Ok(Found::Jump { below, above }) => Ok(mixture(problem, below, above, charge)),
        Err(SearchError::Eval(e)) => Err(e),
        Err(SearchError::NoBracket | SearchError::NotFound) => Err(FloatingError::NotFound { charge }),
    }
}

/// `dQ/dψ` of the zone of `sol`: its normal rows at their gaps and its electric rows at `ψ`,
/// `1ᵀ S⁻¹ e` with `S` the compliance's block on those rows.
fn charge_slope<E>(
    problem: &ElectricContactProblem,
    sol: &ContactSolution,
    e: &ElectricValues,
    charge: f64,
) -> Result<f64, FloatingError<E>> {
    let (n, m, o) = (problem.weight.len(), problem.m(), problem.order());
    let mut rows: Vec<usize> = (0..n).filter(|&i| sol.lambda.normal[i] > 0.0).collect();
    let first_electric = rows.len();
    rows.extend(
        e.points
            .iter()
            .enumerate()
            .filter(|&(_, &i)| sol.lambda.normal[i] > 0.0)
            .map(|(k, _)| m + k),
    );
    if rows.len() == first_electric {
        return Err(FloatingError::Untouched { charge });
    }
    let k = rows.len();
    let s = faer::Mat::<f64>::from_fn(k, k, |a, b| problem.compliance[rows[a] * o + rows[b]]);
    let mut y = faer::Mat::<f64>::from_fn(k, 1, |a, _| if a >= first_electric { 1.0 } else { 0.0 });
    let lu = s.partial_piv_lu();
    faer::linalg::solvers::SolveCore::solve_in_place_with_conj(&lu, faer::Conj::No, y.as_mut());
    Some((first_electric..k).map(|a| y[(a, 0)]).sum::<f64>())
        .filter(|d| d.is_finite() && *d > 0.0)
        .ok_or(FloatingError::Singular)
}

/// The mixture `(1 - θ) b + θ a` of the members at the two ends of a closed bracket (`b`
/// below the charge, `a` above, each with its potential and evaluation) that carries `charge`;
/// `problem`'s potential set to the mixture's.
fn mixture(
    problem: &mut ElectricContactProblem,
    (psi_b, b): (f64, Evaluation<ContactSolution>),
    (psi_a, a): (f64, Evaluation<ContactSolution>),
    charge: f64,
) -> ContactSolution {
    let (q_b, q_a) = (b.residual + charge, a.residual + charge);
    let (b, a) = (b.value, a.value);
    let theta = ((charge - q_b) / (q_a - q_b)).clamp(0.0, 1.0);
    let mix = |x: &[f64], y: &[f64]| -> Vec<f64> { x.iter().zip(y).map(|(x, y)| x + theta * (y - x)).collect() };
    let values = |x: &PointValues, y: &PointValues| {
        PointValues::from_parts(
            mix(&x.normal, &y.normal),
            mix(&x.tangential, &y.tangential),
            x.n_tangential(),
        )
        .expect("two solutions of one problem share their layout")
    };
    problem.electric.potential = psi_b + theta * (psi_a - psi_b);
    let electric = match (&b.electric, &a.electric) {
        (Some(eb), Some(ea)) => Some(ElectricValues {
            points: eb.points.clone(),
            flux: mix(&eb.flux, &ea.flux),
            potential: mix(&eb.potential, &ea.potential),
        }),
        _ => None,
    };
    let lambda = values(&b.lambda, &a.lambda);
    let mut info = b.info.clone();
    info.newton_iters += a.info.newton_iters;
    info.residual = b.info.residual.max(a.info.residual);
    info.complementarity = b.info.complementarity.max(a.info.complementarity);
    let status = if theta < 0.5 { b.status } else { a.status };
    ContactSolution {
        u: values(&b.u, &a.u),
        lambda,
        status,
        info,
        electric,
    }
}
