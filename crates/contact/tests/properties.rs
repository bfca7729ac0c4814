//! Property tests of the contact crate on small dense problems (no finite elements):
//! projections, contraction of the friction fixed point, Uzawa against an independent
//! active-set enumeration and a KKT check, and homogeneity in the load.

use contact::{
    complementarity_residual, project_cone, project_disc, project_nonnegative, solve_gauss_seidel, solve_newton,
    solve_uzawa, ContactError, ContactPoints, DenseContactProblem, GaussSeidelParams, Law, NewtonParams, Phase,
    PointValues, ProblemClass, Schedule, StopRule, UzawaParams,
};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

fn points(n: usize, dim: usize, w: &[f64], friction: f64) -> ContactPoints {
    ContactPoints {
        dim,
        position: vec![[0.0; 3]; n],
        normal: vec![[0.0, 0.0, -1.0]; n],
        tangent: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; n],
        weight: w[..n].iter().map(|x| 0.5 + x.abs()).collect(),
        gap: vec![0.0; n],
        friction: vec![friction; n],
        held: vec![[false; 2]; n],
        foundation: Default::default(),
        foundations: vec![],
        slipped: vec![],
        weakening: vec![],
        tresca: vec![],
    }
}

/// A random SPD compliance of size m: M Mᵀ / m + 0.1 I.
fn compliance(m: usize, seed: &[f64]) -> Vec<f64> {
    let a = DMatrix::from_fn(m, m, |i, j| seed[(i * 7 + j * 3) % seed.len()]);
    let d = &a * a.transpose() / m as f64 + DMatrix::identity(m, m) * 0.1;
    (0..m)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .map(|(i, j)| d[(i, j)])
        .collect()
}

fn problem(n: usize, nt: usize, pts: &ContactPoints, seed: &[f64], load: &[f64]) -> DenseContactProblem {
    let m = n * (1 + nt);
    DenseContactProblem {
        u0: PointValues::from_parts(load[..n].to_vec(), load[n..n + n * nt].to_vec(), nt).unwrap(),
        compliance: compliance(m, seed),
        weight: pts.weight.clone(),
        nt,
    }
}

