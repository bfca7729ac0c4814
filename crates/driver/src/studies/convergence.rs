//! The convergence study (`piezocontact study`): one scene over mesh sizes, strategies and
//! tolerances, and for every run its error and its wall time.
//!
//! Every error says what it is measured against:
//! - a scene with an `[exact]` section is measured against its exact solution (run.json's
//!   `exact.error`: the energy norm for field solutions, the traction profile for Hertz and
//!   Cattaneo-Mindlin);
//! - any other scene against a run on a finer mesh (`reference_n`, nested, so that every node
//!   of a coarse mesh is a node of the fine one), by the relative l2 difference of the contact
//!   multipliers at the coarse contact nodes (of the displacements at the coarse nodes when
//!   the scene has no contact).
//!
//! The *discretisation* error of a size is that of a tight run on it (the default strategy to
//! `1e-12`); the *algebraic* error of a run is its difference from that tight run (same
//! measure); the *total* error is the run's own error against the reference.

use crate::run::{run, RunOutcome, STRATEGIES};
use crate::scene;
use crate::DriverError;
use std::collections::HashMap;
use std::fmt::Write as _;

/// The tolerance of the tight runs that give the discretisation error.
pub const TIGHT_TOL: f64 = 1e-12;

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct StudySpec {
    /// Mesh sizes (`mesh.n`), coarse to fine.
    pub sizes: Vec<usize>,
    /// Strategies (names of [`STRATEGIES`]).
    pub strategies: Vec<String>,
    /// Tolerances (`solver.tol`; for a scene without contact, the Schur PCG's tolerance).
    pub tols: Vec<f64>,
    /// The size of the reference run, for a scene without an exact solution (default: four
    /// times the largest size).
    pub reference_n: Option<usize>,
}

/// One run of the study.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyRow {
    /// `mesh.n`.
    pub n: usize,
    /// Largest cell diameter.
    pub h: f64,
    /// Free unknowns, u + φ.
    pub dofs: u64,
    /// Strategy.
    pub strategy: String,
    /// Tolerance.
    pub tol: f64,
    /// Outer iterations (Newton steps, else Uzawa steps, else PCG iterations).
    pub iterations: u64,
    /// What `iterations` counts.
    pub iteration_kind: &'static str,
    /// Wall time of the whole run (run.json `timings_s.total`), s.
    pub seconds: f64,
    /// The run's error against the reference (exact or finer mesh).
    pub error: f64,
    /// The discretisation error of this size (the tight run's error).
    pub discretisation: f64,
    /// The difference from the tight run on the same mesh.
    pub algebraic: f64,
}

/// A finished study.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// The scene's name.
    pub scene: String,
    /// What the errors are measured against, in words.
    pub against: String,
    /// The runs.
    pub rows: Vec<StudyRow>,
    /// `(n, discretisation error, h)` of the tight runs, coarse to fine.
    pub tight: Vec<(usize, f64, f64)>,
}

impl Study {
    /// Observed orders `log(e0/e1) / log(h0/h1)` between successive sizes of the tight runs.
    pub fn rates(&self) -> Vec<(usize, usize, f64)> {
        self.tight
            .windows(2)
            .map(|w| (w[0].0, w[1].0, (w[0].1 / w[1].1).ln() / (w[0].2 / w[1].2).ln()))
            .collect()
    }
}

/// The fields a comparison needs from a run.
struct Snapshot {
    nodes: Vec<[f64; 3]>,
    u: Vec<[f64; 3]>,
    contact: Option<(Vec<[f64; 3]>, Vec<f64>)>,
    exact: Option<f64>,
}

impl Snapshot {
    fn of(r: &RunOutcome) -> Self {
        let contact = r.contact.as_ref().map(|(p, sol)| {
            let nt = sol.lambda.tangential.len() / p.len().max(1);
            let mut v = Vec::with_capacity(p.len() * (1 + nt));
            for i in 0..p.len() {
                v.push(sol.lambda.normal[i]);
                v.extend_from_slice(&sol.lambda.tangential[i * nt..(i + 1) * nt]);
            }
            (p.position.clone(), v)
        });
        Snapshot {
            nodes: r.nodes.clone(),
            u: r.u.clone(),
            contact,
            exact: r.report["exact"]["error"].as_f64(),
        }
    }

