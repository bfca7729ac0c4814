//! The Gmsh MSH 4.1 reader (ASCII and binary).
//!
//! The body of the file is parsed by `mshio`; `$PhysicalNames`, which `mshio` skips, is read
//! here. Physical groups of dimension `dim - 1` become boundary groups and those of dimension
//! `dim` become regions, named by their physical name (or by their tag where unnamed). Every
//! cell also belongs to the region `body`, unless the file names a group `body` itself.
//!
//! Node tags: MSH 4.1 lets a `$Nodes` block list its tags in any order. Where the tags are dense
//! (`max - min + 1 == count`) `mshio` does not keep them, so they are read here
//! ([`node_tags`]), in ASCII and binary, and every node keeps the tag the file gives it.
//!
//! Orientation: the cells of a 2D entity block that are all negatively oriented (a surface whose
//! normal is `-z`, which Gmsh writes when a surface is defined clockwise) are turned round, and
//! counted in [`Mesh::reoriented_cells`]; a 3D mesh whose tetrahedra are all inverted is refused
//! (Gmsh writes positive ones: such a file is mirrored or misread). A block with cells of both
//! orientations is left as it is, and [`Mesh::check`] then reports the inverted cells.

use crate::{CellKind, FacetGroup, Mesh, MeshError};
use mshio::mshfile::ElementType;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Reads a Gmsh MSH 4.1 file (ASCII or binary) and checks it with [`Mesh::check`].
pub fn read_msh(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| MeshError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    read_msh_bytes(&bytes, &path.display().to_string())
}

/// Checks the `$MeshFormat` line: version 4.1, file type 0 (ASCII) or 1 (binary), and a data
/// size of 8 (the only size Gmsh writes, and the only one the body parser reads).
fn format_header(bytes: &[u8]) -> Result<(), String> {
    let line = bytes
        .split(|&b| b == b'\n')
        .nth(1)
        .map(|l| String::from_utf8_lossy(l).trim().to_string())
        .unwrap_or_default();
    let fields: Vec<&str> = line.split_whitespace().collect();
    match fields.as_slice() {
        [version, kind, size] => {
            if *version != "4.1" {
                return Err(format!(
                    "MSH version `{version}` is not supported (only 4.1; Gmsh: -format msh41)"
                ));
            }
            if !["0", "1"].contains(kind) {
                return Err(format!(
                    "file type `{kind}` in `$MeshFormat` is neither 0 (ASCII) nor 1 (binary)"
                ));
            }
            if *size != "8" {
                return Err(format!("data size `{size}` in `$MeshFormat` is not 8"));
            }
            Ok(())
        }
        _ => Err(format!(
            "the `$MeshFormat` line `{line}` is not `version file-type data-size`"
        )),
    }
}

/// Reads the bytes of a Gmsh MSH 4.1 file; `name` is used in error messages.
pub fn read_msh_bytes(bytes: &[u8], name: &str) -> Result<Mesh, MeshError> {
    let err = |message: String| MeshError::Gmsh {
        path: name.to_string(),
        message,
    };
    let data = parse(bytes).map_err(err)?;
    let names = physical_names(bytes).map_err(err)?;
    let entities = data
        .entities
        .ok_or_else(|| err("the file has no `$Entities` section".into()))?;
    let nodes = data
        .nodes
        .ok_or_else(|| err("the file has no `$Nodes` section".into()))?;
    let elements = data
        .elements
        .ok_or_else(|| err("the file has no `$Elements` section".into()))?;
    let (points, index_of) = read_nodes(bytes, &nodes).map_err(err)?;
    let groups = Groups {
        physical: physical_tags(&entities),
        names,
    };
    let mut mesh = read_elements(&elements, points, &index_of, &groups).map_err(err)?;
    flatten_2d(&mut mesh).map_err(err)?;
    mesh.check().map_err(|e| err(format!("{e}")))?;
    Ok(mesh)
}

type Parsed = mshio::MshData<u64, i32, f64>;

