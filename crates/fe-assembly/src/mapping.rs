//! Curved (isoparametric) second-order cells and facets: the map `x(ξ) = Σ_a N_a(ξ) x_a` of
//! the reference simplex through the P2 shape functions of its nodes (corners, then the edges'
//! midpoints), where an edge node lies off its edge's midpoint (a second-order Gmsh mesh of a
//! curved geometry). A straight-sided simplex keeps its affine map (its corners), whose
//! Jacobian is constant: the kernels then take their fast form, and the numbers of a
//! straight-sided mesh are what they were.
//!
//! The reference coordinates are `ξ_k = λ_{k+1}` (`λ_0 = 1 - Σ ξ_k`), so
//! `∂N_a/∂ξ_k = ∂N_a/∂λ_{k+1} - ∂N_a/∂λ_0`; the Jacobian's columns are `∂x/∂ξ_k`; a point of a
//! rule whose weights sum to 1 stands for `w |det J| / d!` of measure on a `d`-cell
//! (`√det(JᵀJ) / d!` on a facet).

use crate::kernels::{shape_values, simplex_edges, QuadraticRule, MAX_NODES, MAX_POINTS};

/// `∂N_a/∂ξ_k` of the P2 shape functions of the simplex of dimension `d` at the barycentric
/// coordinates `l` (corner `i`: `λ_i (2 λ_i - 1)`, edge `i-j`: `4 λ_i λ_j`, the edges in
/// [`simplex_edges`]' order).
pub fn shape_derivatives(d: usize, l: &[f64; 4]) -> [[f64; 3]; MAX_NODES] {
    // ∂N_a/∂λ_i first, then to ξ
    let corners = d + 1;
    let mut by_lambda = [[0.0; 4]; MAX_NODES];
    for i in 0..corners {
        by_lambda[i][i] = 4.0 * l[i] - 1.0;
    }
    for (e, &[i, j]) in simplex_edges(d).iter().enumerate() {
        by_lambda[corners + e][i] = 4.0 * l[j];
        by_lambda[corners + e][j] = 4.0 * l[i];
    }
    let mut out = [[0.0; 3]; MAX_NODES];
    for (o, b) in out.iter_mut().zip(&by_lambda).take(corners + simplex_edges(d).len()) {
        for k in 0..d {
            o[k] = b[k + 1] - b[0];
        }
    }
    out
}

/// The point `x(l)` of the simplex of dimension `d` whose nodes are `x` (its `d + 1` corners:
/// the affine map; or a P2 simplex's corners and edge midpoints: the isoparametric one), and
/// the Jacobian's columns `∂x/∂ξ_k` there.
pub fn map_at(d: usize, x: &[[f64; 3]], l: &[f64; 4]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut point = [0.0; 3];
    let mut jac = [[0.0; 3]; 3];
    if x.len() == d + 1 {
        for (a, xa) in x.iter().enumerate() {
            for i in 0..3 {
                point[i] += l[a] * xa[i];
            }
        }
        for (k, col) in jac.iter_mut().enumerate().take(d) {
            for i in 0..3 {
                col[i] = x[k + 1][i] - x[0][i];
            }
        }
        return (point, jac);
    }
    let (n, dn) = (shape_values(d, 2, l), shape_derivatives(d, l));
    for (a, xa) in x.iter().enumerate() {
        for i in 0..3 {
            point[i] += n[a] * xa[i];
            for (k, col) in jac.iter_mut().enumerate().take(d) {
                col[i] += dn[a][k] * xa[i];
            }
        }
    }
    (point, jac)
}

/// The measure a unit of reference weight stands for at a point whose Jacobian's columns are
/// `jac` (`d` of them): `√det(JᵀJ) / d!` (`|det J| / d!` on a cell of the space's dimension,
/// the length of `∂x/∂ξ` on a segment, half the area of the parallelogram on a triangle).
pub fn measure_at(d: usize, jac: &[[f64; 3]; 3]) -> f64 {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    match d {
        1 => dot(&jac[0], &jac[0]).sqrt(),
        2 => {
            let (a, b) = (&jac[0], &jac[1]);
            let c = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            0.5 * dot(&c, &c).sqrt()
        }
        _ => signed_volume(jac).abs() / 6.0,
    }
}

/// `det J` of a 3D cell's map (`∂x/∂ξ_k` as columns).
fn signed_volume(jac: &[[f64; 3]; 3]) -> f64 {
    let (a, b, c) = (&jac[0], &jac[1], &jac[2]);
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// The signed `det J` of a cell of dimension `dim` (its columns `jac`; in 2D the z components
/// are 0): positive where the map keeps the reference simplex's orientation.
pub fn jacobian_det(dim: usize, jac: &[[f64; 3]; 3]) -> f64 {
    if dim == 2 {
        jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]
    } else {
        signed_volume(jac)
    }
}

