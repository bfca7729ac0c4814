//! `Scene`: what to solve, as the library reads it. It keeps the scene's TOML tree (so that a
//! change is a change of a key, named in its error as on the command line), the typed scene
//! that tree validates to, and the mesh handed over as arrays, if any.

use crate::errors::{mesh_err, to_py, Kind};
use crate::values::{from_table, from_toml, to_table, to_toml};
use files::scene_file::{self, Source};
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyMapping, PyString, PyTuple};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

/// What to solve: a mesh, materials, boundary conditions, a load, an electrode, the contact
/// law and the solver's settings. Made from a shipped scene (`Scene.load("paper")`), a TOML
/// file or text (`Scene.from_toml`), or a dict (`Scene.from_dict`); changed key by key with
/// `set`; given a mesh as arrays with `set_mesh`. Every change is validated at once, with the
/// errors of the command line (an `InputError` naming the key).
#[pyclass(module = "piezocontact")]
#[derive(Clone)]
pub struct Scene {
    tree: toml::Table,
    pub(crate) scene: problem::Scene,
    pub(crate) source: Source,
    pub(crate) mesh: Option<Arc<mesh::Mesh>>,
}

/// The nodes of `set_mesh`'s `points` as `[x, y, z]` rows and the mesh's dimension (after the
/// memory check, which reads the size of `cells` too).
fn points_of(py: Python<'_>, points: &Bound<'_, PyAny>, cells: &Bound<'_, PyAny>) -> PyResult<(Vec<[f64; 3]>, usize)> {
    let np = py.import("numpy")?;
    let raw = np
        .call_method1("asarray", (points,))
        .map_err(|e| Kind::Mesh.err(format!("mesh arrays: points are not an array of numbers ({e})")))?;
    let kind: String = raw.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") && raw.getattr("size")?.extract::<usize>()? > 0 {
        // a complex array would lose its imaginary parts to the cast with a mere warning
        return Err(Kind::Mesh.err(format!(
            "mesh arrays: points must hold real numbers, not {}",
            raw.getattr("dtype")?.str()?
        )));
    }
    let points = np
        .call_method1("ascontiguousarray", (raw, "float64"))
        .map_err(|e| Kind::Mesh.err(format!("mesh arrays: points are not an array of numbers ({e})")))?;
    let points: PyReadonlyArray2<'_, f64> = points
        .extract()
        .map_err(|_| Kind::Mesh.err("mesh arrays: points must be a 2-D array, (n, 2) or (n, 3)"))?;
    let columns = points.shape()[1];
    if !(columns == 2 || columns == 3) {
        return Err(Kind::Mesh.err(format!(
            "mesh arrays: points have {columns} columns: (n, 2) in 2D, (n, 3) in 3D"
        )));
    }
    // the cells' size, from NumPy's own shape, before any array is copied
    // (cells that are no array are refused with their own message when they are read)
    let shape: Vec<usize> = np
        .call_method1("shape", (cells,))
        .and_then(|s| s.extract())
        .unwrap_or_default();
    if let [rows, width] = shape[..] {
        check_mesh_memory(points.shape()[0], rows.saturating_mul(width), width, columns)?;
    }
    let mut xyz = vec![[0.0; 3]; points.shape()[0]];
    for (p, row) in xyz.iter_mut().zip(points.as_array().rows()) {
        for (k, x) in row.iter().enumerate() {
            p[k] = *x;
        }
    }
    // (n, 3) points in one plane z = const are a 2D mesh, as meshio gives a 2D Gmsh mesh
    // (the Gmsh reader's rule); the plane is put at z = 0
    let planar = columns == 3 && xyz.windows(2).all(|w| w[0][2] == w[1][2]);
    let dim = if planar { 2 } else { columns };
    if planar {
        xyz.iter_mut().for_each(|p| p[2] = 0.0);
    }
    Ok((xyz, dim))
}

/// The scene's tree with its `[mesh]` table made `kind = "given"`: the arrays replace how the
/// mesh was made, and only that; what the table says of the body (`axisymmetric`, `revolve`)
/// stays.
fn given_mesh_table(mut tree: toml::Table) -> toml::Table {
    let mut spec = match tree.remove("mesh") {
        Some(toml::Value::Table(t)) => t,
        _ => toml::Table::new(),
    };
    for key in MAKING_KEYS {
        spec.remove(key);
    }
    spec.insert("kind".into(), toml::Value::String("given".into()));
    tree.insert("mesh".into(), toml::Value::Table(spec));
    tree
}

