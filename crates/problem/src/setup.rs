//! From a scene to the finite-element problem: the mesh (generated here, or read by the
//! application and handed over), the materials, the plan, the Dirichlet conditions and the
//! loads.

use crate::exact::FieldSolution;
use crate::plan::{electric_data, Plan};
use crate::scene::{MaterialSpec, MeshKind, Scene, Valid};
use crate::ProblemError;
use crate::SetupError;
use fe_assembly::{Constraint, Coordinates, Discretization, Field, Load, Material};
use std::sync::Arc;

/// Everything a scene sets up before assembly.
pub struct Setup {
    /// The mesh (with an `electrode` group where the scene has one).
    pub mesh: mesh::Mesh,
    /// What the mesh is of: the body, or a body of revolution's meridian section
    /// (`mesh.axisymmetric`).
    pub coordinates: Coordinates,
    /// Materials by region, each made for the coordinates (without their electric part when
    /// the plan has no electric unknowns).
    pub materials: Vec<(String, Material)>,
    /// What the run computes.
    pub plan: Plan,
    /// Dirichlet conditions (electric ones only when the plan has electric unknowns).
    pub constraints: Vec<Constraint>,
    /// Loads.
    pub loads: Vec<Load>,
    /// The exact field solution of a `manufactured` or `affine` scene (its Dirichlet data and
    /// loads are in `constraints` and `loads`).
    pub exact: Option<FieldSolution>,
    /// What the mesh's checks noted without refusing it.
    pub notes: MeshNotes,
    /// The unit of every reported quantity, from the scene's system.
    pub units: crate::Units,
    /// The group names of the electrodes given by `electrode.x_range` (run.json's terminals
    /// report the extent they cover, `covered_x`).
    pub ranged_electrodes: Vec<String>,
}

/// Boundary facets that lie on other boundary facets ([`mesh::Mesh::seam_facets`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Seam {
    /// Their number.
    pub facets: usize,
    /// Their total length (2D) or area (3D).
    pub measure: f64,
    /// The mesh's dimension.
    pub dim: usize,
}

impl Seam {
    /// The seam's length (2D) or area (3D): each of its sides is found, so half the facets'.
    pub fn size(&self) -> f64 {
        self.measure / 2.0
    }
}

/// What the mesh's checks noted without refusing it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshNotes {
    /// Cells the Gmsh reader turned round (a surface written clockwise).
    pub reoriented_cells: usize,
    /// Nodes at the coordinates of another node (a crack, or parts not merged).
    pub coincident_nodes: usize,
    /// Boundary facets on other boundary facets: a seam where the mesh's parts are not joined
    /// (of the whole mesh; none on a piece).
    pub seam: Seam,
    /// Nodes that no cell uses (the centre of a Gmsh arc): carried with no unknown.
    pub unused_nodes: usize,
    /// Curved second-order cells (an edge node off its edge's midpoint), mapped through their
    /// nodes.
    pub curved_cells: usize,
    /// Electrodes given by `x_range` whose facets cover less of it than asked (of the whole
    /// mesh; a piece's cover only its part).
    pub narrowed_electrodes: Vec<NarrowedElectrode>,
    /// Regions by box whose cells do not fill the box to its sides (of the whole mesh).
    pub staircase_regions: Vec<StaircaseRegion>,
}

/// A region by box (`[[mesh.region]]`) whose cells (those whose centroids lie in the box) do not
/// end on the box's sides within the mesh: the mesh has no cell faces there, and the region's
/// boundary is a staircase about them (a layer's thickness off by up to a cell).
#[derive(Clone, Debug, PartialEq)]
pub struct StaircaseRegion {
    /// The region's name.
    pub name: String,
    /// The box as asked, clamped to the mesh's extent: `[lo, hi]` along each axis.
    pub asked: Vec<[f64; 2]>,
    /// The extent of its cells along each axis.
    pub covered: Vec<[f64; 2]>,
}

