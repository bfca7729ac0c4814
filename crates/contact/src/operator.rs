//! The one interface the solvers see: "given multipliers on the contact points, return the
//! displacement of those points". Implemented by a full primal solve (the driver) and by the
//! condensed dense problem below (small tests, and the condensed strategy).

use crate::points::PointValues;
use crate::OperatorError;
use faer::sparse::{SparseRowMat, SparseRowMatRef};
use rayon::prelude::*;

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

/// The operator of a problem given by its data (`u0`, `D`, weights `weight`, `nt`): `apply`
/// it, with the forces alone exactly (no difference of two calls).
macro_rules! affine_operator {
    ($($t:ty),*) => {$(
        impl ContactOperator for $t {
            fn n_points(&self) -> usize {
                self.weight.len()
            }
            fn n_tangential(&self) -> usize {
                self.nt
            }
            fn displacement(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
                apply(self, lambda, out, true);
                Ok(0)
            }
            fn forces_alone(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
                apply(self, lambda, out, false);
                Ok(0)
            }
        }
    )*};
}

affine_operator!(DenseContactProblem, SparseContactProblem);

/// An affine contact problem with a sparse compliance: `u = u0 - D W λ`, `D` in compressed
/// rows, in the layout `[normal (n); tangential (n·nt)]` (the Delassus operators of multibody
/// problems: a few entries per row). `D` need not be definite, nor exactly symmetric.
#[derive(Clone, Debug)]
pub struct SparseContactProblem {
    /// Contact displacement under the loads alone (λ = 0).
    pub u0: PointValues,
    /// Compliance, `m x m` with `m = n (1 + nt)`.
    pub compliance: SparseRowMat<usize, f64>,
    /// Weights `w_i`.
    pub weight: Vec<f64>,
    /// Tangential components per point.
    pub nt: usize,
}

/// The order from which a dense compliance's product runs on rayon's pool (below it, a
/// product takes less than the tasks cost).
const PARALLEL_ROWS: usize = 512;

/// The compliance of an affine problem, as the solvers read it.
#[derive(Clone, Copy, Debug)]
pub enum Compliance<'a> {
    /// Row-major, `m x m`.
    Dense(&'a [f64]),
    /// Compressed rows.
    Sparse(SparseRowMatRef<'a, usize, f64>),
}

impl Compliance<'_> {
    /// Rows (= columns) of the compliance.
    pub fn size(&self) -> usize {
        match self {
            Compliance::Dense(d) => (d.len() as f64).sqrt().round() as usize,
            Compliance::Sparse(s) => s.nrows(),
        }
    }

    /// `out = D x`.
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        match self {
            Compliance::Dense(d) => {
                let m = x.len();
                let row = |(r, o): (usize, &mut f64)| *o = dot8(&d[r * m..(r + 1) * m], x);
                if m >= PARALLEL_ROWS {
                    // memory-bound: a second core adds bandwidth; each row's sum is the same
                    out.par_iter_mut().enumerate().for_each(row);
                } else {
                    out.iter_mut().enumerate().for_each(row);
                }
            }
            Compliance::Sparse(s) => {
                for (r, o) in out.iter_mut().enumerate() {
                    *o = s.col_idx_of_row(r).zip(s.val_of_row(r)).map(|(j, v)| v * x[j]).sum();
                }
            }
        }
    }

    /// Row `r`'s stored entries, `(column, value)`.
    pub fn row(&self, r: usize) -> Box<dyn Iterator<Item = (usize, f64)> + '_> {
        match self {
            Compliance::Dense(d) => {
                let m = self.size();
                Box::new(d[r * m..(r + 1) * m].iter().copied().enumerate())
            }
            Compliance::Sparse(s) => Box::new(s.col_idx_of_row(r).zip(s.val_of_row(r).iter().copied())),
        }
    }

    /// The largest `|D_ij - D_ji|` relative to the largest `|D_ij|` (0 for a symmetric `D`).
    pub fn asymmetry(&self) -> f64 {
        let m = self.size();
        let (mut diff, mut size) = (0.0f64, 0.0f64);
        match self {
            Compliance::Dense(d) => {
                // by tiles, so that the transposed reads stay in cache; the rows of tiles on
                // rayon's pool
                const TILE: usize = 64;
                (diff, size) = (0..m.div_ceil(TILE))
                    .into_par_iter()
                    .map(|t| {
                        let (mut diff, mut size) = (0.0f64, 0.0f64);
                        let i0 = t * TILE;
                        for j0 in (0..=i0).step_by(TILE) {
                            for i in i0..(i0 + TILE).min(m) {
                                for j in j0..(j0 + TILE).min(i + 1) {
                                    let (a, b) = (d[i * m + j], d[j * m + i]);
                                    size = size.max(a.abs()).max(b.abs());
                                    diff = diff.max((a - b).abs());
                                }
                            }
                        }
                        (diff, size)
                    })
                    .reduce(|| (0.0, 0.0), |x, y| (x.0.max(y.0), x.1.max(y.1)));
            }
            Compliance::Sparse(s) => {
                let at = |i: usize, j: usize| {
                    s.col_idx_of_row(i)
                        .zip(s.val_of_row(i))
                        .find(|(c, _)| *c == j)
                        .map_or(0.0, |(_, v)| *v)
                };
                for i in 0..m {
                    for (j, &v) in s.col_idx_of_row(i).zip(s.val_of_row(i)) {
                        size = size.max(v.abs());
                        diff = diff.max((v - at(j, i)).abs());
                    }
                }
            }
        }
        if size > 0.0 {
            diff / size
        } else {
            0.0
        }
    }
}

