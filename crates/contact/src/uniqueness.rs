//! Whether Coulomb's law can have more than one solution near a point: the expansion of the
//! fixed-point map on the slip bound, `Φ(S) = F λ_n(S)` with `λ(S)` the Tresca solution for
//! the bound `S` (the paper's Algorithm 4 iterates it; its existence and uniqueness theorem
//! rests on its being a contraction). An expansion of at least 1 near the best iterate of a
//! failed solve says that the data are past that theory, not that the solvers gave up early.

use crate::operator::AffineProblem;
use crate::points::{ContactPoints, PointValues};
use crate::{slip_bound, ContactError, Interrupt, Law, NewtonParams};

/// Power steps of the estimate.
const PROBES: usize = 4;

/// An estimate (from below) of the Lipschitz constant of `Φ(S) = F λ_n(S)` near `lambda`, in
/// the weighted norm: a few power steps on finite differences `(Φ(S + ε v) - Φ(S)) / ε` from
/// `S = F λ_n`, along non-negative directions (the bound stays a bound), each `λ(S)` a Tresca
/// solve by [`crate::solve_newton`] warm-started from `lambda`.
///
/// # Errors
/// The Tresca solves' errors.
pub fn slip_bound_expansion<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    lambda: &PointValues,
    interrupt: &Interrupt,
) -> Result<f64, ContactError> {
    let n = points.len();
    let s0 = slip_bound(points, &Law::Coulomb, &lambda.normal);
    let params = NewtonParams {
        tol: 1e-12,
        interrupt: *interrupt,
        ..Default::default()
    };
    let mut tresca = |s: &[f64], start: &PointValues| -> Result<PointValues, ContactError> {
        Ok(crate::solve_newton(
            problem,
            points,
            &Law::Tresca(s.to_vec()),
            &params,
            Some(start.clone()),
            &mut |_| {},
        )?
        .lambda)
    };
    let base = tresca(&s0, lambda)?;
    let w = &points.weight;
    let norm = |v: &[f64]| v.iter().zip(w).map(|(x, w)| w * x * x).sum::<f64>().sqrt();
    // the step's scale: the bound, or (at a start with no pressure) the bound it maps to
    let mapped = slip_bound(points, &Law::Coulomb, &base.normal);
    let size = norm(&s0).max(norm(&mapped)).max(f64::MIN_POSITIVE);
    // a deterministic start without symmetry, on the points that carry friction
    let mut v: Vec<f64> = (0..n)
        .map(|i| {
            if points.friction[i] > 0.0 {
                1.0 + 0.5 * (1.7 * i as f64).sin()
            } else {
                0.0
            }
        })
        .collect();
    let mut expansion = 0.0f64;
    for _ in 0..PROBES {
        let nv = norm(&v);
        if !(nv > 0.0) {
            break;
        }
        let eps = 1e-4 * size / nv;
        let s1: Vec<f64> = s0.iter().zip(&v).map(|(s, d)| s + eps * d).collect();
        let moved = tresca(&s1, &base)?;
        let phi: Vec<f64> = (0..n)
            .map(|i| points.friction[i] * (moved.normal[i] - base.normal[i]) / eps)
            .collect();
        expansion = expansion.max(norm(&phi) / nv);
        v = phi.iter().map(|x| x.abs()).collect();
    }
    Ok(expansion)
}
