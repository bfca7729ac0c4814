//! End-to-end contact tests on whole scenes (docs/scenes.md sections 1-4).
//!
//! ```text
//!            p (traction on top)
//!      +---------------------------+
//!  u=0 |  PZT-5A, poled along y    | u=0
//! phi=0|                           | phi=0
//!      +---------------------------+
//!      ///// rigid foundation, Coulomb F ///////
//! ```
//!
//! Expected numbers: `paper-slip` has 69 of 127 points slipping at n = 64 (docs/scenes.md);
//! `paper` sticks everywhere; the answer is proportional to p (g = 0); `pzt5a-si` is `paper`
//! under the change of units of docs/scenes.md section 4; the strategies agree to 1e-8.

use problem::Solution;

fn run(scene: &str, sets: &[&str]) -> Solution {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    driver::studies::solve(scene, &sets).unwrap()
}

fn counts(r: &Solution) -> (usize, usize, usize) {
    let c = &r.report.contact;
    (c.n_stick, c.n_slip, c.n_separated)
}

fn lambdas(r: &Solution) -> Vec<f64> {
    let lambda = &r.contact.as_ref().unwrap().solution.lambda;
    lambda.normal.iter().chain(&lambda.tangential).copied().collect()
}

fn rel_diff(a: &[f64], b: &[f64], scale_b: f64) -> f64 {
    let s = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x * scale_b - y).abs())
        .fold(0.0, f64::max)
        / s
}

/// run.json's `contact.frame` (and each group's) gives the directions of contact.csv's
/// components: the tangential force rebuilt from the points' `λ_t` along the frame's tangents
/// is the reported resultant, the normal force along the normal balances the load's share,
/// and the frame is the scene's (`n = -z` gives `t1 = x`, `t2 = y`); zones of different normals
/// have no shared frame, each its own.
#[test]
fn the_contact_frame_gives_the_directions_of_the_components() {
    for (scene, sets) in [
        ("paper-slip", vec!["mesh.n=8"]),
        ("paper-3d", vec!["mesh.n=3"]),
        ("corner", vec!["mesh.n=8"]),
    ] {
        let r = run(scene, &sets);
        let (c, report) = (r.contact.as_ref().unwrap(), &r.report.contact);
        let frames: Vec<(&problem::report::ContactFrame, Vec<usize>)> = match &report.frame {
            Some(f) => vec![(f, (0..c.points.len()).collect())],
            None => (report.groups.iter().enumerate())
                .map(|(k, g)| {
                    (
                        g.frame.as_ref().unwrap(),
                        (0..c.points.len()).filter(|&i| c.group_of[i] == k).collect(),
                    )
                })
                .collect(),
        };
        assert_eq!(frames.len(), if scene == "corner" { 2 } else { 1 }, "{scene}");
        let dim = c.points.dim;
        let nt = c.solution.lambda.n_tangential();
        let mut resultant = vec![0.0; dim];
        for (frame, points) in &frames {
            assert_eq!((frame.normal.len(), frame.tangents.len()), (dim, dim - 1));
            for &i in points {
                for q in 0..nt {
                    let w = c.points.weight[i] * c.solution.lambda.tangential[i * nt + q];
                    for k in 0..dim {
                        resultant[k] += w * frame.tangents[q][k];
                    }
                }
            }
        }
        let scale = report.normal_force.abs();
        for k in 0..dim {
            assert!(
                (resultant[k] - report.tangential_resultant[k]).abs() <= 1e-12 * scale,
                "{scene}: {resultant:?} {report:?}"
            );
        }
        // the normal resultant: each zone's normal force pushing the body out along -n
        let forces: Vec<f64> = match report.groups.len() {
            0 => vec![report.normal_force],
            _ => report.groups.iter().map(|g| g.normal_force).collect(),
        };
        for k in 0..dim {
            let pushed: f64 = frames.iter().zip(&forces).map(|((f, _), p)| -p * f.normal[k]).sum();
            assert!(
                (pushed - report.normal_resultant[k]).abs() <= 1e-12 * scale,
                "{scene}: {report:?}"
            );
        }
        if scene == "paper-3d" {
            let f = &frames[0].0;
            assert_eq!(
                (f.normal.as_slice(), &f.tangents[..]),
                (&[0.0, 0.0, -1.0][..], &[vec![1.0, 0.0, 0.0], vec![0.0, 1.0, 0.0]][..])
            );
        }
    }
}

/// A closed form of a contact zone where nothing touches: its errors would be NaN (the run
/// once failed on "a reported number is not finite ... the problem may be singular"); it is
/// refused on `exact.kind`, and the same run without [exact] solves.
#[test]
fn a_contact_closed_form_where_nothing_touches_is_refused_by_its_key() {
    for scene in ["hertz", "cattaneo-mindlin"] {
        let sets = vec!["mesh.n=8".to_string(), "contact.gap=0.5".to_string()];
        let e = driver::studies::solve(scene, &sets).err().unwrap().to_string();
        assert!(
            e.contains("exact.kind") && e.contains("nothing touches"),
            "{scene}: {e}"
        );
        let without: Vec<String> = sets.into_iter().chain(["~exact".to_string()]).collect();
        let r = driver::studies::solve(scene, &without).unwrap();
        assert_eq!(r.report.contact.normal_force, 0.0);
    }
}

/// The command line says the run's results, each number with its unit: the contact's counts
/// and forces, an indenter's figures, each terminal's charge at its potential.
#[test]
fn the_results_are_said_with_their_units() {
    let r = run("actuator", &["mesh.n=8"]);
    let lines = problem::report::result_lines(&r.report);
    let c = &r.report.contact;
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(
        lines[0].contains(&format!("normal force {:.4e} GN/m", c.normal_force)),
        "{lines:?}"
    );
    assert!(
        lines[0].contains("tangential force")
            && lines[0].contains(&format!("{} of {} points stick", c.n_stick, c.n_points))
    );
    let electrode = r.report.terminals.iter().find(|t| t.group == "electrode").unwrap();
    assert!(
        lines[1].contains(&format!("`electrode` {:.4e} C/m at 5.0000e-2 GV", electrode.charge)),
        "{lines:?}"
    );
    // an indenter in µm and mN, frictionless: no tangential force said
    let r = run("indent-sphere", &["mesh.n=8"]);
    let lines = problem::report::result_lines(&r.report);
    let i = r.report.indenter.as_ref().unwrap();
    assert!(!lines[0].contains("tangential"), "{lines:?}");
    assert!(
        lines[1].starts_with(&format!("indenter: depth {:.4e} µm, force {:.4e} mN", i.depth, i.force)),
        "{lines:?}"
    );
}

#[test]
fn paper_slip_has_the_slip_zone_of_scenes_md() {
    let r = run("paper-slip", &[]);
    assert_eq!(r.report.contact.n_points, 127);
    assert_eq!(counts(&r), (58, 69, 0));
    assert!(r.report.residuals.complementarity <= 1e-10);
    assert!(r.report.residuals.equilibrium <= 1e-12);
}

