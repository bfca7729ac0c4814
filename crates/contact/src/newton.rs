//! A semismooth Newton method on the condensed contact problem: the natural-map (Alart–Curnier)
//! equations of Signorini contact with Tresca or Coulomb friction, solved for the multipliers
//! with the contact compliance given densely. Coulomb friction is solved directly (the radius
//! `F [λ_n + c (u_n - g)]₊` moves with the pressure), without the fixed point on `S`.
//!
//! With `u(λ) = u₀ - D W λ` and `z = λ + c (u(λ) - g̃)` (`g̃ = (g, 0)`), the equations are
//! `λ_n - [z_n]₊ = 0` and `λ_t - P_S(z_t) = 0` at every point. They are piecewise smooth; a
//! generalised Jacobian picks, per point, the branch of `z` (separated, stick, slip). Each step
//! solves the dense `m x m` Newton system by LU, and an Armijo line search on the weighted norm
//! of the equations globalises the iteration. Where the line search fails (a Newton direction
//! that does not reduce the residual), the solve falls back on the accelerated projected
//! gradient of [`crate::solve`], warm-started from the best multipliers found, so that the
//! answer is never worse than the first-order method's. `c = 1/μ_max`, the residual's own
//! constant: nothing is tuned by hand.

use crate::operator::DenseContactProblem;
use crate::points::{ContactPoints, PointValues};
use crate::projection::project_disc;
use crate::solution::{
    check_input, classify, complementarity_residual, counts, estimate_mu_max, multiplier_scale, slip_bound, Counter,
};
use crate::{ContactError, ContactInfo, ContactSolution, Law, Progress, Stage, StopRule, UzawaParams};
use faer::linalg::solvers::Solve;
use faer::Mat;

/// Parameters of [`solve_newton`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonParams {
    /// Tolerance on the complementarity residual (the same as [`crate::complementarity_residual`]
    /// with the law's radius).
    pub tol: f64,
    /// Newton iteration limit before the fallback takes over.
    pub max_iters: usize,
    /// Power iterations for `μ_max`.
    pub power_iters: usize,
    /// Whether to fall back on the accelerated projected gradient when Newton stalls (when
    /// false, a stall is a [`ContactError::NewtonStalled`]).
    pub fallback: bool,
}

impl Default for NewtonParams {
    fn default() -> Self {
        NewtonParams {
            tol: 1e-10,
            max_iters: 100,
            power_iters: 30,
            fallback: true,
        }
    }
}

/// `(Σ w_j x_j²)^½`; where the sum of squares would overflow or underflow, scaled by the
/// largest entry first.
fn weighted_norm(x: &[f64], w: &[f64]) -> f64 {
    // divided by s: `1/s` overflows for a subnormal s
    let sum = |s: f64| x.iter().zip(w).map(|(v, w)| w * (v / s) * (v / s)).sum::<f64>();
    let plain = sum(1.0);
    if crate::projection::trusted(plain) || x.iter().all(|v| *v == 0.0) {
        return plain.sqrt();
    }
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return if x.iter().any(|v| v.is_nan()) { f64::NAN } else { scale };
    }
    scale * sum(scale).sqrt()
}

/// Armijo's sufficient-decrease constant.
const ARMIJO: f64 = 1e-4;
/// Merit values the non-monotone line search compares with.
const MEMORY: usize = 8;
/// Step halvings of the line search before the direction is given up.
const MAX_HALVINGS: usize = 30;

/// One row of the generalised Jacobian, `J_r = E_r + B_r C` (`C = c D W`), with `E_r` and `B_r`
/// sparse: `(index, coefficient)` pairs.
#[derive(Clone, Debug, Default, PartialEq)]
struct RowForm {
    e: Vec<(usize, f64)>,
    b: Vec<(usize, f64)>,
}

/// The branch of a point's equations at `z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Branch {
    Separated,
    Stick,
    Slip,
}

/// The problem in the flat layout `[normal (n); tangential (n·nt)]`.
struct Flat<'a> {
    p: &'a DenseContactProblem,
    points: &'a ContactPoints,
    law: &'a Law,
    n: usize,
    nt: usize,
    m: usize,
    c: f64,
    /// Weight of each flat index.
    w: Vec<f64>,
    u0: Vec<f64>,
}

/// The equations and their pieces at one `λ`.
struct State {
    x: Vec<f64>,
    u: Vec<f64>,
    z: Vec<f64>,
    f: Vec<f64>,
    /// Weighted norm of `f`.
    norm: f64,
}

