//! The PETSc backend against the default one (feature `petsc`): every shipped scene solved by
//! faer's direct factorisation and by the PETSc backend (MUMPS with the contact dofs' Schur
//! complement, or PETSc's Krylov solvers without contact) on 1 and 2 ranks gives the same
//! answers. Each test starts itself again under `mpirun -np N` (the child
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

/// The weighted relative difference of two sets of multipliers on the same points.
fn multiplier_diff(a: &problem::ContactResult, b: &problem::ContactResult) -> f64 {
    let w = &a.points.weight;
    let d = a.solution.lambda.minus(&b.solution.lambda);
    d.weighted_norm(w) / a.solution.lambda.weighted_norm(w).max(f64::MIN_POSITIVE)
}

/// How far apart two runs of one scene are, at most, over what they report: displacements,
/// potentials, contact multipliers, the terminals' charges and potentials, an indenter's
/// figures, and a path's rows at every instant (forces, depths, charges), each relative to its
/// own scale.
fn farthest(a: &problem::Solution, b: &problem::Solution) -> (f64, String) {
    let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
    let mut worst = vec![
        (rel_diff(&flat(&a.u), &flat(&b.u)), "u".to_string()),
        (rel_diff(&a.phi, &b.phi), "phi".to_string()),
    ];
    if let (Some(x), Some(y)) = (&a.contact, &b.contact) {
        assert_eq!(x.nodes, y.nodes, "the same contact points");
        worst.push((multiplier_diff(x, y), "multipliers".into()));
    }
    // charges against the flux the body carries (its largest |D| over its largest extent, in
    // the dimension's measure), or, in an open circuit (D = 0 throughout: a floating
    // electrode), the flux its field would drive through a permittivity of 1 in the scene's
    // units (the shipped scenes' are 1 to 10 in them): a terminal no flux reaches holds
    // round-off on both backends
    let extent = (0..3)
        .map(|k| {
            let (lo, hi) = a
                .mesh
                .points
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[k]), h.max(p[k])));
            hi - lo
        })
        .fold(0.0f64, f64::max);
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let flux = largest(&a.fields.electric_displacement).max(largest(&a.fields.electric_field));
    let q_scale = flux * extent.powi(a.mesh.dim as i32 - 1);
    let charges = |s: &problem::Solution| s.report.terminals.iter().map(|t| t.charge).collect::<Vec<f64>>();
    let potentials = |s: &problem::Solution| s.report.terminals.iter().map(|t| t.potential).collect::<Vec<f64>>();
    let q_diff = charges(a)
        .iter()
        .zip(charges(b))
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if q_scale > 0.0 {
        worst.push((q_diff / q_scale, "the terminals' charges".into()));
    }
    worst.push((
        rel_diff(&potentials(a), &potentials(b)),
        "the terminals' potentials".into(),
    ));
    if let (Some(x), Some(y)) = (&a.report.indenter, &b.report.indenter) {
        let fig = |i: &problem::report::IndenterReport| {
            [
                i.depth,
                i.force,
                i.charge.unwrap_or(0.0),
                i.tip_potential.unwrap_or(0.0),
            ]
            .to_vec()
        };
        worst.push((rel_diff(&fig(x), &fig(y)), "indenter".into()));
    }
    if let (Some(x), Some(y)) = (&a.report.path, &b.report.path) {
        assert_eq!(x.rows.len(), y.rows.len(), "the same instants");
        // each kind over the instants, relative to its largest value: the forces together (a
        // frictionless path's tangential force is round-off), the slips against the largest
        // displacement (a stuck zone's are round-off), the depths, the charges together
        let u_scale = flat(&a.u).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let kinds = |p: &problem::report::PathReport| {
            let mut k: [Vec<f64>; 4] = Default::default();
            for r in &p.rows {
                k[0].extend([r.normal_force, r.tangential_force]);
                k[1].push(r.max_slip);
                k[2].push(r.depth.unwrap_or(0.0));
                k[3].push(r.tip_charge.unwrap_or(0.0));
                k[3].extend(&r.charges);
            }
            k
        };
        let (kx, ky) = (kinds(x), kinds(y));
        for (i, what) in ["forces", "slips", "depths", "charges"].iter().enumerate() {
            let d = match i {
                1 => {
                    let diff = kx[1].iter().zip(&ky[1]).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
                    diff / u_scale.max(f64::MIN_POSITIVE)
                }
                _ => rel_diff(&kx[i], &ky[i]),
            };
            worst.push((d, format!("the path's {what}")));
        }
    }
    worst
        .into_iter()
        .fold((0.0, String::new()), |m, w| if w.0 > m.0 { w } else { m })
}

