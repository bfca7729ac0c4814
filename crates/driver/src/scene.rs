//! Scene files (TOML): what to solve. A scene is read, `--set KEY=VALUE` overrides are applied
//! to its TOML tree, and the result is deserialised with unknown keys rejected, so a typo names
//! itself in the error.

use crate::DriverError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The scenes shipped with the program, by name (their files are in `scenes/`).
pub const SHIPPED: &[(&str, &str)] = &[
    ("paper", include_str!("../../../scenes/paper.toml")),
    ("paper-slip", include_str!("../../../scenes/paper-slip.toml")),
    (
        "paper-frictionless",
        include_str!("../../../scenes/paper-frictionless.toml"),
    ),
    ("paper-stick", include_str!("../../../scenes/paper-stick.toml")),
    ("paper-tresca", include_str!("../../../scenes/paper-tresca.toml")),
    ("paper-elastic", include_str!("../../../scenes/paper-elastic.toml")),
    ("paper-3d", include_str!("../../../scenes/paper-3d.toml")),
    ("actuator", include_str!("../../../scenes/actuator.toml")),
    ("pzt5a-si", include_str!("../../../scenes/pzt5a-si.toml")),
    ("layered", include_str!("../../../scenes/layered.toml")),
    (
        "near-incompressible",
        include_str!("../../../scenes/near-incompressible.toml"),
    ),
    ("hertz", include_str!("../../../scenes/hertz.toml")),
    (
        "cattaneo-mindlin",
        include_str!("../../../scenes/cattaneo-mindlin.toml"),
    ),
    ("manufactured", include_str!("../../../scenes/manufactured.toml")),
    ("manufactured-3d", include_str!("../../../scenes/manufactured-3d.toml")),
    ("patch", include_str!("../../../scenes/patch.toml")),
];

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
    /// The mechanical load.
    #[serde(default)]
    pub load: Option<LoadSpec>,
    /// A voltage electrode.
    #[serde(default)]
    pub electrode: Option<ElectrodeSpec>,
    /// Contact with a rigid foundation.
    #[serde(default)]
    pub contact: Option<ContactSpec>,
    /// Solver choices.
    #[serde(default)]
    pub solver: SolverSpec,
    /// A known solution, for verification: the run reports its error against it.
    #[serde(default)]
    pub exact: Option<ExactSpec>,
}

/// The exact solutions a scene can be checked against (SCENES.md section 6).
///
/// - `manufactured`: the smooth coupled solution of [`fe_assembly::Exact::manufactured`]; the
///   run prescribes it on every boundary group of the generated mesh and adds the body force
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
    /// `manufactured`, `affine`, `hertz` or `cattaneo-mindlin`.
    pub kind: String,
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
    #[serde(default)]
    pub phi0: f64,
    /// `affine`: `∇φ`.
    #[serde(default)]
    pub grad_phi: Vec<f64>,
}

/// How the mesh is made.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// `rectangle` (P1 triangles, SW-NE split), `box` (Kuhn tetrahedra) or `gmsh`.
    pub kind: String,
    /// Lower corner (rectangle, box).
    #[serde(default)]
    pub lo: Vec<f64>,
    /// Upper corner (rectangle, box).
    #[serde(default)]
    pub hi: Vec<f64>,
    /// Cells along the shortest edge; the other edges get proportionally many.
    #[serde(default)]
    pub n: Option<usize>,
    /// Cells along x, y, z (override `n` per axis).
    #[serde(default)]
    pub nx: Option<usize>,
    /// Cells along y.
    #[serde(default)]
    pub ny: Option<usize>,
    /// Cells along z.
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

