//! The projected block Gauss–Seidel method on the contact points (Jean and Moreau's
//! non-smooth Gauss–Seidel, Siconos' NSGS): each point in turn solves its own contact law
//! exactly ([`crate::local`]) against the forces of the others held at their latest values.
//! Coulomb's law is met directly, without the fixed point on `S`. It needs no factorisation,
//! only the rows of the compliance, and it does not mind a compliance that is only
//! semidefinite (rigid multibody problems), where Newton's matrices are singular; it converges
//! linearly, so it is the last stage of [`crate::solve_newton`] for Coulomb's law.

use crate::local::{Point, PointLaw};
use crate::operator::AffineProblem;
use crate::points::{ContactPoints, PointValues};
use crate::solution::{check_input, classify, counts, estimate_mu_max, multiplier_scale, slip_bound, Counter};
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
    let (n, nt) = check_input(points, law, problem.weights().len(), problem.n_tangential())?;
    let (mu_max, reference, u0) = {
        let mut counter = Counter::new(problem);
        let (mu, u0) = estimate_mu_max(&mut counter, points, nt, params.power_iters)?;
        (mu, multiplier_scale(points, &u0, 1.0 / mu), u0)
    };
    let mut lambda = match lambda0 {
        Some(l) if l.n_points() == n && l.n_tangential() == nt => l,
        Some(_) => return Err(ContactError::Input("warm start of the wrong size".into())),
        None => PointValues::zeros(n, nt),
    };
    let d = problem.compliance();
    let w = problem.weights().to_vec();
    let index = |i: usize, k: usize| if k == 0 { i } else { n + i * nt + k - 1 };
    let m = n * (1 + nt);
    // the flat index's point, and each point's block of D W
    let owner: Vec<(usize, usize)> = (0..m)
        .map(|r| {
            if r < n {
                (r, 0)
            } else {
                ((r - n) / nt, 1 + (r - n) % nt)
            }
        })
        .collect();
    let mut blocks = vec![[[0.0; 3]; 3]; n];
    for r in 0..m {
        let (i, kr) = owner[r];
        for (col, v) in d.row(r) {
            let (j, kc) = owner[col];
            if j == i {
                blocks[i][kr][kc] = v * w[i];
            }
        }
    }
    let mut info = ContactInfo::new(mu_max);
    let mut flat = vec![0.0; m];
    let mut best: Option<Iterate> = None;
    let mut since_best = 0;
    let mut residual = f64::NAN;
    for sweep in 1..=params.max_sweeps {
        for i in 0..n {
            // b = u0_i - Σ_{j ≠ i} D_ij w_j λ_j, from the latest multipliers
            let mut b = [0.0; 3];
            for k in 0..=nt {
                let r = index(i, k);
                let u0r = if k == 0 {
                    u0.normal[i]
                } else {
                    u0.tangential[i * nt + k - 1]
                };
                let mut acc = 0.0;
                for (col, v) in d.row(r) {
                    let (j, kc) = owner[col];
                    if j != i {
                        let l = if kc == 0 {
                            lambda.normal[j]
                        } else {
                            lambda.tangential[j * nt + kc - 1]
                        };
                        acc += v * w[j] * l;
                    }
                }
                b[k] = u0r - acc;
            }
            let point = Point {
                a: blocks[i],
                b,
                g: points.gap[i],
                k: 1 + nt,
                law: match law {
                    Law::Frictionless => PointLaw::Frictionless,
                    Law::Tresca(s) => PointLaw::Tresca(s[i]),
                    Law::Coulomb => PointLaw::Coulomb(points.friction[i]),
                },
                held: points.held[i],
            };
            let mut x0 = [0.0; 3];
            x0[0] = lambda.normal[i];
            x0[1..=nt].copy_from_slice(lambda.tangential_of(i));
            let x = point.solve(x0);
            lambda.normal[i] = x[0];
            lambda.tangential[i * nt..(i + 1) * nt].copy_from_slice(&x[1..=nt]);
        }
        info.uzawa_iters = sweep;
        // the sweep's residual, on u = u0 - D W λ
        for (r, slot) in flat.iter_mut().enumerate() {
            let (i, k) = owner[r];
            *slot = w[i]
                * if k == 0 {
                    lambda.normal[i]
                } else {
                    lambda.tangential[i * nt + k - 1]
                };
        }
        let mut dw = vec![0.0; m];
        d.apply(&flat, &mut dw);
        let mut u = u0.clone();
        for (r, v) in dw.iter().enumerate() {
            let (i, k) = owner[r];
            if k == 0 {
                u.normal[i] -= v;
            } else {
                u.tangential[i * nt + k - 1] -= v;
            }
        }
        residual = params
            .measure
            .of(points, law, &lambda, &u, &u0, 1.0 / mu_max, reference);
        let improved = best.as_ref().is_none_or(|b| residual < 0.99 * b.residual);
        if best.as_ref().is_none_or(|b| residual < b.residual) {
            best = Some(Iterate {
                lambda: lambda.clone(),
                u: u.clone(),
                residual,
            });
        }
        since_best = if improved { 0 } else { since_best + 1 };
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
            return Err(stopped(Stall::NonFinite, sweep, residual, best));
        }
        if let Some(why) = params.interrupt.check() {
            return Err(ContactError::Interrupted {
                why,
                n_iters: sweep,
                residual,
                best: best.map(Box::new),
            });
        }
        if since_best >= STALL_SWEEPS {
            return Err(stopped(Stall::NoProgress, sweep, residual, best));
        }
    }
    let best = match best {
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
    })
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
