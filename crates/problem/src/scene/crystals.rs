//! Materials by name and by datasheet: a library of poled ceramics and crystals of class 6mm
//! with their sources (`material.crystal = "PZT-5H"`), and the strain-charge form that
//! datasheets give (`[material.datasheet]`: the `d` or `g` constants with the compliances
//! `s^E` or `s^D` and the free permittivity `ε^T`) converted to the stress-charge form the
//! solver takes (`c^E`, `e`, `ε^S`), by the identities of IEEE Std 176-1987 (docs/theory.md,
//! "Materials by name and by datasheet"):
//!
//! `c^E = (s^E)⁻¹`, `e = d c^E`, `ε^S = ε^T - d c^E dᵀ`; from `g`: `d = ε^T g`; from `s^D`:
//! `s^E = s^D + dᵀ g` (with `g = (ε^T)⁻¹ d`).
//!
//! Either is resolved once, when the scene is read, into the material's `c`, `e` and
//! `permittivity` in the unit system the entry names (`material.units`: no default, so that a
//! library's numbers never land silently in a scene of other units).

use serde::{Deserialize, Serialize};

use super::{choice, MaterialModel, MaterialSpec};
use std::fmt;

/// The permittivity of free space, F/m (CODATA 2018).
pub const EPSILON_0: f64 = 8.854_187_812_8e-12;

choice! {
    /// The unit system a named or datasheet material's constants are given in.
    pub enum CrystalUnits ("material.units") {
        /// GPa, C/m², nF/m: the shipped scenes' system (potentials in GV where lengths are in
        /// m).
        Gpa = "GPa",
        /// Pa, C/m², F/m (potentials in V, lengths in m).
        Si = "SI",
    }
}

impl CrystalUnits {
    /// The factors from the GPa system to this one: on stiffness, on the piezoelectric
    /// constants, on permittivity.
    fn factors(self) -> (f64, f64, f64) {
        match self {
            CrystalUnits::Gpa => (1.0, 1.0, 1.0),
            CrystalUnits::Si => (1e9, 1.0, 1e-9),
        }
    }
}

/// A material's constants in the stress-charge form, in the GPa system (the sources'
/// tables): `c^E` (GPa) as `[c11, c12, c13, c33, c44, c66]`, `e` (C/m²) as
/// `[e31, e33, e15]`, `ε^S` (nF/m) as `[ε11, ε33]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StressCharge {
    /// `c^E`, GPa.
    pub c: [f64; 6],
    /// `e`, C/m².
    pub e: [f64; 3],
    /// `ε^S`, nF/m.
    pub permittivity: [f64; 2],
}

/// `ε₀` in nF/m.
const EPSILON_0_NF: f64 = EPSILON_0 * 1e9;

/// A named crystal of the library, with where its numbers come from.
#[derive(Clone, Copy, Debug)]
pub struct NamedCrystal {
    /// The name `material.crystal` takes.
    pub name: &'static str,
    /// Its constants, in the GPa system.
    pub constants: StressCharge,
    /// Where they come from.
    pub source: &'static str,
}

/// GPa, C/m², nF/m.
const fn tabulated(c: [f64; 6], e: [f64; 3], permittivity: [f64; 2]) -> StressCharge {
    StressCharge { c, e, permittivity }
}

/// `ε/ε₀` as a source tabulates it, in nF/m.
const fn relative(eps: [f64; 2]) -> [f64; 2] {
    [eps[0] * EPSILON_0_NF, eps[1] * EPSILON_0_NF]
}

