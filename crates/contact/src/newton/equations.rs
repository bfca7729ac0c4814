//! The natural-map (Alart–Curnier) equations of an affine contact problem and the rows of a
//! generalised Jacobian, in the flat layout `[normal (n); tangential (n·nt)]`.
//!
//! With `u(λ) = u₀ - D W λ - σ λ` (`σ = 0` for the problem itself, `σ > 0` for a proximal
//! step) and `z = λ + c (u(λ) - g̃)` (`g̃ = (g, 0)`), the equations are `λ_n - [z_n]₊ = 0` and
//! `λ_t - P_S(z_t) = 0` at every point. A generalised Jacobian picks, per point, the branch of
//! `z` (separated, stick, slip); each row is `J_r = E_r + B_r C` with `C = c (D W + σ I)` and
//! `E_r`, `B_r` sparse over the point's own components.

use crate::electric::ElectricContact;
use crate::operator::Compliance;
use crate::points::{ContactPoints, Foundation, PointValues};
use crate::projection::DiscPiece;
use crate::Law;

/// One row of the generalised Jacobian, `J_r = E_r + B_r C`: `(index, coefficient)` pairs.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct RowForm {
    pub(super) e: Vec<(usize, f64)>,
    pub(super) b: Vec<(usize, f64)>,
}

impl RowForm {
    /// Whether row `r` is the identity of `y = C δ` (a point in contact and sticking:
    /// `E_r = 0`, `B_r = e_r`).
    pub(super) fn is_c_row(&self, r: usize) -> bool {
        self.e.is_empty() && self.b == [(r, 1.0)]
    }

    /// Whether row `r` is the identity of `δ` (a separated point: `E_r = e_r`, `B_r = 0`).
    pub(super) fn is_identity(&self, r: usize) -> bool {
        self.b.is_empty() && self.e == [(r, 1.0)]
    }
}

/// The pattern of a generalised Jacobian: which entries each row holds (so the branch of every
/// point: in contact or separated, sticking or slipping), hashed. Iterates of one pattern take
/// their Newton steps on the same piece of the equations.
pub(super) fn pattern(rows: &[RowForm]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for row in rows {
        (row.e.len(), row.b.len()).hash(&mut hasher);
        for &(j, _) in row.e.iter().chain(&row.b) {
            j.hash(&mut hasher);
        }
    }
    hasher.finish()
}

/// The floor of the electric residual's denominator, relative to the ideal conductor's flux
/// scale ([`Flat::electric_residual`]).
const ELECTRIC_FLOOR: f64 = 1e-6;

/// An affine contact problem in the flat layout.
#[derive(Clone)]
pub(super) struct Flat<'a> {
    pub(super) d: Compliance<'a>,
    pub(super) points: &'a ContactPoints,
    pub(super) law: &'a Law,
    pub(super) n: usize,
    pub(super) nt: usize,
    pub(super) m: usize,
    /// The natural map's constant of each flat index: `1/μ_max` for the problem itself, one
    /// per point for a proximal problem ([`Flat::proximal`]).
    pub(super) c: Vec<f64>,
    /// `μ_max`, the largest eigenvalue of `D W`.
    pub(super) mu_max: f64,
    /// Weight of each flat index.
    pub(super) w: Vec<f64>,
    /// `u₀` (for a proximal step, `u₀ + σ λ_k`).
    pub(super) u0: Vec<f64>,
    /// The proximal shift `σ` (0 for the problem itself).
    pub(super) sigma: f64,
    /// Slip-weakening friction: at each point with a law of its own, Coulomb's radius with
    /// the coefficient `μ(|u_t|)` of its own slip ([`crate::NewtonParams::weakening`]).
    pub(super) weakening: bool,
    /// Electrical contact: the rows after the mechanical ones.
    pub(super) electric: Option<ElectricRows<'a>>,
    /// Points held in contact whatever their multiplier (their normal row `u_n = g`, an ideal
    /// conductor's electric row `φ = φ_F`): the trial zones of the widest member's search; empty for
    /// the problem itself.
    pub(super) forced: Vec<bool>,
    /// `d`'s relative asymmetry, read once ([`Flat::asymmetry`]; a proximal problem, a clone
    /// with the same `d`, keeps it).
    asymmetry: std::sync::OnceLock<f64>,
}

