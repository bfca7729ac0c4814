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
        units: None,
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

/// A floating terminal is a conductor like the others in the capacitance matrix, whether a
/// floating `dirichlet.charge` or a floating `[[electrode]]` (whose row and column were once
/// zeros: its potential was never set to a column's unit), and the matrix is the one of the
/// same electrode at a voltage.
#[test]
fn a_floating_electrode_is_a_terminal_of_the_capacitance() {
    let sets = |second: &str| -> Vec<String> {
        vec![
            "mesh.n=8".into(),
            "electrode.0.x_range=[0.25, 0.75]".into(),
            format!("electrode.1={{group=\"top\", name=\"second\", {second}, x_range=[1.25, 1.75]}}"),
        ]
    };
    let matrix = |second: &str| {
        let (scene, _) = files::scene_file::load("actuator", &sets(second)).unwrap();
        problem::capacitance(&scene, None).unwrap()
    };
    let (floating, driven) = (matrix("charge=0.0"), matrix("v=1.0"));
    assert_eq!(floating.terminals, ["left", "right", "electrode", "second"]);
    assert_eq!(floating.terminals, driven.terminals);
    for (row_f, row_d) in floating.matrix.iter().zip(&driven.matrix) {
        for (f, d) in row_f.iter().zip(row_d) {
            assert!(
                (f - d).abs() <= 1e-12 * driven.matrix[3][3],
                "{floating:?} against {driven:?}"
            );
        }
    }
    assert!(
        floating.matrix[3][3] > 0.0 && floating.column_sum < 1e-10,
        "{floating:?}"
    );
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
    // one conductor: its capacitance to nothing is 0, and what a solve gives is round-off
    // (indent-sphere grounds its top alone: 2.8e-10 pC/kV was printed, Gauss's check 1.0)
    let (one, _) = files::scene_file::load("indent-sphere", &["mesh.n=4".into()]).unwrap();
    let e = problem::capacitance(&one, None).unwrap_err();
    assert!(e.to_string().contains("one terminal (`top`)"), "{e}");
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
                (top.charge - q).abs() < 1e-10 * (q.abs() + c_free * open.abs()),
                "charge {}",
                top.charge
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
    // a floating terminal touching a grounded one: one conductor, by name
    let mut touching = sensor(false, 0.01, 0.0);
    touching.dirichlet.push(DirichletSpec {
        group: "left".into(),
        phi: Some(0.0),
        ..Default::default()
    });
    let e = problem::solve(&touching, None, &mut problem::Silent).err().unwrap();
    assert!(
        e.to_string().contains("one conductor") && e.to_string().contains("`top`"),
        "{e}"
    );
    // an electrical contact on the floating terminal's face
    let mut conducting = pressed_onto_a_foundation(2, 1e-3, 0.0);
    conducting.dirichlet.retain(|d| d.group != "top");
    conducting.dirichlet.push(DirichletSpec {
        group: "top".into(),
        uy: Some(-1e-3),
        ..Default::default()
    });
    conducting
        .dirichlet
        .iter_mut()
        .find(|d| d.group == "bottom")
        .unwrap()
        .phi = None;
    conducting
        .dirichlet
        .iter_mut()
        .find(|d| d.group == "bottom")
        .unwrap()
        .charge = Some(0.0);
    conducting.dirichlet.push(DirichletSpec {
        group: "top".into(),
        phi: Some(0.0),
        ..Default::default()
    });
    conducting.first_contact_mut().unwrap().electric = Some(problem::ElectricCondition::Conducting);
    let e = problem::solve(&conducting, None, &mut problem::Silent).err().unwrap();
    assert!(
        e.to_string().contains("contact.electric") && e.to_string().contains("floating terminal"),
        "{e}"
    );
    // a charge without electric unknowns
    let mut elastic = sensor(false, 0.01, 1e-3);
    elastic.material[0] = MaterialSpec::isotropic("body", 100.0, 0.3);
    let e = problem::solve(&elastic, None, &mut problem::Silent).err().unwrap();
    assert!(e.to_string().contains("dirichlet.charge"), "{e}");
}

