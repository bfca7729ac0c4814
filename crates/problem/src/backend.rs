//! What differs between the backends that solve a scene, as one trait: the run
//! (the crate's `run`) sets up, discretises, builds the contact boundary, checks, recovers and
//! reports once; a [`Backend`] assembles the system, prepares it (factors it, or configures
//! its Krylov solvers), solves the linear or the contact problem on it, measures its
//! equilibrium residual, and hands the free unknowns back.
//!
//! Two backends implement it: [`SharedMemory`](crate::SharedMemory) (this crate's default: faer's sparse factorisations on
//! one machine, the condensed contact problem and its semismooth Newton) and the `distributed`
//! crate's PETSc backend (Krylov solves with algebraic multigrid on the ranks of an MPI run).
//! The run knows neither by name.

use crate::progress::Reporter;
use crate::report::PetscReport;
use crate::scene::{ContactSolver, Scene, Valid};
use crate::ProblemError;
use contact::{ContactPoints, ContactSolution, Law, PointValues};
use fe_assembly::Discretization;
use linalg::CondenseRoute;

pub use crate::boundary::{ContactBoundary, MAX_NORMAL_ANGLE_DEG};
pub use crate::outer::ForceControl;
pub use crate::plan::Plan;
pub use crate::setup::{
    electrode_without_facets, piece_refusal, region_without_cells, setup, setup_piece, x_extent, MeshNotes,
    NarrowedElectrode, Setup,
};

/// A scene a backend does not solve: the backend, the scene key that asks for what it lacks,
/// and what that is. Raised by [`Backend::supports`] before anything is built; the scene is
/// valid (another backend may solve it).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{key}: {feature}; the {backend} backend does not solve it{}", advice.as_deref().map_or(String::new(), |a| format!(" ({a})")))]
pub struct Unsupported {
    /// The backend's name, as `solver.backend` takes it.
    pub backend: &'static str,
    /// The scene key that asks for it, dotted as `--set` takes it.
    pub key: String,
    /// What the scene asks for, in words.
    pub feature: String,
    /// What to do instead, where there is a way.
    pub advice: Option<String>,
}

impl Unsupported {
    /// `backend` does not solve `feature`, asked for by `key`.
    pub fn new(backend: &'static str, key: &str, feature: impl Into<String>) -> Self {
        Unsupported {
            backend,
            key: key.into(),
            feature: feature.into(),
            advice: None,
        }
    }

    /// With what to do instead.
    pub fn advise(mut self, advice: impl Into<String>) -> Self {
        self.advice = Some(advice.into());
        self
    }
}

/// What a run may use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Limits {
    /// Bytes of memory the run may take (`None`: no check).
    pub memory_bytes: Option<u64>,
    /// What sets `memory_bytes`, in words (for the message of a run too large): the
    /// machine's available memory, an address-space limit, a memory cgroup.
    pub memory_limit: Option<&'static str>,
    /// A deadline or a cancel flag for the contact solve (a typed
    /// [`contact::ContactError::Interrupted`], with the best iterate, when it fires).
    pub interrupt: contact::Interrupt,
}

impl Limits {
    /// What limits the memory, in words.
    pub(crate) fn limit(&self) -> &'static str {
        self.memory_limit.unwrap_or("the memory available")
    }
}

/// A backend: how the discrete problem of a run is assembled and solved. The run (the
/// crate's `run`) calls [`supports`](Backend::supports), [`estimate`](Backend::estimate),
/// [`assemble`](Backend::assemble) and [`prepare`](Backend::prepare) once, then
/// [`begin`](Backend::begin) once, then for each instant of its path (a static scene is a
/// path of one instant) [`prime`](Backend::prime) and [`solve_posed`](Backend::solve_posed)
/// (more than once where an outer unknown is sought around the contact solve: force
/// control's depth, a compliant bed's springs) and, at the instants whose fields it needs,
/// [`instant_fields`](Backend::instant_fields); then [`finish`](Backend::finish). A backend
/// whose steps are collective (MPI) makes them collective on every rank; only
/// [`instant_fields`](Backend::instant_fields) may return `None` (a rank that does not hold
/// the gathered fields).
pub trait Backend {
    /// The backend's name, as `solver.backend` spells it (for its refusals).
    const NAME: &'static str;

