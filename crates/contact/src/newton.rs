//! A semismooth Newton method on the condensed contact problem: the natural-map (Alart–Curnier)
//! equations of Signorini contact with Tresca or Coulomb friction, solved for the multipliers
//! with the contact compliance given densely. Coulomb friction is solved directly (the radius
//! `F [λ_n + c (u_n - g)]₊` moves with the pressure), without the fixed point on `S`.
//!
//! With `u(λ) = u₀ - D W λ` and `z = λ + c (u(λ) - g̃)` (`g̃ = (g, 0)`), the equations are
//! `λ_n - [z_n]₊ = 0` and `λ_t - P_S(z_t) = 0` at every point. They are piecewise smooth; a
//! generalised Jacobian picks, per point, the branch of `z` (separated, stick, slip). Each step
//! solves the dense `m x m` Newton system by LU, and an Armijo line search on the weighted norm
//! of the equations globalises the iteration. Where the line search fails (a Newton direction
//! that does not reduce the residual), the solve falls back on the accelerated projected
//! gradient of [`crate::solve`], warm-started from the best multipliers found, so that the
//! answer is never worse than the first-order method's. `c = 1/μ_max`, the residual's own
//! constant: nothing is tuned by hand.

use crate::operator::DenseContactProblem;
use crate::points::{ContactPoints, PointValues};
use crate::projection::project_disc;
use crate::uzawa::{classify, complementarity_residual, estimate_mu_max, slip_bound, Counter};
use crate::{ContactError, ContactSolution, Law, Progress, StopRule, UzawaInfo, UzawaParams};
use faer::linalg::solvers::Solve;
use faer::Mat;

/// Parameters of [`solve_newton`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonParams {
    /// Tolerance on the complementarity residual (the same as [`crate::complementarity_residual`]
    /// with the law's radius).
    pub tol: f64,
    /// Newton iteration limit before the fallback takes over.
    pub max_iters: usize,
    /// Power iterations for `μ_max`.
    pub power_iters: usize,
    /// Whether to fall back on the accelerated projected gradient when Newton stalls (when
    /// false, a stall is a [`ContactError::NewtonStalled`]).
    pub fallback: bool,
}

impl Default for NewtonParams {
    fn default() -> Self {
        NewtonParams {
            tol: 1e-10,
            max_iters: 100,
            power_iters: 30,
            fallback: true,
        }
    }
}

/// Armijo's sufficient-decrease constant.
const ARMIJO: f64 = 1e-4;
/// Merit values the non-monotone line search compares with.
const MEMORY: usize = 8;
/// Step halvings of the line search before the direction is given up.
const MAX_HALVINGS: usize = 30;

/// The branch of a point's equations at `z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Branch {
    Separated,
    Stick,
    Slip,
}

/// The problem in the flat layout `[normal (n); tangential (n·nt)]`.
struct Flat<'a> {
    p: &'a DenseContactProblem,
    points: &'a ContactPoints,
    law: &'a Law,
    n: usize,
    nt: usize,
    m: usize,
    c: f64,
    /// Weight of each flat index.
    w: Vec<f64>,
    u0: Vec<f64>,
}

/// The equations and their pieces at one `λ`.
struct State {
    x: Vec<f64>,
    u: Vec<f64>,
    z: Vec<f64>,
    f: Vec<f64>,
    /// Weighted norm of `f`.
    norm: f64,
}

