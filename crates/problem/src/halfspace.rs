//! Closed forms for a rigid axisymmetric indenter pressed, without friction, into a
//! transversely isotropic piezoelectric half-space poled along its inward normal: the force,
//! the contact radius, the induced surface potential (an insulating tip) or charge (a
//! conducting tip at a given potential) at a given depth, for any convex profile.
//!
//! Two steps, each from a source written elsewhere (docs/theory.md, "Indentation of a
//! piezoelectric half-space"):
//!
//! 1. **The surface Green's matrix** `G` from the crystal constants: a point force `P` (into
//!    the body) and a point charge `Q` at the surface give the surface deflection and
//!    potential `[w; φ](r) = G [P; Q] / (2π r)`. For a body whose symmetry axis is the
//!    normal, the axisymmetric problem has the characteristic roots of the plane problem
//!    (Hankel in place of Fourier), so `G` is the normal/electric block of the inverse of
//!    Barnett and Lothe's surface-impedance tensor `L` of the extended (u, φ) Stroh
//!    formalism (Barnett & Lothe 1975; Lothe & Barnett 1976 for piezoelectrics; Ting,
//!    *Anisotropic Elasticity*, 1996, chapters 7 and 8), computed by its integral
//!    formalism `L = -(1/π) ∫₀^π N₃(ω) dω`: no eigenvectors, so degenerate (isotropic)
//!    limits are as accurate as any other. For an isotropic solid `G₁₁ = 2(1 - ν²)/E`
//!    (Boussinesq), for a dielectric `G₂₂ = 1/√(ε₁₁ε₃₃)`.
//! 2. **The correspondence principle** (Karapetian, Kachanov & Kalinin 2005, 2009): with
//!    `[p̃; q̃] = G [p; q]` the coupled problem splits into two scalar Boussinesq problems
//!    of unit compliance (`E* = 2`) on the same contact disc, each solved by Sneddon's
//!    axisymmetric punch integrals (Sneddon 1965): for a profile `f(ρ)` pushed in by `d`,
//!    `g(x) = x ∫₀^{π/2} f'(x sin s) ds`, the load `P = 2E* ∫₀^a (d - g(x)) dx` and the
//!    edge singularity `∝ d - g(a)`. A smooth profile's pressure must not be singular at
//!    `ρ = a`; a conductor's surface charge may be.

use fe_assembly::Crystal;
use nalgebra::{Matrix2, Matrix4};
use std::f64::consts::PI;

/// Why the half-space's constants cannot be formed.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum HalfSpaceError {
    /// `T(ω)` (the (u, φ) stiffness along one direction) is singular: no admissible material.
    #[error("the material's stiffness along the direction at {angle_deg:.1} degrees is singular")]
    Singular {
        /// The direction, degrees from the surface.
        angle_deg: f64,
    },
    /// The Green's matrix is not that of a solid (`G₁₁ ≤ 0`) or has a non-finite entry.
    #[error("the half-space's surface compliance G11 = {g11:e} is not positive and finite")]
    NotPositive {
        /// `G₁₁`.
        g11: f64,
    },
}

/// The surface Green's matrix of a half-space: `[w; φ](r) = G [P; Q] / (2π r)` with `w` the
/// deflection into the body under the force `P` pushing in and `φ` the potential under the
/// charge `Q` put on the surface. Without electric unknowns only `G₁₁` is used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSpace {
    /// `G` (row 0: deflection, row 1: potential; column 0: force, column 1: charge).
    pub g: [[f64; 2]; 2],
    /// Whether the solid has electric unknowns (a permittivity).
    pub electric: bool,
}

/// The electric condition of the indenter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tip {
    /// An insulator: no charge on the contact disc (the surface potential follows the
    /// deflection there, `φ = (G₂₁/G₁₁) w`).
    Insulating,
    /// A conductor at the potential `ψ` (against the body's far field): `φ = ψ` on the disc.
    Conducting {
        /// Its potential.
        potential: f64,
    },
    /// A floating conductor carrying the charge `Q` on the contact disc (0: an open
    /// circuit): equipotential there, its potential found.
    Floating {
        /// The charge (as [`Indentation::charge`]).
        charge: f64,
    },
}

