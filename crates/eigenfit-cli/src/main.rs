//! `eigenfit`: finite-element model updating from the command line. The commands live in the
//! library (`lib.rs`), which the Python package calls too.
//!
//! Exit codes: 0 an answer, 1 internal failure (or results that could not all be written to
//! standard output), 2 bad input refused before any fitting (arguments, files, data), 3 no acceptable answer or the budget used up (its results are still printed).

use clap::Parser;
use eigenfit_cli::{error, Cli};
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    quiet_panics();
    let cli = Cli::parse();
    match eigenfit_cli::run(&cli) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            error::set_exit_on_closed_pipe(e.exit_code());
            eprintln!("eigenfit: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// No Rust panic text or backtrace ever reaches the user: a closed pipe (`eigenfit … | head`)
/// ends the program quietly with the exit code already decided, anything else is reported as an internal error with exit code 1.
fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("unknown");
        // Results that could not all be written (`eigenfit … | head -1`, a full disk under a
        // redirect) are not an answer: the decided code if it is not 0, else 1.
        if msg.contains("failed printing to stdout") || msg.contains("Broken pipe") {
            let decided = error::EXIT_ON_CLOSED_PIPE.load(std::sync::atomic::Ordering::Relaxed);
            let _ = writeln!(
                std::io::stderr(),
                "eigenfit: the results could not all be written to standard output ({})",
                msg.trim_start_matches("failed printing to stdout: ")
            );
            std::process::exit(i32::from(decided.max(error::EXIT_FAILURE)));
        }
        eprintln!("eigenfit: internal error: {msg} (please report this with the input that caused it)");
        std::process::exit(i32::from(error::EXIT_FAILURE));
    }));
}
