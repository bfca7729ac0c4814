//! The Gmsh MSH 4.1 reader, ASCII and binary, in every form Gmsh writes: any whitespace and
//! either line end (CR LF or LF), a `size_t` of 8 or 4 bytes in either byte order, partitioned
//! files (`$PartitionedEntities`, ghost cells), parametric nodes, every element saved
//! (`Mesh.SaveAll`), periodic meshes, post-processing data and sections of other programs
//! after the mesh (passed over, as Gmsh does).
//!
//! Physical groups of dimension `dim - 1` become facet groups (on the boundary, or inside: a
//! material interface or an internal electrode), and those of dimension `dim` become regions,
//! named by their physical name (or by their tag where unnamed). Every cell also belongs to
//! the region `body`, unless the file names a group `body` itself. Elements of lower
//! dimensions (points, and curves of a 3D mesh) are not used.
//!
//! Node tags: a `$Nodes` block may list its tags in any order; every node keeps the tag the
//! file gives it, and the mesh's nodes are the file's in its order. Nodes that no cell uses
//! (the centre of a circle arc, a point of the geometry outside the body) are kept: they carry
//! no unknown, and [`Mesh::check`] counts them.
//!
//! Orientation: the cells of a 2D entity block that are all negatively oriented (a surface whose
//! normal is `-z`, which Gmsh writes when a surface is defined clockwise) are turned round, and
//! counted in [`Mesh::reoriented_cells`]; a 3D mesh whose tetrahedra are all inverted is refused
//! (Gmsh writes positive ones: such a file is mirrored or misread). A block with cells of both
//! orientations is left as it is, and [`Mesh::check`] then reports the inverted cells.

mod cursor;
mod part;
mod sections;

pub use part::{parts_of, read_msh_part, MshPart};

use crate::{CellKind, FacetGroup, Mesh, MeshError};
use sections::{type_name, File};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Reads a Gmsh MSH 4.1 file (ASCII or binary) and checks it with [`Mesh::check`]. A path
/// that is not a regular file (a FIFO, a device, a directory) is refused before it is opened
/// for reading: reading it could block for ever.
pub fn read_msh(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
    let path = path.as_ref();
    let io = |message: String| MeshError::Io {
        path: path.display().to_string(),
        message,
    };
    let meta = std::fs::metadata(path).map_err(|e| {
        let parts = part::parts_of(path);
        match (e.kind(), parts.first(), parts.last()) {
            (std::io::ErrorKind::NotFound, Some(first), Some(last)) => io(format!(
                "does not exist, but {} .. {} are its parts (a mesh Gmsh split into {} files): run on {} ranks of the PETSc backend (solver.backend = \"petsc\", mpirun -np {}), each of which reads its part, or save the mesh whole",
                first.display(),
                last.display(),
                parts.len(),
                parts.len(),
                parts.len()
            )),
            _ => io(e.to_string()),
        }
    })?;
    if !meta.is_file() {
        return Err(io("is not a regular file (a directory, a FIFO or a device)".into()));
    }
    let bytes = std::fs::read(path).map_err(|e| io(e.to_string()))?;
    read_msh_bytes(&bytes, &path.display().to_string())
}

/// Reads the bytes of a Gmsh MSH 4.1 file; `name` is used in error messages.
pub fn read_msh_bytes(bytes: &[u8], name: &str) -> Result<Mesh, MeshError> {
    let err = |message: String| MeshError::Gmsh {
        path: name.to_string(),
        message,
    };
    let file = sections::read(bytes).map_err(err)?;
    whole_partitions(&file).map_err(err)?;
    let mut mesh = build(&file, false).map_err(err)?;
    flatten_2d(&mut mesh).map_err(err)?;
    mesh.check().map_err(|e| err(format!("{e}")))?;
    Ok(mesh)
}

/// The names of the groups of entity `(d, tag)` (a group's tag where it has no name).
fn groups_of(file: &File, d: i32, tag: i32) -> Vec<String> {
    let name = |p: i32| file.names.get(&(d, p)).cloned().unwrap_or_else(|| p.to_string());
    let mut out: Vec<String> = file
        .physical
        .get(&(d, tag))
        .into_iter()
        .flatten()
        .map(|&p| name(p))
        .collect();
    out.sort();
    out.dedup();
    out
}

