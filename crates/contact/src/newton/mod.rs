//! A semismooth Newton method on an affine contact problem `u = u₀ - D W λ` (the condensed
//! contact problem, or any problem given by its compliance, dense or sparse): the natural-map
//! (Alart–Curnier) equations of Signorini contact with Tresca or Coulomb friction, solved for
//! the multipliers ([`equations`]). Coulomb friction is solved directly (the radius
//! `F [λ_n + c (u_n - g)]₊` moves with the pressure), without the fixed point on `S`. The
//! natural map's constant is `c = 1/μ_max` on the problem itself (the residual's own), and one
//! per point on the proximal problems, `c_i = 1/‖B_i‖_F` with `B_i` the point's block of
//! `D W + σ I` (Alart and Curnier's `r`; Siconos chooses it so too): each point's rows of the
//! Newton matrix are then of order one, however far its own compliance is from the largest,
//! which is what the nearly singular problems of that stage need.
//!
//! Three stages (and a half), each from the best iterate so far (by the measure the caller
//! asked for), so that the answer is never worse than the start:
//! 1. **Newton** on the problem itself, globalised by an Armijo line search on the weighted
//!    norm of the equations: a full step is compared with the largest of the last norms
//!    (non-monotone: Grippo, Lampariello and Lucidi), a damped one with the current norm. A
//!    best norm that no longer falls ends the stage.
//! 2. **Proximal point** where Newton stalls (a singular Jacobian where `D` is only
//!    semidefinite, as for rigid multibody problems; a line search that fails; a cycle): a
//!    sequence of regularised problems `u_σ(λ) = u(λ) - σ (λ - λ_k)`, each solved by Newton
//!    to a tenth of the current residual (an inner solve that stalls, by stage 1's patience
//!    or cycle rule, has failed), whose solutions converge to a solution of the
//!    problem itself (Rockafellar's proximal point algorithm; Siconos' PROX solver is this
//!    method around its Alart–Curnier Newton). `D + σ W⁻¹` is definite for any `σ > 0`; `σ`
//!    follows the residual (in units of the points' mean compliance), ten times more after an
//!    inner solve that failed, coming back down by halves.
//!
//!    Then, where `D` is sparse or asymmetric and both stages stalled, Newton again from
//!    stage 1's best iterate under the rules of a dense symmetric `D` (damped steps against
//!    the history, no patience rule),
//!    for at most ten times `max_iters` steps: stage 1's stricter rules keep it cheap on the
//!    problems it solves, and can stop it short of an active set a longer search finds.
//! 3. **Fallback**, capped: for Coulomb's law the block Gauss–Seidel method
//!    ([`crate::solve_gauss_seidel`]), for the convex laws the accelerated projected gradient
//!    ([`crate::solve_uzawa`]).
//!
//! Nothing is tuned to a problem: the constants are relative to the problem's own compliance
//! and residual.

mod direction;
mod equations;
mod member;
mod refactor;

use crate::coarse;
use crate::electric::{ElectricContactProblem, ElectricValues};
use crate::gauss_seidel::{self, SweepEnd};
use crate::operator::AffineProblem;
use crate::operator::Compliance;
use crate::points::{ContactPoints, PointValues};
use crate::solution::{classify, counts, slip_bound, Best, Counter, Preamble, Scales};
use crate::InputError;
use crate::{
    ContactError, ContactInfo, ContactSolution, GaussSeidelParams, Interrupt, Interruption, Iterate, Law, Measure,
    Progress, Stage, Stall, StopRule, UzawaParams,
};
use crate::{Phase, Schedule};
use direction::Directions;
use equations::{Flat, RowForm, State};

/// Parameters of [`solve_newton`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonParams {
    /// Tolerance on the residual of [`NewtonParams::measure`].
    pub tol: f64,
    /// The residual to bring below `tol`.
    pub measure: Measure,
    /// Newton steps on the problem itself before the proximal stage takes over.
    pub max_iters: usize,
    /// Outer steps of the proximal stage (0: no proximal stage). Its inner Newton steps are
    /// capped too, at 20 000 in all.
    pub max_proximal: usize,
    /// Power iterations for `μ_max`.
    pub power_iters: usize,
    /// A known estimate of `μ_max` for this problem (a solve of the same operator again, as
    /// the steps of a fixed point on the friction coefficients): the power iteration is
    /// skipped. `None`: estimated.
    pub mu_max: Option<f64>,
    /// Slip-weakening friction solved directly: at each point with a law of its own
    /// ([`ContactPoints::weakening`]), Coulomb's radius with the coefficient of its own slip,
    /// differentiated through the slip (with `Law::Coulomb`; such a point's `friction` is not
    /// read). No last stage runs (its solvers hold a constant coefficient): a stall is the
    /// caller's to handle ([`crate::solve_slip_weakening`] goes on with its fixed point).
    /// `false`: every point's coefficient is its `friction`, and points that weaken are refused.
    pub weakening: bool,
    /// The stages the solve may run ([`Schedule::of`] the problem's class): sweeps first
    /// (stage 0), the nested start (a solve from zero multipliers starts from the answer of
    /// the problem on a coarser set of its points: the step count then does not grow with the
    /// number of points), Newton, the proximal stage, the lenient Newton, the fallback (block
    /// Gauss–Seidel for Coulomb's law, the accelerated projected gradient for the convex laws;
    /// without it, a stall is a [`ContactError::Stalled`]).
    pub schedule: Schedule,
    /// Sweeps or steps the last stage may take.
    pub max_fallback_iters: usize,
    /// Whether a start that already meets the tolerance still takes Newton steps, until one
    /// meets it (the answer is then a Newton iterate, not the start; the start where they
    /// stall). For a warm start on changed data whose answer must follow the data more closely
    /// than the tolerance: force control's search for a depth evaluates the force at each
    /// depth, and a start taken as it is carries the force of the depth before.
    pub refine_start: bool,
    /// A deadline or a cancel flag.
    pub interrupt: Interrupt,
}

impl Default for NewtonParams {
    fn default() -> Self {
        NewtonParams {
            tol: 1e-10,
            measure: Measure::Complementarity,
            max_iters: 100,
            max_proximal: 1000,
            power_iters: 30,
            mu_max: None,
            weakening: false,
            schedule: Schedule::all(),
            max_fallback_iters: 200_000,
            refine_start: false,
            interrupt: Interrupt::NONE,
        }
    }
}

