//! Preconditioned conjugate gradients (the paper's Algorithm 3) on an operator trait.

use crate::LinalgError;
use crate::ShapeError;

/// A linear map `out = M x` on vectors of length `n()`. Preconditioners are operators too:
/// they apply `P⁻¹`. `apply` takes `&mut self` so that an operator may keep its scratch.
pub trait LinearOperator {
    /// Dimension.
    fn n(&self) -> usize;
    /// `out = M x`.
    fn apply(&mut self, out: &mut [f64], x: &[f64]);
}

/// The identity (no preconditioning).
pub struct Identity(pub usize);

impl LinearOperator for Identity {
    fn n(&self) -> usize {
        self.0
    }
    fn apply(&mut self, out: &mut [f64], x: &[f64]) {
        out.copy_from_slice(x);
    }
}

/// When PCG stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PcgStop {
    /// `‖r‖₂ ≤ rel_tol ‖b‖₂ + abs_tol`: a scale-free residual test (the default).
    RelativeResidual,
    /// The paper's rule, `(r, z) ≤ rel_tol (r₀, z₀)` (loose: relative to the warm start's
    /// residual, in the preconditioner's norm squared).
    PaperRz,
}

/// Parameters of [`pcg`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgParams {
    /// Relative tolerance.
    pub rel_tol: f64,
    /// Absolute tolerance on `‖r‖₂` (only for [`PcgStop::RelativeResidual`]).
    pub abs_tol: f64,
    /// Iteration limit.
    pub max_iters: usize,
    /// The stopping rule.
    pub stop: PcgStop,
}

impl Default for PcgParams {
    fn default() -> Self {
        PcgParams {
            rel_tol: 1e-10,
            abs_tol: 0.0,
            max_iters: 1000,
            stop: PcgStop::RelativeResidual,
        }
    }
}

/// What a converged [`pcg`] reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgInfo {
    /// Iterations done (0 when the warm start already met the test).
    pub n_iters: usize,
    /// `‖r‖₂ / ‖b‖₂` at the end (`‖r‖₂` when `b = 0`).
    pub rel_residual: f64,
}

/// Solves `M x = b` for a symmetric positive definite `M`, with preconditioner `P⁻¹`,
/// starting from the `x` given (warm start).
pub fn pcg(
    op: &mut dyn LinearOperator,
    precond: &mut dyn LinearOperator,
    b: &[f64],
    x: &mut [f64],
    params: &PcgParams,
) -> Result<PcgInfo, LinalgError> {
    let n = op.n();
    if b.len() != n || x.len() != n || precond.n() != n {
        return Err(ShapeError::Pcg {
            operator: n,
            preconditioner: precond.n(),
            b: b.len(),
            x: x.len(),
        }
        .into());
    }
    let norm_b = norm(b);
    let scale = if norm_b > 0.0 { norm_b } else { 1.0 };
    let mut r = vec![0.0; n];
    op.apply(&mut r, x);
    for i in 0..n {
        r[i] = b[i] - r[i];
    }
    let mut z = vec![0.0; n];
    precond.apply(&mut z, &r);
    let mut rz = dot(&r, &z);
    let rz0 = rz;
    let converged = |r: &[f64], rz: f64| match params.stop {
        PcgStop::RelativeResidual => norm(r) <= params.rel_tol * norm_b + params.abs_tol,
        PcgStop::PaperRz => rz <= params.rel_tol * rz0,
    };
    if !rz.is_finite() {
        return Err(LinalgError::NonFinite {
            what: "the initial residual of PCG".into(),
        });
    }
    if converged(&r, rz) || norm(&r) == 0.0 {
        return Ok(PcgInfo {
            n_iters: 0,
            rel_residual: norm(&r) / scale,
        });
    }
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    for it in 1..=params.max_iters {
        op.apply(&mut q, &p);
        let pq = dot(&p, &q);
        if !(pq > 0.0) {
            return Err(LinalgError::NotPositiveDefiniteOperator {
                n_iters: it,
                curvature: pq,
            });
        }
        let alpha = rz / pq;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        precond.apply(&mut z, &r);
        let rz_new = dot(&r, &z);
        if converged(&r, rz_new) {
            return Ok(PcgInfo {
                n_iters: it,
                rel_residual: norm(&r) / scale,
            });
        }
        if !(rz_new >= 0.0) {
            return Err(LinalgError::NotPositiveDefiniteOperator {
                n_iters: it,
                curvature: rz_new,
            });
        }
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    Err(LinalgError::NoConvergence {
        n_iters: params.max_iters,
        rel_residual: norm(&r) / scale,
    })
}

/// Euclidean dot product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Euclidean norm; where the sum of squares would overflow or underflow (entries near 1e±150
/// and beyond), scaled by the largest entry first.
pub fn norm(a: &[f64]) -> f64 {
    let plain = dot(a, a);
    if plain > 1e-290 && plain < 1e290 || a.iter().all(|x| *x == 0.0) {
        return plain.sqrt();
    }
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 || !scale.is_finite() {
        // zero, or a NaN or infinity that the caller must see
        return if a.iter().any(|x| x.is_nan()) { f64::NAN } else { scale };
    }
    // divided by scale: `1/scale` overflows for a subnormal scale
    scale * a.iter().map(|x| (x / scale) * (x / scale)).sum::<f64>().sqrt()
}
