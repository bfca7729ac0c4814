//! Slip-weakening (non-monotone) friction: Coulomb's bound `μ(|u_t|) λ_n` with a coefficient
//! that falls from its static value at no slip to its dynamic value over a slip length. The
//! static problem is a hemivariational inequality and may have several solutions; it is solved
//! by a fixed point on the coefficients, each step Coulomb's law with the coefficients frozen
//! (semismooth Newton, warm-started from the last step), from the stick start (the static
//! coefficient everywhere). The map's contraction is measured and reported.

use crate::newton::{solve_newton_cached, NewtonCache};
use crate::operator::AffineProblem;
use crate::points::ContactPoints;
use crate::solution::{classify, counts, slip_bound, Best, Iterate};
use crate::{
    solve_gauss_seidel, ContactError, ContactSolution, GaussSeidelParams, InputError, Law, NewtonParams, Progress,
    Stage,
};

/// Changes below this many times the tolerance are taken as round-off in the contraction's
/// measure.
const NOISE: f64 = 1e4;

/// The change of the coefficients (relative to `μ_s`) below which Newton on the law itself
/// takes over from the fixed point.
const POLISH: f64 = 1e-2;

/// Steps of history in Anderson's mixing (Walker and Ni, SIAM J. Numer. Anal. 49 (2011) 1715).
pub const ANDERSON_DEPTH: usize = 3;

