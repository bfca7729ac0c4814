//! The layer's tests, each run on two ranks: a test started by `cargo test` starts itself again
//! under `mpirun -np 2` (the child processes see `OMPI_COMM_WORLD_SIZE` and run the body), and
//! passes when every rank passes. Needs the feature `bind` (PETSc and Open MPI installed).
#![cfg(feature = "bind")]

use petsc::testing::on_ranks;
use petsc::{partition, Index, Ksp, Matrix, Petsc, PetscError, Vector};

/// The neighbours of vertex `r` of a k x k grid (the 5-point stencil without the centre).
fn grid_neighbours(k: usize, r: usize) -> Vec<usize> {
    let (i, j) = (r / k, r % k);
    let mut c = vec![];
    if i > 0 {
        c.push(r - k);
    }
    if i + 1 < k {
        c.push(r + k);
    }
    if j > 0 {
        c.push(r - 1);
    }
    if j + 1 < k {
        c.push(r + 1);
    }
    c
}

/// The 5-point Laplacian of a k x k grid with Dirichlet boundary (rows of this rank's range).
fn laplacian<'p>(p: &'p Petsc, k: usize) -> Matrix<'p> {
    let n = k * k;
    let (lo, hi) = p.split(n);
    let own = |c: usize| (lo..hi).contains(&c);
    let mut d_nnz = vec![0 as Index; hi - lo];
    let mut o_nnz = vec![0 as Index; hi - lo];
    let neighbours = |r: usize| std::iter::once(r).chain(grid_neighbours(k, r)).collect::<Vec<_>>();
    for r in lo..hi {
        for c in neighbours(r) {
            if own(c) {
                d_nnz[r - lo] += 1;
            } else {
                o_nnz[r - lo] += 1;
            }
        }
    }
    let mut a = Matrix::aij(p, hi - lo, n, &d_nnz, &o_nnz).unwrap();
    for r in lo..hi {
        let cols: Vec<Index> = neighbours(r).iter().map(|&c| c as Index).collect();
        let vals: Vec<f64> = cols.iter().map(|&c| if c as usize == r { 4.0 } else { -1.0 }).collect();
        a.add_values(&[r as Index], &cols, &vals).unwrap();
    }
    a.assemble().unwrap();
    a.set_symmetric().unwrap();
    a
}

#[test]
fn a_manufactured_solution_is_recovered_by_cg_with_algebraic_multigrid() {
    on_ranks(
        "a_manufactured_solution_is_recovered_by_cg_with_algebraic_multigrid",
        2,
        |p| {
            assert_eq!(p.size(), 2);
            let k = 40;
            let a = laplacian(p, k);
            let (lo, hi) = p.split(k * k);
            let exact: Vec<f64> = (lo..hi)
                .map(|r| ((r as f64) * 0.37).sin() + 0.1 * (r % 7) as f64)
                .collect();
            let x_star = Vector::from_local(p, &exact).unwrap();
            let mut b = x_star.duplicate().unwrap();
            a.mult(&x_star, &mut b).unwrap();
            let mut x = x_star.duplicate().unwrap();
            for pc in ["gamg", "hypre", "jacobi"] {
                let mut ksp = Ksp::new(p, &a).unwrap();
                ksp.set_types("cg", pc).unwrap();
                ksp.set_tolerances(1e-12, 0.0, 2000).unwrap();
                let info = ksp.solve(&b, &mut x).unwrap();
                let mut err = x.duplicate().unwrap();
                err.axpy(1.0, &x).unwrap();
                err.axpy(-1.0, &x_star).unwrap();
                let rel = err.norm().unwrap() / x_star.norm().unwrap();
                assert!(
                    rel < 1e-9,
                    "{pc}: relative error {rel:.2e} after {} iterations",
                    info.iterations
                );
                assert!(info.reason.starts_with("CONVERGED"), "{pc}: {}", info.reason);
            }
            // The whole solution on rank 0, in global order.
            let all = x.gather().unwrap();
            let ends = p.all_gather(hi as u64).unwrap();
            if p.rank() == 0 {
                let all = all.expect("rank 0 holds the gathered vector");
                assert_eq!(all.len(), k * k);
                assert_eq!(ends.last().copied(), Some((k * k) as u64));
                assert!((all[0] - exact[0]).abs() < 1e-8);
            } else {
                assert!(all.is_none());
            }
        },
    );
}

