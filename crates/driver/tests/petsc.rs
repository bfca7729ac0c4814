//! The PETSc backend against the default one (feature `petsc`): the same scenes solved by
//! faer's direct factorisation and by PETSc's Krylov solvers on 1 and 2 ranks give the same
//! displacements and potentials. Each test starts itself again under `mpirun -np N` (the child
//! processes see `OMPI_COMM_WORLD_SIZE`) and passes when every rank passes.
#![cfg(feature = "petsc")]

use files::scene_file;
use petsc::testing::on_ranks;
use petsc::Petsc;

/// A shipped scene with the overrides `sets`, for the default backend and for PETSc (with the
/// PETSc-only overrides `extra` too).
fn both(name: &str, sets: &[&str], extra: &[&str]) -> (problem::Scene, problem::Scene) {
    let text = scene_file::SHIPPED
        .iter()
        .find(|(n, _)| *n == name)
        .expect("a shipped scene")
        .1;
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let faer = scene_file::parse(text, name, &sets).expect("the scene reads");
    let mut with = sets;
    with.push("solver.backend=\"petsc\"".into());
    with.extend(extra.iter().map(|s| s.to_string()));
    (faer, scene_file::parse(text, name, &with).expect("the scene reads"))
}

/// The largest difference relative to the largest magnitude.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if scale > 0.0 {
        diff / scale
    } else {
        diff
    }
}

/// Scenes without contact, each by both backends: coupled 2D and 3D, electrodes (a prescribed
/// non-zero potential), prescribed displacements all round (manufactured), a purely elastic body
/// (CG with GAMG instead of the field split).
const CASES: &[(&str, &[&str])] = &[
    ("paper", &["mesh.n=32", "contact.law=\"none\""]),
    ("paper-3d", &["mesh.n=6", "contact.law=\"none\""]),
    ("actuator", &["contact.law=\"none\""]),
    ("manufactured", &["mesh.n=16"]),
    ("paper-elastic", &["mesh.n=32", "contact.law=\"none\""]),
];

/// Scenes with contact: every law, stick and slip zones, 2D and 3D (where the slip direction
/// turns), separation (the actuator's lift-off), an elastic body.
const CONTACT_CASES: &[(&str, &[&str])] = &[
    ("paper", &["mesh.n=32"]),
    ("paper-slip", &["mesh.n=32"]),
    ("paper-tresca", &["mesh.n=32"]),
    // Tresca's bound along the zone: the active sets take a bound per point
    (
        "paper-tresca",
        &[
            "mesh.n=32",
            "~contact.slip_bound",
            "contact.slip_bound_profile={along=[1.0,0.0],at=[0.0,2.0],value=[0.01,0.1]}",
        ],
    ),
    ("paper-frictionless", &["mesh.n=32"]),
    ("paper-3d", &["mesh.n=6"]),
    ("paper-3d", &["mesh.n=6", "contact.friction=0.1"]),
    ("actuator", &[]),
    ("paper-elastic", &["mesh.n=32"]),
];

/// The weighted relative difference of two sets of multipliers on the same points.
fn multiplier_diff(a: &problem::ContactResult, b: &problem::ContactResult) -> f64 {
    let w = &a.points.weight;
    let d = a.solution.lambda.minus(&b.solution.lambda);
    d.weighted_norm(w) / a.solution.lambda.weighted_norm(w).max(f64::MIN_POSITIVE)
}

fn agree_on_contact(petsc: &Petsc) {
    for (name, sets) in CONTACT_CASES {
        let (faer, scene) = both(name, sets, &[]);
        let dist = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .expect("the PETSc run");
        let Some(dist) = dist else { continue };
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let (a, b) = (
            direct.contact.as_ref().expect("contact"),
            dist.contact.as_ref().expect("contact"),
        );
        assert_eq!(a.nodes, b.nodes, "{name}: the same points");
        let dl = multiplier_diff(a, b);
        let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
        let du = rel_diff(&flat(&direct.u), &flat(&dist.u));
        eprintln!(
            "{name} {sets:?}: {} steps, {} Krylov iterations, residual {:.1e}, lambda {dl:.1e}, u {du:.1e}, counts {:?} / {:?}",
            dist.report.iterations.newton,
            dist.report.petsc.as_ref().map_or(0, |p| p.krylov_iterations),
            dist.report.residuals.complementarity,
            a.solution.counts(),
            b.solution.counts()
        );
        assert!(dl < 1e-8, "{name} {sets:?}: multipliers differ by {dl:.2e}");
        assert!(du < 1e-8, "{name} {sets:?}: displacements differ by {du:.2e}");
        assert!(dist.report.residuals.complementarity <= scene.solver.tol);
    }
}

#[test]
fn contact_on_one_rank_agrees_with_the_direct_solver() {
    on_ranks("contact_on_one_rank_agrees_with_the_direct_solver", 1, agree_on_contact);
}

#[test]
fn contact_on_two_ranks_agrees_with_the_direct_solver() {
    on_ranks(
        "contact_on_two_ranks_agrees_with_the_direct_solver",
        2,
        agree_on_contact,
    );
}

