//! A part of a mesh that Gmsh partitioned and split into one file per partition
//! (`Mesh.PartitionSplitMeshFiles = 1`, with `Mesh.PartitionCreateGhostCells = 1`): the
//! partition's cells, the layer of other partitions' cells that share a node with them (Gmsh's
//! ghost cells, listed in `$GhostElements` with their owners), and the facets that Gmsh gave
//! the partition. One rank of a parallel run reads one part, and no rank reads the whole.
//!
//! A part alone does not know everything its piece needs: the ghost cells lie on an entity
//! without physical groups (their regions are their owners'), and a facet of a ghost cell is
//! in its owner's file only. The parts complete each other through a table indexed by the
//! whole mesh's element tags, [`MshPart::SLOTS`] numbers per cell, that a parallel run spreads over
//! its ranks: each part writes its own cells' regions and its facets into it
//! ([`MshPart::records`]), and reads back the rows of its piece's cells ([`MshPart::slots`],
//! [`MshPart::complete`]). A row holds the cell's regions as bits (doubled, plus one: the mark
//! of a cell that its owner wrote), then for each of its faces
//! the facet groups on it as bits, times 6, plus the order of the facet's corners (one of the
//! 6 permutations of the face's), so that a facet keeps the orientation its file gives it.

use super::sections::{self, File};
use super::{build, cell_blocks, cell_dim, flatten_2d, groups_of, partitions_held};
use crate::topology::{key, Key};
use crate::{CellKind, FacetGroup, Mesh, MeshError, MeshPiece};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// Numbers per cell in the table the parts complete each other through: its regions, then
/// the facet groups on each of (up to) four faces.
const SLOTS: usize = 5;

/// Regions, and facet groups, a mesh in parts may name: bits of a number that `f64` holds
/// exactly, a face's 6 orders beside them.
const MAX_GROUPS: usize = 48;

/// The 6 orders of three corners (the first 2 of them are the orders of two).
const ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [1, 0, 2], [0, 2, 1], [1, 2, 0], [2, 0, 1], [2, 1, 0]];

/// One part of a split mesh, as its file holds it.
#[derive(Clone, Debug)]
pub struct MshPart {
    /// The part's cells, its own (`0..own_cells`) then its ghost cells; the regions of its
    /// own cells, and the facets its file holds. Complete it with [`MshPart::complete`].
    pub mesh: Mesh,
    /// The part's own cells: the first `own_cells` of `mesh`.
    pub own_cells: usize,
    /// The part's rank: its partition number less one.
    pub rank: usize,
    /// The parts in all (Gmsh's partitions).
    pub parts: usize,
    /// The rank that owns each cell (the owner's partition less one).
    pub cell_rank: Vec<usize>,
    /// Each cell's element tag in the file.
    pub cell_tag: Vec<u64>,
    /// Each node's tag in the file.
    pub node_tag: Vec<u64>,
    /// The whole mesh's regions (the physical groups of the cells' dimension), by name.
    pub regions: Vec<String>,
    /// The whole mesh's facet groups (the physical groups one dimension lower), by name.
    pub groups: Vec<String>,
    /// The part's file, for messages.
    pub name: String,
}

/// The parts of a mesh that Gmsh split for `path`: `stem_1.ext`, `stem_2.ext`, ... as long
/// as they exist (none where there are none).
pub fn parts_of(path: &Path) -> Vec<PathBuf> {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    (1..)
        .map(|k| path.with_file_name(format!("{stem}_{k}{ext}")))
        .take_while(|p| p.is_file())
        .collect()
}

/// Reads one part of a split mesh (MSH 4.1, ASCII or binary).
///
/// # Errors
/// [`MeshError::Io`] where the file cannot be read, [`MeshError::Gmsh`] for a file that is
/// not one part of a split mesh with ghost cells (a whole or unsplit file, a part saved
/// without ghost cells), cells of the second order, more than 48 regions or facet groups, and
/// the reader's errors.
pub fn read_msh_part(path: impl AsRef<Path>) -> Result<MshPart, MeshError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshError::Io {
        path: name.clone(),
        message: e.to_string(),
    })?;
    let err = |message: String| MeshError::Gmsh {
        path: name.clone(),
        message,
    };
    let file = sections::read(&bytes).map_err(err)?;
    drop(bytes);
    let mut part = part_of(&file).map_err(err)?;
    part.name = name;
    Ok(part)
}

