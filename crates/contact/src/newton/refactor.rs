//! A sparse LU that keeps its first pivots: each later matrix of the same pattern is factored
//! on the row order and the factors' pattern of the first (the refactorisation of KLU: Davis
//! and Palamadai Natarajan, ACM Trans. Math. Softw. 37 (2010) 36, section 3.3), so that a
//! Newton step pays the arithmetic of its factorisation and none of the graph searches that
//! choose the pivots and find each column's pattern (Gilbert and Peierls' depth-first search,
//! half of the simplicial factorisation's time on Siconos' capsule problems, measured).
//!
//! With `P A Q = L U` (`Q` the fill-reducing column order, `P` the pivots' row order, `L` unit
//! lower and `U` upper triangular), the refactorisation is Gilbert and Peierls' left-looking
//! column solve on the known pattern, in the steps' ascending order (a topological order of
//! `L`'s graph). A pivot kept from the first factorisation must stay at least
//! [`PIVOT_THRESHOLD`] of its column's largest candidate (threshold partial pivoting, UMFPACK's
//! default 0.1: the growth of each step bounded by `1 + 1/0.1`); where one does not, the
//! matrix is factored afresh with new pivots, and those are kept.

use faer::perm::PermRef;
use faer::sparse::SparseColMatRef;

/// The smallest ratio of a kept pivot to its column's largest candidate.
pub(super) const PIVOT_THRESHOLD: f64 = 0.1;

/// No step (a row not pivoted yet).
const NONE: usize = usize::MAX;

/// `P A Q = L U` of a square sparse matrix, for solves with `Aᵀ` and refactorisations on the
/// same pivots.
#[derive(Clone, Debug)]
pub(super) struct PivotedLu {
    /// `q[j]`: the column of `A` eliminated at step `j`.
    q: Vec<usize>,
    /// `p[k]`: the row of `A` pivoted at step `k`.
    p: Vec<usize>,
    /// `pinv[i]`: the step whose pivot is row `i` of `A` ([`NONE`] while none).
    pinv: Vec<usize>,
    /// `L`'s columns below the diagonal: rows of `A` (the candidates a step did not pivot on),
    /// and values.
    l: Columns,
    /// `U`'s columns above the diagonal: steps, in a topological order of `L`'s graph, and
    /// values.
    u: Columns,
    /// `U`'s diagonal: the pivots.
    pivots: Vec<f64>,
    /// A dense column by rows of `A`, zero between columns.
    x: Vec<f64>,
    /// The depth-first search's marks (the search's number where visited), its number, stack
    /// and postorder.
    mark: Vec<usize>,
    searches: usize,
    stack: Vec<(usize, usize)>,
    reach: Vec<usize>,
}

/// A compressed sparse column store.
#[derive(Clone, Debug, Default)]
struct Columns {
    ptr: Vec<usize>,
    idx: Vec<usize>,
    val: Vec<f64>,
}

impl Columns {
    fn range(&self, j: usize) -> std::ops::Range<usize> {
        self.ptr[j]..self.ptr[j + 1]
    }

    /// Drops the columns from `j` on.
    fn truncate(&mut self, j: usize) {
        self.ptr.truncate(j + 1);
        self.idx.truncate(self.ptr[j]);
        self.val.truncate(self.ptr[j]);
    }
}

impl PivotedLu {
    /// The LU of `a` (square) with its columns in the order `q` and partial pivoting (the
    /// largest candidate of each column its pivot). `None` where `a` is singular in its
    /// structure or its values, or a value is not finite.
    pub(super) fn factor(a: SparseColMatRef<'_, usize, f64>, q: PermRef<'_, usize>) -> Option<Self> {
        let n = a.ncols();
        let mut lu = PivotedLu {
            q: q.arrays().0.to_vec(),
            p: vec![NONE; n],
            pinv: vec![NONE; n],
            l: Columns {
                ptr: vec![0],
                ..Columns::default()
            },
            u: Columns {
                ptr: vec![0],
                ..Columns::default()
            },
            pivots: vec![0.0; n],
            x: vec![0.0; n],
            mark: vec![0; n],
            searches: 0,
            stack: Vec::new(),
            reach: Vec::new(),
        };
        lu.factor_from(a, 0).then_some(lu)
    }

