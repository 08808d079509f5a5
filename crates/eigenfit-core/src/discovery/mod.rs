//! Missing-effect discovery: when updating the nominal parameters cannot close the gap between
//! model and measurement, find which candidate effect explains it.
//!
//! 1. **Calibrate** the nominal parameters (damped least squares).
//! 2. **Detect**: χ² of the calibrated residual against the noise, overall (p-value) and per mode.
//! 3. **Screen** every candidate by the χ² reduction a linear fit of its value would give, with
//!    the residual's sensitivity projected off the already-fitted parameters.
//! 4. **Refit** the most promising with the nominal parameters; **select** by AICc among the
//!    physically plausible fits, and report the runner-up.
//!
//! Nothing here is rotor-specific: a plugin offers [`Candidate`]s, the engine does the rest.

mod candidate;
mod chi2;

pub use candidate::{Augmented, Candidate};
pub use chi2::chi2_upper_tail;

use crate::measurement::{MeasuredMode, Measurement};
use crate::multi::Stacked;
use crate::residual::{Linearisation, Problem};
use crate::statistics::uncertainty;
use crate::update::{Damped, Driver, Evaluate};
use crate::{EigenSolver, StructuralModel};
use nalgebra::DVector;
use thiserror::Error;

/// Why discovery could not run.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum DiscoveryError {
    /// The measurement cannot support detection (too few modes).
    #[error("{0}")]
    Data(String),
    /// The base calibration failed.
    #[error("calibrating the nominal parameters failed: {0}")]
    Calibration(String),
}

/// Settings of the workflow.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscoveryOptions {
    /// Significance level of the χ² test (default 0.05).
    pub significance: f64,
    /// Candidates refitted after screening (default 8; switches are always refitted).
    pub refits: usize,
    /// AICc improvement over the base model needed to name an effect (default 4).
    pub min_aicc_gain: f64,
    /// Relative frequency std assumed for modes without one (default 1e-3).
    pub assumed_relative_std: f64,
    /// An effect is named only if, with it, the misfit is one noise can explain: P(χ² ≥ observed)
    /// at least this (default 1e-3). A better but still inconsistent fit is reported, not named.
    pub min_after_p_value: f64,
}

impl Default for DiscoveryOptions {
    fn default() -> Self {
        Self {
            significance: 0.05,
            refits: 8,
            min_aicc_gain: 4.0,
            assumed_relative_std: 1e-3,
            min_after_p_value: 1e-3,
        }
    }
}

/// One mode before and after adding the selected effect.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeComparison {
    /// Test configuration (0 when there is one).
    pub configuration: usize,
    /// 0-based mode number.
    pub mode: usize,
    /// Measured frequency, Hz.
    pub measured_hz: f64,
    /// Standard deviation used, Hz.
    pub std_hz: f64,
    /// Calibrated base model, Hz.
    pub before_hz: f64,
    /// Augmented model (or the base when nothing was added), Hz.
    pub after_hz: f64,
}

impl ModeComparison {
    /// (model − measured)/σ before.
    pub fn normalised_before(&self) -> f64 {
        (self.before_hz - self.measured_hz) / self.std_hz
    }
    /// (model − measured)/σ after.
    pub fn normalised_after(&self) -> f64 {
        (self.after_hz - self.measured_hz) / self.std_hz
    }
}

/// A refitted candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The candidate's label, `kind@location`.
    pub label: String,
    /// Kind.
    pub kind: String,
    /// Location.
    pub location: Option<usize>,
    /// Fitted value (`None` for a switch).
    pub value: Option<f64>,
    /// Unit of the value.
    pub unit: String,
    /// 95% interval of the value.
    pub interval: Option<[f64; 2]>,
    /// All fitted parameters: the base's, then the value.
    pub parameters: Vec<f64>,
    /// χ² of the fit.
    pub chi2: f64,
    /// AICc of the fit.
    pub aicc: f64,
    /// Is the value physically plausible (and, for a value, its interval clear of zero)?
    pub plausible: bool,
    /// Model frequencies of the measured modes, Hz.
    pub frequencies_hz: Vec<f64>,
}

