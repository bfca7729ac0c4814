//! From a scene to the finite-element problem: mesh, materials, conditions, loads, and the
//! plan of what the run needs.

use crate::scene::{MaterialSpec, Scene, Source};
use crate::DriverError;
use fe_assembly::{Constraint, Crystal, Field, Load, Material};
use serde::Serialize;
use std::sync::Arc;

/// What a run will compute, decided before anything is computed.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Plan {
    /// Spatial dimension.
    pub dim: usize,
    /// Whether electric unknowns exist (some coupling or electric data).
    pub electric: bool,
    /// Contact law (`none`, `signorini`, `tresca`, `coulomb`).
    pub contact_law: String,
    /// Whether the tangential multipliers exist (friction).
    pub friction: bool,
    /// Whether the fixed point on the slip bound runs (Coulomb with F > 0).
    pub fixed_point: bool,
    /// The linear strategy.
    pub linear_strategy: String,
    /// The stopping rule (`tight` or `paper`).
    pub rule: String,
    /// Files to write.
    pub outputs: Vec<String>,
}

impl std::fmt::Display for Plan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "plan: {}D, electric unknowns: {}, contact: {}{}{}, linear: {}, rule: {}, outputs: {}",
            self.dim,
            if self.electric { "yes" } else { "left out" },
            self.contact_law,
            if self.friction { " (tangential multipliers)" } else { "" },
            if self.fixed_point { " + fixed point on S" } else { "" },
            self.linear_strategy,
            self.rule,
            self.outputs.join(", ")
        )
    }
}

/// Cells per axis from `mesh.n` (along the shortest edge), `mesh.h`, `mesh.nx/ny/nz`.
pub fn cells_per_axis(scene: &Scene) -> Vec<usize> {
    let m = &scene.mesh;
    let lens: Vec<f64> = m.lo.iter().zip(&m.hi).map(|(a, b)| b - a).collect();
    let shortest = lens.iter().cloned().fold(f64::INFINITY, f64::min);
    let n = match (m.h, m.n) {
        (Some(h), _) => (shortest / h).round().max(1.0) as usize,
        (None, Some(n)) => n,
        (None, None) => 8,
    };
    let mut out: Vec<usize> = lens
        .iter()
        .map(|l| ((l / shortest) * n as f64).round().max(1.0) as usize)
        .collect();
    for (k, o) in [m.nx, m.ny, m.nz].iter().enumerate() {
        if let (Some(v), Some(slot)) = (o, out.get_mut(k)) {
            *slot = *v;
        }
    }
    out
}

/// Builds the mesh of the scene, with an `electrode` group where the scene has one.
pub fn mesh(scene: &Scene, source: &Source) -> Result<mesh::Mesh, DriverError> {
    let m = &scene.mesh;
    let mut mesh = match m.kind.as_str() {
        "rectangle" => {
            let n = cells_per_axis(scene);
            mesh::rectangle_tri([m.lo[0], m.lo[1]], [m.hi[0], m.hi[1]], n[0], n[1])
        }
        "box" => {
            let n = cells_per_axis(scene);
            mesh::box_tet(
                [m.lo[0], m.lo[1], m.lo[2]],
                [m.hi[0], m.hi[1], m.hi[2]],
                n[0],
                n[1],
                n[2],
            )
        }
        _ => {
            let file = m.file.as_deref().unwrap_or_default();
            mesh::read_msh(source.dir.join(file))?
        }
    };
    mesh.check()?;
    for r in &m.regions {
        let cells: Vec<usize> = (0..mesh.n_cells())
            .filter(|&c| {
                let cell = mesh.cell(c);
                (0..r.lo.len()).all(|k| {
                    let x = cell.iter().map(|&v| mesh.points[v][k]).sum::<f64>() / cell.len() as f64;
                    x >= r.lo[k] && x <= r.hi[k]
                })
            })
            .collect();
        if cells.is_empty() {
            return Err(DriverError::Input(format!("mesh.region `{}` holds no cell", r.name)));
        }
        mesh.regions.insert(r.name.clone(), cells);
    }
    if let Some(e) = &scene.electrode {
        let range = e
            .x_range
            .clone()
            .unwrap_or_else(|| vec![f64::NEG_INFINITY, f64::INFINITY]);
        if range.len() != 2 {
            return Err(DriverError::Input("electrode.x_range needs two numbers".into()));
        }
        let tol = 1e-12 * (1.0 + range[0].abs().max(range[1].abs()));
        let g = mesh.select_facets(&e.group, |x| x[0] >= range[0] - tol && x[0] <= range[1] + tol)?;
        if g.n_facets() == 0 {
            return Err(DriverError::Input(format!(
                "the electrode covers no facet of `{}` in x in [{}, {}]",
                e.group, range[0], range[1]
            )));
        }
        mesh.boundaries.insert("electrode".into(), g);
    }
    Ok(mesh)
}

