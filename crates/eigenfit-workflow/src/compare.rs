//! `compare`: strategies × targets × initial guesses on reference data from the model itself,
//! with a summary per target and strategy.
//!
//! Two accuracies, both defined here: the summary's `converged_within_1e-6` (and the text maps'
//! ●) count runs within [`WITHIN_1E6`] — the key names its threshold and other tools rely on
//! it; the convergence plots and the demo's basins call a run "at the target" within
//! [`AT_TARGET`], the basin of the target rather than an accuracy.

use crate::error::{input, WorkflowError};
use crate::overrides::{parse_list, points};
use eigenfit_core::analysis::compare::{
    axes_grid, checked_strategies, log_space, run_grid, CompareRun, CompareSettings, ReferenceSettings,
};
use eigenfit_core::analysis::Identifiability;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::update::registry;
use serde::Serialize;

/// Relative error within which a converged run counts in the summary's `converged_within_1e-6`.
pub const WITHIN_1E6: f64 = 1e-6;
/// Relative error under which a converged run counts as "at the target" on the convergence
/// plots and in the demo's basins: separates the basin of the target from the basin of another
/// exact solution (which lies a factor ≥ 2 away on the paper rotor), while the paper
/// strategies' 0.01 Hz stopping test (up to ~6 % off on stiff supports) still counts as
/// reaching the target.
pub const AT_TARGET: f64 = 0.1;
/// Most runs one comparison accepts: far beyond any study (the paper's maps are 10⁴), checked
/// before anything is allocated.
pub const MAX_RUNS: usize = 1_000_000;

/// What to compare, as the command line gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareRequest {
    /// Target parameter sets `K1:K2,…` (in the parameters' units).
    pub targets: String,
    /// Log grid of initial guesses with this many points per parameter.
    pub grid: Option<usize>,
    /// Range of the grid, `FROM:TO` for every parameter or one `FROM:TO` per parameter,
    /// comma-separated (each in its parameter's unit).
    pub range: String,
    /// Explicit initial guesses `K1:K2,…`, instead of a grid.
    pub initials: Option<String>,
    /// Strategies, comma-separated.
    pub strategies: String,
    /// Round the reference frequencies to this many decimals.
    pub decimals: Option<i32>,
    /// Standard deviation of each reference frequency (Hz).
    pub std_hz: Option<f64>,
    /// Reference modes given to every strategy (default: as many as parameters).
    pub modes: Option<usize>,
    /// Iteration limit per run.
    pub max_iterations: usize,
    /// Most model evaluations (eigen-solves) one run may spend on its fit and intervals.
    pub budget: usize,
    /// Include each run's wall-clock time.
    pub timing: bool,
}

/// A checked comparison, ready to run.
#[derive(Debug, Clone)]
pub struct ComparePlan {
    /// Target parameter vectors.
    pub targets: Vec<Vec<f64>>,
    /// Initial guesses.
    pub initials: Vec<Vec<f64>>,
    /// Strategies, as the registry names them (settings kept, aliases replaced).
    pub strategies: Vec<String>,
    /// Reference-data settings.
    pub settings: CompareSettings,
    /// Include each run's wall-clock time in the report.
    pub timing: bool,
}

impl ComparePlan {
    /// Runs in total.
    pub fn runs(&self) -> usize {
        self.targets.len() * self.initials.len() * self.strategies.len()
    }
}

/// The log-spaced axis of each of `np` parameters, `n` points over its range: `text` is one
/// `FROM:TO` for all or one per parameter (`1e4:1e6,1:10`), so parameters in different units
/// (a stiffness and a mass) each get a range of their own.
fn grid_axes(text: &str, np: usize, n: usize) -> Result<Vec<Vec<f64>>, WorkflowError> {
    let ranges: Vec<&str> = text.split(',').map(str::trim).collect();
    if ranges.len() != 1 && ranges.len() != np {
        return Err(input(format!(
            "--range `{text}`: {} ranges for {np} parameters; give one FROM:TO for all or one per parameter",
            ranges.len()
        )));
    }
    (0..np)
        .map(|i| {
            let range = ranges[i.min(ranges.len() - 1)];
            let r = parse_list("--range", &range.replace(':', ","))?;
            if r.len() != 2 || !(r[0] > 0.0 && r[1] > r[0]) {
                return Err(input(format!("--range `{range}`: expected FROM:TO with 0 < FROM < TO")));
            }
            Ok(log_space(r[0], r[1], n))
        })
        .collect()
}