fn tight(tol: f64) -> UzawaParams {
    UzawaParams {
        rule: StopRule::Tight { tol },
        ..Default::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn projections_are_projections(x in prop::collection::vec(-5.0f64..5.0, 3), y in prop::collection::vec(-5.0f64..5.0, 3), radius in 0.0f64..3.0, nt in 1usize..=2) {
        // normal cone
        let p = project_nonnegative(x[0]);
        prop_assert!(p >= 0.0);
        prop_assert_eq!(project_nonnegative(p), p);
        prop_assert!((project_nonnegative(x[0]) - project_nonnegative(y[0])).abs() <= (x[0] - y[0]).abs());
        let ys = y[0].abs(); // a point of the set
        prop_assert!((x[0] - p) * (ys - p) <= 1e-12);
        // friction disc (interval in 2D)
        let mut px = x[..nt].to_vec();
        project_disc(&mut px, radius);
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        prop_assert!(norm(&px) <= radius * (1.0 + 1e-12));
        let mut twice = px.clone();
        project_disc(&mut twice, radius);
        for (a, b) in twice.iter().zip(&px) { prop_assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs())); }
        let mut py = y[..nt].to_vec();
        project_disc(&mut py, radius);
        let d: Vec<f64> = px.iter().zip(&py).map(|(a, b)| a - b).collect();
        let e: Vec<f64> = x[..nt].iter().zip(&y[..nt]).map(|(a, b)| a - b).collect();
        prop_assert!(norm(&d) <= norm(&e) * (1.0 + 1e-12) + 1e-12);
        // variational inequality with a point z of the disc
        let mut z = y[..nt].to_vec();
        let nz = norm(&z);
        if nz > radius { z.iter_mut().for_each(|v| *v *= radius / nz); }
        let vi: f64 = (0..nt).map(|k| (x[k] - px[k]) * (z[k] - px[k])).sum();
        prop_assert!(vi <= 1e-10, "VI {vi}");
    }

    /// The projection onto Coulomb's cone: into the cone, idempotent, non-expansive, and the
    /// variational inequality `(x - P x)·(y - P x) ≤ 0` for every `y` of the cone.
    #[test]
    fn the_cone_projection_is_a_projection(x in prop::collection::vec(-5.0f64..5.0, 3), y in prop::collection::vec(-5.0f64..5.0, 3), mu in 0.0f64..2.0, dim in 2usize..=3) {
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let mut px = x[..dim].to_vec();
        project_cone(&mut px, mu);
        prop_assert!(norm(&px[1..]) <= mu * px[0] * (1.0 + 1e-12) + 1e-12);
        let mut twice = px.clone();
        project_cone(&mut twice, mu);
        for (a, b) in twice.iter().zip(&px) { prop_assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs())); }
        let mut py = y[..dim].to_vec();
        project_cone(&mut py, mu);
        let d: Vec<f64> = px.iter().zip(&py).map(|(a, b)| a - b).collect();
        let e: Vec<f64> = x[..dim].iter().zip(&y[..dim]).map(|(a, b)| a - b).collect();
        prop_assert!(norm(&d) <= norm(&e) * (1.0 + 1e-12) + 1e-12);
        // py is a point of the cone
        let vi: f64 = (0..dim).map(|k| (x[k] - px[k]) * (py[k] - px[k])).sum();
        prop_assert!(vi <= 1e-10 * (1.0 + norm(&x) * norm(&y)), "VI {vi}");
    }

    /// Block Gauss–Seidel and Newton find the same Coulomb solution where it is unique (a
    /// small coefficient on a definite compliance).
    #[test]
    fn gauss_seidel_matches_newton(n in 1usize..=5, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), f in 0.05f64..0.3) {
        let nt = dim - 1;
        let pts = points(n, dim, &w, f);
        let op = problem(n, nt, &pts, &seed, &load);
        let newton = solve_newton(&mut op.clone(), &pts, &Law::Coulomb, &NewtonParams { tol: 1e-13, ..Default::default() }, None, &mut |_| {}).unwrap();
        let gs = solve_gauss_seidel(&mut op.clone(), &pts, &Law::Coulomb, &GaussSeidelParams { tol: 1e-13, ..Default::default() }, None, &mut |_| {}).unwrap();
        let d = gs.lambda.minus(&newton.lambda).norm();
        prop_assert!(d <= 1e-8 * newton.lambda.norm().max(1e-300), "{d}");
    }

    /// On a compliant foundation (`λ_n = k [u_n - g]₊^m`, `k` over nine decades, `m` from 1
    /// to 3), with Coulomb's law, Tresca's or none: Newton and block Gauss-Seidel find the same
    /// solution, and it meets the law (the pressure the bed gives, friction within its
    /// bound).
    #[test]
    fn compliant_foundations_newton_and_gauss_seidel_agree(n in 1usize..=5, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), f in 0.05f64..0.3, log_k in -3.0f64..6.0, m in 1.0f64..3.0, which in 0usize..3) {
        let nt = dim - 1;
        let mut pts = points(n, dim, &w, f);
        pts.foundation = contact::Foundation::Compliant { stiffness: 10f64.powf(log_k), exponent: m };
        let law = match which {
            0 => Law::Coulomb,
            1 => Law::Tresca(vec![0.1; n]),
            _ => Law::Frictionless,
        };
        let nt = if which == 2 { 0 } else { nt };
        let op = problem(n, nt, &pts, &seed, &load);
        let newton = solve_newton(&mut op.clone(), &pts, &law, &NewtonParams { tol: 1e-12, ..Default::default() }, None, &mut |_| {}).unwrap();
        let gs = solve_gauss_seidel(&mut op.clone(), &pts, &law, &GaussSeidelParams { tol: 1e-12, ..Default::default() }, None, &mut |_| {}).unwrap();
        let scale = newton.lambda.norm().max(1e-12);
        prop_assert!(gs.lambda.minus(&newton.lambda).norm() <= 1e-7 * scale, "{:?} {:?}", gs.lambda, newton.lambda);
        let k = 10f64.powf(log_k);
        for i in 0..n {
            let pressure = k * newton.u.normal[i].max(0.0).powf(m);
            prop_assert!((newton.lambda.normal[i] - pressure).abs() <= 1e-8 * (1.0 + pressure) * (1.0 + k), "point {i}");
        }
        prop_assert!(newton.info.complementarity <= 1e-12);
        // Uzawa refuses a law that is no projection, by a typed error
        let e = solve_uzawa(&mut op.clone(), &pts, &law, &tight(1e-10), None, &mut |_| {}).unwrap_err();
        prop_assert!(matches!(e, ContactError::Input(contact::InputError::Unsupported(_))), "{e}");
    }

    /// Slip-weakening friction by its fixed point on the coefficients, each step by Newton or
    /// by block Gauss-Seidel: each answer meets the law at its own slips (within the bound
    /// everywhere, on it where the point slides). Slip weakening may have several equilibria
    /// (found by this test: a point that slides 3e-3 at `μ ≈ μ_s` and the same point sliding
    /// 5e-2 at `μ_d`, both exact); the two methods must agree where the map on the slips is a
    /// contraction by a margin, its Lipschitz constant bounded by `‖D W‖_F max λ_n Δμ / L`
    /// (a slip's change per coefficient is at most the compliance times the pressure).
    #[test]
    fn slip_weakening_by_newton_and_by_gauss_seidel_meet_the_law(n in 1usize..=5, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), mu_s in 0.05f64..0.3, fall in 0.0f64..1.0, log_l in -2.0f64..1.0, exponential: bool) {
        use contact::{solve_slip_weakening, Inner, SlipWeakening, Weakening, WeakeningParams};
        let nt = dim - 1;
        let pts = points(n, dim, &w, mu_s);
        let op = problem(n, nt, &pts, &seed, &load);
        let law = SlipWeakening {
            static_coefficient: mu_s,
            dynamic_coefficient: mu_s * (1.0 - fall),
            slip_length: 10f64.powf(log_l),
            form: if exponential { Weakening::Exponential } else { Weakening::Linear },
        };
        let by = |inner| WeakeningParams { tol: 1e-12, inner, newton: NewtonParams { tol: 1e-13, ..Default::default() }, ..Default::default() };
        let newton = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(law), &by(Inner::Newton), &mut |_| {});
        prop_assume!(newton.is_ok()); // a map that does not settle: its own error, another test
        let newton = newton.unwrap();
        // Gauss-Seidel's steps have no Newton polish: a map contracting by 0.9 takes ~250 steps
        let slow = WeakeningParams { max_iters: 2000, ..by(Inner::GaussSeidel) };
        let gs = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(law), &slow, &mut |_| {}).unwrap();
        for sol in [&newton, &gs] {
            let scale = sol.lambda.norm().max(1e-12);
            for i in 0..n {
                let (lt, ln, s) = (sol.lambda.tangential_norm(i), sol.lambda.normal[i], sol.u.tangential_norm(i));
                prop_assert!(lt <= law.coefficient(s) * ln * (1.0 + 1e-8) + 1e-10 * scale);
                if s > 1e-9 * (1.0 + sol.u.norm()) {
                    prop_assert!((lt - law.coefficient(s) * ln).abs() <= 1e-7 * scale, "point {i}");
                }
            }
        }
        let m = n * (1 + nt);
        let point = |j: usize| if j < n { j } else { (j - n) / nt };
        let dw = (0..m * m).map(|e| (op.compliance[e] * pts.weight[point(e % m)]).powi(2)).sum::<f64>().sqrt();
        let pressure = newton.lambda.normal.iter().chain(&gs.lambda.normal).fold(0.0f64, |a, b| a.max(*b));
        let lipschitz = dw * pressure * (law.static_coefficient - law.dynamic_coefficient) / law.slip_length;
        if lipschitz < 0.5 {
            let scale = newton.lambda.norm().max(1e-12);
            prop_assert!(gs.lambda.minus(&newton.lambda).norm() <= 1e-7 * scale, "{lipschitz}: {:?} {:?}", gs.lambda, newton.lambda);
        }
    }

    /// Each point its own friction law: Tresca's bound at some points (`ContactPoints::tresca`),
    /// Coulomb's coefficient at the others, under Coulomb's law. Newton's answer meets each
    /// point's law, and is the answer of Tresca's law (unique: a strictly convex problem) with
    /// the bounds `S_i` of the Tresca points and `F_i λ_n,i` of the others, the fixed point's
    /// identity; block Gauss-Seidel takes the mixed points too and meets the same laws.
    #[test]
    fn tresca_points_beside_coulomb_points_meet_each_their_law(n in 2usize..=5, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), mu in 0.05f64..0.5, bound in 0.0f64..0.2, mask in 1u32..31) {
        let nt = dim - 1;
        let mut pts = points(n, dim, &w, mu);
        pts.tresca = (0..n).map(|i| (mask & (1 << i) != 0).then_some(bound)).collect();
        for i in 0..n {
            if pts.tresca[i].is_some() {
                pts.friction[i] = 0.0;
            }
        }
        let op = problem(n, nt, &pts, &seed, &load);
        let params = NewtonParams { tol: 1e-13, ..Default::default() };
        let newton = solve_newton(&mut op.clone(), &pts, &Law::Coulomb, &params, None, &mut |_| {});
        prop_assume!(newton.is_ok()); // Coulomb's law may stall Newton: its own tests
        let newton = newton.unwrap();
        let gs = contact::GaussSeidelParams { tol: 1e-12, max_sweeps: 20000, ..Default::default() };
        let sweeps = contact::solve_gauss_seidel(&mut op.clone(), &pts, &Law::Coulomb, &gs, None, &mut |_| {});
        for sol in std::iter::once(&newton).chain(sweeps.as_ref().ok()) {
            let scale = sol.lambda.norm().max(1e-12);
            for i in 0..n {
                let (lt, ln, s) = (sol.lambda.tangential_norm(i), sol.lambda.normal[i], sol.u.tangential_norm(i));
                let radius = pts.tresca[i].unwrap_or(mu * ln.max(0.0));
                prop_assert!(lt <= radius * (1.0 + 1e-8) + 1e-9 * scale, "point {i}: |λ_t| {lt} above {radius}");
                if s > 1e-8 * (1.0 + sol.u.norm()) {
                    prop_assert!((lt - radius).abs() <= 1e-7 * scale, "point {i} slides: |λ_t| {lt}, radius {radius}");
                }
            }
        }
        let radii: Vec<f64> = (0..n).map(|i| pts.tresca[i].unwrap_or(mu * newton.lambda.normal[i].max(0.0))).collect();
        let plain = ContactPoints { tresca: vec![], ..pts.clone() };
        let tresca = solve_newton(&mut op.clone(), &plain, &Law::Tresca(radii), &params, None, &mut |_| {}).unwrap();
        let scale = newton.lambda.norm().max(1e-12);
        prop_assert!(tresca.lambda.minus(&newton.lambda).norm() <= 1e-7 * scale, "{:?} against {:?}", tresca.lambda, newton.lambda);
    }

    /// Tiny frictionless problems: Uzawa's answer equals the one found by enumerating the
    /// 2^n active sets (the KKT point of a strictly convex QP is unique).
    #[test]
    fn uzawa_matches_active_set_enumeration(n in 1usize..=4, seed in prop::collection::vec(-1.0f64..1.0, 40), w in prop::collection::vec(-1.0f64..1.0, 4), load in prop::collection::vec(-1.0f64..1.0, 12)) {
        let pts = points(n, 2, &w, 0.0);
        let mut op = problem(n, 0, &pts, &seed, &load);
        let sol = solve_uzawa(&mut op, &pts, &Law::Frictionless, &tight(1e-12), None, &mut |_| {}).unwrap();
        // enumeration: u = u0 - D W λ; on the active set u_n = g (= 0)
        let d = DMatrix::from_row_slice(n, n, &op.compliance);
        let mut found = None;
        for mask in 0u32..(1 << n) {
            let act: Vec<usize> = (0..n).filter(|i| mask & (1 << i) != 0).collect();
            let mut lam = vec![0.0; n];
            if !act.is_empty() {
                let k = act.len();
                let a = DMatrix::from_fn(k, k, |r, c| d[(act[r], act[c])] * pts.weight[act[c]]);
                let b = DVector::from_fn(k, |r, _| op.u0.normal[act[r]]);
                let x = a.lu().solve(&b).unwrap();
                for (r, &i) in act.iter().enumerate() { lam[i] = x[r]; }
            }
            let u: Vec<f64> = (0..n).map(|i| op.u0.normal[i] - (0..n).map(|j| d[(i, j)] * pts.weight[j] * lam[j]).sum::<f64>()).collect();
            let ok = lam.iter().all(|&l| l >= -1e-12) && (0..n).all(|i| act.contains(&i) || u[i] <= 1e-12);
            if ok { found = Some(lam); break; }
        }
        let exact = found.expect("some active set satisfies the KKT conditions");
        // the solver's residual is relative to the larger of |λ| and the problem's multiplier
        // scale `|u0 - g|_W / μ_max` (complementarity_residual): a contact carrying a tiny force
        // beside a large separated load is accurate to that scale, not to its own force
        let u0_scale = (0..n).map(|i| pts.weight[i] * op.u0.normal[i].powi(2)).sum::<f64>().sqrt() / sol.info.mu_max;
        let scale = exact.iter().fold(1e-12f64, |m, x| m.max(x.abs())).max(u0_scale);
        for i in 0..n {
            prop_assert!((sol.lambda.normal[i] - exact[i]).abs() <= 1e-8 * scale, "{:?} vs {:?}", sol.lambda.normal, exact);
        }
    }

    /// With friction (Tresca and Coulomb, 2D and 3D), the answer satisfies the KKT conditions:
    /// λ_n ≥ 0, u_n ≤ g, λ_n (u_n - g) = 0, |λ_t| ≤ S, u_t = 0 where |λ_t| < S, and
    /// u_t = α λ_t with α ≥ 0 where |λ_t| = S.
    #[test]
    fn uzawa_answer_satisfies_kkt(n in 1usize..=5, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), f in 0.05f64..0.5, coulomb in proptest::bool::ANY) {
        let nt = dim - 1;
        let pts = points(n, dim, &w, f);
        let mut op = problem(n, nt, &pts, &seed, &load);
        let law = if coulomb { Law::Coulomb } else { Law::Tresca(vec![0.1; n]) };
        let sol = solve_uzawa(&mut op, &pts, &law, &tight(1e-11), None, &mut |_| {}).unwrap();
        let (l, u) = (&sol.lambda, &sol.u);
        // the residual's denominator: ‖λ‖, floored at the multipliers of the free motion
        // c ‖u(0) - g‖ (c = 1/μ_max), so that round-off of a small λ is no failure; a load
        // that mostly slides the points off (λ a thousandth of that scale) is resolved to the
        // floor's 1e-11 (found by this test: a sliding point 1e-11 inside its disc)
        let floor = op.u0.norm() / sol.info.mu_max;
        let scale_l = l.norm().max(floor).max(1e-12);
        let scale_u = u.norm().max(op.u0.norm()).max(1e-12);
        for i in 0..n {
            let s = if coulomb { f * l.normal[i] } else { 0.1 };
            prop_assert!(l.normal[i] >= 0.0);
            prop_assert!(u.normal[i] <= 1e-7 * scale_u);
            prop_assert!((l.normal[i] * u.normal[i]).abs() <= 1e-7 * scale_l * scale_u);
            // a point whose pressure is round-off (docs/theory.md: λ_n ≤ 1e-9 max λ_n) is separated:
            // it may slide freely
            if l.normal[i] <= 1e-9 * l.normal.iter().cloned().fold(0.0, f64::max) {
                continue;
            }
            let lt: Vec<f64> = (0..nt).map(|k| l.tangential[i * nt + k]).collect();
            let ut: Vec<f64> = (0..nt).map(|k| u.tangential[i * nt + k]).collect();
            let nl = lt.iter().map(|x| x * x).sum::<f64>().sqrt();
            let nu = ut.iter().map(|x| x * x).sum::<f64>().sqrt();
            // in the disc up to what a complementarity residual of 1e-11 allows (relative to ‖λ‖)
            prop_assert!(nl <= s * (1.0 + 1e-9) + 1e-8 * scale_l, "{nl} > {s}");
            // stick, judged with the residual's absolute resolution (tol ‖λ‖): a point of small
            // pressure on the edge of its disc is sliding even if |λ_t| / S is 1 - 1e-5
            if nl < s - 1e-8 * scale_l {
                prop_assert!(nu <= 1e-7 * scale_u, "stick point moves: {nu}");
            } else if nu > 1e-7 * scale_u {
                let dot: f64 = lt.iter().zip(&ut).map(|(a, b)| a * b).sum();
                prop_assert!(dot >= (1.0 - 1e-5) * nl * nu, "slip not along lambda_t");
            }
        }
    }

    /// The accelerated projected gradient (FISTA with restart) reaches the KKT point plain
    /// Uzawa reaches, with Tresca and Coulomb friction in 2D and 3D.
    #[test]
    fn accelerated_and_plain_uzawa_agree(n in 1usize..=5, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), f in 0.05f64..0.5, coulomb in proptest::bool::ANY) {
        let nt = dim - 1;
        let pts = points(n, dim, &w, f);
        let law = if coulomb { Law::Coulomb } else { Law::Tresca(vec![0.1; n]) };
        let mut op1 = problem(n, nt, &pts, &seed, &load);
        let mut op2 = op1.clone();
        let plain = solve_uzawa(&mut op1, &pts, &law, &tight(1e-12), None, &mut |_| {}).unwrap();
        let fast = solve_uzawa(&mut op2, &pts, &law, &UzawaParams { accelerate: true, ..tight(1e-12) }, None, &mut |_| {}).unwrap();
        let scale = plain.lambda.norm().max(op1.u0.norm());
        let d = plain.lambda.minus(&fast.lambda).norm();
        prop_assert!(d <= 1e-8 * scale.max(1e-12), "difference {d} (scale {scale})");
        prop_assert!(fast.info.complementarity <= 1e-12);
    }

    /// Semismooth Newton (without its fallback) reaches the KKT point plain Uzawa reaches:
    /// frictionless, Tresca and Coulomb (solved directly, no fixed point), in 2D and 3D.
    #[test]
    fn newton_and_uzawa_agree(n in 1usize..=6, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 6), load in prop::collection::vec(-1.0f64..1.0, 18), f in 0.05f64..0.5, law in 0usize..3) {
        let pts = points(n, dim, &w, f);
        let (law, nt) = match law {
            0 => (Law::Frictionless, 0),
            1 => (Law::Tresca(vec![0.1; n]), dim - 1),
            _ => (Law::Coulomb, dim - 1),
        };
        let mut op1 = problem(n, nt, &pts, &seed, &load);
        let mut op2 = op1.clone();
        let plain = solve_uzawa(&mut op1, &pts, &law, &tight(1e-12), None, &mut |_| {}).unwrap();
        let params = NewtonParams { tol: 1e-12, schedule: Schedule::all().without(Phase::Fallback), ..Default::default() };
        let newton = solve_newton(&mut op2, &pts, &law, &params, None, &mut |_| {}).unwrap();
        let scale = plain.lambda.norm().max(op1.u0.norm());
        let d = plain.lambda.minus(&newton.lambda).norm();
        prop_assert!(d <= 1e-8 * scale.max(1e-12), "difference {d} (scale {scale})");
        prop_assert!(newton.info.complementarity <= 1e-12);
        prop_assert!(newton.info.newton_iters <= 30, "{} Newton steps", newton.info.newton_iters);
        // the same status, but at a degenerate point (on the edge of its disc, or touching with
        // no pressure, to the resolution of the tolerance) where either answer is right
        let l = &newton.lambda;
        for i in 0..n {
            if newton.status[i] != plain.status[i] {
                let edge = match &law {
                    Law::Frictionless => f64::INFINITY,
                    Law::Tresca(s) => s[i],
                    Law::Coulomb => f * l.normal[i],
                };
                let lt = (0..nt).map(|k| l.tangential[i * nt + k].powi(2)).sum::<f64>().sqrt();
                let degenerate = (lt - edge).abs() <= 1e-7 * scale || l.normal[i] <= 1e-7 * scale;
                prop_assert!(degenerate, "point {}: {:?} against Uzawa's {:?}", i, newton.status[i], plain.status[i]);
            }
        }
    }

    /// The fixed point S -> F λ_n(S) contracts for small F: the ratio of successive differences
    /// stays below 1.
    #[test]
    fn friction_fixed_point_contracts(n in 2usize..=5, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(0.2f64..1.0, 15), f in 0.05f64..0.3) {
        let pts = points(n, 2, &w, f);
        let mut op = problem(n, 1, &pts, &seed, &load);
        let mut s = vec![0.0; n];
        let mut diffs = vec![];
        for _ in 0..4 {
            let sol = solve_uzawa(&mut op, &pts, &Law::Tresca(s.clone()), &tight(1e-13), None, &mut |_| {}).unwrap();
            let s_new: Vec<f64> = sol.lambda.normal.iter().map(|l| f * l).collect();
            diffs.push(s_new.iter().zip(&s).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt());
            s = s_new;
        }
        for k in 1..diffs.len() {
            if diffs[k - 1] > 1e-9 * diffs[0] {
                let ratio = diffs[k] / diffs[k - 1];
                prop_assert!(ratio < 1.0, "contraction ratio {ratio} at step {k} (F = {f})");
            }
        }
    }

    /// With g = 0 every datum is proportional to the load, so the solution is too.
    #[test]
    fn solution_is_homogeneous_in_the_load(n in 1usize..=4, seed in prop::collection::vec(-1.0f64..1.0, 40), w in prop::collection::vec(-1.0f64..1.0, 4), load in prop::collection::vec(-1.0f64..1.0, 12), alpha in 0.1f64..10.0) {
        let pts = points(n, 2, &w, 0.3);
        let mut op1 = problem(n, 1, &pts, &seed, &load);
        let scaled: Vec<f64> = load.iter().map(|x| alpha * x).collect();
        let mut op2 = problem(n, 1, &pts, &seed, &scaled);
        let s1 = solve_uzawa(&mut op1, &pts, &Law::Coulomb, &tight(1e-12), None, &mut |_| {}).unwrap();
        let s2 = solve_uzawa(&mut op2, &pts, &Law::Coulomb, &tight(1e-12), None, &mut |_| {}).unwrap();
        let scale = s1.lambda.norm().max(1e-12);
        for (a, b) in s1.lambda.normal.iter().chain(&s1.lambda.tangential).zip(s2.lambda.normal.iter().chain(&s2.lambda.tangential)) {
            prop_assert!((alpha * a - b).abs() <= 1e-7 * alpha * scale);
        }
        prop_assert_eq!(s1.status, s2.status);
    }
}

