//! Bodies of revolution (the hoop strain `u_r / r`, `dx = 2π r dr dz`) against closed forms:
//!
//! - Lamé's thick cylinder under internal pressure in plane strain (Timoshenko & Goodier,
//!   Theory of Elasticity, 3rd ed., §28): `u_r = (1 + ν) p a² / (E (b² - a²)) ((1 - 2ν) r +
//!   b² / r)`, not in the P1 space: the nodal error (root mean square) falls like h²;
//! - a poled disc between electrodes (a uniform field along the axis, no load): the strain
//!   `ε = -C⁻¹ eᵀ ∇φ` is uniform, `u_r = ε_rr r` and `u_z = ε_zz z` are linear and P1 holds them
//!   to round-off (a patch test of the hoop terms), and the charge on the top electrode is
//!   `D_z π R²`, the whole disc's (the `2π r` of every integral);
//! - a cylinder pressed between sliding plates (uniaxial stress): its lateral expansion
//!   `ν δ r / H` and its force `E (δ / H) π R²` through the cells' volumes of revolution.

mod common;

use common::{jitter, solve_nodal as solve};
use fe_assembly::{Constraint, Coordinates, Crystal, Discretization, Field, Load, Material};
use std::sync::Arc;

#[test]
fn lame_cylinder_converges_at_second_order() {
    let errors = lame_errors(1, &[4, 8, 16]);
    let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    // measured: 5.6e-4, 1.4e-4, 3.4e-5 (rates 2.01, 2.03; 2.03, 2.02 on to n = 64)
    assert!(errors[2] < 4e-5, "errors {errors:?}");
    assert!(rates.iter().all(|&r| r > 1.95), "errors {errors:?}, rates {rates:?}");
}

/// The same cylinder on six-node triangles: the nodal error at third order and beyond
/// (measured 2.1e-5, 2.0e-6, 1.8e-7 at n = 2, 4, 8: rates 3.39, 3.48), below P1's at n = 16.
#[test]
fn lame_cylinder_converges_at_third_order_with_quadratic_elements() {
    let errors = lame_errors(2, &[2, 4, 8]);
    let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    assert!(errors[2] < 3.4e-5, "errors {errors:?}");
    assert!(rates.iter().all(|&r| r > 2.8), "errors {errors:?}, rates {rates:?}");
}

/// The root mean square of Lamé's nodal error, relative to `u_r(a)`, on meshes of `4n x n`
/// cells of `order`.
fn lame_errors(order: usize, sizes: &[usize]) -> Vec<f64> {
    let (a, b, e, nu, p) = (1.0, 2.0, 100.0, 0.3, 1.5);
    let exact = |r: f64| (1.0 + nu) * p * a * a / (e * (b * b - a * a)) * ((1.0 - 2.0 * nu) * r + b * b / r);
    let mut errors = vec![];
    for &n in sizes {
        let mut mesh = mesh::rectangle_tri([a, 0.0], [b, 0.25], 4 * n, n);
        if order == 2 {
            mesh = mesh.quadratic().unwrap();
        }
        let mat =
            Material::from_crystal_axisymmetric("steel", &Crystal::isotropic(e, nu, 0.0), [0.0, 1.0, 0.0]).unwrap();
        let bcs = vec![
            Constraint::constant("top", Field::Displacement(1), 0.0),
            Constraint::constant("bottom", Field::Displacement(1), 0.0),
        ];
        let disc = Discretization::new(&mesh, Coordinates::Axisymmetric, &[("body".into(), mat)], &bcs).unwrap();
        assert_eq!(disc.coordinates, Coordinates::Axisymmetric);
        disc.check_held().unwrap();
        // the inner face pushed outwards: σ n = -p n with n = -e_r
        let load = Load::Traction {
            group: "left".into(),
            value: Arc::new(move |_| [p, 0.0, 0.0]),
        };
        let (u, _) = solve(&disc, &[load]);
        let scale = exact(a);
        // the nodal error's root mean square (the maximum carries P1's log h)
        let sum: f64 = mesh
            .points
            .iter()
            .zip(&u)
            .map(|(x, u)| (u[0] - exact(x[0])).powi(2) + u[1].powi(2))
            .sum();
        errors.push((sum / mesh.n_nodes() as f64).sqrt() / scale);
    }
    errors
}

