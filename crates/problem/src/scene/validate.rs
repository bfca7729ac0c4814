//! The checks of a scene, before anything is computed: every number finite and in range, every
//! list of the length it needs, and no key that does not apply to the chosen kind, model or
//! law (a key that would be silently ignored is refused, with the reason). Lengths that depend
//! on the dimension are checked here for generated meshes and again by the set-up once a Gmsh
//! mesh is read ([`Scene::check_dimension`]).

use super::{
    ContactLaw, ContactSpec, ExactKind, ExactSpec, IndenterShape, IndenterSpec, MaterialModel, MaterialSpec, MeshKind,
    MeshSpec, PathSpec, Rule, Scene, SlipBoundProfile, SolverSpec, Strategy,
};

/// A scene value that cannot be used: the key at fault (dotted, as `--set` takes it) and what
/// is wrong with it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct SceneError {
    /// The key at fault, e.g. `contact.friction`.
    pub key: String,
    /// What is wrong, naming the key.
    pub message: String,
}

impl SceneError {
    /// An error on `key`.
    pub fn new(key: &str, message: impl Into<String>) -> Self {
        SceneError {
            key: key.into(),
            message: message.into(),
        }
    }

    /// `key` given where it has no effect: `reason` says why.
    fn not_applicable(key: &str, reason: &str) -> Self {
        SceneError::new(
            key,
            format!("{key} does not apply: {reason} (remove it, or `--set ~{key}` on the command line)"),
        )
    }
}

/// The largest structured mesh a scene may ask for, in squares or cubes (2D n = 1024 on
/// `paper` is 2.1e6; the sparse factor of 5e7 cells would not fit in memory): beyond it, an
/// error rather than an allocation failure.
const MAX_CELLS: f64 = 5e7;

/// The range of a relative tolerance (`solver.tol`, `solver.pcg_tol`).
pub const TOL_RANGE: (f64, f64) = (1e-15, 0.1);

/// The magnitudes a material constant or a length may have (zero aside): no system of units
/// needs more, and products of such numbers (a stiffness times a strain, an area) overflow or
/// underflow double precision.
pub const PHYSICAL_RANGE: (f64, f64) = (1e-100, 1e100);

/// Checks that every non-zero value of `key` lies in [`PHYSICAL_RANGE`] in magnitude.
fn physical(key: &str, values: &[f64]) -> Result<(), SceneError> {
    match values.iter().find(|v| **v != 0.0 && !(PHYSICAL_RANGE.0..=PHYSICAL_RANGE.1).contains(&v.abs())) {
        Some(v) => Err(SceneError::new(
            key,
            format!(
                "{key} = {v:e} is outside [{:e}, {:e}] in magnitude: no system of units needs it, and its products overflow double precision",
                PHYSICAL_RANGE.0, PHYSICAL_RANGE.1
            ),
        )),
        None => Ok(()),
    }
}

fn finite(key: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::new(key, format!("{key} = {v} is not a finite number")))
    }
}

fn all_finite(key: &str, values: &[f64]) -> Result<(), SceneError> {
    values.iter().try_for_each(|&v| finite(key, v))
}

fn refuse_if(given: bool, key: &str, reason: &str) -> Result<(), SceneError> {
    if given {
        Err(SceneError::not_applicable(key, reason))
    } else {
        Ok(())
    }
}

/// A scene that [`Scene::validate`] accepted: the one way into a run's set-up, so that a step
/// given one knows its values are in range and its keys apply. It reads as the scene.
#[derive(Clone, Copy, Debug)]
pub struct Valid<'a>(&'a Scene);

impl std::ops::Deref for Valid<'_> {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        self.0
    }
}

impl<'a> Valid<'a> {
    /// The scene.
    pub fn scene(self) -> &'a Scene {
        self.0
    }
}

impl Scene {
    /// Checks the whole scene; the scene as [`Valid`] where it passes.
    ///
    /// # Errors
    /// The first [`SceneError`] found, naming its key.
    pub fn validate(&self) -> Result<Valid<'_>, SceneError> {
        self.check_all()?;
        Ok(Valid(self))
    }

    /// A named crystal's or datasheet's `material.units` is the scene's system's stress unit
    /// (where `[units]` names one), and every material's the same: the constants are written
    /// in it, and every other number of the scene read in `[units]`'.
    fn check_units(&self) -> Result<(), SceneError> {
        let declared = self.units.and_then(|u| u.stress);
        let mut first: Option<(crate::StressUnit, &str)> = declared.map(|s| (s, "units.stress"));
        for m in &self.material {
            let Some(u) = m.units.map(crate::StressUnit::of_crystals) else {
                continue;
            };
            match first {
                Some((s, key)) if s != u => {
                    return Err(SceneError::new(
                        "material.units",
                        format!(
                            "material `{}`: material.units = \"{}\" puts its constants in {u}, and {key} says the scene's stresses are in {s}: give one system",
                            m.region,
                            m.units.map_or("", |x| x.name()),
                        ),
                    ))
                }
                None => first = Some((u, "the material before")),
                _ => {}
            }
        }
        Ok(())
    }

    /// Every check of [`Scene::validate`].
    fn check_all(&self) -> Result<(), SceneError> {
        validate_mesh(&self.mesh)?;
        if self.material.is_empty() {
            return Err(SceneError::new("material", "the scene has no [[material]]"));
        }
        for m in &self.material {
            validate_material(m)
                .map_err(|e| SceneError::new(&e.key, format!("material `{}`: {}", m.region, e.message)))?;
        }
        for (k, m) in self.material.iter().enumerate() {
            if let Some(j) = self.material[..k].iter().position(|o| o.region == m.region) {
                return Err(SceneError::new(
                    &format!("material.{k}.region"),
                    format!(
                        "material.{k}.region = `{}`, and material.{j} is that region's already: one material per region",
                        m.region
                    ),
                ));
            }
        }
        self.check_units()?;
        for d in &self.dirichlet {
            let scalars = [
                ("ux", d.ux),
                ("uy", d.uy),
                ("uz", d.uz),
                ("phi", d.phi),
                ("charge", d.charge),
            ];
            all_finite("dirichlet.u", d.u.as_deref().unwrap_or_default()).map_err(|e| on_group(e, &d.group))?;
            for (name, v) in scalars {
                v.map_or(Ok(()), |v| finite(&format!("dirichlet.{name}"), v))
                    .map_err(|e| on_group(e, &d.group))?;
            }
            if d.u.is_none() && scalars.iter().all(|(_, v)| v.is_none()) {
                return Err(SceneError::new(
                    "dirichlet",
                    format!(
                        "the dirichlet entry on `{}` prescribes nothing (give u, ux, uy, uz, phi or charge)",
                        d.group
                    ),
                ));
            }
            refuse_if(
                d.charge.is_some() && d.phi.is_some(),
                "dirichlet.charge",
                &format!(
                    "a floating terminal's charge on `{}`, and dirichlet.phi prescribes its potential",
                    d.group
                ),
            )?;
        }
        for l in self.loads() {
            let on_load = |e: SceneError| SceneError::new(&e.key, format!("load on `{}`: {}", l.group, e.message));
            finite("load.p", l.p).map_err(on_load)?;
            all_finite("load.direction", &l.direction).map_err(on_load)?;
            if !(mesh::scaled_norm(&l.direction) > 0.0) {
                return Err(on_load(SceneError::new(
                    "load.direction",
                    "load.direction is the zero vector: give the traction's direction (its magnitude is load.p)",
                )));
            }
            refuse_load_on_held(self, l).map_err(on_load)?;
        }
        validate_electrodes(self)?;
        // every entry of `[[contact]]` is read as the first one is: its own keys, each
        // refused by name where it does not apply
        each_contact(self, |_, c| validate_contact(c))?;
        refuse_several_contacts(self)?;
        validate_solver(&self.solver)?;
        refuse_axisymmetric(self)?;
        each_contact(self, |s, c| {
            refuse_force_control(s, c)?;
            refuse_compliance(s, c)?;
            refuse_weakening(s, c)?;
            refuse_electric(s, c)
        })?;
        if let Some(x) = &self.exact {
            validate_exact(x, self)?;
        }
        if let Some(p) = &self.path {
            validate_path(p, self)?;
        }
        if let Some(dim) = self.mesh.dim() {
            self.check_dimension(dim)?;
        }
        Ok(())
    }

    /// Checks the lengths that depend on the dimension `dim` of the mesh: Dirichlet data, the
    /// load's direction, the contact normal and the gap's centre, the regions' boxes and the
    /// affine solution's data.
    ///
    /// # Errors
    /// A [`SceneError`] naming the key and the length it needs.
    pub fn check_dimension(&self, dim: usize) -> Result<(), SceneError> {
        if self.mesh.axisymmetric && dim != 2 {
            return Err(SceneError::new(
                "mesh.axisymmetric",
                format!("mesh.axisymmetric: a body of revolution is meshed in its 2D meridian plane, and the mesh is {dim}D"),
            ));
        }
        for d in &self.dirichlet {
            if let Some(u) = &d.u {
                len("dirichlet.u", u, dim).map_err(|e| on_group(e, &d.group))?;
            }
            for (k, (v, name)) in [(d.ux, "ux"), (d.uy, "uy"), (d.uz, "uz")].into_iter().enumerate() {
                if v.is_some() && (d.u.is_some() || k >= dim) {
                    return Err(SceneError::new(
                        &format!("dirichlet.{name}"),
                        format!(
                            "dirichlet on `{}`: {name} is given together with u, or beyond the {dim}D mesh",
                            d.group
                        ),
                    ));
                }
            }
        }
        for l in self.loads() {
            len("load.direction", &l.direction, dim)?;
        }
        refuse_if(
            dim == 2 && self.path.as_ref().is_some_and(|p| p.uz.is_some()),
            "path.uz",
            "a displacement along z, and the mesh is 2D (plane strain: u = (ux, uy))",
        )?;
        each_contact(self, |_, c| check_contact_dimension(c, dim))?;
        if let Some(g) = self.mesh.grading.as_ref().map(|g| g.ratios()) {
            if g.len() != 1 && g.len() != dim {
                return Err(SceneError::new(
                    "mesh.grading",
                    format!(
                        "mesh.grading needs one stretch, or one per axis ({dim}), not {}",
                        g.len()
                    ),
                ));
            }
        }
        for r in &self.mesh.regions {
            if r.lo.len() != dim || r.hi.len() != dim {
                return Err(SceneError::new(
                    "mesh.region",
                    format!("mesh.region `{}`: lo and hi need {dim} coordinates", r.name),
                ));
            }
        }
        match &self.exact {
            Some(x) => x.check_lengths(dim),
            None => Ok(()),
        }
    }
}

