//! `Result` and `Contact`: a run's solution as NumPy arrays over the solution's own storage
//! (read-only, no copy where the layout allows), its report as a dict, and its outputs.

use crate::arrays::{lend, owned};
use crate::errors::{to_py, Kind};
use crate::values::from_json;
use numpy::ndarray::{s, Array2, Array3, ArrayView1, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Contact status codes of `Contact.status` (and of `contact_status` in the outputs).
pub const STICK: i8 = 1;
/// A point that slides.
pub const SLIP: i8 = 2;
/// A point off the foundation.
pub const SEPARATED: i8 = 3;

/// The solution of a run: the mesh (`points`, `cells`), the nodal fields (`u`, `phi`), the
/// per-cell fields (`stress`, `strain`, `electric_displacement`, `electric_field`), the contact
/// boundary's values (`contact`), and the report (`report`, run.json as a dict). The arrays
/// are read-only views of the solution's storage (float64; `cells` int64).
#[pyclass(module = "piezocontact", name = "Result", frozen)]
pub struct RunResult {
    pub(crate) solution: problem::Solution,
    /// A load path's contact values at every instant, where the run was asked for them.
    pub(crate) series: Option<Series>,
}

/// A load path's contact values at every instant (`run(..., series=True)`): one row of
/// `n_points` per instant, flat.
#[derive(Default)]
pub struct Series {
    /// Points per instant.
    pub n_points: usize,
    /// Tangential components per point (`dim - 1`).
    pub n_tangential: usize,
    /// `λ_n`.
    pub lambda_n: Vec<f64>,
    /// `λ_t`, every tangential component of each point.
    pub lambda_t: Vec<f64>,
    /// `u_n`.
    pub u_n: Vec<f64>,
    /// `u_t`, every tangential component of each point.
    pub u_t: Vec<f64>,
    /// Contact status codes.
    pub status: Vec<i8>,
    /// With electrical contact, the outward flux `q = D·ν` of each point (NaN at a point
    /// without an electric unknown); empty without.
    pub flux: Vec<f64>,
}

impl Series {
    /// Adds an instant's contact solution.
    pub fn push(&mut self, c: &problem::ContactResult) {
        let n = c.points.len();
        self.n_points = n;
        self.n_tangential = c.points.dim - 1;
        let (lambda, u) = (&c.solution.lambda, &c.displacement);
        // every tangential component (zeros where the solution carries none: frictionless)
        let all = |v: &contact::PointValues, i: usize, out: &mut Vec<f64>| {
            let t = v.tangential_of(i);
            out.extend((0..c.points.dim - 1).map(|k| t.get(k).copied().unwrap_or(0.0)));
        };
        for i in 0..n {
            self.lambda_n.push(lambda.normal[i]);
            all(lambda, i, &mut self.lambda_t);
            self.u_n.push(u.normal[i]);
            all(u, i, &mut self.u_t);
            self.status.push(status_code(c.solution.status[i]));
        }
        if let Some(e) = &c.solution.electric {
            let start = self.flux.len();
            self.flux.resize(start + n, f64::NAN);
            for (&i, q) in e.points.iter().zip(&e.flux) {
                self.flux[start + i] = *q;
            }
        }
    }
}

/// The code of a contact status.
pub fn status_code(s: contact::Status) -> i8 {
    match s {
        contact::Status::Stick => STICK,
        contact::Status::Slip => SLIP,
        contact::Status::Separated => SEPARATED,
    }
}

/// The `dim`-column view of `[x, y, z]` rows.
fn columns(rows: &[[f64; 3]], dim: usize) -> ArrayView2<'_, f64> {
    let full = ArrayView2::from_shape((rows.len(), 3), rows.as_flattened()).expect("3 values per row");
    full.slice_move(s![.., ..dim])
}