fn material(spec: &MaterialSpec, dim: usize) -> Result<Material, DriverError> {
    let bad = |m: String| DriverError::Input(format!("material of region `{}`: {m}", spec.region));
    let crystal = match spec.model.as_str() {
        "crystal-6mm" => {
            if spec.c.len() != 6 || spec.e.len() != 3 || spec.permittivity.len() != 2 {
                return Err(bad("crystal-6mm needs c (6 values), e (3) and permittivity (2)".into()));
            }
            Crystal::hexagonal_6mm(
                [spec.c[0], spec.c[1], spec.c[2], spec.c[3], spec.c[4], spec.c[5]],
                [spec.e[0], spec.e[1], spec.e[2]],
                [spec.permittivity[0], spec.permittivity[1]],
            )
        }
        "isotropic" => {
            let (Some(y), Some(nu)) = (spec.young, spec.poisson) else {
                return Err(bad("isotropic needs young and poisson".into()));
            };
            if !(y > 0.0 && nu > -1.0 && nu < 0.5) {
                return Err(bad(format!(
                    "young = {y} must be positive and poisson = {nu} in (-1, 0.5): C is not positive definite"
                )));
            }
            Crystal::isotropic(y, nu, spec.permittivity.first().copied().unwrap_or(0.0))
        }
        other => return Err(bad(format!("model `{other}` is unknown (crystal-6mm, isotropic)"))),
    };
    let poling = match spec.poling.len() {
        0 => [0.0, 0.0, 1.0],
        3 => [spec.poling[0], spec.poling[1], spec.poling[2]],
        n => return Err(bad(format!("poling needs 3 components, not {n}"))),
    };
    let scale = spec.coupling_scale.unwrap_or(1.0);
    if !scale.is_finite() {
        return Err(bad(format!("coupling_scale = {scale} is not finite")));
    }
    Ok(Material::from_crystal(&spec.region, &crystal, poling, dim)?.with_coupling_scale(scale))
}

/// The materials (global frame), with the electric part removed when the plan leaves it out.
pub fn materials(scene: &Scene, dim: usize) -> Result<Vec<(String, Material)>, DriverError> {
    scene
        .material
        .iter()
        .map(|s| Ok((s.region.clone(), material(s, dim)?)))
        .collect()
}

/// Decides what the run needs.
pub fn plan(scene: &Scene, dim: usize, materials: &[(String, Material)]) -> Plan {
    let coupling = materials.iter().any(|(_, m)| m.e.iter().any(|&x| x != 0.0));
    let electric_data = scene.electrode.as_ref().is_some_and(|e| e.v != 0.0);
    let electric = (coupling || electric_data) && materials.iter().any(|(_, m)| m.electric);
    let law = scene.contact.as_ref().map_or("none".to_string(), |c| c.law.clone());
    let friction_coeff = scene.contact.as_ref().map_or(0.0, |c| c.friction);
    let slip = scene.contact.as_ref().map_or(0.0, |c| c.slip_bound);
    let friction = match law.as_str() {
        "coulomb" => friction_coeff > 0.0,
        "tresca" => slip > 0.0,
        _ => false,
    };
    let mut outputs = vec!["run.json".to_string(), "solution.vtu".to_string()];
    if law != "none" {
        outputs.push("contact.csv".into());
        outputs.push("multipliers.svg/png".into());
    }
    if dim == 2 || scene.mesh.kind == "box" {
        outputs.push("deformed.svg/png".into());
        if (coupling || electric_data) && materials.iter().any(|(_, m)| m.electric) {
            outputs.push("potential.svg/png".into());
        }
    }
    Plan {
        dim,
        electric,
        contact_law: law.clone(),
        friction,
        // semismooth Newton solves Coulomb's law directly
        fixed_point: law == "coulomb" && friction_coeff > 0.0 && scene.solver.strategy != "newton-condensed",
        linear_strategy: scene.solver.strategy.clone(),
        rule: scene.solver.rule.clone(),
        outputs,
    }
}

