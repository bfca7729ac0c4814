//! The robustness study of the contact crate on the class of the hardest third-party problems:
//! random rigid multibody problems (`contact::siconos::FrictionProblem::multibody`, rank
//! deficient `W`), 2D and 3D, each solved by the default semismooth Newton to a tolerance.
//! Prints one line per problem that needed more than Newton, and a summary: problems solved,
//! median and total time, and the stages used. `--dump DIR` writes the problems in Siconos'
//! text format instead, for Siconos' own solvers (`bench/siconos/solve.py`).
//!
//! ```text
//! cargo run --release -p contact --example multibody -- [--seeds 100] [--scale 1] [--tol 1e-8] [--measure siconos|crate] [--dump DIR]
//! ```
//! Problem `seed` has `scale·(2 + seed mod 7)` bodies and `scale·(2 + 7 seed mod 23)` contacts.
//! `--one DIM,BODIES,CONTACTS` solves one problem of that size instead (seed 1), with its
//! progress, time and the process's peak memory: `--one 2,3000,7002` is the size of the
//! largest granular problem of Siconos' set (14,004 rows).

use contact::siconos::FrictionProblem;
use contact::{Interrupt, Law, Measure, NewtonParams};
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let seeds: u64 = value("--seeds").map_or(100, |v| v.parse().expect("--seeds N"));
    let scale: usize = value("--scale").map_or(1, |v| v.parse().expect("--scale K"));
    let tol: f64 = value("--tol").map_or(1e-8, |v| v.parse().expect("--tol T"));
    let measure = match value("--measure").as_deref() {
        Some("crate") => Measure::Complementarity,
        _ => Measure::DeSaxce,
    };
    let dump = value("--dump");
    if let Some(one) = value("--one") {
        let v: Vec<usize> = one
            .split(',')
            .map(|x| x.parse().expect("--one DIM,BODIES,CONTACTS"))
            .collect();
        let start = Instant::now();
        let p = FrictionProblem::multibody(v[0], v[1], v[2], 1);
        println!(
            "{} rows, {} stored entries of W, made in {:.2} s",
            p.q.len(),
            p.w.compute_nnz(),
            start.elapsed().as_secs_f64()
        );
        if let Some(dir) = &dump {
            let name = format!("{dir}/mb-{}d-s1-b{}-c{}.dat", v[0], v[1], v[2]);
            std::fs::write(&name, p.to_text()).expect("a writable --dump directory");
            println!("wrote {name}");
            return;
        }
        let params = NewtonParams {
            tol,
            measure,
            schedule: contact::Schedule::of(contact::ProblemClass::Multibody),
            ..Default::default()
        };
        let start = Instant::now();
        let mut progress = |g: &contact::Progress| println!("  {} {} {:.3e}", g.stage.name(), g.iter, g.residual);
        let sol = contact::solve_newton(
            &mut p.sparse_problem(),
            &p.points(),
            &Law::Coulomb,
            &params,
            None,
            &mut progress,
        );
        let peak = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM")).map(str::to_string))
            .unwrap_or_default();
        match sol {
            Ok(s) => println!(
                "solved in {:.2} s: {} Newton, {} proximal, Siconos error {:.2e}; {peak}",
                start.elapsed().as_secs_f64(),
                s.info.newton_iters,
                s.info.proximal_iters,
                p.error(&p.reaction(&s.lambda))
            ),
            Err(e) => println!("FAILED after {:.2} s: {e}; {peak}", start.elapsed().as_secs_f64()),
        }
        return;
    }
    let (mut solved, mut times, mut proximal, mut fallback) = (0, vec![], 0, 0);
    for seed in 0..seeds {
        for dim in [2, 3] {
            let bodies = scale * (2 + (seed as usize % 7));
            let contacts = scale * (2 + (seed as usize * 7 % 23));
            let p = FrictionProblem::multibody(dim, bodies, contacts, seed);
            let name = format!("mb-{dim}d-s{seed}-b{bodies}-c{contacts}");
            if let Some(dir) = &dump {
                std::fs::write(format!("{dir}/{name}.dat"), p.to_text()).expect("a writable --dump directory");
                continue;
            }
            let params = NewtonParams {
                tol,
                measure,
                schedule: contact::Schedule::of(contact::ProblemClass::Multibody),
                interrupt: Interrupt {
                    deadline: Some(Instant::now() + Duration::from_secs(60)),
                    cancel: None,
                },
                ..Default::default()
            };
            let start = Instant::now();
            let result = contact::solve_newton(
                &mut p.sparse_problem(),
                &p.points(),
                &Law::Coulomb,
                &params,
                None,
                &mut |_| {},
            );
            let t = start.elapsed().as_secs_f64();
            times.push(t);
            match result {
                Ok(s) => {
                    solved += 1;
                    proximal += usize::from(s.info.proximal_iters > 0);
                    fallback += usize::from(s.info.fallback);
                    if s.info.fallback || t > 1.0 {
                        println!(
                            "{name}: {} Newton, {} proximal, fallback {} ({} sweeps), {t:.3} s",
                            s.info.newton_iters,
                            s.info.proximal_iters,
                            s.info.fallback,
                            s.info.uzawa_iters + s.info.sweeps
                        );
                    }
                }
                Err(e) => println!("{name}: FAILED {e} ({t:.3} s)"),
            }
        }
    }
    if dump.is_none() {
        times.sort_by(f64::total_cmp);
        let median = times.get(times.len() / 2).copied().unwrap_or(0.0);
        println!(
            "solved {solved} of {}: {proximal} needed the proximal stage, {fallback} the fallback; median {median:.4} s, total {:.2} s",
            times.len(),
            times.iter().sum::<f64>()
        );
    }
}
