//! The numeric `L D Lᵀ` on several cores (the supernodes' elimination tree walked in parallel)
//! against faer's own sequential factorisation of the same matrix in the same order: the
//! same pivots, the same solution, the same condensation onto dofs ordered last, on a
//! quasi-definite `K = [[A, Gᵀ], [G, -B]]` of a grid (two displacements and one potential per
//! node) in a nested-dissection order, whose tree has independent subtrees at every level.

use faer::sparse::{SparseColMat, Triplet};
use faer::Par;
use linalg::{CoupledSolver, DirectLdlt, FactorKind, Ordering, SparseFactor};

/// `K` of an `m x m` grid: `A = L ⊗ I₂ + I`, `B = L + I` (`L` the graph Laplacian with random
/// positive edge weights), `G` coupling each potential to its node's and its neighbours'
/// displacements; `(A, G, B)` and the lower triangle of `K`. Dofs: `u` node-major, then `φ`.
type Blocks = (
    SparseColMat<usize, f64>,
    SparseColMat<usize, f64>,
    SparseColMat<usize, f64>,
);

fn grid(m: usize, seed: u64) -> Blocks {
    let mut state = seed;
    let mut rnd = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let n = m * m;
    let (mut a, mut g, mut b) = (vec![], vec![], vec![]);
    let node = |i: usize, j: usize| i * m + j;
    for i in 0..m {
        for j in 0..m {
            let p = node(i, j);
            for k in 0..2 {
                a.push(Triplet::new(2 * p + k, 2 * p + k, 1.0));
            }
            b.push(Triplet::new(p, p, 1.0));
            g.push(Triplet::new(p, 2 * p, rnd() - 0.5));
            let mut link = |q: usize| {
                let w = 1.0 + rnd();
                for (lo, hi) in [(p, q), (q, p)] {
                    for k in 0..2 {
                        a.push(Triplet::new(2 * lo + k, 2 * lo + k, w));
                        a.push(Triplet::new(2 * lo + k, 2 * hi + k, -w));
                    }
                    b.push(Triplet::new(lo, lo, w));
                    b.push(Triplet::new(lo, hi, -w));
                }
                g.push(Triplet::new(p, 2 * q + 1, rnd() - 0.5));
                g.push(Triplet::new(q, 2 * p, rnd() - 0.5));
            };
            if i + 1 < m {
                link(node(i + 1, j));
            }
            if j + 1 < m {
                link(node(i, j + 1));
            }
        }
    }
    (
        SparseColMat::try_new_from_triplets(2 * n, 2 * n, &a).unwrap(),
        SparseColMat::try_new_from_triplets(n, 2 * n, &g).unwrap(),
        SparseColMat::try_new_from_triplets(n, n, &b).unwrap(),
    )
}