/// Dirichlet conditions (electric ones only when the plan has electric unknowns).
pub fn constraints(scene: &Scene, plan: &Plan) -> Result<Vec<Constraint>, DriverError> {
    let mut out = vec![];
    for d in &scene.dirichlet {
        if let Some(u) = &d.u {
            if u.len() != plan.dim {
                return Err(DriverError::Input(format!(
                    "dirichlet on `{}`: u needs {} components, not {}",
                    d.group,
                    plan.dim,
                    u.len()
                )));
            }
            for (k, &v) in u.iter().enumerate() {
                out.push(Constraint::constant(&d.group, Field::Displacement(k), v));
            }
        }
        // single components (rollers); with `u` as well, a component would be given twice
        for (k, v) in [d.ux, d.uy, d.uz].into_iter().enumerate() {
            let Some(v) = v else { continue };
            if d.u.is_some() || k >= plan.dim {
                return Err(DriverError::Input(format!(
                    "dirichlet on `{}`: u{} is given together with u, or beyond the {}D mesh",
                    d.group,
                    ["x", "y", "z"][k],
                    plan.dim
                )));
            }
            if !v.is_finite() {
                return Err(DriverError::Input(format!(
                    "dirichlet on `{}`: u{} = {v} is not finite",
                    d.group,
                    ["x", "y", "z"][k]
                )));
            }
            out.push(Constraint::constant(&d.group, Field::Displacement(k), v));
        }
        if let (Some(phi), true) = (d.phi, plan.electric) {
            out.push(Constraint::constant(&d.group, Field::Potential, phi));
        }
    }
    if let (Some(e), true) = (&scene.electrode, plan.electric) {
        out.push(Constraint::constant("electrode", Field::Potential, e.v));
    }
    Ok(out)
}

/// The loads of the scene.
pub fn loads(scene: &Scene, dim: usize) -> Result<Vec<Load>, DriverError> {
    let mut out = vec![];
    if let Some(l) = &scene.load {
        if l.direction.len() != dim {
            return Err(DriverError::Input(format!("load.direction needs {dim} components")));
        }
        let mut t = [0.0; 3];
        for k in 0..dim {
            t[k] = l.p * l.direction[k];
        }
        out.push(Load::Traction {
            group: l.group.clone(),
            value: Arc::new(move |_| t),
        });
    }
    Ok(out)
}

/// Everything a scene sets up before assembly: the mesh, the materials (without their electric
/// part when the plan has no electric unknowns), the plan, the Dirichlet conditions and the loads.
pub struct Setup {
    /// The mesh (with an `electrode` group where the scene has one).
    pub mesh: mesh::Mesh,
    /// Materials by region.
    pub materials: Vec<(String, Material)>,
    /// What the run computes.
    pub plan: Plan,
    /// Dirichlet conditions.
    pub constraints: Vec<Constraint>,
    /// Loads.
    pub loads: Vec<Load>,
    /// The exact field solution of a `manufactured` or `affine` scene (its Dirichlet data and
    /// loads are in `constraints` and `loads`).
    pub exact: Option<fe_assembly::Exact>,
}

/// Makes the [`Setup`] of a scene.
pub fn setup(scene: &Scene, source: &Source) -> Result<Setup, DriverError> {
    let mesh = mesh(scene, source)?;
    let dim = mesh.dim;
    let materials = materials(scene, dim)?;
    let plan = plan(scene, dim, &materials);
    let materials = if plan.electric {
        materials
    } else {
        without_electric(materials)
    };
    let mut constraints = constraints(scene, &plan)?;
    let mut loads = loads(scene, dim)?;
    let exact = crate::exact::field_solution(scene, dim)?;
    if let (Some(ex), Some(spec)) = (&exact, &scene.exact) {
        let groups = crate::exact::groups(spec, scene);
        let groups: Vec<&str> = groups.iter().map(String::as_str).collect();
        constraints.extend(
            ex.constraints(&groups)
                .into_iter()
                .filter(|c| plan.electric || !matches!(c.field, Field::Potential)),
        );
        loads.extend(ex.loads(&materials[0].1));
    }
    Ok(Setup {
        mesh,
        materials,
        plan,
        constraints,
        loads,
        exact,
    })
}

/// Materials with the electric part removed (for a plan without electric unknowns).
pub fn without_electric(materials: Vec<(String, Material)>) -> Vec<(String, Material)> {
    materials
        .into_iter()
        .map(|(r, mut m)| {
            m.electric = false;
            m.beta.iter_mut().for_each(|x| *x = 0.0);
            m.e.iter_mut().for_each(|x| *x = 0.0);
            (r, m)
        })
        .collect()
}
