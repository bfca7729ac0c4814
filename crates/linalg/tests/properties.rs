//! Property tests of the linear algebra on random matrices (no finite elements):
//! - PCG reaches its tolerance on random SPD systems, with and without a preconditioner;
//! - the Schur operator equals the dense `S = A + Gᵀ B⁻¹ G`;
//! - the direct `L D Lᵀ` and the Schur PCG give the same solution of `K x = b`;
//! - an ordering that puts chosen dofs last gives the same solution as AMD, and `K` has
//!   exactly `n_φ` negative pivots;
//! - the condensation onto chosen dofs is the block of `K⁻¹`, by both of its routes;
//! - iterative refinement goes on only while each step at least halves the residual.

use faer::sparse::{SparseColMat, Triplet};
use faer::Par;
use linalg::sparse::{mul_add, to_dense};
use linalg::{
    pcg, CondenseRoute, CoupledSolver, DirectLdlt, FactorKind, Identity, LinearOperator, Ordering, PcgParams,
    SchurOperator, SchurPcg, SparseFactor,
};
use nalgebra::DMatrix;
use proptest::prelude::*;

/// A random sparse SPD matrix: a random sparse M, then Mᵀ M + shift I.
fn spd(n: usize, vals: &[f64], shift: f64) -> SparseColMat<usize, f64> {
    let mut m = DMatrix::<f64>::zeros(n, n);
    for (k, &v) in vals.iter().enumerate() {
        let (i, j) = ((k * 7) % n, (k * 13 + k / n) % n);
        m[(i, j)] += v;
    }
    let a = m.transpose() * &m + DMatrix::identity(n, n) * shift;
    dense_to_sparse(&a)
}

/// A random `np x nu` coupling block: the values `vals` summed into scattered entries.
fn coupling(np: usize, nu: usize, vals: &[f64]) -> DMatrix<f64> {
    let mut gd = DMatrix::<f64>::zeros(np, nu);
    for (k, &v) in vals.iter().enumerate() {
        gd[((k * 5) % np, (k * 3 + k / np) % nu)] += v;
    }
    gd
}

fn dense_to_sparse(a: &DMatrix<f64>) -> SparseColMat<usize, f64> {
    let mut t = vec![];
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            if a[(i, j)] != 0.0 {
                t.push(Triplet::new(i, j, a[(i, j)]));
            }
        }
    }
    SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &t).unwrap()
}

fn dense(m: &SparseColMat<usize, f64>) -> DMatrix<f64> {
    let d = to_dense(m.as_ref());
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| d[i][j])
}

struct Csc<'a>(&'a SparseColMat<usize, f64>);
impl LinearOperator for Csc<'_> {
    fn n(&self) -> usize {
        self.0.nrows()
    }
    fn apply(&mut self, out: &mut [f64], x: &[f64]) {
        out.fill(0.0);
        mul_add(self.0.as_ref(), x, out, 1.0);
    }
}

