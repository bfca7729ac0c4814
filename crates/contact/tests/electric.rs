//! Electrical contact on small condensed problems built from a quasi-definite `K` (nalgebra's
//! inverse, not this crate's): the limits σ_c → 0 (insulated) and σ_c → ∞ (conducting), the
//! conditions at the solution checked on `K` itself, and Newton against a fixed point that
//! alternates the mechanical and the electric problems.

use contact::{
    solve_newton, solve_newton_electric, ContactPoints, ContactSolution, DenseContactProblem, ElectricContact,
    ElectricContactProblem, ElectricLaw, Foundation, Law, NewtonParams, PointValues,
};
use nalgebra::{DMatrix, DVector};

/// `n` points on a line, each with a normal (and in 2D one tangential) displacement dof and a
/// potential dof, all of them condensed: `K = [[A, Gᵀ], [G, -B]]` with a stiffness `A` of
/// springs between neighbours and to the ground, a dielectric `B` likewise, a coupling `G`
/// of strength `e`; a load pressing the points into the foundation and a potential applied.
struct Chain {
    n: usize,
    nt: usize,
    k: DMatrix<f64>,
    b: DVector<f64>,
    weight: Vec<f64>,
}

impl Chain {
    fn new(n: usize, nt: usize, e: f64) -> Self {
        let nu = n * (1 + nt);
        let size = nu + n;
        let mut k = DMatrix::zeros(size, size);
        // A: normal and tangential chains
        for c in 0..=nt {
            for i in 0..n {
                let r = c * n + i;
                k[(r, r)] += 2.0 + 0.1 * i as f64;
                if i + 1 < n {
                    k[(r, r + 1)] -= 1.0;
                    k[(r + 1, r)] -= 1.0;
                    k[(r, r)] += 1.0;
                    k[(r + 1, r + 1)] += 1.0;
                }
            }
        }
        // -B: a dielectric chain, of another scale
        for i in 0..n {
            let r = nu + i;
            k[(r, r)] -= 3e-3 * (1.5 + 0.05 * i as f64);
            if i + 1 < n {
                k[(r, r + 1)] += 1e-3;
                k[(r + 1, r)] += 1e-3;
            }
        }
        // G: the potential of point i against the normal motion of i and i+1
        for i in 0..n {
            let r = nu + i;
            for (j, v) in [(i, e), (i + 1, -0.5 * e)] {
                if j < n {
                    k[(r, j)] += v;
                    k[(j, r)] += v;
                }
            }
        }
        let mut b = DVector::zeros(size);
        for i in 0..n {
            // pressed in (u_n > g = 0 without contact) at most points, pulled off at some, and
            // along t
            b[i] = 0.3 + (i as f64 * 1.3).sin();
            if nt > 0 {
                b[n + i] = 0.3;
            }
            // the potential's rows are negated: a charge -q
            b[nu + i] = -2e-3 * (1.0 + 0.2 * i as f64);
        }
        let weight = (0..n).map(|i| 0.5 + 0.05 * i as f64).collect();
        Chain { n, nt, k, b, weight }
    }

    fn points(&self, foundation: Foundation) -> ContactPoints {
        let n = self.n;
        ContactPoints {
            dim: 2,
            position: vec![[0.0; 3]; n],
            normal: vec![[0.0, -1.0, 0.0]; n],
            tangent: vec![[[1.0, 0.0, 0.0], [0.0; 3]]; n],
            weight: self.weight.clone(),
            gap: vec![0.0; n],
            friction: vec![0.4; n],
            held: vec![[false; 2]; n],
            foundation,
            foundations: vec![],
            slipped: vec![],
            weakening: vec![],
            tresca: vec![],
        }
    }

    /// The condensed problem: `D_uu = K⁻¹_uu`, `D_eu = K⁻¹_φu`, `D_ue = -K⁻¹_uφ`,
    /// `D_ee = -K⁻¹_φφ`, the loads' solution `K⁻¹ b`.
    fn problem(&self, law: ElectricLaw, potential: f64) -> ElectricContactProblem {
        let inv = self.k.clone().try_inverse().expect("K is quasi-definite");
        let x0 = &inv * &self.b;
        let nu = self.n * (1 + self.nt);
        let size = nu + self.n;
        let sign = |r: usize, c: usize| match (r >= nu, c >= nu) {
            (false, false) | (true, false) => 1.0,
            _ => -1.0,
        };
        let compliance = (0..size * size)
            .map(|k| {
                let (r, c) = (k / size, k % size);
                sign(r, c) * inv[(r, c)]
            })
            .collect();
        let u0 = PointValues::from_parts(
            x0.rows(0, self.n).iter().copied().collect(),
            x0.rows(self.n, nu - self.n).iter().copied().collect(),
            self.nt,
        )
        .unwrap();
        ElectricContactProblem {
            u0,
            phi0: x0.rows(nu, self.n).iter().copied().collect(),
            compliance,
            weight: self.weight.clone(),
            nt: self.nt,
            electric: ElectricContact {
                law,
                potential,
                points: (0..self.n).collect(),
            },
        }
    }

