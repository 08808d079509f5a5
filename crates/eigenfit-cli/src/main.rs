//! `eigenfit`: finite-element model updating from the command line.
//!
//! Exit codes: 0 success, 1 internal failure, 2 bad input (arguments, files, data),
//! 3 an estimation that did not converge (its results are still printed).

mod any_model;
mod commands;
mod error;
mod measured;
mod output;
mod plot;
mod progress;
mod source;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(name = "eigenfit", version, about = "Finite-element model updating by eigenvalue sensitivity")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Natural frequencies of a model; a stiffness sweep with --sweep.
    Simulate(commands::simulate::SimulateArgs),
    /// Update the bearing stiffnesses to match measured frequencies.
    Estimate(commands::estimate::EstimateArgs),
    /// Compare update strategies over targets and a grid of initial guesses.
    Compare(commands::compare::CompareArgs),
    /// Find where model and measurement disagree, name the missing effect and add it.
    Discover(commands::discover::DiscoverArgs),
    /// The paper rotor end to end: Table 1, Table 3 case 1 with every strategy, a convergence map
    /// and a discovery, with every plot written to a folder.
    Demo(commands::demo::DemoArgs),
}

fn main() -> ExitCode {
    quiet_panics();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Simulate(a) => commands::simulate::run(a).map(|()| error::EXIT_OK),
        Command::Estimate(a) => commands::estimate::run(a),
        Command::Compare(a) => commands::compare::run(a).map(|()| error::EXIT_OK),
        Command::Discover(a) => commands::discover::run(a).map(|()| error::EXIT_OK),
        Command::Demo(a) => commands::demo::run(a).map(|()| error::EXIT_OK),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("eigenfit: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// No Rust panic text or backtrace ever reaches the user: a closed pipe (`eigenfit … | head`)
/// ends the program quietly, anything else is reported as an internal error with exit code 1.
fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("unknown");
        if msg.contains("Broken pipe") {
            std::process::exit(0);
        }
        eprintln!("eigenfit: internal error: {msg} (please report this with the input that caused it)");
        std::process::exit(i32::from(error::EXIT_FAILURE));
    }));
}
