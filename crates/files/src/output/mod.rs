//! The files of a run, exactly those its plan lists (`run.json`, `solution.vtu`, a body of
//! revolution's `revolved.vtu`,
//! `contact.csv`, the pictures), written as one set ([`Outputs`], in `set`): the new set
//! appears all at once, in place of the previous one, or not at all.

mod frames;
pub mod pieces;
mod set;
mod vtu;

pub use frames::{pvd, PathFiles};
pub use set::{abandon_and_exit, check_target, Outputs, SetWriter, Staged};

use crate::plots::{self, Mark, Panel, Series};
use crate::Error;
use problem::{ContactResult, Output, RunReport, Solution};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use vtu::{Array, CellType, Grid, Values};

/// `run.json` of a report alone: the report, pretty, its keys in sorted order (without the
/// units of its CSV files' columns, which [`run_json_of`] adds from the solution).
///
/// # Errors
/// [`Error::Picture`] if serde cannot write it (it always can).
pub fn run_json(report: &RunReport) -> Result<Vec<u8>, Error> {
    json(report, None)
}

/// `run.json` of `solution`, with `units.columns`: the unit of each column of the CSV files
/// its set holds (`contact.csv`, `path.csv`), none for a count, a factor or a relative
/// residual.
///
/// # Errors
/// [`Error::Picture`] if serde cannot write it (it always can).
pub fn run_json_of(solution: &Solution) -> Result<Vec<u8>, Error> {
    let report = &solution.report;
    let mut csv: Vec<(&str, Vec<String>)> = vec![];
    if let (Some(c), true) = (&solution.contact, report.plan.outputs.contains(&Output::ContactCsv)) {
        csv.push(("contact.csv", contact_columns(c)));
    }
    if let Some(path) = &report.path {
        csv.push(("path.csv", path_columns(&path.rows, &terminal_groups(report))));
    }
    let columns: serde_json::Map<String, serde_json::Value> = csv
        .into_iter()
        .map(|(name, cols)| {
            let of: serde_json::Map<String, serde_json::Value> = cols
                .iter()
                .map(|c| (c.clone(), column_unit(name, c, &report.units).into()))
                .collect();
            (name.to_string(), of.into())
        })
        .collect();
    json(report, Some(columns))
}

/// The report as pretty JSON, its keys in sorted order, with `columns` in its `units` block
/// where given.
fn json(report: &RunReport, columns: Option<serde_json::Map<String, serde_json::Value>>) -> Result<Vec<u8>, Error> {
    let encode = |e: serde_json::Error| Error::Picture {
        name: "run.json".into(),
        message: e.to_string(),
    };
    let mut tree = serde_json::to_value(report).map_err(encode)?;
    if let (Some(columns), Some(u)) = (columns, tree.get_mut("units").and_then(|u| u.as_object_mut())) {
        u.insert("columns".into(), columns.into());
    }
    serde_json::to_vec_pretty(&tree).map_err(encode)
}

/// The terminals' groups of a report, in its order (`path.csv`'s `charge_G`, `potential_G`).
fn terminal_groups(report: &RunReport) -> Vec<&str> {
    report.terminals.iter().map(|t| t.group.as_str()).collect()
}

/// The files of a solution, those its plan lists (and, for the last instant of a load path,
/// `path.csv` and its pictures), each made on rayon's pool at the same time as the others (the
/// grid's encoding and the pictures' rendering do not depend on each other), in the plan's
/// order.
///
/// # Errors
/// [`Error::Picture`] where a file cannot be made (the first in the plan's order).
pub fn files(solution: &Solution) -> Result<Outputs, Error> {
    files_but(solution, None)
}

/// [`files`] without the plan's output `left_out` (a path's `run.json`, made once its steps'
/// files are written and timed).
fn files_but(solution: &Solution, left_out: Option<Output>) -> Result<Outputs, Error> {
    let made: Vec<Result<plots::Files, Error>> = solution
        .report
        .plan
        .outputs
        .par_iter()
        .filter(|&&output| Some(output) != left_out)
        .map(|&output| output_files(solution, output))
        .collect();
    let mut out = Outputs::new(Path::new(""));
    for files in made {
        out.extend(files?);
    }
    // a load path's rows and curves
    out.extend(path_files(solution)?);
    Ok(out)
}

/// The unit of the column `column` of the CSV file `file`, from the run's `units` ("" where it
/// has none: a count, a status, a path's time or factor, a relative residual).
pub fn column_unit(file: &str, column: &str, units: &problem::Units) -> String {
    let path = file == "path.csv";
    if column == "seconds" {
        return "s".into();
    }
    let quantity = match column {
        // a path's factors and its time are pure numbers
        "t" | "load" | "voltage" | "ux" | "uy" | "uz" | "gap" if path => "",
        "x"
        | "y"
        | "z"
        | "gap"
        | "u_n"
        | "u_t"
        | "u_t2"
        | "depth"
        | "contact_radius"
        | "max_slip"
        | "max_slip_increment"
        | "half_space_depth"
        | "half_space_contact_radius"
        | "indenter_depth"
        | "indenter_contact_radius" => "length",
        "indenter_potential" => "potential",
        "lambda_n" | "lambda_t" | "lambda_t2" => "traction",
        "flux" => "flux",
        c if c.starts_with("potential") => "potential",
        c if c.contains("force") => "force",
        c if c.contains("charge") => "charge",
        _ => "",
    };
    units.of_quantity(quantity).to_string()
}

/// The files of one output of the plan.
fn output_files(solution: &Solution, output: Output) -> Result<plots::Files, Error> {
    let missing = |what: &str| Error::Picture {
        name: what.into(),
        message: "the plan lists it, but the run has nothing to draw it from".into(),
    };
    let one = |name: &str, bytes: Vec<u8>| vec![(name.to_string(), bytes)];
    let (mesh, fields) = (&solution.mesh, (&solution.u[..], &solution.phi[..]));
    Ok(match output {
        Output::RunJson => one("run.json", run_json_of(solution)?),
        Output::SolutionVtu => one(
            "solution.vtu",
            vtu(mesh, fields, &solution.fields, solution.contact.as_ref())?,
        ),
        Output::RevolvedVtu => {
            let segments = solution.report.scene.settings.mesh.revolve;
            let segments = segments.ok_or_else(|| missing("revolved.vtu"))?;
            one("revolved.vtu", revolved_vtu(mesh, fields, &solution.fields, segments)?)
        }
        Output::ContactCsv => {
            let c = solution.contact.as_ref().ok_or_else(|| missing("contact.csv"))?;
            one("contact.csv", contact_csv(c, &solution.report.units))
        }
        Output::Multipliers => {
            let c = solution.contact.as_ref().ok_or_else(|| missing("multipliers"))?;
            multipliers_picture(
                c,
                (&solution.report.units, &solution.report.plan),
                indenter_zone(solution, c),
            )?
        }
        Output::Deformed => {
            let pic = plots::mesh_view::deformed_picture(&solution.mesh, &solution.u, &solution.report.units)?;
            pic.ok_or_else(|| missing("deformed"))?
        }
        Output::Potential => {
            let fields = (&solution.u[..], &solution.phi[..]);
            let zone = solution.contact.as_ref().and_then(|c| tip_window(solution, c));
            let electric = problem::cell_electric(&solution.report.scene.settings, &solution.mesh);
            let pic = plots::mesh_view::potential_picture(
                &solution.mesh,
                fields,
                &solution.report.units,
                (zone.as_ref(), electric.as_deref()),
            )?;
            pic.ok_or_else(|| missing("potential"))?
        }
    })
}

/// Writes the files of a solution into `dir`, as one set.
///
/// # Errors
/// As [`files`] and [`Outputs::commit`].
pub fn write(solution: &Solution, dir: &Path) -> Result<(), Error> {
    files(solution)?.into(dir).commit()
}

