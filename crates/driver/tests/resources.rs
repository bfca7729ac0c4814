//! Runs under a memory limit (issue 20, class 5): under an address-space limit (`ulimit -v`)
//! or a data-size limit (`ulimit -d`), runs of every size either finish or stop with the typed
//! refusal that names the limit, never killed by a signal at an allocation.

use std::process::Command;

/// Runs `piezocontact ARGS` under `ulimit -v KIB`; `(exit code, stderr)`, the code `None` where
/// a signal ended it.
fn under_limit(kib: u64, args: &str) -> (Option<i32>, String) {
    under("-v", kib, args)
}

/// Runs `piezocontact ARGS` under `ulimit FLAG KIB`; as [`under_limit`].
fn under(flag: &str, kib: u64, args: &str) -> (Option<i32>, String) {
    let exe = env!("CARGO_BIN_EXE_piezocontact");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit {flag} {kib} && exec '{exe}' {args}"))
        .output()
        .expect("sh runs");
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn under_an_address_space_limit_runs_finish_or_are_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    // a run far beyond the limit: refused before it is built
    let (code, stderr) = under_limit(
        1_500_000,
        &format!("run paper --set mesh.n=512 --out {}", out.display()),
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("the address-space limit (ulimit -v)"), "{stderr}");
    assert!(!out.exists());
    // a family of sizes near a limit: each finishes, or is refused by the estimate
    for (scene, n) in [
        ("paper", 16),
        ("paper", 96),
        ("paper", 192),
        ("paper-3d", 10),
        ("paper-3d", 18),
    ] {
        let (code, stderr) = under_limit(
            3_000_000,
            &format!("run {scene} --set mesh.n={n} --out {}", out.display()),
        );
        match code {
            Some(0) => {}
            Some(1) => assert!(stderr.contains("the run needs about"), "{scene} {n}: {stderr}"),
            other => panic!("{scene} {n}: ended by {other:?} (a signal?): {stderr}"),
        }
    }
}

/// Under a data-size limit the dense products' scratch counts too (a run of `paper` at n = 256
/// under `ulimit -d 1500000` aborted at its 960 MiB allocation, exit 134): each run finishes or
/// is refused by the estimate, whatever the limit.
#[test]
fn under_a_data_size_limit_runs_finish_or_are_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    for kib in [1_500_000, 3_000_000, 6_000_000] {
        for (scene, n) in [("paper", 96), ("paper", 256), ("paper-3d", 10), ("paper-3d", 18)] {
            let (code, stderr) = under(
                "-d",
                kib,
                &format!("run {scene} --set mesh.n={n} --out {}", out.display()),
            );
            match code {
                Some(0) => {}
                Some(1) => assert!(
                    stderr.contains("the run needs about") && stderr.contains("ulimit -d"),
                    "{scene} {n} under {kib} KiB: {stderr}"
                ),
                other => panic!("{scene} {n} under {kib} KiB: ended by {other:?} (a signal?): {stderr}"),
            }
        }
    }
}

/// Under a file-size limit (`ulimit -f`) a run whose file would pass it stops with the output
/// error that names the limit, exit 1, nothing written (SIGXFSZ killed it with exit 153 and no
/// word).
#[test]
fn past_the_file_size_limit_a_run_stops_with_an_error_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let exe = env!("CARGO_BIN_EXE_piezocontact");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -f 100 && exec '{exe}' run paper --set mesh.n=64 --out '{}'",
            out.display()
        ))
        .output()
        .expect("sh runs");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("the file-size limit, ulimit -f"), "{stderr}");
    assert!(!out.exists());
}

/// SIGINT and SIGTERM during a path (its step files streamed into the set being written) end
/// the run with 128 + the signal, the partial set removed and the directory's previous set
/// still its own.
#[cfg(unix)]
#[test]
fn a_signal_removes_the_partial_set_and_keeps_the_previous_one() {
    let exe = env!("CARGO_BIN_EXE_piezocontact");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let previous = Command::new(exe)
        .args(["run", "paper", "--set", "mesh.n=8", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(previous.status.success());
    let hidden = out.join(".piezocontact");
    let sets = || -> Vec<std::path::PathBuf> {
        std::fs::read_dir(&hidden)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("set-"))
            .collect()
    };
    let current = std::fs::read_link(hidden.join("current")).unwrap();
    for (signal, name) in [(2, "INT"), (15, "TERM")] {
        let mut child = Command::new(exe)
            .args([
                "run",
                "paper-cycle",
                "--set",
                "mesh.n=64",
                "--set",
                "path.steps=2000",
                "--set",
                "path.output_every=1",
                "--out",
            ])
            .arg(&out)
            .stderr(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // wait until the run's own set holds a step file
        let started = std::time::Instant::now();
        loop {
            let writing = sets()
                .into_iter()
                .any(|s| !s.ends_with(&current) && s.join("step-0001.vtu").exists());
            if writing {
                break;
            }
            assert!(started.elapsed().as_secs() < 120, "no step file was written");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let kill = Command::new("kill")
            .args([&format!("-{name}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(128 + signal), "SIG{name}");
        assert_eq!(sets(), [hidden.join(&current)], "SIG{name}: the partial set is left");
        assert_eq!(std::fs::read_link(hidden.join("current")).unwrap(), current);
        assert!(out.join("run.json").exists());
    }
}