impl Flat<'_> {
    /// The radius of point `i` at `z`: Tresca `S`, Coulomb `F [z_n]₊`.
    fn radius(&self, i: usize, z: &[f64]) -> f64 {
        match self.law {
            Law::Frictionless => 0.0,
            Law::Tresca(s) => s[i],
            Law::Coulomb => self.points.friction[i] * z[i].max(0.0),
        }
    }

    fn state(&self, x: Vec<f64>) -> State {
        let m = self.m;
        let wx: Vec<f64> = x.iter().zip(&self.w).map(|(a, b)| a * b).collect();
        let mut u = vec![0.0; m];
        let mut z = vec![0.0; m];
        for r in 0..m {
            u[r] = self.u0[r] - crate::operator::dot8(&self.p.compliance[r * m..(r + 1) * m], &wx);
            let g = if r < self.n { self.points.gap[r] } else { 0.0 };
            z[r] = x[r] + self.c * (u[r] - g);
        }
        let mut f = vec![0.0; m];
        let mut buf = [0.0; 2];
        for i in 0..self.n {
            f[i] = x[i] - z[i].max(0.0);
            if self.nt > 0 {
                let t = self.n + i * self.nt;
                buf[..self.nt].copy_from_slice(&z[t..t + self.nt]);
                project_disc(&mut buf[..self.nt], self.radius(i, &z));
                for k in 0..self.nt {
                    f[t + k] = x[t + k] - buf[k];
                }
            }
        }
        let norm = weighted_norm(&f, &self.w);
        State { x, u, z, f, norm }
    }

    /// The rows of a generalised Jacobian at `s`, each as `J_r = E_r + B_r C` with
    /// `C = c D W` (so that `M = I - C` is the derivative of `z`) and `E_r`, `B_r` sparse over
    /// the point's own components.
    fn rows(&self, s: &State) -> Vec<RowForm> {
        let (n, nt) = (self.n, self.nt);
        let mut rows = vec![RowForm::default(); self.m];
        for i in 0..n {
            // normal: [z_n]₊ has derivative 1 (contact: J = C) or 0 (separated: J = I)
            if s.z[i] > 0.0 {
                rows[i].b.push((i, 1.0));
            } else {
                rows[i].e.push((i, 1.0));
            }
            if nt == 0 {
                continue;
            }
            let t = n + i * nt;
            let q = &s.z[t..t + nt];
            let qn = crate::projection::norm(q);
            let radius = self.radius(i, &s.z);
            let branch = if !(radius > 0.0) {
                Branch::Separated
            } else if qn <= radius {
                Branch::Stick
            } else {
                Branch::Slip
            };
            for k in 0..nt {
                let row = &mut rows[t + k];
                match branch {
                    // λ_t - z_t: derivative C
                    Branch::Stick => row.b.push((t + k, 1.0)),
                    // λ_t - P_0(z_t) = λ_t (a zero radius): the identity
                    Branch::Separated => row.e.push((t + k, 1.0)),
                    Branch::Slip => {
                        // λ_t - S q/|q|: derivative I - (S/|q|)(I - q̂q̂ᵀ) M_t - q̂ dS, with
                        // dS = F M_n for Coulomb at a contact point
                        let ratio = radius / qn;
                        let slope = match self.law {
                            Law::Coulomb if s.z[i] > 0.0 => self.points.friction[i],
                            _ => 0.0,
                        };
                        row.e.push((t + k, 1.0));
                        for l in 0..nt {
                            let proj = if k == l { 1.0 } else { 0.0 } - (q[k] / qn) * (q[l] / qn);
                            if proj != 0.0 {
                                row.e.push((t + l, -ratio * proj));
                                row.b.push((t + l, ratio * proj));
                            }
                        }
                        if slope > 0.0 {
                            row.e.push((i, -q[k] / qn * slope));
                            row.b.push((i, q[k] / qn * slope));
                        }
                    }
                }
            }
        }
        rows
    }

    /// The Newton direction `J δ = -f` by one LU of the whole `m x m` Jacobian; `None` where
    /// it is singular.
    fn direction(&self, s: &State, rows: &[RowForm]) -> Option<Vec<f64>> {
        let (m, c) = (self.m, self.c);
        let d = &self.p.compliance;
        // Jᵀ, column-major: row r of J is column r of Jᵀ, written contiguously
        let mut jt = Mat::<f64>::zeros(m, m);
        for (r, form) in rows.iter().enumerate() {
            for &(j, v) in &form.e {
                jt[(j, r)] += v;
            }
            for &(j, v) in &form.b {
                for col in 0..m {
                    jt[(col, r)] += v * c * d[j * m + col] * self.w[col];
                }
            }
        }
        let lu = jt.partial_piv_lu();
        let mut rhs = Mat::<f64>::from_fn(m, 1, |r, _| -s.f[r]);
        lu.solve_transpose_in_place(rhs.as_mut());
        let delta: Vec<f64> = (0..m).map(|r| rhs[(r, 0)]).collect();
        delta.iter().all(|v| v.is_finite()).then_some(delta)
    }

    /// The same direction through `y = C δ`: `(E C⁻¹ + B) y = -f`, whose rows are the identity
    /// at every point in contact and sticking (`E_r = 0`, `B_r = e_r`), so that only the rows of
    /// sliding and separated points form a dense system (`N x N`, often far smaller than
    /// `m x m`, and empty when every point sticks); then `δ = C⁻¹ y`. `stiffness` is `D⁻¹`
    /// (row-major). `None` where the reduced system is singular.
    fn direction_reduced(&self, s: &State, rows: &[RowForm], stiffness: &[f64]) -> Option<Vec<f64>> {
        let (m, c) = (self.m, self.c);
        let identity = |r: usize, form: &RowForm| form.e.is_empty() && form.b == [(r, 1.0)];
        let mut slot = vec![usize::MAX; m];
        let others: Vec<usize> = (0..m).filter(|&r| !identity(r, &rows[r])).collect();
        for (k, &r) in others.iter().enumerate() {
            slot[r] = k;
        }
        // y on the identity rows is -f there
        let mut y: Vec<f64> = (0..m)
            .map(|r| if slot[r] == usize::MAX { -s.f[r] } else { 0.0 })
            .collect();
        let nn = others.len();
        if nn > 0 {
            // rows of M = E C⁻¹ + B on the other rows; C⁻¹ = W⁻¹ D⁻¹ / c
            let mut mnn = Mat::<f64>::zeros(nn, nn);
            let mut rhs = Mat::<f64>::zeros(nn, 1);
            let mut row = vec![0.0; m];
            for (k, &r) in others.iter().enumerate() {
                row.iter_mut().for_each(|v| *v = 0.0);
                for &(j, v) in &rows[r].e {
                    let scale = v / (c * self.w[j]);
                    for (x, dj) in row.iter_mut().zip(&stiffness[j * m..(j + 1) * m]) {
                        *x += scale * dj;
                    }
                }
                for &(j, v) in &rows[r].b {
                    row[j] += v;
                }
                let mut b = -s.f[r];
                for col in 0..m {
                    if slot[col] == usize::MAX {
                        b -= row[col] * y[col];
                    } else {
                        mnn[(k, slot[col])] = row[col];
                    }
                }
                rhs[(k, 0)] = b;
            }
            let lu = mnn.partial_piv_lu();
            lu.solve_in_place(rhs.as_mut());
            for (k, &r) in others.iter().enumerate() {
                y[r] = rhs[(k, 0)];
            }
        }
        // δ = C⁻¹ y; on a row that is the identity in J (a separated point: E_r = e_r, B_r = 0)
        // δ_r = -f_r exactly, which sets its multiplier to exactly zero, not to round-off
        let delta: Vec<f64> = (0..m)
            .map(|r| {
                if rows[r].b.is_empty() && rows[r].e == [(r, 1.0)] {
                    -s.f[r]
                } else {
                    crate::operator::dot8(&stiffness[r * m..(r + 1) * m], &y) / (c * self.w[r])
                }
            })
            .collect();
        delta.iter().all(|v| v.is_finite()).then_some(delta)
    }

    fn to_values(&self, x: &[f64]) -> PointValues {
        PointValues::from_flat(x, self.n, self.nt)
    }
}

