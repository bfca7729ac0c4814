//! Every form of MSH 4.1 that Gmsh writes, read as one mesh: the files of `fixtures/forms/`
//! (written by the real Gmsh, `fixtures/write_forms.py`), and the forms made from them here
//! that Gmsh reads as well (CR LF line ends, tabs and runs of spaces, blank lines, sections of
//! other programs). Each must give the same cells, groups and regions, point for point.

use mesh::{read_msh_bytes, Mesh};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn forms() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/forms")
}

fn bytes(name: &str) -> Vec<u8> {
    std::fs::read(forms().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A cell or facet as its nodes' coordinates, sorted and rounded to 1e-10 (ASCII files carry 16
/// significant digits, binary ones every bit): the same in every numbering of the nodes.
type Shape = Vec<[i64; 3]>;

/// What a mesh is, whatever its node numbering: its cells, and the facets of each group and the
/// cells of each region, as sorted shapes.
#[derive(Debug, PartialEq)]
struct Signature {
    dim: usize,
    cells: Vec<Shape>,
    groups: BTreeMap<String, Vec<Shape>>,
    regions: BTreeMap<String, Vec<Shape>>,
    unused_nodes: usize,
}

fn shape(m: &Mesh, nodes: &[usize]) -> Shape {
    let mut s: Shape = nodes
        .iter()
        .map(|&v| m.points[v].map(|x| (x * 1e10).round() as i64))
        .collect();
    s.sort_unstable();
    s
}

fn signature(m: &Mesh) -> Signature {
    let sorted = |mut v: Vec<Shape>| {
        v.sort_unstable();
        v
    };
    Signature {
        dim: m.dim,
        cells: sorted(m.iter_cells().map(|c| shape(m, c)).collect()),
        groups: m
            .boundaries
            .iter()
            .map(|(k, g)| (k.clone(), sorted(g.iter().map(|f| shape(m, f)).collect())))
            .collect(),
        regions: m
            .regions
            .iter()
            .map(|(k, r)| (k.clone(), sorted(r.iter().map(|&c| shape(m, m.cell(c))).collect())))
            .collect(),
        unused_nodes: m.check().expect("a checked mesh").unused_nodes,
    }
}

fn read(name: &str, data: &[u8]) -> Signature {
    signature(&read_msh_bytes(data, name).unwrap_or_else(|e| panic!("{name}: {e}")))
}

/// The first difference between two signatures, or `None`.
fn difference(a: &Signature, b: &Signature) -> Option<String> {
    if a.dim != b.dim || a.unused_nodes != b.unused_nodes {
        return Some(format!(
            "dim {} / {}, unused nodes {} / {}",
            a.dim, b.dim, a.unused_nodes, b.unused_nodes
        ));
    }
    let first = |what: &str, x: &[Shape], y: &[Shape]| {
        (x != y).then(|| {
            let at = x
                .iter()
                .zip(y)
                .position(|(p, q)| p != q)
                .unwrap_or(x.len().min(y.len()));
            format!(
                "{what}: {} / {} items, first differing {:?} / {:?}",
                x.len(),
                y.len(),
                x.get(at),
                y.get(at)
            )
        })
    };
    first("cells", &a.cells, &b.cells)
        .or_else(|| {
            (a.groups.keys().ne(b.groups.keys()))
                .then(|| format!("groups {:?} / {:?}", a.groups.keys(), b.groups.keys()))
        })
        .or_else(|| a.groups.iter().find_map(|(k, g)| first(k, g, &b.groups[k])))
        .or_else(|| {
            (a.regions.keys().ne(b.regions.keys()))
                .then(|| format!("regions {:?} / {:?}", a.regions.keys(), b.regions.keys()))
        })
        .or_else(|| a.regions.iter().find_map(|(k, r)| first(k, r, &b.regions[k])))
}

/// Asserts that `a` and `b` are one mesh.
#[track_caller]
fn assert_same(a: &Signature, b: &Signature, what: &str) {
    if let Some(d) = difference(a, b) {
        panic!("{what}: {d}");
    }
}

/// Every form of one model, read as the plain ASCII file.
fn same_as_plain(dim: usize, forms: &[&str]) -> Signature {
    let plain = read("plain", &bytes(&format!("{dim}d-ascii.msh")));
    for form in forms {
        let name = format!("{dim}d-{form}.msh");
        let mut m = read(&name, &bytes(&name));
        // with every element saved (and in a partitioned file) the arc's own nodes come too,
        // unused as its centre is
        assert!(m.unused_nodes >= plain.unused_nodes, "{name}");
        m.unused_nodes = plain.unused_nodes;
        assert_same(&m, &plain, &name);
    }
    plain
}

#[test]
fn every_form_gmsh_writes_gives_the_same_2d_mesh() {
    let m = same_as_plain(
        2,
        &[
            "bin",
            "ascii-parametric",
            "bin-parametric",
            "ascii-all",
            "bin-all",
            "ascii-view",
            "bin-view",
            "ascii-partitioned",
            "bin-partitioned",
            "ascii-partitioned-ghosts",
            "bin-partitioned-ghosts",
        ],
    );
    let names: Vec<&str> = m.groups.keys().map(String::as_str).collect();
    assert_eq!(names, ["bottom", "interface", "left", "right", "top"]);
    assert!(m.regions.contains_key("pzt") && m.regions.contains_key("substrate"));
    // the arc's centre, in a point group, is a node no cell uses
    assert_eq!(m.unused_nodes, 1);
}

#[test]
fn every_form_gmsh_writes_gives_the_same_3d_mesh() {
    let m = same_as_plain(
        3,
        &[
            "bin",
            "ascii-parametric",
            "bin-parametric",
            "ascii-partitioned",
            "bin-partitioned",
        ],
    );
    assert!(m.groups.contains_key("interface") && m.groups.contains_key("bottom"));
}

#[test]
fn an_interior_group_is_read_and_counted() {
    for (dim, measure) in [(2, 2.0), (3, 2.0)] {
        let m = read_msh_bytes(&bytes(&format!("{dim}d-ascii.msh")), "plain").unwrap();
        let interior = m.interior_facets("interface").unwrap();
        let group = m.boundary("interface").unwrap();
        assert_eq!(interior.len(), group.n_facets(), "{dim}D: the interface lies inside");
        assert_eq!(m.check().unwrap().interior_group_facets, group.n_facets());
        let total: f64 = group
            .iter()
            .map(|f| {
                let x: Vec<[f64; 3]> = f.iter().map(|&v| m.points[v]).collect();
                if dim == 2 {
                    ((x[1][0] - x[0][0]).powi(2) + (x[1][1] - x[0][1]).powi(2)).sqrt()
                } else {
                    let (a, b) = (
                        [x[1][0] - x[0][0], x[1][1] - x[0][1], x[1][2] - x[0][2]],
                        [x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]],
                    );
                    0.5 * ((a[1] * b[2] - a[2] * b[1]).powi(2)
                        + (a[2] * b[0] - a[0] * b[2]).powi(2)
                        + (a[0] * b[1] - a[1] * b[0]).powi(2))
                    .sqrt()
                }
            })
            .sum();
        assert!((total - measure).abs() < 1e-12, "{dim}D interface measure {total}");
        assert!(m.interior_facets("bottom").unwrap().is_empty());
    }
}

#[test]
fn a_periodic_mesh_reads_in_both_encodings() {
    let a = read("periodic", &bytes("periodic-ascii.msh"));
    assert_same(&read("periodic", &bytes("periodic-bin.msh")), &a, "periodic-bin");
}

#[test]
fn second_order_files_read_as_the_first_order_mesh_raised_to_order_two() {
    // Gmsh's second-order mesh is its first-order one with a node on every edge: the same as
    // this crate's raising of the first-order file (the cells, groups and regions by their
    // nodes' coordinates); a ten-node tetrahedron's edge nodes in the wrong order would put
    // one off its edge's midpoint, which the check refuses as a curved cell
    for dim in [2, 3] {
        let p2 = read_msh_bytes(&bytes(&format!("{dim}d-ascii-order2.msh")), "order2").unwrap();
        assert_eq!(p2.kind.order(), 2);
        assert_eq!(p2.kind.dim(), dim);
        let p1 = read_msh_bytes(&bytes(&format!("{dim}d-ascii.msh")), "order1").unwrap();
        let (a, b) = (signature(&p2), signature(&p1.quadratic().unwrap()));
        assert_eq!(
            (&a.cells, &a.groups, &a.regions),
            (&b.cells, &b.groups, &b.regions),
            "{dim}D"
        );
    }
}

#[test]
fn a_curved_second_order_cell_reads_as_curved() {
    // an edge node moved off its edge: the cells around it are curved (isoparametric, mapped
    // through their nodes where they are assembled), the others straight
    let text = String::from_utf8(bytes("2d-ascii-order2.msh")).unwrap();
    let m = read_msh_bytes(text.as_bytes(), "order2").unwrap();
    assert!(m.curved_cells().iter().all(|&c| !c));
    let interior = m.cell(0)[4];
    let at = m.points[interior];
    let line = format!("{} {} 0", at[0], at[1]);
    let moved = format!("{} {} 0", at[0] + 0.01, at[1]);
    assert!(text.contains(&line), "{line}");
    let bent = read_msh_bytes(text.replacen(&line, &moved, 1).as_bytes(), "bent.msh").unwrap();
    let curved: Vec<usize> = (0..bent.n_cells()).filter(|&c| bent.curved_cells()[c]).collect();
    assert!(curved.contains(&0) && (1..=2).contains(&curved.len()), "{curved:?}");
}

/// The ASCII forms as other tools and editors leave them: each must read as the file itself.
fn text_variants(text: &str) -> Vec<(&'static str, String)> {
    let crlf = text.replace('\n', "\r\n");
    // runs of spaces and tabs between values, blanks at the ends of lines, blank lines
    let spaced: String = text
        .lines()
        .map(|l| {
            if l.contains('"') {
                // a name keeps its spaces; the numbers before it get tabs
                let (head, name) = l.split_at(l.find('"').unwrap_or(0));
                format!("  {}\t{name}  \n", head.trim().replace(' ', " \t  "))
            } else {
                format!("\t{}  \n", l.replace(' ', "  \t "))
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    // a section of another program between the mesh's sections, and a comment at the end
    let other = text.replacen(
        "$Nodes",
        "$Comments\nwritten by hand: $Nodes $Elements\n$EndComments\n$Nodes",
        1,
    ) + "$MyTool\n1 2 3\n$EndMyTool\n";
    vec![
        ("crlf", crlf),
        ("spaced", spaced.clone()),
        ("crlf-spaced", spaced.replace('\n', "\r\n")),
        ("other-sections", other),
    ]
}

#[test]
fn line_ends_whitespace_and_other_sections_do_not_change_the_mesh() {
    for name in [
        "2d-ascii.msh",
        "2d-ascii-parametric.msh",
        "2d-ascii-partitioned-ghosts.msh",
        "2d-ascii-view.msh",
        "3d-ascii-partitioned.msh",
        "periodic-ascii.msh",
    ] {
        let text = String::from_utf8(bytes(name)).unwrap();
        let plain = read(name, text.as_bytes());
        for (variant, changed) in text_variants(&text) {
            assert_same(&read(variant, changed.as_bytes()), &plain, &format!("{name} {variant}"));
        }
    }
    // the binary header's own line may end in CR LF too, and carry blanks and tabs
    let bin = bytes("2d-bin.msh");
    let at = bin.iter().position(|&b| b == b'\n').unwrap() + 1;
    let line_end = bin[at..].iter().position(|&b| b == b'\n').unwrap() + at;
    let mut changed = b"$MeshFormat\r\n  4.1\t1   8 \r".to_vec();
    changed.extend_from_slice(&bin[line_end..]);
    assert_same(
        &read("bin-crlf-header", &changed),
        &read("bin", &bin),
        "bin-crlf-header",
    );
}
