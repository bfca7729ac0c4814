//! The projected block Gauss–Seidel method on the contact points (Jean and Moreau's
//! non-smooth Gauss–Seidel, Siconos' NSGS): each point in turn solves its own contact law
//! exactly ([`crate::local`]) against the forces of the others held at their latest values.
//! Coulomb's law is met directly, without the fixed point on `S`. It needs no factorisation,
//! only the rows of the compliance, and it does not mind a compliance that is only
//! semidefinite (rigid multibody problems), where Newton's matrices are singular; it converges
//! linearly, so it is the last stage of [`crate::solve_newton`] for Coulomb's law.

use crate::local::{inverse, Point, PointLaw};
use crate::operator::{dot8, AffineProblem, Compliance};
use crate::points::{ContactPoints, Flat, PointValues};
use crate::solution::{classify, counts, slip_bound, Best, Counter, Preamble};
use crate::{
    ContactError, ContactInfo, ContactSolution, Interrupt, Interruption, Iterate, Law, Measure, Progress, Stage, Stall,
};

/// Parameters of [`solve_gauss_seidel`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussSeidelParams {
    /// Tolerance on the residual of [`GaussSeidelParams::measure`].
    pub tol: f64,
    /// The residual to bring below `tol`.
    pub measure: Measure,
    /// Sweeps over the points at most.
    pub max_sweeps: usize,
    /// Power iterations for `μ_max` (the complementarity residual's constant).
    pub power_iters: usize,
    /// Report progress every this many sweeps (0: never).
    pub report_every: usize,
    /// A deadline or a cancel flag.
    pub interrupt: Interrupt,
}

impl Default for GaussSeidelParams {
    fn default() -> Self {
        GaussSeidelParams {
            tol: 1e-10,
            measure: Measure::Complementarity,
            max_sweeps: 100_000,
            power_iters: 30,
            report_every: 0,
            interrupt: Interrupt::NONE,
        }
    }
}

/// Sweeps without a 1 % gain on the best residual before the method is declared stalled.
const STALL_SWEEPS: usize = 2_000;
/// The full residual is evaluated at least every this many sweeps (it costs about one sweep:
/// one product with `D`), and whenever the sweeps' own change says the tolerance may be met.
const FULL_EVERY: usize = 10;

/// Solves the affine contact problem `problem` for `law` by block Gauss–Seidel sweeps over
/// the points, from `lambda0` (zeros when `None`). The answer is the best iterate (by the
/// measure asked for, evaluated at least every ten sweeps and wherever the sweeps' change
/// falls below its threshold); [`ContactInfo::sweeps`] counts the sweeps.
///
/// # Errors
/// [`ContactError::Input`] for inconsistent data; [`ContactError::Stalled`] or
/// [`ContactError::NoConvergence`] (with the best iterate) when the sweeps stop short of the
/// tolerance; [`ContactError::Interrupted`].
pub fn solve_gauss_seidel<P: AffineProblem>(
    problem: &mut P,
    points: &ContactPoints,
    law: &Law,
    params: &GaussSeidelParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    points.refuse_weakening()?;
    let pre = Preamble::new(&mut Counter::new(problem), points, law, params.power_iters, None)?;
    let lambda = pre.start(lambda0)?;
    let (mu_max, reference) = (pre.mu_max, pre.reference);
    let mut info = ContactInfo::new(mu_max);
    let run = Sweeps {
        problem: &*problem,
        points,
        law,
        measure: params.measure,
        tol: params.tol,
        mu_max,
        reference,
    }
    .run(
        &lambda,
        params.max_sweeps,
        None,
        params.report_every,
        &params.interrupt,
        progress,
    );
    info.sweeps = run.sweeps;
    match run.end {
        SweepEnd::Converged => {}
        SweepEnd::Interrupted(why) => {
            return Err(ContactError::Interrupted {
                why,
                n_iters: run.sweeps,
                residual: run.residual,
                best: run.best.map(Box::new),
            })
        }
        SweepEnd::Stalled(reason) => return Err(stopped(reason, run.sweeps, run.residual, run.best)),
        SweepEnd::Limit | SweepEnd::Abandoned => {
            return Err(ContactError::NoConvergence {
                n_iters: run.sweeps,
                residual: run.residual,
                best: run.best.map(Box::new),
            })
        }
    }
    let best = run.best.expect("a converged run judged an iterate");
    Ok(solution(best, points, law, info, mu_max, reference))
}

