//! The files of a run on pieces (issue 45): no process holds the whole mesh, so the solution
//! is written by pieces in ParaView's parallel form, `solution.pvtu` naming one
//! `solution-<rank>.vtu` per rank. Each piece holds its rank's own cells and one layer of
//! ghost cells, marked in the cell array `vtkGhostType` (1, VTK's duplicate cell) so that
//! ParaView draws and integrates each cell once; the point and cell arrays `node_id` and
//! `cell_id` give each node's and cell's number in the whole mesh. The rest of the set
//! (`run.json`, `contact.csv`, the pictures) is rank 0's, from the gathered surfaces: the
//! plan's files but `solution.vtu`.

use super::{mesh_arrays, output_files, path_files, FieldArrays, NamedValues};
use crate::Error;
use problem::{ContactResult, Output, Solution};
use std::path::Path;

use super::vtu::{self, Array, Grid, Values};

/// VTK's ghost flag of a cell another piece owns (`vtkDataSetAttributes::DUPLICATECELL`).
const DUPLICATE_CELL: u8 = 1;

/// The name of rank `rank`'s piece of the solution.
pub fn piece_name(rank: usize) -> String {
    piece_file("solution", rank)
}

/// The name of rank `rank`'s piece of the parallel file `<stem>.pvtu`.
pub fn piece_file(stem: &str, rank: usize) -> String {
    format!("{stem}-{rank}.vtu")
}

/// The stem of a path's instant `k` in its series (`step-NNNN.pvtu`, its pieces
/// `step-NNNN-<rank>.vtu`).
pub fn step_stem(k: usize) -> String {
    format!("step-{k:04}")
}

/// The files a run of `scene` on `ranks` pieces is sure to write, known before it is set up
/// (for [`super::SetWriter::begin`]'s check): the solution's pieces and `.pvtu`, `run.json`,
/// `contact.csv` where the scene has contact, and a path's instants (each written one's
/// pieces and `.pvtu`), `path.csv` and `path.pvd`.
pub fn names_of_pieces(scene: &problem::Scene, ranks: usize) -> Vec<String> {
    let mut names: Vec<String> = vec!["solution.pvtu".into(), "run.json".into()];
    names.extend((0..ranks).map(piece_name));
    if !scene.zones().is_empty() {
        names.push("contact.csv".into());
    }
    if let Some(path) = &scene.path {
        let n = path.instants().len();
        for k in (0..n).filter(|&k| path.has_fields(k, n)) {
            let stem = step_stem(k);
            names.push(format!("{stem}.pvtu"));
            names.extend((0..ranks).map(|r| piece_file(&stem, r)));
        }
        names.extend(["path.csv".into(), "path.pvd".into()]);
    }
    names
}

/// One rank's piece: its mesh (own and ghost cells), nodal fields, cell fields, its contact
/// points (with nodes of its mesh), each cell's owner and the whole mesh's numbers of its
/// nodes and cells.
pub struct Piece<'a> {
    /// The piece's mesh.
    pub mesh: &'a mesh::Mesh,
    /// Nodal displacements and potentials.
    pub fields: (&'a [[f64; 3]], &'a [f64]),
    /// Stress, strain, D and E per cell (a path's instant without them: `path.cell_fields`).
    pub cells: Option<&'a problem::CellFields>,
    /// The rank's contact points, where the run has contact (an empty set on a rank without
    /// any: every piece carries the same arrays).
    pub contact: Option<&'a ContactResult>,
    /// The rank that owns each cell, and this rank: a cell another rank owns is a ghost.
    pub owner: (&'a [usize], usize),
    /// Each node's number in the whole mesh.
    pub node_id: &'a [usize],
    /// Each cell's number in the whole mesh.
    pub cell_id: &'a [usize],
}

impl Piece<'_> {
    /// The piece as a `.vtu` file, and (for rank 0 to write) the `.pvtu` that names the
    /// `ranks` pieces with the arrays this one holds.
    pub fn files(&self, ranks: usize) -> (Vec<u8>, Vec<u8>) {
        self.encoded("solution", ranks, None)
    }

    /// The piece as rank `rank`'s `<stem>-<rank>.vtu` of a time series (its arrays
    /// zlib-compressed, the mesh's from `frames`, compressed at its first frame), and the
    /// `<stem>.pvtu` naming the `ranks` pieces. The cells' fields are written where
    /// `self.cells` has them (a path's `path.cell_fields`).
    pub fn frame(&self, frames: &mut Frames, stem: &str, ranks: usize) -> (Vec<u8>, Vec<u8>) {
        let mesh = frames.mesh.get_or_insert_with(|| {
            let (points, connectivity, offsets, cell_type) = mesh_arrays(self.mesh);
            vtu::CompressedMesh::new(&points, (&connectivity, &offsets), cell_type)
        });
        self.encoded(stem, ranks, Some(mesh))
    }

    /// The piece's `.vtu` (compressed on `mesh` where given) and the `.pvtu` of `stem`.
    fn encoded(&self, stem: &str, ranks: usize, mesh: Option<&vtu::CompressedMesh>) -> (Vec<u8>, Vec<u8>) {
        let data = FieldArrays::new(self.mesh, self.fields, self.cells, self.contact);
        let (cell_rank, rank) = self.owner;
        let ghost: Vec<u8> = cell_rank
            .iter()
            .map(|&r| if r != rank { DUPLICATE_CELL } else { 0 })
            .collect();
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
        let pvtu = pvtu(&point, &cell, stem, ranks);
        if let Some(mesh) = mesh {
            return (vtu::write_compressed(mesh, &point, &cell).to_bytes(), pvtu);
        }
        let (points, connectivity, offsets, cell_type) = mesh_arrays(self.mesh);
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

/// A rank's pieces of a time series: its mesh's arrays, compressed once for every frame.
#[derive(Default)]
pub struct Frames {
    mesh: Option<vtu::CompressedMesh>,
}

/// The `.pvtu` of the `ranks` pieces of `stem` holding the arrays `point` and `cell`.
fn pvtu(point: &[Array<'_>], cell: &[Array<'_>], stem: &str, ranks: usize) -> Vec<u8> {
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
        s.push_str(&format!("<Piece Source=\"{}\"/>\n", piece_file(stem, r)));
    }
    s.push_str("</PUnstructuredGrid>\n</VTKFile>\n");
    s.into_bytes()
}

/// Rank 0's files of a run on pieces: the plan's files but `solution.vtu` (the pieces and
/// their `.pvtu` are written apart), and a path's `path.csv` and curves, made from `solution`, whose mesh is what the pictures
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
    // a load path's rows and curves
    out.extend(path_files(solution)?);
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
