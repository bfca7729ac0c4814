//! The contact law at one point, solved exactly against a given local compliance: the step of
//! the block Gauss–Seidel method ([`crate::solve_gauss_seidel`]).
//!
//! With the point's multipliers `x` (normal first, then `nt ≤ 2` tangential components), its
//! displacement `u = b - A x` (`A` the point's block of `D W`, `b` the displacement the other
//! points' forces and the loads give it) and gap `g`, the natural-map equations are
//! `x_n - [z_n]₊ = 0`, `x_t - P_R(z_t) = 0` with `z = x + c (u - g e_n)`, `R` the law's radius
//! (Coulomb `F [z_n]₊`, Tresca `S`, frictionless 0) and `c = 1/‖A‖_F`. They are solved by a
//! semismooth Newton method on at most 3 unknowns (on the stack), with a monotone Armijo line
//! search, and, should it stall, the projected fixed point `x ← P(z(x))` with a shrinking `c`.
//! The answer is the iterate with the least equations' norm.

use crate::points::Foundation;
use crate::projection::{norm, project_disc};

/// The law at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum PointLaw {
    /// Signorini alone.
    Frictionless,
    /// Tresca with this slip bound.
    Tresca(f64),
    /// Coulomb with this coefficient.
    Coulomb(f64),
}

/// One point's problem: `u = b - A x`, gap `g`, `k = 1 + nt` components, the tangential
/// directions a support holds (their multiplier 0).
pub(crate) struct Point {
    pub(crate) a: [[f64; 3]; 3],
    pub(crate) b: [f64; 3],
    pub(crate) g: f64,
    pub(crate) k: usize,
    pub(crate) law: PointLaw,
    pub(crate) held: [bool; 2],
    /// The foundation, which gives the normal law.
    pub(crate) foundation: Foundation,
    /// `A⁻¹` where the caller keeps it (a sweep's blocks do not change): the sticking case's
    /// multipliers in nine products.
    pub(crate) inverse: Option<[[f64; 3]; 3]>,
}

/// Newton steps before the fixed point takes over.
const NEWTON_STEPS: usize = 40;
/// Fixed-point steps of the fallback.
const FIXED_POINT_STEPS: usize = 400;

impl Point {
    /// `z` and the equations `F` at `x`, with constant `c`.
    fn equations(&self, x: &[f64; 3], c: f64) -> ([f64; 3], [f64; 3]) {
        let k = self.k;
        let mut z = [0.0; 3];
        for r in 0..k {
            let u = self.b[r] - (0..k).map(|j| self.a[r][j] * x[j]).sum::<f64>();
            z[r] = x[r] + c * (u - if r == 0 { self.g } else { 0.0 });
        }
        let mut f = [0.0; 3];
        // the penetration u_n - g = (z_n - x_n) / c
        f[0] = self.foundation.normal_residual(x[0], (z[0] - x[0]) / c, c);
        let mut t = [z[1], z[2]];
        self.hold(&mut t);
        project_disc(&mut t[..k - 1], self.radius(self.normal(x, &z)));
        for r in 1..k {
            f[r] = x[r] - t[r - 1];
        }
        (z, f)
    }

    /// Sets the held tangential components to 0.
    fn hold(&self, t: &mut [f64; 2]) {
        for (v, &h) in t.iter_mut().zip(&self.held) {
            if h {
                *v = 0.0;
            }
        }
    }

    /// The normal value the radius is taken at ([`Foundation::radius_normal`]).
    fn normal(&self, x: &[f64; 3], z: &[f64; 3]) -> f64 {
        self.foundation.radius_normal(z[0], x[0])
    }

    fn radius(&self, zn: f64) -> f64 {
        match self.law {
            PointLaw::Frictionless => 0.0,
            PointLaw::Tresca(s) => s,
            PointLaw::Coulomb(mu) => crate::coulomb_radius(mu, zn),
        }
    }

