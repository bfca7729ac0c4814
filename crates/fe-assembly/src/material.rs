//! Electro-elastic materials: 3D crystal constants with a poling direction, rotated into the
//! global frame and, in 2D, reduced to plane strain.
//!
//! Voigt order `[11, 22, 33, 23, 13, 12]` with engineering shear strains, so the Voigt entries
//! of `C` and `e` are the tensor components themselves (no factors of 2).

use nalgebra::{DMatrix, Matrix3};

/// 3D constants in the crystal frame (poling along the crystal's 3-axis).
#[derive(Clone, Debug, PartialEq)]
pub struct Crystal {
    /// Elasticity, 6x6 Voigt (stress units, e.g. GPa).
    pub c: [[f64; 6]; 6],
    /// Piezoelectric stress constants, 3x6 (rows D_1, D_2, D_3), e.g. C/m^2.
    pub e: [[f64; 6]; 3],
    /// Permittivity at constant strain, 3x3, e.g. nF/m.
    pub permittivity: [[f64; 3]; 3],
}

impl Crystal {
    /// PZT-5A as tabulated in docs/scenes.md (GPa, C/m^2, nF/m): c11 = 121, c12 = 75.4,
    /// c13 = 75.2, c33 = 111, c44 = 21.1, c66 = 22.6; e31 = -5.4, e33 = 15.8, e15 = 12.3;
    /// eps11 = 8.11, eps33 = 7.35.
    pub fn pzt5a() -> Self {
        Self::hexagonal_6mm([121.0, 75.4, 75.2, 111.0, 21.1, 22.6], [-5.4, 15.8, 12.3], [8.11, 7.35])
    }

    /// A crystal of class 6mm (poled ceramics): `c = [c11, c12, c13, c33, c44, c66]`,
    /// `e = [e31, e33, e15]`, `eps = [eps11, eps33]`. `c66` is taken as given, not as
    /// `(c11 - c12) / 2`.
    pub fn hexagonal_6mm(c: [f64; 6], e: [f64; 3], eps: [f64; 2]) -> Self {
        let [c11, c12, c13, c33, c44, c66] = c;
        let mut cm = [[0.0; 6]; 6];
        cm[0][0] = c11;
        cm[1][1] = c11;
        cm[2][2] = c33;
        cm[0][1] = c12;
        cm[1][0] = c12;
        cm[0][2] = c13;
        cm[2][0] = c13;
        cm[1][2] = c13;
        cm[2][1] = c13;
        cm[3][3] = c44;
        cm[4][4] = c44;
        cm[5][5] = c66;
        let [e31, e33, e15] = e;
        let mut em = [[0.0; 6]; 3];
        em[2][0] = e31;
        em[2][1] = e31;
        em[2][2] = e33;
        em[0][4] = e15;
        em[1][3] = e15;
        let permittivity = [[eps[0], 0.0, 0.0], [0.0, eps[0], 0.0], [0.0, 0.0, eps[1]]];
        Crystal {
            c: cm,
            e: em,
            permittivity,
        }
    }

    /// An isotropic elastic solid (Young's modulus, Poisson's ratio) with no piezoelectricity
    /// and the given isotropic permittivity (0 for a body with no electric unknowns).
    pub fn isotropic(young: f64, poisson: f64, permittivity: f64) -> Self {
        let lambda = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
        let mu = young / (2.0 * (1.0 + poisson));
        let mut c = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] = lambda + if i == j { 2.0 * mu } else { 0.0 };
            }
            c[i + 3][i + 3] = mu;
        }
        let p = permittivity;
        Crystal {
            c,
            e: [[0.0; 6]; 3],
            permittivity: [[p, 0.0, 0.0], [0.0, p, 0.0], [0.0, 0.0, p]],
        }
    }
}

