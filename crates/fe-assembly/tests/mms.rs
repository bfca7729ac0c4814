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

use common::{solve_both, voigt};
use fe_assembly::{kernels, Constraint, Crystal, Discretization, Field, Load, Material};
use std::f64::consts::PI;
use std::sync::Arc;

/// Value, gradient and Hessian of one scalar field.
type Jet = (f64, [f64; 3], [[f64; 3]; 3]);

/// `a sin(kx x + px) sin(ky y + py) sin(kz z + pz)` with its derivatives (z factor 1 in 2D).
fn prod(dim: usize, a: f64, k: [f64; 3], p: [f64; 3], x: &[f64]) -> Jet {
    let s: Vec<f64> = (0..3)
        .map(|i| if i < dim { (k[i] * x[i] + p[i]).sin() } else { 1.0 })
        .collect();
    let c: Vec<f64> = (0..3)
        .map(|i| {
            if i < dim {
                k[i] * (k[i] * x[i] + p[i]).cos()
            } else {
                0.0
            }
        })
        .collect();
    let s2: Vec<f64> = (0..3)
        .map(|i| if i < dim { -k[i] * k[i] * s[i] } else { 0.0 })
        .collect();
    let v = a * s[0] * s[1] * s[2];
    let mut g = [0.0; 3];
    let mut h = [[0.0; 3]; 3];
    for i in 0..dim {
        let f = |q: usize| if q == i { c[q] } else { s[q] };
        g[i] = a * f(0) * f(1) * f(2);
        for j in 0..dim {
            let ff = |q: usize| {
                if q == i && q == j {
                    s2[q]
                } else if q == i || q == j {
                    c[q]
                } else {
                    s[q]
                }
            };
            h[i][j] = a * ff(0) * ff(1) * ff(2);
        }
    }
    (v, g, h)
}

fn u_jet(dim: usize, k: usize, x: &[f64]) -> Jet {
    prod(
        dim,
        1e-3,
        [PI * (k as f64 + 1.0) / 2.0, PI, PI / 2.0],
        [0.0, 0.0, PI / 2.0],
        x,
    )
}
fn phi_jet(dim: usize, x: &[f64]) -> Jet {
    prod(dim, 1e-2, [PI / 2.0, PI, PI / 2.0], [PI / 2.0, 0.0, PI / 2.0], x)
}