#[test]
fn paper_sticks_everywhere_and_is_proportional_to_the_load() {
    let r2 = run("paper", &["mesh.n=16"]);
    let r4 = run("paper", &["mesh.n=16", "load.p=-4"]);
    let r6 = run("paper", &["mesh.n=16", "load.p=-6"]);
    assert_eq!(counts(&r2), (31, 0, 0));
    assert_eq!(counts(&r4), counts(&r2));
    assert_eq!(counts(&r6), counts(&r2));
    assert!(rel_diff(&lambdas(&r2), &lambdas(&r4), 2.0) < 1e-8);
    assert!(rel_diff(&lambdas(&r2), &lambdas(&r6), 3.0) < 1e-8);
}

#[test]
fn strategies_agree() {
    for (scene, n) in [
        ("paper", "mesh.n=16"),
        ("paper-slip", "mesh.n=16"),
        ("actuator", "mesh.n=16"),
        ("paper-3d", "mesh.n=2"),
    ] {
        let a = run(scene, &[n, "solver.strategy=uzawa-condensed"]);
        let b = run(scene, &[n, "solver.strategy=uzawa-direct"]);
        let c = run(scene, &[n, "solver.strategy=uzawa-schur-pcg"]);
        // a different iteration: compared at a residual of 1e-12 (at 1e-10 the two differ by
        // 2.4e-8 on paper at n = 16, the dual's conditioning times the residual)
        let a12 = run(scene, &[n, "solver.tol=1e-12", "solver.strategy=uzawa-condensed"]);
        let d = run(scene, &[n, "solver.tol=1e-12", "solver.strategy=apg-condensed"]);
        let e = run(scene, &[n, "solver.tol=1e-12", "solver.strategy=newton-condensed"]);
        assert!(
            rel_diff(&lambdas(&a12), &lambdas(&d), 1.0) < 1e-8,
            "{scene}: condensed vs accelerated"
        );
        assert!(
            rel_diff(&lambdas(&a12), &lambdas(&e), 1.0) < 1e-8,
            "{scene}: Uzawa vs semismooth Newton"
        );
        assert!(!e.report.iterations.newton_fallback, "{scene}");
        assert!(
            rel_diff(&lambdas(&a), &lambdas(&b), 1.0) < 1e-8,
            "{scene}: condensed vs direct"
        );
        assert!(
            rel_diff(&lambdas(&a), &lambdas(&c), 1.0) < 1e-8,
            "{scene}: condensed vs schur-pcg"
        );
        assert_eq!(counts(&a), counts(&b), "{scene}");
        assert!(c.report.iterations.pcg > 0);
    }
}

#[test]
fn si_units_give_the_paper_answer_mapped() {
    let paper = run("paper", &["mesh.n=16"]);
    let si = run("pzt5a-si", &["mesh.n=16"]);
    // lambda_SI = 1e6 lambda, u_SI = 1e-5 u, phi_SI = 1e4 phi (docs/scenes.md section 4)
    assert!(rel_diff(&lambdas(&paper), &lambdas(&si), 1e6) < 1e-11);
    let up: Vec<f64> = paper.u.iter().flatten().copied().collect();
    let us: Vec<f64> = si.u.iter().flatten().copied().collect();
    assert!(rel_diff(&up, &us, 1e-5) < 1e-11);
    assert!(rel_diff(&paper.phi, &si.phi, 1e4) < 1e-11);
    assert_eq!(counts(&paper), counts(&si));
    // the same iteration counts: every stopping test is scale-free
    assert_eq!(paper.report.iterations, si.report.iterations);
}

#[test]
fn frictionless_and_tresca_plans_leave_out_what_they_do_not_need() {
    let f = run("paper-frictionless", &["mesh.n=8"]);
    assert!(!f.report.plan.friction);
    assert_eq!(f.report.iterations.fixed_point, 0);
    assert!(f.contact.as_ref().unwrap().solution.lambda.tangential.is_empty());
    let (_, s, _) = counts(&f);
    assert_eq!(s, 15);
    let t = run("paper-tresca", &["mesh.n=16"]);
    assert!(!t.report.plan.fixed_point);
    assert_eq!(t.report.iterations.fixed_point, 0);
    let sol = &t.contact.as_ref().unwrap().solution;
    assert!(sol.lambda.tangential.iter().all(|l| l.abs() <= 0.05 * (1.0 + 1e-9)));
    let none = run("paper", &["mesh.n=8", "contact.law=none"]);
    assert!(none.contact.is_none());
    assert_eq!(none.report.iterations.uzawa, 0);
}

#[test]
fn actuator_lifts_off_sticks_and_slips_along_the_voltage() {
    let off = run("actuator", &["mesh.n=16", "electrode.v=-0.1"]);
    assert_eq!(counts(&off), (0, 0, 31), "complete lift-off");
    let zero = run("actuator", &["mesh.n=16", "electrode.v=0"]);
    assert_eq!(counts(&zero).2, 0);
    assert_eq!(counts(&zero).1, 0, "all stick at V = 0");
    let up = run("actuator", &["mesh.n=16", "electrode.v=0.1"]);
    assert!(counts(&up).1 > 0, "a slip zone at V = 0.1: {:?}", counts(&up));
}

#[test]
fn paper_rule_is_labelled_and_reproduces_the_table_counts() {
    let r = run(
        "paper",
        &["mesh.n=32", "solver.rule=paper", "solver.strategy=uzawa-schur-pcg"],
    );
    assert!(r.report.solver.rule.starts_with("paper"));
    assert!(!r.report.residuals.converged_to_tolerance);
    let it = &r.report.iterations;
    eprintln!("paper rule at n = 32: {it:?}");
    // the paper's Table 1 at h = 1/32: 3 fixed-point, 39 Uzawa, 2 PCG iterations (per solve)
    assert_eq!(it.fixed_point, 3);
    let uz = it.uzawa;
    // 39 with exact inner solves (solver.pcg_tol=1e-12); with the paper's loose PCG the step
    // r = 1.8/μ_max comes from inexact solves, and the count moves a little: 38 since μ_max is
    // estimated from the contact forces alone (no cancellation against the loads), 43 before
    assert!((36..=45).contains(&uz), "Uzawa iterations: {uz}");
    let pcg_per_solve = it.pcg as f64 / (uz as f64 + 1.0);
    assert!(pcg_per_solve <= 3.0, "PCG iterations per Uzawa solve: {pcg_per_solve}");
    let exact = run(
        "paper",
        &["mesh.n=32", "solver.rule=paper", "solver.strategy=uzawa-direct"],
    );
    assert_eq!(exact.report.iterations.uzawa, 39);
    assert_eq!(exact.report.iterations.fixed_point, 3);
}

