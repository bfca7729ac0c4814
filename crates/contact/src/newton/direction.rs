//! The Newton direction `J δ = -f`, three ways: on a dense symmetric positive definite
//! compliance, through `y = C δ` on the rows of the sliding and separated points only (the
//! stiffness `(D + σ W⁻¹)⁻¹` once per problem); on any dense compliance, by one LU of the whole
//! Jacobian; on a sparse compliance, by a sparse LU of the Jacobian (whose rows are sparse
//! combinations of the compliance's rows), so that no `m x m` dense matrix is formed.

use super::equations::{Flat, RowForm, State};
use super::refactor::PivotedLu;
use crate::operator::{dot8, Compliance};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::solvers::Solve;
use faer::perm::PermRef;
use faer::sparse::linalg::lu::simplicial::factorize_simplicial_numeric_lu_scratch;
use faer::sparse::linalg::lu::{factorize_symbolic_lu, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;
use std::sync::{Arc, Mutex, OnceLock};

/// Largest relative asymmetry of a dense compliance that is solved through its symmetric part
/// (a condensed finite-element compliance is symmetric to round-off; Siconos' printed files
/// are not, by up to 1e-3).
const SYMMETRIC: f64 = 1e-8;

/// The stiffness `K = (D + σ W⁻¹)⁻¹` of the reduced directions: on a symmetric `D` its
/// Cholesky factor (`m³/3` flops), with `K`'s rows by solves while a direction needs few of
/// them and its explicit inverse (`m³` more) made once one needs many; on a positive-real `D`
/// (electric rows) the inverse from one LU.
pub(super) struct Stiffness {
    /// The Cholesky factor `L` of `K⁻¹`, column-major `m x m` (its lower triangle; the upper
    /// one is not read), where `K` is factored.
    factor: Option<Vec<f64>>,
    /// `K`, row-major, once made.
    inverse: OnceLock<Vec<f64>>,
}

impl Stiffness {
    /// A stiffness given as its inverse, row-major.
    fn inverse(k: Vec<f64>) -> Self {
        Stiffness {
            factor: None,
            inverse: OnceLock::from(k),
        }
    }

    /// The stiffness of the row-major `m x m` compliance `d` (its upper triangle, symmetric
    /// within [`SYMMETRIC`]) with `shift[i]` added to its diagonal, by its Cholesky factor;
    /// `None` where that fails (not positive definite). The factor's columns are copied from
    /// `d`'s rows (contiguous reads) on rayon's pool, into fresh pages that each task touches
    /// first, and factored in place with faer's parallel kernels: an `m²` matrix is written
    /// once (faer's `Llt` zeroes, copies and clears it on one core, three passes).
    fn factored(d: &[f64], m: usize, shift: impl Fn(usize) -> f64 + Sync) -> Option<Self> {
        let mut l = vec![0.0; m * m];
        if m > 0 {
            l.par_chunks_mut(m).enumerate().for_each(|(j, col)| {
                col[j..].copy_from_slice(&d[j * m + j..(j + 1) * m]);
                col[j] += shift(j);
            });
        }
        let par = faer::get_global_parallelism();
        let mut mem = MemBuffer::try_new(cholesky_in_place_scratch::<f64>(m, par, Default::default())).ok()?;
        let lm = MatMut::from_column_major_slice_mut(&mut l, m, m);
        cholesky_in_place(lm, Default::default(), par, MemStack::new(&mut mem), Default::default()).ok()?;
        Some(Stiffness {
            factor: Some(l),
            inverse: OnceLock::new(),
        })
    }

    /// `X ← K X`: solves with the factor, in place.
    fn solve(l: &[f64], x: MatMut<'_, f64>) {
        let m = x.nrows();
        let lm = MatRef::from_column_major_slice(l, m, m);
        let par = faer::get_global_parallelism();
        faer::linalg::cholesky::llt::solve::solve_in_place_with_conj(lm, Conj::No, x, par, MemStack::new(&mut []));
    }

    /// `K`, row-major, made from the factor where it is not yet.
    fn explicit(&self, m: usize) -> &[f64] {
        self.inverse.get_or_init(|| {
            let l = self
                .factor
                .as_ref()
                .expect("a stiffness without its inverse has its factor");
            let par = faer::get_global_parallelism();
            let mut mem = MemBuffer::new(faer::linalg::cholesky::llt::inverse::inverse_scratch::<f64>(m, par));
            // the inverse's lower half, column-major: row-major, `K`'s upper half
            let mut k = vec![0.0; m * m];
            let lm = MatRef::from_column_major_slice(l, m, m);
            let out = MatMut::from_column_major_slice_mut(&mut k, m, m);
            faer::linalg::cholesky::llt::inverse::inverse(out, lm, par, MemStack::new(&mut mem));
            for r in 0..m {
                for c in 0..r {
                    k[r * m + c] = k[c * m + r];
                }
            }
            k
        })
    }

    /// Rows `js` of `K` (`K` symmetric where it is factored: row `j` is `K e_j`), row-major,
    /// `js.len() x m`: by solves while they are fewer than `m / 8` and the inverse is not made.
    fn rows(&self, js: &[usize], m: usize) -> Vec<f64> {
        match (&self.factor, self.inverse.get()) {
            (Some(l), None) if 8 * js.len() < m => {
                let mut rhs = Mat::<f64>::zeros(m, js.len());
                for (k, &j) in js.iter().enumerate() {
                    rhs[(j, k)] = 1.0;
                }
                Stiffness::solve(l, rhs.as_mut());
                (0..js.len() * m).map(|i| rhs[(i % m, i / m)]).collect()
            }
            _ => {
                let k = self.explicit(m);
                js.iter().flat_map(|&j| k[j * m..(j + 1) * m].iter().copied()).collect()
            }
        }
    }

    /// `K v`.
    fn apply(&self, v: &[f64]) -> Vec<f64> {
        let m = v.len();
        match (&self.factor, self.inverse.get()) {
            (Some(l), None) => {
                let mut x = v.to_vec();
                Stiffness::solve(l, MatMut::from_column_major_slice_mut(&mut x, m, 1));
                x
            }
            _ => {
                let k = self.explicit(m);
                (0..m).map(|r| dot8(&k[r * m..(r + 1) * m], v)).collect()
            }
        }
    }
}

/// A Newton step on a sparse compliance, in block Gauss–Seidel sweeps: 14 to 50 measured on
/// Siconos' test problems (docs/fclib.md), with 52 to 2020 contacts.
const SPARSE_STEP_SWEEPS: f64 = 30.0;

/// How the Newton directions of one problem are solved.
#[derive(Clone)]
pub(super) enum Directions {
    /// Dense SPD, or positive real with electric rows: the reduced system, with the stiffness
    /// `(D + σ W⁻¹)⁻¹`.
    Reduced(Arc<Stiffness>),
    /// Dense, not SPD or not symmetric: one LU of `J` per step.
    DenseLu {
        /// Whether `D` is symmetric (to [`SYMMETRIC`]), or a condensed finite-element
        /// compliance with electric rows: Newton's lenient rules.
        symmetric: bool,
    },
    /// Sparse: one sparse LU of `J` per step, on a pattern (and its symbolic factorisation)
    /// fixed for the problem and shared by its proximal problems (`σ` moves only the values
    /// of the points' own columns, which the pattern holds whatever the branch).
    SparseLu(Arc<SparsePattern>),
}

/// The pattern of every Jacobian of a sparse problem, row by row: row `r` of point `i` may hold
/// the columns of every row of `D` that belongs to point `i`, and the point's own columns
/// (whatever the branch); and the symbolic LU of `Jᵀ`, whose columns are `J`'s rows.
pub(super) struct SparsePattern {
    /// Row pointers of `J` (= column pointers of `Jᵀ`).
    ptr: Vec<usize>,
    /// Column indices of `J`'s rows, sorted.
    idx: Vec<usize>,
    /// The factors, kept from one step to the next (a fresh factor's pages cost as much as
    /// its arithmetic).
    factors: Mutex<Factors>,
}

/// How a sparse pattern's Jacobians are factored: as faer's analysis chose, simplicial (by the
/// refactoring LU, on the first pivots and pattern) or supernodal (where the factors are dense
/// enough for dense kernels: the Kapla tower's 1,710 rows).
enum Factors {
    /// [`PivotedLu`]: the fill-reducing column order (COLAMD's, as `fwd` and `inv`), and the
    /// factors once made (`None` before the first step, and after a singular one).
    Pivoted((Vec<usize>, Vec<usize>), Option<Box<PivotedLu>>),
    /// faer's supernodal LU: its analysis, the numeric factor's storage and the workspace.
    Supernodal(Box<(SymbolicLu<usize>, NumericLu<usize, f64>, MemBuffer)>),
}

impl SparsePattern {
    fn new(flat: &Flat<'_>) -> Option<Self> {
        let m = flat.m;
        let (mut ptr, mut idx) = (vec![0], Vec::new());
        let mut rows_of = vec![Vec::new(); flat.n];
        for i in 0..flat.n {
            rows_of[i] = flat.indices(i).collect::<Vec<_>>();
        }
        let owner = |r: usize| if r < flat.n { r } else { (r - flat.n) / flat.nt };
        let mut mark = vec![usize::MAX; m];
        for r in 0..m {
            let start = idx.len();
            for &own in &rows_of[owner(r)] {
                for col in std::iter::once(own).chain(flat.d.row(own).map(|(c, _)| c)) {
                    if mark[col] != r {
                        mark[col] = r;
                        idx.push(col);
                    }
                }
            }
            idx[start..].sort_unstable();
            ptr.push(idx.len());
        }
        let pattern = SymbolicSparseColMatRef::new_checked(m, m, &ptr, None, &idx);
        let symbolic = factorize_symbolic_lu(pattern, Default::default()).ok()?;
        let scratch = symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default());
        // (faer's analysis does not say which form it chose; the simplicial form's workspace
        // tells it)
        let factors = if scratch == factorize_simplicial_numeric_lu_scratch::<usize, f64>(m, m) {
            let (fwd, inv) = symbolic.col_perm().arrays();
            Factors::Pivoted((fwd.to_vec(), inv.to_vec()), None)
        } else {
            let scratch = scratch.or(symbolic.solve_transpose_in_place_scratch::<f64>(1, Par::Seq));
            Factors::Supernodal(Box::new((
                symbolic,
                NumericLu::new(),
                MemBuffer::try_new(scratch).ok()?,
            )))
        };
        Some(SparsePattern {
            ptr,
            idx,
            factors: Mutex::new(factors),
        })
    }
}

