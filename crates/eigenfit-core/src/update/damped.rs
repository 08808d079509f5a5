//! Damped least squares (Levenberg–Marquardt) in scaled parameters, with bounds.

use super::{Evaluate, Step, StepStatus, UpdateError, UpdateStrategy};
use crate::parameters::ParameterSet;
use crate::residual::Linearisation;
use nalgebra::{DMatrix, DVector};

/// Levenberg–Marquardt on the weighted residual, in each parameter's scale (log for
/// stiffnesses), with Marquardt's diagonal scaling, a gain-ratio test that accepts or rejects
/// each trial (Nielsen's damping update), bounds by projection, and a cap on the scaled step so a
/// flat start (a stiff support, where the frequencies barely move) cannot jump across decades.
/// Any number of modes ≥ the number of free parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Damped {
    /// Converged when every |f_model − f_measured| / f_measured is below this.
    pub residual_tolerance: f64,
    /// Converged when an accepted scaled step has ‖δ‖∞ below this.
    pub step_tolerance: f64,
    /// Largest ‖δ‖∞ of one step in scaled units (ln 100: two decades for a log parameter).
    pub max_step: f64,
    /// Rejected trials allowed per iteration before the run stalls.
    pub max_trials: usize,
    /// Parameters held at their starting value (profile likelihood, partial updates).
    pub fixed: Vec<bool>,
    mu: f64,
    nu: f64,
}

impl Default for Damped {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-12,
            step_tolerance: 1e-10,
            max_step: 100f64.ln(),
            max_trials: 30,
            fixed: Vec::new(),
            mu: 1e-3,
            nu: 2.0,
        }
    }
}

impl Damped {
    /// Holds the parameters flagged `true` fixed.
    pub fn with_fixed(mut self, fixed: Vec<bool>) -> Self {
        self.fixed = fixed;
        self
    }

    fn is_free(&self, i: usize) -> bool {
        !self.fixed.get(i).copied().unwrap_or(false)
    }
}

/// Jacobian with respect to the scaled parameters: J · diag(dp/ds).
pub fn scaled_jacobian(params: &ParameterSet, lin: &Linearisation) -> DMatrix<f64> {
    let mut js = lin.jacobian.clone();
    for (i, par) in params.iter().enumerate() {
        js.column_mut(i)
            .scale_mut(par.scale_derivative(lin.parameters[i]));
    }
    js
}

impl UpdateStrategy for Damped {
    fn name(&self) -> &'static str {
        "damped"
    }

    fn start(
        &mut self,
        problem: &dyn Evaluate,
        initial: &Linearisation,
    ) -> Result<(), UpdateError> {
        let free = (0..problem.parameters().len())
            .filter(|&i| self.is_free(i))
            .count();
        if initial.residual.len() < free {
            return Err(UpdateError::Setup(format!(
                "damped least squares needs at least as many measured modes as free parameters: {} modes, {free} parameters",
                initial.residual.len()
            )));
        }
        self.mu = 1e-3;
        self.nu = 2.0;
        Ok(())
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        lin.max_rel_diff() <= self.residual_tolerance
    }

    fn step(
        &mut self,
        problem: &dyn Evaluate,
        current: &Linearisation,
    ) -> Result<Step, UpdateError> {
        let params = problem.parameters();
        let np = params.len();
        let mut js = scaled_jacobian(params, current);
        for i in (0..np).filter(|&i| !self.is_free(i)) {
            js.column_mut(i).fill(0.0);
        }
        let a = js.transpose() * &js;
        let g = js.transpose() * &current.residual;
        // Marquardt scaling, floored so a (nearly) insensitive parameter still gets damped.
        let amax = a.diagonal().amax().max(f64::MIN_POSITIVE);
        let d = DVector::from_iterator(np, (0..np).map(|i| a[(i, i)].max(1e-12 * amax)));
        let s0: Vec<f64> = params
            .iter()
            .zip(&current.parameters)
            .map(|(p, &v)| p.to_scaled(v))
            .collect();
        let cost0 = current.cost();
        let mut evaluations = 0;
        for _ in 0..self.max_trials {
            let mut lhs = a.clone();
            for i in 0..np {
                if self.is_free(i) {
                    lhs[(i, i)] += self.mu * d[i];
                } else {
                    lhs[(i, i)] = 1.0;
                }
            }
            let Some(mut delta) = lhs.cholesky().map(|c| c.solve(&g)) else {
                self.mu *= self.nu;
                self.nu *= 2.0;
                continue;
            };
            let cap = delta.amax();
            if cap > self.max_step {
                delta *= self.max_step / cap;
            }
            // Project onto the bounds in scaled space.
            let mut p_new = Vec::with_capacity(np);
            for (i, par) in params.iter().enumerate() {
                let lo = if par.lower.is_finite() {
                    par.to_scaled(par.lower)
                } else {
                    f64::NEG_INFINITY
                };
                let hi = if par.upper.is_finite() {
                    par.to_scaled(par.upper)
                } else {
                    f64::INFINITY
                };
                let s = (s0[i] + delta[i]).clamp(lo, hi);
                delta[i] = s - s0[i];
                p_new.push(par.from_scaled(s).clamp(par.lower, par.upper));
            }
            let predicted = delta.dot(&g) - 0.5 * delta.dot(&(&a * &delta));
            evaluations += 1;
            let trial = match problem.linearise(&p_new) {
                Ok(t) if t.residual.iter().all(|v| v.is_finite()) => t,
                _ => {
                    self.mu *= self.nu;
                    self.nu *= 2.0;
                    continue;
                }
            };
            let actual = cost0 - trial.cost();
            let small_step = delta.amax() <= self.step_tolerance;
            if predicted > 0.0 && actual / predicted > 1e-4 {
                let rho = actual / predicted;
                self.mu *= f64::max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0).powi(3));
                self.nu = 2.0;
                let status = if self.converged(&trial) || small_step {
                    StepStatus::Converged
                } else {
                    StepStatus::Continue
                };
                return Ok(Step {
                    next: trial,
                    status,
                    evaluations,
                });
            }
            if small_step || predicted <= 0.0 {
                // No descent left at round-off level: the current point is the minimum.
                return Ok(Step {
                    next: current.clone(),
                    status: StepStatus::Converged,
                    evaluations,
                });
            }
            self.mu *= self.nu;
            self.nu *= 2.0;
        }
        Err(UpdateError::Stalled(format!(
            "no acceptable step in {} trials",
            self.max_trials
        )))
    }
}
