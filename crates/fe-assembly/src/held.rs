//! What the Dirichlet conditions hold: every connected part of the mesh must have its rigid
//! motions and, where it carries a potential, its potential fixed, or `K` is singular.
//!
//! The paper's theory (its `Γ1` of positive measure, which makes the displacement space a
//! Hilbert space with Korn's inequality; its `Γa` for the potential) assumes this, and every
//! solve here needs `A` and `B` invertible: contact alone does not hold a body. A body held
//! only by contact (sides on rollers, nothing fixing the vertical translation) is refused
//! here, before any factorisation, with the motion that is free, instead of failing as a
//! pivot somewhere in a sparse factor.
//!
//! The test: the infinitesimal rigid motions of a part (cells joined through facets), `r(x) = a + ω × (x - c)` (3 in 2D: two
//! translations and the rotation about z; 6 in 3D), are held when the only one that vanishes
//! on every prescribed component of the part's nodes is zero. Each prescribed component
//! `(node, k)` gives a linear condition `r_k(x_node) = 0` on `(a, ω)`; the part's motions are
//! held when these conditions have full rank, judged on the eigenvalues of their Gram matrix
//! (coordinates taken from the part's centroid and scaled by its size, so that the test is
//! independent of units and position).
//!
//! A compliant bed holds a body too, along its normal only: [`check_with`] counts each bed
//! point's normal component as a condition `r(x_node) · n = 0`, and says whether the body
//! needs the bed ([`Held::WithSupports`]: the solver then holds it with springs it takes out
//! again) and, where the bed too leaves a motion free, which.

use crate::{Coordinates, Dof, DofMap};
use mesh::Mesh;
use nalgebra::{DMatrix, SymmetricEigen};

/// A part of the mesh the Dirichlet conditions leave free.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Unheld {
    /// Rigid motions of a part are free.
    #[error(
        "{by} leave {count} rigid motion{s} of the body free ({motions}) in its part with cell \
         {cell} ({cells} cells): {why}; prescribe that motion on a boundary group, e.g. the \
         component along it on a face that contact does not need",
        s = if *count == 1 { "" } else { "s" },
        by = if *with_supports { "the Dirichlet conditions and the compliant bed" } else { "the Dirichlet conditions" },
        why = if *with_supports {
            "a compliant bed holds a body along its normal only, and friction holds nothing in \
             this solver (every solve needs the stiffness invertible)"
        } else {
            "a rigid foundation's contact does not hold a body in this solver (the paper's Γ1 has \
             positive measure: every solve needs the stiffness invertible; a compliant bed, \
             contact.compliance, would hold it along the bed's normal)"
        }
    )]
    Motion {
        /// How many independent motions are free.
        count: usize,
        /// Each free motion, in words.
        motions: String,
        /// A cell of the part.
        cell: usize,
        /// The part's number of cells.
        cells: usize,
        /// Whether a compliant bed's supports were counted.
        with_supports: bool,
    },
    /// The potential of an electric part is free (no condition on φ reaches it).
    #[error(
        "the potential is floating in the electric part with cell {cell} ({cells} cells): no \
         Dirichlet condition on φ reaches it, so it is fixed only up to a constant; prescribe φ \
         on a group of that part (an electrode at 0 V, say)"
    )]
    Potential {
        /// A cell of the part.
        cell: usize,
        /// The part's number of cells.
        cells: usize,
    },
}

/// The rigid-motion parameters `(a, ω)` of component `k` at the scaled point `y`: the row of
/// the condition `r_k(y) = 0` (2D: `a = (a_x, a_y)`, `ω` about z; 3D: `a`, `ω` in R³).
fn rigid_row(dim: usize, k: usize, y: [f64; 3]) -> Vec<f64> {
    if dim == 2 {
        // r = (a_x - ω y, a_y + ω x)
        match k {
            0 => vec![1.0, 0.0, -y[1]],
            _ => vec![0.0, 1.0, y[0]],
        }
    } else {
        // r = a + ω × y
        let mut row = vec![0.0; 6];
        row[k] = 1.0;
        let (w, cross) = match k {
            0 => ([1, 2], [y[2], -y[1]]), // ω_y z - ω_z y
            1 => ([2, 0], [y[0], -y[2]]), // ω_z x - ω_x z
            _ => ([0, 1], [y[1], -y[0]]), // ω_x y - ω_y x
        };
        row[3 + w[0]] = cross[0];
        row[3 + w[1]] = cross[1];
        row
    }
}