/// A plate (2D: plane strain, or a box in 3D) poled across its thickness `h = 0.5`, laterally
/// confined by rollers, its top pushed down by `d` and carrying a floating electrode with
/// `charge` on it, its grounded bottom resting on a rigid foundation (frictionless contact).
/// Uniaxial strain `ε = -d/h` with `D_z = -Q/A`: the top reads `V = (e33 ε h + Q h / A) / ε33`
/// (the clamped capacitance: the strain is given), and the foundation carries the pressure
/// `p = -σ_zz = -(c33 ε + e33 (e33 ε + Q/A) / ε33)`.
fn pressed_onto_a_foundation(dim: usize, d: f64, charge: f64) -> Scene {
    let mut scene = plate(false, true);
    let (up, normal) = if dim == 2 {
        (1, vec![0.0, -1.0])
    } else {
        (2, vec![0.0, 0.0, -1.0])
    };
    let mut dirichlet = vec![];
    let sides: &[(&str, usize)] = if dim == 2 {
        &[("left", 0), ("right", 0)]
    } else {
        &[("left", 0), ("right", 0), ("front", 1), ("back", 1)]
    };
    for &(group, k) in sides {
        let mut roller = DirichletSpec {
            group: group.into(),
            ..Default::default()
        };
        match k {
            0 => roller.ux = Some(0.0),
            _ => roller.uy = Some(0.0),
        }
        dirichlet.push(roller);
    }
    let mut top = DirichletSpec {
        group: "top".into(),
        charge: Some(charge),
        ..Default::default()
    };
    if up == 1 {
        top.uy = Some(-d);
    } else {
        top.uz = Some(-d);
    }
    dirichlet.push(top);
    dirichlet.push(DirichletSpec {
        group: "bottom".into(),
        phi: Some(0.0),
        ..Default::default()
    });
    scene.dirichlet = dirichlet;
    if dim == 3 {
        scene.mesh = MeshSpec::cuboid([0.0; 3], [2.0, 1.0, 0.5], 4);
        scene.material[0].poling = vec![0.0, 0.0, 1.0];
    }
    scene.contact = Some(problem::ContactSpec::new("bottom", problem::ContactLaw::Signorini, &normal).into());
    scene
}

#[test]
fn a_floating_electrode_pressed_onto_a_foundation_reads_its_closed_form() {
    let (h, d) = (0.5, 1e-3);
    let strain = -d / h;
    for dim in [2, 3] {
        // the top: 2 x 1 per unit depth in plane strain, 2 x 1 in 3D
        let area = 2.0;
        for q in [0.0, 0.05] {
            let s = problem::solve(&pressed_onto_a_foundation(dim, d, q), None, &mut problem::Silent).unwrap();
            let top = s.report.terminals.iter().find(|t| t.group == "top").unwrap();
            assert!(top.floating);
            let v = (E33 * strain * h + q * h / area) / EPS33;
            assert!(
                (top.potential - v).abs() < 1e-9 * v.abs(),
                "{dim}D, Q = {q}: V = {} against {v}",
                top.potential
            );
            assert!(
                (top.charge - q).abs() < 1e-9 * (q.abs() + EPS33 * area / h * v.abs()),
                "{dim}D charge {}",
                top.charge
            );
            let pressure = -(C33 * strain + E33 * (E33 * strain + q / area) / EPS33);
            let force = s.report.contact.normal_force;
            assert!(
                (force - pressure * area).abs() < 1e-9 * pressure * area,
                "{dim}D, Q = {q}: force {force} against {}",
                pressure * area
            );
        }
    }
}

/// The largest difference between two solutions' nodal displacements, and the largest
/// displacement of the second (the scale it is judged against).
fn displacement_gap(a: &problem::Solution, b: &problem::Solution) -> (f64, f64) {
    let scale = b.u.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let gap = (a.u.iter().zip(&b.u))
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
        .fold(0.0f64, f64::max);
    (gap, scale)
}

