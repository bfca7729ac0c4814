//! Benchmark of the linear part on the `paper` geometry (issue: foundation): for one mesh size
//! per process (so that the peak memory is that size's), the median over `REPEATS` runs of
//! assembly, symbolic and numeric L D Lᵀ, one solve, the Schur PCG (Cholesky of A and B, PCG
//! iterations to 1e-10, solve time), and the difference between the two answers.
//!
//! Sample runs:
//!   cargo run --release -p driver --example bench_linear -- 256
//!   cargo xtask bench          (n = 64, 128, 256, 512, one process each)

use fe_assembly::{Discretization, Parallelism};
use linalg::{CoupledSolver, FactorKind, Ordering, PcgParams, SchurPcg, SparseFactor};
use std::time::Instant;

const REPEATS: usize = 3;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(64);
    let (scene, _) =
        files::scene_file::load("paper", &[format!("mesh.n={n}"), "contact.law=none".into()]).expect("paper scene");
    let problem::backend::Setup {
        mesh,
        materials: mats,
        constraints: bcs,
        loads,
        ..
    } = problem::backend::setup(scene.validate().expect("a valid scene"), None).expect("setup");
    let (mut t_asm, mut t_sym, mut t_num, mut t_solve, mut t_chol, mut t_pcg) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    let mut iters = 0;
    let mut diff = 0.0;
    let mut dofs = (0, 0);
    for _ in 0..REPEATS {
        let t = Instant::now();
        let disc = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &mats, &bcs).expect("setup");
        let blocks = disc.assemble(Parallelism::Rayon);
        let (bu, bp) = disc.rhs(&loads).expect("rhs");
        t_asm.push(t.elapsed().as_secs_f64());
        dofs = (disc.dofs.n_u, disc.dofs.n_phi);
        // direct: symbolic + numeric, then numeric again alone
        let k = linalg::sparse::lower_quasi_definite(blocks.a.as_ref(), blocks.g.as_ref(), blocks.b.as_ref());
        let t = Instant::now();
        let mut f = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &Ordering::Amd, faer::Par::Seq).expect("ldlt");
        let both = t.elapsed().as_secs_f64();
        let t = Instant::now();
        f.refactor(k.as_ref()).expect("refactor");
        let num = t.elapsed().as_secs_f64();
        t_num.push(num);
        t_sym.push((both - num).max(0.0));
        let mut x: Vec<f64> = bu.iter().chain(&bp).copied().collect();
        let t = Instant::now();
        f.solve_in_place(&mut x);
        t_solve.push(t.elapsed().as_secs_f64());
        // Schur PCG
        let t = Instant::now();
        let params = PcgParams {
            rel_tol: 1e-10,
            max_iters: 1000,
            ..Default::default()
        };
        let mut s =
            SchurPcg::new(blocks.a.clone(), blocks.g.clone(), &blocks.b, params, faer::Par::Seq).expect("schur");
        t_chol.push(t.elapsed().as_secs_f64());
        let (mut u, mut p) = (vec![0.0; dofs.0], vec![0.0; dofs.1]);
        let t = Instant::now();
        iters = s.solve(&bu, &bp, &mut u, &mut p).expect("pcg").pcg_iters;
        t_pcg.push(t.elapsed().as_secs_f64());
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        diff = x
            .iter()
            .zip(u.iter().chain(&p))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale;
    }
    println!(
        "{n},{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{},{:.4},{:.2e},{:.1}",
        dofs.0,
        dofs.1,
        median(t_asm),
        median(t_sym),
        median(t_num),
        median(t_solve),
        median(t_chol),
        iters,
        median(t_pcg),
        diff,
        files::run::peak_memory_bytes() as f64 / 1048576.0
    );
}
