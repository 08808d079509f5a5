//! The blocks the estimating reports state alike (how the iteration ended, the budget, the fit
//! quality, the verdict, the parameters, the frequencies), each built by one function; all but
//! the budget are flattened into the report, so their keys stand at its top level.

use crate::named::Named;
use eigenfit_core::analysis::alternatives::OtherSolution;
use eigenfit_core::analysis::verdict::FitVerdict;
use eigenfit_core::analysis::Identifiability;
use eigenfit_core::nalgebra::DMatrix;
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
    /// Σr² of the weighted residual whatever σ is: χ² with std; without, what the alternatives'
    /// `misfit` compares with (σ̂² = misfit / dof when `alternatives_sigma` is `residuals`).
    pub misfit: f64,
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
            misfit: quality.misfit,
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
    /// fit at the estimate explains the data (as discover's `explained`, at the same level).
    pub acceptable: bool,
    /// The run's stop reason when it did not converge, `budget-exhausted`, `poor-fit`,
    /// `not-identifiable` (a parameter on a limit), `not-unique` (another solution is equally
    /// good: the data do not determine the parameters uniquely), or `converged` (saying so when
    /// the fit quality could not be judged).
    pub verdict: &'static str,
    /// No other solution found is equally good. The exit code is 0 only when the estimate is
    /// `acceptable` and `unique`.
    pub unique: bool,
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
        unique: bool,
    ) -> Self {
        let verdict = match not_converged {
            Some(reason) => reason,
            None if budget_spent => "budget-exhausted",
            None if fit == FitVerdict::Poor => "poor-fit",
            None if on_limit => "not-identifiable",
            None if !unique => "not-unique",
            None if fit == FitVerdict::NotJudged => "converged (fit quality not judged: no std)",
            None => "converged",
        };
        let acceptable =
            not_converged.is_none() && fit != FitVerdict::Poor && !on_limit && !budget_spent && !unpaired;
        Self { acceptable, verdict, unique }
    }

    /// An answer to use as it is: acceptable and unique (exit code 0).
    pub fn is_answer(&self) -> bool {
        self.acceptable && self.unique
    }
}

/// Another minimum of the misfit (or a symmetric model's mirror point), with the test that says
/// whether the data can tell it from the estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlternativeSolution {
    /// Its values.
    pub parameters: Named<f64>,
    /// Its χ² (with std; without, Σr²/σ̂² with σ̂ from the estimate's residuals; `null` when σ
    /// cannot be estimated: no degree of freedom left, or an exact estimate).
    pub chi2: Option<f64>,
    /// χ² here − χ² at the estimate (same scaling; `null` as `chi2`).
    pub delta_chi2: Option<f64>,
    /// Σr² of the residual (weighted with std): the misfit whatever σ is.
    pub misfit: f64,
    /// The data cannot tell it from the estimate: Δχ² below the χ² quantile at 1 − α with as
    /// many degrees of freedom as free parameters (α = 0.05); without σ, an exact fit as the
    /// estimate is.
    pub equally_good: bool,
    /// A mirror solution: the model has the exchange as a symmetry (checked at two points) and
    /// the exchanged point is equally good.
    pub mirror: bool,
    /// The exchanged pair when it is a mirror solution of a symmetric model that exchanges one
    /// pair of parameters (`None` for a symmetry exchanging more: see `exchanged`).
    pub mirror_of: Option<[String; 2]>,
    /// A mirror solution's exchanged parameters as cycles (`[["zone1", "zone3"], ["zone2",
    /// "zone4"]]`: a plate's zones mirrored about its centre line); empty for other solutions.
    pub exchanged: Vec<Vec<String>>,
}

