//! Degrees of freedom: displacement components and potentials at nodes, free or prescribed.
//!
//! Free dofs are numbered node by node (node-major), displacements and potentials
//! separately, so that the columns of one node are contiguous in every block. A node carries a
//! potential only if an electric cell (a material with a permittivity) holds it.
//!
//! A floating terminal ([`Field::Floating`]) ties the potentials of its group's nodes to one
//! free dof (an equipotential conductor whose potential is unknown): the group's nodes share
//! that index, numbered after every other potential. Its equation is the conductor's charge
//! balance (the rows of the group summed), and its right-hand side the charge put on it.

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
    /// The potential of a floating terminal: one unknown shared by every node of the group
    /// (the condition's value is not used; the charge on the terminal is a load,
    /// [`crate::Load::TerminalCharge`]).
    Floating,
}

impl std::fmt::Display for Field {
    /// The unknown as the scene file's keys name it: `ux`, `uy`, `uz`, `phi`, or the floating
    /// potential of a terminal.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Field::Displacement(k) => write!(f, "u{}", ["x", "y", "z"].get(*k).copied().unwrap_or("?")),
            Field::Potential => f.write_str("phi"),
            Field::Floating => f.write_str("a floating terminal's potential"),
        }
    }
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

impl Constraint {
    /// A floating terminal on `group` ([`Field::Floating`]).
    pub fn floating(group: &str) -> Self {
        Constraint::constant(group, Field::Floating, 0.0)
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
    /// Number of free potential dofs (a floating terminal's counted once).
    pub n_phi: usize,
    /// The floating terminals: each group and its potential's free index (the last ones,
    /// `n_phi - floating.len()..n_phi`, in the order of their conditions).
    pub floating: Vec<(String, usize)>,
}

/// A dof map's prescribed values by index ([`DofMap::prescribed`]): `(index, value)` of the
/// displacements (`node * dim + k`) and of the potentials.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Prescribed {
    u: Vec<(usize, f64)>,
    phi: Vec<(usize, f64)>,
}

impl DofMap {
    /// The same map with its prescribed values scaled: displacement component `k` by `u[k]`,
    /// potentials by `phi` (the same dofs free: a load path's instant).
    pub fn scaled(&self, u: [f64; 3], phi: f64) -> DofMap {
        let mut out = self.clone();
        out.rescale(&self.prescribed(), u, phi);
        out
    }

    /// The prescribed values of the map, by index: what [`DofMap::rescale`] scales.
    pub fn prescribed(&self) -> Prescribed {
        let fixed = |dofs: &[Dof]| {
            dofs.iter()
                .enumerate()
                .filter_map(|(i, d)| match *d {
                    Dof::Fixed(v) => Some((i, v)),
                    _ => None,
                })
                .collect()
        };
        Prescribed {
            u: fixed(&self.u),
            phi: fixed(&self.phi),
        }
    }

    /// Sets the prescribed values of this map to those of `prescribed` (a map of the same
    /// dofs: [`DofMap::prescribed`]) scaled as [`DofMap::scaled`] scales them, in place: a
    /// path's instant after instant, in the time of its prescribed values alone.
    ///
    /// # Panics
    /// Where `prescribed` holds an index beyond this map's dofs (another map's values).
    pub fn rescale(&mut self, prescribed: &Prescribed, u: [f64; 3], phi: f64) {
        let dim = self.dim.max(1);
        for &(i, v) in &prescribed.u {
            self.u[i] = Dof::Fixed(v * u[i % dim]);
        }
        for &(i, v) in &prescribed.phi {
            self.phi[i] = Dof::Fixed(v * phi);
        }
    }

