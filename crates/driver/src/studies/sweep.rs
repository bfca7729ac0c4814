//! Runs of a scene along one parameter (`piezocontact sweep`): contact states, forces and
//! residuals against the parameter, as CSV and a picture of two panels.

use super::solve;
use crate::DriverError;
use files::output::Outputs;
use files::plots::{self, Panel, Series};
use std::path::Path;
use std::time::Instant;

/// One run of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRow {
    /// The parameter's value.
    pub value: f64,
    /// Stick, slip, separated counts.
    pub counts: (usize, usize, usize),
    /// Sum of w λ_n.
    pub normal_force: f64,
    /// |Σ w λ_t|.
    pub tangential_force: f64,
    /// `Σ w λ_t t` in the global frame, one component per dimension (run.json's
    /// `contact.tangential_resultant`; empty where the point failed).
    pub tangential_resultant: Vec<f64>,
    /// Complementarity residual.
    pub complementarity: f64,
    /// Equilibrium residual.
    pub equilibrium: f64,
    /// First-order iterations.
    pub uzawa: usize,
    /// Fixed-point iterations.
    pub fixed_point: usize,
    /// Wall time of the run (s).
    pub seconds: f64,
    /// A rigid indenter's figures, where the scene has one (a force-controlled indenter's
    /// depth against a voltage: piezoresponse).
    pub indenter: Option<SweepIndenter>,
    /// Each terminal's group, charge and potential (run.json's `terminals`).
    pub terminals: Vec<(String, f64, f64)>,
    /// The run's error where this point failed (its numbers then NaN): the other points are
    /// kept.
    pub error: Option<String>,
    /// The units of the run's numbers (none where it failed).
    pub units: Option<problem::Units>,
}

/// An indenter's figures at a point of a sweep, with the half-space's closed form where it
/// applies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepIndenter {
    /// The depth (under force control, the depth found).
    pub depth: f64,
    /// The force it carries.
    pub force: f64,
    /// The contact radius.
    pub contact_radius: f64,
    /// A conducting tip's charge.
    pub charge: Option<f64>,
    /// A conducting tip's potential.
    pub potential: Option<f64>,
    /// The half-space's force, contact radius and charge at the point's depth.
    pub half_space: Option<(f64, f64, Option<f64>)>,
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

