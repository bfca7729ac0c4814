//! The paper's Table 1, honestly (`piezocontact table1`): the `paper` scene with Uzawa +
//! Schur PCG + the fixed point, under the paper's loose rule and under the tight rule, each
//! with the error of λ against the discrete solution solved to 1e-13.

use super::solve;
use crate::DriverError;
use problem::{Rule, Solution};

/// One row of the Table 1 reproduction.
#[derive(Clone, Debug, PartialEq)]
pub struct Table1Row {
    /// Mesh size n (h = 1/n).
    pub n: usize,
    /// The stopping rule.
    pub rule: Rule,
    /// Fixed-point iterations.
    pub fixed_point: usize,
    /// Uzawa iterations.
    pub uzawa: usize,
    /// PCG iterations per Uzawa solve (mean).
    pub pcg_per_solve: f64,
    /// Wall time of the contact solve (s).
    pub contact_seconds: f64,
    /// Total wall time (s).
    pub total_seconds: f64,
    /// `‖λ - λ*‖_W / ‖λ*‖_W` against the discrete solution solved to 1e-13.
    pub lambda_error: f64,
    /// The run's complementarity residual.
    pub complementarity: f64,
}

/// `‖λ - λ*‖_W / ‖λ*‖_W` of two runs on one mesh (NaN without contact).
fn weighted_error(run: &Solution, exact: &Solution) -> f64 {
    let (Some(a), Some(b)) = (&run.contact, &exact.contact) else {
        return f64::NAN;
    };
    let d = a.solution.lambda.minus(&b.solution.lambda);
    d.weighted_norm(&a.points.weight) / b.solution.lambda.weighted_norm(&a.points.weight)
}

/// The paper's Table 1: `paper` with Uzawa + Schur PCG + fixed point under the paper's loose
/// rule at `loose_sizes`, then under the tight rule (complementarity 1e-10) at `tight_sizes`.
///
/// # Errors
/// A run's error.
pub fn table1(
    loose_sizes: &[usize],
    tight_sizes: &[usize],
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Table1Row>, DriverError> {
    let mut rows = vec![];
    let mut sizes: Vec<usize> = loose_sizes.iter().chain(tight_sizes).copied().collect();
    sizes.sort_unstable();
    sizes.dedup();
    for n in sizes {
        let mesh = format!("mesh.n={n}");
        let exact = solve("paper", &[mesh.clone(), "solver.tol=1e-13".into()])?;
        for (rule, wanted) in [(Rule::Paper, loose_sizes), (Rule::Tight, tight_sizes)] {
            if !wanted.contains(&n) {
                continue;
            }
            let sets = [
                mesh.clone(),
                format!("solver.rule={rule}"),
                "solver.strategy=uzawa-schur-pcg".into(),
            ];
            let r = solve("paper", &sets)?;
            let (it, report) = (&r.report.iterations, &r.report);
            let row = Table1Row {
                n,
                rule,
                fixed_point: it.fixed_point,
                uzawa: it.uzawa,
                pcg_per_solve: it.pcg as f64 / it.uzawa.max(1) as f64,
                contact_seconds: report.timings_s.contact,
                total_seconds: report.timings_s.total,
                lambda_error: weighted_error(&r, &exact),
                complementarity: report.residuals.complementarity,
            };
            progress(&format!(
                "h = 1/{n:<4} {rule:5} rule: FP {:>2}, UA {:>5}, PCG/solve {:>4.1}, time {:>8.3} s, lambda error {:.2e}, residual {:.2e}",
                row.fixed_point, row.uzawa, row.pcg_per_solve, row.total_seconds, row.lambda_error, row.complementarity
            ));
            rows.push(row);
        }
    }
    Ok(rows)
}

/// The Table 1 rows as Markdown.
pub fn markdown(rows: &[Table1Row]) -> String {
    let mut s = String::from("| h | rule | fixed point | Uzawa | PCG per solve | time (s) | error of lambda | complementarity |\n|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        s.push_str(&format!(
            "| 1/{} | {} | {} | {} | {:.1} | {:.3} | {:.2e} | {:.2e} |\n",
            r.n, r.rule, r.fixed_point, r.uzawa, r.pcg_per_solve, r.total_seconds, r.lambda_error, r.complementarity
        ));
    }
    s
}
