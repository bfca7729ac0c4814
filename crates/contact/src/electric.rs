//! Electrical contact: a foundation that conducts where it touches. The potentials of the
//! contact points join the condensed unknowns, with one more multiplier per point, the
//! outward electric flux `q = D·ν` through it, and one more equation, the electric law at the
//! point, which switches with the point's contact status:
//!
//! - [`ElectricLaw::Conductive`]: the regularised conductivity condition of Barboteu and
//!   Sofonea (J. Math. Anal. Appl. 358 (2009)) and of Lerguet, Shillor and Sofonea (EJDE
//!   2007/170), `q = σ_c p (φ - φ_F)`, with `p` the contact pressure `λ_n` on a rigid
//!   foundation and the penetration `[u_n - g]₊` on a compliant one: no flux where the point
//!   is separated;
//! - [`ElectricLaw::Conducting`]: an ideal conductor, `φ = φ_F` where the point is in contact,
//!   `q = 0` where it is separated (the limit `σ_c → ∞`).
//!
//! The problem is `[u; φ] = [u₀; φ₀] - D W [λ; q]` with `D` of order `m + n_e` (`m` the
//! mechanical rows, `n_e` the points whose potential is free). Its mechanical block is the
//! contact compliance; the electric one, `-(K⁻¹)_φφ`, is positive definite; the couplings are
//! opposite, `D_ue = -D_euᵀ`, so that `D` is positive real, not symmetric: the paper's
//! non-symmetric coercive form. [`crate::solve_newton_electric`] solves it by the semismooth Newton
//! method on all its rows at once (docs/theory.md, "Electrical contact").

use crate::operator::{Compliance, ContactOperator, DenseContactProblem};
use crate::points::{ContactPoints, PointValues};
use crate::{ContactError, InputError, OperatorError};

/// The electric law at the contact points where the foundation conducts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElectricLaw {
    /// `q = σ_c p (φ - φ_F)`: the flux through the point proportional to the potential
    /// difference and to `p` (the pressure on a rigid foundation, the penetration on a
    /// compliant one).
    Conductive {
        /// `σ_c ≥ 0`, the conductance (flux per unit potential and unit `p`).
        conductance: f64,
    },
    /// `φ = φ_F` in contact, `q = 0` separated.
    Conducting,
}

/// The electric condition of the contact points: the law, the foundation's potential and the
/// points whose potential is free (a point on an electrode has its potential prescribed and no
/// electric unknown).
#[derive(Clone, Debug, PartialEq)]
pub struct ElectricContact {
    /// The law.
    pub law: ElectricLaw,
    /// `φ_F`, the foundation's potential.
    pub potential: f64,
    /// The contact points with an electric unknown, in the order of the electric rows.
    pub points: Vec<usize>,
}

impl ElectricContact {
    /// Checks the data against `n` contact points.
    ///
    /// # Errors
    /// [`InputError::Electric`] naming the value out of range.
    pub fn validate(&self, n: usize) -> Result<(), InputError> {
        let bad = |what: &'static str, value: f64, must: &'static str| InputError::Electric { what, value, must };
        if !self.potential.is_finite() {
            return Err(bad("foundation potential", self.potential, "must be finite"));
        }
        if let ElectricLaw::Conductive { conductance } = self.law {
            if !(conductance >= 0.0 && conductance.is_finite()) {
                return Err(bad("conductance", conductance, "must be finite and >= 0"));
            }
        }
        if let Some(&p) = self.points.iter().find(|&&p| p >= n) {
            return Err(bad("point", p as f64, "must be one of the contact points"));
        }
        if self.points.windows(2).any(|w| w[0] >= w[1]) {
            return Err(bad("point", f64::NAN, "must be listed once each, in increasing order"));
        }
        Ok(())
    }

