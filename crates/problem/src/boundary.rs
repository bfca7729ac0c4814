//! The contact boundary as the `contact` crate sees it: points with normals, tangents, lumped
//! weights and gaps, and two implementations of "given multipliers, return the contact
//! displacement": one full primal solve per call ([`FullSolve`]), or the condensed dense
//! compliance `D = R (K⁻¹)_cc Rᵀ` (Delassus operator), from the condensation of `K` onto the
//! contact dofs that `linalg` does ([`ContactBoundary::condense`]). The projection `R` of the
//! contact dofs onto each point's normal and tangents is this module's; the sparse work is
//! linalg's.

use crate::factorization::Factorization;
use crate::scene::{ContactSpec, Friction};
use crate::ProblemError;
use crate::SetupError;
use contact::{
    ContactOperator, ContactPoints, DenseContactProblem, ElectricContactProblem, OperatorError, PointValues,
};
use fe_assembly::{facet_measure, Coordinates, Discretization, Dof, DofMap};
use linalg::{CondensedLoads, CoupledSolver};
use rayon::prelude::*;

/// The foundation a contact zone presses on: its `contact.compliance`, or rigid.
fn foundation_of(spec: &ContactSpec) -> contact::Foundation {
    spec.model().map_or(contact::Foundation::Rigid, |m| m.normal)
}

/// The contact points of a boundary group and the u dofs of their nodes.
#[derive(Clone)]
pub struct ContactBoundary {
    /// The points.
    pub points: ContactPoints,
    /// Mesh node of each point.
    pub nodes: Vec<usize>,
    /// The free u dofs of the points' nodes, point by point, components in order: the dofs the
    /// condensation puts last.
    pub dofs: Vec<usize>,
    /// Each component (`dim` per point) of the points' displacement: a sum of terms, each a
    /// coefficient times a nodal component, free (its place in `dofs`) or prescribed by a
    /// Dirichlet condition; one term of coefficient 1, the point's node's, except at the edge
    /// nodes of a second-order face in the modified basis ([`MODIFIED_ALPHA`]).
    slots: Vec<Vec<Term>>,
    /// Nodes of the group whose normal displacement a Dirichlet condition prescribes: the
    /// support holds them, and they are no contact points (a clamped corner).
    pub held_nodes: usize,
    /// Those of them that the condition holds past the gap, inside the foundation (a clamped
    /// corner of a body pressed in by a negative gap): the condition wins.
    pub held_inside: usize,
    /// Electrical contact: the law and the points with a free potential, and the potentials'
    /// dofs their potentials are made of (indices into `[u; φ]`), condensed after `dofs`: each
    /// point's own first, in the points' order, then those its terms add.
    pub electric: Option<(contact::ElectricContact, Vec<usize>)>,
    /// Each electric point's potential as terms: a coefficient times a free potential (its
    /// place in the electric dofs) or a prescribed one; its own dof alone, or in the modified
    /// basis its edge's corners' too.
    phi_terms: Vec<Vec<Term>>,
    /// The contact group of each point (an index into `groups`).
    pub group_of: Vec<usize>,
    /// The contact groups, in the scene's order.
    pub groups: Vec<String>,
    /// Whether the body is one of revolution (its meridian meshed, x the radius): a vector's
    /// radial part has no resultant over the revolution.
    pub revolution: bool,
    /// The uniform part of each point's gap (its group's `contact.gap` less an indenter's
    /// depth), which a load path's `gap` factor scales.
    uniform: Vec<f64>,
}

/// A term of a contact point's displacement component: its coefficient and the nodal
/// component it takes.
type Term = (f64, Slot);

/// The share of each edge function of a second-order contact face moved to its two corners in
/// the modified basis (`Ñ_i = N_i + α Σ_edges N_ij`, `Ñ_ij = (1 - 2α) N_ij`; Popp, Wohlmuth,
/// Gee & Wall, SIAM J. Sci. Comput. 34 (2012) B421, whose `α = 1/5` gives a six-node face's
/// corners `2A/15` and its edges `A/5`): every point's weight positive where a corner's own
/// vanishes (a 3D face, a corner on the axis of a body of revolution). The points then carry
/// the displacements of that basis, `û_c = u_c` at a corner and `û_ij = (u_ij - α (u_i +
/// u_j)) / (1 - 2α)` at an edge node (equal to `u` for every linear field).
pub const MODIFIED_ALPHA: f64 = 0.2;

/// The free terms of a point's potential: `(coefficient, place in the electric dofs)`.
fn free_terms(terms: &[Term]) -> impl Iterator<Item = (f64, usize)> + '_ {
    terms.iter().filter_map(|&(c, slot)| match slot {
        Slot::Free(j) => Some((c, j)),
        Slot::Fixed(_) => None,
    })
}

/// The error of a contact node `node` at `x` whose weight `w` is not positive: no force of the
/// face's acts on it, so its law could hold nothing there.
fn weightless(spec: &ContactSpec, node: usize, x: &[f64], w: f64) -> ProblemError {
    SetupError::new(
        "contact.group",
        format!(
            "node {node} of contact group `{}` (at {x:?}) carries no weight of the face ({w:e}): contact could not act on it (a face of zero measure there?)",
            spec.group
        ),
    )
    .into()
}

/// One displacement component of a contact point.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slot {
    /// A free dof, by its place in [`ContactBoundary::dofs`].
    Free(usize),
    /// A prescribed value.
    Fixed(f64),
}

/// How a contact direction (the normal, or a tangent) meets a node's prescribed components.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Direction {
    /// No prescribed component moves along it: contact acts.
    Free,
    /// Prescribed components alone span it: the support holds it.
    Held,
    /// Both: neither contact nor the support alone decides the motion along it.
    Mixed,
}

/// Directions within this of the free or the prescribed components are taken as along them.
const ALIGNED: f64 = 1e-9;

fn direction(d: &[f64; 3], fixed: &[bool], dim: usize) -> Direction {
    let part = |held: bool| {
        (0..dim)
            .filter(|&k| fixed[k] == held)
            .map(|k| d[k] * d[k])
            .sum::<f64>()
            .sqrt()
    };
    if part(true) <= ALIGNED {
        Direction::Free
    } else if part(false) <= ALIGNED {
        Direction::Held
    } else {
        Direction::Mixed
    }
}

/// `t1` = the first axis made orthogonal to `n`; in 3D `t2 = t1 x n` (so that n = -z gives
/// t1 = x, t2 = y, as docs/scenes.md fixes).
fn tangent_basis(dim: usize, n: [f64; 3]) -> [[f64; 3]; 2] {
    if dim == 2 {
        return [[-n[1], n[0], 0.0], [0.0; 3]];
    }
    let mut t1 = [0.0; 3];
    for axis in 0..3 {
        let mut e = [0.0; 3];
        e[axis] = 1.0;
        let d = n[axis];
        let v = [e[0] - d * n[0], e[1] - d * n[1], e[2] - d * n[2]];
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if l > 1e-8 {
            t1 = [v[0] / l, v[1] / l, v[2] / l];
            break;
        }
    }
    let t2 = [
        t1[1] * n[2] - t1[2] * n[1],
        t1[2] * n[0] - t1[0] * n[2],
        t1[0] * n[1] - t1[1] * n[0],
    ];
    [t1, t2]
}

/// The largest angle between `contact.normal` and the outward normal of a facet of the
/// contact group: beyond it the given normal does not describe the face (pointing into the
/// body, it would let the body pass through the foundation; tangent to it, it would turn the
/// contact force sideways). 45° lets a mildly curved face keep one normal.
pub const MAX_NORMAL_ANGLE_DEG: f64 = 45.0;

