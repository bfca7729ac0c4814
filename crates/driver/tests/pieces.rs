//! Runs in which no rank holds the whole mesh (feature `petsc`, issue 45): each rank generates
//! its piece, assembles its own cells and holds the solution at its piece's nodes only. On 1, 2
//! and 4 ranks (4 oversubscribed on a 2-core machine) the pieces' nodal solution and recovered
//! fields equal the default backend's on the whole mesh, node by node and cell by cell.
#![cfg(feature = "petsc")]

use files::scene_file;
use petsc::testing::on_ranks;
use petsc::Petsc;

/// A shipped scene, or one of the scenes of several contact zones made here from them
/// ([`zoned`]), with the overrides `sets`, for the default backend and for PETSc.
fn both(name: &str, sets: &[&str]) -> (problem::Scene, problem::Scene) {
    let text = zoned(name).unwrap_or_else(|| shipped(name).to_string());
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let faer = scene_file::parse(&text, name, &sets).expect("the scene reads");
    let mut with = sets;
    with.push("solver.backend=\"petsc\"".into());
    (faer, scene_file::parse(&text, name, &with).expect("the scene reads"))
}

/// The shipped scene `name`'s text.
fn shipped(name: &str) -> &'static str {
    scene_file::SHIPPED
        .iter()
        .find(|(n, _)| *n == name)
        .expect("a shipped scene")
        .1
}

/// Scenes of several contact zones: `squeeze` and `squeeze-3d`, the paper's block pressed
/// by a plate on its top (a Tresca zone, the plate 0.05 into the block) above its Coulomb
/// foundation (the zones share no node: the clamped ends hold the corners); `corner-3d`, a
/// cube pushed into a corner by three frictionless walls that meet at its edges and corner.
fn zoned(name: &str) -> Option<String> {
    let plate = |base: &str, normal: &str| {
        shipped(base).replace("[contact]\n", "[[contact]]\n")
            + &format!(
                "\n[[contact]]\ngroup = \"top\"\nlaw = \"tresca\"\nslip_bound = 0.05\ngap = -0.05\nnormal = {normal}\n"
            )
    };
    match name {
        "squeeze" => Some(plate("paper", "[0.0, 1.0]")),
        "squeeze-3d" => Some(plate("paper-3d", "[0.0, 0.0, 1.0]")),
        "corner-3d" => {
            let mut text = String::from(
                "name = \"corner-3d\"\ndescription = \"a cube pushed into a corner by three walls\"\n[units]\nlength = \"m\"\nstress = \"GPa\"\n\
                 [mesh]\nkind = \"box\"\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\nn = 4\n\
                 [[material]]\nregion = \"body\"\nmodel = \"crystal-6mm\"\n\
                 c = [121.0, 75.4, 75.2, 111.0, 21.1, 22.6]\ne = [-5.4, 15.8, 12.3]\n\
                 permittivity = [8.11, 7.35]\npoling = [0.0, 0.0, 1.0]\n\
                 [[dirichlet]]\ngroup = \"left\"\nux = 0.0\n[[dirichlet]]\ngroup = \"front\"\nuy = 0.0\n\
                 [[dirichlet]]\ngroup = \"bottom\"\nuz = 0.0\nphi = 0.0\n",
            );
            for (group, normal) in [
                ("right", "[1.0, 0.0, 0.0]"),
                ("back", "[0.0, 1.0, 0.0]"),
                ("top", "[0.0, 0.0, 1.0]"),
            ] {
                text +=
                    &format!("[[contact]]\ngroup = \"{group}\"\nlaw = \"signorini\"\nnormal = {normal}\ngap = -1e-3\n");
            }
            Some(text)
        }
        _ => None,
    }
}

