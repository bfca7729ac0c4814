//! The projected block Gauss–Seidel method on the contact points (Jean and Moreau's
//! non-smooth Gauss–Seidel, Siconos' NSGS): each point in turn solves its own contact law
//! exactly ([`crate::local`]) against the forces of the others held at their latest values.
//! Coulomb's law is met directly, without the fixed point on `S`. It needs no factorisation,
//! only the rows of the compliance, and it does not mind a compliance that is only
//! semidefinite (rigid multibody problems), where Newton's matrices are singular; it converges
//! linearly, so it is the last stage of [`crate::solve_newton`] for Coulomb's law.

use crate::local::{Point, PointLaw};
use crate::operator::{AffineProblem, Compliance};
use crate::points::{ContactPoints, Flat, PointValues};
use crate::solution::{classify, counts, slip_bound, Best, Counter, Preamble};
use crate::{ContactError, ContactInfo, ContactSolution, Interrupt, Iterate, Law, Measure, Progress, Stage, Stall};

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

/// Solves the affine contact problem `problem` for `law` by block Gauss–Seidel sweeps over
/// the points, from `lambda0` (zeros when `None`). The answer is the best iterate (by the
/// measure asked for); [`ContactInfo::uzawa_iters`] counts the sweeps.
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
    let pre = Preamble::new(&mut Counter::new(problem), points, law, params.power_iters, None)?;
    let mut lambda = pre.start(lambda0)?;
    let Preamble {
        n,
        nt,
        mu_max,
        u0,
        reference,
    } = pre;
    let sweeper = Sweeper::new(problem, Flat { n, nt });
    let mut info = ContactInfo::new(mu_max);
    let mut best = Best::new(0.99);
    let mut residual = f64::NAN;
    for sweep in 1..=params.max_sweeps {
        sweeper.sweep(points, law, &u0, &mut lambda);
        info.uzawa_iters = sweep;
        let u = sweeper.displacement(&u0, &lambda);
        residual = params
            .measure
            .of(points, law, &lambda, &u, &u0, 1.0 / mu_max, reference);
        best.offer(&lambda, &u, residual);
        if params.report_every > 0 && sweep % params.report_every == 0 {
            progress(&Progress {
                stage: Stage::GaussSeidel,
                iter: sweep,
                residual,
                counts: counts(&classify(&lambda, &slip_bound(points, law, &lambda.normal))),
            });
        }
        if residual <= params.tol {
            break;
        }
        if !residual.is_finite() {
            return Err(stopped(Stall::NonFinite, sweep, residual, best.take()));
        }
        if let Some(why) = params.interrupt.check() {
            return Err(ContactError::Interrupted {
                why,
                n_iters: sweep,
                residual,
                best: best.boxed(),
            });
        }
        if best.since() >= STALL_SWEEPS {
            return Err(stopped(Stall::NoProgress, sweep, residual, best.take()));
        }
    }
    let best = match best.take() {
        Some(b) if b.residual <= params.tol => b,
        best => {
            return Err(ContactError::NoConvergence {
                n_iters: info.uzawa_iters,
                residual,
                best: best.map(Box::new),
            })
        }
    };
    let radius = slip_bound(points, law, &best.lambda.normal);
    info.residual = best.residual;
    info.complementarity =
        crate::complementarity_residual(points, &radius, &best.lambda, &best.u, 1.0 / mu_max, reference);
    Ok(ContactSolution {
        status: classify(&best.lambda, &radius),
        lambda: best.lambda,
        u: best.u,
        info,
        electric: None,
    })
}

/// The sweeps' data: the compliance `D` (its rows in the flat layout), the weights `W`, and
/// each point's own block of `D W`, which its local problem inverts.
struct Sweeper<'p> {
    d: Compliance<'p>,
    w: Vec<f64>,
    flat: Flat,
    blocks: Vec<[[f64; 3]; 3]>,
}

impl<'p> Sweeper<'p> {
    fn new<P: AffineProblem>(problem: &'p P, flat: Flat) -> Self {
        let d = problem.compliance();
        let w = problem.weights().to_vec();
        let mut blocks = vec![[[0.0; 3]; 3]; flat.n];
        for r in 0..flat.len() {
            let (i, kr) = flat.owner(r);
            for (col, v) in d.row(r) {
                let (j, kc) = flat.owner(col);
                if j == i {
                    blocks[i][kr][kc] = v * w[i];
                }
            }
        }
        Sweeper { d, w, flat, blocks }
    }

    /// One sweep: each point in turn solves its own law exactly against
    /// `b = u0_i - Σ_{j ≠ i} D_ij w_j λ_j`, from the latest multipliers.
    fn sweep(&self, points: &ContactPoints, law: &Law, u0: &PointValues, lambda: &mut PointValues) {
        let nt = self.flat.nt;
        for i in 0..self.flat.n {
            let mut b = [0.0; 3];
            for (k, bk) in b.iter_mut().enumerate().take(1 + nt) {
                let mut acc = 0.0;
                for (col, v) in self.d.row(self.flat.index(i, k)) {
                    let (j, kc) = self.flat.owner(col);
                    if j != i {
                        acc += v * self.w[j] * lambda.component(j, kc);
                    }
                }
                *bk = u0.component(i, k) - acc;
            }
            let point = Point {
                a: self.blocks[i],
                b,
                g: points.gap[i],
                k: 1 + nt,
                law: match law {
                    Law::Frictionless => PointLaw::Frictionless,
                    Law::Tresca(s) => PointLaw::Tresca(s[i]),
                    Law::Coulomb => PointLaw::Coulomb(points.friction[i]),
                },
                held: points.held[i],
                foundation: points.foundation,
            };
            let mut x0 = [0.0; 3];
            for (k, x) in x0.iter_mut().enumerate().take(1 + nt) {
                *x = lambda.component(i, k);
            }
            let x = point.solve(x0);
            for (k, &xk) in x.iter().enumerate().take(1 + nt) {
                *lambda.component_mut(i, k) = xk;
            }
        }
    }

    /// The contact displacement `u = u0 - D W λ`.
    fn displacement(&self, u0: &PointValues, lambda: &PointValues) -> PointValues {
        let flat: Vec<f64> = (0..self.flat.len())
            .map(|r| {
                let (i, k) = self.flat.owner(r);
                self.w[i] * lambda.component(i, k)
            })
            .collect();
        let mut dw = vec![0.0; self.flat.len()];
        self.d.apply(&flat, &mut dw);
        let mut u = u0.clone();
        for (r, v) in dw.iter().enumerate() {
            let (i, k) = self.flat.owner(r);
            *u.component_mut(i, k) -= v;
        }
        u
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
