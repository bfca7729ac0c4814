//! A scene's known solution (its `[exact]` section; docs/scenes.md section 6) and the errors a run
//! reports against it: the fields of a manufactured or affine solution (energy and L2 norms),
//! and the contact tractions of Hertz and Cattaneo-Mindlin (profile errors, the contact and
//! stick zones). The formulas of the contact solutions are in [`crate::analytical`].

use crate::analytical::{cattaneo_stick_half_width, cattaneo_traction, hertz, hertz_pressure, hertz_sphere};
use crate::scene::{ElectricCondition, ExactKind, Scene};
use contact::{ContactPoints, ContactSolution, Status};
use fe_assembly::{Discretization, Exact, Face, FaceConstants, FaceElectric, FrictionFn, Sliding};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// The potential of the contact face above the foundation's in the manufactured solution on a
/// conductive or insulated foundation (`φ - φ_F`, in the scene's unit: of the order of the
/// solution's own potentials, 10⁻² s).
const FACE_OFFSET: f64 = 1e-2;

/// A field solution set up for a run: the exact fields and the groups they are prescribed on.
pub struct FieldSolution {
    /// Which kind.
    pub kind: ExactKind,
    /// The exact `(u, φ)` with its loads and Dirichlet data.
    pub exact: Exact,
    /// The boundary groups it is prescribed on.
    pub groups: Vec<String>,
}

impl FieldSolution {
    /// The field solution of a validated `manufactured` or `affine` scene in dimension `dim`
    /// (`None` for other scenes).
    pub fn of(scene: &Scene, dim: usize) -> Option<FieldSolution> {
        let x = scene.exact.as_ref().filter(|x| x.kind.is_field())?;
        let pad = |v: &[f64], n: usize| -> Vec<f64> {
            let mut out = vec![0.0; n];
            out[..v.len().min(n)].copy_from_slice(&v[..v.len().min(n)]);
            out
        };
        let exact = if x.kind == ExactKind::Manufactured {
            Exact::manufactured(dim)
        } else if x.kind == ExactKind::ManufacturedContact {
            // validated: a box or rectangle, contact on its bottom face; a bed or an electric
            // face other than the conducting one under one 6mm crystal poled along the normal
            let c = scene.first_contact()?;
            let center = pad(c.gap_center.as_deref().unwrap_or_default(), 3);
            let s0 = scene.mesh.lo.get(dim - 1).copied().unwrap_or(0.0);
            let m = &scene.material[0];
            let at = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
            let electric = match c.electric.unwrap_or(ElectricCondition::Insulated) {
                ElectricCondition::Conducting => FaceElectric::Conducting,
                ElectricCondition::Conductive => FaceElectric::Conductive {
                    conductance: c.conductance.unwrap_or(0.0),
                    offset: FACE_OFFSET,
                },
                ElectricCondition::Insulated => FaceElectric::Conductive {
                    conductance: 0.0,
                    offset: FACE_OFFSET,
                },
            };
            let constants = FaceConstants {
                c33: at(&m.c, 3),
                c13: at(&m.c, 2),
                c44: at(&m.c, 4),
                e33: at(&m.e, 1),
                e31: at(&m.e, 0),
                eps33: at(&m.permittivity, 1),
            };
            let friction: FrictionFn = match c.slip_weakening() {
                Some(w) => Arc::new(move |s| [w.coefficient(s), w.slope(s), w.curvature(s)]),
                None => {
                    let f = c.friction();
                    Arc::new(move |_| [f, 0.0, 0.0])
                }
            };
            let face = Face {
                constants,
                bed: c.compliance.map(|k| (k.stiffness, k.exponent)),
                electric,
                sliding: x.slip.map(|amplitude| Sliding { amplitude, friction }),
            };
            let gap = (c.gap, c.gap_curvature, [center[0], center[1], center[2]]);
            Exact::on_foundation(dim, s0, gap, c.foundation_potential.unwrap_or(0.0), face)
        } else {
            let (u0, g, gp) = (pad(&x.u0, 3), pad(&x.grad_u, dim * dim), pad(&x.grad_phi, 3));
            let mut grad_u = [[0.0; 3]; 3];
            for k in 0..dim {
                for j in 0..dim {
                    grad_u[k][j] = g[k * dim + j];
                }
            }
            Exact::affine(
                dim,
                [u0[0], u0[1], u0[2]],
                grad_u,
                x.phi0.unwrap_or(0.0),
                [gp[0], gp[1], gp[2]],
            )
        };
        Some(FieldSolution {
            kind: x.kind,
            exact,
            groups: x.groups(&scene.mesh),
        })
    }

