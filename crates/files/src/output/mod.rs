//! The files of a run, exactly those its plan lists (`run.json`, `solution.vtu`,
//! `contact.csv`, the pictures), written as one set ([`Outputs`], in `set`): the new set
//! appears all at once, in place of the previous one, or not at all.

mod set;

pub use set::{Outputs, SetWriter};

use crate::plots::{self, Mark, Panel, Series};
use crate::Error;
use problem::{ContactResult, Output, RunReport, Solution};
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// `run.json`: the report, pretty, its keys in sorted order.
///
/// # Errors
/// [`Error::Picture`] if serde cannot write it (it always can).
pub fn run_json(report: &RunReport) -> Result<Vec<u8>, Error> {
    let encode = |e: serde_json::Error| Error::Picture {
        name: "run.json".into(),
        message: e.to_string(),
    };
    let tree = serde_json::to_value(report).map_err(encode)?;
    serde_json::to_vec_pretty(&tree).map_err(encode)
}

/// The files of a solution, those its plan lists (and, for the last instant of a load path,
/// `path.csv` and its pictures).
///
/// # Errors
/// [`Error::Picture`] where a file cannot be made.
pub fn files(solution: &Solution) -> Result<Outputs, Error> {
    let mut out = Outputs::new(Path::new(""));
    let missing = |what: &str| Error::Picture {
        name: what.into(),
        message: "the plan lists it, but the run has nothing to draw it from".into(),
    };
    for &output in &solution.report.plan.outputs {
        match output {
            Output::RunJson => out.add("run.json", run_json(&solution.report)?),
            Output::SolutionVtu => out.add(
                "solution.vtu",
                vtu(
                    &solution.mesh,
                    (&solution.u, &solution.phi),
                    &solution.fields,
                    solution.contact.as_ref(),
                )?,
            ),
            Output::ContactCsv => {
                let c = solution.contact.as_ref().ok_or_else(|| missing("contact.csv"))?;
                out.add("contact.csv", contact_csv(c));
            }
            Output::Multipliers => {
                let c = solution.contact.as_ref().ok_or_else(|| missing("multipliers"))?;
                out.extend(multipliers_picture(c)?);
            }
            Output::Deformed => {
                let pic = plots::mesh_view::deformed_picture(&solution.mesh, &solution.u)?;
                out.extend(pic.ok_or_else(|| missing("deformed"))?);
            }
            Output::Potential => {
                let pic = plots::mesh_view::potential_picture(&solution.mesh, &solution.u, &solution.phi)?;
                out.extend(pic.ok_or_else(|| missing("potential"))?);
            }
        }
    }
    // a load path's rows and curves
    out.extend(path_files(solution)?);
    Ok(out)
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
    (u, phi): (&[[f64; 3]], &[f64]),
    fields: &problem::CellFields,
    contact: Option<&ContactResult>,
) -> Result<Vec<u8>, Error> {
    let points: Vec<f64> = mesh.points.iter().flatten().copied().collect();
    let k = mesh.kind.n_nodes();
    let connectivity: Vec<u64> = mesh.cells.iter().map(|&v| v as u64).collect();
    let offsets: Vec<u64> = (1..=mesh.n_cells()).map(|c| (c * k) as u64).collect();
    let ct = match mesh.kind {
        mesh::CellKind::Tri3 => CellType::Triangle,
        mesh::CellKind::Quad4 => CellType::Quad,
        mesh::CellKind::Tet4 => CellType::Tetra,
    };
    let dim = mesh.dim;
    // Voigt components per cell: 3 in plane strain, 4 on a body of revolution ([rr, zz, rz,
    // θθ]), 6 in 3D
    let nv = fields.stress.len() / mesh.n_cells().max(1);
    let mut point = vec![
        Attribute::generic("u", 3).with_data(u.iter().flatten().copied().collect::<Vec<f64>>()),
        Attribute::scalars("phi", 1).with_data(phi.to_vec()),
    ];
    if let Some(c) = contact {
        let mut status = vec![0.0; mesh.n_nodes()];
        for (i, &node) in c.nodes.iter().enumerate() {
            status[node] = match c.solution.status[i] {
                contact::Status::Stick => 1.0,
                contact::Status::Slip => 2.0,
                contact::Status::Separated => 3.0,
            };
        }
        point.push(Attribute::scalars("contact_status", 1).with_data(status));
    }
    let cell = vec![
        Attribute::generic("stress", nv as u32).with_data(fields.stress.clone()),
        Attribute::generic("strain", nv as u32).with_data(fields.strain.clone()),
        Attribute::generic("electric_displacement", dim as u32).with_data(fields.electric_displacement.clone()),
        Attribute::generic("electric_field", dim as u32).with_data(fields.electric_field.clone()),
    ];
    let vtk = Vtk {
        version: Version::new((1, 0)),
        title: "piezocontact solution".into(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: points.into(),
            cells: Cells {
                cell_verts: VertexNumbers::XML { connectivity, offsets },
                types: vec![ct; mesh.n_cells()],
            },
            data: Attributes { point, cell },
        }),
    };
    let mut buf = Vec::new();
    vtk.write_xml(&mut buf).map_err(|e| Error::Picture {
        name: "solution.vtu".into(),
        message: e.to_string(),
    })?;
    Ok(buf)
}

