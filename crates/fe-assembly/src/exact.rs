//! Exact solutions for verification: a smooth solution `(u, φ)` given with its first and second
//! derivatives, the body force and charge that make it solve the coupled equations
//! (manufactured solutions, Roache 2002), the Dirichlet data it prescribes, and the errors of a
//! discrete solution against it in the L2 and energy norms.
//!
//! The equations (signs of DESIGN.md): `-div σ = f0`, `div D = q0`, with
//! `σ = C ε(u) + eᵀ ∇φ` and `D = e ε(u) - β ∇φ`. So, in index form,
//! `f0_i = -Σ_jkl C_ijkl ∂_jl u_k - Σ_jk e_kij ∂_jk φ` and
//! `q0 = Σ_ikl e_ikl ∂_il u_k - Σ_ik β_ik ∂_ik φ`.

use crate::{kernels, voigt, Constraint, Discretization, Field, Load, Material};
use std::f64::consts::PI;
use std::sync::Arc;

/// The law of the contact face of [`Exact::on_foundation`]: the bed under it and its electric
/// condition, with the constants of the material along the normal (a 6mm crystal poled along
/// it) that make the face's pressure and flux.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    /// `c33`, `e33`, `ε33` along the normal.
    pub constants: [f64; 3],
    /// A deformable foundation, normal compliance `λ_n = k [u_n - g]₊^m`: `(k, m)`; `None`
    /// for a rigid one.
    pub bed: Option<(f64, f64)>,
    /// The electric condition of the face.
    pub electric: FaceElectric,
}

/// The electric condition of the contact face of [`Exact::on_foundation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaceElectric {
    /// An ideal conductor: `φ = φ_F` on the face.
    Conducting,
    /// A conductive foundation, `D·ν = σ_c p (φ - φ_F)` with `p` the pressure (rigid) or the
    /// penetration (a linear bed), the face at `φ_F + offset`; `conductance = 0` is the
    /// insulated face `D·ν = 0`.
    Conductive {
        /// `σ_c ≥ 0`.
        conductance: f64,
        /// The potential of the face above the foundation's, `φ - φ_F`.
        offset: f64,
    },
}

/// Value, gradient and Hessian of a scalar field at a point (unused components zero).
pub type Jet = (f64, [f64; 3], [[f64; 3]; 3]);

/// The jets of the displacement components at a point.
pub type VectorJetFn = Arc<dyn Fn(&[f64]) -> [Jet; 3] + Send + Sync>;
/// The jet of a scalar field at a point.
pub type ScalarJetFn = Arc<dyn Fn(&[f64]) -> Jet + Send + Sync>;

/// An exact solution: the jets of the `dim` displacement components and of the potential.
#[derive(Clone)]
pub struct Exact {
    /// Spatial dimension, 2 or 3.
    pub dim: usize,
    /// `u(x)[k]` is the jet of `u_k`.
    pub u: VectorJetFn,
    /// The jet of `φ`.
    pub phi: ScalarJetFn,
}

/// `a Π_i sin(k_i x_i + p_i)` over the first `dim` coordinates, with its derivatives.
pub fn sine_product(dim: usize, a: f64, k: [f64; 3], p: [f64; 3], x: &[f64]) -> Jet {
    let mut s = [1.0; 3];
    let mut c = [0.0; 3];
    for i in 0..dim {
        s[i] = (k[i] * x[i] + p[i]).sin();
        c[i] = k[i] * (k[i] * x[i] + p[i]).cos();
    }
    let mut g = [0.0; 3];
    let mut h = [[0.0; 3]; 3];
    for i in 0..dim {
        let f = |q: usize| if q == i { c[q] } else { s[q] };
        g[i] = a * f(0) * f(1) * f(2);
        for j in 0..dim {
            let ff = |q: usize| match (q == i, q == j) {
                (true, true) => -k[q] * k[q] * s[q],
                (true, false) | (false, true) => c[q],
                (false, false) => s[q],
            };
            h[i][j] = a * ff(0) * ff(1) * ff(2);
        }
    }
    (a * s[0] * s[1] * s[2], g, h)
}

