//! Structured generators: a rectangle into P1 triangles or Q1 quadrilaterals, a box into P1
//! tetrahedra (Kuhn split), with named boundary groups and the region `body`.

use crate::{CellKind, FacetGroup, Mesh};
use std::collections::BTreeMap;

/// The rectangle `[lo, hi]` cut into `nx x ny` squares, each split along its SW-NE diagonal
/// into the P1 triangles `(n00, n10, n11)` and `(n00, n11, n01)` (docs/scenes.md, `paper`).
///
/// Node `(i, j)` has index `j (nx + 1) + i`. Boundary groups `left`, `right`, `bottom`, `top`
/// hold segments ordered counter-clockwise around the rectangle; the region `body` holds every
/// cell. `nx` and `ny` are clamped to at least 1.
pub fn rectangle_tri(lo: [f64; 2], hi: [f64; 2], nx: usize, ny: usize) -> Mesh {
    // the whole rectangle is the one piece of one rank: one generator for both
    let blocks = crate::Blocks {
        dim: 2,
        n: [nx.max(1), ny.max(1), 1],
        p: [1, 1, 1],
    };
    blocks.rectangle_piece(lo, hi, 0).mesh
}

/// The rectangle `[lo, hi]` cut into `nx x ny` Q1 quadrilaterals `(n00, n10, n11, n01)`,
/// with the same nodes, groups and region as [`rectangle_tri`].
pub fn rectangle_quad(lo: [f64; 2], hi: [f64; 2], nx: usize, ny: usize) -> Mesh {
    let (nx, ny) = (nx.max(1), ny.max(1));
    let mut cells = Vec::with_capacity(4 * nx * ny);
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    for j in 0..ny {
        for i in 0..nx {
            cells.extend_from_slice(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    rectangle(lo, hi, nx, ny, CellKind::Quad4, cells)
}

fn rectangle(lo: [f64; 2], hi: [f64; 2], nx: usize, ny: usize, kind: CellKind, cells: Vec<usize>) -> Mesh {
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut points = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            points.push([lerp(lo[0], hi[0], i, nx), lerp(lo[1], hi[1], j, ny), 0.0]);
        }
    }
    let seg = |pairs: Vec<(usize, usize)>| FacetGroup {
        nodes_per_facet: 2,
        facets: pairs.into_iter().flat_map(|(a, b)| [a, b]).collect(),
    };
    let mut boundaries = BTreeMap::new();
    boundaries.insert(
        "bottom".into(),
        seg((0..nx).map(|i| (id(i, 0), id(i + 1, 0))).collect()),
    );
    boundaries.insert(
        "right".into(),
        seg((0..ny).map(|j| (id(nx, j), id(nx, j + 1))).collect()),
    );
    boundaries.insert(
        "top".into(),
        seg((0..nx).rev().map(|i| (id(i + 1, ny), id(i, ny))).collect()),
    );
    boundaries.insert(
        "left".into(),
        seg((0..ny).rev().map(|j| (id(0, j + 1), id(0, j))).collect()),
    );
    let n_cells = cells.len() / kind.n_nodes();
    let mut regions = BTreeMap::new();
    regions.insert("body".into(), (0..n_cells).collect());
    Mesh {
        dim: 2,
        kind,
        points,
        cells,
        boundaries,
        regions,
        reoriented_cells: 0,
        other_groups: Default::default(),
    }
}

/// The box `[lo, hi]` cut into `nx x ny x nz` cubes, each split into the six Kuhn tetrahedra
/// `(v000, v000 + e_p1, v000 + e_p1 + e_p2, v111)`, one per order `(p1, p2, p3)` of the axes
/// (docs/scenes.md, `paper-3d`), stored positively oriented. The split is conforming, and every
/// face is cut along the diagonal joining its lowest and highest corners (SW-NE).
///
/// Node `(i, j, k)` has index `(k (ny + 1) + j)(nx + 1) + i`. Boundary groups: `left`/`right`
/// (x = lo/hi), `front`/`back` (y = lo/hi), `bottom`/`top` (z = lo/hi), triangles ordered so
/// that their right-hand normal points out of the box. Region: `body`.
pub fn box_tet(lo: [f64; 3], hi: [f64; 3], nx: usize, ny: usize, nz: usize) -> Mesh {
    // the whole box is the one piece of one rank: one generator for both
    let blocks = crate::Blocks {
        dim: 3,
        n: [nx.max(1), ny.max(1), nz.max(1)],
        p: [1, 1, 1],
    };
    blocks.box_piece(lo, hi, 0).mesh
}

/// `lo + (hi - lo) i / n`, exact at both ends.
pub(crate) fn lerp(lo: f64, hi: f64, i: usize, n: usize) -> f64 {
    if i == n {
        hi
    } else {
        lo + (hi - lo) * (i as f64 / n as f64)
    }
}

pub(crate) fn signed_volume(points: &[[f64; 3]], t: &[usize]) -> f64 {
    let p0 = points[t[0]];
    let d = |q: usize, k: usize| points[t[q]][k] - p0[k];
    let (a, b, c) = (
        [d(1, 0), d(1, 1), d(1, 2)],
        [d(2, 0), d(2, 1), d(2, 2)],
        [d(3, 0), d(3, 1), d(3, 2)],
    );
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0
}

pub(crate) fn triangle_normal(points: &[[f64; 3]], t: &[usize]) -> [f64; 3] {
    let p0 = points[t[0]];
    let u = [
        points[t[1]][0] - p0[0],
        points[t[1]][1] - p0[1],
        points[t[1]][2] - p0[2],
    ];
    let v = [
        points[t[2]][0] - p0[0],
        points[t[2]][1] - p0[1],
        points[t[2]][2] - p0[2],
    ];
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_counts_and_split() {
        let m = rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2);
        assert_eq!(m.n_nodes(), 15);
        assert_eq!(m.n_cells(), 16);
        // the first square's two triangles, SW-NE
        assert_eq!(m.cell(0), &[0, 1, 6]);
        assert_eq!(m.cell(1), &[0, 6, 5]);
        let r = m.check().unwrap();
        assert!((r.total_measure - 2.0).abs() < 1e-14);
        for (name, len) in [("bottom", 4), ("top", 4), ("left", 2), ("right", 2)] {
            assert_eq!(m.boundary(name).unwrap().n_facets(), len, "{name}");
        }
        let q = rectangle_quad([0.0, 0.0], [2.0, 1.0], 4, 2);
        assert!((q.check().unwrap().total_measure - 2.0).abs() < 1e-14);
    }

    #[test]
    fn box_is_conforming_and_oriented() {
        let m = box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2);
        assert_eq!(m.n_cells(), 6 * 16);
        let r = m.check().unwrap();
        assert!((r.total_measure - 2.0).abs() < 1e-13);
        // conforming: every interior face is shared by exactly two tets, boundary faces by one,
        // and the boundary faces are exactly the union of the six groups.
        let mut faces = std::collections::HashMap::new();
        for c in m.iter_cells() {
            for skip in 0..4 {
                let mut f: Vec<usize> = (0..4).filter(|&q| q != skip).map(|q| c[q]).collect();
                f.sort_unstable();
                *faces.entry(f).or_insert(0) += 1;
            }
        }
        let boundary: Vec<_> = faces.iter().filter(|(_, &k)| k == 1).map(|(f, _)| f.clone()).collect();
        assert!(faces.values().all(|&k| k == 1 || k == 2));
        let mut from_groups: Vec<Vec<usize>> = m
            .boundaries
            .values()
            .flat_map(|g| {
                g.iter().map(|f| {
                    let mut f = f.to_vec();
                    f.sort_unstable();
                    f
                })
            })
            .collect();
        from_groups.sort();
        let mut boundary = boundary;
        boundary.sort();
        assert_eq!(from_groups, boundary);
        // bottom faces point down
        let b = m.boundary("bottom").unwrap();
        for f in b.iter() {
            assert!(triangle_normal(&m.points, f)[2] < 0.0);
        }
    }
}