/// An axisymmetric profile `f(ρ)` above its tip.
#[derive(Clone, Debug, PartialEq)]
pub enum Profile {
    /// `f = ρ²/(2R)`.
    Paraboloid {
        /// The tip radius `R`.
        radius: f64,
    },
    /// `f = R - √(R² - ρ²)`.
    Sphere {
        /// Its radius `R`.
        radius: f64,
    },
    /// `f = ρ / tan θ`.
    Cone {
        /// The semi-vertical angle θ, degrees.
        half_angle: f64,
    },
    /// A flat-ended cylinder of radius `a`: the contact radius is `a` whatever the depth.
    Punch {
        /// Its radius.
        radius: f64,
    },
    /// `f` tabulated as `[[ρ, f], ...]` (ρ increasing from 0, linear between).
    Tabulated(Vec<[f64; 2]>),
}

/// The closed form at one depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Indentation {
    /// The depth `d`.
    pub depth: f64,
    /// The force `P`.
    pub force: f64,
    /// The contact radius `a`.
    pub contact_radius: f64,
    /// The potential at the tip: the indenter's own (conducting) or the surface's under the
    /// tip `(G₂₁/G₁₁) d` (insulating); `None` without electric unknowns.
    pub potential: Option<f64>,
    /// The charge the body's surface carries on the disc (`∫ q dA`, `q = -D·ν` with `ν` out
    /// of the body: the flux into it): `Some(0)` insulating, `None` without electric unknowns.
    pub charge: Option<f64>,
}

impl Profile {
    /// `f'(ρ)`; `None` beyond the profile's reach.
    fn slope(&self, rho: f64) -> Option<f64> {
        match self {
            Profile::Paraboloid { radius } => Some(rho / radius),
            // `√(R² - ρ²)` as `√(R - ρ) √(R + ρ)`: no overflow of R²
            Profile::Sphere { radius } => {
                (rho < *radius).then(|| rho / ((radius - rho).sqrt() * (radius + rho).sqrt()))
            }
            Profile::Cone { half_angle } => Some(1.0 / half_angle.to_radians().tan()),
            Profile::Punch { .. } => Some(0.0),
            Profile::Tabulated(t) => {
                let k = t.windows(2).position(|w| rho <= w[1][0])?;
                Some((t[k + 1][1] - t[k][1]) / (t[k + 1][0] - t[k][0]))
            }
        }
    }

    /// The largest radius the profile reaches.
    fn reach(&self) -> f64 {
        match self {
            Profile::Sphere { radius } | Profile::Punch { radius } => *radius,
            Profile::Tabulated(t) => t.last().map_or(0.0, |p| p[0]),
            _ => f64::INFINITY,
        }
    }

    /// Sneddon's `g(x) = x ∫₀^{π/2} f'(x sin s) ds` (the depth at which a flat-data punch
    /// of radius `x` would have no edge singularity): composite 3-point Gauss-Legendre.
    fn sneddon_g(&self, x: f64) -> f64 {
        match self {
            Profile::Paraboloid { radius } => x * x / radius,
            Profile::Cone { half_angle } => PI / 2.0 * x / half_angle.to_radians().tan(),
            Profile::Punch { .. } => 0.0,
            Profile::Sphere { .. } | Profile::Tabulated(_) => {
                x * gauss(0.0, PI / 2.0, 400, |s| self.slope(x * s.sin()).unwrap_or(f64::INFINITY))
            }
        }
    }
}

/// `∫ₐᵇ f` by 3-point Gauss-Legendre on `panels` equal panels.
fn gauss(a: f64, b: f64, panels: usize, f: impl Fn(f64) -> f64) -> f64 {
    let (x, w) = ((0.6f64).sqrt(), [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]);
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let m = a + (k as f64 + 0.5) * h;
        for (t, wt) in [-x, 0.0, x].iter().zip(w) {
            sum += wt * f(m + t * h / 2.0);
        }
    }
    sum * h / 2.0
}

