//! The discrete problem of piezocontact and its method, as a library: the typed scene, the
//! plan of what a run computes, the set-up of the finite-element problem, the contact
//! boundary, the run as named steps, and a typed report. It ties the four crates below it
//! together (`mesh`, `fe-assembly`, `linalg`, `contact`); it does no file IO, never prints,
//! and every choice in it is an enum. The `piezocontact` application (`driver`) reads scene
//! files, writes outputs and draws pictures on top of it.
//!
//! # Glossary (signs fixed by docs/theory.md)
//! - scene ([`Scene`]): what to solve (mesh, materials, Dirichlet data, load, electrode,
//!   contact, solver, exact solution); checked by [`Scene::validate`].
//! - plan ([`Plan`]): what a run computes, decided before computing (electric unknowns or
//!   not, which contact loops, which strategy, which outputs); the run obeys it.
//! - `λ_n ≥ 0`: the contact pressure; `λ_t`: the tangential multiplier; `u_n ≤ g`.
//! - Units are the scene's (`[units]`, [`UnitsSpec`]; SI where it says nothing): the solver
//!   never converts, and every output says its unit ([`Units`]).
//!
//! # Example
//! A scene built in code (no file): the paper's PZT-5A block, clamped at its sides, pressed
//! onto a rigid foundation with Coulomb friction; then the multipliers and the displacement
//! read back.
//! ```
//! use problem::{ContactLaw, ContactSpec, DirichletSpec, LoadSpec, MaterialSpec, MeshSpec, Scene, Silent};
//! let clamped = |group: &str| DirichletSpec {
//!     group: group.into(),
//!     u: Some(vec![0.0, 0.0]),
//!     phi: Some(0.0),
//!     ..Default::default()
//! };
//! let pzt5a = [121.0, 75.4, 75.2, 111.0, 21.1, 22.6]; // GPa
//! let mut contact = ContactSpec::new("bottom", ContactLaw::Coulomb, &[0.0, -1.0]);
//! contact.friction = Some(0.6);
//! let scene = Scene {
//!     name: "block".into(),
//!     description: "PZT-5A pressed on a rigid floor".into(),
//!     mesh: MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 8),
//!     material: vec![MaterialSpec::crystal_6mm("body", pzt5a, [-5.4, 15.8, 12.3], [8.11, 7.35], [0.0, 1.0, 0.0])],
//!     dirichlet: vec![clamped("left"), clamped("right")],
//!     load: Some(LoadSpec { group: "top".into(), p: -2.0, direction: vec![0.0, 1.0] }.into()),
//!     electrode: None,
//!     contact: Some(contact.into()),
//!     solver: Default::default(),
//!     exact: None,
//!     path: None,
//!     units: Some(problem::UnitsSpec { length: None, stress: Some(problem::StressUnit::Gpa) }),
//! };
//! let solution = problem::solve(&scene, None, &mut Silent).unwrap();
//! let contact = solution.contact.as_ref().unwrap();
//! // the foundation carries the load: Σ w λ_n = 2 x (length of the top face less the corners)
//! let lambda_n = &contact.solution.lambda.normal;
//! let force: f64 = contact.points.weight.iter().zip(lambda_n).map(|(w, l)| w * l).sum();
//! assert!((force - solution.report.contact.normal_force).abs() < 1e-12);
//! assert!(lambda_n.iter().all(|&l| l > 0.0)); // pressed everywhere
//! assert!(solution.report.residuals.complementarity <= 1e-10);
//! // the body moves down under the load, and not into the floor (u_n = -u_y ≤ gap = 0)
//! let top_middle = solution.mesh.points.iter().position(|x| x[0] == 1.0 && x[1] == 1.0).unwrap();
//! assert!(solution.u[top_middle][1] < 0.0);
//! assert!(contact.nodes.iter().all(|&v| -solution.u[v][1] <= 1e-12));
//! ```

mod analytical;
pub mod backend;
mod bed;
mod boundary;
mod capacitance;
mod estimate;
mod exact;
mod factorization;
mod halfspace;
mod instants;
mod outer;
mod path;
mod plan;
mod progress;
mod reach;
pub mod report;
mod run;
mod scene;
mod setup;
mod shared_memory;
mod solution;
mod units;