/// Everything the workflow found, for reports.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscoveryReport {
    /// Calibrated nominal parameters.
    pub base_parameters: Vec<f64>,
    /// χ² of the calibrated base model.
    pub chi2_before: f64,
    /// Degrees of freedom of the base fit (modes − parameters).
    pub dof_before: usize,
    /// P(χ² ≥ observed) under noise alone.
    pub p_value: f64,
    /// True when the misfit is significant at the chosen level.
    pub disagreement_significant: bool,
    /// AICc of the base model.
    pub aicc_before: f64,
    /// Screening scores (predicted χ² reduction), best first.
    pub screening: Vec<(String, f64)>,
    /// Refitted candidates, best AICc first.
    pub fits: Vec<Fit>,
    /// The named effect, if any.
    pub selected: Option<Fit>,
    /// The best plausible alternative to the named effect.
    pub runner_up: Option<Fit>,
    /// Per mode, before and after.
    pub modes: Vec<ModeComparison>,
    /// RMS of model − measured before, Hz.
    pub rms_before_hz: f64,
    /// RMS of model − measured after, Hz.
    pub rms_after_hz: f64,
}

/// Corrected Akaike information criterion with known σ: χ² + 2k + 2k(k+1)/(n − k − 1).
pub fn aicc(chi2: f64, n: usize, k: usize) -> f64 {
    let (n, k) = (n as f64, k as f64);
    let correction = if n - k - 1.0 > 0.0 { 2.0 * k * (k + 1.0) / (n - k - 1.0) } else { f64::INFINITY };
    chi2 + 2.0 * k + correction
}

/// Runs the workflow on `model` against `measured`, starting the calibration from `initial`.
pub fn discover<M, S>(
    model: &M,
    solver: &S,
    measured: &Measurement,
    candidates: &[Candidate],
    initial: &[f64],
    options: &DiscoveryOptions,
) -> Result<DiscoveryReport, DiscoveryError>
where
    M: StructuralModel,
    S: EigenSolver,
{
    discover_configurations(&[(model, measured)], solver, candidates, initial, options)
}

/// Runs the workflow on several test configurations of one structure at once (e.g. a building
/// measured bare and with known test masses): each configuration is a model sharing the same
/// parameters and the same candidate contributions, with its own measured modes. Mode numbers
/// in the report run over the configurations in order.
pub fn discover_configurations<M, S>(
    configurations: &[(&M, &Measurement)],
    solver: &S,
    candidates: &[Candidate],
    initial: &[f64],
    options: &DiscoveryOptions,
) -> Result<DiscoveryReport, DiscoveryError>
where
    M: StructuralModel,
    S: EigenSolver,
{
    let Some(&(model, _)) = configurations.first() else {
        return Err(DiscoveryError::Data("no test configuration given".into()));
    };
    let measured: Vec<Measurement> = configurations
        .iter()
        .map(|(_, m)| with_std(m, options.assumed_relative_std))
        .collect::<Result<_, _>>()?;
    let models: Vec<&M> = configurations.iter().map(|&(m, _)| m).collect();
    let n: usize = measured.iter().map(Measurement::len).sum();
    let nb = model.parameters().len();
    if n <= nb {
        return Err(DiscoveryError::Data(format!(
            "{n} measured modes for {nb} parameters: detecting a missing effect needs more modes than parameters"
        )));
    }
    let problems: Vec<Problem<&M, &S>> =
        models.iter().zip(&measured).map(|(&m, d)| Problem::new(m, solver, d.clone())).collect();
    let base = Stacked::new(problems.iter().map(|p| p as &dyn Evaluate).collect())
        .ok_or_else(|| DiscoveryError::Data("the configurations' parameters differ".into()))?;
    // (a) calibrate
    let est = Driver::default()
        .run(&base, &mut Damped::default(), initial, &mut [])
        .map_err(|e| DiscoveryError::Calibration(e.to_string()))?;
    let base_lin = est.last;
    let chi2_before = 2.0 * base_lin.cost();
    let dof_before = n - nb;
    let p_value = chi2_upper_tail(chi2_before, dof_before);
    let aicc_before = aicc(chi2_before, n, nb);
    let disagreement_significant = p_value < options.significance;
    let mut report = DiscoveryReport {
        base_parameters: base_lin.parameters.clone(),
        chi2_before,
        dof_before,
        p_value,
        disagreement_significant,
        aicc_before,
        screening: Vec::new(),
        fits: Vec::new(),
        selected: None,
        runner_up: None,
        modes: compare_modes(&measured, &base_lin, &base_lin),
        rms_before_hz: rms_diff(&base_lin),
        rms_after_hz: rms_diff(&base_lin),
    };
    if !disagreement_significant {
        return Ok(report);
    }
    // (c) screen, then refit the most promising
    let projector = Projector::new(&base, &base_lin);
    let mut scored: Vec<(usize, f64)> = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| c.parameter.is_some())
        .filter_map(|(i, c)| screen(&models, solver, &measured, c, &base_lin, &projector).map(|s| (i, s)))
        .collect();
    scored.sort_by(|a, b| b.1.total_cmp(&a.1));
    report.screening = scored.iter().map(|&(i, s)| (candidates[i].label(), s)).collect();
    let to_refit = scored
        .iter()
        .take(options.refits)
        .map(|&(i, _)| i)
        .chain(candidates.iter().enumerate().filter(|(_, c)| c.parameter.is_none()).map(|(i, _)| i));
    for i in to_refit {
        if let Some(fit) = refit(&models, solver, &measured, &candidates[i], &base_lin.parameters) {
            report.fits.push(fit);
        }
    }
    report.fits.sort_by(|a, b| a.aicc.total_cmp(&b.aicc));
    // (d) select by AICc among plausible fits
    let mut plausible = report.fits.iter().filter(|f| f.plausible);
    if let Some(best) = plausible.next() {
        let k = best.parameters.len();
        let consistent = n > k && chi2_upper_tail(best.chi2, n - k) >= options.min_after_p_value;
        if aicc_before - best.aicc >= options.min_aicc_gain && consistent {
            report.selected = Some(best.clone());
            report.runner_up = plausible.next().cloned();
        }
    }
    if let Some(sel) = &report.selected {
        let after: Vec<f64> = sel.frequencies_hz.clone();
        for (m, f) in report.modes.iter_mut().zip(&after) {
            m.after_hz = *f;
        }
        let diffs: Vec<f64> = report.modes.iter().map(|m| m.after_hz - m.measured_hz).collect();
        report.rms_after_hz = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    }
    Ok(report)
}

