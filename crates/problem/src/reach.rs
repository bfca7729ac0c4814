//! The contact points that can touch. An indenter pushed to the depth `d` into a face (its
//! `depth` less the zone's `gap`) touches it where its profile `h` (its height above the tip,
//! [`ContactBoundary::profile_height`]) is below about `d / 2` (Hertz's sphere: `a = √(R d)`, `h(a) = d / 2`); a point whose
//! profile lies [`REACH`] depths or more above the tip is far out of that zone. A static run
//! with such points condenses only the others: the factor's trailing block, the condensed
//! compliance and the contact problem hold the points that can touch, and an indenter's small
//! zone costs little beside the body (issue 48, item 2). The points left out are open by
//! assumption; the fields of the solve check it ([`Reach::widen`]): where one of them would
//! pass through the indenter, the run is solved again with every point.

use crate::boundary::ContactBoundary;
use crate::scene::ContactSpec;
use contact::{ContactSolution, PointValues, Status};

/// How far above an indenter's tip (in depths) a point's profile may lie and the point still
/// be held in the contact problem: 3, six times the height of Hertz's contact edge (a
/// sphere's points within `√6 ≈ 2.4` contact radii; a cone's within `3 d tan θ ≈ 4.7` radii).
pub const REACH: f64 = 3.0;

/// The points are left out only where at most this fraction of them is kept: below, the
/// condensation costs about what it did with every point, and the check and its rare second
/// run would not pay.
const WORTH: f64 = 0.5;

/// A contact boundary narrowed to the points that can touch: the whole boundary, and which of
/// its points the narrowed one holds.
pub(crate) struct Reach {
    whole: ContactBoundary,
    keep: Vec<usize>,
}

/// Points left out of the contact problem that the solve's fields push through the
/// foundation: the contact problem needs them (a second run holds every point).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Beyond {
    /// How many.
    pub(crate) points: usize,
}

impl Reach {
    /// The points of `whole` that can touch, where a zone of `zones` (in the boundary's group
    /// order) is an indenter pushed into the face (its depth less the zone's gap, positive;
    /// force control's depth is an unknown: its zone keeps every point) and they are few enough to pay: the narrowed boundary beside what
    /// widens its solution. `None` where every point is kept, with electrical contact, and
    /// under Tresca's law (whose bound holds an open point's slip too).
    pub(crate) fn of(whole: &ContactBoundary, zones: &[&ContactSpec]) -> Option<(Reach, ContactBoundary)> {
        // Tresca's bound acts at a point whether it touches or not: no point is free of force
        let tresca = zones.iter().any(|z| z.law == crate::ContactLaw::Tresca);
        if tresca || whole.points.tresca.iter().any(Option::is_some) {
            return None;
        }
        // how far the tip presses into the undeformed face: its depth less the zone's gap
        let depth: Vec<Option<f64>> = zones
            .iter()
            .map(|z| match &z.indenter {
                Some(i) if i.force.is_none() => Some(-z.uniform_gap()).filter(|d| *d > 0.0 && d.is_finite()),
                _ => None,
            })
            .collect();
        let n = whole.points.len();
        let keep: Vec<usize> = (0..n)
            .filter(|&i| match depth.get(whole.group_of[i]).copied().flatten() {
                Some(d) => whole.profile_height(i) <= REACH * d,
                None => true,
            })
            .collect();
        if keep.is_empty() || keep.len() as f64 > WORTH * n as f64 {
            return None;
        }
        let part = whole.select(&keep)?;
        let reach = Reach {
            whole: whole.clone(),
            keep,
        };
        Some((reach, part))
    }

    /// `(kept, all)`: the points of the narrowed boundary, and of the whole.
    pub(crate) fn counts(&self) -> (usize, usize) {
        (self.keep.len(), self.whole.points.len())
    }

    /// Values of the narrowed boundary's points as values of the whole's, 0 at the points
    /// left out.
    pub(crate) fn spread(&self, v: &PointValues) -> PointValues {
        v.spread(&self.keep, self.whole.points.len())
    }

    /// One value per point of the narrowed boundary as one per point of the whole, 0 at the
    /// points left out.
    pub(crate) fn spread_each(&self, v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.whole.points.len()];
        for (&i, x) in self.keep.iter().zip(v) {
            out[i] = *x;
        }
        out
    }

    /// The solution `sol` on the narrowed boundary as one on the whole, with the fields' free
    /// displacements `u`: the points left out open (no force, [`Status::Separated`]), their
    /// displacement the fields'; the whole boundary beside it.
    ///
    /// # Errors
    /// [`Beyond`] where a point left out has its normal displacement past its gap in `u`.
    pub(crate) fn widen(&self, sol: ContactSolution, u: &[f64]) -> Result<(ContactBoundary, ContactSolution), Beyond> {
        let (whole, keep) = (&self.whole, &self.keep);
        let n = whole.points.len();
        let mut at = PointValues::zeros(n, whole.points.n_tangential());
        whole.extract(u, &mut at);
        let mut kept = vec![false; n];
        for &i in keep {
            kept[i] = true;
        }
        let points = (0..n)
            .filter(|&i| !kept[i] && at.normal[i] > whole.points.gap[i])
            .count();
        if points > 0 {
            return Err(Beyond { points });
        }
        let nt = sol.lambda.n_tangential();
        let mut displacement = if nt == at.n_tangential() {
            at
        } else {
            PointValues::from_parts(at.normal, vec![], 0).unwrap_or_else(|_| PointValues::zeros(n, nt))
        };
        for (j, &i) in keep.iter().enumerate() {
            displacement.normal[i] = sol.u.normal[j];
            if nt > 0 {
                displacement
                    .tangential_of_mut(i)
                    .copy_from_slice(sol.u.tangential_of(j));
            }
        }
        let mut status = vec![Status::Separated; n];
        for (&i, s) in keep.iter().zip(&sol.status) {
            status[i] = *s;
        }
        debug_assert!(sol.electric.is_none(), "a narrowed boundary has no electrical contact");
        let widened = ContactSolution {
            lambda: self.spread(&sol.lambda),
            u: displacement,
            status,
            info: sol.info,
            electric: sol.electric,
        };
        Ok((whole.clone(), widened))
    }
}
