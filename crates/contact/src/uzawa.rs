//! Uzawa's algorithm with projections (the paper's Algorithm 2, signs of DESIGN.md), its
//! accelerated version, and the fixed point on the slip bound for Coulomb friction
//! (Algorithm 4), with the step from the dual operator's largest eigenvalue.

use crate::operator::ContactOperator;
use crate::points::{ContactPoints, PointValues};
use crate::projection::{project_disc, project_nonnegative};
use crate::solution::{
    check_input, classify, complementarity_residual, counts, estimate_mu_max, multiplier_scale, slip_bound, Counter,
};
use crate::{ContactError, ContactInfo, ContactSolution, Law, Progress, Stage};

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

/// The accelerated iteration's memory: the momentum weight and the previous projected iterate.
struct Momentum {
    t: f64,
    x_prev: Option<PointValues>,
}

impl Momentum {
    /// FISTA's extrapolation: `lambda` holds `x_{k+1} = P(y_k + r (u(y_k) - g))`; the momentum
    /// restarts when the step goes against it (O'Donoghue and Candès' gradient test, in the
    /// `W` inner product), else `lambda` becomes `x_{k+1} + β (x_{k+1} - x_k)`.
    fn extrapolate(&mut self, y_old: &PointValues, lambda: &mut PointValues, w: &[f64]) {
        let x_prev = self.x_prev.get_or_insert_with(|| y_old.clone());
        let test = y_old.minus(lambda).weighted_dot(&lambda.minus(x_prev), w);
        let t_next = 0.5 * (1.0 + (1.0 + 4.0 * self.t * self.t).sqrt());
        let beta = if test > 0.0 {
            self.t = 1.0;
            0.0
        } else {
            let b = (self.t - 1.0) / t_next;
            self.t = t_next;
            b
        };
        let x_new = lambda.clone();
        let parts = [
            (&mut lambda.normal, &x_new.normal, &x_prev.normal),
            (&mut lambda.tangential, &x_new.tangential, &x_prev.tangential),
        ];
        for (l, xn, xp) in parts {
            for (l, (xn, xp)) in l.iter_mut().zip(xn.iter().zip(xp)) {
                *l = xn + beta * (xn - xp);
            }
        }
        *x_prev = x_new;
    }
}

/// Uzawa's projected update in place, `λ_n ← max(0, λ_n + r (u_n - g))`,
/// `λ_t ← P_S(λ_t + r u_t)`; returns `(‖Δλ‖², ‖λ_new‖²)` for the paper's rule.
fn projected_step(
    points: &ContactPoints,
    radius: &[f64],
    r: f64,
    lambda: &mut PointValues,
    u: &PointValues,
) -> (f64, f64) {
    let nt = lambda.n_tangential();
    let (mut diff2, mut norm2) = (0.0, 0.0);
    let mut buf = [0.0; 2];
    for i in 0..points.len() {
        let new = project_nonnegative(lambda.normal[i] + r * (u.normal[i] - points.gap[i]));
        diff2 += (new - lambda.normal[i]).powi(2);
        norm2 += new * new;
        lambda.normal[i] = new;
        if nt > 0 {
            for q in 0..nt {
                buf[q] = lambda.tangential[i * nt + q] + r * u.tangential[i * nt + q];
            }
            project_disc(&mut buf[..nt], radius[i]);
            for q in 0..nt {
                diff2 += (buf[q] - lambda.tangential[i * nt + q]).powi(2);
                norm2 += buf[q] * buf[q];
                lambda.tangential[i * nt + q] = buf[q];
            }
        }
    }
    (diff2, norm2)
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
    /// The current step `r`.
    step: f64,
    /// Counts so far.
    info: ContactInfo,
    /// A tolerance for the Tresca solves tighter than the rule's, once the friction fixed point
    /// stalls just above its tolerance (inexact inner solves put a floor under its residual).
    inner_tol: Option<f64>,
}

/// Solves the contact problem for `law` through `op`, from `lambda0` (warm start; zeros when
/// `None`): Uzawa's iteration (or the accelerated gradient), with the fixed point on `S` for
/// Coulomb's law. Reports progress through `progress`.
///
/// # Errors
/// [`ContactError::Input`] for inconsistent data, [`ContactError::NotLoaded`] when the
/// multipliers do not move the points, the loops' own errors with their last residual, and
/// [`ContactError::Operator`] when a primal solve fails.
pub fn solve(
    op: &mut dyn ContactOperator,
    points: &ContactPoints,
    law: &Law,
    params: &UzawaParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    let (n, nt) = check_input(points, law, op.n_points(), op.n_tangential())?;
    if params.accelerate && params.rule == StopRule::Paper {
        return Err(ContactError::Input(
            "acceleration needs the tight rule (the paper's rule is plain Uzawa)".into(),
        ));
    }
    let mut c = Counter::new(op);
    let (mu_max, u0) = estimate_mu_max(&mut c, points, nt, params.power_iters)?;
    let estimate_inner = c.inner;
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
    let mut d = Dual {
        c,
        points,
        params,
        canon,
        reference: multiplier_scale(points, &u0, canon),
        step,
        info: ContactInfo::new(mu_max),
        inner_tol: None,
    };
    let mut lambda = lambda0.unwrap_or_else(|| PointValues::zeros(n, nt));
    let mut u = PointValues::zeros(n, nt);
    let fresh = match law {
        Law::Frictionless | Law::Tresca(_) => {
            let radius = slip_bound(points, law, &lambda.normal);
            uzawa(&mut d, &radius, &mut lambda, &mut u, progress)?
        }
        Law::Coulomb => fixed_point(&mut d, law, &mut lambda, &mut u, progress)?,
    };
    if !fresh {
        d.c.call(&lambda, &mut u)?;
    }
    d.info.estimate_inner_iters = estimate_inner;
    finish(d, law, lambda, u)
}

