//! The capacitance matrix between terminals (`problem::capacitance`) against the parallel-plate
//! capacitor's closed forms, for a poled PZT-5A plate between electrodes on its faces:
//!
//! - clamped (no displacement can occur: rollers on every face), `C = ε33 A / h`;
//! - free to thicken (its top free), uniaxial strain `ε_zz = e33 E_z / c33` stiffens the
//!   permittivity, `C = (ε33 + e33² / c33) A / h` (IEEE Std 176-1987's clamped and
//!   "stiffened" permittivities);
//!
//! in plane strain (A the width, per unit depth) and on a disc of revolution (A = π R²); P1
//! holds these uniform fields, so the matrix is the closed form to round-off. And the
//! identities of any matrix: reciprocity `C = Cᵀ`, Gauss's law (each column sums to 0),
//! groups joined by a node counted as one conductor.
//!
//! Floating terminals (`dirichlet.charge`): the same plate pressed by `p` with its top
//! electrode open (no charge) reads `V = -p e33 h / (c33 ε33 + e33²)` (uniaxial strain with
//! `D_z = 0`), and a charge `Q` on it adds `Q / C` with the stiffened `C`.

use problem::{DirichletSpec, MaterialSpec, MeshSpec, Scene};

const C33: f64 = 111.0;
const E33: f64 = 15.8;
const EPS33: f64 = 7.35;

fn plate(axisymmetric: bool, top_free: bool) -> Scene {
    let roller = |group: &str, ux: bool| DirichletSpec {
        group: group.into(),
        ux: ux.then_some(0.0),
        uy: (!ux).then_some(0.0),
        ..Default::default()
    };
    let mut dirichlet = vec![roller("left", true), roller("right", true)];
    let mut bottom = roller("bottom", false);
    bottom.phi = Some(0.0);
    dirichlet.push(bottom);
    let mut top = if top_free {
        DirichletSpec {
            group: "top".into(),
            ..Default::default()
        }
    } else {
        roller("top", false)
    };
    top.phi = Some(1.0);
    dirichlet.push(top);
    let mut mesh = MeshSpec::rectangle([0.0, 0.0], [2.0, 0.5], 4);
    mesh.axisymmetric = axisymmetric;
    Scene {
        name: "plate".into(),
        description: String::new(),
        mesh,
        material: vec![MaterialSpec::crystal_6mm(
            "body",
            [121.0, 75.4, 75.2, C33, 21.1, 22.6],
            [-5.4, E33, 12.3],
            [8.11, EPS33],
            [0.0, 1.0, 0.0],
        )],
        dirichlet,
        load: None,
        electrode: None,
        contact: None,
        solver: Default::default(),
        exact: None,
        path: None,
    }
}

#[test]
fn a_plate_between_electrodes_is_the_parallel_plate_capacitor() {
    let h = 0.5;
    for axisymmetric in [false, true] {
        // the area: the width per unit depth, or the disc of radius 2
        let area = if axisymmetric { std::f64::consts::PI * 4.0 } else { 2.0 };
        for (top_free, permittivity) in [(false, EPS33), (true, EPS33 + E33 * E33 / C33)] {
            let c = problem::capacitance(&plate(axisymmetric, top_free), None).unwrap();
            assert_eq!(c.terminals, ["bottom", "top"]);
            let expected = permittivity * area / h;
            for (i, j, sign) in [(0, 0, 1.0), (1, 1, 1.0), (0, 1, -1.0), (1, 0, -1.0)] {
                let got = c.matrix[i][j];
                assert!(
                    (got - sign * expected).abs() < 1e-10 * expected,
                    "axisymmetric {axisymmetric}, top free {top_free}: C[{i}][{j}] = {got} against {}",
                    sign * expected
                );
            }
            assert!(c.asymmetry < 1e-12 && c.column_sum < 1e-12, "{c:?}");
        }
    }
}

#[test]
fn three_terminals_are_reciprocal_and_joined_groups_are_one_conductor() {
    // the paper's actuator: two grounded sides and an electrode on part of the top
    let (scene, _) = files::scene_file::load("actuator", &["mesh.n=16".into()]).unwrap();
    let c = problem::capacitance(&scene, None).unwrap();
    assert_eq!(c.terminals.len(), 3, "{:?}", c.terminals);
    assert!(c.asymmetry < 1e-10, "reciprocity: {c:?}");
    assert!(c.column_sum < 1e-10, "Gauss: {c:?}");
    for i in 0..3 {
        assert!(c.matrix[i][i] > 0.0, "{c:?}");
    }
    // its bottom grounded too: it joins both grounded sides at the corners, one conductor
    let (mut scene, _) = files::scene_file::load("actuator", &["mesh.n=16".into()]).unwrap();
    scene.dirichlet.push(DirichletSpec {
        group: "bottom".into(),
        phi: Some(0.0),
        ..Default::default()
    });
    let joined = problem::capacitance(&scene, None).unwrap();
    assert_eq!(joined.terminals, ["left+right+bottom", "electrode"], "{joined:?}");
    assert!(joined.asymmetry < 1e-10 && joined.column_sum < 1e-10, "{joined:?}");
    // a grounded bottom under the electrode takes more of its field: a larger capacitance
    assert!(joined.matrix[1][1] > c.matrix[2][2], "{joined:?} {c:?}");
}

