//! The coupled system condensed onto chosen dofs `c` (for example those of the contact
//! points): the block `(K⁻¹)_cc` of the inverse, the solution at `c` under the loads, and the
//! solve whose right-hand side changes from the loads' only at `c`.
//!
//! When the factorisation ordered the dofs `c` last ([`crate::Ordering::GivenThenLast`]) and
//! its last supernode holds them, everything comes off the factor's trailing block:
//! `(K⁻¹)_cc = S_c⁻¹ = L_cc⁻ᵀ D_c⁻¹ L_cc⁻¹` (no further factorisation), the solution at `c`
//! from the loads' forward sweep and the trailing block alone, and the final solve as a dense
//! triangular update of that forward sweep and one backward sweep: the whole contact run then
//! costs the sparse work of one solve. Otherwise, by block solves with the factor.

use crate::coupled::{DirectLdlt, UPhi};
use crate::LinalgError;
use crate::ShapeError;

/// How a condensation was formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CondenseRoute {
    /// Read off the trailing block of the factor (the dofs ordered last).
    TrailingBlock,
    /// Block solves with the factor, 64 right-hand sides at a time.
    BlockSolves,
    /// Another solver's own Schur complement of the dofs (MUMPS' on the ranks of an MPI run).
    SchurComplement,
}

/// `K` condensed onto the dofs `c`.
#[derive(Debug)]
pub struct Condensed {
    /// `(K⁻¹)_cc`, dense, row-major `k x k` (`k = c.len()`), symmetric.
    pub inverse: Vec<f64>,
    /// The loads' part, kept for [`DirectLdlt::solve_with_update`].
    pub loads: CondensedLoads,
}

/// The loads' part of a condensation: the solution at `c` under the loads alone, and what the
/// final solve with a change of the right-hand side at `c` needs.
#[derive(Debug)]
pub struct CondensedLoads {
    /// `x_c`: the solution of `K x = b` at the dofs `c`, in their order.
    pub solution: Vec<f64>,
    /// How the condensation was formed.
    pub route: CondenseRoute,
    /// The dofs `c`.
    dofs: Vec<usize>,
    /// The forward half `L⁻¹ P b` of the loads' solve (trailing-block route).
    forward: Option<Vec<f64>>,
}

impl DirectLdlt {
    /// Condenses `K` onto `dofs` (indices into `[u; φ]`) with the loads `[b_u; b_φ]`.
    ///
    /// # Errors
    /// [`LinalgError::NotPositiveDefinite`] where a pivot of the trailing block has not its
    /// dof's sign (positive on a displacement, negative on a potential: `K` is quasi-definite);
    /// [`LinalgError::Shape`] for a dof out of range.
    pub fn condense(&mut self, b_u: &[f64], b_phi: &[f64], dofs: &[usize]) -> Result<Condensed, LinalgError> {
        let b: Vec<f64> = b_u.iter().chain(b_phi).copied().collect();
        if let Some(&bad) = dofs.iter().find(|&&d| d >= b.len()) {
            return Err(ShapeError::CondensedDof { dof: bad, n: b.len() }.into());
        }
        if let Some(condensed) = self.condense_from_factor(&b, dofs, b_u.len())? {
            return Ok(condensed);
        }
        self.condense_by_solves(b, dofs)
    }

    /// `[u; φ]` solving `K x = [b_u; b_φ] + Σ_j d_j e_{c_j}`: the loads plus `d` at the dofs of
    /// the condensation.
    ///
    /// # Errors
    /// [`LinalgError::Shape`] where `d` does not have one value per dof.
    pub fn solve_with_update(
        &mut self,
        loads: CondensedLoads,
        b_u: &[f64],
        b_phi: &[f64],
        d: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), LinalgError> {
        if d.len() != loads.dofs.len() {
            return Err(ShapeError::CondensedValues {
                values: d.len(),
                dofs: loads.dofs.len(),
            }
            .into());
        }
        let n_u = b_u.len();
        if let Some(mut y) = loads.forward {
            if self.factor.forward_update_trailing(&mut y, d) {
                if let Some(mut x) = self.factor.backward(y) {
                    let phi = x.split_off(n_u);
                    return Ok((x, phi));
                }
            }
        }
        let mut rhs: Vec<f64> = b_u.iter().chain(b_phi).copied().collect();
        for (&j, v) in loads.dofs.iter().zip(d) {
            rhs[j] += v;
        }
        self.factor.solve_in_place(&mut rhs);
        let phi = rhs.split_off(n_u);
        Ok((rhs, phi))
    }

