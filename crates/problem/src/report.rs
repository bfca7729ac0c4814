//! The report of a run as a typed value ([`RunReport`]): what `run.json` holds, field for
//! field (serde writes it; the application writes the file). Its sections are the ones
//! the README lists: the scene, the plan, sizes, contact counts and forces, iterations,
//! residuals, timings, memory, and the solver's own parameters.

use crate::exact::ExactReport;
pub use crate::exact::HalfSpaceReport;
use crate::plan::Plan;
use crate::scene::{Rule, Scene, Strategy};
use serde::{Deserialize, Serialize};

/// The report of one run (`run.json`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RunReport {
    /// The scene as run.
    pub scene: SceneReport,
    /// What the run computed.
    pub plan: Plan,
    /// Mesh sizes.
    pub mesh: MeshReport,
    /// Free unknowns, after Dirichlet elimination.
    pub dofs: DofsReport,
    /// The contact boundary's counts and resultant forces (zeros without contact).
    pub contact: ContactReport,
    /// The error against the scene's exact solution, where it has one.
    pub exact: Option<ExactReport>,
    /// Iteration counts (0 where a loop is not in the plan; a load path's, its steps' summed).
    pub iterations: Iterations,
    /// Scale-free residuals of the final state.
    pub residuals: Residuals,
    /// Wall times of the steps, s.
    pub timings_s: Timings,
    /// Memory.
    pub memory: Memory,
    /// The solver's parameters.
    pub solver: SolverReport,
    /// What the PETSc backend did (absent from runs of the default backend).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub petsc: Option<PetscReport>,
    /// A load path's figures (absent from a run of one instant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathReport>,
    /// The terminals: the boundary groups where the potential is prescribed (the electrodes,
    /// grounded sides) or floats (`dirichlet.charge`, `electrode.charge`), each with its
    /// potential and the charge through it (absent without electric unknowns).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub terminals: Vec<TerminalReport>,
    /// A rigid indenter's figures (absent without `contact.indenter`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indenter: Option<IndenterReport>,
    /// The unit of every reported quantity, from the scene's system.
    #[serde(default)]
    pub units: crate::Units,
}

/// A rigid indenter's figures (`run.json`'s `indenter`), in the scene's units (a body of
/// revolution's force is the whole body's).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct IndenterReport {
    /// The shape.
    pub shape: String,
    /// How far its tip is pushed along `-n` (`contact.indenter.depth`, less `contact.gap`).
    pub depth: f64,
    /// The total normal force the body carries from it.
    pub force: f64,
    /// The largest distance from its axis of a contact point that carries pressure (0 where
    /// none does): the contact zone's radius, to the mesh's resolution.
    pub contact_radius: f64,
    /// The distance from the axis of the nearest point beyond `contact_radius` that carries
    /// no pressure: the zone's edge lies between the two, the mesh's resolution there (a zone
    /// within the first cell reads `contact_radius` 0 and this the first cell's size); absent
    /// where no point beyond carries none (the zone reaches the face's edge).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_radius_next: Option<f64>,
    /// Contact points carrying pressure.
    pub points_in_contact: usize,
    /// A conducting indenter (`contact.electric = "conducting"` or `"conductive"`): its
    /// potential (`contact.foundation_potential`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub potential: Option<f64>,
    /// A conducting indenter: the charge it carries, the negative of the flux `Σ w D·ν`
    /// through the contact zone out of the body (the charge on the conductor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
    /// With electric unknowns: the surface's potential at the contact point nearest the
    /// indenter's axis (under an insulating tip, the potential the pressure induces there).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_potential: Option<f64>,
    /// On a body of revolution under a frictionless axisymmetric indenter (one isotropic or
    /// 6mm material poled along the axis, an insulating or conducting tip): the closed form
    /// of a half-space of the same material at the same depth (force control: the same
    /// force), and the run's errors against it (`problem::HalfSpace`; a finite body differs
    /// by its size effect).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_space: Option<HalfSpaceReport>,
    /// Where the half-space's closed form applies to the scene but not to this run's data
    /// (nothing touches; dimensions double precision does not resolve): why it is absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_space_absent: Option<String>,
}