/// `(L2 error of (u, φ), energy error)` on the mesh of size n.
fn errors(dim: usize, n: usize) -> (f64, f64) {
    let mesh = if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 2 * n, n)
    } else {
        mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 2 * n, n, n)
    };
    let poling = if dim == 2 { [0.0, 1.0, 0.0] } else { [0.0, 0.0, 1.0] };
    let m = Material::from_crystal("pzt5a", &Crystal::pzt5a(), poling, dim).unwrap();
    let nv = m.nv();
    let (mf, mq) = (m.clone(), m.clone());
    let f0 = move |x: &[f64]| {
        // f0_i = -Σ_j ∂_j σ_ij = -Σ_j Σ_kl C_ijkl ∂_jl u_k - Σ_j Σ_k e_kij ∂_jk φ
        let hu: Vec<Jet> = (0..dim).map(|k| u_jet(dim, k, x)).collect();
        let hp = phi_jet(dim, x).2;
        let mut f = [0.0; 3];
        for i in 0..dim {
            let mut s = 0.0;
            for j in 0..dim {
                for k in 0..dim {
                    for l in 0..dim {
                        s += mf.c[voigt(dim, i, j) * nv + voigt(dim, k, l)] * hu[k].2[l][j];
                    }
                    s += mf.e[k * nv + voigt(dim, i, j)] * hp[k][j];
                }
            }
            f[i] = -s;
        }
        f
    };
    let q0 = move |x: &[f64]| {
        // q0 = div D = Σ_i (Σ_kl e_ikl ∂_il u_k - Σ_k β_ik ∂_ik φ)
        let hu: Vec<Jet> = (0..dim).map(|k| u_jet(dim, k, x)).collect();
        let hp = phi_jet(dim, x).2;
        let mut s = 0.0;
        for i in 0..dim {
            for k in 0..dim {
                for l in 0..dim {
                    s += mq.e[i * nv + voigt(dim, k, l)] * hu[k].2[l][i];
                }
                s -= mq.beta[i * dim + k] * hp[i][k];
            }
        }
        s
    };
    let groups: &[&str] = if dim == 2 {
        &["left", "right", "bottom", "top"]
    } else {
        &["left", "right", "bottom", "top", "front", "back"]
    };
    let mut bcs = vec![];
    for &g in groups {
        for k in 0..dim {
            bcs.push(Constraint {
                group: g.into(),
                field: Field::Displacement(k),
                value: Arc::new(move |x| u_jet(dim, k, x).0),
            });
        }
        bcs.push(Constraint {
            group: g.into(),
            field: Field::Potential,
            value: Arc::new(move |x| phi_jet(dim, x).0),
        });
    }
    let disc = Discretization::new(&mesh, &[("body".into(), m.clone())], &bcs).unwrap();
    let loads = [Load::BodyForce(Arc::new(f0)), Load::BodyCharge(Arc::new(q0))];
    let ((u1, p1), (u2, p2), _) = solve_both(&disc, &loads);
    // the two strategies agree to round-off
    let scale = u1.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(common::max_diff(&u1, &u2) < 1e-9 * scale, "strategies disagree");
    assert!(common::max_diff(&p1, &p2) < 1e-9 * p1.iter().fold(0.0f64, |a, x| a.max(x.abs())));
    let (un, pn) = (disc.dofs.expand_u(&u1), disc.dofs.expand_phi(&p1));
    // integrate the errors with a degree-2 rule per cell (exact for the P1 error's square up
    // to O(h^3) terms of the smooth part, enough for the rates)
    let rule: Vec<[f64; 4]> = if dim == 2 {
        let (a, b) = (2.0 / 3.0, 1.0 / 6.0);
        vec![[a, b, b, 0.0], [b, a, b, 0.0], [b, b, a, 0.0]]
    } else {
        let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
        vec![[a, b, b, b], [b, a, b, b], [b, b, a, b], [b, b, b, a]]
    };
    let (mut l2, mut energy) = (0.0, 0.0);
    for (c, cell) in mesh.iter_cells().enumerate() {
        let g = &disc.geometry[c];
        let w = g.measure / rule.len() as f64;
        let ul: Vec<[f64; 3]> = cell.iter().map(|&v| un[v]).collect();
        let pl: Vec<f64> = cell.iter().map(|&v| pn[v]).collect();
        let eps_h = kernels::cell_strain(dim, g, &ul);
        let gp_h = kernels::cell_gradient(dim, g, &pl);
        for bary in &rule {
            let mut x = [0.0; 3];
            let (mut uh, mut ph) = ([0.0; 3], 0.0);
            for (a, &v) in cell.iter().enumerate() {
                for k in 0..3 {
                    x[k] += bary[a] * mesh.points[v][k];
                    uh[k] += bary[a] * un[v][k];
                }
                ph += bary[a] * pn[v];
            }
            let x = &x[..dim];
            let ju: Vec<Jet> = (0..dim).map(|k| u_jet(dim, k, x)).collect();
            let jp = phi_jet(dim, x);
            for k in 0..dim {
                l2 += w * (uh[k] - ju[k].0).powi(2);
            }
            l2 += w * (ph - jp.0).powi(2);
            // strain error (Voigt, engineering shear) and its energy
            let mut de = [0.0; 6];
            for i in 0..dim {
                for j in i..dim {
                    let exact = if i == j { ju[i].1[i] } else { ju[i].1[j] + ju[j].1[i] };
                    de[voigt(dim, i, j)] = eps_h[voigt(dim, i, j)] - exact;
                }
            }
            for a in 0..nv {
                for b in 0..nv {
                    energy += w * de[a] * m.c[a * nv + b] * de[b];
                }
            }
            let dg: Vec<f64> = (0..dim).map(|i| gp_h[i] - jp.1[i]).collect();
            for a in 0..dim {
                for b in 0..dim {
                    energy += w * dg[a] * m.beta[a * dim + b] * dg[b];
                }
            }
        }
    }
    (l2.sqrt(), energy.sqrt())
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

fn rates(rows: &[(usize, f64, f64)]) -> Vec<(f64, f64)> {
    rows.windows(2)
        .map(|w| {
            let r = (w[1].0 as f64 / w[0].0 as f64).ln();
            ((w[0].1 / w[1].1).ln() / r, (w[0].2 / w[1].2).ln() / r)
        })
        .collect()
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
