//! Missing-effect discovery: when updating the nominal parameters cannot close the gap between
//! model and measurement, find which candidate effect explains it.
//!
//! 1. **Calibrate** the nominal parameters (damped least squares).
//! 2. **Detect**: χ² of the calibrated residual against the noise, overall (p-value) and per mode.
//! 3. **Screen** every candidate by the χ² reduction a linear fit of its value would give, with
//!    the residual's sensitivity projected off the already-fitted parameters.
//! 4. **Refit** the most promising with the nominal parameters (a local fit from the screen's
//!    Gauss–Newton value; the best few confirmed with restarts), each round within its share of
//!    the budget ([`Spending`] says how it was spent); **select** by AICc among the physically
//!    plausible fits, and report the runner-up. An ambiguous leader is carried beside its
//!    alternatives through the next step ([`BEAM_WIDTH`]); candidates that would leave no degree
//!    of freedom are reported as [`Untestable`].
//!
//! Nothing here is rotor-specific: a plugin offers [`Candidate`]s, the engine does the rest.

mod interval;

use crate::analysis::chi2::{normal_quantile_upper, Z_95};
use crate::analysis::{chi2_quantile_upper, chi2_upper_tail};
use crate::eigen::EigenSolver;
use crate::measurement::{MeasuredMode, Measurement};
use crate::model::{Augmented, Candidate, StructuralModel};
use crate::problem::multi::Stacked;
use crate::problem::{Linearisation, Objective, Problem};
use crate::update::refit::{RefitChoice, RefitRequest};
use crate::update::{Budget, Driver, Termination};
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
    /// The evaluation budget ([`DiscoveryOptions::max_evaluations`]) ran out before the
    /// calibration finished: there is no misfit to judge yet.
    #[error("the budget of {0} model evaluations ran out before the calibration finished")]
    BudgetExhausted(usize),
}

/// Settings of the workflow.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscoveryOptions {
    /// Significance level of the χ² test (default [`SIGNIFICANCE`](crate::analysis::verdict::SIGNIFICANCE),
    /// the one level of every verdict).
    pub significance: f64,
    /// Candidates refitted after screening (default 8; switches are always refitted), and the
    /// most candidates predicting like the leading fit refitted beside it in each round.
    pub refits: usize,
    /// AICc improvement over the base model needed to name an effect (default 6: with ~130
    /// candidates to choose from, 4 named a noise fit in 2.4 % of 330 clean independent draws,
    /// 6 in 1.5 %; docs/discovery.md).
    pub min_aicc_gain: f64,
    /// Relative frequency std assumed for modes without one (default 1e-3).
    pub assumed_relative_std: f64,
    /// An effect is named only if, with it, the misfit is one noise can explain: P(χ² ≥ observed)
    /// at least this (default 1e-3). A better but still inconsistent fit is reported, not named.
    pub min_after_p_value: f64,
    /// Candidates of each kind refitted whatever their screening rank (default 1).
    pub refits_per_kind: usize,
    /// Most effects added by forward selection (default 3).
    pub max_effects: usize,
    /// Alternatives within this AICc of a named effect are always reported as ambiguous (default
    /// 2); so is any alternative the data cannot reject ([`indistinguishable`]).
    pub ambiguity_aicc: f64,
    /// Most model evaluations (eigen-solves) the whole run may spend (default
    /// [`DEFAULT_EVALUATIONS`]): bounded time whatever the data. When they run out the search
    /// stops with what it has ([`DiscoveryReport::budget_exhausted`]).
    pub max_evaluations: usize,
    /// Calibrate by a local fit from `initial` only, without restarts from a coarse grid
    /// (default false): for a start known to be close, such as one mesh's calibration carried
    /// to a refined mesh, where restarts would only spend solves on a misfit no start removes.
    pub local_calibration: bool,
    /// Most first choices carried through the next step when the leader's alternatives pass the
    /// ambiguity test and a further effect is needed (default [`BEAM_WIDTH`]; 1: the leader
    /// only, the selection of before).
    pub beam_width: usize,
    /// The strategy of the calibration and of every candidate's refit (default: damped least
    /// squares, [`Damped`](crate::update::refit::Damped)); a registered one by
    /// [`Registered`](crate::update::refit::Registered).
    pub refit: RefitChoice,
}

/// Evaluations a discovery run may spend by default: about 1 s of one core on 8 modes of the
/// paper rotor (~0.1 ms per evaluation of its 22 DOFs, more on the 4-fold refined mesh), several
/// times what the hardest independent data of the study needed (see docs/discovery.md,
/// "Bounded time").
pub const DEFAULT_EVALUATIONS: usize = 10_000;

impl Default for DiscoveryOptions {
    fn default() -> Self {
        Self {
            significance: crate::analysis::verdict::SIGNIFICANCE,
            refits: 8,
            min_aicc_gain: 6.0,
            assumed_relative_std: 1e-3,
            min_after_p_value: 1e-3,
            refits_per_kind: 1,
            max_effects: 3,
            ambiguity_aicc: 2.0,
            max_evaluations: DEFAULT_EVALUATIONS,
            local_calibration: false,
            beam_width: BEAM_WIDTH,
            refit: RefitChoice::default(),
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

/// What an effect is and where: the part of a refitted candidate, an alternative and a named
/// effect that identifies it (serialised flat into each).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct Place {
    /// The candidate's label, `kind@location`.
    #[serde(skip)]
    pub label: String,
    /// Kind.
    pub kind: String,
    /// Location.
    pub location: Option<usize>,
    /// Position along the structure (m), for an effect placed by coordinate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position_m: Option<f64>,
    /// First and last element, for an effect over a run of elements.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<[usize; 2]>,
    /// For a taper over `elements`, the element where the value applies in full (the change
    /// falls linearly to nothing at the run's other end).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub taper_to: Option<usize>,
}

impl Place {
    /// An effect of `kind` placed so, labelled as a candidate would be.
    pub fn new(
        kind: &str,
        location: Option<usize>,
        position_m: Option<f64>,
        elements: Option<[usize; 2]>,
    ) -> Self {
        let label = crate::model::candidate::label_of(kind, location, position_m, elements, None);
        Self { label, kind: kind.to_string(), location, position_m, elements, taper_to: None }
    }

    /// The same place as a taper whose value applies in full at element `e` (`None`: uniform).
    pub fn tapered_to(self, e: Option<usize>) -> Self {
        let label =
            crate::model::candidate::label_of(&self.kind, self.location, self.position_m, self.elements, e);
        Self { label, taper_to: e, ..self }
    }

    /// The place of candidate `c`.
    pub fn of(c: &Candidate) -> Self {
        Self::new(&c.kind, c.location, c.position_m, c.elements).tapered_to(c.taper_to)
    }
}

/// Reads through to the place (`fit.kind`, `effect.location`): what every report reads first.
macro_rules! reads_place {
    ($($t:ty),*) => {$(
        impl std::ops::Deref for $t {
            type Target = Place;
            fn deref(&self) -> &Place {
                &self.place
            }
        }
    )*};
}
reads_place!(Fit, Alternative, NamedEffect);

/// A refitted candidate. Serialises as a `discover` report's candidate (what, where, value,
/// interval, χ², AICc, plausibility).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Fit {
    /// What was fitted and where.
    #[serde(flatten)]
    pub place: Place,
    /// Fitted value (`None` for a switch).
    pub value: Option<f64>,
    /// Unit of the value.
    pub unit: String,
    /// 95% interval of the value.
    pub interval: Option<[f64; 2]>,
    /// All fitted parameters: the base's, then the values of every effect in the fit.
    #[serde(skip)]
    pub parameters: Vec<f64>,
    /// 95% (covariance) intervals of all fitted parameters, where they could be computed.
    #[serde(skip)]
    pub intervals: Vec<Option<[f64; 2]>>,
    /// χ² of the fit.
    pub chi2: f64,
    /// AICc of the fit.
    pub aicc: f64,
    /// What choosing its effects' places cost: 2·ln m per effect whose kind the search tried at
    /// m places (see [`place_charges`]). Selection ranks by `aicc + place_charge`.
    pub place_charge: f64,
    /// Is the value physically plausible (and, for a value, its interval clear of zero)?
    pub plausible: bool,
    /// True when the fit leaves too few degrees of freedom for the AICc (n − k − 1 ≤ 0, its
    /// correction unbounded): `aicc` then holds the AIC χ² + 2k, and the effect is named only if
    /// it also passes a likelihood-ratio test (see [`criterion`]).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub aicc_undefined: bool,
    /// Model frequencies of the measured modes, Hz.
    #[serde(skip)]
    pub frequencies_hz: Vec<f64>,
}

impl Fit {
    /// What selection ranks by: AICc plus the charge for the places chosen.
    pub fn score(&self) -> f64 {
        self.aicc + self.place_charge
    }

