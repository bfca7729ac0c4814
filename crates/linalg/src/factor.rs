//! Sparse Cholesky (`L Lᵀ`, SPD) and `L D Lᵀ` (quasi-definite) factorisations over faer's
//! low-level API: the symbolic analysis is done once, the numeric factorisation can be redone
//! in place when the values change, and solves reuse their workspace (no allocation).

use crate::progress::FactorProgress;
use crate::tree::Breakdown;
use crate::LinalgError;
use crate::ShapeError;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::simplicial::SymbolicSimplicialCholesky;
use faer::sparse::linalg::cholesky::supernodal::{SupernodalLdltRef, SymbolicSupernodalCholesky};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

/// Below this `|pivot| / |diagonal entry|` a factorisation reports the matrix singular to
/// working precision ([`LinalgError::NearlySingular`]).
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-13;

/// The parallelism of rayon's current pool for a factorisation: `Par::rayon` over all of the
/// pool's threads (`RAYON_NUM_THREADS`, else the cores; one included). An `L D Lᵀ` given it
/// walks its elimination tree on the pool, independent subtrees on different threads where
/// there are several ([`SparseFactor::parallel_tree`]); given [`Par::Seq`] it is faer's
/// sequential walk.
pub fn pool_par() -> Par {
    Par::rayon(rayon::current_num_threads().max(1))
}

/// Which factorisation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FactorKind {
    /// `L Lᵀ`: the matrix must be symmetric positive definite.
    Cholesky,
    /// `L D Lᵀ` without pivoting: any symmetric ordering of a quasi-definite matrix works.
    Ldlt,
}

/// The fill-reducing ordering.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Ordering {
    /// Approximate minimum degree on the whole matrix.
    #[default]
    Amd,
    /// AMD on every index but `last`, which come last in the given order (for example the
    /// contact dofs, so that the trailing block of the factor is their Schur complement).
    AmdThenLast(Vec<usize>),
    /// A given permutation, `fwd[new] = old` (for example AMD on the mesh's node graph,
    /// expanded to each node's dofs).
    Given(Vec<usize>),
    /// A given permutation (`order`, `fwd[new] = old`) with the indices of `last` taken out of
    /// it and put last, in the given order (for example nested dissection of the mesh with the
    /// contact dofs last; measured cheaper than [`Ordering::AmdThenLast`] on 2D meshes).
    GivenThenLast {
        /// The permutation of all indices.
        order: Vec<usize>,
        /// The indices to put last.
        last: Vec<usize>,
    },
}

/// A sparse symmetric factorisation with its workspaces. Only the lower triangle of the matrix
/// is read.
pub struct SparseFactor {
    kind: FactorKind,
    symbolic: Analysis,
    values: crate::values::Values,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    solve_mem_ncols: usize,
    par: Par,
    /// The supernodes' tree, where the numeric `L D Lᵀ` runs on several cores.
    tree: Option<crate::tree::Tree>,
    /// The smallest `|pivot| / |diagonal entry|` of the last numeric factorisation.
    pivot_ratio: f64,
    /// Wall time of the last numeric factorisation, s.
    numeric_seconds: f64,
}

impl std::fmt::Debug for SparseFactor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "SparseFactor({:?}, n = {}, len = {})",
            self.kind,
            self.n(),
            self.values.len()
        )
    }
}

impl SparseFactor {
    /// Analyses and factors `a` (square; the lower triangle is read).
    ///
    /// `par`: with `Par::rayon(t)` an `L D Lᵀ` walks its elimination tree on rayon's current
    /// pool (independent subtrees at the same time, the large supernodes above them with
    /// faer's parallel dense kernels; [`pool_par`] picks it from the pool), and a given order
    /// is analysed here (made a postorder of its elimination tree, the column counts in time
    /// about proportional to the matrix's entries: `docs/theory.md`); otherwise (`Par::Seq`,
    /// `L Lᵀ`) the analysis and the factorisation are faer's.
    ///
    /// # Errors
    /// A non-square or non-finite matrix, an ordering that is not a permutation, a failed
    /// symbolic analysis, or a matrix that is not (quasi-)definite.
    pub fn new(
        a: SparseColMatRef<'_, usize, f64>,
        kind: FactorKind,
        ordering: &Ordering,
        par: Par,
    ) -> Result<Self, LinalgError> {
        Self::new_within(a, kind, ordering, par, None)
    }

    /// As [`SparseFactor::new`], refusing with [`LinalgError::TooLarge`] before any numeric work
    /// where the factor and its workspace (known after the symbolic analysis) would take more
    /// than `budget` bytes.
    ///
    /// # Errors
    /// As [`SparseFactor::new`], and [`LinalgError::TooLarge`].
    pub fn new_within(
        a: SparseColMatRef<'_, usize, f64>,
        kind: FactorKind,
        ordering: &Ordering,
        par: Par,
        budget: Option<usize>,
    ) -> Result<Self, LinalgError> {
        Self::new_watched(a, kind, ordering, (par, budget), None)
    }

