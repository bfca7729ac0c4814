//! The linear floor of a scene's matrix without contact (`K` of `[u; φ]`, symmetric
//! quasi-definite): analysis (the nested-dissection order and the symbolic factorisation),
//! numeric `L D Lᵀ` and one solve with faer, as the default backend does them, on rayon's pool
//! (`RAYON_NUM_THREADS`): the order, and the factor's elimination tree. Writes the matrix (its lower triangle, Matrix
//! Market, 1-based) and a right-hand side for the comparators of `bench/direct/compare.py`, and
//! prints one line `faer analysis A factor F solve S residual R` per repeat. With a fifth
//! argument `last=GROUP`, the free displacements of that boundary group's nodes are ordered
//! last, as a condensed contact strategy orders its contact dofs (the run's own factorisation:
//! a root supernode as wide as the contact surface and the separator above it).
//!
//!   cargo run --release -p driver --example bench_direct -- 256 paper out/bench-direct [repeats] [last=GROUP]

mod common;

use fe_assembly::{Discretization, Parallelism};
use linalg::{FactorKind, Ordering, SparseFactor};
use std::io::Write;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let name = args.get(2).cloned().unwrap_or_else(|| "paper".into());
    let dir = std::path::PathBuf::from(args.get(3).cloned().unwrap_or_else(|| "out/bench-direct".into()));
    let repeats: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(3);
    let last_group = args.get(5).and_then(|s| s.strip_prefix("last="));
    let problem::backend::Setup {
        mesh,
        materials,
        constraints,
        ..
    } = common::setup_without_contact(&name, n);
    let disc = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &materials, &constraints)
        .expect("discretisation");
    let b = disc.assemble(Parallelism::Rayon);
    let k = linalg::sparse::lower_quasi_definite(b.a.as_ref(), b.g.as_ref(), b.b.as_ref());
    let last = last_group.map(|group| group_displacements(&mesh, &disc.dofs, group));
    let rhs: Vec<f64> = (0..k.nrows()).map(|i| 1.0 + (i % 7) as f64 * 0.1).collect();
    std::fs::create_dir_all(&dir).expect("the output directory");
    write_market(&dir.join("K.mtx"), &k).expect("K.mtx");
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("b.txt")).expect("b.txt"));
    for v in &rhs {
        writeln!(f, "{v:e}").expect("b.txt");
    }
    drop(f);
    println!(
        "matrix {} x {}, {} entries in its lower triangle",
        k.nrows(),
        k.ncols(),
        k.compute_nnz()
    );
    for _ in 0..repeats {
        let t = Instant::now();
        let order = disc.dofs.expand_node_order(&mesh.nested_dissection());
        let ordering = match &last {
            Some(last) => Ordering::GivenThenLast {
                order,
                last: last.clone(),
            },
            None => Ordering::Given(order),
        };
        let mut factor = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ordering, linalg::pool_par()).expect("ldlt");
        let both = t.elapsed().as_secs_f64();
        let t = Instant::now();
        factor.refactor(k.as_ref()).expect("refactor");
        let numeric = t.elapsed().as_secs_f64();
        let mut x = rhs.clone();
        let t = Instant::now();
        factor.solve_in_place(&mut x);
        let solve = t.elapsed().as_secs_f64();
        // the analysis: the order and the symbolic factorisation (what `new` did beyond one
        // numeric factorisation)
        let analysis = (both - numeric).max(0.0);
        println!(
            "faer analysis {analysis:.4} factor {numeric:.4} solve {solve:.4} residual {:.2e} values {:.1} MB",
            residual(&k, &x, &rhs),
            factor.values_bytes() as f64 / 1e6
        );
    }
}

/// The free displacement dofs of the nodes of boundary group `group`, in node order.
fn group_displacements(mesh: &mesh::Mesh, dofs: &fe_assembly::DofMap, group: &str) -> Vec<usize> {
    mesh.boundary(group)
        .unwrap_or_else(|e| panic!("last={group}: {e}"))
        .nodes()
        .into_iter()
        .flat_map(|p| (0..dofs.dim).map(move |k| p * dofs.dim + k))
        .filter_map(|i| match dofs.u[i] {
            fe_assembly::Dof::Free(d) => Some(d),
            _ => None,
        })
        .collect()
}

/// `|K x - b| / |b|` with `K` given by its lower triangle.
fn residual(k: &faer::sparse::SparseColMat<usize, f64>, x: &[f64], b: &[f64]) -> f64 {
    let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
    for j in 0..k.ncols() {
        for (i, v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
            r[i] += v * x[j];
            if i != j {
                r[j] += v * x[i];
            }
        }
    }
    linalg::norm(&r) / linalg::norm(b)
}

/// The lower triangle of `k` as a Matrix Market coordinate file (`symmetric`, 1-based).
fn write_market(path: &std::path::Path, k: &faer::sparse::SparseColMat<usize, f64>) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "%%MatrixMarket matrix coordinate real symmetric")?;
    writeln!(f, "{} {} {}", k.nrows(), k.ncols(), k.compute_nnz())?;
    for j in 0..k.ncols() {
        for (i, v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
            writeln!(f, "{} {} {v:e}", i + 1, j + 1)?;
        }
    }
    f.flush()
}