    /// The calibrated base model as a "fit" with no effect, `n` measured values.
    fn base(lin: &Linearisation, n: usize) -> Self {
        let chi2 = 2.0 * lin.cost();
        let (aicc, aicc_undefined) = criterion(chi2, n, lin.parameters.len());
        Self {
            place: Place::default(),
            value: None,
            unit: String::new(),
            interval: None,
            parameters: lin.parameters.clone(),
            intervals: vec![None; lin.parameters.len()],
            chi2,
            aicc,
            place_charge: 0.0,
            plausible: true,
            aicc_undefined,
            frequencies_hz: lin.frequencies_hz.clone(),
        }
    }
}

/// An alternative that explains the data about as well as a named effect.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Alternative {
    /// What and where.
    #[serde(flatten)]
    pub place: Place,
    /// Its fitted value.
    pub value: Option<f64>,
    /// Unit of the value.
    pub unit: String,
    /// Its AICc minus the named effect's, each with its place charge ([`Fit::score`]; ≥ 0).
    pub delta_aicc: f64,
}

impl Alternative {
    fn new(c: &Candidate, fit: &Fit, named_aicc: f64) -> Self {
        Self {
            place: Place::of(c),
            value: fit.value,
            unit: c.unit().to_string(),
            delta_aicc: fit.score() - named_aicc,
        }
    }
}

/// One effect named by forward selection, with its value from the final joint fit.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NamedEffect {
    /// What and where.
    #[serde(flatten)]
    pub place: Place,
    /// Fitted value in the final joint fit (`None` for a switch, reported as 1: on).
    #[serde(serialize_with = "value_or_on")]
    pub value: Option<f64>,
    /// Its 95% interval.
    pub interval: Option<[f64; 2]>,
    /// Unit of the value.
    pub unit: String,
    /// AICc gained when the effect was added, less the charge for choosing its place
    /// ([`Fit::score`]).
    pub delta_aicc: f64,
    /// Alternatives within [`DiscoveryOptions::ambiguity_aicc`] when it was chosen, or that the
    /// data could not reject ([`indistinguishable`]).
    pub ambiguous_with: Vec<Alternative>,
    /// The effect's further fitted values ([`Candidate::companions`]) in the final joint fit.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub companions: Vec<CompanionValue>,
}

/// A further fitted value of a named effect (a pedestal's stiffness beside its mass).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CompanionValue {
    /// The parameter's name.
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// Its 95% interval.
    pub interval: Option<[f64; 2]>,
    /// Unit.
    pub unit: String,
}

/// A switched effect has no value; reports give it as 1 ("on").
fn value_or_on<S: serde::Serializer>(value: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(value.unwrap_or(1.0))
}

impl NamedEffect {
    fn new(c: &Candidate, delta_aicc: f64, ambiguous_with: Vec<Alternative>) -> Self {
        Self {
            place: Place::of(c),
            value: None,
            interval: None,
            unit: c.unit().to_string(),
            delta_aicc,
            ambiguous_with,
            companions: Vec::new(),
        }
    }
}

/// How far the calibrated base model (no effect added) misses the data: the test that decides
/// whether to search at all. Serialises with the keys `discover` reports (`chi2_before`,
/// `dof_before`, `p_value`, `disagreement_significant`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BaseMisfit {
    /// χ² of the calibrated base model.
    #[serde(rename = "chi2_before")]
    pub chi2: f64,
    /// Degrees of freedom of the base fit (modes − parameters).
    #[serde(rename = "dof_before")]
    pub dof: usize,
    /// P(χ² ≥ observed) under noise alone.
    pub p_value: f64,
    /// True when the misfit is significant at the chosen level.
    #[serde(rename = "disagreement_significant")]
    pub significant: bool,
    /// AICc of the base model (the score every effect must beat).
    #[serde(skip)]
    pub aicc: f64,
}

/// Everything the workflow found, for reports.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscoveryReport {
    /// Calibrated nominal parameters.
    pub base_parameters: Vec<f64>,
    /// How far the calibrated base model misses the data, and whether that is beyond the noise.
    pub before: BaseMisfit,
    /// Screening scores (predicted χ² reduction), best first.
    pub screening: Vec<(String, f64)>,
    /// Refitted candidates, best AICc first.
    pub fits: Vec<Fit>,
    /// The final joint fit, labelled by the strongest (first) named effect; `None` when nothing
    /// is named.
    pub selected: Option<Fit>,
    /// Every named effect, in the order forward selection added them (strongest first).
    pub effects: Vec<NamedEffect>,
    /// The best plausible alternative to the named effect.
    pub runner_up: Option<Fit>,
    /// Per mode, before and after.
    pub modes: Vec<ModeComparison>,
    /// RMS of model − measured before, Hz.
    pub rms_before_hz: f64,
    /// RMS of model − measured after, Hz.
    pub rms_after_hz: f64,
    /// Model evaluations (eigen-solves) spent.
    pub evaluations: usize,
    /// True when [`DiscoveryOptions::max_evaluations`] ran out before the search ended.
    pub budget_exhausted: bool,
    /// How the evaluations were spent, by phase.
    pub spending: Spending,
    /// Candidates that could not be tested in the first round: with them the fit would have as
    /// many parameters as measured values (no degree of freedom left), so any of them fits
    /// exactly and its χ² says nothing.
    pub untestable: Vec<Untestable>,
}

