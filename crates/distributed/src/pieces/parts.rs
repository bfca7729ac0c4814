//! A Gmsh mesh read in parts: each rank reads the one file of its partition
//! ([`mesh::read_msh_part`]), the parts complete each other through a table over the element
//! tags spread across the ranks (a parallel vector: each rank holds `1/p` of it), and the
//! connected bodies of the whole mesh are found by labels passed between the pieces. No rank
//! reads or holds the whole mesh.

use crate::error::DistributedError;
use crate::layout::Layout;
use mesh::{MeshPiece, MshPart};
use petsc::{Petsc, Vector};
use problem::{ProblemError, SetupError};
use std::path::PathBuf;

/// This rank's piece of the mesh split into `parts` (one file per rank, in rank order), the
/// estimate of each rank's peak checked against `limits` before the set-up (the part read is a
/// few percent of it). Collective: a rank that cannot read its part makes every rank fail.
///
/// # Errors
/// A count of parts other than the ranks', a part of another partition or of another mesh,
/// the reader's errors, the estimate over the limit ([`ProblemError::TooLarge`], naming the
/// rank).
pub(super) fn read(petsc: &Petsc, parts: &[PathBuf], limits: problem::Limits) -> Result<MeshPiece, DistributedError> {
    let (rank, ranks) = (petsc.rank(), petsc.size());
    if parts.len() != ranks {
        return Err(mesh_file(format!(
            "the mesh is in {} parts ({} .. {}), one per rank: run on {} ranks (mpirun -np {})",
            parts.len(),
            name(parts.first()),
            name(parts.last()),
            parts.len(),
            parts.len()
        )));
    }
    let read = mesh::read_msh_part(&parts[rank]).map_err(ProblemError::from).and_then(|part| {
        if part.rank == rank && part.parts == ranks {
            return Ok(part);
        }
        Err(SetupError::new(
            "mesh.file",
            format!(
                "{} is part {} of {}, where rank {rank} of {ranks} reads part {} of {ranks}: the parts are not of one split",
                name(parts.get(rank)),
                part.rank + 1,
                part.parts,
                rank + 1
            ),
        )
        .into())
    });
    let part = agreed(petsc, read)?;
    same_groups(petsc, &part)?;
    check_memory(petsc, &part.mesh, limits)?;
    complete(petsc, part)
}

/// `result` where every rank has one; where some rank has an error, an error on every rank
/// (the rank's own, or one of the mesh's file saying how many ranks failed). Collective.
fn agreed<T>(petsc: &Petsc, result: Result<T, ProblemError>) -> Result<T, DistributedError> {
    super::agree_as(
        petsc,
        result.map_err(DistributedError::from),
        "read their part of the mesh",
        mesh_file,
    )
}

/// Refuses parts that name different regions or facet groups (not parts of one mesh), by a
/// hash of the names compared across the ranks. Collective.
fn same_groups(petsc: &Petsc, part: &MshPart) -> Result<(), DistributedError> {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (&part.regions, &part.groups).hash(&mut h);
    let x = (h.finish() >> 12) as f64; // exact in f64
    let range = petsc.max(&[x, -x])?;
    if range[0] != -range[1] {
        return Err(mesh_file(
            "the parts name different regions or facet groups: they are not parts of one mesh".into(),
        ));
    }
    Ok(())
}

/// The estimate of a rank's peak from its piece's cells and nodes (`m`), refused on every
/// rank alike where the largest is over what one rank may take, naming that rank. Collective.
pub(super) fn check_memory(petsc: &Petsc, m: &mesh::Mesh, limits: problem::Limits) -> Result<(), DistributedError> {
    let unknowns = (m.dim + 1) as f64 * m.n_nodes() as f64;
    let bytes = crate::run::BYTES_PER_UNKNOWN * unknowns + crate::run::BYTES_PER_CELL * m.n_cells() as f64;
    let all = petsc.all_gather(bytes as u64)?;
    let (worst, &needed) = all.iter().enumerate().max_by_key(|(_, b)| **b).unwrap_or((0, &0));
    match limits.memory_bytes {
        Some(available) if needed > available => Err(ProblemError::TooLarge {
            what: format!("rank {worst} of {}: a piece of the mesh and its unknowns", petsc.size()),
            needed,
            available,
            limit: limits.memory_limit.unwrap_or("the memory available to one rank"),
        }
        .into()),
        _ => Ok(()),
    }
}

