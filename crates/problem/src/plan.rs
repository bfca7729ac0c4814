//! The plan: what a run computes, decided from the scene and its materials before anything is
//! computed. The run reads its decisions from the plan and nowhere else: a part the plan leaves
//! out is not built (no electric unknowns, no contact boundary, no tangential multipliers, no
//! output file), and the printed plan is this same value.

use crate::scene::{choice, ComplianceSpec, ContactLaw, ContactSolver, MeshKind, Rule, Scene, Strategy};
use fe_assembly::Material;
use serde::{Deserialize, Serialize};
use std::fmt;

choice! {
    /// A file a run writes.
    pub enum Output ("output") {
        /// The report.
        RunJson = "run.json",
        /// The solution for ParaView.
        SolutionVtu = "solution.vtu",
        /// One row per contact point.
        ContactCsv = "contact.csv",
        /// The multipliers along the contact boundary (SVG and PNG).
        Multipliers = "multipliers.svg/png",
        /// The deformed mesh (SVG and PNG).
        Deformed = "deformed.svg/png",
        /// Contours of the potential (SVG and PNG).
        Potential = "potential.svg/png",
        /// A body of revolution's solution swept round its axis, a 3D view for ParaView
        /// (`mesh.revolve`).
        RevolvedVtu = "revolved.vtu",
    }
}

/// What a run will compute.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Plan {
    /// Spatial dimension.
    pub dim: usize,
    /// Whether electric unknowns exist (some coupling or electric data, on an electric material).
    pub electric: bool,
    /// The contact law (`none`: no contact boundary is built).
    pub contact_law: ContactLaw,
    /// Whether the tangential multipliers exist (friction).
    pub friction: bool,
    /// Whether the fixed point on the slip bound runs (Coulomb friction solved by a first-order
    /// strategy; Newton solves Coulomb's law directly).
    pub fixed_point: bool,
    /// The strategy.
    pub linear_strategy: Strategy,
    /// The stopping rule.
    pub rule: Rule,
    /// The files the run writes.
    pub outputs: Vec<Output>,
    /// The foundation's normal compliance, the first compliant zone's (absent: a rigid foundation, Signorini's
    /// conditions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<ComplianceSpec>,
    /// Whether every contact zone presses on the same foundation (the compliance above, or a
    /// rigid one); otherwise each zone on its own.
    #[serde(default = "shared", skip_serializing_if = "is_shared")]
    pub compliance_shared: bool,
    /// The zones whose friction weakens with the slip, each with its law (the others keep
    /// a constant coefficient).
    #[serde(skip)]
    pub weakening: Vec<(String, contact::SlipWeakening)>,
    /// The contact solve's complementarity tolerance (`solver.tol`).
    #[serde(skip)]
    pub tol: f64,
    /// The PCG's relative tolerance: `solver.pcg_tol`, else 1e-2 under the paper's rule (its
    /// Table 1) and 1e-12 under the tight rule.
    #[serde(skip)]
    pub pcg_tol: f64,
    /// Tresca's slip bound of each contact zone, in the scene's order (`contact.slip_bound`, or
    /// `contact.slip_bound_profile`; 0 where the law is not Tresca's).
    #[serde(skip)]
    pub slip_bounds: Vec<ZoneBound>,
}

pub use crate::scene::ZoneBound;

impl Plan {
    /// Decides what the run of `scene` needs, on a mesh of dimension `dim` with `materials`.
    pub fn new(scene: &Scene, dim: usize, materials: &[(String, Material)]) -> Plan {
        let coupling = materials.iter().any(|(_, m)| m.e.iter().any(|&x| x != 0.0));
        let electric = (coupling || electric_data(scene)) && materials.iter().any(|(_, m)| m.electric);
        let law = scene.contact_law();
        // friction on any contact group gives every point its tangential multipliers (a
        // frictionless group's coefficient is 0)
        // each zone by its own law (a Tresca zone may stand beside Coulomb's)
        let friction = scene.zones().into_iter().any(|c| match c.law {
            _ if law == ContactLaw::None => false,
            ContactLaw::Coulomb => c.friction() > 0.0,
            ContactLaw::Tresca => {
                c.slip_bound() > 0.0
                    || c.slip_bound_profile
                        .as_ref()
                        .is_some_and(|p| p.value.iter().any(|&v| v > 0.0))
            }
            _ => false,
        });
        let strategy = scene.solver.strategy;
        let mut outputs = vec![Output::RunJson, Output::SolutionVtu];
        if scene.mesh.revolve.is_some() {
            outputs.push(Output::RevolvedVtu);
        }
        if law != ContactLaw::None {
            outputs.extend([Output::ContactCsv, Output::Multipliers]);
        }
        // the pictures of the mesh are drawn in 2D, and on the face y = lo of a box
        if dim == 2 || scene.mesh.kind == MeshKind::Box {
            outputs.push(Output::Deformed);
            if electric {
                outputs.push(Output::Potential);
            }
        }
        Plan {
            dim,
            electric,
            contact_law: law,
            friction,
            fixed_point: law == ContactLaw::Coulomb
                && friction
                && matches!(strategy.contact_solver(), ContactSolver::FirstOrder { .. }),
            linear_strategy: strategy,
            rule: scene.solver.rule,
            outputs,
            compliance: scene
                .zones()
                .into_iter()
                .filter(|_| law != ContactLaw::None)
                .find_map(|c| c.compliance),
            compliance_shared: law == ContactLaw::None
                || scene
                    .zones()
                    .into_iter()
                    .all(|c| scene.active_contact().is_some_and(|f| f.compliance == c.compliance)),
            // a weakening law from a static coefficient of 0 is frictionless (its dynamic one,
            // at most the static, is 0 too): no tangential multipliers for it to act on
            weakening: scene
                .zones()
                .into_iter()
                .filter(|_| law == ContactLaw::Coulomb && friction)
                .filter_map(|c| Some((c.group.clone(), c.slip_weakening()?)))
                .collect(),
            tol: scene.solver.tol,
            pcg_tol: scene.solver.pcg_tol.unwrap_or(match scene.solver.rule {
                Rule::Paper => 1e-2,
                Rule::Tight => 1e-12,
            }),
            // each zone's Tresca bound; 0 where its law is not Tresca's (frictionless there)
            slip_bounds: scene
                .zones()
                .into_iter()
                .map(|c| match c.model().map(|m| m.friction) {
                    Some(crate::scene::Friction::Tresca(bound)) => bound,
                    _ => ZoneBound::Uniform(0.0),
                })
                .collect(),
        }
    }

