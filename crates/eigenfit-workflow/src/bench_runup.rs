//! A ROSS run-up as a bench problem (issue 32 item 1): a two-plane rotor saved by ROSS, whirl
//! frequencies measured over a run-up, and the true factors on the bearings' coefficient curves
//! (the run-up objective's parameters, [`RunupObjective`]: `kxx_DE = 1.2` is the file's kxx
//! table of bearing DE × 1.2, as `estimate`'s `scales`).
//!
//! The built-in `ross-runup` is the committed ROSS 2.3 fixture of the rotordynamics crate:
//! `runup_nominal.toml`, `runup_truth6.csv` (ROSS's 6 lowest modes at 10 speeds, 500–8500 rpm,
//! with whirl, std 0.01 Hz) and the twelve factors of `runup_truth.json`
//! (scripts/ross_runup_reference.py, scripts/ross_realistic_runups.py).

use crate::error::{input, WorkflowError};
use eigenfit_core::model::ParameterSet;
use eigenfit_core::problem::Objective;
use eigenfit_core::update::Sampler;
use eigenfit_rotordynamics::identify::{bearing_parameters, parse_runup, Parameter as Factor, RunupPoint};
use eigenfit_rotordynamics::objective::RunupObjective;
use eigenfit_rotordynamics::{ross_file, Rotor};
use std::path::Path;

/// The built-in run-up's rotor file (ROSS 2.3).
const NOMINAL_TOML: &str = include_str!("../../eigenfit-rotordynamics/tests/data/runup_nominal.toml");
/// Its run-up: 6 modes at 10 speeds with whirl and std.
const RUNUP_CSV: &str = include_str!("../../eigenfit-rotordynamics/tests/data/runup_truth6.csv");
/// The factors ROSS's truth rotor has on the file's coefficient curves.
const TRUTH_JSON: &str = include_str!("../../eigenfit-rotordynamics/tests/data/runup_truth.json");

/// A ROSS rotor, the factors fitted on it and the measured run-up.
pub struct RunupCase {
    rotor: Rotor,
    factors: Vec<Factor>,
    points: Vec<RunupPoint>,
    parameters: ParameterSet,
}

impl RunupCase {
    /// The case of `factors` (full parameter names, `kxx_DE`) on `rotor` against `points`;
    /// refuses a selection the run-up cannot fit, as `estimate` does.
    pub fn new(rotor: Rotor, factors: &[&str], points: Vec<RunupPoint>) -> Result<Self, WorkflowError> {
        let factors = bearing_parameters(&rotor, factors).map_err(|e| input(e.to_string()))?;
        eigenfit_rotordynamics::identify::check_selection(&rotor, &factors, &points)
            .map_err(|e| input(e.to_string()))?;
        let parameters = RunupObjective::new(&rotor, factors.clone(), &points, None)
            .map_err(|e| input(e.to_string()))?
            .parameters()
            .clone();
        Ok(Self { rotor, factors, points, parameters })
    }

    /// The fitted factors, in the objective's order.
    pub fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }

    /// The measured points.
    pub fn points(&self) -> &[RunupPoint] {
        &self.points
    }

    /// The run-up's least-squares objective (residuals in std units, or relative without std).
    pub fn objective(&self) -> RunupObjective<'_> {
        RunupObjective::new(&self.rotor, self.factors.clone(), &self.points, None)
            .expect("checked when the case was made") // proof: `new` built the same objective
    }

    /// χ² = Σ ((f_measured − f_model)/σ)² at `p` (NaN without std or where the model fails).
    pub fn chi2(&self, p: &[f64]) -> f64 {
        if self.points.iter().any(|q| q.std_hz.is_none()) {
            return f64::NAN;
        }
        self.objective().cost(p).map_or(f64::NAN, |c| 2.0 * c)
    }

    /// Samples the posterior of the factors with `sampler` (Gaussian likelihood in Hz with the
    /// run-up's std, uniform prior in ln factor between the bounds).
    pub fn sample(
        &self,
        sampler: &dyn Sampler,
        seed: u64,
        budget: &eigenfit_core::update::Budget,
    ) -> Result<eigenfit_core::update::Posterior, crate::posterior::SamplingError> {
        let sigma: Vec<Option<f64>> = self.points.iter().map(|p| p.std_hz).collect();
        crate::posterior::sample_objective(&self.objective(), &sigma, "the run-up", sampler, seed, budget)
    }
}

/// The built-in `ross-runup`: the twelve factors (kxx, kyy, kxy, kyx, cxx, cyy of bearings DE
/// and NDE) of `runup_nominal.toml` from ROSS's run-up of the truth rotor, and the truth.
pub fn builtin() -> Result<(RunupCase, Vec<(String, f64)>), WorkflowError> {
    let rotor = ross_file::parse(NOMINAL_TOML).map_err(|e| WorkflowError::Failure(e.to_string()))?;
    let points = parse_runup(RUNUP_CSV).map_err(|e| WorkflowError::Failure(e.to_string()))?;
    let truth: serde_json::Value =
        serde_json::from_str(TRUTH_JSON).map_err(|e| WorkflowError::Failure(e.to_string()))?;
    let factors: Vec<(String, f64)> = truth["factors"]
        .as_object()
        .map(|m| m.iter().filter_map(|(k, v)| Some((k.clone(), v.as_f64()?))).collect())
        .unwrap_or_default();
    let names: Vec<&str> = factors.iter().map(|(n, _)| n.as_str()).collect();
    Ok((RunupCase::new(rotor, &names, points)?, factors))
}

/// A problem file's ROSS run-up: the rotor at `model`, the run-up CSV at `measured`, the
/// factors named by the truth's keys.
pub fn from_files(model: &Path, measured: &Path, names: &[&str]) -> Result<RunupCase, WorkflowError> {
    let rotor = ross_file::read(model).map_err(|e| input(format!("{}: {e}", model.display())))?;
    let points = eigenfit_rotordynamics::identify::read_runup(measured).map_err(|e| input(e.to_string()))?;
    RunupCase::new(rotor, names, points)
}