/// Scenes without contact: coupled 2D and 3D, a partial electrode at a non-zero potential, a
/// purely elastic body (CG with GAMG), a box cut into blocks along two axes.
const CASES: &[(&str, &[&str])] = &[
    ("paper", &["mesh.n=32", "contact.law=\"none\""]),
    // errors against a field solution, summed over the ranks' own cells
    ("manufactured-3d", &["mesh.n=4"]),
    // a layered body: four layers, internal electrodes on their interfaces
    ("stack", &["contact.law=\"none\""]),
    // a PZT layer on an elastic substrate: electric and non-electric cells
    ("layered", &["mesh.n=16", "contact.law=\"none\""]),
    ("patch", &[]),
    ("paper-3d", &["mesh.n=6", "contact.law=\"none\""]),
    ("actuator", &["mesh.n=16", "contact.law=\"none\""]),
    ("paper-elastic", &["mesh.n=32", "contact.law=\"none\""]),
    (
        "paper-3d",
        &["mesh.n=4", "mesh.hi=[1.0,1.0,1.0]", "contact.law=\"none\""],
    ),
    // the PZT layer across x from one cell past the cut of 2 ranks: rank 0's ghost cells are
    // the substrate's alone, and their far nodes, on the interface, carry a potential that
    // only their owner's cells show (rank 0's piece wrote 0 there, taking its own cells' word)
    (
        "layered",
        &[
            "mesh.n=16",
            "contact.law=\"none\"",
            "mesh.region.0.lo=[1.0625,0.0]",
            "mesh.region.1.hi=[1.0625,1.0]",
            "~dirichlet.0.phi",
        ],
    ),
    // floating terminals: a pressed plate's open top (its voltage found), and a box's face
    // carrying a charge, its group over several ranks (one row, the last rank's)
    // (a charge on it: an open circuit's D is round-off, on both sides)
    (
        "sensor",
        &["mesh.axisymmetric=false", "~mesh.revolve", "dirichlet.2.charge=1e-4"],
    ),
    (
        "paper-3d",
        &[
            "mesh.n=6",
            "contact.law=\"none\"",
            "~dirichlet.1.phi",
            "dirichlet.1.charge=2e-3",
        ],
    ),
    // two floating terminals, one a partial electrode, which share cells (their rows couple)
    (
        "paper-3d",
        &[
            "mesh.n=8",
            "contact.law=\"none\"",
            "~dirichlet.0.phi",
            "dirichlet.0.charge=1e-3",
            "electrode.group=\"top\"",
            "electrode.charge=-2e-3",
            "electrode.x_range=[0.25,1.75]",
        ],
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
    // a graded quarter model under a sphere: two symmetry planes through the contact face
    ("indent-sphere-3d", &["mesh.n=8"]),
    // a floating terminal (a face carrying a charge, its potential found) beside the contact
    ("paper", &["mesh.n=32", "~dirichlet.1.phi", "dirichlet.1.charge=-1e-3"]),
    (
        "paper-3d",
        &[
            "mesh.n=6",
            "contact.friction=0.1",
            "~dirichlet.1.phi",
            "dirichlet.1.charge=2e-3",
        ],
    ),
    // a contact's closed form judged on the gathered points: Hertz's cylinder, and
    // Cattaneo-Mindlin's partial slip
    ("hertz", &["mesh.n=48"]),
    ("cattaneo-mindlin", &["mesh.n=48"]),
    // a layered stack, internal electrodes on its interfaces, on a Coulomb foundation
    ("stack", &[]),
    // a PZT layer on an elastic substrate, the substrate on the foundation
    ("layered", &["mesh.n=16"]),
    // several zones: two frictionless walls meeting at a corner node, with a floating
    // electrode; three meeting at edges in 3D; a Tresca plate above a Coulomb foundation
    ("corner", &["mesh.n=16"]),
    ("corner-3d", &[]),
    ("squeeze", &["mesh.n=32"]),
    ("squeeze-3d", &["mesh.n=6"]),
    // a compliant foundation: linear in 2D, a power law in 3D, and beside the rigid plate
    ("paper-compliance", &["mesh.n=32"]),
    (
        "paper-3d",
        &["mesh.n=6", "contact.compliance={stiffness=100.0,exponent=1.5}"],
    ),
    // (at stiffness 50 one point's tangential multiplier lies within 1e-9 of its bound, where
    // the statuses' rule calls it sliding on one backend and sticking on the other, their
    // values 2e-10 apart)
    (
        "squeeze-3d",
        &["mesh.n=6", "contact.0.compliance={stiffness=500.0,exponent=2.0}"],
    ),
    // force control: the depth that carries a force, found by the same search on every rank;
    // a sphere pressed by a force beside a squeezing wall (its points alone driven)
    (
        "indent-sphere-3d",
        &["mesh.n=8", "contact.indenter.depth=0.0", "contact.indenter.force=0.1"],
    ),
    (
        "corner",
        &[
            "mesh.n=32",
            "~electrode",
            "contact.1.indenter={shape=\"sphere\",radius=2.0,force=0.05}",
            "contact.1.gap=0.0",
        ],
    ),
    // slip-weakening friction: the fixed point on the coefficients around the active sets
    ("paper-slip-weakening", &["mesh.n=32"]),
    (
        "paper-3d",
        &[
            "mesh.n=6",
            "~contact.friction",
            "contact.friction_law=\"slip-weakening\"",
            "contact.friction_static=0.3",
            "contact.friction_dynamic=0.1",
            "contact.slip_length=1e-3",
        ],
    ),
    // Tresca's law at points that separate (a curved gap): the given bound holds there too
    (
        "paper-tresca",
        &[
            "mesh.n=32",
            "contact.gap_curvature=0.05",
            "contact.gap_center=[1.0,0.0]",
        ],
    ),
    // a tall box cut along z, upside down: rank 0 holds no contact point
    (
        "paper-3d",
        &[
            "mesh.n=4",
            "mesh.hi=[1.0,1.0,2.0]",
            "contact.group=\"top\"",
            "contact.normal=[0.0,0.0,1.0]",
            "load.group=\"bottom\"",
            "load.direction=[0.0,0.0,-1.0]",
        ],
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
        let s = distributed::solve_on_pieces(
            p,
            &scene,
            distributed::PieceMesh::Generated,
            problem::Limits::default(),
            &mut problem::Silent,
        )
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
        // a coupled body on pieces: BoomerAMG on the elastic block where PETSc has hypre
        let petsc_report = s.report.petsc.as_ref().expect("the PETSc section");
        let options = &petsc_report.options;
        if options.contains("-fieldsplit_phi_pc_type hypre") {
            assert!(options.contains(distributed::PIECES_ELASTIC_BLOCK), "{options}");
        }
        let mine = (0..piece.node_rank.len()).filter(|&v| owned(v)).count();
        let all = p.sum(&[mine as f64]).expect("a sum")[0];
        assert_eq!(all as usize, whole.mesh.n_nodes(), "{name}: each node owned once");
        eprintln!(
            "{name} {sets:?} rank {rank}/{}: blocks {:?}, {} of {} cells held, {} iterations; u {du:.1e}, phi {dphi:.1e}, stress {ds:.1e}, D {dd:.1e}",
            p.size(),
            petsc_report.pieces,
            piece.mesh.n_cells(),
            whole.mesh.n_cells(),
            petsc_report.krylov_iterations
        );
        // a 2D body's pictures draw the whole mesh, which no rank holds: not planned
        if whole.mesh.dim == 2 {
            assert!(!s.report.plan.outputs.contains(&problem::Output::Deformed), "{name}");
        }
        // the per-rank unknowns are the layout's, and sum to the whole problem's
        assert_eq!(petsc_report.unknowns_per_rank.len(), p.size());
        assert_eq!(
            petsc_report.unknowns_per_rank.iter().sum::<usize>(),
            petsc_report.unknowns
        );
        // the report's sums over the ranks: the terminals' charges, the free unknowns, the
        // errors against an exact solution
        assert_eq!(s.report.dofs, whole.report.dofs, "{name}");
        match (&s.report.exact, &whole.report.exact) {
            (Some(a), Some(b)) => {
                // (an affine solution's error is round-off on both sides)
                let (x, y) = (a.error(), b.error());
                let close = if y < 1e-10 { x < 1e-9 } else { (x - y).abs() <= 1e-6 * y };
                assert!(close, "{name}: error {x} against {y}");
            }
            (a, b) => assert_eq!(a.is_some(), b.is_some(), "{name}: an exact section on one side only"),
        }
        assert_eq!(s.report.terminals.len(), whole.report.terminals.len(), "{name}");
        // (an open circuit's charges, or those of a body without a voltage, are round-off on
        // both sides: against the charge the largest D would put on a face of the body's
        // size, the Krylov solve's error being relative to the fields')
        let d_max = whole
            .fields
            .electric_displacement
            .iter()
            .fold(0.0f64, |m, d| m.max(d.abs()));
        let (lo, hi) = whole.mesh.bounding_box();
        let size = (0..whole.mesh.dim).fold(0.0f64, |m, k| m.max(hi[k] - lo[k]));
        let scale = whole
            .report
            .terminals
            .iter()
            .fold(d_max * size.powi(whole.mesh.dim as i32 - 1), |m, t| {
                m.max(t.charge.abs())
            });
        for (a, b) in s.report.terminals.iter().zip(&whole.report.terminals) {
            assert_eq!(a.group, b.group);
            assert!(
                (a.charge - b.charge).abs() <= 1e-7 * scale,
                "{name} {}: {} against {}",
                a.group,
                a.charge,
                b.charge
            );
            assert_eq!(a.floating, b.floating, "{name} {}", a.group);
            // (a prescribed potential is exact; a floating terminal's is the Krylov solve's)
            let tol = if b.floating {
                1e-7 * b.potential.abs()
            } else {
                1e-12 * (1.0 + b.potential.abs())
            };
            assert!(
                (a.potential - b.potential).abs() <= tol,
                "{name} {}: potential {} against {}",
                a.group,
                a.potential,
                b.potential
            );
        }
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
        let s = distributed::solve_on_pieces(
            p,
            &scene,
            distributed::PieceMesh::Generated,
            problem::Limits::default(),
            &mut problem::Silent,
        )
        .unwrap_or_else(|e| panic!("{name} {sets:?} on pieces: {e}"));
        let piece = &s.piece;
        let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
        let du = farthest(&flat(&whole.u), &flat(&s.u), &piece.global_node, 3, |_| true);
        let dphi = farthest(&whole.phi, &s.phi, &piece.global_node, 1, |_| true);
        let (wc, c) = (
            whole.contact.as_ref().expect("contact"),
            s.contact.as_ref().expect("contact"),
        );
        // (a node of two zones is a point of each)
        let at: std::collections::HashMap<(usize, usize), usize> = (0..wc.nodes.len())
            .map(|i| ((wc.group_of[i], wc.nodes[i]), i))
            .collect();
        let (wl, l) = (&wc.solution.lambda, &c.solution.lambda);
        let nt = l.n_tangential();
        let scale = wl.normal.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
        let mut dl = 0.0f64;
        for (i, &v) in c.boundary.nodes.iter().enumerate() {
            let j = at[&(c.boundary.group_of[i], piece.global_node[v])];
            dl = dl.max((l.normal[i] - wl.normal[j]).abs());
            // (frictionless: no tangential multipliers)
            for q in (0..nt).filter(|_| !l.tangential.is_empty() && !wl.tangential.is_empty()) {
                dl = dl.max((l.tangential[i * nt + q] - wl.tangential[j * nt + q]).abs());
            }
        }
        let dl = dl / scale;
        let df = (c.normal_force - whole.report.contact.normal_force).abs() / whole.report.contact.normal_force.abs();
        assert_eq!(c.points, wc.nodes.len(), "{name}: the points over the ranks");
        // rank 0's report of every rank's points (a rank may hold none)
        let gathered = s.gathered(p, &scene).expect("the gathered surfaces");
        if let Some(g) = gathered {
            let force = g.report.contact.normal_force;
            let expected = whole.report.contact.normal_force;
            assert!(
                (force - expected).abs() <= 1e-6 * expected.abs(),
                "{name}: {force} against {expected}"
            );
        }
        eprintln!(
            "{name} {sets:?} rank {}/{}: {} steps, residual {:.1e}, equilibrium {:.1e}; u {du:.1e}, phi {dphi:.1e}, multipliers {dl:.1e}, normal force {df:.1e}",
            p.rank(),
            p.size(),
            c.steps,
            c.residual,
            c.equilibrium
        );
        // rank 0's report completed from the gathered points: the contact section, an
        // indenter's figures
        if let Some(g) = s.gathered(p, &scene).expect("the gather") {
            let (a, b) = (&g.report.contact, &whole.report.contact);
            assert_eq!(
                (a.n_points, a.n_stick, a.n_slip, a.n_separated),
                (b.n_points, b.n_stick, b.n_slip, b.n_separated),
                "{name}"
            );
            assert!(
                (a.normal_force - b.normal_force).abs() <= 1e-8 * b.normal_force.abs(),
                "{name}"
            );
            // several zones: each one's counts and forces
            assert_eq!(a.groups.len(), b.groups.len(), "{name}");
            for (x, y) in a.groups.iter().zip(&b.groups) {
                assert_eq!(
                    (&x.group, x.n_points, x.n_stick, x.n_slip, x.n_separated),
                    (&y.group, y.n_points, y.n_stick, y.n_slip, y.n_separated),
                    "{name}"
                );
                assert!(
                    (x.normal_force - y.normal_force).abs() <= 1e-8 * y.normal_force.abs().max(b.normal_force.abs()),
                    "{name} {}: {} against {}",
                    x.group,
                    x.normal_force,
                    y.normal_force
                );
            }
            assert_eq!(g.report.indenter.is_some(), whole.report.indenter.is_some(), "{name}");
            assert_eq!(g.report.exact.is_some(), whole.report.exact.is_some(), "{name}");
            if let (Some(x), Some(y)) = (&g.report.exact, &whole.report.exact) {
                assert_eq!(x.error_name(), y.error_name(), "{name}");
                assert!(
                    (x.error() - y.error()).abs() <= 1e-6 * y.error().abs(),
                    "{name}: error {} against {}",
                    x.error(),
                    y.error()
                );
            }
            if let (Some(x), Some(y)) = (&g.report.indenter, &whole.report.indenter) {
                assert_eq!(
                    (x.points_in_contact, x.contact_radius),
                    (y.points_in_contact, y.contact_radius),
                    "{name}"
                );
                assert!(
                    (x.force - y.force).abs() <= 1e-8 * y.force.abs(),
                    "{name}: {} against {}",
                    x.force,
                    y.force
                );
                // (a depth found by force control's search, to the force's tolerance; else given)
                let forced = scene
                    .zones()
                    .iter()
                    .any(|c| c.indenter.as_ref().is_some_and(|i| i.force.is_some()));
                let within = if forced { 1e-8 } else { 1e-14 };
                assert!(
                    (x.depth - y.depth).abs() <= within * y.depth.abs(),
                    "{name}: depth {} against {}",
                    x.depth,
                    y.depth
                );
                let tip = |r: &problem::report::IndenterReport| r.tip_potential.unwrap_or(0.0);
                assert!(
                    (tip(x) - tip(y)).abs() <= 1e-8 * tip(y).abs().max(1e-30),
                    "{name}: tip {} against {}",
                    tip(x),
                    tip(y)
                );
            }
        }
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

/// Load paths that the active sets walk on pieces: Coulomb's friction loaded, unloaded (its
/// points slipping back) and loaded again in 3D, in 2D (the shipped cycle, shortened), Tresca's
/// and an indenter pressed in (the gap's factor).
const PATH_CASES: &[(&str, &[&str])] = &[
    (
        "paper-3d",
        &[
            "mesh.n=6",
            "contact.friction=0.05",
            "path.t=[0.0,1.0,2.0,3.0]",
            "path.load=[0.0,1.0,0.3,1.0]",
            "path.steps=6",
        ],
    ),
    ("paper-cycle", &["mesh.n=32", "path.steps=9"]),
    // two zones along a path: the plate's Tresca zone and the Coulomb foundation, loaded and
    // unloaded
    (
        "squeeze-3d",
        &[
            "mesh.n=4",
            "path.t=[0.0,1.0,2.0]",
            "path.load=[0.2,1.0,0.4]",
            "path.steps=4",
        ],
    ),
    // force control along a path, its force scaled by the load factor
    (
        "indent-sphere-3d",
        &[
            "mesh.n=6",
            "contact.indenter.depth=0.0",
            "contact.indenter.force=0.1",
            "path.t=[0.0,1.0]",
            "path.load=[0.4,1.0]",
            "path.steps=2",
        ],
    ),
    // slip weakening along a path: each point's slip carried from instant to instant
    (
        "paper-slip-weakening",
        &[
            "mesh.n=32",
            "path.t=[0.0,1.0,2.0]",
            "path.load=[0.5,1.0,0.7]",
            "path.steps=4",
        ],
    ),
    // a compliant foundation along the cycle
    (
        "paper-cycle",
        &["mesh.n=32", "path.steps=9", "contact.compliance={stiffness=100.0}"],
    ),
    // every point sticks from the first instant (their displacement is no scale of the
    // body's), then slips at the unloaded turn: the instants after it are resolved
    (
        "paper-cycle",
        &["mesh.n=32", "path.load=[0.2,1.0,0.0,1.0]", "path.steps=9"],
    ),
    // a floating terminal's charge along the path (scaled with the potentials' factor); at
    // t = 0 the charge alone pulls the body onto the foundation, every touching point slipping
    // (friction's predictor: from the loads alone the active sets cycle)
    (
        "paper-cycle",
        &[
            "mesh.n=32",
            "path.steps=9",
            "~dirichlet.1.phi",
            "dirichlet.1.charge=1e-3",
        ],
    ),
    (
        "paper-tresca",
        &[
            "mesh.n=32",
            "path.t=[0.0,1.0,2.0]",
            "path.load=[0.0,1.0,0.2]",
            "path.steps=4",
        ],
    ),
    (
        "indent-sphere-3d",
        &["mesh.n=8", "path.t=[0.0,1.0]", "path.gap=[0.0,1.0]", "path.steps=3"],
    ),
];

/// The path cases on pieces against the default backend's path on the whole mesh: every
/// instant's row (forces, counts, slips, an indenter's depth and radius, the terminals'
/// charges), the written instants handed on with their fields, and the last instant's nodal
/// solution.
fn paths_on_pieces(p: &Petsc) {
    for (name, sets) in PATH_CASES {
        let (faer, scene) = both(name, sets);
        let whole = problem::solve(&faer, None, &mut problem::Silent).expect("the whole mesh's run");
        let mut frames = vec![];
        let mut each = |step: distributed::PieceStep<'_>| {
            if let Some(f) = &step.frame {
                assert_eq!(f.u.len(), f.mesh.n_nodes());
                frames.push(step.row.step);
            }
            Ok(())
        };
        let s = distributed::solve_path_on_pieces(
            p,
            &scene,
            distributed::PieceMesh::Generated,
            problem::Limits::default(),
            &mut problem::Silent,
            &mut each,
        )
        .unwrap_or_else(|e| panic!("{name} {sets:?} on pieces: {e}"));
        let (a, b) = (
            &s.report.path.as_ref().expect("the path's rows").rows,
            &whole.report.path.as_ref().expect("the path's rows").rows,
        );
        assert_eq!(a.len(), b.len(), "{name}: instants");
        let spec = scene.path.as_ref().expect("a path");
        let written: Vec<usize> = (0..b.len()).filter(|&k| spec.has_fields(k, b.len())).collect();
        assert_eq!(frames, written, "{name}: the instants handed on with their fields");
        let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= 1e-7 * scale.abs().max(1e-300);
        let force = b.iter().fold(0.0f64, |m, r| m.max(r.normal_force.abs()));
        for (x, y) in a.iter().zip(b) {
            let k = y.step;
            // (an instant unloaded to nothing: its statuses are round-off's, on both)
            if y.normal_force.abs() > 1e-9 * force {
                assert_eq!(
                    (x.n_stick, x.n_slip, x.n_separated),
                    (y.n_stick, y.n_slip, y.n_separated),
                    "{name} step {k}"
                );
            }
            assert!(
                close(x.normal_force, y.normal_force, force),
                "{name} step {k}: {x:?} {y:?}"
            );
            for (tx, ty) in x.tangential_resultant.iter().zip(&y.tangential_resultant) {
                assert!(close(*tx, *ty, force), "{name} step {k}: tangential {tx} against {ty}");
            }
            // several zones: each one's counts and forces at the instant
            assert_eq!(x.groups.len(), y.groups.len(), "{name} step {k}");
            for (gx, gy) in x.groups.iter().zip(&y.groups) {
                assert_eq!(
                    (gx.n_points, gx.n_stick, gx.n_slip, gx.n_separated),
                    (gy.n_points, gy.n_stick, gy.n_slip, gy.n_separated),
                    "{name} step {k} {}",
                    gy.group
                );
                assert!(
                    close(gx.normal_force, gy.normal_force, force),
                    "{name} step {k} {}",
                    gy.group
                );
                for (tx, ty) in gx.tangential_resultant.iter().zip(&gy.tangential_resultant) {
                    assert!(close(*tx, *ty, force), "{name} step {k} {}", gy.group);
                }
            }
            // (slips against the body's displacements: where all stick they are round-off)
            let moved = whole.u.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
            let slip = b.iter().fold(moved, |m, r| m.max(r.max_slip));
            assert!(close(x.max_slip, y.max_slip, slip), "{name} step {k}: slip {x:?} {y:?}");
            assert!(
                close(x.max_slip_increment, y.max_slip_increment, slip),
                "{name} step {k}: slip increment {} against {} (scale {slip}) {x:?} {y:?}",
                x.max_slip_increment,
                y.max_slip_increment
            );
            assert_eq!(x.depth.is_some(), y.depth.is_some(), "{name} step {k}");
            if let (Some(dx), Some(dy)) = (x.depth, y.depth) {
                assert!(close(dx, dy, dy), "{name} step {k}: depth {dx} against {dy}");
                assert_eq!(x.contact_radius, y.contact_radius, "{name} step {k}");
            }
            assert_eq!(x.charges.len(), y.charges.len(), "{name}");
            // (charges of round-off, an insulating indenter's grounded base at 1e-14 where the
            // paper's terminals carry 3e-4: against a floor of 1e-12 in the scenes' units)
            let q = b.iter().flat_map(|r| &r.charges).fold(1e-6f64, |m, c| m.max(c.abs()));
            for (cx, cy) in x.charges.iter().zip(&y.charges) {
                assert!((cx - cy).abs() <= 1e-6 * q, "{name} step {k}: charge {cx} against {cy}");
            }
            // the terminals' potentials (a floating one's found at each instant)
            let v = b
                .iter()
                .flat_map(|r| &r.potentials)
                .fold(1e-12f64, |m, v| m.max(v.abs()));
            for (vx, vy) in x.potentials.iter().zip(&y.potentials) {
                assert!(
                    (vx - vy).abs() <= 1e-7 * v,
                    "{name} step {k}: potential {vx} against {vy}"
                );
            }
            assert!(x.complementarity <= scene.solver.tol, "{name} step {k}");
        }
        let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
        let du = farthest(&flat(&whole.u), &flat(&s.u), &s.piece.global_node, 3, |_| true);
        eprintln!(
            "{name} {sets:?} rank {}/{}: {} instants, last u {du:.1e}",
            p.rank(),
            p.size(),
            a.len()
        );
        assert!(du < 1e-7, "{name} {sets:?}: the last instant's u differs by {du:.2e}");
    }
    // an excursion of the load: the instant after it is round-off beside friction's history,
    // refused as the default backend's path refuses it (it was judged against the excursion's
    // multipliers, and met the tolerance at once)
    let excursion = [
        "mesh.n=4",
        "contact.friction=0.05",
        "path.t=[0.0,1.0,2.0]",
        "path.load=[1.0,1e30,1.0]",
        "path.steps=2",
    ];
    let (faer, scene) = both("paper-3d", &excursion);
    let e = problem::solve(&faer, None, &mut problem::Silent)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    let f = distributed::solve_path_on_pieces(
        p,
        &scene,
        distributed::PieceMesh::Generated,
        problem::Limits::default(),
        &mut problem::Silent,
        &mut |_| Ok(()),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    for said in [&e, &f] {
        assert!(
            said.contains("path step 2") && said.contains("friction's history"),
            "{said}"
        );
    }
}

#[test]
fn paths_on_pieces_agree_with_the_whole_mesh_on_one_rank() {
    on_ranks(
        "paths_on_pieces_agree_with_the_whole_mesh_on_one_rank",
        1,
        paths_on_pieces,
    );
}

#[test]
fn paths_on_pieces_agree_with_the_whole_mesh_on_two_ranks() {
    on_ranks(
        "paths_on_pieces_agree_with_the_whole_mesh_on_two_ranks",
        2,
        paths_on_pieces,
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
            match distributed::solve_on_pieces(
                p,
                &scene,
                distributed::PieceMesh::Generated,
                problem::Limits::default(),
                &mut problem::Silent,
            ) {
                Ok(_) => panic!("{name} {sets:?} solved on pieces"),
                Err(e) => e.to_string(),
            }
        };
        let e = refused("paper-conductive", &["mesh.n=8"]);
        assert!(e.contains("contact.electric") && e.contains("pieces"), "{e}");
        let e = refused("indent-sphere", &["mesh.n=8"]);
        assert!(e.contains("mesh.axisymmetric") && e.contains("pieces"), "{e}");
        // a body its conditions do not hold: refused as the whole mesh's check refuses it, by
        // the conditions summed over the ranks (no rank holds them all)
        let e = refused(
            "paper-3d",
            &[
                "mesh.n=4",
                "contact.law=\"none\"",
                "~dirichlet.1",
                "~dirichlet.0.u",
                "dirichlet.0.ux=0.0",
            ],
        );
        assert!(e.contains("3 rigid motions of the body free"), "{e}");
        let e = refused(
            "paper-3d",
            &["mesh.n=4", "contact.law=\"none\"", "~dirichlet.1", "~dirichlet.0.phi"],
        );
        assert!(e.contains("the potential is floating"), "{e}");
        // loads finite one by one whose squares overflow: named as the default backend names
        // them (it was the Krylov solve's NaN, with advice on PETSc's options)
        for (set, named) in [
            ("load.p=1e308", "load.p = 1e308"),
            ("dirichlet.1.charge=1e308", "dirichlet.charge = 1e308"),
        ] {
            let e = refused(
                "paper-3d",
                &["mesh.n=4", "contact.law=\"none\"", "~dirichlet.1.phi", set],
            );
            assert!(
                e.contains("the norm of the loads is not finite") && e.contains(named),
                "{e}"
            );
        }
        // a floating terminal alone does not hold the potential's level (its own is unknown)
        let e = refused(
            "paper-3d",
            &[
                "mesh.n=4",
                "contact.law=\"none\"",
                "~dirichlet.0.phi",
                "~dirichlet.1.phi",
                "dirichlet.1.charge=1e-3",
            ],
        );
        assert!(e.contains("the potential is floating"), "{e}");
        // a PZT layer on a non-electric substrate, its potential held nowhere: the electric
        // parts counted across the ranks (no piece sees the whole layer)
        let e = refused(
            "layered",
            &[
                "mesh.n=8",
                "contact.law=\"none\"",
                "~dirichlet.0.phi",
                "~dirichlet.1.phi",
            ],
        );
        assert!(e.contains("the potential is floating"), "{e}");
        // two frictional walls meeting at the corner: the corner node's friction along the
        // other wall's normal
        let e = refused(
            "corner",
            &[
                "mesh.n=8",
                "contact.0.law=\"coulomb\"",
                "contact.0.friction=0.3",
                "contact.1.law=\"coulomb\"",
                "contact.1.friction=0.3",
            ],
        );
        assert!(
            e.contains("contact") && e.contains("two contact zones") && e.contains("(1.000000e0, 1.000000e0"),
            "{e}"
        );
        let e = refused("paper-3d", &["mesh.n=4", "contact.law=\"none\"", "mesh.order=2"]);
        assert!(e.contains("mesh.order") && e.contains("pieces"), "{e}");
        let e = refused("paper", &["mesh.n=1", "contact.law=\"none\"", "mesh.hi=[1.0,1.0]"]);
        assert!(e.contains("mesh.n") && e.contains("2 ranks"), "{e}");
        let (_, scene) = both("paper-3d", &["mesh.n=16", "contact.law=\"none\""]);
        let limits = problem::Limits {
            memory_bytes: Some(1 << 20),
            memory_limit: Some("a test's limit"),
            ..Default::default()
        };
        let e = distributed::solve_on_pieces(
            p,
            &scene,
            distributed::PieceMesh::Generated,
            limits,
            &mut problem::Silent,
        )
        .map(|_| ())
        .unwrap_err()
        .to_string();
        assert!(
            e.contains(&format!("rank {} of 2", p.rank())) && e.contains("a test's limit"),
            "{e}"
        );
    });
}

/// The values of the array `name` of a `.vtu` written by this program (inline `binary`
/// arrays: base64 of an 8-byte count, then the values), as `f64`.
fn vtu_array(text: &str, name: &str) -> Vec<f64> {
    use base64::Engine;
    let tag = format!("Name=\"{name}\"");
    let at = text.find(&tag).unwrap_or_else(|| panic!("no array {name}"));
    let start = at + text[at..].find('>').expect("the tag ends") + 1;
    let end = start + text[start..].find("</DataArray>").expect("the array ends");
    let head = &text[text[..at].rfind('<').expect("a tag")..at];
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(text[start..end].trim())
        .expect("base64");
    let body = &bytes[8..];
    if head.contains("UInt8") {
        body.iter().map(|&b| f64::from(b)).collect()
    } else if head.contains("UInt64") {
        body.chunks(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect()
    } else {
        body.chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }
}

/// The solution of an output directory by the whole mesh's numbers: per node `u` (3) and
/// `phi`, per cell `stress` (6), from `solution.vtu` or from the pieces of `solution.pvtu`
/// (each cell once: its owner's, the ghosts skipped).
fn solution_of(dir: &std::path::Path) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    if dir.join("solution.vtu").exists() {
        let t = read("solution.vtu");
        return (vtu_array(&t, "u"), vtu_array(&t, "phi"), vtu_array(&t, "stress"));
    }
    let pvtu = read("solution.pvtu");
    let sources: Vec<&str> = pvtu
        .split("Source=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    let (mut u, mut phi, mut stress) = (vec![], vec![], vec![]);
    for src in sources {
        let t = read(src);
        let (nodes, cells, ghost) = (
            vtu_array(&t, "node_id"),
            vtu_array(&t, "cell_id"),
            vtu_array(&t, "vtkGhostType"),
        );
        let (pu, pphi, ps) = (vtu_array(&t, "u"), vtu_array(&t, "phi"), vtu_array(&t, "stress"));
        for (i, &g) in nodes.iter().enumerate() {
            let g = g as usize;
            if u.len() < 3 * (g + 1) {
                u.resize(3 * (g + 1), f64::NAN);
                phi.resize(g + 1, f64::NAN);
            }
            u[3 * g..3 * g + 3].copy_from_slice(&pu[3 * i..3 * i + 3]);
            phi[g] = pphi[i];
        }
        for (c, &g) in cells.iter().enumerate().filter(|(c, _)| ghost[*c] == 0.0) {
            let g = g as usize;
            if stress.len() < 6 * (g + 1) {
                stress.resize(6 * (g + 1), f64::NAN);
            }
            stress[6 * g..6 * g + 6].copy_from_slice(&ps[6 * c..6 * c + 6]);
        }
    }
    (u, phi, stress)
}

/// The largest difference of two arrays over the largest magnitude of `b` (a NaN, an entry
/// that no piece wrote, is infinitely far).
fn rel(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            if x.is_nan() || y.is_nan() {
                f64::INFINITY
            } else {
                (x - y).abs()
            }
        })
        .fold(0.0, f64::max)
        / scale
}

