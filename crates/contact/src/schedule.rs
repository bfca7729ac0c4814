//! Newton's schedule: the stages a solve may run, in order, each only where the ones before
//! stalled (and where its own condition on the problem holds: sweeps on a compliance that is
//! not a condensed finite-element one, the nested start from zero multipliers on a dense one,
//! the lenient Newton on a sparse or asymmetric one), built once from the class of the
//! problem ([`Schedule::of`]). The parameters keep tolerances and budgets only; the solution
//! lists the stages that ran ([`crate::ContactInfo::stages`]).

/// A stage of Newton's schedule (docs/theory.md, "Semismooth Newton").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Stage 0: block Gauss–Seidel sweeps first, while their measured rate promises the
    /// tolerance within some Newton steps' cost (a compliance that is not a condensed
    /// finite-element one, constant friction coefficients).
    Sweeps,
    /// Newton's start from the answer of the problem on a coarser set of its points (a solve
    /// from zero multipliers on a dense compliance).
    NestedStart,
    /// Stage 1: Newton on the problem itself, with its patience rule.
    Newton,
    /// Stage 2: the proximal point method around Newton.
    Proximal,
    /// Stage 2b: Newton again from stage 1's best under lenient rules (a sparse or asymmetric
    /// compliance).
    Lenient,
    /// Stage 3: the first-order fallback (block Gauss–Seidel for Coulomb's law, the
    /// accelerated projected gradient for the convex laws), for a constant friction
    /// coefficient.
    Fallback,
}

impl Phase {
    /// Every stage, in the order a solve runs them.
    pub const ALL: [Phase; 6] = [
        Phase::Sweeps,
        Phase::NestedStart,
        Phase::Newton,
        Phase::Proximal,
        Phase::Lenient,
        Phase::Fallback,
    ];

    /// Lower-case name (`sweeps`, `nested-start`, `newton`, `proximal`, `lenient`,
    /// `fallback`).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Sweeps => "sweeps",
            Phase::NestedStart => "nested-start",
            Phase::Newton => "newton",
            Phase::Proximal => "proximal",
            Phase::Lenient => "lenient",
            Phase::Fallback => "fallback",
        }
    }

    fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

/// The class of a contact problem, which names its schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProblemClass {
    /// A condensed finite-element compliance (dense, symmetric): the nested start, Newton, the
    /// proximal stage, the fallback.
    CondensedFe,
    /// A multibody Delassus operator (sparse, possibly asymmetric or singular): sweeps first,
    /// Newton, the proximal stage, the lenient Newton, the fallback.
    Multibody,
    /// Electrical contact (mechanical and electric rows together, started from the alternating
    /// fixed point, whose insulated candidate takes the nested start): Newton and the proximal
    /// stage; the first-order solvers hold no electric rows.
    CoupledElectric,
    /// Slip-weakening friction solved directly (a coefficient that moves with the slip): the
    /// nested start, Newton, the proximal stage; the first-order solvers hold a constant
    /// coefficient.
    SlipWeakening,
}

/// The stages a Newton solve may run ([`Phase`]), in their fixed order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Schedule {
    phases: u8,
}

impl Schedule {
    /// The schedule of a class of problems.
    pub fn of(class: ProblemClass) -> Schedule {
        use Phase::*;
        let phases: &[Phase] = match class {
            ProblemClass::CondensedFe => &[NestedStart, Newton, Proximal, Fallback],
            ProblemClass::Multibody => &[Sweeps, Newton, Proximal, Lenient, Fallback],
            ProblemClass::CoupledElectric => &[NestedStart, Newton, Proximal],
            ProblemClass::SlipWeakening => &[NestedStart, Newton, Proximal],
        };
        Schedule {
            phases: phases.iter().fold(0, |m, p| m | p.bit()),
        }
    }

    /// Every stage, each where its own condition on the problem holds (a problem of unknown
    /// class).
    pub fn all() -> Schedule {
        Schedule {
            phases: Phase::ALL.iter().fold(0, |m, p| m | p.bit()),
        }
    }

    /// Whether the schedule holds `phase`.
    pub fn has(self, phase: Phase) -> bool {
        self.phases & phase.bit() != 0
    }

    /// The schedule without `phase`.
    pub fn without(self, phase: Phase) -> Schedule {
        Schedule {
            phases: self.phases & !phase.bit(),
        }
    }

    /// Its stages, in order.
    pub fn phases(self) -> impl Iterator<Item = Phase> {
        Phase::ALL.into_iter().filter(move |p| self.has(*p))
    }
}

impl Default for Schedule {
    fn default() -> Self {
        Schedule::all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_class_names_its_stages_in_order() {
        let names = |c| Schedule::of(c).phases().map(Phase::name).collect::<Vec<_>>();
        assert_eq!(
            names(ProblemClass::CondensedFe),
            ["nested-start", "newton", "proximal", "fallback"]
        );
        assert_eq!(
            names(ProblemClass::Multibody),
            ["sweeps", "newton", "proximal", "lenient", "fallback"]
        );
        assert_eq!(
            names(ProblemClass::CoupledElectric),
            ["nested-start", "newton", "proximal"]
        );
        assert_eq!(
            names(ProblemClass::SlipWeakening),
            ["nested-start", "newton", "proximal"]
        );
        let s = Schedule::all().without(Phase::Fallback);
        assert!(!s.has(Phase::Fallback) && s.has(Phase::Sweeps));
        assert_eq!(s.phases().count(), 5);
    }
}
