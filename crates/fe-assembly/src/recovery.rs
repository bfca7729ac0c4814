//! Recovery of the stress `σ = C ε(u) + eᵀ ∇φ` and the electric displacement
//! `D = e ε(u) - β ∇φ` (docs/theory.md's law; `E = -∇φ`), at each cell's centroid (constant on
//! a P1 cell, linear on a P2 one) and, on P2 cells, at the nodes too.

use crate::kernels::{gradient_at, simplex_nodes, strain_at, CellRule, MAX_NODES};
use crate::Discretization;
use crate::Material;
use rayon::prelude::*;

/// Per-cell fields, Voigt order for the stress (`[xx, yy, xy]` in 2D, 6 entries in 3D).
#[derive(Clone, Debug, PartialEq)]
pub struct CellFields {
    /// Stress per cell (Voigt, `nv` entries each, flat).
    pub stress: Vec<f64>,
    /// Electric displacement per cell (`dim` entries each, flat).
    pub electric_displacement: Vec<f64>,
    /// Strain per cell (Voigt, engineering shear, flat).
    pub strain: Vec<f64>,
    /// Electric field `E = -∇φ` per cell (`dim` entries each, flat).
    pub electric_field: Vec<f64>,
    /// In plane strain, `[σ_zz, σ_yz, σ_xz, D_z]` per cell (4 entries each, flat: what the
    /// in-plane Voigt rows leave out, [`crate::OutOfPlane`]); empty on a body of revolution
    /// and in 3D (their Voigt rows hold every component), and where a material has no 3D
    /// tensors to give them.
    pub out_of_plane: Vec<f64>,
    /// On a mesh of P2 cells (whose fields are linear in each cell, so that the centroid's
    /// value leaves out their variation): the same fields at the nodes, `None` on P1 cells
    /// (constant in each).
    pub at_nodes: Option<NodeFields>,
}

/// The fields at the mesh's nodes, laid out as [`CellFields`]' but one entry per node: at
/// each node the average, weighted by the cells' measures, of the values there of the cells
/// around it (each cell's own value at its node, not at its centroid: exact for a field that
/// the cells hold, continuous across cells or not; a node where materials meet averages both
/// sides' values, as ParaView's cell-to-point filter would).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeFields {
    /// Stress per node (Voigt, `nv` entries each).
    pub stress: Vec<f64>,
    /// Electric displacement per node (`dim` entries each).
    pub electric_displacement: Vec<f64>,
    /// Strain per node (Voigt, engineering shear).
    pub strain: Vec<f64>,
    /// Electric field per node (`dim` entries each).
    pub electric_field: Vec<f64>,
    /// `[σ_zz, σ_yz, σ_xz, D_z]` per node in plane strain, as [`CellFields::out_of_plane`].
    pub out_of_plane: Vec<f64>,
}

/// The components of a symmetric tensor in the order VTK's files hold them (ParaView labels
/// them `XX, YY, ZZ, XY, YZ, XZ`), the order of [`Tensors`]; Voigt's (the fields' own) is
/// `xx, yy, zz, yz, xz, xy`.
pub const VTK_TENSOR_ORDER: [&str; 6] = ["xx", "yy", "zz", "xy", "yz", "xz"];

/// Recovered fields as 3D tensors and vectors, whatever the body's dimension: what a viewer
/// (ParaView, meshio's formats) reads without knowing the body's Voigt layout. Per entry
/// (cell or node), the stress and the strain as the six components of a symmetric tensor in
/// [`VTK_TENSOR_ORDER`] (the strain's shears the tensor's `ε_xy = γ_xy / 2`, not Voigt's
/// engineering `γ_xy`), `D` and `E` with three components. In plane strain the stress
/// holds `σ_zz` (and `σ_yz`, `σ_xz` where the material couples them), the strain's
/// out-of-plane components are 0, `D_z` is that of the state, `E_z = 0`; on a body of
/// revolution meshed in its meridian plane (`x = r`, `y = z`) the third axis is the hoop
/// direction: `zz` holds `θθ`, the shears with it vanish, as do `D_θ` and `E_θ`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tensors {
    /// Stress, 6 entries per cell or node.
    pub stress: Vec<f64>,
    /// Strain, 6 entries per cell or node (tensor shears).
    pub strain: Vec<f64>,
    /// Electric displacement, 3 entries per cell or node.
    pub electric_displacement: Vec<f64>,
    /// Electric field, 3 entries per cell or node.
    pub electric_field: Vec<f64>,
}