    /// Relative l2 difference of `self` from `reference` at the points of `self` (matched by
    /// position); an error if a point has no match.
    fn difference(&self, reference: &Snapshot) -> Result<f64, DriverError> {
        let key = |x: &[f64; 3]| x.map(|c| (c * 1e9).round() as i64);
        let (pts, vals, rpts, rvals, width) = match (&self.contact, &reference.contact) {
            (Some((p, v)), Some((rp, rv))) => (p, v.clone(), rp, rv.clone(), v.len() / p.len().max(1)),
            _ => {
                let flat = |u: &[[f64; 3]]| u.iter().flat_map(|x| x.iter().copied()).collect::<Vec<f64>>();
                (&self.nodes, flat(&self.u), &reference.nodes, flat(&reference.u), 3)
            }
        };
        let rw = rvals.len() / rpts.len().max(1);
        if rw != width {
            return Err(DriverError::Input(
                "the reference run has another number of multipliers per point".into(),
            ));
        }
        let index: HashMap<[i64; 3], usize> = rpts.iter().enumerate().map(|(i, x)| (key(x), i)).collect();
        let (mut num, mut den) = (0.0, 0.0);
        for (i, x) in pts.iter().enumerate() {
            let j = *index.get(&key(x)).ok_or_else(|| {
                DriverError::Input(format!(
                    "the point ({:.6}, {:.6}, {:.6}) of the coarse mesh is not a node of the reference mesh (a finer mesh must contain the coarse one: use a multiple of mesh.n)",
                    x[0], x[1], x[2]
                ))
            })?;
            for k in 0..width {
                num += (vals[i * width + k] - rvals[j * width + k]).powi(2);
                den += rvals[j * width + k].powi(2);
            }
        }
        Ok(if den > 0.0 { (num / den).sqrt() } else { num.sqrt() })
    }
}

fn iterations(r: &RunOutcome) -> (u64, &'static str) {
    let it = &r.report["iterations"];
    let get = |k: &str| it[k].as_u64().unwrap_or(0);
    if get("newton") > 0 {
        (get("newton"), "Newton")
    } else if get("uzawa") > 0 {
        // the accelerated gradient counts its steps with Uzawa's
        let accelerated = r.report["solver"]["strategy"] == "apg-condensed";
        (get("uzawa"), if accelerated { "APG" } else { "Uzawa" })
    } else if get("pcg") > 0 {
        (get("pcg"), "PCG")
    } else {
        (0, "direct")
    }
}

fn settings(sets: &[String], n: usize, strategy: &str, tol: f64, has_contact: bool) -> Vec<String> {
    let mut s = sets.to_vec();
    s.push(format!("mesh.n={n}"));
    s.push(format!("solver.strategy=\"{strategy}\""));
    s.push("solver.rule=\"tight\"".into());
    s.push(format!("solver.tol={tol:e}"));
    if !has_contact || strategy == "uzawa-schur-pcg" {
        // the PCG's own tolerance: the whole algebraic error without contact
        s.push(format!(
            "solver.pcg_tol={:e}",
            if has_contact { tol.min(1e-10) } else { tol }
        ));
    }
    s
}

/// Runs the study of `scene_name` (with the overrides `sets`); `progress` gets a line per run.
pub fn study(
    scene_name: &str,
    sets: &[String],
    spec: &StudySpec,
    progress: &mut dyn FnMut(&str),
) -> Result<Study, DriverError> {
    if spec.sizes.is_empty() || spec.strategies.is_empty() || spec.tols.is_empty() {
        return Err(DriverError::Input(
            "a study needs at least one size, strategy and tolerance".into(),
        ));
    }
    for s in &spec.strategies {
        if !STRATEGIES.iter().any(|(n, _)| n == s) {
            return Err(DriverError::Input(format!(
                "strategy `{s}` is unknown (see `piezocontact strategies`)"
            )));
        }
    }
    if let Some(t) = spec.tols.iter().find(|t| !(**t > 0.0 && t.is_finite())) {
        return Err(DriverError::Input(format!("tolerance {t} must be positive")));
    }
    let mut sizes = spec.sizes.clone();
    sizes.sort_unstable();
    sizes.dedup();
    let (base, _) = scene::load(scene_name, sets)?;
    let has_contact = base.contact.as_ref().is_some_and(|c| c.law != "none");
    let has_exact = base.exact.is_some();
    let one = |n: usize, strategy: &str, tol: f64, progress: &mut dyn FnMut(&str)| -> Result<RunOutcome, DriverError> {
        let (sc, src) = scene::load(scene_name, &settings(sets, n, strategy, tol, has_contact))?;
        let r = run(&sc, &src, None, &mut |_| {})?;
        progress(&format!(
            "study {}: n = {n}, {strategy}, tol {tol:.0e}: {:.3} s",
            base.name,
            r.report["timings_s"]["total"].as_f64().unwrap_or(0.0)
        ));
        Ok(r)
    };
    let reference = if has_exact {
        None
    } else {
        let largest = *sizes.last().expect("checked non-empty");
        let n_ref = spec.reference_n.unwrap_or(4 * largest);
        if n_ref <= largest || n_ref % largest != 0 {
            return Err(DriverError::Input(format!(
                "the reference size {n_ref} must be a multiple of the largest size {largest}, and larger"
            )));
        }
        Some((
            n_ref,
            Snapshot::of(&one(n_ref, "newton-condensed", TIGHT_TOL, progress)?),
        ))
    };
    let against = match (&reference, &base.exact) {
        (Some((n_ref, _)), _) => format!(
            "a tight run on the finer mesh n = {n_ref}: relative l2 difference of the {} ",
            if has_contact {
                "contact multipliers at the coarse contact nodes"
            } else {
                "displacements at the coarse nodes"
            }
        ),
        (None, Some(x)) => format!(
            "the exact solution ({}): {}",
            x.kind,
            crate::exact::KINDS
                .iter()
                .find(|(k, _)| *k == x.kind)
                .map_or("", |(_, d)| d)
        ),
        (None, None) => unreachable!("a scene has an exact solution or gets a reference run"),
    };
    let error_of = |snap: &Snapshot| -> Result<f64, DriverError> {
        match &reference {
            Some((_, r)) => snap.difference(r),
            None => snap
                .exact
                .ok_or_else(|| DriverError::Input("the run reported no exact error".into())),
        }
    };
    let mut rows = vec![];
    let mut tight = vec![];
    for &n in &sizes {
        let t_run = one(n, "newton-condensed", TIGHT_TOL, progress)?;
        let t_snap = Snapshot::of(&t_run);
        let disc = error_of(&t_snap)?;
        let h = t_run.report["mesh"]["h"].as_f64().unwrap_or(f64::NAN);
        tight.push((n, disc, h));
        for strategy in &spec.strategies {
            // a direct solve without contact has no tolerance: one run stands for all
            let tols: &[f64] = if !has_contact && strategy != "uzawa-schur-pcg" {
                &spec.tols[..1]
            } else {
                &spec.tols
            };
            for &tol in tols {
                let r = one(n, strategy, tol, progress)?;
                let snap = Snapshot::of(&r);
                let (iterations, iteration_kind) = iterations(&r);
                let dofs = r.report["dofs"]["u"].as_u64().unwrap_or(0) + r.report["dofs"]["phi"].as_u64().unwrap_or(0);
                rows.push(StudyRow {
                    n,
                    h,
                    dofs,
                    strategy: strategy.clone(),
                    tol,
                    iterations,
                    iteration_kind,
                    seconds: r.report["timings_s"]["total"].as_f64().unwrap_or(f64::NAN),
                    error: error_of(&snap)?,
                    discretisation: disc,
                    algebraic: snap.difference(&t_snap)?,
                });
            }
        }
    }
    Ok(Study {
        scene: base.name,
        against,
        rows,
        tight,
    })
}

