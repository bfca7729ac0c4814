//! Degrees of freedom: displacement components and potentials at nodes, free or prescribed.
//!
//! Free dofs are numbered node by node (node-major), displacements and potentials
//! separately, so that the columns of one node are contiguous in every block. A node carries a
//! potential only if an electric cell (a material with a permittivity) holds it.

use crate::InputError;
use crate::{AssemblyError, ScalarFn};
use mesh::Mesh;

/// The state of one degree of freedom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dof {
    /// An unknown, with its index among the free dofs of its field.
    Free(usize),
    /// A prescribed value (Dirichlet condition), eliminated from the system.
    Fixed(f64),
    /// No such unknown (a potential at a node of a purely elastic region).
    Absent,
}

/// Which field a Dirichlet condition prescribes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Displacement component `k` (0 = x, 1 = y, 2 = z).
    Displacement(usize),
    /// The electric potential.
    Potential,
}

/// A Dirichlet condition `field = value(x)` on the nodes of a boundary group.
#[derive(Clone)]
pub struct Constraint {
    /// The boundary group's name.
    pub group: String,
    /// The prescribed field.
    pub field: Field,
    /// The value at a node's coordinates.
    pub value: ScalarFn,
}

impl Constraint {
    /// `field = value` (a constant) on `group`.
    pub fn constant(group: &str, field: Field, value: f64) -> Self {
        Constraint {
            group: group.into(),
            field,
            value: std::sync::Arc::new(move |_| value),
        }
    }
}

impl std::fmt::Debug for Constraint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Constraint({:?} on `{}`)", self.field, self.group)
    }
}

/// Displacement and potential dofs of every node.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// Spatial dimension (components per node).
    pub dim: usize,
    /// `u[node * dim + k]`.
    pub u: Vec<Dof>,
    /// `phi[node]`.
    pub phi: Vec<Dof>,
    /// Number of free displacement dofs.
    pub n_u: usize,
    /// Number of free potential dofs.
    pub n_phi: usize,
}

impl DofMap {
    /// The same map with its prescribed values scaled: displacement component `k` by `u[k]`,
    /// potentials by `phi` (the same dofs free: a load path's instant).
    pub fn scaled(&self, u: [f64; 3], phi: f64) -> DofMap {
        let dim = self.dim;
        let scale = |d: &Dof, f: f64| match *d {
            Dof::Fixed(v) => Dof::Fixed(v * f),
            other => other,
        };
        DofMap {
            u: self.u.iter().enumerate().map(|(i, d)| scale(d, u[i % dim])).collect(),
            phi: self.phi.iter().map(|d| scale(d, phi)).collect(),
            ..self.clone()
        }
    }

