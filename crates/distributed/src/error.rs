//! What can stop a run of the PETSc backend: the problem's errors, PETSc's, MPI's and MUMPS',
//! and the active sets' (the Krylov route's contact).

use petsc::PetscError;
use problem::ProblemError;

/// What can stop a run of the PETSc backend.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DistributedError {
    /// The scene, its mesh or its data (as the default backend reports them).
    #[error(transparent)]
    Problem(#[from] ProblemError),
    /// PETSc, MPI or MUMPS.
    #[error(transparent)]
    Petsc(#[from] PetscError),
    /// The active sets (the Krylov route's contact) did not converge.
    #[error("contact: {0}")]
    Contact(crate::contact::ActiveSetError),
    /// PETSc's or the active sets' error at a path's step (the problem's own are wrapped as
    /// the default backend wraps them, [`ProblemError::AtStep`]).
    #[error("path step {step} (t = {t}): {source}")]
    AtStep {
        /// The step (0 is the path's first instant).
        step: usize,
        /// Its instant.
        t: f64,
        /// What stopped it.
        source: Box<DistributedError>,
    },
}

impl DistributedError {
    /// The error as at a path's step `step` (instant `t`): the problem's own wrapped as the
    /// default backend's path wraps them, the others in [`DistributedError::AtStep`].
    #[must_use]
    pub fn at_step(self, step: usize, t: f64) -> Self {
        match self {
            DistributedError::Problem(p) => DistributedError::Problem(p.at_step(step, t)),
            e @ DistributedError::AtStep { .. } => e,
            other => DistributedError::AtStep {
                step,
                t,
                source: Box::new(other),
            },
        }
    }
}

impl From<crate::contact::ActiveSetError> for DistributedError {
    /// PETSc's own failure as PETSc's, the iteration's as the contact's.
    fn from(e: crate::contact::ActiveSetError) -> Self {
        match e {
            crate::contact::ActiveSetError::Petsc(p) => DistributedError::Petsc(p),
            other => DistributedError::Contact(other),
        }
    }
}

impl From<fe_assembly::AssemblyError> for DistributedError {
    fn from(e: fe_assembly::AssemblyError) -> Self {
        DistributedError::Problem(e.into())
    }
}

impl From<problem::SceneError> for DistributedError {
    fn from(e: problem::SceneError) -> Self {
        DistributedError::Problem(e.into())
    }
}

/// A PETSc error of a solve on the ranks (`sought`: which), among the problem's.
pub(crate) fn solve_failed(sought: &'static str, e: PetscError) -> ProblemError {
    ProblemError::NoSolution {
        sought,
        why: e.to_string(),
    }
}