/// An electrode given by `electrode.x_range` whose facets (those of its group wholly inside the
/// range) cover less of it than asked: the mesh has no node at an end of the range.
#[derive(Clone, Debug, PartialEq)]
pub struct NarrowedElectrode {
    /// The electrode's group name (`electrode.name`).
    pub name: String,
    /// `x_range` as asked.
    pub asked: [f64; 2],
    /// The x extent its facets cover.
    pub covered: [f64; 2],
}

/// Without electric unknowns (no coupling and no potential or charge that is not 0), what acts
/// on them only would be ignored: a floating terminal (even an open one), a path's voltage.
fn refuse_electric_keys_without_unknowns(scene: &Scene, plan: &Plan) -> Result<(), ProblemError> {
    if plan.electric {
        return Ok(());
    }
    let why = "the body has no electric unknowns (no piezoelectric coupling, no potential or charge that is not 0), so it would be ignored";
    let voltage = scene
        .path
        .as_ref()
        .is_some_and(|p| p.voltage.is_some())
        .then_some("path.voltage");
    let Some(key) = scene.floating_key().or(voltage) else {
        return Ok(());
    };
    Err(SetupError::new(
        key,
        format!("{key} does not apply: {why} (remove it, or `--set ~{key}`)"),
    )
    .into())
}

/// Makes the [`Setup`] of a validated scene ([`Scene::validate`]). `given` is the mesh of a
/// `gmsh` scene, read by the caller (this crate does no IO); a generated mesh is made here.
///
/// # Errors
/// A [`ProblemError`] naming the scene key, mesh group or material at fault.
pub fn setup(scene: Valid<'_>, given: Option<mesh::Mesh>) -> Result<Setup, ProblemError> {
    set_up(scene, Source::Whole(given))
}

/// The [`Setup`] of one rank's piece of a generated mesh (a [`mesh::MeshPiece`]'s mesh: the
/// rank's block of cells and one layer of ghosts), for a run in which no rank holds the whole
/// mesh. The scene's mesh must be one a piece is made of ([`piece_refusal`]); a grading maps
/// each node by its own grid index, as on the whole mesh. What only the whole
/// mesh can tell is the caller's to check, by reductions over the ranks: that each region
/// (`mesh.region`) holds a cell and each electrode a facet on some piece.
///
/// # Errors
/// As [`setup`].
pub fn setup_piece(scene: Valid<'_>, piece: mesh::Mesh) -> Result<Setup, ProblemError> {
    set_up(scene, Source::Piece(piece))
}

/// Where the mesh of a set-up comes from.
enum Source {
    /// The whole mesh: handed over (a `gmsh` or `given` scene), or generated here.
    Whole(Option<mesh::Mesh>),
    /// A rank's piece of the generated mesh.
    Piece(mesh::Mesh),
}

