//! The `piezocontact` application over the [`problem`] library: scene files and `--set`
//! overrides ([`scene_file`]), the run of a scene with its Gmsh mesh read and its outputs
//! written ([`run`], [`output`]), pictures drawn from plain series ([`plots`]), and the studies
//! (sweep, Table 1, convergence, verification, stability: [`studies`]). The command-line
//! program (`src/main.rs`) is one dispatch over these.
//!
//! # Example
//! ```
//! let (scene, source) = driver::scene_file::load("paper", &["mesh.n=4".into(), "contact.law=none".into()]).unwrap();
//! let solution = driver::run::solve(&scene, &source, &mut problem::Silent).unwrap();
//! // 9 x 5 nodes, the two clamped columns removed: 2 x 7 x 5 free displacements
//! assert_eq!(solution.report.dofs.u, 2 * 7 * 5);
//! assert!(solution.report.residuals.equilibrium < 1e-12);
//! ```

pub mod fclib;
pub mod limits;
pub mod memory;
pub mod output;
pub mod plots;
pub mod run;
pub mod scene_file;
pub mod studies;

/// What can go wrong in the application; each variant names the file or item at fault.
#[derive(Debug, thiserror::Error)]
pub enum DriverError {
    /// A scene that does not read, or holds an invalid value.
    #[error("scene {file}: {message}")]
    Scene {
        /// The scene's name or path.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// An input file (other than a scene or a mesh) that cannot be read, or does not hold what
    /// it must.
    #[error("{file}: {message}")]
    File {
        /// The file's path.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A Gmsh file that cannot be read.
    #[error("mesh: {0}")]
    Mesh(#[from] mesh::MeshError),
    /// The run failed (the message names the input or step at fault).
    #[error(transparent)]
    Problem(#[from] problem::ProblemError),
    /// A file or directory that cannot be written.
    #[error("output: {what}: {source}")]
    Output {
        /// What was being done, with the path.
        what: String,
        /// The error of the file system.
        source: std::io::Error,
    },
    /// An output that would remove or change what the program did not write, or a set's name
    /// that is not a plain file name.
    #[error("output: {path} {reason}")]
    OutputConflict {
        /// The path at fault.
        path: String,
        /// Why.
        reason: String,
    },
    /// A picture or file that cannot be made.
    #[error("output: {name}: {message}")]
    Picture {
        /// The file.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// PETSc or MPI, in a run of the PETSc backend.
    #[cfg(feature = "petsc")]
    #[error(transparent)]
    Petsc(#[from] petsc::PetscError),
    /// The PETSc backend's contact iteration did not converge.
    #[cfg(feature = "petsc")]
    #[error("contact: {0}")]
    ActiveSet(distributed::contact::ActiveSetError),
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