/// Checks `request` against a model with `np` parameters; nothing is allocated beyond
/// [`MAX_RUNS`].
pub fn plan(request: &CompareRequest, np: usize) -> Result<ComparePlan, WorkflowError> {
    let targets = points("--targets", &request.targets, np)?;
    let initials = match (&request.initials, request.grid) {
        (Some(text), _) => points("--initials", text, np)?,
        (None, Some(n)) if n >= 2 => {
            // Counted before the grid is built: 10000^2 points would exhaust memory first.
            u32::try_from(np)
                .ok()
                .and_then(|d| n.checked_pow(d))
                .filter(|&c| c <= MAX_RUNS)
                .ok_or_else(|| {
                    input(format!(
                        "--grid {n}: {n}^{np} initial guesses, more than the {MAX_RUNS} runs compare accepts; use a smaller --grid"
                    ))
                })?;
            axes_grid(&grid_axes(&request.range, np, n)?)
        }
        _ => return Err(input("give --grid N (N ≥ 2) or --initials K1:K2,…")),
    };
    let named: Vec<String> = request.strategies.split(',').map(|s| s.trim().to_string()).collect();
    let strategies =
        checked_strategies(&registry::registry(), &named).map_err(|e| input(format!("--strategies: {e}")))?;
    // Beyond ±15 decimals rounding either changes nothing a double holds or overflows to NaN.
    if let Some(d) = request.decimals.filter(|d| !(-15..=15).contains(d)) {
        return Err(input(format!(
            "--decimals {d}: must be between -15 and 15 (a double holds about 16 digits)"
        )));
    }
    let total_runs = targets.len().saturating_mul(initials.len()).saturating_mul(strategies.len());
    if total_runs > MAX_RUNS {
        return Err(input(format!(
            "{} targets × {} initial guesses × {} strategies = {total_runs} runs, more than the {MAX_RUNS} compare accepts",
            targets.len(),
            initials.len(),
            strategies.len()
        )));
    }
    if let Some(s) = request.std_hz {
        if !(s.is_finite() && s > 0.0) {
            return Err(input(format!("--std-hz {s}: must be a positive finite number")));
        }
    }
    if request.budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    let settings = CompareSettings {
        reference: ReferenceSettings {
            modes: request.modes.unwrap_or(np).max(np),
            decimals: request.decimals,
            std_hz: request.std_hz,
        },
        max_iterations: request.max_iterations,
        budget: request.budget,
    };
    Ok(ComparePlan { targets, initials, strategies, settings, timing: request.timing })
}

/// What the data say about one parameter of a run: `true`, `false` or the one bound known.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum RunIdentifiability {
    /// Determined (`true`) or not at all (`false`).
    Flag(bool),
    /// Only a lower bound.
    Lower {
        /// The bound.
        lower_bound: f64,
    },
    /// Only an upper bound.
    Upper {
        /// The bound.
        upper_bound: f64,
    },
}

impl From<&Identifiability> for RunIdentifiability {
    fn from(i: &Identifiability) -> Self {
        match *i {
            Identifiability::Determined => Self::Flag(true),
            Identifiability::LowerBoundOnly { lower } => Self::Lower { lower_bound: lower },
            Identifiability::UpperBoundOnly { upper } => Self::Upper { upper_bound: upper },
            Identifiability::Undetermined => Self::Flag(false),
        }
    }
}

/// One run of a comparison: the run's own fields and, on request, its time and statistics.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunReport {
    /// Strategy name.
    pub strategy: String,
    /// Target, initial guess, outcome, iterations, evaluations, estimate, relative error.
    #[serde(flatten)]
    pub run: CompareRun,
    /// Wall-clock time, when asked for.
    pub seconds: Option<f64>,
    /// Other equally good solutions (converged runs).
    pub alternative_solutions: Option<Vec<Vec<f64>>>,
    /// Identifiability of each parameter (with a reference std).
    pub identifiable: Option<Vec<RunIdentifiability>>,
}

impl RunReport {
    /// The report of `r`, with its time when `timing`.
    pub fn new(r: &CompareRun, timing: bool) -> Self {
        Self {
            strategy: r.strategy.clone(),
            run: r.clone(),
            seconds: timing.then_some(r.seconds),
            alternative_solutions: r.outcome.converged.then(|| r.alternatives.clone()),
            identifiable: r.identifiability.as_ref().map(|ids| ids.iter().map(Into::into).collect()),
        }
    }
}

