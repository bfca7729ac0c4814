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
    let runs = loose_sizes.len() + tight_sizes.len();
    let whole: f64 = loose_sizes
        .iter()
        .map(|&n| expected_seconds(Rule::Paper, n))
        .chain(tight_sizes.iter().map(|&n| expected_seconds(Rule::Tight, n)))
        .sum();
    progress(&format!(
        "table1: {runs} runs, about {} in all (as measured on 2 cores, docs/table1.md)",
        in_words(whole)
    ));
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
            progress(&format!(
                "h = 1/{n:<4} {rule:5} rule: running, about {}",
                in_words(expected_seconds(rule, n))
            ));
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

/// The seconds a row takes, as measured on this machine's 2 cores (docs/table1.md: the loose
/// rule's rows at n = 32 to 256, the tight rule's at 32, 64 and 128), other sizes scaled from
/// the nearest measured one below by the growth the measured rows show (n³ loose, n⁵ tight:
/// the tight rule's Uzawa iterations double with n, each a PCG solve).
fn expected_seconds(rule: Rule, n: usize) -> f64 {
    let (measured, power): (&[(usize, f64)], i32) = match rule {
        Rule::Paper => (&[(32, 0.083), (64, 0.44), (128, 3.6), (256, 20.3)], 3),
        Rule::Tight => (&[(32, 2.9), (64, 42.4), (128, 2236.0)], 5),
    };
    let (m, seconds) = measured
        .iter()
        .rev()
        .find(|&&(m, _)| m <= n)
        .copied()
        .unwrap_or(measured[0]);
    seconds * (n as f64 / m as f64).powi(power)
}

/// A duration in words: seconds, minutes or hours.
fn in_words(seconds: f64) -> String {
    if seconds < 1.0 {
        "a second or less".into()
    } else if seconds < 90.0 {
        format!("{seconds:.0} s")
    } else if seconds < 5400.0 {
        format!("{:.0} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimates are the measured rows where measured, and grow from them elsewhere; the
    /// default table (tight to n = 64) is told as under a minute, the paper's tight n = 128 as
    /// about 37 minutes.
    #[test]
    fn the_table_tells_how_long_it_takes() {
        assert_eq!(expected_seconds(Rule::Tight, 128), 2236.0);
        assert_eq!(in_words(expected_seconds(Rule::Tight, 128)), "37 min");
        let quick: f64 = [32, 64, 128, 256]
            .iter()
            .map(|&n| expected_seconds(Rule::Paper, n))
            .sum::<f64>()
            + [32, 64].iter().map(|&n| expected_seconds(Rule::Tight, n)).sum::<f64>();
        assert!(quick < 90.0, "{quick}");
        assert!(expected_seconds(Rule::Tight, 256) > expected_seconds(Rule::Tight, 128));
        assert!(expected_seconds(Rule::Paper, 16) > 0.0);
    }
}
