//! What a contact solve returns and how it is judged, the same for every solver: the law, the
//! solution with its counts ([`ContactInfo`]), progress lines, the slip bound, the
//! scale-free complementarity residual and the stick/slip status of docs/theory.md.

use crate::operator::ContactOperator;
use crate::points::{ContactPoints, PointValues, Status};
use crate::projection::{norm, project_cone, project_disc, project_nonnegative};
use crate::InputError;
use crate::{ContactError, OperatorError};

/// The friction law.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// Signorini contact alone (no tangential multiplier).
    Frictionless,
    /// Tresca friction with a given slip bound per point.
    Tresca(Vec<f64>),
    /// Coulomb friction `S = F λ_n`: by the fixed point on `S` ([`crate::solve_uzawa`]), or directly
    /// ([`crate::solve_newton`]).
    Coulomb,
}

/// What a contact solve reports, whichever solver ran: each field means one thing, and a
/// count is 0 (a step `None`) where its loop did not run.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactInfo {
    /// First-order steps (Uzawa or the accelerated gradient), summed over the fixed point.
    pub uzawa_iters: usize,
    /// Block Gauss–Seidel sweeps: the method's own, those [`crate::solve_newton`] runs first
    /// (its stage 0), or its fallback's for Coulomb's law.
    pub sweeps: usize,
    /// Semismooth Newton steps ([`crate::solve_newton`]).
    pub newton_iters: usize,
    /// Newton steps on the coarser problems of Newton's nested start (each on a fraction of
    /// the points: [`crate::solve_newton`]), not counted in `newton_iters`.
    pub coarse_newton_iters: usize,
    /// Outer steps of Newton's proximal stage (each a regularised problem solved by Newton).
    pub proximal_iters: usize,
    /// Step halvings in Newton's line search, summed.
    pub line_search_cuts: usize,
    /// Whether Newton stalled and the accelerated gradient finished the solve.
    pub fallback: bool,
    /// The stages of Newton's schedule that ran, in order (empty for the other solvers).
    pub stages: Vec<crate::Phase>,
    /// Fixed-point iterations on the slip bound (0 when the solve has none).
    pub fixed_point_iters: usize,
    /// Inner iterations reported by the operator (PCG) in the first-order loops, summed.
    pub inner_iters: usize,
    /// Inner iterations spent estimating `μ_max` (power iteration).
    pub estimate_inner_iters: usize,
    /// Calls of the operator (primal solves), including the power iteration.
    pub operator_calls: usize,
    /// The first-order step `r` last used; `None` when no first-order step was taken.
    pub step: Option<f64>,
    /// The constant `c` of Newton's natural map on the problem itself (`1/μ_max`); `None` when
    /// Newton did not run.
    pub augmentation: Option<f64>,
    /// The estimate of the dual operator's largest eigenvalue.
    pub mu_max: f64,
    /// Complementarity residual of the returned pair (the law's own radius):
    /// [`complementarity_residual`], whatever the measure the solve was asked to meet.
    pub complementarity: f64,
    /// The residual of the returned pair by the measure the solve was asked to meet (equal to
    /// `complementarity` for [`Measure::Complementarity`]).
    pub residual: f64,
    /// Halvings of the first-order step (divergence or a stall detected).
    pub step_backoffs: usize,
    /// Halvings of the friction fixed point's relaxation factor (a residual that did not fall).
    pub relaxations: usize,
    /// The measured contraction of an outer fixed point (the largest ratio of successive
    /// changes of slip-weakening friction's coefficients, [`crate::solve_slip_weakening`]);
    /// `None` where none ran, or it took fewer than two steps. At or above 1 the map was not
    /// contractive along the way: the static problem may have several solutions, and this is
    /// the branch reached from the stick start.
    pub contraction: Option<f64>,
}