/// The piece of `part`, completed through the table every part writes into. Collective.
fn complete(petsc: &Petsc, part: MshPart) -> Result<MeshPiece, DistributedError> {
    let records = agreed(petsc, part.records().map_err(ProblemError::from))?;
    let top_cell = part.cell_tag.iter().max().copied().unwrap_or(0) as f64;
    let top_node = part.node_tag.iter().max().copied().unwrap_or(0) as f64;
    let tops = petsc.max(&[top_cell, top_node])?;
    let cells = petsc.sum(&[part.own_cells as f64])?[0] as usize;
    sparse_tags(petsc, &part, &tops)?;
    let (lo, hi) = petsc.split(MshPart::SLOTS * tops[0] as usize);
    let mut table = Vector::mpi(petsc, hi - lo)?;
    let (at, values): (Vec<_>, Vec<_>) = records.into_iter().map(|(s, v)| (Layout::index(s), v)).unzip();
    table.add_values(&at, &values)?;
    table.assemble()?;
    let slots: Vec<_> = part.slots().into_iter().map(Layout::index).collect();
    let rows = table.fetch(&slots)?;
    drop(table);
    let piece = part
        .complete(&rows, tops[1] as usize, cells)
        .map_err(ProblemError::from);
    let piece = agreed(petsc, piece)?;
    same_nodes(petsc, &piece)?;
    Ok(piece)
}

/// Refuses parts whose shared nodes are not where their owners put them (parts of different
/// meshes, or of one mesh saved twice): each node's owner writes its coordinates into a
/// directory over the node numbers, and the other ranks compare theirs. Collective.
fn same_nodes(petsc: &Petsc, piece: &MeshPiece) -> Result<(), DistributedError> {
    let (rank, m) = (petsc.rank(), &piece.mesh);
    let (lo, hi) = petsc.split(3 * piece.n_global_nodes);
    let mut directory = Vector::mpi(petsc, hi - lo)?;
    let (mut at, mut values, mut asked, mut mine) = (vec![], vec![], vec![], vec![]);
    for (v, x) in m.points.iter().enumerate() {
        let slots = (0..3).map(|k| Layout::index(3 * piece.global_node[v] + k));
        if piece.node_rank[v] == rank {
            at.extend(slots);
            values.extend_from_slice(x);
        } else {
            asked.extend(slots);
            mine.extend_from_slice(x);
        }
    }
    directory.set_values(&at, &values)?;
    directory.assemble()?;
    let theirs = directory.fetch(&asked)?;
    let moved = mine.iter().zip(&theirs).filter(|(a, b)| a != b).count() / 3;
    let moved_anywhere = petsc.sum(&[moved as f64])?[0];
    if moved_anywhere > 0.0 {
        return Err(mesh_file(format!(
            "{moved_anywhere} nodes that parts share lie elsewhere in the part of the rank that owns them: the parts are not of one mesh (split them again from one Gmsh model)"
        )));
    }
    Ok(())
}

/// Refuses tags that would size the tables past what they index: the tables over the node and
/// element tags are as long as the highest tag (times their numbers per entry), so tags far
/// beyond the count of nodes or elements (a file renumbered by hand, or hostile) would take
/// memory for nothing, and past PETSc's 32-bit indices they would wrap. Collective.
fn sparse_tags(petsc: &Petsc, part: &MshPart, tops: &[f64]) -> Result<(), DistributedError> {
    // (over the parts: shared nodes and ghost cells counted more than once, an upper bound)
    let counts = petsc.sum(&[part.cell_tag.len() as f64, part.node_tag.len() as f64])?;
    let widest = 8.0; // the contact fields' directory: 3 + 2 (dim - 1) numbers per node
    let index_limit = f64::from(i32::MAX);
    for (what, top, count, per) in [
        ("element", tops[0], counts[0], MshPart::SLOTS as f64),
        ("node", tops[1], counts[1], widest),
    ] {
        if top * per > index_limit || top > 16.0 * count + 1e6 {
            return Err(mesh_file(format!(
                "the parts' {what} tags reach {top:.0} for about {count:.0} {what}s: the tables over the tags would be too large; renumber the mesh (Gmsh: gmsh.model.mesh.renumberNodes() and renumberElements(), or Mesh.Renumber = 1) and split it again"
            )));
        }
    }
    Ok(())
}

