//! Contact with a rigid foundation, seen from the multipliers: contact points, the projections
//! onto the multiplier sets, Uzawa's algorithm, the fixed point on the friction threshold,
//! residuals and stick/slip status. It knows no finite elements: it sees the problem only
//! through [`ContactOperator`] ("given multipliers, return the displacement of the contact
//! points"), so the same solvers run on the full system and on small dense problems.
//!
//! # Glossary (signs fixed by DESIGN.md)
//! - `n`: outward normal of the body; `u_n = u·n`, `u_t = (u·t_k)_k`; gap `g`: `u_n ≤ g`.
//! - `λ_n = -σ_n ≥ 0`: the contact pressure; `λ_t = -(σn)·t`, so at a sliding point `λ_t`
//!   points along `u_t`. Equilibrium: `A u + Gᵀ φ = f - Nᵀ W λ_n - Tᵀ W λ_t`, `W` the weights.
//! - Uzawa: `λ_n ← max(0, λ_n + r (u_n - g))`, `λ_t ← P_S(λ_t + r u_t)`, `P_S` the projection
//!   onto the disc `|λ_t| ≤ S`; Coulomb: `S = F λ_n` by a fixed point.
//! - `μ_max`: the largest eigenvalue of the dual operator (weighted contact compliance); the
//!   step is `r = 1.8 / μ_max` by default (convergence needs `r < 2 / μ_max`).
//! - Complementarity residual: the natural map with `c = 1 / μ_max`, weighted, relative to
//!   `‖λ‖_W` (see [`complementarity_residual`]).
//!
//! # Example
//! ```
//! use contact::{solve, ContactPoints, DenseContactProblem, Law, PointValues, Status, UzawaParams};
//! // one point pressed 1 unit into the foundation through a spring of compliance 1:
//! // u_n = 1 - λ_n (w = 1), contact at g = 0 needs λ_n = 1.
//! let points = ContactPoints {
//!     dim: 2, position: vec![[0.0; 3]], normal: vec![[0.0, -1.0, 0.0]],
//!     tangent: vec![[[1.0, 0.0, 0.0], [0.0; 3]]], weight: vec![1.0], gap: vec![0.0], friction: vec![0.0],
//! };
//! let mut op = DenseContactProblem {
//!     u0: PointValues::from_parts(vec![1.0], vec![], 0).unwrap(),
//!     compliance: vec![1.0], weight: vec![1.0], nt: 0,
//! };
//! let sol = solve(&mut op, &points, &Law::Frictionless, &UzawaParams::default(), None, &mut |_| {}).unwrap();
//! assert!((sol.lambda.normal[0] - 1.0).abs() < 1e-10);
//! assert_eq!(sol.status[0], Status::Slip); // frictionless contact: slip
//! ```

mod newton;
mod operator;
mod points;
mod projection;
mod solution;
mod uzawa;

pub use newton::{solve_newton, NewtonParams};
pub use operator::{ContactOperator, DenseContactProblem};
pub use points::{ContactPoints, PointValues, Status};
pub use projection::{project_disc, project_nonnegative};
pub use solution::{
    classify, complementarity_residual, slip_bound, ContactInfo, ContactSolution, Law, Progress, Stage,
};
pub use uzawa::{solve, StopRule, UzawaParams};

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

/// What can go wrong in a contact solve; each variant of a loop that stopped carries its last
/// residual. The messages name no solver option: the application that chose the solver knows
/// what else to try.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ContactError {
    /// The first-order iteration did not reach its tolerance.
    #[error("Uzawa did not converge in {n_iters} iterations (complementarity residual {residual:.3e})")]
    NoConvergence {
        /// Iterations done.
        n_iters: usize,
        /// Last residual.
        residual: f64,
    },
    /// The fixed point on the slip bound did not converge.
    #[error("the friction fixed point did not converge in {n_iters} iterations (residual {residual:.3e}); the fixed point on S may cycle under strong coupling or large F")]
    FixedPointNoConvergence {
        /// Iterations done.
        n_iters: usize,
        /// Last residual.
        residual: f64,
    },
    /// The iteration diverged even after halving the step.
    #[error("Uzawa diverged after {n_iters} iterations (residual {residual:.3e}, step {step:.3e})")]
    Diverged {
        /// Iterations done.
        n_iters: usize,
        /// Last residual.
        residual: f64,
        /// The last step.
        step: f64,
    },
    /// The semismooth Newton iteration stalled (and its fallback was switched off).
    #[error("semismooth Newton stalled after {n_iters} steps on {reason} (complementarity residual {residual:.3e})")]
    NewtonStalled {
        /// Newton steps done.
        n_iters: usize,
        /// Last residual.
        residual: f64,
        /// What stopped it.
        reason: String,
    },
    /// The multipliers do not move the contact points: the dual operator's largest eigenvalue
    /// is not positive and finite.
    #[error("the dual operator's largest eigenvalue estimate is {mu_max}: the contact points are not loaded by their multipliers")]
    NotLoaded {
        /// The estimate.
        mu_max: f64,
    },
    /// The primal solve failed.
    #[error("primal solve failed: {0}")]
    Operator(#[source] OperatorError),
    /// Bad input.
    #[error("contact input: {0}")]
    Input(String),
}