/// The dimension of the file's cells: the highest of its elements', 2 or 3.
fn cell_dim(file: &File) -> Result<i32, String> {
    let dim = file
        .elements
        .iter()
        .filter(|b| !b.tags.is_empty())
        .map(|b| b.dim)
        .max()
        .ok_or("the file has no elements")?;
    if !(2..=3).contains(&dim) {
        return Err(format!(
            "the highest element dimension is {dim}; a 2D or 3D mesh is needed"
        ));
    }
    Ok(dim)
}

/// The blocks of cells of dimension `dim`: the file's own, then (with `ghosts`) those on
/// ghost entities, which hold other partitions' cells in a part of a split mesh.
fn cell_blocks(file: &File, dim: i32, ghosts: bool) -> Vec<&sections::ElementBlock> {
    let cells = file.elements.iter().filter(|b| b.dim == dim && !b.tags.is_empty());
    let on_ghost = |b: &&sections::ElementBlock| file.ghost_entities.contains_key(&b.entity);
    let own = cells.clone().filter(|b| !on_ghost(b));
    let ghost = cells.filter(on_ghost).filter(|_| ghosts);
    own.chain(ghost).collect()
}

/// The partitions whose cells a partitioned file holds, and the partitions in all (`0` for a
/// file that is not partitioned).
fn partitions_held(file: &File) -> Result<(Vec<i32>, u64), String> {
    let dim = cell_dim(file)?;
    let mut held: Vec<i32> = cell_blocks(file, dim, false)
        .iter()
        .filter_map(|b| file.entity_partitions.get(&(dim, b.entity)))
        .flatten()
        .copied()
        .collect();
    held.sort_unstable();
    held.dedup();
    Ok((held, file.partitions))
}

/// Refuses a part of a mesh Gmsh split into files (`Mesh.PartitionSplitMeshFiles = 1`) read
/// as a whole mesh: it holds one partition's cells and a layer of its neighbours', a piece of
/// the body that would be solved as if it were the body.
fn whole_partitions(file: &File) -> Result<(), String> {
    let (held, partitions) = partitions_held(file)?;
    if partitions > 1 && (held.len() as u64) < partitions {
        let which = held.iter().map(i32::to_string).collect::<Vec<_>>().join(", ");
        return Err(format!(
            "the file is part {which} of a mesh that Gmsh split into {partitions} files (Mesh.PartitionSplitMeshFiles = 1): alone it is a piece of the body. Name the mesh saved whole, or name the parts' common stem (`mesh.msh` for `mesh_1.msh` .. `mesh_{partitions}.msh`) and run on {partitions} ranks of the PETSc backend, each of which reads its part"
        ));
    }
    Ok(())
}

/// The mesh of the file's sections: cells of the highest dimension present (one kind, each
/// block turned round where all its cells are negatively oriented) with their regions, facets
/// one dimension lower in their groups. With `ghosts`, the cells on ghost entities follow
/// the file's own (a part of a split mesh); without, they are left out.
fn build(file: &File, ghosts: bool) -> Result<Mesh, String> {
    let dim = cell_dim(file)?;
    let (coords, index_of) = node_table(file)?;
    // the cells first (a second-order mesh is named by its cells, not its facets)
    let mut kind: Option<CellKind> = None;
    let mut cell_tags: Vec<u64> = vec![];
    let mut blocks = vec![];
    let mut regions: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let cell_blocks = cell_blocks(file, dim, ghosts);
    for &block in &cell_blocks {
        let k = cell_kind(block.element_type, dim, kind)?;
        kind = Some(k);
        let first = cell_tags.len() / k.n_nodes();
        cell_tags.extend_from_slice(&block.nodes);
        let last = cell_tags.len() / k.n_nodes();
        blocks.push((first, last));
        for g in groups_of(file, dim, block.entity) {
            regions.entry(g).or_default().extend(first..last);
        }
    }
    let kind = kind.ok_or_else(|| format!("no {dim}D cells"))?;
    let mut cells: Vec<usize> = cell_tags
        .chunks_exact(kind.n_nodes())
        .zip(cell_blocks.iter().flat_map(|b| b.tags.iter().copied()))
        .flat_map(|(c, e)| c.iter().map(move |&t| (t, e)))
        .map(|(t, e)| node_index(&index_of, t, e))
        .collect::<Result<_, _>>()?;
    from_gmsh_order(kind, &mut cells);
    let mut reoriented = 0;
    for &(first, last) in &blocks {
        reoriented += orient_block(&coords, &mut cells, kind, first, last);
    }
    let n_cells = cells.len() / kind.n_nodes();
    if kind.dim() == 3 && reoriented == n_cells {
        return Err(format!(
            "all {n_cells} tetrahedra are inverted (negative volume): Gmsh writes them positive, so the file is mirrored or its nodes are misnumbered"
        ));
    }
    let facets = facet_groups(file, kind, &index_of)?;
    for v in regions.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    regions.entry("body".into()).or_insert_with(|| (0..n_cells).collect());
    Ok(Mesh {
        dim: dim as usize,
        kind,
        points: coords,
        cells,
        other_groups: other_groups(file, dim),
        boundaries: facets,
        regions,
        reoriented_cells: reoriented,
    })
}

