//! `estimate`: update a model's parameters to match measured frequencies (and shapes), with
//! the verdict, intervals, other equally good solutions and the updated model file.

use crate::error::{input, WorkflowError};
use crate::named::Named;
use crate::outcome::{
    cycles, phase_counts, Covariances, FitQualityReport, Outcome, PairedFrequencies, ParameterValues, Verdict,
};
pub use crate::outcome::{AlternativeSolution, ParameterIdentifiability, SearchReport};
use crate::overrides::{fixed, parameter_vector};
use crate::posterior::{PosteriorReport, SamplingError};
use crate::progress::{Progress, StepsObserver};
use crate::rotordynamics::{self, RunupEstimateReport};
use crate::simulate::check_roundoff_of;
use crate::source::ModelSource;
use crate::test_data::{self, updated_model_toml, Fit, ShapeReport, TestData, TestDataOptions};
use eigenfit_core::analysis::alternatives::{
    adopt_better_minimum, better_minimum, default_screening, like_exchanges, listed_alternatives,
    local_minima_refit, mirror_solutions, screened_search, search_starts, Equivalence, Mirrors,
};
use eigenfit_core::analysis::verdict::{at_limits, check_reachable, check_softest, judge, FitQuality};
use eigenfit_core::analysis::{Identifiability, Rank, Uncertainty};
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::measurement::mac::MacReport;
use eigenfit_core::measurement::measured_csv::{shown, shown_number};
use eigenfit_core::measurement::Measurement;
use eigenfit_core::model::{ParameterSet, StructuralModel};
use eigenfit_core::problem::{Objective, Problem, ResidualKind};
use eigenfit_core::update::refit::{RefitChoice, Registered};
use eigenfit_core::update::{registry, Budget, Driver, Estimate, LevenbergMarquardt, Method, UpdateStrategy};
use serde::Serialize;
use std::path::PathBuf;

/// Refuses measured frequencies that one unit slip explains (every one entered in kHz, say:
/// [`check_softest`]'s slip), naming `file`: what estimate refuses before any fit, for the
/// configurations of a campaign too.
pub fn refuse_unit_slip(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    measurement: &Measurement,
    file: &str,
) -> Result<(), WorkflowError> {
    let numbers: Vec<usize> = measurement.modes().iter().map(|m| m.mode + 1).collect();
    match check_softest(model, solver, measurement, &numbers) {
        Some(e) if e.slip.is_some() => Err(input(format!("{file}: {e}"))),
        _ => Ok(()),
    }
}

/// The refit strategy `--refit SPEC` names (damped least squares without it), checked before
/// anything is read: an unknown name, a bad setting or a sampler is bad input.
pub fn refit_choice(spec: Option<&str>) -> Result<RefitChoice, WorkflowError> {
    match spec {
        None => Ok(RefitChoice::default()),
        Some(spec) => Registered::new(spec)
            .map(|r| RefitChoice(std::sync::Arc::new(r)))
            .map_err(|e| input(format!("--refit {}: {e}", shown(spec)))),
    }
}

/// Starts of the search for other solutions when not given: a space-filling design sized to the
/// free parameters ([`search_starts`]: 4 per parameter and 8 more).
pub fn default_alternative_starts(free: usize) -> usize {
    search_starts(free)
}

/// What to estimate, as the command line gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateRequest {
    /// The model and solver.
    pub source: ModelSource,
    /// Measured data: frequency CSV, universal file, or (ROSS rotor) a run-up CSV.
    pub measured: PathBuf,
    /// Shapes, sensors and held parameters.
    pub test_data: TestDataOptions,
    /// Update strategy by its registered name, with settings after colons (`damped`, `trf`,
    /// `tmcmc:chain=5`, …; [`registry`]).
    pub strategy: String,
    /// A sampler's (`tmcmc`) number of posterior samples (`None`: its default); refused for
    /// other strategies.
    pub samples: Option<usize>,
    /// A sampler's random seed.
    pub seed: u64,
    /// Initial values `K1,K2,…` (default: the model's).
    pub initial: Option<String>,
    /// Residual: relative, hz or eigenvalue.
    pub residual: String,
    /// Iteration limit.
    pub max_iterations: usize,
    /// Most model evaluations the fit, its intervals and the search for other solutions spend.
    pub budget: usize,
    /// Also build the updated model file (rotor TOML).
    pub write_model: bool,
    /// Starts of the space-filling design refitted locally when searching for other minima
    /// (0: no such search; the exchange of like parameters is still checked; `None`: sized to the
    /// free parameters, [`default_alternative_starts`]). On a large model most of a run's
    /// evaluations.
    pub alternative_starts: Option<usize>,
    /// ROSS rotors: the bearing coefficients to estimate (`kxx,kyy,…` or `kxy_<bearing>`; `None`:
    /// kxx and kyy of every bearing). Refused for other models.
    pub bearing_parameters: Option<String>,
    /// The strategy of the local refits behind the intervals (profile likelihood) and the search
    /// for other solutions: a registered name with settings after colons, run as registered
    /// (`None`: damped least squares without restarts). Lets a user's own strategy be the one
    /// the analysis trusts; refused for ROSS run-ups.
    pub refit: Option<String>,
}

