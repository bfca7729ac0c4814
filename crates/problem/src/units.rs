//! The scene's unit system and the unit of every quantity a run reports.
//!
//! The equations are homogeneous: a scene's numbers may be in any consistent system, and the
//! solver never converts them. A system is fixed by a unit of length `L` and a unit of stress
//! `S` (`[units]`: `length`, `stress`; SI, m and Pa, where the scene says nothing), the
//! piezoelectric constants always in C/m². The rest follows (docs/scenes.md, "Units"):
//! permittivity in F/m divided by `S`'s factor (nF/m for GPa), potentials in V times the
//! factors of `S` and `L` (GV for GPa and m, kV for GPa and µm, V for GPa and nm), electric
//! fields in V/m times `S`'s factor, electric displacements and fluxes in C/m², forces in N
//! times `S L²` (per unit thickness in plane strain: divided by `L`), charges in C times `L²`
//! (plane strain: divided by `L`), a piezoresponse (displacement per potential) in m/V divided
//! by `S`'s factor, reported in pm/V.

use crate::scene::{choice, Scene};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

choice! {
    /// A unit of length (`units.length`).
    pub enum LengthUnit ("units.length") {
        /// Metres.
        M = "m",
        /// Millimetres.
        Mm = "mm",
        /// Micrometres.
        Um = "um",
        /// Nanometres.
        Nm = "nm",
    }
}

choice! {
    /// A unit of stress (`units.stress`): of stiffness, pressure and contact tractions.
    pub enum StressUnit ("units.stress") {
        /// Pascals.
        Pa = "Pa",
        /// Kilopascals.
        Kpa = "kPa",
        /// Megapascals.
        Mpa = "MPa",
        /// Gigapascals.
        Gpa = "GPa",
    }
}

impl LengthUnit {
    /// The power of ten of the unit in metres.
    pub fn exponent(self) -> i32 {
        match self {
            LengthUnit::M => 0,
            LengthUnit::Mm => -3,
            LengthUnit::Um => -6,
            LengthUnit::Nm => -9,
        }
    }
}

impl StressUnit {
    /// The stress unit of a named or datasheet material's system (`material.units`).
    pub fn of_crystals(units: crate::CrystalUnits) -> Self {
        match units {
            crate::CrystalUnits::Gpa => StressUnit::Gpa,
            crate::CrystalUnits::Si => StressUnit::Pa,
        }
    }

    /// The power of ten of the unit in pascals.
    pub fn exponent(self) -> i32 {
        match self {
            StressUnit::Pa => 0,
            StressUnit::Kpa => 3,
            StressUnit::Mpa => 6,
            StressUnit::Gpa => 9,
        }
    }
}

/// A scene's unit system (`[units]`): each unit SI where not given.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct UnitsSpec {
    /// The unit of every length and displacement (metres by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<LengthUnit>,
    /// The unit of stiffness, pressure and tractions (pascals by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<StressUnit>,
}

