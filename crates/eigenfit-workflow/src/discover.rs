//! `discover`: calibrate, find where model and measurement disagree, name the missing effect
//! and build the augmented model.

use crate::error::{failure, input, WorkflowError};
use crate::model::AnyModel;
use crate::named::Named;
use crate::progress::Progress;
use eigenfit_core::discovery::{discover, Alternative, DiscoveryOptions, Fit, NamedEffect};
use eigenfit_core::{EigenSolver, StructuralModel};
use eigenfit_rotor::discovery::{discover_rotor, RotorDiscovery};
use serde::Serialize;
use std::path::Path;

/// What and where an effect is: the part every effect in a report has.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Place {
    /// Effect kind.
    pub kind: String,
    /// Where (node or element), when the kind has a place.
    pub location: Option<usize>,
    /// The unit of its value.
    pub unit: String,
    /// Position along the shaft (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position_m: Option<f64>,
    /// Elements covered.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<[usize; 2]>,
}

/// The place of an effect from its fields (the core's discovery types each carry them).
macro_rules! place {
    ($e:expr) => {
        Place {
            kind: $e.kind.clone(),
            location: $e.location,
            unit: $e.unit.clone(),
            position_m: $e.position_m,
            elements: $e.elements,
        }
    };
}

/// A refitted candidate in a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitReport {
    /// What and where.
    #[serde(flatten)]
    pub place: Place,
    /// Fitted value.
    pub value: Option<f64>,
    /// 95 % interval of the value.
    pub interval: Option<[f64; 2]>,
    /// χ² after the refit.
    pub chi2: f64,
    /// AICc after the refit.
    pub aicc: f64,
    /// Whether the value is physically plausible.
    pub plausible: bool,
}

impl From<&Fit> for FitReport {
    fn from(f: &Fit) -> Self {
        Self {
            place: place!(f),
            value: f.value,
            interval: f.interval,
            chi2: f.chi2,
            aicc: f.aicc,
            plausible: f.plausible,
        }
    }
}

/// An effect the data cannot tell apart from the named one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlternativeReport {
    /// What and where.
    #[serde(flatten)]
    pub place: Place,
    /// Fitted value.
    pub value: Option<f64>,
    /// AICc against the named effect.
    pub delta_aicc: f64,
}

impl From<&Alternative> for AlternativeReport {
    fn from(a: &Alternative) -> Self {
        Self { place: place!(a), value: a.value, delta_aicc: a.delta_aicc }
    }
}

/// A named missing effect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectReport {
    /// What and where.
    #[serde(flatten)]
    pub place: Place,
    /// Fitted value (1 for an on/off effect).
    pub value: f64,
    /// 95 % interval of the value.
    pub interval: Option<[f64; 2]>,
    /// AICc gain.
    pub delta_aicc: f64,
    /// Effects the data cannot tell apart from this one.
    pub ambiguous_with: Vec<AlternativeReport>,
}

impl From<&NamedEffect> for EffectReport {
    fn from(e: &NamedEffect) -> Self {
        Self {
            place: place!(e),
            value: e.value.unwrap_or(1.0),
            interval: e.interval,
            delta_aicc: e.delta_aicc,
            ambiguous_with: e.ambiguous_with.iter().map(Into::into).collect(),
        }
    }
}

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
    /// Whether the misfit is beyond the noise.
    pub disagreement_significant: bool,
    /// The strongest named effect.
    pub missing_effect: Option<EffectReport>,
    /// Every named effect, strongest first.
    pub missing_effects: Vec<EffectReport>,
    /// Mesh refinement factor settled on (1: the user's mesh).
    pub mesh_refinement: usize,
    /// RMS residual before (Hz).
    pub rms_residual_before_hz: f64,
    /// RMS residual after (Hz).
    pub rms_residual_after_hz: f64,
    /// χ² before.
    pub chi2_before: f64,
    /// Degrees of freedom before.
    pub dof_before: usize,
    /// P(χ² this large from noise alone).
    pub p_value: f64,
    /// The nominal parameters calibrated.
    pub calibrated_parameters: Named<f64>,
    /// The best candidate after the first.
    pub runner_up: Option<FitReport>,
    /// Every candidate refitted.
    pub candidates_refitted: Vec<FitReport>,
    /// Each measured mode before and after.
    pub modes: Vec<ModeReport>,
    /// Files written (the augmented model, plots).
    pub written: Vec<String>,
}

/// A discovery and its report.
pub struct Discovery {
    /// What the workflow found.
    pub found: RotorDiscovery,
    /// The report (`written` empty: the caller adds the files it writes).
    pub report: DiscoverReport,
}

/// Runs the discovery on `model` against the measured CSV at `measured`, assuming a relative
/// standard deviation `assumed_std` where the file gives none. Notes on the file go to `notes`.
pub fn run(
    label: &str,
    model: &AnyModel,
    solver: &dyn EigenSolver,
    measured: &Path,
    assumed_std: f64,
    notes: &mut Vec<String>,
    progress: &mut dyn Progress,
) -> Result<Discovery, WorkflowError> {
    let (data, file_notes) = crate::test_data::read_frequencies(measured)?;
    notes.extend(file_notes);
    if !(assumed_std.is_finite() && assumed_std > 0.0) {
        return Err(input(format!("--assumed-std {assumed_std}: must be a positive number")));
    }
    let options = DiscoveryOptions { assumed_relative_std: assumed_std, ..Default::default() };
    progress.begin("discovering: calibrate, detect, screen and refit candidates", None);
    let found = match model {
        AnyModel::Rotor(r) => discover_rotor(r, &solver, &data, &r.nominal_stiffnesses(), &options),
        // A matrices model has no mesh to refine: the generic workflow over its [[candidate]]s.
        AnyModel::Matrices(m) => {
            discover(m, &solver, &data, &m.candidates(), &m.parameters().nominal_values(), &options)
                .map(|report| RotorDiscovery { effects: report.effects.clone(), report, mesh_factor: 1 })
        }
    };
    progress.end();
    let found = found.map_err(|e| input(format!("{}: {e}", measured.display())))?;
    let names: Vec<String> = model.parameters().iter().map(|p| p.name.clone()).collect();
    let r = &found.report;
    let report = DiscoverReport {
        model: label.to_string(),
        disagreement_significant: r.disagreement_significant,
        missing_effect: found.effects.first().map(Into::into),
        missing_effects: found.effects.iter().map(Into::into).collect(),
        mesh_refinement: found.mesh_factor,
        rms_residual_before_hz: r.rms_before_hz,
        rms_residual_after_hz: r.rms_after_hz,
        chi2_before: r.chi2_before,
        dof_before: r.dof_before,
        p_value: r.p_value,
        calibrated_parameters: Named::new(&names, r.base_parameters.iter().copied()),
        runner_up: r.runner_up.as_ref().map(Into::into),
        candidates_refitted: r.fits.iter().map(Into::into).collect(),
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
    };
    Ok(Discovery { found, report })
}

/// The augmented model (calibrated stiffnesses and the named effects) as rotor TOML; a
/// matrices model has no file form for its effects and says so.
pub fn augmented_model_toml(found: &RotorDiscovery, model: &AnyModel) -> Result<String, WorkflowError> {
    let augmented = found.augmented_model(model.rotor("--write-model")?).map_err(failure)?;
    augmented.to_toml_string().map_err(failure)
}