impl ContactInfo {
    /// Counts at zero for a solve with this estimate of `μ_max`.
    pub fn new(mu_max: f64) -> Self {
        ContactInfo {
            uzawa_iters: 0,
            sweeps: 0,
            newton_iters: 0,
            coarse_newton_iters: 0,
            proximal_iters: 0,
            line_search_cuts: 0,
            fallback: false,
            stages: vec![],
            fixed_point_iters: 0,
            inner_iters: 0,
            estimate_inner_iters: 0,
            operator_calls: 0,
            step: None,
            augmentation: None,
            mu_max,
            complementarity: f64::NAN,
            residual: f64::NAN,
            step_backoffs: 0,
            relaxations: 0,
            contraction: None,
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
    pub info: ContactInfo,
    /// The flux and potential of the points with electrical contact
    /// ([`crate::solve_newton_electric`]); `None` without.
    pub electric: Option<crate::ElectricValues>,
}

impl ContactSolution {
    /// `(stick, slip, separated)` counts.
    pub fn counts(&self) -> (usize, usize, usize) {
        counts(&self.status)
    }
}

/// The loop a progress line comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// A first-order step (Uzawa or the accelerated gradient).
    Uzawa,
    /// A step of the fixed point on the slip bound.
    FixedPoint,
    /// A semismooth Newton step.
    Newton,
    /// An outer step of the proximal-point method around Newton (a regularised problem).
    Proximal,
    /// A sweep of the block Gauss–Seidel method.
    GaussSeidel,
    /// Newton stalled: the last stage takes over (one line, then its own steps).
    Fallback,
}

impl Stage {
    /// Lower-case name (`uzawa`, `fixed-point`, `newton`, `proximal`, `gauss-seidel`,
    /// `fallback`).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Uzawa => "uzawa",
            Stage::FixedPoint => "fixed-point",
            Stage::Newton => "newton",
            Stage::Proximal => "proximal",
            Stage::GaussSeidel => "gauss-seidel",
            Stage::Fallback => "fallback",
        }
    }
}

/// Why a loop stopped making progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stall {
    /// The iteration limit, reached while the residual still fell.
    IterationLimit,
    /// A Newton matrix that could not be solved.
    SingularMatrix,
    /// A Newton direction along which no step lowered the residual.
    LineSearch,
    /// A residual that is not a number.
    NonFinite,
    /// Steps that no longer lowered the residual, even with a smaller step size.
    NoProgress,
    /// Steps that came back to the branches (the active set) of an earlier iterate without a
    /// gain: a cycle.
    Cycle,
}

impl std::fmt::Display for Stall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stall::IterationLimit => "the iteration limit",
            Stall::SingularMatrix => "a singular Newton matrix",
            Stall::LineSearch => "a failed line search",
            Stall::NonFinite => "a non-finite residual",
            Stall::NoProgress => "no progress",
            Stall::Cycle => "a cycle of active sets",
        })
    }
}

/// The residual a solve must bring below its tolerance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Measure {
    /// This crate's: the natural map with `c = 1/μ_max`, weighted, relative to the multipliers
    /// or their scale ([`complementarity_residual`]). Free of units and of the solver.
    #[default]
    Complementarity,
    /// Siconos' (and FCLib's): the natural map of De Saxcé's cone complementarity with `c = 1`,
    /// unweighted, relative to `max(‖u0 - g‖, ‖λ‖, ‖u - g‖)` ([`desaxce_residual`]). It mixes
    /// the units of forces and displacements, so it means most where the compliance is near 1.
    DeSaxce,
    /// The larger of the two: a solve that meets it meets both (where one measure breaks down,
    /// a huge `μ` or a tiny `q` making Siconos' error vanish at `r = 0`, the other does not).
    Both,
}

/// An iterate that a stopped solve hands back: multipliers, the displacement they give, and
/// the residual (by the measure the solve was asked to meet).
#[derive(Clone, Debug, PartialEq)]
pub struct Iterate {
    /// The multipliers.
    pub lambda: PointValues,
    /// The contact displacement of `lambda`.
    pub u: PointValues,
    /// Its residual.
    pub residual: f64,
}

/// What stops a solve from outside: a deadline, a flag another thread may set (a Ctrl-C
/// handler, a user interface), or both. Checked once per iteration of every loop. Two are
/// equal when their deadlines are and they watch the same flag.
#[derive(Clone, Copy, Debug, Default)]
pub struct Interrupt {
    /// Stop at this instant.
    pub deadline: Option<std::time::Instant>,
    /// Stop once this flag is set.
    pub cancel: Option<&'static std::sync::atomic::AtomicBool>,
}