/// Nested dissection of the grid's nodes (split the longer side in the middle, the middle
/// line last), expanded to each node's dofs (`u`, then `φ`).
fn dissection(m: usize) -> Vec<usize> {
    fn rec(i0: usize, i1: usize, j0: usize, j1: usize, m: usize, out: &mut Vec<usize>) {
        if (i1 - i0) * (j1 - j0) <= 16 {
            for i in i0..i1 {
                for j in j0..j1 {
                    out.push(i * m + j);
                }
            }
            return;
        }
        if i1 - i0 >= j1 - j0 {
            let c = (i0 + i1) / 2;
            rec(i0, c, j0, j1, m, out);
            rec(c + 1, i1, j0, j1, m, out);
            rec(c, c + 1, j0, j1, m, out);
        } else {
            let c = (j0 + j1) / 2;
            rec(i0, i1, j0, c, m, out);
            rec(i0, i1, c + 1, j1, m, out);
            rec(i0, i1, c, c + 1, m, out);
        }
    }
    let mut nodes = vec![];
    rec(0, m, 0, m, m, &mut nodes);
    let n = m * m;
    nodes.iter().flat_map(|&p| [2 * p, 2 * p + 1, 2 * n + p]).collect()
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn relative_gap(a: &[f64], b: &[f64]) -> f64 {
    let num = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    num / b.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The pivots of `f` by the matrix's index (the factor's order undone), so that factors in
/// two equivalent orders compare.
fn pivots_by_index(f: &SparseFactor) -> Vec<f64> {
    let pivots = f.pivots();
    let mut d = vec![0.0; pivots.len()];
    for (new, old) in f.permutation().into_iter().enumerate() {
        d[old] = pivots[new];
    }
    d
}

#[test]
fn the_tree_on_two_cores_factors_as_faer_does_on_one() {
    for (m, seed) in [(90, 1), (61, 2)] {
        let (a, g, b) = grid(m, seed);
        let k = linalg::sparse::lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref());
        let n = k.nrows();
        let ord = Ordering::Given(dissection(m));
        let mut seq = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::Seq).unwrap();
        // a pool of one thread walks the tree in order
        for threads in [1, 2, 3] {
            let mut par = on_threads(threads, || {
                SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::rayon(2))
            })
            .unwrap();
            assert!(par.parallel_tree() && !seq.parallel_tree());
            // the order made a postorder of its elimination tree: an equivalent order, with
            // the same fill (the stored values differ by the supernodes' padding) and, index
            // by index, the same pivots
            let (lp, ls) = (par.factor_len() as f64, seq.factor_len() as f64);
            assert!((lp / ls - 1.0).abs() < 0.05, "{lp} values against {ls}");
            let gap = relative_gap(&pivots_by_index(&par), &pivots_by_index(&seq));
            assert!(gap < 1e-13, "m = {m}, {threads} threads: pivots differ by {gap:e}");
            assert_eq!(par.inertia(), (2 * m * m, m * m, 0));
            let rhs: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
            let (mut x, mut y) = (rhs.clone(), rhs.clone());
            seq.solve_in_place(&mut x);
            // the solve on the same pool (one thread: faer's sweeps on the tree's factor)
            on_threads(threads, || par.solve_in_place(&mut y));
            let gap = relative_gap(&y, &x);
            assert!(gap < 1e-12, "m = {m}, {threads} threads: solutions differ by {gap:e}");
            // and again after a refactorisation with new values on the same pattern
            let k2 = linalg::sparse::lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref());
            on_threads(threads, || par.refactor(k2.as_ref())).unwrap();
            let mut z = rhs.clone();
            par.solve_in_place(&mut z);
            assert!(relative_gap(&z, &x) < 1e-12);
            // faer's analysis with the tree (its AMD, the analysis redone in postorder)
            let mut amd = on_threads(threads, || {
                SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &Ordering::Amd, Par::rayon(2))
            })
            .unwrap();
            assert!(amd.parallel_tree());
            let mut w = rhs.clone();
            on_threads(threads, || amd.solve_in_place(&mut w));
            assert!(relative_gap(&w, &x) < 1e-12, "AMD, {threads} threads");
        }
    }
}

/// The displacements of an `m x m` grid's first row, as contact dofs would be, and the
/// grid's nested dissection with them last.
fn first_row_last(m: usize) -> (Vec<usize>, Ordering) {
    let last: Vec<usize> = (0..2 * m).collect();
    let ordering = Ordering::GivenThenLast {
        order: dissection(m),
        last: last.clone(),
    };
    (last, ordering)
}