/// A free rigid motion in words, from its scaled parameters `v` about the centroid `c` of a
/// part of size `size`.
fn describe(dim: usize, v: &[f64], c: [f64; 3], size: f64) -> String {
    let fmt = |x: &[f64]| {
        let n = x.iter().map(|a| a * a).sum::<f64>().sqrt();
        // round-off below the printed digits shown as 0, without a sign
        let parts: Vec<String> = x.iter().map(|a| format!("{:.3}", snap(a / n, 1.0))).collect();
        format!("[{}]", parts.join(", "))
    };
    let (a, w) = v.split_at(dim);
    let (na, nw) = (
        a.iter().map(|x| x * x).sum::<f64>().sqrt(),
        w.iter().map(|x| x * x).sum::<f64>().sqrt(),
    );
    if nw <= 1e-6 * na {
        return format!("a translation along {}", fmt(a));
    }
    if dim == 2 {
        // a_x - ω y = -ω (y - p_y), a_y + ω x = ω (x - p_x): p = (-a_y / ω, a_x / ω)
        let p = [c[0] - size * a[1] / w[0], c[1] + size * a[0] / w[0]];
        return format!(
            "a rotation about the point ({:.4e}, {:.4e})",
            snap(p[0], size),
            snap(p[1], size)
        );
    }
    // a = -ω × p + t ω: p = ω × a / |ω|²
    let p = [
        (w[1] * a[2] - w[2] * a[1]) / (nw * nw),
        (w[2] * a[0] - w[0] * a[2]) / (nw * nw),
        (w[0] * a[1] - w[1] * a[0]) / (nw * nw),
    ];
    let slide = (a[0] * w[0] + a[1] * w[1] + a[2] * w[2]).abs() / (na.max(f64::MIN_POSITIVE) * nw);
    format!(
        "a rotation about the axis along {} through ({:.4e}, {:.4e}, {:.4e}){}",
        fmt(w),
        snap(c[0] + size * p[0], size),
        snap(c[1] + size * p[1], size),
        snap(c[2] + size * p[2], size),
        if slide > 1e-6 && na > 1e-6 * nw {
            ", with a slide along it"
        } else {
            ""
        }
    )
}

/// `x`, or 0 where it is round-off next to `scale`.
fn snap(x: f64, scale: f64) -> f64 {
    if x.abs() <= 1e-9 * scale {
        0.0
    } else {
        x
    }
}

/// Below this fraction of the largest eigenvalue of the conditions' Gram matrix, a rigid
/// motion is free (the Gram matrix is a sum of unit-scale rows: its eigenvalues are at least
/// one for a held motion held by one node, and grow with the nodes; a motion held only by a
/// lever of 1e-6 of the part's size is free in double precision anyway).
const FREE: f64 = 1e-12;

/// Checks that every solid part of the mesh ([`Mesh::solid_parts`]) has its rigid motions
/// held by the prescribed displacement components of its nodes, and every electric part
/// (joined by the `cell_electric` cells through any node) its potential by a prescribed φ.
///
/// # Errors
/// [`Unheld::Motion`] with the free motions of the first part that has any, or
/// [`Unheld::Potential`].
///
/// A body of revolution ([`Coordinates::Axisymmetric`]) has one rigid motion, the translation along its axis
/// (a radial one strains the hoops).
pub fn check(mesh: &Mesh, dofs: &DofMap, cell_electric: &[bool], coordinates: Coordinates) -> Result<(), Unheld> {
    check_with(mesh, dofs, cell_electric, coordinates, &[]).map(|_| ())
}

/// A support along one direction at a node: a compliant bed's hold on its point, along the
/// bed's normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Support {
    /// The node.
    pub node: usize,
    /// The direction it holds (a unit vector).
    pub direction: [f64; 3],
}

/// What holds the body's rigid motions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Held {
    /// The Dirichlet conditions alone.
    ByConditions,
    /// The Dirichlet conditions with the supports: some motion the conditions leave free, the
    /// supports hold.
    WithSupports,
}