    /// The equation of one electric row and its generalised derivative, in the natural-map
    /// form of the mechanical rows: `x` the flux, `u` the potential, `c` the row's constant, `p`
    /// the point's pressure or penetration, `contact` its status (`z_n > 0` on a rigid
    /// foundation, a positive penetration on a compliant one).
    ///
    /// Conductive: `f = (x - σ p (u - φ_F)) / s` with `s = 1 + σ p / c`, of order one in both limits: `x` for a poor conductor, and `-c (u - φ_F)`,
    /// the ideal conductor's, for a good one. Conducting: `-c (u - φ_F)` in contact, `x`
    /// separated.
    pub(crate) fn row(&self, x: f64, u: f64, c: f64, p: f64, contact: bool) -> Row {
        let du = u - self.potential;
        match self.law {
            ElectricLaw::Conductive { conductance } => {
                let p = crate::project_nonnegative(p);
                let scale = 1.0 + conductance * p / c;
                let f = (x - conductance * p * du) / scale;
                // ∂f/∂p = -(σ/s) (u - φ_F + f/c): the scale's own derivative included
                Row {
                    f,
                    identity: 1.0 / scale,
                    along_c: conductance * p / (c * scale),
                    along_p: if p > 0.0 {
                        -conductance / scale * (du + f / c)
                    } else {
                        0.0
                    },
                }
            }
            ElectricLaw::Conducting if contact => Row {
                f: -c * du,
                identity: 0.0,
                along_c: 1.0,
                along_p: 0.0,
            },
            ElectricLaw::Conducting => Row {
                f: x,
                identity: 1.0,
                along_c: 0.0,
                along_p: 0.0,
            },
        }
    }
}

/// One electric row: its value `f` and its derivative `identity · e_r + along_c · C_r +
/// along_p · ∂p`, with `C = diag(c) (D W + σ I)` as for the mechanical rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Row {
    pub f: f64,
    pub identity: f64,
    pub along_c: f64,
    pub along_p: f64,
}

/// The contact problem with the potentials of its points: `[u; φ] = [u₀; φ₀] - D W [λ; q]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ElectricContactProblem {
    /// Contact displacement under the loads alone (`λ = 0`, `q = 0`).
    pub u0: PointValues,
    /// The potential of the electric points under the loads alone.
    pub phi0: Vec<f64>,
    /// `D`, row-major, of order `m + n_e`: `m = n (1 + nt)` mechanical rows in the layout
    /// `[normal (n); tangential (n·nt)]`, then one row per electric point.
    pub compliance: Vec<f64>,
    /// Weights `w_i` of the contact points.
    pub weight: Vec<f64>,
    /// Tangential components per point.
    pub nt: usize,
    /// The electric condition.
    pub electric: ElectricContact,
}

/// The flux and potential of the electric points of a solution.
#[derive(Clone, Debug, PartialEq)]
pub struct ElectricValues {
    /// The contact points with an electric unknown.
    pub points: Vec<usize>,
    /// The outward flux `q = D·ν` at each (charge per unit area).
    pub flux: Vec<f64>,
    /// The potential `φ` at each.
    pub potential: Vec<f64>,
}

impl ElectricValues {
    /// The charge on the conductor across the contact zone (the foundation, or the tip), the
    /// negative of the flux out of the body, `-Σ w_i q_i`: the project's one convention for
    /// a charge (the charge on the conductor, positive where the conductor is at the higher
    /// potential of a capacitor).
    pub fn charge(&self, weight: &[f64]) -> f64 {
        -self
            .points
            .iter()
            .zip(&self.flux)
            .map(|(&i, q)| weight[i] * q)
            .sum::<f64>()
            // no charge reads 0, not -0
            + 0.0
    }
}

impl ElectricContactProblem {
    /// The mechanical rows.
    pub fn m(&self) -> usize {
        self.weight.len() * (1 + self.nt)
    }

    /// The order of `D`.
    pub fn order(&self) -> usize {
        self.m() + self.electric.points.len()
    }

    /// The problem without electrical contact (an insulating foundation: no flux), a
    /// [`DenseContactProblem`] on the mechanical rows.
    pub fn insulated(&self) -> DenseContactProblem {
        let (m, o) = (self.m(), self.order());
        let compliance = (0..m * m).map(|k| self.compliance[(k / m) * o + k % m]).collect();
        DenseContactProblem {
            u0: self.u0.clone(),
            compliance,
            weight: self.weight.clone(),
            nt: self.nt,
        }
    }