/// A boundary group at a prescribed potential (`run.json`'s `terminals`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct TerminalReport {
    /// The boundary group (`electrode` for the scene's `[electrode]`).
    pub group: String,
    /// Its potential (at its first node, where the prescribed value varies).
    pub potential: f64,
    /// The charge on it, `-∫ D·ν ds` (`ν` out of the body): the charge on the conductor, the
    /// program's one convention (a floating terminal's reads back its `charge`; the charges
    /// of all terminals and contact conductors sum to 0 where they enclose every flux), as the
    /// electric equation's reaction at its nodes.
    pub charge: f64,
    /// A floating terminal (`dirichlet.charge`): its potential found, its charge given.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub floating: bool,
    /// An electrode given by `x_range`: the x extent its facets cover (those of its group wholly
    /// inside the range: less than the range where the mesh has no node at its ends).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covered_x: Option<[f64; 2]>,
}

/// A load path's figures (`run.json`'s `path`): its steps, one row each, and what was reused.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PathReport {
    /// Instants solved (`t[0]` and the steps after it).
    pub instants: usize,
    /// Factorisations of `K` over the whole path (1: the matrix does not change).
    pub factorisations: usize,
    /// Condensations of `K` onto the contact dofs over the whole path.
    pub condensations: usize,
    /// Wall time of the steps after the factorisation and condensation, s.
    pub steps_s: f64,
    /// One row per instant.
    pub rows: Vec<StepRow>,
}

/// One instant of a load path (a row of `path.csv`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct StepRow {
    /// The step (0 for `t[0]`).
    pub step: usize,
    /// The instant.
    pub t: f64,
    /// The factors at `t`: load, voltage, displacement x, y, z, gap.
    pub factors: [f64; 6],
    /// The total normal contact force (the pressures integrated).
    pub normal_force: f64,
    /// The magnitude of the total tangential contact force, `|Σ w λ_t t|` (as run.json's
    /// `contact.tangential_force`).
    pub tangential_force: f64,
    /// The total tangential contact force as a vector, `Σ w λ_t t` in the global frame (one
    /// component per dimension): a friction loop plots its component along the drive.
    #[serde(default)]
    pub tangential_resultant: Vec<f64>,
    /// Several contact groups (`[[contact]]`): each one's counts and forces at the step.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<ContactGroupReport>,
    /// The largest tangential displacement of a point in contact (the slip from rest).
    pub max_slip: f64,
    /// The largest slip of a point in contact in this step (the increment's).
    pub max_slip_increment: f64,
    /// Points that stick, slip, are separated.
    pub n_stick: usize,
    /// Points that slip.
    pub n_slip: usize,
    /// Points separated.
    pub n_separated: usize,
    /// Newton (or first-order) iterations of the step.
    pub iterations: usize,
    /// A rigid indenter's depth at the step (under force control: the depth found).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<f64>,
    /// A rigid indenter's contact radius at the step (the farthest pressed point from its
    /// axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_radius: Option<f64>,
    /// A conducting indenter's charge at the step (the charge on it across its zone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_charge: Option<f64>,
    /// The half-space's closed form at the step, where it applies to the scene (a frictionless
    /// axisymmetric indenter on a body of revolution): its force at the step's depth (under
    /// force control, its depth at the step's force: `half_space_depth`), contact radius and
    /// a conducting tip's charge.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_space: Option<HalfSpaceRow>,
    /// The charge on each terminal (the charge on the conductor), in the order of
    /// [`RunReport::terminals`].
    #[serde(default)]
    pub charges: Vec<f64>,
    /// The potential of each terminal, in the order of [`RunReport::terminals`] (a floating
    /// terminal's found, a prescribed one's scaled by the voltage factor).
    #[serde(default)]
    pub potentials: Vec<f64>,
    /// The complementarity residual of the step.
    pub complementarity: f64,
    /// The equilibrium residual of the step, where its fields were computed (the instants
    /// whose files are written, and the last).
    pub equilibrium: Option<f64>,
}

/// The half-space's closed form at a step of a path ([`StepRow::half_space`]).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct HalfSpaceRow {
    /// Its depth (the step's under depth control).
    pub depth: f64,
    /// Its force (the step's under force control).
    pub force: f64,
    /// Its contact radius.
    pub contact_radius: f64,
    /// A conducting tip's charge.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
}

impl SceneReport {
    /// The scene as run (its source is the scene's name until the application, which read
    /// it, says where it came from).
    pub fn of(scene: &Scene) -> Self {
        SceneReport {
            name: scene.name.clone(),
            source: scene.name.clone(),
            description: scene.description.clone(),
            settings: scene.clone(),
        }
    }
}

