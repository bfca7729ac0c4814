//! Hostile and unusual inputs, by family (issue 12's classes): each a shipped scene with
//! overrides and the outcome it must have: it solves (to finite outputs whose residuals meet
//! the tolerance), or it is refused with a typed error whose message names what is wrong, and
//! nothing is written. `piezocontact stability` runs them, each in its own process with a time
//! limit, into a section of docs/stability.md; a test runs them in process.

use super::child::run_with_limit;
use problem::RunReport;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// What an input must give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A solution, its residuals within the tolerance, every number finite.
    Solves,
    /// A typed error whose message holds this text, and no output.
    Refused(&'static str),
}

/// One input of a family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Input {
    /// The family (the class of silent wrong answer it once gave, or a message that named
    /// nothing).
    pub family: &'static str,
    /// The shipped scene.
    pub scene: &'static str,
    /// Its overrides (a small mesh among them).
    pub sets: &'static [&'static str],
    /// What it must give.
    pub expect: Outcome,
}

const fn input(family: &'static str, scene: &'static str, sets: &'static [&'static str], expect: Outcome) -> Input {
    Input {
        family,
        scene,
        sets,
        expect,
    }
}

use Outcome::{Refused, Solves};

/// The inputs (the Gmsh files of the mesh families are in `tests/bad-input` and the mesh
/// crate's tests: they need files, not overrides).
pub const INPUTS: &[Input] = &[
    input(
        "contact normal",
        "paper",
        &["mesh.n=8", "contact.normal=[0, 1]"],
        Refused("makes 180° with the outward normal"),
    ),
    input(
        "contact normal",
        "paper",
        &["mesh.n=8", "contact.normal=[1, 0]"],
        Refused("makes 90° with the outward normal"),
    ),
    input(
        "contact normal",
        "paper",
        &["mesh.n=8", "contact.normal=[0, -1e300]"],
        Solves,
    ),
    input(
        "contact normal",
        "paper",
        &["mesh.n=8", "contact.normal=[0, -1e-300]"],
        Solves,
    ),
    input(
        "load direction",
        "paper",
        &["mesh.n=8", "load.direction=[0, 10]"],
        Solves,
    ),
    input(
        "load direction",
        "paper",
        &["mesh.n=8", "load.direction=[0, 0]"],
        Refused("load.direction is the zero vector"),
    ),
    input(
        "tolerance",
        "paper",
        &["mesh.n=8", "solver.tol=1"],
        Refused("solver.tol = 1e0 is outside"),
    ),
    input(
        "tolerance",
        "paper",
        &["mesh.n=8", "solver.tol=1e-308"],
        Refused("solver.tol = 1e-308 is outside"),
    ),
    input(
        "tolerance",
        "paper",
        &["mesh.n=8", "solver.strategy=uzawa-schur-pcg", "solver.pcg_tol=0"],
        Refused("solver.pcg_tol = 0e0 is outside"),
    ),
    input(
        "cancelling loads",
        "paper",
        &["mesh.n=8", "load.group=bottom", "load.direction=[0, -1]"],
        Solves,
    ),
    input("data scale", "paper", &["mesh.n=8", "load.p=-1e-300"], Solves),
    input("data scale", "paper", &["mesh.n=8", "load.p=-1e-200"], Solves),
    input("data scale", "paper", &["mesh.n=8", "load.p=-1e200"], Solves),
    input("data scale", "paper", &["mesh.n=8", "load.p=-1e300"], Solves),
    input("data scale", "paper-3d", &["mesh.n=2", "load.p=-1e-250"], Solves),
    input(
        "overflow",
        "paper",
        &["mesh.n=8", "contact.law=none", "load.p=-1e308"],
        Refused("is not finite: the data overflow double precision; the most extreme inputs are load.p = -1e308"),
    ),
    input(
        "overflow",
        "paper",
        &["mesh.n=8", "contact.gap=-1e308"],
        Refused("the most extreme inputs are contact.gap = -1e308"),
    ),
    input(
        "overflow",
        "actuator",
        &["mesh.n=8", "electrode.v=1e308"],
        Refused("the most extreme inputs are electrode.v = 1e308"),
    ),
    input(
        "overflow",
        "paper",
        &["mesh.n=8", "material.c=[1e308, 75.4, 75.2, 111.0, 21.1, 22.6]"],
        Refused("material.c = 1e308 is outside [1e-100, 1e100]"),
    ),
    input(
        "overflow",
        "paper",
        &["mesh.n=8", "material.coupling_scale=1e300"],
        Refused("material.coupling_scale = 1e300 is outside"),
    ),
    input(
        "extreme but finite",
        "paper",
        &["mesh.n=8", "contact.friction=1e308"],
        Solves,
    ),
    input(
        "extreme but finite",
        "paper",
        &["mesh.n=8", "contact.gap=1e300"],
        Solves,
    ),
    input(
        "keys that do not apply",
        "paper",
        &["mesh.n=8", "contact.law=signorini"],
        Refused("contact.friction does not apply"),
    ),
    input(
        "keys that do not apply",
        "paper-tresca",
        &["mesh.n=8", "contact.friction=0.3"],
        Refused("contact.friction does not apply"),
    ),
    input(
        "keys that do not apply",
        "paper",
        &["mesh.n=8", "solver.pcg_tol=1e-8"],
        Refused("solver.pcg_tol does not apply"),
    ),
    input(
        "keys that do not apply",
        "paper",
        &["mesh.n=8", "mesh.nx=8", "mesh.ny=4"],
        Refused("mesh.n does not apply"),
    ),
    input(
        "keys that do not apply",
        "pfm-film",
        &["mesh.n=8"],
        Refused("mesh.n does not apply"),
    ),
    input(
        "inputs silently dropped",
        "paper",
        &["mesh.n=8", "~material.poling"],
        Refused("crystal-6mm needs poling"),
    ),
    // issue 20: prescribed components on contact nodes (a roller through the contact face)
    input(
        "prescribed components on contact nodes",
        "paper",
        &["mesh.n=8", "~dirichlet.1.u", "dirichlet.1.ux=0"],
        Solves,
    ),
    input(
        "prescribed components on contact nodes",
        "paper-3d",
        &["mesh.n=2", "~dirichlet.1.u", "dirichlet.1.ux=0"],
        Solves,
    ),
    input(
        "prescribed components on contact nodes",
        "paper",
        &["mesh.n=8", "dirichlet.2.group=bottom", "dirichlet.2.ux=0"],
        Solves,
    ),
    input(
        "prescribed components on contact nodes",
        "paper",
        &["mesh.n=8", "dirichlet.2.group=bottom", "dirichlet.2.uy=0"],
        Refused("contact never acts"),
    ),
    input(
        "prescribed components on contact nodes",
        "paper",
        &["mesh.n=8", "contact.gap=-1e-3"],
        Solves,
    ),
    input(
        "numbers",
        "paper",
        &["mesh.n=8", "load.p=1e400"],
        Refused("is beyond double precision"),
    ),
    input(
        "numbers",
        "paper",
        &["mesh.n=99999999999999999999"],
        Refused("an integer beyond 64 bits"),
    ),
    input("numbers", "paper", &["mesh.h=1/8"], Solves),
    input(
        "numbers",
        "paper",
        &["mesh.h=10"],
        Refused("longer than the body's shortest side"),
    ),
    input("numbers", "layered", &["mesh.n=10", "material.1.young=0.02"], Solves),
    input(
        "accepted means honoured",
        "paper",
        &["mesh.n=8", "material.coupling_scale=1e6"],
        Solves,
    ),
    input(
        "accepted means honoured",
        "paper",
        &["mesh.n=8", "material.coupling_scale=1e8"],
        Refused("the coupling number e²/(c ε)"),
    ),
    input(
        "slow failures",
        "paper",
        &[
            "mesh.n=32",
            "material.coupling_scale=100",
            "solver.strategy=uzawa-condensed",
        ],
        Refused("it stopped improving"),
    ),
    input("memory", "paper", &["mesh.n=4000"], Refused("more than the")),
    input("memory", "paper-3d", &["mesh.n=60"], Refused("more than the")),
];

