//! P1 kernels: geometry of a simplex, the strain-displacement operator, and the columns of
//! the element matrices
//!
//! - `A_e = ∫_T Bᵀ C B dx`        (elasticity),
//! - `G_e = ∫_T ∇Nᵀ e B dx`       (coupling, rows ψ, columns u: `∫ (e ε(u)) · ∇ψ`),
//! - `B_e = ∫_T ∇Nᵀ β ∇N dx`      (dielectric),
//!
//! with `N` the P1 shape functions, whose gradients are constant on the cell, so that each
//! integral is the cell's measure times the integrand.

use crate::Material;

/// Measure and shape-function gradients of one P1 simplex (at most 4 nodes, 3 components).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimplexGeometry {
    /// Area (2D) or volume (3D), positive for a positively oriented cell.
    pub measure: f64,
    /// `grads[a][k] = ∂N_a / ∂x_k`.
    pub grads: [[f64; 3]; 4],
}

impl SimplexGeometry {
    /// The geometry of the simplex with vertices `x` (`dim + 1` points).
    pub fn new(dim: usize, x: &[[f64; 3]]) -> Self {
        let mut g = SimplexGeometry::default();
        if dim == 2 {
            let (x0, x1, x2) = (x[0], x[1], x[2]);
            let det = (x1[0] - x0[0]) * (x2[1] - x0[1]) - (x2[0] - x0[0]) * (x1[1] - x0[1]);
            g.measure = 0.5 * det;
            let inv = 1.0 / det;
            g.grads[0] = [(x1[1] - x2[1]) * inv, (x2[0] - x1[0]) * inv, 0.0];
            g.grads[1] = [(x2[1] - x0[1]) * inv, (x0[0] - x2[0]) * inv, 0.0];
            g.grads[2] = [(x0[1] - x1[1]) * inv, (x1[0] - x0[0]) * inv, 0.0];
        } else {
            // J = [x1 - x0, x2 - x0, x3 - x0] (columns); grad N_a (a = 1..3) = row a-1 of J^-1
            let d = |a: usize, k: usize| x[a][k] - x[0][k];
            let j = [
                [d(1, 0), d(2, 0), d(3, 0)],
                [d(1, 1), d(2, 1), d(3, 1)],
                [d(1, 2), d(2, 2), d(3, 2)],
            ];
            let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
            g.measure = det / 6.0;
            let inv = 1.0 / det;
            // inverse by cofactors: (J^-1)_{ik} = cof(J)_{ki} / det
            let cof = |r: usize, c: usize| {
                let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
                let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
                j[r1][c1] * j[r2][c2] - j[r1][c2] * j[r2][c1]
            };
            for a in 0..3 {
                for k in 0..3 {
                    g.grads[a + 1][k] = cof(k, a) * inv;
                }
            }
            for k in 0..3 {
                g.grads[0][k] = -(g.grads[1][k] + g.grads[2][k] + g.grads[3][k]);
            }
        }
        g
    }
}

/// `B_a`, the strain of the displacement `N_a e_k` for `k = 0..dim`, as a column-major
/// `nv x dim` array: `b[k][v]` is Voigt strain `v` of the unit displacement of component `k`.
pub fn strain_columns(dim: usize, grad: &[f64; 3]) -> [[f64; 6]; 3] {
    let mut b = [[0.0; 6]; 3];
    let [gx, gy, gz] = *grad;
    if dim == 2 {
        // [xx, yy, xy]
        b[0][0] = gx;
        b[0][2] = gy;
        b[1][1] = gy;
        b[1][2] = gx;
    } else {
        // [xx, yy, zz, yz, xz, xy]
        b[0][0] = gx;
        b[0][4] = gz;
        b[0][5] = gy;
        b[1][1] = gy;
        b[1][3] = gz;
        b[1][5] = gx;
        b[2][2] = gz;
        b[2][3] = gy;
        b[2][4] = gx;
    }
    b
}

/// Column `(a, k)` of `A_e = ∫ Bᵀ C B`: `out[b][l]` is the entry of row `(b, l)`.
pub fn elasticity_column(m: &Material, g: &SimplexGeometry, n_local: usize, a: usize, k: usize) -> [[f64; 3]; 4] {
    let (dim, nv) = (m.dim, m.nv());
    let ba = strain_columns(dim, &g.grads[a])[k];
    let mut cb = [0.0; 6];
    for i in 0..nv {
        cb[i] = (0..nv).map(|j| m.c[i * nv + j] * ba[j]).sum::<f64>() * g.measure;
    }
    let mut out = [[0.0; 3]; 4];
    for (b, row) in out.iter_mut().enumerate().take(n_local) {
        let bb = strain_columns(dim, &g.grads[b]);
        for (l, v) in row.iter_mut().enumerate().take(dim) {
            *v = (0..nv).map(|i| bb[l][i] * cb[i]).sum();
        }
    }
    out
}