/// Runs `scene` along `spec`, with the other overrides `sets`; writes `sweep.csv` and
/// `sweep.svg/png` into `out` when given. Each point is its own run: one that fails is a row
/// with its error (and NaN numbers), the others are kept and written.
///
/// # Errors
/// [`DriverError::Usage`] for fewer than 2 steps; the first point's error where every point
/// failed (nothing is written); [`DriverError::Unexpected`] naming the failed points where
/// some did (after the rest is written).
pub fn sweep(
    scene: &str,
    sets: &[String],
    spec: &SweepSpec,
    out: Option<&Path>,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<SweepRow>, DriverError> {
    let SweepSpec { param, from, to, steps } = spec;
    if *steps < 2 {
        return Err(DriverError::Usage("sweep needs --steps of at least 2".into()));
    }
    for (name, v) in [("--from", from), ("--to", to)] {
        if !v.is_finite() {
            return Err(DriverError::Usage(format!("sweep {name} {v} is not a finite number")));
        }
    }
    super::refuse_decided("the sweep", sets, &[(param, "--param, its values from --from to --to")])?;
    let integer = integer_key(scene, sets, param, [*from, *to])?;
    if integer {
        whole_points(param, *from, *to, *steps)?;
    }
    let mut rows = vec![];
    let mut eta = super::Eta::default();
    let mut first_error: Option<files::Error> = None;
    for k in 0..*steps {
        // a weighted mean of the bounds: finite for any finite bounds (their difference may
        // overflow), and the bounds themselves at the ends
        let t = k as f64 / (steps - 1) as f64;
        let mut value = if k + 1 == *steps {
            *to
        } else {
            from * (1.0 - t) + to * t
        };
        let mut s = sets.to_vec();
        if integer {
            // an integer key (`mesh.n`, `path.steps`) takes the nearest integer, written as one
            value = value.round();
            s.push(format!("{param}={}", value as i64));
        } else {
            // the shortest digits that read back to the value (`{:?}`: 1e300, not 301 digits)
            s.push(format!("{param}={value:?}"));
        }
        let shown = shown(value, integer);
        let t = Instant::now();
        let r = match solve(scene, &s) {
            Ok(solved) => solved.report,
            Err(e) => {
                eta.record(0, t.elapsed().as_secs_f64());
                progress(&format!("[{}/{steps}] {param} = {shown}: failed: {e}", k + 1));
                rows.push(SweepRow::failed(value, t.elapsed().as_secs_f64(), e.to_string()));
                first_error.get_or_insert(e);
                continue;
            }
        };
        let row = SweepRow::of(value, &r, t.elapsed().as_secs_f64());
        eta.record(0, row.seconds);
        let left = eta.words(&vec![0; steps - k - 1]);
        progress(&point_line((k + 1, *steps), (param, &shown), &row, &r.units, &left));
        rows.push(row);
    }
    let failed: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            r.error
                .as_ref()
                .map(|e| format!("{param} = {}: {e}", shown(r.value, integer)))
        })
        .collect();
    if let (Some(e), true) = (first_error, failed.len() == rows.len()) {
        // nothing found: the first point's error, nothing written
        return Err(e.into());
    }
    if let Some(dir) = out {
        let mut outs = Outputs::new(dir);
        outs.add("sweep.csv", csv(param, &rows, integer).into_bytes());
        outs.extend(picture(param, &rows)?);
        outs.commit()?;
        progress(&format!("wrote sweep.csv, sweep.svg, sweep.png in {}", dir.display()));
    }
    if let Some((response, n)) = piezoresponse(param, &rows) {
        progress(&format!(
            "piezoresponse: {response:.1} pm/V (the indenter's depth against {param}, a least-squares line through {n} points)"
        ));
    }
    if !failed.is_empty() {
        return Err(DriverError::Unexpected {
            what: "sweep points that failed (the others are in sweep.csv)",
            items: failed,
        });
    }
    Ok(rows)
}

/// The progress line of the point `k` of `steps` solved (`param` at its value `shown`), each
/// number with its unit (none for a count, a factor, a relative residual), and the time `left`.
fn point_line(
    (k, steps): (usize, usize),
    (param, shown): (&str, &str),
    row: &SweepRow,
    units: &problem::Units,
    left: &str,
) -> String {
    let unit = |q: &str| match units.of_quantity(q) {
        "" => String::new(),
        u => format!(" {u}"),
    };
    format!(
        "[{k}/{steps}] {param} = {shown}{}: stick {}, slip {}, separated {}, normal force {:.4e}{}, residual {:.2e}; {left}",
        unit(param_quantity(param)),
        row.counts.0,
        row.counts.1,
        row.counts.2,
        row.normal_force,
        unit("force"),
        row.complementarity,
    )
}

/// An integer key's sweep (`mesh.n`, `path.steps`): its points are rounded to whole numbers,
/// so its bounds must be whole and its steps no more than the whole numbers between them
/// (else two points would run the same value, or a bound would not be the one asked for).
fn whole_points(param: &str, from: f64, to: f64, steps: usize) -> Result<(), DriverError> {
    for (name, v) in [("--from", from), ("--to", to)] {
        if v.fract() != 0.0 {
            return Err(DriverError::Usage(format!(
                "sweep {name} {v}: {param} takes whole numbers"
            )));
        }
    }
    let distinct = (to - from).abs() + 1.0;
    if steps as f64 > distinct {
        return Err(DriverError::Usage(format!(
            "sweep --steps {steps}: {param} takes whole numbers, and there are {distinct} from {from} to {to} (give --steps {distinct} at most)"
        )));
    }
    Ok(())
}