pub use crate::outcome::BudgetReport;

/// One iteration of the fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistoryRecord {
    /// Iteration number.
    pub iteration: usize,
    /// Parameters.
    pub parameters: Vec<f64>,
    /// Model frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Largest |model − measured| (Hz).
    pub max_abs_diff_hz: f64,
    /// `true` on the last record when it is not an iteration of the fit but the deeper minimum
    /// the search for other solutions found, which the estimate took (absent otherwise).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub from_search: bool,
}

/// The intervals part of an estimate report: every key present, `null` when not computed (a
/// run that did not converge, or no std and no residual scatter to estimate σ from).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IntervalsReport {
    /// 95 % intervals.
    pub intervals: Option<Named<[f64; 2]>>,
    /// Identifiability per parameter.
    pub identifiable: Option<Named<ParameterIdentifiability>>,
    /// Singular values of the scaled Jacobian.
    pub singular_values: Option<Vec<f64>>,
    /// Their ratio.
    pub condition_number: Option<f64>,
    /// Standard deviations.
    pub standard_deviations: Option<Named<f64>>,
    /// Combinations of parameters the data barely tell apart (a linearised 95 % interval wider
    /// than a factor of 10 each way along them), in words ([`Uncertainty::poorly_determined`]).
    pub poorly_determined_directions: Option<Vec<String>>,
}

impl IntervalsReport {
    /// The report of `u` for parameters `names` (all `null` without one).
    pub fn new(names: &[String], u: Option<&Uncertainty>) -> Self {
        Self {
            intervals: u.map(|u| Named::new(names, u.intervals.iter().copied())),
            identifiable: u.map(|u| Named::new(names, u.identifiability.iter().map(Into::into))),
            singular_values: u.map(|u| u.singular_values.clone()),
            condition_number: u.map(|u| u.condition_number),
            standard_deviations: u
                .map(|u| Named::new(names, (0..names.len()).map(|i| u.covariance[(i, i)].sqrt()))),
            poorly_determined_directions: u.map(|u| Rank::said(&u.poorly_determined, names)),
        }
    }
}

/// `estimate`'s report (the `--json` object).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimateReport {
    /// The model's label.
    pub model: String,
    /// Strategy name.
    pub strategy: &'static str,
    /// Converged, why it stopped, iterations, model evaluations of the fit.
    #[serde(flatten)]
    pub outcome: Outcome,
    /// Converged, fit not poor, no parameter on a limit, budget not spent, every mode paired; the
    /// verdict in words.
    #[serde(flatten)]
    pub verdict: Verdict,
    /// χ², dof, p-value, relative RMS and the measured mode numbers that disagree by > 3σ.
    #[serde(flatten)]
    pub fit: FitQualityReport<usize>,
    /// The evaluation budget.
    pub budget: BudgetReport,
    /// Evaluations spent in each phase reached: reachability, fit, intervals,
    /// mirror_solutions, other_solutions (on a large model each is an eigen-solve of seconds).
    pub evaluations_by_phase: Named<usize>,
    /// The data counted and what they determine: the rank of their weighted Jacobian at the
    /// estimate and the parameter directions they cannot tell apart.
    pub data_rank: DataRankReport,
    /// Initial and estimated values, and what the data say about each parameter, in words.
    #[serde(flatten)]
    pub values: ParameterValues,
    /// Parameters on a limit.
    pub at_limit: Vec<String>,
    /// Intervals and what the data determine (a converged run with std or scatter).
    #[serde(flatten)]
    pub uncertainty: IntervalsReport,
    /// Each parameter's unit as declared (empty when none was), by name.
    pub units: Named<String>,
    /// The parameters' covariance (physical coordinates) and correlation, `null` when not
    /// computed or not computable.
    #[serde(flatten)]
    pub covariances: Covariances,
    /// Other minima found and mirror points, each with its χ², Δχ² and the test's outcome.
    pub alternative_solutions: Vec<AlternativeSolution>,
    /// What the screened search for other solutions (above 8 free parameters) did with its
    /// starts; absent when the search was not screened.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub search: Option<SearchReport>,
    /// How σ was taken for the alternatives' test: `std` (given), `residuals` (estimated from the
    /// estimate's residuals), or `exact` (no σ: only fits at least as good as the estimate are
    /// equally good).
    pub alternatives_sigma: &'static str,
    /// A regularised strategy's λ and the rule that chose it (`--strategy tikhonov`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regularisation: Option<eigenfit_core::update::Regularisation>,
    /// A sampler's posterior (`--strategy tmcmc`); the fit and its verdict then start from the
    /// posterior's best sample.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior: Option<crate::posterior::PosteriorReport>,
    /// Model frequencies at the estimate and measured frequencies (Hz).
    #[serde(flatten)]
    pub frequencies: PairedFrequencies,
    /// The iterations.
    pub history: Vec<HistoryRecord>,
    /// Plot files written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Vec<String>>,
    /// Pairing, MAC and sensors.
    #[serde(flatten)]
    pub test_data: ShapeReport,
    /// Held parameters.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixed: Option<Named<f64>>,
}

