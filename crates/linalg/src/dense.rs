//! Dense kernels of the condensation: the symmetric inverse `Xᵀ D⁻¹ X` from a unit
//! lower-triangular `X = L⁻¹`, written row-major, on rayon's pool.

use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

/// Rows of the product computed by one task of [`unit_lower_gram`] (one dense product each).
const GRAM_ROWS: usize = 128;

/// Side of the square tiles [`mirror_lower`] copies (two of them fit in a core's L2 cache).
const TILE: usize = 64;

/// `P = Xᵀ diag(d)⁻¹ X` for a unit lower-triangular `x` (`k x k`, its strict upper part zero),
/// symmetric, row-major. Row block `[i₀, i₁)` of `P`'s lower part is one dense product,
/// `P[i₀..i₁, ..i₁] = (Y[i₀.., ..i₁]ᵀ X[i₀.., i₀..i₁])ᵀ` with `Y = diag(d)⁻¹ X`: the zeros above
/// the diagonal start every sum `Σ_l X_li Y_lj` at `l = max(i, j) ≥ i₀`, so the block costs
/// `2 (k - i₀) i₁ (i₁ - i₀)` flops and all of them `k³/3`, as a triangular product's, but in
/// dense kernels; the row blocks run as rayon tasks, and the upper part is mirrored.
pub(crate) fn unit_lower_gram(x: MatRef<'_, f64>, d: &[f64]) -> Vec<f64> {
    let k = x.nrows();
    let mut out = vec![0.0; k * k];
    if k == 0 {
        return out;
    }
    // `Y`'s lower part, column by column on the pool (fresh zero pages: the upper part zero)
    let mut y_values = vec![0.0; k * k];
    y_values.par_chunks_mut(k).enumerate().for_each(|(j, col)| {
        for i in j..k {
            col[i] = x[(i, j)] / d[i];
        }
    });
    let y = MatRef::from_column_major_slice(&y_values, k, k);
    out.par_chunks_mut(GRAM_ROWS * k).enumerate().for_each(|(b, rows)| {
        let (i0, nb) = (b * GRAM_ROWS, rows.len() / k);
        let i1 = i0 + nb;
        // element (c, r) at rows[r k + c]: P[i0 + r, c], c < i1, row-major
        let dest = MatMut::from_column_major_slice_with_stride_mut(rows, i1, nb, k);
        faer::linalg::matmul::matmul(
            dest,
            Accum::Replace,
            y.as_ref().subrows(i0, k - i0).subcols(0, i1).transpose(),
            x.subrows(i0, k - i0).subcols(i0, nb),
            1.0,
            Par::Seq,
        );
    });
    mirror_lower(&mut out, k);
    out
}

/// Copies the lower triangle of the row-major `k x k` matrix `a` onto its upper triangle, by
/// tiles, on rayon's pool (a symmetric matrix computed by its lower half).
///
/// # Panics
/// Where `a` holds fewer than `k²` values.
pub fn mirror_lower(a: &mut [f64], k: usize) {
    mirror_rows(a, 0..k, k);
}

/// [`mirror_lower`] on the square `span x span` of `rows` (the matrix's rows `span`, each of
/// `k` values): the two halves' own squares at the same time, after the off-diagonal block.
fn mirror_rows(rows: &mut [f64], span: std::ops::Range<usize>, k: usize) {
    let (lo, hi) = (span.start, span.end);
    if hi - lo <= 4 * TILE {
        for r in lo..hi {
            for c in r + 1..hi {
                rows[(r - lo) * k + c] = rows[(c - lo) * k + r];
            }
        }
        return;
    }
    let mid = lo + (hi - lo) / 2;
    let (top, bottom) = rows.split_at_mut((mid - lo) * k);
    // the top rows' columns mid..hi from the bottom rows' columns lo..mid, by tiles
    top.par_chunks_mut(TILE * k).enumerate().for_each(|(t, chunk)| {
        let r0 = lo + t * TILE;
        for c0 in (mid..hi).step_by(TILE) {
            for c in c0..(c0 + TILE).min(hi) {
                let src = &bottom[(c - mid) * k..];
                for (rr, r) in (r0..r0 + chunk.len() / k).enumerate() {
                    chunk[rr * k + c] = src[r];
                }
            }
        }
    });
    let bottom_span = mid..hi;
    rayon::join(|| mirror_rows(top, lo..mid, k), || mirror_rows(bottom, bottom_span, k));
}

