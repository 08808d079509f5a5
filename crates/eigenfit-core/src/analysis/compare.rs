//! Strategy comparison: targets × initial guesses × strategies on reference data synthesised
//! from the model itself (the paper's Tables 2–5 and convergence maps).

use crate::analysis::alternatives::{local_minima, other_solutions, search_starts};
use crate::analysis::{uncertainty_within, Identifiability};
use crate::eigen::EigenSolver;
use crate::measurement::synthetic::SynthesisError;
use crate::measurement::{MeasuredMode, Measurement};
use crate::model::StructuralModel;
use crate::problem::{Linearisation, Objective, Problem};
use crate::update::registry::{build_local, Registry, StrategyError};
use crate::update::{Budget, Driver, LevenbergMarquardt, Outcome, TerminationReport};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;
use thiserror::Error;

/// Most evaluations the one-off search for the data's local minima may spend (shared by every
/// run of a grid).
const SEARCH_EVALUATIONS: usize = 5_000;

/// The strategies a comparison runs when none are named: the paper's two and the damped one.
pub const DEFAULT_STRATEGIES: [&str; 3] = ["newton", "p-step", "damped"];

/// How the reference data are made: `modes`, `decimals`, `std_hz`, as a comparison's report
/// states them (flattened into it).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ReferenceSettings {
    /// Number of lowest modes measured (the paper: as many as parameters).
    pub modes: usize,
    /// Round reference frequencies to this many decimals (the paper's Table 1: 3), or exact.
    pub decimals: Option<i32>,
    /// Standard deviation attached to each reference frequency (Hz), enabling intervals and
    /// identifiability flags for the damped strategy.
    pub std_hz: Option<f64>,
}

/// How the reference data are made and how each run is limited.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareSettings {
    /// Modes, rounding and standard deviation of the reference data.
    pub reference: ReferenceSettings,
    /// Iteration limit per run.
    pub max_iterations: usize,
    /// Most model evaluations (eigen-solves) one run may spend on its fit and, for a damped run,
    /// its intervals ([`Budget`]); a run that hits it ends `budget-exhausted`.
    pub budget: usize,
}

/// One run of the comparison. Serialises as the `compare` report's run (the fields a report
/// shows as they are; the strategy, time and statistics are reported by name or on request).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CompareRun {
    /// Strategy, as the registry names it (with any settings: `damped:max_trials=50`).
    #[serde(skip)]
    pub strategy: String,
    /// True parameters.
    pub target: Vec<f64>,
    /// Initial guess.
    pub initial: Vec<f64>,
    /// Converged, termination reason as text, iterations, model evaluations (eigen-solves,
    /// including rejected trials).
    #[serde(flatten)]
    pub outcome: Outcome,
    /// Final parameters.
    pub estimate: Vec<f64>,
    /// max |estimate / target − 1| over the parameters.
    pub relative_error: f64,
    /// Wall-clock time of the run (s); for reports, never for tests.
    #[serde(skip)]
    pub seconds: f64,
    /// Per parameter, whether the data determine it (converged runs with `std_hz` only).
    #[serde(skip)]
    pub identifiability: Option<Vec<Identifiability>>,
    /// Other parameter vectors that fit the data equally well (converged runs, any strategy):
    /// when not empty, the data cannot choose between them and the estimate.
    #[serde(skip)]
    pub alternatives: Vec<Vec<f64>>,
    /// True when the run's budget ([`CompareSettings::budget`]) ran out: its fit or its
    /// identifiability flags are incomplete. Written only when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub budget_exhausted: bool,
}

