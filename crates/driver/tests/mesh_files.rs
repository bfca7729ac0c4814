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
            // (a part of a split mesh is a piece of the body: refused read alone)
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            name.starts_with("2d-") && !name.contains("-split_")
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

/// A cylindrical capacitor: the quarter annulus 1 < r < 2 of Gmsh's curved second-order meshes
/// (crates/mesh/tests/fixtures/make_curved.py), a dielectric (ε = 3, no coupling) grounded at
/// r = 1 with an electrode at V = 1 on r = 2: `φ = V ln r / ln 2`, and the electrode's charge
/// `π ε V / (2 ln 2)` per unit depth (times the 3D mesh's depth 1/2).
fn capacitor(file: &Path) -> String {
    format!(
        r#"
name = "capacitor"
description = "a cylindrical capacitor on curved cells"
[mesh]
kind = "gmsh"
file = "{}"
[[material]]
region = "body"
model = "isotropic"
young = 100.0
poisson = 0.3
permittivity = [3.0]
[[dirichlet]]
group = "inner"
u = [0.0, 0.0, 0.0]
phi = 0.0
[electrode]
group = "outer"
v = 1.0
"#,
        file.display()
    )
}

/// The charge on the terminal `group` of a run's report.
fn charge_on(s: &problem::Solution, group: &str) -> f64 {
    s.report
        .terminals
        .iter()
        .find(|t| t.group == group)
        .expect("the terminal")
        .charge
}

#[test]
fn gmshs_curved_cells_hold_a_cylindrical_capacitor() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mesh/tests/fixtures");
    let source = files::scene_file::Source {
        label: "capacitor".into(),
        dir: PathBuf::new(),
    };
    for (file, depth) in [("annulus2d-order2.msh", 1.0), ("annulus3d-order2.msh", 0.5)] {
        let path = dir.join(file);
        let mut text = capacitor(&path);
        if file.starts_with("annulus2d") {
            text = text.replace("u = [0.0, 0.0, 0.0]", "u = [0.0, 0.0]");
        }
        let scene = files::scene_file::parse(&text, "capacitor", &[]).unwrap();
        let s = files::run::solve(&scene, &source, &mut problem::Silent).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(s.mesh.curved_cells().iter().any(|&c| c), "{file}: no curved cell");
        let ln2 = std::f64::consts::LN_2;
        let mut worst = 0.0f64;
        for (v, x) in s.mesh.points.iter().enumerate() {
            worst = worst.max((s.phi[v] - x[0].hypot(x[1]).ln() / ln2).abs());
        }
        let exact = std::f64::consts::PI * 3.0 / (2.0 * ln2) * depth;
        let (q, ground) = (charge_on(&s, "electrode"), charge_on(&s, "inner"));
        eprintln!(
            "{file}: potential within {worst:.2e}, charge {q} against {exact} ({:.1e})",
            (q - exact) / exact
        );
        assert!(worst < 1e-3, "{file}: φ off by {worst:e}");
        assert!(((q - exact) / exact).abs() < 1e-4, "{file}: charge {q} against {exact}");
        assert!((q + ground).abs() < 1e-9 * q.abs(), "{file}: Gauss: {q} + {ground}");
    }
    // the 2D mesh as a meridian section (r, z): a hemispherical shell 1 < R < 2, a spherical
    // capacitor with φ = 2 V (1 - 1/R) and the charge 4π ε V (half of 8π ε V) on R = 2
    let text = capacitor(&dir.join("annulus2d-order2.msh"))
        .replace("u = [0.0, 0.0, 0.0]", "u = [0.0, 0.0]")
        .replace("file = ", "axisymmetric = true\nfile = ");
    let scene = files::scene_file::parse(&text, "capacitor", &[]).unwrap();
    let s = files::run::solve(&scene, &source, &mut problem::Silent).unwrap();
    let worst = s
        .mesh
        .points
        .iter()
        .zip(&s.phi)
        .map(|(x, p)| (p - 2.0 * (1.0 - 1.0 / x[0].hypot(x[1]))).abs())
        .fold(0.0f64, f64::max);
    let exact = 4.0 * std::f64::consts::PI * 3.0;
    let q = charge_on(&s, "electrode");
    eprintln!(
        "shell: potential within {worst:.2e}, charge {q} against {exact} ({:.1e})",
        (q - exact) / exact
    );
    assert!(
        worst < 1e-3 && ((q - exact) / exact).abs() < 1e-4,
        "shell: φ {worst:e}, charge {q}"
    );
}
