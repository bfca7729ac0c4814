//! One contact zone's model, typed: what a validated `[[contact]]` entry's keys say, each
//! part an enum whose variants carry exactly their data (the normal law, friction, the
//! electric condition, the obstacle), so that what the run reads of a zone is a match, not a
//! set of optional keys ([`ContactSpec::model`]: parse, don't validate).

use super::{ContactLaw, ContactSpec, ElectricCondition, IndenterSpec};

/// A contact zone's model.
#[derive(Clone, Debug, PartialEq)]
pub struct ZoneModel {
    /// The normal law: Signorini's on a rigid foundation, or normal compliance.
    pub normal: contact::Foundation,
    /// The friction law.
    pub friction: Friction,
    /// The electric condition on the zone.
    pub electric: ZoneElectric,
    /// What the zone presses on.
    pub obstacle: Obstacle,
}

/// A zone's friction.
#[derive(Clone, Debug, PartialEq)]
pub enum Friction {
    /// None (Signorini's conditions alone).
    Frictionless,
    /// Tresca's, with its bound (uniform or along the zone).
    Tresca(ZoneBound),
    /// Coulomb's, with its coefficient.
    Coulomb(f64),
    /// Coulomb's with a coefficient that falls with the slip.
    SlipWeakening(contact::SlipWeakening),
}

/// A zone's electric condition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ZoneElectric {
    /// No flux through the zone.
    Insulated,
    /// A conductive foundation at the potential `potential`, with its conductance.
    Conductive {
        /// `σ_c ≥ 0`.
        conductance: f64,
        /// `φ_F`.
        potential: f64,
    },
    /// An ideal conductor held at `potential`.
    Conducting {
        /// `φ_F`.
        potential: f64,
    },
    /// A conductor (ideal, or conductive with its conductance) floating with the charge
    /// `charge`, its potential found (the search starting at `start`).
    Floating {
        /// The conductance of a conductive one; `None` for an ideal conductor.
        conductance: Option<f64>,
        /// The charge it carries.
        charge: f64,
        /// Where the search for its potential starts.
        start: f64,
    },
}

/// What a zone presses on.
#[derive(Clone, Debug, PartialEq)]
pub enum Obstacle {
    /// A flat foundation at the gap `gap`, parabolic about `center` where `curvature > 0`.
    Flat {
        /// The uniform gap.
        gap: f64,
        /// `1/R` of a parabolic gap (0: flat).
        curvature: f64,
        /// The parabola's centre.
        center: [f64; 3],
    },
    /// A rigid indenter, at a depth or pressed with a force.
    Indenter {
        /// Its shape and placement.
        spec: IndenterSpec,
        /// How it is driven.
        control: Control,
    },
}

/// How an indenter is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// At a given depth.
    Depth(f64),
    /// With a given force, its depth found.
    Force(f64),
}

impl ContactSpec {
    /// The zone's model; `None` for a zone switched off (`contact.law = "none"`). Read from a
    /// validated scene (the keys a law does not take are refused there; a missing value reads
    /// as its default).
    pub fn model(&self) -> Option<ZoneModel> {
        let friction = match self.law {
            ContactLaw::None => return None,
            ContactLaw::Signorini => Friction::Frictionless,
            ContactLaw::Tresca => Friction::Tresca(match &self.slip_bound_profile {
                Some(p) => ZoneBound::Profile(p.clone()),
                None => ZoneBound::Uniform(self.slip_bound()),
            }),
            ContactLaw::Coulomb => match self.slip_weakening() {
                Some(w) => Friction::SlipWeakening(w),
                None => Friction::Coulomb(self.friction()),
            },
        };
        let normal = match self.compliance {
            Some(k) => contact::Foundation::Compliant {
                stiffness: k.stiffness,
                exponent: k.exponent,
            },
            None => contact::Foundation::Rigid,
        };
        let potential = self.foundation_potential.unwrap_or(0.0);
        let conductance = self.conductance.unwrap_or(0.0);
        let electric = match (self.electric.unwrap_or(ElectricCondition::Insulated), self.charge) {
            (ElectricCondition::Insulated, _) => ZoneElectric::Insulated,
            (condition, Some(charge)) => ZoneElectric::Floating {
                conductance: (condition == ElectricCondition::Conductive).then_some(conductance),
                charge,
                start: potential,
            },
            (ElectricCondition::Conductive, None) => ZoneElectric::Conductive { conductance, potential },
            (ElectricCondition::Conducting, None) => ZoneElectric::Conducting { potential },
        };
        let obstacle = match &self.indenter {
            Some(spec) => Obstacle::Indenter {
                spec: spec.clone(),
                control: match spec.force {
                    Some(f) => Control::Force(f),
                    None => Control::Depth(spec.depth),
                },
            },
            None => {
                let c = self.gap_center.as_deref().unwrap_or_default();
                Obstacle::Flat {
                    gap: self.gap,
                    curvature: self.gap_curvature,
                    center: std::array::from_fn(|k| c.get(k).copied().unwrap_or(0.0)),
                }
            }
        };
        Some(ZoneModel {
            normal,
            friction,
            electric,
            obstacle,
        })
    }
}

