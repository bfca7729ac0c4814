//! Gmsh meshes as a user brings them (issue 20, classes 2 and 3): an internal electrode on an
//! interior facet group of a two-material mesh, in every form of the file that Gmsh writes,
//! against the closed form; and a relative `mesh.file` given by `--set`, resolved where it was
//! typed.

use std::path::{Path, PathBuf};
use std::process::Command;

fn forms() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../mesh/tests/fixtures/forms")
}

/// Two dielectric layers, `substrate` (y < 0.8, ε = 2) and `pzt` (y > 0.8, ε = 5), an electrode
/// at voltage 1 on their interface, the outer faces y = 0 and y = 1 grounded: no piezoelectric
/// coupling, so the potential is the closed form φ = y / 0.8 below the electrode and
/// (1 - y) / 0.2 above, which P1 and P2 elements hold exactly.
fn stack(file: &Path) -> String {
    format!(
        r#"
name = "stack"
description = "an internal electrode between two dielectric layers"
[mesh]
kind = "gmsh"
file = "{}"
[[material]]
region = "substrate"
model = "isotropic"
young = 100.0
poisson = 0.3
permittivity = [2.0]
[[material]]
region = "pzt"
model = "isotropic"
young = 50.0
poisson = 0.25
permittivity = [5.0]
[[dirichlet]]
group = "bottom"
u = [0.0, 0.0]
phi = 0.0
[[dirichlet]]
group = "top"
phi = 0.0
[electrode]
group = "interface"
v = 1.0
"#,
        file.display()
    )
}

#[test]
fn an_internal_electrode_on_an_interface_gives_the_closed_form_in_every_form_of_the_file() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(forms())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            name.starts_with("2d-")
        })
        .collect();
    files.sort();
    assert!(files.len() >= 11, "{files:?}");
    for file in &files {
        let scene = files::scene_file::parse(&stack(file), "stack", &[]).unwrap();
        let source = files::scene_file::Source {
            label: "stack".into(),
            dir: PathBuf::new(),
        };
        let s = files::run::solve(&scene, &source, &mut problem::Silent)
            .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        // the second-order file runs as it is: six-node triangles, their edge nodes exact too
        let order = if file.to_string_lossy().contains("order2") {
            2
        } else {
            1
        };
        assert_eq!(s.mesh.kind.order(), order, "{}", file.display());
        let mut checked = 0;
        for (v, x) in s.mesh.points.iter().enumerate() {
            if s.mesh.unused_nodes().contains(&v) {
                continue; // the arc's centre: no unknown
            }
            let exact = if x[1] <= 0.8 { x[1] / 0.8 } else { (1.0 - x[1]) / 0.2 };
            assert!(
                (s.phi[v] - exact).abs() < 1e-12,
                "{}: φ at {x:?} = {} against {exact}",
                file.display(),
                s.phi[v]
            );
            checked += 1;
        }
        assert!(checked > 50);
        assert!(
            s.report.mesh.unused_nodes >= 1,
            "{}: the arc's centre is counted",
            file.display()
        );
    }
}

#[test]
fn a_second_order_file_at_order_one_and_an_order_past_two_are_refused_by_key() {
    let file = forms().join("2d-ascii-order2.msh");
    let source = files::scene_file::Source {
        label: "stack".into(),
        dir: PathBuf::new(),
    };
    for (set, words) in [
        ("mesh.order=1", &["mesh.order = 1", "second-order"][..]),
        ("mesh.order=3", &["mesh.order", "1 (linear) or 2"][..]),
    ] {
        let e = match files::scene_file::parse(&stack(&file), "stack", &[set.to_string()]) {
            Err(e) => e.to_string(),
            Ok(scene) => match files::run::solve(&scene, &source, &mut problem::Silent) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{set} ran"),
            },
        };
        assert!(words.iter().all(|w| e.contains(w)), "{set}: {e}");
    }
}

#[test]
fn a_relative_mesh_file_given_by_set_is_found_where_it_was_typed() {
    let tmp = tempfile::tempdir().unwrap();
    // the scene elsewhere, naming a mesh that is not beside it
    let scene = tmp.path().join("stack.toml");
    std::fs::write(&scene, stack(Path::new("not-here.msh"))).unwrap();
    let out = tmp.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .current_dir(forms())
        .arg("run")
        .arg(&scene)
        .args(["--set", "mesh.file=2d-ascii.msh", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(out.join("run.json").exists());
    // the scene file's own relative path still resolves against the scene's directory
    std::fs::copy(forms().join("2d-ascii.msh"), tmp.path().join("beside.msh")).unwrap();
    std::fs::write(&scene, stack(Path::new("beside.msh"))).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .current_dir(forms())
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
}

#[test]
fn a_fifo_as_mesh_file_is_refused_not_read() {
    let tmp = tempfile::tempdir().unwrap();
    let fifo = tmp.path().join("mesh.msh");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        return; // no mkfifo here
    }
    let scene = tmp.path().join("stack.toml");
    std::fs::write(&scene, stack(Path::new("mesh.msh"))).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(tmp.path().join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("is not a regular file"),
        "{stderr}"
    );
}