/// The gradients `∇_x N_a = J⁻ᵀ ∇_ξ N_a` of a cell of dimension `dim` from the reference
/// derivatives `dn` of its `n` shape functions and its Jacobian's columns `jac` (of
/// determinant `det`).
pub fn physical_gradients(
    dim: usize,
    n: usize,
    dn: &[[f64; 3]; MAX_NODES],
    jac: &[[f64; 3]; 3],
    det: f64,
) -> [[f64; 3]; MAX_NODES] {
    // J[i][k] = jac[k][i]; the rows of J⁻¹ are the gradients of ξ_k
    let j = |i: usize, k: usize| jac[k][i];
    let mut inv = [[0.0; 3]; 3]; // inv[k][i] = ∂ξ_k/∂x_i
    if dim == 2 {
        inv[0] = [j(1, 1) / det, -j(0, 1) / det, 0.0];
        inv[1] = [-j(1, 0) / det, j(0, 0) / det, 0.0];
    } else {
        for k in 0..3 {
            for i in 0..3 {
                // the cofactor of J[i][k], over det
                let (i1, i2, k1, k2) = ((i + 1) % 3, (i + 2) % 3, (k + 1) % 3, (k + 2) % 3);
                inv[k][i] = (j(i1, k1) * j(i2, k2) - j(i1, k2) * j(i2, k1)) / det;
            }
        }
    }
    let mut out = [[0.0; 3]; MAX_NODES];
    for (o, d) in out.iter_mut().zip(dn).take(n) {
        for i in 0..dim {
            o[i] = (0..dim).map(|k| d[k] * inv[k][i]).sum();
        }
    }
    out
}

impl QuadraticRule {
    /// The P2 shape functions of a curved (isoparametric) cell of dimension `dim` whose nodes
    /// are at `x` (corners, then the edges' midpoints off their chords), at the `points`
    /// (barycentric coordinates of the reference simplex) with their `weights` (fractions of
    /// the reference measure): each point's gradients `J⁻ᵀ ∇_ξ N_a`, its weight
    /// `w |det J| / dim!`, on a body of revolution (`axisymmetric`) times `2π r` with
    /// `r = Σ N_a r_a` and `N_a / r` its hoop values ([`crate::mapping`]).
    pub fn mapped(dim: usize, x: &[[f64; 3]], points: &[[f64; 4]], weights: &[f64], axisymmetric: bool) -> Self {
        let n_local = x.len();
        let mut rule = QuadraticRule {
            n_local,
            n_points: points.len().min(MAX_POINTS),
            weight: [0.0; MAX_POINTS],
            value: [[0.0; MAX_NODES]; MAX_POINTS],
            grad: [[[0.0; 3]; MAX_NODES]; MAX_POINTS],
            hoop: [[0.0; MAX_NODES]; MAX_POINTS],
        };
        let factorial = if dim == 2 { 2.0 } else { 6.0 };
        for (p, (l, w)) in points.iter().zip(weights).enumerate().take(MAX_POINTS) {
            let (at, jac) = map_at(dim, x, l);
            let det = jacobian_det(dim, &jac);
            let dn = shape_derivatives(dim, l);
            rule.value[p] = shape_values(dim, 2, l);
            rule.grad[p] = physical_gradients(dim, n_local, &dn, &jac, det);
            // positive: a cell whose map folds is refused where it is made (`Discretization::new`)
            rule.weight[p] = w * det / factorial;
            if axisymmetric {
                let r = at[0];
                rule.weight[p] *= std::f64::consts::TAU * r;
                for a in 0..n_local {
                    rule.hoop[p][a] = rule.value[p][a] / r;
                }
            }
        }
        rule
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_p2_simplex_maps_as_its_corners() {
        // a tetrahedron with its edge nodes at the midpoints: the P2 map is the affine one
        let corners = [[0.1, 0.0, 0.2], [1.3, 0.2, 0.0], [0.2, 1.1, 0.1], [0.3, 0.2, 0.9]];
        let mut x = corners.to_vec();
        for &[a, b] in simplex_edges(3) {
            x.push(std::array::from_fn(|i| 0.5 * (corners[a][i] + corners[b][i])));
        }
        let l = [0.1, 0.2, 0.3, 0.4];
        let (p1, j1) = map_at(3, &corners, &l);
        let (p2, j2) = map_at(3, &x, &l);
        for i in 0..3 {
            assert!((p1[i] - p2[i]).abs() < 1e-15);
            for k in 0..3 {
                assert!((j1[k][i] - j2[k][i]).abs() < 1e-14);
            }
        }
        // the gradients of the corners' P1 functions through J⁻ᵀ: the barycentric gradients,
        // whose sum is 0 and which take the edges to the Kronecker delta
        let det = jacobian_det(3, &j1);
        assert!((measure_at(3, &j1) - det / 6.0).abs() < 1e-15);
        let mut dn = [[0.0; 3]; MAX_NODES];
        dn[0] = [-1.0, -1.0, -1.0];
        for k in 0..3 {
            dn[k + 1][k] = 1.0;
        }
        let g = physical_gradients(3, 4, &dn, &j1, det);
        for a in 0..4 {
            for b in 1..4 {
                let e: f64 = (0..3).map(|i| g[a][i] * (corners[b][i] - corners[0][i])).sum();
                let expected = if a == b {
                    1.0
                } else if a == 0 {
                    -1.0
                } else {
                    0.0
                };
                assert!((e - expected).abs() < 1e-13, "{a} {b}: {e}");
            }
        }
    }

    #[test]
    fn a_quarter_circle_arc_has_its_length() {
        // the P2 segment through (1, 0), (cos 45°, sin 45°), (0, 1): its length by Gauss'
        // rule of the map within the P2 interpolation's error of π/2
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let x = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [s, s, 0.0]];
        let (w, p) = crate::kernels::simplex_rule(1, 2);
        let len: f64 = w
            .iter()
            .zip(p)
            .map(|(w, l)| w * measure_at(1, &map_at(1, &x, l).1))
            .sum();
        assert!(
            (len - std::f64::consts::FRAC_PI_2).abs() < 2e-2 && (len - 2f64.sqrt()).abs() > 0.1,
            "{len}"
        );
    }
}
