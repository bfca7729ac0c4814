//! Sparse linear algebra for piezocontact: factorisations (faer's low-level sparse Cholesky and
//! `L D Lᵀ`), preconditioned conjugate gradients, the Schur-complement operator, and the two
//! strategies for the coupled system. It knows no finite elements: it sees matrices.
//!
//! # Glossary (signs fixed by docs/theory.md)
//! - `A` (n_u x n_u, SPD), `G` (n_φ x n_u), `B` (n_φ x n_φ, SPD): the blocks of
//!   `K = [[A, Gᵀ], [G, -B]]`, symmetric quasi-definite, with exactly `n_φ` negative pivots.
//! - `S = A + Gᵀ B⁻¹ G`: the Schur complement of `K` onto `u` (SPD), applied by
//!   [`SchurOperator`], never formed.
//! - Sparse matrices are faer's `SparseColMat<usize, f64>`; factorisations read only the lower
//!   triangle.
//! - Parallelism is an explicit `faer::Par` argument.
//!
//! # Example
//! ```
//! use faer::sparse::{SparseColMat, Triplet};
//! use linalg::{pcg, FactorKind, Identity, Ordering, PcgParams, SparseFactor};
//! // the 1D Laplacian, 5 x 5
//! let n = 5;
//! let mut t = vec![];
//! for i in 0..n {
//!     t.push(Triplet::new(i, i, 2.0));
//!     if i + 1 < n {
//!         t.push(Triplet::new(i, i + 1, -1.0));
//!         t.push(Triplet::new(i + 1, i, -1.0));
//!     }
//! }
//! let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
//! let mut f = SparseFactor::new(a.as_ref(), FactorKind::Cholesky, &Ordering::Amd, faer::Par::Seq).unwrap();
//! let mut x = vec![1.0; n];
//! f.solve_in_place(&mut x);
//! // x = A⁻¹ 1 = (i + 1)(n - i) / 2
//! for i in 0..n {
//!     assert!((x[i] - ((i + 1) * (n - i)) as f64 / 2.0).abs() < 1e-12);
//! }
//! ```

mod condense;
mod coupled;
mod dense;
mod factor;
mod pcg;
mod progress;
pub mod sparse;
mod tree;
mod values;

pub use condense::{CondenseRoute, Condensed, CondensedLoads};
pub use coupled::{
    equilibrium_residual, refine, refine_by, refine_many, relative_residual, CoupledBlocks, CoupledSolver, DirectLdlt,
    FactorPreconditioner, Refinable, Refined, Residual, Rhs, SchurOperator, SchurPcg, SolveInfo, UPhi, UPhiRef,
};
pub use dense::{mirror_lower, symmetric_inverse};
pub use factor::{pool_par, FactorKind, Ordering, SparseFactor, SINGULAR_PIVOT_RATIO};
pub use pcg::{dot, norm, pcg, Identity, LinearOperator, PcgInfo, PcgParams, PcgStop};
pub use progress::FactorProgress;

/// What can go wrong in the linear algebra.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum LinalgError {
    /// A Cholesky factorisation met a non-positive pivot: the matrix is not SPD (for example a
    /// body that is not held against rigid motions).
    #[error("the matrix is not positive definite (pivot {pivot})")]
    NotPositiveDefinite {
        /// The matrix's index (row and column) whose pivot it was.
        pivot: usize,
    },
    /// An `L D Lᵀ` factorisation met an exactly zero pivot.
    #[error("zero pivot {pivot} in the L D Lᵀ factorisation")]
    ZeroPivot {
        /// The matrix's index (row and column) whose pivot it was.
        pivot: usize,
    },
    /// A pivot lost all but a few digits of its diagonal entry to cancellation: the matrix is
    /// singular to working precision.
    #[error("the matrix is singular to working precision at unknown {index} (its pivot is {ratio:.1e} of its diagonal entry): is a rigid-body motion, or a floating potential, left free by the Dirichlet conditions? (contact alone does not hold a body here: every solve needs K invertible)")]
    NearlySingular {
        /// The unknown (original index) whose pivot cancelled.
        index: usize,
        /// `|pivot| / |diagonal entry|`.
        ratio: f64,
    },
    /// PCG did not reach its tolerance.
    #[error("PCG did not converge in {n_iters} iterations (relative residual {rel_residual:.3e})")]
    NoConvergence {
        /// Iterations done.
        n_iters: usize,
        /// The last relative residual.
        rel_residual: f64,
    },
    /// PCG met a direction of non-positive curvature.
    #[error("the operator is not positive definite: curvature {curvature:.3e} at PCG iteration {n_iters}")]
    NotPositiveDefiniteOperator {
        /// The iteration.
        n_iters: usize,
        /// `pᵀ M p` (or `rᵀ P⁻¹ r`).
        curvature: f64,
    },
    /// A NaN or infinity.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Where.
        what: String,
    },
    /// A factor that would not fit in the memory allowed (known after the symbolic analysis,
    /// before any numeric work).
    #[error("the factor and its workspace need {needed} bytes, more than the {budget} allowed")]
    TooLarge {
        /// Bytes the factor needs.
        needed: usize,
        /// Bytes allowed.
        budget: usize,
    },
    /// A solver outside this crate failed (one implementing [`CoupledSolver`] on the ranks
    /// of an MPI run, say), in its own words.
    #[error("{0}")]
    Solver(String),
    /// Sizes that do not fit.
    #[error("shape mismatch: {0}")]
    Shape(#[from] ShapeError),
    /// The symbolic analysis failed.
    #[error("symbolic factorisation failed: {0}")]
    Symbolic(String),
    /// An error with the name of the matrix it concerns.
    #[error("{what}: {source}")]
    In {
        /// The matrix.
        what: &'static str,
        /// The error.
        source: Box<LinalgError>,
    },
}

/// Sizes that do not fit, by what they are.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ShapeError {
    /// A matrix that is not square.
    #[error("a {rows}x{cols} matrix is not square")]
    NotSquare {
        /// Its rows.
        rows: usize,
        /// Its columns.
        cols: usize,
    },
    /// An ordering that is not a permutation (an index out of range or repeated).
    #[error("ordering: {what} {index} is out of range or repeated")]
    Ordering {
        /// Which part of the ordering (`index` of the trailing dofs, or the permutation's entry).
        what: &'static str,
        /// The index.
        index: usize,
    },
    /// A condensation dof out of range.
    #[error("condensation: dof {dof} of {n}")]
    CondensedDof {
        /// The dof.
        dof: usize,
        /// The unknowns.
        n: usize,
    },
    /// Values for the condensed dofs that are not one per dof.
    #[error("{values} values for {dofs} condensed dofs")]
    CondensedValues {
        /// Values given.
        values: usize,
        /// Condensed dofs.
        dofs: usize,
    },
    /// A right-hand side whose length is not the system's.
    #[error("a right-hand side of {got} entries for a system of {expected}")]
    Rhs {
        /// The system's unknowns.
        expected: usize,
        /// The right-hand side's entries.
        got: usize,
    },
    /// Vectors of PCG whose sizes are not the operator's.
    #[error("pcg: operator {operator}, preconditioner {preconditioner}, b {b}, x {x}")]
    Pcg {
        /// The operator's order.
        operator: usize,
        /// The preconditioner's.
        preconditioner: usize,
        /// The right-hand side's length.
        b: usize,
        /// The solution's length.
        x: usize,
    },
}

impl LinalgError {
    /// Wraps the error with the name of the matrix it concerns.
    pub fn context(self, what: &'static str) -> Self {
        LinalgError::In {
            what,
            source: Box::new(self),
        }
    }
}
