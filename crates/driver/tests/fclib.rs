//! `piezocontact fclib` through the binary: the table, `summary.json` and the CSV of each
//! solved file, and a broken file named with its line, with nothing written.

use std::path::{Path, PathBuf};
use std::process::Command;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../contact/tests/data/fclib")
        .join(name)
}

#[test]
fn the_summary_and_the_solutions_are_written() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let out = tmp.path().join("fclib");
    let files = ["FrictionContactProblem00031.dat", "Capsules-i101-404.dat"];
    let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .arg("fclib")
        .args(files.iter().map(|f| data(f)))
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the binary runs");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(stdout.contains("solved 2 of 2"), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).expect("summary.json")).expect("JSON");
    let rows = summary.as_array().expect("a list");
    assert_eq!(rows.len(), 2);
    for (row, (file, dim, contacts)) in rows.iter().zip([(files[0], 2, 11), (files[1], 3, 225)]) {
        assert_eq!(row["file"], file);
        assert_eq!(row["dim"], dim);
        assert_eq!(row["contacts"], contacts);
        assert_eq!(row["solver"], "newton");
        assert_eq!(row["converged"], true);
        assert!(row["siconos_error"].as_f64().expect("a number") <= 1e-8, "{row}");
        for key in ["iterations", "time_s", "residual"] {
            assert!(row[key].is_number(), "{key} in {row}");
        }
        let csv = std::fs::read_to_string(out.join(file.replace(".dat", ".csv"))).expect("the CSV");
        let mut lines = csv.lines();
        let header = lines.next().expect("a header");
        assert_eq!(header.split(',').count(), 1 + 2 * dim as usize, "{header}");
        assert_eq!(lines.count(), contacts as usize);
    }
}

#[test]
fn a_broken_file_is_named_and_nothing_is_written() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let broken = tmp.path().join("broken.dat");
    std::fs::write(&broken, "3\n1\n0\n3\n3\n3\t3\n2 0 0\n0 one 0\n").expect("writable");
    let out = tmp.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .arg("fclib")
        .arg(data("FC3D_Example1.dat"))
        .arg(&broken)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the binary runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("broken.dat: line 8: expected an entry of W (a finite number), found `one`"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("FC3D_Example1.dat: solved"),
        "read before any solve: {stderr}"
    );
    assert!(!out.exists());
}
