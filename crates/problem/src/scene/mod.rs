//! The scene as typed data: what to solve. Every choice (mesh kind, material model, contact
//! law, strategy, rule, exact solution) is an enum from the moment the scene is read; the
//! numbers are plain fields. A scene comes from a TOML file through serde (the application
//! reads the text) or is built in code; either way [`Scene::validate`] checks it before
//! anything is computed (`validate.rs`), and refuses keys that do not exist or do not apply.

mod crystals;
mod validate;
mod zone;

use serde::{Deserialize, Serialize};
use std::fmt;

use crystals::named as named_crystal;
pub use crystals::{CrystalUnits, Datasheet, NamedCrystal, StressCharge, LIBRARY as CRYSTALS};
pub use validate::{SceneError, Valid, TOL_RANGE};
pub use zone::{Control, Friction, Obstacle, ZoneBound, ZoneElectric, ZoneModel};

/// An enum of named choices: serde reads and writes the names, `name()` gives them, `ALL` lists
/// the variants, and `FromStr` parses a name (with a message that names the key and lists the
/// choices; serde reads through it).
macro_rules! choice {
    ($(#[$meta:meta])* $vis:vis enum $ty:ident ($what:literal) {
        $($(#[$vmeta:meta])* $var:ident = $text:literal,)+
    }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(try_from = "String")]
        $vis enum $ty {
            $($(#[$vmeta])* #[serde(rename = $text)] $var,)+
        }
        impl $ty {
            /// Every variant, in the order of the documentation.
            pub const ALL: &'static [$ty] = &[$($ty::$var),+];
            /// The name in scene files.
            pub fn name(self) -> &'static str {
                match self { $($ty::$var => $text),+ }
            }
        }
        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.pad(self.name())
            }
        }
        impl TryFrom<String> for $ty {
            type Error = String;
            fn try_from(s: String) -> Result<Self, String> {
                s.parse()
            }
        }
        impl std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                Self::ALL.iter().copied().find(|v| v.name() == s).ok_or_else(|| {
                    let names: Vec<&str> = Self::ALL.iter().map(|v| v.name()).collect();
                    format!("{} `{s}` is unknown ({})", $what, names.join(", "))
                })
            }
        }
    };
}
pub(crate) use choice;

choice! {
    /// How the mesh is made.
    pub enum MeshKind ("mesh.kind") {
        /// P1 triangles on a rectangle (each square split SW-NE).
        Rectangle = "rectangle",
        /// P1 tetrahedra on a box (Kuhn's split of each cube).
        Box = "box",
        /// A Gmsh file (MSH 4.1), read by the application.
        Gmsh = "gmsh",
        /// A mesh the caller hands over with the scene (built in code, or from arrays: the
        /// Python package's `Scene.set_mesh`).
        Given = "given",
    }
}

choice! {
    /// The constitutive model of a material.
    pub enum MaterialModel ("material.model") {
        /// A poled ceramic of class 6mm: `c = [c11, c12, c13, c33, c44, c66]`,
        /// `e = [e31, e33, e15]`, `permittivity = [eps11, eps33]`, `poling`.
        Crystal6mm = "crystal-6mm",
        /// An isotropic elastic solid: `young`, `poisson`, `permittivity = [eps]` (optional).
        Isotropic = "isotropic",
    }
}

choice! {
    /// The contact law on the contact group.
    pub enum ContactLaw ("contact.law") {
        /// No contact: the contact section is switched off (its other keys are kept, unused).
        None = "none",
        /// Signorini contact, frictionless.
        Signorini = "signorini",
        /// Tresca friction with a given slip bound `slip_bound`.
        Tresca = "tresca",
        /// Coulomb friction with coefficient `friction`.
        Coulomb = "coulomb",
    }
}

choice! {
    /// The form of Coulomb's coefficient (`contact.friction_law`).
    pub enum FrictionLaw ("contact.friction_law") {
        /// A constant coefficient, `contact.friction`.
        Coulomb = "coulomb",
        /// A coefficient that falls with the slip, from `friction_static` to `friction_dynamic`
        /// over `slip_length` (a non-monotone law).
        SlipWeakening = "slip-weakening",
    }
}

choice! {
    /// The electric condition on the contact zone (`contact.electric`).
    pub enum ElectricCondition ("contact.electric") {
        /// An insulating foundation, `D·ν = 0` on the whole zone (the paper's; the default).
        Insulated = "insulated",
        /// A foundation at `foundation_potential` that conducts where it touches,
        /// `D·ν = σ_c p (φ - φ_F)` (`σ_c` = `conductance`; `p` the pressure, or the
        /// penetration under normal compliance).
        Conductive = "conductive",
        /// An ideal conductor: `φ = φ_F` where in contact, `D·ν = 0` where separated.
        Conducting = "conducting",
    }
}

choice! {
    /// The shape of a rigid indenter (`contact.indenter.shape`): its height `h(ρ)` above its
    /// tip at the distance `ρ` from its axis.
    pub enum IndenterShape ("contact.indenter.shape") {
        /// A flat rigid plane, `h = 0` (a foundation).
        Plane = "plane",
        /// A sphere of `radius` R, `h = R - √(R² - ρ²)` (points beyond `ρ = R` out of reach).
        Sphere = "sphere",
        /// Hertz's paraboloid of tip radius R, `h = ρ² / (2R)`.
        Paraboloid = "paraboloid",
        /// A cone of semi-vertical angle `half_angle` (degrees), `h = ρ / tan(half_angle)`.
        Cone = "cone",
        /// A flat-ended cylindrical punch of `radius` a, `h = 0` for `ρ ≤ a` (points beyond out
        /// of reach).
        Punch = "punch",
        /// A cylinder of `radius` R lying on the face along `axis` (3D; in 2D the plane-strain
        /// cylinder), `h = R - √(R² - ρ²)` with `ρ` the distance across its axis.
        Cylinder = "cylinder",
        /// An axisymmetric profile tabulated as `profile = [[ρ, h], ...]` (ρ increasing from 0,
        /// linear between; points beyond the last ρ out of reach).
        Profile = "profile",
    }
}

choice! {
    /// How slip-weakening friction's coefficient falls (`contact.weakening`).
    pub enum WeakeningForm ("contact.weakening") {
        /// Linearly, reaching the dynamic value at the slip length.
        Linear = "linear",
        /// Exponentially, by `exp(-s / L)`.
        Exponential = "exponential",
    }
}

choice! {
    /// How the contact problem and its linear systems are solved (`piezocontact strategies`).
    pub enum Strategy ("solver.strategy") {
        /// Semismooth Newton on the contact compliance read off the `L D Lᵀ` of `K`.
        NewtonCondensed = "newton-condensed",
        /// The accelerated projected gradient on the same compliance.
        ApgCondensed = "apg-condensed",
        /// Uzawa on the same compliance.
        UzawaCondensed = "uzawa-condensed",
        /// Uzawa with one full solve per iteration by the `L D Lᵀ` of `K`.
        UzawaDirect = "uzawa-direct",
        /// The paper's: Uzawa with one Schur-complement PCG solve per iteration.
        UzawaSchurPcg = "uzawa-schur-pcg",
    }
}

choice! {
    /// Who does the linear algebra.
    pub enum BackendChoice ("solver.backend") {
        /// faer's sparse direct factorisations, on one machine (the default).
        Faer = "faer",
        /// PETSc: Krylov methods with algebraic multigrid (a field split with the Schur
        /// complement of the potentials where the body is electric), on the ranks of an MPI run.
        /// Needs a build with the feature `petsc`.
        Petsc = "petsc",
    }
}

choice! {
    /// When the contact loops stop.
    pub enum Rule ("solver.rule") {
        /// The complementarity residual at most `solver.tol`.
        Tight = "tight",
        /// The paper's loose rules (Table 1), never reported as converged to a tolerance.
        Paper = "paper",
    }
}

choice! {
    /// The known solution a scene is checked against.
    pub enum ExactKind ("exact.kind") {
        /// The smooth manufactured solution of `fe_assembly::Exact::manufactured`.
        Manufactured = "manufactured",
        /// An affine `(u, φ)` (a patch test).
        Affine = "affine",
        /// A smooth `(u, φ)` in sticking contact with the scene's foundation on the whole
        /// contact face (`fe_assembly::Exact::on_foundation`, from the scene's gap, bed and
        /// electric condition: conducting, conductive or insulated).
        ManufacturedContact = "manufactured-contact",
        /// Hertz's frictionless cylinder on a half-plane.
        Hertz = "hertz",
        /// Cattaneo-Mindlin's partial slip under a tangential force.
        CattaneoMindlin = "cattaneo-mindlin",
        /// A rigid axisymmetric indenter on a transversely isotropic piezoelectric (or
        /// isotropic) half-space: `problem::HalfSpace`'s closed form.
        HalfSpace = "half-space",
    }
}

/// How a strategy's contact solver works.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactSolver {
    /// Semismooth Newton (`contact::solve_newton`).
    Newton,
    /// Uzawa's first-order iteration (`contact::solve_uzawa`), accelerated or not.
    FirstOrder {
        /// Nesterov's acceleration (the APG strategy).
        accelerate: bool,
    },
}

impl Strategy {
    /// One line: what the strategy does.
    pub fn description(self) -> &'static str {
        match self {
            Strategy::NewtonCondensed => "default: semismooth Newton (Alart-Curnier, Coulomb solved directly) on the contact compliance, read once off the L D Lᵀ of K (contact dofs last); one final full solve",
            Strategy::ApgCondensed => "Nesterov-accelerated projected gradient (FISTA, adaptive restart, step 1/mu_max) on the same compliance",
            Strategy::UzawaCondensed => "Uzawa (r = 1.8/mu_max) on the same compliance",
            Strategy::UzawaDirect => "Uzawa with one full solve per iteration by the L D Lᵀ of K (factored once)",
            Strategy::UzawaSchurPcg => "the paper's: Uzawa with one Schur-complement PCG solve per iteration (Algorithm 3, preconditioned by A)",
        }
    }

    /// Whether the contact problem is solved on the condensed compliance (one factorisation with
    /// the contact dofs last).
    pub fn is_condensed(self) -> bool {
        matches!(
            self,
            Strategy::NewtonCondensed | Strategy::ApgCondensed | Strategy::UzawaCondensed
        )
    }

    /// Whether the linear systems are solved by the Schur-complement PCG (Algorithm 3).
    pub fn runs_pcg(self) -> bool {
        self == Strategy::UzawaSchurPcg
    }

    /// Whether the contact iteration is the paper's Uzawa (so the paper's rule applies).
    pub fn is_uzawa(self) -> bool {
        matches!(
            self,
            Strategy::UzawaCondensed | Strategy::UzawaDirect | Strategy::UzawaSchurPcg
        )
    }

    /// The contact solver it runs.
    pub fn contact_solver(self) -> ContactSolver {
        match self {
            Strategy::NewtonCondensed => ContactSolver::Newton,
            Strategy::ApgCondensed => ContactSolver::FirstOrder { accelerate: true },
            _ => ContactSolver::FirstOrder { accelerate: false },
        }
    }
}