/// `max_i |a_i - b_i|`.
fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Anderson's acceleration of a fixed point `x = G(x)` (type II, Walker and Ni 2011): from the
/// last `depth` pairs `(x_j, G(x_j))`, `x_{k+1} = G(x_k) - ΔG γ` with `γ` the least-squares
/// coefficients of the residuals' differences `ΔF` against `f_k = G(x_k) - x_k`. Its vectors
/// may be spread over several processes ([`Anderson::step_spread`]).
pub struct Anderson {
    depth: usize,
    /// The last pairs `(x_j, G(x_j))`, oldest first.
    history: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Anderson {
    /// No history yet; `depth` pairs at most (at most [`ANDERSON_DEPTH`]: its small system
    /// is solved in place).
    pub fn new(depth: usize) -> Self {
        Anderson {
            depth: depth.min(ANDERSON_DEPTH),
            history: vec![],
        }
    }

    /// The next iterate from `x` and `g = G(x)`.
    pub fn step(&mut self, x: &[f64], g: &[f64]) -> Vec<f64> {
        match self.step_spread(x, g, |_| Ok::<_, std::convert::Infallible>(())) {
            Ok(next) => next,
            Err(never) => match never {},
        }
    }

    /// [`Anderson::step`] on vectors spread over several processes, each calling it with its
    /// own part of `x` and `g`: `sum` replaces the inner products it is given (this process's
    /// share of each) by their sums over the processes (collective), so that every process
    /// takes the same `γ`.
    ///
    /// # Errors
    /// `sum`'s.
    pub fn step_spread<E>(
        &mut self,
        x: &[f64],
        g: &[f64],
        mut sum: impl FnMut(&mut [f64]) -> Result<(), E>,
    ) -> Result<Vec<f64>, E> {
        self.history.push((x.to_vec(), g.to_vec()));
        if self.history.len() > self.depth + 1 {
            self.history.remove(0);
        }
        let f = |j: usize| -> Vec<f64> {
            let (x, g) = &self.history[j];
            g.iter().zip(x).map(|(a, b)| a - b).collect()
        };
        let last = self.history.len() - 1;
        let fk = f(last);
        let m = last;
        if m == 0 {
            return Ok(g.to_vec());
        }
        // columns j = 0..m: ΔF_j = f_{j+1} - f_j, ΔG_j = g_{j+1} - g_j
        let df: Vec<Vec<f64>> = (0..m)
            .map(|j| f(j + 1).iter().zip(&f(j)).map(|(a, b)| a - b).collect())
            .collect();
        // the normal equations' entries, then the right-hand side, summed at once
        let mut products = vec![0.0; m * m + m];
        for i in 0..m {
            for j in 0..m {
                products[i * m + j] = dot(&df[i], &df[j]);
            }
            products[m * m + i] = dot(&df[i], &fk);
        }
        sum(&mut products)?;
        let mut a = [[0.0; ANDERSON_DEPTH]; ANDERSON_DEPTH];
        let mut b = [0.0; ANDERSON_DEPTH];
        for i in 0..m {
            a[i][..m].copy_from_slice(&products[i * m..(i + 1) * m]);
            b[i] = products[m * m + i];
        }
        // a touch of Tikhonov: nearly parallel differences make the normal equations singular
        let trace: f64 = (0..m).map(|i| a[i][i]).sum();
        for (i, row) in a.iter_mut().enumerate().take(m) {
            row[i] += 1e-12 * trace.max(f64::MIN_POSITIVE);
        }
        let Some(gamma) = solve_spd(a, b, m) else {
            return Ok(g.to_vec());
        };
        let mut next = g.to_vec();
        for (j, &gj) in gamma.iter().enumerate().take(m) {
            let (g1, g0) = (&self.history[j + 1].1, &self.history[j].1);
            for (v, (a, b)) in next.iter_mut().zip(g1.iter().zip(g0)) {
                *v -= gj * (a - b);
            }
        }
        Ok(next)
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves the symmetric positive definite `m x m` system (`m ≤ 3`) by Cholesky; `None` where
/// it is not positive definite.
fn solve_spd(
    mut a: [[f64; ANDERSON_DEPTH]; ANDERSON_DEPTH],
    mut b: [f64; ANDERSON_DEPTH],
    m: usize,
) -> Option<[f64; ANDERSON_DEPTH]> {
    for j in 0..m {
        for k in 0..j {
            a[j][j] -= a[j][k] * a[j][k];
        }
        if !(a[j][j] > 0.0) {
            return None;
        }
        a[j][j] = a[j][j].sqrt();
        for i in j + 1..m {
            for k in 0..j {
                a[i][j] -= a[i][k] * a[j][k];
            }
            a[i][j] /= a[j][j];
        }
    }
    for i in 0..m {
        for k in 0..i {
            b[i] -= a[i][k] * b[k];
        }
        b[i] /= a[i][i];
    }
    for i in (0..m).rev() {
        for k in i + 1..m {
            b[i] -= a[k][i] * b[k];
        }
        b[i] /= a[i][i];
    }
    Some(b)
}

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

    /// `dμ/ds` at the slip `s ≥ 0` (the linear form's right derivative at `s = L`: 0).
    pub fn slope(&self, slip: f64) -> f64 {
        let (ms, md, l) = (self.static_coefficient, self.dynamic_coefficient, self.slip_length);
        match self.form {
            Weakening::Linear if slip < l => -(ms - md) / l,
            Weakening::Linear => 0.0,
            Weakening::Exponential => -(ms - md) / l * (-slip / l).exp(),
        }
    }

    /// `d²μ/ds²` at the slip `s ≥ 0` (0 on the linear form, its kink at `s = L` aside).
    pub fn curvature(&self, slip: f64) -> f64 {
        let (ms, md, l) = (self.static_coefficient, self.dynamic_coefficient, self.slip_length);
        match self.form {
            Weakening::Linear => 0.0,
            Weakening::Exponential => (ms - md) / (l * l) * (-slip / l).exp(),
        }
    }

    /// Checks the law's data.
    pub(crate) fn check(&self) -> Result<(), InputError> {
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
    /// Anderson's mixing of the last steps instead of the plain step. Off by default: the plain
    /// iteration from the stick start decreases the coefficients monotonically where the map
    /// does (more slip, a lower coefficient, more slip) and ends on the branch nearest to
    /// sticking; the mixed steps reach a fixed point in about half the steps (24 against 46
    /// on `paper-slip-weakening`), but may land on another branch of a problem with several.
    pub accelerate: bool,
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
            accelerate: false,
            tol: 1e-10,
            max_iters: 100,
        }
    }
}

/// One step of the fixed point: Coulomb's law with the coefficients of `frozen`, by `inner`.
fn frozen_step<P: AffineProblem>(
    problem: &mut P,
    frozen: &ContactPoints,
    inner: Inner,
    newton: &NewtonParams,
    start: Option<crate::PointValues>,
    progress: &mut dyn FnMut(&Progress),
    shared: &mut NewtonCache,
) -> Result<ContactSolution, ContactError> {
    match inner {
        Inner::Newton => solve_newton_cached(problem, frozen, &Law::Coulomb, newton, start, progress, shared),
        Inner::GaussSeidel => {
            let gs = GaussSeidelParams {
                tol: newton.tol,
                measure: newton.measure,
                interrupt: newton.interrupt,
                power_iters: newton.power_iters,
                ..Default::default()
            };
            solve_gauss_seidel(problem, frozen, &Law::Coulomb, &gs, start, progress)
        }
    }
}

/// Newton on the law itself from an iterate of the fixed point: each weakening point's
/// coefficient at its slip, differentiated through it ([`NewtonParams::weakening`]), from the
/// iterate's coefficients and multipliers.
struct Polish<'a> {
    /// The points with their laws.
    points: &'a ContactPoints,
    /// The points with the iterate's coefficients.
    frozen: &'a ContactPoints,
    /// The fixed point's Newton parameters.
    newton: &'a NewtonParams,
    /// The iterate's multipliers.
    start: &'a crate::PointValues,
}

impl Polish<'_> {
    fn solve<P: AffineProblem>(
        &self,
        problem: &mut P,
        progress: &mut dyn FnMut(&Progress),
        shared: &mut NewtonCache,
    ) -> Result<ContactSolution, ContactError> {
        let direct = NewtonParams {
            weakening: true,
            schedule: crate::Schedule::of(crate::ProblemClass::SlipWeakening),
            ..*self.newton
        };
        let weakening = ContactPoints {
            weakening: self.points.weakening.clone(),
            ..self.frozen.clone()
        };
        let start = Some(self.start.clone());
        solve_newton_cached(problem, &weakening, &Law::Coulomb, &direct, start, progress, shared)
    }
}

