//! What the condensed route of a run's instants ([`crate::Instants`]) asks of a backend's
//! factorisation of `K`: solves, the condensation onto chosen dofs and the solve that finishes
//! it, refinement and the equilibrium residual. The default backend's `L D Lᵀ` implements it,
//! and so does the PETSc backend's MUMPS factorisation on the ranks.

use crate::ProblemError;
use linalg::{Condensed, CondensedLoads, CoupledSolver};

/// The free unknowns `(u, φ)` of the discretisation.
pub type Fields = (Vec<f64>, Vec<f64>);

/// What [`Factorization::refine`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Refinement {
    /// Corrections applied (each one solve with the factors).
    pub steps: usize,
    /// The equilibrium residual of the result, where the refinement measured it (a direct
    /// factorisation's; `None` where it does not refine).
    pub residual: Option<f64>,
}

impl From<linalg::Refined> for Refinement {
    fn from(r: linalg::Refined) -> Self {
        Refinement {
            steps: r.steps,
            residual: Some(r.residual),
        }
    }
}

/// What the instants ask of a backend's factorisation of `K` (the free unknowns laid out
/// `[u; φ]`, `K = [[A, Gᵀ], [G, -B]]` as docs/theory.md writes it). Its calls are collective
/// where the backend's are (every rank makes them, in the same order), and every rank holds
/// the whole vectors they take and give.
pub trait Factorization {
    /// `K⁻¹ [b_u; b_φ]`, with the inner iterations it took (an iterative solver's; 0 for a
    /// direct one).
    ///
    /// # Errors
    /// The solver's.
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64]) -> Result<(Fields, usize), ProblemError>;

    /// `K` condensed onto `dofs` (indices into `[u; φ]`) with the loads `[b_u; b_φ]`
    /// ([`linalg::Condensed`]).
    ///
    /// # Errors
    /// The factorisation's; a backend that does not condense refuses.
    fn condense(&mut self, b_u: &[f64], b_phi: &[f64], dofs: &[usize]) -> Result<Condensed, ProblemError>;

    /// `K⁻¹ ([b_u; b_φ] + Σ_j d_j e_{c_j})`, finishing the solve of a condensation whose loads'
    /// part is `loads` (the dofs `c` its own).
    ///
    /// # Errors
    /// The solver's.
    fn solve_with_update(
        &mut self,
        loads: CondensedLoads,
        b_u: &[f64],
        b_phi: &[f64],
        d: &[f64],
    ) -> Result<Fields, ProblemError>;

    /// Iterative refinement of `(u, φ)` towards `rhs`, to the equilibrium residual `tol`: the
    /// steps taken (none where the factorisation is not a direct one), and the equilibrium
    /// residual of the result where the refinement measured it (what [`Self::equilibrium`]
    /// would give, without its product with `K`).
    ///
    /// # Errors
    /// The solver's.
    fn refine(
        &mut self,
        rhs: linalg::Rhs<'_>,
        u: &mut [f64],
        phi: &mut [f64],
        tol: f64,
    ) -> Result<Refinement, ProblemError>;

    /// `K⁻¹ [b_u; b_φ]` for each right-hand side of `rhs`, in their order (one solve each,
    /// unless the factorisation solves several at once).
    ///
    /// # Errors
    /// The solver's.
    fn solve_many(&mut self, rhs: &[(&[f64], &[f64])]) -> Result<Vec<Fields>, ProblemError> {
        rhs.iter().map(|(b_u, b_phi)| Ok(self.solve(b_u, b_phi)?.0)).collect()
    }

    /// [`Self::refine`] of several solutions `xs`, one per right-hand side of `rhs` (one at a
    /// time, unless the factorisation corrects several at once).
    ///
    /// # Errors
    /// The solver's.
    fn refine_many(
        &mut self,
        rhs: &[linalg::Rhs<'_>],
        xs: &mut [Fields],
        tol: f64,
    ) -> Result<Vec<Refinement>, ProblemError> {
        rhs.iter()
            .zip(xs.iter_mut())
            .map(|(b, (u, phi))| self.refine(*b, u, phi, tol))
            .collect()
    }

    /// `K⁻¹ Σ_i d_i e_{c_i}` for each `d` of `updates` (values at the condensation's dofs
    /// `dofs`), solved together, where the factorisation can solve such right-hand sides for
    /// less than full solves (a factor whose order ends with `dofs`: a backward sweep each,
    /// [`linalg::DirectLdlt::solve_trailing_many`]); `None` otherwise (the caller solves in
    /// full).
    ///
    /// # Errors
    /// The solver's.
    fn solve_trailing_many(&mut self, dofs: &[usize], updates: &[&[f64]]) -> Result<Option<Vec<Fields>>, ProblemError> {
        let _ = (dofs, updates);
        Ok(None)
    }

    /// `‖K x - b‖ / max(‖b‖, scale)` ([`linalg::equilibrium_residual`]).
    ///
    /// # Errors
    /// The backend's (a collective that failed).
    fn equilibrium(&mut self, u: &[f64], phi: &[f64], rhs: linalg::Rhs<'_>) -> Result<f64, ProblemError>;

    /// The solver for one full primal solve per first-order step (the strategies without the
    /// condensation), where the backend runs them.
    fn coupled(&mut self) -> Option<&mut dyn CoupledSolver>;

    /// Whether [`Factorization::condense`] condenses (a direct factorisation).
    fn condenses(&self) -> bool;
}
