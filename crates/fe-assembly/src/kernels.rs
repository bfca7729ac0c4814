//! Element kernels: geometry of a simplex, the strain-displacement operator, and the columns
//! of the element matrices
//!
//! - `A_e = ∫_T Bᵀ C B dx`        (elasticity),
//! - `G_e = ∫_T ∇Nᵀ e B dx`       (coupling, rows ψ, columns u: `∫ (e ε(u)) · ∇ψ`),
//! - `B_e = ∫_T ∇Nᵀ β ∇N dx`      (dielectric),
//!
//! summed over the points of a cell's quadrature ([`CellRule`]): with the P1 shape functions
//! ([`LinearRule`]) the gradients are constant on the cell and each integral is the cell's
//! measure times the integrand; with the P2 ones ([`QuadraticRule`], six-node triangles and
//! ten-node tetrahedra, straight-sided) the gradients are linear and a rule exact for their
//! products (degree 2) integrates them.
//!
//! A body of revolution (axisymmetric, meshed in its meridian plane `(r, z) = (x, y)`) adds the
//! hoop strain `ε_θθ = u_r / r` (Voigt entry 3 after `[rr, zz, rz]`) and integrates over the
//! whole body, `dx = 2π r dr dz`: interior rules of the triangle (P1: three points, degree 2;
//! P2: six points, degree 4; points at `r > 0` even on a cell touching the axis), so that forces
//! and charges are totals.

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

/// The most nodes of a cell (the ten-node tetrahedron).
pub const MAX_NODES: usize = 10;

/// The most points of a cell's quadrature (a curved tetrahedron's, [`curved_rule`]).
pub const MAX_POINTS: usize = 14;

/// What the element kernels read of a cell: the points of its quadrature, and at each the
/// weight (the measure it stands for, `2π r` included on a body of revolution), every shape
/// function's value and gradient, and `N_a / r` (0 off a body of revolution).
pub trait CellRule {
    /// The cell's shape functions (its nodes).
    fn n_local(&self) -> usize;
    /// The points of the quadrature.
    fn n_points(&self) -> usize;
    /// The weight of point `p`.
    fn weight(&self, p: usize) -> f64;
    /// `N_a` at point `p`.
    fn value(&self, p: usize, a: usize) -> f64;
    /// `∇N_a` at point `p`.
    fn grad(&self, p: usize, a: usize) -> &[f64; 3];
    /// `N_a / r` at point `p` (0 off a body of revolution).
    fn hoop(&self, p: usize, a: usize) -> f64;
    /// The cell's volume where the gradients are the same at every point (a P1 cell), so that
    /// the sums over the points factor; `None` otherwise.
    fn constant_gradients(&self) -> Option<f64>;
}

/// A P1 cell's quadrature ([`SimplexGeometry::points`]): its constant gradients, and the
/// points where the hoop terms of a body of revolution are taken.
#[derive(Clone, Copy, Debug)]
pub struct LinearRule<'g> {
    g: &'g SimplexGeometry,
    points: [CellPoint; 3],
    n_points: usize,
    n_local: usize,
    /// The barycentric coordinates of the points (`N_a` there).
    bary: [[f64; 4]; 3],
}

impl<'g> LinearRule<'g> {
    /// The rule of the P1 cell `g` of dimension `dim`.
    pub fn new(dim: usize, g: &'g SimplexGeometry) -> Self {
        let (points, n_points) = g.points();
        let mut bary = [[0.0; 4]; 3];
        if g.radii.is_some() {
            for (b, r) in bary.iter_mut().zip(&TRIANGLE_RULE) {
                b[..3].copy_from_slice(r);
            }
        } else {
            bary[0] = [1.0 / (dim + 1) as f64; 4];
        }
        LinearRule {
            g,
            points,
            n_points,
            n_local: dim + 1,
            bary,
        }
    }
}

