//! Gmsh reader tests on fixtures written by the real Gmsh (see `fixtures/make_meshes.py`):
//! ASCII and binary MSH 4.1, named physical groups, several regions, and broken files.

use mesh::{read_msh, read_msh_bytes, CellKind, MeshError};
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// Total length of a 2D facet group.
fn length(m: &mesh::Mesh, group: &str) -> f64 {
    m.boundary(group)
        .unwrap()
        .iter()
        .map(|f| {
            let (a, b) = (m.points[f[0]], m.points[f[1]]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        })
        .sum()
}

#[test]
fn ascii_2d_with_two_regions() {
    let m = read_msh(fixture("layered2d.msh")).unwrap();
    assert_eq!((m.dim, m.kind), (2, CellKind::Tri3));
    let report = m.check().unwrap();
    assert!((report.total_measure - 2.0).abs() < 1e-12);
    for (g, len) in [("bottom", 2.0), ("top", 2.0), ("left", 1.0), ("right", 1.0)] {
        assert!((length(&m, g) - len).abs() < 1e-12, "{g}");
    }
    // region areas: the layer 0.8 <= y <= 1 and the substrate below it
    let area = |name: &str| -> f64 {
        m.region(name)
            .unwrap()
            .iter()
            .map(|&c| {
                let t = m.cell(c);
                let (a, b, cc) = (m.points[t[0]], m.points[t[1]], m.points[t[2]]);
                0.5 * ((b[0] - a[0]) * (cc[1] - a[1]) - (cc[0] - a[0]) * (b[1] - a[1]))
            })
            .sum()
    };
    assert!((area("pzt") - 0.4).abs() < 1e-12);
    assert!((area("substrate") - 1.6).abs() < 1e-12);
    assert_eq!(m.region("body").unwrap().len(), m.n_cells());
    for &c in m.region("pzt").unwrap() {
        assert!(m.cell(c).iter().all(|&v| m.points[v][1] >= 0.8 - 1e-12));
    }
}

#[test]
fn ascii_quads() {
    let m = read_msh(fixture("quads2d.msh")).unwrap();
    assert_eq!(m.kind, CellKind::Quad4);
    assert!((m.check().unwrap().total_measure - 1.0).abs() < 1e-12);
    assert!((length(&m, "top") - 1.0).abs() < 1e-12);
}

#[test]
fn binary_3d_box() {
    let m = read_msh(fixture("box3d_bin.msh")).unwrap();
    assert_eq!((m.dim, m.kind), (3, CellKind::Tet4));
    assert!((m.check().unwrap().total_measure - 2.0).abs() < 1e-12);
    for (g, area, axis, value) in [
        ("bottom", 2.0, 2, 0.0),
        ("top", 2.0, 2, 1.0),
        ("left", 1.0, 0, 0.0),
        ("right", 1.0, 0, 2.0),
        ("front", 2.0, 1, 0.0),
        ("back", 2.0, 1, 1.0),
    ] {
        let grp = m.boundary(g).unwrap();
        let mut total = 0.0;
        for f in grp.iter() {
            let p: Vec<[f64; 3]> = f.iter().map(|&v| m.points[v]).collect();
            assert!(p.iter().all(|q| (q[axis] - value).abs() < 1e-12), "{g}");
            let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
            let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
            let c = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            total += 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        }
        assert!((total - area).abs() < 1e-12, "{g}: {total}");
    }
}

#[test]
fn broken_files_give_typed_errors() {
    let bytes = std::fs::read(fixture("layered2d.msh")).unwrap();
    // cut short in the middle of the elements
    let cut = &bytes[..bytes.len() * 3 / 4];
    let e = read_msh_bytes(cut, "cut.msh").unwrap_err();
    assert!(matches!(e, MeshError::Gmsh { .. }), "{e}");
    assert!(e.to_string().contains("cut.msh"));
    // not a mesh at all
    let e = read_msh_bytes(b"hello", "x.msh").unwrap_err();
    assert!(e.to_string().contains("does not start with `$MeshFormat`"), "{e}");
    // a missing file
    let e = read_msh(fixture("nope.msh")).unwrap_err();
    assert!(matches!(e, MeshError::Io { .. }));
    // an element that names a node tag that does not exist
    let text = String::from_utf8(bytes.clone()).unwrap();
    let broken = corrupt_last_element(&text);
    let e = read_msh_bytes(broken.as_bytes(), "tag.msh").unwrap_err();
    assert!(e.to_string().contains("node tag 999999"), "{e}");
    // every truncation point gives an error, never a panic
    for cut in (0..bytes.len()).step_by(97) {
        assert!(read_msh_bytes(&bytes[..cut], "cut.msh").is_err());
    }
}

/// Replaces the first node of the last element line with a tag that does not exist.
fn corrupt_last_element(text: &str) -> String {
    let end = text.find("$EndElements").unwrap();
    let before = &text[..end];
    let last_line_start = before.trim_end().rfind('\n').unwrap() + 1;
    let line = before[last_line_start..].trim_end();
    let mut parts: Vec<&str> = line.split_whitespace().collect();
    parts[1] = "999999";
    format!("{}{}\n{}", &text[..last_line_start], parts.join(" "), &text[end..])
}

/// The file with every node tag `t` replaced by `perm(t)`, in `$Nodes` and `$Elements` (ASCII):
/// the same mesh, its nodes listed with their tags out of order.
fn renumber_ascii(text: &str, perm: &dyn Fn(u64) -> u64) -> String {
    let section = |name: &str| {
        let a = text.find(&format!("${name}\n")).unwrap() + name.len() + 2;
        (a, text[a..].find(&format!("$End{name}")).unwrap() + a)
    };
    let ((na, nb), (ea, eb)) = (section("Nodes"), section("Elements"));
    let mut nodes = String::new();
    let mut lines = text[na..nb].lines();
    nodes.push_str(lines.next().unwrap());
    nodes.push('\n');
    while let Some(header) = lines.next() {
        let n: usize = header.split_whitespace().nth(3).unwrap().parse().unwrap();
        nodes.push_str(header);
        nodes.push('\n');
        for _ in 0..n {
            let t: u64 = lines.next().unwrap().trim().parse().unwrap();
            nodes.push_str(&format!("{}\n", perm(t)));
        }
        for _ in 0..n {
            nodes.push_str(lines.next().unwrap());
            nodes.push('\n');
        }
    }
    let mut elements = String::new();
    let mut lines = text[ea..eb].lines();
    elements.push_str(lines.next().unwrap());
    elements.push('\n');
    while let Some(header) = lines.next() {
        let n: usize = header.split_whitespace().nth(3).unwrap().parse().unwrap();
        elements.push_str(header);
        elements.push('\n');
        for _ in 0..n {
            let mut parts = lines.next().unwrap().split_whitespace();
            let tag = parts.next().unwrap().to_string();
            let nodes: Vec<String> = parts.map(|t| perm(t.parse().unwrap()).to_string()).collect();
            elements.push_str(&format!("{tag} {}\n", nodes.join(" ")));
        }
    }
    format!("{}{nodes}{}{elements}{}", &text[..na], &text[nb..ea], &text[eb..])
}

/// The same for a binary file (size_t of 8 bytes, little endian, as Gmsh writes it here).
fn renumber_binary(bytes: &[u8], perm: &dyn Fn(u64) -> u64) -> Vec<u8> {
    let find =
        |from: usize, needle: &[u8]| bytes[from..].windows(needle.len()).position(|w| w == needle).unwrap() + from;
    let mut out = bytes.to_vec();
    let word = |b: &[u8], at: usize| u64::from_le_bytes(b[at..at + 8].try_into().unwrap());
    let int = |b: &[u8], at: usize| i32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let put = |out: &mut Vec<u8>, at: usize| {
        let t = word(bytes, at);
        out[at..at + 8].copy_from_slice(&perm(t).to_le_bytes());
    };
    // $Nodes: 4 words, then blocks of (3 ints, 1 word, n tags, 3 n doubles)
    let mut at = find(find(0, b"$EndEntities"), b"$Nodes\n") + 7;
    let blocks = word(bytes, at);
    at += 32;
    for _ in 0..blocks {
        let n = word(bytes, at + 12) as usize;
        at += 20;
        for k in 0..n {
            put(&mut out, at + 8 * k);
        }
        at += 8 * n + 24 * n;
    }
    // $Elements: 4 words, then blocks of (3 ints, 1 word, n x (tag, nodes))
    let mut at = find(at, b"$Elements\n") + 10;
    let blocks = word(bytes, at);
    at += 32;
    for _ in 0..blocks {
        let kind = int(bytes, at + 8);
        let n = word(bytes, at + 12) as usize;
        at += 20;
        let per = match kind {
            15 => 1, // point
            1 => 2,  // line
            2 => 3,  // triangle
            4 => 4,  // tetrahedron
            other => panic!("element type {other} in the fixture"),
        };
        for _ in 0..n {
            for q in 0..per {
                put(&mut out, at + 8 * (1 + q));
            }
            at += 8 * (1 + per);
        }
    }
    out
}

/// Cells or facets, each as its nodes' (rounded) coordinates, sorted.
type Shapes = Vec<Vec<[i64; 3]>>;

/// The cells of a mesh and of each boundary group as sets of coordinates (independent of the
/// node numbering).
fn geometry(m: &mesh::Mesh) -> (Shapes, Vec<(String, Shapes)>) {
    let key = |v: usize| m.points[v].map(|x| (x * 1e9).round() as i64);
    let sorted = |items: Shapes| {
        let mut items: Shapes = items
            .into_iter()
            .map(|mut c| {
                c.sort();
                c
            })
            .collect();
        items.sort();
        items
    };
    let cells = sorted(m.iter_cells().map(|c| c.iter().map(|&v| key(v)).collect()).collect());
    let groups = m
        .boundaries
        .iter()
        .map(|(name, g)| {
            (
                name.clone(),
                sorted(g.iter().map(|f| f.iter().map(|&v| key(v)).collect()).collect()),
            )
        })
        .collect();
    (cells, groups)
}

/// MSH 4.1 lets a `$Nodes` block list its tags in any order: dense tags reversed, or
/// shuffled, give the same mesh as the file written in order (the reader once gave node `k`
/// the tag `min + k`: a reversed file became a mirrored body), in ASCII and in binary.
#[test]
fn node_tags_in_any_order_give_the_same_mesh() {
    let text = std::fs::read_to_string(fixture("layered2d.msh")).unwrap();
    let original = read_msh(fixture("layered2d.msh")).unwrap();
    let n = original.n_nodes() as u64;
    let reverse = move |t: u64| n + 1 - t;
    // a shuffle of 1..=n: t -> 1 + (t * 37) mod n, a permutation since gcd(37, n) = 1
    assert_ne!(n % 37, 0);
    let shuffle = move |t: u64| 1 + (t * 37) % n;
    for (name, perm) in [("reversed", &reverse as &dyn Fn(u64) -> u64), ("shuffled", &shuffle)] {
        let m = read_msh_bytes(renumber_ascii(&text, perm).as_bytes(), name).unwrap();
        assert_eq!(geometry(&m), geometry(&original), "{name}");
        assert_eq!(m.reoriented_cells, original.reoriented_cells, "{name}");
    }
    let bytes = std::fs::read(fixture("box3d_bin.msh")).unwrap();
    let original = read_msh(fixture("box3d_bin.msh")).unwrap();
    let n = original.n_nodes() as u64;
    let reverse = move |t: u64| n + 1 - t;
    let m = read_msh_bytes(&renumber_binary(&bytes, &reverse), "reversed.msh").unwrap();
    assert_eq!(geometry(&m), geometry(&original));
}

/// A 3D file whose tetrahedra are all inverted (every node mirrored in z) is refused: Gmsh
/// writes positive tetrahedra, so such a file is mirrored or misread.
#[test]
fn a_wholly_inverted_tet_mesh_is_refused() {
    let bytes = std::fs::read(fixture("box3d_bin.msh")).unwrap();
    let m = read_msh_bytes(&bytes, "box.msh").unwrap();
    assert_eq!(m.reoriented_cells, 0);
    // swap two nodes of every tetrahedron: all inverted
    let find =
        |from: usize, needle: &[u8]| bytes[from..].windows(needle.len()).position(|w| w == needle).unwrap() + from;
    let mut out = bytes.clone();
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    let mut at = find(0, b"$Elements\n") + 10;
    let blocks = word(at);
    at += 32;
    for _ in 0..blocks {
        let kind = i32::from_le_bytes(bytes[at + 8..at + 12].try_into().unwrap());
        let n = word(at + 12) as usize;
        at += 20;
        let per = [0, 2, 3, 0, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1][kind as usize];
        for _ in 0..n {
            if kind == 4 {
                let (a, b) = (at + 8, at + 16);
                out[a..a + 8].copy_from_slice(&bytes[b..b + 8]);
                out[b..b + 8].copy_from_slice(&bytes[a..a + 8]);
            }
            at += 8 * (1 + per);
        }
    }
    let e = read_msh_bytes(&out, "mirrored.msh").unwrap_err().to_string();
    assert!(e.contains("tetrahedra are inverted"), "{e}");
}

/// Two physical groups of one name (on one curve, or on two) are one group: the union of
/// their facets, each once (listed twice, a facet would count its load or contact twice).
#[test]
fn physical_groups_of_one_name_are_one_group() {
    let m = read_msh(fixture("duplicate-group.msh")).unwrap();
    let g = m.boundary("bottom").unwrap();
    let mut keys: Vec<Vec<usize>> = g
        .iter()
        .map(|f| {
            let mut k = f.to_vec();
            k.sort_unstable();
            k
        })
        .collect();
    let n = keys.len();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), n, "each facet once");
    assert!((length(&m, "bottom") - 2.0).abs() < 1e-12);
}