/// Why a comparison grid could not be run.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CompareError {
    /// The reference data of a target could not be computed.
    #[error(transparent)]
    Reference(#[from] SynthesisError),
    /// A strategy name the registry cannot build, or a sampler.
    #[error(transparent)]
    Strategy(#[from] StrategyError),
    /// A worker thread panicked (a bug; the other runs are lost with it).
    #[error("a comparison run panicked")]
    RunPanicked,
}

/// Modes solved beyond those asked for, for the reference data to skip a free structure's
/// rigid-body modes (six per free body in space).
const RIGID_BODY_SPARE: usize = 6;

/// Reference data: the lowest `modes` elastic frequencies of `model` at `target` (rigid-body
/// modes skipped), optionally rounded.
pub fn reference_measurement<M, S>(
    model: &M,
    solver: &S,
    target: &[f64],
    settings: &CompareSettings,
) -> Result<Measurement, SynthesisError>
where
    M: StructuralModel + ?Sized,
    S: EigenSolver + ?Sized,
{
    // A free structure's rigid-body modes (zero to round-off) are no measured frequency: the
    // reference is its lowest elastic modes, numbered as the model numbers them (a free-free
    // model's comparison failed every run on a 0 Hz 'mode 1').
    let system = model.assemble(target)?;
    let wanted = settings.reference.modes;
    let solved = solver.lowest(&system, (wanted + RIGID_BODY_SPARE).min(system.dofs()))?;
    let rigid = crate::eigen::roundoff::rigid_body_modes(&system, &solved).unwrap_or_default();
    let round = |f: f64| match settings.reference.decimals {
        Some(d) => (f * 10f64.powi(d)).round() / 10f64.powi(d),
        None => f,
    };
    let measured = solved
        .frequencies_hz()
        .into_iter()
        .enumerate()
        .filter(|(k, _)| !rigid.get(*k).copied().unwrap_or(false))
        .take(wanted)
        .map(|(k, f)| MeasuredMode {
            mode: k,
            frequency_hz: round(f),
            std_hz: settings.reference.std_hz,
            shape: None,
        })
        .collect();
    Ok(Measurement::new(measured)?)
}

/// What every run on the same reference data shares, computed once: the coarse grid of restart
/// seeds ranked by residual (for strategies that restart from them) and the local solutions of
/// the data (for the check for alternative solutions). Both depend on the data only, not on the
/// initial guess.
pub struct SharedData {
    seeds: Arc<Vec<Vec<f64>>>,
    solutions: Vec<Linearisation>,
}

impl SharedData {
    /// Finds the local solutions of `problem`'s data and, when `rank_seeds`, ranks the
    /// restart seeds.
    pub fn new(problem: &(dyn Objective + Sync), rank_seeds: bool) -> Self {
        Self {
            seeds: if rank_seeds { LevenbergMarquardt::rank_seeds(problem) } else { Arc::new(Vec::new()) },
            solutions: local_minima(
                problem,
                search_starts(problem.parameters().len()),
                &[],
                &Budget::new(SEARCH_EVALUATIONS),
            ),
        }
    }

    /// What runs of `strategies` (registry names) on `problem` share: the local solutions, and
    /// the ranked seeds when one of them restarts from ranked starts.
    pub fn for_runs(
        problem: &(dyn Objective + Sync),
        registry: &Registry,
        strategies: &[String],
    ) -> Result<Self, StrategyError> {
        let mut rank = false;
        for spec in strategies {
            rank |= build_local(registry, spec)?.1.uses_ranked_starts();
        }
        Ok(Self::new(problem, rank))
    }
}

/// Checks that every name in `strategies` builds a strategy that runs from a start, and returns
/// the names as the registry reports them (aliases replaced, settings kept).
pub fn checked_strategies(registry: &Registry, strategies: &[String]) -> Result<Vec<String>, StrategyError> {
    strategies.iter().map(|spec| build_local(registry, spec).map(|(name, _)| name)).collect()
}

/// Runs one strategy (a registry name, checked by [`checked_strategies`]) from one initial guess
/// against reference data made at `target`. A strategy that restarts from ranked starts uses
/// `shared`'s, so its `evaluations` leave out the one-off ranking of the grid. Every converged
/// run, whatever its strategy, gets the same identifiability flags and check for other
/// solutions: a comparison judges the answers, not who found them.
pub fn run_case<M, S>(
    problem: &Problem<M, S>,
    shared: &SharedData,
    registry: &Registry,
    target: &[f64],
    initial: &[f64],
    strategy: &str,
    settings: &CompareSettings,
) -> CompareRun
where
    M: StructuralModel,
    S: EigenSolver,
{
    let start = Instant::now();
    let budget = Budget::new(settings.budget);
    let outcome = build_local(registry, strategy).map_err(|e| e.to_string()).and_then(|(_, mut s)| {
        if s.uses_ranked_starts() && !shared.seeds.is_empty() {
            s.share_ranked_starts(shared.seeds.clone());
        }
        Driver { max_iterations: settings.max_iterations }
            .run_within(problem, s.as_mut(), initial, &budget)
            .map_err(|e| e.to_string())
    });
    let seconds = start.elapsed().as_secs_f64();
    let strategy = strategy.to_string();
    match outcome {
        Ok(est) => {
            let converged = est.termination.is_converged();
            let identifiability = converged
                .then(|| uncertainty_within(problem, &est.last, &budget))
                .flatten()
                .map(|u| u.identifiability);
            let alternatives = if converged {
                other_solutions(problem, &est.last, &shared.solutions)
                    .into_iter()
                    .filter(|s| s.judged.equally_good)
                    .map(|s| s.parameters)
                    .collect()
            } else {
                Vec::new()
            };
            CompareRun {
                alternatives,
                strategy,
                target: target.to_vec(),
                initial: initial.to_vec(),
                outcome: Outcome::of(&est, converged),
                relative_error: relative_error(&est.parameters, target),
                estimate: est.parameters,
                seconds,
                identifiability,
                budget_exhausted: budget.exhausted(),
            }
        }
        Err(e) => CompareRun {
            strategy,
            target: target.to_vec(),
            initial: initial.to_vec(),
            outcome: Outcome {
                converged: false,
                termination: TerminationReport::new("failed", "setup", e),
                iterations: 0,
                evaluations: 0,
            },
            estimate: initial.to_vec(),
            relative_error: relative_error(initial, target),
            seconds,
            identifiability: None,
            alternatives: Vec::new(),
            budget_exhausted: budget.exhausted(),
        },
    }
}

/// Every combination of targets × initial guesses × strategies, in that nesting order, run in
/// parallel (rayon); `on_run` sees each finished run on the calling thread, in the order the runs
/// finish (progress, streaming output). The result is identical to [`run_grid_serial`]'s but for
/// the wall-clock `seconds` of each run.
pub fn run_grid<M, S>(
    model: &M,
    solver: &S,
    targets: &[Vec<f64>],
    initials: &[Vec<f64>],
    strategies: &[String],
    settings: &CompareSettings,
    mut on_run: impl FnMut(&CompareRun),
) -> Result<Vec<CompareRun>, CompareError>
where
    M: StructuralModel + Sync,
    S: EigenSolver + Sync,
{
    let registry = crate::update::registry::registry();
    let strategies = checked_strategies(&registry, strategies)?;
    let problems = targets
        .iter()
        .map(|target| {
            Ok(Problem::new(model, solver, reference_measurement(model, solver, target, settings)?))
        })
        .collect::<Result<Vec<_>, CompareError>>()?;
    let shared = problems
        .iter()
        .map(|p| SharedData::for_runs(p, &registry, &strategies))
        .collect::<Result<Vec<_>, _>>()?;
    let strategies = &strategies;
    let cases: Vec<(usize, &Vec<f64>, &str)> = (0..targets.len())
        .flat_map(|t| initials.iter().flat_map(move |i| strategies.iter().map(move |s| (t, i, s.as_str()))))
        .collect();
    let registry = &registry;
    let (sender, receiver) = std::sync::mpsc::channel::<CompareRun>();
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            cases
                .par_iter()
                .map_with(sender, |sender, &(t, initial, strategy)| {
                    let run = run_case(
                        &problems[t],
                        &shared[t],
                        registry,
                        &targets[t],
                        initial,
                        strategy,
                        settings,
                    );
                    // The receiver lives until every run is sent; a failed send only loses progress.
                    let _ = sender.send(run.clone());
                    run
                })
                .collect::<Vec<_>>()
        });
        for run in receiver {
            on_run(&run);
        }
        worker.join().map_err(|_| CompareError::RunPanicked)
    })
}