/// The outcome of one input.
#[derive(Clone, Debug, PartialEq)]
pub struct InputRow {
    /// The input.
    pub input: Input,
    /// What happened, in words.
    pub outcome: String,
    /// Wall time of the process (s).
    pub seconds: f64,
    /// Whether it is what the input must give.
    pub as_expected: bool,
}

/// Checks a finished run's report against `Solves`: converged, finite.
pub fn check_solved(report: &RunReport) -> Result<String, String> {
    let r = &report.residuals;
    let numbers = [
        r.equilibrium,
        r.complementarity,
        report.contact.normal_force,
        report.contact.tangential_force,
    ];
    if !numbers.iter().all(|x| x.is_finite()) {
        return Err(format!("a reported number is not finite: {numbers:?}"));
    }
    if !(r.converged_to_tolerance && r.complementarity <= report.solver.tol && r.equilibrium <= 1e-8) {
        return Err(format!(
            "not converged: complementarity {:.1e}, equilibrium {:.1e}",
            r.complementarity, r.equilibrium
        ));
    }
    let c = &report.contact;
    Ok(format!(
        "solved ({}); stick {}, slip {}, separated {}",
        report.iterations.summary(),
        c.n_stick,
        c.n_slip,
        c.n_separated
    ))
}

/// Runs one input through `exe run`, with a time limit.
fn run_input(exe: &Path, input: Input, index: usize, limit: Duration) -> InputRow {
    let scratch = std::env::temp_dir().join(format!("piezocontact-inputs-{}-{index}", std::process::id()));
    let mut cmd = Command::new(exe);
    cmd.arg("run").arg(input.scene).arg("--out").arg(&scratch);
    for s in input.sets {
        cmd.arg("--set").arg(s);
    }
    let started = Instant::now();
    let output = run_with_limit(cmd, limit);
    let seconds = started.elapsed().as_secs_f64();
    let wrote = scratch.exists();
    let report = std::fs::read(scratch.join("run.json"))
        .ok()
        .and_then(|b| serde_json::from_slice::<RunReport>(&b).ok());
    let _ = std::fs::remove_dir_all(&scratch);
    let (outcome, as_expected) = match output {
        Err(e) => (format!("CRASHED: could not start: {e}"), false),
        Ok(out) => {
            let stderr = String::from_utf8_lossy(&out.stderr);
            let message = stderr
                .lines()
                .rev()
                .find(|l| l.starts_with("error:"))
                .unwrap_or("")
                .to_string();
            match (out.status.code(), input.expect, report) {
                (None, _, _) => (format!("killed (a hang or a signal) after {seconds:.0} s"), false),
                (Some(0), Solves, Some(r)) => match check_solved(&r) {
                    Ok(s) => (s, true),
                    Err(e) => (format!("UNEXPECTED: {e}"), false),
                },
                (Some(1), Refused(text), None) if !wrote && message.contains(text) => (message, true),
                (code, _, _) => (format!("UNEXPECTED: exit {code:?}, wrote {wrote}: {message}"), false),
            }
        }
    };
    InputRow {
        input,
        outcome,
        seconds,
        as_expected,
    }
}

