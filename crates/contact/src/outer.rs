//! One more unknown around a contact solve: a scalar `s` (an indenter's depth under force
//! control, a floating conductor's potential) with one more equation `r(s) = 0`, `r`
//! nondecreasing, each evaluation a contact solve at the data `s` gives. One bracketed solver,
//! [`bracketed_root`], finds it for every such unknown ([`crate::solve_floating`],
//! [`crate::solve_force_controlled`]); it knows nothing of what `s` means.
//!
//! The steps: Newton's where the evaluation gives the slope of `r` (exact while the contact
//! zone does not change), else regula falsi in its Illinois variant inside the bracket, and
//! before a bracket is known steps growing fourfold away from the start; a step that leaves the
//! bracket is replaced by bisection. `r` may jump (a point entering the zone brings a
//! condition with it): where the bracket closes without a root, the caller gets both ends.

/// One evaluation of `r` at `s`: its value, its slope where known, whether it meets the
/// caller's tolerance, and what the caller keeps (the contact solution).
#[derive(Clone, Debug)]
pub struct Evaluation<T> {
    /// `r(s)`.
    pub residual: f64,
    /// `r'(s)`, where the evaluation knows it (positive).
    pub slope: Option<f64>,
    /// Whether `r(s)` is zero to the caller's tolerance.
    pub met: bool,
    /// The caller's result at `s`.
    pub value: T,
}

/// Where [`bracketed_root`] starts and how far it may go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search {
    /// The first `s` evaluated.
    pub start: f64,
    /// Before a bracket is known and without a slope: steps up are taken from here (an
    /// indenter's depth at first touch, where every shallower depth carries no force), and
    /// down from `start`.
    pub up_from: f64,
    /// The first such step; each next one four times longer.
    pub first_step: f64,
    /// The longest such step before the search gives up.
    pub max_step: f64,
    /// The bracket is closed where its width is at most this much of its ends' size (and
    /// `floor`).
    pub closed: f64,
    /// The least width of a bracket told from zero.
    pub floor: f64,
    /// Evaluations at most.
    pub max_evals: usize,
}

/// What [`bracketed_root`] found.
#[derive(Debug)]
pub enum Found<T> {
    /// An `s` whose evaluation meets the tolerance.
    Root {
        /// The unknown.
        s: f64,
        /// Its evaluation.
        at: Evaluation<T>,
    },
    /// A bracket closed on a jump of `r` across zero: its two ends, below zero and above.
    Jump {
        /// The end below zero, `(s, evaluation)`.
        below: (f64, Evaluation<T>),
        /// The end above zero.
        above: (f64, Evaluation<T>),
    },
}

/// Why [`bracketed_root`] stopped without an answer.
#[derive(Debug)]
#[non_exhaustive]
pub enum SearchError<E> {
    /// An evaluation failed.
    Eval(E),
    /// No sign change of `r` within [`Search::max_step`] of the start.
    NoBracket,
    /// No root in [`Search::max_evals`] evaluations.
    NotFound,
}