/// The solution of the converged iterate `best`, with the counts `info`.
pub(crate) fn solution(
    best: Iterate,
    points: &ContactPoints,
    law: &Law,
    mut info: ContactInfo,
    mu_max: f64,
    reference: f64,
) -> ContactSolution {
    let radius = slip_bound(points, law, &best.lambda.normal);
    info.residual = best.residual;
    info.complementarity =
        crate::complementarity_residual(points, &radius, &best.lambda, &best.u, 1.0 / mu_max, reference);
    ContactSolution {
        status: classify(&best.lambda, &radius),
        lambda: best.lambda,
        u: best.u,
        info,
        electric: None,
    }
}

/// How a run of sweeps ended.
pub(crate) enum SweepEnd {
    /// The residual met the tolerance.
    Converged,
    /// The sweep limit.
    Limit,
    /// The measured rate promised no answer within the budget ([`Sweeps::run`]).
    Abandoned,
    Stalled(Stall),
    Interrupted(Interruption),
}

/// A run of sweeps: the best iterate judged, the sweeps, the last residual, how it ended.
pub(crate) struct SweepRun {
    pub best: Option<Iterate>,
    pub sweeps: usize,
    pub residual: f64,
    pub end: SweepEnd,
}

/// The sweeps' problem, law and measure, with the preamble's `μ_max` and multiplier scale.
pub(crate) struct Sweeps<'a, P> {
    pub problem: &'a P,
    pub points: &'a ContactPoints,
    pub law: &'a Law,
    pub measure: Measure,
    pub tol: f64,
    pub mu_max: f64,
    pub reference: f64,
}

impl<P: AffineProblem> Sweeps<'_, P> {
    /// Sweeps from `lambda`, at most `max_sweeps`. The full residual is evaluated at least
    /// every [`FULL_EVERY`] sweeps and where the sweep's relative change of the multipliers
    /// falls below a threshold (Siconos' "light" error, the threshold lowered in proportion
    /// where the full residual then misses the tolerance, as Siconos' NSGS does). With a
    /// `budget`, the run is abandoned as soon as the rate measured between two evaluations
    /// (from the second window on) predicts more sweeps in all than the budget.
    pub(crate) fn run(
        &self,
        lambda: &PointValues,
        max_sweeps: usize,
        budget: Option<f64>,
        report_every: usize,
        interrupt: &Interrupt,
        progress: &mut dyn FnMut(&Progress),
    ) -> SweepRun {
        let (points, law) = (self.points, self.law);
        let (n, nt) = (lambda.n_points(), lambda.n_tangential());
        let sweeper = Sweeper::new(self.problem, Flat { n, nt });
        let u0 = self.problem.loads();
        let mut x = lambda.to_flat();
        let u0_flat = u0.to_flat();
        let laws: Vec<PointLaw> = (0..n).map(|i| point_law(law, points, i)).collect();
        let mut best = Best::new();
        let mut residual = f64::NAN;
        let mut light_tol = self.tol;
        let mut last_gain = 0;
        // the last evaluation before this one: (sweep, residual)
        let mut previous: Option<(usize, f64)> = None;
        let end = 'sweeps: {
            for sweep in 1..=max_sweeps {
                let light = sweeper.sweep(points, &laws, &u0_flat, &mut x);
                let report = report_every > 0 && sweep % report_every == 0;
                let evaluate = light <= light_tol || report || sweep % FULL_EVERY == 0 || sweep == max_sweeps;
                if !light.is_finite() {
                    break 'sweeps (sweep, SweepEnd::Stalled(Stall::NonFinite));
                }
                if evaluate {
                    let before = best.residual();
                    let lambda;
                    (lambda, residual) = self.judge(&sweeper, &x, &u0_flat, &mut best);
                    if !residual.is_finite() {
                        break 'sweeps (sweep, SweepEnd::Stalled(Stall::NonFinite));
                    }
                    if before.is_none_or(|b| residual < 0.99 * b) {
                        last_gain = sweep;
                    }
                    if report {
                        progress(&Progress {
                            stage: Stage::GaussSeidel,
                            iter: sweep,
                            residual,
                            counts: counts(&classify(&lambda, &slip_bound(points, law, &lambda.normal))),
                        });
                    }
                    if residual <= self.tol {
                        break 'sweeps (sweep, SweepEnd::Converged);
                    }
                    if light == 0.0 {
                        // a sweep that moved nothing: every later one is the same
                        break 'sweeps (sweep, SweepEnd::Stalled(Stall::NoProgress));
                    }
                    if light <= light_tol {
                        light_tol = light * self.tol / residual;
                    }
                    if let (Some(budget), Some((at, before))) = (budget, previous) {
                        if !(predicted(sweep, residual, at, before, self.tol) <= budget) {
                            break 'sweeps (sweep, SweepEnd::Abandoned);
                        }
                    }
                    previous = Some((sweep, residual));
                }
                if let Some(why) = interrupt.check() {
                    break 'sweeps (sweep, SweepEnd::Interrupted(why));
                }
                if sweep - last_gain >= STALL_SWEEPS {
                    break 'sweeps (sweep, SweepEnd::Stalled(Stall::NoProgress));
                }
            }
            (max_sweeps, SweepEnd::Limit)
        };
        let (sweeps, end) = end;
        if matches!(end, SweepEnd::Interrupted(_)) && best.residual().is_none() {
            // interrupted before the first evaluation: the caller gets the iterate it stopped at
            residual = self.judge(&sweeper, &x, &u0_flat, &mut best).1;
        }
        SweepRun {
            best: best.take(),
            sweeps,
            residual,
            end,
        }
    }

    /// The residual of the multipliers `x` (flat layout), offered to `best`: the multipliers
    /// as point values, and the residual.
    fn judge(&self, sweeper: &Sweeper<'_>, x: &[f64], u0: &[f64], best: &mut Best) -> (PointValues, f64) {
        let (n, nt) = (sweeper.flat.n, sweeper.flat.nt);
        let lambda = PointValues::from_flat(x, n, nt);
        let u = sweeper.displacement(u0, x);
        let scales = crate::solution::Scales {
            c: 1.0 / self.mu_max,
            reference: self.reference,
        };
        let residual = self
            .measure
            .of(self.points, self.law, &lambda, &u, self.problem.loads(), scales);
        best.offer(&lambda, &u, residual);
        (lambda, residual)
    }
}

