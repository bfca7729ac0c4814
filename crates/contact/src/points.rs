//! Contact points and the multiplier / displacement vectors on them.

use crate::ContactError;
use crate::InputError;

/// The contact points: geometry, weights, gaps and friction coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPoints {
    /// Spatial dimension (2 or 3): each point has 1 normal and `dim - 1` tangential components.
    pub dim: usize,
    /// Positions.
    pub position: Vec<[f64; 3]>,
    /// Outward unit normals of the body.
    pub normal: Vec<[f64; 3]>,
    /// Tangent bases (`dim - 1` unit vectors used).
    pub tangent: Vec<[[f64; 3]; 2]>,
    /// Weights (lumped boundary mass).
    pub weight: Vec<f64>,
    /// Initial gaps `g` (`u_n ≤ g`).
    pub gap: Vec<f64>,
    /// Coulomb coefficients `F`.
    pub friction: Vec<f64>,
    /// The tangential directions of each point that a support holds (a Dirichlet condition on
    /// that component of the body's motion): the multiplier there is 0, the support taking the
    /// force, and the law acts in the other directions. `[false; 2]` where the point may slide
    /// in every direction; only the first `dim - 1` entries are read.
    pub held: Vec<[bool; 2]>,
    /// What the points press on: a rigid foundation (Signorini's conditions) or a deformable
    /// one (normal compliance); each point's own where [`ContactPoints::foundations`] gives
    /// it.
    pub foundation: Foundation,
    /// Each point's foundation where they differ (zones on different foundations: a compliant
    /// bed beside a rigid wall). Empty: every point's is [`ContactPoints::foundation`].
    pub foundations: Vec<Foundation>,
    /// The slip each point has accumulated before this problem (the earlier steps of a load
    /// path): slip-weakening friction takes its coefficient at this plus the problem's own
    /// slip `|u_t|`. Empty: none (zeros).
    pub slipped: Vec<f64>,
    /// Each point's slip-weakening law, where its coefficient falls with its slip
    /// ([`crate::solve_slip_weakening`]; `None`: its `friction` is its constant coefficient).
    /// Empty: no point weakens.
    pub weakening: Vec<Option<crate::SlipWeakening>>,
    /// Each point's Tresca bound where its zone's law is Tresca's beside zones of Coulomb's
    /// (the problem's law then Coulomb's): its slip radius is that constant whatever its normal
    /// value, its coefficient `friction` not read (0). `None`: Coulomb's radius. Empty: none.
    pub tresca: Vec<Option<f64>>,
}

/// The foundation under the contact points, which gives the normal law.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Foundation {
    /// Rigid: Signorini's conditions `u_n ≤ g`, `λ_n ≥ 0`, `λ_n (u_n - g) = 0`.
    #[default]
    Rigid,
    /// Deformable, by normal compliance: `λ_n = k [u_n - g]₊^m` (the penetration's power
    /// law; `m = 1` a linear spring bed).
    Compliant {
        /// `k > 0`: pressure per unit penetration to the power `m`.
        stiffness: f64,
        /// `m ≥ 1`.
        exponent: f64,
    },
}

impl Foundation {
    /// The pressure of the foundation at the penetration `p = u_n - g` (compliance), with its
    /// derivative: `(k [p]₊^m, k m [p]₊^(m-1))`; `None` for a rigid foundation.
    pub fn pressure(self, p: f64) -> Option<(f64, f64)> {
        match self {
            Foundation::Rigid => None,
            Foundation::Compliant { stiffness, exponent } => {
                let q = crate::project_nonnegative(p);
                if q == 0.0 {
                    return Some((0.0, 0.0));
                }
                Some((
                    stiffness * q.powf(exponent),
                    stiffness * exponent * q.powf(exponent - 1.0),
                ))
            }
        }
    }

    /// The scale below which multipliers are round-off, given the rigid one (`c` times the
    /// free motion's size) and the free penetration `p`: the rigid scale on a rigid
    /// foundation; on a compliant one the smaller of it and the bed's pressure `k [p]₊^m` (a
    /// soft bed under a small load carries pressures many decades below the rigid scale, and a
    /// floor there would take their round-off for the answer).
    pub fn multiplier_floor(self, rigid: f64, p: f64) -> f64 {
        match self.pressure(p) {
            Some((pressure, _)) if !pressure.is_nan() => rigid.min(pressure),
            _ => rigid,
        }
    }

