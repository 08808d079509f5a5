//! Monte Carlo studies: many noisy realisations of a model's own frequencies, each estimated by
//! damped least squares and its 95 % intervals checked against the truth — in parallel (rayon),
//! with results identical to the serial run.
//!
//! Trial i draws its noise from its own generator, seeded from the study's seed and i alone, so
//! no trial depends on which thread ran it or on the others.

use crate::analysis::statistics::{uncertainty_refit_serial, UNCERTAINTY_EVALUATIONS};
use crate::eigen::EigenSolver;
use crate::measurement::{synthetic::synthesise, synthetic::NoiseRng};
use crate::model::StructuralModel;
use crate::problem::Problem;
use crate::update::refit::{RefitChoice, RefitRequest};
use crate::update::Budget;
use rayon::prelude::*;

/// What a study simulates and how each trial is estimated.
#[derive(Debug, Clone, PartialEq)]
pub struct StudySettings {
    /// Number of noisy realisations.
    pub trials: usize,
    /// Seed of the study; trial i uses a generator derived from it and i.
    pub seed: u64,
    /// Lowest modes measured.
    pub modes: usize,
    /// Standard deviation of each frequency relative to it (e.g. 1e-3 for 0.1 %).
    pub relative_std: f64,
    /// Initial guess of every estimate.
    pub initial: Vec<f64>,
    /// Iteration limit of every estimate.
    pub max_iterations: usize,
    /// The strategy of every trial's fit (with its restarts) and of its intervals' profile
    /// refits: damped least squares by default, any registered one by name.
    pub refit: RefitChoice,
}

/// One trial's estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialEstimate {
    /// Estimated parameters.
    pub parameters: Vec<f64>,
    /// Whether the damped run converged.
    pub converged: bool,
    /// Iterations taken.
    pub iterations: usize,
    /// χ² of the fit.
    pub chi2: f64,
    /// 95 % intervals per parameter, when the uncertainty could be computed.
    pub intervals: Option<Vec<[f64; 2]>>,
}

/// One realisation: its noise seed and the estimate, or why there is none.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// Seed of this trial's noise.
    pub seed: u64,
    /// The estimate, or the error that prevented it (data synthesis, model, estimation).
    pub outcome: Result<TrialEstimate, String>,
}

/// The trials of a study, in trial order.
#[derive(Debug, Clone, PartialEq)]
pub struct Study {
    /// The parameters the data were simulated at.
    pub truth: Vec<f64>,
    /// Every trial, in order.
    pub trials: Vec<Trial>,
}

impl Study {
    /// Trials whose estimate converged.
    pub fn converged(&self) -> usize {
        self.estimates().filter(|e| e.converged).count()
    }

    /// Per parameter, the fraction of trials with intervals whose interval covers the truth.
    pub fn coverage(&self) -> Vec<f64> {
        (0..self.truth.len()).map(|i| self.rate(|hits| hits[i])).collect()
    }

    /// The fraction of trials with intervals whose intervals cover every parameter at once.
    pub fn joint_coverage(&self) -> f64 {
        self.rate(|hits| hits.iter().all(|&h| h))
    }

    fn estimates(&self) -> impl Iterator<Item = &TrialEstimate> {
        self.trials.iter().filter_map(|t| t.outcome.as_ref().ok())
    }

    fn rate(&self, counts: impl Fn(&[bool]) -> bool) -> f64 {
        let hits: Vec<Vec<bool>> = self
            .estimates()
            .filter_map(|e| e.intervals.as_ref())
            .map(|iv| iv.iter().zip(&self.truth).map(|(b, t)| b[0] <= *t && *t <= b[1]).collect())
            .collect();
        if hits.is_empty() {
            return f64::NAN;
        }
        hits.iter().filter(|h| counts(h)).count() as f64 / hits.len() as f64
    }
}

/// Runs the study in parallel; the result equals [`run_serial`]'s.
///
/// ```
/// use eigenfit_core::analysis::{monte_carlo::StudySettings, monte_carlo::run};
/// # use eigenfit_core::eigen::DenseSolver;
/// # use eigenfit_core::matrix::System;
/// # use eigenfit_core::model::{ModelError, Parameter, ParameterSet, StructuralModel};
/// # use nalgebra::DMatrix;
/// # struct Spring(ParameterSet);
/// # impl StructuralModel for Spring {
/// #     fn parameters(&self) -> &ParameterSet { &self.0 }
/// #     fn dofs(&self) -> usize { 1 }
/// #     fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
/// #         Ok(System::new(DMatrix::from_element(1, 1, p[0]), DMatrix::identity(1, 1))?)
/// #     }
/// # }
/// # let spring = Spring(ParameterSet::new(vec![Parameter::new("k", "N/m", 4.0)])?);
/// let settings = StudySettings {
///     trials: 200, seed: 1, modes: 1, relative_std: 1e-3, initial: vec![1.0], max_iterations: 100,
///     refit: Default::default(),
/// };
/// let study = run(&spring, &DenseSolver, &[4.0], &settings);
/// assert_eq!(study.converged(), 200);
/// assert!((0.9..=0.99).contains(&study.coverage()[0]));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run<M, S>(model: &M, solver: &S, truth: &[f64], settings: &StudySettings) -> Study
where
    M: StructuralModel + Sync + ?Sized,
    S: EigenSolver + ?Sized,
{
    let trials =
        (0..settings.trials).into_par_iter().map(|i| trial(model, solver, truth, settings, i)).collect();
    Study { truth: truth.to_vec(), trials }
}