/// Newton steps of each candidate start of electrical contact ([`electric_start`]).
const START_STEPS: usize = 30;
/// Armijo's sufficient-decrease constant.
const ARMIJO: f64 = 1e-4;
/// Merit values the non-monotone line search compares with.
const MEMORY: usize = 8;
/// Step halvings of the line search before the direction is given up.
const MAX_HALVINGS: usize = 30;
/// Newton steps without a 10 % gain on the best norm of the equations before a stall (where
/// `D` is sparse or asymmetric).
const PATIENCE: usize = 15;
/// Iterates, under Newton's own rules (no patience rule), whose generalised Jacobian has the
/// pattern of an earlier one since the best's last 10 % gain, before a stall
/// ([`Stall::Cycle`]). The non-monotone line search lets a step rise as high as the norms it
/// remembers, so a cycle of active sets shorter than its memory goes on by itself: measured on
/// the chains of the property test (3D, Coulomb), a period of 3 steps through the same three
/// active sets for 90 steps, the norm at 2e-5 in each period, until the iteration limit. On
/// 3000 such chains from their nested start (every repeat counted, before a damped step in
/// one piece was told apart): 2 revisits cost 30 % more Newton steps in all (revisits that are
/// no cycle, on Coulomb's curved slip branch), 8 left one cycle, 4 none. Only a pattern left
/// and come back to counts ([`Watch::before`]).
const REVISITS: usize = 4;
/// Outer proximal steps of a coarser problem of the nested start ([`nested_start`]), at most:
/// its answer is a start, worth a few. On 3000 random chains of the property test, the
/// coarser problems that needed the stage took 3 to 5 of them; without it, one failed and
/// its fine problem started from zero (129 steps, against 5 from the coarse answer).
const COARSE_PROXIMAL: usize = 20;
/// The lenient Newton stage's steps, in units of `max_iters`.
const LENIENT_STEPS: usize = 10;
/// Newton steps of one proximal problem. Its solve also ends, failed, as stage 1's does: after
/// [`PATIENCE`] steps without a 10 % gain where `D` is sparse or asymmetric, on a cycle of
/// active sets ([`REVISITS`]) where it is dense and symmetric. A failed inner solve is what
/// raises `σ`, and one that has stalled at this `σ` seldom recovers (on Siconos' rigid
/// multibody problems the inner solves that spent all 100 steps had made no 10 % gain in any
/// of them).
const INNER_STEPS: usize = 100;
/// Newton steps the proximal stage may take in all its inner solves: the stage's worst case
/// of 200 outer steps of [`INNER_STEPS`] each, from before the inner solves had a patience
/// rule (the outer steps that rule saves go to more outer steps, up to `max_proximal`).
const PROXIMAL_STEPS: usize = 200 * INNER_STEPS;
/// The tolerance of one proximal problem's solve, relative to the outer residual.
const INNER_RATIO: f64 = 0.1;
/// The proximal shift's bounds, relative to the points' mean compliance.
const SIGMA_MIN: f64 = 1e-12;
const SIGMA_MAX: f64 = 1e2;

/// The larger of two residuals, NaN if either is (`f64::max` drops a NaN: a residual that
/// is not a number must stay one).
trait NanMax {
    fn nan_max(self, other: f64) -> f64;
}

impl NanMax for f64 {
    fn nan_max(self, other: f64) -> f64 {
        if self.is_nan() || other.is_nan() {
            f64::NAN
        } else {
            self.max(other)
        }
    }
}

/// What a solve is asked: its points, its law and Newton's parameters.
#[derive(Clone, Copy)]
struct Asked<'a> {
    points: &'a ContactPoints,
    law: &'a Law,
    params: &'a NewtonParams,
}

/// How a run of Newton steps ended.
enum End {
    Converged,
    Stalled(Stall),
    Interrupted(Interruption),
}

/// The problem itself, the measure, and the best iterate seen.
struct Judge<'a> {
    flat: Flat<'a>,
    law: &'a Law,
    points: &'a ContactPoints,
    u0: &'a PointValues,
    measure: Measure,
    reference: f64,
    tol: f64,
    best: Best<State>,
    /// The norm of the equations at zero multipliers where Newton starts elsewhere by its
    /// nested start ([`nested_start`]): the first steps may rise to it.
    seed: Option<f64>,
}

impl<'a> Judge<'a> {
    /// The judge of `flat`, the problem itself, with the preamble's multiplier scale
    /// `reference`; no iterate judged yet.
    fn new(
        flat: Flat<'a>,
        law: &'a Law,
        points: &'a ContactPoints,
        u0: &'a PointValues,
        params: &NewtonParams,
        reference: f64,
    ) -> Self {
        Judge {
            flat,
            law,
            points,
            u0,
            measure: params.measure,
            reference,
            tol: params.tol,
            best: Best::new(),
            seed: None,
        }
    }

    /// Newton's stages from `x0`, and how they ended: the best state of all and its residual
    /// (taken from the judge), with the stall's reason where it is short of the tolerance; an
    /// interruption is an error carrying the best iterate.
    fn run_stages(
        &mut self,
        x0: Vec<f64>,
        params: &NewtonParams,
        info: &mut ContactInfo,
        progress: &mut dyn FnMut(&Progress),
        cache: &mut Option<Directions>,
    ) -> Result<(State, f64, Option<Stall>), ContactError> {
        let end = newton_stages(self, x0, params, info, progress, cache);
        let (best, best_residual) = self.best.take_kept().expect("the start was judged");
        match end {
            End::Converged => Ok((best, best_residual, None)),
            _ if best_residual <= params.tol => Ok((best, best_residual, None)),
            End::Interrupted(why) => Err(ContactError::Interrupted {
                why,
                n_iters: info.newton_iters,
                residual: best_residual,
                best: Some(Box::new(self.iterate(&best, best_residual))),
            }),
            End::Stalled(why) => Ok((best, best_residual, Some(why))),
        }
    }

    /// The state `s` of the problem itself as an iterate, with its residual.
    fn iterate(&self, s: &State, residual: f64) -> Iterate {
        Iterate {
            lambda: self.flat.values(&s.x),
            u: self.flat.values(&s.u),
            residual,
        }
    }
}

