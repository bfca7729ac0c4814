//! The stability study (`piezocontact stability`): the stiff and extreme cases of docs/scenes.md
//! section 5, each run in its own process (so that its peak memory is its own, and a failure
//! cannot take the study down), with the default strategy and, on the cases up to n = 128, the
//! paper's Uzawa + Schur PCG. Every case either converges (the residuals of its `run.json`
//! meet the tolerance, and what it must show, it shows: all separated for a gap of 1, all
//! stuck for F = 1e6, ...) or stops with the typed error it printed. The table goes to
//! `docs/stability.md`.

use super::child::run_with_limit;
use crate::DriverError;
use files::output::Outputs;
use problem::{RunReport, Strategy};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// What a case must show beyond convergence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    /// Converged, nothing more.
    Converged,
    /// Every contact point separated (no contact force).
    AllSeparated,
    /// Every contact point in contact and sticking.
    AllStick,
    /// Every contact point in contact and sliding (frictionless).
    AllSlip,
    /// Some contact, none separated.
    NoneSeparated,
    /// A typed refusal whose message holds this text (an input beyond what the solver
    /// honours, named as such).
    Refused(&'static str),
}

/// One extreme case: a shipped scene with overrides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    /// Short name.
    pub name: &'static str,
    /// What it stresses.
    pub why: &'static str,
    /// Shipped scene.
    pub scene: &'static str,
    /// Overrides for the default strategy.
    pub sets: &'static [&'static str],
    /// Overrides for the paper's strategy (a smaller mesh), or `None` where that run is left
    /// out (the fine cases).
    pub paper_sets: Option<&'static [&'static str]>,
    /// What the answer must show.
    pub expect: Expect,
    /// A fine case (left out by `--quick`).
    pub fine: bool,
}

impl Case {
    /// The case's overrides with the mesh brought down to a smoke size (for tests): `mesh.n`
    /// to 16, and an anisotropic `nx` x `ny` mesh to 128 x 1 (the same aspect ratio).
    pub fn smoke_sets(&self) -> Vec<String> {
        self.sets
            .iter()
            .map(|s| match s.split_once('=') {
                Some(("mesh.n", _)) => "mesh.n=16".to_string(),
                Some(("mesh.nx", _)) => "mesh.nx=128".to_string(),
                Some(("mesh.ny", _)) => "mesh.ny=1".to_string(),
                _ => s.to_string(),
            })
            .collect()
    }
}

/// The actuator with its electrodes replaced by a grounded bottom and a floating top carrying
/// `charge` (the last entry), under Coulomb friction with F = 0.05.
macro_rules! floating_top {
    ($charge:literal) => {
        [
            "mesh.n=64",
            "~electrode",
            "~dirichlet.0.phi",
            "~dirichlet.1.phi",
            "dirichlet.2.group=\"bottom\"",
            "dirichlet.2.phi=0.0",
            "dirichlet.3.group=\"top\"",
            "contact.friction=0.05",
            concat!("dirichlet.3.charge=", $charge),
        ]
    };
}
const FLOATING_TOP_SETS: [&str; 9] = floating_top!("0.05");
const FLOODED_TOP_SETS: [&str; 9] = floating_top!("1e6");