    /// The assembled system, before it is prepared.
    type Assembled;
    /// The system ready to be solved (factored, or its solvers configured), with what the
    /// run's instants keep on it.
    type System;
    /// The backend's error: the problem's errors and its own.
    type Error: From<ProblemError>;

    /// Whether the backend's solution is held to the tight rule's tolerances (the run fails,
    /// naming the ill-conditioned inputs, where it misses them): a direct backend refines to
    /// round-off and is; a Krylov backend's accuracy is its solver's tolerance, and its report
    /// says whether it met them.
    const HELD_TO_TOLERANCE: bool;

    /// How many points left out of a static run's narrowed contact problem would touch
    /// (`crate::reach`), known to every process: `found` is what the process that holds the
    /// last instant's fields counted (`None` where none would, and on the processes that do not
    /// hold them). A backend on one process returns it; one on several sends the holder's to
    /// every process, so that all of them do the run again with every point, or none.
    ///
    /// # Errors
    /// The backend's own (its communication).
    fn agree_beyond(&mut self, found: Option<usize>) -> Result<Option<usize>, Self::Error> {
        Ok(found)
    }

    /// Whether this backend solves the (valid) scene: its `solver.backend`, and every law,
    /// condition and process it asks for. Called before anything is built. What a backend
    /// lacks lives here, not in the scene's validation, which knows no backend.
    ///
    /// # Errors
    /// [`Unsupported`], naming the key.
    fn supports(&self, scene: &Scene) -> Result<(), Unsupported>;

    /// The lower estimate of the run's peak memory in bytes (per process), with what it
    /// counts, before the mesh is made; `None` where it cannot be told (a mesh read from a
    /// file, whose size the run checks once read).
    fn estimate(&self, scene: &Scene) -> Option<(f64, String)>;

    /// The same estimate once the mesh is made or read (its nodes and cells known), for a
    /// body with potentials where `electric`: the run checks it before it builds anything on
    /// the mesh.
    fn estimate_on_mesh(&self, scene: &Scene, mesh: &mesh::Mesh, electric: bool) -> Option<(f64, String)>;

