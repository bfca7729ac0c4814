//! Electrical contact (`contact.electric`) against its closed form: a piezoelectric block
//! poled along the contact normal, held laterally by rollers, pushed down by `δ` at its top
//! with the top's potential `V` given, on a foundation at `φ_F`, is in uniaxial strain and a
//! uniform field along the normal (P1 elements hold it exactly). With the 6mm constants along
//! the poling, `σ = c33 ε + e33 φ'` and `D = e33 ε - ε33 φ'` (docs/theory.md's signs), `ε = -δ/H`:
//! - conducting: `φ(0) = φ_F`, so `φ' = (V - φ_F)/H`; the pressure `λ = -σ`, the flux through
//!   the contact face `q = D·ν = -D`;
//! - conductive: `q = σ_c λ (φ(0) - φ_F)` with `λ` and `q` affine in `a = φ(0)`: a quadratic in
//!   `a`, whose root between the insulated one (`D = 0`) and `φ_F` is the answer;
//! - insulated: `D = 0`.
//!
//! The finite element answer is the closed form to round-off, in 2D and 3D, for `σ_c` from 0
//! to 1e12, and tends to the conducting one as `σ_c → ∞`.

use problem::{ContactLaw, ContactSpec, DirichletSpec, ElectricCondition, MaterialSpec, MeshSpec, Scene, Silent};

const C33: f64 = 111.0;
const E33: f64 = 15.8;
const EPS33: f64 = 7.35;
const DELTA: f64 = 0.01;
const V: f64 = 0.0;
const PHI_F: f64 = 0.05;