impl Directions {
    /// The way for `flat`: the reduced system where `D + σ W⁻¹` is symmetric and its Cholesky
    /// factorisation succeeds, else an LU of the Jacobian.
    pub(super) fn new(flat: &Flat<'_>) -> Self {
        let d = match flat.d {
            Compliance::Sparse(_) => {
                return match SparsePattern::new(flat) {
                    Some(p) => Directions::SparseLu(Arc::new(p)),
                    None => Directions::DenseLu { symmetric: false },
                }
            }
            Compliance::Dense(d) => d,
        };
        let m = flat.m;
        if flat.electric.is_some() {
            // `(D + σW⁻¹)ᵀ`, read column by column (a contiguous copy)
            let mut transposed = MatRef::from_column_major_slice(d, m, m).to_owned();
            for i in 0..m {
                transposed[(i, i)] += flat.sigma / flat.w[i];
            }
            // positive real, not symmetric (the electric couplings are opposite): the reduced
            // system with the stiffness from one LU; a condensed finite-element compliance
            // all the same, under its rules
            // the inverse of the transpose is the transposed inverse: row-major `(D + σW⁻¹)⁻¹`
            // is its column-major storage
            let inv = faer::linalg::solvers::DenseSolveCore::inverse(&transposed.partial_piv_lu());
            let inv: Vec<f64> = (0..m * m).map(|k| inv[(k % m, k / m)]).collect();
            return if inv.iter().all(|v| v.is_finite()) {
                Directions::Reduced(Arc::new(Stiffness::inverse(inv)))
            } else {
                Directions::DenseLu { symmetric: true }
            };
        }
        if flat.asymmetry() > SYMMETRIC {
            return Directions::DenseLu { symmetric: false };
        }
        // the Cholesky factorisation reads the lower triangle of `(D + σW⁻¹)ᵀ`, `D`'s upper one
        // (the same within [`SYMMETRIC`])
        match Stiffness::factored(d, m, |i| flat.sigma / flat.w[i]) {
            Some(stiffness) => Directions::Reduced(Arc::new(stiffness)),
            None => Directions::DenseLu { symmetric: true },
        }
    }