#[test]
fn errors_come_back_typed_with_petscs_message() {
    on_ranks("errors_come_back_typed_with_petscs_message", 2, |p| {
        // A second start is refused.
        assert!(matches!(Petsc::init(), Err(PetscError::AlreadyInitialised)));
        let k = 20;
        let a = laplacian(p, k);
        let (lo, hi) = p.split(k * k);
        let b = Vector::filled(p, hi - lo, 1.0).unwrap();
        let mut x = b.duplicate().unwrap();
        // Too few iterations: the reason, not a silent answer.
        let mut ksp = Ksp::new(p, &a).unwrap();
        ksp.set_types("cg", "none").unwrap();
        ksp.set_tolerances(1e-12, 0.0, 3).unwrap();
        match ksp.solve(&b, &mut x) {
            Err(PetscError::KspDiverged { reason, iterations, .. }) => {
                assert_eq!(reason, "DIVERGED_ITS");
                assert_eq!(iterations, 3);
            }
            other => panic!("expected DIVERGED_ITS, got {other:?}"),
        }
        // An entry outside the preallocation: PETSc's own message, no traceback printed.
        let mut m = Matrix::aij(p, hi - lo, k * k, &vec![1; hi - lo], &vec![0; hi - lo]).unwrap();
        let r = lo as Index;
        m.add_values(&[r], &[r], &[1.0]).unwrap();
        let e = m
            .add_values(&[r], &[((r as usize + 1) % (k * k)) as Index], &[1.0])
            .unwrap_err();
        let text = e.to_string();
        assert!(
            matches!(
                e,
                PetscError::Call {
                    call: "MatSetValues",
                    ..
                }
            ),
            "{text}"
        );
        assert!(text.contains("nonzero"), "{text}");
        // Mismatched lengths are caught before PETSc sees them.
        assert!(matches!(
            b.duplicate().unwrap().add_values(&[0], &[]),
            Err(PetscError::Argument(_))
        ));
        // Options from the database override the code's choice.
        p.insert_options("-bad_ksp_type nonsense").unwrap();
        let mut bad = Ksp::new(p, &a).unwrap();
        bad.set_options_prefix("bad_").unwrap();
        let e = bad.set_from_options().unwrap_err();
        assert!(e.to_string().contains("nonsense"), "{e}");
    });
}

#[test]
fn a_grid_graph_is_split_in_balanced_connected_halves() {
    on_ranks("a_grid_graph_is_split_in_balanced_connected_halves", 2, |p| {
        let k = 30;
        let n = k * k;
        let (lo, hi) = p.split(n);
        let neighbours = |r: usize| grid_neighbours(k, r);
        let mut offsets = vec![0];
        let mut adj = vec![];
        for r in lo..hi {
            adj.extend(neighbours(r));
            offsets.push(adj.len());
        }
        let parts = partition(p, &offsets, &adj, n).unwrap();
        assert_eq!(parts.len(), hi - lo);
        let parts: Vec<i32> = parts.iter().map(|&q| q as i32).collect();
        if let Some(all) = p.gather_i32(&parts).unwrap() {
            let ones = all.iter().filter(|&&q| q == 1).count();
            assert!(all.iter().all(|&q| q == 0 || q == 1));
            // Balanced within 5 %, and a cut of at most a few grid lines (a straight cut is k).
            assert!((ones as f64 - n as f64 / 2.0).abs() <= 0.05 * n as f64, "{ones} of {n}");
            let cut = (0..n)
                .flat_map(|r| neighbours(r).into_iter().map(move |c| (r, c)))
                .filter(|&(r, c)| all[r] != all[c])
                .count()
                / 2;
            assert!(cut <= 3 * k, "edge cut {cut} on a {k} x {k} grid");
        }
        // Bad graphs are refused by name.
        assert!(matches!(partition(p, &[0, 1], &[n], n), Err(PetscError::Argument(_))));
    });
}

