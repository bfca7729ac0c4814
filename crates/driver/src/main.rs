//! `piezocontact`: the command line. See `piezocontact --help`.

use clap::{Args, Parser, Subcommand};
use driver::studies::{convergence, stability, sweep, table1, verification};
use driver::{fclib, DriverError};
use files::{output, scene_file};
use problem::{BackendChoice, Event, Strategy};
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "piezocontact",
    version,
    about = "Frictional contact of piezoelectric bodies (semismooth Newton, Uzawa, Schur PCG, fixed point)"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene (a shipped scene's name or a TOML file; default: paper).
    Run {
        /// Scene name or file.
        scene: Option<String>,
        /// Override a scene key, e.g. --set mesh.n=128 (repeatable, applied in order: a key set twice keeps the last; `--set ~KEY` removes a key).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Remove a scene key, e.g. --unset contact.friction (repeatable).
        #[arg(long = "unset", value_name = "KEY")]
        unset: Vec<String>,
        /// Output directory (default: out/SCENE/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Options for PETSc's database, as on PETSc's command line, e.g. --petsc "-ksp_monitor
        /// -fieldsplit_u_pc_type hypre" (with solver.backend=petsc; added to the scene's
        /// solver.petsc_options).
        #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
        petsc: Option<String>,
    },
    /// List the shipped scenes.
    Scenes,
    /// The capacitance matrix between a scene's terminals (its electrode and the groups at a
    /// prescribed potential; the displacements it prescribes held at 0, no load, the contact
    /// face free); prints it and writes capacitance.csv and capacitance.json.
    Capacitance {
        /// Scene name or file (default: actuator).
        scene: Option<String>,
        /// Override a scene key (repeatable; `--set ~KEY` removes a key).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Output directory (default: out/SCENE-capacitance/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run a scene along one parameter; writes sweep.csv and sweep.svg/png.
    Sweep {
        /// Scene name or file.
        scene: String,
        /// The key to vary, e.g. electrode.v.
        #[arg(long)]
        param: String,
        /// First value.
        #[arg(long, allow_hyphen_values = true)]
        from: f64,
        /// Last value.
        #[arg(long, allow_hyphen_values = true)]
        to: f64,
        /// Number of values (at least 2).
        #[arg(long, default_value_t = 11)]
        steps: usize,
        /// Other overrides.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Output directory (default: out/SCENE-sweep/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Reproduce the paper's Table 1 (Uzawa + Schur PCG + fixed point on `paper`).
    Table1 {
        /// Sizes n (h = 1/n) under the paper's loose rule.
        #[arg(long, value_delimiter = ',', default_values_t = [32, 64, 128, 256])]
        loose: Vec<usize>,
        /// Sizes under the tight rule (complementarity 1e-10). The default is the quick table
        /// (under a minute on 2 cores); the paper's h = 1/128 under the tight rule takes about
        /// 37 minutes more (`--tight 32,64,128`; docs/table1.md).
        #[arg(long, value_delimiter = ',', default_values_t = [32, 64])]
        tight: Vec<usize>,
        /// Output directory for table1.md (default: out/table1/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// List the solver strategies.
    Strategies,
    /// The verification report: a smoke run of every shipped scene and the convergence study
    /// of each analytic instance and of `paper`, each checked; writes docs/verification.md.
    Verification {
        /// Run the studies to their finest meshes.
        #[arg(long)]
        full: bool,
        /// Directory for verification.md (plots go to its img/).
        #[arg(long, default_value = "docs")]
        out: PathBuf,
    },
    /// Error against h and against run time: a scene over element orders, mesh sizes,
    /// strategies and tolerances; writes study.md, study.csv and log-log plots (SVG, PNG).
    Study(StudyArgs),
    /// Solve third-party frictional contact problems (Siconos' text format, e.g. FCLib's test
    /// problems) with the contact crate alone; prints one line per file.
    Fclib {
        /// The problem files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The solver.
        #[arg(long, value_enum, default_value_t = fclib::Solver::Newton)]
        solver: fclib::Solver,
        /// The tolerance.
        #[arg(long, default_value_t = 1e-8)]
        tol: f64,
        /// The residual the solver iterates on (a file is solved where both meet the
        /// tolerance).
        #[arg(long, value_enum, default_value_t = fclib::Criterion::Both)]
        criterion: fclib::Criterion,
        /// Seconds allowed per file (`inf`: no limit).
        #[arg(long, default_value_t = 60.0)]
        time_limit: f64,
        /// Print the solver's progress (one line per Newton or proximal step).
        #[arg(long, short)]
        verbose: bool,
        /// Directory for summary.json and one CSV of (r, u) per solved file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the stiff and extreme cases (docs/scenes.md section 5), each in its own process, and
    /// write their table to docs/stability.md.
    Stability {
        /// Leave out the fine cases (2D n = 512 and 1024, 3D n = 32).
        #[arg(long)]
        quick: bool,
        /// Directory for stability.md.
        #[arg(long, default_value = "docs")]
        out: PathBuf,
        /// Time limit per run of the paper's strategy, in seconds (the default strategy gets
        /// 1800 s at least).
        #[arg(long, default_value_t = 600)]
        limit: u64,
        /// Run every case on the PETSc backend under `mpirun -np RANKS` (a build with the
        /// feature `petsc`), into stability-petsc.md.
        #[arg(long)]
        ranks: Option<usize>,
    },
}

/// The arguments of `piezocontact study`.
#[derive(Args)]
struct StudyArgs {
    /// Scene name or file (default: paper).
    scene: Option<String>,
    /// Mesh sizes mesh.n (default: the scene's n/4, n/2, n).
    #[arg(long, value_delimiter = ',')]
    sizes: Vec<usize>,
    /// Strategies (default: the scene's).
    #[arg(long, value_delimiter = ',')]
    strategies: Vec<Strategy>,
    /// Tolerances (default: 1e-4, 1e-6, 1e-8).
    #[arg(long, value_delimiter = ',', default_values_t = [1e-4, 1e-6, 1e-8])]
    tols: Vec<f64>,
    /// Size of the reference run for a scene without an exact solution (default: 4 x the
    /// largest size).
    #[arg(long)]
    reference: Option<usize>,
    /// Element orders (mesh.order), each over every size: `--orders 1,2` draws both
    /// fronts of error against run time (default: the scene's).
    #[arg(long, value_delimiter = ',')]
    orders: Vec<usize>,
    /// Other overrides.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Output directory (default: out/SCENE-study/).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Lines to stderr, and a progress bar for the contact solve when stderr is a terminal; along
/// a load path, one line per step and a bar over the steps (the steps' own contact lines left
/// out).
struct Terminal {
    bar: Option<indicatif::ProgressBar>,
    first_residual: Option<f64>,
    path: Option<indicatif::ProgressBar>,
    factoring: Option<FactorBar>,
}

impl Terminal {
    fn new() -> Self {
        Terminal {
            bar: None,
            first_residual: None,
            path: None,
            factoring: None,
        }
    }

    /// Along a path: the bar over its steps; `true` where the event's own line is left out.
    fn path_event(&mut self, event: &Event<'_>) -> bool {
        match event {
            Event::PathStep { step, of, t } => {
                let bar = self.path.get_or_insert_with(|| path_bar(*of as u64 + 1));
                bar.set_position(*step as u64);
                bar.set_message(format!("t = {}", problem::instant(*t)));
                true
            }
            Event::PathStepDone { row, of, .. } => {
                if let Some(bar) = &self.path {
                    bar.set_position(row.step as u64 + 1);
                    if row.step == *of {
                        bar.finish_and_clear();
                    }
                }
                false
            }
            Event::Contact { .. } => self.path.is_some(),
            _ => false,
        }
    }
}

/// The progress bar over a load path's steps.
fn path_bar(steps: u64) -> indicatif::ProgressBar {
    bar(steps, "path [{bar:40}] {pos}/{len} steps, {msg}, {elapsed}")
}

/// A bar of `len` positions on stderr (hidden where it is not a terminal), drawn by `template`.
fn bar(len: u64, template: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::with_draw_target(Some(len), indicatif::ProgressDrawTarget::stderr());
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// The bar of a factorisation that takes more than a second: the share of its work done
/// (its supernodes' operations) and the time left at that rate, redrawn by a thread of its own
/// while the factorisation runs on the caller's; gone when it ends (or is dropped).
struct FactorBar {
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl FactorBar {
    /// Shown after this long only: most factorisations end before.
    const DELAY: std::time::Duration = std::time::Duration::from_secs(1);

    fn start(watch: problem::FactorWatch) -> Self {
        use std::sync::atomic::Ordering;
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let stopped = stop.clone();
        let thread = std::thread::spawn(move || {
            let tick = std::time::Duration::from_millis(100);
            let started = std::time::Instant::now();
            let mut bar: Option<indicatif::ProgressBar> = None;
            while !stopped.load(Ordering::Relaxed) {
                std::thread::park_timeout(tick);
                let Some(fraction) = watch.0.fraction() else { continue };
                if started.elapsed() < Self::DELAY {
                    continue;
                }
                let bar = bar.get_or_insert_with(|| factor_bar().with_elapsed(started.elapsed()));
                bar.set_position((fraction * 1000.0) as u64);
            }
            if let Some(bar) = bar {
                bar.finish_and_clear();
            }
        });
        FactorBar {
            stop,
            thread: Some(thread),
        }
    }
}

impl Drop for FactorBar {
    fn drop(&mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            thread.thread().unpark();
            let _ = thread.join();
        }
    }
}

/// The progress bar of a factorisation: its work done, and the time left at its rate so far.
fn factor_bar() -> indicatif::ProgressBar {
    bar(
        1000,
        "factorisation [{bar:40}] {percent:>3}% of its work, {elapsed}, about {eta} left",
    )
}

impl problem::Reporter for Terminal {
    fn event(&mut self, event: &Event<'_>) {
        // a factorisation's bar lasts until the next event (its end, or the run's error)
        self.factoring = match event {
            Event::Factoring { watch } => Some(FactorBar::start(watch.clone())),
            _ => None,
        };
        if self.path_event(event) {
            return;
        }
        if let Some(line) = event.line() {
            match self.path.as_ref().or(self.bar.as_ref()) {
                Some(bar) if !bar.is_hidden() => bar.println(line),
                _ => eprintln!("{line}"),
            }
        }
        if let Event::Contact { progress, .. } = event {
            let first = *self.first_residual.get_or_insert(progress.residual);
            if let Some(fraction) = event.contact_fraction(first) {
                self.bar
                    .get_or_insert_with(contact_bar)
                    .set_position((fraction * 1000.0) as u64);
            }
        }
        if let (Event::Solved { .. }, Some(bar)) = (event, self.bar.take()) {
            bar.finish_and_clear();
        }
    }
}

/// The progress bar of the contact solve: the way down to the tolerance, on a log scale.
fn contact_bar() -> indicatif::ProgressBar {
    bar(
        1000,
        "contact [{bar:40}] {percent:>3}% of the way to the tolerance, {elapsed}",
    )
}

fn main() -> ExitCode {
    files::memory::bound_heaps_under_an_address_space_limit();
    on_signals();
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Run {
        scene: None,
        set: vec![],
        unset: vec![],
        out: None,
        petsc: None,
    });
    match dispatch(command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // under mpirun every rank meets the same error: the first rank says it
            if mpi_rank().is_none_or(|r| r == 0) {
                eprintln!("error: {e}");
            }
            ExitCode::FAILURE
        }
    }
}

/// This process's rank under Open MPI's or MPICH's `mpirun` (`None` outside one).
fn mpi_rank() -> Option<u64> {
    ["OMPI_COMM_WORLD_RANK", "PMI_RANK"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse().ok())
}

/// What a signal does to a run. SIGINT, SIGTERM and SIGHUP end it at once (their usual exit
/// status, 128 + the signal), the output sets it was writing removed (the directory keeps its
/// previous set); SIGXFSZ is not left to kill it (exit 153 with no word): a write past the
/// file-size limit (`ulimit -f`) fails, and the run stops with an output error naming the limit.
fn on_signals() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM, SIGXFSZ};
        let ignored = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        if let Err(e) = signal_hook::flag::register(SIGXFSZ, ignored) {
            eprintln!("warning: SIGXFSZ keeps its default action ({e}): a file past `ulimit -f` ends the run");
        }
        match signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            Ok(mut signals) => {
                std::thread::spawn(move || {
                    if let Some(signal) = signals.forever().next() {
                        eprintln!("\nstopped by signal {signal}: the partial output set is removed");
                        files::output::abandon_and_exit(128 + signal);
                    }
                });
            }
            Err(e) => {
                eprintln!("warning: no handler for SIGINT and SIGTERM ({e}): a stopped run may leave a partial set")
            }
        }
    }
}

