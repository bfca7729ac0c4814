//! The contact boundary as the `contact` crate sees it: points with normals, tangents,
//! lumped weights and gaps, and two implementations of "given multipliers, return the contact
//! displacement": one full primal solve per call, or the condensed dense compliance
//! (Delassus operator) formed once from the `L D Lᵀ` factor of `K`: read off its trailing
//! supernode when the contact dofs were ordered last, else by block solves.

use crate::scene::ContactSpec;
use crate::DriverError;
use contact::{ContactOperator, ContactPoints, DenseContactProblem, PointValues};
use fe_assembly::{facet_measure, Dof, DofMap};
use linalg::{CoupledSolver, DirectLdlt};

/// The contact points of a boundary group and the u dofs of their nodes.
pub struct ContactBoundary {
    /// The points.
    pub points: ContactPoints,
    /// Mesh node of each point.
    pub nodes: Vec<usize>,
    /// Free u dof of each component of each point's node (`dim` per point).
    pub dofs: Vec<usize>,
}

/// Builds the contact points: the nodes of `group` whose displacement is entirely free
/// (clamped nodes are left out), weighted by their lumped boundary mass.
pub fn boundary(mesh: &mesh::Mesh, dofs: &DofMap, spec: &ContactSpec) -> Result<ContactBoundary, DriverError> {
    let (group, normal, friction) = (spec.group.as_str(), spec.normal.as_slice(), spec.friction);
    let dim = mesh.dim;
    let center = match &spec.gap_center {
        None => [0.0; 3],
        Some(c) if c.len() == dim => [c[0], c[1], c.get(2).copied().unwrap_or(0.0)],
        Some(c) => {
            return Err(DriverError::Input(format!(
                "contact.gap_center needs {dim} components, not {}",
                c.len()
            )))
        }
    };
    if normal.len() != dim {
        return Err(DriverError::Input(format!("contact.normal needs {dim} components")));
    }
    let len = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(len > 0.0) || !len.is_finite() {
        return Err(DriverError::Input("contact.normal is not a non-zero vector".into()));
    }
    let mut nv = [0.0; 3];
    for k in 0..dim {
        nv[k] = normal[k] / len;
    }
    let tangents = tangent_basis(dim, nv);
    let g = mesh.boundary(group)?;
    let mut weight = vec![0.0; mesh.n_nodes()];
    for f in g.iter() {
        let x: Vec<[f64; 3]> = f.iter().map(|&v| mesh.points[v]).collect();
        let m = facet_measure(&x) / f.len() as f64;
        for &v in f {
            weight[v] += m;
        }
    }
    let mut out = ContactBoundary {
        points: ContactPoints {
            dim,
            position: vec![],
            normal: vec![],
            tangent: vec![],
            weight: vec![],
            gap: vec![],
            friction: vec![],
        },
        nodes: vec![],
        dofs: vec![],
    };
    for node in g.nodes() {
        let free: Vec<usize> = (0..dim)
            .filter_map(|k| match dofs.u[node * dim + k] {
                Dof::Free(j) => Some(j),
                _ => None,
            })
            .collect();
        if free.len() != dim {
            continue;
        }
        out.nodes.push(node);
        out.dofs.extend_from_slice(&free);
        out.points.position.push(mesh.points[node]);
        out.points.normal.push(nv);
        out.points.tangent.push(tangents);
        out.points.weight.push(weight[node]);
        // the gap: uniform, plus the parabola of a curved body along the face
        let x = mesh.points[node];
        let d = [x[0] - center[0], x[1] - center[1], x[2] - center[2]];
        let along_n: f64 = (0..3).map(|k| d[k] * nv[k]).sum();
        let dist2 = (0..3).map(|k| d[k] * d[k]).sum::<f64>() - along_n * along_n;
        out.points
            .gap
            .push(spec.gap + 0.5 * spec.gap_curvature * dist2.max(0.0));
        out.points.friction.push(friction);
    }
    if out.nodes.is_empty() {
        return Err(DriverError::Input(format!(
            "contact group `{group}` has no node with a free displacement"
        )));
    }
    Ok(out)
}

/// `t1` = the first axis made orthogonal to `n`; in 3D `t2 = t1 x n` (so that n = -z gives
/// t1 = x, t2 = y, as SCENES.md fixes).
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

impl ContactBoundary {
    /// Adds the contact forces `-Nᵀ W λ_n - Tᵀ W λ_t` to `b_u`.
    pub fn add_forces(&self, lambda: &PointValues, b_u: &mut [f64]) {
        let p = &self.points;
        let (dim, nt) = (p.dim, lambda.tangential.len().checked_div(p.len()).unwrap_or(0));
        for i in 0..p.len() {
            for k in 0..dim {
                let mut f = lambda.normal[i] * p.normal[i][k];
                for q in 0..nt {
                    f += lambda.tangential[i * nt + q] * p.tangent[i][q][k];
                }
                b_u[self.dofs[i * dim + k]] -= p.weight[i] * f;
            }
        }
    }