    /// The errors of the nodal solution `(u, φ)` against it.
    pub fn errors(&self, disc: &Discretization<'_>, u: &[[f64; 3]], phi: &[f64], electric: bool) -> ExactReport {
        self.report(&disc.error_norms(u, phi, &self.exact), electric)
    }

    /// The report of the error norms `e` (of the whole mesh: a run on pieces sums their
    /// squares over the ranks, `fe_assembly::ErrorNorms::from_squares`).
    pub fn report(&self, e: &fe_assembly::ErrorNorms, electric: bool) -> ExactReport {
        ExactReport::Field(FieldErrors {
            kind: self.kind,
            error: e.rel_energy(),
            error_name: if electric {
                "relative energy-norm error of (u, φ)"
            } else {
                "relative energy-norm error of u"
            }
            .into(),
            l2_u: e.l2_u,
            l2_phi: e.l2_phi,
            energy: e.energy,
            rel_l2_u: e.rel_l2_u(),
            rel_l2_phi: if electric { e.rel_l2_phi() } else { 0.0 },
            rel_energy: e.rel_energy(),
        })
    }
}

/// The `exact` section of run.json.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum ExactReport {
    /// Against a field solution.
    Field(FieldErrors),
    /// Against Hertz or Cattaneo-Mindlin.
    Contact(ContactErrors),
    /// Against the half-space's closed form of an axisymmetric indenter (`half-space`).
    HalfSpace(Box<HalfSpaceReport>),
}

impl ExactReport {
    /// The kind of solution.
    pub fn kind(&self) -> ExactKind {
        match self {
            ExactReport::Field(f) => f.kind,
            ExactReport::Contact(c) => c.kind,
            ExactReport::HalfSpace(_) => ExactKind::HalfSpace,
        }
    }

    /// The headline error (what [`ExactKind::measures`] says).
    pub fn error(&self) -> f64 {
        match self {
            ExactReport::Field(f) => f.error,
            ExactReport::Contact(c) => c.error,
            ExactReport::HalfSpace(h) => h.error,
        }
    }

    /// What the headline error measures, in words.
    pub fn error_name(&self) -> &str {
        match self {
            ExactReport::Field(f) => &f.error_name,
            ExactReport::Contact(c) => &c.error_name,
            ExactReport::HalfSpace(h) => &h.error_name,
        }
    }
}

/// The errors of a run against a field solution.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct FieldErrors {
    /// `manufactured` or `affine`.
    pub kind: ExactKind,
    /// The relative energy-norm error.
    pub error: f64,
    /// What `error` measures.
    pub error_name: String,
    /// L2 error of u.
    pub l2_u: f64,
    /// L2 error of φ.
    pub l2_phi: f64,
    /// Energy-norm error.
    pub energy: f64,
    /// Relative L2 error of u.
    pub rel_l2_u: f64,
    /// Relative L2 error of φ (0 without electric unknowns).
    pub rel_l2_phi: f64,
    /// Relative energy-norm error.
    pub rel_energy: f64,
}

