//! Exact solutions for verification: a smooth solution `(u, φ)` given with its first and second
//! derivatives, the body force and charge that make it solve the coupled equations
//! (manufactured solutions, Roache 2002), the Dirichlet data it prescribes, and the errors of a
//! discrete solution against it in the L2 and energy norms.
//!
//! The equations (signs of docs/theory.md): `-div σ = f0`, `div D = q0`, with
//! `σ = C ε(u) + eᵀ ∇φ` and `D = e ε(u) - β ∇φ`. So, in index form,
//! `f0_i = -Σ_jkl C_ijkl ∂_jl u_k - Σ_jk e_kij ∂_jk φ` and
//! `q0 = Σ_ikl e_ikl ∂_il u_k - Σ_ik β_ik ∂_ik φ`.

use crate::{kernels, voigt, Constraint, Discretization, Field, Load, Material};
use std::f64::consts::PI;
use std::sync::Arc;

/// The law of the contact face of [`Exact::on_foundation`]: the bed under it, its electric
/// condition and its friction, with the constants of the material (a 6mm crystal poled along
/// the normal) that make the face's pressure, flux and shear.
#[derive(Clone)]
pub struct Face {
    /// The material's constants.
    pub constants: FaceConstants,
    /// A deformable foundation, normal compliance `λ_n = k [u_n - g]₊^m`: `(k, m)`; `None`
    /// for a rigid one.
    pub bed: Option<(f64, f64)>,
    /// The electric condition of the face.
    pub electric: FaceElectric,
    /// The face slides along the first tangent (`None`: it sticks).
    pub sliding: Option<Sliding>,
}

/// The constants of a 6mm crystal poled along the normal of [`Exact::on_foundation`]'s face.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceConstants {
    /// `c33`, along the normal.
    pub c33: f64,
    /// `c13`, the normal stress of a tangential strain.
    pub c13: f64,
    /// `c44`, the shear across the face.
    pub c44: f64,
    /// `e33`.
    pub e33: f64,
    /// `e31`.
    pub e31: f64,
    /// `ε33`, the permittivity along the normal.
    pub eps33: f64,
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

/// The coefficient of friction at a slip `s`, with its first two derivatives in `s`.
pub type FrictionFn = Arc<dyn Fn(f64) -> [f64; 3] + Send + Sync>;

/// A face that slides along the first tangent by `U(t₀) = A (1 + sin(π t₀ / 2) / 2)`, its
/// shear the friction law's `μ(U) λ_n` along the slip.
#[derive(Clone)]
pub struct Sliding {
    /// `A > 0`.
    pub amplitude: f64,
    /// `μ(s)`, `μ'(s)`, `μ''(s)`: the law's coefficient at the slip `s`.
    pub friction: FrictionFn,
}

/// `a0 + a1 sin(h t) + a2 cos(h t)` with `h = π/2`, and its derivatives.
#[derive(Clone, Copy, Debug)]
struct Trig([f64; 3]);

impl Trig {
    /// The value and the first three derivatives at `t`.
    fn at(self, t: f64) -> [f64; 4] {
        let h = PI / 2.0;
        let [a0, a1, a2] = self.0;
        let (sn, cs) = ((h * t).sin(), (h * t).cos());
        [
            a0 + a1 * sn + a2 * cs,
            h * (a1 * cs - a2 * sn),
            -h * h * (a1 * sn + a2 * cs),
            -h * h * h * (a1 * cs - a2 * sn),
        ]
    }
}

/// The tangential jets of [`Exact::on_foundation`]'s sticking face:
/// `u_k = 10⁻³ s sin(π t_k / 2 + 0.3)`.
fn sticking(x: &[f64], s: f64, n: usize, out: &mut [Jet; 3]) {
    let h = PI / 2.0;
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
}