    /// The way for `problem`, a proximal problem of the problem these directions are for:
    /// the same sparse pattern, or made anew (a dense stiffness depends on `σ`).
    pub(super) fn for_proximal(&self, problem: &Flat<'_>) -> Self {
        match self {
            Directions::SparseLu(pattern) => Directions::SparseLu(Arc::clone(pattern)),
            _ => Directions::new(problem),
        }
    }

    /// A Newton step's cost in block Gauss–Seidel sweeps on `flat`, where sweeps may be tried
    /// first (read from the compliance, before any factorisation): a sparse LU of the Jacobian
    /// about [`SPARSE_STEP_SWEEPS`] sweeps, a dense one (`2N³/3` flops, `N` about `m/2` rows
    /// in contact, against a sweep's `m²`) `m/12` at least that; `None` for a dense symmetric
    /// `D` (a condensed finite-element compliance, on which sweeps converge slowly and Newton's
    /// reduced steps are cheap) and for electric rows.
    pub(super) fn step_in_sweeps(flat: &Flat<'_>) -> Option<f64> {
        match flat.d {
            Compliance::Sparse(_) => Some(SPARSE_STEP_SWEEPS),
            Compliance::Dense(_) if flat.electric.is_none() && flat.asymmetry() > SYMMETRIC => {
                Some((flat.m as f64 / 12.0).max(SPARSE_STEP_SWEEPS))
            }
            Compliance::Dense(_) => None,
        }
    }