fn set_up(scene: Valid<'_>, source: Source) -> Result<Setup, ProblemError> {
    let scene = scene.scene();
    let (mesh, notes) = mesh(scene, source)?;
    let dim = mesh.dim;
    scene.check_dimension(dim)?;
    let materials = materials(scene, dim)?;
    if electric_data(scene) && !materials.iter().any(|(_, m)| m.electric) {
        let (key, what) = if scene.electrodes().iter().any(|e| e.v.is_some_and(|v| v != 0.0)) {
            ("electrode.v", "a potential")
        } else if scene.electrodes().iter().any(|e| e.charge.is_some_and(|q| q != 0.0)) {
            ("electrode.charge", "a charge")
        } else if scene.dirichlet.iter().any(|d| d.phi.is_some_and(|p| p != 0.0)) {
            ("dirichlet.phi", "a potential")
        } else {
            ("dirichlet.charge", "a charge")
        };
        return Err(SetupError::new(
            key,
            format!("{key} prescribes {what}, but no material has a permittivity (no electric unknowns): it would be ignored"),
        )
        .into());
    }
    let plan = Plan::new(scene, dim, &materials);
    refuse_electric_keys_without_unknowns(scene, &plan)?;
    let materials = if plan.electric {
        materials
    } else {
        materials.into_iter().map(|(r, m)| (r, m.without_electric())).collect()
    };
    let mut constraints = constraints(scene, &plan);
    if mesh.boundaries.contains_key("axis") && scene.mesh.axisymmetric {
        // the axis of a body of revolution: no radial displacement
        constraints.push(Constraint::constant("axis", Field::Displacement(0), 0.0));
    }
    let mut loads = loads(scene, dim, plan.electric);
    let exact = FieldSolution::of(scene, dim);
    if let Some(ex) = &exact {
        let groups: Vec<&str> = ex.groups.iter().map(String::as_str).collect();
        constraints.extend(
            ex.exact
                .constraints(&groups)
                .into_iter()
                .filter(|c| plan.electric || !matches!(c.field, Field::Potential)),
        );
        loads.extend(ex.exact.loads(&materials[0].1));
    }
    let coordinates = match scene.mesh.axisymmetric {
        true => Coordinates::Axisymmetric,
        false => Coordinates::Cartesian,
    };
    let units = crate::Units::of(scene, mesh.dim);
    let ranged_electrodes = (scene.electrodes().iter().enumerate())
        .filter(|(_, e)| e.x_range.is_some())
        .map(|(k, e)| e.group_name(k))
        .collect();
    Ok(Setup {
        mesh,
        coordinates,
        materials,
        plan,
        constraints,
        loads,
        exact,
        notes,
        units,
        ranged_electrodes,
    })
}

impl Setup {
    /// The discretisation of the set-up: its mesh in its coordinates, with its materials and
    /// Dirichlet conditions.
    ///
    /// # Errors
    /// What [`Discretization::new`] refuses.
    pub fn discretize(&self) -> Result<Discretization<'_>, fe_assembly::AssemblyError> {
        Discretization::new(&self.mesh, self.coordinates, &self.materials, &self.constraints)
    }
}

/// The mesh of the scene, checked, with its regions by box and an `electrode` group where the
/// scene has one, and what its checks noted.
fn mesh(scene: &Scene, source: Source) -> Result<(mesh::Mesh, MeshNotes), ProblemError> {
    let m = &scene.mesh;
    let n = m.cells_per_axis();
    let given = match source {
        Source::Whole(given) => given,
        Source::Piece(piece) => return mesh_piece(scene, piece),
    };
    let mut mesh = match (m.kind, given) {
        // a mesh handed over to a scene that makes its own would be ignored
        (MeshKind::Rectangle | MeshKind::Box, Some(_)) => {
            return Err(ProblemError::Setup(SetupError::new(
                "mesh.kind",
                format!(
                    "mesh.kind = \"{}\" makes its mesh, and a mesh was handed over too: mesh.kind = \"given\" uses the one handed over",
                    m.kind
                ),
            )))
        }
        (MeshKind::Rectangle, None) => mesh::rectangle_tri([m.lo[0], m.lo[1]], [m.hi[0], m.hi[1]], n[0], n[1]),
        (MeshKind::Box, None) => mesh::box_tet(
            [m.lo[0], m.lo[1], m.lo[2]],
            [m.hi[0], m.hi[1], m.hi[2]],
            n[0],
            n[1],
            n[2],
        ),
        (MeshKind::Gmsh | MeshKind::Given, Some(mesh)) => mesh,
        (MeshKind::Gmsh, None) => {
            return Err(ProblemError::Setup(SetupError::new(
                "mesh.file",
                "mesh.kind = \"gmsh\": the caller reads the file and hands the mesh over",
            )))
        }
        (MeshKind::Given, None) => {
            return Err(ProblemError::Setup(SetupError::new(
                "mesh.kind",
                "mesh.kind = \"given\": the caller hands the mesh over with the scene, and none was given",
            )))
        }
    };
    if let Some(g) = &m.grading {
        grade(&mut mesh, m, &g.ratios());
    }
    if !m.layers.is_empty() {
        layer(&mut mesh, m)?;
    }
    // raised before the cylinder is rounded: at order 2 the edge nodes are rounded with the
    // corners, onto the cylinder's face (curved cells that follow it, not its chords)
    mesh = of_order(mesh, scene)?;
    if m.cylinder {
        mesh::round_quarter_section(&mut mesh);
    }
    let quality = mesh.check()?;
    for l in scene.loads() {
        crate::boundary::check_boundary(&mesh, &l.group, "load.group", "traction")?;
    }
    let staircase_regions = box_regions(&mut mesh, &m.regions, true)?;
    let narrowed_electrodes = electrodes(&mut mesh, scene, true)?;
    let notes = MeshNotes {
        reoriented_cells: mesh.reoriented_cells,
        coincident_nodes: quality.coincident_nodes,
        seam: Seam {
            facets: quality.seam.0,
            measure: quality.seam.1,
            dim: mesh.dim,
        },
        unused_nodes: quality.unused_nodes,
        curved_cells: mesh.curved_cells().iter().filter(|&&c| c).count(),
        narrowed_electrodes,
        staircase_regions,
    };
    if m.axisymmetric {
        axis_group(&mut mesh)?;
    }
    Ok((mesh, notes))
}