#[test]
fn the_condensation_reads_the_same_trailing_block_off_the_parallel_factor() {
    let m = 70;
    let (a, g, b) = grid(m, 3);
    let (n_u, n_phi) = (a.nrows(), b.nrows());
    let (last, ordering) = first_row_last(m);
    let b_u: Vec<f64> = (0..n_u).map(|i| ((i * 13) % 7) as f64 - 3.0).collect();
    let b_phi: Vec<f64> = (0..n_phi).map(|i| ((i * 5) % 3) as f64).collect();
    let mut seq = DirectLdlt::new(&a, &g, &b, &ordering, Par::Seq).unwrap();
    let mut par = on_threads(2, || DirectLdlt::new(&a, &g, &b, &ordering, Par::rayon(2))).unwrap();
    let cs = seq.condense(&b_u, &b_phi, &last).unwrap();
    // on two threads the condensation's forward sweep and the final backward one walk the tree
    let cp = on_threads(2, || par.condense(&b_u, &b_phi, &last)).unwrap();
    assert_eq!(cp.loads.route, linalg::CondenseRoute::TrailingBlock);
    assert!(relative_gap(&cp.inverse, &cs.inverse) < 1e-12);
    assert!(relative_gap(&cp.loads.solution, &cs.loads.solution) < 1e-12);
    let d: Vec<f64> = (0..last.len()).map(|i| (i % 5) as f64 * 0.1).collect();
    let (us, ps) = seq.solve_with_update(cs.loads, &b_u, &b_phi, &d).unwrap();
    let (up, pp) = on_threads(2, || par.solve_with_update(cp.loads, &b_u, &b_phi, &d)).unwrap();
    assert!(relative_gap(&up, &us) < 1e-12);
    assert!(relative_gap(&pp, &ps) < 1e-12);
}

/// Solves whose right-hand sides are zero but at the trailing dofs, solved together by their
/// backward sweeps alone, are each the full solve of that right-hand side (on one core and on
/// the tree's two); dofs the factor does not end with are declined.
#[test]
fn trailing_right_hand_sides_solved_together_are_full_solves() {
    let m = 50;
    let (a, g, b) = grid(m, 3);
    let (n_u, n_phi) = (a.nrows(), b.nrows());
    let (last, ordering) = first_row_last(m);
    let updates: Vec<Vec<f64>> = (0..5)
        .map(|s| (0..last.len()).map(|i| ((i * (3 + s)) % 7) as f64 - 3.0).collect())
        .collect();
    let views: Vec<&[f64]> = updates.iter().map(|d| &d[..]).collect();
    for threads in [1, 2] {
        let mut f = on_threads(threads, || DirectLdlt::new(&a, &g, &b, &ordering, Par::rayon(threads))).unwrap();
        let got = on_threads(threads, || f.solve_trailing_many(&last, &views))
            .unwrap()
            .expect("the factor ends with the dofs");
        assert_eq!(got.len(), updates.len());
        for (d, (u, phi)) in updates.iter().zip(&got) {
            let mut b_u = vec![0.0; n_u];
            for (&i, v) in last.iter().zip(d) {
                b_u[i] = *v;
            }
            let (mut x, mut y) = (vec![0.0; n_u], vec![0.0; n_phi]);
            on_threads(threads, || f.solve(&b_u, &vec![0.0; n_phi], &mut x, &mut y)).unwrap();
            assert!(relative_gap(u, &x) < 1e-12, "{threads} threads");
            assert!(relative_gap(phi, &y) < 1e-12, "{threads} threads");
        }
        let mut other = last.clone();
        other.reverse();
        assert!(f.solve_trailing_many(&other, &views).unwrap().is_none());
        assert!(f.solve_trailing_many(&last, &[&[1.0][..]]).is_err());
    }
}