/// Why a solve was interrupted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interruption {
    /// Its deadline passed.
    Deadline,
    /// Its cancel flag was set.
    Cancelled,
}

impl std::fmt::Display for Interruption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Interruption::Deadline => "the deadline passed",
            Interruption::Cancelled => "cancelled",
        })
    }
}

impl PartialEq for Interrupt {
    fn eq(&self, other: &Self) -> bool {
        self.deadline == other.deadline
            && match (self.cancel, other.cancel) {
                (Some(a), Some(b)) => std::ptr::eq(a, b),
                (a, b) => a.is_none() && b.is_none(),
            }
    }
}

impl Eq for Interrupt {}

impl Interrupt {
    /// No deadline, no flag.
    pub const NONE: Interrupt = Interrupt {
        deadline: None,
        cancel: None,
    };

    /// Whether the solve must stop now, and why.
    pub fn check(&self) -> Option<Interruption> {
        if self
            .cancel
            .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
        {
            return Some(Interruption::Cancelled);
        }
        self.deadline
            .is_some_and(|d| std::time::Instant::now() >= d)
            .then_some(Interruption::Deadline)
    }
}

/// One line of progress.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// The loop it comes from.
    pub stage: Stage,
    /// Iteration number within the stage.
    pub iter: usize,
    /// The stage's residual (complementarity, or the paper's relative change).
    pub residual: f64,
    /// Stick / slip / separated counts.
    pub counts: (usize, usize, usize),
}

/// The slip bound of each point for a law and multipliers: Tresca `S`, Coulomb `F [λ_n]₊`,
/// frictionless 0 ([`Law::radius`] at each point).
pub fn slip_bound(points: &ContactPoints, law: &Law, lambda_n: &[f64]) -> Vec<f64> {
    (0..points.len()).map(|i| law.radius(points, i, lambda_n[i])).collect()
}

impl Law {
    /// The law at the points `keep` of its points (Tresca's bounds there; the others have
    /// none per point), as [`ContactPoints::select`] keeps them.
    pub fn select(&self, keep: &[usize]) -> Law {
        match self {
            Law::Tresca(s) => Law::Tresca(keep.iter().map(|&i| s[i]).collect()),
            other => other.clone(),
        }
    }

    /// The slip radius of point `i` at the normal value `z_n` (a multiplier, or Newton's
    /// augmented `z_n`): Tresca's `S_i`, Coulomb's `F_i [z_n]₊` ([`coulomb_radius`]) or, at a
    /// point of a Tresca zone beside Coulomb's ([`ContactPoints::tresca_of`]), its bound; 0
    /// without friction. The one place the radius is written.
    pub fn radius(&self, points: &ContactPoints, i: usize, z_n: f64) -> f64 {
        match self {
            Law::Frictionless => 0.0,
            Law::Tresca(s) => s[i],
            Law::Coulomb => match points.tresca_of(i) {
                Some(s) => s,
                None => coulomb_radius(points.friction[i], z_n),
            },
        }
    }
}

/// Coulomb's slip radius `F [z_n]₊` for the friction coefficient `friction`.
pub fn coulomb_radius(friction: f64, z_n: f64) -> f64 {
    friction * crate::project_nonnegative(z_n)
}

/// The natural-map residual of docs/theory.md with step `c`:
/// `‖(λ_n - max(0, λ_n + c (u_n - g)), λ_t - P_S(λ_t + c u_t))‖_W / max(‖λ‖_W, reference)`.
///
/// `reference` is the multiplier scale of the problem, `c ‖(u_n(0) - g, u_t(0))‖_W` with `u(0)`
/// the contact displacement under the loads alone ([`crate::solve_uzawa`] computes it): without it, a
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
    let (num, lam) = complementarity_norms(points, radius, lambda, u, c);
    relative_complementarity(num, lam, reference)
}