    /// Factors `a`'s columns from step `first` on with partial pivoting (Gilbert and Peierls'
    /// left-looking LU: each column's pattern the rows its entries reach in `L`'s graph, found
    /// by a depth-first search, then solved with the columns before it), the steps before kept.
    /// `false` where a column has no nonzero finite pivot.
    fn factor_from(&mut self, a: SparseColMatRef<'_, usize, f64>, first: usize) -> bool {
        for k in first..self.p.len() {
            if self.p[k] != NONE {
                self.pinv[self.p[k]] = NONE;
                self.p[k] = NONE;
            }
        }
        self.l.truncate(first);
        self.u.truncate(first);
        for j in first..self.p.len() {
            let rows = a.row_idx_of_col_raw(self.q[j]);
            self.search(rows);
            for (&i, &v) in rows.iter().zip(a.val_of_col(self.q[j])) {
                self.x[i] += v;
            }
            let (mut pivot_row, mut largest) = (NONE, -1.0);
            for t in (0..self.reach.len()).rev() {
                let i = self.reach[t];
                let k = self.pinv[i];
                if k == NONE {
                    if self.x[i].abs() > largest || self.x[i].is_nan() {
                        (pivot_row, largest) = (i, self.x[i].abs());
                    }
                    continue;
                }
                let xk = std::mem::take(&mut self.x[i]);
                self.u.idx.push(k);
                self.u.val.push(xk);
                for s in self.l.range(k) {
                    self.x[self.l.idx[s]] -= self.l.val[s] * xk;
                }
            }
            self.u.ptr.push(self.u.idx.len());
            let pivot = if pivot_row == NONE {
                0.0
            } else {
                std::mem::take(&mut self.x[pivot_row])
            };
            for t in 0..self.reach.len() {
                let i = self.reach[t];
                if self.pinv[i] == NONE && i != pivot_row {
                    self.l.idx.push(i);
                    self.l.val.push(std::mem::take(&mut self.x[i]) / pivot);
                }
            }
            self.l.ptr.push(self.l.idx.len());
            if !(pivot.is_finite() && pivot != 0.0) {
                return false;
            }
            (self.p[j], self.pinv[pivot_row], self.pivots[j]) = (pivot_row, j, pivot);
        }
        self.l.val.iter().chain(&self.u.val).all(|v| v.is_finite())
    }

    /// The rows that `rows` reach in the graph of `L`'s columns so far (row `i` pivoted at
    /// step `k` leads to the rows of `L`'s column `k`), into `self.reach` in postorder: read
    /// backwards, every row comes before the rows it updates.
    fn search(&mut self, rows: &[usize]) {
        self.reach.clear();
        self.searches += 1;
        let stamp = self.searches;
        for &start in rows {
            if self.mark[start] == stamp {
                continue;
            }
            self.mark[start] = stamp;
            self.stack.push((start, 0));
            while let Some(&(i, next)) = self.stack.last() {
                let k = self.pinv[i];
                let range = if k == NONE { 0..0 } else { self.l.range(k) };
                let child = range.clone().skip(next).position(|s| self.mark[self.l.idx[s]] != stamp);
                match child {
                    Some(offset) => {
                        let r = self.l.idx[range.start + next + offset];
                        self.mark[r] = stamp;
                        self.stack.last_mut().expect("not empty").1 = next + offset + 1;
                        self.stack.push((r, 0));
                    }
                    None => {
                        self.stack.pop();
                        self.reach.push(i);
                    }
                }
            }
        }
    }