    /// The normal value Coulomb's radius `F [·]₊` is taken at: Newton's augmented `z_n` on a
    /// rigid foundation (`[z_n]₊ = λ_n` at a solution), the pressure `λ_n` itself on a
    /// compliant one.
    pub fn radius_normal(self, z_n: f64, lambda_n: f64) -> f64 {
        match self {
            Foundation::Rigid => z_n,
            Foundation::Compliant { .. } => lambda_n,
        }
    }

    /// The compliance's equation at a point, `f = (λ_n - k [p]₊^m) / s` with
    /// `s = 1 + k m [p]₊^(m-1) / c` (`p = u_n - g`, `c` the natural map's constant), and the
    /// derivative of `λ_n - k [p]₊^m` in `p`, `k m [p]₊^(m-1)`: `(f, s, slope)`; `None` on a
    /// rigid foundation. The scale `s` makes the equation of order one in both limits: a soft
    /// bed's `λ_n - k p^m`, a stiff one's `c (λ_n / (k m p^(m-1)) - p / m)`, which tends to
    /// Signorini's `-c (u_n - g)` in contact (unscaled, the equation of a stiff bed holds only
    /// to `k` times the round-off of `u_n`).
    pub fn equation(self, lambda_n: f64, penetration: f64, c: f64) -> Option<(f64, f64, f64)> {
        let (pressure, slope) = self.pressure(penetration)?;
        let scale = 1.0 + slope / c;
        Some(((lambda_n - pressure) / scale, scale, slope))
    }

    /// The normal part of the natural-map residual: Signorini's `λ_n - [λ_n + c (u_n - g)]₊`,
    /// or the compliance's scaled equation ([`Foundation::equation`]).
    pub fn normal_residual(self, lambda_n: f64, penetration: f64, c: f64) -> f64 {
        match self.equation(lambda_n, penetration, c) {
            None => lambda_n - crate::project_nonnegative(lambda_n + c * penetration),
            Some((f, _, _)) => f,
        }
    }
}

