//! P1 kernels: geometry of a simplex, the strain-displacement operator, and the columns of
//! the element matrices
//!
//! - `A_e = ∫_T Bᵀ C B dx`        (elasticity),
//! - `G_e = ∫_T ∇Nᵀ e B dx`       (coupling, rows ψ, columns u: `∫ (e ε(u)) · ∇ψ`),
//! - `B_e = ∫_T ∇Nᵀ β ∇N dx`      (dielectric),
//!
//! with `N` the P1 shape functions, whose gradients are constant on the cell, so that each
//! integral is the cell's measure times the integrand.
//!
//! A body of revolution (axisymmetric, meshed in its meridian plane `(r, z) = (x, y)`) adds the
//! hoop strain `ε_θθ = u_r / r` (Voigt entry 3 after `[rr, zz, rz]`) and integrates over the
//! whole body, `dx = 2π r dr dz`: the three-point interior rule of the triangle (degree 2,
//! points at `r > 0` even on a cell touching the axis), so that forces and charges are totals.

use crate::Material;

/// Measure and shape-function gradients of one P1 simplex (at most 4 nodes, 3 components).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimplexGeometry {
    /// Area (2D) or volume (3D), positive for a positively oriented cell.
    pub measure: f64,
    /// `grads[a][k] = ∂N_a / ∂x_k`.
    pub grads: [[f64; 3]; 4],
    /// The radii `r = x` of the vertices of a cell of a body of revolution; `None` in plane
    /// strain and 3D.
    pub radii: Option<[f64; 3]>,
}

/// A point of a cell's quadrature: its weight (the measure it stands for, `2π r` included in a
/// body of revolution) and `N_a / r` there (0 off a body of revolution).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellPoint {
    /// Weight.
    pub weight: f64,
    /// `hoop[a] = N_a / r` at the point.
    pub hoop: [f64; 4],
}

/// The barycentric coordinates of the triangle's interior three-point rule (degree 2).
const TRIANGLE_RULE: [[f64; 3]; 3] = [
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

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

    /// The same cell as a meridian section of a body of revolution about the y axis (its
    /// vertices' `x` are their radii).
    pub fn axisymmetric(x: &[[f64; 3]]) -> Self {
        SimplexGeometry {
            radii: Some([x[0][0], x[1][0], x[2][0]]),
            ..Self::new(2, x)
        }
    }

    /// The points of the cell's quadrature: one (the measure, the integrands being constant)
    /// in plane strain and 3D; three on a body of revolution (`2π r` in the weights, the hoop
    /// terms `N_a / r` varying over the cell). Returns the points and how many are used.
    pub fn points(&self) -> ([CellPoint; 3], usize) {
        let mut out = [CellPoint::default(); 3];
        let Some(r) = self.radii else {
            out[0].weight = self.measure;
            return (out, 1);
        };
        for (p, bary) in out.iter_mut().zip(&TRIANGLE_RULE) {
            let rq: f64 = (0..3).map(|a| bary[a] * r[a]).sum();
            p.weight = std::f64::consts::TAU * rq * self.measure / 3.0;
            for a in 0..3 {
                p.hoop[a] = bary[a] / rq;
            }
        }
        (out, 3)
    }

    /// The cell's volume: its measure, or `2π r̄` times it for a meridian section (`r̄` the
    /// centroid's radius: Pappus).
    pub fn volume(&self) -> f64 {
        match self.radii {
            Some(r) => std::f64::consts::TAU * (r[0] + r[1] + r[2]) / 3.0 * self.measure,
            None => self.measure,
        }
    }

    /// `N_a / r` at the centroid of a meridian section (`1 / (3 r̄)` for every vertex); 0
    /// otherwise.
    pub fn centroid_hoop(&self) -> [f64; 4] {
        match self.radii {
            Some(r) => {
                let h = 1.0 / (r[0] + r[1] + r[2]);
                [h, h, h, 0.0]
            }
            None => [0.0; 4],
        }
    }
}

/// `B_a` at a point where `N_a / r = hoop` (0 off a body of revolution): [`strain_columns`]
/// with the hoop strain `u_r / r` of the radial component in Voigt entry 3 (`[rr, zz, rz, θθ]`).
pub fn strain_columns_at(dim: usize, grad: &[f64; 3], hoop: f64) -> [[f64; 6]; 3] {
    let mut b = strain_columns(dim, grad);
    if dim == 2 {
        b[0][3] = hoop;
    }
    b
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
    let mut out = [[0.0; 3]; 4];
    let (points, n_points) = g.points();
    for p in &points[..n_points] {
        let ba = strain_columns_at(dim, &g.grads[a], p.hoop[a])[k];
        let mut cb = [0.0; 6];
        for i in 0..nv {
            cb[i] = (0..nv).map(|j| m.c[i * nv + j] * ba[j]).sum::<f64>() * p.weight;
        }
        for (b, row) in out.iter_mut().enumerate().take(n_local) {
            let bb = strain_columns_at(dim, &g.grads[b], p.hoop[b]);
            for (l, v) in row.iter_mut().enumerate().take(dim) {
                *v += (0..nv).map(|i| bb[l][i] * cb[i]).sum::<f64>();
            }
        }
    }
    out
}