/// The generalised (u, φ) stiffness `E_iJKl` of `crystal` in a frame whose axis 2 (0-based
/// index 1) is the crystal's 3-axis (the half-space's inward normal) and axis 1 its 1-axis:
/// `E_ijkl = c_ijkl`, `E_ij4l = e_lij`, `E_i4kl = e_ikl`, `E_i44l = -ε_il`.
fn generalised(crystal: &Crystal) -> [[[[f64; 3]; 4]; 4]; 3] {
    // frame index -> crystal index: 0 -> 0, 1 -> 2 (the normal), 2 -> 1
    let p = [0usize, 2, 1];
    let voigt = |i: usize, j: usize| match (i.min(j), i.max(j)) {
        (0, 0) => 0,
        (1, 1) => 1,
        (2, 2) => 2,
        (1, 2) => 3,
        (0, 2) => 4,
        _ => 5,
    };
    let c = |i, j, k, l| crystal.c[voigt(p[i], p[j])][voigt(p[k], p[l])];
    let e = |k: usize, i: usize, j: usize| crystal.e[p[k]][voigt(p[i], p[j])];
    let eps = |i: usize, l: usize| crystal.permittivity[p[i]][p[l]];
    let mut out = [[[[0.0; 3]; 4]; 4]; 3];
    for i in 0..3 {
        for l in 0..3 {
            for jj in 0..4 {
                for kk in 0..4 {
                    out[i][jj][kk][l] = match (jj, kk) {
                        (3, 3) => -eps(i, l),
                        (j, 3) => e(l, i, j),
                        (3, k) => e(i, k, l),
                        (j, k) => c(i, j, k, l),
                    };
                }
            }
        }
    }
    out
}

impl HalfSpace {
    /// The half-space of `crystal` (poled along its 3-axis, the inward normal; a crystal
    /// with zero permittivity is taken as elastic). The integral `L = -(1/π) ∫₀^π N₃ dω` by
    /// the trapezoidal rule on 512 points (the integrand is smooth and π-periodic, so the rule
    /// converges geometrically: 256 and 512 points agree to round-off).
    ///
    /// # Errors
    /// [`HalfSpaceError`] where the stiffness along a direction is singular or the surface
    /// compliance is not that of a solid.
    pub fn from_crystal(crystal: &Crystal) -> Result<Self, HalfSpaceError> {
        let electric = (0..3).any(|i| crystal.permittivity[i][i] != 0.0);
        let big = generalised(crystal);
        let nk = if electric { 4 } else { 3 };
        let samples = 512;
        let mut l = Matrix4::<f64>::zeros();
        for s in 0..samples {
            let w = PI * s as f64 / samples as f64;
            let n = [w.cos(), w.sin(), 0.0];
            let m = [-w.sin(), w.cos(), 0.0];
            let contract = |a: &[f64; 3], b: &[f64; 3]| {
                let mut out = Matrix4::<f64>::zeros();
                for jj in 0..nk {
                    for kk in 0..nk {
                        let mut v = 0.0;
                        for i in 0..3 {
                            for ll in 0..3 {
                                v += a[i] * big[i][jj][kk][ll] * b[ll];
                            }
                        }
                        out[(jj, kk)] = v;
                    }
                }
                if !electric {
                    out[(3, 3)] = 1.0; // a placeholder row: decoupled, never read
                }
                out
            };
            let (q, r, t) = (contract(&n, &n), contract(&n, &m), contract(&m, &m));
            let t_inv = t.try_inverse().ok_or(HalfSpaceError::Singular {
                angle_deg: w.to_degrees(),
            })?;
            let n3 = r * t_inv * r.transpose() - q;
            l -= n3 / samples as f64; // -(1/π) ∫ N₃ dω with dω = π / samples
        }
        if !electric {
            l[(3, 3)] = 1.0;
        }
        let li = l.try_inverse().ok_or(HalfSpaceError::NotPositive { g11: f64::NAN })?;
        // a point force P into the body (the generalised force (0, P, 0, -Q): the charge Q
        // enters the electric equation div D = q with the opposite sign of a force)
        let g = [[li[(1, 1)], -li[(1, 3)]], [li[(3, 1)], -li[(3, 3)]]];
        let g = if electric { g } else { [[g[0][0], 0.0], [0.0, 0.0]] };
        if !(g[0][0] > 0.0 && g.iter().flatten().all(|v| v.is_finite())) {
            return Err(HalfSpaceError::NotPositive { g11: g[0][0] });
        }
        Ok(HalfSpace { g, electric })
    }