/// The data an estimate counted and what they determine (the `data_rank` object).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DataRankReport {
    /// What was counted, in words: `3 measured frequencies + 3 × 6 shape components = 21 data`.
    pub counted: String,
    /// Data rows: frequencies and shape components.
    pub rows: usize,
    /// Free parameters.
    pub parameters: usize,
    /// The numerical rank of the weighted Jacobian of all the data at the estimate.
    pub rank: usize,
    /// The parameter directions the data do not see (null directions of that Jacobian, in
    /// scaled parameters), in words; empty at full rank.
    pub null_directions: Vec<String>,
}

impl DataRankReport {
    /// The report of `rank` for `rows` data (`counted` in words) and parameters `names`.
    pub fn new(counted: &str, rows: usize, rank: &Rank, names: &[String]) -> Self {
        Self {
            counted: counted.to_string(),
            rows,
            parameters: names.len(),
            rank: rank.rank,
            null_directions: Rank::said(rank.null_directions(), names),
        }
    }
}

/// The data rows of `modes` measured modes with shapes at `sensors` sensors (0: frequencies
/// alone), and what was counted in words.
pub fn counted_data(modes: usize, sensors: usize) -> (usize, String) {
    let rows = modes * (1 + sensors);
    let text = match sensors {
        0 if modes == 1 => "1 measured frequency".to_string(),
        0 => format!("{modes} measured frequencies"),
        s => format!("{modes} measured modes × (1 frequency + {s} shape components) = {rows} data"),
    };
    (rows, text)
}

/// An estimation: the report and what a front end needs beside it (tables, plots, files).
pub struct Estimation {
    /// The report.
    pub report: EstimateReport,
    /// The estimate with its history.
    pub estimate: Estimate,
    /// The fit quality.
    pub quality: FitQuality,
    /// The intervals.
    pub uncertainty: Option<Uncertainty>,
    /// The MAC report (shapes).
    pub mac: Option<MacReport>,
    /// The data read.
    pub data: TestData,
    /// The residual scatter the shape intervals were scaled by.
    pub scatter: Option<f64>,
    /// Whether the data carry standard deviations.
    pub has_std: bool,
    /// Measured mode numbers (from 1), in the data's order.
    pub mode_numbers: Vec<usize>,
    /// Per parameter: whether it sits on a limit.
    pub on_limit: Vec<bool>,
    /// The free parameters' units, each once, joined by `, ` (for a plot's axis drawing them
    /// all; empty when none declares one).
    pub unit: String,
    /// The largest measured standard deviation (Hz).
    pub sigma_max: Option<f64>,
    /// The exit verdict: converged, fit not poor, nothing on a limit, budget left, all paired, and
    /// no other solution equally good (the report's `acceptable` and `unique`).
    pub acceptable: bool,
    /// The updated model as TOML, when asked for (or why there is none).
    pub updated_model: Option<Result<String, WorkflowError>>,
}

/// What an estimation ended with.
pub enum EstimateOutcome {
    /// A two-plane (ROSS) rotor's bearing stiffnesses from run-up data.
    Runup(Box<RunupEstimateReport>),
    /// The budget ran out before the fit could start; nothing to report.
    BudgetExhaustedBeforeFit {
        /// The budget.
        limit: usize,
    },
    /// The fit and its report.
    Done(Box<Estimation>),
}