/// Lines of the studies' progress, to stderr.
fn say(line: &str) {
    eprintln!("{line}");
}

fn dispatch(command: Command) -> Result<(), DriverError> {
    match command {
        Command::Run {
            scene,
            set,
            unset,
            out,
            petsc,
        } => run(scene, overrides(set, unset), out, petsc),
        Command::Scenes => scenes(),
        Command::Capacitance { scene, set, out } => capacitance(scene, &set, out),
        Command::Fclib {
            files,
            solver,
            tol,
            criterion,
            time_limit,
            verbose,
            out,
        } => {
            let options = fclib::Options {
                solver,
                tol,
                criterion,
                time_limit: files::limits::seconds(time_limit, "--time-limit")?,
                verbose,
            };
            options.check()?;
            let rows = fclib::run(&files, &options, out.as_deref(), &mut |l| say(l))?;
            print!("{}", fclib::table(&rows));
            let unsolved: Vec<String> = rows
                .iter()
                .filter(|r| !r.converged)
                .map(|r| format!("{}: {}", r.file, r.outcome))
                .collect();
            if unsolved.is_empty() {
                Ok(())
            } else {
                Err(DriverError::Unexpected {
                    what: "files not solved",
                    items: unsolved,
                })
            }
        }
        Command::Strategies => {
            for s in Strategy::ALL {
                println!("{:16} {}", s.name(), s.description());
            }
            Ok(())
        }
        Command::Sweep {
            scene,
            param,
            from,
            to,
            steps,
            set,
            out,
        } => {
            // the default under out/, named by the scene file's stem made a safe name
            let stem = std::path::Path::new(&scene)
                .file_stem()
                .map_or_else(|| scene.clone(), |s| s.to_string_lossy().into_owned());
            let dir = out.unwrap_or_else(|| output::default_dir(&format!("{stem}-sweep")));
            let spec = sweep::SweepSpec { param, from, to, steps };
            sweep::sweep(&scene, &set, &spec, Some(&dir), &mut say).map(|_| ())
        }
        Command::Table1 { loose, tight, out } => {
            let md = table1::markdown(&table1::table1(&loose, &tight, &mut say)?);
            println!("{md}");
            let mut o = output::Outputs::documents(&out.unwrap_or_else(|| PathBuf::from("out").join("table1")));
            o.add("table1.md", md.into_bytes());
            Ok(o.commit()?)
        }
        Command::Study(args) => study(args),
        Command::Verification { full, out } => verification(full, &out),
        Command::Stability {
            quick,
            out,
            limit,
            ranks,
        } => stability(quick, &out, limit, ranks),
    }
}