#[test]
fn every_shipped_scene_runs_at_its_smoke_size() {
    for (name, text) in files::scene_file::SHIPPED {
        let scene = files::scene_file::parse(text, name, &[]).unwrap();
        assert!(
            scene.mesh.smoke_n.is_some(),
            "{name}: every shipped scene has a smoke size"
        );
        let r = driver::studies::solve(name, &scene.mesh.smoke()).unwrap();
        let eq = r.report.residuals.equilibrium;
        assert!(eq < 1e-10, "{name}: equilibrium {eq}");
        if r.contact.is_some() {
            assert!(r.report.residuals.complementarity <= 1e-10, "{name}");
        }
    }
}

#[test]
fn gmsh_mesh_with_two_materials_by_region() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/layered-gmsh.toml");
    let r = driver::studies::solve(file, &[]).unwrap();
    let mesh = &r.mesh;
    // potentials only on the nodes of the PZT layer (y >= 0.8), less the grounded ones
    let pzt_nodes: std::collections::BTreeSet<usize> = mesh
        .region("pzt")
        .unwrap()
        .iter()
        .flat_map(|&c| mesh.cell(c).to_vec())
        .collect();
    let grounded = pzt_nodes
        .iter()
        .filter(|&&v| mesh.points[v][0] == 0.0 || mesh.points[v][0] == 2.0)
        .count();
    assert_eq!(r.report.dofs.phi, pzt_nodes.len() - grounded);
    assert!(pzt_nodes.iter().all(|&v| mesh.points[v][1] >= 0.8 - 1e-12));
    assert!(r.report.residuals.complementarity <= 1e-10);
    assert!(r.report.residuals.equilibrium <= 1e-12);
    // the foundation carries the load: sum of w lambda_n is the applied force less what the
    // clamped sides take, so it lies between 0 and |p| times the top's length
    let f = r.report.contact.normal_force;
    assert!(f > 0.5 && f < 4.0, "normal force {f}");
    // potentials vanish in the substrate (no electric unknowns there)
    let substrate_only: Vec<usize> = (0..mesh.n_nodes()).filter(|v| !pzt_nodes.contains(v)).collect();
    assert!(substrate_only.iter().all(|&v| r.phi[v] == 0.0));
    assert!(r.phi.iter().any(|&p| p != 0.0));
}

/// Every case of the stability study reads, and at a smoke size converges with the default
/// strategy to what it must show (the study itself runs the real sizes: `piezocontact
/// stability`).
#[test]
fn stability_cases_hold_at_smoke_size() {
    use driver::studies::stability;
    for case in stability::CASES.iter().filter(|c| !c.fine) {
        let sets = case.smoke_sets();
        match (driver::studies::solve(case.scene, &sets), case.expect) {
            (Err(e), stability::Expect::Refused(why)) => {
                assert!(
                    e.to_string().contains(why),
                    "{}: refused for another reason: {e}",
                    case.name
                )
            }
            (Ok(_), stability::Expect::Refused(why)) => panic!("{}: solved, but must be refused ({why})", case.name),
            (Err(e), _) => panic!("{}: {e}", case.name),
            (Ok(r), expect) => {
                if let Err(e) = stability::check(expect, &r.report) {
                    panic!("{}: {e}", case.name);
                }
            }
        }
        if let Some(p) = &case.paper_sets {
            let sets: Vec<String> = p.iter().map(|s| s.to_string()).collect();
            files::scene_file::load(case.scene, &sets).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        }
    }
}

/// Hertz's problem in plane strain (scene `hertz`).
///
/// - Source: K. L. Johnson, Contact Mechanics (1985), section 4.2: a cylinder of radius R on a
///   half-plane, load P per unit length, `a² = 4 P R / (π E*)`, `p0 = 2 P / (π a)`,
///   `p(x) = p0 √(1 - x²/a²)`; here the foundation is rigid, so `E* = E / (1 - ν²)`.
/// - Goal: the contact pressure of the discrete frictionless problem is Hertz's, which checks
///   the gap, the Signorini multipliers and their weights against a solution we did not write.
/// - Sketch: the block (-4,4)x(0,4), E = 100, ν = 0.3, the curvature 1/R = 0.1 in the gap
///   `g = x²/(2R)`, rollers on the sides, the top pushed down 0.03: P (the reaction) is about
///   1.84, a about 0.461, p0 about 2.54; the block is 9 half-widths wide and deep.
/// - Expected at n = 48 (h = 1/12, about a/5.5), measured: peak pressure 0.9 % above p0; the
///   last point in contact is the last node with |x| < a; the nodal pressure profile within
///   3.8 % of Hertz's in the discrete L2 norm over |x| ≤ 1.5 a (1.9 % at n = 96, 1.5 % at
///   n = 192: the rest is the block's finite size).
/// - Tolerances: peak within 3 % (the nodal peak of a P1 field on a semi-ellipse sampled at
///   h = a/5.5, plus the 0.4 % finite-size error that remains at n = 192); the edge within one
///   cell, where the discrete contact zone can only end at a node; the profile within 6 %
///   (its error is largest in the cell that holds the edge, where √(1 - x²/a²) is steepest).
#[test]
fn hertz_pressure_is_johnsons() {
    let r = run("hertz", &["mesh.n=48"]);
    let c = r.contact.as_ref().unwrap();
    let (points, sol) = (&c.points, &c.solution);
    let p = r.report.contact.normal_force;
    let e_star = 100.0 / (1.0 - 0.3f64 * 0.3);
    let a = (4.0 * p * 10.0 / (std::f64::consts::PI * e_star)).sqrt();
    let p0 = 2.0 * p / (std::f64::consts::PI * a);
    let h = 8.0 / 96.0;
    let peak = sol.lambda.normal.iter().cloned().fold(0.0, f64::max);
    assert!((peak / p0 - 1.0).abs() < 0.03, "peak {peak} against p0 = {p0}");
    let edge = points
        .position
        .iter()
        .zip(&sol.lambda.normal)
        .filter(|(_, &l)| l > 0.0)
        .map(|(x, _)| x[0].abs())
        .fold(0.0, f64::max);
    assert!(edge <= a && a < edge + h, "contact ends at {edge}, a = {a}");
    let (mut err, mut norm) = (0.0, 0.0);
    for (x, &l) in points.position.iter().zip(&sol.lambda.normal) {
        if x[0].abs() <= 1.5 * a {
            let exact = p0 * (1.0 - x[0] * x[0] / (a * a)).max(0.0).sqrt();
            err += (l - exact).powi(2);
            norm += exact * exact;
        }
    }
    assert!((err / norm).sqrt() < 0.06, "profile error {}", (err / norm).sqrt());
}