/// Checks the `$MeshFormat` line and parses the body with `mshio`.
fn parse(bytes: &[u8]) -> Result<Parsed, String> {
    if !bytes.starts_with(b"$MeshFormat") {
        return Err("not a Gmsh file: it does not start with `$MeshFormat`".into());
    }
    format_header(bytes)?;
    // mshio answers most malformed input with an error, but a few inputs reach an
    // `unimplemented!` in it (found by the mutation fuzzing of driver/tests/fuzz_readers.rs):
    // those become an error too
    let parsed = std::panic::catch_unwind(|| mshio::parse_msh_bytes(bytes))
        .map_err(|_| "does not parse as MSH 4.1 (the parser gave up on malformed data)".to_string())?;
    let file = parsed.map_err(|e| {
        let text = e.to_string();
        let first = text.lines().take(6).collect::<Vec<_>>().join("; ");
        format!("does not parse as MSH 4.1: {first}")
    })?;
    Ok(file.data)
}

/// The physical tags of each entity, by `(dimension, entity tag)`.
fn physical_tags(entities: &mshio::Entities<i32, f64>) -> HashMap<(i32, i32), Vec<i32>> {
    let mut phys = HashMap::new();
    for p in &entities.points {
        phys.insert((0, p.tag), p.physical_tags.clone());
    }
    for c in &entities.curves {
        phys.insert((1, c.tag), c.physical_tags.clone());
    }
    for s in &entities.surfaces {
        phys.insert((2, s.tag), s.physical_tags.clone());
    }
    for v in &entities.volumes {
        phys.insert((3, v.tag), v.physical_tags.clone());
    }
    phys
}

/// Coordinates in block order, and the index of each node tag.
type NodeTable = (Vec<[f64; 3]>, HashMap<u64, usize>);

/// The nodes' coordinates in block order, and the index of each node tag.
fn read_nodes(bytes: &[u8], nodes: &mshio::Nodes<u64, i32, f64>) -> Result<NodeTable, String> {
    let held: usize = nodes.node_blocks.iter().map(|b| b.nodes.len()).sum();
    if held as u64 != nodes.num_nodes {
        return Err(format!(
            "the $Nodes header declares {} nodes but its blocks hold {held}",
            nodes.num_nodes
        ));
    }
    let tags = node_tags(bytes)?;
    if tags.len() != held {
        return Err(format!(
            "the $Nodes blocks hold {held} nodes but {} node tags",
            tags.len()
        ));
    }
    let mut index_of: HashMap<u64, usize> = HashMap::with_capacity(held);
    for (k, &tag) in tags.iter().enumerate() {
        if index_of.insert(tag, k).is_some() {
            return Err(format!("node tag {tag} is defined twice"));
        }
    }
    let mut points: Vec<[f64; 3]> = Vec::with_capacity(held);
    for block in &nodes.node_blocks {
        points.extend(block.nodes.iter().map(|n| [n.x, n.y, n.z]));
    }
    Ok((points, index_of))
}

/// The physical groups of the file: the tags of each entity and their names.
struct Groups {
    physical: HashMap<(i32, i32), Vec<i32>>,
    names: HashMap<(i32, i32), String>,
}

impl Groups {
    /// The names of the groups of entity `(d, tag)` (a group's tag where it has no name).
    fn of(&self, d: i32, tag: i32) -> Vec<String> {
        let name = |p: i32| self.names.get(&(d, p)).cloned().unwrap_or_else(|| p.to_string());
        self.physical
            .get(&(d, tag))
            .into_iter()
            .flatten()
            .map(|&p| name(p))
            .collect()
    }
}

/// The cell kind of a supported element type.
fn kind_of(t: ElementType) -> Option<CellKind> {
    match t {
        ElementType::Tri3 => Some(CellKind::Tri3),
        ElementType::Qua4 => Some(CellKind::Quad4),
        ElementType::Tet4 => Some(CellKind::Tet4),
        _ => None,
    }
}