/// The electric rows of a problem with electrical contact: one per electric point, from
/// `start` (the mechanical rows' count) on.
#[derive(Clone)]
pub(super) struct ElectricRows<'a> {
    pub(super) contact: &'a ElectricContact,
    pub(super) start: usize,
    /// The flux scale of the electric residual, `‖c (φ₀ - φ_F)‖_W`.
    pub(super) reference: f64,
}

/// The equations and their pieces at one `λ`.
#[derive(Clone, Debug)]
pub(super) struct State {
    pub(super) x: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) z: Vec<f64>,
    pub(super) f: Vec<f64>,
    /// Weighted norm of `f`, the line search's merit.
    pub(super) norm: f64,
}

/// `(Σ w_j x_j²)^½`; where the sum of squares would overflow or underflow, scaled by the
/// largest entry first.
pub(super) fn weighted_norm(x: &[f64], w: &[f64]) -> f64 {
    // divided by s: `1/s` overflows for a subnormal s
    let sum = |s: f64| x.iter().zip(w).map(|(v, w)| w * (v / s) * (v / s)).sum::<f64>();
    let plain = sum(1.0);
    if crate::projection::trusted(plain) || x.iter().all(|v| *v == 0.0) {
        return plain.sqrt();
    }
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return if x.iter().any(|v| v.is_nan()) { f64::NAN } else { scale };
    }
    scale * sum(scale).sqrt()
}

impl<'a> Flat<'a> {
    /// The problem `u = u0 - D W λ` on `points` for `law`; `mu_max` the largest eigenvalue
    /// of `D W`, whose inverse is the natural map's constant.
    pub(super) fn new(
        d: Compliance<'a>,
        u0: &PointValues,
        points: &'a ContactPoints,
        law: &'a Law,
        nt: usize,
        mu_max: f64,
    ) -> Self {
        let n = points.len();
        let m = n * (1 + nt);
        let mut flat = Flat {
            d,
            points,
            law,
            n,
            nt,
            m,
            c: vec![],
            mu_max,
            w: (0..m)
                .map(|j| points.weight[if j < n { j } else { (j - n) / nt }])
                .collect(),
            u0: u0.to_flat(),
            sigma: 0.0,
            weakening: false,
            electric: None,
            forced: vec![],
            asymmetry: std::sync::OnceLock::new(),
        };
        flat.c = vec![1.0 / mu_max; m];
        flat
    }

    /// The problem with the electric rows of `contact` after the mechanical ones: `d` the
    /// whole compliance, `phi0` the potentials under the loads alone. Each electric row's
    /// constant is its own, `1/(D_rr w_r)` (within the mechanical rows' range).
    pub(super) fn with_electric(mut self, d: Compliance<'a>, contact: &'a ElectricContact, phi0: &[f64]) -> Self {
        let start = self.m;
        self.d = d;
        self.asymmetry = std::sync::OnceLock::new();
        self.m = start + contact.points.len();
        self.w.extend(contact.points.iter().map(|&i| self.points.weight[i]));
        self.u0.extend_from_slice(phi0);
        for r in start..self.m {
            let own = self
                .d
                .row(r)
                .find(|(col, _)| *col == r)
                .map_or(0.0, |(_, v)| v * self.w[r]);
            self.c.push(self.local_constant(own));
        }
        let free: Vec<f64> = (start..self.m)
            .map(|r| self.c[r] * (self.u0[r] - contact.potential))
            .collect();
        let reference = weighted_norm(&free, &self.w[start..]);
        self.electric = Some(ElectricRows {
            contact,
            start,
            reference,
        });
        self
    }

    /// The compliance's largest relative asymmetry ([`Compliance::asymmetry`], an `m²` pass),
    /// computed on the first call.
    pub(super) fn asymmetry(&self) -> f64 {
        *self.asymmetry.get_or_init(|| self.d.asymmetry())
    }

    /// The asymmetry where it was computed (or given), without computing it.
    pub(super) fn known_asymmetry(&self) -> Option<f64> {
        self.asymmetry.get().copied()
    }

