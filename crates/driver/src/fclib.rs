//! `piezocontact fclib`: third-party frictional contact problems (Siconos' text format, the
//! problems Siconos and FCLib compare solvers on) solved by the contact crate alone, each
//! reported with the crate's own residual and Siconos' error computed independently.

use crate::DriverError;
use contact::siconos::FrictionProblem;
use contact::{ContactError, ContactSolution, Interrupt, Law, Measure, NewtonParams, StopRule, UzawaParams};
use files::output::Outputs;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The contact crate's solvers, as the command names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// The semismooth Newton method (`contact::solve_newton`), block Gauss–Seidel sweeps first
    /// where their measured rate wins.
    Newton,
    /// The accelerated projected gradient with the fixed point on the slip bound.
    Apg,
    /// Uzawa's projected iteration with the fixed point on the slip bound.
    Uzawa,
    /// The block Gauss–Seidel method (`contact::solve_gauss_seidel`, Siconos' NSGS).
    Nsgs,
}

/// The residual the solver iterates on, as the command names it. Whichever it is, a file is
/// solved only where both residuals meet the tolerance (each breaks down where the other does
/// not: Siconos' error vanishes at `r = 0` for a huge `μ` or a tiny `q`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Criterion {
    /// The larger of the two (the default).
    Both,
    /// Siconos' error (De Saxcé's natural map, relative to max(|q|, |r|, |u|)).
    Siconos,
    /// The contact crate's complementarity residual.
    Crate,
}

impl Criterion {
    fn measure(self) -> Measure {
        match self {
            Criterion::Both => Measure::Both,
            Criterion::Siconos => Measure::DeSaxce,
            Criterion::Crate => Measure::Complementarity,
        }
    }
}

/// The tolerances a file can be solved to: below 1e-15 round-off keeps either residual above
/// it; at 1 and beyond, every point (even `r = 0`) passes.
pub const TOLERANCES: (f64, f64) = (1e-15, 1e-1);

impl Solver {
    /// The name the command line takes.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Newton => "newton",
            Solver::Apg => "apg",
            Solver::Uzawa => "uzawa",
            Solver::Nsgs => "nsgs",
        }
    }
}

/// What the command was asked.
#[derive(Clone, Debug)]
pub struct Options {
    /// The solver.
    pub solver: Solver,
    /// The tolerance, in [`TOLERANCES`].
    pub tol: f64,
    /// The residual the solver iterates on.
    pub criterion: Criterion,
    /// Time allowed per file (`None`: no limit).
    pub time_limit: Option<std::time::Duration>,
    /// Whether to print the solver's progress lines.
    pub verbose: bool,
}

impl Options {
    /// Checks the tolerance's range.
    ///
    /// # Errors
    /// [`DriverError::Usage`] naming the option.
    pub fn check(&self) -> Result<(), DriverError> {
        let (lo, hi) = TOLERANCES;
        if !(self.tol >= lo && self.tol <= hi) {
            return Err(DriverError::Usage(format!(
                "--tol {} is outside [{lo:e}, {hi:e}]: below it round-off keeps the residuals above it, above it every point passes (even r = 0)",
                self.tol
            )));
        }
        Ok(())
    }
}

/// One file's line of the summary.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The file's name.
    pub file: String,
    /// 2 or 3.
    pub dim: usize,
    /// Contacts.
    pub contacts: usize,
    /// The solver.
    pub solver: Solver,
    /// Steps: Newton steps plus first-order steps.
    pub iterations: usize,
    /// Wall time of the solve (reading excluded), seconds.
    pub time_s: f64,
    /// The crate's complementarity residual of the answer.
    pub residual: f64,
    /// Siconos' error of the answer.
    pub siconos_error: f64,
    /// Whether both residuals meet the tolerance (the file is solved).
    pub converged: bool,
    /// `solved`, or the solver's error.
    pub outcome: String,
    /// The CSV of `(r, u)` in the output set (solved files, with `--out`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub csv: Option<String>,
}

/// A solution in Siconos' terms: the reactions `r` and the velocities `u = W r + q`.
pub type Reactions = (Vec<f64>, Vec<f64>);