/// Makes the section `[0, r]²` of a 3D mesh (its x and y, any `r`) a quarter of the disc of
/// radius `r` about the z axis: each point moves along its ray from the axis, from distance `ρ` to
/// `ρ max(|cos θ|, |sin θ|)` (the squares `max(x, y) = s` become the circles of radius `s`).
/// The faces x = 0 and y = 0 stay in place, x = r and y = r become the cylinder's face. The
/// map keeps the polar angle and stretches the radius by a factor in `[1/√2, 1]` with positive
/// Jacobian `max(|cos θ|, |sin θ|)²` on each side of the diagonal, so no cell turns over.
pub fn round_quarter_section(mesh: &mut Mesh) {
    for p in &mut mesh.points {
        let (x, y) = (p[0], p[1]);
        let rho = x.hypot(y);
        if rho > 0.0 {
            let f = x.abs().max(y.abs()) / rho;
            p[0] = x * f;
            p[1] = y * f;
        }
    }
}

#[cfg(test)]
mod round_tests {
    use super::*;

    #[test]
    fn a_rounded_box_is_a_quarter_cylinder_with_no_cell_turned() {
        let mut m = box_tet([0.0; 3], [2.0, 2.0, 1.0], 6, 6, 3);
        let before: Vec<f64> = (0..m.n_cells()).map(|c| signed_volume(&m.points, m.cell(c))).collect();
        round_quarter_section(&mut m);
        for face in ["right", "back"] {
            for v in m.boundary(face).unwrap().nodes() {
                let p = m.points[v];
                assert!((p[0].hypot(p[1]) - 2.0).abs() < 1e-14, "{face}: {p:?}");
            }
        }
        for v in m.boundary("left").unwrap().nodes() {
            assert_eq!(m.points[v][0], 0.0);
        }
        // every cell keeps its orientation, and the volume is the quarter cylinder's (its
        // polygonal section a little short of the disc)
        let after: Vec<f64> = (0..m.n_cells()).map(|c| signed_volume(&m.points, m.cell(c))).collect();
        assert!(before
            .iter()
            .zip(&after)
            .all(|(b, a)| b.signum() == a.signum() && a.abs() > 0.0));
        let volume: f64 = after.iter().map(|v| v.abs()).sum();
        let quarter = std::f64::consts::PI;
        assert!(
            volume < quarter && volume > 0.98 * quarter,
            "{volume} against {quarter}"
        );
    }
}