/// [`complementarity_residual`] from its parts: the natural map's norm `num`, the multipliers'
/// `lam` (both `‖·‖_W`) and the multiplier scale `reference`. For a caller that holds the
/// points in parts (the ranks of a parallel run: each part's norms from
/// [`complementarity_norms`], combined as `sqrt(Σ ‖·‖²)`).
pub fn relative_complementarity(num: f64, lam: f64, reference: f64) -> f64 {
    let den = lam.max(reference);
    if den > 0.0 {
        num / den
    } else {
        num
    }
}

/// The two norms of [`complementarity_residual`] over `points`: the natural map's
/// `‖(λ_n - max(0, λ_n + c (u_n - g)), λ_t - P_S(λ_t + c u_t))‖_W` and `‖λ‖_W`.
pub fn complementarity_norms(
    points: &ContactPoints,
    radius: &[f64],
    lambda: &PointValues,
    u: &PointValues,
    c: f64,
) -> (f64, f64) {
    let n = points.len();
    let nt = lambda.n_tangential();
    let mut r = PointValues::zeros(n, nt);
    let mut buf = [0.0; 2];
    for i in 0..n {
        r.normal[i] = points
            .foundation_of(i)
            .normal_residual(lambda.normal[i], u.normal[i] - points.gap[i], c);
        if nt > 0 {
            let (l, ut) = (lambda.tangential_of(i), u.tangential_of(i));
            for k in 0..nt {
                buf[k] = l[k] + c * ut[k];
            }
            points.project_friction(i, &mut buf[..nt], radius[i]);
            for (rk, (lk, bk)) in r.tangential_of_mut(i).iter_mut().zip(l.iter().zip(&buf)) {
                *rk = lk - bk;
            }
        }
    }
    (r.weighted_norm(&points.weight), lambda.weighted_norm(&points.weight))
}

/// Siconos' error measure in this crate's terms ([`Measure::DeSaxce`]). With `r = λ`, the
/// velocity `v = (g - u_n, -u_t)` (Siconos' `u = W r + q`, `u_N ≥ 0` meaning separation) and
/// `q = (g - u0_n, -u0_t)`, per point `e = r - P_K(r - ṽ)`: for Coulomb `K` is the cone
/// `|r_t| ≤ F r_n` and `ṽ = v + F |v_t| e_n` (De Saxcé's change of variable), for Tresca
/// `K = {r_n ≥ 0, |r_t| ≤ S}` and `ṽ = v`, frictionless `K = {r_n ≥ 0}`. The result is
/// `‖e‖ / max(‖q‖, ‖r‖, ‖v‖)`, unweighted (`‖e‖` where the three vanish).
pub fn desaxce_residual(
    points: &ContactPoints,
    law: &Law,
    lambda: &PointValues,
    u: &PointValues,
    u0: &PointValues,
) -> f64 {
    let nt = lambda.n_tangential();
    let (mut e2, mut r2, mut v2, mut q2) = (0.0, 0.0, 0.0, 0.0);
    let mut x = [0.0; 3];
    for i in 0..points.len() {
        let g = points.gap[i];
        let (rn, vn) = (lambda.normal[i], g - u.normal[i]);
        let (rt, ut) = (lambda.tangential_of(i), u.tangential_of(i));
        q2 += (g - u0.normal[i]).powi(2) + u0.tangential_of(i).iter().map(|a| a * a).sum::<f64>();
        r2 += rn * rn + rt.iter().map(|a| a * a).sum::<f64>();
        v2 += vn * vn + ut.iter().map(|a| a * a).sum::<f64>();
        // r - ṽ, with v_t = -u_t
        x[0] = rn - vn;
        for k in 0..nt {
            x[1 + k] = rt[k] + ut[k];
        }
        // a held direction is no direction of the set: the projection is the subspace's first
        points.hold(i, &mut x[1..1 + nt]);
        match (law, points.tresca_of(i)) {
            (Law::Coulomb, Some(s)) => {
                x[0] = project_nonnegative(x[0]);
                project_disc(&mut x[1..1 + nt], s);
            }
            (Law::Coulomb, None) => {
                let f = points.friction[i];
                let mut slip = [0.0; 2];
                slip[..nt].copy_from_slice(ut);
                points.hold(i, &mut slip[..nt]);
                x[0] -= f * norm(&slip[..nt]);
                project_cone(&mut x[..1 + nt], f);
            }
            (Law::Tresca(s), _) => {
                x[0] = project_nonnegative(x[0]);
                project_disc(&mut x[1..1 + nt], s[i]);
            }
            (Law::Frictionless, _) => x[0] = project_nonnegative(x[0]),
        }
        e2 += (rn - x[0]).powi(2) + (0..nt).map(|k| (rt[k] - x[1 + k]).powi(2)).sum::<f64>();
    }
    let den = q2.max(r2).max(v2).sqrt();
    if den > 0.0 {
        e2.sqrt() / den
    } else {
        e2.sqrt()
    }
}