/// The unit normal of a validated spec in dimension `dim` (scaled, so that tiny or huge
/// components neither underflow nor overflow).
fn unit_normal(spec: &ContactSpec, dim: usize) -> Result<[f64; 3], SetupError> {
    let len = mesh::scaled_norm(&spec.normal);
    if !(len > 0.0) || !len.is_finite() {
        return Err(SetupError::new(
            "contact.normal",
            "contact.normal is not a non-zero vector",
        ));
    }
    let mut nv = [0.0; 3];
    for k in 0..dim {
        nv[k] = spec.normal[k] / len;
    }
    Ok(nv)
}

/// Checks the unit normal `nv` against the outward normal of every facet of the group.
fn check_normal(mesh: &mesh::Mesh, spec: &ContactSpec, nv: [f64; 3]) -> Result<(), ProblemError> {
    let g = mesh.boundary(&spec.group)?;
    for (f, out) in mesh.outward_normals(&spec.group)?.iter().enumerate() {
        let cos: f64 = (0..3).map(|k| out[k] * nv[k]).sum();
        let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
        if angle > MAX_NORMAL_ANGLE_DEG {
            let at = mesh.points[g.facet(f)[0]];
            let shown: Vec<String> = out[..mesh.dim].iter().map(|x| format!("{x:.3}")).collect();
            return Err(SetupError::new(
                "contact.normal",
                format!(
                    "contact.normal {:?} makes {angle:.0}° with the outward normal [{}] of facet {f} of `{}` (at {:?}); it must point out of the body, within {MAX_NORMAL_ANGLE_DEG}° of every facet's",
                    spec.normal,
                    shown.join(", "),
                    spec.group,
                    &at[..mesh.dim]
                ),
            )
            .into());
        }
    }
    Ok(())
}

/// The boundary mass of each node on `group`, `∫ N_a ds` over its facets: with P1 each
/// facet's measure shared equally among its nodes; a straight six-node triangle (3D, P2)
/// gives its corners 0 and its edges a third each; on a body of revolution
/// ([`Coordinates::Axisymmetric`]), the ring's, `∫ N_a 2π r ds = 2π L (2 r_a + r_b) / 6` for
/// the segment of length L from node a to node b. A second-order segment (2D, its corners then
/// its midpoint) gives Simpson's `L / 6, L / 6, 2 L / 3`, and on a body of revolution
/// `2π L (r_a / 6, r_b / 6, (r_a + r_b) / 3)` (the corners' share of the linear part of `r`
/// vanishes: `∫ s (1 - s)(1 - 2s) ds = 0`), so a corner on the axis weighs nothing. A curved
/// second-order facet (an edge node off its chord): by the loads' rule over its map
/// ([`fe_assembly::FacetMap`]).
fn lumped_weights(mesh: &mesh::Mesh, group: &mesh::FacetGroup, coordinates: Coordinates) -> Vec<f64> {
    let mut weight = vec![0.0; mesh.n_nodes()];
    for f in group.iter() {
        for (&v, w) in f.iter().zip(facet_weights(mesh, f, coordinates)) {
            weight[v] += w;
        }
    }
    weight
}

/// Facet `f`'s share of [`lumped_weights`]: `∫ N_a ds` over it of each of its nodes, in its
/// order (at most six).
fn facet_weights(mesh: &mesh::Mesh, f: &[usize], coordinates: Coordinates) -> [f64; 6] {
    let ring = coordinates == Coordinates::Axisymmetric;
    let tau = std::f64::consts::TAU;
    let mut weight = [0.0; 6];
    let map = fe_assembly::FacetMap::of(mesh, f);
    if map.is_curved() {
        // a curved second-order facet: ∫ N_a over its map, by the loads' rule
        let d = mesh.dim - 1;
        let (weights, points) = fe_assembly::kernels::simplex_rule(d, 2);
        for (w, l) in weights.iter().zip(points) {
            let (at, measure) = map.at(l);
            let n = fe_assembly::kernels::shape_values(d, 2, l);
            let ds = w * measure * if ring { tau * at[0] } else { 1.0 };
            for (o, na) in weight.iter_mut().zip(n).take(f.len()) {
                *o += ds * na;
            }
        }
        return weight;
    }
    let x: Vec<[f64; 3]> = f.iter().map(|&v| mesh.points[v]).collect();
    let len = facet_measure(&x[..mesh.dim.min(x.len())]);
    match (f.len(), ring) {
        (3, true) if mesh.dim == 2 => {
            let (ra, rb) = (x[0][0], x[1][0]);
            weight[..3].copy_from_slice(&[tau * len * ra / 6.0, tau * len * rb / 6.0, tau * len * (ra + rb) / 3.0]);
        }
        (3, false) if mesh.dim == 2 => weight[..3].copy_from_slice(&[len / 6.0, len / 6.0, 2.0 * len / 3.0]),
        (_, true) => {
            let (ra, rb) = (x[0][0], x[1][0]);
            weight[..2].copy_from_slice(&[tau * len * (2.0 * ra + rb) / 6.0, tau * len * (ra + 2.0 * rb) / 6.0]);
        }
        // a six-node triangle: its corners' ∫ N_c = 0, its edges' ∫ N_ij = A/3
        (6, false) => weight[3..6].fill(len / 3.0),
        (n, false) => weight[..n].fill(len / n as f64),
    }
    weight
}

/// The basis of a contact face's points: their weights, and the corners of each edge node
/// whose displacement the modified basis mixes in (none with P1, or a 2D second-order face
/// off the axis, whose weights are all positive as they are).
struct FaceBasis {
    weight: Vec<f64>,
    edge_corners: std::collections::HashMap<usize, [usize; 2]>,
}

impl FaceBasis {
    /// The basis of `group`: the face's own (`∫ N_a`, [`lumped_weights`]), or on a
    /// second-order face in 3D or on a body of revolution the modified one
    /// ([`MODIFIED_ALPHA`]): `w̃_c = ∫ N_c + α Σ ∫ N_e` over the edges at each corner,
    /// `w̃_e = (1 - 2α) ∫ N_e`.
    fn of(mesh: &mesh::Mesh, group: &mesh::FacetGroup, coordinates: Coordinates) -> FaceBasis {
        let own = lumped_weights(mesh, group, coordinates);
        let modified = mesh.kind.order() == 2 && (mesh.dim == 3 || coordinates == Coordinates::Axisymmetric);
        if !modified {
            return FaceBasis {
                weight: own,
                edge_corners: Default::default(),
            };
        }
        let alpha = MODIFIED_ALPHA;
        let edges = fe_assembly::kernels::simplex_edges(mesh.dim - 1);
        let corners = mesh.dim;
        let mut weight = vec![0.0; mesh.n_nodes()];
        let mut edge_corners = std::collections::HashMap::new();
        for f in group.iter() {
            // the facet's own ∫ N_a, each node's share of this facet alone
            let n = facet_weights(mesh, f, coordinates);
            for (e, &[a, b]) in edges.iter().enumerate() {
                let m = f[corners + e];
                let ne = n[corners + e];
                weight[f[a]] += alpha * ne;
                weight[f[b]] += alpha * ne;
                weight[m] += (1.0 - 2.0 * alpha) * ne;
                edge_corners.insert(m, [f[a], f[b]]);
            }
            for (&c, nc) in f[..corners].iter().zip(n) {
                weight[c] += nc;
            }
        }
        FaceBasis { weight, edge_corners }
    }

    /// The nodal components point `node`'s displacement is made of: `(coefficient, node)`.
    fn terms(&self, node: usize) -> Vec<(f64, usize)> {
        match self.edge_corners.get(&node) {
            None => vec![(1.0, node)],
            Some(&[a, b]) => {
                let (alpha, scale) = (MODIFIED_ALPHA, 1.0 / (1.0 - 2.0 * MODIFIED_ALPHA));
                vec![(scale, node), (-alpha * scale, a), (-alpha * scale, b)]
            }
        }
    }
}