    /// As [`SparseFactor::new_within`] (`par`, `budget`), the numeric factorisation's progress
    /// kept in `progress` as it goes.
    ///
    /// # Errors
    /// As [`SparseFactor::new_within`].
    pub fn new_watched(
        a: SparseColMatRef<'_, usize, f64>,
        kind: FactorKind,
        ordering: &Ordering,
        (par, budget): (Par, Option<usize>),
        progress: Option<&FactorProgress>,
    ) -> Result<Self, LinalgError> {
        let n = a.nrows();
        if n != a.ncols() {
            return Err(ShapeError::NotSquare {
                rows: n,
                cols: a.ncols(),
            }
            .into());
        }
        if let Some(i) = a.val().iter().position(|x| !x.is_finite()) {
            return Err(LinalgError::NonFinite {
                what: format!("matrix entry {i}"),
            });
        }
        let wants_tree = kind == FactorKind::Ldlt && matches!(par, Par::Rayon(_));
        let (fwd, inv, kept, etree) = resolve_order(a, ordering, wants_tree)?;
        let (symbolic, tree) = match etree.and_then(|parent| own_analysis(a, fwd.clone(), &inv, &parent).transpose()) {
            Some(own) => {
                let (symbolic, tree) = own?;
                (symbolic, Some(tree))
            }
            None => faer_analysis(a, ordering, (&fwd, &inv, kept), wants_tree)?,
        };
        let (factor_req, solve_req) = match (&symbolic, kind) {
            (Analysis::Own { sym, .. }, _) => (StackReq::EMPTY, sym.solve_in_place_scratch::<f64>(1, Par::Seq)),
            (Analysis::Faer(s), FactorKind::Cholesky) => (
                s.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
                s.solve_in_place_scratch::<f64>(1, par),
            ),
            (Analysis::Faer(s), FactorKind::Ldlt) => (
                s.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
                s.solve_in_place_scratch::<f64>(1, par),
            ),
        };
        let needed = 8 * symbolic.len_val() + factor_req.size_bytes() + solve_req.size_bytes();
        if let Some(budget) = budget.filter(|&b| needed > b) {
            return Err(LinalgError::TooLarge { needed, budget });
        }
        let solve_mem = MemBuffer::new(solve_req);
        let mut f = SparseFactor {
            kind,
            values: crate::values::Values::zeros(symbolic.len_val()),
            symbolic,
            factor_mem: MemBuffer::new(if tree.is_some() { StackReq::EMPTY } else { factor_req }),
            solve_mem,
            solve_mem_ncols: 1,
            par,
            tree,
            pivot_ratio: f64::NAN,
            numeric_seconds: 0.0,
        };
        f.refactor_watched(a, progress)?;
        Ok(f)
    }

    /// Factors again, in place, a matrix with the same pattern and new values.
    ///
    /// # Errors
    /// A matrix that is not (quasi-)definite, or non-finite values in the factor.
    pub fn refactor(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), LinalgError> {
        self.refactor_watched(a, None)
    }

    /// [`SparseFactor::refactor`], its progress kept in `progress`.
    fn refactor_watched(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        progress: Option<&FactorProgress>,
    ) -> Result<(), LinalgError> {
        let started = std::time::Instant::now();
        let done = self.numeric(a, progress);
        self.numeric_seconds = started.elapsed().as_secs_f64();
        done
    }

