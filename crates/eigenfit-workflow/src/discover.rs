//! `discover`: calibrate, find where model and measurement disagree, name the missing effect
//! and build the augmented model.

use crate::error::{failure, input, WorkflowError};
use crate::model::AnyModel;
use crate::named::Named;
use crate::progress::Progress;
use eigenfit_core::analysis::verdict::{check_reachable, check_softest};
use eigenfit_core::discovery::{
    discover, BaseMisfit, DiscoveryError, DiscoveryOptions, DiscoveryReport, Fit, NamedEffect, Spending,
    Untestable,
};
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::Problem;
use eigenfit_core::update::refit::RefitChoice;
use eigenfit_core::update::Budget;
use eigenfit_rotor::discovery::{discover_rotor, RotorDiscovery};
use serde::Serialize;
use std::path::Path;

/// One measured mode before and after.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeReport {
    /// Mode number from 1.
    pub mode: usize,
    /// Measured frequency (Hz).
    pub measured_hz: f64,
    /// Its standard deviation (Hz).
    pub std_hz: f64,
    /// Model before (Hz).
    pub before_hz: f64,
    /// Model after (Hz).
    pub after_hz: f64,
}

/// `discover`'s report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DiscoverReport {
    /// The model's label.
    pub model: String,
    /// χ² before, its degrees of freedom, P(χ² this large from noise alone), whether the misfit
    /// is beyond the noise.
    #[serde(flatten)]
    pub before: BaseMisfit,
    /// The strongest named effect.
    pub missing_effect: Option<NamedEffect>,
    /// Every named effect, strongest first.
    pub missing_effects: Vec<NamedEffect>,
    /// Mesh refinement factor settled on (1: the user's mesh).
    pub mesh_refinement: usize,
    /// RMS residual before and after (Hz).
    #[serde(flatten)]
    pub rms: RmsResidual,
    /// The nominal parameters calibrated.
    pub calibrated_parameters: Named<f64>,
    /// The model's own parameters refitted together with the selected effect(s): the values a
    /// user should take, not the calibration without the effect (`None` when nothing was named).
    pub refitted_parameters: Option<Named<Refitted>>,
    /// The best candidate after the first.
    pub runner_up: Option<Fit>,
    /// Every candidate refitted.
    pub candidates_refitted: Vec<Fit>,
    /// Each measured mode before and after.
    pub modes: Vec<ModeReport>,
    /// Files written (the augmented model, plots).
    pub written: Vec<String>,
    /// Eigen-solves the run spent (the data check, the user's and the refined mesh together).
    pub evaluations: usize,
    /// The evaluation budget the run was given (`--budget`).
    pub budget_limit: usize,
    /// True when the search stopped at its budget of eigen-solves.
    pub budget_exhausted: bool,
    /// How `evaluations` were spent, by phase (the data check, calibration, screening, the
    /// leaders' refits, confirmation, carried alternatives, the refined mesh) and how many leader
    /// refits the budget's share for them left out.
    pub budget_spent: Spending,
    /// Candidates that could not be tested: with one of them the fit would leave no degree of
    /// freedom (as many parameters as measured modes), so it would fit exactly whatever the truth.
    pub untestable_candidates: Vec<Untestable>,
    /// True when the data are explained: by the noise from the start, or by the named effects
    /// (the search names effects only when, with them, the noise explains what is left). False
    /// when a significant disagreement stays unexplained or the budget ran out: exit code 3.
    pub explained: bool,
}

/// `rms_residual_before_hz`, `rms_residual_after_hz`: how far model and measurement lie apart
/// before and after the named effects, as `discover` and the demo's discovery state it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RmsResidual {
    /// RMS residual before (Hz).
    pub rms_residual_before_hz: f64,
    /// RMS residual after (Hz).
    pub rms_residual_after_hz: f64,
}

impl RmsResidual {
    /// The RMS residuals of a discovery run.
    pub fn of(r: &DiscoveryReport) -> Self {
        Self { rms_residual_before_hz: r.rms_before_hz, rms_residual_after_hz: r.rms_after_hz }
    }
}

/// A parameter refitted with the named effect(s).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refitted {
    /// The value.
    pub value: f64,
    /// Its 95 % interval, when one could be computed.
    pub interval: Option<[f64; 2]>,
}

/// The model's own parameters as refitted together with the selected effect(s).
fn refitted(r: &DiscoveryReport, names: &[String]) -> Option<Named<Refitted>> {
    let fit = r.selected.as_ref()?;
    (fit.parameters.len() >= names.len()).then(|| {
        Named::new(
            names,
            (0..names.len()).map(|i| Refitted {
                value: fit.parameters[i],
                interval: fit.intervals.get(i).copied().flatten(),
            }),
        )
    })
}

/// A discovery and its report.
pub struct Discovery {
    /// What the workflow found.
    pub found: RotorDiscovery,
    /// The report (`written` empty: the caller adds the files it writes).
    pub report: DiscoverReport,
}