impl ExactKind {
    /// What the headline error of this kind measures.
    pub fn measures(self) -> &'static str {
        match self {
            ExactKind::Manufactured => "relative energy-norm error of (u, φ) against the manufactured solution",
            ExactKind::Affine => "relative energy-norm error against the affine solution (a patch test: round-off)",
            ExactKind::ManufacturedContact => {
                "relative energy-norm error of (u, φ) against the manufactured solution in contact with the foundation"
            }
            ExactKind::Hertz => "relative l2 error of the nodal contact pressure against Hertz's, over |x| ≤ 1.5 a",
            ExactKind::CattaneoMindlin => {
                "relative l2 error of the nodal tangential traction against Cattaneo-Mindlin's, over |x| ≤ 1.5 a"
            }
            ExactKind::HalfSpace => {
                "relative error of the indenter's force (its depth under force control) against the half-space's closed form"
            }
        }
    }

    /// Whether it is a field solution (manufactured, affine; and the manufactured solution on
    /// the foundation, the one with contact).
    pub fn is_field(self) -> bool {
        matches!(
            self,
            ExactKind::Manufactured | ExactKind::Affine | ExactKind::ManufacturedContact
        )
    }
}

/// A whole scene.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Short name.
    pub name: String,
    /// One line: what the scene is.
    pub description: String,
    /// The mesh.
    pub mesh: MeshSpec,
    /// Materials by region.
    pub material: Vec<MaterialSpec>,
    /// Clamped / grounded groups.
    #[serde(default)]
    pub dirichlet: Vec<DirichletSpec>,
    /// The mechanical loads: one `[load]`, or several `[[load]]`.
    #[serde(default)]
    pub load: Option<Loads>,
    /// Electrodes on parts of boundary groups: one table `[electrode]`, or an array
    /// `[[electrode]]`, each at a voltage or floating.
    #[serde(default)]
    pub electrode: Option<Electrodes>,
    /// Contact with a rigid foundation or indenter: one table `[contact]`, or an array
    /// `[[contact]]` of groups (each its own face, normal, gap, friction or indenter).
    #[serde(default)]
    pub contact: Option<Contacts>,
    /// Solver choices.
    #[serde(default)]
    pub solver: SolverSpec,
    /// A known solution, for verification: the run reports its error against it.
    #[serde(default)]
    pub exact: Option<ExactSpec>,
    /// A load path: the quasi-static process over instants, friction on the slip increment.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathSpec>,
    /// The unit system of the scene's numbers (`[units]`: `length`, `stress`); SI where it
    /// says nothing. The solver never converts: the outputs carry these units
    /// ([`crate::Units`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::UnitsSpec>,
}

/// A quasi-static load path (`[path]`): instants `t` and, per quantity, its factor at each
/// instant (piecewise linear between them; a quantity without a table keeps factor 1). The
/// run solves at `t[0]` from rest and then at `steps` instants up to the last `t`, every
/// instant of `t` among them ([`PathSpec::instants`]), each step with the friction law on the
/// slip since the step before (backward Euler of the quasi-static law).
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    /// The instants, strictly increasing (at least two).
    pub t: Vec<f64>,
    /// Steps after `t[0]` (default: one per later instant of `t`), shared out over the legs
    /// between the instants of `t` by their durations, at least one each.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    /// The factor on the load (`load.p`, every `[[load]]`, and an indenter's force under force
    /// control, `contact.indenter.force`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<Vec<f64>>,
    /// The factor on every prescribed potential (`electrode.v`, `dirichlet.phi`) and on the
    /// charges of the floating terminals (`dirichlet.charge`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub voltage: Option<Vec<f64>>,
    /// The factor on every prescribed displacement component (where `ux`, `uy`, `uz` give
    /// none of their own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<Vec<f64>>,
    /// The factor on the prescribed x components.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ux: Option<Vec<f64>>,
    /// The factor on the prescribed y components.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uy: Option<Vec<f64>>,
    /// The factor on the prescribed z components.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uz: Option<Vec<f64>>,
    /// The factor on the uniform gap (`contact.gap` less an indenter's `depth`; the shape's part stays).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap: Option<Vec<f64>>,
    /// The fields (and a run's `step-NNNN.vtu`) of every `output_every`-th instant (0: the
    /// last alone; by default every instant up to [`DEFAULT_FRAMES`] steps, every
    /// `⌈(n - 1) / 50⌉`-th of `n` instants beyond); the rows of `path.csv` are every instant's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_every: Option<usize>,
    /// Whether each `step-NNNN.vtu` also holds the cell fields (stress, strain, D, E), which
    /// the last instant's `solution.vtu` always holds: false by default (they are 3/4 of a
    /// step's bytes in 2D, more in 3D).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cell_fields: bool,
}

/// The steps after the first whose fields a path writes by default: every instant of a path
/// of up to 50 steps, and at most 51 steps' files of a longer one.
pub const DEFAULT_FRAMES: usize = 50;

/// The factors of one instant of a path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors {
    /// On the load.
    pub load: f64,
    /// On the prescribed potentials.
    pub voltage: f64,
    /// On the prescribed displacement components x, y, z.
    pub displacement: [f64; 3],
    /// On the uniform gap.
    pub gap: f64,
}

impl Factors {
    /// Every factor 1: the scene as written.
    pub const ONE: Factors = Factors {
        load: 1.0,
        voltage: 1.0,
        displacement: [1.0; 3],
        gap: 1.0,
    };
}

impl PathSpec {
    /// The instants solved: `t[0]`, then `steps` more up to the last `t`, shared out over the
    /// legs between the instants of `t` in proportion to their durations, at least one each
    /// and evenly spaced within a leg, so that every instant of `t` is solved (a load's turning
    /// points are where friction's history turns: steps evenly spaced over the whole path
    /// stepped over them, and a cycle's peak load was never reached). Without `steps`, the
    /// instants of `t`. Validation asks for at least one step per leg.
    pub fn instants(&self) -> Vec<f64> {
        let Some(steps) = self.steps else {
            return self.t.clone();
        };
        let mut out = vec![self.t[0]];
        for (w, n) in self.t.windows(2).zip(self.leg_steps(steps)) {
            let (a, b) = (w[0], w[1]);
            out.extend((1..=n).map(|k| {
                let s = k as f64 / n as f64;
                match b - a {
                    _ if k == n => b,
                    // the start plus the step's share: exact where the grid is (2.9, not
                    // the mean's 2.9000000000000004 between 2 and 3)
                    d if d.is_finite() => a + d * k as f64 / n as f64,
                    // the weighted mean: finite for any finite ends whose difference overflows
                    _ => (1.0 - s) * a + s * b,
                }
            }));
        }
        out
    }

    /// `steps` shared out over the legs of `t`: one each, and the rest by the largest
    /// remainders of the legs' shares of the whole duration.
    fn leg_steps(&self, steps: usize) -> Vec<usize> {
        // halves, so that no difference of finite instants overflows; the shares are the same
        let durations: Vec<f64> = self.t.windows(2).map(|w| w[1] / 2.0 - w[0] / 2.0).collect();
        let whole: f64 = durations.iter().sum();
        let rest = steps.saturating_sub(durations.len());
        let quotas: Vec<f64> = durations.iter().map(|d| rest as f64 * (d / whole)).collect();
        let mut counts: Vec<usize> = quotas.iter().map(|q| 1 + (q.floor() as usize).min(rest)).collect();
        let given: usize = counts.iter().sum::<usize>() - counts.len();
        let mut by_remainder: Vec<usize> = (0..quotas.len()).collect();
        by_remainder.sort_by(|&i, &j| (quotas[j] - quotas[j].floor()).total_cmp(&(quotas[i] - quotas[i].floor())));
        for &i in by_remainder.iter().take(rest.saturating_sub(given)) {
            counts[i] += 1;
        }
        counts
    }

    /// Every how many of `n` instants the fields are written: `output_every`, by default 1 up
    /// to [`DEFAULT_FRAMES`] steps and `⌈(n - 1) / DEFAULT_FRAMES⌉` beyond.
    pub fn output_every(&self, n: usize) -> usize {
        self.output_every
            .unwrap_or_else(|| n.saturating_sub(1).div_ceil(DEFAULT_FRAMES).max(1))
    }

    /// Whether instant `k` of `n` has its fields (and a run its `step-NNNN.vtu`): every
    /// [`PathSpec::output_every`]-th (0: none), and the last.
    pub fn has_fields(&self, k: usize, n: usize) -> bool {
        let every = self.output_every(n);
        k + 1 == n || (every > 0 && k.is_multiple_of(every))
    }

    /// The factors at instant `t` (piecewise linear in the tables, constant beyond their ends).
    pub fn factors(&self, t: f64) -> Factors {
        let at =
            |table: &Option<Vec<f64>>, default: f64| table.as_ref().map_or(default, |f| interpolate(&self.t, f, t));
        let d = at(&self.displacement, 1.0);
        Factors {
            load: at(&self.load, 1.0),
            voltage: at(&self.voltage, 1.0),
            displacement: [at(&self.ux, d), at(&self.uy, d), at(&self.uz, d)],
            gap: at(&self.gap, 1.0),
        }
    }

    /// The factor tables with their keys.
    pub(crate) fn tables(&self) -> [(&'static str, &Option<Vec<f64>>); 7] {
        [
            ("path.load", &self.load),
            ("path.voltage", &self.voltage),
            ("path.displacement", &self.displacement),
            ("path.ux", &self.ux),
            ("path.uy", &self.uy),
            ("path.uz", &self.uz),
            ("path.gap", &self.gap),
        ]
    }
}

/// The piecewise-linear interpolant of `(t, f)` at `x`, constant beyond the ends: the weighted
/// mean `(1 - s) f₀ + s f₁`, exact at the instants (the form `f₀ + s (f₁ - f₀)` gave 0 for
/// `f₁ = 1` after `f₀ = 1e30`: the difference had lost `f₁`) and finite for any finite factors.
fn interpolate(t: &[f64], f: &[f64], x: f64) -> f64 {
    if x <= t[0] {
        return f[0];
    }
    for k in 1..t.len() {
        if x <= t[k] {
            // an instant's own factor exactly, whatever its neighbour's magnitude
            if x == t[k] {
                return f[k];
            }
            // halves: the differences of instants near the largest double would overflow
            let s = (x / 2.0 - t[k - 1] / 2.0) / (t[k] / 2.0 - t[k - 1] / 2.0);
            return (1.0 - s) * f[k - 1] + s * f[k];
        }
    }
    f[f.len() - 1]
}

impl Scene {
    /// The contact law, `none` where the scene has no contact section.
    pub fn contact_law(&self) -> ContactLaw {
        // the zones switched off aside; a frictionless zone among frictional ones takes their
        // law with a zero coefficient or bound (exactly frictionless), a Tresca zone beside
        // Coulomb's Coulomb's law with its bound as the radius of its points
        let zones = self.zones();
        let any = |law: ContactLaw| zones.iter().any(|c| c.law == law);
        match zones.first() {
            None => ContactLaw::None,
            Some(_) if any(ContactLaw::Coulomb) => ContactLaw::Coulomb,
            Some(_) if any(ContactLaw::Tresca) => ContactLaw::Tresca,
            Some(c) => c.law,
        }
    }

