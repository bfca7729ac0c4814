//! Uzawa's algorithm with projections (the paper's Algorithm 2, signs of docs/theory.md), its
//! accelerated version, and the fixed point on the slip bound for Coulomb friction
//! (Algorithm 4), with the step from the dual operator's largest eigenvalue.

use crate::operator::ContactOperator;
use crate::points::{ContactPoints, PointValues};
use crate::projection::project_nonnegative;
use crate::solution::{
    classify, complementarity_residual, counts, desaxce_residual, slip_bound, Best, Counter, Preamble,
};
use crate::InputError;
use crate::{ContactError, ContactInfo, ContactSolution, Interrupt, Iterate, Law, Measure, Progress, Stage, Stall};

/// When the loops stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StopRule {
    /// The complementarity residual (docs/theory.md) at most `tol`; for Coulomb the residual with
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

/// Parameters of [`solve_uzawa`].
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
    /// The residual the tight rule brings below its tolerance.
    pub measure: Measure,
    /// A deadline or a cancel flag.
    pub interrupt: Interrupt,
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
            measure: Measure::Complementarity,
            interrupt: Interrupt::NONE,
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
            let (l, ut) = (lambda.tangential_of_mut(i), u.tangential_of(i));
            for q in 0..nt {
                buf[q] = l[q] + r * ut[q];
            }
            points.project_friction(i, &mut buf[..nt], radius[i]);
            for q in 0..nt {
                diff2 += (buf[q] - l[q]).powi(2);
                norm2 += buf[q] * buf[q];
                l[q] = buf[q];
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
    /// The tolerance of the Tresca solves of the friction fixed point, where it is not the
    /// rule's: a fraction of the fixed point's last residual, so that the inexact inner solves
    /// do not put a floor under the outer residual (nor cycle at a loose tolerance).
    inner_tol: Option<f64>,
    /// The contact displacement under the loads alone.
    u0: PointValues,
    /// The best iterate of the law itself (Coulomb: with the radius `F λ_n`) seen by the
    /// tight rule, with its residual.
    best: Best,
}