/// Evaluations (eigen-solves) a discovery run spent, by phase; `discover --json` reports it as
/// `budget_spent`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Spending {
    /// The caller's check of the data before the search (`discover`'s check that every measured
    /// mode is within the model's reach); 0 in the library's own runs.
    pub data_check: usize,
    /// Calibrating the nominal parameters.
    pub calibration: usize,
    /// The linear screen: one linearisation per candidate and round (the candidate's sensitivity
    /// column beside the current fit's Jacobian; no refit).
    pub screening: usize,
    /// Refits of the screen's leaders (the best few, the best of each kind, the switches).
    pub refits: usize,
    /// Confirming each round's leading fit: refits of the candidates predicting alike.
    pub confirmation: usize,
    /// Carrying an ambiguous leader's alternatives through the next steps ([`BEAM_WIDTH`]).
    pub carried: usize,
    /// Leader refits not run or cut short because the round's share of the budget was spent
    /// (the rest is kept for confirmation and the rounds after).
    pub refits_skipped: usize,
    /// A plugin's further searches on another form of the model (the rotor's refined mesh: its
    /// calibration and, when run, its whole search).
    pub refined_mesh: usize,
}

/// A candidate that could not be tested: with it the fit would leave no degree of freedom.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Untestable {
    /// What and where.
    #[serde(flatten)]
    pub place: Place,
    /// Parameters the fit with it would have.
    pub parameters: usize,
    /// Measured values.
    pub modes: usize,
}

/// Corrected Akaike information criterion with known σ: χ² + 2k + 2k(k+1)/(n − k − 1).
pub fn aicc(chi2: f64, n: usize, k: usize) -> f64 {
    let (n, k) = (n as f64, k as f64);
    let correction = if n - k - 1.0 > 0.0 { 2.0 * k * (k + 1.0) / (n - k - 1.0) } else { f64::INFINITY };
    chi2 + 2.0 * k + correction
}

/// The score of a fit of `k` parameters to `n` values with χ² `chi2`: its [`aicc`] when defined
/// (n − k − 1 > 0), else the AIC χ² + 2k and `true` (the AICc's small-sample correction is
/// unbounded there; comparisons then also need a likelihood-ratio test).
pub fn criterion(chi2: f64, n: usize, k: usize) -> (f64, bool) {
    if n > k + 1 {
        (aicc(chi2, n, k), false)
    } else {
        (chi2 + 2.0 * k as f64, true)
    }
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
    let search = ModelSearch { models, solver, measured };
    if search.models.iter().any(|m| m.parameters() != model.parameters()) {
        return Err(DiscoveryError::Data("the configurations' parameters differ".into()));
    }
    discover_effects(&search, candidates, initial, options)
}

/// One measured value of the data discovery explains, with the standard deviation it is
/// weighed by.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRow {
    /// Test configuration (or, on a run-up, the speed's index).
    pub configuration: usize,
    /// 0-based mode number.
    pub mode: usize,
    /// Measured frequency, Hz.
    pub frequency_hz: f64,
    /// Its standard deviation, Hz.
    pub std_hz: f64,
}

/// What discovery searches: a base least-squares problem, and the same problem with candidate
/// effects added. [`discover_configurations`] builds one from [`StructuralModel`]s (effects as
/// symmetric ΔK, ΔM through [`Augmented`]); a plugin whose effects are not of that form (the
/// two-plane rotor at speed: gyroscopic and cross-coupled terms) implements it over its own
/// [`Objective`] and runs the same selection with [`discover_effects`].
pub trait EffectSearch {
    /// Runs `f` on the objective with the effects `set` added, their values after the base
    /// parameters in order; `None` when it cannot be built.
    fn with_effects<T>(&self, set: &[&Candidate], f: impl FnOnce(&dyn Objective) -> Option<T>) -> Option<T>;

    /// Runs `f` on the base objective, for the calibration (by default with no effect added).
    fn with_base<T>(&self, f: impl FnOnce(&dyn Objective) -> Option<T>) -> Option<T> {
        self.with_effects(&[], f)
    }

    /// The measured rows, in the objective's residual order.
    fn rows(&self) -> Vec<MeasuredRow>;

    /// The base parameters a candidate's refit starts from, given the `calibrated` ones (the
    /// current fit's): by default those. A calibration without the missing effect can drive the
    /// base parameters to where they absorb part of it (a rotor's bearings onto their bounds
    /// under a hidden hub), and a refit started there can stay in that basin; a search that
    /// can tell may start from elsewhere (the model file's values).
    fn refit_base_start(&self, calibrated: &[f64]) -> Vec<f64> {
        calibrated.to_vec()
    }
}

/// Discovery over structural models: each configuration's model with the effects added to its
/// K and M.
struct ModelSearch<'a, M, S> {
    models: Vec<&'a M>,
    solver: &'a S,
    measured: Vec<Measurement>,
}

impl<M: StructuralModel, S: EigenSolver> EffectSearch for ModelSearch<'_, M, S> {
    fn with_effects<T>(&self, set: &[&Candidate], f: impl FnOnce(&dyn Objective) -> Option<T>) -> Option<T> {
        with_augmented(&self.models, self.solver, &self.measured, set, f)
    }

    fn with_base<T>(&self, f: impl FnOnce(&dyn Objective) -> Option<T>) -> Option<T> {
        let problems: Vec<Problem<&M, &S>> = self
            .models
            .iter()
            .zip(&self.measured)
            .map(|(&m, d)| Problem::new(m, self.solver, d.clone()))
            .collect();
        let base = Stacked::new(problems.iter().map(|p| p as &dyn Objective).collect())?;
        f(&base)
    }

    fn rows(&self) -> Vec<MeasuredRow> {
        self.measured
            .iter()
            .enumerate()
            .flat_map(|(c, m)| m.modes().iter().map(move |mode| (c, mode)))
            .map(|(configuration, m)| MeasuredRow {
                configuration,
                mode: m.mode,
                frequency_hz: m.frequency_hz,
                std_hz: m.std_hz.unwrap_or(f64::NAN),
            })
            .collect()
    }
}

