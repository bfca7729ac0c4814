//! A mesh that Gmsh split into one file per partition, read part by part as the ranks of a
//! parallel run read it (`fixtures/forms/{2d,3d}-{ascii,bin}-split_{1,2,3}.msh`, written by the
//! real Gmsh from the layered models of `fixtures/write_forms.py`: two regions, an interior
//! facet group). The parts complete each other through their table (summed here in one
//! process, as a parallel vector sums it across ranks), and each piece is checked against the
//! whole mesh read from the unsplit file: the own cells of the parts are the whole mesh's
//! cells, each once; a piece's ghost cells are exactly the whole mesh's cells that share a node
//! with its own; every cell is in its regions, every facet on the piece's cells in its groups
//! with the file's orientation, and every node of an own cell owned by the lowest rank of the
//! cells around it.

use mesh::{parts_of, read_msh, read_msh_part, Mesh, MeshPiece, MshPart};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::PathBuf;

fn forms() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/forms")
}

/// A node's position, rounded to 1e-10: the same in the whole file and in a part.
type Point = [i64; 3];

fn at(m: &Mesh, v: usize) -> Point {
    m.points[v].map(|x| (x * 1e10).round() as i64)
}

/// A cell or facet as its nodes' positions in their order.
fn ordered(m: &Mesh, nodes: &[usize]) -> Vec<Point> {
    nodes.iter().map(|&v| at(m, v)).collect()
}

/// The same, sorted: the same whatever the order.
fn sorted(m: &Mesh, nodes: &[usize]) -> Vec<Point> {
    let mut s = ordered(m, nodes);
    s.sort_unstable();
    s
}

/// A part's rows of the table (0 where no part wrote).
fn rows_of(part: &MshPart, table: &HashMap<usize, f64>) -> Vec<f64> {
    part.slots()
        .iter()
        .map(|s| table.get(s).copied().unwrap_or(0.0))
        .collect()
}

/// The pieces of `stem`'s parts, completed through their summed table.
fn pieces(stem: &str) -> Vec<MeshPiece> {
    let paths = parts_of(&forms().join(format!("{stem}.msh")));
    assert_eq!(paths.len(), 3, "{stem}: three parts");
    let parts: Vec<MshPart> = paths.iter().map(|p| read_msh_part(p).expect("a part")).collect();
    let mut table: HashMap<usize, f64> = HashMap::new();
    for part in &parts {
        for (slot, value) in part.records().expect("records") {
            *table.entry(slot).or_default() += value;
        }
    }
    let nodes = parts.iter().flat_map(|p| p.node_tag.iter()).max().copied().unwrap_or(0) as usize;
    let cells: usize = parts.iter().map(|p| p.own_cells).sum();
    parts
        .into_iter()
        .map(|part| {
            let rows = rows_of(&part, &table);
            part.complete(&rows, nodes, cells).expect("a piece")
        })
        .collect()
}

fn check(stem: &str, whole_file: &str) {
    let whole = read_msh(forms().join(whole_file)).expect("the whole mesh");
    let pieces = pieces(stem);
    // the whole mesh's cells by shape, each cell's rank from the piece that owns it
    let index: HashMap<Vec<Point>, usize> = (0..whole.n_cells())
        .map(|c| (sorted(&whole, whole.cell(c)), c))
        .collect();
    let mut rank_of = vec![usize::MAX; whole.n_cells()];
    for (r, p) in pieces.iter().enumerate() {
        for c in 0..p.own_cells {
            let w = index[&sorted(&p.mesh, p.mesh.cell(c))];
            assert_eq!(rank_of[w], usize::MAX, "{stem}: cell {w} owned twice");
            rank_of[w] = r;
            assert_eq!(p.cell_rank[c], r);
        }
    }
    assert!(rank_of.iter().all(|&r| r < 3), "{stem}: every cell owned");
    let mut cells_of: HashMap<Point, Vec<usize>> = HashMap::new();
    for c in 0..whole.n_cells() {
        for &v in whole.cell(c) {
            cells_of.entry(at(&whole, v)).or_default().push(c);
        }
    }
    for (r, p) in pieces.iter().enumerate() {
        let m = &p.mesh;
        assert_eq!(p.n_global_cells, whole.n_cells());
        // the ghost layer: every cell of another rank that shares a node with an own cell
        let own_nodes: BTreeSet<Point> = (0..p.own_cells).flat_map(|c| ordered(m, m.cell(c))).collect();
        let layer: BTreeSet<usize> = own_nodes
            .iter()
            .flat_map(|x| cells_of[x].iter().copied())
            .filter(|&c| rank_of[c] != r)
            .collect();
        let ghosts: BTreeSet<usize> = (p.own_cells..m.n_cells())
            .map(|c| index[&sorted(m, m.cell(c))])
            .collect();
        assert_eq!(ghosts, layer, "{stem}: rank {r}'s ghost cells");
        for c in 0..m.n_cells() {
            let w = index[&sorted(m, m.cell(c))];
            assert_eq!(p.cell_rank[c], rank_of[w], "{stem}: the owner of rank {r}'s cell {c}");
            assert_eq!(
                ordered(m, m.cell(c)),
                ordered(&whole, whole.cell(w)),
                "{stem}: a cell's node order"
            );
            for (name, cells) in &whole.regions {
                assert_eq!(
                    m.regions[name].contains(&c),
                    cells.contains(&w),
                    "{stem}: region {name}"
                );
            }
        }
        // the facets: the whole mesh's facets on the piece's cells, oriented as in the file
        let piece_nodes: BTreeSet<Point> = (0..m.n_nodes()).map(|v| at(m, v)).collect();
        let on_cells: BTreeSet<Vec<Point>> = (0..m.n_cells()).map(|c| sorted(m, m.cell(c))).collect();
        for (name, group) in &whole.boundaries {
            let mut expected: Vec<Vec<Point>> = group
                .iter()
                .filter(|f| f.iter().all(|&v| piece_nodes.contains(&at(&whole, v))))
                .filter(|f| {
                    let f: BTreeSet<Point> = f.iter().map(|&v| at(&whole, v)).collect();
                    on_cells.iter().any(|c| f.iter().all(|x| c.contains(x)))
                })
                .map(|f| ordered(&whole, f))
                .collect();
            let mut got: Vec<Vec<Point>> = m.boundaries[name].iter().map(|f| ordered(m, f)).collect();
            expected.sort();
            got.sort();
            assert_eq!(got, expected, "{stem}: rank {r}'s facets of `{name}`");
        }
        // the owners of the own cells' nodes, and the numbers of the whole mesh
        let mut seen = BTreeMap::new();
        for v in 0..m.n_nodes() {
            assert!(seen.insert(p.global_node[v], v).is_none(), "{stem}: a node twice");
            if own_nodes.contains(&at(m, v)) {
                let lowest = cells_of[&at(m, v)].iter().map(|&c| rank_of[c]).min();
                assert_eq!(Some(p.node_rank[v]), lowest, "{stem}: the owner of a node");
            } else {
                assert_ne!(p.node_rank[v], r, "{stem}: a ghost cell's node owned here");
            }
        }
    }
}