#[test]
fn residual_is_zero_at_a_solution_and_scale_free() {
    let pts = points(1, 2, &[0.5], 0.0);
    let lambda = PointValues::from_parts(vec![2.0], vec![], 0).unwrap();
    let u = PointValues::from_parts(vec![0.0], vec![], 0).unwrap();
    assert_eq!(complementarity_residual(&pts, &[0.0], &lambda, &u, 1.0, 0.0), 0.0);
    // penetration of 1 with λ = 2: residual |2 - (2 + c)| / 2 = c / 2
    let u = PointValues::from_parts(vec![1.0], vec![], 0).unwrap();
    assert!((complementarity_residual(&pts, &[0.0], &lambda, &u, 0.5, 0.0) - 0.25).abs() < 1e-15);
    // the reference floors the denominator: with ‖λ‖_W = 2 sqrt(0.5) below it, it is used
    let r = complementarity_residual(&pts, &[0.0], &lambda, &u, 0.5, 10.0);
    assert!((r - 0.5 / 10.0).abs() < 1e-15, "{r}"); // weight 1 (see `points`)
}

#[test]
fn non_convergence_is_a_typed_error_with_the_residual() {
    let pts = points(2, 2, &[0.5, 0.5], 0.3);
    let mut op = problem(2, 1, &pts, &[0.3, -0.2, 0.5, 0.1], &[1.0, 0.5, 0.2, -0.1]);
    let params = UzawaParams {
        max_iters: 2,
        ..tight(1e-14)
    };
    match solve_uzawa(&mut op, &pts, &Law::Coulomb, &params, None, &mut |_| {}) {
        Err(contact::ContactError::NoConvergence { residual, .. }) => assert!(residual > 1e-14),
        other => panic!("{other:?}"),
    }
}