/// The paper's block with its sides clamped, its bottom grounded and pressed by Coulomb friction
/// onto the foundation, its top loaded and carrying a floating electrode with `charge`: a
/// contact zone that sticks and slips, and a terminal whose potential moves it.
fn floating_on_friction(dim: usize, charge: f64) -> Scene {
    let (mut scene, _) =
        files::scene_file::load(if dim == 2 { "actuator" } else { "paper-3d" }, &["mesh.n=8".into()]).unwrap();
    scene.electrode = None;
    for d in &mut scene.dirichlet {
        d.phi = None;
    }
    scene
        .dirichlet
        .retain(|d| d.u.is_some() || d.ux.is_some() || d.uy.is_some() || d.uz.is_some());
    scene.dirichlet.push(DirichletSpec {
        group: "bottom".into(),
        phi: Some(0.0),
        ..Default::default()
    });
    scene.dirichlet.push(DirichletSpec {
        group: "top".into(),
        charge: Some(charge),
        ..Default::default()
    });
    let contact = scene.first_contact_mut().unwrap();
    contact.law = problem::ContactLaw::Coulomb;
    contact.friction = Some(if dim == 2 { 0.05 } else { 0.2 });
    scene
}

#[test]
fn a_floating_terminal_under_friction_is_the_prescribed_potential_that_carries_its_charge() {
    // the floating run's potential, prescribed: the same solution, with the charge asked for
    for dim in [2, 3] {
        let charge = if dim == 2 { 0.05 } else { 0.02 };
        let floating = problem::solve(&floating_on_friction(dim, charge), None, &mut problem::Silent).unwrap();
        let top = floating.report.terminals.iter().find(|t| t.group == "top").unwrap();
        let contact = &floating.report.contact;
        assert!(contact.n_stick > 0 && contact.n_slip > 0, "{dim}D: {contact:?}");
        let mut prescribed = floating_on_friction(dim, charge);
        let spec = prescribed.dirichlet.iter_mut().find(|d| d.group == "top").unwrap();
        spec.charge = None;
        spec.phi = Some(top.potential);
        let fixed = problem::solve(&prescribed, None, &mut problem::Silent).unwrap();
        let fixed_top = fixed.report.terminals.iter().find(|t| t.group == "top").unwrap();
        assert!(!fixed_top.floating);
        assert!(
            (fixed_top.charge - charge).abs() < 1e-8 * charge,
            "{dim}D: the potential {} carries {} against {charge}",
            top.potential,
            fixed_top.charge
        );
        let (gap, scale) = displacement_gap(&floating, &fixed);
        assert!(
            gap < 1e-8 * scale,
            "{dim}D: displacements differ by {gap:e} of {scale:e}"
        );
    }
}