    /// `u_n` and `u_t` of the free displacement vector `u`.
    pub fn extract(&self, u: &[f64], out: &mut PointValues) {
        let p = &self.points;
        let (dim, nt) = (p.dim, out.tangential.len().checked_div(p.len()).unwrap_or(0));
        for i in 0..p.len() {
            let ui: Vec<f64> = (0..dim).map(|k| u[self.dofs[i * dim + k]]).collect();
            out.normal[i] = (0..dim).map(|k| ui[k] * p.normal[i][k]).sum();
            for q in 0..nt {
                out.tangential[i * nt + q] = (0..dim).map(|k| ui[k] * p.tangent[i][q][k]).sum();
            }
        }
    }
}

/// One full primal solve per call (warm-started: the iterative linear solver starts from the
/// previous solution).
pub struct FullSolve<'a> {
    /// The contact boundary.
    pub boundary: &'a ContactBoundary,
    /// The factored linear solver.
    pub solver: &'a mut dyn CoupledSolver,
    /// Load right-hand sides.
    pub b_u: &'a [f64],
    /// Electric right-hand side.
    pub b_phi: &'a [f64],
    /// Tangential components carried.
    pub nt: usize,
    /// The last primal solution (u, φ).
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
    fn displacement(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, String> {
        let mut rhs = self.b_u.to_vec();
        self.boundary.add_forces(lambda, &mut rhs);
        let info = self
            .solver
            .solve(&rhs, self.b_phi, &mut self.u, &mut self.phi)
            .map_err(|e| e.to_string())?;
        self.boundary.extract(&self.u, out);
        Ok(info.pcg_iters)
    }
}

/// How the compliance of a condensed problem was formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CondenseRoute {
    /// Read off the trailing block of the factor (contact dofs ordered last): `D = R S_c⁻¹ Rᵀ`.
    TrailingBlock,
    /// Block solves with the factor, 64 right-hand sides at a time.
    BlockSolves,
}

/// The condensed problem `u_c = u0 - D W λ` with `D = C K⁻¹ Cᵀ`. When the factor of `K` was
/// ordered with the contact dofs last, `(K⁻¹)_cc = S_c⁻¹` with `S_c` read off its trailing block
/// (one dense inverse, no extra sparse solve); otherwise by block solves.
pub fn condense(
    boundary: &ContactBoundary,
    solver: &mut DirectLdlt,
    b_u: &[f64],
    b_phi: &[f64],
    nt: usize,
) -> Result<Condensed, DriverError> {
    if let Some((problem, forward)) = condense_from_factor(boundary, solver, b_u, b_phi, nt)? {
        return Ok(Condensed {
            problem,
            route: CondenseRoute::TrailingBlock,
            forward: Some(forward),
        });
    }
    Ok(Condensed {
        problem: condense_by_solves(boundary, solver, b_u, b_phi, nt)?,
        route: CondenseRoute::BlockSolves,
        forward: None,
    })
}

/// The condensed problem, how it was formed, and (trailing-block route) the forward half of
/// the solve with the loads, which the recovery of `u` and `φ` finishes.
pub struct Condensed {
    /// `u_c = u0 - D W λ`.
    pub problem: DenseContactProblem,
    /// How `D` was formed.
    pub route: CondenseRoute,
    /// `L⁻¹ P [b_u; b_φ]`, where the factor has the contact dofs last.
    pub forward: Option<Vec<f64>>,
}

/// `u` and `φ` under the loads and the contact forces of `lambda`. With the forward half of the
/// loads' solve at hand (contact dofs last), the forces change the right-hand side only on the
/// trailing indices: their forward half is a dense triangular solve, and one backward sweep
/// finishes, so the whole contact run costs the same sparse work as one solve.
pub fn recover(
    boundary: &ContactBoundary,
    solver: &mut DirectLdlt,
    condensed: Condensed,
    lambda: &PointValues,
    b_u: &[f64],
    b_phi: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), DriverError> {
    let n_u = b_u.len();
    if let Some(mut y) = condensed.forward {
        let mut forces = vec![0.0; n_u];
        boundary.add_forces(lambda, &mut forces);
        let d: Vec<f64> = boundary.dofs.iter().map(|&j| forces[j]).collect();
        if solver.factor().forward_update_trailing(&mut y, &d) {
            if let Some(mut x) = solver.factor().backward(y) {
                let phi = x.split_off(n_u);
                return Ok((x, phi));
            }
        }
    }
    let mut rhs = b_u.to_vec();
    boundary.add_forces(lambda, &mut rhs);
    let (mut u, mut phi) = (vec![0.0; n_u], vec![0.0; b_phi.len()]);
    solver.solve(&rhs, b_phi, &mut u, &mut phi)?;
    Ok((u, phi))
}

/// `u0` (the loads alone) at the contact points.
fn loads_alone(
    boundary: &ContactBoundary,
    solver: &mut DirectLdlt,
    b_u: &[f64],
    b_phi: &[f64],
    nt: usize,
) -> Result<PointValues, DriverError> {
    let n = boundary.points.len();
    let mut u0 = PointValues::zeros(n, nt);
    let (mut u, mut phi) = (vec![0.0; b_u.len()], vec![0.0; b_phi.len()]);
    solver.solve(b_u, b_phi, &mut u, &mut phi)?;
    boundary.extract(&u, &mut u0);
    Ok(u0)
}