/// One row per contact point: `x,y[,z],gap,u_n,u_t[,u_t2],lambda_n,lambda_t[,lambda_t2],status`
/// and, with electrical contact, `flux,potential` (`nan` where an electrode holds the point);
/// the displacements are those of the final solution (a frictionless body slides: its `u_t`
/// is written too), the tangential multipliers 0 where the law carries none.
fn contact_csv(c: &ContactResult) -> Vec<u8> {
    let (points, sol, u) = (&c.points, &c.solution, &c.displacement);
    let dim = points.dim;
    let nt = sol.lambda.n_tangential();
    let mut s = String::new();
    s.push_str(if dim == 2 {
        "x,y,gap,u_n,u_t,lambda_n,lambda_t,status"
    } else {
        "x,y,z,gap,u_n,u_t,u_t2,lambda_n,lambda_t,lambda_t2,status"
    });
    // electrical contact: the flux D.n and the potential of each point (nan on an electrode)
    let electric = sol.electric.as_ref().map(|e| {
        let mut at = vec![(f64::NAN, f64::NAN); points.len()];
        for (k, &i) in e.points.iter().enumerate() {
            at[i] = (e.flux[k], e.potential[k]);
        }
        at
    });
    s.push_str(if electric.is_some() { ",flux,potential\n" } else { "\n" });
    for i in 0..points.len() {
        // `{:e}`: the shortest digits that read back to the same double
        let mut row: Vec<String> = points.position[i][..dim].iter().map(|x| format!("{x:e}")).collect();
        row.push(format!("{:e}", points.gap[i]));
        row.push(format!("{:e}", u.normal[i]));
        for &ut in u.tangential_of(i) {
            row.push(format!("{ut:e}"));
        }
        row.push(format!("{:e}", sol.lambda.normal[i]));
        for q in 0..dim - 1 {
            row.push(format!(
                "{:e}",
                if nt > 0 { sol.lambda.tangential[i * nt + q] } else { 0.0 }
            ));
        }
        row.push(sol.status[i].name().to_string());
        if let Some(at) = &electric {
            row.push(format!("{:e}", at[i].0));
            row.push(format!("{:e}", at[i].1));
        }
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s.into_bytes()
}

/// The multipliers along the contact boundary (in 3D, along the contact face's middle line
/// y = y_mid), like the paper's figures: `λ_n`, `λ_t` (first component), the Coulomb bound
/// `F λ_n`, and the sliding points.
fn multipliers_picture(c: &ContactResult) -> Result<plots::Files, Error> {
    let (p, s) = (&c.points, &c.solution);
    let nt = s.lambda.n_tangential();
    let mut idx: Vec<usize> = (0..p.len()).collect();
    if p.dim == 3 {
        let ys: Vec<f64> = p.position.iter().map(|x| x[1]).collect();
        let (ymin, ymax) = ys
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| (a.min(y), b.max(y)));
        let mid = 0.5 * (ymin + ymax);
        let best = ys.iter().map(|y| (y - mid).abs()).fold(f64::INFINITY, f64::min);
        idx.retain(|&i| ((ys[i] - mid).abs() - best).abs() < 1e-12);
    }
    idx.sort_by(|&a, &b| p.position[a][0].total_cmp(&p.position[b][0]));
    let along = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&i| (p.position[i][0], f(i))).collect::<Vec<_>>();
    let mut series = vec![Series::line("lambda_n (pressure)", along(&|i| s.lambda.normal[i]))];
    if nt > 0 {
        let name = if nt > 1 {
            "lambda_t (first component)"
        } else {
            "lambda_t"
        };
        series.push(Series::line(name, along(&|i| s.lambda.tangential[i * nt])));
        series.push(Series {
            name: "slipping point".into(),
            points: idx
                .iter()
                .filter(|&&i| s.status[i] == contact::Status::Slip)
                .map(|&i| (p.position[i][0], s.lambda.tangential[i * nt]))
                .collect(),
            mark: Mark::Dots,
        });
        series.push(Series {
            name: "F lambda_n (Coulomb bound)".into(),
            points: along(&|i| p.friction[i] * s.lambda.normal[i]),
            mark: Mark::Reference,
        });
    }
    let title = if p.dim == 3 {
        "Multipliers on the contact face's middle line"
    } else {
        "Multipliers along the contact boundary"
    };
    let mut panels = vec![Panel {
        title: title.into(),
        labels: ("x".into(), "multiplier".into()),
        series,
    }];
    if let Some(e) = &s.electric {
        // the flux through the points (those with a free potential), along the same line
        let flux: Vec<(f64, f64)> = idx
            .iter()
            .filter_map(|&i| {
                e.points
                    .iter()
                    .position(|&j| j == i)
                    .map(|k| (p.position[i][0], e.flux[k]))
            })
            .collect();
        panels.push(Panel {
            title: "Electric flux D.n through the contact boundary".into(),
            labels: ("x".into(), "flux".into()),
            series: vec![Series::line("D.n (leaving the body)", flux)],
        });
    }
    plots::panels("multipliers", &panels)
}