    /// The Newton matrix at `z`: `J = ∂F/∂x` on the branch of `z`, with `M = I - c A` the
    /// derivative of `z`.
    fn jacobian(&self, x: &[f64; 3], z: &[f64; 3], c: f64) -> [[f64; 3]; 3] {
        let k = self.k;
        let mut m = [[0.0; 3]; 3];
        for r in 0..k {
            for j in 0..k {
                m[r][j] = if r == j { 1.0 } else { 0.0 } - c * self.a[r][j];
            }
        }
        let mut jac = [[0.0; 3]; 3];
        let compliance = self.foundation.equation(x[0], (z[0] - x[0]) / c, c);
        for j in 0..k {
            let e = if j == 0 { 1.0 } else { 0.0 };
            jac[0][j] = match compliance {
                None => e - if z[0] > 0.0 { m[0][j] } else { 0.0 },
                // (x_n - k [b_n - (A x)_n - g]₊^m) / s, the scale held
                Some((_, scale, slope)) => (e + slope * self.a[0][j]) / scale,
            };
        }
        let mut q = [z[1], z[2]];
        self.hold(&mut q);
        let qn = norm(&q[..k - 1]);
        let normal = self.normal(x, z);
        let radius = self.radius(normal);
        for r in 1..k {
            for j in 0..k {
                let identity = if r == j { 1.0 } else { 0.0 };
                jac[r][j] = if self.held[r - 1] || !(radius > 0.0) {
                    identity
                } else if qn <= radius {
                    identity - m[r][j]
                } else {
                    // slip: -(R/|q|)(I - q̂q̂ᵀ) M_t - q̂ dR, dR = F M_n for Coulomb in contact
                    let mut v = identity;
                    for l in (1..k).filter(|&l| !self.held[l - 1]) {
                        let proj = if r == l { 1.0 } else { 0.0 } - (q[r - 1] / qn) * (q[l - 1] / qn);
                        v -= radius / qn * proj * m[l][j];
                    }
                    if let PointLaw::Coulomb(mu) = self.law {
                        if normal > 0.0 {
                            // dR = F M_n (rigid: R = F [z_n]₊), F e_n (compliant: R = F x_n)
                            let dn = match compliance {
                                None => m[0][j],
                                Some(_) => {
                                    if j == 0 {
                                        1.0
                                    } else {
                                        0.0
                                    }
                                }
                            };
                            v -= q[r - 1] / qn * mu * dn;
                        }
                    }
                    v
                };
            }
        }
        jac
    }

    /// Solves the point's law from `x0`; returns the multipliers.
    pub(crate) fn solve(&self, x0: [f64; 3]) -> [f64; 3] {
        let size = self.size();
        if !(size > 0.0 && size.is_finite()) {
            return x0;
        }
        // on a rigid foundation the law's cases have closed forms (in 3D all but sliding)
        self.cases_2d()
            .or_else(|| self.cases_3d())
            .unwrap_or_else(|| self.iterate(x0))
    }

