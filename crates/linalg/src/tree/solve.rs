//! `L D Lᵀ x = b` on the supernodes' elimination tree, on every core of rayon's pool: both
//! sweeps visit the tree as the factorisation does, so that subtrees that share no supernode
//! run at the same time and each writes only its own rows.
//!
//! - Forward, `L y = b`, left-looking: supernode `s` subtracts from its rows `L_sd y_d` of
//!   every descendant `d` whose pattern meets them (the factorisation's updaters), then solves
//!   with its unit diagonal block. It reads only its finished descendants.
//! - Backward, `Lᵀ x = D⁻¹ y`, from the roots: supernode `s` takes `D_s⁻¹ y_s - L_bsᵀ x_b` (`b`
//!   its pattern's rows, all in its ancestors, finished) and solves with `L_ssᵀ`. It reads
//!   only its ancestors.
//!
//! The right-hand sides are stored index by index (row-major, `k` values per index), so that
//! the rows of a range of supernodes are one contiguous slice, split between the tasks as the
//! factor's values are.

use super::{Split, Tree};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::{Accum, MatMut, MatRef, Par};

/// Ranges of supernodes holding fewer factor values than this are solved on one core (a
/// sweep over them reads about 8 MB: 1 to 2 ms).
const SEQUENTIAL_VALUES: usize = 1 << 20;

/// Supernodes of at least this many columns use the pool in their dense kernels.
const PARALLEL_COLUMNS: usize = 512;

/// Rows of the right-hand sides finished by the backward sweep above a range of supernodes:
/// contiguous runs of indices, each with its values (row-major, `k` per index).
#[derive(Clone)]
struct Above<'a> {
    runs: Vec<(usize, &'a [f64])>,
}

impl Above<'_> {
    /// The `k` values of index `r`.
    fn row(&self, r: usize, k: usize) -> &[f64] {
        for &(start, vals) in &self.runs {
            if r >= start && (r - start) * k < vals.len() {
                return &vals[(r - start) * k..(r - start + 1) * k];
            }
        }
        unreachable!("index {r} is not an ancestor's")
    }
}

struct Solve<'a> {
    sym: &'a SymbolicSupernodalCholesky<usize>,
    tree: &'a Tree,
    values: &'a [f64],
    /// Right-hand sides.
    k: usize,
    /// Ranges with fewer factor values than this are solved in order ([`SEQUENTIAL_VALUES`]).
    sequential: usize,
}

impl Tree {
    /// Solves `L D Lᵀ x = b` in place for the `k` right-hand sides in `x` (in the factor's
    /// order, stored index by index: `x[i k + j]` is index `i` of right-hand side `j`), with
    /// `values` the factor this tree's [`Tree::factor`] wrote.
    pub(crate) fn solve(&self, sym: &SymbolicSupernodalCholesky<usize>, values: &[f64], x: &mut [f64], k: usize) {
        self.sweeps(sym, values, (x, k), SEQUENTIAL_VALUES, (true, true));
    }

    /// The forward half of [`Tree::solve`], `y = L⁻¹ b`, in place.
    pub(crate) fn forward(&self, sym: &SymbolicSupernodalCholesky<usize>, values: &[f64], x: &mut [f64], k: usize) {
        self.sweeps(sym, values, (x, k), SEQUENTIAL_VALUES, (true, false));
    }

    /// The backward half of [`Tree::solve`], `x = L⁻ᵀ D⁻¹ y`, in place.
    pub(crate) fn backward(&self, sym: &SymbolicSupernodalCholesky<usize>, values: &[f64], x: &mut [f64], k: usize) {
        self.sweeps(sym, values, (x, k), SEQUENTIAL_VALUES, (false, true));
    }

