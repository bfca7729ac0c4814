//! Quadratic elements (six-node triangles, ten-node tetrahedra) against what nobody here
//! wrote:
//!
//! - the patch test of order 2: a quadratic displacement and potential (their body force and
//!   charge constant, from the Hessians) are reproduced to round-off on jittered meshes in 2D
//!   and 3D, where P1 misses them;
//! - the manufactured solution of `mms.rs`: L2 error O(h³) and energy error O(h²);
//! - (bodies of revolution at order 2: Lamé's cylinder and the poled disc, in
//!   `axisymmetric.rs` beside their P1 checks);
//! - the node-owned parallel assembly equals the serial cell loop.

mod common;

use common::{jitter, pzt5a, rates, solve_nodal as solve};

use fe_assembly::{Constraint, Coordinates, Discretization, Exact, Field, Parallelism};
use std::sync::Arc;

/// `u_k = Σ a_kij x_i x_j + b_k · x`, `φ` likewise: full quadratics with all their terms.
fn quadratic(dim: usize) -> Exact {
    let coef = |k: usize, i: usize, j: usize| 1e-3 * (1.0 + 0.3 * k as f64 - 0.2 * i as f64 + 0.7 * j as f64);
    let jet = move |k: usize, x: &[f64]| {
        let (mut v, mut g, mut h) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
        for i in 0..dim {
            v += 2e-3 * (k + i + 1) as f64 * x[i];
            g[i] += 2e-3 * (k + i + 1) as f64;
            for j in 0..dim {
                let a = coef(k, i, j);
                v += a * x[i] * x[j];
                g[i] += a * x[j];
                g[j] += a * x[i];
                h[i][j] += a;
                h[j][i] += a;
            }
        }
        (v, g, h)
    };
    Exact {
        dim,
        u: Arc::new(move |x| {
            let mut out = [(0.0, [0.0; 3], [[0.0; 3]; 3]); 3];
            for (k, o) in out.iter_mut().enumerate().take(dim) {
                *o = jet(k, x);
            }
            out
        }),
        phi: Arc::new(move |x| {
            let (v, g, h) = jet(3, x);
            (10.0 * v, g.map(|y| 10.0 * y), h.map(|r| r.map(|y| 10.0 * y)))
        }),
    }
}

fn block(dim: usize, n: usize) -> mesh::Mesh {
    if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 2 * n, n)
    } else {
        mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 2 * n, n, n)
    }
}

fn groups(dim: usize) -> &'static [&'static str] {
    if dim == 2 {
        &["left", "right", "bottom", "top"]
    } else {
        &["left", "right", "bottom", "top", "front", "back"]
    }
}

/// The relative errors `(L2 of (u, φ), energy)` of `exact` on `mesh`, its boundary prescribed.
fn errors(mesh: &mesh::Mesh, exact: &Exact) -> (f64, f64) {
    let dim = mesh.dim;
    let m = pzt5a(dim, false);
    let disc = Discretization::new(
        mesh,
        Coordinates::Cartesian,
        &[("body".into(), m.clone())],
        &exact.constraints(groups(dim)),
    )
    .unwrap();
    let (u, phi) = solve(&disc, &exact.loads(&m));
    let e = disc.error_norms(&u, &phi, exact);
    let l2 = (e.l2_u.powi(2) + e.l2_phi.powi(2)).sqrt() / (e.norms.0.powi(2) + e.norms.1.powi(2)).sqrt();
    (l2, e.rel_energy())
}

#[test]
fn quadratic_fields_are_reproduced_to_round_off() {
    for (dim, n) in [(2, 3), (3, 2)] {
        let mut p1 = block(dim, n);
        jitter(&mut p1, 0.3 / n as f64, 4242);
        let p2 = p1.quadratic().unwrap();
        p2.check().unwrap();
        let exact = quadratic(dim);
        let (l2, energy) = errors(&p2, &exact);
        assert!(l2 < 1e-11 && energy < 1e-10, "{dim}D P2: L2 {l2:e}, energy {energy:e}");
        // the test can fail: P1 does not hold a quadratic
        let (l2, energy) = errors(&p1, &exact);
        assert!(l2 > 1e-4 && energy > 1e-2, "{dim}D P1: L2 {l2:e}, energy {energy:e}");
    }
}