/// The library: poled ceramics and crystals of class 6mm (the classes the model takes;
/// LiNbO3 (3m) and quartz (32) are not among them). Each as its source tabulates it, in the
/// stress-charge form.
pub const LIBRARY: [NamedCrystal; 5] = [
    NamedCrystal {
        name: "PZT-4",
        constants: tabulated(
            [139.0, 77.8, 74.3, 115.0, 25.6, 30.6],
            [-5.2, 15.1, 12.7],
            [6.46, 5.62],
        ),
        source: "Berlincourt, Curran & Jaffe, Physical Acoustics I-A (1964), Table 2 (ε^S = 730, 635 ε₀, in nF/m to 3 digits, as the shipped indentation scenes give it)",
    },
    NamedCrystal {
        name: "PZT-5A",
        constants: tabulated(
            [121.0, 75.4, 75.2, 111.0, 21.1, 22.6],
            [-5.4, 15.8, 12.3],
            [8.11, 7.35],
        ),
        source: "Berlincourt, Curran & Jaffe, Physical Acoustics I-A (1964), Table 2 (ε^S = 916, 830 ε₀, in nF/m to 3 digits); the paper's block (Bouallala, Essoufi & Zafrar 2020)",
    },
    NamedCrystal {
        name: "PZT-5H",
        constants: tabulated(
            [126.0, 79.5, 84.1, 117.0, 23.0, 23.25],
            [-6.5, 23.3, 17.0],
            relative([1700.0, 1470.0]),
        ),
        source: "Berlincourt, Curran & Jaffe, Physical Acoustics I-A (1964), Table 2 (c66 = (c11 - c12)/2)",
    },
    NamedCrystal {
        name: "BaTiO3",
        constants: tabulated(
            [150.0, 66.0, 66.0, 146.0, 44.0, 42.0],
            [-4.35, 17.5, 11.4],
            relative([1115.0, 1260.0]),
        ),
        source: "poled ceramic: Berlincourt & Jaffe, Phys. Rev. 111 (1958) 143, as tabulated by Jaffe, Cook & Jaffe, Piezoelectric Ceramics (1971)",
    },
    NamedCrystal {
        name: "AlN",
        constants: tabulated(
            [345.0, 125.0, 120.0, 395.0, 118.0, 110.0],
            [-0.58, 1.55, -0.48],
            relative([8.0, 9.5]),
        ),
        source: "Tsubouchi, Sugai & Mikoshiba, IEEE Ultrasonics Symp. (1981) and Tsubouchi & Mikoshiba, IEEE Trans. Sonics Ultrason. 32 (1985) 634 (c66 = (c11 - c12)/2)",
    },
];

/// The library's crystal named `name` (letter case aside).
pub fn named(name: &str) -> Option<&'static NamedCrystal> {
    LIBRARY.iter().find(|c| c.name.eq_ignore_ascii_case(name))
}

/// A material in the strain-charge form a datasheet gives, for class 6mm: the piezoelectric
/// `d` (pC/N) or `g` (10⁻³ V·m/N) constants `[_31, _33, _15]`, the compliances at constant
/// field `s^E` or at constant displacement `s^D` (1/TPa, that is pm²/N)
/// `[s11, s12, s13, s33, s44, s66]`, and the free relative permittivity `ε^T/ε₀`
/// `[ε11, ε33]`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Datasheet {
    /// `[d31, d33, d15]`, pC/N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d: Option<[f64; 3]>,
    /// `[g31, g33, g15]`, 10⁻³ V·m/N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g: Option<[f64; 3]>,
    /// `s^E = [s11, s12, s13, s33, s44, s66]`, 1/TPa.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub s_e: Option<[f64; 6]>,
    /// `s^D = [s11, s12, s13, s33, s44, s66]`, 1/TPa.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub s_d: Option<[f64; 6]>,
    /// `ε^T/ε₀ = [ε11, ε33]`.
    pub relative_permittivity_t: [f64; 2],
}

type M6 = nalgebra::Matrix6<f64>;
type M36 = nalgebra::Matrix3x6<f64>;
type M3 = nalgebra::Matrix3<f64>;

