//! A cap on model evaluations, shared by every fit, refit and interval of one task, so that no
//! input — a typing slip, data no stiffness can produce — can make eigenfit run for hours.

use super::settings::{Guard, SettingsError};
use crate::model::ParameterSet;
use crate::problem::{Linearisation, Objective, ResidualError};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Evaluations a task may spend when the user sets no budget: a few seconds on the largest
/// models the CLI accepts, far more than any well-posed fit needs (tens to a few hundred).
pub const DEFAULT_EVALUATIONS: usize = 20_000;

/// How many model evaluations (eigen-solves) a task may spend. Shared by reference, so one budget
/// bounds an estimate together with its intervals and alternative solutions.
#[derive(Debug)]
pub struct Budget {
    limit: usize,
    used: AtomicUsize,
    refused: AtomicBool,
}

impl Budget {
    /// A budget of `limit` evaluations.
    pub fn new(limit: usize) -> Self {
        Self { limit, used: AtomicUsize::new(0), refused: AtomicBool::new(false) }
    }

    /// A budget of `limit` evaluations, refused when zero (no fit could even start).
    pub fn checked(limit: usize) -> Result<Self, SettingsError> {
        Guard("budget").at_least_one("limit", limit)?;
        Ok(Self::new(limit))
    }

    /// No limit (for callers that bound the work themselves).
    pub fn unlimited() -> Self {
        Self::new(usize::MAX)
    }

    /// The limit.
    pub fn limit(&self) -> usize {
        self.limit
    }

    /// Evaluations spent so far.
    pub fn used(&self) -> usize {
        self.used.load(Ordering::Relaxed).min(self.limit)
    }

    /// Evaluations left.
    pub fn remaining(&self) -> usize {
        self.limit - self.used()
    }

    /// True once an evaluation was refused: every result computed afterwards is incomplete.
    pub fn exhausted(&self) -> bool {
        self.refused.load(Ordering::Relaxed)
    }

    /// Charges one evaluation; false (and the budget marked exhausted) when none is left.
    pub fn charge(&self) -> bool {
        if self.used.fetch_add(1, Ordering::Relaxed) < self.limit {
            true
        } else {
            self.refused.store(true, Ordering::Relaxed);
            false
        }
    }

    /// Marks the budget exhausted now: a caller that ends a run early for its own reason (a
    /// local fit of the search abandoned) stops the driver as a spent budget would.
    pub fn refuse(&self) {
        self.refused.store(true, Ordering::Relaxed);
    }

    /// `problem` with every evaluation charged to this budget.
    pub fn wrap<'a>(&'a self, problem: &'a dyn Objective) -> Budgeted<'a> {
        Budgeted { inner: problem, budget: self }
    }
}

/// An [`Objective`] that charges each evaluation to a [`Budget`] and fails with
/// [`ResidualError::BudgetExhausted`] once it is spent.
pub struct Budgeted<'a> {
    inner: &'a dyn Objective,
    budget: &'a Budget,
}

impl Objective for Budgeted<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        if !self.budget.charge() {
            return Err(ResidualError::BudgetExhausted { limit: self.budget.limit });
        }
        self.inner.linearise(p)
    }
    fn cost(&self, p: &[f64]) -> Option<f64> {
        if !self.budget.charge() {
            return None;
        }
        self.inner.cost(p)
    }
    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        if !self.budget.charge() {
            return Err(ResidualError::BudgetExhausted { limit: self.budget.limit });
        }
        self.inner.linearise_accepted(p, accept)
    }
}

#[cfg(test)]
mod tests {
    use super::Budget;

    #[test]
    fn refuses_after_the_limit_and_remembers_it() {
        let b = Budget::new(2);
        assert!(b.charge() && b.charge());
        assert!(!b.exhausted());
        assert!(!b.charge());
        assert!(b.exhausted());
        assert_eq!((b.used(), b.remaining()), (2, 0));
    }
}