impl Flat<'_> {
    /// The radius of point `i` at `z`: Tresca `S`, Coulomb `F [z_n]₊`.
    fn radius(&self, i: usize, z: &[f64]) -> f64 {
        match self.law {
            Law::Frictionless => 0.0,
            Law::Tresca(s) => s[i],
            Law::Coulomb => self.points.friction[i] * z[i].max(0.0),
        }
    }

    fn state(&self, x: Vec<f64>) -> State {
        let m = self.m;
        let wx: Vec<f64> = x.iter().zip(&self.w).map(|(a, b)| a * b).collect();
        let mut u = vec![0.0; m];
        let mut z = vec![0.0; m];
        for r in 0..m {
            u[r] = self.u0[r] - crate::operator::dot8(&self.p.compliance[r * m..(r + 1) * m], &wx);
            let g = if r < self.n { self.points.gap[r] } else { 0.0 };
            z[r] = x[r] + self.c * (u[r] - g);
        }
        let mut f = vec![0.0; m];
        let mut buf = [0.0; 2];
        for i in 0..self.n {
            f[i] = x[i] - z[i].max(0.0);
            if self.nt > 0 {
                let t = self.n + i * self.nt;
                buf[..self.nt].copy_from_slice(&z[t..t + self.nt]);
                project_disc(&mut buf[..self.nt], self.radius(i, &z));
                for k in 0..self.nt {
                    f[t + k] = x[t + k] - buf[k];
                }
            }
        }
        let norm = f.iter().zip(&self.w).map(|(a, w)| w * a * a).sum::<f64>().sqrt();
        State { x, u, z, f, norm }
    }

    /// The Newton direction `J δ = -f` at `s`, with `J` a generalised Jacobian of the
    /// equations; `None` where `J` is singular.
    fn direction(&self, s: &State) -> Option<Vec<f64>> {
        let (n, nt, m, c) = (self.n, self.nt, self.m, self.c);
        let d = &self.p.compliance;
        // row r of M = I - c D W, the derivative of z
        let m_row = |r: usize, col: usize| -> f64 {
            let id = if r == col { 1.0 } else { 0.0 };
            id - c * d[r * m + col] * self.w[col]
        };
        // Jᵀ, column-major: row r of J is column r of Jᵀ, written contiguously
        let mut jt = Mat::<f64>::zeros(m, m);
        for i in 0..n {
            // normal: [z_n]₊ has derivative 1 (contact) or 0 (separated)
            if s.z[i] > 0.0 {
                for col in 0..m {
                    jt[(col, i)] = c * d[i * m + col] * self.w[col];
                }
            } else {
                jt[(i, i)] = 1.0;
            }
            if nt == 0 {
                continue;
            }
            let t = n + i * nt;
            let q = &s.z[t..t + nt];
            let qn = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            let radius = self.radius(i, &s.z);
            let branch = if !(radius > 0.0) {
                Branch::Separated
            } else if qn <= radius {
                Branch::Stick
            } else {
                Branch::Slip
            };
            match branch {
                Branch::Stick => {
                    // λ_t - z_t: derivative c D W
                    for k in 0..nt {
                        for col in 0..m {
                            jt[(col, t + k)] = c * d[(t + k) * m + col] * self.w[col];
                        }
                    }
                }
                Branch::Separated => {
                    // λ_t - P_0(z_t) = λ_t (a zero radius): the identity
                    for k in 0..nt {
                        jt[(t + k, t + k)] = 1.0;
                    }
                }
                Branch::Slip => {
                    // λ_t - S q/|q|: derivative I - (S/|q|)(I - q̂q̂ᵀ) M_t - q̂ dS
                    let qh: Vec<f64> = q.iter().map(|v| v / qn).collect();
                    let ratio = radius / qn;
                    let coulomb_slope = match self.law {
                        Law::Coulomb if s.z[i] > 0.0 => self.points.friction[i],
                        _ => 0.0,
                    };
                    for k in 0..nt {
                        for col in 0..m {
                            let mut v = if t + k == col { 1.0 } else { 0.0 };
                            for l in 0..nt {
                                let proj = if k == l { 1.0 } else { 0.0 } - qh[k] * qh[l];
                                if proj != 0.0 {
                                    v -= ratio * proj * m_row(t + l, col);
                                }
                            }
                            if coulomb_slope > 0.0 {
                                v -= qh[k] * coulomb_slope * m_row(i, col);
                            }
                            jt[(col, t + k)] = v;
                        }
                    }
                }
            }
        }
        let lu = jt.partial_piv_lu();
        let mut rhs = Mat::<f64>::from_fn(m, 1, |r, _| -s.f[r]);
        lu.solve_transpose_in_place(rhs.as_mut());
        let delta: Vec<f64> = (0..m).map(|r| rhs[(r, 0)]).collect();
        delta.iter().all(|v| v.is_finite()).then_some(delta)
    }

    fn to_values(&self, x: &[f64]) -> PointValues {
        PointValues {
            normal: x[..self.n].to_vec(),
            tangential: x[self.n..].to_vec(),
        }
    }
}

