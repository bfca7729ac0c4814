//! Compares fill-reducing orderings of `K` on the paper geometry: faer's AMD on the dofs against
//! geometric nested dissection on the nodes (expanded to dofs). Prints, for one n: ordering,
//! factor entries, symbolic, numeric and solve seconds (median of 3).
//!
//!   cargo run --release -p driver --example bench_ordering -- 256

mod common;

use fe_assembly::{Discretization, Parallelism};
use linalg::{FactorKind, Ordering, SparseFactor};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(128);
    let name = std::env::args().nth(2).unwrap_or_else(|| "paper".into());
    let problem::backend::Setup {
        mesh,
        materials: mats,
        constraints: bcs,
        ..
    } = common::setup_without_contact(&name, n);
    let disc = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &mats, &bcs).expect("setup");
    let b = disc.assemble(Parallelism::Rayon);
    let k = linalg::sparse::lower_quasi_definite(b.a.as_ref(), b.g.as_ref(), b.b.as_ref());
    let t = Instant::now();
    let nd = disc.dofs.expand_node_order(&mesh.nested_dissection());
    let t_nd = t.elapsed().as_secs_f64();
    println!("n = {n}: nested dissection order computed in {t_nd:.3} s");
    let bottom = mesh.boundary("bottom").expect("paper has a bottom").nodes();
    let dim = mesh.dim;
    let contact_dofs: Vec<usize> = bottom
        .iter()
        .flat_map(|&v| (0..dim).map(move |k| (v, k)))
        .filter_map(|(v, k)| match disc.dofs.u[v * dim + k] {
            fe_assembly::Dof::Free(j)
                if (0..dim).all(|q| matches!(disc.dofs.u[v * dim + q], fe_assembly::Dof::Free(_))) =>
            {
                Some(j)
            }
            _ => None,
        })
        .collect();
    let mut is_last = vec![false; k.nrows()];
    for &j in &contact_dofs {
        is_last[j] = true;
    }
    let mut nd_last: Vec<usize> = nd.iter().copied().filter(|&j| !is_last[j]).collect();
    nd_last.extend_from_slice(&contact_dofs);
    for (name, ord) in [
        ("amd", Ordering::Amd),
        ("nested-dissection", Ordering::Given(nd)),
        ("nd-contact-last", Ordering::Given(nd_last)),
        ("amd-contact-last", Ordering::AmdThenLast(contact_dofs)),
    ] {
        let (mut sym, mut num, mut sol) = (vec![], vec![], vec![]);
        let (mut len, mut flops) = (0, 0.0);
        for _ in 0..std::env::var("REPEATS").ok().and_then(|s| s.parse().ok()).unwrap_or(3) {
            let t = Instant::now();
            let mut f = SparseFactor::new(k.as_ref(), FactorKind::Ldlt, &ord, faer::Par::Seq).expect("ldlt");
            let both = t.elapsed().as_secs_f64();
            let t = Instant::now();
            f.refactor(k.as_ref()).expect("refactor");
            let nu = t.elapsed().as_secs_f64();
            num.push(nu);
            sym.push((both - nu).max(0.0));
            let mut x = vec![1.0; k.nrows()];
            let t = Instant::now();
            f.solve_in_place(&mut x);
            sol.push(t.elapsed().as_secs_f64());
            len = f.factor_len();
            flops = f.factor_flops();
        }
        let nu = median(num.clone());
        println!(
            "{name:18} factor entries {len:>10}  symbolic {:.3} s  numeric {nu:.3} s ({:.2} GFlop, {:.2} GFlop/s)  solve {:.3} s",
            median(sym),
            flops / 1e9,
            flops / 1e9 / nu,
            median(sol)
        );
    }
}
