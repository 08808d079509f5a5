//! The blocks the estimating reports state alike (how the iteration ended, the budget, the fit
//! quality, the verdict, the parameters, the frequencies), each built by one function; all but
//! the budget are flattened into the report, so their keys stand at its top level.

use crate::named::Named;
use eigenfit_core::analysis::verdict::FitVerdict;
use serde::Serialize;

/// `converged`, `termination`, `iterations`, `evaluations`, flattened into every estimating
/// report: core's, so that a comparison's runs and a run-up identification state it alike.
pub use eigenfit_core::update::Outcome;

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

/// `fit_quality`, `chi2`, `dof`, `p_value`, `relative_rms_residual`, `disagreeing_modes`: core's
/// [`FitQuality`](eigenfit_core::analysis::verdict::FitQuality) as every estimating report states it,
/// flattened into it. `D` names a disagreeing mode (a mode number, or a run-up point).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitQualityReport<D> {
    /// `acceptable`, `poor-fit` or `not-judged`.
    pub fit_quality: &'static str,
    /// χ² = Σ (residual/σ)² (with std only).
    pub chi2: Option<f64>,
    /// Degrees of freedom: measured values − free parameters.
    pub dof: usize,
    /// P(χ²_dof > χ²): the probability that noise alone gives a misfit this large (with std only).
    pub p_value: Option<f64>,
    /// √(mean((f_model − f_measured)/f_measured)²).
    pub relative_rms_residual: f64,
    /// The measured values that miss by more than 3σ, worst first.
    pub disagreeing_modes: Vec<D>,
}

impl<D> FitQualityReport<D> {
    /// The report of `quality`, naming the k-th measured value `name(k)`.
    pub fn of(quality: &eigenfit_core::analysis::verdict::FitQuality, name: impl Fn(usize) -> D) -> Self {
        Self {
            fit_quality: quality.verdict.label(),
            chi2: quality.chi2,
            dof: quality.dof,
            p_value: quality.p_value,
            relative_rms_residual: quality.relative_rms,
            disagreeing_modes: quality.disagreeing.iter().map(|&k| name(k)).collect(),
        }
    }
}

/// `initial`, `parameters`, `parameter_status`: each parameter's start, its estimate and what the
/// data say about it in words (its interval, or why there is none), as estimate and the run-up
/// estimate state them, flattened into the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterValues {
    /// Initial values.
    pub initial: Named<f64>,
    /// Estimated values.
    pub parameters: Named<f64>,
    /// What the data say about each parameter, in words.
    pub parameter_status: Named<String>,
}

impl ParameterValues {
    /// The parameters `names` from `initial` to `estimated`, the i-th described by `status(i)`.
    pub fn new(
        names: &[String],
        initial: &[f64],
        estimated: &[f64],
        status: impl Fn(usize) -> String,
    ) -> Self {
        Self {
            initial: Named::new(names, initial.iter().copied()),
            parameters: Named::new(names, estimated.iter().copied()),
            parameter_status: Named::new(names, (0..names.len()).map(status)),
        }
    }
}

/// `frequencies_hz`, `measured_hz`: the model's frequencies of the paired modes at the estimate
/// beside the measured ones, as estimate and each configuration of a campaign state them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairedFrequencies {
    /// Model frequencies at the estimate (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Measured frequencies (Hz).
    pub measured_hz: Vec<f64>,
}

impl PairedFrequencies {
    /// The frequencies of a linearisation (the estimate's last).
    pub fn of(lin: &eigenfit_core::problem::Linearisation) -> Self {
        Self { frequencies_hz: lin.frequencies_hz.clone(), measured_hz: lin.measured_hz.clone() }
    }
}

/// `acceptable`, `verdict`: whether an estimate can be used and, in words, the first thing that
/// stands against it, as estimate and the run-up estimate state it, flattened into the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Verdict {
    /// Converged, fit not poor, no parameter on a limit, budget not spent, every mode paired: the
    /// exit verdict.
    pub acceptable: bool,
    /// The run's stop reason when it did not converge, `budget-exhausted`, `poor-fit`,
    /// `not-identifiable` (a parameter on a limit), or `converged` (saying so when the fit quality
    /// could not be judged).
    pub verdict: &'static str,
}

impl Verdict {
    /// The verdict of a run that stopped for `not_converged` (`None`: it converged), with
    /// `budget_spent`, fit quality `fit`, some parameter `on_limit`, and some measured mode
    /// `unpaired` (no verdict word of its own: the pairing report says which).
    pub fn of(
        not_converged: Option<&'static str>,
        budget_spent: bool,
        fit: FitVerdict,
        on_limit: bool,
        unpaired: bool,
    ) -> Self {
        let verdict = match not_converged {
            Some(reason) => reason,
            None if budget_spent => "budget-exhausted",
            None if fit == FitVerdict::Poor => "poor-fit",
            None if on_limit => "not-identifiable",
            None if fit == FitVerdict::NotJudged => "converged (fit quality not judged: no std)",
            None => "converged",
        };
        let acceptable =
            not_converged.is_none() && fit != FitVerdict::Poor && !on_limit && !budget_spent && !unpaired;
        Self { acceptable, verdict }
    }
}