/// The root of the nondecreasing `r` that `eval` evaluates, by the steps of the module's
/// documentation, from `search.start`.
///
/// # Errors
/// [`SearchError`]: an evaluation's own error, no bracket within reach, or no root in the
/// evaluations allowed.
pub fn bracketed_root<T, E>(
    search: &Search,
    mut eval: impl FnMut(f64) -> Result<Evaluation<T>, E>,
) -> Result<Found<T>, SearchError<E>> {
    let mut below: Option<(f64, Evaluation<T>)> = None;
    let mut above: Option<(f64, Evaluation<T>)> = None;
    // Illinois: the newest end (0 below, 1 above), whether the last step kept its sign (-1)
    // or changed it (1), and the ends' residual weights
    let (mut newest, mut side, mut weight) = (None, 0i8, [1.0f64; 2]);
    let mut step = search.first_step;
    let mut s = search.start;
    for _ in 0..search.max_evals {
        let at = eval(s).map_err(SearchError::Eval)?;
        if at.met {
            return Ok(Found::Root { s, at });
        }
        let (residual, slope) = (at.residual, at.slope);
        // Illinois: the end of the new point's sign moves; where that is the newest end's sign
        // for the second step running, the other end's residual is halved; where the sign
        // changed, the other end (the newest before) counts whole again
        let (moved, other) = if residual < 0.0 { (0, 1) } else { (1, 0) };
        if newest == Some(moved) {
            if side == -1 {
                weight[other] /= 2.0;
            }
            side = -1;
        } else {
            weight[other] = 1.0;
            side = 1;
        }
        (newest, weight[moved]) = (Some(moved), 1.0);
        if residual < 0.0 {
            below = Some((s, at));
        } else {
            above = Some((s, at));
        }
        let (lo, hi) = (
            below.as_ref().map_or(f64::NEG_INFINITY, |b| b.0),
            above.as_ref().map_or(f64::INFINITY, |a| a.0),
        );
        // closed: both ends known (a finite width) and as near as the numbers tell
        let closed = hi - lo <= (search.closed * lo.abs().max(hi.abs())).max(search.floor);
        (below, above) = match (below, above) {
            (Some(below), Some(above)) if closed => return Ok(Found::Jump { below, above }),
            ends => ends,
        };
        let next = match (slope, &below, &above) {
            (Some(d), _, _) if d > 0.0 && d.is_finite() => s - residual / d,
            (_, Some((lo, below)), Some((hi, above))) => {
                // regula falsi through the ends, written from the newest `b`
                let ends = [(*lo, below.residual * weight[0]), (*hi, above.residual * weight[1])];
                let newest = newest.unwrap_or(1);
                let ((a, ra), (b, rb)) = (ends[1 - newest], ends[newest]);
                b - rb * (b - a) / (rb - ra)
            }
            // no bracket, no slope: a step away from the side the residual is on
            _ => {
                if step > search.max_step {
                    return Err(SearchError::NoBracket);
                }
                let next = if residual < 0.0 {
                    search.up_from.max(search.start) + step
                } else {
                    search.start - step
                };
                step *= 4.0;
                next
            }
        };
        s = if next > lo && next < hi { next } else { 0.5 * (lo + hi) };
    }
    Err(SearchError::NotFound)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search(start: f64) -> Search {
        Search {
            start,
            up_from: start,
            first_step: 1e-6,
            max_step: 1e6,
            closed: 1e-14,
            floor: 1e-300,
            max_evals: 200,
        }
    }

    #[test]
    fn newton_with_a_slope_and_regula_falsi_without() {
        // r(s) = s³ + s - 10, root 2
        let r = |s: f64| s * s * s + s - 10.0;
        for slope in [true, false] {
            let mut evals = 0;
            let found = bracketed_root(&search(0.0), |s| {
                evals += 1;
                Ok::<_, ()>(Evaluation {
                    residual: r(s),
                    slope: slope.then_some(3.0 * s * s + 1.0),
                    met: r(s).abs() <= 1e-12,
                    value: (),
                })
            })
            .unwrap();
            let Found::Root { s, .. } = found else { panic!("a root") };
            assert!((s - 2.0).abs() < 1e-12, "slope {slope}: {s}");
            assert!(evals < 60, "slope {slope}: {evals} evaluations");
        }
    }

    #[test]
    fn a_jump_across_zero_gives_both_ends() {
        // r jumps from -1 to 1 at s = 0.3
        let found = bracketed_root(&search(0.0), |s| {
            let residual = if s < 0.3 { -1.0 } else { 1.0 };
            Ok::<_, ()>(Evaluation {
                residual,
                slope: None,
                met: false,
                value: s,
            })
        })
        .unwrap();
        let Found::Jump { below, above } = found else {
            panic!("a jump")
        };
        assert!(
            below.0 < 0.3 && above.0 >= 0.3 && above.0 - below.0 < 1e-12,
            "{below:?} {above:?}"
        );
    }

    #[test]
    fn no_sign_change_in_reach_is_an_error() {
        let e = bracketed_root(&search(0.0), |_| {
            Ok::<_, ()>(Evaluation {
                residual: -1.0,
                slope: None,
                met: false,
                value: (),
            })
        })
        .unwrap_err();
        assert!(matches!(e, SearchError::NoBracket), "{e:?}");
    }
}
