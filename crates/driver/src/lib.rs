//! The `piezocontact` driver: scene files, the run plan, the solve, and the outputs
//! (`run.json`, `solution.vtu`). The command-line program is a thin layer over this library.
//!
//! # Glossary
//! - scene: a TOML file (or a shipped scene's name) that says what to solve; `--set KEY=VALUE`
//!   overrides any of its keys (`mesh.n=128`, `contact.law=none`, `mesh.h=1/128`).
//! - plan: what the run needs, decided before computing (electric unknowns or not, which
//!   contact loops, which linear strategy, which outputs); printed and stored in `run.json`.
//! - Units are those of the scene (the scaled scenes: m, GPa, C/m², nF/m; φ in GV).
//!
//! # Example
//! ```
//! let (scene, source) = driver::scene::load("paper", &["mesh.n=4".into(), "contact.law=none".into()]).unwrap();
//! let out = driver::run::run(&scene, &source, None, &mut |_| {}).unwrap();
//! // 9 x 5 nodes, the two clamped columns removed: 2 x 7 x 5 free displacements
//! assert_eq!(out.report["dofs"]["u"], 2 * 7 * 5);
//! assert!(out.report["residuals"]["equilibrium"].as_f64().unwrap() < 1e-12);
//! ```

pub mod build;
pub mod contact_setup;
pub mod convergence;
pub mod exact;
pub mod output;
pub mod plots;
pub mod run;
pub mod scene;
pub mod stability;
pub mod studies;
pub mod verification;

/// What can go wrong in a run; each variant names the file or item at fault.
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
    /// A mesh problem.
    #[error("mesh: {0}")]
    Mesh(#[from] mesh::MeshError),
    /// An assembly problem (materials, conditions, groups).
    #[error("setup: {0}")]
    Assembly(#[from] fe_assembly::AssemblyError),
    /// A material problem.
    #[error("material: {0}")]
    Material(#[from] fe_assembly::MaterialError),
    /// A linear-algebra failure.
    #[error("linear solve: {0}")]
    Linalg(#[from] linalg::LinalgError),
    /// Inconsistent input.
    #[error("{0}")]
    Input(String),
    /// The contact solve failed (with its last residual).
    #[error("contact: {0}")]
    Contact(#[from] contact::ContactError),
    /// Writing the outputs failed.
    #[error("output: {0}")]
    Output(String),
}