/// Every shipped scene at its smoke size, and some at order 2 too (without contact, with
/// contact in 2D and in the modified basis, on curved cells), solved by the PETSc backend and
/// by the default one, agrees to 1e-7 in everything it reports ([`farthest`]).
fn every_scene_agrees(petsc: &Petsc) {
    // at order 2 too: the scenes without contact, 2D contact (a path, electrical contact),
    // and the modified basis (3D, a body of revolution, a 3D path with friction, a conducting
    // tip)
    let quadratic = [
        "manufactured",
        "manufactured-3d",
        "sensor",
        "patch",
        "paper",
        "paper-cycle",
        "manufactured-conducting",
        "cattaneo-mindlin",
        "paper-3d",
        "hertz-sphere",
        "mindlin-sphere-cycle",
        "pfm",
    ];
    let orders = scene_file::SHIPPED.iter().map(|s| (s, "mesh.order=1")).chain(
        scene_file::SHIPPED
            .iter()
            .filter(|s| quadratic.contains(&s.0))
            .map(|s| (s, "mesh.order=2")),
    );
    // and curved cells (the quarter cylinder's round face at order 2) under an indenter
    let curved = scene_file::SHIPPED
        .iter()
        .filter(|s| s.0 == "indent-sphere-3d")
        .map(|s| (s, "mesh.cylinder=true"));
    for ((name, text), order) in orders.chain(curved) {
        let scene = scene_file::parse(text, name, &[]).expect("the scene reads");
        assert!(scene.mesh.smoke_n.is_some(), "{name}: a smoke size");
        let smoke = scene.mesh.smoke();
        let mut sized: Vec<&str> = smoke.iter().map(String::as_str).collect();
        let sets: &[&str] = match order {
            "mesh.order=2" => {
                sized.push(order);
                &sized
            }
            "mesh.cylinder=true" => &["mesh.n=4", "mesh.order=2", order],
            _ => &sized,
        };
        let (faer, scene) = both(name, sets, &[]);
        let t = std::time::Instant::now();
        let dist = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .unwrap_or_else(|e| panic!("{name}: the PETSc run: {e}"));
        let Some(dist) = dist else { continue };
        let seconds = t.elapsed().as_secs_f64();
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let (d, what) = farthest(&direct, &dist);
        eprintln!(
            "{name} ({}, {order}): {seconds:.2} s, farthest {what} at {d:.1e}",
            smoke.join(" ")
        );
        assert!(d < 1e-7, "{name}: {what} differs by {d:.2e}");
        if dist.contact.is_some() {
            assert!(dist.report.residuals.complementarity <= scene.solver.tol, "{name}");
        }
        assert!(dist.report.residuals.equilibrium < 1e-8, "{name}");
    }
}

#[test]
fn every_shipped_scene_on_one_rank_agrees_with_the_default_backend() {
    on_ranks(
        "every_shipped_scene_on_one_rank_agrees_with_the_default_backend",
        1,
        every_scene_agrees,
    );
}

#[test]
fn every_shipped_scene_on_two_ranks_agrees_with_the_default_backend() {
    on_ranks(
        "every_shipped_scene_on_two_ranks_agrees_with_the_default_backend",
        2,
        every_scene_agrees,
    );
}