impl ContactPoints {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.weight.len()
    }
    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.weight.is_empty()
    }

    /// What point `i` presses on ([`ContactPoints::foundations`], else
    /// [`ContactPoints::foundation`]).
    #[inline]
    pub fn foundation_of(&self, i: usize) -> Foundation {
        self.foundations.get(i).copied().unwrap_or(self.foundation)
    }

    /// Whether every point presses on a rigid foundation.
    pub fn all_rigid(&self) -> bool {
        (0..self.len()).all(|i| self.foundation_of(i) == Foundation::Rigid)
    }

    /// The slip point `i` accumulated before this problem ([`ContactPoints::slipped`]).
    #[inline]
    pub fn slipped(&self, i: usize) -> f64 {
        self.slipped.get(i).copied().unwrap_or(0.0)
    }

    /// Point `i`'s slip-weakening law ([`ContactPoints::weakening`]), if its coefficient
    /// falls with its slip.
    #[inline]
    pub fn weakening_of(&self, i: usize) -> Option<&crate::SlipWeakening> {
        self.weakening.get(i).and_then(Option::as_ref)
    }

    /// Point `i`'s Tresca bound under Coulomb's law ([`ContactPoints::tresca`]), if its
    /// radius is a constant.
    #[inline]
    pub fn tresca_of(&self, i: usize) -> Option<f64> {
        self.tresca.get(i).copied().flatten()
    }

    /// Whether a point's coefficient falls with its slip.
    pub fn weakens(&self) -> bool {
        self.weakening.iter().any(Option::is_some)
    }

    /// The points with `law` at every one of them ([`ContactPoints::weakening`]).
    pub fn with_weakening(&self, law: crate::SlipWeakening) -> ContactPoints {
        ContactPoints {
            weakening: vec![Some(law); self.len()],
            ..self.clone()
        }
    }

    /// Refuses points that weaken, for a solver that holds each point's coefficient constant.
    ///
    /// # Errors
    /// [`InputError::Unsupported`] where a point's coefficient falls with its slip.
    pub(crate) fn refuse_weakening(&self) -> Result<(), InputError> {
        if self.weakens() {
            return Err(InputError::Unsupported(
                "points whose coefficient falls with their slip: solve_slip_weakening solves them (this solver holds each point's coefficient)",
            ));
        }
        Ok(())
    }

    /// Each point's Coulomb coefficient at its slip in `u` (and what it slipped before the
    /// problem): its weakening law's there, or its constant one.
    pub fn coefficients_at(&self, u: &crate::PointValues) -> Vec<f64> {
        (0..self.len())
            .map(|i| match self.weakening_of(i) {
                Some(w) => w.coefficient(self.slipped(i) + u.tangential_norm(i)),
                None => self.friction[i],
            })
            .collect()
    }

    /// The points with the coefficients at their slips in `u` ([`ContactPoints::coefficients_at`]).
    pub fn at_slips(&self, u: &crate::PointValues) -> ContactPoints {
        ContactPoints {
            friction: self.coefficients_at(u),
            ..self.clone()
        }
    }

    /// The points `keep` (indices, in the order given) as points of their own: every
    /// per-point array taken at them, the per-point arrays left empty where they were.
    ///
    /// # Panics
    /// Where an index of `keep` is not a point's.
    pub fn select(&self, keep: &[usize]) -> ContactPoints {
        fn at<T: Clone>(v: &[T], keep: &[usize]) -> Vec<T> {
            if v.is_empty() {
                return vec![];
            }
            keep.iter().map(|&i| v[i].clone()).collect()
        }
        ContactPoints {
            dim: self.dim,
            position: at(&self.position, keep),
            normal: at(&self.normal, keep),
            tangent: at(&self.tangent, keep),
            weight: at(&self.weight, keep),
            gap: at(&self.gap, keep),
            friction: at(&self.friction, keep),
            held: at(&self.held, keep),
            foundation: self.foundation,
            foundations: at(&self.foundations, keep),
            slipped: at(&self.slipped, keep),
            weakening: at(&self.weakening, keep),
            tresca: at(&self.tresca, keep),
        }
    }

    /// Tangential components per point.
    pub fn n_tangential(&self) -> usize {
        self.dim - 1
    }
    /// `x` (point `i`'s tangential components) projected onto the point's friction set: the disc
    /// `|x| ≤ radius` in the directions it may slide in, 0 in those a support holds. (The set
    /// lies in the subspace of the free directions, so the projection is the subspace's, then
    /// the disc's.)
    #[inline]
    pub fn project_friction(&self, i: usize, x: &mut [f64], radius: f64) {
        self.hold(i, x);
        crate::projection::project_disc(x, radius);
    }

    /// Sets to 0 the components of point `i`'s tangential `x` that a support holds.
    #[inline]
    pub fn hold(&self, i: usize, x: &mut [f64]) {
        for (v, &h) in x.iter_mut().zip(&self.held[i]) {
            if h {
                *v = 0.0;
            }
        }
    }

    /// Whether tangential direction `q` of point `i` is held by a support.
    #[inline]
    pub fn is_held(&self, i: usize, q: usize) -> bool {
        self.held[i][q]
    }

    /// Checks sizes and values.
    ///
    /// # Errors
    /// The first bad item.
    pub fn validate(&self) -> Result<(), InputError> {
        let n = self.len();
        if self.position.len() != n
            || self.normal.len() != n
            || self.tangent.len() != n
            || self.gap.len() != n
            || self.friction.len() != n
            || self.held.len() != n
            || !(self.slipped.is_empty() || self.slipped.len() == n)
            || !(self.foundations.is_empty() || self.foundations.len() == n)
            || !(self.weakening.is_empty() || self.weakening.len() == n)
            || !(self.tresca.is_empty() || self.tresca.len() == n)
        {
            return Err(InputError::PointArrays);
        }
        let bad = |point, field, value, must| InputError::PointValue {
            point,
            field,
            value,
            must,
        };
        for i in 0..n {
            if !(self.weight[i] > 0.0 && self.weight[i].is_finite()) {
                return Err(bad(i, "weight", self.weight[i], "is not positive"));
            }
            if !self.gap[i].is_finite() {
                return Err(bad(i, "gap", self.gap[i], "is not finite"));
            }
            if !(self.friction[i] >= 0.0 && self.friction[i].is_finite()) {
                return Err(bad(i, "friction", self.friction[i], "must be finite and non-negative"));
            }
            if let Some(s) = self.tresca_of(i).filter(|s| !(*s >= 0.0 && s.is_finite())) {
                return Err(bad(i, "tresca", s, "must be finite and non-negative"));
            }
            if !(self.slipped(i) >= 0.0 && self.slipped(i).is_finite()) {
                return Err(bad(i, "slipped", self.slipped(i), "must be finite and non-negative"));
            }
        }
        for w in self.weakening.iter().flatten() {
            w.check()?;
        }
        for f in self.foundations.iter().chain(std::iter::once(&self.foundation)) {
            let Foundation::Compliant { stiffness, exponent } = *f else {
                continue;
            };
            if !(stiffness > 0.0 && stiffness.is_finite()) {
                return Err(InputError::Foundation {
                    what: "stiffness",
                    value: stiffness,
                    must: "must be positive and finite",
                });
            }
            if !(exponent >= 1.0 && exponent.is_finite()) {
                return Err(InputError::Foundation {
                    what: "exponent",
                    value: exponent,
                    must: "must be finite and at least 1",
                });
            }
        }
        Ok(())
    }
}