/// [`mesh`] of a rank's piece: its regions and electrodes, the emptiness of each left to the
/// caller (a piece may hold none of a region that other pieces hold).
fn mesh_piece(scene: &Scene, mut mesh: mesh::Mesh) -> Result<(mesh::Mesh, MeshNotes), ProblemError> {
    let m = &scene.mesh;
    if let Some((key, what)) = piece_refusal(m) {
        return Err(SetupError::new(key, format!("{key}: {what} on a mesh made in pieces")).into());
    }
    // a node's graded coordinate depends on its own grid index alone: a piece's are the
    // whole mesh's
    if let Some(g) = &m.grading {
        grade(&mut mesh, m, &g.ratios());
    }
    // so do a layered mesh's (its rows of nodes moved by their grid row), its cells' layers
    // (by their centroids) and its interfaces (the facets of the layer below in each plane)
    if !m.layers.is_empty() {
        layer(&mut mesh, m)?;
    }
    let quality = mesh.check()?;
    let notes = MeshNotes {
        coincident_nodes: quality.coincident_nodes,
        unused_nodes: quality.unused_nodes,
        ..MeshNotes::default()
    };
    box_regions(&mut mesh, &m.regions, false)?;
    electrodes(&mut mesh, scene, false)?;
    Ok((mesh, notes))
}

/// What a mesh made in pieces cannot be, as the key that asks for it and the thing in words,
/// or `None`: a piece is of a generated rectangle or box (graded or layered or not) or of a
/// Gmsh mesh, of order 1, neither rounded nor a body of revolution. [`setup_piece`] refuses these, and so does a
/// backend before it makes a piece.
pub fn piece_refusal(m: &crate::scene::MeshSpec) -> Option<(&'static str, &'static str)> {
    [
        (
            !matches!(m.kind, MeshKind::Rectangle | MeshKind::Box | MeshKind::Gmsh),
            "mesh.kind",
            "a mesh handed over by the caller",
        ),
        (m.order.is_some_and(|o| o != 1), "mesh.order", "second-order cells"),
        (m.cylinder, "mesh.cylinder", "a rounded mesh"),
        (m.axisymmetric, "mesh.axisymmetric", "a body of revolution"),
    ]
    .into_iter()
    .find(|(refused, _, _)| *refused)
    .map(|(_, key, what)| (key, what))
}

/// The refusal of a region by box (`mesh.region` named `name`) that holds no cell: of the
/// whole mesh, or of every piece.
pub fn region_without_cells(name: &str) -> SetupError {
    SetupError::new("mesh.region", format!("mesh.region `{name}` holds no cell"))
}

/// The refusal of the scene's electrode `k` that covers no facet: of the whole mesh, or of
/// every piece.
pub fn electrode_without_facets(scene: &Scene, k: usize) -> SetupError {
    let e = &scene.electrodes()[k];
    let range = e
        .x_range
        .clone()
        .unwrap_or_else(|| vec![f64::NEG_INFINITY, f64::INFINITY]);
    SetupError::new(
        "electrode.x_range",
        format!(
            "the electrode `{}` covers no facet of `{}` in x in [{}, {}]",
            e.group_name(k),
            e.group,
            range[0],
            range[1]
        ),
    )
}