/// A file whose cells of highest dimension are triangles that do not lie in one plane (a 3D
/// body saved without its volume cells: Gmsh writes only the elements of physical groups) is
/// refused as a surface, naming the missing volume group, not as a 2D mesh off its plane.
#[test]
fn a_surface_without_its_volume_is_named_so() {
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
        $Entities\n0 0 1 0\n1 0 0 0 1 1 1 0 0\n$EndEntities\n\
        $Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n\
        $Elements\n1 4 1 4\n2 1 2 4\n1 1 3 2\n2 1 2 4\n3 2 3 4\n4 3 1 4\n$EndElements\n";
    let e = read_msh_bytes(text.as_bytes(), "surface.msh").unwrap_err().to_string();
    assert!(
        e.contains("a surface, not a body") && e.contains("Physical Volume"),
        "{e}"
    );
}

/// A flat 2D mesh drawn in another plane than z = const is told so, with the plane's normal.
#[test]
fn a_flat_mesh_off_the_xy_plane_is_named_so() {
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
        $Entities\n0 0 1 0\n1 0 0 0 1 0 1 0 0\n$EndEntities\n\
        $Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 0 1\n0 0 1\n$EndNodes\n\
        $Elements\n1 2 1 2\n2 1 2 2\n1 1 2 3\n2 1 3 4\n$EndElements\n";
    let e = read_msh_bytes(text.as_bytes(), "xz.msh").unwrap_err().to_string();
    let plane = e.contains("[0.000, -1.000, 0.000]") || e.contains("[0.000, 1.000, 0.000]");
    assert!(e.contains("draw the 2D body in the x-y plane") && plane, "{e}");
}