    /// `[u; φ]` of `K x = b + f` with the forces of the solution: `-W λ` on u, `W q` on φ.
    fn fields(&self, sol: &ContactSolution) -> DVector<f64> {
        let nu = self.n * (1 + self.nt);
        let mut rhs = self.b.clone();
        let e = sol.electric.as_ref().unwrap();
        for i in 0..self.n {
            rhs[i] -= self.weight[i] * sol.lambda.normal[i];
            if self.nt > 0 {
                rhs[self.n + i] -= self.weight[i] * sol.lambda.tangential[i];
            }
            rhs[nu + i] += self.weight[i] * e.flux[i];
        }
        self.k.clone().lu().solve(&rhs).unwrap()
    }
}

fn params() -> NewtonParams {
    NewtonParams {
        tol: 1e-12,
        ..Default::default()
    }
}

fn laws(nt: usize) -> Law {
    if nt == 0 {
        Law::Frictionless
    } else {
        Law::Coulomb
    }
}

/// No conductance is the insulated problem: no flux, the mechanical answer of the problem
/// without electric rows, to round-off.
#[test]
fn no_conductance_is_insulated() {
    for nt in [0, 1] {
        let chain = Chain::new(12, nt, 0.4);
        let points = chain.points(Foundation::Rigid);
        let problem = chain.problem(ElectricLaw::Conductive { conductance: 0.0 }, 0.0);
        let sol = solve_newton_electric(&problem, &points, &laws(nt), &params(), &mut |_| {}).unwrap();
        let mut insulated: DenseContactProblem = problem.insulated();
        let plain = solve_newton(&mut insulated, &points, &laws(nt), &params(), None, &mut |_| {}).unwrap();
        let e = sol.electric.as_ref().unwrap();
        assert!(e.flux.iter().all(|q| *q == 0.0), "{:?}", e.flux);
        let scale = plain.lambda.normal.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for (a, b) in sol.lambda.normal.iter().zip(&plain.lambda.normal) {
            assert!((a - b).abs() <= 1e-10 * scale, "nt {nt}: {a} vs {b}");
        }
        let in_contact = sol.lambda.normal.iter().filter(|l| **l > 0.0).count();
        assert!(
            in_contact > 0 && in_contact < chain.n,
            "a mixed active set: {in_contact}"
        );
    }
}

/// The conditions hold on `K` itself: the conducting foundation's potential at the points in
/// contact and no flux elsewhere; the conductive law's flux at every point; Signorini's
/// conditions; and the conductive answer tends to the conducting one like 1/σ_c.
#[test]
fn conditions_and_the_conducting_limit() {
    for nt in [0, 1] {
        let chain = Chain::new(12, nt, 0.4);
        let points = chain.points(Foundation::Rigid);
        let phi_f = 0.5;
        let conducting = chain.problem(ElectricLaw::Conducting, phi_f);
        let ideal = solve_newton_electric(&conducting, &points, &laws(nt), &params(), &mut |_| {}).unwrap();
        let x = chain.fields(&ideal);
        let nu = chain.n * (1 + nt);
        let e = ideal.electric.as_ref().unwrap();
        let flux_scale = e.flux.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(flux_scale > 0.0);
        let mut touching = 0;
        for i in 0..chain.n {
            let (lambda, u_n, phi) = (ideal.lambda.normal[i], x[i], x[nu + i]);
            assert!(
                lambda >= 0.0 && u_n <= 1e-12 && lambda * u_n.abs() <= 1e-12,
                "{i}: λ {lambda} u_n {u_n}"
            );
            if lambda > 0.0 {
                touching += 1;
                assert!((phi - phi_f).abs() <= 1e-10, "{i} in contact: φ {phi}");
            } else {
                assert!(e.flux[i].abs() <= 1e-12 * flux_scale, "{i} separated: q {}", e.flux[i]);
            }
            assert!((e.potential[i] - phi).abs() <= 1e-9 * phi.abs().max(1.0));
        }
        assert!(touching > 0 && touching < chain.n);
        let mut last = f64::INFINITY;
        for sigma in [1e2, 1e4, 1e6, 1e8, 1e12] {
            let problem = chain.problem(ElectricLaw::Conductive { conductance: sigma }, phi_f);
            let sol = solve_newton_electric(&problem, &points, &laws(nt), &params(), &mut |_| {})
                .unwrap_or_else(|e| panic!("nt {nt} σ {sigma}: {e}"));
            let x = chain.fields(&sol);
            let ev = sol.electric.as_ref().unwrap();
            for i in 0..chain.n {
                // the law at the solution's own potential, which is K's to round-off
                assert!((ev.potential[i] - x[nu + i]).abs() <= 1e-10 * x[nu + i].abs().max(1.0));
                let p = sol.lambda.normal[i].max(0.0);
                let expected = sigma * p * (ev.potential[i] - phi_f);
                // a good conductor fixes φ, and q only to σ p times φ's precision
                let round_off = 1e-10 * sigma * p * (ev.potential[i].abs() + phi_f.abs());
                assert!(
                    (ev.flux[i] - expected).abs() <= 1e-9 * flux_scale + round_off,
                    "σ {sigma} point {i}: q {} vs {expected}",
                    ev.flux[i]
                );
            }
            let diff = sol
                .lambda
                .normal
                .iter()
                .zip(&ideal.lambda.normal)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f64, f64::max);
            // like 1/σ until round-off
            assert!(
                diff <= last.max(1e-9) && diff <= 50.0 / sigma + 1e-9,
                "σ {sigma}: {diff}"
            );
            last = diff;
        }
    }
}