/// The block (height 1) in `dim` dimensions on a foundation with the electric `condition`.
fn block(dim: usize, condition: ElectricCondition, conductance: Option<f64>) -> Scene {
    let roller = |group: &str, axis: usize| DirichletSpec {
        group: group.into(),
        ux: (axis == 0).then_some(0.0),
        uy: (axis == 1).then_some(0.0),
        ..Default::default()
    };
    let (mesh, normal, top_u, poling, mut dirichlet) = if dim == 2 {
        (
            MeshSpec::rectangle([0.0, 0.0], [2.0, 1.0], 4),
            vec![0.0, -1.0],
            vec![0.0, -DELTA],
            [0.0, 1.0, 0.0],
            vec![roller("left", 0), roller("right", 0)],
        )
    } else {
        (
            MeshSpec::cuboid([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 3),
            vec![0.0, 0.0, -1.0],
            vec![0.0, 0.0, -DELTA],
            [0.0, 0.0, 1.0],
            vec![
                roller("left", 0),
                roller("right", 0),
                roller("front", 1),
                roller("back", 1),
            ],
        )
    };
    dirichlet.push(DirichletSpec {
        group: "top".into(),
        u: Some(top_u),
        phi: Some(V),
        ..Default::default()
    });
    let mut contact = ContactSpec::new("bottom", ContactLaw::Coulomb, &normal);
    contact.friction = Some(0.5);
    contact.electric = Some(condition);
    if condition != ElectricCondition::Insulated {
        contact.foundation_potential = Some(PHI_F);
    }
    contact.conductance = conductance;
    Scene {
        name: "electric-block".into(),
        description: String::new(),
        mesh,
        material: vec![MaterialSpec::crystal_6mm(
            "body",
            [121.0, 75.4, 75.2, C33, 21.1, 22.6],
            [-5.4, E33, 12.3],
            [8.11, EPS33],
            poling,
        )],
        dirichlet,
        load: None,
        electrode: None,
        contact: Some(contact.into()),
        solver: Default::default(),
        exact: None,
        path: None,
        units: None,
    }
}

/// `(λ, q)` at the bottom potential `a`.
fn at(a: f64) -> (f64, f64) {
    let (strain, field) = (-DELTA, V - a);
    (-(C33 * strain + E33 * field), -(E33 * strain - EPS33 * field))
}

/// The bottom potential of the closed form: `φ_F` (conducting), the root of
/// `q(a) = σ λ(a) (a - φ_F)` between the insulated one and `φ_F` (conductive), the insulated
/// `q(a) = 0` (no conductance).
fn bottom_potential(condition: ElectricCondition, sigma: f64) -> f64 {
    // q(a) = q0 + q1 a, λ(a) = l0 + l1 a
    let (l0, q0) = at(0.0);
    let (l1, q1) = (at(1.0).0 - l0, at(1.0).1 - q0);
    let insulated = -q0 / q1;
    match condition {
        ElectricCondition::Conducting => PHI_F,
        ElectricCondition::Insulated => insulated,
        ElectricCondition::Conductive if sigma == 0.0 => insulated,
        ElectricCondition::Conductive => {
            // σ (l0 + l1 a)(a - φ_F) - q0 - q1 a = 0
            let (a2, a1, a0) = (sigma * l1, sigma * (l0 - l1 * PHI_F) - q1, -sigma * l0 * PHI_F - q0);
            let disc = (a1 * a1 - 4.0 * a2 * a0).sqrt();
            // the stable pair of roots
            let r1 = (-a1 - a1.signum() * disc) / (2.0 * a2);
            let r2 = a0 / (a2 * r1);
            let between = |r: f64| (r - insulated) * (r - PHI_F) <= 0.0;
            if between(r1) {
                r1
            } else {
                assert!(between(r2), "no root between {insulated} and {PHI_F}: {r1} {r2}");
                r2
            }
        }
    }
}

/// The largest relative errors of the pressure and of the flux at the points, and of the
/// potential at the points with a free potential.
fn errors(dim: usize, condition: ElectricCondition, sigma: Option<f64>) -> (f64, f64, f64) {
    let solution = problem::solve(&block(dim, condition, sigma), None, &mut Silent).unwrap();
    assert!(solution.report.residuals.converged_to_tolerance);
    let contact = solution.contact.as_ref().unwrap();
    let a = bottom_potential(condition, sigma.unwrap_or(0.0));
    let (lambda, q) = at(a);
    assert!(lambda > 0.0, "the block is in contact: λ = {lambda}");
    // the flux out through the top is `D·e_n = -q`, so the top electrode carries the charge
    // `q` times its area (the charge on the conductor: the negative of the flux; the electric
    // equation's reaction at its nodes)
    let area = if dim == 2 { 2.0 } else { 1.0 };
    let top = solution.report.terminals.iter().find(|t| t.group == "top").unwrap();
    assert!(
        (top.charge - q * area).abs() <= 1e-9 * (q * area).abs().max(E33 * DELTA),
        "{dim}D {condition:?}: top charge {} vs {}",
        top.charge,
        q * area
    );
    assert!((top.potential - V).abs() < 1e-15);
    let rel = |x: f64, y: f64, scale: f64| (x - y).abs() / scale;
    let e_lambda = contact
        .solution
        .lambda
        .normal
        .iter()
        .map(|l| rel(*l, lambda, lambda))
        .fold(0.0, f64::max);
    let Some(e) = &contact.solution.electric else {
        assert_eq!(condition, ElectricCondition::Insulated);
        return (e_lambda, 0.0, 0.0);
    };
    let q_scale = q.abs().max(1e-300);
    let e_q = e.flux.iter().map(|f| rel(*f, q, q_scale)).fold(0.0, f64::max);
    let e_phi = e.potential.iter().map(|p| rel(*p, a, PHI_F)).fold(0.0, f64::max);
    // the charge on the foundation across the zone: -q times the face's area (the flux q
    // leaves the body into it), opposite to the top electrode's (Gauss)
    let charge = solution.report.contact.charge.unwrap();
    assert!(
        (charge + q * area).abs() <= 1e-9 * (q * area).abs().max(1e-12),
        "{charge} vs {}",
        -q * area
    );
    assert!(
        (charge + top.charge).abs() <= 1e-9 * (q * area).abs().max(E33 * DELTA),
        "Gauss: foundation {charge} + top {}",
        top.charge
    );
    (e_lambda, e_q, e_phi)
}

#[test]
fn a_block_on_a_conducting_or_conductive_foundation_is_the_closed_form_to_round_off() {
    for dim in [2, 3] {
        let (el, eq, ep) = errors(dim, ElectricCondition::Conducting, None);
        assert!(
            el < 1e-10 && eq < 1e-10 && ep < 1e-10,
            "{dim}D conducting: {el:e} {eq:e} {ep:e}"
        );
        for sigma in [0.0, 1e-2, 1.0, 1e2, 1e4, 1e8, 1e12] {
            let (el, eq, ep) = errors(dim, ElectricCondition::Conductive, Some(sigma));
            // at σ = 0 the flux is 0: its error is absolute
            let eq = if sigma == 0.0 { eq * 1e-300 } else { eq };
            assert!(
                el < 1e-9 && eq < 1e-8 && ep < 1e-9,
                "{dim}D σ_c = {sigma:e}: {el:e} {eq:e} {ep:e}"
            );
        }
    }
}

/// No conductance is the insulated foundation (the paper's), to round-off; a large one the
/// conducting foundation, at the rate 1/σ_c.
#[test]
fn the_conductive_foundation_tends_to_its_limits() {
    let pressure = |condition, sigma| {
        let s = problem::solve(&block(2, condition, sigma), None, &mut Silent).unwrap();
        s.contact.unwrap().solution.lambda.normal
    };
    let insulated = pressure(ElectricCondition::Insulated, None);
    let none = pressure(ElectricCondition::Conductive, Some(0.0));
    for (a, b) in none.iter().zip(&insulated) {
        assert!((a - b).abs() <= 1e-12 * b.abs(), "σ_c = 0: {a} vs insulated {b}");
    }
    let ideal = pressure(ElectricCondition::Conducting, None);
    let gap = |sigma: f64| {
        let p = pressure(ElectricCondition::Conductive, Some(sigma));
        p.iter().zip(&ideal).map(|(a, b)| (a - b).abs() / b).fold(0.0, f64::max)
    };
    let (d1, d2) = (gap(1e2), gap(1e4));
    let rate = (d1 / d2).log10() / 2.0;
    assert!((rate - 1.0).abs() < 0.05, "rate {rate}: {d1:e} at 1e2, {d2:e} at 1e4");
}

#[test]
fn keys_that_do_not_fit_electrical_contact_are_refused_by_name() {
    let refused = |scene: &str, sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        match files::scene_file::load(scene, &sets).unwrap_err() {
            files::Error::Scene {
                source: files::SceneFileError::Invalid(e),
                ..
            } => e.key,
            other => panic!("{other}"),
        }
    };
    let c = "paper-conductive";
    assert_eq!(refused(c, &["~contact.conductance"]), "contact.conductance");
    assert_eq!(refused(c, &["contact.conductance=-1"]), "contact.conductance");
    assert_eq!(refused(c, &["contact.electric=\"conducting\""]), "contact.conductance");
    assert_eq!(
        refused(c, &["contact.electric=\"insulated\"", "~contact.conductance"]),
        "contact.foundation_potential"
    );
    assert_eq!(refused(c, &["solver.strategy=\"uzawa-condensed\""]), "contact.electric");
    // the PETSc backend solves it too
    let (petsc, _) = files::scene_file::load(c, &["solver.backend=\"petsc\"".into()]).unwrap();
    distributed::supports(&petsc).expect("the PETSc backend solves electrical contact");
    assert_eq!(
        refused("paper-conducting", &["contact.foundation_potential=nan"]),
        "contact.foundation_potential"
    );
    assert_eq!(
        refused("paper-slip-weakening", &["contact.electric=\"conducting\""]),
        "contact.electric"
    );
    // a body without electric unknowns: refused once the plan knows it
    let elastic = files::scene_file::load("paper-elastic", &["contact.electric=\"conducting\"".into()]).unwrap();
    match problem::solve(&elastic.0, None, &mut Silent) {
        Err(problem::ProblemError::Setup(e)) => assert_eq!(e.key, "contact.electric"),
        Err(other) => panic!("{other}"),
        Ok(_) => panic!("an elastic body with electrical contact was solved"),
    }
    // contact switched off: the section's keys are kept, unused, as everywhere
    assert!(files::scene_file::load(c, &["contact.law=\"none\"".into()]).is_ok());
}