/// A group asked for as a boundary group that the mesh has as something else (a region, or
/// a file's group of points or of curves in 3D, which the mesh does not use) is named so.
#[test]
fn a_group_of_another_kind_is_named_where_it_is_asked_for() {
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
        $PhysicalNames\n3\n0 1 \"corner\"\n1 2 \"bottom\"\n2 3 \"body\"\n$EndPhysicalNames\n\
        $Entities\n1 1 1 0\n1 0 0 0 1 1\n1 0 0 0 1 0 0 1 2 0\n1 0 0 0 1 1 0 1 3 0\n$EndEntities\n\
        $Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n\
        $Elements\n3 4 1 4\n0 1 15 1\n1 1\n1 1 1 1\n2 1 2\n2 1 2 2\n3 1 2 3\n4 1 3 4\n$EndElements\n";
    let m = read_msh_bytes(text.as_bytes(), "square.msh").unwrap();
    assert!(m.boundary("bottom").is_ok());
    let e = m.boundary("corner").unwrap_err().to_string();
    assert!(e.contains("`corner` is a group of points (dimension 0)"), "{e}");
    let e = m.boundary("body").unwrap_err().to_string();
    assert!(e.contains("`body` is a region"), "{e}");
    let e = m.region("bottom").unwrap_err().to_string();
    assert!(e.contains("`bottom` is a boundary group"), "{e}");
    let e = m.boundary("nothing").unwrap_err().to_string();
    assert!(e.ends_with("(the mesh has: bottom)"), "{e}");
}