    /// The forward sweep, the backward sweep or both (`(forward, backward)`), ranges of fewer
    /// than `sequential` factor values solved in order.
    fn sweeps(
        &self,
        sym: &SymbolicSupernodalCholesky<usize>,
        values: &[f64],
        (x, k): (&mut [f64], usize),
        sequential: usize,
        (forward, backward): (bool, bool),
    ) {
        let ns = sym.n_supernodes();
        if ns == 0 || k == 0 {
            return;
        }
        let s = Solve {
            sym,
            tree: self,
            values,
            k,
            sequential,
        };
        if forward {
            s.forward(0, ns, x, 0);
        }
        if backward {
            s.backward(0, ns, x, 0, &Above { runs: vec![] });
        }
    }
}

impl Solve<'_> {
    /// The first index of supernode `s` (or the end of the last one).
    fn col(&self, s: usize) -> usize {
        if s == self.sym.n_supernodes() {
            self.sym.nrows()
        } else {
            self.sym.supernode_begin()[s]
        }
    }

    /// The factor's values of supernode `s`: its rows (its columns', then its pattern's) by its
    /// columns, column-major.
    fn block(&self, s: usize) -> MatRef<'_, f64> {
        let sym = self.sym;
        let (cpv, cp_row) = (sym.col_ptr_for_val(), sym.col_ptr_for_row_idx());
        let w = sym.supernode_end()[s] - sym.supernode_begin()[s];
        let rows = w + cp_row[s + 1] - cp_row[s];
        MatRef::from_column_major_slice(&self.values[cpv[s]..cpv[s + 1]], rows, w)
    }

    /// How the range `lo..hi` (whole subtrees) is solved: [`Tree::split`] by the factor's
    /// values, which a sweep reads once.
    fn split(&self, lo: usize, hi: usize) -> Split {
        let (cpv, t) = (self.sym.col_ptr_for_val(), self.tree);
        t.split(
            lo,
            hi,
            |r| (cpv[r + 1] - cpv[t.first[r]]) as f64,
            self.sequential as f64,
        )
    }

    /// The forward sweep over the supernodes `lo..hi` (whole subtrees), whose rows are `x`
    /// (from index `col_lo`).
    fn forward(&self, lo: usize, hi: usize, x: &mut [f64], col_lo: usize) {
        let k = self.k;
        match self.split(lo, hi) {
            Split::InOrder => {
                let mut prod = vec![];
                for s in lo..hi {
                    let (head, mine) = x.split_at_mut((self.col(s) - col_lo) * k);
                    self.forward_node(s, (head, col_lo), mine, &mut prod);
                }
            }
            Split::Root(root) => {
                let (head, mine) = x.split_at_mut((self.col(root) - col_lo) * k);
                self.forward(lo, root, head, col_lo);
                self.forward_node(root, (head, col_lo), mine, &mut vec![]);
            }
            Split::Between(mid) => {
                let (left, right) = x.split_at_mut((self.col(mid) - col_lo) * k);
                let col_mid = self.col(mid);
                rayon::join(
                    || self.forward(lo, mid, left, col_lo),
                    || self.forward(mid, hi, right, col_mid),
                );
            }
        }
    }

    /// Supernode `s`'s forward step: its rows (the start of `mine`) less `L_sd y_d` of each
    /// descendant (in `head`, from index `col_lo`), then the unit diagonal block's solve
    /// (`prod`: a buffer for the products).
    fn forward_node(&self, s: usize, (head, col_lo): (&[f64], usize), mine: &mut [f64], prod: &mut Vec<f64>) {
        let (sym, t, k) = (self.sym, self.tree, self.k);
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let (cp_row, rows) = (sym.col_ptr_for_row_idx(), sym.row_idx());
        let (s_start, s_end) = (begin[s], end[s]);
        let xs = &mut mine[..(s_end - s_start) * k];
        for &d in &t.updaters[t.upd_ptr[s]..t.upd_ptr[s + 1]] {
            let pattern = &rows[cp_row[d]..cp_row[d + 1]];
            let start = pattern.partition_point(|&r| r < s_start);
            let mid = pattern[start..].partition_point(|&r| r < s_end);
            let w = end[d] - begin[d];
            let l = self.block(d).subrows(w + start, mid);
            let yd = MatRef::from_row_major_slice(&head[(begin[d] - col_lo) * k..(end[d] - col_lo) * k], w, k);
            prod.clear();
            prod.resize(mid * k, 0.0);
            let p = MatMut::from_row_major_slice_mut(prod, mid, k);
            faer::linalg::matmul::matmul(p, Accum::Replace, l, yd, 1.0, Par::Seq);
            for (i, &r) in pattern[start..start + mid].iter().enumerate() {
                let at = (r - s_start) * k;
                for (x, p) in xs[at..at + k].iter_mut().zip(&prod[i * k..(i + 1) * k]) {
                    *x -= p;
                }
            }
        }
        let w = s_end - s_start;
        let top = self.block(s).subrows(0, w);
        let xm = MatMut::from_row_major_slice_mut(xs, w, k);
        faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(top, xm, dense_par(w));
    }

    /// The backward sweep over the supernodes `lo..hi` (whole subtrees), whose rows are `x`
    /// (from index `col_lo`), with their ancestors' rows finished in `above`.
    fn backward(&self, lo: usize, hi: usize, x: &mut [f64], col_lo: usize, above: &Above<'_>) {
        let k = self.k;
        match self.split(lo, hi) {
            Split::InOrder => {
                let mut gathered = vec![];
                for s in (lo..hi).rev() {
                    let end = self.sym.supernode_end()[s];
                    let (lower, upper) = x.split_at_mut((end - col_lo) * k);
                    let xs = &mut lower[(self.col(s) - col_lo) * k..];
                    self.backward_node(s, xs, ((end, upper), above), &mut gathered);
                }
            }
            Split::Root(root) => {
                let (below, mine) = x.split_at_mut((self.col(root) - col_lo) * k);
                self.backward_node(root, mine, ((0, &[]), above), &mut vec![]);
                let mut here = above.clone();
                here.runs.insert(0, (self.col(root), &*mine));
                self.backward(lo, root, below, col_lo, &here);
            }
            Split::Between(mid) => {
                let (left, right) = x.split_at_mut((self.col(mid) - col_lo) * k);
                let col_mid = self.col(mid);
                rayon::join(
                    || self.backward(lo, mid, left, col_lo, above),
                    || self.backward(mid, hi, right, col_mid, above),
                );
            }
        }
    }

    /// Supernode `s`'s backward step on its rows `xs`: `D_s⁻¹ y_s - L_bsᵀ x_b`, then the solve
    /// with the unit upper `L_ssᵀ`; the rows `x_b` are in `near` (a run from its first index) or
    /// else in `above`.
    fn backward_node(
        &self,
        s: usize,
        xs: &mut [f64],
        (near, above): ((usize, &[f64]), &Above<'_>),
        gathered: &mut Vec<f64>,
    ) {
        let (sym, k) = (self.sym, self.k);
        let w = sym.supernode_end()[s] - sym.supernode_begin()[s];
        let pattern = &sym.row_idx()[sym.col_ptr_for_row_idx()[s]..sym.col_ptr_for_row_idx()[s + 1]];
        let block = self.block(s);
        let (top, bot) = block.split_at_row(w);
        let mut xm = MatMut::from_row_major_slice_mut(&mut xs[..w * k], w, k);
        for i in 0..w {
            let d = top[(i, i)].recip();
            for j in 0..k {
                xm[(i, j)] *= d;
            }
        }
        if !pattern.is_empty() {
            gathered.clear();
            let (start, run) = near;
            for &r in pattern {
                let row = if r >= start && (r - start) * k < run.len() {
                    &run[(r - start) * k..(r - start + 1) * k]
                } else {
                    above.row(r, k)
                };
                gathered.extend_from_slice(row);
            }
            let xb = MatRef::from_row_major_slice(gathered, pattern.len(), k);
            faer::linalg::matmul::matmul(xm.as_mut(), Accum::Add, bot.transpose(), xb, -1.0, dense_par(w));
        }
        faer::linalg::triangular_solve::solve_unit_upper_triangular_in_place(top.transpose(), xm, dense_par(w));
    }
}