/// Symmetric tensors of six components in VTK's order (`xx, yy, zz, xy, yz, xz`) as full
/// `(n, 3, 3)` matrices.
fn full_tensors(six: &[f64]) -> Array3<f64> {
    let n = six.len() / 6;
    Array3::from_shape_fn((n, 3, 3), |(i, a, b)| {
        // the position in VTK's order of the pair (a, b)
        const AT: [[usize; 3]; 3] = [[0, 3, 5], [3, 1, 4], [5, 4, 2]];
        six[6 * i + AT[a][b]]
    })
}

/// The `(n / width, width)` view of a flat list.
fn table(flat: &[f64], width: usize) -> ArrayView2<'_, f64> {
    let rows = flat.len().checked_div(width).unwrap_or(0);
    ArrayView2::from_shape((rows, width), flat).expect("whole rows")
}

impl RunResult {
    fn dim(&self) -> usize {
        self.solution.mesh.dim
    }

    /// Voigt components per cell: 3 in plane strain, 4 on a body of revolution (`[rr, zz,
    /// rz, θθ]`), 6 in 3D.
    fn nv(&self) -> usize {
        self.solution.fields.stress.len() / self.solution.mesh.n_cells().max(1)
    }

    /// The per-cell fields as 3D tensors and vectors.
    fn cell_tensors(&self) -> problem::Tensors {
        self.solution.fields.tensors(self.dim())
    }

    /// The meshio cell type of the mesh's cells.
    fn cell_type(&self) -> &'static str {
        match self.solution.mesh.kind {
            mesh::CellKind::Tri3 => "triangle",
            mesh::CellKind::Quad4 => "quad",
            mesh::CellKind::Tet4 => "tetra",
            mesh::CellKind::Tri6 => "triangle6",
            mesh::CellKind::Tet10 => "tetra10",
        }
    }
}