/// The files of a load path, written step by step ([`PathFiles::step`]: each instant's
/// `step-NNNN.vtu`, a ParaView time series) and finished with the last instant's solution
/// ([`PathFiles::finish`]): the plan's files of the last instant, `path.csv` (one row per
/// instant), `path.pvd` (the series' collection), and `path.svg`/`.png` (the contact forces
/// against time, and the tangential force against the prescribed x displacement: friction's
/// loop).
#[derive(Default)]
pub struct PathFiles {
    series: Vec<(f64, String)>,
}

impl PathFiles {
    /// The names a path's set is sure to hold (checked before anything is written): its steps'
    /// files, the path's own, and the last instant's report, solution and contact table.
    pub fn expected_names(scene: &problem::Scene) -> Vec<String> {
        let steps = scene.path.as_ref().map_or(1, |p| p.instants().len());
        let written = |k: &usize| scene.path.as_ref().is_none_or(|p| p.has_fields(*k, steps));
        let mut names: Vec<String> = (0..steps).filter(written).map(step_name).collect();
        names.extend(["path.csv", "path.pvd", "run.json", "solution.vtu", "contact.csv"].map(String::from));
        names
    }

    /// Writes one instant's `step-NNNN.vtu` into the set.
    ///
    /// # Errors
    /// [`Error::Picture`] where its VTU cannot be made, [`Error::Output`] where it cannot be
    /// written.
    pub fn step(&mut self, step: &problem::Step<'_>, writer: &mut SetWriter) -> Result<(), Error> {
        let Some(f) = &step.fields else {
            return Ok(());
        };
        let name = step_name(step.row.step);
        writer.write(&name, &vtu(step.mesh, (f.u, f.phi), f.fields, Some(step.contact))?)?;
        self.series.push((step.row.t, name));
        Ok(())
    }

    /// The files of the last instant and the path's own.
    ///
    /// # Errors
    /// As [`files`].
    pub fn finish(self, last: &Solution) -> Result<Outputs, Error> {
        let mut out = files(last)?;
        if !self.series.is_empty() {
            out.add("path.pvd", pvd(&self.series));
        }
        Ok(out)
    }
}