/// [`check`], the `supports` counted as holding their nodes along their directions where the
/// Dirichlet conditions alone leave a motion free.
///
/// # Errors
/// As [`check`]; [`Unheld::Motion`] names the motions that the conditions and the supports
/// together leave free (`with_supports` where there are supports).
pub fn check_with(
    mesh: &Mesh,
    dofs: &DofMap,
    cell_electric: &[bool],
    coordinates: Coordinates,
    supports: &[Support],
) -> Result<Held, Unheld> {
    let solids = Solids::new(mesh);
    let mut held = Held::ByConditions;
    for i in 0..solids.first.len() {
        let free = |with: &[Support]| {
            if coordinates == Coordinates::Axisymmetric {
                solids.free_axial_motion(dofs, i, with)
            } else {
                solids.free_motions(mesh, dofs, i, with)
            }
        };
        let mut motions = free(&[]);
        if !motions.is_empty() && !supports.is_empty() {
            motions = free(supports);
            held = Held::WithSupports;
        }
        if !motions.is_empty() {
            return Err(Unheld::Motion {
                count: motions.len(),
                motions: motions.join("; "),
                cell: solids.first[i],
                cells: solids.cells[i],
                with_supports: !supports.is_empty(),
            });
        }
    }
    floating_potential(mesh, dofs, cell_electric)?;
    Ok(held)
}

/// The solid parts of a mesh with their nodes, centroids and sizes.
struct Solids {
    /// `(part, node)`, sorted: each node once in its first cell's part, and again in any other
    /// part it hinges; part `i`'s at `members[start[i]..start[i + 1]]`.
    members: Vec<(usize, usize)>,
    start: Vec<usize>,
    /// Each part's first cell and number of cells.
    first: Vec<usize>,
    cells: Vec<usize>,
    /// Each part's centroid and largest extent.
    centroid: Vec<[f64; 3]>,
    size: Vec<f64>,
}

impl Solids {
    /// The supports at nodes of part `i`.
    fn supports_of<'s>(&self, i: usize, supports: &'s [Support]) -> impl Iterator<Item = &'s Support> + use<'s, '_> {
        let members = &self.members[self.start[i]..self.start[i + 1]];
        supports
            .iter()
            .filter(move |s| members.binary_search(&(i, s.node)).is_ok())
    }

    fn new(mesh: &Mesh) -> Self {
        let dim = mesh.dim;
        let (cell_part, n_parts) = mesh.solid_parts();
        let mut node_part = vec![usize::MAX; mesh.n_nodes()];
        let mut hinges = vec![];
        for (c, cell) in mesh.iter_cells().enumerate() {
            let p = cell_part[c];
            for &v in cell {
                if node_part[v] == usize::MAX {
                    node_part[v] = p;
                } else if node_part[v] != p {
                    hinges.push((p, v));
                }
            }
        }
        hinges.sort_unstable();
        hinges.dedup();
        let mut members: Vec<(usize, usize)> = (0..mesh.n_nodes())
            .filter(|&v| node_part[v] != usize::MAX)
            .map(|v| (node_part[v], v))
            .chain(hinges)
            .collect();
        members.sort_unstable();
        let mut start = vec![0usize; n_parts + 1];
        for &(p, _) in &members {
            start[p + 1] += 1;
        }
        for p in 0..n_parts {
            start[p + 1] += start[p];
        }
        let (mut first, mut cells) = (vec![usize::MAX; n_parts], vec![0usize; n_parts]);
        for (c, &p) in cell_part.iter().enumerate() {
            first[p] = first[p].min(c);
            cells[p] += 1;
        }
        let mut count = vec![0usize; n_parts];
        let mut centroid = vec![[0.0; 3]; n_parts];
        let (mut lo, mut hi) = (vec![[f64::INFINITY; 3]; n_parts], vec![[f64::NEG_INFINITY; 3]; n_parts]);
        for &(i, v) in &members {
            let x = mesh.points[v];
            count[i] += 1;
            for k in 0..dim {
                centroid[i][k] += x[k];
                lo[i][k] = lo[i][k].min(x[k]);
                hi[i][k] = hi[i][k].max(x[k]);
            }
        }
        for (i, c) in centroid.iter_mut().enumerate() {
            c.iter_mut().for_each(|x| *x /= count[i] as f64);
        }
        // the largest extent (a sum of squares would underflow on a mesh in units of 1e-170)
        let size = (0..n_parts)
            .map(|i| (0..dim).map(|k| hi[i][k] - lo[i][k]).fold(f64::MIN_POSITIVE, f64::max))
            .collect();
        Solids {
            members,
            start,
            first,
            cells,
            centroid,
            size,
        }
    }

    /// The translation along the axis of part `i` of a body of revolution, in words, where no
    /// prescribed axial component holds it.
    fn free_axial_motion(&self, dofs: &DofMap, i: usize, supports: &[Support]) -> Vec<String> {
        let held = self.members[self.start[i]..self.start[i + 1]]
            .iter()
            .any(|&(_, v)| matches!(dofs.u[v * 2 + 1], Dof::Fixed(_)))
            || self.supports_of(i, supports).any(|s| s.direction[1].abs() > 1e-6);
        if held {
            vec![]
        } else {
            vec!["a translation along the axis [0, 1]".into()]
        }
    }

    /// The rigid motions of part `i` that its prescribed components leave free, in words:
    /// the null space of the Gram matrix of the conditions they put on its motions.
    fn free_motions(&self, mesh: &Mesh, dofs: &DofMap, i: usize, supports: &[Support]) -> Vec<String> {
        let dim = dofs.dim;
        let frame = (self.centroid[i], self.size[i]);
        let members = self.members[self.start[i]..self.start[i + 1]].iter().map(|&(_, v)| v);
        let mut gram = gram_of(mesh, dofs, members, frame);
        // a support's condition: the motion's component along its direction, r(x) · n = 0
        for s in self.supports_of(i, supports) {
            let mut row = nalgebra::DVector::<f64>::zeros(gram.nrows());
            for k in 0..dim {
                row +=
                    nalgebra::DVector::from_vec(rigid_row(dim, k, scaled(mesh, s.node, frame, dim))) * s.direction[k];
            }
            gram += &row * row.transpose();
        }
        free_of(dim, gram, frame)
    }
}