    /// The numeric factorisation of [`SparseFactor::refactor_watched`].
    fn numeric(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        progress: Option<&FactorProgress>,
    ) -> Result<(), LinalgError> {
        let stack = MemStack::new(&mut self.factor_mem);
        match self.kind {
            FactorKind::Cholesky => {
                let Analysis::Faer(symbolic) = &self.symbolic else {
                    unreachable!("an L Lᵀ stands on faer's analysis");
                };
                symbolic
                    .factorize_numeric_llt(
                        &mut self.values,
                        a,
                        Side::Lower,
                        LltRegularization::default(),
                        self.par,
                        stack,
                        Default::default(),
                    )
                    .map_err(|e| match e {
                        faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => {
                            LinalgError::NotPositiveDefinite {
                                pivot: original(&self.symbolic, index),
                            }
                        }
                    })?;
            }
            FactorKind::Ldlt => match (self.tree.as_ref(), self.symbolic.supernodal(), &self.symbolic) {
                (Some(tree), Some(sym), _) => {
                    // the tree checks each supernode's values as it factors it
                    tree.factor(sym, a, &mut self.values, (self.par, progress))
                        .map_err(|b| match b {
                            Breakdown::ZeroPivot(index) => LinalgError::ZeroPivot {
                                pivot: original(&self.symbolic, index),
                            },
                            Breakdown::NonFinite(i) => non_finite_entry(i),
                        })?;
                }
                (_, _, Analysis::Own { .. }) => unreachable!("this crate's analysis comes with its tree"),
                (_, _, Analysis::Faer(symbolic)) => {
                    symbolic
                        .factorize_numeric_ldlt(
                            &mut self.values,
                            a,
                            Side::Lower,
                            LdltRegularization::default(),
                            self.par,
                            stack,
                            Default::default(),
                        )
                        .map_err(|e| match e {
                            faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index } => {
                                LinalgError::ZeroPivot {
                                    pivot: original(&self.symbolic, index),
                                }
                            }
                        })?;
                }
            },
        }
        if self.tree.is_none() {
            if let Some(i) = crate::tree::first_non_finite(&self.values, self.par) {
                return Err(non_finite_entry(i));
            }
        }
        // a pivot that kept fewer than 3 significant digits of its diagonal entry (the rest
        // cancelled): the matrix is singular to working precision. The ratio is free of the
        // units (a diagonal scaling of the matrix scales both alike).
        let (ratio, at) = self.smallest_pivot_ratio(a);
        self.pivot_ratio = ratio;
        if ratio < SINGULAR_PIVOT_RATIO {
            return Err(LinalgError::NearlySingular { index: at, ratio });
        }
        Ok(())
    }

    /// The floating-point operations of a numeric factorisation, as the tree's `L D Lᵀ` counts
    /// them (per column of a supernode of `c` rows below and at it, `c (c + 3)`: its update's
    /// multiply-adds and the column's scaling); `None` for a factorisation faer walks.
    pub fn flops(&self) -> Option<f64> {
        self.tree.as_ref().map(crate::tree::Tree::work_total)
    }

    /// Wall time of the last numeric factorisation, s (the analysis left out).
    pub fn numeric_seconds(&self) -> f64 {
        self.numeric_seconds
    }

    /// The smallest `|pivot| / |diagonal entry|` of the last numeric factorisation: a measure of
    /// how close to singular the matrix is (1 for a diagonal matrix; below
    /// [`SINGULAR_PIVOT_RATIO`] the factorisation is refused).
    pub fn pivot_ratio(&self) -> f64 {
        self.pivot_ratio
    }

    /// The smallest `|d_i| / |a_ii|` over the pivots (`l_ii² / a_ii` for `L Lᵀ`), with the
    /// original index where it occurs.
    pub fn smallest_pivot_ratio(&self, a: SparseColMatRef<'_, usize, f64>) -> (f64, usize) {
        let fwd = self.permutation();
        let pivots = self.pivots();
        let mut best = (f64::INFINITY, 0);
        for (new, &old) in fwd.iter().enumerate() {
            let col = a.symbolic().row_idx_of_col_raw(old);
            let diag = col
                .iter()
                .position(|&r| r == old)
                .map_or(0.0, |k| a.val_of_col(old)[k].abs());
            let d = match self.kind {
                FactorKind::Ldlt => pivots[new].abs(),
                FactorKind::Cholesky => pivots[new] * pivots[new],
            };
            let ratio = if diag > 0.0 { d / diag } else { f64::INFINITY };
            if ratio < best.0 {
                best = (ratio, old);
            }
        }
        best
    }

    /// The tree, the supernodal symbolic factor and the values, where the factorisation walked
    /// the tree (for the tree's own tests).
    #[cfg(test)]
    pub(crate) fn tree_parts(
        &self,
    ) -> Option<(
        &crate::tree::Tree,
        &faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
        &[f64],
    )> {
        Some((self.tree.as_ref()?, self.symbolic.supernodal()?, &self.values))
    }

    /// Whether the numeric factorisation walks the supernodes' elimination tree on rayon's
    /// pool (a supernodal `L D Lᵀ` given `Par::rayon`; on several threads independent subtrees
    /// are factored at the same time), rather than faer's sequential walk.
    pub fn parallel_tree(&self) -> bool {
        self.tree.is_some()
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Number of stored factor values (about 10 % more than nnz(L) for a supernodal factor).
    pub fn factor_len(&self) -> usize {
        self.values.len()
    }

    /// Floating-point operations of one numeric factorisation, counted as
    /// `Σ_j c_j (c_j + 3)`, with `c_j` the number of entries below the diagonal of column `j`
    /// of `L` (a multiply-add counts two; the count of George and Liu's book). With the time
    /// of [`SparseFactor::refactor`] it gives the achieved rate.
    pub fn factor_flops(&self) -> f64 {
        match self.symbolic.raw() {
            Raw::Supernodal(s) => (0..s.n_supernodes())
                .map(|k| {
                    let w = s.supernode_end()[k] - s.supernode_begin()[k];
                    let p = s.col_ptr_for_row_idx()[k + 1] - s.col_ptr_for_row_idx()[k];
                    (0..w)
                        .map(|j| {
                            let c = (w - 1 - j + p) as f64;
                            c * (c + 3.0)
                        })
                        .sum::<f64>()
                })
                .sum(),
            Raw::Simplicial(s) => {
                let cp = s.col_ptr();
                (0..cp.len() - 1)
                    .map(|j| {
                        // the simplicial pattern stores the diagonal first
                        let c = (cp[j + 1] - cp[j]).saturating_sub(1) as f64;
                        c * (c + 3.0)
                    })
                    .sum()
            }
        }
    }

    /// Bytes held by the factor's values (the symbolic structure and workspaces come on top;
    /// the driver measures the process's peak memory for the whole picture).
    pub fn values_bytes(&self) -> usize {
        8 * self.values.len()
    }

    /// Solves `M x = rhs` in place (`x` holds the right-hand side on entry).
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        let n = self.n();
        let mat = MatMut::from_column_major_slice_mut(x, n, 1);
        self.solve_mat(mat);
    }

    /// Solves with every column of `rhs` at once (blocks of right-hand sides cost several
    /// times less per column than one at a time).
    pub fn solve_many(&mut self, rhs: MatMut<'_, f64>) {
        self.solve_mat(rhs);
    }

    fn solve_mat(&mut self, mut rhs: MatMut<'_, f64>) {
        let k = rhs.ncols();
        let n = self.n();
        if let Analysis::Own { sym, fwd } = &self.symbolic {
            if rayon::current_num_threads() == 1 {
                // one thread: faer's sequential sweeps, which read the factor in order (the
                // tree's forward sweep gathers from each supernode's descendants), on the
                // right-hand sides permuted into the factor's order
                let mut x = vec![0.0; n * k];
                for j in 0..k {
                    for (new, &old) in fwd.iter().enumerate() {
                        x[j * n + new] = rhs[(old, j)];
                    }
                }
                if k > self.solve_mem_ncols {
                    self.solve_mem = MemBuffer::new(sym.solve_in_place_scratch::<f64>(k, Par::Seq));
                    self.solve_mem_ncols = k;
                }
                let xm = MatMut::from_column_major_slice_mut(&mut x, n, k);
                SupernodalLdltRef::new(sym, &self.values).solve_in_place_with_conj(
                    Conj::No,
                    xm,
                    Par::Seq,
                    MemStack::new(&mut self.solve_mem),
                );
                for j in 0..k {
                    for (new, &old) in fwd.iter().enumerate() {
                        rhs[(old, j)] = x[j * n + new];
                    }
                }
                return;
            }
        }
        if let (Some(tree), Some(sym)) = (self.tree_sweeps(), self.symbolic.supernodal()) {
            // the tree's sweeps, on the right-hand sides permuted into the factor's order,
            // index by index (on one thread faer's sweeps, above or below)
            let fwd = self.permutation();
            let mut x = Vec::with_capacity(fwd.len() * k);
            for &old in &fwd {
                x.extend((0..k).map(|j| rhs[(old, j)]));
            }
            tree.solve(sym, &self.values, &mut x, k);
            for (new, &old) in fwd.iter().enumerate() {
                for j in 0..k {
                    rhs[(old, j)] = x[new * k + j];
                }
            }
            return;
        }
        let Analysis::Faer(symbolic) = &self.symbolic else {
            unreachable!("this crate's analysis comes with its tree");
        };
        if k > self.solve_mem_ncols {
            self.solve_mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(k, self.par));
            self.solve_mem_ncols = k;
        }
        let stack = MemStack::new(&mut self.solve_mem);
        match self.kind {
            FactorKind::Cholesky => {
                LltRef::new(symbolic, &self.values).solve_in_place_with_conj(Conj::No, rhs, self.par, stack)
            }
            FactorKind::Ldlt => {
                LdltRef::new(symbolic, &self.values).solve_in_place_with_conj(Conj::No, rhs, self.par, stack)
            }
        }
    }

    /// The pivots of the factor (the diagonal of `D` for `L D Lᵀ`, of `L` for `L Lᵀ`), in the
    /// factor's (permuted) order.
    pub fn pivots(&self) -> Vec<f64> {
        let mut d = Vec::with_capacity(self.n());
        match self.symbolic.raw() {
            Raw::Simplicial(s) => {
                let (cp, ri) = (s.col_ptr(), s.row_idx());
                for j in 0..self.n() {
                    // the diagonal is stored first in each column
                    debug_assert_eq!(ri[cp[j]], j);
                    d.push(self.values[cp[j]]);
                }
            }
            Raw::Supernodal(s) => {
                let (begin, end) = (s.supernode_begin(), s.supernode_end());
                let (cp_row, cp_val) = (s.col_ptr_for_row_idx(), s.col_ptr_for_val());
                for k in 0..s.n_supernodes() {
                    let w = end[k] - begin[k];
                    let rows = w + (cp_row[k + 1] - cp_row[k]);
                    let block = &self.values[cp_val[k]..cp_val[k + 1]];
                    for j in 0..w {
                        d.push(block[j * rows + j]);
                    }
                }
            }
        }
        d
    }

    /// The inverse of the Schur complement onto the last `k` indices of the factor's order,
    /// `S_c⁻¹ = L_cc⁻ᵀ D_c⁻¹ L_cc⁻¹` (dense, row-major `k x k`): the block of the matrix's
    /// inverse on the last `k` indices, with no further factorisation (one unit-triangular
    /// inverse and one product of the two triangles by dense row blocks, `2k³/3` flops).
    /// `None` unless the factor is a supernodal `L D Lᵀ` whose last supernode holds all `k`
    /// columns;
    /// [`LinalgError::NotPositiveDefinite`] where a pivot of the block has not the sign of its
    /// kind: the pivots of a quasi-definite matrix, in any order, are positive on its
    /// positive-definite dofs and negative on the others (Vanderbei, SIAM J. Optim. 5 (1995));
    /// `negative(j)` says which the block's `j`-th index is.
    pub(crate) fn trailing_schur_inverse(
        &self,
        k: usize,
        negative: &dyn Fn(usize) -> bool,
    ) -> Result<Option<Vec<f64>>, LinalgError> {
        let Some(l) = self.trailing_block(k) else {
            return Ok(None);
        };
        let d: Vec<f64> = (0..k).map(|j| l[(j, j)]).collect();
        let wrong_sign = |j: usize, x: f64| if negative(j) { !(x < 0.0) } else { !(x > 0.0) };
        if let Some(j) = (0..k).find(|&j| wrong_sign(j, d[j])) {
            return Err(LinalgError::NotPositiveDefinite {
                pivot: original(&self.symbolic, self.n() - k + j),
            });
        }
        // fresh zero pages (the strict upper part stays zero), touched first by faer's kernels
        let mut x = vec![0.0; k * k];
        let mut xm = MatMut::from_column_major_slice_mut(&mut x, k, k);
        faer::linalg::triangular_inverse::invert_unit_lower_triangular(xm.rb_mut(), l, self.par);
        // the unit diagonal is implied, not necessarily written
        for j in 0..k {
            xm[(j, j)] = 1.0;
        }
        Ok(Some(crate::dense::unit_lower_gram(xm.rb(), &d)))
    }

    /// The trailing `k x k` corner of the factor, `D_c` on its diagonal and `L_cc` below it (a
    /// view into the last supernode), when the factor is a supernodal `L D Lᵀ` whose last
    /// supernode holds the last `k` columns.
    fn trailing_block(&self, k: usize) -> Option<faer::MatRef<'_, f64>> {
        if self.kind != FactorKind::Ldlt || k == 0 || k > self.n() {
            return None;
        }
        let s = self.symbolic.supernodal()?;
        let last = s.n_supernodes().checked_sub(1)?;
        let (begin, end) = (s.supernode_begin()[last], s.supernode_end()[last]);
        if end != self.n() || begin > self.n() - k {
            return None;
        }
        let w = end - begin;
        let rows = w + (s.col_ptr_for_row_idx()[last + 1] - s.col_ptr_for_row_idx()[last]);
        let block = &self.values[s.col_ptr_for_val()[last]..s.col_ptr_for_val()[last + 1]];
        let off = w - k;
        Some(faer::MatRef::from_column_major_slice_with_stride(
            &block[off * rows + off..],
            k,
            k,
            rows,
        ))
    }

    /// The forward half of an `L D Lᵀ` solve: `y = L⁻¹ P x` (in the factor's order), for a
    /// supernodal `L D Lᵀ` (`None` otherwise). With [`SparseFactor::backward`] it is
    /// [`SparseFactor::solve_in_place`]; split, a right-hand side that differs from a solved one
    /// only on the trailing indices needs no second forward sweep
    /// ([`SparseFactor::forward_update_trailing`]).
    pub(crate) fn forward(&self, x: &[f64]) -> Option<Vec<f64>> {
        let (sym, fwd) = self.supernodal_ldlt()?;
        let mut y: Vec<f64> = fwd.iter().map(|&old| x[old]).collect();
        if let Some(tree) = self.tree_sweeps() {
            tree.forward(sym, &self.values, &mut y, 1);
            return Some(y);
        }
        let f = SupernodalLdltRef::new(sym, &self.values);
        let mut ym = MatMut::from_column_major_slice_mut(&mut y, self.n(), 1);
        let mut tmp = vec![];
        for s in 0..sym.n_supernodes() {
            let node = f.supernode(s);
            let ls = node.val();
            let w = ls.ncols();
            let (top, bot) = ls.split_at_row(w);
            let mut x_top = ym.rb_mut().subrows_mut(node.start(), w);
            faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(top, x_top.rb_mut(), Par::Seq);
            let pattern = node.pattern();
            tmp.clear();
            tmp.resize(pattern.len(), 0.0);
            let mut t = MatMut::from_column_major_slice_mut(&mut tmp, pattern.len(), 1);
            faer::linalg::matmul::matmul(t.rb_mut(), faer::Accum::Replace, bot, x_top.rb(), 1.0, Par::Seq);
            for (k, &i) in pattern.iter().enumerate() {
                ym[(i, 0)] -= tmp[k];
            }
        }
        Some(y)
    }

    /// Adds `L_cc⁻¹ d` to the last `d.len()` entries of a forward result `y`: `y` becomes the
    /// forward half of the right-hand side plus `d` on the last indices of the factor's order
    /// (`L` is block lower triangular, so such a change reaches no earlier index). `false`
    /// where the trailing indices are not all in the last supernode.
    pub(crate) fn forward_update_trailing(&self, y: &mut [f64], d: &[f64]) -> bool {
        let Some(z) = self.trailing_forward(d) else {
            return false;
        };
        let n = self.n();
        for (yi, zi) in y[n - d.len()..].iter_mut().zip(&z) {
            *yi += zi;
        }
        true
    }

    /// `L_cc⁻¹ d`: the forward half, on the last `d.len()` indices of the factor's order, of a
    /// right-hand side that is `d` there and zero elsewhere (`L` is block lower triangular, so
    /// it is zero on every earlier index). `None` where those indices are not all in the last
    /// supernode.
    pub(crate) fn trailing_forward(&self, d: &[f64]) -> Option<Vec<f64>> {
        let k = d.len();
        let l = self.trailing_block(k)?;
        let mut z = d.to_vec();
        let zm = MatMut::from_column_major_slice_mut(&mut z, k, 1);
        faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(l, zm, Par::Seq);
        Some(z)
    }

    /// The last `k` entries of the solution `Pᵀ L⁻ᵀ D⁻¹ y` (in the factor's order), from the
    /// trailing block alone (`L⁻ᵀ` is block upper triangular): the solution on the trailing
    /// indices for the price of a dense `k x k` triangular solve. `None` where the last `k`
    /// indices are not all in the last supernode.
    pub(crate) fn trailing_backward(&self, y: &[f64], k: usize) -> Option<Vec<f64>> {
        let l = self.trailing_block(k)?;
        let n = self.n();
        let mut z: Vec<f64> = (0..k).map(|j| y[n - k + j] / l[(j, j)]).collect();
        let zm = MatMut::from_column_major_slice_mut(&mut z, k, 1);
        faer::linalg::triangular_solve::solve_unit_upper_triangular_in_place(l.transpose(), zm, Par::Seq);
        Some(z)
    }

    /// The backward half of an `L D Lᵀ` solve: `x = Pᵀ L⁻ᵀ D⁻¹ y` from a forward result `y`
    /// (consumed). `None` unless the factor is a supernodal `L D Lᵀ`.
    pub(crate) fn backward(&self, mut y: Vec<f64>) -> Option<Vec<f64>> {
        let (sym, fwd) = self.supernodal_ldlt()?;
        let n = self.n();
        match self.tree_sweeps() {
            Some(tree) => tree.backward(sym, &self.values, &mut y, 1),
            None => {
                let f = SupernodalLdltRef::new(sym, &self.values);
                let mut ym = MatMut::from_column_major_slice_mut(&mut y, n, 1);
                for s in 0..sym.n_supernodes() {
                    let node = f.supernode(s);
                    let ls = node.val();
                    for j in 0..ls.ncols() {
                        ym[(node.start() + j, 0)] /= ls[(j, j)];
                    }
                }
                let mut tmp = vec![];
                for s in (0..sym.n_supernodes()).rev() {
                    let node = f.supernode(s);
                    let ls = node.val();
                    let w = ls.ncols();
                    let (top, bot) = ls.split_at_row(w);
                    let pattern = node.pattern();
                    tmp.clear();
                    tmp.extend(pattern.iter().map(|&i| ym[(i, 0)]));
                    let t = faer::MatRef::from_column_major_slice(&tmp, pattern.len(), 1);
                    let mut x_top = ym.rb_mut().subrows_mut(node.start(), w);
                    faer::linalg::matmul::matmul(x_top.rb_mut(), faer::Accum::Add, bot.transpose(), t, -1.0, Par::Seq);
                    faer::linalg::triangular_solve::solve_unit_upper_triangular_in_place(
                        top.transpose(),
                        x_top,
                        Par::Seq,
                    );
                }
            }
        }
        let mut x = vec![0.0; n];
        for (new, &old) in fwd.iter().enumerate() {
            x[old] = y[new];
        }
        Some(x)
    }

    /// The backward halves of several solves at once: `x_j = Pᵀ L⁻ᵀ D⁻¹ y_j` for the `k`
    /// forward results in `y` (in the factor's order, index by index: `y[i k + j]`, consumed),
    /// returned column by column in the original order. One sweep reads the factor once for
    /// every column (on the tree where it solves, else column by column). `None` unless the
    /// factor is a supernodal `L D Lᵀ`.
    pub(crate) fn backward_many(&self, mut y: Vec<f64>, k: usize) -> Option<Vec<Vec<f64>>> {
        let (sym, fwd) = self.supernodal_ldlt()?;
        let n = self.n();
        if let Some(tree) = self.tree_sweeps() {
            tree.backward(sym, &self.values, &mut y, k);
            let mut out = vec![vec![0.0; n]; k];
            for (new, &old) in fwd.iter().enumerate() {
                for (j, x) in out.iter_mut().enumerate() {
                    x[old] = y[new * k + j];
                }
            }
            return Some(out);
        }
        (0..k)
            .map(|j| self.backward((0..n).map(|i| y[i * k + j]).collect()))
            .collect()
    }

    /// The tree, where its sweeps solve: a factor made on it, solved on a pool of several
    /// threads (on one, faer's sequential sweeps read the factor in order, and are faster).
    fn tree_sweeps(&self) -> Option<&crate::tree::Tree> {
        self.tree.as_ref().filter(|_| rayon::current_num_threads() > 1)
    }

    /// The supernodal symbolic factor and the permutation, for an `L D Lᵀ`.
    fn supernodal_ldlt(
        &self,
    ) -> Option<(
        &faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
        Vec<usize>,
    )> {
        if self.kind != FactorKind::Ldlt {
            return None;
        }
        Some((self.symbolic.supernodal()?, self.permutation()))
    }

    /// `(positive, negative, zero)` pivot counts of an `L D Lᵀ` factor: by Sylvester's law the
    /// inertia of the matrix.
    pub fn inertia(&self) -> (usize, usize, usize) {
        let p = self.pivots();
        (
            p.iter().filter(|&&x| x > 0.0).count(),
            p.iter().filter(|&&x| x < 0.0).count(),
            p.iter().filter(|&&x| x == 0.0).count(),
        )
    }

    /// The fill-reducing permutation, `fwd[new] = old`.
    pub fn permutation(&self) -> Vec<usize> {
        match self.symbolic.fwd() {
            Some(fwd) => fwd.to_vec(),
            None => (0..self.n()).collect(),
        }
    }
}