impl SweepRow {
    /// The point `value` whose run reported `r` in `seconds`.
    fn of(value: f64, r: &problem::RunReport, seconds: f64) -> Self {
        let c = &r.contact;
        SweepRow {
            value,
            counts: (c.n_stick, c.n_slip, c.n_separated),
            normal_force: c.normal_force,
            tangential_force: c.tangential_force,
            tangential_resultant: c.tangential_resultant.clone(),
            complementarity: r.residuals.complementarity,
            equilibrium: r.residuals.equilibrium,
            uzawa: r.iterations.uzawa,
            fixed_point: r.iterations.fixed_point,
            seconds,
            indenter: r.indenter.as_ref().map(|i| SweepIndenter {
                depth: i.depth,
                force: i.force,
                contact_radius: i.contact_radius,
                charge: i.charge,
                potential: i.potential,
                half_space: i.half_space.as_ref().map(|h| (h.force, h.contact_radius, h.charge)),
            }),
            terminals: r
                .terminals
                .iter()
                .map(|t| (t.group.clone(), t.charge, t.potential))
                .collect(),
            error: None,
            units: Some(r.units.clone()),
        }
    }

    /// A point whose run failed with `error`: its numbers NaN, its error kept.
    fn failed(value: f64, seconds: f64, error: String) -> Self {
        SweepRow {
            value,
            counts: (0, 0, 0),
            normal_force: f64::NAN,
            tangential_force: f64::NAN,
            tangential_resultant: vec![],
            complementarity: f64::NAN,
            equilibrium: f64::NAN,
            uzawa: 0,
            fixed_point: 0,
            seconds,
            indenter: None,
            terminals: vec![],
            error: Some(error),
            units: None,
        }
    }
}

/// A swept value as the progress lines show it: an integer key's as the integer it is set to,
/// another's with seven digits.
fn shown(value: f64, integer: bool) -> String {
    match integer {
        true => format!("{}", value as i64),
        false => format!("{value:.6e}"),
    }
}

/// Whether `param` is an integer key of the scene: its value in the scene (with `sets`) is a
/// TOML integer; where the scene leaves it out, whether both bounds are whole numbers within
/// the integers a double holds exactly.
///
/// # Errors
/// A usage error where the scene's value is no number (a list, a table, a string): a sweep
/// varies one number, and every point would fail alike.
fn integer_key(scene: &str, sets: &[String], param: &str, bounds: [f64; 2]) -> Result<bool, DriverError> {
    let found = files::scene_file::load(scene, sets)
        .ok()
        .and_then(|(s, _)| toml::Value::try_from(&s).ok())
        .and_then(|tree| {
            param
                .split('.')
                .try_fold(tree, |node, part| match (node, part.parse::<usize>()) {
                    (toml::Value::Array(mut items), Ok(i)) if i < items.len() => Some(items.swap_remove(i)),
                    (toml::Value::Table(mut table), _) => table.remove(part),
                    _ => None,
                })
        });
    match found {
        Some(v) if v.is_integer() || v.is_float() => Ok(v.is_integer()),
        Some(toml::Value::Array(items)) => Err(DriverError::Usage(format!(
            "sweep --param {param}: the scene's {param} is a list of {} values ({}), and a sweep varies one number: sweep one component, as --param {param}.0",
            items.len(),
            toml::Value::Array(items.clone())
        ))),
        Some(v) => Err(DriverError::Usage(format!(
            "sweep --param {param}: the scene's {param} is {} ({v}), and a sweep varies one number",
            match v {
                toml::Value::Table(_) => "a table",
                toml::Value::String(_) => "a string",
                toml::Value::Boolean(_) => "a boolean",
                _ => "no number",
            }
        ))),
        // a key the scene leaves unset: its type is the one the scene's reader takes (an
        // integer key refuses `4.0`, a real one takes it), never a guess from the bounds,
        // which are whole for many a real key's sweep (`coupling_scale` from 0 to 1)
        None => {
            let takes = |value: String| {
                let mut s = sets.to_vec();
                s.push(format!("{param}={value}"));
                files::scene_file::load(scene, &s).is_ok()
            };
            let [from, _] = bounds;
            Ok(from.fract() == 0.0
                && from.abs() < 2f64.powi(53)
                && !takes(format!("{from:?}"))
                && takes(format!("{}", from as i64)))
        }
    }
}