    /// Gives the compliance's asymmetry, known from an earlier solve of the same `D`.
    pub(super) fn know_asymmetry(&mut self, asymmetry: f64) {
        let _ = self.asymmetry.set(asymmetry);
    }

    /// The natural map's constant of a row whose own compliance is `own`: its inverse, within
    /// `[1/μ_max, 10⁸/μ_max]`.
    fn local_constant(&self, own: f64) -> f64 {
        (1.0 / own.abs()).clamp(1.0 / self.mu_max, 1e8 / self.mu_max)
    }

    /// The mechanical rows' count.
    pub(super) fn mechanical(&self) -> usize {
        self.n * (1 + self.nt)
    }

    /// The electric residual of `s`: the weighted norm of the electric equations relative to
    /// the flux's, `‖f_e‖_W / max(‖q‖_W, 10⁻⁶ reference)`; 0 without electric rows.
    pub(super) fn electric_residual(&self, s: &State) -> f64 {
        let Some(e) = &self.electric else {
            return 0.0;
        };
        let rows = e.start..self.m;
        let num = weighted_norm(&s.f[rows.clone()], &self.w[rows.clone()]);
        // relative to the flux itself: a poor conductor's flux is far below the ideal
        // conductor's scale, and must be known to its own digits; the floor, a millionth of
        // that scale, keeps a vanishing flux reachable
        let den = weighted_norm(&s.x[rows.clone()], &self.w[rows]).max(ELECTRIC_FLOOR * e.reference);
        if den > 0.0 {
            num / den
        } else {
            num
        }
    }

    /// The flux of the electric rows with the mechanical multipliers of `x` held (its
    /// electric part ignored): the electric law is then linear in the flux. `None` where the
    /// linear system is singular.
    pub(super) fn electric_given_mechanics(&self, x: &[f64]) -> Option<Vec<f64>> {
        let e = self.electric.as_ref()?;
        let Compliance::Dense(d) = self.d else {
            return None;
        };
        let (m, start) = (self.m, e.start);
        let ne = m - start;
        let mut held = x.to_vec();
        held[start..].iter_mut().for_each(|v| *v = 0.0);
        let s = self.state(held);
        // at no flux: φ = φ(λ); with the flux, φ - D_ee W q
        let mut a = faer::Mat::<f64>::zeros(ne, ne);
        let mut rhs = faer::Mat::<f64>::zeros(ne, 1);
        for (k, &i) in e.contact.points.iter().enumerate() {
            let r = start + k;
            let (p, contact) = self.contact_of(i, &s.u, &s.z);
            let du = s.u[r] - e.contact.potential;
            let (diag, coupled, b) = match e.contact.law {
                crate::ElectricLaw::Conductive { conductance } => {
                    let sp = conductance * crate::project_nonnegative(p);
                    (1.0, sp, sp * du)
                }
                crate::ElectricLaw::Conducting if contact => (0.0, 1.0, du),
                crate::ElectricLaw::Conducting => (1.0, 0.0, 0.0),
            };
            for l in 0..ne {
                a[(k, l)] = coupled * d[r * m + start + l] * self.w[start + l];
            }
            a[(k, k)] += diag;
            rhs[(k, 0)] = b;
        }
        let lu = a.partial_piv_lu();
        faer::linalg::solvers::SolveCore::solve_in_place_with_conj(&lu, faer::Conj::No, rhs.as_mut());
        let q: Vec<f64> = (0..ne).map(|k| rhs[(k, 0)]).collect();
        q.iter().all(|v| v.is_finite()).then_some(q)
    }

    /// Point `i`'s `p` for the electric law and its contact status: on a rigid foundation
    /// the augmented `z_n` (whose `[z_n]₊` is the pressure `λ_n` at a solution, as for
    /// Coulomb's radius: from the start, a point pressed in conducts, and the derivative sees
    /// it), on a compliant one the penetration.
    fn contact_of(&self, i: usize, s_u: &[f64], s_z: &[f64]) -> (f64, bool) {
        match self.points.foundation_of(i) {
            Foundation::Rigid => (s_z[i], s_z[i] > 0.0 || self.is_forced(i)),
            Foundation::Compliant { .. } => {
                let pen = s_u[i] - self.points.gap[i];
                (pen, pen > 0.0)
            }
        }
    }