/// Cattaneo-Mindlin in plane strain (scene `cattaneo-mindlin`).
///
/// - Source: K. L. Johnson, Contact Mechanics (1985), section 7.1 (Cattaneo 1938, Mindlin
///   1949): a cylinder pressed by P and pulled by Q < F P on a half-plane, with normal and
///   tangential loading uncoupled, has a central stick zone of half-width `c = a √(1 - Q/(F P))`,
///   and `q(x) = F p0 √(1 - x²/a²) - F p0 (c/a) √(1 - x²/c²)` (second term inside the stick
///   zone only).
/// - Goal: the Coulomb solution (stick zone, slip with `|λ_t| = F λ_n`, traction profile)
///   against a solution we did not write.
/// - Sketch: the `hertz` block with Poisson's ratio 0.475, F = 0.5, its sides free and its top
///   displaced by (0.02, -0.03): P ≈ 2.35, Q ≈ 0.75, Q/(F P) ≈ 0.64, c/a ≈ 0.60; n = 192
///   (h = 1/48, about a/23).
/// - Expected, measured at n = 192: the stick zone [-0.271, 0.250] (half-width 0.260 against
///   c = 0.290, centred 0.02 a left of the axis); the traction profile within 10.1 % (19.5 %
///   at n = 96, 6.8 % at n = 384).
/// - Tolerances: the stick zone's edge moves in steps of h and the uncoupling is not exact:
///   Dundurs' β = (1 - 2ν)/(2(1 - ν)) = 0.048 against a rigid foundation (Cattaneo needs 0),
///   and P1 stiffens as ν nears ½. So: half-width within 3 h of c, centre within 0.05 a,
///   profile within 13 %, and Coulomb's law itself (slip at `F λ_n`) to 1e-8.
#[test]
fn cattaneo_mindlin_stick_zone() {
    let r = run("cattaneo-mindlin", &["mesh.n=192"]);
    let Some(problem::ExactReport::Contact(x)) = &r.report.exact else {
        panic!("no contact errors reported");
    };
    let (a, c, c_h) = (x.a, x.c.unwrap(), x.c_h.unwrap());
    let h = 1.0 / 48.0;
    let q_over_fp = x.load_q.unwrap() / (0.5 * x.load_p);
    assert!((0.5..0.75).contains(&q_over_fp), "Q/(F P) = {q_over_fp}");
    assert!(
        (c_h - c).abs() < 3.0 * h,
        "stick half-width {c_h} against c = {c} (a = {a})"
    );
    assert!(x.stick_offset.unwrap().abs() < 0.05, "{x:?}");
    assert!(x.error < 0.13, "traction profile error {}", x.error);
    let sol = &r.contact.as_ref().unwrap().solution;
    for (i, s) in sol.status.iter().enumerate() {
        if *s == contact::Status::Slip {
            let (ln, lt) = (sol.lambda.normal[i], sol.lambda.tangential[i].abs());
            assert!(
                (lt - 0.5 * ln).abs() <= 1e-8 * ln.max(1.0),
                "slip point {i}: |λ_t| {lt}, F λ_n {}",
                0.5 * ln
            );
        }
    }
}

/// The convergence study on `paper` against a finer nested mesh.
///
/// - Goal: `piezocontact study` measures what it says: the discretisation error falls with h,
///   Newton's algebraic error is round-off at any tolerance it accepts, Uzawa's falls with its
///   tolerance, and a reference that does not nest is refused with a typed error.
/// - Sketch: sizes 4 and 8, reference 32; Newton and Uzawa on the condensed problem at
///   tolerances 1e-2 and 1e-8.
#[test]
fn study_separates_discretisation_and_algebraic_errors() {
    use driver::studies::convergence::{study, StudySpec};
    use problem::Strategy;
    let spec = StudySpec {
        sizes: vec![4, 8],
        strategies: vec![Strategy::NewtonCondensed, Strategy::UzawaCondensed],
        tols: vec![1e-2, 1e-8],
        reference_n: Some(32),
        orders: vec![],
    };
    let s = study("paper", &[], &spec, &mut |_| {}).unwrap();
    assert_eq!(s.rows.len(), 8);
    assert!(s.tight[1].error < s.tight[0].error, "{:?}", s.tight);
    // the scene's own order, where the study names none
    assert!(s.rows.iter().all(|r| r.order == 1));
    for r in &s.rows {
        assert!(r.seconds > 0.0 && r.error > 0.0);
        match (r.strategy, r.tol) {
            (Strategy::NewtonCondensed, _) => assert!(r.algebraic < 1e-10, "{r:?}"),
            (_, 1e-8) => assert!(r.algebraic < 1e-6, "{r:?}"),
            _ => assert!(r.algebraic > 1e-6, "{r:?}"),
        }
    }
    let bad = StudySpec {
        reference_n: Some(12),
        ..spec.clone()
    };
    let e = study("paper", &[], &bad, &mut |_| {}).unwrap_err().to_string();
    assert!(e.contains("must be a multiple of the largest size 8"), "{e}");
    // 16 is a multiple of 8 but not of 6: the nodes at x = 1/6 have no match
    let bad = StudySpec {
        sizes: vec![6, 8],
        reference_n: Some(16),
        ..spec
    };
    let e = study("paper", &[], &bad, &mut |_| {}).unwrap_err().to_string();
    assert!(e.contains("is not a node of the reference mesh"), "{e}");
}

/// Frictionless contact: the body slides, and the tangential displacement of the final
/// solution is reported (it was written as 0, the law carrying no tangential multiplier).
#[test]
fn frictionless_contact_reports_the_sliding() {
    let r = run("paper-frictionless", &["mesh.n=16"]);
    let c = r.contact.as_ref().unwrap();
    assert_eq!(c.displacement.n_tangential(), 1);
    let slide = c.displacement.tangential.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(slide > 1e-5, "largest slide {slide}");
    // it is the tangential component of the nodal displacement
    for (i, &node) in c.nodes.iter().enumerate() {
        let t = c.points.tangent[i][0];
        let ut = r.u[node][0] * t[0] + r.u[node][1] * t[1];
        assert!((ut - c.displacement.tangential[i]).abs() <= 1e-12 * slide, "point {i}");
    }
}

/// A load pressing the contact face straight into the foundation: the loads and the contact
/// forces cancel, and the equilibrium residual must stay relative to them (dividing by their
/// vanishing sum once gave 0.13, reported as converged).
#[test]
fn the_equilibrium_residual_stays_meaningful_when_the_loads_cancel() {
    let r = run("paper", &["mesh.n=8", "load.group=bottom", "load.direction=[0, -1]"]);
    assert!(
        r.report.residuals.equilibrium < 1e-12,
        "{}",
        r.report.residuals.equilibrium
    );
    assert!(r.report.residuals.complementarity <= 1e-10);
}