/// Solves the contact problem for `law` through `op`, from `lambda0` (warm start; zeros when
/// `None`): Uzawa's iteration (or the accelerated gradient), with the fixed point on `S` for
/// Coulomb's law. Reports progress through `progress`.
///
/// # Errors
/// [`ContactError::Input`] for inconsistent data, [`ContactError::NotLoaded`] when the
/// multipliers do not move the points, the loops' own errors with their last residual, and
/// [`ContactError::Operator`] when a primal solve fails.
pub fn solve_uzawa(
    op: &mut dyn ContactOperator,
    points: &ContactPoints,
    law: &Law,
    params: &UzawaParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    points.refuse_weakening()?;
    if !points.all_rigid() {
        // its projections are onto Signorini's cone: a compliant foundation's law is no
        // projection
        return Err(InputError::Unsupported(
            "normal compliance is solved by semismooth Newton or block Gauss-Seidel (solve_newton, solve_gauss_seidel), not by Uzawa's projections",
        )
        .into());
    }
    if params.accelerate && params.rule == StopRule::Paper {
        return Err(
            InputError::Unsupported("acceleration needs the tight rule (the paper's rule is plain Uzawa)").into(),
        );
    }
    let mut c = Counter::new(op);
    let pre = Preamble::new(&mut c, points, law, params.power_iters, None)?;
    let mut lambda = pre.start(lambda0)?;
    let Preamble {
        n,
        nt,
        mu_max,
        u0,
        reference,
    } = pre;
    let estimate_inner = c.inner;
    // plain Uzawa converges for r < 2/μ_max; the accelerated gradient wants r ≤ 1/μ_max
    let step = params.step.unwrap_or(if params.accelerate {
        1.0 / mu_max
    } else {
        params.safety / mu_max
    });
    if !(step > 0.0 && step.is_finite()) {
        return Err(InputError::Parameter(format!("Uzawa step {step} must be positive")).into());
    }
    let canon = 1.0 / mu_max;
    let mut d = Dual {
        c,
        points,
        params,
        canon,
        reference,
        step,
        info: ContactInfo::new(mu_max),
        inner_tol: None,
        u0,
        best: Best::new(),
    };
    let mut u = PointValues::zeros(n, nt);
    let outcome = match law {
        Law::Frictionless | Law::Tresca(_) => {
            let radius = slip_bound(points, law, &lambda.normal);
            uzawa(&mut d, Some(law), &radius, &mut lambda, &mut u, progress)
        }
        Law::Coulomb => fixed_point(&mut d, law, &mut lambda, &mut u, progress),
    };
    // a loop that stopped short (an inner solve of the fixed point, say) may have met the law
    // to the tolerance on the way: that is an answer, not an error
    let fresh = match outcome {
        Ok(fresh) => fresh,
        Err(e) => match d.best.take() {
            Some(best) if d.tol().is_some_and(|tol| best.residual <= tol) => {
                (lambda, u) = (best.lambda, best.u);
                true
            }
            Some(best) => return Err(e.with_best(best)),
            None => return Err(e),
        },
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
/// cause (the fixed points are the same for every ω > 0), and doubles again (up to 1) after
/// two falls in a row. Under the tight rule each Tresca solve goes to a tenth of the fixed
/// point's last residual (1e-3 at most, a tenth of the rule's tolerance at least): solving the
/// first Tresca problems to round-off while `S` is far from its fixed point only costs time
/// (minutes of full solves, measured), and an inner solve only as exact as the outer tolerance
/// would leave an error of that size in `S`, on which the outer residual could cycle above it.
/// Steps that no longer contract ([`FIXED_POINT_PATIENCE`] without a better residual) stop the
/// loop with the measured contraction.
fn fixed_point(
    d: &mut Dual<'_, '_>,
    law: &Law,
    lambda: &mut PointValues,
    u: &mut PointValues,
    progress: &mut dyn FnMut(&Progress),
) -> Result<bool, ContactError> {
    let (points, params) = (d.points, d.params);
    let mut s = slip_bound(points, law, &lambda.normal);
    let mut relax = Relaxation { omega: 1.0, falls: 0 };
    let mut previous = f64::INFINITY;
    // the map's measured contraction: the changes of S, and the best residual's age
    let mut moves: Vec<f64> = vec![];
    let (mut best, mut since_best) = (f64::INFINITY, 0);
    for l in 1..=params.max_fixed_point {
        d.info.fixed_point_iters = l;
        if let Some(tol) = d.tol() {
            // a tenth of the last outer residual (no tighter than needed while S is far from
            // its fixed point), and a tenth of the tolerance at the end
            d.inner_tol = Some((0.1 * previous).min(1e-3).max(0.1 * tol).max(1e-15));
        }
        let mut fresh = uzawa(d, None, &s, lambda, u, progress)?;
        let s_new = slip_bound(points, law, &lambda.normal);
        let residual = match params.rule {
            StopRule::Tight { .. } => {
                if !fresh {
                    d.c.call(lambda, u)?;
                    fresh = true;
                }
                let r = d.residual(Some(law), &s_new, lambda, u);
                d.offer(r, lambda, u);
                r
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
            if relax.update(residual, previous, tol) {
                d.info.relaxations += 1;
            }
        }
        let omega = relax.omega;
        previous = residual;
        moves.push(s_new.iter().zip(&s).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt());
        s = if omega == 1.0 {
            s_new
        } else {
            s.iter().zip(&s_new).map(|(a, b)| a + omega * (b - a)).collect()
        };
        if done {
            return Ok(fresh);
        }
        if residual < 0.9 * best {
            (best, since_best) = (residual, 0);
        } else {
            since_best += 1;
        }
        if params.rule != StopRule::Paper && since_best >= FIXED_POINT_PATIENCE {
            // steps that no longer contract: more of them would only cost time
            return Err(ContactError::FixedPointNoConvergence {
                n_iters: l,
                contraction: contraction(&moves),
                residual,
                best: d.best(),
            });
        }
        if let Some(why) = params.interrupt.check() {
            return Err(ContactError::Interrupted {
                why,
                n_iters: d.info.uzawa_iters,
                residual,
                best: d.best(),
            });
        }
    }
    Err(ContactError::FixedPointNoConvergence {
        n_iters: params.max_fixed_point,
        contraction: None,
        residual: previous,
        best: d.best(),
    })
}

/// The relaxation `ω` of the fixed point on `S`: halved where a step did not lower the
/// residual (down to 1/64), doubled back after two steps that did (a damping that is no longer
/// needed only slows the iteration down).
struct Relaxation {
    omega: f64,
    falls: usize,
}

impl Relaxation {
    /// Updates `ω` from the step's residual and the previous one; true where it halved.
    fn update(&mut self, residual: f64, previous: f64, tol: f64) -> bool {
        if residual >= previous && residual > 100.0 * tol && self.omega > 1.0 / 64.0 {
            self.omega *= 0.5;
            self.falls = 0;
            return true;
        }
        if residual < previous {
            self.falls += 1;
            if self.falls >= 2 && self.omega < 1.0 {
                self.omega = (2.0 * self.omega).min(1.0);
                self.falls = 0;
            }
        }
        false
    }
}

/// Fixed-point steps without a residual a tenth below the best before the loop is stopped as
/// not contracting (enough for the relaxation to fall from 1 to its floor 1/64 and try there).
pub const FIXED_POINT_PATIENCE: usize = 12;

/// The geometric mean of the ratios of successive changes over the last steps.
fn contraction(moves: &[f64]) -> Option<f64> {
    let last = &moves[moves.len().saturating_sub(FIXED_POINT_PATIENCE)..];
    let ratios: Vec<f64> = last
        .windows(2)
        .filter(|w| w[0] > 0.0 && w[1] > 0.0)
        .map(|w| (w[1] / w[0]).ln())
        .collect();
    (!ratios.is_empty()).then(|| (ratios.iter().sum::<f64>() / ratios.len() as f64).exp())
}

/// The solution of a finished solve: its residual with the law's radius (checked against the
/// tight rule's tolerance), status and counts.
fn finish(d: Dual<'_, '_>, law: &Law, lambda: PointValues, u: PointValues) -> Result<ContactSolution, ContactError> {
    let radius = slip_bound(d.points, law, &lambda.normal);
    let residual = d.residual(Some(law), &radius, &lambda, &u);
    let best = d.best();
    let mut info = d.info;
    info.complementarity = complementarity_residual(d.points, &radius, &lambda, &u, d.canon, d.reference);
    info.residual = residual;
    info.operator_calls = d.c.calls;
    info.inner_iters = d.c.inner - info.estimate_inner_iters;
    info.step = Some(d.step);
    if let StopRule::Tight { tol } = d.params.rule {
        if !(info.residual <= tol) {
            return Err(ContactError::NoConvergence {
                n_iters: info.uzawa_iters,
                residual: info.residual,
                best,
            });
        }
    }
    Ok(ContactSolution {
        status: classify(&lambda, &radius),
        lambda,
        u,
        info,
        electric: None,
    })
}

impl Dual<'_, '_> {
    /// The residual of `(λ, u)` by the parameters' measure, for the slip bound `radius`
    /// (a Tresca solve's) or for `law` itself.
    fn residual(&self, law: Option<&Law>, radius: &[f64], lambda: &PointValues, u: &PointValues) -> f64 {
        match (self.params.measure, law) {
            (Measure::Complementarity, _) => {
                complementarity_residual(self.points, radius, lambda, u, self.canon, self.reference)
            }
            (Measure::DeSaxce, Some(law)) => desaxce_residual(self.points, law, lambda, u, &self.u0),
            (Measure::DeSaxce, None) => {
                desaxce_residual(self.points, &Law::Tresca(radius.to_vec()), lambda, u, &self.u0)
            }
            (Measure::Both, law) => {
                let complementarity =
                    complementarity_residual(self.points, radius, lambda, u, self.canon, self.reference);
                let siconos = match law {
                    Some(law) => desaxce_residual(self.points, law, lambda, u, &self.u0),
                    None => desaxce_residual(self.points, &Law::Tresca(radius.to_vec()), lambda, u, &self.u0),
                };
                complementarity.max(siconos)
            }
        }
    }

    /// Keeps `(λ, u)` if it is the best iterate of the law itself.
    fn offer(&mut self, residual: f64, lambda: &PointValues, u: &PointValues) {
        self.best.offer(lambda, u, residual);
    }

    /// The loop's divergence at the residual `r`, with the best iterate.
    fn diverged(&self, r: f64) -> ContactError {
        ContactError::Diverged {
            n_iters: self.info.uzawa_iters,
            residual: r,
            step: self.step,
            best: self.best(),
        }
    }

    /// The best iterate, boxed for an error.
    fn best(&self) -> Option<Box<Iterate>> {
        self.best.boxed()
    }

    /// The rule's tolerance (`None` under the paper's rule).
    fn tol(&self) -> Option<f64> {
        match self.params.rule {
            StopRule::Tight { tol } => Some(tol),
            StopRule::Paper => None,
        }
    }

    /// Halves the step after a stall (the residual did not grow: a step too large for an
    /// under-estimated `μ_max`, or a problem too hard for it); a [`ContactError::Stalled`]
    /// after [`MAX_BACKOFFS`] halvings.
    fn back_off(&mut self, residual: f64) -> Result<(), ContactError> {
        self.step *= 0.5;
        self.info.step_backoffs += 1;
        if self.info.step_backoffs > MAX_BACKOFFS {
            return Err(ContactError::Stalled {
                stage: Stage::Uzawa,
                n_iters: self.info.uzawa_iters,
                residual,
                reason: Stall::NoProgress,
                best: self.best(),
            });
        }
        Ok(())
    }
}

/// Iterations over which the rate of a first-order loop is measured.
const RATE_WINDOW: usize = 2000;

/// The residual at the last mark, a window ago.
#[derive(Default)]
struct Rate {
    at_mark: Option<f64>,
}

impl Rate {
    fn mark(&mut self, r: f64) {
        self.at_mark = Some(r);
    }

    /// The iterations the loop needs from `r` to `target` at the rate of the last window;
    /// `None` where it fell by less than 1 % (a stall, which the loop's own rules handle, with
    /// a smaller step first).
    fn needed(&self, r: f64, target: f64) -> Option<usize> {
        let before = self.at_mark?;
        if !(r < 0.99 * before && r > target && target > 0.0) {
            return None;
        }
        let per_step = (r / before).ln() / RATE_WINDOW as f64;
        let steps = (target / r).ln() / per_step;
        Some(if steps.is_finite() && steps < 1e15 {
            steps.ceil() as usize
        } else {
            usize::MAX / 2
        })
    }
}

/// Stops a loop whose measured rate would not reach its target within its limit now, not at
/// the limit (hours of full solves, on an ill-conditioned dual): every [`RATE_WINDOW`] steps,
/// from the residual `r` at step `k`.
fn too_slow(d: &Dual<'_, '_>, rate: &mut Rate, k: usize, r: f64) -> Result<(), ContactError> {
    let (Some(tol), true) = (d.tol(), k.is_multiple_of(RATE_WINDOW)) else {
        return Ok(());
    };
    let target = d.inner_tol.unwrap_or(tol);
    if let Some(needed) = rate.needed(r, target) {
        if k + needed > d.params.max_iters {
            return Err(ContactError::TooSlow {
                n_iters: d.info.uzawa_iters,
                residual: r,
                target,
                needed,
                limit: d.params.max_iters,
                best: d.best(),
            });
        }
    }
    rate.mark(r);
    Ok(())
}

/// Uzawa iterations for a given radius. Returns whether `u` is the displacement of the final
/// `lambda` (true under the tight rule; under the paper's rule the last update is not solved).
///
/// A residual far above the best seen (a thousandfold, after ten steps) halves the step and,
/// after [`MAX_BACKOFFS`] halvings, is a [`ContactError::Diverged`]; so is a residual that is
/// not a number. No 1 % gain on the best over [`STALL_WINDOW`] steps also halves the step (a
/// step too large for an under-estimated `μ_max`), and is a [`ContactError::Stalled`] in the
/// end. Where the law itself is met to the rule's tolerance, none of these is an error.
fn uzawa(
    d: &mut Dual<'_, '_>,
    law: Option<&Law>,
    radius: &[f64],
    lambda: &mut PointValues,
    u: &mut PointValues,
    progress: &mut dyn FnMut(&Progress),
) -> Result<bool, ContactError> {
    let (points, params) = (d.points, d.params);
    let mut best = f64::INFINITY;
    let mut window_best = f64::INFINITY;
    let mut window_start = 0;
    let mut last = f64::NAN;
    let mut momentum = Momentum { t: 1.0, x_prev: None };
    let mut rate = Rate::default();
    for k in 1..=params.max_iters {
        d.c.call(lambda, u)?;
        let r = d.residual(law, radius, lambda, u);
        last = r;
        if law.is_some() {
            d.offer(r, lambda, u);
        }
        if !r.is_finite() {
            return Err(d.diverged(r));
        }
        if let Some(tol) = d.tol() {
            if r <= d.inner_tol.unwrap_or(tol) {
                return Ok(true);
            }
        }
        if let Some(why) = params.interrupt.check() {
            return Err(ContactError::Interrupted {
                why,
                n_iters: d.info.uzawa_iters,
                residual: r,
                best: d.best(),
            });
        }
        let diverging = r > 1e3 * best && k > 10;
        if r < 0.99 * window_best {
            window_best = r;
            window_start = k;
        }
        if diverging || k - window_start >= STALL_WINDOW {
            if let Err(e) = d.back_off(r) {
                // a tighter inner tolerance than the law needs may stall at the law's own
                if law.is_some() && d.tol().is_some_and(|tol| r <= tol) {
                    return Ok(true);
                }
                return Err(if diverging { d.diverged(r) } else { e });
            }
            best = r;
            window_best = r;
            window_start = k;
            momentum = Momentum { t: 1.0, x_prev: None };
        }
        best = best.min(r);
        too_slow(d, &mut rate, k, r)?;
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
        best: d.best(),
    })
}