    /// The first contact zone that is posed (`contact.law` not `none`).
    pub fn active_contact(&self) -> Option<&ContactSpec> {
        self.zones().first().copied()
    }

    /// Every contact group (none, one `[contact]`, or the `[[contact]]` array).
    pub fn contacts(&self) -> &[ContactSpec] {
        self.contact.as_ref().map_or(&[], Contacts::all)
    }

    /// The contact zones that are posed: every contact group but those switched off
    /// (`contact.law = "none"`), in the scene's order. A zone's index here is its index in
    /// the run (the contact boundary's groups, run.json's `contact.groups`).
    pub fn zones(&self) -> Vec<&ContactSpec> {
        self.contacts().iter().filter(|c| c.law != ContactLaw::None).collect()
    }

    /// The key of the scene's first floating terminal (`dirichlet.charge`, else
    /// `electrode.charge`), `None` without one.
    pub fn floating_key(&self) -> Option<&'static str> {
        if self.dirichlet.iter().any(|d| d.charge.is_some()) {
            Some("dirichlet.charge")
        } else if self.electrodes().iter().any(|e| e.charge.is_some()) {
            Some("electrode.charge")
        } else {
            None
        }
    }

    /// The contact section, or the first of several.
    pub fn first_contact(&self) -> Option<&ContactSpec> {
        self.contacts().first()
    }

    /// The contact section, or the first of several, to change.
    pub fn first_contact_mut(&mut self) -> Option<&mut ContactSpec> {
        match self.contact.as_mut()? {
            Contacts::One(c) => Some(c),
            Contacts::Many(v) => v.first_mut(),
        }
    }

    /// The contact zone whose face a rigid indenter presses (at most one: validated), with
    /// its index among [`Scene::zones`].
    pub fn indenter_contact(&self) -> Option<(usize, &ContactSpec)> {
        self.zones().into_iter().enumerate().find(|(_, c)| c.indenter.is_some())
    }

    /// Every number of the scene with its key (`load.p`, `material.c`, ...).
    pub fn numbers(&self) -> Vec<(&'static str, f64)> {
        let mut out: Vec<(&'static str, f64)> = vec![];
        let mut add = |key: &'static str, values: &[f64]| out.extend(values.iter().map(|&v| (key, v)));
        let m = &self.mesh;
        add("mesh.lo", &m.lo);
        add("mesh.hi", &m.hi);
        add("mesh.h", m.h.as_slice());
        for mat in &self.material {
            add("material.c", &mat.c);
            add("material.e", &mat.e);
            add("material.permittivity", &mat.permittivity);
            add("material.young", mat.young.as_slice());
            add("material.coupling_scale", mat.coupling_scale.as_slice());
        }
        for d in &self.dirichlet {
            add("dirichlet.u", d.u.as_deref().unwrap_or_default());
            add("dirichlet.ux", d.ux.as_slice());
            add("dirichlet.uy", d.uy.as_slice());
            add("dirichlet.uz", d.uz.as_slice());
            add("dirichlet.phi", d.phi.as_slice());
            add("dirichlet.charge", d.charge.as_slice());
        }
        for l in self.loads() {
            add("load.p", &[l.p]);
        }
        for e in self.electrodes() {
            add("electrode.v", e.v.as_slice());
            add("electrode.charge", e.charge.as_slice());
        }
        for c in self.contacts() {
            add("contact.friction", c.friction.as_slice());
            add("contact.slip_bound", c.slip_bound.as_slice());
            if let Some(p) = &c.slip_bound_profile {
                add("contact.slip_bound_profile.value", &p.value);
            }
            add("contact.gap", &[c.gap]);
            add("contact.gap_curvature", &[c.gap_curvature]);
            add(
                "contact.compliance.stiffness",
                &c.compliance.map(|k| k.stiffness).into_iter().collect::<Vec<_>>(),
            );
            add("contact.friction_static", c.friction_static.as_slice());
            add("contact.friction_dynamic", c.friction_dynamic.as_slice());
            add("contact.slip_length", c.slip_length.as_slice());
            add("contact.foundation_potential", c.foundation_potential.as_slice());
            add("contact.conductance", c.conductance.as_slice());
            add("contact.charge", c.charge.as_slice());
            if let Some(i) = &c.indenter {
                add("contact.indenter.radius", i.radius.as_slice());
                add("contact.indenter.depth", &[i.depth]);
                add("contact.indenter.force", i.force.as_slice());
            }
        }
        out
    }

    /// What makes the coupled system ill-conditioned, largest first: each piezoelectric
    /// material's coupling number `e²/(c ε)` (its largest `e`, scaled by `coupling_scale`,
    /// over its smallest diagonal `c` and `ε`: the stiffening `G B⁻¹ Gᵀ` brings to `A`), each
    /// isotropic material's `1/(1 - 2ν)` (near incompressibility), and the contrast of the
    /// stiffnesses; dimensionless, about 1 for a well-posed scene.
    pub fn conditioning(&self) -> Vec<(String, f64)> {
        let mut out: Vec<(String, f64)> = vec![];
        let mut stiffness: Vec<f64> = vec![];
        for m in &self.material {
            let scale = m.coupling_scale.unwrap_or(1.0);
            match m.model {
                MaterialModel::Crystal6mm => {
                    // the diagonal constants (c11, c33, c44, c66)
                    let c: Vec<f64> = [0, 3, 4, 5].iter().filter_map(|&k| m.c.get(k).copied()).collect();
                    let c_min = c.iter().copied().fold(f64::INFINITY, f64::min);
                    stiffness.extend(&c);
                    let e = m.e.iter().fold(0.0f64, |a, x| a.max(x.abs())) * scale.abs();
                    let eps = m.permittivity.iter().copied().fold(f64::INFINITY, f64::min);
                    if e > 0.0 && c_min > 0.0 && eps > 0.0 {
                        let name = if scale != 1.0 {
                            format!("the coupling number e²/(c ε) of material `{}` (with material.coupling_scale = {scale:e})", m.region)
                        } else {
                            format!("the coupling number e²/(c ε) of material `{}`", m.region)
                        };
                        out.push((name, e * e / (c_min * eps)));
                    }
                }
                MaterialModel::Isotropic => {
                    if let (Some(young), Some(nu)) = (m.young, m.poisson) {
                        stiffness.push(young);
                        if nu < 0.5 {
                            out.push((
                                format!("1/(1 - 2ν) of material `{}` (poisson = {nu})", m.region),
                                1.0 / (1.0 - 2.0 * nu),
                            ));
                        }
                    }
                }
            }
        }
        let (lo, hi) = stiffness
            .iter()
            .filter(|c| **c > 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &c| (lo.min(c), hi.max(c)));
        if hi > 0.0 && lo.is_finite() {
            out.push((
                "the stiffness contrast between and within the materials".into(),
                hi / lo,
            ));
        }
        out.sort_by(|a, b| b.1.total_cmp(&a.1));
        out
    }

    /// The scene's numbers far from 1 (beyond 1e100 or below 1e-100 in magnitude), the most
    /// extreme first: where a result that is not finite most likely comes from.
    pub fn extreme_numbers(&self) -> Vec<(&'static str, f64)> {
        let mut out: Vec<(&'static str, f64)> = self
            .numbers()
            .into_iter()
            .filter(|(_, v)| v.abs() > 1e100 || (*v != 0.0 && v.abs() < 1e-100))
            .collect();
        out.sort_by(|a, b| b.1.abs().log10().abs().total_cmp(&a.1.abs().log10().abs()));
        out
    }
}

/// How the mesh is made. A generated mesh (`rectangle`, `box`) takes `lo`, `hi` and a size
/// (`n`, `nx`, `ny`, `nz` or `h`) and may name regions by box; a Gmsh mesh takes `file`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// `rectangle`, `box` or `gmsh`.
    pub kind: MeshKind,
    /// Lower corner (rectangle, box).
    #[serde(default)]
    pub lo: Vec<f64>,
    /// Upper corner (rectangle, box).
    #[serde(default)]
    pub hi: Vec<f64>,
    /// Cells along the shortest edge; the other edges get proportionally many.
    #[serde(default)]
    pub n: Option<usize>,
    /// Cells along x (overrides `n` on that axis).
    #[serde(default)]
    pub nx: Option<usize>,
    /// Cells along y.
    #[serde(default)]
    pub ny: Option<usize>,
    /// Cells along z (box).
    #[serde(default)]
    pub nz: Option<usize>,
    /// Target cell size (a length): sets `n` from the shortest edge.
    #[serde(default)]
    pub h: Option<f64>,
    /// Gmsh file (for `kind = "gmsh"`), relative to the scene file.
    #[serde(default)]
    pub file: Option<String>,
    /// The coarse size the smoke tests run.
    #[serde(default)]
    pub smoke_n: Option<usize>,
    /// Named cell regions of a generated mesh, by box (`[[mesh.region]]`).
    #[serde(default, rename = "region")]
    pub regions: Vec<RegionSpec>,
    /// A body of revolution about the y axis: the 2D mesh is its meridian section, `x = r ≥ 0`
    /// (the radial displacement held on the axis; forces and charges are the whole body's).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub axisymmetric: bool,
    /// A generated mesh graded towards `lo`: along each axis, the last cell `grading` times the
    /// size of the first, the sizes growing geometrically between (one stretch per axis, or one
    /// for all; 1 is uniform), as for a contact zone at a corner of a large body. The stretch
    /// does not depend on the number of cells, so that `mesh.n` refines the same grading
    /// (every cell halves when `n` doubles).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grading: Option<Grading>,
    /// A box whose section is a quarter of a disc: the box `[0, R]² x [z₀, z₁]` made a quarter
    /// of the cylinder of radius R about the z axis (`mesh::round_quarter_section`, after any
    /// grading), its faces `left` (x = 0) and `front` (y = 0) the symmetry planes, `right` and
    /// `back` together its curved face: the 3D twin of a body of revolution.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cylinder: bool,
    /// A body of revolution's 3D view: `revolved.vtu`, the solution swept round the axis in
    /// this many segments (its cells are `revolve` times the meridian's; absent: not written).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub revolve: Option<usize>,
    /// A layered body (`[[mesh.layer]]`): layers stacked along the last axis (y in 2D, z in
    /// 3D) from `lo` to `hi`, their thicknesses summing to the height, each its own cell
    /// region and its own number of cells across; each interface a facet group of the mesh
    /// (an interior one: an electrode between two layers, a film's bottom electrode).
    #[serde(default, rename = "layer", skip_serializing_if = "Vec::is_empty")]
    pub layers: Vec<LayerSpec>,
    /// The polynomial order of the elements: 1 (three-node triangles, four-node tetrahedra) or
    /// 2 (six-node triangles, ten-node tetrahedra: a node at the midpoint of every edge of the
    /// generated or read mesh, straight-sided; on `mesh.cylinder`'s round face, on the
    /// cylinder). Absent: a generated mesh's order 1, a Gmsh file's own (a second-order file's
    /// cells on a curved boundary curved, mapped through their nodes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
}

/// One layer of a layered body (`[[mesh.layer]]`), from the bottom up.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LayerSpec {
    /// The cell region the layer's cells make (materials refer to it; layers may share one).
    pub region: String,
    /// Its thickness along the stacking axis (a length).
    pub thickness: f64,
    /// Cells across it (default: the mesh's cell count along the stacking axis shared out by
    /// thickness, at least 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n: Option<usize>,
    /// The name of the facet group at its bottom, the interface with the layer below (default
    /// `REGIONBELOW_REGION`); the first layer's bottom is the mesh's own bottom group.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interface: Option<String>,
}