/// The solution as a VTK XML unstructured grid: point data `u` (3 components), `phi`; cell
/// data `stress` (Voigt), `strain`, `electric_displacement`, `electric_field`; and, with
/// contact, point data `contact_status` (0 none, 1 stick, 2 slip, 3 separated).
fn vtu(
    mesh: &mesh::Mesh,
    fields: (&[[f64; 3]], &[f64]),
    cells: &problem::CellFields,
    contact: Option<&ContactResult>,
) -> Result<Vec<u8>, Error> {
    let (points, connectivity, offsets, cell_type) = mesh_arrays(mesh);
    let data = FieldArrays::new(mesh, fields, Some(cells), contact);
    Ok(vtu::write(&Grid {
        points: &points,
        connectivity: &connectivity,
        offsets: &offsets,
        cell_type,
        point: data.point.iter().map(NamedValues::array).collect(),
        cell: data.cell.iter().map(NamedValues::array).collect(),
    }))
}

/// The mesh as VTK's arrays: coordinates (3 per point), connectivity, offsets, the cell type.
fn mesh_arrays(mesh: &mesh::Mesh) -> (Vec<f64>, Vec<u64>, Vec<u64>, CellType) {
    let points: Vec<f64> = mesh.points.iter().flatten().copied().collect();
    let k = mesh.kind.n_nodes();
    let connectivity: Vec<u64> = mesh.cells.iter().map(|&v| v as u64).collect();
    let offsets: Vec<u64> = (1..=mesh.n_cells()).map(|c| (c * k) as u64).collect();
    let cell_type = match mesh.kind {
        mesh::CellKind::Tri3 => CellType::Triangle,
        mesh::CellKind::Quad4 => CellType::Quad,
        mesh::CellKind::Tet4 => CellType::Tetra,
        mesh::CellKind::Tri6 => CellType::QuadraticTriangle,
        mesh::CellKind::Tet10 => CellType::QuadraticTetra,
    };
    (points, connectivity, offsets, cell_type)
}

/// A named array of `f64`, borrowed or owned (a path's frame owns its copies, to be written
/// on another thread).
struct NamedValues<'a> {
    name: &'static str,
    components: usize,
    values: std::borrow::Cow<'a, [f64]>,
}

impl NamedValues<'_> {
    fn array(&self) -> Array<'_> {
        Array {
            name: self.name,
            components: self.components,
            values: Values::F64(&self.values),
        }
    }

    fn into_owned(self) -> NamedValues<'static> {
        NamedValues {
            name: self.name,
            components: self.components,
            values: std::borrow::Cow::Owned(self.values.into_owned()),
        }
    }
}

/// The point and cell data of a solution's grid: `u`, `phi` and, with contact, its point data
/// (status, pressure, traction, gap, flux); with `cells`, the cell data (stress, strain, D, E)
/// and, on P2 cells, the same fields as point data (their values at the nodes).
struct FieldArrays<'a> {
    point: Vec<NamedValues<'a>>,
    cell: Vec<NamedValues<'a>>,
}

impl<'a> FieldArrays<'a> {
    fn new(
        mesh: &mesh::Mesh,
        (u, phi): (&[[f64; 3]], &'a [f64]),
        cells: Option<&'a problem::CellFields>,
        contact: Option<&ContactResult>,
    ) -> Self {
        use std::borrow::Cow;
        let named = |name, components, values| NamedValues {
            name,
            components,
            values,
        };
        let u: Vec<f64> = u.iter().flatten().copied().collect();
        let mut point = vec![named("u", 3, Cow::Owned(u)), named("phi", 1, Cow::Borrowed(phi))];
        if let Some(c) = contact {
            let mut status = vec![0.0; mesh.n_nodes()];
            for (i, &node) in c.nodes.iter().enumerate() {
                status[node] = match c.solution.status[i] {
                    contact::Status::Stick => 1.0,
                    contact::Status::Slip => 2.0,
                    contact::Status::Separated => 3.0,
                };
            }
            let data = contact_point_data(c, mesh.n_nodes());
            point.push(named("contact_status", 1, Cow::Owned(status)));
            point.push(named("contact_pressure", 1, Cow::Owned(data.pressure)));
            point.push(named("contact_traction", 3, Cow::Owned(data.traction)));
            point.push(named("contact_gap", 1, Cow::Owned(data.gap)));
            if let Some(flux) = data.flux {
                point.push(named("contact_flux", 1, Cow::Owned(flux)));
            }
        }
        // the four fields as 3D tensors and vectors, which ParaView reads as such (the six
        // components of a symmetric tensor in VTK's order, tensor shears; plane strain's
        // σ_zz and D_z; a body of revolution's hoop components along z)
        let four = |t: problem::Tensors| {
            vec![
                named("stress", 6, Cow::Owned(t.stress)),
                named("strain", 6, Cow::Owned(t.strain)),
                named("electric_displacement", 3, Cow::Owned(t.electric_displacement)),
                named("electric_field", 3, Cow::Owned(t.electric_field)),
            ]
        };
        if let Some(at) = cells.and_then(|f| f.at_nodes.as_ref()) {
            // P2 cells: the fields at the nodes too, which ParaView draws quadratic
            point.extend(four(at.tensors(mesh.dim)));
        }
        let cell = cells.map_or(vec![], |f| four(f.tensors(mesh.dim)));
        FieldArrays { point, cell }
    }

    /// The bytes of the arrays' values.
    fn bytes(&self) -> usize {
        self.point.iter().chain(&self.cell).map(|a| 8 * a.values.len()).sum()
    }

    /// The arrays, every one owned.
    fn into_owned(self) -> FieldArrays<'static> {
        FieldArrays {
            point: self.point.into_iter().map(NamedValues::into_owned).collect(),
            cell: self.cell.into_iter().map(NamedValues::into_owned).collect(),
        }
    }
}

/// The contact values as point data of the mesh's nodes (0 off the contact face, where
/// `contact_status` is 0): the pressure `λ_n`, the tangential traction `Σ_k λ_t,k t_k` in the
/// global frame (3 components), the initial gap, and with electrical contact the flux `D·ν`.
struct ContactPointData {
    pressure: Vec<f64>,
    traction: Vec<f64>,
    gap: Vec<f64>,
    flux: Option<Vec<f64>>,
}

fn contact_point_data(c: &ContactResult, n_nodes: usize) -> ContactPointData {
    let (p, s) = (&c.points, &c.solution);
    let nt = s.lambda.n_tangential();
    let mut out = ContactPointData {
        pressure: vec![0.0; n_nodes],
        traction: vec![0.0; 3 * n_nodes],
        gap: vec![0.0; n_nodes],
        flux: s.electric.as_ref().map(|_| vec![0.0; n_nodes]),
    };
    for (i, &node) in c.nodes.iter().enumerate() {
        out.pressure[node] = s.lambda.normal[i];
        out.gap[node] = p.gap[i];
        for q in 0..nt {
            for k in 0..3 {
                out.traction[3 * node + k] += s.lambda.tangential[i * nt + q] * p.tangent[i][q][k];
            }
        }
    }
    if let (Some(flux), Some(e)) = (&mut out.flux, &s.electric) {
        for (&i, q) in e.points.iter().zip(&e.flux) {
            flux[c.nodes[i]] = *q;
        }
    }
    out
}