/// Per target and strategy: how many runs converged, how fast, how accurately.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Target parameters.
    pub target: Vec<f64>,
    /// Strategy name.
    pub strategy: String,
    /// Runs.
    pub runs: usize,
    /// Converged runs.
    pub converged: usize,
    /// Converged runs within [`WITHIN_1E6`] of the target.
    #[serde(rename = "converged_within_1e-6")]
    pub converged_within_1e6: usize,
    /// Converged runs for which another solution fits the data at least as well (the
    /// equally-good test of `analysis::alternatives`; a better one passes it too).
    pub ambiguous: usize,
    /// Median iterations of the converged runs.
    pub median_iterations: Option<usize>,
    /// Most iterations of the converged runs.
    pub max_iterations: Option<usize>,
    /// Largest relative error of the converged runs (`null` when none converged: no error to
    /// report, not a perfect one).
    pub max_relative_error: Option<f64>,
    /// Runs cut short by their evaluation budget (`--budget`).
    pub budget_exhausted: usize,
}

/// The summary of `runs` per target and strategy.
pub fn summarise(runs: &[CompareRun], targets: &[Vec<f64>], strategies: &[String]) -> Vec<Summary> {
    let mut out = Vec::new();
    for t in targets {
        for s in strategies {
            let group: Vec<&CompareRun> =
                runs.iter().filter(|r| &r.target == t && &r.strategy == s).collect();
            let conv: Vec<&&CompareRun> = group.iter().filter(|r| r.outcome.converged).collect();
            let mut iters: Vec<usize> = conv.iter().map(|r| r.outcome.iterations).collect();
            iters.sort_unstable();
            out.push(Summary {
                target: t.clone(),
                strategy: s.clone(),
                runs: group.len(),
                converged: conv.len(),
                converged_within_1e6: conv.iter().filter(|r| r.relative_error <= WITHIN_1E6).count(),
                ambiguous: conv.iter().filter(|r| !r.alternatives.is_empty()).count(),
                median_iterations: (!iters.is_empty()).then(|| iters[iters.len() / 2]),
                max_iterations: iters.last().copied(),
                max_relative_error: conv.iter().map(|r| r.relative_error).reduce(f64::max),
                budget_exhausted: group.iter().filter(|r| r.budget_exhausted).count(),
            });
        }
    }
    out
}

/// Per strategy: runs, converged runs, and converged runs within [`AT_TARGET`] of the target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Basin {
    /// Strategy name.
    pub strategy: String,
    /// Runs.
    pub runs: usize,
    /// Converged runs.
    pub converged: usize,
    /// Converged runs at the target.
    pub at_target: usize,
}

/// The basin of each strategy over `runs` (one target).
pub fn basins(runs: &[CompareRun], strategies: &[String]) -> Vec<Basin> {
    strategies
        .iter()
        .map(|s| {
            let group: Vec<_> = runs.iter().filter(|r| &r.strategy == s).collect();
            Basin {
                strategy: s.clone(),
                runs: group.len(),
                converged: group.iter().filter(|r| r.outcome.converged).count(),
                at_target: group
                    .iter()
                    .filter(|r| r.outcome.converged && r.relative_error <= AT_TARGET)
                    .count(),
            }
        })
        .collect()
}

/// A comparison's report.
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// The model's label.
    pub model: String,
    /// The eigen-solver's name.
    pub solver: String,
    /// Each parameter's unit as declared (empty when none was), by name: the unit of targets,
    /// initial guesses and estimates.
    pub units: crate::Named<String>,
    /// Reference modes, the decimals their frequencies were rounded to, their standard
    /// deviation (Hz).
    #[serde(flatten)]
    pub reference: ReferenceSettings,
    /// Every run.
    pub runs: Vec<RunReport>,
    /// Per target and strategy.
    pub summary: Vec<Summary>,
    /// Plot files written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Vec<String>>,
    /// The runs as computed (for maps).
    #[serde(skip)]
    pub raw: Vec<CompareRun>,
}

/// Runs `plan` on `model`; `on_run` sees each run's report as it finishes (progress, a stream).
pub fn run(
    label: &str,
    model: &(dyn StructuralModel + Sync),
    solver: &(dyn EigenSolver + Sync),
    plan: &ComparePlan,
    mut on_run: impl FnMut(&RunReport),
) -> Result<CompareReport, WorkflowError> {
    let runs =
        run_grid(&model, &solver, &plan.targets, &plan.initials, &plan.strategies, &plan.settings, |r| {
            on_run(&RunReport::new(r, plan.timing))
        })
        .map_err(|e| input(format!("reference data: {e}")))?;
    Ok(CompareReport {
        model: label.to_string(),
        solver: solver.name().to_string(),
        units: crate::simulate::units_of(model),
        reference: plan.settings.reference.clone(),
        runs: runs.iter().map(|r| RunReport::new(r, plan.timing)).collect(),
        summary: summarise(&runs, &plan.targets, &plan.strategies),
        plots: None,
        raw: runs,
    })
}