/// The hostile inputs of docs/stability.md (issue 12's families) give what they must: a
/// solution whose residuals meet the tolerance, or the typed error that names the fault.
#[test]
fn hostile_inputs_solve_or_are_refused_by_name() {
    use driver::studies::inputs::{check_solved, Outcome, INPUTS};
    for input in INPUTS {
        let sets: Vec<String> = input.sets.iter().map(|s| s.to_string()).collect();
        let result = driver::studies::solve(input.scene, &sets);
        match (input.expect, result) {
            (Outcome::Solves, Ok(r)) => {
                if let Err(e) = check_solved(&r.report) {
                    panic!("{} {:?}: {e}", input.scene, input.sets);
                }
            }
            (Outcome::Refused(text), Err(e)) => {
                assert!(e.to_string().contains(text), "{} {:?}: {e}", input.scene, input.sets)
            }
            (expect, Ok(_)) => panic!("{} {:?}: solved, expected {expect:?}", input.scene, input.sets),
            (expect, Err(e)) => panic!("{} {:?}: {e}, expected {expect:?}", input.scene, input.sets),
        }
    }
}

/// Every combination of displacement components held on the paper's two sides, and of the
/// potential held or not, in 2D and 3D: solved where the conditions hold the body, and
/// otherwise refused before any factorisation with the rigid motion or the potential that is
/// free (never a pivot failure deep in a sparse factor).
#[test]
fn a_body_left_free_is_refused_by_what_is_free() {
    let mut seen = [0usize; 3]; // solved, a motion free, a potential floating
    for (scene, dim, n) in [("paper", 2usize, "mesh.n=8"), ("paper-3d", 3, "mesh.n=2")] {
        let axes = ["ux", "uy", "uz"];
        for held in 0..(1usize << (2 * dim)) {
            for phi in [true, false] {
                let mut sets = vec![n.to_string(), "~dirichlet.0.u".into(), "~dirichlet.1.u".into()];
                for side in 0..2 {
                    for (k, axis) in axes.iter().enumerate().take(dim) {
                        if held & (1 << (side * dim + k)) != 0 {
                            sets.push(format!("dirichlet.{side}.{axis}=0"));
                        }
                    }
                    if !phi {
                        sets.push(format!("~dirichlet.{side}.phi"));
                    }
                }
                // a side with nothing left on it is no condition at all
                let empty: Vec<usize> = (0..2)
                    .filter(|s| (held >> (s * dim)) & ((1 << dim) - 1) == 0 && !phi)
                    .collect();
                for s in empty.iter().rev() {
                    sets.retain(|x| {
                        !x.starts_with(&format!("dirichlet.{s}.")) && !x.starts_with(&format!("~dirichlet.{s}."))
                    });
                    sets.push(format!("~dirichlet.{s}"));
                }
                let what = format!("{scene} {}", sets.join(" "));
                match driver::studies::solve(scene, &sets) {
                    Ok(r) => {
                        assert!(r.report.residuals.converged_to_tolerance, "{what}: not converged");
                        seen[0] += 1;
                    }
                    Err(e) => {
                        let e = e.to_string();
                        seen[1] += usize::from(e.contains("rigid motion"));
                        seen[2] += usize::from(e.contains("potential is floating"));
                        let told = e.contains("rigid motion")
                            || e.contains("potential is floating")
                            || e.contains("no condition");
                        assert!(told, "{what}: {e}");
                        assert!(!e.contains("pivot") && !e.contains("singular"), "{what}: {e}");
                    }
                }
            }
        }
    }
    assert!(
        seen.iter().all(|&n| n > 0),
        "solved, motion free, potential floating: {seen:?}"
    );
}

/// Semismooth Newton's steps on the problem itself do not grow with the mesh (its nested
/// start: the problem on every other contact point first, `contact`'s `coarse` module). From
/// zero multipliers they did: 4, 6, 7 on `paper-slip` at n = 32, 64, 128; 6, 7, 8 on
/// `paper-compliance`; 5, 7, 8 on `paper-conducting`; 8, 10, 11 on `paper-conductive`.
#[test]
fn newton_steps_do_not_grow_with_the_mesh() {
    for scene in ["paper-slip", "paper-compliance", "paper-conducting", "paper-conductive"] {
        let steps: Vec<usize> = [32, 64, 128]
            .iter()
            .map(|n| run(scene, &[&format!("mesh.n={n}")]).report.iterations.newton)
            .collect();
        eprintln!("{scene}: Newton steps {steps:?} at n = 32, 64, 128");
        assert!(steps.iter().all(|&s| s <= steps[0] + 1), "{scene}: {steps:?}");
        assert!(steps.iter().all(|&s| s <= 7), "{scene}: {steps:?}");
    }
}

/// A unit square (cube) on symmetry rollers (`left`, `bottom`, and `front` in 3D) pressed into
/// a corner: every other face against its own rigid wall (`[[contact]]`, frictionless) placed
/// `delta` inside it. The walls squeeze the body uniformly, `u = -delta x`, so each wall carries
/// the pressure `p = (dim λ + 2μ) delta` over its unit face; the corner nodes are points of two
/// (three) groups.
fn squeezed_into_a_corner(dim: usize, delta: f64) -> problem::Scene {
    let (kind, hi, n) = if dim == 2 {
        ("rectangle", "[1.0, 1.0]", 4)
    } else {
        ("box", "[1.0, 1.0, 1.0]", 3)
    };
    let mut toml = format!(
        "name = \"corner-{dim}d\"\ndescription = \"a unit square or cube squeezed by its walls\"\n\
         [mesh]\nkind = \"{kind}\"\nlo = {}\nhi = {hi}\nn = {n}\n\
         [[material]]\nregion = \"body\"\nmodel = \"isotropic\"\nyoung = 100.0\npoisson = 0.3\n",
        hi.replace('1', "0")
    );
    // per axis: the symmetry face (a roller) and the face against its wall
    let faces = if dim == 2 {
        &[("left", "right"), ("bottom", "top")][..]
    } else {
        &[("left", "right"), ("front", "back"), ("bottom", "top")][..]
    };
    for (k, (roller, wall)) in faces.iter().enumerate() {
        let normal: Vec<String> = (0..dim)
            .map(|q| if q == k { "1.0" } else { "0.0" }.to_string())
            .collect();
        toml += &format!("[[dirichlet]]\ngroup = \"{roller}\"\nu{} = 0.0\n", ["x", "y", "z"][k]);
        toml += &format!(
            "[[contact]]\ngroup = \"{wall}\"\nlaw = \"signorini\"\nnormal = [{}]\ngap = {}\n",
            normal.join(", "),
            -delta
        );
    }
    files::scene_file::parse(&toml, "corner", &[]).unwrap()
}

#[test]
fn several_contact_groups_squeeze_a_body_into_a_corner_as_the_closed_form_says() {
    let (young, poisson, delta) = (100.0, 0.3, 1e-3);
    let (lambda, mu) = (
        young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)),
        young / (2.0 * (1.0 + poisson)),
    );
    for dim in [2, 3] {
        let scene = squeezed_into_a_corner(dim, delta);
        let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
        let p = (dim as f64 * lambda + 2.0 * mu) * delta;
        let groups = &s.report.contact.groups;
        assert_eq!(groups.len(), dim, "{dim}D: {groups:?}");
        for g in groups {
            assert!(
                (g.normal_force - p).abs() < 1e-9 * p,
                "{dim}D `{}`: force {} against {p}",
                g.group,
                g.normal_force
            );
            assert_eq!(g.n_separated, 0, "{dim}D `{}`", g.group);
        }
        for (x, u) in s.mesh.points.iter().zip(&s.u) {
            for k in 0..dim {
                assert!((u[k] + delta * x[k]).abs() < 1e-12, "{dim}D at {x:?}: {u:?}");
            }
        }
        // the corner's node is a point of each wall
        let n = s.report.contact.n_points;
        let faces: usize = groups.iter().map(|g| g.n_points).sum();
        assert_eq!(n, faces);
    }
}