impl Exact {
    /// The manufactured solution of the verification study, on `(0,2) x (0,1) [x (0,1)]`:
    /// `u_k = 1e-3 sin(π x (k+1)/2) sin(π y) [cos(π z/2)]`, `φ = 1e-2 cos(π x/2) sin(π y)
    /// [cos(π z/2)]` (amplitudes of the paper's scaled units: strains of 1e-3, fields of 1e-2).
    pub fn manufactured(dim: usize) -> Self {
        Exact {
            dim,
            u: Arc::new(move |x| {
                let mut out = [(0.0, [0.0; 3], [[0.0; 3]; 3]); 3];
                for (k, o) in out.iter_mut().enumerate().take(dim) {
                    *o = sine_product(
                        dim,
                        1e-3,
                        [PI * (k as f64 + 1.0) / 2.0, PI, PI / 2.0],
                        [0.0, 0.0, PI / 2.0],
                        x,
                    );
                }
                out
            }),
            phi: Arc::new(move |x| sine_product(dim, 1e-2, [PI / 2.0, PI, PI / 2.0], [PI / 2.0, 0.0, PI / 2.0], x)),
        }
    }

    /// A solution in contact everywhere on the face `x_n = s0` (`n = dim - 1`, the outward
    /// normal `-e_n`) with a foundation whose gap is `g(t) = g0 + κ |t - c|² / 2` (`t` the
    /// tangential coordinates) and whose potential is `φ_F`, the points sticking. With
    /// `s = x_n - s0` and `E(t) = 10⁻² + 10⁻³ sin(π t_0 / 2)`:
    /// `u_k = 10⁻³ s sin(π t_k / 2 + 0.3)` (`k < n`: no slip on the face),
    /// `u_n = -g(t) - δ(t) - s E(t)` (`ε_nn = -E`: a compression; `δ` the penetration into the
    /// bed, 0 on a rigid foundation), and by the face's electric condition:
    /// - conducting: `φ = φ_F + s (10⁻² + 5·10⁻³ cos(π t_0 / 2))` (`φ = φ_F` on the face);
    /// - conductive: `φ = φ_F + a + s ϰ E(t)`, `a` the face's offset, with `ϰ` the slope that
    ///   makes the flux the law's: on the face (`ε_tt = 0`) the pressure is
    ///   `λ_n = -σ_nn = c33 E - e33 ∂_s φ` and the flux `D·ν = e33 E + ε33 ∂_s φ`, so
    ///   `D·ν = σ' a λ_n` (`σ' = σ_c`, or `σ_c / k` on a linear bed, whose penetration is
    ///   `λ_n / k`) gives `ϰ = (σ' a c33 - e33) / (ε33 + σ' a e33)`; `σ_c = 0` is the insulated
    ///   face. (On a bed with `m ≠ 1` the penetration is not linear in the pressure and the
    ///   slope has no closed form: there `σ_c` must be 0.)
    ///
    /// On a bed the face sinks by `δ = (λ_n / k)^(1/m)`, `λ_n` the pressure the fields give on
    /// the face. Whether the pressure is positive and the shear within the friction bound
    /// depends on the material and the coefficient: the caller checks the run's status.
    pub fn on_foundation(
        dim: usize,
        s0: f64,
        (g0, curvature, center): (f64, f64, [f64; 3]),
        phi_f: f64,
        face: Face,
    ) -> Self {
        let n = dim - 1;
        let h = PI / 2.0;
        let (delta, b) = (1e-2, 1e-3);
        let [c33, e33, eps33] = face.constants;
        // ∂_s φ on the face as `p0 + p1 sin(h t0) + p2 cos(h t0)`, and its value there
        let (slope, face_phi) = match face.electric {
            FaceElectric::Conducting => ([1e-2, 0.0, 5e-3], phi_f),
            FaceElectric::Conductive { conductance, offset } => {
                let sigma = conductance / face.bed.map_or(1.0, |(k, _)| k);
                let kappa = (sigma * offset * c33 - e33) / (eps33 + sigma * offset * e33);
                ([kappa * delta, kappa * b, 0.0], phi_f + offset)
            }
        };
        // the pressure on the face, `l0 + l1 sin + l2 cos`, and the penetration's jet in t_0
        let pressure = [c33 * delta - e33 * slope[0], c33 * b - e33 * slope[1], -e33 * slope[2]];
        let penetration = move |t0: f64| -> (f64, f64, f64) {
            let Some((k, m)) = face.bed else {
                return (0.0, 0.0, 0.0);
            };
            let (sn, cs) = ((h * t0).sin(), (h * t0).cos());
            let l = (pressure[0] + pressure[1] * sn + pressure[2] * cs) / k;
            let dl = h * (pressure[1] * cs - pressure[2] * sn) / k;
            let ddl = -h * h * (pressure[1] * sn + pressure[2] * cs) / k;
            // δ = l^(1/m)
            let r = 1.0 / m;
            let v = l.powf(r);
            let dv = r * l.powf(r - 1.0) * dl;
            let ddv = r * (r - 1.0) * l.powf(r - 2.0) * dl * dl + r * l.powf(r - 1.0) * ddl;
            (v, dv, ddv)
        };
        Exact {
            dim,
            u: Arc::new(move |x| {
                let s = x[n] - s0;
                let mut out = [(0.0, [0.0; 3], [[0.0; 3]; 3]); 3];
                for (k, o) in out.iter_mut().enumerate().take(n) {
                    let (sn, cs) = ((h * x[k] + 0.3).sin(), (h * x[k] + 0.3).cos());
                    let a = 1e-3;
                    let mut g = [0.0; 3];
                    let mut hh = [[0.0; 3]; 3];
                    g[k] = a * s * h * cs;
                    g[n] = a * sn;
                    hh[k][k] = -a * s * h * h * sn;
                    hh[k][n] = a * h * cs;
                    hh[n][k] = a * h * cs;
                    *o = (a * s * sn, g, hh);
                }
                let (sn, cs) = ((h * x[0]).sin(), (h * x[0]).cos());
                let (pen, dpen, ddpen) = penetration(x[0]);
                let gap = g0 + pen + 0.5 * curvature * (0..n).map(|k| (x[k] - center[k]).powi(2)).sum::<f64>();
                let mut g = [0.0; 3];
                let mut hh = [[0.0; 3]; 3];
                for k in 0..n {
                    g[k] = -curvature * (x[k] - center[k]);
                    hh[k][k] = -curvature;
                }
                g[0] -= dpen;
                hh[0][0] -= ddpen;
                g[0] -= s * b * h * cs;
                g[n] = -(delta + b * sn);
                hh[0][0] += s * b * h * h * sn;
                hh[0][n] = -b * h * cs;
                hh[n][0] = -b * h * cs;
                out[n] = (-gap - s * (delta + b * sn), g, hh);
                out
            }),
            phi: Arc::new(move |x| {
                let s = x[n] - s0;
                let (sn, cs) = ((h * x[0]).sin(), (h * x[0]).cos());
                let [p0, p1, p2] = slope;
                let value = p0 + p1 * sn + p2 * cs;
                let dvalue = h * (p1 * cs - p2 * sn);
                let ddvalue = -h * h * (p1 * sn + p2 * cs);
                let mut g = [0.0; 3];
                let mut hh = [[0.0; 3]; 3];
                g[0] = s * dvalue;
                g[n] = value;
                hh[0][0] = s * ddvalue;
                hh[0][n] = dvalue;
                hh[n][0] = dvalue;
                (face_phi + s * value, g, hh)
            }),
        }
    }