/// The file's named groups below the facets' dimension (points, curves of a 3D mesh), with
/// their dimension ([`Mesh::other_groups`]).
fn other_groups(file: &File, dim: i32) -> BTreeMap<String, usize> {
    file.names
        .iter()
        .filter(|((d, _), _)| *d < dim - 1)
        .map(|((d, _), name)| (name.clone(), *d as usize))
        .collect()
}

/// The index of node tag `tag`, named by element `elem` where the file lacks it.
fn node_index(index_of: &HashMap<u64, usize>, tag: u64, elem: u64) -> Result<usize, String> {
    index_of
        .get(&tag)
        .copied()
        .ok_or_else(|| format!("element {elem} refers to node tag {tag}, which the file does not define"))
}

/// Coordinates in block order, and the index of each node tag.
type NodeTable = (Vec<[f64; 3]>, HashMap<u64, usize>);

/// The coordinates of every node in block order, and the index of each node tag.
fn node_table(file: &File) -> Result<NodeTable, String> {
    let total: usize = file.nodes.iter().map(|b| b.tags.len()).sum();
    let mut index_of = HashMap::with_capacity(total);
    let mut coords = Vec::with_capacity(total);
    for block in &file.nodes {
        for (&tag, x) in block.tags.iter().zip(&block.coords) {
            if index_of.insert(tag, coords.len()).is_some() {
                return Err(format!("node tag {tag} is defined twice"));
            }
            coords.push(*x);
        }
    }
    Ok((coords, index_of))
}

/// The facet groups: the elements one dimension below the cells in each physical group (a
/// segment in 2D, a triangle in 3D, of the cells' order), on the boundary or inside.
fn facet_groups(
    file: &File,
    kind: CellKind,
    index_of: &HashMap<u64, usize>,
) -> Result<BTreeMap<String, FacetGroup>, String> {
    let dim = kind.dim() as i32;
    let mut out: BTreeMap<String, FacetGroup> = BTreeMap::new();
    for block in file.elements.iter().filter(|b| b.dim == dim - 1) {
        let names = groups_of(file, dim - 1, block.entity);
        if names.is_empty() || block.tags.is_empty() {
            continue; // elements in no group (Mesh.SaveAll) are not used
        }
        let facet_type = facet_type(kind);
        if block.element_type != facet_type {
            return Err(format!(
                "group `{}` holds {} elements: the facets of a {dim}D mesh of {} cells are {}",
                names[0],
                type_name(block.element_type),
                kind.name(),
                type_name(facet_type)
            ));
        }
        let mut facets = Vec::with_capacity(block.nodes.len());
        for (e, nodes) in block.tags.iter().zip(block.nodes.chunks_exact(block.per)) {
            for &t in nodes {
                facets.push(node_index(index_of, t, *e)?);
            }
        }
        for g in names {
            let group = out.entry(g).or_insert_with(|| FacetGroup {
                nodes_per_facet: kind.facet_n_nodes(),
                facets: vec![],
            });
            group.facets.extend_from_slice(&facets);
        }
    }
    Ok(out)
}