/// The manufactured contact scene made a unit cube poled along z, its contact face the bottom.
const BOX_3D: [&str; 6] = [
    "mesh.kind=\"box\"",
    "mesh.lo=[0.0, 0.0, 0.0]",
    "mesh.hi=[1.0, 1.0, 1.0]",
    "material.0.poling=[0.0, 0.0, 1.0]",
    "contact.normal=[0.0, 0.0, -1.0]",
    "contact.gap_center=[0.5, 0.5, 0.0]",
];

/// The manufactured solution in sticking contact with the foundation on the whole contact
/// face (`exact.kind = "manufactured-contact"`, `fe_assembly::Exact::on_foundation`): P1
/// converges as O(h) in the energy norm and O(h²) in L2, in 2D and 3D, every point in contact
/// and sticking, on each foundation: rigid or a bed (linear, or `m = 2.5` under the ideal
/// conductor), its face an ideal conductor, a conductive one (`σ_c = 5`) or an insulator; and
/// on a bed every point sinks by its own law, `(λ_n / k)^(1/m)`.
#[test]
fn the_manufactured_solution_in_contact_converges_at_order_one() {
    let electric: [(&str, &[&str]); 3] = [
        ("conducting", &[]),
        ("conductive", &["contact.conductance=5.0"]),
        ("insulated", &["~contact.foundation_potential"]),
    ];
    let beds: [Option<(f64, f64)>; 3] = [None, Some((100.0, 1.0)), Some((100.0, 2.5))];
    let cases = [(2, [8, 16, 32]), (3, [2, 4, 8])];
    for (dim, sizes) in cases {
        for ((face, face_sets), bed) in electric.iter().flat_map(|e| beds.map(|b| (*e, b))) {
            if face == "conductive" && bed.is_some_and(|(_, m)| m != 1.0) {
                continue; // refused: no closed form (the test below)
            }
            let mut energy = vec![];
            let mut l2 = vec![];
            for n in sizes {
                let mut sets = vec![format!("mesh.n={n}"), format!("contact.electric=\"{face}\"")];
                sets.extend(face_sets.iter().map(|s| s.to_string()));
                if let Some((k, m)) = bed {
                    sets.push(format!("contact.compliance.stiffness={k}"));
                    sets.push(format!("contact.compliance.exponent={m}"));
                }
                if dim == 3 {
                    sets.extend(BOX_3D.map(String::from));
                }
                let what = format!("{dim}D n = {n}, {face}, bed {bed:?}");
                let (scene, _) = files::scene_file::load("manufactured-conducting", &sets).unwrap();
                let s = problem::solve(&scene, None, &mut Silent).unwrap();
                let c = s.contact.as_ref().unwrap();
                let (stick, slip, separated) = c.solution.counts();
                assert!(
                    slip == 0 && separated == 0 && stick > 0,
                    "{what}: {stick} {slip} {separated}"
                );
                if let Some((k, m)) = bed {
                    // sunk into the bed by its own law
                    for (u, (g, l)) in c
                        .displacement
                        .normal
                        .iter()
                        .zip(c.points.gap.iter().zip(&c.solution.lambda.normal))
                    {
                        let sink = (l / k).powf(1.0 / m);
                        assert!(((u - g) - sink).abs() <= 1e-8 * sink, "{what}: {u} {g} {l}");
                    }
                }
                let Some(problem::ExactReport::Field(e)) = &s.report.exact else {
                    panic!("a field solution's errors")
                };
                energy.push(e.rel_energy);
                l2.push(e.rel_l2_u);
            }
            eprintln!("{dim}D {face}, bed {bed:?}: energy {energy:?}, L2 {l2:?}");
            for k in 1..energy.len() {
                let order = |v: &[f64]| (v[k - 1] / v[k]).log2();
                let what = format!("{dim}D {face}, bed {bed:?}");
                assert!(
                    (order(&energy) - 1.0).abs() < 0.1,
                    "{what}: energy order {}",
                    order(&energy)
                );
                assert!(order(&l2) > 1.8, "{what}: L2 order {}", order(&l2));
            }
        }
    }
    // a conductive face on a power-law bed has no closed form: refused by the key
    let sets = [
        "contact.electric=\"conductive\"",
        "contact.conductance=5.0",
        "contact.compliance.stiffness=100.0",
        "contact.compliance.exponent=2.0",
    ]
    .map(String::from);
    match files::scene_file::load("manufactured-conducting", &sets) {
        Err(files::Error::Scene {
            source: files::SceneFileError::Invalid(e),
            ..
        }) => assert_eq!(e.key, "contact.compliance.exponent"),
        other => panic!("{:?}", other.map(|_| ())),
    }
}