/// Found by the property test (3000 cases): a 2x2 dual operator whose lower eigenvector is
/// (W-)parallel to a constant vector. A power iteration started there estimated the lower
/// eigenvalue, the step exceeded 2/μ_max and Uzawa cycled at a residual of 0.65. Both points
/// are in contact: λ = (D W)⁻¹ u0.
#[test]
fn regression_power_iteration_sees_the_top_eigenvalue() {
    let d = vec![
        0.6052426855451863,
        -0.04304387242789706,
        -0.04304387242789706,
        0.7235217446426216,
    ];
    let w = vec![1.196450878607202, 1.010716700710865];
    let mut pts = points(2, 2, &[0.0, 0.0], 0.0);
    pts.weight = w.clone();
    let u0 = [0.0, 0.856966981224736];
    let mut op = DenseContactProblem {
        u0: PointValues::from_parts(u0.to_vec(), vec![], 0).unwrap(),
        compliance: d.clone(),
        weight: w.clone(),
        nt: 0,
    };
    let sol = solve_uzawa(&mut op, &pts, &Law::Frictionless, &tight(1e-12), None, &mut |_| {}).unwrap();
    let a = DMatrix::from_fn(2, 2, |i, j| d[i * 2 + j] * w[j]);
    let exact = a.lu().solve(&DVector::from_row_slice(&u0)).unwrap();
    for i in 0..2 {
        assert!(
            (sol.lambda.normal[i] - exact[i]).abs() < 1e-9 * exact.amax(),
            "{:?} vs {exact}",
            sol.lambda.normal
        );
    }
    // the top eigenvalue of W^½ D W^½ is 0.7752 (by hand); the step must stay below 2 / 0.7752
    assert!(
        sol.info.step.is_some_and(|r| r < 2.0 / 0.7752),
        "step {:?} from mu_max estimate {}",
        sol.info.step,
        sol.info.mu_max
    );
}

/// Found by the property test: a Coulomb point of small pressure (3.4e-7 against 1.3) on the edge
/// of its disc slides (u_t along λ_t) although |λ_t| / F λ_n = 1 - 2e-5: the residual resolves λ
/// to tol ‖λ‖, not to tol F λ_n. The answer meets the KKT conditions at that resolution.
#[test]
fn regression_grazing_coulomb_point() {
    let seed: Vec<f64> = vec![
        0.008925409187059892,
        0.13227518050516598,
        0.8707524604043606,
        -0.022627715842901807,
        -0.47149587672179966,
        -0.7043758036018389,
        0.4435082149136713,
        0.29963004667594056,
        0.5190722930258421,
        -0.752358219206777,
        -0.7018195232643204,
        0.0,
        -0.9515232386680026,
        0.8097213651473112,
        0.0,
        -0.4811199022853766,
        0.6299617333308923,
        0.0,
        0.660792981027592,
        0.12090628157906223,
        0.0,
        0.5756706978078774,
        0.5972992928677556,
        0.0,
        -0.9837888128453111,
        -0.2392789739363984,
        0.0,
        -0.7847400409699141,
        0.6794219612350854,
        0.0,
        0.15582497231643924,
        -0.38919804112025363,
        0.0,
        -0.9369706721915753,
        0.7317847233991839,
        -0.9659484378074485,
        0.05767879097733943,
        0.12663952171002513,
        0.4773599184895834,
        -0.9073322692477119,
        0.12385733587629011,
        -0.7283862997742543,
        0.13836049798703917,
        -0.39914763275688453,
        -0.27372093825661564,
        0.9707698539301293,
        0.4208671242242073,
        0.2824271261005917,
        -0.5699955674861195,
        -0.2614376391710398,
        -0.41756337674461314,
        -0.8927331667502518,
        0.1513193852755074,
        0.23442066852724536,
        -0.4393588522353138,
        -0.15047829874485924,
        -0.9311842421085919,
        0.9584240544589223,
        -0.17193582960254855,
        0.05481265867094484,
    ];
    let load = [
        0.2945922197174039,
        0.11793010988799946,
        -0.9829798561918247,
        -0.05772934162347857,
        0.4908103017564955,
        0.3249021202676558,
        -0.6389783250959045,
        0.30156146591879235,
        0.0,
        0.0,
        0.0,
        0.0,
    ];
    let f = 0.2439128030433884;
    let pts = points(4, 3, &[0.0; 4], f);
    let mut op = problem(4, 2, &pts, &seed, &load);
    let sol = solve_uzawa(&mut op, &pts, &Law::Coulomb, &tight(1e-11), None, &mut |_| {}).unwrap();
    assert!(sol.info.complementarity <= 1e-11);
    // point 3: in contact with a small pressure, sliding along λ_t
    let (l, u) = (&sol.lambda, &sol.u);
    assert!(l.normal[3] > 1e-8 && l.normal[3] < 1e-6);
    let dot = l.tangential[6] * u.tangential[6] + l.tangential[7] * u.tangential[7];
    let nl = (l.tangential[6].powi(2) + l.tangential[7].powi(2)).sqrt();
    let nu = (u.tangential[6].powi(2) + u.tangential[7].powi(2)).sqrt();
    assert!(dot >= (1.0 - 1e-5) * nl * nu);
    assert!((nl - f * l.normal[3]).abs() <= 1e-8 * l.norm());
}

