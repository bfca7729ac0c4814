//! Patch tests (source: the classical patch test of Irons; for piezoelectricity, any linear
//! `u` and linear `φ` solve the homogeneous equations exactly).
//!
//! Goal: a uniform strain and a uniform electric field are reproduced to round-off by P1 on an
//! irregular mesh, with mixed conditions, by both linear strategies.
//!
//! ```text
//!        top: traction σn, charge D·n
//!      +-----------------------+
//! left |  jittered P1 mesh     | right: traction σn, charge D·n
//! u, φ |                       |
//!      +-----------------------+
//!        bottom: u prescribed (both components), φ free with D·n given
//! ```
//!
//! Expected: nodal u and φ equal `u = M x + c`, `φ = a·x + b` to about 1e-12 (relative).

mod common;

use common::{jitter, max_diff, solve_both, stress_and_d};
use fe_assembly::{Constraint, Crystal, Discretization, Field, Load, Material};
use std::sync::Arc;

fn run_patch(dim: usize) {
    let mut mesh = if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 6, 4)
    } else {
        mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2)
    };
    jitter(&mut mesh, if dim == 2 { 0.08 } else { 0.1 }, 12345);
    mesh.check().unwrap();
    let poling = if dim == 2 { [0.0, 1.0, 0.0] } else { [0.0, 0.0, 1.0] };
    let mat = Material::from_crystal("pzt5a", &Crystal::pzt5a(), poling, dim).unwrap();
    // the exact linear fields
    let grad_u = [[1e-3, 2e-3, -1e-3], [-0.5e-3, 3e-3, 0.7e-3], [0.2e-3, -0.4e-3, 1.1e-3]];
    let grad_phi = [0.02, -0.03, 0.01];
    let u_exact = move |x: &[f64]| {
        let mut u = [0.0; 3];
        for k in 0..dim {
            u[k] = 1e-4 * (k as f64 + 1.0) + (0..dim).map(|l| grad_u[k][l] * x[l]).sum::<f64>();
        }
        u
    };
    let phi_exact = move |x: &[f64]| 0.5 + (0..dim).map(|l| grad_phi[l] * x[l]).sum::<f64>();
    let (sigma, d) = stress_and_d(&mat, &grad_u, &grad_phi);
    // Dirichlet: u on the bottom, φ on the left; the rest Neumann with the exact flux
    let mut bcs = vec![];
    for k in 0..dim {
        bcs.push(Constraint {
            group: "bottom".into(),
            field: Field::Displacement(k),
            value: Arc::new(move |x| u_exact(x)[k]),
        });
    }
    bcs.push(Constraint {
        group: "left".into(),
        field: Field::Potential,
        value: Arc::new(phi_exact),
    });
    let mut loads = vec![];
    let mut normals: Vec<(&str, [f64; 3])> = vec![("right", [1.0, 0.0, 0.0]), ("left", [-1.0, 0.0, 0.0])];
    if dim == 2 {
        normals.push(("top", [0.0, 1.0, 0.0]));
        normals.push(("bottom", [0.0, -1.0, 0.0]));
    } else {
        normals.extend([
            ("top", [0.0, 0.0, 1.0]),
            ("bottom", [0.0, 0.0, -1.0]),
            ("front", [0.0, -1.0, 0.0]),
            ("back", [0.0, 1.0, 0.0]),
        ]);
    }
    for (g, n) in normals {
        let mut t = [0.0; 3];
        for i in 0..dim {
            t[i] = (0..dim).map(|j| sigma[i][j] * n[j]).sum();
        }
        let dn: f64 = (0..dim).map(|i| d[i] * n[i]).sum();
        loads.push(Load::Traction {
            group: g.into(),
            value: Arc::new(move |_| t),
        });
        loads.push(Load::SurfaceCharge {
            group: g.into(),
            value: Arc::new(move |_| dn),
        });
    }
    let disc = Discretization::new(
        &mesh,
        fe_assembly::Coordinates::Cartesian,
        &[("body".into(), mat)],
        &bcs,
    )
    .unwrap();
    let ((u1, p1), (u2, p2), _) = solve_both(&disc, &loads);
    let nodal_u: Vec<[f64; 3]> = (0..mesh.n_nodes()).map(|i| u_exact(mesh.point(i))).collect();
    let nodal_p: Vec<f64> = (0..mesh.n_nodes()).map(|i| phi_exact(mesh.point(i))).collect();
    let ue = disc.dofs.restrict_u(&nodal_u);
    let pe = disc.dofs.restrict_phi(&nodal_p);
    let (su, sp) = (
        ue.iter().fold(0.0f64, |m, x| m.max(x.abs())),
        pe.iter().fold(0.0f64, |m, x| m.max(x.abs())),
    );
    for (u, p, name) in [(&u1, &p1, "direct"), (&u2, &p2, "schur-pcg")] {
        let (eu, ep) = (max_diff(u, &ue) / su, max_diff(p, &pe) / sp);
        assert!(
            eu < 1e-11 && ep < 1e-11,
            "{dim}D {name}: u error {eu:.2e}, phi error {ep:.2e}"
        );
    }
    // the recovered stress and electric displacement are the uniform ones
    let f = disc.recover(&disc.dofs.expand_u(&u1), &disc.dofs.expand_phi(&p1));
    let nv = if dim == 2 { 3 } else { 6 };
    let smax = sigma.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for c in 0..mesh.n_cells() {
        for i in 0..dim {
            for j in i..dim {
                let v = common::voigt(dim, i, j);
                assert!((f.stress[c * nv + v] - sigma[i][j]).abs() < 1e-10 * smax);
            }
            assert!(
                (f.electric_displacement[c * dim + i] - d[i]).abs()
                    < 1e-10 * d.iter().fold(0.0f64, |m, x| m.max(x.abs()))
            );
        }
    }
}

