//! Runs in which no rank holds the whole mesh (feature `petsc`, issue 45): each rank generates
//! its piece, assembles its own cells and holds the solution at its piece's nodes only. On 1, 2
//! and 4 ranks (4 oversubscribed on a 2-core machine) the pieces' nodal solution and recovered
//! fields equal the default backend's on the whole mesh, node by node and cell by cell.
#![cfg(feature = "petsc")]

use files::scene_file;
use petsc::testing::on_ranks;
use petsc::Petsc;

/// A shipped scene with the overrides `sets`, for the default backend and for PETSc.
fn both(name: &str, sets: &[&str]) -> (problem::Scene, problem::Scene) {
    let text = scene_file::SHIPPED
        .iter()
        .find(|(n, _)| *n == name)
        .expect("a shipped scene")
        .1;
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let faer = scene_file::parse(text, name, &sets).expect("the scene reads");
    let mut with = sets;
    with.push("solver.backend=\"petsc\"".into());
    (faer, scene_file::parse(text, name, &with).expect("the scene reads"))
}

/// Scenes without contact: coupled 2D and 3D, a partial electrode at a non-zero potential,
/// prescribed displacements all round (manufactured), a purely elastic body (CG with GAMG), a
/// box cut into blocks along two axes.
const CASES: &[(&str, &[&str])] = &[
    ("paper", &["mesh.n=32", "contact.law=\"none\""]),
    ("paper-3d", &["mesh.n=6", "contact.law=\"none\""]),
    ("actuator", &["mesh.n=16", "contact.law=\"none\""]),
    ("manufactured", &["mesh.n=16"]),
    ("paper-elastic", &["mesh.n=32", "contact.law=\"none\""]),
    (
        "paper-3d",
        &["mesh.n=4", "mesh.hi=[1.0,1.0,1.0]", "contact.law=\"none\""],
    ),
];

/// Scenes with contact that the active sets hold: Signorini, Tresca (uniform and a profile),
/// Coulomb in 2D and 3D, a roller through the contact face, a purely elastic body.
const CONTACT_CASES: &[(&str, &[&str])] = &[
    ("paper", &["mesh.n=32"]),
    ("paper-slip", &["mesh.n=32"]),
    ("paper-tresca", &["mesh.n=32"]),
    (
        "paper-tresca",
        &[
            "mesh.n=32",
            "~contact.slip_bound",
            "contact.slip_bound_profile={along=[1.0,0.0],at=[0.0,2.0],value=[0.01,0.1]}",
        ],
    ),
    ("paper-frictionless", &["mesh.n=32"]),
    ("paper-elastic", &["mesh.n=32"]),
    ("paper-3d", &["mesh.n=6"]),
    ("paper-3d", &["mesh.n=6", "contact.friction=0.1"]),
    (
        "paper-3d",
        &["mesh.n=6", "contact.friction=0.1", "~dirichlet.0.u", "dirichlet.0.ux=0"],
    ),
];

/// The largest difference over the largest magnitude of `whole`, comparing each of the piece's
/// items that `take` selects with the whole mesh's item it maps to.
fn farthest(whole: &[f64], piece: &[f64], map: &[usize], width: usize, take: impl Fn(usize) -> bool) -> f64 {
    let scale = whole.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (i, &g) in map.iter().enumerate().filter(|(i, _)| take(*i)) {
        for k in 0..width {
            worst = worst.max((piece[i * width + k] - whole[g * width + k]).abs());
        }
    }
    worst / scale
}

