//! The verification report (`piezocontact verification`, run by `cargo xtask verify`): a smoke
//! run of every shipped scene, then the convergence study of each analytic instance and of the
//! paper scene, each checked against what it must show, written to `docs/verification.md` with
//! its plots, so the page cannot drift from the code.

use super::convergence::{self, Study, StudySpec};
use crate::DriverError;
use files::output::Outputs;
use files::scene_file;
use problem::Strategy::{self, ApgCondensed, NewtonCondensed, UzawaCondensed, UzawaSchurPcg};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// One study of the report and the check it must pass.
pub struct Entry {
    /// Scene.
    pub scene: &'static str,
    /// Sizes (quick, full).
    pub sizes: (&'static [usize], &'static [usize]),
    /// Reference size for scenes without an exact solution (quick, full).
    pub reference: (Option<usize>, Option<usize>),
    /// Element orders (`mesh.order`), each over every size.
    pub orders: &'static [usize],
    /// Strategies.
    pub strategies: &'static [Strategy],
    /// Tolerances.
    pub tols: &'static [f64],
    /// What must hold, in words (printed on the page).
    pub claim: &'static str,
    /// The check of the claim.
    pub check: fn(&Study) -> Result<(), String>,
}

fn last_rate(s: &Study) -> f64 {
    s.rates().last().map_or(f64::NAN, |r| r.value)
}

/// Whether the observed order on the finest pair of sizes lies in `range`.
fn last_order_within(s: &Study, range: std::ops::Range<f64>) -> Result<(), String> {
    let r = last_rate(s);
    if range.contains(&r) {
        Ok(())
    } else {
        Err(format!("energy order {r:.3}, outside {range:?}"))
    }
}

fn finest(s: &Study) -> f64 {
    s.tight.last().map_or(f64::NAN, |t| t.error)
}

/// Whether the error falls from each size to the next and ends below `bound`.
fn falls_to_below(s: &Study, bound: f64) -> Result<(), String> {
    let falls = s.tight.windows(2).all(|w| w[1].error < w[0].error);
    let e = finest(s);
    if falls && e < bound {
        Ok(())
    } else {
        Err(format!("finest error {e:.3e}, falling with h: {falls}"))
    }
}