/// A material on a region.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// The region (`body` = every cell of a generated mesh).
    pub region: String,
    /// `crystal-6mm` (c = [c11, c12, c13, c33, c44, c66], e = [e31, e33, e15],
    /// permittivity = [eps11, eps33]) or `isotropic` (young, poisson, permittivity).
    pub model: String,
    /// Elastic constants (crystal-6mm).
    #[serde(default)]
    pub c: Vec<f64>,
    /// Piezoelectric constants (crystal-6mm).
    #[serde(default)]
    pub e: Vec<f64>,
    /// Permittivity: `[eps11, eps33]` (crystal-6mm) or `[eps]` (isotropic; omitted or 0: no
    /// electric unknowns).
    #[serde(default)]
    pub permittivity: Vec<f64>,
    /// Poling direction (global coordinates, 3 components).
    #[serde(default)]
    pub poling: Vec<f64>,
    /// Young's modulus (isotropic).
    #[serde(default)]
    pub young: Option<f64>,
    /// Poisson's ratio (isotropic).
    #[serde(default)]
    pub poisson: Option<f64>,
    /// Multiplies the piezoelectric constants (`material.coupling_scale`; default 1).
    #[serde(default)]
    pub coupling_scale: Option<f64>,
}

/// Dirichlet conditions on a boundary group.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
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

/// A voltage on the part of a group inside a box.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ElectrodeSpec {
    /// Boundary group the electrode lies on.
    pub group: String,
    /// Voltage (`electrode.v`).
    pub v: f64,
    /// Only facets whose nodes have `x_range[0] <= x <= x_range[1]`.
    #[serde(default)]
    pub x_range: Option<Vec<f64>>,
}

/// Contact with a rigid, non-conductive foundation.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Boundary group in contact.
    pub group: String,
    /// `none`, `signorini`, `tresca` or `coulomb`.
    pub law: String,
    /// Coulomb coefficient F.
    #[serde(default)]
    pub friction: f64,
    /// Tresca slip bound S.
    #[serde(default)]
    pub slip_bound: f64,
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
}

/// Solver choices.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Strategy: `newton-condensed` (default), `apg-condensed`, `uzawa-condensed`,
    /// `uzawa-direct`, `uzawa-schur-pcg` (the paper's);
    /// `piezocontact strategies` lists them.
    #[serde(default = "default_strategy")]
    pub strategy: String,
    /// Tolerance of the contact solve (complementarity residual).
    #[serde(default = "default_tol")]
    pub tol: f64,
    /// `tight` (default) or `paper`.
    #[serde(default = "default_rule")]
    pub rule: String,
    /// PCG relative tolerance for `schur-pcg` (default 1e-12).
    #[serde(default)]
    pub pcg_tol: Option<f64>,
}

fn default_strategy() -> String {
    "newton-condensed".into()
}
fn default_tol() -> f64 {
    1e-10
}
fn default_rule() -> String {
    "tight".into()
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            strategy: default_strategy(),
            tol: default_tol(),
            rule: default_rule(),
            pcg_tol: None,
        }
    }
}

/// Where a scene came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The name or path given.
    pub label: String,
    /// The directory relative paths resolve against.
    pub dir: std::path::PathBuf,
}

/// Reads a shipped scene by name, or a scene file by path, and applies the overrides.
pub fn load(name_or_path: &str, overrides: &[String]) -> Result<(Scene, Source), DriverError> {
    let (text, source) = if let Some((_, text)) = SHIPPED.iter().find(|(n, _)| *n == name_or_path) {
        (
            text.to_string(),
            Source {
                label: name_or_path.into(),
                dir: std::env::current_dir().unwrap_or_default(),
            },
        )
    } else if Path::new(name_or_path).exists() {
        let text = std::fs::read_to_string(name_or_path).map_err(|e| DriverError::Scene {
            file: name_or_path.into(),
            message: e.to_string(),
        })?;
        let dir = Path::new(name_or_path)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        (
            text,
            Source {
                label: name_or_path.into(),
                dir,
            },
        )
    } else {
        return Err(DriverError::Scene {
            file: name_or_path.into(),
            message: format!(
                "no shipped scene of that name and no such file (shipped: {})",
                SHIPPED.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
            ),
        });
    };
    let scene = parse(&text, &source.label, overrides)?;
    Ok((scene, source))
}