/// A body of revolution's solution swept round its axis (y) in `segments` steps: each meridian
/// triangle `(r, z)` a ring of wedges, the point `(r, z)` at the angle θ at `(r cos θ, z, r sin θ)`
/// (points on the axis repeated at every angle). Point data `u` (Cartesian: `u_r` turned by θ),
/// `phi`; cell data `stress` and `strain` as Cartesian tensors in VTK's order,
/// `electric_displacement` and `electric_field` as Cartesian vectors, each turned by the
/// wedge's mid-angle from the meridian's (where the hoop direction is z).
fn revolved_vtu(
    mesh: &mesh::Mesh,
    (u, phi): (&[[f64; 3]], &[f64]),
    fields: &problem::CellFields,
    segments: usize,
) -> Result<Vec<u8>, Error> {
    let (n, cells) = (mesh.n_nodes(), mesh.n_cells());
    let angle = |k: usize| 2.0 * std::f64::consts::PI * (k % segments) as f64 / segments as f64;
    let (mut points, mut uu, mut pp) = (vec![], vec![], vec![]);
    for k in 0..segments {
        let (c, s) = (angle(k).cos(), angle(k).sin());
        for v in 0..n {
            let [r, z, _] = mesh.points[v];
            points.extend([r * c, z, r * s]);
            uu.extend([u[v][0] * c, u[v][1], u[v][0] * s]);
            pp.push(phi[v]);
        }
    }
    let (mut connectivity, mut offsets) = (vec![], vec![]);
    // the meridian's tensors (x = r, y = z, the hoop direction along z), turned with each wedge
    let meridian = fields.tensors(2);
    let (mut stress, mut strain, mut d, mut e) = (vec![], vec![], vec![], vec![]);
    for k in 0..segments {
        let (lo, hi) = ((k * n) as u64, (((k + 1) % segments) * n) as u64);
        let mid = 0.5 * (angle(k) + angle(k) + 2.0 * std::f64::consts::PI / segments as f64);
        let (c, s) = (mid.cos(), mid.sin());
        for cell in 0..cells {
            // a six-node triangle as its four triangles of corners and edge nodes
            let t = mesh.cell(cell);
            for part in mesh.kind.linear_triangles() {
                // VTK's wedge: the base (0, 1, 2) turns about its outward normal, away from
                // the top (3, 4, 5); a counterclockwise meridian triangle faces the growing
                // angle, so the base is the later angle's
                connectivity.extend(part.iter().map(|&q| hi + t[q] as u64));
                connectivity.extend(part.iter().map(|&q| lo + t[q] as u64));
                offsets.push(connectivity.len() as u64);
                for (out, of) in [(&mut stress, &meridian.stress), (&mut strain, &meridian.strain)] {
                    out.extend(turned_about_y(&of[6 * cell..6 * cell + 6], c, s));
                }
                for (out, of) in [
                    (&mut d, &meridian.electric_displacement),
                    (&mut e, &meridian.electric_field),
                ] {
                    let (vr, vz) = (of[3 * cell], of[3 * cell + 1]);
                    out.extend([vr * c, vz, vr * s]);
                }
            }
        }
    }
    let array = |name, components, values| Array {
        name,
        components,
        values: Values::F64(values),
    };
    Ok(vtu::write(&Grid {
        points: &points,
        connectivity: &connectivity,
        offsets: &offsets,
        cell_type: CellType::Wedge,
        point: vec![array("u", 3, &uu), array("phi", 1, &pp)],
        cell: vec![
            array("stress", 6, &stress),
            array("strain", 6, &strain),
            array("electric_displacement", 3, &d),
            array("electric_field", 3, &e),
        ],
    }))
}

/// A symmetric tensor in VTK's order (`xx, yy, zz, xy, yz, xz`) turned about the y axis by
/// the angle of cosine `c` and sine `s` that takes x to `(c, 0, s)`: `Q T Qᵀ`, the columns of
/// `Q` the turned axes `(c, 0, s)`, `(0, 1, 0)`, `(-s, 0, c)`.
fn turned_about_y(t: &[f64], c: f64, s: f64) -> [f64; 6] {
    let m = [[t[0], t[3], t[5]], [t[3], t[1], t[4]], [t[5], t[4], t[2]]];
    let q = [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]];
    let at = |i: usize, j: usize| {
        (0..3)
            .flat_map(|k| (0..3).map(move |l| (k, l)))
            .map(|(k, l)| q[i][k] * m[k][l] * q[j][l])
            .sum::<f64>()
    };
    [at(0, 0), at(1, 1), at(2, 2), at(0, 1), at(1, 2), at(0, 2)]
}

/// A CSV field as RFC 4180 writes it: quoted (its quotes doubled) where it holds a comma, a
/// quote or a line break, as it is elsewhere. Every name that becomes a column or a cell (a
/// Gmsh group's physical name, a terminal) goes through it, so no name can shift a column.
pub fn csv_field(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\"")).into()
    } else {
        text.into()
    }
}

/// A number of a CSV output: the shortest digits that read back to the same double (`{:e}`),
/// and 0 for a zero of either sign (round-off's -0 reads as 0).
fn num(x: f64) -> String {
    format!("{:e}", x + 0.0)
}

/// `contact.csv`'s columns: `x,y[,z],gap,u_n,u_t[,u_t2],lambda_n,lambda_t[,lambda_t2],status`,
/// with electrical contact `flux,potential`, with several contact groups `group`.
fn contact_columns(c: &ContactResult) -> Vec<String> {
    let mut out: Vec<&str> = if c.points.dim == 2 {
        vec!["x", "y", "gap", "u_n", "u_t", "lambda_n", "lambda_t", "status"]
    } else {
        vec![
            "x",
            "y",
            "z",
            "gap",
            "u_n",
            "u_t",
            "u_t2",
            "lambda_n",
            "lambda_t",
            "lambda_t2",
            "status",
        ]
    };
    if c.solution.electric.is_some() {
        out.extend(["flux", "potential"]);
    }
    if c.groups.len() > 1 {
        out.push("group");
    }
    out.into_iter().map(String::from).collect()
}

/// The CSV header line of `file`'s `columns`: each column's name and, where it has one, its
/// unit in brackets ([`column_unit`]: `normal_force [mN]`, `t`), quoted where it needs it.
fn header(file: &str, columns: &[String], units: &problem::Units) -> String {
    let named = |c: &String| header_cell(c, &column_unit(file, c, units));
    let mut s = columns.iter().map(named).collect::<Vec<_>>().join(",");
    s.push('\n');
    s
}

/// A CSV header's cell of column `name` in `unit`: `name [unit]`, or `name` alone without a
/// unit, quoted where it needs it ([`column_name`] reads the name back).
pub fn header_cell(name: &str, unit: &str) -> String {
    match unit {
        "" => csv_field(name).into_owned(),
        unit => csv_field(&format!("{name} [{unit}]")).into_owned(),
    }
}

/// A CSV header's column `cell` without its unit (`normal_force [mN]` is `normal_force`): the
/// name run.json's `units.columns` gives its unit under.
pub fn column_name(cell: &str) -> &str {
    match cell.strip_suffix(']').and_then(|c| c.rsplit_once(" [")) {
        Some((name, _)) => name,
        None => cell,
    }
}