/// A NaN or an infinity at entry `i` of the factor's values: an overflow.
fn non_finite_entry(i: usize) -> LinalgError {
    LinalgError::NonFinite {
        what: format!("factor entry {i} (overflow)"),
    }
}

/// The order `ordering` asks for as `(fwd, inv, kept)` (`fwd[new] = old`, `inv` its inverse,
/// both empty for faer's own AMD; `kept` indices ordered last), made a postorder of its
/// elimination tree where `postorder` (the tree's schedule) and that keeps the last ones last;
/// then with the tree in that order (`parent[k]`, `usize::MAX` for a root).
#[allow(clippy::type_complexity)]
fn resolve_order(
    a: SparseColMatRef<'_, usize, f64>,
    ordering: &Ordering,
    postorder: bool,
) -> Result<(Vec<usize>, Vec<usize>, usize, Option<Vec<usize>>), LinalgError> {
    let n = a.nrows();
    let (fwd, inv, kept) = match ordering {
        Ordering::Amd => (vec![], vec![], 0),
        Ordering::AmdThenLast(last) => {
            let (f, i) = amd_then_last(a, last)?;
            (f, i, last.len())
        }
        Ordering::Given(given) => (given.clone(), inverse_permutation(given)?, 0),
        Ordering::GivenThenLast { order, last } => {
            let is_last = mark(n, last)?;
            let mut f: Vec<usize> = order.iter().copied().filter(|&i| i >= n || !is_last[i]).collect();
            f.extend_from_slice(last);
            let i = inverse_permutation(&f)?;
            (f, i, last.len())
        }
    };
    // the parallel tree walks subtrees that are contiguous: the order made a postorder of
    // its elimination tree first (the same fill), where that keeps the chosen last dofs last
    let post = if postorder {
        crate::tree::postordered(a, &fwd, &inv)
    } else {
        None
    };
    Ok(match post {
        Some((post, parent)) if post[n - kept..] == fwd[n - kept..] => {
            let post_inv = inverse_permutation(&post)?;
            (post, post_inv, kept, Some(parent))
        }
        _ => (fwd, inv, kept, None),
    })
}