impl ContactBoundary {
    /// The contact points of the group of `spec`: its nodes, weighted by their lumped boundary
    /// mass, with the gap `gap + |x - c|²_t / (2R)` (uniform, plus the parabola of a curved
    /// body along the face). A node some of whose displacement components a Dirichlet condition
    /// prescribes is a contact point in its free directions: a tangent that the prescribed
    /// components span is held (its multiplier 0: the support takes the force, as on a symmetry
    /// plane); a normal they span leaves the node to its support (it is no contact point,
    /// counted in `held_nodes`, and in `held_inside` where the condition holds it past the gap).
    ///
    /// # Errors
    /// A missing group, a group with facets inside the mesh, a zero normal or one beyond
    /// [`MAX_NORMAL_ANGLE_DEG`] of a facet; a node whose prescribed components lie across the
    /// normal or a tangent (neither along nor orthogonal to it); a group with no contact point
    /// left.
    pub fn new(disc: &Discretization<'_>, spec: &ContactSpec) -> Result<Self, ProblemError> {
        Self::of_groups(disc, &[spec])
    }

    /// The contact points of several groups (`[[contact]]`), each as [`ContactBoundary::new`]
    /// makes them with its own normal, gap and friction, in the order of the groups. A node
    /// of two groups (a corner against two faces) is a point of each, its displacement dofs
    /// condensed once.
    ///
    /// # Errors
    /// As [`ContactBoundary::new`], for each group.
    pub fn of_groups(disc: &Discretization<'_>, specs: &[&ContactSpec]) -> Result<Self, ProblemError> {
        Self::of_nodes(disc, specs, None)
    }

    /// [`ContactBoundary::of_groups`] on a rank's piece of the mesh: the points of the nodes
    /// the rank owns (`owned`, per node of the piece) only, each counted by one rank. A group
    /// may hold none of them here (another rank's piece holds its points): whether it holds
    /// any on some rank is the caller's to sum.
    ///
    /// # Errors
    /// As [`ContactBoundary::of_groups`], but for a group without points.
    pub fn of_groups_on_piece(
        disc: &Discretization<'_>,
        specs: &[&ContactSpec],
        owned: &[bool],
    ) -> Result<Self, ProblemError> {
        Self::of_nodes(disc, specs, Some(owned))
    }

    /// The boundary of the points of `specs` at the nodes `owned` marks (every node where
    /// `None`, and then a group without points is refused).
    fn of_nodes(
        disc: &Discretization<'_>,
        specs: &[&ContactSpec],
        owned: Option<&[bool]>,
    ) -> Result<Self, ProblemError> {
        let dim = disc.mesh.dim;
        let mut b = ContactBoundary {
            points: ContactPoints {
                dim,
                position: vec![],
                normal: vec![],
                tangent: vec![],
                weight: vec![],
                gap: vec![],
                friction: vec![],
                held: vec![],
                foundation: specs.first().map_or(contact::Foundation::Rigid, |s| foundation_of(s)),
                foundations: vec![],
                slipped: vec![],
                weakening: vec![],
                tresca: vec![],
            },
            nodes: vec![],
            dofs: vec![],
            slots: vec![],
            held_nodes: 0,
            held_inside: 0,
            electric: None,
            phi_terms: vec![],
            group_of: vec![],
            groups: specs.iter().map(|s| s.group.clone()).collect(),
            revolution: disc.coordinates == fe_assembly::Coordinates::Axisymmetric,
            uniform: vec![],
        };
        let mut place: std::collections::HashMap<usize, usize> = Default::default();
        // each point's displacement as terms on nodes, for the potentials of electrical contact
        let mut node_terms = vec![];
        for (k, spec) in specs.iter().enumerate() {
            node_terms.extend(b.add_group(disc, (k, spec), owned, &mut place)?);
        }
        // the zone that conducts (at most one: validated), its points' potentials condensed
        if let Some((k, spec)) = specs.iter().enumerate().find(|(_, s)| s.electric_law().is_some()) {
            let members = (0..b.nodes.len())
                .filter(|&i| b.group_of[i] == k)
                .map(|i| (i, b.nodes[i]));
            b.electric = electric_points(spec, &disc.dofs, members)?;
            b.phi_terms = b.electric_terms(spec, &disc.dofs, &node_terms)?;
        }
        // zones whose friction weakens with the slip: each point its zone's law (a law from a
        // static coefficient of 0 is frictionless: its points keep the coefficient 0)
        let weakening: Vec<Option<contact::SlipWeakening>> = specs
            .iter()
            .map(|s| match s.model().map(|m| m.friction) {
                Some(Friction::SlipWeakening(w)) if w.static_coefficient > 0.0 => Some(w),
                _ => None,
            })
            .collect();
        if weakening.iter().any(Option::is_some) {
            b.points.weakening = b.group_of.iter().map(|&k| weakening[k]).collect();
        }
        // Tresca zones beside Coulomb zones (the problem's law Coulomb's): each such point's
        // radius its zone's bound there
        let coulomb = specs.iter().any(|s| s.law == crate::ContactLaw::Coulomb);
        let bounds: Vec<Option<crate::scene::ZoneBound>> = specs
            .iter()
            .map(|s| match s.model().map(|m| m.friction) {
                Some(Friction::Tresca(bound)) if coulomb => Some(bound),
                _ => None,
            })
            .collect();
        if bounds.iter().any(Option::is_some) {
            b.points.tresca = (0..b.points.len())
                .map(|i| bounds[b.group_of[i]].as_ref().map(|z| z.at(b.points.position[i])))
                .collect();
        }
        // zones on different foundations: each point its own zone's
        let zones: Vec<contact::Foundation> = specs.iter().map(|s| foundation_of(s)).collect();
        if zones.iter().any(|f| *f != b.points.foundation) {
            b.points.foundations = b.group_of.iter().map(|&k| zones[k]).collect();
        }
        Ok(b)
    }