/// Values on the contact points: one normal and `nt` tangential components each (`nt = 0` for
/// a frictionless problem, else `dim - 1`), in the layout `[normal (n); tangential (n·nt)]`.
/// The shape is set when the values are made ([`PointValues::zeros`],
/// [`PointValues::from_parts`]) and known after (`n_tangential`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointValues {
    /// Normal components, one per point.
    pub normal: Vec<f64>,
    /// Tangential components, `nt` per point.
    pub tangential: Vec<f64>,
    nt: usize,
}

impl PointValues {
    /// Zeros for `n` points with `nt` tangential components each.
    pub fn zeros(n: usize, nt: usize) -> Self {
        PointValues {
            normal: vec![0.0; n],
            tangential: vec![0.0; n * nt],
            nt,
        }
    }

    /// Values from their parts, `nt` tangential components per point.
    ///
    /// # Errors
    /// [`ContactError::Input`] where `tangential` does not hold `nt` values per point.
    pub fn from_parts(normal: Vec<f64>, tangential: Vec<f64>, nt: usize) -> Result<Self, ContactError> {
        if tangential.len() != normal.len() * nt {
            return Err(InputError::TangentialShape {
                tangential: tangential.len(),
                points: normal.len(),
                nt,
            }
            .into());
        }
        Ok(PointValues { normal, tangential, nt })
    }

    /// Component `k` of point `i`: the normal for `k = 0`, tangent `k - 1` after.
    pub fn component(&self, i: usize, k: usize) -> f64 {
        if k == 0 {
            self.normal[i]
        } else {
            self.tangential[i * self.nt + k - 1]
        }
    }

    /// Component `k` of point `i`, to change it.
    pub fn component_mut(&mut self, i: usize, k: usize) -> &mut f64 {
        if k == 0 {
            &mut self.normal[i]
        } else {
            &mut self.tangential[i * self.nt + k - 1]
        }
    }

    /// The values of a flat vector in the layout `[normal (n); tangential (n·nt)]`.
    pub(crate) fn from_flat(x: &[f64], n: usize, nt: usize) -> Self {
        PointValues {
            normal: x[..n].to_vec(),
            tangential: x[n..].to_vec(),
            nt,
        }
    }