#[test]
fn patch_test_2d() {
    run_patch(2);
}

#[test]
fn patch_test_3d() {
    run_patch(3);
}

/// The right-hand side in parts: loads, each component's lifting, the potentials' lifting sum
/// to `rhs`, and a map with its prescribed values scaled gives `rhs` = the parts scaled the
/// same way (what a load path relies on), 2D and 3D, a manufactured solution's data.
#[test]
fn the_right_hand_side_is_the_sum_of_its_parts() {
    for dim in [2, 3] {
        let mesh = if dim == 2 {
            mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 6, 3)
        } else {
            mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2)
        };
        let poling = if dim == 2 { [0.0, 1.0, 0.0] } else { [0.0, 0.0, 1.0] };
        let m = Material::from_crystal("pzt5a", &Crystal::pzt5a(), poling, dim).unwrap();
        let exact = fe_assembly::Exact::manufactured(dim);
        let groups: &[&str] = &["left", "right", "bottom"];
        let mats = [("body".to_string(), m.clone())];
        let mut disc = Discretization::new(
            &mesh,
            fe_assembly::Coordinates::Cartesian,
            &mats,
            &exact.constraints(groups),
        )
        .unwrap();
        let loads = exact.loads(&m);
        let (bu, bphi) = disc.rhs(&loads).unwrap();
        let parts = disc.rhs_parts(&loads).unwrap();
        let f = [0.3, -1.7, 2.5];
        let fphi = -0.6;
        let fl = 1.9;
        let combine = |fl: f64, f: [f64; 3], fphi: f64, electric: bool| -> Vec<f64> {
            let pick = |p: &(Vec<f64>, Vec<f64>)| if electric { p.1.clone() } else { p.0.clone() };
            let mut out: Vec<f64> = pick(&parts.loads).iter().map(|v| fl * v).collect();
            for (k, d) in parts.displacements.iter().enumerate() {
                for (o, v) in out.iter_mut().zip(pick(d)) {
                    *o += f[k] * v;
                }
            }
            for (o, v) in out.iter_mut().zip(pick(&parts.potentials)) {
                *o += fphi * v;
            }
            out
        };
        let close = |a: &[f64], b: &[f64]| {
            let scale = a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs()));
            a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-13 * scale)
        };
        assert!(close(&combine(1.0, [1.0; 3], 1.0, false), &bu), "{dim}D: b_u");
        assert!(close(&combine(1.0, [1.0; 3], 1.0, true), &bphi), "{dim}D: b_phi");
        assert!(
            parts.displacements.iter().all(|d| d.0.iter().any(|v| *v != 0.0)),
            "{dim}D: each component lifts"
        );
        // the scaled map's right-hand side with the loads scaled: the scaled parts
        disc.dofs = disc.dofs.scaled(f, fphi);
        let scaled_loads: Vec<Load> = exact
            .loads(&m)
            .into_iter()
            .map(|l| match l {
                Load::BodyForce(g) => Load::BodyForce(Arc::new(move |x| g(x).map(|v| fl * v))),
                Load::BodyCharge(q) => Load::BodyCharge(Arc::new(move |x| fl * q(x))),
                other => panic!("unexpected load {other:?}"),
            })
            .collect();
        let (su, sphi) = disc.rhs(&scaled_loads).unwrap();
        assert!(close(&combine(fl, f, fphi, false), &su), "{dim}D: scaled b_u");
        assert!(close(&combine(fl, f, fphi, true), &sphi), "{dim}D: scaled b_phi");
    }
}