/// The entries `(i, j, v)` of a quasi-definite matrix of order `k² + k`: the grid Laplacian
/// on the first `k²` unknowns, `-I - 0.1 L₁` (a 1D Laplacian) on the last `k`, coupled by
/// `0.3` between unknown `k² + i` and grid vertex `i (k + 1)`, the last block's diagonal
/// `last`: negative, symmetric and indefinite as the piezoelectric system is; positive, definite.
fn quasi_definite(k: usize, last: f64) -> (usize, Vec<(usize, usize, f64)>) {
    let (n1, n) = (k * k, k * k + k);
    let mut e = vec![];
    for r in 0..n1 {
        e.push((r, r, 4.0));
        for c in grid_neighbours(k, r) {
            e.push((r, c, -1.0));
        }
    }
    for i in 0..k {
        let r = n1 + i;
        e.push((r, r, last));
        if i + 1 < k {
            e.push((r, r + 1, 0.1));
            e.push((r + 1, r, 0.1));
        }
        let g = (i * (k + 1)) % n1;
        e.push((r, g, 0.3));
        e.push((g, r, 0.3));
    }
    (n, e)
}

/// `A x = b` by Gaussian elimination with partial pivoting (dense, row-major `A`).
fn dense_solve(n: usize, mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| a[x * n + c].abs().total_cmp(&a[y * n + c].abs()))
            .unwrap();
        for j in 0..n {
            a.swap(c * n + j, p * n + j);
        }
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for j in c..n {
                a[r * n + j] -= f * a[c * n + j];
            }
            b[r] -= f * b[c];
        }
    }
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|j| a[r * n + j] * b[j]).sum();
        b[r] = (b[r] - s) / a[r * n + r];
    }
    b
}

