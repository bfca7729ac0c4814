//! VTK XML unstructured grids (`.vtu`), as ParaView, VTK and meshio read them: every array
//! inline, `format="binary"` (base64 of an 8-byte little-endian byte count, `header_type =
//! "UInt64"`, then the values, little-endian), byte for byte the files vtkio 0.6 writes (a
//! test compares them), encoded in pieces on rayon's pool: vtkio encodes one array after
//! another, then escapes the base64 text once more on one core, which at 400 000 cells took
//! a second after a minute's solve.

use base64::engine::general_purpose::STANDARD;
use base64::Engine;
use rayon::prelude::*;

/// The values of one array.
#[derive(Clone, Copy)]
pub(super) enum Values<'a> {
    /// `Float64`.
    F64(&'a [f64]),
    /// `UInt64`.
    U64(&'a [u64]),
    /// `UInt8`.
    U8(&'a [u8]),
}

/// A named array of point or cell data, `components` values per point or cell.
pub(super) struct Array<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: Values<'a>,
}

/// VTK's cell types of the grids written here.
#[derive(Clone, Copy)]
pub(super) enum CellType {
    Triangle = 5,
    Quad = 9,
    Tetra = 10,
    Wedge = 13,
}

/// An unstructured grid of cells of one type.
pub(super) struct Grid<'a> {
    /// Coordinates, 3 per point.
    pub points: &'a [f64],
    /// The cells' points, one cell after another.
    pub connectivity: &'a [u64],
    /// Where each cell's points end in `connectivity`.
    pub offsets: &'a [u64],
    pub cell_type: CellType,
    /// Point data; the first of one component is the grid's active scalars.
    pub point: Vec<Array<'a>>,
    /// Cell data.
    pub cell: Vec<Array<'a>>,
}

/// The grid as a `.vtu` file.
pub(super) fn write(grid: &Grid<'_>) -> Vec<u8> {
    let (n_points, n_cells) = (grid.points.len() / 3, grid.offsets.len());
    let types = vec![grid.cell_type as u8; n_cells];
    // every array, in the file's order, with its tag's attributes; encoded all at once
    let mut arrays: Vec<(String, Values<'_>)> = vec![];
    let tag = |name: Option<&str>, ty: &str, components: usize| {
        let name = name.map_or(String::new(), |n| format!(" Name=\"{n}\""));
        format!("<DataArray type=\"{ty}\"{name} format=\"binary\" NumberOfComponents=\"{components}\">")
    };
    for a in grid.point.iter().chain(&grid.cell) {
        arrays.push((tag(Some(a.name), type_name(a.values), a.components), a.values));
    }
    arrays.push((tag(None, "Float64", 3), Values::F64(grid.points)));
    arrays.push((tag(Some("connectivity"), "UInt64", 1), Values::U64(grid.connectivity)));
    arrays.push((tag(Some("offsets"), "UInt64", 1), Values::U64(grid.offsets)));
    arrays.push((tag(Some("types"), "UInt8", 1), Values::U8(&types)));
    let encoded: Vec<String> = arrays.iter().map(|(_, v)| binary(*v)).collect();
    let size: usize = encoded.iter().map(String::len).sum::<usize>() + 4096 + 64 * arrays.len();
    let mut out = String::with_capacity(size);
    out.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">",
    );
    out.push_str(&format!(
        "<UnstructuredGrid><Piece NumberOfPoints=\"{n_points}\" NumberOfCells=\"{n_cells}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\" NumberOfVerts=\"0\">"
    ));
    let mut next = arrays
        .iter()
        .zip(&encoded)
        .map(|((tag, _), data)| format!("{tag}{data}</DataArray>"));
    let mut section = |out: &mut String, open: String, close: &str, count: usize| {
        out.push_str(&open);
        for a in next.by_ref().take(count) {
            out.push_str(&a);
        }
        out.push_str(close);
    };
    let scalars = grid
        .point
        .iter()
        .find(|a| a.components == 1)
        .map_or(String::new(), |a| format!(" Scalars=\"{}\"", a.name));
    section(
        &mut out,
        format!("<PointData{scalars}>"),
        "</PointData>",
        grid.point.len(),
    );
    section(&mut out, "<CellData>".into(), "</CellData>", grid.cell.len());
    section(&mut out, "<Points>".into(), "</Points>", 1);
    section(&mut out, "<Cells>".into(), "</Cells>", 3);
    out.push_str("</Piece></UnstructuredGrid></VTKFile>");
    out.into_bytes()
}