impl CellRule for LinearRule<'_> {
    fn n_local(&self) -> usize {
        self.n_local
    }
    fn n_points(&self) -> usize {
        self.n_points
    }
    fn weight(&self, p: usize) -> f64 {
        self.points[p].weight
    }
    fn value(&self, p: usize, a: usize) -> f64 {
        self.bary[p][a]
    }
    fn grad(&self, _: usize, a: usize) -> &[f64; 3] {
        &self.g.grads[a]
    }
    fn hoop(&self, p: usize, a: usize) -> f64 {
        self.points[p].hoop[a]
    }
    fn constant_gradients(&self) -> Option<f64> {
        Some(self.g.volume())
    }
}

/// Barycentric quadrature on a simplex of dimension `dim` for shape functions of order
/// `order`: `(weights, points)`, weights summing to 1 (multiply by the measure). Order 1:
/// degree 2 (Gauss' two points on a segment, the interior `(2/3, 1/6, 1/6)` and its
/// permutations on a triangle, and on a
/// tetrahedron `(a, b, b, b)` and its permutations with `a = (5 + 3√5) / 20`,
/// `b = (5 - √5) / 20`, each of weight 1/4: Keast, Comput. Methods Appl. Mech. Eng. 55 (1986)
/// 339, rule 2). Order 2: Gauss' three points on a segment (degree 5), Dunavant's six on a
/// triangle (degree 4: `(a, a, 1 - 2a)` and its permutations; Int. J. Numer. Methods Eng. 21
/// (1985) 1129, table for p = 4), and on a tetrahedron the five-point rule of degree 3 (its
/// centroid weighted -4/5, the points `(1/2, 1/6, 1/6, 1/6)` 9/20; Stroud, Approximate
/// Calculation of Multiple Integrals, 1971, T3:3-1).
///
/// The rules are made once and kept: a P2 cell's rule is built for each of its nodes' columns
/// in the assembly.
pub fn simplex_rule(dim: usize, order: usize) -> (&'static [f64], &'static [[f64; 4]]) {
    type Rules = Vec<Vec<(Vec<f64>, Vec<[f64; 4]>)>>;
    static RULES: std::sync::LazyLock<Rules> =
        std::sync::LazyLock::new(|| (1..=3).map(|d| (1..=2).map(|o| made_rule(d, o)).collect()).collect());
    let (weights, points) = &RULES[dim.clamp(1, 3) - 1][order.clamp(1, 2) - 1];
    (weights, points)
}

/// The quadrature of a curved (isoparametric) P2 cell, whose map's Jacobian varies: on a
/// triangle Dunavant's six points of degree 4 ([`simplex_rule`]`(2, 2)`); on a tetrahedron
/// fourteen of degree 5 with positive weights (Walkington's, as libMesh and Keast's tables
/// give it), where the straight cell's four of degree 2 would miss the degree-3 integrand
/// `adj(J)ᵀ ∇_ξ N` of the patch test and Keast's five of degree 3 has a negative weight.
/// Weights as fractions of the reference measure (summing to 1).
pub fn curved_rule(dim: usize) -> (&'static [f64], &'static [[f64; 4]]) {
    static TET: std::sync::LazyLock<(Vec<f64>, Vec<[f64; 4]>)> = std::sync::LazyLock::new(|| {
        let (mut w, mut p) = (vec![], vec![]);
        // four points (a, a, a, 1 - 3a) of each of two kinds, then six (b, b, 1/2 - b, 1/2 - b)
        for (a, weight) in [
            (0.092_735_250_310_891_23, 0.012_248_840_519_393_66),
            (0.310_885_919_263_300_6, 0.018_781_320_953_002_64),
        ] {
            for k in 0..4 {
                let mut l = [a; 4];
                l[k] = 1.0 - 3.0 * a;
                p.push(l);
                w.push(6.0 * weight);
            }
        }
        let (b, weight) = (0.045_503_704_125_649_65, 0.007_091_003_462_846_911);
        for &[i, j] in simplex_edges(3) {
            let mut l = [0.5 - b; 4];
            (l[i], l[j]) = (b, b);
            p.push(l);
            w.push(6.0 * weight);
        }
        (w, p)
    });
    if dim == 3 {
        (&TET.0, &TET.1)
    } else {
        simplex_rule(dim, 2)
    }
}