/// The unit of each quantity a run reports (`run.json`'s `units`), from the scene's system.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Units {
    /// The unit of length.
    pub length: String,
    /// The unit of stress.
    pub stress: String,
    /// Whether the scene states its system (`[units]`, or a named crystal's
    /// `material.units`); SI is assumed where it does not.
    pub stated: bool,
    /// The unit of each quantity, by name: `length`, `displacement`, `stress`, `stiffness`,
    /// `pressure`, `traction`, `piezoelectric`, `permittivity`, `potential`,
    /// `electric_field`, `electric_displacement`, `flux`, `force`, `charge`, `piezoresponse`.
    pub quantities: BTreeMap<String, String>,
    /// The factor from the scene's displacement per potential to pm/V (a piezoresponse).
    pub pm_per_volt: f64,
    /// Where the materials' stiffness is no solid's in the stated (or assumed) system: what
    /// is wrong, and how to state the system.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl Units {
    /// The units of `scene` (its `[units]`, else its named crystals' `material.units`, else
    /// SI) in a body of dimension `dim`: plane strain (2D, not of revolution) reports forces
    /// and charges per unit thickness.
    pub fn of(scene: &Scene, dim: usize) -> Self {
        let spec = scene.units.unwrap_or_default();
        let from_crystals = scene.material.iter().find_map(|m| m.units).map(StressUnit::of_crystals);
        let length = spec.length.unwrap_or(LengthUnit::M);
        let stress = spec.stress.or(from_crystals).unwrap_or(StressUnit::Pa);
        let stated = scene.units.is_some() || from_crystals.is_some();
        let per_thickness = dim == 2 && !scene.mesh.axisymmetric;
        let mut units = Units::system(length, stress, per_thickness);
        units.stated = stated;
        units.note = stiffness_note(scene, stress, stated);
        units
    }

    /// The units of the system (`length`, `stress`); `per_thickness`: forces and charges per
    /// unit thickness (plane strain).
    pub fn system(length: LengthUnit, stress: StressUnit, per_thickness: bool) -> Self {
        let (l, s) = (length.exponent(), stress.exponent());
        let len = prefixed(l, "m");
        let potential = prefixed(s + l, "V");
        let (mut force, mut charge) = (prefixed(s + 2 * l, "N"), prefixed(2 * l, "C"));
        if per_thickness {
            force = format!("{force}/{len}");
            charge = format!("{charge}/{len}");
        }
        let stress_name = stress.name().to_string();
        let quantities = [
            ("length", len.clone()),
            ("displacement", len.clone()),
            ("stress", stress_name.clone()),
            ("stiffness", stress_name.clone()),
            ("pressure", stress_name.clone()),
            ("traction", stress_name.clone()),
            ("piezoelectric", "C/m²".to_string()),
            ("permittivity", prefixed(-s, "F/m")),
            ("potential", potential.clone()),
            ("electric_field", format!("{potential}/{len}")),
            ("electric_displacement", "C/m²".to_string()),
            ("flux", "C/m²".to_string()),
            ("force", force),
            ("charge", charge),
            ("piezoresponse", "pm/V".to_string()),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        Units {
            length: len,
            stress: stress_name,
            stated: true,
            quantities,
            pm_per_volt: 10f64.powi(12 - s),
            note: None,
        }
    }

    /// The unit of `quantity` ("" where it has none: a count, a factor, a relative residual).
    pub fn of_quantity(&self, quantity: &str) -> &str {
        self.quantities.get(quantity).map_or("", String::as_str)
    }

    /// `label [unit]`, or `label` alone where `quantity` has no unit.
    pub fn label(&self, label: &str, quantity: &str) -> String {
        match self.of_quantity(quantity) {
            "" => label.to_string(),
            unit => format!("{label} [{unit}]"),
        }
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "units: lengths in {}, stresses in {}, potentials in {}, forces in {}, charges in {}{}",
            self.length,
            self.stress,
            self.of_quantity("potential"),
            self.of_quantity("force"),
            self.of_quantity("charge"),
            if self.stated {
                ""
            } else {
                " (SI assumed: the scene states no [units])"
            }
        )
    }
}

/// `unit` with the SI prefix of `10^exponent` (a multiple of 3 from -18 to 18), else
/// `1e{exponent} unit`.
fn prefixed(exponent: i32, unit: &str) -> String {
    const PREFIXES: [&str; 13] = ["a", "f", "p", "n", "µ", "m", "", "k", "M", "G", "T", "P", "E"];
    match usize::try_from(exponent + 18) {
        Ok(k) if exponent % 3 == 0 && k / 3 < PREFIXES.len() => format!("{}{unit}", PREFIXES[k / 3]),
        _ => format!("1e{exponent} {unit}"),
    }
}

/// Pascals no solid's stiffness is below (a soft gel's is about 1 kPa).
const SOFTEST: f64 = 1e3;
/// Pascals no solid's stiffness is above (diamond's c11 is about 1.1e12 Pa).
const STIFFEST: f64 = 1e13;

