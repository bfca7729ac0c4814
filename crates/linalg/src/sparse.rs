//! Small sparse helpers on faer's compressed-column matrices.

use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use rayon::prelude::*;

/// Matrices with fewer stored entries than this are multiplied on one core (a product reads
/// them once: 3 MB here, under a millisecond).
const PARALLEL_ENTRIES: usize = 1 << 18;

/// Larger products are cut into this many ranges of columns of about equal entries, whose
/// partial sums are added in this fixed order: the result does not depend on the pool's size.
const PARTS: usize = 8;

/// `y += alpha M x`: by columns (each scatters into `y`); a large `M` in 8 ranges of
/// columns of about equal entries on rayon's pool, each into a vector of its own, added in
/// order (the same result on any pool).
pub fn mul_add(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], alpha: f64) {
    let ncols = m.ncols().min(x.len());
    if m.val().len() < PARALLEL_ENTRIES {
        mul_add_columns(m, 0..ncols, x, y, alpha);
        return;
    }
    let cp = m.symbolic().col_ptr();
    let total = cp[ncols];
    let mut cuts: Vec<usize> = (0..PARTS)
        .map(|p| cp[..=ncols].partition_point(|&e| e < total * p / PARTS).min(ncols))
        .collect();
    cuts.push(ncols);
    let partial: Vec<Vec<f64>> = cuts
        .par_windows(2)
        .map(|w| {
            let mut part = vec![0.0; y.len()];
            mul_add_columns(m, w[0]..w[1], x, &mut part, alpha);
            part
        })
        .collect();
    const CHUNK: usize = 1 << 14;
    y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, ys)| {
        for part in &partial {
            for (yi, pi) in ys.iter_mut().zip(&part[c * CHUNK..]) {
                *yi += pi;
            }
        }
    });
}

/// `y += alpha M x` on the calling thread alone (the reference of the interleaved products).
#[cfg(test)]
fn mul_add_seq(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], alpha: f64) {
    mul_add_columns(m, 0..m.ncols().min(x.len()), x, y, alpha);
}

/// `y += alpha Mᵀ x` on the calling thread alone ([`mul_add_seq`]'s transpose).
pub(crate) fn mul_t_add_seq(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], alpha: f64) {
    let n = m.ncols().min(y.len());
    y[..n]
        .iter_mut()
        .enumerate()
        .for_each(|(j, yj)| *yj += alpha * column_dot(m, x, j));
}

/// `Y += alpha M X` on the calling thread for `k` vectors stored interleaved (entry `j` of
/// vector `f` at `X[j k + f]`): `M` read once for all of them, where [`mul_add_seq`] per
/// vector reads it `k` times (a product of a 2D `K` is bound by reading its entries). Each
/// vector's entries are summed in [`mul_add_seq`]'s order, so each is that product's.
pub(crate) fn mul_add_interleaved(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], k: usize, alpha: f64) {
    let (cp, ri, vals) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    let ncols = m.ncols().min(x.len() / k.max(1));
    let mut s = vec![0.0; k];
    for j in 0..ncols {
        let xj = &x[j * k..(j + 1) * k];
        if xj.iter().all(|&v| v == 0.0) {
            continue;
        }
        for (sf, &xf) in s.iter_mut().zip(xj) {
            *sf = alpha * xf;
        }
        for p in cp[j]..cp[j + 1] {
            let v = vals[p];
            let yi = &mut y[ri[p] * k..(ri[p] + 1) * k];
            for (yf, sf) in yi.iter_mut().zip(&s) {
                *yf += v * sf;
            }
        }
    }
}

/// `Y += alpha Mᵀ X` on the calling thread for `k` vectors stored interleaved
/// ([`mul_add_interleaved`]'s transpose; each vector's entries those of [`mul_t_add_seq`]).
pub(crate) fn mul_t_add_interleaved(
    m: SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    y: &mut [f64],
    k: usize,
    alpha: f64,
) {
    let (cp, ri, vals) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    let n = m.ncols().min(y.len() / k.max(1));
    let mut s = vec![0.0; k];
    for j in 0..n {
        s.fill(0.0);
        for p in cp[j]..cp[j + 1] {
            let v = vals[p];
            for (sf, xf) in s.iter_mut().zip(&x[ri[p] * k..(ri[p] + 1) * k]) {
                *sf += v * xf;
            }
        }
        for (yf, sf) in y[j * k..(j + 1) * k].iter_mut().zip(&s) {
            *yf += alpha * sf;
        }
    }
}

/// Column `j` of `M` dotted with `x`: entry `j` of `Mᵀ x`.
fn column_dot(m: SparseColMatRef<'_, usize, f64>, x: &[f64], j: usize) -> f64 {
    let (cp, ri, vals) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    let mut s = 0.0;
    for p in cp[j]..cp[j + 1] {
        s += vals[p] * x[ri[p]];
    }
    s
}