/// One row per contact point, under a [`header`] with the columns' units:
/// `x,y[,z],gap,u_n,u_t[,u_t2],lambda_n,lambda_t[,lambda_t2],status`
/// and, with electrical contact, `flux,potential` (`nan` where an electrode holds the point),
/// with several contact groups `group`;
/// the displacements are those of the final solution (a frictionless body slides: its `u_t`
/// is written too), the tangential multipliers 0 where the law carries none.
fn contact_csv(c: &ContactResult, units: &problem::Units) -> Vec<u8> {
    let (points, sol, u) = (&c.points, &c.solution, &c.displacement);
    let dim = points.dim;
    let nt = sol.lambda.n_tangential();
    let mut s = header("contact.csv", &contact_columns(c), units);
    // electrical contact: the flux D.n and the potential of each point (nan on an electrode)
    let electric = sol.electric.as_ref().map(|e| {
        let mut at = vec![(f64::NAN, f64::NAN); points.len()];
        for (k, &i) in e.points.iter().enumerate() {
            at[i] = (e.flux[k], e.potential[k]);
        }
        at
    });
    let several = c.groups.len() > 1;
    for i in 0..points.len() {
        let mut row: Vec<String> = points.position[i][..dim].iter().map(|x| num(*x)).collect();
        row.push(num(points.gap[i]));
        row.push(num(u.normal[i]));
        for &ut in u.tangential_of(i) {
            row.push(num(ut));
        }
        row.push(num(sol.lambda.normal[i]));
        for q in 0..dim - 1 {
            row.push(num(if nt > 0 { sol.lambda.tangential[i * nt + q] } else { 0.0 }));
        }
        row.push(sol.status[i].name().to_string());
        if let Some(at) = &electric {
            row.push(num(at[i].0));
            row.push(num(at[i].1));
        }
        if several {
            row.push(csv_field(&c.groups[c.group_of[i]]).into_owned());
        }
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s.into_bytes()
}

/// Under an indenter that touches: each contact point's distance from its axis (NaN off its
/// zone) and the contact radius; `None` without an indenter or contact.
fn indenter_zone(solution: &Solution, c: &ContactResult) -> Option<(Vec<f64>, f64)> {
    let a = solution.report.indenter.as_ref()?.contact_radius;
    if !(a > 0.0) {
        return None;
    }
    let (k, spec) = solution.report.scene.settings.indenter_contact()?;
    let indenter = spec.indenter.as_ref()?;
    let p = &c.points;
    let rho = (0..p.len())
        .map(|i| match c.group_of.get(i) {
            Some(&g) if g == k => indenter.local(&p.position[i], &p.normal[i]).1,
            _ => f64::NAN,
        })
        .collect();
    Some((rho, a))
}

/// A 2D body's part near an indenter that touches: the contact face's points within three
/// contact radii of its axis give the x range (both sides of a plane tip's axis, from the
/// axis of a body of revolution) and the face's y, the body on the side its outward normal
/// does not point to, the x range over 1.7 deep (the width over the height of the picture's
/// close view, whose axes keep the body's proportions).
fn tip_window(solution: &Solution, c: &ContactResult) -> Option<plots::mesh_view::Window> {
    if solution.mesh.dim != 2 {
        return None;
    }
    let (rho, a) = indenter_zone(solution, c)?;
    let near: Vec<usize> = (0..rho.len()).filter(|&i| rho[i] <= 3.0 * a).collect();
    let p = &c.points;
    let xs = near.iter().map(|&i| p.position[i][0]);
    let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
    if !(x1 > x0) {
        return None;
    }
    let m = near.len() as f64;
    let surface = near.iter().map(|&i| p.position[i][1]).sum::<f64>() / m;
    let outward = near.iter().map(|&i| p.normal[i][1]).sum::<f64>() / m;
    let depth = (x1 - x0) / 1.7;
    let y = match outward < 0.0 {
        true => surface..surface + depth,
        false => surface - depth..surface,
    };
    // the face's own nodes on the window's edge are within it
    let pad = 1e-9 * (x1 - x0);
    Some(plots::mesh_view::Window {
        x: x0 - pad..x1 + pad,
        y: y.start - pad..y.end + pad,
        what: "near the tip (r/a ≤ 3)".into(),
    })
}

/// The multipliers along the contact boundary (in 3D, along the contact face's middle line
/// y = y_mid), like the paper's figures: `λ_n`, `λ_t` (in 3D its magnitude), the slip bound
/// (Coulomb's `F λ_n`, Tresca's `S`; in 2D on both sides), and the sliding points. Under an
/// indenter that touches (`zone`: each point's distance from its axis, NaN off its zone, and
/// the contact radius `a`), the zone seen close:
/// against `r/a` from 0 to 3, every point of the zone within (in 3D each as a dot).
fn multipliers_picture(
    c: &ContactResult,
    (units, plan): (&problem::Units, &problem::Plan),
    zone: Option<(Vec<f64>, f64)>,
) -> Result<plots::Files, Error> {
    let (p, s) = (&c.points, &c.solution);
    let nt = s.lambda.n_tangential();
    let mut idx: Vec<usize> = (0..p.len()).collect();
    let x: Vec<f64> = match &zone {
        Some((rho, a)) => {
            idx.retain(|&i| rho[i] <= 3.0 * a);
            rho.iter().map(|r| r / a).collect()
        }
        None => {
            if p.dim == 3 {
                let ys: Vec<f64> = p.position.iter().map(|x| x[1]).collect();
                let (ymin, ymax) = ys
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| (a.min(y), b.max(y)));
                let mid = 0.5 * (ymin + ymax);
                let best = ys.iter().map(|y| (y - mid).abs()).fold(f64::INFINITY, f64::min);
                idx.retain(|&i| ((ys[i] - mid).abs() - best).abs() < 1e-12);
            }
            p.position.iter().map(|x| x[0]).collect()
        }
    };
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let along = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&i| (x[i], f(i))).collect::<Vec<_>>();
    // in 3D the zone's points lie at every angle: dots, not a line
    let dots = zone.is_some() && p.dim == 3;
    let curve = |name: &str, points| {
        let mut series = Series::line(name, points);
        if dots {
            series.mark = Mark::Dots;
        }
        series
    };
    let mut series = vec![curve("lambda_n (pressure)", along(&|i| s.lambda.normal[i]))];
    if nt > 0 {
        series.extend(friction_series(c, plan, (&idx, &x), &curve));
    }
    let (title, x_label) = match &zone {
        Some((_, a)) => (
            format!(
                "Multipliers under the indenter (a = {a:.4e}{})",
                match units.of_quantity("length") {
                    "" => String::new(),
                    unit => format!(" {unit}"),
                }
            ),
            "r/a".to_string(),
        ),
        None if p.dim == 3 => (
            "Multipliers on the contact face's middle line".into(),
            units.label("x", "length"),
        ),
        None => (
            "Multipliers along the contact boundary".into(),
            units.label("x", "length"),
        ),
    };
    let mut panels = vec![Panel {
        title,
        labels: (x_label.clone(), units.label("multiplier", "traction")),
        series,
    }];
    if let Some(e) = &s.electric {
        // the flux through the points (those with a free potential), along the same line
        let flux: Vec<(f64, f64)> = idx
            .iter()
            .filter_map(|&i| e.points.iter().position(|&j| j == i).map(|k| (x[i], e.flux[k])))
            .collect();
        panels.push(Panel {
            title: "Electric flux D.n through the contact boundary".into(),
            labels: (x_label, units.label("flux", "flux")),
            series: vec![curve("D.n (leaving the body)", flux)],
        });
    }
    plots::panels("multipliers", &panels)
}

/// A series of `(x, y)` points under a name, drawn as the picture draws its curves.
type Curve<'a> = dyn Fn(&str, Vec<(f64, f64)>) -> Series + 'a;