    /// Assembles the system of `posed` (its loads the first instant's).
    ///
    /// # Errors
    /// Numbers that overflowed, the backend's own.
    fn assemble(&mut self, posed: &Posed<'_>) -> Result<Self::Assembled, Self::Error>;

    /// Prepares the assembled system for the solves: where the plan has contact, `boundary`
    /// is its contact boundary (a direct backend orders its dofs last), within `limits`.
    ///
    /// # Errors
    /// A factor too large for `limits`, a factorisation that broke down, the backend's own.
    fn prepare(
        &mut self,
        posed: &Posed<'_>,
        assembled: Self::Assembled,
        boundary: Option<&ContactBoundary>,
        limits: Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<Self::System, Self::Error>;

    /// Begins the run's instants on the prepared `system`: where the run has contact, what
    /// its contact solves keep from instant to instant (the default backend: the contact
    /// problem condensed for the loads of `posed`, the first instant's); and the fields
    /// `K⁻¹ b_q` of each part `q` of a path's right-hand side (`parts`: the loads, each
    /// displacement component's lifting, the potentials' lifting; a path's later instants are
    /// sums of them), in their order. A run of one instant gives no parts.
    ///
    /// # Errors
    /// A solve that failed; a system the backend cannot walk a path on.
    fn begin(
        &mut self,
        system: &mut Self::System,
        posed: &Posed<'_>,
        contact: Option<Contact<'_>>,
        parts: &[Fields],
        reporter: &mut dyn Reporter,
    ) -> Result<Vec<Fields>, Self::Error>;

    /// `K⁻¹ [a_u; a_φ]` for each functional `(a_u, a_φ)` of `a` (their responses), in their
    /// order.
    ///
    /// # Errors
    /// A solve that failed.
    fn respond(&mut self, system: &mut Self::System, a: &[(&[f64], &[f64])]) -> Result<Vec<Fields>, Self::Error>;

    /// Poses an instant's contact problem: its data (`primed.posed`'s loads and prescribed
    /// values; on a path, the parts' `factors`), on its boundary in its frame (the instant
    /// before's tangential displacement), with the point forces of the multipliers `springs`
    /// among its loads (zeros but where only a compliant bed holds the body).
    ///
    /// # Errors
    /// A solve that failed; the backend's own.
    fn prime(&mut self, system: &mut Self::System, primed: Primed<'_>) -> Result<(), Self::Error>;

    /// The contact solve of the posed instant `at` its points, warm start and rule; its
    /// displacements in the instant's frame.
    ///
    /// # Errors
    /// A contact solve that did not converge.
    fn solve_posed(
        &mut self,
        system: &mut Self::System,
        how: &ContactSolve<'_>,
        at: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<ContactSolution, Self::Error>;

    /// The largest displacement of the contact dofs that a path's instant's own data make at
    /// `factors`: the scale of its answer (0 where the backend keeps no parts).
    fn own_scale(&self, system: &Self::System, factors: &[f64]) -> f64;

    /// The fields of the posed instant: under its loads alone (no contact), or under the
    /// contact forces of the contact solve `sol` (in its frame), refined, the law judged on
    /// them; with their equilibrium residual `‖K x - b - f_c‖ / max(‖b‖, ‖f_c‖)`. `None` on a
    /// process that does not hold the gathered fields.
    ///
    /// # Errors
    /// A solve that failed.
    fn instant_fields(
        &mut self,
        system: &mut Self::System,
        posed: &Posed<'_>,
        contact: Option<InstantOf<'_>>,
        reporter: &mut dyn Reporter,
    ) -> Result<Option<InstantSolution>, Self::Error>;

    /// Whether [`Backend::frames_fields`] computes a path's written instants' fields after the
    /// path has gone on from them (from their loads and multipliers alone); where not, the
    /// fields of each written instant are computed at the instant.
    fn defers_fields(&self, system: &Self::System) -> bool;

    /// The fields of several of a path's instants at once, in their order, each under its loads
    /// and the contact forces of its solve (in its frame), refined, with its equilibrium
    /// residual; no instant's contact solve changed (the path has gone on from it), its law
    /// judged on the condensed problem as the instants whose fields are not computed. A
    /// factorisation solves them together (one pair of sweeps for all). `None` for each on a
    /// process that does not hold the gathered fields.
    ///
    /// # Errors
    /// A solve that failed.
    fn frames_fields(
        &mut self,
        system: &mut Self::System,
        frames: Vec<(Posed<'_>, InstantOf<'_>)>,
        reporter: &mut dyn Reporter,
    ) -> Result<Vec<Option<InstantSolution>>, Self::Error>;

    /// What the backend measured, for the report; the system dropped (its memory freed
    /// before the last instant's recovery).
    ///
    /// # Errors
    /// The backend's own.
    fn finish(&mut self, system: Self::System) -> Result<Figures, Self::Error>;

    /// `e`, naming the path's step `k` at instant `t` where it happened.
    fn at_step(e: Self::Error, k: usize, t: f64) -> Self::Error {
        let _ = (k, t);
        e
    }
}

pub use crate::factorization::Fields;

/// The contact problem of a run's instants ([`Backend::begin`]): its boundary at the first
/// instant's data, and how it is solved.
#[derive(Clone, Copy)]
pub struct Contact<'a> {
    /// The contact boundary.
    pub boundary: &'a ContactBoundary,
    /// The law, the tolerance, the interrupt.
    pub how: &'a ContactSolve<'a>,
}

/// An instant posed for its contact solves ([`Backend::prime`]).
#[derive(Clone, Copy)]
pub struct Primed<'a> {
    /// The discrete problem with the instant's loads and prescribed values.
    pub posed: &'a Posed<'a>,
    /// The boundary at the instant, in the frame of the instant before.
    pub framed: Framed<'a>,
    /// A path's instant: the parts' factors, in their order ([`Backend::begin`]); `None` for
    /// the one instant of a static run, whose loads the run began with.
    pub factors: Option<&'a [f64]>,
    /// The multipliers of the springs that hold a body only its compliant bed holds (zeros
    /// otherwise), whose point forces are among the instant's loads.
    pub springs: &'a PointValues,
}

/// Where an instant's contact solve starts ([`Backend::solve_posed`]).
pub struct At<'a> {
    /// The points (their gaps an indenter's depth's under force control).
    pub points: &'a ContactPoints,
    /// The warm start.
    pub start: Option<PointValues>,
    /// Whether Newton steps from a start that already meets the tolerance (force control's
    /// depths: the force must be the depth's own).
    pub refine_start: bool,
}

/// The contact of an instant whose fields are computed ([`Backend::instant_fields`]): its
/// contact solve, its boundary in its frame, the solution found.
pub struct InstantOf<'a> {
    /// The contact solve.
    pub how: &'a ContactSolve<'a>,
    /// The boundary at the instant, in the frame of the instant before.
    pub framed: Framed<'a>,
    /// The contact solution found ([`Backend::solve_posed`]).
    pub sol: ContactSolution,
}