/// VTK's name of the values' type.
fn type_name(v: Values<'_>) -> &'static str {
    match v {
        Values::F64(_) => "Float64",
        Values::U64(_) => "UInt64",
        Values::U8(_) => "UInt8",
    }
}

/// Values per encoded piece: a multiple of 3, so that each piece's bytes are one too, and the
/// pieces' base64 texts, put end to end, are the whole's (only the last one padded).
const PIECE: usize = 3 << 14;

/// The base64 text of the byte count (8 bytes, little-endian) and the values, little-endian,
/// encoded in pieces on rayon's pool.
fn binary(values: Values<'_>) -> String {
    match values {
        Values::F64(v) => pieces(v, |x, out| out.extend_from_slice(&x.to_le_bytes())),
        Values::U64(v) => pieces(v, |x, out| out.extend_from_slice(&x.to_le_bytes())),
        Values::U8(v) => pieces(v, |x, out| out.push(*x)),
    }
}

/// [`binary`] of values of `size_of::<T>()` bytes each, put by `le`.
fn pieces<T: Sync>(values: &[T], le: impl Fn(&T, &mut Vec<u8>) + Sync) -> String {
    let size = std::mem::size_of::<T>();
    let header = (std::mem::size_of_val(values) as u64).to_le_bytes();
    // the first piece holds the header too: as many values as make its bytes a multiple of 3
    let first = (1..=3)
        .map(|j| PIECE - j)
        .find(|k| (header.len() + k * size).is_multiple_of(3))
        .unwrap_or(PIECE)
        .min(values.len());
    let starts: Vec<usize> = std::iter::once(0).chain((first..values.len()).step_by(PIECE)).collect();
    let texts: Vec<String> = starts
        .par_iter()
        .enumerate()
        .map(|(k, &s)| {
            let e = if k == 0 { first } else { (s + PIECE).min(values.len()) };
            let mut bytes = Vec::with_capacity(header.len() + (e - s) * size);
            if k == 0 {
                bytes.extend_from_slice(&header);
            }
            for v in &values[s..e] {
                le(v, &mut bytes);
            }
            STANDARD.encode(&bytes)
        })
        .collect();
    texts.concat()
}

#[cfg(test)]
mod tests {
    use super::*;
    use vtkio::model::{
        Attribute, Attributes, ByteOrder, Cells, DataSet, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
    };

    /// A grid of `n` tetrahedra (not a mesh: the writer does not care) with point and cell
    /// data, written here and by vtkio: the same bytes. Sizes below one piece, across the first
    /// piece's boundary, and over several pieces of every array (not 0 cells, where vtkio
    /// leaves out `NumberOfCells`, which VTK's reader needs; a mesh has cells).
    #[test]
    fn the_file_is_vtkio_s() {
        for n in [1, 7, PIECE / 4 - 1, PIECE / 4, PIECE + 5, 3 * PIECE + 1] {
            let n_points = n + 3;
            let points: Vec<f64> = (0..3 * n_points).map(|i| (i as f64 * 0.37).sin()).collect();
            let connectivity: Vec<u64> = (0..4 * n).map(|i| (i / 4 + i % 4) as u64).collect();
            let offsets: Vec<u64> = (1..=n).map(|c| 4 * c as u64).collect();
            let u: Vec<f64> = (0..3 * n_points).map(|i| i as f64 * 1e-3 - 0.5).collect();
            let phi: Vec<f64> = (0..n_points).map(|i| (i as f64).cos()).collect();
            let stress: Vec<f64> = (0..6 * n).map(|i| (i as f64 * 1.1).tan()).collect();
            let grid = Grid {
                points: &points,
                connectivity: &connectivity,
                offsets: &offsets,
                cell_type: CellType::Tetra,
                point: vec![
                    Array {
                        name: "u",
                        components: 3,
                        values: Values::F64(&u),
                    },
                    Array {
                        name: "phi",
                        components: 1,
                        values: Values::F64(&phi),
                    },
                ],
                cell: vec![Array {
                    name: "stress",
                    components: 6,
                    values: Values::F64(&stress),
                }],
            };
            let vtk = Vtk {
                version: Version::new((1, 0)),
                title: "t".into(),
                byte_order: ByteOrder::LittleEndian,
                file_path: None,
                data: DataSet::inline(UnstructuredGridPiece {
                    points: points.clone().into(),
                    cells: Cells {
                        cell_verts: VertexNumbers::XML {
                            connectivity: connectivity.clone(),
                            offsets: offsets.clone(),
                        },
                        types: vec![vtkio::model::CellType::Tetra; n],
                    },
                    data: Attributes {
                        point: vec![
                            Attribute::generic("u", 3).with_data(u.clone()),
                            Attribute::scalars("phi", 1).with_data(phi.clone()),
                        ],
                        cell: vec![Attribute::generic("stress", 6).with_data(stress.clone())],
                    },
                }),
            };
            let mut theirs = Vec::new();
            vtk.write_xml(&mut theirs).unwrap();
            let ours = write(&grid);
            if ours != theirs {
                let at = ours
                    .iter()
                    .zip(&theirs)
                    .position(|(a, b)| a != b)
                    .unwrap_or(ours.len().min(theirs.len()));
                let show =
                    |b: &[u8]| String::from_utf8_lossy(&b[at.saturating_sub(80)..(at + 80).min(b.len())]).into_owned();
                panic!(
                    "{n} cells: the files differ from byte {at}:\n ours   {}\n theirs {}",
                    show(&ours),
                    show(&theirs)
                );
            }
        }
    }
}
