//! Update strategies and the driver that owns the iteration loop.
//!
//! A strategy ([`UpdateStrategy`]) turns the linearisation at the current point into the next
//! point; the [`Driver`] owns the loop, the iteration limit, the history and the termination
//! reason, like argmin's `Executor`.

mod budget;
mod counted;
mod driver;
mod gauss_newton;
pub(crate) mod grid;
pub(crate) mod levenberg_marquardt;
mod newton;
mod pstep;
pub mod refit;
pub mod registry;
pub mod sampler;
mod settings;
#[cfg(test)]
mod tests;
mod tikhonov;
mod tmcmc;
mod trust_region_reflective;

pub use budget::{Budget, Budgeted, DEFAULT_EVALUATIONS};
pub use counted::Counted;
pub use driver::{
    Driver, Estimate, IterationRecord, IterationRecordSink, ObservedDriver, Observer, Outcome, Termination,
    TerminationReport, FROM_SEARCH,
};
pub use gauss_newton::GaussNewtonLineSearch;
pub use grid::halton;
pub use levenberg_marquardt::{scaled_bounds, stationary, LevenbergMarquardt, LevenbergMarquardtSettings};
pub use newton::Newton;
pub use pstep::PStep;
pub use registry::{Method, StrategyError, StrategyFactory, StrategySettings};
pub use sampler::{Gaussian, LogLikelihood, Posterior, Sampler};
pub use settings::{Guard, SettingsError};
pub use tikhonov::{ParameterChoice, Regularisation, TikhonovGaussNewton, TikhonovProblem};
pub use tmcmc::{Tmcmc, TmcmcSettings, MAX_STAGES as TMCMC_MAX_STAGES};
pub use trust_region_reflective::{trust_region_step, TrustRegionReflective};

use crate::problem::{EigenView, Linearisation, Objective, ResidualError};
use thiserror::Error;

/// Why an update step could not be taken.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum UpdateError {
    /// The strategy cannot be used on this problem (e.g. Newton needs a square system).
    #[error("{0}")]
    Setup(String),
    /// The iterate left the physical range or the model failed there.
    #[error("diverged: {0}")]
    Diverged(String),
    /// No acceptable step could be found.
    #[error("stalled: {0}")]
    Stalled(String),
    /// The residual could not be evaluated at the starting point.
    #[error(transparent)]
    Residual(#[from] ResidualError),
}

/// Whether the iterate returned by a step ends the run, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepStatus {
    /// Keep iterating.
    Continue,
    /// The strategy's convergence test (a step or frequency tolerance) holds at the new iterate.
    Converged,
    /// The residual is at its round-off level: an exact fit.
    ExactFit,
    /// No step reduces the misfit (the gradient vanishes) at a fit the strategy accepts.
    Stationary,
    /// The strategy's restarts are used up; the new iterate is the best point it found, which
    /// its own acceptance rule did not accept.
    RestartsUsed,
}

/// One accepted step. The evaluations it spent are counted by the [`Driver`], not reported here.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Linearisation at the new point.
    pub next: Linearisation,
    /// Convergence verdict at the new point.
    pub status: StepStatus,
}

/// One way of moving from the current linearisation to the next point.
pub trait UpdateStrategy {
    /// Name for reports, e.g. `newton`.
    fn name(&self) -> &'static str;
    /// Resets internal state before a run starting at `initial`.
    fn start(&mut self, problem: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError>;
    /// Whether `lin` already satisfies the convergence test (checked at the start).
    fn converged(&self, lin: &Linearisation) -> bool;
    /// What [`converged`](Self::converged) holding at the start means: the termination the
    /// driver reports when the starting point already passes the test (default: the strategy's
    /// tolerance test, [`Termination::Converged`]).
    fn start_termination(&self) -> Termination {
        Termination::Converged
    }
    /// Takes one step.
    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError>;
    /// Whether the strategy restarts from starts ranked by residual over the whole range, so
    /// that many runs on the same data (a comparison grid) can rank them once
    /// ([`share_ranked_starts`](Self::share_ranked_starts)). Default: it does not.
    fn uses_ranked_starts(&self) -> bool {
        false
    }
    /// Restart starts ranked once for every run on the same data, used instead of ranking its
    /// own; ignored by a strategy that does not restart (the default).
    fn share_ranked_starts(&mut self, _starts: std::sync::Arc<Vec<Vec<f64>>>) {}
    /// The regularisation the run ended with (λ and the rule that chose it), for the report;
    /// `None` (the default) for a strategy that does not regularise.
    fn regularisation(&self) -> Option<Regularisation> {
        None
    }
    /// The strategy's own state after its last step, by name, for observers (progress, logs,
    /// a study of how a strategy behaves): Levenberg–Marquardt's damping `mu`, a trust region's
    /// `radius`, the regularisation's `lambda`. Default: none.
    fn metrics(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
    /// Whether the strategy solves with the model's eigenvalues and their sensitivities
    /// ([`Linearisation::eigen`], through [`eigen_view`]) and so does not apply to a problem
    /// whose frequencies are not eigenvalues of K − λM (a run-up). Default: it works on the
    /// residual alone.
    fn needs_eigenvalues(&self) -> bool {
        false
    }
}

/// The eigenvalue view the paper's strategies solve with, or a set-up error naming `who` where
/// the problem has none (a run-up's frequencies are not eigenvalues of K − λM).
pub fn eigen_view<'a>(who: &str, lin: &'a Linearisation) -> Result<&'a EigenView, UpdateError> {
    lin.eigen.as_ref().ok_or_else(|| {
        UpdateError::Setup(format!(
            "{who} solves with model eigenvalues and their sensitivities (the paper's eq. 27–28); \
             this problem compares frequencies that are not eigenvalues of K − λM (not applicable): \
             use a least-squares strategy such as damped"
        ))
    })
}