/// The electrodes' facet groups (`electrode.x_range` of `electrode.group`), each refused
/// where it covers no facet when `whole` (a piece may cover none of an electrode); the
/// electrodes whose facets cover less of their range than asked, when `whole`.
fn electrodes(mesh: &mut mesh::Mesh, scene: &Scene, whole: bool) -> Result<Vec<NarrowedElectrode>, ProblemError> {
    let mut narrowed = vec![];
    for (k, e) in scene.electrodes().iter().enumerate() {
        let range = e
            .x_range
            .clone()
            .unwrap_or_else(|| vec![f64::NEG_INFINITY, f64::INFINITY]);
        let tol = 1e-12 * (1.0 + range[0].abs().max(range[1].abs()));
        let g = mesh.select_facets(&e.group, |x| x[0] >= range[0] - tol && x[0] <= range[1] + tol)?;
        let name = e.group_name(k);
        if whole && g.n_facets() == 0 {
            return Err(electrode_without_facets(scene, k).into());
        }
        if mesh.boundaries.contains_key(&name) {
            return Err(SetupError::new(
                "electrode.name",
                format!("the electrode `{name}` would replace the mesh's own group of that name: name it otherwise (electrode.name)"),
            )
            .into());
        }
        if let (true, Some(&[a, b])) = (whole, e.x_range.as_deref()) {
            let covered = x_extent(mesh, &g);
            // an end within the tolerance of the selection is the range's own
            if covered[0] > a + tol || covered[1] < b - tol {
                narrowed.push(NarrowedElectrode {
                    name: name.clone(),
                    asked: [a, b],
                    covered,
                });
            }
        }
        mesh.boundaries.insert(name, g);
    }
    Ok(narrowed)
}

/// The least and largest x of the nodes of `group`.
pub fn x_extent(mesh: &mesh::Mesh, group: &mesh::FacetGroup) -> [f64; 2] {
    group
        .nodes()
        .iter()
        .map(|&v| mesh.points[v][0])
        .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| [lo.min(x), hi.max(x)])
}

/// `mesh` at the scene's `mesh.order`: raised to order 2 where it asks (a node at every
/// edge's midpoint), as it is otherwise; a second-order mesh where the scene asks for order 1
/// is refused (its edge nodes would be dropped silently).
fn of_order(mesh: mesh::Mesh, scene: &Scene) -> Result<mesh::Mesh, ProblemError> {
    match (scene.mesh.order, mesh.kind.order()) {
        (Some(2), 1) => Ok(mesh.quadratic()?),
        (Some(1), 2) => Err(SetupError::new(
            "mesh.order",
            format!(
                "mesh.order = 1, and the mesh holds second-order cells ({}): remove mesh.order, or mesh with Mesh.ElementOrder = 1",
                mesh.kind.name()
            ),
        )
        .into()),
        _ => Ok(mesh),
    }
}

/// The regions by box (`[[mesh.region]]`): the cells whose centroid lies in each box, each
/// refused where it holds none when `whole` (a piece may hold none of a region); the regions
/// whose cells do not end on their box's sides within the mesh, when `whole`.
fn box_regions(
    mesh: &mut mesh::Mesh,
    regions: &[crate::scene::RegionSpec],
    whole: bool,
) -> Result<Vec<StaircaseRegion>, ProblemError> {
    let (mesh_lo, mesh_hi) = mesh.bounding_box();
    let mut staircase = vec![];
    for r in regions {
        let cells: Vec<usize> = (0..mesh.n_cells())
            .filter(|&c| {
                let cell = mesh.cell(c);
                (0..r.lo.len()).all(|k| {
                    let x = cell.iter().map(|&v| mesh.points[v][k]).sum::<f64>() / cell.len() as f64;
                    x >= r.lo[k] && x <= r.hi[k]
                })
            })
            .collect();
        if whole && cells.is_empty() {
            return Err(region_without_cells(&r.name).into());
        }
        if whole {
            staircase.extend(off_the_box(mesh, r, &cells, (mesh_lo, mesh_hi)));
        }
        mesh.regions.insert(r.name.clone(), cells);
    }
    Ok(staircase)
}