impl MeshReport {
    /// The sizes of the set-up's mesh, and what its checks noted.
    pub fn of(scene: &Scene, setup: &crate::setup::Setup) -> Self {
        MeshReport {
            n_nodes: setup.mesh.n_nodes(),
            n_cells: setup.mesh.n_cells(),
            h: setup.mesh.h_max(),
            cells_per_axis: scene.mesh.cells_per_axis(),
            reoriented_cells: setup.notes.reoriented_cells,
            coincident_nodes: setup.notes.coincident_nodes,
            seam_facets: setup.notes.seam.facets,
            seam_size: setup.notes.seam.size(),
            unused_nodes: setup.notes.unused_nodes,
            curved_cells: setup.notes.curved_cells,
        }
    }
}

/// What a run of the PETSc backend did (`solver.backend = "petsc"`).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct PetscReport {
    /// MPI ranks.
    pub ranks: usize,
    /// Unknowns of the distributed system (prescribed ones included, eliminated in place).
    pub unknowns: usize,
    /// Stored entries of the distributed matrix, summed over the ranks.
    pub nonzeros: f64,
    /// Iterations of the outer Krylov method.
    pub krylov_iterations: usize,
    /// PETSc's reason for stopping (`CONVERGED_RTOL`, ...).
    pub reason: String,
    /// The options database the solver was configured from: the backend's defaults, then the
    /// scene's `solver.petsc_options` (later options win).
    pub options: String,
    /// Cells assembled by each rank.
    pub cells_per_rank: Vec<usize>,
    /// Unknowns owned by each rank.
    pub unknowns_per_rank: Vec<usize>,
    /// Peak resident memory of each rank, bytes (set by the application; empty where unknown).
    pub peak_bytes_per_rank: Vec<u64>,
    /// Building the preconditioner (multigrid hierarchies, the Schur approximation), s.
    pub preconditioner_setup_s: f64,
    /// A run in which no rank held the whole mesh: the blocks of cells per axis the generated
    /// mesh was cut into, one per rank (the solution written as `solution.pvtu` with one
    /// `solution-<rank>.vtu` per rank); absent where every rank held the whole mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pieces: Option<[usize; 3]>,
}

/// The scene as run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SceneReport {
    /// Its name.
    pub name: String,
    /// Where it came from: a shipped scene's name or a file's path (set by the application;
    /// the scene's name otherwise).
    pub source: String,
    /// Its description.
    pub description: String,
    /// Every setting, overrides applied.
    pub settings: Scene,
}

/// Mesh sizes.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct MeshReport {
    /// Nodes.
    pub n_nodes: usize,
    /// Cells.
    pub n_cells: usize,
    /// Largest cell diameter.
    pub h: f64,
    /// Cells per axis of a generated mesh (empty for a Gmsh mesh).
    pub cells_per_axis: Vec<usize>,
    /// Cells the Gmsh reader turned round (a surface written clockwise).
    #[serde(default)]
    pub reoriented_cells: usize,
    /// Nodes at the coordinates of another node (a crack, or parts not merged).
    #[serde(default)]
    pub coincident_nodes: usize,
    /// Boundary facets that lie on other boundary facets: the sides of a seam where the mesh's
    /// parts are not joined, so that the body is cut there.
    #[serde(default)]
    pub seam_facets: usize,
    /// The seam's length (2D) or area (3D), in the scene's length unit (0 without one).
    #[serde(default)]
    pub seam_size: f64,
    /// Nodes that no cell uses (the centre of a Gmsh arc): they carry no unknown.
    #[serde(default)]
    pub unused_nodes: usize,
    /// Curved second-order cells (edge nodes off their edges' midpoints, as Gmsh puts them on a
    /// curved boundary), mapped through their nodes (isoparametric).
    #[serde(default)]
    pub curved_cells: usize,
}

/// Free unknowns.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DofsReport {
    /// Displacement.
    pub u: usize,
    /// Potential.
    pub phi: usize,
}

impl DofsReport {
    /// `u + φ`.
    pub fn total(&self) -> usize {
        self.u + self.phi
    }
}

