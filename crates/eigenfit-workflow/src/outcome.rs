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

/// Model evaluations allowed and spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct BudgetReport {
    /// The limit.
    pub limit: usize,
    /// Spent.
    pub used: usize,
    /// Whether it ran out.
    pub exhausted: bool,
}

impl BudgetReport {
    /// What `budget` allowed and what was spent of it.
    pub fn of(budget: &eigenfit_core::update::Budget) -> Self {
        Self { limit: budget.limit(), used: budget.used(), exhausted: budget.exhausted() }
    }
}