/// Runs every input through `exe`.
pub fn study(exe: &Path, progress: &mut dyn FnMut(&str)) -> Vec<InputRow> {
    INPUTS
        .iter()
        .enumerate()
        .map(|(k, &input)| {
            let row = run_input(exe, input, k, Duration::from_secs(120));
            progress(&format!(
                "{:24} {:12} {:60} {:6.2} s  {}",
                input.family,
                input.scene,
                input.sets.join(" "),
                row.seconds,
                row.outcome
            ));
            row
        })
        .collect()
}

/// The section of docs/stability.md.
pub fn markdown(rows: &[InputRow]) -> String {
    let mut s = String::from("\n## Hostile and unusual inputs\n\n");
    let _ = writeln!(
        s,
        "Each input runs in its own process (time limit 120 s). It must solve, to finite outputs whose residuals meet the tolerance, or be refused with a typed error that names what is wrong, writing nothing; a hang, a crash, a non-finite output or an error that names nothing is a failure. The Gmsh families (node tags in any order, duplicated groups, interior or doubled facets, overlapping or duplicate cells, wholly inverted tetrahedra) are tested with files in `tests/bad-input` and the mesh crate's tests; `crates/driver/tests/input_ranges.rs` draws further inputs at random across the range of `f64`.\n"
    );
    s.push_str("| family | scene | overrides | time (s) | outcome |\n|---|---|---|---|---|\n");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | `{}` | {:.2} | {}{} |",
            r.input.family,
            r.input.scene,
            r.input.sets.join(" "),
            r.seconds,
            if r.as_expected { "" } else { "**NOT AS EXPECTED**: " },
            r.outcome.replace('|', "\\|")
        );
    }
    let bad = rows.iter().filter(|r| !r.as_expected).count();
    let _ = writeln!(
        s,
        "\n{} inputs, {} as expected, {bad} not.",
        rows.len(),
        rows.len() - bad
    );
    s
}
