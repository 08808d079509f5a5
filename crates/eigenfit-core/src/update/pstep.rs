//! The paper's Fig. 1: large eigenvalue differences are split into p parts, converged one by one.

use super::settings::{Guard, SettingsError};
use super::{
    eigen_view, evaluate_or_diverge, newton_point, square_converged, square_max_diff_hz,
    within as frequency_within, Step, StepStatus, UpdateError, UpdateStrategy,
};
use crate::problem::{Linearisation, Objective};
use crate::units::eigenvalue_to_hz;
use nalgebra::DVector;

/// The paper's p-step method. When the largest frequency difference at the start exceeds
/// `split_above_hz` (tol2), the eigenvalue differences are divided into `parts` (p) equal parts;
/// Newton steps converge each intermediate target to `tolerance_hz` (tol1) in turn.
///
/// The paper does not state its tol2 and p; the defaults here (5 Hz, 5 parts) are ours.
#[derive(Debug, Clone, PartialEq)]
pub struct PStep {
    /// tol1: convergence of each stage and of the whole, Hz (the paper: 0.01 Hz), together with
    /// the relative [`RELATIVE_FREQUENCY_TOLERANCE`](super::RELATIVE_FREQUENCY_TOLERANCE).
    tolerance_hz: f64,
    /// tol2: split when the largest starting difference exceeds this, Hz.
    split_above_hz: f64,
    /// p: number of parts.
    parts: usize,
    start_eigenvalues: DVector<f64>,
    measured_eigenvalues: DVector<f64>,
    stage: usize,
    stages: usize,
}

impl Default for PStep {
    fn default() -> Self {
        Self::with_checked(0.01, 5.0, 5)
    }
}

impl PStep {
    /// A p-step strategy with tol1 (finite, > 0), tol2 (≥ 0; ∞ never splits) and p (≥ 1),
    /// refused with the setting's name otherwise.
    pub fn new(tolerance_hz: f64, split_above_hz: f64, parts: usize) -> Result<Self, SettingsError> {
        let guard = Guard("p-step");
        guard.positive("tolerance_hz", tolerance_hz)?;
        guard.non_negative_or_infinite("split_above_hz", split_above_hz)?;
        guard.at_least_one("parts", parts)?;
        Ok(Self::with_checked(tolerance_hz, split_above_hz, parts))
    }

    fn with_checked(tolerance_hz: f64, split_above_hz: f64, parts: usize) -> Self {
        Self {
            tolerance_hz,
            split_above_hz,
            parts,
            start_eigenvalues: DVector::zeros(0),
            measured_eigenvalues: DVector::zeros(0),
            stage: 1,
            stages: 1,
        }
    }

    /// tol1, tol2 (Hz) and p.
    pub fn settings(&self) -> (f64, f64, usize) {
        (self.tolerance_hz, self.split_above_hz, self.parts)
    }

    fn target(&self) -> DVector<f64> {
        let t = self.stage as f64 / self.stages as f64;
        &self.start_eigenvalues + (&self.measured_eigenvalues - &self.start_eigenvalues) * t
    }

    fn within(&self, lin: &Linearisation, target: &DVector<f64>) -> bool {
        lin.frequencies_hz
            .iter()
            .zip(target.iter())
            .take(lin.parameters.len())
            .all(|(f, &l)| frequency_within(*f, eigenvalue_to_hz(l), self.tolerance_hz))
    }
}

impl UpdateStrategy for PStep {
    fn name(&self) -> &'static str {
        "p-step"
    }

    fn needs_eigenvalues(&self) -> bool {
        true
    }

    fn start(&mut self, _: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        let eigen = eigen_view("p-step", initial)?;
        newton_point(initial, &eigen.measured_eigenvalues)?;
        self.start_eigenvalues = eigen.model_eigenvalues.clone();
        self.measured_eigenvalues = eigen.measured_eigenvalues.clone();
        self.stages = if square_max_diff_hz(initial) > self.split_above_hz { self.parts } else { 1 };
        self.stage = 1;
        Ok(())
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        square_converged(lin, self.tolerance_hz)
    }

    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        let p = newton_point(current, &self.target())?;
        let next = evaluate_or_diverge(problem, &p)?;
        // Advance through every stage whose target the new point already meets.
        while self.stage < self.stages && self.within(&next, &self.target()) {
            self.stage += 1;
        }
        let status = if self.stage == self.stages && self.converged(&next) {
            StepStatus::Converged
        } else {
            StepStatus::Continue
        };
        Ok(Step { next, status })
    }
}