/// Where Newton stops short (here: no step allowed), the accelerated gradient finishes the
/// solve from where it stopped and says so; with the fallback off, the stall is a typed error
/// naming its cause.
#[test]
fn newton_falls_back_on_the_accelerated_gradient() {
    let seed: Vec<f64> = (0..40).map(|i| ((i * 37 % 17) as f64 / 8.5) - 1.0).collect();
    let pts = points(4, 3, &[0.3, -0.2, 0.9, 0.1], 0.3);
    let load = [0.8, 0.5, 0.9, 0.2, 0.3, -0.4, 0.1, 0.6, -0.2, 0.5, 0.4, -0.1];
    let mut op = problem(4, 2, &pts, &seed, &load);
    let reference = solve_newton(
        &mut op.clone(),
        &pts,
        &Law::Coulomb,
        &NewtonParams {
            tol: 1e-12,
            ..Default::default()
        },
        None,
        &mut |_| {},
    )
    .unwrap();
    assert!(!reference.info.fallback);
    let none = NewtonParams {
        tol: 1e-12,
        max_iters: 0,
        max_proximal: 0,
        ..Default::default()
    };
    let sol = solve_newton(&mut op, &pts, &Law::Coulomb, &none, None, &mut |_| {}).unwrap();
    assert!(sol.info.fallback && sol.info.newton_iters == 0 && sol.info.sweeps > 0);
    assert!(sol.info.complementarity <= 1e-12);
    let d = sol.lambda.minus(&reference.lambda).norm();
    assert!(d <= 1e-8 * reference.lambda.norm(), "{d}");
    let e = solve_newton(
        &mut op,
        &pts,
        &Law::Coulomb,
        &NewtonParams {
            schedule: none.schedule.without(Phase::Fallback),
            ..none
        },
        None,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(
        matches!(
            &e,
            contact::ContactError::Stalled {
                reason: contact::Stall::IterationLimit,
                best: Some(_),
                ..
            }
        ),
        "{e}"
    );
}

/// Homogeneity over the whole range of `f64`: with the gap 0, the contact problem with the loads
/// scaled by `s` has the solution scaled by `s` (the laws are positively homogeneous), so the
/// solvers must return `s λ(1)` with the same statuses and iteration counts, for `s` from 1e-300
/// to 1e300. Norms whose squares overflow or underflow (1e±150 and beyond) once made the
/// projection onto the disc return 0 (a Coulomb problem solved as a frictionless one), and the
/// power iteration see a zero eigenvalue where the loads dwarfed the unit multipliers.
#[test]
fn solutions_scale_with_the_data_over_the_whole_range() {
    for dim in [2, 3] {
        let (n, nt) = (6, dim - 1);
        let seed: Vec<f64> = (0..40).map(|k| ((k * 37 % 17) as f64 - 8.0) / 9.0).collect();
        let pts = points(n, dim, &seed, 0.4);
        let load: Vec<f64> = (0..n * (1 + nt))
            .map(|k| {
                if k < n {
                    1.0 + 0.1 * k as f64
                } else {
                    0.3 * (k as f64).sin()
                }
            })
            .collect();
        let reference = {
            let mut p = problem(n, nt, &pts, &seed, &load);
            solve_newton(&mut p, &pts, &Law::Coulomb, &NewtonParams::default(), None, &mut |_| {}).unwrap()
        };
        for s in [1e-300, 1e-200, 1e-150, 1e-100, 1e100, 1e150, 1e200, 1e300] {
            let scaled: Vec<f64> = load.iter().map(|x| x * s).collect();
            let mut p = problem(n, nt, &pts, &seed, &scaled);
            let newton = solve_newton(&mut p, &pts, &Law::Coulomb, &NewtonParams::default(), None, &mut |_| {})
                .unwrap_or_else(|e| panic!("{dim}D, s = {s:e}: {e}"));
            let mut p = problem(n, nt, &pts, &seed, &scaled);
            let apg = UzawaParams {
                accelerate: true,
                ..tight(1e-12)
            };
            let first_order = solve_uzawa(&mut p, &pts, &Law::Coulomb, &apg, None, &mut |_| {})
                .unwrap_or_else(|e| panic!("{dim}D, s = {s:e}: {e}"));
            for (what, sol) in [("Newton", &newton), ("APG", &first_order)] {
                assert_eq!(sol.status, reference.status, "{what} {dim}D, s = {s:e}");
                let lambda = sol.lambda.normal.iter().chain(&sol.lambda.tangential);
                let expected = reference.lambda.normal.iter().chain(&reference.lambda.tangential);
                for (a, b) in lambda.zip(expected) {
                    assert!(
                        (a / s - b).abs() <= 1e-8 * reference.lambda.norm(),
                        "{what} {dim}D, s = {s:e}: {a:e} vs {b}"
                    );
                }
            }
            assert!(!newton.info.fallback, "{dim}D, s = {s:e}: Newton fell back");
            assert_eq!(
                newton.info.newton_iters, reference.info.newton_iters,
                "{dim}D, s = {s:e}"
            );
        }
    }
}

/// A stall is not a divergence: a step far too small makes no progress (the residual never
/// rises) and ends as `Stalled`; a step far too large makes the residual grow and ends as
/// `Diverged`. Neither is reported where the residual meets the tolerance.
#[test]
fn stalls_and_divergences_are_told_apart() {
    let seed: Vec<f64> = (0..40).map(|i| ((i * 37 % 17) as f64 / 8.5) - 1.0).collect();
    let pts = points(4, 2, &[0.3, -0.2, 0.9, 0.1], 0.0);
    let load = [0.8, 0.5, 0.9, 0.2, 0.3, -0.4, 0.1, 0.6];
    let op = problem(4, 0, &pts, &seed, &load);
    let run = |step: f64| {
        let params = UzawaParams {
            step: Some(step),
            max_iters: 1_000_000,
            ..tight(1e-12)
        };
        solve_uzawa(&mut op.clone(), &pts, &Law::Frictionless, &params, None, &mut |_| {})
    };
    let e = run(1e-14).unwrap_err();
    assert!(matches!(e, ContactError::Stalled { best: Some(_), .. }), "{e}");
    let e = run(1e6).unwrap_err();
    assert!(matches!(e, ContactError::Diverged { .. }), "{e}");
    assert!(run(0.5).is_ok());
}

/// Past uniqueness, a failed solve says so: one 2D point whose normal and tangential
/// compliances are coupled (`D = [[1, 0.9], [0.9, 1]]`), pressed and pulled, with `F = 2`. At
/// a sliding point the Tresca pressure moves with the bound by `∓0.9`, so the fixed point on
/// `S` expands by `F 0.9 = 1.8`; with every stage of Newton switched off the error is
/// `NotUnique` with that expansion (measured), where `F = 0.5` gives `0.45` and the plain stall.
#[test]
fn a_stall_past_uniqueness_is_diagnosed() {
    for (f, expect_not_unique) in [(2.0, true), (0.5, false)] {
        let mut pts = points(1, 2, &[0.5], f);
        pts.weight = vec![1.0];
        let mut op = DenseContactProblem {
            u0: PointValues::from_parts(vec![1.0], vec![0.5], 1).unwrap(),
            compliance: vec![1.0, 0.9, 0.9, 1.0],
            weight: vec![1.0],
            nt: 1,
        };
        let expansion = contact::slip_bound_expansion(
            &mut op.clone(),
            &pts,
            &PointValues::from_parts(vec![0.5], vec![0.4], 1).unwrap(),
            &contact::Interrupt::NONE,
        )
        .unwrap();
        assert!((expansion - 0.9 * f).abs() < 1e-6, "F {f}: {expansion}");
        let params = NewtonParams {
            tol: 1e-12,
            max_iters: 0,
            max_proximal: 0,
            schedule: Schedule::all().without(Phase::Fallback),
            ..Default::default()
        };
        let e = solve_newton(&mut op, &pts, &Law::Coulomb, &params, None, &mut |_| {}).unwrap_err();
        if expect_not_unique {
            assert!(
                matches!(e, ContactError::NotUnique { expansion, .. } if (expansion - 1.8).abs() < 1e-6),
                "{e}"
            );
            assert!(e.to_string().contains("uniqueness"), "{e}");
        } else {
            assert!(matches!(e, ContactError::Stalled { .. }), "{e}");
        }
    }
}

/// The compliance of a problem whose held directions move with no force: their rows and columns
/// of `D` zero, as the condensation of a body whose support holds those components gives, with
/// `u0` there the prescribed value.
fn held_problem(op: &DenseContactProblem, pts: &ContactPoints) -> DenseContactProblem {
    let (n, nt) = (pts.len(), op.nt);
    let m = n * (1 + nt);
    let held = |r: usize| r >= n && pts.is_held((r - n) / nt, (r - n) % nt);
    let mut out = op.clone();
    for r in 0..m {
        for c in 0..m {
            if held(r) || held(c) {
                out.compliance[r * m + c] = 0.0;
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// A tangential direction held by a support carries no multiplier, and the law acts in the
    /// others: in 2D a held tangent is a frictionless point (the same answer as `F = 0` there);
    /// in 3D, Newton, Gauss–Seidel and Uzawa agree, every held multiplier is exactly 0, and
    /// Coulomb's law holds in the free direction (stick: `u_t = 0` there; slip: `λ_t` along
    /// `u_t` at `F λ_n`).
    #[test]
    fn held_directions_carry_no_multiplier(n in 2usize..=5, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 5), load in prop::collection::vec(-1.0f64..1.0, 15), mask in prop::collection::vec(0u8..4, 5), f in 0.05f64..0.4) {
        // 2D: held ⇔ frictionless at that point
        let mut pts = points(n, 2, &w, f);
        for i in 0..n {
            pts.held[i][0] = mask[i] & 1 == 1;
        }
        let op = held_problem(&problem(n, 1, &pts, &seed, &load), &pts);
        let params = NewtonParams { tol: 1e-13, ..Default::default() };
        let held = solve_newton(&mut op.clone(), &pts, &Law::Coulomb, &params, None, &mut |_| {}).unwrap();
        let mut free = pts.clone();
        for i in 0..n {
            if free.held[i][0] {
                free.held[i][0] = false;
                free.friction[i] = 0.0;
            }
        }
        let frictionless = solve_newton(&mut op.clone(), &free, &Law::Coulomb, &params, None, &mut |_| {}).unwrap();
        let d = held.lambda.minus(&frictionless.lambda).norm();
        prop_assert!(d <= 1e-9 * held.lambda.norm().max(1e-300), "2D: {d}");
        // 3D, any mask of the two tangents
        let mut pts = points(n, 3, &w, f);
        for i in 0..n {
            pts.held[i] = [mask[i] & 1 == 1, mask[i] & 2 == 2];
        }
        let op = held_problem(&problem(n, 2, &pts, &seed, &load), &pts);
        let newton = solve_newton(&mut op.clone(), &pts, &Law::Coulomb, &params, None, &mut |_| {}).unwrap();
        let gs = solve_gauss_seidel(&mut op.clone(), &pts, &Law::Coulomb, &GaussSeidelParams { tol: 1e-13, ..Default::default() }, None, &mut |_| {}).unwrap();
        let scale = newton.lambda.norm().max(1e-300);
        prop_assert!(gs.lambda.minus(&newton.lambda).norm() <= 1e-8 * scale);
        let tresca_bound: Vec<f64> = newton.lambda.normal.iter().map(|l| f * l.max(0.0)).collect();
        let uzawa = solve_uzawa(&mut op.clone(), &pts, &Law::Tresca(tresca_bound), &tight(1e-12), None, &mut |_| {}).unwrap();
        prop_assert!(uzawa.lambda.minus(&newton.lambda).norm() <= 1e-7 * scale, "Tresca at Newton's bound");
        for sol in [&newton, &gs, &uzawa] {
            for i in 0..n {
                for q in 0..2 {
                    if pts.held[i][q] {
                        prop_assert_eq!(sol.lambda.tangential[2 * i + q], 0.0);
                    }
                }
            }
        }
        for i in 0..n {
            let (ln, lt, ut) = (newton.lambda.normal[i], newton.lambda.tangential_of(i), newton.u.tangential_of(i));
            let free: Vec<usize> = (0..2).filter(|&q| !pts.held[i][q]).collect();
            let lt_norm = free.iter().map(|&q| lt[q] * lt[q]).sum::<f64>().sqrt();
            let ut_norm = free.iter().map(|&q| ut[q] * ut[q]).sum::<f64>().sqrt();
            prop_assert!(lt_norm <= f * ln * (1.0 + 1e-9) + 1e-12 * scale);
            if ln > 1e-9 * scale && lt_norm < f * ln * (1.0 - 1e-6) {
                prop_assert!(ut_norm <= 1e-8 * (1.0 + scale), "a sticking point slides: {ut_norm}");
            }
            if ut_norm > 1e-8 * (1.0 + scale) {
                for &q in &free {
                    let along = f * ln * ut[q] / ut_norm;
                    prop_assert!((lt[q] - along).abs() <= 1e-7 * (1.0 + scale), "slip direction");
                }
            }
        }
    }
}

/// Slow failures end early (issue 20, class 9): a first-order loop whose measured rate would
/// not reach its target within its limit stops after a few measuring windows with
/// `TooSlow`, not at the limit. (A fixed point that stops improving: tests/accuracy.rs.)
#[test]
fn slow_failures_are_told_early() {
    // a diagonal compliance from 1 down to 1e-5: plain Uzawa gains 2e-5 of the slow mode per
    // step, a million steps to 1e-12 (a fall too slow for the limit, too fast for a stall)
    let n = 6;
    let pts = points(n, 2, &[0.0; 6], 0.0);
    let m = n;
    let mut d = vec![0.0; m * m];
    for i in 0..m {
        d[i * m + i] = 10f64.powf(-5.0 * i as f64 / (m - 1) as f64) / pts.weight[i];
    }
    let mut op = DenseContactProblem {
        u0: PointValues::from_parts(vec![1.0; n], vec![], 0).unwrap(),
        compliance: d,
        weight: pts.weight.clone(),
        nt: 0,
    };
    let params = UzawaParams {
        max_iters: 200_000,
        ..tight(1e-12)
    };
    let e = solve_uzawa(&mut op, &pts, &Law::Frictionless, &params, None, &mut |_| {}).unwrap_err();
    match e {
        ContactError::TooSlow {
            n_iters, needed, limit, ..
        } => {
            assert!(n_iters <= 20_000, "measured early, a tenth of the limit: {n_iters}");
            assert!(needed > limit, "{needed} {limit}");
        }
        other => panic!("{other}"),
    }
}

/// One point, `D W = diag(2, 1)`, pressed by `u0_n = 1`, pulled by `u0_t = -0.5`: it closes
/// with `λ_n = 1/2` and, where `μ/2 < 1/2`, slides by `s = (1 - μ)/2`. With the linear
/// slip-weakening law `μ(s) = μ_s - (μ_s - μ_d) s / L` (`s < L`) the fixed point is
/// `μ* = (μ_s - Δ/(2L)) / (1 - Δ/(2L))`, `Δ = μ_s - μ_d`; the map's slope `Δ/(2L)` is its
/// contraction. Equal coefficients give Coulomb's answer to round-off.
#[test]
fn slip_weakening_on_one_point_is_its_hand_solution() {
    use contact::{solve_slip_weakening, SlipWeakening, Weakening, WeakeningParams};
    let pts = ContactPoints {
        weight: vec![1.0],
        ..points(1, 2, &[0.5], 0.6)
    };
    let op = DenseContactProblem {
        u0: PointValues::from_parts(vec![1.0], vec![-0.5], 1).unwrap(),
        compliance: vec![2.0, 0.0, 0.0, 1.0],
        weight: vec![1.0],
        nt: 1,
    };
    let law = SlipWeakening {
        static_coefficient: 0.6,
        dynamic_coefficient: 0.3,
        slip_length: 1.0,
        form: Weakening::Linear,
    };
    let params = tight_weakening();
    let sol = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(law), &params, &mut |_| {}).unwrap();
    let half_slope = 0.5 * (0.6 - 0.3) / 1.0;
    let mu = (0.6 - half_slope) / (1.0 - half_slope);
    assert!((sol.lambda.normal[0] - 0.5).abs() < 1e-14);
    assert!(
        (sol.lambda.tangential[0] + 0.5 * mu).abs() < 1e-12,
        "{:?} {mu}",
        sol.lambda
    );
    assert!((sol.u.tangential[0] + 0.5 * (1.0 - mu)).abs() < 1e-12);
    let c = sol.info.contraction.unwrap();
    assert!(
        (c - half_slope).abs() < 1e-6,
        "measured contraction {c}, slope {half_slope}"
    );
    // Anderson's mixing: the same (unique) answer, in fewer steps
    let fast = WeakeningParams {
        accelerate: true,
        ..params
    };
    let mixed = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(law), &fast, &mut |_| {}).unwrap();
    assert!((mixed.lambda.tangential[0] - sol.lambda.tangential[0]).abs() < 1e-12);
    assert!(mixed.info.fixed_point_iters <= sol.info.fixed_point_iters);
    // equal coefficients: Coulomb's law itself, to round-off
    let flat = SlipWeakening {
        dynamic_coefficient: 0.6,
        ..law
    };
    let sw = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(flat), &params, &mut |_| {}).unwrap();
    let coulomb = solve_newton(&mut op.clone(), &pts, &Law::Coulomb, &params.newton, None, &mut |_| {}).unwrap();
    assert_eq!(sw.lambda, coulomb.lambda);
    assert_eq!(sw.info.fixed_point_iters, 1);
    // a dynamic coefficient above the static one is refused by a typed error
    let up = SlipWeakening {
        dynamic_coefficient: 0.7,
        ..law
    };
    let e = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(up), &params, &mut |_| {}).unwrap_err();
    assert!(matches!(e, ContactError::Input(_)), "{e}");
    // the exponential form: μ(s) = μ_d + Δ exp(-s/L), its fixed point checked by its equation
    let exp = SlipWeakening {
        form: Weakening::Exponential,
        ..law
    };
    let s = solve_slip_weakening(&mut op.clone(), &pts.with_weakening(exp), &params, &mut |_| {}).unwrap();
    let slip = -s.u.tangential[0];
    let mu = -s.lambda.tangential[0] / 0.5;
    assert!((mu - exp.coefficient(slip)).abs() < 1e-12 && (slip - 0.5 * (1.0 - mu)).abs() < 1e-12);
}