/// The rule of [`simplex_rule`], made.
fn made_rule(dim: usize, order: usize) -> (Vec<f64>, Vec<[f64; 4]>) {
    match (dim, order) {
        (1, 1) => {
            let s = 0.5 / 3f64.sqrt();
            (
                vec![0.5, 0.5],
                vec![[0.5 - s, 0.5 + s, 0.0, 0.0], [0.5 + s, 0.5 - s, 0.0, 0.0]],
            )
        }
        (2, 1) => (
            vec![1.0 / 3.0; 3],
            TRIANGLE_RULE.iter().map(|l| [l[0], l[1], l[2], 0.0]).collect(),
        ),
        (_, 1) => {
            let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
            (
                vec![0.25; 4],
                vec![[a, b, b, b], [b, a, b, b], [b, b, a, b], [b, b, b, a]],
            )
        }
        (1, _) => {
            let s = 0.5 * (3.0f64 / 5.0).sqrt();
            (
                vec![5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0],
                vec![
                    [0.5 - s, 0.5 + s, 0.0, 0.0],
                    [0.5, 0.5, 0.0, 0.0],
                    [0.5 + s, 0.5 - s, 0.0, 0.0],
                ],
            )
        }
        (2, _) => {
            let (a1, w1) = (0.445_948_490_915_965, 0.223_381_589_678_011);
            let (a2, w2) = (0.091_576_213_509_771, 0.109_951_743_655_322);
            let (b1, b2) = (1.0 - 2.0 * a1, 1.0 - 2.0 * a2);
            (
                vec![w1, w1, w1, w2, w2, w2],
                vec![
                    [a1, a1, b1, 0.0],
                    [a1, b1, a1, 0.0],
                    [b1, a1, a1, 0.0],
                    [a2, a2, b2, 0.0],
                    [a2, b2, a2, 0.0],
                    [b2, a2, a2, 0.0],
                ],
            )
        }
        _ => {
            let (a, b) = (0.5, 1.0 / 6.0);
            (
                vec![-0.8, 0.45, 0.45, 0.45, 0.45],
                vec![[0.25; 4], [a, b, b, b], [b, a, b, b], [b, b, a, b], [b, b, b, a]],
            )
        }
    }
}

/// The shape functions of order `order` on a simplex of dimension `dim` at the barycentric
/// coordinates `l`: P1, `λ_a`; P2, the corners' `λ_i (2 λ_i - 1)` then the edges' `4 λ_i λ_j`
/// (a segment's one edge; a triangle's 0-1, 1-2, 2-0; a tetrahedron's 0-1, 1-2, 2-0, 0-3, 1-3,
/// 2-3: the order of the cells' and facets' nodes).
pub fn shape_values(dim: usize, order: usize, l: &[f64; 4]) -> [f64; MAX_NODES] {
    let corners = dim + 1;
    let mut n = [0.0; MAX_NODES];
    if order == 1 {
        n[..corners].copy_from_slice(&l[..corners]);
        return n;
    }
    for i in 0..corners {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
    }
    for (e, &[i, j]) in simplex_edges(dim).iter().enumerate() {
        n[corners + e] = 4.0 * l[i] * l[j];
    }
    n
}

/// The barycentric coordinates of a second-order simplex's nodes: its `dim + 1` corners, then
/// its edges' midpoints in [`simplex_edges`]' order.
pub fn simplex_nodes(dim: usize) -> Vec<[f64; 4]> {
    let corners = (0..=dim).map(|i| std::array::from_fn(|k| if k == i { 1.0 } else { 0.0 }));
    let edges = simplex_edges(dim)
        .iter()
        .map(|&[i, j]| std::array::from_fn(|k| if k == i || k == j { 0.5 } else { 0.0 }));
    corners.chain(edges).collect()
}