/// The 6 x 6 Voigt matrix of a 6mm compliance or stiffness `[x11, x12, x13, x33, x44, x66]`.
fn voigt(x: [f64; 6]) -> M6 {
    let [x11, x12, x13, x33, x44, x66] = x;
    let mut m = M6::zeros();
    m[(0, 0)] = x11;
    m[(1, 1)] = x11;
    m[(0, 1)] = x12;
    m[(1, 0)] = x12;
    for (i, j) in [(0, 2), (2, 0), (1, 2), (2, 1)] {
        m[(i, j)] = x13;
    }
    m[(2, 2)] = x33;
    m[(3, 3)] = x44;
    m[(4, 4)] = x44;
    m[(5, 5)] = x66;
    m
}

/// The 3 x 6 matrix of 6mm piezoelectric constants `[x31, x33, x15]`.
fn piezo(x: [f64; 3]) -> M36 {
    let mut m = M36::zeros();
    m[(2, 0)] = x[0];
    m[(2, 1)] = x[0];
    m[(2, 2)] = x[1];
    m[(0, 4)] = x[2];
    m[(1, 3)] = x[2];
    m
}

/// The diagonal 3 x 3 matrix of `[x11, x33]`.
fn dielectric(x: [f64; 2]) -> M3 {
    M3::from_diagonal(&nalgebra::Vector3::new(x[0], x[0], x[1]))
}

impl Datasheet {
    /// The stress-charge form, in the GPa system (IEEE Std 176's identities, computed in SI).
    ///
    /// # Errors
    /// In words: neither or both of `d` and `g`, or of `s_e` and `s_d`; a number not finite; a
    /// permittivity not positive; compliances not positive definite (a singular `s`).
    pub fn stress_charge(&self) -> Result<StressCharge, String> {
        let numbers = self.d.iter().chain(&self.g).flatten();
        let numbers = numbers.chain(self.s_e.iter().chain(&self.s_d).flatten());
        if let Some(x) = numbers.chain(&self.relative_permittivity_t).find(|x| !x.is_finite()) {
            return Err(format!("material.datasheet: {x} is not a finite number"));
        }
        if self.relative_permittivity_t.iter().any(|&e| e <= 0.0) {
            return Err(format!(
                "material.datasheet.relative_permittivity_t = {:?} must be positive",
                self.relative_permittivity_t
            ));
        }
        let eps_t = dielectric(self.relative_permittivity_t) * EPSILON_0;
        let d = match (self.d, self.g) {
            (Some(d), None) => piezo(d) * 1e-12,
            // d = ε^T g
            (None, Some(g)) => eps_t * piezo(g) * 1e-3,
            _ => return Err("material.datasheet takes d (pC/N) or g (10⁻³ V·m/N), one of them".into()),
        };
        let s_e = match (self.s_e, self.s_d) {
            (Some(s), None) => voigt(s) * 1e-12,
            // s^E = s^D + dᵀ g, g = (ε^T)⁻¹ d
            (None, Some(s)) => {
                let beta = eps_t.try_inverse().ok_or("material.datasheet: a singular ε^T")?;
                voigt(s) * 1e-12 + d.transpose() * beta * d
            }
            _ => return Err("material.datasheet takes s_e or s_d (1/TPa), one of them".into()),
        };
        if s_e.cholesky().is_none() {
            return Err(
                "material.datasheet: the compliances s^E are not positive definite (check their signs: s12 and s13 are negative for most ceramics)"
                    .into(),
            );
        }
        let c = s_e.try_inverse().ok_or("material.datasheet: a singular s^E")?;
        let e = d * c;
        let eps_s = eps_t - d * c * d.transpose();
        if eps_s[(0, 0)] <= 0.0 || eps_s[(2, 2)] <= 0.0 {
            return Err(format!(
                "material.datasheet: the clamped permittivity ε^S = ε^T - d c^E dᵀ is not positive ({:.3e}, {:.3e} F/m): d too large for s and ε^T",
                eps_s[(0, 0)],
                eps_s[(2, 2)]
            ));
        }
        Ok(StressCharge {
            c: [c[(0, 0)], c[(0, 1)], c[(0, 2)], c[(2, 2)], c[(3, 3)], c[(5, 5)]].map(|x| x * 1e-9),
            e: [e[(2, 0)], e[(2, 2)], e[(0, 4)]],
            permittivity: [eps_s[(0, 0)], eps_s[(2, 2)]].map(|x| x * 1e9),
        })
    }

