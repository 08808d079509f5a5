//! `campaign`: several test configurations (one model and one data set each) estimated jointly
//! (docs/test-data.md).

use crate::error::{failure, input, WorkflowError};
use crate::model::Updatable;
use crate::named::Named;
use crate::outcome::{BudgetReport, Covariances, Outcome, PairedFrequencies, Verdict};
use crate::overrides::fixed;
use crate::progress::Progress;
use crate::test_data::{self, interval_basis, pairing, Fit, ShapeOptions, TestDataOptions};
use eigenfit_core::analysis::verdict::{at_limits, judge, FitQuality};
use eigenfit_core::analysis::Joint;
use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::{Objective, Problem, ResidualKind};
use eigenfit_core::update::{registry, Budget, Driver, Method};
use eigenfit_rotor::campaign::Campaign;
use eigenfit_rotor::{Rotor, UpdatableRotor};
use serde::Serialize;
use std::path::PathBuf;

/// A campaign to estimate, as the command line gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignRequest {
    /// The campaign file (TOML, `[[configuration]]` tables).
    pub campaign: PathBuf,
    /// Update strategy: newton, p-step or damped.
    pub strategy: String,
    /// Eigen-solver: banded (or auto) or dense.
    pub solver: String,
    /// Iteration limit.
    pub max_iterations: usize,
    /// Most model evaluations (eigen-solves) the joint fit and its intervals may spend together.
    pub budget: usize,
    /// Node matching, shape weight and MAC threshold for every configuration.
    pub shape: ShapeOptions,
}

/// One configuration at the joint estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConfigurationReport {
    /// Its name.
    pub name: String,
    /// Model and measured frequencies (Hz).
    #[serde(flatten)]
    pub frequencies: PairedFrequencies,
    /// Measured mode number → model mode number, both from 1.
    pub pairing: Named<usize>,
    /// MAC matrix (shapes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mac: Option<Vec<Vec<f64>>>,
    /// Measured modes below the MAC threshold (shapes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unpaired: Option<Vec<usize>>,
    /// What the user should know about the data.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Measured mode numbers (from 1), in the data's order.
    #[serde(skip)]
    pub mode_numbers: Vec<usize>,
    /// (measured mode, paired model mode, MAC) per measured mode (shapes).
    #[serde(skip)]
    pub mac_pairing: Option<Vec<(usize, usize, f64)>>,
}

/// `campaign`'s report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CampaignReport {
    /// The campaign file.
    pub campaign: String,
    /// Strategy name.
    pub strategy: &'static str,
    /// Converged (with every mode paired), why it stopped, iterations, evaluations.
    #[serde(flatten)]
    pub outcome: Outcome,
    /// `acceptable` and `verdict` by estimate's rule (`Verdict::of`): not converged, the budget
    /// spent, a poor fit (χ² with measured std), a parameter on a limit or an unpaired mode make
    /// the estimate not acceptable (exit code 3), as they do for `estimate`.
    #[serde(flatten)]
    pub verdict: Verdict,
    /// The joint fit's quality (χ² test when every configuration has std).
    #[serde(skip)]
    pub quality: FitQuality,
    /// Parameters on a limit at the estimate.
    pub at_limit: Vec<String>,
    /// The evaluation budget: the limit, what the fit and its intervals spent, whether it ran out
    /// (intervals cut short are incomplete).
    pub budget: BudgetReport,
    /// Initial values.
    pub initial: Named<f64>,
    /// Estimated values.
    pub parameters: Named<f64>,
    /// χ² of the joint fit.
    pub chi2: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// 95 % intervals.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intervals: Option<Named<[f64; 2]>>,
    /// What the intervals were scaled by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_basis: Option<String>,
    /// Each parameter's unit as declared (empty when none was), by name.
    pub units: Named<String>,
    /// The parameters' covariance (physical coordinates) and correlation, `null` when not
    /// computed or not computable.
    #[serde(flatten)]
    pub covariances: Covariances,
    /// Each configuration.
    pub configurations: Vec<ConfigurationReport>,
    /// Every configuration has std and no shapes.
    #[serde(skip)]
    pub has_std: bool,
    /// The residual scatter the intervals were scaled by.
    #[serde(skip)]
    pub scatter: Option<f64>,
    /// Notes on the frequency CSVs' columns, for the log.
    #[serde(skip)]
    pub file_notes: Vec<String>,
}

