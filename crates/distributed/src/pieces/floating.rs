//! Floating terminals on pieces: a conductor whose one potential is unknown and whose charge
//! is given, its group spread over several ranks.
//!
//! The whole mesh's dof map ties the group's potentials to one free unknown, numbered after the
//! others; its row is the group's rows summed, its right-hand side the charge. On pieces no rank
//! holds the group, so each piece's dof map is untied (a potential at each node, as without the
//! terminal: its loads are the nodes' own), and the layout ties them instead: every node of the
//! group puts its potential's row and column into the terminal's one row, which the last rank
//! owns ([`crate::layout::Layout::phi_row`]). That row's right-hand side is the group's nodes'
//! `b_φ` summed over the ranks, less the charge, added once ([`crate::system`]). The terminals are
//! numbered by the scene (the order of their conditions), the same on every rank, whether or not
//! a piece touches them.

use fe_assembly::{Discretization, Dof, Field, Load};
use problem::backend::Setup;

/// The run's floating terminals: each one's group and the charge put on it, the same on every
/// rank.
#[derive(Clone, Debug, Default)]
pub(crate) struct Floating {
    groups: Vec<String>,
    charges: Vec<f64>,
}

impl Floating {
    /// The terminals of `setup` (before its conditions are cut to a piece's), their charges
    /// taken out of its loads: a piece's loads are its nodes' own, and a charge is the whole
    /// group's, put on the terminal's row once.
    pub(crate) fn take(setup: &mut Setup) -> Floating {
        let mut groups: Vec<String> = vec![];
        for c in setup.constraints.iter().filter(|c| c.field == Field::Floating) {
            if !groups.contains(&c.group) {
                groups.push(c.group.clone());
            }
        }
        let mut charges = vec![0.0; groups.len()];
        setup.loads.retain(|l| match l {
            Load::TerminalCharge { group, charge } => {
                if let Some(t) = groups.iter().position(|g| g == group) {
                    charges[t] += charge;
                }
                false
            }
            _ => true,
        });
        Floating { groups, charges }
    }

    /// How many terminals the run has.
    pub(crate) fn len(&self) -> usize {
        self.groups.len()
    }

    /// Whether `group` is a floating terminal's.
    pub(crate) fn holds(&self, group: &str) -> bool {
        self.groups.iter().any(|g| g == group)
    }

    /// The charges on the terminals at an instant whose terminals' factor is `factor` (1 for a
    /// static run; a load path scales them with the prescribed potentials).
    pub(crate) fn charges(&self, factor: f64) -> Vec<f64> {
        self.charges.iter().map(|q| factor * q).collect()
    }

    /// Unties the piece's dof map (a potential of its own at each node of a terminal's group
    /// the piece holds) and returns the terminal each node's potential is tied to, with the
    /// run's count of terminals: [`crate::layout::Layout::of_piece`]'s `tie`.
    pub(crate) fn untie(&self, disc: &mut Discretization<'_>) -> (Vec<Option<usize>>, usize) {
        let d = &disc.dofs;
        let terminal_of = |j: usize| {
            d.floating
                .iter()
                .find(|(_, k)| *k == j)
                .and_then(|(g, _)| self.groups.iter().position(|h| h == g))
        };
        let tie: Vec<Option<usize>> = d
            .phi
            .iter()
            .map(|p| match *p {
                Dof::Free(j) => terminal_of(j),
                _ => None,
            })
            .collect();
        if let Some((untied, _)) = d.untied() {
            disc.dofs = untied;
        }
        (tie, self.len())
    }
}