/// Each point its own friction law: beside the weakening point of
/// `slip_weakening_on_one_point_is_its_hand_solution`, an uncoupled point with a constant
/// coefficient `μ = 0.4` (no law of its own) keeps it, and each meets its own hand solution; the
/// solvers that hold coefficients constant refuse points that weaken.
#[test]
fn slip_weakening_acts_only_where_a_point_has_the_law() {
    use contact::{solve_slip_weakening, SlipWeakening, Weakening};
    let mut pts = ContactPoints {
        weight: vec![1.0; 2],
        ..points(2, 2, &[0.5, 0.5], 0.6)
    };
    pts.friction[1] = 0.4;
    let law = SlipWeakening {
        static_coefficient: 0.6,
        dynamic_coefficient: 0.3,
        slip_length: 1.0,
        form: Weakening::Linear,
    };
    pts.weakening = vec![Some(law), None];
    let op = DenseContactProblem {
        u0: PointValues::from_parts(vec![1.0; 2], vec![-0.5; 2], 1).unwrap(),
        compliance: (0..16)
            .map(|k| [2.0, 2.0, 1.0, 1.0][k / 4] * f64::from(k % 5 == 0))
            .collect(),
        weight: vec![1.0; 2],
        nt: 1,
    };
    let params = tight_weakening();
    let sol = solve_slip_weakening(&mut op.clone(), &pts, &params, &mut |_| {}).unwrap();
    let half_slope = 0.5 * (0.6 - 0.3) / 1.0;
    let mu = (0.6 - half_slope) / (1.0 - half_slope);
    for (i, mu) in [(0, mu), (1, 0.4)] {
        assert!((sol.lambda.normal[i] - 0.5).abs() < 1e-14);
        assert!(
            (sol.lambda.tangential[i] + 0.5 * mu).abs() < 1e-12,
            "point {i}: {:?} {mu}",
            sol.lambda
        );
        assert!((sol.u.tangential[i] + 0.5 * (1.0 - mu)).abs() < 1e-12);
    }
    // Newton with constant coefficients, Gauss-Seidel and Uzawa do not take points that weaken
    let e = solve_newton(&mut op.clone(), &pts, &Law::Coulomb, &params.newton, None, &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("solve_slip_weakening solves them"), "{e}");
    let gs = contact::GaussSeidelParams::default();
    let e = contact::solve_gauss_seidel(&mut op.clone(), &pts, &Law::Coulomb, &gs, None, &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("solve_slip_weakening solves them"), "{e}");
    // the points' arrays must agree in length
    pts.weakening.pop();
    assert!(solve_slip_weakening(&mut op.clone(), &pts, &params, &mut |_| {}).is_err());
}