/// The dense kernels' parallelism for a supernode of `w` columns: rayon's pool for the wide
/// ones (a 3D mesh's top separators, thousands of columns, where no other task runs),
/// sequential below [`PARALLEL_COLUMNS`].
fn dense_par(w: usize) -> Par {
    if w >= PARALLEL_COLUMNS {
        crate::pool_par()
    } else {
        Par::Seq
    }
}

#[cfg(test)]
mod tests {
    use crate::{FactorKind, Ordering, SparseFactor};
    use faer::sparse::{SparseColMat, Triplet};

    /// The lower triangle of a quasi-definite matrix on an `m x m` grid: per node a
    /// displacement (positive definite Laplacian part) and a potential (negative), coupled.
    fn grid(m: usize) -> SparseColMat<usize, f64> {
        let node = |i: usize, j: usize| i * m + j;
        let n = m * m;
        let mut t = vec![];
        for i in 0..m {
            for j in 0..m {
                let a = node(i, j);
                t.push(Triplet::new(a, a, 4.5 + (a % 3) as f64));
                t.push(Triplet::new(n + a, n + a, -2.0 - (a % 5) as f64 * 0.1));
                t.push(Triplet::new(n + a, a, 0.3));
                for (di, dj) in [(1, 0), (0, 1)] {
                    if i + di < m && j + dj < m {
                        let b = node(i + di, j + dj);
                        t.push(Triplet::new(b, a, -1.0));
                        t.push(Triplet::new(n + b, n + a, 0.5));
                        t.push(Triplet::new(n + b, a, -0.1));
                    }
                }
            }
        }
        SparseColMat::try_new_from_triplets(2 * n, 2 * n, &t).unwrap()
    }