    /// An affine solution `u = u0 + (∇u) x`, `φ = φ0 + ∇φ · x`: what a patch test reproduces to
    /// round-off. `grad_u[k][j] = ∂_j u_k`.
    pub fn affine(dim: usize, u0: [f64; 3], grad_u: [[f64; 3]; 3], phi0: f64, grad_phi: [f64; 3]) -> Self {
        Exact {
            dim,
            u: Arc::new(move |x| {
                let mut out = [(0.0, [0.0; 3], [[0.0; 3]; 3]); 3];
                for k in 0..dim {
                    let v = u0[k] + (0..dim).map(|j| grad_u[k][j] * x[j]).sum::<f64>();
                    out[k] = (v, grad_u[k], [[0.0; 3]; 3]);
                }
                out
            }),
            phi: Arc::new(move |x| {
                let v = phi0 + (0..dim).map(|j| grad_phi[j] * x[j]).sum::<f64>();
                (v, grad_phi, [[0.0; 3]; 3])
            }),
        }
    }

    /// The body force `f0` and body charge `q0` for which this is the solution with material
    /// `m` (one material in the whole body).
    pub fn loads(&self, m: &Material) -> [Load; 2] {
        let dim = self.dim;
        let nv = m.nv();
        let (mf, mq) = (m.clone(), m.clone());
        let (uf, pf) = (self.u.clone(), self.phi.clone());
        let (uq, pq) = (self.u.clone(), self.phi.clone());
        let f0 = move |x: &[f64]| {
            let (hu, hp) = (uf(x), pf(x).2);
            let mut f = [0.0; 3];
            for (i, fi) in f.iter_mut().enumerate().take(dim) {
                let mut s = 0.0;
                for j in 0..dim {
                    for k in 0..dim {
                        for l in 0..dim {
                            s += mf.c[voigt(dim, i, j) * nv + voigt(dim, k, l)] * hu[k].2[l][j];
                        }
                        s += mf.e[k * nv + voigt(dim, i, j)] * hp[k][j];
                    }
                }
                *fi = -s;
            }
            f
        };
        let q0 = move |x: &[f64]| {
            let (hu, hp) = (uq(x), pq(x).2);
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
        [Load::BodyForce(Arc::new(f0)), Load::BodyCharge(Arc::new(q0))]
    }

    /// Dirichlet data for every displacement component and the potential on each of `groups`.
    pub fn constraints(&self, groups: &[&str]) -> Vec<Constraint> {
        let mut out = vec![];
        for &g in groups {
            for k in 0..self.dim {
                let u = self.u.clone();
                out.push(Constraint {
                    group: g.into(),
                    field: Field::Displacement(k),
                    value: Arc::new(move |x| u(x)[k].0),
                });
            }
            let phi = self.phi.clone();
            out.push(Constraint {
                group: g.into(),
                field: Field::Potential,
                value: Arc::new(move |x| phi(x).0),
            });
        }
        out
    }
}

/// Errors of a discrete solution against an [`Exact`] one, absolute and relative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorNorms {
    /// `‖u_h - u‖_L2`.
    pub l2_u: f64,
    /// `‖φ_h - φ‖_L2`.
    pub l2_phi: f64,
    /// The energy norm of the error, `(∫ ε(e_u):C:ε(e_u) + ∇e_φ·β∇e_φ)^½` (the coupling
    /// cancels in the paper's form).
    pub energy: f64,
    /// `‖u‖_L2`, `‖φ‖_L2` and the energy norm of the exact solution, for relative errors.
    pub norms: (f64, f64, f64),
}