/// What the complementarity residual is measured with: the natural map's constant `c` and
/// the multipliers' scale `reference` ([`complementarity_residual`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scales {
    pub(crate) c: f64,
    pub(crate) reference: f64,
}

impl Measure {
    /// The residual of `(lambda, u)` by this measure; `scales` are the natural map's constant
    /// and the multipliers' scale of [`complementarity_residual`], `u0` the displacement under
    /// the loads alone.
    pub(crate) fn of(
        self,
        points: &ContactPoints,
        law: &Law,
        lambda: &PointValues,
        u: &PointValues,
        u0: &PointValues,
        scales: Scales,
    ) -> f64 {
        match self {
            Measure::Complementarity => {
                let radius = slip_bound(points, law, &lambda.normal);
                complementarity_residual(points, &radius, lambda, u, scales.c, scales.reference)
            }
            Measure::DeSaxce => desaxce_residual(points, law, lambda, u, u0),
            Measure::Both => Measure::Complementarity
                .of(points, law, lambda, u, u0, scales)
                .max(Measure::DeSaxce.of(points, law, lambda, u, u0, scales)),
        }
    }
}

/// Status of each point (docs/theory.md): separated if `λ_n ≤ 1e-9 max λ_n`; otherwise slip if the
/// radius is 0 or `|λ_t| ≥ (1 - 1e-9) S`; otherwise stick.
pub fn classify(lambda: &PointValues, radius: &[f64]) -> Vec<Status> {
    let max_n = lambda.normal.iter().cloned().fold(0.0f64, f64::max);
    (0..lambda.n_points())
        .map(|i| {
            if !(lambda.normal[i] > 1e-9 * max_n) {
                Status::Separated
            } else if radius[i] <= 0.0 || lambda.tangential_norm(i) >= (1.0 - 1e-9) * radius[i] {
                Status::Slip
            } else {
                Status::Stick
            }
        })
        .collect()
}

/// `(stick, slip, separated)` counts of a status vector.
pub(crate) fn counts(status: &[Status]) -> (usize, usize, usize) {
    let c = |s| status.iter().filter(|&&x| x == s).count();
    (c(Status::Stick), c(Status::Slip), c(Status::Separated))
}

/// Checks the points, the law's data, and the size of the problem (`n_points` points with
/// `n_tangential` tangential components each) against them; returns `(n, nt)`.
fn check_input(
    points: &ContactPoints,
    law: &Law,
    n_points: usize,
    n_tangential: usize,
) -> Result<(usize, usize), ContactError> {
    points.validate()?;
    let n = points.len();
    let nt = if matches!(law, Law::Frictionless) {
        0
    } else {
        points.n_tangential()
    };
    if n_points != n || n_tangential != nt {
        return Err(InputError::ProblemSize {
            points: n_points,
            tangential: n_tangential,
            expected_points: n,
            expected_tangential: nt,
        }
        .into());
    }
    if let Law::Tresca(s) = law {
        if s.len() != n || s.iter().any(|x| !(*x >= 0.0 && x.is_finite())) {
            return Err(InputError::TrescaBounds.into());
        }
    }
    Ok((n, nt))
}