#[test]
fn the_manufactured_solution_converges_at_third_order_in_l2_and_second_in_energy() {
    for (dim, levels) in [(2, &[2, 4, 8, 16][..]), (3, &[1, 2, 4][..])] {
        let exact = Exact::manufactured(dim);
        let rows: Vec<(usize, f64, f64)> = levels
            .iter()
            .map(|&n| {
                let (l2, en) = errors(&block(dim, n).quadratic().unwrap(), &exact);
                (n, l2, en)
            })
            .collect();
        let r = rates(&rows);
        eprintln!("{dim}D P2 MMS: {rows:?}\nrates (L2, energy): {r:?}");
        let last = r.last().unwrap();
        assert!(last.0 > 2.8 && last.0 < 3.4, "{dim}D L2 rate {}", last.0);
        assert!(last.1 > 1.85 && last.1 < 2.3, "{dim}D energy rate {}", last.1);
        // at the same mesh, far below P1's
        let n = *levels.last().unwrap();
        let (p1, _) = errors(&block(dim, n), &exact);
        assert!(
            rows.last().unwrap().1 < 0.2 * p1,
            "{dim}D n = {n}: P2 {rows:?}, P1 {p1:e}"
        );
    }
}

#[test]
fn the_parallel_assembly_equals_the_cell_loop() {
    for dim in [2, 3] {
        let mut p1 = block(dim, 2);
        jitter(&mut p1, 0.1, 4242);
        let mesh = p1.quadratic().unwrap();
        let m = pzt5a(dim, false);
        let bcs = vec![
            Constraint::constant("left", Field::Displacement(0), 0.0),
            Constraint::constant("bottom", Field::Potential, 0.0),
        ];
        let disc = Discretization::new(&mesh, Coordinates::Cartesian, &[("body".into(), m)], &bcs).unwrap();
        let (a, b) = (disc.assemble(Parallelism::Rayon), disc.assemble(Parallelism::Serial));
        for (x, y) in [(&a.a, &b.a), (&a.g, &b.g), (&a.b, &b.b)] {
            let scale = x.val().iter().fold(0.0f64, |s, v| s.max(v.abs()));
            assert_eq!(x.symbolic().row_idx(), y.symbolic().row_idx());
            let worst = x
                .val()
                .iter()
                .zip(y.val())
                .fold(0.0f64, |s, (p, q)| s.max((p - q).abs()));
            assert!(worst <= 1e-14 * scale, "{dim}D: {worst:e}");
        }
    }
}

/// The strain `[ε_v]` (Voigt, engineering shears; on a body of revolution `[rr, zz, rz, θθ]`
/// with `θθ = u_r / r`, `∂u_r/∂r` on the axis) of a displacement with gradient `gu` and value
/// `u` at `x`.
fn strain_of(dim: usize, axisymmetric: bool, x: &[f64], u: &[f64; 3], gu: &[[f64; 3]; 3]) -> Vec<f64> {
    let nv = if axisymmetric {
        4
    } else {
        fe_assembly::voigt_len(dim, Coordinates::Cartesian)
    };
    let mut eps = vec![0.0; nv];
    for i in 0..dim {
        for j in i..dim {
            let v = fe_assembly::voigt(dim, i, j);
            eps[v] = if i == j { gu[i][i] } else { gu[i][j] + gu[j][i] };
        }
    }
    if axisymmetric {
        eps[3] = if x[0] > 0.0 { u[0] / x[0] } else { gu[0][0] };
    }
    eps
}

