//! The ideal conductor's member: a rigid foundation that conducts ideally
//! ([`crate::ElectricLaw::Conducting`]) poses a problem with a family of solutions, since a
//! point entering contact brings its potential condition with it. At a potential `ψ` of the
//! foundation, the contact zone may carry a pressure singularity at its edge that the charge's
//! own singularity keeps from interpenetrating, so every zone between the narrowest (the edge's
//! deflection without singularity) and the widest (its pressure without singularity) solves
//! the conditions (docs/theory.md, "The ideal conductor's member"). Newton lands on one of
//! them, chosen by where the mesh's nodes fall. The closed forms of indentation (and the
//! physics: a pressure that vanishes at the edge of a smooth indenter) take the widest, which
//! [`widest`] selects on purpose: from the member Newton found, the zone is grown by its
//! nearest separated points as long as the grown zone is a solution.

use super::equations::weighted_norm;
use super::{newton_steps, Directions, Judge, Rules, State, PATIENCE};
use crate::{ContactInfo, NewtonParams};

/// How much nearer than the nearest a separated point's distance may be and still enter
/// together with it (the points a symmetric mesh places at one distance).
const TIE: f64 = 1e-9;

/// Newton steps a trial zone may take: its equations are those of one active set where the
/// other points keep theirs, solved in one step from the member beside it (measured: 1 to 3
/// on the indentation scenes).
const TRIAL_STEPS: usize = 30;

/// Grows the contact zone of `best`, a solution of `judge`'s problem (residual `residual`),
/// by its nearest separated points while the grown zone solves the conditions: the widest
/// member of the family. A trial holds the entering points in contact (their normal rows
/// `u_n = g`, their electric rows at the foundation's potential) and solves by Newton from
/// `best`; it is a member where its entering points are pressed (`λ_n ≥ 0`) and it solves the
/// problem itself to the tolerance. Returns the widest member found and its residual; `info`
/// counts the trials' Newton steps; `directions` is the problem's factorisation, shared.
pub(super) fn widest(
    judge: &Judge<'_>,
    mut best: State,
    mut residual: f64,
    params: &NewtonParams,
    info: &mut ContactInfo,
    directions: &mut Option<Directions>,
) -> (State, f64) {
    let directions = directions.get_or_insert_with(|| Directions::new(&judge.flat)).clone();
    let rules = Rules {
        steps: TRIAL_STEPS,
        patience: PATIENCE,
        lenient: false,
        seed: None,
        cycles: false,
    };
    while let Some(entering) = nearest_separated(judge, &best) {
        let mut trial = judge.flat.clone();
        trial.forced = vec![false; trial.n];
        entering.iter().for_each(|&i| trial.forced[i] = true);
        // the held zone's equations solved: to round-off in the norm of the multipliers
        let mut solved = |s: &State, _: &mut ContactInfo| s.norm <= 1e-13 * weighted_norm(&s.x, &trial.w);
        let start = trial.state(best.x.clone());
        let (end_state, _) = newton_steps(&trial, &directions, start, rules, &params.interrupt, info, &mut solved);
        let member = judge.flat.state(end_state.x);
        let member_residual = judge.residual(&member);
        let pressed = entering.iter().all(|&i| member.x[i] > 0.0);
        let kept = (0..judge.flat.n).all(|i| best.x[i] <= 0.0 || member.x[i] > 0.0);
        if !(pressed && kept && member_residual <= params.tol) {
            break;
        }
        best = member;
        residual = member_residual;
    }
    (best, residual)
}
/// The separated points nearest the foundation (their distance `g - u_n` within [`TIE`] of
/// the least), or `None` where every point touches.
fn nearest_separated(judge: &Judge<'_>, s: &State) -> Option<Vec<usize>> {
    let flat = &judge.flat;
    let distance = |i: usize| flat.points.gap[i] - s.u[i];
    let separated: Vec<usize> = (0..flat.n).filter(|&i| s.x[i] <= 0.0 && distance(i) > 0.0).collect();
    let least = separated.iter().map(|&i| distance(i)).fold(f64::INFINITY, f64::min);
    (least.is_finite()).then(|| {
        separated
            .into_iter()
            .filter(|&i| distance(i) <= least * (1.0 + TIE))
            .collect()
    })
}