    /// Whether point `i` is held in contact ([`Flat::forced`]).
    fn is_forced(&self, i: usize) -> bool {
        self.forced.get(i).copied().unwrap_or(false)
    }

    /// The flat indices of point `i`'s components.
    pub(super) fn indices(&self, i: usize) -> impl Iterator<Item = usize> {
        let layout = self.layout();
        (0..=self.nt).map(move |k| layout.index(i, k))
    }

    /// The flat layout `[normal (n); tangential (n·nt)]`.
    pub(super) fn layout(&self) -> crate::points::Flat {
        crate::points::Flat { n: self.n, nt: self.nt }
    }

    /// The natural map's constant per flat index: `1/‖B_i‖_F` for point `i`, `B_i` its
    /// diagonal block of `D W + σ I` (Alart and Curnier's `r`, per contact as Siconos' split
    /// spectral rule chooses it). A global `1/μ_max` leaves the Jacobian's rows of a point
    /// whose own compliance is far below `μ_max` nearly zero, and Newton's directions long and
    /// poor; the local choice makes each point's rows of order one.
    fn constants(&self) -> Vec<f64> {
        let mut c = vec![0.0; self.m];
        for i in 0..self.n {
            let rows: Vec<usize> = self.indices(i).collect();
            let mut sum = 0.0;
            for &r in &rows {
                for (col, v) in self.d.row(r) {
                    if rows.contains(&col) {
                        let e = v * self.w[col] + if col == r { self.sigma } else { 0.0 };
                        sum += e * e;
                    }
                }
            }
            let local = self.local_constant(sum.sqrt());
            for &r in &rows {
                c[r] = local;
            }
        }
        for r in self.mechanical()..self.m {
            let own = self
                .d
                .row(r)
                .find(|(col, _)| *col == r)
                .map_or(0.0, |(_, v)| v * self.w[r]);
            c[r] = self.local_constant(own + self.sigma);
        }
        c
    }

    /// The mean of the diagonal of `D W`: the size of a point's own compliance.
    pub(super) fn mean_diagonal(&self) -> f64 {
        let sum: f64 = (0..self.m)
            .map(|r| self.d.row(r).find(|(c, _)| *c == r).map_or(0.0, |(_, v)| v * self.w[r]))
            .sum();
        if sum > 0.0 {
            sum / self.m as f64
        } else {
            self.mu_max
        }
    }

    /// The proximal problem about `center`: `u_σ(λ) = u(λ) - σ (λ - center)`, with the natural
    /// map's constants per point.
    pub(super) fn proximal(&self, sigma: f64, center: &[f64]) -> Self {
        let mut p = self.clone();
        p.sigma = self.sigma + sigma;
        for (u, x) in p.u0.iter_mut().zip(center) {
            *u += sigma * x;
        }
        p.c = p.constants();
        p
    }

    /// The radius of point `i` at `z` (the multipliers `x`): Tresca `S`, Coulomb `F [z_n]₊`
    /// on a rigid foundation, `F [λ_n]₊` on a compliant one (whose `λ_n` is the pressure).
    pub(super) fn radius(&self, i: usize, z: &[f64], x: &[f64], u: &[f64]) -> f64 {
        let normal = self.radius_normal(i, z, x);
        match self.weakening_of(i) {
            Some(w) => crate::coulomb_radius(w.coefficient(self.points.slipped(i) + self.slip(i, u)), normal),
            None => self.law.radius(self.points, i, normal),
        }
    }

    /// Point `i`'s slip-weakening law where the problem solves it directly.
    fn weakening_of(&self, i: usize) -> Option<&crate::SlipWeakening> {
        self.points.weakening_of(i).filter(|_| self.weakening)
    }

    /// The normal value Coulomb's radius is taken at: `z_n` on a rigid foundation, the
    /// pressure `x_n` on a compliant one.
    fn radius_normal(&self, i: usize, z: &[f64], x: &[f64]) -> f64 {
        self.points.foundation_of(i).radius_normal(z[i], x[i])
    }

