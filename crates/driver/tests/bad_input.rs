//! The bad-input corpus (`tests/bad-input/`): every broken scene or mesh makes `piezocontact run`
//! exit non-zero with its own message (the file's `# expect:` line), and write no output.

use std::path::{Path, PathBuf};
use std::process::Command;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad-input")
}

#[test]
fn every_broken_input_names_its_fault_exits_non_zero_and_writes_nothing() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(corpus())
        .expect("the corpus directory")
        .map(|e| e.expect("a corpus entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 25, "only {} cases", files.len());
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let mut failures = vec![];
    for file in &files {
        let text = std::fs::read_to_string(file).expect("readable");
        let expect = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{}: no `# expect:` first line", file.display()));
        let out = tmp.path().join(file.file_stem().expect("a name"));
        let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
            .arg("run")
            .arg(file)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("the binary runs");
        let stderr = String::from_utf8_lossy(&run.stderr);
        let name = file.file_name().expect("a name").to_string_lossy();
        if run.status.success() {
            failures.push(format!("{name}: exit status 0"));
        }
        if run.status.code().is_none() {
            failures.push(format!("{name}: killed by a signal (a panic or an abort?)"));
        }
        if stderr.contains("panicked") {
            failures.push(format!("{name}: panicked: {stderr}"));
        }
        if !stderr.contains(expect) {
            failures.push(format!("{name}: expected `{expect}` in: {stderr}"));
        }
        if out.exists() {
            failures.push(format!("{name}: wrote {}", out.display()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Runs the binary with `args`, killing it after `limit`; `(exit code, stderr)`, the code `None`
/// where it had to be killed (a hang).
fn run_with_limit(args: &[&str], limit: std::time::Duration) -> (Option<i32>, String) {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let started = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("the child's status") {
            let mut stderr = String::new();
            child
                .stderr
                .take()
                .expect("piped")
                .read_to_string(&mut stderr)
                .expect("utf-8");
            return (status.code(), stderr);
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return (None, String::new());
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// A FIFO given as the scene is refused at once (reading it would block for ever).
#[cfg(target_os = "linux")]
#[test]
fn a_fifo_is_not_a_scene() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let fifo = tmp.path().join("scene.toml");
    rustix::fs::mkfifoat(rustix::fs::CWD, &fifo, rustix::fs::Mode::from_raw_mode(0o600)).expect("mkfifo");
    let out = tmp.path().join("out");
    let (code, stderr) = run_with_limit(
        &[
            "run",
            fifo.to_str().expect("a UTF-8 path"),
            "--out",
            out.to_str().expect("UTF-8"),
        ],
        std::time::Duration::from_secs(20),
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("is not a regular file"), "{stderr}");
    assert!(!out.exists());
}

/// Extreme values that solve at once must not hang or fail the pictures: a friction
/// coefficient of 1e308 (an infinite range of the multipliers picture once looped for ever in
/// the axis computation), loads of 1e±200 (each run's answer is its scaled answer at p = -2).
#[test]
fn extreme_values_solve_and_draw() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    for (k, set) in [
        "contact.friction=1e308",
        "load.p=-1e200",
        "load.p=-1e-200",
        "contact.gap=1e300",
    ]
    .into_iter()
    .enumerate()
    {
        let out = tmp.path().join(k.to_string());
        let args = [
            "run",
            "paper",
            "--set",
            "mesh.n=8",
            "--set",
            set,
            "--out",
            out.to_str().expect("UTF-8"),
        ];
        let (code, stderr) = run_with_limit(&args, std::time::Duration::from_secs(60));
        assert_eq!(code, Some(0), "{set}: {stderr}");
        for file in [
            "multipliers.svg",
            "multipliers.png",
            "deformed.png",
            "contact.csv",
            "run.json",
        ] {
            assert!(out.join(file).exists(), "{set}: {file}");
        }
    }
}

/// Without the feature `petsc`, the PETSc backend is refused by name, with how to build it,
/// and nothing is written.
#[cfg(not(feature = "petsc"))]
#[test]
fn the_petsc_backend_needs_its_feature() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let out = tmp.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .args([
            "run",
            "paper",
            "--set",
            "mesh.n=8",
            "--set",
            "contact.law=\"none\"",
            "--set",
            "solver.backend=\"petsc\"",
            "--out",
        ])
        .arg(&out)
        .output()
        .expect("the binary runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(stderr.contains("--features petsc"), "{stderr}");
    assert!(!out.exists());
}
