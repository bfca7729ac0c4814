//! Analytical solutions of contact problems (plane strain, a rigid flat foundation), from
//! Johnson, *Contact Mechanics* (Cambridge, 1985): Hertz's frictionless cylinder (section 4.2)
//! and Cattaneo-Mindlin's partial slip under a tangential force (section 7.1).

use std::f64::consts::PI;

/// Hertz's half-width `a` and peak pressure `p0` for the load `p` per unit length on a cylinder
/// of radius `radius` (Johnson 1985, section 4.2): `a² = 4 P R / (π E*)`, `p0 = 2 P / (π a)`,
/// with `E* = E / (1 - ν²)` against a rigid foundation.
pub fn hertz(p: f64, radius: f64, young: f64, poisson: f64) -> (f64, f64) {
    let e_star = young / (1.0 - poisson * poisson);
    let a = (4.0 * p * radius / (PI * e_star)).sqrt();
    (a, 2.0 * p / (PI * a))
}

/// Hertz's contact radius `a` for the load `p` on a sphere of radius `radius` against a rigid
/// flat (Johnson 1985, eq. (4.22)): `a³ = 3 P R / (4 E*)`, `E* = E / (1 - ν²)`.
pub fn hertz_sphere(p: f64, radius: f64, young: f64, poisson: f64) -> f64 {
    let e_star = young / (1.0 - poisson * poisson);
    (3.0 * p * radius / (4.0 * e_star)).cbrt()
}

/// The energy friction dissipates in one cycle of the tangential load between `±q_star` on a
/// sphere of contact radius `a` under the normal load `p` against a rigid flat, coefficient `f`
/// (Mindlin and Deresiewicz 1953; Johnson 1985, section 7.2). The loading curve is Johnson's
/// eq. (7.42), `δ(Q) = (3 F P / (16 a)) ((2 - ν)/G) [1 - (1 - Q/(F P))^(2/3)]`; unloading and
/// reloading follow it at twice the scale from each turn (Masing's rule), so the loop's area is
/// `4 Q* δ(Q*) - 8 ∫₀^Q* δ`:
/// `W = (9 F² P² (2 - ν) / (10 a G)) [1 - (1 - x)^(5/3) - (5x/6)(1 + (1 - x)^(2/3))]`,
/// `x = Q*/(F P) ≤ 1`, `G = E / (2 (1 + ν))`.
pub fn mindlin_deresiewicz_dissipation(p: f64, q_star: f64, f: f64, a: f64, young: f64, poisson: f64) -> f64 {
    let g = young / (2.0 * (1.0 + poisson));
    let x = (q_star / (f * p)).min(1.0);
    let y = 1.0 - x;
    9.0 * f * f * p * p * (2.0 - poisson) / (10.0 * a * g)
        * (1.0 - y.powf(5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + y.powf(2.0 / 3.0)))
}

/// Hertz's pressure at `x` from the centre: `p0 √(1 - x²/a²)` inside the contact, 0 outside.
pub fn hertz_pressure(x: f64, a: f64, p0: f64) -> f64 {
    p0 * (1.0 - x * x / (a * a)).max(0.0).sqrt()
}

/// The stick half-width of Cattaneo-Mindlin, `c = a √(1 - Q/(F P))` (0 once `Q ≥ F P`).
pub fn cattaneo_stick_half_width(a: f64, q: f64, f: f64, p: f64) -> f64 {
    a * (1.0 - (q / (f * p)).min(1.0)).sqrt()
}

/// Cattaneo-Mindlin's tangential traction (Johnson 1985, section 7.1) for the friction
/// coefficient `f`, Hertz's `a` and `p0`, and the stick half-width `c`:
/// `q = F p0 √(1 - x²/a²) - F p0 (c/a) √(1 - x²/c²)` (the second term for `|x| < c` only).
pub fn cattaneo_traction(x: f64, f: f64, a: f64, p0: f64, c: f64) -> f64 {
    let slip = f * p0 * (1.0 - x * x / (a * a)).max(0.0).sqrt();
    let stick = if x.abs() < c {
        f * p0 * (c / a) * (1.0 - x * x / (c * c)).sqrt()
    } else {
        0.0
    };
    slip - stick
}

/// Cattaneo-Mindlin's traction under the tangential load `q` (`|q| ≤ F p`), signed as `q`.
pub fn cattaneo_at(x: f64, f: f64, (a, p0, p): (f64, f64, f64), q: f64) -> f64 {
    let c = cattaneo_stick_half_width(a, q.abs(), f, p);
    q.signum() * cattaneo_traction(x, f, a, p0, c)
}

