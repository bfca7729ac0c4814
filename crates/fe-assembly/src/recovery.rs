//! Recovery of the stress `σ = C ε(u) + eᵀ ∇φ` and the electric displacement
//! `D = e ε(u) - β ∇φ` (DESIGN.md's law; `E = -∇φ`), constant on each P1 cell.

use crate::kernels::{cell_gradient, cell_strain};
use crate::Discretization;

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
}

impl Discretization<'_> {
    /// Stress, strain, electric displacement and field on every cell, from nodal `u` and `φ`.
    pub fn recover(&self, u: &[[f64; 3]], phi: &[f64]) -> CellFields {
        let mesh = self.mesh;
        let dim = mesh.dim;
        let nv = if dim == 2 { 3 } else { 6 };
        let n = mesh.n_cells();
        let mut out = CellFields {
            stress: Vec::with_capacity(n * nv),
            electric_displacement: Vec::with_capacity(n * dim),
            strain: Vec::with_capacity(n * nv),
            electric_field: Vec::with_capacity(n * dim),
        };
        for (c, cell) in mesh.iter_cells().enumerate() {
            let g = &self.geometry[c];
            let m = self.material(c);
            let ul: Vec<[f64; 3]> = cell.iter().map(|&v| u[v]).collect();
            let pl: Vec<f64> = cell.iter().map(|&v| phi[v]).collect();
            let eps = cell_strain(dim, g, &ul);
            let grad = if self.cell_electric[c] {
                cell_gradient(dim, g, &pl)
            } else {
                [0.0; 3]
            };
            for i in 0..nv {
                let s: f64 = (0..nv).map(|j| m.c[i * nv + j] * eps[j]).sum::<f64>()
                    + (0..dim).map(|k| m.e[k * nv + i] * grad[k]).sum::<f64>();
                out.stress.push(s);
                out.strain.push(eps[i]);
            }
            for k in 0..dim {
                let dk: f64 = (0..nv).map(|j| m.e[k * nv + j] * eps[j]).sum::<f64>()
                    - (0..dim).map(|l| m.beta[k * dim + l] * grad[l]).sum::<f64>();
                out.electric_displacement.push(dk);
                out.electric_field.push(-grad[k]);
            }
        }
        out
    }
}
