//! Small sparse helpers on faer's compressed-column matrices.

use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};

/// `y += alpha M x`.
pub fn mul_add(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], alpha: f64) {
    let sym = m.symbolic();
    let vals = m.val();
    let cp = sym.col_ptr();
    let ri = sym.row_idx();
    for (j, &xj) in x.iter().enumerate().take(m.ncols()) {
        if xj == 0.0 {
            continue;
        }
        let s = alpha * xj;
        for p in cp[j]..cp[j + 1] {
            y[ri[p]] += vals[p] * s;
        }
    }
}

/// `y += alpha Mᵀ x`.
pub fn mul_t_add(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], alpha: f64) {
    let sym = m.symbolic();
    let vals = m.val();
    let cp = sym.col_ptr();
    let ri = sym.row_idx();
    for (j, yj) in y.iter_mut().enumerate().take(m.ncols()) {
        let mut s = 0.0;
        for p in cp[j]..cp[j + 1] {
            s += vals[p] * x[ri[p]];
        }
        *yj += alpha * s;
    }
}

/// The lower triangle of `K = [[A, Gᵀ], [G, -B]]` (what the factorisations read): column `j`
/// of the u part holds `A`'s rows `≥ j` then `G`'s column `j` shifted by `n_u`; column `j` of
/// the φ part holds `-B`'s rows `≥ j`.
pub fn lower_quasi_definite(
    a: SparseColMatRef<'_, usize, f64>,
    g: SparseColMatRef<'_, usize, f64>,
    b: SparseColMatRef<'_, usize, f64>,
) -> SparseColMat<usize, f64> {
    let (n_u, n_phi) = (a.nrows(), b.nrows());
    let n = n_u + n_phi;
    let mut col_ptr = Vec::with_capacity(n + 1);
    let cap = a.val().len() / 2 + n_u + g.val().len() + b.val().len() / 2 + n_phi;
    let mut rows = Vec::with_capacity(cap);
    let mut vals = Vec::with_capacity(cap);
    col_ptr.push(0);
    for j in 0..n_u {
        for (&i, &v) in a.symbolic().row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if i >= j {
                rows.push(i);
                vals.push(v);
            }
        }
        for (&i, &v) in g.symbolic().row_idx_of_col_raw(j).iter().zip(g.val_of_col(j)) {
            rows.push(n_u + i);
            vals.push(v);
        }
        col_ptr.push(rows.len());
    }
    for j in 0..n_phi {
        for (&i, &v) in b.symbolic().row_idx_of_col_raw(j).iter().zip(b.val_of_col(j)) {
            if i >= j {
                rows.push(n_u + i);
                vals.push(-v);
            }
        }
        col_ptr.push(rows.len());
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows), vals)
}

/// `M` as a dense row-major array (for tests and small problems).
pub fn to_dense(m: SparseColMatRef<'_, usize, f64>) -> Vec<Vec<f64>> {
    let mut d = vec![vec![0.0; m.ncols()]; m.nrows()];
    for j in 0..m.ncols() {
        for (&i, &v) in m.symbolic().row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)) {
            d[i][j] += v;
        }
    }
    d
}