    /// Builds the map: `has_phi[node]` says which nodes carry a potential; `constraints` are
    /// applied in order; a node that no cell uses has its displacement held at 0 (no unknown). A node constrained twice to values that differ by more than 1e-12
    /// (relative) is an error, and so is a condition that reaches no dof.
    pub fn new(mesh: &Mesh, has_phi: &[bool], constraints: &[Constraint]) -> Result<DofMap, AssemblyError> {
        let (n, dim) = (mesh.n_nodes(), mesh.dim);
        let mut u: Vec<Option<(f64, usize)>> = vec![None; n * dim];
        let mut phi: Vec<Option<(f64, usize)>> = vec![None; n];
        for (ci, c) in constraints.iter().enumerate() {
            let group = mesh.boundary(&c.group)?;
            let mut reached = 0usize;
            for node in group.nodes() {
                let slot = match c.field {
                    Field::Displacement(k) if k < dim => &mut u[node * dim + k],
                    Field::Displacement(k) => {
                        return Err(InputError::Component {
                            group: c.group.clone(),
                            component: k,
                            dim,
                        }
                        .into())
                    }
                    Field::Potential if has_phi[node] => &mut phi[node],
                    Field::Potential => continue,
                };
                let v = (c.value)(mesh.point(node));
                if !v.is_finite() {
                    return Err(InputError::NotFiniteCondition {
                        group: c.group.clone(),
                        value: v,
                        node,
                    }
                    .into());
                }
                if let Some((old, from)) = *slot {
                    if (old - v).abs() > 1e-12 * old.abs().max(v.abs()) {
                        return Err(InputError::Conflicting {
                            node,
                            at: mesh.point(node).to_vec(),
                            field: c.field,
                            first: constraints[from].group.clone(),
                            first_value: old,
                            second: c.group.clone(),
                            second_value: v,
                        }
                        .into());
                    }
                }
                *slot = Some((v, ci));
                reached += 1;
            }
            if reached == 0 {
                return Err(InputError::ReachesNothing {
                    field: c.field,
                    group: c.group.clone(),
                }
                .into());
            }
        }
        // a node that no cell uses (the centre of a Gmsh arc) has no stiffness: its displacement
        // is no unknown (held at 0, as the mesh reports)
        let mut used = vec![false; n];
        for &v in &mesh.cells {
            used[v] = true;
        }
        let mut n_u = 0;
        let u = u
            .into_iter()
            .enumerate()
            .map(|(i, s)| match s {
                Some((v, _)) => Dof::Fixed(v),
                None if !used[i / dim] => Dof::Fixed(0.0),
                None => {
                    n_u += 1;
                    Dof::Free(n_u - 1)
                }
            })
            .collect();
        let mut n_phi = 0;
        let phi = phi
            .into_iter()
            .zip(has_phi)
            .map(|(s, &has)| match (s, has) {
                (_, false) => Dof::Absent,
                (Some((v, _)), true) => Dof::Fixed(v),
                (None, true) => {
                    n_phi += 1;
                    Dof::Free(n_phi - 1)
                }
            })
            .collect();
        Ok(DofMap {
            dim,
            u,
            phi,
            n_u,
            n_phi,
        })
    }

    /// Expands a node order (`order[new] = old node`) to the free dofs of `K`'s `[u; φ]`
    /// layout: each node's displacement components, then its potential (index `n_u + j`).
    pub fn expand_node_order(&self, order: &[usize]) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.n_u + self.n_phi);
        for &node in order {
            for k in 0..self.dim {
                if let Dof::Free(j) = self.u[node * self.dim + k] {
                    out.push(j);
                }
            }
            if let Dof::Free(j) = self.phi[node] {
                out.push(self.n_u + j);
            }
        }
        out
    }

    /// Nodal displacements `[x, y, z]` from the free values (prescribed values filled in).
    pub fn expand_u(&self, u_free: &[f64]) -> Vec<[f64; 3]> {
        self.u
            .chunks_exact(self.dim)
            .map(|node| {
                let mut out = [0.0; 3];
                for (k, d) in node.iter().enumerate() {
                    out[k] = value(*d, u_free);
                }
                out
            })
            .collect()
    }

    /// Nodal potentials from the free values (prescribed values filled in; 0 where absent).
    pub fn expand_phi(&self, phi_free: &[f64]) -> Vec<f64> {
        self.phi.iter().map(|d| value(*d, phi_free)).collect()
    }

    /// The free-dof vector of a nodal displacement field (the inverse of [`DofMap::expand_u`]
    /// on the free dofs).
    pub fn restrict_u(&self, nodal: &[[f64; 3]]) -> Vec<f64> {
        let mut out = vec![0.0; self.n_u];
        for (i, d) in self.u.iter().enumerate() {
            if let Dof::Free(j) = d {
                out[*j] = nodal[i / self.dim][i % self.dim];
            }
        }
        out
    }

    /// The free-dof vector of a nodal potential.
    pub fn restrict_phi(&self, nodal: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n_phi];
        for (i, d) in self.phi.iter().enumerate() {
            if let Dof::Free(j) = d {
                out[*j] = nodal[i];
            }
        }
        out
    }
}

fn value(d: Dof, free: &[f64]) -> f64 {
    match d {
        Dof::Free(j) => free[j],
        Dof::Fixed(v) => v,
        Dof::Absent => 0.0,
    }
}
