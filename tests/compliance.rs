//! Normal compliance (`contact.compliance`) against its closed form: an isotropic block on a
//! deformable foundation, pushed down by `δ` at its top, held laterally by rollers, is in
//! uniaxial strain. With `C = E (1 - ν) / ((1 + ν)(1 - 2ν))` the constrained modulus, `H` the
//! height and `p` the penetration, the stress `C (δ - p) / H` equals the foundation's pressure
//! `k p^m`: for `m = 1`, `p = C δ / (C + k H)`; for `m = 2`, the positive root of
//! `k p² + (C/H) p - C δ / H`. P1 elements hold the linear field exactly, so the finite
//! element answer is the closed form to round-off, at every point, in 2D and in 3D; as
//! `k → ∞` it tends to Signorini's answer at the rate `1/k`.

use problem::{ComplianceSpec, ContactLaw, ContactSpec, DirichletSpec, MaterialSpec, MeshSpec, Scene, Silent};

const E: f64 = 100.0;
const NU: f64 = 0.3;
const DELTA: f64 = 0.01;

/// The constrained modulus.
fn c_modulus() -> f64 {
    E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU))
}

/// The block (height 1) in `dim` dimensions on a foundation of `compliance` (none: rigid).
fn block(dim: usize, compliance: Option<ComplianceSpec>, friction: bool) -> Scene {
    let roller = |group: &str, axis: usize| DirichletSpec {
        group: group.into(),
        ux: (axis == 0).then_some(0.0),
        uy: (axis == 1).then_some(0.0),
        ..Default::default()
    };
    let (mesh, normal, top_u, mut dirichlet) = if dim == 2 {
        (
            MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 4),
            vec![0.0, -1.0],
            vec![0.0, -DELTA],
            vec![roller("left", 0), roller("right", 0)],
        )
    } else {
        (
            MeshSpec::cuboid([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 3),
            vec![0.0, 0.0, -1.0],
            vec![0.0, 0.0, -DELTA],
            vec![
                roller("left", 0),
                roller("right", 0),
                roller("front", 1),
                roller("back", 1),
            ],
        )
    };
    dirichlet.push(DirichletSpec {
        group: "top".into(),
        u: Some(top_u),
        ..Default::default()
    });
    let law = if friction {
        ContactLaw::Coulomb
    } else {
        ContactLaw::Signorini
    };
    let mut contact = ContactSpec::new("bottom", law, &normal);
    contact.compliance = compliance;
    if friction {
        contact.friction = Some(0.5);
    }
    Scene {
        name: "compliant-bed".into(),
        description: String::new(),
        mesh,
        material: vec![MaterialSpec::isotropic("body", E, NU)],
        dirichlet,
        load: None,
        electrode: None,
        contact: Some(contact.into()),
        solver: Default::default(),
        exact: None,
        path: None,
    }
}

/// The penetration of the closed form.
fn penetration(k: f64, m: f64) -> f64 {
    let c = c_modulus(); // H = 1
    if m == 1.0 {
        c * DELTA / (c + k)
    } else {
        assert_eq!(m, 2.0);
        (-c + (c * c + 4.0 * k * c * DELTA).sqrt()) / (2.0 * k)
    }
}

/// The largest relative errors of the pressure and of the penetration over the points.
fn errors(dim: usize, k: f64, m: f64, friction: bool) -> (f64, f64) {
    let spec = ComplianceSpec {
        stiffness: k,
        exponent: m,
    };
    let solution = problem::solve(&block(dim, Some(spec), friction), None, &mut Silent).unwrap();
    let contact = solution.contact.as_ref().unwrap();
    let p = penetration(k, m);
    // the bed's side of the balance: no cancellation (`C (δ - p)` loses digits on a soft bed)
    let pressure = k * p.powf(m);
    let e_pressure = contact
        .solution
        .lambda
        .normal
        .iter()
        .map(|l| (l - pressure).abs() / pressure)
        .fold(0.0, f64::max);
    let e_penetration = contact
        .displacement
        .normal
        .iter()
        .map(|u| (u - p).abs() / p)
        .fold(0.0, f64::max);
    assert!(solution.report.residuals.converged_to_tolerance);
    (e_pressure, e_penetration)
}

