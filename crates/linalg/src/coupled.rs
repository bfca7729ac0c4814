//! The coupled system `K [u; φ] = [b_u; b_φ]`, `K = [[A, Gᵀ], [G, -B]]` (A, B SPD), solved
//! two ways that must agree to round-off:
//!
//! - [`SchurPcg`] (the paper's Algorithm 3): eliminate φ = B⁻¹ (G u - b_φ), solve
//!   `S u = b_u + Gᵀ B⁻¹ b_φ` with `S = A + Gᵀ B⁻¹ G` by PCG preconditioned by `A`, using
//!   Cholesky factors of `A` and `B` computed once;
//! - [`DirectLdlt`]: one sparse `L D Lᵀ` of `K`, one forward/back solve.

use crate::factor::{FactorKind, Ordering, SparseFactor};
use crate::pcg::{pcg, LinearOperator, PcgParams};
use crate::sparse::{lower_quasi_definite, mul_add, mul_add_interleaved, mul_t_add, mul_t_add_interleaved};
use crate::{LinalgError, ShapeError};
use faer::sparse::SparseColMat;
use faer::{MatMut, Par};
use rayon::prelude::*;

/// What one coupled solve reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveInfo {
    /// PCG iterations (0 for the direct solve).
    pub pcg_iters: usize,
}

/// A solver of `K [u; φ] = [b_u; b_φ]` whose factorisations are done at construction.
pub trait CoupledSolver {
    /// Solves; `u` and `phi` hold a warm start on entry (used by iterative solvers) and the
    /// solution on exit.
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64], u: &mut [f64], phi: &mut [f64]) -> Result<SolveInfo, LinalgError>;
    /// Bytes of the factor values held.
    fn factor_bytes(&self) -> usize;
}

/// `S = A + Gᵀ B⁻¹ G` as an operator (never formed).
pub struct SchurOperator<'a> {
    a: &'a SparseColMat<usize, f64>,
    g: &'a SparseColMat<usize, f64>,
    b_factor: &'a mut SparseFactor,
    tmp: Vec<f64>,
}

impl<'a> SchurOperator<'a> {
    /// The operator of the blocks `a` (n_u x n_u, both triangles stored), `g` (n_φ x n_u) and
    /// the factor of `B`.
    pub fn new(
        a: &'a SparseColMat<usize, f64>,
        g: &'a SparseColMat<usize, f64>,
        b_factor: &'a mut SparseFactor,
    ) -> Self {
        let n_phi = g.nrows();
        SchurOperator {
            a,
            g,
            b_factor,
            tmp: vec![0.0; n_phi],
        }
    }
}

impl LinearOperator for SchurOperator<'_> {
    fn n(&self) -> usize {
        self.a.nrows()
    }
    fn apply(&mut self, out: &mut [f64], x: &[f64]) {
        out.fill(0.0);
        mul_add(self.a.as_ref(), x, out, 1.0);
        if self.tmp.is_empty() {
            return;
        }
        self.tmp.fill(0.0);
        mul_add(self.g.as_ref(), x, &mut self.tmp, 1.0);
        self.b_factor.solve_in_place(&mut self.tmp);
        mul_t_add(self.g.as_ref(), &self.tmp, out, 1.0);
    }
}

/// `P⁻¹ = A⁻¹` through a Cholesky factor.
pub struct FactorPreconditioner<'a>(pub &'a mut SparseFactor);

impl LinearOperator for FactorPreconditioner<'_> {
    fn n(&self) -> usize {
        self.0.n()
    }
    fn apply(&mut self, out: &mut [f64], x: &[f64]) {
        out.copy_from_slice(x);
        self.0.solve_in_place(out);
    }
}

/// The paper's strategy: Cholesky of `A` and `B`, PCG on the Schur complement.
pub struct SchurPcg {
    a: SparseColMat<usize, f64>,
    g: SparseColMat<usize, f64>,
    chol_a: SparseFactor,
    chol_b: Option<SparseFactor>,
    /// PCG parameters, changeable between solves.
    pub params: PcgParams,
}

impl SchurPcg {
    /// Factors `A` and `B` (Cholesky, AMD). `B` may be empty (no electric unknowns).
    ///
    /// # Errors
    /// As [`SparseFactor::new`], naming the block.
    pub fn new(
        a: SparseColMat<usize, f64>,
        g: SparseColMat<usize, f64>,
        b: &SparseColMat<usize, f64>,
        params: PcgParams,
        par: Par,
    ) -> Result<Self, LinalgError> {
        Self::new_within(a, g, b, params, par, None)
    }