/// `|G(x) - G(x₀)|_∞ / |x - x₀|_∞` (relative to `scale`) between the last pair `(x₀, G(x₀))`
/// and `(x, G(x))`, where the step stands above [`NOISE`] times `tol`.
fn secant_ratio(last: Option<&(Vec<f64>, Vec<f64>)>, (x, g): (&[f64], &[f64]), scale: f64, tol: f64) -> Option<f64> {
    let (x0, g0) = last?;
    let dx = max_difference(x, x0) / scale;
    (dx > NOISE * tol).then(|| max_difference(g, g0) / scale / dx)
}

/// Solves Coulomb's law with each point's coefficient falling with its slip by its own law
/// ([`ContactPoints::weakening`]; a point without one keeps its coefficient `friction`) by the
/// fixed point on the coefficients, from the stick start.
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
    params: &WeakeningParams,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    solve_slip_weakening_cached(problem, points, params, progress, &mut NewtonCache::default())
}

/// [`solve_slip_weakening`], its Newton solves sharing what they may with the other solves of
/// `problem`'s compliance in `cache` ([`NewtonCache`]).
///
/// # Errors
/// As [`solve_slip_weakening`].
pub fn solve_slip_weakening_cached<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    params: &WeakeningParams,
    progress: &mut dyn FnMut(&Progress),
    shared: &mut NewtonCache,
) -> Result<ContactSolution, ContactError> {
    points.validate()?;
    // each step's points: the coefficients frozen, none weakening within the step
    let mut frozen = ContactPoints {
        weakening: vec![],
        ..points.clone()
    };
    // the stick start: each point's coefficient at what it slipped before (μ_s where nothing)
    frozen.friction = points.coefficients_at(&crate::PointValues::zeros(points.len(), points.n_tangential()));
    let scale = points
        .weakening
        .iter()
        .flatten()
        .fold(f64::MIN_POSITIVE, |m, w| m.max(w.static_coefficient));
    let (mut start, mut newton_iters) = (None, 0);
    let mut contraction: Option<f64> = None;
    let mut best = Best::new();
    let mut anderson = Anderson::new(ANDERSON_DEPTH);
    let mut previous: Option<(Vec<f64>, Vec<f64>)> = None;
    let mut newton = params.newton;
    let mut polished = false;
    for k in 1..=params.max_iters {
        let mut sol = frozen_step(problem, &frozen, params.inner, &newton, start.take(), progress, shared)?;
        newton_iters += sol.info.newton_iters;
        // the operator is the same at every step: its μ_max once
        newton.mu_max = Some(sol.info.mu_max);
        let next = points.coefficients_at(&sol.u);
        let change = max_difference(&next, &frozen.friction) / scale;
        // the map's secant ratio |G(μ_k) - G(μ_j)| / |μ_k - μ_j| between successive iterates,
        // where the step stands above the round-off of the step's own solve
        if let Some(ratio) = secant_ratio(previous.as_ref(), (&frozen.friction, &next), scale, params.tol) {
            contraction = Some(contraction.unwrap_or(0.0).max(ratio));
        }
        previous = Some((frozen.friction.clone(), next.clone()));
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
        // near the fixed point, Newton on the law itself: the same branch (the solution near
        // the iterate), in a few quadratic steps; where it does not converge, the fixed point
        // goes on
        if change > params.tol && change <= POLISH && !polished && params.inner == Inner::Newton {
            polished = true;
            let at = Polish {
                points,
                frozen: &frozen,
                newton: &newton,
                start: &sol.lambda,
            };
            if let Ok(mut polish) = at.solve(problem, progress, shared) {
                polish.info.fixed_point_iters = k;
                polish.info.newton_iters += newton_iters;
                polish.info.contraction = contraction;
                return Ok(polish);
            }
        }
        if change <= params.tol {
            sol.info.fixed_point_iters = k;
            sol.info.newton_iters = newton_iters;
            sol.info.contraction = contraction;
            return Ok(sol);
        }
        // Anderson's mixing of the last steps (the plain step `next` where it has no history),
        // kept within the law's range
        frozen.friction = if params.accelerate {
            anderson.step(&frozen.friction, &next)
        } else {
            next
        };
        for (i, m) in frozen.friction.iter_mut().enumerate() {
            *m = match points.weakening_of(i) {
                Some(w) => m.clamp(w.dynamic_coefficient, w.static_coefficient),
                None => points.friction[i],
            };
        }
        start = Some(sol.lambda);
    }
    Err(ContactError::FixedPointNoConvergence {
        n_iters: params.max_iters,
        contraction,
        residual: best.residual().unwrap_or(f64::NAN),
        best: best.take().map(|it: Iterate| Box::new(it)),
    })
}