    /// The datasheet of a stress-charge material, with `d` and `s^E` (the inverse
    /// conversion: `s^E = (c^E)⁻¹`, `d = e s^E`, `ε^T = ε^S + d c^E dᵀ`).
    pub fn of(m: &StressCharge) -> Option<Datasheet> {
        let c = voigt(m.c) * 1e9;
        let s = c.try_inverse()?;
        let d = piezo(m.e) * s;
        let eps_t = dielectric(m.permittivity) * 1e-9 + d * c * d.transpose();
        Some(Datasheet {
            d: Some([d[(2, 0)] * 1e12, d[(2, 2)] * 1e12, d[(0, 4)] * 1e12]),
            g: None,
            s_e: Some([s[(0, 0)], s[(0, 1)], s[(0, 2)], s[(2, 2)], s[(3, 3)], s[(5, 5)]].map(|x| x * 1e12)),
            s_d: None,
            relative_permittivity_t: [eps_t[(0, 0)] / EPSILON_0, eps_t[(2, 2)] / EPSILON_0],
        })
    }
}

impl StressCharge {
    /// The constants in `units`: `(c, e, permittivity)`.
    pub fn in_units(&self, units: CrystalUnits) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (sc, se, sp) = units.factors();
        (
            self.c.iter().map(|x| x * sc).collect(),
            self.e.iter().map(|x| x * se).collect(),
            self.permittivity.iter().map(|x| x * sp).collect(),
        )
    }
}

/// A `[[material]]` entry as written: the constants given, or a crystal by name, or a
/// datasheet, resolved into [`MaterialSpec`] once when the scene is read.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialInput {
    region: String,
    #[serde(default)]
    model: Option<MaterialModel>,
    #[serde(default)]
    c: Vec<f64>,
    #[serde(default)]
    e: Vec<f64>,
    #[serde(default)]
    permittivity: Vec<f64>,
    #[serde(default)]
    poling: Vec<f64>,
    #[serde(default)]
    young: Option<f64>,
    #[serde(default)]
    poisson: Option<f64>,
    #[serde(default)]
    coupling_scale: Option<f64>,
    #[serde(default)]
    crystal: Option<String>,
    #[serde(default)]
    datasheet: Option<Datasheet>,
    #[serde(default)]
    units: Option<CrystalUnits>,
}

impl TryFrom<MaterialInput> for MaterialSpec {
    type Error = String;

