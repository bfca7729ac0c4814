//! Uzawa's algorithm with projections (the paper's Algorithm 2, signs of DESIGN.md), the fixed
//! point on the slip bound for Coulomb friction (Algorithm 4), the step from the dual
//! operator's largest eigenvalue, and the scale-free residuals.

use crate::operator::ContactOperator;
use crate::points::{ContactPoints, PointValues, Status};
use crate::projection::{project_disc, project_nonnegative};
use crate::ContactError;

/// The friction law.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// Signorini contact alone (no tangential multiplier).
    Frictionless,
    /// Tresca friction with a given slip bound per point.
    Tresca(Vec<f64>),
    /// Coulomb friction `S = F λ_n`, by the fixed point on `S`.
    Coulomb,
}

/// When the loops stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StopRule {
    /// The complementarity residual (DESIGN.md) at most `tol`; for Coulomb the residual with
    /// the Coulomb radius `F λ_n`, so that the fixed point stops only at a Coulomb solution.
    Tight {
        /// Tolerance.
        tol: f64,
    },
    /// The paper's loose rules, as reproduced by an independent study: Uzawa stops when
    /// `‖λ^{k+1} - λ^k‖₂ ≤ 1e-3 ‖λ^{k+1}‖₂`, the fixed point when
    /// `‖S^l - S^{l-1}‖₂ ≤ 1e-3 ‖S^l‖₂`. Never reported as converged to a tolerance.
    Paper,
}

/// Parameters of [`solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UzawaParams {
    /// The Uzawa step `r`; `None`: `safety / μ_max` from a power-iteration estimate.
    pub step: Option<f64>,
    /// The factor in `r = safety / μ_max` (the paper's study: 1.8; convergence needs < 2).
    pub safety: f64,
    /// Power iterations for `μ_max`.
    pub power_iters: usize,
    /// Stopping rule.
    pub rule: StopRule,
    /// Uzawa iteration limit (per Tresca solve).
    pub max_iters: usize,
    /// Fixed-point iteration limit.
    pub max_fixed_point: usize,
    /// Report progress every this many Uzawa iterations (0: never).
    pub report_every: usize,
    /// Nesterov acceleration of the projected gradient (FISTA) with adaptive restart, step
    /// `1 / μ_max`; only with the tight rule (the paper's rule is plain Uzawa).
    pub accelerate: bool,
}

impl Default for UzawaParams {
    fn default() -> Self {
        UzawaParams {
            step: None,
            safety: 1.8,
            power_iters: 30,
            rule: StopRule::Tight { tol: 1e-10 },
            max_iters: 200_000,
            max_fixed_point: 100,
            report_every: 0,
            accelerate: false,
        }
    }
}

/// What a converged [`solve`] reports.
#[derive(Clone, Debug, PartialEq)]
pub struct UzawaInfo {
    /// Uzawa (first-order) iterations, summed over the fixed point.
    pub uzawa_iters: usize,
    /// Semismooth Newton steps ([`crate::solve_newton`]; 0 for the first-order methods).
    pub newton_iters: usize,
    /// Step halvings in Newton's line search, summed.
    pub line_search_cuts: usize,
    /// Whether Newton stalled and the accelerated gradient finished the solve.
    pub fallback: bool,
    /// Fixed-point iterations (0 when the law has none).
    pub fixed_point_iters: usize,
    /// Inner iterations reported by the operator (PCG) in the Uzawa loops, summed.
    pub inner_iters: usize,
    /// Inner iterations spent estimating `μ_max` (power iteration).
    pub estimate_inner_iters: usize,
    /// Calls of the operator (primal solves), including the power iteration.
    pub operator_calls: usize,
    /// The step used.
    pub step: f64,
    /// The estimate of the dual operator's largest eigenvalue.
    pub mu_max: f64,
    /// Complementarity residual of the returned pair (the law's own radius).
    pub complementarity: f64,
    /// Whether a stricter step was needed (divergence detected and the step halved).
    pub step_backoffs: usize,
    /// Halvings of the friction fixed point's relaxation factor (a residual that did not fall).
    pub relaxations: usize,
}