/// The discovery workflow (calibrate, detect, forward selection of `candidates`) on any
/// [`EffectSearch`], starting the calibration from `initial`.
pub fn discover_effects<E: EffectSearch>(
    search: &E,
    candidates: &[Candidate],
    initial: &[f64],
    options: &DiscoveryOptions,
) -> Result<DiscoveryReport, DiscoveryError> {
    let rows = search.rows();
    let n = rows.len();
    let nb = search
        .with_base(|base| Some(base.parameters().len()))
        .ok_or_else(|| DiscoveryError::Data("the base problem could not be built".into()))?;
    if n <= nb {
        return Err(DiscoveryError::Data(format!(
            "{n} measured modes for {nb} parameters: detecting a missing effect needs more modes than parameters"
        )));
    }
    let stds: Vec<f64> = rows.iter().map(|r| r.std_hz).collect();
    let budget = Budget::new(options.max_evaluations);
    // (a) calibrate
    let est = search
        .with_base(|base| {
            let request = RefitRequest { restarts: !options.local_calibration, ..RefitRequest::default() };
            Some(options.refit.refit(base, initial, &request, Driver::default().max_iterations, &budget))
        })
        .ok_or_else(|| DiscoveryError::Data("the base problem could not be built".into()))?
        .map_err(|e| match budget.exhausted() {
            true => DiscoveryError::BudgetExhausted(options.max_evaluations),
            false => DiscoveryError::Calibration(e.to_string()),
        })?;
    // A calibration cut short has no χ² to judge: saying "explained by the noise" would be a guess.
    if matches!(est.termination, Termination::BudgetExhausted { .. }) {
        return Err(DiscoveryError::BudgetExhausted(options.max_evaluations));
    }
    let base_lin = est.last;
    let chi2 = 2.0 * base_lin.cost();
    let p_value = chi2_upper_tail(chi2, n - nb);
    let before = BaseMisfit {
        chi2,
        dof: n - nb,
        p_value,
        significant: p_value < options.significance,
        aicc: aicc(chi2, n, nb),
    };
    let mut report = DiscoveryReport {
        base_parameters: base_lin.parameters.clone(),
        before,
        screening: Vec::new(),
        fits: Vec::new(),
        selected: None,
        runner_up: None,
        effects: Vec::new(),
        modes: compare_modes(&rows, &base_lin, &base_lin),
        rms_before_hz: rms_diff(&base_lin),
        rms_after_hz: rms_diff(&base_lin),
        evaluations: 0,
        budget_exhausted: false,
        spending: Spending { calibration: budget.used(), ..Spending::default() },
        untestable: Vec::new(),
    };
    if !before.significant {
        report.evaluations = budget.used();
        report.budget_exhausted = budget.exhausted();
        return Ok(report);
    }
    // (b) forward selection: each round screens the candidates not yet chosen against the model
    // with the chosen ones, refits the most promising jointly with everything already fitted, and
    // adds the best plausible one if it earns its parameter (AICc); it stops when the noise
    // explains what is left. When the leader's alternatives pass the ambiguity test and a further
    // effect is needed, each of them (at most `BEAM_WIDTH` in all) is carried through the
    // following rounds and the final models are compared.
    let context = Selection {
        search,
        candidates,
        charges: place_charges(candidates),
        stds,
        n,
        options,
        budget: &budget,
        compared: candidates.len().max(1),
    };
    let trunk = Path { chosen: Vec::new(), current: Fit::base(&base_lin, n), named: Vec::new() };
    let mut log = RoundLog::default();
    let path = context.extend(trunk, 0, true, budget.limit(), &mut log);
    report.screening = log.screening;
    report.fits = log.fits;
    report.runner_up = log.runner_up;
    report.untestable = log.untestable;
    report.spending.screening = log.spending.screening;
    report.spending.refits = log.spending.refits;
    report.spending.confirmation = log.spending.confirmation;
    report.spending.refits_skipped = log.spending.refits_skipped;
    report.spending.carried = log.spending.carried;
    let Path { chosen, current, mut named } = path;
    report.evaluations = budget.used();
    // Refits cut short by the budget plan are not refused evaluations, but a search that used
    // every evaluation it had did stop at its budget: said so, as a refusal would be.
    report.budget_exhausted = budget.exhausted() || budget.remaining() == 0;
    // (c) name the effects only if, with them, the misfit is one the noise can explain.
    let k = current.parameters.len();
    let consistent = n > k && chi2_upper_tail(current.chi2, n - k) >= options.min_after_p_value;
    if named.is_empty() || !consistent {
        return Ok(report);
    }
    // Values and intervals of the final joint fit, in the order the effects were added.
    let mut next = nb;
    for (effect, &i) in named.iter_mut().zip(&chosen) {
        let c = &candidates[i];
        if c.parameter.is_some() {
            effect.value = Some(current.parameters[next]);
            effect.interval = current.intervals.get(next).copied().flatten();
            next += 1;
        }
        for comp in &c.companions {
            effect.companions.push(CompanionValue {
                name: comp.parameter.name.clone(),
                value: current.parameters[next],
                interval: current.intervals.get(next).copied().flatten(),
                unit: comp.parameter.unit.clone(),
            });
            next += 1;
        }
    }
    let first = &named[0];
    let mut selected = current.clone();
    selected.place = first.place.clone();
    selected.value = first.value;
    selected.unit = first.unit.clone();
    selected.interval = first.interval;
    for (m, f) in report.modes.iter_mut().zip(&selected.frequencies_hz) {
        m.after_hz = *f;
    }
    let diffs: Vec<f64> = report.modes.iter().map(|m| m.after_hz - m.measured_hz).collect();
    report.rms_after_hz = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    report.selected = Some(selected);
    report.effects = named;
    Ok(report)
}

/// Squared distance between two fits' predictions in units of the noise: Σ ((a − b)/σ)².
pub fn separation2(a: &[f64], b: &[f64], std_hz: &[f64]) -> f64 {
    a.iter().zip(b).zip(std_hz).map(|((a, b), s)| ((a - b) / s).powi(2)).sum()
}

/// Can the data not tell an alternative from the fit it trails by `delta` (its score minus the
/// other's, ≥ 0), their predictions `separation2` apart ([`separation2`])? Always when `delta` is
/// under `floor` (the AICc margin); else when a 95 % likelihood-ratio test cannot reject the
/// alternative. Were the alternative true, the other fit's χ² would exceed its own by
/// d² + 2d·Z (d = √separation2, Z standard normal: the noise projected on the difference of the
/// predictions), so the data reject it only when `delta` > 2·1.96·d − d². The margin is largest,
/// 1.96² = 3.84, for fits about 2σ apart (a taper and the step it resembles at 0.2 % noise) and
/// falls under `floor` for fits the data separate clearly (d > 3.4).
pub fn indistinguishable(delta: f64, separation2: f64, floor: f64) -> bool {
    within_margin(delta, separation2, floor, Z_95)
}

/// [`indistinguishable`] by a one-sided test at the normal quantile `z` (1.96: 2.5 %; larger when
/// one test of several): the margin 2·z·d − d², at least `floor`.
fn within_margin(delta: f64, separation2: f64, floor: f64, z: f64) -> bool {
    let d = separation2.max(0.0).sqrt();
    delta < floor.max(2.0 * z * d - separation2)
}

/// Likeness ([`likeness`]) from which a candidate is refitted beside the leading fit.
const ALIKE: f64 = 0.9;

/// The charge for choosing each candidate's place: 2·ln m, m the number of places its kind is
/// offered at. The best of m places fits noise better than one place given in advance (the
/// look-elsewhere effect: the largest of m χ²₁ draws grows as 2·ln m), so a point mass picked
/// among 41 positions must beat a switch with one place (the shaft's rotary inertia) by that much
/// more before it is preferred — the charge of the risk-inflation criterion (Foster & George,
/// Ann. Statist. 22, 1994) for choosing one of m candidate places.
pub fn place_charges(candidates: &[Candidate]) -> Vec<f64> {
    let mut places: Vec<(&str, Vec<Place>)> = Vec::new();
    for c in candidates {
        let place = Place::of(c);
        match places.iter_mut().find(|(k, _)| *k == c.kind) {
            Some((_, seen)) if !seen.contains(&place) => seen.push(place),
            Some(_) => {}
            None => places.push((&c.kind, vec![place])),
        }
    }
    candidates
        .iter()
        .map(|c| {
            let m = places.iter().find(|(k, _)| *k == c.kind).map_or(1, |(_, seen)| seen.len());
            2.0 * (m as f64).ln()
        })
        .collect()
}

/// (a − b)/σ per measured value: a change of predictions in units of the noise.
fn noise_units(a: &[f64], b: &[f64], std_hz: &[f64]) -> DVector<f64> {
    DVector::from_iterator(a.len(), a.iter().zip(b).zip(std_hz).map(|((a, b), s)| (a - b) / s))
}

/// How alike two changes of the predictions are, whatever their size or sign: |cos| of the
/// angle between them (0 when either is nothing).
fn likeness(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    let norms = a.norm() * b.norm();
    if norms > 0.0 {
        (a.dot(b) / norms).abs()
    } else {
        0.0
    }
}