/// The contact boundary's counts and resultant forces.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ContactReport {
    /// Contact points.
    pub n_points: usize,
    /// Points in contact and sticking.
    pub n_stick: usize,
    /// Points in contact and sliding (all of them, frictionless).
    pub n_slip: usize,
    /// Points with no contact force.
    pub n_separated: usize,
    /// `Σ w λ_n`: the pressures integrated (over zones of different normals a sum of their
    /// magnitudes; [`ContactReport::normal_resultant`] is the vector).
    pub normal_force: f64,
    /// The normal force as a vector, `-Σ w λ_n n` in the global frame (one component per
    /// dimension; the force the foundation exerts on the body, pushing it out along `-n`).
    #[serde(default)]
    pub normal_resultant: Vec<f64>,
    /// `|Σ w λ_t t|`: the magnitude of [`ContactReport::tangential_resultant`].
    pub tangential_force: f64,
    /// The tangential force as a vector, `Σ w λ_t t` in the global frame (`x, y[, z]`: one
    /// component per dimension; the force the foundation exerts on the body, against the slip).
    #[serde(default)]
    pub tangential_resultant: Vec<f64>,
    /// The largest contact pressure (absent without contact).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_lambda_n: Option<f64>,
    /// Points with a tangent that a Dirichlet condition holds (no multiplier there: the
    /// support takes the force, as on a symmetry plane).
    #[serde(default)]
    pub held_tangent_points: usize,
    /// Nodes of the contact group whose normal displacement a Dirichlet condition prescribes:
    /// the support holds them, and they are no contact points.
    #[serde(default)]
    pub held_nodes: usize,
    /// Those of them held past the gap, inside the foundation (the condition wins).
    #[serde(default)]
    pub held_inside: usize,
    /// Electrical contact: the charge on the foundation (or the tip) across the contact zone,
    /// `-Σ w q` with `q = D·ν` the flux out of the body (C, or C/m in plane strain: the
    /// scene's units); the charge on the conductor, as every charge the program reports or
    /// reads (`contact.charge` of a floating tip takes this value back).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
    /// A conducting foundation (or tip): its potential, prescribed
    /// (`contact.foundation_potential`) or, floating with a given `contact.charge`, found (the
    /// potential of the points it presses).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub potential: Option<f64>,
    /// Electrical contact: the points whose potential is free (the others sit on an
    /// electrode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electric_points: Option<usize>,
    /// The frame of the contact values, where every point shares one (one zone, or zones of
    /// one normal): contact.csv's `u_n`, `lambda_n` along its `normal`, `u_t`, `lambda_t`
    /// (`u_t2`, `lambda_t2` in 3D) along its `tangents`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<ContactFrame>,
    /// Several contact groups (`[[contact]]`): each one's own counts and forces.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<ContactGroupReport>,
}

/// The directions of a zone's contact values, unit vectors in the global frame (one
/// component per dimension): `normal` the body face's outward normal (`contact.normal`,
/// along which `u_n` moves toward the foundation and `λ_n` presses), `tangents` the `dim - 1`
/// directions of the tangential components, `t1` the first axis made orthogonal to the
/// normal, in 3D `t2 = t1 × n` (docs/theory.md, "Signs that every output shares").
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ContactFrame {
    /// The outward normal.
    pub normal: Vec<f64>,
    /// The tangents, `dim - 1` of them.
    pub tangents: Vec<Vec<f64>>,
}

impl ContactFrame {
    /// The frame the points `of` share; `None` where they share none (or there is no point).
    fn of(points: &contact::ContactPoints, mut of: impl Iterator<Item = usize>) -> Option<Self> {
        let first = of.next()?;
        let same = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12);
        let (n, t) = (&points.normal[first], &points.tangent[first]);
        let shared = of.all(|i| {
            same(&points.normal[i], n) && (0..points.n_tangential()).all(|q| same(&points.tangent[i][q], &t[q]))
        });
        let dim = points.dim;
        // `+ 0.0`: round-off's -0 reads as 0
        let vector = |v: &[f64; 3]| v[..dim].iter().map(|x| x + 0.0).collect();
        shared.then(|| ContactFrame {
            normal: vector(n),
            tangents: t[..dim - 1].iter().map(vector).collect(),
        })
    }
}