/// The sweeps in all that a linear rate measured between `(at, before)` and `(sweep, now)`
/// predicts to reach `tol` (infinite where the residual did not fall).
fn predicted(sweep: usize, now: f64, at: usize, before: f64, tol: f64) -> f64 {
    let rate = (now / before).ln() / (sweep - at) as f64;
    if !(rate < 0.0) {
        return f64::INFINITY;
    }
    sweep as f64 + (tol / now).ln() / rate
}

/// Point `i`'s law.
fn point_law(law: &Law, points: &ContactPoints, i: usize) -> PointLaw {
    match law {
        Law::Frictionless => PointLaw::Frictionless,
        Law::Tresca(s) => PointLaw::Tresca(s[i]),
        Law::Coulomb => match points.tresca_of(i) {
            Some(s) => PointLaw::Tresca(s),
            None => PointLaw::Coulomb(points.friction[i]),
        },
    }
}

/// The rows of `D W` with each point's own block left out, which a sweep multiplies by the
/// latest multipliers.
enum Coupling<'p> {
    /// A dense `D` (row-major), multiplied by `W λ`: a row's product skips the point's own
    /// columns, `i` and `n + i nt ..`, by summing the three stretches between them.
    Dense(&'p [f64]),
    /// A sparse `D W` without the own blocks, compressed rows.
    Sparse {
        ptr: Vec<usize>,
        col: Vec<u32>,
        val: Vec<f64>,
    },
}

/// The sweeps' data: the compliance's rows without the own blocks, the weights, and each
/// point's own block of `D W`, which its local problem inverts.
struct Sweeper<'p> {
    d: Compliance<'p>,
    coupling: Coupling<'p>,
    /// The weights in the flat layout.
    w: Vec<f64>,
    flat: Flat,
    blocks: Vec<[[f64; 3]; 3]>,
    /// The blocks' inverses in 3D (`None` where singular), for the sticking case.
    inverses: Vec<Option<[[f64; 3]; 3]>>,
}