    #[test]
    fn the_tree_solve_split_everywhere_is_faers_solve() {
        let k = grid(40);
        let n = k.nrows();
        let f = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| {
                SparseFactor::new(
                    k.as_ref(),
                    FactorKind::Ldlt,
                    &Ordering::AmdThenLast(vec![]),
                    faer::Par::rayon(2),
                )
            })
            .unwrap();
        let (tree, sym, values) = f.tree_parts().expect("the tree's route");
        let ncols = 3;
        let b: Vec<f64> = (0..n * ncols).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        // faer's sequential sweeps, column by column (column-major n x ncols, factor's order)
        let mut want = b.clone();
        let ldlt = faer::sparse::linalg::cholesky::supernodal::SupernodalLdltRef::new(sym, values);
        let mut mem = faer::dyn_stack::MemBuffer::new(sym.solve_in_place_scratch::<f64>(ncols, faer::Par::Seq));
        ldlt.solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(&mut want, n, ncols),
            faer::Par::Seq,
            faer::dyn_stack::MemStack::new(&mut mem),
        );
        for (threads, sequential) in [(1, usize::MAX), (2, 1), (3, 1), (2, 5000)] {
            // index by index, as the tree takes them
            let mut x: Vec<f64> = (0..n * ncols).map(|i| b[(i % ncols) * n + i / ncols]).collect();
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| tree.sweeps(sym, values, (&mut x, ncols), sequential, (true, true)));
            let gap = (0..n * ncols)
                .map(|i| (x[i] - want[(i % ncols) * n + i / ncols]).abs())
                .fold(0.0, f64::max);
            let scale = want.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(
                gap <= 1e-12 * scale,
                "{threads} threads, split below {sequential}: {gap:e} of {scale:e}"
            );
        }
    }
}
