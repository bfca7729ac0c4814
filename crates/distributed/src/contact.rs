//! Contact on the full system: a primal-dual active set method (Hüeber, Stadler and Wohlmuth,
//! SIAM J. Sci. Comput. 30 (2008) 572-596; a semismooth Newton method on the natural map),
//! each step one Krylov solve of the full system with the step's constraints.
//!
//! With `z_n = λ_n + c (u_n - g)` and `z_t = λ_t + c u_t` from the last iterate, per point:
//!
//! - `z_n ≤ 0`: separated, `λ = 0`;
//! - `z_n > 0` and `|z_t| ≤ S`: stick, `u_n = g` and `u_t = 0` (the point is held; `λ` is its
//!   reaction);
//! - `z_n > 0` and `|z_t| > S`: slip, `u_n = g` and `λ_t = S z_t / |z_t|` (a given force);
//!
//! with `S` Tresca's bound, `F max(0, z_n)` for Coulomb, 0 without friction: the slip radius is
//! the contact crate's `Law::radius` and the branch its `disc_piece`, as its condensed Newton
//! picks them (no law written twice). A point without a normal multiplier yet (the first step)
//! under Coulomb's law is held: judged by the loads alone, its slip would be the free body's
//! (`paper-3d` n = 32: 8 steps from the loads' verdict, 1 from held points). A held component
//! is an eliminated row (`MatZeroRowsColumns`), a slip force a load: each step is a linear
//! problem of the same kind as a run without contact, solved by the same Krylov method. The
//! multipliers are the reactions, `λ = -Wᵀ⁻¹ (K x - b)` at the points (`W`: the lumped
//! weights). The method stops when the sets repeat and the complementarity residual of the
//! contact crate is within the tolerance; for Tresca and Signorini it is Newton's method and
//! converges in a few steps; for Coulomb the bound follows `z_n` (as in Hüeber, Stadler and
//! Wohlmuth), the slip direction is the last iterate's.
//!
//! On a load path friction remembers: `u_t` above is the increment since the instant before
//! (`ContactRows::with_history`), a sticking point is held where it was, and the solution's
//! `u_t` is the total again (backward Euler of the quasi-static law, as the default backend's
//! path solves it).
//!
//! The normal must be a coordinate axis (the held components are then unknowns of the
//! system; the scene's validation says so).

use crate::layout::Layout;
use crate::system::System;
use contact::{
    classify, complementarity_norms, relative_complementarity, ContactInfo, ContactPoints, ContactSolution, DiscPiece,
    Law, PointValues, Progress, Stage, Status,
};
use petsc::{Index, Matrix, Petsc, PetscError, Vector};

/// The active-set iteration's limits.
#[derive(Clone, Copy, Debug)]
pub struct ActiveSetParams {
    /// The complementarity residual to reach.
    pub tol: f64,
    /// Steps at most.
    pub max_steps: usize,
}

/// The contact points this rank owns (those at its nodes), with their rows: every rank works
/// on its own points only, and what the iteration decides on (the residual, the multiplier
/// scale, whether the sets repeat) is reduced over the ranks.
#[derive(Clone)]
pub struct ContactRows {
    /// This rank's points, as the contact crate's points.
    points: ContactPoints,
    /// The mesh node of each of them.
    nodes: Vec<usize>,
    /// Each one's index among the points it was chosen from.
    mine: Vec<usize>,
    /// The points chosen from, on every rank together (where each rank was handed the whole
    /// boundary: its size; where each was handed its own points: their sum).
    total: usize,
    /// The law at this rank's points.
    law: Law,
    /// This rank.
    rank: usize,
    /// `c` of the natural map, pressure per length: [`C_START`] times the stiffness scale (the
    /// mean diagonal of `A` over the mean weight of all the ranks' points) to begin with,
    /// divided by 10 where the sets cycle.
    c: f64,
    /// Friction's memory on a load path: the tangential displacement of each of this rank's
    /// points at the instant before (zero for a static run). The sets judge, hold and slip
    /// the increment `u_t - shift` (backward Euler of the quasi-static law, as the default
    /// backend's path does).
    shift: PointValues,
    /// The multipliers the iteration starts from at this rank's points (a path's instant
    /// before; `None`: zero, the loads alone judge the first sets).
    start: Option<PointValues>,
}

/// One step's sets: per point, whether it is in contact, and whether held tangentially; and
/// for a slipping point `κ = S / |z_t| < 1`, the weight of the direction's linearisation.
#[derive(Clone, Debug)]
struct Sets {
    active: Vec<bool>,
    stick: Vec<bool>,
    kappa: Vec<f64>,
    /// At a point pressed into a compliant foundation, its pressure's linearisation at the
    /// iterate, `λ_n ≈ a + s u_n`: `(s, a)` (`s = k m p^(m-1)`, `a = k p^m - s u_n`).
    spring: Vec<Option<(f64, f64)>>,
}

impl PartialEq for Sets {
    /// The same sets (κ, a number of the iterate, aside).
    fn eq(&self, other: &Self) -> bool {
        self.active == other.active && self.stick == other.stick
    }
}

