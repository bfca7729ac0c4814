//! Right-hand sides of `K [u; φ] = [f; -q]` (docs/theory.md):
//!
//! - `f_v = ∫_Ω f0 · v dx + ∫_Γ2 f2 · v ds`           (body force, traction),
//! - `q_ψ = ∫_Ω q0 ψ dx - ∫_Γb q2 ψ ds`              (the paper's (3) `div D = q0`, and `D·n = q2`),
//!
//! minus the columns of `K` of the prescribed dofs times their values (Dirichlet lifting).
//! Integrals use rules exact for quadratics (degree 2) with P1, enough for O(h²) in L2; with
//! P2, rules of degree 5 on segments, 4 on triangles and 3 on tetrahedra (at least `2k - 1`
//! for `k = 2`: the loads' quadrature keeps the L2 error's O(h³); Ciarlet, The Finite
//! Element Method for Elliptic Problems, 1978, section 4.1).

use crate::kernels::{
    coupling_column, coupling_row, dielectric_column, elasticity_column, shape_values, simplex_rule, MAX_NODES,
};
use crate::InputError;
use crate::{AssemblyError, Discretization, Dof, ScalarFn, VectorFn};

/// A load on the body or on a boundary group.
#[derive(Clone)]
pub enum Load {
    /// Body force `f0(x)` per unit volume.
    BodyForce(VectorFn),
    /// Body charge `q0(x)` in the paper's sign (`div D = q0`).
    BodyCharge(ScalarFn),
    /// Traction `f2(x) = σ n` on a boundary group.
    Traction {
        /// Boundary group.
        group: String,
        /// The traction vector at a point.
        value: VectorFn,
    },
    /// Surface charge `q2(x) = D · n` on a boundary group.
    SurfaceCharge {
        /// Boundary group.
        group: String,
        /// The charge density at a point.
        value: ScalarFn,
    },
    /// The total charge on a floating terminal ([`crate::Field::Floating`]): the negative of
    /// the flux `∫ D·n ds` out of the body through its group, the right-hand side of its one
    /// potential's equation. A load path scales it with the terminals' potentials (it goes to
    /// [`RhsParts::potentials`]).
    TerminalCharge {
        /// The floating terminal's group.
        group: String,
        /// The charge.
        charge: f64,
    },
}

impl std::fmt::Debug for Load {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Load::BodyForce(_) => write!(f, "BodyForce"),
            Load::BodyCharge(_) => write!(f, "BodyCharge"),
            Load::Traction { group, .. } => write!(f, "Traction on `{group}`"),
            Load::SurfaceCharge { group, .. } => write!(f, "SurfaceCharge on `{group}`"),
            Load::TerminalCharge { group, charge } => write!(f, "TerminalCharge {charge} on `{group}`"),
        }
    }
}

/// `v`, or the error naming the load `what` where it is not finite.
fn check(what: &'static str, v: f64) -> Result<f64, AssemblyError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(AssemblyError::from(InputError::NotFiniteLoad { what, value: v }))
    }
}

/// Measure of a facet (segment length or triangle area).
pub fn facet_measure(x: &[[f64; 3]]) -> f64 {
    let d = x.len() - 1;
    crate::mapping::measure_at(d, &crate::mapping::map_at(d, x, &[0.0; 4]).1)
}

/// The map of a boundary facet (its nodes: corners, then in a P2 mesh its edges' midpoints):
/// its corners' (affine) where it is straight-sided, through all its nodes on a curved P2
/// facet ([`crate::mapping`]). Made once per facet, for the points of a rule on it.
pub struct FacetMap {
    /// The facet's dimension (the mesh's less one).
    d: usize,
    /// Its nodes' coordinates (`n` of them).
    x: [[f64; 3]; 6],
    n: usize,
    /// A straight-sided facet's measure; `None` on a curved one.
    straight: Option<f64>,
}

impl FacetMap {
    /// The map of facet `f` of `mesh`.
    pub fn of(mesh: &mesh::Mesh, f: &[usize]) -> Self {
        let d = mesh.dim - 1;
        let mut x = [[0.0; 3]; 6];
        for (xa, &v) in x.iter_mut().zip(f) {
            *xa = mesh.points[v];
        }
        let n = f.len().min(6);
        let straight =
            mesh::straight_sided(&x[..n], d + 1, crate::kernels::simplex_edges(d)).then(|| facet_measure(&x[..=d]));
        FacetMap { d, x, n, straight }
    }

    /// Whether the facet is curved (a P2 facet with an edge node off its chord).
    pub fn is_curved(&self) -> bool {
        self.straight.is_none()
    }

    /// The point at the barycentric coordinates `l`, and the measure a unit of reference
    /// weight stands for there: the facet's measure where it is straight-sided; on a curved P2
    /// facet its map's `√det(JᵀJ) / d!`. Without a body of revolution's `2π r`.
    pub fn at(&self, l: &[f64; 4]) -> ([f64; 3], f64) {
        let d = self.d;
        match self.straight {
            Some(measure) => (crate::mapping::map_at(d, &self.x[..=d], l).0, measure),
            None => {
                let (at, jac) = crate::mapping::map_at(d, &self.x[..self.n], l);
                (at, crate::mapping::measure_at(d, &jac))
            }
        }
    }
}