/// The name of a path's instant `k` in its series.
fn step_name(k: usize) -> String {
    format!("step-{k:04}.vtu")
}

/// A path's own files without its series: `path.csv` and the pictures of its global curves
/// (none for a run of one instant).
fn path_files(solution: &Solution) -> Result<plots::Files, Error> {
    let Some(path) = &solution.report.path else {
        return Ok(vec![]);
    };
    let terminals: Vec<&str> = solution.report.terminals.iter().map(|t| t.group.as_str()).collect();
    let mut out = vec![("path.csv".to_string(), path_csv(&path.rows, &terminals))];
    out.extend(path_picture(&path.rows, &terminals)?);
    Ok(out)
}

/// `path.csv`: one row per instant, with the charge through each terminal (`charge_GROUP`).
fn path_csv(rows: &[problem::report::StepRow], terminals: &[&str]) -> Vec<u8> {
    let mut s = String::from(
        "step,t,load,voltage,ux,uy,uz,gap,normal_force,tangential_force,max_slip,max_slip_increment,n_stick,n_slip,n_separated,iterations,complementarity,equilibrium",
    );
    for t in terminals {
        s.push_str(&format!(",charge_{t}"));
    }
    s.push('\n');
    for r in rows {
        let mut row = vec![r.step.to_string(), format!("{:e}", r.t)];
        row.extend(r.factors.iter().map(|f| format!("{f:e}")));
        row.extend(
            [r.normal_force, r.tangential_force, r.max_slip, r.max_slip_increment]
                .iter()
                .map(|v| format!("{v:e}")),
        );
        row.extend(
            [r.n_stick, r.n_slip, r.n_separated, r.iterations]
                .iter()
                .map(|v| v.to_string()),
        );
        row.push(format!("{:e}", r.complementarity));
        row.push(r.equilibrium.map_or(String::new(), |e| format!("{e:e}")));
        row.extend(r.charges.iter().map(|q| format!("{q:e}")));
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s.into_bytes()
}

/// `path.pvd`: ParaView's collection of the steps' files, each at its instant.
fn pvd(series: &[(f64, String)]) -> Vec<u8> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, name) in series {
        s.push_str(&format!(
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{name}\"/>\n"
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s.into_bytes()
}

/// The path's global curves: the contact forces against time; the forces against the factor
/// that drives the path (the one that varies most: a load, a voltage, a displacement), whose
/// loop is friction's hysteresis; and the charges through the terminals against time.
fn path_picture(rows: &[problem::report::StepRow], terminals: &[&str]) -> Result<plots::Files, Error> {
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
    let mut panels = vec![
        Panel {
            title: "Contact forces along the path".into(),
            labels: ("t".into(), "force".into()),
            series: vec![
                Series::line("normal force", over(&|r| (r.t, r.normal_force))),
                Series::line("tangential force", over(&|r| (r.t, r.tangential_force))),
            ],
        },
        Panel {
            title: format!(
                "Tangential force against the {} factor (friction's loop)",
                FACTORS[driver]
            ),
            labels: (format!("{} factor", FACTORS[driver]), "tangential force".into()),
            series: vec![Series::line(
                "tangential force",
                over(&|r| (r.factors[driver], r.tangential_force)),
            )],
        },
    ];
    if !terminals.is_empty() {
        panels.push(Panel {
            title: "Charge through each terminal".into(),
            labels: ("t".into(), "charge".into()),
            series: terminals
                .iter()
                .enumerate()
                .map(|(g, name)| Series::line(name, over(&|r| (r.t, r.charges.get(g).copied().unwrap_or(f64::NAN)))))
                .collect(),
        });
    }
    plots::panels_apart("path", &panels)
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

    #[test]
    fn the_default_directory_stays_under_out() {
        assert_eq!(default_dir("paper"), Path::new("out/paper"));
        assert_eq!(default_dir("../x"), Path::new("out/_x"));
        assert_eq!(default_dir("/tmp/x"), Path::new("out/_tmp_x"));
        assert_eq!(default_dir(".."), Path::new("out/scene"));
    }
}