/// What the iteration produced: the multipliers and displacements at this rank's points, the
/// final solution vector, counts.
pub struct ContactOutcome<'p> {
    /// The contact solution at this rank's points (multipliers, displacements, statuses; the
    /// counts are the run's).
    pub solution: ContactSolution,
    /// The solution of the last step.
    pub x: Vector<'p>,
    /// Krylov iterations over all steps.
    pub krylov_iterations: usize,
    /// The last solve's reason.
    pub reason: String,
}

impl ContactRows {
    /// The points of `points` (at the mesh `nodes`, under `law`) this rank owns under
    /// `layout`: `points` may be the whole boundary, the same on every rank, or this rank's
    /// piece of it (`whole` says which). Collective.
    pub fn new(
        petsc: &Petsc,
        (points, nodes, law): (&ContactPoints, &[usize], &Law),
        whole: bool,
        layout: &Layout,
        system: &System<'_>,
    ) -> Result<Self, PetscError> {
        let mine: Vec<usize> = (0..points.len())
            .filter(|&i| layout.node_rank[nodes[i]] == petsc.rank())
            .collect();
        let own = points.select(&mine);
        let sums = petsc.sum(&[own.weight.iter().sum::<f64>(), own.len() as f64, points.len() as f64])?;
        let mean_w = sums[0] / sums[1].max(1.0);
        Ok(ContactRows {
            shift: PointValues::zeros(own.len(), own.n_tangential()),
            start: None,
            nodes: mine.iter().map(|&i| nodes[i]).collect(),
            points: own,
            law: law.select(&mine),
            mine,
            total: if whole { points.len() } else { sums[2] as usize },
            rank: petsc.rank(),
            c: C_START * system.diagonal[0] / mean_w,
        })
    }

    /// The rows of an instant of a load path: `shift` the tangential displacement of this
    /// rank's points (in their order) at the instant before, friction's frame; `start` the
    /// multipliers to begin with (the iteration's first sets, and its residual's scale).
    ///
    /// # Panics
    /// Where `shift` or `start` is not at this rank's points (a caller's bug).
    #[must_use]
    pub fn with_history(mut self, shift: PointValues, start: Option<PointValues>) -> Self {
        let (n, nt) = (self.points.len(), self.points.n_tangential());
        assert!(
            shift.normal.len() == n && shift.tangential.len() == n * nt,
            "the history is at this rank's points"
        );
        assert!(start
            .as_ref()
            .is_none_or(|s| s.normal.len() == n && s.tangential.len() == n * nt));
        self.shift = shift;
        self.start = start;
        self
    }

    /// A solution at this rank's points spread into the whole boundary's, on every rank (the
    /// points were chosen from the whole boundary): multipliers and displacements summed over
    /// the ranks (each point is one rank's), the statuses classified again under `law`.
    /// Collective.
    pub fn whole(
        &self,
        petsc: &Petsc,
        own: &ContactSolution,
        law: &Law,
        all: &ContactPoints,
    ) -> Result<ContactSolution, PetscError> {
        let (n, nt) = (self.total, self.points.n_tangential());
        let spread = |v: &PointValues| -> Result<PointValues, PetscError> {
            let mut flat = vec![0.0; n * (1 + nt)];
            for (k, &i) in self.mine.iter().enumerate() {
                flat[i] = v.normal[k];
                flat[n + i * nt..n + (i + 1) * nt].copy_from_slice(&v.tangential[k * nt..(k + 1) * nt]);
            }
            let sum = petsc.sum(&flat)?;
            Ok(PointValues::from_parts(sum[..n].to_vec(), sum[n..].to_vec(), nt).expect("lengths agree"))
        };
        let (lambda, u) = (spread(&own.lambda)?, spread(&own.u)?);
        let status = classify(&lambda, &bound(all, law, &lambda.normal));
        Ok(ContactSolution {
            lambda,
            u,
            status,
            info: own.info.clone(),
            electric: None,
        })
    }
}

/// The first of `points` (at the mesh `nodes`, under `law`) whose node is another point's and
/// whose conditions act on a component of the node's displacement that the other's act on
/// too: a normal along the other's normal, or a tangent that friction loads along the other's
/// normal or loaded tangent. The active sets hold or load each component of a node once (a
/// held component is an eliminated row), where the condensed route couples the two points'
/// multipliers; frictionless zones meeting at a corner act on different components and are
/// held. `None` where no two points share a component.
pub fn shared_components(points: &ContactPoints, nodes: &[usize], law: &Law) -> Option<usize> {
    let (dim, nt) = (points.dim, points.n_tangential());
    // friction acts where the law's radius at a unit normal value is positive
    let rubs = |i: usize| law.radius(points, i, 1.0) > 0.0;
    let mut taken: std::collections::HashMap<(usize, usize), usize> = Default::default();
    for i in 0..points.len() {
        let normal = std::iter::once(axis(&points.normal[i], dim));
        let tangents = (0..nt)
            .filter(|&q| rubs(i) && !points.is_held(i, q))
            .map(|q| axis(&points.tangent[i][q], dim));
        for component in normal.chain(tangents) {
            if taken.insert((nodes[i], component), i).is_some_and(|j| j != i) {
                return Some(i);
            }
        }
    }
    None
}

/// `a · b` over the first `dim` components.
fn dot(a: &[f64; 3], b: &[f64; 3], dim: usize) -> f64 {
    (0..dim).map(|k| a[k] * b[k]).sum()
}

