//! What rank 0 gathers of a run on pieces: surfaces only, never the body. The contact points
//! (for `contact.csv`, the multipliers' picture and the report's contact section) and, in 3D,
//! the face `front` (y = lo) with its nodes' displacements and potentials (for the deformed
//! mesh's and the potential's pictures, which draw that face). Each item is sent by one rank:
//! a contact point by the rank that owns its node, a facet by the rank that owns its first
//! node (which holds every cell of that node, so the facet's cell too).

use super::PieceSolution;
use crate::error::DistributedError;
use contact::{ContactSolution, PointValues, Status};
use petsc::Petsc;
use problem::ContactResult;
use std::collections::BTreeMap;

/// Values per contact point in the gathered rows, for `nt` tangential components: its zone,
/// the node's number in the whole mesh, position (3), normal (3), tangents (3 nt), weight,
/// gap, friction, its Tresca bound beside Coulomb zones (NaN: none), held tangents (nt),
/// `λ_n`, `λ_t` (nt), `u_n`, `u_t` (nt), status, the node's potential.
fn width(nt: usize) -> usize {
    2 + 3 + 3 + 3 * nt + 4 + nt + 1 + nt + 1 + nt + 1 + 1
}

/// The status as a number, and back.
/// A status as a number (0 stick, 1 slip, 2 separated), to travel in a vector of `f64`.
pub(super) fn status_code(s: Status) -> f64 {
    match s {
        Status::Stick => 0.0,
        Status::Slip => 1.0,
        Status::Separated => 2.0,
    }
}

/// The status of [`status_code`]'s number.
pub(super) fn status_of(x: f64) -> Status {
    match x as u8 {
        0 => Status::Stick,
        1 => Status::Slip,
        _ => Status::Separated,
    }
}

/// What rank 0 holds of a run on pieces once the ranks' surfaces are gathered.
pub struct Gathered {
    /// The run's report, whole: the sums over the ranks, the contact section and an
    /// indenter's figures from every rank's points.
    pub report: problem::RunReport,
    /// Every rank's contact points (their `nodes` the whole mesh's numbers).
    pub contact: Option<ContactResult>,
    /// The face `front` (y = lo) of a 3D body as a mesh of its facets alone, with its nodes'
    /// displacements and potentials.
    #[allow(clippy::type_complexity)]
    pub front: Option<(mesh::Mesh, Vec<[f64; 3]>, Vec<f64>)>,
}

impl PieceSolution {
    /// The ranks' surfaces gathered on rank 0 and the report completed there (`None` on the
    /// other ranks). Collective.
    pub fn gathered(&self, petsc: &Petsc, scene: &problem::Scene) -> Result<Option<Gathered>, DistributedError> {
        let contact = self.gathered_contact(petsc)?;
        let front = self.gathered_front(petsc)?;
        let held = self.contact.as_ref().map_or([0.0; 2], |c| {
            [c.boundary.held_nodes as f64, c.boundary.held_inside as f64]
        });
        let held = petsc.sum(&held)?;
        if petsc.rank() != 0 {
            return Ok(None);
        }
        let mut report = self.report.clone();
        if let Some((c, phi)) = &contact {
            report.contact = problem::report::ContactReport {
                held_nodes: held[0] as usize,
                held_inside: held[1] as usize,
                ..problem::report::ContactReport::of_groups(
                    &c.points,
                    &c.solution,
                    &c.groups,
                    &c.group_of,
                    scene.mesh.axisymmetric,
                )
            };
            // a contact's closed form (Hertz, Cattaneo-Mindlin) is judged on every point
            if report.exact.is_none() {
                let (p, q) = (report.contact.normal_force, report.contact.tangential_force);
                report.exact = problem::contact_errors(scene, &c.points, &c.solution, p, q)
                    .map_err(problem::ProblemError::from)?;
            }
            let at = problem::Indented {
                points: &c.points,
                group_of: &c.group_of,
                sol: &c.solution,
                potential: None,
            };
            report.indenter =
                problem::indenter_figures(scene, report.plan.electric, at, &|i| phi[i], &problem::Factors::ONE);
        }
        Ok(Some(Gathered {
            report,
            contact: contact.map(|(c, _)| c),
            front,
        }))
    }