/// Newton on the coupled rows against a fixed point that alternates the two problems: the
/// mechanical one with the flux held (its loads shifted by `-D_ue W q`), and the linear
/// electric one with the pressure held. Both on a rigid and on a compliant foundation.
#[test]
fn newton_agrees_with_the_alternating_fixed_point() {
    for foundation in [
        Foundation::Rigid,
        Foundation::Compliant {
            stiffness: 5.0,
            exponent: 1.5,
        },
    ] {
        let chain = Chain::new(10, 1, 0.1);
        let points = chain.points(foundation);
        let (sigma, phi_f) = (40.0, -0.3);
        let problem = chain.problem(ElectricLaw::Conductive { conductance: sigma }, phi_f);
        let newton = solve_newton_electric(&problem, &points, &Law::Coulomb, &params(), &mut |_| {}).unwrap();
        let (n, m, o) = (chain.n, problem.m(), problem.order());
        let d = |r: usize, c: usize| problem.compliance[r * o + c];
        let w = &chain.weight;
        let mut q = vec![0.0; n];
        let mut lambda = None;
        for _ in 0..200 {
            // mechanics with the flux held
            let mut mech = problem.insulated();
            for r in 0..m {
                let shift: f64 = (0..n).map(|k| d(r, m + k) * w[k] * q[k]).sum();
                if r < n {
                    mech.u0.normal[r] -= shift;
                } else {
                    mech.u0.tangential[r - n] -= shift;
                }
            }
            let sol = solve_newton(
                &mut mech,
                &points,
                &Law::Coulomb,
                &params(),
                lambda.clone(),
                &mut |_| {},
            )
            .unwrap();
            // the electric rows with the pressure held: (I + Σ D_ee W) q = Σ (φ₀ - D_eu W λ - φ_F)
            let p: Vec<f64> = (0..n)
                .map(|i| match foundation {
                    Foundation::Rigid => sol.lambda.normal[i].max(0.0),
                    Foundation::Compliant { .. } => (sol.u.normal[i] - points.gap[i]).max(0.0),
                })
                .collect();
            let flat: Vec<f64> = sol
                .lambda
                .normal
                .iter()
                .chain(&sol.lambda.tangential)
                .copied()
                .collect();
            let wl = |c: usize| flat[c] * w[if c < n { c } else { c - n }];
            let mut a = DMatrix::<f64>::identity(n, n);
            let mut rhs = DVector::<f64>::zeros(n);
            for k in 0..n {
                for l in 0..n {
                    a[(k, l)] += sigma * p[k] * d(m + k, m + l) * w[l];
                }
                let phi = problem.phi0[k] - (0..m).map(|c| d(m + k, c) * wl(c)).sum::<f64>();
                rhs[k] = sigma * p[k] * (phi - phi_f);
            }
            let next = a.lu().solve(&rhs).unwrap();
            let change = (0..n).map(|k| (next[k] - q[k]).abs()).fold(0.0f64, f64::max);
            q = next.iter().copied().collect();
            lambda = Some(sol.lambda);
            if change <= 1e-13 * q.iter().fold(1e-300f64, |a, v| a.max(v.abs())) {
                break;
            }
        }
        let lambda = lambda.unwrap();
        let scale = lambda.normal.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for (a, b) in newton.lambda.normal.iter().zip(&lambda.normal) {
            assert!((a - b).abs() <= 1e-9 * scale, "{foundation:?}: λ_n {a} vs {b}");
        }
        let flux = &newton.electric.as_ref().unwrap().flux;
        let qs = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(qs > 0.0);
        for (a, b) in flux.iter().zip(&q) {
            assert!((a - b).abs() <= 1e-9 * qs, "{foundation:?}: q {a} vs {b}");
        }
        assert!(
            newton.info.newton_iters <= 20,
            "{} Newton steps",
            newton.info.newton_iters
        );
    }
}