/// A material in the global frame of a `dim`-dimensional problem: `c` is `nv x nv`
/// (`nv = 3` in 2D: `[xx, yy, xy]`; 6 in 3D), `e` is `dim x nv`, `beta` is `dim x dim`,
/// all row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Spatial dimension.
    pub dim: usize,
    /// Elasticity, row-major `nv x nv`.
    pub c: Vec<f64>,
    /// Piezoelectric stress constants, row-major `dim x nv`.
    pub e: Vec<f64>,
    /// Permittivity, row-major `dim x dim`; all zero for a purely elastic material.
    pub beta: Vec<f64>,
    /// Whether the material carries electric unknowns (a non-zero permittivity).
    pub electric: bool,
    /// In plane strain, what the reduction to `[xx, yy, xy]` leaves out but the state still
    /// carries: the stresses across the plane and the field along its normal (`None` on a body
    /// of revolution and in 3D, whose Voigt rows hold every component, and for a material
    /// built without its 3D tensors, whose out-of-plane values are then unknown).
    pub out_of_plane: Option<OutOfPlane>,
}

/// The out-of-plane rows of a plane-strain material's 3D tensors: with `ε_zz = γ_yz = γ_xz =
/// 0` and `E_z = 0`, the stresses `[σ_zz, σ_yz, σ_xz] = c ε + e ∇φ` and the electric
/// displacement `D_z = e_z·ε - β_z·∇φ`, from the in-plane strain `ε = [ε_xx, ε_yy, γ_xy]` and
/// gradient `∇φ = [∂_x φ, ∂_y φ]` (docs/theory.md, "Recovered fields").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutOfPlane {
    /// `C`'s rows `zz, yz, xz` on the columns `xx, yy, xy`.
    pub c: [[f64; 3]; 3],
    /// `eᵀ`'s rows `zz, yz, xz` on the in-plane fields `x, y`: `e_{k, zz}` etc.
    pub e: [[f64; 2]; 3],
    /// `e`'s row `z` on the columns `xx, yy, xy`.
    pub e_z: [f64; 3],
    /// The permittivity's row `z` on the in-plane fields `x, y`.
    pub beta_z: [f64; 2],
}

impl OutOfPlane {
    /// `[σ_zz, σ_yz, σ_xz, D_z]` at the in-plane strain `eps` and gradient `grad`.
    pub fn at(&self, eps: &[f64], grad: &[f64]) -> [f64; 4] {
        let mut out = [0.0; 4];
        for (r, o) in out.iter_mut().take(3).enumerate() {
            *o = (0..3).map(|j| self.c[r][j] * eps[j]).sum::<f64>()
                + (0..2).map(|k| self.e[r][k] * grad[k]).sum::<f64>();
        }
        out[3] =
            (0..3).map(|j| self.e_z[j] * eps[j]).sum::<f64>() - (0..2).map(|k| self.beta_z[k] * grad[k]).sum::<f64>();
        out
    }

    /// The piezoelectric parts times `factor` (none at 0).
    fn scale_coupling(&mut self, factor: f64) {
        self.e.iter_mut().flatten().for_each(|x| *x *= factor);
        self.e_z.iter_mut().for_each(|x| *x *= factor);
    }
}