/// This crate's analysis for the tree's walk (`fwd`, `inv`: an order that is a postorder of
/// its elimination tree `parent`): the column counts and supernodes, with the matrix's lower
/// triangle in that order ([`crate::tree::supernodal`]), and the tree. `None` where the
/// supernodes are not in postorder (not expected of a postordered tree; faer's analysis then
/// takes over).
fn own_analysis(
    a: SparseColMatRef<'_, usize, f64>,
    fwd: Vec<usize>,
    inv: &[usize],
    parent: &[usize],
) -> Result<Option<(Analysis, crate::tree::Tree)>, LinalgError> {
    let (sym, lower) = crate::tree::supernodal(a, inv, parent)?;
    Ok(crate::tree::Tree::new(&sym, a, Some(inv), Some(lower)).map(|tree| (Analysis::Own { sym, fwd }, tree)))
}

/// faer's analysis of `a` in the order `(fwd, inv)` (faer's AMD where `ordering` is
/// [`Ordering::Amd`]), with the tree for the parallel walk where `wants_tree`
/// ([`parallel_tree`]); `kept`: the number of indices ordered last.
fn faer_analysis(
    a: SparseColMatRef<'_, usize, f64>,
    ordering: &Ordering,
    (fwd, inv, kept): (&[usize], &[usize], usize),
    wants_tree: bool,
) -> Result<(Analysis, Option<crate::tree::Tree>), LinalgError> {
    let n = a.nrows();
    let ord = match ordering {
        Ordering::Amd => SymmetricOrdering::Amd,
        _ => SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, n)),
    };
    // chosen dofs last are there to be read off the last supernode: force supernodal
    let params = match ordering {
        Ordering::AmdThenLast(_) | Ordering::GivenThenLast { .. } => CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
        _ => CholeskySymbolicParams::default(),
    };
    let symbolic = factorize_symbolic_cholesky(a.symbolic(), Side::Lower, ord, params)
        .map_err(|e| LinalgError::Symbolic(format!("{e:?}")))?;
    if !wants_tree {
        return Ok((Analysis::Faer(symbolic), None));
    }
    let (symbolic, tree) = parallel_tree(a, symbolic, params, kept)?;
    Ok((Analysis::Faer(symbolic), tree))
}