/// The studies of the report.
pub const ENTRIES: &[Entry] = &[
    Entry {
        scene: "patch",
        sizes: (&[2, 4, 8], &[2, 4, 8, 16]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, UzawaSchurPcg],
        tols: &[1e-12],
        claim: "an affine (u, φ) is reproduced to round-off: relative energy error below 1e-11 on every mesh and strategy",
        check: |s| match s.rows.iter().find(|r| !(r.error < 1e-11)) {
            Some(r) => Err(format!("n = {}, {}: error {:.3e}", r.n, r.strategy, r.error)),
            None => Ok(()),
        },
    },
    Entry {
        scene: "manufactured",
        sizes: (&[4, 8, 16, 32], &[4, 8, 16, 32, 64, 128]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, UzawaSchurPcg],
        tols: &[1e-6, 1e-10],
        claim: "P1 converges at order 1 in the energy norm (observed order between 0.95 and 1.2 on the finest pair)",
        check: |s| last_order_within(s, 0.95..1.2),
    },
    Entry {
        scene: "manufactured-3d",
        sizes: (&[2, 4, 8], &[2, 4, 8, 16]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, UzawaSchurPcg],
        tols: &[1e-6, 1e-10],
        claim: "order 1 in the energy norm in 3D (between 0.9 and 1.2 on the finest pair)",
        check: |s| last_order_within(s, 0.9..1.2),
    },
    Entry {
        scene: "manufactured",
        sizes: (&[4, 8, 16], &[4, 8, 16, 32, 64]),
        reference: (None, None),
        orders: &[1, 2],
        strategies: &[NewtonCondensed],
        tols: &[1e-10],
        claim: "quadratic elements (mesh.order = 2) converge at order 2 in the energy norm (observed order between 1.85 and 2.3 on the finest pair), and at every size below a fifth of P1's error",
        check: |s| {
            last_order_within(s, 1.85..2.3)?;
            let at = |order: usize, n: usize| s.tight.iter().find(|t| t.order == order && t.n == n).map(|t| t.error);
            match s.tight.iter().filter(|t| t.order == 1).find(|t| at(2, t.n).is_none_or(|e| e >= 0.2 * t.error)) {
                Some(t) => Err(format!("n = {}: P1 {:.3e}, P2 {:?}", t.n, t.error, at(2, t.n))),
                None => Ok(()),
            }
        },
    },
    Entry {
        scene: "manufactured-3d",
        sizes: (&[2, 4], &[2, 4, 8]),
        reference: (None, None),
        orders: &[2],
        strategies: &[NewtonCondensed],
        tols: &[1e-10],
        claim: "quadratic elements in 3D: order 2 in the energy norm (between 1.75 and 2.3 on the finest pair: the coarse pair is pre-asymptotic)",
        check: |s| last_order_within(s, 1.75..2.3),
    },
    Entry {
        scene: "hertz",
        sizes: (&[48, 96, 192], &[48, 96, 192, 384]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, ApgCondensed],
        tols: &[1e-6, 1e-10],
        claim: "the contact pressure approaches Hertz's: profile error below 3 % on the finest mesh and below half the coarsest's (the block's finite size leaves about 1 %)",
        check: |s| {
            let (first, e) = (s.tight.first().map_or(f64::NAN, |t| t.error), finest(s));
            if e < 0.03 && e < 0.5 * first {
                Ok(())
            } else {
                Err(format!("finest error {e:.3e}, coarsest {first:.3e}"))
            }
        },
    },
    Entry {
        scene: "hertz-sphere",
        sizes: (&[96, 128, 160], &[96, 128, 160, 192]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, ApgCondensed],
        tols: &[1e-6, 1e-10],
        claim: "on a body of revolution under a sphere, the contact pressure approaches Hertz's: profile error falling with h, below 1 % on the finest mesh (the body's finite size leaves about 0.4 %)",
        check: |s| falls_to_below(s, 0.01),
    },
    Entry {
        scene: "indent-sphere",
        sizes: (&[96, 128, 160], &[96, 128, 160, 224]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, ApgCondensed],
        tols: &[1e-6, 1e-10],
        claim: "a PZT-4 body of revolution under an insulating sphere carries the half-space's force (problem::halfspace's closed form): error falling with h, below 1 % on the finest mesh (the body's finite size leaves about 0.5 %, halving as the body doubles: docs/theory.md)",
        check: |s| falls_to_below(s, 0.01),
    },
    Entry {
        scene: "indent-cone",
        sizes: (&[96, 128, 160], &[96, 128, 160, 224]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, ApgCondensed],
        tols: &[1e-6, 1e-10],
        claim: "a PZT-4 body of revolution under an insulating 70° cone carries the half-space's force (problem::halfspace, Sneddon's cone through the correspondence principle): error falling with h, below 1 % on the finest mesh (the tip's pressure singular, the body's size effect as the sphere's)",
        check: |s| falls_to_below(s, 0.01),
    },
    Entry {
        scene: "cattaneo-mindlin",
        sizes: (&[48, 96, 192], &[48, 96, 192, 384]),
        reference: (None, None),
        orders: &[1],
        strategies: &[NewtonCondensed, ApgCondensed],
        tols: &[1e-6, 1e-10],
        claim: "the tangential traction approaches Cattaneo-Mindlin's: error falling with h, below 12 % at n = 192 (β = 0.048 and P1 near-incompressibility remain, see the scene)",
        check: |s| {
            let falls = s.tight.windows(2).all(|w| w[1].error < w[0].error);
            let at192 = s.tight.iter().find(|t| t.n == 192).map_or(f64::NAN, |t| t.error);
            if falls && at192 < 0.12 {
                Ok(())
            } else {
                Err(format!("error at n = 192 {at192:.3e}, falling with h: {falls}"))
            }
        },
    },
    Entry {
        scene: "paper",
        sizes: (&[8, 16, 32, 64], &[16, 32, 64, 128]),
        reference: (Some(256), Some(512)),
        orders: &[1],
        strategies: &[NewtonCondensed, ApgCondensed, UzawaCondensed, UzawaSchurPcg],
        tols: &[1e-2, 1e-4, 1e-6, 1e-8],
        claim: "the multipliers converge under refinement (observed order above 0.8 against the finer mesh), and every strategy reaches the tight run's answer as its tolerance falls",
        check: |s| {
            let r = last_rate(s);
            let tightest = s.rows.iter().map(|r| r.tol).fold(f64::INFINITY, f64::min);
            let bad = s.rows.iter().find(|r| r.tol == tightest && !(r.algebraic < 1e-5));
            match (r > 0.8, bad) {
                (true, None) => Ok(()),
                (false, _) => Err(format!("order {r:.3}")),
                (_, Some(b)) => Err(format!("{} at n = {}: algebraic error {:.3e} at tol {:.0e}", b.strategy, b.n, b.algebraic, b.tol)),
            }
        },
    },
];