/// The run's results in words, each number with its unit (run.json's `units`): the contact's
/// counts and forces, an indenter's depth, force and contact radius, each terminal's charge
/// at its potential. A load path's rows are its own lines; this is its last instant's.
pub fn result_lines(r: &RunReport) -> Vec<String> {
    let unit = |q: &str| r.units.quantities.get(q).cloned().unwrap_or_default();
    let with = |x: f64, q: &str| {
        let u = unit(q);
        if u.is_empty() {
            format!("{x:.4e}")
        } else {
            format!("{x:.4e} {u}")
        }
    };
    let mut out = vec![];
    let c = &r.contact;
    if c.n_points > 0 {
        let mut line = format!(
            "contact: {} of {} points stick, {} slip, {} separated; normal force {}",
            c.n_stick,
            c.n_points,
            c.n_slip,
            c.n_separated,
            with(c.normal_force, "force"),
        );
        if r.plan.friction {
            line.push_str(&format!(", tangential force {}", with(c.tangential_force, "force")));
        }
        if let Some(q) = c.charge {
            line.push_str(&format!(", charge across the zone {}", with(q, "charge")));
        }
        out.push(line);
    }
    if let Some(i) = &r.indenter {
        let mut line = format!(
            "indenter: depth {}, force {}, contact radius {}",
            with(i.depth, "length"),
            with(i.force, "force"),
            with(i.contact_radius, "length"),
        );
        if let Some(next) = i.contact_radius_next.filter(|_| i.points_in_contact > 0) {
            line.push_str(&format!(
                " (the next point out, at {}, carries none)",
                with(next, "length")
            ));
        }
        if let Some(q) = i.charge {
            line.push_str(&format!(", charge {}", with(q, "charge")));
        }
        if let Some(v) = i.tip_potential {
            line.push_str(&format!(", surface potential at the tip {}", with(v, "potential")));
        }
        out.push(line);
    }
    if !r.terminals.is_empty() {
        let each: Vec<String> = (r.terminals.iter())
            .map(|t| {
                let floating = if t.floating { " (floating)" } else { "" };
                format!(
                    "`{}` {} at {}{floating}",
                    t.group,
                    with(t.charge, "charge"),
                    with(t.potential, "potential")
                )
            })
            .collect();
        out.push(format!("charges: {}", each.join(", ")));
    }
    out
}

/// One contact group's share of a contact solution (several `[[contact]]` groups).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ContactGroupReport {
    /// The group.
    pub group: String,
    /// Its contact points.
    pub n_points: usize,
    /// Its points in contact and sticking.
    pub n_stick: usize,
    /// Its points in contact and sliding.
    pub n_slip: usize,
    /// Its points with no contact force.
    pub n_separated: usize,
    /// `Σ w λ_n` over its points (along its own normal).
    pub normal_force: f64,
    /// `|Σ w λ_t t|` over its points.
    pub tangential_force: f64,
    /// `Σ w λ_t t` over its points, in the global frame (one component per dimension).
    #[serde(default)]
    pub tangential_resultant: Vec<f64>,
    /// The frame of its contact values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<ContactFrame>,
}

/// What the points `of` a contact solution add up to.
struct Tally {
    /// Stick, slip, separated.
    counts: [usize; 3],
    /// `Σ w λ_n`.
    normal: f64,
    /// `-Σ w λ_n n`.
    pushed: [f64; 3],
    /// `Σ w λ_t t`.
    tangential: [f64; 3],
}

/// The points `of` a contact solution added up; on a body of `revolution` the resultants
/// without their radial part (x), which cancels over the revolution.
fn tally(
    points: &contact::ContactPoints,
    sol: &contact::ContactSolution,
    of: impl Iterator<Item = usize>,
    revolution: bool,
) -> Tally {
    let nt = sol.lambda.n_tangential();
    let mut out = Tally {
        counts: [0; 3],
        normal: 0.0,
        pushed: [0.0; 3],
        tangential: [0.0; 3],
    };
    for i in of {
        out.counts[match sol.status[i] {
            contact::Status::Stick => 0,
            contact::Status::Slip => 1,
            contact::Status::Separated => 2,
        }] += 1;
        let w = points.weight[i];
        out.normal += w * sol.lambda.normal[i];
        for k in 0..3 {
            out.pushed[k] -= w * sol.lambda.normal[i] * points.normal[i][k];
            for q in 0..nt {
                out.tangential[k] += w * sol.lambda.tangential[i * nt + q] * points.tangent[i][q][k];
            }
        }
    }
    if revolution {
        out.pushed[0] = 0.0;
        out.tangential[0] = 0.0;
    }
    out
}

