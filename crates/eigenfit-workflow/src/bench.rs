//! `bench`: strategies × problems × starts, run in parallel within a budget per run; one record
//! per run and a summary per problem and strategy (docs/strategies.md).
//!
//! A problem is a model, measured frequencies (with standard deviations), the truth and where
//! starts are drawn. The built-ins are the paper's Tables 2–5 (the paper rotor, its two lowest
//! modes rounded to 3 decimals as in its Table 1, with 0.1 % std; starts log-uniform in
//! [1e2, 1e8] N/m, the span of the paper's initial guesses; reached within 1 %, Table 4 within
//! 2 %), a 3-storey shear frame (three modes, 0.1 % std, starts in [2e6, 2e8] N/m) and the
//! five-group truss (`eigenfit_core::model::truss`: five EA from eight modes, 0.2 % std, starts
//! within a decade of the design) and a ROSS run-up (`ross-runup`, [`crate::bench_runup`]: twelve
//! factors on two bearings' coefficient curves from 60 whirl frequencies, std 0.01 Hz, starts
//! 0.6–1.5× the truth; reached within 1e-3); a path to a problem file (TOML) is a problem too:
//!
//! ```toml
//! model = "rotor.toml"          # relative to this file: a rotor or a kind = "matrices" model
//! measured = "measured.csv"     # mode,frequency_hz,std_hz (optional: synthesised at the truth,
//! modes = 3                     #   this many modes with relative_std, when no file is given)
//! relative_std = 0.001
//! truth = { k_A = 1e5, k_B = 1e5 }
//! tolerance = 0.01              # reached_truth: every parameter within this relative error
//! [starts]                      # optional ranges starts are drawn from (default: search range)
//! k_A = [1e3, 1e7]
//! ```
//!
//! A problem file whose `model` is a ROSS rotor takes a run-up CSV as `measured` (required) and
//! its `truth` as factors on the file's coefficient curves by parameter name (`kxx_DE = 1.2`,
//! `estimate`'s `scales`): the truth's names are the parameters fitted. On a run-up a strategy
//! that solves with the model's eigenvalues (the paper's newton and p-step, or a user's that says
//! so, `UpdateStrategy::needs_eigenvalues`) is recorded `refused`.
//!
//! Start `i` of a problem is drawn uniformly in each parameter's scaled coordinate (ln p for a
//! log parameter) within the start range, from the seed and `i` only: every strategy starts from
//! the same points. A sampler ignores the start and uses seed + `i` as its seed; its `final` is
//! its best sample.

use crate::bench_runup::RunupCase;
use crate::error::{input, WorkflowError};
use crate::named::Named;
use crate::posterior::SamplingError;
use crate::source::ModelSource;
use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::matrix::System;
use eigenfit_core::measurement::measured_csv::{self, shown};
use eigenfit_core::measurement::synthetic::{synthesise, NoiseRng};
use eigenfit_core::measurement::{MeasuredMode, Measurement};
use eigenfit_core::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use eigenfit_core::problem::{Objective, Problem, ResidualKind};
use eigenfit_core::update::{registry, Budget, Driver, Method, Posterior, Sampler};
use eigenfit_rotor::presets;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The built-in problems.
pub const BUILTIN_PROBLEMS: [&str; 7] = [
    "paper-table2",
    "paper-table3",
    "paper-table4",
    "paper-table5",
    "shear-frame",
    "five-group-truss",
    "ross-runup",
];

/// Evaluations one local run may spend when no budget is given.
pub const DEFAULT_RUN_BUDGET: usize = 5000;

/// Samples a sampler draws in a bench when its name sets none.
pub const DEFAULT_BENCH_SAMPLES: usize = 500;

/// A model that can be shared by the parallel runs.
pub type SharedModel = Arc<dyn StructuralModel + Send + Sync>;

/// What a problem fits.
#[derive(Clone)]
pub enum ProblemData {
    /// A structural model's natural frequencies.
    Modal {
        /// The model.
        model: SharedModel,
        /// The measured frequencies, with standard deviations.
        measured: Measurement,
        /// The solver by name (as `--solver`).
        solver: String,
    },
    /// A ROSS rotor's run-up: factors on its bearings' coefficient curves.
    Runup(Arc<RunupCase>),
}

