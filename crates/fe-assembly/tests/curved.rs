//! Curved (isoparametric) P2 cells against what nobody here wrote: the manufactured solution
//! on a quarter annulus (2D) and a quarter of a thick cylinder (3D), whose round faces a P2
//! mesh follows with its edge nodes on the arcs. Mapped through their nodes the curved cells
//! keep P2's energy error O(h²) and measure the body and its round face to O(h⁴); the same
//! meshes with every edge node moved back to its chord's midpoint (straight-sided cells on the
//! polygon) measure them to O(h²) only. A linear field is reproduced exactly on curved cells
//! (the isoparametric patch test), and Gmsh's own curved meshes measure their arcs.

mod common;

use common::{pzt5a, solve_nodal as solve, stress_and_d};
use fe_assembly::{Coordinates, Discretization, Exact, Load};
use std::sync::Arc;

/// `box` raised to P2 and bent: `(ξ0, ξ1[, ξ2]) -> (r cos θ, r sin θ[, z])` with `r = 1 + ξ0`,
/// `θ = π ξ1 / 2`; with `curved` false every edge node then moved back to the midpoint of its
/// edge's bent corners.
fn bent(mesh: mesh::Mesh, curved: bool) -> mesh::Mesh {
    let mut m = mesh.quadratic().unwrap();
    for p in &mut m.points {
        let (r, t) = (1.0 + p[0], std::f64::consts::FRAC_PI_2 * p[1]);
        (p[0], p[1]) = (r * t.cos(), r * t.sin());
    }
    if !curved {
        m = on_chords(m);
    }
    m.check().unwrap();
    m
}

/// `m` with every edge node moved to the midpoint of its edge's corners: straight-sided cells.
fn on_chords(mut m: mesh::Mesh) -> mesh::Mesh {
    let (corners, edges) = (m.kind.n_corners(), m.kind.midside_edges());
    for c in 0..m.n_cells() {
        let cell = m.cell(c).to_vec();
        for (e, &[a, b]) in edges.iter().enumerate() {
            let (xa, xb) = (m.points[cell[a]], m.points[cell[b]]);
            m.points[cell[corners + e]] = std::array::from_fn(|k| 0.5 * (xa[k] + xb[k]));
        }
    }
    m
}

fn block(dim: usize, n: usize) -> mesh::Mesh {
    if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], n, 2 * n)
    } else {
        mesh::box_tet([0.0; 3], [1.0, 1.0, 0.5], n, 2 * n, n)
    }
}

fn groups(dim: usize) -> &'static [&'static str] {
    if dim == 2 {
        &["left", "right", "bottom", "top"]
    } else {
        &["left", "right", "bottom", "top", "front", "back"]
    }
}

/// The relative energy error of the manufactured solution on `mesh`: its round outer face
/// (`right`, r = 2) loaded by the exact traction `σ n` and surface charge `D · n` with the
/// circle's normal `n = (x, y) / r`, the other faces prescribed.
fn energy_error(mesh: &mesh::Mesh, exact: &Exact) -> f64 {
    let dim = mesh.dim;
    let m = pzt5a(dim, false);
    let held: Vec<&str> = groups(dim).iter().copied().filter(|&g| g != "right").collect();
    let disc = Discretization::new(
        mesh,
        Coordinates::Cartesian,
        &[("body".into(), m.clone())],
        &exact.constraints(&held),
    )
    .unwrap();
    let at = {
        let (e, m) = (exact.clone(), m.clone());
        move |x: &[f64]| {
            let jets = (e.u)(x);
            let gu = std::array::from_fn(|k| if k < dim { jets[k].1 } else { [0.0; 3] });
            let (sigma, d) = stress_and_d(&m, &gu, &(e.phi)(x).1);
            let r = x[0].hypot(x[1]);
            let n = [x[0] / r, x[1] / r, 0.0];
            let t: [f64; 3] = std::array::from_fn(|i| (0..dim).map(|j| sigma[i][j] * n[j]).sum());
            (t, (0..dim).map(|i| d[i] * n[i]).sum::<f64>())
        }
    };
    let (a1, a2) = (Arc::new(at.clone()), Arc::new(at));
    let [body_force, body_charge] = exact.loads(&m);
    let loads = [
        body_force,
        body_charge,
        Load::Traction {
            group: "right".into(),
            value: Arc::new(move |x| a1(x).0),
        },
        Load::SurfaceCharge {
            group: "right".into(),
            value: Arc::new(move |x| a2(x).1),
        },
    ];
    let (u, phi) = solve(&disc, &loads);
    disc.error_norms(&u, &phi, exact).rel_energy()
}

/// The body's measure and its round outer face's (`right`): [`measures_of`].
fn measures(mesh: &mesh::Mesh) -> (f64, f64) {
    measures_of(mesh, "right")
}

/// The body's measure and that of its face `group`: a unit body force's and a unit traction's
/// total on the free mesh's x dofs.
fn measures_of(mesh: &mesh::Mesh, group: &str) -> (f64, f64) {
    let dim = mesh.dim;
    let disc = Discretization::new(mesh, Coordinates::Cartesian, &[("body".into(), pzt5a(dim, false))], &[]).unwrap();
    let total = |load: Load| disc.rhs(&[load]).unwrap().0.iter().step_by(dim).sum::<f64>();
    (
        total(Load::BodyForce(Arc::new(|_| [1.0, 0.0, 0.0]))),
        total(Load::Traction {
            group: group.into(),
            value: Arc::new(|_| [1.0, 0.0, 0.0]),
        }),
    )
}