/// `piezocontact run`: the scene solved, its plan's outputs written.
fn run(
    scene: Option<String>,
    overrides: Vec<String>,
    out: Option<PathBuf>,
    petsc: Option<String>,
) -> Result<(), DriverError> {
    let name = scene.unwrap_or_else(|| "paper".into());
    let (mut scene, source) = scene_file::load(&name, &overrides)?;
    if let Some(extra) = petsc {
        let all = [scene.solver.petsc_options.take(), Some(extra)];
        scene.solver.petsc_options = Some(all.into_iter().flatten().collect::<Vec<_>>().join(" "));
        // the options joined are the scene's `solver.petsc_options`: its key names them
        scene.validate().map_err(|e| files::Error::scene(&name, e))?;
    }
    let dir = out.unwrap_or_else(|| output::default_dir(&scene.name));
    let mut terminal = Terminal::new();
    let solution = match scene.solver.backend {
        BackendChoice::Faer => Some(files::run::run(&scene, &source, &dir, &mut terminal)?),
        BackendChoice::Petsc => run_petsc(&scene, &source, &dir, &mut terminal)?,
    };
    if let Some(solution) = solution {
        for line in problem::report::result_lines(&solution.report) {
            say(&line);
        }
        if let Some(p) = &solution.report.petsc {
            say(&format!(
                "PETSc: {} ranks, {} unknowns, {} Krylov iterations ({})",
                p.ranks, p.unknowns, p.krylov_iterations, p.reason
            ));
        }
        let mut names: Vec<String> = solution
            .report
            .plan
            .outputs
            .iter()
            .map(|o| o.name().to_string())
            .collect();
        let on_pieces = solution
            .report
            .petsc
            .as_ref()
            .filter(|p| p.pieces.is_some())
            .map(|p| p.ranks);
        if let Some(n) = on_pieces {
            // no rank held the whole mesh: the solution is in pieces
            let pieces = match n {
                1 => "solution-0.vtu".to_string(),
                n => format!("solution-0.vtu ... solution-{}.vtu", n - 1),
            };
            for name in names.iter_mut().filter(|x| *x == "solution.vtu") {
                *name = format!("solution.pvtu with {pieces}");
            }
        }
        if let (Some(path), Some(spec)) = (&solution.report.path, &scene.path) {
            // the instants whose step file was written: every output_every-th and the last
            let n = path.instants;
            let written: Vec<usize> = (0..n).filter(|&k| spec.has_fields(k, n)).collect();
            // (on pieces each instant is a `.pvtu` with one piece per rank)
            let ext = if on_pieces.is_some() { "pvtu" } else { "vtu" };
            let steps = match written[..] {
                [only] => format!("step-{only:04}.{ext}"),
                [first, .., last] => format!(
                    "{} step files, step-{first:04}.{ext} ... step-{last:04}.{ext}",
                    written.len()
                ),
                [] => "no step file".into(),
            };
            names.push(format!("path.csv, path.svg/png, path.pvd with {steps}"));
        }
        say(&format!("wrote {} in {}", names.join(", "), dir.display()));
    }
    Ok(())
}