/// The tangential jets of [`Exact::on_foundation`]'s sliding face: `u_0 = U + s W`,
/// `W = μ(U) λ_n / c44 + ∂_0 (g + δ)`, and in 3D `u_1 = s κ (t_1 - c_1)`; `l` and `pen` the
/// pressure's and the penetration's derivatives in `t_0`.
fn sliding_face(
    x: &[f64],
    s: f64,
    (dim, c44): (usize, f64),
    (slip, law, l, pen): (Trig, &Sliding, [f64; 4], [f64; 4]),
    (curvature, center): (f64, [f64; 3]),
    out: &mut [Jet; 3],
) {
    let n = dim - 1;
    let u = slip.at(x[0]);
    let [mu, dmu, ddmu] = (law.friction)(u[0]);
    // μ(U(t)) and its derivatives in t
    let m = [mu, dmu * u[1], ddmu * u[1] * u[1] + dmu * u[2]];
    let w = [
        m[0] * l[0] / c44 + curvature * (x[0] - center[0]) + pen[1],
        (m[1] * l[0] + m[0] * l[1]) / c44 + curvature + pen[2],
        (m[2] * l[0] + 2.0 * m[1] * l[1] + m[0] * l[2]) / c44 + pen[3],
    ];
    let mut g = [0.0; 3];
    let mut hh = [[0.0; 3]; 3];
    g[0] = u[1] + s * w[1];
    g[n] = w[0];
    hh[0][0] = u[2] + s * w[2];
    hh[0][n] = w[1];
    hh[n][0] = w[1];
    out[0] = (u[0] + s * w[0], g, hh);
    if dim == 3 {
        let mut g = [0.0; 3];
        let mut hh = [[0.0; 3]; 3];
        g[1] = s * curvature;
        g[n] = curvature * (x[1] - center[1]);
        hh[1][n] = curvature;
        hh[n][1] = curvature;
        out[1] = (s * curvature * (x[1] - center[1]), g, hh);
    }
}

