//! Benchmark of the contact solvers against the linear floor (issue: the contact problem for
//! about the cost of one linear solve). Two modes, each printing a Markdown table and writing a
//! CSV next to it:
//!
//! - `floor SCENE N...`: for each size, the same scene with `contact.law=none` (one assembly,
//!   one factorisation, one solve: the linear floor) and each strategy to a complementarity
//!   residual of 1e-10, interleaved in one process and repeated (medians), with the ratio of
//!   each strategy's time to the floor's;
//! - `error SCENE N`: error of the multipliers against run time for each strategy over a range
//!   of tolerances, the error measured against the same mesh solved by semismooth Newton to a
//!   residual of 1e-14 (the algebraic error).
//!
//! Times are `run.json`'s `timings_s.total` (set-up to solution, outputs not written).
//!
//!   cargo run --release -p driver --example bench_contact -- floor paper 64 128 256 512
//!   cargo run --release -p driver --example bench_contact -- error paper 64
//!   options: --strategies a,b,c  --repeats R  --tols 1e-2,1e-4  --csv FILE

use problem::Solution;
use std::fmt::Write as _;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn run(scene: &str, sets: &[String]) -> Result<Solution, String> {
    driver::studies::solve(scene, sets).map_err(|e| e.to_string())
}

fn total(r: &Solution) -> f64 {
    r.report.timings_s.total
}

/// The weighted multipliers `√w λ` in one vector (normal, then tangential).
fn weighted_lambda(r: &Solution) -> Vec<f64> {
    let Some(c) = &r.contact else {
        return vec![];
    };
    let (lambda, w) = (&c.solution.lambda, &c.points.weight);
    let nt = lambda.n_tangential();
    let mut v: Vec<f64> = lambda.normal.iter().zip(w).map(|(l, w)| l * w.sqrt()).collect();
    for (j, l) in lambda.tangential.iter().enumerate() {
        v.push(l * w[j / nt.max(1)].sqrt());
    }
    v
}

fn relative_error(a: &[f64], reference: &[f64]) -> f64 {
    let d: f64 = a
        .iter()
        .zip(reference)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt();
    let n: f64 = reference.iter().map(|x| x * x).sum::<f64>().sqrt();
    d / n
}

struct Options {
    strategies: Vec<String>,
    repeats: usize,
    tols: Vec<f64>,
    csv: Option<String>,
    rest: Vec<String>,
}

fn options(args: &[String]) -> Options {
    let mut o = Options {
        strategies: ["newton-condensed", "apg-condensed", "uzawa-condensed"]
            .map(String::from)
            .to_vec(),
        repeats: 3,
        tols: vec![1e-2, 1e-4, 1e-6, 1e-8, 1e-10],
        csv: None,
        rest: vec![],
    };
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--strategies" => {
                o.strategies = args[i + 1].split(',').map(String::from).collect();
                i += 1;
            }
            "--repeats" => {
                o.repeats = args[i + 1].parse().expect("--repeats R");
                i += 1;
            }
            "--tols" => {
                o.tols = args[i + 1].split(',').map(|t| t.parse().expect("--tols")).collect();
                i += 1;
            }
            "--csv" => {
                o.csv = Some(args[i + 1].clone());
                i += 1;
            }
            _ => o.rest.push(args[i].clone()),
        }
        i += 1;
    }
    o
}

