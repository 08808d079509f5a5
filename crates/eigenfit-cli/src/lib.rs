//! The `eigenfit` command-line tool as a library: the binary (`main.rs`) parses the command line
//! and calls [`run`]; other front ends (the Python package in `python/`) call [`run_json`] with
//! the same arguments and get the command's `--json` result as a value, so both always agree.
//!
//! Exit codes: 0 success, 1 internal failure, 2 bad input (arguments, files, data),
//! 3 an estimation that did not converge (its results are still printed).

pub mod commands;
pub mod error;
pub mod output;
pub mod plot;
pub mod progress;
pub mod report;
pub mod rotordynamics;
pub mod source;
pub mod testdata;

use clap::{Parser, Subcommand};
pub use error::CliError;

/// The command line.
#[derive(Debug, Parser)]
#[command(name = "eigenfit", version, about = "Finite-element model updating by eigenvalue sensitivity")]
pub struct Cli {
    /// The subcommand to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Natural frequencies of a model; a stiffness sweep with --sweep.
    Simulate(commands::simulate::SimulateArgs),
    /// Update the bearing stiffnesses to match measured frequencies.
    Estimate(commands::estimate::EstimateArgs),
    /// Estimate jointly from several test configurations (a campaign file).
    Campaign(commands::campaign::CampaignArgs),
    /// Compare update strategies over targets and a grid of initial guesses.
    Compare(commands::compare::CompareArgs),
    /// Find where model and measurement disagree, name the missing effect and add it.
    Discover(commands::discover::DiscoverArgs),
    /// The paper rotor end to end: Table 1, Table 3 case 1 with every strategy, a convergence map
    /// and a discovery, with every plot written to a folder.
    Demo(commands::demo::DemoArgs),
    /// Strategies × problems × starts in parallel: one record per run, a summary per problem
    /// and strategy (success rate, evaluations), with --plot performance profiles and ECDFs.
    Bench(commands::bench::BenchArgs),
    /// Campbell diagram of a two-plane (ROSS) rotor: damped frequencies, whirl and log
    /// decrement against speed in rpm, with the critical speeds.
    Campbell(commands::campbell::CampbellArgs),
}

/// Runs a parsed command line; returns the exit code of a run that produced results
/// (0, or 3 for an estimation that did not converge).
pub fn run(cli: &Cli) -> Result<u8, CliError> {
    match &cli.command {
        Command::Simulate(a) => commands::simulate::run(a).map(|()| error::EXIT_OK),
        Command::Estimate(a) => commands::estimate::run(a),
        Command::Campaign(a) => commands::campaign::run(a),
        Command::Compare(a) => commands::compare::run(a),
        Command::Discover(a) => commands::discover::run(a),
        Command::Demo(a) => commands::demo::run(a).map(|()| error::EXIT_OK),
        Command::Bench(a) => commands::bench::run(a),
        Command::Campbell(a) => commands::campbell::run(a).map(|()| error::EXIT_OK),
    }
}

/// The long options `command` takes (`max-iterations`, without the dashes), as `--help` lists
/// them; `None` when there is no such command. Front ends check their keyword arguments against
/// them before running (the Python package raises a `TypeError` naming a misspelled keyword and
/// the nearest option, rather than passing clap's usage text on).
pub fn option_names(command: &str) -> Option<Vec<String>> {
    use clap::CommandFactory;
    let cli = Cli::command();
    let sub = cli.get_subcommands().find(|c| c.get_name() == command)?;
    Some(sub.get_arguments().filter_map(|a| a.get_long().map(str::to_string)).collect())
}

/// Runs `eigenfit ARGS… --json` in this process and returns its JSON result with the exit code
/// (0, or 3 for an estimation that did not converge), exactly what the binary would print.
/// `args` start at the subcommand (`["simulate", "--preset", "paper-rotor"]`); `--json` is added
/// when missing. Bad arguments are [`CliError::Input`] with clap's message; a panic inside a
/// command is caught and returned as [`CliError::Failure`], never unwound into the caller.
pub fn run_json(args: &[String]) -> Result<(serde_json::Value, u8), CliError> {
    let mut argv = Vec::with_capacity(args.len() + 2);
    argv.push("eigenfit".to_string());
    argv.extend(args.iter().cloned());
    if !args.iter().any(|a| a == "--json") {
        argv.push("--json".to_string());
    }
    let cli =
        Cli::try_parse_from(&argv).map_err(|e| CliError::Input(e.to_string().trim_end().to_string()))?;
    let (outcome, value) = output::capture_json(|| {
        report::with_command_line(&argv, || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(&cli)))
        })
    });
    let code = match outcome {
        Ok(result) => result?,
        Err(panic) => {
            let msg = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("unknown");
            return Err(CliError::Failure(format!(
                "internal error: {msg} (please report this with the input that caused it)"
            )));
        }
    };
    let name = args.first().map_or("", String::as_str);
    let value = value.ok_or_else(|| CliError::Failure(format!("`{name}` produced no JSON result")))?;
    Ok((value, code))
}
