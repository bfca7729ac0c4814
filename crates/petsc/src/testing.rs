//! Tests on several ranks: a test started by `cargo test` starts its own binary again under
//! `mpirun -np N`, and each child process (which sees `OMPI_COMM_WORLD_SIZE`) initialises PETSc
//! and runs the body; the test passes when every rank passes.

use crate::petsc::Petsc;
use std::process::Command;

/// Runs `body` on `ranks` ranks, `name` being the test's own name (the filter its children run
/// with). Panics, as a test does, with every rank's output, where a rank fails; a rank that
/// panics aborts the others (`MPI_Abort`), and a rank that hangs is stopped after 15 minutes.
pub fn on_ranks(name: &str, ranks: usize, body: impl FnOnce(&Petsc)) {
    if std::env::var_os("OMPI_COMM_WORLD_SIZE").is_some() {
        let p = Petsc::init().expect("PETSc starts");
        // a rank that fails ends them all: the others would wait for it in their next
        // collective until the timeout
        if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| body(&p))).is_err() {
            p.abort(101);
        }
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