/// Node `v`'s coordinates about the centre `c` of a part of size `size`, over that size.
fn scaled(mesh: &Mesh, v: usize, (c, size): ([f64; 3], f64), dim: usize) -> [f64; 3] {
    std::array::from_fn(|k| {
        if k < dim {
            (mesh.points[v][k] - c[k]) / size
        } else {
            0.0
        }
    })
}

/// The Gram matrix of the rigid-motion conditions that the prescribed displacement components
/// of `nodes` make (one row per component, `r_k(x) = 0`), about the centre `c` of a part of size
/// `size`, flat (column by column; 3 x 3 in 2D, 6 x 6 in 3D). A sum over the nodes: the Gram
/// matrix of a part held in pieces (the ranks of a parallel run, each with its own nodes) is
/// its pieces' sum, judged by [`free_in`].
pub fn rigid_gram(mesh: &Mesh, dofs: &DofMap, nodes: impl Iterator<Item = usize>, frame: ([f64; 3], f64)) -> Vec<f64> {
    gram_of(mesh, dofs, nodes, frame).as_slice().to_vec()
}

/// The rigid motions that a part's Gram matrix of conditions ([`rigid_gram`], flat, in the
/// frame `(c, size)`) leaves free, in words: those along its eigenvalues below 1e-12 times the
/// largest, as the check of a whole mesh ([`check`]) judges them.
pub fn free_in(dim: usize, gram: &[f64], frame: ([f64; 3], f64)) -> Vec<String> {
    let n = if dim == 2 { 3 } else { 6 };
    free_of(dim, DMatrix::from_column_slice(n, n, gram), frame)
}

fn gram_of(mesh: &Mesh, dofs: &DofMap, nodes: impl Iterator<Item = usize>, frame: ([f64; 3], f64)) -> DMatrix<f64> {
    let dim = dofs.dim;
    let n_modes = if dim == 2 { 3 } else { 6 };
    let mut gram = DMatrix::<f64>::zeros(n_modes, n_modes);
    for v in nodes {
        for k in (0..dim).filter(|&k| matches!(dofs.u[v * dim + k], Dof::Fixed(_))) {
            let row = nalgebra::DVector::from_vec(rigid_row(dim, k, scaled(mesh, v, frame, dim)));
            gram += &row * row.transpose();
        }
    }
    gram
}

/// The motions along the eigenvalues of `gram` below [`FREE`] times the largest, in words.
fn free_of(dim: usize, gram: DMatrix<f64>, (c, size): ([f64; 3], f64)) -> Vec<String> {
    let n_modes = gram.nrows();
    let eig = SymmetricEigen::new(gram);
    let largest = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    (0..n_modes)
        .filter(|&j| !(eig.eigenvalues[j] > FREE * largest))
        .map(|j| {
            let v: Vec<f64> = eig.eigenvectors.column(j).iter().cloned().collect();
            describe(dim, &v, c, size)
        })
        .collect()
}