/// Several right-hand sides solved together are each one's own solve (on one core and on the
/// tree's two), and refined together each ends where its own refinement does: below the
/// tolerance, with its residual measured as [`linalg::equilibrium_residual`] measures it.
#[test]
fn right_hand_sides_solved_and_refined_together_are_each_one_s_own() {
    let m = 40;
    let (a, g, b) = grid(m, 5);
    let (n_u, n_phi) = (a.nrows(), b.nrows());
    let ordering = Ordering::Given(dissection(m));
    let column = |s: usize| -> (Vec<f64>, Vec<f64>) {
        let u = (0..n_u).map(|i| ((i * (7 + s)) % 11) as f64 - 5.0).collect();
        let phi = (0..n_phi).map(|i| ((i * (3 + s)) % 5) as f64 * 0.3).collect();
        (u, phi)
    };
    let rhs: Vec<_> = (0..5).map(column).collect();
    let columns: Vec<(&[f64], &[f64])> = rhs.iter().map(|(u, p)| (&u[..], &p[..])).collect();
    for threads in [1, 2] {
        let mut f = on_threads(threads, || DirectLdlt::new(&a, &g, &b, &ordering, Par::rayon(threads))).unwrap();
        let together = on_threads(threads, || f.solve_many(&columns)).unwrap();
        assert_eq!(together.len(), 5);
        for ((b_u, b_phi), (u, phi)) in rhs.iter().zip(&together) {
            let (mut u1, mut p1) = (vec![0.0; n_u], vec![0.0; n_phi]);
            linalg::CoupledSolver::solve(&mut f, b_u, b_phi, &mut u1, &mut p1).unwrap();
            assert!(relative_gap(u, &u1) < 1e-13 && relative_gap(phi, &p1) < 1e-13);
        }
        let k = linalg::CoupledBlocks { a: &a, g: &g, b: &b };
        let measures: Vec<linalg::Rhs<'_>> = rhs.iter().map(|(u, phi)| linalg::Rhs { u, phi, scale: 0.0 }).collect();
        // perturbed solutions: each refined back below the tolerance, in at most 3 steps
        let mut xs: Vec<(Vec<f64>, Vec<f64>)> = together
            .iter()
            .enumerate()
            .map(|(s, (u, phi))| {
                let bump = 1e-6 * (s as f64 + 1.0);
                (u.iter().map(|x| x * (1.0 + bump)).collect(), phi.clone())
            })
            .collect();
        let refined = on_threads(threads, || linalg::refine_many(&mut f, k, &measures, &mut xs, 1e-13, 3)).unwrap();
        for ((r, (u, phi)), b) in refined.iter().zip(&xs).zip(&measures) {
            assert!((1..=3).contains(&r.steps), "{r:?}");
            assert!(r.residual < 1e-13, "{r:?}");
            assert_eq!(r.residual, linalg::equilibrium_residual(k, u, phi, *b));
        }
        // a solution already below the tolerance is left as it is
        let again = linalg::refine_many(&mut f, k, &measures, &mut xs, 1e-13, 3).unwrap();
        assert!(again.iter().all(|r| r.steps == 0));
        assert!(linalg::refine_many(&mut f, k, &measures[..2], &mut xs, 1e-13, 3).is_err());
    }
}

/// A root supernode wider than 4096 columns (the displacements of the grid's first 30 rows
/// ordered last: 4200 dofs coupled through the whole grid), whose dense `L D Lᵀ` the tree
/// makes with 512-column panels (faer's default is 128): the same pivots and solution as
/// faer's sequential walk.
#[test]
fn a_wide_root_factors_as_faer_does_on_one_core() {
    let m = 70;
    let (a, g, b) = grid(m, 5);
    let k = linalg::sparse::lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref());
    let n = k.nrows();
    let last: Vec<usize> = (0..2 * m * 30).collect();
    let ord = Ordering::GivenThenLast {
        order: dissection(m),
        last,
    };
    let mut seq = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::Seq).unwrap();
    let mut par = on_threads(2, || {
        SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::rayon(2))
    })
    .unwrap();
    assert!(par.parallel_tree());
    assert!(relative_gap(&pivots_by_index(&par), &pivots_by_index(&seq)) < 1e-12);
    assert_eq!(par.inertia(), (2 * m * m, m * m, 0));
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let (mut x, mut y) = (rhs.clone(), rhs);
    seq.solve_in_place(&mut x);
    on_threads(2, || par.solve_in_place(&mut y));
    let gap = relative_gap(&y, &x);
    assert!(gap < 1e-12, "solutions differ by {gap:e}");
}