/// [`run_grid`] on the calling thread only, one run after another.
pub fn run_grid_serial<M, S>(
    model: &M,
    solver: &S,
    targets: &[Vec<f64>],
    initials: &[Vec<f64>],
    strategies: &[String],
    settings: &CompareSettings,
    mut on_run: impl FnMut(&CompareRun),
) -> Result<Vec<CompareRun>, CompareError>
where
    M: StructuralModel + Sync,
    S: EigenSolver,
{
    let registry = crate::update::registry::registry();
    let strategies = checked_strategies(&registry, strategies)?;
    let mut runs = Vec::with_capacity(targets.len() * initials.len() * strategies.len());
    for target in targets {
        let measured = reference_measurement(model, solver, target, settings)?;
        let problem = Problem::new(model, solver, measured);
        let shared = SharedData::for_runs(&problem, &registry, &strategies)?;
        for initial in initials {
            for strategy in &strategies {
                let run = run_case(&problem, &shared, &registry, target, initial, strategy, settings);
                on_run(&run);
                runs.push(run);
            }
        }
    }
    Ok(runs)
}

/// `n` log-spaced values from `lo` to `hi` inclusive.
pub fn log_space(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![lo];
    }
    let (a, b) = (lo.log10(), hi.log10());
    (0..n).map(|i| 10f64.powf(a + (b - a) * i as f64 / (n - 1) as f64)).collect()
}

