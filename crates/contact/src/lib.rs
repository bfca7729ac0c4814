//! Contact with a rigid foundation, seen from the multipliers: contact points, the projections
//! onto the multiplier sets, Uzawa's algorithm, the fixed point on the friction threshold,
//! residuals and stick/slip status. It knows no finite elements: it sees the problem only
//! through [`ContactOperator`] ("given multipliers, return the displacement of the contact
//! points"), so the same solvers run on the full system and on small dense problems. Problems
//! given by their compliance ([`AffineProblem`], dense or sparse) have two more solvers: the
//! semismooth Newton method with its proximal and Gauss–Seidel stages ([`solve_newton`]) and
//! block Gauss–Seidel ([`solve_gauss_seidel`]). [`siconos`] reads the frictional contact
//! problems of the Siconos project, on which the solvers are judged against Siconos' own.
//!
//! # Glossary (signs fixed by docs/theory.md)
//! - `n`: outward normal of the body; `u_n = u·n`, `u_t = (u·t_k)_k`; gap `g`: `u_n ≤ g`.
//! - `λ_n = -σ_n ≥ 0`: the contact pressure; `λ_t = -(σn)·t`, so at a sliding point `λ_t`
//!   points along `u_t`. Equilibrium: `A u + Gᵀ φ = f - Nᵀ W λ_n - Tᵀ W λ_t`, `W` the weights.
//! - Uzawa: `λ_n ← max(0, λ_n + r (u_n - g))`, `λ_t ← P_S(λ_t + r u_t)`, `P_S` the projection
//!   onto the disc `|λ_t| ≤ S`; Coulomb: `S = F λ_n` by a fixed point.
//! - `μ_max`: the largest eigenvalue of the dual operator (weighted contact compliance); the
//!   step is `r = 1.8 / μ_max` by default (convergence needs `r < 2 / μ_max`).
//! - Complementarity residual: the natural map with `c = 1 / μ_max`, weighted, relative to
//!   `‖λ‖_W` (see [`complementarity_residual`]); Siconos' error is the other [`Measure`].
//!
//! # Example
//! ```
//! use contact::{solve_uzawa, ContactPoints, DenseContactProblem, Law, PointValues, Status, UzawaParams};
//! // one point pressed 1 unit into the foundation through a spring of compliance 1:
//! // u_n = 1 - λ_n (w = 1), contact at g = 0 needs λ_n = 1.
//! let points = ContactPoints {
//!     dim: 2, position: vec![[0.0; 3]], normal: vec![[0.0, -1.0, 0.0]],
//!     tangent: vec![[[1.0, 0.0, 0.0], [0.0; 3]]], weight: vec![1.0], gap: vec![0.0], friction: vec![0.0],
//!     held: vec![[false; 2]],
//!     foundation: Default::default(), foundations: vec![], slipped: vec![], weakening: vec![], tresca: vec![],
//! };
//! let mut op = DenseContactProblem {
//!     u0: PointValues::from_parts(vec![1.0], vec![], 0).unwrap(),
//!     compliance: vec![1.0], weight: vec![1.0], nt: 0,
//! };
//! let sol = solve_uzawa(&mut op, &points, &Law::Frictionless, &UzawaParams::default(), None, &mut |_| {}).unwrap();
//! assert!((sol.lambda.normal[0] - 1.0).abs() < 1e-10);
//! assert_eq!(sol.status[0], Status::Slip); // frictionless contact: slip
//! ```

mod coarse;
mod electric;
mod floating;
mod force_control;
mod gauss_seidel;
mod local;
mod newton;
mod operator;
pub mod outer;
mod points;
mod projection;
mod schedule;
pub mod siconos;
mod solution;
mod uniqueness;
mod uzawa;
mod weakening;

pub use electric::{ElectricContact, ElectricContactProblem, ElectricLaw, ElectricValues};
pub use floating::{solve_floating, FloatingError, CHARGE_TOL};
pub use force_control::{solve_force_controlled, solve_force_controlled_spread, ForceError, Spread, FORCE_TOL};
pub use gauss_seidel::{solve_gauss_seidel, GaussSeidelParams};
pub use newton::{solve_newton, solve_newton_cached, solve_newton_electric, NewtonCache, NewtonParams};
pub use operator::{AffineProblem, Compliance, ContactOperator, DenseContactProblem, SparseContactProblem};
pub use points::{ContactPoints, Foundation, PointValues, Status};
pub use projection::{disc_piece, project_cone, project_disc, project_nonnegative, DiscPiece};
pub use schedule::{Phase, ProblemClass, Schedule};
pub use solution::{
    classify, complementarity_norms, complementarity_residual, coulomb_radius, desaxce_residual, multiplier_scale,
    relative_complementarity, slip_bound, ContactInfo, ContactSolution, Interrupt, Interruption, Iterate, Law, Measure,
    Progress, Stage, Stall,
};
pub use uniqueness::slip_bound_expansion;
pub use uzawa::{solve_uzawa, StopRule, UzawaParams, FIXED_POINT_PATIENCE};
pub use weakening::{
    solve_slip_weakening, solve_slip_weakening_cached, Anderson, Inner, SlipWeakening, Weakening, WeakeningParams,
    ANDERSON_DEPTH,
};