    /// Adds the points of group `k` (`spec`); `place` holds each condensed dof's place in
    /// `dofs`, shared by the points of one node. Returns each added point's displacement as
    /// terms `(coefficient, node)` ([`FaceBasis::terms`]).
    fn add_group(
        &mut self,
        disc: &Discretization<'_>,
        (k, spec): (usize, &ContactSpec),
        owned: Option<&[bool]>,
        place: &mut std::collections::HashMap<usize, usize>,
    ) -> Result<Vec<Vec<(f64, usize)>>, ProblemError> {
        let (mesh, dofs) = (disc.mesh, &disc.dofs);
        let dim = mesh.dim;
        let nv = unit_normal(spec, dim)?;
        check_boundary(mesh, &spec.group, "contact.group", "contact face")?;
        check_normal(mesh, spec, nv)?;
        let tangents = tangent_basis(dim, nv);
        let group = mesh.boundary(&spec.group)?;
        let basis = FaceBasis::of(mesh, group, disc.coordinates);
        let weight = &basis.weight;
        let friction = spec.friction();
        let (mut added, mut held_nodes, mut out_of_reach) = (vec![], 0, 0);
        for node in group.nodes().into_iter().filter(|&v| owned.is_none_or(|o| o[v])) {
            let x = mesh.points[node];
            if !(weight[node] > 0.0) {
                return Err(weightless(spec, node, &x[..dim], weight[node]));
            }
            let Some(gap) = spec.gap_at(&x, &nv) else {
                // beyond the indenter's shape (a punch's edge, a sphere's equator)
                out_of_reach += 1;
                continue;
            };
            // in the modified basis the gap is the basis's too: `ĝ = Σ c g(x_m)` over the
            // point's terms, as its displacement is (the constraint `û_n ≤ ĝ` is then the
            // nodal interpolant's, exact for a quadratic gap)
            let terms = basis.terms(node);
            let gap = terms
                .iter()
                .map(|&(c, m)| spec.gap_at(&mesh.points[m], &nv).map(|g| c * g))
                .sum::<Option<f64>>()
                .unwrap_or(gap);
            let comps: Vec<Dof> = (0..dim).map(|k| dofs.u[node * dim + k]).collect();
            let held = match held_directions(spec, node, &x, &comps, &nv, &tangents)? {
                Held::Normal(u_n) => {
                    // the support holds the normal: the node is no contact point (the
                    // Dirichlet condition wins, even where it holds the node past the gap)
                    held_nodes += 1;
                    if u_n > gap + 1e-12 * (u_n.abs() + gap.abs()) {
                        self.held_inside += 1;
                    }
                    continue;
                }
                Held::Tangents(held) => held,
            };
            self.push_terms(&terms, dofs, place);
            self.nodes.push(node);
            let p = &mut self.points;
            p.position.push(x);
            p.normal.push(nv);
            p.tangent.push(tangents);
            p.weight.push(weight[node]);
            p.gap.push(gap);
            p.friction.push(friction);
            p.held.push(held);
            self.group_of.push(k);
            self.uniform.push(spec.uniform_gap());
            added.push(terms);
        }
        self.held_nodes += held_nodes;
        if owned.is_some() {
            return Ok(added);
        }
        if added.is_empty() && out_of_reach > 0 {
            return Err(SetupError::new(
                "contact.indenter",
                format!(
                    "the indenter reaches no node of contact group `{}`: all its {out_of_reach} free nodes lie beyond the shape's reach (its radius, or its profile's last point)",
                    spec.group
                ),
            )
            .into());
        }
        if added.is_empty() {
            return Err(SetupError::new(
                "contact.group",
                format!(
                    "contact group `{}` has no contact point: Dirichlet conditions prescribe the normal displacement of all its {held_nodes} nodes, so the support holds them and contact never acts (remove the contact, or the condition on the normal component)",
                    spec.group
                ),
            )
            .into());
        }
        Ok(added)
    }

    /// Pushes a point's displacement components, each the sum of `terms` (`(coefficient,
    /// node)`) of that component; a free dof is condensed once (`place`: its place in `dofs`).
    fn push_terms(
        &mut self,
        terms: &[(f64, usize)],
        dofs: &DofMap,
        place: &mut std::collections::HashMap<usize, usize>,
    ) {
        let dim = self.points.dim;
        for k in 0..dim {
            let mut component = Vec::with_capacity(terms.len());
            for &(c, m) in terms {
                let slot = match dofs.u[m * dim + k] {
                    Dof::Free(j) => Slot::Free(*place.entry(j).or_insert_with(|| {
                        self.dofs.push(j);
                        self.dofs.len() - 1
                    })),
                    Dof::Fixed(v) => Slot::Fixed(v),
                    Dof::Absent => Slot::Fixed(0.0),
                };
                component.push((c, slot));
            }
            self.slots.push(component);
        }
    }

    /// The boundary at an instant of a load path: the uniform part of every gap (its group's
    /// `contact.gap` less an indenter's depth) scaled by `gap`, each prescribed displacement
    /// component `k` of a point by `displacement[k]`, and a conducting foundation's potential
    /// (a prescribed potential) by `voltage` (the points, their dofs and weights are the same).
    pub fn at_factors(&self, gap: f64, displacement: [f64; 3], voltage: f64) -> ContactBoundary {
        let dim = self.points.dim;
        let mut b = ContactBoundary {
            points: self.points.clone(),
            nodes: self.nodes.clone(),
            dofs: self.dofs.clone(),
            slots: self.slots.clone(),
            held_nodes: self.held_nodes,
            held_inside: self.held_inside,
            electric: self.electric.clone(),
            phi_terms: self.phi_terms.clone(),
            group_of: self.group_of.clone(),
            groups: self.groups.clone(),
            revolution: self.revolution,
            uniform: self.uniform.clone(),
        };
        for (g, g0) in b.points.gap.iter_mut().zip(&self.uniform) {
            *g += (gap - 1.0) * g0;
        }
        if let Some((electric, _)) = b.electric.as_mut() {
            electric.potential *= voltage;
        }
        for (_, slot) in b.phi_terms.iter_mut().flatten() {
            if let Slot::Fixed(v) = slot {
                *v *= voltage;
            }
        }
        for (j, terms) in b.slots.iter_mut().enumerate() {
            for (_, slot) in terms {
                if let Slot::Fixed(v) = slot {
                    *v *= displacement[j % dim];
                }
            }
        }
        b
    }

    /// The points `keep` (indices, in order) as a boundary of their own, their free
    /// displacement dofs alone condensed (in the order the points first name them); what the
    /// group's Dirichlet conditions hold is counted as before. `None` with electrical contact,
    /// whose potentials this does not select.
    ///
    /// # Panics
    /// Where an index of `keep` is not a point's.
    pub fn select(&self, keep: &[usize]) -> Option<ContactBoundary> {
        if self.electric.is_some() {
            return None;
        }
        let dim = self.points.dim;
        let mut place = vec![usize::MAX; self.dofs.len()];
        let (mut dofs, mut slots) = (vec![], Vec::with_capacity(keep.len() * dim));
        for &i in keep {
            for terms in &self.slots[i * dim..(i + 1) * dim] {
                let mut component = Vec::with_capacity(terms.len());
                for &(c, slot) in terms {
                    component.push((
                        c,
                        match slot {
                            Slot::Free(j) => {
                                if place[j] == usize::MAX {
                                    place[j] = dofs.len();
                                    dofs.push(self.dofs[j]);
                                }
                                Slot::Free(place[j])
                            }
                            fixed @ Slot::Fixed(_) => fixed,
                        },
                    ));
                }
                slots.push(component);
            }
        }
        Some(ContactBoundary {
            points: self.points.select(keep),
            nodes: keep.iter().map(|&i| self.nodes[i]).collect(),
            dofs,
            slots,
            held_nodes: self.held_nodes,
            held_inside: self.held_inside,
            electric: None,
            phi_terms: vec![],
            group_of: keep.iter().map(|&i| self.group_of[i]).collect(),
            groups: self.groups.clone(),
            revolution: self.revolution,
            uniform: keep.iter().map(|&i| self.uniform[i]).collect(),
        })
    }

    /// The part of point `i`'s gap that is no uniform offset: an indenter's profile above its
    /// tip there (or a curved body's parabola), `0` on a flat face.
    pub fn profile_height(&self, i: usize) -> f64 {
        self.points.gap[i] - self.uniform[i]
    }

    /// Bytes of a condensed strategy's dense contact problem on this boundary, with
    /// `n_tangential` tangential components a point: the inverse block on the condensed dofs,
    /// the compliance on the contact components and Newton's matrices (`k² + 3 m²` doubles
    /// for `k` condensed dofs and `m` contact components).
    pub fn dense_bytes(&self, n_tangential: usize) -> f64 {
        let k = self.condensed_dofs().len();
        let m = self.points.len() * (1 + n_tangential) + (k - self.dofs.len());
        crate::estimate::dense_contact(k, m)
    }

    /// The dofs the condensation puts last: the points' free displacements, then (electrical
    /// contact) their free potentials.
    pub fn condensed_dofs(&self) -> Vec<usize> {
        self.dofs.iter().chain(self.electric_dofs()).copied().collect()
    }

    /// The flux of `sol` as the change of the electric right-hand side (the potential's rows
    /// negated: `+w q` at each electric point's potential), as `(index into φ, value)`.
    pub fn electric_charges(&self, sol: &contact::ContactSolution, n_u: usize) -> Vec<(usize, f64)> {
        let (Some((_, dofs)), Some(e)) = (&self.electric, &sol.electric) else {
            return vec![];
        };
        let mut out = Vec::with_capacity(dofs.len());
        for ((terms, &i), q) in self.phi_terms.iter().zip(&e.points).zip(&e.flux) {
            for &(c, slot) in terms {
                // a prescribed potential takes its share from its terminal
                if let Slot::Free(j) = slot {
                    out.push((dofs[j] - n_u, c * self.points.weight[i] * q));
                }
            }
        }
        out
    }

