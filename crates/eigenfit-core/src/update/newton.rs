//! The paper's plain method (section III): Δk from eq. 28, added to k every iteration.

use super::settings::{Guard, SettingsError};
use super::{
    eigen_view, evaluate_or_diverge, newton_point, square_converged, Step, StepStatus, UpdateError,
    UpdateStrategy,
};
use crate::problem::{Linearisation, Objective};

/// Plain Newton on eigenvalues in linear stiffness, as in the paper: square system (as many
/// modes as parameters), no damping, no bounds handling — a step that leaves the physical range
/// ends the run as diverged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Newton {
    tolerance_hz: f64,
}

impl Default for Newton {
    fn default() -> Self {
        Self { tolerance_hz: 0.01 }
    }
}

impl Newton {
    /// Converged when every |f_model − f_measured| is below `tolerance_hz` (the paper: 0.01 Hz)
    /// and below [`RELATIVE_FREQUENCY_TOLERANCE`](super::RELATIVE_FREQUENCY_TOLERANCE) of
    /// f_measured (scale-free); refused unless a finite number greater than zero.
    pub fn new(tolerance_hz: f64) -> Result<Self, SettingsError> {
        Guard("Newton").positive("tolerance_hz", tolerance_hz)?;
        Ok(Self { tolerance_hz })
    }

    /// The convergence tolerance, Hz.
    pub fn tolerance_hz(&self) -> f64 {
        self.tolerance_hz
    }
}

impl UpdateStrategy for Newton {
    fn name(&self) -> &'static str {
        "newton"
    }

    fn needs_eigenvalues(&self) -> bool {
        true
    }

    fn start(&mut self, _: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        newton_point(initial, &eigen_view("newton", initial)?.measured_eigenvalues).map(|_| ())
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        square_converged(lin, self.tolerance_hz)
    }

    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        let p = newton_point(current, &eigen_view("newton", current)?.measured_eigenvalues)?;
        let next = evaluate_or_diverge(problem, &p)?;
        let status = if self.converged(&next) { StepStatus::Converged } else { StepStatus::Continue };
        Ok(Step { next, status })
    }
}
