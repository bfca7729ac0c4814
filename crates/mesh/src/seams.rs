//! Seams: boundary facets that lie on other boundary facets, where a mesh glued from parts
//! that were not merged is cut (Gmsh meshes two surfaces apart unless they are fragmented:
//! their common curve becomes two, with nodes that match or not). The body is then two bodies
//! there, held together nowhere along the seam: a crack, meant or not.

use crate::generate::triangle_normal;
use crate::topology::Key;
use crate::Mesh;
use std::collections::HashMap;

impl Mesh {
    /// The boundary facets (those of one cell) whose centroid lies on another boundary facet:
    /// their number and their total length (2D) or area (3D). Matching seams (duplicated
    /// nodes) and non-matching ones (nodes of one side on the other side's edges) alike.
    pub fn seam_facets(&self) -> (usize, f64) {
        self.seams_of(&self.cell_facets())
    }

    /// [`Mesh::seam_facets`] from the cells' facets, sorted ([`Mesh::cell_facets`]).
    pub(crate) fn seams_of(&self, facets: &[(Key, usize)]) -> (usize, f64) {
        let corners = self.kind.facet_corners();
        let boundary: Vec<&[usize]> = facets
            .chunk_by(|a, b| a.0 == b.0)
            .filter(|run| run.len() == 1)
            .map(|run| &run[0].0[..corners])
            .collect();
        let at_corner = |f: &[usize], q: usize| &self.points[f[q]];
        let size = |f: &[usize]| {
            (1..corners)
                .map(|q| crate::dist(at_corner(f, 0), at_corner(f, q)))
                .fold(0.0, f64::max)
        };
        // a grid of cells about the longest facet's size: a facet is listed in every grid cell
        // its bounding box meets, a centroid looked up in its own
        let cell = boundary
            .iter()
            .map(|f| size(f))
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let at = |x: &[f64; 3]| x.map(|c| (c / cell).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (k, f) in boundary.iter().enumerate() {
            let bound = |pick: fn(f64, f64) -> f64| -> [f64; 3] {
                std::array::from_fn(|d| f.iter().map(|&v| self.points[v][d]).reduce(pick).unwrap_or(0.0))
            };
            let (a, b) = (at(&bound(f64::min)), at(&bound(f64::max)));
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        grid.entry([x, y, z]).or_default().push(k);
                    }
                }
            }
        }
        let (mut count, mut measure) = (0, 0.0);
        for (k, f) in boundary.iter().enumerate() {
            let centroid: [f64; 3] =
                std::array::from_fn(|d| f.iter().map(|&v| self.points[v][d]).sum::<f64>() / corners as f64);
            let on_another = grid.get(&at(&centroid)).is_some_and(|near| {
                (near.iter()).any(|&g| g != k && self.holds(boundary[g], &centroid, 1e-9 * size(boundary[g])))
            });
            if on_another {
                count += 1;
                measure += match corners {
                    2 => crate::dist(at_corner(f, 0), at_corner(f, 1)),
                    _ => 0.5 * norm(&triangle_normal(&self.points, f)),
                };
            }
        }
        (count, measure)
    }

    /// Whether the facet of corners `f` (a segment of 2, a triangle of 3) holds the point `x`,
    /// to the distance `tol`.
    fn holds(&self, f: &[usize], x: &[f64; 3], tol: f64) -> bool {
        let o = &self.points[f[0]];
        let (e1, r) = (sub(&self.points[f[1]], o), sub(x, o));
        if f.len() == 2 {
            let t = dot(&r, &e1) / dot(&e1, &e1);
            let off: [f64; 3] = std::array::from_fn(|d| r[d] - t * e1[d]);
            return (0.0..=1.0).contains(&t) && norm(&off) <= tol;
        }
        let e2 = sub(&self.points[f[2]], o);
        let n = triangle_normal(&self.points, f);
        if dot(&r, &n).abs() / norm(&n) > tol {
            return false;
        }
        // barycentric coordinates in the facet's plane
        let (a, b, c) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
        let (p, q) = (dot(&r, &e1), dot(&r, &e2));
        let det = a * c - b * b;
        let (s, t) = ((c * p - b * q) / det, (a * q - b * p) / det);
        let slack = 1e-9;
        s >= -slack && t >= -slack && s + t <= 1.0 + slack
    }
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|d| a[d] - b[d])
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|d| a[d] * b[d]).sum()
}

fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use crate::{box_tet, rectangle_tri, Mesh, MeshParts};

    /// Two meshes side by side in one, their nodes not merged (as Gmsh writes two surfaces or
    /// volumes it did not fragment).
    fn glued(a: &Mesh, b: &Mesh) -> Mesh {
        let shift = a.n_nodes();
        let mut points = a.points.clone();
        points.extend(&b.points);
        let mut cells = a.cells.clone();
        cells.extend(b.cells.iter().map(|v| v + shift));
        Mesh::from_parts(MeshParts {
            dim: a.dim,
            points,
            cells,
            nodes_per_cell: a.kind.n_nodes(),
            boundaries: Default::default(),
            regions: Default::default(),
        })
        .unwrap()
    }

    /// A seam is found whether its nodes match (a crack of duplicated nodes) or not (one
    /// side's nodes on the other side's edges), both sides of it, and nothing on a mesh that is
    /// one piece: the 2 x 1 block glued at x = 1 has a seam of length 1 on each side.
    #[test]
    fn a_seam_is_found_matching_or_not_and_nowhere_else() {
        let left = rectangle_tri([0.0, 0.0], [1.0, 1.0], 4, 4);
        for (right, facets) in [
            (rectangle_tri([1.0, 0.0], [2.0, 1.0], 4, 4), 8),
            (rectangle_tri([1.0, 0.0], [2.0, 1.0], 3, 3), 7),
        ] {
            let (n, length) = glued(&left, &right).seam_facets();
            assert_eq!(n, facets);
            assert!((length - 2.0).abs() < 1e-12, "{length}");
        }
        assert_eq!(rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4).seam_facets(), (0, 0.0));
        // 3D: two unit cubes glued at x = 1, their faces matching or not
        let cube = box_tet([0.0; 3], [1.0; 3], 2, 2, 2);
        for (other, facets) in [
            (box_tet([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], 2, 2, 2), 16),
            (box_tet([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], 3, 3, 3), 8 + 18),
        ] {
            let (n, area) = glued(&cube, &other).seam_facets();
            assert!(n == facets && (area - 2.0).abs() < 1e-12, "{n} facets, area {area}");
        }
        assert_eq!(box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2).seam_facets(), (0, 0.0));
    }
}