    /// Each electric point's potential from its terms: `free(j)` the value of the `j`-th
    /// electric dof, the prescribed terms at this boundary's values where `prescribed` (a
    /// response to a load has none: `false`).
    fn combine(&self, free: impl Fn(usize) -> f64, prescribed: bool) -> Vec<f64> {
        self.phi_terms
            .iter()
            .map(|terms| {
                terms
                    .iter()
                    .map(|&(c, slot)| match slot {
                        Slot::Free(j) => c * free(j),
                        Slot::Fixed(v) if prescribed => c * v,
                        Slot::Fixed(_) => 0.0,
                    })
                    .sum()
            })
            .collect()
    }

    /// The free potentials' dofs (indices into `[u; φ]`) of electrical contact, none without.
    fn electric_dofs(&self) -> &[usize] {
        self.electric.as_ref().map_or(&[][..], |(_, d)| d.as_slice())
    }

    /// The potentials at the electric points of the fields' free potentials `phi` (of `n_u`
    /// free displacements before them in `[u; φ]`), the prescribed terms at this boundary's
    /// values.
    pub fn potentials_at_points(&self, phi: &[f64], n_u: usize) -> Vec<f64> {
        let dofs = self.electric_dofs();
        self.combine(|j| phi[dofs[j] - n_u], true)
    }

    /// As [`ContactBoundary::potentials_at_points`] for a response to a load (a path's part):
    /// the free terms alone, the prescribed ones added at each instant's values
    /// ([`ContactBoundary::prescribed_potentials`]).
    pub fn free_potentials_at_points(&self, phi: &[f64], n_u: usize) -> Vec<f64> {
        let dofs = self.electric_dofs();
        self.combine(|j| phi[dofs[j] - n_u], false)
    }

    /// The prescribed terms of each electric point's potential, at this boundary's values.
    pub fn prescribed_potentials(&self) -> Vec<f64> {
        self.combine(|_| 0.0, true)
    }

    /// The potentials at the electric points of the values `phi_c` at the condensed
    /// potentials (in the order of the electric dofs).
    fn potentials_of_condensed(&self, phi_c: &[f64]) -> Vec<f64> {
        self.combine(|j| phi_c[j], true)
    }

    /// Each electric point's potential terms, and the dofs they add after the points' own
    /// (the edge's corners of a point of the modified basis); a corner on a terminal gives a
    /// prescribed term, which a load path scales with its voltage. A term on no potential (a
    /// corner of a body without electric unknowns there) is refused. `node_terms`: each
    /// point's displacement as terms on nodes.
    fn electric_terms(
        &mut self,
        spec: &ContactSpec,
        dofs: &DofMap,
        node_terms: &[Vec<(f64, usize)>],
    ) -> Result<Vec<Vec<Term>>, ProblemError> {
        let Some((electric, phi)) = self.electric.as_mut() else {
            return Ok(vec![]);
        };
        let mut place: std::collections::HashMap<usize, usize> = phi.iter().enumerate().map(|(e, &d)| (d, e)).collect();
        let mut out = Vec::with_capacity(electric.points.len());
        for (e, &i) in electric.points.iter().enumerate() {
            let mut terms = vec![];
            for &(c, m) in &node_terms[i] {
                if m == self.nodes[i] {
                    terms.push((c, Slot::Free(e)));
                    continue;
                }
                let j = match dofs.phi[m] {
                    Dof::Free(j) => j,
                    Dof::Fixed(v) => {
                        terms.push((c, Slot::Fixed(v)));
                        continue;
                    }
                    Dof::Absent => {
                        return Err(SetupError::new(
                            "contact.electric",
                            format!(
                                "a point of contact group `{}` in the modified basis (node {}) takes node {m}'s potential, and that node has none (no electric material there): electrical contact needs the face's every node electric",
                                spec.group, self.nodes[i]
                            ),
                        )
                        .into())
                    }
                };
                let d = dofs.n_u + j;
                let at = *place.entry(d).or_insert_with(|| {
                    phi.push(d);
                    phi.len() - 1
                });
                terms.push((c, Slot::Free(at)));
            }
            out.push(terms);
        }
        Ok(out)
    }

    /// Tells `reporter` what Dirichlet conditions hold of the group `group` where it is more
    /// than nodes clamped within the gap (the corners of a clamped body): held tangents (where
    /// the contact is `frictional`: a frictionless zone's tangents carry no force anyway), or
    /// nodes held inside the foundation.
    pub fn report_held(&self, group: &str, frictional: bool, reporter: &mut dyn crate::Reporter) {
        let nt = self.points.n_tangential();
        let tangents = (0..self.points.len())
            .filter(|&i| frictional && self.points.held[i][..nt].iter().any(|&h| h))
            .count();
        if tangents + self.held_inside > 0 {
            reporter.event(&crate::Event::ContactHeld {
                group,
                tangents,
                nodes: self.held_nodes,
                inside: self.held_inside,
            });
        }
    }

    /// The contact forces `-Nᵀ W λ_n - Tᵀ W λ_t` on the contact dofs, in the order of `dofs`
    /// (the components a support holds take theirs from it).
    pub fn forces(&self, lambda: &PointValues) -> Vec<f64> {
        let mut out = vec![0.0; self.dofs.len()];
        self.each_force(lambda, |slots, w, f| {
            for &(c, slot) in slots {
                if let Slot::Free(j) = slot {
                    out[j] -= c * w * f;
                }
            }
        });
        out
    }