#[test]
fn a_disc_between_electrodes_is_reproduced_and_its_charge_is_the_whole_discs() {
    let mut mesh = mesh::rectangle_tri([0.0, 0.0], [1.0, 0.5], 8, 4);
    jitter(&mut mesh, 0.04, 777);
    disc_between_electrodes(&mesh);
    // and on six-node triangles (the edge nodes at the jittered edges' midpoints)
    disc_between_electrodes(&mesh.quadratic().unwrap());
}

/// The disc of radius 1 and height 0.5 meshed by `mesh`, poled along its axis between a
/// grounded bottom and a top at 0.02: its fields uniform, held to round-off at every node, and
/// the charge on each electrode the whole disc's.
fn disc_between_electrodes(mesh: &mesh::Mesh) {
    let (radius, height, volts) = (1.0, 0.5, 0.02);
    let mat = Material::from_crystal_axisymmetric("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0]).unwrap();
    let bcs = vec![
        Constraint::constant("left", Field::Displacement(0), 0.0),
        Constraint::constant("bottom", Field::Displacement(1), 0.0),
        Constraint::constant("bottom", Field::Potential, 0.0),
        Constraint::constant("top", Field::Potential, volts),
    ];
    let disc = Discretization::new(mesh, Coordinates::Axisymmetric, &[("body".into(), mat.clone())], &bcs).unwrap();
    let (u, phi) = solve(&disc, &[]);
    // the stress-free strain of the field: C ε = -eᵀ ∇φ on [rr, zz, rz, θθ]
    let grad = [0.0, volts / height];
    let c = nalgebra::DMatrix::from_row_slice(4, 4, &mat.c);
    let rhs = nalgebra::DVector::from_iterator(
        4,
        (0..4).map(|v| -(0..2).map(|k| mat.e[k * 4 + v] * grad[k]).sum::<f64>()),
    );
    let eps = c.lu().solve(&rhs).unwrap();
    assert!((eps[0] - eps[3]).abs() < 1e-14, "ε_rr = ε_θθ: {eps}");
    let scale = eps.amax() * radius;
    for (x, (u, p)) in mesh.points.iter().zip(u.iter().zip(&phi)) {
        assert!(
            (u[0] - eps[0] * x[0]).abs() < 1e-11 * scale,
            "u_r at {x:?}: {} against {}",
            u[0],
            eps[0] * x[0]
        );
        assert!((u[1] - eps[1] * x[1]).abs() < 1e-11 * scale, "u_z at {x:?}");
        assert!((p - volts * x[1] / height).abs() < 1e-12 * volts, "φ at {x:?}");
    }
    let d_z: f64 = (0..4).map(|v| mat.e[4 + v] * eps[v]).sum::<f64>() - mat.beta[3] * grad[1];
    let charges = disc.charges(&u, &phi, &["top", "bottom"], &[]).unwrap();
    // the charge on the top electrode is -D_z π R² (D·ν = D_z there), the bottom's its negative
    let whole = -d_z * std::f64::consts::PI * radius * radius;
    assert!(
        (charges[0] - whole).abs() < 1e-11 * whole.abs(),
        "top {} against {whole}",
        charges[0]
    );
    assert!(
        (charges[1] + whole).abs() < 1e-11 * whole.abs(),
        "bottom {} against {}",
        charges[1],
        -whole
    );
    let fields = disc.recover(&u, &phi);
    assert_eq!(fields.stress.len(), 4 * mesh.n_cells());
    assert!(fields.stress.iter().all(|s| s.abs() < 1e-9 * mat.c[0] * eps.amax()));
}

#[test]
fn a_pressed_cylinder_carries_e_eps_pi_r_squared() {
    // uniaxial stress: the plates slide freely (u_r free on them), the top moved by -δ
    let (radius, height, e, nu, delta) = (0.5, 1.0, 70.0, 0.25, 1e-3);
    let mesh = mesh::rectangle_tri([0.0, 0.0], [radius, height], 4, 8);
    let mat = Material::from_crystal_axisymmetric("al", &Crystal::isotropic(e, nu, 0.0), [0.0, 1.0, 0.0]).unwrap();
    let bcs = vec![
        Constraint::constant("left", Field::Displacement(0), 0.0),
        Constraint::constant("bottom", Field::Displacement(1), 0.0),
        Constraint::constant("top", Field::Displacement(1), -delta),
    ];
    let disc = Discretization::new(&mesh, Coordinates::Axisymmetric, &[("body".into(), mat)], &bcs).unwrap();
    let (u, _) = solve(&disc, &[]);
    for (x, u) in mesh.points.iter().zip(&u) {
        assert!(
            (u[0] - nu * delta / height * x[0]).abs() < 1e-13,
            "lateral expansion at {x:?}"
        );
    }
    // the plates' force: σ_zz over the cross-section, ∫ σ_zz dV / H with the cells' volumes of
    // revolution, -E (δ/H) π R²
    let fields = disc.recover(&u, &vec![0.0; mesh.n_nodes()]);
    let sigma_zz = fields.stress[1];
    assert!(
        (sigma_zz + e * delta / height).abs() < 1e-10 * e * delta,
        "σ_zz = {sigma_zz}"
    );
    let force = disc
        .geometry
        .iter()
        .enumerate()
        .map(|(c, g)| g.volume() * fields.stress[4 * c + 1])
        .sum::<f64>()
        / height;
    let expected = -e * delta / height * std::f64::consts::PI * radius * radius;
    assert!(
        (force - expected).abs() < 1e-10 * expected.abs(),
        "{force} against {expected}"
    );
}

#[test]
fn bodies_of_revolution_are_refused_where_they_cannot_be() {
    let mesh = mesh::rectangle_tri([-1.0, 0.0], [1.0, 1.0], 4, 2);
    let mat = Material::from_crystal_axisymmetric("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0]).unwrap();
    let e = Discretization::new(&mesh, Coordinates::Axisymmetric, &[("body".into(), mat.clone())], &[])
        .err()
        .unwrap();
    assert!(e.to_string().contains("r = x < 0"), "{e}");
    let plane = Material::from_crystal("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0], 2).unwrap();
    let mut mesh = mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], 4, 2);
    let n = mesh.n_cells();
    mesh.regions.insert("upper".into(), (0..n / 2).collect());
    mesh.regions.insert("lower".into(), (n / 2..n).collect());
    let e = Discretization::new(
        &mesh,
        Coordinates::Axisymmetric,
        &[("upper".into(), mat.clone()), ("lower".into(), plane.clone())],
        &[],
    )
    .err()
    .unwrap();
    assert!(
        e.to_string()
            .contains("region `lower`'s material is made for Cartesian coordinates and the body's are axisymmetric"),
        "{e}"
    );
    // the geometry is the discretisation's argument: a body of revolution's material on a plane body, or a 3D mesh
    let e = Discretization::new(
        &mesh,
        Coordinates::Cartesian,
        &[("upper".into(), plane.clone()), ("lower".into(), mat.clone())],
        &[],
    )
    .err()
    .unwrap();
    assert!(
        e.to_string()
            .contains("region `lower`'s material is made for axisymmetric coordinates"),
        "{e}"
    );
    let cube = mesh::box_tet([0.0; 3], [1.0; 3], 1, 1, 1);
    let e = Discretization::new(&cube, Coordinates::Axisymmetric, &[("body".into(), mat.clone())], &[])
        .err()
        .unwrap();
    assert!(
        e.to_string()
            .contains("meshed in its 2D meridian plane, and the mesh is 3D"),
        "{e}"
    );
    // a material's layout is the order of its C: one that fits none is refused by name
    let mut odd = plane.clone();
    odd.c.truncate(5);
    let e = odd.validate("odd").unwrap_err();
    assert!(e.to_string().contains("material `odd`: C has 5 entries"), "{e}");
    let mut odd = plane;
    odd.e.pop();
    assert!(odd.validate("odd").unwrap_err().to_string().contains("e has 5 entries"));
    let e = Material::from_crystal_axisymmetric("tilted", &Crystal::pzt5a(), [1.0, 1.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("symmetric about its axis"), "{e}");
    // a body of revolution held only radially is free along its axis
    let mat = Material::from_crystal_axisymmetric("al", &Crystal::isotropic(70.0, 0.3, 0.0), [0.0, 1.0, 0.0]).unwrap();
    let mesh = mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], 4, 4);
    let bcs = vec![Constraint::constant("right", Field::Displacement(0), 0.0)];
    let disc = Discretization::new(&mesh, Coordinates::Axisymmetric, &[("body".into(), mat)], &bcs).unwrap();
    let e = disc.check_held().unwrap_err();
    assert!(e.to_string().contains("translation along the axis"), "{e}");
}