/// A material that cannot be used.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum MaterialError {
    /// A constant is NaN or infinite.
    #[error("material `{material}`: {what} has a non-finite entry")]
    NonFinite {
        /// The material's name.
        material: String,
        /// Which constant.
        what: &'static str,
    },
    /// C or the permittivity is not symmetric.
    #[error("material `{material}`: {what} is not symmetric (entry ({i}, {j}))")]
    NotSymmetric {
        /// The material's name.
        material: String,
        /// Which constant.
        what: &'static str,
        /// Row.
        i: usize,
        /// Column.
        j: usize,
    },
    /// C or the permittivity is not positive definite.
    #[error("material `{material}`: {what} is not positive definite (smallest eigenvalue {min_eig:.4e})")]
    NotPositiveDefinite {
        /// The material's name.
        material: String,
        /// Which constant.
        what: &'static str,
        /// Its smallest eigenvalue.
        min_eig: f64,
    },
    /// An axisymmetric body whose material is not symmetric about the body's axis.
    #[error(
        "material `{material}`: an axisymmetric body needs a material symmetric about its axis \
         (y), and this one is not (poled along {poling:?}: pole it along [0, 1, 0])"
    )]
    NotAxisymmetric {
        /// The material's name.
        material: String,
        /// The poling direction given.
        poling: [f64; 3],
    },
    /// A constant whose number of entries fits no Voigt layout of the material's dimension.
    #[error(
        "material `{material}`: {what} has {len} entries, which fit no layout of a {dim}D material \
         (C is 3 x 3 in plane strain, 4 x 4 on a body of revolution, 6 x 6 in 3D; e is dim x that)"
    )]
    Layout {
        /// The material's name.
        material: String,
        /// Which constant.
        what: &'static str,
        /// Its number of entries.
        len: usize,
        /// The material's dimension.
        dim: usize,
    },
    /// The poling direction is zero or not finite.
    #[error("material `{material}`: the poling direction {dir:?} is not a non-zero vector")]
    BadPoling {
        /// The material's name.
        material: String,
        /// The direction given.
        dir: [f64; 3],
    },
}

/// What the mesh is of: the body itself, or the meridian section of a body of revolution. An
/// argument of the discretisation ([`crate::Discretization::new`]): the geometry decides the
/// strains (the hoop strain of a body of revolution) and the measure of every integral (`2π r`
/// there), and each material's Voigt layout must be the geometry's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Coordinates {
    /// The mesh is the body: plane strain in 2D, the solid in 3D.
    #[default]
    Cartesian,
    /// A body of revolution about the y axis, meshed in its meridian plane `(r, z) = (x, y)`
    /// (2D, every node at `r >= 0`): the Voigt order is `[rr, zz, rz, θθ]`, the hoop strain
    /// `u_r / r` last; a material for it is made by [`Material::from_crystal_axisymmetric`].
    Axisymmetric,
}

impl Coordinates {
    /// Their name in messages: `Cartesian` or `axisymmetric`.
    pub fn name(self) -> &'static str {
        match self {
            Coordinates::Cartesian => "Cartesian",
            Coordinates::Axisymmetric => "axisymmetric",
        }
    }
}

/// Number of Voigt strain components in dimension `dim`: 3 in plane strain, 4 on a body of
/// revolution (`[rr, zz, rz, θθ]`), 6 in 3D.
pub fn voigt_len(dim: usize, coordinates: Coordinates) -> usize {
    match (dim, coordinates) {
        (2, Coordinates::Cartesian) => 3,
        (2, Coordinates::Axisymmetric) => 4,
        _ => 6,
    }
}

/// Voigt index of the symmetric pair `(i, j)` in dimension `dim`: `[xx, yy, xy]` in 2D,
/// `[xx, yy, zz, yz, xz, xy]` (= `[11, 22, 33, 23, 13, 12]`) in 3D.
pub fn voigt(dim: usize, i: usize, j: usize) -> usize {
    match (dim, i.min(j), i.max(j)) {
        (2, 0, 0) => 0,
        (2, 1, 1) => 1,
        (2, _, _) => 2,
        (_, 0, 0) => 0,
        (_, 1, 1) => 1,
        (_, 2, 2) => 2,
        (_, 1, 2) => 3,
        (_, 0, 2) => 4,
        _ => 5,
    }
}