#[test]
fn a_scene_without_terminals_or_permittivity_is_refused_by_name() {
    let mut scene = plate(false, false);
    for d in &mut scene.dirichlet {
        d.phi = None;
    }
    let e = problem::capacitance(&scene, None).unwrap_err();
    assert!(e.to_string().contains("no terminal"), "{e}");
    let (elastic, _) = files::scene_file::load("hertz-sphere", &[]).unwrap();
    let e = problem::capacitance(&elastic, None).unwrap_err();
    assert!(e.to_string().contains("no electric unknowns"), "{e}");
}

/// The plate pressed by `p` on its top, its top electrode floating with `charge` on it.
fn sensor(axisymmetric: bool, p: f64, charge: f64) -> Scene {
    let mut scene = plate(axisymmetric, true);
    let top = scene.dirichlet.iter_mut().find(|d| d.group == "top").unwrap();
    top.phi = None;
    top.charge = Some(charge);
    scene.load = Some(
        problem::LoadSpec {
            group: "top".into(),
            p,
            direction: vec![0.0, -1.0],
        }
        .into(),
    );
    scene
}

#[test]
fn an_open_electrode_on_a_pressed_plate_reads_its_closed_form_voltage() {
    let (h, p) = (0.5, 0.01);
    let open = -p * E33 * h / (C33 * EPS33 + E33 * E33);
    for axisymmetric in [false, true] {
        let area = if axisymmetric { std::f64::consts::PI * 4.0 } else { 2.0 };
        let c_free = (EPS33 + E33 * E33 / C33) * area / h;
        for q in [0.0, 1e-3] {
            let s = problem::solve(&sensor(axisymmetric, p, q), None, &mut problem::Silent).unwrap();
            let top = s.report.terminals.iter().find(|t| t.group == "top").unwrap();
            assert!(top.floating);
            let expected = open + q / c_free;
            assert!(
                (top.potential - expected).abs() < 1e-10 * open.abs(),
                "axisymmetric {axisymmetric}, Q = {q}: V = {} against {expected}",
                top.potential
            );
            // the charge asked for, as the final run's reaction
            assert!(
                (-top.charge - q).abs() < 1e-10 * (q.abs() + c_free * open.abs()),
                "charge {}",
                -top.charge
            );
            // the whole top at that potential
            let nodes = s.mesh.boundary("top").unwrap().nodes();
            assert!(nodes
                .iter()
                .all(|&v| (s.phi[v] - top.potential).abs() < 1e-14 * open.abs()));
        }
    }
}

#[test]
fn what_a_floating_terminal_cannot_carry_is_refused_by_name() {
    let mut with_phi = sensor(false, 0.01, 0.0);
    with_phi.dirichlet.iter_mut().find(|d| d.group == "top").unwrap().phi = Some(1.0);
    let e = problem::solve(&with_phi, None, &mut problem::Silent).err().unwrap();
    assert!(e.to_string().contains("dirichlet.charge"), "{e}");
    let (mut contact, _) = files::scene_file::load("actuator", &["mesh.n=8".into()]).unwrap();
    contact.dirichlet[0].phi = None;
    contact.dirichlet[0].charge = Some(0.0);
    let e = problem::solve(&contact, None, &mut problem::Silent).err().unwrap();
    assert!(e.to_string().contains("contact"), "{e}");
    // one run of a backend does not take it: problem::solve does
    let e = problem::run(
        &mut problem::Faer,
        &sensor(false, 0.01, 0.0),
        None,
        Default::default(),
        &mut problem::Silent,
    )
    .err()
    .unwrap();
    assert!(e.to_string().contains("problem::solve"), "{e}");
}

#[test]
fn several_loads_add_up() {
    // the sensor's pressure as two [[load]] entries of half each: the same open-circuit voltage
    let one = problem::solve(&sensor(false, 0.01, 0.0), None, &mut problem::Silent).unwrap();
    let mut two = sensor(false, 0.01, 0.0);
    let half = problem::LoadSpec {
        group: "top".into(),
        p: 0.005,
        direction: vec![0.0, -1.0],
    };
    two.load = Some(problem::Loads::Many(vec![half.clone(), half]));
    let two = problem::solve(&two, None, &mut problem::Silent).unwrap();
    let v = |s: &problem::Solution| s.report.terminals.iter().find(|t| t.group == "top").unwrap().potential;
    assert!(
        (v(&one) - v(&two)).abs() < 1e-12 * v(&one).abs(),
        "{} {}",
        v(&one),
        v(&two)
    );
    // and from a scene file's [[load]] array
    let text = r#"
name = "two-loads"
description = "two tractions"
[mesh]
kind = "rectangle"
lo = [0.0, 0.0]
hi = [2.0, 1.0]
n = 4
[[material]]
region = "body"
model = "isotropic"
young = 100.0
poisson = 0.3
[[dirichlet]]
group = "bottom"
u = [0.0, 0.0]
[[load]]
group = "top"
p = 1.0
direction = [1.0, 0.0]
[[load]]
group = "right"
p = 2.0
direction = [0.0, 1.0]
"#;
    let scene = files::scene_file::parse(text, "two-loads", &[]).unwrap();
    assert_eq!(scene.loads().len(), 2);
    assert!(problem::solve(&scene, None, &mut problem::Silent).is_ok());
}