/// The elements: cells of the highest dimension present (one kind, each block turned round
/// where all its cells are negatively oriented) with their regions, and facets one dimension
/// lower in their boundary groups.
fn read_elements(
    elements: &mshio::Elements<u64, i32>,
    points: Vec<[f64; 3]>,
    index_of: &HashMap<u64, usize>,
    groups: &Groups,
) -> Result<Mesh, String> {
    let dim = elements
        .element_blocks
        .iter()
        .map(|b| b.entity_dim)
        .max()
        .ok_or("the file has no elements")?;
    if !(2..=3).contains(&dim) {
        return Err(format!(
            "the highest element dimension is {dim}; a 2D or 3D mesh is needed"
        ));
    }
    let node_index = |tag: u64, elem: u64| {
        index_of
            .get(&tag)
            .copied()
            .ok_or_else(|| format!("element {elem} refers to node tag {tag}, which the file does not define"))
    };
    let nodes_of = |block: &mshio::ElementBlock<u64, i32>, per: usize| -> Result<Vec<usize>, String> {
        let mut out = Vec::with_capacity(block.elements.len() * per);
        for e in &block.elements {
            if e.nodes.len() != per {
                return Err(format!("element {} has {} nodes", e.element_tag, e.nodes.len()));
            }
            for &t in &e.nodes {
                out.push(node_index(t, e.element_tag)?);
            }
        }
        Ok(out)
    };
    let mut kind: Option<CellKind> = None;
    let (mut cells, mut reoriented) = (Vec::new(), 0);
    let mut regions: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let mut boundaries: BTreeMap<String, FacetGroup> = BTreeMap::new();
    for block in &elements.element_blocks {
        let d = block.entity_dim;
        if d == dim {
            let k = cell_kind(block.element_type, dim, kind)?;
            kind = Some(k);
            let first = cells.len() / k.n_nodes();
            cells.extend(nodes_of(block, k.n_nodes())?);
            let last = cells.len() / k.n_nodes();
            reoriented += orient_block(&points, &mut cells, k, first, last);
            for g in groups.of(d, block.entity_tag) {
                regions.entry(g).or_default().extend(first..last);
            }
        } else if d == dim - 1 {
            if !matches!(
                (dim, block.element_type),
                (2, ElementType::Lin2) | (3, ElementType::Tri3)
            ) {
                return Err(format!(
                    "boundary element type {:?} is not supported in a {dim}D mesh",
                    block.element_type
                ));
            }
            let per = dim as usize;
            let facets = nodes_of(block, per)?;
            for g in groups.of(d, block.entity_tag) {
                let group = boundaries.entry(g).or_insert_with(|| FacetGroup {
                    nodes_per_facet: per,
                    facets: vec![],
                });
                group.facets.extend_from_slice(&facets);
            }
        }
    }
    let kind = kind.ok_or_else(|| format!("no {dim}D cells"))?;
    let n_cells = cells.len() / kind.n_nodes();
    if kind == CellKind::Tet4 && reoriented == n_cells {
        return Err(format!(
            "all {n_cells} tetrahedra are inverted (negative volume): Gmsh writes them positive, so the file is mirrored or its nodes are misnumbered"
        ));
    }
    for v in regions.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    regions.entry("body".into()).or_insert_with(|| (0..n_cells).collect());
    Ok(Mesh {
        dim: dim as usize,
        kind,
        points,
        cells,
        boundaries,
        regions,
        reoriented_cells: reoriented,
    })
}

/// The cell kind of a block of the mesh's dimension, which must match the kind so far.
fn cell_kind(t: ElementType, dim: i32, so_far: Option<CellKind>) -> Result<CellKind, String> {
    let k = kind_of(t).ok_or_else(|| {
        format!("element type {t:?} is not supported: cells must be 3-node triangles, 4-node quadrilaterals or 4-node tetrahedra")
    })?;
    if k.dim() != dim as usize {
        return Err(format!("{} cells in a {dim}D mesh", k.name()));
    }
    match so_far {
        Some(k0) if k0 != k => Err(format!(
            "mixed cell kinds ({} and {}): one kind per mesh",
            k0.name(),
            k.name()
        )),
        _ => Ok(k),
    }
}

