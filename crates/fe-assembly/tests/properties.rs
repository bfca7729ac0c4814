//! Property tests of the assembled coupled form (docs/theory.md, "The bilinear form and the
//! blocks"):
//! - coercivity: `xᵀ [[A, Gᵀ], [-G, B]] x = uᵀ A u + φᵀ B φ` to round-off, both parts
//!   positive, on random admissible materials and randomly perturbed meshes;
//! - the symmetric `K` has exactly `n_φ` negative pivots;
//! - serial (cell loop) and parallel (node-owned) assembly give the same matrices;
//! - rigid motions lie in the kernel of the unconstrained `A`.

use fe_assembly::{Constraint, Crystal, Discretization, Field, Material, Parallelism};
use linalg::sparse::{mul_add, mul_t_add};
use linalg::{DirectLdlt, Ordering};
use proptest::prelude::*;

/// A random admissible crystal: C = M Mᵀ + δ I, e arbitrary, permittivity = N Nᵀ + δ I.
fn crystal(seed: &[f64]) -> Crystal {
    let mut c = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            c[i][j] = (0..6).map(|k| seed[i * 6 + k] * seed[j * 6 + k]).sum::<f64>();
        }
        c[i][i] += 0.5;
    }
    let mut e = [[0.0; 6]; 3];
    for i in 0..3 {
        for j in 0..6 {
            e[i][j] = 3.0 * seed[36 + i * 6 + j];
        }
    }
    let mut p = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            p[i][j] = (0..3).map(|k| seed[54 + i * 3 + k] * seed[54 + j * 3 + k]).sum::<f64>();
        }
        p[i][i] += 0.2;
    }
    Crystal { c, e, permittivity: p }
}

fn perturbed_mesh(dim: usize, n: usize, jitter: &[f64]) -> mesh::Mesh {
    let mut m = if dim == 2 {
        mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 2 * n, n)
    } else {
        mesh::box_tet([0.0; 3], [2.0, 1.0, 1.0], 2 * n, n, n)
    };
    let h = 1.0 / n as f64;
    let (lo, hi) = m.bounding_box();
    for (i, p) in m.points.iter_mut().enumerate() {
        if (0..dim).any(|q| p[q] == lo[q] || p[q] == hi[q]) {
            continue;
        }
        for k in 0..dim {
            p[k] += 0.2 * h * jitter[(i * 3 + k) % jitter.len()];
        }
    }
    m
}