/// The linear solve of one step: matrix, right-hand side, the initial guess, overwritten by
/// the solution, and the relative tolerance the step may be solved to where it is looser than
/// the solver's own (an inexact Newton step; `None`: the solver's); returns Krylov iterations,
/// PETSc's reason, and whether the step was solved looser than the solver's tolerance.
pub type LinearSolve<'s, 'p> = dyn FnMut(&mut Matrix<'p>, &Vector<'p>, &mut Vector<'p>, Option<f64>) -> Result<(usize, String, bool), PetscError>
    + 's;

/// An inexact step's relative tolerance per unit of the last complementarity residual (the
/// forcing term of an inexact Newton method, `η_k = FORCING r_(k-1)`: the step's error of the
/// order of the residual squared keeps the convergence superlinear; Eisenstat and Walker,
/// SIAM J. Sci. Comput. 17 (1996) 16-32).
const FORCING: f64 = 1e-2;
/// The loosest relative tolerance of a step.
const LOOSEST: f64 = 1e-4;

/// The iterate: multipliers, point displacements, the solution vector, and the counts.
struct Iterate<'p> {
    lambda: PointValues,
    u: PointValues,
    x: Vector<'p>,
    steps: usize,
    reductions: usize,
    krylov: usize,
    reason: String,
    /// The multiplier scale of the residual, `c |(u_n(0) - g, u_t(0))|_W`.
    reference: f64,
    /// The complementarity residual of the last iterate (the next step's forcing).
    last_residual: f64,
}

/// How one run of active-set steps on a law ended.
enum Ended {
    /// The law's residual is within the tolerance, the sets repeated.
    Converged,
    /// The sets came back to an earlier state (a cycle), or the residual stopped falling; the
    /// residual then.
    Cycled(f64),
}

/// Solves the contact problem by active sets. `solve` solves one linear system. The first
/// iterate is `warm` where given (a path's instant before: its solution vector, with the
/// multipliers of [`ContactRows::with_history`]), else the solution of the loads alone. Where
/// the sets cycle or the residual stops falling, `c` is divided by 10 and the steps go on from
/// the iterate (at most [`MAX_REDUCTIONS`] times).
///
/// Where Coulomb's law from nothing does not converge, it starts again from friction's
/// predictor: Signorini's problem alone first, then Coulomb's from its solution and normal
/// multipliers, the tangential ones zero (the first step of the paper's fixed point,
/// `S = F λ_n` of the frictionless solution; a path's later instants start the same way from
/// the instant before). From the loads alone, a contact that friction barely holds (a body
/// that a potential alone pulls onto the foundation: normal forces 1e-4 of the loaded ones,
/// every point slipping) cycled through every reduction of `c`; from the predictor it
/// converges as the loaded instants do. (The predictor is not the first try: Cattaneo and
/// Mindlin's partial slip, `cattaneo-mindlin` at n = 48, converges from the loads alone and
/// cycles from the predictor.) The steps of every try are counted. Collective.
#[allow(clippy::too_many_arguments)]
pub fn active_set<'p>(
    petsc: &'p Petsc,
    layout: &Layout,
    system: &System<'p>,
    (rows, warm): (&ContactRows, Option<Vector<'p>>),
    params: ActiveSetParams,
    solve: &mut LinearSolve<'_, 'p>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactOutcome<'p>, ActiveSetError> {
    let cold = warm.is_none() && rows.start.is_none() && matches!(rows.law, Law::Coulomb);
    let tried = match sets_from(petsc, layout, system, (rows, warm), params, solve, progress) {
        Err(ActiveSetError::NoConvergence { steps, .. }) if cold => steps,
        other => return other,
    };
    let mut frictionless = rows.clone();
    frictionless.law = Law::Frictionless;
    let first = sets_from(petsc, layout, system, (&frictionless, None), params, solve, progress)?;
    let touching = petsc.max(&[first.solution.lambda.normal.iter().fold(0.0f64, |m, l| m.max(*l))])?[0];
    if touching <= 0.0 {
        // nothing presses: friction has nothing to hold
        return Ok(first);
    }
    let mut start = PointValues::zeros(rows.points.len(), rows.points.n_tangential());
    start.normal.clone_from(&first.solution.lambda.normal);
    let coulomb = rows.clone().with_history(rows.shift.clone(), Some(start));
    let steps = tried + first.solution.info.newton_iters;
    let mut out = sets_from(
        petsc,
        layout,
        system,
        (&coulomb, Some(first.x)),
        params,
        solve,
        progress,
    )
    .map_err(|e| match e {
        ActiveSetError::NoConvergence { steps: s, residual } => ActiveSetError::NoConvergence {
            steps: s + steps,
            residual,
        },
        other => other,
    })?;
    out.solution.info.newton_iters += steps;
    out.solution.info.operator_calls += first.solution.info.operator_calls;
    out.krylov_iterations += first.krylov_iterations;
    Ok(out)
}