/// The multipliers' picture's friction series: `λ_t` (in 2D along the tangent, in 3D its
/// magnitude), the sliding points, and the slip bound it meets where it slides (Coulomb's
/// `F λ_n`, Tresca's `S`; in 2D on both sides) of the points `idx` at `x`.
fn friction_series(
    c: &ContactResult,
    plan: &problem::Plan,
    (idx, x): (&[usize], &[f64]),
    curve: &Curve<'_>,
) -> Vec<Series> {
    let (p, s) = (&c.points, &c.solution);
    let nt = s.lambda.n_tangential();
    let along = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&i| (x[i], f(i))).collect::<Vec<_>>();
    let mut series = vec![];
    // the slip bound each point's |λ_t| meets where it slides: Coulomb's F λ_n, Tresca's S
    let law = plan.law(p, &c.group_of);
    let bound = contact::slip_bound(p, &law, &s.lambda.normal);
    let bound_name = match law {
        contact::Law::Tresca(_) => "S (Tresca bound)",
        _ => "F lambda_n (Coulomb bound)",
    };
    // in 2D λ_t along the tangent, between -bound and +bound; in 3D its magnitude (its
    // components lie along the frame of run.json's contact.frame, in contact.csv)
    let (name, t): (&str, Box<dyn Fn(usize) -> f64>) = if nt > 1 {
        ("|lambda_t|", Box::new(|i| s.lambda.tangential_norm(i)))
    } else {
        ("lambda_t", Box::new(|i| s.lambda.tangential[i]))
    };
    series.push(curve(name, along(&|i| t(i))));
    series.push(Series {
        name: "slipping point".into(),
        points: idx
            .iter()
            .filter(|&&i| s.status[i] == contact::Status::Slip)
            .map(|&i| (x[i], t(i)))
            .collect(),
        mark: Mark::Dots,
    });
    series.push(Series {
        name: if nt > 1 {
            bound_name.into()
        } else {
            format!("±{bound_name}")
        },
        points: along(&|i| bound[i]),
        mark: Mark::Reference,
    });
    if nt == 1 {
        series.push(Series {
            name: String::new(),
            points: along(&|i| -bound[i]),
            mark: Mark::Reference,
        });
    }
    series
}

/// A path's own files without its series: `path.csv` and the pictures of its global curves
/// (none for a run of one instant).
pub(super) fn path_files(solution: &Solution) -> Result<plots::Files, Error> {
    let Some(path) = &solution.report.path else {
        return Ok(vec![]);
    };
    let terminals = terminal_groups(&solution.report);
    let units = &solution.report.units;
    let mut out = vec![("path.csv".to_string(), path_csv(&path.rows, &terminals, units))];
    let scene = &solution.report.scene.settings;
    out.extend(path_picture(&path.rows, &terminals, (scene, &solution.report.units))?);
    Ok(out)
}

/// `path.csv`'s columns (see [`path_csv`]), those a scene cannot fill left out.
fn path_columns(rows: &[problem::report::StepRow], terminals: &[&str]) -> Vec<String> {
    let columns = every_path_column(rows, terminals);
    let keep = filled_columns(&columns, rows);
    kept(&columns, &keep)
}

/// Which of `columns` (every column, [`every_path_column`]) the `rows` fill, as Python's path
/// dict has them: an indenter's where a row has one, the z factor in 3D alone.
fn filled_columns(columns: &[String], rows: &[problem::report::StepRow]) -> Vec<bool> {
    let dim = rows.first().map_or(0, |r| r.tangential_resultant.len());
    let any = |f: &dyn Fn(&problem::report::StepRow) -> bool| rows.iter().any(f);
    let half_space =
        |f: &dyn Fn(&problem::report::HalfSpaceRow) -> bool| any(&|r| r.half_space.as_ref().is_some_and(f));
    (columns.iter())
        .map(|c| match c.as_str() {
            "uz" => dim == 3,
            "depth" => any(&|r| r.depth.is_some()),
            "contact_radius" => any(&|r| r.contact_radius.is_some()),
            "tip_charge" => any(&|r| r.tip_charge.is_some()),
            "half_space_charge" => half_space(&|h| h.charge.is_some()),
            c if c.starts_with("half_space_") => half_space(&|_| true),
            _ => true,
        })
        .collect()
}

/// The entries of `cells` that `keep` keeps.
fn kept(cells: &[String], keep: &[bool]) -> Vec<String> {
    (cells.iter().zip(keep))
        .filter(|(_, &k)| k)
        .map(|(c, _)| c.clone())
        .collect()
}

/// Every column `path.csv` can have.
fn every_path_column(rows: &[problem::report::StepRow], terminals: &[&str]) -> Vec<String> {
    let mut out: Vec<String> = "step,t,load,voltage,ux,uy,uz,gap,normal_force,tangential_force,max_slip,max_slip_increment,n_stick,n_slip,n_separated,iterations,complementarity,equilibrium,depth,contact_radius,tip_charge,half_space_depth,half_space_force,half_space_contact_radius,half_space_charge"
        .split(',')
        .map(String::from)
        .collect();
    let dim = rows.first().map_or(0, |r| r.tangential_resultant.len());
    let axes = ["x", "y", "z"];
    out.extend(axes.iter().take(dim).map(|axis| format!("tangential_force_{axis}")));
    // several contact groups: each one's normal force and tangential force (magnitude, then
    // components), named after the group
    let groups: Vec<&str> = rows
        .first()
        .map_or(vec![], |r| r.groups.iter().map(|g| g.group.as_str()).collect());
    for g in &groups {
        out.extend([format!("normal_force_{g}"), format!("tangential_force_{g}")]);
        out.extend(axes.iter().take(dim).map(|axis| format!("tangential_force_{axis}_{g}")));
    }
    out.extend(terminals.iter().map(|t| format!("charge_{t}")));
    out.extend(terminals.iter().map(|t| format!("potential_{t}")));
    out
}

/// `path.csv`, under a [`header`] with the columns' units: one row per instant (an
/// indenter's depth, contact radius and a conducting tip's charge, with the half-space's
/// closed form beside them where it applies:
/// `half_space_depth`, `_force`, `_contact_radius`, `_charge`), with the tangential force's
/// magnitude (`tangential_force`)
/// and its components in the global frame (`tangential_force_x`, `_y`, `_z` in 3D), with
/// several contact groups each one's forces (`normal_force_G`, `tangential_force_G`,
/// `tangential_force_x_G`, ...), the charge
/// on each terminal (`charge_GROUP`, the charge on the conductor) and its potential
/// (`potential_GROUP`).
fn path_csv(rows: &[problem::report::StepRow], terminals: &[&str], units: &problem::Units) -> Vec<u8> {
    let columns = every_path_column(rows, terminals);
    let keep = filled_columns(&columns, rows);
    let mut s = header("path.csv", &kept(&columns, &keep), units);
    for row in path_cells(rows) {
        s.push_str(&kept(&row, &keep).join(","));
        s.push('\n');
    }
    s.into_bytes()
}

/// The cells of `path.csv`'s rows, every column of [`every_path_column`] (empty where a row has
/// no value).
fn path_cells(rows: &[problem::report::StepRow]) -> Vec<Vec<String>> {
    let dim = rows.first().map_or(0, |r| r.tangential_resultant.len());
    let n_groups = rows.first().map_or(0, |r| r.groups.len());
    let mut table = Vec::with_capacity(rows.len());
    for r in rows {
        let mut row = vec![r.step.to_string(), num(r.t)];
        row.extend(r.factors.iter().map(|f| num(*f)));
        row.extend(
            [r.normal_force, r.tangential_force, r.max_slip, r.max_slip_increment]
                .iter()
                .map(|v| num(*v)),
        );
        row.extend(
            [r.n_stick, r.n_slip, r.n_separated, r.iterations]
                .iter()
                .map(|v| v.to_string()),
        );
        row.push(num(r.complementarity));
        row.push(r.equilibrium.map_or(String::new(), num));
        row.push(r.depth.map_or(String::new(), num));
        row.push(r.contact_radius.map_or(String::new(), num));
        row.push(r.tip_charge.map_or(String::new(), num));
        let h = r.half_space.as_ref();
        row.push(h.map_or(String::new(), |h| num(h.depth)));
        row.push(h.map_or(String::new(), |h| num(h.force)));
        row.push(h.map_or(String::new(), |h| num(h.contact_radius)));
        row.push(h.and_then(|h| h.charge).map_or(String::new(), num));
        row.extend((0..dim).map(|k| num(r.tangential_resultant.get(k).copied().unwrap_or(f64::NAN))));
        for k in 0..n_groups {
            let g = r.groups.get(k);
            row.push(num(g.map_or(f64::NAN, |g| g.normal_force)));
            row.push(num(g.map_or(f64::NAN, |g| g.tangential_force)));
            let at = |q: usize| {
                g.and_then(|g| g.tangential_resultant.get(q))
                    .copied()
                    .unwrap_or(f64::NAN)
            };
            row.extend((0..dim).map(|q| num(at(q))));
        }
        row.extend(r.charges.iter().map(|q| num(*q)));
        row.extend(r.potentials.iter().map(|v| num(*v)));
        table.push(row);
    }
    table
}