    /// An isotropic elastic half-space: `G₁₁ = 2(1 - ν²)/E` (Boussinesq), no electric unknowns.
    pub fn isotropic(young: f64, poisson: f64) -> Self {
        HalfSpace {
            g: [[2.0 * (1.0 - poisson * poisson) / young, 0.0], [0.0, 0.0]],
            electric: false,
        }
    }

    /// The same half-space poled away from the body (the coupling's sign reversed).
    pub fn reversed(self) -> Self {
        let g = self.g;
        HalfSpace {
            g: [[g[0][0], -g[0][1]], [-g[1][0], g[1][1]]],
            ..self
        }
    }

    /// The indentation modulus of an insulating tip, `E* = 2/G₁₁` (Hertz's `E/(1 - ν²)`).
    pub fn insulating_modulus(&self) -> f64 {
        2.0 / self.g[0][0]
    }

    /// The indentation modulus of a conducting tip, `E* = 2 K₁₁` with `K = G⁻¹` (equal to
    /// the insulating one without electric unknowns).
    pub fn conducting_modulus(&self) -> f64 {
        if self.electric {
            2.0 * self.k()[(0, 0)]
        } else {
            self.insulating_modulus()
        }
    }

    fn k(&self) -> Matrix2<f64> {
        let g = Matrix2::new(self.g[0][0], self.g[0][1], self.g[1][0], self.g[1][1]);
        g.try_inverse().unwrap_or_else(Matrix2::zeros)
    }

    /// The closed form for `profile` pushed in by `depth ≥ 0` with the electric condition
    /// `tip` (taken as insulating without electric unknowns).
    pub fn at_depth(&self, profile: &Profile, depth: f64, tip: Tip) -> Indentation {
        let tip = if self.electric { tip } else { Tip::Insulating };
        if let Tip::Floating { charge } = tip {
            let potential = self.floating_potential(profile, depth, charge);
            let mut out = self.at_depth(profile, depth, Tip::Conducting { potential });
            out.charge = Some(charge);
            return out;
        }
        let k = self.k();
        // the depth the scalar problem of the pressure sees: an edge without singularity
        // where g(a) = d + (K₁₂/K₁₁) ψ (conducting), g(a) = d (insulating)
        let (d_edge, psi) = match tip {
            Tip::Conducting { potential } => (depth + k[(0, 1)] / k[(0, 0)] * potential, potential),
            _ => (depth, 0.0),
        };
        let a = match profile {
            Profile::Punch { radius } => *radius,
            _ => contact_radius(profile, d_edge),
        };
        // I = ∫₀^a (d - g(x)) dx: the unit-compliance problem's load is 4 I
        let integral = match profile {
            Profile::Paraboloid { radius } => a * depth - a.powi(3) / (3.0 * radius),
            Profile::Cone { half_angle } => a * depth - PI / 4.0 * a * a / half_angle.to_radians().tan(),
            Profile::Punch { .. } => a * depth,
            _ => a * depth - gauss(0.0, a, 200, |x| profile.sneddon_g(x)),
        };
        match tip {
            Tip::Insulating => Indentation {
                depth,
                force: 4.0 * integral / self.g[0][0],
                contact_radius: a,
                potential: self.electric.then(|| self.g[1][0] / self.g[0][0] * depth),
                charge: self.electric.then_some(0.0),
            },
            Tip::Conducting { .. } | Tip::Floating { .. } => Indentation {
                depth,
                force: 4.0 * (k[(0, 0)] * integral + k[(0, 1)] * a * psi),
                contact_radius: a,
                potential: Some(psi),
                charge: Some(4.0 * (k[(1, 0)] * integral + k[(1, 1)] * a * psi)),
            },
        }
    }

