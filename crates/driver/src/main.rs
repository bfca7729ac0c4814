//! `piezocontact`: the command line. See `piezocontact --help`.

use clap::{Parser, Subcommand};
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
        /// Override a scene key, e.g. --set mesh.n=128 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Output directory (default: out/SCENE/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// List the shipped scenes.
    Scenes,
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
        /// Sizes under the tight rule (complementarity 1e-10).
        #[arg(long, value_delimiter = ',', default_values_t = [32, 64, 128])]
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
    /// Error against h and against run time: a scene over mesh sizes, strategies and
    /// tolerances; writes study.md, study.csv and log-log plots (SVG, PNG).
    Study {
        /// Scene name or file (default: paper).
        scene: Option<String>,
        /// Mesh sizes mesh.n (default: the scene's n/4, n/2, n).
        #[arg(long, value_delimiter = ',')]
        sizes: Vec<usize>,
        /// Strategies (default: the scene's).
        #[arg(long, value_delimiter = ',')]
        strategies: Vec<String>,
        /// Tolerances (default: 1e-4, 1e-6, 1e-8).
        #[arg(long, value_delimiter = ',', default_values_t = [1e-4, 1e-6, 1e-8])]
        tols: Vec<f64>,
        /// Size of the reference run for a scene without an exact solution (default: 4 x the
        /// largest size).
        #[arg(long)]
        reference: Option<usize>,
        /// Other overrides.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Output directory (default: out/SCENE-study/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the stiff and extreme cases (SCENES.md section 5), each in its own process, and
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
    },
}

/// Lines to stderr, and a progress bar for the contact solve when stderr is a terminal.
struct Terminal {
    bar: Option<indicatif::ProgressBar>,
}

impl Terminal {
    fn new() -> Self {
        Terminal { bar: None }
    }
}

impl driver::run::Reporter for Terminal {
    fn line(&mut self, text: &str) {
        match &self.bar {
            Some(bar) if !bar.is_hidden() => bar.println(text),
            _ => eprintln!("{text}"),
        }
        if text.starts_with("solve ") {
            if let Some(bar) = self.bar.take() {
                bar.finish_and_clear();
            }
        }
    }
    fn fraction(&mut self, stage: &str, fraction: f64) {
        let bar = self.bar.get_or_insert_with(|| {
            let bar = indicatif::ProgressBar::with_draw_target(Some(1000), indicatif::ProgressDrawTarget::stderr());
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{prefix} [{bar:40}] {percent:>3}% of the way to the tolerance, {elapsed}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_prefix(stage.to_string());
            bar
        });
        bar.set_position((fraction * 1000.0) as u64);
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Run {
        scene: None,
        set: vec![],
        out: None,
    });
    match command {
        Command::Scenes => {
            use std::io::Write;
            let mut out = std::io::stdout().lock();
            for (name, text) in driver::scene::SHIPPED {
                let desc = driver::scene::parse(text, name, &[])
                    .map(|s| s.description)
                    .unwrap_or_default();
                // a closed pipe (`| head`) ends the listing quietly
                if writeln!(out, "{name:18} {desc}").is_err() {
                    break;
                }
            }
            ExitCode::SUCCESS
        }
        Command::Verification { full, out } => {
            match driver::verification::report(full, &out, &mut |l| eprintln!("{l}")) {
                Ok(failures) if failures.is_empty() => {
                    eprintln!(
                        "verification: every check holds; wrote {}",
                        out.join("verification.md").display()
                    );
                    ExitCode::SUCCESS
                }
                Ok(failures) => {
                    for f in &failures {
                        eprintln!("verification FAILED: {f}");
                    }
                    ExitCode::FAILURE
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Study {
            scene,
            sizes,
            strategies,
            tols,
            reference,
            set,
            out,
        } => {
            let scene = scene.unwrap_or_else(|| "paper".into());
            match study_command(&scene, sizes, strategies, tols, reference, &set, out) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
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
            let dir =
                out.unwrap_or_else(|| PathBuf::from("out").join(format!("{}-sweep", scene.trim_end_matches(".toml"))));
            let spec = driver::studies::SweepSpec { param, from, to, steps };
            match driver::studies::sweep(&scene, &set, &spec, Some(&dir), &mut |l| eprintln!("{l}")) {
                Ok(_) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Table1 { loose, tight, out } => {
            let dir = out.unwrap_or_else(|| PathBuf::from("out").join("table1"));
            let result = driver::studies::table1(&loose, &tight, &mut |l| eprintln!("{l}")).and_then(|rows| {
                let md = driver::studies::table1_markdown(&rows);
                println!("{md}");
                let mut o = driver::output::Outputs::new(&dir);
                o.add("table1.md", md.into_bytes());
                o.commit()
            });
            match result {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Stability { quick, out, limit } => {
            let exe = match std::env::current_exe() {
                Ok(e) => e,
                Err(e) => {
                    eprintln!("error: cannot find this program's path to run the cases: {e}");
                    return ExitCode::FAILURE;
                }
            };
            match driver::stability::write(&exe, quick, std::time::Duration::from_secs(limit), &out, &mut |l| {
                eprintln!("{l}")
            }) {
                Ok(rows) => {
                    eprintln!(
                        "{} runs as expected; wrote {}",
                        rows.len(),
                        out.join("stability.md").display()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Strategies => {
            for (name, desc) in driver::run::STRATEGIES {
                println!("{name:16} {desc}");
            }
            ExitCode::SUCCESS
        }
        Command::Run { scene, set, out } => {
            let name = scene.unwrap_or_else(|| "paper".into());
            let result = driver::scene::load(&name, &set).and_then(|(scene, source)| {
                let dir = out.unwrap_or_else(|| driver::output::default_dir(&scene.name));
                driver::run::run_with_reporter(&scene, &source, Some(&dir), &mut Terminal::new())
            });
            match result {
                Ok(_) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}

/// `piezocontact study`: defaults from the scene, the study, its files.
fn study_command(
    scene: &str,
    mut sizes: Vec<usize>,
    mut strategies: Vec<String>,
    tols: Vec<f64>,
    reference_n: Option<usize>,
    set: &[String],
    out: Option<PathBuf>,
) -> Result<(), driver::DriverError> {
    let (base, _) = driver::scene::load(scene, set)?;
    if sizes.is_empty() {
        let n = base.mesh.n.unwrap_or(16).max(4);
        sizes = vec![n / 4, n / 2, n];
    }
    if strategies.is_empty() {
        strategies.push(base.solver.strategy.clone());
    }
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{}-study", base.name)));
    let spec = driver::convergence::StudySpec {
        sizes,
        strategies,
        tols,
        reference_n,
    };
    let study = driver::convergence::study(scene, set, &spec, &mut |l| eprintln!("{l}"))?;
    let mut outs = driver::output::Outputs::new(&dir);
    let md = format!(
        "# Study of `{}`\n\n{}",
        study.scene,
        driver::convergence::markdown(&study, "study")
    );
    outs.add("study.md", md.clone().into_bytes());
    outs.add("study.csv", driver::convergence::csv(&study).into_bytes());
    for (name, bytes) in driver::plots::study_pictures("study", &study)? {
        outs.add(&name, bytes);
    }
    outs.commit()?;
    println!("{md}");
    eprintln!("wrote study.md, study.csv and the plots in {}", dir.display());
    Ok(())
}