/// The connected parts of the whole mesh's cells that `keep` marks (joined through any node),
/// labelled across the pieces (`m`: the piece's mesh, which the set-up took from it): each
/// node of a kept cell of the piece with its part's label, the least of the part's node
/// numbers in the whole mesh. A directory over those numbers holds a label per node, at first
/// its number. Each round, every rank gives each node of a connected part of its piece the
/// least label that the directory holds for the part's nodes, and writes it back where it is
/// less than the directory's (where several ranks write one node, one of their values stays:
/// each less than the round's start, so the labels only fall and the rounds end). When no rank
/// writes, every connected part of every piece holds one label; every cell lies whole in its
/// owner's piece, so two nodes share a label exactly when a path of kept cells joins them.
/// Collective.
fn labels(
    petsc: &Petsc,
    m: &mesh::Mesh,
    piece: &MeshPiece,
    keep: &dyn Fn(usize) -> bool,
) -> Result<Vec<(usize, f64)>, DistributedError> {
    let n = m.n_nodes();
    // the connected parts of the piece: a union-find over its kept cells
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut v: usize) -> usize {
        while root[v] != v {
            root[v] = root[root[v]];
            v = root[v];
        }
        v
    }
    let mut used = vec![false; n];
    for (_, cell) in m.iter_cells().enumerate().filter(|(c, _)| keep(*c)) {
        let a = find(&mut root, cell[0]);
        for &v in cell {
            used[v] = true;
            let b = find(&mut root, v);
            root[b] = a;
        }
    }
    let part: Vec<usize> = (0..n).map(|v| find(&mut root, v)).collect();
    let nodes: Vec<usize> = (0..n).filter(|&v| used[v]).collect();
    let items = Items {
        global: &piece.global_node,
        owner: &piece.node_rank,
        count: piece.n_global_nodes,
    };
    let known = propagate(petsc, &nodes, &part, items)?;
    Ok(nodes.into_iter().zip(known).collect())
}

/// Items (nodes or cells) of a piece: each one's number in the whole mesh and its owner, and
/// how many the whole mesh has.
#[derive(Clone, Copy)]
struct Items<'a> {
    global: &'a [usize],
    owner: &'a [usize],
    count: usize,
}

/// The least whole-mesh number over the connected parts spanning the pieces, at each of the
/// piece's items `listed` (`part`: each item's connected part in the piece): a directory over
/// the whole mesh's numbers starts with each item's own, and each round every rank gives the
/// items of each of its parts the least label the directory holds for them, writing back those
/// that fell (labels only fall, so the rounds end). Collective.
fn propagate(petsc: &Petsc, listed: &[usize], part: &[usize], items: Items<'_>) -> Result<Vec<f64>, DistributedError> {
    let at: Vec<_> = listed.iter().map(|&v| Layout::index(items.global[v])).collect();
    let (lo, hi) = petsc.split(items.count);
    let mut directory = Vector::mpi(petsc, hi - lo)?;
    let (own_at, own): (Vec<_>, Vec<f64>) = listed
        .iter()
        .zip(&at)
        .filter(|(&v, _)| items.owner[v] == petsc.rank())
        .map(|(&v, &i)| (i, items.global[v] as f64))
        .unzip();
    directory.set_values(&own_at, &own)?;
    directory.assemble()?;
    let mut known = directory.fetch(&at)?;
    loop {
        let mut least = vec![f64::INFINITY; part.len()];
        for (k, &v) in listed.iter().enumerate() {
            least[part[v]] = least[part[v]].min(known[k]);
        }
        let (lower_at, lower): (Vec<_>, Vec<f64>) = listed
            .iter()
            .enumerate()
            .filter(|&(k, &v)| least[part[v]] < known[k])
            .map(|(k, &v)| (at[k], least[part[v]]))
            .unzip();
        if petsc.sum(&[lower.len() as f64])?[0] == 0.0 {
            return Ok(known);
        }
        directory.set_values(&lower_at, &lower)?;
        directory.assemble()?;
        known = directory.fetch(&at)?;
    }
}