/// Mindlin and Deresiewicz's traction along a cycle of the tangential load under a constant
/// normal one (Johnson 1985, section 7.2; Mindlin & Deresiewicz, J. Appl. Mech. 20 (1953)
/// 327): `reversals` are the loads where the direction turned (`[]` on the first loading,
/// `[Q₁]` after the first turn, `[Q₁, Q₂]` after the second), `q` the load now. Each turn
/// adds twice a Cattaneo distribution of half the change since it (Masing's rule):
/// `q(x) = cat(Q₁) - 2 cat((Q₁ - Q)/2)` unloading from `Q₁`, and from a second turn at `Q₂`,
/// `q₁(x; Q₂) + 2 cat((Q - Q₂)/2)`; its stick zone the half-width of the last term.
pub fn mindlin_deresiewicz_traction(x: f64, f: f64, hertz: (f64, f64, f64), reversals: &[f64], q: f64) -> f64 {
    match reversals {
        [] => cattaneo_at(x, f, hertz, q),
        [.., last] => {
            let before = mindlin_deresiewicz_traction(x, f, hertz, &reversals[..reversals.len() - 1], *last);
            before + 2.0 * cattaneo_at(x, f, hertz, (q - last) / 2.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Johnson's numbers: P = 1, R = 1, E* = 1 gives a = 2/√π and p0 = 1/√π; the
    /// Cattaneo traction integrates to Q.
    #[test]
    fn hertz_and_cattaneo_formulas() {
        let (a, p0) = hertz(1.0, 1.0, 1.0, 0.0);
        assert!((a - 2.0 / PI.sqrt()).abs() < 1e-14);
        assert!((p0 - 1.0 / PI.sqrt()).abs() < 1e-14);
        // ∫ q dx = F P - F P (c/a)² = Q by construction of c
        let (f, q): (f64, f64) = (0.5, 0.3);
        let c = cattaneo_stick_half_width(a, q, f, 1.0);
        assert!((c - a * (1.0 - q / f).sqrt()).abs() < 1e-15);
        let n = 200_000;
        let h = 2.0 * a / n as f64;
        let integral: f64 = (0..n)
            .map(|i| cattaneo_traction(-a + (i as f64 + 0.5) * h, f, a, p0, c) * h)
            .sum();
        assert!((integral - q).abs() < 1e-5, "{integral}");
        // and Hertz's pressure integrates to P
        let pressure: f64 = (0..n)
            .map(|i| hertz_pressure(-a + (i as f64 + 0.5) * h, a, p0) * h)
            .sum();
        assert!((pressure - 1.0).abs() < 1e-5, "{pressure}");
        // Mindlin-Deresiewicz: continuous at each turn, the full reversal to -Q* is -q*, and
        // the unloading traction integrates to the load now
        let hz = (a, p0, 1.0);
        let q_star = 0.4;
        for x in [-0.9 * a, -0.3 * a, 0.0, 0.5 * a] {
            let q1 = mindlin_deresiewicz_traction(x, f, hz, &[], q_star);
            assert!((mindlin_deresiewicz_traction(x, f, hz, &[q_star], q_star) - q1).abs() < 1e-15);
            assert!((mindlin_deresiewicz_traction(x, f, hz, &[q_star], -q_star) + q1).abs() < 1e-14);
            let q2 = mindlin_deresiewicz_traction(x, f, hz, &[q_star], -0.1);
            assert!((mindlin_deresiewicz_traction(x, f, hz, &[q_star, -0.1], -0.1) - q2).abs() < 1e-15);
        }
        let down: f64 = (0..n)
            .map(|i| mindlin_deresiewicz_traction(-a + (i as f64 + 0.5) * h, f, hz, &[q_star], 0.1) * h)
            .sum();
        assert!((down - 0.1).abs() < 1e-5, "{down}");
        // the sphere's loop: its area by quadrature of Masing's branches of Johnson's (7.42)
        let (p, fr, a3, e, nu) = (2.0, 0.4, 0.5, 100.0, 0.3);
        let g = e / (2.0 * (1.0 + nu));
        let delta = |q: f64| 3.0 * fr * p / (16.0 * a3) * (2.0 - nu) / g * (1.0 - (1.0 - q / (fr * p)).powf(2.0 / 3.0));
        let q_star = 0.6;
        let m = 20_000;
        let hq = 2.0 * q_star / m as f64;
        let area: f64 = (0..m)
            .map(|i| {
                let q = -q_star + (i as f64 + 0.5) * hq;
                // the unloading branch's displacement less the reloading one's
                let down = delta(q_star) - 2.0 * delta((q_star - q) / 2.0);
                let up = -delta(q_star) + 2.0 * delta((q + q_star) / 2.0);
                (down - up) * hq
            })
            .sum();
        let w = mindlin_deresiewicz_dissipation(p, q_star, fr, a3, e, nu);
        assert!((area - w).abs() < 1e-6 * w, "{area} {w}");
    }
}