/// `(M + Mᵀ)/2` of a square matrix, row-major: a product that is symmetric in exact arithmetic,
/// with its round-off asymmetry removed.
pub(crate) fn symmetric_row_major(m: &faer::Mat<f64>) -> Vec<f64> {
    let k = m.nrows();
    let mut out = vec![0.0; k * k];
    for i in 0..k {
        for j in 0..=i {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            out[i * k + j] = v;
            out[j * k + i] = v;
        }
    }
    out
}

/// The inverse of the symmetric, nonsingular `k x k` matrix `a` (row-major), row-major: by
/// Cholesky where `a` is positive definite, else by LU with partial pivoting (a quasi-definite
/// Schur complement, say, whose potentials' block is negative); symmetric to the last bit (its
/// lower half mirrored).
///
/// # Errors
/// [`crate::LinalgError::NonFinite`] where the inverse is not finite (a singular `a`).
pub fn symmetric_inverse(a: &[f64], k: usize) -> Result<Vec<f64>, crate::LinalgError> {
    use faer::linalg::solvers::DenseSolveCore;
    let m = faer::Mat::<f64>::from_fn(k, k, |i, j| a[i * k + j]);
    let inv = match m.llt(faer::Side::Lower) {
        Ok(llt) => llt.inverse(),
        Err(_) => m.partial_piv_lu().inverse(),
    };
    let mut out = vec![0.0; k * k];
    for i in 0..k {
        for j in 0..=i {
            out[i * k + j] = inv[(i, j)];
        }
    }
    if out.iter().any(|v| !v.is_finite()) {
        return Err(crate::LinalgError::NonFinite {
            what: "the inverse of a dense symmetric matrix (singular?)".into(),
        });
    }
    mirror_lower(&mut out, k);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit lower-triangular matrix with entries of both signs, and pivots of both signs.
    fn data(k: usize) -> (faer::Mat<f64>, Vec<f64>) {
        let x = faer::Mat::<f64>::from_fn(k, k, |i, j| match i.cmp(&j) {
            std::cmp::Ordering::Less => 0.0,
            std::cmp::Ordering::Equal => 1.0,
            std::cmp::Ordering::Greater => ((i * 31 + j * 17) % 13) as f64 / 13.0 - 0.45,
        });
        let d = (0..k)
            .map(|i| {
                if i % 5 == 3 {
                    -0.5 - i as f64 * 1e-3
                } else {
                    1.0 + (i % 7) as f64
                }
            })
            .collect();
        (x, d)
    }

    #[test]
    fn the_gram_product_is_the_triangular_one() {
        // sizes below, at and across the row blocks and the mirror's tiles
        for k in [0, 1, 5, 127, 128, 129, 300, 700] {
            let (x, d) = data(k);
            let p = unit_lower_gram(x.as_ref(), &d);
            let mut scale = 0.0f64;
            let mut err = 0.0f64;
            for i in 0..k {
                for j in 0..k {
                    let exact: f64 = (i.max(j)..k).map(|l| x[(l, i)] * x[(l, j)] / d[l]).sum();
                    scale = scale.max(exact.abs());
                    err = err.max((p[i * k + j] - exact).abs());
                    assert_eq!(p[i * k + j], p[j * k + i], "not symmetric at ({i}, {j}), k = {k}");
                }
            }
            assert!(err <= 1e-13 * scale.max(1.0), "k = {k}: error {err:e} of {scale:e}");
        }
    }

    #[test]
    fn the_mirror_copies_the_lower_triangle() {
        for k in [1, 2, 255, 256, 257, 1000] {
            let mut a: Vec<f64> = (0..k * k).map(|i| i as f64).collect();
            mirror_lower(&mut a, k);
            for i in 0..k {
                for j in 0..k {
                    let (r, c) = (i.max(j), i.min(j));
                    assert_eq!(a[i * k + j], (r * k + c) as f64, "k = {k}, ({i}, {j})");
                }
            }
        }
    }

    /// `a · a⁻¹ = I` for a definite and an indefinite (quasi-definite) matrix, and a singular
    /// one refused.
    #[test]
    fn the_symmetric_inverse_inverts_definite_and_indefinite_matrices() {
        let definite = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let indefinite = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, -2.0];
        for a in [definite, indefinite] {
            let inv = super::symmetric_inverse(&a, 3).unwrap();
            for i in 0..3 {
                for j in 0..3 {
                    let p: f64 = (0..3).map(|l| a[i * 3 + l] * inv[l * 3 + j]).sum();
                    assert!((p - f64::from(u8::from(i == j))).abs() < 1e-14, "({i}, {j}): {p}");
                    assert_eq!(inv[i * 3 + j], inv[j * 3 + i]);
                }
            }
        }
        assert!(super::symmetric_inverse(&[1.0, 1.0, 1.0, 1.0], 2).is_err());
    }
}