/// Runs the study on the calling thread.
pub fn run_serial<M, S>(model: &M, solver: &S, truth: &[f64], settings: &StudySettings) -> Study
where
    M: StructuralModel + ?Sized,
    S: EigenSolver + ?Sized,
{
    let trials = (0..settings.trials).map(|i| trial(model, solver, truth, settings, i)).collect();
    Study { truth: truth.to_vec(), trials }
}

/// The seed of trial `index`: a SplitMix64 step from the study's seed, so neighbouring trials get
/// unrelated streams.
fn trial_seed(seed: u64, index: usize) -> u64 {
    NoiseRng(seed ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03)).uniform().to_bits()
}

fn trial<M, S>(model: &M, solver: &S, truth: &[f64], settings: &StudySettings, index: usize) -> Trial
where
    M: StructuralModel + ?Sized,
    S: EigenSolver + ?Sized,
{
    let seed = trial_seed(settings.seed, index);
    let outcome = (|| {
        let mut noise = NoiseRng(seed);
        let data = synthesise(model, solver, truth, settings.modes, settings.relative_std, Some(&mut noise))
            .map_err(|e| e.to_string())?;
        let problem = Problem::new(model, solver, data);
        let request = RefitRequest { restarts: true, ..RefitRequest::default() };
        let est = settings
            .refit
            .refit(&problem, &settings.initial, &request, settings.max_iterations, &Budget::unlimited())
            .map_err(|e| e.to_string())?;
        let budget = Budget::new(UNCERTAINTY_EVALUATIONS);
        let intervals =
            uncertainty_refit_serial(&problem, &est.last, &budget, &*settings.refit).map(|u| u.intervals);
        Ok(TrialEstimate {
            chi2: est.last.chi2(),
            converged: est.termination.is_converged(),
            iterations: est.iterations,
            parameters: est.parameters,
            intervals,
        })
    })();
    Trial { seed, outcome }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::{BandedSolver, DenseSolver};
    use crate::test_chain::Chain;

    fn settings(trials: usize) -> StudySettings {
        StudySettings {
            trials,
            seed: 42,
            modes: 3,
            relative_std: 1e-3,
            initial: vec![1e4, 1e4],
            max_iterations: 200,
            refit: RefitChoice::default(),
        }
    }

    #[test]
    fn parallel_study_equals_serial_trial_by_trial() {
        let model = Chain::new(&[1.0, 2.0]);
        let truth = [3e3, 8e3];
        let s = StudySettings { modes: 2, ..settings(64) };
        for solver in [&DenseSolver as &dyn EigenSolver, &BandedSolver::default()] {
            let parallel = run(&model, solver, &truth, &s);
            assert_eq!(parallel, run_serial(&model, solver, &truth, &s), "{}", solver.name());
            assert_eq!(parallel.trials.len(), 64);
            assert_eq!(parallel.converged(), 64);
        }
    }

    /// The study's estimator chosen by name: the trust-region strategy's trials land where the
    /// damped ones do (each to its own tolerance), so the coverage is the same.
    #[test]
    fn a_study_runs_on_the_refit_strategy_it_is_given() {
        let model = Chain::new(&[1.0, 2.0]);
        let truth = [3e3, 8e3];
        let damped = run(&model, &DenseSolver, &truth, &StudySettings { modes: 2, ..settings(32) });
        let refit = RefitChoice(std::sync::Arc::new(crate::update::refit::Registered::new("trf").unwrap()));
        let trf = run(&model, &DenseSolver, &truth, &StudySettings { modes: 2, refit, ..settings(32) });
        assert_eq!(trf.converged(), 32);
        for (a, b) in damped.trials.iter().zip(&trf.trials) {
            let (a, b) = (a.outcome.as_ref().unwrap(), b.outcome.as_ref().unwrap());
            for (x, y) in a.parameters.iter().zip(&b.parameters) {
                assert!((x / y - 1.0).abs() < 1e-6, "{:?} against {:?}", a.parameters, b.parameters);
            }
        }
        assert_eq!(damped.coverage(), trf.coverage());
    }

    #[test]
    fn trials_have_their_own_reproducible_noise() {
        let seeds: Vec<u64> = (0..1000).map(|i| trial_seed(42, i)).collect();
        let mut unique = seeds.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), seeds.len());
        assert_eq!(trial_seed(42, 7), seeds[7]);
        assert_ne!(trial_seed(43, 7), seeds[7]);
    }

    #[test]
    fn failures_are_reported_per_trial_not_raised() {
        let model = Chain::new(&[1.0, 2.0]);
        // Asking for more modes than the model has fails every trial with its reason.
        let study = run(&model, &DenseSolver, &[3e3, 8e3], &settings(4));
        assert!(study.trials.iter().all(|t| t.outcome.as_ref().is_err_and(|e| !e.is_empty())));
        assert_eq!(study.converged(), 0);
        assert!(study.coverage()[0].is_nan());
    }
}