fn clamped(dim: usize) -> Vec<Constraint> {
    let mut bcs = vec![];
    for side in ["left", "right"] {
        for k in 0..dim {
            bcs.push(Constraint::constant(side, Field::Displacement(k), 0.0));
        }
        bcs.push(Constraint::constant(side, Field::Potential, 0.0));
    }
    bcs
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn coupled_form_is_coercive_and_k_has_the_right_inertia(
        dim in 2usize..=3,
        seed in prop::collection::vec(-1.0f64..1.0, 63),
        jitter in prop::collection::vec(-1.0f64..1.0, 64),
        x in prop::collection::vec(-1.0f64..1.0, 4000),
        poling in prop::collection::vec(-1.0f64..1.0, 3),
    ) {
        let n = if dim == 2 { 3 } else { 1 };
        let mesh = perturbed_mesh(dim, n, &jitter);
        prop_assume!(mesh.check().is_ok());
        let pol = [poling[0], poling[1], poling[2] + 2.0];
        let mat = Material::from_crystal("random", &crystal(&seed), pol, dim).unwrap();
        let disc = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &[("body".into(), mat)], &clamped(dim)).unwrap();
        let bl = disc.assemble(Parallelism::Rayon);
        let (nu, np) = (disc.dofs.n_u, disc.dofs.n_phi);
        let (u, phi) = (&x[..nu], &x[nu..nu + np]);
        let mut au = vec![0.0; nu];
        mul_add(bl.a.as_ref(), u, &mut au, 1.0);
        let mut gtphi = vec![0.0; nu];
        mul_t_add(bl.g.as_ref(), phi, &mut gtphi, 1.0);
        let mut gu = vec![0.0; np];
        mul_add(bl.g.as_ref(), u, &mut gu, 1.0);
        let mut bphi = vec![0.0; np];
        mul_add(bl.b.as_ref(), phi, &mut bphi, 1.0);
        let uau: f64 = u.iter().zip(&au).map(|(a, b)| a * b).sum();
        let pbp: f64 = phi.iter().zip(&bphi).map(|(a, b)| a * b).sum();
        let cross: f64 = u.iter().zip(&gtphi).map(|(a, b)| a * b).sum::<f64>()
            - phi.iter().zip(&gu).map(|(a, b)| a * b).sum::<f64>();
        let total = uau + pbp + cross;
        prop_assert!(uau > 0.0 && pbp > 0.0, "uAu = {uau}, phiBphi = {pbp}");
        prop_assert!((total - (uau + pbp)).abs() <= 1e-12 * (uau + pbp), "{total} vs {}", uau + pbp);
        // inertia of K
        let ldlt = DirectLdlt::new(&bl.a, &bl.g, &bl.b, &Ordering::Amd, faer::Par::Seq).unwrap();
        let (pos, neg, zero) = ldlt.factor().inertia();
        prop_assert_eq!((pos, neg, zero), (nu, np, 0));
    }

    #[test]
    fn serial_and_parallel_assembly_agree(
        dim in 2usize..=3,
        seed in prop::collection::vec(-1.0f64..1.0, 63),
        jitter in prop::collection::vec(-1.0f64..1.0, 64),
    ) {
        let n = if dim == 2 { 4 } else { 2 };
        let mesh = perturbed_mesh(dim, n, &jitter);
        prop_assume!(mesh.check().is_ok());
        let mat = Material::from_crystal("random", &crystal(&seed), [0.0, 0.3, 1.0], dim).unwrap();
        let disc = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &[("body".into(), mat)], &clamped(dim)).unwrap();
        let (s, p) = (disc.assemble(Parallelism::Serial), disc.assemble(Parallelism::Rayon));
        for (x, y) in [(&s.a, &p.a), (&s.g, &p.g), (&s.b, &p.b)] {
            prop_assert_eq!(x.symbolic().col_ptr(), y.symbolic().col_ptr());
            prop_assert_eq!(x.symbolic().row_idx(), y.symbolic().row_idx());
            let scale = x.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in x.val().iter().zip(y.val()) {
                prop_assert!((a - b).abs() <= 1e-13 * scale);
            }
        }
        // A is symmetric
        let d = linalg::sparse::to_dense(p.a.as_ref());
        for i in 0..d.len() {
            for j in 0..i {
                prop_assert!((d[i][j] - d[j][i]).abs() <= 1e-13 * d[i][i].abs().max(d[j][j].abs()));
            }
        }
    }

    #[test]
    fn rigid_motions_are_in_the_kernel_of_a(
        dim in 2usize..=3,
        seed in prop::collection::vec(-1.0f64..1.0, 63),
        jitter in prop::collection::vec(-1.0f64..1.0, 64),
    ) {
        let n = if dim == 2 { 3 } else { 1 };
        let mesh = perturbed_mesh(dim, n, &jitter);
        prop_assume!(mesh.check().is_ok());
        let mat = Material::from_crystal("random", &crystal(&seed), [1.0, 0.0, 1.0], dim).unwrap();
        // no conditions: A is the full stiffness matrix, singular on rigid motions
        let disc = Discretization::new(&mesh, fe_assembly::Coordinates::Cartesian, &[("body".into(), mat)], &[]).unwrap();
        let bl = disc.assemble(Parallelism::Rayon);
        let mut motions: Vec<Vec<[f64; 3]>> = vec![];
        for k in 0..dim {
            motions.push((0..mesh.n_nodes()).map(|_| { let mut t = [0.0; 3]; t[k] = 1.0; t }).collect());
        }
        let rotations: Vec<(usize, usize)> = if dim == 2 { vec![(0, 1)] } else { vec![(0, 1), (1, 2), (0, 2)] };
        for (a, b) in rotations {
            motions.push((0..mesh.n_nodes()).map(|i| {
                let x = mesh.points[i];
                let mut r = [0.0; 3];
                r[a] = -x[b];
                r[b] = x[a];
                r
            }).collect());
        }
        let scale = bl.a.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for mo in motions {
            let v = disc.dofs.restrict_u(&mo);
            let mut out = vec![0.0; v.len()];
            mul_add(bl.a.as_ref(), &v, &mut out, 1.0);
            let r = out.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            prop_assert!(r <= 1e-12 * scale * 3.0, "rigid motion residual {r} (scale {scale})");
            // and the coupling sees no strain either
            let mut gout = vec![0.0; disc.dofs.n_phi];
            mul_add(bl.g.as_ref(), &v, &mut gout, 1.0);
            prop_assert!(gout.iter().all(|x| x.abs() <= 1e-12 * scale * 3.0));
        }
    }
}