    /// `‖A‖_F`.
    fn size(&self) -> f64 {
        self.a.iter().flatten().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// The law solved by Newton's method from `x0`, then the projected fixed point should it
    /// stall.
    fn iterate(&self, x0: [f64; 3]) -> [f64; 3] {
        let k = self.k;
        let mut c = 1.0 / self.size();
        let two = |v: &[f64; 3]| norm(&v[..k]);
        // round-off of the multipliers: the rigid scale (c times the free motion), or a soft
        // bed's pressure at the free penetration where that is smaller
        let floor = |c: f64| {
            let rigid = (c * two(&self.b)).max(c * self.g.abs());
            self.foundation.multiplier_floor(rigid, self.b[0] - self.g)
        };
        let scale = |x: &[f64; 3], c: f64| two(x).max(floor(c));
        let done = |f: &[f64; 3], x: &[f64; 3], c: f64| two(f) <= 1e-14 * scale(x, c) || two(f) == 0.0;
        let mut x = x0;
        let (mut z, mut f) = self.equations(&x, c);
        let mut best = (two(&f), x);
        for _ in 0..NEWTON_STEPS {
            if done(&f, &x, c) {
                return x;
            }
            let Some(d) = solve_small(self.jacobian(&x, &z, c), f, k) else {
                break;
            };
            let current = two(&f);
            let mut alpha = 1.0;
            let mut moved = false;
            for _ in 0..30 {
                let mut trial = x;
                for r in 0..k {
                    trial[r] -= alpha * d[r];
                }
                let (tz, tf) = self.equations(&trial, c);
                if two(&tf) <= (1.0 - 1e-4 * alpha) * current {
                    (x, z, f) = (trial, tz, tf);
                    moved = true;
                    break;
                }
                alpha *= 0.5;
            }
            if two(&f) < best.0 {
                best = (two(&f), x);
            }
            if !moved {
                break;
            }
        }
        // the projected fixed point x ← P(z(x)), its constant halved whenever the norm rises
        x = best.1;
        let mut previous = f64::INFINITY;
        for _ in 0..FIXED_POINT_STEPS {
            (_, f) = self.equations(&x, c);
            let now = two(&f);
            if now < best.0 {
                best = (now, x);
            }
            if done(&f, &x, c) {
                return x;
            }
            if now >= previous {
                c *= 0.5;
            }
            previous = now;
            for r in 0..k {
                x[r] -= f[r];
            }
        }
        best.1
    }

    /// A 3D point under Coulomb's law on a rigid foundation with no held direction: the cases
    /// that have closed forms, separated (`x = 0` where `e_n ≤ 0`) and in contact and sticking
    /// (`A x = e` with `x_n ≥ 0`, `|x_t| ≤ F x_n`), in the notation of [`Point::cases_2d`];
    /// `None` where neither holds (the point slides: Newton finds its direction).
    fn cases_3d(&self) -> Option<[f64; 3]> {
        let PointLaw::Coulomb(mu) = self.law else {
            return None;
        };
        if self.k != 3 || self.foundation != Foundation::Rigid || self.held != [false; 2] {
            return None;
        }
        let e = [self.b[0] - self.g, self.b[1], self.b[2]];
        if e[0] <= 0.0 {
            return Some([0.0; 3]);
        }
        let x = match &self.inverse {
            Some(inv) => inv.map(|row| row[0] * e[0] + row[1] * e[1] + row[2] * e[2]),
            None => solve_small(self.a, e, 3)?,
        };
        (x[0] >= 0.0 && norm(&x[1..]) <= mu * x[0]).then_some(x)
    }

    /// A 2D point on a rigid foundation with no held direction: the law's cases in closed
    /// form, `e = b - g e_n` the free penetration and `v = e - A x` the penetration at `x`
    /// (`v_n ≤ 0`, `x_n ≥ 0`, `x_n v_n = 0`; `x_t = P_R(x_t + c v_t)`). Separated (`x = 0`,
    /// `e_n ≤ 0`; for Tresca the tangent's own cases at `x_n = 0`), in contact and sticking
    /// (`A x = e`, `|x_t| ≤ R`), in contact and sliding either way (`x_t = ±R`, `±v_t ≥ 0`:
    /// Coulomb's `x_n = e_n / (A_nn ± F A_nt)`, Tresca's `x_n = (e_n ∓ A_nt S) / A_nn`). Returns
    /// the first case whose conditions hold, or `None` where none does (a case on the edge
    /// between two, lost to round-off) or the point is not of this kind.
    fn cases_2d(&self) -> Option<[f64; 3]> {
        if self.k != 2 || self.foundation != Foundation::Rigid || self.held[0] {
            return None;
        }
        let a = &self.a;
        let e = [self.b[0] - self.g, self.b[1]];
        let v = |xn: f64, xt: f64| [e[0] - a[0][0] * xn - a[0][1] * xt, e[1] - a[1][0] * xn - a[1][1] * xt];
        let finite = |xn: f64, xt: f64| xn.is_finite() && xt.is_finite();
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let stick = [
            (e[0] * a[1][1] - a[0][1] * e[1]) / det,
            (a[0][0] * e[1] - a[1][0] * e[0]) / det,
        ];
        let sticks = |radius: f64| finite(stick[0], stick[1]) && stick[0] >= 0.0 && stick[1].abs() <= radius;
        match self.law {
            // frictionless points have no tangent (k = 1): never here
            PointLaw::Frictionless => None,
            PointLaw::Coulomb(mu) => {
                if e[0] <= 0.0 {
                    return Some([0.0; 3]);
                }
                if sticks(mu * stick[0]) {
                    return Some([stick[0], stick[1], 0.0]);
                }
                [1.0, -1.0].into_iter().find_map(|s| {
                    let xn = e[0] / (a[0][0] + s * mu * a[0][1]);
                    let xt = s * mu * xn;
                    (finite(xn, xt) && xn >= 0.0 && s * v(xn, xt)[1] >= 0.0).then_some([xn, xt, 0.0])
                })
            }
            PointLaw::Tresca(bound) => {
                if sticks(bound) {
                    return Some([stick[0], stick[1], 0.0]);
                }
                // separated: the tangent alone, sticking or sliding
                let xt = e[1] / a[1][1];
                if finite(0.0, xt) && xt.abs() <= bound && v(0.0, xt)[0] <= 0.0 {
                    return Some([0.0, xt, 0.0]);
                }
                [1.0, -1.0].into_iter().find_map(|s| {
                    let xt = s * bound;
                    if v(0.0, xt)[0] <= 0.0 && s * v(0.0, xt)[1] >= 0.0 {
                        return Some([0.0, xt, 0.0]);
                    }
                    let xn = (e[0] - s * a[0][1] * bound) / a[0][0];
                    (finite(xn, xt) && xn >= 0.0 && s * v(xn, xt)[1] >= 0.0).then_some([xn, xt, 0.0])
                })
            }
        }
    }
}

/// The inverse of the leading `k x k` block of `a`, `None` where it is singular.
pub(crate) fn inverse(a: [[f64; 3]; 3], k: usize) -> Option<[[f64; 3]; 3]> {
    let mut inv = [[0.0; 3]; 3];
    for col in 0..k {
        let mut unit = [0.0; 3];
        unit[col] = 1.0;
        let x = solve_small(a, unit, k)?;
        for r in 0..k {
            inv[r][col] = x[r];
        }
    }
    Some(inv)
}

/// `J d = f` for `k ≤ 3` by Gaussian elimination with partial pivoting; `None` if singular.
fn solve_small(mut a: [[f64; 3]; 3], mut f: [f64; 3], k: usize) -> Option<[f64; 3]> {
    for col in 0..k {
        let pivot = (col..k).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if !(a[pivot][col].abs() > 1e-300) {
            return None;
        }
        a.swap(col, pivot);
        f.swap(col, pivot);
        for r in col + 1..k {
            let l = a[r][col] / a[col][col];
            for j in col..k {
                a[r][j] -= l * a[col][j];
            }
            f[r] -= l * f[col];
        }
    }
    let mut d = [0.0; 3];
    for r in (0..k).rev() {
        let s: f64 = (r + 1..k).map(|j| a[r][j] * d[j]).sum();
        d[r] = (f[r] - s) / a[r][r];
    }
    d.iter().all(|v| v.is_finite()).then_some(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hand solution of the one-contact problem of the Siconos tests (`A = diag(2, 1, 1)`,
    /// pressed by `b_n = 1`, pulled by `b_t = -0.5`, `F = 0.3`): the point closes with
    /// `x_n = 1/2` and slides with `|x_t| = 0.15` along `u_t`.
    #[test]
    fn one_sliding_contact() {
        let p = Point {
            a: [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            b: [1.0, -0.5, 0.0],
            g: 0.0,
            k: 3,
            law: PointLaw::Coulomb(0.3),
            held: [false; 2],
            foundation: Foundation::Rigid,
            inverse: None,
        };
        let x = p.solve([0.0; 3]);
        assert!(
            (x[0] - 0.5).abs() < 1e-14 && (x[1] + 0.15).abs() < 1e-14 && x[2].abs() < 1e-14,
            "{x:?}"
        );
        // sticking with a large coefficient: u = 0, x = A⁻¹ b
        let stick = Point {
            law: PointLaw::Coulomb(10.0),
            ..p
        };
        let x = stick.solve([0.0; 3]);
        assert!((x[0] - 0.5).abs() < 1e-14 && (x[1] + 0.5).abs() < 1e-14, "{x:?}");
        // pulled away: separated
        let away = Point {
            b: [-1.0, 0.3, 0.2],
            ..stick
        };
        assert_eq!(away.solve([1.0, 1.0, 1.0]), [0.0; 3]);
    }

    /// A point on a linear spring bed (`m = 1`, `k = 4`), `A = diag(2, 1)`, pressed by
    /// `b_n = 1`, pulled by `b_t = -0.5`, `F = 0.3`: `x_n = k (b_n - 2 x_n)` gives
    /// `x_n = k b_n / (1 + 2 k) = 4/9`; the slip bound `F x_n = 2/15` is below the stick force
    /// `|b_t| = 1/2`, so the point slides with `|x_t| = 2/15`. With `m = 2` (`k = 4`),
    /// `x_n = 4 (1 - 2 x_n)²`, the root below 1/2: `x_n = (17 - √33)/32`.
    #[test]
    fn a_point_on_a_compliant_bed() {
        let at = |exponent: f64| {
            Point {
                a: [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]],
                b: [1.0, -0.5, 0.0],
                g: 0.0,
                k: 2,
                law: PointLaw::Coulomb(0.3),
                held: [false; 2],
                foundation: Foundation::Compliant {
                    stiffness: 4.0,
                    exponent,
                },
                inverse: None,
            }
            .solve([0.0; 3])
        };
        let x = at(1.0);
        assert!((x[0] - 4.0 / 9.0).abs() < 1e-14, "{x:?}");
        assert!((x[1] + 0.3 * 4.0 / 9.0).abs() < 1e-14, "{x:?}");
        let x = at(2.0);
        let xn = (17.0 - 33f64.sqrt()) / 32.0;
        assert!((x[0] - xn).abs() < 1e-14, "{x:?} {xn}");
        assert!((x[1] + 0.3 * xn).abs() < 1e-14, "{x:?}");
    }

    proptest::proptest! {
        /// The closed forms of the 2D cases (Coulomb, Tresca) and of the 3D separated and
        /// sticking cases against Newton's iteration on the same point: both meet the natural
        /// map's equations, and where the law has one solution (the block symmetric positive
        /// definite and `F` small enough: Hild's condition for one point) they agree.
        #[test]
        fn closed_forms_meet_the_law(
            k in 2usize..=3,
            entries in proptest::collection::vec(-1.0f64..1.0, 9),
            b in proptest::collection::vec(-2.0f64..2.0, 3),
            gap in -0.5f64..0.5,
            friction in 0.0f64..0.8,
            tresca in proptest::bool::ANY,
        ) {
            // A = G Gᵀ + I/2 on the leading k x k block: symmetric positive definite
            let mut a = [[0.0; 3]; 3];
            for r in 0..k {
                for c in 0..k {
                    a[r][c] = (0..k).map(|l| entries[3 * r + l] * entries[3 * c + l]).sum::<f64>()
                        + if r == c { 0.5 } else { 0.0 };
                }
            }
            let law = if tresca && k == 2 { PointLaw::Tresca(friction) } else { PointLaw::Coulomb(friction) };
            let point = Point {
                a,
                b: [b[0], b[1], if k == 3 { b[2] } else { 0.0 }],
                g: gap,
                k,
                law,
                held: [false; 2],
                foundation: Foundation::Rigid,
                inverse: if k == 3 { inverse(a, 3) } else { None },
            };
            let scale = 1.0 + point.b.iter().map(|v| v.abs()).sum::<f64>();
            let c = 1.0 / point.size();
            let Some(closed) = point.cases_2d().or_else(|| point.cases_3d()) else {
                // only a 3D slide has no closed form
                proptest::prop_assert!(k == 3);
                return Ok(());
            };
            let (_, f) = point.equations(&closed, c);
            proptest::prop_assert!(norm(&f[..k]) <= 1e-12 * scale, "{closed:?}: {f:?}");
            let iterated = point.iterate([0.0; 3]);
            for r in 0..k {
                proptest::prop_assert!((closed[r] - iterated[r]).abs() <= 1e-9 * scale, "{closed:?} vs {iterated:?}");
            }
        }
    }
}