    /// Whether `D` is dense and symmetric (a condensed finite-element compliance), where
    /// Newton's damped steps may rise against the line search's history; not where `D` is
    /// sparse or asymmetric (multibody Delassus operators, Siconos' files), where such rises
    /// let the iteration wander (measured: `docs/theory.md`, stage 1).
    pub(super) fn symmetric_dense(&self) -> bool {
        matches!(self, Directions::Reduced(_) | Directions::DenseLu { symmetric: true })
    }

    /// The direction at `s`; `None` where the system is singular.
    pub(super) fn direction(&self, flat: &Flat<'_>, s: &State, rows: &[RowForm]) -> Option<Vec<f64>> {
        match self {
            Directions::Reduced(stiffness) => {
                // the smaller of the two systems: the rows that are not `C`'s identity (the
                // reduced one), or those that are not `δ`'s (the separated points' rows
                // eliminated: where most points are separated, as under an indenter)
                let n_reduced = (0..flat.m).filter(|&r| !rows[r].is_c_row(r)).count();
                let n_free = (0..flat.m).filter(|&r| !rows[r].is_identity(r)).count();
                if n_free < n_reduced {
                    dense_lu(flat, s, rows).or_else(|| reduced(flat, s, rows, stiffness))
                } else {
                    reduced(flat, s, rows, stiffness).or_else(|| dense_lu(flat, s, rows))
                }
            }
            Directions::DenseLu { .. } => dense_lu(flat, s, rows),
            Directions::SparseLu(pattern) => sparse_lu(flat, s, rows, pattern),
        }
    }
}

/// The direction by one LU of the Jacobian (dense compliance), its identity rows (separated
/// points: `δ_r = -f_r`) eliminated first: the rows and columns of the other points make an
/// `N x N` system, `N` the points in contact times their components.
pub(super) fn dense_lu(flat: &Flat<'_>, s: &State, rows: &[RowForm]) -> Option<Vec<f64>> {
    let (m, c) = (flat.m, &flat.c);
    let Compliance::Dense(d) = flat.d else {
        return SparsePattern::new(flat).and_then(|p| sparse_lu(flat, s, rows, &p));
    };
    let mut delta: Vec<f64> = vec![0.0; m];
    let mut slot = vec![usize::MAX; m];
    let mut free = vec![];
    for r in 0..m {
        if rows[r].is_identity(r) {
            delta[r] = -s.f[r];
        } else {
            slot[r] = free.len();
            free.push(r);
        }
    }
    let n = free.len();
    if n == 0 {
        return Some(delta);
    }
    // Jᵀ on the free rows and columns, column-major (row r of J is column r of Jᵀ); the known
    // δ of the identity rows moved to the right-hand side
    let mut jt = Mat::<f64>::zeros(n, n);
    let mut rhs = Mat::<f64>::zeros(n, 1);
    let mut row = vec![0.0; m];
    for (k, &r) in free.iter().enumerate() {
        row.iter_mut().for_each(|v| *v = 0.0);
        let form = &rows[r];
        for &(j, v) in &form.e {
            row[j] += v;
        }
        for &(j, v) in &form.b {
            let scale = v * c[j];
            for ((x, dj), w) in row.iter_mut().zip(&d[j * m..(j + 1) * m]).zip(&flat.w) {
                *x += scale * dj * w;
            }
            row[j] += scale * flat.sigma;
        }
        let mut b = -s.f[r];
        for (col, x) in row.iter().enumerate() {
            match slot[col] {
                usize::MAX => b -= x * delta[col],
                kc => jt[(kc, k)] = *x,
            }
        }
        rhs[(k, 0)] = b;
    }
    let lu = jt.partial_piv_lu();
    lu.solve_transpose_in_place(rhs.as_mut());
    for (k, &r) in free.iter().enumerate() {
        delta[r] = rhs[(k, 0)];
    }
    delta.iter().all(|v| v.is_finite()).then_some(delta)
}