/// The errors of a run against Hertz's or Cattaneo-Mindlin's solution.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ContactErrors {
    /// `hertz` or `cattaneo-mindlin`.
    pub kind: ExactKind,
    /// The contact reaction P (per unit length).
    pub load_p: f64,
    /// The cylinder's radius R.
    pub radius: f64,
    /// Hertz's half-width.
    pub a: f64,
    /// Hertz's peak pressure.
    pub p0: f64,
    /// The half-width of the computed contact zone.
    pub a_h: f64,
    /// The centre of the computed contact zone.
    pub contact_centre: f64,
    /// `|a_h - a| / a`.
    pub a_error: f64,
    /// `|max λ_n - p0| / p0`.
    pub peak_error: f64,
    /// Relative l2 error of the pressure profile over `|x| ≤ 1.5 a`.
    pub pressure_error: f64,
    /// The headline error: the pressure profile's (Hertz) or the traction profile's.
    pub error: f64,
    /// What `error` measures.
    pub error_name: String,
    /// A body of revolution under a sphere or paraboloid pushed in by `depth` (Hertz's sphere):
    /// the force Hertz gives at that depth, `(4/3) E* √R d^(3/2)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_hertz: Option<f64>,
    /// `|P - force_hertz| / force_hertz`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_error: Option<f64>,
    /// Hertz's contact radius at that depth, `√(R d)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a_depth: Option<f64>,
    /// Cattaneo-Mindlin: the tangential reaction Q.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_q: Option<f64>,
    /// Cattaneo-Mindlin: the stick half-width `c`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c: Option<f64>,
    /// Cattaneo-Mindlin: the half-width of the computed stick zone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c_h: Option<f64>,
    /// Cattaneo-Mindlin: `|c_h - c| / a`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c_error: Option<f64>,
    /// Cattaneo-Mindlin: the centre of the computed stick zone, in units of `a`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stick_offset: Option<f64>,
}

/// Relative discrete l2 error of `values` against `exact(x)` over the points with
/// `|x| ≤ reach`.
fn profile_error(xs: &[f64], values: &[f64], reach: f64, exact: impl Fn(f64) -> f64) -> f64 {
    let (mut err, mut norm) = (0.0, 0.0);
    for (&x, &v) in xs.iter().zip(values) {
        if x.abs() <= reach {
            let e = exact(x);
            err += (v - e).powi(2);
            norm += e * e;
        }
    }
    (err / norm).sqrt()
}

