//! The contact crate on problems nobody here made: the twelve frictional contact problems of
//! Siconos' test data in `tests/data/fclib/` (rigid and flexible multibody systems; see its
//! README), read by `contact::siconos` and solved by the crate's solvers. Each answer is judged
//! by a check written here from the definitions alone (signs, complementarity, the friction
//! cone, sliding against the velocity), not by the crate's own residuals; the reader and the
//! error measure are checked against numbers that Siconos 4.4 itself computed from the same
//! files (`bench/siconos/solve.py` has the script).

use contact::siconos::{FrictionProblem, Storage};
use contact::{
    solve_gauss_seidel, solve_newton, ContactError, GaussSeidelParams, Law, Measure, NewtonParams, Phase, PointValues,
    ProblemClass, Schedule,
};

fn problem(name: &str) -> FrictionProblem {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fclib")
        .join(name);
    FrictionProblem::parse(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// Per file, as Siconos 4.4 read them (`frictionContact_new_from_filename`, then `W` as a
/// dense array through `NM_convert`):
/// `yᵀ W x` and `yᵀ q` with `x_k = sin(k+1)`, `y_k = cos(k+1)`, and `Σ μ`.
const CHECKSUMS: [(&str, f64, f64, f64); 12] = [
    (
        "BoxesStack1-i100000-32.hdf5.dat",
        -1601.9913909624445,
        2.4287072407165815,
        36.40000000000001,
    ),
    ("Capsules-i101-404.dat", -38.55878193742869, 16.326082104120974, 157.5),
    (
        "Confeti-ex03-Fc3D-SBM.dat",
        0.00035603082327405935,
        15.854749592558186,
        21.59999999999999,
    ),
    (
        "FC2D_SliderCrankLagrangian00000.dat",
        1189.3592767019506,
        9.524346278167144,
        0.02,
    ),
    (
        "FC3D_Example1.dat",
        -0.1332197783447332,
        -3.7414030397446316,
        0.30000000000000004,
    ),
    (
        "FrictionContact3D_1c.dat",
        -0.29965004366144044,
        -4.342573468763761,
        0.1,
    ),
    (
        "FrictionContactProblem00031.dat",
        -0.15961316303936193,
        0.19236107168759398,
        9.9,
    ),
    (
        "FrictionContactProblem00727.dat",
        1.6421889165362251,
        45.915225852954116,
        330.3000000000001,
    ),
    ("NESpheres_10_1.dat", -1.1905625838199647, 2.677205635533432, 7.2),
    ("Rover1039.dat", -0.04393368087452939, -0.1886799634601204, 2.8),
    ("Rover4144.dat", -0.053440214286326525, -1.284041706497808, 2.8),
    (
        "fc2d_granularflowonwall_00667_00000.dat",
        -22374.676847134633,
        -2.058180215071183e-18,
        333.5,
    ),
];

/// Siconos 4.4's `fc3d_compute_error` (called with `norm = |q|`, so that it divides by
/// `max(|q|, |r|, |u|)`) at `r_N = 1 + sin(i)/2`, `r_T1 = 0.3 cos(i)`, `r_T2 = 0.2 sin(2i)` (2D
/// problems lifted to 3D with an uncoupled second tangent, which leaves the error as it is).
const ERRORS: [(&str, f64); 12] = [
    ("BoxesStack1-i100000-32.hdf5.dat", 0.38570397439424714),
    ("Capsules-i101-404.dat", 0.3186619845034909),
    ("Confeti-ex03-Fc3D-SBM.dat", 0.5768452313203992),
    ("FC2D_SliderCrankLagrangian00000.dat", 0.6106203536934773),
    ("FC3D_Example1.dat", 0.1400094742664344),
    ("FrictionContact3D_1c.dat", 0.07096832459507678),
    ("FrictionContactProblem00031.dat", 0.7469526387534768),
    ("FrictionContactProblem00727.dat", 0.5419282588214012),
    ("NESpheres_10_1.dat", 0.4421507328215291),
    ("Rover1039.dat", 0.15324093959890173),
    ("Rover4144.dat", 0.32622509296016566),
    ("fc2d_granularflowonwall_00667_00000.dat", 0.05865333975169831),
];

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn the_reader_agrees_with_siconos() {
    for (name, wxy, qy, mu) in CHECKSUMS {
        let p = problem(name);
        let m = p.q.len();
        let x: Vec<f64> = (1..=m).map(|k| (k as f64).sin()).collect();
        let y: Vec<f64> = (1..=m).map(|k| (k as f64).cos()).collect();
        let wx: Vec<f64> = p.velocity(&x).iter().zip(&p.q).map(|(u, q)| u - q).collect();
        // sums of terms that cancel: compared relative to the sum of their sizes
        let dot = |a: &[f64], b: &[f64]| {
            let terms = a.iter().zip(b).map(|(a, b)| a * b);
            (terms.clone().sum::<f64>(), terms.map(f64::abs).sum::<f64>())
        };
        let (got_w, size_w) = dot(&wx, &y);
        let (got_q, size_q) = dot(&p.q, &y);
        assert!(
            (got_w - wxy).abs() <= 1e-13 * size_w,
            "{name}: yᵀWx {got_w} vs Siconos {wxy}"
        );
        assert!(
            (got_q - qy).abs() <= 1e-13 * size_q,
            "{name}: yᵀq {got_q} vs Siconos {qy}"
        );
        assert!(close(p.mu.iter().sum::<f64>(), mu, 1e-13), "{name}: Σμ vs Siconos {mu}");
    }
}

#[test]
fn the_error_agrees_with_siconos() {
    for (name, expected) in ERRORS {
        let p = problem(name);
        let nc = p.n_contacts();
        let mut r = vec![0.0; p.q.len()];
        for i in 0..nc {
            let f = i as f64;
            r[i * p.dim] = 1.0 + 0.5 * f.sin();
            r[i * p.dim + 1] = 0.3 * f.cos();
            if p.dim == 3 {
                r[i * p.dim + 2] = 0.2 * (2.0 * f).sin();
            }
        }
        let got = p.error(&r);
        assert!(close(got, expected, 1e-9), "{name}: {got} vs Siconos {expected}");
    }
}

/// An independent check of a solution `r` of `p`, from the definitions: with `u = W r + q`,
/// per contact, `r` in the cone (`r_N ≥ 0`, `|r_T| ≤ μ r_N`), `u_N ≥ 0`, and the two
/// non-negative parts of De Saxcé's complementarity zero, `r_N u_N = 0` and
/// `r_T·u_T + μ r_N |u_T| = 0` (no work of the friction force but the dissipated one: sliding
/// against `u_T` at the cone's edge, or no sliding). Returns the largest violation, relative
/// to the scale Siconos' error divides by, `max(|q|, |r|, |u|)` (relative to `|r|` alone, a
/// solve stopped at that error may leave `|q| / |r|` times more: 1500 on Confeti-ex03).
fn violation(p: &FrictionProblem, r: &[f64]) -> f64 {
    let d = p.dim;
    let u = p.velocity(r);
    let two = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let scale = two(r).max(two(&u)).max(two(&p.q)).max(1e-300);
    let (rs, us) = (scale, scale);
    let mut worst = 0.0f64;
    for (i, &mu) in p.mu.iter().enumerate() {
        let (ri, ui) = (&r[i * d..(i + 1) * d], &u[i * d..(i + 1) * d]);
        let (rn, un) = (ri[0], ui[0]);
        let (rt, ut) = (two(&ri[1..]), two(&ui[1..]));
        let dissipation = (1..d).map(|k| ri[k] * ui[k]).sum::<f64>() + mu * rn * ut;
        let v = [
            (-rn / rs).max(0.0),
            ((rt - mu * rn) / rs).max(0.0),
            (-un / us).max(0.0),
            (rn * un / (rs * us)).abs(),
            (dissipation / (rs * us)).abs(),
        ];
        worst = v.iter().fold(worst, |a, b| a.max(*b));
    }
    worst
}

/// `λ` solves `p` to Siconos' error 1e-8, and the laws hold to 1e-6 ([`violation`]).
fn assert_solves(p: &FrictionProblem, name: &str, lambda: &PointValues) {
    let r = p.reaction(lambda);
    assert!(p.error(&r) <= 1e-8 && violation(p, &r) <= 1e-6, "{name}");
}

/// Every one of the twelve, by the default solver, to Siconos' error 1e-8: the tolerance at
/// which Siconos' own test suite runs its Newton solvers on these files is 1e-3 to 1e-8 (1e-3
/// for BoxesStack1 in `test_nsn_3.c`), so this is at least as tight.
#[test]
fn the_twelve_are_solved_by_default_newton() {
    for (name, ..) in CHECKSUMS {
        let p = problem(name);
        let mut op = p.sparse_problem();
        let params = NewtonParams {
            tol: 1e-8,
            measure: Measure::DeSaxce,
            ..Default::default()
        };
        let sol = solve_newton(&mut op, &p.points(), &Law::Coulomb, &params, None, &mut |_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = p.reaction(&sol.lambda);
        let error = p.error(&r);
        assert!(error <= 1e-8, "{name}: Siconos' error {error:.3e}");
        assert!(
            sol.info.residual <= 1e-8 && (sol.info.residual - error).abs() <= 1e-12,
            "{name}"
        );
        // 1e-8 in the natural map leaves violations of the laws of about that size
        let v = violation(&p, &r);
        assert!(v <= 1e-6, "{name}: a law is violated by {v:.3e}");
    }
}

/// The dense and the sparse compliance give Newton the same problem: the same answer (the
/// direction is solved one way or the other).
#[test]
fn dense_and_sparse_newton_agree() {
    for name in [
        "Confeti-ex03-Fc3D-SBM.dat",
        "FrictionContactProblem00031.dat",
        "NESpheres_10_1.dat",
    ] {
        let p = problem(name);
        let params = NewtonParams {
            tol: 1e-12,
            ..Default::default()
        };
        let points = p.points();
        let a = solve_newton(
            &mut p.dense_problem(),
            &points,
            &Law::Coulomb,
            &params,
            None,
            &mut |_| {},
        )
        .unwrap();
        let b = solve_newton(
            &mut p.sparse_problem(),
            &points,
            &Law::Coulomb,
            &params,
            None,
            &mut |_| {},
        )
        .unwrap();
        let d = a.lambda.minus(&b.lambda).norm();
        assert!(d <= 1e-9 * a.lambda.norm(), "{name}: {d}");
    }
}

/// The block Gauss–Seidel method on the well-conditioned ones (it converges linearly, and on
/// the rank-deficient ones too slowly to be a first choice, as in Siconos).
#[test]
fn gauss_seidel_solves_the_well_conditioned_ones() {
    for name in [
        "FC3D_Example1.dat",
        "FrictionContact3D_1c.dat",
        "Rover1039.dat",
        "NESpheres_10_1.dat",
        "fc2d_granularflowonwall_00667_00000.dat",
        "FrictionContactProblem00727.dat",
    ] {
        let p = problem(name);
        let params = GaussSeidelParams {
            tol: 1e-8,
            measure: Measure::DeSaxce,
            ..Default::default()
        };
        let sol = solve_gauss_seidel(
            &mut p.sparse_problem(),
            &p.points(),
            &Law::Coulomb,
            &params,
            None,
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_solves(&p, name, &sol.lambda);
    }
}

/// Stage 0 of Newton's method: the sweeps run first on a sparse compliance, and are kept
/// only where their measured rate wins. On the 2D granular problem they solve it alone (no
/// Newton step); on the rigid capsules they stall, are abandoned early, and Newton then takes
/// exactly the steps it takes without them (it starts where it would have); both answers pass
/// the check from the definitions.
#[test]
fn sweeps_run_first_where_they_win() {
    let solve = |name: &str, sweeps_first: bool| {
        let p = problem(name);
        let params = NewtonParams {
            tol: 1e-8,
            measure: Measure::Both,
            schedule: if sweeps_first {
                Schedule::of(ProblemClass::Multibody)
            } else {
                Schedule::of(ProblemClass::Multibody).without(Phase::Sweeps)
            },
            ..Default::default()
        };
        let sol = solve_newton(
            &mut p.sparse_problem(),
            &p.points(),
            &Law::Coulomb,
            &params,
            None,
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_solves(&p, name, &sol.lambda);
        sol.info
    };
    let granular = solve("FrictionContactProblem00727.dat", true);
    assert!(granular.sweeps > 0 && granular.newton_iters == 0, "{granular:?}");
    assert!(solve("FrictionContactProblem00727.dat", false).sweeps == 0);
    let (capsules, alone) = (
        solve("Capsules-i101-404.dat", true),
        solve("Capsules-i101-404.dat", false),
    );
    assert!(capsules.sweeps > 0 && capsules.sweeps < 200, "{capsules:?}");
    assert_eq!(
        (capsules.newton_iters, capsules.proximal_iters),
        (alone.newton_iters, alone.proximal_iters)
    );
}

/// Where Newton alone cannot finish (BoxesStack1: half of W's rank is missing), the answer
/// comes from the proximal stage, and the counts say so; switched off, the stall is a typed
/// error that carries the best iterate, never worse than the start.
#[test]
fn the_proximal_stage_finishes_rank_deficient_problems() {
    let p = problem("BoxesStack1-i100000-32.hdf5.dat");
    let points = p.points();
    let mut params = NewtonParams {
        tol: 1e-8,
        measure: Measure::DeSaxce,
        ..Default::default()
    };
    let sol = solve_newton(
        &mut p.sparse_problem(),
        &points,
        &Law::Coulomb,
        &params,
        None,
        &mut |_| {},
    )
    .unwrap();
    assert!(sol.info.proximal_iters > 0 && !sol.info.fallback);
    params.schedule = params.schedule.without(Phase::Proximal).without(Phase::Fallback);
    let e = solve_newton(
        &mut p.sparse_problem(),
        &points,
        &Law::Coulomb,
        &params,
        None,
        &mut |_| {},
    )
    .unwrap_err();
    let start = p.error(&vec![0.0; p.q.len()]);
    let best = e.best().expect("a stall carries its best iterate");
    assert!(
        best.residual <= start && (p.error(&p.reaction(&best.lambda)) - best.residual).abs() < 1e-14,
        "{e}"
    );
    assert!(
        matches!(e, ContactError::Stalled { .. } | ContactError::NotUnique { .. }),
        "{e}"
    );
}

/// A deadline already past stops every solver at once, with the best iterate (the start).
#[test]
fn a_deadline_interrupts() {
    let p = problem("Capsules-i101-404.dat");
    let (points, law) = (p.points(), Law::Coulomb);
    let past = contact::Interrupt {
        deadline: Some(std::time::Instant::now()),
        cancel: None,
    };
    static CANCEL: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(true);
    let cancelled = contact::Interrupt {
        deadline: None,
        cancel: Some(&CANCEL),
    };
    let newton = NewtonParams {
        tol: 1e-8,
        interrupt: past,
        ..Default::default()
    };
    let gauss_seidel = GaussSeidelParams {
        interrupt: cancelled,
        ..Default::default()
    };
    let results = [
        (
            solve_newton(&mut p.sparse_problem(), &points, &law, &newton, None, &mut |_| {}),
            contact::Interruption::Deadline,
        ),
        (
            solve_gauss_seidel(&mut p.sparse_problem(), &points, &law, &gauss_seidel, None, &mut |_| {}),
            contact::Interruption::Cancelled,
        ),
    ];
    for (result, expected) in results {
        let e = result.unwrap_err();
        assert!(
            matches!(e, ContactError::Interrupted { why, best: Some(_), .. } if why == expected),
            "{e}"
        );
        let _: Option<PointValues> = e.best().map(|b| b.lambda.clone());
    }
}

/// The seed of the multibody property test's cases: fixed, so that CI runs the same 48
/// problems every time (`PROPTEST_RNG_SEED=N` runs others; 61 other seeds, 2928 problems, were
/// all solved when the lenient Newton stage came in).
fn multibody_seed() -> proptest::test_runner::RngSeed {
    let seed = std::env::var("PROPTEST_RNG_SEED").ok().and_then(|s| s.parse().ok());
    proptest::test_runner::RngSeed::Fixed(seed.unwrap_or(2026))
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 48, rng_seed: multibody_seed(), ..Default::default() })]

    /// The class the twelve stand for: rigid multibody problems (`W = H M⁻¹ Hᵀ`, rank at most
    /// the bodies' velocities, often far below the contacts' count), 2D and 3D, solved by the
    /// default Newton to Siconos' error 1e-8 and checked by the laws themselves.
    #[test]
    fn rigid_multibody_problems_are_solved(seed in 0u64..1_000_000, dim in 2usize..=3, bodies in 1usize..=12, contacts in 1usize..=40) {
        let p = FrictionProblem::multibody(dim, bodies, contacts, seed);
        let params = NewtonParams { tol: 1e-8, measure: Measure::DeSaxce, ..Default::default() };
        let sol = solve_newton(&mut p.sparse_problem(), &p.points(), &Law::Coulomb, &params, None, &mut |_| {});
        let sol = sol.map_err(|e| proptest::test_runner::TestCaseError::fail(format!("{e}")))?;
        let r = p.reaction(&sol.lambda);
        proptest::prop_assert!(p.error(&r) <= 1e-8);
        let v = violation(&p, &r);
        proptest::prop_assert!(v <= 1e-6, "violation {v:.3e}");
    }
}

/// A random seed of the property test found this problem: every stage then ended at Siconos'
/// error 9e-6 (a fixed point on the slip bound expanding by 3.3 near the best iterate), where
/// Siconos' NSN-AC reaches 5e-15 in 222 steps. Stage 1's stricter rules for a sparse
/// compliance stopped it (stored dense it was solved); the lenient Newton stage after the
/// proximal one solves it, from stage 1's best iterate (from the proximal stage's, 1.3e-5
/// once its inner solves had a patience rule, it did not).
#[test]
fn the_multibody_problem_that_stalled_every_stage_is_solved() {
    let p = FrictionProblem::multibody(3, 5, 32, 701498);
    let params = NewtonParams {
        tol: 1e-8,
        measure: Measure::DeSaxce,
        ..Default::default()
    };
    let sol = solve_newton(
        &mut p.sparse_problem(),
        &p.points(),
        &Law::Coulomb,
        &params,
        None,
        &mut |_| {},
    )
    .unwrap();
    let r = p.reaction(&sol.lambda);
    assert!(p.error(&r) <= 1e-8, "{:.3e}", p.error(&r));
    assert!(violation(&p, &r) <= 1e-6);
    assert!(!sol.info.fallback, "solved before the last stage");
}

/// The text `to_text` writes reads back to the same problem, and a multibody problem's `W` is
/// symmetric and semidefinite of rank at most the bodies' velocities (by its Cholesky-free
/// Gram structure: `xᵀ W x ≥ 0`).
#[test]
fn multibody_problems_round_trip() {
    // the last one past a million entries: written in CSparse's compressed columns
    for (dim, bodies, contacts) in [(2, 3, 10), (3, 2, 7), (2, 300, 520)] {
        let p = FrictionProblem::multibody(dim, bodies, contacts, 7);
        assert!(p.asymmetry() < 1e-15);
        let back = FrictionProblem::parse(&p.to_text()).unwrap();
        let storage = if p.q.len() > 1000 {
            Storage::Sparse
        } else {
            Storage::Dense
        };
        assert_eq!(back.storage, storage);
        let x: Vec<f64> = (0..p.q.len()).map(|k| (k as f64 * 0.7).cos()).collect();
        assert_eq!(back.velocity(&x), p.velocity(&x));
        assert_eq!((back.mu.clone(), back.q.clone()), (p.mu.clone(), p.q.clone()));
        let wx: Vec<f64> = p.velocity(&x).iter().zip(&p.q).map(|(a, b)| a - b).collect();
        assert!(x.iter().zip(&wx).map(|(a, b)| a * b).sum::<f64>() >= -1e-12);
    }
}
