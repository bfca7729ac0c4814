//! Runs under a memory limit (issue 20, class 5): under an address-space limit (`ulimit -v`),
//! runs of every size either finish or stop with the typed refusal that names the limit,
//! never killed by a signal at an allocation.

use std::process::Command;

/// Runs `piezocontact ARGS` under `ulimit -v KIB`; `(exit code, stderr)`, the code `None` where
/// a signal ended it.
fn under_limit(kib: u64, args: &str) -> (Option<i32>, String) {
    let exe = env!("CARGO_BIN_EXE_piezocontact");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec '{exe}' {args}"))
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