/// A run of the PETSc backend (rank 0 returns the solution).
#[cfg(feature = "petsc")]
fn run_petsc(
    scene: &problem::Scene,
    source: &scene_file::Source,
    dir: &std::path::Path,
    terminal: &mut Terminal,
) -> Result<Option<problem::Solution>, DriverError> {
    driver::petsc_run::run_distributed(scene, source, dir, terminal)
}

/// Without the feature, a run of the PETSc backend is refused by name: first what the backend
/// would not solve in the scene (so that nobody builds PETSc to learn it), then the build.
#[cfg(not(feature = "petsc"))]
fn run_petsc(
    scene: &problem::Scene,
    _: &scene_file::Source,
    _: &std::path::Path,
    _: &mut Terminal,
) -> Result<Option<problem::Solution>, DriverError> {
    distributed::supports(scene).map_err(problem::ProblemError::from)?;
    Err(DriverError::Usage(
        "solver.backend = \"petsc\" needs a build with PETSc: cargo build --release --features petsc (with petsc-dev, libclang-dev and pkg-config installed; see the README), then mpirun -np N target/release/piezocontact run ...".into(),
    ))
}

/// `piezocontact scenes`: one line per shipped scene.
/// `piezocontact capacitance`: the matrix printed, and written as CSV and JSON.
fn capacitance(scene: Option<String>, set: &[String], out: Option<PathBuf>) -> Result<(), DriverError> {
    let name = scene.unwrap_or_else(|| "actuator".into());
    let (scene, source) = scene_file::load(&name, set)?;
    let c = files::run::capacitance(&scene, &source, None)?;
    let field = files::output::csv_field;
    let names: Vec<_> = c.terminals.iter().map(|t| field(t)).collect();
    // each column's unit in brackets, as every CSV output carries it
    let columns: Vec<_> = c
        .terminals
        .iter()
        .map(|t| files::output::header_cell(t, &c.unit))
        .collect();
    let mut csv = format!("terminal,{}\n", columns.join(","));
    for (t, row) in names.iter().zip(&c.matrix) {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:e}")).collect();
        csv.push_str(&format!("{t},{}\n", cells.join(",")));
    }
    let width = c.terminals.iter().map(|t| t.len()).max().unwrap_or(0).max(8);
    println!("capacitance of `{}` (Q_i = sum_j C_ij V_j, in {}):", scene.name, c.unit);
    println!(
        "{:width$} {}",
        "",
        c.terminals.iter().map(|t| format!("{t:>14}")).collect::<String>()
    );
    for (t, row) in c.terminals.iter().zip(&c.matrix) {
        println!(
            "{t:width$} {}",
            row.iter().map(|x| format!("{x:>14.6e}")).collect::<String>()
        );
    }
    say(&format!(
        "reciprocity max|C - Cᵀ|/max|C| = {:.1e}; Gauss max|column sum|/max|C| = {:.1e}",
        c.asymmetry, c.column_sum
    ));
    for note in &c.notes {
        say(&format!("note: {note}"));
    }
    let dir = out.unwrap_or_else(|| output::default_dir(&format!("{}-capacitance", scene.name)));
    let mut o = output::Outputs::documents(&dir);
    o.add("capacitance.csv", csv.into_bytes());
    o.add(
        "capacitance.json",
        serde_json::to_vec_pretty(&c).map_err(|e| DriverError::Unexpected {
            what: "capacitance.json",
            items: vec![e.to_string()],
        })?,
    );
    o.commit()?;
    say(&format!("wrote capacitance.csv, capacitance.json in {}", dir.display()));
    Ok(())
}

