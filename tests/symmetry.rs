//! Prescribed components on contact nodes (issue 20, class 1): a half model with a symmetry
//! roller (`ux = 0` on the plane x = 1) through the contact face must give the full model's
//! answer on a mesh that is its own mirror image, to round-off: displacements, potentials and
//! contact pressures; the roller's nodes stay in contact, and their tangential multiplier is 0
//! (the full model's, by symmetry). A family: 2D and 3D, Signorini, Tresca and Coulomb, a gap.
//! And the other combinations of prescribed components and contact: a roller along the normal
//! over the whole face is refused with its reason, one across an oblique normal too, and a
//! prescribed normal displacement leaves its node to its support (the condition wins, and is
//! counted where it holds the node inside the foundation).

use mesh::Mesh;
use problem::{
    ContactLaw, ContactSpec, DirichletSpec, LoadSpec, MaterialSpec, MeshSpec, Scene, Silent, Solution, Strategy,
};
use std::collections::BTreeMap;

/// The mesh and its mirror image in the plane x = `plane`, joined there: the original's nodes
/// keep their numbers (the mirror's follow), `left` stays, the mirror's `left` becomes
/// `right`, the groups along the body (`bottom`, `top`, `front`, `back`) take both halves, and
/// the original's `right` (the plane) is dropped.
fn mirrored(m: &Mesh, plane: f64) -> Mesh {
    let n = m.n_nodes();
    let on_plane = |v: usize| (m.points[v][0] - plane).abs() < 1e-12;
    let mut points = m.points.clone();
    let mut image = vec![0; n];
    for v in 0..n {
        image[v] = if on_plane(v) {
            v
        } else {
            let mut p = m.points[v];
            p[0] = 2.0 * plane - p[0];
            points.push(p);
            points.len() - 1
        };
    }
    let mut cells = m.cells.clone();
    let k = m.kind.n_nodes();
    for c in m.iter_cells() {
        let mut mc: Vec<usize> = c.iter().map(|&v| image[v]).collect();
        mc.swap(1, 2); // a reflection turns the orientation round
        assert_eq!(k, mc.len());
        cells.extend(mc);
    }
    let mut boundaries = BTreeMap::new();
    for (name, g) in &m.boundaries {
        let mirror: Vec<usize> = g.facets.iter().map(|&v| image[v]).collect();
        match name.as_str() {
            "left" => {
                boundaries.insert("left".to_string(), g.clone());
                let mut r = g.clone();
                r.facets = mirror;
                boundaries.insert("right".to_string(), r);
            }
            "right" => {}
            _ => {
                let mut both = g.clone();
                both.facets.extend(mirror);
                boundaries.insert(name.clone(), both);
            }
        }
    }
    let n_cells = cells.len() / k;
    let mesh = Mesh {
        dim: m.dim,
        kind: m.kind,
        points,
        cells,
        boundaries,
        regions: [("body".to_string(), (0..n_cells).collect())].into(),
        reoriented_cells: 0,
        other_groups: Default::default(),
    };
    mesh.check().expect("the mirrored mesh is a mesh");
    mesh
}

/// The paper's block (2D) or box (3D), poled across the contact face: clamped at x = 0 (and
/// at x = 2 for the full model, or held by the roller `ux = 0` at x = 1 for the half).
fn block(dim: usize, law: ContactLaw, gap: f64, half: bool) -> Scene {
    let zero = vec![0.0; dim];
    let clamped = |group: &str| DirichletSpec {
        group: group.into(),
        u: Some(zero.clone()),
        phi: Some(0.0),
        ..Default::default()
    };
    let mut dirichlet = vec![clamped("left")];
    dirichlet.push(if half {
        DirichletSpec {
            group: "right".into(),
            ux: Some(0.0),
            ..Default::default()
        }
    } else {
        clamped("right")
    });
    let mut down = vec![0.0; dim];
    down[dim - 1] = -1.0;
    let mut up = vec![0.0; dim];
    up[dim - 1] = 1.0;
    let mut contact = ContactSpec::new("bottom", law, &down);
    contact.gap = gap;
    match law {
        ContactLaw::Coulomb => contact.friction = Some(0.6),
        ContactLaw::Tresca => contact.slip_bound = Some(0.3),
        _ => {}
    }
    let mut poling = [0.0; 3];
    poling[dim - 1] = 1.0;
    Scene {
        name: "symmetry".into(),
        description: String::new(),
        mesh: MeshSpec::given(),
        material: vec![MaterialSpec::crystal_6mm(
            "body",
            [121.0, 75.4, 75.2, 111.0, 21.1, 22.6],
            [-5.4, 15.8, 12.3],
            [8.11, 7.35],
            poling,
        )],
        dirichlet,
        load: Some(
            LoadSpec {
                group: "top".into(),
                p: -2.0,
                direction: up,
            }
            .into(),
        ),
        electrode: None,
        contact: Some(contact.into()),
        solver: Default::default(),
        exact: None,
        path: None,
        units: None,
    }
}