/// Region `r`'s `cells` as a [`StaircaseRegion`] where their extent is not its box (clamped to
/// the mesh's extent `whole`, within 1e-9 of the mesh's size along each axis); `None` where it is.
fn off_the_box(
    mesh: &mesh::Mesh,
    r: &crate::scene::RegionSpec,
    cells: &[usize],
    (mesh_lo, mesh_hi): ([f64; 3], [f64; 3]),
) -> Option<StaircaseRegion> {
    let axes = 0..mesh.dim.min(r.lo.len());
    let asked: Vec<[f64; 2]> = axes
        .clone()
        .map(|k| {
            [
                r.lo[k].clamp(mesh_lo[k], mesh_hi[k]),
                r.hi[k].clamp(mesh_lo[k], mesh_hi[k]),
            ]
        })
        .collect();
    let nodes = || cells.iter().flat_map(|&c| mesh.cell(c));
    let covered: Vec<[f64; 2]> = axes
        .clone()
        .map(|k| {
            let xs = nodes().map(|&v| mesh.points[v][k]);
            [
                xs.clone().fold(f64::INFINITY, f64::min),
                xs.fold(f64::NEG_INFINITY, f64::max),
            ]
        })
        .collect();
    let off = axes.into_iter().any(|k| {
        let tol = 1e-9 * (mesh_hi[k] - mesh_lo[k]);
        (covered[k][0] - asked[k][0]).abs() > tol || (covered[k][1] - asked[k][1]).abs() > tol
    });
    off.then(|| StaircaseRegion {
        name: r.name.clone(),
        asked,
        covered,
    })
}

/// The group `axis` of a body of revolution's meridian section: its boundary segments on
/// `x = 0` (where `u_r = 0` is prescribed), unless the mesh names its own `axis` group (then
/// checked to lie on `x = 0`). A body off the axis (a ring) has none.
fn axis_group(mesh: &mut mesh::Mesh) -> Result<(), ProblemError> {
    let (lo, hi) = mesh.bounding_box();
    let tol = 1e-12 * (0..2).map(|k| hi[k] - lo[k]).fold(f64::MIN_POSITIVE, f64::max);
    if let Ok(g) = mesh.boundary("axis") {
        if let Some(&v) = g.nodes().iter().find(|&&v| mesh.points[v][0].abs() > tol) {
            return Err(SetupError::new(
                "mesh.axisymmetric",
                format!(
                    "the mesh's group `axis` has node {v} at r = {:e}, off the axis x = 0 (where a body of revolution's radial displacement is held)",
                    mesh.points[v][0]
                ),
            )
            .into());
        }
        return Ok(());
    }
    let on_axis = |v: usize| mesh.points[v][0].abs() <= tol;
    let mut facets = vec![];
    for cell in mesh.iter_cells() {
        // each edge on the axis, with its midpoint node in a second-order mesh
        for f in mesh.kind.facets() {
            if on_axis(cell[f[0]]) && on_axis(cell[f[1]]) {
                facets.extend(f.iter().map(|&l| cell[l]));
            }
        }
    }
    if !facets.is_empty() {
        mesh.boundaries.insert(
            "axis".into(),
            mesh::FacetGroup {
                nodes_per_facet: mesh.kind.facet_n_nodes(),
                facets,
            },
        );
    }
    Ok(())
}