/// [`Tensors`] of fields laid out as [`CellFields`] (`dim`-dimensional: `D` has `dim`
/// components per entry, which counts the entries; `nv` Voigt components, `out_of_plane` 4 per
/// entry or empty).
fn tensors([stress, strain, d, e]: [&[f64]; 4], out_of_plane: &[f64], dim: usize) -> Tensors {
    let count = d.len() / dim;
    let nv = stress.len().checked_div(count).unwrap_or(0);
    let mut out = Tensors {
        stress: Vec::with_capacity(6 * count),
        strain: Vec::with_capacity(6 * count),
        electric_displacement: Vec::with_capacity(3 * count),
        electric_field: Vec::with_capacity(3 * count),
    };
    for i in 0..count {
        let (s, eps) = (&stress[i * nv..(i + 1) * nv], &strain[i * nv..(i + 1) * nv]);
        // [σ_zz, σ_yz, σ_xz, D_z] in plane strain; unknown where the material lacks them
        let z = out_of_plane.get(4 * i..4 * i + 4);
        let across = |k: usize| z.map_or(f64::NAN, |z| z[k]);
        let (t_s, t_e) = match nv {
            // Voigt [xx, yy, zz, yz, xz, xy]
            6 => (
                [s[0], s[1], s[2], s[5], s[3], s[4]],
                [eps[0], eps[1], eps[2], eps[5] / 2.0, eps[3] / 2.0, eps[4] / 2.0],
            ),
            // a body of revolution's [rr, zz, rz, θθ]
            4 => (
                [s[0], s[1], s[3], s[2], 0.0, 0.0],
                [eps[0], eps[1], eps[3], eps[2] / 2.0, 0.0, 0.0],
            ),
            // plane strain's [xx, yy, xy]
            _ => (
                [s[0], s[1], across(0), s[2], across(1), across(2)],
                [eps[0], eps[1], 0.0, eps[2] / 2.0, 0.0, 0.0],
            ),
        };
        out.stress.extend(t_s);
        out.strain.extend(t_e);
        let (di, ei) = (&d[i * dim..(i + 1) * dim], &e[i * dim..(i + 1) * dim]);
        if dim == 3 {
            out.electric_displacement.extend_from_slice(di);
            out.electric_field.extend_from_slice(ei);
        } else {
            let d_z = if nv == 3 { across(3) } else { 0.0 };
            out.electric_displacement.extend([di[0], di[1], d_z]);
            out.electric_field.extend([ei[0], ei[1], 0.0]);
        }
    }
    out
}

impl CellFields {
    /// The fields of the cells of a `dim`-dimensional body as [`Tensors`].
    pub fn tensors(&self, dim: usize) -> Tensors {
        let arrays = [
            &self.stress,
            &self.strain,
            &self.electric_displacement,
            &self.electric_field,
        ];
        tensors(arrays.map(|a| &a[..]), &self.out_of_plane, dim)
    }
}

impl NodeFields {
    /// The fields of the nodes of a `dim`-dimensional body as [`Tensors`].
    pub fn tensors(&self, dim: usize) -> Tensors {
        let arrays = [
            &self.stress,
            &self.strain,
            &self.electric_displacement,
            &self.electric_field,
        ];
        tensors(arrays.map(|a| &a[..]), &self.out_of_plane, dim)
    }
}