pub use analytical::{hertz, hertz_sphere, mindlin_deresiewicz_dissipation, mindlin_deresiewicz_traction};
pub use backend::Limits;
pub use capacitance::Capacitance;
pub use estimate::{Bytes, BASE_BYTES};
pub use exact::{contact_errors, ExactReport};
pub use factorization::{Factorization, Refinement};
pub use fe_assembly::{CellFields, Tensors};
pub use halfspace::{HalfSpace, HalfSpaceError, Indentation, Profile, Tip};
pub use instants::Instants;
pub use path::{check_history_scales, run, run_steps, step_loads, step_row, PathSolution, Step, StepFields};
pub use plan::{Output, Plan};
pub use progress::{instant, Event, FactorWatch, Lines, Reporter, Silent};
pub use report::{PetscReport, RunReport};
pub use run::{equilibrium_tol, indenter_figures, terminal_groups, ContactResult, Indented, Solution, EQUILIBRIUM_TOL};
pub use scene::{
    BackendChoice, ComplianceSpec, ContactLaw, ContactSolver, ContactSpec, Contacts, DirichletSpec, ElectricCondition,
    ElectrodeSpec, Electrodes, ExactKind, ExactSpec, Factors, Grading, IndenterShape, IndenterSpec, LayerSpec,
    LoadSpec, Loads, MaterialModel, MaterialSpec, MeshKind, MeshSpec, PathSpec, RegionSpec, Rule, Scene, SceneError,
    SlipBoundProfile, SolverSpec, Strategy, Valid,
};
pub use scene::{Control, Friction, Obstacle, ZoneBound, ZoneElectric, ZoneModel, DEFAULT_FRAMES, TOL_RANGE};
pub use scene::{CrystalUnits, Datasheet, NamedCrystal, StressCharge, CRYSTALS};
pub use setup::cell_electric;
pub use shared_memory::SharedMemory;
pub use units::{LengthUnit, StressUnit, Units, UnitsSpec};

use contact::ContactError;

/// Solves `scene` on the default backend ([`SharedMemory`]). `mesh` is the mesh of a `gmsh` scene,
/// read by the caller (generated meshes are made here); `reporter` receives one event per
/// step and per outer iteration.
///
/// # Errors
/// A [`ProblemError`] naming the scene key, mesh item, material or solver step at fault.
pub fn solve(scene: &Scene, mesh: Option<mesh::Mesh>, reporter: &mut dyn Reporter) -> Result<Solution, ProblemError> {
    solve_within(scene, mesh, Limits::default(), reporter)
}

