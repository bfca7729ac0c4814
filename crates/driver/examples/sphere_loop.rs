//! The friction loop of `mindlin-sphere-cycle` against Mindlin and Deresiewicz's closed form,
//! over mesh sizes and numbers of path steps: the table of docs/theory.md ("Load paths").
//!
//!   cargo run --release -p driver --example sphere_loop -- 8,12,16,20,24 24,96,192 [ORDER]
//!
//! (`ORDER` the elements' order, `mesh.order`: 1 by default, 2 for quadratic ones.) Further
//! arguments are overrides of the scene, as `--set` takes them (`mesh.kind="gmsh"
//! mesh.file="box.msh"`: a mesh of one's own, whose size `n` then only labels the row).

fn list(arg: Option<String>, default: &str) -> Vec<usize> {
    arg.unwrap_or_else(|| default.into())
        .split(',')
        .map(|s| s.trim().parse().expect("a list of whole numbers, 8,12,16"))
        .collect()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let sizes = list(args.next(), "8,12,16,20,24");
    let steps = list(args.next(), "24,96");
    let order: usize = args.next().map_or(1, |o| o.parse().expect("an order, 1 or 2"));
    let extra: Vec<String> = args.collect();
    println!("| n | steps | loop area | Mindlin-Deresiewicz | error | P | Q* | Q at t = 0 | s |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for &n in &sizes {
        for &s in &steps {
            let t = std::time::Instant::now();
            let mut sets = vec![
                format!("mesh.n={n}"),
                format!("mesh.order={order}"),
                format!("path.steps={s}"),
            ];
            sets.extend(extra.iter().cloned());
            match driver::studies::loops::sphere_loop_with(&sets) {
                Ok(f) => println!(
                    "| {n} | {s} | {:.4e} | {:.4e} | {:+.2} % | {:.4e} | {:.4e} | {:.3e} | {:.1} |",
                    f.area,
                    f.closed_form,
                    100.0 * (f.area - f.closed_form) / f.closed_form,
                    f.normal_force,
                    f.amplitude,
                    f.offset,
                    t.elapsed().as_secs_f64()
                ),
                Err(e) => println!("| {n} | {s} | error: {e} ||||||"),
            }
        }
    }
}