impl ErrorNorms {
    /// `‖u_h - u‖ / ‖u‖` in L2.
    pub fn rel_l2_u(&self) -> f64 {
        self.l2_u / self.norms.0
    }
    /// `‖φ_h - φ‖ / ‖φ‖` in L2.
    pub fn rel_l2_phi(&self) -> f64 {
        self.l2_phi / self.norms.1
    }
    /// Relative error in the energy norm.
    pub fn rel_energy(&self) -> f64 {
        self.energy / self.norms.2
    }
}

impl Discretization<'_> {
    /// The errors of the nodal solution `(u, φ)` (all nodes, as [`crate::DofMap::expand_u`]
    /// gives them) against `exact`, by a degree-2 rule on each cell (exact for the square of
    /// a P1 function; for the smooth part, accurate to `O(h³)` relative, enough for rates).
    pub fn error_norms(&self, u: &[[f64; 3]], phi: &[f64], exact: &Exact) -> ErrorNorms {
        let (mesh, dim) = (self.mesh, self.mesh.dim);
        let rule: Vec<[f64; 4]> = if dim == 2 {
            let (a, b) = (2.0 / 3.0, 1.0 / 6.0);
            vec![[a, b, b, 0.0], [b, a, b, 0.0], [b, b, a, 0.0]]
        } else {
            let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
            vec![[a, b, b, b], [b, a, b, b], [b, b, a, b], [b, b, b, a]]
        };
        let (mut eu, mut ep, mut en) = (0.0, 0.0, 0.0);
        let (mut nu, mut np, mut nn) = (0.0, 0.0, 0.0);
        let energy = |m: &Material, eps: &[f64; 6], grad: &[f64]| {
            let nv = m.nv();
            let mut s = 0.0;
            for a in 0..nv {
                for b in 0..nv {
                    s += eps[a] * m.c[a * nv + b] * eps[b];
                }
            }
            for a in 0..dim {
                for b in 0..dim {
                    s += grad[a] * m.beta[a * dim + b] * grad[b];
                }
            }
            s
        };
        for (c, cell) in mesh.iter_cells().enumerate() {
            let g = &self.geometry[c];
            let m = &self.materials[self.cell_material[c]];
            let w = g.measure / rule.len() as f64;
            let ul: Vec<[f64; 3]> = cell.iter().map(|&v| u[v]).collect();
            let pl: Vec<f64> = cell.iter().map(|&v| phi[v]).collect();
            let eps_h = kernels::cell_strain(dim, g, &ul);
            let gp_h = kernels::cell_gradient(dim, g, &pl);
            for bary in &rule {
                let mut x = [0.0; 3];
                let (mut uh, mut ph) = ([0.0; 3], 0.0);
                for (a, &v) in cell.iter().enumerate() {
                    for k in 0..3 {
                        x[k] += bary[a] * mesh.points[v][k];
                        uh[k] += bary[a] * u[v][k];
                    }
                    ph += bary[a] * phi[v];
                }
                let x = &x[..dim];
                let (ju, jp) = ((exact.u)(x), (exact.phi)(x));
                for k in 0..dim {
                    eu += w * (uh[k] - ju[k].0).powi(2);
                    nu += w * ju[k].0.powi(2);
                }
                ep += w * (ph - jp.0).powi(2);
                np += w * jp.0.powi(2);
                // strains in Voigt order with engineering shears
                let (mut de, mut ex) = ([0.0; 6], [0.0; 6]);
                for i in 0..dim {
                    for j in i..dim {
                        let e = if i == j { ju[i].1[i] } else { ju[i].1[j] + ju[j].1[i] };
                        ex[voigt(dim, i, j)] = e;
                        de[voigt(dim, i, j)] = eps_h[voigt(dim, i, j)] - e;
                    }
                }
                let dg: Vec<f64> = (0..dim).map(|i| gp_h[i] - jp.1[i]).collect();
                en += w * energy(m, &de, &dg);
                nn += w * energy(m, &ex, &jp.1[..dim]);
            }
        }
        ErrorNorms {
            l2_u: eu.sqrt(),
            l2_phi: ep.sqrt(),
            energy: en.sqrt(),
            norms: (nu.sqrt(), np.sqrt(), nn.sqrt()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The jets' derivatives against central differences.
    #[test]
    fn sine_product_derivatives_match_differences() {
        let x = [0.3, 0.7, 0.2];
        let (k, p) = ([1.3, 2.1, 0.7], [0.2, 0.0, 1.1]);
        let (_, g, h) = sine_product(3, 0.5, k, p, &x);
        let d = 1e-5;
        for i in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[i] += d;
            xm[i] -= d;
            let (vp, gp, _) = sine_product(3, 0.5, k, p, &xp);
            let (vm, gm, _) = sine_product(3, 0.5, k, p, &xm);
            assert!(((vp - vm) / (2.0 * d) - g[i]).abs() < 1e-8);
            for j in 0..3 {
                assert!(((gp[j] - gm[j]) / (2.0 * d) - h[j][i]).abs() < 1e-8);
            }
        }
    }

    /// The jets of the solution on a foundation against central differences, in 2D and 3D,
    /// rigid and on beds, conducting, conductive and insulated, and its contact face's values:
    /// the gap's normal displacement (and the bed's penetration `(λ_n/k)^(1/m)`), no slip, the
    /// face's potential, and the conductive law's flux `σ' (φ - φ_F) λ_n`.
    #[test]
    fn the_foundation_solution_has_consistent_jets_and_its_face_law() {
        let constants = [111.0, 15.8, 7.35];
        let beds = [None, Some((50.0, 1.0)), Some((3.0, 2.5))];
        let electric = [
            FaceElectric::Conducting,
            FaceElectric::Conductive {
                conductance: 20.0,
                offset: 0.01,
            },
            FaceElectric::Conductive {
                conductance: 0.0,
                offset: -0.3,
            },
        ];
        for dim in [2, 3] {
            for (bed, electric) in beds.iter().flat_map(|b| electric.map(|e| (*b, e))) {
                let nonlinear = bed.is_some_and(|(_, m)| m != 1.0);
                if nonlinear && matches!(electric, FaceElectric::Conductive { conductance, .. } if conductance > 0.0) {
                    continue; // no closed form (see on_foundation)
                }
                let face = Face {
                    constants,
                    bed,
                    electric,
                };
                let e = Exact::on_foundation(dim, 0.1, (0.02, 0.3, [1.0, 0.5, 0.0]), 0.04, face);
                let x = [0.3, 0.7, 0.45];
                let jets = |x: &[f64]| {
                    let u = (e.u)(x);
                    let mut all: Vec<Jet> = u[..dim].to_vec();
                    all.push((e.phi)(x));
                    all
                };
                let d = 1e-5;
                let at = jets(&x);
                for i in 0..dim {
                    let (mut xp, mut xm) = (x, x);
                    xp[i] += d;
                    xm[i] -= d;
                    let (p, m) = (jets(&xp), jets(&xm));
                    for f in 0..=dim {
                        assert!(
                            ((p[f].0 - m[f].0) / (2.0 * d) - at[f].1[i]).abs() < 1e-8,
                            "{dim}D field {f} d{i}"
                        );
                        for j in 0..dim {
                            let fd = (p[f].1[j] - m[f].1[j]) / (2.0 * d);
                            assert!((fd - at[f].2[j][i]).abs() < 1e-7, "{dim}D field {f} d{j}d{i}");
                        }
                    }
                }
                // on the face x_n = 0.1
                let mut y = x;
                y[dim - 1] = 0.1;
                let face_jets = jets(&y);
                let gap = 0.02 + 0.15 * (0..dim - 1).map(|k| (y[k] - [1.0, 0.5][k]).powi(2)).sum::<f64>();
                // the pressure and flux from the jets: -σ_nn = -(c33 ε_nn + e33 φ_n) and
                // D·ν = -(e33 ε_nn - ε33 φ_n), the tangential strain being 0 on the face
                let n = dim - 1;
                assert!((0..n).all(|k| face_jets[k].1[k] == 0.0));
                let (eps_nn, phi_n) = (face_jets[n].1[n], face_jets[dim].1[n]);
                let pressure = -(constants[0] * eps_nn + constants[1] * phi_n);
                let flux = -(constants[1] * eps_nn - constants[2] * phi_n);
                assert!(pressure > 0.0);
                let sink = bed.map_or(0.0, |(k, m)| (pressure / k).powf(1.0 / m));
                assert!((-face_jets[n].0 - gap - sink).abs() < 1e-15);
                assert!((0..n).all(|k| face_jets[k].0 == 0.0));
                match electric {
                    FaceElectric::Conducting => assert!((face_jets[dim].0 - 0.04).abs() < 1e-15),
                    FaceElectric::Conductive { conductance, offset } => {
                        assert!((face_jets[dim].0 - 0.04 - offset).abs() < 1e-15);
                        // the law: σ_c p (φ - φ_F), p the pressure, or the penetration
                        let p = if bed.is_some() { sink } else { pressure };
                        assert!((flux - conductance * p * offset).abs() < 1e-13, "{flux}");
                    }
                }
            }
        }
    }
}