/// Estimates a campaign jointly.
pub fn run(request: &CampaignRequest, progress: &mut dyn Progress) -> Result<CampaignReport, WorkflowError> {
    let campaign = Campaign::from_toml_file(&request.campaign).map_err(|e| input(e.to_string()))?;
    let solver: Box<dyn EigenSolver> = match request.solver.as_str() {
        "banded" | "auto" => Box::new(BandedSolver::default()),
        "dense" => Box::new(DenseSolver),
        other => return Err(input(eigenfit_core::names::unknown("solver", other, &["banded", "dense"]))),
    };
    let (strategy_name, method) =
        registry::build(&request.strategy).map_err(|e| input(format!("--strategy: {e}")))?;
    let mut strategy = match method {
        Method::Local(s) => s,
        Method::Sampler(_) => {
            return Err(input(format!(
                "--strategy {strategy_name}: a sampler; a campaign is fitted by a local strategy (damped, trf, …)"
            )))
        }
    };
    let mut models = Vec::new();
    let mut data = Vec::new();
    let mut names = Vec::new();
    let mut file_notes = Vec::new();
    for conf in &campaign.configurations {
        let name = conf.name.clone().unwrap_or_default();
        crate::model::check_model_file(&conf.model).map_err(|e| input(format!("{name}: {e}")))?;
        if let Some(e) = crate::model::other_kind(&conf.model, "a campaign") {
            return Err(input(format!("{name}: {e}")));
        }
        let rotor = Rotor::from_toml_file(&conf.model).map_err(|e| input(format!("{name}: {e}")))?;
        let options = TestDataOptions {
            shapes: conf.shapes.clone(),
            sensor_map: conf.sensor_map.clone(),
            shape: request.shape,
            fix: Vec::new(),
        };
        let d = test_data::read(&conf.measured, Some(&rotor), &options)
            .map_err(|e| input(format!("{name}: {e}")))?;
        // The check estimate makes, before anything is solved for that many modes.
        if d.measurement.modes_needed() > rotor.dofs() {
            return Err(input(format!(
                "{name}: {}: mode {} measured but the model has only {} modes",
                conf.measured.display(),
                d.measurement.modes_needed(),
                rotor.dofs()
            )));
        }
        file_notes.extend(d.file_notes.iter().cloned());
        let updatable = UpdatableRotor::new(rotor)
            .map(|r| Updatable::Rotor(Box::new(r)))
            .map_err(|e| input(format!("{}: {e}", conf.model.display())))?;
        models.push(updatable);
        data.push(d);
        names.push(name);
    }
    let fixed: Vec<_> = models.iter().map(|m| fixed(m, &[])).collect::<Result<_, _>>()?;
    // The check estimate makes: no measured mode numbered onto a rigid-body mode (a
    // configuration without bearings), refused naming the configuration and its file.
    for (k, (m, d)) in fixed.iter().zip(&data).enumerate() {
        let file = format!("{}: {}", names[k], campaign.configurations[k].measured.display());
        crate::estimate::refuse_rigid_body_pairing(
            m,
            solver.as_ref(),
            &m.parameters().nominal_values(),
            &d.measurement,
            &file,
        )?;
        crate::estimate::refuse_unit_slip(m, solver.as_ref(), &d.measurement, &file)?;
    }
    let fits: Vec<Fit> = fixed
        .iter()
        .zip(&data)
        .map(|(m, d)| {
            let problem =
                Problem::new(m, solver.as_ref(), d.measurement.clone()).with_kind(ResidualKind::Relative);
            Fit::new(problem, d, request.shape.shape_std)
        })
        .collect();
    let mut joint = Joint::new(fits.iter().map(|f| f as &(dyn Objective + Sync)).collect())
        .map_err(|e| input(format!("{}: {e}", request.campaign.display())))?;
    let has_std = data.iter().all(|d| d.measurement.has_std() && d.sensors.is_none());
    let initial = joint.parameters().nominal_values();
    progress.begin(&format!("estimating the campaign ({strategy_name})"), None);
    if request.budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    let budget = Budget::new(request.budget);
    let estimate = Driver { max_iterations: request.max_iterations }
        .run_within(&joint, strategy.as_mut(), &initial, &budget)
        .map_err(|e| match budget.exhausted() {
            true => WorkflowError::BudgetExhausted(format!(
                "the budget of {} model evaluations ran out before the fit could start (raise it with --budget)",
                budget.limit()
            )),
            false => input(e.to_string()),
        });
    progress.end();
    let estimate = estimate?;
    let p = estimate.parameters.clone();
    let (unc, scatter) = match estimate.termination.is_converged() {
        true => joint
            .uncertainty_within(&estimate.last, has_std, &budget)
            .map_or((None, None), |(u, s)| (Some(u), Some(s))),
        false => (None, None),
    };
    let pnames: Vec<String> = joint.parameters().iter().map(|q| q.name.clone()).collect();
    let mut configurations = Vec::new();
    let mut unpaired = false;
    for (k, fit) in fits.iter().enumerate() {
        let sub = joint.part_values(k, &p);
        let lin = joint.part_linearise(k, &p).map_err(|e| failure(format!("{}: {e}", names[k])))?;
        let mac = fit.mac(&sub, request.shape.mac_threshold);
        unpaired |= mac.as_ref().is_some_and(|r| !r.unpaired.is_empty());
        configurations.push(ConfigurationReport {
            name: names[k].clone(),
            pairing: pairing(fit.measured(), &lin.paired_modes),
            frequencies: PairedFrequencies::of(&lin),
            mac: mac.as_ref().map(|r| r.matrix.clone()),
            unpaired: mac.as_ref().map(|r| r.unpaired.clone()),
            notes: data[k].notes.clone(),
            mode_numbers: data[k].measurement.modes().iter().map(|m| m.mode + 1).collect(),
            mac_pairing: mac.map(|r| r.pairing),
        });
    }
    // One rule for the verdict, estimate's: a campaign is a fit like any other (issue 28).
    let converged = estimate.termination.is_converged();
    let quality = judge(&estimate.last, pnames.len());
    let limits = at_limits(joint.parameters(), &p);
    let at_limit: Vec<String> =
        (0..pnames.len()).filter(|&i| limits[i] != 0).map(|i| pnames[i].clone()).collect();
    let verdict = Verdict::of(
        (!converged).then(|| estimate.termination.label()),
        budget.exhausted(),
        quality.verdict,
        !at_limit.is_empty(),
        unpaired,
        true,
    );
    Ok(CampaignReport {
        campaign: request.campaign.display().to_string(),
        strategy: estimate.strategy,
        verdict,
        quality,
        at_limit,
        outcome: Outcome::of(&estimate, estimate.termination.is_converged() && !unpaired),
        budget: BudgetReport::of(&budget),
        initial: Named::new(&pnames, initial.iter().copied()),
        parameters: Named::new(&pnames, p.iter().copied()),
        chi2: estimate.last.chi2(),
        dof: estimate.last.degrees_of_freedom(),
        intervals: unc.as_ref().map(|u| Named::new(&pnames, u.intervals.iter().copied())),
        interval_basis: scatter.map(|s| interval_basis(s, has_std)),
        units: crate::simulate::units_of_parameters(joint.parameters()),
        covariances: Covariances::of(&pnames, unc.as_ref().map(|u| &u.covariance)),
        configurations,
        has_std,
        scatter,
        file_notes,
    })
}