/// Refuses, before any fitting, measured modes numbered onto rigid-body modes of the model at
/// `p` (a free–free structure, a rotor without bearings: eigenvalues zero to round-off, see
/// [`crate::simulate::rigid_body_flags`]): no measured natural frequency pairs with one, and
/// its frequency sensitivity is undefined. The message names the measured modes, the model's
/// rigid-body modes and its first elastic one. A model that cannot be solved at `p` is left to
/// the fit, which says why.
pub fn refuse_rigid_body_pairing(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    measurement: &Measurement,
    measured_name: &str,
) -> Result<(), WorkflowError> {
    let count = measurement.modes_needed();
    let Ok(system) = model.assemble(p) else { return Ok(()) };
    let Ok(modes) = solver.lowest(&system, count) else { return Ok(()) };
    if crate::simulate::check_stable(model, &system, &modes, p).is_err() {
        return Ok(());
    }
    let rigid = crate::simulate::rigid_body_flags(solver, &system, &modes)?;
    let on_rigid: Vec<&eigenfit_core::measurement::MeasuredMode> =
        measurement.modes().iter().filter(|m| rigid.get(m.mode).copied().unwrap_or(false)).collect();
    if on_rigid.is_empty() {
        return Ok(());
    }
    let numbers = crate::simulate::rigid_numbers(&rigid);
    let first_elastic = (1..).find(|m| !numbers.contains(m)).unwrap_or(1);
    let said: Vec<String> = on_rigid
        .iter()
        .map(|m| format!("mode {} ({} Hz)", m.mode + 1, shown_number(m.frequency_hz)))
        .collect();
    let one = on_rigid.len() == 1;
    Err(input(format!(
        "{measured_name}: measured {} numbered onto {} of the model ({} zero to round-off: nothing \
         holds the model in {}; a free–free structure or a rotor without bearings), which no \
         measured natural frequency pairs with. Measured modes pair with the model's by number, \
         counting its rigid-body modes ({}): its first elastic mode is mode {first_elastic}; \
         renumber the measured modes, or give the model supports",
        said.join(", "),
        if one { "a rigid-body mode" } else { "rigid-body modes" },
        if one { "its eigenvalue is" } else { "their eigenvalues are" },
        if one { "that motion" } else { "those motions" },
        numbers.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
    )))
}