/// Contact cases of the paper's base model: every law, stick and slip zones, 2D and 3D (where
/// the slip direction turns), separation (the actuator's lift-off), an elastic body, a Tresca
/// bound along the zone.
const ACTIVE_SET_CASES: &[(&str, &[&str])] = &[
    ("paper", &["mesh.n=32"]),
    ("paper-slip", &["mesh.n=32"]),
    ("paper-tresca", &["mesh.n=32"]),
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
    // a roller through the contact face: the left side's x held, the contact edge's points'
    // x tangent with it
    (
        "paper-3d",
        &["mesh.n=6", "contact.friction=0.1", "~dirichlet.0.u", "dirichlet.0.ux=0"],
    ),
    (
        "paper",
        &[
            "mesh.n=32",
            "contact.friction=0.1",
            "~dirichlet.0.u",
            "dirichlet.0.ux=0",
        ],
    ),
    // a quarter model: two symmetry planes through an indenter's zone
    ("indent-sphere-3d", &[]),
    ("actuator", &[]),
    ("paper-elastic", &["mesh.n=32"]),
    // a compliant foundation, and two zones meeting at a corner (its floating electrode
    // removed: the whole mesh's rows are node by node)
    ("paper-compliance", &["mesh.n=32"]),
    ("corner", &["mesh.n=16", "~electrode"]),
    // force control (the search around the active sets' solves)
    (
        "indent-sphere-3d",
        &["mesh.n=8", "contact.indenter.depth=0.0", "contact.indenter.force=0.1"],
    ),
];

/// The Krylov route's active sets (taken where MUMPS' factorisation would not fit the memory
/// of a rank; asked for here by the library's `ContactRoute`) give the default backend's
/// answers on the base model, and refuse by key what they do not hold.
fn agree_on_active_sets(petsc: &Petsc) {
    let mut backend = distributed::DistributedMemory {
        petsc,
        limits: problem::Limits::default(),
        contact: distributed::ContactRoute::ActiveSets,
    };
    for (name, sets) in ACTIVE_SET_CASES {
        let (faer, scene) = both(name, sets, &[]);
        let dist = distributed::solve_with(&mut backend, &scene, None, &mut problem::Silent, &mut |_| Ok(()))
            .unwrap_or_else(|e| panic!("{name} {sets:?}: the PETSc run: {e}"));
        let Some(dist) = dist else { continue };
        let report = dist.report.petsc.as_ref().expect("the PETSc section");
        assert!(!report.options.contains("MUMPS"), "{name}: {}", report.options);
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let (d, what) = farthest(&direct, &dist);
        eprintln!(
            "{name} {sets:?}: {} steps, {} Krylov iterations, farthest {what} at {d:.1e}",
            dist.report.iterations.newton, report.krylov_iterations
        );
        assert!(d < 1e-7, "{name} {sets:?}: {what} differs by {d:.2e}");
        assert!(dist.report.residuals.complementarity <= scene.solver.tol);
    }
    // the paper's Uzawa with one Krylov solve per step (the Krylov route without the active
    // sets): the default backend's answer to the tolerance
    backend.contact = distributed::ContactRoute::Auto;
    let (faer, scene) = both("paper", &["mesh.n=8", "solver.strategy=\"uzawa-schur-pcg\""], &[]);
    let dist = distributed::solve_with(&mut backend, &scene, None, &mut problem::Silent, &mut |_| Ok(()))
        .unwrap_or_else(|e| panic!("uzawa-schur-pcg: the PETSc run: {e}"));
    if let Some(dist) = dist {
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let (d, what) = farthest(&direct, &dist);
        assert!(d < 1e-6, "uzawa-schur-pcg: {what} differs by {d:.2e}");
        assert!(dist.report.iterations.uzawa > 1, "{:?}", dist.report.iterations);
    }
    backend.contact = distributed::ContactRoute::ActiveSets;
    // a law they do not hold: refused by its key
    let (_, scene) = both("paper-slip-weakening", &["mesh.n=32"], &[]);
    let e = distributed::solve_with(&mut backend, &scene, None, &mut problem::Silent, &mut |_| Ok(()))
        .map(|_| ())
        .unwrap_err();
    assert!(e.to_string().contains("contact.friction_law"), "{e}");
}

#[test]
fn the_active_sets_agree_with_the_default_backend_on_one_rank() {
    on_ranks(
        "the_active_sets_agree_with_the_default_backend_on_one_rank",
        1,
        agree_on_active_sets,
    );
}