    /// `[u; φ]` at the flat multipliers `[λ; q]` (flat layout).
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        let o = self.order();
        let w = self.flat_weights();
        let wx: Vec<f64> = x.iter().zip(&w).map(|(a, b)| a * b).collect();
        let mut out = vec![0.0; o];
        Compliance::Dense(&self.compliance).apply(&wx, &mut out);
        let u0 = self.flat_loads();
        out.iter_mut().zip(&u0).for_each(|(o, u)| *o = u - *o);
        out
    }

    /// The weight of each flat row.
    fn flat_weights(&self) -> Vec<f64> {
        let (n, nt) = (self.weight.len(), self.nt);
        let mut w: Vec<f64> = (0..self.m())
            .map(|r| self.weight[if r < n { r } else { (r - n) / nt }])
            .collect();
        w.extend(self.electric.points.iter().map(|&i| self.weight[i]));
        w
    }

    /// `[u₀; φ₀]`, flat.
    fn flat_loads(&self) -> Vec<f64> {
        let u = &self.u0;
        u.normal
            .iter()
            .chain(&u.tangential)
            .chain(&self.phi0)
            .copied()
            .collect()
    }

    pub(crate) fn check(&self, points: &ContactPoints) -> Result<(), ContactError> {
        self.electric.validate(points.len())?;
        let o = self.order();
        if self.compliance.len() != o * o
            || self.phi0.len() != self.electric.points.len()
            || self.u0.n_points() != self.weight.len()
        {
            return Err(InputError::ComplianceSize {
                size: (self.compliance.len() as f64).sqrt() as usize,
                points: self.u0.n_points(),
                n: self.weight.len(),
                nt: self.nt,
                m: o,
            }
            .into());
        }
        Ok(())
    }

    /// The problem with its electric rows scaled to its mechanical ones, and the scale `s`:
    /// the flux `q = s q̃`, the potential `φ = φ̃ / s`, so that the electric block's mean
    /// diagonal is the normal block's (`D̃_ee = s² D_ee`, `D̃_ue = s D_ue`) and both kinds of
    /// rows weigh alike in Newton's merit; `φ_F` and `σ_c` follow (`s φ_F`, `σ_c / s²`).
    pub(crate) fn scaled(&self) -> (ElectricContactProblem, f64) {
        let (n, m, o) = (self.weight.len(), self.m(), self.order());
        let mean = |rows: std::ops::Range<usize>| {
            let k = rows.len().max(1) as f64;
            rows.map(|r| self.compliance[r * o + r].abs()).sum::<f64>() / k
        };
        let (normal, electric) = (mean(0..n), mean(m..o));
        let s = if normal > 0.0 && electric > 0.0 && (normal / electric).is_finite() {
            (normal / electric).sqrt()
        } else {
            1.0
        };
        let mut p = self.clone();
        let factor = |r: usize| if r >= m { s } else { 1.0 };
        for (k, d) in p.compliance.iter_mut().enumerate() {
            *d *= factor(k / o) * factor(k % o);
        }
        p.phi0.iter_mut().for_each(|v| *v *= s);
        p.electric.potential *= s;
        if let ElectricLaw::Conductive { conductance } = &mut p.electric.law {
            *conductance /= s * s;
        }
        (p, s)
    }
}

impl ContactOperator for ElectricContactProblem {
    fn n_points(&self) -> usize {
        self.weight.len()
    }
    fn n_tangential(&self) -> usize {
        self.nt
    }
    /// The mechanical rows at no flux.
    fn displacement(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        self.forces_alone(lambda, out)?;
        for (o, u) in out
            .normal
            .iter_mut()
            .chain(out.tangential.iter_mut())
            .zip(self.u0.normal.iter().chain(&self.u0.tangential))
        {
            *o += u;
        }
        Ok(0)
    }
    fn forces_alone(&mut self, lambda: &PointValues, out: &mut PointValues) -> Result<usize, OperatorError> {
        let (m, o) = (self.m(), self.order());
        let mut x = lambda.to_flat();
        x.resize(o, 0.0);
        let w = self.flat_weights();
        for r in 0..m {
            let row = &self.compliance[r * o..r * o + m];
            let v: f64 = row.iter().zip(&x).zip(&w).map(|((d, x), w)| d * x * w).sum();
            if r < out.normal.len() {
                out.normal[r] = -v;
            } else {
                out.tangential[r - out.normal.len()] = -v;
            }
        }
        Ok(0)
    }
}
