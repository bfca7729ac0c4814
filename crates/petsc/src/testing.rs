//! Tests on several ranks: a test started by `cargo test` starts its own binary again under
//! `mpirun -np N`, and each child process (which sees `OMPI_COMM_WORLD_SIZE`) initialises PETSc
//! and runs the body; the test passes when every rank passes.

use crate::petsc::Petsc;
use std::process::Command;

/// Runs `body` on `ranks` ranks, `name` being the test's own name (the filter its children run
/// with). Panics, as a test does, with every rank's output, where a rank fails; a rank that
/// hangs (waiting in a collective for one that died) is stopped after 15 minutes.
pub fn on_ranks(name: &str, ranks: usize, body: impl FnOnce(&Petsc)) {
    if std::env::var_os("OMPI_COMM_WORLD_SIZE").is_some() {
        let p = Petsc::init().expect("PETSc starts");
        body(&p);
        return;
    }
    let exe = std::env::current_exe().expect("the test binary's path");
    let out = Command::new("timeout")
        .args([
            "900",
            "mpirun",
            "-np",
            &ranks.to_string(),
            "--allow-run-as-root",
            "--oversubscribe",
        ])
        .arg(exe)
        .args([name, "--exact", "--test-threads=1", "--nocapture"])
        .output()
        .expect("mpirun runs (apt-get install petsc-dev brings Open MPI)");
    assert!(
        out.status.success(),
        "{name} on {ranks} ranks failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