/// `mesh.grading`: one stretch (last cell over first) for every axis, or one per axis.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Grading {
    /// The same ratio along every axis.
    One(f64),
    /// A ratio per axis.
    PerAxis(Vec<f64>),
}

impl Grading {
    /// The stretches given (one, or one per axis).
    pub fn ratios(&self) -> Vec<f64> {
        match self {
            Grading::One(q) => vec![*q],
            Grading::PerAxis(v) => v.clone(),
        }
    }
}

impl MeshSpec {
    /// A rectangle `[lo, hi]` of P1 triangles, `n` cells along its shorter edge.
    pub fn rectangle(lo: [f64; 2], hi: [f64; 2], n: usize) -> Self {
        Self::generated(MeshKind::Rectangle, lo.to_vec(), hi.to_vec(), n)
    }

    /// A box `[lo, hi]` of P1 tetrahedra, `n` cells along its shortest edge.
    pub fn cuboid(lo: [f64; 3], hi: [f64; 3], n: usize) -> Self {
        Self::generated(MeshKind::Box, lo.to_vec(), hi.to_vec(), n)
    }

    /// A mesh the caller hands over (to [`crate::solve`]) with the scene.
    pub fn given() -> Self {
        Self::generated(MeshKind::Given, vec![], vec![], 0)
    }

    /// A Gmsh file (MSH 4.1), relative to the scene file.
    pub fn gmsh(file: &str) -> Self {
        MeshSpec {
            file: Some(file.into()),
            ..Self::generated(MeshKind::Gmsh, vec![], vec![], 0)
        }
    }

    fn generated(kind: MeshKind, lo: Vec<f64>, hi: Vec<f64>, n: usize) -> Self {
        MeshSpec {
            kind,
            lo,
            hi,
            n: (n > 0).then_some(n),
            nx: None,
            ny: None,
            nz: None,
            h: None,
            file: None,
            smoke_n: None,
            regions: vec![],
            axisymmetric: false,
            grading: None,
            cylinder: false,
            revolve: None,
            layers: vec![],
            order: None,
        }
    }

    /// The cells across each layer of a layered body (none without layers): each layer's `n`,
    /// or the count along the stacking axis shared out by thickness (at least 1 each).
    pub fn layer_cells(&self) -> Vec<usize> {
        if self.layers.is_empty() {
            return vec![];
        }
        let along = self.cells_per_axis_plain().last().copied().unwrap_or(1);
        let height: f64 = self.layers.iter().map(|l| l.thickness).sum();
        self.layers
            .iter()
            .map(|l| {
                l.n.unwrap_or_else(|| (along as f64 * l.thickness / height).round().max(1.0) as usize)
            })
            .collect()
    }

    /// The facet group at the bottom of layer `k >= 1` (its interface with the layer below):
    /// its `interface`, or `LOWER_UPPER` after the two layers' regions, with `_k` added where
    /// another interface of the stack would take that name too (a stack's alternate layers).
    pub fn interface_name(&self, k: usize) -> String {
        let default = |k: usize| format!("{}_{}", self.layers[k - 1].region, self.layers[k].region);
        match &self.layers[k].interface {
            Some(name) => name.clone(),
            None => {
                let name = default(k);
                let taken = (1..self.layers.len()).filter(|&j| j != k).any(|j| {
                    self.layers[j].interface.as_deref() == Some(name.as_str())
                        || (self.layers[j].interface.is_none() && default(j) == name)
                });
                if taken {
                    format!("{name}_{k}")
                } else {
                    name
                }
            }
        }
    }

    /// The dimension of a generated mesh (`None` for a Gmsh file or a given mesh: known once it
    /// is read or handed over).
    pub fn dim(&self) -> Option<usize> {
        match self.kind {
            MeshKind::Rectangle => Some(2),
            MeshKind::Box => Some(3),
            MeshKind::Gmsh | MeshKind::Given => None,
        }
    }

    /// The overrides (`--set`) that size a generated mesh by `n`: `mesh.n = n` for the axes
    /// without a count of their own (where there are any), and `n` for each count the scene
    /// gives (`mesh.nx`, `ny`, `nz`, each layer's `n`), which `mesh.n` does not reach. Empty
    /// for a Gmsh or given mesh.
    pub fn sized(&self, n: usize) -> Vec<String> {
        if matches!(self.kind, MeshKind::Gmsh | MeshKind::Given) {
            return vec![];
        }
        let mut out: Vec<String> = [("nx", self.nx), ("ny", self.ny), ("nz", self.nz)]
            .iter()
            .take(self.lo.len())
            .filter(|(_, c)| c.is_some())
            .map(|(k, _)| format!("mesh.{k}={n}"))
            .collect();
        for k in (0..self.layers.len()).filter(|&k| self.layers[k].n.is_some()) {
            out.push(format!("mesh.layer.{k}.n={n}"));
        }
        if self.counted_axes().contains(&None) {
            out.push(format!("mesh.n={n}"));
        }
        out
    }

    /// For each axis of a generated mesh, what fixes its count of cells where something does
    /// (`mesh.nx`, `ny`, `nz`, along a stack every layer's `n`): `None` for the axes `mesh.n`
    /// or `mesh.h` size.
    pub fn counted_axes(&self) -> Vec<Option<&'static str>> {
        let d = self.lo.len().min(3);
        let layered = !self.layers.is_empty() && self.layers.iter().all(|l| l.n.is_some());
        [("mesh.nx", self.nx), ("mesh.ny", self.ny), ("mesh.nz", self.nz)]
            .into_iter()
            .take(d)
            .enumerate()
            .map(|(k, (name, count))| match (count, k + 1 == d && layered) {
                (Some(_), _) => Some(name),
                (None, true) => Some("the layers' mesh.layer.n"),
                (None, false) => None,
            })
            .collect()
    }

    /// [`MeshSpec::sized`] at the scene's smoke size (`smoke_n`, 4 where it gives none): the
    /// size of the verification's and the tests' runs of every shipped scene.
    pub fn smoke(&self) -> Vec<String> {
        self.sized(self.smoke_n.unwrap_or(4))
    }

    /// Cells per axis of a generated mesh from `n` (along the shortest edge), `h`, `nx`, `ny`,
    /// `nz` (8 along the shortest edge when none is given); along the stacking axis of a layered
    /// body, the layers' cells together.
    pub fn cells_per_axis(&self) -> Vec<usize> {
        let mut out = self.cells_per_axis_plain();
        if let Some(last) = out.last_mut().filter(|_| !self.layers.is_empty()) {
            *last = self.layer_cells().iter().sum();
        }
        out
    }

    /// [`MeshSpec::cells_per_axis`] without the layers' counts.
    fn cells_per_axis_plain(&self) -> Vec<usize> {
        let lens: Vec<f64> = self.lo.iter().zip(&self.hi).map(|(a, b)| b - a).collect();
        let shortest = lens.iter().cloned().fold(f64::INFINITY, f64::min);
        let n = match (self.h, self.n) {
            (Some(h), _) => (shortest / h).round().max(1.0) as usize,
            (None, Some(n)) => n,
            (None, None) => 8,
        };
        let mut out: Vec<usize> = lens
            .iter()
            .map(|l| ((l / shortest) * n as f64).round().max(1.0) as usize)
            .collect();
        for (k, o) in [self.nx, self.ny, self.nz].iter().enumerate() {
            if let (Some(v), Some(slot)) = (o, out.get_mut(k)) {
                *slot = *v;
            }
        }
        out
    }
}

/// A named region of a generated mesh: the cells whose centroid lies in the box `[lo, hi]`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    /// The region's name (materials refer to it).
    pub name: String,
    /// Lower corner of the box.
    pub lo: Vec<f64>,
    /// Upper corner of the box.
    pub hi: Vec<f64>,
}

/// A material on a region: its constants given, or a crystal of the library by name
/// (`crystal`), or its datasheet (`datasheet`), the last two resolved into `c`, `e` and
/// `permittivity` when the scene is read (in the unit system `units` names).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(try_from = "crystals::MaterialInput")]
pub struct MaterialSpec {
    /// The region (`body` = every cell of a generated mesh).
    pub region: String,
    /// `crystal-6mm` or `isotropic`.
    pub model: MaterialModel,
    /// Elastic constants `[c11, c12, c13, c33, c44, c66]` (crystal-6mm).
    #[serde(default)]
    pub c: Vec<f64>,
    /// Piezoelectric constants `[e31, e33, e15]` (crystal-6mm).
    #[serde(default)]
    pub e: Vec<f64>,
    /// Permittivity: `[eps11, eps33]` (crystal-6mm) or `[eps]` (isotropic; omitted or 0: no
    /// electric unknowns).
    #[serde(default)]
    pub permittivity: Vec<f64>,
    /// Poling direction (global coordinates, 3 components; crystal-6mm).
    #[serde(default)]
    pub poling: Vec<f64>,
    /// Young's modulus (isotropic).
    #[serde(default)]
    pub young: Option<f64>,
    /// Poisson's ratio (isotropic).
    #[serde(default)]
    pub poisson: Option<f64>,
    /// Multiplies the piezoelectric constants (`material.coupling_scale`; crystal-6mm; default 1).
    #[serde(default)]
    pub coupling_scale: Option<f64>,
    /// The library's crystal whose constants `c`, `e`, `permittivity` are
    /// (`material.crystal`: PZT-4, PZT-5A, PZT-5H, BaTiO3, AlN).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crystal: Option<String>,
    /// The datasheet (strain-charge form) whose conversion `c`, `e`, `permittivity` are.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub datasheet: Option<Datasheet>,
    /// The unit system of a crystal by name or of a datasheet's conversion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<CrystalUnits>,
}

