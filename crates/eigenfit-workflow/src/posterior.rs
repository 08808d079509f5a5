//! Bayesian updating: a sampler's posterior of a model's parameters given measured frequencies
//! with standard deviations, and its report (`estimate --strategy tmcmc --json`'s `posterior`).
//!
//! The prior is uniform in each parameter's scaled coordinate (ln p for `scale = "log"`, p for
//! linear) between its bounds; the likelihood is Gaussian in Hz with the measured `std_hz`,
//! normalised, so `log_evidence` compares models.

use crate::error::{input, WorkflowError};
use crate::named::Named;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::measurement::Measurement;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::{Objective, Problem, ResidualError, ResidualKind};
use eigenfit_core::update::{Budget, Gaussian, Posterior, Sampler, UpdateError};
use serde::Serialize;

/// The posterior part of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PosteriorReport {
    /// The sampler, with its settings as named.
    pub sampler: String,
    /// The seed of its random numbers (the same seed gives the same samples).
    pub seed: u64,
    /// One row per sample, values in the order of the report's `parameters` keys as the JSON
    /// prints them (sorted by name: every JSON object's keys are), in the parameters' units.
    pub samples: Vec<Vec<f64>>,
    /// The parameter of each column of `samples`.
    pub columns: Vec<String>,
    /// Posterior means.
    pub mean: Named<f64>,
    /// Posterior standard deviations.
    pub std: Named<f64>,
    /// 2.5 % and 97.5 % posterior quantiles.
    pub credible_95: Named<[f64; 2]>,
    /// The sample of highest likelihood.
    pub best_sample: Named<f64>,
    /// ln of the evidence p(data | model): the normalised Gaussian likelihood averaged over the
    /// prior.
    pub log_evidence: f64,
    /// Tempering stages from prior to posterior.
    pub stages: usize,
    /// Fraction of Metropolis proposals accepted.
    pub acceptance: f64,
    /// Model evaluations the sampling spent.
    pub evaluations: usize,
}

impl PosteriorReport {
    /// The report of `post` for parameters `names`.
    pub fn new(names: &[String], sampler: &str, seed: u64, post: &Posterior, evaluations: usize) -> Self {
        // The JSON's objects list their keys sorted (serde_json's map): the columns follow.
        let mut order: Vec<usize> = (0..names.len()).collect();
        order.sort_by(|&a, &b| names[a].cmp(&names[b]));
        Self {
            sampler: sampler.to_string(),
            seed,
            samples: post.samples.iter().map(|row| order.iter().map(|&i| row[i]).collect()).collect(),
            columns: order.iter().map(|&i| names[i].clone()).collect(),
            mean: Named::new(names, post.mean.iter().copied()),
            std: Named::new(names, post.std.iter().copied()),
            credible_95: Named::new(names, post.credible_95.iter().copied()),
            best_sample: Named::new(names, post.best_sample().unwrap_or(&post.mean).iter().copied()),
            log_evidence: post.log_evidence,
            stages: post.stages.len() - 1,
            acceptance: post.acceptance,
            evaluations,
        }
    }
}

/// How sampling ended when it gave no posterior.
#[derive(Debug)]
pub enum SamplingError {
    /// The budget ran out first.
    BudgetExhausted {
        /// The budget's limit.
        limit: usize,
    },
    /// Bad input or a sampler that could not proceed (the message says why).
    Failed(WorkflowError),
}

/// Samples the posterior of `model`'s parameters given `measured` (every mode with a `std_hz`)
/// with `sampler`, charging `budget`. `measured_name` names the data in messages.
pub fn sample(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    measured: &Measurement,
    measured_name: &str,
    sampler: &dyn Sampler,
    seed: u64,
    budget: &Budget,
) -> Result<Posterior, SamplingError> {
    let sigma: Vec<Option<f64>> = measured.modes().iter().map(|m| m.std_hz).collect();
    let problem = Problem::new(model, solver, measured.clone()).with_kind(ResidualKind::FrequencyHz);
    sample_objective(&problem, &sigma, measured_name, sampler, seed, budget)
}

/// [`sample`] on any objective whose residual rows are (f_measured − f_model)/σ in Hz with the
/// row's `sigma_hz` (a run-up's, [`crate::bench_runup`]).
pub fn sample_objective(
    problem: &dyn Objective,
    sigma_hz: &[Option<f64>],
    measured_name: &str,
    sampler: &dyn Sampler,
    seed: u64,
    budget: &Budget,
) -> Result<Posterior, SamplingError> {
    let likelihood = Gaussian::hz(sigma_hz).ok_or_else(|| {
        SamplingError::Failed(input(format!(
            "{measured_name}: the {} likelihood is Gaussian in Hz with the measured standard deviations: \
             every mode needs a std_hz greater than zero (a column `std_hz`)",
            sampler.name()
        )))
    })?;
    sampler.sample(problem, &likelihood, seed, budget).map_err(|e| match e {
        UpdateError::Residual(ResidualError::BudgetExhausted { limit }) => {
            SamplingError::BudgetExhausted { limit }
        }
        other => SamplingError::Failed(input(format!("{}: {other}", sampler.name()))),
    })
}