    /// The plan's contact law on `points` (`group_of[i]`: point `i`'s contact zone, an index
    /// into the scene's contacts), as the contact crate takes it: frictionless without
    /// tangential multipliers, Tresca with each zone's bound at each of its points, else
    /// Coulomb.
    pub fn law(&self, points: &contact::ContactPoints, group_of: &[usize]) -> contact::Law {
        match (self.contact_law, self.friction) {
            (_, false) => contact::Law::Frictionless,
            (ContactLaw::Tresca, true) => contact::Law::Tresca(
                points
                    .position
                    .iter()
                    .zip(group_of)
                    .map(|(&x, &g)| self.slip_bounds.get(g).map_or(0.0, |b| b.at(x)))
                    .collect(),
            ),
            _ => contact::Law::Coulomb,
        }
    }

    /// Tangential components per contact point: `dim - 1` with friction, else 0.
    pub fn n_tangential(&self) -> usize {
        if self.friction {
            self.dim - 1
        } else {
            0
        }
    }

    /// Whether the run writes `output`.
    pub fn writes(&self, output: Output) -> bool {
        self.outputs.contains(&output)
    }
}

/// Whether the scene prescribes a non-zero potential (an electrode's voltage or a Dirichlet
/// potential) or a non-zero charge on a floating terminal: electric data that needs electric
/// unknowns even without coupling.
pub fn electric_data(scene: &Scene) -> bool {
    scene
        .electrodes()
        .iter()
        .any(|e| e.v.is_some_and(|v| v != 0.0) || e.charge.is_some_and(|q| q != 0.0))
        || scene
            .dirichlet
            .iter()
            .any(|d| d.phi.is_some_and(|p| p != 0.0) || d.charge.is_some_and(|q| q != 0.0))
}

/// The plan's words for its slip-weakening zones: each law, and its zone where the scene has
/// several.
fn weakening_words(zones: &[(String, contact::SlipWeakening)], several: bool) -> String {
    if zones.is_empty() {
        return String::new();
    }
    let laws: Vec<String> = zones
        .iter()
        .map(|(group, w)| {
            let law = format!(
                "{} -> {} over {:e}",
                w.static_coefficient, w.dynamic_coefficient, w.slip_length
            );
            if several {
                format!("{law} on `{group}`")
            } else {
                law
            }
        })
        .collect();
    format!(
        " with slip weakening ({}) by a fixed point on the coefficients",
        laws.join("; ")
    )
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let outputs: Vec<&str> = self.outputs.iter().map(|o| o.name()).collect();
        write!(
            f,
            "plan: {}D, electric unknowns: {}, contact: {}{}{}{}{}, linear: {}, rule: {}, outputs: {}",
            self.dim,
            if self.electric { "yes" } else { "left out" },
            self.contact_law,
            match (self.compliance, self.compliance_shared) {
                (Some(k), true) => format!(" on a compliant foundation (k = {:e}, m = {})", k.stiffness, k.exponent),
                (Some(_), false) => " on a compliant foundation in some zones (each zone its own)".into(),
                (None, _) => String::new(),
            },
            weakening_words(&self.weakening, self.slip_bounds.len() > 1),
            if self.friction { " (tangential multipliers)" } else { "" },
            if self.fixed_point { " + fixed point on S" } else { "" },
            self.linear_strategy,
            self.rule,
            outputs.join(", ")
        )
    }
}

/// `true` (a report written before zones had foundations of their own had one).
fn shared() -> bool {
    true
}

/// Whether `shared` is `true` (left out of the report: the common case).
fn is_shared(shared: &bool) -> bool {
    *shared
}