    fn try_from(m: MaterialInput) -> Result<Self, String> {
        let sourced = match (&m.crystal, &m.datasheet) {
            (Some(_), Some(_)) => {
                return Err(
                    "material.crystal and material.datasheet: give one (a crystal by name, or its datasheet)".into(),
                )
            }
            (Some(name), None) => Some(
                named(name)
                    .map(|c| c.constants)
                    .ok_or_else(|| format!("material.crystal `{name}` is not in the library ({})", names()))?,
            ),
            (None, Some(sheet)) => Some(sheet.stress_charge()?),
            (None, None) => None,
        };
        let Some(constants) = sourced else {
            if m.units.is_some() {
                return Err(
                    "material.units names the units of a crystal by name or of a datasheet (material.crystal, material.datasheet); this material gives its constants itself".into(),
                );
            }
            let model = m.model.ok_or(
                "material.model is missing (crystal-6mm or isotropic; or material.crystal, a crystal by name)",
            )?;
            return Ok(MaterialSpec {
                region: m.region,
                model,
                c: m.c,
                e: m.e,
                permittivity: m.permittivity,
                poling: m.poling,
                young: m.young,
                poisson: m.poisson,
                coupling_scale: m.coupling_scale,
                crystal: None,
                datasheet: None,
                units: None,
            });
        };
        let what = if m.crystal.is_some() {
            "material.crystal"
        } else {
            "material.datasheet"
        };
        if m.model.is_some_and(|model| model != MaterialModel::Crystal6mm) {
            return Err(format!(
                "{what} gives a crystal of class 6mm, and material.model = \"{}\"",
                m.model.map_or("", |x| x.name())
            ));
        }
        if m.young.is_some() || m.poisson.is_some() {
            return Err(format!("{what} gives a crystal's constants, and material.young or material.poisson an isotropic solid's: remove them"));
        }
        let units = m.units.ok_or_else(|| {
            format!("{what} needs material.units, the unit system of the scene's other numbers: \"GPa\" (GPa, C/m², nF/m: the shipped scenes') or \"SI\" (Pa, C/m², F/m)")
        })?;
        let (c, e, permittivity) = constants.in_units(units);
        // the constants written beside the name (a scene written back out) must be its own
        for (key, given, own) in [
            ("material.c", &m.c, &c),
            ("material.e", &m.e, &e),
            ("material.permittivity", &m.permittivity, &permittivity),
        ] {
            if !given.is_empty() && given != own {
                return Err(format!(
                    "{what} brings its own {}, and {key} = {given:?} gives others: remove {key} (`--set ~{key}`), or the crystal",
                    &key["material.".len()..]
                ));
            }
        }
        Ok(MaterialSpec {
            region: m.region,
            model: MaterialModel::Crystal6mm,
            c,
            e,
            permittivity,
            poling: m.poling,
            young: None,
            poisson: None,
            coupling_scale: m.coupling_scale,
            crystal: m.crystal.and_then(|n| named(&n)).map(|c| c.name.to_string()),
            datasheet: m.datasheet,
            units: Some(units),
        })
    }
}

/// The library's names, for messages.
pub fn names() -> String {
    LIBRARY.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
}