/// Runs the program under `mpirun -np ranks` (with `prefix` run by each rank's shell first).
fn mpirun(ranks: usize, prefix: &str, args: &[&str]) -> std::process::Output {
    let exe = env!("CARGO_BIN_EXE_piezocontact");
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!("{prefix} exec '{exe}' {}", quoted.join(" "));
    std::process::Command::new("timeout")
        .args([
            "600",
            "mpirun",
            "-np",
            &ranks.to_string(),
            "--allow-run-as-root",
            "--oversubscribe",
        ])
        .args(["sh", "-c", &script])
        .output()
        .expect("mpirun runs")
}

/// `paper-3d` and `indent-sphere-3d` (a graded quarter model under a sphere) at n = 24
/// (contact, on the active sets) on pieces from 1, 2 and 4 ranks: the same set of files but
/// for the number of pieces; the pieces' nodal and cell values, merged by the whole mesh's
/// numbers, `contact.csv` and `run.json`'s figures (an indenter's among them) equal across the
/// ranks and equal to the default backend's run within the Krylov tolerance's reach.
#[test]
fn the_outputs_of_a_run_on_pieces_do_not_depend_on_the_ranks() {
    for scene in ["paper-3d", "indent-sphere-3d"] {
        outputs_on_pieces(scene);
    }
}