    /// Factors `a`, of the pattern the first factorisation was given, on its pivots and
    /// pattern; from the first column whose kept pivot falls below [`PIVOT_THRESHOLD`] of
    /// its largest candidate, with new pivots (those kept from then on). `false` where `a`
    /// is singular or a value is not finite.
    pub(super) fn refactor(&mut self, a: SparseColMatRef<'_, usize, f64>) -> bool {
        for j in 0..self.p.len() {
            for (&i, &v) in a.row_idx_of_col_raw(self.q[j]).iter().zip(a.val_of_col(self.q[j])) {
                self.x[i] += v;
            }
            for t in self.u.range(j) {
                let k = self.u.idx[t];
                let xk = std::mem::take(&mut self.x[self.p[k]]);
                self.u.val[t] = xk;
                for s in self.l.range(k) {
                    self.x[self.l.idx[s]] -= self.l.val[s] * xk;
                }
            }
            let pivot = self.x[self.p[j]];
            let lower = self.l.range(j);
            let largest = lower.clone().map(|s| self.x[self.l.idx[s]].abs()).fold(0.0, f64::max);
            if !(pivot.is_finite() && pivot != 0.0 && pivot.abs() >= PIVOT_THRESHOLD * largest) {
                // this column again with new pivots, from a clean work column
                self.x[self.p[j]] = 0.0;
                for s in lower {
                    self.x[self.l.idx[s]] = 0.0;
                }
                return self.factor_from(a, j);
            }
            self.x[self.p[j]] = 0.0;
            for s in lower {
                self.l.val[s] = std::mem::take(&mut self.x[self.l.idx[s]]) / pivot;
            }
            self.pivots[j] = pivot;
        }
        self.l.val.iter().chain(&self.u.val).all(|v| v.is_finite())
    }

