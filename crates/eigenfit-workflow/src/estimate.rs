//! `estimate`: update a model's parameters to match measured frequencies (and shapes), with
//! the verdict, intervals, other equally good solutions and the updated model file.

use crate::error::{input, WorkflowError};
use crate::named::Named;
use crate::outcome::{FitQualityReport, Outcome, PairedFrequencies, ParameterValues, Verdict};
use crate::overrides::{fixed, parameter_vector};
use crate::progress::{Progress, StepsObserver};
use crate::rotordynamics::{self, RunupEstimateReport};
use crate::simulate::check_roundoff_of;
use crate::source::ModelSource;
use crate::test_data::{self, updated_model_toml, Fit, ShapeReport, TestData, TestDataOptions};
use eigenfit_core::analysis::verdict::{at_limits, check_reachable, judge, FitQuality, FitVerdict};
use eigenfit_core::analysis::{
    alternative_solutions_within, mirror_solutions, permuted_solutions, Identifiability, Uncertainty,
};
use eigenfit_core::measurement::mac::MacReport;
use eigenfit_core::measurement::measured_csv::shown;
use eigenfit_core::model::{ParameterSet, StructuralModel};
use eigenfit_core::problem::{Objective, Problem, ResidualKind};
use eigenfit_core::update::{Budget, Driver, Estimate, LevenbergMarquardt, StrategyKind};
use serde::Serialize;
use std::path::PathBuf;

/// Another equally good parameter vector, with the permutation of the parameters (parameter i's
/// value moved to π\[i\]) when it is a mirror solution.
type Alternative = (Vec<f64>, Option<Vec<usize>>);

/// Most DOFs of a model updated from measured shapes: their derivatives (Nelson's method) take
/// a dense factorisation per mode and iteration, seconds each at this size and O(n³) beyond.
pub const SHAPE_DOF_LIMIT: usize = 2000;

/// Restart-grid points refitted locally when searching for other equally good solutions.
pub const ALTERNATIVE_STARTS: usize = 6;

/// What to estimate, as the command line gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateRequest {
    /// The model and solver.
    pub source: ModelSource,
    /// Measured data: frequency CSV, universal file, or (ROSS rotor) a run-up CSV.
    pub measured: PathBuf,
    /// Shapes, sensors and held parameters.
    pub test_data: TestDataOptions,
    /// Update strategy: newton, p-step or damped.
    pub strategy: String,
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
    /// Points of the coarse grid refitted locally when searching for other equally good
    /// solutions (0: no such search; the exchange of like parameters is still checked; default
    /// [`ALTERNATIVE_STARTS`]). On a large model most of a run's evaluations.
    pub alternative_starts: usize,
    /// ROSS rotors: the bearing coefficients to estimate (`kxx,kyy,…` or `kxy_<bearing>`; `None`:
    /// kxx and kyy of every bearing). Refused for other models.
    pub bearing_parameters: Option<String>,
}

pub use crate::outcome::BudgetReport;

/// Another equally good parameter vector.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlternativeSolution {
    /// Its values.
    pub parameters: Named<f64>,
    /// The exchanged pair when it is a mirror solution of a symmetric model that exchanges one
    /// pair of parameters (`None` for a symmetry exchanging more: see `exchanged`).
    pub mirror_of: Option<[String; 2]>,
    /// A mirror solution's exchanged parameters as cycles (`[["zone1", "zone3"], ["zone2",
    /// "zone4"]]`: a plate's zones mirrored about its centre line); empty for other solutions.
    pub exchanged: Vec<Vec<String>>,
}

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

/// The intervals part of an estimate report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IntervalsReport {
    /// 95 % intervals.
    pub intervals: Named<[f64; 2]>,
    /// Identifiability per parameter.
    pub identifiable: Named<ParameterIdentifiability>,
    /// Singular values of the scaled Jacobian.
    pub singular_values: Vec<f64>,
    /// Their ratio.
    pub condition_number: f64,
    /// Standard deviations.
    pub standard_deviations: Named<f64>,
}