/// A failure of the primal solve behind a [`ContactOperator`], with its cause (for example the
/// linear solver's own error), which [`std::error::Error::source`] returns.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{0}")]
pub struct OperatorError(std::sync::Arc<dyn std::error::Error + Send + Sync>);

impl OperatorError {
    /// Wraps the error of a primal solve.
    pub fn new(source: impl std::error::Error + Send + Sync + 'static) -> Self {
        OperatorError(std::sync::Arc::new(source))
    }

    /// The error of the primal solve.
    pub fn cause(&self) -> &(dyn std::error::Error + Send + Sync + 'static) {
        &*self.0
    }
}

/// What can go wrong in a contact solve. Each variant of a loop that stopped carries its
/// iterations, the residual it stopped at and, where there was one, the best iterate it
/// found (by the measure it was asked to meet), so that a caller can still use or inspect it.
/// A loop never reports an error at a residual that meets its tolerance. The messages name no
/// solver option: the application that chose the solver knows what else to try.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ContactError {
    /// A first-order iteration reached its iteration limit while still making progress.
    #[error("Uzawa did not converge in {n_iters} iterations (residual {residual:.3e})")]
    NoConvergence {
        /// Iterations done.
        n_iters: usize,
        /// Last residual.
        residual: f64,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// The fixed point on the slip bound did not converge: it reached its iteration limit, or
    /// stopped early where its steps no longer contracted (no better residual over
    /// [`FIXED_POINT_PATIENCE`] steps, its relaxation at its floor or not).
    #[error("the friction fixed point did not converge in {n_iters} iterations (residual {residual:.3e}){}", contraction.map_or(String::new(), |q| format!("; it stopped improving: no residual a tenth below its best over its last {FIXED_POINT_PATIENCE} steps, each of which moved the slip bound by {q:.2} times the step before (a fixed point that contracts gains digits at every step), so it was stopped there")))]
    FixedPointNoConvergence {
        /// Fixed-point iterations done.
        n_iters: usize,
        /// The measured ratio of successive changes of the slip bound (the map's contraction,
        /// geometric mean over the last steps), where the loop stopped for it.
        contraction: Option<f64>,
        /// Last residual.
        residual: f64,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// A first-order loop that falls, but at a rate that would not reach its target within its
    /// iteration limit: stopped at once (measured over the last iterations).
    #[error("a first-order loop falls too slowly: at its measured rate it would need about {needed} more iterations to go from {residual:.3e} to {target:.1e}, beyond its limit of {limit} (the dual problem is ill-conditioned: strong coupling, or a fine mesh)")]
    TooSlow {
        /// Iterations done.
        n_iters: usize,
        /// The residual now.
        residual: f64,
        /// The residual it must reach.
        target: f64,
        /// The iterations it would need, at its rate.
        needed: usize,
        /// Its limit.
        limit: usize,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// The residual grew without bound (or stopped being a number), even after the step was
    /// halved.
    #[error("Uzawa diverged after {n_iters} iterations (residual {residual:.3e}, step {step:.3e})")]
    Diverged {
        /// Iterations done.
        n_iters: usize,
        /// Last residual.
        residual: f64,
        /// The last step.
        step: f64,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// The iteration stopped making progress (its residual did not grow): every remedy the
    /// solver has was tried.
    #[error("{} stalled after {n_iters} iterations on {reason} (residual {residual:.3e}; best {:.3e})", .stage.name(), best.as_ref().map_or(f64::NAN, |b| b.residual))]
    Stalled {
        /// The loop that stalled last.
        stage: Stage,
        /// Iterations done, all loops together.
        n_iters: usize,
        /// The residual at the stall.
        residual: f64,
        /// What stopped it.
        reason: Stall,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// The solve was stopped from outside: its deadline passed or it was cancelled.
    #[error("{why} after {n_iters} iterations (residual {residual:.3e})")]
    Interrupted {
        /// Deadline or cancellation.
        why: Interruption,
        /// Iterations done.
        n_iters: usize,
        /// The residual then.
        residual: f64,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// Every solver stalled on a Coulomb problem whose fixed point on the slip bound does not
    /// contract near the best iterate found ([`slip_bound_expansion`]): the contraction on
    /// which the existence and uniqueness of the solution rest fails there, and the problem
    /// may have several solutions nearby, or none.
    #[error("no solver converged (best residual {residual:.3e}), and the data are past the uniqueness of Coulomb's law: near the best iterate the fixed point on the slip bound S = F λ_n expands perturbations by {expansion:.2} (the existence and uniqueness theory needs a contraction, below 1), so the problem may have several solutions or none")]
    NotUnique {
        /// The measured expansion of the fixed-point map (at least 1).
        expansion: f64,
        /// Iterations done.
        n_iters: usize,
        /// The best residual.
        residual: f64,
        /// The best iterate.
        best: Option<Box<Iterate>>,
    },
    /// The multipliers do not move the contact points: the dual operator's largest eigenvalue
    /// is not positive and finite.
    #[error("the compliance's largest eigenvalue estimate is {mu_max} (the dual operator D W, Siconos' W): the multipliers move no contact point, so the compliance is zero, or not positive semidefinite, or not finite")]
    NotLoaded {
        /// The estimate.
        mu_max: f64,
    },
    /// The primal solve failed.
    #[error("primal solve failed: {0}")]
    Operator(#[source] OperatorError),
    /// Bad input.
    #[error("contact input: {0}")]
    Input(#[from] InputError),
}

/// What is wrong with the input of a contact solve: the first bad item, by name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// The arrays of the contact points do not all have one entry per point.
    #[error("contact points: arrays of different lengths")]
    PointArrays,
    /// A point's value out of its range: a weight that is not positive, a gap that is not
    /// finite, a friction coefficient that is negative or not finite.
    #[error("contact point {point}: {field} {value} {must}")]
    PointValue {
        /// The point.
        point: usize,
        /// The field (`weight`, `gap`, `friction`).
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be, in words.
        must: &'static str,
    },
    /// Values of the wrong shape: `tangential` values for `points` points of `nt` components.
    #[error("{tangential} tangential values for {points} points with {nt} components each")]
    TangentialShape {
        /// Tangential values given.
        tangential: usize,
        /// Points.
        points: usize,
        /// Tangential components per point.
        nt: usize,
    },
    /// A problem whose size does not match its points.
    #[error("the problem has {points} points with {tangential} tangential components; expected {expected_points} with {expected_tangential}")]
    ProblemSize {
        /// The problem's points.
        points: usize,
        /// The problem's tangential components per point.
        tangential: usize,
        /// The points given.
        expected_points: usize,
        /// The tangential components the law needs.
        expected_tangential: usize,
    },
    /// A compliance whose size does not match its loads.
    #[error("the compliance is {size} x {size} and the loads have {points} points; {n} points with {nt} tangential components need {m} x {m}")]
    ComplianceSize {
        /// The compliance's order.
        size: usize,
        /// The loads' points.
        points: usize,
        /// The points.
        n: usize,
        /// Tangential components per point.
        nt: usize,
        /// The order they need.
        m: usize,
    },
    /// An electrical contact's value out of its range.
    #[error("electrical contact: {what} {value} {must}")]
    Electric {
        /// The value (`conductance`, `foundation potential`, `point`).
        what: &'static str,
        /// Its value.
        value: f64,
        /// What it must be, in words.
        must: &'static str,
    },
    /// A foundation's parameter out of its range.
    #[error("normal compliance: {what} {value} {must}")]
    Foundation {
        /// `stiffness` or `exponent`.
        what: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        must: &'static str,
    },
    /// Tresca's bounds are not one finite non-negative value per point.
    #[error("Tresca slip bounds: one finite non-negative value per point")]
    TrescaBounds,
    /// A warm start whose shape is not the problem's.
    #[error("warm start of the wrong size")]
    WarmStart,
    /// A parameter out of its range (a tolerance or a step that is not positive), in words.
    #[error("{0}")]
    Parameter(String),
    /// A solver handed a problem of a kind it does not solve.
    #[error("{0}")]
    Unsupported(&'static str),
}

impl ContactError {
    /// The residual the solve stopped at (`None` for errors that are not a stopped loop).
    pub fn residual(&self) -> Option<f64> {
        match self {
            ContactError::NoConvergence { residual, .. }
            | ContactError::TooSlow { residual, .. }
            | ContactError::FixedPointNoConvergence { residual, .. }
            | ContactError::Diverged { residual, .. }
            | ContactError::Stalled { residual, .. }
            | ContactError::NotUnique { residual, .. }
            | ContactError::Interrupted { residual, .. } => Some(*residual),
            _ => None,
        }
    }

    /// The best iterate of a stopped loop, if it kept one.
    pub fn best(&self) -> Option<&Iterate> {
        match self {
            ContactError::NoConvergence { best, .. }
            | ContactError::TooSlow { best, .. }
            | ContactError::FixedPointNoConvergence { best, .. }
            | ContactError::Diverged { best, .. }
            | ContactError::Stalled { best, .. }
            | ContactError::NotUnique { best, .. }
            | ContactError::Interrupted { best, .. } => best.as_deref(),
            _ => None,
        }
    }

    /// The error with `candidate` as its best iterate where `candidate` is better than the one
    /// it holds (or it holds none).
    pub fn with_best(mut self, candidate: Iterate) -> Self {
        if let ContactError::NoConvergence { best, .. }
        | ContactError::TooSlow { best, .. }
        | ContactError::FixedPointNoConvergence { best, .. }
        | ContactError::Diverged { best, .. }
        | ContactError::Stalled { best, .. }
        | ContactError::NotUnique { best, .. }
        | ContactError::Interrupted { best, .. } = &mut self
        {
            if best.as_ref().is_none_or(|b| !(b.residual <= candidate.residual)) {
                *best = Some(Box::new(candidate));
            }
        }
        self
    }
}