    /// Solves `Aᵀ x = b` in place: `Uᵀ Lᵀ (P x) = Qᵀ b`, by `U`'s columns forward and `L`'s
    /// backward (each a row of the transposed factor: dot products, no scatter).
    pub(super) fn solve_transpose_in_place(&self, b: &mut [f64]) {
        let n = self.pivots.len();
        let mut z: Vec<f64> = self.q.iter().map(|&c| b[c]).collect();
        for j in 0..n {
            let s: f64 = self.u.range(j).map(|t| self.u.val[t] * z[self.u.idx[t]]).sum();
            z[j] = (z[j] - s) / self.pivots[j];
        }
        for j in (0..n).rev() {
            let s: f64 = self
                .l
                .range(j)
                .map(|t| self.l.val[t] * z[self.pinv[self.l.idx[t]]])
                .sum();
            z[j] -= s;
        }
        for (i, x) in b.iter_mut().enumerate() {
            *x = z[self.pinv[i]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::colamd;
    use faer::sparse::SymbolicSparseColMatRef;
    use proptest::prelude::*;

    /// A random sparse `n x n` matrix with a strong diagonal or none, as column pointers,
    /// sorted rows, values.
    fn matrix(n: usize, seed: u64, density: f64, diagonal: f64) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut ptr, mut idx, mut val) = (vec![0], vec![], vec![]);
        for j in 0..n {
            for i in 0..n {
                if i == j || next() < density {
                    idx.push(i);
                    val.push(2.0 * next() - 1.0 + if i == j { diagonal } else { 0.0 });
                }
            }
            ptr.push(idx.len());
        }
        (ptr, idx, val)
    }

    /// `Aᵀ x` for the column store.
    fn transposed_times(ptr: &[usize], idx: &[usize], val: &[f64], x: &[f64]) -> Vec<f64> {
        (0..ptr.len() - 1)
            .map(|j| (ptr[j]..ptr[j + 1]).map(|k| val[k] * x[idx[k]]).sum())
            .collect()
    }

    fn column_order(n: usize, ptr: &[usize], idx: &[usize]) -> (Vec<usize>, Vec<usize>) {
        let a = SymbolicSparseColMatRef::new_checked(n, n, ptr, None, idx);
        let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
        let nnz = idx.len();
        let mut mem = MemBuffer::new(colamd::order_scratch::<usize>(n, n, nnz));
        colamd::order(&mut fwd, &mut inv, a, Default::default(), MemStack::new(&mut mem)).unwrap();
        (fwd, inv)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Factored afresh or on the first pivots (new ones from the first column where those
        /// fall below the threshold), the solve of `Aᵀ x = b` leaves a residual at round-off,
        /// and every kept pivot is within the threshold of its column's largest candidate.
        #[test]
        fn solves_are_round_off_and_refactorisations_keep_them(
            n in 1usize..40, seed in 0u64..1000, density in 0.02f64..0.3, diagonal in 0.0f64..4.0,
            change in 0.0f64..3.0,
        ) {
            let (ptr, idx, first) = matrix(n, seed, density, diagonal);
            let (fwd, inv) = column_order(n, &ptr, &idx);
            let q = PermRef::new_checked(&fwd, &inv, n);
            let pattern = SymbolicSparseColMatRef::new_checked(n, n, &ptr, None, &idx);
            let Some(mut lu) = PivotedLu::factor(SparseColMatRef::new(pattern, &first), q) else {
                return Ok(()); // singular: nothing to check
            };
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 1.0).collect();
            let check = |lu: &PivotedLu, val: &[f64]| {
                let mut x = b.clone();
                lu.solve_transpose_in_place(&mut x);
                let r = transposed_times(&ptr, &idx, val, &x);
                let scale = 1.0 + x.iter().map(|v| v.abs()).fold(0.0, f64::max)
                    * val.iter().map(|v| v.abs()).fold(0.0, f64::max);
                r.iter().zip(&b).map(|(r, b)| (r - b).abs()).fold(0.0, f64::max) / scale
            };
            prop_assert!(check(&lu, &first) < 1e-10 * n as f64);
            // new values on the same pattern (the first's, changed a little or a lot: pivots kept
            // or chosen again)
            let (_, _, noise) = matrix(n, seed + 7, density, 0.0);
            let second: Vec<f64> = first.iter().enumerate().map(|(k, v)| v + change * noise[k % noise.len()]).collect();
            // (a matrix that is singular in its values is the one case it may refuse)
            if lu.refactor(SparseColMatRef::new(pattern, &second)) {
                prop_assert!(check(&lu, &second) < 1e-8 * n as f64);
                for j in 0..n {
                    let largest = lu.l.range(j).map(|s| (lu.l.val[s] * lu.pivots[j]).abs()).fold(0.0, f64::max);
                    prop_assert!(lu.pivots[j].abs() >= PIVOT_THRESHOLD * largest * (1.0 - 1e-12));
                }
            }
        }
    }

    /// A pivot that the new values make zero is chosen again, from its column on.
    #[test]
    fn a_pivot_the_new_values_cancel_is_chosen_again() {
        // A = [[2, 1], [1, 1]] pivots on row 0 of column 0; A' = [[0, 1], [1, 1]] cannot
        let (ptr, idx) = (vec![0, 2, 4], vec![0, 1, 0, 1]);
        let (fwd, inv) = (vec![0, 1], vec![0, 1]);
        let q = PermRef::new_checked(&fwd, &inv, 2);
        let pattern = SymbolicSparseColMatRef::new_checked(2, 2, &ptr, None, &idx);
        let mut lu = PivotedLu::factor(SparseColMatRef::new(pattern, &[2.0, 1.0, 1.0, 1.0]), q).unwrap();
        assert_eq!(lu.p, [0, 1]);
        assert!(lu.refactor(SparseColMatRef::new(pattern, &[0.0, 1.0, 1.0, 1.0])));
        assert_eq!(lu.p, [1, 0]);
        let mut x = vec![1.0, 2.0];
        lu.solve_transpose_in_place(&mut x);
        // Aᵀ = A: 0 x0 + x1 = 1, x0 + x1 = 2
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15, "{x:?}");
        // a singular matrix is told
        assert!(!lu.refactor(SparseColMatRef::new(pattern, &[1.0, 1.0, 1.0, 1.0])));
    }
}