/// The smoke run of one shipped scene: `(scene, unknowns, iterations, seconds, outcome)`.
pub type SmokeRow = (String, usize, String, f64, Result<String, String>);

/// Runs every shipped scene at its smoke size.
pub fn smoke(progress: &mut dyn FnMut(&str)) -> Vec<SmokeRow> {
    scene_file::SHIPPED
        .iter()
        .map(|(name, _)| {
            let t = Instant::now();
            let result = scene_file::load(name, &[]).and_then(|(sc, _)| super::solve(name, &sc.mesh.smoke()));
            let secs = t.elapsed().as_secs_f64();
            let row = match result {
                Ok(r) => {
                    let (c, it) = (&r.report.contact, &r.report.iterations);
                    let iters = format!("{} Newton, {} Uzawa, {} PCG", it.newton, it.uzawa, it.pcg);
                    let outcome = if c.n_points > 0 {
                        format!(
                            "ran; stick {}, slip {}, separated {}",
                            c.n_stick, c.n_slip, c.n_separated
                        )
                    } else {
                        "ran (no contact)".to_string()
                    };
                    (name.to_string(), r.report.dofs.total(), iters, secs, Ok(outcome))
                }
                Err(e) => (name.to_string(), 0, "-".into(), secs, Err(e.to_string())),
            };
            progress(&format!(
                "smoke {}: {:.2} s, {}",
                row.0,
                row.3,
                row.4.as_ref().map_or_else(|e| format!("FAILED: {e}"), |s| s.clone())
            ));
            row
        })
        .collect()
}

/// One study of the report, done: its section of the page and its summary line.
struct Done {
    /// The scene, with its element orders where they are not P1's alone.
    scene: String,
    rate: f64,
    finest: f64,
    seconds: f64,
    holds: bool,
    section: String,
}

/// Runs the study of `entry` and checks its claim; its pictures go to `pictures`.
fn run_entry(
    entry: &Entry,
    full: bool,
    pictures: &mut Outputs,
    progress: &mut dyn FnMut(&str),
) -> Result<(Done, Option<String>), DriverError> {
    let spec = StudySpec {
        sizes: if full { entry.sizes.1 } else { entry.sizes.0 }.to_vec(),
        strategies: entry.strategies.to_vec(),
        tols: entry.tols.to_vec(),
        reference_n: if full { entry.reference.1 } else { entry.reference.0 },
        orders: entry.orders.to_vec(),
    };
    let t = Instant::now();
    let study = convergence::study(entry.scene, &[], &spec, progress)?;
    let seconds = t.elapsed().as_secs_f64();
    let verdict = (entry.check)(&study);
    // a scene studied at other orders than P1's alone is named with them (one file each)
    let (named, suffix) = match entry.orders {
        [1] => (format!("`{}`", entry.scene), String::new()),
        orders => {
            let list: Vec<String> = orders.iter().map(|o| format!("P{o}")).collect();
            (
                format!("`{}` ({})", entry.scene, list.join(", ")),
                format!("-{}", list.join("-").to_lowercase()),
            )
        }
    };
    let prefix = format!("verification-{}{suffix}", entry.scene);
    pictures.extend(convergence::pictures(&prefix, &study)?);
    let mut section = format!("## {named}\n\n");
    let _ = writeln!(
        section,
        "Claim: {}. **{}**{}.\n",
        entry.claim,
        if verdict.is_ok() { "Holds" } else { "FAILS" },
        verdict.as_ref().err().map_or(String::new(), |e| format!(" ({e})"))
    );
    section.push_str(&convergence::markdown(&study, &format!("img/{prefix}")));
    section.push('\n');
    let done = Done {
        scene: named,
        rate: last_rate(&study),
        finest: finest(&study),
        seconds,
        holds: verdict.is_ok(),
        section,
    };
    Ok((done, verdict.err().map(|e| format!("{}: {e}", entry.scene))))
}

