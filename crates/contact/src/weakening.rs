//! Slip-weakening (non-monotone) friction: Coulomb's bound `μ(|u_t|) λ_n` with a coefficient
//! that falls from its static value at no slip to its dynamic value over a slip length. The
//! static problem is a hemivariational inequality and may have several solutions; it is solved
//! by a fixed point on the coefficients, each step Coulomb's law with the coefficients frozen
//! (semismooth Newton, warm-started from the last step), from the stick start (the static
//! coefficient everywhere). The map's contraction is measured and reported.

use crate::operator::AffineProblem;
use crate::points::ContactPoints;
use crate::solution::{classify, counts, slip_bound, Best, Iterate};
use crate::{
    solve_gauss_seidel, solve_newton, ContactError, ContactSolution, GaussSeidelParams, InputError, Law, NewtonParams,
    Progress, Stage,
};

/// Changes below this many times the tolerance are taken as round-off in the contraction's
/// measure.
const NOISE: f64 = 1e4;

/// How the coefficient falls with the slip `s`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weakening {
    /// `μ(s) = μ_s - (μ_s - μ_d) min(s / L, 1)`.
    Linear,
    /// `μ(s) = μ_d + (μ_s - μ_d) exp(-s / L)`.
    Exponential,
}

/// A slip-weakening friction law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlipWeakening {
    /// `μ_s`, the coefficient at no slip.
    pub static_coefficient: f64,
    /// `μ_d ≤ μ_s`, the coefficient once slid far.
    pub dynamic_coefficient: f64,
    /// `L > 0`, the slip over which the coefficient falls.
    pub slip_length: f64,
    /// The form of the fall.
    pub form: Weakening,
}

impl SlipWeakening {
    /// The coefficient at the slip `s ≥ 0`.
    pub fn coefficient(&self, slip: f64) -> f64 {
        let (ms, md, l) = (self.static_coefficient, self.dynamic_coefficient, self.slip_length);
        match self.form {
            Weakening::Linear => ms - (ms - md) * (slip / l).min(1.0),
            Weakening::Exponential => md + (ms - md) * (-slip / l).exp(),
        }
    }

    /// Checks the law's data.
    fn check(&self) -> Result<(), InputError> {
        let (ms, md, l) = (self.static_coefficient, self.dynamic_coefficient, self.slip_length);
        let ok = md >= 0.0 && ms >= md && ms.is_finite() && l > 0.0 && l.is_finite();
        if ok {
            Ok(())
        } else {
            Err(InputError::Parameter(format!(
                "slip weakening: need 0 <= dynamic {md} <= static {ms} (finite) and a slip length {l} > 0"
            )))
        }
    }
}

/// The solver of each fixed-point step (Coulomb's law with the coefficients frozen).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Inner {
    /// Semismooth Newton on the whole problem (the default).
    #[default]
    Newton,
    /// Block Gauss-Seidel, point by point (a second method, for checks).
    GaussSeidel,
}

/// Parameters of [`solve_slip_weakening`].
#[derive(Clone, Copy, Debug)]
pub struct WeakeningParams {
    /// Newton's parameters for each step (its tolerance the complementarity residual's; the
    /// Gauss-Seidel steps take the same tolerance, interrupt and measure).
    pub newton: NewtonParams,
    /// The solver of each step.
    pub inner: Inner,
    /// The fixed point stops where no coefficient changes by more than this times `μ_s`.
    pub tol: f64,
    /// Fixed-point steps at most.
    pub max_iters: usize,
}

impl Default for WeakeningParams {
    fn default() -> Self {
        WeakeningParams {
            newton: NewtonParams::default(),
            inner: Inner::Newton,
            tol: 1e-10,
            max_iters: 100,
        }
    }
}

/// Solves Coulomb's law with the slip-weakening coefficient `law` on `points` (their own
/// coefficients are not read) by the fixed point on the coefficients, from the stick start.
/// The returned solution's `info` counts the fixed-point steps (`fixed_point_iters`), Newton's
/// steps summed (`newton_iters`), and the measured `contraction`; its `complementarity` is
/// Coulomb's residual at the last coefficients, which the slips of the answer reproduce to
/// `tol`.
///
/// # Errors
/// The law's data out of range ([`ContactError::Input`]); a Newton step's error; where the
/// fixed point does not settle within `max_iters`, [`ContactError::FixedPointNoConvergence`]
/// with the measured contraction and the best iterate.
pub fn solve_slip_weakening<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    law: &SlipWeakening,
    params: &WeakeningParams,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    law.check()?;
    let n = points.len();
    let mut frozen = points.clone();
    frozen.friction = vec![law.static_coefficient; n];
    let scale = law.static_coefficient.max(f64::MIN_POSITIVE);
    let (mut start, mut newton_iters) = (None, 0);
    let (mut last_change, mut contraction): (Option<f64>, Option<f64>) = (None, None);
    let mut best = Best::new(1.0);
    for k in 1..=params.max_iters {
        let mut sol = match params.inner {
            Inner::Newton => solve_newton(problem, &frozen, &Law::Coulomb, &params.newton, start.take(), progress)?,
            Inner::GaussSeidel => {
                let gs = GaussSeidelParams {
                    tol: params.newton.tol,
                    measure: params.newton.measure,
                    interrupt: params.newton.interrupt,
                    power_iters: params.newton.power_iters,
                    ..Default::default()
                };
                solve_gauss_seidel(problem, &frozen, &Law::Coulomb, &gs, start.take(), progress)?
            }
        };
        newton_iters += sol.info.newton_iters;
        let next: Vec<f64> = (0..n).map(|i| law.coefficient(sol.u.tangential_norm(i))).collect();
        let change = next
            .iter()
            .zip(&frozen.friction)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale;
        // the ratio of successive changes, where both stand above the round-off of the step's
        // own solve (near the end they are noise)
        if let Some(before) = last_change.filter(|&b| b > 0.0 && change > NOISE * params.tol) {
            contraction = Some(contraction.unwrap_or(0.0).max(change / before));
        }
        last_change = Some(change);
        best.offer(&sol.lambda, &sol.u, change);
        progress(&Progress {
            stage: Stage::FixedPoint,
            iter: k,
            residual: change,
            counts: counts(&classify(
                &sol.lambda,
                &slip_bound(&frozen, &Law::Coulomb, &sol.lambda.normal),
            )),
        });
        if change <= params.tol {
            sol.info.fixed_point_iters = k;
            sol.info.newton_iters = newton_iters;
            sol.info.contraction = contraction;
            return Ok(sol);
        }
        frozen.friction = next;
        start = Some(sol.lambda);
    }
    Err(ContactError::FixedPointNoConvergence {
        n_iters: params.max_iters,
        contraction,
        residual: last_change.unwrap_or(f64::NAN),
        best: best.take().map(|it: Iterate| Box::new(it)),
    })
}