impl UzawaInfo {
    /// Counts at zero for a solve with this step (or Newton augmentation) and `μ_max`.
    pub(crate) fn new(step: f64, mu_max: f64) -> Self {
        UzawaInfo {
            uzawa_iters: 0,
            newton_iters: 0,
            line_search_cuts: 0,
            fallback: false,
            fixed_point_iters: 0,
            inner_iters: 0,
            estimate_inner_iters: 0,
            operator_calls: 0,
            step,
            mu_max,
            complementarity: f64::NAN,
            step_backoffs: 0,
            relaxations: 0,
        }
    }
}

/// A converged contact solution.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSolution {
    /// Multipliers `λ_n ≥ 0` (pressure) and `λ_t`.
    pub lambda: PointValues,
    /// Displacement at the points for these multipliers.
    pub u: PointValues,
    /// Status of each point.
    pub status: Vec<Status>,
    /// Counts and residuals.
    pub info: UzawaInfo,
}

/// One line of progress.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// `uzawa` or `fixed-point`.
    pub stage: &'static str,
    /// Iteration number within the stage.
    pub iter: usize,
    /// The stage's residual (complementarity, or the paper's relative change).
    pub residual: f64,
    /// Stick / slip / separated counts.
    pub counts: (usize, usize, usize),
}

/// The slip bound of each point for a law and multipliers: Tresca `S`, Coulomb `F λ_n`,
/// frictionless 0.
pub fn slip_bound(points: &ContactPoints, law: &Law, lambda_n: &[f64]) -> Vec<f64> {
    match law {
        Law::Frictionless => vec![0.0; points.len()],
        Law::Tresca(s) => s.clone(),
        Law::Coulomb => points.friction.iter().zip(lambda_n).map(|(f, l)| f * l).collect(),
    }
}

/// The natural-map residual of DESIGN.md with step `c`:
/// `‖(λ_n - max(0, λ_n + c (u_n - g)), λ_t - P_S(λ_t + c u_t))‖_W / max(‖λ‖_W, reference)`.
///
/// `reference` is the multiplier scale of the problem, `c ‖(u_n(0) - g, u_t(0))‖_W` with `u(0)`
/// the contact displacement under the loads alone ([`solve`] computes it): without it, a
/// solution whose multipliers vanish at a grazing point would be approached with `‖r‖` and `‖λ‖`
/// shrinking together and a relative residual that never falls. Both terms scale like λ, so
/// the residual is free of units and of the solver's own step. A zero denominator gives the
/// absolute residual.
pub fn complementarity_residual(
    points: &ContactPoints,
    radius: &[f64],
    lambda: &PointValues,
    u: &PointValues,
    c: f64,
    reference: f64,
) -> f64 {
    let n = points.len();
    let nt = lambda.tangential.len().checked_div(n).unwrap_or(0);
    let mut r = PointValues::zeros(n, nt);
    let mut buf = [0.0; 2];
    for i in 0..n {
        r.normal[i] = lambda.normal[i] - project_nonnegative(lambda.normal[i] + c * (u.normal[i] - points.gap[i]));
        if nt > 0 {
            for k in 0..nt {
                buf[k] = lambda.tangential[i * nt + k] + c * u.tangential[i * nt + k];
            }
            project_disc(&mut buf[..nt], radius[i]);
            for k in 0..nt {
                r.tangential[i * nt + k] = lambda.tangential[i * nt + k] - buf[k];
            }
        }
    }
    let num = r.weighted_norm(&points.weight);
    let den = lambda.weighted_norm(&points.weight).max(reference);
    if den > 0.0 {
        num / den
    } else {
        num
    }
}

/// Status of each point (DESIGN.md): separated if `λ_n ≤ 1e-9 max λ_n`; otherwise slip if the
/// radius is 0 or `|λ_t| ≥ (1 - 1e-9) S`; otherwise stick.
pub fn classify(lambda: &PointValues, radius: &[f64]) -> Vec<Status> {
    let n = lambda.normal.len();
    let nt = lambda.tangential.len().checked_div(n).unwrap_or(0);
    let max_n = lambda.normal.iter().cloned().fold(0.0f64, f64::max);
    (0..n)
        .map(|i| {
            if !(lambda.normal[i] > 1e-9 * max_n) {
                Status::Separated
            } else {
                let t = (0..nt)
                    .map(|k| lambda.tangential[i * nt + k].powi(2))
                    .sum::<f64>()
                    .sqrt();
                if radius[i] <= 0.0 || t >= (1.0 - 1e-9) * radius[i] {
                    Status::Slip
                } else {
                    Status::Stick
                }
            }
        })
        .collect()
}