impl ContactReport {
    /// The summary of a contact solution on its points; with several groups (`groups[k]` the
    /// name of group k, `group_of[i]` point i's), each group's share too. On a body of
    /// `revolution` (its meridian meshed, x the radius) the tangential resultants have no
    /// radial part: radial tractions cancel over the revolution (a ring pulled outward
    /// everywhere carries no net force), and the axial part is the whole body's.
    pub fn of_groups(
        points: &contact::ContactPoints,
        sol: &contact::ContactSolution,
        groups: &[String],
        group_of: &[usize],
        revolution: bool,
    ) -> Self {
        let mut out = Self::of(points, sol, revolution);
        if groups.len() > 1 {
            out.groups = groups
                .iter()
                .enumerate()
                .map(|(k, group)| {
                    let mine = || (0..points.len()).filter(move |&i| group_of[i] == k);
                    let t = tally(points, sol, mine(), revolution);
                    let [n_stick, n_slip, n_separated] = t.counts;
                    ContactGroupReport {
                        group: group.clone(),
                        n_points: mine().count(),
                        n_stick,
                        n_slip,
                        n_separated,
                        normal_force: t.normal,
                        tangential_force: linalg::norm(&t.tangential),
                        tangential_resultant: t.tangential[..points.dim].to_vec(),
                        frame: ContactFrame::of(points, mine()),
                    }
                })
                .collect();
        }
        out
    }

    /// The summary of a contact solution on its points (on a body of `revolution`, its
    /// resultants without their radial part).
    pub fn of(points: &contact::ContactPoints, sol: &contact::ContactSolution, revolution: bool) -> Self {
        let t = tally(points, sol, 0..points.len(), revolution);
        let [n_stick, n_slip, n_separated] = t.counts;
        ContactReport {
            n_points: points.len(),
            n_stick,
            n_slip,
            n_separated,
            normal_force: t.normal,
            // `+ 0.0`: round-off's -0 reads as 0
            normal_resultant: t.pushed[..points.dim].iter().map(|x| x + 0.0).collect(),
            tangential_force: linalg::norm(&t.tangential),
            tangential_resultant: t.tangential[..points.dim].to_vec(),
            max_lambda_n: Some(sol.lambda.normal.iter().cloned().fold(0.0f64, f64::max)),
            held_tangent_points: (0..points.len())
                .filter(|&i| points.held[i][..points.n_tangential()].iter().any(|&h| h))
                .count(),
            held_nodes: 0,
            held_inside: 0,
            charge: sol.electric.as_ref().map(|e| e.charge(&points.weight)),
            potential: None,
            electric_points: sol.electric.as_ref().map(|e| e.points.len()),
            frame: ContactFrame::of(points, 0..points.len()),
            groups: vec![],
        }
    }
}

/// Iteration counts.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Iterations {
    /// Fixed-point steps on the slip bound.
    pub fixed_point: usize,
    /// First-order steps (Uzawa, or the accelerated gradient's).
    pub uzawa: usize,
    /// Block Gauss–Seidel sweeps (Newton's fallback for Coulomb's law).
    #[serde(default)]
    pub sweeps: usize,
    /// Semismooth Newton steps (those of the proximal stage's problems included).
    pub newton: usize,
    /// Newton steps on the coarser problems of Newton's nested start (each on a fraction of
    /// the contact points), not counted in `newton`.
    #[serde(default)]
    pub coarse_newton: usize,
    /// Outer steps of Newton's proximal stage (each a regularised problem).
    #[serde(default)]
    pub proximal: usize,
    /// Halvings in Newton's line search.
    pub line_search_cuts: usize,
    /// Whether Newton stalled and its last stage finished (block Gauss–Seidel for Coulomb's
    /// law, the accelerated gradient otherwise; its sweeps are counted in `sweeps`, its steps in `uzawa`).
    pub newton_fallback: bool,
    /// PCG iterations in the contact loops (or the one linear solve).
    pub pcg: usize,
    /// Primal solves (1 without contact).
    pub primal_solves: usize,
    /// PCG iterations spent estimating `μ_max`.
    pub pcg_in_step_estimate: usize,
    /// Steps of the fixed point on the springs that hold a body only its compliant bed holds
    /// (each a contact solve; the counts above are the last one's), 0 where the Dirichlet
    /// conditions hold the body.
    #[serde(default)]
    pub bed: usize,
    /// The stages of Newton's schedule that ran (`nested-start`, `newton`, `proximal`,
    /// `fallback`, ...: `contact::Phase`), in order; on a path, those that ran at any step.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<String>,
}