/// One benchmark problem.
#[derive(Clone)]
pub struct BenchProblem {
    /// Its name in records.
    pub name: String,
    /// The model and the data.
    pub data: ProblemData,
    /// The true parameters (the model's order).
    pub truth: Vec<f64>,
    /// Where starts are drawn, per parameter (values, not scaled).
    pub start_range: Vec<(f64, f64)>,
    /// Relative error within which every parameter has reached the truth.
    pub tolerance: f64,
}

impl BenchProblem {
    /// The parameters.
    pub fn parameters(&self) -> &ParameterSet {
        match &self.data {
            ProblemData::Modal { model, .. } => model.parameters(),
            ProblemData::Runup(case) => case.parameters(),
        }
    }

    /// The parameters' names.
    pub fn names(&self) -> Vec<String> {
        self.parameters().iter().map(|p| p.name.clone()).collect()
    }

    /// Start `i` under `seed`: uniform in each parameter's scaled coordinate within the start
    /// range.
    pub fn start(&self, seed: u64, i: usize) -> Vec<f64> {
        let mut rng = NoiseRng(
            seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03),
        );
        self.parameters()
            .iter()
            .zip(&self.start_range)
            .map(|(p, &(lo, hi))| {
                let (a, b) = (p.to_scaled(lo), p.to_scaled(hi));
                p.from_scaled(a + rng.uniform() * (b - a)).clamp(p.lower, p.upper)
            })
            .collect()
    }

    /// Whether `p` is within the tolerance of the truth in every parameter.
    pub fn reached(&self, p: &[f64]) -> bool {
        p.len() == self.truth.len()
            && p.iter().zip(&self.truth).all(|(v, t)| ((v - t) / t).abs() <= self.tolerance)
    }
}

/// A structural problem's data.
fn modal(model: SharedModel, measured: Measurement, solver: &str) -> ProblemData {
    ProblemData::Modal { model, measured, solver: solver.to_string() }
}

/// A 3-storey shear frame: floor masses 1e4, 1e4 and 8e3 kg on storey stiffnesses k1 (ground
/// storey) to k3, log scale, bounds [1e5, 1e10] N/m.
struct ShearFrame {
    masses: Vec<f64>,
    params: ParameterSet,
}

impl ShearFrame {
    fn new() -> Self {
        let k = |i: usize| {
            Parameter::new(format!("k{}", i + 1), "N/m", 1e7).with_bounds(1e5, 1e10).with_scale(Scale::Log)
        };
        let params = ParameterSet::new((0..3).map(k).collect()).expect("valid built-in parameters"); // proof: fixed names and bounds
        Self { masses: vec![1e4, 1e4, 8e3], params }
    }
}

impl StructuralModel for ShearFrame {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }
    fn dofs(&self) -> usize {
        self.masses.len()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let n = self.masses.len();
        let mut k = nalgebra::DMatrix::zeros(n, n);
        for (i, &ki) in p.iter().enumerate() {
            k[(i, i)] += ki;
            if i > 0 {
                k[(i - 1, i - 1)] += ki;
                k[(i - 1, i)] -= ki;
                k[(i, i - 1)] -= ki;
            }
        }
        Ok(System::new(
            k,
            nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&self.masses)),
        )?)
    }
}

/// Exact frequencies of `model` at `truth` (rounded to `decimals` when given), each with std
/// `relative_std`·f.
fn synthetic(
    model: &dyn StructuralModel,
    truth: &[f64],
    modes: usize,
    relative_std: f64,
    decimals: Option<i32>,
) -> Result<Measurement, WorkflowError> {
    let exact = synthesise(model, &DenseSolver, truth, modes, relative_std, None)
        .map_err(|e| input(format!("synthesising the data at the truth: {e}")))?;
    let round = |f: f64| decimals.map_or(f, |d| (f * 10f64.powi(d)).round() / 10f64.powi(d));
    let modes = exact
        .modes()
        .iter()
        .map(|m| MeasuredMode { frequency_hz: round(m.frequency_hz), ..m.clone() })
        .collect();
    Measurement::new(modes).map_err(|e| input(e.to_string()))
}