fn scenes() -> Result<(), DriverError> {
    let mut out = std::io::stdout().lock();
    for (name, text) in scene_file::SHIPPED {
        let desc = scene_file::parse(text, name, &[])
            .map(|s| s.description)
            .unwrap_or_default();
        // a closed pipe (`| head`) ends the listing quietly
        if writeln!(out, "{name:18} {desc}").is_err() {
            break;
        }
    }
    Ok(())
}

/// `piezocontact verification`: the report, an error listing the checks that fail.
fn verification(full: bool, out: &std::path::Path) -> Result<(), DriverError> {
    let failures = verification::report(full, out, &mut say)?;
    if !failures.is_empty() {
        return Err(DriverError::Unexpected {
            what: "verification checks that fail",
            items: failures,
        });
    }
    say(&format!(
        "verification: every check holds; wrote {}",
        out.join("verification.md").display()
    ));
    Ok(())
}

/// `piezocontact stability`: the cases, each in a child process of this program.
fn stability(quick: bool, out: &std::path::Path, limit: u64, ranks: Option<usize>) -> Result<(), DriverError> {
    let exe = std::env::current_exe().map_err(|e| files::Error::Output {
        what: "cannot find this program's path to run the cases".into(),
        source: e,
    })?;
    let backend = match ranks {
        Some(0) => return Err(DriverError::Usage("--ranks: at least 1".into())),
        Some(ranks) => stability::Backend::Petsc { ranks },
        None => stability::Backend::Default,
    };
    let limit = std::time::Duration::from_secs(limit);
    let rows = stability::write(&exe, (backend, quick), limit, out, &mut say)?;
    let name = if ranks.is_some() {
        "stability-petsc.md"
    } else {
        "stability.md"
    };
    say(&format!(
        "{} runs as expected; wrote {}",
        rows.len(),
        out.join(name).display()
    ));
    Ok(())
}

