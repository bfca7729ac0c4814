//! Manufactured solution of the coupled linear problem (method of manufactured solutions, e.g.
//! Roache, "Code Verification by the Method of Manufactured Solutions", 2002).
//!
//! Goal: P1 converges at the optimal rates, O(h²) in L2 and O(h) in the energy norm, in 2D and
//! 3D; the measured errors are stored in `tests/reference/mms.csv` and checked against it.
//!
//! ```text
//!   Ω = (0,2) x (0,1) [x (0,1)],  PZT-5A poled along y (2D) or z (3D)
//!   u_k = 1e-3 sin(π x (k+1)/2) sin(π y) [cos(π z / 2)],   φ = 1e-2 cos(π x / 2) sin(π y) [..]
//!   f0 = -div σ(u, φ),  q0 = div D(u, φ)  (computed from the Hessians),  u, φ prescribed on ∂Ω
//! ```
//!
//! Energy norm: `a(e, e) = ∫ ε(e_u):C:ε(e_u) + ∫ ∇e_φ·β∇e_φ` (the coupling cancels in the
//! paper's form). Expected rates: L2 ≥ 1.9, energy ≥ 0.95 between the two finest levels, and
//! errors within 2 % of the reference table (set `PIEZO_BLESS=1` to rewrite it).

mod common;

use common::{rates, solve_both};
use fe_assembly::{Crystal, Discretization, Exact, Material};

/// `(L2 error of (u, φ), energy error)` on the mesh of size n.
fn errors(dim: usize, n: usize) -> (f64, f64) {
    let mesh = if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 2 * n, n)
    } else {
        mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 2 * n, n, n)
    };
    let poling = if dim == 2 { [0.0, 1.0, 0.0] } else { [0.0, 0.0, 1.0] };
    let m = Material::from_crystal("pzt5a", &Crystal::pzt5a(), poling, dim).unwrap();
    let exact = Exact::manufactured(dim);
    let groups: &[&str] = if dim == 2 {
        &["left", "right", "bottom", "top"]
    } else {
        &["left", "right", "bottom", "top", "front", "back"]
    };
    let disc = Discretization::new(
        &mesh,
        fe_assembly::Coordinates::Cartesian,
        &[("body".into(), m.clone())],
        &exact.constraints(groups),
    )
    .unwrap();
    let loads = exact.loads(&m);
    let ((u1, p1), (u2, p2), _) = solve_both(&disc, &loads);
    // the two strategies agree to round-off
    let scale = u1.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(common::max_diff(&u1, &u2) < 1e-9 * scale, "strategies disagree");
    assert!(common::max_diff(&p1, &p2) < 1e-9 * p1.iter().fold(0.0f64, |a, x| a.max(x.abs())));
    let (un, pn) = (disc.dofs.expand_u(&u1), disc.dofs.expand_phi(&p1));
    let e = disc.error_norms(&un, &pn, &exact);
    ((e.l2_u.powi(2) + e.l2_phi.powi(2)).sqrt(), e.energy)
}

fn study(dim: usize, levels: &[usize]) -> Vec<(usize, f64, f64)> {
    levels
        .iter()
        .map(|&n| {
            let (l2, en) = errors(dim, n);
            (n, l2, en)
        })
        .collect()
}

fn check_against_reference(dim: usize, rows: &[(usize, f64, f64)]) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/mms.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_default();
    if std::env::var("PIEZO_BLESS").is_ok() {
        let mut kept: Vec<String> = text
            .lines()
            .filter(|l| !l.starts_with(&format!("{dim},")))
            .map(String::from)
            .collect();
        if kept.is_empty() {
            kept.push("dim,n,l2_error,energy_error".into());
        }
        for (n, l2, en) in rows {
            kept.push(format!("{dim},{n},{l2:.6e},{en:.6e}"));
        }
        std::fs::write(&path, kept.join("\n") + "\n").unwrap();
        return;
    }
    let mut found = 0;
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f[0].parse::<usize>().unwrap() != dim {
            continue;
        }
        let n: usize = f[1].parse().unwrap();
        let (l2, en): (f64, f64) = (f[2].parse().unwrap(), f[3].parse().unwrap());
        let row = rows.iter().find(|r| r.0 == n).expect("level in the reference table");
        assert!(
            (row.1 / l2 - 1.0).abs() < 0.02,
            "{dim}D n={n}: L2 {} vs reference {l2}",
            row.1
        );
        assert!(
            (row.2 / en - 1.0).abs() < 0.02,
            "{dim}D n={n}: energy {} vs reference {en}",
            row.2
        );
        found += 1;
    }
    assert_eq!(
        found,
        rows.len(),
        "reference table {} lacks {dim}D rows",
        path.display()
    );
}

#[test]
fn mms_rates_2d() {
    let rows = study(2, &[4, 8, 16, 32]);
    let r = rates(&rows);
    eprintln!("2D MMS: {rows:?}\nrates (L2, energy): {r:?}");
    let last = r.last().unwrap();
    assert!(last.0 > 1.9 && last.0 < 2.2, "L2 rate {}", last.0);
    assert!(last.1 > 0.95 && last.1 < 1.2, "energy rate {}", last.1);
    check_against_reference(2, &rows);
}

#[test]
fn mms_rates_3d() {
    let rows = study(3, &[2, 4, 8]);
    let r = rates(&rows);
    eprintln!("3D MMS: {rows:?}\nrates (L2, energy): {r:?}");
    let last = r.last().unwrap();
    assert!(last.0 > 1.8 && last.0 < 2.3, "L2 rate {}", last.0);
    assert!(last.1 > 0.9 && last.1 < 1.2, "energy rate {}", last.1);
    check_against_reference(3, &rows);
}