/// `key`'s vector `v` has `n` components.
fn len(key: &str, v: &[f64], n: usize) -> Result<(), SceneError> {
    if v.len() == n {
        Ok(())
    } else {
        Err(SceneError::new(
            key,
            format!("{key} needs {n} components, not {}", v.len()),
        ))
    }
}

/// The lengths of a contact entry's vectors in dimension `dim`, and a cylinder's axis: in 3D,
/// given and in the contact face's plane.
fn check_contact_dimension(c: &ContactSpec, dim: usize) -> Result<(), SceneError> {
    len("contact.normal", &c.normal, dim)?;
    if let Some(p) = &c.slip_bound_profile {
        len("contact.slip_bound_profile.along", &p.along, dim)?;
    }
    if let Some(g) = &c.gap_center {
        len("contact.gap_center", g, dim)?;
    }
    if let Some(i) = &c.indenter {
        if let Some(tip) = &i.tip {
            len("contact.indenter.tip", tip, dim)?;
        }
        if let Some(axis) = &i.axis {
            len("contact.indenter.axis", axis, dim)?;
            refuse_if(
                dim != 3,
                "contact.indenter.axis",
                "a 3D cylinder's axis, and the mesh is 2D (the plane-strain cylinder needs none)",
            )?;
            // a cylinder lies on the face: its axis in the face's plane (an axis along
            // the normal would leave the distance across it that of a sphere)
            let (a, n) = (mesh::scaled_norm(axis), mesh::scaled_norm(&c.normal));
            let cos: f64 = axis.iter().zip(&c.normal).map(|(x, y)| (x / a) * (y / n)).sum();
            if cos.abs() > 1e-9 {
                return Err(SceneError::new(
                        "contact.indenter.axis",
                        format!(
                            "contact.indenter.axis = {axis:?} is not in the contact face's plane (its angle with contact.normal = {:?} is {:.6}°): a cylinder lies on the face, its axis perpendicular to the normal",
                            c.normal,
                            cos.clamp(-1.0, 1.0).acos().to_degrees()
                        ),
                    ));
            }
        } else if i.shape == IndenterShape::Cylinder && dim == 3 {
            return Err(SceneError::new(
                    "contact.indenter.axis",
                    "contact.indenter.shape = \"cylinder\" in 3D needs contact.indenter.axis (a direction in the contact face's plane)",
                ));
        }
    }
    Ok(())
}

/// Most steps a path may take.
const MAX_PATH_STEPS: usize = 1_000_000;

/// Which of a path's factors would scale anything: each multiplies values of the scene, and a
/// factor on values that are all 0 changes no instant.
struct Scaled {
    load: bool,
    voltage: bool,
    displacement: [bool; 3],
    gap: bool,
}

impl Scaled {
    fn of(scene: &Scene) -> Scaled {
        let some = |v: Option<f64>| v.is_some_and(|v| v != 0.0);
        let force = scene
            .indenter_contact()
            .and_then(|(_, c)| c.indenter.as_ref())
            .is_some_and(|i| some(i.force));
        let component = |k: usize| scene.dirichlet.iter().any(|d| some(d.component(k)));
        Scaled {
            load: force || scene.loads().iter().any(|l| l.p != 0.0),
            voltage: scene.dirichlet.iter().any(|d| some(d.phi) || some(d.charge))
                || scene.electrodes().iter().any(|e| some(e.v) || some(e.charge))
                || scene.zones().iter().any(|c| some(c.foundation_potential)),
            displacement: [component(0), component(1), component(2)],
            gap: scene.zones().iter().any(|c| c.uniform_gap() != 0.0),
        }
    }
}

/// A path: at least two strictly increasing finite instants, each table as long as `t` and
/// finite, `steps` in range; refused where the run cannot carry friction's history (a solver
/// without the condensed compliance, an exact solution; a floating conducting tip is refused
/// with its charge); a factor table on values that are all 0 ([`Scaled`]) refused by its key.
fn validate_path(p: &PathSpec, scene: &Scene) -> Result<(), SceneError> {
    all_finite("path.t", &p.t)?;
    if p.t.len() < 2 || p.t.windows(2).any(|w| !(w[0] < w[1])) {
        return Err(SceneError::new(
            "path.t",
            format!(
                "path.t needs at least two instants, strictly increasing (got {:?})",
                p.t
            ),
        ));
    }
    for (key, table) in p.tables() {
        let Some(f) = table else { continue };
        all_finite(key, f)?;
        if f.len() != p.t.len() {
            return Err(SceneError::new(
                key,
                format!("{key} has {} factors for the {} instants of path.t", f.len(), p.t.len()),
            ));
        }
    }
    if let Some(n) = p.steps {
        if n == 0 || n > MAX_PATH_STEPS {
            return Err(SceneError::new(
                "path.steps",
                format!("path.steps = {n}: give between 1 and {MAX_PATH_STEPS} steps"),
            ));
        }
        let legs = p.t.len() - 1;
        if n < legs {
            return Err(SceneError::new(
                "path.steps",
                format!(
                    "path.steps = {n} is fewer than the {legs} legs between the instants of path.t: every instant of path.t is solved (a turning point of the load is where friction's history turns), so give at least {legs}"
                ),
            ));
        }
    }
    let applies = |given: bool, key: &str, what: &str| {
        refuse_if(
            given && p.tables().iter().any(|(k, t)| *k == key && t.is_some()),
            key,
            what,
        )
    };
    refuse_if(
        scene.active_contact().is_none(),
        "path",
        "a path carries friction's history from step to step, and the scene has no contact (contact.law = \"none\"): without it each instant is the static answer scaled",
    )?;
    // a factor multiplies the scene's own values: where they are all 0 (or none) it changes
    // no instant, and the path the user asked for is not the one solved
    let scales = Scaled::of(scene);
    applies(
        !scales.load,
        "path.load",
        "the factor scales nothing: the scene has no [load] with p other than 0 (nor an indenter under force control with a force, contact.indenter.force)",
    )?;
    applies(
        !scales.voltage,
        "path.voltage",
        "the factor scales nothing: every prescribed potential (dirichlet.phi, electrode.v, contact.foundation_potential) and every floating terminal's charge (dirichlet.charge, electrode.charge) is 0 or not given",
    )?;
    // (a z factor on a generated 2D mesh: check_dimension says why more plainly)
    let beyond = |k: usize| scene.mesh.dim().is_some_and(|d| k >= d);
    for (k, key) in ["path.ux", "path.uy", "path.uz"].into_iter().enumerate() {
        applies(
            !scales.displacement[k] && !beyond(k),
            key,
            &format!(
                "the factor scales nothing: no dirichlet entry prescribes a {} component other than 0",
                ["x", "y", "z"][k]
            ),
        )?;
    }
    let own = [&p.ux, &p.uy, &p.uz];
    applies(
        !(0..3).any(|k| own[k].is_none() && scales.displacement[k]),
        "path.displacement",
        "the factor scales nothing: no dirichlet entry prescribes a displacement component other than 0 that path.ux, path.uy or path.uz does not scale already",
    )?;
    applies(
        !scales.gap,
        "path.gap",
        "the factor scales nothing: every contact zone's uniform gap (contact.gap less an indenter's depth) is 0",
    )?;
    refuse_if(
        scene.exact.is_some(),
        "path",
        "an exact solution is checked at one instant; a path solves many (remove [exact] or [path])",
    )?;
    if scene.active_contact().is_some() {
        refuse_if(
            !scene.solver.strategy.is_condensed(),
            "path",
            "a path carries friction's history on the condensed compliance: use solver.strategy = \"newton-condensed\", \"apg-condensed\" or \"uzawa-condensed\"",
        )?;
    }
    Ok(())
}