/// A 2D mesh must lie in a plane `z = const`; it is put at `z = 0`.
fn flatten_2d(mesh: &mut Mesh) -> Result<(), String> {
    if mesh.dim != 2 {
        return Ok(());
    }
    let z0 = mesh.points.first().map_or(0.0, |p| p[2]);
    if let Some((i, p)) = mesh.points.iter().enumerate().find(|(_, p)| p[2] != z0) {
        return Err(format!(
            "a 2D mesh must lie in a plane z = const; node {i} has z = {} (node 0: {z0})",
            p[2]
        ));
    }
    for p in &mut mesh.points {
        p[2] = 0.0;
    }
    Ok(())
}

/// Turns round every cell of `first..last` when all of them are negatively oriented; returns
/// how many were turned.
pub(crate) fn orient_block(
    points: &[[f64; 3]],
    cells: &mut [usize],
    kind: CellKind,
    first: usize,
    last: usize,
) -> usize {
    let k = kind.n_nodes();
    let sign = |c: &[usize]| -> f64 {
        match kind {
            CellKind::Tet4 => crate::generate::signed_volume(points, c),
            _ => {
                let (a, b, cc) = (points[c[0]], points[c[1]], points[c[2]]);
                (b[0] - a[0]) * (cc[1] - a[1]) - (cc[0] - a[0]) * (b[1] - a[1])
            }
        }
    };
    let block = &mut cells[first * k..last * k];
    if block.is_empty() || !block.chunks_exact(k).all(|c| sign(c) < 0.0) {
        return 0;
    }
    for c in block.chunks_exact_mut(k) {
        match kind {
            CellKind::Quad4 => c.swap(1, 3),
            _ => c.swap(1, 2),
        }
    }
    last - first
}

/// The node tags of the `$Nodes` section, in the order of its blocks (ASCII or binary, as the
/// `$MeshFormat` line says; binary in either byte order, as the one written after it says).
pub(crate) fn node_tags(bytes: &[u8]) -> Result<Vec<u64>, String> {
    let binary = bytes
        .split(|&b| b == b'\n')
        .nth(1)
        .is_some_and(|l| l.split(|&b| b == b' ').nth(1) == Some(b"1"));
    // the section follows `$EndEntities` (binary data before it could hold any bytes)
    let from = find(bytes, b"$EndEntities").unwrap_or(0);
    let start = find(&bytes[from..], b"$Nodes\n").ok_or("no `$Nodes` section")? + from + 7;
    if binary {
        // the int 1 written right after the `$MeshFormat` line tells the byte order
        let after_header = bytes
            .iter()
            .enumerate()
            .filter(|(_, &b)| b == b'\n')
            .nth(1)
            .map_or(0, |(i, _)| i + 1);
        let big = bytes.get(after_header..after_header + 4) == Some(&1i32.to_be_bytes()[..]);
        binary_node_tags(&bytes[start..], !big)
    } else {
        let end = find(&bytes[start..], b"$EndNodes").ok_or("`$Nodes` has no `$EndNodes`")? + start;
        let text = std::str::from_utf8(&bytes[start..end]).map_err(|_| "`$Nodes` is not text")?;
        ascii_node_tags(text)
    }
}

/// The next token of `$Nodes`, named `what` in the error where there is none.
fn token<'t>(tokens: &mut impl Iterator<Item = &'t str>, what: &str) -> Result<&'t str, String> {
    tokens.next().ok_or_else(|| format!("`$Nodes`: {what} is missing"))
}

/// The next token of `$Nodes` as a whole number.
fn whole<'t>(tokens: &mut impl Iterator<Item = &'t str>, what: &str) -> Result<u64, String> {
    let t = token(tokens, what)?;
    t.parse::<u64>()
        .map_err(|_| format!("`$Nodes`: {what} `{t}` is not a whole number"))
}