/// Reads one file.
///
/// # Errors
/// [`files::Error::File`] when the file cannot be read or is not a problem.
pub fn read(path: &Path) -> Result<FrictionProblem, DriverError> {
    let bad = |message: String| -> DriverError {
        files::Error::File {
            file: path.display().to_string(),
            message,
        }
        .into()
    };
    // a FIFO or a device would block the read, or never end it
    let meta = std::fs::metadata(path).map_err(|e| bad(e.to_string()))?;
    if !meta.is_file() {
        return Err(bad("is not a regular file (a directory, a FIFO or a device)".into()));
    }
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let problem = FrictionProblem::parse(&text).map_err(|e| bad(e.to_string()))?;
    if let Some(why) = problem.indefinite() {
        return Err(bad(why));
    }
    Ok(problem)
}

/// Solves the problem of file `file` (its name, for the row); the solution (when there is one)
/// in Siconos' terms `(r, u)`. A solver that fails gives a row with its error.
pub fn solve(
    file: &str,
    problem: &FrictionProblem,
    options: &Options,
    say: &mut dyn FnMut(&str),
) -> (Row, Option<Reactions>) {
    let start = Instant::now();
    let interrupt = Interrupt {
        deadline: options.time_limit.and_then(|l| start.checked_add(l)),
        cancel: None,
    };
    let mut progress = |p: &contact::Progress| {
        if options.verbose {
            let (stick, slip, separated) = p.counts;
            say(&format!(
                "  {:>11} {:>6}  residual {:.3e}  stick {stick} slip {slip} separated {separated}",
                p.stage.name(),
                p.iter,
                p.residual
            ));
        }
    };
    let solved = run_solver(problem, options, interrupt, &mut progress);
    let time_s = start.elapsed().as_secs_f64();
    let mut row = Row {
        file: file.to_string(),
        dim: problem.dim,
        contacts: problem.n_contacts(),
        solver: options.solver,
        iterations: 0,
        time_s,
        residual: f64::NAN,
        siconos_error: f64::NAN,
        converged: false,
        outcome: String::new(),
        csv: None,
    };
    match solved {
        Ok(sol) => {
            let r = problem.reaction(&sol.lambda);
            let u = problem.velocity(&r);
            row.iterations = sol.info.newton_iters + sol.info.uzawa_iters + sol.info.sweeps;
            row.residual = sol.info.complementarity;
            row.siconos_error = problem.error(&r);
            let tol = options.tol;
            let failed: Vec<String> = [
                ("the contact crate's complementarity residual", row.residual),
                ("Siconos' error", row.siconos_error),
            ]
            .iter()
            .filter(|(_, v)| !(*v <= tol))
            .map(|(what, v)| format!("{what} {v:.2e}"))
            .collect();
            row.converged = failed.is_empty();
            row.outcome = if row.converged {
                "solved".into()
            } else {
                format!(
                    "not solved: {} above the tolerance {tol:e} (the solver met its criterion, {})",
                    failed.join(" and "),
                    options.criterion.name()
                )
            };
            let solved = row_solution(row.converged, r, u);
            (row, solved)
        }
        Err(e) => {
            if let Some(best) = e.best() {
                let r = problem.reaction(&best.lambda);
                row.residual = best.residual;
                row.siconos_error = problem.error(&r);
            }
            row.outcome = e.to_string();
            (row, None)
        }
    }
}

/// Runs the solver `options` name on `problem`, reporting to `progress`.
fn run_solver(
    problem: &FrictionProblem,
    options: &Options,
    interrupt: Interrupt,
    progress: &mut dyn FnMut(&contact::Progress),
) -> Result<ContactSolution, ContactError> {
    let mut sparse = problem.sparse_problem();
    let points = problem.points();
    match options.solver {
        Solver::Newton => {
            let params = NewtonParams {
                tol: options.tol,
                measure: options.criterion.measure(),
                interrupt,
                schedule: contact::Schedule::of(contact::ProblemClass::Multibody),
                ..Default::default()
            };
            contact::solve_newton(&mut sparse, &points, &Law::Coulomb, &params, None, progress)
        }
        Solver::Nsgs => {
            let params = contact::GaussSeidelParams {
                tol: options.tol,
                measure: options.criterion.measure(),
                interrupt,
                report_every: 10,
                ..Default::default()
            };
            contact::solve_gauss_seidel(&mut sparse, &points, &Law::Coulomb, &params, None, progress)
        }
        Solver::Apg | Solver::Uzawa => {
            let params = UzawaParams {
                rule: StopRule::Tight { tol: options.tol },
                accelerate: options.solver == Solver::Apg,
                measure: options.criterion.measure(),
                interrupt,
                ..Default::default()
            };
            contact::solve_uzawa(&mut sparse, &points, &Law::Coulomb, &params, None, progress)
        }
    }
}