/// [`active_set`] on the rows' own law, from `warm` or from the loads alone.
fn sets_from<'p>(
    petsc: &'p Petsc,
    layout: &Layout,
    system: &System<'p>,
    (rows, warm): (&ContactRows, Option<Vector<'p>>),
    params: ActiveSetParams,
    solve: &mut LinearSolve<'_, 'p>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ContactOutcome<'p>, ActiveSetError> {
    let (p, law) = (&rows.points, &rows.law);
    let (n, nt) = (p.len(), p.n_tangential());
    let (x, krylov, reason, reference) = match warm {
        // a path's instant from the one before: its solution, its sets, and its multipliers'
        // norm the residual's scale (an instant unloaded to nothing has round-off multipliers,
        // which cannot scale their own residual)
        Some(x) => {
            let before = rows.start.as_ref().map_or(0.0, |l| l.weighted_norm(&p.weight));
            (x, 0, String::new(), over_ranks(petsc, before)?)
        }
        None => {
            // the loads alone: the first iterate, and the residual's multiplier scale
            let mut x = system.rhs.duplicate()?;
            let mut k0 = system.matrix.duplicate()?;
            let (krylov, reason, _) = solve(&mut k0, &system.rhs, &mut x, None)?;
            drop(k0);
            let mut gap_u = displacements(petsc, layout, rows, &x)?;
            for i in 0..n {
                gap_u.normal[i] -= p.gap[i];
            }
            let rigid = rows.c * over_ranks(petsc, gap_u.weighted_norm(&p.weight))?;
            // on a compliant foundation the bed's pressures at the free penetrations, where
            // smaller (the contact crate's multiplier scale: a soft bed's pressures are many
            // decades below the rigid scale, whose round-off would pass for its answer)
            let compliant = petsc.max(&[f64::from(u8::from(!p.all_rigid()))])?[0] > 0.0;
            let reference = if compliant {
                let mut bed = PointValues::zeros(n, 0);
                for (i, b) in bed.normal.iter_mut().enumerate() {
                    *b = p.foundation_of(i).pressure(gap_u.normal[i]).map_or(0.0, |(q, _)| q);
                }
                rigid.min(over_ranks(petsc, bed.weighted_norm(&p.weight))?)
            } else {
                rigid
            };
            (x, krylov, reason, reference)
        }
    };
    let u = displacements(petsc, layout, rows, &x)?;
    let lambda = rows.start.clone().unwrap_or_else(|| PointValues::zeros(n, nt));
    let last_residual = residual(petsc, rows, law, (&lambda, &u), reference)?;
    let mut it = Iterate {
        lambda,
        u,
        x,
        steps: 0,
        reductions: 0,
        krylov,
        reason,
        reference,
        last_residual,
    };
    let mut rows = rows.clone();
    loop {
        let ctx = Context {
            petsc,
            layout,
            system,
            rows: &rows,
        };
        let residual = match ctx.steps(&mut it, law, params, solve, progress)? {
            Ended::Converged => return Ok(ctx.outcome(it, law)?),
            Ended::Cycled(r) => r,
        };
        if it.reductions == MAX_REDUCTIONS || it.steps >= params.max_steps {
            return Err(ActiveSetError::NoConvergence {
                steps: it.steps,
                residual,
            });
        }
        // a smaller c weighs the multipliers more than the displacements in the sets' tests
        // (the solution does not depend on c; the default backend's Newton takes c = 1/μ_max,
        // the inverse of the largest compliance)
        rows.c /= 10.0;
        it.reductions += 1;
        it.reference /= 10.0;
    }
}

/// `c`'s first value, in units of the stiffness scale (mean diagonal of `A` over the mean
/// weight): the diagonal is the stiffness of the stiffest local mode, `1/μ_max` that of the
/// softest. Measured (2 ranks, steps to round-off): `paper` n = 32 / 128: 6 / 11 steps at 1,
/// 4 / 4 at 0.1, 4 / 4 at 0.01; `paper-slip`: 4 / 15, 5 / 8, 5 / 8; `paper-3d` n = 8 / 16:
/// 3 / 4 at 0.1 and 0.01.
pub const C_START: f64 = 0.1;

/// Divisions of `c` by 10 at most.
pub const MAX_REDUCTIONS: usize = 6;

/// Steps without a new best residual before the direct iteration counts as stalled.
const PATIENCE: usize = 8;

/// What every step needs.
struct Context<'a, 'p> {
    petsc: &'p Petsc,
    layout: &'a Layout,
    system: &'a System<'p>,
    rows: &'a ContactRows,
}