/// The orthonormal crystal frame for a poling direction: column `a` of `q` is crystal axis
/// `a` in global coordinates; axis 3 is the poling direction, axis 1 the first global axis
/// not parallel to it (made orthogonal), axis 2 = axis 3 x axis 1.
fn crystal_frame(poling: [f64; 3]) -> Option<Matrix3<f64>> {
    let d = nalgebra::Vector3::from(poling);
    let norm = d.norm();
    if !norm.is_finite() || norm == 0.0 {
        return None;
    }
    let a3 = d / norm;
    let a1 = (0..3)
        .map(|k| {
            let mut v = nalgebra::Vector3::zeros();
            v[k] = 1.0;
            v - a3 * a3[k]
        })
        .find(|v| v.norm() > 1e-8)?
        .normalize();
    let a2 = a3.cross(&a1);
    Some(Matrix3::from_columns(&[a1, a2, a3]))
}

impl Material {
    /// The crystal rotated so that its 3-axis points along `poling` (global coordinates), then,
    /// for `dim = 2`, reduced to plane strain in the x-y plane (eps_zz = gamma_xz = gamma_yz = 0,
    /// E_z = 0: keep the rows and columns `[xx, yy, xy]` and `[x, y]`). Checks that C and the
    /// permittivity are symmetric and positive definite (the permittivity may be all zero: then
    /// the material has no electric unknowns and `e` must be zero too).
    ///
    /// ```
    /// use fe_assembly::{Crystal, Material};
    /// // PZT-5A poled along y in plane strain: docs/scenes.md's 2D values.
    /// let m = Material::from_crystal("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0], 2).unwrap();
    /// assert_eq!(m.c, vec![121.0, 75.2, 0.0, 75.2, 111.0, 0.0, 0.0, 0.0, 21.1]);
    /// ```
    pub fn from_crystal(
        name: &str,
        crystal: &Crystal,
        poling: [f64; 3],
        dim: usize,
    ) -> Result<Material, MaterialError> {
        let (c3, e3, b3) = poled(name, crystal, poling)?;
        let (rows, fields): (Vec<usize>, Vec<usize>) = match dim {
            2 => (vec![0, 1, 5], vec![0, 1]),
            _ => ((0..6).collect(), (0..3).collect()),
        };
        let mut m = reduced(name, &(c3, e3, b3), &rows, &fields, dim)?;
        if dim == 2 {
            // the rows zz (2), yz (3), xz (4) and the field z (2) on the plane's columns
            let across = [2, 3, 4];
            m.out_of_plane = Some(OutOfPlane {
                c: across.map(|i| [c3[i][0], c3[i][1], c3[i][5]]),
                e: across.map(|i| [e3[0][i], e3[1][i]]),
                e_z: [e3[2][0], e3[2][1], e3[2][5]],
                beta_z: [b3[2][0], b3[2][1]],
            });
        }
        Ok(m)
    }