    /// The contact force `-w (λ_n n + λ_t t)` of each point, `dim` components a point, 0 in a
    /// component a support holds (a linear face's points are its nodes: the force on the
    /// point's node).
    pub fn point_forces(&self, lambda: &PointValues) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.points.len() * self.points.dim);
        self.each_force(lambda, |slots, w, f| {
            let free = slots.iter().any(|(_, slot)| matches!(slot, Slot::Free(_)));
            out.push(if free { -w * f } else { 0.0 });
        });
        out
    }

    /// `each(slots, w, f)` for every point and component in order, with the point's weight
    /// `w`, `f = λ_n n_k + λ_t t_k` (the force is `-w f`) and the component's slots.
    fn each_force(&self, lambda: &PointValues, mut each: impl FnMut(&[Term], f64, f64)) {
        let p = &self.points;
        let (dim, nt) = (p.dim, lambda.n_tangential());
        for i in 0..p.len() {
            for k in 0..dim {
                let mut f = lambda.normal[i] * p.normal[i][k];
                for q in 0..nt {
                    f += lambda.tangential[i * nt + q] * p.tangent[i][q][k];
                }
                each(&self.slots[i * dim + k], p.weight[i], f);
            }
        }
    }

    /// The points' holds along their normals, for the rigid motions a compliant bed holds
    /// ([`fe_assembly::Discretization::check_held_with`]).
    pub fn supports(&self) -> Vec<fe_assembly::Support> {
        self.nodes
            .iter()
            .zip(&self.points.normal)
            .map(|(&node, &direction)| fe_assembly::Support { node, direction })
            .collect()
    }

    /// The springs `k w_i n_i n_iᵀ` at the points on a compliant foundation, on their free
    /// components, as `(row, column, value)` in the free u numbering (both triangles): a
    /// compliant bed's hold on a body only
    /// it holds (the run's `Bed`).
    pub fn normal_springs(&self, k: f64) -> Vec<(usize, usize, f64)> {
        let p = &self.points;
        let dim = p.dim;
        let mut out = vec![];
        for i in (0..p.len()).filter(|&i| p.foundation_of(i) != contact::Foundation::Rigid) {
            for a in 0..dim {
                for &(ca, sa) in &self.slots[i * dim + a] {
                    let Slot::Free(ja) = sa else { continue };
                    for b in 0..dim {
                        for &(cb, sb) in &self.slots[i * dim + b] {
                            let Slot::Free(jb) = sb else { continue };
                            let v = k * p.weight[i] * ca * cb * p.normal[i][a] * p.normal[i][b];
                            if v != 0.0 {
                                out.push((self.dofs[ja], self.dofs[jb], v));
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// The multipliers whose forces are those of the springs of
    /// [`ContactBoundary::normal_springs`] at the points' normal displacement `u_n`:
    /// `-k (u_n - u_n,p)`, `u_n,p` the prescribed components' part (the springs act on the free
    /// ones), with `nt` tangential components at 0; 0 at the points on a rigid foundation.
    pub fn spring_multipliers(&self, k: f64, u_n: &[f64], nt: usize) -> PointValues {
        let p = &self.points;
        let dim = p.dim;
        let zero = vec![0.0; self.dofs.len()];
        let mut lambda = PointValues::zeros(p.len(), nt);
        for i in (0..p.len()).filter(|&i| p.foundation_of(i) != contact::Foundation::Rigid) {
            let prescribed = self.point_u(i, &zero);
            let along: f64 = (0..dim).map(|a| prescribed[a] * p.normal[i][a]).sum();
            // the force of a multiplier is -w λ n: the spring's is w k u_n
            lambda.normal[i] = -k * (u_n[i] - along);
        }
        lambda
    }

    /// Adds the contact forces of `lambda` to `b_u`.
    pub fn add_forces(&self, lambda: &PointValues, b_u: &mut [f64]) {
        for (&j, f) in self.dofs.iter().zip(self.forces(lambda)) {
            b_u[j] += f;
        }
    }

    /// Point `i`'s displacement from the values `u_c` at the contact dofs (in the order of
    /// `dofs`) and the prescribed components.
    fn point_u(&self, i: usize, u_c: &[f64]) -> [f64; 3] {
        let dim = self.points.dim;
        std::array::from_fn(|k| match self.slots.get(i * dim + k) {
            Some(terms) if k < dim => terms
                .iter()
                .map(|&(c, slot)| match slot {
                    Slot::Free(j) => c * u_c[j],
                    Slot::Fixed(v) => c * v,
                })
                .sum(),
            _ => 0.0,
        })
    }

    /// `u_n` and `u_t` of the values `u_c` at the contact dofs (in the order of `dofs`).
    fn project(&self, u_c: &[f64], out: &mut PointValues) {
        let p = &self.points;
        let (dim, nt) = (p.dim, out.n_tangential());
        for i in 0..p.len() {
            let ui = self.point_u(i, u_c);
            out.normal[i] = (0..dim).map(|k| ui[k] * p.normal[i][k]).sum();
            for q in 0..nt {
                out.tangential[i * nt + q] = (0..dim).map(|k| ui[k] * p.tangent[i][q][k]).sum();
            }
        }
    }

    /// `u_n` and `u_t` of a free displacement vector `u` that prescribes nothing (a response to
    /// a load, its prescribed components 0): the components at the free slots alone.
    pub fn extract_free(&self, u: &[f64], out: &mut PointValues) {
        let p = &self.points;
        let (dim, nt) = (p.dim, out.n_tangential());
        for i in 0..p.len() {
            let ui: [f64; 3] = std::array::from_fn(|k| match self.slots.get(i * dim + k) {
                Some(terms) if k < dim => terms
                    .iter()
                    .map(|&(c, slot)| match slot {
                        Slot::Free(j) => c * u[self.dofs[j]],
                        Slot::Fixed(_) => 0.0,
                    })
                    .sum(),
                _ => 0.0,
            });
            out.normal[i] = (0..dim).map(|k| ui[k] * p.normal[i][k]).sum();
            for q in 0..nt {
                out.tangential[i * nt + q] = (0..dim).map(|k| ui[k] * p.tangent[i][q][k]).sum();
            }
        }
    }

    /// `u_n` and `u_t` of the free displacement vector `u`.
    pub fn extract(&self, u: &[f64], out: &mut PointValues) {
        let u_c: Vec<f64> = self.dofs.iter().map(|&j| u[j]).collect();
        self.project(&u_c, out);
    }

    /// The contact problem condensed onto the points, `u = u0 - D W λ` with
    /// `D = R (K⁻¹)_cc Rᵀ` (`R`: each point's normal, then its `nt` tangents), and the loads'
    /// part of the condensation for [`ContactBoundary::recover`].
    ///
    /// # Errors
    /// The condensation's linear-algebra error.
    pub fn condense(
        &self,
        solver: &mut dyn Factorization,
        b_u: &[f64],
        b_phi: &[f64],
        nt: usize,
    ) -> Result<(DenseContactProblem, CondensedLoads), ProblemError> {
        let condensed = solver.condense(b_u, b_phi, &self.dofs)?;
        let p = &self.points;
        let d = self.mechanical_block(&condensed.inverse, self.dofs.len(), nt);
        let mut u0 = PointValues::zeros(p.len(), nt);
        self.project(&condensed.loads.solution, &mut u0);
        let problem = DenseContactProblem {
            u0,
            compliance: d,
            weight: p.weight.clone(),
            nt,
        };
        Ok((problem, condensed.loads))
    }

    /// The contact problem with electrical contact condensed onto the points' displacements
    /// and free potentials: `D` of order `m + n_e` with `D_uu = R (K⁻¹)_uu Rᵀ`,
    /// `D_eu = (K⁻¹)_φu Rᵀ`, `D_ue = -R (K⁻¹)_uφ`, `D_ee = -(K⁻¹)_φφ` (the flux `q = D·ν`
    /// enters the negated electric rows as `+W q`), and the loads' part for
    /// [`ContactBoundary::recover`].
    ///
    /// # Errors
    /// The condensation's linear-algebra error.
    pub fn condense_electric(
        &self,
        electric: &contact::ElectricContact,
        solver: &mut dyn Factorization,
        b_u: &[f64],
        b_phi: &[f64],
        nt: usize,
    ) -> Result<(ElectricContactProblem, CondensedLoads), ProblemError> {
        let all = self.condensed_dofs();
        let condensed = solver.condense(b_u, b_phi, &all)?;
        let (inv, kk, k) = (&condensed.inverse, all.len(), self.dofs.len());
        let p = &self.points;
        let (n, m) = (p.len(), p.len() * (1 + nt));
        // the electric points (their potentials' terms on the condensed potentials)
        let terms = &self.phi_terms;
        let ne = terms.len();
        let o = m + ne;
        let mech = self.mechanical_block(inv, kk, nt);
        let mut d = vec![0.0; o * o];
        for r in 0..m {
            d[r * o..r * o + m].copy_from_slice(&mech[r * m..(r + 1) * m]);
        }
        let free = self.free_slots();
        for r in 0..m {
            let (i, a) = self.direction_of(r, nt);
            for (e, te) in terms.iter().enumerate() {
                let v: f64 = free_terms(te)
                    .map(|(ce, je)| {
                        ce * free[i]
                            .iter()
                            .map(|&(x, jx, cx)| cx * a[x] * inv[(k + je) * kk + jx])
                            .sum::<f64>()
                    })
                    .sum();
                d[(m + e) * o + r] = v;
                d[r * o + m + e] = -v;
            }
        }
        for (e, te) in terms.iter().enumerate() {
            for (f, tf) in terms.iter().enumerate() {
                let v: f64 = free_terms(te)
                    .map(|(ce, je)| {
                        free_terms(tf)
                            .map(|(cf, jf)| ce * inv[(k + je) * kk + k + jf] * cf)
                            .sum::<f64>()
                    })
                    .sum();
                d[(m + e) * o + m + f] = -v;
            }
        }
        let mut u0 = PointValues::zeros(n, nt);
        self.project(&condensed.loads.solution[..k], &mut u0);
        let at_points = self.potentials_of_condensed(&condensed.loads.solution[k..]);
        let problem = ElectricContactProblem {
            u0,
            phi0: at_points,
            compliance: d,
            weight: p.weight.clone(),
            nt,
            electric: electric.clone(),
        };
        Ok((problem, condensed.loads))
    }

    /// The free dofs of each point: `(component, place in the condensed dofs, coefficient)`.
    fn free_slots(&self) -> Vec<Vec<(usize, usize, f64)>> {
        let dim = self.points.dim;
        (0..self.points.len())
            .map(|i| {
                (0..dim)
                    .flat_map(|x| {
                        self.slots[i * dim + x].iter().filter_map(move |&(c, slot)| match slot {
                            Slot::Free(j) => Some((x, j, c)),
                            Slot::Fixed(_) => None,
                        })
                    })
                    .collect()
            })
            .collect()
    }

    /// Row `r` of `R`: its point, and the direction (the point's normal, then its `nt`
    /// tangents).
    fn direction_of(&self, r: usize, nt: usize) -> (usize, [f64; 3]) {
        let p = &self.points;
        let n = p.len();
        if r < n {
            (r, p.normal[r])
        } else {
            let (i, q) = ((r - n) / nt, (r - n) % nt);
            (i, p.tangent[i][q])
        }
    }

    /// `D = R (K⁻¹)_cc Rᵀ` on the points' displacements, from the condensed inverse `inv`
    /// (row-major, of order `stride`, the displacements first), with the held tangents'
    /// diagonal set ([`hold_rows`]).
    fn mechanical_block(&self, inv: &[f64], stride: usize, nt: usize) -> Vec<f64> {
        let p = &self.points;
        let (n, m) = (p.len(), p.len() * (1 + nt));
        let free = self.free_slots();
        let mut d = vec![0.0; m * m];
        // the lower triangle by rows on rayon's pool, then mirrored
        d.par_chunks_mut(m.max(1)).enumerate().for_each(|(r, row)| {
            let (i, a) = self.direction_of(r, nt);
            for (c, out) in row.iter_mut().enumerate().take(r + 1) {
                let (j, b) = self.direction_of(c, nt);
                let mut v = 0.0;
                for &(x, jx, cx) in &free[i] {
                    for &(y, jy, cy) in &free[j] {
                        v += cx * a[x] * inv[jx * stride + jy] * b[y] * cy;
                    }
                }
                *out = v;
            }
        });
        linalg::mirror_lower(&mut d, m);
        hold_rows(&mut d, m, n, nt, p);
        d
    }

    /// `u` and `φ` under the loads and the contact forces of `lambda`, finishing the
    /// condensation's solve (the forces change the right-hand side at the contact dofs only).
    ///
    /// # Errors
    /// The solve's linear-algebra error.
    pub fn recover(
        &self,
        solver: &mut dyn Factorization,
        loads: CondensedLoads,
        lambda: &PointValues,
        b_u: &[f64],
        b_phi: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), ProblemError> {
        solver.solve_with_update(loads, b_u, b_phi, &self.forces(lambda))
    }

    /// `u` and `φ` under the loads, the contact forces and the electric flux of `sol`
    /// (electrical contact), finishing the condensation's solve.
    ///
    /// # Errors
    /// The solve's linear-algebra error.
    pub fn recover_electric(
        &self,
        solver: &mut dyn Factorization,
        loads: CondensedLoads,
        sol: &contact::ContactSolution,
        b_u: &[f64],
        b_phi: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), ProblemError> {
        let mut d = self.forces(&sol.lambda);
        // each condensed potential's share of the flux, in their order
        let n = self.electric.as_ref().map_or(0, |(_, dofs)| dofs.len());
        let at = d.len();
        d.resize(at + n, 0.0);
        let place: std::collections::HashMap<usize, usize> = self
            .electric
            .iter()
            .flat_map(|(_, dofs)| dofs.iter().enumerate().map(|(e, &j)| (j - b_u.len(), e)))
            .collect();
        for (j, q) in self.electric_charges(sol, b_u.len()) {
            d[at + place[&j]] += q;
        }
        solver.solve_with_update(loads, b_u, b_phi, &d)
    }
}

/// The electric points of a conductive or conducting foundation: the contact points of its
/// zone (`members`: each point's index among the boundary's and its node) whose potential is
/// free (one on an electrode has it prescribed).
///
/// # Errors
/// `contact.electric` on a body without electric unknowns.
fn electric_points(
    spec: &ContactSpec,
    dofs: &DofMap,
    members: impl Iterator<Item = (usize, usize)>,
) -> Result<Option<(contact::ElectricContact, Vec<usize>)>, ProblemError> {
    let Some((law, potential)) = spec.electric_law() else {
        return Ok(None);
    };
    if dofs.n_phi == 0 {
        return Err(SetupError::new(
            "contact.electric",
            "electrical contact needs electric unknowns, and no material has a permittivity (or the electrodes prescribe every potential): remove contact.electric",
        )
        .into());
    }
    let (mut points, mut phi) = (vec![], vec![]);
    for (i, node) in members {
        if let Some((group, _)) = dofs.floating.iter().find(|(_, j)| dofs.phi[node] == Dof::Free(*j)) {
            return Err(SetupError::new(
                "contact.electric",
                format!("the contact face touches the floating terminal `{group}`, and an electrical contact there would join the foundation and the terminal into one conductor: keep contact.electric = \"insulated\", or make the foundation the floating conductor (contact.charge)"),
            )
            .into());
        }
        match dofs.phi[node] {
            Dof::Free(j) => {
                points.push(i);
                phi.push(dofs.n_u + j);
            }
            // an ideal conductor touching a terminal at another potential: a short circuit
            // between two prescribed potentials, which no contact state satisfies
            Dof::Fixed(v)
                if matches!(law, contact::ElectricLaw::Conducting) && (spec.charge.is_some() || v != potential) =>
            {
                let foundation = match spec.charge {
                    Some(_) => "a floating foundation (contact.charge), which would take it".to_string(),
                    None => format!("the foundation at contact.foundation_potential = {potential:e}"),
                };
                return Err(SetupError::new(
                    "contact.electric",
                    format!("a contact point of `{}` lies on a terminal at the potential {v:e}, and contact.electric = \"conducting\" joins it to {foundation}: two conductors at two potentials would touch; give them one potential, use contact.electric = \"conductive\" (a finite conductance), or keep the terminal off the contact face", spec.group),
                )
                .into());
            }
            _ => {}
        }
    }
    let contact = contact::ElectricContact { law, potential, points };
    Ok(Some((contact, phi)))
}

/// A held tangent moves with no force (its rows and columns of `D` vanish) and its multiplier
/// is 0 whatever `D` holds there: its diagonal is set to the mean of the others, so that `D`
/// stays definite for the solvers that factor it, without changing the solution.
fn hold_rows(d: &mut [f64], m: usize, n: usize, nt: usize, p: &ContactPoints) {
    let held = |r: usize| r >= n && p.is_held((r - n) / nt, (r - n) % nt);
    let (sum, count) = (0..m)
        .filter(|&r| !held(r))
        .fold((0.0, 0usize), |(s, c), r| (s + d[r * m + r], c + 1));
    let mean = if count > 0 && sum > 0.0 {
        sum / count as f64
    } else {
        1.0
    };
    for r in (0..m).filter(|&r| held(r)) {
        d[r * m + r] = mean;
    }
}

/// The facets of `group` must lie on the boundary where `what` needs a boundary (a traction, a
/// contact face): the scene `key` names the group.
///
/// # Errors
/// A scene error naming `key` where the group has facets inside the mesh.
pub(crate) fn check_boundary(mesh: &mesh::Mesh, group: &str, key: &str, what: &str) -> Result<(), ProblemError> {
    let inside = mesh.interior_facets(group)?;
    if let Some(&f) = inside.first() {
        let at = mesh.points[mesh.boundary(group)?.facet(f)[0]];
        return Err(SetupError::new(
            key,
            format!(
                "{key} `{group}` has {} facet(s) inside the mesh (shared by two cells, the first at {:?}): a {what} lies on the boundary (an interior group serves as an electrode or a Dirichlet condition)",
                inside.len(),
                &at[..mesh.dim]
            ),
        )
        .into());
    }
    Ok(())
}

/// One full primal solve per call (warm-started: the iterative linear solver starts from the
/// previous solution).
pub struct FullSolve<'a> {
    /// The contact boundary.
    pub boundary: &'a ContactBoundary,
    /// The factored linear solver.
    pub solver: &'a mut dyn CoupledSolver,
    /// Load right-hand side.
    pub b_u: &'a [f64],
    /// Electric right-hand side.
    pub b_phi: &'a [f64],
    /// Tangential components carried.
    pub nt: usize,
    /// The last displacement.
    pub u: Vec<f64>,
    /// The last potential.
    pub phi: Vec<f64>,
}

impl ContactOperator for FullSolve<'_> {
    fn n_points(&self) -> usize {
        self.boundary.points.len()
    }
    fn n_tangential(&self) -> usize {
        self.nt
    }
    fn displacement(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        let mut rhs = self.b_u.to_vec();
        self.boundary.add_forces(lambda, &mut rhs);
        let info = self
            .solver
            .solve(&rhs, self.b_phi, &mut self.u, &mut self.phi)
            .map_err(OperatorError::new)?;
        self.boundary.extract(&self.u, out);
        Ok(info.pcg_iters)
    }
    fn forces_alone(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        let mut rhs = vec![0.0; self.b_u.len()];
        self.boundary.add_forces(lambda, &mut rhs);
        let (mut u, mut phi) = (vec![0.0; self.u.len()], vec![0.0; self.phi.len()]);
        let zero = vec![0.0; self.b_phi.len()];
        let info = self
            .solver
            .solve(&rhs, &zero, &mut u, &mut phi)
            .map_err(OperatorError::new)?;
        self.boundary.extract(&u, out);
        Ok(info.pcg_iters)
    }
}

/// What the Dirichlet conditions of a contact node hold.
enum Held {
    /// The normal, at the prescribed normal displacement: no contact point.
    Normal(f64),
    /// The tangents marked (none, one or both): a contact point.
    Tangents([bool; 2]),
}

/// Classifies the prescribed components `comps` of contact node `node` (at `x`) against the
/// normal `nv` and the `tangents`.
///
/// # Errors
/// Prescribed components that lie across the normal or a tangent (neither along nor
/// orthogonal to it).
fn held_directions(
    spec: &ContactSpec,
    node: usize,
    x: &[f64; 3],
    comps: &[Dof],
    nv: &[f64; 3],
    tangents: &[[f64; 3]; 2],
) -> Result<Held, ProblemError> {
    let dim = comps.len();
    let fixed: Vec<bool> = comps.iter().map(|c| !matches!(c, Dof::Free(_))).collect();
    let across = |dir: &[f64; 3], what: &str| -> ProblemError {
        let axes: Vec<&str> = (0..dim)
            .filter(|&k| fixed[k] && dir[k].abs() > ALIGNED)
            .map(|k| ["ux", "uy", "uz"][k])
            .collect();
        SetupError::new(
            "contact.group",
            format!(
                "node {node} of contact group `{}` (at {:?}): a Dirichlet condition prescribes {}, which lies across the contact {what} {:?} (neither along nor orthogonal to it): prescribe components along the normal or the tangents, or none",
                spec.group,
                &x[..dim],
                axes.join(", "),
                &dir[..dim]
            ),
        )
        .into()
    };
    match direction(nv, &fixed, dim) {
        Direction::Held => {
            let prescribed = |k: usize| match comps[k] {
                Dof::Fixed(v) => v,
                _ => 0.0,
            };
            return Ok(Held::Normal((0..dim).map(|k| nv[k] * prescribed(k)).sum()));
        }
        Direction::Mixed => return Err(across(nv, "normal")),
        Direction::Free => {}
    }
    let mut held = [false; 2];
    for q in 0..dim - 1 {
        match direction(&tangents[q], &fixed, dim) {
            Direction::Free => {}
            Direction::Held => held[q] = true,
            Direction::Mixed => return Err(across(&tangents[q], "tangent")),
        }
    }
    Ok(Held::Tangents(held))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The modified basis of a second-order face: every weight positive, the weights summing
    /// to the face's measure (a 3D face) or to `∫ 2π r ds` (a body of revolution's), and the
    /// points' displacements equal to the nodes' for every linear field.
    #[test]
    fn the_modified_basis_has_positive_weights_and_holds_linear_fields() {
        let linear = |x: &[f64; 3]| 0.3 + 1.1 * x[0] - 0.7 * x[1] + 0.4 * x[2];
        let cases = [
            (
                mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2),
                Coordinates::Cartesian,
                2.0,
            ),
            (
                mesh::rectangle_tri([0.0, 0.0], [1.5, 1.0], 6, 4),
                Coordinates::Axisymmetric,
                std::f64::consts::PI * 1.5 * 1.5,
            ),
        ];
        for (p1, coordinates, measure) in cases {
            let m = p1.quadratic().unwrap();
            let group = m.boundary("bottom").unwrap();
            let basis = FaceBasis::of(&m, group, coordinates);
            let nodes = group.nodes();
            assert!(nodes.iter().all(|&v| basis.weight[v] > 0.0), "{coordinates:?}");
            let total: f64 = nodes.iter().map(|&v| basis.weight[v]).sum();
            assert!(
                (total - measure).abs() < 1e-12 * measure,
                "{coordinates:?}: {total} against {measure}"
            );
            for &v in &nodes {
                let at: f64 = basis.terms(v).iter().map(|&(c, n)| c * linear(&m.points[n])).sum();
                assert!((at - linear(&m.points[v])).abs() < 1e-13, "node {v}");
            }
            // the edge nodes mix in their corners, the corners are their own
            assert_eq!(
                basis.edge_corners.len(),
                nodes.len() - p1.boundary("bottom").unwrap().nodes().len()
            );
        }
        // in 3D the weights are ∫ Ñ: each straight six-node face of area A gives its corners
        // 2A/15 and its edges A/5 (∫ N_c = 0, ∫ N_ij = A/3; Popp et al. 2012), not an equal share
        let m = mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2).quadratic().unwrap();
        let group = m.boundary("bottom").unwrap();
        let basis = FaceBasis::of(&m, group, Coordinates::Cartesian);
        let mut expected = vec![0.0; m.n_nodes()];
        for f in group.iter() {
            let area = facet_measure(&[m.points[f[0]], m.points[f[1]], m.points[f[2]]]);
            for (k, &v) in f.iter().enumerate() {
                expected[v] += area * if k < 3 { 2.0 / 15.0 } else { 0.2 };
            }
        }
        for v in group.nodes() {
            assert!(
                (basis.weight[v] - expected[v]).abs() < 1e-14,
                "node {v}: {} against {}",
                basis.weight[v],
                expected[v]
            );
        }
        // a 2D face in plane strain keeps its own (Simpson's) weights
        let m = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 4, 2).quadratic().unwrap();
        let basis = FaceBasis::of(&m, m.boundary("bottom").unwrap(), Coordinates::Cartesian);
        assert!(basis.edge_corners.is_empty());
    }
}