/// Two candidates that describe the same thing at the same place (never chosen twice).
fn same_place(a: &Candidate, b: &Candidate) -> bool {
    a.kind == b.kind && a.location == b.location && a.position_m == b.position_m && a.elements == b.elements
}

/// Most first choices carried through the next step when the leader is ambiguous, by default
/// ([`DiscoveryOptions::beam_width`]): the leader and its best alternatives that the data cannot
/// tell from it (a small beam).
pub const BEAM_WIDTH: usize = 3;

/// Share of a round's allowance that the local refits of the screen's leaders may spend; the rest
/// is kept for confirming the leading fits (look-alikes, restarts), so a round of many candidates
/// can no longer spend the budget before its leader is confirmed.
const REFIT_SHARE: f64 = 0.5;

/// Share of what is left of the budget that a round may spend when more rounds may follow: the
/// rest is kept so a further effect can still be screened, refitted and confirmed (a second
/// round costs more than the first: one more parameter in every fit).
const ROUND_SHARE: f64 = 0.75;

/// Fits of a round refitted with restarts (from a grid of seeds) before the choice: the best few
/// local fits, so the leader and its nearest rivals rest on full fits.
const CONFIRMED: usize = 3;

/// One line of forward selection: the effects chosen so far and the joint fit with them.
#[derive(Clone)]
struct Path {
    chosen: Vec<usize>,
    current: Fit,
    named: Vec<NamedEffect>,
}

/// What the rounds record for the report (the first round's screen, fits and runner-up) and how
/// the budget was spent.
#[derive(Default)]
struct RoundLog {
    screening: Vec<(String, f64)>,
    fits: Vec<Fit>,
    runner_up: Option<Fit>,
    untestable: Vec<Untestable>,
    spending: Spending,
}

/// Everything a round of forward selection needs.
struct Selection<'a, E> {
    search: &'a E,
    candidates: &'a [Candidate],
    charges: Vec<f64>,
    stds: Vec<f64>,
    n: usize,
    options: &'a DiscoveryOptions,
    budget: &'a Budget,
    /// Candidates on offer: the look-elsewhere count of the likelihood-ratio test.
    compared: usize,
}

/// How one refit ended.
enum RefitOutcome {
    /// Converged (or stopped) with a fit.
    Fit(Box<Fit>),
    /// Could not be built or run.
    Failed,
    /// Cut short by the share of the budget it was given: not a fit.
    CutShort,
}