/// A built-in problem by name.
pub fn builtin(name: &str) -> Option<Result<BenchProblem, WorkflowError>> {
    let paper = |truth: [f64; 2], tolerance: f64| -> Result<BenchProblem, WorkflowError> {
        let rotor = eigenfit_rotor::UpdatableRotor::new(presets::paper_rotor())
            .map_err(|e| WorkflowError::Failure(e.to_string()))?;
        let model: SharedModel = Arc::new(rotor);
        let measured = synthetic(model.as_ref(), &truth, 2, 1e-3, Some(3))?;
        Ok(BenchProblem {
            name: name.to_string(),
            data: modal(model, measured, "dense"),
            truth: truth.to_vec(),
            // The paper's initial guesses span 1e2 to 1e8 N/m.
            start_range: vec![(1e2, 1e8); 2],
            tolerance,
        })
    };
    Some(match name {
        "paper-table2" => paper([1e2, 1e2], 0.01),
        "paper-table3" => paper([1e5, 1e5], 0.01),
        // Rigid supports barely move the frequencies: the exact solution of the rounded data is
        // (1.0065e8, 9.897e7), 1.03 % from the truth (the paper's own answer, 1.0508e8, is 5 % off).
        "paper-table4" => paper([1e8, 1e8], 0.02),
        "paper-table5" => paper([1e5, 1e3], 0.01),
        "shear-frame" => {
            let model: SharedModel = Arc::new(ShearFrame::new());
            let truth = vec![2e7, 1.8e7, 1.5e7];
            synthetic(model.as_ref(), &truth, 3, 1e-3, None).map(|measured| BenchProblem {
                name: name.to_string(),
                data: modal(model, measured, "dense"),
                truth,
                start_range: vec![(2e6, 2e8); 3],
                tolerance: 0.01,
            })
        }
        // Five member groups' EA from the 8 lowest modes (0.2 % std, the example's noise level,
        // here without the noise): more data than parameters, the bottom chord 25 % weaker than
        // designed; starts within a decade of the design either way.
        "five-group-truss" => {
            use eigenfit_core::model::truss::{Truss, DESIGN, TRUTH};
            let model: SharedModel = Arc::new(Truss::new());
            synthetic(model.as_ref(), &TRUTH, 8, 2e-3, None).map(|measured| BenchProblem {
                name: name.to_string(),
                data: modal(model, measured, "dense"),
                truth: TRUTH.to_vec(),
                start_range: DESIGN.iter().map(|&d| (d / 10.0, d * 10.0)).collect(),
                tolerance: 0.01,
            })
        }
        // Twelve bearing factors from ROSS's run-up (6 modes at 10 speeds with whirl); starts
        // 0.6–1.5× the truth, the range `fit_runup`'s staging is measured on (docs/rotordynamics.md).
        "ross-runup" => crate::bench_runup::builtin().and_then(|(case, truth)| {
            let names: Vec<String> = case.parameters().iter().map(|p| p.name.clone()).collect();
            let truth: Vec<f64> = names
                .iter()
                .map(|n| truth.iter().find(|(t, _)| t == n).map(|(_, v)| *v))
                .collect::<Option<_>>()
                .ok_or_else(|| WorkflowError::Failure("runup_truth.json lacks a factor".into()))?;
            Ok(BenchProblem {
                name: name.to_string(),
                start_range: truth.iter().map(|&t| (0.6 * t, 1.5 * t)).collect(),
                truth,
                data: ProblemData::Runup(Arc::new(case)),
                tolerance: 1e-3,
            })
        }),
        _ => return None,
    })
}

/// A problem file's contents.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ProblemFile {
    model: PathBuf,
    measured: Option<PathBuf>,
    truth: toml::Table,
    modes: Option<usize>,
    relative_std: Option<f64>,
    tolerance: Option<f64>,
    name: Option<String>,
    solver: Option<String>,
    starts: Option<toml::Table>,
}

fn number(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64)).filter(|x| x.is_finite())
}