/// The `[mesh]` keys that say how a mesh is made (a generator's box and sizes, a file): the
/// ones a mesh given as arrays replaces.
const MAKING_KEYS: [&str; 13] = [
    "kind", "lo", "hi", "n", "nx", "ny", "nz", "h", "file", "smoke_n", "region", "grading", "cylinder",
];

/// Refuses a mesh whose arrays this process cannot hold and check, before any of them is
/// copied: the nodes (3 doubles each, twice: the copy and the mesh), the cells' indices
/// (`entries`, 8 bytes each, twice) and the topology check's facets (each cell's facets, their
/// sorted nodes and owner: `(dim + 2)` words per facet, `dim + 1` facets per simplex), against
/// what `files::memory::available` finds (the machine, `ulimit`, a cgroup). A mesh of 1e8
/// points aborted at an allocation.
fn check_mesh_memory(n_points: usize, entries: usize, nodes_per_cell: usize, dim: usize) -> PyResult<()> {
    let cells = entries.checked_div(nodes_per_cell).unwrap_or(0) as f64;
    let need = 2.0 * 24.0 * n_points as f64
        + 2.0 * 8.0 * entries as f64
        + cells * nodes_per_cell as f64 * (dim + 2) as f64 * 8.0;
    match files::memory::available() {
        Some(a) if need > a.bytes as f64 => Err(Kind::Solver.err(format!(
            "mesh arrays: a mesh of {n_points} points and {cells} cells needs about {:.1} GB to hold and check, and {} leaves {:.1} GB",
            need / 1e9,
            a.limit,
            a.bytes as f64 / 1e9
        ))),
        _ => Ok(()),
    }
}

fn here() -> PathBuf {
    std::env::current_dir().unwrap_or_default()
}

