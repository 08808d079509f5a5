//! Samplers: strategies that return a posterior distribution instead of one point.
//!
//! The prior is uniform in each parameter's scaled coordinate (ln p for a log parameter, p for a
//! linear one) between its bounds; the likelihood is the caller's ([`Gaussian`] for measured
//! frequencies with standard deviations).

use super::{Budget, UpdateError};
use crate::problem::{Objective, ResidualError};

/// ln L of the data at a point.
pub trait LogLikelihood {
    /// ln L at `p` on `problem`; −∞ where the model cannot be evaluated there (or the
    /// evaluation is refused).
    fn log_likelihood(&self, problem: &dyn Objective, p: &[f64]) -> f64;
}

/// Independent Gaussian errors on residuals given in noise units (r = (measured − model)/σ, as
/// a [`Problem`](crate::problem::Problem) with [`ResidualKind::FrequencyHz`](crate::problem::ResidualKind::FrequencyHz) and measured std
/// makes them), normalised: ln L = −½‖r‖² + `log_normaliser`, the objective's cost giving ½‖r‖².
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian {
    /// Σ −ln(σ√(2π)) over the measured values.
    pub log_normaliser: f64,
}

impl Gaussian {
    /// The normalised likelihood of frequencies with standard deviations `sigma_hz` (Hz);
    /// `None` when one is missing, not finite or not > 0.
    ///
    /// [`ResidualKind::FrequencyHz`]: crate::problem::ResidualKind::FrequencyHz
    pub fn hz(sigma_hz: &[Option<f64>]) -> Option<Self> {
        let norm = (2.0 * std::f64::consts::PI).sqrt();
        sigma_hz
            .iter()
            .map(|s| s.filter(|v| v.is_finite() && *v > 0.0).map(|s| -(s * norm).ln()))
            .sum::<Option<f64>>()
            .map(|log_normaliser| Self { log_normaliser })
    }
}

impl LogLikelihood for Gaussian {
    fn log_likelihood(&self, problem: &dyn Objective, p: &[f64]) -> f64 {
        problem.cost(p).filter(|c| c.is_finite()).map_or(f64::NEG_INFINITY, |c| self.log_normaliser - c)
    }
}

/// A posterior as samples, with its summaries. Values are in the parameters' own units.
#[derive(Debug, Clone, PartialEq)]
pub struct Posterior {
    /// The samples, one row per sample, one value per parameter.
    pub samples: Vec<Vec<f64>>,
    /// ln L at each sample.
    pub log_likelihood: Vec<f64>,
    /// Posterior mean of each parameter.
    pub mean: Vec<f64>,
    /// Posterior standard deviation of each parameter.
    pub std: Vec<f64>,
    /// The 2.5 % and 97.5 % quantiles of each parameter.
    pub credible_95: Vec<[f64; 2]>,
    /// ln of the evidence ∫ L π dθ.
    pub log_evidence: f64,
    /// The tempering exponents β of the stages, from 0 to 1.
    pub stages: Vec<f64>,
    /// Fraction of Metropolis proposals accepted, over all stages.
    pub acceptance: f64,
}

impl Posterior {
    /// The sample of highest likelihood (the posterior mode among the samples, the prior being
    /// uniform).
    pub fn best_sample(&self) -> Option<&[f64]> {
        self.log_likelihood
            .iter()
            .enumerate()
            .filter(|(_, l)| l.is_finite())
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| self.samples[i].as_slice())
    }

    /// The summaries (mean, std, 95 % quantiles) of `samples` in the parameters' units.
    pub fn summaries(samples: &[Vec<f64>], np: usize) -> (Vec<f64>, Vec<f64>, Vec<[f64; 2]>) {
        let n = samples.len().max(1) as f64;
        let mean: Vec<f64> = (0..np).map(|j| samples.iter().map(|s| s[j]).sum::<f64>() / n).collect();
        let std = (0..np)
            .map(|j| {
                (samples.iter().map(|s| (s[j] - mean[j]).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt()
            })
            .collect();
        let credible = (0..np)
            .map(|j| {
                let mut v: Vec<f64> = samples.iter().map(|s| s[j]).collect();
                v.sort_by(f64::total_cmp);
                [quantile(&v, 0.025), quantile(&v, 0.975)]
            })
            .collect();
        (mean, std, credible)
    }
}

/// The `q` quantile of sorted `v` (linear interpolation between order statistics).
fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let x = q * (v.len() - 1) as f64;
    let (i, t) = (x.floor() as usize, x - x.floor());
    let j = (i + 1).min(v.len() - 1);
    v[i] * (1.0 - t) + v[j] * t
}

/// Draws a posterior of the parameters of `problem`.
pub trait Sampler {
    /// Name for reports, e.g. `tmcmc`.
    fn name(&self) -> &'static str;
    /// The most model evaluations one run can spend (its own bound, used for default budgets).
    fn most_evaluations(&self) -> usize;
    /// Samples the posterior under `likelihood` and the uniform prior in the scaled coordinates
    /// between the bounds, charging every evaluation to `budget` (ending with
    /// [`ResidualError::BudgetExhausted`] when it runs out); the same `seed` gives the same
    /// samples.
    fn sample(
        &self,
        problem: &dyn Objective,
        likelihood: &dyn LogLikelihood,
        seed: u64,
        budget: &Budget,
    ) -> Result<Posterior, UpdateError>;
}

/// The error a sampler returns when `budget` has run out.
pub fn budget_exhausted(budget: &Budget) -> UpdateError {
    UpdateError::Residual(ResidualError::BudgetExhausted { limit: budget.limit() })
}