    /// The slip `|u_t|` of point `i` in the flat `u`.
    fn slip(&self, i: usize, u: &[f64]) -> f64 {
        if self.nt == 0 {
            return 0.0;
        }
        let t = self.layout().index(i, 1);
        crate::projection::norm(&u[t..t + self.nt])
    }

    pub(super) fn state(&self, x: Vec<f64>) -> State {
        let m = self.m;
        let wx: Vec<f64> = x.iter().zip(&self.w).map(|(a, b)| a * b).collect();
        let mut u = vec![0.0; m];
        self.d.apply(&wx, &mut u);
        let mut z = vec![0.0; m];
        let potential = self.electric.as_ref().map_or(0.0, |e| e.contact.potential);
        let mechanical = self.mechanical();
        for r in 0..m {
            u[r] = self.u0[r] - u[r] - self.sigma * x[r];
            let g = if r < self.n {
                self.points.gap[r]
            } else if r >= mechanical {
                potential
            } else {
                0.0
            };
            z[r] = x[r] + self.c[r] * (u[r] - g);
        }
        let mut f = vec![0.0; m];
        let mut buf = [0.0; 2];
        for i in 0..self.n {
            f[i] = if self.is_forced(i) {
                // held in contact: u_n = g, in the natural map's units
                -self.c[i] * (u[i] - self.points.gap[i])
            } else {
                self.points
                    .foundation_of(i)
                    .normal_residual(x[i], u[i] - self.points.gap[i], self.c[i])
            };
            if self.nt > 0 {
                let t = self.layout().index(i, 1);
                buf[..self.nt].copy_from_slice(&z[t..t + self.nt]);
                self.points
                    .project_friction(i, &mut buf[..self.nt], self.radius(i, &z, &x, &u));
                for k in 0..self.nt {
                    f[t + k] = x[t + k] - buf[k];
                }
            }
        }
        if let Some(e) = &self.electric {
            for (k, &i) in e.contact.points.iter().enumerate() {
                let r = e.start + k;
                let (p, contact) = self.contact_of(i, &u, &z);
                f[r] = e.contact.row(x[r], u[r], self.c[r], p, contact).f;
            }
        }
        let norm = weighted_norm(&f, &self.w);
        State { x, u, z, f, norm }
    }

