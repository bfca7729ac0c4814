//! `piezocontact`: the command line. See `piezocontact --help`.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "piezocontact",
    version,
    about = "Frictional contact of piezoelectric bodies (Uzawa, Schur PCG, fixed point)"
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
        /// Output directory (default: out/<scene>/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// List the shipped scenes.
    Scenes,
    /// List the solver strategies.
    Strategies,
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
            for (name, text) in driver::scene::SHIPPED {
                let desc = driver::scene::parse(text, name, &[])
                    .map(|s| s.description)
                    .unwrap_or_default();
                println!("{name:16} {desc}");
            }
            ExitCode::SUCCESS
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
                driver::run::run(&scene, &source, Some(&dir), &mut |line| eprintln!("{line}"))
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