/// Each cell's solid part across the pieces, as the whole mesh's check sees the parts
/// (`Mesh::solid_parts`: cells joined through a shared facet, not through a lone node or edge,
/// a hinge about which two parts turn freely): the least whole-mesh number of the part's cells
/// ([`propagate`]). A piece holds every facet neighbour of its own cells (they share its nodes),
/// so every join is seen by the owner of one of its cells. Collective.
pub(super) fn solid_labels(petsc: &Petsc, m: &mesh::Mesh, piece: &MeshPiece) -> Result<Vec<f64>, DistributedError> {
    // the piece's own solid parts, by the whole mesh's rule
    let (part, _) = m.solid_parts();
    let n = m.n_cells();
    let cells: Vec<usize> = (0..n).collect();
    // (a Gmsh part's cells are numbered by their element tags, which may pass the count of
    // cells: the directory spans the largest)
    let largest = piece.global_cell.iter().max().map_or(0.0, |&g| g as f64 + 1.0);
    let items = Items {
        global: &piece.global_cell,
        owner: &piece.cell_rank,
        count: (petsc.max(&[largest])?[0] as usize).max(piece.n_global_cells),
    };
    propagate(petsc, &cells, &part, items)
}

/// The solid parts of the whole mesh ([`solid_labels`]) as a rank sees them: every part's
/// label (the least whole-mesh number of its cells), in order, the same on every rank; this
/// rank's owned nodes of each (a hinge node in both of its parts); and each part's cells over
/// the ranks.
pub(super) struct Bodies {
    pub(super) labels: Vec<i32>,
    pub(super) nodes: Vec<Vec<usize>>,
    pub(super) cells: Vec<f64>,
}

/// [`Bodies`] of the piece's cells labelled `labels`. Collective.
pub(super) fn bodies(
    petsc: &Petsc,
    m: &mesh::Mesh,
    piece: &MeshPiece,
    labels: &[f64],
) -> Result<Bodies, DistributedError> {
    let rank = petsc.rank();
    let as_i32 = |l: f64| -> Result<i32, DistributedError> {
        i32::try_from(l as u64)
            .map_err(|_| mesh_file("a body's label past 2^31 cells: too large a mesh to check on pieces".into()))
    };
    let mut roots = vec![];
    for c in (0..piece.own_cells).filter(|&c| labels[c] == piece.global_cell[c] as f64) {
        roots.push(as_i32(labels[c])?);
    }
    let mut all = petsc.all_gather_i32(&roots)?;
    all.sort_unstable();
    let index = |l: f64| all.binary_search(&(l as i32)).ok();
    let mut cells = vec![0.0; all.len()];
    for c in 0..piece.own_cells {
        if let Some(b) = index(labels[c]) {
            cells[b] += 1.0;
        }
    }
    let cells = petsc.sum(&cells)?;
    // an owned node's cells are all in the piece: its bodies are theirs
    let (offsets, node_cells) = m.node_cells();
    let mut nodes = vec![vec![]; all.len()];
    for v in (0..m.n_nodes()).filter(|&v| piece.node_rank[v] == rank) {
        let mut of: Vec<usize> = node_cells[offsets[v]..offsets[v + 1]]
            .iter()
            .filter_map(|&c| index(labels[c]))
            .collect();
        of.sort_unstable();
        of.dedup();
        for b in of {
            nodes[b].push(v);
        }
    }
    Ok(Bodies {
        labels: all,
        nodes,
        cells,
    })
}

