//! Slip-weakening friction (`contact.friction_law = "slip-weakening"`) on the shipped scene
//! against its limits: equal coefficients are Coulomb's law to round-off; a falling one lets
//! more of the face slip and carries less tangential force; the answer meets the law at its own
//! slips; the keys that do not fit are refused by name.

use files::scene_file;
use problem::Silent;

fn solve(scene: &str, sets: &[&str]) -> problem::Solution {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let (scene, _) = scene_file::load(scene, &sets).unwrap();
    problem::solve(&scene, None, &mut Silent).unwrap()
}

#[test]
fn equal_coefficients_are_coulombs_law_to_round_off() {
    let weak = solve("paper-slip-weakening", &["mesh.n=16", "contact.friction_dynamic=0.1"]);
    let coulomb = solve("paper-slip", &["mesh.n=16"]);
    let (a, b) = (&weak.contact.unwrap().solution, &coulomb.contact.unwrap().solution);
    assert_eq!(a.lambda, b.lambda);
    assert_eq!(weak.report.iterations.fixed_point, 1);
}

#[test]
fn a_weakening_coefficient_lets_more_slip_and_meets_its_law() {
    let (mu_s, mu_d, length) = (0.1, 0.05, 1e-4);
    let weak = solve("paper-slip-weakening", &["mesh.n=32"]);
    let coulomb = solve("paper-slip", &["mesh.n=32"]);
    let (w, c) = (weak.contact.as_ref().unwrap(), coulomb.contact.as_ref().unwrap());
    let slips = |r: &problem::ContactResult| {
        r.solution
            .status
            .iter()
            .filter(|s| **s == contact::Status::Slip)
            .count()
    };
    assert!(slips(w) > slips(c), "{} against {}", slips(w), slips(c));
    assert!(weak.report.contact.tangential_force.abs() < coulomb.report.contact.tangential_force.abs());
    // every slipping point carries μ(s) λ_n, with s its own slip
    for i in 0..w.points.len() {
        if w.solution.status[i] != contact::Status::Slip {
            continue;
        }
        let s = w.solution.u.tangential_norm(i);
        let mu = mu_s - (mu_s - mu_d) * (s / length).min(1.0);
        let (lt, ln) = (w.solution.lambda.tangential_norm(i), w.solution.lambda.normal[i]);
        assert!(
            (lt - mu * ln).abs() <= 1e-8 * ln,
            "point {i}: |λ_t| {lt}, μ(s) λ_n {}",
            mu * ln
        );
    }
    assert!(weak.report.residuals.converged_to_tolerance);
    assert!(weak.report.solver.friction_map_contraction.is_some_and(|c| c < 1.0));
}

#[test]
fn keys_that_do_not_fit_slip_weakening_are_refused_by_name() {
    let refused = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        match scene_file::load("paper-slip-weakening", &sets).unwrap_err() {
            files::Error::Scene {
                source: files::SceneFileError::Invalid(e),
                ..
            } => e.key,
            other => panic!("{other}"),
        }
    };
    assert_eq!(refused(&["contact.friction=0.3"]), "contact.friction");
    assert_eq!(refused(&["contact.friction_dynamic=0.2"]), "contact.friction_dynamic");
    assert_eq!(refused(&["contact.slip_length=0"]), "contact.slip_length");
    assert_eq!(refused(&["~contact.slip_length"]), "contact.slip_length");
    assert_eq!(refused(&["solver.strategy=uzawa-condensed"]), "contact.friction_law");
    // the PETSc backend solves it too
    let (petsc, _) = scene_file::load("paper-slip-weakening", &["solver.backend=petsc".into()]).unwrap();
    distributed::supports(&petsc).expect("the PETSc backend solves slip weakening");
    // its fixed point solves the contact many times over: MUMPS' route, which factors once,
    // where it fits; the active sets (a pass each) only where it does not
    assert!(distributed::repeats_contact_solves(&petsc));
    let (plain, _) = scene_file::load("paper-slip", &["solver.backend=petsc".into()]).unwrap();
    assert!(!distributed::repeats_contact_solves(&plain));
    let (forced, _) = scene_file::load(
        "indent-sphere-3d",
        &["contact.indenter.depth=0.0".into(), "contact.indenter.force=0.1".into()],
    )
    .unwrap();
    assert!(distributed::repeats_contact_solves(&forced));
    assert_eq!(
        refused(&["contact.law=signorini", "~contact.friction_static"]),
        "contact.friction_law"
    );
    // contact switched off: the section's keys are kept, unused, as everywhere
    assert!(scene_file::load("paper-slip-weakening", &["contact.law=none".into()]).is_ok());
    let (_, _) = scene_file::load("paper-slip", &["contact.slip_length=1".into()])
        .map(|_| panic!("slip_length without slip weakening"))
        .unwrap_or_else(|e| {
            assert!(e.to_string().contains("contact.slip_length does not apply"), "{e}");
            (0, 0)
        });
}