impl Judge<'_> {
    /// The points with the coefficients of the law at the slips of `u` (slip weakening), or
    /// as they are.
    fn points_at(&self, u: &PointValues) -> std::borrow::Cow<'_, ContactPoints> {
        if self.flat.weakening {
            std::borrow::Cow::Owned(self.points.at_slips(u))
        } else {
            std::borrow::Cow::Borrowed(self.points)
        }
    }

    /// The complementarity residual's scales: the problem's own constant `1/μ_max` and the
    /// preamble's multiplier scale.
    fn scales(&self) -> Scales {
        Scales {
            c: 1.0 / self.flat.mu_max,
            reference: self.reference,
        }
    }

    /// The residual of a state of the problem itself.
    fn residual(&self, s: &State) -> f64 {
        self.residual_of(&self.flat, s)
    }

    /// The residual, by the measure asked for, of a state of `problem` (the problem itself, or
    /// a proximal problem: its own loads and constant).
    fn residual_of(&self, problem: &Flat<'_>, s: &State) -> f64 {
        let lambda = problem.values(&s.x);
        let u = problem.values(&s.u);
        let u0 = problem.values(&problem.u0);
        self.measure
            .of(&self.points_at(&u), self.law, &lambda, &u, &u0, self.scales())
            .nan_max(problem.electric_residual(s))
    }

    /// The complementarity residual of a state of the problem itself, whatever the measure.
    fn complementarity(&self, s: &State) -> f64 {
        let u = self.flat.values(&s.u);
        Measure::Complementarity
            .of(
                &self.points_at(&u),
                self.law,
                &self.flat.values(&s.x),
                &u,
                self.u0,
                self.scales(),
            )
            .nan_max(self.flat.electric_residual(s))
    }

    /// Judges a state of the problem itself: keeps it if it is the best; whether it meets the
    /// tolerance.
    fn offer(&mut self, s: &State) -> (f64, bool) {
        let r = self.residual(s);
        self.best.offer_with(r, || s.clone());
        (r, r <= self.tol)
    }

    /// The progress line of a state.
    fn progress(&self, stage: Stage, iter: usize, s: &State, residual: f64) -> Progress {
        let lambda = self.flat.values(&s.x);
        Progress {
            stage,
            iter,
            residual,
            counts: counts(&classify(&lambda, &slip_bound(self.points, self.law, &lambda.normal))),
        }
    }
}

/// Newton steps on `flat` from `s` until `accept` takes a state (returned), a stall, an
/// interruption or `max_steps` (the state of least merit is returned: the non-monotone line
/// search may end above it).
fn newton_steps(
    flat: &Flat<'_>,
    directions: &Directions,
    s: State,
    rules: Rules,
    interrupt: &Interrupt,
    info: &mut ContactInfo,
    accept: &mut dyn FnMut(&State, &mut ContactInfo) -> bool,
) -> (State, End) {
    let mut history = std::collections::VecDeque::with_capacity(MEMORY + 1);
    // a start that stands for an earlier iterate (the nested start, for zero multipliers):
    // the non-monotone search compares with that iterate's norm too
    history.extend(rules.seed);
    // a dense symmetric D (a condensed finite-element compliance), or a caller that asks:
    // Newton's own rules, damped steps that may rise against the history and no patience rule
    // (its norm often rests on a plateau until the active set is found, then drops to
    // round-off in one step); on a dense symmetric D, a stall where the active sets come back
    // without a gain (a cycle, [`REVISITS`]: a plateau moves on to new ones) where the rules
    // ask for it
    let rises = rules.lenient || directions.symmetric_dense();
    let patience = if rises { rules.steps } else { rules.patience };
    let mut watch = Watch::new(patience, rules.cycles && directions.symmetric_dense());
    let mut best = s.clone();
    let mut s = s;
    let end = 'steps: {
        for _ in 0..rules.steps {
            if let Some(why) = interrupt.check() {
                break 'steps End::Interrupted(why);
            }
            let rows = flat.rows(&s);
            if let Some(why) = watch.before(&rows) {
                break 'steps End::Stalled(why);
            }
            let Some(delta) = directions.direction(flat, &s, &rows) else {
                break 'steps End::Stalled(Stall::SingularMatrix);
            };
            // non-monotone Armijo backtracking on the weighted norm of the equations, against
            // the largest of the last MEMORY norms: a full step that changes a point's branch
            // may raise the norm for a step on the way to the solution
            let reference_norm = history.iter().copied().fold(s.norm, f64::max);
            let mut alpha = 1.0;
            let mut accepted = None;
            for _ in 0..=MAX_HALVINGS {
                let x: Vec<f64> = s.x.iter().zip(&delta).map(|(a, b)| a + alpha * b).collect();
                let trial = flat.state(x);
                // the full step against the history; a damped one too where `D` is dense and
                // symmetric, else it must lower the norm itself
                let reference = if alpha == 1.0 || rises { reference_norm } else { s.norm };
                if trial.norm <= (1.0 - ARMIJO * alpha) * reference {
                    accepted = Some(trial);
                    break;
                }
                alpha *= 0.5;
                info.line_search_cuts += 1;
            }
            let Some(next) = accepted else {
                break 'steps End::Stalled(Stall::LineSearch);
            };
            history.push_back(s.norm);
            if history.len() > MEMORY {
                history.pop_front();
            }
            s = next;
            info.newton_iters += 1;
            if !s.norm.is_finite() {
                break 'steps End::Stalled(Stall::NonFinite);
            }
            if accept(&s, info) {
                return (s, End::Converged);
            }
            let stall = watch.after(s.norm, best.norm);
            if s.norm < best.norm {
                best = s.clone();
            }
            if let Some(why) = stall {
                break 'steps End::Stalled(why);
            }
        }
        End::Stalled(Stall::IterationLimit)
    };
    (best, end)
}

/// The stall rules of a run of Newton steps: the non-monotone search lets the norm wander, so
/// a best that no longer falls is a stall (the patience rule), and so are active sets that come
/// back without a gain (the cycle rule, [`REVISITS`]).
struct Watch {
    /// Steps without a 10 % gain on the best norm before a stall.
    patience: usize,
    /// Whether the cycle rule applies.
    cycles: bool,
    /// Steps since the best's last 10 % gain.
    since_best: usize,
    /// The Jacobian patterns of the iterates since then ([`equations::pattern`]).
    visited: Vec<u64>,
    /// How many of those iterates had a pattern seen before.
    revisits: usize,
}

