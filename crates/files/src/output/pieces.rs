//! The files of a run on pieces (issue 45): no process holds the whole mesh, so the solution
//! is written by pieces in ParaView's parallel form, `solution.pvtu` naming one
//! `solution-<rank>.vtu` per rank. Each piece holds its rank's own cells and one layer of
//! ghost cells, marked in the cell array `vtkGhostType` (1, VTK's duplicate cell) so that
//! ParaView draws and integrates each cell once; the point and cell arrays `node_id` and
//! `cell_id` give each node's and cell's number in the whole mesh. The rest of the set
//! (`run.json`, `contact.csv`, the pictures) is rank 0's, from the gathered surfaces: the
//! plan's files but `solution.vtu`.

use super::{mesh_arrays, output_files, FieldArrays, NamedValues};
use crate::Error;
use problem::{ContactResult, Output, Solution};
use std::path::Path;

use super::vtu::{self, Array, Grid, Values};

/// VTK's ghost flag of a cell another piece owns (`vtkDataSetAttributes::DUPLICATECELL`).
const DUPLICATE_CELL: u8 = 1;

/// The name of rank `rank`'s piece of the solution.
pub fn piece_name(rank: usize) -> String {
    format!("solution-{rank}.vtu")
}

/// The files of a set of `ranks` pieces other than the pieces themselves, known before the
/// run: `solution.pvtu` and the plan's other files (for [`super::SetWriter::begin`]'s check).
pub fn names_beside_pieces(outputs: &[Output], ranks: usize) -> Vec<String> {
    let mut names: Vec<String> = vec!["solution.pvtu".into()];
    names.extend((0..ranks).map(piece_name));
    for o in outputs.iter().filter(|&&o| o != Output::SolutionVtu) {
        // a picture's name says both of its files: `deformed.svg/png`
        match o.name().split_once(".svg/") {
            Some((stem, other)) => names.extend([format!("{stem}.svg"), format!("{stem}.{other}")]),
            None => names.push(o.name().to_string()),
        }
    }
    names
}

/// One rank's piece: its mesh (own and ghost cells), nodal fields, cell fields, its contact
/// points (with nodes of its mesh), each cell's ghost flag and the whole mesh's numbers of its
/// nodes and cells.
pub struct Piece<'a> {
    /// The piece's mesh.
    pub mesh: &'a mesh::Mesh,
    /// Nodal displacements and potentials.
    pub fields: (&'a [[f64; 3]], &'a [f64]),
    /// Stress, strain, D and E per cell.
    pub cells: &'a problem::CellFields,
    /// The rank's contact points, where the run has contact (an empty set on a rank without
    /// any: every piece carries the same arrays).
    pub contact: Option<&'a ContactResult>,
    /// Whether each cell is another rank's.
    pub ghost: &'a [bool],
    /// Each node's number in the whole mesh.
    pub node_id: &'a [usize],
    /// Each cell's number in the whole mesh.
    pub cell_id: &'a [usize],
}

impl Piece<'_> {
    /// The piece as a `.vtu` file, and (for rank 0 to write) the `.pvtu` that names the
    /// `ranks` pieces with the arrays this one holds.
    pub fn files(&self, ranks: usize) -> (Vec<u8>, Vec<u8>) {
        let (points, connectivity, offsets, cell_type) = mesh_arrays(self.mesh);
        let data = FieldArrays::new(self.mesh, self.fields, Some(self.cells), self.contact);
        let ghost: Vec<u8> = self.ghost.iter().map(|&g| if g { DUPLICATE_CELL } else { 0 }).collect();
        let node_id: Vec<u64> = self.node_id.iter().map(|&v| v as u64).collect();
        let cell_id: Vec<u64> = self.cell_id.iter().map(|&c| c as u64).collect();
        let mut point: Vec<Array<'_>> = data.point.iter().map(NamedValues::array).collect();
        point.push(Array {
            name: "node_id",
            components: 1,
            values: Values::U64(&node_id),
        });
        let mut cell: Vec<Array<'_>> = data.cell.iter().map(NamedValues::array).collect();
        cell.push(Array {
            name: "cell_id",
            components: 1,
            values: Values::U64(&cell_id),
        });
        cell.push(Array {
            name: "vtkGhostType",
            components: 1,
            values: Values::U8(&ghost),
        });
        let pvtu = pvtu(&point, &cell, ranks);
        let piece = vtu::write(&Grid {
            points: &points,
            connectivity: &connectivity,
            offsets: &offsets,
            cell_type,
            point,
            cell,
        });
        (piece, pvtu)
    }
}

/// The `.pvtu` of `ranks` pieces holding the arrays `point` and `cell`.
fn pvtu(point: &[Array<'_>], cell: &[Array<'_>], ranks: usize) -> Vec<u8> {
    let decl = |a: &Array<'_>| {
        format!(
            "<PDataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"/>",
            vtu::type_name(a.values),
            a.name,
            a.components
        )
    };
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PUnstructuredGrid GhostLevel=\"1\">\n",
    );
    s.push_str("<PPointData>");
    point.iter().for_each(|a| s.push_str(&decl(a)));
    s.push_str("</PPointData>\n<PCellData>");
    cell.iter().for_each(|a| s.push_str(&decl(a)));
    s.push_str("</PCellData>\n<PPoints><PDataArray type=\"Float64\" NumberOfComponents=\"3\"/></PPoints>\n");
    for r in 0..ranks {
        s.push_str(&format!("<Piece Source=\"{}\"/>\n", piece_name(r)));
    }
    s.push_str("</PUnstructuredGrid>\n</VTKFile>\n");
    s.into_bytes()
}

/// Rank 0's files of a run on pieces: the plan's files but `solution.vtu` (the pieces and
/// their `.pvtu` are written apart), made from `solution`, whose mesh is what the pictures
/// draw (the gathered face `front` of a 3D body) and whose contact is every rank's points.
///
/// # Errors
/// As [`super::files`].
pub fn files_beside_pieces(solution: &Solution) -> Result<Vec<(String, Vec<u8>)>, Error> {
    let mut out = vec![];
    for &o in solution
        .report
        .plan
        .outputs
        .iter()
        .filter(|&&o| o != Output::SolutionVtu)
    {
        out.extend(output_files(solution, o)?);
    }
    Ok(out)
}

/// Writes a piece that another process's set is gathering into that set's staging directory
/// `staging` (`SetWriter::staging`), to be adopted by the set's writer
/// (`SetWriter::adopt`): for the ranks of a parallel run, whose rank 0 writes the set.
///
/// # Errors
/// [`Error::Output`] where the file cannot be written.
pub fn write_into(staging: &Path, name: &str, bytes: &[u8]) -> Result<(), Error> {
    let path = staging.join(name);
    std::fs::write(&path, bytes).map_err(|e| Error::Output {
        what: format!("cannot write {}", path.display()),
        source: e,
    })
}