/// The edges of a simplex of dimension `dim` by its corners, in the order of a second-order
/// simplex's edge nodes: a segment's one edge; a triangle's 0-1, 1-2, 2-0; a tetrahedron's
/// 0-1, 1-2, 2-0, 0-3, 1-3, 2-3 (`mesh::CellKind::midside_edges` of the cells).
pub fn simplex_edges(dim: usize) -> &'static [[usize; 2]] {
    match dim {
        1 => &[[0, 1]],
        2 => &[[0, 1], [1, 2], [2, 0]],
        _ => &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
    }
}

/// A P2 cell's quadrature: the six-node triangle or ten-node tetrahedron on its straight-sided
/// simplex, its shape functions in the barycentric coordinates `λ` (corner `i`:
/// `λ_i (2 λ_i - 1)`; edge `i-j`: `4 λ_i λ_j`), their gradients through the constant `∇λ_i`
/// of the simplex. The points: degree 2 (three on a triangle, four on a tetrahedron: exact for
/// the products of gradients); on a body of revolution six of degree 4.
#[derive(Clone, Debug)]
pub struct QuadraticRule {
    pub(crate) n_local: usize,
    pub(crate) n_points: usize,
    pub(crate) weight: [f64; MAX_POINTS],
    pub(crate) value: [[f64; MAX_NODES]; MAX_POINTS],
    pub(crate) grad: [[[f64; 3]; MAX_NODES]; MAX_POINTS],
    pub(crate) hoop: [[f64; MAX_NODES]; MAX_POINTS],
}

impl QuadraticRule {
    /// The rule of the P2 cell on the simplex `g` of dimension `dim`.
    pub fn new(dim: usize, g: &SimplexGeometry) -> Self {
        // degree 2 (the rule for P1's loads), or degree 4 for the hoop terms of a body of
        // revolution (the rule for P2's loads on a triangle)
        let rule_order = if g.radii.is_some() { 2 } else { 1 };
        let (weights, points) = simplex_rule(dim, rule_order);
        Self::at(dim, g, points, weights)
    }

    /// The P2 shape functions of the simplex `g` at the `points` (barycentric coordinates),
    /// each standing for its `weights`' fraction of the cell's measure.
    pub fn at(dim: usize, g: &SimplexGeometry, points: &[[f64; 4]], weights: &[f64]) -> Self {
        let corners = dim + 1;
        let edges = simplex_edges(dim);
        let mut rule = QuadraticRule {
            n_local: corners + edges.len(),
            n_points: points.len().min(MAX_POINTS),
            weight: [0.0; MAX_POINTS],
            value: [[0.0; MAX_NODES]; MAX_POINTS],
            grad: [[[0.0; 3]; MAX_NODES]; MAX_POINTS],
            hoop: [[0.0; MAX_NODES]; MAX_POINTS],
        };
        for (p, (l, w)) in points.iter().zip(weights).enumerate().take(MAX_POINTS) {
            let gl = &g.grads;
            rule.value[p] = shape_values(dim, 2, l);
            for i in 0..corners {
                rule.grad[p][i] = gl[i].map(|x| (4.0 * l[i] - 1.0) * x);
            }
            for (e, &[i, j]) in edges.iter().enumerate() {
                rule.grad[p][corners + e] = std::array::from_fn(|k| 4.0 * (l[i] * gl[j][k] + l[j] * gl[i][k]));
            }
            rule.weight[p] = w * g.measure;
            if let Some(r) = g.radii {
                let rp: f64 = (0..3).map(|i| l[i] * r[i]).sum();
                rule.weight[p] *= std::f64::consts::TAU * rp;
                for a in 0..rule.n_local {
                    rule.hoop[p][a] = rule.value[p][a] / rp;
                }
            }
        }
        rule
    }
}

