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