#[test]
fn a_singular_matrix_is_refused_on_the_parallel_route_too() {
    // the grid with one node's potential cut off from everything and its diagonal zero
    let m = 60;
    let (a, g, b) = grid(m, 4);
    let mut t = vec![];
    let dead = m * m / 2;
    for j in 0..b.ncols() {
        for (i, v) in b.row_idx_of_col(j).zip(b.val_of_col(j)) {
            if i != dead && j != dead {
                t.push(Triplet::new(i, j, *v));
            }
        }
    }
    let b0 = SparseColMat::try_new_from_triplets(b.nrows(), b.ncols(), &t).unwrap();
    let mut tg = vec![];
    for j in 0..g.ncols() {
        for (i, v) in g.row_idx_of_col(j).zip(g.val_of_col(j)) {
            if i != dead {
                tg.push(Triplet::new(i, j, *v));
            }
        }
    }
    let g0 = SparseColMat::try_new_from_triplets(g.nrows(), g.ncols(), &tg).unwrap();
    let k = linalg::sparse::lower_quasi_definite(a.as_ref(), g0.as_ref(), b0.as_ref());
    let ord = Ordering::Given(dissection(m));
    let seq = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::Seq).unwrap_err();
    let par = on_threads(2, || {
        SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::rayon(2))
    })
    .unwrap_err();
    assert_eq!(format!("{par}"), format!("{seq}"));
}

/// The tree checks each supernode's values as it factors it (the whole factor is not read
/// again after). The first node's potential, uncoupled from the displacements and given the
/// subnormal diagonal `1e-310`, is the last pivot of its supernode, `-1e-310`: the entries
/// below it, `b_i0 / 1e-310`, are infinities under finite pivots. The tree names them an
/// overflow of the factor where they appear; faer's sequential walk stops on the pivot they
/// make infinite next (faer calls a non-finite pivot a zero one). Both refuse the matrix.
#[test]
fn an_overflow_is_refused_on_the_parallel_route_too() {
    let m = 40;
    let (a, g, b) = grid(m, 6);
    let keep = |m: &SparseColMat<usize, f64>, f: &dyn Fn(usize, usize, f64) -> Option<f64>| {
        let mut t = vec![];
        for j in 0..m.ncols() {
            for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                if let Some(x) = f(i, j, *v) {
                    t.push(Triplet::new(i, j, x));
                }
            }
        }
        SparseColMat::try_new_from_triplets(m.nrows(), m.ncols(), &t).unwrap()
    };
    let b = keep(&b, &|i, j, v| Some(if (i, j) == (0, 0) { 1e-310 } else { v }));
    let g = keep(&g, &|i, _, v| (i != 0).then_some(v));
    let k = linalg::sparse::lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref());
    let ord = Ordering::Given(dissection(m));
    assert!(SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::Seq).is_err());
    for threads in [1, 2] {
        let e = on_threads(threads, || {
            SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::rayon(2))
        })
        .unwrap_err();
        assert!(
            matches!(&e, linalg::LinalgError::NonFinite { what } if what.contains("overflow")),
            "{threads} threads: {e}"
        );
    }
}