/// The terminals' groups of a sweep, as its first point that has them names them (a failed
/// point has none).
fn terminal_groups(rows: &[SweepRow]) -> Vec<String> {
    rows.iter()
        .find(|r| !r.terminals.is_empty())
        .map_or(vec![], |r| r.terminals.iter().map(|t| t.0.clone()).collect())
}

/// The rows as CSV: the counts, forces, residuals, iterations and seconds, the tangential
/// force's components (`tangential_force_x`, `_y`, `_z` in 3D); where the scene has
/// an indenter its figures (`indenter_depth`, `indenter_charge` (`nan` for an insulating
/// one's), `indenter_force`, `indenter_contact_radius`, `indenter_potential`) and the
/// half-space's closed form beside them (`half_space_force`, `_contact_radius`, `_charge`,
/// `nan` where it does not apply); each terminal's `charge_GROUP` and `potential_GROUP`; a
/// failed point's `error`. The swept value an integer where the key is one (`integer`).
pub fn csv(param: &str, rows: &[SweepRow], integer: bool) -> String {
    let indenter = rows.iter().any(|r| r.indenter.is_some());
    let errors = rows.iter().any(|r| r.error.is_some());
    let groups = terminal_groups(rows);
    let mut columns: Vec<String> = std::iter::once(param.to_string())
        .chain(
            "n_stick,n_slip,n_separated,normal_force,tangential_force,complementarity,equilibrium,uzawa_iters,fixed_point_iters,seconds"
                .split(',')
                .map(String::from),
        )
        .collect();
    // the tangential force's components beside its magnitude (as path.csv's)
    let dim = rows.iter().map(|r| r.tangential_resultant.len()).max().unwrap_or(0);
    columns.extend(
        ["x", "y", "z"]
            .iter()
            .take(dim)
            .map(|a| format!("tangential_force_{a}")),
    );
    if indenter {
        columns.extend("indenter_depth,indenter_charge,indenter_force,indenter_contact_radius,indenter_potential,half_space_force,half_space_contact_radius,half_space_charge".split(',').map(String::from));
    }
    for (prefix, g) in ["charge", "potential"]
        .iter()
        .flat_map(|p| groups.iter().map(move |g| (p, g)))
    {
        columns.push(format!("{prefix}_{g}"));
    }
    if errors {
        columns.push("error".into());
    }
    // each column's unit in brackets, the swept key's its quantity's
    let units = rows.iter().find_map(|r| r.units.clone()).unwrap_or_default();
    let header: Vec<String> = columns
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let unit = match k {
                0 => units.of_quantity(param_quantity(param)).to_string(),
                _ => files::output::column_unit("sweep.csv", c, &units),
            };
            files::output::header_cell(c, &unit)
        })
        .collect();
    let mut csv = header.join(",") + "\n";
    let or_nan = |v: Option<f64>| v.unwrap_or(f64::NAN);
    for r in rows {
        let mut extra = String::new();
        for k in 0..dim {
            extra.push_str(&format!(",{:e}", or_nan(r.tangential_resultant.get(k).copied())));
        }
        if indenter {
            let i = r.indenter.as_ref();
            let h = i.and_then(|i| i.half_space);
            let values = [
                i.map(|i| i.depth),
                i.and_then(|i| i.charge),
                i.map(|i| i.force),
                i.map(|i| i.contact_radius),
                i.and_then(|i| i.potential),
                h.map(|h| h.0),
                h.map(|h| h.1),
                h.and_then(|h| h.2),
            ];
            for v in values {
                extra.push_str(&format!(",{:e}", or_nan(v)));
            }
        }
        for pick in [1, 2] {
            for g in &groups {
                let t = r.terminals.iter().find(|t| &t.0 == g);
                let v = t.map(|t| if pick == 1 { t.1 } else { t.2 });
                extra.push_str(&format!(",{:e}", or_nan(v)));
            }
        }
        let error = match (errors, &r.error) {
            (false, _) => String::new(),
            (true, e) => format!(",{}", files::output::csv_field(e.as_deref().unwrap_or(""))),
        };
        let value = match integer {
            true => format!("{}", r.value as i64),
            false => format!("{:e}", r.value),
        };
        csv.push_str(&format!(
            "{value},{},{},{},{:e},{:e},{:.3e},{:.3e},{},{},{:.4}{extra}{error}\n",
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
    csv
}

/// The quantity a swept key is (for its unit): a potential, a pressure, a force, a length or
/// displacement, a material constant, a charge, a traction, or none known (""); a component of
/// a list (`material.0.c.3`) is of the list's quantity.
pub fn param_quantity(param: &str) -> &'static str {
    let mut parts = param.rsplit('.');
    let mut last = parts.next().unwrap_or(param);
    if last.parse::<usize>().is_ok() {
        last = parts.next().unwrap_or(last);
    }
    match last {
        l if l.ends_with("potential") || matches!(l, "phi" | "voltage" | "v") => "potential",
        "p" | "pressure" => "pressure",
        l if l.ends_with("force") => "force",
        l if l.ends_with("depth") || l.ends_with("gap") || l.ends_with("radius") => "length",
        "h" | "lo" | "hi" | "thickness" | "gap_center" | "tip" | "slip_length" => "length",
        "u" | "ux" | "uy" | "uz" => "displacement",
        "c" | "young" => "stiffness",
        "e" => "piezoelectric",
        "permittivity" => "permittivity",
        "charge" => "charge",
        "slip_bound" => "traction",
        _ => "",
    }
}

/// The piezoresponse of a sweep over a potential with an indenter: the slope of the indenter's
/// depth against the potential, a least-squares line through the points that solved, in pm/V
/// (the scene's units converted, [`problem::Units::pm_per_volt`]), and the number of points;
/// `None` where the key is not a potential or fewer than two points have a depth.
pub fn piezoresponse(param: &str, rows: &[SweepRow]) -> Option<(f64, usize)> {
    if param_quantity(param) != "potential" {
        return None;
    }
    let points: Vec<(f64, f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.value, r.indenter.as_ref()?.depth, r.units.as_ref()?.pm_per_volt)))
        .filter(|(v, d, _)| v.is_finite() && d.is_finite())
        .collect();
    let n = points.len();
    if n < 2 {
        return None;
    }
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y, _)| (a + x / n as f64, b + y / n as f64));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y, _)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (sxx > 0.0).then(|| (sxy / sxx * points[0].2, n))
}