/// Solves the paper's eq. 28, S Δk = Δλ, on the first N modes (N = number of parameters, as in
/// eq. 27) with target eigenvalues `target`, and returns k + Δk.
pub fn newton_point(
    current: &Linearisation,
    target: &nalgebra::DVector<f64>,
) -> Result<Vec<f64>, UpdateError> {
    let eigen = eigen_view("the paper's Newton step", current)?;
    let n = eigen.eigenvalue_jacobian.ncols();
    if eigen.eigenvalue_jacobian.nrows() < n {
        return Err(UpdateError::Setup(format!(
            "the paper's Newton step needs as many modes as parameters (eq. 27); got {} modes for {n} parameters",
            eigen.eigenvalue_jacobian.nrows()
        )));
    }
    let s = eigen.eigenvalue_jacobian.rows(0, n).into_owned();
    let dlambda = target.rows(0, n) - eigen.model_eigenvalues.rows(0, n);
    let dk = s
        .lu()
        .solve(&dlambda)
        .filter(|d| d.iter().all(|v| v.is_finite()))
        .ok_or_else(|| UpdateError::Stalled("the sensitivity matrix is singular".into()))?;
    Ok(current.parameters.iter().zip(dk.iter()).map(|(k, d)| k + d).collect())
}

/// Relative convergence of the paper's strategies: a frequency counts as matched when it is
/// within this fraction of the measured one (the paper's 0.01 Hz at 100 Hz), whatever the units
/// or the scale of the structure — a model whose modes lie near 6e-4 Hz is not "converged" at the
/// start because every difference is below an absolute 0.01 Hz.
pub const RELATIVE_FREQUENCY_TOLERANCE: f64 = 1e-4;

/// True when every paired frequency of the square system (as many modes as parameters) is within
/// `tolerance_hz` of its measured value and within [`RELATIVE_FREQUENCY_TOLERANCE`] of it: the
/// absolute tolerance keeps the paper's behaviour, the relative one makes the test scale-free.
pub(crate) fn square_converged(lin: &Linearisation, tolerance_hz: f64) -> bool {
    let n = lin.parameters.len().min(lin.frequencies_hz.len());
    lin.frequencies_hz[..n].iter().zip(&lin.measured_hz[..n]).all(|(f, m)| within(*f, *m, tolerance_hz))
}

/// |f − target| below both `tolerance_hz` and [`RELATIVE_FREQUENCY_TOLERANCE`]·|target|.
pub(crate) fn within(f: f64, target: f64, tolerance_hz: f64) -> bool {
    (f - target).abs() < tolerance_hz.min(RELATIVE_FREQUENCY_TOLERANCE * target.abs())
}

/// Largest |f_model − f_measured| (Hz) over the first N modes, N = number of parameters: the
/// paper's stopping test for its square system.
pub fn square_max_diff_hz(lin: &Linearisation) -> f64 {
    let n = lin.parameters.len().min(lin.frequencies_hz.len());
    lin.frequencies_hz[..n]
        .iter()
        .zip(&lin.measured_hz[..n])
        .fold(0.0, |m, (a, b)| f64::max(m, (a - b).abs()))
}

/// Refuses a start with fewer residuals than parameters, naming the strategy (`who`): a
/// least-squares step needs at least as many rows as unknowns.
pub fn require_enough_residuals(
    who: &str,
    problem: &dyn Objective,
    initial: &Linearisation,
) -> Result<(), UpdateError> {
    if initial.residual.len() < problem.parameters().len() {
        return Err(UpdateError::Setup(format!(
            "{who} needs at least as many residuals as parameters: {} for {}",
            initial.residual.len(),
            problem.parameters().len()
        )));
    }
    Ok(())
}

/// Linearises at `p`, turning a point outside the bounds or a failed model into `Diverged`.
pub fn evaluate_or_diverge(problem: &dyn Objective, p: &[f64]) -> Result<Linearisation, UpdateError> {
    problem.parameters().check(p).map_err(|e| UpdateError::Diverged(e.to_string()))?;
    problem.linearise(p).map_err(|e| UpdateError::Diverged(e.to_string()))
}