/// The page: how it was written, the summary, the smoke runs, then each study's section.
fn page(full: bool, seconds: f64, studies: &[Done], smoke_rows: &[SmokeRow]) -> String {
    let flag = if full { " --full" } else { "" };
    let mut md = String::new();
    let _ = writeln!(md, "# Verification\n");
    let _ = writeln!(
        md,
        "Written by `piezocontact verification{flag}` (run by `cargo xtask verify{flag}`) in {seconds:.0} s; do not edit by hand. \
         Times are wall times of whole runs on the machine that wrote the page (2 cores, shared).\n"
    );
    let _ = writeln!(
        md,
        "Every error says what it is measured against. The discretisation error of a size is that of a tight run \
         (newton-condensed to {:e}); the algebraic error of a run is its difference from that tight run; the error \
         of a run is its own error against the exact solution or the finer mesh, both parts together.\n",
        convergence::TIGHT_TOL
    );
    let _ = writeln!(md, "## Summary\n\n| scene | finest discretisation error | last observed order | study time (s) | claim |\n|---|---|---|---|---|");
    for d in studies {
        let verdict = if d.holds { "holds" } else { "FAILS" };
        let _ = writeln!(
            md,
            "| {} | {:.3e} | {:.2} | {:.1} | {verdict} |",
            d.scene, d.finest, d.rate, d.seconds
        );
    }
    let _ = writeln!(
        md,
        "\n## Smoke runs of the shipped scenes (each at its `mesh.smoke_n`)\n"
    );
    let _ = writeln!(
        md,
        "| scene | unknowns | iterations | time (s) | outcome |\n|---|---|---|---|---|"
    );
    for (name, dofs, iters, secs, r) in smoke_rows {
        let outcome = r.as_ref().map_or_else(|e| format!("FAILED: {e}"), |s| s.clone());
        let _ = writeln!(md, "| {name} | {dofs} | {iters} | {secs:.3} | {outcome} |");
    }
    md.push('\n');
    for d in studies {
        md.push_str(&d.section);
    }
    md
}

/// Runs the report (`full`: to the finest meshes), writes `verification.md` into `docs` and
/// its plots into `docs/img`; returns the failed checks (empty: all hold).
///
/// # Errors
/// A study's error, or the files'.
pub fn report(full: bool, docs: &Path, progress: &mut dyn FnMut(&str)) -> Result<Vec<String>, DriverError> {
    let t0 = Instant::now();
    let smoke_rows = smoke(progress);
    let mut failures: Vec<String> = smoke_rows
        .iter()
        .filter_map(|(name, _, _, _, r)| r.as_ref().err().map(|e| format!("smoke run of `{name}`: {e}")))
        .collect();
    let mut pictures = Outputs::documents(&docs.join("img"));
    let mut studies = vec![];
    for entry in ENTRIES {
        let (done, failure) = run_entry(entry, full, &mut pictures, progress)?;
        failures.extend(failure);
        studies.push(done);
    }
    let md = page(full, t0.elapsed().as_secs_f64(), &studies, &smoke_rows);
    pictures.commit()?;
    let mut page = Outputs::documents(docs);
    page.add("verification.md", md.into_bytes());
    page.commit()?;
    Ok(failures)
}