    /// Builds the map: `has_phi[node]` says which nodes carry a potential; `constraints` are
    /// applied in order; a node that no cell uses has its displacement held at 0 (no unknown).
    /// A node constrained twice to values that differ by more than 1e-12 (relative) is an
    /// error, and so are a condition that reaches no dof and a floating terminal that touches
    /// another terminal.
    pub fn new(mesh: &Mesh, has_phi: &[bool], constraints: &[Constraint]) -> Result<DofMap, AssemblyError> {
        let mut held = Held {
            mesh,
            has_phi,
            constraints,
            u: vec![None; mesh.n_nodes() * mesh.dim],
            phi: vec![None; mesh.n_nodes()],
            tie: vec![None; mesh.n_nodes()],
            floating: vec![],
        };
        for (ci, c) in constraints.iter().enumerate() {
            let reached = match c.field {
                Field::Floating => held.tie(ci)?,
                _ => held.prescribe(ci)?,
            };
            if reached == 0 {
                return Err(InputError::ReachesNothing {
                    field: c.field,
                    group: c.group.clone(),
                }
                .into());
            }
        }
        Ok(held.number())
    }

    /// Expands a node order (`order[new] = old node`) to the free dofs of `K`'s `[u; φ]`
    /// layout: each node's displacement components, then its potential (index `n_u + j`).
    ///
    /// A floating terminal's potential, coupled to every node of its group, comes last (as a
    /// dense row would: eliminated early it would fill the whole group's neighbourhood).
    pub fn expand_node_order(&self, order: &[usize]) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.n_u + self.n_phi);
        let first_floating = self.n_phi - self.floating.len();
        for &node in order {
            for k in 0..self.dim {
                if let Dof::Free(j) = self.u[node * self.dim + k] {
                    out.push(j);
                }
            }
            match self.phi[node] {
                Dof::Free(j) if j < first_floating => out.push(self.n_u + j),
                _ => {}
            }
        }
        out.extend((first_floating..self.n_phi).map(|j| self.n_u + j));
        out
    }

    /// The same map with each node of a floating terminal given a potential of its own (the
    /// potentials numbered node by node again, as without the terminals), and the fold that
    /// takes each of its potentials to the tied map's (`fold[j]`): the element-by-element
    /// assembly works on the untied map, whose unknowns belong to one node each, in node
    /// order. `None` without floating terminals.
    pub fn untied(&self) -> Option<(DofMap, Vec<usize>)> {
        if self.floating.is_empty() {
            return None;
        }
        let mut out = self.clone();
        let mut fold = vec![];
        for d in &mut out.phi {
            if let Dof::Free(j) = *d {
                *d = Dof::Free(fold.len());
                fold.push(j);
            }
        }
        out.n_phi = fold.len();
        out.floating.clear();
        Some((out, fold))
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

/// The conditions met so far while a [`DofMap`] is built: each dof's prescribed value and the
/// condition that set it, and each node's floating terminal.
struct Held<'a> {
    mesh: &'a Mesh,
    has_phi: &'a [bool],
    constraints: &'a [Constraint],
    u: Vec<Option<(f64, usize)>>,
    phi: Vec<Option<(f64, usize)>>,
    /// The floating terminal (an index into `floating`) that ties a node's potential.
    tie: Vec<Option<usize>>,
    /// Each floating terminal's group and its first condition.
    floating: Vec<(String, usize)>,
}

