//! CLI errors and their exit codes.

use thiserror::Error;

/// Exit code for success.
pub const EXIT_OK: u8 = 0;
/// Exit code for a failure inside eigenfit (a solver that broke on valid input).
pub const EXIT_FAILURE: u8 = 1;
/// Exit code for bad input: arguments, model files, measured data (clap also uses 2).
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit code for an estimation that ended without converging (results are still printed).
pub const EXIT_NOT_CONVERGED: u8 = 3;

/// What went wrong, with the exit code it maps to.
#[derive(Debug, Error)]
pub enum CliError {
    /// The user's input is wrong; the message says what and where.
    #[error("{0}")]
    Input(String),
    /// eigenfit failed on valid input.
    #[error("{0}")]
    Failure(String),
    /// The evaluation budget ran out before any result (exit code 3, like a fit cut short).
    #[error("budget-exhausted: {0}")]
    BudgetExhausted(String),
    /// Valid input with no acceptable answer (an eigen-solver that did not converge), exit 3.
    #[error("{0}")]
    NoAnswer(String),
}

impl CliError {
    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => EXIT_BAD_INPUT,
            CliError::Failure(_) => EXIT_FAILURE,
            CliError::BudgetExhausted(_) | CliError::NoAnswer(_) => EXIT_NOT_CONVERGED,
        }
    }
}

impl From<eigenfit_workflow::WorkflowError> for CliError {
    fn from(e: eigenfit_workflow::WorkflowError) -> Self {
        match e {
            eigenfit_workflow::WorkflowError::Input(m) => CliError::Input(m),
            eigenfit_workflow::WorkflowError::Failure(m) => CliError::Failure(m),
            eigenfit_workflow::WorkflowError::BudgetExhausted(m) => CliError::BudgetExhausted(m),
            eigenfit_workflow::WorkflowError::NoAnswer(m) => CliError::NoAnswer(m),
        }
    }
}

/// Shorthand for an input error.
pub fn input(msg: impl Into<String>) -> CliError {
    CliError::Input(msg.into())
}

/// The exit code the run ends with if output fails on a closed pipe (`eigenfit … | head`): set
/// before the results (or the error) are printed, so a verdict of 2 or 3 is not turned into 0.
pub static EXIT_ON_CLOSED_PIPE: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(EXIT_OK);

/// Records the exit code a closed pipe must not hide.
pub fn set_exit_on_closed_pipe(code: u8) {
    EXIT_ON_CLOSED_PIPE.store(code, std::sync::atomic::Ordering::Relaxed);
}