fn agree_on_pieces(p: &Petsc) {
    for (name, sets) in CASES {
        let (faer, scene) = both(name, sets);
        let whole = problem::solve(&faer, None, &mut problem::Silent).expect("the whole mesh's run");
        let s = distributed::solve_on_pieces(p, &scene, problem::Limits::default(), &mut problem::Silent)
            .unwrap_or_else(|e| panic!("{name} {sets:?} on pieces: {e}"));
        let piece = &s.piece;
        let rank = p.rank();
        assert_eq!(piece.n_global_nodes, whole.mesh.n_nodes());
        assert_eq!(piece.n_global_cells, whole.mesh.n_cells());
        assert!(
            piece.mesh.n_cells() < whole.mesh.n_cells() || p.size() == 1,
            "{name}: a rank holds the whole mesh"
        );
        let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
        let owned = |v: usize| piece.node_rank[v] == rank;
        // every node of the piece, the ghosts' fetched from their owners
        let du = farthest(&flat(&whole.u), &flat(&s.u), &piece.global_node, 3, |_| true);
        let dphi = farthest(&whole.phi, &s.phi, &piece.global_node, 1, |_| true);
        let ds = farthest(
            &whole.fields.stress,
            &s.fields.stress,
            &piece.global_cell,
            whole.fields.stress.len() / whole.mesh.n_cells(),
            |_| true,
        );
        let dd = farthest(
            &whole.fields.electric_displacement,
            &s.fields.electric_displacement,
            &piece.global_cell,
            whole.fields.electric_displacement.len() / whole.mesh.n_cells(),
            |_| true,
        );
        let mine = (0..piece.node_rank.len()).filter(|&v| owned(v)).count();
        let all = p.sum(&[mine as f64]).expect("a sum")[0];
        assert_eq!(all as usize, whole.mesh.n_nodes(), "{name}: each node owned once");
        eprintln!(
            "{name} {sets:?} rank {rank}/{}: blocks {:?}, {} of {} cells held, {} iterations; u {du:.1e}, phi {dphi:.1e}, stress {ds:.1e}, D {dd:.1e}",
            p.size(),
            s.blocks,
            piece.mesh.n_cells(),
            whole.mesh.n_cells(),
            s.iterations
        );
        for (what, d) in [("u", du), ("phi", dphi), ("stress", ds), ("D", dd)] {
            assert!(d < 1e-7, "{name} {sets:?} rank {rank}: {what} differs by {d:.2e}");
        }
    }
}

/// The contact cases on pieces against the default backend's whole run: nodal solution, and
/// each rank's multipliers at its own points against the whole run's at the same nodes.
fn contact_on_pieces(p: &Petsc) {
    for (name, sets) in CONTACT_CASES {
        let (faer, scene) = both(name, sets);
        let whole = problem::solve(&faer, None, &mut problem::Silent).expect("the whole mesh's run");
        let s = distributed::solve_on_pieces(p, &scene, problem::Limits::default(), &mut problem::Silent)
            .unwrap_or_else(|e| panic!("{name} {sets:?} on pieces: {e}"));
        let piece = &s.piece;
        let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
        let du = farthest(&flat(&whole.u), &flat(&s.u), &piece.global_node, 3, |_| true);
        let dphi = farthest(&whole.phi, &s.phi, &piece.global_node, 1, |_| true);
        let (wc, c) = (
            whole.contact.as_ref().expect("contact"),
            s.contact.as_ref().expect("contact"),
        );
        let at: std::collections::HashMap<usize, usize> = wc.nodes.iter().enumerate().map(|(i, &v)| (v, i)).collect();
        let (wl, l) = (&wc.solution.lambda, &c.solution.lambda);
        let nt = l.n_tangential();
        let scale = wl.normal.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
        let mut dl = 0.0f64;
        for (i, &v) in c.boundary.nodes.iter().enumerate() {
            let j = at[&piece.global_node[v]];
            dl = dl.max((l.normal[i] - wl.normal[j]).abs());
            // (frictionless: no tangential multipliers)
            for q in (0..nt).filter(|_| !l.tangential.is_empty() && !wl.tangential.is_empty()) {
                dl = dl.max((l.tangential[i * nt + q] - wl.tangential[j * nt + q]).abs());
            }
        }
        let dl = dl / scale;
        let df = (c.normal_force - whole.report.contact.normal_force).abs() / whole.report.contact.normal_force.abs();
        assert_eq!(c.points, wc.nodes.len(), "{name}: the points over the ranks");
        eprintln!(
            "{name} {sets:?} rank {}/{}: {} steps, residual {:.1e}, equilibrium {:.1e}; u {du:.1e}, phi {dphi:.1e}, multipliers {dl:.1e}, normal force {df:.1e}",
            p.rank(),
            p.size(),
            c.steps,
            c.residual,
            c.equilibrium
        );
        assert!(c.residual <= scene.solver.tol, "{name}: residual {}", c.residual);
        for (what, d) in [("u", du), ("phi", dphi), ("multipliers", dl), ("normal force", df)] {
            assert!(d < 1e-7, "{name} {sets:?} rank {}: {what} differs by {d:.2e}", p.rank());
        }
    }
}