/// The overrides of `--set KEY=VALUE` and `--unset KEY` (as `~KEY`), in that order.
fn overrides(set: Vec<String>, unset: Vec<String>) -> Vec<String> {
    set.into_iter()
        .chain(unset.into_iter().map(|k| format!("~{k}")))
        .collect()
}

/// `piezocontact study`: defaults from the scene, the study, its files.
fn study(args: StudyArgs) -> Result<(), DriverError> {
    let StudyArgs {
        scene,
        sizes,
        strategies,
        tols,
        reference,
        orders,
        set,
        out,
    } = args;
    let scene = scene.unwrap_or_else(|| "paper".into());
    let mut spec = convergence::StudySpec {
        sizes,
        strategies,
        tols,
        reference_n: reference,
        orders,
    };
    let (scene, set) = (&scene[..], &set[..]);
    convergence::refuse_overrides(set, &spec)?;
    let (base, _) = scene_file::load(scene, set)?;
    if spec.sizes.is_empty() {
        let n = base.mesh.n.unwrap_or(16).max(4);
        spec.sizes = vec![n / 4, n / 2, n];
    }
    if spec.strategies.is_empty() {
        spec.strategies.push(base.solver.strategy);
    }
    let dir = out.unwrap_or_else(|| output::default_dir(&format!("{}-study", base.name)));
    let study = convergence::study(scene, set, &spec, &mut say)?;
    let mut outs = output::Outputs::new(&dir);
    let md = format!(
        "# Study of `{}`\n\n{}",
        study.scene,
        convergence::markdown(&study, "study")
    );
    outs.add("study.md", md.clone().into_bytes());
    outs.add("study.csv", convergence::csv(&study).into_bytes());
    outs.extend(convergence::pictures("study", &study)?);
    outs.commit()?;
    println!("{md}");
    say(&format!("wrote study.md, study.csv and the plots in {}", dir.display()));
    Ok(())
}