/// What every solver computes before its first step: the problem's size checked against its
/// points and law, the dual operator's largest eigenvalue `μ_max`, the contact displacement
/// under the loads alone `u(0)`, and the multiplier scale of the residual.
pub(crate) struct Preamble {
    /// Points.
    pub n: usize,
    /// Tangential components per point (0 without friction).
    pub nt: usize,
    /// The estimate of the dual operator's largest eigenvalue.
    pub mu_max: f64,
    /// The contact displacement under the loads alone.
    pub u0: PointValues,
    /// The multiplier scale with `c = 1/μ_max` ([`multiplier_scale`]).
    pub reference: f64,
}

impl Preamble {
    /// Checks the input of a solve through `c` and estimates `μ_max` by `power_iters` steps,
    /// or takes the `known` estimate (then only `u(0)` is computed).
    pub fn new(
        c: &mut Counter<'_>,
        points: &ContactPoints,
        law: &Law,
        power_iters: usize,
        known: Option<f64>,
    ) -> Result<Self, ContactError> {
        let (n, nt) = check_input(points, law, c.op.n_points(), c.op.n_tangential())?;
        let (mu_max, u0) = match known.filter(|m| *m > 0.0 && m.is_finite()) {
            Some(mu) => {
                let mut u0 = PointValues::zeros(n, nt);
                c.call(&PointValues::zeros(n, nt), &mut u0)?;
                (mu, u0)
            }
            None => estimate_mu_max(c, points, nt, power_iters)?,
        };
        let reference = multiplier_scale(points, &u0, 1.0 / mu_max);
        Ok(Preamble {
            n,
            nt,
            mu_max,
            u0,
            reference,
        })
    }

    /// The first iterate: the warm start `lambda0` where its shape is the problem's, zeros
    /// where there is none.
    pub fn start(&self, lambda0: Option<PointValues>) -> Result<PointValues, ContactError> {
        match lambda0 {
            Some(l) if l.n_points() == self.n && l.n_tangential() == self.nt => Ok(l),
            Some(_) => Err(InputError::WarmStart.into()),
            None => Ok(PointValues::zeros(self.n, self.nt)),
        }
    }
}

/// The multiplier scale of the problem (the floor of the residual's denominator, see
/// [`complementarity_residual`]): on a rigid foundation `c ‖([u_n(0) - g]₊, u_t(0))‖_W`, the
/// multipliers that push the free motion's penetration back by its own size; on a compliant one the smaller of that and the
/// bed's pressure at the free penetration, `‖k [u(0)_n - g]₊^m‖_W` (a soft bed under a small
/// load carries pressures many decades below `c ‖u(0) - g‖`, and a floor at the rigid scale
/// would accept their round-off as the answer: 1e-7 of a pressure of 1e-6 on `k = 3e-3`,
/// `m = 2.4`, found by the property tests).
pub fn multiplier_scale(points: &ContactPoints, u0: &PointValues, c: f64) -> f64 {
    let mut free = u0.clone();
    for (u, g) in free.normal.iter_mut().zip(&points.gap) {
        *u -= g;
    }
    // the free motion's penetrations: a point the free motion leaves clear by its gap needs no
    // multiplier, and a large gap far from the contact (a body under a sphere: gaps of
    // r²/2R) must not set the scale (it did: 1e-10 of it was 1e-4 of a small indenter's force)
    let mut penetration = free.clone();
    penetration
        .normal
        .iter_mut()
        .for_each(|p| *p = crate::project_nonnegative(*p));
    let rigid = c * penetration.weighted_norm(&points.weight);
    if points.all_rigid() {
        return rigid;
    }
    // the bed's pressures at the free penetrations, weighted like the multipliers
    let mut bed = PointValues::zeros(free.n_points(), 0);
    for (i, (p, penetration)) in bed.normal.iter_mut().zip(&free.normal).enumerate() {
        *p = points
            .foundation_of(i)
            .pressure(*penetration)
            .map_or(0.0, |(pressure, _)| pressure);
    }
    let bed = bed.weighted_norm(&points.weight);
    if bed.is_nan() {
        rigid
    } else {
        rigid.min(bed)
    }
}