impl AlternativeSolution {
    /// What the test said about it, in words: equally good, rejected by the data, or — without a
    /// Δχ², when no test was possible (no std and no degree of freedom) — only fitting worse.
    pub fn judgement(&self) -> &'static str {
        match (self.equally_good, self.delta_chi2) {
            (true, _) => "equally good",
            (false, Some(_)) => "worse (the data reject it)",
            (false, None) => "fits worse (no test: no std and no degree of freedom)",
        }
    }

    /// The report of `others` for parameters `names` (values in the parameters' own units).
    pub fn list(names: &[String], others: &[OtherSolution]) -> Vec<Self> {
        others
            .iter()
            .map(|a| {
                let cycles = a.permutation.as_deref().map(cycles).unwrap_or_default();
                let mirror = a.is_mirror();
                AlternativeSolution {
                    parameters: Named::new(names, a.parameters.iter().copied()),
                    chi2: a.judged.chi2,
                    delta_chi2: a.judged.delta_chi2,
                    misfit: a.misfit,
                    equally_good: a.judged.equally_good,
                    mirror,
                    mirror_of: match cycles.as_slice() {
                        [pair] if mirror && pair.len() == 2 => {
                            Some([names[pair[0]].clone(), names[pair[1]].clone()])
                        }
                        _ => None,
                    },
                    exchanged: cycles.iter().map(|c| c.iter().map(|&i| names[i].clone()).collect()).collect(),
                }
            })
            .collect()
    }
}

/// What the data say about one parameter: `true`, or `{"identifiable": false}` with the one
/// bound known.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ParameterIdentifiability {
    /// Determined.
    Determined(bool),
    /// Not determined; a bound where one is known.
    Not {
        /// Always false.
        identifiable: bool,
        /// The lower bound, when only that is known.
        #[serde(skip_serializing_if = "Option::is_none")]
        lower_bound: Option<f64>,
        /// The upper bound, when only that is known.
        #[serde(skip_serializing_if = "Option::is_none")]
        upper_bound: Option<f64>,
    },
}

impl From<&Identifiability> for ParameterIdentifiability {
    fn from(i: &Identifiability) -> Self {
        let not = |lower_bound, upper_bound| Self::Not { identifiable: false, lower_bound, upper_bound };
        match *i {
            Identifiability::Determined => Self::Determined(true),
            Identifiability::LowerBoundOnly { lower } => not(Some(lower), None),
            Identifiability::UpperBoundOnly { upper } => not(None, Some(upper)),
            Identifiability::Undetermined => not(None, None),
        }
    }
}

/// The cycles (two or more parameters each) of a permutation, each from its lowest index.
pub(crate) fn cycles(perm: &[usize]) -> Vec<Vec<usize>> {
    let mut seen = vec![false; perm.len()];
    let mut out = Vec::new();
    for start in 0..perm.len() {
        let mut cycle = Vec::new();
        let mut i = start;
        while !seen[i] {
            seen[i] = true;
            cycle.push(i);
            i = perm[i];
        }
        if cycle.len() > 1 {
            out.push(cycle);
        }
    }
    out
}

/// `{phase: evaluations}` from the running totals after each phase (a phase not reached is left
/// out).
pub(crate) fn phase_counts(totals: &[(&str, usize)]) -> Named<usize> {
    let mut before = 0;
    Named(
        totals
            .iter()
            .map(|&(name, total)| {
                let n = total - before;
                before = total;
                (name.to_string(), n)
            })
            .collect(),
    )
}

/// A parameter covariance in a report: `coordinates` says in which (always `physical`: each
/// parameter in its own unit, as `units` gives it, so entry (i, j) is in unitᵢ·unitⱼ), and
/// `matrix[i][j]` is between `parameters[i]` and `parameters[j]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CovarianceReport {
    /// `physical`: the parameters in their own units (not the update's scaled coordinates).
    pub coordinates: &'static str,
    /// Row and column order.
    pub parameters: Vec<String>,
    /// The symmetric matrix, row by row.
    pub matrix: Vec<Vec<f64>>,
}

/// A parameter correlation in a report: cov(i, j)/√(cov(i, i)·cov(j, j)), the same in any
/// coordinates that scale each parameter on its own (physical, log or factors on a nominal).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CorrelationReport {
    /// Row and column order.
    pub parameters: Vec<String>,
    /// The symmetric matrix, row by row, ones on the diagonal.
    pub matrix: Vec<Vec<f64>>,
}

/// `covariance`, `correlation`: the linearised covariance the intervals come from, and the
/// correlation, flattened into every estimating report; each `null` when it is not computed (no
/// std and no residual scatter, a run that did not converge) or not computable (a
/// rank-deficient Jacobian: some combination of parameters the data do not determine).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Covariances {
    /// The covariance in physical coordinates.
    pub covariance: Option<CovarianceReport>,
    /// The correlation.
    pub correlation: Option<CorrelationReport>,
}

