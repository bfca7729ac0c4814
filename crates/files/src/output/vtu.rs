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
    QuadraticTriangle = 22,
    QuadraticTetra = 24,
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
    let scalars = scalars(&grid.point);
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

/// `PointData`'s attribute naming the active scalars: the first point array of one component
/// (none without one).
fn scalars(point: &[Array<'_>]) -> String {
    point
        .iter()
        .find(|a| a.components == 1)
        .map_or(String::new(), |a| format!(" Scalars=\"{}\"", a.name))
}

/// VTK's name of the values' type.
pub(super) fn type_name(v: Values<'_>) -> &'static str {
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

/// Uncompressed bytes per zlib block of a compressed array (VTK's header counts them; the
/// blocks are compressed on rayon's pool).
const BLOCK: usize = 1 << 18;

/// One array's bytes in a compressed file's appended section: VTK's header (`UInt64`: the
/// number of blocks, the uncompressed size of a block, that of the last block where it is
/// partial, else 0, and each block's compressed size), then the blocks, each a zlib stream:
/// deflated at zlib's fastest level where at least half its bytes are zeros, stored (deflate's
/// blocks without compression) where fewer are ([`zlib_block`]).
pub(super) fn compressed(values: Values<'_>) -> Compressed {
    let bytes = little_endian_bytes(values);
    let blocks: Vec<Vec<u8>> = bytes.par_chunks(BLOCK).map(zlib_block).collect();
    let mut header = vec![blocks.len() as u64, BLOCK as u64, (bytes.len() % BLOCK) as u64];
    header.extend(blocks.iter().map(|b| b.len() as u64));
    Compressed {
        header: header.iter().flat_map(|x| x.to_le_bytes()).collect(),
        blocks,
    }
}

/// One array as [`compressed`] leaves it: VTK's header and the blocks, in pieces (written one
/// after another, never copied into one: a path's steps were copied twice, 6 MB a frame).
pub(super) struct Compressed {
    header: Vec<u8>,
    blocks: Vec<Vec<u8>>,
}

impl Compressed {
    /// Its bytes in the appended section.
    fn len(&self) -> usize {
        self.header.len() + self.blocks.iter().map(Vec::len).sum::<usize>()
    }

    /// Its pieces in order: the header, then the blocks.
    fn pieces(&self) -> impl Iterator<Item = &[u8]> {
        std::iter::once(&self.header[..]).chain(self.blocks.iter().map(|b| &b[..]))
    }
}

/// One block as a zlib stream (RFC 1950). A fast deflate of a field's values finds little but
/// their zero bytes (their mantissas are as good as random): on `paper-cycle` at n = 256 the
/// displacements (a third of their bytes the zeros of 2D's third component) deflate to 0.64
/// of their size in 4.1 ms a megabyte, the potentials to 0.92 in 5.3 ms, where storing them
/// costs a copy and a checksum, and a megabyte more to write costs 2 ms; mostly zero arrays
/// (the contact's fields away from the contact face, a mesh's indices) deflate to under 0.4
/// at 0.3-2 ms a megabyte. So a block with at least half its bytes zero is deflated at
/// zlib's fastest level, another is stored: the path's written instants spent 18 ms a frame
/// less for a file 1.2 MB larger (4.9 to 6.1 MB a frame there).
fn zlib_block(chunk: &[u8]) -> Vec<u8> {
    let zeros = chunk.iter().filter(|&&b| b == 0).count();
    if 2 * zeros >= chunk.len() {
        use std::io::Write;
        let mut z = flate2::write::ZlibEncoder::new(Vec::with_capacity(chunk.len() / 2), flate2::Compression::fast());
        // writing into a Vec cannot fail
        let _ = z.write_all(chunk);
        return z.finish().unwrap_or_default();
    }
    stored_zlib(chunk)
}

/// `bytes` as a zlib stream of stored deflate blocks (RFC 1950 and RFC 1951 §3.2.4): the
/// header of a 32 KB window at the fastest level, each at most 65,535 bytes behind its
/// length and the length's complement, the last marked final, then the Adler-32 checksum of
/// `bytes`, big-endian.
fn stored_zlib(bytes: &[u8]) -> Vec<u8> {
    const MAX: usize = 65_535;
    let mut out = Vec::with_capacity(bytes.len() + 5 * (bytes.len() / MAX + 1) + 6);
    out.extend_from_slice(&[0x78, 0x01]);
    let mut pieces = bytes.chunks(MAX).peekable();
    if bytes.is_empty() {
        out.extend_from_slice(&[1, 0, 0, 0xff, 0xff]);
    }
    while let Some(piece) = pieces.next() {
        out.push(u8::from(pieces.peek().is_none()));
        let len = piece.len() as u16;
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&(!len).to_le_bytes());
        out.extend_from_slice(piece);
    }
    let mut adler = simd_adler32::Adler32::new();
    adler.write(bytes);
    out.extend_from_slice(&adler.finish().to_be_bytes());
    out
}

/// The values' bytes in little-endian order: on a little-endian machine the values' own
/// memory, borrowed (a path's step converted 10 MB a frame at `paper-cycle` n = 256 before
/// compressing them).
fn little_endian_bytes(values: Values<'_>) -> std::borrow::Cow<'_, [u8]> {
    use std::borrow::Cow;
    match values {
        Values::U8(v) => Cow::Borrowed(v),
        Values::F64(v) if cfg!(target_endian = "little") => Cow::Borrowed(bytemuck::cast_slice(v)),
        Values::U64(v) if cfg!(target_endian = "little") => Cow::Borrowed(bytemuck::cast_slice(v)),
        Values::F64(v) => Cow::Owned(v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Values::U64(v) => Cow::Owned(v.iter().flat_map(|x| x.to_le_bytes()).collect()),
    }
}

/// A grid's geometry and cells as [`compressed`] arrays, made once for every frame of a time
/// series on one mesh.
pub(super) struct CompressedMesh {
    pub n_points: usize,
    pub n_cells: usize,
    /// `points`, `connectivity`, `offsets`, `types`, each [`compressed`].
    arrays: [Compressed; 4],
}

impl CompressedMesh {
    /// The grid of `points` (3 coordinates each) and cells of `cell_type` (`connectivity`,
    /// `offsets`, as [`Grid`] holds them).
    pub fn new(points: &[f64], (connectivity, offsets): (&[u64], &[u64]), cell_type: CellType) -> Self {
        let n_cells = offsets.len();
        let types = vec![cell_type as u8; n_cells];
        CompressedMesh {
            n_points: points.len() / 3,
            n_cells,
            arrays: [
                compressed(Values::F64(points)),
                compressed(Values::U64(connectivity)),
                compressed(Values::U64(offsets)),
                compressed(Values::U8(&types)),
            ],
        }
    }
}

/// A `.vtu` file with every array zlib-compressed in raw appended data
/// (`compressor="vtkZLibDataCompressor"`): the mesh's arrays from `mesh`, `point` and `cell`
/// data compressed here. ParaView, VTK and meshio read it.
pub(super) fn write_compressed<'m>(
    mesh: &'m CompressedMesh,
    point: &[Array<'_>],
    cell: &[Array<'_>],
) -> CompressedFile<'m> {
    let data: Vec<Compressed> = point.iter().chain(cell).map(|a| compressed(a.values)).collect();
    let mut xml = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
        mesh.n_points, mesh.n_cells
    );
    let mut offset = 0usize;
    let mut tag = |xml: &mut String, name: Option<&str>, ty: &str, components: usize, len: usize| {
        let name = name.map_or(String::new(), |n| format!(" Name=\"{n}\""));
        xml.push_str(&format!(
            "<DataArray type=\"{ty}\"{name} NumberOfComponents=\"{components}\" format=\"appended\" offset=\"{offset}\"/>\n"
        ));
        offset += len;
    };
    let scalars = scalars(point);
    let mut bytes = data.iter().map(Compressed::len);
    let mut named = |xml: &mut String, arrays: &[Array<'_>]| {
        for a in arrays {
            let len = bytes.next().unwrap_or(0);
            tag(xml, Some(a.name), type_name(a.values), a.components, len);
        }
    };
    xml.push_str(&format!("<PointData{scalars}>\n"));
    named(&mut xml, point);
    xml.push_str("</PointData>\n<CellData>\n");
    named(&mut xml, cell);
    let [points, connectivity, offsets, types] = &mesh.arrays;
    xml.push_str("</CellData>\n<Points>\n");
    tag(&mut xml, None, "Float64", 3, points.len());
    xml.push_str("</Points>\n<Cells>\n");
    tag(&mut xml, Some("connectivity"), "UInt64", 1, connectivity.len());
    tag(&mut xml, Some("offsets"), "UInt64", 1, offsets.len());
    tag(&mut xml, Some("types"), "UInt8", 1, types.len());
    xml.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_");
    CompressedFile {
        head: xml.into_bytes(),
        data,
        mesh,
    }
}

/// A compressed `.vtu` file ([`write_compressed`]) in pieces: its XML, each array's header and
/// blocks, the mesh's, and the closing tags.
pub(super) struct CompressedFile<'m> {
    head: Vec<u8>,
    data: Vec<Compressed>,
    mesh: &'m CompressedMesh,
}

impl CompressedFile<'_> {
    const TAIL: &'static [u8] = b"\n</AppendedData>\n</VTKFile>\n";

    /// The file's pieces in order.
    fn pieces(&self) -> impl Iterator<Item = &[u8]> {
        let arrays = self.data.iter().chain(&self.mesh.arrays);
        std::iter::once(&self.head[..])
            .chain(arrays.flat_map(Compressed::pieces))
            .chain(std::iter::once(Self::TAIL))
    }

    /// Writes the file into `w`, piece by piece.
    ///
    /// # Errors
    /// `w`'s.
    pub fn write_to(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        self.pieces().try_for_each(|p| w.write_all(p))
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pieces().map(<[u8]>::len).sum());
        self.pieces().for_each(|p| out.extend_from_slice(p));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vtkio::model::{
        Attribute, Attributes, ByteOrder, Cells, DataSet, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
    };

    /// VTK's compressed layout read back by hand: the header's block count and sizes, each
    /// block a zlib stream inflating to the array's bytes in order.
    fn inflate(data: &[u8]) -> (Vec<u8>, usize) {
        use std::io::Read;
        let word = |k: usize| u64::from_le_bytes(data[8 * k..8 * k + 8].try_into().unwrap()) as usize;
        let (blocks, size, last) = (word(0), word(1), word(2));
        assert_eq!(size, BLOCK);
        let mut at = 8 * (3 + blocks);
        let mut out = vec![];
        for b in 0..blocks {
            let len = word(3 + b);
            let mut block = vec![];
            flate2::read::ZlibDecoder::new(&data[at..at + len])
                .read_to_end(&mut block)
                .unwrap();
            let expected = if b + 1 == blocks && last != 0 { last } else { size };
            assert_eq!(block.len(), expected, "block {b} of {blocks}");
            out.extend(block);
            at += len;
        }
        (out, at)
    }

    /// Every size around the block's: the header is VTK's (a full last block says 0) and the
    /// blocks inflate to the values' bytes.
    #[test]
    fn compressed_arrays_inflate_to_their_values() {
        for n in [
            1,
            7,
            BLOCK / 8 - 1,
            BLOCK / 8,
            BLOCK / 8 + 1,
            3 * BLOCK / 8,
            5 * BLOCK / 8 + 3,
        ] {
            let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
            let data: Vec<u8> = compressed(Values::F64(&v)).pieces().flatten().copied().collect();
            let (bytes, used) = inflate(&data);
            assert_eq!(used, data.len());
            let back: Vec<f64> = bytes
                .chunks(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect();
            assert_eq!(back, v, "{n} values");
        }
    }

    /// Stored zlib streams are zlib's (flate2 and miniz_oxide inflate them, checksum checked)
    /// at every length about a stored block's limit, and a block is deflated or stored by its
    /// zero bytes, either way inflating to itself.
    #[test]
    fn stored_and_deflated_blocks_inflate_to_their_bytes() {
        use std::io::Read;
        let mut x = 1u64;
        let mut random = move || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 33) as u8 | 1
        };
        for n in [0, 1, 65_534, 65_535, 65_536, 2 * 65_535 + 7, BLOCK] {
            let bytes: Vec<u8> = (0..n).map(|_| random()).collect();
            let z = stored_zlib(&bytes);
            let mut back = vec![];
            flate2::read::ZlibDecoder::new(&z[..]).read_to_end(&mut back).unwrap();
            assert_eq!(back, bytes, "{n} bytes");
            let mut corrupt = z.clone();
            if let Some(last) = corrupt.last_mut() {
                *last ^= 1;
                let mut out = vec![];
                assert!(flate2::read::ZlibDecoder::new(&corrupt[..])
                    .read_to_end(&mut out)
                    .is_err());
            }
        }
        let some_zeros: Vec<u8> = (0..BLOCK).map(|i| if i % 3 == 0 { 0 } else { random() }).collect();
        let mostly_zeros: Vec<u8> = (0..BLOCK).map(|i| if i % 3 == 0 { random() } else { 0 }).collect();
        for (bytes, deflated) in [(&some_zeros, false), (&mostly_zeros, true)] {
            let z = zlib_block(bytes);
            assert_eq!(z.len() < bytes.len() * 9 / 10, deflated);
            let mut back = vec![];
            flate2::read::ZlibDecoder::new(&z[..]).read_to_end(&mut back).unwrap();
            assert_eq!(&back, bytes);
        }
    }

    /// A compressed file's offsets point at each array's data in the appended section, in the
    /// order of the tags, and the data are the arrays'.
    #[test]
    fn a_compressed_file_s_offsets_find_its_arrays() {
        let points: Vec<f64> = (0..3 * 40).map(|i| i as f64 * 0.25).collect();
        let connectivity: Vec<u64> = (0..4 * 30).map(|i| (i % 40) as u64).collect();
        let offsets: Vec<u64> = (1..=30).map(|c| 4 * c as u64).collect();
        let mesh = CompressedMesh::new(&points, (&connectivity, &offsets), CellType::Tetra);
        let u: Vec<f64> = (0..3 * 40).map(|i| -(i as f64)).collect();
        let stress: Vec<f64> = (0..6 * 30).map(|i| i as f64 * 1e3).collect();
        let point = [Array {
            name: "u",
            components: 3,
            values: Values::F64(&u),
        }];
        let cell = [Array {
            name: "stress",
            components: 6,
            values: Values::F64(&stress),
        }];
        let file = write_compressed(&mesh, &point, &cell).to_bytes();
        let text = String::from_utf8_lossy(&file);
        let marker = b"<AppendedData encoding=\"raw\">\n_";
        let start = file.windows(marker.len()).position(|w| w == marker).unwrap() + marker.len();
        let offsets_found: Vec<usize> = text
            .split("offset=\"")
            .skip(1)
            .map(|s| s[..s.find('"').unwrap()].parse().unwrap())
            .collect();
        let f64s =
            |b: Vec<u8>| -> Vec<f64> { b.chunks(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect() };
        let u64s =
            |b: Vec<u8>| -> Vec<u64> { b.chunks(8).map(|c| u64::from_le_bytes(c.try_into().unwrap())).collect() };
        let at = |k: usize| inflate(&file[start + offsets_found[k]..]).0;
        assert_eq!(offsets_found.len(), 6);
        assert_eq!(f64s(at(0)), u);
        assert_eq!(f64s(at(1)), stress);
        assert_eq!(f64s(at(2)), points);
        assert_eq!(u64s(at(3)), connectivity);
        assert_eq!(u64s(at(4)), offsets);
        assert_eq!(at(5), vec![CellType::Tetra as u8; 30]);
        assert!(text.contains("compressor=\"vtkZLibDataCompressor\"") && text.contains("NumberOfCells=\"30\""));
        assert!(text.ends_with("</AppendedData>\n</VTKFile>\n"));
    }

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