/// The manufactured solution with its face sliding (`exact.slip`): the slip
/// `A (1 + sin(π x/2)/2)` along the first tangent and the shear `μ(U) λ_n` along it, for
/// Coulomb's constant coefficient and for slip-weakening friction (exponential, and linear below
/// its slip length; on an insulating foundation, since slip weakening is not solved with
/// electrical contact); P1 converges as O(h) in energy and O(h²) in L2, in 2D and 3D, every
/// point in contact and slipping.
#[test]
fn the_manufactured_sliding_solution_converges_at_order_one() {
    let laws: [(&str, &[&str]); 3] = [
        ("coulomb", &["contact.friction=0.3", "exact.slip=2e-3"]),
        (
            "exponential weakening",
            &[
                "~contact.friction",
                "contact.friction_law=\"slip-weakening\"",
                "contact.friction_static=0.4",
                "contact.friction_dynamic=0.25",
                "contact.slip_length=4e-3",
                "contact.weakening=\"exponential\"",
                "exact.slip=2e-3",
                "contact.electric=\"insulated\"",
                "~contact.foundation_potential",
            ],
        ),
        (
            "linear weakening",
            &[
                "~contact.friction",
                "contact.friction_law=\"slip-weakening\"",
                "contact.friction_static=0.4",
                "contact.friction_dynamic=0.25",
                "contact.slip_length=4e-3",
                "exact.slip=2e-3",
                "contact.electric=\"insulated\"",
                "~contact.foundation_potential",
            ],
        ),
    ];
    let cases = [(2, [8, 16, 32]), (3, [2, 4, 8])];
    for (dim, sizes) in cases {
        for (law, law_sets) in laws {
            let mut energy = vec![];
            let mut l2 = vec![];
            for n in sizes {
                let mut sets = vec![format!("mesh.n={n}")];
                sets.extend(law_sets.iter().map(|s| s.to_string()));
                if dim == 3 {
                    sets.extend(BOX_3D.map(String::from));
                }
                let what = format!("{dim}D n = {n}, {law}");
                let (scene, _) = files::scene_file::load("manufactured-conducting", &sets).unwrap();
                let s = problem::solve(&scene, None, &mut Silent).unwrap_or_else(|e| panic!("{what}: {e}"));
                let c = s.contact.as_ref().unwrap();
                let (stick, slip, separated) = c.solution.counts();
                assert!(
                    stick == 0 && separated == 0 && slip > 0,
                    "{what}: {stick} {slip} {separated}"
                );
                let Some(problem::ExactReport::Field(e)) = &s.report.exact else {
                    panic!("a field solution's errors")
                };
                energy.push(e.rel_energy);
                l2.push(e.rel_l2_u);
            }
            eprintln!("{dim}D {law}: energy {energy:?}, L2 {l2:?}");
            for k in 1..energy.len() {
                let order = |v: &[f64]| (v[k - 1] / v[k]).log2();
                let what = format!("{dim}D {law}");
                assert!(
                    (order(&energy) - 1.0).abs() < 0.1,
                    "{what}: energy order {}",
                    order(&energy)
                );
                assert!(order(&l2) > 1.8, "{what}: L2 order {}", order(&l2));
            }
        }
    }
}