impl Watch {
    fn new(patience: usize, cycles: bool) -> Self {
        Watch {
            patience,
            cycles,
            since_best: 0,
            visited: Vec::new(),
            revisits: 0,
        }
    }

    /// Before a step from an iterate whose generalised Jacobian has the rows `rows`: a cycle.
    fn before(&mut self, rows: &[RowForm]) -> Option<Stall> {
        if !self.cycles {
            return None;
        }
        // a damped step within one piece keeps the pattern: only one left and come back to
        // is a revisit
        let pattern = equations::pattern(rows);
        if self.visited.last() != Some(&pattern) {
            if self.visited.contains(&pattern) {
                self.revisits += 1;
            }
            self.visited.push(pattern);
        }
        (self.revisits >= REVISITS).then_some(Stall::Cycle)
    }

    /// After a step to the norm `norm`, where the best before it was `best`: no progress.
    fn after(&mut self, norm: f64, best: f64) -> Option<Stall> {
        if norm < 0.9 * best {
            self.since_best = 0;
            self.visited.clear();
            self.revisits = 0;
        } else {
            self.since_best += 1;
        }
        (self.since_best >= self.patience).then_some(Stall::NoProgress)
    }
}

/// The rules of a run of Newton steps on the problem itself.
#[derive(Clone, Copy)]
struct Rules {
    /// Steps at most.
    steps: usize,
    /// Steps without a 10 % gain on the best norm before a stall.
    patience: usize,
    /// Damped steps compared with the history, as on a dense symmetric `D`.
    lenient: bool,
    /// A norm the history starts with (see [`newton_steps`]).
    seed: Option<f64>,
    /// Whether a cycle of active sets is a stall, on a dense symmetric `D` ([`REVISITS`]):
    /// where a later stage takes over from it.
    cycles: bool,
}

/// Newton steps on the problem itself from `start`, each offered to the judge (the best
/// iterate, the stop) and reported as a Newton step.
fn judged_steps(
    judge: &mut Judge<'_>,
    directions: &Directions,
    start: State,
    rules: Rules,
    params: &NewtonParams,
    info: &mut ContactInfo,
    progress: &mut dyn FnMut(&Progress),
) -> End {
    let flat = judge.flat.clone();
    let accept = &mut |s: &State, info: &mut ContactInfo| {
        let (r, done) = judge.offer(s);
        progress(&judge.progress(Stage::Newton, info.newton_iters, s, r));
        done
    };
    let (_, end) = newton_steps(&flat, directions, start, rules, &params.interrupt, info, accept);
    end
}

/// The proximal stage from the best iterate, its directions made from `base` (the problem's
/// own): returns how it ended.
fn proximal_stage(
    judge: &mut Judge<'_>,
    base: &Directions,
    params: &NewtonParams,
    info: &mut ContactInfo,
    progress: &mut dyn FnMut(&Progress),
) -> End {
    let Some((start, r0)) = judge.best.get().cloned() else {
        return End::Stalled(Stall::NonFinite);
    };
    // σ's unit: the points' own compliance, the mean diagonal of D W
    let unit = judge.flat.mean_diagonal();
    let mut center = start.x;
    let mut residual = r0;
    // σ follows the residual (Siconos' PROX rule): the residual's size in the points' own
    // compliance after an inner solve that converged, ten times more after one that failed
    let mut boost = 1.0;
    let mut last = End::Stalled(Stall::IterationLimit);
    let first_step = info.newton_iters;
    for outer in 1..=params.max_proximal {
        if let Some(why) = params.interrupt.check() {
            return End::Interrupted(why);
        }
        if info.newton_iters - first_step >= PROXIMAL_STEPS {
            return last;
        }
        let sigma = (boost * residual).clamp(SIGMA_MIN, SIGMA_MAX);
        let problem = judge.flat.proximal(sigma * unit, &center);
        let directions = base.for_proximal(&problem);
        let s0 = problem.state(center.clone());
        // an inexact inner solve, in the measure asked for: a tenth of the outer residual
        let inner_tol = (INNER_RATIO * residual).max(0.5 * params.tol);
        // a cycle fails the inner solve, as a stall does: a larger σ follows
        let rules = Rules {
            steps: INNER_STEPS,
            patience: PATIENCE,
            lenient: false,
            seed: None,
            cycles: true,
        };
        let (s, end) = newton_steps(
            &problem,
            &directions,
            s0,
            rules,
            &params.interrupt,
            info,
            &mut |s, _| judge.residual_of(&problem, s) <= inner_tol,
        );
        info.proximal_iters += 1;
        let here = judge.flat.state(s.x.clone());
        let (r, done) = judge.offer(&here);
        progress(&judge.progress(Stage::Proximal, outer, &here, r));
        if done {
            return End::Converged;
        }
        // the proximal iterates go on from the inner solve's point (its best, where it
        // stalled), as Rockafellar's inexact method does
        center = s.x;
        residual = r;
        match end {
            End::Interrupted(why) => return End::Interrupted(why),
            // after a failure, come back down to σ = residual gradually: straight back, the
            // same failure would follow
            End::Converged => boost = (boost * 0.5).max(1.0),
            End::Stalled(why) => {
                // a harder inner problem than σ allows: regularise more
                last = End::Stalled(why);
                if sigma >= SIGMA_MAX {
                    return last;
                }
                boost *= 10.0;
            }
        }
        if !residual.is_finite() {
            return End::Stalled(Stall::NonFinite);
        }
    }
    last
}