    /// The potential of a floating conducting tip carrying `charge` at `depth`. A punch's
    /// radius is fixed: `Q = 4a (K₂₁ d + K₂₂ ψ)`. A smooth profile's edge ties the radius to
    /// the potential, `ψ = (K₁₁/K₁₂)(g(a) - d)` (no pressure singularity), and the charge
    /// `Q(a) = 4 [K₂₁ (a d - ∫₀^a g) + K₂₂ a ψ(a)]` is met by bisection on `a` between the
    /// radii where it changes sign (scanned on a geometric grid about the insulating radius).
    fn floating_potential(&self, profile: &Profile, depth: f64, charge: f64) -> f64 {
        let k = self.k();
        if let Profile::Punch { radius } = profile {
            return (charge / (4.0 * radius) - k[(1, 0)] * depth) / k[(1, 1)];
        }
        let psi = |a: f64| k[(0, 0)] / k[(0, 1)] * (profile.sneddon_g(a) - depth);
        let q = |a: f64| {
            let integral = a * depth - gauss(0.0, a, 200, |x| profile.sneddon_g(x));
            4.0 * (k[(1, 0)] * integral + k[(1, 1)] * a * psi(a)) - charge
        };
        let a0 = contact_radius(profile, depth.max(f64::MIN_POSITIVE));
        let reach = profile.reach();
        let grid: Vec<f64> = (0..=240)
            .map(|i| a0 * 1e-3 * 10f64.powf(i as f64 / 60.0))
            .filter(|a| *a < reach)
            .collect();
        let Some(w) = grid.windows(2).find(|w| q(w[0]).signum() != q(w[1]).signum()) else {
            return f64::NAN;
        };
        let (mut lo, mut hi) = (w[0], w[1]);
        let q_lo = q(lo);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if q(mid).signum() == q_lo.signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        psi(0.5 * (lo + hi))
    }