impl<E: EffectSearch> Selection<'_, E> {
    /// Is `fit` a misfit the noise explains at the detection level (no further effect sought)?
    fn explained(&self, fit: &Fit) -> bool {
        let k = fit.parameters.len();
        self.n > k && chi2_upper_tail(fit.chi2, self.n - k) >= self.options.significance
    }

    /// Does `best` earn its place over `current`: AICc (with the place charges) better by
    /// [`DiscoveryOptions::min_aicc_gain`]? Where a fit leaves too few degrees of freedom for the
    /// AICc (n − k − 1 ≤ 0: [`Fit::aicc_undefined`]) both are scored by the AIC χ² + 2k instead,
    /// and the added values must also pass the likelihood-ratio test at the significance level
    /// shared among the candidates on offer (Bonferroni: the best of many fits noise better).
    /// Returns the gain when it does.
    fn earns(&self, current: &Fit, best: &Fit) -> Option<f64> {
        if !(current.aicc_undefined || best.aicc_undefined) {
            let gain = current.score() - best.score();
            return (gain >= self.options.min_aicc_gain).then_some(gain);
        }
        let aic = |f: &Fit| f.chi2 + 2.0 * f.parameters.len() as f64 + f.place_charge;
        let gain = aic(current) - aic(best);
        let added = best.parameters.len().saturating_sub(current.parameters.len());
        let tested = added == 0
            || current.chi2 - best.chi2
                > chi2_quantile_upper(self.options.significance / self.compared as f64, added);
        (gain >= self.options.min_aicc_gain && tested).then_some(gain)
    }

    /// The alternatives to `best` (candidate `best_i`) among a round's `fits` that the data cannot
    /// reject: each tested against it at 2.5 %/m, m the plausible fits compared (Bonferroni), so
    /// the named effect and its alternatives together hold the truth in ≥ 95 % of draws.
    fn ambiguity(&self, fits: &[(usize, Fit)], best_i: usize, best: &Fit) -> Vec<Alternative> {
        let c = self.candidates;
        let others: Vec<&(usize, Fit)> =
            fits.iter().filter(|(i, f)| f.plausible && !same_place(&c[*i], &c[best_i])).collect();
        let z = normal_quantile_upper(0.025 / others.len().max(1) as f64);
        others
            .into_iter()
            .filter(|(_, f)| {
                let apart = separation2(&f.frequencies_hz, &best.frequencies_hz, &self.stds);
                within_margin(f.score() - best.score(), apart, self.options.ambiguity_aicc, z)
            })
            .map(|(i, f)| Alternative::new(&c[*i], f, best.score()))
            .collect()
    }

    /// Forward selection from `path`, rounds `first..`; `may_branch`: an ambiguous leader may be
    /// carried beside its alternatives (once per search: the branches do not branch again).
    /// The rounds spend the budget up to `until` evaluations used: each round [`ROUND_SHARE`] of
    /// what is left, the last round possible all of it.
    fn extend(
        &self,
        mut path: Path,
        first: usize,
        may_branch: bool,
        until: usize,
        log: &mut RoundLog,
    ) -> Path {
        let candidates = self.candidates;
        for round in first..self.options.max_effects {
            if self.budget.exhausted() || (round > 0 && self.explained(&path.current)) {
                break;
            }
            let used = self.budget.used();
            let round_end = match self.options.max_effects - round {
                1 => until,
                _ => used + (until.saturating_sub(used) as f64 * ROUND_SHARE) as usize,
            };
            let fits = self.round(&path, round == 0, round_end, log);
            let mut plausible = fits.iter().filter(|(_, f)| f.plausible);
            let Some((best_i, best)) = plausible.next().cloned() else { break };
            let Some(gain) = self.earns(&path.current, &best) else { break };
            if round == 0 {
                log.runner_up = plausible.next().map(|(_, f)| f.clone());
            }
            let ambiguous_with = self.ambiguity(&fits, best_i, &best);
            let continues = round + 1 < self.options.max_effects && !self.explained(&best);
            if may_branch && continues && !ambiguous_with.is_empty() && self.options.beam_width > 1 {
                return self.carry(path, round, &fits, (best_i, &best), until, log);
            }
            path.named.push(NamedEffect::new(&candidates[best_i], gain, ambiguous_with));
            path.chosen.push(best_i);
            path.current = best;
        }
        path
    }

    /// The leader `best` of round `round` is ambiguous and a further effect is needed: the leader
    /// and its best alternatives (at most [`BEAM_WIDTH`], each earning its place on its own) are
    /// each carried through the rounds after, and the final model with the best AICc (place
    /// charges included) wins. A second effect that only compensates a wrong first choice then
    /// loses to the right first choice, which needs none. The other carried first choices are
    /// listed as ambiguous with the winner's when the data cannot tell the final models apart.
    fn carry(
        &self,
        path: Path,
        round: usize,
        fits: &[(usize, Fit)],
        (best_i, best): (usize, &Fit),
        until: usize,
        log: &mut RoundLog,
    ) -> Path {
        let c = self.candidates;
        let leader_alternatives = self.ambiguity(fits, best_i, best);
        let mut starts: Vec<(usize, Fit)> = vec![(best_i, best.clone())];
        for (i, f) in fits {
            if starts.len() >= self.options.beam_width {
                break;
            }
            let listed = leader_alternatives.iter().any(|a| a.place == Place::of(&c[*i]));
            if f.plausible && *i != best_i && listed && self.earns(&path.current, f).is_some() {
                starts.push((*i, f.clone()));
            }
        }
        let mut ends: Vec<Path> = Vec::with_capacity(starts.len());
        for (b, (i, f)) in starts.iter().enumerate() {
            // Each carried first choice gets an equal share of what is left.
            let used = self.budget.used();
            let until = used + until.saturating_sub(used) / (starts.len() - b);
            let mut p = path.clone();
            let gain = self.earns(&p.current, f).unwrap_or(p.current.score() - f.score());
            p.named.push(NamedEffect::new(&c[*i], gain, Vec::new()));
            p.chosen.push(*i);
            p.current = f.clone();
            if b == 0 {
                ends.push(self.extend(p, round + 1, false, until, log));
            } else {
                // The alternatives' steps are what carrying the doubt costs.
                let mut scratch = RoundLog::default();
                let spent = self.budget.used();
                ends.push(self.extend(p, round + 1, false, until, &mut scratch));
                log.spending.carried += self.budget.used() - spent;
                log.spending.refits_skipped += scratch.spending.refits_skipped;
            }
        }
        let w = (0..ends.len())
            .min_by(|&a, &b| ends[a].current.score().total_cmp(&ends[b].current.score()))
            .unwrap_or(0);
        // The winner's first choice: its alternatives among the round's fits, except the other
        // carried first choices, which are judged by their final models instead.
        let (wi, wf) = (&starts[w].0, &starts[w].1);
        let carried = |i: usize| starts.iter().any(|(s, _)| same_place(&c[*s], &c[i]));
        let mut ambiguous_with: Vec<Alternative> = self
            .ambiguity(fits, *wi, wf)
            .into_iter()
            .filter(|a| !fits.iter().any(|(i, _)| carried(*i) && Place::of(&c[*i]) == a.place))
            .collect();
        let winner = &ends[w].current;
        let z = normal_quantile_upper(0.025 / (ends.len() - 1).max(1) as f64);
        for (b, end) in ends.iter().enumerate().filter(|&(b, _)| b != w) {
            let delta = end.current.score() - winner.score();
            let apart = separation2(&end.current.frequencies_hz, &winner.frequencies_hz, &self.stds);
            if within_margin(delta, apart, self.options.ambiguity_aicc, z) {
                let (si, sf) = &starts[b];
                ambiguous_with.push(Alternative {
                    place: Place::of(&c[*si]),
                    value: sf.value,
                    unit: c[*si].unit().to_string(),
                    delta_aicc: delta,
                });
            }
        }
        let mut end = ends.swap_remove(w);
        if let Some(first) = end.named.get_mut(round) {
            first.ambiguous_with = ambiguous_with;
        }
        end
    }

    /// One round: screen every open candidate against the current fit, refit the leaders (the
    /// best few, the best of each kind, the switches) within the round's share of the budget,
    /// then confirm the leading fit by refitting its look-alikes. Returns the fits, best first.
    fn round(&self, path: &Path, record: bool, round_end: usize, log: &mut RoundLog) -> Vec<(usize, Fit)> {
        let (candidates, n, options, budget) = (self.candidates, self.n, self.options, self.budget);
        let chosen_refs: Vec<&Candidate> = path.chosen.iter().map(|&i| &candidates[i]).collect();
        let open = |i: usize| !path.chosen.iter().any(|&c| same_place(&candidates[c], &candidates[i]));
        // A candidate whose fit would leave no degree of freedom cannot be tested: every such fit
        // is exact, so its χ² says nothing. Said, not refitted.
        let k_now = path.current.parameters.len();
        let testable = |c: &Candidate| k_now + c.parameter_count() < n;
        if record {
            log.untestable = candidates
                .iter()
                .enumerate()
                .filter(|&(i, c)| open(i) && !testable(c))
                .map(|(_, c)| Untestable {
                    place: Place::of(c),
                    parameters: k_now + c.parameter_count(),
                    modes: n,
                })
                .collect();
        }
        let spent = budget.used();
        let (screened, projector) = self
            .search
            .with_effects(&chosen_refs, |problem| {
                let lin = budget.wrap(problem).linearise(&path.current.parameters).ok()?;
                let projector = Projector::new(problem, &lin);
                let screened: Vec<(usize, Screened)> = candidates
                    .iter()
                    .enumerate()
                    .filter(|&(i, c)| !c.needs_refit() && open(i) && testable(c))
                    .filter_map(|(i, c)| {
                        screen(self.search, &chosen_refs, c, (&lin, &projector), budget).map(|s| (i, s))
                    })
                    .collect();
                Some((screened, projector))
            })
            .unwrap_or_else(|| (Vec::new(), Projector::none()));
        log.spending.screening += budget.used() - spent;
        let mut scored: Vec<(usize, f64)> = screened.iter().map(|(i, s)| (*i, s.reduction)).collect();
        scored.sort_by(|a, b| b.1.total_cmp(&a.1));
        if record {
            log.screening = scored.iter().map(|&(i, s)| (candidates[i].label(), s)).collect();
        }
        // The best few overall, and the best of every kind: a linear screen misjudges large
        // effects, and one kind's many locations must not crowd out the other kinds. In the
        // screen's order, so the leaders are refitted first.
        let mut per_kind: Vec<(&str, usize)> = Vec::new();
        let mut picks: Vec<usize> = Vec::new();
        for (rank, &(i, _)) in scored.iter().enumerate() {
            let kind = candidates[i].kind.as_str();
            let seen = per_kind.iter().position(|(k, _)| *k == kind);
            let taken = seen.map_or(0, |s| per_kind[s].1);
            if rank < options.refits || taken < options.refits_per_kind {
                picks.push(i);
                match seen {
                    Some(s) => per_kind[s].1 += 1,
                    None => per_kind.push((kind, 1)),
                }
            }
        }
        // Effects the screen cannot judge (switches, added DOFs) after the screen's leader.
        let unscreened = candidates
            .iter()
            .enumerate()
            .filter(|&(i, c)| c.needs_refit() && open(i) && testable(c))
            .map(|(i, _)| i);
        let mut to_refit: Vec<usize> = picks.iter().take(1).copied().collect();
        to_refit.extend(unscreened);
        to_refit.extend(picks.iter().skip(1));
        let refit_one = |i: usize, cap: usize, restarts: bool| {
            let mut set = chosen_refs.clone();
            set.push(&candidates[i]);
            // A screened candidate's local fit starts where the screen's Gauss–Newton step put
            // its value (a step cap far below a large value can otherwise keep the fit short of
            // it); the confirmation with restarts from its nominal value, the start the local
            // path may have missed — the better of the two is kept.
            let from = screened.iter().find(|(j, _)| *j == i).map(|(_, s)| s.value).filter(|_| !restarts);
            let fit = refit(
                self.search,
                n,
                &set,
                &path.current.parameters,
                budget,
                (cap, restarts, &self.options.refit),
                from,
            );
            match fit {
                RefitOutcome::Fit(mut fit) => {
                    fit.place_charge = path.current.place_charge + self.charges[i];
                    RefitOutcome::Fit(fit)
                }
                other => other,
            }
        };
        // Refits: a local fit from the current one for each of the screen's leaders (a wrong
        // candidate's fit does not reach the noise, and restarting it from a grid of seeds was
        // most of the work); with restarts for the effects the screen cannot judge. Within the
        // leaders' share of the round's allowance.
        let spent = budget.used();
        let refits_end = spent + ((round_end.saturating_sub(spent)) as f64 * REFIT_SHARE) as usize;
        let mut fits: Vec<(usize, Fit, bool)> = Vec::new();
        let mut skipped = 0;
        for &i in &to_refit {
            let restarts = candidates[i].needs_refit();
            match refit_one(i, refits_end.saturating_sub(budget.used()), restarts) {
                RefitOutcome::Fit(fit) => fits.push((i, *fit, restarts)),
                RefitOutcome::CutShort => skipped += 1,
                RefitOutcome::Failed => {}
            }
        }
        log.spending.refits += budget.used() - spent;
        fits.sort_by(|a, b| a.1.score().total_cmp(&b.1.score()));
        // Confirmation, within the round's allowance: the linear screen misranks close variants
        // of a large effect (a step and the tapers around it crowd each other out of the refits,
        // whether their places overlap or not), so the candidates whose predictions are most
        // alike the leader's are refitted too (at most `refits`), and the best `CONFIRMED` fits
        // are refitted with restarts, so the choice and its ambiguities rest on full fits.
        let spent = budget.used();
        if let Some((_, lead, _)) = fits.iter().find(|(_, f, _)| f.plausible) {
            let change =
                projector.apply(&noise_units(&lead.frequencies_hz, &path.current.frequencies_hz, &self.stds));
            let mut alike: Vec<(usize, f64)> = screened
                .iter()
                .filter(|(i, _)| !fits.iter().any(|(j, _, _)| j == i))
                .map(|(i, s)| (*i, likeness(&s.direction, &change)))
                .collect();
            alike.sort_by(|a, b| b.1.total_cmp(&a.1));
            let near: Vec<usize> =
                alike.iter().take_while(|(_, l)| *l >= ALIKE).take(options.refits).map(|&(i, _)| i).collect();
            for i in near {
                match refit_one(i, round_end.saturating_sub(budget.used()), false) {
                    RefitOutcome::Fit(fit) => fits.push((i, *fit, false)),
                    RefitOutcome::CutShort => skipped += 1,
                    RefitOutcome::Failed => {}
                }
            }
            fits.sort_by(|a, b| a.1.score().total_cmp(&b.1.score()));
        }
        let mut confirmed = 0;
        for (i, fit, full) in &mut fits {
            if confirmed == CONFIRMED {
                break;
            }
            if *full {
                confirmed += 1;
                continue;
            }
            match refit_one(*i, round_end.saturating_sub(budget.used()), true) {
                RefitOutcome::Fit(restarted) => {
                    if restarted.score() <= fit.score() {
                        *fit = *restarted;
                    }
                    *full = true;
                    confirmed += 1;
                }
                RefitOutcome::CutShort => skipped += 1,
                RefitOutcome::Failed => {}
            }
        }
        let mut fits: Vec<(usize, Fit)> = fits.into_iter().map(|(i, f, _)| (i, f)).collect();
        fits.sort_by(|a, b| a.1.score().total_cmp(&b.1.score()));
        log.spending.refits_skipped += skipped;
        log.spending.confirmation += budget.used() - spent;
        if record {
            log.fits = fits.iter().map(|(_, f)| f.clone()).collect();
        }
        fits
    }
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

