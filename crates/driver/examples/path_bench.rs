//! A load path's cost against one static run of the same scene, side by side in one process:
//! `cargo run --release -p driver --example path_bench -- paper-cycle 256 100` (scene, mesh.n,
//! steps; the static run is the scene without its path, at its last instant's factors). Prints
//! the medians of 3 interleaved runs of each, their ratio, and the path's own split (steps,
//! factorisation), without writing files.
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("paper-cycle", String::as_str);
    let n: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(256);
    let steps: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(100);
    let sets = [format!("mesh.n={n}"), format!("path.steps={}", steps - 1)];
    let (scene, _) = files::scene_file::load(name, &sets).expect("the scene loads");
    let mut stat = scene.clone();
    stat.path = None;
    let (mut tp, mut ts, mut split) = (vec![], vec![], (0.0, 0.0));
    for _ in 0..3 {
        let t = Instant::now();
        let s = problem::solve(&stat, None, &mut problem::Silent).expect("the static run solves");
        ts.push(t.elapsed().as_secs_f64());
        drop(s);
        let t = Instant::now();
        let p = problem::solve_path(
            &scene,
            None,
            problem::Limits::default(),
            &mut problem::Silent,
            false,
            &mut |_| Ok(()),
        )
        .expect("the path solves");
        tp.push(t.elapsed().as_secs_f64());
        let r = &p.last.report;
        split = (r.path.as_ref().map_or(0.0, |p| p.steps_s), r.timings_s.factorization);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (mp, ms) = (median(&mut tp), median(&mut ts));
    println!(
        "{name} n = {n}: static {ms:.3} s, path of {steps} instants {mp:.3} s (steps {:.3} s, factorisation {:.3} s): ratio {:.2}",
        split.0,
        split.1,
        mp / ms
    );
}