/// A charge's coefficients on the free unknowns: `(a_u, a_φ)`.
pub type ChargeFunctional = (Vec<f64>, Vec<f64>);

impl Discretization<'_> {
    /// Stress, strain, electric displacement and field on every cell, from nodal `u` and `φ`.
    pub fn recover(&self, u: &[[f64; 3]], phi: &[f64]) -> CellFields {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let nv = self.nv();
        let n = mesh.n_cells();
        let mut out = CellFields {
            stress: Vec::with_capacity(n * nv),
            electric_displacement: Vec::with_capacity(n * dim),
            strain: Vec::with_capacity(n * nv),
            electric_field: Vec::with_capacity(n * dim),
            out_of_plane: Vec::with_capacity(if self.out_of_plane() { 4 * n } else { 0 }),
            at_nodes: (mesh.kind.order() == 2).then(|| self.recover_at_nodes(u, phi)),
        };
        for (c, cell) in mesh.iter_cells().enumerate() {
            let r = self.centroid_rule(c);
            let m = self.material(c);
            let ul: Vec<[f64; 3]> = cell.iter().map(|&v| u[v]).collect();
            let pl: Vec<f64> = cell.iter().map(|&v| phi[v]).collect();
            let eps = strain_at(dim, &r, 0, &ul);
            let grad = if self.cell_electric[c] {
                gradient_at(dim, &r, 0, &pl)
            } else {
                [0.0; 3]
            };
            out.stress.extend_from_slice(&stress(m, &eps, &grad)[..nv]);
            out.strain.extend_from_slice(&eps[..nv]);
            let d = displacement(m, &eps, &grad);
            for k in 0..dim {
                out.electric_displacement.push(d[k]);
                out.electric_field.push(-grad[k]);
            }
            if out.out_of_plane.capacity() > 0 {
                out.out_of_plane.extend(out_of_plane(m, &eps, &grad));
            }
        }
        out
    }

    /// Whether the fields carry [`CellFields::out_of_plane`]: plane strain, every material
    /// with its [`crate::OutOfPlane`] rows.
    fn out_of_plane(&self) -> bool {
        self.coordinates == crate::Coordinates::Cartesian
            && self.mesh.dim == 2
            && (0..self.mesh.n_cells()).all(|c| self.material(c).out_of_plane.is_some())
    }

    /// [`NodeFields`] of a mesh of P2 cells: each node's cells' values at it (the P2 shape
    /// functions' gradients at the node; on a body of revolution the hoop strain `u_r / r` of
    /// the node, on the axis its limit `∂u_r/∂r`), averaged with the cells' measures as
    /// weights. Nodes in parallel on rayon's pool.
    fn recover_at_nodes(&self, u: &[[f64; 3]], phi: &[f64]) -> NodeFields {
        let mesh = self.mesh;
        let (dim, nv, n) = (mesh.dim, self.nv(), mesh.n_nodes());
        // each local node's barycentric coordinates: the corners, then the edges' midpoints
        let bary = simplex_nodes(dim);
        let (offsets, node_cells) = mesh.node_cells();
        let across = if self.out_of_plane() { 4 } else { 0 };
        let mut out = NodeFields {
            stress: vec![0.0; n * nv],
            electric_displacement: vec![0.0; n * dim],
            strain: vec![0.0; n * nv],
            electric_field: vec![0.0; n * dim],
            out_of_plane: vec![0.0; n * across],
        };
        // a node's share of `out_of_plane`: its 4 entries, or an empty slice
        let mut across_chunks: Vec<&mut [f64]> = if across == 0 {
            (0..n).map(|_| <&mut [f64]>::default()).collect()
        } else {
            out.out_of_plane.chunks_mut(4).collect()
        };
        out.stress
            .par_chunks_mut(nv)
            .zip(out.strain.par_chunks_mut(nv))
            .zip(out.electric_displacement.par_chunks_mut(dim))
            .zip(out.electric_field.par_chunks_mut(dim))
            .zip(across_chunks.par_iter_mut())
            .enumerate()
            .for_each(|(v, ((((s_out, eps_out), d_out), e_out), z_out))| {
                let mut total = 0.0;
                for &c in &node_cells[offsets[v]..offsets[v + 1]] {
                    let cell = mesh.cell(c);
                    let Some(a) = cell.iter().position(|&w| w == v) else {
                        continue;
                    };
                    let g = &self.geometry[c];
                    let rule = self.quadratic_rule_at(c, &bary[a..=a], &[1.0], false);
                    let ul: Vec<[f64; 3]> = cell.iter().map(|&w| u[w]).collect();
                    let mut eps = strain_at(dim, &rule, 0, &ul);
                    if let Some(r) = g.radii {
                        // the node's own radius (on a curved cell too)
                        let (rn, reach) = (mesh.points[v][0], r.iter().fold(0.0f64, |m, x| m.max(x.abs())));
                        eps[3] = if rn > 1e-12 * reach { u[v][0] / rn } else { eps[0] };
                    }
                    let grad = if self.cell_electric[c] {
                        let pl: Vec<f64> = cell.iter().map(|&w| phi[w]).collect();
                        gradient_at(dim, &rule, 0, &pl)
                    } else {
                        [0.0; 3]
                    };
                    let m = self.material(c);
                    let (sigma, d) = (stress(m, &eps, &grad), displacement(m, &eps, &grad));
                    let w = rule.weight(0);
                    total += w;
                    if !z_out.is_empty() {
                        let z = out_of_plane(m, &eps, &grad);
                        z_out.iter_mut().zip(z).for_each(|(o, x)| *o += w * x);
                    }
                    for i in 0..nv {
                        s_out[i] += w * sigma[i];
                        eps_out[i] += w * eps[i];
                    }
                    for k in 0..dim {
                        d_out[k] += w * d[k];
                        e_out[k] -= w * grad[k];
                    }
                }
                if total > 0.0 {
                    for x in s_out
                        .iter_mut()
                        .chain(eps_out.iter_mut())
                        .chain(d_out.iter_mut())
                        .chain(e_out.iter_mut())
                        .chain(z_out.iter_mut())
                    {
                        *x /= total;
                    }
                }
            });
        out
    }

    /// Voigt strain components: 3 in plane strain, 4 on a body of revolution (`[rr, zz, rz,
    /// θθ]`), 6 in 3D.
    pub fn nv(&self) -> usize {
        crate::voigt_len(self.mesh.dim, self.coordinates)
    }

    /// The charge on each of `groups` (boundary groups where the potential is prescribed or
    /// floats: electrodes, grounded sides), in the project's one convention: the charge on the
    /// conductor, `Q = -∫ D·ν ds` with `ν` the body's outward normal (a positive electrode
    /// draws positive charge; the body's charges on all its terminals sum to 0, Gauss).
    /// It is the reaction of the electric equation at the group's nodes: with `div D = q0`, the
    /// weak form gives `∫_Γ (D·ν) ψ_i = ∫_Ω D·∇ψ_i + ∫_Ω q0 ψ_i` for each hat function `ψ_i`,
    /// and the hats of a group's nodes sum to 1 on it (P1: `D` constant per cell, so each
    /// cell adds `|T| D_T·∇ψ_i`, or its quadrature on a body of revolution, where `D` varies
    /// with the hoop strain; the body charge `q0` of `loads`, where there is one, at the
    /// cell's centroid), from the nodal `u` and `φ`. A node of several groups counts for the first. The variationally consistent
    /// charge: exact for the discrete solution, at the order of the energy norm's error in `h`.
    ///
    /// # Errors
    /// [`crate::AssemblyError`] where a group is not in the mesh.
    pub fn charges(
        &self,
        u: &[[f64; 3]],
        phi: &[f64],
        groups: &[&str],
        loads: &[crate::Load],
    ) -> Result<Vec<f64>, crate::AssemblyError> {
        self.charges_at(u, phi, groups, loads, None)
    }

    /// [`Discretization::charges`] summed over the nodes `counted` marks only (every node
    /// where `None`): a rank's share of the charges where the mesh is a rank's piece (its own
    /// nodes, each of whose cells the piece holds), the ranks' shares summing to the charges.
    ///
    /// # Errors
    /// As [`Discretization::charges`].
    pub fn charges_at(
        &self,
        u: &[[f64; 3]],
        phi: &[f64],
        groups: &[&str],
        loads: &[crate::Load],
        counted: Option<&[bool]>,
    ) -> Result<Vec<f64>, crate::AssemblyError> {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let mut owner = self.owners(groups)?;
        if let Some(counted) = counted {
            for (o, &c) in owner.iter_mut().zip(counted) {
                if !c {
                    *o = usize::MAX;
                }
            }
        }
        let q0 = loads.iter().find_map(|l| match l {
            crate::Load::BodyCharge(q) => Some(q),
            _ => None,
        });
        let mut out = vec![0.0; groups.len()];
        for (c, cell) in mesh.iter_cells().enumerate() {
            if !cell.iter().any(|&v| owner[v] != usize::MAX) {
                continue;
            }
            let (r, m) = (self.rule(c), self.material(c));
            let ul: Vec<[f64; 3]> = cell.iter().map(|&v| u[v]).collect();
            let pl: Vec<f64> = cell.iter().map(|&v| phi[v]).collect();
            let source = match q0 {
                Some(q) => self.source_weights(c, q),
                None => [0.0; MAX_NODES],
            };
            // D at each point of the cell's quadrature, once for all its nodes
            let flux_at: Vec<(f64, [f64; 3])> = (0..r.n_points())
                .map(|p| {
                    let grad = if self.cell_electric[c] {
                        gradient_at(dim, &r, p, &pl)
                    } else {
                        [0.0; 3]
                    };
                    (r.weight(p), displacement(m, &strain_at(dim, &r, p, &ul), &grad))
                })
                .collect();
            for (a, &v) in cell.iter().enumerate() {
                if owner[v] == usize::MAX {
                    continue;
                }
                // the conductor's charge is the negative of the flux out of the body
                for (p, (weight, d)) in flux_at.iter().enumerate() {
                    let flux: f64 = (0..dim).map(|k| d[k] * r.grad(p, a)[k]).sum();
                    out[owner[v]] -= weight * flux;
                }
                out[owner[v]] -= source[a];
            }
        }
        Ok(out)
    }

    /// `∫_T q0 N_a` for each node `a` of cell `c`: on a P1 cell at its centroid (`|T| q0(x̄)
    /// / (dim + 1)`), on a P2 cell by the loads' rule.
    fn source_weights(&self, c: usize, q: &crate::ScalarFn) -> [f64; MAX_NODES] {
        let (mesh, dim) = (self.mesh, self.mesh.dim);
        let cell = mesh.cell(c);
        let mut out = [0.0; MAX_NODES];
        if mesh.kind.order() == 1 {
            let mut x = [0.0; 3];
            for &v in cell {
                for k in 0..dim {
                    x[k] += mesh.points[v][k] / cell.len() as f64;
                }
            }
            let each = q(&x[..dim]) / cell.len() as f64;
            out[..cell.len()].fill(self.geometry[c].volume() * each);
            return out;
        }
        let (weights, points) = crate::kernels::simplex_rule(dim, 2);
        for (w, l) in weights.iter().zip(points) {
            let (x, measure) = self.cell_point(c, l);
            let qx = q(&x[..dim]) * w * measure * self.ring(&x);
            let n = crate::kernels::shape_values(dim, 2, l);
            for (o, na) in out.iter_mut().zip(n) {
                *o += qx * na;
            }
        }
        out
    }

    /// For each node, the index in `groups` of the first group holding it (`usize::MAX`: none).
    fn owners(&self, groups: &[&str]) -> Result<Vec<usize>, crate::AssemblyError> {
        let mut owner = vec![usize::MAX; self.mesh.n_nodes()];
        for (g, name) in groups.iter().enumerate() {
            for v in self.mesh.boundary(name)?.nodes() {
                if owner[v] == usize::MAX {
                    owner[v] = g;
                }
            }
        }
        Ok(owner)
    }

    /// The part of [`Discretization::charges`] that the free unknowns make: for each group,
    /// the coefficients `(a_u, a_φ)` on the free displacements and potentials with
    /// `charge = a_u · u + a_φ · φ` plus what the prescribed values and the body charge add
    /// (`-|T| (e B_b)ᵀ ∇ψ_a` on `u_b`, `|T| ∇ψ_aᵀ β ∇ψ_b` on `φ_b`, for each node `a` of the group
    /// in a cell `T` and each node `b` of `T`). A load path's charges at every step come from
    /// them without the fields.
    ///
    /// # Errors
    /// [`crate::AssemblyError`] where a group is not in the mesh.
    pub fn charge_functionals(&self, groups: &[&str]) -> Result<Vec<ChargeFunctional>, crate::AssemblyError> {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let nv = self.nv();
        let owner = self.owners(groups)?;
        let mut out = vec![(vec![0.0; self.dofs.n_u], vec![0.0; self.dofs.n_phi]); groups.len()];
        for (c, cell) in mesh.iter_cells().enumerate() {
            if !cell.iter().any(|&v| owner[v] != usize::MAX) {
                continue;
            }
            let (r, m) = (self.rule(c), self.material(c));
            for (a, &va) in cell.iter().enumerate() {
                let Some((a_u, a_phi)) = out.get_mut(owner[va]) else {
                    continue;
                };
                for (b, &vb) in cell.iter().enumerate() {
                    for p in 0..r.n_points() {
                        let grad_a = r.grad(p, a);
                        let columns = crate::kernels::strain_columns_at(dim, r.grad(p, b), r.hoop(p, b));
                        for (k, column) in columns.iter().enumerate().take(dim) {
                            if let crate::Dof::Free(j) = self.dofs.u[vb * dim + k] {
                                let d: f64 = (0..dim)
                                    .map(|l| grad_a[l] * (0..nv).map(|v| m.e[l * nv + v] * column[v]).sum::<f64>())
                                    .sum();
                                a_u[j] -= r.weight(p) * d;
                            }
                        }
                    }
                    if let (true, crate::Dof::Free(j)) = (self.cell_electric[c], self.dofs.phi[vb]) {
                        let beta = |p: usize| -> f64 {
                            let (ga, gb) = (r.grad(p, a), r.grad(p, b));
                            (0..dim)
                                .map(|l| ga[l] * (0..dim).map(|q| m.beta[l * dim + q] * gb[q]).sum::<f64>())
                                .sum()
                        };
                        a_phi[j] += match r.constant_gradients() {
                            Some(volume) => volume * beta(0),
                            None => (0..r.n_points()).map(|p| r.weight(p) * beta(p)).sum(),
                        };
                    }
                }
            }
        }
        Ok(out)
    }
}