/// The path's global curves: the contact forces against time; the forces against the factor
/// that drives the path (the one that varies most: a load, a voltage, a displacement), whose
/// loop is friction's hysteresis; an indenter's force against its depth; and the charges
/// through the terminals and their potentials against time.
fn path_picture(
    rows: &[problem::report::StepRow],
    terminals: &[&str],
    (scene, units): (&problem::Scene, &problem::Units),
) -> Result<plots::Files, Error> {
    let over = |f: &dyn Fn(&problem::report::StepRow) -> (f64, f64)| rows.iter().map(f).collect::<Vec<_>>();
    const FACTORS: [&str; 6] = ["load", "voltage", "ux", "uy", "uz", "gap"];
    let range = |k: usize| {
        let (lo, hi) = rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
            (lo.min(r.factors[k]), hi.max(r.factors[k]))
        });
        hi - lo
    };
    let driver = (0..FACTORS.len())
        .max_by(|&a, &b| range(a).total_cmp(&range(b)))
        .unwrap_or(0);
    // the loop's force: the component along a driving displacement (ux, uy, uz), else the
    // magnitude
    let along = |r: &problem::report::StepRow| match driver {
        2..=4 => r.tangential_resultant.get(driver - 2).copied().unwrap_or(f64::NAN),
        _ => r.tangential_force,
    };
    let loop_label = match driver {
        2..=4 => format!("tangential force along {}", &FACTORS[driver][1..]),
        _ => "tangential force (magnitude)".to_string(),
    };
    // (a frictionless path has no tangential force: no line of zeros for it, no loop)
    let friction = rows.iter().any(|r| r.tangential_force != 0.0);
    let mut forces = vec![Series::line("normal force", over(&|r| (r.t, r.normal_force)))];
    if friction {
        forces.push(Series::line("tangential force", over(&|r| (r.t, r.tangential_force))));
    }
    let mut panels = vec![Panel {
        title: "Contact forces along the path".into(),
        labels: ("t".into(), units.label("force", "force")),
        series: forces,
    }];
    // friction's loop where there is friction, against the quantity the driving factor scales
    // where the scene prescribes one
    if friction {
        let (scale, x_label, what) = match driven(scene, driver) {
            Some((value, quantity, name)) => (value, units.label(&name, quantity), name),
            None => {
                let factor = format!("{} factor", FACTORS[driver]);
                (1.0, factor.clone(), factor)
            }
        };
        panels.push(Panel {
            title: format!("Tangential force against the {what} (friction's loop)"),
            labels: (x_label, units.label(&loop_label, "force")),
            series: vec![Series::line(
                &loop_label,
                over(&|r| (scale * r.factors[driver], along(r))),
            )],
        });
    }
    panels.extend(indenter_panels(rows, units));
    if !terminals.is_empty() {
        panels.push(Panel {
            title: "Charge on each terminal".into(),
            labels: ("t".into(), units.label("charge", "charge")),
            series: terminals
                .iter()
                .enumerate()
                .map(|(g, name)| Series::line(name, over(&|r| (r.t, r.charges.get(g).copied().unwrap_or(f64::NAN)))))
                .collect(),
        });
        // the potentials where one moves (a floating terminal's, or a voltage along the path)
        let moves = (0..terminals.len()).any(|g| {
            let of = |r: &problem::report::StepRow| r.potentials.get(g).copied().unwrap_or(f64::NAN);
            rows.iter().any(|r| of(r) != of(&rows[0]))
        });
        if moves {
            panels.push(Panel {
                title: "Potential of each terminal".into(),
                labels: ("t".into(), units.label("potential", "potential")),
                series: terminals
                    .iter()
                    .enumerate()
                    .map(|(g, name)| {
                        Series::line(name, over(&|r| (r.t, r.potentials.get(g).copied().unwrap_or(f64::NAN))))
                    })
                    .collect(),
            });
        }
    }
    plots::panels_apart("path", &panels)
}

/// The value a path's driving factor (`driver`: load, voltage, ux, uy, uz, gap) multiplies,
/// its quantity and its name: the largest in magnitude of the scene's pressures, prescribed
/// potentials or prescribed displacement components; `None` for the gap and where the scene
/// prescribes none (the loop is then drawn against the factor).
fn driven(scene: &problem::Scene, driver: usize) -> Option<(f64, &'static str, String)> {
    let largest = |values: Vec<f64>| {
        values
            .into_iter()
            .filter(|v| v.is_finite() && *v != 0.0)
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
    };
    match driver {
        0 => largest(scene.loads().iter().map(|l| l.p).collect()).map(|p| (p, "pressure", "load p".into())),
        1 => {
            let mut v: Vec<f64> = scene.electrodes().iter().filter_map(|e| e.v).collect();
            v.extend(scene.dirichlet.iter().filter_map(|d| d.phi));
            largest(v).map(|v| (v, "potential", "prescribed potential".into()))
        }
        2..=4 => {
            let k = driver - 2;
            let component = |d: &problem::DirichletSpec| {
                [d.ux, d.uy, d.uz][k].or_else(|| d.u.as_ref().and_then(|u| u.get(k).copied()))
            };
            let axis = ["x", "y", "z"][k];
            largest(scene.dirichlet.iter().filter_map(component).collect())
                .map(|u| (u, "length", format!("prescribed u_{axis}")))
        }
        _ => None,
    }
}

/// An indenter's panels of a path: its force against its depth, and a conducting tip's charge,
/// each with the half-space's closed form beside it where it applies (none without an
/// indenter).
fn indenter_panels(rows: &[problem::report::StepRow], units: &problem::Units) -> Vec<Panel> {
    type Row = problem::report::StepRow;
    let mut panels = vec![];
    if !rows.iter().any(|r| r.depth.is_some()) {
        return panels;
    }
    panels.push(against_depth(
        rows,
        (
            "Indenter force against depth",
            &units.label("force", "force"),
            "normal force",
        ),
        units,
        &|r: &Row| Some(r.normal_force),
        &|r: &Row| r.half_space.as_ref().map(|h| h.force),
    ));
    if rows.iter().any(|r| r.tip_charge.is_some()) {
        panels.push(against_depth(
            rows,
            (
                "Tip's charge against depth",
                &units.label("charge", "charge"),
                "tip's charge",
            ),
            units,
            &|r: &Row| r.tip_charge,
            &|r: &Row| r.half_space.as_ref().and_then(|h| h.charge),
        ));
    }
    panels
}

/// A panel of `value` against the indenter's depth over the path's `rows`, with the half-space's
/// closed form `form` beside it where any row has one (`(title, axis label, series name)`).
fn against_depth(
    rows: &[problem::report::StepRow],
    (title, label, name): (&str, &str, &str),
    units: &problem::Units,
    value: &dyn Fn(&problem::report::StepRow) -> Option<f64>,
    form: &dyn Fn(&problem::report::StepRow) -> Option<f64>,
) -> Panel {
    let over = |f: &dyn Fn(&problem::report::StepRow) -> Option<f64>| {
        rows.iter()
            .map(|r| (r.depth.unwrap_or(f64::NAN), f(r).unwrap_or(f64::NAN)))
            .collect::<Vec<_>>()
    };
    let mut series = vec![Series::line(name, over(value))];
    if rows.iter().any(|r| form(r).is_some()) {
        series.push(Series::reference("half-space (closed form)", over(form)));
    }
    Panel {
        title: title.into(),
        labels: (units.label("depth", "length"), label.into()),
        series,
    }
}