/// The operator with a count of its calls and of the inner iterations they report.
pub(crate) struct Counter<'a> {
    op: &'a mut dyn ContactOperator,
    pub(crate) calls: usize,
    pub(crate) inner: usize,
}

impl<'a> Counter<'a> {
    pub(crate) fn new(op: &'a mut dyn ContactOperator) -> Self {
        Counter { op, calls: 0, inner: 0 }
    }

    pub(crate) fn call(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<(), ContactError> {
        self.calls += 1;
        self.inner += self
            .op
            .displacement(lambda, out)
            .map_err(|e: OperatorError| ContactError::Operator(e))?;
        Ok(())
    }

    /// [`ContactOperator::forces_alone`], counted.
    fn forces_alone(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<(), ContactError> {
        self.calls += 1;
        self.inner += self.op.forces_alone(lambda, out).map_err(ContactError::Operator)?;
        Ok(())
    }
}

/// Largest eigenvalue of the dual operator `λ ↦ u(0) - u(λ) = D W λ` in the `W` inner product,
/// by power iteration (a Rayleigh quotient, so a lower estimate), applied through
/// [`ContactOperator::forces_alone`] (no cancellation against the loads, whatever their size);
/// also returns `u(0)`, the contact displacement under the loads alone.
fn estimate_mu_max(
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
    let mut v = PointValues::zeros(n, nt);
    for (i, x) in v.normal.iter_mut().chain(v.tangential.iter_mut()).enumerate() {
        *x = start(i);
    }
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
        c.forces_alone(&v, &mut out)?;
        let mut mv = out.clone();
        mv.normal
            .iter_mut()
            .chain(mv.tangential.iter_mut())
            .for_each(|x| *x = -*x);
        mu = f64::max(mu, v.weighted_dot(&mv, &points.weight));
        v = mv;
    }
    // leave the operator's warm start (an iterative primal solver starts from its last
    // solution) at the loads alone, where the solvers start
    c.call(&zero, &mut out)?;
    if !(mu > 0.0 && mu.is_finite()) {
        return Err(ContactError::NotLoaded { mu_max: mu });
    }
    Ok((mu, u0))
}

/// The best iterate of a loop by its residual: the bookkeeping of every solver's best-iterate
/// answer. `T` is the solver's iterate ([`Iterate`], or Newton's own state). A kept residual
/// that is not a number is replaced by any other.
#[derive(Clone, Debug)]
pub(crate) struct Best<T = Iterate> {
    kept: Option<(T, f64)>,
}

impl<T: Clone> Best<T> {
    /// No iterate yet.
    pub fn new() -> Self {
        Best { kept: None }
    }

    /// Keeps the iterate `make` gives where `residual` is the lowest yet (or the kept one's is
    /// NaN).
    pub fn offer_with(&mut self, residual: f64, make: impl FnOnce() -> T) {
        if self.residual().is_none_or(|b| residual < b || b.is_nan()) {
            self.kept = Some((make(), residual));
        }
    }

    /// The best residual, where an iterate was offered.
    pub fn residual(&self) -> Option<f64> {
        self.kept.as_ref().map(|(_, r)| *r)
    }

    /// The best iterate and its residual.
    pub fn get(&self) -> Option<&(T, f64)> {
        self.kept.as_ref()
    }

    /// The best iterate and its residual, taken.
    pub fn take_kept(&mut self) -> Option<(T, f64)> {
        self.kept.take()
    }
}

impl Best<Iterate> {
    /// Keeps `(λ, u)` where its residual is the lowest yet.
    pub fn offer(&mut self, lambda: &crate::PointValues, u: &crate::PointValues, residual: f64) {
        self.offer_with(residual, || Iterate {
            lambda: lambda.clone(),
            u: u.clone(),
            residual,
        });
    }

    /// The best iterate, boxed for an error.
    pub fn boxed(&self) -> Option<Box<Iterate>> {
        self.get().map(|(it, _)| Box::new(it.clone()))
    }

    /// The best iterate.
    pub fn take(&mut self) -> Option<Iterate> {
        self.take_kept().map(|(it, _)| it)
    }
}