/// Two zones on two foundations: the unit square of [`squeezed_into_a_corner`] with its top
/// wall a compliant bed (`λ_n = k p`) and its right wall rigid, each pressed in by `δ`. The
/// strain is uniform (P1 holds it exactly): `ε_xx = -δ`, `ε_yy = -(δ - p)` with `p` the
/// penetration into the bed, where the bed's pressure `k p` balances `-σ_yy`:
/// `p = (λ δ + (λ + 2μ) δ) / (k + λ + 2μ)`; the right wall carries `(λ + 2μ) δ + λ (δ - p)`.
/// On a path scaling the gaps (`path.gap`) each instant is that at its `δ` (frictionless: no
/// history).
#[test]
fn a_compliant_bed_beside_a_rigid_wall_holds_each_zone_to_its_own_law() {
    let (young, poisson, delta) = (100.0, 0.3, 1e-3);
    let (lambda, mu) = (
        young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)),
        young / (2.0 * (1.0 + poisson)),
    );
    let k = lambda + 2.0 * mu;
    let mut scene = squeezed_into_a_corner(2, delta);
    let Some(problem::Contacts::Many(zones)) = scene.contact.as_mut() else {
        panic!("an array")
    };
    let top = zones.iter_mut().find(|z| z.group == "top").unwrap();
    top.compliance = Some(problem::ComplianceSpec {
        stiffness: k,
        exponent: 1.0,
    });
    let expected = |d: f64| {
        let p = (lambda * d + (lambda + 2.0 * mu) * d) / (k + lambda + 2.0 * mu);
        (k * p, (lambda + 2.0 * mu) * d + lambda * (d - p))
    };
    let check = |s: &problem::Solution, d: f64, what: &str| {
        let (bed, wall) = expected(d);
        for g in &s.report.contact.groups {
            // a face of length 1: the force is the pressure
            let want = if g.group == "top" { bed } else { wall };
            assert!(
                (g.normal_force - want).abs() < 1e-9 * want,
                "{what} `{}`: force {} against {want}",
                g.group,
                g.normal_force
            );
        }
    };
    let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
    check(&s, delta, "one instant");
    assert!(s.report.plan.to_string().contains("in some zones"), "{}", s.report.plan);
    // the same on a path of the gaps, 0 to δ in 4 steps
    scene.path = Some(problem::PathSpec {
        t: vec![0.0, 1.0],
        steps: Some(4),
        gap: Some(vec![0.0, 1.0]),
        ..Default::default()
    });
    let mut forces = vec![];
    let path = problem::solve_path(
        &scene,
        None,
        problem::Limits::default(),
        &mut problem::Silent,
        false,
        &mut |step| {
            forces.push((
                step.row.t,
                step.row
                    .groups
                    .iter()
                    .map(|g| (g.group.clone(), g.normal_force))
                    .collect::<Vec<_>>(),
            ));
            Ok(())
        },
    )
    .unwrap();
    check(&path.last, delta, "the path's last instant");
    assert_eq!(forces.len(), 5);
    for (t, groups) in forces {
        let (bed, wall) = expected(t * delta);
        for (group, force) in groups {
            let want = if group == "top" { bed } else { wall };
            assert!(
                (force - want).abs() <= 1e-9 * expected(delta).1,
                "t = {t} `{group}`: {force} against {want}"
            );
        }
    }
}

#[test]
fn what_several_contact_groups_cannot_share_is_refused_by_name() {
    let base = squeezed_into_a_corner(2, 1e-3);
    let refused = |change: &dyn Fn(&mut problem::Scene)| {
        let mut s = base.clone();
        change(&mut s);
        s.validate().unwrap_err().key
    };
    let Some(problem::Contacts::Many(_)) = &base.contact else {
        panic!("an array")
    };
    fn group(s: &mut problem::Scene, k: usize) -> &mut problem::ContactSpec {
        match s.contact.as_mut().unwrap() {
            problem::Contacts::Many(v) => &mut v[k],
            problem::Contacts::One(c) => c,
        }
    }
    assert_eq!(refused(&|s| group(s, 1).group = "right".into()), "contact.group");
    // one zone conducts, the others are insulated
    assert_eq!(
        refused(&|s| {
            group(s, 0).electric = Some(problem::ElectricCondition::Conducting);
            group(s, 1).electric = Some(problem::ElectricCondition::Conducting);
        }),
        "contact.electric"
    );
    // several zones: the PETSc backend solves them too, and refuses options for Krylov
    // solvers that its run with contact (MUMPS) would not use
    let mut petsc = base.clone();
    petsc.solver.backend = problem::BackendChoice::Petsc;
    distributed::supports(&petsc).expect("the PETSc backend solves several zones");
    petsc.solver.petsc_options = Some("-ksp_type cg".into());
    assert_eq!(distributed::supports(&petsc).unwrap_err().key, "solver.petsc_options");
}

#[test]
fn the_shipped_corner_meets_its_closed_form() {
    // scenes/corner.toml: a PZT-5A square squeezed into a corner by two walls, its top an open
    // electrode: uniform strain -delta, the open top's field (e31 + e33)(-delta)/eps33
    let (c11, c13, c33, e31, e33, eps33, delta) = (121.0, 75.2, 111.0, -5.4, 15.8, 7.35, 1e-3);
    let (scene, _) = files::scene_file::load("corner", &[]).unwrap();
    let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
    let field = (e31 + e33) * (-delta) / eps33;
    let sense = s.report.terminals.iter().find(|t| t.group == "sense").unwrap();
    assert!(sense.floating);
    assert!(
        (sense.potential - field).abs() < 1e-9 * field.abs(),
        "V = {} against {field}",
        sense.potential
    );
    let p = [
        -((c11 + c13) * (-delta) + e31 * field),
        -((c13 + c33) * (-delta) + e33 * field),
    ];
    for (g, p) in s.report.contact.groups.iter().zip(p) {
        assert!(
            (g.normal_force - p).abs() < 1e-9 * p,
            "`{}`: {} against {p}",
            g.group,
            g.normal_force
        );
    }
}