    /// The crystal rotated so that its 3-axis points along `poling`, for a body of revolution
    /// about the y axis meshed in its meridian plane (`x = r`, `y = z`, the hoop direction the
    /// third): the Voigt rows `[rr, zz, rz, θθ]` and the fields `[r, z]` of the 3D tensors.
    /// The material must be symmetric about y (checked: its tensors unchanged by a rotation
    /// about y, to 1 % of each tensor's largest constant, since tables round the 6mm identity
    /// `c66 = (c11 - c12) / 2`, which the meridian plane does not use), as a 6mm crystal poled
    /// along y or an isotropic solid are.
    ///
    /// ```
    /// use fe_assembly::{Crystal, Material};
    /// let m = Material::from_crystal_axisymmetric("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0]).unwrap();
    /// // [rr, zz, rz, θθ]: c11, c13, 0, c12 on the first row
    /// assert_eq!(&m.c[..4], &[121.0, 75.2, 0.0, 75.4]);
    /// assert!(Material::from_crystal_axisymmetric("x", &Crystal::pzt5a(), [1.0, 0.0, 0.0]).is_err());
    /// ```
    ///
    /// # Errors
    /// As [`Material::from_crystal`], and [`MaterialError::NotAxisymmetric`].
    pub fn from_crystal_axisymmetric(
        name: &str,
        crystal: &Crystal,
        poling: [f64; 3],
    ) -> Result<Material, MaterialError> {
        let (c3, e3, b3) = poled(name, crystal, poling)?;
        // symmetric about y: the same tensors after a rotation by 1 rad about y (to the 1 % of
        // tabulated data: PZT-5A's c66 is 22.6 beside (c11 - c12) / 2 = 22.8)
        let (s, c) = 1f64.sin_cos();
        let about_y = Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c);
        let global = Crystal {
            c: c3,
            e: e3,
            permittivity: b3,
        };
        let (c4, e4, b4) = rotated(&global, &about_y);
        let differs = |a: &[f64], b: &[f64]| {
            let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            a.iter().zip(b).any(|(x, y)| (x - y).abs() > 1e-2 * scale)
        };
        if differs(c3.as_flattened(), c4.as_flattened())
            || differs(e3.as_flattened(), e4.as_flattened())
            || differs(b3.as_flattened(), b4.as_flattened())
        {
            return Err(MaterialError::NotAxisymmetric {
                material: name.into(),
                poling,
            });
        }
        reduced(name, &(c3, e3, b3), &[0, 1, 5, 2], &[0, 1], 2)
    }

    /// Number of Voigt strain components (3 in plane strain, 4 axisymmetric, 6 in 3D): the
    /// order of `c`.
    pub fn nv(&self) -> usize {
        self.c.len().isqrt()
    }

    /// The coordinates whose Voigt layout this material has: [`Coordinates::Axisymmetric`]
    /// for the 4 strains of a body of revolution, else Cartesian.
    pub fn coordinates(&self) -> Coordinates {
        if self.dim == 2 && self.nv() == 4 {
            Coordinates::Axisymmetric
        } else {
            Coordinates::Cartesian
        }
    }

    /// A copy with `e` multiplied by `factor` (the `material.coupling_scale` of the scenes).
    pub fn with_coupling_scale(mut self, factor: f64) -> Self {
        for x in &mut self.e {
            *x *= factor;
        }
        if let Some(o) = &mut self.out_of_plane {
            o.scale_coupling(factor);
        }
        self
    }

    /// The material without its electric part (no permittivity, no coupling): for a problem
    /// whose plan has no electric unknowns.
    pub fn without_electric(mut self) -> Self {
        self.electric = false;
        self.beta.iter_mut().for_each(|x| *x = 0.0);
        self.e.iter_mut().for_each(|x| *x = 0.0);
        if let Some(o) = &mut self.out_of_plane {
            o.scale_coupling(0.0);
            o.beta_z = [0.0; 2];
        }
        self
    }

    /// Checks symmetry and positive definiteness of C and (for an electric material) beta.
    pub fn validate(&self, name: &str) -> Result<(), MaterialError> {
        let nv = self.nv();
        let layouts: &[usize] = if self.dim == 2 { &[3, 4] } else { &[6] };
        for (what, len, expected) in [
            ("C", self.c.len(), nv * nv),
            ("e", self.e.len(), self.dim * nv),
            ("the permittivity", self.beta.len(), self.dim * self.dim),
        ] {
            if !layouts.contains(&nv) || len != expected || !matches!(self.dim, 2 | 3) {
                return Err(MaterialError::Layout {
                    material: name.into(),
                    what,
                    len,
                    dim: self.dim,
                });
            }
        }
        check_spd(name, "C", &self.c, nv)?;
        if self.electric {
            check_spd(name, "the permittivity", &self.beta, self.dim)?;
        } else if self.e.iter().any(|&x| x != 0.0) {
            return Err(MaterialError::NotPositiveDefinite {
                material: name.into(),
                what: "the permittivity (zero, with a non-zero coupling e)",
                min_eig: 0.0,
            });
        }
        Ok(())
    }
}