/// A layered body (`mesh.layer`): the rows of nodes along the stacking axis (the last) moved so
/// that each layer's cells span its thickness uniformly, each layer's cells added to its
/// region, and each interface made a facet group (the cell facets in its plane, oriented as
/// the layer below's: their normal points up).
fn layer(mesh: &mut mesh::Mesh, m: &crate::scene::MeshSpec) -> Result<(), ProblemError> {
    let axis = mesh.dim - 1;
    let cells = m.layer_cells();
    let total: usize = cells.iter().sum();
    let (lo, hi) = (m.lo[axis], m.hi[axis]);
    // the planes of the rows of nodes, and the first row of each layer
    let mut at = vec![lo];
    let mut first = vec![];
    let mut base = lo;
    for (layer, &n) in m.layers.iter().zip(&cells) {
        first.push(at.len() - 1);
        at.extend((1..=n).map(|j| base + layer.thickness * j as f64 / n as f64));
        base += layer.thickness;
    }
    at[total] = hi;
    for p in &mut mesh.points {
        let row = (((p[axis] - lo) / (hi - lo)) * total as f64)
            .round()
            .clamp(0.0, total as f64) as usize;
        p[axis] = at[row];
    }
    // each cell's layer: the one whose rows hold its centroid
    let layer_of = |c: &[usize], points: &[[f64; 3]]| {
        let y = c.iter().map(|&v| points[v][axis]).sum::<f64>() / c.len() as f64;
        first.iter().rposition(|&r| at[r] <= y).unwrap_or(0)
    };
    let of: Vec<usize> = mesh.iter_cells().map(|c| layer_of(c, &mesh.points)).collect();
    for (k, layer) in m.layers.iter().enumerate() {
        let region = mesh.regions.entry(layer.region.clone()).or_default();
        region.extend((0..of.len()).filter(|&c| of[c] == k));
        region.sort_unstable();
    }
    let kind = mesh.kind;
    for k in 1..m.layers.len() {
        let name = m.interface_name(k);
        if mesh.boundaries.contains_key(&name) {
            return Err(SetupError::new(
                "mesh.layer.interface",
                format!("the interface `{name}` below layer {k} would replace the mesh's own group of that name: name it otherwise (mesh.layer.interface)"),
            )
            .into());
        }
        let plane = at[first[k]];
        let mut facets = vec![];
        for cell in mesh
            .iter_cells()
            .enumerate()
            .filter(|&(c, _)| of[c] == k - 1)
            .map(|(_, cell)| cell)
        {
            for local in kind.facets() {
                if local.iter().all(|&i| mesh.points[cell[i]][axis] == plane) {
                    facets.extend(local.iter().map(|&i| cell[i]));
                }
            }
        }
        let group = mesh::FacetGroup {
            nodes_per_facet: kind.facet_n_nodes(),
            facets,
        };
        mesh.boundaries.insert(name, group);
    }
    Ok(())
}

/// Grades a generated mesh towards `lo`: along axis k the cells' sizes grow geometrically from
/// the first to the last, `grading[k]` (or the one stretch given) times the first, the nodes
/// keeping their places in the structured grid.
fn grade(mesh: &mut mesh::Mesh, m: &crate::scene::MeshSpec, grading: &[f64]) {
    let n = m.cells_per_axis();
    for (k, &cells) in n.iter().enumerate().take(mesh.dim) {
        let stretch = grading.get(k).or(grading.first()).copied().unwrap_or(1.0);
        // the ratio of neighbouring cells that stretches the first to the last
        let q = stretch.powf(1.0 / cells.saturating_sub(1).max(1) as f64);
        // cell widths q^i, scaled by the largest so that no power overflows
        let top = if q >= 1.0 { (cells - 1) as f64 } else { 0.0 };
        let widths: Vec<f64> = (0..cells).map(|i| q.powf(i as f64 - top)).collect();
        let total: f64 = widths.iter().sum();
        let mut at = vec![0.0; cells + 1];
        for i in 0..cells {
            at[i + 1] = at[i] + widths[i] / total;
        }
        at[cells] = 1.0;
        let (lo, len) = (m.lo[k], m.hi[k] - m.lo[k]);
        for p in &mut mesh.points {
            let i = (((p[k] - lo) / len) * cells as f64).round().clamp(0.0, cells as f64) as usize;
            p[k] = lo + len * at[i];
        }
    }
}