#[pymethods]
impl RunResult {
    /// Node coordinates, (n_points, dim).
    #[getter]
    fn points<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = this.get();
        lend(this.as_any(), columns(&r.solution.mesh.points, r.dim()))
    }

    /// Cell connectivity, (n_cells, nodes per cell), int64, 0-based; counter-clockwise (2D),
    /// positively oriented (3D).
    #[getter]
    fn cells<'py>(this: &Bound<'py, Self>) -> Bound<'py, PyArray2<i64>> {
        // a copy: NumPy's index type is signed (arithmetic on unsigned indices turns to floats)
        let m = &this.get().solution.mesh;
        let k = m.kind.n_nodes();
        let flat: Vec<i64> = m.cells.iter().map(|&v| v as i64).collect();
        owned(
            this.py(),
            numpy::ndarray::Array2::from_shape_vec((m.n_cells(), k), flat).expect("whole cells"),
        )
    }

    /// The cells' kind, as meshio names it: "triangle", "quad", "tetra", and at order 2
    /// "triangle6" or "tetra10" (VTK's node order).
    #[getter(cell_type)]
    fn py_cell_type(&self) -> &'static str {
        self.cell_type()
    }

    /// The spatial dimension, 2 (plane strain) or 3.
    #[getter(dim)]
    fn py_dim(&self) -> usize {
        self.dim()
    }

    /// Nodal displacements, (n_points, dim).
    #[getter]
    fn u<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = this.get();
        lend(this.as_any(), columns(&r.solution.u, r.dim()))
    }

    /// Nodal electric potentials, (n_points,) (0 where a node has no electric unknown).
    #[getter]
    fn phi<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        lend(this.as_any(), ArrayView1::from(&this.get().solution.phi[..]))
    }

    /// Stress per cell, Voigt order, (n_cells, 3) in plane strain (xx, yy, xy), (n_cells, 4) on
    /// a body of revolution (rr, zz, rz, θθ), (n_cells, 6) in 3D (xx, yy, zz, yz, xz, xy).
    #[getter]
    fn stress<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = this.get();
        lend(this.as_any(), table(&r.solution.fields.stress, r.nv()))
    }

    /// Strain per cell, Voigt order with engineering shears, shaped as `stress`.
    #[getter]
    fn strain<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = this.get();
        lend(this.as_any(), table(&r.solution.fields.strain, r.nv()))
    }

    /// Electric displacement per cell, (n_cells, dim).
    #[getter]
    fn electric_displacement<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = this.get();
        lend(this.as_any(), table(&r.solution.fields.electric_displacement, r.dim()))
    }

    /// Electric field `E = -grad phi` per cell, (n_cells, dim).
    #[getter]
    fn electric_field<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = this.get();
        lend(this.as_any(), table(&r.solution.fields.electric_field, r.dim()))
    }

    /// Stress per cell as full symmetric 3x3 tensors, (n_cells, 3, 3), in every dimension: in
    /// plane strain with the stresses across the plane (σ_zz, and σ_yz, σ_xz where the
    /// material couples them), on a body of revolution in the axes (r, z, θ) (its hoop
    /// stress at [2, 2]), in 3D (x, y, z). The same values as `stress`, laid out so that
    /// no Voigt order needs knowing (the invariants, `numpy.linalg.eigvalsh`, von Mises).
    #[getter]
    fn stress_tensor<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let t = self.cell_tensors();
        owned(py, full_tensors(&t.stress))
    }

    /// Strain per cell as full symmetric 3x3 tensors (tensor shears, ε_xy = γ_xy / 2), shaped
    /// and laid out as `stress_tensor` (in plane strain its out-of-plane components are 0).
    #[getter]
    fn strain_tensor<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let t = self.cell_tensors();
        owned(py, full_tensors(&t.strain))
    }

    /// On quadratic (P2) cells, whose fields vary across each cell: the fields at the nodes,
    /// a dict of `stress`, `strain` ((n_points, nv)), `electric_displacement` and
    /// `electric_field` ((n_points, dim)), each node's value the measure-weighted average of
    /// its cells' values there; None on P1 cells (constant in each: the per-cell arrays are
    /// the whole field).
    #[getter]
    fn fields_at_nodes<'py>(this: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let r = this.get();
        let Some(at) = &r.solution.fields.at_nodes else {
            return Ok(None);
        };
        let (owner, out) = (this.as_any(), PyDict::new(this.py()));
        out.set_item("stress", lend(owner, table(&at.stress, r.nv()))?)?;
        out.set_item("strain", lend(owner, table(&at.strain, r.nv()))?)?;
        out.set_item(
            "electric_displacement",
            lend(owner, table(&at.electric_displacement, r.dim()))?,
        )?;
        out.set_item("electric_field", lend(owner, table(&at.electric_field, r.dim()))?)?;
        Ok(Some(out))
    }

    /// The contact boundary's values, None for a scene without contact.
    #[getter]
    fn contact(this: &Bound<'_, Self>) -> Option<Contact> {
        this.get().solution.contact.as_ref().map(|_| Contact {
            owner: this.clone().unbind(),
        })
    }

    /// A load path's series (None for a run of one instant), a dict of NumPy arrays over its
    /// instants: the `path.csv` columns (`step`, `t`, the factors `load`, `voltage`, `ux`, `uy`,
    /// `uz`, `gap`, `normal_force`, `tangential_force`, `max_slip`, `max_slip_increment`,
    /// `n_stick`, `n_slip`, `n_separated`, `iterations`, `complementarity`, `equilibrium` (NaN
    /// where the instant's fields were not computed), and under an indenter `depth` and
    /// `contact_radius`, a conducting tip's `tip_charge`, and where the half-space's closed form
    /// applies `half_space_depth`, `_force`, `_contact_radius`, `_charge`), the tangential force's components `tangential_force_x`, `_y`
    /// (`_z` in 3D) beside its magnitude `tangential_force`, `charges` and `potentials`
    /// (n_instants, n_terminals: the charge on each conductor) with `terminals` their groups;
    /// and with `run(..., series=True)` the contact values of every point at every instant:
    /// `lambda_n`, `u_n` and `status` (n_instants, n_points), `lambda_t` and `u_t` (n_instants,
    /// n_points, dim - 1: every tangential component, as `contact.lambda_t`).
    #[getter]
    fn path<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(path) = &self.solution.report.path else {
            return Ok(None);
        };
        let rows = &path.rows;
        let out = PyDict::new(py);
        let column = |f: &dyn Fn(&problem::report::StepRow) -> f64| {
            owned(py, numpy::ndarray::Array1::from_iter(rows.iter().map(f)))
        };
        out.set_item("step", column(&|r| r.step as f64))?;
        out.set_item("t", column(&|r| r.t))?;
        for (k, name) in ["load", "voltage", "ux", "uy", "uz", "gap"].iter().enumerate() {
            // a 2D scene has no z factor (path.csv leaves the column out too)
            if *name != "uz" || self.solution.mesh.dim == 3 {
                out.set_item(*name, column(&|r| r.factors[k]))?;
            }
        }
        out.set_item("normal_force", column(&|r| r.normal_force))?;
        out.set_item("tangential_force", column(&|r| r.tangential_force))?;
        for (k, axis) in ["x", "y", "z"].iter().enumerate().take(self.solution.mesh.dim) {
            let component = column(&|r| r.tangential_resultant.get(k).copied().unwrap_or(f64::NAN));
            out.set_item(format!("tangential_force_{axis}"), component)?;
        }
        // several contact groups: each one's forces, as path.csv's columns
        let groups: Vec<String> = rows
            .first()
            .map_or(vec![], |r| r.groups.iter().map(|g| g.group.clone()).collect());
        for (k, g) in groups.iter().enumerate() {
            let of = |f: &dyn Fn(&problem::report::ContactGroupReport) -> f64| {
                column(&|r| r.groups.get(k).map_or(f64::NAN, f))
            };
            out.set_item(format!("normal_force_{g}"), of(&|g| g.normal_force))?;
            out.set_item(format!("tangential_force_{g}"), of(&|g| g.tangential_force))?;
            for (q, axis) in ["x", "y", "z"].iter().enumerate().take(self.solution.mesh.dim) {
                let component = of(&|g| g.tangential_resultant.get(q).copied().unwrap_or(f64::NAN));
                out.set_item(format!("tangential_force_{axis}_{g}"), component)?;
            }
        }
        out.set_item("max_slip", column(&|r| r.max_slip))?;
        out.set_item("max_slip_increment", column(&|r| r.max_slip_increment))?;
        out.set_item("n_stick", column(&|r| r.n_stick as f64))?;
        out.set_item("n_slip", column(&|r| r.n_slip as f64))?;
        out.set_item("n_separated", column(&|r| r.n_separated as f64))?;
        out.set_item("iterations", column(&|r| r.iterations as f64))?;
        out.set_item("complementarity", column(&|r| r.complementarity))?;
        out.set_item("equilibrium", column(&|r| r.equilibrium.unwrap_or(f64::NAN)))?;
        if rows.iter().any(|r| r.depth.is_some()) {
            out.set_item("depth", column(&|r| r.depth.unwrap_or(f64::NAN)))?;
            out.set_item("contact_radius", column(&|r| r.contact_radius.unwrap_or(f64::NAN)))?;
        }
        if rows.iter().any(|r| r.tip_charge.is_some()) {
            out.set_item("tip_charge", column(&|r| r.tip_charge.unwrap_or(f64::NAN)))?;
        }
        if rows.iter().any(|r| r.half_space.is_some()) {
            let of = |f: &dyn Fn(&problem::report::HalfSpaceRow) -> f64| {
                column(&|r| r.half_space.as_ref().map_or(f64::NAN, f))
            };
            out.set_item("half_space_depth", of(&|h| h.depth))?;
            out.set_item("half_space_force", of(&|h| h.force))?;
            out.set_item("half_space_contact_radius", of(&|h| h.contact_radius))?;
            out.set_item("half_space_charge", of(&|h| h.charge.unwrap_or(f64::NAN)))?;
        }
        let terminals: Vec<&str> = self
            .solution
            .report
            .terminals
            .iter()
            .map(|t| t.group.as_str())
            .collect();
        let shape = (rows.len(), terminals.len());
        let per_terminal = |of: &dyn Fn(&problem::report::StepRow) -> &[f64]| {
            let values: Vec<f64> = rows.iter().flat_map(|r| of(r).iter().copied()).collect();
            numpy::ndarray::Array2::from_shape_vec(shape, values).map_err(|e| Kind::Base.err(e.to_string()))
        };
        out.set_item("charges", owned(py, per_terminal(&|r| &r.charges)?))?;
        out.set_item("potentials", owned(py, per_terminal(&|r| &r.potentials)?))?;
        out.set_item("terminals", terminals)?;
        if let Some(series) = &self.series {
            let shape = (rows.len(), series.n_points);
            let table = |v: &[f64]| {
                numpy::ndarray::Array2::from_shape_vec(shape, v.to_vec()).map_err(|e| Kind::Base.err(e.to_string()))
            };
            out.set_item("lambda_n", owned(py, table(&series.lambda_n)?))?;
            let tangential = |v: &[f64]| {
                numpy::ndarray::Array3::from_shape_vec((rows.len(), series.n_points, series.n_tangential), v.to_vec())
                    .map_err(|e| Kind::Base.err(e.to_string()))
            };
            out.set_item("lambda_t", owned(py, tangential(&series.lambda_t)?))?;
            out.set_item("u_n", owned(py, table(&series.u_n)?))?;
            out.set_item("u_t", owned(py, tangential(&series.u_t)?))?;
            let status = numpy::ndarray::Array2::from_shape_vec(shape, series.status.clone())
                .map_err(|e| Kind::Base.err(e.to_string()))?;
            out.set_item("status", owned(py, status))?;
            if series.flux.len() == series.lambda_n.len() {
                out.set_item("flux", owned(py, table(&series.flux)?))?;
            }
        }
        Ok(Some(out))
    }

    /// The report (run.json) as a dict: the scene, the plan, the sizes, the iterations, the
    /// residuals, the contact forces and counts, the timings.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let bytes = files::output::run_json_of(&self.solution).map_err(to_py)?;
        from_json(py, &String::from_utf8_lossy(&bytes))
    }

    /// Writes the run's outputs into `directory` as the command line does (run.json,
    /// solution.vtu, contact.csv and the pictures the plan lists), as one set: on error nothing
    /// is left half-written (`OutputError`).
    fn write(&self, py: Python<'_>, directory: &Bound<'_, PyAny>) -> PyResult<()> {
        let dir: String = py.import("os")?.call_method1("fspath", (directory,))?.extract()?;
        py.detach(|| files::output::write(&self.solution, std::path::Path::new(&dir)))
            .map_err(to_py)
    }

    /// The solution as a `meshio.Mesh` (needs meshio): 3-component points and `u` as ParaView
    /// takes them, `phi` and `contact_status` as point data, the per-cell fields as cell data
    /// as solution.vtu holds them (`stress`, `strain` six components in VTK's tensor order,
    /// `xx, yy, zz, xy, yz, xz`, tensor shears; `electric_displacement`, `electric_field`
    /// three);
    /// from there, `meshio.write`, PyVista (`pyvista.from_meshio`) and the rest.
    fn to_meshio<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = this.py();
        let meshio = py.import("meshio").map_err(|_| {
            pyo3::exceptions::PyImportError::new_err(
                "to_meshio needs meshio (pip install meshio, or pip install piezocontact[meshio])",
            )
        })?;
        let r = this.get();
        let owner = this.as_any();
        let points = lend(owner, columns(&r.solution.mesh.points, 3))?;
        let cells = pyo3::types::PyList::new(py, [(r.cell_type(), Self::cells(this))])?;
        let point_data = PyDict::new(py);
        point_data.set_item("u", lend(owner, columns(&r.solution.u, 3))?)?;
        point_data.set_item("phi", Self::phi(this)?)?;
        if let Some(c) = &r.solution.contact {
            let mut status = vec![0i8; r.solution.mesh.n_nodes()];
            for (i, &node) in c.nodes.iter().enumerate() {
                status[node] = status_code(c.solution.status[i]);
            }
            point_data.set_item("contact_status", status.into_pyarray(py))?;
        }
        // the fields as the files hold them: tensors of six components in VTK's order (which
        // ParaView reads as XX, YY, ZZ, XY, YZ, XZ), vectors of three
        let viewed = |t: problem::Tensors| -> [(&str, Bound<'py, PyArray2<f64>>); 4] {
            let rows = |flat: Vec<f64>, w: usize| {
                let n = flat.len() / w;
                owned(py, Array2::from_shape_vec((n, w), flat).expect("whole rows"))
            };
            [
                ("stress", rows(t.stress, 6)),
                ("strain", rows(t.strain, 6)),
                ("electric_displacement", rows(t.electric_displacement, 3)),
                ("electric_field", rows(t.electric_field, 3)),
            ]
        };
        if let Some(at) = &r.solution.fields.at_nodes {
            // P2 cells: the fields at the nodes beside the cells'
            for (name, values) in viewed(at.tensors(r.dim())) {
                point_data.set_item(name, values)?;
            }
        }
        let cell_data = PyDict::new(py);
        for (name, values) in viewed(r.cell_tensors()) {
            cell_data.set_item(name, [values])?;
        }
        let kwargs = PyDict::new(py);
        kwargs.set_item("point_data", point_data)?;
        kwargs.set_item("cell_data", cell_data)?;
        meshio.getattr("Mesh")?.call((points, cells), Some(&kwargs))
    }

    fn __repr__(&self) -> String {
        let rep = &self.solution.report;
        let contact = match &self.solution.contact {
            Some(c) => {
                let (stick, slip, sep) = c.solution.counts();
                format!(", contact: {stick} stick, {slip} slip, {sep} separated")
            }
            None => String::new(),
        };
        format!(
            "<piezocontact.Result of {:?}: {} nodes, {} cells{contact}, {:.3} s>",
            rep.scene.name,
            self.solution.mesh.n_nodes(),
            self.solution.mesh.n_cells(),
            rep.timings_s.total
        )
    }
}

