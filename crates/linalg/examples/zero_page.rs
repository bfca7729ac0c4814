//! Fresh zeroed memory filled on rayon's pool by adding to it (`+=`, the first touch of a page
//! a read) against writing it first (`fill(0.0)`, then adding): the measurement behind the
//! writes-first of the assembly's values, `K`'s lower triangle and the coarse contact problem
//! (docs/performance.md, "The zero page"). A fresh page read first maps the kernel's shared
//! zero page; the write after it faults again, and replacing the mapping flushes it from the
//! TLB of every other core that runs the process (an interrupt to each, an exit from a VM).
//! Prints one line per round: `MB, threads, read first s, written first s`.
//!
//!   RAYON_NUM_THREADS=2 cargo run --release -p linalg --example zero_page -- 80 5

use rayon::prelude::*;
use std::time::Instant;

/// Fills `len` fresh values by rows of `row`, each value added to; `write_first`: each row
/// written with zeros first. Returns the seconds it took, allocation included.
fn fill(len: usize, row: usize, write_first: bool) -> f64 {
    let t = Instant::now();
    let mut v = vec![0.0f64; len];
    v.par_chunks_mut(row).enumerate().for_each(|(r, out)| {
        if write_first {
            out.fill(0.0);
        }
        for (i, x) in out.iter_mut().enumerate() {
            *x += (r + i) as f64;
        }
    });
    // one read per page, so that the work is not optimised away
    std::hint::black_box(v.iter().step_by(512).sum::<f64>());
    t.elapsed().as_secs_f64()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mb: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(80);
    let rounds: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    // rows of a contact problem's width (paper-3d n = 32: 6237 contact dofs)
    let row = 6237;
    let len = (mb << 20) / 8 / row * row;
    for _ in 0..rounds {
        let (read, write) = (fill(len, row, false), fill(len, row, true));
        println!(
            "{} MB on a pool of {}: read first {read:.3} s, written first {write:.3} s",
            (len * 8) >> 20,
            rayon::current_num_threads()
        );
    }
}