impl MaterialSpec {
    /// The constants of a validated spec in its crystal frame (the coupling not yet scaled).
    pub(crate) fn crystal(&self) -> fe_assembly::Crystal {
        use fe_assembly::Crystal;
        match self.model {
            MaterialModel::Crystal6mm => {
                let (c, e, p) = (&self.c, &self.e, &self.permittivity);
                Crystal::hexagonal_6mm([c[0], c[1], c[2], c[3], c[4], c[5]], [e[0], e[1], e[2]], [p[0], p[1]])
            }
            MaterialModel::Isotropic => Crystal::isotropic(
                self.young.unwrap_or_default(),
                self.poisson.unwrap_or_default(),
                self.permittivity.first().copied().unwrap_or(0.0),
            ),
        }
    }

    /// A poled 6mm crystal on `region`: `c = [c11, c12, c13, c33, c44, c66]`,
    /// `e = [e31, e33, e15]`, `permittivity = [eps11, eps33]`, poled along `poling`.
    pub fn crystal_6mm(region: &str, c: [f64; 6], e: [f64; 3], permittivity: [f64; 2], poling: [f64; 3]) -> Self {
        MaterialSpec {
            c: c.to_vec(),
            e: e.to_vec(),
            permittivity: permittivity.to_vec(),
            poling: poling.to_vec(),
            ..Self::bare(region, MaterialModel::Crystal6mm)
        }
    }

    /// An isotropic elastic solid on `region` (no electric unknowns).
    pub fn isotropic(region: &str, young: f64, poisson: f64) -> Self {
        MaterialSpec {
            young: Some(young),
            poisson: Some(poisson),
            ..Self::bare(region, MaterialModel::Isotropic)
        }
    }

    fn bare(region: &str, model: MaterialModel) -> Self {
        MaterialSpec {
            region: region.into(),
            model,
            c: vec![],
            e: vec![],
            permittivity: vec![],
            poling: vec![],
            young: None,
            poisson: None,
            coupling_scale: None,
            crystal: None,
            datasheet: None,
            units: None,
        }
    }

    /// The library's crystal `name` on `region` (its constants in `units`), poled along
    /// `poling`; `None` where the library has no such crystal ([`CRYSTALS`]).
    pub fn named(region: &str, name: &str, units: CrystalUnits, poling: [f64; 3]) -> Option<Self> {
        let crystal = named_crystal(name)?;
        let (c, e, permittivity) = crystal.constants.in_units(units);
        Some(MaterialSpec {
            c,
            e,
            permittivity,
            poling: poling.to_vec(),
            crystal: Some(crystal.name.into()),
            units: Some(units),
            ..Self::bare(region, MaterialModel::Crystal6mm)
        })
    }
}

/// Dirichlet conditions on a boundary group: any of a whole displacement `u`, single components
/// `ux`, `uy`, `uz` (rollers), and the potential `phi`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DirichletSpec {
    /// Boundary group.
    pub group: String,
    /// Prescribed displacement (all components), if any.
    #[serde(default)]
    pub u: Option<Vec<f64>>,
    /// Prescribed x component alone (a roller), if any.
    #[serde(default)]
    pub ux: Option<f64>,
    /// Prescribed y component alone, if any.
    #[serde(default)]
    pub uy: Option<f64>,
    /// Prescribed z component alone, if any.
    #[serde(default)]
    pub uz: Option<f64>,
    /// Prescribed potential, if any.
    #[serde(default)]
    pub phi: Option<f64>,
    /// A floating terminal: the group's potential is unknown (one value over the group) and
    /// the charge on it is this (the negative of the flux `∫ D·ν ds` out of the body through
    /// it; 0 for an open circuit). Instead of `phi`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
}

impl DirichletSpec {
    /// The displacement component `k` (0 x, 1 y, 2 z) it prescribes, if it does: of `u`
    /// given whole, or `ux`, `uy`, `uz` alone (a roller).
    pub fn component(&self, k: usize) -> Option<f64> {
        let whole = self.u.as_ref().and_then(|u| u.get(k)).copied();
        whole.or([self.ux, self.uy, self.uz].get(k).copied().flatten())
    }
}

/// The scene's tractions: one table `[load]`, or an array `[[load]]`.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Loads {
    /// `[load]`.
    One(LoadSpec),
    /// `[[load]]`.
    Many(Vec<LoadSpec>),
}

impl Loads {
    /// Every load.
    pub fn all(&self) -> &[LoadSpec] {
        match self {
            Loads::One(l) => std::slice::from_ref(l),
            Loads::Many(v) => v,
        }
    }
}

impl From<LoadSpec> for Loads {
    fn from(l: LoadSpec) -> Self {
        Loads::One(l)
    }
}

impl Scene {
    /// The scene's tractions (none, one or several).
    pub fn loads(&self) -> &[LoadSpec] {
        self.load.as_ref().map_or(&[], Loads::all)
    }
}

/// A uniform traction `p * direction` on a group.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Boundary group.
    pub group: String,
    /// Magnitude (`load.p`).
    pub p: f64,
    /// Unit direction.
    pub direction: Vec<f64>,
}

/// The scene's electrodes: one table `[electrode]`, or an array `[[electrode]]`.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Electrodes {
    /// `[electrode]`.
    One(ElectrodeSpec),
    /// `[[electrode]]`.
    Many(Vec<ElectrodeSpec>),
}

impl Electrodes {
    /// Every electrode.
    pub fn all(&self) -> &[ElectrodeSpec] {
        match self {
            Electrodes::One(e) => std::slice::from_ref(e),
            Electrodes::Many(v) => v,
        }
    }

    /// Every electrode, to change.
    pub fn all_mut(&mut self) -> &mut [ElectrodeSpec] {
        match self {
            Electrodes::One(e) => std::slice::from_mut(e),
            Electrodes::Many(v) => v,
        }
    }
}

impl From<ElectrodeSpec> for Electrodes {
    fn from(e: ElectrodeSpec) -> Self {
        Electrodes::One(e)
    }
}

impl Scene {
    /// The scene's electrodes (none, one or several).
    pub fn electrodes(&self) -> &[ElectrodeSpec] {
        self.electrode.as_ref().map_or(&[], Electrodes::all)
    }
}

/// An electrode: the part of a boundary group inside a range of x, at a voltage or floating,
/// made a boundary group of its own (its `name`: the scene's terminal).
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ElectrodeSpec {
    /// Boundary group the electrode lies on.
    pub group: String,
    /// Voltage (`electrode.v`); or `charge`, not both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v: Option<f64>,
    /// A floating electrode: its potential unknown (one value over it), the charge on it this
    /// (0 for an open circuit), as a floating `dirichlet.charge`. Instead of `v`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
    /// Only facets whose nodes have `x_range[0] <= x <= x_range[1]`.
    #[serde(default)]
    pub x_range: Option<Vec<f64>>,
    /// The group the electrode makes, its name as a terminal (default: `electrode` for the
    /// first, `electrode-2`, `electrode-3`, ... for the others).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
}

impl ElectrodeSpec {
    /// An electrode on the whole of `group` at the voltage `v`.
    pub fn at(group: &str, v: f64) -> Self {
        ElectrodeSpec {
            group: group.into(),
            v: Some(v),
            ..Default::default()
        }
    }

    /// The group the `k`-th electrode of a scene makes (0-based): its `name`, or `electrode`,
    /// `electrode-2`, ...
    pub fn group_name(&self, k: usize) -> String {
        match (&self.name, k) {
            (Some(n), _) => n.clone(),
            (None, 0) => "electrode".into(),
            (None, k) => format!("electrode-{}", k + 1),
        }
    }
}

/// The scene's contact groups: one table `[contact]`, or an array `[[contact]]`.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
// a scene holds one of these, read once: its size is no matter, a box would only obscure it
#[allow(clippy::large_enum_variant)]
pub enum Contacts {
    /// `[contact]`.
    One(ContactSpec),
    /// `[[contact]]`.
    Many(Vec<ContactSpec>),
}

impl Contacts {
    /// Every contact group.
    pub fn all(&self) -> &[ContactSpec] {
        match self {
            Contacts::One(c) => std::slice::from_ref(c),
            Contacts::Many(v) => v,
        }
    }
}

impl From<ContactSpec> for Contacts {
    fn from(c: ContactSpec) -> Self {
        Contacts::One(c)
    }
}

/// Contact with a rigid, non-conductive foundation.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Boundary group in contact.
    pub group: String,
    /// `none`, `signorini`, `tresca` or `coulomb`.
    pub law: ContactLaw,
    /// Coulomb coefficient F (Coulomb only).
    #[serde(default, serialize_with = "zero_when_absent")]
    pub friction: Option<f64>,
    /// Tresca slip bound S (Tresca only).
    #[serde(default, serialize_with = "zero_when_absent")]
    pub slip_bound: Option<f64>,
    /// Tresca's slip bound varying along the zone (Tresca only; in place of `slip_bound`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_bound_profile: Option<SlipBoundProfile>,
    /// Initial gap g (uniform part).
    #[serde(default)]
    pub gap: f64,
    /// Curvature `1/R` of a parabolic gap, `g(x) = gap + |x - c|²_t / (2R)` with `|·|_t` the
    /// distance along the contact face from `gap_center` (a body of radius R on a flat
    /// foundation, as in Hertz's problem); 0 by default.
    #[serde(default)]
    pub gap_curvature: f64,
    /// The point `c` of the parabolic gap (default: the origin).
    #[serde(default)]
    pub gap_center: Option<Vec<f64>>,
    /// Outward normal of the contact face.
    pub normal: Vec<f64>,
    /// A deformable foundation (normal compliance, `λ_n = k [u_n - g]₊^m`); absent: a rigid
    /// one (Signorini's conditions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<ComplianceSpec>,
    /// Coulomb's coefficient constant (`coulomb`, the default) or falling with the slip
    /// (`slip-weakening`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_law: Option<FrictionLaw>,
    /// Slip weakening: the coefficient at no slip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_static: Option<f64>,
    /// Slip weakening: the coefficient once slid far (`≤ friction_static`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_dynamic: Option<f64>,
    /// Slip weakening: the slip over which the coefficient falls (`> 0`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_length: Option<f64>,
    /// Slip weakening: `linear` (the default) or `exponential`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weakening: Option<WeakeningForm>,
    /// The electric condition on the zone: `insulated` (the default), `conductive`,
    /// `conducting`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electric: Option<ElectricCondition>,
    /// `φ_F`, the potential of a conductive or conducting foundation (V; 0 by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub foundation_potential: Option<f64>,
    /// `σ_c ≥ 0`, a conductive foundation's conductance (flux per unit potential and unit
    /// pressure, or unit penetration under normal compliance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub conductance: Option<f64>,
    /// A floating conducting foundation or indenter (`electric = "conducting"` or
    /// `"conductive"`): the charge
    /// it carries (as run.json's `indenter.charge`; 0 for an open circuit), its potential one
    /// more unknown, found with the contact solution (`foundation_potential` is where the
    /// search starts).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
    /// A rigid indenter of a given shape (the obstacle), instead of a flat or parabolic gap.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indenter: Option<IndenterSpec>,
}