/// Where the largest stiffness of the materials (`material.c`, `material.young`), in the
/// unit `stress`, is outside any solid's: the note that says so and how to state the system.
fn stiffness_note(scene: &Scene, stress: StressUnit, stated: bool) -> Option<String> {
    let largest = scene
        .material
        .iter()
        .flat_map(|m| m.c.iter().copied().chain(m.young))
        .map(f64::abs)
        .fold(0.0, f64::max);
    if largest == 0.0 {
        return None;
    }
    let pascals = largest * 10f64.powi(stress.exponent());
    if (SOFTEST..=STIFFEST).contains(&pascals) {
        return None;
    }
    // the unit that puts it at a ceramic's 100 GPa
    let guess = StressUnit::ALL
        .iter()
        .copied()
        .min_by_key(|u| ((largest * 10f64.powi(u.exponent())).log10() - 11.0).abs() as i64)
        .unwrap_or(StressUnit::Pa);
    let how = if stated {
        format!("in the scene's unit of stress, {}", stress.name())
    } else {
        "in pascals, which the scene assumes by stating no [units]".to_string()
    };
    Some(format!(
        "the materials' stiffness, up to {largest:e} in the scene's numbers, is {pascals:e} Pa {how}: no solid's; if the numbers are in {}, state it: [units] stress = \"{}\"",
        guess.name(),
        guess.name()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The systems the shipped scenes use: GPa with m (potentials in GV), with µm (kV, forces
    /// in mN, charges in pC), with nm (V); SI; and plane strain's per unit thickness.
    #[test]
    fn derived_units_follow_from_length_and_stress() {
        let u = Units::system(LengthUnit::M, StressUnit::Gpa, false);
        assert_eq!(u.of_quantity("potential"), "GV");
        assert_eq!(u.of_quantity("permittivity"), "nF/m");
        assert_eq!(u.of_quantity("force"), "GN");
        assert_eq!(u.of_quantity("electric_field"), "GV/m");
        let u = Units::system(LengthUnit::Um, StressUnit::Gpa, false);
        assert_eq!(u.of_quantity("potential"), "kV");
        assert_eq!(u.of_quantity("force"), "mN");
        assert_eq!(u.of_quantity("charge"), "pC");
        assert_eq!(u.of_quantity("displacement"), "µm");
        assert_eq!(u.pm_per_volt, 1e3);
        let u = Units::system(LengthUnit::Nm, StressUnit::Gpa, false);
        assert_eq!(u.of_quantity("potential"), "V");
        assert_eq!(u.of_quantity("force"), "nN");
        let u = Units::system(LengthUnit::M, StressUnit::Pa, true);
        assert_eq!(u.of_quantity("potential"), "V");
        assert_eq!(u.of_quantity("force"), "N/m");
        assert_eq!(u.of_quantity("charge"), "C/m");
        assert_eq!(u.of_quantity("permittivity"), "F/m");
        assert_eq!(u.pm_per_volt, 1e12);
        assert_eq!(u.label("x", "length"), "x [m]");
        assert_eq!(u.label("n", "count"), "n");
    }

    /// A consistent system leaves every equation's terms in one unit: `e E` and `c ε` both in
    /// the stress unit (`C/m² × potential/length` against the stress's factor), `ε E` and `e ε`
    /// both in C/m² (`permittivity × potential / length`); force = stress × area; charge =
    /// C/m² × area. Checked on every pair of units, by their powers of ten.
    #[test]
    fn every_system_is_consistent() {
        for &l in LengthUnit::ALL {
            for &s in StressUnit::ALL {
                let (le, se) = (l.exponent(), s.exponent());
                let potential = se + le;
                // e E: C/m² × 10^(potential - length) V/m = 10^(potential - le) Pa
                assert_eq!(potential - le, se);
                // ε E: 10^-se F/m × 10^(potential - le) V/m = 10^0 C/m²
                assert_eq!(-se + potential - le, 0);
                let u = Units::system(l, s, false);
                assert!(!u.of_quantity("force").starts_with("1e"), "{l} {s}");
                assert!(!u.of_quantity("potential").starts_with("1e"), "{l} {s}");
            }
        }
        assert_eq!(prefixed(-21, "C"), "1e-21 C");
        assert_eq!(prefixed(4, "N"), "1e4 N");
    }
}
