//! The convergence study (`piezocontact study`): one scene over element orders, mesh sizes,
//! strategies and tolerances, and for every run its error and its wall time.
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

use super::solve;
use crate::DriverError;
use files::plots::{self, Series};
use problem::{ContactLaw, Solution, Strategy};
use std::collections::HashMap;
use std::fmt::Write as _;

/// The tolerance of the tight runs that give the discretisation error.
pub const TIGHT_TOL: f64 = 1e-12;

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct StudySpec {
    /// Mesh sizes (`mesh.n`), coarse to fine.
    pub sizes: Vec<usize>,
    /// Strategies.
    pub strategies: Vec<Strategy>,
    /// Tolerances (`solver.tol`; for a scene without contact, the Schur PCG's tolerance).
    pub tols: Vec<f64>,
    /// The size of the reference run, for a scene without an exact solution (default: four
    /// times the largest size).
    pub reference_n: Option<usize>,
    /// Element orders (`mesh.order`: 1, 2), each over every size (empty: the scene's own).
    pub orders: Vec<usize>,
}

/// One run of the study.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyRow {
    /// The elements' order (`mesh.order`).
    pub order: usize,
    /// `mesh.n`.
    pub n: usize,
    /// Largest cell diameter.
    pub h: f64,
    /// Free unknowns, u + φ.
    pub dofs: usize,
    /// Strategy.
    pub strategy: Strategy,
    /// Tolerance.
    pub tol: f64,
    /// Outer iterations (Newton steps, else Uzawa steps, else PCG iterations).
    pub iterations: usize,
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
    /// The tight runs, per element order coarse to fine.
    pub tight: Vec<Tight>,
    /// The units of the runs' numbers (study.csv's `h` is a length).
    pub units: problem::Units,
}

/// A tight run of the study: the discretisation error of its order and size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tight {
    /// The elements' order.
    pub order: usize,
    /// `mesh.n`.
    pub n: usize,
    /// The discretisation error.
    pub error: f64,
    /// Largest cell diameter.
    pub h: f64,
    /// Wall time of the run, s.
    pub seconds: f64,
    /// Free unknowns, u + φ.
    pub dofs: usize,
}

/// The convergence rate observed between two sizes of one element order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rate {
    /// The elements' order.
    pub order: usize,
    /// The coarser size.
    pub from: usize,
    /// The finer size.
    pub to: usize,
    /// `log(e0/e1) / log(h0/h1)`.
    pub value: f64,
}

impl Study {
    /// Observed orders `log(e0/e1) / log(h0/h1)` between successive sizes of the tight runs
    /// of each element order (the orders in their study's order).
    pub fn rates(&self) -> Vec<Rate> {
        self.tight
            .windows(2)
            .filter(|w| w[0].order == w[1].order)
            .map(|w| Rate {
                order: w[0].order,
                from: w[0].n,
                to: w[1].n,
                value: (w[0].error / w[1].error).ln() / (w[0].h / w[1].h).ln(),
            })
            .collect()
    }

