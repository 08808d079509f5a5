//! The driver's evaluation count: an [`Objective`] adaptor that counts the evaluations reaching
//! the model, so strategies need not count their own.

use crate::model::ParameterSet;
use crate::problem::{Linearisation, Objective, ResidualError};
use std::cell::Cell;

/// `inner` with every call of [`linearise`](Objective::linearise) and
/// [`cost`](Objective::cost) counted, whether it succeeds or not (a failed trial cost a solve
/// all the same). The driver places it inside the budget's adaptor, so an evaluation the budget
/// refused never reached the model and is not counted.
pub struct Counted<'a> {
    inner: &'a dyn Objective,
    count: Cell<usize>,
}

impl<'a> Counted<'a> {
    /// `inner`, counted from zero.
    pub fn new(inner: &'a dyn Objective) -> Self {
        Self { inner, count: Cell::new(0) }
    }

    /// Evaluations so far.
    pub fn count(&self) -> usize {
        self.count.get()
    }

    fn charge(&self) {
        self.count.set(self.count.get() + 1);
    }
}

impl Objective for Counted<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.charge();
        self.inner.linearise(p)
    }
    fn cost(&self, p: &[f64]) -> Option<f64> {
        self.charge();
        self.inner.cost(p)
    }
    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        self.charge();
        self.inner.linearise_accepted(p, accept)
    }
}