/// As [`solve`], within `limits`: a run whose memory estimate exceeds them stops with
/// [`ProblemError::TooLarge`] before the memory is taken.
///
/// # Errors
/// As [`solve`], and [`ProblemError::TooLarge`].
pub fn solve_within(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Solution, ProblemError> {
    // a path's instants are the run's too (each step's files unwritten: the last instant,
    // with the rows)
    let solution = path::run(&mut SharedMemory, scene, mesh, limits, reporter)?;
    Ok(solution.expect("the default backend runs in one process, which holds the solution"))
}

/// The capacitance matrix between `scene`'s terminals on the default backend ([`SharedMemory`]): one
/// factorisation, a unit potential per column, the charges as reactions (`mesh` the mesh of a
/// `gmsh` or `given` scene, read by the caller).
///
/// # Errors
/// The scene's and set-up's errors, as a run's; a scene without electric unknowns or without
/// a terminal (key `dirichlet`); a body its mechanical conditions do not hold.
pub fn capacitance(scene: &Scene, mesh: Option<mesh::Mesh>) -> Result<Capacitance, ProblemError> {
    let c = capacitance::capacitance(&mut SharedMemory, scene, mesh)?;
    Ok(c.expect("the default backend runs in one process, which holds the solution"))
}

/// Solves `scene`'s load path on the default backend ([`SharedMemory`]): the instants of
/// `scene.path` one after the other on one factorisation and one condensation, friction on
/// the slip increment; `each` is called once per instant, in order, with the instant's row
/// and contact solution, and, where `with_fields` asks for them, the fields of every
/// `path.output_every`-th instant (and of the last, which the returned solution holds).
/// Nothing of a step is kept after it but its row. A scene without a path is solved as the
/// one instant it describes, which [`solve`] gives.
///
/// # Errors
/// The errors of [`solve`], naming the step where one happened; `path` refused by the scene's
/// checks where the run cannot carry friction's history; the error `each` returns.
pub fn solve_path(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
    with_fields: bool,
    each: &mut dyn FnMut(Step<'_>) -> Result<(), ProblemError>,
) -> Result<PathSolution, ProblemError> {
    let last = path::walk(&mut SharedMemory, scene, mesh, limits, reporter, with_fields, each)?;
    Ok(PathSolution {
        last: last.expect("the default backend runs in one process, which holds the solution"),
    })
}

/// "the most extreme inputs are ..." naming the scene's numbers far from 1 (each key once), or
/// `None` where there are none.
/// The scene's conditioning factors above 1e3, in words (at most three), or its largest.
fn conditioning_in_words(scene: &Scene) -> String {
    let factors = scene.conditioning();
    let large: Vec<String> = factors
        .iter()
        .filter(|(_, v)| *v > 1e3)
        .take(3)
        .map(|(k, v)| format!("{k} is {v:.1e}"))
        .collect();
    match (large.is_empty(), factors.first()) {
        (false, _) => format!(
            "its largest conditioning factors: {} (about 1 is well posed; each decade of them costs one of the 16 digits of a double)",
            large.join(", ")
        ),
        (true, Some((k, v))) => format!("no input makes it so ({k}, the largest factor, is {v:.1e}): the mesh's cells may be degenerate"),
        (true, None) => "no input makes it so: the mesh's cells may be degenerate".into(),
    }
}

impl ProblemError {
    /// A factorisation's error on `scene`: where the scene's conditioning factors are large, an
    /// [`ProblemError::IllConditioned`] that names them; else the error itself (a body left free,
    /// whose message says so).
    pub fn linear(e: linalg::LinalgError, scene: &Scene) -> Self {
        let inner = match &e {
            linalg::LinalgError::In { source, .. } => source.as_ref(),
            other => other,
        };
        let breakdown = matches!(
            inner,
            linalg::LinalgError::NotPositiveDefinite { .. }
                | linalg::LinalgError::ZeroPivot { .. }
                | linalg::LinalgError::NearlySingular { .. }
        );
        let large = scene.conditioning().first().is_some_and(|(_, v)| *v > 1e6);
        if breakdown && large {
            ProblemError::IllConditioned {
                what: format!("linear solve: {e}"),
                factors: conditioning_in_words(scene),
            }
        } else {
            ProblemError::Linalg(e)
        }
    }

    /// The error, with a linear solver's breakdown made [`ProblemError::IllConditioned`] where
    /// the scene is ([`ProblemError::linear`]).
    pub fn on_scene(self, scene: &Scene) -> Self {
        match self {
            ProblemError::Linalg(e) => ProblemError::linear(e, scene),
            other => other,
        }
    }

    /// A run whose residual `what` (`value`) is above its tolerance `tol` after refinement.
    pub fn inaccurate(what: &str, value: f64, tol: f64, scene: &Scene) -> Self {
        ProblemError::IllConditioned {
            what: format!("the {what} {value:.2e} is above its tolerance {tol:e} after iterative refinement"),
            factors: conditioning_in_words(scene),
        }
    }
}

fn extremes(scene: &Scene) -> Option<String> {
    let mut named: Vec<String> = vec![];
    for (k, v) in scene.extreme_numbers() {
        let item = format!("{k} = {v:e}");
        if !named.contains(&item) && named.len() < 3 {
            named.push(item);
        }
    }
    (!named.is_empty()).then(|| {
        format!(
            "the most extreme inputs are {} (bring them nearer 1, e.g. by a change of units)",
            named.join(", ")
        )
    })
}

/// The README's Rust examples, run as doc tests (the library consumer's example among them).
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// A valid scene whose data do not fit its mesh, found while setting it up: the key at fault
/// (dotted, as `--set` takes it) and what is wrong (a group or region the mesh lacks or leaves
/// empty, a normal the contact face does not have, an indenter that reaches no node, a
/// terminal a capacitance needs). The scene's own values are [`SceneError`]s, raised by
/// [`Scene::validate`] only.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct SetupError {
    /// The key at fault, e.g. `contact.normal`.
    pub key: String,
    /// What is wrong, naming the key.
    pub message: String,
}

impl SetupError {
    /// An error on `key`.
    pub fn new(key: &str, message: impl Into<String>) -> Self {
        SetupError {
            key: key.into(),
            message: message.into(),
        }
    }
}

/// What can go wrong in a run; each variant names the input or the step at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProblemError {
    /// A scene value that cannot be used (named by its key): raised by the scene's
    /// validation only.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A valid scene whose data do not fit its mesh, found while setting it up (named by the
    /// key at fault).
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The caller's callback stopped the run (a path's `each`): its message.
    #[error("stopped by the caller: {0}")]
    Stopped(String),
    /// A valid scene the backend does not solve (another backend may).
    #[error(transparent)]
    Unsupported(#[from] backend::Unsupported),
    /// No solution found for one more unknown of the scene (an indenter's depth under force
    /// control, a floating tip's potential): what was sought, by its key, and why not.
    #[error("{sought}: {why}")]
    NoSolution {
        /// The key of what was sought.
        sought: &'static str,
        /// Why it was not found.
        why: String,
    },
    /// A mesh problem (a missing group, a bad cell).
    #[error("mesh: {0}")]
    Mesh(#[from] mesh::MeshError),
    /// An assembly problem (materials, conditions, groups).
    #[error("setup: {0}")]
    Assembly(#[from] fe_assembly::AssemblyError),
    /// A material that cannot be used.
    #[error("material: {0}")]
    Material(#[from] fe_assembly::MaterialError),
    /// A linear-algebra failure.
    #[error("linear solve: {0}")]
    Linalg(#[from] linalg::LinalgError),
    /// A solve that double precision cannot make accurate: a factorisation that broke down, or
    /// residuals above their tolerances after iterative refinement, on a scene whose
    /// conditioning factors ([`Scene::conditioning`]) are large; the message names them.
    #[error("{what}: the coupled system is too ill-conditioned for double precision; {factors}")]
    IllConditioned {
        /// What failed (the linear solver's error, or the residual above its tolerance).
        what: String,
        /// The scene's largest conditioning factors, in words.
        factors: String,
    },
    /// A run that would need more memory than it may use, found before the memory is taken.
    #[error("the run needs about {} ({what}), more than the {} that {limit} leaves: use a coarser mesh (a smaller mesh.n or a larger mesh.h)", estimate::Bytes(*needed as f64), estimate::Bytes(*available as f64))]
    TooLarge {
        /// What the estimate counts.
        what: String,
        /// Bytes needed (an estimate).
        needed: u64,
        /// Bytes available.
        available: u64,
        /// What limits them (the machine's available memory, an address-space limit, a
        /// memory cgroup).
        limit: &'static str,
    },
    /// A result that is not a finite number: the data overflow (or underflow) double
    /// precision, or the problem is singular.
    #[error("{what} is not finite: {cause}")]
    NotFinite {
        /// The result.
        what: &'static str,
        /// The inputs that most likely overflowed, or what else it may be.
        cause: String,
    },
    /// The run was stopped from outside (its [`Limits::interrupt`]) between two steps; a stop
    /// within the contact solve is a [`ProblemError::Contact`] with
    /// [`ContactError::Interrupted`].
    #[error("interrupted after {after} ({why})")]
    Interrupted {
        /// The last step done.
        after: &'static str,
        /// A deadline or the cancel flag.
        why: contact::Interruption,
    },
    /// A step of a load path failed: the step, its instant, and the error.
    #[error("path step {step} (t = {t}): {source}")]
    AtStep {
        /// The step (0 for the path's first instant).
        step: usize,
        /// Its instant.
        t: f64,
        /// What failed.
        source: Box<ProblemError>,
    },
    /// The contact solve failed (with its last residual), and what else to try.
    #[error("contact: {source}{hint}")]
    Contact {
        /// The contact solver's error.
        source: ContactError,
        /// What to try that the run did not (empty when nothing is known to help).
        hint: String,
    },
}

impl ProblemError {
    /// Whether the run was stopped from outside (its deadline, or its cancel flag), between
    /// steps or within the contact solve.
    pub fn is_interrupted(&self) -> bool {
        if let ProblemError::AtStep { source, .. } = self {
            return source.is_interrupted();
        }
        matches!(
            self,
            ProblemError::Interrupted { .. }
                | ProblemError::Contact {
                    source: ContactError::Interrupted { .. },
                    ..
                }
        )
    }

    /// This error at step `step` (instant `t`) of a load path.
    pub fn at_step(self, step: usize, t: f64) -> ProblemError {
        ProblemError::AtStep {
            step,
            t,
            source: Box::new(self),
        }
    }

    /// `Ok` when every value is finite, else [`ProblemError::NotFinite`] naming `what` and the
    /// scene's most extreme numbers.
    pub fn check_finite(values: &[f64], what: &'static str, scene: &Scene) -> Result<(), ProblemError> {
        if values.iter().all(|v| v.is_finite()) {
            return Ok(());
        }
        let cause = match extremes(scene) {
            Some(named) => format!("the data overflow double precision; {named}"),
            None => {
                "no input is extreme (all within 1e-100 to 1e100 in magnitude): the problem may be singular".to_string()
            }
        };
        Err(ProblemError::NotFinite { what, cause })
    }

    /// A contact error of a run of `strategy` on `scene`, with a hint that names only what it
    /// did not try, or, where its residual is not a number, the scene's most extreme inputs.
    pub fn contact(source: ContactError, strategy: Strategy, scene: &Scene) -> Self {
        let residual = source.residual().unwrap_or(0.0);
        if !residual.is_finite() {
            if let Some(named) = extremes(scene) {
                return ProblemError::Contact {
                    source,
                    hint: format!("; the data overflow double precision: {named}"),
                };
            }
        }
        let newton = strategy == Strategy::NewtonCondensed;
        let electric = scene.zones().iter().find_map(|c| c.electric_law()).map(|(law, _)| law);
        let hint = match (&source, electric) {
            (ContactError::Stalled { .. }, Some(contact::ElectricLaw::Conducting)) => {
                "; semismooth Newton and its proximal stage stalled on the coupled rows (electrical contact has no first-order stage): an ideally conducting foundation whose potential lifts the body off where it touches may have no solution (contact gives the potential that lifts, lift-off takes it away); contact.electric = \"conductive\" with a finite contact.conductance is the regularised law, solved there"
            }
            (ContactError::Stalled { .. }, Some(_)) => {
                "; semismooth Newton and its proximal stage stalled on the coupled rows (electrical contact has no first-order stage): a looser solver.tol, or a smaller contact.conductance (the papers' existence needs it small), may be reached"
            }
            _ => "",
        };
        let hint = if !hint.is_empty() {
            hint
        } else {
            match &source {
            ContactError::FixedPointNoConvergence { .. } if !newton => {
                "; try solver.strategy=newton-condensed, which solves Coulomb's law directly (no fixed point on S)"
            }
            ContactError::NoConvergence { .. }
            | ContactError::TooSlow { .. }
            | ContactError::Diverged { .. }
            | ContactError::Stalled { .. }
                if !newton =>
            {
                "; try solver.strategy=newton-condensed (semismooth Newton), or a looser solver.tol"
            }
            ContactError::NoConvergence { .. }
            | ContactError::FixedPointNoConvergence { .. }
            | ContactError::Diverged { .. }
            | ContactError::Stalled { .. } => {
                "; semismooth Newton, its proximal stage and its last stage (block Gauss-Seidel for Coulomb's law) all stalled: a looser solver.tol may be reached"
            }
            ContactError::NotUnique { .. } => {
                "; a smaller contact.friction or material.coupling_scale brings the problem back within the uniqueness theory"
            }
            _ => "",
            }
        };
        ProblemError::Contact {
            source,
            hint: hint.into(),
        }
    }
}