#[test]
fn contact_on_pieces_agrees_with_the_whole_mesh_on_one_rank() {
    on_ranks(
        "contact_on_pieces_agrees_with_the_whole_mesh_on_one_rank",
        1,
        contact_on_pieces,
    );
}

#[test]
fn contact_on_pieces_agrees_with_the_whole_mesh_on_two_ranks() {
    on_ranks(
        "contact_on_pieces_agrees_with_the_whole_mesh_on_two_ranks",
        2,
        contact_on_pieces,
    );
}

#[test]
fn contact_on_pieces_agrees_with_the_whole_mesh_on_four_ranks() {
    on_ranks(
        "contact_on_pieces_agrees_with_the_whole_mesh_on_four_ranks",
        4,
        contact_on_pieces,
    );
}

#[test]
fn pieces_agree_with_the_whole_mesh_on_one_rank() {
    on_ranks("pieces_agree_with_the_whole_mesh_on_one_rank", 1, agree_on_pieces);
}

#[test]
fn pieces_agree_with_the_whole_mesh_on_two_ranks() {
    on_ranks("pieces_agree_with_the_whole_mesh_on_two_ranks", 2, agree_on_pieces);
}

#[test]
fn pieces_agree_with_the_whole_mesh_on_four_ranks() {
    on_ranks("pieces_agree_with_the_whole_mesh_on_four_ranks", 4, agree_on_pieces);
}

/// What a run on pieces does not solve yet is refused by its key, and so are more ranks than
/// the mesh's blocks can take and a piece over a rank's memory, on every rank alike.
#[test]
fn what_pieces_do_not_solve_is_refused_by_key() {
    on_ranks("what_pieces_do_not_solve_is_refused_by_key", 2, |p| {
        let refused = |name: &str, sets: &[&str]| {
            let (_, scene) = both(name, sets);
            match distributed::solve_on_pieces(p, &scene, problem::Limits::default(), &mut problem::Silent) {
                Ok(_) => panic!("{name} {sets:?} solved on pieces"),
                Err(e) => e.to_string(),
            }
        };
        let e = refused("paper-cycle", &["mesh.n=8"]);
        assert!(e.contains("path") && e.contains("pieces"), "{e}");
        let e = refused("indent-sphere", &["mesh.n=8"]);
        assert!(e.contains("mesh.grading") && e.contains("pieces"), "{e}");
        let e = refused("actuator", &["mesh.n=8", "contact.law=\"none\"", "mesh.grading=4.0"]);
        assert!(e.contains("mesh.grading"), "{e}");
        let e = refused("paper", &["mesh.n=1", "contact.law=\"none\"", "mesh.hi=[1.0,1.0]"]);
        assert!(e.contains("mesh.n") && e.contains("2 ranks"), "{e}");
        let (_, scene) = both("paper-3d", &["mesh.n=16", "contact.law=\"none\""]);
        let limits = problem::Limits {
            memory_bytes: Some(1 << 20),
            memory_limit: Some("a test's limit"),
            ..Default::default()
        };
        let e = distributed::solve_on_pieces(p, &scene, limits, &mut problem::Silent)
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("rank {} of 2", p.rank())) && e.contains("a test's limit"),
            "{e}"
        );
    });
}