/// The material of a validated spec in dimension `dim`, in the global frame (of a body of
/// revolution about y where `axisymmetric`).
fn material(spec: &MaterialSpec, dim: usize, axisymmetric: bool) -> Result<Material, ProblemError> {
    let crystal = spec.crystal();
    // an isotropic material has no poling; the validated crystal has 3 components
    let poling = match spec.poling[..] {
        [a, b, c] => [a, b, c],
        _ if axisymmetric => [0.0, 1.0, 0.0],
        _ => [0.0, 0.0, 1.0],
    };
    let scale = spec.coupling_scale.unwrap_or(1.0);
    let material = if axisymmetric {
        Material::from_crystal_axisymmetric(&spec.region, &crystal, poling)?
    } else {
        Material::from_crystal(&spec.region, &crystal, poling, dim)?
    };
    Ok(material.with_coupling_scale(scale))
}

/// Whether each cell of `mesh` carries the potential (its material has a permittivity) under
/// `scene`'s materials; `None` where they do not resolve on the mesh (a picture then draws
/// every cell's potential).
pub fn cell_electric(scene: &Scene, mesh: &mesh::Mesh) -> Option<Vec<bool>> {
    let materials = materials(scene, mesh.dim).ok()?;
    let of = fe_assembly::cell_materials(mesh, &materials).ok()?;
    Some(of.iter().map(|&m| materials[m].1.electric).collect())
}

/// The materials of the scene by region, in the global frame.
fn materials(scene: &Scene, dim: usize) -> Result<Vec<(String, Material)>, ProblemError> {
    scene
        .material
        .iter()
        .map(|s| Ok((s.region.clone(), material(s, dim, scene.mesh.axisymmetric)?)))
        .collect()
}

/// Dirichlet conditions of a validated scene (electric ones only when the plan has electric
/// unknowns).
fn constraints(scene: &Scene, plan: &Plan) -> Vec<Constraint> {
    let mut out = vec![];
    for d in &scene.dirichlet {
        // the components given (all of `u`, or a roller's alone)
        for (k, v) in (0..3).filter_map(|k| Some((k, d.component(k)?))) {
            out.push(Constraint::constant(&d.group, Field::Displacement(k), v));
        }
        if let (Some(phi), true) = (d.phi, plan.electric) {
            out.push(Constraint::constant(&d.group, Field::Potential, phi));
        }
        if let (Some(_), true) = (d.charge, plan.electric) {
            out.push(Constraint::floating(&d.group));
        }
    }
    for (k, e) in scene.electrodes().iter().enumerate().filter(|_| plan.electric) {
        match (e.v, e.charge) {
            (Some(v), _) => out.push(Constraint::constant(&e.group_name(k), Field::Potential, v)),
            (None, Some(_)) => out.push(Constraint::floating(&e.group_name(k))),
            (None, None) => {}
        }
    }
    out
}

/// The loads of a validated scene: each a uniform traction on its group (several on one group
/// add up), and the charges on the floating terminals.
fn loads(scene: &Scene, dim: usize, electric: bool) -> Vec<Load> {
    let on_groups = scene
        .dirichlet
        .iter()
        .filter_map(|d| d.charge.map(|q| (d.group.clone(), q)));
    let on_electrodes = (scene.electrodes().iter().enumerate())
        .filter_map(|(k, e)| e.charge.filter(|_| e.v.is_none()).map(|q| (e.group_name(k), q)));
    let charges = on_groups
        .chain(on_electrodes)
        .filter(|_| electric)
        .map(|(group, charge)| Load::TerminalCharge { group, charge });
    scene
        .loads()
        .iter()
        .map(|l| {
            // a direction: normalised (the magnitude is load.p), robustly for tiny or huge entries
            let len = mesh::scaled_norm(&l.direction);
            let mut t = [0.0; 3];
            for k in 0..dim {
                t[k] = l.p * (l.direction[k] / len);
            }
            Load::Traction {
                group: l.group.clone(),
                value: Arc::new(move |_| t),
            }
        })
        .chain(charges)
        .collect()
}