/// The fixed point on the slip bound (Algorithm 4), each step a Tresca solve; returns whether
/// `u` is the displacement of the final `lambda`.
///
/// The paper starts from `S = 0` (a warm start from λ uses `F λ_n`). The update is relaxed,
/// `S ← S + ω (F λ_n - S)`: ω = 1 is the paper's iteration; under the tight rule ω halves (down
/// to 1/64) whenever the residual fails to fall, which damps the two-cycles strong coupling can
/// cause (the fixed points are the same for every ω > 0).
fn fixed_point(
    d: &mut Dual<'_, '_>,
    law: &Law,
    lambda: &mut PointValues,
    u: &mut PointValues,
    progress: &mut dyn FnMut(&Progress),
) -> Result<bool, ContactError> {
    let (points, params) = (d.points, d.params);
    let mut s = slip_bound(points, law, &lambda.normal);
    let mut omega = 1.0;
    let mut previous = f64::INFINITY;
    for l in 1..=params.max_fixed_point {
        d.info.fixed_point_iters = l;
        let mut fresh = uzawa(d, &s, lambda, u, progress)?;
        let s_new = slip_bound(points, law, &lambda.normal);
        let residual = match params.rule {
            StopRule::Tight { .. } => {
                if !fresh {
                    d.c.call(lambda, u)?;
                    fresh = true;
                }
                complementarity_residual(points, &s_new, lambda, u, d.canon, d.reference)
            }
            StopRule::Paper => {
                let diff: f64 = s_new.iter().zip(&s).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
                let norm: f64 = s_new.iter().map(|a| a * a).sum::<f64>().sqrt();
                if norm > 0.0 {
                    diff / norm
                } else {
                    diff
                }
            }
        };
        let done = match params.rule {
            StopRule::Tight { tol } => residual <= tol,
            StopRule::Paper => residual <= 1e-3,
        };
        progress(&Progress {
            stage: Stage::FixedPoint,
            iter: l,
            residual,
            counts: counts(&classify(lambda, &s_new)),
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
            return Ok(fresh);
        }
    }
    Err(ContactError::FixedPointNoConvergence {
        n_iters: params.max_fixed_point,
        residual: previous,
    })
}

/// The solution of a finished solve: its residual with the law's radius (checked against the
/// tight rule's tolerance), status and counts.
fn finish(d: Dual<'_, '_>, law: &Law, lambda: PointValues, u: PointValues) -> Result<ContactSolution, ContactError> {
    let radius = slip_bound(d.points, law, &lambda.normal);
    let mut info = d.info;
    info.complementarity = complementarity_residual(d.points, &radius, &lambda, &u, d.canon, d.reference);
    info.operator_calls = d.c.calls;
    info.inner_iters = d.c.inner - info.estimate_inner_iters;
    info.step = Some(d.step);
    if let StopRule::Tight { tol } = d.params.rule {
        if !(info.complementarity <= tol) {
            return Err(ContactError::NoConvergence {
                n_iters: info.uzawa_iters,
                residual: info.complementarity,
            });
        }
    }
    Ok(ContactSolution {
        status: classify(&lambda, &radius),
        lambda,
        u,
        info,
    })
}

impl Dual<'_, '_> {
    /// Halves the step; a [`ContactError::Diverged`] after [`MAX_BACKOFFS`] halvings.
    fn back_off(&mut self, residual: f64) -> Result<(), ContactError> {
        self.step *= 0.5;
        self.info.step_backoffs += 1;
        if self.info.step_backoffs > MAX_BACKOFFS {
            return Err(ContactError::Diverged {
                n_iters: self.info.uzawa_iters,
                residual,
                step: self.step,
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
    let mut best = f64::INFINITY;
    let mut window_best = f64::INFINITY;
    let mut window_start = 0;
    let mut last = f64::NAN;
    let mut momentum = Momentum { t: 1.0, x_prev: None };
    for k in 1..=params.max_iters {
        d.c.call(lambda, u)?;
        let r = complementarity_residual(points, radius, lambda, u, canon, reference);
        last = r;
        if !r.is_finite() {
            return Err(ContactError::Diverged {
                n_iters: d.info.uzawa_iters,
                residual: r,
                step: d.step,
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
        let (diff2, norm2) = projected_step(points, radius, d.step, lambda, u);
        if let Some(y_old) = y_old {
            momentum.extrapolate(&y_old, lambda, &points.weight);
        }
        if params.report_every > 0 && k % params.report_every == 0 {
            progress(&Progress {
                stage: Stage::Uzawa,
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