/// Solves the affine contact problem `problem` for `law` by the semismooth Newton method of
/// this module, from `lambda0` (zeros when `None`). Reports one progress line per Newton step
/// and per proximal step.
///
/// The returned [`ContactInfo`] counts Newton steps in `newton_iters` (the proximal stage's
/// inner steps included), proximal steps in `proximal_iters`, and gives Newton's constant `c`
/// in `augmentation` (and the fallback's first-order steps or sweeps, if any, in `uzawa_iters` or `sweeps`, with
/// their step in `step`); `residual` is the residual of `params.measure`, at most
/// `params.tol`, and `complementarity` the complementarity residual. The answer is the best
/// iterate found.
///
/// # Errors
/// [`ContactError::Input`] for inconsistent data; when every stage stopped short, the last
/// stage's error ([`ContactError::Stalled`], or the fallback's own), carrying the best iterate
/// of all stages, or for Coulomb's law [`ContactError::NotUnique`] where the fixed point on the
/// slip bound expands near that iterate ([`crate::slip_bound_expansion`]);
/// [`ContactError::Interrupted`] at the deadline or on cancellation.
pub fn solve_newton<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    solve_newton_cached(
        problem,
        points,
        law,
        params,
        lambda0,
        progress,
        &mut NewtonCache::default(),
    )
}

/// What the Newton solves of one compliance `D` share, whatever their loads `u₀` and their
/// law's data (a load path's steps, a fixed point's steps on the friction coefficients, the
/// corrections of a solve by the refined fields): the directions' factorisation of `D` (its
/// inverse, `m³` flops: at 1022 rows 0.05 s, more than the steps of a warm-started solve), the
/// estimate of `μ_max`, and `D`'s asymmetry (an `m²` pass: at 1026 rows about 2 ms of a
/// path's 7 ms instant). Hand the same cache only to solves of one `D` (and weights).
#[derive(Default)]
pub struct NewtonCache {
    directions: Option<Directions>,
    /// `D`'s largest relative asymmetry, where a solve of the mechanical rows read it.
    asymmetry: Option<f64>,
    /// The insulated problem's answer of a coupled problem (`Some(None)` where its solve
    /// failed).
    insulated: Option<Option<PointValues>>,
    /// The estimate of `μ_max` of a coupled problem's `D`, whatever its electric law.
    mu_max: Option<f64>,
}

/// [`solve_newton`], with what it shares with the other solves of `problem`'s compliance in
/// `cache` (taken from it where there, left in it).
///
/// # Errors
/// As [`solve_newton`].
pub fn solve_newton_cached<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
    cache: &mut NewtonCache,
) -> Result<ContactSolution, ContactError> {
    let nt = check_newton_input(problem, params)?;
    if !params.weakening {
        points.refuse_weakening()?;
    }
    let pre = Preamble::new(
        &mut Counter::new(problem),
        points,
        law,
        params.power_iters,
        params.mu_max.or(cache.mu_max),
    )?;
    let (mu_max, reference) = (pre.mu_max, pre.reference);
    cache.mu_max = Some(mu_max);
    let mut info = ContactInfo::new(mu_max);
    let start = match lambda0 {
        Some(l) => pre.start(Some(l))?,
        None => match nested_start(problem, points, law, params) {
            Some((l, steps)) => {
                info.coarse_newton_iters = steps;
                info.stages.push(Phase::NestedStart);
                l
            }
            None => pre.start(None)?,
        },
    };
    let x0 = start.to_flat();
    let u0 = problem.loads().clone();
    let mut flat = Flat::new(problem.compliance(), &u0, points, law, nt, mu_max);
    flat.weakening = params.weakening;
    if let Some(a) = cache.asymmetry {
        flat.know_asymmetry(a);
    }
    info.augmentation = Some(1.0 / mu_max);
    let asked = Asked { points, law, params };
    let in_sweeps = Directions::step_in_sweeps(&flat);
    cache.asymmetry = flat.known_asymmetry();
    let x0 = match sweeps_first(
        problem,
        asked,
        (mu_max, reference),
        &start,
        in_sweeps,
        &mut info,
        progress,
    )? {
        First::Solved(solution) => return Ok(*solution),
        First::Skipped => x0,
    };
    let mut judge = Judge::new(flat, law, points, &u0, params, reference);
    if info.coarse_newton_iters > 0 {
        judge.seed = Some(judge.flat.state(vec![0.0; x0.len()]).norm);
    }
    let (best, best_residual, stall) = judge.run_stages(x0, params, &mut info, progress, &mut cache.directions)?;
    cache.asymmetry = judge.flat.known_asymmetry();
    let Some(reason) = stall else {
        let (lambda, u) = (judge.flat.values(&best.x), judge.flat.values(&best.u));
        info.complementarity = judge.complementarity(&best);
        info.residual = best_residual;
        let status = classify(&lambda, &slip_bound(&judge.points_at(&u), law, &lambda.normal));
        return Ok(ContactSolution {
            status,
            lambda,
            u,
            info,
            electric: None,
        });
    };
    let stalled = judge.iterate(&best, best_residual);
    after_stall(problem, asked, stalled, reason, info, progress)
}

/// How stage 0 ended.
enum First {
    /// The sweeps met the tolerance.
    Solved(Box<ContactSolution>),
    /// No sweeps ran, or they were abandoned: Newton starts as it would without them.
    Skipped,
}

/// Newton steps the budget of stage 0 stands for: the sweeps go on while their measured rate
/// promises the tolerance within the cost of this many Newton steps. Measured on Siconos'
/// test problems (docs/fclib.md): where the sweeps win they need the cost of 1 to 20 Newton
/// steps (2D granular problems: 320 to 610 sweeps, where Newton takes 76 to 101 steps); where
/// Newton wins, 35 or more (the Kapla tower: 1056 sweeps against 10 proximal Newton steps), or
/// they stall (rigid capsules and boxes).
const FIRST_SWEEPS_STEPS: f64 = 25.0;