/// A traction pushes along its direction's components; where the Dirichlet conditions of its
/// own group hold one of them, that part of it acts on nothing (the displacement is given)
/// and the run would drop it silently: refused, naming the component.
fn refuse_load_on_held(scene: &Scene, l: &crate::LoadSpec) -> Result<(), SceneError> {
    let held = |k: usize| (scene.dirichlet.iter()).any(|d| d.group == l.group && d.component(k).is_some());
    let pushed = (0..l.direction.len().min(3)).filter(|&k| l.direction[k] != 0.0 && l.p != 0.0);
    match pushed.filter(|&k| held(k)).map(|k| ["x", "y", "z"][k]).collect::<Vec<_>>()[..] {
        [] => Ok(()),
        ref axes => Err(SceneError::new(
            "load.group",
            format!(
                "the traction pushes along {}, which dirichlet on `{}` prescribes: that part of it would act on nothing (a given displacement takes any force) and be dropped; load a group whose displacement is free, or prescribe the displacement alone",
                axes.join(" and "),
                l.group
            ),
        )),
    }
}

/// Runs `check` on every contact entry (each check passes over a section switched off,
/// `contact.law = "none"`, where it must); with several `[[contact]]` entries, an error names
/// the entry as `--set` reaches it (`contact.1.KEY`) and its group.
fn each_contact(s: &Scene, check: impl Fn(&Scene, &ContactSpec) -> Result<(), SceneError>) -> Result<(), SceneError> {
    let contacts = s.contacts();
    let several = contacts.len() > 1;
    for (k, c) in contacts.iter().enumerate() {
        check(s, c).map_err(|e| match (several, e.key.strip_prefix("contact.")) {
            // the entry's own keys in the message too (`--set ~contact.1.conductance`)
            (true, Some(rest)) => SceneError::new(
                &format!("contact.{k}.{rest}"),
                format!(
                    "[[contact]] {k} on `{}`: {}",
                    c.group,
                    e.message.replace("contact.", &format!("contact.{k}."))
                ),
            ),
            _ => e,
        })?;
    }
    Ok(())
}

fn on_group(e: SceneError, group: &str) -> SceneError {
    SceneError::new(&e.key, format!("dirichlet on `{group}`: {}", e.message))
}

fn validate_mesh(m: &MeshSpec) -> Result<(), SceneError> {
    if let Some(order) = m.order.filter(|o| !(1..=2).contains(o)) {
        return Err(SceneError::new(
            "mesh.order",
            format!("mesh.order = {order}: the elements are of order 1 (linear) or 2 (quadratic)"),
        ));
    }
    for (key, v) in [
        ("mesh.n", m.n),
        ("mesh.nx", m.nx),
        ("mesh.ny", m.ny),
        ("mesh.nz", m.nz),
        ("mesh.smoke_n", m.smoke_n),
    ] {
        if v == Some(0) {
            return Err(SceneError::new(key, format!("{key} must be at least 1")));
        }
    }
    if let Some(g) = m.grading.as_ref().map(|g| g.ratios()) {
        refuse_if(
            m.dim().is_none(),
            "mesh.grading",
            "a generated mesh's grading, and a Gmsh or given mesh fixes its own",
        )?;
        all_finite("mesh.grading", &g)?;
        if let Some(q) = g.iter().find(|q| !(**q >= 1e-6 && **q <= 1e6)) {
            return Err(SceneError::new(
                "mesh.grading",
                format!("mesh.grading = {q}: the last cell over the first must lie in [1e-6, 1e6] (1 is uniform; above 1 the cells grow away from lo)"),
            ));
        }
    }
    if let Some(k) = m.revolve {
        refuse_if(
            !m.axisymmetric,
            "mesh.revolve",
            "mesh.revolve sweeps a body of revolution round its axis, and mesh.axisymmetric is not set",
        )?;
        if !(3..=360).contains(&k) {
            return Err(SceneError::new(
                "mesh.revolve",
                format!("mesh.revolve = {k}: the segments of the revolved view must number 3 to 360"),
            ));
        }
    }
    if m.cylinder {
        refuse_if(
            m.kind != MeshKind::Box,
            "mesh.cylinder",
            &format!(
                "mesh.cylinder rounds a generated box's section, and mesh.kind = \"{}\"",
                m.kind
            ),
        )?;
        let square = m.lo.len() == 3 && m.hi.len() == 3 && m.lo[0] == 0.0 && m.lo[1] == 0.0 && m.hi[0] == m.hi[1];
        refuse_if(
            !square,
            "mesh.cylinder",
            "mesh.cylinder makes the section [0, R]² a quarter disc of radius R: give mesh.lo = [0, 0, z0] and mesh.hi = [R, R, z1]",
        )?;
    }
    validate_layers(m)?;
    match m.dim() {
        None => validate_read(m),
        Some(d) => validate_generated(m, d),
    }
}

/// A layered body's layers (`[[mesh.layer]]`): on a generated mesh, each a named region of a
/// positive thickness, together the height along the stacking axis; its cell counts given once
/// (per layer, or by `mesh.ny`/`mesh.nz` shared out); no grading across them.
fn validate_layers(m: &MeshSpec) -> Result<(), SceneError> {
    if m.layers.is_empty() {
        return Ok(());
    }
    let Some(dim) = m.dim() else {
        return Err(SceneError::new(
            "mesh.layer",
            format!("layers of a generated mesh, and mesh.kind = \"{}\" fixes its own cells (name the layers' regions in the mesh file)", m.kind),
        ));
    };
    for (k, layer) in m.layers.iter().enumerate() {
        check_name("mesh.layer.region", &layer.region)?;
        refuse_if(
            layer.region == "body",
            "mesh.layer.region",
            "a layer named `body`, the region of every cell of a generated mesh: name it for what it is (film, substrate)",
        )?;
        if !(layer.thickness.is_finite() && layer.thickness > 0.0) {
            return Err(SceneError::new(
                "mesh.layer.thickness",
                format!(
                    "mesh.layer.{k}.thickness = {} must be a positive length",
                    layer.thickness
                ),
            ));
        }
        if layer.n == Some(0) {
            return Err(SceneError::new(
                "mesh.layer.n",
                format!("mesh.layer.{k}.n must be at least 1"),
            ));
        }
        if let Some(name) = &layer.interface {
            check_name("mesh.layer.interface", name)?;
            refuse_if(
                k == 0,
                "mesh.layer.interface",
                "the first layer's interface: its bottom is the mesh's own bottom face (`bottom` in 2D, `bottom` in 3D)",
            )?;
        }
    }
    let axis = dim - 1;
    if m.lo.len() == dim && m.hi.len() == dim {
        let height = m.hi[axis] - m.lo[axis];
        let sum: f64 = m.layers.iter().map(|l| l.thickness).sum();
        if !((sum - height).abs() <= 1e-9 * height.abs()) {
            let axis_name = ["x", "y", "z"][axis];
            return Err(SceneError::new(
                "mesh.layer.thickness",
                format!("the layers' thicknesses (mesh.layer.thickness) sum to {sum}, and the body's height along {axis_name} (mesh.hi - mesh.lo) is {height}: make them equal"),
            ));
        }
    }
    let names: Vec<String> = (1..m.layers.len()).map(|k| m.interface_name(k)).collect();
    if let Some(name) = names.iter().find(|n| names.iter().filter(|x| x == n).count() > 1) {
        return Err(SceneError::new(
            "mesh.layer.interface",
            format!("two interfaces of the layers are named `{name}`: name each its own (mesh.layer.interface)"),
        ));
    }
    let count = if dim == 2 { ("mesh.ny", m.ny) } else { ("mesh.nz", m.nz) };
    refuse_if(
        count.1.is_some() && m.layers.iter().any(|l| l.n.is_some()),
        count.0,
        "cells along the stacking axis, and the layers give their own (mesh.layer.n): give one or the other",
    )?;
    refuse_if(
        m.grading.is_some(),
        "mesh.grading",
        "a graded mesh, and layers (mesh.layer): each layer's cells are uniform across it; grade by thinner layers",
    )
}