/// The dotted keys and values of a `set` call: a key and a value, a mapping of dotted keys, or
/// keywords (a section as a dict merged key by key, or a key with `__` for its dots). `None`
/// removes a key.
fn changes(
    key: Option<&Bound<'_, PyAny>>,
    value: Option<&Bound<'_, PyAny>>,
    sections: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(String, Option<toml::Value>)>> {
    let mut out = vec![];
    match (key, value) {
        (Some(k), Some(v)) if k.is_instance_of::<PyString>() => out.push(change(&k.extract::<String>()?, v)?),
        (Some(k), None) if k.is_instance_of::<PyString>() => {
            return Err(Kind::Input.err(format!("set(\"{k}\") needs a value (None removes the key)")))
        }
        (Some(m), None) => {
            let m = m
                .cast::<PyMapping>()
                .map_err(|_| Kind::Input.err("set() takes a dotted key and a value, or a dict of them"))?;
            for item in m.items()?.iter() {
                let (k, v): (String, Bound<'_, PyAny>) = item.extract()?;
                out.push(change(&k, &v)?);
            }
        }
        (Some(_), Some(_)) => return Err(Kind::Input.err("set(key, value): the key is a dotted string")),
        (None, _) => {}
    }
    if let Some(sections) = sections {
        for (name, v) in sections.iter() {
            // `mesh__n=128` is `mesh.n` (a keyword holds no dot)
            flatten(&name.extract::<String>()?.replace("__", "."), &v, &mut out)?;
        }
    }
    refuse_overlaps(&out)?;
    Ok(out)
}

/// One call names each key once: a key given twice (by a dict and by a keyword, `mesh.n` and
/// `mesh__n`), a key and a table that holds it (`mesh` and `mesh.n`), or two keys of one
/// quantity (`mesh.n` and `mesh.h`) would keep one of them silently
/// (`scene_file::keys_overlap`).
fn refuse_overlaps(changes: &[(String, Option<toml::Value>)]) -> PyResult<()> {
    for (k, (a, _)) in changes.iter().enumerate() {
        if let Some((b, _)) = changes[..k].iter().find(|(b, _)| scene_file::keys_overlap(a, b)) {
            let what = if a == b {
                format!("`{a}` is given twice")
            } else {
                format!("`{b}` and `{a}` both change one value")
            };
            return Err(Kind::Input.err(format!(
                "set(): {what} in one call (a dict and a keyword, a table and one of its keys, or mesh.n and mesh.h); give each once"
            )));
        }
    }
    Ok(())
}

/// A keyword section: a dict is merged key by key (nested dicts too), anything else set whole.
fn flatten(prefix: &str, v: &Bound<'_, PyAny>, out: &mut Vec<(String, Option<toml::Value>)>) -> PyResult<()> {
    if let Ok(d) = v.cast::<PyDict>() {
        for (k, x) in d.iter() {
            flatten(&format!("{prefix}.{}", k.extract::<String>()?), &x, out)?;
        }
        return Ok(());
    }
    out.push(change(prefix, v)?);
    Ok(())
}

/// One key's change: its TOML value, or `None` (removal) for Python's None.
fn change(key: &str, v: &Bound<'_, PyAny>) -> PyResult<(String, Option<toml::Value>)> {
    Ok((key.to_string(), if v.is_none() { None } else { Some(to_toml(v, key)?) }))
}

impl Scene {
    /// The scene of `tree`, validated, after `changes`.
    fn of(
        mut tree: toml::Table,
        source: Source,
        changes: Vec<(String, Option<toml::Value>)>,
        mesh: Option<Arc<mesh::Mesh>>,
    ) -> PyResult<Scene> {
        for (key, value) in changes {
            let removing = value.is_none();
            scene_file::set(&mut tree, &key, value).map_err(|m| {
                let what = if removing { "removing" } else { "setting" };
                Kind::Input.err(format!("scene {}: {what} {key}: {m}", source.label))
            })?;
        }
        let scene = scene_file::from_tree(tree.clone(), &source.label).map_err(to_py)?;
        // the arrays go with `mesh.kind = "given"`; a change of the mesh's kind lets them go
        let mesh = mesh.filter(|_| scene.mesh.kind == problem::MeshKind::Given);
        Ok(Scene {
            tree,
            scene,
            source,
            mesh,
        })
    }

    fn from_text(
        text: &str,
        source: Source,
        overrides: Option<&Bound<'_, PyAny>>,
        keywords: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        let tree: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| Kind::Input.err(format!("scene {}: {e}", source.label)))?;
        Self::of(tree, source, changes(overrides, None, keywords)?, None)
    }
}

#[pymethods]
impl Scene {
    /// A shipped scene by name (see `Scene.shipped()`), or a scene file by path, with
    /// `overrides` (a dict of dotted keys; None removes a key) and keywords (as `set` takes
    /// them: `mesh__n=128`, `solver={"tol": 1e-10}`) applied before it is validated.
    #[staticmethod]
    #[pyo3(signature = (name, overrides = None, **keywords))]
    fn load(
        name: &Bound<'_, PyAny>,
        overrides: Option<&Bound<'_, PyAny>>,
        keywords: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        let name = name.str()?.to_string();
        let (text, source) = scene_file::text(&name).map_err(to_py)?;
        Self::from_text(&text, source, overrides, keywords)
    }

    /// A scene from a TOML file (a path, or a string naming a file) or from TOML text. Relative
    /// paths in the scene (a Gmsh file) resolve against the file's directory, or for text
    /// against the working directory.
    #[staticmethod]
    #[pyo3(signature = (source, overrides = None, **keywords))]
    fn from_toml(
        source: &Bound<'_, PyAny>,
        overrides: Option<&Bound<'_, PyAny>>,
        keywords: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        // a string is a path where it names a file, or looks like one (one line ending in
        // `.toml`, so that a mistyped path says "no such file", not a TOML error)
        let is_text = source.is_instance_of::<PyString>() && {
            let s: String = source.extract()?;
            s.contains('\n') || (!std::path::Path::new(&s).exists() && !s.trim_end().ends_with(".toml"))
        };
        if is_text {
            let s: String = source.extract()?;
            let label = "<toml text>".to_string();
            return Self::from_text(&s, Source { label, dir: here() }, overrides, keywords);
        }
        let path = source
            .py()
            .import("os")?
            .call_method1("fspath", (source,))?
            .extract::<String>()
            .map_err(|_| Kind::Input.err("from_toml takes a path or TOML text"))?;
        let (text, source) = scene_file::text(&path).map_err(to_py)?;
        Self::from_text(&text, source, overrides, keywords)
    }

    /// A scene from a dict of its sections, as the TOML file would hold them (`{"mesh":
    /// {"kind": "rectangle", ...}, "material": [{...}], ...}`).
    #[staticmethod]
    #[pyo3(signature = (scene, overrides = None, **keywords))]
    fn from_dict(
        scene: &Bound<'_, PyAny>,
        overrides: Option<&Bound<'_, PyAny>>,
        keywords: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        let tree = to_table(scene)?;
        let source = Source {
            label: "<dict>".into(),
            dir: here(),
        };
        Self::of(tree, source, changes(overrides, None, keywords)?, None)
    }

    /// The names of the shipped scenes.
    #[staticmethod]
    fn shipped() -> Vec<&'static str> {
        scene_file::SHIPPED.iter().map(|(n, _)| *n).collect()
    }

    /// Changes keys: `set("mesh.n", 128)`, `set({"contact.law": "signorini", "contact.friction":
    /// None})`, or keywords: a key with `__` for its dots (`set(mesh__n=128)`), or a section
    /// merged key by key (`set(mesh={"n": 128}, solver={"tol": 1e-10})`). None removes a key. The changes are validated together and
    /// made only if the scene they give is valid (else `InputError`, the scene unchanged).
    #[pyo3(signature = (*args, **sections))]
    fn set(&mut self, args: &Bound<'_, PyTuple>, sections: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        let changes = match args.len() {
            0 => changes(None, None, sections)?,
            1 => changes(Some(&args.get_item(0)?), None, sections)?,
            2 => changes(Some(&args.get_item(0)?), Some(&args.get_item(1)?), sections)?,
            n => return Err(Kind::Input.err(format!("set() takes a key and a value, or a dict; {n} arguments given"))),
        };
        *self = Self::of(self.tree.clone(), self.source.clone(), changes, self.mesh.clone())?;
        Ok(())
    }

    /// The value of a dotted key (`scene.get("mesh.n")`, `scene.get("contact.1.gap")`: read as
    /// `set` writes it), or `default` where the scene does not set it; an `InputError` for a key
    /// that does not say which of several tables it means (`contact.gap` with two zones).
    #[pyo3(signature = (key, default = None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        key: &str,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        let found = scene_file::get(&self.tree, key).map_err(|m| Kind::Input.err(format!("get(\"{key}\"): {m}")))?;
        match found {
            Some(v) => from_toml(py, v).map(Some),
            None => Ok(default),
        }
    }

    /// Gives the scene a mesh as arrays (`mesh.kind` becomes `"given"`): `points` (n, 2) or (n,
    /// 3) floats; `cells` (m, 3) triangles or (m, 4) quadrilaterals in 2D, (m, 4) tetrahedra in
    /// 3D, 0-based, or second-order cells ((m, 6) triangles, (m, 10) tetrahedra, their edge
    /// nodes in VTK's order); `boundary` a dict of named facet arrays ((k, 2) segments in 2D,
    /// (k, 3) triangles in 3D; of a second-order mesh (k, 3) and (k, 6), the corners then the
    /// edges' midpoints) for the conditions' groups; `regions` a dict of named cell-index
    /// arrays for the materials (default: all cells in `"body"`). Cells numbered clockwise
    /// (2D) or negatively (3D) throughout are turned round. The mesh is checked as a file's
    /// is (`MeshError`). The arrays replace only how the mesh was made: the `[mesh]` keys that
    /// describe the body (`axisymmetric`, `revolve`) stay. A mesh too large for the memory
    /// left is refused before it is copied (`SolverError`, naming the limit).
    #[pyo3(signature = (points, cells, boundary, regions = None))]
    fn set_mesh(
        &mut self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        cells: &Bound<'_, PyAny>,
        boundary: &Bound<'_, PyAny>,
        regions: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (xyz, dim) = points_of(py, points, cells)?;
        let (flat, nodes_per_cell) = indices(py, cells, "cells")?;
        let mut boundaries = BTreeMap::new();
        let boundary = boundary
            .cast::<PyMapping>()
            .map_err(|_| Kind::Mesh.err("mesh arrays: boundary is a dict of named facet arrays"))?;
        for item in boundary.items()?.iter() {
            let (name, facets): (String, Bound<'_, PyAny>) = item.extract()?;
            let (flat, width) = indices(py, &facets, &format!("boundary[{name:?}]"))?;
            // a facet of a second-order mesh: its corners, then its edges' midpoints
            let expected = match mesh::CellKind::of(dim, nodes_per_cell) {
                Some(kind) => kind.facet_n_nodes(),
                None => dim,
            };
            if !flat.is_empty() && width != expected {
                return Err(Kind::Mesh.err(format!(
                    "mesh arrays: boundary[{name:?}] has facets of {width} nodes: {expected} for cells of {nodes_per_cell} nodes in {dim}D"
                )));
            }
            boundaries.insert(name, flat);
        }
        let n_cells = flat.len().checked_div(nodes_per_cell).unwrap_or(0);
        let mut region_map = BTreeMap::new();
        match regions {
            None => {
                region_map.insert("body".to_string(), (0..n_cells).collect());
            }
            Some(r) => {
                let r = r
                    .cast::<PyMapping>()
                    .map_err(|_| Kind::Mesh.err("mesh arrays: regions is a dict of named cell-index arrays"))?;
                for item in r.items()?.iter() {
                    let (name, list): (String, Bound<'_, PyAny>) = item.extract()?;
                    let ints = integers(py, &list, &format!("regions[{name:?}]"))?;
                    let ints: PyReadonlyArray1<'_, i64> = ints.extract().map_err(|_| {
                        Kind::Mesh.err(format!(
                            "mesh arrays: regions[{name:?}] must be a 1-D array of cell indices"
                        ))
                    })?;
                    region_map.insert(name.clone(), unsigned(ints.as_slice()?, &format!("regions[{name:?}]"))?);
                }
            }
        }
        let parts = mesh::MeshParts {
            dim,
            points: xyz,
            cells: flat,
            nodes_per_cell,
            boundaries,
            regions: region_map,
        };
        let mesh = py.detach(|| mesh::Mesh::from_parts(parts)).map_err(mesh_err)?;
        let tree = given_mesh_table(self.tree.clone());
        *self = Self::of(tree, self.source.clone(), vec![], Some(Arc::new(mesh)))?;
        Ok(())
    }

    /// The scene as a dict of its sections (as `from_dict` takes it).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        from_table(py, &self.tree)
    }

    /// The scene as TOML text (as `from_toml` takes it; a mesh given as arrays is not in it).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.tree).map_err(|e| Kind::Input.err(e.to_string()))
    }

    /// A copy, to change without changing this one (for a sweep).
    fn copy(&self) -> Scene {
        self.clone()
    }

    fn __copy__(&self) -> Scene {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Scene {
        self.clone()
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> &str {
        &self.scene.name
    }

    /// The spatial dimension (2 or 3), None for a Gmsh file not yet read.
    #[getter]
    fn dim(&self) -> Option<usize> {
        self.mesh.as_ref().map(|m| m.dim).or_else(|| self.scene.mesh.dim())
    }

    /// Where the scene came from: a shipped scene's name, a path, `<dict>` or `<toml text>`.
    #[getter]
    fn source(&self) -> &str {
        &self.source.label
    }

    fn __repr__(&self) -> String {
        let mesh = match &self.mesh {
            Some(m) => format!(", mesh given: {} nodes, {} cells", m.n_nodes(), m.n_cells()),
            None => String::new(),
        };
        format!(
            "<piezocontact.Scene {:?} from {}{mesh}: {}>",
            self.scene.name, self.source.label, self.scene.description
        )
    }
}

/// Non-negative 64-bit integers as indices; `what` names them in the error.
fn unsigned(v: &[i64], what: &str) -> PyResult<Vec<usize>> {
    v.iter()
        .map(|&i| {
            usize::try_from(i).map_err(|_| Kind::Mesh.err(format!("mesh arrays: {what} holds the negative index {i}")))
        })
        .collect()
}

/// A 2-D integer array as flat indices and its row length.
fn indices(py: Python<'_>, v: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<usize>, usize)> {
    let a = integers(py, v, what)?;
    let a: PyReadonlyArray2<'_, i64> = a
        .extract()
        .map_err(|_| Kind::Mesh.err(format!("mesh arrays: {what} must be a 2-D array, one row per item")))?;
    let width = a.shape()[1];
    Ok((unsigned(a.as_slice()?, what)?, width))
}

/// `v` as a contiguous array of 64-bit integers, refused where it holds other numbers (a float
/// index would be cut silently).
fn integers<'py>(py: Python<'py>, v: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (v,))
        .map_err(|e| Kind::Mesh.err(format!("mesh arrays: {what} is not an array of indices ({e})")))?;
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    if !(kind == "i" || kind == "u") && a.getattr("size")?.extract::<usize>()? > 0 {
        return Err(Kind::Mesh.err(format!(
            "mesh arrays: {what} must hold integer indices, not {}",
            a.getattr("dtype")?.str()?
        )));
    }
    np.call_method1("ascontiguousarray", (a, "int64"))
}