/// Stage 0: block Gauss–Seidel sweeps from `start` ([`crate::gauss_seidel`]), where `step`
/// (a Newton step's cost in sweeps) says the compliance is not a condensed finite-element one (a multibody Delassus operator, sparse or
/// asymmetric) and the law holds constant coefficients. The sweeps run while the rate they
/// measure promises the tolerance within [`FIRST_SWEEPS_STEPS`] Newton steps' cost
/// ([`Directions::step_in_sweeps`]); where it does not, Newton starts as it would have. The
/// choice is the problem's: where a point's own block dominates its coupling to
/// the others, sweeps converge fast and need no factorisation.
fn sweeps_first<P: AffineProblem>(
    problem: &P,
    Asked { points, law, params }: Asked<'_>,
    (mu_max, reference): (f64, f64),
    start: &PointValues,
    step: Option<f64>,
    info: &mut ContactInfo,
    progress: &mut dyn FnMut(&Progress),
) -> Result<First, ContactError> {
    let Some(step) = step else {
        return Ok(First::Skipped);
    };
    if !params.schedule.has(Phase::Sweeps) || params.weakening {
        return Ok(First::Skipped);
    }
    let budget = FIRST_SWEEPS_STEPS * step;
    let run = gauss_seidel::Sweeps {
        problem,
        points,
        law,
        measure: params.measure,
        tol: params.tol,
        mu_max,
        reference,
    }
    .run(start, budget as usize, Some(budget), 10, &params.interrupt, progress);
    info.sweeps += run.sweeps;
    info.stages.push(Phase::Sweeps);
    match run.end {
        SweepEnd::Converged => {
            let best = run.best.expect("a converged run judged an iterate");
            // no Newton step ran: no natural-map constant to report
            let info = ContactInfo {
                augmentation: None,
                ..info.clone()
            };
            let solution = gauss_seidel::solution(best, points, law, info, mu_max, reference);
            Ok(First::Solved(Box::new(solution)))
        }
        SweepEnd::Interrupted(why) => Err(ContactError::Interrupted {
            why,
            n_iters: run.sweeps,
            residual: run.residual,
            best: run.best.map(Box::new),
        }),
        // Newton from its own start: from the sweeps' best iterate it took more steps on the
        // rigid multibody problems where sweeps stall (measured: Capsules-i101-404 162 steps
        // against 90, RockPile_tob1 past 60 s against 47 s)
        _ => Ok(First::Skipped),
    }
}

/// Newton's start from the answer of the problem on a coarser set of the points
/// ([`crate::coarse`], nested iteration), solved by this same method (so from a coarser one
/// still; no fallback, and at most [`COARSE_PROXIMAL`] proximal steps), with its steps on all
/// coarser problems; `None` where the points make no coarser
/// set, `D` is not dense, or the coarser solve fails (Newton then starts from zero).
fn nested_start<P: AffineProblem>(
    problem: &P,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
) -> Option<(PointValues, usize)> {
    if !params.schedule.has(Phase::NestedStart) {
        return None;
    }
    let coarsening = coarse::coarsen(points)?;
    let mut coarse = coarsening.problem(problem.compliance(), problem.loads(), points)?;
    let quiet = NewtonParams {
        schedule: params.schedule.without(Phase::Fallback),
        max_proximal: params.max_proximal.min(COARSE_PROXIMAL),
        mu_max: None,
        ..*params
    };
    let sol = solve_newton(
        &mut coarse,
        &coarsening.points(points),
        &coarsening.law(law, points),
        &quiet,
        None,
        &mut |_| {},
    )
    .ok()?;
    let steps = sol.info.newton_iters + sol.info.coarse_newton_iters;
    Some((coarsening.prolong(&sol.lambda, points), steps))
}

/// Solves the contact problem with electrical contact, `problem`, for `law` by the semismooth
/// Newton method on the mechanical and electric rows together (stages 1 and 2 of
/// [`crate::solve_newton`]; no first-order fallback, whose solvers hold no electric rows).
/// The solution carries the flux and potential of the electric points
/// ([`ContactSolution::electric`]); its residuals are the larger of the mechanical one (the
/// measure asked for) and the electric equations' own, relative to the flux.
///
/// # Errors
/// [`ContactError::Input`] for inconsistent data or slip-weakening parameters (not solved with
/// electrical contact); [`ContactError::Stalled`] where both stages stopped short, with the
/// best iterate; [`ContactError::Interrupted`].
pub fn solve_newton_electric(
    problem: &ElectricContactProblem,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    problem.check(points)?;
    if params.weakening || points.weakens() {
        return Err(InputError::Unsupported("slip-weakening friction with electrical contact").into());
    }
    let (mut scaled, s) = problem.scaled();
    let mut sol = solve_electric(&mut scaled, points, law, params, progress, &mut NewtonCache::default())?;
    if let Some(e) = &mut sol.electric {
        e.flux.iter_mut().for_each(|q| *q *= s);
        e.potential.iter_mut().for_each(|v| *v /= s);
    }
    Ok(sol)
}

/// [`crate::solve_newton_electric`] on the scaled problem: stages 1 and 2 on the mechanical
/// and electric rows together; a stall is a [`ContactError::Stalled`] with the best iterate.
/// What the solves of one `D` under its electric laws share ([`NewtonCache`]) comes from `cache`
/// where it is there, and is left there.
fn solve_electric(
    problem: &mut ElectricContactProblem,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    progress: &mut dyn FnMut(&Progress),
    cache: &mut NewtonCache,
) -> Result<ContactSolution, ContactError> {
    check_tolerance(params)?;
    // the candidates and the coupled problem share `D`, and so its largest eigenvalue
    let pre = Preamble::new(
        &mut Counter::new(problem),
        points,
        law,
        params.power_iters,
        params.mu_max.or(cache.mu_max),
    )?;
    let (mu_max, reference) = (pre.mu_max, pre.reference);
    cache.mu_max = Some(mu_max);
    let mut info = ContactInfo::new(mu_max);
    info.augmentation = Some(1.0 / mu_max);
    let u0 = problem.u0.clone();
    let flat = Flat::new(Compliance::Dense(&problem.compliance), &u0, points, law, pre.nt, mu_max).with_electric(
        Compliance::Dense(&problem.compliance),
        &problem.electric,
        &problem.phi0,
    );
    // the start's own Newton steps count among the run's
    let (x0, steps) = electric_start(problem, &flat, points, law, params, cache);
    info.newton_iters += steps;
    let mut judge = Judge::new(flat, law, points, &u0, params, reference);
    let (best, best_residual, stall) = judge.run_stages(x0, params, &mut info, progress, &mut cache.directions)?;
    if let Some(reason) = stall {
        let best = judge.iterate(&best, best_residual);
        return Err(stall_error(&info, best_residual, reason, Some(best)));
    }
    // the ideal conductor on a rigid foundation: the widest member of its family
    let (best, best_residual) = match (problem.electric.law, points.all_rigid()) {
        (crate::ElectricLaw::Conducting, true) => {
            member::widest(&judge, best, best_residual, params, &mut info, &mut cache.directions)
        }
        _ => (best, best_residual),
    };
    let (lambda, u) = (judge.flat.values(&best.x), judge.flat.values(&best.u));
    info.complementarity = judge.complementarity(&best);
    info.residual = best_residual;
    let start = judge.flat.mechanical();
    let electric = ElectricValues {
        points: problem.electric.points.clone(),
        flux: best.x[start..].to_vec(),
        potential: best.u[start..].to_vec(),
    };
    let status = classify(&lambda, &slip_bound(points, law, &lambda.normal));
    Ok(ContactSolution {
        status,
        lambda,
        u,
        info,
        electric: Some(electric),
    })
}