/// Solves the condensed contact problem `problem` for `law` by the semismooth Newton method of
/// this module, from `lambda0` (zeros when `None`). Reports one progress line per Newton step.
///
/// The returned [`UzawaInfo`] counts Newton steps in `newton_iters` (and the fallback's
/// first-order steps, if any, in `uzawa_iters`); `complementarity` is the residual of
/// [`crate::complementarity_residual`] with the law's radius, at most `params.tol`.
pub fn solve_newton(
    problem: &mut DenseContactProblem,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    points.validate().map_err(ContactError::Input)?;
    let n = points.len();
    let nt = if matches!(law, Law::Frictionless) {
        0
    } else {
        points.n_tangential()
    };
    if problem.weight.len() != n || problem.nt != nt || problem.compliance.len() != problem.m() * problem.m() {
        return Err(ContactError::Input(format!(
            "condensed problem has {} points with {} tangential components and {} compliance entries; expected {n} points with {nt}",
            problem.weight.len(),
            problem.nt,
            problem.compliance.len()
        )));
    }
    if let Law::Tresca(s) = law {
        if s.len() != n || s.iter().any(|x| !(*x >= 0.0 && x.is_finite())) {
            return Err(ContactError::Input(
                "Tresca slip bounds: one finite non-negative value per point".into(),
            ));
        }
    }
    if !(params.tol > 0.0) {
        return Err(ContactError::Input(format!(
            "Newton tolerance {} must be positive",
            params.tol
        )));
    }
    let (mu_max, reference) = {
        let mut counter = Counter::new(problem);
        let (mu, u0) = estimate_mu_max(&mut counter, points, nt, params.power_iters)?;
        let free = PointValues {
            normal: u0.normal.iter().zip(&points.gap).map(|(u, g)| u - g).collect(),
            tangential: u0.tangential.clone(),
        };
        (mu, free.weighted_norm(&points.weight) / mu)
    };
    let c = 1.0 / mu_max;
    let m = n * (1 + nt);
    let flat = Flat {
        p: problem,
        points,
        law,
        n,
        nt,
        m,
        c,
        w: (0..m)
            .map(|j| points.weight[if j < n { j } else { (j - n) / nt }])
            .collect(),
        u0: problem
            .u0
            .normal
            .iter()
            .chain(&problem.u0.tangential)
            .copied()
            .collect(),
    };
    let x0 = match lambda0 {
        Some(l) if l.normal.len() == n && l.tangential.len() == n * nt => {
            l.normal.iter().chain(&l.tangential).copied().collect()
        }
        Some(_) => return Err(ContactError::Input("warm start of the wrong size".into())),
        None => vec![0.0; m],
    };
    let mut info = UzawaInfo {
        uzawa_iters: 0,
        newton_iters: 0,
        line_search_cuts: 0,
        fallback: false,
        fixed_point_iters: 0,
        inner_iters: 0,
        estimate_inner_iters: 0,
        operator_calls: 0,
        step: c,
        mu_max,
        complementarity: f64::NAN,
        step_backoffs: 0,
        relaxations: 0,
    };
    let residual = |s: &State| {
        let lambda = flat.to_values(&s.x);
        let u = flat.to_values(&s.u);
        let radius = slip_bound(points, law, &lambda.normal);
        complementarity_residual(points, &radius, &lambda, &u, c, reference)
    };
    let mut s = flat.state(x0);
    let mut r = residual(&s);
    let mut stalled = None;
    let mut history = std::collections::VecDeque::with_capacity(MEMORY + 1);
    while !(r <= params.tol) {
        if info.newton_iters >= params.max_iters {
            stalled = Some("the iteration limit");
            break;
        }
        let Some(delta) = flat.direction(&s) else {
            stalled = Some("a singular Newton matrix");
            break;
        };
        // non-monotone Armijo backtracking on the weighted norm of the equations, against the
        // largest of the last MEMORY norms (Grippo, Lampariello and Lucidi): a full step that
        // changes a point's branch may raise the norm for a step on the way to the solution
        let reference_norm = history.iter().copied().fold(s.norm, f64::max);
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..=MAX_HALVINGS {
            let x: Vec<f64> = s.x.iter().zip(&delta).map(|(a, b)| a + alpha * b).collect();
            let trial = flat.state(x);
            if trial.norm <= (1.0 - ARMIJO * alpha) * reference_norm {
                accepted = Some(trial);
                break;
            }
            alpha *= 0.5;
            info.line_search_cuts += 1;
        }
        let Some(next) = accepted else {
            stalled = Some("a failed line search");
            break;
        };
        history.push_back(s.norm);
        if history.len() > MEMORY {
            history.pop_front();
        }
        s = next;
        r = residual(&s);
        info.newton_iters += 1;
        let lambda = flat.to_values(&s.x);
        let status = classify(&lambda, &slip_bound(points, law, &lambda.normal));
        let count = |st| status.iter().filter(|&&x| x == st).count();
        progress(&Progress {
            stage: "newton",
            iter: info.newton_iters,
            residual: r,
            counts: (
                count(crate::Status::Stick),
                count(crate::Status::Slip),
                count(crate::Status::Separated),
            ),
        });
        if !r.is_finite() {
            stalled = Some("a non-finite residual");
            break;
        }
    }
    if let Some(why) = stalled {
        if !params.fallback {
            return Err(ContactError::NewtonStalled {
                n_iters: info.newton_iters,
                residual: r,
                reason: why.to_string(),
            });
        }
        // the first-order method from the multipliers reached, projected onto the sets
        let mut start = flat.to_values(&s.x);
        start.normal.iter_mut().for_each(|v| *v = v.max(0.0));
        let radius = slip_bound(points, law, &start.normal);
        for i in 0..n {
            project_disc(&mut start.tangential[i * nt..(i + 1) * nt], radius[i]);
        }
        let apg = UzawaParams {
            rule: StopRule::Tight { tol: params.tol },
            accelerate: true,
            power_iters: params.power_iters,
            report_every: 500,
            ..Default::default()
        };
        let mut sol = crate::solve(problem, points, law, &apg, Some(start), progress)?;
        sol.info.newton_iters = info.newton_iters;
        sol.info.line_search_cuts = info.line_search_cuts;
        sol.info.fallback = true;
        return Ok(sol);
    }
    let lambda = flat.to_values(&s.x);
    let u = flat.to_values(&s.u);
    let radius = slip_bound(points, law, &lambda.normal);
    info.complementarity = r;
    Ok(ContactSolution {
        status: classify(&lambda, &radius),
        lambda,
        u,
        info,
    })
}