/// The corner squeezed along a path (the walls' gap factor from 0 to 1): each instant's row
/// carries each wall's forces, which sum to the row's total, and at the last instant each
/// wall's pressure is the static closed form's (the problem is linear in the squeeze).
#[test]
fn a_path_reports_each_contact_groups_forces() {
    let (c11, c13, c33, e31, e33, eps33, delta) = (121.0, 75.2, 111.0, -5.4, 15.8, 7.35, 1e-3);
    let sets = [
        "mesh.n=4".to_string(),
        "path={t=[0.0,1.0],gap=[0.0,1.0],steps=4}".into(),
    ];
    let (scene, _) = files::scene_file::load("corner", &sets).unwrap();
    let p = problem::solve_path(
        &scene,
        None,
        Default::default(),
        &mut problem::Silent,
        false,
        &mut |_| Ok(()),
    )
    .unwrap();
    let rows = p.last.report.path.unwrap().rows;
    let field = (e31 + e33) * (-delta) / eps33;
    let closed = [
        -((c11 + c13) * (-delta) + e31 * field),
        -((c13 + c33) * (-delta) + e33 * field),
    ];
    for r in &rows {
        let names: Vec<&str> = r.groups.iter().map(|g| g.group.as_str()).collect();
        assert_eq!(names, ["right", "top"]);
        let sum: f64 = r.groups.iter().map(|g| g.normal_force).sum();
        assert!(
            (sum - r.normal_force).abs() <= 1e-12 * r.normal_force.max(1e-300),
            "t = {}",
            r.t
        );
        let f = r.factors[5];
        for (g, p) in r.groups.iter().zip(closed) {
            assert!(
                (g.normal_force - f * p).abs() <= 1e-9 * p,
                "t = {}, `{}`: {}",
                r.t,
                g.group,
                g.normal_force
            );
            assert_eq!(g.tangential_resultant, [0.0, 0.0], "frictionless walls");
        }
    }
}

#[test]
fn friction_on_a_later_contact_group_is_not_lost() {
    // the corner's walls under Coulomb's law, the first frictionless, the second F = 0.3: the
    // plan has friction (it once looked at the first group alone, and the second wall's
    // friction was dropped), the second wall carries a tangential force, the first none
    let mut scene = squeezed_into_a_corner(2, 1e-3);
    let Some(problem::Contacts::Many(walls)) = scene.contact.as_mut() else {
        panic!("an array")
    };
    for (w, f) in walls.iter_mut().zip([0.0, 0.3]) {
        w.law = problem::ContactLaw::Coulomb;
        w.friction = Some(f);
    }
    let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
    assert!(s.report.plan.friction);
    let groups = &s.report.contact.groups;
    assert_eq!(groups[0].tangential_force, 0.0, "{groups:?}");
    assert!(groups[1].tangential_force > 1e-6 * groups[1].normal_force, "{groups:?}");
}

/// Tresca's bound along the zone (`contact.slip_bound_profile`): a profile of one value is the
/// uniform bound to the bit; a bound rising along x holds every slipping point at its own bound
/// and every sticking point under it (2D, and 3D with the bound along y); the profile's data
/// are refused by key where they cannot be read.
#[test]
fn a_tresca_bound_along_the_zone_holds_each_point_at_its_own() {
    let profile = |along: &str, at: &str, value: &str| {
        format!("contact.slip_bound_profile={{along={along},at={at},value={value}}}")
    };
    let uniform = run("paper-tresca", &["mesh.n=16"]);
    let one = profile("[1.0,0.0]", "[0.0]", "[0.05]");
    let flat = run("paper-tresca", &["mesh.n=16", "~contact.slip_bound", &one]);
    assert_eq!(lambdas(&uniform), lambdas(&flat));
    let cases = [
        (
            "paper-tresca",
            vec!["mesh.n=32".to_string(), "~contact.slip_bound".into()],
            profile("[1.0,0.0]", "[0.0,2.0]", "[0.01,0.1]"),
        ),
        (
            "paper-3d",
            vec![
                "mesh.n=8".into(),
                "contact.law=\"tresca\"".into(),
                "~contact.friction".into(),
            ],
            profile("[0.0,1.0,0.0]", "[0.0,1.0]", "[0.02,0.2]"),
        ),
    ];
    for (scene, mut sets, p) in cases {
        sets.push(p);
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let r = run(scene, &sets);
        let c = r.contact.as_ref().unwrap();
        let (sol, nt) = (&c.solution, c.solution.lambda.n_tangential());
        let (mut slipping, mut bounds) = (0, vec![]);
        for (i, x) in c.points.position.iter().enumerate() {
            // the bound the profile gives here, piecewise linear along its direction
            let (s, (lo, hi), (v0, v1)) = if nt == 1 {
                (x[0], (0.0, 2.0), (0.01, 0.1))
            } else {
                (x[1], (0.0, 1.0), (0.02, 0.2))
            };
            let bound = v0 + (v1 - v0) * ((s - lo) / (hi - lo)).clamp(0.0, 1.0);
            bounds.push(bound);
            let t: f64 = (0..nt)
                .map(|k| sol.lambda.component(i, 1 + k).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                t <= bound * (1.0 + 1e-9) + 1e-14,
                "{scene} point {i}: |λ_t| = {t} above {bound}"
            );
            if sol.status[i] == contact::Status::Slip {
                slipping += 1;
                assert!(
                    (t - bound).abs() <= 1e-9 * bound,
                    "{scene} point {i} slips: |λ_t| = {t}, bound {bound}"
                );
            }
        }
        assert!(slipping > 0, "{scene}: some points slip");
        let spread =
            bounds.iter().cloned().fold(0.0f64, f64::max) / bounds.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!(spread > 5.0, "{scene}: the bound varies along the zone ({spread})");
    }
    // read or refused by key
    for (sets, key) in [
        (vec![one.clone()], "contact.slip_bound"),
        (
            vec![
                "~contact.slip_bound".into(),
                profile("[1.0,0.0]", "[1.0,0.0]", "[0.1,0.1]"),
            ],
            "contact.slip_bound_profile.at",
        ),
        (
            vec!["~contact.slip_bound".into(), profile("[1.0,0.0]", "[0.0,1.0]", "[0.1]")],
            "contact.slip_bound_profile.value",
        ),
        (
            vec!["~contact.slip_bound".into(), profile("[1.0,0.0]", "[0.0]", "[-0.1]")],
            "contact.slip_bound_profile.value",
        ),
        (
            vec!["~contact.slip_bound".into(), profile("[0.0,0.0]", "[0.0]", "[0.1]")],
            "contact.slip_bound_profile.along",
        ),
        (
            vec!["~contact.slip_bound".into(), profile("[1.0]", "[0.0]", "[0.1]")],
            "contact.slip_bound_profile.along",
        ),
        (
            vec![
                "contact.law=\"coulomb\"".into(),
                "contact.friction=0.3".into(),
                "~contact.slip_bound".into(),
                one.clone(),
            ],
            "contact.slip_bound_profile",
        ),
    ] {
        let e = files::scene_file::load("paper-tresca", &sets).unwrap_err();
        let files::Error::Scene {
            source: files::SceneFileError::Invalid(e),
            ..
        } = e
        else {
            panic!("{sets:?}: {e}")
        };
        assert_eq!(e.key, key, "{sets:?}: {e}");
    }
}