/// A Gmsh mesh, a file, or a given mesh, no file; and none of the generator's keys (they would
/// be silently ignored).
fn validate_read(m: &MeshSpec) -> Result<(), SceneError> {
    let why = match m.kind {
        MeshKind::Given => "a given mesh fixes the mesh (mesh.kind = \"given\")",
        _ => "a Gmsh file fixes the mesh (mesh.kind = \"gmsh\")",
    };
    for (key, given) in [
        ("mesh.lo", !m.lo.is_empty()),
        ("mesh.hi", !m.hi.is_empty()),
        ("mesh.n", m.n.is_some()),
        ("mesh.nx", m.nx.is_some()),
        ("mesh.ny", m.ny.is_some()),
        ("mesh.nz", m.nz.is_some()),
        ("mesh.h", m.h.is_some()),
        ("mesh.region", !m.regions.is_empty()),
    ] {
        refuse_if(given, key, why)?;
    }
    match (m.kind, &m.file) {
        (MeshKind::Gmsh, None) => Err(SceneError::new("mesh.file", "mesh.kind = \"gmsh\" needs mesh.file")),
        (MeshKind::Given, Some(_)) => Err(SceneError::new(
            "mesh.file",
            "does not apply to a given mesh (mesh.kind = \"given\"): the caller hands the mesh over",
        )),
        _ => Ok(()),
    }
}

/// `mesh.n` or `mesh.h` sets the cells of the axes that no count of their own fixes: where
/// every axis has one (`mesh.nx`, `ny`, `nz`, along a stack the layers' `n`), the size would be
/// ignored (`--set mesh.n=8` on such a scene once ran its full size with nothing said).
fn size_applies(m: &MeshSpec) -> Result<(), SceneError> {
    let Some(key) = [("mesh.n", m.n.is_some()), ("mesh.h", m.h.is_some())]
        .into_iter()
        .find_map(|(k, given)| given.then_some(k))
    else {
        return Ok(());
    };
    let Some(fixing) = m.counted_axes().into_iter().collect::<Option<Vec<&str>>>() else {
        return Ok(());
    };
    Err(SceneError::not_applicable(
        key,
        &format!(
            "{key} sizes the axes without a count of their own, and {} give every axis its cells (or remove those for {key} to size the mesh)",
            fixing.join(" and ")
        ),
    ))
}

/// A generated mesh in dimension `d`: its box, size and regions.
fn validate_generated(m: &MeshSpec, d: usize) -> Result<(), SceneError> {
    refuse_if(
        m.file.is_some(),
        "mesh.file",
        "the mesh is generated (mesh.kind is not \"gmsh\")",
    )?;
    refuse_if(
        m.kind == MeshKind::Rectangle && m.nz.is_some(),
        "mesh.nz",
        "a rectangle has no z axis",
    )?;
    if m.lo.len() != d || m.hi.len() != d {
        return Err(SceneError::new(
            "mesh.lo",
            format!("mesh.lo and mesh.hi need {d} coordinates for a {}", m.kind),
        ));
    }
    physical("mesh.lo", &m.lo)?;
    physical("mesh.hi", &m.hi)?;
    for k in 0..d {
        finite("mesh.lo", m.lo[k])?;
        finite("mesh.hi", m.hi[k])?;
        if !(m.hi[k] > m.lo[k]) {
            return Err(SceneError::new(
                "mesh.hi",
                format!("mesh.hi[{k}] = {} must exceed mesh.lo[{k}] = {}", m.hi[k], m.lo[k]),
            ));
        }
    }
    if m.h.is_some() && m.n.is_some() {
        return Err(SceneError::new(
            "mesh.h",
            "mesh.h and mesh.n both give the mesh's size (mesh.h would win): give one (a --set of either replaces the other)",
        ));
    }
    size_applies(m)?;
    if let Some(h) = m.h {
        if !(h > 0.0 && h.is_finite()) {
            return Err(SceneError::new(
                "mesh.h",
                format!("mesh.h = {h} must be a positive length"),
            ));
        }
        // a cell size past the body's shortest side would make one cell of another size (a
        // length in the wrong unit, as often as not)
        let shortest = m.lo.iter().zip(&m.hi).map(|(a, b)| b - a).fold(f64::INFINITY, f64::min);
        if h > shortest {
            return Err(SceneError::new(
                "mesh.h",
                format!("mesh.h = {h} is longer than the body's shortest side, {shortest} (the scene's lengths are in its [units]): at most that, for one cell across it"),
            ));
        }
    }
    for r in &m.regions {
        let key = format!("a corner of mesh.region `{}`", r.name);
        all_finite(&key, &r.lo)?;
        all_finite(&key, &r.hi)?;
        if r.lo.iter().zip(&r.hi).any(|(a, b)| !(b >= a)) {
            return Err(SceneError::new(
                "mesh.region",
                format!("mesh.region `{}`: hi must not be below lo", r.name),
            ));
        }
    }
    let cells: f64 = m.cells_per_axis().iter().map(|&c| c as f64).product();
    if cells > MAX_CELLS {
        return Err(SceneError::new(
            "mesh.n",
            format!(
                "the mesh would have {cells:.3e} cells (squares or cubes); the limit is {MAX_CELLS:.0e}, beyond what one machine factors (use a smaller mesh.n or a larger mesh.h)"
            ),
        ));
    }
    Ok(())
}

/// The largest coupling number `e²/(c ε)` of a material that the solver honours (equilibrium
/// to 1e-8 and complementarity to the tolerance after refinement; measured on paper,
/// paper-3d and actuator, docs/stability.md).
pub const MAX_COUPLING_NUMBER: f64 = 2e12;

/// A material's constants for its model (the caller names the region in the message).
fn validate_material(m: &MaterialSpec) -> Result<(), SceneError> {
    let bad = |what: &str| SceneError::new("material", what);
    for (key, values) in [
        ("material.c", &m.c),
        ("material.e", &m.e),
        ("material.permittivity", &m.permittivity),
        ("material.poling", &m.poling),
    ] {
        all_finite(key, values)?;
        physical(key, values)?;
    }
    for (key, v) in [
        ("material.young", m.young),
        ("material.coupling_scale", m.coupling_scale),
    ] {
        if let Some(v) = v {
            finite(key, v)?;
            physical(key, &[v])?;
        }
    }
    match m.model {
        MaterialModel::Crystal6mm => {
            let why = "an isotropic constant, and the model is crystal-6mm";
            refuse_if(m.young.is_some(), "material.young", why)?;
            refuse_if(m.poisson.is_some(), "material.poisson", why)?;
            if m.c.len() != 6 || m.e.len() != 3 || m.permittivity.len() != 2 {
                return Err(bad("crystal-6mm needs c (6 values), e (3) and permittivity (2)"));
            }
            if m.poling.len() != 3 {
                return Err(SceneError::new(
                    "material.poling",
                    format!(
                        "crystal-6mm needs poling, the poling direction (3 components, e.g. [0, 1, 0] for a block poled along y); {} given",
                        m.poling.len()
                    ),
                ));
            }
            if let Some(s) = m.coupling_scale {
                finite("material.coupling_scale", s)?;
            }
            // the coupling the solver honours: beyond it, double precision keeps too few digits
            let c_min = [0, 3, 4, 5].iter().map(|&k| m.c[k]).fold(f64::INFINITY, f64::min);
            let e_max = m.e.iter().fold(0.0f64, |a, x| a.max(x.abs())) * m.coupling_scale.unwrap_or(1.0).abs();
            let eps_min = m.permittivity.iter().copied().fold(f64::INFINITY, f64::min);
            if c_min > 0.0 && eps_min > 0.0 {
                let k = e_max * e_max / (c_min * eps_min);
                if !(k <= MAX_COUPLING_NUMBER) {
                    return Err(SceneError::new(
                        if m.coupling_scale.is_some() { "material.coupling_scale" } else { "material.e" },
                        format!(
                            "the coupling number e²/(c ε) of material `{}` is {k:.2e} (largest e{} over the smallest diagonal c and ε), beyond {MAX_COUPLING_NUMBER:.0e}: past it the coupled system loses the digits the tolerances need (measured in docs/stability.md: PZT-5A with material.coupling_scale up to 1e6, a coupling number of 1.6e12, is solved to its tolerances; 1e7 is not)",
                            m.region,
                            if m.coupling_scale.is_some() { " times material.coupling_scale" } else { "" }
                        ),
                    ));
                }
            }
        }
        MaterialModel::Isotropic => {
            let why = "the model is isotropic";
            refuse_if(!m.c.is_empty(), "material.c", why)?;
            refuse_if(!m.e.is_empty(), "material.e", why)?;
            refuse_if(!m.poling.is_empty(), "material.poling", why)?;
            refuse_if(
                m.coupling_scale.is_some(),
                "material.coupling_scale",
                "an isotropic material has no piezoelectric coupling to scale",
            )?;
            let (Some(y), Some(nu)) = (m.young, m.poisson) else {
                return Err(bad("isotropic needs young and poisson"));
            };
            finite("material.poisson", nu)?;
            if !(y > 0.0 && nu > -1.0 && nu < 0.5) {
                return Err(bad(&format!(
                    "young = {y} must be positive and poisson = {nu} in (-1, 0.5): C is not positive definite"
                )));
            }
            if m.permittivity.len() > 1 {
                return Err(bad("isotropic takes one permittivity value"));
            }
        }
    }
    Ok(())
}