/// The panels against the parameter: the contact states, the contact forces, and where the
/// sweep has them, an indenter's depth (the piezoresponse against a voltage) and the charges
/// (each terminal's, a conducting tip's).
///
/// # Errors
/// [`files::Error::Picture`] where plotters cannot draw.
pub fn picture(param: &str, rows: &[SweepRow]) -> Result<plots::Files, DriverError> {
    let along = |f: &dyn Fn(&SweepRow) -> f64| rows.iter().map(|r| (r.value, f(r))).collect::<Vec<_>>();
    let units = rows.iter().find_map(|r| r.units.clone()).unwrap_or_default();
    let x = units.label(param, param_quantity(param));
    let states = Panel {
        title: format!("Contact states along {param}"),
        labels: (x.clone(), "points".into()),
        series: vec![
            Series::line("separated", along(&|r| r.counts.2 as f64)),
            Series::line("slip", along(&|r| r.counts.1 as f64)),
            Series::line("stick", along(&|r| r.counts.0 as f64)),
        ],
    };
    let forces = Panel {
        title: "Contact forces".into(),
        labels: (x.clone(), units.label("force", "force")),
        series: vec![
            Series::line("normal (sum w lambda_n)", along(&|r| r.normal_force)),
            Series::line("tangential |sum w lambda_t|", along(&|r| r.tangential_force)),
        ],
    };
    let mut panels = vec![states, forces];
    if rows.iter().any(|r| r.indenter.is_some()) {
        let title = match piezoresponse(param, rows) {
            Some((r, n)) => format!("Indenter depth: response {r:.1} pm/V (least squares over {n} points)"),
            None => "Indenter depth".into(),
        };
        panels.push(Panel {
            title,
            labels: (x.clone(), units.label("depth", "length")),
            series: vec![Series::line(
                "depth",
                along(&|r| r.indenter.as_ref().map_or(f64::NAN, |i| i.depth)),
            )],
        });
    }
    let groups = terminal_groups(rows);
    let mut charges: Vec<Series> = groups
        .iter()
        .map(|g| {
            let of = |r: &SweepRow| r.terminals.iter().find(|t| &t.0 == g).map_or(f64::NAN, |t| t.1);
            Series::line(&format!("on {g}"), along(&of))
        })
        .collect();
    if rows
        .iter()
        .any(|r| r.indenter.as_ref().is_some_and(|i| i.charge.is_some()))
    {
        let tip = |r: &SweepRow| r.indenter.as_ref().and_then(|i| i.charge).unwrap_or(f64::NAN);
        charges.push(Series::line("on the tip", along(&tip)));
    }
    if !charges.is_empty() {
        panels.push(Panel {
            title: "Charges".into(),
            labels: (x.clone(), units.label("charge", "charge")),
            series: charges,
        });
    }
    Ok(plots::panels("sweep", &panels)?)
}