/// `l^r` with its first three derivatives from those of `l`.
fn power([l, dl, ddl, dddl]: [f64; 4], r: f64) -> [f64; 4] {
    let p = |k: f64| l.powf(r - k);
    [
        p(0.0),
        r * p(1.0) * dl,
        r * (r - 1.0) * p(2.0) * dl * dl + r * p(1.0) * ddl,
        r * (r - 1.0) * (r - 2.0) * p(3.0) * dl.powi(3) + 3.0 * r * (r - 1.0) * p(2.0) * dl * ddl + r * p(1.0) * dddl,
    ]
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
    /// tangential coordinates) and whose potential is `φ_F`. With `s = x_n - s0`,
    /// `E(t) = 10⁻² + 10⁻³ sin(π t₀ / 2)` and `U(t₀)` the face's slip (0 where it sticks):
    /// - `u_n = -g(t) - δ(t) - s E(t)` (`ε_nn = -E`: a compression; `δ` the penetration into
    ///   the bed, 0 on a rigid foundation);
    /// - sticking: `u_k = 10⁻³ s sin(π t_k / 2 + 0.3)` (`k < n`: no slip on the face);
    /// - sliding along the first tangent: `u_0 = U + s W` with
    ///   `W = μ(U) λ_n / c44 + ∂_0 (g + δ)`, so that the face's shear
    ///   `σ_0n = c44 (∂_0 u_n + ∂_s u_0) = μ(U) λ_n` is the friction law's along the slip, and
    ///   in 3D `u_1 = s κ (t_1 - c_1)` (no shear across the slip);
    /// - the potential by the face's electric condition: conducting,
    ///   `φ = φ_F + s (10⁻² + 5·10⁻³ cos(π t₀ / 2))`; conductive, `φ = φ_F + a + s Q(t₀)` with
    ///   `Q` the slope that makes the flux the law's. On the face the fields give the pressure
    ///   `λ_n = -σ_nn = c33 E - e33 Q - c13 U'` and the flux `D·ν = e33 E + ε33 Q - e31 U'`, so
    ///   `D·ν = σ' a λ_n` (`σ' = σ_c`, or `σ_c / k` on a linear bed, whose penetration is
    ///   `λ_n / k`) gives `Q = ((σ' a c33 - e33) E + (e31 - σ' a c13) U') / (ε33 + σ' a e33)`;
    ///   `σ_c = 0` is the insulated face. (On a bed with `m ≠ 1` the penetration is not linear
    ///   in the pressure and `Q` has no closed form: there `σ_c` must be 0.)
    ///
    /// On a bed the face sinks by `δ = (λ_n / k)^(1/m)`. Whether the pressure is positive and,
    /// on a sticking face, the shear within the friction bound depends on the material and the
    /// coefficient: the caller checks the run's status.
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
        let k = face.constants;
        let e = Trig([delta, b, 0.0]);
        let amplitude = face.sliding.as_ref().map_or(0.0, |sl| sl.amplitude);
        let slip = Trig([amplitude, 0.5 * amplitude, 0.0]);
        // U' = A h cos / 2, as a Trig
        let slip_rate = [0.0, 0.0, 0.5 * amplitude * h];
        // ∂_s φ on the face, and the face's potential
        let (slope, face_phi) = match face.electric {
            FaceElectric::Conducting => (Trig([1e-2, 0.0, 5e-3]), phi_f),
            FaceElectric::Conductive { conductance, offset } => {
                let sigma = conductance / face.bed.map_or(1.0, |(stiffness, _)| stiffness) * offset;
                let d = k.eps33 + sigma * k.e33;
                let (from_e, from_u) = ((sigma * k.c33 - k.e33) / d, (k.e31 - sigma * k.c13) / d);
                let q = [0, 1, 2].map(|j| from_e * e.0[j] + from_u * slip_rate[j]);
                (Trig(q), phi_f + offset)
            }
        };
        let pressure = Trig([0, 1, 2].map(|j| k.c33 * e.0[j] - k.e33 * slope.0[j] - k.c13 * slip_rate[j]));
        // the penetration into the bed, with its derivatives in t_0
        let penetration = move |t0: f64| -> [f64; 4] {
            match face.bed {
                None => [0.0; 4],
                Some((stiffness, m)) => power(pressure.at(t0).map(|v| v / stiffness), 1.0 / m),
            }
        };
        let sliding = face.sliding.clone();
        Exact {
            dim,
            u: Arc::new(move |x| {
                let s = x[n] - s0;
                let mut out = [(0.0, [0.0; 3], [[0.0; 3]; 3]); 3];
                let pen = penetration(x[0]);
                match &sliding {
                    None => sticking(x, s, n, &mut out),
                    Some(sl) => {
                        let l = pressure.at(x[0]);
                        sliding_face(x, s, (dim, k.c44), (slip, sl, l, pen), (curvature, center), &mut out);
                    }
                }
                let ev = e.at(x[0]);
                let gap = g0 + pen[0] + 0.5 * curvature * (0..n).map(|k| (x[k] - center[k]).powi(2)).sum::<f64>();
                let mut g = [0.0; 3];
                let mut hh = [[0.0; 3]; 3];
                for k in 0..n {
                    g[k] = -curvature * (x[k] - center[k]);
                    hh[k][k] = -curvature;
                }
                g[0] -= pen[1] + s * ev[1];
                hh[0][0] -= pen[2] + s * ev[2];
                g[n] = -ev[0];
                hh[0][n] = -ev[1];
                hh[n][0] = -ev[1];
                out[n] = (-gap - s * ev[0], g, hh);
                out
            }),
            phi: Arc::new(move |x| {
                let s = x[n] - s0;
                let [value, dvalue, ddvalue, _] = slope.at(x[0]);
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
    /// The norms of squared integrals summed over parts of a mesh (the [`ErrorNorms::squares`]
    /// of each part, added): the squares of the errors' three norms, then of the exact
    /// solution's.
    pub fn from_squares(sq: &[f64]) -> ErrorNorms {
        let r = |k: usize| sq.get(k).copied().unwrap_or(0.0).sqrt();
        ErrorNorms {
            l2_u: r(0),
            l2_phi: r(1),
            energy: r(2),
            norms: (r(3), r(4), r(5)),
        }
    }

    /// The squares of the six norms, to be summed over the parts of a mesh
    /// ([`ErrorNorms::from_squares`]).
    pub fn squares(&self) -> [f64; 6] {
        [
            self.l2_u,
            self.l2_phi,
            self.energy,
            self.norms.0,
            self.norms.1,
            self.norms.2,
        ]
        .map(|x| x * x)
    }

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
    /// gives them) against `exact`, by a rule on each cell of degree 2 with P1 (exact for the
    /// square of a P1 function; for the smooth part, accurate to `O(h³)` relative, enough for
    /// rates) and of degree 4 on triangles, 3 on tetrahedra with P2.
    pub fn error_norms(&self, u: &[[f64; 3]], phi: &[f64], exact: &Exact) -> ErrorNorms {
        self.error_norms_on(u, phi, exact, 0..self.mesh.n_cells())
    }

    /// [`Discretization::error_norms`] over the cells `cells` alone (a rank's own cells of a
    /// mesh in pieces: their [`ErrorNorms::squares`] summed over the ranks are the whole
    /// mesh's).
    pub fn error_norms_on(
        &self,
        u: &[[f64; 3]],
        phi: &[f64],
        exact: &Exact,
        cells: impl Iterator<Item = usize>,
    ) -> ErrorNorms {
        let (mesh, dim) = (self.mesh, self.mesh.dim);
        let order = mesh.kind.order();
        let (weights, rule) = kernels::simplex_rule(dim, order);
        let shapes: Vec<_> = rule.iter().map(|l| kernels::shape_values(dim, order, l)).collect();
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
        for c in cells {
            let cell = mesh.cell(c);
            let m = &self.materials[self.cell_material[c]];
            let ul: Vec<[f64; 3]> = cell.iter().map(|&v| u[v]).collect();
            let pl: Vec<f64> = cell.iter().map(|&v| phi[v]).collect();
            // a P1 cell's strain and gradient are its centroid's
            let centroid = self.centroid_rule(c);
            let at_centroid = (
                kernels::strain_at(dim, &centroid, 0, &ul),
                kernels::gradient_at(dim, &centroid, 0, &pl),
            );
            for ((bary, n), weight) in rule.iter().zip(&shapes).zip(weights) {
                let (x, measure) = self.cell_point(c, bary);
                let w = measure * weight;
                let (eps_h, gp_h) = match order {
                    2 => {
                        let r = self.quadratic_rule_at(c, &[*bary], &[1.0], true);
                        (
                            kernels::strain_at(dim, &r, 0, &ul),
                            kernels::gradient_at(dim, &r, 0, &pl),
                        )
                    }
                    _ => at_centroid,
                };
                let (mut uh, mut ph) = ([0.0; 3], 0.0);
                for (a, &v) in cell.iter().enumerate() {
                    for k in 0..3 {
                        uh[k] += n[a] * u[v][k];
                    }
                    ph += n[a] * phi[v];
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

    /// Faces of every kind: rigid and on beds (linear, `m = 2.5`), conducting, conductive and
    /// insulated, sticking, sliding under Coulomb's law and under an exponential weakening
    /// (not the conductive face on a nonlinear bed: no closed form).
    fn faces() -> Vec<Face> {
        let constants = FaceConstants {
            c33: 111.0,
            c13: 75.2,
            c44: 21.1,
            e33: 15.8,
            e31: -5.4,
            eps33: 7.35,
        };
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
        let (ms, md, l) = (0.6, 0.2, 1.5e-3);
        let weakening: FrictionFn = Arc::new(move |s: f64| {
            let x = (-s / l).exp();
            [md + (ms - md) * x, -(ms - md) / l * x, (ms - md) / (l * l) * x]
        });
        let slides = [
            None,
            Some(Sliding {
                amplitude: 2e-3,
                friction: Arc::new(|_| [0.3, 0.0, 0.0]),
            }),
            Some(Sliding {
                amplitude: 1e-3,
                friction: weakening,
            }),
        ];
        let mut out = vec![];
        for bed in beds {
            for electric in electric {
                let nonlinear = bed.is_some_and(|(_, m)| m != 1.0);
                if nonlinear && matches!(electric, FaceElectric::Conductive { conductance, .. } if conductance > 0.0) {
                    continue;
                }
                for sliding in slides.clone() {
                    out.push(Face {
                        constants,
                        bed,
                        electric,
                        sliding,
                    });
                }
            }
        }
        out
    }

    /// The first and second derivatives of `e`'s jets at `x` against central differences.
    fn jets_match_differences(e: &Exact, x: [f64; 3]) {
        let dim = e.dim;
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
    }

    /// The jets of the solution on a foundation against central differences, in 2D and 3D,
    /// rigid and on beds, conducting, conductive and insulated, sticking and sliding; and its
    /// contact face's values: the gap's normal displacement (and the bed's penetration
    /// `(λ_n/k)^(1/m)`), the slip, the face's potential, the conductive law's flux
    /// `σ_c p (φ - φ_F)`, and a sliding face's shear `μ(U) λ_n`.
    #[test]
    fn the_foundation_solution_has_consistent_jets_and_its_face_law() {
        for dim in [2, 3] {
            for face in faces() {
                let (constants, bed, electric, sliding) =
                    (face.constants, face.bed, face.electric, face.sliding.clone());
                let e = Exact::on_foundation(dim, 0.1, (0.02, 0.3, [1.0, 0.5, 0.0]), 0.04, face);
                let x = [0.3, 0.7, 0.45];
                jets_match_differences(&e, x);
                let jets = |x: &[f64]| {
                    let u = (e.u)(x);
                    let mut all: Vec<Jet> = u[..dim].to_vec();
                    all.push((e.phi)(x));
                    all
                };
                // on the face x_n = 0.1
                let mut y = x;
                y[dim - 1] = 0.1;
                let face_jets = jets(&y);
                let gap = 0.02 + 0.15 * (0..dim - 1).map(|k| (y[k] - [1.0, 0.5][k]).powi(2)).sum::<f64>();
                // the pressure, flux and shear from the jets (the face's tangential strain is
                // ε_00 = U' alone)
                let n = dim - 1;
                let eps_tt: f64 = (0..n).map(|k| face_jets[k].1[k]).sum();
                let (eps_nn, phi_n) = (face_jets[n].1[n], face_jets[dim].1[n]);
                let pressure = -(constants.c13 * eps_tt + constants.c33 * eps_nn + constants.e33 * phi_n);
                let flux = -(constants.e31 * eps_tt + constants.e33 * eps_nn - constants.eps33 * phi_n);
                let shear = |k: usize| constants.c44 * (face_jets[n].1[k] + face_jets[k].1[n]);
                assert!(pressure > 0.0);
                let sink = bed.map_or(0.0, |(k, m)| (pressure / k).powf(1.0 / m));
                assert!((-face_jets[n].0 - gap - sink).abs() < 1e-15);
                assert!(
                    (0..dim).all(|k| face_jets[dim].1[k] == 0.0 || k == n),
                    "the face is equipotential"
                );
                match &sliding {
                    None => assert!((0..n).all(|k| face_jets[k].0 == 0.0)),
                    Some(sl) => {
                        let u = face_jets[0].0;
                        assert!((u - sl.amplitude * (1.0 + 0.5 * (PI / 2.0 * y[0]).sin())).abs() < 1e-15);
                        let mu = (sl.friction)(u)[0];
                        assert!(
                            (shear(0) - mu * pressure).abs() < 1e-12,
                            "{} {}",
                            shear(0),
                            mu * pressure
                        );
                        assert!(n == 1 || (face_jets[1].0 == 0.0 && shear(1).abs() < 1e-14));
                    }
                }
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