    /// The rows of a generalised Jacobian at `s`, each as `J_r = E_r + B_r C` with
    /// `C = diag(c) (D W + σ I)` (so that `M = I - C` is the derivative of `z`).
    pub(super) fn rows(&self, s: &State) -> Vec<RowForm> {
        let (n, nt) = (self.n, self.nt);
        let mut rows = vec![RowForm::default(); self.m];
        for i in 0..n {
            let penetration = s.u[i] - self.points.gap[i];
            match self.points.foundation_of(i).equation(s.x[i], penetration, self.c[i]) {
                // normal: [z_n]₊ has derivative 1 (contact: J = C) or 0 (separated: J = I)
                None if s.z[i] > 0.0 || self.is_forced(i) => rows[i].b.push((i, 1.0)),
                None => rows[i].e.push((i, 1.0)),
                // (λ_n - k [u_n - g]₊^m) / s, with ∂u/∂λ = -(D W + σ I) = -C / c and the scale
                // s held: J = (I + (k'/c) C) / s
                Some((_, scale, slope)) => {
                    rows[i].e.push((i, 1.0 / scale));
                    if slope > 0.0 {
                        rows[i].b.push((i, slope / (self.c[i] * scale)));
                    }
                }
            }
            if nt == 0 {
                continue;
            }
            let t = self.layout().index(i, 1);
            // the projection sees the free directions only (a held one's multiplier is 0)
            let mut held_out = [0.0; 2];
            held_out[..nt].copy_from_slice(&s.z[t..t + nt]);
            self.points.hold(i, &mut held_out[..nt]);
            let q = &held_out[..nt];
            let radius = self.radius(i, &s.z, &s.x, &s.u);
            // slip weakening: the coefficient at the point's slip, and its slope there
            // (at what it slipped before the problem and its slip in it)
            let slip = self.slip(i, &s.u);
            let total = self.points.slipped(i) + slip;
            let (coefficient, weakens) = match self.weakening_of(i) {
                Some(w) => (w.coefficient(total), w.slope(total)),
                None => (self.points.friction[i], 0.0),
            };
            let piece = crate::projection::disc_piece(q, radius);
            for k in 0..nt {
                let row = &mut rows[t + k];
                if self.points.is_held(i, k) {
                    // λ_t,k = 0: the identity
                    row.e.push((t + k, 1.0));
                    continue;
                }
                match piece {
                    // λ_t - z_t: derivative C
                    DiscPiece::Inside => row.b.push((t + k, 1.0)),
                    // λ_t - P_0(z_t) = λ_t (a zero radius): the identity
                    DiscPiece::Zero => row.e.push((t + k, 1.0)),
                    DiscPiece::Boundary { ratio, direction: d } => {
                        // λ_t - S q/|q|: derivative I - (S/|q|)(I - q̂q̂ᵀ) M_t - q̂ dS, with
                        // dS = F M_n for Coulomb at a contact point (q̂ = d, S/|q| = ratio)
                        let rigid = self.points.foundation_of(i) == Foundation::Rigid;
                        // the normal value the radius is taken at, in contact where positive
                        let normal = crate::project_nonnegative(self.radius_normal(i, &s.z, &s.x));
                        let slope = match self.law {
                            Law::Coulomb if normal > 0.0 => coefficient,
                            _ => 0.0,
                        };
                        row.e.push((t + k, 1.0));
                        for l in (0..nt).filter(|&l| !self.points.is_held(i, l)) {
                            let proj = if k == l { 1.0 } else { 0.0 } - d[k] * d[l];
                            if proj != 0.0 {
                                row.e.push((t + l, -ratio * proj));
                                row.b.push((t + l, ratio * proj));
                            }
                        }
                        if slope > 0.0 {
                            // dS = F M_n = F (I - C)_n on a rigid foundation (S = F [z_n]₊),
                            // F e_n on a compliant one (S = F λ_n)
                            row.e.push((i, -d[k] * slope));
                            if rigid {
                                row.b.push((i, d[k] * slope));
                            }
                        }
                        // slip weakening: dS ∋ [n]₊ μ'(s) û_t · du_t, with du = -(C δ) / c
                        if weakens != 0.0 && slip > 0.0 && normal > 0.0 {
                            for l in (0..nt).filter(|&l| !self.points.is_held(i, l)) {
                                let u_hat = s.u[t + l] / slip;
                                let v = d[k] * normal * weakens * u_hat / self.c[t + l];
                                if v != 0.0 {
                                    row.b.push((t + l, v));
                                }
                            }
                        }
                    }
                }
            }
        }
        self.electric_rows(s, &mut rows);
        rows
    }

    /// The electric rows of the generalised Jacobian at `s` (none without electrical contact).
    fn electric_rows(&self, s: &State, rows: &mut [RowForm]) {
        let Some(e) = &self.electric else {
            return;
        };
        for (k, &i) in e.contact.points.iter().enumerate() {
            let r = e.start + k;
            let (p, contact) = self.contact_of(i, &s.u, &s.z);
            let row = e.contact.row(s.x[r], s.u[r], self.c[r], p, contact);
            let form = &mut rows[r];
            if row.identity != 0.0 {
                form.e.push((r, row.identity));
            }
            if row.along_c != 0.0 {
                form.b.push((r, row.along_c));
            }
            if row.along_p != 0.0 {
                match self.points.foundation_of(i) {
                    // p = [z_n]₊: ∂p = (I - C)_i
                    Foundation::Rigid => {
                        form.e.push((i, row.along_p));
                        form.b.push((i, -row.along_p));
                    }
                    // p = u_n - g: ∂p = -C_i / c_i
                    Foundation::Compliant { .. } => form.b.push((i, -row.along_p / self.c[i])),
                }
            }
        }
    }

    /// The mechanical part of flat values as [`PointValues`].
    pub(super) fn values(&self, x: &[f64]) -> PointValues {
        PointValues::from_flat(&x[..self.mechanical()], self.n, self.nt)
    }
}
