//! Slip-weakening friction on pieces: the contact crate's fixed point on the coefficients
//! (`contact::solve_slip_weakening`), each step Coulomb's law with the coefficients frozen, run
//! around the active sets, its coefficients spread over the ranks as their points are. The
//! steps are mixed as the contact crate mixes them (Anderson's type II, Walker and Ni, SIAM J.
//! Numer. Anal. 49 (2011) 1715), its inner products summed over the ranks so that every rank
//! takes the same mixing. The contact crate's Newton on the law itself, which needs the whole
//! compliance, is not used: a law whose mixed fixed point does not settle is told by name.

use crate::contact::ContactOutcome;
use crate::error::DistributedError;
use contact::{ContactPoints, PointValues};
use petsc::{Petsc, PetscError, Vector};
use problem::ProblemError;

/// Steps of the fixed point at most.
const MAX_STEPS: usize = 200;

/// Steps of history in the mixing (the contact crate's depth).
const DEPTH: usize = 3;

/// Slip-weakening friction on the points `points`: from the coefficients at the slip before
/// this problem (the static ones in a static run; a path's earlier slip in
/// [`ContactPoints::slipped`]), each step `solve`
/// (Coulomb's law with the coefficients frozen, from the last step's multipliers and
/// solution), the next coefficients those at its slips, mixed and kept within each law's
/// range (each at the slip before plus this problem's, `u` less `shift`), until no
/// coefficient moves by more than `tol` of the largest static one between a
/// step's and its slips' (over the ranks). Returns the last step's outcome, whose coefficients
/// are then those of its slips to that tolerance, with the fixed point's steps and every
/// step's active-set steps counted. Collective.
///
/// # Errors
/// `solve`'s; [`ProblemError::NoSolution`] keyed `contact.friction_law` where the fixed point
/// does not settle in [`MAX_STEPS`] steps.
pub(super) fn weakened<'p>(
    petsc: &Petsc,
    (points, shift): (&ContactPoints, &PointValues),
    (mut start, mut warm): (Option<PointValues>, Option<Vector<'p>>),
    tol: f64,
    solve: &mut impl FnMut(
        &ContactPoints,
        Option<PointValues>,
        Option<Vector<'p>>,
    ) -> Result<ContactOutcome<'p>, DistributedError>,
) -> Result<ContactOutcome<'p>, DistributedError> {
    // the coefficients at the slip before this problem (a path's earlier instants; the static
    // ones in a static run), and the largest static coefficient, the change's scale
    let mut at = points.clone();
    at.friction = points.coefficients_at(&PointValues::zeros(points.len(), points.n_tangential()));
    let most = points
        .weakening
        .iter()
        .flatten()
        .fold(f64::MIN_POSITIVE, |m, w| m.max(w.static_coefficient));
    let scale = petsc.max(&[most])?[0];
    let mut mixing = Mixing::default();
    let (mut change, mut steps) = (f64::INFINITY, 0);
    for k in 1..=MAX_STEPS {
        let mut out = solve(&at, start.take(), warm.take())?;
        steps += out.solution.info.newton_iters;
        let next = at.coefficients_at(&increments(&out.solution.u, shift));
        let own = next
            .iter()
            .zip(&at.friction)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        change = petsc.max(&[own])?[0];
        if change <= tol * scale {
            out.solution.info.fixed_point_iters = k;
            out.solution.info.newton_iters = steps;
            return Ok(out);
        }
        at.friction = mixing.step(petsc, &at.friction, next)?;
        for (i, m) in at.friction.iter_mut().enumerate() {
            *m = match points.weakening_of(i) {
                Some(w) => m.clamp(w.dynamic_coefficient, w.static_coefficient),
                None => points.friction[i],
            };
        }
        start = Some(out.solution.lambda);
        warm = Some(out.x);
    }
    Err(ProblemError::NoSolution {
        sought: "contact.friction_law",
        why: format!(
            "the fixed point on the slip-weakening coefficients did not settle in {MAX_STEPS} steps (the last moved a coefficient by {change:.3e}); the default backend's Newton on the law itself may"
        ),
    }
    .into())
}

/// The tangential displacements `u` less friction's frame `shift` (a path's instant before;
/// zero in a static run): the slip of this problem, the coefficient's argument beside the
/// slip before it.
pub(super) fn increments(u: &PointValues, shift: &PointValues) -> PointValues {
    let mut slip = u.clone();
    for (v, s) in slip.tangential.iter_mut().zip(&shift.tangential) {
        *v -= s;
    }
    slip
}