impl Iterations {
    /// The counts of a contact solve (`None`: a run without contact, one linear solve) with
    /// `pcg` PCG iterations.
    pub fn of(info: Option<&contact::ContactInfo>, pcg: usize) -> Self {
        Iterations {
            fixed_point: info.map_or(0, |i| i.fixed_point_iters),
            uzawa: info.map_or(0, |i| i.uzawa_iters),
            sweeps: info.map_or(0, |i| i.sweeps),
            newton: info.map_or(0, |i| i.newton_iters),
            coarse_newton: info.map_or(0, |i| i.coarse_newton_iters),
            proximal: info.map_or(0, |i| i.proximal_iters),
            line_search_cuts: info.map_or(0, |i| i.line_search_cuts),
            newton_fallback: info.is_some_and(|i| i.fallback),
            pcg,
            primal_solves: info.map_or(1, |i| i.operator_calls),
            pcg_in_step_estimate: info.map_or(0, |i| i.estimate_inner_iters),
            bed: 0,
            stages: info.map_or(vec![], |i| i.stages.iter().map(|p| p.name().to_string()).collect()),
        }
    }

    /// The counts of `other` added to these (a load path's steps summed).
    pub fn add(&mut self, other: &Iterations) {
        self.fixed_point += other.fixed_point;
        self.uzawa += other.uzawa;
        self.sweeps += other.sweeps;
        self.newton += other.newton;
        self.coarse_newton += other.coarse_newton;
        self.proximal += other.proximal;
        self.line_search_cuts += other.line_search_cuts;
        self.newton_fallback |= other.newton_fallback;
        self.pcg += other.pcg;
        self.primal_solves += other.primal_solves;
        self.pcg_in_step_estimate += other.pcg_in_step_estimate;
        self.bed += other.bed;
        // the stages that ran at any step, in the schedule's order
        let ran = |name: &str, a: &[String], b: &[String]| a.iter().chain(b).any(|s| s == name);
        self.stages = contact::Phase::ALL
            .iter()
            .map(|p| p.name())
            .filter(|n| ran(n, &self.stages, &other.stages))
            .map(String::from)
            .collect();
    }

    /// One line: the counts of the loops that ran (`4 Newton`, `39 Uzawa, 3 FP, 812 PCG`),
    /// `-` for a direct linear solve.
    pub fn summary(&self) -> String {
        let mut parts = vec![];
        for (count, name) in [
            (self.newton, "Newton"),
            (self.coarse_newton, "coarse Newton"),
            (self.proximal, "proximal"),
            (self.uzawa, "Uzawa"),
            (self.sweeps, "sweeps"),
            (self.fixed_point, "FP"),
            (self.pcg, "PCG"),
            (self.bed, "bed"),
        ] {
            if count > 0 {
                parts.push(format!("{count} {name}"));
            }
        }
        if self.newton_fallback {
            parts.push("fallback".into());
        }
        if parts.is_empty() {
            "-".into()
        } else {
            parts.join(", ")
        }
    }

    /// The outer iteration count of a run of `strategy` and what it counts: Newton steps, else
    /// first-order steps (APG for the accelerated strategy), else PCG iterations, else
    /// `direct`.
    pub fn outer(&self, strategy: Strategy) -> (usize, &'static str) {
        if self.newton > 0 {
            (self.newton, "Newton")
        } else if self.uzawa > 0 {
            (
                self.uzawa,
                if strategy == Strategy::ApgCondensed {
                    "APG"
                } else {
                    "Uzawa"
                },
            )
        } else if self.pcg > 0 {
            (self.pcg, "PCG")
        } else {
            (0, "direct")
        }
    }
}

/// Scale-free residuals of the final state.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Residuals {
    /// `‖K x - b‖ / ‖b‖` with the contact forces in `b`.
    pub equilibrium: f64,
    /// The natural-map residual of docs/theory.md (0 without contact).
    pub complementarity: f64,
    /// Whether the run stopped on its tolerance (the tight rule), not on the paper's loose rule.
    pub converged_to_tolerance: bool,
}