fn solve(scene: &Scene, mesh: Mesh) -> Solution {
    problem::solve(scene, Some(mesh), &mut Silent).unwrap_or_else(|e| panic!("{e}"))
}

/// The half model against the full one: every field at the half's nodes, and the contact
/// multipliers at its points, to 1e-9 relative (the strategies' tolerance is 1e-12 here).
fn half_equals_full(dim: usize, law: ContactLaw, gap: f64, strategy: Strategy) {
    let half_mesh = if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [1.0, 1.0], 8, 8)
    } else {
        mesh::box_tet([0.0; 3], [1.0; 3], 3, 3, 3)
    };
    let full_mesh = mirrored(&half_mesh, 1.0);
    let with = |mut s: Scene| {
        s.solver.strategy = strategy;
        s.solver.tol = 1e-12;
        s
    };
    let half = solve(&with(block(dim, law, gap, true)), half_mesh.clone());
    let full = solve(&with(block(dim, law, gap, false)), full_mesh);
    let what = format!("{dim}D {law:?} gap {gap} {strategy}");
    let scale = full.u.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(scale > 0.0, "{what}: the body moves");
    for v in 0..half_mesh.n_nodes() {
        for k in 0..dim {
            let d = (half.u[v][k] - full.u[v][k]).abs();
            assert!(
                d <= 1e-9 * scale,
                "{what}: u[{v}][{k}] {} against {}",
                half.u[v][k],
                full.u[v][k]
            );
        }
    }
    let phi_scale = full.phi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for v in 0..half_mesh.n_nodes() {
        assert!(
            (half.phi[v] - full.phi[v]).abs() <= 1e-9 * phi_scale,
            "{what}: phi[{v}]"
        );
    }
    // the multipliers: the half's points are the full's of the same nodes
    let (hc, fc) = (half.contact.as_ref().unwrap(), full.contact.as_ref().unwrap());
    let p_scale = fc.solution.lambda.normal.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let nt = hc.solution.lambda.n_tangential();
    let mut on_plane = 0;
    for (i, &node) in hc.nodes.iter().enumerate() {
        let j = fc
            .nodes
            .iter()
            .position(|&v| v == node)
            .expect("the full model has the node");
        let (ln_h, ln_f) = (hc.solution.lambda.normal[i], fc.solution.lambda.normal[j]);
        assert!(
            (ln_h - ln_f).abs() <= 1e-9 * p_scale.max(1e-300),
            "{what}: λ_n at node {node}: {ln_h} against {ln_f}"
        );
        for q in 0..nt {
            let (th, tf) = (
                hc.solution.lambda.tangential[i * nt + q],
                fc.solution.lambda.tangential[j * nt + q],
            );
            if (half_mesh.points[node][0] - 1.0).abs() < 1e-12 && q == 0 {
                on_plane += 1;
                assert_eq!(th, 0.0, "{what}: the roller's tangent is held");
                assert!(
                    tf.abs() <= 1e-9 * p_scale.max(1e-300),
                    "{what}: the full model's λ_t on the plane {tf}"
                );
            } else {
                assert!(
                    (th - tf).abs() <= 1e-9 * p_scale.max(1e-300),
                    "{what}: λ_t at node {node}"
                );
            }
        }
        // a node of the contact face never passes the foundation
        let u_n = -half.u[node][dim - 1];
        assert!(u_n <= gap + 1e-12, "{what}: node {node} sinks: u_n = {u_n}");
    }
    if nt > 0 {
        assert!(on_plane > 0, "{what}: the roller's nodes are contact points");
        assert_eq!(half.report.contact.held_tangent_points, on_plane);
    }
    assert!(half.report.residuals.complementarity <= 1e-10, "{what}");
}