/// The first electric part (joined by electric cells through any node) that no prescribed φ
/// reaches.
fn floating_potential(mesh: &Mesh, dofs: &DofMap, cell_electric: &[bool]) -> Result<(), Unheld> {
    let (part, found) = mesh.node_parts(|c| cell_electric[c]);
    let mut held = vec![false; found.len()];
    for (v, d) in dofs.phi.iter().enumerate() {
        if let (Dof::Fixed(_), Some(i)) = (d, part[v]) {
            held[i] = true;
        }
    }
    match held.iter().position(|h| !h) {
        Some(i) => Err(Unheld::Potential {
            cell: found[i].0,
            cells: found[i].1,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Constraint, Field};
    use proptest::prelude::*;

    /// The dof map with the components `fixed(x, k)` selects held at 0, and φ where `phi(x)`.
    fn dofs(mesh: &Mesh, fixed: impl Fn(&[f64], usize) -> bool, phi: impl Fn(&[f64]) -> bool) -> DofMap {
        let mut d = DofMap::new(mesh, &vec![true; mesh.n_nodes()], &[]).unwrap();
        for v in 0..mesh.n_nodes() {
            for k in 0..mesh.dim {
                if fixed(mesh.point(v), k) {
                    d.u[v * mesh.dim + k] = Dof::Fixed(0.0);
                }
            }
            if phi(mesh.point(v)) {
                d.phi[v] = Dof::Fixed(0.0);
            }
        }
        d
    }

    fn free(r: Result<(), Unheld>) -> usize {
        match r {
            Ok(()) => 0,
            Err(Unheld::Motion { count, .. }) => count,
            Err(e) => panic!("{e}"),
        }
    }

    /// Two copies of `mesh`, the second shifted by `dx` along x (two bodies).
    fn two_bodies(mesh: &Mesh, dx: f64) -> Mesh {
        let mut m = mesh.clone();
        let n = mesh.n_nodes();
        m.points.extend(mesh.points.iter().map(|p| [p[0] + dx, p[1], p[2]]));
        m.cells.extend(mesh.cells.iter().map(|v| v + n));
        m
    }

    #[test]
    fn the_motions_left_free_in_2d_are_counted_and_named() {
        let m = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4);
        let all = vec![true; m.n_cells()];
        let left = |x: &[f64]| x[0] < 1e-12;
        let sides = |x: &[f64]| x[0] < 1e-12 || x[0] > 2.0 - 1e-12;
        // clamped on one side: held
        assert_eq!(
            free(check(&m, &dofs(&m, |x, _| left(x), left), &all, Coordinates::Cartesian)),
            0
        );
        // nothing held: two translations and the rotation
        assert_eq!(
            free(check(&m, &dofs(&m, |_, _| false, left), &all, Coordinates::Cartesian)),
            3
        );
        // both sides on rollers (ux = 0): the vertical translation
        let e = check(
            &m,
            &dofs(&m, |x, k| k == 0 && sides(x), left),
            &all,
            Coordinates::Cartesian,
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("1 rigid motion of the body free (a translation along [0.000, 1.000])"),
            "{e}"
        );
        // one node pinned: the rotation about it
        let pin = |x: &[f64]| x[0] < 1e-12 && x[1] < 1e-12;
        let e = check(&m, &dofs(&m, |x, _| pin(x), left), &all, Coordinates::Cartesian).unwrap_err();
        assert!(
            e.to_string()
                .contains("a rotation about the point (0.0000e0, 0.0000e0)"),
            "{e}"
        );
        // pinned and rollered elsewhere: held
        assert_eq!(
            free(check(
                &m,
                &dofs(&m, |x, k| pin(x) || (k == 1 && x[0] > 2.0 - 1e-12), left),
                &all,
                Coordinates::Cartesian
            )),
            0
        );
    }

    #[test]
    fn a_bed_holds_a_body_along_its_normal_only() {
        let m = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4);
        let all = vec![true; m.n_cells()];
        let left = |x: &[f64]| x[0] < 1e-12;
        let sides = |x: &[f64]| x[0] < 1e-12 || x[0] > 2.0 - 1e-12;
        let bed: Vec<Support> = (0..m.n_nodes())
            .filter(|&v| m.point(v)[1] < 1e-12)
            .map(|node| Support {
                node,
                direction: [0.0, -1.0, 0.0],
            })
            .collect();
        // on rollers: the bed holds the vertical translation
        let rollers = dofs(&m, |x, k| k == 0 && sides(x), left);
        assert_eq!(
            check_with(&m, &rollers, &all, Coordinates::Cartesian, &bed),
            Ok(Held::WithSupports)
        );
        assert_eq!(free(check(&m, &rollers, &all, Coordinates::Cartesian)), 1);
        // clamped: the conditions alone
        let clamped = dofs(&m, |x, _| left(x), left);
        assert_eq!(
            check_with(&m, &clamped, &all, Coordinates::Cartesian, &bed),
            Ok(Held::ByConditions)
        );
        // free: the bed holds the vertical translation and the rotation, not the slide
        let e = check_with(&m, &dofs(&m, |_, _| false, left), &all, Coordinates::Cartesian, &bed).unwrap_err();
        assert!(
            matches!(
                e,
                Unheld::Motion {
                    count: 1,
                    with_supports: true,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("a translation along [1.000, 0.000]"), "{e}");
        // rollers at the top corners and one point of the bed (the corner (0, 0)): the rotation
        // about (0, 1) moves none of them
        let e = check_with(
            &m,
            &dofs(&m, |x, k| k == 0 && sides(x) && x[1] > 0.99, left),
            &all,
            Coordinates::Cartesian,
            &bed[..1],
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("a rotation about the point (0.0000e0, 1.0000e0)"),
            "{e}"
        );
        // a body of revolution: a bed across the axis holds its axial translation
        let r = mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], 4, 4);
        let axis = dofs(&r, |x, k| k == 0 && x[0] < 1e-12, |x: &[f64]| x[1] > 0.99);
        let under: Vec<Support> = bed.iter().filter(|s| r.point(s.node)[0] <= 1.0).copied().collect();
        let all_r = vec![true; r.n_cells()];
        assert_eq!(free(check(&r, &axis, &all_r, Coordinates::Axisymmetric)), 1);
        assert_eq!(
            check_with(&r, &axis, &all_r, Coordinates::Axisymmetric, &under),
            Ok(Held::WithSupports)
        );
    }

    #[test]
    fn a_body_fixed_on_a_line_in_3d_can_turn_about_it() {
        let m = mesh::box_tet([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 3, 3, 3);
        let all = vec![true; m.n_cells()];
        let edge = |x: &[f64]| x[0] < 1e-12 && x[1] < 1e-12;
        let e = check(&m, &dofs(&m, |x, _| edge(x), edge), &all, Coordinates::Cartesian).unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("1 rigid motion") && s.contains("axis along [0.000, 0.000, 1.000]")
                || s.contains("axis along [0.000, 0.000, -1.000]"),
            "{s}"
        );
        assert!(s.contains("through (0.0000e0, 0.0000e0,"), "{s}");
        // a face clamped: held; a face on rollers (uz = 0 on z = 0): three motions free
        let bottom = |x: &[f64]| x[2] < 1e-12;
        assert_eq!(
            free(check(
                &m,
                &dofs(&m, |x, _| bottom(x), edge),
                &all,
                Coordinates::Cartesian
            )),
            0
        );
        assert_eq!(
            free(check(
                &m,
                &dofs(&m, |x, k| k == 2 && bottom(x), edge),
                &all,
                Coordinates::Cartesian
            )),
            3
        );
    }

    #[test]
    fn each_body_of_a_mesh_needs_its_own_hold() {
        let m = two_bodies(&mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], 4, 4), 3.0);
        let all = vec![true; m.n_cells()];
        let left = |x: &[f64]| x[0] < 1e-12;
        let both = |x: &[f64]| x[0] < 1e-12 || (x[0] - 3.0).abs() < 1e-12;
        let e = check(&m, &dofs(&m, |x, _| left(x), both), &all, Coordinates::Cartesian).unwrap_err();
        assert!(
            matches!(
                e,
                Unheld::Motion {
                    count: 3,
                    cell: 32,
                    cells: 32,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(
            free(check(&m, &dofs(&m, |x, _| both(x), both), &all, Coordinates::Cartesian)),
            0
        );
        // the second body's potential floats
        let e = check(&m, &dofs(&m, |x, _| both(x), left), &all, Coordinates::Cartesian).unwrap_err();
        assert_eq!(e, Unheld::Potential { cell: 32, cells: 32 });
        // unless it is elastic only
        let first: Vec<bool> = (0..m.n_cells()).map(|c| c < 32).collect();
        assert_eq!(
            check(&m, &dofs(&m, |x, _| both(x), left), &first, Coordinates::Cartesian),
            Ok(())
        );
    }

    #[test]
    fn two_parts_on_a_hinge_node_turn_about_it() {
        // squares (0,1)² and (1,2)², sharing the node (1, 1) only
        let a = mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], 2, 2);
        let mut m = two_bodies(&a, 1.0);
        let n = a.n_nodes();
        let shared_a = a.points.iter().position(|p| p[0] == 1.0 && p[1] == 1.0).unwrap();
        let shared_b = a.points.iter().position(|p| p[0] == 0.0 && p[1] == 0.0).unwrap() + n;
        for p in m.points[n..].iter_mut() {
            p[1] += 1.0;
        }
        for v in m.cells.iter_mut() {
            if *v == shared_b {
                *v = shared_a;
            }
        }
        let all = vec![true; m.n_cells()];
        // the first square clamped on its left, the hinge pinned: the second turns about it
        let held = |x: &[f64], _| x[0] == 0.0 || (x[0] == 1.0 && x[1] == 1.0);
        let e = check(&m, &dofs(&m, held, |x| x[0] == 0.0), &all, Coordinates::Cartesian).unwrap_err();
        assert!(e.to_string().contains("1 rigid motion of the body free (a rotation about the point (1.0000e0, 1.0000e0)) in its part with cell 8 (8 cells)"), "{e}");
        // the potential is continuous through the node: one electric part
        let both = |x: &[f64], _| x[0] == 0.0 || x[0] == 2.0;
        assert_eq!(
            check(&m, &dofs(&m, both, |x| x[0] == 0.0), &all, Coordinates::Cartesian),
            Ok(())
        );
    }

    #[test]
    fn a_dof_map_built_from_conditions_is_judged_the_same() {
        let m = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4);
        let c = [
            Constraint::constant("left", Field::Displacement(0), 0.0),
            Constraint::constant("right", Field::Displacement(0), 0.0),
            Constraint::constant("left", Field::Potential, 0.0),
        ];
        let d = DofMap::new(&m, &vec![true; m.n_nodes()], &c).unwrap();
        assert_eq!(free(check(&m, &d, &vec![true; m.n_cells()], Coordinates::Cartesian)), 1);
    }

    proptest! {
        /// The verdict does not depend on units or position: the mesh scaled by any factor
        /// and moved anywhere gives the same count of free motions.
        #[test]
        fn the_verdict_is_independent_of_units_and_position(
            scale in -200.0f64..200.0,
            shift in prop::array::uniform3(-1e6f64..1e6),
            which in 0usize..5,
        ) {
            let s = 10f64.powf(scale);
            let mut m = mesh::box_tet([0.0, 0.0, 0.0], [2.0, 1.0, 1.0], 2, 2, 2);
            let base = m.clone();
            for p in m.points.iter_mut() {
                for k in 0..3 {
                    p[k] = p[k] * s + shift[k] * s;
                }
            }
            // conditions chosen on the unscaled coordinates
            let pick = |v: usize, k: usize| {
                let x = base.points[v];
                match which {
                    0 => x[0] == 0.0,
                    1 => x[0] == 0.0 && k == 0,
                    2 => x[0] == 0.0 && x[1] == 0.0,
                    3 => (x[0] == 0.0 && x[1] == 0.0 && x[2] == 0.0) || (x[0] == 2.0 && k != 0),
                    _ => false,
                }
            };
            let expected = [0, 3, 1, 0, 6][which];
            let mut d = DofMap::new(&m, &vec![true; m.n_nodes()], &[]).unwrap();
            for v in 0..m.n_nodes() {
                for k in 0..3 {
                    if pick(v, k) {
                        d.u[v * 3 + k] = Dof::Fixed(0.0);
                    }
                }
            }
            d.phi[0] = Dof::Fixed(0.0);
            prop_assert_eq!(free(check(&m, &d, &vec![true; m.n_cells()], Coordinates::Cartesian)), expected);
        }
    }
}