/// The cell kind of a block of the mesh's dimension, which must match the kind so far.
fn cell_kind(t: i32, dim: i32, so_far: Option<CellKind>) -> Result<CellKind, String> {
    let k = match t {
        2 => CellKind::Tri3,
        3 => CellKind::Quad4,
        4 => CellKind::Tet4,
        9 => CellKind::Tri6,
        11 => CellKind::Tet10,
        _ => {
            let hint = match t {
                10 | 16 => " (second-order quadrilaterals: mesh with triangles, Mesh.RecombineAll = 0, or at Mesh.ElementOrder = 1)",
                20..=31 => " (third- and higher-order elements: mesh with Mesh.ElementOrder = 1 or 2)",
                _ => "",
            };
            return Err(format!(
                "{} cells are not supported: cells must be 3- or 6-node triangles, 4-node quadrilaterals or 4- or 10-node tetrahedra{hint}",
                type_name(t)
            ));
        }
    };
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

/// Gmsh's type of the facets of a mesh of `kind`: a 2- or 3-node line in 2D, a 3- or 6-node
/// triangle in 3D.
fn facet_type(kind: CellKind) -> i32 {
    match kind {
        CellKind::Tri3 | CellKind::Quad4 => 1,
        CellKind::Tet4 => 2,
        CellKind::Tri6 => 8,
        CellKind::Tet10 => 9,
    }
}

/// A cell's nodes as Gmsh lists them, in this crate's (VTK's) order: the ten-node
/// tetrahedron's last two edge nodes (edges 2-3 and 1-3 in Gmsh, 1-3 and 2-3 here) swap.
fn from_gmsh_order(kind: CellKind, cells: &mut [usize]) {
    if kind == CellKind::Tet10 {
        for c in cells.chunks_exact_mut(10) {
            c.swap(8, 9);
        }
    }
}

/// A 2D mesh must lie in a plane `z = const`; it is put at `z = 0`. One off that plane is told
/// apart: flat in another plane (drawn in the x-z plane, say), or not flat at all (the surface
/// of a 3D body saved without its volume cells).
fn flatten_2d(mesh: &mut Mesh) -> Result<(), String> {
    if mesh.dim != 2 {
        return Ok(());
    }
    let z0 = mesh.points.first().map_or(0.0, |p| p[2]);
    if let Some((i, p)) = mesh.points.iter().enumerate().find(|(_, p)| p[2] != z0) {
        let at = format!("node {i} has z = {}, node 0 z = {z0}", p[2]);
        return Err(match plane_normal(&mesh.points) {
            Some(n) => format!(
                "a 2D mesh lies in a plane z = const, and this one lies in the plane of normal \
                 [{:.3}, {:.3}, {:.3}] ({at}): draw the 2D body in the x-y plane",
                n[0], n[1], n[2]
            ),
            None => format!(
                "the file's cells of highest dimension are 2D ({}), and they do not lie in one \
                 plane ({at}): a surface, not a body. A 3D body needs its volume cells: Gmsh \
                 writes only the elements of physical groups, so give the volume one (Physical \
                 Volume, gmsh.model.addPhysicalGroup(3, ...)) or set Mesh.SaveAll = 1",
                mesh.kind.name()
            ),
        });
    }
    for p in &mut mesh.points {
        p[2] = 0.0;
    }
    Ok(())
}

/// The unit normal of the plane all `points` lie in (within 1e-9 of their extent), `None`
/// where they do not lie in one.
fn plane_normal(points: &[[f64; 3]]) -> Option<[f64; 3]> {
    let sub = |a: &[f64; 3], b: &[f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let o = points.first()?;
    // the largest normal of a triangle (o, a, b) over the points: the best conditioned plane
    let far = points
        .iter()
        .max_by(|a, b| dot(&sub(a, o), &sub(a, o)).total_cmp(&dot(&sub(b, o), &sub(b, o))))?;
    let u = sub(far, o);
    // the points' extent from `o`: the distance to the farthest
    let extent = dot(&u, &u).sqrt();
    let cross = |v: &[f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let normal = points
        .iter()
        .map(|p| cross(&sub(p, o)))
        .max_by(|a, b| dot(a, a).total_cmp(&dot(b, b)))?;
    let size = dot(&normal, &normal).sqrt();
    if !(size > 0.0) || !(extent > 0.0) {
        return None;
    }
    let n = normal.map(|c| c / size);
    let flat = points.iter().all(|p| dot(&sub(p, o), &n).abs() <= 1e-9 * extent);
    flat.then_some(n)
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
            CellKind::Tet4 | CellKind::Tet10 => crate::generate::signed_volume(points, c),
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
            // the corners 1 and 2 swapped: the edges 0-1 and 2-0 swap, 1-2 stays
            CellKind::Tri6 => {
                c.swap(1, 2);
                c.swap(3, 5);
            }
            // and in a tetrahedron the edges 1-3 and 2-3 swap too
            CellKind::Tet10 => {
                c.swap(1, 2);
                c.swap(4, 6);
                c.swap(8, 9);
            }
            _ => c.swap(1, 2),
        }
    }
    last - first
}
