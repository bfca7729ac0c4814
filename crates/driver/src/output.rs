//! The files of a run, exactly those its plan lists (`run.json`, `solution.vtu`,
//! `contact.csv`, the pictures), and their writing as one set ([`Outputs`]): every file goes
//! to a temporary name in the output directory and is renamed only when all of them are
//! written; on any error nothing is left behind.

use crate::plots::{self, Mark, Panel, Series};
use crate::DriverError;
use problem::{ContactResult, Output, RunReport, Solution};
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// Files to write together.
pub struct Outputs {
    dir: PathBuf,
    files: Vec<(String, Vec<u8>)>,
}

impl Outputs {
    /// Files for directory `dir` (created on commit).
    pub fn new(dir: &Path) -> Self {
        Outputs {
            dir: dir.to_path_buf(),
            files: vec![],
        }
    }

    /// Adds a file's bytes.
    pub fn add(&mut self, name: &str, bytes: Vec<u8>) {
        self.files.push((name.to_string(), bytes));
    }

    /// Adds several files.
    pub fn extend(&mut self, files: plots::Files) {
        self.files.extend(files);
    }

    /// Writes every file under a temporary name, then renames them all.
    ///
    /// # Errors
    /// [`DriverError::Output`] naming the path that could not be created, written or renamed.
    pub fn commit(self) -> Result<(), DriverError> {
        let io = |what: &str, p: &Path, e: std::io::Error| DriverError::Output {
            what: format!("{what} {}", p.display()),
            source: e,
        };
        std::fs::create_dir_all(&self.dir).map_err(|e| io("cannot create", &self.dir, e))?;
        let pid = std::process::id();
        let mut written: Vec<(PathBuf, PathBuf)> = vec![];
        for (name, bytes) in &self.files {
            let tmp = self.dir.join(format!(".{name}.{pid}.tmp"));
            if let Err(e) = std::fs::write(&tmp, bytes) {
                for (t, _) in &written {
                    let _ = std::fs::remove_file(t);
                }
                let _ = std::fs::remove_file(&tmp);
                return Err(io("cannot write", &tmp, e));
            }
            written.push((tmp, self.dir.join(name)));
        }
        for (tmp, fin) in &written {
            std::fs::rename(tmp, fin).map_err(|e| io("cannot rename to", fin, e))?;
        }
        Ok(())
    }
}

/// `run.json`: the report, pretty, its keys in sorted order.
///
/// # Errors
/// [`DriverError::Picture`] if serde cannot write it (it always can).
pub fn run_json(report: &RunReport) -> Result<Vec<u8>, DriverError> {
    let encode = |e: serde_json::Error| DriverError::Picture {
        name: "run.json".into(),
        message: e.to_string(),
    };
    let tree = serde_json::to_value(report).map_err(encode)?;
    serde_json::to_vec_pretty(&tree).map_err(encode)
}

/// The files of a solution, those its plan lists.
///
/// # Errors
/// [`DriverError::Picture`] where a file cannot be made.
pub fn files(solution: &Solution) -> Result<Outputs, DriverError> {
    let mut out = Outputs::new(Path::new(""));
    let missing = |what: &str| DriverError::Picture {
        name: what.into(),
        message: "the plan lists it, but the run has nothing to draw it from".into(),
    };
    for &output in &solution.report.plan.outputs {
        match output {
            Output::RunJson => out.add("run.json", run_json(&solution.report)?),
            Output::SolutionVtu => out.add("solution.vtu", vtu(solution)?),
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
    Ok(out)
}

/// Writes the files of a solution into `dir`, as one set.
///
/// # Errors
/// As [`files`] and [`Outputs::commit`].
pub fn write(solution: &Solution, dir: &Path) -> Result<(), DriverError> {
    let mut out = files(solution)?;
    out.dir = dir.to_path_buf();
    out.commit()
}

/// The solution as a VTK XML unstructured grid: point data `u` (3 components), `phi`; cell
/// data `stress` (Voigt), `strain`, `electric_displacement`, `electric_field`; and, with
/// contact, point data `contact_status` (0 none, 1 stick, 2 slip, 3 separated).
fn vtu(solution: &Solution) -> Result<Vec<u8>, DriverError> {
    let (mesh, fields) = (&solution.mesh, &solution.fields);
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
    let nv = if dim == 2 { 3 } else { 6 };
    let mut point = vec![
        Attribute::generic("u", 3).with_data(solution.u.iter().flatten().copied().collect::<Vec<f64>>()),
        Attribute::scalars("phi", 1).with_data(solution.phi.clone()),
    ];
    if let Some(c) = &solution.contact {
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
    vtk.write_xml(&mut buf).map_err(|e| DriverError::Picture {
        name: "solution.vtu".into(),
        message: e.to_string(),
    })?;
    Ok(buf)
}

/// One row per contact point: `x,y[,z],gap,u_n,u_t[,u_t2],lambda_n,lambda_t[,lambda_t2],status`;
/// the displacements are those of the final solution (a frictionless body slides: its `u_t`
/// is written too), the tangential multipliers 0 where the law carries none.
fn contact_csv(c: &ContactResult) -> Vec<u8> {
    let (points, sol, u) = (&c.points, &c.solution, &c.displacement);
    let dim = points.dim;
    let nt = sol.lambda.n_tangential();
    let mut s = String::new();
    s.push_str(if dim == 2 {
        "x,y,gap,u_n,u_t,lambda_n,lambda_t,status\n"
    } else {
        "x,y,z,gap,u_n,u_t,u_t2,lambda_n,lambda_t,lambda_t2,status\n"
    });
    for i in 0..points.len() {
        let mut row: Vec<String> = points.position[i][..dim].iter().map(|x| format!("{x:.12e}")).collect();
        row.push(format!("{:.12e}", points.gap[i]));
        row.push(format!("{:.12e}", u.normal[i]));
        for &ut in u.tangential_of(i) {
            row.push(format!("{ut:.12e}"));
        }
        row.push(format!("{:.12e}", sol.lambda.normal[i]));
        for q in 0..dim - 1 {
            row.push(format!(
                "{:.12e}",
                if nt > 0 { sol.lambda.tangential[i * nt + q] } else { 0.0 }
            ));
        }
        row.push(sol.status[i].name().to_string());
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s.into_bytes()
}

/// The multipliers along the contact boundary (in 3D, along the contact face's middle line
/// y = y_mid), like the paper's figures: `λ_n`, `λ_t` (first component), the Coulomb bound
/// `F λ_n`, and the sliding points.
fn multipliers_picture(c: &ContactResult) -> Result<plots::Files, DriverError> {
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
    let panel = Panel {
        title: title.into(),
        labels: ("x".into(), "multiplier".into()),
        series,
    };
    plots::panels("multipliers", &[panel])
}

/// Where a run writes by default: `out/<scene>/`.
pub fn default_dir(scene_name: &str) -> PathBuf {
    Path::new("out").join(scene_name)
}

#[cfg(test)]
mod tests {
    #[test]
    fn failed_commit_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        // a directory where a file should go makes the rename fail; the temporaries vanish
        let target = dir.path().join("run");
        let mut o = super::Outputs::new(&target);
        o.add("a.txt", b"a".to_vec());
        o.add("nested/b.txt", b"b".to_vec()); // cannot be written: no such subdirectory
        assert!(o.commit().is_err());
        let left: Vec<_> = std::fs::read_dir(&target).unwrap().collect();
        assert!(left.is_empty(), "{left:?}");
    }
}