impl fmt::Display for NamedCrystal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.name, self.source)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PZT-5A and PZT-5H as a datasheet gives them (strain-charge: Erturk & Inman,
    /// Piezoelectric Energy Harvesting, Wiley 2011, Table E.1).
    fn pzt_5a_sheet() -> Datasheet {
        Datasheet {
            d: Some([-171.0, 374.0, 584.0]),
            s_e: Some([16.4, -5.74, -7.22, 18.8, 47.5, 44.3]),
            relative_permittivity_t: [1730.0, 1700.0],
            ..Default::default()
        }
    }

    fn pzt_5h_sheet() -> Datasheet {
        Datasheet {
            d: Some([-274.0, 593.0, 741.0]),
            s_e: Some([16.5, -4.78, -8.45, 20.7, 43.5, 42.6]),
            relative_permittivity_t: [3130.0, 3400.0],
            ..Default::default()
        }
    }

    /// The largest relative difference between two materials, constant by constant.
    fn worst(a: &StressCharge, b: &StressCharge) -> f64 {
        let pairs =
            a.c.iter()
                .zip(&b.c)
                .chain(a.e.iter().zip(&b.e))
                .chain(a.permittivity.iter().zip(&b.permittivity));
        pairs.map(|(x, y)| (x - y).abs() / y.abs()).fold(0.0, f64::max)
    }

    #[test]
    fn a_datasheet_converts_to_the_stress_charge_table_of_the_same_ceramic() {
        // two sources of each ceramic, measured and rounded apart: the conversion of the
        // strain-charge datasheet meets the stress-charge table within their rounding
        let a = pzt_5a_sheet().stress_charge().unwrap();
        let own = named("PZT-5A").unwrap().constants;
        assert!(worst(&a, &own) < 0.01, "PZT-5A: {:.3}", worst(&a, &own));
        let h = pzt_5h_sheet().stress_charge().unwrap();
        let own = named("pzt-5h").unwrap().constants;
        assert!(worst(&h, &own) < 0.03, "PZT-5H: {:.3}", worst(&h, &own));
        // the sign of each constant, and the clamped permittivity below the free one
        assert!(a.e[0] < 0.0 && a.e[1] > 0.0 && a.e[2] > 0.0);
        assert!(a.permittivity[1] < 1700.0 * EPSILON_0_NF);
    }

    #[test]
    fn the_conversion_and_its_inverse_are_one_identity() {
        for crystal in LIBRARY {
            let sheet = Datasheet::of(&crystal.constants).unwrap();
            let back = sheet.stress_charge().unwrap();
            assert!(
                worst(&back, &crystal.constants) < 1e-12,
                "{}: {:e}",
                crystal.name,
                worst(&back, &crystal.constants)
            );
        }
    }

    #[test]
    fn the_four_datasheet_forms_give_one_material() {
        // g = β^T d and s^D = s^E - dᵀ g (IEEE Std 176) written from the d, s^E sheet
        let sheet = pzt_5a_sheet();
        let eps_t = dielectric(sheet.relative_permittivity_t) * EPSILON_0;
        let d = piezo(sheet.d.unwrap()) * 1e-12;
        let g = eps_t.try_inverse().unwrap() * d;
        let s_d = voigt(sheet.s_e.unwrap()) * 1e-12 - d.transpose() * g;
        let g3 = [g[(2, 0)] * 1e3, g[(2, 2)] * 1e3, g[(0, 4)] * 1e3];
        let sd6 = [
            s_d[(0, 0)],
            s_d[(0, 1)],
            s_d[(0, 2)],
            s_d[(2, 2)],
            s_d[(3, 3)],
            s_d[(5, 5)],
        ]
        .map(|x| x * 1e12);
        let reference = sheet.stress_charge().unwrap();
        for (dd, gg, se, sd) in [
            (None, Some(g3), sheet.s_e, None),
            (sheet.d, None, None, Some(sd6)),
            (None, Some(g3), None, Some(sd6)),
        ] {
            let other = Datasheet {
                d: dd,
                g: gg,
                s_e: se,
                s_d: sd,
                relative_permittivity_t: sheet.relative_permittivity_t,
            };
            let w = worst(&other.stress_charge().unwrap(), &reference);
            assert!(w < 1e-12, "{other:?}: {w:e}");
        }
        // the coupling factor two ways: k33² = d33² / (s33^E ε33^T) = 1 - s33^D / s33^E
        let k2 = (374e-12f64).powi(2) / (18.8e-12 * 1700.0 * EPSILON_0);
        assert!((k2 - (1.0 - sd6[3] / 18.8)).abs() < 1e-12, "{k2}");
        // a g33 of the datasheet's order (24.8e-3 V m/N for PZT-5A)
        assert!((g3[1] - 24.85).abs() < 0.1, "{}", g3[1]);
    }

    #[test]
    fn a_broken_datasheet_is_refused_in_words() {
        let mut sheet = pzt_5a_sheet();
        sheet.g = Some([1.0, 2.0, 3.0]);
        assert!(sheet.stress_charge().unwrap_err().contains("one of them"));
        let mut sheet = pzt_5a_sheet();
        sheet.s_e = Some([16.4, 5.74, 17.22, 18.8, 47.5, 44.3]);
        assert!(sheet.stress_charge().unwrap_err().contains("not positive definite"));
        let mut sheet = pzt_5a_sheet();
        sheet.relative_permittivity_t = [1730.0, f64::NAN];
        assert!(sheet.stress_charge().unwrap_err().contains("finite"));
        let mut sheet = pzt_5a_sheet();
        sheet.d = Some([-171.0, 3740.0, 584.0]);
        assert!(sheet.stress_charge().unwrap_err().contains("not positive"));
    }
}