/// `σ = C ε + eᵀ ∇φ` at a point (Voigt, `nv` entries).
fn stress(m: &Material, eps: &[f64; 6], grad: &[f64; 3]) -> [f64; 6] {
    let (dim, nv) = (m.dim, m.nv());
    let mut s = [0.0; 6];
    for (i, si) in s.iter_mut().enumerate().take(nv) {
        *si = (0..nv).map(|j| m.c[i * nv + j] * eps[j]).sum::<f64>()
            + (0..dim).map(|k| m.e[k * nv + i] * grad[k]).sum::<f64>();
    }
    s
}

/// `[σ_zz, σ_yz, σ_xz, D_z]` at a point of a plane-strain body (its material has the rows).
fn out_of_plane(m: &Material, eps: &[f64; 6], grad: &[f64; 3]) -> [f64; 4] {
    m.out_of_plane
        .as_ref()
        .map_or([f64::NAN; 4], |o| o.at(&eps[..3], &grad[..2]))
}

/// `D = e ε - β ∇φ` at a point.
fn displacement(m: &Material, eps: &[f64; 6], grad: &[f64; 3]) -> [f64; 3] {
    let (dim, nv) = (m.dim, m.nv());
    let mut d = [0.0; 3];
    for (k, dk) in d.iter_mut().enumerate().take(dim) {
        *dk = (0..nv).map(|j| m.e[k * nv + j] * eps[j]).sum::<f64>()
            - (0..dim).map(|l| m.beta[k * dim + l] * grad[l]).sum::<f64>();
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each Voigt layout lands in VTK's tensor order, shears of the strain halved: 3D's
    /// `[xx, yy, zz, yz, xz, xy]`, plane strain's `[xx, yy, xy]` with its out-of-plane rows,
    /// a body of revolution's `[rr, zz, rz, θθ]` with the hoop direction as z.
    #[test]
    fn every_layout_becomes_a_tensor_in_vtks_order() {
        let fields = |nv: usize, dim: usize, out_of_plane: Vec<f64>| CellFields {
            stress: (1..=nv).map(|i| i as f64).collect(),
            strain: (1..=nv).map(|i| 10.0 * i as f64).collect(),
            electric_displacement: (1..=dim).map(|i| i as f64).collect(),
            electric_field: (1..=dim).map(|i| -(i as f64)).collect(),
            out_of_plane,
            at_nodes: None,
        };
        let t = fields(6, 3, vec![]).tensors(3);
        assert_eq!(t.stress, [1.0, 2.0, 3.0, 6.0, 4.0, 5.0]);
        assert_eq!(t.strain, [10.0, 20.0, 30.0, 30.0, 20.0, 25.0]);
        assert_eq!(
            (t.electric_displacement, t.electric_field),
            (vec![1.0, 2.0, 3.0], vec![-1.0, -2.0, -3.0])
        );
        let t = fields(3, 2, vec![7.0, 8.0, 9.0, 4.0]).tensors(2);
        assert_eq!(t.stress, [1.0, 2.0, 7.0, 3.0, 8.0, 9.0]);
        assert_eq!(t.strain, [10.0, 20.0, 0.0, 15.0, 0.0, 0.0]);
        assert_eq!(
            (t.electric_displacement, t.electric_field),
            (vec![1.0, 2.0, 4.0], vec![-1.0, -2.0, 0.0])
        );
        // without the rows (a material given without its 3D tensors) the unknowns are NaN
        let t = fields(3, 2, vec![]).tensors(2);
        assert!(t.stress[2].is_nan() && t.stress[3] == 3.0 && t.electric_displacement[2].is_nan());
        let t = fields(4, 2, vec![]).tensors(2);
        assert_eq!(t.stress, [1.0, 2.0, 4.0, 3.0, 0.0, 0.0]);
        assert_eq!(t.strain, [10.0, 20.0, 40.0, 15.0, 0.0, 0.0]);
        assert_eq!(t.electric_displacement, [1.0, 2.0, 0.0]);
        // no entries (a run on pieces keeps none on rank 0): no tensors
        let none = CellFields {
            stress: vec![],
            strain: vec![],
            electric_displacement: vec![],
            electric_field: vec![],
            out_of_plane: vec![],
            at_nodes: None,
        };
        assert_eq!(none.tensors(3), Tensors::default());
    }
}