fn counts(status: &[Status]) -> (usize, usize, usize) {
    let c = |s| status.iter().filter(|&&x| x == s).count();
    (c(Status::Stick), c(Status::Slip), c(Status::Separated))
}

/// The operator with a count of its calls and of the inner iterations they report.
pub(crate) struct Counter<'a> {
    op: &'a mut dyn ContactOperator,
    calls: usize,
    inner: usize,
}

impl<'a> Counter<'a> {
    pub(crate) fn new(op: &'a mut dyn ContactOperator) -> Self {
        Counter { op, calls: 0, inner: 0 }
    }

    fn call(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<(), ContactError> {
        self.calls += 1;
        self.inner += self.op.displacement(lambda, out).map_err(ContactError::Operator)?;
        Ok(())
    }
}

/// Largest eigenvalue of the dual operator `λ ↦ u(0) - u(λ)` in the `W` inner product, by
/// power iteration from `λ = 1` (a Rayleigh quotient, so a lower estimate).
pub(crate) fn estimate_mu_max(
    c: &mut Counter<'_>,
    points: &ContactPoints,
    nt: usize,
    iters: usize,
) -> Result<(f64, PointValues), ContactError> {
    let n = points.len();
    let zero = PointValues::zeros(n, nt);
    let mut u0 = PointValues::zeros(n, nt);
    c.call(&zero, &mut u0)?;
    // a deterministic start with no symmetry (a constant vector can lie along an eigenvector of
    // a lower eigenvalue, and the Rayleigh quotient then never sees the top one)
    let start = |i: usize| 1.0 + 0.5 * (1.3 * i as f64 + 0.7).sin();
    let mut v = PointValues {
        normal: (0..n).map(start).collect(),
        tangential: (0..n * nt).map(|i| start(n + i)).collect(),
    };
    let mut mu = 0.0;
    let mut out = PointValues::zeros(n, nt);
    for _ in 0..iters.max(1) {
        let nv = v.weighted_norm(&points.weight);
        if !(nv > 0.0) {
            break;
        }
        v.normal
            .iter_mut()
            .chain(v.tangential.iter_mut())
            .for_each(|x| *x /= nv);
        c.call(&v, &mut out)?;
        let mv = u0.minus(&out);
        let w = &points.weight;
        let mut rq = 0.0;
        for i in 0..n {
            rq += w[i] * v.normal[i] * mv.normal[i];
            for k in 0..nt {
                rq += w[i] * v.tangential[i * nt + k] * mv.tangential[i * nt + k];
            }
        }
        mu = f64::max(mu, rq);
        v = mv;
    }
    // leave the operator's warm start (an iterative primal solver starts from its last
    // solution) at the loads alone, where Uzawa starts
    c.call(&zero, &mut out)?;
    if !(mu > 0.0 && mu.is_finite()) {
        return Err(ContactError::Operator(format!("the dual operator's largest eigenvalue estimate is {mu}: the contact points are not loaded by their multipliers")));
    }
    Ok((mu, u0))
}

/// Checks the points, the law's data, and the size of the problem (`n_points` points with
/// `n_tangential` tangential components each) against them; returns `(n, nt)`.
pub(crate) fn check_input(
    points: &ContactPoints,
    law: &Law,
    n_points: usize,
    n_tangential: usize,
) -> Result<(usize, usize), ContactError> {
    points.validate().map_err(ContactError::Input)?;
    let n = points.len();
    let nt = if matches!(law, Law::Frictionless) {
        0
    } else {
        points.n_tangential()
    };
    if n_points != n || n_tangential != nt {
        return Err(ContactError::Input(format!(
            "the problem has {n_points} points with {n_tangential} tangential components; expected {n} with {nt}"
        )));
    }
    if let Law::Tresca(s) = law {
        if s.len() != n || s.iter().any(|x| !(*x >= 0.0 && x.is_finite())) {
            return Err(ContactError::Input(
                "Tresca slip bounds: one finite non-negative value per point".into(),
            ));
        }
    }
    Ok((n, nt))
}

/// The multiplier scale of the problem, `c ‖u(0) - g‖_W` (the floor of the residual's
/// denominator, see [`complementarity_residual`]).
pub(crate) fn multiplier_scale(points: &ContactPoints, u0: &PointValues, c: f64) -> f64 {
    let free = PointValues {
        normal: u0.normal.iter().zip(&points.gap).map(|(u, g)| u - g).collect(),
        tangential: u0.tangential.clone(),
    };
    c * free.weighted_norm(&points.weight)
}

/// The accelerated iteration's memory: the momentum weight and the previous projected iterate.
struct Momentum {
    t: f64,
    x_prev: Option<PointValues>,
}

/// Uzawa iterations without a 1 % gain on the best residual before the step is halved.
const STALL_WINDOW: usize = 500;

/// Halvings of the step before the iteration is declared divergent.
const MAX_BACKOFFS: usize = 20;

/// The state of the dual iteration shared by the Uzawa loops of one solve.
struct Dual<'a, 'b> {
    c: Counter<'b>,
    points: &'a ContactPoints,
    params: &'a UzawaParams,
    /// The canonical step `1 / μ_max` of the residual.
    canon: f64,
    /// The multiplier scale of the residual's denominator.
    reference: f64,
    /// Counts so far; `info.step` is the current step.
    info: UzawaInfo,
    /// A tolerance for the Tresca solves tighter than the rule's, once the friction fixed point
    /// stalls just above its tolerance (inexact inner solves put a floor under its residual).
    inner_tol: Option<f64>,
}

/// Solves the contact problem for `law` through `op`, from `lambda0` (warm start; zeros when
/// `None`). Reports progress through `progress`.
pub fn solve(
    op: &mut dyn ContactOperator,
    points: &ContactPoints,
    law: &Law,
    params: &UzawaParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    let (n, nt) = check_input(points, law, op.n_points(), op.n_tangential())?;
    let mut c = Counter::new(op);
    let (mu_max, u0) = estimate_mu_max(&mut c, points, nt, params.power_iters)?;
    let estimate_inner = c.inner;
    if params.accelerate && params.rule == StopRule::Paper {
        return Err(ContactError::Input(
            "acceleration needs the tight rule (the paper's rule is plain Uzawa)".into(),
        ));
    }
    // plain Uzawa converges for r < 2/μ_max; the accelerated gradient wants r ≤ 1/μ_max
    let step = params.step.unwrap_or(if params.accelerate {
        1.0 / mu_max
    } else {
        params.safety / mu_max
    });
    if !(step > 0.0 && step.is_finite()) {
        return Err(ContactError::Input(format!("Uzawa step {step} must be positive")));
    }
    let canon = 1.0 / mu_max;
    let reference = multiplier_scale(points, &u0, canon);
    let mut lambda = lambda0.unwrap_or_else(|| PointValues::zeros(n, nt));
    let mut u = PointValues::zeros(n, nt);
    let info = UzawaInfo::new(step, mu_max);
    let mut d = Dual {
        c,
        points,
        params,
        canon,
        reference,
        info,
        inner_tol: None,
    };
    match law {
        Law::Frictionless | Law::Tresca(_) => {
            let radius = slip_bound(points, law, &lambda.normal);
            let fresh = uzawa(&mut d, &radius, &mut lambda, &mut u, progress)?;
            if !fresh {
                d.c.call(&lambda, &mut u)?;
            }
        }
        Law::Coulomb => {
            // the paper starts from S = 0; a warm start from λ uses F λ_n
            let mut s = slip_bound(points, law, &lambda.normal);
            let mut fresh = false;
            // relaxation of the fixed point, S ← S + ω (F λ_n - S): ω = 1 is the paper's
            // iteration; under the tight rule ω halves (down to 1/64) whenever the residual
            // fails to fall, which damps the two-cycles strong coupling can cause (the fixed
            // points are the same for every ω > 0)
            let mut omega = 1.0;
            let mut previous = f64::INFINITY;
            for l in 1..=params.max_fixed_point {
                d.info.fixed_point_iters = l;
                fresh = uzawa(&mut d, &s, &mut lambda, &mut u, progress)?;
                let s_new = slip_bound(points, law, &lambda.normal);
                let status = classify(&lambda, &s_new);
                let (done, residual) = match params.rule {
                    StopRule::Tight { tol } => {
                        if !fresh {
                            d.c.call(&lambda, &mut u)?;
                            fresh = true;
                        }
                        let r = complementarity_residual(points, &s_new, &lambda, &u, canon, reference);
                        (r <= tol, r)
                    }
                    StopRule::Paper => {
                        let diff: f64 = s_new.iter().zip(&s).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
                        let norm: f64 = s_new.iter().map(|a| a * a).sum::<f64>().sqrt();
                        let rel = if norm > 0.0 { diff / norm } else { diff };
                        (rel <= 1e-3, rel)
                    }
                };
                progress(&Progress {
                    stage: "fixed-point",
                    iter: l,
                    residual,
                    counts: counts(&status),
                });
                if let StopRule::Tight { tol } = params.rule {
                    if residual >= previous && residual > 100.0 * tol && omega > 1.0 / 64.0 {
                        omega *= 0.5;
                        d.info.relaxations += 1;
                    }
                    // near the tolerance the inner solves' own error shows: solve them tighter
                    if residual <= 100.0 * tol {
                        d.inner_tol = Some(d.inner_tol.unwrap_or(tol).min(0.01 * tol).max(1e-15));
                    }
                }
                previous = residual;
                s = if omega == 1.0 {
                    s_new
                } else {
                    s.iter().zip(&s_new).map(|(a, b)| a + omega * (b - a)).collect()
                };
                if done {
                    break;
                }
                if l == params.max_fixed_point {
                    return Err(ContactError::FixedPointNoConvergence { n_iters: l, residual });
                }
            }
            if !fresh {
                d.c.call(&lambda, &mut u)?;
            }
        }
    }
    let radius = slip_bound(points, law, &lambda.normal);
    let mut info = d.info;
    info.complementarity = complementarity_residual(points, &radius, &lambda, &u, canon, reference);
    info.operator_calls = d.c.calls;
    info.estimate_inner_iters = estimate_inner;
    info.inner_iters = d.c.inner - estimate_inner;
    if let StopRule::Tight { tol } = params.rule {
        if !(info.complementarity <= tol) {
            return Err(ContactError::NoConvergence {
                n_iters: info.uzawa_iters,
                residual: info.complementarity,
            });
        }
    }
    let status = classify(&lambda, &radius);
    Ok(ContactSolution {
        lambda,
        u,
        status,
        info,
    })
}

impl Dual<'_, '_> {
    /// Halves the step; a [`ContactError::Diverged`] after [`MAX_BACKOFFS`] halvings.
    fn back_off(&mut self, residual: f64) -> Result<(), ContactError> {
        self.info.step *= 0.5;
        self.info.step_backoffs += 1;
        if self.info.step_backoffs > MAX_BACKOFFS {
            return Err(ContactError::Diverged {
                n_iters: self.info.uzawa_iters,
                residual,
                step: self.info.step,
            });
        }
        Ok(())
    }
}

/// Uzawa iterations for a given radius. Returns whether `u` is the displacement of the final
/// `lambda` (true under the tight rule; under the paper's rule the last update is not solved).
fn uzawa(
    d: &mut Dual<'_, '_>,
    radius: &[f64],
    lambda: &mut PointValues,
    u: &mut PointValues,
    progress: &mut dyn FnMut(&Progress),
) -> Result<bool, ContactError> {
    let (points, params, canon, reference) = (d.points, d.params, d.canon, d.reference);
    let n = points.len();
    let nt = lambda.tangential.len().checked_div(n).unwrap_or(0);
    let mut best = f64::INFINITY;
    let mut window_best = f64::INFINITY;
    let mut window_start = 0;
    let mut last = f64::NAN;
    let mut buf = [0.0; 2];
    let mut momentum = Momentum { t: 1.0, x_prev: None };
    for k in 1..=params.max_iters {
        d.c.call(lambda, u)?;
        let r = complementarity_residual(points, radius, lambda, u, canon, reference);
        last = r;
        if !r.is_finite() {
            return Err(ContactError::Diverged {
                n_iters: d.info.uzawa_iters,
                residual: r,
                step: d.info.step,
            });
        }
        if let StopRule::Tight { tol } = params.rule {
            if r <= d.inner_tol.unwrap_or(tol) {
                return Ok(true);
            }
        }
        // a residual far above the best seen (divergence), or no 1 % gain on the best over a
        // window (a stall): the step is too large for the dual operator (an under-estimated
        // μ_max); halve it and start the momentum afresh
        let diverging = r > 1e3 * best && k > 10;
        if r < 0.99 * window_best {
            window_best = r;
            window_start = k;
        }
        if diverging || k - window_start >= STALL_WINDOW {
            d.back_off(r)?;
            best = r;
            window_best = r;
            window_start = k;
            momentum = Momentum { t: 1.0, x_prev: None };
        }
        best = best.min(r);
        d.info.uzawa_iters += 1;
        let y_old = if params.accelerate { Some(lambda.clone()) } else { None };
        // the projected update
        let mut diff2 = 0.0;
        let mut norm2 = 0.0;
        for i in 0..n {
            let new = project_nonnegative(lambda.normal[i] + d.info.step * (u.normal[i] - points.gap[i]));
            diff2 += (new - lambda.normal[i]).powi(2);
            norm2 += new * new;
            lambda.normal[i] = new;
            if nt > 0 {
                for q in 0..nt {
                    buf[q] = lambda.tangential[i * nt + q] + d.info.step * u.tangential[i * nt + q];
                }
                project_disc(&mut buf[..nt], radius[i]);
                for q in 0..nt {
                    diff2 += (buf[q] - lambda.tangential[i * nt + q]).powi(2);
                    norm2 += buf[q] * buf[q];
                    lambda.tangential[i * nt + q] = buf[q];
                }
            }
        }
        if let Some(y_old) = y_old {
            // FISTA: λ holds x_{k+1} = P(y_k + r (u(y_k) - g)); restart the momentum when the
            // step goes against it (O'Donoghue and Candès' gradient test), then extrapolate
            let x_prev = momentum.x_prev.get_or_insert_with(|| y_old.clone());
            let w = &points.weight;
            let mut test = 0.0;
            for i in 0..n {
                test += w[i] * (y_old.normal[i] - lambda.normal[i]) * (lambda.normal[i] - x_prev.normal[i]);
                for q in 0..nt {
                    let j = i * nt + q;
                    test += w[i]
                        * (y_old.tangential[j] - lambda.tangential[j])
                        * (lambda.tangential[j] - x_prev.tangential[j]);
                }
            }
            let t_next = 0.5 * (1.0 + (1.0 + 4.0 * momentum.t * momentum.t).sqrt());
            let beta = if test > 0.0 {
                momentum.t = 1.0;
                0.0
            } else {
                let b = (momentum.t - 1.0) / t_next;
                momentum.t = t_next;
                b
            };
            let x_new = lambda.clone();
            for (l, (xn, xp)) in lambda.normal.iter_mut().zip(x_new.normal.iter().zip(&x_prev.normal)) {
                *l = xn + beta * (xn - xp);
            }
            for (l, (xn, xp)) in lambda
                .tangential
                .iter_mut()
                .zip(x_new.tangential.iter().zip(&x_prev.tangential))
            {
                *l = xn + beta * (xn - xp);
            }
            *x_prev = x_new;
        }
        if params.report_every > 0 && k % params.report_every == 0 {
            progress(&Progress {
                stage: "uzawa",
                iter: k,
                residual: r,
                counts: counts(&classify(lambda, radius)),
            });
        }
        if params.rule == StopRule::Paper {
            let rel = if norm2 > 0.0 {
                (diff2 / norm2).sqrt()
            } else {
                diff2.sqrt()
            };
            if rel <= 1e-3 {
                return Ok(false);
            }
        }
    }
    Err(ContactError::NoConvergence {
        n_iters: d.info.uzawa_iters,
        residual: last,
    })
}