impl Covariances {
    /// The report of `covariance` (physical) for parameters `names`: both `null` without one,
    /// or when an entry is not finite or a variance not positive (rank-deficient).
    pub fn of(names: &[String], covariance: Option<&DMatrix<f64>>) -> Self {
        let n = names.len();
        let usable = covariance.filter(|c| {
            c.nrows() == n
                && c.ncols() == n
                && c.iter().all(|v| v.is_finite())
                && (0..n).all(|i| c[(i, i)] > 0.0)
        });
        let Some(c) = usable else { return Self { covariance: None, correlation: None } };
        let rows = |f: &dyn Fn(usize, usize) -> f64| -> Vec<Vec<f64>> {
            (0..n).map(|i| (0..n).map(|j| f(i, j)).collect()).collect()
        };
        // Symmetric to the last bit: (i, j) and (j, i) from the same sum.
        let sym = |i: usize, j: usize| 0.5 * (c[(i, j)] + c[(j, i)]);
        let correlation = rows(&|i, j| {
            if i == j {
                1.0
            } else {
                (sym(i, j) / (c[(i, i)].sqrt() * c[(j, j)].sqrt())).clamp(-1.0, 1.0)
            }
        });
        Self {
            covariance: Some(CovarianceReport {
                coordinates: "physical",
                parameters: names.to_vec(),
                matrix: rows(&sym),
            }),
            correlation: Some(CorrelationReport { parameters: names.to_vec(), matrix: correlation }),
        }
    }
}

/// What the screened search for other solutions did with its starts (`search` in the report).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SearchReport {
    /// Starts ranked by misfit: the design's and the exchanged points of asymmetric exchanges.
    pub ranked: usize,
    /// Starts fitted locally (the best by misfit).
    pub fitted: usize,
    /// Local fits abandoned: not within `reach_delta_chi2` of the estimate after a few
    /// evaluations. They tested nothing: no claim rests on them.
    pub abandoned: usize,
    /// Δχ² above the estimate within which a local fit had to come (`null` when σ is unknown).
    pub reach_delta_chi2: Option<f64>,
    /// Evaluations after which the search starts no further batch of local fits (`null`: no cap
    /// but the task's budget): on a model whose evaluation takes seconds, as many as the fit
    /// took. The first batch runs whatever the ranking cost, and a batch once started ends.
    pub most_evaluations: Option<usize>,
    /// Starts kept by the ranking but not fitted because `most_evaluations` were spent.
    pub not_fitted: usize,
}

impl SearchReport {
    /// What `found` did with the starts `screening` ranked and `extra` exchanged points.
    pub fn of(
        found: &eigenfit_core::analysis::alternatives::Search,
        screening: &eigenfit_core::analysis::alternatives::Screening,
        extra: usize,
    ) -> Self {
        Self {
            ranked: screening.starts + extra,
            fitted: found.fitted,
            abandoned: found.abandoned,
            reach_delta_chi2: found.reach_delta_chi2,
            most_evaluations: screening.most_evaluations,
            not_fitted: found.not_fitted,
        }
    }

    /// The notes that say local fits were abandoned or not made, and what that means.
    pub fn note(&self) -> Vec<String> {
        let mut notes = Vec::new();
        if let Some(most) = self.most_evaluations {
            notes.push(format!(
                "one evaluation of this model takes seconds, so the search for other solutions was proportioned to \
                 the fit: it ranked {} starts and fitted {} of them locally, the first {} whatever they cost and further \
                 ones only while it had spent fewer evaluations than the fit ({most}){}; --alternative-starts N fits N \
                 starts in full",
                self.ranked,
                self.fitted,
                eigenfit_core::analysis::alternatives::FITS_AT_ONCE,
                if self.not_fitted > 0 { format!("; {} more were left unfitted", self.not_fitted) } else { String::new() },
            ));
        }
        if self.abandoned > 0 {
            notes.push(format!(
                "the search for other solutions abandoned {} of its {} local fits: after {} evaluations each was \
                 still more than Δχ² {} above the estimate; they tested nothing, so the search supports no claim \
                 about the regions they started from",
                self.abandoned,
                self.fitted,
                eigenfit_core::analysis::alternatives::REACH_EVALUATIONS,
                self.reach_delta_chi2.map_or_else(|| "?".into(), |d| format!("{d:.1}")),
            ));
        }
        notes
    }
}