struct Inv<'a>(&'a mut SparseFactor);
impl LinearOperator for Inv<'_> {
    fn n(&self) -> usize {
        self.0.n()
    }
    fn apply(&mut self, out: &mut [f64], x: &[f64]) {
        out.copy_from_slice(x);
        self.0.solve_in_place(out);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn pcg_reaches_its_tolerance(
        n in 5usize..60,
        vals in prop::collection::vec(-1.0f64..1.0, 200),
        b in prop::collection::vec(-1.0f64..1.0, 60),
        shift in 1e-3f64..1.0,
    ) {
        let a = spd(n, &vals, shift);
        let b = &b[..n];
        let params = PcgParams { rel_tol: 1e-10, max_iters: 10 * n, ..Default::default() };
        let mut x = vec![0.0; n];
        let info = pcg(&mut Csc(&a), &mut Identity(n), b, &mut x, &params).unwrap();
        // the true residual meets the tolerance (not only the recursive one), up to drift
        let mut r = vec![0.0; n];
        mul_add(a.as_ref(), &x, &mut r, 1.0);
        let res: f64 = r.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt();
        let nb: f64 = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        prop_assert!(info.rel_residual <= 1e-10);
        prop_assert!(res <= 1e-8 * nb, "true residual {res}");
        // preconditioned by the exact inverse: one iteration (two with round-off)
        let mut f = SparseFactor::new(a.as_ref(), FactorKind::Cholesky, &Ordering::Amd, Par::Seq).unwrap();
        let mut x2 = vec![0.0; n];
        let info2 = pcg(&mut Csc(&a), &mut Inv(&mut f), b, &mut x2, &params).unwrap();
        prop_assert!(info2.n_iters <= 2, "{} iterations with the exact preconditioner", info2.n_iters);
    }

    #[test]
    fn schur_operator_equals_dense_and_strategies_agree(
        nu in 4usize..30,
        np in 2usize..15,
        va in prop::collection::vec(-1.0f64..1.0, 120),
        vb in prop::collection::vec(-1.0f64..1.0, 60),
        vg in prop::collection::vec(-2.0f64..2.0, 80),
        rhs in prop::collection::vec(-1.0f64..1.0, 45),
    ) {
        let a = spd(nu, &va, 0.1);
        let b = spd(np, &vb, 0.1);
        let gd = coupling(np, nu, &vg);
        let g = dense_to_sparse(&gd);
        let (ad, bd) = (dense(&a), dense(&b));
        let s_dense = &ad + gd.transpose() * bd.clone().try_inverse().unwrap() * &gd;
        let mut fb = SparseFactor::new(b.as_ref(), FactorKind::Cholesky, &Ordering::Amd, Par::Seq).unwrap();
        let mut op = SchurOperator::new(&a, &g, &mut fb);
        let scale = s_dense.amax();
        for j in 0..nu {
            let mut e = vec![0.0; nu];
            e[j] = 1.0;
            let mut col = vec![0.0; nu];
            op.apply(&mut col, &e);
            for i in 0..nu {
                prop_assert!((col[i] - s_dense[(i, j)]).abs() <= 1e-10 * scale);
            }
        }
        // both strategies solve K x = b
        let (bu, bp) = (&rhs[..nu], &rhs[30..30 + np]);
        let mut direct = DirectLdlt::new(&a, &g, &b, &Ordering::Amd, Par::Seq).unwrap();
        prop_assert_eq!(direct.factor().inertia(), (nu, np, 0));
        let (mut u1, mut p1) = (vec![0.0; nu], vec![0.0; np]);
        direct.solve(bu, bp, &mut u1, &mut p1).unwrap();
        let params = PcgParams { rel_tol: 1e-14, max_iters: 200, ..Default::default() };
        let mut schur = SchurPcg::new(a.clone(), g.clone(), &b, params, Par::Seq).unwrap();
        let (mut u2, mut p2) = (vec![0.0; nu], vec![0.0; np]);
        schur.solve(bu, bp, &mut u2, &mut p2).unwrap();
        let xs: f64 = u1.iter().chain(&p1).fold(0.0, |m, x| m.max(x.abs()));
        for (x, y) in u1.iter().chain(&p1).zip(u2.iter().chain(&p2)) {
            prop_assert!((x - y).abs() <= 1e-9 * xs.max(1e-300), "{x} vs {y}");
        }
        // the same with the electric dofs and two u dofs ordered last
        let mut last: Vec<usize> = (nu..nu + np).collect();
        last.extend([0, nu / 2]);
        let mut custom = DirectLdlt::new(&a, &g, &b, &Ordering::AmdThenLast(last.clone()), Par::Seq).unwrap();
        prop_assert_eq!(&custom.factor().permutation()[nu + np - last.len()..], &last[..]);
        let (mut u3, mut p3) = (vec![0.0; nu], vec![0.0; np]);
        custom.solve(bu, bp, &mut u3, &mut p3).unwrap();
        for (x, y) in u1.iter().chain(&p1).zip(u3.iter().chain(&p3)) {
            prop_assert!((x - y).abs() <= 1e-10 * xs.max(1e-300));
        }
        // and with a given permutation (reversed)
        let rev: Vec<usize> = (0..nu + np).rev().collect();
        let mut given = DirectLdlt::new(&a, &g, &b, &Ordering::Given(rev.clone()), Par::Seq).unwrap();
        prop_assert_eq!(given.factor().permutation(), rev);
        prop_assert_eq!(given.factor().inertia(), (nu, np, 0));
        let (mut u4, mut p4) = (vec![0.0; nu], vec![0.0; np]);
        given.solve(bu, bp, &mut u4, &mut p4).unwrap();
        for (x, y) in u1.iter().chain(&p1).zip(u4.iter().chain(&p4)) {
            prop_assert!((x - y).abs() <= 1e-10 * xs.max(1e-300));
        }
    }
}

#[test]
fn not_positive_definite_is_a_typed_error() {
    let a =
        SparseColMat::<usize, f64>::try_new_from_triplets(2, 2, &[Triplet::new(0, 0, 1.0), Triplet::new(1, 1, -1.0)])
            .unwrap();
    let e = SparseFactor::new(a.as_ref(), FactorKind::Cholesky, &Ordering::Amd, Par::Seq).unwrap_err();
    assert!(matches!(e, linalg::LinalgError::NotPositiveDefinite { .. }), "{e}");
    let nan = SparseColMat::<usize, f64>::try_new_from_triplets(1, 1, &[Triplet::new(0, 0, f64::NAN)]).unwrap();
    assert!(matches!(
        SparseFactor::new(nan.as_ref(), FactorKind::Ldlt, &Ordering::Amd, Par::Seq),
        Err(linalg::LinalgError::NonFinite { .. })
    ));
}