/// Found by the property test in CI: a soft bed (`k ≈ 3.4e-3`, `m ≈ 2.4`) under a tiny load,
/// where the pressure is ~1e-6 and Newton and Gauss-Seidel differed by 1e-7 of it.
#[test]
fn a_soft_superlinear_bed_under_a_tiny_load() {
    let mut seed = vec![0.0; 60];
    seed[7] = 0.4972197135515202;
    seed[10] = -0.09802355838282029;
    seed[13] = -0.7619526124015317;
    seed[22] = -0.9362218703465781;
    seed[31] = 0.4492089711467912;
    let w = [0.0, 0.0, 0.0, 0.0, 0.6633171594469244];
    let mut load = vec![0.0; 15];
    load[1] = 0.033109743152174284;
    load[4] = 0.02050246591287915;
    let (n, dim, f, k, m) = (5, 2, 0.05, 10f64.powf(-2.465224758129356), 2.4004285516157635);
    let mut pts = points(n, dim, &w, f);
    pts.foundation = contact::Foundation::Compliant {
        stiffness: k,
        exponent: m,
    };
    let op = problem(n, dim - 1, &pts, &seed, &load);
    let newton = solve_newton(
        &mut op.clone(),
        &pts,
        &Law::Coulomb,
        &NewtonParams {
            tol: 1e-12,
            ..Default::default()
        },
        None,
        &mut |_| {},
    )
    .unwrap();
    let gs = solve_gauss_seidel(
        &mut op.clone(),
        &pts,
        &Law::Coulomb,
        &GaussSeidelParams {
            tol: 1e-12,
            ..Default::default()
        },
        None,
        &mut |_| {},
    )
    .unwrap();
    for s in [&newton, &gs] {
        let law: Vec<f64> = (0..n)
            .map(|i| s.lambda.normal[i] - k * s.u.normal[i].max(0.0).powf(m))
            .collect();
        eprintln!(
            "lambda {:?}\nu {:?}\nlaw residual {:?}\ninfo {:?}",
            s.lambda.normal, s.u.normal, law, s.info
        );
    }
    let scale = newton.lambda.norm().max(1e-12);
    assert!(
        gs.lambda.minus(&newton.lambda).norm() <= 1e-7 * scale,
        "{:?} {:?}",
        gs.lambda,
        newton.lambda
    );
}

/// A chain of `n` points at spacing `h` along x pressed on the foundation: the compliance of an
/// elastic string on springs (the inverse of a tridiagonal stiffness, per direction), the loads
/// and gaps varying along it, so that stick, slip and separated zones form.
fn chain(n: usize, nt: usize, load: f64, tilt: f64, friction: f64) -> (DenseContactProblem, ContactPoints) {
    let h = 1.0 / n as f64;
    let mut pts = points(n, 1 + nt, &vec![h - 0.5; n], friction);
    for i in 0..n {
        pts.position[i] = [i as f64 * h, 0.0, 0.0];
        pts.gap[i] = 0.02 * ((i as f64 * h - 0.5) * 6.0).powi(2);
    }
    let stiffness = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
        0 => 2.0 / h + h,
        1 => -1.0 / h,
        _ => 0.0,
    });
    let inverse = stiffness.try_inverse().unwrap();
    let m = n * (1 + nt);
    let mut d = vec![0.0; m * m];
    // block per direction: normal rows 0..n, tangential rows n + i nt + k (uncoupled)
    let row = |i: usize, k: usize| if k == 0 { i } else { n + i * nt + (k - 1) };
    for k in 0..=nt {
        for i in 0..n {
            for j in 0..n {
                d[row(i, k) * m + row(j, k)] = inverse[(i, j)] / h;
            }
        }
    }
    let normal = (0..n)
        .map(|i| load * (1.0 + 0.5 * (i as f64 * h * 7.0).sin()))
        .collect();
    let tangential = (0..n * nt).map(|r| tilt * (1.0 + (r as f64 * h * 3.0).cos())).collect();
    let op = DenseContactProblem {
        u0: PointValues::from_parts(normal, tangential, nt).unwrap(),
        compliance: d,
        weight: pts.weight.clone(),
        nt,
    };
    (op, pts)
}

/// The law of a chain of `n` points with `nt` tangential directions: frictionless without
/// them, else Tresca's with the bound `friction / 2` or Coulomb's.
fn chain_law(n: usize, nt: usize, friction: f64, tresca: bool) -> Law {
    match (nt, tresca) {
        (0, _) => Law::Frictionless,
        (_, true) => Law::Tresca(vec![0.5 * friction; n]),
        (_, false) => Law::Coulomb,
    }
}

/// Newton to `tol` on a chain from its nested start and from zero.
fn nested_and_zero(
    op: &DenseContactProblem,
    pts: &ContactPoints,
    law: &Law,
    tol: f64,
) -> (contact::ContactSolution, contact::ContactSolution) {
    let solve_with = |nested_start: bool| {
        let params = NewtonParams {
            tol,
            schedule: if nested_start {
                Schedule::of(ProblemClass::CondensedFe)
            } else {
                Schedule::of(ProblemClass::CondensedFe).without(Phase::NestedStart)
            },
            ..Default::default()
        };
        solve_newton(&mut op.clone(), pts, law, &params, None, &mut |_| {}).unwrap()
    };
    (solve_with(true), solve_with(false))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Newton's nested start (the problem on every other point first) reaches the answer of the
    /// start from zero, on chains long enough to be coarsened, for each law and in 2D and 3D,
    /// in no more steps on the problem itself.
    #[test]
    fn the_nested_start_reaches_the_same_answer(n in 60usize..160, nt in 0usize..=2, load in 0.01f64..0.2, tilt in -0.1f64..0.1, friction in 0.05f64..0.8, tresca in any::<bool>()) {
        let (op, pts) = chain(n, nt, load, tilt, friction);
        let law = chain_law(n, nt, friction, tresca);
        // to 1e-14: to 1e-12 the two answers differed by up to 8e-10 of their size on 3000
        // random chains, and by more than 1e-9 on one (n = 124, 3D Coulomb), whose start from
        // zero stopped at 7e-13 (the compliance's condition number, about 4/h², times the
        // tolerance); to 1e-14 by at most 2e-11 on 9000
        let (nested, zero) = nested_and_zero(&op, &pts, &law, 1e-14);
        prop_assert!(nested.info.coarse_newton_iters > 0);
        prop_assert_eq!(zero.info.coarse_newton_iters, 0);
        // a dense symmetric compliance (a condensed finite-element one): no sweeps first
        prop_assert_eq!(nested.info.uzawa_iters + zero.info.uzawa_iters + nested.info.sweeps + zero.info.sweeps, 0);
        let scale = zero.lambda.norm().max(1e-12);
        prop_assert!(nested.lambda.minus(&zero.lambda).norm() <= 1e-9 * scale, "{:?}\n{:?}", nested.info, zero.info);
        prop_assert!(nested.info.complementarity <= 1e-12);
        // no trap: on 12 000 of these chains the nested start took 7 times fewer steps in all
        // (the_nested_start_saves_steps_on_many_chains), and at most 8 more on one of them
        // (78 against 70, a hard 3D one through the proximal stage); a cycle took 108 against 38
        prop_assert!(nested.info.newton_iters <= 2 * zero.info.newton_iters + 3, "{:?}\n{:?}", nested.info, zero.info);
    }
}

/// A cycle of active sets, found by the property test above: from its nested start, Newton on
/// this 3D Coulomb chain went round the same three active sets every three steps (the norm at
/// 2e-5 in each round, then up to 1e-2), 108 steps in all against 38 from zero. The cycle is
/// told after a few revisits ([`contact::Stall::Cycle`]) and the proximal stage leaves it.
#[test]
fn a_cycle_of_active_sets_is_left() {
    for (n, load, tilt, friction) in [
        (145, 0.1888547998003657, 0.04092033225673486, 0.40578634619728887),
        (113, 0.17709188084864785, -0.04103457779954359, 0.47648700373388914),
    ] {
        let (op, pts) = chain(n, 2, load, tilt, friction);
        let (nested, zero) = nested_and_zero(&op, &pts, &Law::Coulomb, 1e-12);
        let scale = zero.lambda.norm();
        assert!(nested.lambda.minus(&zero.lambda).norm() <= 1e-9 * scale);
        assert!(
            nested.info.newton_iters <= zero.info.newton_iters + 3,
            "{:?}\n{:?}",
            nested.info,
            zero.info
        );
    }
}