/// Each `[[contact]]` zone its own Tresca bound (zones once had to share it): the corner's two
/// walls under Tresca, the right wall's bound a hundredth of the top's; every point within its
/// own zone's bound, the slipping points on it, and the zones' bounds distinct in the law.
#[test]
fn each_contact_zone_keeps_its_own_tresca_bound() {
    let bounds = [1e-4, 1e-2];
    let sets: Vec<String> = vec![
        "contact.0.law=\"tresca\"".into(),
        format!("contact.0.slip_bound={}", bounds[0]),
        "contact.1.law=\"tresca\"".into(),
        format!("contact.1.slip_bound={}", bounds[1]),
    ];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let r = run("corner", &sets);
    let c = r.contact.as_ref().unwrap();
    let sol = &c.solution;
    let mut slipping = [0usize; 2];
    for (i, &g) in c.group_of.iter().enumerate() {
        let bound = bounds[g];
        let t = sol.lambda.component(i, 1).abs();
        assert!(
            t <= bound * (1.0 + 1e-9),
            "point {i} of zone {g}: |λ_t| = {t} above {bound}"
        );
        if sol.status[i] == contact::Status::Slip {
            slipping[g] += 1;
            assert!(
                (t - bound).abs() <= 1e-9 * bound,
                "point {i} of zone {g} slips: |λ_t| = {t}, bound {bound}"
            );
        }
    }
    assert!(slipping[0] > 0, "the weak wall slips: {slipping:?}");
    // the strong wall holds more than the weak wall's bound could: its own bound is in the law
    let strongest = (0..c.group_of.len())
        .filter(|&i| c.group_of[i] == 1)
        .map(|i| sol.lambda.component(i, 1).abs())
        .fold(0.0f64, f64::max);
    assert!(
        strongest > 2.0 * bounds[0],
        "the top wall's largest |λ_t| = {strongest}"
    );
}

/// A zone switched off among others (`contact.1.law = "none"`; once refused) is not posed: the
/// corner with its top wall switched off is the corner with its right wall alone, to the last
/// bit, and reports the right wall alone; its keys are inert (a conducting condition on it
/// changes nothing, as on one `[contact]` switched off).
#[test]
fn a_zone_switched_off_among_others_is_not_posed() {
    let (corner, _) = files::scene_file::load("corner", &[]).unwrap();
    let problem::Contacts::Many(zones) = corner.contact.clone().unwrap() else {
        panic!("the corner has two zones")
    };
    let mut off = corner.clone();
    let mut switched = zones.clone();
    switched[1].law = problem::ContactLaw::None;
    switched[1].electric = Some(problem::ElectricCondition::Conducting);
    off.contact = Some(problem::Contacts::Many(switched));
    let mut alone = corner.clone();
    alone.contact = Some(problem::Contacts::Many(vec![zones[0].clone()]));
    let (a, b) = (
        problem::solve(&off, None, &mut problem::Silent).unwrap(),
        problem::solve(&alone, None, &mut problem::Silent).unwrap(),
    );
    let (x, y) = (a.contact.as_ref().unwrap(), b.contact.as_ref().unwrap());
    assert_eq!(x.groups, ["right"]);
    assert_eq!(x.solution.lambda, y.solution.lambda);
    assert_eq!(a.phi, b.phi);
    assert_eq!(a.report.contact.groups.len(), b.report.contact.groups.len());
    // every zone switched off: no contact at all
    let mut none = off;
    if let Some(problem::Contacts::Many(v)) = none.contact.as_mut() {
        v[0].law = problem::ContactLaw::None;
    }
    assert!(problem::solve(&none, None, &mut problem::Silent)
        .unwrap()
        .contact
        .is_none());
}

/// A Tresca zone beside a Coulomb zone (zones once could not mix the two): the corner's right
/// wall under Tresca's bound 1e-3, its top wall under Coulomb's 0.3; every point within its own
/// zone's radius (the bound, or `F λ_n`), the sliding points on it, some of each wall sliding.
#[test]
fn a_tresca_zone_beside_a_coulomb_zone_keeps_each_its_law() {
    let (bound, mu) = (1e-3, 0.3);
    let sets = [
        "contact.0.law=\"tresca\"".to_string(),
        format!("contact.0.slip_bound={bound}"),
        "contact.1.law=\"coulomb\"".into(),
        format!("contact.1.friction={mu}"),
    ];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let r = run("corner", &sets);
    assert_eq!(r.report.plan.contact_law, problem::ContactLaw::Coulomb);
    let c = r.contact.as_ref().unwrap();
    let sol = &c.solution;
    let mut sliding = [0usize; 2];
    for (i, &g) in c.group_of.iter().enumerate() {
        let (n, t) = (sol.lambda.normal[i], sol.lambda.component(i, 1).abs());
        let radius = if g == 0 { bound } else { mu * n };
        assert!(
            t <= radius * (1.0 + 1e-9) + 1e-14,
            "point {i} of zone {g}: |λ_t| = {t} above {radius}"
        );
        if sol.status[i] == contact::Status::Slip {
            sliding[g] += 1;
            assert!(
                (t - radius).abs() <= 1e-8 * radius.max(1e-12),
                "point {i} of zone {g} slides: |λ_t| = {t}, radius {radius}"
            );
        }
    }
    assert!(
        sliding[0] > 0 && sliding[1] > 0,
        "each wall has sliding points: {sliding:?}"
    );
    assert!(r.report.residuals.converged_to_tolerance);
}

/// A frictionless zone beside a frictional one (zones once had to share their law): the
/// corner's right wall under Coulomb (F = 0.3), its top wall Signorini's; the top's tangential
/// multipliers are zero, the right wall's within Coulomb's cone, some of its points sliding on it.
#[test]
fn a_frictionless_zone_joins_a_coulomb_zone() {
    let r = run(
        "corner",
        &["contact.0.law=\"coulomb\"", "contact.0.friction=0.3", "mesh.n=16"],
    );
    let c = r.contact.as_ref().unwrap();
    assert_eq!(r.report.plan.contact_law, problem::ContactLaw::Coulomb);
    let sol = &c.solution;
    let mut on_the_cone = 0;
    for (i, &g) in c.group_of.iter().enumerate() {
        let (n, t) = (sol.lambda.normal[i], sol.lambda.component(i, 1).abs());
        if g == 1 {
            assert_eq!(t, 0.0, "point {i} of the frictionless top");
        } else {
            assert!(
                t <= 0.3 * n * (1.0 + 1e-9) + 1e-14,
                "point {i}: |λ_t| = {t}, F λ_n = {}",
                0.3 * n
            );
            on_the_cone += usize::from(n > 0.0 && (t - 0.3 * n).abs() <= 1e-9 * n);
        }
    }
    assert!(on_the_cone > 0, "the right wall's points slide on Coulomb's cone");
}