    /// The contact points of every rank on rank 0, in the order of their nodes' numbers in the
    /// whole mesh (the whole mesh's own order), as the default backend's run reports them, with
    /// the potential at each; `None` on the other ranks and without contact. Collective.
    pub fn gathered_contact(&self, petsc: &Petsc) -> Result<Option<(ContactResult, Vec<f64>)>, DistributedError> {
        let s = self;
        let Some(c) = &s.contact else {
            return Ok(None);
        };
        let (p, sol) = (&c.boundary.points, &c.solution);
        let nt = p.n_tangential();
        // whether the law has tangential multipliers: from every rank (one without points has
        // none to show)
        let has_t = petsc.max(&[f64::from(u8::from(!sol.lambda.tangential.is_empty()))])?[0] > 0.0;
        let mut rows = Vec::with_capacity(p.len() * width(nt));
        for i in 0..p.len() {
            rows.push(c.boundary.group_of[i] as f64);
            rows.push(s.piece.global_node[c.boundary.nodes[i]] as f64);
            rows.extend_from_slice(&p.position[i]);
            rows.extend_from_slice(&p.normal[i]);
            for q in 0..nt {
                rows.extend_from_slice(&p.tangent[i][q]);
            }
            rows.extend([p.weight[i], p.gap[i], p.friction[i], p.tresca_of(i).unwrap_or(f64::NAN)]);
            rows.extend((0..nt).map(|q| f64::from(u8::from(p.is_held(i, q)))));
            rows.push(sol.lambda.normal[i]);
            rows.extend((0..nt).map(|q| if has_t { sol.lambda.tangential[i * nt + q] } else { 0.0 }));
            rows.push(sol.u.normal[i]);
            rows.extend((0..nt).map(|q| sol.u.tangential[i * nt + q]));
            rows.push(status_code(sol.status[i]));
            rows.push(s.phi[c.boundary.nodes[i]]);
        }
        let Some(all) = petsc.gather_f64(&rows)? else {
            return Ok(None);
        };
        // zone by zone, each in the order of its nodes: the whole mesh's run's order
        let mut sorted: Vec<&[f64]> = all.chunks(width(nt)).collect();
        sorted.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        let n = sorted.len();
        // the boundary's per-zone data with no point yet; the points pushed below
        let mut points = p.select(&[]);
        let (mut lambda, mut u) = (PointValues::zeros(n, nt), PointValues::zeros(n, nt));
        let (mut nodes, mut status, mut phi) = (vec![], vec![], vec![]);
        let (mut group_of, mut tresca) = (vec![], vec![]);
        for (i, r) in sorted.iter().enumerate() {
            let mut at = 2;
            let mut take = |k: usize| {
                let out = &r[at..at + k];
                at += k;
                out
            };
            group_of.push(r[0] as usize);
            nodes.push(r[1] as usize);
            let three = |x: &[f64]| [x[0], x[1], x[2]];
            points.position.push(three(take(3)));
            points.normal.push(three(take(3)));
            let mut tangent = [[0.0; 3]; 2];
            for t in tangent.iter_mut().take(nt) {
                *t = three(take(3));
            }
            points.tangent.push(tangent);
            let wgf = take(4);
            points.weight.push(wgf[0]);
            points.gap.push(wgf[1]);
            points.friction.push(wgf[2]);
            tresca.push(Some(wgf[3]).filter(|b| !b.is_nan()));
            let held = take(nt);
            let mut h = [false; 2];
            for q in 0..nt {
                h[q] = held[q] != 0.0;
            }
            points.held.push(h);
            lambda.normal[i] = take(1)[0];
            lambda.tangential[i * nt..(i + 1) * nt].copy_from_slice(take(nt));
            u.normal[i] = take(1)[0];
            u.tangential[i * nt..(i + 1) * nt].copy_from_slice(take(nt));
            status.push(status_of(take(1)[0]));
            phi.push(take(1)[0]);
        }
        if !has_t {
            lambda.tangential.clear();
        }
        if tresca.iter().any(Option::is_some) {
            points.tresca = tresca;
        }
        let solution = ContactSolution {
            lambda,
            u: u.clone(),
            status,
            info: sol.info.clone(),
            electric: None,
        };
        let result = ContactResult {
            group_of,
            groups: c.boundary.groups.clone(),
            points,
            nodes,
            solution,
            displacement: u,
        };
        Ok(Some((result, phi)))
    }

    /// The face `front` (y = lo) of a 3D run on rank 0, as a mesh of its facets alone (no cells:
    /// what the 3D pictures draw), with its nodes' displacements and potentials; `None` on the
    /// other ranks, in 2D and where the mesh has no `front`. Collective.
    #[allow(clippy::type_complexity)]
    pub fn gathered_front(
        &self,
        petsc: &Petsc,
    ) -> Result<Option<(mesh::Mesh, Vec<[f64; 3]>, Vec<f64>)>, DistributedError> {
        let s = self;
        let m = &s.piece.mesh;
        let Some(face) = m.boundaries.get("front").filter(|_| m.dim == 3) else {
            return Ok(None);
        };
        let rank = petsc.rank();
        let k = face.nodes_per_facet;
        // per facet: its nodes' numbers, then per node position (3), u (3), phi
        let mut rows = vec![];
        for f in face.facets.chunks(k) {
            if s.piece.node_rank[f[0]] != rank {
                continue;
            }
            for &v in f {
                rows.push(s.piece.global_node[v] as f64);
            }
            for &v in f {
                rows.extend_from_slice(&m.points[v]);
                rows.extend_from_slice(&s.u[v]);
                rows.push(s.phi[v]);
            }
        }
        let Some(all) = petsc.gather_f64(&rows)? else {
            return Ok(None);
        };
        let mut index: BTreeMap<usize, usize> = BTreeMap::new();
        let (mut points, mut u, mut phi, mut facets) = (vec![], vec![], vec![], vec![]);
        for r in all.chunks(k * 8) {
            for a in 0..k {
                let g = r[a] as usize;
                let d = &r[k + 7 * a..k + 7 * (a + 1)];
                let next = index.len();
                let at = *index.entry(g).or_insert_with(|| {
                    points.push([d[0], d[1], d[2]]);
                    u.push([d[3], d[4], d[5]]);
                    phi.push(d[6]);
                    next
                });
                facets.push(at);
            }
        }
        let mesh = mesh::Mesh {
            dim: 3,
            kind: m.kind,
            points,
            cells: vec![],
            boundaries: [(
                "front".to_string(),
                mesh::FacetGroup {
                    nodes_per_facet: k,
                    facets,
                },
            )]
            .into(),
            regions: Default::default(),
            reoriented_cells: 0,
            other_groups: Default::default(),
        };
        Ok(Some((mesh, u, phi)))
    }
}