#[test]
fn a_symmetry_roller_on_the_contact_face_gives_the_full_models_half_in_2d() {
    for law in [ContactLaw::Coulomb, ContactLaw::Tresca, ContactLaw::Signorini] {
        for gap in [0.0, 1e-3] {
            half_equals_full(2, law, gap, Strategy::NewtonCondensed);
        }
    }
    // the first-order strategies, on the condensed compliance and through full solves
    for strategy in [Strategy::ApgCondensed, Strategy::UzawaDirect, Strategy::UzawaSchurPcg] {
        half_equals_full(2, ContactLaw::Tresca, 0.0, strategy);
    }
}

#[test]
fn a_symmetry_roller_on_the_contact_face_gives_the_full_models_half_in_3d() {
    for law in [ContactLaw::Coulomb, ContactLaw::Tresca, ContactLaw::Signorini] {
        half_equals_full(3, law, 0.0, Strategy::NewtonCondensed);
    }
}

fn refusal(scene: &Scene, mesh: Mesh) -> String {
    match problem::solve(scene, Some(mesh), &mut Silent) {
        Ok(_) => panic!("solved, not refused"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_other_combinations_are_solved_or_refused_with_their_reason() {
    // a roller along the normal on the whole contact face: the support holds every node
    let mut s = block(2, ContactLaw::Coulomb, 0.0, false);
    s.dirichlet.push(DirichletSpec {
        group: "bottom".into(),
        uy: Some(0.0),
        ..Default::default()
    });
    let m = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4);
    let e = refusal(&s, m.clone());
    assert!(
        e.contains("prescribe the normal displacement of all its") && e.contains("contact never acts"),
        "{e}"
    );
    // the side x = 2 lifted, or pushed down, by a prescribed uy: its corner on the contact face
    // is left to its support (the Dirichlet condition wins), counted where it is held inside
    // the foundation, and never a contact point
    let mut s = block(2, ContactLaw::Coulomb, 0.0, false);
    for (uy, inside) in [(0.01, 0), (-0.01, 1)] {
        s.dirichlet[1] = DirichletSpec {
            group: "right".into(),
            uy: Some(uy),
            ..Default::default()
        };
        let held = solve(&s, m.clone());
        assert_eq!(held.report.contact.held_nodes, 2, "both corners: clamped, and moved");
        assert_eq!(held.report.contact.held_inside, inside);
        assert!(held
            .contact
            .as_ref()
            .unwrap()
            .nodes
            .iter()
            .all(|&v| m.points[v][0] < 2.0));
        assert!((held.u[8][1] - uy).abs() < 1e-15, "the corner (2, 0) where it is put");
    }
    // a roller across an oblique normal
    let mut s = block(2, ContactLaw::Coulomb, 0.0, false);
    s.first_contact_mut().unwrap().normal = vec![0.3, -1.0];
    s.dirichlet.push(DirichletSpec {
        group: "bottom".into(),
        ux: Some(0.0),
        ..Default::default()
    });
    let e = refusal(&s, m.clone());
    assert!(e.contains("lies across the contact normal") && e.contains("ux"), "{e}");
    // a tangential roller on the whole face: every point frictionless (held), solved
    let mut s = block(2, ContactLaw::Coulomb, 0.0, false);
    s.dirichlet.push(DirichletSpec {
        group: "bottom".into(),
        ux: Some(0.0),
        ..Default::default()
    });
    let held = solve(&s, m.clone());
    let c = held.contact.as_ref().unwrap();
    assert!(c.solution.lambda.tangential.iter().all(|&t| t == 0.0));
    assert!(c.solution.lambda.normal.iter().any(|&l| l > 0.0));
    assert_eq!(held.report.contact.held_tangent_points, held.report.contact.n_points);
    // its answer is the frictionless answer with ux = 0 on the face: a body glued sideways
    // and free to lift off, solved with Signorini alone
    let mut signorini = s.clone();
    signorini.contact = Some(ContactSpec::new("bottom", ContactLaw::Signorini, &[0.0, -1.0]).into());
    let other = solve(&signorini, m);
    for (a, b) in held.u.iter().zip(&other.u) {
        assert!((a[1] - b[1]).abs() <= 1e-12 * (1.0 + a[1].abs()));
    }
}
