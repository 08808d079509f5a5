//! Errors of the rotordynamics crate: each names what is wrong and where.

use thiserror::Error;

/// What went wrong while reading, building or solving a rotor.
#[derive(Debug, Error)]
pub enum RotorDynError {
    /// The rotor file cannot be read or parsed.
    #[error("{0}")]
    File(String),
    /// The rotor's data are inconsistent (names the element).
    #[error("{0}")]
    Model(String),
    /// The measured data do not fit the rotor (names the row).
    #[error("{0}")]
    Data(String),
    /// A numerical method failed on valid input.
    #[error("{0}")]
    Solver(String),
}
