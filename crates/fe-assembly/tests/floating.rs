//! A floating terminal ([`Field::Floating`]) ties its group's potentials to one unknown. The
//! tied system must be the free one restricted to fields constant on the group: with `P` the
//! map from the tied unknowns to the free ones (the group's nodes all taking the terminal's
//! value), `K_tied = Pᵀ K_free P` and `b_tied = Pᵀ b_free`. Checked on random vectors, on a
//! jittered mesh of PZT-5A, in 2D, 3D and on a body of revolution, for both assembly loops; and
//! the charge put on the terminal is the right-hand side of its one equation.

mod common;

use faer::sparse::SparseColMat;
use fe_assembly::{Constraint, Crystal, Discretization, Dof, Field, Load, Material, Parallelism};

fn mat_vec(m: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m.nrows()];
    for j in 0..m.ncols() {
        for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            out[i] += v * x[j];
        }
    }
    out
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn check(dim: usize, axisymmetric: bool) {
    let coordinates = if axisymmetric {
        fe_assembly::Coordinates::Axisymmetric
    } else {
        fe_assembly::Coordinates::Cartesian
    };
    let mut random = common::random_source(7);
    let mesh = common::jittered_block(dim, &mut random);
    let mat = common::pzt5a(dim, axisymmetric);
    let materials = vec![("body".to_string(), mat)];
    let held = vec![
        Constraint::constant("left", Field::Displacement(0), 0.0),
        Constraint::constant("left", Field::Displacement(1), 0.0),
        Constraint::constant("bottom", Field::Potential, 0.25),
    ];
    let mut tied_conditions = held.clone();
    tied_conditions.push(Constraint::floating("top"));
    let free = Discretization::new(&mesh, coordinates, &materials, &held).unwrap();
    let tied = Discretization::new(&mesh, coordinates, &materials, &tied_conditions).unwrap();
    let (df, dt) = (&free.dofs, &tied.dofs);
    assert_eq!(dt.floating, vec![("top".to_string(), dt.n_phi - 1)]);
    let top = mesh.boundary("top").unwrap().nodes();
    assert!(top.iter().all(|&v| dt.phi[v] == Dof::Free(dt.n_phi - 1)));
    assert_eq!(dt.n_phi, df.n_phi - top.len() + 1);
    // P: the tied unknowns' potential on every node, restricted to the free unknowns
    let p = |y: &[f64]| df.restrict_phi(&dt.expand_phi(y));
    let charge = 0.37;
    let loads = vec![
        Load::SurfaceCharge {
            group: "right".into(),
            value: std::sync::Arc::new(|x| 1.0 + x[1]),
        },
        Load::TerminalCharge {
            group: "top".into(),
            charge,
        },
    ];
    let free_loads = &loads[..1];
    for par in [Parallelism::Rayon, Parallelism::Serial] {
        let (kf, kt) = (free.assemble(par), tied.assemble(par));
        assert_eq!(kt.b.nrows(), dt.n_phi);
        assert_eq!(kt.g.nrows(), dt.n_phi);
        for trial in 0..3 {
            let u: Vec<f64> = (0..dt.n_u).map(|_| random()).collect();
            let (y, z): (Vec<f64>, Vec<f64>) = (
                (0..dt.n_phi).map(|_| random()).collect(),
                (0..dt.n_phi).map(|_| random()).collect(),
            );
            // zᵀ B_tied y = (P z)ᵀ B_free (P y), and the coupling's
            let tied_b = dot(&z, &mat_vec(&kt.b, &y));
            let free_b = dot(&p(&z), &mat_vec(&kf.b, &p(&y)));
            assert!(
                (tied_b - free_b).abs() < 1e-12 * free_b.abs().max(1.0),
                "{dim}D {par:?} #{trial}: B {tied_b} {free_b}"
            );
            let tied_g = dot(&z, &mat_vec(&kt.g, &u));
            let free_g = dot(&p(&z), &mat_vec(&kf.g, &u));
            assert!(
                (tied_g - free_g).abs() < 1e-12 * free_g.abs().max(1.0),
                "{dim}D {par:?} #{trial}: G {tied_g} {free_g}"
            );
        }
        // b_tied = Pᵀ b_free, and the charge the right-hand side of the terminal's row
        let (_, bt) = tied.rhs(&loads).unwrap();
        let (_, bf) = free.rhs(free_loads).unwrap();
        let z: Vec<f64> = (0..dt.n_phi).map(|_| random()).collect();
        let mut zt = z.clone();
        zt[dt.n_phi - 1] = 0.0;
        let (tied_rhs, free_rhs) = (dot(&zt, &bt), dot(&p(&zt), &bf));
        assert!(
            (tied_rhs - free_rhs).abs() < 1e-12 * free_rhs.abs().max(1.0),
            "{tied_rhs} {free_rhs}"
        );
        let mut unit = vec![0.0; dt.n_phi];
        unit[dt.n_phi - 1] = 1.0;
        let on_terminal = bt[dt.n_phi - 1] - dot(&p(&unit), &bf);
        assert!((on_terminal + charge).abs() < 1e-14, "{on_terminal}");
    }
    // the order puts the terminal's potential last, every unknown once
    let order: Vec<usize> = (0..mesh.n_nodes()).collect();
    let expanded = dt.expand_node_order(&order);
    assert_eq!(*expanded.last().unwrap(), dt.n_u + dt.n_phi - 1);
    let mut sorted = expanded.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..dt.n_u + dt.n_phi).collect::<Vec<_>>());
}

#[test]
fn a_floating_terminal_is_the_free_system_restricted_to_one_potential_on_its_group() {
    check(2, false);
    check(3, false);
    check(2, true);
}

#[test]
fn a_floating_terminal_touching_another_terminal_is_one_conductor() {
    let mesh = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2);
    let mat = Material::from_crystal("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0], 2).unwrap();
    let materials = vec![("body".to_string(), mat)];
    for conditions in [
        vec![
            Constraint::constant("left", Field::Potential, 0.0),
            Constraint::floating("top"),
        ],
        vec![
            Constraint::floating("top"),
            Constraint::constant("left", Field::Potential, 0.0),
        ],
        vec![Constraint::floating("top"), Constraint::floating("right")],
    ] {
        let e = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &materials, &conditions)
            .err()
            .unwrap();
        assert!(e.to_string().contains("one conductor"), "{e}");
    }
    // a charge on a group that does not float
    let disc = Discretization::new(
        &mesh,
        fe_assembly::Coordinates::Cartesian,
        &materials,
        &[Constraint::constant("left", Field::Potential, 0.0)],
    )
    .unwrap();
    let e = disc
        .rhs(&[Load::TerminalCharge {
            group: "left".into(),
            charge: 1.0,
        }])
        .unwrap_err();
    assert!(e.to_string().contains("no floating terminal"), "{e}");
}