/// The crystal's tensors in the global frame, its 3-axis along `poling`, its constants checked
/// finite.
fn poled(name: &str, crystal: &Crystal, poling: [f64; 3]) -> Result<Tensors3, MaterialError> {
    let q = crystal_frame(poling).ok_or_else(|| MaterialError::BadPoling {
        material: name.into(),
        dir: poling,
    })?;
    finite(name, crystal)?;
    Ok(rotated(crystal, &q))
}

/// Checks that every constant of the crystal is finite.
fn finite(name: &str, crystal: &Crystal) -> Result<(), MaterialError> {
    for (what, v) in [
        ("C", crystal.c.as_flattened()),
        ("e", crystal.e.as_flattened()),
        ("the permittivity", crystal.permittivity.as_flattened()),
    ] {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(MaterialError::NonFinite {
                material: name.into(),
                what,
            });
        }
    }
    Ok(())
}

/// 3D tensors in the global frame: `(C, e, β)`.
type Tensors3 = ([[f64; 6]; 6], [[f64; 6]; 3], [[f64; 3]; 3]);

/// The crystal's tensors rotated by `q` (column `a` of `q`: crystal axis `a` in global
/// coordinates): `T'_{ij..} = q_{ia} q_{jb} .. T_{ab..}`, round-off cleaned.
fn rotated(crystal: &Crystal, q: &Matrix3<f64>) -> Tensors3 {
    let mut c3 = [[0.0; 6]; 6];
    let mut e3 = [[0.0; 6]; 3];
    let mut b3 = [[0.0; 3]; 3];
    let r = |i: usize, a: usize| q[(i, a)];
    for i in 0..3 {
        for j in i..3 {
            for k in 0..3 {
                for l in k..3 {
                    let mut s = 0.0;
                    for a in 0..3 {
                        for b in 0..3 {
                            for cc in 0..3 {
                                for d in 0..3 {
                                    let v = crystal.c[voigt(3, a, b)][voigt(3, cc, d)];
                                    if v != 0.0 {
                                        s += r(i, a) * r(j, b) * r(k, cc) * r(l, d) * v;
                                    }
                                }
                            }
                        }
                    }
                    c3[voigt(3, i, j)][voigt(3, k, l)] = s;
                }
            }
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            for k in j..3 {
                let mut s = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        for cc in 0..3 {
                            s += r(i, a) * r(j, b) * r(k, cc) * crystal.e[a][voigt(3, b, cc)];
                        }
                    }
                }
                e3[i][voigt(3, j, k)] = s;
            }
            let mut s = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    s += r(i, a) * r(j, b) * crystal.permittivity[a][b];
                }
            }
            b3[i][j] = s;
        }
    }
    clean(c3.as_flattened_mut());
    clean(e3.as_flattened_mut());
    clean(b3.as_flattened_mut());
    (c3, e3, b3)
}

/// The material of the Voigt `rows` and field components `fields` of the 3D tensors,
/// validated.
fn reduced(
    name: &str,
    (c3, e3, b3): &Tensors3,
    rows: &[usize],
    fields: &[usize],
    dim: usize,
) -> Result<Material, MaterialError> {
    let c: Vec<f64> = rows.iter().flat_map(|&i| rows.iter().map(move |&j| c3[i][j])).collect();
    let e: Vec<f64> = fields
        .iter()
        .flat_map(|&i| rows.iter().map(move |&j| e3[i][j]))
        .collect();
    let beta: Vec<f64> = fields
        .iter()
        .flat_map(|&i| fields.iter().map(move |&j| b3[i][j]))
        .collect();
    let electric = beta.iter().any(|&x| x != 0.0);
    let m = Material {
        dim,
        c,
        e,
        beta,
        electric,
        out_of_plane: None,
    };
    m.validate(name)?;
    Ok(m)
}