/// Tresca's bound along the zone: in place of the uniform one; a direction, increasing
/// coordinates and as many non-negative values, all finite.
fn validate_slip_bound_profile(p: &SlipBoundProfile, uniform: bool) -> Result<(), SceneError> {
    let key = "contact.slip_bound_profile";
    refuse_if(
        uniform,
        "contact.slip_bound",
        "a uniform bound, and contact.slip_bound_profile gives the bound along the zone: give one",
    )?;
    all_finite(&format!("{key}.along"), &p.along)?;
    all_finite(&format!("{key}.at"), &p.at)?;
    all_finite(&format!("{key}.value"), &p.value)?;
    refuse_if(
        p.along.iter().all(|&a| a == 0.0),
        &format!("{key}.along"),
        "contact.slip_bound_profile.along is the zero vector: give the direction the bound varies along",
    )?;
    if p.at.is_empty() || p.at.len() != p.value.len() {
        return Err(SceneError::new(
            &format!("{key}.value"),
            format!(
                "contact.slip_bound_profile has {} coordinates (at) and {} values: give one value per coordinate, at least one",
                p.at.len(),
                p.value.len()
            ),
        ));
    }
    if p.at.windows(2).any(|w| w[0] >= w[1]) {
        return Err(SceneError::new(
            &format!("{key}.at"),
            "contact.slip_bound_profile.at must increase strictly".to_string(),
        ));
    }
    if let Some(v) = p.value.iter().find(|&&v| v < 0.0) {
        return Err(SceneError::new(
            &format!("{key}.value"),
            format!("contact.slip_bound_profile.value holds {v}: a slip bound is non-negative"),
        ));
    }
    Ok(())
}

fn validate_contact(c: &ContactSpec) -> Result<(), SceneError> {
    finite("contact.gap", c.gap)?;
    finite("contact.gap_curvature", c.gap_curvature)?;
    for (key, v) in [
        ("contact.friction", c.friction()),
        ("contact.slip_bound", c.slip_bound()),
    ] {
        finite(key, v)?;
        if v < 0.0 {
            return Err(SceneError::new(key, format!("{key} = {v} must be non-negative")));
        }
    }
    if let Some(p) = &c.slip_bound_profile {
        validate_slip_bound_profile(p, c.slip_bound.is_some())?;
    }
    all_finite("contact.gap_center", c.gap_center.as_deref().unwrap_or_default())?;
    all_finite("contact.normal", &c.normal)?;
    if !(mesh::scaled_norm(&c.normal) > 0.0) {
        return Err(SceneError::new(
            "contact.normal",
            "contact.normal is the zero vector: give the foundation's outward normal (its length does not matter)",
        ));
    }
    if let Some(k) = &c.compliance {
        if !(k.stiffness > 0.0 && k.stiffness.is_finite()) {
            return Err(SceneError::new(
                "contact.compliance.stiffness",
                format!(
                    "contact.compliance.stiffness = {} must be positive and finite (a rigid foundation: remove contact.compliance)",
                    k.stiffness
                ),
            ));
        }
        if !(k.exponent >= 1.0 && k.exponent.is_finite()) {
            return Err(SceneError::new(
                "contact.compliance.exponent",
                format!(
                    "contact.compliance.exponent = {} must be finite and at least 1 (below 1 the law is not Lipschitz at first touch)",
                    k.exponent
                ),
            ));
        }
    }
    match c.law {
        ContactLaw::Signorini => {
            let why = "friction, and contact.law = \"signorini\" is frictionless";
            refuse_if(c.friction.is_some(), "contact.friction", why)?;
            refuse_if(c.slip_bound.is_some(), "contact.slip_bound", why)?;
            refuse_if(c.slip_bound_profile.is_some(), "contact.slip_bound_profile", why)?;
        }
        ContactLaw::Tresca => refuse_if(
            c.friction.is_some(),
            "contact.friction",
            "Coulomb's coefficient, and contact.law = \"tresca\" takes contact.slip_bound",
        )?,
        ContactLaw::Coulomb => {
            let why = "Tresca's bound, and contact.law = \"coulomb\" takes contact.friction";
            refuse_if(c.slip_bound.is_some(), "contact.slip_bound", why)?;
            refuse_if(c.slip_bound_profile.is_some(), "contact.slip_bound_profile", why)?;
        }
        // contact switched off: the section is kept as it is, unused (the plan says so)
        ContactLaw::None => {}
    }
    refuse_if(
        c.gap_center.is_some() && c.gap_curvature == 0.0,
        "contact.gap_center",
        "the centre of a curved gap, and contact.gap_curvature is 0",
    )?;
    match &c.indenter {
        Some(i) => validate_indenter(i, c),
        None => Ok(()),
    }
}

/// An indenter's keys: those of its shape, given and in range, and no others; not beside a
/// curved gap (the indenter is the obstacle's shape).
fn validate_indenter(i: &IndenterSpec, c: &ContactSpec) -> Result<(), SceneError> {
    use IndenterShape as S;
    let why = "the obstacle's shape, and contact.indenter gives it";
    refuse_if(c.gap_curvature != 0.0, "contact.gap_curvature", why)?;
    refuse_if(c.gap_center.is_some(), "contact.gap_center", why)?;
    finite("contact.indenter.depth", i.depth)?;
    if let Some(f) = i.force {
        if !(f > 0.0 && f.is_finite()) {
            return Err(SceneError::new(
                "contact.indenter.force",
                format!(
                    "contact.indenter.force = {f} must be positive and finite (the force the indenter presses with)"
                ),
            ));
        }
    }
    all_finite("contact.indenter.tip", i.tip.as_deref().unwrap_or_default())?;
    all_finite("contact.indenter.axis", i.axis.as_deref().unwrap_or_default())?;
    let shape = i.shape;
    let needs_radius = matches!(shape, S::Sphere | S::Paraboloid | S::Cylinder | S::Punch);
    let not_for = |key: &str| format!("{key}, and contact.indenter.shape = \"{shape}\" does not take it");
    refuse_if(
        !needs_radius && i.radius.is_some(),
        "contact.indenter.radius",
        &not_for("a radius"),
    )?;
    refuse_if(
        shape != S::Cone && i.half_angle.is_some(),
        "contact.indenter.half_angle",
        &not_for("a cone's angle"),
    )?;
    refuse_if(
        shape != S::Profile && i.profile.is_some(),
        "contact.indenter.profile",
        &not_for("a profile"),
    )?;
    refuse_if(
        shape != S::Cylinder && i.axis.is_some(),
        "contact.indenter.axis",
        &not_for("a cylinder's axis"),
    )?;
    if needs_radius {
        let r = i.radius.ok_or_else(|| {
            SceneError::new(
                "contact.indenter.radius",
                format!("contact.indenter.shape = \"{shape}\" needs contact.indenter.radius"),
            )
        })?;
        if !(r > 0.0 && r.is_finite()) {
            return Err(SceneError::new(
                "contact.indenter.radius",
                format!("contact.indenter.radius = {r} must be positive and finite"),
            ));
        }
    }
    if shape == S::Cone {
        let a = i.half_angle.ok_or_else(|| {
            SceneError::new(
                "contact.indenter.half_angle",
                "contact.indenter.shape = \"cone\" needs contact.indenter.half_angle (degrees)",
            )
        })?;
        if !(a > 0.0 && a < 90.0) {
            return Err(SceneError::new(
                "contact.indenter.half_angle",
                format!("contact.indenter.half_angle = {a} must lie strictly between 0 and 90 degrees"),
            ));
        }
    }
    if let Some(axis) = &i.axis {
        if !(mesh::scaled_norm(axis) > 0.0) {
            return Err(SceneError::new(
                "contact.indenter.axis",
                "contact.indenter.axis is the zero vector",
            ));
        }
    }
    if shape == S::Profile {
        let table = i.profile.as_deref().unwrap_or_default();
        let flat: Vec<f64> = table.iter().flatten().copied().collect();
        all_finite("contact.indenter.profile", &flat)?;
        if table.len() < 2 || table[0] != [0.0, 0.0] || table.windows(2).any(|w| !(w[0][0] < w[1][0])) {
            return Err(SceneError::new(
                "contact.indenter.profile",
                "contact.indenter.profile needs at least two points [ρ, h], the first [0, 0] (the tip), ρ strictly increasing",
            ));
        }
    }
    Ok(())
}

