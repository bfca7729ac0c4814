//! The files of piezocontact, over the [`problem`] library, for the application and for
//! library users (the Python package among them): scene files and `--set` overrides
//! ([`scene_file`]), the run of a scene with its Gmsh mesh read and the machine's memory
//! probed ([`run`], [`memory`]), time limits ([`limits`]), the output set (`run.json`,
//! ParaView's `.vtu`, `contact.csv`, pictures: [`output`]) and pictures drawn from plain
//! series ([`plots`]). It never prints.
//!
//! # Example
//! ```
//! let (scene, source) = files::scene_file::load("paper", &["mesh.n=4".into(), "contact.law=none".into()]).unwrap();
//! let solution = files::run::solve(&scene, &source, &mut problem::Silent).unwrap();
//! // 9 x 5 nodes, the two clamped columns removed: 2 x 7 x 5 free displacements
//! assert_eq!(solution.report.dofs.u, 2 * 7 * 5);
//! assert!(solution.report.residuals.equilibrium < 1e-12);
//! // a scene error keeps its key
//! let e = files::scene_file::load("paper", &["mesh.n=0".into()]).unwrap_err();
//! let files::Error::Scene { source: files::SceneFileError::Invalid(invalid), .. } = &e else { panic!("{e}") };
//! assert_eq!(invalid.key, "mesh.n");
//! ```

pub mod limits;
pub mod memory;
pub mod output;
pub mod plots;
pub mod run;
pub mod scene_file;

/// What can go wrong with the files of a run; each variant names the file or item at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A scene that does not read, or holds an invalid value.
    #[error("scene {file}: {source}")]
    Scene {
        /// The scene's name or path.
        file: String,
        /// What is wrong.
        source: SceneFileError,
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
    /// A value given by a caller that is out of its range (a time limit that is not a positive
    /// number of seconds).
    #[error("{0}")]
    Usage(String),
}

/// Why a scene file does not become a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneFileError {
    /// No shipped scene has the name, and no file the path.
    #[error("no shipped scene of that name and no such file (shipped: {})", .shipped.join(", "))]
    NotFound {
        /// The shipped scenes' names.
        shipped: Vec<&'static str>,
    },
    /// The path is a directory, a FIFO or a device: its read would block, or never end.
    #[error("is not a regular file")]
    NotAFile,
    /// The file does not read.
    #[error(transparent)]
    Read(std::io::Error),
    /// The text is not TOML, or not a scene (an unknown key, a value of the wrong kind).
    /// (toml's text ends in blank lines, which a message that goes on after it does not want.)
    #[error("{}", .0.to_string().trim_end())]
    Toml(#[from] toml::de::Error),
    /// An override (`--set`, or a Python keyword) that does not apply.
    #[error("--set {set}: {message}")]
    Override {
        /// The override as given.
        set: String,
        /// The key it names (before `=`, without a leading `~`).
        key: String,
        /// Why it does not apply.
        message: String,
    },
    /// A value that [`problem::Scene::validate`] refuses, with its key.
    #[error(transparent)]
    Invalid(#[from] problem::SceneError),
}

impl Error {
    /// The error of scene `file`.
    pub fn scene(file: &str, source: impl Into<SceneFileError>) -> Self {
        Error::Scene {
            file: file.into(),
            source: source.into(),
        }
    }
}