impl Discretization<'_> {
    /// The right-hand sides `(b_u, b_φ)` of `K [u; φ] = [b_u; b_φ]` for the given loads, with
    /// the prescribed values lifted: `b_u = f - A_ud u_d - Gᵀ_uφd φ_d`,
    /// `b_φ = -q - G_φud u_d + B_φφd φ_d`.
    pub fn rhs(&self, loads: &[Load]) -> Result<(Vec<f64>, Vec<f64>), AssemblyError> {
        let (mut bu, mut bphi) = self.load_vectors(loads)?;
        self.lift(&mut bu, &mut bphi, Lifted::All);
        Ok((bu, bphi))
    }

    /// The right-hand side of [`Discretization::rhs`] in parts, each linear in its own data:
    /// the loads alone, the lifting of each component of the prescribed displacements, the
    /// lifting of the prescribed potentials (`rhs = loads + Σ_k displacements[k] +
    /// potentials`). A load path scales each by its factor over time without assembling
    /// again.
    ///
    /// # Errors
    /// As [`Discretization::rhs`].
    pub fn rhs_parts(&self, loads: &[Load]) -> Result<RhsParts, AssemblyError> {
        let lifted = |which| {
            let mut bu = vec![0.0; self.dofs.n_u];
            let mut bphi = vec![0.0; self.dofs.n_phi];
            self.lift(&mut bu, &mut bphi, which);
            (bu, bphi)
        };
        let terminal = |l: &&Load| matches!(l, Load::TerminalCharge { .. });
        let (charges, others): (Vec<Load>, Vec<Load>) = loads.iter().cloned().partition(|l| terminal(&l));
        let mut potentials = lifted(Lifted::Potentials);
        let (_, on_terminals) = self.load_vectors(&charges)?;
        for (b, q) in potentials.1.iter_mut().zip(on_terminals) {
            *b += q;
        }
        Ok(RhsParts {
            loads: self.load_vectors(&others)?,
            displacements: (0..self.mesh.dim).map(|k| lifted(Lifted::Component(k))).collect(),
            potentials,
        })
    }

    /// The loads' vectors on the free dofs, without the lifting.
    fn load_vectors(&self, loads: &[Load]) -> Result<(Vec<f64>, Vec<f64>), AssemblyError> {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let d = &self.dofs;
        let mut bu = vec![0.0; d.n_u];
        let mut bphi = vec![0.0; d.n_phi];
        let order = mesh.kind.order();
        let (w_cell, p_cell) = simplex_rule(dim, order);
        let (w_facet, p_facet) = simplex_rule(dim - 1, order);
        let n_cell: Vec<_> = p_cell.iter().map(|p| shape_values(dim, order, p)).collect();
        let n_facet: Vec<_> = p_facet.iter().map(|p| shape_values(dim - 1, order, p)).collect();
        let ring = |x: &[f64; 3]| self.ring(x);
        for load in loads {
            match load {
                Load::BodyForce(f) => {
                    for (c, cell) in mesh.iter_cells().enumerate() {
                        for ((w, p), n) in w_cell.iter().zip(p_cell).zip(&n_cell) {
                            let (x, vol) = self.cell_point(c, p);
                            let fx = f(&x[..dim]);
                            let vol = vol * ring(&x);
                            for (a, &v) in cell.iter().enumerate() {
                                for k in 0..dim {
                                    if let Dof::Free(j) = d.u[v * dim + k] {
                                        bu[j] += check("the body force", fx[k])? * w * vol * n[a];
                                    }
                                }
                            }
                        }
                    }
                }
                Load::BodyCharge(q0) => {
                    for (c, cell) in mesh.iter_cells().enumerate() {
                        if !self.cell_electric[c] {
                            continue;
                        }
                        for ((w, p), n) in w_cell.iter().zip(p_cell).zip(&n_cell) {
                            let (x, vol) = self.cell_point(c, p);
                            let qx = check("the body charge", q0(&x[..dim]))?;
                            let vol = vol * ring(&x);
                            for (a, &v) in cell.iter().enumerate() {
                                if let Dof::Free(j) = d.phi[v] {
                                    bphi[j] -= qx * w * vol * n[a];
                                }
                            }
                        }
                    }
                }
                Load::Traction { group, value } => {
                    for f in mesh.boundary(group)?.iter() {
                        let map = FacetMap::of(mesh, f);
                        for ((w, p), n) in w_facet.iter().zip(p_facet).zip(&n_facet) {
                            let (y, len) = map.at(p);
                            let t = value(&y[..dim]);
                            let len = len * ring(&y);
                            for (a, &v) in f.iter().enumerate() {
                                for k in 0..dim {
                                    if let Dof::Free(j) = d.u[v * dim + k] {
                                        bu[j] += check("the traction", t[k])? * w * len * n[a];
                                    }
                                }
                            }
                        }
                    }
                }
                Load::SurfaceCharge { group, value } => {
                    for f in mesh.boundary(group)?.iter() {
                        let map = FacetMap::of(mesh, f);
                        for ((w, p), n) in w_facet.iter().zip(p_facet).zip(&n_facet) {
                            let (y, len) = map.at(p);
                            let qx = check("the surface charge", value(&y[..dim]))?;
                            let len = len * ring(&y);
                            for (a, &v) in f.iter().enumerate() {
                                if let Dof::Free(j) = d.phi[v] {
                                    // q has -∫ q2 ψ, and b_φ = -q
                                    bphi[j] += qx * w * len * n[a];
                                }
                            }
                        }
                    }
                }
                Load::TerminalCharge { group, charge } => {
                    let Some(&(_, j)) = d.floating.iter().find(|(g, _)| g == group) else {
                        return Err(InputError::NotFloating { group: group.clone() }.into());
                    };
                    // the flux out of the body is -Q, and b_φ carries +∫ q2 ψ
                    bphi[j] -= check("the terminal's charge", *charge)?;
                }
            }
        }
        Ok((bu, bphi))
    }

    /// The point of barycentric coordinates `bary` on the simplex of `nodes`.
    pub(crate) fn point_at(&self, nodes: &[usize], bary: &[f64; 4]) -> [f64; 3] {
        let mut x = [0.0; 3];
        for (q, &v) in nodes.iter().enumerate() {
            for k in 0..3 {
                x[k] += bary[q] * self.mesh.points[v][k];
            }
        }
        x
    }

    /// The measure's factor at `x`: `2π r` on a body of revolution (its integrals are over the
    /// whole body), 1 otherwise.
    pub(crate) fn ring(&self, x: &[f64; 3]) -> f64 {
        if self.coordinates == crate::Coordinates::Axisymmetric {
            std::f64::consts::TAU * x[0]
        } else {
            1.0
        }
    }

    /// Subtracts the columns of `K` of the prescribed dofs (those of `which`) times their
    /// values.
    fn lift(&self, bu: &mut [f64], bphi: &mut [f64], which: Lifted) {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let d = &self.dofs;
        for (c, cell) in mesh.iter_cells().enumerate() {
            let lifts_u = |k: usize| matches!(which, Lifted::All) || which == Lifted::Component(k);
            let fixed_u = cell
                .iter()
                .any(|&v| (0..dim).any(|k| lifts_u(k) && matches!(d.u[v * dim + k], Dof::Fixed(x) if x != 0.0)));
            let lifts_phi = matches!(which, Lifted::All | Lifted::Potentials);
            let fixed_phi = lifts_phi && cell.iter().any(|&v| matches!(d.phi[v], Dof::Fixed(x) if x != 0.0));
            if !fixed_u && !fixed_phi {
                continue;
            }
            let (m, r) = (self.material(c), self.rule(c));
            for (a, &va) in cell.iter().enumerate() {
                for k in (0..dim).filter(|&k| lifts_u(k)) {
                    let Dof::Fixed(val) = d.u[va * dim + k] else {
                        continue;
                    };
                    if val == 0.0 {
                        continue;
                    }
                    let col: [[f64; 3]; MAX_NODES] = elasticity_column(m, &r, a, k);
                    let colg: [f64; MAX_NODES] = coupling_column(m, &r, a, k);
                    for (b, &vb) in cell.iter().enumerate() {
                        for l in 0..dim {
                            if let Dof::Free(j) = d.u[vb * dim + l] {
                                bu[j] -= col[b][l] * val;
                            }
                        }
                        if self.cell_electric[c] {
                            if let Dof::Free(j) = d.phi[vb] {
                                bphi[j] -= colg[b] * val;
                            }
                        }
                    }
                }
                if !self.cell_electric[c] || !fixed_phi {
                    continue;
                }
                let Dof::Fixed(val) = d.phi[va] else { continue };
                if val == 0.0 {
                    continue;
                }
                let gt: [[f64; 3]; MAX_NODES] = coupling_row(m, &r, a);
                let bcol: [f64; MAX_NODES] = dielectric_column(m, &r, a);
                for (b, &vb) in cell.iter().enumerate() {
                    for l in 0..dim {
                        if let Dof::Free(j) = d.u[vb * dim + l] {
                            bu[j] -= gt[b][l] * val;
                        }
                    }
                    if let Dof::Free(j) = d.phi[vb] {
                        bphi[j] += bcol[b] * val;
                    }
                }
            }
        }
    }
}

/// Which prescribed values [`Discretization::rhs`]'s lifting takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lifted {
    /// Every prescribed value.
    All,
    /// Component `k` of the prescribed displacements.
    Component(usize),
    /// The prescribed potentials.
    Potentials,
}

/// The right-hand side in parts ([`Discretization::rhs_parts`]), each `(b_u, b_φ)`.
#[derive(Clone, Debug)]
pub struct RhsParts {
    /// The loads (body forces and charges, tractions, surface charges).
    pub loads: (Vec<f64>, Vec<f64>),
    /// The lifting of each component (x, y, z) of the prescribed displacements.
    pub displacements: Vec<(Vec<f64>, Vec<f64>)>,
    /// The lifting of the prescribed potentials.
    pub potentials: (Vec<f64>, Vec<f64>),
}
