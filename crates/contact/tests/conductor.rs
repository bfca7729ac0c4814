//! The ideal conductor's family of solutions, on problems small enough to solve by hand: the
//! member Newton returns is the widest (a point the conductor's potential attracts is in
//! contact wherever its being in contact solves the conditions), and a floating conductor's
//! search meets its charge between two members by their mixture.
//!
//! The problems are condensed compliances `D = [[A, B], [-Bᵀ, E]]` (mechanical rows, then one
//! electric row per point), `u = u₀ - D W [λ; q]` with unit weights and gaps 0.

use contact::{
    solve_floating, solve_newton_electric, ContactPoints, ContactSolution, ElectricContact, ElectricContactProblem,
    ElectricLaw, FloatingError, Foundation, Law, NewtonParams, PointValues,
};

fn points(n: usize) -> ContactPoints {
    ContactPoints {
        dim: 2,
        position: (0..n).map(|i| [i as f64, 0.0, 0.0]).collect(),
        normal: vec![[0.0, -1.0, 0.0]; n],
        tangent: vec![[[1.0, 0.0, 0.0], [0.0; 3]]; n],
        weight: vec![1.0; n],
        gap: vec![0.0; n],
        friction: vec![0.0; n],
        held: vec![[false; 2]; n],
        foundation: Foundation::Rigid,
        foundations: vec![],
        slipped: vec![],
        weakening: vec![],
        tresca: vec![],
    }
}

/// Point 0 pressed in (`u₀ = 1`), electrically on its own (`q₀ = φ₀ - ψ`); point 1 held off
/// by 1 (`u₀ = -1`) and pulled in by the potential: `[λ₁ + q₁; -λ₁ + q₁] = [u₀ - g; φ₀ - ψ]`
/// in contact. Point 1 separated solves the conditions at every `ψ`; in contact
/// (`λ₁ = (ψ - 1)/2`) wherever `ψ ≥ 1`: two members there, the widest with charge
/// `Q = ψ + (ψ + 1)/2` against `Q = ψ` without point 1.
fn attracted(psi: f64) -> ElectricContactProblem {
    #[rustfmt::skip]
    let compliance = vec![
        1.0, 0.0, 0.0, 0.0,
        0.0, 1.0, 0.0, 1.0,
        0.0, 0.0, 1.0, 0.0,
        0.0, -1.0, 0.0, 1.0,
    ];
    ElectricContactProblem {
        u0: PointValues::from_parts(vec![1.0, -1.0], vec![], 0).unwrap(),
        phi0: vec![0.0, 0.0],
        compliance,
        weight: vec![1.0, 1.0],
        nt: 0,
        electric: ElectricContact {
            law: ElectricLaw::Conducting,
            potential: psi,
            points: vec![0, 1],
        },
    }
}

fn params() -> NewtonParams {
    NewtonParams {
        tol: 1e-12,
        ..Default::default()
    }
}

fn solve(problem: &ElectricContactProblem, points: &ContactPoints) -> Result<ContactSolution, contact::ContactError> {
    solve_newton_electric(problem, points, &Law::Frictionless, &params(), &mut |_| {})
}

#[test]
fn the_member_returned_is_the_widest() {
    let pts = points(2);
    for psi in [0.0, 0.5, 0.99, 1.0, 1.5, 3.0] {
        let sol = solve(&attracted(psi), &pts).unwrap();
        let want = if psi >= 1.0 { (psi - 1.0) / 2.0 } else { 0.0 };
        let got = sol.lambda.normal[1];
        assert!(
            (got - want).abs() <= 1e-10,
            "ψ = {psi}: λ₁ = {got}, the widest member's {want}"
        );
        assert!(
            (sol.lambda.normal[0] - 1.0).abs() <= 1e-10,
            "ψ = {psi}: {:?}",
            sol.lambda
        );
        let q = sol.electric.as_ref().unwrap().charge(&pts.weight);
        let want_q = psi + if psi > 1.0 { (psi + 1.0) / 2.0 } else { 0.0 };
        // at ψ = 1 both members carry λ₁ = 0; the widest has point 1's flux
        if psi != 1.0 {
            assert!((q - want_q).abs() <= 1e-10, "ψ = {psi}: Q = {q}, want {want_q}");
        }
    }
}

#[test]
fn a_floating_conductor_meets_its_charge_on_a_member_or_between_two() {
    let pts = points(2);
    // on a member: below the jump (point 1 off), above it (point 1 on)
    for (charge, psi) in [(0.5, 0.5), (2.5, 4.0 / 3.0)] {
        let mut problem = attracted(0.0);
        let sol = solve_floating(&mut problem, &pts, charge, solve).unwrap();
        let q = sol.electric.as_ref().unwrap().charge(&pts.weight);
        assert!((q - charge).abs() <= 1e-9, "Q = {q}, want {charge}");
        assert!(
            (problem.electric.potential - psi).abs() <= 1e-9,
            "ψ = {}",
            problem.electric.potential
        );
    }
    // in the jump at ψ = 1 (Q from 1 to 2): the mixture carrying the charge, its point 1's
    // flux that fraction of the member's above
    for (charge, theta) in [(1.25, 0.25), (1.5, 0.5), (1.9, 0.9)] {
        let mut problem = attracted(0.0);
        let sol = solve_floating(&mut problem, &pts, charge, solve).unwrap();
        let e = sol.electric.as_ref().unwrap();
        assert!((e.charge(&pts.weight) - charge).abs() <= 1e-9, "{sol:?}");
        assert!(
            (problem.electric.potential - 1.0).abs() <= 1e-9,
            "ψ = {}",
            problem.electric.potential
        );
        // above the jump point 1's flux is q₁ = -(ψ + 1)/2 = -1
        assert!((e.flux[1] + theta).abs() <= 1e-6, "θ = {theta}: q₁ = {}", e.flux[1]);
        assert!(sol.lambda.normal[1].abs() <= 1e-6, "{:?}", sol.lambda);
    }
    // a conductor that touches nowhere carries no charge: refused, not guessed
    let mut off = attracted(0.0);
    off.u0 = PointValues::from_parts(vec![-1.0, -1.0], vec![], 0).unwrap();
    let e = solve_floating(&mut off, &pts, 1.0, solve).unwrap_err();
    assert!(matches!(e, FloatingError::Untouched { .. }), "{e}");
}