#[test]
fn a_block_on_a_linear_or_quadratic_bed_is_the_closed_form_to_round_off() {
    for dim in [2, 3] {
        for m in [1.0, 2.0] {
            // from a soft bed (k C⁻¹ H = 1e-3) to a stiff one (1e6)
            for k in [1e-3, 1.0, 1e3, 1e6].map(|f| f * c_modulus()) {
                let (ep, eu) = errors(dim, k, m, false);
                assert!(ep < 1e-9 && eu < 1e-8, "{dim}D, k = {k:e}, m = {m}: {ep:e} {eu:e}");
            }
        }
    }
}

#[test]
fn a_bed_stiffer_than_the_body_by_twelve_decades_still_solves_to_its_tolerance() {
    // the penetration (1e-14 of δ) is below the displacement's round-off: only the pressure
    // is measured, and the run must meet its tolerances (the scaled compliance equation)
    for dim in [2, 3] {
        for k in [1e9, 1e12].map(|f| f * c_modulus()) {
            let (ep, _) = errors(dim, k, 1.0, false);
            assert!(ep < 1e-9, "{dim}D, k = {k:e}: {ep:e}");
        }
    }
}

#[test]
fn friction_changes_nothing_where_nothing_slides() {
    // the uniaxial state has no tangential traction: Coulomb's law leaves it as it is
    for dim in [2, 3] {
        let (ep, eu) = errors(dim, c_modulus(), 1.0, true);
        assert!(ep < 1e-9 && eu < 1e-8, "{dim}D: {ep:e} {eu:e}");
    }
}

#[test]
fn a_stiffening_bed_tends_to_the_rigid_foundation_at_the_rate_one_over_k() {
    let rigid = problem::solve(&block(2, None, false), None, &mut Silent).unwrap();
    let p_rigid = rigid.contact.as_ref().unwrap().solution.lambda.normal[0];
    assert!((p_rigid - c_modulus() * DELTA).abs() < 1e-9 * p_rigid);
    let mut previous: Option<f64> = None;
    for k in [1e2, 1e4, 1e6, 1e8].map(|f| f * c_modulus()) {
        let spec = ComplianceSpec {
            stiffness: k,
            exponent: 1.0,
        };
        let s = problem::solve(&block(2, Some(spec), false), None, &mut Silent).unwrap();
        let p = s.contact.as_ref().unwrap().solution.lambda.normal[0];
        let gap = (p_rigid - p) / p_rigid;
        assert!(gap > 0.0, "a compliant bed carries less: {gap:e}");
        if let Some(before) = previous {
            // k up a hundredfold: the difference down a hundredfold (rate 1)
            let rate = (before / gap).log10() / 2.0;
            assert!((rate - 1.0).abs() < 0.01, "k = {k:e}: rate {rate}");
        }
        previous = Some(gap);
    }
}

#[test]
fn compliance_is_refused_where_it_is_not_solved() {
    let spec = ComplianceSpec {
        stiffness: 1.0,
        exponent: 1.0,
    };
    let mut s = block(2, Some(spec), false);
    s.solver.strategy = problem::Strategy::UzawaCondensed;
    let e = s.validate().unwrap_err();
    assert_eq!(e.key, "contact.compliance");
    let mut s = block(2, Some(spec), false);
    s.solver.backend = problem::BackendChoice::Petsc;
    s.validate()
        .expect("a valid scene; the PETSc backend's own refusal follows");
    assert_eq!(distributed::supports(&s).unwrap_err().key, "contact.compliance");
    // Hertz's closed form is a rigid foundation's: not compared against a compliant one
    let (mut hertz, _) = files::scene_file::load("hertz", &[]).unwrap();
    hertz.first_contact_mut().unwrap().compliance = Some(spec);
    assert_eq!(hertz.validate().unwrap_err().key, "contact.compliance");
    let bad = ComplianceSpec {
        stiffness: 1.0,
        exponent: 0.5,
    };
    assert_eq!(
        block(2, Some(bad), false).validate().unwrap_err().key,
        "contact.compliance.exponent"
    );
    let bad = ComplianceSpec {
        stiffness: f64::NAN,
        exponent: 1.0,
    };
    assert_eq!(
        block(2, Some(bad), false).validate().unwrap_err().key,
        "contact.compliance.stiffness"
    );
}