#[cfg(test)]
mod tests {
    use super::{csv, integer_key, param_quantity, picture, sweep, SweepSpec};
    use crate::DriverError;

    /// A sweep whose first points fail (nothing touches, and [exact] is refused there) keeps
    /// the point that solves: sweep.csv holds all three rows, the failed ones with their error,
    /// and the sweep ends with an error naming them; where every point fails, the first
    /// point's own error and nothing written.
    #[test]
    fn a_sweep_keeps_the_points_that_solve() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("sweep");
        let spec = |from: f64, to: f64, steps: usize| SweepSpec {
            param: "contact.indenter.depth".into(),
            from,
            to,
            steps,
        };
        let sets = ["mesh.n=40".to_string()];
        let e = sweep("indent-sphere", &sets, &spec(-0.01, 0.01, 3), Some(&dir), &mut |_| {}).unwrap_err();
        assert!(
            matches!(&e, DriverError::Unexpected { items, .. } if items.len() == 2),
            "{e}"
        );
        let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4, "{text}");
        assert!(lines[0].ends_with(",error"));
        assert!(lines[1].contains("nothing touches") && lines[2].contains("nothing touches"));
        assert!(lines[3].starts_with("1e-2,") && lines[3].ends_with(','), "{}", lines[3]);
        let none = tmp.path().join("none");
        let e = sweep(
            "indent-sphere",
            &sets,
            &spec(-0.01, -0.005, 2),
            Some(&none),
            &mut |_| {},
        )
        .unwrap_err();
        assert!(e.to_string().contains("exact.kind"), "{e}");
        assert!(!none.exists());
    }

    /// A piezoresponse sweep (`pfm`: a conductive tip pressed with a constant force, its
    /// voltage swept) keeps every figure the run reports: the indenter's depth (which the
    /// voltage moves: the response), force, contact radius, charge and potential, and each
    /// terminal's charge and potential; its picture has a panel for the depth and the charges.
    #[test]
    fn a_sweep_keeps_every_figure_of_its_runs() {
        let spec = SweepSpec {
            param: "contact.foundation_potential".into(),
            from: -2e-4,
            to: 2e-4,
            steps: 2,
        };
        let rows = sweep("pfm", &["mesh.n=24".into()], &spec, None, &mut |_| {}).unwrap();
        let text = csv(&spec.param, &rows, false);
        let lines: Vec<&str> = text.lines().collect();
        // each column's unit in its header, the scene's (lengths in µm, potentials in kV)
        for named in [
            "contact.foundation_potential [kV]",
            "indenter_depth [µm]",
            "indenter_force [mN]",
            "normal_force [mN]",
            "seconds [s]",
        ] {
            assert!(lines[0].split(',').any(|c| c == named), "{named}: {}", lines[0]);
        }
        let header: Vec<&str> = lines[0].split(',').map(files::output::column_name).collect();
        for column in [
            "indenter_depth",
            "indenter_force",
            "indenter_contact_radius",
            "indenter_charge",
            "indenter_potential",
            "charge_top",
            "potential_top",
        ] {
            assert!(header.contains(&column), "{column}: {}", lines[0]);
        }
        let at = |line: &str, column: &str| -> f64 {
            let k = header.iter().position(|h| *h == column).unwrap();
            line.split(',').nth(k).unwrap().parse().unwrap()
        };
        // the response: the depth under a constant force moves with the voltage
        let (d0, d1) = (at(lines[1], "indenter_depth"), at(lines[2], "indenter_depth"));
        assert!((d0 - d1).abs() > 1e-6 * d0.abs(), "{d0} {d1}");
        assert_eq!(at(lines[2], "indenter_potential"), 2e-4);
        assert!((at(lines[1], "indenter_force") - 0.3).abs() < 1e-9);
        let panels = picture(&spec.param, &rows).unwrap();
        assert_eq!(panels.len(), 2);
    }

    #[test]
    fn a_sweep_knows_an_integer_key_from_the_scene() {
        // written as the integers they are set to
        let spec = |param: &str, from: f64, to: f64, steps: usize| SweepSpec {
            param: param.into(),
            from,
            to,
            steps,
        };
        let s = spec("mesh.n", 4.0, 8.0, 2);
        let rows = sweep("paper", &[], &s, None, &mut |_| {}).unwrap();
        let text = csv(&s.param, &rows, true);
        let first: Vec<&str> = text.lines().skip(1).map(|l| l.split(',').next().unwrap()).collect();
        assert_eq!(first, ["4", "8"]);
        // a bound that is not whole, or more points than whole numbers, would run another
        // value than asked or one value twice: refused, naming the key
        for (bad, says) in [
            (
                spec("mesh.n", 4.0, 7.6, 2),
                "sweep --to 7.6: mesh.n takes whole numbers",
            ),
            (
                spec("mesh.n", 4.0, 8.0, 6),
                "there are 5 from 4 to 8 (give --steps 5 at most)",
            ),
            (spec("mesh.nx", 8.0, 16.5, 2), "mesh.nx takes whole numbers"),
        ] {
            let e = sweep("paper", &[], &bad, None, &mut |_| {}).unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
        let integer = |scene: &str, key: &str, bounds: [f64; 2]| integer_key(scene, &[], key, bounds).unwrap();
        assert!(integer("paper", "mesh.n", [8.0, 9.5]));
        assert!(!integer("paper", "load.p", [-4.0, -2.0]));
        assert!(integer("cattaneo-mindlin-cycle", "path.steps", [3.0, 7.0]));
        assert!(!integer("corner", "contact.1.gap", [-1.0, 0.0]));
        // a key the scene leaves out: the type its reader takes, whatever the bounds
        assert!(integer("paper", "mesh.nx", [8.0, 16.0]));
        assert!(!integer("paper", "material.0.coupling_scale", [0.0, 1.0]));
        assert!(!integer("paper", "contact.slip_bound", [0.0, 2.0]));
        // a component of a list is a number
        assert!(!integer("paper", "material.0.c.3", [100.0, 120.0]));
    }

    /// A swept key's quantity, for its unit in sweep.csv, the picture and the progress lines: a
    /// component of a list is of the list's quantity, a factor or a count has none.
    #[test]
    fn a_swept_key_knows_its_quantity() {
        for (param, q) in [
            ("load.p", "pressure"),
            ("electrode.v", "potential"),
            ("contact.foundation_potential", "potential"),
            ("material.0.c.3", "stiffness"),
            ("material.0.e.1", "piezoelectric"),
            ("dirichlet.0.u.1", "displacement"),
            ("contact.gap_center.0", "length"),
            ("mesh.h", "length"),
            ("dirichlet.2.charge", "charge"),
            ("contact.friction", ""),
            ("material.0.coupling_scale", ""),
            ("mesh.n", ""),
        ] {
            assert_eq!(param_quantity(param), q, "{param}");
        }
    }

    /// A key whose value is no number (a vector, a choice) is refused before any point runs,
    /// with the way to sweep a component (every point failed alike on the reader's type
    /// error, after running the others).
    #[test]
    fn a_sweep_of_what_is_no_number_is_refused_before_it_runs() {
        for (param, says) in [
            ("load.direction", "is a list of 2 values ([0.0, 1.0]), and a sweep varies one number: sweep one component, as --param load.direction.0"),
            ("contact.law", "is a string (\"coulomb\")"),
            ("mesh", "is a table"),
        ] {
            let s = SweepSpec {
                param: param.into(),
                from: 0.0,
                to: 1.0,
                steps: 2,
            };
            let e = sweep("paper", &[], &s, None, &mut |l| panic!("{param} ran: {l}")).unwrap_err();
            assert!(e.to_string().contains(says), "{param}: {e}");
        }
        // the swept key given by --set too: the sweep's values replaced it silently
        let s = SweepSpec {
            param: "load.p".into(),
            from: -1.0,
            to: -2.0,
            steps: 2,
        };
        let e = sweep(
            "paper",
            &["load={group=\"top\", p=-3.0, direction=[0.0, 1.0]}".into()],
            &s,
            None,
            &mut |l| panic!("ran: {l}"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("the sweep sets load.p on each of its runs (--param"), "{e}");
        // and a component sweeps
        let s = SweepSpec {
            param: "load.direction.0".into(),
            from: 0.0,
            to: 0.2,
            steps: 2,
        };
        let rows = sweep("paper", &["mesh.n=4".into()], &s, None, &mut |_| {}).unwrap();
        assert!(rows.iter().all(|r| r.error.is_none()));
    }

    /// A real key the scene leaves unset, swept between whole bounds, runs its points as given
    /// (they were once rounded to the bounds: coupling_scale 0, 0, 1, 1, 1 for 0 to 1 in 5).
    #[test]
    fn an_unset_real_key_is_swept_at_its_points() {
        let s = SweepSpec {
            param: "material.0.coupling_scale".into(),
            from: 0.0,
            to: 1.0,
            steps: 5,
        };
        let rows = sweep("paper", &["mesh.n=4".into()], &s, None, &mut |_| {}).unwrap();
        let values: Vec<f64> = rows.iter().map(|r| r.value).collect();
        assert_eq!(values, [0.0, 0.25, 0.5, 0.75, 1.0]);
        let forces: Vec<f64> = rows.iter().map(|r| r.normal_force).collect();
        assert!(
            forces.windows(2).all(|w| w[0] != w[1]),
            "each point its own run: {forces:?}"
        );
        // the tangential force's components beside its magnitude, as run.json's resultant
        let text = csv(&s.param, &rows, false);
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let at = |name: &str| header.iter().position(|h| h.starts_with(name)).unwrap();
        let (x, y, norm) = (
            at("tangential_force_x"),
            at("tangential_force_y"),
            at("tangential_force ["),
        );
        for (line, r) in text.lines().skip(1).zip(&rows) {
            let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap_or(f64::NAN)).collect();
            assert_eq!([v[x], v[y]], [r.tangential_resultant[0], r.tangential_resultant[1]]);
            assert!((v[x].hypot(v[y]) - v[norm]).abs() <= 1e-12 * v[norm].abs().max(1e-300));
        }
    }
}