/// The part of `file`.
fn part_of(file: &File) -> Result<MshPart, String> {
    let (held, parts) = partitions_held(file)?;
    let ([partition], true) = (held.as_slice(), parts >= 1) else {
        return Err(format!(
            "a mesh in parts needs one partition's cells per file (Gmsh: Mesh.PartitionSplitMeshFiles = 1); this file holds those of {} of {parts} partitions",
            held.len()
        ));
    };
    let dim = cell_dim(file)?;
    if parts > 1 && file.ghost_owner.is_empty() {
        return Err(
            "the parts were saved without ghost cells: partition with Mesh.PartitionCreateGhostCells = 1".into(),
        );
    }
    let mut mesh = build(file, true)?;
    flatten_2d(&mut mesh)?;
    if !matches!(mesh.kind, CellKind::Tri3 | CellKind::Quad4 | CellKind::Tet4) {
        return Err(format!(
            "{} cells in a mesh in parts: its cells must be of the first order (Mesh.ElementOrder = 1)",
            mesh.kind.name()
        ));
    }
    let rank = (*partition - 1) as usize;
    let mut cell_tag = vec![];
    let mut cell_rank = vec![];
    let mut own_cells = 0;
    for block in cell_blocks(file, dim, true) {
        let ghost = file.ghost_entities.contains_key(&block.entity);
        for &tag in &block.tags {
            let owner = match (ghost, file.ghost_owner.get(&tag)) {
                (false, _) => rank,
                (true, Some(&p)) if p >= 1 && p as u64 <= parts && p - 1 != rank as i32 => (p - 1) as usize,
                (true, p) => {
                    return Err(format!(
                        "ghost cell {tag} has {} as its owner in `$GhostElements` (partitions 1 to {parts}, not this one, {partition})",
                        p.map_or("no partition".to_string(), |p| format!("partition {p}"))
                    ))
                }
            };
            own_cells += usize::from(!ghost);
            cell_tag.push(tag);
            cell_rank.push(owner);
        }
    }
    let node_tag: Vec<u64> = file.nodes.iter().flat_map(|b| b.tags.iter().copied()).collect();
    if node_tag.contains(&0) || cell_tag.contains(&0) {
        return Err("a node or element tag 0: Gmsh's tags start at 1".into());
    }
    let regions = names_of(file, dim)?;
    let groups = names_of(file, dim - 1)?;
    Ok(MshPart {
        mesh,
        own_cells,
        rank,
        parts: parts.max(1) as usize,
        cell_rank,
        cell_tag,
        node_tag,
        regions,
        groups,
        name: String::new(),
    })
}

/// The names of the physical groups of dimension `d` on the file's entities, sorted.
fn names_of(file: &File, d: i32) -> Result<Vec<String>, String> {
    let mut names: Vec<String> = file
        .physical
        .keys()
        .filter(|&&(dd, _)| dd == d)
        .flat_map(|&(_, tag)| groups_of(file, d, tag))
        .collect();
    names.sort();
    names.dedup();
    if names.len() > MAX_GROUPS {
        return Err(format!(
            "{} physical groups of dimension {d}: a mesh in parts may name at most {MAX_GROUPS}",
            names.len()
        ));
    }
    Ok(names)
}

/// The corners of face `k` of a cell of `kind` (its nodes `c`), in the order of
/// [`CellKind::facets`]; `None` past the cell's faces.
fn face(kind: CellKind, c: &[usize], k: usize) -> Option<Vec<usize>> {
    let f = kind.facets().get(k)?;
    Some(f[..kind.facet_corners()].iter().map(|&i| c[i]).collect())
}

/// `x` as the integer it holds (exact in `f64`), where it is one.
fn as_bits(x: f64) -> Option<u64> {
    (x >= 0.0 && x.fract() == 0.0 && x < 2f64.powi(53)).then_some(x as u64)
}

impl MshPart {
    /// Numbers per cell in the table the parts complete each other through: the cell's
    /// regions, then the facet groups on each of its (up to) four faces.
    pub const SLOTS: usize = SLOTS;