/// Half the extent and the centre of the points whose flag is set.
fn extent(xs: &[f64], flag: impl Fn(usize) -> bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, &x) in xs.iter().enumerate() {
        if flag(i) {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    if lo > hi {
        (0.0, 0.0)
    } else {
        ((hi - lo) / 2.0, (hi + lo) / 2.0)
    }
}

/// The `exact` section of a Hertz or Cattaneo-Mindlin scene (validated: one isotropic
/// material, a curved gap): the reactions `p` (normal) and `q` (tangential), Hertz's `a` and
/// `p0`, the measured contact and stick zones, and the profile errors. `None` for other scenes.
///
/// # Errors
/// On `exact.kind` where nothing touches (`p` not positive): a closed form of a contact zone
/// measures none, and its relative errors would be NaN.
pub fn contact_errors(
    scene: &Scene,
    points: &ContactPoints,
    sol: &ContactSolution,
    p: f64,
    q: f64,
) -> Result<Option<ExactReport>, crate::SetupError> {
    let Some(x) = scene.exact.as_ref().filter(|x| !x.kind.is_field()) else {
        return Ok(None);
    };
    if !(p > 0.0) {
        return Err(crate::SetupError::new(
            "exact.kind",
            format!(
                "exact.kind `{}`: nothing touches (the contact force is {p:e}), and its closed form measures a contact zone: push the body past its gap, or remove [exact] (`--set ~exact`)",
                x.kind
            ),
        ));
    }
    Ok(contact_errors_of(scene, x, points, sol, (p, q)))
}

/// [`contact_errors`] where something touches.
fn contact_errors_of(
    scene: &Scene,
    x: &crate::ExactSpec,
    points: &ContactPoints,
    sol: &ContactSolution,
    (p, q): (f64, f64),
) -> Option<ExactReport> {
    let c = scene.first_contact()?;
    let m = scene.material.first()?;
    let (young, poisson) = (m.young?, m.poisson?);
    let radius = c.hertz_radius()?;
    let x0 = c.gap_center.as_ref().and_then(|v| v.first().copied()).unwrap_or(0.0);
    let xs: Vec<f64> = points.position.iter().map(|p| p[0] - x0).collect();
    let sphere = scene.mesh.axisymmetric;
    let (a, p0) = if sphere {
        // Johnson (4.22): a³ = 3PR/(4E*), p0 = 3P/(2πa²)
        let a = hertz_sphere(p, radius, young, poisson);
        (a, 3.0 * p / (2.0 * std::f64::consts::PI * a * a))
    } else {
        hertz(p, radius, young, poisson)
    };
    let (a_h, centre) = if sphere {
        // the contact zone is a disc about the axis: its radius
        let r = xs
            .iter()
            .enumerate()
            .filter(|&(i, _)| sol.lambda.normal[i] > 0.0)
            .fold(0.0, |m: f64, (_, x)| m.max(*x));
        (r, 0.0)
    } else {
        extent(&xs, |i| sol.lambda.normal[i] > 0.0)
    };
    // pushed in by d = -(the uniform gap): Hertz's force and radius at that depth (Johnson
    // (4.23): d = a²/R, P = (4/3) E* R^(1/2) d^(3/2))
    let depth = c.depth_at(points);
    let e_star = young / (1.0 - poisson * poisson);
    let at_depth = (sphere && depth > 0.0).then(|| {
        (
            4.0 / 3.0 * e_star * radius.sqrt() * depth.powf(1.5),
            (radius * depth).sqrt(),
        )
    });
    let pressure_error = profile_error(&xs, &sol.lambda.normal, 1.5 * a, |x| hertz_pressure(x, a, p0));
    let peak = sol.lambda.normal.iter().cloned().fold(0.0, f64::max);
    let mut out = ContactErrors {
        kind: x.kind,
        load_p: p,
        radius,
        a,
        p0,
        a_h,
        contact_centre: centre,
        a_error: (a_h - a).abs() / a,
        peak_error: (peak - p0).abs() / p0,
        pressure_error,
        error: pressure_error,
        error_name: x.kind.measures().into(),
        force_hertz: at_depth.map(|(f, _)| f),
        force_error: at_depth.map(|(f, _)| (p - f).abs() / f),
        a_depth: at_depth.map(|(_, a)| a),
        load_q: None,
        c: None,
        c_h: None,
        c_error: None,
        stick_offset: None,
    };
    if x.kind == ExactKind::CattaneoMindlin {
        let f = c.friction();
        let cc = cattaneo_stick_half_width(a, q, f, p);
        let (c_h, stick_centre) = extent(&xs, |i| sol.status[i] == Status::Stick);
        let t: Vec<f64> = (0..points.len()).map(|i| sol.lambda.tangential_norm(i)).collect();
        out.error = profile_error(&xs, &t, 1.5 * a, |x| cattaneo_traction(x, f, a, p0, cc));
        out.load_q = Some(q);
        out.c = Some(cc);
        out.c_h = Some(c_h);
        out.c_error = Some((c_h - cc).abs() / a);
        out.stick_offset = Some(stick_centre / a);
    }
    Some(ExactReport::Contact(out))
}

/// The half-space closed form of `problem::HalfSpace` for the scene's indenter, and the run's
/// errors against it (`indenter.half_space`): `None` where it does not apply to the scene
/// ([`Scene::half_space_problem`] refuses it), `Some(Err)` with the reason where the run lies
/// outside its domain: nothing touches (the run's or the closed form's force 0: no relative
/// error exists), or the closed form does not evaluate to a finite contact at these data (a
/// radius of 1e-300 gave a force of -4.6e210).
pub(crate) fn half_space(
    scene: &Scene,
    electric: bool,
    run: &Measured,
    f: &crate::Factors,
) -> Option<Result<HalfSpaceReport, String>> {
    use crate::halfspace::Tip;
    let (body, profile, tip) = scene.half_space_problem(electric).ok()?;
    // a path's instant: the tip's potential (a prescribed one) scaled by the voltage factor,
    // an indenter's force by the load factor
    let tip = match tip {
        Tip::Conducting { potential } => Tip::Conducting {
            potential: potential * f.voltage,
        },
        other => other,
    };
    let force = scene.active_contact()?.indenter.as_ref()?.force.map(|x| x * f.load);
    Some(half_space_in_domain(&body, &profile, tip, force, run))
}

/// [`half_space`] for a scene it applies to: the closed form at the run's depth (or at the
/// force under force control), or why the run lies outside its domain.
fn half_space_in_domain(
    body: &crate::halfspace::HalfSpace,
    profile: &crate::halfspace::Profile,
    tip: crate::halfspace::Tip,
    force: Option<f64>,
    run: &Measured,
) -> Result<HalfSpaceReport, String> {
    use crate::halfspace::Tip;
    if !(run.force > 0.0) {
        return Err("nothing touches: the indenter carries no force".into());
    }
    let form = match force {
        Some(f) => body.at_force(profile, f, tip),
        None => body.at_depth(profile, run.depth, tip),
    };
    let numbers = [form.depth, form.force, form.contact_radius];
    let finite = numbers
        .iter()
        .chain(&form.potential)
        .chain(&form.charge)
        .all(|v| v.is_finite());
    if !(finite && form.force > 0.0 && form.contact_radius > 0.0) {
        return Err(format!(
            "the closed form does not evaluate to a contact at these data (depth {:e}, force {:e}, contact radius {:e}): the indenter's dimensions are outside what double precision resolves",
            form.depth, form.force, form.contact_radius
        ));
    }
    let rel = |h: f64, exact: f64| (h - exact).abs() / exact.abs();
    let (error, error_name) = match force {
        Some(_) => (
            rel(run.depth, form.depth),
            "relative error of the depth against the half-space's closed form at the same force",
        ),
        None => (
            rel(run.force, form.force),
            "relative error of the force against the half-space's closed form at the same depth",
        ),
    };
    // the quantity found: a conductor's charge at a given potential, an insulator's or a
    // floating conductor's potential
    let electric_error = match tip {
        Tip::Conducting { .. } => run.charge.zip(form.charge).map(|(h, q)| rel(h, q)),
        Tip::Insulating => run.tip_potential.zip(form.potential).map(|(h, p)| rel(h, p)),
        Tip::Floating { .. } => run.potential.zip(form.potential).map(|(h, p)| rel(h, p)),
    };
    Ok(HalfSpaceReport {
        depth: form.depth,
        force: form.force,
        contact_radius: form.contact_radius,
        potential: form.potential,
        charge: form.charge.filter(|_| !matches!(tip, Tip::Insulating)),
        modulus: match tip {
            Tip::Insulating => Some(body.insulating_modulus()),
            Tip::Conducting { .. } => Some(body.conducting_modulus()),
            Tip::Floating { .. } => None,
        },
        error,
        error_name: error_name.into(),
        radius_error: rel(run.contact_radius, form.contact_radius),
        electric_error,
    })
}

/// What a run measured of its indenter, for [`half_space`] (run.json's `indenter`).
pub(crate) struct Measured {
    /// The depth.
    pub depth: f64,
    /// The force.
    pub force: f64,
    /// The contact radius.
    pub contact_radius: f64,
    /// The tip's potential (a conductor's).
    pub potential: Option<f64>,
    /// The tip's charge (a conductor's).
    pub charge: Option<f64>,
    /// The surface's potential under the tip.
    pub tip_potential: Option<f64>,
}

/// The closed form of a half-space under the scene's indenter (`run.json`'s
/// `indenter.half_space`), and the run's relative errors against it.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct HalfSpaceReport {
    /// The depth (the run's under depth control; the closed form's under force control).
    pub depth: f64,
    /// The force (the closed form's under depth control; the run's under force control).
    pub force: f64,
    /// The contact radius.
    pub contact_radius: f64,
    /// The tip's potential: a conductor's own; under an insulator, the surface's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub potential: Option<f64>,
    /// A conducting tip's charge (the same sign convention as `indenter.charge`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charge: Option<f64>,
    /// The indentation modulus the tip sees (`P = (4/3) E* √R d^(3/2)` for a paraboloid):
    /// `2/G₁₁` insulating, `2 (G⁻¹)₁₁` conducting at a given potential; none floating.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modulus: Option<f64>,
    /// Depth control: `|P_h - P| / P`; force control: `|d_h - d| / d`.
    pub error: f64,
    /// What `error` measures, in words (the force's error, or the depth's under force control).
    pub error_name: String,
    /// `|a_h - a| / a`.
    pub radius_error: f64,
    /// `|Q_h - Q| / |Q|` (conducting) or `|φ_h - φ| / |φ|` at the tip (insulating).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electric_error: Option<f64>,
}