impl<'p> Context<'_, 'p> {
    /// Active-set steps on `law` from `it` until its residual is within the tolerance and the
    /// sets repeat, or the sets cycle or stall (reported against `report`'s residual).
    fn steps(
        &self,
        it: &mut Iterate<'p>,
        law: &Law,
        params: ActiveSetParams,
        solve: &mut LinearSolve<'_, 'p>,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<Ended, ActiveSetError> {
        let p = &self.rows.points;
        let mut seen: Vec<Sets> = vec![];
        let (mut best, mut since_best) = (f64::INFINITY, 0);
        while it.steps < params.max_steps {
            it.steps += 1;
            let (sets, direction) = sets(self.rows, law, (&it.lambda, &it.u), it.reference);
            // a step from an iterate within the tolerance is solved to the solver's own: the
            // iteration ends only on such a step, whose solution meets the equilibrium too
            // (the complementarity of an inexact step's iterate says nothing of it)
            let loose = (it.last_residual > params.tol).then(|| (FORCING * it.last_residual).min(LOOSEST));
            let loosened = self.step(it, law, (&sets, &direction), solve, loose)?;
            let residual = self.residual(it, law)?;
            it.last_residual = residual;
            let counts = counts(&classify(&it.lambda, &bound(p, law, &it.lambda.normal)));
            let all = self.petsc.sum(&[counts.0 as f64, counts.1 as f64, counts.2 as f64])?;
            progress(&Progress {
                stage: Stage::Newton,
                iter: it.steps,
                residual,
                counts: (all[0] as usize, all[1] as usize, all[2] as usize),
            });
            // the sets of every rank against its own earlier ones: the same on all ranks or not
            let same = self.everywhere(seen.iter().map(|s| *s == sets))?;
            let repeated = same.last() == Some(&true);
            if !loosened && residual <= params.tol && (repeated || residual <= 0.01 * params.tol) {
                return Ok(Ended::Converged);
            }
            if residual < best {
                (best, since_best) = (residual, 0);
            } else {
                since_best += 1;
            }
            let cycled = !repeated && same.iter().rev().skip(1).any(|&s| s);
            if cycled || since_best >= PATIENCE {
                return Ok(Ended::Cycled(residual));
            }
            seen.push(sets);
        }
        Ok(Ended::Cycled(self.residual(it, law)?))
    }

    /// Whether each of `flags` holds on every rank. Collective.
    fn everywhere(&self, flags: impl Iterator<Item = bool>) -> Result<Vec<bool>, PetscError> {
        let misses: Vec<f64> = flags.map(|f| f64::from(u8::from(!f))).collect();
        Ok(self.petsc.sum(&misses)?.into_iter().map(|m| m == 0.0).collect())
    }

    /// One step: hold the active and sticking components, load the slipping ones, solve (to
    /// the relative tolerance `loose` where it is looser than the solver's); whether the solve
    /// was loosened.
    fn step(
        &self,
        it: &mut Iterate<'p>,
        law: &Law,
        (sets, direction): (&Sets, &PointValues),
        solve: &mut LinearSolve<'_, 'p>,
        loose: Option<f64>,
    ) -> Result<bool, PetscError> {
        let (petsc, layout, system) = (self.petsc, self.layout, self.system);
        let mut matrix = system.matrix.duplicate()?;
        let mut b = system.rhs.copy()?;
        let held = hold(self.rows, layout, law, sets, direction, &mut matrix, &mut b)?;
        let mut values = Vector::mpi(petsc, layout.owned(petsc.rank()).len())?;
        set_held_values(layout, petsc.rank(), &held, &mut values)?;
        let rows_only: Vec<Index> = held.iter().map(|&(r, _)| r).collect();
        matrix.zero_rows_columns(&rows_only, system.diagonal[0], &values, &mut b)?;
        let (its, reason, loosened) = solve(&mut matrix, &b, &mut it.x, loose)?;
        it.krylov += its;
        it.reason = reason;
        it.u = displacements(petsc, layout, self.rows, &it.x)?;
        it.lambda = multipliers(petsc, layout, system, self.rows, sets, &it.x)?;
        Ok(loosened)
    }

    /// The natural-map residual of `law` at the iterate, over the ranks. Collective.
    fn residual(&self, it: &Iterate<'_>, law: &Law) -> Result<f64, PetscError> {
        residual(self.petsc, self.rows, law, (&it.lambda, &it.u), it.reference)
    }

    /// The converged iterate as the contact crate's solution at this rank's points.
    /// Collective.
    fn outcome(&self, it: Iterate<'p>, law: &Law) -> Result<ContactOutcome<'p>, PetscError> {
        let residual = self.residual(&it, law)?;
        let status = classify(&it.lambda, &bound(&self.rows.points, law, &it.lambda.normal));
        // the iterate's tangential displacements are the increments since the instant before
        let mut u = it.u;
        for (v, s) in u.tangential.iter_mut().zip(&self.rows.shift.tangential) {
            *v += s;
        }
        let info = ContactInfo {
            newton_iters: it.steps,
            operator_calls: it.steps + 1,
            complementarity: residual,
            residual,
            augmentation: Some(self.rows.c),
            ..ContactInfo::new(1.0 / self.rows.c)
        };
        Ok(ContactOutcome {
            solution: ContactSolution {
                lambda: it.lambda,
                u,
                status,
                info,
                electric: None,
            },
            x: it.x,
            krylov_iterations: it.krylov,
            reason: it.reason,
        })
    }
}

/// Why the active-set iteration stopped without an answer.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ActiveSetError {
    /// PETSc or MPI failed.
    #[error(transparent)]
    Petsc(#[from] PetscError),
    /// The sets did not settle within the step limit.
    #[error("the active-set iteration did not converge in {steps} steps (complementarity residual {residual:.3e}); for Coulomb friction the sets may cycle: try the default backend, whose Newton has a proximal stage and a Gauss-Seidel fallback")]
    NoConvergence {
        /// Steps taken.
        steps: usize,
        /// The last residual.
        residual: f64,
    },
}

/// `(stick, slip, separated)` counts.
fn counts(status: &[Status]) -> (usize, usize, usize) {
    let c = |s| status.iter().filter(|&&x| x == s).count();
    (c(Status::Stick), c(Status::Slip), c(Status::Separated))
}

/// The slip bound of each point for the multipliers' normal part.
fn bound(p: &ContactPoints, law: &Law, lambda_n: &[f64]) -> Vec<f64> {
    contact::slip_bound(p, law, lambda_n)
}

/// The step's sets, and the slip direction `d = z_t / |z_t|` of each slipping point (zero
/// elsewhere); a point on a compliant foundation presses where it penetrates, its pressure
/// above [`BED_FLOOR`] of `reference` (the multiplier scale).
fn sets(
    rows: &ContactRows,
    law: &Law,
    (lambda, u): (&PointValues, &PointValues),
    reference: f64,
) -> (Sets, PointValues) {
    let p = &rows.points;
    let (n, nt) = (p.len(), p.n_tangential());
    let c = rows.c;
    let mut active = vec![false; n];
    let mut stick = vec![false; n];
    let mut direction = PointValues::zeros(n, nt);
    let mut kappa = vec![0.0; n];
    let mut spring = vec![None; n];
    for i in 0..n {
        let penetration = u.normal[i] - p.gap[i];
        let zn = lambda.normal[i] + c * penetration;
        let foundation = p.foundation_of(i);
        let pressed = match foundation.pressure(penetration) {
            // a compliant foundation presses where the point penetrates it: Newton's
            // linearisation of `λ_n = k [p]₊^m` there
            Some((pressure, slope)) if penetration > 0.0 && pressure > BED_FLOOR * reference => {
                spring[i] = Some((slope, pressure - slope * u.normal[i]));
                true
            }
            Some(_) => false,
            None => zn > 0.0,
        };
        // a given slip bound (Tresca's) holds whether or not the point presses: its
        // tangential law is judged at a separated point too, as the contact crate poses it
        if !pressed && given_bound(p, law, i).is_none() {
            continue;
        }
        active[i] = pressed;
        // the slip radius as the contact crate writes it (Tresca's bound, Coulomb's F z_n; on
        // a compliant foundation F λ_n)
        let s = law.radius(p, i, foundation.radius_normal(zn, lambda.normal[i]));
        if nt == 0 {
            continue;
        }
        // Coulomb's bound at a point without a normal multiplier yet (the first step) would
        // judge its slip by the loads alone: the point is held, and its reaction judges it.
        // Not on a path's later instant, which starts from the instant before: a point without
        // one there came into contact during the instant, and held where it was then it jumps
        // back; the sets alternated so where points slipped back
        if matches!(law, Law::Coulomb)
            && given_bound(p, law, i).is_none()
            && rows.start.is_none()
            && lambda.normal[i] == 0.0
            && p.friction[i] > 0.0
        {
            stick[i] = true;
            continue;
        }
        let mut zt: Vec<f64> = (0..nt)
            .map(|q| lambda.tangential[i * nt + q] + c * u.tangential[i * nt + q])
            .collect();
        // the projection sees the free directions only (a support holds the others)
        p.hold(i, &mut zt);
        // the branch of the disc's projection, as the contact crate's Newton picks it
        match contact::disc_piece(&zt, s) {
            DiscPiece::Zero => {}
            DiscPiece::Inside => stick[i] = true,
            DiscPiece::Boundary { ratio, direction: d } => {
                direction.tangential[i * nt..(i + 1) * nt].copy_from_slice(&d[..nt]);
                kappa[i] = ratio;
            }
        }
    }
    (
        Sets {
            active,
            stick,
            kappa,
            spring,
        },
        direction,
    )
}

/// Point `i`'s slip bound where it is given (Tresca's law, or a Tresca zone beside Coulomb
/// ones) rather than its normal force's.
fn given_bound(p: &ContactPoints, law: &Law, i: usize) -> Option<f64> {
    match law {
        Law::Tresca(s) => Some(s[i]),
        Law::Coulomb => p.tresca_of(i),
        Law::Frictionless => None,
    }
}

/// A compliant foundation's pressure below this share of the multiplier scale is the
/// round-off of a bed that nothing presses (an instant of a path unloaded to nothing: its
/// Krylov solves leave penetrations of 1e-47, whose points would report contact), and the
/// point is separated.
const BED_FLOOR: f64 = 1e-14;

/// Applies the step's conditions to this rank's points: returns the held components as
/// `(row, value)` (`u_n = g` where active, `u_t = s` where sticking, `s` the shift: the
/// tangential displacement at a path's instant before, zero in a static run), and writes the
/// slipping points' tangential rows as Newton's linearisation of `λ_t = S z_t / |z_t|` at the
/// iterate (`z_t = λ_t + c (u_t - s)`),
///
/// ```text
/// λ_t = S d + β P (u_t - s),   P = I - d dᵀ,   β = c κ / (1 - κ),   κ = S / |z_t|
/// ```
///
/// (a spring across the slip direction, zero in 2D): Tresca's `S d` as a load (`-w λ_t t`);
/// Coulomb's `S = F λ_n` with the step's own normal reaction, as the equation
/// `r_t = F d (n·e)(t·e) r_n` between the reactions `r = K x - b` (the row of `u_t` minus a
/// multiple of the row of `u_n`). Collective (the matrix and `b` are assembled).
#[allow(clippy::too_many_arguments)]
fn hold(
    rows: &ContactRows,
    layout: &Layout,
    law: &Law,
    sets: &Sets,
    direction: &PointValues,
    matrix: &mut Matrix<'_>,
    b: &mut Vector<'_>,
) -> Result<Vec<(Index, f64)>, PetscError> {
    let p = &rows.points;
    let (dim, nt) = (p.dim, p.n_tangential());
    let b_local = b.local()?;
    let start = layout.rank_start[rows.rank];
    let mut edits = Edits::default();
    for i in 0..p.len() {
        // (a separated point with a given slip bound keeps its tangential law)
        if !sets.active[i] && given_bound(p, law, i).is_none() {
            continue;
        }
        let first = layout.first[rows.nodes[i]];
        // the normal is an axis: its component holds u_n = g on a rigid foundation; on a
        // compliant one the bed's linearised pressure acts on it, `-w (a + s u_n) n`
        let kn = axis(&p.normal[i], dim);
        let rn = (first + kn) as Index;
        match sets.spring[i] {
            _ if !sets.active[i] => {}
            None => edits.held.push((rn, p.gap[i] * p.normal[i][kn])),
            Some((slope, at_zero)) => {
                let (cols, mut vals) = matrix.row(rn)?;
                if let Ok(at) = cols.binary_search(&rn) {
                    vals[at] += p.weight[i] * slope;
                }
                edits.rows.push((rn, cols, vals));
                edits.load(rn, -p.weight[i] * at_zero * p.normal[i][kn]);
            }
        }
        let kt: Vec<usize> = (0..nt).map(|q| axis(&p.tangent[i][q], dim)).collect();
        // a tangent a support holds (a roller through the contact face) is its prescribed
        // unknown already: the contact conditions are the free tangents'
        let free: Vec<usize> = (0..nt).filter(|&q| !p.is_held(i, q)).collect();
        // (on a path, a sticking point is held where it was at the instant before)
        let shift = rows.shift.tangential_of(i);
        if sets.stick[i] {
            edits.held.extend(
                free.iter()
                    .map(|&q| ((first + kt[q]) as Index, shift[q] * p.tangent[i][q][kt[q]])),
            );
            continue;
        }
        let d = &direction.tangential[i * nt..(i + 1) * nt];
        if d.iter().all(|&x| x == 0.0) {
            continue; // frictionless: the tangential rows stay free
        }
        let at = Sliding {
            i,
            first,
            kn,
            kt: &kt,
            free: &free,
            d,
            beta: rows.c * sets.kappa[i] / (1.0 - sets.kappa[i]),
            b_n: b_local[first + kn - start],
        };
        edits.slide(rows, law, &at, matrix)?;
    }
    for (rt, cols, vals) in &edits.rows {
        matrix.set_values(&[*rt], cols, vals)?;
    }
    matrix.assemble()?;
    b.add_values(&edits.loads.0, &edits.loads.1)?;
    b.assemble()?;
    Ok(edits.held)
}

/// A step's changes to the system at this rank's points: the held components `(row,
/// value)`, the loads added, and the rows rewritten (row, columns, values).
#[derive(Default)]
struct Edits {
    held: Vec<(Index, f64)>,
    loads: (Vec<Index>, Vec<f64>),
    rows: Vec<(Index, Vec<Index>, Vec<f64>)>,
}

/// A sliding point's data for [`Edits::slide`]: its index, its node's first unknown, the
/// axes of its normal and tangents, its free tangents, the slip direction `d`, the spring's
/// `β`, and the load at its normal row (Coulomb's equation reads it).
struct Sliding<'a> {
    i: usize,
    first: usize,
    kn: usize,
    kt: &'a [usize],
    free: &'a [usize],
    d: &'a [f64],
    beta: f64,
    b_n: f64,
}

