//! Force control: an indenter pressed with a given force, its depth the unknown. The force is a
//! continuous, nondecreasing function of how far the gaps are lowered (`s`), 0 while the body
//! is clear of the indenter; [`solve_force_controlled`] finds the `s` that carries the force
//! by the bracketed search of [`crate::outer`] around any contact solve.

use crate::outer::{bracketed_root, Evaluation, Found, Search, SearchError};
use crate::{ContactPoints, ContactSolution, PointValues};

/// Relative tolerance on the force.
pub const FORCE_TOL: f64 = 1e-10;

/// The contact solves the search may take.
const MAX_SOLVES: usize = 200;

/// Why the depth was not found.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ForceError<E> {
    /// A contact solve at some depth failed.
    #[error(transparent)]
    Solve(E),
    /// No depth within reach carries the force.
    #[error(
        "no depth within a million face sizes carries the force {force:e} (the body carries {most:e} at most there)"
    )]
    Unreachable {
        /// The force asked for.
        force: f64,
        /// The largest force carried at the depths tried.
        most: f64,
    },
    /// The search did not close in 200 contact solves.
    #[error("the depth that carries the force {force:e} was not found in {MAX_SOLVES} contact solves")]
    NotFound {
        /// The force asked for.
        force: f64,
    },
}

impl<E> ForceError<E> {
    /// The failed contact solve's own error (`Ok`), or the search's failure in words (`Err`):
    /// for a caller whose solve's error is not [`std::fmt::Display`].
    pub fn into_solve(self) -> Result<E, String> {
        type Search = ForceError<std::convert::Infallible>;
        match self {
            ForceError::Solve(e) => Ok(e),
            ForceError::Unreachable { force, most } => Err(Search::Unreachable { force, most }.to_string()),
            ForceError::NotFound { force } => Err(Search::NotFound { force }.to_string()),
        }
    }
}

/// The depth at which the body carries `force` (`Σ w_i λ_n,i` over the indenter's points:
/// `driven`, or every point where `None`) from the indenter: each evaluation a contact solve
/// (`solve`, on the points with the indenter's gaps lowered by `s`, the others' as they are,
/// from the last multipliers, the first from `start`); the search's steps up start at first touch and
/// grow fourfold from a millionth of the face's size, then regula falsi (Illinois) closes on the
/// depth. A zero force (a path's load factor at 0) is met with the indenter just touching
/// (every shallower depth carries none too). The caller's solve must take Newton steps from a
/// start that already meets its tolerance (its force must be this depth's). Leaves the points
/// with the gaps of the depth found, and returns its solution.
///
/// # Errors
/// [`ForceError`]: a solve's own error, no depth within a million face sizes, or no depth in
/// 200 contact solves.
pub fn solve_force_controlled<E>(
    points: &mut ContactPoints,
    driven: Option<&[bool]>,
    force: f64,
    start: Option<PointValues>,
    solve: impl FnMut(&ContactPoints, Option<PointValues>) -> Result<ContactSolution, E>,
) -> Result<ContactSolution, ForceError<E>> {
    solve_force_controlled_spread(points, driven, force, start, solve, |_, x| Ok(x))
}

/// How [`solve_force_controlled_spread`] combines a value of its points with the other
/// processes' where the points are spread over several (each process its own points and its
/// own contact solve of them, the search the same on every one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spread {
    /// The sum over the processes (the force carried).
    Sum,
    /// The smallest (the nearest gap, the face's lower bounds).
    Min,
    /// The largest (the face's upper bounds).
    Max,
}

