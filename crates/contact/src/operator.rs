//! The one interface the solvers see: "given multipliers on the contact points, return the
//! displacement of those points". Implemented by a full primal solve (the driver) and by the
//! condensed dense problem below (small tests, and the condensed strategy).

use crate::points::PointValues;
use crate::OperatorError;

/// The contact problem seen from the multipliers.
pub trait ContactOperator {
    /// Number of contact points.
    fn n_points(&self) -> usize;
    /// Tangential components per point carried by this operator (0 for frictionless).
    fn n_tangential(&self) -> usize;
    /// Given `lambda`, computes the contact displacement `(u_n, u_t)` of the equilibrium with
    /// the contact forces `-Nᵀ W λ_n - Tᵀ W λ_t`. Returns inner iterations done (e.g. PCG).
    ///
    /// # Errors
    /// An [`OperatorError`] that carries the primal solver's own error.
    fn displacement(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError>;

    /// The contact displacement under the contact forces of `lambda` alone, without the loads:
    /// `-D W λ`, the linear part of [`ContactOperator::displacement`]. The default takes the
    /// difference of two calls, `u(λ) - u(0)`, which loses the digits of `D W λ` where the loads
    /// are far larger than `λ`; an operator that can apply the forces alone should.
    ///
    /// # Errors
    /// As [`ContactOperator::displacement`].
    fn forces_alone(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        let zero = PointValues::zeros(lambda.n_points(), lambda.n_tangential());
        let mut u0 = zero.clone();
        let inner = self.displacement(&zero, &mut u0)? + self.displacement(lambda, out)?;
        for (o, z) in out.normal.iter_mut().zip(&u0.normal) {
            *o -= z;
        }
        for (o, z) in out.tangential.iter_mut().zip(&u0.tangential) {
            *o -= z;
        }
        Ok(inner)
    }
}

/// An affine contact problem given densely: `u = u0 - D W λ` with `D` symmetric positive
/// (semi)definite (the contact compliance, or Delassus operator), in the layout
/// `[normal (n); tangential (n·nt)]`.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseContactProblem {
    /// Contact displacement under the loads alone (λ = 0).
    pub u0: PointValues,
    /// Compliance, row-major, `m x m` with `m = n (1 + nt)`.
    pub compliance: Vec<f64>,
    /// Weights `w_i`.
    pub weight: Vec<f64>,
    /// Tangential components per point.
    pub nt: usize,
}

impl DenseContactProblem {
    /// Size of the dense system.
    pub fn m(&self) -> usize {
        self.weight.len() * (1 + self.nt)
    }
}

impl ContactOperator for DenseContactProblem {
    fn n_points(&self) -> usize {
        self.weight.len()
    }
    fn n_tangential(&self) -> usize {
        self.nt
    }
    fn displacement(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        self.apply(lambda, out, true);
        Ok(0)
    }
    fn forces_alone(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        self.apply(lambda, out, false);
        Ok(0)
    }
}

impl DenseContactProblem {
    /// `out = u0 - D W λ` (`with_loads`) or `-D W λ`.
    fn apply(&self, lambda: &PointValues, out: &mut PointValues, with_loads: bool) {
        let n = self.weight.len();
        let m = self.m();
        // W λ in the flat layout
        let mut wl = Vec::with_capacity(m);
        wl.extend(lambda.normal.iter().zip(&self.weight).map(|(l, w)| l * w));
        for i in 0..n {
            for k in 0..self.nt {
                wl.push(lambda.tangential[i * self.nt + k] * self.weight[i]);
            }
        }
        for r in 0..m {
            let row = &self.compliance[r * m..(r + 1) * m];
            let dot = dot8(row, &wl);
            let (slot, load) = if r < n {
                (&mut out.normal[r], self.u0.normal[r])
            } else {
                (&mut out.tangential[r - n], self.u0.tangential[r - n])
            };
            *slot = if with_loads { load - dot } else { -dot };
        }
    }
}

/// A dot product with eight independent partial sums, so that it vectorises (a single running
/// sum is a chain of dependent additions).
pub(crate) fn dot8(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s: f64 = acc.iter().sum();
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}