#[test]
fn slip_weakening_in_three_dimensions_meets_its_law() {
    let sets = [
        "mesh.n=4",
        "~contact.friction",
        "contact.friction_law=\"slip-weakening\"",
        "contact.friction_static=0.1",
        "contact.friction_dynamic=0.05",
        "contact.slip_length=1e-4",
        "contact.weakening=\"exponential\"",
    ];
    let weak = solve("paper-3d", &sets);
    let w = weak.contact.as_ref().unwrap();
    let law = contact::SlipWeakening {
        static_coefficient: 0.1,
        dynamic_coefficient: 0.05,
        slip_length: 1e-4,
        form: contact::Weakening::Exponential,
    };
    let mut slipping = 0;
    for i in 0..w.points.len() {
        let (lt, ln) = (w.solution.lambda.tangential_norm(i), w.solution.lambda.normal[i]);
        let mu = law.coefficient(w.solution.u.tangential_norm(i));
        assert!(
            lt <= mu * ln * (1.0 + 1e-8) + 1e-12,
            "point {i}: |λ_t| {lt} above μ(s) λ_n {}",
            mu * ln
        );
        if w.solution.status[i] == contact::Status::Slip {
            slipping += 1;
            assert!((lt - mu * ln).abs() <= 1e-8 * ln, "point {i}");
        }
    }
    assert!(slipping > 0);
    assert!(weak.report.residuals.converged_to_tolerance);
}

/// Each `[[contact]]` zone its own friction law (zones once could not carry slip weakening):
/// the corner's right wall weakens (0.3 -> 0.1 over 1e-5), its top wall keeps Coulomb's 0.3.
/// Every slipping point carries its own zone's coefficient at its own slip, some point of the
/// right wall below 0.3 (the law acts there), every point of the top at 0.3; with equal
/// coefficients the two zones are Coulomb's law on both to round-off.
#[test]
fn each_contact_zone_keeps_its_own_friction_law() {
    let (mu_s, mu_d, length, mu) = (0.3, 0.1, 1e-5, 0.3);
    let zones = |dynamic: f64| {
        let sets = [
            "contact.0.law=\"coulomb\"".to_string(),
            "contact.0.friction_law=\"slip-weakening\"".into(),
            format!("contact.0.friction_static={mu_s}"),
            format!("contact.0.friction_dynamic={dynamic}"),
            format!("contact.0.slip_length={length}"),
            "contact.1.law=\"coulomb\"".into(),
            format!("contact.1.friction={mu}"),
        ];
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        solve("corner", &sets)
    };
    let weak = zones(mu_d);
    let c = weak.contact.as_ref().unwrap();
    let sol = &c.solution;
    let mut weakened = 0;
    for (i, &g) in c.group_of.iter().enumerate() {
        let (ln, lt) = (sol.lambda.normal[i], sol.lambda.tangential_norm(i));
        let s = sol.u.tangential_norm(i);
        let coefficient = if g == 0 {
            mu_s - (mu_s - mu_d) * (s / length).min(1.0)
        } else {
            mu
        };
        assert!(
            lt <= coefficient * ln * (1.0 + 1e-8) + 1e-14,
            "point {i} of zone {g}: |λ_t| {lt} above {coefficient} λ_n"
        );
        if sol.status[i] == contact::Status::Slip {
            assert!(
                (lt - coefficient * ln).abs() <= 1e-8 * ln,
                "point {i} of zone {g} slips: |λ_t| {lt}, μ λ_n {}",
                coefficient * ln
            );
            weakened += usize::from(g == 0 && coefficient < mu_s * (1.0 - 1e-6));
        }
    }
    assert!(
        weakened > 0,
        "no point of the weakening wall slid far enough for the law to act"
    );
    assert!(weak.report.residuals.converged_to_tolerance);
    assert!(
        weak.report.plan.to_string().contains("0.3 -> 0.1 over 1e-5 on `right`"),
        "{}",
        weak.report.plan
    );
    // equal coefficients: Coulomb's law on both walls, to round-off
    let flat = zones(mu_s);
    let coulomb = solve(
        "corner",
        &[
            "contact.0.law=\"coulomb\"",
            "contact.0.friction=0.3",
            "contact.1.law=\"coulomb\"",
            "contact.1.friction=0.3",
        ],
    );
    assert_eq!(
        flat.contact.unwrap().solution.lambda,
        coulomb.contact.unwrap().solution.lambda
    );
}