#[test]
fn curved_cells_follow_the_round_body_and_keep_p2s_order() {
    // a quarter annulus 1 < r < 2 (2D: area 3π/4, outer arc π; 3D: its extrusion to z = 1/2)
    for (dim, levels) in [(2, &[2, 4, 8, 16][..]), (3, &[1, 2, 4][..])] {
        let depth = if dim == 2 { 1.0 } else { 0.5 };
        let exact_measures = (0.75 * std::f64::consts::PI * depth, std::f64::consts::PI * depth);
        let exact = Exact::manufactured(dim);
        let run = |curved: bool| -> Vec<(usize, f64, f64, f64)> {
            levels
                .iter()
                .map(|&n| {
                    let mesh = bent(block(dim, n), curved);
                    let (area, arc) = measures(&mesh);
                    (
                        n,
                        energy_error(&mesh, &exact),
                        (area - exact_measures.0).abs() / exact_measures.0,
                        (arc - exact_measures.1).abs() / exact_measures.1,
                    )
                })
                .collect()
        };
        let (iso, sub) = (run(true), run(false));
        let rate = |rows: &[(usize, f64, f64, f64)], pick: fn(&(usize, f64, f64, f64)) -> f64| {
            let (a, b) = (&rows[rows.len() - 2], &rows[rows.len() - 1]);
            (pick(a) / pick(b)).ln() / ((b.0 as f64) / (a.0 as f64)).ln()
        };
        eprintln!("{dim}D curved {iso:?}\n{dim}D straight {sub:?}");
        // the energy error at P2's order on the curved cells (and on the straight ones, whose
        // loads and exact solution extend smoothly past the polygon)
        let energy = rate(&iso, |r| r.1);
        assert!(energy > 1.8, "{dim}D curved: energy rate {energy}");
        // the body and its face: the chords miss O(h²) of them, the arcs O(h⁴)
        for (what, pick) in [
            ("measure", (|r: &(usize, f64, f64, f64)| r.2) as fn(&_) -> f64),
            ("face", |r| r.3),
        ] {
            let (ri, rs) = (rate(&iso, pick), rate(&sub, pick));
            assert!(
                ri > 3.5 && (1.8..2.3).contains(&rs),
                "{dim}D {what}: rates curved {ri}, straight {rs}"
            );
            assert!(
                pick(iso.last().unwrap()) < 0.05 * pick(sub.last().unwrap()),
                "{dim}D {what}"
            );
        }
    }
}

#[test]
fn a_linear_field_is_reproduced_on_curved_cells() {
    // the isoparametric patch test: every P2 map holds the linear functions of x
    for dim in [2, 3] {
        let mesh = bent(block(dim, 2), true);
        let grad_u = [[1e-3, -2e-3, 0.5e-3], [0.7e-3, 1.5e-3, -1e-3], [0.2e-3, 0.4e-3, 0.9e-3]];
        let field = Exact::affine(dim, [1e-3, 2e-3, -1e-3], grad_u, 0.1, [0.3, -0.2, 0.1]);
        let m = pzt5a(dim, false);
        let disc = Discretization::new(
            &mesh,
            Coordinates::Cartesian,
            &[("body".into(), m.clone())],
            &field.constraints(groups(dim)),
        )
        .unwrap();
        let (u, phi) = solve(&disc, &field.loads(&m));
        let e = disc.error_norms(&u, &phi, &field);
        assert!(e.rel_energy() < 1e-10 && e.l2_u < 1e-12 * e.norms.0, "{dim}D: {e:?}");
    }
}

#[test]
fn gmshs_curved_meshes_measure_their_round_bodies() {
    // Gmsh's second-order meshes of a quarter annulus and of its extrusion (edge nodes on the
    // arcs, crates/mesh/tests/fixtures/make_curved.py): their area (volume) and outer arc
    // (face) by the curved cells' maps, against the same nodes with the edge nodes moved back
    // to the chords
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mesh/tests/fixtures");
    for (file, depth) in [("annulus2d-order2.msh", 1.0), ("annulus3d-order2.msh", 0.5)] {
        let mesh = mesh::read_msh(dir.join(file)).unwrap();
        let curved = mesh.curved_cells().iter().filter(|&&c| c).count();
        assert!(curved > 0 && mesh.kind.order() == 2, "{file}: {curved} curved cells");
        let exact = (0.75 * std::f64::consts::PI * depth, std::f64::consts::PI * depth);
        let errors = |m: &mesh::Mesh| {
            let (body, face) = measures_of(m, "outer");
            ((body - exact.0).abs() / exact.0, (face - exact.1).abs() / exact.1)
        };
        let (iso, sub) = (errors(&mesh), errors(&on_chords(mesh.clone())));
        eprintln!("{file}: {curved} curved cells; relative errors (measure, face): curved {iso:?}, chords {sub:?}");
        // (the chords' area lost outside and gained at the hole partly cancel: the face tells)
        assert!(iso.0 < 1e-5 && iso.0 < sub.0 && iso.1 < 1e-5, "{file}: {iso:?}");
        assert!(iso.1 < 0.01 * sub.1, "{file}: {iso:?} against {sub:?}");
    }
}