/// [`solve_force_controlled`] on points spread over several processes: `points` and the
/// solutions are this process's, and `combine(how, x)` gives the combination of this
/// process's `x` with the others' (collective: every process calls it in the same order), so
/// that the force, the first touch and the face's size, and so the search's every step, are
/// those of all the points together.
///
/// # Errors
/// As [`solve_force_controlled`]; `combine`'s error as a solve's.
pub fn solve_force_controlled_spread<E>(
    points: &mut ContactPoints,
    driven: Option<&[bool]>,
    force: f64,
    start: Option<PointValues>,
    mut solve: impl FnMut(&ContactPoints, Option<PointValues>) -> Result<ContactSolution, E>,
    mut combine: impl FnMut(Spread, f64) -> Result<f64, E>,
) -> Result<ContactSolution, ForceError<E>> {
    let base = points.gap.clone();
    let drives = |i: usize| driven.is_none_or(|d| d.get(i).copied().unwrap_or(false));
    let size = face_size(points, &mut combine).map_err(ForceError::Solve)?;
    let touch = (0..base.len())
        .filter(|&i| drives(i))
        .map(|i| base[i])
        .fold(f64::INFINITY, f64::min);
    let touch = combine(Spread::Min, touch).map_err(ForceError::Solve)?;
    let mut last = start;
    // the largest force carried so far (`f - force` loses `f` when the force asked is huge)
    let mut most = 0.0f64;
    let mut eval = |s: f64, points: &mut ContactPoints| -> Result<Evaluation<ContactSolution>, E> {
        lower(points, &base, s, &drives);
        let sol = solve(points, last.take())?;
        last = Some(sol.lambda.clone());
        let own = sol
            .lambda
            .normal
            .iter()
            .zip(&points.weight)
            .enumerate()
            .filter(|&(i, _)| drives(i))
            .map(|(_, (l, w))| l * w)
            .sum::<f64>();
        let f = combine(Spread::Sum, own)?;
        most = most.max(f);
        Ok(Evaluation {
            residual: f - force,
            slope: None,
            met: (f - force).abs() <= FORCE_TOL * force,
            value: sol,
        })
    };
    if force == 0.0 {
        // every depth short of first touch carries no force: the indenter just touching
        return eval(touch, points).map(|e| e.value).map_err(ForceError::Solve);
    }
    let search = Search {
        start: 0.0,
        // the body clear of the indenter: the first step up reaches the nearest point
        up_from: touch.max(0.0),
        first_step: size * 1e-6,
        max_step: 1e6 * size,
        closed: 4.0 * f64::EPSILON,
        floor: size * 1e-12 * 4.0 * f64::EPSILON,
        max_evals: MAX_SOLVES,
    };
    let found = bracketed_root(&search, |s| eval(s, points));
    let (s, sol) = match found {
        Ok(Found::Root { s, at }) => (s, at.value),
        // a continuous force: the bracket closes at the depth to round-off; the nearer end
        Ok(Found::Jump { below, above }) => {
            if below.1.residual.abs() < above.1.residual.abs() {
                (below.0, below.1.value)
            } else {
                (above.0, above.1.value)
            }
        }
        Err(SearchError::Eval(e)) => return Err(ForceError::Solve(e)),
        Err(SearchError::NoBracket) => return Err(ForceError::Unreachable { force, most }),
        Err(SearchError::NotFound) => return Err(ForceError::NotFound { force }),
    };
    lower(points, &base, s, &drives);
    Ok(sol)
}

/// The gaps of the points the indenter drives lowered by the depth `s` from `base`.
fn lower(points: &mut ContactPoints, base: &[f64], s: f64, drives: &dyn Fn(usize) -> bool) {
    for (i, (g, b)) in points.gap.iter_mut().zip(base).enumerate() {
        if drives(i) {
            *g = b - s;
        }
    }
}

/// The largest extent of the contact points along any axis (the scale of the search's steps).
fn face_size<E>(points: &ContactPoints, combine: &mut impl FnMut(Spread, f64) -> Result<f64, E>) -> Result<f64, E> {
    let mut size = f64::MIN_POSITIVE;
    for k in 0..3 {
        let (lo, hi) = points
            .position
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x[k]), hi.max(x[k]))
            });
        let (lo, hi) = (combine(Spread::Min, lo)?, combine(Spread::Max, hi)?);
        size = size.max(hi - lo);
    }
    Ok(size)
}