/// Tresca's bound of one contact zone: uniform, or along the zone.
#[derive(Clone, Debug, PartialEq)]
pub enum ZoneBound {
    /// `contact.slip_bound`.
    Uniform(f64),
    /// `contact.slip_bound_profile`.
    Profile(super::SlipBoundProfile),
}

impl ZoneBound {
    /// The bound at the point `x`.
    pub fn at(&self, x: [f64; 3]) -> f64 {
        match self {
            ZoneBound::Uniform(s) => *s,
            ZoneBound::Profile(p) => p.at_point(x),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{ComplianceSpec, FrictionLaw, IndenterShape};

    /// Each key lands in its part of the model, and only there.
    #[test]
    fn a_zones_keys_become_its_model() {
        let mut c = ContactSpec::new("bottom", ContactLaw::Coulomb, &[0.0, -1.0]);
        c.friction = Some(0.3);
        c.compliance = Some(ComplianceSpec {
            stiffness: 10.0,
            exponent: 2.0,
        });
        c.gap = 0.1;
        c.gap_curvature = 0.5;
        c.gap_center = Some(vec![1.0, 0.0]);
        let m = c.model().unwrap();
        assert_eq!(m.friction, Friction::Coulomb(0.3));
        assert_eq!(
            m.normal,
            contact::Foundation::Compliant {
                stiffness: 10.0,
                exponent: 2.0
            }
        );
        assert_eq!(m.electric, ZoneElectric::Insulated);
        assert_eq!(
            m.obstacle,
            Obstacle::Flat {
                gap: 0.1,
                curvature: 0.5,
                center: [1.0, 0.0, 0.0]
            }
        );
        // slip weakening, a floating conductive tip under force control
        c.friction_law = Some(FrictionLaw::SlipWeakening);
        (c.friction_static, c.friction_dynamic, c.slip_length) = (Some(0.6), Some(0.2), Some(1e-3));
        c.electric = Some(ElectricCondition::Conductive);
        (c.conductance, c.charge, c.foundation_potential) = (Some(2.0), Some(-1e-3), Some(0.5));
        c.indenter = Some(IndenterSpec {
            shape: IndenterShape::Sphere,
            radius: Some(1.0),
            half_angle: None,
            profile: None,
            tip: None,
            axis: None,
            depth: 0.0,
            force: Some(3.0),
        });
        let m = c.model().unwrap();
        assert!(
            matches!(m.friction, Friction::SlipWeakening(w) if w.static_coefficient == 0.6 && w.dynamic_coefficient == 0.2)
        );
        assert_eq!(
            m.electric,
            ZoneElectric::Floating {
                conductance: Some(2.0),
                charge: -1e-3,
                start: 0.5
            }
        );
        assert!(matches!(m.obstacle, Obstacle::Indenter { control: Control::Force(f), .. } if f == 3.0));
        // Tresca's bound; a zone switched off has no model
        let mut t = ContactSpec::new("top", ContactLaw::Tresca, &[0.0, 1.0]);
        t.slip_bound = Some(0.2);
        assert_eq!(t.model().unwrap().friction, Friction::Tresca(ZoneBound::Uniform(0.2)));
        t.electric = Some(ElectricCondition::Conducting);
        assert_eq!(t.model().unwrap().electric, ZoneElectric::Conducting { potential: 0.0 });
        assert!(ContactSpec::new("top", ContactLaw::None, &[0.0, 1.0]).model().is_none());
    }
}