/// The direction by a sparse LU of the Jacobian on its fixed pattern: row `r` holds `E_r`
/// and, for each `(j, v)` of `B_r`, `v c_j` times row `j` of `D W + σ I`. The rows of `J` are
/// the columns of `Jᵀ`, which is factored; `J δ = -f` is its transposed solve.
fn sparse_lu(flat: &Flat<'_>, s: &State, rows: &[RowForm], pattern: &SparsePattern) -> Option<Vec<f64>> {
    let (m, c) = (flat.m, &flat.c);
    let mut values = vec![0.0; pattern.idx.len()];
    let mut slot = vec![usize::MAX; m];
    for (r, form) in rows.iter().enumerate() {
        let range = pattern.ptr[r]..pattern.ptr[r + 1];
        for k in range.clone() {
            slot[pattern.idx[k]] = k;
        }
        for &(j, v) in &form.e {
            values[slot[j]] += v;
        }
        for &(j, v) in &form.b {
            for (col, d) in flat.d.row(j) {
                values[slot[col]] += v * c[j] * d * flat.w[col];
            }
            values[slot[j]] += v * c[j] * flat.sigma;
        }
        for k in range {
            slot[pattern.idx[k]] = usize::MAX;
        }
    }
    let structure = SymbolicSparseColMatRef::new_checked(m, m, &pattern.ptr, None, &pattern.idx);
    let jt = SparseColMatRef::new(structure, &values);
    let mut kept = pattern.factors.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let mut delta: Vec<f64> = s.f.iter().map(|f| -f).collect();
    match &mut *kept {
        Factors::Pivoted((fwd, inv), lu) => {
            // on the last step's pivots where they hold (new ones from the first column where
            // they do not), else afresh
            if !lu.as_mut().is_some_and(|lu| lu.refactor(jt)) {
                *lu = PivotedLu::factor(jt, PermRef::new_checked(fwd, inv, m)).map(Box::new);
            }
            lu.as_ref()?.solve_transpose_in_place(&mut delta);
        }
        Factors::Supernodal(kept) => {
            // sequential: these matrices are small (a thread pool's start costs more than it
            // saves)
            let (symbolic, numeric, buffer) = &mut **kept;
            let stack = MemStack::new(buffer);
            let lu = symbolic
                .factorize_numeric_lu(numeric, jt, Par::Seq, stack, Default::default())
                .ok()?;
            let mut rhs = MatMut::from_column_major_slice_mut(&mut delta, m, 1);
            lu.solve_transpose_in_place_with_conj(Conj::No, rhs.as_mut(), Par::Seq, stack);
        }
    }
    delta.iter().all(|v| v.is_finite()).then_some(delta)
}