/// The condensation onto chosen dofs, by both routes (the trailing block of an `L D Lᵀ` with
/// the dofs last, and block solves): its inverse block equals the block of `K⁻¹` computed by
/// unit solves, its solution at the dofs the full solve's, and the solve with a change of the
/// right-hand side at the dofs the full solve of the changed loads (checked on the 2D
/// Laplacian-like quasi-definite matrix of a grid, large enough to go supernodal).
#[test]
fn condensation_is_the_block_of_the_inverse() {
    // K = [[A, Gᵀ], [G, -B]] with A, B grid Laplacians + I and G a shifted identity
    let m = 40; // grid m x m, so n_u = n_phi = 1600
    let n = m * m;
    let lap = |shift: f64| {
        let mut t = vec![];
        for i in 0..m {
            for j in 0..m {
                let p = i * m + j;
                t.push(Triplet::new(p, p, 4.0 + shift));
                if i + 1 < m {
                    t.push(Triplet::new(p, p + m, -1.0));
                    t.push(Triplet::new(p + m, p, -1.0));
                }
                if j + 1 < m {
                    t.push(Triplet::new(p, p + 1, -1.0));
                    t.push(Triplet::new(p + 1, p, -1.0));
                }
            }
        }
        SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap()
    };
    let (a, b) = (lap(0.5), lap(1.0));
    let g = SparseColMat::<usize, f64>::try_new_from_triplets(
        n,
        n,
        &(0..n).map(|i| Triplet::new(i, i, 0.7)).collect::<Vec<_>>(),
    )
    .unwrap();
    // the "contact" dofs: the u dofs of the grid's first row; then with their potentials too
    // (electrical contact: the trailing block is indefinite, its pivots of both signs)
    let u_only: Vec<usize> = (0..m).collect();
    let with_phi: Vec<usize> = (0..m).chain(n..n + m).collect();
    for last in [u_only, with_phi] {
        // AMD on the rest, or a given order of all (reversed) with the contact dofs taken out
        let given = Ordering::GivenThenLast {
            order: (0..2 * n).rev().collect(),
            last: last.clone(),
        };
        for ordering in [Ordering::AmdThenLast(last.clone()), given] {
            check_trailing_block(&a, &g, &b, &ordering, &last);
        }
    }
}

fn check_trailing_block(
    a: &SparseColMat<usize, f64>,
    g: &SparseColMat<usize, f64>,
    b: &SparseColMat<usize, f64>,
    ordering: &Ordering,
    last: &[usize],
) {
    let (n, m) = (a.nrows(), last.len());
    let mut f = DirectLdlt::new(a, g, b, ordering, Par::Seq).unwrap();
    assert_eq!(&f.factor().permutation()[2 * n - m..], last);
    // the loads, and a change of the right-hand side on the condensed dofs
    let rhs: Vec<f64> = (0..2 * n).map(|i| ((i * 7 % 11) as f64) - 5.0).collect();
    let (b_u, b_phi) = rhs.split_at(n);
    let d: Vec<f64> = (0..m).map(|j| 0.5 + j as f64).collect();
    let solve = |f: &mut DirectLdlt, rhs: &[f64]| {
        let (mut u, mut p) = (vec![0.0; n], vec![0.0; n]);
        f.solve(&rhs[..n], &rhs[n..], &mut u, &mut p).unwrap();
        u.into_iter().chain(p).collect::<Vec<f64>>()
    };
    let full = solve(&mut f, &rhs);
    let mut changed = rhs.clone();
    for (j, &i) in last.iter().enumerate() {
        changed[i] += d[j];
    }
    let full_changed = solve(&mut f, &changed);
    // column j of K⁻¹ restricted to the condensed dofs, by a solve with a unit load
    let mut inv = DMatrix::<f64>::zeros(m, m);
    for (j, &dj) in last.iter().enumerate() {
        let mut e = vec![0.0; 2 * n];
        e[dj] = 1.0;
        let x = solve(&mut f, &e);
        for (i, &di) in last.iter().enumerate() {
            inv[(i, j)] = x[di];
        }
    }
    let scale = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for route in [CondenseRoute::TrailingBlock, CondenseRoute::BlockSolves] {
        // the block route, forced by condensing onto the dofs in another order than the factor's
        let mut dofs = last.to_vec();
        if route == CondenseRoute::BlockSolves {
            dofs.reverse();
        }
        let condensed = f.condense(b_u, b_phi, &dofs).unwrap();
        assert_eq!(condensed.loads.route, route);
        let got = DMatrix::from_row_slice(m, m, &condensed.inverse);
        for (i, &di) in dofs.iter().enumerate() {
            let p = last.iter().position(|&x| x == di).unwrap();
            assert!((condensed.loads.solution[i] - full[di]).abs() <= 1e-12 * scale(&full));
            for (j, &dj) in dofs.iter().enumerate() {
                let q = last.iter().position(|&x| x == dj).unwrap();
                assert!(
                    (got[(i, j)] - inv[(p, q)]).abs() < 1e-12 * inv.amax(),
                    "{route:?} ({i}, {j})"
                );
            }
        }
        // the solve with the update at the condensed dofs is the full solve of the changed loads
        let d_in_order: Vec<f64> = dofs
            .iter()
            .map(|&x| d[last.iter().position(|&y| y == x).unwrap()])
            .collect();
        let (u, p) = f.solve_with_update(condensed.loads, b_u, b_phi, &d_in_order).unwrap();
        let updated: Vec<f64> = u.into_iter().chain(p).collect();
        let s = scale(&full_changed);
        assert!(
            updated
                .iter()
                .zip(&full_changed)
                .all(|(x, y)| (x - y).abs() <= 1e-12 * s),
            "{route:?}"
        );
    }
}