fn floor(scene: &str, sizes: &[usize], o: &Options) -> (String, String) {
    let mut md = String::from("| n | dofs | contact points | linear floor (s) | strategy | iterations | time (s) | ratio to floor | residual |\n|---|---|---|---|---|---|---|---|---|\n");
    let mut csv = String::from("scene,n,dofs,points,floor_s,strategy,iterations,time_s,ratio,residual\n");
    for &n in sizes {
        let size = format!("mesh.n={n}");
        let mut floors = vec![];
        let mut times: Vec<Vec<f64>> = vec![vec![]; o.strategies.len()];
        let mut last: Vec<Option<Solution>> = (0..o.strategies.len()).map(|_| None).collect();
        let mut dofs = 0;
        for _ in 0..o.repeats {
            let f = run(scene, &[size.clone(), "contact.law=none".into()]).expect("linear floor");
            dofs = f.report.dofs.total();
            floors.push(total(&f));
            for (k, s) in o.strategies.iter().enumerate() {
                match run(
                    scene,
                    &[size.clone(), format!("solver.strategy={s}"), "solver.tol=1e-10".into()],
                ) {
                    Ok(r) => {
                        times[k].push(total(&r));
                        last[k] = Some(r);
                    }
                    Err(e) => eprintln!("{scene} n = {n} {s}: {e}"),
                }
            }
        }
        let fl = median(floors);
        eprintln!("{scene} n = {n}: floor {fl:.3} s");
        for (k, s) in o.strategies.iter().enumerate() {
            let Some(r) = &last[k] else {
                let _ = writeln!(md, "| {n} | {dofs} | | {fl:.3} | {s} | failed | | | |");
                continue;
            };
            let t = median(times[k].clone());
            let points = r.report.contact.n_points;
            let res = r.report.residuals.complementarity;
            let it = r.report.iterations.summary();
            eprintln!("  {s:18} {it:>16}  {t:8.3} s  ratio {:.2}", t / fl);
            let _ = writeln!(
                md,
                "| {n} | {dofs} | {points} | {fl:.3} | {s} | {it} | {t:.3} | {:.2} | {res:.1e} |",
                t / fl
            );
            let _ = writeln!(csv, "{scene},{n},{dofs},{points},{fl},{s},{it},{t},{},{res}", t / fl);
        }
    }
    (md, csv)
}

fn error(scene: &str, n: usize, o: &Options) -> (String, String) {
    let size = format!("mesh.n={n}");
    let reference = run(
        scene,
        &[
            size.clone(),
            "solver.strategy=newton-condensed".into(),
            "solver.tol=1e-14".into(),
        ],
    )
    .expect("reference run");
    let lref = weighted_lambda(&reference);
    let mut md = String::from("| n | strategy | tolerance | iterations | time (s) | error of lambda | residual |\n|---|---|---|---|---|---|---|\n");
    let mut csv = String::from("scene,n,strategy,tol,iterations,time_s,lambda_error,residual\n");
    for s in &o.strategies {
        for &tol in &o.tols {
            let mut ts = vec![];
            let mut last = None;
            for _ in 0..o.repeats {
                match run(
                    scene,
                    &[
                        size.clone(),
                        format!("solver.strategy={s}"),
                        format!("solver.tol={tol:e}"),
                    ],
                ) {
                    Ok(r) => {
                        ts.push(total(&r));
                        last = Some(r);
                    }
                    Err(e) => eprintln!("{scene} n = {n} {s} tol {tol:e}: {e}"),
                }
            }
            let Some(r) = last else { continue };
            let t = median(ts);
            let err = relative_error(&weighted_lambda(&r), &lref);
            let res = r.report.residuals.complementarity;
            let it = r.report.iterations.summary();
            eprintln!("  {s:18} tol {tol:7.0e} {it:>16}  {t:8.3} s  error {err:.2e}");
            let _ = writeln!(md, "| {n} | {s} | {tol:.0e} | {it} | {t:.3} | {err:.2e} | {res:.1e} |");
            let _ = writeln!(csv, "{scene},{n},{s},{tol:e},{it},{t},{err},{res}");
        }
    }
    (md, csv)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let o = options(&args);
    let (mode, scene) = (o.rest.first().cloned(), o.rest.get(1).cloned());
    let sizes: Vec<usize> = o.rest.iter().skip(2).map(|s| s.parse().expect("a mesh size")).collect();
    let (md, csv) = match (mode.as_deref(), scene) {
        (Some("floor"), Some(scene)) if !sizes.is_empty() => floor(&scene, &sizes, &o),
        (Some("error"), Some(scene)) if sizes.len() == 1 => error(&scene, sizes[0], &o),
        _ => {
            eprintln!("usage: bench_contact floor SCENE N... | error SCENE N  [--strategies a,b] [--repeats R] [--tols t,..] [--csv FILE]");
            std::process::exit(2);
        }
    };
    println!("{md}");
    println!(
        "peak memory of the process: {} MiB",
        files::run::peak_memory_bytes() >> 20
    );
    if let Some(path) = o.csv {
        std::fs::write(&path, csv).expect("write the CSV");
    }
}