/// A warm start that meets the tolerance on changed data is the answer as it is, or, with
/// `refine_start`, the start of Newton steps whose answer follows the change: force control's
/// search for a depth needs the force of each depth, not of the one before.
#[test]
fn a_refined_warm_start_follows_the_data_below_the_tolerance() {
    let (op, mut pts) = chain(80, 1, 0.1, 0.02, 0.3);
    let law = Law::Coulomb;
    let params = NewtonParams {
        tol: 1e-10,
        ..Default::default()
    };
    let first = solve_newton(&mut op.clone(), &pts, &law, &params, None, &mut |_| {}).unwrap();
    // the gaps lowered by far less than the tolerance can see in the multipliers
    pts.gap.iter_mut().for_each(|g| *g -= 1e-11);
    let again = |refine_start: bool| {
        let params = NewtonParams { refine_start, ..params };
        solve_newton(
            &mut op.clone(),
            &pts,
            &law,
            &params,
            Some(first.lambda.clone()),
            &mut |_| {},
        )
        .unwrap()
    };
    let (kept, refined) = (again(false), again(true));
    let exact = solve_newton(
        &mut op.clone(),
        &pts,
        &law,
        &NewtonParams { tol: 1e-14, ..params },
        None,
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(kept.info.newton_iters, 0);
    assert_eq!(kept.lambda, first.lambda);
    assert!(refined.info.newton_iters >= 1);
    let force = |l: &PointValues| l.normal.iter().zip(&pts.weight).map(|(a, w)| a * w).sum::<f64>();
    let f = force(&exact.lambda);
    assert!(
        (force(&refined.lambda) - f).abs() <= 1e-14 * f,
        "{} {}",
        force(&refined.lambda),
        f
    );
    // the start itself is off by more than that
    assert!(
        (force(&first.lambda) - f).abs() > 1e3 * 1e-14 * f,
        "{} {}",
        force(&first.lambda),
        f
    );
}

/// The nested start over many chains of the property test's kind, drawn from a fixed seed:
/// the same answers, each from a coarser problem, in far fewer Newton steps in all.
#[test]
fn the_nested_start_saves_steps_on_many_chains() {
    // xorshift64: a fixed sequence of chains
    let mut seed = 12345u64;
    let mut uniform = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut steps_nested, mut steps_zero) = (0, 0);
    for _ in 0..300 {
        let n = 60 + (uniform() * 100.0) as usize;
        let nt = (uniform() * 3.0) as usize;
        let (load, tilt, friction) = (0.01 + 0.19 * uniform(), -0.1 + 0.2 * uniform(), 0.05 + 0.75 * uniform());
        let law = chain_law(n, nt, friction, uniform() < 0.5);
        let (op, pts) = chain(n, nt, load, tilt, friction);
        let (nested, zero) = nested_and_zero(&op, &pts, &law, 1e-12);
        let what = format!("n = {n}, nt = {nt}, load = {load}, tilt = {tilt}, friction = {friction}, {law:?}");
        assert!(nested.info.coarse_newton_iters > 0, "{what}");
        assert!(
            nested.lambda.minus(&zero.lambda).norm() <= 1e-9 * zero.lambda.norm(),
            "{what}"
        );
        steps_nested += nested.info.newton_iters;
        steps_zero += zero.info.newton_iters;
    }
    // measured: 1250 against 8856 (on 3000 chains: 11 516 against 86 572; 12 170 against
    // 87 495 before the cycle rule and the coarser problems' proximal stage)
    assert!(4 * steps_nested <= steps_zero, "{steps_nested} against {steps_zero}");
}

/// Force control drives the indenter's points alone: of two uncoupled frictionless points
/// (`u = u₀ - λ`, `u₀ = (-1, -0.25)`, gaps 0), the first the indenter's, the second a wall's,
/// the force 2 on the first is carried at the depth 3 (`λ₀ = s - 1`); the wall's gap stays, and
/// its multiplier 0 is not counted. Driving both points, the wall would carry 2.75.
#[test]
fn force_control_drives_only_the_indenters_points() {
    let pts = ContactPoints {
        weight: vec![1.0; 2],
        position: vec![[0.0; 3], [1.0, 0.0, 0.0]],
        ..points(2, 2, &[0.5, 0.5], 0.0)
    };
    let op = DenseContactProblem {
        u0: PointValues::from_parts(vec![-1.0, -0.25], vec![], 0).unwrap(),
        compliance: vec![1.0, 0.0, 0.0, 1.0],
        weight: vec![1.0; 2],
        nt: 0,
    };
    let params = NewtonParams {
        tol: 1e-14,
        ..Default::default()
    };
    let solve = |p: &ContactPoints, start: Option<PointValues>| {
        solve_newton(&mut op.clone(), p, &Law::Frictionless, &params, start, &mut |_| {})
    };
    let mut driven = pts.clone();
    let sol = contact::solve_force_controlled(&mut driven, Some(&[true, false]), 2.0, None, solve).unwrap();
    assert!((sol.lambda.normal[0] - 2.0).abs() < 1e-9 * 2.0, "{:?}", sol.lambda);
    assert_eq!(sol.lambda.normal[1], 0.0);
    assert!(
        (driven.gap[0] + 3.0).abs() < 1e-8 && driven.gap[1] == 0.0,
        "{:?}",
        driven.gap
    );
    // every point driven: the force is shared, each lowered alike
    let mut both = pts.clone();
    let sol = contact::solve_force_controlled(&mut both, None, 2.0, None, solve).unwrap();
    let total = sol.lambda.normal[0] + sol.lambda.normal[1];
    assert!(
        (total - 2.0).abs() < 1e-9 * 2.0 && both.gap[0] == both.gap[1],
        "{:?} {:?}",
        sol.lambda,
        both.gap
    );
}

/// The slip-weakening fixed point's parameters of the hand solutions: its tolerance 1e-13,
/// Newton's 1e-14.
fn tight_weakening() -> contact::WeakeningParams {
    contact::WeakeningParams {
        tol: 1e-13,
        newton: NewtonParams {
            tol: 1e-14,
            ..Default::default()
        },
        ..Default::default()
    }
}

proptest! {
    /// Points that a solution leaves open can be left out of the problem
    /// (`ContactPoints::select`, and the compliance's rows and columns of the rest): its
    /// solution, spread back to every point (`PointValues::spread`), is the whole problem's.
    /// What a run that condenses only the points an indenter can touch rests on.
    #[test]
    fn points_left_open_can_be_left_out(n in 2usize..=6, dim in 2usize..=3, seed in prop::collection::vec(-1.0f64..1.0, 60), w in prop::collection::vec(-1.0f64..1.0, 6), load in prop::collection::vec(-1.0f64..1.0, 18), mask in 0u32..64, f in 0.0f64..0.2) {
        // Signorini, or Coulomb's law with a small coefficient (one solution); not Tresca's,
        // whose bound holds the slip of an open point too
        let pts = points(n, dim, &w, f);
        let (law, nt) = if f < 0.05 { (Law::Frictionless, 0) } else { (Law::Coulomb, dim - 1) };
        let params = NewtonParams { tol: 1e-13, schedule: Schedule::all().without(Phase::Fallback), ..Default::default() };
        let mut whole = problem(n, nt, &pts, &seed, &load);
        let all = solve_newton(&mut whole, &pts, &law, &params, None, &mut |_| {}).unwrap();
        // the points in contact, and some of the open ones
        let keep: Vec<usize> = (0..n).filter(|&i| all.lambda.normal[i] > 0.0 || mask & (1 << i) != 0).collect();
        prop_assume!(!keep.is_empty() && keep.len() < n);
        let sub_pts = pts.select(&keep);
        let rows: Vec<usize> = keep.iter().copied()
            .chain(keep.iter().flat_map(|&i| (0..nt).map(move |q| n + i * nt + q)))
            .collect();
        let m = whole.compliance.len().isqrt();
        let u0: Vec<f64> = rows.iter().map(|&r| if r < n { whole.u0.normal[r] } else { whole.u0.tangential[r - n] }).collect();
        let k = keep.len();
        let mut part = DenseContactProblem {
            u0: PointValues::from_parts(u0[..k].to_vec(), u0[k..].to_vec(), nt).unwrap(),
            compliance: rows.iter().flat_map(|&r| rows.iter().map(move |&c| (r, c))).map(|(r, c)| whole.compliance[r * m + c]).collect(),
            weight: sub_pts.weight.clone(),
            nt,
        };
        let some = solve_newton(&mut part, &sub_pts, &law, &params, None, &mut |_| {}).unwrap();
        let spread = some.lambda.spread(&keep, n);
        let scale = all.lambda.norm().max(whole.u0.norm());
        let d = spread.minus(&all.lambda).norm();
        prop_assert!(d <= 1e-9 * scale.max(1e-12), "difference {d} (scale {scale})");
        for (j, &i) in keep.iter().enumerate() {
            prop_assert_eq!(sub_pts.weight[j], pts.weight[i]);
        }
    }
}