/// Gives every mode a standard deviation (the assumed relative one where none was measured).
fn with_std(measured: &Measurement, relative: f64) -> Result<Measurement, DiscoveryError> {
    let modes: Vec<MeasuredMode> = measured
        .modes()
        .iter()
        .map(|m| MeasuredMode { std_hz: Some(m.std_hz.unwrap_or(relative * m.frequency_hz)), ..m.clone() })
        .collect();
    Measurement::new(modes).map_err(|e| DiscoveryError::Data(e.to_string()))
}

fn compare_modes(
    measured: &[Measurement],
    before: &Linearisation,
    after: &Linearisation,
) -> Vec<ModeComparison> {
    measured
        .iter()
        .enumerate()
        .flat_map(|(c, m)| m.modes().iter().map(move |mode| (c, mode)))
        .enumerate()
        .map(|(k, (configuration, m))| ModeComparison {
            configuration,
            mode: m.mode,
            measured_hz: m.frequency_hz,
            std_hz: m.std_hz.unwrap_or(f64::NAN),
            before_hz: before.frequencies_hz[k],
            after_hz: after.frequencies_hz[k],
        })
        .collect()
}

fn rms_diff(lin: &Linearisation) -> f64 {
    let n = lin.frequencies_hz.len() as f64;
    (lin.frequencies_hz.iter().zip(&lin.measured_hz).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / n).sqrt()
}

/// Projection off the span of the base Jacobian: what the fitted parameters cannot absorb.
struct Projector {
    basis: nalgebra::DMatrix<f64>,
}

impl Projector {
    fn new(base: &dyn Evaluate, lin: &Linearisation) -> Self {
        let js = crate::update::damped::scaled_jacobian(base.parameters(), lin);
        // Orthonormal basis of the column space (thin SVD, dropping null directions).
        let svd = js.svd(true, false);
        let u = svd.u.expect("requested"); // proof: svd(true, _) always computes U
        let smax = svd.singular_values.iter().cloned().fold(0.0, f64::max);
        let keep: Vec<usize> =
            (0..svd.singular_values.len()).filter(|&i| svd.singular_values[i] > 1e-12 * smax).collect();
        Self {
            basis: nalgebra::DMatrix::from_columns(&keep.iter().map(|&i| u.column(i)).collect::<Vec<_>>()),
        }
    }