#[test]
fn the_active_sets_agree_with_the_default_backend_on_two_ranks() {
    on_ranks(
        "the_active_sets_agree_with_the_default_backend_on_two_ranks",
        2,
        agree_on_active_sets,
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
fn bad_options_are_refused_by_name_and_oblique_faces_solved() {
    on_ranks("bad_options_are_refused_by_name_and_oblique_faces_solved", 2, |petsc| {
        let run = |name: &str, sets: &[&str]| {
            let (faer, scene) = both(name, sets, &[]);
            let dist = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent);
            (faer, dist)
        };
        // an oblique contact face and a roller through it (held tangents at contact points):
        // solved, as the default backend solves them
        for sets in [
            &["mesh.n=8", "contact.normal=[0.3, -1.0]"][..],
            &["mesh.n=8", "~dirichlet.1.u", "dirichlet.1.ux=0"][..],
        ] {
            let (faer, dist) = run("paper", sets);
            if let Some(dist) = dist.expect("the PETSc run") {
                let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
                let (d, what) = farthest(&direct, &dist);
                assert!(d < 1e-7, "{sets:?}: {what} differs by {d:.2e}");
            }
        }
        // options PETSc does not know: its message, by key
        let e = run(
            "paper",
            &[
                "mesh.n=8",
                "contact.law=\"none\"",
                "solver.petsc_options=\"-ksp_type nonsense\"",
            ],
        )
        .1
        .map(|_| ())
        .unwrap_err();
        assert!(e.to_string().contains("nonsense"), "{e}");
        // options in a run that factors by MUMPS, which takes none: refused, not ignored
        let e = run("paper", &["mesh.n=8", "solver.petsc_options=\"-ksp_type cg\""])
            .1
            .map(|_| ())
            .unwrap_err();
        assert!(e.to_string().contains("solver.petsc_options"), "{e}");
    });
}

/// PETSc's own MUMPS stays available by options alone on the Krylov route (a run without
/// contact): the same answer as the default backend.
#[test]
fn mumps_through_the_options_gives_the_same_answer() {
    on_ranks("mumps_through_the_options_gives_the_same_answer", 2, |petsc| {
        let mumps = "solver.petsc_options=\"-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps\"";
        let (faer, scene) = both("paper-3d", &["mesh.n=6", "contact.law=\"none\""], &[mumps]);
        let Some(dist) = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .expect("the MUMPS run")
        else {
            return;
        };
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let (d, what) = farthest(&direct, &dist);
        assert!(d < 1e-10, "MUMPS: {what} differs by {d:.2e}");
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

/// Runs `scene` on the ranks of `petsc` within `memory` bytes a rank, checks that it took the
/// active sets for the reason that `why` begins, and (where `faer` is given) that it gives the
/// default backend's answer on that scene; returns the options in force (rank 0; `None` on
/// the others).
fn on_the_active_sets(
    petsc: &Petsc,
    scene: &problem::Scene,
    memory: Option<u64>,
    why: &str,
    faer: Option<&problem::Scene>,
) -> Option<String> {
    let limits = problem::Limits {
        memory_bytes: memory,
        ..Default::default()
    };
    let dist = distributed::solve(scene, None, petsc, limits, &mut problem::Silent)
        .unwrap_or_else(|e| panic!("the PETSc run within {memory:?} a rank: {e}"));
    let dist = dist?;
    let options = &dist.report.petsc.as_ref().expect("the PETSc section").options;
    assert!(
        options.starts_with(why) && options.contains("the Krylov route's active sets"),
        "{options}"
    );
    if let Some(faer) = faer {
        let direct = problem::solve(faer, None, &mut problem::Silent).expect("the faer run");
        let (d, what) = farthest(&direct, &dist);
        assert!(d < 1e-7, "{what} differs by {d:.2e}");
    }
    Some(options.clone())
}

/// A generated body's load path that MUMPS' own estimate, after its analysis, does not fit on
/// a rank, where the estimate before the mesh (a lower one) did: the driver walks the path on
/// pieces instead, in the same run, no rank factoring anything, and gives the default
/// backend's path. The memory is given as the driver takes it from the process's limits (the
/// fallback had no test for want of a machine where the two estimates disagree).
#[test]
fn a_path_mumps_cannot_factor_walks_on_pieces() {
    on_ranks("a_path_mumps_cannot_factor_walks_on_pieces", 2, |petsc| {
        use problem::backend::Backend;
        let sets = ["mesh.n=14", "path={t=[0.0,1.0],load=[0.0,1.0],steps=2}"];
        let (faer, _) = both("paper-3d", &sets, &[]);
        let mut with: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        with.push("solver.backend=\"petsc\"".into());
        let (scene, source) = scene_file::load("paper-3d", &with).expect("the scene reads");
        // within the estimate before the mesh, below MUMPS' own (about 1.6 times the share)
        let (share, _) = problem::SharedMemory.estimate(&scene).expect("a generated mesh");
        let memory = (Some((1.05 * share / 2.0) as u64), Some("the test's limit"));
        assert!(
            !distributed::direct_exceeds(&scene, None, 2, memory.0),
            "the estimate before the mesh takes the whole mesh's route"
        );
        // one directory for the ranks, named by rank 0
        let nonce = petsc.all_gather(u64::from(std::process::id())).expect("gathered")[0];
        let dir = std::env::temp_dir().join(format!("piezocontact-fallback-{nonce}"));
        let solved = driver::petsc_run::run_on(petsc, &scene, &source, &dir, memory, &mut problem::Silent)
            .unwrap_or_else(|e| panic!("the run within {memory:?} a rank: {e}"));
        let Some(solution) = solved else { return };
        let pieces = solution.report.petsc.as_ref().and_then(|p| p.pieces);
        let rows = |s: &problem::Solution| -> Vec<f64> {
            s.report
                .path
                .as_ref()
                .expect("a path")
                .rows
                .iter()
                .map(|r| r.normal_force)
                .collect()
        };
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let written = dir.join("path.csv").exists() && dir.join("run.json").exists();
        let _ = std::fs::remove_dir_all(&dir);
        assert!(pieces.is_some(), "the path on pieces: {:?}", solution.report.petsc);
        assert!(written, "the path's files");
        let d = rel_diff(&rows(&direct), &rows(&solution));
        assert!(d < 1e-6, "the normal forces along the path differ by {d:.2e}");
    });
}

/// Where MUMPS' factorisation would not fit a rank's memory (its own estimate after its
/// analysis, above the estimate before the mesh) and the active sets hold the run, the run
/// takes the Krylov route's active sets and gives the default backend's answer; where they do
/// not hold it, MUMPS' refusal is the error, typed, before it allocates. A large 3D body takes
/// the active sets for speed.
#[test]
fn where_mumps_would_not_fit_the_active_sets_solve() {
    on_ranks("where_mumps_would_not_fit_the_active_sets_solve", 2, |petsc| {
        use problem::backend::Backend;
        // paper-3d at n = 14 (26,100 unknowns, below `ACTIVE_SETS_FROM`: MUMPS' route by
        // speed): MUMPS' estimate after its analysis about 1.6 times the share of the default
        // backend's estimate, within which the run would start on MUMPS; the active sets'
        // estimate 72 MB a rank
        let (faer, scene) = both("paper-3d", &["mesh.n=14"], &[]);
        let (share, _) = problem::SharedMemory.estimate(&scene).expect("a generated mesh");
        let within = |fraction: f64| Some((fraction * share / 2.0) as u64);
        on_the_active_sets(petsc, &scene, within(1.05), "MUMPS' analysis estimates", Some(&faer));
        // where MUMPS' factorisation would not fit by the estimate before it: the active sets,
        // and the run says why
        on_the_active_sets(
            petsc,
            &scene,
            within(0.9),
            "MUMPS' factorisation would need about",
            None,
        );
        // slip-weakening friction, which the active sets do not hold: refused before MUMPS
        // allocates (by its estimate, or by the lower one before the mesh)
        let weakening = [
            "mesh.n=14",
            "~contact.friction",
            "contact.friction_law=\"slip-weakening\"",
            "contact.friction_static=0.6",
            "contact.friction_dynamic=0.3",
            "contact.slip_length=1e-3",
        ];
        let (_, scene) = both("paper-3d", &weakening, &[]);
        let limits = problem::Limits {
            memory_bytes: within(0.9),
            ..Default::default()
        };
        let e = distributed::solve(&scene, None, petsc, limits, &mut problem::Silent)
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("MUMPS' analysis estimates") || e.starts_with("the run needs about"),
            "{e}"
        );
        // a 3D body above `ACTIVE_SETS_FROM` unknowns (n = 20: 68,800 free), memory to spare: the
        // active sets by speed, the default backend's answer
        let (faer, scene) = both("paper-3d", &["mesh.n=20"], &[]);
        on_the_active_sets(petsc, &scene, None, "a 3D body of 6.880e4 unknowns", Some(&faer));
        // which takes PETSc's options (refused where MUMPS factors)
        let restart = "solver.petsc_options=\"-ksp_gmres_restart 150\"";
        let (_, scene) = both("paper-3d", &["mesh.n=20", restart], &[]);
        if let Some(options) = on_the_active_sets(petsc, &scene, None, "a 3D body of 6.880e4 unknowns", None) {
            assert!(options.ends_with("-ksp_gmres_restart 150"), "{options}");
        }
        let (_, scene) = both("paper-3d", &["mesh.n=8", restart], &[]);
        let e = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .map(|_| ())
            .unwrap_err();
        assert!(e.to_string().contains("solver.petsc_options"), "{e}");
    });
}

/// An indenter's contact problem narrowed to the points it can touch (docs/theory.md, "The
/// points that can touch") on every rank: the default backend's answer; and where the body is
/// pushed onto the indenter beyond those points, every rank learns it from the one that holds
/// the fields and all solve again with every point.
fn narrowed_on_every_rank(petsc: &Petsc) {
    for (push, narrowed) in [(None, true), (Some("dirichlet.0.u=[0.0,0.0,-0.5]"), false)] {
        let sets: Vec<&str> = ["mesh.n=8"].into_iter().chain(push).collect();
        let (faer, scene) = both("indent-sphere-3d", &sets, &[]);
        let dist = distributed::solve(&scene, None, petsc, problem::Limits::default(), &mut problem::Silent)
            .unwrap_or_else(|e| panic!("{push:?}: the PETSc run: {e}"));
        let Some(dist) = dist else { continue };
        let direct = problem::solve(&faer, None, &mut problem::Silent).expect("the faer run");
        let (d, what) = farthest(&direct, &dist);
        assert!(d < 1e-7, "{push:?}: {what} differs by {d:.2e}");
        assert_eq!(dist.report.solver.condensed_points.is_some(), narrowed, "{push:?}");
        assert_eq!(
            dist.report.solver.condensed_points,
            direct.report.solver.condensed_points
        );
    }
}

#[test]
fn an_indenters_narrowed_problem_on_two_ranks_agrees_with_the_default_backend() {
    on_ranks(
        "an_indenters_narrowed_problem_on_two_ranks_agrees_with_the_default_backend",
        2,
        narrowed_on_every_rank,
    );
}

/// Ranks with different memory limits (here rank 1 under a data-size limit) agree on the least
/// before any of them judges the run: every rank refuses it alike, rank 0 saying that another
/// rank's limit is the least, and none is left waiting in a collective call for one that
/// stopped (the program under `mpirun -np 2`, each rank's shell setting its own limit).
#[test]
fn ranks_with_different_limits_refuse_a_run_alike() {
    let exe = env!("CARGO_BIN_EXE_piezocontact");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let script = format!(
        "if [ \"$OMPI_COMM_WORLD_RANK\" = 1 ]; then ulimit -d 1500000; fi; exec '{exe}' run paper-3d --set mesh.n=48 --set 'solver.backend=\"petsc\"' --out '{}'",
        out.display()
    );
    let o = std::process::Command::new("timeout")
        .args([
            "300",
            "mpirun",
            "-np",
            "2",
            "--allow-run-as-root",
            "--oversubscribe",
            "sh",
            "-c",
            &script,
        ])
        .output()
        .expect("mpirun runs");
    let stderr = String::from_utf8_lossy(&o.stderr);
    // timeout's 124 would be a rank left waiting
    assert_ne!(o.status.code(), Some(124), "a rank was left waiting: {stderr}");
    assert!(!o.status.success(), "{stderr}");
    assert!(
        stderr.contains("the run needs about") && stderr.contains("the memory limit of another rank"),
        "{stderr}"
    );
    assert!(!out.exists());
}