    /// The closed form under the force `force > 0` (the depth found by bisection: the force
    /// grows with the depth).
    pub fn at_force(&self, profile: &Profile, force: f64, tip: Tip) -> Indentation {
        let at = |d: f64| self.at_depth(profile, d, tip);
        // a depth below the tip's own potential shift carries no force: start from there
        let (mut lo, mut hi) = (-1.0, 1.0);
        while at(lo).force > force && lo > -1e30 {
            lo *= 2.0;
        }
        while at(hi).force < force && hi < 1e30 {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if at(mid).force < force {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        at(0.5 * (lo + hi))
    }
}

/// The contact radius `a` with `g(a) = d` (g grows from 0; 0 for `d ≤ 0`), by bisection,
/// capped at the profile's reach.
fn contact_radius(profile: &Profile, d: f64) -> f64 {
    if d <= 0.0 {
        return 0.0;
    }
    let reach = profile.reach();
    let mut hi = if reach.is_finite() { reach } else { 1.0 };
    while reach.is_infinite() && profile.sneddon_g(hi) < d {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if profile.sneddon_g(mid) < d {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn isotropic_crystal(young: f64, nu: f64, eps: f64) -> Crystal {
        let lam = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = young / (2.0 * (1.0 + nu));
        Crystal::hexagonal_6mm([lam + 2.0 * mu, lam, lam, lam + 2.0 * mu, mu, mu], [0.0; 3], [eps, eps])
    }

    #[test]
    fn an_isotropic_solid_is_boussinesq_and_a_dielectric_is_coulomb() {
        // Boussinesq: w = (1 - ν²) P / (π E r), so G₁₁ = 2 (1 - ν²)/E; the solid's
        // elastic constants do not reach the potential: G₂₂ = 1/ε
        for nu in [0.0, 0.25, 0.3, 0.45] {
            let h = HalfSpace::from_crystal(&isotropic_crystal(100.0, nu, 3.0)).unwrap();
            let want = 2.0 * (1.0 - nu * nu) / 100.0;
            assert!((h.g[0][0] - want).abs() < 1e-12 * want, "nu {nu}: {} {want}", h.g[0][0]);
            assert!((h.g[1][1] - 1.0 / 3.0).abs() < 1e-12, "{:?}", h.g);
            assert!(h.g[0][1].abs() < 1e-14 && h.g[1][0].abs() < 1e-14);
            let elastic = HalfSpace::from_crystal(&isotropic_crystal(100.0, nu, 0.0)).unwrap();
            assert!((elastic.g[0][0] - want).abs() < 1e-12 * want);
            assert!(!elastic.electric);
        }
        // a transversely isotropic dielectric: φ = Q / (2π √(ε₁₁ ε₃₃) r) (the field of a
        // charge in an anisotropic medium, after scaling the normal coordinate)
        let mut c = isotropic_crystal(100.0, 0.3, 1.0);
        c.permittivity = [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 8.0]];
        let h = HalfSpace::from_crystal(&c).unwrap();
        assert!((h.g[1][1] - 0.25).abs() < 1e-12, "{:?}", h.g);
    }

    #[test]
    fn the_green_matrix_of_a_piezoelectric_is_reciprocal_and_converged() {
        // PZT-4: G is symmetric up to the sign convention of a charge (G₁₂ = -G₂₁: a force
        // and a charge are conjugate to w and -φ in the electric enthalpy)
        let pzt4 = Crystal::hexagonal_6mm([139.0, 77.8, 74.3, 115.0, 25.6, 30.6], [-5.2, 15.1, 12.7], [6.46, 5.62]);
        let h = HalfSpace::from_crystal(&pzt4).unwrap();
        let g = h.g;
        assert!((g[0][1] + g[1][0]).abs() < 1e-12 * g[0][1].abs(), "{g:?}");
        // stiffer than the elastic body alone: the coupling stiffens an insulating tip's contact
        let mut bare = pzt4.clone();
        bare.e = [[0.0; 6]; 3];
        let elastic = HalfSpace::from_crystal(&bare).unwrap();
        assert!(h.insulating_modulus() > elastic.insulating_modulus());
        assert!(h.conducting_modulus() > elastic.insulating_modulus());
    }

    #[test]
    fn sneddon_integrals_give_hertz_and_the_cone() {
        let h = HalfSpace::isotropic(100.0, 0.3);
        let e_star = 100.0 / (1.0 - 0.09);
        // Hertz: a = √(R d), P = (4/3) E* √R d^(3/2)
        let p = h.at_depth(&Profile::Paraboloid { radius: 10.0 }, 0.01, Tip::Insulating);
        assert!((p.contact_radius - 0.1f64.sqrt()).abs() < 1e-12);
        assert!((p.force - 4.0 / 3.0 * e_star * 10f64.sqrt() * 0.001).abs() < 1e-12 * p.force);
        // the same profile tabulated finely
        let table: Vec<[f64; 2]> = (0..=2000).map(|i| i as f64 * 1e-3).map(|r| [r, r * r / 20.0]).collect();
        let t = h.at_depth(&Profile::Tabulated(table), 0.01, Tip::Insulating);
        assert!((t.force / p.force - 1.0).abs() < 1e-5, "{} {}", t.force, p.force);
        // Sneddon's cone: P = (2/π) E* d² tan θ
        let c = h.at_depth(&Profile::Cone { half_angle: 70.0 }, 0.01, Tip::Insulating);
        let want = 2.0 / PI * e_star * 1e-4 * 70f64.to_radians().tan();
        assert!((c.force - want).abs() < 1e-12 * want);
        // Sneddon's sphere: d = (a/2) ln((R + a)/(R - a)), P = E* [(a² + R²)/2 ln((R+a)/(R-a)) - a R]
        let s = h.at_depth(&Profile::Sphere { radius: 1.0 }, 0.3, Tip::Insulating);
        let a = s.contact_radius;
        let ln = ((1.0 + a) / (1.0 - a)).ln();
        assert!((a / 2.0 * ln - 0.3).abs() < 1e-9);
        let want = e_star * ((a * a + 1.0) / 2.0 * ln - a);
        assert!((s.force / want - 1.0).abs() < 1e-8, "{} {want}", s.force);
        // force control inverts depth control
        let f = h.at_force(&Profile::Paraboloid { radius: 10.0 }, p.force, Tip::Insulating);
        assert!((f.depth - 0.01).abs() < 1e-12);
    }

    #[test]
    fn a_floating_tip_carries_its_charge_and_lies_between_the_others() {
        let pzt4 = Crystal::hexagonal_6mm([139.0, 77.8, 74.3, 115.0, 25.6, 30.6], [-5.2, 15.1, 12.7], [6.46, 5.62]);
        let h = HalfSpace::from_crystal(&pzt4).unwrap();
        for prof in [
            Profile::Paraboloid { radius: 10.0 },
            Profile::Cone { half_angle: 70.0 },
            Profile::Punch { radius: 1.0 },
        ] {
            let open = h.at_depth(&prof, 0.01, Tip::Floating { charge: 0.0 });
            // the conducting tip at the potential found carries no charge
            let again = h.at_depth(
                &prof,
                0.01,
                Tip::Conducting {
                    potential: open.potential.unwrap(),
                },
            );
            assert!(again.charge.unwrap().abs() < 1e-9 * open.force, "{prof:?}: {again:?}");
            assert!((again.force - open.force).abs() < 1e-12 * open.force);
            // an open circuit: stiffer than the grounded tip, its potential of the insulator's sign
            let grounded = h.at_depth(&prof, 0.01, Tip::Conducting { potential: 0.0 });
            let insulating = h.at_depth(&prof, 0.01, Tip::Insulating);
            assert!(open.force > grounded.force, "{prof:?}");
            assert!(open.potential.unwrap() * insulating.potential.unwrap() > 0.0);
            // a charge Q: the conducting tip at the potential found carries Q
            let q = 0.5 * grounded.charge.unwrap();
            let charged = h.at_depth(&prof, 0.01, Tip::Floating { charge: q });
            let check = h.at_depth(
                &prof,
                0.01,
                Tip::Conducting {
                    potential: charged.potential.unwrap(),
                },
            );
            assert!(
                (check.charge.unwrap() - q).abs() < 1e-8 * q.abs(),
                "{prof:?}: {check:?}"
            );
        }
    }

    #[test]
    fn a_conducting_tip_at_a_voltage_moves_the_depth_at_constant_force() {
        let pzt4 = Crystal::hexagonal_6mm([139.0, 77.8, 74.3, 115.0, 25.6, 30.6], [-5.2, 15.1, 12.7], [6.46, 5.62]);
        let h = HalfSpace::from_crystal(&pzt4).unwrap();
        let prof = Profile::Paraboloid { radius: 10.0 };
        let f0 = h.at_depth(&prof, 0.01, Tip::Conducting { potential: 0.0 }).force;
        let up = h.at_force(&prof, f0, Tip::Conducting { potential: 1e-4 });
        let down = h.at_force(&prof, f0, Tip::Conducting { potential: -1e-4 });
        // the force fixes the contact radius (P = (8/3) K₁₁ a³/R whatever ψ); the depth moves
        // by -(K₁₂/K₁₁) ψ
        assert!((up.contact_radius - down.contact_radius).abs() < 1e-9);
        let k = h.k();
        let slope = (up.depth - down.depth) / 2e-4;
        assert!((slope + k[(0, 1)] / k[(0, 0)]).abs() < 1e-6 * slope.abs(), "{slope}");
    }
}