impl Edits {
    fn load(&mut self, row: Index, value: f64) {
        self.loads.0.push(row);
        self.loads.1.push(value);
    }

    /// A sliding point's tangential rows (see [`hold`]): a given slip force (Tresca's law, or
    /// a Tresca zone's point beside Coulomb zones) as a load, or Coulomb's law coupling the
    /// tangential reactions to the normal one; the spring `w β P` across the direction.
    fn slide(
        &mut self,
        rows: &ContactRows,
        law: &Law,
        at: &Sliding<'_>,
        matrix: &Matrix<'_>,
    ) -> Result<(), PetscError> {
        let (p, i, d) = (&rows.points, at.i, at.d);
        let (w, shift) = (p.weight[i], rows.shift.tangential_of(i));
        let tresca = given_bound(p, law, i);
        let normal_row = match (law, tresca) {
            (Law::Coulomb, None) => Some(matrix.row((at.first + at.kn) as Index)?),
            _ => None,
        };
        for &q in at.free {
            let rt = (at.first + at.kt[q]) as Index;
            let (cols, mut vals) = matrix.row(rt)?;
            let sign_t = p.tangent[i][q][at.kt[q]];
            // the spring acts on the increment: `w β P (u_t - shift)`, its shift a load
            let spring: f64 = at
                .free
                .iter()
                .map(|&q2| (f64::from(u8::from(q == q2)) - d[q] * d[q2]) * shift[q2])
                .sum::<f64>()
                * w
                * at.beta
                * sign_t;
            match (tresca, &normal_row) {
                (Some(s), _) => self.load(rt, -w * s * d[q] * sign_t + spring),
                (None, Some((cols_n, vn))) => {
                    debug_assert_eq!(&cols, cols_n, "a node's rows share their columns");
                    let alpha = p.friction[i] * d[q] * p.normal[i][at.kn] * sign_t;
                    for (v, n) in vals.iter_mut().zip(vn) {
                        *v -= alpha * n;
                    }
                    self.load(rt, -alpha * at.b_n + spring);
                }
                _ => {}
            }
            // the spring w β P across the slip direction
            for &q2 in at.free {
                let pq = f64::from(u8::from(q == q2)) - d[q] * d[q2];
                let col = (at.first + at.kt[q2]) as Index;
                if let Ok(k) = cols.binary_search(&col) {
                    vals[k] += w * at.beta * sign_t * pq * p.tangent[i][q2][at.kt[q2]];
                }
            }
            self.rows.push((rt, cols, vals));
        }
        Ok(())
    }
}

