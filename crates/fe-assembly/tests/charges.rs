//! The charges through the groups at a prescribed potential (`Discretization::charges`, from the
//! recovered fields) against their functionals on the free unknowns
//! (`Discretization::charge_functionals`): with the prescribed values zero and no body charge,
//! `charge = a_u · u + a_φ · φ` for any `(u, φ)`, on a jittered mesh of PZT-5A, in 2D, 3D and
//! on a body of revolution.

mod common;

use fe_assembly::{Constraint, Discretization, Field};

fn check(dim: usize, axisymmetric: bool) {
    let coordinates = if axisymmetric {
        fe_assembly::Coordinates::Axisymmetric
    } else {
        fe_assembly::Coordinates::Cartesian
    };
    let mut random = common::random_source(99);
    let mesh = common::jittered_block(dim, &mut random);
    let mat = common::pzt5a(dim, axisymmetric);
    let materials = vec![("body".to_string(), mat)];
    let constraints = vec![
        Constraint::constant("left", Field::Displacement(0), 0.0),
        Constraint::constant("left", Field::Displacement(1), 0.0),
        Constraint::constant("top", Field::Potential, 0.0),
        Constraint::constant("bottom", Field::Potential, 0.0),
    ];
    let disc = Discretization::new(&mesh, coordinates, &materials, &constraints).unwrap();
    let u_free: Vec<f64> = (0..disc.dofs.n_u).map(|_| 1e-3 * random()).collect();
    let phi_free: Vec<f64> = (0..disc.dofs.n_phi).map(|_| 1e-2 * random()).collect();
    let (u, phi) = (disc.dofs.expand_u(&u_free), disc.dofs.expand_phi(&phi_free));
    let groups = ["top", "bottom"];
    let charges = disc.charges(&u, &phi, &groups, &[]).unwrap();
    let functionals = disc.charge_functionals(&groups).unwrap();
    for (q, (a_u, a_phi)) in charges.iter().zip(&functionals) {
        let from: f64 = a_u.iter().zip(&u_free).map(|(a, x)| a * x).sum::<f64>()
            + a_phi.iter().zip(&phi_free).map(|(a, x)| a * x).sum::<f64>();
        assert!(
            (q - from).abs() <= 1e-12 * q.abs().max(1e-6),
            "{dim}D: {q} against {from}"
        );
    }
}

#[test]
fn the_charge_functionals_are_the_charges_of_the_fields() {
    check(2, false);
    check(3, false);
    check(2, true);
}