/// Solves the condensed contact problem `problem` for `law` by the semismooth Newton method of
/// this module, from `lambda0` (zeros when `None`). Reports one progress line per Newton step.
///
/// The returned [`ContactInfo`] counts Newton steps in `newton_iters` and gives Newton's
/// constant `c` in `augmentation` (and the fallback's first-order steps, if any, in
/// `uzawa_iters`, with their step in `step`); `complementarity` is the residual of
/// [`crate::complementarity_residual`] with the law's radius, at most `params.tol`.
///
/// # Errors
/// [`ContactError::Input`] for inconsistent data, [`ContactError::NewtonStalled`] when Newton
/// stalls with the fallback switched off, and the fallback's own errors.
pub fn solve_newton(
    problem: &mut DenseContactProblem,
    points: &ContactPoints,
    law: &Law,
    params: &NewtonParams,
    lambda0: Option<PointValues>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactSolution, ContactError> {
    let nt_given = if problem.compliance.len() == problem.m() * problem.m() {
        problem.nt
    } else {
        return Err(ContactError::Input(format!(
            "the compliance has {} entries, not ({})²",
            problem.compliance.len(),
            problem.m()
        )));
    };
    let (n, nt) = check_input(points, law, problem.weight.len(), nt_given)?;
    if !(params.tol > 0.0) {
        return Err(ContactError::Input(format!(
            "Newton tolerance {} must be positive",
            params.tol
        )));
    }
    let (mu_max, reference) = {
        let mut counter = Counter::new(problem);
        let (mu, u0) = estimate_mu_max(&mut counter, points, nt, params.power_iters)?;
        (mu, multiplier_scale(points, &u0, 1.0 / mu))
    };
    let c = 1.0 / mu_max;
    let m = n * (1 + nt);
    let flat = Flat {
        p: problem,
        points,
        law,
        n,
        nt,
        m,
        c,
        w: (0..m)
            .map(|j| points.weight[if j < n { j } else { (j - n) / nt }])
            .collect(),
        u0: problem
            .u0
            .normal
            .iter()
            .chain(&problem.u0.tangential)
            .copied()
            .collect(),
    };
    let x0 = match lambda0 {
        Some(l) if l.normal.len() == n && l.tangential.len() == n * nt => {
            l.normal.iter().chain(&l.tangential).copied().collect()
        }
        Some(_) => return Err(ContactError::Input("warm start of the wrong size".into())),
        None => vec![0.0; m],
    };
    let mut info = ContactInfo::new(mu_max);
    info.augmentation = Some(c);
    let residual = |s: &State| {
        let lambda = flat.to_values(&s.x);
        let u = flat.to_values(&s.u);
        let radius = slip_bound(points, law, &lambda.normal);
        complementarity_residual(points, &radius, &lambda, &u, c, reference)
    };
    // D⁻¹ once (the compliance is SPD): each Newton step then solves only on the rows of the
    // sliding and separated points; without it, on the whole Jacobian
    let stiffness = {
        let d = Mat::<f64>::from_fn(m, m, |i, j| problem.compliance[i * m + j]);
        d.llt(faer::Side::Lower).ok().map(|llt| {
            let inv = faer::linalg::solvers::DenseSolveCore::inverse(&llt);
            let mut flat = vec![0.0; m * m];
            for i in 0..m {
                for j in 0..m {
                    flat[i * m + j] = inv[(i, j)];
                }
            }
            flat
        })
    };
    let mut s = flat.state(x0);
    let mut r = residual(&s);
    let mut stalled = None;
    let mut history = std::collections::VecDeque::with_capacity(MEMORY + 1);
    while !(r <= params.tol) {
        if info.newton_iters >= params.max_iters {
            stalled = Some("the iteration limit");
            break;
        }
        let rows = flat.rows(&s);
        let reduced = stiffness.as_deref().and_then(|k| flat.direction_reduced(&s, &rows, k));
        let Some(delta) = reduced.or_else(|| flat.direction(&s, &rows)) else {
            stalled = Some("a singular Newton matrix");
            break;
        };
        // non-monotone Armijo backtracking on the weighted norm of the equations, against the
        // largest of the last MEMORY norms (Grippo, Lampariello and Lucidi): a full step that
        // changes a point's branch may raise the norm for a step on the way to the solution
        let reference_norm = history.iter().copied().fold(s.norm, f64::max);
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..=MAX_HALVINGS {
            let x: Vec<f64> = s.x.iter().zip(&delta).map(|(a, b)| a + alpha * b).collect();
            let trial = flat.state(x);
            if trial.norm <= (1.0 - ARMIJO * alpha) * reference_norm {
                accepted = Some(trial);
                break;
            }
            alpha *= 0.5;
            info.line_search_cuts += 1;
        }
        let Some(next) = accepted else {
            stalled = Some("a failed line search");
            break;
        };
        history.push_back(s.norm);
        if history.len() > MEMORY {
            history.pop_front();
        }
        s = next;
        r = residual(&s);
        info.newton_iters += 1;
        let lambda = flat.to_values(&s.x);
        progress(&Progress {
            stage: Stage::Newton,
            iter: info.newton_iters,
            residual: r,
            counts: counts(&classify(&lambda, &slip_bound(points, law, &lambda.normal))),
        });
        if !r.is_finite() {
            stalled = Some("a non-finite residual");
            break;
        }
    }
    if let Some(why) = stalled {
        if !params.fallback {
            return Err(ContactError::NewtonStalled {
                n_iters: info.newton_iters,
                residual: r,
                reason: why.to_string(),
            });
        }
        let lambda = flat.to_values(&s.x);
        progress(&Progress {
            stage: Stage::Fallback,
            iter: info.newton_iters,
            residual: r,
            counts: counts(&classify(&lambda, &slip_bound(points, law, &lambda.normal))),
        });
        // the first-order method from the multipliers reached, projected onto the sets
        let mut start = lambda;
        start.normal.iter_mut().for_each(|v| *v = v.max(0.0));
        let radius = slip_bound(points, law, &start.normal);
        for i in 0..n {
            project_disc(&mut start.tangential[i * nt..(i + 1) * nt], radius[i]);
        }
        let apg = UzawaParams {
            rule: StopRule::Tight { tol: params.tol },
            accelerate: true,
            power_iters: params.power_iters,
            report_every: 500,
            ..Default::default()
        };
        let mut sol = crate::solve(problem, points, law, &apg, Some(start), progress)?;
        sol.info.newton_iters = info.newton_iters;
        sol.info.line_search_cuts = info.line_search_cuts;
        sol.info.augmentation = info.augmentation;
        sol.info.fallback = true;
        return Ok(sol);
    }
    let lambda = flat.to_values(&s.x);
    let u = flat.to_values(&s.u);
    let radius = slip_bound(points, law, &lambda.normal);
    info.complementarity = r;
    Ok(ContactSolution {
        status: classify(&lambda, &radius),
        lambda,
        u,
        info,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduced Newton solve (through `y = C δ`, on the sliding and separated rows only)
    /// gives the direction of the full LU, at states with every branch present.
    #[test]
    fn reduced_direction_is_the_full_one() {
        for (case, law) in [Law::Coulomb, Law::Tresca(vec![0.05; 5]), Law::Frictionless]
            .into_iter()
            .enumerate()
        {
            for dim in [2, 3] {
                let n = 5;
                let nt = if matches!(law, Law::Frictionless) { 0 } else { dim - 1 };
                let m = n * (1 + nt);
                let points = ContactPoints {
                    dim,
                    position: vec![[0.0; 3]; n],
                    normal: vec![[0.0, 0.0, -1.0]; n],
                    tangent: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; n],
                    weight: (0..n).map(|i| 0.5 + 0.1 * i as f64).collect(),
                    gap: vec![0.0; n],
                    friction: vec![0.3; n],
                };
                // an SPD compliance: a Gram matrix plus the identity
                let g = |i: usize, j: usize| ((i * 7 + j * 3 + case) % 5) as f64 * 0.1 - 0.2;
                let compliance: Vec<f64> = (0..m * m)
                    .map(|k| {
                        let (i, j) = (k / m, k % m);
                        (0..m).map(|l| g(i, l) * g(j, l)).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
                    })
                    .collect();
                let u0: Vec<f64> = (0..m).map(|r| (r as f64 * 1.7).sin()).collect();
                let problem = DenseContactProblem {
                    u0: PointValues::from_flat(&u0, n, nt),
                    compliance: compliance.clone(),
                    weight: points.weight.clone(),
                    nt,
                };
                let flat = Flat {
                    p: &problem,
                    points: &points,
                    law: &law,
                    n,
                    nt,
                    m,
                    c: 0.7,
                    w: (0..m)
                        .map(|j| points.weight[if j < n { j } else { (j - n) / nt }])
                        .collect(),
                    u0,
                };
                let inv = Mat::<f64>::from_fn(m, m, |i, j| compliance[i * m + j])
                    .llt(faer::Side::Lower)
                    .map(|l| faer::linalg::solvers::DenseSolveCore::inverse(&l))
                    .unwrap();
                let stiffness: Vec<f64> = (0..m * m).map(|k| inv[(k / m, k % m)]).collect();
                let x: Vec<f64> = (0..m).map(|r| 0.8 * (r as f64 * 2.3 + 0.4).cos()).collect();
                let s = flat.state(x);
                let rows = flat.rows(&s);
                // both kinds of rows are present, so the reduction is exercised
                let reduced_rows = (0..m)
                    .filter(|&r| !(rows[r].e.is_empty() && rows[r].b == [(r, 1.0)]))
                    .count();
                assert!(
                    reduced_rows > 0 && reduced_rows < m,
                    "{law:?} {dim}D: {reduced_rows} of {m}"
                );
                let full = flat.direction(&s, &rows).unwrap();
                let reduced = flat.direction_reduced(&s, &rows, &stiffness).unwrap();
                let scale = full.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                for (a, b) in full.iter().zip(&reduced) {
                    assert!((a - b).abs() <= 1e-10 * scale, "{law:?} {dim}D: {a} vs {b}");
                }
            }
        }
    }
}
