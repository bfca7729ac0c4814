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
        units: None,
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
    s.validate().expect("a valid scene");
    // the PETSc backend solves it too (its answers against the default backend's:
    // crates/driver/tests/petsc.rs)
    distributed::supports(&s).expect("the PETSc backend solves a compliant foundation");
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

/// The block of [`block`] with its top pressed by the traction `q` instead of held: only the
/// bed holds its vertical translation (the rollers hold the rest). In uniaxial strain the
/// pressure is `q` at every point and the penetration `(q / k)^(1/m)`; the run holds the body
/// with springs it takes out again (`problem::bed`).
fn on_its_bed(dim: usize, k: f64, m: f64, friction: bool, q: f64) -> Scene {
    let spec = ComplianceSpec {
        stiffness: k,
        exponent: m,
    };
    let mut s = block(dim, Some(spec), friction);
    s.dirichlet.retain(|d| d.group != "top");
    let mut direction = vec![0.0; dim];
    direction[dim - 1] = 1.0;
    s.load = Some(
        problem::LoadSpec {
            group: "top".into(),
            p: -q,
            direction,
        }
        .into(),
    );
    s
}

#[test]
fn a_block_only_its_bed_holds_is_the_closed_form_to_round_off() {
    let q = c_modulus() * DELTA;
    for dim in [2, 3] {
        for m in [1.0, 2.0] {
            for friction in [false, true] {
                // from a soft bed (k C⁻¹ H = 1e-3) to a stiff one (1e6)
                for k in [1e-3, 1.0, 1e3, 1e6].map(|f| f * c_modulus()) {
                    let what = format!("{dim}D, k = {k:e}, m = {m}, friction {friction}");
                    let s = problem::solve(&on_its_bed(dim, k, m, friction, q), None, &mut Silent)
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                    let contact = s.contact.as_ref().unwrap();
                    let p = (q / k).powf(1.0 / m);
                    let e_pressure = contact
                        .solution
                        .lambda
                        .normal
                        .iter()
                        .map(|l| (l - q).abs() / q)
                        .fold(0.0, f64::max);
                    // against the displacement's scale: the body's own shortening is δ
                    let e_penetration = contact
                        .displacement
                        .normal
                        .iter()
                        .map(|u| (u - p).abs() / p.max(DELTA))
                        .fold(0.0, f64::max);
                    assert!(
                        e_pressure < 1e-9 && e_penetration < 1e-8,
                        "{what}: {e_pressure:e} {e_penetration:e}"
                    );
                    assert!(s.report.residuals.converged_to_tolerance, "{what}");
                    let steps = s.report.iterations.bed;
                    assert!(
                        (1..=12).contains(&steps),
                        "{what}: {steps} steps of the bed's fixed point"
                    );
                }
            }
        }
    }
}

#[test]
fn a_body_the_conditions_hold_runs_without_the_beds_springs() {
    let spec = ComplianceSpec {
        stiffness: c_modulus(),
        exponent: 1.0,
    };
    let s = problem::solve(&block(2, Some(spec), false), None, &mut Silent).unwrap();
    assert_eq!(s.report.iterations.bed, 0);
}

/// The error of a run that must fail.
fn fails(s: &Scene) -> problem::ProblemError {
    match problem::solve(s, None, &mut Silent) {
        Ok(_) => panic!("{} solved", s.name),
        Err(e) => e,
    }
}

#[test]
fn what_the_bed_does_not_hold_is_named_and_a_bed_it_leaves_is_no_solution() {
    let k = c_modulus();
    let q = k * DELTA;
    // no rollers: the bed holds the vertical translation and the tilts, not the slide
    let mut s = on_its_bed(2, k, 1.0, true, q);
    s.dirichlet.clear();
    let e = fails(&s).to_string();
    assert!(
        e.contains("the Dirichlet conditions and the compliant bed leave 1 rigid motion of the body free (a translation along [1.000, 0.000])")
            && e.contains("friction holds nothing"),
        "{e}"
    );
    // 3D, rollers on the x faces only: the slide along y is free
    let mut s = on_its_bed(3, k, 1.0, false, q);
    s.dirichlet.retain(|d| d.group == "left" || d.group == "right");
    let e = fails(&s).to_string();
    let along_y = ["[0.000, 1.000, 0.000]", "[0.000, -1.000, 0.000]"]
        .map(|d| format!("1 rigid motion of the body free (a translation along {d})"));
    assert!(along_y.iter().any(|m| e.contains(m.as_str())), "{e}");
    // a rigid foundation holds nothing: the message says what a bed would
    let mut s = on_its_bed(2, k, 1.0, false, q);
    s.first_contact_mut().unwrap().compliance = None;
    let e = fails(&s).to_string();
    assert!(
        e.contains("the Dirichlet conditions leave 1 rigid motion") && e.contains("contact.compliance"),
        "{e}"
    );
    // pulled off its bed: nothing holds it
    for dim in [2, 3] {
        let e = fails(&on_its_bed(dim, k, 1.0, false, -q));
        assert!(
            matches!(
                e,
                problem::ProblemError::NoSolution {
                    sought: "contact.compliance",
                    ..
                }
            ),
            "{dim}D: {e}"
        );
    }
    // a load along the bed only (held by the rollers): nothing presses it onto the bed, and a
    // body that floats has no position
    let mut s = on_its_bed(2, k, 1.0, false, q);
    if let Some(problem::Loads::One(l)) = s.load.as_mut() {
        l.direction = vec![1.0, 0.0];
    }
    let e = fails(&s);
    assert!(
        matches!(
            e,
            problem::ProblemError::NoSolution {
                sought: "contact.compliance",
                ..
            }
        ) && e.to_string().contains("do not press it onto the bed"),
        "{e}"
    );
    // no load at all: nothing presses it onto the bed
    let mut s = on_its_bed(2, k, 1.0, false, q);
    s.load = None;
    let e = fails(&s);
    assert!(matches!(e, problem::ProblemError::NoSolution { .. }), "{e}");
}