#[test]
fn mumps_factors_on_two_ranks_with_the_schur_complement_of_chosen_unknowns() {
    use petsc::{Mumps, Symmetry};
    on_ranks(
        "mumps_factors_on_two_ranks_with_the_schur_complement_of_chosen_unknowns",
        2,
        |p| {
            let k = 9;
            // every entry given by one rank, the diagonal's in halves by both (MUMPS sums them)
            let mine = |entries: &[(usize, usize, f64)], symmetric: bool| {
                let (mut r, mut c, mut v) = (vec![], vec![], vec![]);
                for (e, &(i, j, x)) in entries.iter().enumerate() {
                    if symmetric && i < j {
                        continue;
                    }
                    let (give, x) = if i == j {
                        (true, 0.5 * x)
                    } else {
                        (e % 2 == p.rank(), x)
                    };
                    if give {
                        r.push(i);
                        c.push(j);
                        v.push(x);
                    }
                }
                (r, c, v)
            };
            // the chosen unknowns: three grid vertices and two of the last block
            let chosen = [3, 40, 77, k * k + 1, k * k + 5];
            for symmetry in [
                Symmetry::Indefinite,
                Symmetry::QuasiDefinite,
                Symmetry::General,
                Symmetry::Definite,
            ] {
                let last = if symmetry == Symmetry::Definite { 1.2 } else { -1.2 };
                let (n, entries) = quasi_definite(k, last);
                let mut dense = vec![0.0; n * n];
                for &(i, j, v) in &entries {
                    dense[i * n + j] += v;
                }
                let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).cos()).collect();
                let exact = dense_solve(n, dense.clone(), b.clone());
                let (r, c, v) = mine(&entries, symmetry != Symmetry::General);
                // without a Schur complement: one solve
                let mut plain = Mumps::factor(p, n, (&r, &c, v.clone()), symmetry, &[], None, None).unwrap();
                let mut x = if p.rank() == 0 { b.clone() } else { vec![] };
                plain.solve(&mut x).unwrap();
                if p.rank() == 0 {
                    let err = x.iter().zip(&exact).map(|(a, e)| (a - e).abs()).fold(0.0, f64::max);
                    assert!(err < 1e-12, "{symmetry:?}: the solve is off by {err:.2e}");
                }
                // with one: S, the condensed right-hand side, the expansion
                let mut m = Mumps::factor(p, n, (&r, &c, v), symmetry, &chosen, None, None).unwrap();
                let mut rhs = if p.rank() == 0 { b.clone() } else { vec![] };
                let reduced = m.condense(&mut rhs).unwrap();
                let s = m.schur_complement().map(<[f64]>::to_vec);
                let x_s = match &s {
                    Some(s) => dense_solve(chosen.len(), s.clone(), reduced.clone()),
                    None => vec![],
                };
                m.expand(&mut rhs, &x_s).unwrap();
                // MUMPS keeps a condensation's forward half inside itself for the expansion
                // that follows it: a second expansion is refused, typed
                let mut again = rhs.clone();
                match m.expand(&mut again, &x_s) {
                    Err(PetscError::Mumps { info: -35, .. }) => {}
                    other => panic!("a second expansion: {:?}", other.map(|_| ())),
                }
                if p.rank() == 0 {
                    let s = s.expect("rank 0 holds the Schur complement");
                    // S is symmetric, and its inverse is the chosen block of K's inverse
                    for i in 0..chosen.len() {
                        for j in 0..chosen.len() {
                            let d = (s[i * chosen.len() + j] - s[j * chosen.len() + i]).abs();
                            assert!(d < 1e-12, "{symmetry:?}: S is not symmetric at ({i}, {j})");
                        }
                    }
                    for (jj, &j) in chosen.iter().enumerate() {
                        let mut e = vec![0.0; n];
                        e[j] = 1.0;
                        let col = dense_solve(n, dense.clone(), e);
                        let mut unit = vec![0.0; chosen.len()];
                        unit[jj] = 1.0;
                        let inv = dense_solve(chosen.len(), s.clone(), unit);
                        for (ii, &i) in chosen.iter().enumerate() {
                            assert!((inv[ii] - col[i]).abs() < 1e-12, "{symmetry:?}: (S⁻¹)[{ii}, {jj}]");
                        }
                    }
                    let err = rhs.iter().zip(&exact).map(|(a, e)| (a - e).abs()).fold(0.0, f64::max);
                    assert!(err < 1e-12, "{symmetry:?}: the solve in two halves is off by {err:.2e}");
                } else {
                    assert!(s.is_none() && reduced.is_empty());
                }
            }
            // a Schur complement of hundreds of unknowns (MUMPS fills its upper triangle only in
            // part): its inverse is the chosen block of K's inverse, K's columns by MUMPS alone
            let k = 30;
            let (n, entries) = quasi_definite(k, -1.2);
            let (r, c, v) = mine(&entries, true);
            let chosen: Vec<usize> = (0..n).filter(|i| i % 2 == 0).collect();
            // a pivot order given (the others first, reversed; the chosen last)
            let mut order: Vec<usize> = (0..n).rev().filter(|i| i % 2 == 1).collect();
            order.extend(&chosen);
            let mut plain = Mumps::factor(p, n, (&r, &c, v.clone()), Symmetry::Indefinite, &[], None, None).unwrap();
            let m = Mumps::factor(p, n, (&r, &c, v), Symmetry::Indefinite, &chosen, Some(&order), None).unwrap();
            let ks = chosen.len();
            for jj in [0, ks / 3, ks - 1] {
                let mut col = vec![0.0; n];
                col[chosen[jj]] = 1.0;
                plain.solve(&mut col).unwrap();
                if let Some(s) = m.schur_complement() {
                    let mut unit = vec![0.0; ks];
                    unit[jj] = 1.0;
                    let inv = dense_solve(ks, s.to_vec(), unit);
                    for (ii, &i) in chosen.iter().enumerate() {
                        assert!(
                            (inv[ii] - col[i]).abs() < 1e-12,
                            "a large Schur complement: ({ii}, {jj})"
                        );
                    }
                }
            }
            // a singular matrix: MUMPS' error, typed
            let (r, c) = (vec![0, 1], vec![0, 1]);
            let v = if p.rank() == 0 { vec![1.0, 0.0] } else { vec![0.0, 0.0] };
            match Mumps::factor(p, 2, (&r, &c, v), Symmetry::General, &[], None, None) {
                Err(PetscError::Mumps { info: -10, .. }) => {}
                Err(other) => panic!("expected MUMPS' singular matrix, got {other}"),
                Ok(_) => panic!("a singular matrix was factored"),
            }
            // more memory than a rank may use, by MUMPS' own estimate: refused before the
            // factorisation, the estimate the same on every rank
            let (n, entries) = quasi_definite(80, -1.0);
            let (r, c, v) = mine(&entries, true);
            let fits = Mumps::factor(p, n, (&r, &c, v.clone()), Symmetry::QuasiDefinite, &[], None, None).unwrap();
            let needed = fits.estimated_bytes();
            assert!(needed > 0, "MUMPS estimates its memory");
            let estimates = p.all_gather(needed).unwrap();
            assert!(estimates.iter().all(|&e| e == needed), "{estimates:?}");
            let limit = Some(needed - 1);
            match Mumps::factor(p, n, (&r, &c, v), Symmetry::QuasiDefinite, &[], None, limit) {
                Err(PetscError::MumpsTooLarge { needed: n, available }) => {
                    assert_eq!((n, available), (needed, needed - 1));
                }
                Err(other) => panic!("expected the estimate's refusal, got {other}"),
                Ok(_) => panic!("a factorisation past its memory was done"),
            }
            // the same data broadcast from rank 0
            let mut values = vec![p.rank() as f64; 3];
            p.broadcast(&mut values).unwrap();
            assert_eq!(values, vec![0.0; 3]);
        },
    );
}