    /// As [`SchurPcg::new`], each factor within a memory `budget` (see
    /// [`SparseFactor::new_within`]).
    ///
    /// # Errors
    /// As [`SparseFactor::new_within`], naming the block.
    pub fn new_within(
        a: SparseColMat<usize, f64>,
        g: SparseColMat<usize, f64>,
        b: &SparseColMat<usize, f64>,
        params: PcgParams,
        par: Par,
        budget: Option<usize>,
    ) -> Result<Self, LinalgError> {
        let chol_a = SparseFactor::new_within(a.as_ref(), FactorKind::Cholesky, &Ordering::Amd, par, budget)
            .map_err(|e| e.context("the elasticity block A"))?;
        let left = budget.map(|b| b.saturating_sub(chol_a.values_bytes()));
        let chol_b = if b.nrows() > 0 {
            Some(
                SparseFactor::new_within(b.as_ref(), FactorKind::Cholesky, &Ordering::Amd, par, left)
                    .map_err(|e| e.context("the dielectric block B"))?,
            )
        } else {
            None
        };
        Ok(SchurPcg {
            a,
            g,
            chol_a,
            chol_b,
            params,
        })
    }
}

impl CoupledSolver for SchurPcg {
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64], u: &mut [f64], phi: &mut [f64]) -> Result<SolveInfo, LinalgError> {
        let Some(chol_b) = self.chol_b.as_mut() else {
            u.copy_from_slice(b_u);
            self.chol_a.solve_in_place(u);
            return Ok(SolveInfo { pcg_iters: 0 });
        };
        // rhs of S u = b_u + Gᵀ B⁻¹ b_φ
        let mut y = b_phi.to_vec();
        chol_b.solve_in_place(&mut y);
        let mut rhs = b_u.to_vec();
        mul_t_add(self.g.as_ref(), &y, &mut rhs, 1.0);
        let mut op = SchurOperator::new(&self.a, &self.g, chol_b);
        let mut pre = FactorPreconditioner(&mut self.chol_a);
        let info = pcg(&mut op, &mut pre, &rhs, u, &self.params)?;
        // φ = B⁻¹ (G u - b_φ)
        phi.iter_mut().zip(b_phi).for_each(|(p, b)| *p = -b);
        mul_add(self.g.as_ref(), u, phi, 1.0);
        chol_b.solve_in_place(phi);
        Ok(SolveInfo {
            pcg_iters: info.n_iters,
        })
    }
    fn factor_bytes(&self) -> usize {
        self.chol_a.values_bytes() + self.chol_b.as_ref().map_or(0, |f| f.values_bytes())
    }
}

/// One `L D Lᵀ` of `K` (lower triangle built from the blocks).
pub struct DirectLdlt {
    pub(crate) factor: SparseFactor,
    pub(crate) n_u: usize,
    buf: Vec<f64>,
}

impl DirectLdlt {
    /// Builds the lower triangle of `K` and factors it; `ordering` may put chosen dofs last
    /// (indices into `[u; φ]`).
    ///
    /// # Errors
    /// As [`SparseFactor::new`], naming the coupled matrix.
    pub fn new(
        a: &SparseColMat<usize, f64>,
        g: &SparseColMat<usize, f64>,
        b: &SparseColMat<usize, f64>,
        ordering: &Ordering,
        par: Par,
    ) -> Result<Self, LinalgError> {
        Self::new_within(a, g, b, ordering, par, None)
    }

    /// As [`DirectLdlt::new`], within a memory `budget` for the factor (see
    /// [`SparseFactor::new_within`]).
    ///
    /// # Errors
    /// As [`SparseFactor::new_within`], naming the coupled matrix.
    pub fn new_within(
        a: &SparseColMat<usize, f64>,
        g: &SparseColMat<usize, f64>,
        b: &SparseColMat<usize, f64>,
        ordering: &Ordering,
        par: Par,
        budget: Option<usize>,
    ) -> Result<Self, LinalgError> {
        Self::new_watched([a, g, b], ordering, (par, budget), None)
    }

