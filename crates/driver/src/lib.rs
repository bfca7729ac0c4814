//! The `piezocontact` application over the [`problem`] library and its files ([`files`]): the
//! third-party friction problems ([`fclib`]), the studies (sweep, Table 1, convergence,
//! verification, stability: [`studies`]) and, with the feature `petsc`, the run on the ranks
//! of an MPI run. The command-line program (`src/main.rs`) is one dispatch over these and
//! [`files`]' scene files, runs and outputs.

pub mod fclib;
#[cfg(feature = "petsc")]
pub mod petsc_run;
pub mod studies;

/// What can go wrong in the application; each variant names the file or item at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DriverError {
    /// A scene, mesh or input file, the run, or an output (as the library reports them).
    #[error(transparent)]
    Files(#[from] files::Error),
    /// PETSc or MPI, in a run of the PETSc backend.
    #[cfg(feature = "petsc")]
    #[error(transparent)]
    Petsc(#[from] petsc::PetscError),
    /// The PETSc backend's active sets (its Krylov route's contact) did not converge.
    #[cfg(feature = "petsc")]
    #[error("contact: {0}")]
    ActiveSet(distributed::contact::ActiveSetError),
    /// Another failure of the PETSc backend's run.
    #[cfg(feature = "petsc")]
    #[error(transparent)]
    Distributed(distributed::DistributedError),
    /// Command-line arguments (or a library caller's) that do not fit together, or are out of
    /// their range.
    #[error("{0}")]
    Usage(String),
    /// Cases of a study that did not end as they must.
    #[error("{what}: {}", .items.join("; "))]
    Unexpected {
        /// What the items are.
        what: &'static str,
        /// The cases, each with what went wrong.
        items: Vec<String>,
    },
}

impl From<problem::ProblemError> for DriverError {
    fn from(e: problem::ProblemError) -> Self {
        DriverError::Files(e.into())
    }
}

impl DriverError {
    /// The run's own error, where this is one.
    pub fn problem(&self) -> Option<&problem::ProblemError> {
        match self {
            DriverError::Files(files::Error::Problem(p)) => Some(p),
            _ => None,
        }
    }
}