/// The solution of a solved row (`None` for one that is not).
fn row_solution(solved: bool, r: Vec<f64>, u: Vec<f64>) -> Option<Reactions> {
    solved.then_some((r, u))
}

impl Criterion {
    /// The name the command line takes.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Both => "both",
            Criterion::Siconos => "siconos",
            Criterion::Crate => "crate",
        }
    }
}

/// The table's header and one line per row, for the terminal.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:40} {:>3} {:>8} {:>7} {:>6} {:>9} {:>10} {:>10}  {}\n",
        "file", "dim", "contacts", "solver", "iters", "time (s)", "residual", "siconos", "outcome"
    );
    let solved = rows.iter().filter(|r| r.converged).count();
    for r in rows {
        s += &format!(
            "{:40} {:>3} {:>8} {:>7} {:>6} {:>9.3} {:>10.2e} {:>10.2e}  {}\n",
            r.file,
            r.dim,
            r.contacts,
            r.solver.name(),
            r.iterations,
            r.time_s,
            r.residual,
            r.siconos_error,
            r.outcome
        );
    }
    s + &format!("solved {solved} of {}\n", rows.len())
}

/// `r` and `u` contact by contact, as CSV: `contact, r_n, r_t1[, r_t2], u_n, u_t1[, u_t2]`.
pub fn solution_csv(dim: usize, r: &[f64], u: &[f64]) -> String {
    let names = ["n", "t1", "t2"];
    let mut s = String::from("contact");
    for v in ["r", "u"] {
        for name in &names[..dim] {
            s += &format!(",{v}_{name}");
        }
    }
    s.push('\n');
    for (i, (ri, ui)) in r.chunks(dim).zip(u.chunks(dim)).enumerate() {
        s += &i.to_string();
        for x in ri.iter().chain(ui) {
            s += &format!(",{x:e}");
        }
        s.push('\n');
    }
    s
}

/// The name of the CSV of the file at `path`: its stem made a safe file name, with `-2`, `-3`,
/// ... where files of one name from several directories would share it.
fn csv_name<'a>(path: &Path, taken: impl Iterator<Item = &'a str>) -> String {
    let stem = path
        .file_stem()
        .map_or_else(|| "problem".to_string(), |s| s.to_string_lossy().into_owned());
    let base = files::output::safe_file_name(&stem, "problem");
    let taken: Vec<&str> = taken.collect();
    let mut name = format!("{base}.csv");
    let mut k = 2;
    while taken.contains(&name.as_str()) || name == "summary.json" {
        name = format!("{base}-{k}.csv");
        k += 1;
    }
    name
}

/// Reads every file (so that a broken one stops the command before any solve), solves each,
/// and with `out` writes `summary.json` and one CSV of `(r, u)` per solved file, as one set.
///
/// # Errors
/// A file that cannot be read or parsed, or outputs that cannot be written.
pub fn run(
    files: &[PathBuf],
    options: &Options,
    out: Option<&Path>,
    say: &mut dyn FnMut(&str),
) -> Result<Vec<Row>, DriverError> {
    let problems = files.iter().map(|p| read(p)).collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    let mut outputs = out.map(Outputs::new);
    for (path, problem) in files.iter().zip(&problems) {
        let name = path
            .file_name()
            .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
        let (row, solution) = solve(&name, problem, options, say);
        say(&format!(
            "{}: {} in {:.3} s, siconos error {:.2e}",
            row.file, row.outcome, row.time_s, row.siconos_error
        ));
        let mut row = row;
        if let (Some(outputs), Some((r, u))) = (outputs.as_mut(), solution) {
            let csv = csv_name(path, outputs.names());
            outputs.add(&csv, solution_csv(row.dim, &r, &u).into_bytes());
            row.csv = Some(csv);
        }
        rows.push(row);
    }
    if let Some(mut outputs) = outputs {
        let json = serde_json::to_vec_pretty(&rows).map_err(|e| files::Error::Picture {
            name: "summary.json".into(),
            message: e.to_string(),
        })?;
        outputs.add("summary.json", json);
        outputs.commit()?;
    }
    Ok(rows)
}