/// A rigid indenter (`contact.indenter`): its shape, its tip and how far the tip is pushed
/// along the contact normal into the body. The gap of a contact point `x` is measured along the
/// contact normal `n` (small deformations): `g(x) = gap + (tip - x)·n + h(ρ) - depth`, `ρ` the
/// distance of `x` from the indenter's axis (through the tip along `n`).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IndenterSpec {
    /// The shape.
    pub shape: IndenterShape,
    /// Sphere, paraboloid, cylinder: R; punch: its radius a.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Cone: the semi-vertical angle, degrees (0 < θ < 90).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_angle: Option<f64>,
    /// Profile: `[[ρ, h], ...]`, ρ from 0 increasing, `h(0) = 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<Vec<[f64; 2]>>,
    /// The tip's position before it is pushed (default: the origin; on a body of revolution
    /// the axis, `[0, z]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip: Option<Vec<f64>>,
    /// Cylinder in 3D: the direction of its axis (in the face's plane).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Vec<f64>>,
    /// How far the tip is pushed into the body along `-n` (depth control; a load path's `gap`
    /// factor scales it with `contact.gap`); under force control, where the search for the
    /// depth starts.
    #[serde(default)]
    pub depth: f64,
    /// Force control: the total normal force the indenter carries (> 0); its depth is then an
    /// unknown, found with the contact solution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force: Option<f64>,
}

impl IndenterSpec {
    /// The half-space's [`Profile`](crate::halfspace::Profile) of this indenter; `Err` (why,
    /// in words) for a shape that is not one of revolution, a missing radius or angle, or a
    /// tabulated profile that falls from its tip outward.
    fn half_space_profile(&self) -> Result<crate::halfspace::Profile, String> {
        use crate::halfspace::Profile;
        let need = |v: Option<f64>| v.ok_or_else(|| "the indenter's radius or angle is missing".to_string());
        Ok(match self.shape {
            IndenterShape::Paraboloid => Profile::Paraboloid {
                radius: need(self.radius)?,
            },
            IndenterShape::Sphere => Profile::Sphere {
                radius: need(self.radius)?,
            },
            IndenterShape::Cone => Profile::Cone {
                half_angle: need(self.half_angle)?,
            },
            IndenterShape::Punch => Profile::Punch {
                radius: need(self.radius)?,
            },
            IndenterShape::Profile => {
                let table = self.profile.clone().ok_or("the profile is missing")?;
                // Sneddon's solution presses a disc: the profile rises from its tip outward
                // (a profile that dips touches a ring first, and its contact is no disc)
                if let Some(w) = table.windows(2).find(|w| w[1][1] < w[0][1]) {
                    return Err(format!(
                        "contact.indenter.profile falls from h = {} at ρ = {} to h = {} at ρ = {}, and the half-space's closed form needs a profile that rises from its tip (its contact a disc)",
                        w[0][1], w[0][0], w[1][1], w[1][0]
                    ));
                }
                Profile::Tabulated(table)
            }
            IndenterShape::Plane | IndenterShape::Cylinder => {
                return Err(format!("a {} is no axisymmetric indenter", self.shape));
            }
        })
    }
}

impl Scene {
    /// The half-space problem of the scene's indenter: the body's [`HalfSpace`], the indenter's
    /// [`Profile`] and its electric [`Tip`]; `Err` (why, in words) where no closed form applies: a
    /// plane body, friction, a compliant bed, a conductive (finite-conductance) tip, several
    /// materials, a crystal not poled along the axis, an indenter off the axis or without an
    /// axisymmetric profile or with one that falls from its tip outward. `electric`: whether
    /// the run has electric unknowns.
    ///
    /// [`HalfSpace`]: crate::halfspace::HalfSpace
    /// [`Profile`]: crate::halfspace::Profile
    /// [`Tip`]: crate::halfspace::Tip
    pub(crate) fn half_space_problem(
        &self,
        electric: bool,
    ) -> Result<
        (
            crate::halfspace::HalfSpace,
            crate::halfspace::Profile,
            crate::halfspace::Tip,
        ),
        String,
    > {
        use crate::halfspace::{HalfSpace, Tip};
        let zones = self.zones();
        let [c] = zones[..] else {
            return Err(match zones.len() {
                0 => "it needs [contact]".into(),
                n => format!("the body has {n} contact zones, and the half-space's has one, its indenter's"),
            });
        };
        let ind = c.indenter.as_ref().ok_or("it needs a [contact.indenter]")?;
        let [m] = &self.material[..] else {
            return Err("it needs one material".into());
        };
        if !self.mesh.axisymmetric {
            return Err("it needs a body of revolution (mesh.axisymmetric = true)".into());
        }
        if c.law != ContactLaw::Signorini || c.compliance.is_some() {
            return Err(
                "it is frictionless on a rigid indenter: contact.law = \"signorini\", no contact.compliance".into(),
            );
        }
        if !ind.tip.as_deref().and_then(|t| t.first()).is_none_or(|x| *x == 0.0) {
            return Err("the indenter's tip must lie on the axis (contact.indenter.tip = [0, z])".into());
        }
        let profile = ind.half_space_profile()?;
        let mut crystal = m.crystal();
        let scale = m.coupling_scale.unwrap_or(1.0);
        crystal
            .e
            .iter_mut()
            .flatten()
            .for_each(|x| *x *= if electric { scale } else { 0.0 });
        if !electric {
            crystal.permittivity = [[0.0; 3]; 3];
        }
        // the half-space's inward normal is -n (the axis, y); a crystal poled along it, either way
        let inward = -c.normal.get(1).copied().unwrap_or(0.0);
        let along = match m.model {
            MaterialModel::Isotropic => 1.0,
            MaterialModel::Crystal6mm => {
                let p = &m.poling;
                let len = p.iter().map(|x| x * x).sum::<f64>().sqrt();
                if p.len() != 3 || (p[0].abs() + p[2].abs()) > 1e-12 * len {
                    return Err("the crystal must be poled along the axis (material.poling = [0, ±1, 0])".into());
                }
                p[1].signum() * inward.signum()
            }
        };
        let body = HalfSpace::from_crystal(&crystal).map_err(|e| e.to_string())?;
        let body = if along < 0.0 { body.reversed() } else { body };
        let tip = match (electric, c.electric.unwrap_or(ElectricCondition::Insulated)) {
            (false, _) | (true, ElectricCondition::Insulated) => Tip::Insulating,
            (true, ElectricCondition::Conducting) => match c.charge {
                Some(charge) => Tip::Floating { charge },
                None => Tip::Conducting {
                    potential: c.foundation_potential.unwrap_or(0.0),
                },
            },
            (true, ElectricCondition::Conductive) => {
                return Err(
                    "a conductive tip (finite conductance) has no closed form; use \"insulated\" or \"conducting\""
                        .into(),
                );
            }
        };
        Ok((body, profile, tip))
    }
}

impl IndenterSpec {
    /// An indenter of `shape` pushed in by `depth`, its tip at the origin, no other key (a
    /// shape's radius, angle or profile to be set).
    pub fn new(shape: IndenterShape, depth: f64) -> Self {
        IndenterSpec {
            shape,
            radius: None,
            half_angle: None,
            profile: None,
            tip: None,
            axis: None,
            depth,
            force: None,
        }
    }

    /// The point `x` in the indenter's frame: its distance along the normal `n` from the tip,
    /// and its distance `ρ` from the indenter's axis (across a cylinder's axis).
    pub fn local(&self, x: &[f64; 3], n: &[f64; 3]) -> (f64, f64) {
        let tip = self.tip.as_deref().unwrap_or_default();
        let d: Vec<f64> = (0..3).map(|k| x[k] - tip.get(k).copied().unwrap_or(0.0)).collect();
        let along: f64 = (0..3).map(|k| d[k] * n[k]).sum();
        let mut across: Vec<f64> = (0..3).map(|k| d[k] - along * n[k]).collect();
        if let (IndenterShape::Cylinder, Some(axis)) = (self.shape, self.axis.as_deref()) {
            // the distance across the cylinder's axis: remove the component along it
            let len = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
            let t: Vec<f64> = (0..3).map(|k| axis.get(k).copied().unwrap_or(0.0) / len).collect();
            let along_axis: f64 = (0..3).map(|k| across[k] * t[k]).sum();
            across.iter_mut().zip(&t).for_each(|(a, t)| *a -= along_axis * t);
        }
        (along, across.iter().map(|a| a * a).sum::<f64>().sqrt())
    }

    /// The height `h(ρ)` of the shape above its tip at the distance `ρ ≥ 0` from its axis;
    /// `None` beyond the shape's reach (a sphere's radius, a punch's, a profile's last point).
    /// The keys are those [`Scene::validate`] checked.
    pub fn height(&self, rho: f64) -> Option<f64> {
        let r = self.radius.unwrap_or(0.0);
        match self.shape {
            IndenterShape::Plane => Some(0.0),
            // `ρ (ρ / 2R)`: no overflow of ρ² before the division
            IndenterShape::Paraboloid => Some(rho * (rho / (2.0 * r))),
            IndenterShape::Sphere | IndenterShape::Cylinder => (rho <= r).then(|| sphere_height(r, rho)),
            IndenterShape::Cone => Some(rho / self.half_angle.unwrap_or(45.0).to_radians().tan()),
            IndenterShape::Punch => (rho <= r).then_some(0.0),
            IndenterShape::Profile => {
                let table = self.profile.as_deref().unwrap_or_default();
                let k = table.windows(2).position(|w| rho <= w[1][0])?;
                let ([r0, h0], [r1, h1]) = (table[k], table[k + 1]);
                Some(h0 + (h1 - h0) * (rho - r0) / (r1 - r0))
            }
        }
    }
}

/// The height `R - √(R² - ρ²)` of a sphere of radius `R` above its tip at `0 ≤ ρ ≤ R` from its
/// axis, evaluated without cancellation as `ρ² / (R + √(R² - ρ²))`, and without overflow in
/// the ratio `x = ρ / R ∈ [0, 1]` as `ρ x / (1 + √(1 - x) √(1 + x))` (the direct form loses
/// every digit once `ρ² < ε R²`, and `R²` overflows past 1e154).
pub fn sphere_height(r: f64, rho: f64) -> f64 {
    let x = (rho / r).min(1.0);
    rho * (x / (1.0 + (1.0 - x).sqrt() * (1.0 + x).sqrt()))
}