/// `y += alpha M[:, cols] x[cols]`, one column after another.
fn mul_add_columns(
    m: SparseColMatRef<'_, usize, f64>,
    cols: std::ops::Range<usize>,
    x: &[f64],
    y: &mut [f64],
    alpha: f64,
) {
    let (cp, ri, vals) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    for j in cols {
        let xj = x[j];
        if xj == 0.0 {
            continue;
        }
        let s = alpha * xj;
        for p in cp[j]..cp[j + 1] {
            y[ri[p]] += vals[p] * s;
        }
    }
}

/// `y += alpha Mᵀ x`: a dot product per column, on rayon's pool for a large `M` (each writes
/// its own entry of `y`: the same result on any pool).
pub fn mul_t_add(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64], alpha: f64) {
    if m.val().len() < PARALLEL_ENTRIES {
        return mul_t_add_seq(m, x, y, alpha);
    }
    let n = m.ncols().min(y.len());
    y[..n]
        .par_iter_mut()
        .with_min_len(1024)
        .enumerate()
        .for_each(|(j, yj)| *yj += alpha * column_dot(m, x, j));
}

/// The lower triangle of `K = [[A, Gᵀ], [G, -B]]` (what the factorisations read): column `j`
/// of the u part holds `A`'s rows `≥ j` then `G`'s column `j` shifted by `n_u`; column `j` of
/// the φ part holds `-B`'s rows `≥ j`. Each column's entries are counted, then written, by
/// ranges of columns on rayon's pool (a 3D `K` has tens of millions of entries: 0.27 s on one
/// core at `paper-3d` n = 32); the result does not depend on the pool.
pub fn lower_quasi_definite(
    a: SparseColMatRef<'_, usize, f64>,
    g: SparseColMatRef<'_, usize, f64>,
    b: SparseColMatRef<'_, usize, f64>,
) -> SparseColMat<usize, f64> {
    let (n_u, n_phi) = (a.nrows(), b.nrows());
    let n = n_u + n_phi;
    // column j of K: the lower part of column c of A (or of -B, its rows shifted by n_u),
    // then (u part) G's column c below it
    let part = |j: usize| {
        if j < n_u {
            (a, j, Some(g), 1.0, 0)
        } else {
            (b, j - n_u, None, -1.0, n_u)
        }
    };
    let count = |j: usize| {
        let (m, c, below, _, _) = part(j);
        let own = m.symbolic().row_idx_of_col_raw(c).iter().filter(|&&i| i >= c).count();
        own + below.map_or(0, |g| g.symbolic().row_idx_of_col_raw(c).len())
    };
    let counts: Vec<usize> = (0..n)
        .into_par_iter()
        .with_min_len(COLUMNS_PER_TASK)
        .map(count)
        .collect();
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    for c in counts {
        col_ptr.push(col_ptr[col_ptr.len() - 1] + c);
    }
    let (mut rows, mut vals) = (vec![0usize; col_ptr[n]], vec![0.0; col_ptr[n]]);
    // ranges of columns, each writing its own run of entries (fresh pages, written first)
    let mut ranges = Vec::with_capacity(n.div_ceil(COLUMNS_PER_TASK));
    let (mut rest_r, mut rest_v) = (&mut rows[..], &mut vals[..]);
    for lo in (0..n).step_by(COLUMNS_PER_TASK) {
        let hi = (lo + COLUMNS_PER_TASK).min(n);
        let len = col_ptr[hi] - col_ptr[lo];
        let (r, rr) = std::mem::take(&mut rest_r).split_at_mut(len);
        let (v, vr) = std::mem::take(&mut rest_v).split_at_mut(len);
        ranges.push((lo..hi, r, v));
        (rest_r, rest_v) = (rr, vr);
    }
    ranges.into_par_iter().for_each(|(cols, r, v)| {
        let mut k = 0;
        for j in cols {
            let (m, c, below, sign, shift) = part(j);
            for (&i, &x) in m.symbolic().row_idx_of_col_raw(c).iter().zip(m.val_of_col(c)) {
                if i >= c {
                    (r[k], v[k]) = (shift + i, sign * x);
                    k += 1;
                }
            }
            if let Some(g) = below {
                for (&i, &x) in g.symbolic().row_idx_of_col_raw(c).iter().zip(g.val_of_col(c)) {
                    (r[k], v[k]) = (n_u + i, x);
                    k += 1;
                }
            }
        }
    });
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows), vals)
}

/// Columns per task where [`lower_quasi_definite`] counts and writes `K`'s columns.
const COLUMNS_PER_TASK: usize = 4096;