/// Each electrode at a voltage or floating (not both), under a name of its own, its x range
/// two ordered numbers.
fn validate_electrodes(s: &Scene) -> Result<(), SceneError> {
    let mut names: Vec<String> = vec![];
    for (k, e) in s.electrodes().iter().enumerate() {
        let name = e.group_name(k);
        if let Some(given) = &e.name {
            check_name("electrode.name", given)?;
        }
        match (e.v, e.charge) {
            (Some(v), None) => finite("electrode.v", v)?,
            (None, Some(q)) => finite("electrode.charge", q)?,
            (Some(_), Some(_)) => {
                return Err(SceneError::new(
                    "electrode.charge",
                    format!("the electrode `{name}` has a voltage (electrode.v) and a charge (electrode.charge): a floating electrode's potential is found, give one of them"),
                ))
            }
            (None, None) => {
                return Err(SceneError::new(
                    "electrode.v",
                    format!("the electrode `{name}` has neither a voltage (electrode.v) nor a charge (electrode.charge, floating)"),
                ))
            }
        }
        if names.contains(&name) {
            return Err(SceneError::new(
                "electrode.name",
                format!("two electrodes make the group `{name}`: give each its own electrode.name"),
            ));
        }
        names.push(name);
        if let Some(r) = &e.x_range {
            all_finite("electrode.x_range", r)?;
            if r.len() != 2 || !(r[0] <= r[1]) {
                return Err(SceneError::new(
                    "electrode.x_range",
                    "electrode.x_range needs two numbers, the first not above the second",
                ));
            }
        }
    }
    Ok(())
}

/// A name the scene gives to something the outputs name (a group, a terminal: a column of
/// path.csv and capacitance.csv, a ParaView array): not empty, no control characters (a line
/// break would end a CSV row), no blanks at either end (they would not survive a spreadsheet).
fn check_name(key: &str, name: &str) -> Result<(), SceneError> {
    let problem = if name.is_empty() {
        Some("is empty")
    } else if name.chars().any(char::is_control) {
        Some("holds a control character (a line break, a tab)")
    } else if name.trim() != name {
        Some("begins or ends with a blank")
    } else {
        None
    };
    match problem {
        Some(what) => Err(SceneError::new(
            key,
            format!(
                "{key} = {name:?} {what}: a name becomes a column of the CSV outputs; use letters, digits, `-`, `_`"
            ),
        )),
        None => Ok(()),
    }
}

/// Several contact groups (`[[contact]]`): each its own face, normal, gap, friction
/// coefficient or slip-weakening law, Tresca bound, foundation (rigid, or its own compliance)
/// and (one of them) an indenter, at a depth or pressed with a force (its own points driven,
/// the others resting on their foundations); each its own friction law (Signorini's,
/// Tresca's, Coulomb's with a constant or a weakening coefficient); one
/// zone conducting (electrical contact, held at its potential or floating with its charge),
/// the others insulated; a zone switched off (`contact.law = "none"`) not posed, its keys
/// inert; an exact solution with several groups refused by key.
fn refuse_several_contacts(s: &Scene) -> Result<(), SceneError> {
    let contacts = s.contacts();
    if contacts.len() < 2 {
        return Ok(());
    }
    for (k, c) in contacts.iter().enumerate() {
        if let Some(other) = contacts[..k].iter().find(|o| o.group == c.group) {
            return Err(SceneError::new(
                "contact.group",
                format!(
                    "two [[contact]] entries on the group `{}`: one entry per face",
                    other.group
                ),
            ));
        }
    }
    // the zones that are posed (a zone switched off, contact.law = "none", keeps its keys
    // inert, as one [contact] switched off does): each its own law (a frictionless zone's
    // coefficient or bound 0, a Tresca zone's radius its bound beside Coulomb's)
    let zones = s.zones();
    for (k, c) in zones.iter().enumerate() {
        if let Some(other) = zones[..k].iter().find(|o| o.electric_law().is_some()) {
            refuse_if(
                c.electric_law().is_some(),
                "contact.electric",
                &format!(
                    "electrical contact on two [[contact]] groups (`{}` and `{}`): one zone conducts, the others are insulated",
                    other.group, c.group
                ),
            )?;
        }
    }
    refuse_if(
        zones.iter().filter(|c| c.indenter.is_some()).count() > 1,
        "contact.indenter",
        "two [[contact]] groups with an indenter: one indenter per scene (the others are foundations)",
    )?;
    refuse_if(
        s.exact.is_some(),
        "exact",
        "an exact solution, and several [[contact]] groups: the known solutions have one contact zone",
    )
}

/// Force control (`contact.indenter.force`): found on the condensed compliance, at one instant or at each instant of a path (the force scaled by its load factor).
fn refuse_force_control(s: &Scene, c: &ContactSpec) -> Result<(), SceneError> {
    if c.law == ContactLaw::None {
        return Ok(());
    }
    if c.indenter.as_ref().is_none_or(|i| i.force.is_none()) {
        return Ok(());
    }
    let key = "contact.indenter.force";
    refuse_if(
        !s.solver.strategy.is_condensed(),
        key,
        &format!("force control, and solver.strategy = \"{}\" does not condense: the depth is found on the condensed compliance (newton-condensed)", s.solver.strategy),
    )?;
    refuse_if(
        s.path.as_ref().is_some_and(|p| p.gap.is_some()),
        key,
        "force control, and path.gap drives the depth: under force control the depth is found at each instant for the force times the load factor (path.load); remove path.gap",
    )
}

/// A body of revolution: what it cannot carry (a plane or 3D exact solution, a cylinder lying
/// on the face, a tip off the axis), and a material symmetric about its axis (checked when
/// the material is built).
fn refuse_axisymmetric(s: &Scene) -> Result<(), SceneError> {
    if !s.mesh.axisymmetric {
        return Ok(());
    }
    if let Some(x) = &s.exact {
        refuse_if(
            !matches!(x.kind, ExactKind::Hertz | ExactKind::HalfSpace),
            "exact.kind",
            &format!("exact.kind `{}`, a plane or 3D solution, and the body is one of revolution (mesh.axisymmetric; `hertz` is the sphere's there)", x.kind),
        )?;
    }
    // the indenter of whichever zone carries it (not the first zone's alone)
    if let Some(i) = s.indenter_contact().and_then(|(_, c)| c.indenter.as_ref()) {
        refuse_if(
            i.shape == IndenterShape::Cylinder,
            "contact.indenter.shape",
            "a cylinder lying on the face, and a body of revolution is indented along its axis (sphere, paraboloid, cone, punch, profile)",
        )?;
        refuse_if(
            i.tip.as_ref().is_some_and(|t| t.first().is_some_and(|&r| r != 0.0)),
            "contact.indenter.tip",
            "a tip off the axis, and a body of revolution is indented on its axis (tip = [0, z])",
        )?;
    }
    Ok(())
}

/// A compliant foundation's law is no projection: only semismooth Newton (with block
/// Gauss-Seidel as its last stage) solves it.
fn refuse_compliance(s: &Scene, c: &ContactSpec) -> Result<(), SceneError> {
    if !(c.compliance.is_some() && c.law != ContactLaw::None) {
        return Ok(());
    }
    newton_condensed_only(s, "contact.compliance", |strategy| {
        format!("a deformable foundation, and solver.strategy = \"{strategy}\" projects onto Signorini's conditions: normal compliance is solved by newton-condensed")
    })
}

