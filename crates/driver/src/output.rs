//! Outputs, written atomically: every file goes to a temporary name in the output directory
//! and is renamed only when all of them are written; on any error nothing is left behind.

use crate::DriverError;
use fe_assembly::CellFields;
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
    /// Writes every file under a temporary name, then renames them all.
    pub fn commit(self) -> Result<(), DriverError> {
        let io = |what: &str, p: &Path, e: std::io::Error| DriverError::Output(format!("{what} {}: {e}", p.display()));
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

/// The solution as a VTK XML unstructured grid: point data `u` (3 components), `phi`; cell
/// data `stress` (Voigt), `electric_displacement`, `electric_field`; and optional point data
/// `contact_status` (0 none, 1 stick, 2 slip, 3 separated).
pub fn vtu(
    mesh: &mesh::Mesh,
    u: &[[f64; 3]],
    phi: &[f64],
    fields: &CellFields,
    contact_status: Option<&[f64]>,
) -> Result<Vec<u8>, DriverError> {
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
        Attribute::generic("u", 3).with_data(u.iter().flatten().copied().collect::<Vec<f64>>()),
        Attribute::scalars("phi", 1).with_data(phi.to_vec()),
    ];
    if let Some(s) = contact_status {
        point.push(Attribute::scalars("contact_status", 1).with_data(s.to_vec()));
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
    vtk.write_xml(&mut buf)
        .map_err(|e| DriverError::Output(format!("solution.vtu: {e}")))?;
    Ok(buf)
}

/// One row per contact point: `x,y[,z],gap,u_n,u_t[,u_t2],lambda_n,lambda_t[,lambda_t2],status`.
pub fn contact_csv(points: &contact::ContactPoints, sol: &contact::ContactSolution) -> Vec<u8> {
    let dim = points.dim;
    let nt = sol.lambda.tangential.len().checked_div(points.len()).unwrap_or(0);
    let mut s = String::new();
    s.push_str(if dim == 2 {
        "x,y,gap,u_n,u_t,lambda_n,lambda_t,status\n"
    } else {
        "x,y,z,gap,u_n,u_t,u_t2,lambda_n,lambda_t,lambda_t2,status\n"
    });
    for i in 0..points.len() {
        let mut row: Vec<String> = points.position[i][..dim].iter().map(|x| format!("{x:.12e}")).collect();
        row.push(format!("{:.12e}", points.gap[i]));
        row.push(format!("{:.12e}", sol.u.normal[i]));
        for q in 0..dim - 1 {
            row.push(format!(
                "{:.12e}",
                if nt > 0 { sol.u.tangential[i * nt + q] } else { 0.0 }
            ));
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