    /// The values as a flat vector in the layout `[normal (n); tangential (n·nt)]`, the
    /// inverse of [`PointValues::from_flat`].
    pub(crate) fn to_flat(&self) -> Vec<f64> {
        self.normal.iter().chain(&self.tangential).copied().collect()
    }

    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.normal.len()
    }

    /// Tangential components per point.
    pub fn n_tangential(&self) -> usize {
        self.nt
    }

    /// The tangential components of point `i`.
    pub fn tangential_of(&self, i: usize) -> &[f64] {
        &self.tangential[i * self.nt..(i + 1) * self.nt]
    }

    /// The tangential components of point `i`, to change.
    pub fn tangential_of_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.tangential[i * self.nt..(i + 1) * self.nt]
    }

    /// These values (of `keep.len()` points) as values of `n` points, point `j` at `keep[j]`
    /// and zeros elsewhere: the inverse of [`ContactPoints::select`]'s choice.
    ///
    /// # Panics
    /// Where `keep` does not have one index per point, or an index is `n` or more.
    pub fn spread(&self, keep: &[usize], n: usize) -> PointValues {
        assert_eq!(keep.len(), self.normal.len(), "one index per point");
        let nt = self.nt;
        let mut out = PointValues::zeros(n, nt);
        for (j, &i) in keep.iter().enumerate() {
            out.normal[i] = self.normal[j];
            out.tangential_of_mut(i).copy_from_slice(self.tangential_of(j));
        }
        out
    }

    /// The Euclidean norm of the tangential components of point `i`.
    pub fn tangential_norm(&self, i: usize) -> f64 {
        crate::projection::norm(self.tangential_of(i))
    }

    /// Weighted 2-norm `(Σ w_i |x_i|²)^½` over both parts; where the sum of squares would
    /// overflow or underflow (data near 1e±150 and beyond), scaled by the largest entry first.
    pub fn weighted_norm(&self, w: &[f64]) -> f64 {
        let plain = self.weighted_sum_of_squares(w, 1.0);
        if crate::projection::trusted(plain)
            || plain == 0.0 && !self.normal.iter().chain(&self.tangential).any(|x| *x != 0.0)
        {
            return plain.sqrt();
        }
        let scale = self
            .normal
            .iter()
            .chain(&self.tangential)
            .fold(0.0f64, |m, x| m.max(x.abs()));
        if scale == 0.0 || !scale.is_finite() {
            return if self.is_finite() { scale } else { f64::NAN };
        }
        scale * self.weighted_sum_of_squares(w, scale).sqrt()
    }

    /// `Σ w_i |x_i / s|²` (a division: `1/s` overflows for a subnormal `s`).
    fn weighted_sum_of_squares(&self, w: &[f64], s: f64) -> f64 {
        let mut sum = 0.0;
        for (i, &wi) in w.iter().enumerate() {
            sum += wi * (self.normal[i] / s) * (self.normal[i] / s);
            for x in self.tangential_of(i) {
                sum += wi * (x / s) * (x / s);
            }
        }
        sum
    }

    /// Weighted inner product `Σ w_i (x_i · y_i)` over both parts.
    pub fn weighted_dot(&self, other: &PointValues, w: &[f64]) -> f64 {
        let mut s = 0.0;
        for (i, &wi) in w.iter().enumerate() {
            s += wi * self.normal[i] * other.normal[i];
            for (a, b) in self.tangential_of(i).iter().zip(other.tangential_of(i)) {
                s += wi * a * b;
            }
        }
        s
    }

    /// Euclidean 2-norm over both parts.
    pub fn norm(&self) -> f64 {
        self.normal
            .iter()
            .chain(&self.tangential)
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
    }

    /// `self - other`.
    pub fn minus(&self, other: &PointValues) -> PointValues {
        PointValues {
            normal: self.normal.iter().zip(&other.normal).map(|(a, b)| a - b).collect(),
            tangential: self
                .tangential
                .iter()
                .zip(&other.tangential)
                .map(|(a, b)| a - b)
                .collect(),
            nt: self.nt,
        }
    }

    /// Whether every value is finite.
    pub fn is_finite(&self) -> bool {
        self.normal.iter().chain(&self.tangential).all(|x| x.is_finite())
    }
}

/// The state of a contact point in a solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// In contact, `|λ_t| < S`.
    Stick,
    /// In contact, on the friction bound (or frictionless).
    Slip,
    /// No contact force.
    Separated,
}

impl Status {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Status::Stick => "stick",
            Status::Slip => "slip",
            Status::Separated => "separated",
        }
    }
}

/// The flat layout of the compliance's rows and columns: `[normal (n); tangential (n·nt)]`,
/// point `i`'s component `k` (0 the normal) at [`Flat::index`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Flat {
    /// Points.
    pub n: usize,
    /// Tangential components per point.
    pub nt: usize,
}

impl Flat {
    /// Rows in all.
    pub fn len(self) -> usize {
        self.n * (1 + self.nt)
    }

    /// The row of component `k` of point `i`.
    pub fn index(self, i: usize, k: usize) -> usize {
        if k == 0 {
            i
        } else {
            self.n + i * self.nt + k - 1
        }
    }

    /// The point and component of row `r`.
    pub fn owner(self, r: usize) -> (usize, usize) {
        if r < self.n {
            (r, 0)
        } else {
            ((r - self.n) / self.nt, 1 + (r - self.n) % self.nt)
        }
    }
}