fn agree(petsc: &Petsc) {
    for (name, sets) in CASES {
        let (faer, scene) = both(name, sets, &[]);
        let dist = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .expect("the PETSc run");
        if petsc.rank() != 0 {
            assert!(dist.is_none());
            continue;
        }
        let dist = dist.expect("rank 0 has the solution");
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
        let du = rel_diff(&flat(&direct.u), &flat(&dist.u));
        let dphi = rel_diff(&direct.phi, &dist.phi);
        let report = dist.report.petsc.as_ref().expect("the PETSc section");
        eprintln!(
            "{name}: {} ranks, {} unknowns, {} iterations ({}), u {du:.1e}, phi {dphi:.1e}",
            report.ranks, report.unknowns, report.krylov_iterations, report.reason
        );
        assert!(
            du < 1e-8 && dphi < 1e-8,
            "{name}: u differs by {du:.2e}, phi by {dphi:.2e}"
        );
        assert_eq!(report.ranks, petsc.size());
        assert_eq!(report.cells_per_rank.iter().sum::<usize>(), direct.mesh.n_cells());
        assert!(dist.report.residuals.equilibrium < 1e-8, "{name}");
        if let (Some(a), Some(b)) = (&direct.report.exact, &dist.report.exact) {
            let (ea, eb) = (a.error(), b.error());
            assert!(
                (ea - eb).abs() <= 1e-6 * ea.abs().max(1e-300),
                "{name}: exact errors {ea} and {eb}"
            );
        }
    }
}

#[test]
fn one_rank_agrees_with_the_direct_solver() {
    on_ranks("one_rank_agrees_with_the_direct_solver", 1, agree);
}

#[test]
fn two_ranks_agree_with_the_direct_solver() {
    on_ranks("two_ranks_agree_with_the_direct_solver", 2, agree);
}

#[test]
fn bad_options_and_oblique_normals_are_refused_by_name() {
    on_ranks("bad_options_and_oblique_normals_are_refused_by_name", 2, |petsc| {
        let text = scene_file::SHIPPED
            .iter()
            .find(|(n, _)| n.eq(&"paper"))
            .expect("paper")
            .1;
        let sets = ["mesh.n=8".to_string(), "solver.backend=\"petsc\"".to_string()];
        let mut oblique = sets.to_vec();
        oblique.push("contact.normal=[0.3, -1.0]".into());
        // a valid scene, which the backend does not solve: refused before anything is built
        let scene = scene_file::parse(text, "paper", &oblique).expect("a valid scene");
        let e = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .map(|_| ())
            .unwrap_err();
        assert!(e.to_string().contains("coordinate axis"), "{e}");
        let mut sets = sets.to_vec();
        sets.push("solver.petsc_options=\"-ksp_type nonsense\"".into());
        let scene = scene_file::parse(text, "paper", &sets).expect("the scene reads");
        let e = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .map(|_| ())
            .unwrap_err();
        assert!(e.to_string().contains("nonsense"), "{e}");
        // a roller through the contact face: held tangents, which the active sets do not hold
        let mut roller = ["mesh.n=8".to_string(), "solver.backend=\"petsc\"".to_string()].to_vec();
        roller.extend(["~dirichlet.1.u".to_string(), "dirichlet.1.ux=0".to_string()]);
        let scene = scene_file::parse(text, "paper", &roller).expect("the scene reads");
        let e = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .map(|_| ())
            .unwrap_err();
        assert!(
            e.to_string().contains("do not hold a tangent of a contact point"),
            "{e}"
        );
    });
}

/// MUMPS, PETSc's distributed direct solver, stays available by options alone: the contact
/// iteration on it gives the default backend's answer.
#[test]
fn mumps_through_the_options_gives_the_same_answer() {
    on_ranks("mumps_through_the_options_gives_the_same_answer", 2, |petsc| {
        let mumps = "solver.petsc_options=\"-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps\"";
        let (faer, scene) = both("paper-3d", &["mesh.n=6", "contact.friction=0.1"], &[mumps]);
        let Some(dist) = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .expect("the MUMPS run")
        else {
            return;
        };
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let d = multiplier_diff(
            direct.contact.as_ref().expect("contact"),
            dist.contact.as_ref().expect("contact"),
        );
        assert!(d < 1e-10, "MUMPS: multipliers differ by {d:.2e}");
        let report = dist.report.petsc.as_ref().expect("the PETSc section");
        assert!(report.options.contains("mumps"), "{}", report.options);
    });
}

/// A mesh too large for the memory given is refused before anything is built, with the
/// estimate, on every rank alike.
#[test]
fn a_mesh_too_large_is_refused_by_its_estimate() {
    on_ranks("a_mesh_too_large_is_refused_by_its_estimate", 2, |petsc| {
        let (_, scene) = both("paper-3d", &["mesh.n=160"], &[]);
        let limits = problem::Limits {
            memory_bytes: Some(8 << 30),
            ..Default::default()
        };
        let e = distributed::solve(&scene, None, petsc, limits, &mut problem::Silent)
            .map(|_| ())
            .unwrap_err();
        assert!(e.to_string().contains("on each of 2 ranks"), "{e}");
    });
}