/// Anderson's mixing of a fixed point `x = G(x)` whose vectors are spread over the ranks: from
/// the last [`DEPTH`] pairs `(x_j, G(x_j))`, `x_(k+1) = G(x_k) - ΔG γ`, `γ` the least-squares
/// coefficients of the residuals' differences `ΔF` against `f_k = G(x_k) - x_k`, their inner
/// products summed over the ranks.
#[derive(Default)]
struct Mixing {
    /// The last pairs `(x_j, G(x_j))`, oldest first.
    history: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Mixing {
    /// The next iterate from `x` and `g = G(x)`. Collective.
    fn step(&mut self, petsc: &Petsc, x: &[f64], g: Vec<f64>) -> Result<Vec<f64>, PetscError> {
        self.history.push((x.to_vec(), g.clone()));
        if self.history.len() > DEPTH + 1 {
            self.history.remove(0);
        }
        let m = self.history.len() - 1;
        if m == 0 {
            return Ok(g);
        }
        let f = |j: usize| -> Vec<f64> {
            let (x, g) = &self.history[j];
            g.iter().zip(x).map(|(a, b)| a - b).collect()
        };
        let df: Vec<Vec<f64>> = (0..m)
            .map(|j| f(j + 1).iter().zip(&f(j)).map(|(a, b)| a - b).collect())
            .collect();
        let fk = f(m);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        // the normal equations' entries, then the right-hand side, summed over the ranks at once
        let mut sums: Vec<f64> = (0..m)
            .flat_map(|i| (0..m).map(move |j| (i, j)))
            .map(|(i, j)| dot(&df[i], &df[j]))
            .collect();
        sums.extend((0..m).map(|i| dot(&df[i], &fk)));
        let sums = petsc.sum(&sums)?;
        let mut a: Vec<Vec<f64>> = (0..m).map(|i| sums[i * m..(i + 1) * m].to_vec()).collect();
        let mut b = sums[m * m..].to_vec();
        // a touch of Tikhonov: nearly parallel differences make the normal equations singular
        let trace: f64 = (0..m).map(|i| a[i][i]).sum();
        for (i, row) in a.iter_mut().enumerate() {
            row[i] += 1e-12 * trace.max(f64::MIN_POSITIVE);
        }
        let Some(gamma) = solve_small(&mut a, &mut b) else {
            return Ok(g);
        };
        let mut next = g;
        for (j, gj) in gamma.iter().enumerate() {
            let (g1, g0) = (&self.history[j + 1].1, &self.history[j].1);
            for (v, (a, b)) in next.iter_mut().zip(g1.iter().zip(g0)) {
                *v -= gj * (a - b);
            }
        }
        Ok(next)
    }
}

/// Solves the small symmetric positive definite system `a γ = b` (`m ≤ DEPTH`) by Gaussian
/// elimination without pivoting (its pivots are the positive ones of Cholesky's); `None` where
/// a pivot is not positive.
fn solve_small(a: &mut [Vec<f64>], b: &mut [f64]) -> Option<Vec<f64>> {
    let m = b.len();
    for k in 0..m {
        if !(a[k][k] > 0.0) {
            return None;
        }
        for i in k + 1..m {
            let l = a[i][k] / a[k][k];
            for j in k..m {
                a[i][j] -= l * a[k][j];
            }
            b[i] -= l * b[k];
        }
    }
    let mut x = vec![0.0; m];
    for i in (0..m).rev() {
        let s: f64 = (i + 1..m).map(|j| a[i][j] * x[j]).sum();
        x[i] = (b[i] - s) / a[i][i];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::solve_small;

    #[test]
    fn a_small_positive_definite_system_is_solved() {
        let mut a = vec![vec![4.0, 1.0, 0.5], vec![1.0, 3.0, 0.2], vec![0.5, 0.2, 2.0]];
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = a.iter().map(|r| r.iter().zip(&x).map(|(p, q)| p * q).sum()).collect();
        let got = solve_small(&mut a, &mut b).expect("positive definite");
        for (g, e) in got.iter().zip(&x) {
            assert!((g - e).abs() < 1e-14, "{got:?}");
        }
        assert!(solve_small(&mut [vec![0.0]], &mut [1.0]).is_none());
    }
}