/// Parses scene text and applies `KEY=VALUE` overrides to its TOML tree.
pub fn parse(text: &str, label: &str, overrides: &[String]) -> Result<Scene, DriverError> {
    let err = |message: String| DriverError::Scene {
        file: label.into(),
        message,
    };
    let mut tree: toml::Table = text.parse().map_err(|e: toml::de::Error| err(e.to_string()))?;
    for o in overrides {
        set(&mut tree, o).map_err(|m| err(format!("--set {o}: {m}")))?;
    }
    let scene: Scene = toml::Value::Table(tree)
        .try_into()
        .map_err(|e: toml::de::Error| err(e.to_string()))?;
    validate(&scene).map_err(err)?;
    Ok(scene)
}

/// Applies one `a.b.c=value` to the tree. The value is read as TOML (number, string, bool,
/// array), else as a fraction `p/q`, else as a bare string.
fn set(tree: &mut toml::Table, assignment: &str) -> Result<(), String> {
    let (key, raw) = assignment.split_once('=').ok_or("expected KEY=VALUE")?;
    let path: Vec<&str> = key.trim().split('.').collect();
    if path.iter().any(|p| p.is_empty()) {
        return Err(format!("`{key}` is not a dotted key"));
    }
    let value = parse_value(raw.trim())?;
    let mut table = tree;
    for part in &path[..path.len() - 1] {
        let entry = table
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = match entry {
            toml::Value::Table(t) => t,
            toml::Value::Array(a) if a.len() == 1 => match &mut a[0] {
                toml::Value::Table(t) => t,
                _ => return Err(format!("`{part}` is not a table")),
            },
            _ => return Err(format!("`{part}` is not a table")),
        };
    }
    table.insert(path[path.len() - 1].to_string(), value);
    Ok(())
}

fn parse_value(raw: &str) -> Result<toml::Value, String> {
    if let Ok(t) = format!("v = {raw}").parse::<toml::Table>() {
        if let Some(v) = t.get("v") {
            return Ok(v.clone());
        }
    }
    if let Some((p, q)) = raw.split_once('/') {
        if let (Ok(p), Ok(q)) = (p.trim().parse::<f64>(), q.trim().parse::<f64>()) {
            return Ok(toml::Value::Float(p / q));
        }
    }
    if raw.is_empty() {
        return Err("empty value".into());
    }
    Ok(toml::Value::String(raw.to_string()))
}

/// The largest structured mesh a scene may ask for, in squares or cubes (2D n = 1024 on
/// `paper` is 2.1e6; the sparse factor of 5e7 cells would not fit in memory): beyond it, an
/// error rather than an allocation failure.
const MAX_CELLS: f64 = 5e7;