/// Column `(a, k)` of `G_e = ∫ ∇Nᵀ e B` (rows ψ_b): `out[b] = Σ_q w_q ∇N_b · (e B_a(q) e_k)`.
pub fn coupling_column(m: &Material, g: &SimplexGeometry, n_local: usize, a: usize, k: usize) -> [f64; 4] {
    let (dim, nv) = (m.dim, m.nv());
    let mut eb = [0.0; 3];
    let (points, n_points) = g.points();
    for p in &points[..n_points] {
        let ba = strain_columns_at(dim, &g.grads[a], p.hoop[a])[k];
        for (i, v) in eb.iter_mut().enumerate().take(dim) {
            *v += (0..nv).map(|j| m.e[i * nv + j] * ba[j]).sum::<f64>() * p.weight;
        }
    }
    let mut out = [0.0; 4];
    for (b, v) in out.iter_mut().enumerate().take(n_local) {
        *v = (0..dim).map(|i| g.grads[b][i] * eb[i]).sum();
    }
    out
}

/// Row `b` of `G_e` as columns `(a, k)`: `out[a][k] = Σ_q w_q ∇N_b · (e B_a(q) e_k)`; this is
/// the column `b` of `G_eᵀ` (rows u).
pub fn coupling_row(m: &Material, g: &SimplexGeometry, n_local: usize, b: usize) -> [[f64; 3]; 4] {
    let (dim, nv) = (m.dim, m.nv());
    // eT grad_b (nv), then B_a^T (eT grad_b)
    let mut etg = [0.0; 6];
    for (j, v) in etg.iter_mut().enumerate().take(nv) {
        *v = (0..dim).map(|i| m.e[i * nv + j] * g.grads[b][i]).sum::<f64>();
    }
    let mut out = [[0.0; 3]; 4];
    let (points, n_points) = g.points();
    for p in &points[..n_points] {
        let mut weighted = [0.0; 6];
        for (w, e) in weighted.iter_mut().zip(&etg).take(nv) {
            *w = e * p.weight;
        }
        for (a, row) in out.iter_mut().enumerate().take(n_local) {
            let ba = strain_columns_at(dim, &g.grads[a], p.hoop[a]);
            for (k, v) in row.iter_mut().enumerate().take(dim) {
                *v += (0..nv).map(|j| ba[k][j] * weighted[j]).sum::<f64>();
            }
        }
    }
    out
}

/// Column `a` of `B_e = ∫ ∇Nᵀ β ∇N`: `out[b] = |T| ∇N_b · β ∇N_a` (`|T|` the cell's volume).
pub fn dielectric_column(m: &Material, g: &SimplexGeometry, n_local: usize, a: usize) -> [f64; 4] {
    let dim = m.dim;
    let mut bg = [0.0; 3];
    for (i, v) in bg.iter_mut().enumerate().take(dim) {
        *v = (0..dim).map(|j| m.beta[i * dim + j] * g.grads[a][j]).sum::<f64>() * g.volume();
    }
    let mut out = [0.0; 4];
    for (b, v) in out.iter_mut().enumerate().take(n_local) {
        *v = (0..dim).map(|i| g.grads[b][i] * bg[i]).sum();
    }
    out
}

/// Voigt strain of a P1 displacement on a cell: `ε = Σ_a B_a u_a` (at the centroid, where the
/// hoop strain of a body of revolution varies).
pub fn cell_strain(dim: usize, g: &SimplexGeometry, u_local: &[[f64; 3]]) -> [f64; 6] {
    strain_at(dim, g, &g.centroid_hoop(), u_local)
}

/// Voigt strain of a P1 displacement at a point where `N_a / r = hoop[a]`.
pub fn strain_at(dim: usize, g: &SimplexGeometry, hoop: &[f64; 4], u_local: &[[f64; 3]]) -> [f64; 6] {
    let mut eps = [0.0; 6];
    let coordinates = match g.radii {
        Some(_) => crate::Coordinates::Axisymmetric,
        None => crate::Coordinates::Cartesian,
    };
    let nv = crate::voigt_len(dim, coordinates);
    for (a, ua) in u_local.iter().enumerate() {
        let b = strain_columns_at(dim, &g.grads[a], hoop[a]);
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