/// Runs an estimation. Notes for the log (ignored columns, strategy choices, round-off) go to
/// `notes` as they arise.
pub fn run(
    request: &EstimateRequest,
    notes: &mut Vec<String>,
    progress: &mut dyn Progress,
) -> Result<EstimateOutcome, WorkflowError> {
    // Each start of the search for other minima costs at least one evaluation, so more starts
    // than the budget allows are a slip; refused before the design (starts × parameters) is
    // allocated.
    if let Some(n) = request.alternative_starts.filter(|&n| n > request.budget) {
        return Err(input(format!(
            "--alternative-starts {n}: more starts than the evaluation budget ({}) can run, each start being \
             at least one model evaluation; use fewer, or raise --budget",
            request.budget
        )));
    }
    // The refit strategy by name, checked before anything is read.
    let refit = refit_choice(request.refit.as_deref())?;
    // Two-plane rotors saved by ROSS: bearing kxx/kyy from run-up whirl frequencies.
    if let Some(path) = rotordynamics::ross_model(request.source.model.as_deref()) {
        // A run-up fit on a large rotor takes minutes (each evaluation solves every speed):
        // a spinner with the elapsed time shows it is working.
        let t = &request.test_data;
        rotordynamics::refuse_planar_options(
            &request.strategy,
            &request.residual,
            &[
                ("--shapes", t.shapes.is_some()),
                ("--sensor-map", t.sensor_map.is_some()),
                ("--fix", !t.fix.is_empty()),
                ("--refit", request.refit.is_some()),
            ],
        )?;
        progress.begin("fitting the run-up", None);
        let options = rotordynamics::RunupOptions {
            selection: request.bearing_parameters.as_deref(),
            initial: request.initial.as_deref(),
            write_model: request.write_model,
        };
        let report = rotordynamics::estimate_with(
            path,
            &request.measured,
            &options,
            request.max_iterations,
            request.alternative_starts.unwrap_or(rotordynamics::RUNUP_REFITS),
            request.budget,
        );
        progress.end();
        return report.map(|r| EstimateOutcome::Runup(Box::new(r)));
    }
    if request.bearing_parameters.is_some() {
        return Err(input(
            "--parameters selects bearing coefficients of a ROSS rotor model; \
             this model's parameters are its [[parameter]] tables",
        ));
    }
    let (any, label) = request.source.load_any()?;
    let solver = request.source.solver()?;
    let options = &request.test_data;
    let data = test_data::read(&request.measured, any.layout(), options)?;
    notes.extend(data.file_notes.iter().cloned());
    let measurement = data.measurement.clone();
    let (strategy_name, method) = build_strategy(&request.strategy, request.samples)?;
    let base_name = strategy_name.split(':').next().unwrap_or_default().to_string();
    let kind = match request.residual.as_str() {
        "relative" => ResidualKind::Relative,
        "hz" => ResidualKind::FrequencyHz,
        "eigenvalue" => ResidualKind::Eigenvalue,
        other => {
            return Err(input(format!(
                "--residual: {}",
                eigenfit_core::names::unknown("residual", &shown(other), &["relative", "hz", "eigenvalue"])
            )))
        }
    };
    if request.budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    // Refused before the fit: the updated file is written for rotor models only, and a user who
    // asked for it must not wait through a fit whose result is then not written.
    if request.write_model {
        any.rotor("--write-model")?;
    }
    let updatable = any.updatable(&label)?;
    let initial = parameter_vector(&updatable, "--initial", request.initial.as_deref(), &[])?;
    let model = fixed(&updatable, &options.fix)?;
    let initial = model.reduce(&initial);
    let np = model.parameters().len();
    let measured_name = request.measured.display();
    // The data are counted, not the modes: with shapes every mode gives a row per sensor too,
    // so fewer modes than parameters may do. Fewer data than parameters cannot determine them;
    // otherwise the rank of the weighted Jacobian at the estimate decides (below).
    let sensors = data.sensors.as_ref().map_or(0, |s| s.sensors.len());
    let (rows, counted) = counted_data(measurement.len(), sensors);
    if rows < np {
        return Err(input(format!(
            "{measured_name}: {counted} for {np} parameters: at least {np} are needed"
        )));
    }
    if measurement.modes_needed() > any.dofs() {
        return Err(input(format!(
            "{measured_name}: mode {} measured but the model has only {} modes",
            measurement.modes_needed(),
            any.dofs()
        )));
    }
    // Rigid-body motion is the model's, not the start's: a start with a support of 1e-6 N/m is
    // nearly free, yet the fit moves it. Refused only when the modes are rigid at the file's
    // nominal values as well.
    let name = measured_name.to_string();
    let nominal = model.parameters().nominal_values();
    if refuse_rigid_body_pairing(&model, solver.as_ref(), &nominal, &measurement, &name).is_err() {
        refuse_rigid_body_pairing(&model, solver.as_ref(), &initial, &measurement, &name)?;
    }
    // A mass matrix that is not positive definite at the nominal values and at the start is the
    // model's fault, said naming the DOF before anything is fitted; at one of them only, the fit
    // moves away from it (the damped strategy starts from its coarse grid).
    if crate::simulate::check_mass_at(&model, solver.as_ref(), &nominal).is_err() {
        crate::simulate::check_mass_at(&model, solver.as_ref(), &initial)?;
    }
    if matches!(base_name.as_str(), "newton" | "p-step") && measurement.len() > np {
        notes.push(format!(
            "the {base_name} strategy solves the paper's square system: it uses the first {np} of the {} measured modes; \
             the damped strategy uses all",
            measurement.len()
        ));
    }
    let has_std = measurement.has_std();
    let mode_numbers: Vec<usize> = measurement.modes().iter().map(|m| m.mode + 1).collect();
    let sigma_max = measurement.modes().iter().filter_map(|m| m.std_hz).reduce(f64::max);
    let measurement_for_sampling = measurement.clone();
    // Frequencies no stiffness can give, all explained by one unit slip (entered in kHz, say),
    // are refused naming the unit before anything is fitted; without such a slip they may be a
    // model error, said in a note. With shapes a measured mode may pair with another model mode,
    // so the mode-by-mode bounds are checked on frequency data only.
    // A unit slip moves every frequency by one factor, which no pairing explains: refused for
    // universal files (shapes) too, as one path for measured modes whatever the format.
    match check_softest(&model, solver.as_ref(), &measurement, &mode_numbers) {
        Some(e) if e.slip.is_some() => return Err(input(format!("{measured_name}: {e}"))),
        Some(e) if data.sensors.is_none() => notes.push(format!(
            "{measured_name}: no stiffness within the limits can produce {}: the fit cannot reach these \
             modes; a missing effect (`eigenfit discover`) or modes numbered differently from the model's?",
            e.modes_said()
        )),
        _ => {}
    }
    let problem = Problem::new(&model, solver.as_ref(), measurement).with_kind(kind);
    let mut fit = Fit::new(problem, &data, options.shape.shape_std);
    let budget = Budget::new(request.budget);
    // Data no parameter value can produce is refused before any fitting. Frequency data only,
    // as check_softest: with shapes each corner pairs the measured modes by MAC with whichever
    // model modes they resemble there (a free-free bending shape pairs with a pinned mode on
    // stiff supports), so the corners' frequencies bound nothing (a soft-supported rotor's own
    // universal file was refused as unreachable).
    let reach = if data.sensors.is_none() { check_reachable(&fit, &mode_numbers, &budget) } else { Ok(()) };
    if let Err(e) = reach {
        // A reach cut short by the budget says nothing about the data.
        if budget.exhausted() {
            return Ok(EstimateOutcome::BudgetExhaustedBeforeFit { limit: budget.limit() });
        }
        return Err(input(format!("{measured_name}: {e}")));
    }
    // Running totals of evaluations after each phase, reported per phase.
    let mut phases: Vec<(&str, usize)> = vec![("reachability", budget.used())];
    // A sampler draws the posterior first; the fit (damped) then starts from its best sample.
    let (mut strategy, posterior) = match method {
        Method::Local(strategy) => (strategy, None),
        Method::Sampler(sampler) => {
            if data.sensors.is_some() {
                notes
                    .push(format!("the {base_name} posterior uses the measured frequencies, not the shapes"));
            }
            progress.begin(&format!("sampling the posterior ({strategy_name})"), None);
            let before = budget.used();
            let post = crate::posterior::sample(
                &model,
                solver.as_ref(),
                &measurement_for_sampling,
                &measured_name.to_string(),
                sampler.as_ref(),
                request.seed,
                &budget,
            );
            progress.end();
            let post = match post {
                Ok(p) => p,
                Err(SamplingError::BudgetExhausted { limit }) => {
                    return Ok(EstimateOutcome::BudgetExhaustedBeforeFit { limit })
                }
                Err(SamplingError::Failed(e)) => return Err(e),
            };
            phases.push(("sampling", budget.used()));
            let names: Vec<String> = model.parameters().iter().map(|p| p.name.clone()).collect();
            let report =
                PosteriorReport::new(&names, &strategy_name, request.seed, &post, budget.used() - before);
            let lm: Box<dyn UpdateStrategy> = Box::new(LevenbergMarquardt::default());
            (lm, Some((post, report, sampler.name())))
        }
    };
    // A start inside the bounds where the model cannot be evaluated (a support so soft its mode
    // is a rigid-body mode to round-off) is no reason to refuse: the damped strategy starts from
    // the best point of its coarse grid instead, and says so.
    let mut start = match &posterior {
        Some((post, _, _)) => post.best_sample().map_or_else(|| initial.clone(), <[f64]>::to_vec),
        None => initial.clone(),
    };
    if base_name == "damped" {
        let budgeted = budget.wrap(&fit);
        if let Err(e) = budgeted.linearise(&initial) {
            if let Some(seed) = LevenbergMarquardt::rank_seeds(&budgeted).first() {
                notes.push(format!(
                    "the model cannot be evaluated at --initial ({e}); starting from the best point of the coarse grid"
                ));
                start = seed.clone();
            }
        }
    }
    progress.begin(&format!("estimating ({})", strategy.name()), None);
    let estimate = Driver { max_iterations: request.max_iterations }
        .run_within(&fit, strategy.as_mut(), &start, &budget)
        .map_err(|e| input(e.to_string()));
    progress.end();
    let estimate = match estimate {
        Err(_) if budget.exhausted() => {
            return Ok(EstimateOutcome::BudgetExhaustedBeforeFit { limit: budget.limit() })
        }
        other => other?,
    };
    phases.push(("fit", budget.used()));
    let mut estimate = estimate;
    // The search for other minima runs before the intervals: when it finds a deeper minimum than
    // the fit, that one is the estimate, and the intervals are drawn around it.
    let mut mirrors = Mirrors::default();
    let mut minima = Vec::new();
    let mut search = None;
    if estimate.termination.is_converged() {
        progress.begin("searching for other solutions", None);
        // Exchanges of like parameters, and a structure's symmetries exchanging more than one pair
        // (a matrices model's mirrored zones) on the parameters left free.
        let mut exchanges = like_exchanges(&fit);
        exchanges.extend(free_permutations(
            &any.parameter_symmetries(),
            updatable.parameters(),
            model.parameters(),
        ));
        mirrors = mirror_solutions(&fit, &estimate.last, &exchanges, &budget);
        phases.push(("mirror_solutions", budget.used()));
        let starts = request.alternative_starts.unwrap_or_else(|| default_alternative_starts(np));
        // The default design of a problem with many parameters, or of a model whose evaluation
        // takes seconds, is screened by misfit; starts given on the command line are each
        // fitted. Skipped with no start.
        let (extra, refit) = (&mirrors.asymmetric, &*refit);
        // The fit's own evaluations (the phases hold running totals: a sampler's come before).
        let fit_evaluations = phases
            .iter()
            .position(|(name, _)| *name == "fit")
            .map_or(0, |i| phases[i].1 - i.checked_sub(1).map_or(0, |j| phases[j].1));
        let screening = default_screening(np, model.dofs(), fit_evaluations);
        match screening.filter(|_| request.alternative_starts.is_none()) {
            _ if starts == 0 => {}
            Some(screening) => {
                let found = screened_search(&fit, &screening, extra, &budget, refit, &estimate.last);
                let report = SearchReport::of(&found, &screening, extra.len());
                notes.extend(report.note());
                minima = found.minima;
                search = Some(report);
            }
            None => minima = local_minima_refit(&fit, starts, extra, &budget, refit),
        }
        phases.push(("other_solutions", budget.used()));
        // A regularised estimate is not the least-squares minimum, by design: a deeper one is
        // listed among the other solutions, never put in its place.
        let better = better_minimum(&fit, &estimate.last, &minima).cloned();
        if let (Some(better), Some(reg)) = (&better, &estimate.regularisation) {
            notes.push(format!(
                "the search for other solutions found a deeper least-squares minimum (Σr² {} → {}); the estimate \
                 stays the regularised one (λ = {} by {})",
                shown_number(estimate.last.chi2()),
                shown_number(better.chi2()),
                shown_number(reg.lambda),
                reg.rule
            ));
        }
        if let Some(better) = better.filter(|_| estimate.regularisation.is_none()) {
            notes.push(adopt_better_minimum(&mut estimate, better, &mut minima));
            mirrors = mirror_solutions(&fit, &estimate.last, &exchanges, &budget);
        }
        progress.end();
    }
    // Never a fit whose model frequencies are lost to round-off (an extreme stiffness).
    // A shape fit's MAC report solves the modes at the estimate anyway: the check reads them.
    let system = model.assemble(&estimate.parameters).map_err(|e| input(e.to_string()))?;
    let (mac, mac_modes) = fit.mac_with_modes(&estimate.parameters, options.shape.mac_threshold).unzip();
    let highest = mode_numbers.iter().copied().max().unwrap_or(1);
    let modes = match mac_modes.filter(|m| m.count() >= highest) {
        Some(modes) => Ok(modes),
        None => solver.lowest(&system, highest),
    };
    if let Ok(modes) = modes {
        notes.extend(check_roundoff_of(&system, &modes, Some(&mode_numbers))?);
    }
    // Whether the data determine the parameters: the numerical rank of the weighted Jacobian of
    // every datum (frequencies and shape components) at the estimate, not a count of modes.
    let rank = Rank::at(model.parameters(), &estimate.last);
    let names: Vec<String> = model.parameters().iter().map(|p| p.name.clone()).collect();
    let data_rank = DataRankReport::new(&counted, rows, &rank, &names);
    if !rank.is_full() {
        notes.push(format!(
            "{measured_name}: {counted} determine {} of the {np} parameter directions (the rank of the weighted \
             Jacobian of all the data at the estimate); they cannot tell apart changes along {}",
            rank.rank,
            data_rank.null_directions.join("; ")
        ));
    }
    let converged = estimate.termination.is_converged();
    let quality = judge(&estimate.last, np);
    let limits = at_limits(model.parameters(), &estimate.parameters);
    // Profile bounds done / total through the driver's observer mechanism.
    let (unc, scatter) = if converged {
        let mut bounds = StepsObserver::new(progress, "interval bounds");
        let unc = fit.uncertainty_within(&estimate.last, &budget, &mut [&mut bounds], &*refit);
        bounds.finish();
        unc
    } else {
        (None, None)
    };
    phases.push(("intervals", budget.used()));
    if let Some(u) = &unc {
        let widened = u.widened_by_round_off(model.parameters());
        if !widened.is_empty() {
            let named: Vec<&str> = widened.iter().map(|&i| names[i].as_str()).collect();
            notes.push(format!(
                "round-off on a fine mesh: the model's frequencies jump between neighbouring points (bound {:.1e} \
                 relative, scaled to the jitter measured at the estimate); that alone moves {} by up to {:.1e} (in ln \
                 for a log-scaled parameter), and their intervals are widened by as much",
                estimate.last.max_round_off(),
                named.join(", "),
                widened.iter().map(|&i| u.round_off_reach[i]).fold(0.0, f64::max),
            ));
        }
    }
    // Mirrors first, then the other minima not already listed, each judged against the estimate.
    let alternatives = listed_alternatives(&fit, &estimate.last, mirrors.symmetric, &minima);
    let alternatives_sigma = Equivalence::at(&estimate.last, np).sigma_source();
    let unique = !alternatives.iter().any(|a| a.judged.equally_good);
    let budget_spent = budget.exhausted();
    let pinned: Vec<String> = (0..np).filter(|&i| limits[i] != 0).map(|i| names[i].clone()).collect();
    // A measured mode below the MAC threshold makes the result not acceptable.
    let unpaired = mac.as_ref().is_some_and(|r| !r.unpaired.is_empty());
    let verdict = Verdict::of(
        (!converged).then(|| estimate.termination.label()),
        budget_spent,
        quality.verdict,
        !pinned.is_empty(),
        unpaired,
        unique,
    );
    let acceptable = verdict.is_answer();
    // What the data say about each parameter, in words.
    let status = |i: usize| -> String {
        let bound = unc.as_ref().map(|u| &u.identifiability[i]);
        match (limits[i], bound) {
            (_, Some(Identifiability::LowerBoundOnly { lower })) => {
                format!("not identifiable: ≥ {lower:.4e}")
            }
            (_, Some(Identifiability::UpperBoundOnly { upper })) => {
                format!("not identifiable: ≤ {upper:.4e}")
            }
            (0, Some(Identifiability::Determined)) => {
                let u = unc.as_ref().map_or([0.0; 2], |u| u.intervals[i]);
                format!("[{:.4e}, {:.4e}]", u[0], u[1])
            }
            (1, _) => "not identifiable: at its upper limit, the data see no upper bound".into(),
            (-1, _) => "not identifiable: at its lower limit".into(),
            (_, Some(_)) => "not identifiable".into(),
            (_, None) if !converged => "(not computed: the run did not converge)".into(),
            (_, None) if !has_std => "(no std given)".into(),
            (_, None) => "(not computed)".into(),
        }
    };
    let held = model.held();
    let mut report = EstimateReport {
        model: label,
        strategy: posterior.as_ref().map_or(estimate.strategy, |(_, _, name)| name),
        outcome: Outcome::of(&estimate, converged),
        verdict,
        fit: FitQualityReport::of(&quality, |k| k),
        budget: BudgetReport { limit: budget.limit(), used: budget.used(), exhausted: budget_spent },
        evaluations_by_phase: phase_counts(&phases),
        data_rank,
        values: ParameterValues::new(&names, &initial, &estimate.parameters, status),
        at_limit: pinned,
        alternative_solutions: AlternativeSolution::list(&names, &alternatives),
        search,
        alternatives_sigma,
        regularisation: estimate.regularisation.clone(),
        posterior: posterior.map(|(_, report, _)| report),
        frequencies: PairedFrequencies::of(&estimate.last),
        history: estimate
            .history
            .iter()
            .map(|r| HistoryRecord {
                iteration: r.iteration,
                parameters: r.parameters.clone(),
                frequencies_hz: r.frequencies_hz.clone(),
                max_abs_diff_hz: r.max_abs_diff_hz,
                from_search: r.is_from_search(),
            })
            .collect(),
        uncertainty: IntervalsReport::new(&names, unc.as_ref()),
        units: crate::simulate::units_of(&model),
        covariances: Covariances::of(&names, unc.as_ref().map(|u| &u.covariance)),
        plots: None,
        test_data: ShapeReport::new(&fit, &data, &estimate, mac.as_ref(), scatter),
        fixed: (!held.is_empty()).then_some(Named(held)),
    };
    // A residual row is a frequency or, with shapes, a sensor of a mode: named by its mode, once.
    report.fit.disagreeing_modes = test_data::modes_of_rows(
        &quality.disagreeing,
        &mode_numbers,
        data.sensors.as_ref().map_or(0, |s| s.sensors.len()),
    );
    let updated_model =
        request.write_model.then(|| updated_model_toml(&request.measured, &model, &estimate, unc.as_ref()));
    let unit = axis_unit(model.parameters());
    drop(fit);
    Ok(EstimateOutcome::Done(Box::new(Estimation {
        report,
        estimate,
        quality,
        uncertainty: unc,
        mac,
        data,
        scatter,
        has_std,
        mode_numbers,
        on_limit: limits.iter().map(|&l| l != 0).collect(),
        unit,
        sigma_max,
        acceptable,
        updated_model,
    })))
}