    /// As [`DirectLdlt::new_within`] on the blocks `[A, G, B]`, the factorisation's progress
    /// kept in `progress` as it goes ([`crate::FactorProgress`]).
    ///
    /// # Errors
    /// As [`DirectLdlt::new_within`].
    pub fn new_watched(
        [a, g, b]: [&SparseColMat<usize, f64>; 3],
        ordering: &Ordering,
        (par, budget): (Par, Option<usize>),
        progress: Option<&crate::FactorProgress>,
    ) -> Result<Self, LinalgError> {
        let k = lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref());
        let factor = SparseFactor::new_watched(k.as_ref(), FactorKind::Ldlt, ordering, (par, budget), progress)
            .map_err(|e| e.context("the coupled matrix K"))?;
        Ok(DirectLdlt {
            factor,
            n_u: a.nrows(),
            buf: vec![0.0; k.nrows()],
        })
    }

    /// `K⁻¹ [b_u; b_φ]` for several right-hand sides at once, each `(b_u, b_φ)` of the
    /// blocks' sizes, in one pair of sweeps over the factor (a sweep reads the whole factor
    /// whatever the number of columns: several cost little more than one).
    ///
    /// # Errors
    /// [`ShapeError::Rhs`] where a right-hand side is not of the blocks' sizes.
    pub fn solve_many(&mut self, rhs: &[UPhiRef<'_>]) -> Result<Vec<UPhi>, LinalgError> {
        let (n, n_u, k) = (self.buf.len(), self.n_u, rhs.len());
        let mut x = vec![0.0; n * k];
        for ((b_u, b_phi), col) in rhs.iter().zip(x.chunks_exact_mut(n.max(1))) {
            if b_u.len() != n_u || b_phi.len() != n - n_u {
                return Err(ShapeError::Rhs {
                    expected: n,
                    got: b_u.len() + b_phi.len(),
                }
                .into());
            }
            col[..n_u].copy_from_slice(b_u);
            col[n_u..].copy_from_slice(b_phi);
        }
        if k > 0 && n > 0 {
            self.factor
                .solve_many(MatMut::from_column_major_slice_mut(&mut x, n, k));
        }
        Ok(x.chunks_exact(n.max(1))
            .take(k)
            .map(|c| (c[..n_u].to_vec(), c[n_u..].to_vec()))
            .collect())
    }

    /// The factor (for its inertia, pivots, ordering and size).
    pub fn factor(&self) -> &SparseFactor {
        &self.factor
    }
}

impl CoupledSolver for DirectLdlt {
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64], u: &mut [f64], phi: &mut [f64]) -> Result<SolveInfo, LinalgError> {
        let n_u = self.n_u;
        self.buf[..n_u].copy_from_slice(b_u);
        self.buf[n_u..].copy_from_slice(b_phi);
        self.factor.solve_in_place(&mut self.buf);
        u.copy_from_slice(&self.buf[..n_u]);
        phi.copy_from_slice(&self.buf[n_u..]);
        Ok(SolveInfo { pcg_iters: 0 })
    }
    fn factor_bytes(&self) -> usize {
        self.factor.values_bytes()
    }
}

/// A vector of `[u; φ]` by its blocks, `(u, φ)`.
pub type UPhi = (Vec<f64>, Vec<f64>);

/// A borrowed vector of `[u; φ]` by its blocks, `(u, φ)`.
pub type UPhiRef<'a> = (&'a [f64], &'a [f64]);

/// The blocks `A`, `G`, `B` of `K = [[A, Gᵀ], [G, -B]]`.
#[derive(Clone, Copy)]
pub struct CoupledBlocks<'a> {
    /// `A`.
    pub a: &'a SparseColMat<usize, f64>,
    /// `G`.
    pub g: &'a SparseColMat<usize, f64>,
    /// `B`.
    pub b: &'a SparseColMat<usize, f64>,
}

/// A right-hand side `b = [b_u; b_φ]`, with `scale` the size of the parts it is made of (for a
/// `b` whose parts cancel: loads balanced by contact forces), what a residual is measured
/// against ([`equilibrium_residual`]).
#[derive(Clone, Copy, Debug)]
pub struct Rhs<'a> {
    /// `b_u`.
    pub u: &'a [f64],
    /// `b_φ`.
    pub phi: &'a [f64],
    /// The size of `b`'s parts (0: `‖b‖` itself).
    pub scale: f64,
}

/// `b - K x` by blocks, `(b_u - A u - Gᵀ φ, b_φ - G u + B φ)`, the products on rayon's pool.
fn minus_k_x(k: CoupledBlocks<'_>, (u, phi): (&[f64], &[f64]), (b_u, b_phi): (&[f64], &[f64])) -> (Vec<f64>, Vec<f64>) {
    let mut ru = b_u.to_vec();
    mul_add(k.a.as_ref(), u, &mut ru, -1.0);
    mul_t_add(k.g.as_ref(), phi, &mut ru, -1.0);
    let mut rp = b_phi.to_vec();
    mul_add(k.g.as_ref(), u, &mut rp, -1.0);
    mul_add(k.b.as_ref(), phi, &mut rp, 1.0);
    (ru, rp)
}