impl IntervalsReport {
    /// The report of `u` for parameters `names`.
    pub fn new(names: &[String], u: &Uncertainty) -> Self {
        Self {
            intervals: Named::new(names, u.intervals.iter().copied()),
            identifiable: Named::new(names, u.identifiability.iter().map(Into::into)),
            singular_values: u.singular_values.clone(),
            condition_number: u.condition_number,
            standard_deviations: Named::new(names, (0..names.len()).map(|i| u.covariance[(i, i)].sqrt())),
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
    /// Initial and estimated values, and what the data say about each parameter, in words.
    #[serde(flatten)]
    pub values: ParameterValues,
    /// Parameters on a limit.
    pub at_limit: Vec<String>,
    /// Intervals and what the data determine (a converged run with std or scatter).
    #[serde(flatten)]
    pub uncertainty: Option<IntervalsReport>,
    /// Other equally good solutions.
    pub alternative_solutions: Vec<AlternativeSolution>,
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
    /// The unit of the first parameter (for plots).
    pub unit: String,
    /// The largest measured standard deviation (Hz).
    pub sigma_max: Option<f64>,
    /// The exit verdict: converged, fit not poor, nothing on a limit, budget left, all paired.
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

/// Runs an estimation. Notes for the log (ignored columns, strategy choices, round-off) go to
/// `notes` as they arise.
pub fn run(
    request: &EstimateRequest,
    notes: &mut Vec<String>,
    progress: &mut dyn Progress,
) -> Result<EstimateOutcome, WorkflowError> {
    // Two-plane rotors saved by ROSS: bearing kxx/kyy from run-up whirl frequencies.
    if let Some(path) = rotordynamics::ross_model(request.source.model.as_deref()) {
        // A run-up fit on a large rotor takes minutes (each evaluation solves every speed):
        // a spinner with the elapsed time shows it is working.
        progress.begin("fitting the run-up", None);
        let report = rotordynamics::estimate(
            path,
            &request.measured,
            request.bearing_parameters.as_deref(),
            request.max_iterations,
            request.alternative_starts,
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
    if data.sensors.is_some() && any.dofs() > SHAPE_DOF_LIMIT {
        return Err(input(format!(
            "{}: measured shapes need the shapes' derivatives, computed here by Nelson's method on \
             dense matrices (O(n³) per mode and iteration): the model has {} DOFs, more than the {SHAPE_DOF_LIMIT} \
             this is done for; estimate from the frequencies alone (a CSV of mode,frequency_hz)",
            request.measured.display(),
            any.dofs()
        )));
    }
    notes.extend(data.file_notes.iter().cloned());
    let measurement = data.measurement.clone();
    let strategy_kind = StrategyKind::from_name(&request.strategy).ok_or_else(|| {
        input(format!(
            "unknown strategy `{}`; available: newton, p-step, damped (alias levenberg-marquardt)",
            shown(&request.strategy)
        ))
    })?;
    let kind = match request.residual.as_str() {
        "relative" => ResidualKind::Relative,
        "hz" => ResidualKind::FrequencyHz,
        "eigenvalue" => ResidualKind::Eigenvalue,
        other => {
            return Err(input(format!(
                "unknown residual `{}`; available: relative, hz, eigenvalue",
                shown(other)
            )))
        }
    };
    if request.budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    let updatable = any.updatable(&label)?;
    let initial = parameter_vector(&updatable, "--initial", request.initial.as_deref(), &[])?;
    let model = fixed(&updatable, &options.fix)?;
    let initial = model.reduce(&initial);
    let np = model.parameters().len();
    let measured_name = request.measured.display();
    // With shapes every mode gives a row per sensor too: fewer modes than parameters may do.
    let rows = measurement.len() * (1 + data.sensors.as_ref().map_or(0, |s| s.sensors.len()));
    if rows < np {
        return Err(input(format!(
            "{measured_name}: {} measured modes for {np} parameters: at least {np} are needed",
            measurement.len()
        )));
    }
    if measurement.modes_needed() > any.dofs() {
        return Err(input(format!(
            "{measured_name}: mode {} measured but the model has only {} modes",
            measurement.modes_needed(),
            any.dofs()
        )));
    }
    if matches!(strategy_kind, StrategyKind::Newton | StrategyKind::PStep) && measurement.len() > np {
        notes.push(format!(
            "the {} strategy solves the paper's square system: it uses the first {np} of the {} measured modes; \
             the damped strategy uses all",
            strategy_kind.name(),
            measurement.len()
        ));
    }
    let has_std = measurement.has_std();
    let mode_numbers: Vec<usize> = measurement.modes().iter().map(|m| m.mode + 1).collect();
    let sigma_max = measurement.modes().iter().filter_map(|m| m.std_hz).reduce(f64::max);
    let problem = Problem::new(&model, solver.as_ref(), measurement).with_kind(kind);
    let mut fit = Fit::new(problem, &data, options.shape.shape_std);
    let budget = Budget::new(request.budget);
    // Data no parameter value can produce is refused before any fitting.
    if let Err(e) = check_reachable(&fit, &mode_numbers, &budget) {
        // A reach cut short by the budget says nothing about the data.
        if budget.exhausted() {
            return Ok(EstimateOutcome::BudgetExhaustedBeforeFit { limit: budget.limit() });
        }
        return Err(input(format!("{measured_name}: {e}")));
    }
    // Running totals of evaluations after each phase, reported per phase.
    let mut phases: Vec<(&str, usize)> = vec![("reachability", budget.used())];
    // A start inside the bounds where the model cannot be evaluated (a support so soft its mode
    // is a rigid-body mode to round-off) is no reason to refuse: the damped strategy starts from
    // the best point of its coarse grid instead, and says so.
    let mut start = initial.clone();
    if strategy_kind == StrategyKind::LevenbergMarquardt {
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
    let mut strategy = strategy_kind.build();
    progress.begin(&format!("estimating ({})", strategy_kind.name()), None);
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
    // Never a fit whose model frequencies are lost to round-off (an extreme stiffness).
    let system = model.assemble(&estimate.parameters).map_err(|e| input(e.to_string()))?;
    if let Ok(modes) = solver.lowest(&system, mode_numbers.iter().copied().max().unwrap_or(1)) {
        notes.extend(check_roundoff_of(&system, &modes, Some(&mode_numbers))?);
    }
    let converged = estimate.termination.is_converged();
    let quality = judge(&estimate.last, np);
    let limits = at_limits(model.parameters(), &estimate.parameters);
    // Profile bounds done / total through the driver's observer mechanism, then other solutions.
    let (unc, scatter) = if converged {
        let mut bounds = StepsObserver::new(progress, "interval bounds");
        let unc = fit.uncertainty_within(&estimate.last, has_std, &budget, &mut [&mut bounds]);
        bounds.finish();
        unc
    } else {
        (None, None)
    };
    phases.push(("intervals", budget.used()));
    if converged {
        progress.begin("searching for other solutions", None);
    }
    let mac = fit.mac(&estimate.parameters, options.shape.mac_threshold);
    let mut alternatives: Vec<Alternative> = Vec::new();
    if converged && quality.verdict != FitVerdict::Poor {
        for (i, j, p) in mirror_solutions(&fit, &estimate.last, &budget) {
            let mut swap: Vec<usize> = (0..np).collect();
            swap.swap(i, j);
            alternatives.push((p, Some(swap)));
        }
        // A structure's symmetries exchanging more than one pair (a matrices model's mirrored
        // zones), on the parameters left free.
        let symmetries =
            free_permutations(&any.parameter_symmetries(), updatable.parameters(), model.parameters());
        for (k, p) in permuted_solutions(&fit, &estimate.last, &symmetries, &budget) {
            alternatives.push((p, Some(symmetries[k].clone())));
        }
        phases.push(("mirror_solutions", budget.used()));
        // Ranking the coarse grid alone costs an evaluation per point: skipped with no start.
        let others = if request.alternative_starts == 0 {
            Vec::new()
        } else {
            alternative_solutions_within(&fit, &estimate.last, request.alternative_starts, &budget)
        };
        for p in others {
            let same = |q: &[f64]| {
                model
                    .parameters()
                    .iter()
                    .zip(q.iter().zip(&p))
                    .all(|(par, (&a, &b))| (par.to_scaled(a) - par.to_scaled(b)).abs() <= 0.01)
            };
            if !alternatives.iter().any(|(q, _)| same(q)) {
                alternatives.push((p, None));
            }
        }
    }
    if converged {
        progress.end();
    }
    phases.push(("other_solutions", budget.used()));
    let budget_spent = budget.exhausted();
    let names: Vec<String> = model.parameters().iter().map(|p| p.name.clone()).collect();
    let pinned: Vec<String> = (0..np).filter(|&i| limits[i] != 0).map(|i| names[i].clone()).collect();
    // A measured mode below the MAC threshold makes the result not acceptable.
    let unpaired = mac.as_ref().is_some_and(|r| !r.unpaired.is_empty());
    let verdict = Verdict::of(
        (!converged).then(|| estimate.termination.label()),
        budget_spent,
        quality.verdict,
        !pinned.is_empty(),
        unpaired,
    );
    let acceptable = verdict.acceptable;
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
        strategy: estimate.strategy,
        outcome: Outcome::of(&estimate, converged),
        verdict,
        fit: FitQualityReport::of(&quality, |k| k),
        budget: BudgetReport { limit: budget.limit(), used: budget.used(), exhausted: budget_spent },
        evaluations_by_phase: phase_counts(&phases),
        values: ParameterValues::new(&names, &initial, &estimate.parameters, status),
        at_limit: pinned,
        alternative_solutions: alternatives
            .iter()
            .map(|(p, mirror)| {
                let cycles = mirror.as_deref().map(cycles).unwrap_or_default();
                AlternativeSolution {
                    parameters: Named::new(&names, p.iter().copied()),
                    mirror_of: match cycles.as_slice() {
                        [pair] if pair.len() == 2 => Some([names[pair[0]].clone(), names[pair[1]].clone()]),
                        _ => None,
                    },
                    exchanged: cycles.iter().map(|c| c.iter().map(|&i| names[i].clone()).collect()).collect(),
                }
            })
            .collect(),
        frequencies: PairedFrequencies::of(&estimate.last),
        history: estimate
            .history
            .iter()
            .map(|r| HistoryRecord {
                iteration: r.iteration,
                parameters: r.parameters.clone(),
                frequencies_hz: r.frequencies_hz.clone(),
                max_abs_diff_hz: r.max_abs_diff_hz,
            })
            .collect(),
        uncertainty: unc.as_ref().map(|u| IntervalsReport::new(&names, u)),
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
    let unit = any.parameters().iter().next().map_or(String::new(), |p| p.unit.clone());
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

/// `{phase: evaluations}` from the running totals after each phase (a phase not reached is left
/// out).
fn phase_counts(totals: &[(&str, usize)]) -> Named<usize> {
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

/// The cycles (two or more parameters each) of a permutation, each from its lowest index.
fn cycles(perm: &[usize]) -> Vec<Vec<usize>> {
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