/// The component along which a unit axis vector points.
fn axis(v: &[f64; 3], dim: usize) -> usize {
    (0..dim).max_by(|&a, &b| v[a].abs().total_cmp(&v[b].abs())).unwrap_or(0)
}

/// Writes the held values into this rank's entries of `values`.
fn set_held_values(
    layout: &Layout,
    rank: usize,
    held: &[(Index, f64)],
    values: &mut Vector<'_>,
) -> Result<(), PetscError> {
    let start = layout.owned(rank).start;
    values.with_local_mut(|v| {
        for &(r, x) in held {
            v[r as usize - start] = x;
        }
    })
}

/// `u_n` and `u_t - shift` at this rank's points (the tangential increment since a path's
/// instant before; a static run's shift is zero).
fn displacements(
    petsc: &Petsc,
    layout: &Layout,
    rows: &ContactRows,
    x: &Vector<'_>,
) -> Result<PointValues, PetscError> {
    let p = &rows.points;
    let (n, dim, nt) = (p.len(), p.dim, p.n_tangential());
    let local = x.local()?;
    let start = layout.owned(petsc.rank()).start;
    let mut u = PointValues::zeros(n, nt);
    for i in 0..n {
        let first = layout.first[rows.nodes[i]] - start;
        let ui: [f64; 3] = std::array::from_fn(|k| if k < dim { local[first + k] } else { 0.0 });
        u.normal[i] = dot(&ui, &p.normal[i], dim);
        for q in 0..nt {
            u.tangential[i * nt + q] = dot(&ui, &p.tangent[i][q], dim) - rows.shift.tangential[i * nt + q];
        }
    }
    Ok(u)
}