impl<'p> Sweeper<'p> {
    fn new<P: AffineProblem>(problem: &'p P, flat: Flat) -> Self {
        let d = problem.compliance();
        let weights = problem.weights();
        let w: Vec<f64> = (0..flat.len()).map(|r| weights[flat.owner(r).0]).collect();
        let mut blocks = vec![[[0.0; 3]; 3]; flat.n];
        let coupling = match d {
            Compliance::Dense(dense) => {
                let m = flat.len();
                for r in 0..m {
                    let (i, kr) = flat.owner(r);
                    for (kc, b) in blocks[i][kr].iter_mut().enumerate().take(1 + flat.nt) {
                        *b = dense[r * m + flat.index(i, kc)] * w[r];
                    }
                }
                Coupling::Dense(dense)
            }
            Compliance::Sparse(s) => {
                let (mut ptr, mut col, mut val) = (vec![0], vec![], vec![]);
                for r in 0..flat.len() {
                    let (i, kr) = flat.owner(r);
                    for (c, v) in s.col_idx_of_row(r).zip(s.val_of_row(r)) {
                        let (j, kc) = flat.owner(c);
                        if j == i {
                            blocks[i][kr][kc] = v * w[c];
                        } else {
                            col.push(c as u32);
                            val.push(v * w[c]);
                        }
                    }
                    ptr.push(col.len());
                }
                Coupling::Sparse { ptr, col, val }
            }
        };
        let inverses = blocks
            .iter()
            .map(|b| if flat.nt == 2 { inverse(*b, 3) } else { None })
            .collect();
        Sweeper {
            d,
            coupling,
            w,
            flat,
            blocks,
            inverses,
        }
    }

    /// `Σ_{j ≠ i} (D W)_{r j} λ_j` for row `r` of point `i`, with `xw = W λ` (dense) or `x = λ`
    /// (sparse).
    fn coupled(&self, r: usize, i: usize, x: &[f64], xw: &[f64]) -> f64 {
        match &self.coupling {
            Coupling::Dense(d) => {
                let (m, n, nt) = (self.flat.len(), self.flat.n, self.flat.nt);
                let row = &d[r * m..(r + 1) * m];
                let (t0, t1) = (n + i * nt, n + (i + 1) * nt);
                dot8(&row[..i], &xw[..i]) + dot8(&row[i + 1..t0], &xw[i + 1..t0]) + dot8(&row[t1..], &xw[t1..])
            }
            Coupling::Sparse { ptr, col, val } => {
                let range = ptr[r]..ptr[r + 1];
                col[range.clone()]
                    .iter()
                    .zip(&val[range])
                    .map(|(&c, v)| v * x[c as usize])
                    .sum()
            }
        }
    }

    /// One sweep over `x = λ` (flat layout): each point in turn solves its own law exactly
    /// against `b = u0_i - Σ_{j ≠ i} D_ij w_j λ_j`, from the latest multipliers. Returns the
    /// sweep's relative change `‖Δλ‖ / ‖λ‖` (0 where λ stays 0).
    fn sweep(&self, points: &ContactPoints, laws: &[PointLaw], u0: &[f64], x: &mut [f64]) -> f64 {
        let (n, k) = (self.flat.n, 1 + self.flat.nt);
        let mut xw: Vec<f64> = match &self.coupling {
            Coupling::Dense(_) => x.iter().zip(&self.w).map(|(a, b)| a * b).collect(),
            Coupling::Sparse { .. } => Vec::new(),
        };
        let (mut change, mut size) = (0.0, 0.0);
        for i in 0..n {
            let mut b = [0.0; 3];
            let mut x0 = [0.0; 3];
            for c in 0..k {
                let r = self.flat.index(i, c);
                b[c] = u0[r] - self.coupled(r, i, x, &xw);
                x0[c] = x[r];
            }
            let point = Point {
                a: self.blocks[i],
                b,
                g: points.gap[i],
                k,
                law: laws[i],
                held: points.held[i],
                foundation: points.foundation_of(i),
                inverse: self.inverses[i],
            };
            let new = point.solve(x0);
            for c in 0..k {
                let r = self.flat.index(i, c);
                change += (new[c] - x0[c]) * (new[c] - x0[c]);
                size += new[c] * new[c];
                x[r] = new[c];
                if !xw.is_empty() {
                    xw[r] = new[c] * self.w[r];
                }
            }
        }
        if size > 0.0 {
            (change / size).sqrt()
        } else {
            change.sqrt()
        }
    }

    /// The contact displacement `u = u0 - D W λ`.
    fn displacement(&self, u0: &[f64], x: &[f64]) -> PointValues {
        let xw: Vec<f64> = x.iter().zip(&self.w).map(|(a, b)| a * b).collect();
        let mut dw = vec![0.0; self.flat.len()];
        self.d.apply(&xw, &mut dw);
        let u: Vec<f64> = u0.iter().zip(&dw).map(|(a, b)| a - b).collect();
        PointValues::from_flat(&u, self.flat.n, self.flat.nt)
    }
}

/// A Gauss–Seidel stall, with the best iterate.
fn stopped(reason: Stall, sweeps: usize, residual: f64, best: Option<Iterate>) -> ContactError {
    ContactError::Stalled {
        stage: Stage::GaussSeidel,
        n_iters: sweeps,
        residual,
        reason,
        best: best.map(Box::new),
    }
}