/// Each body's frame: the centre and size of its bounding box, from its owned nodes on every
/// rank. Collective.
pub(super) fn frames(petsc: &Petsc, m: &mesh::Mesh, bodies: &Bodies) -> Result<Vec<([f64; 3], f64)>, DistributedError> {
    let mut ends = vec![f64::NEG_INFINITY; 6 * bodies.labels.len()];
    for (b, nodes) in bodies.nodes.iter().enumerate() {
        for &v in nodes {
            let x = m.points[v];
            for k in 0..3 {
                ends[6 * b + k] = ends[6 * b + k].max(x[k]);
                ends[6 * b + 3 + k] = ends[6 * b + 3 + k].max(-x[k]);
            }
        }
    }
    let ends = petsc.max(&ends)?;
    Ok(ends
        .chunks(6)
        .map(|e| {
            let centre = std::array::from_fn(|k| 0.5 * (e[k] - e[3 + k]));
            let size = (0..m.dim).map(|k| e[k] + e[3 + k]).fold(0.0, f64::max);
            (centre, size)
        })
        .collect())
}

/// The electric parts of the whole mesh (joined by the `electric` cells through any node,
/// [`labels`]) whose potential no prescribed φ holds (`fixed` at a node): their count, as the
/// whole mesh's check judges them (`fe_assembly::held`). Each rank lists the parts its owned
/// nodes start (the node whose number is the label) and the parts its owned nodes prescribe,
/// and the lists are gathered: their sizes are the count of parts, not of nodes. Collective.
pub(super) fn floating_parts(
    petsc: &Petsc,
    m: &mesh::Mesh,
    piece: &MeshPiece,
    electric: &[bool],
    fixed: &dyn Fn(usize) -> bool,
) -> Result<usize, DistributedError> {
    let rank = petsc.rank();
    let labels = labels(petsc, m, piece, &|c| electric[c])?;
    let as_i32 = |l: f64| -> Result<i32, DistributedError> {
        i32::try_from(l as u64).map_err(|_| {
            mesh_file("an electric part's label past 2^31 nodes: too large a mesh to check on pieces".into())
        })
    };
    let (mut parts, mut held) = (vec![], vec![]);
    for &(v, l) in labels.iter().filter(|(v, _)| piece.node_rank[*v] == rank) {
        if l == piece.global_node[v] as f64 {
            parts.push(as_i32(l)?);
        }
        if fixed(v) {
            held.push(as_i32(l)?);
        }
    }
    held.sort_unstable();
    held.dedup();
    let parts = petsc.all_gather_i32(&parts)?;
    let mut held = petsc.all_gather_i32(&held)?;
    held.sort_unstable();
    Ok(parts.iter().filter(|p| held.binary_search(p).is_err()).count())
}

/// The centre and size of the whole mesh's bounding box, from the owned nodes of every piece
/// (`m`: the piece's mesh).
/// Collective.
pub(super) fn frame(petsc: &Petsc, m: &mesh::Mesh, piece: &MeshPiece) -> Result<([f64; 3], f64), DistributedError> {
    let rank = petsc.rank();
    let mut ends = [f64::NEG_INFINITY; 6];
    for (_, x) in m.points.iter().enumerate().filter(|(v, _)| piece.node_rank[*v] == rank) {
        for k in 0..3 {
            ends[k] = ends[k].max(x[k]);
            ends[3 + k] = ends[3 + k].max(-x[k]);
        }
    }
    let ends = petsc.max(&ends)?;
    let centre = std::array::from_fn(|k| 0.5 * (ends[k] - ends[3 + k]));
    let size = (0..m.dim).map(|k| ends[k] + ends[3 + k]).fold(0.0, f64::max);
    Ok((centre, size))
}

/// A refusal of the scene's mesh file.
fn mesh_file(message: String) -> DistributedError {
    ProblemError::from(SetupError::new("mesh.file", message)).into()
}

/// A part's file name, for messages.
fn name(path: Option<&PathBuf>) -> String {
    path.map_or(String::new(), |p| p.display().to_string())
}