#[test]
fn parts_of_a_split_3d_mesh_are_its_pieces() {
    check("3d-ascii-split", "3d-ascii.msh");
    check("3d-bin-split", "3d-bin.msh");
}

#[test]
fn parts_of_a_split_2d_mesh_are_its_pieces() {
    check("2d-ascii-split", "2d-ascii.msh");
    check("2d-bin-split", "2d-bin.msh");
}

#[test]
fn a_part_read_as_a_whole_mesh_is_refused() {
    let e = read_msh(forms().join("3d-ascii-split_2.msh")).expect_err("a part is not the body");
    let text = e.to_string();
    assert!(text.contains("part 2 of a mesh that Gmsh split into 3 files"), "{text}");
    assert!(text.contains("3d-ascii-split_2.msh"), "{text}");
}

#[test]
fn a_whole_file_read_as_a_part_is_refused() {
    // an unsplit partitioned file holds every partition's cells
    let e = read_msh_part(forms().join("3d-ascii-partitioned.msh")).expect_err("not one part");
    assert!(e.to_string().contains("holds those of 2 of 2 partitions"), "{e}");
    let e = read_msh_part(forms().join("3d-ascii.msh")).expect_err("not a part");
    assert!(e.to_string().contains("one partition's cells per file"), "{e}");
}

#[test]
fn a_table_of_another_mesh_is_refused() {
    let part = read_msh_part(forms().join("3d-ascii-split_1.msh")).expect("a part");
    let rows = vec![0.5; part.slots().len()];
    let e = part.complete(&rows, 1000, 100).expect_err("not this mesh's table");
    assert!(e.to_string().contains("not of one mesh"), "{e}");
}

#[test]
fn a_ghost_cell_that_no_part_owns_is_refused() {
    // the table without the records of part 3: part 1's ghosts of part 3 have no owner's mark
    let paths = parts_of(&forms().join("3d-ascii-split.msh"));
    let parts: Vec<MshPart> = paths.iter().map(|p| read_msh_part(p).expect("a part")).collect();
    let mut table: HashMap<usize, f64> = HashMap::new();
    for part in &parts[..2] {
        for (slot, value) in part.records().expect("records") {
            *table.entry(slot).or_default() += value;
        }
    }
    let errors: Vec<String> = parts
        .into_iter()
        .filter(|p| p.cell_rank.contains(&2) && p.rank != 2)
        .map(|part| {
            let rows = rows_of(&part, &table);
            part.complete(&rows, 10_000, 10_000)
                .expect_err("a ghost without its owner")
                .to_string()
        })
        .collect();
    assert!(!errors.is_empty());
    for e in errors {
        assert!(
            e.contains("is a ghost of part 3 here, but no part holds it as its own"),
            "{e}"
        );
    }
}

#[test]
fn a_split_mesh_named_whole_says_where_its_parts_are() {
    let e = read_msh(forms().join("3d-ascii-split.msh")).expect_err("no such file");
    let text = e.to_string();
    assert!(
        text.contains("3d-ascii-split_1.msh") && text.contains("3d-ascii-split_3.msh"),
        "{text}"
    );
    assert!(text.contains("run on 3 ranks of the PETSc backend"), "{text}");
}
