//! The contact crate without finite elements: a 1D elastic bed (a string of points joined by
//! springs, each also tied to a moving base) pressed onto a rigid floor and dragged sideways,
//! with Coulomb friction. Its contact compliance is written here as a dense matrix, and the
//! problem is solved by semismooth Newton and by Uzawa with the fixed point on the friction
//! threshold; both must give the same multipliers.
//!
//! Run: `cargo run --release -p contact --example elastic_bed [-- n F]` (default 40 points,
//! F = 0.6: a central stick zone between two slip zones, as in Cattaneo-Mindlin). Prints the stick/slip pattern and the two solvers' agreement.

use contact::{
    solve_newton, solve_uzawa, ContactPoints, DenseContactProblem, Law, NewtonParams, PointValues, Status, UzawaParams,
};

/// The compliance `D = (k_base I + k_spring L)⁻¹` of `n` points (L the 1D Laplacian with free
/// ends), the same for the normal and the tangential direction, uncoupled between them.
fn compliance(n: usize, k_base: f64, k_spring: f64) -> Vec<f64> {
    // stiffness, then its inverse by Gauss-Jordan (small n)
    let mut k = vec![0.0; n * n];
    for i in 0..n {
        k[i * n + i] += k_base;
        if i + 1 < n {
            k[i * n + i] += k_spring;
            k[(i + 1) * n + i + 1] += k_spring;
            k[i * n + i + 1] -= k_spring;
            k[(i + 1) * n + i] -= k_spring;
        }
    }
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        inv[i * n + i] = 1.0;
    }
    for c in 0..n {
        let p = k[c * n + c];
        for j in 0..n {
            k[c * n + j] /= p;
            inv[c * n + j] /= p;
        }
        for r in 0..n {
            if r != c {
                let f = k[r * n + c];
                for j in 0..n {
                    k[r * n + j] -= f * k[c * n + j];
                    inv[r * n + j] -= f * inv[c * n + j];
                }
            }
        }
    }
    inv
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(40);
    let friction: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0.6);
    let h = 1.0 / n as f64;
    let d = compliance(n, 1.0, 50.0);
    // the 2n x 2n compliance in the layout [normal; tangential], block-diagonal
    let m = 2 * n;
    let mut full = vec![0.0; m * m];
    for i in 0..n {
        for j in 0..n {
            full[i * m + j] = d[i * n + j] / h;
            full[(n + i) * m + n + j] = d[i * n + j] / h;
        }
    }
    // the base pushes a parabolic profile into the floor and drags everything by 0.02
    let x: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) * h).collect();
    let u0 = PointValues::from_parts(
        x.iter().map(|x| 0.05 - 0.4 * (x - 0.5).powi(2)).collect(),
        vec![0.02; n],
        1,
    )
    .expect("one tangential value per point");
    let points = ContactPoints {
        dim: 2,
        position: x.iter().map(|&x| [x, 0.0, 0.0]).collect(),
        normal: vec![[0.0, -1.0, 0.0]; n],
        tangent: vec![[[1.0, 0.0, 0.0], [0.0; 3]]; n],
        weight: vec![h; n],
        gap: vec![0.0; n],
        friction: vec![friction; n],
        held: vec![[false; 2]; n],
        foundation: Default::default(),
        foundations: vec![],
        slipped: vec![],
        weakening: vec![],
        tresca: vec![],
    };
    let mut problem = DenseContactProblem {
        u0,
        compliance: full,
        weight: vec![h; n],
        nt: 1,
    };
    let newton = solve_newton(
        &mut problem,
        &points,
        &Law::Coulomb,
        &NewtonParams::default(),
        None,
        &mut |_| {},
    )
    .expect("Newton converges on this problem");
    let uzawa = solve_uzawa(
        &mut problem,
        &points,
        &Law::Coulomb,
        &UzawaParams::default(),
        None,
        &mut |_| {},
    )
    .expect("Uzawa converges on this problem");
    let pattern: String = newton
        .status
        .iter()
        .map(|s| match s {
            Status::Stick => '|',
            Status::Slip => '~',
            Status::Separated => ' ',
        })
        .collect();
    println!("{n} points, F = {friction}: '|' stick, '~' slip, ' ' separated");
    println!("[{pattern}]");
    let diff = newton
        .lambda
        .normal
        .iter()
        .chain(&newton.lambda.tangential)
        .zip(uzawa.lambda.normal.iter().chain(&uzawa.lambda.tangential))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let scale = newton.lambda.normal.iter().cloned().fold(0.0, f64::max);
    println!(
        "Newton: {} steps; Uzawa: {} iterations in {} fixed-point steps; largest difference of the multipliers {:.2e} (relative to max λ_n = {:.3e})",
        newton.info.newton_iters,
        uzawa.info.uzawa_iters,
        uzawa.info.fixed_point_iters,
        diff / scale,
        scale
    );
}