/// The direction through `y = C δ`: `(E C⁻¹ + B) y = -f`, whose rows are the identity at every
/// point in contact and sticking, so that only the rows of sliding and separated points form a
/// dense system (`N x N`, often far smaller than `m x m`, and empty when every point sticks);
/// then `δ = C⁻¹ y`, with `C⁻¹ = W⁻¹ K diag(1/c)` and `K = (D + σ W⁻¹)⁻¹` (row-major). `None`
/// where the reduced system is singular.
fn reduced(flat: &Flat<'_>, s: &State, rows: &[RowForm], stiffness: &Stiffness) -> Option<Vec<f64>> {
    let m = flat.m;
    let inv_c: Vec<f64> = flat.c.iter().map(|c| 1.0 / c).collect();
    let mut slot = vec![usize::MAX; m];
    let others: Vec<usize> = (0..m).filter(|&r| !rows[r].is_c_row(r)).collect();
    for (k, &r) in others.iter().enumerate() {
        slot[r] = k;
    }
    // the rows of K the reduced system reads, each once
    let mut wanted = vec![usize::MAX; m];
    let mut js = vec![];
    for &r in &others {
        for &(j, _) in &rows[r].e {
            if wanted[j] == usize::MAX {
                wanted[j] = js.len();
                js.push(j);
            }
        }
    }
    let k_rows = stiffness.rows(&js, m);
    // y on the identity rows is -f there
    let mut y: Vec<f64> = (0..m)
        .map(|r| if slot[r] == usize::MAX { -s.f[r] } else { 0.0 })
        .collect();
    let nn = others.len();
    if nn > 0 {
        let mut mnn = Mat::<f64>::zeros(nn, nn);
        let mut rhs = Mat::<f64>::zeros(nn, 1);
        let mut row = vec![0.0; m];
        for (k, &r) in others.iter().enumerate() {
            row.iter_mut().for_each(|v| *v = 0.0);
            for &(j, v) in &rows[r].e {
                let scale = v / flat.w[j];
                let kj = &k_rows[wanted[j] * m..(wanted[j] + 1) * m];
                for ((x, kj), ic) in row.iter_mut().zip(kj).zip(&inv_c) {
                    *x += scale * kj * ic;
                }
            }
            for &(j, v) in &rows[r].b {
                row[j] += v;
            }
            let mut b = -s.f[r];
            for col in 0..m {
                if slot[col] == usize::MAX {
                    b -= row[col] * y[col];
                } else {
                    mnn[(k, slot[col])] = row[col];
                }
            }
            rhs[(k, 0)] = b;
        }
        let lu = mnn.partial_piv_lu();
        lu.solve_in_place(rhs.as_mut());
        for (k, &r) in others.iter().enumerate() {
            y[r] = rhs[(k, 0)];
        }
    }
    // δ = C⁻¹ y; on a row that is the identity in J (a separated point) δ_r = -f_r exactly,
    // which sets its multiplier to exactly zero, not to round-off
    let y_c: Vec<f64> = y.iter().zip(&inv_c).map(|(y, ic)| y * ic).collect();
    let k_y = stiffness.apply(&y_c);
    let delta: Vec<f64> = (0..m)
        .map(|r| {
            if rows[r].is_identity(r) {
                -s.f[r]
            } else {
                k_y[r] / flat.w[r]
            }
        })
        .collect();
    delta.iter().all(|v| v.is_finite()).then_some(delta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ContactPoints, Law, PointValues};
    use faer::sparse::{SparseRowMat, Triplet};

    /// The three ways give one direction, at states with every branch present, with and
    /// without a proximal shift.
    #[test]
    fn the_three_ways_agree() {
        for (case, law) in [Law::Coulomb, Law::Tresca(vec![0.05; 5]), Law::Frictionless]
            .into_iter()
            .enumerate()
        {
            for (dim, sigma) in [(2, 0.0), (3, 0.0), (3, 0.3)] {
                let n = 5;
                let nt = if matches!(law, Law::Frictionless) { 0 } else { dim - 1 };
                let m = n * (1 + nt);
                let points = ContactPoints {
                    dim,
                    position: vec![[0.0; 3]; n],
                    normal: vec![[0.0, 0.0, -1.0]; n],
                    tangent: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; n],
                    weight: (0..n).map(|i| 0.5 + 0.1 * i as f64).collect(),
                    gap: vec![0.0; n],
                    friction: vec![0.3; n],
                    held: vec![[false; 2]; n],
                    foundation: Default::default(),
                    foundations: vec![],
                    slipped: vec![],
                    weakening: vec![],
                    tresca: vec![],
                };
                // an SPD compliance with zeros: a Gram matrix plus the identity
                let g = |i: usize, j: usize| ((i * 7 + j * 3 + case) % 5) as f64 * 0.1 - 0.2;
                let compliance: Vec<f64> = (0..m * m)
                    .map(|k| {
                        let (i, j) = (k / m, k % m);
                        (0..m).map(|l| g(i, l) * g(j, l)).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
                    })
                    .collect();
                let sparse = SparseRowMat::try_new_from_triplets(
                    m,
                    m,
                    &(0..m * m)
                        .filter(|&k| compliance[k] != 0.0)
                        .map(|k| Triplet::new(k / m, k % m, compliance[k]))
                        .collect::<Vec<_>>(),
                )
                .unwrap();
                let u0: Vec<f64> = (0..m).map(|r| (r as f64 * 1.7).sin()).collect();
                let u0 = PointValues::from_flat(&u0, n, nt);
                let center: Vec<f64> = (0..m).map(|r| 0.1 * r as f64).collect();
                let dense = Flat::new(Compliance::Dense(&compliance), &u0, &points, &law, nt, 0.7);
                let dense = if sigma > 0.0 {
                    dense.proximal(sigma, &center)
                } else {
                    dense
                };
                let mut sparse_flat = dense.clone();
                sparse_flat.d = Compliance::Sparse(sparse.as_ref());
                let x: Vec<f64> = (0..m).map(|r| 0.8 * (r as f64 * 2.3 + 0.4).cos()).collect();
                let s = dense.state(x.clone());
                assert_eq!(s.f, sparse_flat.state(x).f);
                let rows = dense.rows(&s);
                let reduced_rows = (0..m).filter(|&r| !rows[r].is_c_row(r)).count();
                assert!(
                    reduced_rows > 0 && reduced_rows < m,
                    "{law:?} {dim}D: {reduced_rows} of {m}"
                );
                let Directions::Reduced(stiffness) = Directions::new(&dense) else {
                    panic!("an SPD compliance takes the reduced way")
                };
                let full = dense_lu(&dense, &s, &rows).unwrap();
                let Directions::SparseLu(pattern) = Directions::new(&sparse_flat) else {
                    panic!("a sparse compliance takes the sparse way")
                };
                let ways = [
                    reduced(&dense, &s, &rows, &stiffness).unwrap(),
                    sparse_lu(&sparse_flat, &s, &rows, &pattern).unwrap(),
                ];
                let scale = full.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                for way in ways {
                    for (a, b) in full.iter().zip(&way) {
                        assert!((a - b).abs() <= 1e-10 * scale, "{law:?} {dim}D σ {sigma}: {a} vs {b}");
                    }
                }
            }
        }
    }

    /// The stiffness read through its Cholesky factor (rows by solves, `K v` by a solve)
    /// equals the one read from its explicit inverse, and once the inverse is made (many rows
    /// asked for) both reads go through it.
    #[test]
    fn the_stiffness_by_solves_is_the_inverse() {
        let m = 40;
        let g = |i: usize, j: usize| ((i * 7 + j * 3) % 11) as f64 * 0.1 - 0.5;
        let a = Mat::<f64>::from_fn(m, m, |i, j| {
            (0..m).map(|l| g(i, l) * g(j, l)).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
        });
        let row_major: Vec<f64> = (0..m * m).map(|k| a[(k / m, k % m)]).collect();
        let factored = Stiffness::factored(&row_major, m, |_| 0.0).unwrap();
        let shifted = Stiffness::factored(&row_major, m, |i| 0.5 + 0.01 * i as f64).unwrap();
        let inv = faer::linalg::solvers::DenseSolveCore::inverse(&a.partial_piv_lu());
        let explicit = Stiffness::inverse((0..m * m).map(|k| inv[(k / m, k % m)]).collect());
        let v: Vec<f64> = (0..m).map(|i| (i as f64 * 0.7).sin()).collect();
        let close = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-12 * (1.0 + q.abs()));
        let few = [3, 17, 39];
        assert!(close(&factored.rows(&few, m), &explicit.rows(&few, m)));
        assert!(close(&factored.apply(&v), &explicit.apply(&v)));
        assert!(
            factored.inverse.get().is_none(),
            "three rows of forty are read by solves"
        );
        let many: Vec<usize> = (0..m).step_by(2).collect();
        assert!(close(&factored.rows(&many, m), &explicit.rows(&many, m)));
        assert!(
            factored.inverse.get().is_some(),
            "twenty rows of forty make the inverse"
        );
        assert!(close(&factored.apply(&v), &explicit.apply(&v)));
        // the shift is added to the diagonal; a shift that leaves the matrix indefinite is
        // refused
        let a_shifted = Mat::<f64>::from_fn(m, m, |i, j| {
            a[(i, j)] + if i == j { 0.5 + 0.01 * i as f64 } else { 0.0 }
        });
        let inv = faer::linalg::solvers::DenseSolveCore::inverse(&a_shifted.partial_piv_lu());
        let by_lu: Vec<f64> = (0..m).map(|i| (0..m).map(|j| inv[(i, j)] * v[j]).sum()).collect();
        assert!(close(&shifted.apply(&v), &by_lu));
        assert!(Stiffness::factored(&row_major, m, |_| -100.0).is_none());
    }

    /// The rows of the Jacobian with electric rows are the derivative of the equations: a
    /// difference quotient along random directions, away from the kinks, on a positive-real
    /// compliance (rigid and compliant foundations, both electric laws).
    #[test]
    fn electric_rows_are_the_derivative() {
        use crate::{ElectricContact, ElectricLaw, Foundation};
        let (n, nt) = (4, 1);
        let m = n * (1 + nt);
        let o = m + n;
        let laws = [ElectricLaw::Conductive { conductance: 3.0 }, ElectricLaw::Conducting];
        let foundations = [
            Foundation::Rigid,
            Foundation::Compliant {
                stiffness: 2.0,
                exponent: 1.5,
            },
        ];
        // each law on each foundation, and on the foundation beside a rigid one (every other
        // point's: zones on two foundations)
        let cases = laws
            .iter()
            .flat_map(|l| foundations.iter().map(move |f| (*l, *f)))
            .flat_map(|(l, f)| [(l, f, false), (l, f, true)]);
        for (law, foundation, beside) in cases {
            let points = ContactPoints {
                dim: 2,
                position: vec![[0.0; 3]; n],
                normal: vec![[0.0, -1.0, 0.0]; n],
                tangent: vec![[[1.0, 0.0, 0.0], [0.0; 3]]; n],
                weight: (0..n).map(|i| 0.5 + 0.1 * i as f64).collect(),
                gap: vec![0.0; n],
                friction: vec![0.3; n],
                held: vec![[false; 2]; n],
                foundation,
                foundations: if beside {
                    (0..n)
                        .map(|i| if i % 2 == 0 { foundation } else { Foundation::Rigid })
                        .collect()
                } else {
                    vec![]
                },
                slipped: vec![],
                weakening: vec![],
                tresca: vec![],
            };
            let g = |i: usize, j: usize| ((i * 5 + j * 3) % 7) as f64 * 0.1 - 0.3;
            // symmetric SPD part plus an antisymmetric coupling between u and φ rows
            let d: Vec<f64> = (0..o * o)
                .map(|k| {
                    let (i, j) = (k / o, k % o);
                    let sym = (0..o).map(|l| g(i, l) * g(j, l)).sum::<f64>() + if i == j { 1.0 } else { 0.0 };
                    let anti = match (i >= m, j >= m) {
                        (true, false) => 0.2 * g(i, j),
                        (false, true) => -0.2 * g(j, i),
                        _ => 0.0,
                    };
                    if (i >= m) == (j >= m) {
                        sym
                    } else {
                        anti
                    }
                })
                .collect();
            let u0: Vec<f64> = (0..m).map(|r| 0.7 * (r as f64 * 1.7).sin() + 0.4).collect();
            let u0 = PointValues::from_flat(&u0, n, nt);
            let phi0: Vec<f64> = (0..n).map(|k| 0.3 * (k as f64 + 0.5).cos()).collect();
            let contact = ElectricContact {
                law,
                potential: 0.1,
                points: (0..n).collect(),
            };
            let law_m = Law::Coulomb;
            let flat = Flat::new(Compliance::Dense(&d), &u0, &points, &law_m, nt, 2.0).with_electric(
                Compliance::Dense(&d),
                &contact,
                &phi0,
            );
            let x: Vec<f64> = (0..o).map(|r| 0.5 * (r as f64 * 2.3 + 0.4).cos() + 0.3).collect();
            let s = flat.state(x.clone());
            let rows = flat.rows(&s);
            let v: Vec<f64> = (0..o).map(|r| ((r * 7 % 5) as f64 - 2.0) * 0.3).collect();
            // J v from the rows: E v + B C v, C = diag(c) D W
            let wv: Vec<f64> = v.iter().zip(&flat.w).map(|(a, b)| a * b).collect();
            let cv: Vec<f64> = (0..o)
                .map(|r| flat.c[r] * (0..o).map(|j| d[r * o + j] * wv[j]).sum::<f64>())
                .collect();
            let eps = 1e-7;
            let xp: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a + eps * b).collect();
            let sp = flat.state(xp);
            // (a compliant foundation's normal rows hold their scale: not their exact derivative)
            let first = if foundation == Foundation::Rigid { 0 } else { n };
            for r in first..o {
                let jv: f64 = rows[r].e.iter().map(|&(j, a)| a * v[j]).sum::<f64>()
                    + rows[r].b.iter().map(|&(j, a)| a * cv[j]).sum::<f64>();
                let fd = (sp.f[r] - s.f[r]) / eps;
                assert!(
                    (jv - fd).abs() <= 1e-5 * (1.0 + fd.abs()),
                    "{law:?} {foundation:?} (beside a rigid one: {beside}) row {r}: {jv} vs {fd}"
                );
            }
        }
    }
}