    /// `K⁻¹ Σ_i d_i e_{c_i}` for each `d` of `updates` (values at the dofs `c`, in `dofs`'
    /// order), solved together, where the factor's order ends with `dofs` (as a condensation's
    /// trailing-block route orders them): the forward half of such a right-hand side is the
    /// trailing block's alone (`L_cc⁻¹ d`, dense), so each solve costs a backward sweep, and
    /// the sweeps of all are one. `None` where the factor's order does not end with `dofs`
    /// (the caller then solves in full).
    ///
    /// # Errors
    /// [`LinalgError::Shape`] where an update does not have one value per dof.
    pub fn solve_trailing_many(&self, dofs: &[usize], updates: &[&[f64]]) -> Result<Option<Vec<UPhi>>, LinalgError> {
        let (k, m) = (dofs.len(), updates.len());
        if let Some(d) = updates.iter().find(|d| d.len() != k) {
            return Err(ShapeError::CondensedValues {
                values: d.len(),
                dofs: k,
            }
            .into());
        }
        let fwd = self.factor.permutation();
        let n = fwd.len();
        if k == 0 || k > n || fwd[n - k..] != *dofs || m == 0 {
            return Ok(None);
        }
        // the forward halves, index by index: zero but on the trailing indices
        let mut y = vec![0.0; n * m];
        for (j, d) in updates.iter().enumerate() {
            let Some(tail) = self.factor.trailing_forward(d) else {
                return Ok(None);
            };
            for (i, v) in tail.into_iter().enumerate() {
                y[(n - k + i) * m + j] = v;
            }
        }
        let Some(xs) = self.factor.backward_many(y, m) else {
            return Ok(None);
        };
        Ok(Some(
            xs.into_iter()
                .map(|mut x| {
                    let phi = x.split_off(self.n_u);
                    (x, phi)
                })
                .collect(),
        ))
    }

    /// The trailing-block route, where the factor's order ends with `dofs`; `None` otherwise.
    fn condense_from_factor(&self, b: &[f64], dofs: &[usize], n_u: usize) -> Result<Option<Condensed>, LinalgError> {
        let k = dofs.len();
        let fwd = self.factor.permutation();
        if k == 0 || fwd[fwd.len() - k..] != *dofs {
            return Ok(None);
        }
        let Some(inverse) = self.factor.trailing_schur_inverse(k, &|j| dofs[j] >= n_u)? else {
            return Ok(None);
        };
        let Some(forward) = self.factor.forward(b) else {
            return Ok(None);
        };
        let Some(solution) = self.factor.trailing_backward(&forward, k) else {
            return Ok(None);
        };
        Ok(Some(Condensed {
            inverse,
            loads: CondensedLoads {
                solution,
                route: CondenseRoute::TrailingBlock,
                dofs: dofs.to_vec(),
                forward: Some(forward),
            },
        }))
    }

    /// The block-solves route: column `j` of `(K⁻¹)_cc` is the solution under a unit load at
    /// dof `c_j`, restricted to `c`.
    fn condense_by_solves(&mut self, mut b: Vec<f64>, dofs: &[usize]) -> Result<Condensed, LinalgError> {
        const BLOCK: usize = 64;
        let (n, k) = (b.len(), dofs.len());
        let mut inv = faer::Mat::<f64>::zeros(k, k);
        let mut start = 0;
        while start < k {
            let width = BLOCK.min(k - start);
            let mut rhs = faer::Mat::<f64>::zeros(n, width);
            for c in 0..width {
                rhs[(dofs[start + c], c)] = 1.0;
            }
            self.factor.solve_many(rhs.as_mut());
            for c in 0..width {
                for (r, &dof) in dofs.iter().enumerate() {
                    inv[(r, start + c)] = rhs[(dof, c)];
                }
            }
            start += width;
        }
        self.factor.solve_in_place(&mut b);
        Ok(Condensed {
            inverse: crate::dense::symmetric_row_major(&inv),
            loads: CondensedLoads {
                solution: dofs.iter().map(|&d| b[d]).collect(),
                route: CondenseRoute::BlockSolves,
                dofs: dofs.to_vec(),
                forward: None,
            },
        })
    }
}

impl CondensedLoads {
    /// The loads' part of a condensation that another solver formed (`route`): `solution` at
    /// `dofs` (its final solve is that solver's own).
    pub fn formed(solution: Vec<f64>, route: CondenseRoute, dofs: Vec<usize>) -> Self {
        CondensedLoads {
            solution,
            route,
            dofs,
            forward: None,
        }
    }

    /// The dofs of the condensation.
    pub fn dofs(&self) -> &[usize] {
        &self.dofs
    }

    /// The number of condensed dofs.
    pub fn len(&self) -> usize {
        self.dofs.len()
    }

    /// Whether no dof was condensed.
    pub fn is_empty(&self) -> bool {
        self.dofs.is_empty()
    }
}