/// Tresca's slip bound varying along the contact zone (`contact.slip_bound_profile`): piecewise
/// linear in the point's coordinate `s = x · along` (`along` a direction, not normalised:
/// `[1, 0]` reads `x`), through `value[k]` at `at[k]` (increasing), constant beyond the ends.
/// A wear track, a lubricated patch, a bound that follows the pressure of a known solution.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SlipBoundProfile {
    /// The direction along which the bound varies (the mesh's dimension).
    pub along: Vec<f64>,
    /// The coordinates of the profile's points, increasing.
    pub at: Vec<f64>,
    /// The bound at each (`>= 0`).
    pub value: Vec<f64>,
}

impl SlipBoundProfile {
    /// The bound at the point `x`.
    pub fn at_point(&self, x: [f64; 3]) -> f64 {
        let s: f64 = self.along.iter().zip(x).map(|(a, x)| a * x).sum();
        let k = self.at.partition_point(|&t| t <= s);
        match k {
            0 => self.value[0],
            k if k == self.at.len() => self.value[k - 1],
            k => {
                let (t0, t1) = (self.at[k - 1], self.at[k]);
                let (v0, v1) = (self.value[k - 1], self.value[k]);
                // halved: the differences of coordinates near the largest numbers stay finite
                let w = (s / 2.0 - t0 / 2.0) / (t1 / 2.0 - t0 / 2.0);
                v0 * (1.0 - w) + v1 * w
            }
        }
    }
}

/// Normal compliance: the foundation's pressure `λ_n = k [u_n - g]₊^m` at the penetration
/// `u_n - g` (Oden and Martins 1985; docs/theory.md).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ComplianceSpec {
    /// `k > 0`: pressure per unit penetration to the power `m` (the scene's units: GPa per
    /// m^m in the scaled scenes).
    pub stiffness: f64,
    /// `m ≥ 1` (1 by default: a linear spring bed).
    #[serde(default = "one")]
    pub exponent: f64,
}

fn one() -> f64 {
    1.0
}

impl ContactSpec {
    /// Contact on `group` with outward normal `normal`, initial gap 0.
    pub fn new(group: &str, law: ContactLaw, normal: &[f64]) -> Self {
        ContactSpec {
            group: group.into(),
            law,
            friction: None,
            slip_bound: None,
            slip_bound_profile: None,
            gap: 0.0,
            gap_curvature: 0.0,
            gap_center: None,
            normal: normal.to_vec(),
            compliance: None,
            friction_law: None,
            friction_static: None,
            friction_dynamic: None,
            slip_length: None,
            weakening: None,
            electric: None,
            foundation_potential: None,
            conductance: None,
            charge: None,
            indenter: None,
        }
    }

    /// The radius of the curved body of Hertz's solution: `1 / gap_curvature`, or an
    /// indenter's sphere or paraboloid radius; `None` for a flat or another shape.
    pub fn hertz_radius(&self) -> Option<f64> {
        match &self.indenter {
            Some(i) if matches!(i.shape, IndenterShape::Sphere | IndenterShape::Paraboloid) => i.radius,
            Some(_) => None,
            None => (self.gap_curvature > 0.0).then(|| 1.0 / self.gap_curvature),
        }
    }

    /// How far an indenter's tip is pushed in, read off the gaps of `points` as solved (a
    /// depth found under force control, or scaled along a path): `-(contact.gap - depth)`
    /// plus how far the points' gaps lie below the shape's.
    pub fn depth_at(&self, points: &contact::ContactPoints) -> f64 {
        match points.position.first() {
            Some(x) => self.depth_at_point(x, &points.normal[0], points.gap[0]),
            None => -self.uniform_gap(),
        }
    }

    /// The depth, as [`ContactSpec::depth_at`], from one of this group's points `x` (normal
    /// `n`) and its gap now.
    pub fn depth_at_point(&self, x: &[f64; 3], n: &[f64; 3], gap: f64) -> f64 {
        -self.uniform_gap() + self.gap_at(x, n).map_or(0.0, |g| g - gap)
    }

    /// The uniform part of the gap a load path's `gap` factor scales: `contact.gap` less an
    /// indenter's depth.
    pub fn uniform_gap(&self) -> f64 {
        self.gap - self.indenter.as_ref().map_or(0.0, |i| i.depth)
    }

    /// The gap at the face point `x` along the unit outward normal `n`; `None` where an
    /// indenter's shape does not reach. Without an indenter: `gap + |x - c|²_t / (2R)` (the
    /// parabola of `gap_curvature` about `gap_center`).
    pub fn gap_at(&self, x: &[f64; 3], n: &[f64; 3]) -> Option<f64> {
        let Some(ind) = &self.indenter else {
            let c = self.gap_center.as_deref().unwrap_or_default();
            let d: Vec<f64> = (0..3).map(|k| x[k] - c.get(k).copied().unwrap_or(0.0)).collect();
            let along: f64 = (0..3).map(|k| d[k] * n[k]).sum();
            let dist2 = (0..3).map(|k| d[k] * d[k]).sum::<f64>() - along * along;
            return Some(self.gap + 0.5 * self.gap_curvature * dist2.max(0.0));
        };
        let (along, rho) = ind.local(x, n);
        Some(self.gap - along + ind.height(rho)? - ind.depth)
    }

    /// The electric law of a conductive or conducting foundation, with its potential `φ_F`;
    /// `None` for an insulating one.
    pub fn electric_law(&self) -> Option<(contact::ElectricLaw, f64)> {
        let law = match self.electric? {
            ElectricCondition::Insulated => return None,
            ElectricCondition::Conductive => contact::ElectricLaw::Conductive {
                conductance: self.conductance.unwrap_or(0.0),
            },
            ElectricCondition::Conducting => contact::ElectricLaw::Conducting,
        };
        Some((law, self.foundation_potential.unwrap_or(0.0)))
    }

    /// The Coulomb coefficient F (0 where not given); under slip weakening, the static one
    /// (the stick start).
    pub fn friction(&self) -> f64 {
        match self.slip_weakening() {
            Some(w) => w.static_coefficient,
            None => self.friction.unwrap_or(0.0),
        }
    }

    /// The slip-weakening law, where `friction_law = "slip-weakening"` (the keys checked by
    /// [`Scene::validate`]; a missing one reads as 0).
    pub fn slip_weakening(&self) -> Option<contact::SlipWeakening> {
        (self.friction_law == Some(FrictionLaw::SlipWeakening)).then(|| contact::SlipWeakening {
            static_coefficient: self.friction_static.unwrap_or(0.0),
            dynamic_coefficient: self.friction_dynamic.unwrap_or(0.0),
            slip_length: self.slip_length.unwrap_or(0.0),
            form: match self.weakening.unwrap_or(WeakeningForm::Linear) {
                WeakeningForm::Linear => contact::Weakening::Linear,
                WeakeningForm::Exponential => contact::Weakening::Exponential,
            },
        })
    }

    /// The Tresca slip bound S (0 where not given).
    pub fn slip_bound(&self) -> f64 {
        self.slip_bound.unwrap_or(0.0)
    }
}

/// Solver choices.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// The strategy (default `newton-condensed`).
    #[serde(default = "default_strategy")]
    pub strategy: Strategy,
    /// Tolerance of the contact solve (complementarity residual; default 1e-10).
    #[serde(default = "default_tol")]
    pub tol: f64,
    /// `tight` (default) or `paper`.
    #[serde(default = "default_rule")]
    pub rule: Rule,
    /// PCG relative tolerance (`uzawa-schur-pcg` only; default 1e-12, or the paper's 1e-2 under
    /// its rule).
    #[serde(default)]
    pub pcg_tol: Option<f64>,
    /// The linear-algebra backend (default `faer`).
    #[serde(default = "default_backend")]
    pub backend: BackendChoice,
    /// Options for PETSc's database, as on PETSc's command line (`backend = "petsc"` only):
    /// `"-ksp_monitor -fieldsplit_u_pc_type hypre"`.
    #[serde(default)]
    pub petsc_options: Option<String>,
}

fn default_strategy() -> Strategy {
    Strategy::NewtonCondensed
}
fn default_tol() -> f64 {
    1e-10
}
fn default_rule() -> Rule {
    Rule::Tight
}
fn default_backend() -> BackendChoice {
    BackendChoice::Faer
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            strategy: default_strategy(),
            tol: default_tol(),
            rule: default_rule(),
            pcg_tol: None,
            backend: default_backend(),
            petsc_options: None,
        }
    }
}

/// The exact solution a scene can be checked against (docs/scenes.md section 6).
///
/// - `manufactured`: the smooth coupled solution of `fe_assembly::Exact::manufactured`,
///   prescribed on `groups` (default: every side of the generated mesh), with the body force
///   and charge that make it exact (one material).
/// - `affine`: `u = u0 + grad_u x`, `φ = phi0 + grad_phi · x`, prescribed on `groups` (a
///   patch test: P1 reproduces it to round-off).
/// - `hertz`: Hertz's frictionless cylinder on a half-plane (Johnson 1985, section 4.2),
///   from the contact reaction P, the gap's curvature 1/R and the isotropic material.
/// - `cattaneo-mindlin`: the same with a tangential force Q below F P (Johnson 1985, section
///   7.1): a central stick zone of half-width `c = a √(1 - Q/(F P))`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ExactSpec {
    /// Which solution.
    pub kind: ExactKind,
    /// Groups where an `affine` or `manufactured` solution is prescribed (default: every
    /// side of the generated rectangle or box).
    #[serde(default)]
    pub groups: Vec<String>,
    /// `affine`: the displacement at the origin.
    #[serde(default)]
    pub u0: Vec<f64>,
    /// `affine`: `∂_j u_k`, row `k`, `dim x dim` row-major.
    #[serde(default)]
    pub grad_u: Vec<f64>,
    /// `affine`: the potential at the origin.
    #[serde(default, serialize_with = "zero_when_absent")]
    pub phi0: Option<f64>,
    /// `affine`: `∇φ`.
    #[serde(default)]
    pub grad_phi: Vec<f64>,
    /// `manufactured-contact`: the face slides along the first tangent by
    /// `A (1 + sin(π t₀ / 2) / 2)`, this `A > 0` (absent: it sticks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip: Option<f64>,
}

