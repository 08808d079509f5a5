//! Gauss–Newton with a backtracking line search: the least-squares step (SVD, so a rank-deficient
//! Jacobian gives the minimum-norm step), capped, projected onto the bounds, halved until the
//! Armijo condition holds.

use super::levenberg_marquardt::scaled_bounds;
use super::settings::{Guard, SettingsError};
use super::{Step, StepStatus, UpdateError, UpdateStrategy};
use crate::problem::{Linearisation, Objective, ResidualError};

/// Gauss–Newton with an Armijo line search in the scaled coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussNewtonLineSearch {
    tolerance: f64,
    max_step: f64,
    recent_cost: f64,
    stuck_for: usize,
}

impl Default for GaussNewtonLineSearch {
    fn default() -> Self {
        Self { tolerance: 1e-10, max_step: 100f64.ln(), recent_cost: f64::INFINITY, stuck_for: 0 }
    }
}

/// Iterations without a 0.1 % cost reduction after which the run has stalled on a plateau (as
/// the damped strategy's rule).
const PLATEAU_ITERATIONS: usize = 12;

/// Halvings of the step before a line search gives up.
const HALVINGS: usize = 30;

impl GaussNewtonLineSearch {
    /// `tolerance` (≥ 0): the relative cost decrease and step (scaled) below which the run has
    /// converged, and the relative misfit of an exact fit; `max_step` (> 0): the largest ‖δ‖∞ of
    /// a step in scaled units.
    pub fn new(tolerance: f64, max_step: f64) -> Result<Self, SettingsError> {
        let guard = Guard("Gauss–Newton line search");
        guard.non_negative("tolerance", tolerance)?;
        guard.positive("max_step", max_step)?;
        Ok(Self { tolerance, max_step, ..Self::default() })
    }
}

impl UpdateStrategy for GaussNewtonLineSearch {
    fn name(&self) -> &'static str {
        "gn-line-search"
    }

    fn start(&mut self, problem: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        super::require_enough_residuals("Gauss–Newton", problem, initial)?;
        self.recent_cost = initial.cost();
        self.stuck_for = 0;
        Ok(())
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        lin.is_exact_fit(self.tolerance, lin.parameters.len())
    }

    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        let params = problem.parameters();
        let (lo, hi) = scaled_bounds(params);
        let x = params.to_scaled(&current.parameters);
        let j = current.scaled_jacobian(params);
        let svd = j.clone().svd(true, true);
        let smax = svd.singular_values.max();
        let mut delta = svd
            .solve(&current.residual, 1e-12 * smax)
            .map_err(|e| UpdateError::Stalled(format!("Gauss–Newton step: {e}")))?;
        let cap = delta.amax();
        if cap > self.max_step {
            delta *= self.max_step / cap;
        }
        // Descent rate along δ: d/dα ½‖r − J α δ‖² at 0 = −(Jᵀr)·δ.
        let slope = -(j.transpose() * &current.residual).dot(&delta);
        if slope >= 0.0 || delta.amax() <= self.tolerance {
            return Ok(Step { next: current.clone(), status: StepStatus::Converged });
        }
        let cost0 = current.cost();
        let mut alpha = 1.0;
        for _ in 0..HALVINGS {
            let s: Vec<f64> = (0..x.len()).map(|i| (x[i] + alpha * delta[i]).clamp(lo[i], hi[i])).collect();
            let p = params.from_scaled(&s);
            match problem.linearise(&p) {
                Ok(next) if next.cost() <= cost0 + 1e-4 * alpha * slope => {
                    let moved = s.iter().zip(&x).fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()));
                    let small = cost0 - next.cost() <= self.tolerance * cost0 || moved <= self.tolerance;
                    let status = if small || self.converged(&next) {
                        StepStatus::Converged
                    } else {
                        StepStatus::Continue
                    };
                    if next.cost() < 0.999 * self.recent_cost {
                        self.recent_cost = next.cost();
                        self.stuck_for = 0;
                    } else {
                        self.stuck_for += 1;
                        if self.stuck_for >= PLATEAU_ITERATIONS && status == StepStatus::Continue {
                            return Err(UpdateError::Stalled(format!(
                                "no 0.1 % cost reduction in {PLATEAU_ITERATIONS} iterations (a plateau)"
                            )));
                        }
                    }
                    return Ok(Step { next, status });
                }
                Err(e @ ResidualError::BudgetExhausted { .. }) => return Err(UpdateError::Residual(e)),
                _ => alpha *= 0.5,
            }
        }
        Err(UpdateError::Stalled(format!("the line search found no decrease in {HALVINGS} halvings")))
    }
}