/// An affine contact problem given by its data, `u = u0 - D W λ`: what the semismooth Newton
/// method needs beyond the operator ([`crate::solve_newton`]).
pub trait AffineProblem: ContactOperator {
    /// `u0`, the contact displacement under the loads alone.
    fn loads(&self) -> &PointValues;
    /// The weights `w_i`.
    fn weights(&self) -> &[f64];
    /// The compliance `D`.
    fn compliance(&self) -> Compliance<'_>;
}

impl AffineProblem for DenseContactProblem {
    fn loads(&self) -> &PointValues {
        &self.u0
    }
    fn weights(&self) -> &[f64] {
        &self.weight
    }
    fn compliance(&self) -> Compliance<'_> {
        Compliance::Dense(&self.compliance)
    }
}

impl AffineProblem for SparseContactProblem {
    fn loads(&self) -> &PointValues {
        &self.u0
    }
    fn weights(&self) -> &[f64] {
        &self.weight
    }
    fn compliance(&self) -> Compliance<'_> {
        Compliance::Sparse(self.compliance.as_ref())
    }
}

/// `out = u0 - D W λ` (`with_loads`) or `-D W λ`, for any [`AffineProblem`].
fn apply(p: &impl AffineProblem, lambda: &PointValues, out: &mut PointValues, with_loads: bool) {
    let (n, nt) = (lambda.n_points(), lambda.n_tangential());
    let w = p.weights();
    let mut wl = Vec::with_capacity(n * (1 + nt));
    wl.extend(lambda.normal.iter().zip(w).map(|(l, w)| l * w));
    for i in 0..n {
        wl.extend(lambda.tangential_of(i).iter().map(|l| l * w[i]));
    }
    let mut dw = vec![0.0; wl.len()];
    p.compliance().apply(&wl, &mut dw);
    let u0 = p.loads();
    let parts = [
        (&mut out.normal, &u0.normal, &dw[..n]),
        (&mut out.tangential, &u0.tangential, &dw[n..]),
    ];
    for (o, load, d) in parts {
        for ((o, l), d) in o.iter_mut().zip(load).zip(d) {
            *o = if with_loads { l - d } else { -d };
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
