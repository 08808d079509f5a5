//! The one error type of the workflows: bad input (the user can fix it), a failure inside
//! eigenfit on valid input, a user budget too small to produce any result, or valid input with
//! no acceptable answer (a solver that did not converge). The CLI maps them to exit codes 2, 1
//! and 3.

use thiserror::Error;

/// What went wrong; every message names what and where.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum WorkflowError {
    /// The input is wrong (arguments, files, data); the message says what and where.
    #[error("{0}")]
    Input(String),
    /// eigenfit failed on valid input (a solver that broke).
    #[error("{0}")]
    Failure(String),
    /// The evaluation budget ran out before there was any result to report.
    #[error("{0}")]
    BudgetExhausted(String),
    /// Valid input for which no acceptable answer was reached (an eigen-solver that did not
    /// converge); the message says what to try. Exit code 3, as a fit that did not converge.
    #[error("{0}")]
    NoAnswer(String),
}

/// Shorthand for an input error.
pub(crate) fn input(msg: impl Into<String>) -> WorkflowError {
    WorkflowError::Input(msg.into())
}

/// Shorthand for a failure.
pub(crate) fn failure(msg: impl ToString) -> WorkflowError {
    WorkflowError::Failure(msg.to_string())
}

impl From<eigenfit_core::measurement::measured_csv::MeasuredFileError> for WorkflowError {
    fn from(e: eigenfit_core::measurement::measured_csv::MeasuredFileError) -> Self {
        WorkflowError::Input(e.to_string())
    }
}