impl ExactSpec {
    /// The groups where a field solution is prescribed: the given ones, else every side of
    /// the generated mesh.
    pub fn groups(&self, mesh: &MeshSpec) -> Vec<String> {
        if !self.groups.is_empty() {
            return self.groups.clone();
        }
        if self.kind == ExactKind::ManufacturedContact {
            // the contact face is the foundation's
            let sides: &[&str] = if mesh.dim() == Some(3) {
                &["left", "right", "top", "front", "back"]
            } else {
                &["left", "right", "top"]
            };
            return sides.iter().map(|g| g.to_string()).collect();
        }
        let sides: &[&str] = if mesh.dim() == Some(3) {
            &["left", "right", "bottom", "top", "front", "back"]
        } else {
            &["left", "right", "bottom", "top"]
        };
        sides.iter().map(|g| g.to_string()).collect()
    }

    /// Checks the lengths of an `affine` solution's data in dimension `dim` (empty means
    /// zero); a Gmsh mesh's dimension is known only once it is read, so the set-up calls this
    /// again.
    ///
    /// # Errors
    /// A [`SceneError`] on `exact` naming the lengths needed.
    pub fn check_lengths(&self, dim: usize) -> Result<(), SceneError> {
        let ok = |v: &[f64], n: usize| v.is_empty() || v.len() == n;
        if self.kind != ExactKind::Affine
            || (ok(&self.u0, dim) && ok(&self.grad_u, dim * dim) && ok(&self.grad_phi, dim))
        {
            Ok(())
        } else {
            Err(SceneError::new(
                "exact",
                format!(
                    "exact (affine) in {dim}D needs u0 of {dim}, grad_u of {} (row-major) and grad_phi of {dim} values",
                    dim * dim
                ),
            ))
        }
    }
}

/// Writes an absent optional number as 0, its meaning (the run.json of earlier versions wrote
/// every number of the scene).
fn zero_when_absent<S: serde::Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(v.unwrap_or(0.0))
}

/// A table or an array of tables (`[x]` or `[[x]]`), read as the one or the many: by the
/// value's shape, so that a bad entry's own error (an unknown law, a string for a number)
/// reaches the user, where serde's untagged enums say only that no variant matched.
fn one_or_many<'de, D, T, O>(deserializer: D, one: fn(T) -> O, many: fn(Vec<T>) -> O) -> Result<O, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    struct Shape<T, O>(fn(T) -> O, fn(Vec<T>) -> O);
    impl<'de, T: Deserialize<'de>, O> serde::de::Visitor<'de> for Shape<T, O> {
        type Value = O;
        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a table, or an array of tables")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<O, A::Error> {
            T::deserialize(serde::de::value::MapAccessDeserializer::new(map)).map(self.0)
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<O, A::Error> {
            Vec::<T>::deserialize(serde::de::value::SeqAccessDeserializer::new(seq)).map(self.1)
        }
    }
    deserializer.deserialize_any(Shape(one, many))
}

impl<'de> Deserialize<'de> for Loads {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        one_or_many(d, Loads::One, Loads::Many)
    }
}

impl<'de> Deserialize<'de> for Electrodes {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        one_or_many(d, Electrodes::One, Electrodes::Many)
    }
}

impl<'de> Deserialize<'de> for Contacts {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        one_or_many(d, Contacts::One, Contacts::Many)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path's frames by default: every instant up to 50 steps, at most 51 files beyond (the
    /// first, every `⌈(n - 1)/50⌉`-th, and the last), and `output_every` as given.
    #[test]
    fn a_path_writes_at_most_51_frames_by_default() {
        let frames = |spec: &PathSpec| {
            let n = spec.instants().len();
            (0..n).filter(|&k| spec.has_fields(k, n)).count()
        };
        for (steps, want) in [
            (1, 2),
            (30, 31),
            (50, 51),
            (51, 27),
            (100, 51),
            (101, 35),
            (1000, 51),
            (1001, 49),
        ] {
            let spec = PathSpec {
                t: vec![0.0, 1.0],
                steps: Some(steps),
                ..Default::default()
            };
            assert_eq!(frames(&spec), want, "{steps} steps");
            assert!(frames(&spec) <= DEFAULT_FRAMES + 1);
        }
        let every = |k| PathSpec {
            t: vec![0.0, 1.0],
            steps: Some(100),
            output_every: Some(k),
            ..Default::default()
        };
        let spec = every(1);
        assert_eq!(frames(&spec), 101);
        let spec = every(0);
        assert_eq!(frames(&spec), 1);
    }

    /// A sphere's height in the limits of its parameters: against the paraboloid `ρ²/2R` (its
    /// first term; the next, `ρ⁴/8R³`, below round-off once `ρ²/R² < 1e-16`) for radii up to
    /// the largest double, finite and monotone, `R` at the rim; and, where the direct form
    /// `R - √(R² - ρ²)` keeps its digits, equal to it. The direct form at R = 1e6 was off the
    /// paraboloid by 1.7e-5 (relative), and -inf past R = 1e154.
    #[test]
    fn a_slip_bound_profile_is_piecewise_linear_and_finite_at_the_ends_of_the_numbers() {
        let p = SlipBoundProfile {
            along: vec![1.0, 0.0],
            at: vec![0.0, 1.0, 3.0],
            value: vec![0.0, 1.0, 0.5],
        };
        for (x, want) in [
            (-1.0, 0.0),
            (0.0, 0.0),
            (0.25, 0.25),
            (1.0, 1.0),
            (2.0, 0.75),
            (3.0, 0.5),
            (9.0, 0.5),
        ] {
            assert!((p.at_point([x, 7.0, 0.0]) - want).abs() < 1e-15, "{x}");
        }
        // coordinates and directions near the largest numbers: no overflow to NaN
        let wide = SlipBoundProfile {
            along: vec![1e300, 0.0],
            at: vec![-1.7e308, 1.7e308],
            value: vec![0.0, 2.0],
        };
        for x in [-1e8, 0.0, 1.0, 1e8, f64::MAX] {
            let v = wide.at_point([x, 0.0, 0.0]);
            assert!((0.0..=2.0).contains(&v), "{x}: {v}");
        }
        assert!((wide.at_point([0.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_spheres_height_keeps_its_digits_for_any_radius() {
        for r in [1e-300, 1e-10, 1.0, 1e6, 1e154, 1e200, 1e300, f64::MAX] {
            for rho in [r * 1e-12, r * 1e-9] {
                let h = sphere_height(r, rho);
                let parabola = rho * (rho / r) / 2.0;
                assert!(
                    (h - parabola).abs() <= 4.0 * f64::EPSILON * parabola,
                    "R = {r:e}, ρ = {rho:e}: {h:e}"
                );
            }
            assert_eq!(sphere_height(r, r), r, "R = {r:e} at the rim");
            assert_eq!(sphere_height(r, 0.0), 0.0);
            let hs: Vec<f64> = (0..=100).map(|k| sphere_height(r, r / 100.0 * k as f64)).collect();
            assert!(hs.iter().all(|h| h.is_finite()), "R = {r:e}");
            assert!(hs.windows(2).all(|w| w[0] < w[1]), "R = {r:e}: not increasing");
        }
        for rho in [0.3, 0.6, 0.9, 0.99] {
            let direct = 1.0 - (1.0f64 - rho * rho).sqrt();
            assert!((sphere_height(1.0, rho) - direct).abs() <= 1e-15, "ρ = {rho}");
        }
        // the indenter's own height, the cylinder's the same across its axis
        let mut sphere = IndenterSpec::new(IndenterShape::Sphere, 0.0);
        sphere.radius = Some(1e6);
        assert_eq!(sphere.height(1.0), Some(sphere_height(1e6, 1.0)));
        assert_eq!(sphere.height(2e6), None);
    }

    /// A path's factor at its instants is the factor given, whatever its neighbours (the
    /// form `f₀ + s (f₁ - f₀)` gave 0 at the instant after 1e30), and between them finite and
    /// between its ends.
    #[test]
    fn a_paths_factor_is_exact_at_its_instants() {
        let (t, f) = ([0.0, 1.0, 2.0, 3.0], [1.0, 1.0, 1e30, 1.0]);
        for (x, y) in t.iter().zip(&f) {
            assert_eq!(interpolate(&t, &f, *x), *y);
        }
        let mid = interpolate(&t, &f, 2.5);
        assert!((mid - 5e29).abs() <= 1e-15 * 5e29, "{mid:e}");
        let huge = [f64::MAX, -f64::MAX];
        assert!(interpolate(&[0.0, 1.0], &huge, 0.5).is_finite());
        assert_eq!(interpolate(&t, &f, -1.0), 1.0);
        assert_eq!(interpolate(&t, &f, 9.0), 1.0);
        // instants near the largest double: their difference overflows, the mean does not
        let wide = [-1.7e308, 1.7e308];
        assert_eq!(interpolate(&wide, &[0.0, 1.0], 0.0), 0.5);
        let path = PathSpec {
            t: wide.to_vec(),
            load: Some(vec![0.0, 1.0]),
            steps: Some(4),
            ..Default::default()
        };
        let instants = path.instants();
        for (x, y) in instants.iter().zip([-1.7e308, -0.85e308, 0.0, 0.85e308, 1.7e308]) {
            assert!((x - y).abs() <= 1e-15 * 1.7e308, "{x:e} against {y:e}");
        }
        for (x, y) in instants.iter().zip([0.0, 0.25, 0.5, 0.75, 1.0]) {
            let load = path.factors(*x).load;
            assert!((load - y).abs() <= 1e-15, "{load} against {y}");
        }
    }

    /// A path's steps include every instant of `t` (a cycle's turning points: steps evenly
    /// spaced over the whole path stepped over them), shared over the legs by their durations.
    #[test]
    fn a_paths_steps_include_every_given_instant() {
        let path = |t: &[f64], steps| PathSpec {
            t: t.to_vec(),
            steps: Some(steps),
            ..Default::default()
        };
        let cycle = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(path(&cycle, 4).instants(), [0.0, 0.5, 1.0, 2.0, 3.0]);
        assert_eq!(path(&cycle, 3).instants(), cycle);
        let thirty = path(&cycle, 30).instants();
        assert_eq!(thirty.len(), 31);
        for (k, x) in thirty.iter().enumerate() {
            assert!((x - k as f64 / 10.0).abs() <= 1e-15 * 3.0, "{k}: {x}");
        }
        // each the nearest double to its decimal on this grid (the mean gave 2.9000000000000004)
        assert_eq!(thirty[29], 2.9);
        assert!(thirty.windows(2).all(|w| w[0] < w[1]));
        for given in cycle {
            assert!(thirty.contains(&given) && path(&cycle, 7).instants().contains(&given));
        }
        // uneven legs: steps by duration, 10 and 20 of 30
        let uneven = path(&[0.0, 1.0, 3.0], 30).instants();
        assert_eq!(uneven.len(), 31);
        assert_eq!(uneven[10], 1.0);
        assert_eq!(path(&[0.0, 1.0, 3.0], 30).leg_steps(30), [10, 20]);
        // a short leg keeps its step however long the others
        assert_eq!(path(&[0.0, 1e-9, 1.0], 5).leg_steps(5), [1, 4]);
    }
}