fn ascii_node_tags(text: &str) -> Result<Vec<u64>, String> {
    let mut t = text.split_ascii_whitespace();
    let blocks = whole(&mut t, "the block count")?;
    for what in ["the node count", "the smallest tag", "the largest tag"] {
        whole(&mut t, what)?;
    }
    let mut tags = vec![];
    for _ in 0..blocks {
        let dim = whole(&mut t, "a block's dimension")?;
        whole(&mut t, "a block's entity")?;
        let parametric = whole(&mut t, "a block's parametric flag")?;
        let n = whole(&mut t, "a block's node count")?;
        for _ in 0..n {
            tags.push(whole(&mut t, "a node tag")?);
        }
        // the coordinates: x y z, and the parametric ones
        let per_node = 3 + if parametric == 1 { dim } else { 0 };
        for _ in 0..n.saturating_mul(per_node) {
            token(&mut t, "a coordinate")?;
        }
    }
    Ok(tags)
}

fn binary_node_tags(data: &[u8], little: bool) -> Result<Vec<u64>, String> {
    let mut at = 0usize;
    let mut take = |n: usize| -> Result<&[u8], String> {
        let s = data.get(at..at + n).ok_or("`$Nodes` is cut short")?;
        at += n;
        Ok(s)
    };
    let word = |b: &[u8]| -> u64 {
        let a: [u8; 8] = b.try_into().unwrap_or_default();
        if little {
            u64::from_le_bytes(a)
        } else {
            u64::from_be_bytes(a)
        }
    };
    let int = |b: &[u8]| -> i32 {
        let a: [u8; 4] = b.try_into().unwrap_or_default();
        if little {
            i32::from_le_bytes(a)
        } else {
            i32::from_be_bytes(a)
        }
    };
    let blocks = word(take(8)?);
    take(24)?; // the node count, the smallest and the largest tag
    let mut tags = vec![];
    for _ in 0..blocks {
        let dim = int(take(4)?);
        take(4)?; // the entity tag
        let parametric = int(take(4)?);
        let n = usize::try_from(word(take(8)?)).map_err(|_| "`$Nodes`: a block's node count is too large")?;
        let tag_bytes = take(n.checked_mul(8).ok_or("`$Nodes`: a block's node count is too large")?)?;
        tags.extend(tag_bytes.chunks_exact(8).map(word));
        let per_node = 3 + if parametric == 1 { dim.max(0) as usize } else { 0 };
        take(n.saturating_mul(per_node).saturating_mul(8))?;
    }
    Ok(tags)
}

/// Reads `$PhysicalNames` (ASCII in both encodings): `(dim, tag) -> name`.
fn physical_names(bytes: &[u8]) -> Result<HashMap<(i32, i32), String>, String> {
    let mut out = HashMap::new();
    let Some(start) = find(bytes, b"$PhysicalNames") else {
        return Ok(out);
    };
    let rest = &bytes[start..];
    let end = find(rest, b"$EndPhysicalNames").ok_or("`$PhysicalNames` has no `$EndPhysicalNames`")?;
    let text = std::str::from_utf8(&rest[..end]).map_err(|_| "`$PhysicalNames` is not text")?;
    let mut lines = text.lines().skip(1).filter(|l| !l.trim().is_empty());
    let count: usize = lines
        .next()
        .and_then(|l| l.trim().parse().ok())
        .ok_or("`$PhysicalNames` does not start with a count")?;
    for (i, line) in lines.enumerate() {
        let mut parts = line.trim().splitn(3, char::is_whitespace);
        let bad = || format!("`$PhysicalNames` line {}: `{line}`", i + 2);
        let d: i32 = parts.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = parts.next().and_then(|s| s.trim().parse().ok()).ok_or_else(bad)?;
        let name = parts.next().ok_or_else(bad)?.trim().trim_matches('"').to_string();
        out.insert((d, tag), name);
    }
    if out.len() != count {
        return Err(format!(
            "`$PhysicalNames` announces {count} names and holds {}",
            out.len()
        ));
    }
    Ok(out)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}