/// An instant's contact boundary (its gaps and prescribed values at the instant's factors)
/// and the frame its contact problem is posed in: the tangential displacements of the
/// instant before.
#[derive(Clone, Copy)]
pub struct Framed<'a> {
    /// The boundary at the instant.
    pub boundary: &'a ContactBoundary,
    /// The instant before's tangential displacements.
    pub shift: &'a PointValues,
}

/// The discrete problem a backend solves: the validated scene, its set-up, the discretisation
/// (dof map, cells) and the loads on the free dofs.
pub struct Posed<'a> {
    /// The scene, validated.
    pub scene: Valid<'a>,
    /// Its mesh, materials, plan, conditions.
    pub setup: &'a Setup,
    /// The discretisation on the mesh.
    pub disc: &'a Discretization<'a>,
    /// The loads on the free dofs, checked finite.
    pub loads: Loads,
    /// The springs that hold a body only its compliant bed holds, which the backend assembles
    /// into `K` along the bed's normal ([`ContactBoundary::normal_springs`]) and the run takes
    /// out again by a fixed point on the loads; `None` where the Dirichlet conditions hold the
    /// body.
    pub bed: Option<Bed>,
}

/// The springs that hold a body only its compliant bed holds (the Dirichlet conditions leave
/// a motion free that the bed holds along its normal): `k_s w_i n_i n_iᵀ` at each bed point,
/// assembled into `K` by the backend; the run takes them out again by a fixed point on the
/// loads, `(K + S) u_{j+1} + contact = b + S u_j` (docs/theory.md, "A body only its bed
/// holds").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bed {
    /// `k_s`: the springs' stiffness, pressure per unit normal displacement.
    pub stiffness: f64,
    /// The bed's tangent stiffness at the loads' mean pressure (the same units).
    pub tangent: f64,
    /// The body's own stiffness at the bed, `c / h` (the same units).
    pub body: f64,
}

impl Posed<'_> {
    /// The plan of the run.
    pub fn plan(&self) -> &Plan {
        &self.setup.plan
    }
}

/// The loads on the free dofs: `b_u` on the displacements, `b_φ` on the potentials.
#[derive(Clone, Default)]
pub struct Loads {
    /// On the free displacements.
    pub b_u: Vec<f64>,
    /// On the free potentials.
    pub b_phi: Vec<f64>,
    /// The factors of a path's parts that these loads sum, in the backend's order of the
    /// parts (the loads, each displacement component's lifting, the potentials'); `None`
    /// where the loads are no such sum (a static scene's).
    pub factors: Option<Vec<f64>>,
}