/// Rounds entries that are round-off of zero (below 1e-14 of the largest) to exactly zero.
fn clean(v: &mut [f64]) {
    let big = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for x in v {
        if x.abs() <= 1e-14 * big {
            *x = 0.0;
        } else {
            // snap values that differ from a short decimal by round-off of the rotation
            let r = (*x * 1e12).round() / 1e12;
            if (r - *x).abs() <= 4.0 * f64::EPSILON * x.abs() {
                *x = r;
            }
        }
    }
}

fn check_spd(name: &str, what: &'static str, m: &[f64], n: usize) -> Result<(), MaterialError> {
    if m.iter().any(|x| !x.is_finite()) {
        return Err(MaterialError::NonFinite {
            material: name.into(),
            what,
        });
    }
    let scale = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for i in 0..n {
        for j in 0..i {
            if (m[i * n + j] - m[j * n + i]).abs() > 1e-12 * scale {
                return Err(MaterialError::NotSymmetric {
                    material: name.into(),
                    what,
                    i,
                    j,
                });
            }
        }
    }
    let dm = DMatrix::from_row_slice(n, n, m);
    let min_eig = dm.symmetric_eigenvalues().min();
    if !(min_eig > 1e-12 * scale) {
        return Err(MaterialError::NotPositiveDefinite {
            material: name.into(),
            what,
            min_eig,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/scenes.md section 1: the plane-strain reduction of PZT-5A poled along y.
    #[test]
    fn pzt5a_plane_strain_matches_scenes() {
        let m = Material::from_crystal("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0], 2).unwrap();
        assert_eq!(m.c, vec![121.0, 75.2, 0.0, 75.2, 111.0, 0.0, 0.0, 0.0, 21.1]);
        assert_eq!(m.e, vec![0.0, 0.0, 12.3, -5.4, 15.8, 0.0]);
        assert_eq!(m.beta, vec![8.11, 0.0, 0.0, 7.35]);
        assert!(m.electric);
    }

    /// The plane-strain material's out-of-plane rows give the 3D material's stresses and
    /// `D_z` at the 3D state the plane carries (`ε_zz = γ_yz = γ_xz = 0`, `∂_z φ = 0`): poled
    /// obliquely, so that every row couples (`σ_yz`, `σ_xz` and `D_z` non-zero), and for an
    /// isotropic solid Hooke's `σ_zz = ν (σ_xx + σ_yy)`.
    #[test]
    fn plane_strain_carries_the_3d_stresses_across_its_plane() {
        let (eps, grad) = ([1e-3, -2e-3, 3e-3], [0.5, -0.25]);
        for poling in [[1.0, 2.0, 2.0], [0.0, 1.0, 0.0]] {
            let plane = Material::from_crystal("p", &Crystal::pzt5a(), poling, 2).unwrap();
            let solid = Material::from_crystal("s", &Crystal::pzt5a(), poling, 3).unwrap();
            let eps3 = [eps[0], eps[1], 0.0, 0.0, 0.0, eps[2]];
            let grad3 = [grad[0], grad[1], 0.0];
            let sigma = |i: usize| {
                (0..6).map(|j| solid.c[i * 6 + j] * eps3[j]).sum::<f64>()
                    + (0..3).map(|k| solid.e[k * 6 + i] * grad3[k]).sum::<f64>()
            };
            let d_z = (0..6).map(|j| solid.e[2 * 6 + j] * eps3[j]).sum::<f64>()
                - (0..3).map(|k| solid.beta[2 * 3 + k] * grad3[k]).sum::<f64>();
            let got = plane.out_of_plane.unwrap().at(&eps, &grad);
            let want = [sigma(2), sigma(3), sigma(4), d_z];
            for (g, w) in got.iter().zip(want) {
                assert!((g - w).abs() <= 1e-12 * (1.0 + w.abs()), "{got:?} against {want:?}");
            }
            if poling[2] != 0.0 {
                assert!(
                    got.iter().all(|x| x.abs() > 1e-6),
                    "an oblique poling couples every row: {got:?}"
                );
            }
        }
        let nu = 0.3;
        let m = Material::from_crystal("iso", &Crystal::isotropic(200.0, nu, 0.0), [0.0, 0.0, 1.0], 2).unwrap();
        let [zz, yz, xz, d_z] = m.out_of_plane.unwrap().at(&eps, &[0.0, 0.0]);
        let s = |i: usize| (0..3).map(|j| m.c[i * 3 + j] * eps[j]).sum::<f64>();
        assert!((zz - nu * (s(0) + s(1))).abs() < 1e-12 && yz == 0.0 && xz == 0.0 && d_z == 0.0);
        // without its electric part, the coupling and permittivity go from the rows too
        let cold = Material::from_crystal("p", &Crystal::pzt5a(), [1.0, 2.0, 2.0], 2)
            .unwrap()
            .without_electric();
        assert_eq!(cold.out_of_plane.unwrap().at(&[0.0; 3], &grad), [0.0; 4]);
    }

    /// Poled along z in 3D: the crystal frame is the global frame.
    #[test]
    fn pzt5a_3d_along_z_is_the_table() {
        let cr = Crystal::pzt5a();
        let m = Material::from_crystal("pzt5a", &cr, [0.0, 0.0, 1.0], 3).unwrap();
        assert_eq!(m.c, cr.c.as_flattened().to_vec());
        assert_eq!(m.e, cr.e.as_flattened().to_vec());
        assert_eq!(m.beta, cr.permittivity.as_flattened().to_vec());
    }

    /// A rotation keeps the energy of a rotated strain: W(R eps R^T) with rotated C equals
    /// W(eps) with the original C; checked by rotating about an oblique axis.
    #[test]
    fn oblique_poling_keeps_invariants() {
        let cr = Crystal::pzt5a();
        let m = Material::from_crystal("x", &cr, [1.0, 2.0, 2.0], 3).unwrap();
        let c = DMatrix::from_row_slice(6, 6, &m.c);
        let c0 = DMatrix::from_row_slice(6, 6, cr.c.as_flattened());
        // the trace of the 4th-order tensor's "bulk" contraction C_iijj is rotation invariant
        let bulk = |c: &DMatrix<f64>| {
            (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| c[(i, j)])
                .sum::<f64>()
        };
        assert!((bulk(&c) - bulk(&c0)).abs() < 1e-9);
        let b = DMatrix::from_row_slice(3, 3, &m.beta);
        assert!((b.trace() - (8.11 * 2.0 + 7.35)).abs() < 1e-12);
    }

    #[test]
    fn bad_materials_are_named() {
        let mut cr = Crystal::pzt5a();
        cr.c[0][0] = -1.0;
        let e = Material::from_crystal("bad", &cr, [0.0, 1.0, 0.0], 2).unwrap_err();
        assert!(matches!(e, MaterialError::NotPositiveDefinite { what: "C", .. }), "{e}");
        let mut cr = Crystal::pzt5a();
        cr.permittivity[2][2] = -7.0;
        let e = Material::from_crystal("bad", &cr, [0.0, 1.0, 0.0], 2).unwrap_err();
        assert!(e.to_string().contains("permittivity is not positive definite"), "{e}");
        let mut cr = Crystal::pzt5a();
        cr.e[2][2] = f64::NAN;
        assert!(matches!(
            Material::from_crystal("bad", &cr, [0.0, 1.0, 0.0], 2),
            Err(MaterialError::NonFinite { what: "e", .. })
        ));
        assert!(matches!(
            Material::from_crystal("bad", &Crystal::pzt5a(), [0.0; 3], 2),
            Err(MaterialError::BadPoling { .. })
        ));
        let nu_half = Crystal::isotropic(100.0, 0.5, 0.0);
        assert!(Material::from_crystal("inc", &nu_half, [0.0, 0.0, 1.0], 2).is_err());
    }
}