fn validate(s: &Scene) -> Result<(), String> {
    let finite = |what: &str, v: f64| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(format!("{what} = {v} is not a finite number"))
        }
    };
    match s.mesh.kind.as_str() {
        "rectangle" | "box" => {
            let d = if s.mesh.kind == "rectangle" { 2 } else { 3 };
            if s.mesh.lo.len() != d || s.mesh.hi.len() != d {
                return Err(format!(
                    "mesh.lo and mesh.hi need {d} coordinates for a {}",
                    s.mesh.kind
                ));
            }
            for k in 0..d {
                finite("mesh.lo", s.mesh.lo[k])?;
                finite("mesh.hi", s.mesh.hi[k])?;
                if !(s.mesh.hi[k] > s.mesh.lo[k]) {
                    return Err(format!(
                        "mesh.hi[{k}] = {} must exceed mesh.lo[{k}] = {}",
                        s.mesh.hi[k], s.mesh.lo[k]
                    ));
                }
            }
        }
        "gmsh" => {
            if s.mesh.file.is_none() {
                return Err("mesh.kind = \"gmsh\" needs mesh.file".into());
            }
        }
        k => return Err(format!("mesh.kind `{k}` is unknown (rectangle, box, gmsh)")),
    }
    for (key, v) in [
        ("mesh.n", s.mesh.n),
        ("mesh.nx", s.mesh.nx),
        ("mesh.ny", s.mesh.ny),
        ("mesh.nz", s.mesh.nz),
    ] {
        if v == Some(0) {
            return Err(format!("{key} must be at least 1"));
        }
    }
    if let Some(h) = s.mesh.h {
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!("mesh.h = {h} must be a positive length"));
        }
    }
    for r in &s.mesh.regions {
        let d = s.mesh.lo.len();
        if s.mesh.kind == "gmsh" {
            return Err(format!(
                "mesh.region `{}`: regions by box are for generated meshes (a Gmsh file names its own)",
                r.name
            ));
        }
        if r.lo.len() != d || r.hi.len() != d {
            return Err(format!("mesh.region `{}`: lo and hi need {d} coordinates", r.name));
        }
        for (a, b) in r.lo.iter().zip(&r.hi) {
            finite(&format!("a corner of mesh.region `{}`", r.name), *a)?;
            finite(&format!("a corner of mesh.region `{}`", r.name), *b)?;
            if !(b >= a) {
                return Err(format!("mesh.region `{}`: hi must not be below lo", r.name));
            }
        }
    }
    if s.mesh.kind != "gmsh" {
        let cells: f64 = crate::build::cells_per_axis(s).iter().map(|&c| c as f64).product();
        if cells > MAX_CELLS {
            return Err(format!(
                "the mesh would have {cells:.3e} cells (squares or cubes); the limit is {MAX_CELLS:.0e}, beyond what one machine factors (use a smaller mesh.n or a larger mesh.h)"
            ));
        }
    }
    if s.material.is_empty() {
        return Err("the scene has no [[material]]".into());
    }
    for m in &s.material {
        for v in m.c.iter().chain(&m.e).chain(&m.permittivity).chain(&m.poling) {
            finite(&format!("a constant of the material of region `{}`", m.region), *v)?;
        }
    }
    if let Some(l) = &s.load {
        finite("load.p", l.p)?;
    }
    if let Some(e) = &s.electrode {
        finite("electrode.v", e.v)?;
    }
    if let Some(c) = &s.contact {
        if !["none", "signorini", "tresca", "coulomb"].contains(&c.law.as_str()) {
            return Err(format!(
                "contact.law `{}` is unknown (none, signorini, tresca, coulomb)",
                c.law
            ));
        }
        finite("contact.friction", c.friction)?;
        finite("contact.slip_bound", c.slip_bound)?;
        finite("contact.gap", c.gap)?;
        finite("contact.gap_curvature", c.gap_curvature)?;
        for v in c.gap_center.iter().flatten() {
            finite("contact.gap_center", *v)?;
        }
        if c.friction < 0.0 {
            return Err(format!("contact.friction = {} must be non-negative", c.friction));
        }
        if c.slip_bound < 0.0 {
            return Err(format!("contact.slip_bound = {} must be non-negative", c.slip_bound));
        }
    }
    if !["tight", "paper"].contains(&s.solver.rule.as_str()) {
        return Err(format!("solver.rule `{}` is unknown (tight, paper)", s.solver.rule));
    }
    if s.solver.rule == "paper" && !s.solver.strategy.starts_with("uzawa") {
        return Err(format!(
            "solver.rule `paper` is the paper's rule for Uzawa; strategy `{}` stops on the complementarity residual (use solver.rule=tight, or a uzawa-* strategy)",
            s.solver.strategy
        ));
    }
    if let Some(x) = &s.exact {
        crate::exact::validate(x, s)?;
    }
    finite("solver.tol", s.solver.tol)?;
    if !(s.solver.tol > 0.0) {
        return Err(format!("solver.tol = {} must be positive", s.solver.tol));
    }
    Ok(())
}