#[test]
fn a_floating_terminal_follows_a_load_path() {
    // the plate pushed onto its foundation in five steps (the displacement factor) with a
    // charge ramped by the voltage factor: frictionless, so each instant is the static answer
    // (problem::solve computes the fields of the last instant alone: every other row comes
    // from the charges' and potentials' functionals of the multipliers)
    let (h, d, q) = (0.5, 1e-3, 0.05);
    let mut scene = pressed_onto_a_foundation(2, d, q);
    scene.path = Some(problem::PathSpec {
        t: vec![0.0, 1.0],
        steps: Some(5),
        displacement: Some(vec![0.0, 1.0]),
        voltage: Some(vec![0.0, 1.0]),
        ..Default::default()
    });
    let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
    let path = s.report.path.as_ref().unwrap();
    let top = s.report.terminals.iter().position(|t| t.group == "top").unwrap();
    assert_eq!(path.rows.len(), 6);
    for row in &path.rows {
        let f = row.t;
        let v = (E33 * (-f * d / h) * h + f * q * h / 2.0) / EPS33;
        let got = row.potentials[top];
        assert!(
            (got - v).abs() < 1e-9 * (d * E33 / EPS33),
            "t = {f}: V = {got} against {v}"
        );
        assert!(
            (row.charges[top] - f * q).abs() < 1e-9 * q,
            "t = {f}: charge {}",
            row.charges[top]
        );
        assert_eq!(
            row.equilibrium.is_some(),
            f == 1.0,
            "t = {f}: fields where not asked for"
        );
    }
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

#[test]
fn electrodes_split_in_two_are_the_one_they_cover() {
    // the actuator's electrode (0.25 <= x <= 1.75 of the top, 0.05) as two [[electrode]]
    // halves at the same voltage: the same solution, and their charges add up to its charge
    let (one, _) = files::scene_file::load("actuator", &["mesh.n=16".into()]).unwrap();
    let mut two = one.clone();
    let half = |lo: f64, hi: f64, name: &str| problem::ElectrodeSpec {
        x_range: Some(vec![lo, hi]),
        name: Some(name.into()),
        ..problem::ElectrodeSpec::at("top", 0.05)
    };
    two.electrode = Some(problem::Electrodes::Many(vec![
        half(0.25, 1.0, "west"),
        half(1.0, 1.75, "east"),
    ]));
    let (a, b) = (
        problem::solve(&one, None, &mut problem::Silent).unwrap(),
        problem::solve(&two, None, &mut problem::Silent).unwrap(),
    );
    let (gap, scale) = displacement_gap(&b, &a);
    assert!(gap < 1e-10 * scale, "displacements differ by {gap:e}");
    let charge = |s: &problem::Solution, g: &str| s.report.terminals.iter().find(|t| t.group == g).unwrap().charge;
    let names: Vec<&str> = b.report.terminals.iter().map(|t| t.group.as_str()).collect();
    assert_eq!(names, ["left", "right", "west", "east"]);
    let whole = charge(&a, "electrode");
    let sum = charge(&b, "west") + charge(&b, "east");
    assert!((sum - whole).abs() < 1e-10 * whole.abs(), "{sum} against {whole}");
    // the capacitance matrix: the halves share the node at x = 1, one conductor
    let c = problem::capacitance(&two, None).unwrap();
    assert_eq!(c.terminals, ["left", "right", "west+east"]);
}

#[test]
fn a_floating_electrode_table_reads_the_open_circuit_voltage() {
    // the sensor's open top as an [[electrode]] with charge = 0 instead of a dirichlet group
    let (h, p) = (0.5, 0.01);
    let open = -p * E33 * h / (C33 * EPS33 + E33 * E33);
    let mut scene = sensor(true, p, 0.0);
    scene.dirichlet.retain(|d| d.group != "top");
    scene.electrode = Some(
        problem::ElectrodeSpec {
            group: "top".into(),
            charge: Some(0.0),
            name: Some("sense".into()),
            ..Default::default()
        }
        .into(),
    );
    let s = problem::solve(&scene, None, &mut problem::Silent).unwrap();
    let sense = s.report.terminals.iter().find(|t| t.group == "sense").unwrap();
    assert!(sense.floating);
    assert!(
        (sense.potential - open).abs() < 1e-10 * open.abs(),
        "{} against {open}",
        sense.potential
    );
}

#[test]
fn electrodes_that_cannot_be_are_refused_by_name() {
    let (base, _) = files::scene_file::load("actuator", &["mesh.n=8".into()]).unwrap();
    let with = |e: Vec<problem::ElectrodeSpec>| {
        let mut s = base.clone();
        s.electrode = Some(problem::Electrodes::Many(e));
        problem::solve(&s, None, &mut problem::Silent)
            .err()
            .unwrap()
            .to_string()
    };
    let both = problem::ElectrodeSpec {
        charge: Some(0.0),
        ..problem::ElectrodeSpec::at("top", 1.0)
    };
    assert!(with(vec![both]).contains("a voltage (electrode.v) and a charge"));
    let neither = problem::ElectrodeSpec {
        group: "top".into(),
        ..Default::default()
    };
    assert!(with(vec![neither]).contains("neither a voltage"));
    let e = with(vec![
        problem::ElectrodeSpec::at("top", 1.0),
        problem::ElectrodeSpec::at("top", 2.0),
    ]);
    assert!(e.contains("electrode.v") || e.contains("gets"), "{e}");
    let named = |n: &str| problem::ElectrodeSpec {
        name: Some(n.into()),
        ..problem::ElectrodeSpec::at("top", 1.0)
    };
    assert!(with(vec![named("a"), named("a")]).contains("two electrodes make the group `a`"));
    assert!(with(vec![named("bottom")]).contains("would replace the mesh's own group"));
    // a floating electrode touching a grounded side: one conductor
    let floating_top = problem::ElectrodeSpec {
        group: "top".into(),
        charge: Some(0.0),
        ..Default::default()
    };
    assert!(with(vec![floating_top]).contains("one conductor"));
}

/// The one convention for charge (docs/theory.md, "Signs that every output shares"): on every
/// shipped scene with terminals, at its smoke size, the charges on all the conductors around
/// the body (its terminals, a conducting foundation or tip) sum to 0 (Gauss: the flux is
/// divergence-free; skipped where an exact solution adds a body or surface charge); and a
/// charge reported reads back as the same input: a terminal at a prescribed potential made
/// floating with its reported charge floats at that potential, and a conducting tip or
/// foundation given its reported charge (`contact.charge`) finds its potential again.
#[test]
fn charges_read_back_and_sum_to_zero() {
    use problem::ExactKind;
    let solve = |name: &str, sets: &[String]| {
        let (scene, _) = files::scene_file::load(name, sets).unwrap();
        (problem::solve(&scene, None, &mut problem::Silent).unwrap(), scene)
    };
    let mut checked = 0;
    for (name, text) in files::scene_file::SHIPPED {
        let scene = files::scene_file::parse(text, name, &[]).unwrap();
        let sized = scene.mesh.smoke();
        let (s, scene) = solve(name, &sized);
        let r = &s.report;
        if r.terminals.is_empty() {
            continue;
        }
        let charges: Vec<f64> = r.terminals.iter().map(|t| t.charge).chain(r.contact.charge).collect();
        let scale = charges.iter().fold(0.0f64, |m, q| m.max(q.abs()));
        let added = matches!(
            scene.exact.as_ref().map(|e| e.kind),
            Some(ExactKind::Manufactured | ExactKind::ManufacturedContact | ExactKind::Affine)
        );
        if !added {
            // a lone conductor carries no charge: round-off against the scenes' charges
            // (1e-3..1); the sum of its nodes' reactions leaves 5e-14 to 1e-12 (indent-cone's
            // grounded face at n = 48 to 96, with every contact point condensed or only those
            // the tip can touch)
            let sum: f64 = charges.iter().sum();
            assert!(
                sum.abs() <= 1e-9 * scale.max(1e-3),
                "{name}: the charges {charges:?} sum to {sum}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 5, "Gauss checked on {checked} scenes");

    // the actuator's electrode (at 0.05) made floating with the charge it carried
    let (at_v, _) = solve("actuator", &["mesh.n=16".into()]);
    let q = at_v
        .report
        .terminals
        .iter()
        .find(|t| t.group == "electrode")
        .unwrap()
        .charge;
    assert!(
        q > 0.0,
        "an electrode at the higher potential carries positive charge: {q}"
    );
    let (floated, _) = solve(
        "actuator",
        &[
            "mesh.n=16".into(),
            format!("electrode.charge={q:e}"),
            "~electrode.v".into(),
        ],
    );
    let t = floated
        .report
        .terminals
        .iter()
        .find(|t| t.group == "electrode")
        .unwrap();
    assert!(t.floating);
    assert!((t.potential - 0.05).abs() <= 1e-9 * 0.05, "floats at {}", t.potential);
    assert!(
        (t.charge - q).abs() <= 1e-12 * q.abs(),
        "reads back {} against {q}",
        t.charge
    );

    // a grounded conducting tip's charge given back to the tip: it floats at 0 again
    let tip = |sets: &[String]| {
        let (s, _) = solve("indent-sphere", sets);
        let ind = s.report.indenter.unwrap();
        (
            ind.potential.unwrap(),
            ind.charge.unwrap(),
            s.report.contact.charge.unwrap(),
        )
    };
    let base = ["mesh.n=40".to_string(), "contact.electric=\"conducting\"".into()];
    let (v0, q0, zone) = tip(&base);
    assert_eq!(v0, 0.0);
    assert!((zone - q0).abs() <= 1e-12 * q0.abs(), "the zone's charge is the tip's");
    let mut given = base.to_vec();
    given.push(format!("contact.charge={q0:e}"));
    let (v1, q1, _) = tip(&given);
    assert!((q1 - q0).abs() <= 1e-9 * q0.abs(), "{q1} against {q0}");
    // the potential that carries q0: 0, within what a relative 1e-6 of the charge moves it
    let mut lifted = base.to_vec();
    lifted.push("contact.foundation_potential=1e-3".into());
    let slope = (tip(&lifted).1 - q0) / 1e-3;
    assert!(
        v1.abs() <= 1e-6 * (q0 / slope).abs(),
        "floats at {v1} (dQ/dψ = {slope})"
    );
}

/// The round trip on every shipped scene with terminals (smoke size): each terminal held at a
/// potential by a Dirichlet condition or an electrode, made floating with the charge the run
/// reported on it, floats at that potential and reads that charge back. Skipped where the
/// floating terminal would be refused (it touches another terminal: one conductor) or where
/// no other potential would remain to fix the potentials' level.
#[test]
fn every_terminal_floated_with_its_charge_keeps_its_potential() {
    use problem::{Electrodes, Silent};
    let mut checked = 0;
    for (name, text) in files::scene_file::SHIPPED {
        let base = files::scene_file::parse(text, name, &[]).unwrap();
        let (scene, _) = files::scene_file::load(name, &base.mesh.smoke()).unwrap();
        let Ok(solved) = problem::solve(&scene, None, &mut Silent) else {
            continue;
        };
        let terminals = &solved.report.terminals;
        let scale = terminals.iter().fold(0.0f64, |m, t| m.max(t.potential.abs()));
        let fixed = terminals.iter().filter(|t| !t.floating).count();
        if fixed < 2 || scale == 0.0 {
            continue;
        }
        // each terminal's own condition, made floating at its reported charge
        let mut variants: Vec<(String, problem::Scene)> = vec![];
        for (k, d) in scene.dirichlet.iter().enumerate() {
            let Some(t) = terminals.iter().find(|t| t.group == d.group && !t.floating) else {
                continue;
            };
            let mut s = scene.clone();
            s.dirichlet[k].phi = None;
            s.dirichlet[k].charge = Some(t.charge);
            variants.push((t.group.clone(), s));
        }
        for (k, e) in scene.electrodes().iter().enumerate() {
            let group = e.group_name(k);
            let Some(t) = terminals.iter().find(|t| t.group == group && !t.floating) else {
                continue;
            };
            let mut s = scene.clone();
            let spec = match s.electrode.as_mut().unwrap() {
                Electrodes::One(one) => one,
                Electrodes::Many(many) => &mut many[k],
            };
            spec.v = None;
            spec.charge = Some(t.charge);
            variants.push((group, s));
        }
        for (group, s) in variants {
            let floated = match problem::solve(&s, None, &mut Silent) {
                Ok(r) => r,
                // a terminal that touches another is one conductor with it: refused by key
                Err(e) if e.to_string().contains("one conductor") => continue,
                Err(e) => panic!("{name}, `{group}` floated: {e}"),
            };
            let (before, after) = (
                terminals.iter().find(|t| t.group == group).unwrap(),
                floated.report.terminals.iter().find(|t| t.group == group).unwrap(),
            );
            assert!(after.floating);
            assert!(
                (after.potential - before.potential).abs() <= 1e-8 * scale,
                "{name}, `{group}`: floats at {} against {}",
                after.potential,
                before.potential
            );
            assert!(
                (after.charge - before.charge).abs() <= 1e-10 * before.charge.abs().max(1e-300),
                "{name}, `{group}`: reads back {} against {}",
                after.charge,
                before.charge
            );
            checked += 1;
        }
    }
    eprintln!("the round trip ran on {checked} terminals");
    assert!(checked >= 3, "the round trip ran on {checked} terminals");
}

/// An electrode given by `x_range` is the facets of its group wholly inside the range: where
/// the mesh has no node at an end, it is shorter than asked, and the run says so (a note, and
/// run.json's `covered_x`) instead of solving another electrode silently.
#[test]
fn an_electrode_narrower_than_its_range_is_noted() {
    let solve = |n: usize| {
        let (scene, _) = files::scene_file::load("actuator", &[format!("mesh.n={n}")]).unwrap();
        problem::solve(&scene, None, &mut problem::Silent).unwrap()
    };
    let covered = |s: &problem::Solution| {
        let t = s.report.terminals.iter().find(|t| t.group == "electrode").unwrap();
        t.covered_x.unwrap()
    };
    // n = 8: nodes every 1/8 in x, on 0.25 and 1.75; n = 10: every 0.1, none there
    let on = solve(8);
    assert_eq!(covered(&on), [0.25, 1.75]);
    let off = solve(10);
    let [a, b] = covered(&off);
    assert!((a - 0.3).abs() < 1e-12 && (b - 1.7).abs() < 1e-12, "{a} {b}");
    let (scene, _) = files::scene_file::load("actuator", &["mesh.n=10".into()]).unwrap();
    let valid = scene.validate().unwrap();
    let setup = problem::backend::setup(valid, None).unwrap();
    let narrowed = &setup.notes.narrowed_electrodes;
    assert_eq!(narrowed.len(), 1);
    assert_eq!(narrowed[0].asked, [0.25, 1.75]);
    let setup = problem::backend::setup(
        files::scene_file::load("actuator", &["mesh.n=8".into()])
            .unwrap()
            .0
            .validate()
            .unwrap(),
        None,
    )
    .unwrap();
    assert!(setup.notes.narrowed_electrodes.is_empty());
    // the capacitance matrix, whose electrode's length it scales with, says so too
    let (scene, _) = files::scene_file::load("actuator", &["mesh.n=10".into()]).unwrap();
    let c = problem::capacitance(&scene, None).unwrap();
    assert!(
        c.notes.iter().any(|n| n.contains("covers x in [0.3, 1.7]")),
        "{:?}",
        c.notes
    );
}

/// A region by box is the cells whose centroids lie in the box: where the mesh has no cell
/// faces on the box's sides its boundary is a staircase (a layer thicker or thinner than asked,
/// or jagged), and the set-up says so with the extent its cells span.
#[test]
fn a_region_off_the_mesh_lines_is_noted() {
    let notes = |n: usize| {
        let (scene, _) = files::scene_file::load("layered", &[format!("mesh.n={n}")]).unwrap();
        problem::backend::setup(scene.validate().unwrap(), None)
            .unwrap()
            .notes
            .staircase_regions
    };
    // n = 10: y = 0.8 is a line of the mesh; n = 8: rows at 0.75 and 0.875
    assert!(notes(10).is_empty());
    let off = notes(8);
    let pzt = off.iter().find(|r| r.name == "pzt").unwrap();
    assert_eq!(pzt.asked[1], [0.8, 1.0]);
    assert_eq!(pzt.covered[1], [0.75, 1.0]);
    // the shipped default puts the interface on a line
    let (scene, _) = files::scene_file::load("layered", &[]).unwrap();
    assert!(problem::backend::setup(scene.validate().unwrap(), None)
        .unwrap()
        .notes
        .staircase_regions
        .is_empty());
}

/// A mesh with nothing to note says nothing: a run prints no empty `note:` line (a seam of no
/// facets still carries its dimension, which once made the notes differ from the default).
#[test]
fn a_mesh_with_nothing_to_note_says_nothing() {
    for (name, n) in [("paper", 8), ("paper-3d", 4), ("sensor", 4), ("layered", 10)] {
        let (scene, _) = files::scene_file::load(name, &[format!("mesh.n={n}")]).unwrap();
        let setup = problem::backend::setup(scene.validate().unwrap(), None).unwrap();
        assert!(setup.notes.is_empty(), "{name}: {:?}", setup.notes);
    }
}
