//! Helpers shared by the integration tests: solving the assembled system both ways, full
//! tensors from Voigt arrays, and a jittered PZT-5A block with its random numbers.
#![allow(dead_code)]

use fe_assembly::{Blocks, Discretization, Load, Parallelism};
use linalg::{CoupledSolver, DirectLdlt, Ordering, PcgParams, SchurPcg};

/// Free `(u, φ)` vectors.
pub type Solution = (Vec<f64>, Vec<f64>);

/// Solves with the direct L D Lᵀ and with the Schur PCG; returns both solutions.
pub fn solve_both(disc: &Discretization<'_>, loads: &[Load]) -> (Solution, Solution, Blocks) {
    let blocks = disc.assemble(Parallelism::Rayon);
    let (bu, bphi) = disc.rhs(loads).unwrap();
    let (nu, np) = (disc.dofs.n_u, disc.dofs.n_phi);
    let mut direct = DirectLdlt::new(&blocks.a, &blocks.g, &blocks.b, &Ordering::Amd, faer::Par::Seq).unwrap();
    let (mut u1, mut p1) = (vec![0.0; nu], vec![0.0; np]);
    direct.solve(&bu, &bphi, &mut u1, &mut p1).unwrap();
    let params = PcgParams {
        rel_tol: 1e-13,
        max_iters: 500,
        ..Default::default()
    };
    let mut schur = SchurPcg::new(blocks.a.clone(), blocks.g.clone(), &blocks.b, params, faer::Par::Seq).unwrap();
    let (mut u2, mut p2) = (vec![0.0; nu], vec![0.0; np]);
    schur.solve(&bu, &bphi, &mut u2, &mut p2).unwrap();
    ((u1, p1), (u2, p2), blocks)
}

pub use fe_assembly::voigt;

/// `σ = C ε + eᵀ ∇φ` and `D = e ε - β ∇φ` for a displacement gradient `gu[k][l] = ∂u_k/∂x_l`
/// and a potential gradient `gp`.
pub fn stress_and_d(m: &fe_assembly::Material, gu: &[[f64; 3]; 3], gp: &[f64; 3]) -> ([[f64; 3]; 3], [f64; 3]) {
    let dim = m.dim;
    let nv = m.nv();
    let mut sigma = [[0.0; 3]; 3];
    let mut d = [0.0; 3];
    for i in 0..dim {
        for j in 0..dim {
            let mut s = 0.0;
            for k in 0..dim {
                for l in 0..dim {
                    s += m.c[voigt(dim, i, j) * nv + voigt(dim, k, l)] * gu[k][l];
                }
                s += m.e[k * nv + voigt(dim, i, j)] * gp[k];
            }
            sigma[i][j] = s;
        }
        let mut s = 0.0;
        for k in 0..dim {
            for l in 0..dim {
                s += m.e[i * nv + voigt(dim, k, l)] * gu[k][l];
            }
            s -= m.beta[i * dim + k] * gp[k];
        }
        d[i] = s;
    }
    (sigma, d)
}

/// Largest absolute difference.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Uniform numbers in `[-0.5, 0.5)` from a linear congruential generator seeded with `seed`
/// (reproducible, and independent of any crate's generator).
pub fn random_source(seed: u64) -> impl FnMut() -> f64 {
    let mut seed = seed;
    move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// The block `[0, 2] x [0, 1]` (x `[0, 1]` in 3D) of 6 x 4 triangles or 4 x 2 x 2 boxes of
/// tetrahedra, its interior nodes moved by up to 0.04 in each coordinate (`random`'s numbers,
/// drawn node by node).
pub fn jittered_block(dim: usize, random: &mut impl FnMut() -> f64) -> mesh::Mesh {
    let mut mesh = if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 6, 4)
    } else {
        mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 4, 2, 2)
    };
    let (lo, hi) = mesh.bounding_box();
    for p in &mut mesh.points {
        if (0..dim).all(|q| p[q] != lo[q] && p[q] != hi[q]) {
            for k in 0..dim {
                p[k] += 0.08 * random();
            }
        }
    }
    mesh
}

/// PZT-5A poled along the last axis (y in 2D, z in 3D), in plane strain or 3D, or on a body
/// of revolution about y.
pub fn pzt5a(dim: usize, axisymmetric: bool) -> fe_assembly::Material {
    use fe_assembly::{Crystal, Material};
    let poling = if dim == 2 { [0.0, 1.0, 0.0] } else { [0.0, 0.0, 1.0] };
    if axisymmetric {
        Material::from_crystal_axisymmetric("pzt5a", &Crystal::pzt5a(), poling).unwrap()
    } else {
        Material::from_crystal("pzt5a", &Crystal::pzt5a(), poling, dim).unwrap()
    }
}

/// Moves the interior nodes of `m` (those on no face of its bounding box) by up to `amount / 2`
/// in each coordinate, the numbers of a linear congruential generator seeded with `seed`
/// drawn for every node and coordinate in order.
pub fn jitter(m: &mut mesh::Mesh, amount: f64, seed: u64) {
    let (lo, hi) = m.bounding_box();
    let mut random = random_source(seed);
    for p in &mut m.points {
        for k in 0..m.dim {
            let r = random();
            if (0..m.dim).all(|q| p[q] != lo[q] && p[q] != hi[q]) {
                p[k] += amount * r;
            }
        }
    }
}

/// The nodal `(u, φ)` of the direct solve under `loads` (every node, as
/// `DofMap::expand_u` gives them).
pub fn solve_nodal(disc: &Discretization<'_>, loads: &[Load]) -> (Vec<[f64; 3]>, Vec<f64>) {
    let blocks = disc.assemble(Parallelism::Rayon);
    let (bu, bphi) = disc.rhs(loads).unwrap();
    let mut direct = DirectLdlt::new(&blocks.a, &blocks.g, &blocks.b, &Ordering::Amd, faer::Par::Seq).unwrap();
    let (mut u, mut p) = (vec![0.0; disc.dofs.n_u], vec![0.0; disc.dofs.n_phi]);
    direct.solve(&bu, &bphi, &mut u, &mut p).unwrap();
    (disc.dofs.expand_u(&u), disc.dofs.expand_phi(&p))
}

/// The observed orders `(L2, energy)` between successive rows `(n, L2 error, energy error)`.
pub fn rates(rows: &[(usize, f64, f64)]) -> Vec<(f64, f64)> {
    rows.windows(2)
        .map(|w| {
            let r = (w[1].0 as f64 / w[0].0 as f64).ln();
            ((w[0].1 / w[1].1).ln() / r, (w[0].2 / w[1].2).ln() / r)
        })
        .collect()
}