/// Wall times, s.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Timings {
    /// The mesh, materials, plan, conditions and loads.
    pub setup: f64,
    /// Assembly of the blocks and loads.
    pub assembly: f64,
    /// Factorisation.
    pub factorization: f64,
    /// Forming the contact compliance (condensed strategies).
    pub condense: f64,
    /// The contact solve (0 without contact).
    pub contact: f64,
    /// The solve, contact included.
    pub solve: f64,
    /// Writing a path's step files as it runs (the rest of a set is written after the report
    /// is made); 0 for one instant.
    #[serde(default)]
    pub output: f64,
    /// Set-up to solution.
    pub total: f64,
}

/// Memory.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Memory {
    /// Peak resident memory of the process (set by the application; 0 where unknown).
    pub peak_bytes: u64,
    /// Bytes of the factors' values.
    pub factor_bytes: usize,
}

/// The solver's parameters and what its loops measured.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SolverReport {
    /// The strategy.
    pub strategy: Strategy,
    /// The stopping rule, in words.
    pub rule: String,
    /// The contact tolerance asked.
    pub tol: f64,
    /// The PCG's relative tolerance.
    pub pcg_rel_tol: f64,
    /// The first-order step `r` last used (`null` where no first-order step ran).
    pub step_r: Option<f64>,
    /// The constant `c = 1/μ_max` of Newton's natural map (`null` where Newton did not run).
    pub augmentation_c: Option<f64>,
    /// The estimate of the dual operator's largest eigenvalue.
    pub mu_max: Option<f64>,
    /// Halvings of the first-order step.
    pub step_backoffs: usize,
    /// Halvings of the fixed point's relaxation.
    pub fixed_point_relaxations: usize,
    /// How the contact compliance was formed (condensed strategies).
    pub condense_route: Option<String>,
    /// The contact points the contact problem held where it held only those an indenter can
    /// touch (the rest checked open after the solve; docs/theory.md, "The points that can
    /// touch"); absent where it held every point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condensed_points: Option<usize>,
    /// The smallest `|pivot| / |diagonal entry|` of the `L D Lᵀ` (direct strategies).
    pub smallest_pivot_ratio: Option<f64>,
    /// The numeric factorisation's floating-point operations (the tree's `L D Lᵀ` counts
    /// them; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_flops: Option<f64>,
    /// Its rate, GFlop/s: the operations over the numeric factorisation's wall time (the
    /// analysis left out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_gflops: Option<f64>,
    /// Steps of iterative refinement of the last solve (direct strategies; 0 where its
    /// residual was at round-off already).
    #[serde(default)]
    pub refinement_steps: usize,
    /// Slip weakening: the measured contraction of the fixed point on the coefficients (at or
    /// above 1, the map was not contractive along the way: the static problem may have
    /// several solutions, and this one is the branch from the stick start); absent elsewhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_map_contraction: Option<f64>,
    /// The threads of rayon's pool the run had (`RAYON_NUM_THREADS`, else the cores): the
    /// assembly's, and the `L D Lᵀ`'s (independent subtrees of its elimination tree factored
    /// at the same time; docs/performance.md). The Schur route's Cholesky factors run on one.
    #[serde(default)]
    pub threads: usize,
}

impl SolverReport {
    /// What a contact solve measured (`None`: a run without contact), with the strategy's
    /// settings left at their defaults for the caller to fill.
    pub fn of(info: Option<&contact::ContactInfo>) -> Self {
        SolverReport {
            strategy: Strategy::NewtonCondensed,
            rule: String::new(),
            tol: 0.0,
            pcg_rel_tol: 0.0,
            step_r: info.and_then(|i| i.step),
            augmentation_c: info.and_then(|i| i.augmentation),
            mu_max: info.map(|i| i.mu_max),
            step_backoffs: info.map_or(0, |i| i.step_backoffs),
            fixed_point_relaxations: info.map_or(0, |i| i.relaxations),
            condense_route: None,
            condensed_points: None,
            smallest_pivot_ratio: None,
            factor_flops: None,
            factor_gflops: None,
            refinement_steps: 0,
            friction_map_contraction: info.and_then(|i| i.contraction),
            threads: rayon::current_num_threads(),
        }
    }
}

/// The stopping rule in words, as the report gives it.
pub fn rule_in_words(rule: Rule) -> &'static str {
    match rule {
        Rule::Paper => "paper (the loose rules of the paper's Table 1: relative change 1e-3, PCG (r,z) <= 1e-2 (r0,z0); not converged to a tolerance)",
        Rule::Tight => "tight",
    }
}