/// Column `(a, k)` of `G_e = ∫ ∇Nᵀ e B` (rows ψ_b): `out[b] = |T| ∇N_b · (e B_a e_k)`.
pub fn coupling_column(m: &Material, g: &SimplexGeometry, n_local: usize, a: usize, k: usize) -> [f64; 4] {
    let (dim, nv) = (m.dim, m.nv());
    let ba = strain_columns(dim, &g.grads[a])[k];
    let mut eb = [0.0; 3];
    for (i, v) in eb.iter_mut().enumerate().take(dim) {
        *v = (0..nv).map(|j| m.e[i * nv + j] * ba[j]).sum::<f64>() * g.measure;
    }
    let mut out = [0.0; 4];
    for (b, v) in out.iter_mut().enumerate().take(n_local) {
        *v = (0..dim).map(|i| g.grads[b][i] * eb[i]).sum();
    }
    out
}

/// Row `b` of `G_e` as columns `(a, k)`: `out[a][k] = |T| ∇N_b · (e B_a e_k)`; this is the
/// column `b` of `G_eᵀ` (rows u).
pub fn coupling_row(m: &Material, g: &SimplexGeometry, n_local: usize, b: usize) -> [[f64; 3]; 4] {
    let (dim, nv) = (m.dim, m.nv());
    // eT grad_b (nv), then B_a^T (eT grad_b)
    let mut etg = [0.0; 6];
    for (j, v) in etg.iter_mut().enumerate().take(nv) {
        *v = (0..dim).map(|i| m.e[i * nv + j] * g.grads[b][i]).sum::<f64>() * g.measure;
    }
    let mut out = [[0.0; 3]; 4];
    for (a, row) in out.iter_mut().enumerate().take(n_local) {
        let ba = strain_columns(dim, &g.grads[a]);
        for (k, v) in row.iter_mut().enumerate().take(dim) {
            *v = (0..nv).map(|j| ba[k][j] * etg[j]).sum();
        }
    }
    out
}

/// Column `a` of `B_e = ∫ ∇Nᵀ β ∇N`: `out[b] = |T| ∇N_b · β ∇N_a`.
pub fn dielectric_column(m: &Material, g: &SimplexGeometry, n_local: usize, a: usize) -> [f64; 4] {
    let dim = m.dim;
    let mut bg = [0.0; 3];
    for (i, v) in bg.iter_mut().enumerate().take(dim) {
        *v = (0..dim).map(|j| m.beta[i * dim + j] * g.grads[a][j]).sum::<f64>() * g.measure;
    }
    let mut out = [0.0; 4];
    for (b, v) in out.iter_mut().enumerate().take(n_local) {
        *v = (0..dim).map(|i| g.grads[b][i] * bg[i]).sum();
    }
    out
}

/// Voigt strain of a P1 displacement on a cell: `ε = Σ_a B_a u_a`.
pub fn cell_strain(dim: usize, g: &SimplexGeometry, u_local: &[[f64; 3]]) -> [f64; 6] {
    let mut eps = [0.0; 6];
    let nv = if dim == 2 { 3 } else { 6 };
    for (a, ua) in u_local.iter().enumerate() {
        let b = strain_columns(dim, &g.grads[a]);
        for k in 0..dim {
            for v in 0..nv {
                eps[v] += b[k][v] * ua[k];
            }
        }
    }
    eps
}

/// Gradient of a P1 scalar on a cell: `∇φ = Σ_a φ_a ∇N_a`.
pub fn cell_gradient(dim: usize, g: &SimplexGeometry, phi_local: &[f64]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (a, &p) in phi_local.iter().enumerate() {
        for k in 0..dim {
            out[k] += p * g.grads[a][k];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_sum_to_zero_and_reproduce_linears() {
        let x = [[0.1, 0.2, 0.0], [1.3, 0.1, 0.2], [0.4, 1.1, -0.1], [0.3, 0.2, 0.9]];
        for dim in [2, 3] {
            let g = SimplexGeometry::new(dim, &x);
            assert!(g.measure > 0.0);
            for k in 0..dim {
                let s: f64 = (0..=dim).map(|a| g.grads[a][k]).sum();
                assert!(s.abs() < 1e-14);
                // the gradient of the linear function x_k is e_k
                for m in 0..dim {
                    let d: f64 = (0..=dim).map(|a| x[a][m] * g.grads[a][k]).sum();
                    assert!((d - if m == k { 1.0 } else { 0.0 }).abs() < 1e-14);
                }
            }
        }
    }
}