/// The start of the coupled Newton (with the Newton steps it took): one sweep of the fixed point that alternates the two
/// problems, from the better of two mechanical states. The mechanical state is the insulated
/// problem's (no flux) and, for a conductive foundation, the ideal conductor's too (its limit
/// `σ_c → ∞`, solved first by this same method); with it held, the electric rows are linear in
/// the flux ([`Flat::electric_given_mechanics`]). The start is the candidate of least merit.
/// From zero flux the first Newton step linearises the law's product `p (φ - φ_F)` far from
/// both factors and overshoots (measured on `paper-conductive`: 335 steps from zero).
fn electric_start(
    problem: &ElectricContactProblem,
    flat: &Flat<'_>,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    cache: &mut NewtonCache,
) -> (Vec<f64>, usize) {
    let zero = vec![0.0; flat.m];
    let mut steps = 0;
    // candidates, not answers: Newton's first stage alone, capped (the ideal conductor may
    // have no solution where the potential lifts the body off: measured, its proximal stage
    // took 3300 steps and 25 s at n = 128 before it failed)
    let quiet = NewtonParams {
        schedule: params.schedule.without(Phase::Fallback).without(Phase::Proximal),
        max_proximal: 0,
        max_iters: params.max_iters.min(START_STEPS),
        ..*params
    };
    let mut mechanical = vec![];
    if cache.insulated.is_none() {
        let sol = solve_newton(&mut problem.insulated(), points, law, &quiet, None, &mut |_| {});
        steps += sol.as_ref().map_or(0, |s| s.info.newton_iters);
        cache.insulated = Some(sol.ok().map(|s| s.lambda));
    }
    if let Some(Some(lambda)) = &cache.insulated {
        mechanical.push(lambda.clone());
    }
    if matches!(problem.electric.law, crate::ElectricLaw::Conductive { .. }) {
        let mut ideal = problem.clone();
        ideal.electric.law = crate::ElectricLaw::Conducting;
        if let Ok(sol) = solve_electric(&mut ideal, points, law, &quiet, &mut |_| {}, cache) {
            steps += sol.info.newton_iters;
            mechanical.push(sol.lambda);
        }
    }
    let start = flat.mechanical();
    let mut best = (flat.state(zero.clone()).norm, zero);
    for lambda in mechanical {
        let mut x = vec![0.0; flat.m];
        for (v, l) in x.iter_mut().zip(lambda.normal.iter().chain(&lambda.tangential)) {
            *v = *l;
        }
        if let Some(q) = flat.electric_given_mechanics(&x) {
            x[start..].copy_from_slice(&q);
        }
        let norm = flat.state(x.clone()).norm;
        if norm < best.0 {
            best = (norm, x);
        }
    }
    (best.1, steps)
}

/// After Newton's stages stalled at the iterate `stalled`: stage 3 (the fallback, where the
/// parameters ask for it), and then whose failure it is ([`whose_failure`]).
fn after_stall<P: AffineProblem>(
    problem: &mut P,
    asked: Asked<'_>,
    stalled: Iterate,
    reason: Stall,
    info: ContactInfo,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    let Asked { points, law, params } = asked;
    let best_residual = stalled.residual;
    let failure = if params.schedule.has(Phase::Fallback) && !params.weakening {
        match fallback(
            problem,
            asked,
            stalled.lambda.clone(),
            best_residual,
            info.clone(),
            progress,
        ) {
            Ok(sol) => return Ok(sol),
            Err(e) => e,
        }
    } else {
        stall_error(&info, best_residual, reason, None)
    };
    Err(whose_failure(
        problem,
        points,
        law,
        params,
        failure.with_best(stalled),
        &info,
    ))
}

/// Checks what [`solve_newton`] needs beside the input every solver checks (before the
/// compliance is applied): the compliance's size against the loads', and the tolerance;
/// returns the tangential components per point.
fn check_newton_input<P: AffineProblem>(problem: &P, params: &NewtonParams) -> Result<usize, ContactError> {
    let (n, nt) = (problem.weights().len(), problem.n_tangential());
    let m = n * (1 + nt);
    if problem.compliance().size() != m || problem.loads().n_points() != n {
        return Err(InputError::ComplianceSize {
            size: problem.compliance().size(),
            points: problem.loads().n_points(),
            n,
            nt,
            m,
        }
        .into());
    }
    check_tolerance(params)?;
    Ok(nt)
}

/// The tolerance must be positive.
fn check_tolerance(params: &NewtonParams) -> Result<(), ContactError> {
    if !(params.tol > 0.0) {
        return Err(InputError::Parameter(format!("Newton tolerance {} must be positive", params.tol)).into());
    }
    Ok(())
}

/// Newton's stall at `residual` for `reason`, in the stage it reached, with the best iterate
/// where the caller gives it.
fn stall_error(info: &ContactInfo, residual: f64, reason: Stall, best: Option<Iterate>) -> ContactError {
    ContactError::Stalled {
        stage: if info.proximal_iters > 0 {
            Stage::Proximal
        } else {
            Stage::Newton
        },
        n_iters: info.newton_iters,
        residual,
        reason,
        best: best.map(Box::new),
    }
}

