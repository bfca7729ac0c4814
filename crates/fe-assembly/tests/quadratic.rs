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