#[test]
fn the_fields_at_the_nodes_are_those_of_a_quadratic_field() {
    // the nodal values of a quadratic field set, not solved for: every P2 cell holds it, so
    // each cell's strain and potential gradient at each of its nodes are the field's, and so
    // is their average; on a body of revolution the hoop strain u_r / r too (u_r = r (a + b r
    // + c z) vanishes on the axis, where the limit ∂u_r/∂r is taken)
    for (dim, axisymmetric) in [(2, false), (3, false), (2, true)] {
        let mut p1 = block(dim, 2);
        jitter(&mut p1, 0.1, 77);
        let mesh = p1.quadratic().unwrap();
        let field = quadratic(dim);
        let at = |x: &[f64]| -> ([f64; 3], [[f64; 3]; 3], f64, [f64; 3]) {
            let jets = (field.u)(x);
            let (mut u, mut gu) = ([0.0; 3], [[0.0; 3]; 3]);
            for k in 0..dim {
                u[k] = jets[k].0;
                gu[k] = jets[k].1;
            }
            if axisymmetric {
                // u_r = r (a + b r + c z): the axis holds still radially
                let (a, b, c) = (2e-3, 1e-3, -3e-3);
                u[0] = x[0] * (a + b * x[0] + c * x[1]);
                gu[0] = [a + 2.0 * b * x[0] + c * x[1], c * x[0], 0.0];
            }
            let (p, gp, _) = (field.phi)(x);
            (u, gu, p, gp)
        };
        let coordinates = if axisymmetric {
            Coordinates::Axisymmetric
        } else {
            Coordinates::Cartesian
        };
        let m = pzt5a(dim, axisymmetric);
        let disc = Discretization::new(&mesh, coordinates, &[("body".into(), m.clone())], &[]).unwrap();
        let u: Vec<[f64; 3]> = mesh.points.iter().map(|x| at(&x[..dim]).0).collect();
        let phi: Vec<f64> = mesh.points.iter().map(|x| at(&x[..dim]).2).collect();
        let fields = disc.recover(&u, &phi);
        let nodes = fields.at_nodes.as_ref().expect("P2 cells have nodal fields");
        let nv = disc.nv();
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for (v, x) in mesh.points.iter().enumerate() {
            let (uv, gu, _, gp) = at(&x[..dim]);
            let eps = strain_of(dim, axisymmetric, &x[..dim], &uv, &gu);
            for (i, e) in eps.iter().enumerate() {
                worst = worst.max((nodes.strain[v * nv + i] - e).abs());
                scale = scale.max(e.abs());
            }
            for k in 0..dim {
                worst = worst.max((nodes.electric_field[v * dim + k] + gp[k]).abs() / 10.0);
            }
            // σ = C ε + eᵀ ∇φ and D = e ε - β ∇φ of the exact strain and gradient
            for i in 0..nv {
                let s: f64 = (0..nv).map(|j| m.c[i * nv + j] * eps[j]).sum::<f64>()
                    + (0..dim).map(|k| m.e[k * nv + i] * gp[k]).sum::<f64>();
                worst = worst.max((nodes.stress[v * nv + i] - s).abs() / 100.0);
            }
            for k in 0..dim {
                let d: f64 = (0..nv).map(|j| m.e[k * nv + j] * eps[j]).sum::<f64>()
                    - (0..dim).map(|l| m.beta[k * dim + l] * gp[l]).sum::<f64>();
                worst = worst.max((nodes.electric_displacement[v * dim + k] - d).abs());
            }
        }
        assert!(
            worst < 1e-12 * scale.max(1.0),
            "{dim}D (axisymmetric {axisymmetric}): {worst:e}"
        );
        // the centroid's value misses the field's variation across a cell (the test can fail)
        let c0 = mesh.cell(0);
        let spread = (0..nv)
            .map(|i| (fields.strain[i] - nodes.strain[c0[0] * nv + i]).abs())
            .fold(0.0, f64::max);
        assert!(spread > 1e-6, "{spread:e}");
        // P1 cells hold constant fields: none at the nodes
        let disc = Discretization::new(&p1, coordinates, &[("body".into(), m)], &[]).unwrap();
        assert!(disc
            .recover(&vec![[0.0; 3]; p1.n_nodes()], &vec![0.0; p1.n_nodes()])
            .at_nodes
            .is_none());
    }
}

#[test]
fn the_fields_at_the_nodes_of_a_smooth_field_converge_at_second_order() {
    // the manufactured field interpolated at the nodes: each cell's gradient at a node is the
    // field's to O(h²), and so their average
    for dim in [2, 3] {
        let exact = Exact::manufactured(dim);
        let m = pzt5a(dim, false);
        let levels: &[usize] = if dim == 2 { &[2, 4, 8, 16] } else { &[2, 4, 8] };
        let rows: Vec<(usize, f64, f64)> = levels
            .iter()
            .map(|&n| {
                let mesh = block(dim, n).quadratic().unwrap();
                let disc =
                    Discretization::new(&mesh, Coordinates::Cartesian, &[("body".into(), m.clone())], &[]).unwrap();
                let u: Vec<[f64; 3]> = mesh.points.iter().map(|x| (exact.u)(&x[..dim]).map(|j| j.0)).collect();
                let phi: Vec<f64> = mesh.points.iter().map(|x| (exact.phi)(&x[..dim]).0).collect();
                let nodes = disc.recover(&u, &phi).at_nodes.unwrap();
                let nv = disc.nv();
                let (mut worst, mut scale) = (0.0f64, 0.0f64);
                for (v, x) in mesh.points.iter().enumerate() {
                    let jets = (exact.u)(&x[..dim]);
                    let gu = std::array::from_fn(|k| if k < dim { jets[k].1 } else { [0.0; 3] });
                    let eps = strain_of(dim, false, &x[..dim], &[0.0; 3], &gu);
                    for (i, e) in eps.iter().enumerate() {
                        worst = worst.max((nodes.strain[v * nv + i] - e).abs());
                        scale = scale.max(e.abs());
                    }
                }
                (n, worst / scale, 0.0)
            })
            .collect();
        let r = rates(&rows);
        eprintln!("{dim}D nodal strain of the interpolant: {rows:?}, rates {r:?}");
        let last = r.last().unwrap().0;
        assert!(last > 1.7 && last < 2.5, "{dim}D rate {last}");
    }
}
