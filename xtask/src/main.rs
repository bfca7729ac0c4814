//! Project automation: `cargo xtask verify [--full]` (fmt, clippy, tests, docs, the
//! verification report in docs/verification.md) and `cargo xtask bench`
//! (the linear benchmark on the paper geometry), `cargo xtask metrics` (lines per crate, the
//! longest functions). Kept free of dependencies.

mod metrics;

use std::process::{Command, ExitCode};

fn cargo(args: &[&str], env: &[(&str, &str)]) -> bool {
    eprintln!("$ cargo {}", args.join(" "));
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.status().map(|s| s.success()).unwrap_or(false)
}

/// fmt, clippy, the tests (the tidy test among them), rustdoc, then the verification report:
/// a smoke run of every shipped scene and the convergence studies, written to
/// docs/verification.md (`full`: to the finest meshes).
fn verify(full: bool) -> bool {
    let mut report = vec!["run", "--release", "-p", "driver", "--", "verification"];
    if full {
        report.push("--full");
    }
    // the tests in release mode share their compiled dependencies with the report's release
    // build (the test profile would compile everything a third time: 8 minutes on 2 cores)
    cargo(&["fmt", "--all", "--", "--check"], &[])
        && cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"], &[])
        && cargo(&["test", "--workspace", "--release"], &[])
        && cargo(&["doc", "--workspace", "--no-deps"], &[("RUSTDOCFLAGS", "-D warnings")])
        && cargo(&report, &[])
}

fn bench(sizes: &[String]) -> bool {
    if !cargo(
        &["build", "--release", "-p", "driver", "--example", "bench_linear"],
        &[],
    ) {
        return false;
    }
    println!("n,dofs_u,dofs_phi,assembly_s,ldlt_symbolic_s,ldlt_numeric_s,ldlt_solve_s,schur_cholesky_s,pcg_iters,pcg_solve_s,rel_diff,peak_MiB");
    for n in sizes {
        let exe = std::path::Path::new("target/release/examples/bench_linear");
        match Command::new(exe).arg(n).status() {
            Ok(s) if s.success() => {}
            _ => return false,
        }
    }
    true
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let ok = match args.first().map(String::as_str) {
        Some("metrics") => metrics::run(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .parent()
                .unwrap_or(std::path::Path::new(".")),
        ),
        Some("verify") => verify(args.iter().any(|a| a == "--full")),
        Some("bench") => {
            let sizes: Vec<String> = if args.len() > 1 {
                args[1..].to_vec()
            } else {
                ["64", "128", "256", "512"].map(String::from).to_vec()
            };
            bench(&sizes)
        }
        _ => {
            eprintln!("usage: cargo xtask verify [--full] | cargo xtask bench [n ...] | cargo xtask metrics");
            false
        }
    };
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