/// The exact solve of `K` with its answer scaled by `1 - rho`: each refinement step then
/// leaves exactly the fraction `rho` of the error (and of the residual).
struct Damped {
    exact: DirectLdlt,
    rho: f64,
}

impl CoupledSolver for Damped {
    fn solve(
        &mut self,
        b_u: &[f64],
        b_phi: &[f64],
        u: &mut [f64],
        phi: &mut [f64],
    ) -> Result<linalg::SolveInfo, linalg::LinalgError> {
        let info = self.exact.solve(b_u, b_phi, u, phi)?;
        for x in u.iter_mut().chain(phi.iter_mut()) {
            *x *= 1.0 - self.rho;
        }
        Ok(info)
    }

    fn factor_bytes(&self) -> usize {
        self.exact.factor_bytes()
    }
}

/// Refinement goes on while each step at least halves the residual (LAPACK's `xGERFS` test):
/// a solver that leaves a tenth of the error takes every step allowed, one that leaves 70 %
/// stops after its first step (which is kept: it lowered the residual), and the exact one
/// stops once its residual is round-off.
#[test]
fn refinement_stops_where_a_step_no_longer_halves_the_residual() {
    let (nu, np) = (12, 5);
    let vals: Vec<f64> = (0..40).map(|k| ((k * 37) % 11) as f64 / 11.0 - 0.4).collect();
    let a = spd(nu, &vals, 1.0);
    let b = spd(np, &vals[..15], 0.5);
    let gd = coupling(np, nu, &vals[..20]);
    let g = dense_to_sparse(&gd);
    let k = linalg::CoupledBlocks { a: &a, g: &g, b: &b };
    let b_u: Vec<f64> = (0..nu).map(|i| 1.0 + i as f64).collect();
    let b_phi: Vec<f64> = (0..np).map(|i| (i % 2) as f64 - 0.5).collect();
    let refine = |rho: f64| {
        let exact = DirectLdlt::new(&a, &g, &b, &Ordering::Amd, Par::Seq).unwrap();
        let mut solver = Damped { exact, rho };
        let (mut u, mut phi) = (vec![0.0; nu], vec![0.0; np]);
        let rhs = linalg::Rhs {
            u: &b_u,
            phi: &b_phi,
            scale: 0.0,
        };
        let start = linalg::equilibrium_residual(k, &u, &phi, rhs);
        let out = linalg::refine(&mut solver, k, rhs, &mut u, &mut phi, 1e-300, 3).unwrap();
        (start, out)
    };
    let (start, tenth) = refine(0.1);
    assert_eq!(tenth.steps, 3);
    assert!(
        (tenth.residual / start / 1e-3 - 1.0).abs() < 1e-6,
        "{}",
        tenth.residual / start
    );
    let (start, most) = refine(0.7);
    assert_eq!(most.steps, 1);
    assert!((most.residual / start / 0.7 - 1.0).abs() < 1e-9);
    let (start, exact) = refine(0.0);
    assert!((1..=2).contains(&exact.steps), "{} steps", exact.steps);
    assert!(exact.residual < 1e-14 * start);
}