impl Held<'_> {
    fn joined(&self, node: usize, floating: &str, other: usize) -> AssemblyError {
        InputError::JoinedTerminals {
            node,
            at: self.mesh.point(node).to_vec(),
            floating: floating.to_string(),
            other: self.constraints[other].group.clone(),
        }
        .into()
    }

    /// Condition `ci`, a floating terminal: ties the potentials of its group's nodes. Returns
    /// how many it reached.
    fn tie(&mut self, ci: usize) -> Result<usize, AssemblyError> {
        let c = &self.constraints[ci];
        let group = self.mesh.boundary(&c.group)?;
        let t = match self.floating.iter().position(|(g, _)| g == &c.group) {
            Some(t) => t,
            None => {
                self.floating.push((c.group.clone(), ci));
                self.floating.len() - 1
            }
        };
        let mut reached = 0;
        for node in group.nodes().into_iter().filter(|&v| self.has_phi[v]) {
            let other = match (self.phi[node], self.tie[node]) {
                (Some((_, from)), _) => Some(from),
                (None, Some(s)) if s != t => Some(self.floating[s].1),
                _ => None,
            };
            if let Some(from) = other {
                return Err(self.joined(node, &c.group, from));
            }
            self.tie[node] = Some(t);
            reached += 1;
        }
        Ok(reached)
    }

    /// Condition `ci`, a prescribed value: sets it on its group's dofs. Returns how many it
    /// reached.
    fn prescribe(&mut self, ci: usize) -> Result<usize, AssemblyError> {
        let (c, mesh, dim) = (&self.constraints[ci], self.mesh, self.mesh.dim);
        let mut reached = 0;
        for node in mesh.boundary(&c.group)?.nodes() {
            if let (Field::Potential, Some(t)) = (c.field, self.tie[node]) {
                let floating = self.floating[t].1;
                return Err(self.joined(node, &self.constraints[floating].group, ci));
            }
            let slot = match c.field {
                Field::Displacement(k) if k < dim => &mut self.u[node * dim + k],
                Field::Displacement(k) => {
                    return Err(InputError::Component {
                        group: c.group.clone(),
                        component: k,
                        dim,
                    }
                    .into())
                }
                Field::Potential if self.has_phi[node] => &mut self.phi[node],
                Field::Potential | Field::Floating => continue,
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
                        first: self.constraints[from].group.clone(),
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
        Ok(reached)
    }

    /// The map: the free dofs numbered node by node, each floating terminal's potential after
    /// the other potentials.
    fn number(self) -> DofMap {
        let (mesh, dim) = (self.mesh, self.mesh.dim);
        // a node that no cell uses (the centre of a Gmsh arc) has no stiffness: its displacement
        // is no unknown (held at 0, as the mesh reports)
        let mut used = vec![false; mesh.n_nodes()];
        for &v in &mesh.cells {
            used[v] = true;
        }
        let mut n_u = 0;
        let u = self
            .u
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
        let mut phi: Vec<Dof> = self
            .phi
            .into_iter()
            .zip(self.has_phi)
            .zip(&self.tie)
            .map(|((s, &has), t)| match (s, has, t) {
                (_, false, _) => Dof::Absent,
                (Some((v, _)), true, _) => Dof::Fixed(v),
                (None, true, Some(_)) => Dof::Absent, // numbered below, after the others
                (None, true, None) => {
                    n_phi += 1;
                    Dof::Free(n_phi - 1)
                }
            })
            .collect();
        for (node, t) in self.tie.iter().enumerate() {
            if let Some(t) = t {
                phi[node] = Dof::Free(n_phi + t);
            }
        }
        let floating: Vec<(String, usize)> = self
            .floating
            .into_iter()
            .enumerate()
            .map(|(t, (group, _))| (group, n_phi + t))
            .collect();
        n_phi += floating.len();
        DofMap {
            dim,
            u,
            phi,
            n_u,
            n_phi,
            floating,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Dof, DofMap};

    /// A path's instant's map: every prescribed value scaled by its component's factor (each
    /// node's `dim` components in turn), the free dofs as they were, in place as new.
    #[test]
    fn scaling_in_place_is_scaling_anew() {
        let base = DofMap {
            dim: 2,
            u: vec![
                Dof::Fixed(1.0),
                Dof::Free(0),
                Dof::Free(1),
                Dof::Fixed(-3.0),
                Dof::Fixed(5.0),
                Dof::Fixed(7.0),
            ],
            phi: vec![Dof::Fixed(2.0), Dof::Free(0), Dof::Fixed(-1.0)],
            n_u: 2,
            n_phi: 1,
            floating: vec![],
        };
        let scaled = base.scaled([10.0, 100.0, 1000.0], 0.5);
        let expected_u = [
            Dof::Fixed(10.0),
            Dof::Free(0),
            Dof::Free(1),
            Dof::Fixed(-300.0),
            Dof::Fixed(50.0),
            Dof::Fixed(700.0),
        ];
        assert_eq!(scaled.u, expected_u);
        assert_eq!(scaled.phi, [Dof::Fixed(1.0), Dof::Free(0), Dof::Fixed(-0.5)]);
        assert_eq!((scaled.dim, scaled.n_u, scaled.n_phi), (2, 2, 1));
        let mut again = base.scaled([0.0; 3], 0.0);
        again.rescale(&base.prescribed(), [10.0, 100.0, 1000.0], 0.5);
        assert_eq!(again, scaled);
    }
}