/// The strategy `spec` names, from the process-wide registry; `samples` is a sampler's
/// `samples` setting (refused for other strategies).
pub fn build_strategy(spec: &str, samples: Option<usize>) -> Result<(String, Method), WorkflowError> {
    let (name, method) = registry::build(spec).map_err(|e| input(format!("--strategy: {e}")))?;
    let Some(n) = samples else { return Ok((name, method)) };
    if !matches!(method, Method::Sampler(_)) {
        return Err(input(format!(
            "--samples {n}: the strategy `{}` is not a sampler (tmcmc is)",
            shown(spec)
        )));
    }
    if spec.split(':').skip(1).any(|kv| kv.trim().starts_with("samples")) {
        return Err(input(format!("--samples {n} and `{}`: give the number of samples once", shown(spec))));
    }
    registry::build(&format!("{spec}:samples={n}")).map_err(|e| input(format!("--samples: {e}")))
}

/// The model's parameter permutations (over `all`, its parameters) that move more than one pair
/// and keep every held parameter in place, over the free parameters `free` (matched by name);
/// single exchanges are left to `mirror_solutions`, which checks every like pair.
fn free_permutations(
    permutations: &[Vec<usize>],
    all: &ParameterSet,
    free: &ParameterSet,
) -> Vec<Vec<usize>> {
    let index: Vec<Option<usize>> = all.iter().map(|p| free.iter().position(|q| q.name == p.name)).collect();
    permutations
        .iter()
        .filter(|perm| perm.iter().enumerate().all(|(i, &j)| index[i].is_some() == index[j].is_some()))
        .filter(|perm| perm.iter().enumerate().all(|(i, &j)| index[i].is_some() || i == j))
        .map(|perm| {
            let mut reduced = vec![0; free.len()];
            for (i, &j) in perm.iter().enumerate() {
                if let (Some(a), Some(b)) = (index[i], index[j]) {
                    reduced[a] = b;
                }
            }
            reduced
        })
        .filter(|perm| !matches!(cycles(perm).as_slice(), [pair] if pair.len() == 2))
        .collect()
}

/// The units of `params`, each once in order, joined by `, `: one axis's unit for parameters
/// drawn together (`N/m`; `N/m, kg` when they differ; empty when none declares one).
pub fn axis_unit(params: &ParameterSet) -> String {
    let mut units: Vec<&str> = Vec::new();
    for u in params.iter().map(|p| p.unit()).filter(|u| !u.is_empty()) {
        if !units.contains(&u) {
            units.push(u);
        }
    }
    units.join(", ")
}