fn outputs_on_pieces(scene: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["--set", "mesh.n=24", "--set", "solver.backend=\"petsc\""];
    let whole = tmp.path().join("whole");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .args(["run", scene, "--set", "mesh.n=24", "--out"])
        .arg(&whole)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (wu, wphi, ws) = solution_of(&whole);
    let csv = |dir: &std::path::Path| -> Vec<Vec<f64>> {
        std::fs::read_to_string(dir.join("contact.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').filter_map(|x| x.parse().ok()).collect())
            .collect()
    };
    let json = |dir: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
    };
    let (wc, wj) = (csv(&whole), json(&whole));
    let u_scale = wu.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for ranks in [1, 2, 4] {
        let dir = tmp.path().join(format!("pieces-{ranks}"));
        let mut args = vec!["run", scene];
        args.extend(sets);
        let out = dir.to_str().unwrap();
        args.extend(["--out", out]);
        let o = mpirun(ranks, "", &args);
        assert!(
            o.status.success(),
            "{ranks} ranks: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(said.contains("wrote") && said.contains("solution.pvtu"), "{said}");
        let (u, phi, s) = solution_of(&dir);
        let (du, dphi, ds) = (rel(&u, &wu), rel(&phi, &wphi), rel(&s, &ws));
        let c = csv(&dir);
        assert_eq!(c.len(), wc.len(), "contact points");
        // coordinates and multipliers against their scales, displacements against the body's
        let mut dc = 0.0f64;
        for (row, wrow) in c.iter().zip(&wc) {
            for (k, (x, y)) in row.iter().zip(wrow).enumerate() {
                let scale = if (4..=6).contains(&k) {
                    u_scale
                } else {
                    wc.iter().fold(1e-300_f64, |m, r| m.max(r[k].abs()))
                };
                dc = dc.max((x - y).abs() / scale);
            }
        }
        let j = json(&dir);
        let force = |j: &serde_json::Value| j["contact"]["normal_force"].as_f64().unwrap();
        let charge = |j: &serde_json::Value, k: usize| j["terminals"][k]["charge"].as_f64().unwrap();
        let df = (force(&j) - force(&wj)).abs() / force(&wj).abs();
        // (the one terminal of a body under an insulating tip carries no charge, by Gauss: both
        // runs give round-off there, the default backend's 1e-16, the Krylov solve's 1e-15,
        // and no relative difference means anything)
        let dq = match charge(&wj, 0).abs() > 1e-12 {
            true => (charge(&j, 0) - charge(&wj, 0)).abs() / charge(&wj, 0).abs(),
            false => 0.0,
        };
        let indenter = |j: &serde_json::Value| j["indenter"]["force"].as_f64().unwrap_or(0.0);
        let di = (indenter(&j) - indenter(&wj)).abs() / indenter(&wj).abs().max(1e-300);
        assert_eq!(j["indenter"]["points_in_contact"], wj["indenter"]["points_in_contact"]);
        assert_eq!(j["dofs"], wj["dofs"]);
        assert_eq!(j["mesh"]["n_cells"], wj["mesh"]["n_cells"]);
        assert_eq!(j["contact"]["n_stick"], wj["contact"]["n_stick"]);
        assert_eq!(j["petsc"]["ranks"], ranks);
        eprintln!("{scene} on {ranks} ranks: u {du:.1e}, phi {dphi:.1e}, stress {ds:.1e}, contact.csv {dc:.1e}, force {df:.1e}, charge {dq:.1e}, indenter {di:.1e}");
        for (what, d) in [
            ("u", du),
            ("phi", dphi),
            ("stress", ds),
            ("contact.csv", dc),
            ("normal force", df),
            ("charge", dq),
        ] {
            assert!(d < 1e-7, "{ranks} ranks: {what} differs by {d:.2e}");
        }
        for p in 0..ranks {
            assert!(dir.join(format!("solution-{p}.vtu")).exists());
        }
        assert!(!dir.join(format!("solution-{ranks}.vtu")).exists());
    }
}

/// A rank that cannot write its piece (its file-size limit below the piece's size) stops the
/// run with an error, and the directory keeps the set it had: rank 0 turns the directory to
/// the new set only once every rank has written.
#[test]
fn a_rank_that_cannot_write_its_piece_leaves_the_previous_set() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let out = out.to_str().unwrap();
    let mut args = vec![
        "run",
        "paper-3d",
        "--set",
        "mesh.n=8",
        "--set",
        "contact.law=\"none\"",
        "--set",
        "solver.backend=\"petsc\"",
        "--out",
        out,
    ];
    let o = mpirun(2, "", &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let before = std::fs::read(tmp.path().join("out/run.json")).unwrap();
    // the same run under another load, rank 1 unable to write a file of more than 8 blocks
    args.extend(["--set", "load.p=-3.0"]);
    let changed = args;
    let o = mpirun(
        2,
        "if [ \"$OMPI_COMM_WORLD_RANK\" = 1 ]; then ulimit -f 8; fi;",
        &changed,
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert!(stderr.contains("could not write"), "{stderr}");
    assert_eq!(
        std::fs::read(tmp.path().join("out/run.json")).unwrap(),
        before,
        "the previous set stays"
    );
    assert!(tmp.path().join("out/solution-1.vtu").exists());
}

/// The fixtures of the mesh crate: the layered box (regions `substrate` and `pzt`, the
/// interior group `interface`) whole, and split by Gmsh into three parts with ghost cells.
fn forms() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mesh/tests/fixtures/forms")
}

/// A Gmsh mesh read whole on several ranks, too large for a rank's memory, is refused before
/// anything is built, and the refusal says the way past it that is not a coarser mesh: the
/// mesh saved in parts, which runs on pieces.
#[test]
fn a_whole_gmsh_mesh_too_large_for_its_ranks_is_told_of_its_parts() {
    on_ranks(
        "a_whole_gmsh_mesh_too_large_for_its_ranks_is_told_of_its_parts",
        2,
        |p| {
            let sets = [
                "solver.backend=\"petsc\"".to_string(),
                "contact.law=\"none\"".to_string(),
            ];
            let scene = scene_file::parse(LAYERED, "layered-gmsh", &sets).expect("the scene");
            let mesh = mesh::read_msh(forms().join("3d-ascii.msh")).expect("the whole file");
            let limits = problem::Limits {
                memory_bytes: Some(1 << 20),
                memory_limit: Some("a test's limit"),
                ..Default::default()
            };
            let e = distributed::solve(&scene, Some(mesh), p, limits, &mut problem::Silent)
                .map(|_| ())
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("the run needs about") && e.contains("one part per rank"),
                "{e}"
            );
        },
    );
}

/// The layered box on a Gmsh mesh: both layers PZT-5A (a substrate of half its stiffness),
/// clamped at x = 0 and x = 2, pressed on top, on a Coulomb foundation at z = 0.
const LAYERED: &str = r#"
name = "layered-gmsh"
description = "the layered Gmsh box of the mesh crate's fixtures, on a Coulomb foundation"
[units]
length = "m"
stress = "GPa"
[mesh]
kind = "gmsh"
file = "3d-ascii-split.msh"
[[material]]
region = "pzt"
model = "crystal-6mm"
c = [121.0, 75.4, 75.2, 111.0, 21.1, 22.6]
e = [-5.4, 15.8, 12.3]
permittivity = [8.11, 7.35]
poling = [0.0, 0.0, 1.0]
[[material]]
region = "substrate"
model = "crystal-6mm"
c = [60.5, 37.7, 37.6, 55.5, 10.55, 11.3]
e = [-5.4, 15.8, 12.3]
permittivity = [8.11, 7.35]
poling = [0.0, 0.0, 1.0]
[[dirichlet]]
group = "left"
u = [0.0, 0.0, 0.0]
phi = 0.0
[[dirichlet]]
group = "right"
u = [0.0, 0.0, 0.0]
phi = 0.0
[load]
group = "top"
p = -2.0
direction = [0.0, 0.0, 1.0]
[contact]
group = "bottom"
law = "coulomb"
friction = 0.3
gap = 0.0
normal = [0.0, 0.0, -1.0]
"#;

/// A load path on a Gmsh mesh in three parts, from the command line: loaded, unloaded and
/// loaded again on the Coulomb foundation, each rank reading its part. Every instant the path
/// writes is a `step-NNNN.pvtu` with one piece per rank (each rank's own), `path.pvd` their
/// collection; `path.csv` equals the default backend's on the whole file, row by row, and the
/// last instant's pieces its `solution.vtu`.
#[test]
fn a_path_on_gmsh_parts_writes_its_series_from_the_ranks() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::copy(forms().join("3d-ascii.msh"), tmp.path().join("body.msh")).unwrap();
    let scene = LAYERED.replace("3d-ascii-split.msh", "body.msh")
        + "[path]\nt = [0.0, 1.0, 2.0, 3.0]\nload = [0.0, 1.0, 0.3, 1.0]\nsteps = 6\noutput_every = 2\n";
    std::fs::write(tmp.path().join("whole.toml"), &scene).unwrap();
    let whole = tmp.path().join("whole");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_piezocontact"))
        .arg("run")
        .arg(tmp.path().join("whole.toml"))
        .arg("--out")
        .arg(&whole)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for k in 1..=3 {
        let part = format!("3d-ascii-split_{k}.msh");
        std::fs::copy(forms().join(part), tmp.path().join(format!("body_{k}.msh"))).unwrap();
    }
    let parted = scene.replacen("[[material]]", "[solver]\nbackend = \"petsc\"\n\n[[material]]", 1);
    std::fs::write(tmp.path().join("parts.toml"), parted).unwrap();
    let dir = tmp.path().join("parts");
    let toml = tmp.path().join("parts.toml");
    let o = mpirun(3, "", &["run", toml.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    let said = String::from_utf8_lossy(&o.stderr).to_string() + &String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{said}");
    assert!(said.contains("step-0000.pvtu ... step-0006.pvtu"), "{said}");
    // the series: instants 0, 2, 4 and the last, each in three pieces, collected in order
    let pvd = std::fs::read_to_string(dir.join("path.pvd")).unwrap();
    let listed: Vec<&str> = pvd
        .split("file=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    assert_eq!(
        listed,
        ["step-0000.pvtu", "step-0002.pvtu", "step-0004.pvtu", "step-0006.pvtu"]
    );
    for step in listed {
        let pvtu = std::fs::read_to_string(dir.join(step)).unwrap();
        assert!(
            pvtu.contains("vtkGhostType") && pvtu.contains("contact_pressure"),
            "{step}: {pvtu}"
        );
        for r in 0..3 {
            let piece = step.replace(".pvtu", &format!("-{r}.vtu"));
            assert!(pvtu.contains(&piece), "{step} names {piece}");
            let bytes = std::fs::read(dir.join(&piece)).unwrap();
            assert!(
                String::from_utf8_lossy(&bytes[..400]).contains("vtkZLibDataCompressor"),
                "{piece}"
            );
        }
    }
    assert!(
        !dir.join("step-0001.pvtu").exists(),
        "output_every = 2 writes every other instant"
    );
    let rows = |d: &std::path::Path| -> Vec<Vec<f64>> {
        std::fs::read_to_string(d.join("path.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect())
            .collect()
    };
    let header = std::fs::read_to_string(dir.join("path.csv")).unwrap();
    let columns: Vec<&str> = header.lines().next().unwrap().split(',').collect();
    let (a, b) = (rows(&dir), rows(&whole));
    assert_eq!(a.len(), 7);
    assert_eq!(a.len(), b.len());
    for name in [
        "normal_force",
        "tangential_force_x",
        "n_stick",
        "n_slip",
        "max_slip",
        "charge_left",
    ] {
        let k = columns
            .iter()
            .position(|c| c.starts_with(name))
            .unwrap_or_else(|| panic!("{name}"));
        let scale = b.iter().fold(1e-12f64, |m, r| m.max(r[k].abs()));
        for (x, y) in a.iter().zip(&b) {
            assert!(
                (x[k] - y[k]).abs() <= 1e-6 * scale,
                "{}: {} against {}",
                columns[k],
                x[k],
                y[k]
            );
        }
    }
    // the last instant's contact points, matched by place (the parts number the nodes as
    // Gmsh tagged them, the whole file's run as it read them)
    let points = |d: &std::path::Path| -> Vec<Vec<f64>> {
        let mut rows: Vec<Vec<f64>> = std::fs::read_to_string(d.join("contact.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').filter_map(|x| x.parse().ok()).collect())
            .collect();
        rows.sort_by(|a, b| a[..3].partial_cmp(&b[..3]).unwrap());
        rows
    };
    let (c, wc) = (points(&dir), points(&whole));
    assert_eq!(c.len(), wc.len(), "contact points");
    // (displacements, columns 4 to 6, against the largest of them: u_n is round-off where
    // the points touch)
    let column_scale = |k: usize| {
        let of = if (4..=6).contains(&k) { 4..7 } else { k..k + 1 };
        wc.iter()
            .flat_map(|r| &r[of.clone()])
            .fold(1e-300f64, |m, x| m.max(x.abs()))
    };
    for k in 0..wc[0].len() {
        let scale = column_scale(k);
        let d = c.iter().zip(&wc).fold(0.0f64, |m, (x, y)| m.max((x[k] - y[k]).abs())) / scale;
        assert!(
            d < 1e-6,
            "contact.csv column {k} differs by {d:.1e}: {:?} against {:?}",
            c[0],
            wc[0]
        );
    }
}

/// Two PZT boxes on a Gmsh mesh (`tests/fixtures/bodies`, written by `write_bodies.py`), held
/// at `left` (and `right`), pressed on `top`, without contact.
const BODIES: &str = r#"
name = "bodies"
description = "two boxes of the pieces' fixtures"
[units]
length = "m"
stress = "GPa"
[mesh]
kind = "gmsh"
file = "two.msh"
[[material]]
region = "body"
model = "crystal-6mm"
c = [121.0, 75.4, 75.2, 111.0, 21.1, 22.6]
e = [-5.4, 15.8, 12.3]
permittivity = [8.11, 7.35]
poling = [0.0, 0.0, 1.0]
[[dirichlet]]
group = "left"
u = [0.0, 0.0, 0.0]
phi = 0.0
[[dirichlet]]
group = "right"
u = [0.0, 0.0, 0.0]
phi = 0.0
[load]
group = "top"
p = -2.0
direction = [0.0, 0.0, 1.0]
"#;

/// A mesh of several bodies in parts: each solid part (cells joined through a facet) held by
/// its own conditions, as the whole mesh's check holds it. Two separate boxes, each clamped at
/// its outer end, are solved on pieces as on the whole file (they were refused by key); a box
/// hanging from another by one edge (a hinge, about which it turns: 6 motions of its part
/// free) is refused on pieces as on the whole file, where the bodies counted through nodes
/// took the two boxes for one body held at `left`.
#[test]
fn several_bodies_in_parts_are_each_held_as_the_whole_mesh_holds_them() {
    on_ranks(
        "several_bodies_in_parts_are_each_held_as_the_whole_mesh_holds_them",
        2,
        |p| {
            let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/bodies");
            let files = |k: &str| mesh::parts_of(&dir.join(format!("{k}.msh")));
            let faer = scene_file::parse(BODIES, "bodies", &[]).expect("the scene");
            let scene = scene_file::parse(BODIES, "bodies", &["solver.backend=\"petsc\"".into()]).expect("the scene");
            let whole_mesh = mesh::read_msh(dir.join("two.msh")).expect("the whole file");
            let whole = problem::solve(&faer, Some(whole_mesh), &mut problem::Silent).expect("the whole run");
            let from = distributed::PieceMesh::Parts(files("two"));
            let s = distributed::solve_on_pieces(p, &scene, from, problem::Limits::default(), &mut problem::Silent)
                .unwrap_or_else(|e| panic!("two bodies on parts: {e}"));
            let at: std::collections::HashMap<[i64; 3], usize> = whole
                .mesh
                .points
                .iter()
                .enumerate()
                .map(|(v, x)| (place(x), v))
                .collect();
            let map: Vec<usize> = s.piece.mesh.points.iter().map(|x| at[&place(x)]).collect();
            let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
            let du = farthest(&flat(&whole.u), &flat(&s.u), &map, 3, |_| true);
            let dphi = farthest(&whole.phi, &s.phi, &map, 1, |_| true);
            assert!(du < 1e-7 && dphi < 1e-7, "two bodies: u {du:.1e}, phi {dphi:.1e}");
            // the hinge: held at `left` alone, its second box free
            let sets = vec!["~dirichlet.1".to_string(), "mesh.file=\"hinge.msh\"".to_string()];
            let faer = scene_file::parse(BODIES, "bodies", &sets).expect("the scene");
            let whole_mesh = mesh::read_msh(dir.join("hinge.msh")).expect("the whole file");
            let e = problem::solve(&faer, Some(whole_mesh), &mut problem::Silent)
                .map(|_| ())
                .unwrap_err()
                .to_string();
            let mut with = sets;
            with.push("solver.backend=\"petsc\"".into());
            let scene = scene_file::parse(BODIES, "bodies", &with).expect("the scene");
            let from = distributed::PieceMesh::Parts(files("hinge"));
            let f = distributed::solve_on_pieces(p, &scene, from, problem::Limits::default(), &mut problem::Silent)
                .map(|_| ())
                .unwrap_err()
                .to_string();
            for said in [&e, &f] {
                assert!(said.contains("leave 6 rigid motions of the body free"), "{said}");
            }
            let part = |x: &str| x[x.find(" cells)").map_or(0, |i| x[..i].rfind('(').unwrap_or(0))..].to_string();
            assert_eq!(part(&e)[..12], part(&f)[..12], "the same part: {e} / {f}");
        },
    );
}

/// A node's place, rounded: the same node in the whole file and in a part.
fn place(x: &[f64; 3]) -> [i64; 3] {
    x.map(|c| (c * 1e10).round() as i64)
}

/// A Gmsh mesh split into three parts, each rank reading its own: with and without contact,
/// the nodal solution (ghosts' fetched) and the multipliers at the rank's points equal the
/// default backend's on the whole file, node by node; the report's sums the whole run's.
#[test]
fn gmsh_parts_agree_with_the_whole_mesh_on_three_ranks() {
    on_ranks("gmsh_parts_agree_with_the_whole_mesh_on_three_ranks", 3, |p| {
        let parts = mesh::parts_of(&forms().join("3d-ascii-split.msh"));
        // (the third: the right face a floating terminal carrying a charge, its group over the
        // parts)
        let floating = vec!["~dirichlet.1.phi", "dirichlet.1.charge=1e-3"];
        for sets in [vec!["contact.law=\"none\""], vec![], floating] {
            let sets: Vec<String> = sets.into_iter().map(String::from).collect();
            let faer = scene_file::parse(LAYERED, "layered-gmsh", &sets).expect("the scene");
            let mut with = sets.clone();
            with.push("solver.backend=\"petsc\"".into());
            let scene = scene_file::parse(LAYERED, "layered-gmsh", &with).expect("the scene");
            let whole_mesh = mesh::read_msh(forms().join("3d-ascii.msh")).expect("the whole file");
            let whole = problem::solve(&faer, Some(whole_mesh), &mut problem::Silent).expect("the whole run");
            let from = distributed::PieceMesh::Parts(parts.clone());
            let s = distributed::solve_on_pieces(p, &scene, from, problem::Limits::default(), &mut problem::Silent)
                .unwrap_or_else(|e| panic!("{sets:?} on parts: {e}"));
            let at: std::collections::HashMap<[i64; 3], usize> = whole
                .mesh
                .points
                .iter()
                .enumerate()
                .map(|(v, x)| (place(x), v))
                .collect();
            let map: Vec<usize> = s.piece.mesh.points.iter().map(|x| at[&place(x)]).collect();
            let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
            let du = farthest(&flat(&whole.u), &flat(&s.u), &map, 3, |_| true);
            let dphi = farthest(&whole.phi, &s.phi, &map, 1, |_| true);
            assert!(
                s.piece.mesh.n_cells() < whole.mesh.n_cells(),
                "a rank holds the whole mesh"
            );
            assert_eq!(s.report.mesh.n_cells, whole.mesh.n_cells());
            assert_eq!(s.report.mesh.n_nodes, whole.mesh.n_nodes());
            assert_eq!(s.report.dofs, whole.report.dofs, "{sets:?}: the free unknowns");
            assert_eq!(s.report.terminals.len(), whole.report.terminals.len(), "{sets:?}");
            for (a, b) in s.report.terminals.iter().zip(&whole.report.terminals) {
                assert_eq!((&a.group, a.floating), (&b.group, b.floating), "{sets:?}");
                for (what, x, y) in [("charge", a.charge, b.charge), ("potential", a.potential, b.potential)] {
                    let close = (x - y).abs() <= 1e-7 * y.abs().max(1e-6);
                    assert!(close, "{sets:?} {}: {what} {x} against {y}", a.group);
                }
            }
            let mut dl = 0.0f64;
            if let (Some(wc), Some(c)) = (&whole.contact, &s.contact) {
                let index: std::collections::HashMap<usize, usize> =
                    wc.nodes.iter().enumerate().map(|(i, &v)| (v, i)).collect();
                let scale = wc
                    .solution
                    .lambda
                    .normal
                    .iter()
                    .fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
                for (i, &v) in c.boundary.nodes.iter().enumerate() {
                    dl =
                        dl.max((c.solution.lambda.normal[i] - wc.solution.lambda.normal[index[&map[v]]]).abs() / scale);
                }
                assert_eq!(c.points, wc.nodes.len(), "the points over the ranks");
            }
            eprintln!(
                "gmsh parts {sets:?} rank {}/3: {} of {} cells held; u {du:.1e}, phi {dphi:.1e}, multipliers {dl:.1e}",
                p.rank(),
                s.piece.mesh.n_cells(),
                whole.mesh.n_cells()
            );
            for (what, d) in [("u", du), ("phi", dphi), ("multipliers", dl)] {
                assert!(d < 1e-7, "{sets:?} rank {}: {what} differs by {d:.2e}", p.rank());
            }
        }
        // parts for another count of ranks are refused on every rank, naming the count
        let two = vec![parts[0].clone(), parts[1].clone()];
        let scene =
            scene_file::parse(LAYERED, "layered-gmsh", &["solver.backend=\"petsc\"".into()]).expect("the scene");
        let e = distributed::solve_on_pieces(
            p,
            &scene,
            distributed::PieceMesh::Parts(two),
            problem::Limits::default(),
            &mut problem::Silent,
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
        assert!(
            e.contains("the mesh is in 2 parts") && e.contains("run on 2 ranks"),
            "{e}"
        );
        // a region without material: the ranks that hold it refuse it, and the others with
        // them (none waits in a collective the others never reach)
        let start = LAYERED
            .find("[[material]]\nregion = \"substrate\"")
            .expect("the substrate");
        let end = LAYERED.find("[[dirichlet]]").expect("the conditions");
        let one = format!("{}{}", &LAYERED[..start], &LAYERED[end..]);
        let scene = scene_file::parse(&one, "layered-gmsh", &["solver.backend=\"petsc\"".into()]).expect("the scene");
        let from = distributed::PieceMesh::Parts(parts.clone());
        let e = distributed::solve_on_pieces(p, &scene, from, problem::Limits::default(), &mut problem::Silent)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("has no material") || e.contains("ranks could not set up"),
            "{e}"
        );
        // an element tag far past the count of elements (rank 0's part renumbered by hand):
        // refused on every rank before the tables over the tags are made
        let dir = tempfile::tempdir().expect("a directory");
        let text = std::fs::read_to_string(&parts[p.rank()]).expect("the part");
        // (rank 0's first own tetrahedron renumbered: a line of 5 numbers, not a ghost's)
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        if p.rank() == 0 {
            let at = |marker: &str| lines.iter().position(|l| l == marker).expect("a section");
            let ghosts: Vec<&str> = lines[at("$GhostElements") + 2..at("$EndGhostElements")]
                .iter()
                .filter_map(|l| l.split(' ').next())
                .collect();
            let own = (at("$Elements")..at("$EndElements"))
                .find(|&i| {
                    let t: Vec<&str> = lines[i].split_whitespace().collect();
                    t.len() == 5 && !ghosts.contains(&t[0])
                })
                .expect("an own tetrahedron");
            let rest: Vec<String> = lines[own].split_whitespace().skip(1).map(String::from).collect();
            lines[own] = format!("1500000000 {}", rest.join(" "));
        }
        let text = lines.join("\n");
        let mine = dir.path().join(format!("part_{}.msh", p.rank() + 1));
        std::fs::write(&mine, text).expect("the part written");
        let mut files = parts.clone();
        files[p.rank()] = mine;
        let from = distributed::PieceMesh::Parts(files);
        let e = distributed::solve_on_pieces(p, &scene, from, problem::Limits::default(), &mut problem::Silent)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("tags reach 1500000000") && e.contains("renumber"), "{e}");
    });
}