/// Where a run writes by default: `out/<scene>/`, the scene's name made a safe single path
/// component (letters, digits, `-`, `_` and `.` kept, anything else `_`, no leading dot), so that
/// a name like `../x` or `/tmp/x` cannot write outside `out/`.
pub fn default_dir(scene_name: &str) -> PathBuf {
    Path::new("out").join(safe_file_name(scene_name, "scene"))
}

/// `name` made a safe single path component: letters, digits, `-`, `_` and `.` kept, anything
/// else `_`, no leading dot; `fallback` where nothing is left.
pub fn safe_file_name(name: &str, fallback: &str) -> String {
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let safe = safe.trim_start_matches('.');
    if safe.is_empty() { fallback } else { safe }.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use vtkio::model::{DataSet, VertexNumbers, Vtk};

    /// RFC 4180: a field with a comma, a quote or a line break is quoted, its quotes doubled;
    /// read back by splitting on the commas outside quotes, every field is what was written.
    #[test]
    fn a_name_with_commas_or_quotes_stays_one_csv_field() {
        let names = ["plain", "a,b", "say \"x\"", "two\nlines", "", "-_+."];
        let line: Vec<String> = names.iter().map(|n| csv_field(n).into_owned()).collect();
        let line = line.join(",");
        let (mut fields, mut field, mut quoted, mut chars) = (vec![], String::new(), false, line.chars().peekable());
        while let Some(c) = chars.next() {
            match (c, quoted) {
                ('"', true) if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                ('"', _) => quoted = !quoted,
                (',', false) => fields.push(std::mem::take(&mut field)),
                (c, _) => field.push(c),
            }
        }
        fields.push(field);
        assert_eq!(fields, names);
        assert_eq!(csv_field("plain"), "plain");
    }

    /// A CSV header names each column with its unit in brackets where it has one, the unit
    /// run.json's `units.columns` gives it (a file's own reading: path.csv's `gap` is a factor,
    /// contact.csv's a length), and [`column_name`] gives back the name run.json keys it by,
    /// also for a group's name that holds brackets or commas.
    #[test]
    fn csv_headers_carry_the_columns_units() {
        let mut quantities = std::collections::BTreeMap::new();
        for (q, u) in [("length", "µm"), ("force", "mN"), ("traction", "GPa"), ("charge", "pC")] {
            quantities.insert(q.to_string(), u.to_string());
        }
        let units = problem::Units {
            quantities,
            ..problem::Units::default()
        };
        let columns: Vec<String> = [
            "t",
            "gap",
            "normal_force",
            "n_stick",
            "charge_a [b], c",
            "lambda_n",
            "seconds",
        ]
        .map(String::from)
        .to_vec();
        let path = header("path.csv", &columns, &units);
        assert_eq!(
            path,
            "t,gap,normal_force [mN],n_stick,\"charge_a [b], c [pC]\",lambda_n [GPa],seconds [s]\n"
        );
        assert!(header("contact.csv", &columns, &units).starts_with("t,gap [µm],"));
        for (cell, name) in [
            ("normal_force [mN]", "normal_force"),
            ("n_stick", "n_stick"),
            ("charge_a [b], c [pC]", "charge_a [b], c"),
            ("odd [", "odd ["),
        ] {
            assert_eq!(column_name(cell), name);
        }
    }

    /// The cell arrays a viewer reads: a symmetric tensor of six components in VTK's order
    /// (ParaView's XX, YY, ZZ, XY, YZ, XZ) with tensor shears, a vector of three. A 3D affine
    /// patch of the PZT block poled along y, sheared by `∂u_x/∂y` alone, is a pure xy shear:
    /// `ε_xy = γ/2` and `σ_xy = c44 γ` (docs/scenes.md's c44 = 21.1 GPa; the poling axis
    /// lies in the plane), in slot 3 of every cell and nowhere else. In plane strain the
    /// stress across the plane, which the Voigt rows `[xx, yy, xy]` leave out, is in slot 2.
    #[test]
    fn tensors_are_written_in_vtks_order_with_tensor_shears() {
        let cell_array = |overrides: &[&str]| {
            let set: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
            let (scene, _) = crate::scene_file::load("patch", &set).unwrap();
            let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
            let bytes = vtu(&s.mesh, (&s.u, &s.phi), &s.fields, None).unwrap();
            let vtk = Vtk::parse_xml(&bytes[..]).unwrap();
            let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
                panic!("not a grid")
            };
            let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
                panic!("not inline")
            };
            let cell = piece.data.cell.clone();
            move |name: &str| -> (usize, Vec<f64>) {
                cell.iter()
                    .find_map(|a| match a {
                        vtkio::model::Attribute::DataArray(d) if d.name == name => {
                            Some((d.elem.num_comp() as usize, d.data.clone().cast_into().unwrap()))
                        }
                        _ => None,
                    })
                    .unwrap_or_else(|| panic!("no cell array {name}"))
            }
        };
        let gamma = 1e-3;
        let array = cell_array(&[
            "mesh.kind=\"box\"",
            "mesh.lo=[0, 0, 0]",
            "mesh.hi=[2, 1, 1]",
            "mesh.n=2",
            "exact.u0=[0, 0, 0]",
            "exact.grad_u=[0, 1e-3, 0, 0, 0, 0, 0, 0, 0]",
            "exact.grad_phi=[0, 0, 0]",
        ]);
        let ((ns, stress), (ne, strain), (nd, d)) = (array("stress"), array("strain"), array("electric_field"));
        assert_eq!((ns, ne, nd), (6, 6, 3));
        for (t, e) in stress.chunks(6).zip(strain.chunks(6)) {
            for k in 0..6 {
                let (want_s, want_e) = if k == 3 {
                    (21.1 * gamma, gamma / 2.0)
                } else {
                    (0.0, 0.0)
                };
                assert!(
                    (t[k] - want_s).abs() < 1e-12 && (e[k] - want_e).abs() < 1e-15,
                    "{t:?} {e:?}"
                );
            }
        }
        assert!(d.iter().all(|x| x.abs() < 1e-14));
        // plane strain: ε_xx and ε_yy of the PZT block poled along y carry σ_zz = c12 ε_xx +
        // c13 ε_yy (z is a crystal 1-axis beside x, y the 3-axis) and E = -∇φ's σ_zz = e31 ∂_y φ
        let array = cell_array(&["exact.grad_u=[1e-3, 0, 0, -2e-3]", "exact.grad_phi=[0, 0.05]"]);
        let ((ns, stress), (nd, field)) = (array("stress"), array("electric_field"));
        assert_eq!((ns, nd), (6, 3));
        let zz = 75.4 * 1e-3 + 75.2 * -2e-3 + -5.4 * 0.05;
        for (t, e) in stress.chunks(6).zip(field.chunks(3)) {
            assert!((t[2] - zz).abs() < 1e-12 && t[4] == 0.0 && t[5] == 0.0, "{t:?}");
            assert!((e[1] + 0.05).abs() < 1e-12 && e[2] == 0.0, "{e:?}");
        }
    }

    /// The contact values in every ParaView file (the solution's and a path's steps): the
    /// pressure and the tangential traction of each contact node read back as the solution's
    /// multipliers (the traction along the paper's tangent x), their weighted sum the normal
    /// force, and 0 off the contact face.
    #[test]
    fn the_contact_values_are_point_data_of_the_solution() {
        let (scene, _) = crate::scene_file::load("paper-slip", &["mesh.n=8".to_string()]).unwrap();
        let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
        let c = s.contact.as_ref().unwrap();
        let bytes = vtu(&s.mesh, (&s.u, &s.phi), &s.fields, Some(c)).unwrap();
        let vtk = Vtk::parse_xml(&bytes[..]).unwrap();
        let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
            panic!("not a grid")
        };
        let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
            panic!("not inline")
        };
        let array = |name: &str| -> Vec<f64> {
            piece
                .data
                .point
                .iter()
                .find_map(|a| match a {
                    vtkio::model::Attribute::DataArray(d) if d.name == name => d.data.clone().cast_into(),
                    _ => None,
                })
                .unwrap_or_else(|| panic!("no point array {name}"))
        };
        let (pressure, traction, gap) = (
            array("contact_pressure"),
            array("contact_traction"),
            array("contact_gap"),
        );
        let lambda = &c.solution.lambda;
        let mut force = 0.0;
        for (i, &node) in c.nodes.iter().enumerate() {
            assert_eq!(pressure[node], lambda.normal[i]);
            assert_eq!(traction[3 * node], lambda.tangential[i]);
            assert_eq!(gap[node], c.points.gap[i]);
            force += c.points.weight[i] * pressure[node];
        }
        let r = s.report.contact.normal_force;
        assert!((force - r).abs() <= 1e-12 * r, "{force} against {r}");
        let off: Vec<usize> = (0..s.mesh.n_nodes()).filter(|v| !c.nodes.contains(v)).collect();
        assert!(
            !off.is_empty()
                && off
                    .iter()
                    .all(|&v| pressure[v] == 0.0 && traction[3 * v..3 * v + 3] == [0.0; 3])
        );
    }

    /// The multipliers' picture draws each law's own slip bound (a Tresca run once drew its
    /// "Coulomb bound" F λ_n, 0 there) on both sides of the signed λ_t in 2D, and in 3D the
    /// magnitude |λ_t| that meets it (not one component of the vector).
    #[test]
    fn the_multipliers_picture_draws_the_laws_bound_against_the_right_quantity() {
        for (scene, n, says) in [
            ("paper-tresca", "mesh.n=8", ["±S (Tresca bound)", "lambda_t"]),
            ("paper-slip", "mesh.n=8", ["±F lambda_n (Coulomb bound)", "lambda_t"]),
            ("paper-3d", "mesh.n=3", ["F lambda_n (Coulomb bound)", "|lambda_t|"]),
        ] {
            let (sc, _) = crate::scene_file::load(scene, &[n.to_string()]).unwrap();
            let s = problem::solve(&sc, None, &mut problem::Silent).unwrap();
            let c = s.contact.as_ref().unwrap();
            let files = multipliers_picture(c, (&s.report.units, &s.report.plan), None).unwrap();
            let svg = files.iter().find(|(name, _)| name.ends_with(".svg")).unwrap();
            let text = String::from_utf8_lossy(&svg.1);
            for word in says {
                assert!(text.contains(word), "{scene}: no `{word}` in its picture");
            }
            assert!(!text.contains("first component"), "{scene}");
        }
    }

    /// A meridian's tensor turned with its wedge: at the angle θ its radial, axial and hoop
    /// components are those along `(cos θ, 0, sin θ)`, `y` and `(-sin θ, 0, cos θ)`, and its
    /// trace and norm are unchanged.
    #[test]
    fn a_meridian_tensor_turns_with_its_wedge() {
        // [rr, zz (y), θθ, rz, zθ, rθ]: a body of revolution has no shear with the hoop
        let t = [3.0, -1.0, 2.0, 0.5, 0.0, 0.0];
        assert_eq!(turned_about_y(&t, 1.0, 0.0), t);
        for theta in [0.3f64, 1.2, 2.5, 4.0] {
            let (c, s) = (theta.cos(), theta.sin());
            let g = turned_about_y(&t, c, s);
            let m = [[g[0], g[3], g[5]], [g[3], g[1], g[4]], [g[5], g[4], g[2]]];
            let along = |a: [f64; 3], b: [f64; 3]| -> f64 {
                (0..3)
                    .flat_map(|i| (0..3).map(move |j| (i, j)))
                    .map(|(i, j)| a[i] * m[i][j] * b[j])
                    .sum()
            };
            let (r, y, h) = ([c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]);
            for (got, want) in [
                (along(r, r), t[0]),
                (along(y, y), t[1]),
                (along(h, h), t[2]),
                (along(r, y), t[3]),
                (along(y, h), 0.0),
                (along(r, h), 0.0),
                (g[0] + g[1] + g[2], t[0] + t[1] + t[2]),
            ] {
                assert!((got - want).abs() < 1e-14, "θ = {theta}: {got} against {want}");
            }
        }
    }

    #[test]
    fn a_body_of_revolution_is_swept_into_wedges_that_face_out() {
        let mesh = mesh::rectangle_tri([0.0, 0.0], [1.0, 2.0], 2, 4);
        mesh.check().unwrap();
        let n = mesh.n_nodes();
        let u: Vec<[f64; 3]> = mesh.points.iter().map(|p| [0.1 * p[0], -0.2 * p[1], 0.0]).collect();
        let phi: Vec<f64> = mesh.points.iter().map(|p| p[1]).collect();
        let cells = mesh.n_cells();
        let fields = problem::CellFields {
            stress: vec![1.0; 4 * cells],
            strain: vec![0.5; 4 * cells],
            electric_displacement: [1.0, 0.0].repeat(cells),
            electric_field: [0.0, 1.0].repeat(cells),
            out_of_plane: vec![],
            at_nodes: None,
        };
        let bytes = revolved_vtu(&mesh, (&u, &phi), &fields, 12).unwrap();
        let vtk = Vtk::parse_xml(&bytes[..]).unwrap();
        let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
            panic!("not a grid")
        };
        let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
            panic!("not inline")
        };
        let points: Vec<f64> = piece.points.clone().cast_into().unwrap();
        assert_eq!(points.len(), 3 * 12 * n);
        let VertexNumbers::XML { connectivity, .. } = &piece.cells.cell_verts else {
            panic!("legacy")
        };
        assert_eq!(connectivity.len(), 6 * 12 * cells);
        // every wedge's base turns about a normal pointing away from its top
        let at = |i: u64| {
            [
                points[3 * i as usize],
                points[3 * i as usize + 1],
                points[3 * i as usize + 2],
            ]
        };
        for w in connectivity.chunks(6) {
            let (a, b, c) = (at(w[0]), at(w[1]), at(w[2]));
            let (ab, ac) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let normal = [
                ab[1] * ac[2] - ab[2] * ac[1],
                ab[2] * ac[0] - ab[0] * ac[2],
                ab[0] * ac[1] - ab[1] * ac[0],
            ];
            let top: Vec<[f64; 3]> = w[3..].iter().map(|&i| at(i)).collect();
            let centre: [f64; 3] = std::array::from_fn(|k| top.iter().map(|p| p[k]).sum::<f64>() / 3.0 - a[k]);
            let side: f64 = (0..3).map(|k| normal[k] * centre[k]).sum();
            assert!(side < 0.0, "wedge {w:?}: the base faces its top");
        }
        // the radius of each point is its meridian r, the axis its y
        for (k, p) in points.chunks(3).enumerate() {
            let m = mesh.points[k % n];
            assert!((p[0].hypot(p[2]) - m[0]).abs() < 1e-14 && p[1] == m[1]);
        }
    }

    #[test]
    fn the_default_directory_stays_under_out() {
        assert_eq!(default_dir("paper"), Path::new("out/paper"));
        assert_eq!(default_dir("../x"), Path::new("out/_x"));
        assert_eq!(default_dir("/tmp/x"), Path::new("out/_tmp_x"));
        assert_eq!(default_dir(".."), Path::new("out/scene"));
    }
}