/// Loads a problem file (TOML; paths in it relative to the file).
pub fn load_problem_file(path: &Path) -> Result<BenchProblem, WorkflowError> {
    let at = |msg: String| input(format!("{}: {msg}", path.display()));
    crate::model::check_model_file(path)?;
    let text = std::fs::read_to_string(path).map_err(|e| at(format!("cannot read: {e}")))?;
    let file: ProblemFile = toml::from_str(&text)
        .map_err(|e| at(eigenfit_core::names::with_serde_hint(e.to_string().trim_end())))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let ross = crate::rotordynamics::ross_model(Some(&dir.join(&file.model))).is_some();
    let (data, truth) = if ross { runup_file(&file, dir, &at)? } else { modal_file(&file, dir, &at)? };
    let tolerance = file.tolerance.unwrap_or(0.01);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(at(format!("tolerance = {tolerance}: must be a number greater than zero")));
    }
    let mut problem = BenchProblem { name: String::new(), data, truth, start_range: Vec::new(), tolerance };
    let params = problem.parameters();
    let mut start_range: Vec<(f64, f64)> = params.iter().map(|p| p.search_range()).collect();
    for (key, value) in file.starts.iter().flatten() {
        let i = params.index_of(key).map_err(|e| at(format!("starts: {e}")))?;
        let pair =
            value.as_array().filter(|a| a.len() == 2).and_then(|a| Some((number(&a[0])?, number(&a[1])?)));
        let (lo, hi) = pair.ok_or_else(|| at(format!("starts: `{key}` must be [low, high]")))?;
        let p = &params.as_slice()[i];
        if !(lo < hi && lo >= p.lower && hi <= p.upper && (p.scale == Scale::Linear || lo > 0.0)) {
            return Err(at(format!(
                "starts: `{key}` = [{lo}, {hi}] must be increasing and within the bounds"
            )));
        }
        start_range[i] = (lo, hi);
    }
    problem.start_range = start_range;
    problem.name = file.name.clone().unwrap_or_else(|| path.display().to_string());
    Ok(problem)
}

/// The truth of a problem file in the order of `params`: every parameter given, each a finite
/// number within its bounds.
fn truth_of(
    params: &ParameterSet,
    table: &toml::Table,
    at: &dyn Fn(String) -> WorkflowError,
) -> Result<Vec<f64>, WorkflowError> {
    let mut truth = vec![f64::NAN; params.len()];
    for (key, value) in table {
        let i = params.index_of(key).map_err(|e| at(format!("truth: {e}")))?;
        truth[i] = number(value).ok_or_else(|| at(format!("truth: `{key}` must be a finite number")))?;
    }
    if let Some(missing) = params.iter().zip(&truth).find(|(_, t)| t.is_nan()) {
        return Err(at(format!("truth: no value for parameter `{}`", missing.0.name)));
    }
    params.check(&truth).map_err(|e| at(format!("truth: {e}")))?;
    Ok(truth)
}

/// A problem file on a planar rotor or a matrices model: its data and truth.
fn modal_file(
    file: &ProblemFile,
    dir: &Path,
    at: &dyn Fn(String) -> WorkflowError,
) -> Result<(ProblemData, Vec<f64>), WorkflowError> {
    let source = ModelSource {
        model: Some(dir.join(&file.model)),
        solver: file.solver.clone().unwrap_or_else(|| "auto".into()),
        ..ModelSource::default()
    };
    let (any, label) = source.load_any()?;
    let model: SharedModel = match any {
        crate::model::AnyModel::Rotor(rotor) => {
            Arc::new(eigenfit_rotor::UpdatableRotor::new(rotor).map_err(|e| at(format!("{label}: {e}")))?)
        }
        crate::model::AnyModel::Matrices(m) => Arc::new(m),
        crate::model::AnyModel::Registered(m) => Arc::from(m),
    };
    let params = model.parameters();
    let truth = truth_of(params, &file.truth, at)?;
    let measured = match &file.measured {
        Some(csv) => {
            let csv = dir.join(csv);
            measured_csv::read_with_notes(&csv).map_err(|e| input(e.to_string()))?.0
        }
        None => {
            let rel = file.relative_std.unwrap_or(1e-3);
            if !(rel.is_finite() && rel > 0.0) {
                return Err(at(format!("relative_std = {rel}: must be a number greater than zero")));
            }
            let modes = file.modes.unwrap_or(params.len());
            if modes == 0 || modes > model.dofs() {
                return Err(at(format!(
                    "modes = {modes}: must be between 1 and the model's {} DOFs",
                    model.dofs()
                )));
            }
            synthetic(model.as_ref(), &truth, modes, rel, None).map_err(|e| at(e.to_string()))?
        }
    };
    Ok((ProblemData::Modal { model, measured, solver: source.solver }, truth))
}