/// [`minus_k_x`] of several vectors, each `(b_u - A u - Gᵀ φ, b_φ - G u + B φ)` summed in
/// the order of one column after another on one thread: the vectors split into as many
/// groups as the pool has threads, each group's products made at once on one thread from its
/// vectors stored interleaved, so that a thread reads `K` once for its group (the written instants of a path
/// measured each a product with a 2D `K` of 10^7 entries, 10 ms, bound by reading them).
fn minus_k_x_many(k: CoupledBlocks<'_>, xs: &[UPhiRef<'_>], bs: &[UPhiRef<'_>]) -> Vec<UPhi> {
    let group = xs.len().div_ceil(rayon::current_num_threads().max(1)).max(1);
    let groups: Vec<Vec<UPhi>> = xs
        .par_chunks(group)
        .zip(bs.par_chunks(group))
        .map(|(xs, bs)| minus_k_x_interleaved(k, xs, bs))
        .collect();
    groups.into_iter().flatten().collect()
}

/// Vectors of one length stored interleaved: entry `i` of vector `f` at `i n + f`.
fn interleave(vectors: &[&[f64]]) -> Vec<f64> {
    let n = vectors.len();
    let mut out = vec![0.0; vectors.first().map_or(0, |v| v.len()) * n];
    for (f, v) in vectors.iter().enumerate() {
        for (i, &x) in v.iter().enumerate() {
            out[i * n + f] = x;
        }
    }
    out
}

/// [`minus_k_x_many`]'s products of one group on the calling thread.
fn minus_k_x_interleaved(k: CoupledBlocks<'_>, xs: &[UPhiRef<'_>], bs: &[UPhiRef<'_>]) -> Vec<UPhi> {
    let n = xs.len();
    if n == 0 {
        return vec![];
    }
    let xu = interleave(&xs.iter().map(|x| x.0).collect::<Vec<_>>());
    let xp = interleave(&xs.iter().map(|x| x.1).collect::<Vec<_>>());
    let mut ru = interleave(&bs.iter().map(|b| b.0).collect::<Vec<_>>());
    let mut rp = interleave(&bs.iter().map(|b| b.1).collect::<Vec<_>>());
    mul_add_interleaved(k.a.as_ref(), &xu, &mut ru, n, -1.0);
    mul_t_add_interleaved(k.g.as_ref(), &xp, &mut ru, n, -1.0);
    mul_add_interleaved(k.g.as_ref(), &xu, &mut rp, n, -1.0);
    mul_add_interleaved(k.b.as_ref(), &xp, &mut rp, n, 1.0);
    let column = |r: &[f64], f: usize| -> Vec<f64> { r.iter().skip(f).step_by(n).copied().collect() };
    (0..n).map(|f| (column(&ru, f), column(&rp, f))).collect()
}

/// What iterative refinement did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refined {
    /// Corrections applied (each one solve with the factors).
    pub steps: usize,
    /// The equilibrium residual ([`equilibrium_residual`]) of the result.
    pub residual: f64,
}

/// Iterative refinement of `(u, φ)` for `K x = b` with the factors of `solver`:
/// `x ← x + K⁻¹ (b - K x)` while the equilibrium residual (relative to `scale`, as
/// [`equilibrium_residual`]) is above `tol` and every step so far at least halved it, at
/// most `max_steps` times; a correction that does not lower the residual is not kept. In double
/// precision with a backward-stable factorisation, each step gains the factor's accuracy
/// again, up to `ε κ(K)`: it recovers the digits that a large growth of the pivots (a strongly
/// coupled material, a stiffness contrast) lost. A step that gained less than a factor 2 has
/// reached that floor, and the next ones would only stir its round-off (the test of LAPACK's
/// `xGERFS`; a step is a solve with the factors, the cost of the run's solve).
///
/// # Errors
/// The solver's error.
pub fn refine(
    solver: &mut dyn CoupledSolver,
    k: CoupledBlocks<'_>,
    rhs: Rhs<'_>,
    u: &mut [f64],
    phi: &mut [f64],
    tol: f64,
    max_steps: usize,
) -> Result<Refined, LinalgError> {
    refine_by(&mut Blockwise { solver, k, rhs }, u, phi, tol, max_steps)
}

