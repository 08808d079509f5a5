//! The paper rotor end to end (`eigenfit demo`): Table 1 side by side, Table 3 case 1 with every
//! strategy, where each strategy converges from over a grid of initial guesses, and the
//! discovery of a hidden effect in a built-in dataset.

use crate::compare::{basins, Basin};
use crate::discover::RmsResidual;
use crate::error::{failure, WorkflowError};
use crate::progress::Progress;
use eigenfit_core::analysis::compare::{
    log_space, reference_measurement, run_grid, tensor_grid, CompareRun, CompareSettings, ReferenceSettings,
    DEFAULT_STRATEGIES,
};
use eigenfit_core::discovery::{discover, DiscoveryOptions, DiscoveryReport, Fit};
use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::measurement::measured_csv;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::Problem;
use eigenfit_core::update::{Driver, Estimate, Outcome};
use eigenfit_rotor::presets::{self, PAPER_TABLE_1};
use serde::Serialize;

/// The built-in dataset: 8 noisy frequencies of the paper rotor at K1 = 2e5, K2 = 5e4 N/m with a
/// diametral inertia of 1e-3 kg·m² on disk 0 that the model lacks (docs/discovery.md).
pub const HIDDEN_EFFECT_CSV: &str = include_str!("../../../examples/measured_hidden_effect.csv");
/// Table 3 case 1: the target (N/m).
pub const TARGET: [f64; 2] = [1e5, 1e5];
/// Table 3 case 1: the start (N/m).
pub const INITIAL: [f64; 2] = [1e2, 1e2];
/// The paper's result for Table 3 case 1: K1, K2 (N/m) and iterations.
pub const PAPER_CASE_1: ([f64; 2], usize) = ([1.0000e5, 9.9993e4], 5);
/// The demo's label for its model.
pub const LABEL: &str = "paper-rotor";

/// One row of Table 1: the paper's frequency beside the model's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table1Row {
    /// Support stiffnesses K1, K2 (N/m).
    pub k: [f64; 2],
    /// Mode, from 1.
    pub mode: usize,
    /// The paper's frequency (Hz).
    pub paper_hz: f64,
    /// The model's (Hz).
    pub model_hz: f64,
    /// (model / paper − 1) in %.
    pub difference_percent: f64,
}

/// One strategy's run on Table 3 case 1.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StrategyRun {
    /// Strategy name.
    pub strategy: &'static str,
    /// K1, K2 reached (N/m).
    pub parameters: Vec<f64>,
    /// Whether it converged, why it stopped, iterations and model evaluations.
    #[serde(flatten)]
    pub outcome: Outcome,
}

/// Table 3 case 1: target, start, the reference data and every strategy's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table3 {
    /// Target (N/m).
    pub target: [f64; 2],
    /// Start (N/m).
    pub initial: [f64; 2],
    /// Reference frequencies: the model's at the target, rounded to 3 decimals (Hz).
    pub reference_hz: Vec<f64>,
    /// One run per strategy.
    pub estimates: Vec<StrategyRun>,
}

/// The convergence map's grid and each strategy's basin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvergenceMap {
    /// Points per axis.
    pub grid: usize,
    /// Per strategy: runs, converged, at the target.
    pub strategies: Vec<Basin>,
}

/// The effect discovery named in the built-in dataset (its refit: kind, location, value,
/// interval, χ², AICc, plausibility) with the evidence before and after.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HiddenEffect {
    /// The named effect's refit.
    #[serde(flatten)]
    pub fit: Fit,
    /// χ² with the stiffnesses alone.
    pub chi2_before: f64,
    /// χ² with the effect added.
    pub chi2_after: f64,
    /// RMS residual before and after (Hz).
    #[serde(flatten)]
    pub rms: RmsResidual,
}

/// The demo's report; `out`, `plots` and `seconds` are the front end's to fill.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DemoReport {
    /// The model's label.
    pub model: &'static str,
    /// Table 1, side by side.
    pub table_1: Vec<Table1Row>,
    /// Table 3 case 1.
    pub table_3_case_1: Table3,
    /// The convergence map.
    pub convergence_map: ConvergenceMap,
    /// The named effect, or null when none explains the data.
    pub discovery: Option<HiddenEffect>,
    /// Folder of the plots.
    pub out: String,
    /// Plot files written.
    pub plots: Vec<String>,
    /// Wall-clock time of the whole demo (s).
    pub seconds: f64,
}

