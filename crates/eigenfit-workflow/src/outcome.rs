//! How an iteration ended, as every estimating report states it.

use serde::Serialize;

/// `converged`, `termination`, `iterations`, `evaluations`: the four keys every estimating
/// report (estimate, run-up estimate, campaign) carries, flattened into it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Outcome {
    /// Whether the iteration converged (and, where it applies, every mode was paired).
    pub converged: bool,
    /// Why it stopped.
    pub termination: String,
    /// Iterations taken.
    pub iterations: usize,
    /// Model evaluations (eigen-solves) spent.
    pub evaluations: usize,
}

impl Outcome {
    /// The outcome of a driver run; `converged` as given (the caller may require more).
    pub fn of(estimate: &eigenfit_core::update::Estimate, converged: bool) -> Self {
        Self {
            converged,
            termination: estimate.termination.to_string(),
            iterations: estimate.iterations,
            evaluations: estimate.evaluations,
        }
    }
}