/// Runs the discovery on `model` against the measured CSV at `measured`, assuming a relative
/// standard deviation `assumed_std` where the file gives none, spending at most `budget` model
/// evaluations (eigen-solves) on the data check and the whole search together, calibrating and
/// refitting with `refit`. Notes on the file go to `notes`.
#[allow(clippy::too_many_arguments)]
pub fn run(
    label: &str,
    model: &AnyModel,
    solver: &dyn EigenSolver,
    measured: &Path,
    assumed_std: f64,
    budget: usize,
    refit: RefitChoice,
    notes: &mut Vec<String>,
    progress: &mut dyn Progress,
) -> Result<Discovery, WorkflowError> {
    let (data, file_notes) = crate::test_data::read_frequencies(measured)?;
    notes.extend(file_notes);
    if !(assumed_std.is_finite() && assumed_std > 0.0) {
        return Err(input(format!("--assumed-std {assumed_std}: must be a positive number")));
    }
    if budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    // Estimate's sanity check, so a typing slip ends here as it does there (exit 2, mode named).
    let mode_numbers: Vec<usize> = data.modes().iter().map(|m| m.mode + 1).collect();
    // Frequencies all explained by one unit slip (kHz for Hz) are refused naming it; others
    // outside the model's reach are what discovery is for.
    if let Some(e) = check_softest(model, solver, &data, &mode_numbers).filter(|e| e.slip.is_some()) {
        return Err(input(format!("{}: {e}", measured.display())));
    }
    let problem = Problem::new(model, solver, data.clone());
    let check = Budget::new(budget);
    check_reachable(&problem, &mode_numbers, &check).map_err(|e| {
        if check.exhausted() {
            budget_error(budget)
        } else {
            input(format!("{}: {e}", measured.display()))
        }
    })?;
    // The search gets what the check left, so `budget` bounds the whole run.
    let options = DiscoveryOptions {
        assumed_relative_std: assumed_std,
        max_evaluations: check.remaining(),
        refit,
        ..Default::default()
    };
    progress.begin("discovering: calibrate, detect, screen and refit candidates", None);
    let found = match model {
        AnyModel::Rotor(r) => discover_rotor(r, &solver, &data, &r.nominal_stiffnesses(), &options),
        // A matrices model has no mesh to refine: the generic workflow over its [[candidate]]s.
        AnyModel::Matrices(m) => {
            discover(m, &solver, &data, &m.candidates(), &m.parameters().nominal_values(), &options)
                .map(|report| RotorDiscovery { effects: report.effects.clone(), report, mesh_factor: 1 })
        }
        AnyModel::Registered(m) => {
            let m = m.as_ref();
            discover(&m, &solver, &data, &m.candidates(), &m.parameters().nominal_values(), &options)
                .map(|report| RotorDiscovery { effects: report.effects.clone(), report, mesh_factor: 1 })
        }
    };
    progress.end();
    // A calibration cut short by the budget is no input error: the user's budget was too small.
    let mut found = found.map_err(|e| match e {
        DiscoveryError::BudgetExhausted(_) => budget_error(budget),
        e => input(format!("{}: {e}", measured.display())),
    })?;
    found.report.evaluations += check.used();
    found.report.spending.data_check += check.used();
    let names: Vec<String> = model.parameters().iter().map(|p| p.name.clone()).collect();
    let report = report_of(label, &found.report, &found.effects, found.mesh_factor, &names, budget);
    Ok(Discovery { found, report })
}

/// The `discover` report of a discovery run: `effects` the named ones, `names` the model's own
/// parameters (the first of every fit). Shared by the planar, matrices and two-plane models.
pub(crate) fn report_of(
    label: &str,
    r: &DiscoveryReport,
    effects: &[NamedEffect],
    mesh_refinement: usize,
    names: &[String],
    budget: usize,
) -> DiscoverReport {
    DiscoverReport {
        model: label.to_string(),
        before: r.before,
        missing_effect: effects.first().cloned(),
        missing_effects: effects.to_vec(),
        mesh_refinement,
        rms: RmsResidual::of(r),
        calibrated_parameters: Named::new(names, r.base_parameters.iter().copied()),
        refitted_parameters: refitted(r, names),
        runner_up: r.runner_up.clone(),
        candidates_refitted: r.fits.clone(),
        modes: r
            .modes
            .iter()
            .map(|m| ModeReport {
                mode: m.mode + 1,
                measured_hz: m.measured_hz,
                std_hz: m.std_hz,
                before_hz: m.before_hz,
                after_hz: m.after_hz,
            })
            .collect(),
        written: Vec::new(),
        evaluations: r.evaluations,
        budget_limit: budget,
        budget_exhausted: r.budget_exhausted,
        budget_spent: r.spending,
        untestable_candidates: r.untestable.clone(),
        explained: !r.budget_exhausted && (!r.before.significant || !effects.is_empty()),
    }
}

/// The augmented model (calibrated stiffnesses and the named effects) as rotor TOML; a
/// matrices model has no file form for its effects and says so, and neither has a pedestal
/// (an input error: the request cannot be met, nothing broke).
pub fn augmented_model_toml(found: &RotorDiscovery, model: &AnyModel) -> Result<String, WorkflowError> {
    if let Some(p) = found.effects.iter().find(|e| e.kind == eigenfit_rotor::pedestal::KIND) {
        return Err(input(format!(
            "--write-model: the named `{}` adds a degree of freedom (the pedestal's mass on its own spring), \
             which a rotor model file cannot describe yet; its mass and stiffness are in the report \
             (run without --write-model to see it)",
            p.label
        )));
    }
    let augmented = found.augmented_model(model.rotor("--write-model")?).map_err(failure)?;
    augmented.to_toml_string().map_err(failure)
}

/// The budget ran out before the calibration could finish: nothing to report but that.
pub(crate) fn budget_error(budget: usize) -> WorkflowError {
    WorkflowError::BudgetExhausted(format!(
        "the budget of {budget} model evaluations ran out before the calibration finished (raise it with --budget)"
    ))
}
