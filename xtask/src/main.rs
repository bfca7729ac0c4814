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

/// Whether PETSc and MPI are here to build the feature code against (`pkg-config`'s PETSc).
fn petsc_here() -> bool {
    Command::new("pkg-config")
        .args(["--exists", "PETSc"])
        .status()
        .is_ok_and(|s| s.success())
}

/// clippy and rustdoc over the feature code too (`--all-features`: the PETSc backend, its FFI
/// and MPI code), where PETSc is here to build it; said and left out where it is not.
fn lint_features() -> bool {
    if !petsc_here() {
        eprintln!("PETSc is not here (pkg-config PETSc): clippy and rustdoc of the `petsc` features left out");
        return true;
    }
    cargo(
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--all-features",
            "--",
            "-D",
            "warnings",
        ],
        &[],
    ) && cargo(
        &["doc", "--workspace", "--no-deps", "--all-features"],
        &[("RUSTDOCFLAGS", "-D warnings")],
    )
}

/// fmt, clippy, the tests (the tidy test among them), rustdoc (with every feature where PETSc
/// is here), then the verification report: a smoke run of every shipped scene and the
/// convergence studies, written to docs/verification.md (`full`: to the finest meshes).
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
        && lint_features()
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