/// Adds each `(row, column, value)` of `entries` to the stored entry of `m` there (a sum where
/// a position repeats), without changing its pattern; `Err((row, column))` at the first
/// position `m` does not store, before any value is changed.
pub fn add_to_pattern(m: &mut SparseColMat<usize, f64>, entries: &[(usize, usize, f64)]) -> Result<(), (usize, usize)> {
    let mut at = Vec::with_capacity(entries.len());
    {
        let sym = m.symbolic();
        for &(i, j, _) in entries {
            let col_start = if j < sym.ncols() {
                sym.col_ptr()[j]
            } else {
                return Err((i, j));
            };
            let rows = sym.row_idx_of_col_raw(j);
            match rows.iter().position(|&r| r == i) {
                Some(k) => at.push(col_start + k),
                None => return Err((i, j)),
            }
        }
    }
    let vals = m.val_mut();
    for (&k, &(_, _, v)) in at.iter().zip(entries) {
        vals[k] += v;
    }
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// Uniform numbers in `[0, 1)` from a linear congruential generator started at `seed`.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// `K`'s lower triangle, built by ranges of columns on the pool, is entry for entry the
    /// blocks' (`A` and `-B` below their diagonals, `G` below `A`), whatever the pool, with
    /// columns of every kind: empty, `A` or `B` without entries above the diagonal, `G` empty.
    /// Entries land on their stored positions (repeats summed); a position outside the
    /// pattern is refused with nothing changed.
    #[test]
    fn entries_are_added_within_the_pattern_only() {
        let t = [
            Triplet::new(0, 0, 1.0),
            Triplet::new(2, 0, 2.0),
            Triplet::new(1, 1, 3.0),
            Triplet::new(0, 2, 2.0),
            Triplet::new(2, 2, 5.0),
        ];
        let mut m = SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &t).unwrap();
        add_to_pattern(&mut m, &[(2, 0, 0.5), (0, 2, 0.5), (2, 2, 1.0), (2, 2, 1.0)]).unwrap();
        let d = to_dense(m.as_ref());
        assert_eq!(d, vec![vec![1.0, 0.0, 2.5], vec![0.0, 3.0, 0.0], vec![2.5, 0.0, 7.0]]);
        assert_eq!(add_to_pattern(&mut m, &[(0, 0, 1.0), (1, 0, 1.0)]), Err((1, 0)));
        assert_eq!(add_to_pattern(&mut m, &[(0, 3, 1.0)]), Err((0, 3)));
        assert_eq!(to_dense(m.as_ref()), d);
    }

    #[test]
    fn the_lower_triangle_of_k_is_the_blocks_on_any_pool() {
        let (n_u, n_phi) = (3 * COLUMNS_PER_TASK / 2 + 7, COLUMNS_PER_TASK + 3);
        let mut rnd = uniform(11);
        let mut sym = |n: usize, skip: usize| {
            let mut t = vec![];
            for j in (0..n).filter(|j| j % skip != 0) {
                t.push(Triplet::new(j, j, 4.0 + rnd()));
                for _ in 0..3 {
                    let i = (rnd() * n as f64) as usize;
                    let v = rnd() - 0.5;
                    t.extend([Triplet::new(i, j, v), Triplet::new(j, i, v)]);
                }
            }
            SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap()
        };
        let (a, b) = (sym(n_u, 97), sym(n_phi, 89));
        let mut t = vec![];
        for j in (0..n_u).filter(|j| j % 5 != 0) {
            for _ in 0..2 {
                t.push(Triplet::new((rnd() * n_phi as f64) as usize, j, rnd() - 0.5));
            }
        }
        let g = SparseColMat::<usize, f64>::try_new_from_triplets(n_phi, n_u, &t).unwrap();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref()))
        };
        let k = on(1);
        for threads in [2, 3] {
            let other = on(threads);
            assert_eq!(other.symbolic().col_ptr(), k.symbolic().col_ptr());
            assert_eq!(other.symbolic().row_idx(), k.symbolic().row_idx());
            assert_eq!(other.val(), k.val());
        }
        // K x from its lower triangle (mirrored) against the blocks' products
        let n = n_u + n_phi;
        let x: Vec<f64> = (0..n).map(|_| rnd() - 0.5).collect();
        let mut kx = vec![0.0; n];
        for j in 0..n {
            for (&i, &v) in k.symbolic().row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
                assert!(i >= j, "K[{i}, {j}] above the diagonal");
                kx[i] += v * x[j];
                if i != j {
                    kx[j] += v * x[i];
                }
            }
        }
        let (xu, xp) = x.split_at(n_u);
        let (mut yu, mut yp) = (vec![0.0; n_u], vec![0.0; n_phi]);
        mul_add_columns(a.as_ref(), 0..n_u, xu, &mut yu, 1.0);
        mul_t_add(g.as_ref(), xp, &mut yu, 1.0);
        mul_add_columns(g.as_ref(), 0..n_u, xu, &mut yp, 1.0);
        mul_add_columns(b.as_ref(), 0..n_phi, xp, &mut yp, -1.0);
        for (i, (got, want)) in kx.iter().zip(yu.iter().chain(&yp)).enumerate() {
            assert!(
                (got - want).abs() <= 1e-13 * (1.0 + want.abs()),
                "(K x)[{i}]: {got} against {want}"
            );
        }
    }

    /// Products of several vectors stored interleaved are, vector by vector and bit for bit,
    /// the products of one vector (`M X` and `Mᵀ X`, with zero columns of some vectors and of
    /// all, and empty columns of `M`).
    #[test]
    fn interleaved_products_are_each_vector_s_own() {
        let (rows, cols, k) = (40, 30, 3);
        let mut rnd = uniform(5);
        let mut t = vec![];
        for j in (0..cols).filter(|j| j % 7 != 3) {
            for _ in 0..4 {
                t.push(Triplet::new((rnd() * rows as f64) as usize, j, rnd() - 0.5));
            }
        }
        let m = SparseColMat::<usize, f64>::try_new_from_triplets(rows, cols, &t).unwrap();
        let mut vector = |n: usize, f: usize| -> Vec<f64> {
            (0..n)
                .map(|i| if i % 5 == f || i % 11 == 0 { 0.0 } else { rnd() - 0.5 })
                .collect()
        };
        let xs: Vec<Vec<f64>> = (0..k).map(|f| vector(cols, f)).collect();
        let xts: Vec<Vec<f64>> = (0..k).map(|f| vector(rows, f)).collect();
        let interleave = |v: &[Vec<f64>], n: usize| -> Vec<f64> { (0..n * k).map(|i| v[i % k][i / k]).collect() };
        let (mut y, mut yt) = (vec![1.0; rows * k], vec![1.0; cols * k]);
        mul_add_interleaved(m.as_ref(), &interleave(&xs, cols), &mut y, k, -2.0);
        mul_t_add_interleaved(m.as_ref(), &interleave(&xts, rows), &mut yt, k, 0.5);
        for f in 0..k {
            let (mut one, mut one_t) = (vec![1.0; rows], vec![1.0; cols]);
            mul_add_seq(m.as_ref(), &xs[f], &mut one, -2.0);
            mul_t_add_seq(m.as_ref(), &xts[f], &mut one_t, 0.5);
            let got: Vec<f64> = (0..rows).map(|i| y[i * k + f]).collect();
            let got_t: Vec<f64> = (0..cols).map(|j| yt[j * k + f]).collect();
            assert_eq!(got, one, "M x of vector {f}");
            assert_eq!(got_t, one_t, "Mᵀ x of vector {f}");
        }
    }

    /// A large product (on the pool, in parts) equals the column-by-column one to round-off,
    /// and is the same, bit for bit, on pools of 1 and 3 threads; `Mᵀ x` likewise.
    #[test]
    fn the_parallel_products_are_the_sequential_ones() {
        let (rows, cols) = (3000, 2500);
        let mut rnd = uniform(7);
        let mut t = vec![];
        for j in 0..cols {
            // 120 entries per column: 300 000 in all, above PARALLEL_ENTRIES; the last columns empty
            if j < cols - 3 {
                for _ in 0..120 {
                    t.push(Triplet::new((rnd() * rows as f64) as usize, j, rnd() - 0.5));
                }
            }
        }
        let m = SparseColMat::<usize, f64>::try_new_from_triplets(rows, cols, &t).unwrap();
        assert!(m.val().len() >= PARALLEL_ENTRIES);
        let x: Vec<f64> = (0..cols).map(|_| rnd() - 0.5).collect();
        let xt: Vec<f64> = (0..rows).map(|_| rnd() - 0.5).collect();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let (mut y, mut yt) = (vec![1.0; rows], vec![1.0; cols]);
                mul_add(m.as_ref(), &x, &mut y, -2.0);
                mul_t_add(m.as_ref(), &xt, &mut yt, 0.5);
                (y, yt)
            })
        };
        let (y1, yt1) = on(1);
        assert_eq!(on(3), (y1.clone(), yt1.clone()));
        let mut y = vec![1.0; rows];
        mul_add_columns(m.as_ref(), 0..cols, &x, &mut y, -2.0);
        let scale = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(y.iter().zip(&y1).all(|(a, b)| (a - b).abs() <= 1e-13 * scale));
        let dense = to_dense(m.as_ref());
        for (j, v) in yt1.iter().enumerate() {
            let exact: f64 = 1.0 + 0.5 * (0..rows).map(|i| dense[i][j] * xt[i]).sum::<f64>();
            assert!((v - exact).abs() <= 1e-12 * (1.0 + exact.abs()), "column {j}");
        }
    }
}