/// The symbolic analysis a factor stands on.
enum Analysis {
    /// faer's whole analysis: its AMD, `L Lᵀ`, a simplicial factor, faer's sequential walk
    /// (`Par::Seq`), or an order whose postorder would move the indices asked last.
    Faer(SymbolicCholesky<usize>),
    /// This crate's, for the tree's walk: a supernodal `L D Lᵀ` in a given order made a
    /// postorder of its elimination tree (`fwd[new] = old`).
    Own {
        sym: SymbolicSupernodalCholesky<usize>,
        fwd: Vec<usize>,
    },
}

/// A symbolic factor's structure: supernodal or simplicial.
enum Raw<'a> {
    Supernodal(&'a SymbolicSupernodalCholesky<usize>),
    Simplicial(&'a SymbolicSimplicialCholesky<usize>),
}

impl Analysis {
    fn nrows(&self) -> usize {
        match self {
            Analysis::Faer(s) => s.nrows(),
            Analysis::Own { sym, .. } => sym.nrows(),
        }
    }

    fn len_val(&self) -> usize {
        match self {
            Analysis::Faer(s) => s.len_val(),
            Analysis::Own { sym, .. } => sym.len_val(),
        }
    }

    fn raw(&self) -> Raw<'_> {
        match self {
            Analysis::Faer(s) => match s.raw() {
                SymbolicCholeskyRaw::Supernodal(s) => Raw::Supernodal(s),
                SymbolicCholeskyRaw::Simplicial(s) => Raw::Simplicial(s),
            },
            Analysis::Own { sym, .. } => Raw::Supernodal(sym),
        }
    }

    fn supernodal(&self) -> Option<&SymbolicSupernodalCholesky<usize>> {
        match self.raw() {
            Raw::Supernodal(s) => Some(s),
            Raw::Simplicial(_) => None,
        }
    }

    /// The order, `fwd[new] = old` (`None`: the identity).
    fn fwd(&self) -> Option<&[usize]> {
        match self {
            Analysis::Faer(s) => s.perm().map(|p| p.arrays().0),
            Analysis::Own { fwd, .. } => Some(fwd),
        }
    }
}

