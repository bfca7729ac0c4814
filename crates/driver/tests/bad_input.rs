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