/// The full tensor grid of `axis` over `dims` parameters.
pub fn tensor_grid(axis: &[f64], dims: usize) -> Vec<Vec<f64>> {
    axes_grid(&vec![axis.to_vec(); dims])
}

/// Every combination of one value per axis (axis `i` gives parameter `i`; its own range and
/// count), the last parameter varying fastest as in [`tensor_grid`].
pub fn axes_grid(axes: &[Vec<f64>]) -> Vec<Vec<f64>> {
    crate::update::grid::tensor_product(axes, usize::MAX)
}

fn relative_error(estimate: &[f64], target: &[f64]) -> f64 {
    estimate.iter().zip(target).map(|(e, t)| (e / t - 1.0).abs()).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::DenseSolver;
    use crate::test_chain::Chain;

    #[test]
    fn parallel_grid_equals_serial_in_content_and_order() {
        let chain = Chain::new(&[1.0, 2.0, 1.5]);
        let targets = vec![vec![3e4, 1e4, 2e4], vec![1e3, 5e4, 1e4]];
        let initials = tensor_grid(&log_space(1e2, 1e6, 3), 3);
        let strategies: Vec<String> = DEFAULT_STRATEGIES.map(String::from).to_vec();
        let settings = CompareSettings {
            reference: ReferenceSettings { modes: 3, decimals: Some(3), std_hz: Some(0.01) },
            max_iterations: 100,
            budget: crate::update::DEFAULT_EVALUATIONS,
        };
        let mut seen = 0;
        let par = run_grid(&chain, &DenseSolver, &targets, &initials, &strategies, &settings, |_| seen += 1)
            .unwrap();
        let ser = run_grid_serial(&chain, &DenseSolver, &targets, &initials, &strategies, &settings, |_| {})
            .unwrap();
        assert_eq!(seen, par.len());
        assert_eq!(par.len(), 2 * 27 * strategies.len());
        let strip = |runs: Vec<CompareRun>| -> Vec<CompareRun> {
            runs.into_iter().map(|r| CompareRun { seconds: 0.0, ..r }).collect()
        };
        assert_eq!(strip(par), strip(ser));
    }
}