/// A problem file on a ROSS rotor: the run-up CSV at `measured` (required: a run-up is not
/// synthesised), the factors named by the truth's keys.
fn runup_file(
    file: &ProblemFile,
    dir: &Path,
    at: &dyn Fn(String) -> WorkflowError,
) -> Result<(ProblemData, Vec<f64>), WorkflowError> {
    for (key, given) in [
        ("modes", file.modes.is_some()),
        ("relative_std", file.relative_std.is_some()),
        ("solver", file.solver.is_some()),
    ] {
        if given {
            return Err(at(format!(
                "`{key}` does not apply to a ROSS run-up (the data are the run-up CSV in `measured`)"
            )));
        }
    }
    let measured = file.measured.as_ref().ok_or_else(|| {
        at("a ROSS rotor's problem needs `measured`, a run-up CSV (speed_rpm,mode,frequency_hz,std_hz)"
            .into())
    })?;
    let names: Vec<&str> = file.truth.keys().map(String::as_str).collect();
    if names.is_empty() {
        return Err(at(
            "truth: name at least one factor (e.g. `kxx_DE = 1.2`, a factor on the file's kxx of bearing DE)"
                .into(),
        ));
    }
    let case = crate::bench_runup::from_files(&dir.join(&file.model), &dir.join(measured), &names)
        .map_err(|e| at(e.to_string()))?;
    let truth = truth_of(case.parameters(), &file.truth, at)?;
    Ok((ProblemData::Runup(Arc::new(case)), truth))
}

/// A problem by built-in name or file path.
pub fn problem(name: &str) -> Result<BenchProblem, WorkflowError> {
    if let Some(p) = builtin(name) {
        return p;
    }
    let path = Path::new(name);
    if path.extension().is_some_and(|e| e == "toml") || path.exists() {
        return load_problem_file(path);
    }
    let hint = eigenfit_core::names::nearest(name, &BUILTIN_PROBLEMS)
        .map_or(String::new(), |n| format!(" (did you mean `{n}`?)"));
    Err(input(format!(
        "--problems: `{}` is neither a built-in problem ({}) nor a problem file{hint}",
        shown(name),
        BUILTIN_PROBLEMS.join(", ")
    )))
}

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchRequest {
    /// Problem names or files.
    pub problems: Vec<String>,
    /// Strategy names from the registry, settings after colons.
    pub strategies: Vec<String>,
    /// Starts per problem and strategy.
    pub starts: usize,
    /// Seed of the starts (and of samplers).
    pub seed: u64,
    /// Evaluations each run may spend (`None`: [`DEFAULT_RUN_BUDGET`] for a local strategy, a
    /// sampler's own bound for a sampler).
    pub budget: Option<usize>,
    /// Iteration limit of a local run.
    pub max_iterations: usize,
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchRecord {
    /// The problem's name.
    pub problem: String,
    /// The strategy's name with its settings.
    pub strategy: String,
    /// The start's number.
    pub start: usize,
    /// Where it started (a sampler: nowhere, empty).
    pub initial: Named<f64>,
    /// How it ended: a termination (`converged`, `stalled`, `diverged`, `iteration-limit`,
    /// `budget-exhausted`), `sampled`, or `refused` (the strategy does not apply).
    pub verdict: String,
    /// The why, when it did not converge.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Model evaluations spent.
    pub evaluations: usize,
    /// Iterations (a sampler: its stages).
    pub iterations: usize,
    /// Where it ended (a sampler: its best sample).
    #[serde(rename = "final")]
    pub final_parameters: Named<f64>,
    /// χ² = Σ ((f_measured − f_model)/σ)² at the final point (NaN where the model cannot be
    /// evaluated there).
    pub chi2: f64,
    /// Every parameter within the problem's tolerance of the truth.
    pub reached_truth: bool,
    /// A sampler's ln evidence.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log_evidence: Option<f64>,
    /// A regularised strategy's λ and the rule that chose it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regularisation: Option<eigenfit_core::update::Regularisation>,
}

/// One problem and strategy over every start.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchSummary {
    /// The problem.
    pub problem: String,
    /// The strategy.
    pub strategy: String,
    /// Runs.
    pub runs: usize,
    /// Fraction of runs that reached the truth.
    pub success_rate: f64,
    /// Median evaluations over all runs.
    pub median_evaluations: f64,
    /// Median evaluations of the runs that reached the truth (`null` when none did).
    pub median_evaluations_success: Option<f64>,
    /// Runs per verdict.
    pub verdicts: Named<usize>,
}