/// The tree of a supernodal symbolic factor for the parallel numeric `L D Lᵀ`, the analysis
/// redone once in postorder where its supernodes were not (AMD's order, or relaxed supernodes
/// that merged across a subtree); `None` (and the analysis unchanged) for a simplicial factor,
/// or where the postorder would move the `kept` dofs ordered last.
fn parallel_tree(
    a: SparseColMatRef<'_, usize, f64>,
    symbolic: SymbolicCholesky<usize>,
    params: CholeskySymbolicParams<'_>,
    kept: usize,
) -> Result<(SymbolicCholesky<usize>, Option<crate::tree::Tree>), LinalgError> {
    let SymbolicCholeskyRaw::Supernodal(s) = symbolic.raw() else {
        return Ok((symbolic, None));
    };
    let inv = |sym: &SymbolicCholesky<usize>| sym.perm().map(|p| p.arrays().1.to_vec());
    if let Some(tree) = crate::tree::Tree::new(s, a, inv(&symbolic).as_deref(), None) {
        return Ok((symbolic, Some(tree)));
    }
    let fwd = match symbolic.perm() {
        Some(p) => p.arrays().0.to_vec(),
        None => (0..a.nrows()).collect(),
    };
    let post: Vec<usize> = crate::tree::postorder(s).into_iter().map(|k| fwd[k]).collect();
    let n = a.nrows();
    if post[n - kept..] != fwd[n - kept..] {
        // the chosen last dofs would move: faer's sequential walk keeps them
        return Ok((symbolic, None));
    }
    let post_inv = inverse_permutation(&post)?;
    let ord = SymmetricOrdering::Custom(PermRef::new_checked(&post, &post_inv, a.nrows()));
    let again = factorize_symbolic_cholesky(a.symbolic(), Side::Lower, ord, params)
        .map_err(|e| LinalgError::Symbolic(format!("{e:?}")))?;
    let tree = match again.raw() {
        SymbolicCholeskyRaw::Supernodal(s) => crate::tree::Tree::new(s, a, inv(&again).as_deref(), None),
        SymbolicCholeskyRaw::Simplicial(_) => None,
    };
    Ok((again, tree))
}

