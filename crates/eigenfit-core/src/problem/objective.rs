//! What an update strategy sees of a problem: parameters, and residual and Jacobian at any point.
//!
//! The trait sits in the problem layer so that every problem formulation (single, stacked,
//! shapes, joint) implements it without depending on the strategies that consume it.

use crate::eigen::EigenSolver;
use crate::model::{ParameterSet, StructuralModel};
use crate::problem::{Linearisation, Problem, ResidualError};

/// The least-squares objective ½‖r(p)‖² a strategy minimises, as a strategy sees it: the
/// parameters, and the residual and Jacobian at any point.
pub trait Objective {
    /// The model's parameters.
    fn parameters(&self) -> &ParameterSet;
    /// Residual and Jacobian at `p`.
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError>;
    /// ½‖r‖² at `p`, `None` where the residual cannot be evaluated: equal to
    /// `linearise(p)`'s cost to round-off; implementations may skip the Jacobian (used to rank
    /// many points).
    fn cost(&self, p: &[f64]) -> Option<f64> {
        self.linearise(p).ok().map(|l| l.cost())
    }
    /// A trial point: [`linearise`](Self::linearise) at `p` when `accept` takes the cost there,
    /// `Ok(None)` when it does not — one evaluation either way, but an implementation may skip
    /// the Jacobian of a rejected trial (a shape fit's Nelson systems). Wrappers forward it.
    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        let lin = self.linearise(p)?;
        Ok(accept(lin.cost()).then_some(lin))
    }
}

impl<M: StructuralModel, S: EigenSolver> Objective for Problem<M, S> {
    fn parameters(&self) -> &ParameterSet {
        Problem::parameters(self)
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        Problem::linearise(self, p)
    }
    fn cost(&self, p: &[f64]) -> Option<f64> {
        Problem::cost(self, p).ok()
    }
}