/// The multipliers of the step at this rank's points: the reactions `r = K x - b` of the
/// loads without contact, at the active points (`λ_n = -(r·n)/w`, `λ_t = -(r·t)/w`: held
/// components, Tresca's load and Coulomb's equation alike; `λ_t = 0` without friction), zero
/// where separated but for a given slip bound's `λ_t` (Tresca's law holds there). Collective
/// (the product).
fn multipliers(
    petsc: &Petsc,
    layout: &Layout,
    system: &System<'_>,
    rows: &ContactRows,
    sets: &Sets,
    x: &Vector<'_>,
) -> Result<PointValues, PetscError> {
    let p = &rows.points;
    let (n, dim, nt) = (p.len(), p.dim, p.n_tangential());
    let local = system.reactions(x)?.local()?;
    let start = layout.owned(petsc.rank()).start;
    let mut lambda = PointValues::zeros(n, nt);
    for i in (0..n).filter(|&i| sets.active[i] || given_bound(p, &rows.law, i).is_some()) {
        let first = layout.first[rows.nodes[i]] - start;
        let f: [f64; 3] = std::array::from_fn(|k| if k < dim { local[first + k] } else { 0.0 });
        let w = p.weight[i];
        // (a separated point's normal row is free: no normal multiplier)
        if sets.active[i] {
            lambda.normal[i] = -dot(&f, &p.normal[i], dim) / w;
        }
        // (a held tangent's reaction is its support's, not the contact's; without friction a
        // tangent is free, and its reaction the solve's round-off, not a multiplier)
        let frictional = !matches!(rows.law, Law::Frictionless);
        for q in (0..nt).filter(|&q| frictional && !p.is_held(i, q)) {
            lambda.tangential[i * nt + q] = -dot(&f, &p.tangent[i][q], dim) / w;
        }
    }
    Ok(lambda)
}

/// The Euclidean combination `sqrt(Σ x_r²)` of the ranks' `x` (each a norm over its own
/// points), scaled by the largest so that no square overflows. Collective.
fn over_ranks(petsc: &Petsc, x: f64) -> Result<f64, PetscError> {
    let m = petsc.max(&[x])?[0];
    if !(m > 0.0) || !m.is_finite() {
        return Ok(m);
    }
    Ok(m * petsc.sum(&[(x / m) * (x / m)])?[0].sqrt())
}

/// The natural-map residual of `law` at `(λ, u)` over every rank's points, as the contact
/// crate's `complementarity_residual` is over one set ([`relative_complementarity`] of the
/// norms combined over the ranks). Collective.
fn residual(
    petsc: &Petsc,
    rows: &ContactRows,
    law: &Law,
    (lambda, u): (&PointValues, &PointValues),
    reference: f64,
) -> Result<f64, PetscError> {
    let p = &rows.points;
    let radius = bound(p, law, &lambda.normal);
    let (num, lam) = complementarity_norms(p, &radius, lambda, u, rows.c);
    Ok(relative_complementarity(
        over_ranks(petsc, num)?,
        over_ranks(petsc, lam)?,
        reference,
    ))
}