/// A law only `newton-condensed` solves: refused by `key` with the reason `strategy` gives
/// for another strategy.
fn newton_condensed_only(s: &Scene, key: &str, strategy: impl FnOnce(Strategy) -> String) -> Result<(), SceneError> {
    refuse_if(
        s.solver.strategy != Strategy::NewtonCondensed,
        key,
        &strategy(s.solver.strategy),
    )
}

/// Slip-weakening friction's keys, where `contact.friction_law = "slip-weakening"`: the three
/// numbers given and in range, Coulomb's law, no constant coefficient; solved by
/// `newton-condensed`. Elsewhere its keys do not apply.
fn refuse_weakening(s: &Scene, c: &ContactSpec) -> Result<(), SceneError> {
    // contact switched off: the section is kept as it is, unused
    if c.law == ContactLaw::None {
        return Ok(());
    }
    let keys = [
        ("contact.friction_static", c.friction_static),
        ("contact.friction_dynamic", c.friction_dynamic),
        ("contact.slip_length", c.slip_length),
    ];
    if c.friction_law != Some(crate::scene::FrictionLaw::SlipWeakening) {
        let why = "slip weakening, and contact.friction_law is not \"slip-weakening\"";
        for (key, v) in keys {
            refuse_if(v.is_some(), key, why)?;
        }
        return refuse_if(c.weakening.is_some(), "contact.weakening", why);
    }
    refuse_if(
        c.law != ContactLaw::Coulomb,
        "contact.friction_law",
        "slip weakening (Coulomb's bound with a falling coefficient), and contact.law is not \"coulomb\"",
    )?;
    refuse_if(
        c.friction.is_some(),
        "contact.friction",
        "a constant coefficient, and contact.friction_law = \"slip-weakening\" takes contact.friction_static and contact.friction_dynamic",
    )?;
    for (key, v) in keys {
        let Some(v) = v else {
            return Err(SceneError::new(
                key,
                format!("{key} is needed by contact.friction_law = \"slip-weakening\""),
            ));
        };
        finite(key, v)?;
    }
    let (ms, md, l) = (
        c.friction_static.unwrap_or(0.0),
        c.friction_dynamic.unwrap_or(0.0),
        c.slip_length.unwrap_or(0.0),
    );
    if !(md >= 0.0 && md <= ms) {
        return Err(SceneError::new(
            "contact.friction_dynamic",
            format!("contact.friction_dynamic = {md} must lie in [0, contact.friction_static = {ms}] (a coefficient that weakens with the slip)"),
        ));
    }
    if !(l > 0.0) {
        return Err(SceneError::new(
            "contact.slip_length",
            format!("contact.slip_length = {l} must be positive"),
        ));
    }
    newton_condensed_only(s, "contact.friction_law", |strategy| {
        format!("slip weakening, and solver.strategy = \"{strategy}\": its fixed point on the coefficients runs semismooth Newton (newton-condensed)")
    })
}

/// Electrical contact's keys: `foundation_potential` where the foundation conducts,
/// `conductance` where it is conductive (given, finite, `>= 0`); solved by `newton-condensed`,
/// not with slip weakening. (A body without electric unknowns is
/// refused once the plan knows it.)
fn refuse_electric(s: &Scene, c: &ContactSpec) -> Result<(), SceneError> {
    use crate::scene::ElectricCondition as E;
    if c.law == ContactLaw::None {
        return Ok(());
    }
    let condition = c.electric.unwrap_or(E::Insulated);
    if let Some(v) = c.foundation_potential {
        finite("contact.foundation_potential", v)?;
    }
    refuse_if(
        condition == E::Insulated && c.foundation_potential.is_some(),
        "contact.foundation_potential",
        "a foundation's potential, and contact.electric is \"insulated\" (set contact.electric = \"conductive\" or \"conducting\")",
    )?;
    refuse_if(
        condition != E::Conductive && c.conductance.is_some(),
        "contact.conductance",
        &format!("a conductance, and contact.electric = \"{condition}\" (it is contact.electric = \"conductive\"'s)"),
    )?;
    if let Some(q) = c.charge {
        finite("contact.charge", q)?;
        refuse_if(
            condition == E::Insulated,
            "contact.charge",
            "a floating conductor's charge, and contact.electric = \"insulated\" (a floating tip conducts: set contact.electric = \"conducting\" or \"conductive\")",
        )?;
        // the indenter of any zone (the floating one or another)
        refuse_if(
            s.indenter_contact().is_some_and(|(_, c)| c.indenter.as_ref().is_some_and(|i| i.force.is_some())),
            "contact.charge",
            "a floating tip under force control: not solved yet (the charge jumps as points enter the zone during the search for the depth); give the depth (contact.indenter.depth) instead of contact.indenter.force",
        )?;
        refuse_if(
            s.path.is_some(),
            "contact.charge",
            "a floating conducting tip along a load path: not solved yet (solve its instants one by one)",
        )?;
    }
    if condition == E::Insulated {
        return Ok(());
    }
    if condition == E::Conductive {
        let Some(sigma) = c.conductance else {
            return Err(SceneError::new(
                "contact.conductance",
                "contact.conductance is needed by contact.electric = \"conductive\" (0 is an insulator)",
            ));
        };
        if !(sigma >= 0.0 && sigma.is_finite()) {
            return Err(SceneError::new(
                "contact.conductance",
                format!("contact.conductance = {sigma} must be finite and non-negative"),
            ));
        }
    }
    refuse_if(
        c.friction_law == Some(crate::scene::FrictionLaw::SlipWeakening),
        "contact.electric",
        "electrical contact with slip-weakening friction: the two are not solved together (use contact.friction_law = \"coulomb\", or an insulating foundation)",
    )?;
    newton_condensed_only(s, "contact.electric", |strategy| {
        format!("electrical contact, and solver.strategy = \"{strategy}\": the potentials of the contact points join the condensed unknowns of semismooth Newton (newton-condensed)")
    })
}

fn validate_solver(s: &SolverSpec) -> Result<(), SceneError> {
    if s.rule == Rule::Paper && !s.strategy.is_uzawa() {
        return Err(SceneError::new(
            "solver.rule",
            format!(
                "solver.rule `paper` is the paper's rule for Uzawa; strategy `{}` stops on the complementarity residual (use solver.rule=tight, or a uzawa-* strategy)",
                s.strategy
            ),
        ));
    }
    refuse_if(
        s.pcg_tol.is_some() && !s.strategy.runs_pcg(),
        "solver.pcg_tol",
        &format!("strategy `{}` runs no PCG (only uzawa-schur-pcg does)", s.strategy),
    )?;
    finite("solver.tol", s.tol)?;
    if !(s.tol > 0.0) {
        return Err(SceneError::new(
            "solver.tol",
            format!("solver.tol = {} must be positive", s.tol),
        ));
    }
    // the complementarity residual is relative: at λ = 0 it is at most 1, so a tolerance near 1
    // accepts no contact force at all; below 1e-15 it is under the round-off of the residual
    if !(TOL_RANGE.0..=TOL_RANGE.1).contains(&s.tol) {
        return Err(SceneError::new(
            "solver.tol",
            format!(
                "solver.tol = {:e} is outside [{:e}, {:e}]: the complementarity residual is relative, at most 1 with no contact force at all, and round-off keeps it above about 1e-16",
                s.tol, TOL_RANGE.0, TOL_RANGE.1
            ),
        ));
    }
    if let Some(t) = s.pcg_tol {
        if !(TOL_RANGE.0..=TOL_RANGE.1).contains(&t) {
            return Err(SceneError::new(
                "solver.pcg_tol",
                format!(
                    "solver.pcg_tol = {t:e} is outside [{:e}, {:e}] (a relative residual of the PCG)",
                    TOL_RANGE.0, TOL_RANGE.1
                ),
            ));
        }
    }
    Ok(())
}

/// A contact solution (Hertz, Cattaneo-Mindlin, the half-space) takes none of a field
/// solution's data.
fn refuse_field_data(x: &ExactSpec) -> Result<(), SceneError> {
    let why = "a field solution's data, and exact.kind is a contact solution";
    refuse_if(!x.groups.is_empty(), "exact.groups", why)?;
    refuse_if(
        !(x.u0.is_empty() && x.grad_u.is_empty() && x.grad_phi.is_empty()),
        "exact.u0",
        why,
    )?;
    refuse_if(x.phi0.is_some(), "exact.phi0", why)?;
    refuse_if(x.slip.is_some(), "exact.slip", why)
}