impl CellRule for QuadraticRule {
    fn n_local(&self) -> usize {
        self.n_local
    }
    fn n_points(&self) -> usize {
        self.n_points
    }
    fn weight(&self, p: usize) -> f64 {
        self.weight[p]
    }
    fn value(&self, p: usize, a: usize) -> f64 {
        self.value[p][a]
    }
    fn grad(&self, p: usize, a: usize) -> &[f64; 3] {
        &self.grad[p][a]
    }
    fn hoop(&self, p: usize, a: usize) -> f64 {
        self.hoop[p][a]
    }
    fn constant_gradients(&self) -> Option<f64> {
        None
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

/// `B_a` at point `p` of a cell's rule.
fn b_at(dim: usize, r: &impl CellRule, p: usize, a: usize) -> [[f64; 6]; 3] {
    strain_columns_at(dim, r.grad(p, a), r.hoop(p, a))
}

/// Column `(a, k)` of `A_e = ∫ Bᵀ C B`: `out[b][l]` is the entry of row `(b, l)` (`N` at least
/// the cell's nodes).
pub fn elasticity_column<const N: usize>(m: &Material, r: &impl CellRule, a: usize, k: usize) -> [[f64; 3]; N] {
    let (dim, nv) = (m.dim, m.nv());
    let mut out = [[0.0; 3]; N];
    for p in 0..r.n_points() {
        let ba = b_at(dim, r, p, a)[k];
        let mut cb = [0.0; 6];
        for i in 0..nv {
            cb[i] = (0..nv).map(|j| m.c[i * nv + j] * ba[j]).sum::<f64>() * r.weight(p);
        }
        for (b, row) in out.iter_mut().enumerate().take(r.n_local()) {
            let bb = b_at(dim, r, p, b);
            for (l, v) in row.iter_mut().enumerate().take(dim) {
                *v += (0..nv).map(|i| bb[l][i] * cb[i]).sum::<f64>();
            }
        }
    }
    out
}

/// Column `(a, k)` of `G_e = ∫ ∇Nᵀ e B` (rows ψ_b): `out[b] = Σ_q w_q ∇N_b(q) · (e B_a(q) e_k)`.
pub fn coupling_column<const N: usize>(m: &Material, r: &impl CellRule, a: usize, k: usize) -> [f64; N] {
    let (dim, nv) = (m.dim, m.nv());
    let mut out = [0.0; N];
    let e_b = |p: usize| {
        let ba = b_at(dim, r, p, a)[k];
        let mut eb = [0.0; 3];
        for (i, v) in eb.iter_mut().enumerate().take(dim) {
            *v = (0..nv).map(|j| m.e[i * nv + j] * ba[j]).sum::<f64>() * r.weight(p);
        }
        eb
    };
    if r.constant_gradients().is_some() {
        // the gradients' common value: the points' sum first
        let mut eb = [0.0; 3];
        for p in 0..r.n_points() {
            let ep = e_b(p);
            for i in 0..dim {
                eb[i] += ep[i];
            }
        }
        for (b, v) in out.iter_mut().enumerate().take(r.n_local()) {
            *v = (0..dim).map(|i| r.grad(0, b)[i] * eb[i]).sum();
        }
        return out;
    }
    for p in 0..r.n_points() {
        let eb = e_b(p);
        for (b, v) in out.iter_mut().enumerate().take(r.n_local()) {
            *v += (0..dim).map(|i| r.grad(p, b)[i] * eb[i]).sum::<f64>();
        }
    }
    out
}

/// Row `b` of `G_e` as columns `(a, k)`: `out[a][k] = Σ_q w_q ∇N_b(q) · (e B_a(q) e_k)`; this is
/// the column `b` of `G_eᵀ` (rows u).
pub fn coupling_row<const N: usize>(m: &Material, r: &impl CellRule, b: usize) -> [[f64; 3]; N] {
    let (dim, nv) = (m.dim, m.nv());
    let mut out = [[0.0; 3]; N];
    for p in 0..r.n_points() {
        // eᵀ ∇N_b, weighted, then B_aᵀ of it
        let mut weighted = [0.0; 6];
        for (j, w) in weighted.iter_mut().enumerate().take(nv) {
            *w = (0..dim).map(|i| m.e[i * nv + j] * r.grad(p, b)[i]).sum::<f64>() * r.weight(p);
        }
        for (a, row) in out.iter_mut().enumerate().take(r.n_local()) {
            let ba = b_at(dim, r, p, a);
            for (k, v) in row.iter_mut().enumerate().take(dim) {
                *v += (0..nv).map(|j| ba[k][j] * weighted[j]).sum::<f64>();
            }
        }
    }
    out
}

/// Column `a` of `B_e = ∫ ∇Nᵀ β ∇N`: `out[b] = Σ_q w_q ∇N_b(q) · β ∇N_a(q)` (on a P1 cell
/// `|T| ∇N_b · β ∇N_a`, `|T|` the cell's volume).
pub fn dielectric_column<const N: usize>(m: &Material, r: &impl CellRule, a: usize) -> [f64; N] {
    let dim = m.dim;
    let mut out = [0.0; N];
    let beta_grad = |p: usize, scale: f64| {
        let mut bg = [0.0; 3];
        for (i, v) in bg.iter_mut().enumerate().take(dim) {
            *v = (0..dim).map(|j| m.beta[i * dim + j] * r.grad(p, a)[j]).sum::<f64>() * scale;
        }
        bg
    };
    if let Some(volume) = r.constant_gradients() {
        let bg = beta_grad(0, volume);
        for (b, v) in out.iter_mut().enumerate().take(r.n_local()) {
            *v = (0..dim).map(|i| r.grad(0, b)[i] * bg[i]).sum();
        }
        return out;
    }
    for p in 0..r.n_points() {
        let bg = beta_grad(p, r.weight(p));
        for (b, v) in out.iter_mut().enumerate().take(r.n_local()) {
            *v += (0..dim).map(|i| r.grad(p, b)[i] * bg[i]).sum::<f64>();
        }
    }
    out
}

/// Voigt strain of a cell's displacement `u_local` (its nodes') at point `p` of its rule:
/// `ε = Σ_a B_a u_a`.
pub fn strain_at(dim: usize, r: &impl CellRule, p: usize, u_local: &[[f64; 3]]) -> [f64; 6] {
    let mut eps = [0.0; 6];
    // plane strain's entry 3 (the hoop strain of a body of revolution) stays 0
    let nv = if dim == 3 { 6 } else { 4 };
    for (a, ua) in u_local.iter().enumerate().take(r.n_local()) {
        let b = b_at(dim, r, p, a);
        for k in 0..dim {
            for v in 0..nv {
                eps[v] += b[k][v] * ua[k];
            }
        }
    }
    eps
}

/// Gradient of a cell's scalar `phi_local` (its nodes') at point `p` of its rule:
/// `∇φ = Σ_a φ_a ∇N_a`.
pub fn gradient_at(dim: usize, r: &impl CellRule, p: usize, phi_local: &[f64]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (a, &v) in phi_local.iter().enumerate().take(r.n_local()) {
        for k in 0..dim {
            out[k] += v * r.grad(p, a)[k];
        }
    }
    out
}

/// A cell's quadrature of either order ([`LinearRule`], [`QuadraticRule`]), for the work
/// done cell by cell outside the assembly's loops (loads, fields, charges, errors).
// one lives on the stack for one cell: the P1 variant inline (the common case, every cell of
// a P1 mesh), the P2 one boxed (3 kB)
#[allow(clippy::large_enum_variant)]
pub enum Rule<'g> {
    /// A P1 cell.
    Linear(LinearRule<'g>),
    /// A P2 cell.
    Quadratic(Box<QuadraticRule>),
}

impl<'g> Rule<'g> {
    /// The quadrature of the cell `g` of dimension `dim` and polynomial order `order`.
    pub fn of(dim: usize, order: usize, g: &'g SimplexGeometry) -> Self {
        match order {
            2 => Rule::Quadratic(Box::new(QuadraticRule::new(dim, g))),
            _ => Rule::Linear(LinearRule::new(dim, g)),
        }
    }

    /// The rule of one point at the cell's centroid (where a cell's fields are reported), of
    /// weight the cell's volume.
    pub fn centroid(dim: usize, order: usize, g: &'g SimplexGeometry) -> Self {
        let third = 1.0 / (dim + 1) as f64;
        let l = [third, third, third, if dim == 3 { third } else { 0.0 }];
        if order == 2 {
            let mut r = QuadraticRule::at(dim, g, &[l], &[1.0]);
            r.weight[0] = g.volume();
            return Rule::Quadratic(Box::new(r));
        }
        let mut rule = LinearRule::new(dim, g);
        rule.n_points = 1;
        rule.points[0] = CellPoint {
            weight: g.volume(),
            hoop: g.centroid_hoop(),
        };
        rule.bary[0] = l;
        Rule::Linear(rule)
    }
}

impl CellRule for Rule<'_> {
    fn n_local(&self) -> usize {
        match self {
            Rule::Linear(r) => r.n_local(),
            Rule::Quadratic(r) => r.n_local(),
        }
    }
    fn n_points(&self) -> usize {
        match self {
            Rule::Linear(r) => r.n_points(),
            Rule::Quadratic(r) => r.n_points(),
        }
    }
    fn weight(&self, p: usize) -> f64 {
        match self {
            Rule::Linear(r) => r.weight(p),
            Rule::Quadratic(r) => r.weight(p),
        }
    }
    fn value(&self, p: usize, a: usize) -> f64 {
        match self {
            Rule::Linear(r) => r.value(p, a),
            Rule::Quadratic(r) => r.value(p, a),
        }
    }
    fn grad(&self, p: usize, a: usize) -> &[f64; 3] {
        match self {
            Rule::Linear(r) => r.grad(p, a),
            Rule::Quadratic(r) => r.grad(p, a),
        }
    }
    fn hoop(&self, p: usize, a: usize) -> f64 {
        match self {
            Rule::Linear(r) => r.hoop(p, a),
            Rule::Quadratic(r) => r.hoop(p, a),
        }
    }
    fn constant_gradients(&self) -> Option<f64> {
        match self {
            Rule::Linear(r) => r.constant_gradients(),
            Rule::Quadratic(r) => r.constant_gradients(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curved_tetrahedrons_rule_integrates_every_quintic() {
        // ∫ λ0^a λ1^b λ2^c λ3^d over the simplex, as a fraction of its measure:
        // a! b! c! d! 3! / (a + b + c + d + 3)!
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        let (w, p) = curved_rule(3);
        assert_eq!(w.len(), 14);
        assert!(w.iter().all(|&x| x > 0.0));
        for e in 0..6u32.pow(4) {
            let k = [e % 6, e / 6 % 6, e / 36 % 6, e / 216 % 6];
            if k.iter().sum::<u32>() > 5 {
                continue;
            }
            let exact = k.iter().map(|&x| fact(x)).product::<f64>() * 6.0 / fact(k.iter().sum::<u32>() + 3);
            let rule: f64 = w
                .iter()
                .zip(p)
                .map(|(w, l)| w * (0..4).map(|i| l[i].powi(k[i] as i32)).product::<f64>())
                .sum();
            assert!((rule - exact).abs() < 1e-14, "{k:?}: {rule} against {exact}");
        }
    }

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
