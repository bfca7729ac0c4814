//! Runs of a scene along a parameter (`sweep`) and the reproduction of the paper's Table 1.

use crate::output::Outputs;
use crate::run::{run, RunOutcome};
use crate::scene;
use crate::DriverError;
use plotters::prelude::*;
use std::path::Path;
use std::time::Instant;

/// One row of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRow {
    /// The parameter's value.
    pub value: f64,
    /// Stick, slip, separated counts.
    pub counts: (u64, u64, u64),
    /// Sum of w λ_n.
    pub normal_force: f64,
    /// |Σ w λ_t|.
    pub tangential_force: f64,
    /// Complementarity residual.
    pub complementarity: f64,
    /// Equilibrium residual.
    pub equilibrium: f64,
    /// Uzawa iterations.
    pub uzawa: u64,
    /// Fixed-point iterations.
    pub fixed_point: u64,
    /// Wall time of the run (s).
    pub seconds: f64,
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// The parameter a sweep varies: `steps` values from `from` to `to`, inclusive.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepSpec {
    /// The scene key, e.g. `electrode.v`.
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values (at least 2).
    pub steps: usize,
}

/// Runs `scene_name` along `spec`, with the other overrides `sets`; writes `sweep.csv` and
/// `sweep.svg/png` into `out` when given.
pub fn sweep(
    scene_name: &str,
    sets: &[String],
    spec: &SweepSpec,
    out: Option<&Path>,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<SweepRow>, DriverError> {
    let SweepSpec { param, from, to, steps } = spec;
    let (param, from, to, steps) = (param.as_str(), *from, *to, *steps);
    if steps < 2 {
        return Err(DriverError::Input("sweep needs --steps of at least 2".into()));
    }
    let mut rows = vec![];
    for k in 0..steps {
        let value = from + (to - from) * k as f64 / (steps - 1) as f64;
        let mut s = sets.to_vec();
        s.push(format!("{param}={value}"));
        let (sc, src) = scene::load(scene_name, &s)?;
        let t = Instant::now();
        let r: RunOutcome = run(&sc, &src, None, &mut |_| {})?;
        let c = &r.report["contact"];
        let row = SweepRow {
            value,
            counts: (
                c["n_stick"].as_u64().unwrap_or(0),
                c["n_slip"].as_u64().unwrap_or(0),
                c["n_separated"].as_u64().unwrap_or(0),
            ),
            normal_force: num(&c["normal_force"]),
            tangential_force: num(&c["tangential_force"]),
            complementarity: num(&r.report["residuals"]["complementarity"]),
            equilibrium: num(&r.report["residuals"]["equilibrium"]),
            uzawa: r.report["iterations"]["uzawa"].as_u64().unwrap_or(0),
            fixed_point: r.report["iterations"]["fixed_point"].as_u64().unwrap_or(0),
            seconds: t.elapsed().as_secs_f64(),
        };
        progress(&format!(
            "[{}/{steps}] {param} = {value:.6e}: stick {}, slip {}, separated {}, normal force {:.4e}, residual {:.2e}",
            k + 1,
            row.counts.0,
            row.counts.1,
            row.counts.2,
            row.normal_force,
            row.complementarity
        ));
        rows.push(row);
    }
    if let Some(dir) = out {
        let mut csv = format!("{param},n_stick,n_slip,n_separated,normal_force,tangential_force,complementarity,equilibrium,uzawa_iters,fixed_point_iters,seconds\n");
        for r in &rows {
            csv.push_str(&format!(
                "{:.12e},{},{},{},{:.12e},{:.12e},{:.3e},{:.3e},{},{},{:.4}\n",
                r.value,
                r.counts.0,
                r.counts.1,
                r.counts.2,
                r.normal_force,
                r.tangential_force,
                r.complementarity,
                r.equilibrium,
                r.uzawa,
                r.fixed_point,
                r.seconds
            ));
        }
        let mut outs = Outputs::new(dir);
        outs.add("sweep.csv", csv.into_bytes());
        for (name, bytes) in crate::plots::sweep_pictures(param, &rows)? {
            outs.add(&name, bytes);
        }
        outs.commit()?;
        progress(&format!("wrote sweep.csv, sweep.svg, sweep.png in {}", dir.display()));
    }
    Ok(rows)
}

/// One row of the Table 1 reproduction.
#[derive(Clone, Debug, PartialEq)]
pub struct Table1Row {
    /// Mesh size n (h = 1/n).
    pub n: usize,
    /// `paper` or `tight`.
    pub rule: String,
    /// Fixed-point iterations.
    pub fixed_point: u64,
    /// Uzawa iterations.
    pub uzawa: u64,
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

fn weighted_error(run: &RunOutcome, exact: &RunOutcome) -> f64 {
    let (Some((p, a)), Some((_, b))) = (&run.contact, &exact.contact) else {
        return f64::NAN;
    };
    let d = a.lambda.minus(&b.lambda);
    d.weighted_norm(&p.weight) / b.lambda.weighted_norm(&p.weight)
}

/// The paper's Table 1: `paper` with Uzawa + Schur PCG + fixed point under the paper's loose
/// rule at `loose_sizes`, then under the tight rule (complementarity 1e-10) at `tight_sizes`,
/// each with the error of λ against the discrete solution.
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
        let (sc, src) = scene::load("paper", &[mesh.clone(), "solver.tol=1e-13".into()])?;
        let exact = run(&sc, &src, None, &mut |_| {})?;
        for (rule, wanted) in [("paper", loose_sizes), ("tight", tight_sizes)] {
            if !wanted.contains(&n) {
                continue;
            }
            let (sc, src) = scene::load(
                "paper",
                &[
                    mesh.clone(),
                    format!("solver.rule={rule}"),
                    "solver.strategy=uzawa-schur-pcg".into(),
                ],
            )?;
            let r = run(&sc, &src, None, &mut |_| {})?;
            let it = &r.report["iterations"];
            let uz = it["uzawa"].as_u64().unwrap_or(0);
            let row = Table1Row {
                n,
                rule: rule.into(),
                fixed_point: it["fixed_point"].as_u64().unwrap_or(0),
                uzawa: uz,
                pcg_per_solve: num(&it["pcg"]) / (uz.max(1) as f64),
                contact_seconds: num(&r.report["timings_s"]["contact"]),
                total_seconds: num(&r.report["timings_s"]["total"]),
                lambda_error: weighted_error(&r, &exact),
                complementarity: num(&r.report["residuals"]["complementarity"]),
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
pub fn table1_markdown(rows: &[Table1Row]) -> String {
    let mut s = String::from("| h | rule | fixed point | Uzawa | PCG per solve | time (s) | error of lambda | complementarity |\n|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        s.push_str(&format!(
            "| 1/{} | {} | {} | {} | {:.1} | {:.3} | {:.2e} | {:.2e} |\n",
            r.n, r.rule, r.fixed_point, r.uzawa, r.pcg_per_solve, r.total_seconds, r.lambda_error, r.complementarity
        ));
    }
    s
}

/// A log-log-free line plot of the sweep: counts and forces against the parameter.
pub(crate) fn draw_sweep<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    param: &str,
    rows: &[SweepRow],
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let (top, bottom) = area.split_vertically(300);
    let x0 = rows.first().map_or(0.0, |r| r.value);
    let x1 = rows.last().map_or(1.0, |r| r.value);
    let (lo, hi) = if x1 > x0 { (x0, x1) } else { (x1, x0.max(x1 + 1e-12)) };
    let nmax = rows
        .iter()
        .map(|r| r.counts.0 + r.counts.1 + r.counts.2)
        .max()
        .unwrap_or(1) as f64;
    let mut c1 = ChartBuilder::on(&top)
        .caption(format!("Contact states along {param}"), ("sans-serif", 22))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(lo..hi, 0.0..nmax * 1.05)
        .map_err(e)?;
    c1.configure_mesh()
        .y_desc("points")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    for (name, color, get) in [
        ("stick", GREEN, (|r: &SweepRow| r.counts.0) as fn(&SweepRow) -> u64),
        ("slip", BLUE, |r: &SweepRow| r.counts.1),
        ("separated", RED, |r: &SweepRow| r.counts.2),
    ] {
        c1.draw_series(LineSeries::new(
            rows.iter().map(|r| (r.value, get(r) as f64)),
            color.stroke_width(2),
        ))
        .map_err(e)?
        .label(name)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    c1.configure_series_labels()
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    let fmax = rows
        .iter()
        .map(|r| r.normal_force.max(r.tangential_force))
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let mut c2 = ChartBuilder::on(&bottom)
        .caption("Contact forces", ("sans-serif", 22))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(lo..hi, 0.0..fmax * 1.05)
        .map_err(e)?;
    c2.configure_mesh()
        .x_desc(param)
        .y_desc("force")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    c2.draw_series(LineSeries::new(
        rows.iter().map(|r| (r.value, r.normal_force)),
        RED.stroke_width(2),
    ))
    .map_err(e)?
    .label("normal (sum w lambda_n)")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    c2.draw_series(LineSeries::new(
        rows.iter().map(|r| (r.value, r.tangential_force)),
        BLUE.stroke_width(2),
    ))
    .map_err(e)?
    .label("tangential |sum w lambda_t|")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    c2.configure_series_labels()
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    Ok(())
}