#[test]
fn a_matrix_of_two_unconnected_blocks_has_two_roots_and_factors_alike() {
    let k1 = {
        let (a, g, b) = grid(50, 5);
        linalg::sparse::lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref())
    };
    let k2 = {
        let (a, g, b) = grid(40, 6);
        linalg::sparse::lower_quasi_definite(a.as_ref(), g.as_ref(), b.as_ref())
    };
    let (n1, n2) = (k1.nrows(), k2.nrows());
    let mut t = vec![];
    for (k, off) in [(&k1, 0), (&k2, n1)] {
        for j in 0..k.ncols() {
            for (i, v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
                t.push(Triplet::new(i + off, j + off, *v));
            }
        }
    }
    let k = SparseColMat::try_new_from_triplets(n1 + n2, n1 + n2, &t).unwrap();
    let mut order = dissection(50);
    order.extend(dissection(40).into_iter().map(|i| i + n1));
    let ord = Ordering::Given(order);
    let mut seq = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::Seq).unwrap();
    let mut par = on_threads(2, || {
        SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, Par::rayon(2))
    })
    .unwrap();
    assert!(par.parallel_tree());
    let rhs: Vec<f64> = (0..n1 + n2).map(|i| (i % 9) as f64 - 4.0).collect();
    let (mut x, mut y) = (rhs.clone(), rhs.clone());
    seq.solve_in_place(&mut x);
    par.solve_in_place(&mut y);
    assert!(relative_gap(&y, &x) < 1e-12);
}

/// A factorisation's progress, read from another thread while it runs on 1 and 2 threads:
/// none before it starts, then fractions that never fall, ending at exactly 1; the factor
/// the same as without a watch (its pivots to the last bit).
#[test]
fn a_factorisation_s_progress_rises_to_one() {
    use std::sync::atomic::{AtomicBool, Ordering as Atomic};
    let m = 120;
    let (a, g, b) = grid(m, 7);
    let ord = Ordering::Given(dissection(m));
    for threads in [1, 2] {
        let progress = linalg::FactorProgress::default();
        assert_eq!(progress.fraction(), None);
        let done = AtomicBool::new(false);
        let (watched, seen) = std::thread::scope(|s| {
            let reader = s.spawn(|| {
                let mut seen = vec![];
                while !done.load(Atomic::Relaxed) {
                    if let Some(f) = progress.fraction() {
                        seen.push(f);
                    }
                    std::thread::yield_now();
                }
                seen
            });
            let f = on_threads(threads, || {
                DirectLdlt::new_watched([&a, &g, &b], &ord, (Par::rayon(2), None), Some(&progress))
            })
            .unwrap();
            done.store(true, Atomic::Relaxed);
            (f, reader.join().unwrap())
        });
        assert_eq!(progress.fraction(), Some(1.0), "{threads} threads");
        assert!(
            seen.windows(2).all(|w| w[0] <= w[1]),
            "{threads} threads: a fraction fell"
        );
        assert!(seen.iter().all(|f| (0.0..=1.0).contains(f)));
        let plain = on_threads(threads, || DirectLdlt::new(&a, &g, &b, &ord, Par::rayon(2))).unwrap();
        assert_eq!(watched.factor().pivots(), plain.factor().pivots());
    }
}

/// The operations the tree counts for a numeric factorisation, against a closed form: a dense
/// matrix of order `n` is one supernode whose column `j` has `c = n - 1 - j` rows below its
/// diagonal, each counted `c (c + 3)`, in all `(n-1) n (2n-1)/6 + 3 n (n-1)/2`; and a time to
/// go with them.
#[test]
fn the_factorisation_counts_its_operations() {
    let n = 200;
    let mut t = vec![];
    for j in 0..n {
        for i in j..n {
            let v = if i == j { n as f64 } else { 1.0 / (1.0 + (i - j) as f64) };
            t.push(Triplet::new(i, j, v));
        }
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
    let order: Vec<usize> = (0..n).collect();
    let f = on_threads(2, || {
        SparseFactor::new(a.as_ref(), FactorKind::Ldlt, &Ordering::Given(order), Par::rayon(2))
    })
    .unwrap();
    assert!(f.parallel_tree());
    let m = n as f64;
    let exact = (m - 1.0) * m * (2.0 * m - 1.0) / 6.0 + 3.0 * m * (m - 1.0) / 2.0;
    assert_eq!(f.flops(), Some(exact));
    assert!(f.numeric_seconds() > 0.0);
}