/// The matrix's index at position `new` of the factor's order (`new` itself where it is out
/// of range).
fn original(symbolic: &Analysis, new: usize) -> usize {
    symbolic.fwd().and_then(|fwd| fwd.get(new).copied()).unwrap_or(new)
}

/// The inverse of a permutation, or an error if `fwd` is not one.
fn inverse_permutation(fwd: &[usize]) -> Result<Vec<usize>, LinalgError> {
    let n = fwd.len();
    let mut inv = vec![usize::MAX; n];
    for (new, &old) in fwd.iter().enumerate() {
        if old >= n || inv[old] != usize::MAX {
            return Err(ShapeError::Ordering {
                what: "entry",
                index: old,
            }
            .into());
        }
        inv[old] = new;
    }
    Ok(inv)
}

/// A mask of `last` among `0..n`; an error names an index out of range or repeated.
fn mark(n: usize, last: &[usize]) -> Result<Vec<bool>, LinalgError> {
    let mut is_last = vec![false; n];
    for &i in last {
        if i >= n || is_last[i] {
            return Err(ShapeError::Ordering {
                what: "index",
                index: i,
            }
            .into());
        }
        is_last[i] = true;
    }
    Ok(is_last)
}

/// AMD on the indices not in `last`, then `last` in order. Returns `(fwd, inv)`.
fn amd_then_last(a: SparseColMatRef<'_, usize, f64>, last: &[usize]) -> Result<(Vec<usize>, Vec<usize>), LinalgError> {
    let n = a.nrows();
    let is_last = mark(n, last)?;
    // the pattern of the leading block, renumbered, both triangles
    let mut new_of = vec![usize::MAX; n];
    let mut old_of = Vec::with_capacity(n - last.len());
    for i in 0..n {
        if !is_last[i] {
            new_of[i] = old_of.len();
            old_of.push(i);
        }
    }
    let m = old_of.len();
    let mut cols: Vec<Vec<usize>> = vec![Vec::new(); m];
    let sym = a.symbolic();
    for j in 0..n {
        if is_last[j] {
            continue;
        }
        for &i in sym.row_idx_of_col_raw(j) {
            if !is_last[i] && i != j {
                cols[new_of[j]].push(new_of[i]);
                cols[new_of[i]].push(new_of[j]);
            }
        }
    }
    let mut col_ptr = Vec::with_capacity(m + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    for mut c in cols {
        c.sort_unstable();
        c.dedup();
        row_idx.extend_from_slice(&c);
        col_ptr.push(row_idx.len());
    }
    let nnz = row_idx.len();
    let pattern = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
    let mut perm = vec![0usize; m];
    let mut perm_inv = vec![0usize; m];
    let mut mem = MemBuffer::new(amd::order_scratch::<usize>(m, nnz));
    amd::order(
        &mut perm,
        &mut perm_inv,
        pattern.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .map_err(|e| LinalgError::Symbolic(format!("{e:?}")))?;
    let mut fwd: Vec<usize> = perm.iter().map(|&p| old_of[p]).collect();
    fwd.extend_from_slice(last);
    let mut inv = vec![0usize; n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    Ok((fwd, inv))
}
