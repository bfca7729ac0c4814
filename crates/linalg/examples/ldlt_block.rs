//! faer's dense `L D Lᵀ` of an `n x n` matrix laid out as a supernode's values are (column-major,
//! the column stride exactly `n`), with several panel widths, on rayon's pool or on one core:
//! the measurement behind `tree`'s `WIDE_PANEL` (docs/performance.md). Prints one line
//! `n N threads T panel P S s` per width.
//!
//!   cargo run --release -p linalg --example ldlt_block -- 10630 2 128,512

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LdltParams, LdltRegularization,
};
use faer::{Mat, MatMut, Par, Spec};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(4096);
    let threads: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let panels: Vec<usize> = args
        .get(3)
        .map_or("128,512", String::as_str)
        .split(',')
        .filter_map(|s| s.parse().ok())
        .collect();
    let par = if threads > 1 { Par::rayon(threads) } else { Par::Seq };
    // a symmetric positive definite matrix: a rank-64 Gram matrix and a diagonal shift
    let x = Mat::<f64>::from_fn(n, 64, |i, j| ((i * 7 + j * 13) % 17) as f64 / 17.0 - 0.5);
    let gram = &x * x.transpose();
    for &panel in &panels {
        let mut values = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                values[j * n + i] = gram[(i, j)] + if i == j { 0.1 * n as f64 } else { 0.0 };
            }
        }
        let a = MatMut::from_column_major_slice_mut(&mut values, n, n);
        let mut params = Spec::<LdltParams, f64>::default();
        params.block_size = panel;
        let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(n, par, params));
        let t = Instant::now();
        cholesky_in_place(a, LdltRegularization::default(), par, MemStack::new(&mut mem), params)
            .expect("a positive definite matrix");
        println!(
            "n {n} threads {threads} panel {panel} {:.3} s",
            t.elapsed().as_secs_f64()
        );
    }
}