fn validate_exact(x: &ExactSpec, s: &Scene) -> Result<(), SceneError> {
    if x.kind == ExactKind::HalfSpace {
        refuse_field_data(x)?;
        let electric = s.material.iter().any(|m| m.permittivity.iter().any(|&e| e != 0.0));
        s.half_space_problem(electric).map_err(|why| {
            SceneError::new(
                "exact.kind",
                format!("exact.kind `half-space`: {why} (or remove [exact]: `--set ~exact`)"),
            )
        })?;
        // under depth control at a depth that touches nothing the closed form is no contact,
        // and a relative error against its zero force has no meaning
        let depth = s
            .first_contact()
            .and_then(|c| c.indenter.as_ref())
            .filter(|i| i.force.is_none());
        if let Some(i) = depth.filter(|i| !(i.depth > 0.0) && s.path.is_none()) {
            return Err(SceneError::new(
                "exact.kind",
                format!("exact.kind `half-space` at contact.indenter.depth = {:e}: nothing touches, and no error can be measured against the closed form's force of 0 (the run without [exact] solves it: `--set ~exact`)", i.depth),
            ));
        }
        return Ok(());
    }
    if x.kind.is_field() {
        validate_field_solution(x, s)
    } else {
        validate_contact_solution(x, s)
    }
}

/// A manufactured or affine solution: no contact, one material, its groups and data.
fn validate_field_solution(x: &ExactSpec, s: &Scene) -> Result<(), SceneError> {
    let kind = x.kind;
    if kind == ExactKind::ManufacturedContact {
        validate_manufactured_contact(s)?;
    } else if s.contact_law() != ContactLaw::None {
        return Err(SceneError::new(
            "exact.kind",
            format!("exact.kind `{kind}` is a solution without contact; set contact.law = \"none\""),
        ));
    }
    if s.material.len() != 1 {
        return Err(SceneError::new(
            "exact.kind",
            format!("exact.kind `{kind}` needs exactly one [[material]]"),
        ));
    }
    if s.mesh.dim().is_none() && x.groups.is_empty() {
        return Err(SceneError::new(
            "exact.groups",
            format!("exact.kind `{kind}` on a Gmsh mesh needs exact.groups (the boundary groups to prescribe it on)"),
        ));
    }
    all_finite(
        "exact",
        &[
            &x.u0[..],
            &x.grad_u,
            &x.grad_phi,
            &x.phi0.into_iter().collect::<Vec<_>>(),
        ]
        .concat(),
    )?;
    if let Some(a) = x.slip {
        refuse_if(
            kind != ExactKind::ManufacturedContact,
            "exact.slip",
            "the slip of the face of exact.kind = \"manufactured-contact\", and exact.kind is another",
        )?;
        if !(a > 0.0 && a.is_finite()) {
            return Err(SceneError::new(
                "exact.slip",
                format!("exact.slip = {a}: the face's slip amplitude must be positive and finite"),
            ));
        }
    }
    if kind != ExactKind::Affine {
        let why = "data of an affine solution, and exact.kind is a manufactured one";
        refuse_if(!x.u0.is_empty(), "exact.u0", why)?;
        refuse_if(!x.grad_u.is_empty(), "exact.grad_u", why)?;
        refuse_if(x.phi0.is_some(), "exact.phi0", why)?;
        refuse_if(!x.grad_phi.is_empty(), "exact.grad_phi", why)?;
    }
    Ok(())
}

/// The manufactured solution in contact: a generated rectangle or box, Coulomb contact on its
/// `bottom` face with the outward normal `-e_n` (the solution sticks everywhere on the face);
/// a bed, or an electric face other than the ideal conductor's, under one 6mm crystal poled
/// along the normal (its constants make the face's pressure and flux); a conductive face on a
/// bed only where the bed is linear (the closed form).
fn validate_manufactured_contact(s: &Scene) -> Result<(), SceneError> {
    let why = "exact.kind = \"manufactured-contact\" is a solution in sticking contact with the foundation under the bottom face";
    let Some(c) = s.first_contact().filter(|c| c.law == ContactLaw::Coulomb) else {
        return Err(SceneError::new(
            "contact.law",
            format!("{why}: it needs contact.law = \"coulomb\""),
        ));
    };
    let electric = c.electric.unwrap_or(crate::scene::ElectricCondition::Insulated);
    let conducting = electric == crate::scene::ElectricCondition::Conducting;
    let slides = s.exact.as_ref().is_some_and(|x| x.slip.is_some());
    if c.compliance.is_some() || !conducting || slides {
        let m = &s.material;
        let poled = m.len() == 1
            && m[0].model == crate::scene::MaterialModel::Crystal6mm
            && m[0].poling.iter().zip(&c.normal).all(|(p, n)| (p + n).abs() < 1e-12);
        let on_face = "exact.kind = \"manufactured-contact\" on a deformable, conductive or insulated foundation, or sliding, takes one 6mm crystal poled along the contact normal (its constants make the face's pressure, flux and shear)";
        refuse_if(!poled, "material.poling", on_face)?;
    }
    if let Some(k) = c.compliance {
        let linear = "exact.kind = \"manufactured-contact\" on a conductive foundation takes a linear bed (contact.compliance.exponent = 1): on a power-law bed the flux's condition has no closed form";
        refuse_if(
            k.exponent != 1.0 && electric == crate::scene::ElectricCondition::Conductive,
            "contact.compliance.exponent",
            linear,
        )?;
    }
    let Some(dim) = s
        .mesh
        .dim()
        .filter(|_| matches!(s.mesh.kind, MeshKind::Rectangle | MeshKind::Box))
    else {
        return Err(SceneError::new(
            "mesh.kind",
            format!("{why}: it needs a generated rectangle or box"),
        ));
    };
    let down: Vec<f64> = (0..dim).map(|k| if k + 1 == dim { -1.0 } else { 0.0 }).collect();
    if c.group != "bottom" || c.normal != down {
        return Err(SceneError::new(
            "contact.group",
            format!("{why}: it needs contact.group = \"bottom\" with contact.normal = {down:?}"),
        ));
    }
    Ok(())
}

/// Hertz or Cattaneo-Mindlin: a rectangle, a curved gap, the law they solve, one isotropic
/// material.
fn validate_contact_solution(x: &ExactSpec, s: &Scene) -> Result<(), SceneError> {
    let (law, kind) = (s.contact_law(), x.kind);
    if let Some(c) = s.first_contact().filter(|_| law != ContactLaw::None) {
        // the closed forms are a rigid foundation's, with a constant coefficient
        let why = format!("exact.kind = \"{kind}\" is the closed form of a rigid foundation with a constant friction coefficient: remove [exact], or the key");
        refuse_if(c.compliance.is_some(), "contact.compliance", &why)?;
        refuse_if(c.electric_law().is_some(), "contact.electric", &why)?;
        refuse_if(
            c.friction_law.is_some_and(|f| f != crate::scene::FrictionLaw::Coulomb),
            "contact.friction_law",
            &why,
        )?;
    }
    refuse_field_data(x)?;
    if s.mesh.kind != MeshKind::Rectangle {
        return Err(SceneError::new(
            "exact.kind",
            format!(
                "exact.kind `{kind}` is a plane-strain or axisymmetric solution: it needs mesh.kind = \"rectangle\""
            ),
        ));
    }
    let Some(c) = s.first_contact().filter(|c| c.hertz_radius().is_some()) else {
        return Err(SceneError::new(
            "exact.kind",
            format!("exact.kind `{kind}` needs contact with a curved gap (contact.gap_curvature > 0, or a sphere's or paraboloid's contact.indenter)"),
        ));
    };
    if kind == ExactKind::Hertz && law != ContactLaw::Signorini {
        return Err(SceneError::new(
            "exact.kind",
            "exact.kind `hertz` is frictionless: set contact.law = \"signorini\"",
        ));
    }
    if kind == ExactKind::CattaneoMindlin && !(law == ContactLaw::Coulomb && c.friction() > 0.0) {
        return Err(SceneError::new(
            "exact.kind",
            "exact.kind `cattaneo-mindlin` needs contact.law = \"coulomb\" with contact.friction > 0",
        ));
    }
    if s.material.len() != 1 || s.material[0].model != MaterialModel::Isotropic {
        return Err(SceneError::new(
            "exact.kind",
            format!("exact.kind `{kind}` needs one isotropic material (young, poisson)"),
        ));
    }
    Ok(())
}