/// A problem as the report describes it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProblemInfo {
    /// Name.
    pub name: String,
    /// The truth.
    pub truth: Named<f64>,
    /// Measured frequencies, Hz.
    pub measured_hz: Vec<f64>,
    /// Their standard deviations, Hz (`null` where not given).
    pub std_hz: Vec<Option<f64>>,
    /// Relative error within which a run has reached the truth.
    pub tolerance: f64,
}

/// `bench`'s report (the `--json` object).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    /// The problems.
    pub problems: Vec<ProblemInfo>,
    /// The strategies, as named.
    pub strategies: Vec<String>,
    /// Starts per problem and strategy.
    pub starts: usize,
    /// The seed.
    pub seed: u64,
    /// One per run, ordered by problem, strategy, start.
    pub records: Vec<BenchRecord>,
    /// One per problem and strategy.
    pub summary: Vec<BenchSummary>,
}

impl BenchReport {
    /// Whether every problem and strategy reached the truth at least once (exit 0; else 3).
    pub fn every_pair_succeeded(&self) -> bool {
        self.summary.iter().all(|s| s.success_rate > 0.0)
    }
}

impl BenchProblem {
    /// χ² in Hz at `p` (NaN where the model cannot be evaluated or a std is missing).
    fn chi2(&self, p: &[f64]) -> f64 {
        match &self.data {
            ProblemData::Modal { model, measured, solver } => {
                let Ok(solver) = solver_by_name(solver) else { return f64::NAN };
                if !measured.has_std() {
                    return f64::NAN;
                }
                let hz = Problem::new(model.as_ref(), solver.as_ref(), measured.clone())
                    .with_kind(ResidualKind::FrequencyHz);
                hz.cost(p).map_or(f64::NAN, |c| 2.0 * c)
            }
            ProblemData::Runup(case) => case.chi2(p),
        }
    }

    /// `f` on the least-squares objective a local strategy minimises.
    fn with_objective<T>(&self, f: impl FnOnce(&dyn Objective) -> T) -> Result<T, WorkflowError> {
        Ok(match &self.data {
            ProblemData::Modal { model, measured, solver } => {
                let solver = solver_by_name(solver)?;
                f(&Problem::new(model.as_ref(), solver.as_ref(), measured.clone()))
            }
            ProblemData::Runup(case) => f(&case.objective()),
        })
    }

    /// The posterior under `sampler` (Gaussian in Hz with the measured std).
    fn sample(&self, sampler: &dyn Sampler, seed: u64, budget: &Budget) -> Result<Posterior, SamplingError> {
        match &self.data {
            ProblemData::Modal { model, measured, solver } => {
                let solver = solver_by_name(solver).map_err(SamplingError::Failed)?;
                crate::posterior::sample(
                    model.as_ref(),
                    solver.as_ref(),
                    measured,
                    &self.name,
                    sampler,
                    seed,
                    budget,
                )
            }
            ProblemData::Runup(case) => case.sample(sampler, seed, budget),
        }
    }

    /// Why `method` does not apply to this problem, if it does not: a strategy that solves with
    /// the model's eigenvalues ([`UpdateStrategy::needs_eigenvalues`](eigenfit_core::update::UpdateStrategy::needs_eigenvalues), built-in or registered)
    /// on a run-up, whose rows are whirl frequencies at many speeds.
    fn refuses(&self, method: &Method) -> Option<String> {
        match (&self.data, method) {
            (ProblemData::Runup(_), Method::Local(s)) if s.needs_eigenvalues() => Some(format!(
                "not applicable: {} solves with the model's eigenvalues and their sensitivities (the paper's \
                 eq. 27–28); a run-up's rows are whirl frequencies at many speeds, not eigenvalues of K − λM",
                s.name()
            )),
            _ => None,
        }
    }
}

/// The eigen-solver by name (as `--solver`).
fn solver_by_name(name: &str) -> Result<Box<dyn EigenSolver>, WorkflowError> {
    ModelSource { solver: name.to_string(), ..ModelSource::default() }.solver()
}

