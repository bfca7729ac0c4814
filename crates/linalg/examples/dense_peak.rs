//! The dense peak the factorisation's rate is measured against: faer's matrix product
//! `C = A B` of `n x n` doubles (default 3000) on rayon's pool (`RAYON_NUM_THREADS`, else the
//! cores), the median of 5 products after one to warm up, in GFlop/s (`2 n³` operations each).
//!
//!   cargo run --release -p linalg --example dense_peak -- [n]
use faer::{Accum, Mat, Par};
use std::time::Instant;

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(3000);
    let threads = rayon::current_num_threads();
    let a = Mat::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 13) % 17) as f64 / 17.0 - 0.5);
    let b = Mat::<f64>::from_fn(n, n, |i, j| ((i * 11 + j * 5) % 19) as f64 / 19.0 - 0.5);
    let mut c = Mat::<f64>::zeros(n, n);
    let mut rates = vec![];
    for k in 0..6 {
        let t = Instant::now();
        faer::linalg::matmul::matmul(
            c.as_mut(),
            Accum::Replace,
            a.as_ref(),
            b.as_ref(),
            1.0,
            Par::rayon(threads),
        );
        let seconds = t.elapsed().as_secs_f64();
        if k > 0 {
            rates.push(2.0 * (n as f64).powi(3) / seconds / 1e9);
        }
    }
    rates.sort_by(f64::total_cmp);
    println!(
        "faer matmul n = {n} on {threads} threads: {:.1} GFlop/s (median of 5; {:.1} .. {:.1})",
        rates[2], rates[0], rates[4]
    );
}