/// The demo's results: the report and what the plots are drawn from.
pub struct Demo {
    /// The report.
    pub report: DemoReport,
    /// Largest |difference| of Table 1 (%).
    pub worst_percent: f64,
    /// Each strategy's estimate on Table 3 case 1 (for the convergence plot).
    pub estimates: Vec<Estimate>,
    /// The grid runs (for the convergence maps), their targets and strategies.
    pub grid: Vec<CompareRun>,
    /// The targets of the grid.
    pub targets: Vec<Vec<f64>>,
    /// The strategies of the grid.
    pub strategies: Vec<String>,
    /// The discovery.
    pub discovery: DiscoveryReport,
}

/// Runs the demo's computations with `grid` points per axis (1e1–1e9 N/m) for the map.
pub fn run(grid: usize, progress: &mut dyn Progress) -> Result<Demo, WorkflowError> {
    let rotor = presets::paper_rotor();
    let solver = DenseSolver;
    // 1. Table 1 side by side.
    let mut table_1 = Vec::new();
    let mut worst_percent = 0.0_f64;
    for (k, paper) in PAPER_TABLE_1 {
        let system = rotor.assemble(&k).map_err(failure)?;
        let f = solver.lowest(&system, 2).map_err(failure)?.frequencies_hz();
        for m in 0..2 {
            let difference_percent = (f[m] / paper[m] - 1.0) * 100.0;
            worst_percent = worst_percent.max(difference_percent.abs());
            table_1.push(Table1Row {
                k,
                mode: m + 1,
                paper_hz: paper[m],
                model_hz: f[m],
                difference_percent,
            });
        }
    }
    // 2. Table 3 case 1 with all three strategies.
    let settings = CompareSettings {
        reference: ReferenceSettings { modes: 2, decimals: Some(3), std_hz: None },
        max_iterations: 1000,
        budget: eigenfit_core::update::DEFAULT_EVALUATIONS,
    };
    let measured = reference_measurement(&rotor, &solver, &TARGET, &settings)
        .map_err(|e| WorkflowError::Failure(e.to_string()))?;
    let reference_hz: Vec<f64> = measured.modes().iter().map(|m| m.frequency_hz).collect();
    let problem = Problem::new(&rotor, &solver, measured);
    let mut estimates = Vec::new();
    let registry = eigenfit_core::update::registry::registry();
    for name in DEFAULT_STRATEGIES {
        let mut strategy = eigenfit_core::update::registry::build_local(&registry, name).map_err(failure)?.1;
        estimates.push(
            Driver { max_iterations: 1000 }.run(&problem, strategy.as_mut(), &INITIAL).map_err(failure)?,
        );
    }
    // 3. Where each strategy converges from: a grid of initial guesses.
    let initials = tensor_grid(&log_space(1e1, 1e9, grid), 2);
    let targets = vec![TARGET.to_vec()];
    let strategies: Vec<String> = DEFAULT_STRATEGIES.map(String::from).to_vec();
    progress.begin("convergence map", Some((initials.len() * strategies.len()) as u64));
    let runs = run_grid(&rotor, &solver, &targets, &initials, &strategies, &settings, |_| progress.step());
    progress.end();
    let runs = runs.map_err(|e| WorkflowError::Failure(e.to_string()))?;
    // 4. Discovery of a hidden effect.
    let data = measured_csv::parse(HIDDEN_EFFECT_CSV)
        .map_err(|e| WorkflowError::Failure(format!("built-in dataset: line {e}")))?;
    progress.begin("discovering the hidden effect", None);
    let options = DiscoveryOptions::default();
    let found = discover(&rotor, &solver, &data, &rotor.candidates(), &rotor.nominal_stiffnesses(), &options);
    progress.end();
    let found = found.map_err(failure)?;
    let discovery = found.selected.as_ref().map(|s| HiddenEffect {
        fit: s.clone(),
        chi2_before: found.before.chi2,
        chi2_after: s.chi2,
        rms: RmsResidual::of(&found),
    });
    let report = DemoReport {
        model: LABEL,
        table_1,
        table_3_case_1: Table3 {
            target: TARGET,
            initial: INITIAL,
            reference_hz,
            estimates: estimates
                .iter()
                .map(|e| StrategyRun {
                    strategy: e.strategy,
                    parameters: e.parameters.clone(),
                    outcome: Outcome::of(e, e.termination.is_converged()),
                })
                .collect(),
        },
        convergence_map: ConvergenceMap { grid, strategies: basins(&runs, &strategies) },
        discovery,
        out: String::new(),
        plots: Vec::new(),
        seconds: 0.0,
    };
    Ok(Demo { report, worst_percent, estimates, grid: runs, targets, strategies, discovery: found })
}