/// One run of `strategy` on `problem` from start `start`.
fn run_one(
    problem: &BenchProblem,
    spec: &str,
    start: usize,
    request: &BenchRequest,
) -> Result<BenchRecord, WorkflowError> {
    let names = problem.names();
    let (name, method) = registry::build(spec).map_err(|e| input(format!("--strategies: {e}")))?;
    let initial = problem.start(request.seed, start);
    let record =
        |verdict: &str, reason: Option<String>, evaluations, iterations, fin: &[f64], log_evidence| {
            BenchRecord {
                problem: problem.name.clone(),
                strategy: name.clone(),
                start,
                initial: Named::new(&names, initial.iter().copied()),
                verdict: verdict.to_string(),
                reason,
                evaluations,
                iterations,
                final_parameters: Named::new(&names, fin.iter().copied()),
                chi2: problem.chi2(fin),
                reached_truth: problem.reached(fin),
                log_evidence,
                regularisation: None,
            }
        };
    if let Some(why) = problem.refuses(&method) {
        return Ok(record("refused", Some(why), 0, 0, &initial, None));
    }
    match method {
        Method::Local(mut strategy) => {
            let budget = Budget::new(request.budget.unwrap_or(DEFAULT_RUN_BUDGET));
            let driver = Driver { max_iterations: request.max_iterations };
            let run = problem.with_objective(|objective| {
                driver.run_within(objective, strategy.as_mut(), &initial, &budget)
            })?;
            Ok(match run {
                Ok(est) => {
                    let why = (!est.termination.is_converged()).then(|| est.termination.to_string());
                    BenchRecord {
                        regularisation: est.regularisation.clone(),
                        ..record(
                            est.termination.label(),
                            why,
                            est.evaluations,
                            est.iterations,
                            &est.parameters,
                            None,
                        )
                    }
                }
                Err(e) => {
                    let verdict = if budget.exhausted() { "budget-exhausted" } else { "refused" };
                    record(verdict, Some(e.to_string()), budget.used(), 0, &initial, None)
                }
            })
        }
        Method::Sampler(sampler) => {
            let budget = Budget::new(request.budget.unwrap_or_else(|| sampler.most_evaluations()));
            let seed = request.seed.wrapping_add(start as u64);
            Ok(match problem.sample(sampler.as_ref(), seed, &budget) {
                Ok(post) => {
                    let best = post.best_sample().map_or_else(|| post.mean.clone(), <[f64]>::to_vec);
                    record(
                        "sampled",
                        None,
                        budget.used(),
                        post.stages.len() - 1,
                        &best,
                        Some(post.log_evidence),
                    )
                }
                Err(SamplingError::BudgetExhausted { limit }) => record(
                    "budget-exhausted",
                    Some(format!("the budget of {limit} model evaluations ran out while sampling")),
                    budget.used(),
                    0,
                    &initial,
                    None,
                ),
                Err(SamplingError::Failed(e)) => {
                    record("refused", Some(e.to_string()), budget.used(), 0, &initial, None)
                }
            })
        }
    }
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) })
}

/// The summary of `records` per problem and strategy, in their order of first appearance.
pub fn summarise(records: &[BenchRecord]) -> Vec<BenchSummary> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in records {
        let key = (r.problem.clone(), r.strategy.clone());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys.into_iter()
        .map(|(problem, strategy)| {
            let runs: Vec<&BenchRecord> =
                records.iter().filter(|r| r.problem == problem && r.strategy == strategy).collect();
            let ok: Vec<f64> =
                runs.iter().filter(|r| r.reached_truth).map(|r| r.evaluations as f64).collect();
            let mut verdicts: Vec<(String, usize)> = Vec::new();
            for r in &runs {
                match verdicts.iter_mut().find(|(v, _)| *v == r.verdict) {
                    Some((_, n)) => *n += 1,
                    None => verdicts.push((r.verdict.clone(), 1)),
                }
            }
            BenchSummary {
                runs: runs.len(),
                success_rate: ok.len() as f64 / runs.len().max(1) as f64,
                median_evaluations: median(runs.iter().map(|r| r.evaluations as f64).collect())
                    .unwrap_or(0.0),
                median_evaluations_success: median(ok),
                verdicts: Named(verdicts),
                problem,
                strategy,
            }
        })
        .collect()
}

