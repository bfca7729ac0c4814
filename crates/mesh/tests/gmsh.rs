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