/// One conducting zone among several (zones once could not carry electrical contact): the
/// corner, its open top electrode removed, its right wall an ideal conductor at 0 and its top
/// wall insulated. Where every point of the right wall touches, the conductor is the Dirichlet
/// condition `φ = 0` on the face: the run with that condition in its place gives the same
/// fields, and the wall's charge (the charge on the conductor) is the terminal's. Two zones
/// conducting are refused by key.
#[test]
fn one_conducting_zone_among_several_is_a_terminal_where_it_touches() {
    let (mut base, _) = files::scene_file::load("corner", &[]).unwrap();
    base.electrode = None;
    let mut conducting = base.clone();
    {
        let problem::Contacts::Many(zones) = conducting.contact.as_mut().unwrap() else {
            panic!("the corner has two zones")
        };
        zones[0].electric = Some(ElectricCondition::Conducting);
        zones[0].foundation_potential = Some(0.0);
    }
    let mut grounded = base.clone();
    grounded.dirichlet.push(DirichletSpec {
        group: "right".into(),
        phi: Some(0.0),
        ..Default::default()
    });
    let a = problem::solve(&conducting, None, &mut Silent).unwrap();
    let b = problem::solve(&grounded, None, &mut Silent).unwrap();
    let c = a.contact.as_ref().unwrap();
    let on_wall: Vec<usize> = (0..c.group_of.len()).filter(|&i| c.group_of[i] == 0).collect();
    assert!(
        on_wall.iter().all(|&i| c.solution.lambda.normal[i] > 0.0),
        "every point of the wall touches"
    );
    let e = c.solution.electric.as_ref().unwrap();
    assert!(
        e.points.iter().all(|&i| c.group_of[i] == 0),
        "only the conducting zone's points carry a potential row"
    );
    let scale = b.phi.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    assert!(scale > 0.0);
    let dphi = a.phi.iter().zip(&b.phi).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(dphi <= 1e-9 * scale, "potentials differ by {dphi:e} (scale {scale:e})");
    let uscale = b.u.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let du =
        a.u.iter()
            .flatten()
            .zip(b.u.iter().flatten())
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(du <= 1e-9 * uscale, "displacements differ by {du:e}");
    let wall = a.report.contact.charge.unwrap();
    let terminal = b.report.terminals.iter().find(|t| t.group == "right").unwrap().charge;
    assert!(
        (wall - terminal).abs() <= 1e-8 * terminal.abs(),
        "the wall's charge {wall:e}, the terminal's {terminal:e}"
    );
    // two zones conducting: one conducts, the others are insulated
    let mut both = conducting;
    let problem::Contacts::Many(zones) = both.contact.as_mut().unwrap() else {
        unreachable!()
    };
    zones[1].electric = Some(ElectricCondition::Conducting);
    let e = both.validate().unwrap_err();
    assert_eq!(e.key, "contact.electric", "{e}");
    // along a path, a second zone's conductor is the path's too (it once was refused, and
    // before that solved without it: tests below check the path against the static answer)
    let sets: Vec<String> = [
        "~electrode",
        "contact.1.electric=\"conducting\"",
        "path={t=[0.0,1.0],steps=2,gap=[0.0,1.0]}",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let (scene, _) = files::scene_file::load("corner", &sets).unwrap();
    // a scene with a [path] solves it whole: its last instant, its rows in the report
    let solved = problem::solve(&scene, None, &mut Silent).unwrap();
    let last = solved.contact.as_ref().unwrap();
    let e = last
        .solution
        .electric
        .as_ref()
        .expect("the conducting wall's electric rows");
    assert!(!e.points.is_empty());
}

/// Electrical contact along a load path: `paper-conducting` (a conducting foundation at
/// `φ_F`), frictionless, its load, electrode voltage and foundation potential ramped together
/// from 0. Without friction the answer has no history, so each instant is the static answer
/// at its own data: the path's instant at `t` equals the static run with the load, the
/// voltage and `φ_F` scaled by `t` (its contact force, the electrode's charge, the
/// foundation's flux), to the solver's tolerance, on the conducting and the conductive
/// foundation.
#[test]
fn electrical_contact_follows_a_path_as_its_instants_static_answers() {
    for (electric, extra) in [("conducting", None), ("conductive", Some("contact.conductance=2.0"))] {
        let base = |sets: &[String]| {
            let mut all: Vec<String> = [
                "mesh.n=16",
                "contact.law=\"signorini\"",
                "~contact.friction",
                "contact.foundation_potential=0.01",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect();
            all.push(format!("contact.electric=\"{electric}\""));
            all.extend(extra.map(String::from));
            all.extend(sets.iter().cloned());
            files::scene_file::load("paper-conducting", &all).unwrap().0
        };
        let scene = base(&["path={t=[0.0,1.0],steps=4,load=[0.0,1.0],voltage=[0.0,1.0]}".into()]);
        // a scene with a [path] solves it whole: its last instant, its rows in the report
        let solved = problem::solve(&scene, None, &mut Silent).unwrap();
        let rows = solved.report.path.clone().unwrap().rows;
        assert_eq!(rows.len(), 5);
        for (k, row) in rows.iter().enumerate().skip(1) {
            let t = k as f64 / 4.0;
            let fixed = base(&[
                format!("load.p={}", -2.0 * t),
                format!("electrode.v={}", 0.05 * t),
                format!("contact.foundation_potential={}", 0.01 * t),
            ]);
            let alone = problem::solve(&fixed, None, &mut Silent).unwrap();
            let force = alone.report.contact.normal_force;
            let rel = (row.normal_force - force).abs() / force.abs();
            assert!(
                rel < 1e-7,
                "{electric} t = {t}: force {} against {force} ({rel:.1e})",
                row.normal_force
            );
            // the row's charges are the terminals' in the report's order
            let terminals = &alone.report.terminals;
            let at = terminals.iter().position(|x| x.group == "electrode").unwrap();
            assert_eq!(row.charges.len(), terminals.len());
            let (q, q_path) = (terminals[at].charge, row.charges[at]);
            assert!(
                (q_path - q).abs() <= 1e-7 * q.abs(),
                "{electric} t = {t}: electrode charge {q_path} against {q}"
            );
            if k == 4 {
                // the last instant's fields and the foundation's flux
                let flux = |s: &problem::Solution| -> f64 {
                    let c = s.contact.as_ref().unwrap();
                    let e = c.solution.electric.as_ref().unwrap();
                    e.points.iter().zip(&e.flux).map(|(&i, q)| c.points.weight[i] * q).sum()
                };
                let (f_path, f_alone) = (flux(&solved), flux(&alone));
                assert!(
                    (f_path - f_alone).abs() <= 1e-7 * f_alone.abs(),
                    "{electric}: flux {f_path} against {f_alone}"
                );
                let big = alone.phi.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let dphi = solved
                    .phi
                    .iter()
                    .zip(&alone.phi)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    dphi <= 1e-7 * big,
                    "{electric}: potentials differ by {dphi:.1e} of {big:.1e}"
                );
            }
        }
    }
}

/// The block of the closed form pushed along a path onto a conducting foundation, in 2D and
/// 3D, with Coulomb friction (which the uniaxial state does not engage): its displacement,
/// and the foundation's potential with it, ramped from 0 in 3 steps. The conducting answer is
/// linear in `(δ, φ_F)` together, so each instant carries `t` times the static force, and the
/// last instant is the static run (the closed form) to round-off: the pressure, the flux and
/// the potentials at the points.
#[test]
fn a_block_pushed_along_a_path_onto_a_conductor_is_the_static_answer_scaled() {
    for dim in [2, 3] {
        let fixed = block(dim, ElectricCondition::Conducting, None);
        let alone = problem::solve(&fixed, None, &mut Silent).unwrap();
        let mut walked = fixed.clone();
        walked.path = Some(problem::PathSpec {
            t: vec![0.0, 1.0],
            steps: Some(3),
            displacement: Some(vec![0.0, 1.0]),
            voltage: Some(vec![0.0, 1.0]),
            ..Default::default()
        });
        let mut forces = vec![];
        let path = problem::solve_path(
            &walked,
            None,
            problem::Limits::default(),
            &mut Silent,
            false,
            &mut |step| {
                forces.push((step.row.t, step.row.normal_force));
                Ok(())
            },
        )
        .unwrap();
        let force = alone.report.contact.normal_force;
        for (t, f) in forces {
            assert!(
                (f - t * force).abs() <= 1e-9 * force,
                "{dim}D t = {t}: force {f} against {}",
                t * force
            );
        }
        let (a, b) = (path.last.contact.as_ref().unwrap(), alone.contact.as_ref().unwrap());
        let close = |x: &[f64], y: &[f64], what: &str| {
            let big = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let d = x.iter().zip(y).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            assert!(d <= 1e-9 * big, "{dim}D {what}: {d:.1e} of {big:.1e}");
        };
        close(&a.solution.lambda.normal, &b.solution.lambda.normal, "pressure");
        let (ea, eb) = (
            a.solution.electric.as_ref().unwrap(),
            b.solution.electric.as_ref().unwrap(),
        );
        close(&ea.flux, &eb.flux, "flux");
        close(&ea.potential, &eb.potential, "potential");
    }
}

/// A floating conducting zone among several (zones once could not float): the corner, its
/// left face grounded instead of its bottom, its right wall an ideal conductor carrying the
/// charge 1e-3. Where every point of the wall touches, the floating conductor is a floating
/// terminal with that charge on the face: the same fields, the wall's potential the
/// terminal's, and the grounded face carrying the opposite charge (Gauss).
#[test]
fn a_floating_conducting_zone_among_several_is_a_floating_terminal_where_it_touches() {
    let run = |extra: &[&str]| {
        let mut sets: Vec<String> = ["~electrode", "~dirichlet.1.phi", "dirichlet.0.phi=0.0"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        sets.extend(extra.iter().map(|s| s.to_string()));
        let (scene, _) = files::scene_file::load("corner", &sets).unwrap();
        problem::solve(&scene, None, &mut Silent).unwrap()
    };
    let q = 1e-3;
    let a = run(&["contact.0.electric=\"conducting\"", &format!("contact.0.charge={q}")]);
    let b = run(&[&format!("electrode={{group=\"right\",charge={q},name=\"wall\"}}")]);
    let c = a.contact.as_ref().unwrap();
    assert!((0..c.group_of.len())
        .filter(|&i| c.group_of[i] == 0)
        .all(|i| c.solution.lambda.normal[i] > 0.0));
    let wall = b.report.terminals.iter().find(|t| t.group == "wall").unwrap();
    let potential = a.report.contact.potential.unwrap();
    assert!(
        (potential - wall.potential).abs() <= 1e-9 * wall.potential.abs(),
        "{potential:e} against {:e}",
        wall.potential
    );
    assert!((a.report.contact.charge.unwrap() - q).abs() <= 1e-9 * q);
    let left = a.report.terminals.iter().find(|t| t.group == "left").unwrap();
    assert!(
        (left.charge + q).abs() <= 1e-9 * q,
        "Gauss: the grounded face carries {:e}",
        left.charge
    );
    let scale = b.phi.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    let dphi = a.phi.iter().zip(&b.phi).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(dphi <= 1e-9 * scale, "potentials differ by {dphi:e} of {scale:e}");
}

/// The manufactured solution in contact at order 2 (`mesh.order = 2`): in 2D sticking on a
/// conducting foundation and sliding under Coulomb's law; in 3D (the modified basis) sticking
/// and sliding on an insulated face, and sticking on a conducting foundation.
///
/// - Source: for P2 the energy-norm error is O(h²) where the solution is smooth (Ciarlet
///   1978); in 2D the contact face's points are the nodes of its three-node segments, weighted
///   by `∫ N_a ds` (Simpson's `L/6, 2L/3, L/6`); in 3D the modified basis of Popp et al. (2012),
///   its gap the basis's too (`boundary::MODIFIED_ALPHA`).
/// - Expected (measured): 2D sticking 3.88e-4, 9.70e-5, 2.43e-5 at n = 8, 16, 32 (order
///   2.00), sliding 6.65e-4, 1.67e-4, 4.19e-5 (2.00); 3D sticking 5.26e-3, 1.31e-3, 3.29e-4 at
///   n = 2, 4, 8 (2.00; P1 at n = 8: 2.1e-2), sliding 5.22e-3, 1.34e-3, 3.42e-4 (1.96, 1.98),
///   conducting 6.29e-3, 1.58e-3, 3.97e-4 (1.99; P1 at n = 8: 2.6e-2).
/// - Tolerance: order in [1.9, 2.1].
#[test]
fn the_manufactured_solution_in_contact_converges_at_order_two_with_quadratic_elements() {
    let mut box_insulated = BOX_3D.to_vec();
    box_insulated.push("contact.electric=\"insulated\"");
    let sliding = ["contact.friction=0.3", "exact.slip=2e-3"];
    let mut sliding_3d = box_insulated.clone();
    sliding_3d.extend(sliding);
    sliding_3d.push("~contact.foundation_potential");
    let mut sticking_3d = box_insulated.clone();
    sticking_3d.push("~contact.foundation_potential");
    // conducting in 3D: the points' potentials in the modified basis too (their terms on
    // the sides' prescribed potentials among them)
    let conducting_3d = &BOX_3D[..];
    let cases: [(&str, &[&str], [usize; 3]); 5] = [
        ("2D sticking, conducting", &[], [8, 16, 32]),
        ("2D sliding", &sliding, [8, 16, 32]),
        ("3D sticking (the modified basis)", &sticking_3d, [2, 4, 8]),
        ("3D sliding (the modified basis)", &sliding_3d, [2, 4, 8]),
        ("3D sticking, conducting (the modified basis)", conducting_3d, [2, 4, 8]),
    ];
    for (law, extra, sizes) in cases {
        let errors: Vec<f64> = sizes
            .iter()
            .map(|n| {
                let mut sets = vec![format!("mesh.n={n}"), "mesh.order=2".into()];
                sets.extend(extra.iter().map(|s| s.to_string()));
                let r =
                    driver::studies::solve("manufactured-conducting", &sets).unwrap_or_else(|e| panic!("{law}: {e}"));
                assert_eq!(r.mesh.kind.order(), 2);
                r.report.exact.unwrap().error()
            })
            .collect();
        let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        assert!(
            orders.iter().all(|o| (1.9..2.1).contains(o)),
            "{law}: errors {errors:?}, orders {orders:?}"
        );
    }
}