fn condense_from_factor(
    boundary: &ContactBoundary,
    solver: &mut DirectLdlt,
    b_u: &[f64],
    b_phi: &[f64],
    nt: usize,
) -> Result<Option<(DenseContactProblem, Vec<f64>)>, DriverError> {
    let k = boundary.dofs.len();
    let fwd = solver.factor().permutation();
    if fwd[fwd.len() - k..] != boundary.dofs[..] {
        return Ok(None);
    }
    // (K⁻¹)_cc = S_c⁻¹ = L_cc⁻ᵀ D_c⁻¹ L_cc⁻¹ straight from the factor's trailing block
    let Some(flat) = solver.factor().trailing_schur_inverse(k)? else {
        return Ok(None);
    };
    let inv = |i: usize, j: usize| flat[i * k + j];
    let p = &boundary.points;
    let (n, dim) = (p.len(), p.dim);
    let m = n * (1 + nt);
    // rows of R: the normal, then the tangents, of each point, over its dim dofs
    let dir = |r: usize| -> (usize, [f64; 3]) {
        if r < n {
            (r, p.normal[r])
        } else {
            let (i, q) = ((r - n) / nt, (r - n) % nt);
            (i, p.tangent[i][q])
        }
    };
    let mut d = vec![0.0; m * m];
    for r in 0..m {
        let (i, a) = dir(r);
        for c in 0..=r {
            let (j, b) = dir(c);
            let mut v = 0.0;
            for x in 0..dim {
                for y in 0..dim {
                    v += a[x] * inv(i * dim + x, j * dim + y) * b[y];
                }
            }
            d[r * m + c] = v;
            d[c * m + r] = v;
        }
    }
    // u0 at the contact dofs from the forward half of the loads' solve and the trailing block
    let loads: Vec<f64> = b_u.iter().chain(b_phi).copied().collect();
    let Some(forward) = solver.factor().forward(&loads) else {
        return Ok(None);
    };
    let Some(tail) = solver.factor().trailing_backward(&forward, k) else {
        return Ok(None);
    };
    let mut u_dofs = vec![0.0; b_u.len()];
    for (j, &dof) in boundary.dofs.iter().enumerate() {
        u_dofs[dof] = tail[j];
    }
    let mut u0 = PointValues::zeros(n, nt);
    boundary.extract(&u_dofs, &mut u0);
    Ok(Some((
        DenseContactProblem {
            u0,
            compliance: d,
            weight: p.weight.clone(),
            nt,
        },
        forward,
    )))
}

/// The condensed problem by block solves with the factor of `K`, 64 right-hand sides at a time.
fn condense_by_solves(
    boundary: &ContactBoundary,
    solver: &mut DirectLdlt,
    b_u: &[f64],
    b_phi: &[f64],
    nt: usize,
) -> Result<DenseContactProblem, DriverError> {
    let p = &boundary.points;
    let n = p.len();
    let m = n * (1 + nt);
    let n_u = b_u.len();
    let n_all = n_u + b_phi.len();
    let u0 = loads_alone(boundary, solver, b_u, b_phi, nt)?;
    // column j of D: the contact displacement under a unit force along direction j
    let mut d = vec![0.0; m * m];
    const BLOCK: usize = 64;
    let mut start = 0;
    while start < m {
        let width = BLOCK.min(m - start);
        let mut rhs = faer::Mat::<f64>::zeros(n_all, width);
        for c in 0..width {
            let mut lam = PointValues::zeros(n, nt);
            let j = start + c;
            if j < n {
                lam.normal[j] = 1.0;
            } else {
                lam.tangential[j - n] = 1.0;
            }
            // a unit multiplier without the weight: force -(n or t)
            let mut col = vec![0.0; n_u];
            let w = p.weight[if j < n { j } else { (j - n) / nt.max(1) }];
            boundary.add_forces(&lam, &mut col);
            for (r, v) in col.iter().enumerate() {
                rhs[(r, c)] = -v / w;
            }
        }
        solver.factor_mut().solve_many(rhs.as_mut());
        for c in 0..width {
            let u: Vec<f64> = (0..n_u).map(|r| rhs[(r, c)]).collect();
            let mut out = PointValues::zeros(n, nt);
            boundary.extract(&u, &mut out);
            for r in 0..m {
                d[r * m + start + c] = if r < n { out.normal[r] } else { out.tangential[r - n] };
            }
        }
        start += width;
    }
    // symmetrise the round-off away
    for r in 0..m {
        for c in 0..r {
            let v = 0.5 * (d[r * m + c] + d[c * m + r]);
            d[r * m + c] = v;
            d[c * m + r] = v;
        }
    }
    Ok(DenseContactProblem {
        u0,
        compliance: d,
        weight: p.weight.clone(),
        nt,
    })
}