/// [`refine`] of several solutions `xs` of `K x = b` (one per right-hand side of `rhs`, in
/// their order) at once: each round measures every residual, and the corrections of those
/// still above `tol` are one solve with several right-hand sides ([`DirectLdlt::solve_many`]);
/// each solution follows [`refine`]'s rule on its own (a correction kept only where it lowers
/// the residual, no further step after one that did not halve it), so each ends where
/// [`refine`] would have taken it.
///
/// # Errors
/// The solver's; [`ShapeError::Rhs`] where `xs` and `rhs` differ in number.
pub fn refine_many(
    solver: &mut DirectLdlt,
    k: CoupledBlocks<'_>,
    rhs: &[Rhs<'_>],
    xs: &mut [UPhi],
    tol: f64,
    max_steps: usize,
) -> Result<Vec<Refined>, LinalgError> {
    if xs.len() != rhs.len() {
        return Err(ShapeError::Rhs {
            expected: rhs.len(),
            got: xs.len(),
        }
        .into());
    }
    // the products with `K` made together, each thread reading `K` once
    let measure = |xs: &[UPhiRef<'_>], rhs: &[&Rhs<'_>]| -> Vec<Residual> {
        let bs: Vec<UPhiRef<'_>> = rhs.iter().map(|b| (b.u, b.phi)).collect();
        let r = minus_k_x_many(k, xs, &bs);
        r.into_iter()
            .zip(rhs)
            .map(|((ru, rp), b)| Residual::of(ru, rp, **b))
            .collect()
    };
    let all: Vec<UPhiRef<'_>> = xs.iter().map(|(u, phi)| (&u[..], &phi[..])).collect();
    let mut r: Vec<Residual> = measure(&all, &rhs.iter().collect::<Vec<_>>());
    let mut out: Vec<Refined> = r
        .iter()
        .map(|r| Refined {
            steps: 0,
            residual: r.measure,
        })
        .collect();
    let mut active: Vec<usize> = (0..xs.len()).collect();
    for _ in 0..max_steps {
        active.retain(|&j| out[j].residual > tol && out[j].residual.is_finite());
        if active.is_empty() {
            break;
        }
        let columns: Vec<UPhiRef<'_>> = active.iter().map(|&j| (&r[j].u[..], &r[j].phi[..])).collect();
        let corrections = solver.solve_many(&columns)?;
        let candidates: Vec<UPhi> = active
            .iter()
            .zip(corrections)
            .map(|(&j, (du, dp))| {
                let (u, phi) = &xs[j];
                let nu: Vec<f64> = u.iter().zip(&du).map(|(a, b)| a + b).collect();
                let np: Vec<f64> = phi.iter().zip(&dp).map(|(a, b)| a + b).collect();
                (nu, np)
            })
            .collect();
        let refs: Vec<UPhiRef<'_>> = candidates.iter().map(|(u, phi)| (&u[..], &phi[..])).collect();
        let measured = measure(&refs, &active.iter().map(|&j| &rhs[j]).collect::<Vec<_>>());
        let corrected: Vec<_> = active
            .iter()
            .zip(candidates)
            .zip(measured)
            .map(|((&j, x), next)| (j, x, next))
            .collect();
        let mut next_active = Vec::with_capacity(active.len());
        for (j, x, next) in corrected {
            let (before, after) = (out[j].residual, next.measure);
            if !(after < before) {
                continue;
            }
            xs[j] = x;
            r[j] = next;
            out[j] = Refined {
                steps: out[j].steps + 1,
                residual: after,
            };
            if 2.0 * after <= before {
                next_active.push(j);
            }
        }
        active = next_active;
    }
    Ok(out)
}

/// What iterative refinement asks of a system and its solver ([`refine_by`]), for a system
/// held otherwise than by blocks in memory (on the ranks of an MPI run, say).
pub trait Refinable {
    /// The error of its products and solves.
    type Error;
    /// `r = b - K x` and the equilibrium residual of `x` measured on it
    /// ([`relative_residual`]), from one product with `K`.
    ///
    /// # Errors
    /// The system's.
    fn residual(&mut self, u: &[f64], phi: &[f64]) -> Result<Residual, Self::Error>;
    /// `K⁻¹ r` with the factors.
    ///
    /// # Errors
    /// The solver's.
    fn correction(&mut self, r_u: &[f64], r_phi: &[f64]) -> Result<(Vec<f64>, Vec<f64>), Self::Error>;
}

/// A residual `r = b - K x` by blocks, with its equilibrium residual ([`relative_residual`]).
#[derive(Clone, Debug)]
pub struct Residual {
    /// `r_u`.
    pub u: Vec<f64>,
    /// `r_φ`.
    pub phi: Vec<f64>,
    /// `‖r‖ / max(‖b‖, scale)`.
    pub measure: f64,
}

impl Residual {
    /// `r = (r_u, r_φ)` of the right-hand side `rhs`, measured.
    pub fn of(u: Vec<f64>, phi: Vec<f64>, rhs: Rhs<'_>) -> Self {
        let measure = relative_residual(&u, &phi, rhs);
        Residual { u, phi, measure }
    }
}

/// [`refine`]'s iteration on any [`Refinable`] system: one product with `K` per iterate, its
/// residual both measured and, where the iterate is kept, corrected.
///
/// # Errors
/// The system's.
pub fn refine_by<R: Refinable + ?Sized>(
    system: &mut R,
    u: &mut [f64],
    phi: &mut [f64],
    tol: f64,
    max_steps: usize,
) -> Result<Refined, R::Error> {
    let mut r = system.residual(u, phi)?;
    let mut residual = r.measure;
    let mut steps = 0;
    while steps < max_steps && residual > tol && residual.is_finite() {
        let (du, dp) = system.correction(&r.u, &r.phi)?;
        let nu: Vec<f64> = u.iter().zip(&du).map(|(a, b)| a + b).collect();
        let np: Vec<f64> = phi.iter().zip(&dp).map(|(a, b)| a + b).collect();
        let next = system.residual(&nu, &np)?;
        let after = next.measure;
        if !(after < residual) {
            break;
        }
        u.copy_from_slice(&nu);
        phi.copy_from_slice(&np);
        r = next;
        let halved = 2.0 * after <= residual;
        residual = after;
        steps += 1;
        if !halved {
            break;
        }
    }
    Ok(Refined { steps, residual })
}

/// The blocks in memory and a solver, as [`refine`] refines with them.
struct Blockwise<'a, 'k> {
    solver: &'a mut dyn CoupledSolver,
    k: CoupledBlocks<'k>,
    rhs: Rhs<'k>,
}

impl Refinable for Blockwise<'_, '_> {
    type Error = LinalgError;

    fn residual(&mut self, u: &[f64], phi: &[f64]) -> Result<Residual, LinalgError> {
        let (ru, rp) = minus_k_x(self.k, (u, phi), (self.rhs.u, self.rhs.phi));
        Ok(Residual::of(ru, rp, self.rhs))
    }

    fn correction(&mut self, r_u: &[f64], r_phi: &[f64]) -> Result<(Vec<f64>, Vec<f64>), LinalgError> {
        let (mut du, mut dp) = (vec![0.0; r_u.len()], vec![0.0; r_phi.len()]);
        self.solver.solve(r_u, r_phi, &mut du, &mut dp)?;
        Ok((du, dp))
    }
}

/// `‖K x - b‖₂ / max(‖b‖₂, scale)` from the blocks (`‖K x - b‖₂` when both are 0). `scale`
/// is the size of the parts `b` is made of, for a `b` whose parts cancel (loads balanced by
/// contact forces: `‖b‖` then says nothing of the error's size). The norms are scaled, so the
/// residual is the same for data of any magnitude.
pub fn equilibrium_residual(k: CoupledBlocks<'_>, u: &[f64], phi: &[f64], rhs: Rhs<'_>) -> f64 {
    let (ru, rp) = minus_k_x(k, (u, phi), (rhs.u, rhs.phi));
    relative_residual(&ru, &rp, rhs)
}

/// `‖r‖₂ / max(‖b‖₂, scale)` (`‖r‖₂` when both are 0), `r = (r_u, r_φ)` a residual of `K x = b`
/// ([`equilibrium_residual`]'s measure, for a residual formed elsewhere).
pub fn relative_residual(ru: &[f64], rp: &[f64], rhs: Rhs<'_>) -> f64 {
    let Rhs {
        u: b_u,
        phi: b_phi,
        scale,
    } = rhs;
    let both = |a: &[f64], b: &[f64]| {
        let s = crate::pcg::dot(a, a) + crate::pcg::dot(b, b);
        if s > 1e-290 && s < 1e290 {
            s.sqrt()
        } else {
            crate::pcg::norm(a).hypot(crate::pcg::norm(b))
        }
    };
    let num = both(ru, rp);
    let den = both(b_u, b_phi).max(scale);
    if den > 0.0 {
        num / den
    } else {
        num
    }
}