fn compare_modes(rows: &[MeasuredRow], before: &Linearisation, after: &Linearisation) -> Vec<ModeComparison> {
    rows.iter()
        .enumerate()
        .map(|(k, r)| ModeComparison {
            configuration: r.configuration,
            mode: r.mode,
            measured_hz: r.frequency_hz,
            std_hz: r.std_hz,
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
    fn new(base: &dyn Objective, lin: &Linearisation) -> Self {
        let js = lin.scaled_jacobian(base.parameters());
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

    /// Projects nothing off (no base Jacobian to project).
    fn none() -> Self {
        Self { basis: nalgebra::DMatrix::zeros(0, 0) }
    }

    fn apply(&self, v: &DVector<f64>) -> DVector<f64> {
        if self.basis.ncols() == 0 {
            return v.clone();
        }
        v - &self.basis * (self.basis.transpose() * v)
    }
}

/// The candidates added to every configuration, stacked into one problem, evaluated by `f`.
fn with_augmented<M, S, T>(
    models: &[&M],
    solver: &S,
    measured: &[Measurement],
    set: &[&Candidate],
    f: impl FnOnce(&dyn Objective) -> Option<T>,
) -> Option<T>
where
    M: StructuralModel,
    S: EigenSolver,
{
    let augmented: Vec<Augmented<'_, M>> =
        models.iter().map(|&m| Augmented::with_all(m, set)).collect::<Result<_, _>>().ok()?;
    let problems: Vec<Problem<&Augmented<'_, M>, &S>> =
        augmented.iter().zip(measured).map(|(a, d)| Problem::new(a, solver, d.clone())).collect();
    let stacked = Stacked::new(problems.iter().map(|p| p as &dyn Objective).collect())?;
    f(&stacked)
}

/// What the linear screen says of one candidate.
struct Screened {
    /// Predicted χ² reduction of fitting its value alone, after the current parameters have
    /// absorbed what they can; 0 when the fit would need a value outside the bounds' sign.
    reduction: f64,
    /// How its value moves the predictions (in noise units), off what the current parameters
    /// can do.
    direction: DVector<f64>,
    /// The value one (bound-limited) Gauss–Newton step from the nominal predicts: where its
    /// refit starts.
    value: f64,
}

/// Screens one candidate ([`Screened`]).
fn screen<E: EffectSearch>(
    search: &E,
    chosen: &[&Candidate],
    candidate: &Candidate,
    (current, projector): (&Linearisation, &Projector),
    budget: &Budget,
) -> Option<Screened> {
    let par = candidate.parameter.as_ref()?;
    let mut p = current.parameters.clone();
    p.push(par.nominal);
    let mut set = chosen.to_vec();
    set.push(candidate);
    let lin = search.with_effects(&set, |problem| budget.wrap(problem).linearise(&p).ok())?;
    let j = projector.apply(&lin.jacobian.column(lin.jacobian.ncols() - 1).into_owned());
    let r = projector.apply(&lin.residual);
    let jj = j.norm_squared();
    if jj == 0.0 {
        return Some(Screened { reduction: 0.0, direction: j, value: par.nominal });
    }
    let step = j.dot(&r) / jj;
    let admissible = (par.nominal + step).clamp(par.lower, par.upper) - par.nominal;
    // χ² reduction of the (bound-limited) linear step: 2·a·(j·r) − a²·‖j‖².
    let reduction = (2.0 * admissible * j.dot(&r) - admissible * admissible * jj).max(0.0);
    Some(Screened { reduction, direction: j, value: par.nominal + admissible })
}

/// Refits the current parameters with the candidate set `set` (the chosen ones, then the new
/// one, last); intervals are the covariance ones (cheap: no profile per candidate). The base
/// parameters start where [`EffectSearch::refit_base_start`] says (by default the current ones).
/// The refit may spend at most `cap` evaluations of `budget` (it is cut short,
/// [`RefitOutcome::CutShort`], rather than spend what is kept for later); `restarts`: with the
/// damped strategy's restarts from a grid of seeds when the local fit does not reach the noise,
/// else one local fit; `strategy`: the options' refit strategy. The new candidate's value
/// starts at `from` when given (else its nominal).
fn refit<E: EffectSearch>(
    search: &E,
    n: usize,
    set: &[&Candidate],
    current: &[f64],
    budget: &Budget,
    (cap, restarts, strategy): (usize, bool, &RefitChoice),
    from: Option<f64>,
) -> RefitOutcome {
    let Some(&candidate) = set.last() else { return RefitOutcome::Failed };
    let chosen_values: usize = set[..set.len() - 1].iter().map(|c| c.parameter_count()).sum();
    let Some(base_len) = current.len().checked_sub(chosen_values) else { return RefitOutcome::Failed };
    let mut start = search.refit_base_start(&current[..base_len]);
    if start.len() != base_len {
        return RefitOutcome::Failed;
    }
    start.extend_from_slice(&current[base_len..]);
    start.extend(candidate.parameters().map(|p| p.nominal));
    if let (Some(v), Some(first)) = (from, candidate.parameter.as_ref().map(|_| base_len + chosen_values)) {
        start[first] = v;
    }
    if cap == 0 {
        return RefitOutcome::CutShort;
    }
    let capped = Budget::new(cap);
    let fit = search.with_effects(set, |problem| {
        // Bounded work per candidate: a refit that has not converged in 60 steps is not the
        // explanation (the same limit the profile bounds use).
        let request =
            RefitRequest { step_units: step_units(base_len, set), restarts, ..RefitRequest::default() };
        // Every evaluation charged to the run's budget and to the cap.
        let est = strategy.refit(&budget.wrap(problem), &start, &request, 60, &capped).ok()?;
        // A fit cut short by the budget is not a fit.
        if matches!(est.termination, Termination::BudgetExhausted { .. }) {
            return None;
        }
        let k = problem.parameters().len();
        let chi2 = 2.0 * est.last.cost();
        let (aicc, aicc_undefined) = criterion(chi2, n, k);
        let intervals = interval::covariance_intervals(problem, &est.last);
        // Every fitted effect value (not only the new one) must stay plausible.
        let nb = k - set.iter().map(|c| c.parameter_count()).sum::<usize>();
        let mut index = nb;
        let mut plausible = true;
        let mut value = None;
        let mut interval = None;
        for c in set {
            for (q, (lo, hi)) in c.plausible_ranges().enumerate() {
                let (v, iv) = (est.parameters[index], intervals[index]);
                plausible &= v >= lo && v <= hi;
                if q == 0 && c.parameter.is_some() {
                    // The effect's own value must be clear of zero (a companion need not).
                    plausible &= iv.is_none_or(|iv| iv[0] > 0.0 || iv[1] < 0.0);
                    (value, interval) = (Some(v), iv);
                }
                index += 1;
            }
        }
        if candidate.parameter.is_none() {
            (value, interval) = (None, None);
        }
        Some(Fit {
            place: Place::of(candidate),
            value,
            unit: candidate.unit().to_string(),
            interval,
            chi2,
            aicc,
            place_charge: 0.0,
            plausible,
            aicc_undefined,
            frequencies_hz: est.last.frequencies_hz.clone(),
            parameters: est.parameters,
            intervals,
        })
    });
    match fit {
        Some(fit) => RefitOutcome::Fit(Box::new(fit)),
        None if capped.exhausted() => RefitOutcome::CutShort,
        None => RefitOutcome::Failed,
    }
}

/// The step unit of every parameter of a refit ([`LevenbergMarquardt::with_step_units`](crate::update::LevenbergMarquardt::with_step_units)): 1 for
/// the `base_len` base parameters (in their own scale: a stiffness's log), and for each effect
/// value on a linear scale the size of its plausible range (the largest |value| it admits), so
/// the damped step's cap (ln 100 ≈ 4.6 units per step) means the same for every candidate,
/// whatever its unit. Without it a bearing's tilt stiffness, plausible up to 1e7 N·m/rad, moved
/// at most 4.6 N·m/rad per step: its fit stopped near 276 N·m/rad after 60 steps however large
/// the truth, and section changes were named in its place.
fn step_units(base_len: usize, set: &[&Candidate]) -> Vec<f64> {
    let mut units = vec![1.0; base_len];
    for c in set {
        for (p, (lo, hi)) in c.parameters().zip(c.plausible_ranges()) {
            let typical = lo.abs().max(hi.abs());
            let linear = p.scale == crate::model::Scale::Linear;
            units.push(if linear && typical.is_finite() && typical > 0.0 { typical } else { 1.0 });
        }
    }
    units
}

#[cfg(test)]
mod tests {
    use super::{indistinguishable, separation2};
    use crate::measurement::synthetic::NoiseRng;

    #[test]
    fn the_margin_is_the_floor_or_what_a_95_percent_test_cannot_reject() {
        // Under the floor: always ambiguous, however far apart.
        assert!(indistinguishable(1.9, 1e4, 2.0));
        // Fits 1.96σ apart: the margin is 1.96² = 3.84.
        let d2 = 1.959_963_984_540_054f64.powi(2);
        assert!(indistinguishable(3.8, d2, 2.0));
        assert!(!indistinguishable(3.9, d2, 2.0));
        // Fits the data separate clearly: only the floor.
        assert!(!indistinguishable(2.1, 100.0, 2.0));
    }

    /// When the alternative is the truth, the data reject it (it trails by more than the margin)
    /// in about 2.5 % of noise draws — the one-sided 95 % test the margin stands for.
    #[test]
    fn a_true_alternative_is_rejected_in_one_draw_in_forty() {
        let sigma = [1.0, 2.0, 0.5, 1.5];
        let truth = [10.0, 20.0, 30.0, 40.0];
        // The other fit: 1σ off in three modes, d² = 3 (margin 2·1.96·√3 − 3 = 3.79).
        let other = [11.0, 18.0, 30.0, 41.5];
        let d2 = separation2(&truth, &other, &sigma);
        assert!((d2 - 3.0).abs() < 1e-12, "{d2}");
        let mut rng = NoiseRng(7);
        let draws = 40_000;
        let mut rejected = 0;
        for _ in 0..draws {
            let y: Vec<f64> = truth.iter().zip(&sigma).map(|(t, s)| t + s * rng.normal()).collect();
            let chi2 = |f: &[f64]| -> f64 {
                y.iter().zip(f).zip(&sigma).map(|((y, f), s)| ((y - f) / s).powi(2)).sum()
            };
            // The truth trails the other fit by `delta` (when it trails at all).
            let delta = chi2(&truth) - chi2(&other);
            if delta > 0.0 && !indistinguishable(delta, d2, 0.0) {
                rejected += 1;
            }
        }
        let rate = rejected as f64 / draws as f64;
        assert!((rate - 0.025).abs() < 0.004, "true alternative rejected in {rate} of draws");
    }
}