    /// Where this part writes into the table, and what: its own cells' regions, and the
    /// facet groups of each facet its file holds on the faces of the piece's cells it lies on
    /// (both sides of an interior facet: Gmsh gives a facet to a partition of a cell beside
    /// it, so both cells are in the part). Pairs of a slot (`SLOTS * (tag - 1) + k`) and its
    /// value, to be added to a table of zeros (each slot written by one part).
    ///
    /// # Errors
    /// [`MeshError::Gmsh`] for a facet that lies on none of the part's cells.
    pub fn records(&self) -> Result<Vec<(usize, f64)>, MeshError> {
        let m = &self.mesh;
        let region_bits = self.region_bits();
        let mut out: Vec<(usize, f64)> = (0..self.own_cells)
            .map(|c| (self.slot(c, 0), (1 + 2 * region_bits[c]) as f64))
            .collect();
        // the cells on each face (two on an interior facet)
        let mut faces: HashMap<Key, Vec<(usize, usize)>> = HashMap::new();
        for c in 0..m.n_cells() {
            for k in 0.. {
                let Some(f) = face(m.kind, m.cell(c), k) else { break };
                faces.entry(key(&f)).or_default().push((c, k));
            }
        }
        let mut on_faces: BTreeMap<(usize, usize), (u64, usize)> = BTreeMap::new();
        for (bit, name) in self.groups.iter().enumerate() {
            let Some(group) = m.boundaries.get(name) else { continue };
            for f in group.facets.chunks_exact(group.nodes_per_facet) {
                let Some(cells) = faces.get(&key(f)) else {
                    return Err(MeshError::Gmsh {
                        path: self.name.clone(),
                        message: format!("a facet of group `{name}` lies on none of the part's cells"),
                    });
                };
                for &(c, k) in cells {
                    let corners = face(m.kind, m.cell(c), k).unwrap_or_default();
                    let order = ORDERS
                        .iter()
                        .position(|o| (0..f.len()).all(|i| corners[o[i]] == f[i]))
                        .unwrap_or(0);
                    let entry = on_faces.entry((c, k)).or_insert((0, order));
                    entry.0 |= 1 << bit;
                }
            }
        }
        out.extend(
            on_faces
                .into_iter()
                .map(|((c, k), (bits, order))| (self.slot(c, 1 + k), (bits * 6 + order as u64) as f64)),
        );
        Ok(out)
    }

    /// The slots of the table this part reads back: its cells' rows, in its cells' order.
    pub fn slots(&self) -> Vec<usize> {
        (0..self.cell_tag.len())
            .flat_map(|c| (0..SLOTS).map(move |k| (c, k)))
            .map(|(c, k)| self.slot(c, k))
            .collect()
    }

    /// The table's slot `k` of cell `c`.
    fn slot(&self, c: usize, k: usize) -> usize {
        SLOTS * (self.cell_tag[c] as usize - 1) + k
    }

    /// Each cell's regions as bits (of [`MshPart::regions`]), as far as the part knows them.
    fn region_bits(&self) -> Vec<u64> {
        let mut bits = vec![0u64; self.mesh.n_cells()];
        for (b, name) in self.regions.iter().enumerate() {
            for &c in self.mesh.regions.get(name).into_iter().flatten() {
                bits[c] |= 1 << b;
            }
        }
        bits
    }