    fn apply(&self, v: &DVector<f64>) -> DVector<f64> {
        if self.basis.ncols() == 0 {
            return v.clone();
        }
        v - &self.basis * (self.basis.transpose() * v)
    }
}

/// The candidate added to every configuration, stacked into one problem, evaluated by `f`.
fn with_augmented<M, S, T>(
    models: &[&M],
    solver: &S,
    measured: &[Measurement],
    candidate: &Candidate,
    f: impl FnOnce(&dyn Evaluate) -> Option<T>,
) -> Option<T>
where
    M: StructuralModel,
    S: EigenSolver,
{
    let augmented: Vec<Augmented<'_, M>> =
        models.iter().map(|&m| Augmented::new(m, candidate)).collect::<Result<_, _>>().ok()?;
    let problems: Vec<Problem<&Augmented<'_, M>, &S>> =
        augmented.iter().zip(measured).map(|(a, d)| Problem::new(a, solver, d.clone())).collect();
    let stacked = Stacked::new(problems.iter().map(|p| p as &dyn Evaluate).collect())?;
    f(&stacked)
}

/// Predicted χ² reduction of fitting the candidate's value alone, after the base parameters
/// have absorbed what they can; 0 when the fit would need a value outside the bounds' sign.
fn screen<M: StructuralModel, S: EigenSolver>(
    models: &[&M],
    solver: &S,
    measured: &[Measurement],
    candidate: &Candidate,
    base: &Linearisation,
    projector: &Projector,
) -> Option<f64> {
    let par = candidate.parameter.as_ref()?;
    let mut p = base.parameters.clone();
    p.push(par.nominal);
    let lin = with_augmented(models, solver, measured, candidate, |problem| problem.linearise(&p).ok())?;
    let j = projector.apply(&lin.jacobian.column(lin.jacobian.ncols() - 1).into_owned());
    let r = projector.apply(&lin.residual);
    let jj = j.norm_squared();
    if jj == 0.0 {
        return Some(0.0);
    }
    let step = j.dot(&r) / jj;
    let admissible = (par.nominal + step).clamp(par.lower, par.upper) - par.nominal;
    // χ² reduction of the (bound-limited) linear step: 2·a·(j·r) − a²·‖j‖².
    Some((2.0 * admissible * j.dot(&r) - admissible * admissible * jj).max(0.0))
}

/// Refits the base parameters with the candidate added.
fn refit<M: StructuralModel, S: EigenSolver>(
    models: &[&M],
    solver: &S,
    measured: &[Measurement],
    candidate: &Candidate,
    base_parameters: &[f64],
) -> Option<Fit> {
    let mut start = base_parameters.to_vec();
    start.extend(candidate.parameter.as_ref().map(|p| p.nominal));
    let n: usize = measured.iter().map(Measurement::len).sum();
    with_augmented(models, solver, measured, candidate, |problem| {
        let est = Driver::default().run(problem, &mut Damped::default(), &start, &mut []).ok()?;
        let k = problem.parameters().len();
        let chi2 = 2.0 * est.last.cost();
        let value = candidate.parameter.as_ref().map(|_| est.parameters[k - 1]);
        let interval = value.and_then(|_| uncertainty(problem, &est.last, true)).map(|u| u.intervals[k - 1]);
        let (lo, hi) = candidate.plausible;
        let plausible = match (value, interval) {
            (Some(v), Some(iv)) => v >= lo && v <= hi && (iv[0] > 0.0 || iv[1] < 0.0),
            (Some(v), None) => v >= lo && v <= hi,
            (None, _) => true,
        };
        Some(Fit {
            label: candidate.label(),
            kind: candidate.kind.clone(),
            location: candidate.location,
            value,
            unit: candidate.unit().to_string(),
            interval,
            chi2,
            aicc: aicc(chi2, n, k),
            plausible,
            frequencies_hz: est.last.frequencies_hz.clone(),
            parameters: est.parameters,
        })
    })
}