    /// The element orders of the study, in their order.
    pub fn orders(&self) -> Vec<usize> {
        let mut out: Vec<usize> = vec![];
        for t in &self.tight {
            if !out.contains(&t.order) {
                out.push(t.order);
            }
        }
        out
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
    fn of(r: &Solution) -> Self {
        let contact = r.contact.as_ref().map(|c| {
            let (p, lambda) = (&c.points, &c.solution.lambda);
            let mut v = Vec::with_capacity(p.len() * (1 + lambda.n_tangential()));
            for i in 0..p.len() {
                v.push(lambda.normal[i]);
                v.extend_from_slice(lambda.tangential_of(i));
            }
            (p.position.clone(), v)
        });
        Snapshot {
            nodes: r.mesh.points.clone(),
            u: r.u.clone(),
            contact,
            exact: r.report.exact.as_ref().map(|e| e.error()),
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
            return Err(DriverError::Usage(
                "the reference run has another number of multipliers per point".into(),
            ));
        }
        let index: HashMap<[i64; 3], usize> = rpts.iter().enumerate().map(|(i, x)| (key(x), i)).collect();
        let (mut num, mut den) = (0.0, 0.0);
        for (i, x) in pts.iter().enumerate() {
            let j = *index.get(&key(x)).ok_or_else(|| {
                DriverError::Usage(format!(
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

fn settings(
    sets: &[String],
    (order, n): (usize, usize),
    strategy: Strategy,
    tol: f64,
    has_contact: bool,
) -> Vec<String> {
    let mut s = sets.to_vec();
    s.push(format!("mesh.order={order}"));
    s.push(format!("mesh.n={n}"));
    s.push(format!("solver.strategy=\"{strategy}\""));
    s.push("solver.rule=\"tight\"".into());
    s.push(format!("solver.tol={tol:e}"));
    if strategy.runs_pcg() {
        // the PCG's own tolerance: the whole algebraic error without contact
        s.push(format!(
            "solver.pcg_tol={:e}",
            if has_contact { tol.min(1e-10) } else { tol }
        ));
    }
    s
}

/// The reference of a study's errors: the exact solution, or a tight run on a finer mesh.
enum Reference {
    /// The scene's exact solution (each run reports its error).
    Exact,
    /// A tight run on the finer, nested mesh `n`.
    Finer(usize, Snapshot),
}

impl Reference {
    fn error_of(&self, snap: &Snapshot) -> Result<f64, DriverError> {
        match self {
            Reference::Finer(_, r) => snap.difference(r),
            Reference::Exact => snap
                .exact
                .ok_or_else(|| DriverError::Usage("the run reported no exact error".into())),
        }
    }
}

/// Checks a study's specification.
fn check(spec: &StudySpec) -> Result<(), DriverError> {
    if spec.sizes.is_empty() || spec.strategies.is_empty() || spec.tols.is_empty() {
        return Err(DriverError::Usage(
            "a study needs at least one size, strategy and tolerance".into(),
        ));
    }
    if let Some(t) = spec.tols.iter().find(|t| !(**t > 0.0 && t.is_finite())) {
        return Err(DriverError::Usage(format!("tolerance {t} must be positive")));
    }
    // the runs' solver.tol: refused here, before any run, rather than after the first ones
    let (lo, hi) = problem::TOL_RANGE;
    if let Some(t) = spec.tols.iter().find(|t| !(lo..=hi).contains(*t)) {
        return Err(DriverError::Usage(format!(
            "tolerance {t:e} is outside [{lo:e}, {hi:e}], the range of solver.tol"
        )));
    }
    if spec.sizes.contains(&0) {
        return Err(DriverError::Usage(
            "mesh size 0: the sizes are values of mesh.n, at least 1".into(),
        ));
    }
    Ok(())
}

/// Refuses the overrides of what a study's runs set themselves (its `settings`): the rule and
/// the tolerances always, the mesh's size always (the study sizes by `mesh.n`, and `mesh.h`
/// would be replaced by it), and the strategy or the order where the study's lists are given
/// (`strategies`, `orders`, `sizes` as asked, before the scene's defaults fill them).
///
/// # Errors
/// A usage error naming the key and the option that decides it.
pub fn refuse_overrides(sets: &[String], given: &StudySpec) -> Result<(), DriverError> {
    let mut decided = vec![
        ("solver.rule", "solver.rule = \"tight\": every point to its tolerance"),
        ("solver.tol", "--tols"),
        ("solver.pcg_tol", "from --tols"),
    ];
    // mesh.h alone: an override of mesh.n is where the default sizes come from, and the two
    // keys overlap as two ways to give one size
    if let Some(set) = sets
        .iter()
        .find(|s| files::scene_file::override_key(s).trim() == "mesh.h")
    {
        return Err(DriverError::Usage(format!(
            "--set {set}: the study sizes its meshes by mesh.n (--sizes, or the scene's n/4, n/2, n), which replaces mesh.h on each of its runs; drop the --set"
        )));
    }
    if !given.sizes.is_empty() {
        decided.push(("mesh.n", "--sizes"));
    }
    if !given.strategies.is_empty() {
        decided.push(("solver.strategy", "--strategies"));
    }
    if !given.orders.is_empty() {
        decided.push(("mesh.order", "--orders"));
    }
    super::refuse_decided("the study", sets, &decided)
}

/// The size of every run of a study, in the order it runs them: the finer reference (without
/// an exact solution), then per order and size its tight run and its strategies' runs at each
/// tolerance.
fn planned_sizes(spec: &StudySpec, sizes: &[usize], orders: usize, has_contact: bool, exact: bool) -> Vec<usize> {
    let mut out = vec![];
    if !exact {
        let largest = *sizes.last().unwrap_or(&1);
        out.push(spec.reference_n.unwrap_or(4 * largest));
    }
    for &n in sizes.iter().cycle().take(sizes.len() * orders) {
        out.push(n);
        for strategy in &spec.strategies {
            let tols = if !has_contact && !strategy.runs_pcg() {
                1
            } else {
                spec.tols.len()
            };
            out.extend(std::iter::repeat_n(n, tols));
        }
    }
    out
}

/// Runs the study of `scene_name` (with the overrides `sets`); `progress` gets a line per run.
///
/// # Errors
/// [`DriverError::Usage`] for a specification that does not fit (no size, a tolerance that is
/// not positive, a reference size that does not nest); a run's error.
pub fn study(
    scene_name: &str,
    sets: &[String],
    spec: &StudySpec,
    progress: &mut dyn FnMut(&str),
) -> Result<Study, DriverError> {
    check(spec)?;
    let mut sizes = spec.sizes.clone();
    sizes.sort_unstable();
    sizes.dedup();
    let (base, _) = files::scene_file::load(scene_name, sets)?;
    let mut orders = match spec.orders.is_empty() {
        true => vec![base.mesh.order.unwrap_or(1)],
        false => spec.orders.clone(),
    };
    // each order once, as each size (`--orders 1,1` would run every point twice)
    orders.sort_unstable();
    orders.dedup();
    if let Some(o) = orders.iter().find(|o| !(1..=2).contains(*o)) {
        return Err(DriverError::Usage(format!("element order {o}: the orders are 1 and 2")));
    }
    let has_contact = base.contact_law() != ContactLaw::None;
    // the runs' sizes in the order they run, for the estimate of the time left
    let mut pending = planned_sizes(spec, &sizes, orders.len(), has_contact, base.exact.is_some());
    pending.reverse();
    let mut eta = super::Eta::default();
    let mut units = None;
    let mut one = |(order, n): (usize, usize), strategy: Strategy, tol: f64| -> Result<Solution, DriverError> {
        let t = std::time::Instant::now();
        let r = solve(scene_name, &settings(sets, (order, n), strategy, tol, has_contact))?;
        units.get_or_insert_with(|| r.report.units.clone());
        eta.record(n, t.elapsed().as_secs_f64());
        pending.pop();
        progress(&format!(
            "study {}: order {order}, n = {n}, {strategy}, tol {tol:.0e}: {:.3} s; {} run{} to go, {}",
            base.name,
            r.report.timings_s.total,
            pending.len(),
            if pending.len() == 1 { "" } else { "s" },
            eta.words(&pending)
        ));
        Ok(r)
    };
    let highest = orders.iter().copied().max().unwrap_or(1);
    let reference = match &base.exact {
        Some(_) => Reference::Exact,
        None => {
            let largest = *sizes.last().unwrap_or(&1);
            let n_ref = spec.reference_n.unwrap_or(4 * largest);
            if n_ref <= largest || !n_ref.is_multiple_of(largest) {
                return Err(DriverError::Usage(format!(
                    "the reference size {n_ref} must be a multiple of the largest size {largest}, and larger"
                )));
            }
            let run = one((highest, n_ref), Strategy::NewtonCondensed, TIGHT_TOL)?;
            Reference::Finer(n_ref, Snapshot::of(&run))
        }
    };
    let against = match (&reference, &base.exact) {
        (Reference::Finer(n_ref, _), _) => format!(
            "a tight run on the finer mesh n = {n_ref} (order {highest}): relative l2 difference of the {} ",
            if has_contact {
                "contact multipliers at the coarse contact nodes"
            } else {
                "displacements at the coarse nodes"
            }
        ),
        (Reference::Exact, Some(x)) => format!("the exact solution ({}): {}", x.kind, x.kind.measures()),
        (Reference::Exact, None) => String::new(),
    };
    let (mut rows, mut tight) = (vec![], vec![]);
    for &order in &orders {
        for &n in &sizes {
            let (t, mut runs) = one_size((order, n), spec, has_contact, &reference, &mut one)?;
            tight.push(t);
            rows.append(&mut runs);
        }
    }
    Ok(Study {
        scene: base.name,
        against,
        rows,
        tight,
        units: units.unwrap_or_default(),
    })
}

/// The runs of one element order and size: its tight run, then each strategy at each
/// tolerance (one for all where a direct solve without contact has no tolerance), measured
/// against `reference` and the tight run.
fn one_size(
    (order, n): (usize, usize),
    spec: &StudySpec,
    has_contact: bool,
    reference: &Reference,
    one: &mut dyn FnMut((usize, usize), Strategy, f64) -> Result<Solution, DriverError>,
) -> Result<(Tight, Vec<StudyRow>), DriverError> {
    let t_run = one((order, n), Strategy::NewtonCondensed, TIGHT_TOL)?;
    let t_snap = Snapshot::of(&t_run);
    let disc = reference.error_of(&t_snap)?;
    let h = t_run.report.mesh.h;
    let tight = Tight {
        order,
        n,
        error: disc,
        h,
        seconds: t_run.report.timings_s.total,
        dofs: t_run.report.dofs.total(),
    };
    let mut rows = vec![];
    for &strategy in &spec.strategies {
        let tols = if !has_contact && !strategy.runs_pcg() {
            &spec.tols[..1]
        } else {
            &spec.tols[..]
        };
        for &tol in tols {
            let r = one((order, n), strategy, tol)?;
            let snap = Snapshot::of(&r);
            let (iterations, iteration_kind) = r.report.iterations.outer(strategy);
            rows.push(StudyRow {
                order,
                n,
                h,
                dofs: r.report.dofs.total(),
                strategy,
                tol,
                iterations,
                iteration_kind,
                seconds: r.report.timings_s.total,
                error: reference.error_of(&snap)?,
                discretisation: disc,
                algebraic: snap.difference(&t_snap)?,
            });
        }
    }
    Ok((tight, rows))
}

/// The study as CSV.
pub fn csv(s: &Study) -> String {
    // each column's unit in brackets where it has one (the errors are relative)
    let mut out = format!(
        "scene,order,n,{},dofs,strategy,tol,iterations,iteration_kind,seconds [s],error,discretisation_error,algebraic_error\n",
        files::output::header_cell("h", s.units.of_quantity("length"))
    );
    for r in &s.rows {
        let _ = writeln!(
            out,
            "{},{},{},{:.6e},{},{},{:.1e},{},{},{:.6e},{:.6e},{:.6e},{:.6e}",
            s.scene,
            r.order,
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
    let _ = writeln!(
        out,
        "| order | n | h | unknowns | time (s) | discretisation error | observed order |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|");
    let rates = s.rates();
    for t in &s.tight {
        let rate = rates
            .iter()
            .find(|r| r.order == t.order && r.to == t.n)
            .map_or("-".to_string(), |r| format!("{:.2}", r.value));
        let _ = writeln!(
            out,
            "| {} | {} | {:.4e} | {} | {:.3} | {:.3e} | {rate} |",
            t.order, t.n, t.h, t.dofs, t.seconds, t.error
        );
    }
    let _ = writeln!(
        out,
        "\n| order | n | dofs | strategy | tol | iterations | time (s) | error | discretisation | algebraic |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|");
    for r in &s.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.0e} | {} {} | {:.3} | {:.3e} | {:.3e} | {:.3e} |",
            r.order,
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

/// The three pictures of a study: error against time (one colour per strategy and element
/// order, a line per size through its tolerances; with several orders each order's front of
/// tight runs too), discretisation error against h (a line per order), iterations against h (a
/// line per strategy and order, at its tightest tolerance). Names start with `prefix`.
///
/// # Errors
/// [`files::Error::Picture`] where plotters cannot draw.
pub fn pictures(prefix: &str, s: &Study) -> Result<plots::Files, DriverError> {
    let orders = s.orders();
    let several = orders.len() > 1;
    let named = |what: &str, order: usize| match several {
        true => format!("{what}, P{order}"),
        false => what.to_string(),
    };
    let mut kinds: Vec<(Strategy, usize)> = vec![];
    for r in &s.rows {
        if !kinds.contains(&(r.strategy, r.order)) {
            kinds.push((r.strategy, r.order));
        }
    }
    let (mut time, mut iters) = (vec![], vec![]);
    if several {
        for &order in &orders {
            let front = s
                .tight
                .iter()
                .filter(|t| t.order == order)
                .map(|t| (t.seconds, t.error))
                .collect();
            time.push(Series::line(&format!("P{order}: tight runs"), front));
        }
    }
    for &(st, order) in &kinds {
        let rows: Vec<&StudyRow> = s.rows.iter().filter(|r| r.strategy == st && r.order == order).collect();
        let mut sizes: Vec<usize> = rows.iter().map(|r| r.n).collect();
        sizes.dedup();
        for (i, n) in sizes.iter().enumerate() {
            let mut p: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.n == *n)
                .map(|r| (r.seconds, r.error))
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            // one colour per strategy and order; a line per size joins its tolerances
            let label = if i == 0 { named(st.name(), order) } else { String::new() };
            time.push(Series::line(&label, p));
        }
        let tightest = rows.iter().map(|r| r.tol).fold(f64::INFINITY, f64::min);
        let at_tightest = rows.iter().filter(|r| r.tol == tightest);
        iters.push(Series::line(
            &named(st.name(), order),
            at_tightest.map(|r| (r.h, r.iterations.max(1) as f64)).collect(),
        ));
    }
    let rates = s.rates();
    let err_h: Vec<Series> = orders
        .iter()
        .map(|&order| {
            let label = match rates.iter().rev().find(|r| r.order == order) {
                Some(r) => format!("tight runs (last order {:.2})", r.value),
                None => "tight runs".to_string(),
            };
            let points = s.tight.iter().filter(|t| t.order == order).map(|t| (t.h, t.error));
            Series::line(&named(&label, order), points.collect())
        })
        .collect();
    let mut out = plots::loglog(
        &format!("{prefix}-error-time"),
        &format!("{}: error against run time", s.scene),
        ("wall time of the run (s)", "error"),
        &time,
    )?;
    out.extend(plots::loglog(
        &format!("{prefix}-error-h"),
        &format!("{}: discretisation error against h", s.scene),
        ("h", "error"),
        &err_h,
    )?);
    out.extend(plots::loglog(
        &format!("{prefix}-iterations-h"),
        &format!("{}: iterations against h (tightest tolerance)", s.scene),
        ("h", "iterations"),
        &iters,
    )?);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_log_ratios() {
        let s = Study {
            scene: "x".into(),
            against: "y".into(),
            units: problem::Units::default(),
            rows: vec![],
            tight: [
                (1, 4, 1.0, 0.5),
                (1, 8, 0.25, 0.25),
                (1, 16, 0.125, 0.125),
                (2, 4, 0.1, 0.5),
                (2, 8, 0.0125, 0.25),
            ]
            .map(|(order, n, error, h)| Tight {
                order,
                n,
                error,
                h,
                seconds: 1.0,
                dofs: 1,
            })
            .to_vec(),
        };
        let r = s.rates();
        assert_eq!(r.len(), 3, "no rate across two orders");
        assert!((r[0].value - 2.0).abs() < 1e-12 && (r[1].value - 1.0).abs() < 1e-12);
        assert!((r[2].value - 3.0).abs() < 1e-12 && r[2].order == 2);
    }

    #[test]
    fn a_bad_spec_is_refused() {
        let spec = StudySpec {
            sizes: vec![4],
            strategies: vec![Strategy::NewtonCondensed],
            tols: vec![-1e-6],
            reference_n: None,
            orders: vec![],
        };
        let e = study("paper", &[], &spec, &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("tolerance -0.000001 must be positive"), "{e}");
        let spec = StudySpec {
            tols: vec![1e-6],
            reference_n: Some(6),
            ..spec
        };
        let e = study("paper", &[], &spec, &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("multiple of the largest size"), "{e}");
        // refused before any run: a tolerance solver.tol would refuse, a size of no cells
        let mut runs = 0;
        for (bad, says) in [
            (
                StudySpec {
                    tols: vec![1e-6, 1e-30],
                    reference_n: None,
                    ..spec.clone()
                },
                "tolerance 1e-30 is outside [1e-15, 1e-1]",
            ),
            (
                StudySpec {
                    sizes: vec![0, 4],
                    reference_n: None,
                    ..spec.clone()
                },
                "mesh size 0",
            ),
        ] {
            let e = study("paper", &[], &bad, &mut |_| runs += 1).unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
        assert_eq!(runs, 0);
    }

    /// What every run of a study sets itself is refused as an override (it was replaced
    /// silently: `--set solver.rule="loose"` ran tight), and what the study's lists decide
    /// only where they are given; an override the defaults are drawn from passes.
    #[test]
    fn an_override_of_what_the_study_sets_is_refused() {
        let asked = StudySpec {
            sizes: vec![],
            strategies: vec![],
            tols: vec![1e-6],
            reference_n: None,
            orders: vec![],
        };
        let listed = StudySpec {
            sizes: vec![8],
            strategies: vec![Strategy::NewtonCondensed],
            orders: vec![1],
            ..asked.clone()
        };
        for (set, spec) in [
            ("solver.rule=\"loose\"", &asked),
            ("solver.tol=1e-6", &asked),
            ("~solver.pcg_tol", &asked),
            ("mesh.h=0.1", &asked),
            ("mesh.n=8", &listed),
            ("solver={strategy=\"uzawa-condensed\"}", &listed),
            ("mesh.order=2", &listed),
        ] {
            let e = refuse_overrides(&[set.into()], spec).unwrap_err().to_string();
            assert!(e.contains("the study s") && e.contains(set), "{set}: {e}");
        }
        for set in [
            "mesh.n=8",
            "solver.strategy=\"uzawa-condensed\"",
            "mesh.order=2",
            "load.p=-1.0",
        ] {
            refuse_overrides(&[set.into()], &asked).unwrap_or_else(|e| panic!("{set}: {e}"));
        }
    }
}
