//! `eigenfit`: finite-element model updating from the command line.
//!
//! Exit codes: 0 success, 1 internal failure, 2 bad input (arguments, files, data),
//! 3 an estimation that did not converge (its results are still printed).

mod commands;
mod error;
mod measured;
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Simulate(a) => commands::simulate::run(a).map(|()| error::EXIT_OK),
        Command::Estimate(a) => commands::estimate::run(a),
        Command::Compare(a) => commands::compare::run(a).map(|()| error::EXIT_OK),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("eigenfit: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