/// The fields of an instant ([`Backend::instant_fields`]).
pub struct InstantSolution {
    /// The free unknowns `(u, φ)`.
    pub x: Fields,
    /// The contact solution, as the fields judged it (its complementarity residual the final
    /// fields'), where the instant has contact.
    pub contact: Option<ContactSolution>,
    /// The equilibrium residual of the fields.
    pub equilibrium: f64,
    /// PCG iterations (the Schur-complement strategy; 0 elsewhere).
    pub pcg_iters: usize,
}

/// What a backend measured, for the run's report.
#[derive(Clone, Debug, Default)]
pub struct Figures {
    /// Wall time of the factorisation, or of the preconditioners' set-up, s.
    pub factor_seconds: f64,
    /// The numeric factorisation's floating-point operations and wall time (s), where the
    /// factorisation counts them (the tree's `L D Lᵀ`).
    pub factor_rate: Option<(f64, f64)>,
    /// How the contact compliance was formed, and in how long (condensed strategies).
    pub condense: Option<(CondenseRoute, f64)>,
    /// The PCG's relative tolerance (0 where none ran).
    pub pcg_rel_tol: f64,
    /// The smallest `|pivot| / |diagonal entry|` of an `L D Lᵀ`.
    pub smallest_pivot_ratio: Option<f64>,
    /// Steps of iterative refinement of the last solve.
    pub refinement_steps: usize,
    /// Bytes of the factors' values.
    pub factor_bytes: usize,
    /// The PETSc backend's section of the report.
    pub petsc: Option<PetscReport>,
}

/// How the plan's contact problem is solved: the law on its points, the tolerance, the
/// interrupt.
pub struct ContactSolve<'p> {
    /// The plan.
    pub plan: &'p Plan,
    /// The scene (for the messages of its errors).
    pub scene: &'p Scene,
    /// The law on the points: frictionless, Tresca's bound per point, or Coulomb.
    pub law: Law,
    /// The complementarity tolerance (`solver.tol`).
    pub tol: f64,
    /// A deadline or a cancel flag.
    pub interrupt: contact::Interrupt,
    /// What Newton's solves of the run's one condensed compliance share (a solve's
    /// corrections, a load path's steps): the factorisation of `D` for the directions, the
    /// estimate of `μ_max`.
    pub cache: std::cell::RefCell<contact::NewtonCache>,
}

impl<'p> ContactSolve<'p> {
    /// The points with the coefficients the law gives at the slips of `sol` (slip
    /// weakening), or as they are.
    pub fn points_at<'a>(
        &self,
        points: &'a contact::ContactPoints,
        sol: &ContactSolution,
    ) -> std::borrow::Cow<'a, contact::ContactPoints> {
        if points.weakens() {
            std::borrow::Cow::Owned(points.at_slips(&sol.u))
        } else {
            std::borrow::Cow::Borrowed(points)
        }
    }

    /// The plan's contact law on `boundary`'s points: frictionless without tangential
    /// multipliers, Tresca with each zone's bound at each of its points, else Coulomb.
    pub fn new(plan: &'p Plan, scene: &'p Scene, boundary: &ContactBoundary, interrupt: contact::Interrupt) -> Self {
        let law = plan.law(&boundary.points, &boundary.group_of);
        // the first-order solvers meet Coulomb's law by the fixed point on S, Newton directly
        debug_assert_eq!(
            plan.fixed_point,
            law == Law::Coulomb && matches!(plan.linear_strategy.contact_solver(), ContactSolver::FirstOrder { .. })
        );
        ContactSolve {
            plan,
            scene,
            law,
            tol: plan.tol,
            interrupt,
            cache: Default::default(),
        }
    }
}

/// A generated mesh's sizes before it is made: `(dimension, nodes, cells, unknowns)`, with
/// displacements at every node and a potential where the scene has a piezoelectric or
/// dielectric body; `None` for a Gmsh mesh. For a backend's memory estimate.
pub fn generated_sizes(scene: &Scene) -> Option<(usize, f64, f64, f64)> {
    crate::estimate::generated(scene)
}