/// The contact boundary's values, one row per contact point (a node of the contact group):
/// position `x`, mesh `node`, outward `normal`, `weight` (lumped boundary measure), initial
/// `gap`, displacement `u_n` (normal, `u_n <= gap`) and `u_t` (tangential, dim - 1 columns),
/// multipliers `lambda_n >= 0` (the pressure) and `lambda_t`, and `status` (STICK, SLIP,
/// SEPARATED). Read-only views of the solution's storage where the layout allows.
#[pyclass(module = "piezocontact", frozen)]
pub struct Contact {
    owner: Py<RunResult>,
}

impl Contact {
    fn with<'py, T>(
        &self,
        py: Python<'py>,
        f: impl FnOnce(&Bound<'py, PyAny>, &problem::ContactResult) -> PyResult<T>,
    ) -> PyResult<T> {
        let owner = self.owner.bind(py);
        let c = owner
            .get()
            .solution
            .contact
            .as_ref()
            .ok_or_else(|| Kind::Base.err("the run has no contact"))?;
        f(owner.as_any(), c)
    }
}

#[pymethods]
impl Contact {
    /// Positions, (m, dim).
    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.with(py, |o, c| lend(o, columns(&c.points.position, c.points.dim)))
    }

    /// The mesh node of each point, (m,), int64.
    #[getter]
    fn node<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        self.with(py, |_, c| {
            let nodes: Vec<i64> = c.nodes.iter().map(|&v| v as i64).collect();
            Ok(owned(py, nodes.into()))
        })
    }

    /// The contact group of each point, (m,), int64: its index in `groups` (contact.csv's
    /// `group`; a node of two groups is a point of each).
    #[getter]
    fn group<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        self.with(py, |_, c| {
            let group: Vec<i64> = c.group_of.iter().map(|&g| g as i64).collect();
            Ok(owned(py, group.into()))
        })
    }

    /// The contact groups, in the scene's order (`[[contact]]`; one name for one `[contact]`).
    #[getter]
    fn groups(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        self.with(py, |_, c| Ok(c.groups.clone()))
    }

    /// Outward unit normals of the body, (m, dim).
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.with(py, |o, c| lend(o, columns(&c.points.normal, c.points.dim)))
    }

    /// Weights (lumped boundary measure), (m,): the contact force is `sum(weight * lambda_n)`.
    #[getter]
    fn weight<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.with(py, |o, c| lend(o, ArrayView1::from(&c.points.weight[..])))
    }

    /// Initial gaps, (m,).
    #[getter]
    fn gap<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.with(py, |o, c| lend(o, ArrayView1::from(&c.points.gap[..])))
    }

    /// Normal displacement, (m,): `u_n <= gap`.
    #[getter]
    fn u_n<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.with(py, |o, c| lend(o, ArrayView1::from(&c.displacement.normal[..])))
    }

    /// Tangential displacement, (m, dim - 1).
    #[getter]
    fn u_t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.with(py, |o, c| lend(o, table(&c.displacement.tangential, c.points.dim - 1)))
    }

    /// Normal multiplier (contact pressure), (m,), `>= 0`.
    #[getter]
    fn lambda_n<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.with(py, |o, c| lend(o, ArrayView1::from(&c.solution.lambda.normal[..])))
    }

    /// Tangential multiplier, (m, dim - 1) (zeros without friction).
    #[getter]
    fn lambda_t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.with(py, |o, c| {
            let nt = c.points.dim - 1;
            if c.solution.lambda.tangential.len() == c.points.len() * nt {
                lend(o, table(&c.solution.lambda.tangential, nt))
            } else {
                Ok(owned(py, numpy::ndarray::Array2::zeros((c.points.len(), nt))))
            }
        })
    }

    /// Electrical contact (`contact.electric` conductive or conducting): the outward flux
    /// `D·nu` through each point, (m,) (charge per unit area; NaN where an electrode
    /// prescribes the point's potential); None on an insulating foundation. The charge on the
    /// conductor across the zone is `-nansum(weight * flux)` (`report["contact"]["charge"]`).
    #[getter]
    fn flux<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        self.with(py, |_, c| {
            let Some(e) = &c.solution.electric else {
                return Ok(None);
            };
            let mut flux = vec![f64::NAN; c.points.len()];
            for (&i, q) in e.points.iter().zip(&e.flux) {
                flux[i] = *q;
            }
            Ok(Some(owned(py, flux.into())))
        })
    }

    /// Status of each point, (m,), int8: STICK (1), SLIP (2) or SEPARATED (3).
    #[getter]
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i8>>> {
        self.with(py, |_, c| {
            let status: Vec<i8> = c.solution.status.iter().map(|&s| status_code(s)).collect();
            Ok(owned(py, status.into()))
        })
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, |_, c| Ok(c.points.len()))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        self.with(py, |_, c| {
            let (stick, slip, sep) = c.solution.counts();
            Ok(format!(
                "<piezocontact.Contact: {} points, {stick} stick, {slip} slip, {sep} separated>",
                c.points.len()
            ))
        })
    }
}