/// The study as CSV.
pub fn csv(s: &Study) -> String {
    let mut out = String::from(
        "scene,n,h,dofs,strategy,tol,iterations,iteration_kind,seconds,error,discretisation_error,algebraic_error\n",
    );
    for r in &s.rows {
        let _ = writeln!(
            out,
            "{},{},{:.6e},{},{},{:.1e},{},{},{:.6e},{:.6e},{:.6e},{:.6e}",
            s.scene,
            r.n,
            r.h,
            r.dofs,
            r.strategy,
            r.tol,
            r.iterations,
            r.iteration_kind,
            r.seconds,
            r.error,
            r.discretisation,
            r.algebraic
        );
    }
    out
}

/// The study as Markdown: what the errors are against, the observed orders, and the runs.
/// `img` is the path prefix of the pictures from the page (empty: none).
pub fn markdown(s: &Study, img: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "Errors against {}.\n", s.against);
    let _ = writeln!(out, "| n | h | discretisation error | observed order |");
    let _ = writeln!(out, "|---|---|---|---|");
    let rates = s.rates();
    for (i, (n, e, h)) in s.tight.iter().enumerate() {
        let rate = if i == 0 {
            "-".to_string()
        } else {
            format!("{:.2}", rates[i - 1].2)
        };
        let _ = writeln!(out, "| {n} | {h:.4e} | {e:.3e} | {rate} |");
    }
    let _ = writeln!(
        out,
        "\n| n | dofs | strategy | tol | iterations | time (s) | error | discretisation | algebraic |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|");
    for r in &s.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.0e} | {} {} | {:.3} | {:.3e} | {:.3e} | {:.3e} |",
            r.n,
            r.dofs,
            r.strategy,
            r.tol,
            r.iterations,
            r.iteration_kind,
            r.seconds,
            r.error,
            r.discretisation,
            r.algebraic
        );
    }
    if !img.is_empty() {
        let _ = writeln!(
            out,
            "\n![error against time]({img}-error-time.svg) ![error against h]({img}-error-h.svg) ![iterations against h]({img}-iterations-h.svg)"
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_log_ratios() {
        let s = Study {
            scene: "x".into(),
            against: "y".into(),
            rows: vec![],
            tight: vec![(4, 1.0, 0.5), (8, 0.25, 0.25), (16, 0.125, 0.125)],
        };
        let r = s.rates();
        assert!((r[0].2 - 2.0).abs() < 1e-12 && (r[1].2 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_bad_spec_is_refused() {
        let spec = StudySpec {
            sizes: vec![4],
            strategies: vec!["nope".into()],
            tols: vec![1e-6],
            reference_n: None,
        };
        let e = study("paper", &[], &spec, &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("strategy `nope` is unknown"), "{e}");
        let spec = StudySpec {
            strategies: vec!["newton-condensed".into()],
            reference_n: Some(6),
            ..spec
        };
        let e = study("paper", &[], &spec, &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("multiple of the largest size"), "{e}");
    }
}