/// `Vector::fetch` gives each rank the entries it asks for, wherever they are owned, in the
/// order asked (repeats and an empty request included); `Petsc::broadcast_bytes` gives rank 0's
/// bytes to every rank whatever their lengths were.
#[test]
fn each_rank_fetches_the_entries_it_asks_for_and_hears_rank_0s_bytes() {
    on_ranks(
        "each_rank_fetches_the_entries_it_asks_for_and_hears_rank_0s_bytes",
        2,
        |p| {
            let n = 11;
            let (lo, hi) = p.split(n);
            let mut v = Vector::mpi(p, hi - lo).unwrap();
            v.with_local_mut(|x| {
                for (k, e) in x.iter_mut().enumerate() {
                    *e = 10.0 * (lo + k) as f64;
                }
            })
            .unwrap();
            // every entry of the other ranks', backwards, then one of its own twice
            let asked: Vec<petsc::Index> = (0..n)
                .rev()
                .filter(|i| !(lo..hi).contains(i))
                .chain([lo, lo])
                .map(|i| i as petsc::Index)
                .collect();
            let got = v.fetch(&asked).unwrap();
            let expected: Vec<f64> = asked.iter().map(|&i| 10.0 * i as f64).collect();
            assert_eq!(got, expected);
            // a rank may ask for nothing while the others ask
            let none = if p.rank() == 1 {
                v.fetch(&[]).unwrap()
            } else {
                v.fetch(&[0]).unwrap()
            };
            assert_eq!(none.len(), usize::from(p.rank() != 1));
            let mut bytes = if p.rank() == 0 {
                b"/a/staging/dir".to_vec()
            } else {
                vec![7; 40]
            };
            p.broadcast_bytes(&mut bytes).unwrap();
            assert_eq!(bytes, b"/a/staging/dir");
        },
    );
}