/// Newton's stages from `x0` (docs/theory.md, "Semismooth Newton"), run by one loop over the
/// schedule's Newton stages, each from the best iterate of those before (stage 2b from stage
/// 1's), each run only where the ones before stalled:
///
/// | stage | what | where |
/// |---|---|---|
/// | 1 | Newton on the problem itself, with a patience rule | always |
/// | 2 | the proximal point method | [`Phase::Proximal`] in the schedule, `max_proximal > 0` |
/// | 2b | Newton under its own lenient rules (non-monotone, no patience) | [`Phase::Lenient`], a sparse or asymmetric compliance, where stage 1 ran under stricter rules |
///
/// (Stage 0, the sweeps, and the nested start run before, [`sweeps_first`] and
/// [`nested_start`]; stage 3, the first-order fallback, after, [`fallback`].) The stages that
/// ran are added to `info.stages`. The directions' factorisation is taken from `cache`, or
/// made and left there (problems of one compliance share it).
fn newton_stages(
    judge: &mut Judge<'_>,
    x0: Vec<f64>,
    params: &NewtonParams,
    info: &mut ContactInfo,
    progress: &mut dyn FnMut(&Progress),
    cache: &mut Option<Directions>,
) -> End {
    let s = judge.flat.state(x0);
    // a start that meets the tolerance is the answer, or, where asked, kept aside for the
    // Newton iterates that follow it (offered only if they stall)
    let refined = (params.refine_start && judge.residual(&s) <= judge.tol).then(|| s.clone());
    if refined.is_none() && judge.offer(&s).1 {
        return End::Converged;
    }
    let directions = cache.get_or_insert_with(|| Directions::new(&judge.flat)).clone();
    let proximal = params.schedule.has(Phase::Proximal) && params.max_proximal > 0;
    let lenient = params.schedule.has(Phase::Lenient) && !directions.symmetric_dense();
    let (mut end, mut stage_1, mut start) = (End::Stalled(Stall::IterationLimit), None, Some(s));
    for phase in params.schedule.phases() {
        let ran = match phase {
            Phase::Newton => {
                let strict = Rules {
                    steps: params.max_iters,
                    patience: PATIENCE,
                    lenient: false,
                    seed: judge.seed,
                    // the proximal stage takes over from a cycle; without it (the nested
                    // start's coarser solves) Newton searches on
                    cycles: proximal,
                };
                let Some(s) = start.take() else { continue };
                end = judged_steps(judge, &directions, s, strict, params, info, progress);
                if let (Some(start), End::Stalled(_)) = (&refined, &end) {
                    judge.offer(start);
                    info.stages.push(Phase::Newton);
                    return End::Converged;
                }
                // stage 2b goes on with stage 1's search: from stage 1's best, not from where
                // the proximal iterates wandered (on a problem past uniqueness they can end
                // near a point Newton does not leave: measured on a multibody problem,
                // fclib.rs); kept only where stage 2b may run
                if matches!(end, End::Stalled(_)) && lenient {
                    stage_1 = judge.best.get().map(|(start, _)| start.clone());
                }
                true
            }
            Phase::Proximal if proximal => {
                end = proximal_stage(judge, &directions, params, info, progress);
                true
            }
            Phase::Lenient if lenient => match stage_1.take() {
                Some(start) => {
                    let steps = LENIENT_STEPS * params.max_iters;
                    let rules = Rules {
                        steps,
                        patience: steps,
                        lenient: true,
                        seed: None,
                        cycles: false,
                    };
                    end = judged_steps(judge, &directions, start, rules, params, info, progress);
                    true
                }
                None => false,
            },
            _ => false,
        };
        if ran {
            info.stages.push(phase);
        }
        if !matches!(end, End::Stalled(_)) {
            break;
        }
    }
    end
}

/// Whose failure a failure of every stage is: for Coulomb's law, the problem's where the fixed
/// point on the slip bound expands at the best iterate (the contraction the uniqueness
/// theorem rests on fails: [`ContactError::NotUnique`]), else the solvers' (`failure` itself).
fn whose_failure<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    failure: ContactError,
    info: &ContactInfo,
) -> ContactError {
    if *law != Law::Coulomb || matches!(failure, ContactError::Interrupted { .. }) {
        return failure;
    }
    let Some(best) = failure.best().cloned() else {
        return failure;
    };
    match crate::slip_bound_expansion(problem, points, &best.lambda, &params.interrupt) {
        Ok(expansion) if expansion >= 1.0 => ContactError::NotUnique {
            expansion,
            n_iters: info.newton_iters,
            residual: best.residual,
            best: Some(Box::new(best)),
        },
        _ => failure,
    }
}

/// Stage 3, from the best multipliers projected onto the sets: block Gauss–Seidel for
/// Coulomb's law, the accelerated projected gradient for the convex laws.
fn fallback<P: AffineProblem>(
    problem: &mut P,
    Asked { points, law, params }: Asked<'_>,
    lambda: PointValues,
    residual: f64,
    info: ContactInfo,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    let n = lambda.n_points();
    progress(&Progress {
        stage: Stage::Fallback,
        iter: info.newton_iters,
        residual,
        counts: counts(&classify(&lambda, &slip_bound(points, law, &lambda.normal))),
    });
    let mut start = lambda;
    start
        .normal
        .iter_mut()
        .for_each(|v| *v = crate::project_nonnegative(*v));
    let radius = slip_bound(points, law, &start.normal);
    for i in 0..n {
        points.project_friction(i, start.tangential_of_mut(i), radius[i]);
    }
    let mut sol = if *law == Law::Coulomb || !points.all_rigid() {
        // Coulomb's law, or a compliant foundation's, directly, point by point
        let gs = GaussSeidelParams {
            tol: params.tol,
            measure: params.measure,
            max_sweeps: params.max_fallback_iters,
            power_iters: params.power_iters,
            report_every: 100,
            interrupt: params.interrupt,
        };
        crate::solve_gauss_seidel(problem, points, law, &gs, Some(start), progress)?
    } else {
        // a convex problem: the accelerated gradient converges
        let apg = UzawaParams {
            rule: StopRule::Tight { tol: params.tol },
            measure: params.measure,
            accelerate: true,
            power_iters: params.power_iters,
            max_iters: params.max_fallback_iters,
            report_every: 500,
            interrupt: params.interrupt,
            ..Default::default()
        };
        crate::solve_uzawa(problem, points, law, &apg, Some(start), progress)?
    };
    sol.info.newton_iters = info.newton_iters;
    sol.info.proximal_iters = info.proximal_iters;
    sol.info.line_search_cuts = info.line_search_cuts;
    sol.info.augmentation = info.augmentation;
    sol.info.fallback = true;
    sol.info.sweeps += info.sweeps;
    sol.info.stages.clone_from(&info.stages);
    sol.info.stages.push(Phase::Fallback);
    Ok(sol)
}