    /// The piece of this part, from `rows` (the table's values at [`MshPart::slots`], after
    /// every part wrote its [`MshPart::records`]) and the whole mesh's `nodes` (one more than
    /// its highest node number) and `cells` (its count of cells): every cell in its regions,
    /// every facet of the piece's cells in its groups (each group present, empty where the
    /// piece holds none of it), the nodes no cell of the piece holds left out, each node owned
    /// by the lowest rank among its cells. The numbers in the whole mesh are the file's tags
    /// less one (a cell's number is its element tag's: they may skip numbers).
    ///
    /// # Errors
    /// [`MeshError::Gmsh`] where `rows` hold what no part writes (the table was not this
    /// mesh's).
    pub fn complete(self, rows: &[f64], nodes: usize, cells: usize) -> Result<MeshPiece, MeshError> {
        let n_cells = self.mesh.n_cells();
        if rows.len() != SLOTS * n_cells {
            return Err(self.bad("rows of another length"));
        }
        let (cell_nodes, points, global_node) = self.renumbered();
        let kind = self.mesh.kind;
        let mut regions: BTreeMap<String, Vec<usize>> = self.regions.iter().map(|r| (r.clone(), vec![])).collect();
        let mut boundaries: BTreeMap<String, FacetGroup> = self
            .groups
            .iter()
            .map(|g| {
                let group = FacetGroup {
                    nodes_per_facet: kind.facet_n_nodes(),
                    facets: vec![],
                };
                (g.clone(), group)
            })
            .collect();
        let per = kind.n_nodes();
        let mut seen: std::collections::HashSet<(Key, usize)> = std::collections::HashSet::new();
        for c in 0..n_cells {
            let row = &rows[SLOTS * c..SLOTS * (c + 1)];
            let bits = self.regions_of(c, row[0])?;
            for (_, name) in self.regions.iter().enumerate().filter(|(b, _)| bits >> b & 1 == 1) {
                regions.entry(name.clone()).or_default().push(c);
            }
            for (b, facet) in self.facets_of(&cell_nodes[per * c..per * (c + 1)], &row[1..])? {
                // an interior facet is on the faces of both its cells: kept once
                if seen.insert((key(&facet), b)) {
                    if let Some(g) = boundaries.get_mut(&self.groups[b]) {
                        g.facets.extend_from_slice(&facet);
                    }
                }
            }
        }
        if !self.regions.iter().any(|r| r == "body") {
            regions.insert("body".into(), (0..n_cells).collect());
        }
        let mut node_rank = vec![usize::MAX; points.len()];
        for (c, cell) in cell_nodes.chunks_exact(per).enumerate() {
            for &v in cell {
                node_rank[v] = node_rank[v].min(self.cell_rank[c]);
            }
        }
        let mesh = Mesh {
            dim: self.mesh.dim,
            kind,
            points,
            cells: cell_nodes,
            boundaries,
            regions,
            reoriented_cells: self.mesh.reoriented_cells,
            other_groups: self.mesh.other_groups.clone(),
        };
        Ok(MeshPiece {
            mesh,
            own_cells: self.own_cells,
            cell_rank: self.cell_rank,
            global_cell: self.cell_tag.iter().map(|&t| t as usize - 1).collect(),
            global_node,
            node_rank,
            n_global_nodes: nodes,
            n_global_cells: cells,
        })
    }

    /// A refusal of the parts' table.
    fn bad(&self, what: &str) -> MeshError {
        MeshError::Gmsh {
            path: self.name.clone(),
            message: format!("the parts' table holds {what}: the parts are not of one mesh"),
        }
    }

    /// The nodes the cells hold, numbered anew in the order the cells meet them: the cells'
    /// nodes, the points, each point's number in the whole mesh.
    fn renumbered(&self) -> (Vec<usize>, Vec<[f64; 3]>, Vec<usize>) {
        let mut new = vec![usize::MAX; self.mesh.n_nodes()];
        let (mut points, mut global_node) = (vec![], vec![]);
        for &v in &self.mesh.cells {
            if new[v] == usize::MAX {
                new[v] = points.len();
                points.push(self.mesh.points[v]);
                global_node.push(self.node_tag[v] as usize - 1);
            }
        }
        (self.mesh.cells.iter().map(|&v| new[v]).collect(), points, global_node)
    }

    /// Cell `c`'s regions as bits, from its row's first number (odd: written by its owner).
    fn regions_of(&self, c: usize, x: f64) -> Result<u64, MeshError> {
        let owned = as_bits(x).filter(|b| b % 2 == 1).ok_or_else(|| MeshError::Gmsh {
            path: self.name.clone(),
            message: format!(
                "cell {} is a ghost of part {} here, but no part holds it as its own: the parts are not of one mesh",
                self.cell_tag[c],
                self.cell_rank[c] + 1
            ),
        })?;
        Some(owned / 2)
            .filter(|b| b >> self.regions.len() == 0)
            .ok_or_else(|| self.bad("regions no part names"))
    }

    /// The facets on the faces of a cell (its corners `corners`, its row's face numbers
    /// `faces`): each facet group's index and the facet's nodes in its file's order.
    fn facets_of(&self, corners: &[usize], faces: &[f64]) -> Result<Vec<(usize, Vec<usize>)>, MeshError> {
        let mut out = vec![];
        for (k, &x) in faces.iter().enumerate() {
            let (Some(f), Some(value)) = (face(self.mesh.kind, corners, k), as_bits(x)) else {
                if x != 0.0 {
                    return Err(self.bad("a face no cell has"));
                }
                continue;
            };
            let (bits, order) = (value / 6, (value % 6) as usize);
            if bits >> self.groups.len() != 0 || (f.len() == 2 && order > 1) {
                return Err(self.bad("facet groups no part names"));
            }
            let facet: Vec<usize> = (0..f.len()).map(|i| f[ORDERS[order][i]]).collect();
            out.extend(
                (0..self.groups.len())
                    .filter(|b| bits >> b & 1 == 1)
                    .map(|b| (b, facet.clone())),
            );
        }
        Ok(out)
    }
}