#[test]
fn a_path_of_a_body_only_its_bed_holds_meets_the_closed_form_at_each_instant() {
    // the traction grows from 0 to q in 4 steps; Coulomb's law has nothing to do (uniaxial
    // strain), so each instant is the closed form at its load, and the last the one-instant run
    let k = c_modulus();
    let q = k * DELTA;
    for dim in [2, 3] {
        let mut s = on_its_bed(dim, k, 1.0, true, q);
        s.path = Some(problem::PathSpec {
            t: vec![0.0, 1.0],
            steps: Some(4),
            load: Some(vec![0.0, 1.0]),
            ..Default::default()
        });
        let mut rows = vec![];
        let path = problem::solve_path(&s, None, problem::Limits::default(), &mut Silent, false, &mut |step| {
            rows.push((
                step.row.t,
                step.contact.solution.lambda.normal.clone(),
                step.contact.solution.u.normal.clone(),
            ));
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{dim}D: {e}"));
        assert_eq!(rows.len(), 5);
        // every instant written: its fields (under the springs' forces too, solved with the
        // others after the path went on) in equilibrium, its contact the same
        let mut written = 0;
        let with_fields = problem::solve_path(&s, None, problem::Limits::default(), &mut Silent, true, &mut |step| {
            written += usize::from(step.fields.is_some());
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{dim}D with fields: {e}"));
        assert_eq!(written, 5);
        let (plain, fielded) = (
            path.last.report.path.as_ref().unwrap(),
            with_fields.last.report.path.as_ref().unwrap(),
        );
        for (a, b) in plain.rows.iter().zip(&fielded.rows) {
            assert_eq!(a.normal_force, b.normal_force, "{dim}D t = {}", a.t);
            assert!(
                b.equilibrium.is_some_and(|e| e < 1e-9),
                "{dim}D t = {}: {:?}",
                b.t,
                b.equilibrium
            );
        }
        for (t, lambda, u_n) in &rows {
            let e_pressure = lambda.iter().map(|l| (l - t * q).abs() / q).fold(0.0, f64::max);
            let e_penetration = u_n.iter().map(|u| (u - t * q / k).abs() / DELTA).fold(0.0, f64::max);
            assert!(
                e_pressure < 1e-9 && e_penetration < 1e-8,
                "{dim}D t = {t}: {e_pressure:e} {e_penetration:e}"
            );
        }
        let report = &path.last.report;
        assert!(report.residuals.converged_to_tolerance, "{dim}D");
        assert!(
            report.iterations.bed >= 4,
            "{dim}D: {} steps of the bed's fixed point",
            report.iterations.bed
        );
        s.path = None;
        let once = problem::solve(&s, None, &mut Silent).unwrap();
        let (a, b) = (
            &path.last.contact.as_ref().unwrap().solution.lambda.normal,
            &once.contact.as_ref().unwrap().solution.lambda.normal,
        );
        let diff = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(
            diff < 1e-10 * q,
            "{dim}D: the path's last instant and the run differ by {diff:e}"
        );
    }
}

/// A body only its bed holds, pressed by an indenter: with a force (the springs that hold it
/// sized by that force) it rests on its bed, which carries the indenter's force to round-off
/// (the body is free along the bed's normal: contact alone balances it); at a depth (a force
/// only the solve finds) it is refused, naming the indenter and what to give instead.
#[test]
fn a_body_only_its_bed_holds_is_pressed_by_a_force_controlled_indenter() {
    let text = |control: &str| {
        format!(
            "name = \"bed-indenter\"\ndescription = \"a block on its bed, pressed\"\n\
             [mesh]\nkind = \"rectangle\"\nlo = [0.0, 0.0]\nhi = [2.0, 1.0]\nn = 16\n\
             [[material]]\nregion = \"body\"\nmodel = \"isotropic\"\nyoung = 100.0\npoisson = 0.3\n\
             [[dirichlet]]\ngroup = \"left\"\nux = 0.0\n\
             [[contact]]\ngroup = \"bottom\"\nlaw = \"signorini\"\nnormal = [0.0, -1.0]\ncompliance = {{ stiffness = 10.0, exponent = 1.0 }}\n\
             [[contact]]\ngroup = \"top\"\nlaw = \"signorini\"\nnormal = [0.0, 1.0]\n\
             [contact.indenter]\nshape = \"paraboloid\"\nradius = 1.0\n{control}\n"
        )
    };
    let scene = files::scene_file::parse(&text("force = 0.1"), "bed-indenter", &[]).unwrap();
    let s = problem::solve(&scene, None, &mut Silent).unwrap();
    let groups = &s.report.contact.groups;
    assert_eq!((groups[0].group.as_str(), groups[1].group.as_str()), ("bottom", "top"));
    assert!(
        (groups[1].normal_force - 0.1).abs() < 1e-9,
        "the indenter's force {}",
        groups[1].normal_force
    );
    assert!(
        (groups[0].normal_force - groups[1].normal_force).abs() < 1e-10,
        "the bed carries {} of the indenter's {}",
        groups[0].normal_force,
        groups[1].normal_force
    );
    assert!(s.report.iterations.bed > 0);
    let scene = files::scene_file::parse(&text("depth = 0.01"), "bed-indenter", &[]).unwrap();
    let e = fails(&scene);
    let message = e.to_string();
    assert!(
        message.contains("the indenter at a depth on `top` presses it") && message.contains("contact.indenter.force"),
        "{message}"
    );
}