/// Runs the bench: every problem × strategy × start, in parallel.
pub fn run(request: &BenchRequest) -> Result<BenchReport, WorkflowError> {
    if request.problems.is_empty() || request.strategies.is_empty() {
        return Err(input("--problems and --strategies each need at least one name"));
    }
    if request.starts == 0 {
        return Err(input("--starts 0: at least one start is needed"));
    }
    if request.budget == Some(0) {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    // Names are checked before any run: a typo fails at once.
    let mut strategies = Vec::new();
    for spec in &request.strategies {
        let spec = with_bench_samples(spec)?;
        registry::build(&spec).map_err(|e| input(format!("--strategies: {e}")))?;
        strategies.push(spec);
    }
    // Counted before the tasks are listed: 10⁹ starts would exhaust memory first.
    let runs = request.problems.len().saturating_mul(strategies.len()).saturating_mul(request.starts);
    if runs > crate::compare::MAX_RUNS {
        return Err(input(format!(
            "--starts {}: {} problems × {} strategies × {} starts = {runs} runs, more than the {} a bench accepts; \
             use fewer starts",
            request.starts,
            request.problems.len(),
            strategies.len(),
            request.starts,
            crate::compare::MAX_RUNS
        )));
    }
    let problems: Vec<BenchProblem> =
        request.problems.iter().map(|n| problem(n)).collect::<Result<_, _>>()?;
    let tasks: Vec<(usize, usize, usize)> = (0..problems.len())
        .flat_map(|p| (0..strategies.len()).flat_map(move |s| (0..request.starts).map(move |i| (p, s, i))))
        .collect();
    let records: Vec<BenchRecord> = tasks
        .par_iter()
        .map(|&(p, s, i)| run_one(&problems[p], &strategies[s], i, request))
        .collect::<Result<_, _>>()?;
    let summary = summarise(&records);
    Ok(BenchReport {
        problems: problems.iter().map(info).collect(),
        strategies: records.iter().fold(Vec::new(), |mut v, r| {
            if !v.contains(&r.strategy) {
                v.push(r.strategy.clone());
            }
            v
        }),
        starts: request.starts,
        seed: request.seed,
        records,
        summary,
    })
}

/// A registered strategy as `bench --list` shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StrategyInfo {
    /// Its name.
    pub name: String,
    /// What it is, in one line.
    pub summary: String,
    /// The settings it takes after colons.
    pub settings: Vec<String>,
}

/// `bench --list`: the built-in problems and the registered strategies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchListing {
    /// The built-in problems.
    pub problems: Vec<ProblemInfo>,
    /// The strategies in the process-wide registry.
    pub strategies: Vec<StrategyInfo>,
}

/// The built-in problems and the registered strategies.
pub fn list() -> Result<BenchListing, WorkflowError> {
    let problems =
        BUILTIN_PROBLEMS.iter().map(|name| problem(name).map(|p| info(&p))).collect::<Result<Vec<_>, _>>()?;
    let strategies = registry::registry()
        .factories()
        .iter()
        .map(|f| StrategyInfo {
            name: f.name().to_string(),
            summary: f.summary().to_string(),
            settings: f.settings().iter().map(|s| s.to_string()).collect(),
        })
        .collect();
    Ok(BenchListing { problems, strategies })
}

fn info(p: &BenchProblem) -> ProblemInfo {
    let (measured_hz, std_hz) = match &p.data {
        ProblemData::Modal { measured, .. } => {
            measured.modes().iter().map(|m| (m.frequency_hz, m.std_hz)).unzip()
        }
        ProblemData::Runup(case) => case.points().iter().map(|q| (q.frequency_hz, q.std_hz)).unzip(),
    };
    ProblemInfo {
        name: p.name.clone(),
        truth: Named::new(&p.names(), p.truth.iter().copied()),
        measured_hz,
        std_hz,
        tolerance: p.tolerance,
    }
}

/// A sampler's name with [`DEFAULT_BENCH_SAMPLES`] samples unless it sets its own.
fn with_bench_samples(spec: &str) -> Result<String, WorkflowError> {
    let (_, method) = registry::build(spec).map_err(|e| input(format!("--strategies: {e}")))?;
    let sets_samples = spec.split(':').skip(1).any(|kv| kv.trim().starts_with("samples"));
    Ok(match method {
        Method::Sampler(_) if !sets_samples => format!("{spec}:samples={DEFAULT_BENCH_SAMPLES}"),
        _ => spec.to_string(),
    })
}