/// The cases of docs/scenes.md section 5 (bad input has its own corpus, `tests/bad-input`).
pub const CASES: &[Case] = &[
    Case {
        name: "coupling x10",
        why: "e x 10: the Schur complement drifts from A",
        scene: "paper-slip",
        sets: &["mesh.n=128", "material.coupling_scale=10"],
        paper_sets: Some(&["mesh.n=32", "material.coupling_scale=10"]),
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "coupling x100",
        why: "e x 100",
        scene: "paper-slip",
        sets: &["mesh.n=128", "material.coupling_scale=100"],
        paper_sets: Some(&["mesh.n=32", "material.coupling_scale=100"]),
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "coupling x1e6",
        why: "e x 1e6, near the largest coupling number honoured (docs/theory.md)",
        scene: "paper-slip",
        sets: &["mesh.n=128", "material.coupling_scale=1e6"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "coupling x1e8",
        why: "e x 1e8: beyond what double precision honours, refused by name",
        scene: "paper-slip",
        sets: &["mesh.n=128", "material.coupling_scale=1e8"],
        paper_sets: None,
        expect: Expect::Refused("coupling"),
        fine: false,
    },
    Case {
        name: "3D coupling x1e4",
        why: "e x 1e4 in 3D, F = 0.1 (at F = 0.6 the fixed point expands past e x 10: refused so)",
        scene: "paper-3d",
        sets: &["mesh.n=12", "material.coupling_scale=1e4", "contact.friction=0.1"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "roller",
        why: "left side on rollers (ux = 0) through a contact corner: a held tangent",
        scene: "paper",
        sets: &["mesh.n=128", "~dirichlet.0.u", "dirichlet.0.ux=0"],
        paper_sets: Some(&["mesh.n=32", "~dirichlet.0.u", "dirichlet.0.ux=0"]),
        expect: Expect::Converged, // the rollered side lifts off at its foot
        fine: false,
    },
    Case {
        name: "held by contact alone",
        why: "both sides on rollers: nothing holds the vertical translation but contact",
        scene: "paper",
        sets: &[
            "mesh.n=128",
            "~dirichlet.0.u",
            "dirichlet.0.ux=0",
            "~dirichlet.1.u",
            "dirichlet.1.ux=0",
        ],
        paper_sets: None,
        expect: Expect::Refused("a translation along [0.000, 1.000]"),
        fine: false,
    },
    Case {
        name: "nu = 0.4999",
        why: "near-incompressible isotropic body, E = 100, e = 0",
        scene: "near-incompressible",
        sets: &["mesh.n=128"],
        paper_sets: Some(&["mesh.n=32"]),
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "aspect 64",
        why: "1024 x 8 cells on the paper block",
        scene: "paper",
        sets: &["~mesh.n", "mesh.nx=1024", "mesh.ny=8"],
        paper_sets: Some(&["~mesh.n", "mesh.nx=512", "mesh.ny=4"]),
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "F = 0",
        why: "frictionless through the Coulomb law",
        scene: "paper",
        sets: &["mesh.n=128", "contact.friction=0"],
        paper_sets: Some(&["mesh.n=32", "contact.friction=0"]),
        expect: Expect::AllSlip,
        fine: false,
    },
    Case {
        name: "F = 1e-3",
        why: "almost frictionless",
        scene: "paper",
        sets: &["mesh.n=128", "contact.friction=1e-3"],
        paper_sets: Some(&["mesh.n=32", "contact.friction=1e-3"]),
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "F = 0.1",
        why: "stick and slip zones",
        scene: "paper",
        sets: &["mesh.n=128", "contact.friction=0.1"],
        paper_sets: Some(&["mesh.n=32", "contact.friction=0.1"]),
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "F = 0.6",
        why: "the paper's coefficient",
        scene: "paper",
        sets: &["mesh.n=128"],
        paper_sets: Some(&["mesh.n=32"]),
        expect: Expect::AllStick,
        fine: false,
    },
    Case {
        name: "F = 10",
        why: "large friction",
        scene: "paper",
        sets: &["mesh.n=128", "contact.friction=10"],
        paper_sets: Some(&["mesh.n=32", "contact.friction=10"]),
        expect: Expect::AllStick,
        fine: false,
    },
    Case {
        name: "F = 1e6",
        why: "huge friction",
        scene: "paper",
        sets: &["mesh.n=128", "contact.friction=1e6"],
        paper_sets: Some(&["mesh.n=32", "contact.friction=1e6"]),
        expect: Expect::AllStick,
        fine: false,
    },
    Case {
        name: "gap -1e-3",
        why: "initial penetration",
        scene: "paper",
        sets: &["mesh.n=128", "contact.gap=-1e-3"],
        paper_sets: Some(&["mesh.n=32", "contact.gap=-1e-3"]),
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "gap 1",
        why: "no contact at all",
        scene: "paper",
        sets: &["mesh.n=128", "contact.gap=1"],
        paper_sets: Some(&["mesh.n=32", "contact.gap=1"]),
        expect: Expect::AllSeparated,
        fine: false,
    },
    Case {
        name: "gap 1e-14",
        why: "a gap below round-off of the displacement",
        scene: "paper",
        sets: &["mesh.n=128", "contact.gap=1e-14"],
        paper_sets: Some(&["mesh.n=32", "contact.gap=1e-14"]),
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "layered",
        why: "PZT layer on a substrate 1e4 times softer",
        scene: "layered",
        sets: &["mesh.n=128"],
        paper_sets: Some(&["mesh.n=40"]),
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "SI units",
        why: "entries over 19 orders of magnitude",
        scene: "pzt5a-si",
        sets: &["mesh.n=128"],
        paper_sets: Some(&["mesh.n=32"]),
        expect: Expect::AllStick,
        fine: false,
    },
    Case {
        name: "n = 512",
        why: "2D, 1.6 million unknowns",
        scene: "paper",
        sets: &["mesh.n=512"],
        paper_sets: None,
        expect: Expect::NoneSeparated, // the points next to the clamped corners may slide on fine meshes
        fine: true,
    },
    Case {
        name: "soft bed",
        why: "normal compliance k = 0.1 GPa/m, 1e-3 of the block's stiffness c33 / H",
        scene: "paper-compliance",
        sets: &["mesh.n=128", "contact.compliance.stiffness=0.1"],
        // the paper's Uzawa projects onto Signorini's cone: compliance is refused by key
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "stiff bed",
        why: "normal compliance k = 1e14 GPa/m, 1e12 of c33 / H: tends to the rigid foundation",
        scene: "paper-compliance",
        sets: &["mesh.n=128", "contact.compliance.stiffness=1e14"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "bed alone",
        why: "sides on rollers, nothing holding the vertical translation but the bed (k = 100 GPa/m): springs in K taken out by a fixed point on the loads",
        scene: "paper-compliance",
        sets: &["mesh.n=128", "~dirichlet.0.u", "dirichlet.0.ux=0", "~dirichlet.1.u", "dirichlet.1.ux=0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "soft bed alone",
        why: "the bed alone holds the block, k = 0.1 GPa/m: it sinks 1e4 times as far as it deforms",
        scene: "paper-compliance",
        sets: &[
            "mesh.n=128",
            "~dirichlet.0.u",
            "dirichlet.0.ux=0",
            "~dirichlet.1.u",
            "dirichlet.1.ux=0",
            "contact.compliance.stiffness=0.1",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "stiff bed alone",
        why: "the bed alone holds the block, k = 1e14 GPa/m: springs held to 1e-2 of the body's own stiffness",
        scene: "paper-compliance",
        sets: &[
            "mesh.n=128",
            "~dirichlet.0.u",
            "dirichlet.0.ux=0",
            "~dirichlet.1.u",
            "dirichlet.1.ux=0",
            "contact.compliance.stiffness=1e14",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "quadratic bed",
        why: "normal compliance m = 2 (k = 1e4 GPa/m²): the law's slope vanishes at first touch",
        scene: "paper-compliance",
        sets: &[
            "mesh.n=128",
            "contact.compliance.stiffness=1e4",
            "contact.compliance.exponent=2",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "strong weakening",
        why: "slip weakening μ_s = 100 μ_d (0.1 -> 0.001 over 0.1 mm): a non-monotone law far from Coulomb's",
        scene: "paper-slip-weakening",
        sets: &["mesh.n=128", "contact.friction_dynamic=0.001"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "one zone weakens",
        why: "the corner's right wall weakening 0.3 -> 0.003 over 1e-5 beside its Coulomb top wall (0.3): each zone its own friction law, a steep fall",
        scene: "corner",
        sets: &[
            "mesh.n=64",
            "contact.0.law=\"coulomb\"",
            "contact.0.friction_law=\"slip-weakening\"",
            "contact.0.friction_static=0.3",
            "contact.0.friction_dynamic=0.003",
            "contact.0.slip_length=1e-5",
            "contact.1.law=\"coulomb\"",
            "contact.1.friction=0.3",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "Tresca beside Coulomb",
        why: "the corner's right wall under Tresca's bound 1e-6 (nearly frictionless) beside its top wall under Coulomb's 1.0: each zone its own friction law, far apart",
        scene: "corner",
        sets: &[
            "mesh.n=64",
            "contact.0.law=\"tresca\"",
            "contact.0.slip_bound=1e-6",
            "contact.1.law=\"coulomb\"",
            "contact.1.friction=1.0",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "pressed among walls",
        why: "a sphere pressed with a force on the corner's top beside its squeezing right wall: force control drives the indenter's points alone",
        scene: "corner",
        sets: &[
            "mesh.n=64",
            "~electrode",
            "contact.1.indenter={shape=\"sphere\",radius=2.0,force=0.05}",
            "contact.1.gap=0.0",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "one zone conducts",
        why: "the corner's right wall an ideal conductor at 0 beside its insulated top wall: one zone's potentials condensed with every zone's displacements",
        scene: "corner",
        sets: &[
            "mesh.n=64",
            "~electrode",
            "contact.0.electric=\"conducting\"",
            "contact.0.foundation_potential=0.0",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "long load path",
        why: "the actuator's voltage cycle in 1000 steps (friction on increments of 1/333 of a leg): one factorisation, the fields of every 250th step",
        scene: "actuator-cycle",
        sets: &["mesh.n=64", "path.steps=1000", "path.output_every=250"],
        // a path is solved on the condensed compliance: the paper's strategy is refused by key
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "weakening cycle",
        why: "the Mindlin-Deresiewicz cycle with slip weakening 0.5 -> 0.05 on the slip accumulated along the path",
        scene: "cattaneo-mindlin-cycle",
        sets: &[
            "mesh.n=96",
            "~contact.friction",
            "contact.friction_law=\"slip-weakening\"",
            "contact.friction_static=0.5",
            "contact.friction_dynamic=0.05",
            "contact.slip_length=0.002",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "sphere cycle 3D",
        why: "Mindlin-Deresiewicz in 3D at n = 16: 1089 contact points, 25 in contact",
        scene: "mindlin-sphere-cycle",
        sets: &["mesh.n=16", "path.output_every=6"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "sharp cone",
        why: "a cone of semi-angle 10° on a body of revolution: the pressure singular at the tip, a few points in contact",
        scene: "hertz-sphere",
        sets: &["mesh.n=160", "~exact", "contact.indenter={shape=\"cone\",half_angle=10.0,depth=0.01}"],
        // a body of revolution is solved on the condensed compliance by the default backend;
        // the paper's strategy takes no indenter of its own
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "punch edge",
        why: "a flat punch (a = 0.3): the pressure singular at its edge, every node under it in contact",
        scene: "hertz-sphere",
        sets: &["mesh.n=160", "~exact", "contact.indenter={shape=\"punch\",radius=0.3,depth=0.001}"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "Tresca step",
        why: "Tresca's bound along the zone jumping from 0 (free slip) to 1 (every point held) across 0.002 at the middle of the face: two laws side by side on one face",
        scene: "paper-tresca",
        sets: &[
            "mesh.n=128",
            "~contact.slip_bound",
            "contact.slip_bound_profile={along=[1.0,0.0],at=[0.999,1.001],value=[0.0,1.0]}",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "huge sphere",
        why: "a rigid sphere of radius 1e6 pushed 1e-7 into PZT-4 (contact radius 0.32, as the shipped R = 10 at 0.01): its height R - sqrt(R² - ρ²) evaluated without cancellation",
        scene: "indent-sphere",
        sets: &["mesh.n=160", "~exact", "contact.indenter={shape=\"sphere\",radius=1e6,depth=1e-7}"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "tiny sphere",
        why: "a rigid sphere of radius 1e-300 pushed 0.01 into PZT-4: only the node on its axis lies within its reach; the half-space's closed form is left out (it does not evaluate to a contact there) with the reason in run.json",
        scene: "indent-sphere",
        sets: &["mesh.n=160", "~exact", "contact.indenter={shape=\"sphere\",radius=1e-300,depth=0.01}"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "beyond reach",
        why: "indent-sphere-3d's clamped top pushed 0.5 onto a sphere pushed 0.01: the face comes down far beyond the points within 3 depths of the tip that the contact problem first holds; the run finds them touching and is solved again with every point",
        scene: "indent-sphere-3d",
        sets: &["mesh.n=24", "dirichlet.0.u=[0.0,0.0,-0.5]"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "path excursion",
        why: "paper-cycle's load factor 1, 1, 1e30, 1: friction's history after the excursion (tangential displacements of 7e12) leaves the last instant round-off; the path stops there",
        scene: "paper-cycle",
        sets: &["mesh.n=64", "path.t=[0.0,1.0,2.0,3.0]", "path.load=[1.0,1.0,1e30,1.0]", "~path.steps"],
        paper_sets: None,
        expect: Expect::Refused("friction's history"),
        fine: false,
    },
    Case {
        name: "mild excursion",
        why: "paper-cycle's load factor 1, 1, 1e4, 1: the history 1e4 times the last instant's own displacements, resolved to 1e-12",
        scene: "paper-cycle",
        sets: &["mesh.n=64", "path.t=[0.0,1.0,2.0,3.0]", "path.load=[1.0,1.0,1e4,1.0]", "~path.steps"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "conducting cycle",
        why: "paper-conducting's load and voltage cycled 0, 1, -1, 1 with Coulomb friction: the conducting foundation along a path, friction's history with the electric rows",
        scene: "paper-conducting",
        sets: &[
            "mesh.n=128",
            "path={t=[0.0,1.0,2.0,3.0],steps=12,load=[0.0,1.0,-1.0,1.0],voltage=[0.0,1.0,-1.0,1.0]}",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "grounded tip path",
        why: "a grounded conducting sphere pushed into PZT-4 along a 10-step depth path (path.gap): the force-depth curve with a conducting tip",
        scene: "indent-sphere",
        sets: &[
            "mesh.n=160",
            "~exact",
            "contact.electric=\"conducting\"",
            "path={t=[0.0,1.0],steps=10,gap=[0.0,1.0]}",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "open tip",
        why: "a floating conducting sphere on PZT-4 (contact.charge = 0): its potential found with the contact zone, no charge on it",
        scene: "indent-sphere",
        sets: &["mesh.n=160", "contact.electric=\"conducting\"", "contact.charge=0.0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "open tip, n = 240",
        why: "the open sphere at 1.5 times the shipped size: the widest member of the ideal conductor's family (docs/theory.md), its potential +1.7 % off the closed form against +3.9 % at 160",
        scene: "indent-sphere",
        sets: &["mesh.n=240", "contact.electric=\"conducting\"", "contact.charge=0.0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "open tip, n = 320",
        why: "the open sphere twice as fine: its potential converging to the closed form (-0.8 % against +3.9 % at 160)",
        scene: "indent-sphere",
        sets: &["mesh.n=320", "contact.electric=\"conducting\"", "contact.charge=0.0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "open tip, n = 640",
        why: "the open sphere four times as fine (+0.24 %)",
        scene: "indent-sphere",
        sets: &["mesh.n=640", "contact.electric=\"conducting\"", "contact.charge=0.0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "open punch, n = 640",
        why: "the open punch at four times the shipped size: no family (its radius is its edge), the potential converging (+0.54 % against +1.24 % at 160)",
        scene: "indent-punch",
        sets: &["mesh.n=640", "contact.electric=\"conducting\"", "contact.charge=0.0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "open cone, n = 640",
        why: "a floating conducting cone (semi-angle 70°) four times as fine as shipped: the widest member, its potential converging (-0.33 % against +1.80 % at 160)",
        scene: "indent-cone",
        sets: &["mesh.n=640", "contact.electric=\"conducting\"", "contact.charge=0.0"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "overcharged tip",
        why: "a floating conducting sphere given 11 times the grounded tip's charge: the potential that carries it lifts the body off",
        scene: "indent-sphere",
        sets: &["mesh.n=160", "contact.electric=\"conducting\"", "contact.charge=-1.0"],
        paper_sets: None,
        expect: Expect::Refused("lifts the body off"),
        fine: false,
    },
    Case {
        name: "floating electrode",
        why: "the actuator's top a floating terminal (charge 0.05) over a grounded bottom under Coulomb friction (F = 0.05): its potential found with a zone that sticks and slips",
        scene: "actuator",
        sets: &FLOATING_TOP_SETS,
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "flooded electrode",
        why: "the same floating top given a charge of 1e6 (about 3e7 times the first): its potential of 5e4 lifts the whole face off the foundation",
        scene: "actuator",
        sets: &FLOODED_TOP_SETS,
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "walls with friction",
        why: "the corner's two [[contact]] walls with Coulomb friction (F = 0.3) at n = 128: a node of both walls, each wall sticking and slipping",
        scene: "corner",
        sets: &[
            "mesh.n=128",
            "contact.0.law=\"coulomb\"",
            "contact.0.friction=0.3",
            "contact.1.law=\"coulomb\"",
            "contact.1.friction=0.3",
        ],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "feather force",
        why: "force control with 1e-9 of the sphere's Hertz force: the depth found a millionth of the face's size from first touch",
        scene: "hertz-sphere",
        sets: &["mesh.n=160", "~exact", "contact.indenter.depth=0.0", "contact.indenter.force=4.6e-10"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "heavy force",
        why: "force control with 1e4 times the sphere's Hertz force (a depth of about 4.4 R): the bracket grown far",
        scene: "hertz-sphere",
        sets: &["mesh.n=160", "~exact", "contact.indenter.depth=0.0", "contact.indenter.force=4.6e3"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "conducting tip",
        why: "a grounded conducting sphere on PZT-4: the tip's potential switches with the contact status",
        scene: "indent-sphere",
        sets: &["mesh.n=160", "contact.electric=\"conducting\""],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "no conductance",
        why: "a conductive foundation with σ_c = 0: the insulated answer",
        scene: "paper-conductive",
        sets: &["mesh.n=128", "contact.conductance=0"],
        // the paper's Uzawa holds no electric rows: electrical contact is refused by key
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "ideal conductance",
        why: "a conductive foundation with σ_c = 1e12: tends to the conducting one",
        scene: "paper-conductive",
        sets: &["mesh.n=128", "contact.conductance=1e12"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "conducting, lift-off",
        why: "an ideally conducting foundation at φ_F = -0.1 GV under the paper's load: where it touches, the potential lifts the block off",
        scene: "paper-conducting",
        sets: &["mesh.n=128", "contact.foundation_potential=-0.1"],
        paper_sets: None,
        // contact gives the potential that lifts, lift-off takes it away: no solution of the
        // ideal switch was found (the conductive law's is, 0.5 s: docs/theory.md)
        expect: Expect::Refused("may have no solution"),
        fine: false,
    },
    Case {
        name: "P2 nu = 0.4999",
        why: "quadratic elements on the near-incompressible body (locking moved, not cured: docs/performance.md)",
        scene: "near-incompressible",
        sets: &["mesh.n=64", "mesh.order=2"],
        paper_sets: None,
        expect: Expect::NoneSeparated,
        fine: false,
    },
    Case {
        name: "P2 coupling x1e6",
        why: "quadratic elements with e x 1e6: the coupling's stiffening on denser rows",
        scene: "paper-slip",
        sets: &["mesh.n=64", "mesh.order=2", "material.coupling_scale=1e6"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "P2 3D sphere",
        why: "a sphere on ten-node tetrahedra: the modified basis's points, narrowed to those within reach",
        scene: "indent-sphere-3d",
        sets: &["mesh.n=12", "mesh.order=2"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "P2 curved cylinder",
        why: "indent-sphere-3d on the quarter cylinder at order 2: curved ten-node tetrahedra on its round face, mapped through their nodes",
        scene: "indent-sphere-3d",
        sets: &["mesh.n=12", "mesh.order=2", "mesh.cylinder=true"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "P2 conducting tip",
        why: "a conducting sphere on a body of revolution at order 2: the points' potentials in the modified basis",
        scene: "indent-sphere",
        sets: &["mesh.n=64", "mesh.order=2", "contact.electric=\"conducting\""],
        paper_sets: None,
        expect: Expect::Converged,
        fine: false,
    },
    Case {
        name: "n = 1024",
        why: "2D, 6.3 million unknowns",
        scene: "paper",
        sets: &["mesh.n=1024"],
        paper_sets: None,
        expect: Expect::NoneSeparated,
        fine: true,
    },
    Case {
        name: "3D n = 32",
        why: "3D, 274 thousand unknowns",
        scene: "paper-3d",
        sets: &["mesh.n=32"],
        paper_sets: None,
        expect: Expect::Converged,
        fine: true,
    },
];

/// The outcome of one run of a case.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The case's name.
    pub case: String,
    /// Strategy.
    pub strategy: Strategy,
    /// Overrides used.
    pub sets: String,
    /// Unknowns (u + φ), 0 on failure.
    pub dofs: usize,
    /// Iterations, as a short text.
    pub iterations: String,
    /// Complementarity residual (NaN on failure).
    pub complementarity: f64,
    /// Equilibrium residual.
    pub equilibrium: f64,
    /// Run time (s), set-up to solution.
    pub seconds: f64,
    /// Peak resident memory of the run (MiB).
    pub peak_mib: f64,
    /// `converged, ...` or the error.
    pub outcome: String,
    /// Whether the outcome is what the case must give.
    pub as_expected: bool,
}

/// Checks what the case must show, from its report: `Ok` with the status counts, or what is
/// wrong.
pub fn check(expect: Expect, report: &RunReport) -> Result<String, String> {
    let c = &report.contact;
    let counts = format!("stick {}, slip {}, separated {}", c.n_stick, c.n_slip, c.n_separated);
    let (comp, tol) = (report.residuals.complementarity, report.solver.tol);
    if !report.residuals.converged_to_tolerance || !(comp <= tol) {
        return Err(format!(
            "not converged: complementarity {comp:.2e} (tolerance {tol:.0e})"
        ));
    }
    let ok = match expect {
        Expect::Converged => true,
        Expect::AllSeparated => c.n_separated == c.n_points,
        Expect::AllStick => c.n_stick == c.n_points,
        Expect::AllSlip => c.n_slip == c.n_points,
        Expect::NoneSeparated => c.n_separated == 0 && c.n_points > 0,
        Expect::Refused(_) => false,
    };
    if ok {
        Ok(counts)
    } else {
        Err(format!("{counts}: expected {expect:?}"))
    }
}

/// Where the cases run: the default backend in one process, or the PETSc backend on the ranks
/// of `mpirun -np ranks` (the program built with the feature `petsc`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// The default backend.
    Default,
    /// The PETSc backend on this many ranks.
    Petsc {
        /// MPI ranks.
        ranks: usize,
    },
}

/// `timeout`'s exit code where it stopped its command.
const TIMED_OUT: i32 = 124;

/// The command that runs `exe run` on `backend`: under `timeout` and `mpirun` for PETSc (mpirun
/// stops its ranks on timeout's SIGTERM, where a SIGKILL to it would leave them running).
fn command(exe: &Path, backend: Backend, limit: Duration) -> Command {
    match backend {
        Backend::Default => Command::new(exe),
        Backend::Petsc { ranks } => {
            let mut cmd = Command::new("timeout");
            cmd.args([
                "-s",
                "TERM",
                &limit.as_secs().to_string(),
                "mpirun",
                "--allow-run-as-root",
            ]);
            cmd.args([
                "--oversubscribe",
                "-x",
                "OPENBLAS_NUM_THREADS=1",
                "-np",
                &ranks.to_string(),
            ]);
            cmd.arg(exe);
            cmd
        }
    }
}

/// Runs one case with one strategy through `exe run`, in a scratch directory that is removed.
fn run_case(
    exe: &Path,
    backend: Backend,
    case: &Case,
    (strategy, sets): (Strategy, &[&str]),
    index: usize,
    limit: Duration,
) -> Row {
    let scratch = std::env::temp_dir().join(format!("piezocontact-stability-{}-{index}", std::process::id()));
    let mut cmd = command(exe, backend, limit);
    cmd.arg("run").arg(case.scene);
    if backend != Backend::Default {
        cmd.arg("--set").arg("solver.backend=\"petsc\"");
    }
    for s in sets {
        cmd.arg("--set").arg(s);
    }
    cmd.arg("--set").arg(format!("solver.strategy={strategy}"));
    cmd.arg("--out").arg(&scratch);
    let mut row = Row {
        case: case.name.into(),
        strategy,
        sets: sets.join(" "),
        dofs: 0,
        iterations: "-".into(),
        complementarity: f64::NAN,
        equilibrium: f64::NAN,
        seconds: f64::NAN,
        peak_mib: f64::NAN,
        outcome: String::new(),
        as_expected: false,
    };
    let started = std::time::Instant::now();
    let output = run_with_limit(cmd, limit + Duration::from_secs(30));
    let report = std::fs::read(scratch.join("run.json"))
        .ok()
        .and_then(|b| serde_json::from_slice::<RunReport>(&b).ok());
    let _ = std::fs::remove_dir_all(&scratch);
    match (output, report) {
        (Ok(out), Some(r)) if out.status.success() => {
            row.dofs = r.dofs.total();
            row.iterations = r.iterations.summary();
            row.complementarity = r.residuals.complementarity;
            row.equilibrium = r.residuals.equilibrium;
            row.seconds = r.timings_s.total;
            row.peak_mib = r.memory.peak_bytes as f64 / (1 << 20) as f64;
            match check(case.expect, &r) {
                Ok(counts) => {
                    row.outcome = format!("converged; {counts}");
                    row.as_expected = true;
                }
                Err(e) => row.outcome = format!("UNEXPECTED: {e}"),
            }
        }
        (Ok(out), _)
            if (out.status.code().is_none() || out.status.code() == Some(TIMED_OUT)) && started.elapsed() >= limit =>
        {
            row.seconds = started.elapsed().as_secs_f64();
            row.outcome = format!(
                "not finished in the study's time limit of {} s (stopped)",
                limit.as_secs()
            );
            // slow is not wrong: the paper's method on a hard case is allowed to take long
            row.as_expected = true;
        }
        (Ok(out), _) => {
            row.seconds = started.elapsed().as_secs_f64();
            let stderr = String::from_utf8_lossy(&out.stderr);
            let message = stderr
                .lines()
                .rev()
                .find(|l| l.starts_with("error:"))
                .unwrap_or("no error message")
                .trim_start_matches("error: ")
                .to_string();
            // a typed error is a sound outcome of an extreme case; a crash is not; a case that
            // must be refused must be refused for its reason
            let typed = out.status.code().is_some() && !stderr.contains("panicked");
            row.as_expected = typed
                && match case.expect {
                    Expect::Refused(why) => message.contains(why),
                    _ => true,
                };
            row.outcome = match (typed, row.as_expected) {
                (true, true) => format!("stopped with an error: {message}"),
                (true, false) => format!("UNEXPECTED error: {message}"),
                (false, _) => format!("CRASHED ({}): {message}", out.status),
            };
        }
        (Err(e), _) => row.outcome = format!("CRASHED: could not start {}: {e}", exe.display()),
    }
    row
}

/// Runs the cases (without the fine ones when `quick`) on `backend`, with the default strategy
/// and, where the case has one, the paper's strategy on its smaller mesh. `exe` is the
/// `piezocontact` binary.
pub fn study(exe: &Path, backend: Backend, quick: bool, limit: Duration, progress: &mut dyn FnMut(&str)) -> Vec<Row> {
    let mut rows = vec![];
    for case in CASES.iter().filter(|c| !(quick && c.fine)) {
        let mut runs = vec![(Strategy::NewtonCondensed, case.sets)];
        if let Some(p) = case.paper_sets {
            runs.push((Strategy::UzawaSchurPcg, p));
        }
        for (strategy, sets) in runs {
            // the limit is for the paper's strategy, which may crawl on a hard case; the default
            // strategy's runs (the fine cases among them) get 30 minutes at least
            let limit = if strategy == Strategy::UzawaSchurPcg {
                limit
            } else {
                limit.max(Duration::from_secs(1800))
            };
            let row = run_case(exe, backend, case, (strategy, sets), rows.len(), limit);
            progress(&format!(
                "{:14} {:17} {:>9} dofs  {:>26}  {:8.2} s  {:7.0} MiB  {}",
                row.case, row.strategy, row.dofs, row.iterations, row.seconds, row.peak_mib, row.outcome
            ));
            rows.push(row);
        }
    }
    rows
}

/// The Markdown page of a study.
pub fn markdown(rows: &[Row], command: &str) -> String {
    let mut s = String::from("# Stability: stiff and extreme cases\n\n");
    let _ = writeln!(
        s,
        "Written by `{command}` (do not edit by hand). Each case runs in its own process with the default strategy (`newton-condensed`) and, up to n = 128, with the paper's Uzawa + Schur PCG on a smaller mesh; tolerance 1e-10 on the complementarity residual; a run of the paper's strategy still going at the study's time limit is stopped and reported as such (the default strategy gets 30 minutes at least). Time: set-up to solution; memory: the run's peak resident set. An outcome is \"converged\" only where run.json's residuals meet the tolerance and the answer shows what the case must (all separated for a gap of 1, all stuck for large F, ...); a typed error is a sound outcome, a crash or a wrong answer is not.\n"
    );
    let cases = CASES;
    s.push_str("| case | what it stresses | strategy | mesh | unknowns | iterations | complementarity | equilibrium | time (s) | peak (MiB) | outcome |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let why = cases.iter().find(|c| c.name == r.case).map_or("", |c| c.why);
        // a run that stopped has no report: its numbers are left blank, not NaN
        let shown = |v: f64, text: String| if v.is_finite() { text } else { "-".into() };
        let _ = writeln!(
            s,
            "| {} | {} | {} | `{}` | {} | {} | {} | {} | {:.2} | {} | {} |",
            r.case,
            why,
            r.strategy,
            r.sets,
            if r.dofs > 0 { r.dofs.to_string() } else { "-".into() },
            r.iterations,
            shown(r.complementarity, format!("{:.1e}", r.complementarity)),
            shown(r.equilibrium, format!("{:.1e}", r.equilibrium)),
            r.seconds,
            shown(r.peak_mib, format!("{:.0}", r.peak_mib)),
            r.outcome
        );
    }
    let bad = rows.iter().filter(|r| !r.as_expected).count();
    let _ = writeln!(s, "\n{} runs, {} as expected, {bad} not.", rows.len(), rows.len() - bad);
    s
}

/// Runs the study on `backend` and writes `stability.md` into `dir` (`stability-petsc.md` for
/// the PETSc backend, the cases alone: the inputs' refusals are the scene's, the same on both);
/// an error if any run is not as expected.
pub fn write(
    exe: &Path,
    (backend, quick): (Backend, bool),
    limit: Duration,
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Row>, DriverError> {
    let rows = study(exe, backend, quick, limit, progress);
    let (inputs, name, ranks) = match backend {
        Backend::Default => (super::inputs::study(exe, progress), "stability.md", String::new()),
        Backend::Petsc { ranks } => (vec![], "stability-petsc.md", format!(" --ranks {ranks}")),
    };
    let command = format!(
        "piezocontact stability{} --limit {}{ranks}",
        if quick { " --quick" } else { "" },
        limit.as_secs()
    );
    let mut out = Outputs::documents(dir);
    let mut page = markdown(&rows, &command);
    match backend {
        Backend::Default => page += &super::inputs::markdown(&inputs),
        Backend::Petsc { ranks } => {
            let title = format!(
                "# Stability on the PETSc backend ({ranks} ranks): stiff and extreme cases\n\nThe cases of stability.md, each under `mpirun -np {ranks}` with `solver.backend = \"petsc\"`: the default strategy on MUMPS' condensed route, the paper's Uzawa on the Krylov route (one Krylov solve per step).\n"
            );
            page = page.replacen("# Stability: stiff and extreme cases\n", &title, 1);
        }
    }
    out.add(name, page.into_bytes());
    out.commit()?;
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| !r.as_expected)
        .map(|r| r.case.clone())
        .chain(
            inputs
                .iter()
                .filter(|r| !r.as_expected)
                .map(|r| format!("{} {:?}", r.input.scene, r.input.sets)),
        )
        .collect();
    if bad.is_empty() {
        Ok(rows)
    } else {
        Err(DriverError::Unexpected {
            what: "cases not as expected",
            items: bad,
        })
    }
}
